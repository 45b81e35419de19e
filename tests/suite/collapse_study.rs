//! The column-collapse study in reduced form: `models/column_collapse/sweep_quick.toml` cut to
//! a = 0.5 and 4, both solvers, run through `granflow::sweep::run_sweep`. Checked: the
//! ordering and bands the study must show (issue 5; docs/references.md, column collapse run-out laws),
//! not exact values; the outputs; and that a second run reuses every case.

use granflow::sweep::{run_sweep, Solver};

/// The quick sweep with only the aspect ratios in `keep`, its bases made absolute.
fn reduced_sweep(keep: &[f64]) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse");
    let text = std::fs::read_to_string(root.join("sweep_quick.toml")).unwrap();
    let mut t: toml::Table = text.parse().unwrap();
    for (_, base) in t["solvers"].as_table_mut().unwrap().iter_mut() {
        *base = root
            .join(base.as_str().unwrap())
            .display()
            .to_string()
            .into();
    }
    let dim = t["vary"].as_array_mut().unwrap()[0].as_table_mut().unwrap();
    let a: Vec<f64> = dim["column.aspect_ratio"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)).unwrap())
        .collect();
    let rows: Vec<usize> = (0..a.len()).filter(|&k| keep.contains(&a[k])).collect();
    assert_eq!(rows.len(), keep.len(), "sweep_quick lacks one of {keep:?}");
    for (_, values) in dim.iter_mut() {
        let v = values.as_array().unwrap();
        *values = rows
            .iter()
            .map(|&k| v[k].clone())
            .collect::<Vec<_>>()
            .into();
    }
    toml::to_string(&t).unwrap()
}

#[test]
#[ignore = "heavy tier (≈ 90 s on 2 cores): cargo test -- --ignored"]
fn quick_sweep_reduced_shows_the_ordering_and_bands() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.toml");
    std::fs::write(&sweep, reduced_sweep(&[0.5, 4.0])).unwrap();
    let out = dir.path().join("out");
    let r = run_sweep(&sweep, &out, 0, None, Default::default()).unwrap();
    assert_eq!(r.cases.len(), 4);
    let get = |solver: Solver, a: &str| {
        let c = r
            .cases
            .iter()
            .find(|c| c.case.solver == solver && c.case.name.ends_with(a))
            .unwrap();
        c.outcome
            .clone()
            .unwrap_or_else(|e| panic!("{}: {e}", c.case.name))
    };
    let (d05, d4) = (get(Solver::Dem, "_a0.5"), get(Solver::Dem, "_a4"));
    let (m05, m4) = (get(Solver::Mpm, "_a0.5"), get(Solver::Mpm, "_a4"));
    for o in [&d05, &d4, &m05, &m4] {
        println!(
            "{}: a = {:.3}, ΔL = {:.3}, H_f/L_i = {:.3}, stop {:.2} τ_c, budget error {:.2e}",
            o.name,
            o.aspect_ratio,
            o.delta_l,
            o.h_f_over_l_i,
            o.stop_time_tc,
            o.energy_budget_error
        );
        // Spreading stops after a few τ_c (≈ 3 τ_c in experiments; the DEM's last grains
        // creep on a little longer). A band, not a value: [2, 8] τ_c.
        assert!((2.0..=8.0).contains(&o.stop_time_tc), "{}", o.name);
        assert!(o.at_rest, "{} did not come to rest", o.name);
    }
    // DEM small-a slope ΔL/a within [1.2, 2.0] (Lajeunesse 1.2, thesis DEM 1.67; issue 5's band).
    let slope = d05.delta_l / d05.aspect_ratio;
    assert!((1.2..=2.0).contains(&slope), "DEM ΔL/a at a = 0.5: {slope}");
    // Taller columns run out further and leave a higher deposit, in both methods.
    assert!(d4.delta_l > 4.0 * d05.delta_l && m4.delta_l > 4.0 * m05.delta_l);
    assert!(d4.h_f_over_l_i > d05.h_f_over_l_i && m4.h_f_over_l_i > m05.h_f_over_l_i);
    // A short column keeps its height: H_f = H_i where the top is not reached by the
    // failure (a ≲ 0.7). The DEM column here is ≈ 17 grains tall, H is the top of the highest
    // grain, and the deposited top is domed (its highest grains sit inside the failing wedge):
    // over seeds 2005–2009 H_f/H_i = 0.882 (seed 2005), 0.932, 0.987, 0.939, 0.958, and seed
    // 2005 gave 0.931 under another floating-point rounding. A band of 15 %, not 2 %.
    assert!((d05.h_f_over_l_i / d05.aspect_ratio - 1.0).abs() < 0.15);
    assert!((m05.h_f_over_l_i / m05.aspect_ratio - 1.0).abs() < 0.02);
    // MPM within 15 % of DEM for a ≤ 2 (issue 5), and over-predicting for tall columns
    // (the thesis: no collisional dissipation in the free-fall phase).
    assert!((m05.delta_l / d05.delta_l - 1.0).abs() < 0.15);
    assert!(m4.delta_l > d4.delta_l);
    // Where the energy goes: the DEM dissipates a good part in collisions, the MPM almost
    // none (its wall impacts only); the MPM's is plastic flow.
    let share = |o: &granflow::analysis::runout::CollapseOutcome, part: f64| o.energy.share(part);
    assert!(share(&d4, d4.energy.collision) > 0.1);
    assert!(share(&m4, m4.energy.collision) < 0.02);
    assert!(share(&m4, m4.energy.plastic) > 0.5);
    // DEM energy closes (the budget error is the run's own measure, gate 1e-3).
    assert!(d05.energy_budget_error < 1e-3 && d4.energy_budget_error < 1e-3);
    // Outputs.
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "{csv}");
    assert!(csv.starts_with("case,solver,column.aspect_ratio,"));
    let fits: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fits.json")).unwrap()).unwrap();
    assert_eq!(fits["mpm_vs_dem"].as_array().unwrap().len(), 2);
    for f in [
        "runout",
        "height",
        "front",
        "energy_dem_a0.5",
        "energy_mpm_a4",
    ] {
        for ext in ["svg", "png"] {
            let p = out.join(format!("{f}.{ext}"));
            assert!(
                std::fs::metadata(&p).unwrap().len() > 1000,
                "{}",
                p.display()
            );
        }
    }
    // Resumable: a second run reuses every case.
    let again = run_sweep(&sweep, &out, 0, None, Default::default()).unwrap();
    assert!(again.cases.iter().all(|c| c.reused));
    assert_eq!(again.fits.mpm_vs_dem.len(), 2);
}
