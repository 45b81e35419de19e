//! Execution helpers shared by the solvers and the runners: progress callbacks, thread pools,
//! the median of timed repeats and the memory a run may take.

pub mod machine;
pub mod simd;

use crate::{Error, Result};

/// Progress callback: (work done, work total), in whatever unit the caller reports (steps,
/// thousandths of τ_c, points of a test).
pub type Progress<'a> = &'a mut dyn FnMut(u64, u64);

/// Progress of a phase whose end cannot be foreseen (settling to rest): [`Heartbeat::due`] is
/// true once every 15 s of wall time, when the caller prints a line of where it stands.
pub struct Heartbeat(std::time::Instant);

impl Heartbeat {
    /// Interval between lines.
    pub const EVERY: std::time::Duration = std::time::Duration::from_secs(15);

    /// A heartbeat whose first line is due 15 s from now.
    pub fn new() -> Self {
        Heartbeat(std::time::Instant::now())
    }

    /// Whether a line is due (and, if so, the next one 15 s later).
    pub fn due(&mut self) -> bool {
        let due = self.0.elapsed() >= Self::EVERY;
        if due {
            self.0 = std::time::Instant::now();
        }
        due
    }
}

impl Default for Heartbeat {
    fn default() -> Self {
        Self::new()
    }
}

/// Median of `v` (sorted in place; the upper one of the middle two for an even count).
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Run `f` in a rayon pool of `threads` threads (0: rayon's default, all cores).
pub fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> Result<R> + Send) -> Result<R> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Other(format!("thread pool: {e}")))?
        .install(f)
}

/// Σ_{i < n} f(i), in parallel yet the same to the last bit at every run and on any number of
/// threads: 0..n is cut into fixed chunks of `chunk`, each summed in index order, and the
/// chunk sums are added in order ([`add_in_order`]). A rayon `sum`/`reduce` splits the work as
/// threads steal it, so its rounding varies from run to run; a diagnostic that is written
/// out, or a budget that accumulates over steps, must not (a resumed run repeats an
/// uninterrupted one bit for bit).
pub fn ordered_sum<const N: usize>(
    n: usize,
    chunk: usize,
    f: impl Fn(usize) -> [f64; N] + Sync,
) -> [f64; N] {
    use rayon::prelude::*;
    let parts: Vec<[f64; N]> = (0..n.div_ceil(chunk.max(1)))
        .into_par_iter()
        .map(|c| {
            let end = ((c + 1) * chunk).min(n);
            add_in_order((c * chunk..end).map(&f))
        })
        .collect();
    add_in_order(parts)
}

/// The sum of `parts` in their order, component by component.
pub fn add_in_order<const N: usize>(parts: impl IntoIterator<Item = [f64; N]>) -> [f64; N] {
    parts.into_iter().fold([0.0; N], |mut a, p| {
        for (a, p) in a.iter_mut().zip(p) {
            *a += p;
        }
        a
    })
}

/// Memory the machine can give a new process now (bytes): `MemAvailable` of `/proc/meminfo`;
/// `None` where that is not known (not Linux).
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Refuses a run whose estimated peak memory `need` (bytes) exceeds what the machine has
/// available, naming both.
pub fn check_memory(need: u64) -> Result<()> {
    match available_memory() {
        Some(have) if need > have => Err(crate::Error::config(
            "memory",
            format!(
                "the run needs about {:.1} GiB at its peak and this machine has {:.1} GiB \
                 available: use a coarser grid or fewer grains, or a larger machine",
                need as f64 / GIB,
                have as f64 / GIB
            ),
        )),
        _ => Ok(()),
    }
}

/// `about N MiB at the peak (M MiB available)`: an estimated peak beside what the machine has.
pub fn memory_line(need: usize) -> String {
    let mib = |b: f64| b / (1u64 << 20) as f64;
    let have = available_memory().map_or(String::new(), |a| {
        format!(" ({:.0} MiB available)", mib(a as f64))
    });
    format!("about {:.0} MiB at the peak{have}", mib(need as f64))
}

/// Bytes in a GiB.
pub const GIB: f64 = (1u64 << 30) as f64;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_ordered_sum_is_the_same_on_any_number_of_threads() {
        // Terms of very different sizes, so that another order would round differently.
        let f = |i: usize| [1.0 / (i as f64 + 1.0), (i as f64).sin() * 1e8];
        let serial = add_in_order((0..100_000).map(f));
        let on = |threads| on_threads(threads, || Ok(ordered_sum(100_000, 100_000, f))).unwrap();
        assert_eq!(on(1), serial);
        assert_eq!(on(2), serial);
        let small = |threads| on_threads(threads, || Ok(ordered_sum(100_000, 512, f))).unwrap();
        assert_eq!(small(1), small(3));
        assert!((small(2)[0] - serial[0]).abs() < 1e-12 * serial[0]);
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 3.0);
    }
}
