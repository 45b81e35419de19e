//! The machine a benchmark ran on, so that figures from different machine kinds are never
//! mixed up: the CPU's model, its logical CPUs, the threads used and the measured copy
//! bandwidth (the memory roofline of a streaming kernel).

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

/// Bytes of each array of the copy measurement in [`Machine::measure`]: far beyond any
/// cache, so that the copy runs at memory speed.
const COPY_BYTES: usize = 256 << 20;

/// What `granflow bench` reports of the machine beside its figures.
#[derive(Clone, Debug, Serialize)]
pub struct Machine {
    /// The CPU's model name (`/proc/cpuinfo`), or `unknown`.
    pub cpu_model: String,
    /// Logical CPUs this process may run on.
    pub logical_cpus: usize,
    /// Threads of the rayon pool the measurement (and the benchmark) ran on.
    pub threads: usize,
    /// Parallel copy bandwidth (GB/s, read + write) on those threads ([`copy_bandwidth`]).
    pub copy_gb_s: f64,
}

impl Machine {
    /// Reads the CPU's model and measures the copy bandwidth on the current rayon pool.
    pub fn measure() -> Self {
        Machine {
            cpu_model: cpu_model().unwrap_or_else(|| "unknown".into()),
            logical_cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
            threads: rayon::current_num_threads(),
            copy_gb_s: copy_bandwidth(COPY_BYTES),
        }
    }
}

impl std::fmt::Display for Machine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}, {} logical CPUs; copy {:.1} GB/s on {} threads",
            self.cpu_model, self.logical_cpus, self.copy_gb_s, self.threads
        )
    }
}

/// The first `model name` of `/proc/cpuinfo` (Linux).
fn cpu_model() -> Option<String> {
    let text = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    text.lines()
        .find_map(|l| l.strip_prefix("model name")?.split_once(':'))
        .map(|(_, m)| m.trim().to_string())
}

/// Parallel copy bandwidth (GB/s, read + write) of two arrays of `bytes` each (at least
/// 8 MiB); best of 5.
pub fn copy_bandwidth(bytes: usize) -> f64 {
    let n = (bytes / 8).max(1 << 20);
    let src = vec![1.0f64; n];
    let mut dst = vec![0.0f64; n];
    let chunk = n.div_ceil(rayon::current_num_threads() * 4);
    let mut best: f64 = 0.0;
    for _ in 0..5 {
        let t0 = Instant::now();
        dst.par_chunks_mut(chunk)
            .zip(src.par_chunks(chunk))
            .for_each(|(d, s)| d.copy_from_slice(s));
        let dt = t0.elapsed().as_secs_f64();
        best = best.max(2.0 * (n * 8) as f64 / dt / 1e9);
    }
    std::hint::black_box(&dst);
    best
}
