//! The column-collapse runner, one for every solid: deposit or build the column, release it,
//! follow it to rest, and write
//!
//! * `series.pvd` with the frames of the solid (and of the fluid, when there is one);
//! * `timeseries.csv`: `t`, `t_over_tc`, `runout`, `front`, `height`, then the solid's own
//!   columns (energies, pore pressure, …);
//! * `summary.json`: the solver-independent [`CollapseOutcome`] (the same keys for every
//!   solid, so the runs compare directly) and the solid's own keys.
//!
//! What differs between the solids is a [`Column`]: [`dem`] (grains), [`mpm`] (material
//! points), [`submerged`] (grains in a liquid). The loop is [`run_resumable`]: one time-series
//! row per `series_interval_tc`, a frame every `frame_interval_tc`, and the end when the
//! kinetic energy has stayed below `rest_kinetic_fraction` × the initial potential energy
//! above the floor for `rest_duration_tc` τ_c (and t ≥ 1 τ_c; reported as `rest_time_tc`), or
//! at `end_tc` τ_c. τ_c = √(H_i/g) with H_i the initial (deposited) height; the run-out
//! definitions are in each solid's module and [`crate::analysis::runout`].

pub mod dem;
pub mod mpm;
pub mod submerged;

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::analysis::runout::{CollapseOutcome, CollapseRecord, EnergyBudget};
use crate::exec::Progress;
use crate::io::{write_json, CsvWriter, PvdEntry, PvdSeries, VtkFormat};
use crate::scenario::checkpointing::Control;
use crate::scenario::Kind;
use crate::Result;

/// One time-series row of a collapsing column.
#[derive(Clone, Debug)]
pub struct Row {
    /// Run-out L(t) of the main mass (m, from the back wall).
    pub runout: f64,
    /// Front: the farthest point of any part of the solid (m).
    pub front: f64,
    /// Height H(t) of the main mass (m).
    pub height: f64,
    /// Kinetic energy the rest test compares with the initial potential energy (J).
    pub kinetic: f64,
    /// The solid's own columns, in the order of [`Column::columns`].
    pub values: Vec<f64>,
}

/// The final state of a run, for [`CollapseOutcome`].
#[derive(Clone, Copy, Debug)]
pub struct Tally {
    /// Steps of the solid taken (the coupled steps for a submerged run).
    pub steps: u64,
    /// Their size (s).
    pub dt: f64,
    /// Grains or material points.
    pub particles: usize,
    /// |E − E₀| / dissipated energy (NaN where the budget is not closed, e.g. in a liquid).
    pub energy_budget_error: f64,
    /// Where the released potential energy went.
    pub energy: EnergyBudget,
}

/// A collapsing solid as the runner drives it.
pub trait Column {
    /// What a frame needs from the measurement of its row (e.g. contact counts).
    type Shape;
    /// What `summary.json` holds beside the [`CollapseOutcome`].
    type Summary: Serialize;

    /// The time-series columns after `t, t_over_tc, runout, front, height`.
    fn columns(&self) -> &'static [&'static str];
    /// Simulated time since the release (s).
    fn time(&self) -> f64;
    /// Measure the state now: its time-series row and what a frame of it needs.
    fn measure(&mut self) -> Result<(Row, Self::Shape)>;
    /// Write frame `k` of the state measured as `shape` at time `t` into `dir` in the VTK
    /// `format`, listed in `pvd`.
    fn write_frame(
        &self,
        shape: &Self::Shape,
        format: &VtkFormat,
        dir: &Path,
        k: usize,
        t: f64,
        pvd: &mut PvdSeries,
    ) -> Result<()>;
    /// Advance by one time-series interval.
    fn advance(&mut self) -> Result<()>;
    /// Steps, particles and energy of the state measured last.
    fn tally(&self, shape: &Self::Shape) -> Tally;
    /// The summary: `collapse` and the solid's own keys.
    fn summary(&self, collapse: CollapseOutcome) -> Self::Summary;
}

/// The column and the output schedule of a run (SI; times in τ_c).
#[derive(Clone, Copy, Debug)]
pub struct Plan<'a> {
    /// Scenario name.
    pub name: &'a str,
    /// Initial width L_i (m).
    pub l_i: f64,
    /// Initial height H_i (m).
    pub h_i: f64,
    /// Gravity g (m/s²), for τ_c = √(H_i/g).
    pub gravity: f64,
    /// Initial potential energy above the floor (J), the scale of the rest test.
    pub potential: f64,
    /// Time-series rows every this many τ_c (the solid advances by as much between rows).
    pub series_interval_tc: f64,
    /// Frames every this many τ_c (rounded to whole rows).
    pub frame_interval_tc: f64,
    /// Stop at this time (τ_c).
    pub end_tc: f64,
    /// At rest when the kinetic energy stays below this fraction of `potential` …
    pub rest_kinetic_fraction: f64,
    /// … for this long (τ_c).
    pub rest_duration_tc: f64,
    /// How the frames are written (the scenario's `[vtk]`).
    pub vtk: VtkFormat,
}

impl Plan<'_> {
    /// τ_c = √(H_i/g) (s).
    pub fn tau_c(&self) -> f64 {
        (self.h_i / self.gravity).sqrt()
    }
}

/// What the runner itself has done by a time-series row, saved with the column in a
/// checkpoint: rows and frames written, the rest test's clock, the run-out history, the
/// length of the time series and the frames listed, and the wall time spent.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Bookkeeping {
    row: u64,
    frame: usize,
    rest_since: Option<f64>,
    history: Vec<(f64, f64)>,
    series_bytes: u64,
    pvd: Vec<PvdEntry>,
    wall_time_s: f64,
}

/// A collapse checkpoint: the column (its solver state and own bookkeeping), what its plan
/// was derived from (deposited height, potential energy), and the runner's [`Bookkeeping`].
#[derive(Serialize, Deserialize)]
pub struct Saved<C> {
    /// The column.
    pub column: C,
    /// Initial height H_i (m).
    pub h_i: f64,
    /// Initial potential energy above the floor (J).
    pub potential: f64,
    run: Bookkeeping,
}

/// A column a checkpoint can hold: what is saved of it, and what is read back (the same
/// encoding), from which the caller of [`run_resumable`] rebuilds it.
pub trait Resumable: Column {
    /// What a checkpoint holds (the column itself, by reference, for a DEM or MPM column).
    type Saved<'s>: Serialize
    where
        Self: 's;
    /// The same, read back.
    type Loaded: DeserializeOwned;
    /// The column's state now.
    fn saved(&self) -> Self::Saved<'_>;
}

/// Run a `kind` collapse that checkpoints, stops and resumes as `control` says: the column
/// comes from the newest checkpoint in `out_dir`, through `restore`, when the run resumes,
/// otherwise from `start` (deposition and release); `plan_of` derives the plan from H_i and
/// the potential energy.
pub fn run_resumable<'p, C: Resumable>(
    kind: Kind,
    start: impl FnOnce() -> Result<(C, Plan<'p>)>,
    restore: impl FnOnce(C::Loaded) -> Result<C>,
    plan_of: impl FnOnce(f64, f64) -> Plan<'p>,
    out_dir: &Path,
    mut control: Control,
    progress: Progress,
) -> Result<C::Summary> {
    crate::io::run_dir::create(out_dir)?;
    let (column, plan, resumed) = match control.load::<Saved<C::Loaded>>(out_dir, kind)? {
        Some(l) => {
            let s = l.state;
            (restore(s.column)?, plan_of(s.h_i, s.potential), Some(s.run))
        }
        None => {
            let (column, plan) = start()?;
            (column, plan, None)
        }
    };
    let save = |c: &C, run: &Bookkeeping| {
        let saved = Saved {
            column: c.saved(),
            h_i: plan.h_i,
            potential: plan.potential,
            run: run.clone(),
        };
        control.save(out_dir, kind, run.row, c.time(), &saved)
    };
    let hooks = Hooks {
        control: &control,
        save: &save,
        resumed,
    };
    let summary = run_loop(column, &plan, out_dir, hooks, progress)?;
    crate::io::checkpoint::remove_all(out_dir)?;
    Ok(summary)
}

/// Writes a checkpoint of a column and the runner's bookkeeping; returns the file.
type Save<'h, C> = &'h dyn Fn(&C, &Bookkeeping) -> Result<PathBuf>;

/// How [`run_loop`] checkpoints: when and how to save, and where it resumes from.
struct Hooks<'h, C> {
    control: &'h Control,
    save: Save<'h, C>,
    resumed: Option<Bookkeeping>,
}

fn run_loop<C: Column>(
    mut column: C,
    plan: &Plan,
    out_dir: &Path,
    hooks: Hooks<C>,
    progress: Progress,
) -> Result<C::Summary> {
    crate::io::run_dir::create(out_dir)?;
    let tau_c = plan.tau_c();
    let frame_every = ((plan.frame_interval_tc / plan.series_interval_tc).round() as u64).max(1);
    let mut header = vec!["t", "t_over_tc", "runout", "front", "height"];
    header.extend_from_slice(column.columns());
    let series = out_dir.join("timeseries.csv");
    let (mut csv, mut pvd, mut b) = match hooks.resumed {
        Some(b) => (
            CsvWriter::reopen(&series, header.len(), b.series_bytes)?,
            PvdSeries::resume(out_dir, b.pvd.clone()),
            b,
        ),
        None => (
            CsvWriter::create(&series, &header)?,
            PvdSeries::new(out_dir),
            Bookkeeping::default(),
        ),
    };
    let rest_limit = plan.rest_kinetic_fraction * plan.potential;
    let mut at_rest = false;
    let t_run = Instant::now();
    let row_seconds = plan.series_interval_tc * tau_c;
    let mut values = Vec::with_capacity(header.len());
    let (mut last, mut height) = (None, 0.0);
    let mut last_checkpoint = None;
    // Failed writes (a full disk) end the run naming its last frame and checkpoint.
    let looped = (|| -> Result<()> {
        loop {
            let t = column.time();
            let (r, shape) = column.measure()?;
            b.history.push((t, r.runout));
            values.clear();
            values.extend([t, t / tau_c, r.runout, r.front, r.height]);
            values.extend_from_slice(&r.values);
            csv.row(&values)?;
            if b.row % frame_every == 0 {
                column.write_frame(&shape, &plan.vtk, out_dir, b.frame, t, &mut pvd)?;
                b.frame += 1;
            }
            b.row += 1;
            if r.kinetic < rest_limit {
                let since = *b.rest_since.get_or_insert(t);
                if t >= tau_c && t - since >= plan.rest_duration_tc * tau_c {
                    at_rest = true;
                }
            } else {
                b.rest_since = None;
            }
            (last, height) = (Some(shape), r.height);
            progress((1e3 * t / tau_c) as u64, (1e3 * plan.end_tc) as u64);
            if at_rest || t >= plan.end_tc * tau_c {
                break;
            }
            column.advance()?;
            let signal = hooks.control.stop_signal();
            if hooks.control.due(b.row, row_seconds) || signal.is_some() {
                b.series_bytes = csv.bytes_written();
                b.pvd = pvd.entries().to_vec();
                let wall = b.wall_time_s;
                b.wall_time_s += t_run.elapsed().as_secs_f64();
                let path = (hooks.save)(&column, &b)?;
                last_checkpoint = Some(path.clone());
                b.wall_time_s = wall;
                if let Some(signal) = signal {
                    // The state now, for a look; the resumed run writes its own frame of this
                    // number when one is due.
                    let (_, shape) = column.measure()?;
                    let t = column.time();
                    column.write_frame(&shape, &plan.vtk, out_dir, b.frame, t, &mut pvd)?;
                    return Err(hooks.control.interrupted(signal, b.row, t, path, out_dir));
                }
            }
        }
        Ok(())
    })();
    if let Err(e) = looped {
        let frame = pvd.entries().last().map(|f| f.file.as_str());
        return Err(hooks
            .control
            .write_failed(e, out_dir, frame, last_checkpoint.as_deref()));
    }
    let last = last.expect("the loop measures the column at least once");
    let wall_time_s = b.wall_time_s + t_run.elapsed().as_secs_f64();
    let t_end = column.time();
    if (b.row - 1) % frame_every != 0 {
        column.write_frame(&last, &plan.vtk, out_dir, b.frame, t_end, &mut pvd)?;
    }
    let tally = column.tally(&last);
    let collapse = CollapseOutcome::from(CollapseRecord {
        name: plan.name,
        l_i: plan.l_i,
        h_i: plan.h_i,
        gravity: plan.gravity,
        history: &b.history,
        h_f: height,
        rest_since: b.rest_since,
        at_rest,
        t_end,
        dt: tally.dt,
        steps: tally.steps,
        wall_time_s,
        particles: tally.particles,
        energy_budget_error: tally.energy_budget_error,
        energy: tally.energy,
    });
    let summary = column.summary(collapse);
    write_json(&out_dir.join("summary.json"), &summary)?;
    Ok(summary)
}

/// Steps of `dt` per time-series row: those that cover `interval_tc` τ_c (at least one).
pub(crate) fn steps_per_row(interval_tc: f64, tau_c: f64, dt: f64) -> u64 {
    ((interval_tc * tau_c / dt).ceil() as u64).max(1)
}

/// |**g**| (m/s²) of a collapse file's `gravity` = [g_x, g_y], checked: finite and pointing into
/// the floor (g_y < 0; the floor is y = 0). A tilted **g** = |g| (sin θ, −cos θ) is a collapse on
/// a plane inclined by θ, downhill towards +x for θ > 0.
pub fn collapse_gravity(g: [f64; 2]) -> Result<f64> {
    if !(g.iter().all(|v| v.is_finite()) && g[1] < 0.0) {
        return Err(crate::Error::config(
            "gravity",
            format!(
                "a column collapse needs a finite gravity pointing into the floor (g_y < 0), \
                 got [{}, {}]",
                g[0], g[1]
            ),
        ));
    }
    Ok(g[0].hypot(g[1]))
}

/// The rest test's energy scale (J): Σ m |**g**| y, the potential energy above the floor of
/// masses `m` at heights `y` under gravity of magnitude `g` (for gravity along −y, the
/// potential energy itself).
pub fn rest_scale(m: &[f64], y: &[f64], g: f64) -> f64 {
    m.iter().zip(y).map(|(m, y)| m * g * y).sum()
}
