//! Continuum scenarios (`kind = "continuum"`): the slope model checks, bad keys are refused by
//! name, a layer on a frictionless base under a tilted gravity gains the momentum gravity
//! gives it, the `mpm-slope` case at test size, and a stopped run resumes to the same files.

use std::path::Path;

use granflow::scenario::continuum::run::run_continuum;
use granflow::scenario::continuum::ContinuumScenario;
use granflow::scenario::ScenarioFile;

use crate::common::assert_passes;

fn slope_text() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("models/mpm/slope.toml"))
        .unwrap()
}

/// `text` with the first occurrence of `from` replaced (which must be there).
fn with(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

#[test]
fn the_slope_model_derives_its_layer() {
    let s = ContinuumScenario::from_toml(&slope_text()).unwrap();
    let d = s.derive().unwrap();
    // 4 × 20 cells of material at 2 × 2 points per cell; the grid 4 × 30 cells.
    assert_eq!(d.points.len(), 320);
    assert_eq!(d.cells, [4, 30]);
    let report = s.check_report().unwrap();
    assert!(
        report.contains("periodic in x; bottom fixed, top open"),
        "{report}"
    );
    assert!(s.gravity_at(&d, 10.0)[0] > 0.0);
    let g = s.gravity_at(&d, 100.0);
    assert!(
        (g[0].atan2(-g[1]).to_degrees() - 40.0).abs() < 1e-12,
        "held at until_deg"
    );
}

/// Each bad value is refused naming its key.
#[test]
fn bad_continuum_keys_are_refused_by_name() {
    let text = slope_text();
    let cases = [
        (
            with(&text, "bottom = { kind = \"fixed\" }", "left = { kind = \"roller\" }"),
            "domain.left",
        ),
        (with(&text, "x = [0.0, 0.2]", "x = [0.0, 0.21]"), "domain.x"),
        (with(&text, "y = [0.0, 1.5]", "y = [1.5, 0.0]"), "domain.y"),
        (
            with(&text, "rectangle = [[0.0, 0.0], [0.2, 1.0]]", "rectangle = [[0.0, 0.0], [0.3, 1.0]]"),
            "fill[0]",
        ),
        (
            with(&text, "rectangle = [[0.0, 0.0], [0.2, 1.0]]", "rectangle = [[0.0, 0.0], [0.2, 1.0]]\npolygon = [[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]]"),
            "fill[0]",
        ),
        (with(&text, "until_deg = 40.0", "until_deg = -5.0"), "tilt.until_deg"),
        (with(&text, "rate_deg_per_s = 1.0", "rate_deg_per_s = 0.0"), "tilt.rate_deg_per_s"),
        (with(&text, "onset_speed = 0.01", "onset_speed = -1.0"), "tilt.onset_speed"),
        (with(&text, "end = 31.5", "end = 0.0"), "time.end"),
        (with(&text, "cell_size = 0.05", "cell_size = 0.0"), "mpm.cell_size"),
        (with(&text, "\"-1800*9.81*(1.0 - y)\"", "\"-1800*9.81*(1.0 - z)\""), "initial.stress[1]"),
        (with(&text, "courant = 0.5", "courant = 0.5\nsmoothing = 1.0"), "smoothing"),
    ];
    for (bad, key) in cases {
        let e = ContinuumScenario::from_toml(&bad)
            .and_then(|s| s.check_report())
            .unwrap_err()
            .to_string();
        assert!(e.contains(key), "expected `{key}` in: {e}");
    }
}

/// An elastic layer on a roller (frictionless) base, periodic in x, at its geostatic stress,
/// under g = (1.5, −9.7): nothing but gravity pushes along x, so the mean velocity along x is
/// g_x t at every row (to 1e-9), while the layer stays on its base (|v_y| ≪ g_x t).
#[test]
fn a_layer_on_a_frictionless_base_gains_the_momentum_of_gravity() {
    let text = with(
        &with(
            &with(
                &slope_text(),
                "gravity = [0.0, -9.81]",
                "gravity = [1.5, -9.7]",
            ),
            "[tilt]\nrate_deg_per_s = 1.0\nuntil_deg = 40.0\nonset_speed = 0.01\n",
            "",
        ),
        "bottom = { kind = \"fixed\" }",
        "bottom = { kind = \"roller\" }",
    );
    let text = with(
        &text,
        "model = \"mohr_coulomb\"",
        "model = \"linear_elastic\"",
    );
    let text = with(
        &text,
        "friction_angle_deg = 30.0\ndilatancy_angle_deg = 30.0\ncohesion = 0.0\ntension_cutoff = 0.0\n",
        "",
    );
    let text = with(
        &with(&text, "end = 31.5", "end = 0.5"),
        "cell_size = 0.05",
        "cell_size = 0.1",
    );
    let s = ContinuumScenario::from_toml(&text).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let control =
        granflow::scenario::checkpointing::Control::new(&text, None, Default::default()).unwrap();
    let summary = run_continuum(&s, dir.path(), control, &mut |_, _| {}).unwrap();
    assert!(summary.onset_deg.is_none());
    let csv = std::fs::read_to_string(dir.path().join("timeseries.csv")).unwrap();
    let mut rows = 0;
    for line in csv.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let expected = 1.5 * v[0];
        assert!(
            (v[3] - expected).abs() <= 1e-9 * expected.max(1.0),
            "{line}"
        );
        assert!(v[4].abs() < 0.01 * expected.max(1e-9) + 1e-6, "{line}");
        rows += 1;
    }
    assert_eq!(rows, 11);
    for f in ["series.pvd", "summary.json", "points_000001.vtu"] {
        assert!(dir.path().join(f).is_file(), "{f}");
    }
}

#[test]
fn mpm_slope() {
    assert_passes("mpm-slope");
}
