//! Biaxial test of the collapse models' DEM material (`granflow::scenario::dem::biaxial`), 300 grains
//! at σ₃ = 1 kPa, I = 10⁻³, to ε₁ = 0.3: a loose sample (deposited with the grains' friction,
//! as the collapse columns) and a dense one (deposited frictionless), ≈ 15 s each, run side by
//! side; and the periodic representative volume of the same material beside the walls
//! (`granflow::scenario::dem::rve_biaxial`, ≈ 20 + 17 s in turn).

use granflow::scenario::dem::biaxial::{run_biaxial, BiaxialResult, BiaxialSpec};
use granflow::scenario::dem::DemScenario;
use granflow::scenario::ScenarioFile;

fn sample(prep_friction: f64) -> BiaxialResult {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse/dem_a2.toml");
    let s = DemScenario::from_file(&path).unwrap();
    let spec =
        BiaxialSpec::from_scenario(&s, 300, 1000.0, 1e-3, 0.3, Some(prep_friction), None).unwrap();
    run_biaxial(&spec, &mut |_, _| {}).unwrap()
}

/// Critical state (Schofield & Wroth 1968): sheared far enough, a granular material flows at a
/// stress ratio and a density that do not depend on where it started. Gates, from the
/// measured values (in brackets) and their scatter between record windows:
/// * the pistons hold σ₃: the mean over the second half within 2 % of 1 kPa (1000 ± 4 Pa);
/// * quasi-static: lid and floor carry the same σ₁ on average, within 2 % (≈ 3e-4);
/// * the dense sample dilates (ε_v < 0 at the end) and has a peak above its critical state
///   (Rowe's stress–dilatancy), by > 0.03 in sin φ;
/// * loose and dense reach the same critical sin φ within 0.06 (each is a mean over ≈ 60
///   records whose standard deviation is ≈ 0.04–0.05) and the same solid fraction within 0.01.
#[test]
#[ignore = "heavy tier (≈ 30 s on 2 cores): cargo test -- --ignored"]
fn loose_and_dense_samples_reach_one_critical_state() {
    let (loose, dense) = std::thread::scope(|s| {
        let l = s.spawn(|| sample(0.53));
        let d = s.spawn(|| sample(0.0));
        (l.join().unwrap(), d.join().unwrap())
    });
    for (name, r) in [("loose", &loose), ("dense", &dense)] {
        println!("{name}: {}", r.done_line());
        assert!((r.critical_sigma_3 / 1000.0 - 1.0).abs() < 0.02, "{name}");
        assert!(r.lid_floor_difference.abs() < 0.02, "{name}");
    }
    assert!(dense.initial_packing_fraction > loose.initial_packing_fraction + 0.02);
    assert!(dense.points.last().unwrap().volumetric_strain < 0.0);
    assert!(dense.peak_sin_phi > dense.critical_sin_phi + 0.03);
    assert!((dense.critical_sin_phi - loose.critical_sin_phi).abs() < 0.06);
    assert!((dense.critical_packing_fraction - loose.critical_packing_fraction).abs() < 0.01);
}

/// A sedimented preparation (`deposition.settling_velocity`): its drag belongs to the deposition
/// only, so the sample consolidates at σ₃ and shears (before this was handled, the drag stayed
/// on in the first consolidation and the sample never came to rest). 300 grains to ε₁ = 0.02;
/// σ₃ held within 2 % over the second half, and the sample starts looser than the frictional
/// deposit of `sample(0.53)` consolidated the same way (0.778, docs/dev/dem-status.md; measured
/// 0.764).
#[test]
#[ignore = "heavy tier (≈ 30 s on 2 cores): cargo test -- --ignored"]
fn a_sedimented_sample_consolidates_and_shears() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse/dem_a2.toml");
    let mut s = DemScenario::from_file(&path).unwrap();
    s.deposition.settling_velocity = Some(0.02);
    let spec = BiaxialSpec::from_scenario(&s, 300, 1000.0, 1e-3, 0.02, None, None).unwrap();
    assert!(spec.column.params.global_damping > 0.0);
    let r = run_biaxial(&spec, &mut |_, _| {}).unwrap();
    println!("sedimented: {}", r.done_line());
    assert!((r.critical_sigma_3 / 1000.0 - 1.0).abs() < 0.02);
    assert!(
        r.initial_packing_fraction < 0.775,
        "{}",
        r.initial_packing_fraction
    );
}

/// The representative volume (a bi-periodic cell, `granflow::dem::periodic_cell`) and the
/// wall-bounded sample of the same material reach the same critical state: the `rve-biaxial`
/// validation case at test size (its gates and their sources are in
/// `granflow::scenario::dem::rve_biaxial::validation`).
#[test]
#[ignore = "heavy tier (≈ 40 s on 2 cores): cargo test -- --ignored"]
fn the_periodic_volume_and_the_walls_agree_on_the_critical_state() {
    let checks =
        granflow::scenario::dem::rve_biaxial::validation(granflow::report::Fidelity::Test).unwrap();
    for c in &checks {
        println!(
            "{}: {} = {:.4} (ref {:.4}, tol {:.2}) {}",
            c.case,
            c.quantity,
            c.value,
            c.reference,
            c.tolerance,
            if c.pass { "ok" } else { "FAIL" }
        );
    }
    assert!(checks.iter().all(|c| c.pass));
}
