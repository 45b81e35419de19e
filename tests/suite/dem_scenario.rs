//! DEM column-collapse scenarios: every `models/column_collapse/dem_*.toml` parses and passes
//! its checks; bad values are refused with the field named; a tiny collapse runs and writes
//! its outputs.

use std::path::Path;

use granflow::scenario::collapse::dem::run_column_collapse;
use granflow::scenario::dem::DemScenario;
use granflow::scenario::ScenarioFile;

fn models() -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir("models/column_collapse")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("dem_") && n.ends_with(".toml"))
        })
        .collect();
    v.sort();
    v
}

#[test]
fn model_files_parse_and_check() {
    let files = models();
    assert_eq!(files.len(), 5, "{files:?}");
    for f in files {
        let s = DemScenario::from_file(&f).unwrap();
        let d = s
            .derive()
            .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        // The thesis used ≈ 3000 grains; the scaled files 1000–2500.
        assert!(
            (1000..=2500).contains(&d.grains),
            "{}: {}",
            f.display(),
            d.grains
        );
        println!(
            "{}: {} grains, H_i target {:.4} m",
            f.display(),
            d.grains,
            d.target_height
        );
    }
}

fn tiny() -> String {
    // 2-D units scaled for a test: 5 mm grains, soft contacts; ≈ 60 grains.
    r#"
kind = "dem"
name = "tiny"
description = "test"
gravity = [0.0, -9.81]
seed = 1
[grains]
d_min = 4.0e-3
d_max = 6.0e-3
distribution = "uniform_by_volume"
density = 2500.0
thickness = 5.0e-3
[column]
width = 0.04
aspect_ratio = 1.0
packing_estimate = 0.8
box_length = 0.16
[grain_contact]
k_n = 2.0e3
k_t = 2.0e3
restitution = 0.5
friction = 0.5
rolling_stiffness = 2.0e-3
rolling_damping = 5.0e-7
rolling_friction = 0.1
[wall_contact]
k_n = 2.0e3
k_t = 2.0e3
restitution = 0.5
friction = 0.5
rolling_stiffness = 2.0e-3
rolling_damping = 5.0e-7
rolling_friction = 0.1
[deposition]
friction = 0.5
rolling_friction = 0.1
rest_fraction = 1.0e-5
max_time = 3.0
[time]
lambda = 0.1
frame_interval_tc = 1.0
series_interval_tc = 0.1
end_tc = 10.0
rest_kinetic_fraction = 1.0e-4
rest_duration_tc = 0.5
"#
    .to_string()
}

#[test]
fn bad_values_are_refused_with_the_field_named() {
    let base = tiny();
    for (from, to, field) in [
        ("d_max = 6.0e-3", "d_max = 3.0e-3", "grains.d_max"),
        ("width = 0.04", "width = 0.01", "column.width"),
        (
            "box_length = 0.16",
            "box_length = 0.03",
            "column.box_length",
        ),
        (
            "packing_estimate = 0.8",
            "packing_estimate = 0.95",
            "column.packing_estimate",
        ),
        (
            "restitution = 0.5",
            "restitution = 1.5",
            "grain_contact.restitution",
        ),
        ("lambda = 0.1", "lambda = 0.0", "time.lambda"),
        ("density = 2500.0", "density = -1.0", "grains.density"),
        (
            "rolling_friction = 0.1\nrest_fraction",
            "rolling_friction = -0.1\nrest_fraction",
            "deposition.rolling_friction",
        ),
        (
            "[deposition]\n",
            "[deposition]\nsettling_velocity = 0.0\n",
            "deposition.settling_velocity",
        ),
        (
            "thickness = 5.0e-3",
            "thickness = 5.0e-3\nsides = 2",
            "grains.sides",
        ),
        (
            "thickness = 5.0e-3",
            "thickness = 5.0e-3\nsides = 13",
            "grains.sides",
        ),
    ] {
        assert!(base.contains(from), "{from}");
        let s = DemScenario::from_toml(&base.replacen(from, to, 1)).unwrap();
        let err = s.derive().unwrap_err().to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
    // Misspelt or missing keys are refused by the parser (no silent defaults).
    assert!(DemScenario::from_toml(&base.replace("thickness", "thicknes")).is_err());
    assert!(DemScenario::from_toml(&base.replace("gravity = [0.0, -9.81]\n", "")).is_err());
    // Gravity is a vector that must point into the floor.
    let up =
        DemScenario::from_toml(&base.replace("gravity = [0.0, -9.81]", "gravity = [0.0, 9.81]"));
    let e = up.unwrap().derive().map(|_| ()).unwrap_err().to_string();
    assert!(e.contains("gravity") && e.contains("g_y < 0"), "{e}");
}

/// `deposition.settling_velocity` v_s deposits against the drag α = g/v_s and then relaxes under
/// the undamped grain laws; without it, free fall and (same laws) no relaxation.
#[test]
fn settling_velocity_sets_the_deposition_drag_and_the_relaxation() {
    let base = tiny();
    let free = DemScenario::from_toml(&base).unwrap().derive().unwrap();
    assert_eq!(free.column.params.global_damping, 0.0);
    assert!(free.column.relax.is_none());
    let text = base.replacen(
        "[deposition]\n",
        "[deposition]\nsettling_velocity = 0.02\n",
        1,
    );
    let settled = DemScenario::from_toml(&text).unwrap().derive().unwrap();
    approx::assert_relative_eq!(settled.column.params.global_damping, 9.81 / 0.02);
    let relax = settled
        .column
        .relax
        .expect("a relaxation under the grain laws");
    assert_eq!(relax.global_damping, 0.0);
    assert_eq!(relax.grain, settled.column.params.grain);
}

/// A ≈ 60-grain a = 1 collapse comes to rest, runs out beyond L_i, keeps its height below
/// H_i, closes its energy budget within 1 % (issue 3 gate), and writes every output.
#[test]
fn tiny_collapse_runs_and_writes_outputs() {
    let s = DemScenario::from_toml(&tiny()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let sum = run_column_collapse(&s, dir.path(), &mut |_, _| {}).unwrap();
    println!("{}", serde_json::to_string_pretty(&sum).unwrap());
    assert!(sum.collapse.at_rest);
    assert!(sum.collapse.l_f > sum.collapse.l_i && sum.collapse.h_f < sum.collapse.h_i * 1.001);
    assert!(sum.collapse.delta_l > 0.0 && sum.collapse.delta_l < 5.0);
    assert!(
        sum.collapse.energy_budget_error < 0.01,
        "{}",
        sum.collapse.energy_budget_error
    );
    for f in [
        "summary.json",
        "timeseries.csv",
        "series.pvd",
        "grains_000000.vtu",
        "contacts_000000.vtu",
    ] {
        assert!(Path::new(&dir.path().join(f)).exists(), "{f}");
    }
    let csv = std::fs::read_to_string(dir.path().join("timeseries.csv")).unwrap();
    assert!(csv.starts_with("t,t_over_tc,runout,front,height,"));
    let pvd = std::fs::read_to_string(dir.path().join("series.pvd")).unwrap();
    assert!(pvd.contains("part=\"1\" file=\"contacts_000000.vtu\""));
}
