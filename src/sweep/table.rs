//! The sweep's tables: `sweep.csv` (one row per case) and `fits.json` (the run-out laws).

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use super::{CaseResult, Solver};
use crate::analysis::powerlaw::{fit_runout, RunoutLaw};
use crate::analysis::runout::CollapseOutcome;
use crate::io::write_atomic;
use crate::Result;

/// A published run-out law ΔL = λ_s a (a < a_c), λ_l a^α (a > a_c) (docs/references.md,
/// column collapse run-out laws).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ReferenceLaw {
    /// Source.
    pub source: &'static str,
    /// Small-a slope λ_s.
    pub small_lambda: f64,
    /// Large-a prefactor λ_l.
    pub large_lambda: f64,
    /// Large-a exponent α.
    pub large_alpha: f64,
    /// Crossover a_c as quoted.
    pub crossover: f64,
}

impl ReferenceLaw {
    /// ΔL at `a` (the small-a law below the quoted crossover).
    pub fn at(&self, a: f64) -> f64 {
        if a < self.crossover {
            self.small_lambda * a
        } else {
            self.large_lambda * a.powf(self.large_alpha)
        }
    }
}

/// The laws drawn beside the results: Lajeunesse et al. 2005 (2-D channel, as quoted in the
/// thesis) and the thesis's 2-D DEM.
pub const REFERENCE_LAWS: [ReferenceLaw; 2] = [
    ReferenceLaw {
        source: "Lajeunesse et al. 2005 (experiments, 2-D channel)",
        small_lambda: 1.2,
        large_lambda: 1.9,
        large_alpha: 2.0 / 3.0,
        crossover: 2.3,
    },
    ReferenceLaw {
        source: "thesis, 2-D DEM (≈ 3000 disks)",
        small_lambda: 1.67,
        large_lambda: 2.7,
        large_alpha: 2.0 / 3.0,
        crossover: 2.7,
    },
];

/// The cases of one solver that share every varied value except the aspect ratio, and their
/// run-out law.
#[derive(Clone, Debug, Serialize)]
pub struct GroupFit {
    /// `"dem"`, `"mpm"` or `"rve"`.
    pub solver: &'static str,
    /// The other varied values of the group (path → value).
    pub with: BTreeMap<String, String>,
    /// (a, ΔL) of its cases, sorted by a.
    pub points: Vec<[f64; 2]>,
    /// (a, H_f/L_i) of its cases, sorted by a.
    pub heights: Vec<[f64; 2]>,
    /// The two-regime law (`None` with fewer than three cases).
    pub law: Option<RunoutLaw>,
}

/// A continuum (MPM, or MPM×DEM) against the DEM for one set of varied values (the same
/// nominal aspect ratio; the DEM's deposited column is a little taller than nominal).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Comparison {
    /// Aspect ratio of the DEM case (as deposited).
    pub a: f64,
    /// Aspect ratio of the continuum case.
    pub a_mpm: f64,
    /// ΔL of the DEM.
    pub dem: f64,
    /// ΔL of the continuum.
    pub mpm: f64,
    /// ΔL_continuum/ΔL_DEM − 1.
    pub mpm_excess: f64,
}

/// A failed case.
#[derive(Clone, Debug, Serialize)]
pub struct Failure {
    /// Case name.
    pub case: String,
    /// Its error.
    pub error: String,
}

/// `fits.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Fits {
    /// One law per solver (and per combination of the other varied values).
    pub groups: Vec<GroupFit>,
    /// MPM vs DEM case by case.
    pub mpm_vs_dem: Vec<Comparison>,
    /// MPM×DEM (`rve`) vs DEM case by case.
    pub rve_vs_dem: Vec<Comparison>,
    /// The published laws drawn beside them.
    pub references: [ReferenceLaw; 2],
    /// Cases that failed (left out of the fits).
    pub failed: Vec<Failure>,
}

/// Group key of a case: its solver and every varied value but the aspect ratio.
fn group_key(c: &CaseResult) -> (&'static str, BTreeMap<String, String>) {
    let with = c
        .case
        .labels
        .iter()
        .filter(|(p, _)| p != "column.aspect_ratio")
        .map(|(p, v)| (p.clone(), v.to_string()))
        .collect();
    (c.case.solver.name(), with)
}

/// Fits every group of successful cases (see [`fit_runout`]).
pub fn fits(cases: &[CaseResult]) -> Fits {
    let mut groups: BTreeMap<_, Vec<&CollapseOutcome>> = BTreeMap::new();
    let mut failed = Vec::new();
    for c in cases {
        match &c.outcome {
            Ok(o) => groups.entry(group_key(c)).or_default().push(o),
            Err(e) => failed.push(Failure {
                case: c.case.name.clone(),
                error: e.clone(),
            }),
        }
    }
    let groups: Vec<GroupFit> = groups
        .into_iter()
        .map(|((solver, with), mut os)| {
            os.sort_by(|p, q| p.aspect_ratio.total_cmp(&q.aspect_ratio));
            let (a, dl): (Vec<f64>, Vec<f64>) =
                os.iter().map(|o| (o.aspect_ratio, o.delta_l)).unzip();
            GroupFit {
                solver,
                with,
                points: os.iter().map(|o| [o.aspect_ratio, o.delta_l]).collect(),
                heights: os
                    .iter()
                    .map(|o| [o.aspect_ratio, o.h_f_over_l_i])
                    .collect(),
                law: fit_runout(&a, &dl),
            }
        })
        .collect();
    let (mpm_vs_dem, rve_vs_dem) = (
        versus_dem(cases, Solver::Mpm),
        versus_dem(cases, Solver::Rve),
    );
    Fits {
        groups,
        mpm_vs_dem,
        rve_vs_dem,
        references: REFERENCE_LAWS,
        failed,
    }
}

/// The cases of `solver` against the DEM's with the same varied values (aspect ratio
/// included).
fn versus_dem(cases: &[CaseResult], solver: Solver) -> Vec<Comparison> {
    let done = |c: &CaseResult| c.outcome.as_ref().ok().cloned();
    cases
        .iter()
        .filter(|c| c.case.solver == Solver::Dem)
        .filter_map(|d| {
            let twin = cases
                .iter()
                .find(|m| m.case.solver == solver && m.case.labels == d.case.labels);
            let (od, om) = (done(d)?, twin.and_then(done)?);
            Some(Comparison {
                a: od.aspect_ratio,
                a_mpm: om.aspect_ratio,
                dem: od.delta_l,
                mpm: om.delta_l,
                mpm_excess: om.delta_l / od.delta_l - 1.0,
            })
        })
        .collect()
}

/// Header of `sweep.csv` after the varied paths.
const COLUMNS: [&str; 23] = [
    "a",
    "l_i",
    "h_i",
    "l_f",
    "h_f",
    "delta_l",
    "h_f_over_l_i",
    "stop_time_tc",
    "rest_time_tc",
    "at_rest",
    "potential_released",
    "share_kinetic",
    "share_elastic",
    "share_collision",
    "share_friction",
    "share_rolling",
    "share_plastic",
    "share_damping",
    "energy_budget_error",
    "dt",
    "steps",
    "particle_steps_per_s",
    "wall_time_s",
];

/// The numbers of one case's row, in [`COLUMNS`] order.
fn row(o: &CollapseOutcome) -> [f64; 23] {
    let e = &o.energy;
    [
        o.aspect_ratio,
        o.l_i,
        o.h_i,
        o.l_f,
        o.h_f,
        o.delta_l,
        o.h_f_over_l_i,
        o.stop_time_tc,
        o.rest_time_tc,
        if o.at_rest { 1.0 } else { 0.0 },
        e.potential_released,
        e.share(e.kinetic),
        e.share(e.elastic),
        e.share(e.collision),
        e.share(e.friction),
        e.share(e.rolling),
        e.share(e.plastic),
        e.share(e.damping),
        o.energy_budget_error,
        o.dt,
        o.steps as f64,
        o.particle_steps_per_s,
        o.wall_time_s,
    ]
}

/// Writes `sweep.csv`: case, solver, the varied values, then [`COLUMNS`] (energies as shares
/// of the potential energy released; SI units otherwise). Failed cases are left out.
pub fn write_csv(path: &Path, cases: &[CaseResult]) -> Result<()> {
    let mut varied: Vec<String> = Vec::new();
    for (p, _) in cases.iter().flat_map(|c| &c.case.labels) {
        if !varied.contains(p) {
            varied.push(p.clone());
        }
    }
    let mut text = String::from("case,solver");
    for p in &varied {
        text.push(',');
        text.push_str(p);
    }
    for c in COLUMNS {
        text.push(',');
        text.push_str(c);
    }
    text.push('\n');
    for c in cases {
        let Ok(o) = &c.outcome else { continue };
        text.push_str(&format!("{},{}", c.case.name, c.case.solver.name()));
        for p in &varied {
            let v = c.case.labels.iter().find(|(q, _)| q == p);
            text.push(',');
            text.push_str(&v.map_or(String::new(), |(_, v)| v.to_string()));
        }
        for v in row(o) {
            text.push_str(&format!(",{v:.9e}"));
        }
        text.push('\n');
    }
    write_atomic(path, |w| w.write_all(text.as_bytes()))
}
