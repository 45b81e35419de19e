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
//!
//! Beyond one machine: [`run_one_case`] runs a single case (`granflow sweep FILE --out DIR
//! --case K`, a scheduler's job array, one task per case), after which a plain sweep of the
//! same file and folder reuses every finished case and writes the tables; with the feature
//! `mpi`, `ranks` spreads the cases over MPI ranks.

pub mod figures;
pub mod progress;
#[cfg(feature = "mpi")]
pub mod ranks;
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

/// One case of a sweep run in `out` (or reused from an earlier run there): what becomes of
/// case `k` of `cases` (see the module doc).
fn run_case_in(
    cases: &[Case],
    k: usize,
    out: &Path,
    every: Option<f64>,
    stop: &Arc<AtomicUsize>,
    display: &progress::Display,
) -> CaseResult {
    let case = &cases[k];
    let dir = out.join(&case.name);
    let (outcome, reused, resumed) = match reusable(case, &dir) {
        Some(o) => (Ok(o), true, false),
        None if stop.load(Ordering::Relaxed) != 0 => (Err(NOT_STARTED.into()), false, false),
        None => {
            let mut bar = display.start(k, end_milli_tc(case));
            match run_case(case, &dir, every, stop, &mut bar) {
                Ok((o, resumed)) => (Ok(o), false, resumed),
                Err(e) => (Err(format!("{e:#}")), false, false),
            }
        }
    };
    display.finish(k, &outcome, reused);
    CaseResult {
        case: case.clone(),
        dir,
        outcome,
        reused,
        resumed,
    }
}

/// The outcome of a case that a stopped sweep never started.
const NOT_STARTED: &str = "not started: the sweep was stopped";

/// The sweep of `path`, every case checked (a bad value fails the sweep before anything
/// runs), and its output folder `out` created.
fn prepare(path: &Path, out: &Path) -> Result<(SweepSpec, Vec<Case>)> {
    let (spec, cases) = read_sweep(path)?;
    for case in &cases {
        case.check()?;
    }
    crate::io::run_dir::create(out)?;
    Ok((spec, cases))
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
    let (spec, cases) = prepare(path, out)?;
    let display = progress::Display::new(&cases);
    let results: Mutex<Vec<Option<CaseResult>>> = Mutex::new(vec![None; cases.len()]);
    let work = || {
        (0..cases.len())
            .into_par_iter()
            .with_max_len(1)
            .for_each(|k| {
                let r = run_case_in(&cases, k, out, every, &stop, &display);
                results.lock().expect("no panic while holding the lock")[k] = Some(r);
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
    let results = results
        .into_inner()
        .expect("no panic while holding the lock");
    gather(path, out, (spec, cases), results, &stop)
}

/// The results of the sweep `path` (its spec and cases as read) written out: `sweep.csv`,
/// `fits.json` and the figures, or, when `stop` was set, the interruption with the command
/// that continues it. A case without a result never started.
fn gather(
    path: &Path,
    out: &Path,
    (spec, cases): (SweepSpec, Vec<Case>),
    results: Vec<Option<CaseResult>>,
    stop: &AtomicUsize,
) -> Result<SweepReport> {
    let cases: Vec<CaseResult> = results
        .into_iter()
        .zip(cases)
        .map(|(r, case)| {
            r.unwrap_or_else(|| CaseResult {
                dir: out.join(&case.name),
                case,
                outcome: Err(NOT_STARTED.into()),
                reused: false,
                resumed: false,
            })
        })
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

/// The case of `cases` that `which` names: its index in [`spec::expand`]'s order (from 0, as
/// `granflow sweep --list` numbers them and a job array's task id counts) or its name.
pub fn find_case(cases: &[Case], which: &str) -> Result<usize> {
    if let Ok(k) = which.parse::<usize>() {
        return if k < cases.len() {
            Ok(k)
        } else {
            Err(Error::config(
                "--case",
                format!(
                    "the sweep has {} cases, numbered 0 to {}; {k} is not one",
                    cases.len(),
                    cases.len().saturating_sub(1)
                ),
            ))
        };
    }
    cases.iter().position(|c| c.name == which).ok_or_else(|| {
        Error::config(
            "--case",
            format!("no case is named `{which}` (`granflow sweep FILE --list` lists them)"),
        )
    })
}

/// Runs one case of the sweep of `path` (see [`find_case`]) into its folder under `out`, as
/// a job of a scheduler's array does: the same folder, reuse and checkpoints as a whole
/// sweep, and nothing written outside the case's folder but `out`'s run-folder marker. A
/// later `granflow sweep` of the same file and `out` reuses the case (and runs any still
/// missing) and writes the tables.
pub fn run_one_case(
    path: &Path,
    out: &Path,
    which: &str,
    every: Option<f64>,
    stop: Arc<AtomicUsize>,
) -> Result<CaseResult> {
    let (_, cases) = read_sweep(path)?;
    let k = find_case(&cases, which)?;
    cases[k].check()?;
    crate::io::run_dir::create(out)?;
    let display = progress::Display::new(&cases);
    let r = run_case_in(&cases, k, out, every, &stop, &display);
    let signal = stop.load(Ordering::Relaxed);
    if signal != 0 {
        return Err(Error::Interrupted {
            signal: signal as i32,
            at: format!("in case {}", r.case.name),
            saved: r.dir,
            resume: format!(
                "granflow sweep {} --out {} --case {which}",
                path.display(),
                out.display()
            ),
        });
    }
    Ok(r)
}

/// Where each case of a sweep stands in `out`: done (a complete summary of the same resolved
/// scenario), stopped part-way (checkpoints of it) or not run.
pub fn case_states(cases: &[Case], out: &Path) -> Vec<&'static str> {
    cases
        .iter()
        .map(|case| {
            let dir = out.join(&case.name);
            let same = std::fs::read_to_string(dir.join(SCENARIO_FILE))
                .ok()
                .as_ref()
                == Some(&case.scenario);
            if reusable(case, &dir).is_some() {
                "done"
            } else if same && checkpoint::list(&dir).is_ok_and(|l| !l.is_empty()) {
                "stopped"
            } else {
                "not run"
            }
        })
        .collect()
}
