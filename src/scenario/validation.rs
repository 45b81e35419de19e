//! Validation cases: each runs a scenario from `models/` against an analytic solution, a
//! published table or a conservation law, and reports one [`Check`] per quantity.
//!
//! `granflow validate <case|all> [--json] [--figures DIR]` prints them (and writes each case's
//! [`Plot`](crate::report::Plot)s as SVG); the tests under `tests/` run the same cases at
//! [`Fidelity::Test`] (the smallest resolution that still proves the claim).

use super::dem::{validation as dem, validation_polygon};
use super::fluid::validation::{cavity, conservation, cylinder, les, poiseuille, taylor_green};
use super::mpm::validation as mpm;
use super::submerged::{validation as psm, validation_ladd as ladd};
use crate::lbm::Backend;
use crate::report::{Check, Fidelity, Report};
use crate::Result;

/// A validation case.
pub struct Case {
    /// Name on the command line.
    pub name: &'static str,
    /// One line.
    pub description: &'static str,
    /// Runs it.
    pub run: fn(Fidelity) -> Result<Report>,
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
    Case {
        name: "dem-restitution",
        description: "head-on grain-grain and grain-wall impacts: e within 1 % for e = 0.3..0.95",
        run: |f| checks_only(dem::restitution(f)),
    },
    Case {
        name: "dem-incline",
        description: "frictionless disk on a 45° segment: a/g = 0.7071, no rotation",
        run: |f| checks_only(dem::incline(f)),
    },
    Case {
        name: "dem-conservation",
        description: "grain momentum to round-off; elastic-gas energy drift over 1e5 steps",
        run: |f| checks_only(dem::conservation(f)),
    },
    Case {
        name: "dem-energy",
        description: "DEM energy budget of a settling run closes within 1 %",
        run: |f| checks_only(dem::energy_budget(f)),
    },
    Case {
        name: "dem-polygon",
        description: "rapier2d detector = cell list on disks; polygon grains: rest, rough incline, momentum, budget",
        run: |f| checks_only(validation_polygon::polygons(f)),
    },
    Case {
        name: "silo-beverloo",
        description: "2-D silo: discharge rate W ∝ (D − k d)^{3/2} over orifice widths 8–16 d",
        run: super::granular::validation::run,
    },
    Case {
        name: "chute-bagnold",
        description: "steady chute flow: velocity profile vs Bagnold's within 5 % in the bulk, exponent 3/2",
        run: super::granular::chute::run,
    },
    Case {
        name: "mpm-slope",
        description: "infinite slope on a tilting table: sliding at tan φ/tan β = 1 (ψ = φ) and tan β = sin φ (ψ = 0) within 1°",
        run: super::continuum::slope::run,
    },
    Case {
        name: "rve-biaxial",
        description: "periodic volume vs wall-bounded biaxial test of one material: φ peak and critical within 2°",
        run: |f| checks_only(super::dem::rve_biaxial::validation(f)),
    },
    Case {
        name: "psm-cylinder-array",
        description: "partially saturated cells: Sangani–Acrivos drag within 5 %, d ≥ 20 cells",
        run: psm::psm_cylinder_array,
    },
    Case {
        name: "coupling-momentum",
        description: "fluid + grain momentum in a closed periodic box to 1e-10 relative",
        run: psm::momentum,
    },
    Case {
        name: "settling-disk",
        description: "disk settling in a channel: u_t converges with d, vs Faxén's drag",
        run: psm::settling,
    },
    Case {
        name: "dkt",
        description: "two disks draft, kiss (gap < Δx) and tumble; times reported",
        run: psm::dkt,
    },
    Case {
        name: "ladd-cylinder-array",
        description: "Ladd's bounce-back: Sangani–Acrivos drag within 5 %, d ≥ 20 cells",
        run: ladd::cylinder_array,
    },
    Case {
        name: "ladd-settling-disk",
        description: "Ladd's bounce-back: settling disk vs Faxén and the PSM terminal velocity",
        run: ladd::settling,
    },
    Case {
        name: "ladd-momentum",
        description: "Ladd's bounce-back: fluid + grain momentum in a periodic box, with/without impulses",
        run: ladd::momentum,
    },
    Case {
        name: "ladd-force-noise",
        description: "towed disk: mean drag and per-step fluctuation, Ladd (± impulses) vs PSM",
        run: ladd::force_noise,
    },
    Case {
        name: "mpm-selfweight",
        description: "elastic column under gravity: σ_yy = −ρg(H − y) within 2 % of ρgH",
        run: |f| checks_only(mpm::selfweight(f)),
    },
    Case {
        name: "mpm-mc-biaxial",
        description: "Mohr–Coulomb plane-strain biaxial: peak σ₁ within 1 %, ψ = 0 isochoric",
        run: |f| checks_only(mpm::mc_biaxial(f)),
    },
    Case {
        name: "mpm-cell-crossing",
        description: "points crossing cells (compacting column): GIMP stress error ≥ 10× below standard MPM",
        run: |f| checks_only(mpm::cell_crossing(f)),
    },
    Case {
        name: "mpm-conservation",
        description: "MPM mass exact, momentum to round-off (USF, USL, MUSL, MUSL + PIC)",
        run: |f| checks_only(mpm::conservation(f)),
    },
    Case {
        name: "mpm-friction",
        description: "block sliding on a Coulomb wall: deceleration μg, distance v₀²/(2μg)",
        run: |f| checks_only(mpm::sliding_block(f)),
    },
];

/// A report of checks without figures.
fn checks_only(checks: Result<Vec<Check>>) -> Result<Report> {
    Ok(Report {
        checks: checks?,
        plots: Vec::new(),
    })
}

/// A case that runs on either back end: its checks and references are the same on both.
type OnBackend = fn(Fidelity, Backend) -> Result<Report>;

/// The cases `validate --backend gpu` runs: every fluid-only case, and the coupled cases of
/// the partially saturated cells at test size (momentum, settling disk).
pub const ON_ANY_BACKEND: &[(&str, OnBackend)] = &[
    ("poiseuille", poiseuille::run_on),
    ("taylor-green", taylor_green::run_on),
    ("conservation", conservation::run_on),
    ("les-channel", les::run_on),
    ("cavity-re100", cavity::re100_on),
    ("cavity-re1000", cavity::re1000_on),
    ("cylinder-2d1", cylinder::run_2d1_on),
    ("cylinder-array", cylinder::run_array_on),
    ("shedding", cylinder::run_shedding_on),
    ("coupling-momentum", psm::momentum_on),
    ("settling-disk", psm::settling_on),
];

/// Run a case by name on `backend` (on the GPU: one of [`ON_ANY_BACKEND`]).
pub fn run_on(name: &str, fidelity: Fidelity, backend: Backend) -> Result<Report> {
    if backend == Backend::Cpu {
        return run(name, fidelity);
    }
    let (_, case) = ON_ANY_BACKEND
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| {
            let names: Vec<_> = ON_ANY_BACKEND.iter().map(|c| c.0).collect();
            crate::Error::Other(format!(
                "validation case `{name}` does not run on the {} back end; cases that do: {}",
                backend.name(),
                names.join(", ")
            ))
        })?;
    case(fidelity, backend)
}

/// Run a case by name.
pub fn run(name: &str, fidelity: Fidelity) -> Result<Report> {
    let case = CASES.iter().find(|c| c.name == name).ok_or_else(|| {
        let names: Vec<_> = CASES.iter().map(|c| c.name).collect();
        crate::Error::Other(format!(
            "unknown validation case `{name}`; known: {}, all",
            names.join(", ")
        ))
    })?;
    (case.run)(fidelity)
}
