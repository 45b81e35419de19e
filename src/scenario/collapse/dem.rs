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
//! Definitions (docs/references.md, column collapse run-out laws): τ_c = √(H_i/g) with H_i the
//! deposited height; the *main mass* is the largest set of grains connected through near-contacts, two
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

use super::{collapse_gravity, rest_scale, run_resumable, steps_per_row, Column, Plan, Row, Tally};
use crate::analysis::runout::CollapseOutcome;
use crate::dem::detect_rapier::WALL_BIT;
use crate::dem::packing::deposit_column;
use crate::dem::stress::grain_stress;
use crate::dem::{Dem, Energy, Wall};
use crate::exec::Progress;
use crate::io::{write_vtu_points, Field, PvdSeries, VtkFormat};
use crate::scenario::checkpointing::Control;
use crate::scenario::dem::spec::{DemScenario, DemTimeSpec};
use crate::scenario::Kind;
use crate::Result;

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
pub struct Shape {
    /// Run-out: the largest x + R over the main mass (m).
    pub runout: f64,
    /// Front: the largest x + R over all grains (m).
    pub front: f64,
    /// Height: the largest y + R over the main mass (m).
    pub height: f64,
    /// Touching contacts per grain (grains and walls).
    pub contacts: Vec<f64>,
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
pub fn shape(dem: &Dem) -> Shape {
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
        let [right, top] = g.upper_extent(i);
        front = front.max(right);
        if find(&mut parent, i as u32) == main {
            runout = runout.max(right);
            height = height.max(top);
        }
    }
    Shape {
        runout,
        front,
        height,
        contacts,
    }
}

/// Write frame `k` at `time` (grains, with their `contacts` counts, as part 0; contacts as
/// part 1) into `dir` and list it in `pvd`.
pub fn write_frame(
    dem: &Dem,
    contacts: &[f64],
    thickness: f64,
    (format, dir): (&VtkFormat, &Path),
    (k, time): (usize, f64),
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
            Field::scalar("angle", &g.angle),
            Field::scalar("angular_velocity", &g.omega),
            Field::scalar("contacts", contacts),
            Field::tensor("stress", &stress),
            Field::scalar("mean_pressure", &pressure),
        ],
        &[],
        &[],
        format,
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
    // Contacts found by rapier (polygon grains or walls), one line per contact point:
    // f_n = −**f**·**n**, f_t = **f**·**t** of the force **f** on i, **n** the contact normal.
    if let Some(sc) = dem.shape_contacts() {
        for ((c, st), f) in sc.found.iter().zip(&sc.state).zip(&sc.force) {
            if !st.touching() {
                continue;
            }
            let n = c.normal;
            f_n.push(-(f[0] * n[0] + f[1] * n[1]));
            f_t.push(-f[0] * n[1] + f[1] * n[0]);
            if c.j & WALL_BIT == 0 {
                lines.push([c.i, c.j]);
                wall.push(0.0);
            } else {
                lines.push([c.i, points.len() as u32]);
                points.push(c.point);
                wall.push(1.0);
            }
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
    write_vtu_points(&dir.join(&cname), &points, &[], &lines, cells, format)?;
    pvd.add(time, 0, &gname)?;
    pvd.add(time, 1, &cname)
}

impl super::Resumable for DemColumn {
    type Saved<'s> = &'s DemColumn;
    type Loaded = DemColumn;
    fn saved(&self) -> &DemColumn {
        self
    }
}

/// A DEM column: the grains after deposition, released between the floor and the side walls.
#[derive(Serialize, serde::Deserialize)]
pub struct DemColumn {
    /// The grains and walls.
    pub dem: Dem,
    e0: Energy,
    /// Grain steps per time-series row.
    series_steps: u64,
    thickness: f64,
    packing_fraction: f64,
    deposition_wall_time_s: f64,
}

/// The energies of a time-series row, in the order of the first seven [`COLUMNS`] (J).
pub(super) fn energy_values(e: &Energy) -> [f64; 7] {
    [
        e.kinetic,
        e.rotational,
        e.potential,
        e.elastic(),
        e.dissipated_normal,
        e.dissipated_friction,
        e.dissipated_rolling,
    ]
}

/// The plan of a DEM column (dry or submerged) of initial width `l_i`, deposited height `h_i`
/// and initial potential energy `potential`, on the schedule of the scenario's `[time]`, its
/// frames written in `vtk`.
pub(super) fn plan<'a>(
    scenario_name: &'a str,
    [l_i, h_i]: [f64; 2],
    gravity: f64,
    potential: f64,
    ts: &DemTimeSpec,
    vtk: VtkFormat,
) -> Plan<'a> {
    Plan {
        name: scenario_name,
        l_i,
        h_i,
        gravity,
        potential,
        series_interval_tc: ts.series_interval_tc,
        frame_interval_tc: ts.frame_interval_tc,
        end_tc: ts.end_tc,
        rest_kinetic_fraction: ts.rest_kinetic_fraction,
        rest_duration_tc: ts.rest_duration_tc,
        vtk,
    }
}

/// The DEM's time-series columns after the geometry.
const COLUMNS: &[&str] = &[
    "kinetic",
    "rotational",
    "potential",
    "elastic",
    "dissipated_normal",
    "dissipated_friction",
    "dissipated_rolling",
    "budget_error",
];

impl DemColumn {
    /// Relative energy budget error |E − E₀| / dissipated energy.
    fn budget(&self, e: &Energy) -> f64 {
        (e.total() - self.e0.total()).abs() / e.dissipated().max(1e-300)
    }
}

/// The measurement of one row: the deposit shape and the energies.
pub struct DemShape {
    shape: Shape,
    energy: Energy,
}

impl Column for DemColumn {
    type Shape = DemShape;
    type Summary = CollapseSummary;

    fn columns(&self) -> &'static [&'static str] {
        COLUMNS
    }
    fn time(&self) -> f64 {
        self.dem.time()
    }
    fn measure(&mut self) -> Result<(Row, DemShape)> {
        let e = self.dem.energy();
        let s = shape(&self.dem);
        let row = Row {
            runout: s.runout,
            front: s.front,
            height: s.height,
            kinetic: e.kinetic_total(),
            values: energy_values(&e)
                .into_iter()
                .chain([self.budget(&e)])
                .collect(),
        };
        Ok((
            row,
            DemShape {
                shape: s,
                energy: e,
            },
        ))
    }
    fn write_frame(
        &self,
        s: &DemShape,
        format: &VtkFormat,
        dir: &Path,
        k: usize,
        t: f64,
        pvd: &mut PvdSeries,
    ) -> Result<()> {
        write_frame(
            &self.dem,
            &s.shape.contacts,
            self.thickness,
            (format, dir),
            (k, t),
            pvd,
        )
    }
    fn advance(&mut self) -> Result<()> {
        let dt = self.dem.dt();
        self.dem.advance_with(self.series_steps as f64 * dt, None)
    }
    fn tally(&self, s: &DemShape) -> Tally {
        Tally {
            steps: self.dem.step_count(),
            dt: self.dem.dt(),
            particles: self.dem.grains.len(),
            energy_budget_error: self.budget(&s.energy),
            energy: s.energy.budget(&self.e0),
        }
    }
    fn summary(&self, collapse: CollapseOutcome) -> CollapseSummary {
        CollapseSummary {
            collapse,
            grains: self.dem.grains.len(),
            packing_fraction: self.packing_fraction,
            deposition_wall_time_s: self.deposition_wall_time_s,
        }
    }
}

/// Deposit the column of `scenario` and release it: the DEM system and the run's plan.
pub fn column(scenario: &DemScenario) -> Result<(DemColumn, Plan<'_>)> {
    let d = scenario.derive()?;
    let t0 = Instant::now();
    let deposit = deposit_column(&d.column)?;
    let deposition_wall_time_s = t0.elapsed().as_secs_f64();
    let walls = vec![
        Wall::floor(0.0),
        Wall::left(0.0),
        Wall::right(scenario.column.box_length),
    ];
    let mut dem = Dem::new(deposit.grains, walls, d.params.clone())?;
    dem.refresh_forces();
    let e0 = dem.energy();
    let ts = &scenario.time;
    let g = collapse_gravity(scenario.gravity)?;
    let plan = plan(
        &scenario.name,
        [scenario.column.width, deposit.height],
        g,
        rest_scale(&dem.grains.mass, &dem.grains.y, g),
        ts,
        scenario.vtk,
    );
    let series_steps = steps_per_row(ts.series_interval_tc, plan.tau_c(), dem.dt());
    let column = DemColumn {
        dem,
        e0,
        series_steps,
        thickness: scenario.grains.thickness,
        packing_fraction: deposit.packing_fraction,
        deposition_wall_time_s,
    };
    Ok((column, plan))
}

/// Run the collapse described by `scenario`, writing into `out_dir` (created if missing).
/// Returns the summary also written to `summary.json`.
pub fn run_column_collapse(
    scenario: &DemScenario,
    out_dir: &Path,
    progress: Progress,
) -> Result<CollapseSummary> {
    run_resumable_collapse(scenario, out_dir, Control::default(), progress)
}

/// [`run_column_collapse`] with checkpoints, a stop on request and resume ([`Control`]): a
/// resumed run takes its deposited, released column from the checkpoint.
pub fn run_resumable_collapse(
    scenario: &DemScenario,
    out_dir: &Path,
    control: Control,
    progress: Progress,
) -> Result<CollapseSummary> {
    let g = collapse_gravity(scenario.gravity)?;
    let plan_of = |h_i, potential| {
        plan(
            &scenario.name,
            [scenario.column.width, h_i],
            g,
            potential,
            &scenario.time,
            scenario.vtk,
        )
    };
    let start = || column(scenario);
    run_resumable(Kind::Dem, start, Ok, plan_of, out_dir, control, progress)
}
