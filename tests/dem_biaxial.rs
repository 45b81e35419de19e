//! Biaxial test of the collapse models' DEM material (`granflow::dem::biaxial`), 300 grains
//! at σ₃ = 1 kPa, I = 10⁻³, to ε₁ = 0.3: a loose sample (deposited with the grains' friction,
//! as the collapse columns) and a dense one (deposited frictionless), ≈ 15 s each, run side by
//! side.

use granflow::dem::biaxial::{run_biaxial, BiaxialResult, BiaxialSpec};
use granflow::dem::scenario::DemScenario;

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
