//! `granflow bench coupled`: throughput of the coupled LBM–DEM step.
//!
//! An `nx × ny` box (periodic in x, walls at the bottom and top) with `grains` disks on a
//! square grid of spacing s = √(nx·ny/N), radius 0.4 s (about half the cells covered, no
//! contacts at the start), density ratio 2.65 (quartz in water), without gravity and moving
//! with velocities up to 1 cm/s (lattice 0.033) in varied directions, spinning. Timed over
//! `steps` coupled steps after two warm-up steps; reports lattice updates per second (MLUPS),
//! grain steps per second (one per grain per coupled step, however many DEM sub-steps it
//! takes) and the wall time. With the lattice on a GPU (`--backend gpu`) each coupled step
//! uploads the covered cells and reads their forces back; the grains step on the CPU.

use std::time::Instant;

use serde::Serialize;

use crate::coupling::{Coupled, CoupledFluid, DiskCover, Grid};
use crate::dem::{ContactParams, Dem, DemParams, Grains};
use crate::lbm::{Backend, CollisionModel, Edges, FluidModel, Lattice, Lbm, Obstacles, Real};
use crate::units::Units;
use crate::{Error, Result};

/// Result of `granflow bench coupled`.
#[derive(Clone, Debug, Serialize)]
pub struct CoupledBench {
    /// Million lattice-cell updates per second.
    pub mlups: f64,
    /// Grain updates per second (grains × coupled steps / seconds).
    pub particle_steps_per_s: f64,
    /// Wall time of the timed steps (s).
    pub seconds: f64,
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Grains.
    pub grains: usize,
    /// Coupled steps timed.
    pub steps: u64,
    /// Covered (partially saturated) cells in the last step.
    pub covered_cells: usize,
    /// DEM sub-steps per fluid step.
    pub subcycles: u64,
    /// Threads.
    pub threads: usize,
    /// `"f32"` or `"f64"`.
    pub precision: String,
    /// Where the lattice stepped: `"cpu"` or `"gpu"`.
    pub backend: String,
}

/// What `granflow bench coupled` times.
#[derive(Clone, Copy, Debug)]
pub struct CoupledCase {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Grains.
    pub grains: usize,
    /// Coupled steps timed.
    pub steps: u64,
    /// f64 populations (else f32).
    pub f64: bool,
    /// Where the lattice steps.
    pub backend: Backend,
}

fn time<T: Real>(case: CoupledCase) -> Result<CoupledBench> {
    let CoupledCase {
        nx,
        ny,
        grains: n,
        steps,
        backend,
        ..
    } = case;
    let lat =
        Lattice::<T>::new(nx, ny, Edges::channel(), vec![false; nx * ny]).map_err(Error::Other)?;
    // SI: Δx = 0.1 mm, water, τ = 0.6.
    let (dx, nu, rho_f, rho_s) = (1e-4, 1e-6, 1000.0, 2650.0);
    let tau = 0.6;
    let units = Units::from_tau(dx, tau, nu, rho_f);
    let fluid = CoupledFluid::new(Lbm::new(
        lat,
        FluidModel {
            collision: CollisionModel::Bgk,
            smagorinsky: None,
            body_force: [0.0; 2],
        },
        Obstacles::default(),
        units,
    ))
    .on(backend)?;
    let s = ((nx * ny) as f64 / n as f64).sqrt();
    let per_row = ((nx as f64 / s).floor() as usize).max(1);
    let mut g = Grains::with_capacity(n);
    for k in 0..n {
        let (i, j) = (k % per_row, k / per_row);
        g.push_disk(
            (i as f64 + 0.5) * s * dx,
            (j as f64 + 0.5) * s * dx,
            0.4 * s * dx,
            rho_s,
        );
    }
    let params = DemParams::new(
        ContactParams::elastic(1e4),
        ContactParams::elastic(1e4),
        [0.0, 0.0],
    );
    let dem = Dem::new(g, Vec::new(), params)?;
    let grid = Grid {
        nx,
        ny,
        dx,
        periodic: [true, false],
    };
    let mut c = Coupled::new(fluid, dem, DiskCover::new(grid, 1.0)?);
    c.step()?;
    c.step()?;
    let t0 = Instant::now();
    for _ in 0..steps {
        c.step()?;
    }
    let seconds = t0.elapsed().as_secs_f64();
    crate::lbm::Fluid::check_stable(&*c.fluid.lbm(), 0.5)?;
    Ok(CoupledBench {
        mlups: (nx * ny) as f64 * steps as f64 / seconds / 1e6,
        particle_steps_per_s: n as f64 * steps as f64 / seconds,
        seconds,
        nx,
        ny,
        grains: n,
        steps,
        covered_cells: c.fluid.partial.len(),
        subcycles: c.last_subcycles,
        threads: rayon::current_num_threads(),
        precision: T::NAME.into(),
        backend: backend.name().into(),
    })
}

/// Run the coupled benchmark on `threads` threads (0: rayon's default).
pub fn coupled(case: CoupledCase, threads: usize) -> Result<CoupledBench> {
    let CoupledCase {
        nx,
        ny,
        grains,
        steps,
        ..
    } = case;
    if nx < 3 || ny < 3 || grains == 0 || steps == 0 {
        return Err(Error::Other(
            "bench coupled: need nx, ny ≥ 3 and grains, steps ≥ 1".into(),
        ));
    }
    if grains as f64 > (nx * ny) as f64 / 16.0 {
        return Err(Error::Other(format!(
            "bench coupled: {grains} grains in {nx}×{ny} cells leaves under 4 cells per grain \
             diameter; use fewer grains or more cells"
        )));
    }
    crate::exec::on_threads(threads, || {
        if case.f64 {
            time::<f64>(case)
        } else {
            time::<f32>(case)
        }
    })
}
