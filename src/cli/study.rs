//! `granflow validate`, `sweep`, `biaxial` and `shear`.

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, Result};

use granflow::report::{Check, Fidelity};
use granflow::scenario::dem::spec::dem_memory;
use granflow::scenario::dem::DemScenario;
use granflow::scenario::validation;
use granflow::scenario::ScenarioFile;

use super::{with_progress, Out};

pub fn sweep(
    path: &Path,
    out: &Path,
    jobs: usize,
    checkpoint_every: Option<f64>,
) -> Result<ExitCode> {
    let stop = super::stop_on_signals()?;
    #[cfg(feature = "mpi")]
    let r = {
        use mpi::topology::Communicator;
        let (universe, _) = mpi::initialize_with_threading(mpi::Threading::Funneled)
            .context("MPI could not be initialised")?;
        let world = universe.world();
        if world.size() == 1 {
            granflow::sweep::run_sweep(path, out, jobs, checkpoint_every, stop)?
        } else {
            use granflow::sweep::ranks::run_sweep_on_ranks;
            match run_sweep_on_ranks(&world, path, out, jobs, checkpoint_every, stop)? {
                Some(r) => r,
                // The other ranks leave the report to rank 0.
                None => return Ok(ExitCode::SUCCESS),
            }
        }
    };
    #[cfg(not(feature = "mpi"))]
    let r = granflow::sweep::run_sweep(path, out, jobs, checkpoint_every, stop)?;
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
    for (name, list) in [("MPM", &r.fits.mpm_vs_dem), ("MPM×DEM", &r.fits.rve_vs_dem)] {
        for c in list {
            println!(
                "a = {:.2}: ΔL DEM {:.3}, {name} {:.3} ({:+.1} %)",
                c.a,
                c.dem,
                c.mpm,
                100.0 * c.mpm_excess
            );
        }
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

/// `granflow sweep FILE --list [--out DIR]`: the cases, numbered as `--case` takes them, and
/// with `DIR` where each stands.
pub fn sweep_list(path: &Path, out: Option<&Path>) -> Result<ExitCode> {
    let (_, cases) = granflow::sweep::read_sweep(path)?;
    let states = out.map(|o| granflow::sweep::case_states(&cases, o));
    for (k, c) in cases.iter().enumerate() {
        let labels: Vec<String> = c.labels.iter().map(|(p, v)| format!("{p}={v}")).collect();
        let state = states
            .as_ref()
            .map_or(String::new(), |s| format!("\t{}", s[k]));
        println!(
            "{k}\t{}\t{}\t{}{state}",
            c.name,
            c.solver.name(),
            labels.join(" ")
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `granflow sweep FILE --out DIR --case K`: one case, as a job of an array runs it.
pub fn sweep_case(
    path: &Path,
    out: &Path,
    which: &str,
    checkpoint_every: Option<f64>,
) -> Result<ExitCode> {
    let stop = super::stop_on_signals()?;
    let r = granflow::sweep::run_one_case(path, out, which, checkpoint_every, stop)?;
    match &r.outcome {
        Ok(_) => Ok(ExitCode::SUCCESS),
        Err(e) => {
            eprintln!("failed: {}: {e}", r.case.name);
            Ok(ExitCode::FAILURE)
        }
    }
}

/// `granflow biaxial`; `[σ₃, I, final strain]`; a periodic volume at the packing fraction
/// `periodic` when given, else the wall-bounded sample.
pub fn biaxial(
    path: &Path,
    out: Out,
    [confining, inertial_number, strain]: [f64; 3],
    grains: usize,
    prep_friction: Option<f64>,
    seed: Option<u64>,
    periodic: Option<f64>,
) -> Result<ExitCode> {
    use granflow::scenario::dem::biaxial::{run_biaxial_to, write_biaxial, BiaxialSpec};
    use granflow::scenario::dem::rve_biaxial::{run_rve_biaxial, RveBiaxialSpec};
    let s = DemScenario::from_file(path)?;
    if let Some(phi) = periodic {
        if prep_friction.is_some() {
            anyhow::bail!("--prep-friction applies to the wall-bounded sample only");
        }
        let spec = RveBiaxialSpec::from_scenario(
            &s,
            grains,
            confining,
            phi,
            inertial_number,
            strain,
            seed.unwrap_or(s.seed),
        )?;
        let out = out.claim(dem_memory(grains))?;
        eprintln!(
            "{}: periodic biaxial test, {grains} grains at φ = {phi}, σ₃ = {confining} Pa, I = {inertial_number}, to ε₁ = {strain} -> {}",
            s.name,
            out.display()
        );
        let total = (strain / spec.record_strain) as u64;
        let r = with_progress(total, "points", |p| run_rve_biaxial(&spec, p))
            .with_context(|| format!("periodic biaxial test of {} stopped", path.display()))?;
        write_biaxial(&r, confining, strain, out)?;
        println!("done: {}", r.done_line());
        return Ok(ExitCode::SUCCESS);
    }
    let spec = BiaxialSpec::from_scenario(
        &s,
        grains,
        confining,
        inertial_number,
        strain,
        prep_friction,
        seed,
    )?;
    let out = out.claim(dem_memory(grains))?;
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
pub fn shear(
    path: &Path,
    out: Out,
    pressure: f64,
    inertial_numbers: &[f64],
    grains: usize,
    strain: f64,
    seed: Option<u64>,
) -> Result<ExitCode> {
    use granflow::scenario::dem::shear::{run_mu_i_to, ShearSpec};
    let s = DemScenario::from_file(path)?;
    let specs = inertial_numbers
        .iter()
        .map(|&i| ShearSpec::from_scenario(&s, grains, pressure, i, strain, seed))
        .collect::<granflow::Result<Vec<_>>>()?;
    let out = out.claim(dem_memory(grains))?;
    eprintln!(
        "{}: periodic simple shear, {grains} grains, P = {pressure} Pa, I = {inertial_numbers:?}, \
         to γ = {strain} -> {}",
        s.name,
        out.display()
    );
    let r = with_progress(1000, "‰ of the shear", |p| run_mu_i_to(&specs, out, p))
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

pub fn validate(
    case: &str,
    json: bool,
    full: bool,
    figures: Option<&Path>,
    backend: granflow::lbm::Backend,
) -> Result<ExitCode> {
    if case == "list" {
        for c in validation::CASES {
            println!("{:<16} {}", c.name, c.description);
        }
        return Ok(ExitCode::SUCCESS);
    }
    let fidelity = if full { Fidelity::Full } else { Fidelity::Test };
    let names: Vec<&str> = if case == "all" && backend == granflow::lbm::Backend::Gpu {
        validation::ON_ANY_BACKEND.iter().map(|c| c.0).collect()
    } else if case == "all" {
        validation::CASES.iter().map(|c| c.name).collect()
    } else {
        vec![case]
    };
    if let Some(dir) = figures {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the figures folder {}", dir.display()))?;
    }
    let mut failed = 0;
    let (start, count) = (std::time::Instant::now(), names.len());
    for (k, name) in names.into_iter().enumerate() {
        if count > 1 {
            let so_far = start.elapsed().as_secs_f64();
            eprintln!("[{}/{count}] {name} ({so_far:.0} s so far)", k + 1);
        }
        match validation::run_on(name, fidelity, backend) {
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
