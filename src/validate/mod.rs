//! Validation cases: each runs a scenario from `models/` against an analytic solution, a
//! published table or a conservation law, and reports one [`Check`] per quantity.
//!
//! `granflow validate <case|all> [--json]` prints them; the tests under `tests/` run the same
//! cases at [`Fidelity::Test`] (the smallest resolution that still proves the claim).

use serde::Serialize;

use crate::Result;

mod cavity;
mod conservation;
mod cylinder;
mod les;
mod poiseuille;
mod taylor_green;

/// One checked quantity.
#[derive(Clone, Debug, Serialize)]
pub struct Check {
    /// Case name, e.g. `poiseuille`.
    pub case: String,
    /// What was measured.
    pub quantity: String,
    /// Measured value.
    pub value: f64,
    /// Reference value.
    pub reference: f64,
    /// Allowed deviation (absolute unless the quantity name says otherwise).
    pub tolerance: f64,
    /// Whether the check passed; `None`-like reports (reference shown, no gate) always pass.
    pub pass: bool,
}

impl Check {
    /// |value − reference| ≤ tolerance.
    pub fn abs(case: &str, quantity: &str, value: f64, reference: f64, tolerance: f64) -> Self {
        Check {
            case: case.into(),
            quantity: quantity.into(),
            value,
            reference,
            tolerance,
            pass: (value - reference).abs() <= tolerance,
        }
    }

    /// |value − reference| ≤ tolerance·|reference|.
    pub fn rel(case: &str, quantity: &str, value: f64, reference: f64, tolerance: f64) -> Self {
        Check {
            case: case.into(),
            quantity: format!("{quantity} (relative tolerance)"),
            value,
            reference,
            tolerance,
            pass: (value - reference).abs() <= tolerance * reference.abs(),
        }
    }

    /// value ≤ limit (reference = limit, tolerance 0).
    pub fn at_most(case: &str, quantity: &str, value: f64, limit: f64) -> Self {
        Check {
            case: case.into(),
            quantity: format!("{quantity} (at most)"),
            value,
            reference: limit,
            tolerance: 0.0,
            pass: value <= limit,
        }
    }

    /// value ≥ limit.
    pub fn at_least(case: &str, quantity: &str, value: f64, limit: f64) -> Self {
        Check {
            case: case.into(),
            quantity: format!("{quantity} (at least)"),
            value,
            reference: limit,
            tolerance: 0.0,
            pass: value >= limit,
        }
    }

    /// A reported quantity beside its reference, not gated (always passes).
    pub fn report(case: &str, quantity: &str, value: f64, reference: f64) -> Self {
        Check {
            case: case.into(),
            quantity: format!("{quantity} (reported, not gated)"),
            value,
            reference,
            tolerance: f64::INFINITY,
            pass: true,
        }
    }
}

/// How hard to try.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fidelity {
    /// The smallest resolution that still proves the claim (the test suite).
    Test,
    /// The full resolution of docs/validation.md.
    Full,
}

/// A validation case.
pub struct Case {
    /// Name on the command line.
    pub name: &'static str,
    /// One line.
    pub description: &'static str,
    /// Runs it.
    pub run: fn(Fidelity) -> Result<Vec<Check>>,
}

/// All cases, in the order `validate all` runs them.
pub const CASES: &[Case] = &[
    Case {
        name: "poiseuille",
        description: "force-driven channel: 2nd-order convergence, exact at the magic τ",
        run: poiseuille::run,
    },
    Case {
        name: "taylor-green",
        description: "decaying vortex: decay rate 4νk², velocity error order",
        run: taylor_green::run,
    },
    Case {
        name: "conservation",
        description: "mass conservation in closed and periodic boxes; BGK vs MRT",
        run: conservation::run,
    },
    Case {
        name: "les-channel",
        description: "Smagorinsky channel against its analytic mixing-length profile",
        run: les::run,
    },
    Case {
        name: "cavity-re100",
        description: "lid-driven cavity vs Ghia et al. 1982, Re 100",
        run: cavity::run_re100,
    },
    Case {
        name: "cavity-re1000",
        description: "lid-driven cavity vs Ghia et al. 1982, Re 1000",
        run: cavity::run_re1000,
    },
    Case {
        name: "cylinder-2d1",
        description: "Schäfer–Turek 2D-1: drag, pressure drop, recirculation",
        run: cylinder::run_2d1,
    },
    Case {
        name: "cylinder-array",
        description: "Sangani–Acrivos periodic cylinder array drag",
        run: cylinder::run_array,
    },
    Case {
        name: "shedding",
        description: "seed Table 5.2: onset of shedding and Strouhal number",
        run: cylinder::run_shedding,
    },
];

/// Run a case by name.
pub fn run(name: &str, fidelity: Fidelity) -> Result<Vec<Check>> {
    let case = CASES.iter().find(|c| c.name == name).ok_or_else(|| {
        let names: Vec<_> = CASES.iter().map(|c| c.name).collect();
        crate::Error::Other(format!(
            "unknown validation case `{name}`; known: {}, all",
            names.join(", ")
        ))
    })?;
    (case.run)(fidelity)
}
