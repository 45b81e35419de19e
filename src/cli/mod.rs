//! The commands behind the `granflow` subcommands.
//!
//! * [`run`]: `check` and `run` of a scenario file of any kind (dispatched on its `kind`);
//! * [`study`]: `validate`, `sweep`, `biaxial`, `shear`;
//! * [`schema`]: the `schema` command;
//! * [`bench`]: the `bench` command.

pub mod bench;
pub mod run;
pub mod schema;
pub mod study;

use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize};
use std::sync::Arc;

/// Run `f` with a progress callback: an indicatif bar on a terminal, a plain line every 10 %
/// otherwise (logs, CI).
fn with_progress<R>(total: u64, unit: &str, f: impl FnOnce(&mut dyn FnMut(u64, u64)) -> R) -> R {
    if std::io::stderr().is_terminal() {
        let bar = indicatif::ProgressBar::new(total);
        let template =
            format!("{{elapsed_precise}} [{{bar:40}}] {{pos}}/{{len}} {unit}, eta {{eta}}");
        bar.set_style(indicatif::ProgressStyle::with_template(&template).expect("valid template"));
        let r = f(&mut |i, _| bar.set_position(i));
        bar.finish();
        r
    } else {
        let mut last = 0;
        // The pace is measured from the first report, so that a preparation before it (a
        // deposition) does not count as progress.
        let mut first: Option<(std::time::Instant, u64)> = None;
        f(&mut |i, n| {
            let (start, i0) = *first.get_or_insert((std::time::Instant::now(), i));
            let pct = i * 10 / n.max(1);
            if pct > last {
                last = pct;
                // The time left if the rest goes at the pace so far.
                let elapsed = start.elapsed().as_secs_f64();
                let left = elapsed * (n - i.min(n)) as f64 / (i - i0.min(i)).max(1) as f64;
                eprintln!(
                    "{i}/{n} {unit} ({}%), {elapsed:.0} s so far, about {left:.0} s left",
                    pct * 10
                );
            }
        })
    }
}

/// The flag SIGINT and SIGTERM set to their number from now on: a run that reads it stops at
/// its next step boundary, saves a checkpoint and exits with 128 + the number; a second signal
/// ends the process at once (the same exit code, nothing more saved).
fn stop_on_signals() -> std::io::Result<Arc<AtomicUsize>> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let stop = Arc::new(AtomicUsize::new(0));
    let asked = Arc::new(AtomicBool::new(false));
    for signal in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, Arc::clone(&asked))?;
        signal_hook::flag::register(signal, Arc::clone(&asked))?;
        signal_hook::flag::register_usize(signal, Arc::clone(&stop), signal as usize)?;
    }
    Ok(stop)
}

/// The output folder of a command that writes a run: `--out` and `--force`.
#[derive(Clone, Copy)]
pub struct Out<'a> {
    /// The folder.
    pub dir: &'a Path,
    /// Replace an earlier run in it.
    pub force: bool,
}

impl<'a> Out<'a> {
    /// The folder, once the machine is known to have the run's estimated peak memory
    /// `memory` (bytes, [`granflow::exec::check_memory`]) and the folder to take the run
    /// ([`granflow::io::run_dir::prepare`]: an earlier run in it refused, or deleted with
    /// `--force`); call it after the input has been checked, so that a refused input leaves
    /// an earlier run alone.
    fn claim(self, memory: usize) -> granflow::Result<&'a Path> {
        granflow::exec::check_memory(memory as u64)?;
        granflow::io::run_dir::prepare(self.dir, self.force)?;
        Ok(self.dir)
    }
}

/// Context for a run that failed part-way.
fn stopped(path: &Path, out: &Path) -> String {
    format!(
        "run of {} stopped; frames written so far are in {}",
        path.display(),
        out.display()
    )
}
