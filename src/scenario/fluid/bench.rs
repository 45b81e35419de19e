//! Throughput benchmarks behind `granflow bench`.
//!
//! `lbm`: a fully periodic N_x × N_y box (a decaying shear wave, so the populations are not
//! trivial) timed over S steps, median of `repeats`; beside it, in the same process and with
//! the same threads, a parallel copy of an array as large as the populations, so the fraction
//! of the memory-bandwidth roofline is measured on the machine at hand. A D2Q9 step moves at
//! least 9 populations in and out: 72 B/cell in f32, 144 B/cell in f64. Copy bandwidth counts
//! read + write bytes (as STREAM does).

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::exec::{median, on_threads};
use crate::lbm::{CollisionModel, Edges, FluidModel, Lattice, Lbm, MrtRates, Obstacles, Real};
use crate::units::Units;
use crate::{Error, Result};

/// Result of `granflow bench lbm`.
#[derive(Clone, Debug, Serialize)]
pub struct LbmBench {
    /// Million lattice-cell updates per second (median of the repeats).
    pub mlups: f64,
    /// Minimum bytes moved per cell update (9 populations read and written).
    pub bytes_per_cell: usize,
    /// Measured parallel copy bandwidth in GB/s (read + write).
    pub copy_gb_s: f64,
    /// mlups · bytes_per_cell / copy bandwidth.
    pub roofline_fraction: f64,
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Steps per repeat.
    pub steps: u64,
    /// Threads used.
    pub threads: usize,
    /// `"f32"` or `"f64"`.
    pub precision: String,
    /// `"bgk"` or `"mrt"`.
    pub collision: String,
    /// MLUPS of every repeat.
    pub samples: Vec<f64>,
}

fn time_lbm<T: Real>(
    nx: usize,
    ny: usize,
    steps: u64,
    mrt: bool,
    repeats: usize,
) -> Result<Vec<f64>> {
    let mut lat =
        Lattice::<T>::new(nx, ny, Edges::periodic(), vec![false; nx * ny]).map_err(Error::Other)?;
    let k = 2.0 * std::f64::consts::PI / ny as f64;
    lat.fill(|_, y| (1.0, 0.05 * (k * (y as f64 + 0.5)).sin(), 0.0));
    let tau = 0.6;
    let model = if mrt {
        CollisionModel::Mrt(MrtRates::standard(tau))
    } else {
        CollisionModel::Bgk
    };
    let mut lbm = Lbm::new(
        lat,
        FluidModel {
            collision: model,
            smagorinsky: None,
            body_force: [0.0; 2],
        },
        Obstacles::default(),
        Units::lattice(tau),
    );
    lbm.step();
    lbm.step();
    let mut out = Vec::new();
    for _ in 0..repeats {
        let t0 = Instant::now();
        for _ in 0..steps {
            lbm.step();
        }
        out.push((nx * ny) as f64 * steps as f64 / t0.elapsed().as_secs_f64() / 1e6);
    }
    if let Some((c, why)) = lbm.find_instability(0.5) {
        return Err(Error::Other(format!(
            "benchmark went unstable at cell {c}: {why}"
        )));
    }
    Ok(out)
}

/// Parallel copy bandwidth (GB/s, read + write) of two arrays of `bytes` each; best of 5.
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

/// Run the LBM benchmark on `threads` threads (0: rayon's default).
pub fn lbm(
    nx: usize,
    ny: usize,
    steps: u64,
    f64_: bool,
    mrt: bool,
    threads: usize,
    repeats: usize,
) -> Result<LbmBench> {
    if nx < 3 || ny < 3 || steps == 0 || repeats == 0 {
        return Err(Error::Other(
            "bench lbm: need nx, ny ≥ 3 and steps, repeats ≥ 1".into(),
        ));
    }
    on_threads(threads, || {
        let elem = if f64_ { 8 } else { 4 };
        let copy_gb_s = copy_bandwidth(9 * nx * ny * elem);
        let mut samples = if f64_ {
            time_lbm::<f64>(nx, ny, steps, mrt, repeats)?
        } else {
            time_lbm::<f32>(nx, ny, steps, mrt, repeats)?
        };
        let all = samples.clone();
        let mlups = median(&mut samples);
        let bytes_per_cell = 18 * elem;
        Ok(LbmBench {
            mlups,
            bytes_per_cell,
            copy_gb_s,
            roofline_fraction: mlups * 1e6 * bytes_per_cell as f64 / (copy_gb_s * 1e9),
            nx,
            ny,
            steps,
            threads: rayon::current_num_threads(),
            precision: if f64_ { "f64" } else { "f32" }.into(),
            collision: if mrt { "mrt" } else { "bgk" }.into(),
            samples: all,
        })
    })
}
