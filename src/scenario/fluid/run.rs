//! `granflow run`: advance a fluid scenario and write its outputs.
//!
//! Output folder:
//! * `series.pvd` — ParaView collection; one `fluid_NNNNNN.vti` per frame with cell data
//!   `density` (kg/m³), `pressure` (gauge, Pa), `velocity` (m/s), `vorticity` (1/s), `solid`;
//! * `timeseries.csv` — t, step, mass, kinetic energy, peak speed, obstacle loads, probes;
//! * `summary.json` — derived quantities, final loads and coefficients, wall time, throughput,
//!   and `status` (`"completed"` or the instability message).
//!
//! Every frame is written to a temporary name and renamed; a run that goes unstable (NaN,
//! ρ ≤ 0, Mach > 0.5) stops with [`Error::Unstable`], keeping the frames already written.
//! With `--checkpoint-every` the run saves its state (`checkpoint_<step>.ckpt`, the newest two
//! kept, removed when the run completes); asked to stop, it saves one and writes the current
//! frame; resumed, it cuts the time series back to the checkpoint and continues
//! ([`crate::scenario::checkpointing`]).

use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use crate::analysis::spectrum::dominant_frequency;
use crate::io::{
    write_json, write_vti, CsvWriter, Field, ImageGrid, PvdEntry, PvdSeries, VtkFormat,
};
use crate::lbm::{Fluid, LbmState, Macroscopic, STOP_MACH};
use crate::scenario::checkpointing::Control;
use crate::scenario::fluid::{Derived, Scenario};
use crate::scenario::Kind;
use crate::Result;

/// Most steps between two stability checks.
const CHECK_EVERY: u64 = 500;

/// Final loads on one obstacle.
#[derive(Clone, Debug, Serialize)]
pub struct ObstacleSummary {
    /// Obstacle name.
    pub name: String,
    /// Force per unit depth (N/m), last step.
    pub force: [f64; 2],
    /// Torque per unit depth (N·m/m), last step.
    pub torque: f64,
    /// Force coefficients 2F/(ρU²L) with the reference U and L.
    pub coefficients: [f64; 2],
    /// Strouhal number f L/U of the lift (y-force) history over the second half of the run,
    /// by FFT ([`dominant_frequency`]), if the lift oscillates by more than 1 % of the force.
    pub strouhal: Option<f64>,
}

/// What `summary.json` holds.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub name: String,
    /// `"completed"` or the reason the run stopped.
    pub status: String,
    /// Derived lattice quantities.
    pub derived: Derived,
    /// Steps taken.
    pub steps: u64,
    /// Simulated time in s.
    pub time: f64,
    /// Frames written.
    pub frames: usize,
    /// Relative change of total mass over the run.
    pub mass_drift: f64,
    /// Obstacle loads.
    pub obstacles: Vec<ObstacleSummary>,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// Million lattice-cell updates per second.
    pub mlups: f64,
}

/// What a fluid run saves in a checkpoint: the fluid's state and the bookkeeping of its
/// outputs, enough to continue it bit for bit.
#[derive(serde::Serialize, serde::Deserialize)]
struct Saved {
    lbm: LbmState,
    frames: usize,
    series_bytes: u64,
    pvd: Vec<PvdEntry>,
    lift: Vec<f64>,
    mass0: f64,
    wall_seconds: f64,
}

/// Run `scenario`, writing into `out` (created if needed), checkpointing, stopping and
/// resuming as `control` says. Returns the summary, which is also written, or the error
/// that stopped the run (after writing the summary with it).
pub fn run(
    scenario: &Scenario,
    out: &Path,
    mut control: Control,
    progress: crate::exec::Progress,
) -> Result<Summary> {
    let (mut fluid, derived) = scenario.build()?;
    crate::io::run_dir::create(out)?;
    let names: Vec<String> = scenario
        .lattice_obstacles(&derived.units)
        .into_iter()
        .map(|o| o.name)
        .collect();
    let mut macro_ = Macroscopic::default();
    let (mut state, mut lift, mass0, wall0) = match control.load::<Saved>(out, Kind::Fluid)? {
        Some(saved) => {
            let saved = saved.state;
            let state = Outputs::resume(scenario, &derived, out, &saved)?;
            fluid.set_state(saved.lbm)?;
            (state, saved.lift, saved.mass0, saved.wall_seconds)
        }
        None => {
            let mut state = Outputs::create(scenario, &derived, out)?;
            state.row(fluid.as_ref())?;
            fluid.macroscopic(&mut macro_);
            state.write_frame(&macro_, 0.0)?;
            (state, Vec::new(), fluid.total_mass(), 0.0)
        }
    };
    let start = Instant::now();
    let total = derived.steps;
    let dt = derived.units.dt;
    let checkpoint_every = control.every_steps(dt).unwrap_or(total);
    let mut result = Ok(());
    let mut last_checkpoint = None;
    // The loop's own errors are failed writes (a full disk): they end the run at once.
    let looped = (|| -> Result<()> {
        while fluid.step_count() < total {
            let s = fluid.step_count();
            let next = [
                next_multiple(s, derived.series_every),
                next_multiple(s, derived.frame_every),
                next_multiple(s, CHECK_EVERY),
                next_multiple(s, checkpoint_every),
                total,
            ]
            .into_iter()
            .min()
            .unwrap_or(total);
            fluid.steps(next - s);
            let s = fluid.step_count();
            if let Err(e) = fluid.check_stable(STOP_MACH) {
                result = Err(e);
                break;
            }
            let row = s % derived.series_every == 0 || s == total;
            if row {
                state.row(fluid.as_ref())?;
                if s * 2 >= total {
                    lift.push(fluid.obstacle_loads().0.first().map_or(0.0, |f| f[1]));
                }
            }
            let frame = s % derived.frame_every == 0 || s == total;
            if frame {
                fluid.macroscopic(&mut macro_);
                state.write_frame(&macro_, s as f64 * dt)?;
            }
            let signal = control.stop_signal().filter(|_| s < total);
            if (control.due(s, dt) && s < total) || signal.is_some() {
                let saved = Saved {
                    lbm: fluid.state(),
                    frames: state.frames,
                    series_bytes: state.series.bytes_written(),
                    pvd: state.pvd.entries().to_vec(),
                    lift: lift.clone(),
                    mass0,
                    wall_seconds: wall0 + start.elapsed().as_secs_f64(),
                };
                let path = control.save(out, Kind::Fluid, s, s as f64 * dt, &saved)?;
                last_checkpoint = Some(path.clone());
                if let Some(signal) = signal {
                    // The fields as they are now, for a look; the resumed run writes its own
                    // frame of this number when one is due.
                    if !frame {
                        fluid.macroscopic(&mut macro_);
                        state.write_frame(&macro_, s as f64 * dt)?;
                    }
                    result = Err(control.interrupted(signal, s, s as f64 * dt, path, out));
                    break;
                }
            }
            progress(s, total);
        }
        Ok(())
    })();
    if let Err(e) = looped {
        let frame = state.pvd.entries().last().map(|f| f.file.as_str());
        return Err(control.write_failed(e, out, frame, last_checkpoint.as_deref()));
    }
    let wall = wall0 + start.elapsed().as_secs_f64();
    let cells = (derived.cells[0] * derived.cells[1]) as f64;
    let (forces, torques) = fluid.obstacle_loads();
    let u = &derived.units;
    let (uref, lref, rho) = (
        scenario.reference.velocity,
        scenario.reference.length,
        scenario.fluid.density,
    );
    let series_dt = derived.series_every as f64 * u.dt;
    let obstacles = names
        .into_iter()
        .enumerate()
        .map(|(k, name)| {
            let f = [u.force_to_si(forces[k][0]), u.force_to_si(forces[k][1])];
            let q = 0.5 * rho * uref * uref * lref;
            ObstacleSummary {
                name,
                force: f,
                torque: u.torque_to_si(torques[k]),
                coefficients: [f[0] / q, f[1] / q],
                strouhal: (k == 0 && oscillates(&lift, forces[k][0].hypot(forces[k][1])))
                    .then(|| dominant_frequency(&lift, series_dt))
                    .flatten()
                    .map(|freq| freq * lref / uref),
            }
        })
        .collect();
    let summary = Summary {
        name: scenario.name.clone(),
        status: match &result {
            Ok(()) => "completed".into(),
            Err(e) => e.to_string(),
        },
        derived: derived.clone(),
        steps: fluid.step_count(),
        time: fluid.step_count() as f64 * u.dt,
        frames: state.frames,
        mass_drift: fluid.total_mass() / mass0 - 1.0,
        obstacles,
        wall_seconds: wall,
        mlups: cells * fluid.step_count() as f64 / wall / 1e6,
    };
    write_json(&out.join("summary.json"), &summary)?;
    if result.is_ok() {
        crate::io::checkpoint::remove_all(out)?;
    }
    result.map(|()| summary)
}

/// Does a lift history oscillate? Peak-to-peak above 1 % of the force magnitude `scale`, so
/// that a steady wake's round-off is not reported as a shedding frequency.
fn oscillates(lift: &[f64], scale: f64) -> bool {
    let (lo, hi) = lift
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    lift.len() >= 8 && hi - lo > 0.01 * scale
}

fn next_multiple(s: u64, every: u64) -> u64 {
    (s / every + 1) * every
}

/// The open output files of a run.
struct Outputs {
    dir: std::path::PathBuf,
    derived: Derived,
    rho0: f64,
    series: CsvWriter,
    pvd: PvdSeries,
    probes: Vec<usize>,
    frames: usize,
    vtk: VtkFormat,
}

impl Outputs {
    fn create(scenario: &Scenario, derived: &Derived, dir: &Path) -> Result<Self> {
        let header = Self::header(scenario);
        let header: Vec<&str> = header.iter().map(String::as_str).collect();
        let series = CsvWriter::create(&dir.join("timeseries.csv"), &header)?;
        Ok(Self::with(
            scenario,
            derived,
            dir,
            series,
            PvdSeries::new(dir),
            0,
        ))
    }

    /// The outputs of a run resumed from `saved`: the time series cut back to its length then
    /// and appended to, the frames it had.
    fn resume(scenario: &Scenario, derived: &Derived, dir: &Path, saved: &Saved) -> Result<Self> {
        let columns = Self::header(scenario).len();
        let series = CsvWriter::reopen(&dir.join("timeseries.csv"), columns, saved.series_bytes)?;
        let pvd = PvdSeries::resume(dir, saved.pvd.clone());
        Ok(Self::with(
            scenario,
            derived,
            dir,
            series,
            pvd,
            saved.frames,
        ))
    }

    fn with(
        scenario: &Scenario,
        derived: &Derived,
        dir: &Path,
        series: CsvWriter,
        pvd: PvdSeries,
        frames: usize,
    ) -> Self {
        Outputs {
            dir: dir.to_path_buf(),
            derived: derived.clone(),
            rho0: scenario.fluid.density,
            series,
            pvd,
            probes: scenario
                .probes
                .iter()
                .map(|p| scenario.cell_at(derived, p.position))
                .collect(),
            frames,
            vtk: scenario.vtk,
        }
    }

    /// The time series' column names.
    fn header(scenario: &Scenario) -> Vec<String> {
        let mut header: Vec<String> = ["t", "step", "mass", "kinetic_energy", "max_speed"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        for ob in &scenario.obstacles {
            let name = match ob {
                crate::scenario::fluid::ObstacleSpec::Circle { name, .. }
                | crate::scenario::fluid::ObstacleSpec::Rectangle { name, .. }
                | crate::scenario::fluid::ObstacleSpec::Polygon { name, .. } => name,
            };
            header.extend([
                format!("{name}_fx"),
                format!("{name}_fy"),
                format!("{name}_torque"),
            ]);
        }
        for p in &scenario.probes {
            header.extend([
                format!("{}_p", p.name),
                format!("{}_ux", p.name),
                format!("{}_uy", p.name),
            ]);
        }
        header
    }

    /// Append a time-series row (sums and probes reduced where the fluid lives).
    fn row(&mut self, fluid: &dyn Fluid) -> Result<()> {
        let u = self.derived.units;
        let o = fluid.observe(&self.probes);
        let t = fluid.step_count() as f64 * u.dt;
        let cell_area = u.dx * u.dx;
        let v = u.velocity_to_si(1.0);
        let mut row = vec![
            t,
            fluid.step_count() as f64,
            o.mass * self.rho0 * cell_area,
            o.kinetic_energy * self.rho0 * cell_area * v * v,
            o.max_speed * v,
        ];
        let (forces, torques) = fluid.obstacle_loads();
        for (f, tq) in forces.iter().zip(&torques) {
            row.extend([
                u.force_to_si(f[0]),
                u.force_to_si(f[1]),
                u.torque_to_si(*tq),
            ]);
        }
        for &(rho, ux, uy) in &o.probes {
            row.extend([u.pressure_to_si(rho), ux * v, uy * v]);
        }
        self.series.row(&row)
    }

    fn write_frame(&mut self, m: &Macroscopic, t: f64) -> Result<()> {
        let u = self.derived.units;
        let v = u.velocity_to_si(1.0);
        let density: Vec<f64> = m.rho.iter().map(|&r| u.density_to_si(r)).collect();
        let pressure: Vec<f64> = m.rho.iter().map(|&r| u.pressure_to_si(r)).collect();
        let velocity: Vec<[f64; 2]> =
            m.ux.iter()
                .zip(&m.uy)
                .map(|(a, b)| [a * v, b * v])
                .collect();
        let vorticity: Vec<f64> = m.vorticity().into_iter().map(|w| u.rate_to_si(w)).collect();
        let solid: Vec<f64> = m.solid.iter().map(|&s| if s { 1.0 } else { 0.0 }).collect();
        let grid = ImageGrid {
            nx: m.nx,
            ny: m.ny,
            origin: [0.0, 0.0],
            spacing: [u.dx, u.dx],
        };
        let file = format!("fluid_{:06}.vti", self.frames);
        write_vti(
            &self.dir.join(&file),
            &grid,
            &[
                Field::scalar("density", &density),
                Field::scalar("pressure", &pressure),
                Field::vector("velocity", &velocity),
                Field::scalar("vorticity", &vorticity),
                Field::scalar("solid", &solid),
            ],
            &self.vtk,
        )?;
        self.pvd.add(t, 0, &file)?;
        self.frames += 1;
        Ok(())
    }
}
