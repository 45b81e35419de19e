//! `granflow sweep`: the column-collapse study. A sweep file ([`spec`]) names a base scenario
//! per solver and the fields to vary; every case runs in its own folder (cases in parallel on
//! the rayon pool), and the results are gathered into
//!
//! * `sweep.csv`: one row per case ([`table`]);
//! * `fits.json`: the two-regime run-out law ΔL = λ a^α per solver with the crossover found
//!   from the data ([`crate::analysis::powerlaw`]), beside the reference laws;
//! * figures, SVG and PNG ([`figures`]).
//!
//! Resumable: a case whose folder holds a complete `summary.json` written for the same
//! resolved scenario (`scenario.toml`) is not run again, and one that holds checkpoints of it
//! (`--checkpoint-every`, or a stop by SIGINT/SIGTERM) continues from the newest. A failed
//! case is reported with its error and the others go on. Asked to stop, the running cases stop
//! with a checkpoint, no new case starts, and the sweep ends with [`Error::Interrupted`].

pub mod figures;
pub mod progress;
pub mod spec;
pub mod table;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::analysis::runout::CollapseOutcome;
use crate::io::{checkpoint, write_atomic};
use crate::scenario::checkpointing::Control;
use crate::scenario::ScenarioFile;
use crate::{Error, Result};
pub use spec::{read_sweep, Case, Solver, SweepSpec};

/// File in each case folder holding the resolved scenario the case ran.
pub const SCENARIO_FILE: &str = "scenario.toml";

/// What became of one case.
#[derive(Clone, Debug)]
pub struct CaseResult {
    /// The case.
    pub case: Case,
    /// Its folder.
    pub dir: PathBuf,
    /// The outcome, or the error that stopped it.
    pub outcome: std::result::Result<CollapseOutcome, String>,
    /// Whether an earlier run's result was reused.
    pub reused: bool,
    /// Whether the case continued from a checkpoint of an earlier, stopped run.
    pub resumed: bool,
}

/// The result of a whole sweep.
#[derive(Clone, Debug)]
pub struct SweepReport {
    /// The sweep file as read.
    pub spec: SweepSpec,
    /// Every case, in the order of [`spec::expand`].
    pub cases: Vec<CaseResult>,
    /// The fits written to `fits.json`.
    pub fits: table::Fits,
}

impl SweepReport {
    /// Cases that failed.
    pub fn failed(&self) -> impl Iterator<Item = &CaseResult> {
        self.cases.iter().filter(|c| c.outcome.is_err())
    }
}

/// The summary of an earlier run of `case` in `dir`, if it is complete and was written for the
/// same resolved scenario.
fn reusable(case: &Case, dir: &Path) -> Option<CollapseOutcome> {
    let ran = std::fs::read_to_string(dir.join(SCENARIO_FILE)).ok()?;
    if ran != case.scenario {
        return None;
    }
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    serde_json::from_str(&text).ok()
}

/// Runs one case in `dir` (see the module doc for reuse), from its newest checkpoint if it
/// has one of the same resolved scenario, checkpointing every `every` simulated seconds and
/// stopping when `stop` is set.
fn run_case(
    case: &Case,
    dir: &Path,
    every: Option<f64>,
    stop: &Arc<AtomicUsize>,
    progress: crate::exec::Progress,
) -> Result<(CollapseOutcome, bool)> {
    crate::io::run_dir::create(dir)?;
    let same = std::fs::read_to_string(dir.join(SCENARIO_FILE)).ok() == Some(case.scenario.clone());
    let mut control = Control::new(&case.scenario, every, Arc::clone(stop))?;
    control.resume = same && !checkpoint::list(dir)?.is_empty();
    if !control.resume {
        // A stale summary must not survive a run that fails part-way, nor checkpoints of
        // another scenario the new ones.
        let summary = dir.join("summary.json");
        if summary.exists() {
            std::fs::remove_file(&summary).map_err(|e| Error::io(&summary, e))?;
        }
        checkpoint::remove_all(dir)?;
        write_atomic(&dir.join(SCENARIO_FILE), |w| {
            w.write_all(case.scenario.as_bytes())
        })?;
    }
    let resumed = control.resume;
    let outcome = match case.solver {
        Solver::Dem => {
            let s = crate::scenario::dem::DemScenario::from_toml(&case.scenario)?;
            crate::scenario::collapse::dem::run_resumable_collapse(&s, dir, control, progress)?
                .collapse
        }
        Solver::Mpm | Solver::Rve => {
            let s = crate::scenario::mpm::MpmScenario::from_toml(&case.scenario)?;
            crate::scenario::collapse::mpm::run_column_collapse_with(
                &s,
                dir,
                &[],
                control,
                progress,
            )?
            .collapse
        }
    };
    Ok((outcome, resumed))
}

/// End time of a case in milli-τ_c (for its progress bar).
fn end_milli_tc(case: &Case) -> u64 {
    case.scenario
        .parse::<toml::Table>()
        .ok()
        .and_then(|t| t.get("time")?.get("end_tc")?.as_float())
        .map_or(0, |e| (1e3 * e) as u64)
}

/// Runs the sweep of `path` into `out`: `jobs` cases at a time (0: as many as the rayon pool
/// has threads), each checkpointing every `every` simulated seconds (if given) and stopping
/// when `stop` is set; then writes `sweep.csv`, `fits.json` and the figures.
pub fn run_sweep(
    path: &Path,
    out: &Path,
    jobs: usize,
    every: Option<f64>,
    stop: Arc<AtomicUsize>,
) -> Result<SweepReport> {
    let (spec, cases) = read_sweep(path)?;
    // Every case must parse before anything runs: a bad value fails the sweep up front.
    for case in &cases {
        case.check()?;
    }
    crate::io::run_dir::create(out)?;
    let display = progress::Display::new(&cases);
    let results: Mutex<Vec<Option<CaseResult>>> = Mutex::new(vec![None; cases.len()]);
    let work = || {
        cases
            .par_iter()
            .enumerate()
            .with_max_len(1)
            .for_each(|(k, case)| {
                let dir = out.join(&case.name);
                let (outcome, reused, resumed) = match reusable(case, &dir) {
                    Some(o) => (Ok(o), true, false),
                    None if stop.load(Ordering::Relaxed) != 0 => (
                        Err("not started: the sweep was stopped".into()),
                        false,
                        false,
                    ),
                    None => {
                        let mut bar = display.start(k, end_milli_tc(case));
                        match run_case(case, &dir, every, &stop, &mut bar) {
                            Ok((o, resumed)) => (Ok(o), false, resumed),
                            Err(e) => (Err(format!("{e:#}")), false, false),
                        }
                    }
                };
                display.finish(k, &outcome, reused);
                results.lock().expect("no panic while holding the lock")[k] = Some(CaseResult {
                    case: case.clone(),
                    dir,
                    outcome,
                    reused,
                    resumed,
                });
            })
    };
    if jobs == 0 {
        work();
    } else {
        rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| Error::Other(e.to_string()))?
            .install(work);
    }
    let cases: Vec<CaseResult> = results
        .into_inner()
        .expect("no panic while holding the lock")
        .into_iter()
        .map(|r| r.expect("every case ran"))
        .collect();
    let signal = stop.load(Ordering::Relaxed);
    if signal != 0 {
        let unfinished = cases.iter().filter(|c| c.outcome.is_err()).count();
        return Err(Error::Interrupted {
            signal: signal as i32,
            at: format!("with {unfinished} of {} cases unfinished", cases.len()),
            saved: out.to_path_buf(),
            resume: format!("granflow sweep {} --out {}", path.display(), out.display()),
        });
    }
    table::write_csv(&out.join("sweep.csv"), &cases)?;
    let fits = table::fits(&cases);
    crate::io::write_json(&out.join("fits.json"), &fits)?;
    figures::write_all(out, &cases, &fits)?;
    Ok(SweepReport { spec, cases, fits })
}
