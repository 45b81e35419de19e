//! Runner of the granular scenario ([`GranularScenario`]): settle (if asked), release, advance
//! until `time.end` or until no grain is left, and write
//!
//! * `series.pvd` with, per frame, `grains_NNNNNN.vtu` and `contacts_NNNNNN.vtu` (the arrays
//!   of the column collapse's frames, [`crate::scenario::collapse::dem::write_frame`]);
//! * `timeseries.csv`: `t` (s after the release), `grains` (left), `discharged` (grains
//!   removed by the outlets since the release), `discharged_mass` (kg), `kinetic_energy` (J,
//!   translational and rotational), `contacts` (touching pairs);
//! * `summary.json` ([`GranularSummary`]);
//! * `profile.csv` when the scenario has a `[profile]` ([`Profile::write`]).
//!
//! Outlets are applied every [`OUTLET_STEPS`] steps: a grain whose centre is inside one is
//! removed ([`Dem::remove_grains`]), its mass added to the discharge.
//!
//! The discharge rate W (kg/s) is the least-squares slope of the discharged mass against time
//! over the rows where it lies between [`RATE_WINDOW`] of the mass present at the release
//! (the steady part of a silo's discharge: after the start-up, before the heap thins out);
//! none when fewer than 5 rows fall in the window.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::profile::Profile;
use super::spec::{DerivedGranular, GranularScenario};
use crate::analysis::powerlaw::linear_fit;
use crate::dem::{Dem, Grains};
use crate::exec::Progress;
use crate::io::{write_json, CsvWriter, PvdEntry, PvdSeries};
use crate::scenario::checkpointing::Control;
use crate::scenario::collapse::dem::write_frame;
use crate::scenario::Kind;
use crate::{Error, Result};

/// Steps between two applications of the outlets.
pub const OUTLET_STEPS: u64 = 50;

/// Discharged mass, as fractions of the mass at the release, between which the discharge rate
/// is fitted.
pub const RATE_WINDOW: [f64; 2] = [0.1, 0.6];

/// What a granular run reports (`summary.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GranularSummary {
    /// Scenario name.
    pub name: String,
    /// Grains at the release.
    pub grains_at_release: usize,
    /// Grains left at the end.
    pub grains_at_end: usize,
    /// Grains the outlets removed after the release.
    pub discharged: u64,
    /// Their mass (kg).
    pub discharged_mass: f64,
    /// Mass at the release (kg).
    pub mass_at_release: f64,
    /// Mass left at the end (kg): `mass_at_release − discharged_mass` to round-off.
    pub mass_at_end: f64,
    /// Discharge rate W (kg/s) over the window of [`RATE_WINDOW`], if reached.
    pub discharge_rate: Option<f64>,
    /// Simulated settling time before the release (s), if the scenario settles.
    pub settle_time: Option<f64>,
    /// Time after the release at which the run ended (s).
    pub end_time: f64,
    /// Why it ended: `"end"` (`time.end` reached), `"empty"` (no grain left) or
    /// `"discharged"` (`time.stop_discharged_fraction` reached).
    pub ended: String,
    /// DEM steps after the release and their size (s).
    pub steps: u64,
    /// The step (s).
    pub dt: f64,
    /// Wall time of the whole run, settling included (s).
    pub wall_time_s: f64,
}

/// The state of a run after the release, as a checkpoint holds it.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct State {
    dem: Dem,
    /// Outlets (lower-left, upper-right).
    outlets: Vec<[[f64; 2]; 2]>,
    discharged: u64,
    discharged_mass: f64,
    mass_at_release: f64,
    grains_at_release: usize,
    settle_time: Option<f64>,
    /// (t, discharged mass) per row, for the rate.
    history: Vec<(f64, f64)>,
    /// The `[profile]` sums, if asked for.
    profile: Option<Profile>,
    row: u64,
    frame: usize,
    series_bytes: u64,
    pvd: Vec<PvdEntry>,
    wall_time_s: f64,
}

/// Remove the grains of `dem` whose centre is inside one of `outlets`; their count and mass.
fn drain(dem: &mut Dem, outlets: &[[[f64; 2]; 2]]) -> Result<(u64, f64)> {
    if outlets.is_empty() {
        return Ok((0, 0.0));
    }
    let g = &dem.grains;
    let gone: Vec<bool> = (0..g.len())
        .map(|i| {
            let (x, y) = (g.x[i], g.y[i]);
            outlets
                .iter()
                .any(|[a, b]| x >= a[0] && x <= b[0] && y >= a[1] && y <= b[1])
        })
        .collect();
    let mass: f64 = (0..g.len()).filter(|&i| gone[i]).map(|i| g.mass[i]).sum();
    let n = dem.remove_grains(&gone)?;
    Ok((n as u64, mass))
}

/// Advance `dem` by `steps` steps, applying the outlets every [`OUTLET_STEPS`]; the grains
/// removed and their mass.
fn advance(dem: &mut Dem, outlets: &[[[f64; 2]; 2]], steps: u64) -> Result<(u64, f64)> {
    let (mut n, mut m) = (0, 0.0);
    let mut left = steps;
    while left > 0 {
        let k = left.min(OUTLET_STEPS);
        dem.advance_with(k as f64 * dem.dt(), None)?;
        let (dn, dm) = drain(dem, outlets)?;
        (n, m) = (n + dn, m + dm);
        left -= k;
    }
    Ok((n, m))
}

/// Kinetic energy, translational and rotational (J).
pub(super) fn kinetic(g: &Grains) -> f64 {
    (0..g.len())
        .map(|i| {
            0.5 * (g.mass[i] * (g.vx[i] * g.vx[i] + g.vy[i] * g.vy[i])
                + g.inertia[i] * g.omega[i] * g.omega[i])
        })
        .sum()
}

/// Settle the grains behind every wall and gate until at rest (see the module of the spec);
/// the grains at rest and the simulated time taken.
pub(super) fn settle(s: &GranularScenario, d: &DerivedGranular) -> Result<(Grains, f64)> {
    let Some(spec) = s.settle else {
        return Ok((d.grains.clone(), 0.0));
    };
    let walls: Vec<_> = d
        .walls
        .iter()
        .map(|(w, _)| *w)
        .chain(d.gates.iter().copied())
        .collect();
    let mut dem = Dem::new(d.grains.clone(), walls, d.params.clone())?;
    let g_abs = s.gravity[0].hypot(s.gravity[1]);
    let chunk = 200;
    let mut heartbeat = crate::exec::Heartbeat::new();
    loop {
        advance(&mut dem, &d.outlets, chunk)?;
        let g = &dem.grains;
        if g.is_empty() {
            return Err(Error::config(
                "settle",
                "every grain left through an outlet while settling; close the outlet with a gate",
            ));
        }
        let n = g.len() as f64;
        let m_mean = g.mass.iter().sum::<f64>() / n;
        let d_mean = 2.0 * g.radius.iter().sum::<f64>() / n;
        let rest = spec.rest_fraction * m_mean * g_abs * d_mean;
        if kinetic(g) / n < rest {
            break;
        }
        if heartbeat.due() {
            eprintln!(
                "settling: {:.3} s simulated (at most {} s), kinetic energy {:.1} × the rest \
                 level",
                dem.time(),
                spec.max_time,
                kinetic(g) / n / rest
            );
        }
        if dem.time() > spec.max_time {
            return Err(Error::config(
                "settle.max_time",
                format!(
                    "the grains were not at rest after {} s (kinetic energy per grain {:.3e} J, \
                     rest below {:.3e} J)",
                    spec.max_time,
                    kinetic(g) / n,
                    rest
                ),
            ));
        }
    }
    let t = dem.time();
    let mut grains = dem.grains;
    grains.stop();
    Ok((grains, t))
}

/// The released system: the settled grains, the walls that stay, moving ones set going.
pub(super) fn release(d: &DerivedGranular, grains: Grains) -> Result<Dem> {
    let walls = d.walls.iter().map(|(w, _)| *w).collect();
    let mut dem = Dem::new(grains, walls, d.params.clone())?;
    for (k, (_, v)) in d.walls.iter().enumerate() {
        if let Some(v) = v {
            dem.set_wall_velocity(k, *v)?;
        }
    }
    Ok(dem)
}

/// Discharge a released `dem` through `outlets` without writing anything: (t, discharged
/// mass) every `interval` s from the release until `fraction` of its mass has left, no grain
/// is left, or `end` s have passed.
pub(super) fn discharge(
    dem: &mut Dem,
    outlets: &[[[f64; 2]; 2]],
    interval: f64,
    fraction: f64,
    end: f64,
) -> Result<Vec<(f64, f64)>> {
    let mass: f64 = dem.grains.mass.iter().sum();
    let row_steps = ((interval / dem.dt()).ceil() as u64).max(1);
    let mut history = vec![(dem.time(), 0.0)];
    let mut discharged = 0.0;
    while discharged < fraction * mass && !dem.grains.is_empty() && dem.time() < end {
        discharged += advance(dem, outlets, row_steps)?.1;
        history.push((dem.time(), discharged));
    }
    Ok(history)
}

/// Run the scenario into `out` as `control` says (checkpoints, stop signals, resume);
/// `progress` is told the simulated milliseconds after the release.
pub fn run_granular(
    s: &GranularScenario,
    out: &Path,
    mut control: Control,
    progress: Progress,
) -> Result<GranularSummary> {
    crate::io::run_dir::create(out)?;
    let t_run = Instant::now();
    let header = [
        "t",
        "grains",
        "discharged",
        "discharged_mass",
        "kinetic_energy",
        "contacts",
    ];
    let series = out.join("timeseries.csv");
    let (mut st, mut csv, mut pvd) = match control.load::<State>(out, Kind::Granular)? {
        Some(l) => {
            let st = l.state;
            let csv = CsvWriter::reopen(&series, header.len(), st.series_bytes)?;
            let pvd = PvdSeries::resume(out, st.pvd.clone());
            (st, csv, pvd)
        }
        None => {
            let d = s.derive()?;
            let (grains, settle_time) = settle(s, &d)?;
            let dem = release(&d, grains)?;
            let st = State {
                mass_at_release: dem.grains.mass.iter().sum(),
                grains_at_release: dem.grains.len(),
                dem,
                outlets: d.outlets,
                discharged: 0,
                discharged_mass: 0.0,
                settle_time: s.settle.map(|_| settle_time),
                history: Vec::new(),
                profile: s.profile.map(Profile::new),
                row: 0,
                frame: 0,
                series_bytes: 0,
                pvd: Vec::new(),
                wall_time_s: 0.0,
            };
            (
                st,
                CsvWriter::create(&series, &header)?,
                PvdSeries::new(out),
            )
        }
    };
    let dt = st.dem.dt();
    let row_steps = ((s.time.series_interval / dt).ceil() as u64).max(1);
    let frame_every = ((s.time.frame_interval / s.time.series_interval).round() as u64).max(1);
    let end_ms = (1e3 * s.time.end) as u64;
    let mut last_checkpoint: Option<PathBuf> = None;
    let thickness = s.grains.thickness;
    let mut ended = "end";
    let looped = (|| -> Result<()> {
        loop {
            let t = st.dem.time();
            st.dem.refresh_forces();
            let contacts = st.dem.contacts_per_grain();
            let touching = st.dem.contact_count() as f64;
            csv.row(&[
                t,
                st.dem.grains.len() as f64,
                st.discharged as f64,
                st.discharged_mass,
                kinetic(&st.dem.grains),
                touching,
            ])?;
            st.history.push((t, st.discharged_mass));
            if let Some(p) = st.profile.as_mut().filter(|p| p.due(t)) {
                p.sample(&st.dem.grains);
            }
            let empty = st.dem.grains.is_empty();
            let drained = s
                .time
                .stop_discharged_fraction
                .is_some_and(|f| st.discharged_mass >= f * st.mass_at_release);
            let done = empty || drained || t >= s.time.end * (1.0 - 1e-12);
            if (st.row.is_multiple_of(frame_every) || done) && !empty {
                let c: Vec<f64> = contacts.iter().map(|&c| f64::from(c)).collect();
                write_frame(
                    &st.dem,
                    &c,
                    thickness,
                    (&s.vtk, out),
                    (st.frame, t),
                    &mut pvd,
                )?;
                st.frame += 1;
            }
            st.row += 1;
            progress(((1e3 * t) as u64).min(end_ms), end_ms);
            if done {
                if empty {
                    ended = "empty";
                } else if drained {
                    ended = "discharged";
                }
                return Ok(());
            }
            let (n, m) = advance(&mut st.dem, &st.outlets, row_steps)?;
            st.discharged += n;
            st.discharged_mass += m;
            let signal = control.stop_signal();
            if control.due(st.row, s.time.series_interval) || signal.is_some() {
                st.series_bytes = csv.bytes_written();
                st.pvd = pvd.entries().to_vec();
                let wall = st.wall_time_s;
                st.wall_time_s += t_run.elapsed().as_secs_f64();
                let path = control.save(out, Kind::Granular, st.row, st.dem.time(), &st)?;
                st.wall_time_s = wall;
                last_checkpoint = Some(path.clone());
                if let Some(signal) = signal {
                    let t = st.dem.time();
                    return Err(control.interrupted(signal, st.row, t, path, out));
                }
            }
        }
    })();
    if let Err(e) = looped {
        let frame = pvd.entries().last().map(|f| f.file.as_str());
        return Err(control.write_failed(e, out, frame, last_checkpoint.as_deref()));
    }
    let summary = GranularSummary {
        name: s.name.clone(),
        grains_at_release: st.grains_at_release,
        grains_at_end: st.dem.grains.len(),
        discharged: st.discharged,
        discharged_mass: st.discharged_mass,
        mass_at_release: st.mass_at_release,
        mass_at_end: st.dem.grains.mass.iter().sum(),
        discharge_rate: discharge_rate(&st.history, st.mass_at_release),
        settle_time: st.settle_time,
        end_time: st.dem.time(),
        ended: ended.into(),
        steps: st.dem.step_count(),
        dt,
        wall_time_s: st.wall_time_s + t_run.elapsed().as_secs_f64(),
    };
    if let Some(p) = &st.profile {
        p.write(&out.join("profile.csv"))?;
    }
    write_json(&out.join("summary.json"), &summary)?;
    crate::io::checkpoint::remove_all(out)?;
    Ok(summary)
}

/// The slope of the discharged mass against time over the rows in [`RATE_WINDOW`] of
/// `mass` (kg/s); `None` with fewer than 5 such rows.
pub fn discharge_rate(history: &[(f64, f64)], mass: f64) -> Option<f64> {
    let [lo, hi] = RATE_WINDOW.map(|f| f * mass);
    let (t, m): (Vec<f64>, Vec<f64>) = history
        .iter()
        .filter(|(_, m)| *m >= lo && *m <= hi)
        .copied()
        .unzip();
    (t.len() >= 5).then(|| linear_fit(&t, &m).0)
}
