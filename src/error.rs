//! Library error type. The CLI wraps these with `anyhow` context.

use std::path::PathBuf;

/// Everything that can go wrong in the library, with enough context to act on.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scenario value is missing, out of range or inconsistent; `field` is its TOML path.
    #[error("invalid scenario: `{field}`: {reason}")]
    Config {
        /// Dotted TOML path of the offending field, e.g. `fluid.viscosity`.
        field: String,
        /// Why the value was refused.
        reason: String,
    },
    /// A file could not be parsed as a scenario.
    #[error("cannot parse scenario {path}: {message}")]
    Parse {
        /// The scenario file.
        path: PathBuf,
        /// The parser's message (it names the line and the field).
        message: String,
    },
    /// The simulation became unstable (NaN, non-positive density, Mach too high).
    #[error("unstable at step {step} (t = {time:.6e} s), cell ({x}, {y}): {reason}")]
    Unstable {
        /// Time step at which the check failed.
        step: u64,
        /// Simulated time in seconds.
        time: f64,
        /// Cell column.
        x: usize,
        /// Cell row.
        y: usize,
        /// What was wrong there.
        reason: String,
    },
    /// Reading or writing a file failed.
    #[error("i/o error on {path}: {source}")]
    Io {
        /// The file or folder involved.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The output folder cannot take the run (it holds an earlier run, is not a folder, is not
    /// writable); refused before the run starts.
    #[error("cannot write the run into {path} (--out): {reason}")]
    Output {
        /// The output folder.
        path: PathBuf,
        /// Why, and what to do instead.
        reason: String,
    },
    /// A run was asked to stop (SIGINT, SIGTERM) and stopped at a step boundary with its
    /// state saved.
    #[error(
        "stopped by {} {at}; its state is saved in {}: continue with `{resume}`",
        signal_name(*.signal),
        .saved.display()
    )]
    Interrupted {
        /// The signal's number (SIGINT 2, SIGTERM 15).
        signal: i32,
        /// Where it stopped, e.g. `at step 1200 (t = 1.5e-1 s)`.
        at: String,
        /// The checkpoint written, or the folder holding the checkpoints.
        saved: PathBuf,
        /// The command that continues it.
        resume: String,
    },
    /// Anything else, with a message.
    #[error("{0}")]
    Other(String),
}

/// `SIGINT`, `SIGTERM`, or `signal N` for another number.
pub fn signal_name(signal: i32) -> String {
    match signal {
        2 => "SIGINT".into(),
        15 => "SIGTERM".into(),
        n => format!("signal {n}"),
    }
}

/// Library result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// Shorthand for [`Error::Config`].
    pub fn config(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Config {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// The same error with a [`Error::Config`] field put inside `table` (`lambda` in `time`
    /// is `time.lambda`): a solver names its own parameter, the scenario says where it sits
    /// in the file. Other errors are returned unchanged.
    pub fn within(self, table: &str) -> Self {
        match self {
            Error::Config { field, reason } => Error::Config {
                field: format!("{table}.{field}"),
                reason,
            },
            other => other,
        }
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}
