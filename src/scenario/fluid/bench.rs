//! Throughput benchmarks behind `granflow bench`.
//!
//! `lbm`: a fully periodic N_x × N_y box (a decaying shear wave, so the populations are not
//! trivial) timed over S steps, median of `repeats`; beside it, in the same process and with
//! the same threads, a parallel copy of an array as large as the populations, so the fraction
//! of the memory-bandwidth roofline is measured on the machine at hand. A D2Q9 step moves at
//! least 9 populations in and out: 72 B/cell in f32, 144 B/cell in f64. Copy bandwidth counts
//! read + write bytes (as STREAM does). On the GPU back end (`--backend gpu`) the same box
//! steps on the device, timed from submission to completion, and the roofline is the device's
//! own buffer-to-buffer copy of as many bytes.

use std::time::Instant;

use serde::Serialize;

use crate::exec::machine::copy_bandwidth;
use crate::exec::{median, on_threads};
use crate::lbm::{
    Backend, CollisionModel, Edges, Fluid, FluidModel, Lattice, Lbm, MrtRates, Obstacles, Real,
};
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
    /// `"cpu"` or `"gpu"`.
    pub backend: String,
    /// The GPU adapter (GPU back end only).
    pub device: Option<String>,
}

/// What `granflow bench lbm` times: a periodic `nx × ny` box for `steps` steps per repeat.
#[derive(Clone, Copy, Debug)]
pub struct LbmCase {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Steps per repeat.
    pub steps: u64,
    /// f64 populations (else f32).
    pub f64: bool,
    /// MRT collision (else BGK).
    pub mrt: bool,
    /// Where the lattice steps.
    pub backend: Backend,
}

/// The benchmark's fluid: a decaying shear wave in a periodic box.
fn shear_wave<T: Real>(case: &LbmCase) -> Result<Lbm<T>> {
    let (nx, ny) = (case.nx, case.ny);
    let mut lat =
        Lattice::<T>::new(nx, ny, Edges::periodic(), vec![false; nx * ny]).map_err(Error::Other)?;
    let k = 2.0 * std::f64::consts::PI / ny as f64;
    lat.fill(|_, y| (1.0, 0.05 * (k * (y as f64 + 0.5)).sin(), 0.0));
    let tau = 0.6;
    let model = if case.mrt {
        CollisionModel::Mrt(MrtRates::standard(tau))
    } else {
        CollisionModel::Bgk
    };
    Ok(Lbm::new(
        lat,
        FluidModel {
            collision: model,
            smagorinsky: None,
            body_force: [0.0; 2],
        },
        Obstacles::default(),
        Units::lattice(tau),
    ))
}

/// MLUPS of each repeat of `case.steps` steps on `fluid`, timed to their completion
/// ([`Fluid::finish`]), after two warm-up steps; the run must stay stable.
fn time_steps(case: &LbmCase, repeats: usize, fluid: &mut dyn Fluid) -> Result<Vec<f64>> {
    let run = |fluid: &mut dyn Fluid, n| {
        fluid.steps(n);
        fluid.finish();
    };
    run(fluid, 2);
    let mut out = Vec::new();
    for _ in 0..repeats {
        let t0 = Instant::now();
        run(fluid, case.steps);
        let cells = (case.nx * case.ny) as f64;
        out.push(cells * case.steps as f64 / t0.elapsed().as_secs_f64() / 1e6);
    }
    fluid.check_stable(0.5)?;
    Ok(out)
}

/// MLUPS of each repeat on the CPU, and the copy bandwidth beside it.
fn time_cpu<T: Real>(case: &LbmCase, repeats: usize) -> Result<(Vec<f64>, f64, Option<String>)> {
    let copy = copy_bandwidth(9 * case.nx * case.ny * std::mem::size_of::<T>());
    let mut lbm = shear_wave::<T>(case)?;
    let samples = time_steps(case, repeats, &mut lbm)?;
    Ok((samples, copy, None))
}

/// MLUPS of each repeat on the GPU, the device's copy bandwidth and its name.
#[cfg(feature = "gpu")]
fn time_gpu(case: &LbmCase, repeats: usize) -> Result<(Vec<f64>, f64, Option<String>)> {
    use crate::lbm::gpu::{Gpu, GpuFluid};
    fn on<T: Real>(
        gpu: Gpu,
        case: &LbmCase,
        repeats: usize,
    ) -> Result<(Vec<f64>, f64, Option<String>)> {
        let copy = gpu.copy_bandwidth(9 * case.nx * case.ny * std::mem::size_of::<T>());
        let mut fluid = GpuFluid::new(&gpu, shear_wave::<T>(case)?).map_err(Error::Other)?;
        let samples = time_steps(case, repeats, &mut fluid)?;
        Ok((samples, copy, Some(gpu.name)))
    }
    let gpu = Gpu::new().map_err(Error::Other)?;
    if case.f64 {
        on::<f64>(gpu, case, repeats)
    } else {
        on::<f32>(gpu, case, repeats)
    }
}

#[cfg(not(feature = "gpu"))]
fn time_gpu(_: &LbmCase, _: usize) -> Result<(Vec<f64>, f64, Option<String>)> {
    Err(Error::Other(crate::lbm::backend::NOT_BUILT.into()))
}

/// Run the LBM benchmark of `case` on `threads` threads (0: rayon's default).
pub fn lbm(case: LbmCase, threads: usize, repeats: usize) -> Result<LbmBench> {
    let (nx, ny, steps) = (case.nx, case.ny, case.steps);
    if nx < 3 || ny < 3 || steps == 0 || repeats == 0 {
        return Err(Error::Other(
            "bench lbm: need nx, ny ≥ 3 and steps, repeats ≥ 1".into(),
        ));
    }
    on_threads(threads, || {
        let (mut samples, copy_gb_s, device) = match (case.backend, case.f64) {
            (Backend::Cpu, false) => time_cpu::<f32>(&case, repeats)?,
            (Backend::Cpu, true) => time_cpu::<f64>(&case, repeats)?,
            (Backend::Gpu, _) => time_gpu(&case, repeats)?,
        };
        let all = samples.clone();
        let mlups = median(&mut samples);
        let bytes_per_cell = 18 * if case.f64 { 8 } else { 4 };
        Ok(LbmBench {
            mlups,
            bytes_per_cell,
            copy_gb_s,
            roofline_fraction: mlups * 1e6 * bytes_per_cell as f64 / (copy_gb_s * 1e9),
            nx,
            ny,
            steps,
            threads: rayon::current_num_threads(),
            precision: if case.f64 { "f64" } else { "f32" }.into(),
            collision: if case.mrt { "mrt" } else { "bgk" }.into(),
            samples: all,
            backend: case.backend.name().into(),
            device,
        })
    })
}
