//! DEM validation: restitution, incline, conservation, energy budget, time-step refusal,
//! packing. Tolerances and their sources are in `granflow::dem::validation`.

use granflow::dem::packing::{deposit_column, hex_block, with_friction, ColumnSpec, SizeDistribution};
use granflow::dem::validation;
use granflow::dem::{ContactParams, Dem, DemParams, Grains, Wall};
use granflow::validate::{Check, Fidelity};

fn assert_all(checks: &[Check]) {
    for c in checks {
        println!("{}: {} = {:.6e} (ref {:.6e}, tol {:.1e}) {}", c.case, c.quantity, c.value, c.reference, c.tolerance, if c.pass { "ok" } else { "FAIL" });
    }
    assert!(checks.iter().all(|c| c.pass));
}

/// e = 0.3…0.95 within 1 % (REFERENCES, DEM: linear spring-dashpot, contact ends at δ = 0).
#[test]
fn restitution_within_one_percent() {
    assert_all(&validation::restitution(Fidelity::Test).unwrap());
}

/// Frictionless disk on 45°: a/g = sin 45° within 0.5 %, no rotation.
#[test]
fn incline_acceleration() {
    assert_all(&validation::incline(Fidelity::Test).unwrap());
}

/// Momentum to round-off; elastic gas energy drift < 0.1 % over 1e5 steps.
#[test]
fn conservation_momentum_and_energy() {
    assert_all(&validation::conservation(Fidelity::Test).unwrap());
}

/// Settling run: initial = current + dissipated within 1 %.
#[test]
fn energy_budget_closes() {
    assert_all(&validation::energy_budget(Fidelity::Test).unwrap());
}
