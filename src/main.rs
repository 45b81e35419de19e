//! The `granflow` command line.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand, ValueEnum};

use granflow::config::Scenario;
use granflow::dem::scenario::DemScenario;
use granflow::validate::{self, Check, Fidelity};

#[derive(Parser)]
#[command(
    name = "granflow",
    version,
    about = "Multi-scale granular flows, dry and submerged"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Parse a scenario, derive and print the lattice quantities, refuse bad input; no run.
    Check {
        /// Scenario file (TOML).
        scenario: PathBuf,
    },
    /// Run a scenario and write series.pvd + frames, timeseries.csv and summary.json.
    Run {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Output folder (created if needed; files in it are replaced).
        #[arg(long)]
        out: PathBuf,
    },
    /// Run validation cases against their references.
    Validate {
        /// Case name, or `all`; `granflow validate list` lists them.
        case: String,
        /// One JSON object per checked quantity.
        #[arg(long)]
        json: bool,
        /// Full resolution (slower) instead of the test resolution.
        #[arg(long)]
        full: bool,
        /// Write each case's figures as `<DIR>/<name>.svg` (DIR is created if needed).
        #[arg(long, value_name = "DIR")]
        figures: Option<PathBuf>,
    },
    /// Run a column-collapse sweep (cases in parallel, resumable) and write sweep.csv,
    /// fits.json and the figures.
    Sweep {
        /// Sweep file (TOML): base scenario per solver and the values to vary.
        sweep: PathBuf,
        /// Output folder: one sub-folder per case, plus the tables and figures.
        #[arg(long)]
        out: PathBuf,
        /// Cases run at the same time (0: one per core).
        #[arg(long, default_value_t = 0)]
        jobs: usize,
    },
    /// Biaxial compression of a DEM collapse scenario's material: its peak and critical-state
    /// friction angles, the φ a Mohr–Coulomb continuum of that material needs. Writes
    /// biaxial.csv, summary.json and biaxial.svg.
    Biaxial {
        /// DEM collapse scenario (TOML): its grains, contact laws and deposition are used.
        scenario: PathBuf,
        /// Output folder (created if needed).
        #[arg(long)]
        out: PathBuf,
        /// Confining stress σ₃ (Pa), e.g. the mean stress in the column, ρ φ g H/2.
        #[arg(long, allow_negative_numbers = true)]
        confining: f64,
        /// Grains in the sample (about half as wide as high).
        #[arg(long, default_value_t = 1000)]
        grains: usize,
        /// Inertial number I of the shear, ε̇ = I/(d̄ √(ρ_s/σ₃)); ≤ 1e-3 is quasi-static.
        #[arg(long, default_value_t = 1e-3)]
        inertial_number: f64,
        /// Axial strain at which the test ends (< 0.5).
        #[arg(long, default_value_t = 0.3)]
        strain: f64,
        /// Grain friction during the preparation (default: the scenario's deposition friction).
        #[arg(long)]
        prep_friction: Option<f64>,
        /// Seed of the sample's sizes and deposition (default: the scenario's).
        #[arg(long)]
        seed: Option<u64>,
    },
    /// Periodic simple shear (Lees–Edwards) of a DEM collapse scenario's material at a set of
    /// inertial numbers and a fixed normal stress: its μ(I) and solid fraction φ(I), and the fit
    /// sin φ(I) = sin φ_s + (sin φ_2 − sin φ_s)/(I_0/I + 1) a plane-strain continuum of the
    /// material takes. Writes mu_i.csv, shear_<k>.csv, summary.json and mu_i.svg.
    Shear {
        /// DEM collapse scenario (TOML): its grains and grain–grain contact laws are used.
        scenario: PathBuf,
        /// Output folder (created if needed).
        #[arg(long)]
        out: PathBuf,
        /// Normal stress σ_yy held by the cell's height (Pa).
        #[arg(long, allow_negative_numbers = true)]
        pressure: f64,
        /// Inertial numbers I = γ̇ d̄/√(P/ρ_s), comma-separated (one test each).
        #[arg(
            long,
            value_delimiter = ',',
            allow_negative_numbers = true,
            required = true
        )]
        inertial_numbers: Vec<f64>,
        /// Grains in the cell.
        #[arg(long, default_value_t = 500)]
        grains: usize,
        /// Shear strain γ of each test (the steady state is its second half).
        #[arg(long, default_value_t = 5.0)]
        strain: f64,
        /// Seed of the sizes (default: the scenario's).
        #[arg(long)]
        seed: Option<u64>,
    },
    /// Throughput benchmarks.
    Bench {
        #[command(subcommand)]
        which: Bench,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Precision {
    F32,
    F64,
}

#[derive(Clone, Copy, ValueEnum)]
enum Collision {
    Bgk,
    Mrt,
}

#[derive(Subcommand)]
enum Bench {
    /// GIMPM step on a collapsing column, in material point-steps per second.
    Mpm {
        /// Material points (about; the column is w × 2w cells with 4 points per cell).
        #[arg(long, default_value_t = 8192)]
        points: usize,
        /// Steps per repeat.
        #[arg(long, default_value_t = 200)]
        steps: u64,
        /// Threads (0: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Timed repeats; the median is reported.
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Shape functions: gimp or standard.
        #[arg(long, default_value = "gimp")]
        shape: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// D2Q9 LBM in a periodic box, with the memory-bandwidth roofline measured beside it.
    Lbm {
        /// Cells along x.
        #[arg(long, default_value_t = 2048)]
        nx: usize,
        /// Cells along y.
        #[arg(long, default_value_t = 2048)]
        ny: usize,
        /// Steps per repeat.
        #[arg(long, default_value_t = 100)]
        steps: u64,
        /// Population precision.
        #[arg(long, value_enum, default_value_t = Precision::F32)]
        precision: Precision,
        /// Collision operator.
        #[arg(long, value_enum, default_value_t = Collision::Bgk)]
        collision: Collision,
        /// Threads (0: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Timed repeats; the median is reported.
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// DEM: the LAMMPS `in.gran2d.lmp` case (hex block of disks collapsing between walls).
    Dem {
        /// Number of grains (a √N × √N hex block).
        #[arg(long, default_value_t = 10_000)]
        grains: usize,
        /// Timed steps per repeat (after 500 warm-up steps).
        #[arg(long, default_value_t = 5000)]
        steps: u64,
        /// Threads (0: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Repeats (each a fresh block); the median is reported.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Coupled LBM–DEM step: disks as partially saturated cells in a box (issue 6).
    Coupled {
        /// Cells along x.
        #[arg(long, default_value_t = 1024)]
        nx: usize,
        /// Cells along y.
        #[arg(long, default_value_t = 1024)]
        ny: usize,
        /// Grains.
        #[arg(long, default_value_t = 500)]
        grains: usize,
        /// Coupled steps timed.
        #[arg(long, default_value_t = 100)]
        steps: u64,
        /// Population precision.
        #[arg(long, value_enum, default_value_t = Precision::F32)]
        precision: Precision,
        /// Threads (0: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    match real_main() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn real_main() -> Result<ExitCode> {
    match Cli::parse().command {
        Command::Check { scenario } => check(&scenario),
        Command::Run { scenario, out } => run(&scenario, &out),
        Command::Validate {
            case,
            json,
            full,
            figures,
        } => validate_cmd(&case, json, full, figures.as_deref()),
        Command::Sweep { sweep, out, jobs } => sweep_cmd(&sweep, &out, jobs),
        Command::Biaxial {
            scenario,
            out,
            confining,
            grains,
            inertial_number,
            strain,
            prep_friction,
            seed,
        } => biaxial(
            &scenario,
            &out,
            [confining, inertial_number, strain],
            grains,
            prep_friction,
            seed,
        ),
        Command::Shear {
            scenario,
            out,
            pressure,
            inertial_numbers,
            grains,
            strain,
            seed,
        } => shear(
            &scenario,
            &out,
            pressure,
            &inertial_numbers,
            grains,
            strain,
            seed,
        ),
        Command::Bench { which } => bench(which),
    }
}

fn sweep_cmd(path: &Path, out: &Path, jobs: usize) -> Result<ExitCode> {
    let r = granflow::sweep::run_sweep(path, out, jobs)?;
    for g in &r.fits.groups {
        let with: String = g.with.iter().map(|(p, v)| format!(" {p}={v}")).collect();
        match &g.law {
            Some(l) => println!(
                "{}{with}: ΔL = {:.3}a (a < {:.2}), {:.3}a^{:.3} (±{:.3}) above; {} cases",
                g.solver,
                l.small.lambda,
                l.crossover,
                l.large.lambda,
                l.large.alpha,
                l.large.alpha_err.unwrap_or(f64::NAN),
                g.points.len()
            ),
            None => println!(
                "{}{with}: {} cases (too few to fit)",
                g.solver,
                g.points.len()
            ),
        }
    }
    for c in &r.fits.mpm_vs_dem {
        println!(
            "a = {:.2}: ΔL DEM {:.3}, MPM {:.3} ({:+.1} %)",
            c.a,
            c.dem,
            c.mpm,
            100.0 * c.mpm_excess
        );
    }
    let failed: Vec<_> = r.failed().collect();
    println!(
        "{} cases, {} reused, {} failed -> {}",
        r.cases.len(),
        r.cases.iter().filter(|c| c.reused).count(),
        failed.len(),
        out.display()
    );
    if failed.is_empty() {
        Ok(ExitCode::SUCCESS)
    } else {
        for c in failed {
            eprintln!(
                "failed: {}: {}",
                c.case.name,
                c.outcome.as_ref().unwrap_err()
            );
        }
        Ok(ExitCode::FAILURE)
    }
}

/// Is this a DEM scenario (it has a `[grains]` table)? Anything unreadable is left to the fluid
/// parser, whose error names the problem.
fn is_dem(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .is_some_and(|t| t.contains_key("grains"))
}

/// Is this a coupled (submerged) scenario (it has a `[coupling]` table)?
fn is_submerged(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .is_some_and(|t| t.contains_key("coupling"))
}

/// Is this an MPM scenario (it has a `[material]` table)?
fn is_mpm(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .is_some_and(|t| t.contains_key("material"))
}

fn check(path: &Path) -> Result<ExitCode> {
    if is_submerged(path) {
        let s = granflow::coupling::scenario::SubmergedScenario::from_file(path)?;
        print!("{}", s.check_report()?);
        return Ok(ExitCode::SUCCESS);
    }
    if is_dem(path) {
        return check_dem(path);
    }
    if is_mpm(path) {
        return check_mpm(path);
    }
    let s = Scenario::from_file(path)?;
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
    println!("tau             {:.6}", d.tau);
    println!("nu (lattice)    {:.6e}", d.nu_lattice);
    println!("u_ref (lattice) {:.6e}", d.u_lattice);
    println!(
        "Mach (lattice)  {:.4}  (limit {})",
        d.mach,
        granflow::config::MAX_MACH
    );
    println!("Reynolds        {:.4}", d.reynolds);
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
            1.0 / d.tau
        );
    }
    println!("precision       {:?}", s.lbm.precision);
    println!(
        "memory          {:.1} MiB (populations)",
        d.memory_bytes as f64 / (1 << 20) as f64
    );
    println!("obstacles       {}", s.obstacles.len());
    println!("ok");
    Ok(ExitCode::SUCCESS)
}

fn check_dem(path: &Path) -> Result<ExitCode> {
    let s = DemScenario::from_file(path)?;
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
    match d.params.dt {
        Some(dt) => println!("dt              {dt:.4e} s (given)"),
        None => println!(
            "dt              λ·Δt_cr with λ = {} (computed from the smallest grain)",
            d.params.lambda
        ),
    }
    println!("ok");
    Ok(ExitCode::SUCCESS)
}

fn check_mpm(path: &Path) -> Result<ExitCode> {
    let s = granflow::mpm::scenario::MpmScenario::from_file(path)?;
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
    println!("ok");
    Ok(ExitCode::SUCCESS)
}

fn run_mpm(path: &Path, out: &Path) -> Result<ExitCode> {
    let s = granflow::mpm::scenario::MpmScenario::from_file(path)?;
    let d = s.derive()?;
    eprintln!(
        "{}: MPM column collapse, {} points -> {}",
        s.name,
        d.points,
        out.display()
    );
    let end = (1e3 * s.time.end_tc) as u64;
    let r = with_progress(end, "milli-τ_c", |p| {
        granflow::mpm::run::run_column_collapse(&s, out, p)
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

/// Run `f` with a progress callback: an indicatif bar on a terminal, a plain line every 10 %
/// otherwise (logs, CI).
fn with_progress<R>(total: u64, unit: &str, f: impl FnOnce(&mut dyn FnMut(u64, u64)) -> R) -> R {
    if std::io::stderr().is_terminal() {
        let bar = indicatif::ProgressBar::new(total);
        let template =
            format!("{{elapsed_precise}} [{{bar:40}}] {{pos}}/{{len}} {unit}, eta {{eta}}");
        bar.set_style(indicatif::ProgressStyle::with_template(&template).expect("valid template"));
        let r = f(&mut |i, _| bar.set_position(i));
        bar.finish();
        r
    } else {
        let mut last = 0;
        f(&mut |i, n| {
            let pct = i * 10 / n.max(1);
            if pct > last {
                last = pct;
                eprintln!("{i}/{n} {unit} ({}%)", pct * 10);
            }
        })
    }
}

/// Context for a run that failed part-way.
fn stopped(path: &Path, out: &Path) -> String {
    format!(
        "run of {} stopped; frames written so far are in {}",
        path.display(),
        out.display()
    )
}

fn run_dem(path: &Path, out: &Path) -> Result<ExitCode> {
    let s = DemScenario::from_file(path)?;
    let d = s.derive()?;
    eprintln!(
        "{}: DEM column collapse, {} grains -> {}",
        s.name,
        d.grains,
        out.display()
    );
    let end = (1e3 * s.time.end_tc) as u64;
    let r = with_progress(end, "milli-τ_c", |p| {
        granflow::dem::run::run_column_collapse(&s, out, p)
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

/// `granflow biaxial`; `[σ₃, I, final strain]`.
fn biaxial(
    path: &Path,
    out: &Path,
    [confining, inertial_number, strain]: [f64; 3],
    grains: usize,
    prep_friction: Option<f64>,
    seed: Option<u64>,
) -> Result<ExitCode> {
    use granflow::dem::biaxial::{run_biaxial_to, BiaxialSpec};
    let s = DemScenario::from_file(path)?;
    let spec = BiaxialSpec::from_scenario(
        &s,
        grains,
        confining,
        inertial_number,
        strain,
        prep_friction,
        seed,
    )?;
    eprintln!(
        "{}: biaxial test, {grains} grains, σ₃ = {confining} Pa, I = {inertial_number}, to ε₁ = {strain} -> {}",
        s.name,
        out.display()
    );
    let total = (strain / spec.record_strain) as u64;
    let r = with_progress(total, "points", |p| run_biaxial_to(&spec, out, p))
        .with_context(|| format!("biaxial test of {} stopped", path.display()))?;
    println!("done: {}", r.done_line());
    Ok(ExitCode::SUCCESS)
}

/// `granflow shear`.
fn shear(
    path: &Path,
    out: &Path,
    pressure: f64,
    inertial_numbers: &[f64],
    grains: usize,
    strain: f64,
    seed: Option<u64>,
) -> Result<ExitCode> {
    use granflow::dem::mu_i::{run_mu_i_to, ShearSpec};
    let s = DemScenario::from_file(path)?;
    let specs = inertial_numbers
        .iter()
        .map(|&i| ShearSpec::from_scenario(&s, grains, pressure, i, strain, seed))
        .collect::<granflow::Result<Vec<_>>>()?;
    eprintln!(
        "{}: periodic simple shear, {grains} grains, P = {pressure} Pa, I = {inertial_numbers:?}, \
         to γ = {strain} -> {}",
        s.name,
        out.display()
    );
    let r = run_mu_i_to(&specs, out)
        .with_context(|| format!("shear test of {} stopped", path.display()))?;
    for t in &r.tests {
        println!("{}", t.done_line());
    }
    if let Some(f) = &r.fit {
        println!(
            "fit: sin φ(I) = {:.4} + ({:.4} − {:.4})/(I_0/I + 1), I_0 = {:.4} (φ_s = {:.2}°, \
             φ_2 = {:.2}°, rms {:.1e}{})",
            f.sin_phi_s,
            f.sin_phi_2,
            f.sin_phi_s,
            f.i_0,
            f.phi_s_deg,
            f.phi_2_deg,
            f.rms,
            if f.i_0_at_grid_end {
                "; I_0 at the end of its grid: not bounded by these points"
            } else {
                ""
            }
        );
    }
    Ok(ExitCode::SUCCESS)
}

fn run(path: &Path, out: &Path) -> Result<ExitCode> {
    if is_submerged(path) {
        let s = granflow::coupling::scenario::SubmergedScenario::from_file(path)?;
        eprintln!("{}: submerged column collapse -> {}", s.name, out.display());
        let r = with_progress((1e3 * s.time.end_tc) as u64, "milli-τ_c", |p| {
            granflow::coupling::run::run_submerged(&s, out, p)
        })
        .with_context(|| stopped(path, out))?;
        println!("{}", r.done_line());
        return Ok(ExitCode::SUCCESS);
    }
    if is_dem(path) {
        return run_dem(path, out);
    }
    if is_mpm(path) {
        return run_mpm(path, out);
    }
    let s = Scenario::from_file(path)?;
    let d = s.derive()?;
    eprintln!(
        "{}: {} × {} cells, τ = {:.4}, Mach {:.3}, Re {:.1}, {} steps -> {}",
        s.name,
        d.cells[0],
        d.cells[1],
        d.tau,
        d.mach,
        d.reynolds,
        d.steps,
        out.display()
    );
    let summary = with_progress(d.steps, "steps", |p| granflow::run::run(&s, out, p))
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

fn print_check(c: &Check, json: bool) {
    if json {
        println!("{}", serde_json::to_string(c).expect("checks serialise"));
    } else {
        println!(
            "{:<5} {:<16} {:<60} value {:>12.6e}  reference {:>12.6e}  tolerance {:.3e}",
            if c.pass { "PASS" } else { "FAIL" },
            c.case,
            c.quantity,
            c.value,
            c.reference,
            c.tolerance
        );
    }
}

fn validate_cmd(case: &str, json: bool, full: bool, figures: Option<&Path>) -> Result<ExitCode> {
    if case == "list" {
        for c in validate::CASES {
            println!("{:<16} {}", c.name, c.description);
        }
        return Ok(ExitCode::SUCCESS);
    }
    let fidelity = if full { Fidelity::Full } else { Fidelity::Test };
    let names: Vec<&str> = if case == "all" {
        validate::CASES.iter().map(|c| c.name).collect()
    } else {
        vec![case]
    };
    if let Some(dir) = figures {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the figures folder {}", dir.display()))?;
    }
    let mut failed = 0;
    for name in names {
        match validate::run(name, fidelity) {
            Ok(report) => {
                for c in &report.checks {
                    print_check(c, json);
                    failed += usize::from(!c.pass);
                }
                if let Some(dir) = figures {
                    for plot in &report.plots {
                        let path = dir.join(format!("{}.svg", plot.name));
                        match granflow::io::write_svg(plot, &path) {
                            Ok(()) => eprintln!("figure {}", path.display()),
                            Err(e) => {
                                failed += 1;
                                eprintln!("ERROR figure {}: {e}", path.display());
                            }
                        }
                    }
                }
            }
            Err(e) => {
                failed += 1;
                if json {
                    println!(
                        "{}",
                        serde_json::json!({"case": name, "error": e.to_string(), "pass": false})
                    );
                } else {
                    println!("ERROR {name}: {e}");
                }
            }
        }
    }
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

fn bench(which: Bench) -> Result<ExitCode> {
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
            let r = granflow::mpm::bench::mpm(points, steps, threads, repeats, shape)?;
            if json {
                println!("{}", serde_json::to_string(&r)?);
            } else {
                println!(
                    "mpm {} points ({}×{} cells), {} on {} threads: {:.3e} point-steps/s (samples {:?})",
                    r.points, r.cells[0], r.cells[1], r.shape, r.threads, r.point_steps_per_s, r.samples
                );
            }
            Ok(ExitCode::SUCCESS)
        }
        Bench::Lbm {
            nx,
            ny,
            steps,
            precision,
            collision,
            threads,
            repeats,
            json,
        } => {
            let r = granflow::bench::lbm(
                nx,
                ny,
                steps,
                matches!(precision, Precision::F64),
                matches!(collision, Collision::Mrt),
                threads,
                repeats,
            )?;
            if json {
                println!("{}", serde_json::to_string(&r)?);
            } else {
                println!(
                    "lbm {}×{} {} {} on {} threads: {:.1} MLUPS (samples {:?}); copy {:.1} GB/s; {} B/cell; {:.0} % of roofline",
                    r.nx, r.ny, r.precision, r.collision, r.threads, r.mlups, r.samples.iter().map(|s| (s * 10.0).round() / 10.0).collect::<Vec<_>>(), r.copy_gb_s, r.bytes_per_cell, 100.0 * r.roofline_fraction
                );
            }
            Ok(ExitCode::SUCCESS)
        }
        Bench::Dem {
            grains,
            steps,
            threads,
            repeats,
            json,
        } => {
            let r = granflow::dem::bench::run(grains, steps, threads, repeats)?;
            if json {
                println!("{}", serde_json::to_string(&r)?);
            } else {
                println!(
                    "dem {} grains, {} steps on {} threads: {:.3e} particle-steps/s (samples {:?}); {:.0} contacts/step; {:.3} list builds/step",
                    r.grains, r.steps, r.threads, r.particle_steps_per_s,
                    r.samples.iter().map(|s| format!("{s:.3e}")).collect::<Vec<_>>(),
                    r.contacts_per_step, r.list_builds_per_step
                );
            }
            Ok(ExitCode::SUCCESS)
        }
        Bench::Coupled {
            nx,
            ny,
            grains,
            steps,
            precision,
            threads,
            json,
        } => {
            let r = granflow::coupling::bench::coupled(
                nx,
                ny,
                grains,
                steps,
                matches!(precision, Precision::F64),
                threads,
            )?;
            if json {
                println!("{}", serde_json::to_string(&r)?);
            } else {
                println!(
                    "coupled {}×{} {} with {} grains on {} threads: {:.1} MLUPS, {:.3e} grain steps/s, {:.2} s for {} steps ({} covered cells, {} DEM sub-steps per fluid step)",
                    r.nx, r.ny, r.precision, r.grains, r.threads, r.mlups, r.particle_steps_per_s, r.seconds, r.steps, r.covered_cells, r.subcycles
                );
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}
