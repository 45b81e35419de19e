//! The `granflow` command line: parse the arguments and hand each command to [`cli`], which
//! calls the scenario storey of the library. Nothing here computes physics.

mod cli;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand, ValueEnum};
use granflow::scenario::overrides::Override;

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
        /// Change a key of the file, e.g. --set time.end=2.0 (a dotted path; repeat for more;
        /// docs/scenario-format.md, "--set").
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<Override>,
    },
    /// Run a scenario and write series.pvd + frames, timeseries.csv and summary.json.
    Run {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Change a key of the file, e.g. --set grain_contact.friction=0.4 (a dotted path;
        /// repeat for more); the output folder's scenario.toml records it.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<Override>,
        /// Where the lattice steps: of a fluid file (the same as --set lbm.backend=…) or a
        /// submerged one (--set coupling.backend=…); gpu needs a build with --features gpu.
        #[arg(long, value_enum)]
        backend: Option<Backend>,
        /// Output folder (created if needed; one that holds an earlier run is refused unless
        /// --force).
        #[arg(long)]
        out: PathBuf,
        /// Replace an earlier run in the output folder (everything in that folder is deleted;
        /// only a folder granflow wrote is ever emptied).
        #[arg(long)]
        force: bool,
        /// With every frame, write the grains of the representative volume of the material
        /// point nearest X,Y (m) in the initial column as volume_<k>_<frame>.vtu (MPM files
        /// with model = "rve"; repeat for more volumes).
        #[arg(long = "rve-frames", value_name = "X,Y", value_parser = parse_place)]
        rve_frames: Vec<[f64; 2]>,
        /// Save the run's state every SECONDS of simulated time (the newest two checkpoints
        /// are kept, and removed when the run completes), so that `granflow resume` can
        /// continue it after a crash or a kill. SIGINT or SIGTERM always save one before the
        /// run stops.
        #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
        checkpoint_every: Option<f64>,
    },
    /// Continue a run from the newest checkpoint in its output folder (one stopped by SIGINT,
    /// SIGTERM, a crash or a kill), with the scenario it keeps there; the outputs end as an
    /// uninterrupted run's would.
    Resume {
        /// The run's output folder.
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
        /// Where the fluid cases step; with gpu, `all` runs the fluid-only cases (a build with
        /// --features gpu).
        #[arg(long, value_enum, default_value_t = Backend::Cpu)]
        backend: Backend,
    },
    /// Run a column-collapse sweep (cases in parallel, resumable) and write sweep.csv,
    /// fits.json and the figures. Under `mpirun` (a build with the feature `mpi`) the cases
    /// are spread over the ranks.
    Sweep {
        /// Sweep file (TOML): base scenario per solver and the values to vary.
        sweep: PathBuf,
        /// Output folder: one sub-folder per case, plus the tables and figures.
        #[arg(long, required_unless_present = "list")]
        out: Option<PathBuf>,
        /// List the cases (number, name, solver, varied values; with --out, whether each is
        /// done) and run nothing.
        #[arg(long, conflicts_with_all = ["case", "jobs", "checkpoint_every"])]
        list: bool,
        /// Run only this case, by number (from 0, as --list prints) or name, e.g. a job
        /// array's task id; a later plain `granflow sweep` reuses it and writes the tables.
        #[arg(long, value_name = "K", conflicts_with = "jobs")]
        case: Option<String>,
        /// Cases run at the same time (0: one per core), on each MPI rank under mpirun.
        #[arg(long, default_value_t = 0)]
        jobs: usize,
        /// Save each case's state every SECONDS of simulated time, so that a sweep run again
        /// after a crash or a kill continues its unfinished cases; SIGINT or SIGTERM always
        /// save one before the cases stop.
        #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
        checkpoint_every: Option<f64>,
    },
    /// Biaxial compression of a DEM collapse scenario's material: its peak and critical-state
    /// friction angles, the φ a Mohr–Coulomb continuum of that material needs. Writes
    /// biaxial.csv, summary.json and biaxial.svg.
    Biaxial {
        /// DEM collapse scenario (TOML): its grains, contact laws and deposition are used.
        scenario: PathBuf,
        /// Output folder (created if needed; one that holds an earlier run is refused unless
        /// --force).
        #[arg(long)]
        out: PathBuf,
        /// Replace an earlier run in the output folder (everything in that folder is deleted;
        /// only a folder granflow wrote is ever emptied).
        #[arg(long)]
        force: bool,
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
        /// Test a bi-periodic representative volume (no walls) prepared at σ₃ and this
        /// packing fraction, instead of the wall-bounded sample.
        #[arg(long)]
        periodic_packing_fraction: Option<f64>,
    },
    /// Periodic simple shear (Lees–Edwards) of a DEM collapse scenario's material at a set of
    /// inertial numbers and a fixed normal stress: its μ(I) and solid fraction φ(I), and the fit
    /// sin φ(I) = sin φ_s + (sin φ_2 − sin φ_s)/(I_0/I + 1) a plane-strain continuum of the
    /// material takes. Writes mu_i.csv, shear_<k>.csv, summary.json and mu_i.svg.
    Shear {
        /// DEM collapse scenario (TOML): its grains and grain–grain contact laws are used.
        scenario: PathBuf,
        /// Output folder (created if needed; one that holds an earlier run is refused unless
        /// --force).
        #[arg(long)]
        out: PathBuf,
        /// Replace an earlier run in the output folder (everything in that folder is deleted;
        /// only a folder granflow wrote is ever emptied).
        #[arg(long)]
        force: bool,
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
    /// Print the JSON Schema of a kind of scenario file (for editors' completion and checks
    /// of the TOML files), or with --markdown its key reference (docs/scenario-keys.md is
    /// `granflow schema all --markdown`).
    Schema {
        /// The kind of scenario file (its `kind` key); `all` only with --markdown.
        #[arg(value_enum)]
        kind: SchemaKind,
        /// Print the Markdown key reference (a table per TOML table) instead of the schema.
        #[arg(long)]
        markdown: bool,
    },
    /// Throughput benchmarks.
    Bench {
        #[command(subcommand)]
        which: Bench,
    },
}

/// The kinds `granflow schema` describes.
#[derive(Clone, Copy, ValueEnum)]
enum SchemaKind {
    /// A lattice Boltzmann flow.
    Fluid,
    /// A DEM column collapse.
    Dem,
    /// A GIMPM column collapse.
    Mpm,
    /// A submerged (LBM–DEM) column collapse.
    Submerged,
    /// A DEM problem of any geometry (regions, walls, gates, outlets).
    Granular,
    /// An MPM problem of any geometry (domain, sides, regions, tilting gravity).
    Continuum,
    /// A study over many collapse scenarios.
    Sweep,
    /// Every kind (with --markdown only).
    All,
}

impl SchemaKind {
    /// The scenario kind; `None` for `all`.
    fn kind(self) -> Option<granflow::scenario::Kind> {
        use granflow::scenario::Kind;
        match self {
            SchemaKind::Fluid => Some(Kind::Fluid),
            SchemaKind::Dem => Some(Kind::Dem),
            SchemaKind::Mpm => Some(Kind::Mpm),
            SchemaKind::Submerged => Some(Kind::Submerged),
            SchemaKind::Granular => Some(Kind::Granular),
            SchemaKind::Continuum => Some(Kind::Continuum),
            SchemaKind::Sweep => Some(Kind::Sweep),
            SchemaKind::All => None,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Precision {
    F32,
    F64,
}

/// Where the lattice steps.
#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Backend {
    /// The CPU (rayon threads).
    Cpu,
    /// A GPU through wgpu (a build with `--features gpu`).
    Gpu,
}

impl From<Backend> for granflow::lbm::Backend {
    fn from(b: Backend) -> Self {
        match b {
            Backend::Cpu => granflow::lbm::Backend::Cpu,
            Backend::Gpu => granflow::lbm::Backend::Gpu,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Collision {
    Bgk,
    Mrt,
}

#[derive(Subcommand)]
pub(crate) enum Bench {
    /// The MPM×DEM material: µs per point per MPM step and ns per grain per DEM sub-step of
    /// the representative volume of an MPM scenario with `model = "rve"`.
    Rve {
        /// MPM scenario (TOML) with `[material] model = "rve"`.
        scenario: PathBuf,
        /// Points (each a copy of the prepared volume).
        #[arg(long, default_value_t = 64)]
        points: usize,
        /// MPM steps per repeat.
        #[arg(long, default_value_t = 50)]
        steps: u64,
        /// Threads (0: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Timed repeats; the median is reported.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
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
        /// Where the lattice steps; on the GPU the roofline is the device's own copy
        /// bandwidth.
        #[arg(long, value_enum, default_value_t = Backend::Cpu)]
        backend: Backend,
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
        /// Where the lattice steps (the grains step on the CPU).
        #[arg(long, value_enum, default_value_t = Backend::Cpu)]
        backend: Backend,
        /// Threads (0: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`granflow validate list | head -1`)
    // panics; the default action ends the process quietly, as other command-line tools do.
    // SAFETY: called first, before any other thread exists; setting a signal's disposition to
    // its default has no other effect.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    match real_main() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            // A run stopped by a signal exits as the shell reports a process it killed.
            match e.chain().find_map(|c| c.downcast_ref::<granflow::Error>()) {
                Some(granflow::Error::Interrupted { signal, .. }) => {
                    ExitCode::from((128 + signal) as u8)
                }
                _ => ExitCode::FAILURE,
            }
        }
    }
}

/// A place `X,Y` in metres.
fn parse_place(s: &str) -> std::result::Result<[f64; 2], String> {
    let xy: Vec<f64> = s
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| format!("`{s}`: {e}"))?;
    match xy[..] {
        [x, y] if x.is_finite() && y.is_finite() => Ok([x, y]),
        _ => Err(format!("`{s}`: expected two finite numbers X,Y in metres")),
    }
}

fn out_of(dir: &std::path::Path, force: bool) -> cli::Out<'_> {
    cli::Out { dir, force }
}

fn real_main() -> Result<ExitCode> {
    match Cli::parse().command {
        Command::Check { scenario, set } => cli::run::check(&scenario, &set),
        Command::Run {
            scenario,
            mut set,
            backend,
            out,
            force,
            rve_frames,
            checkpoint_every,
        } => {
            if let Some(b) = backend {
                set.push(cli::run::backend_override(&scenario, b.into())?);
            }
            cli::run::run(
                &scenario,
                &set,
                out_of(&out, force),
                &rve_frames,
                checkpoint_every,
            )
        }
        Command::Resume { out } => cli::run::resume(&out),
        Command::Validate {
            case,
            json,
            full,
            figures,
            backend,
        } => cli::study::validate(&case, json, full, figures.as_deref(), backend.into()),
        Command::Sweep {
            sweep,
            out,
            list,
            case,
            jobs,
            checkpoint_every,
        } => match (out, list) {
            (out, true) => cli::study::sweep_list(&sweep, out.as_deref()),
            (Some(out), false) => match case {
                Some(k) => cli::study::sweep_case(&sweep, &out, &k, checkpoint_every),
                None => cli::study::sweep(&sweep, &out, jobs, checkpoint_every),
            },
            (None, false) => unreachable!("clap requires --out unless --list"),
        },
        Command::Biaxial {
            scenario,
            out,
            force,
            confining,
            grains,
            inertial_number,
            strain,
            prep_friction,
            seed,
            periodic_packing_fraction,
        } => cli::study::biaxial(
            &scenario,
            out_of(&out, force),
            [confining, inertial_number, strain],
            grains,
            prep_friction,
            seed,
            periodic_packing_fraction,
        ),
        Command::Shear {
            scenario,
            out,
            force,
            pressure,
            inertial_numbers,
            grains,
            strain,
            seed,
        } => cli::study::shear(
            &scenario,
            out_of(&out, force),
            pressure,
            &inertial_numbers,
            grains,
            strain,
            seed,
        ),
        Command::Schema { kind, markdown } => cli::schema::schema(kind.kind(), markdown),
        Command::Bench { which } => cli::bench::bench(which),
    }
}
