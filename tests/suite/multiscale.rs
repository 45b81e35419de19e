//! MPM×DEM (issue 20): a column whose material points each carry a DEM representative volume
//! runs through the collapse runner and writes the volumes' state with the points. The
//! physics of the volume (objectivity, MPM consistency, energy, preparation) is tested beside
//! its code in `granflow::dem::periodic_cell` and `granflow::coupling::rve`, and against the
//! wall-bounded biaxial test in `tests/suite/dem_biaxial.rs`.

use granflow::scenario::checkpointing::Control;
use granflow::scenario::collapse::mpm::run_column_collapse_with;
use granflow::scenario::mpm::spec::MaterialSpec;
use granflow::scenario::mpm::MpmScenario;
use granflow::scenario::ScenarioFile;

/// `rve_a1.toml` cut down: a 4 × 4-cell column of 32-disk volumes, released for 0.3 τ_c,
/// writing the grains of one volume with each frame (`--rve-frames`); a place outside the
/// column is refused.
#[test]
fn a_column_of_volumes_runs_and_writes_their_state() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse/rve_a1.toml");
    let mut s = MpmScenario::from_file(&path).unwrap();
    let MaterialSpec::Rve { grains, .. } = &mut s.material else {
        panic!("rve_a1.toml is not an rve file");
    };
    *grains = 32;
    s.column.width = 4.0 * s.mpm.cell_size;
    s.column.box_length = 12.0 * s.mpm.cell_size;
    s.time.end_tc = 0.3;
    s.time.frame_interval_tc = 0.15;
    let dir = tempfile::tempdir().unwrap();
    let far = [10.0 * s.column.width, 0.0];
    let err = run_column_collapse_with(&s, dir.path(), &[far], Control::default(), &mut |_, _| {})
        .unwrap_err();
    assert!(err.to_string().contains("--rve-frames"), "{err}");
    let centre = [0.5 * s.column.width, 0.5 * s.column.width];
    let r = run_column_collapse_with(
        &s,
        dir.path(),
        &[centre],
        Control::default(),
        &mut |_, _| {},
    )
    .unwrap();
    assert_eq!(r.solver, "mpm-rve");
    assert_eq!(r.points, 16);
    // The column slumps: some run-out, no point lost.
    assert!(r.collapse.delta_l >= 0.0 && r.collapse.delta_l.is_finite());
    let vtu = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().ends_with("points_000001.vtu"))
        .expect("a second points frame");
    let text = String::from_utf8_lossy(&std::fs::read(vtu).unwrap()).into_owned();
    for array in ["packing_fraction", "coordination", "fabric_xx", "stress_yy"] {
        assert!(
            text.contains(&format!("Name=\"{array}\"")),
            "no {array} array"
        );
    }
    // The chosen volume's 32 grains, each frame, in the series.
    let grains = std::fs::read(dir.path().join("volume_0_000001.vtu")).unwrap();
    let grains = String::from_utf8_lossy(&grains);
    assert!(grains.contains("NumberOfPoints=\"32\""), "not 32 grains");
    assert!(grains.contains("Name=\"radius\""));
    let series = std::fs::read_to_string(dir.path().join("series.pvd")).unwrap();
    assert!(
        series.contains("part=\"2\" file=\"volume_0_000000.vtu\""),
        "{series}"
    );
    let summary = std::fs::read_to_string(dir.path().join("summary.json")).unwrap();
    assert!(summary.contains("\"solver\": \"mpm-rve\""), "{summary}");
}
