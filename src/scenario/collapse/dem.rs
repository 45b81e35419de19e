//! Runner of the DEM column collapse ([`DemScenario`]): deposit the column, remove the gate,
//! integrate until the mass is at rest, and write
//!
//! * `series.pvd` with, per frame, `grains_NNNNNN.vtu` (part 0: points with radius, velocity,
//!   angular velocity, contact count, Love–Weber stress tensor and its mean −(σ_xx + σ_yy)/2,
//!   see [`crate::dem::stress`]) and `contacts_NNNNNN.vtu` (part 1: a line cell per touching pair —
//!   grain–grain from centre to centre, grain–wall from the centre to the contact point on
//!   the wall — with the normal and tangential forces f_n, f_t and `wall` = 1 for wall
//!   contacts: force chains in ParaView);
//! * `timeseries.csv`: t, t/τ_c, run-out, front, height, energies, budget error;
//! * `summary.json` ([`CollapseSummary`]).
//!
//! Definitions (REFERENCES, granular column collapse): τ_c = √(H_i/g) with H_i the deposited
//! height; the *main mass* is the largest set of grains connected through near-contacts, two
//! grains being connected when their gap is below [`CONNECT_GAP`] × (R_i + R_j) (at rest this
//! is the thesis's "in contact with the main mass"; during the flow the small tolerance keeps
//! the agitated mass from falling apart into clusters at every bounce, which made the
//! run-out flicker with a strict-contact rule); the run-out L(t) is the largest x + R over
//! the main mass (the thesis: the farthest grain still in contact with the main mass),
//! measured from the left wall; the front is the largest x + R over all grains (it includes
//! single grains rolling away); the height H(t) is the largest y + R over the main mass. At
//! rest: L_f, H_f, ΔL = (L_f − L_i)/L_i, H_f/L_i. The *stop time* is when spreading ends:
//! the first time after which L(t) stays within 1 % of L_i of L_f
//! ([`crate::analysis::runout::spreading_end`]). The run ends when the kinetic energy has stayed below `rest_kinetic_fraction` × the initial
//! potential energy above the floor for `rest_duration_tc` τ_c (and t ≥ 1 τ_c; reported as
//! `rest_time_tc`, which also waits for grains rolling away from the deposit), or at
//! `end_tc` τ_c.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use crate::analysis::runout::{CollapseOutcome, CollapseRecord};
use crate::dem::packing::deposit_column;
use crate::dem::solver::Dem;
use crate::dem::stress::grain_stress;
use crate::dem::walls::Wall;
use crate::io::{write_json, write_vtu_points, CsvWriter, Field, PvdSeries};
use crate::scenario::dem::spec::DemScenario;
use crate::{Error, Result};

/// Two grains belong to the same mass when their gap is below this fraction of R_i + R_j.
pub const CONNECT_GAP: f64 = 0.1;

/// What a DEM collapse run reports (`summary.json`): the solver-independent outcome and the
/// DEM's own keys.
#[derive(Clone, Debug, Serialize)]
pub struct CollapseSummary {
    /// L_f, ΔL, H_f, stop time, … (the keys every collapse runner writes).
    #[serde(flatten)]
    pub collapse: CollapseOutcome,
    /// Number of grains.
    pub grains: usize,
    /// Packing fraction of the deposited column (interior strip).
    pub packing_fraction: f64,
    /// Wall time of the deposition (s).
    pub deposition_wall_time_s: f64,
}

/// Main mass, run-out, front, height (m), and contacts per grain.
pub(crate) struct Shape {
    pub(crate) runout: f64,
    pub(crate) front: f64,
    pub(crate) height: f64,
    contacts: Vec<f64>,
}

fn find(parent: &mut [u32], mut a: u32) -> u32 {
    while parent[a as usize] != a {
        let p = parent[a as usize];
        parent[a as usize] = parent[p as usize];
        a = p;
    }
    a
}

/// Measure the deposit shape (see the module doc): main mass by near-contacts found on a
/// uniform grid of cells 2R_max(1 + [`CONNECT_GAP`]) wide, contact counts from the touching
/// pairs.
pub(crate) fn shape(dem: &Dem) -> Shape {
    let g = &dem.grains;
    let n = g.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let mut contacts = vec![0.0; n];
    let pl = dem.pairs();
    for k in 0..pl.i.len() {
        if pl.state[k].touching() {
            contacts[pl.i[k] as usize] += 1.0;
            contacts[pl.j[k] as usize] += 1.0;
        }
    }
    let wl = dem.wall_pairs();
    for k in 0..wl.grain.len() {
        if wl.state[k].touching() {
            contacts[wl.grain[k] as usize] += 1.0;
        }
    }
    // Near-contact graph on a cell grid over the grains' bounding box.
    let h = 2.0 * g.max_radius() * (1.0 + CONNECT_GAP);
    let (x0, y0) = (
        g.x.iter().fold(f64::INFINITY, |a, &b| a.min(b)),
        g.y.iter().fold(f64::INFINITY, |a, &b| a.min(b)),
    );
    let cell = |i: usize| (((g.x[i] - x0) / h) as usize, ((g.y[i] - y0) / h) as usize);
    let ncx = (0..n).map(|i| cell(i).0).max().unwrap_or(0) + 1;
    let ncy = (0..n).map(|i| cell(i).1).max().unwrap_or(0) + 1;
    let mut start = vec![0u32; ncx * ncy + 1];
    for i in 0..n {
        let (cx, cy) = cell(i);
        start[cy * ncx + cx + 1] += 1;
    }
    for c in 0..ncx * ncy {
        start[c + 1] += start[c];
    }
    let mut fill = start.clone();
    let mut sorted = vec![0u32; n];
    for i in 0..n {
        let (cx, cy) = cell(i);
        let c = cy * ncx + cx;
        sorted[fill[c] as usize] = i as u32;
        fill[c] += 1;
    }
    for i in 0..n {
        let (cx, cy) = cell(i);
        for ny in cy.saturating_sub(1)..=(cy + 1).min(ncy - 1) {
            for nx in cx.saturating_sub(1)..=(cx + 1).min(ncx - 1) {
                let c = ny * ncx + nx;
                for &j in &sorted[start[c] as usize..start[c + 1] as usize] {
                    let j_ = j as usize;
                    if j_ <= i {
                        continue;
                    }
                    let reach = (g.radius[i] + g.radius[j_]) * (1.0 + CONNECT_GAP);
                    let (dx, dy) = (g.x[j_] - g.x[i], g.y[j_] - g.y[i]);
                    if dx * dx + dy * dy < reach * reach {
                        let (a, b) = (find(&mut parent, i as u32), find(&mut parent, j));
                        if a != b {
                            parent[a as usize] = b;
                        }
                    }
                }
            }
        }
    }
    let mut size = vec![0u32; n];
    for i in 0..n {
        let r = find(&mut parent, i as u32);
        size[r as usize] += 1;
    }
    let main = (0..n).max_by_key(|&r| size[r]).unwrap_or(0) as u32;
    let (mut runout, mut front, mut height) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..n {
        let right = g.x[i] + g.radius[i];
        front = front.max(right);
        if find(&mut parent, i as u32) == main {
            runout = runout.max(right);
            height = height.max(g.y[i] + g.radius[i]);
        }
    }
    Shape {
        runout,
        front,
        height,
        contacts,
    }
}

/// Write frame `k` (grains as part 0, contacts as part 1) and list it in `pvd` at `time`.
pub(crate) fn write_frame(
    dem: &Dem,
    s: &Shape,
    thickness: f64,
    dir: &Path,
    k: usize,
    time: f64,
    pvd: &mut PvdSeries,
) -> Result<()> {
    let g = &dem.grains;
    let n = g.len();
    let mut points: Vec<[f64; 2]> = (0..n).map(|i| [g.x[i], g.y[i]]).collect();
    let vel: Vec<[f64; 2]> = (0..n).map(|i| [g.vx[i], g.vy[i]]).collect();
    let stress = grain_stress(dem, thickness);
    let pressure: Vec<f64> = stress.iter().map(|t| -0.5 * (t[0] + t[3])).collect();
    let gname = format!("grains_{k:06}.vtu");
    write_vtu_points(
        &dir.join(&gname),
        &points,
        &[
            Field::scalar("radius", &g.radius),
            Field::vector("velocity", &vel),
            Field::scalar("angular_velocity", &g.omega),
            Field::scalar("contacts", &s.contacts),
            Field::tensor("stress", &stress),
            Field::scalar("mean_pressure", &pressure),
        ],
        &[],
        &[],
    )?;
    let (mut lines, mut f_n, mut f_t, mut wall) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let pl = dem.pairs();
    for p in 0..pl.i.len() {
        let st = &pl.state[p];
        if st.touching() {
            lines.push([pl.i[p], pl.j[p]]);
            f_n.push(st.f_n);
            f_t.push(st.f_t);
            wall.push(0.0);
        }
    }
    let wl = dem.wall_pairs();
    for p in 0..wl.grain.len() {
        let st = &wl.state[p];
        if st.touching() {
            let i = wl.grain[p] as usize;
            let (dist, nrm) = dem.walls[wl.wall[p] as usize].distance([g.x[i], g.y[i]]);
            lines.push([i as u32, points.len() as u32]);
            points.push([g.x[i] + dist * nrm[0], g.y[i] + dist * nrm[1]]);
            f_n.push(st.f_n);
            f_t.push(st.f_t);
            wall.push(1.0);
        }
    }
    let cname = format!("contacts_{k:06}.vtu");
    // With no touching pair, write the points only (a valid vertex set).
    let fields = [
        Field::scalar("normal_force", &f_n),
        Field::scalar("tangential_force", &f_t),
        Field::scalar("wall", &wall),
    ];
    let cells: &[Field] = if lines.is_empty() { &[] } else { &fields };
    write_vtu_points(&dir.join(&cname), &points, &[], &lines, cells)?;
    pvd.add(time, 0, &gname)?;
    pvd.add(time, 1, &cname)
}

/// Run the collapse described by `scenario`, writing into `out_dir` (created if missing).
/// Returns the summary also written to `summary.json`.
pub fn run_column_collapse(
    scenario: &DemScenario,
    out_dir: &Path,
    progress: crate::exec::Progress,
) -> Result<CollapseSummary> {
    let d = scenario.derive()?;
    std::fs::create_dir_all(out_dir).map_err(|e| Error::io(out_dir, e))?;
    let t0 = Instant::now();
    let column = deposit_column(&d.column)?;
    let deposition_wall_time_s = t0.elapsed().as_secs_f64();
    let (l_i, h_i) = (scenario.column.width, column.height);
    let gmag = scenario.gravity;
    let tau_c = (h_i / gmag).sqrt();
    let walls = vec![
        Wall::floor(0.0),
        Wall::left(0.0),
        Wall::right(scenario.column.box_length),
    ];
    let mut dem = Dem::new(column.grains, walls, d.params.clone())?;
    dem.refresh_forces();
    let e0 = dem.energy();
    let ts = &scenario.time;
    let dt = dem.dt();
    let series_steps = ((ts.series_interval_tc * tau_c / dt).ceil() as u64).max(1);
    let frame_every = ((ts.frame_interval_tc / ts.series_interval_tc).round() as u64).max(1);
    let mut csv = CsvWriter::create(
        &out_dir.join("timeseries.csv"),
        &[
            "t",
            "t_over_tc",
            "runout",
            "front",
            "height",
            "kinetic",
            "rotational",
            "potential",
            "elastic",
            "dissipated_normal",
            "dissipated_friction",
            "dissipated_rolling",
            "budget_error",
        ],
    )?;
    let mut pvd = PvdSeries::new(out_dir);
    let rest_limit = ts.rest_kinetic_fraction * e0.potential;
    let (mut rest_since, mut at_rest) = (None::<f64>, false);
    let (mut row, mut frame) = (0u64, 0usize);
    let mut history = Vec::new();
    let t_run = Instant::now();
    let budget =
        |e: &crate::dem::Energy| (e.total() - e0.total()).abs() / e.dissipated().max(1e-300);
    let mut last;
    loop {
        let e = dem.energy();
        let s = shape(&dem);
        let t = dem.time();
        history.push((t, s.runout));
        csv.row(&[
            t,
            t / tau_c,
            s.runout,
            s.front,
            s.height,
            e.kinetic,
            e.rotational,
            e.potential,
            e.elastic(),
            e.dissipated_normal,
            e.dissipated_friction,
            e.dissipated_rolling,
            budget(&e),
        ])?;
        if row % frame_every == 0 {
            write_frame(
                &dem,
                &s,
                scenario.grains.thickness,
                out_dir,
                frame,
                dem.time(),
                &mut pvd,
            )?;
            frame += 1;
        }
        row += 1;
        if e.kinetic_total() < rest_limit {
            let since = *rest_since.get_or_insert(t);
            if t >= tau_c && t - since >= ts.rest_duration_tc * tau_c {
                at_rest = true;
            }
        } else {
            rest_since = None;
        }
        last = (s, e);
        // Progress in thousandths of τ_c, up to the end time.
        progress((1e3 * t / tau_c) as u64, (1e3 * ts.end_tc) as u64);
        if at_rest || t >= ts.end_tc * tau_c {
            break;
        }
        dem.advance_with(series_steps as f64 * dt, None)?;
    }
    let wall_time_s = t_run.elapsed().as_secs_f64();
    if (row - 1) % frame_every != 0 {
        write_frame(
            &dem,
            &last.0,
            scenario.grains.thickness,
            out_dir,
            frame,
            dem.time(),
            &mut pvd,
        )?;
    }
    let (s, e) = last;
    let collapse = CollapseOutcome::from(CollapseRecord {
        name: &scenario.name,
        l_i,
        h_i,
        gravity: gmag,
        history: &history,
        h_f: s.height,
        rest_since,
        at_rest,
        t_end: dem.time(),
        dt,
        steps: dem.step_count(),
        wall_time_s,
        particles: dem.grains.len(),
        energy_budget_error: budget(&e),
        energy: e.budget(&e0),
    });
    let summary = CollapseSummary {
        collapse,
        grains: dem.grains.len(),
        packing_fraction: column.packing_fraction,
        deposition_wall_time_s,
    };
    write_json(&out_dir.join("summary.json"), &summary)?;
    Ok(summary)
}
