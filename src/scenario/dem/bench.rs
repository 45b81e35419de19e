//! `granflow bench dem`: the LAMMPS peer case `in.gran2d.lmp` (docs/performance.md), so
//! granflow and LAMMPS's `gran/hooke/history` are timed on the same run.
//!
//! Reduced (LJ) units: a hex-packed block of ≈ N disks (√N × √N, nearest-neighbour spacing 1),
//! diameters uniform in [0.8, 1.0], density 1 with LAMMPS's mass convention for `set density`
//! in 2-D (m = ρ·4/3 π r³, a sphere's mass) and a disk's inertia J = ½ m r² (`nve/sphere disc`),
//! centred in a box of width W = 2√N with frictional walls at x = 0, x = W and a floor at y = 0;
//! k_n = 2000, k_t = 2/7 k_n, γ_n = 50, γ_t = γ_n/2 (LAMMPS's `NULL` defaults), μ = 0.5, e = 1
//! (all normal damping from γ_n, as LAMMPS), no rolling resistance, gravity 1, Δt = 0.001,
//! Verlet skin 0.2 (LAMMPS's `neighbor 0.2 bin`, checked every step). Each repeat builds a
//! fresh block (seed + repeat), runs 500 warm-up steps (as `peers/lammps.sh`) and times
//! `steps` steps; the median of the repeats is reported.

use std::time::Instant;

use serde::Serialize;

use crate::dem::contact::ContactParams;
use crate::dem::packing::{hex_block, SizeDistribution};
use crate::dem::walls::Wall;
use crate::dem::{Dem, DemParams};
use crate::{Error, Result};

/// Warm-up steps before timing (as `peers/lammps.sh`: `-var warm 500`).
pub const WARM_STEPS: u64 = 500;

/// Result of `granflow bench dem`.
#[derive(Clone, Debug, Serialize)]
pub struct DemBench {
    /// Grain-steps per second (median of the repeats).
    pub particle_steps_per_s: f64,
    /// Mean number of touching pairs (grain–grain and grain–wall) per timed step.
    pub contacts_per_step: f64,
    /// Grains.
    pub grains: usize,
    /// Timed steps per repeat.
    pub steps: u64,
    /// Threads used.
    pub threads: usize,
    /// Neighbour-list builds per timed step.
    pub list_builds_per_step: f64,
    /// particle_steps_per_s of every repeat.
    pub samples: Vec<f64>,
}

/// The LAMMPS contact law of `in.gran2d.lmp` (`gran/hooke/history 2000 NULL 50 NULL 0.5 1`).
fn lammps_law() -> ContactParams {
    ContactParams {
        k_n: 2000.0,
        k_t: 2.0 / 7.0 * 2000.0,
        restitution: 1.0,
        gamma_n: 50.0,
        gamma_t: 25.0,
        friction: 0.5,
        rolling_stiffness: 0.0,
        rolling_damping: 0.0,
        rolling_friction: 0.0,
    }
}

/// The benchmark system: ≈ `n` grains (side ⌈√n⌉ × ⌈n/side⌉) from `seed`.
pub fn system(n: usize, seed: u64) -> Result<Dem> {
    let nx = (n as f64).sqrt().round().max(1.0) as usize;
    let ny = n.div_ceil(nx);
    let mut g = hex_block(
        0.5 * nx as f64 + 1.0,
        0.5 + 3f64.sqrt() / 2.0,
        nx,
        ny,
        1.0,
        [0.8, 1.0],
        SizeDistribution::Uniform,
        1.0,
        seed,
    );
    for k in 0..g.len() {
        let r = g.radius[k];
        g.mass[k] = 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        g.inertia[k] = 0.5 * g.mass[k] * r * r;
    }
    let w = 2.0 * nx as f64;
    let law = lammps_law();
    let mut p = DemParams::new(law, law, [0.0, -1.0]);
    p.dt = Some(1e-3);
    p.skin_fraction = 0.2 / 1.0; // skin = 0.2 (fraction of d_max = 1.0)
    Dem::new(
        g,
        vec![Wall::floor(0.0), Wall::left(0.0), Wall::right(w)],
        p,
    )
}

/// Run the DEM benchmark on `threads` threads (0: rayon's default).
pub fn run(grains: usize, steps: u64, threads: usize, repeats: usize) -> Result<DemBench> {
    if grains < 2 || steps == 0 || repeats == 0 {
        return Err(Error::Other(
            "bench dem: need grains ≥ 2 and steps, repeats ≥ 1".into(),
        ));
    }
    crate::exec::on_threads(threads, || {
        let mut samples = Vec::with_capacity(repeats);
        let (mut contacts, mut builds, mut n) = (0.0, 0.0, 0);
        for r in 0..repeats {
            let mut dem = system(grains, 12345 + r as u64)?;
            n = dem.grains.len();
            dem.steps(WARM_STEPS);
            let (b0, c0) = (dem.list_builds(), dem.contact_steps());
            let t0 = Instant::now();
            dem.steps(steps);
            let secs = t0.elapsed().as_secs_f64();
            let c = dem.contact_steps() - c0;
            samples.push(n as f64 * steps as f64 / secs);
            contacts += c as f64 / steps as f64;
            builds += (dem.list_builds() - b0) as f64 / steps as f64;
            if let Some(i) = (0..n).find(|&i| !dem.grains.y[i].is_finite()) {
                return Err(Error::Other(format!(
                    "bench dem went unstable: grain {i} has a non-finite position"
                )));
            }
        }
        let mut sorted = samples.clone();
        Ok(DemBench {
            particle_steps_per_s: crate::exec::median(&mut sorted),
            contacts_per_step: contacts / repeats as f64,
            grains: n,
            steps,
            threads: rayon::current_num_threads(),
            list_builds_per_step: builds / repeats as f64,
            samples,
        })
    })
}
