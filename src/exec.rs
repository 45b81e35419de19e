//! Execution helpers shared by the solvers and the runners: progress callbacks, thread pools
//! and the median of timed repeats.

use crate::{Error, Result};

/// Progress callback: (work done, work total), in whatever unit the caller reports (steps,
/// thousandths of τ_c, points of a test).
pub type Progress<'a> = &'a mut dyn FnMut(u64, u64);

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 3.0);
    }
}
