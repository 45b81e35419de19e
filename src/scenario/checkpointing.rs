//! How a run saves its state and continues from it: `--checkpoint-every`, `granflow resume`
//! and the stop that SIGINT/SIGTERM ask for.
//!
//! A runner asks its [`Control`] at each step boundary whether a checkpoint is due
//! ([`Control::due`]) or a stop was asked for ([`Control::stop_signal`]); it saves what it
//! needs to continue — the solvers' state and its own output bookkeeping (frames written, bytes
//! of the time series, running sums) — with [`Control::save`], and on resume gets it back
//! with [`Control::load`]. The scenario text the run was started with is copied into the
//! output folder ([`SCENARIO_COPY`]), and a checkpoint holds its hash, so that a resumed run
//! is the same run.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use serde::de::DeserializeOwned;
use serde::Serialize;

use super::Kind;
use crate::io::checkpoint::{self, Header, Loaded};
use crate::{Error, Result};

/// The copy of the scenario text a run keeps in its output folder (what `resume` runs).
pub const SCENARIO_COPY: &str = "scenario.toml";

/// How a run checkpoints, stops and resumes.
#[derive(Clone, Debug, Default)]
pub struct Control {
    /// Simulated seconds between checkpoints; `None`: a checkpoint only when stopped.
    pub every: Option<f64>,
    /// [`checkpoint::scenario_hash`] of the scenario text.
    pub scenario_hash: u64,
    /// A signal's number (SIGINT 2, SIGTERM 15) once a stop has been asked for, 0 before: the
    /// run stops at its next step boundary with a checkpoint and the current frame.
    pub stop: Arc<AtomicUsize>,
    /// Continue from the newest checkpoint in the output folder rather than start.
    pub resume: bool,
}

impl Control {
    /// A run of the scenario `text` that checkpoints every `every` simulated seconds (if
    /// given) and stops when `stop` is set.
    pub fn new(text: &str, every: Option<f64>, stop: Arc<AtomicUsize>) -> Result<Self> {
        if let Some(e) = every {
            if !(e.is_finite() && e > 0.0) {
                return Err(Error::config(
                    "--checkpoint-every",
                    format!("{e} s: must be a positive number of simulated seconds"),
                ));
            }
        }
        Ok(Control {
            every,
            scenario_hash: checkpoint::scenario_hash(text),
            stop,
            resume: false,
        })
    }

    /// The signal that asked the run to stop, if one has.
    pub fn stop_signal(&self) -> Option<i32> {
        match self.stop.load(Ordering::Relaxed) {
            0 => None,
            s => Some(s as i32),
        }
    }

    /// Steps between checkpoints for a step of `dt` seconds: ⌈every/dt⌉, at least 1.
    pub fn every_steps(&self, dt: f64) -> Option<u64> {
        self.every
            .map(|e| ((e / dt) * (1.0 - 1e-9)).ceil().max(1.0) as u64)
    }

    /// Is a checkpoint due after step `step`, with steps of `dt` seconds?
    pub fn due(&self, step: u64, dt: f64) -> bool {
        self.every_steps(dt).is_some_and(|k| step.is_multiple_of(k))
    }

    /// Save `state` of a `kind` run at `step` and `time` into `dir`.
    pub fn save<S: Serialize>(
        &self,
        dir: &Path,
        kind: Kind,
        step: u64,
        time: f64,
        state: &S,
    ) -> Result<PathBuf> {
        let header = Header::new(kind.name(), self.scenario_hash, step, time, self.every);
        checkpoint::write(dir, &header, state)
    }

    /// The newest usable checkpoint of this `kind` run in `dir` if the run resumes (`None`
    /// when it starts afresh); the resumed run keeps checkpointing at the period it was
    /// started with. Damaged newer checkpoints passed over are reported on stderr.
    pub fn load<S: DeserializeOwned>(
        &mut self,
        dir: &Path,
        kind: Kind,
    ) -> Result<Option<Loaded<S>>> {
        if !self.resume {
            return Ok(None);
        }
        let loaded = checkpoint::read_latest(dir, kind.name(), self.scenario_hash)?;
        for s in &loaded.skipped {
            eprintln!("warning: passed over a damaged checkpoint: {s}");
        }
        eprintln!(
            "resuming from {} (step {}, t = {:.6e} s)",
            loaded.path.display(),
            loaded.header.step,
            loaded.header.time
        );
        self.every = loaded.header.every;
        Ok(Some(loaded))
    }

    /// The error that ends a run in `out` whose output could not be written (e.g. a full
    /// disk): what failed, the last complete frame (`frame`, a file name) and the last
    /// checkpoint, from which `granflow resume` continues once the output can be written
    /// again. Errors other than failed writes are returned as they are.
    pub fn write_failed(
        &self,
        e: Error,
        out: &Path,
        frame: Option<&str>,
        checkpoint: Option<&Path>,
    ) -> Error {
        if !matches!(e, Error::Io { .. }) {
            return e;
        }
        let frame = frame.map_or("none".into(), |f| out.join(f).display().to_string());
        let resume = match checkpoint {
            Some(c) => format!(
                "the last checkpoint is {}: free some space, then `granflow resume {}`",
                c.display(),
                out.display()
            ),
            None => "no checkpoint was written yet (see --checkpoint-every)".into(),
        };
        Error::Output {
            path: out.to_path_buf(),
            reason: format!("{e}; the last complete frame is {frame}, {resume}"),
        }
    }

    /// The error that ends a run in `out` stopped by `signal` at `step` and `time` after
    /// saving `checkpoint`.
    pub fn interrupted(
        &self,
        signal: i32,
        step: u64,
        time: f64,
        checkpoint: PathBuf,
        out: &Path,
    ) -> Error {
        Error::Interrupted {
            signal,
            at: format!("at step {step} (t = {time:.6e} s)"),
            saved: checkpoint,
            resume: format!("granflow resume {}", out.display()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checkpoints_fall_on_whole_steps_and_a_bad_period_is_refused() {
        let c = Control::new("kind = \"fluid\"", Some(0.25), Arc::default()).unwrap();
        assert_eq!(c.every_steps(0.1), Some(3));
        assert!(c.due(6, 0.1) && !c.due(7, 0.1));
        assert_eq!(c.every_steps(1.0), Some(1));
        let e = Control::new("", Some(-1.0), Arc::default()).unwrap_err();
        assert!(e.to_string().contains("--checkpoint-every"), "{e}");
        assert_eq!(Control::default().every_steps(0.1), None);
    }
}
