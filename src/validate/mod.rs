//! Validation cases: each runs a scenario from `models/` against an analytic solution, a
//! published table or a conservation law, and reports one [`Check`] per quantity.
//!
//! `granflow validate <case|all> [--json] [--figures DIR]` prints them (and writes each case's
//! [`Plot`]s as SVG); the tests under `tests/` run the same cases at [`Fidelity::Test`] (the
//! smallest resolution that still proves the claim).

use serde::Serialize;

use crate::Result;

mod cavity;
mod conservation;
mod cylinder;
mod les;
mod poiseuille;
mod taylor_green;

pub(crate) use cylinder::SANGANI_ACRIVOS;

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

/// What a case returns: its checks and the data of its figures.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Report {
    /// One per checked quantity.
    pub checks: Vec<Check>,
    /// Figures made from data the case computed anyway (no extra simulation).
    pub plots: Vec<Plot>,
}

/// How a [`Series`] is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Style {
    /// Points joined by a line (analytic solutions, time histories).
    Line,
    /// One marker per point (measurements, reference tables).
    Markers,
}

/// One curve or point set of a [`Plot`].
#[derive(Clone, Debug, Serialize)]
pub struct Series {
    /// Legend entry (empty: none).
    pub label: String,
    /// (x, y) data.
    pub points: Vec<(f64, f64)>,
    /// Line or markers.
    pub style: Style,
    /// Palette index of the colour; `None`: the series' position in the plot.
    pub colour: Option<usize>,
}

impl Series {
    /// A line through `points`.
    pub fn line(label: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            style: Style::Line,
            colour: None,
        }
    }

    /// Markers at `points`.
    pub fn markers(label: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            style: Style::Markers,
            colour: None,
        }
    }

    /// Draw in palette colour `k` (so related series can share a colour).
    pub fn coloured(mut self, k: usize) -> Self {
        self.colour = Some(k);
        self
    }

    /// Keep at most `max` points (≥ 2) by taking every k-th one, always keeping the last, so
    /// long time series stay small in a figure.
    pub fn decimated(mut self, max: usize) -> Self {
        let n = self.points.len();
        let max = max.max(2);
        if n > max {
            let stride = n.div_ceil(max - 1);
            let last = self.points[n - 1];
            let mut kept: Vec<_> = self.points.iter().copied().step_by(stride).collect();
            if kept.last() != Some(&last) {
                kept.push(last);
            }
            self.points = kept;
        }
        self
    }
}

/// The data of one figure; `granflow validate --figures DIR` writes it to `DIR/<name>.svg`.
#[derive(Clone, Debug, Serialize)]
pub struct Plot {
    /// File stem, e.g. `poiseuille-profile`.
    pub name: String,
    /// Caption drawn above the axes.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// Logarithmic horizontal axis.
    pub log_x: bool,
    /// Logarithmic vertical axis.
    pub log_y: bool,
    /// Fixed vertical range (points outside are drawn at its edge); `None`: fit the data.
    pub y_range: Option<(f64, f64)>,
    /// The curves, drawn in order.
    pub series: Vec<Series>,
}

impl Plot {
    /// An empty plot with linear axes.
    pub fn new(name: &str, title: &str, x_label: &str, y_label: &str) -> Self {
        Plot {
            name: name.into(),
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: false,
            y_range: None,
            series: Vec::new(),
        }
    }

    /// Fix the vertical range to [lo, hi] instead of fitting the data.
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Logarithmic axes (x, y).
    pub fn log(mut self, x: bool, y: bool) -> Self {
        self.log_x = x;
        self.log_y = y;
        self
    }

    /// Add a series.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }
}

/// Largest number of points a time series keeps in a figure.
pub const MAX_PLOT_POINTS: usize = 500;

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
        run: |f| checks_only(crate::dem::validation::restitution(f)),
    },
    Case {
        name: "dem-incline",
        description: "frictionless disk on a 45° segment: a/g = 0.7071, no rotation",
        run: |f| checks_only(crate::dem::validation::incline(f)),
    },
    Case {
        name: "dem-conservation",
        description: "grain momentum to round-off; elastic-gas energy drift over 1e5 steps",
        run: |f| checks_only(crate::dem::validation::conservation(f)),
    },
    Case {
        name: "dem-energy",
        description: "DEM energy budget of a settling run closes within 1 %",
        run: |f| checks_only(crate::dem::validation::energy_budget(f)),
    },
    Case {
        name: "dem-polygon",
        description: "rapier2d detector = cell list on disks; polygon grains: rest, rough incline, momentum, budget",
        run: |f| checks_only(crate::dem::validation_polygon::polygons(f)),
    },
    Case {
        name: "psm-cylinder-array",
        description: "partially saturated cells: Sangani–Acrivos drag within 5 %, d ≥ 20 cells",
        run: crate::coupling::validation::psm_cylinder_array,
    },
    Case {
        name: "coupling-momentum",
        description: "fluid + grain momentum in a closed periodic box to 1e-10 relative",
        run: crate::coupling::validation::momentum,
    },
    Case {
        name: "settling-disk",
        description: "disk settling in a channel: u_t converges with d, vs Faxén's drag",
        run: crate::coupling::validation::settling,
    },
    Case {
        name: "dkt",
        description: "two disks draft, kiss (gap < Δx) and tumble; times reported",
        run: crate::coupling::validation::dkt,
    },
    Case {
        name: "ladd-cylinder-array",
        description: "Ladd's bounce-back: Sangani–Acrivos drag within 5 %, d ≥ 20 cells",
        run: crate::coupling::validation_ladd::cylinder_array,
    },
    Case {
        name: "ladd-settling-disk",
        description: "Ladd's bounce-back: settling disk vs Faxén and the PSM terminal velocity",
        run: crate::coupling::validation_ladd::settling,
    },
    Case {
        name: "ladd-momentum",
        description: "Ladd's bounce-back: fluid + grain momentum in a periodic box, with/without impulses",
        run: crate::coupling::validation_ladd::momentum,
    },
    Case {
        name: "ladd-force-noise",
        description: "towed disk: mean drag and per-step fluctuation, Ladd (± impulses) vs PSM",
        run: crate::coupling::validation_ladd::force_noise,
    },
    Case {
        name: "mpm-selfweight",
        description: "elastic column under gravity: σ_yy = −ρg(H − y) within 2 % of ρgH",
        run: |f| checks_only(crate::mpm::validation::selfweight(f)),
    },
    Case {
        name: "mpm-mc-biaxial",
        description: "Mohr–Coulomb plane-strain biaxial: peak σ₁ within 1 %, ψ = 0 isochoric",
        run: |f| checks_only(crate::mpm::validation::mc_biaxial(f)),
    },
    Case {
        name: "mpm-cell-crossing",
        description: "points crossing cells (compacting column): GIMP stress error ≥ 10× below standard MPM",
        run: |f| checks_only(crate::mpm::validation::cell_crossing(f)),
    },
    Case {
        name: "mpm-conservation",
        description: "MPM mass exact, momentum to round-off (USF, USL, MUSL, MUSL + PIC)",
        run: |f| checks_only(crate::mpm::validation::conservation(f)),
    },
    Case {
        name: "mpm-friction",
        description: "block sliding on a Coulomb wall: deceleration μg, distance v₀²/(2μg)",
        run: |f| checks_only(crate::mpm::validation::sliding_block(f)),
    },
];

/// A report of checks without figures.
fn checks_only(checks: Result<Vec<Check>>) -> Result<Report> {
    Ok(Report {
        checks: checks?,
        plots: Vec::new(),
    })
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
