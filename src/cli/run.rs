//! `granflow check` and `granflow run`: a scenario file of any kind, dispatched on its `kind`.

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, Result};

use granflow::scenario::checkpointing::{Control, SCENARIO_COPY};
use granflow::scenario::continuum::ContinuumScenario;
use granflow::scenario::dem::spec::dem_memory;
use granflow::scenario::dem::DemScenario;
use granflow::scenario::fluid::Scenario;
use granflow::scenario::granular::GranularScenario;
use granflow::scenario::mpm::spec::Law;
use granflow::scenario::mpm::MpmScenario;
use granflow::scenario::overrides::Override;
use granflow::scenario::submerged::SubmergedScenario;
use granflow::scenario::{Kind, ScenarioFile};

use super::{stopped, with_progress, Out};

/// `granflow check`: parse, derive and print, refuse bad input; no run. `sets`: the keys
/// `--set` changes.
pub fn check(path: &Path, sets: &[Override]) -> Result<ExitCode> {
    let (kind, text) = read_scenario(path, sets)?;
    match kind {
        Kind::Fluid => check_fluid(&Scenario::from_text(&text, path)?),
        Kind::Dem => check_dem(&DemScenario::from_text(&text, path)?),
        Kind::Mpm => check_mpm(&MpmScenario::from_text(&text, path)?),
        Kind::Submerged => {
            let s = SubmergedScenario::from_text(&text, path)?;
            print!("{}", s.check_report()?);
            Ok(ExitCode::SUCCESS)
        }
        Kind::Granular => {
            let s = GranularScenario::from_text(&text, path)?;
            print!("{}", s.check_report()?);
            Ok(ExitCode::SUCCESS)
        }
        Kind::Continuum => {
            let s = ContinuumScenario::from_text(&text, path)?;
            print!("{}", s.check_report()?);
            Ok(ExitCode::SUCCESS)
        }
        Kind::Sweep => check_sweep(path),
    }
}

/// The kind and text of the scenario file at `path`, with the keys `--set` changes; a sweep
/// file takes none.
/// The key `--backend` sets in the scenario `path`: `lbm.backend` of a fluid file,
/// `coupling.backend` of a submerged one; other kinds have no lattice.
pub fn backend_override(path: &Path, backend: granflow::lbm::Backend) -> Result<Override> {
    let (kind, _) = granflow::scenario::read_file(path, &[])?;
    let section = match kind {
        Kind::Fluid => "lbm",
        Kind::Submerged => "coupling",
        other => anyhow::bail!(
            "--backend: {} is a {} scenario, which has no lattice (only fluid and submerged \
             files do)",
            path.display(),
            other.name()
        ),
    };
    let key = format!("{section}.backend=\"{}\"", backend.name());
    key.parse().map_err(anyhow::Error::msg)
}

fn read_scenario(path: &Path, sets: &[Override]) -> Result<(Kind, String)> {
    let (kind, text) = granflow::scenario::read_file(path, sets)?;
    if kind == Kind::Sweep && !sets.is_empty() {
        anyhow::bail!(
            "--set: {} is a sweep file; its cases take their keys from the sweep (change the \
             sweep file)",
            path.display()
        );
    }
    Ok((kind, text))
}

/// A sweep file: its cases, resolved and checked.
fn check_sweep(path: &Path) -> Result<ExitCode> {
    let (spec, cases) = granflow::sweep::read_sweep(path)?;
    println!("sweep           {} — {}", spec.name, spec.description);
    for c in &cases {
        c.check()?;
        println!("case            {} (checked)", c.name);
    }
    println!("ok ({} cases; run with `granflow sweep`)", cases.len());
    Ok(ExitCode::SUCCESS)
}

fn check_fluid(s: &Scenario) -> Result<ExitCode> {
    let d = s.derive()?;
    let u = &d.units;
    println!("scenario        {} — {}", s.name, s.description);
    println!(
        "cells           {} × {} = {}",
        d.cells[0],
        d.cells[1],
        d.cells[0] * d.cells[1]
    );
    println!("dx              {:.6e} m", u.dx);
    println!("dt              {:.6e} s", u.dt);
    println!("tau             {:.6}", u.tau);
    println!("nu (lattice)    {:.6e}", d.nu_lattice);
    println!("u_ref (lattice) {:.6e}", d.u_lattice);
    println!(
        "Mach (lattice)  {:.4}  (limit {})",
        d.mach,
        granflow::scenario::fluid::MAX_MACH
    );
    println!("Reynolds        {:.4}", d.reynolds);
    println!("backend         {}", s.lbm.backend.name());
    println!("steps           {} ({} s)", d.steps, s.time.end);
    println!(
        "frames          every {} steps ({} frames)",
        d.frame_every,
        d.steps.div_ceil(d.frame_every) + 1
    );
    println!("series          every {} steps", d.series_every);
    println!(
        "force (lattice) [{:.4e}, {:.4e}]",
        d.force_lattice[0], d.force_lattice[1]
    );
    println!(
        "collision       {:?}{}",
        s.lbm.collision,
        s.lbm
            .smagorinsky
            .map_or(String::new(), |c| format!(" + Smagorinsky C = {c}"))
    );
    if let Some(r) = d.mrt {
        println!(
            "MRT rates       s_e = {:.4}, s_eps = {:.4}, s_q = {:.4}, s_nu = {:.4}",
            r.s_e,
            r.s_eps,
            r.s_q,
            1.0 / u.tau
        );
    }
    println!("precision       {:?}", s.lbm.precision);
    print_memory(d.memory_bytes);
    println!("obstacles       {}", s.obstacles.len());
    match s.initial.uniform_velocity() {
        Some([u, v]) => println!("initial         uniform, u = [{u}, {v}] m/s"),
        None => {
            let field = s.initial.field(d.cells, u.dx)?;
            println!(
                "initial         field from expressions of x, y; largest speed {:.4e} m/s",
                field.max_speed(d.cells, u.dx)
            );
        }
    }
    println!("ok");
    Ok(ExitCode::SUCCESS)
}

/// The `memory` line of `check`: the estimated peak and what the machine has.
fn print_memory(bytes: usize) {
    println!("memory          {}", granflow::exec::memory_line(bytes));
}

fn check_dem(s: &DemScenario) -> Result<ExitCode> {
    let d = s.derive()?;
    println!(
        "scenario        {} — {} (DEM column collapse)",
        s.name, s.description
    );
    println!("grains          {}", d.grains);
    println!(
        "column          L_i = {:.4e} m, target H_i = {:.4e} m",
        s.column.width, d.target_height
    );
    println!("tau_c (target)  {:.4e} s", d.target_tau_c);
    print_memory(dem_memory(d.grains));
    println!(
        "dt              {:.4e} s (λ·Δt_cr, λ = {}, Δt_cr = {:.4e} s for d_min; the drawn grains may allow more)",
        d.time_step.dt, d.params.lambda, d.time_step.critical
    );
    println!("ok");
    Ok(ExitCode::SUCCESS)
}

fn check_mpm(s: &MpmScenario) -> Result<ExitCode> {
    let d = s.derive()?;
    println!(
        "scenario        {} — {} (MPM column collapse)",
        s.name, s.description
    );
    println!(
        "column          L_i = {:.4e} m, H_i = {:.4e} m, τ_c = {:.4e} s",
        s.column.width, d.height, d.tau_c
    );
    println!(
        "grid            {} × {} cells of {:.4e} m, {} points",
        d.cells[0], d.cells[1], s.mpm.cell_size, d.points
    );
    println!(
        "wave speed      c = √((K + 4G/3)/ρ) = {:.4} m/s",
        d.wave_speed
    );
    println!(
        "dt (CFL)        {:.4e} s (Courant {})",
        d.dt_cfl, s.mpm.courant
    );
    if let Some(dt) = s.time.dt {
        println!("dt              {dt:.4e} s (given)");
    }
    print_memory(d.memory_bytes());
    if let Law::Volume(v) = &d.material {
        let p = &v.preparation;
        let dt = s.time.dt.unwrap_or(d.dt_cfl);
        let sub = granflow::scale::substeps(dt, p.dt).0;
        let steps = (s.time.end_tc * d.tau_c / dt).ceil();
        let grain_steps = steps * (sub * (p.grains * d.points) as u64) as f64;
        let threads = rayon::current_num_threads() as f64;
        println!(
            "volumes         {} grains per point, {} in all, φ = {}, prepared at p₀ = {} Pa, \
             each driven to its geostatic stress (K₀ = {})",
            p.grains,
            p.grains * d.points,
            p.packing_fraction,
            p.pressure,
            v.k0
        );
        println!(
            "DEM step        {:.4e} s: {sub} sub-steps per MPM step (the CFL step above is \
             estimated from the packing before it is prepared)",
            p.dt
        );
        println!(
            "run time        about {:.0} s on {threads} threads to end_tc ({:.2e} grain-steps \
             at {RVE_NS_PER_GRAIN_STEP} ns each, measured; a run at rest stops earlier, a \
             volume re-tiled when stretched thin costs twice as much from then on), after \
             preparing the volume and driving the points' copies to their stresses (not \
             bounded: seconds to minutes)",
            grain_steps * RVE_NS_PER_GRAIN_STEP * 1e-9 / threads,
            grain_steps
        );
    }
    println!("ok");
    Ok(ExitCode::SUCCESS)
}

/// Cost of one grain in one DEM sub-step of a representative volume, on one core of the 2-core
/// machines (docs/performance.md, "MPM×DEM"), for `check`'s run-time estimate.
const RVE_NS_PER_GRAIN_STEP: f64 = 75.0;

fn run_mpm(
    s: &MpmScenario,
    path: &Path,
    out: &Path,
    volumes: &[[f64; 2]],
    control: Control,
) -> Result<ExitCode> {
    let d = s.derive()?;
    eprintln!(
        "{}: MPM column collapse, {} points -> {}",
        s.name,
        d.points,
        out.display()
    );
    let end = (1e3 * s.time.end_tc) as u64;
    let r = with_progress(end, "milli-τ_c", |p| {
        granflow::scenario::collapse::mpm::run_column_collapse_with(s, out, volumes, control, p)
    })
    .with_context(|| stopped(path, out))?;
    println!(
        "done: a = {:.3}, L_f = {:.4} m, (L_f − L_i)/L_i = {:.3}, H_f/L_i = {:.3}, spreading stopped at {:.2} τ_c, {} at {:.2} τ_c, {} points, {:.1} s wall",
        r.collapse.aspect_ratio,
        r.collapse.l_f,
        r.collapse.delta_l,
        r.collapse.h_f_over_l_i,
        r.collapse.stop_time_tc,
        if r.collapse.at_rest { "at rest" } else { "end time reached" },
        r.collapse.rest_time_tc,
        r.points,
        r.collapse.wall_time_s
    );
    Ok(ExitCode::SUCCESS)
}

fn run_dem(s: &DemScenario, path: &Path, out: &Path, control: Control) -> Result<ExitCode> {
    let d = s.derive()?;
    eprintln!(
        "{}: DEM column collapse, {} grains -> {}",
        s.name,
        d.grains,
        out.display()
    );
    let end = (1e3 * s.time.end_tc) as u64;
    let r = with_progress(end, "milli-τ_c", |p| {
        granflow::scenario::collapse::dem::run_resumable_collapse(s, out, control, p)
    })
    .with_context(|| stopped(path, out))?;
    println!(
        "done: a = {:.3}, L_f/L_i − 1 = {:.3}, H_f/L_i = {:.3}, spreading stopped at {:.2} τ_c, {} at {:.2} τ_c, {} grains, packing {:.3}",
        r.collapse.aspect_ratio,
        r.collapse.delta_l,
        r.collapse.h_f_over_l_i,
        r.collapse.stop_time_tc,
        if r.collapse.at_rest { "at rest" } else { "end time reached" },
        r.collapse.rest_time_tc,
        r.grains,
        r.packing_fraction
    );
    Ok(ExitCode::SUCCESS)
}

/// `granflow run`: run a scenario (with the keys `sets` changes) and write its outputs;
/// `volumes`: the places of the representative volumes whose grains every frame writes
/// (`--rve-frames`, MPM files with `model = "rve"` only); `checkpoint_every`: simulated
/// seconds between checkpoints.
pub fn run(
    path: &Path,
    sets: &[Override],
    out: Out,
    volumes: &[[f64; 2]],
    checkpoint_every: Option<f64>,
) -> Result<ExitCode> {
    let (kind, text) = read_scenario(path, sets)?;
    if !volumes.is_empty() && kind != Kind::Mpm {
        anyhow::bail!(
            "--rve-frames: {} is not an MPM scenario (only the points of an MPM file with \
             model = \"rve\" hold grains)",
            path.display()
        );
    }
    let control = Control::new(&text, checkpoint_every, super::stop_on_signals()?)?;
    run_resumable(kind, path, &text, volumes, control, |memory| {
        let dir = out.claim(memory)?;
        keep_scenario(dir, &text)?;
        Ok(dir)
    })
}

/// Parse the scenario `text` (of the file `path`) of `kind`, take its output folder with
/// `take(estimated peak memory)` and run it as `control` says.
fn run_resumable<'a>(
    kind: Kind,
    path: &Path,
    text: &str,
    volumes: &[[f64; 2]],
    control: Control,
    take: impl FnOnce(usize) -> Result<&'a Path>,
) -> Result<ExitCode> {
    match kind {
        Kind::Fluid => {
            let s = Scenario::from_text(text, path)?;
            let dir = take(s.derive()?.memory_bytes)?;
            run_fluid(&s, path, dir, control)
        }
        Kind::Dem => {
            let s = DemScenario::from_text(text, path)?;
            let dir = take(dem_memory(s.derive()?.grains))?;
            run_dem(&s, path, dir, control)
        }
        Kind::Mpm => {
            let s = MpmScenario::from_text(text, path)?;
            granflow::scenario::collapse::mpm::check_volumes(&s, volumes)?;
            let dir = take(s.derive()?.memory_bytes())?;
            run_mpm(&s, path, dir, volumes, control)
        }
        Kind::Submerged => {
            let s = SubmergedScenario::from_text(text, path)?;
            let dir = take(s.derive()?.memory_bytes)?;
            run_submerged(&s, path, dir, control)
        }
        Kind::Granular => {
            let s = GranularScenario::from_text(text, path)?;
            let d = s.derive()?;
            let dir = take(granflow::scenario::granular::granular_memory(
                d.grains.len(),
            ))?;
            eprintln!(
                "{}: granular, {} grains, {} walls, {} outlet(s) -> {}",
                s.name,
                d.grains.len(),
                d.walls.len() + d.gates.len(),
                d.outlets.len(),
                dir.display()
            );
            let r = with_progress((1e3 * s.time.end) as u64, "ms", |p| {
                granflow::scenario::granular::run::run_granular(&s, dir, control, p)
            })
            .with_context(|| stopped(path, dir))?;
            println!("{}", r.done_line());
            Ok(ExitCode::SUCCESS)
        }
        Kind::Continuum => {
            let s = ContinuumScenario::from_text(text, path)?;
            let d = s.derive()?;
            let dir = take(ContinuumScenario::memory_bytes(&d))?;
            eprintln!(
                "{}: continuum, {} points, {} × {} cells -> {}",
                s.name,
                d.points.len(),
                d.cells[0],
                d.cells[1],
                dir.display()
            );
            let r = with_progress((1e3 * s.time.end) as u64, "ms", |p| {
                granflow::scenario::continuum::run::run_continuum(&s, dir, control, p)
            })
            .with_context(|| stopped(path, dir))?;
            println!("{}", r.done_line());
            Ok(ExitCode::SUCCESS)
        }
        Kind::Sweep => anyhow::bail!(
            "{} is a sweep file: run it with `granflow sweep {} --out DIR`",
            path.display(),
            path.display()
        ),
    }
}

fn run_submerged(
    s: &SubmergedScenario,
    path: &Path,
    out: &Path,
    control: Control,
) -> Result<ExitCode> {
    eprintln!("{}: submerged column collapse -> {}", s.name, out.display());
    let r = with_progress((1e3 * s.time.end_tc) as u64, "milli-τ_c", |p| {
        granflow::scenario::collapse::submerged::run_submerged(s, out, control, p)
    })
    .with_context(|| stopped(path, out))?;
    println!("{}", r.done_line());
    Ok(ExitCode::SUCCESS)
}

fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// Keep the scenario text in the run's folder ([`SCENARIO_COPY`]): what `resume` runs.
fn keep_scenario(dir: &Path, text: &str) -> Result<()> {
    granflow::io::run_dir::create(dir)?;
    granflow::io::write_atomic_bytes(&dir.join(SCENARIO_COPY), text.as_bytes())?;
    Ok(())
}

/// `granflow resume DIR`: continue the run in `dir` from its newest checkpoint.
pub fn resume(dir: &Path) -> Result<ExitCode> {
    let path = dir.join(SCENARIO_COPY);
    if !path.is_file() {
        anyhow::bail!(
            "cannot resume {}: it holds no run ({SCENARIO_COPY}, which `granflow run` keeps in \
             its output folder, is missing)",
            dir.display()
        );
    }
    let text = read_text(&path)?;
    let kind = granflow::scenario::kind_of(&text)?;
    let checkpoints = granflow::io::checkpoint::list(dir)?;
    if checkpoints.is_empty() && completed(dir) {
        anyhow::bail!(
            "nothing to resume in {}: its run completed (summary.json)",
            dir.display()
        );
    }
    let mut control = Control::new(&text, None, super::stop_on_signals()?)?;
    control.resume = true;
    run_resumable(kind, &path, &text, &[], control, |memory| {
        granflow::exec::check_memory(memory as u64)?;
        Ok(dir)
    })
}

/// Does the run in `dir` say it completed? A collapse writes `summary.json` when it ends; a
/// fluid run also when it stops, with its `status`.
fn completed(dir: &Path) -> bool {
    std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|v| v.get("status").is_none_or(|s| s == "completed"))
}

fn run_fluid(s: &Scenario, path: &Path, out: &Path, control: Control) -> Result<ExitCode> {
    let d = s.derive()?;
    eprintln!(
        "{}: {} × {} cells, τ = {:.4}, Mach {:.3}, Re {:.1}, {} steps -> {}",
        s.name,
        d.cells[0],
        d.cells[1],
        d.units.tau,
        d.mach,
        d.reynolds,
        d.steps,
        out.display()
    );
    let summary = with_progress(d.steps, "steps", |p| {
        granflow::scenario::fluid::run::run(s, out, control, p)
    })
    .with_context(|| stopped(path, out))?;
    println!(
        "done: {} steps, {:.1} s simulated, {} frames, {:.1} s wall, {:.1} MLUPS, mass drift {:.2e}",
        summary.steps, summary.time, summary.frames, summary.wall_seconds, summary.mlups, summary.mass_drift
    );
    for o in &summary.obstacles {
        println!(
            "  {}: F = ({:.6e}, {:.6e}) N/m, coefficients ({:.4}, {:.4}){}",
            o.name,
            o.force[0],
            o.force[1],
            o.coefficients[0],
            o.coefficients[1],
            o.strouhal
                .map_or(String::new(), |st| format!(", St = {st:.4}"))
        );
    }
    Ok(ExitCode::SUCCESS)
}
