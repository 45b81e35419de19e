//! `granflow bench rve`: the cost of the MPM×DEM material, per point per MPM step and per grain
//! per DEM sub-step.
//!
//! Set-up: the representative volume of an MPM scenario with `model = "rve"` is prepared once
//! (timed apart) and copied to `points` points; each repeat gives every point `steps` MPM
//! steps of the scenario's step Δt (the CFL step of the prepared packing, or `time.dt`) under a
//! simple shear at γ̇ = √(g/H_i) (the rate of a collapsing column, 1/τ_c) with the
//! column's mean pressure held by the packing, points advancing in parallel as in the MPM's
//! stress update. The median of the repeats is reported.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::mpm::material::Material;
use crate::scenario::mpm::spec::{Law, MpmScenario};
use crate::{Error, Result};

/// Result of `granflow bench rve`.
#[derive(Clone, Debug, Serialize)]
pub struct RveBench {
    /// Wall time of one MPM step of one point (µs; median over repeats, with the threads
    /// sharing the points).
    pub us_per_point_step: f64,
    /// Wall time per grain per DEM sub-step × threads (ns): the cost a core pays.
    pub ns_per_grain_substep: f64,
    /// Grains per volume, DEM sub-steps per MPM step, contacts per grain at the start.
    pub grains: usize,
    /// See `grains`.
    pub substeps: u64,
    /// See `grains`.
    pub coordination: f64,
    /// Points, MPM steps per repeat, threads.
    pub points: usize,
    /// See `points`.
    pub steps: u64,
    /// See `points`.
    pub threads: usize,
    /// Wall time of the preparation (s).
    pub preparation_s: f64,
    /// µs per point-step of every repeat.
    pub samples: Vec<f64>,
}

/// Run the benchmark (see the module doc) on the current rayon pool.
pub fn run(scenario: &MpmScenario, points: usize, steps: u64, repeats: usize) -> Result<RveBench> {
    let d = scenario.derive()?;
    let Law::Volume(volume) = &d.material else {
        return Err(Error::config(
            "material.model",
            "`granflow bench rve` needs a scenario with model = \"rve\"",
        ));
    };
    let t0 = Instant::now();
    let material = volume.material()?;
    let preparation_s = t0.elapsed().as_secs_f64();
    let h = scenario.mpm.cell_size;
    let c = (material.p_wave_modulus() / material.density()).sqrt();
    let dt = scenario.time.dt.unwrap_or(scenario.mpm.courant * h / c);
    let gdot = (scenario.gravity[0].hypot(scenario.gravity[1]) / d.height).sqrt();
    let de = [0.0, 0.0, 0.5 * gdot * dt];
    let (start, s0) = material.start();
    let mut samples = Vec::with_capacity(repeats);
    for _ in 0..repeats.max(1) {
        let mut cells = vec![start.clone(); points];
        let t = Instant::now();
        cells
            .par_iter_mut()
            .with_max_len(1)
            .try_for_each(|cell| {
                let mut s = s0;
                for _ in 0..steps {
                    s = material.update_stress(&s, &de, 0.0, dt, cell)?;
                }
                Ok::<(), String>(())
            })
            .map_err(Error::Other)?;
        samples.push(1e6 * t.elapsed().as_secs_f64() / (points as u64 * steps) as f64);
    }
    let us = crate::exec::median(&mut samples.clone());
    let substeps = material.substeps(dt);
    let threads = rayon::current_num_threads();
    Ok(RveBench {
        us_per_point_step: us,
        ns_per_grain_substep: 1e3 * us * threads as f64 / (substeps * start.len() as u64) as f64,
        grains: start.len(),
        substeps,
        coordination: start.coordination(),
        points,
        steps,
        threads,
        preparation_s,
        samples,
    })
}
