//! Runner of the continuum scenario ([`ContinuumScenario`]): advance until `time.end`, the
//! gravity turned at every step when the file tilts it, and write
//!
//! * `series.pvd` with, per frame, `points_NNNNNN.vtu` and `grid_NNNNNN.vti` (the arrays of
//!   the MPM column collapse's frames);
//! * `timeseries.csv`: `t` (s), `tilt_deg` (the angle of gravity from −y), `kinetic_energy`
//!   (J/m: per metre of thickness), `mean_velocity_x`, `mean_velocity_y` (mass-weighted, m/s),
//!   `max_speed` (m/s);
//! * `summary.json` ([`ContinuumSummary`]), with the onset of sliding of a tilting table.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::spec::{angle_deg, ContinuumScenario, DerivedContinuum};
use crate::exec::Progress;
use crate::io::{write_json, CsvWriter, PvdEntry, PvdSeries};
use crate::mpm::Mpm;
use crate::scenario::checkpointing::Control;
use crate::scenario::collapse::mpm::write_frame;
use crate::scenario::Kind;
use crate::Result;

/// What a continuum run reports (`summary.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ContinuumSummary {
    /// Scenario name.
    pub name: String,
    /// Material points.
    pub points: usize,
    /// Cells of the domain (x, y).
    pub cells: [usize; 2],
    /// The step (s).
    pub dt: f64,
    /// Steps taken.
    pub steps: u64,
    /// End time (s).
    pub end_time: f64,
    /// Kinetic energy at the end (J/m).
    pub kinetic_energy: f64,
    /// Angle of gravity from −y at the end (degrees).
    pub tilt_deg: f64,
    /// Tilting table: the angle (degrees) and time (s) of the first row whose mean velocity
    /// along x exceeded `tilt.onset_speed`; none if it never did (or without a tilt).
    pub onset_deg: Option<f64>,
    /// Time of the onset (s).
    pub onset_time: Option<f64>,
    /// Wall time of the run (s).
    pub wall_time_s: f64,
}

/// The state of a run, as a checkpoint holds it.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct State {
    mpm: Mpm,
    onset: Option<(f64, f64)>,
    row: u64,
    frame: usize,
    series_bytes: u64,
    pvd: Vec<PvdEntry>,
    wall_time_s: f64,
}

/// One row of the time series: kinetic energy, mass-weighted mean velocity, largest speed.
pub fn motion(mpm: &Mpm) -> (f64, [f64; 2], f64) {
    let p = &mpm.points;
    let (mut ke, mut m, mut mv, mut vmax) = (0.0, 0.0, [0.0; 2], 0.0f64);
    for q in 0..p.len() {
        let v = p.vel[q];
        let s2 = v[0] * v[0] + v[1] * v[1];
        ke += 0.5 * p.mass[q] * s2;
        m += p.mass[q];
        mv = [mv[0] + p.mass[q] * v[0], mv[1] + p.mass[q] * v[1]];
        vmax = vmax.max(s2.sqrt());
    }
    (ke, [mv[0] / m, mv[1] / m], vmax)
}

/// Advance `mpm` by `steps` steps, turning the gravity to [`ContinuumScenario::gravity_at`]
/// before each.
pub fn advance(
    s: &ContinuumScenario,
    d: &DerivedContinuum,
    mpm: &mut Mpm,
    steps: u64,
) -> Result<()> {
    for _ in 0..steps {
        mpm.params.gravity = s.gravity_at(d, mpm.time());
        mpm.step()?;
    }
    Ok(())
}

/// Run the scenario into `out` as `control` says (checkpoints, stop signals, resume);
/// `progress` is told the simulated milliseconds.
pub fn run_continuum(
    s: &ContinuumScenario,
    out: &Path,
    mut control: Control,
    progress: Progress,
) -> Result<ContinuumSummary> {
    crate::io::run_dir::create(out)?;
    let t_run = Instant::now();
    let header = [
        "t",
        "tilt_deg",
        "kinetic_energy",
        "mean_velocity_x",
        "mean_velocity_y",
        "max_speed",
    ];
    let series = out.join("timeseries.csv");
    let d = s.derive()?;
    let (mut st, mut csv, mut pvd) = match control.load::<State>(out, Kind::Continuum)? {
        Some(l) => {
            let st = l.state;
            let csv = CsvWriter::reopen(&series, header.len(), st.series_bytes)?;
            let pvd = PvdSeries::resume(out, st.pvd.clone());
            (st, csv, pvd)
        }
        None => {
            let st = State {
                mpm: s.build(&d)?,
                onset: None,
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
    let row_steps = ((s.time.series_interval / d.dt).ceil() as u64).max(1);
    let frame_every = ((s.time.frame_interval / s.time.series_interval).round() as u64).max(1);
    let end_ms = (1e3 * s.time.end) as u64;
    let mut last_checkpoint: Option<PathBuf> = None;
    let looped = (|| -> Result<()> {
        loop {
            let t = st.mpm.time();
            let g = s.gravity_at(&d, t);
            let (ke, mean, vmax) = motion(&st.mpm);
            csv.row(&[t, angle_deg(g), ke, mean[0], mean[1], vmax])?;
            if let (Some(tilt), None) = (&s.tilt, st.onset) {
                if mean[0] > tilt.onset_speed {
                    st.onset = Some((t, angle_deg(g)));
                }
            }
            let done = t >= s.time.end * (1.0 - 1e-12);
            if st.row.is_multiple_of(frame_every) || done {
                write_frame(&st.mpm, &[], &s.vtk, out, st.frame, &mut pvd)?;
                st.frame += 1;
            }
            st.row += 1;
            progress(((1e3 * t) as u64).min(end_ms), end_ms);
            if done {
                return Ok(());
            }
            advance(s, &d, &mut st.mpm, row_steps)?;
            let signal = control.stop_signal();
            if control.due(st.row, s.time.series_interval) || signal.is_some() {
                st.series_bytes = csv.bytes_written();
                st.pvd = pvd.entries().to_vec();
                let wall = st.wall_time_s;
                st.wall_time_s += t_run.elapsed().as_secs_f64();
                let path = control.save(out, Kind::Continuum, st.row, st.mpm.time(), &st)?;
                st.wall_time_s = wall;
                last_checkpoint = Some(path.clone());
                if let Some(signal) = signal {
                    let t = st.mpm.time();
                    return Err(control.interrupted(signal, st.row, t, path, out));
                }
            }
        }
    })();
    if let Err(e) = looped {
        let frame = pvd.entries().last().map(|f| f.file.as_str());
        return Err(control.write_failed(e, out, frame, last_checkpoint.as_deref()));
    }
    let summary = ContinuumSummary {
        name: s.name.clone(),
        points: st.mpm.points.len(),
        cells: d.cells,
        dt: st.mpm.dt(),
        steps: st.mpm.step_count(),
        end_time: st.mpm.time(),
        kinetic_energy: motion(&st.mpm).0,
        tilt_deg: angle_deg(s.gravity_at(&d, st.mpm.time())),
        onset_deg: st.onset.map(|o| o.1),
        onset_time: st.onset.map(|o| o.0),
        wall_time_s: st.wall_time_s + t_run.elapsed().as_secs_f64(),
    };
    write_json(&out.join("summary.json"), &summary)?;
    crate::io::checkpoint::remove_all(out)?;
    Ok(summary)
}
