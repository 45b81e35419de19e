//! Progress of a sweep: on a terminal one indicatif bar per running case (a multi-line
//! display), otherwise plain lines (a case starting, each 25 % of it, and its end).

use std::io::IsTerminal;

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};

use super::Case;
use crate::analysis::runout::CollapseOutcome;

/// The progress display of one sweep.
pub struct Display {
    multi: Option<MultiProgress>,
    names: Vec<String>,
}

impl Display {
    /// A display for `cases` (bars on a terminal, lines otherwise).
    pub fn new(cases: &[Case]) -> Self {
        Display {
            multi: std::io::stderr().is_terminal().then(MultiProgress::new),
            names: cases.iter().map(|c| c.name.clone()).collect(),
        }
    }

    /// Case `k` starts: its progress callback, (milli-τ_c done, milli-τ_c at the end time).
    pub fn start(&self, k: usize, total: u64) -> impl FnMut(u64, u64) + '_ {
        let name = &self.names[k];
        let bar = self.multi.as_ref().map(|m| {
            let bar = m.add(ProgressBar::new(total));
            let template = format!(
                "{name:>24} {{elapsed_precise}} [{{bar:30}}] {{pos}}/{{len}} milli-τ_c, eta {{eta}}"
            );
            bar.set_style(ProgressStyle::with_template(&template).expect("valid template"));
            bar
        });
        if bar.is_none() {
            eprintln!("{name}: started");
        }
        let mut last = 0;
        move |i, n| match &bar {
            Some(b) => b.set_position(i),
            None => {
                let quarter = i * 4 / n.max(1);
                if quarter > last {
                    last = quarter;
                    eprintln!("{name}: {}% of the end time", quarter * 25);
                }
            }
        }
    }

    /// Case `k` ended (or was reused from an earlier run).
    pub fn finish(&self, k: usize, outcome: &Result<CollapseOutcome, String>, reused: bool) {
        let name = &self.names[k];
        let line = match outcome {
            Ok(o) => format!(
                "{name}: {}a = {:.3}, ΔL = {:.3}, H_f/L_i = {:.3}, spreading stopped at {:.2} τ_c ({:.0} s wall)",
                if reused { "reused, " } else { "done, " },
                o.aspect_ratio,
                o.delta_l,
                o.h_f_over_l_i,
                o.stop_time_tc,
                o.wall_time_s
            ),
            Err(e) => format!("{name}: FAILED: {e}"),
        };
        match &self.multi {
            Some(m) => {
                let _ = m.println(line);
            }
            None => eprintln!("{line}"),
        }
    }
}
