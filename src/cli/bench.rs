//! `granflow bench`: throughput of each solver, machine-readable with `--json`.

use std::process::ExitCode;

use anyhow::Result;

use granflow::exec::machine::Machine;
use serde::Serialize;

use crate::{Bench, Collision, Precision};

/// Prints a benchmark's result `r` with the machine it ran on, measured on `threads` threads
/// (0: all): as one JSON object with a `machine` key, or as the result's `line` and a
/// machine line.
fn report(r: &impl Serialize, threads: usize, json: bool, line: String) -> Result<ExitCode> {
    let machine = granflow::exec::on_threads(threads, || Ok(Machine::measure()))?;
    if json {
        let mut v = serde_json::to_value(r)?;
        v["machine"] = serde_json::to_value(&machine)?;
        println!("{v}");
    } else {
        println!("{line}");
        println!("machine: {machine}");
    }
    Ok(ExitCode::SUCCESS)
}

pub fn bench(which: Bench) -> Result<ExitCode> {
    match which {
        Bench::Mpm {
            points,
            steps,
            threads,
            repeats,
            shape,
            json,
        } => {
            let shape = match shape.as_str() {
                "gimp" => granflow::mpm::ShapeKind::Gimp,
                "standard" => granflow::mpm::ShapeKind::Standard,
                other => anyhow::bail!("--shape must be gimp or standard, got {other}"),
            };
            let r = granflow::scenario::mpm::bench::mpm(points, steps, threads, repeats, shape)?;
            let line = format!(
                    "mpm {} points ({}×{} cells), {} on {} threads: {:.3e} point-steps/s (samples {:?})",
                    r.points, r.cells[0], r.cells[1], r.shape, r.threads, r.point_steps_per_s, r.samples
            );
            report(&r, threads, json, line)
        }
        Bench::Lbm {
            nx,
            ny,
            steps,
            precision,
            collision,
            backend,
            threads,
            repeats,
            json,
        } => {
            let case = granflow::scenario::fluid::bench::LbmCase {
                nx,
                ny,
                steps,
                f64: matches!(precision, Precision::F64),
                mrt: matches!(collision, Collision::Mrt),
                backend: backend.into(),
            };
            let r = granflow::scenario::fluid::bench::lbm(case, threads, repeats)?;
            let place = match &r.device {
                Some(device) => format!("on {device}"),
                None => format!("on {} threads", r.threads),
            };
            let line = format!(
                    "lbm {}×{} {} {} {place}: {:.1} MLUPS (samples {:?}); copy {:.1} GB/s; {} B/cell; {:.0} % of roofline",
                    r.nx, r.ny, r.precision, r.collision, r.mlups, r.samples.iter().map(|s| (s * 10.0).round() / 10.0).collect::<Vec<_>>(), r.copy_gb_s, r.bytes_per_cell, 100.0 * r.roofline_fraction
            );
            report(&r, threads, json, line)
        }
        Bench::Rve {
            scenario,
            points,
            steps,
            threads,
            repeats,
            json,
        } => {
            use granflow::scenario::mpm::MpmScenario;
            use granflow::scenario::ScenarioFile;
            let s = MpmScenario::from_file(&scenario)?;
            let r = granflow::exec::on_threads(threads, || {
                granflow::scenario::mpm::bench_rve::run(&s, points, steps, repeats)
            })?;
            let line = format!(
                "rve {} grains × {} points, {} MPM steps ({} DEM sub-steps each) on {} threads: \
                     {:.1} µs per point-step, {:.1} ns per grain-sub-step per core (samples {:?}); \
                     z = {:.2}; preparation {:.1} s",
                r.grains,
                r.points,
                r.steps,
                r.substeps,
                r.threads,
                r.us_per_point_step,
                r.ns_per_grain_substep,
                r.samples,
                r.coordination,
                r.preparation_s
            );
            report(&r, threads, json, line)
        }
        Bench::Dem {
            grains,
            steps,
            threads,
            repeats,
            json,
        } => {
            let r = granflow::scenario::dem::bench::run(grains, steps, threads, repeats)?;
            let line = format!(
                    "dem {} grains, {} steps on {} threads: {:.3e} particle-steps/s (samples {:?}); {:.0} contacts/step; {:.3} list builds/step",
                    r.grains, r.steps, r.threads, r.particle_steps_per_s,
                    r.samples.iter().map(|s| format!("{s:.3e}")).collect::<Vec<_>>(),
                    r.contacts_per_step, r.list_builds_per_step
            );
            report(&r, threads, json, line)
        }
        Bench::Coupled {
            nx,
            ny,
            grains,
            steps,
            precision,
            backend,
            threads,
            json,
        } => {
            let r = granflow::scenario::submerged::bench::coupled(
                granflow::scenario::submerged::bench::CoupledCase {
                    nx,
                    ny,
                    grains,
                    steps,
                    f64: matches!(precision, Precision::F64),
                    backend: backend.into(),
                },
                threads,
            )?;
            let line = format!(
                    "coupled {}×{} {} with {} grains, lattice on the {}, {} threads: {:.1} MLUPS, {:.3e} grain steps/s, {:.2} s for {} steps ({} covered cells, {} DEM sub-steps per fluid step)",
                    r.nx, r.ny, r.precision, r.grains, r.backend, r.threads, r.mlups, r.particle_steps_per_s, r.seconds, r.steps, r.covered_cells, r.subcycles
            );
            report(&r, threads, json, line)
        }
    }
}
