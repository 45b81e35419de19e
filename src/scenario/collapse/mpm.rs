//! Runner of the MPM column collapse ([`MpmScenario`]): release the column, integrate until the
//! mass is at rest, and write (the same contract as the DEM's `dem::run`)
//!
//! * `series.pvd` with, per frame, `points_NNNNNN.vtu` (part 0: material points with velocity,
//!   stress components, mean stress p = tr σ/3, deviatoric (von Mises) stress q = √(3J₂),
//!   equivalent plastic strain, volume) and `grid_NNNNNN.vti` (part 1: per cell the mass
//!   density and mean velocity of the points in it); with a representative-volume material
//!   the points also carry each volume's packing fraction, coordination, fabric and grains, and
//!   `volume_<k>_NNNNNN.vtu` (part 2 + k) the grains of the volumes chosen with
//!   [`run_column_collapse_with`];
//! * `timeseries.csv`: t, t/τ_c, run-out, front, height, energies, budget error (the DEM's
//!   column names where they apply);
//! * `summary.json` ([`MpmCollapseSummary`], the DEM's `CollapseSummary` keys plus MPM ones).
//!
//! Attachment (what the run-out measures): a grid cell is occupied when a material point's
//! centre lies in it; occupied cells sharing an edge or a corner are connected; the *main
//! mass* is the connected set holding the most points. So a point is attached when its cell
//! touches the main mass's cells: points up to about one cell (≤ 2h) apart stay attached,
//! isolated points thrown further are not. The run-out L(t) is the largest x + l_p over the
//! main mass (the point's domain edge), measured from the back wall; the front is the largest
//! x + l_p over all points; the height H(t) is the largest y + l_p over the main mass.
//! The *stop time* is when spreading ends: the first time after which L(t) stays within
//! 1 % of L_i of L_f, as for the DEM ([`crate::analysis::runout::spreading_end`]). The run ends when the kinetic energy has
//! stayed below `rest_kinetic_fraction` × the initial potential energy above the floor for
//! `rest_duration_tc` τ_c (and t ≥ 1 τ_c; reported as `rest_time_tc`), or at `end_tc` τ_c.

use std::path::Path;

use serde::Serialize;

use super::{rest_scale, run_resumable, steps_per_row, Column, Plan, Row, Tally};
use crate::analysis::runout::CollapseOutcome;
use crate::coupling::RveMaterial;
use crate::dem::periodic_cell::PeriodicCell;
use crate::exec::Progress;
use crate::io::{write_vti, write_vtu_points, Field, ImageGrid, PvdSeries, VtkFormat};
use crate::mpm::material::{invariants, Material, MaterialModel, MaterialState};
use crate::mpm::solver::{Mpm, MpmEnergy};
use crate::scenario::checkpointing::Control;
use crate::scenario::mpm::spec::{Law, MpmScenario};
use crate::scenario::Kind;
use crate::{Error, Result};

/// What a material adds to the points' VTK output: named scalar arrays of its per-point
/// state.
pub trait PointOutput: Material + Clone + 'static {
    /// The arrays, one value per point.
    fn point_scalars(states: &[Self::State]) -> Vec<(&'static str, Vec<f64>)>;
    /// What the summary calls the solver.
    const SOLVER: &'static str;
    /// Write the grains of one point's state as VTK points centred on `centre` (only
    /// materials whose points hold grains can).
    fn write_grains(
        state: &Self::State,
        centre: [f64; 2],
        format: &VtkFormat,
        path: &Path,
    ) -> Result<()>;
}

impl PointOutput for MaterialModel {
    fn point_scalars(states: &[MaterialState]) -> Vec<(&'static str, Vec<f64>)> {
        vec![(
            "plastic_strain",
            states.iter().map(|s| s.plastic_strain).collect(),
        )]
    }
    const SOLVER: &'static str = "mpm";
    fn write_grains(_: &MaterialState, _: [f64; 2], _: &VtkFormat, path: &Path) -> Result<()> {
        Err(Error::Other(format!(
            "{}: a continuum point holds no grains",
            path.display()
        )))
    }
}

/// A representative volume's packing fraction, coordination number, fabric tensor
/// (1/N_c) Σ n ⊗ n (xx, yy, xy) and number of grains (grown by re-tiling) at each point.
impl PointOutput for RveMaterial {
    fn point_scalars(states: &[PeriodicCell]) -> Vec<(&'static str, Vec<f64>)> {
        let of = |f: &dyn Fn(&PeriodicCell) -> f64| states.iter().map(f).collect::<Vec<f64>>();
        vec![
            ("packing_fraction", of(&|c| c.packing_fraction())),
            ("coordination", of(&|c| c.coordination())),
            ("fabric_xx", of(&|c| c.fabric()[(0, 0)])),
            ("fabric_yy", of(&|c| c.fabric()[(1, 1)])),
            ("fabric_xy", of(&|c| c.fabric()[(0, 1)])),
            ("grains", of(&|c| c.len() as f64)),
        ]
    }
    const SOLVER: &'static str = "mpm-rve";
    /// The volume's grains at their places in the cell, the cell's centre H (½, ½) moved to
    /// `centre`, with their `radius` and `fluctuation_velocity` (the velocity less the
    /// affine part L x).
    fn write_grains(
        cell: &PeriodicCell,
        centre: [f64; 2],
        format: &VtkFormat,
        path: &Path,
    ) -> Result<()> {
        let mid = cell.cell() * nalgebra::Vector2::new(0.5, 0.5);
        let (pos, radius): (Vec<[f64; 2]>, Vec<f64>) = cell
            .grains()
            .map(|(x, r)| ([centre[0] + x[0] - mid.x, centre[1] + x[1] - mid.y], r))
            .unzip();
        let vel: Vec<[f64; 2]> = cell.fluctuation_velocities().collect();
        let fields = [
            Field::scalar("radius", &radius),
            Field::vector("fluctuation_velocity", &vel),
        ];
        write_vtu_points(path, &pos, &fields, &[], &[], format)
    }
}

/// What an MPM collapse run reports (`summary.json`): the solver-independent outcome (the
/// same keys as the DEM's, so the two compare directly), the DEM's other keys where they have
/// a meaning, and MPM-specific ones.
#[derive(Clone, Debug, Serialize)]
pub struct MpmCollapseSummary {
    /// L_f, ΔL, H_f, stop time, … (the keys every collapse runner writes).
    #[serde(flatten)]
    pub collapse: CollapseOutcome,
    /// DEM key: here the number of material points.
    pub grains: usize,
    /// DEM key: not defined for the continuum (null).
    pub packing_fraction: Option<f64>,
    /// DEM key (deposition): 0, the MPM column is built directly.
    pub deposition_wall_time_s: f64,
    /// `"mpm"`.
    pub solver: String,
    /// Number of material points.
    pub points: usize,
    /// Grid cells (x, y).
    pub cells: [usize; 2],
    /// Cell size h (m).
    pub cell_size: f64,
}

/// Run-out, front and height (see the module doc).
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    /// Largest x + l_p over the main mass.
    pub runout: f64,
    /// Largest x + l_p over all points.
    pub front: f64,
    /// Largest y + l_p over the main mass.
    pub height: f64,
}

fn find(parent: &mut [u32], mut a: u32) -> u32 {
    while parent[a as usize] != a {
        let p = parent[a as usize];
        parent[a as usize] = parent[p as usize];
        a = p;
    }
    a
}

/// Measure the deposit shape (see the module doc).
pub fn shape<M: Material>(mpm: &Mpm<M>) -> Shape {
    let g = &mpm.grid;
    let (nx, ny) = (g.nx, g.ny);
    let cell = |x: [f64; 2]| -> usize {
        let i = ((x[0] - g.origin[0]) / g.h)
            .floor()
            .clamp(0.0, (nx - 1) as f64) as usize;
        let j = ((x[1] - g.origin[1]) / g.h)
            .floor()
            .clamp(0.0, (ny - 1) as f64) as usize;
        i * ny + j
    };
    let mut count = vec![0u32; nx * ny];
    for &x in &mpm.points.pos {
        count[cell(x)] += 1;
    }
    let mut parent: Vec<u32> = (0..(nx * ny) as u32).collect();
    for i in 0..nx {
        for j in 0..ny {
            let c = i * ny + j;
            if count[c] == 0 {
                continue;
            }
            // Neighbours already visited: (i−1, j−1..=j+1) and (i, j−1).
            let mut link = |d: usize| {
                if count[d] > 0 {
                    let (a, b) = (find(&mut parent, c as u32), find(&mut parent, d as u32));
                    if a != b {
                        parent[a as usize] = b;
                    }
                }
            };
            if j > 0 {
                link(c - 1);
            }
            if i > 0 {
                for dj in [-1i64, 0, 1] {
                    let jj = j as i64 + dj;
                    if jj >= 0 && jj < ny as i64 {
                        link((i - 1) * ny + jj as usize);
                    }
                }
            }
        }
    }
    let mut size = vec![0u32; nx * ny];
    for (c, &k) in count.iter().enumerate() {
        if k > 0 {
            let r = find(&mut parent, c as u32);
            size[r as usize] += k;
        }
    }
    let main = (0..nx * ny).max_by_key(|&r| size[r]).unwrap_or(0) as u32;
    let (mut runout, mut front, mut height) = (0.0f64, 0.0f64, 0.0f64);
    for (q, &x) in mpm.points.pos.iter().enumerate() {
        let lp = mpm.points.half_size[q];
        front = front.max(x[0] + lp);
        if find(&mut parent, cell(x) as u32) == main {
            runout = runout.max(x[0] + lp);
            height = height.max(x[1] + lp);
        }
    }
    Shape {
        runout,
        front,
        height,
    }
}

pub(crate) fn write_frame<M: PointOutput>(
    mpm: &Mpm<M>,
    volumes: &[[f64; 2]],
    format: &VtkFormat,
    dir: &Path,
    k: usize,
    pvd: &mut PvdSeries,
) -> Result<()> {
    let p = &mpm.points;
    for (v, start) in volumes.iter().enumerate() {
        // Points are re-sorted: a point is known by its initial position.
        let Some(q) = p.pos0.iter().position(|x| x == start) else {
            continue;
        };
        let name = format!("volume_{v}_{k:06}.vtu");
        M::write_grains(&p.state[q], p.pos[q], format, &dir.join(&name))?;
        pvd.add(mpm.time(), 2 + v, &name)?;
    }
    let n = p.len();
    let comp = |c: usize| -> Vec<f64> { p.stress.iter().map(|s| s[c]).collect() };
    let (sxx, syy, sxy, szz) = (comp(0), comp(1), comp(2), comp(3));
    let inv: Vec<(f64, f64)> = p.stress.iter().map(invariants).collect();
    let mean: Vec<f64> = inv.iter().map(|v| v.0).collect();
    let dev: Vec<f64> = inv.iter().map(|v| v.1).collect();
    let own = M::point_scalars(&p.state);
    let name = format!("points_{k:06}.vtu");
    let mut fields = vec![
        Field::vector("velocity", &p.vel),
        Field::scalar("stress_xx", &sxx),
        Field::scalar("stress_yy", &syy),
        Field::scalar("stress_xy", &sxy),
        Field::scalar("stress_zz", &szz),
        Field::scalar("mean_stress", &mean),
        Field::scalar("deviatoric_stress", &dev),
    ];
    fields.extend(own.iter().map(|(n, v)| Field::scalar(n, v)));
    fields.push(Field::scalar("volume", &p.vol));
    write_vtu_points(&dir.join(&name), &p.pos, &fields, &[], &[], format)?;
    let g = &mpm.grid;
    let mut rho = vec![0.0; g.nx * g.ny];
    let mut mv = vec![[0.0; 2]; g.nx * g.ny];
    for q in 0..n {
        let x = p.pos[q];
        let i = ((x[0] - g.origin[0]) / g.h)
            .floor()
            .clamp(0.0, (g.nx - 1) as f64) as usize;
        let j = ((x[1] - g.origin[1]) / g.h)
            .floor()
            .clamp(0.0, (g.ny - 1) as f64) as usize;
        // VTK image cells are x-fastest.
        let c = j * g.nx + i;
        rho[c] += p.mass[q];
        mv[c][0] += p.mass[q] * p.vel[q][0];
        mv[c][1] += p.mass[q] * p.vel[q][1];
    }
    let vel: Vec<[f64; 2]> = rho
        .iter()
        .zip(&mv)
        .map(|(&m, v)| {
            if m > 0.0 {
                [v[0] / m, v[1] / m]
            } else {
                [0.0; 2]
            }
        })
        .collect();
    rho.iter_mut().for_each(|m| *m /= g.h * g.h);
    let gname = format!("grid_{k:06}.vti");
    write_vti(
        &dir.join(&gname),
        &ImageGrid {
            nx: g.nx,
            ny: g.ny,
            origin: g.origin,
            spacing: [g.h, g.h],
        },
        &[
            Field::scalar("density", &rho),
            Field::vector("velocity", &vel),
        ],
        format,
    )?;
    pvd.add(mpm.time(), 0, &name)?;
    pvd.add(mpm.time(), 1, &gname)
}

impl<M> super::Resumable for MpmColumn<M>
where
    M: PointOutput + Serialize + serde::de::DeserializeOwned,
    M::State: Serialize + serde::de::DeserializeOwned,
{
    type Saved<'s>
        = &'s MpmColumn<M>
    where
        M: 's;
    type Loaded = MpmColumn<M>;
    fn saved(&self) -> &MpmColumn<M> {
        self
    }
}

/// An MPM column: the material points released between the floor and the walls.
#[derive(Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "M: Serialize, M::State: Serialize",
    deserialize = "M: serde::Deserialize<'de>, M::State: serde::Deserialize<'de>"
))]
pub struct MpmColumn<M: PointOutput = MaterialModel> {
    /// The continuum.
    pub mpm: Mpm<M>,
    e0: MpmEnergy,
    /// Steps per time-series row.
    series_steps: u64,
    /// Initial positions of the points whose grains each frame writes.
    volumes: Vec<[f64; 2]>,
}

/// The MPM's time-series columns after the geometry (the DEM's names where they apply).
const COLUMNS: &[&str] = &[
    "kinetic",
    "potential",
    "elastic",
    "dissipated_plastic",
    "dissipated_normal",
    "dissipated_friction",
    "dissipated_damping",
    "budget_error",
];

impl<M: PointOutput> MpmColumn<M> {
    /// Relative energy budget error, 0 while almost nothing is dissipated (t ≈ 0, where the
    /// ratio would be round-off over round-off).
    fn budget(&self, e: &MpmEnergy) -> f64 {
        let tiny = 1e-9 * self.e0.total().abs();
        if e.dissipated() > tiny {
            (e.total() - self.e0.total()).abs() / e.dissipated()
        } else {
            0.0
        }
    }
}

impl<M: PointOutput> Column for MpmColumn<M> {
    type Shape = MpmEnergy;
    type Summary = MpmCollapseSummary;

    fn columns(&self) -> &'static [&'static str] {
        COLUMNS
    }
    fn time(&self) -> f64 {
        self.mpm.time()
    }
    fn measure(&mut self) -> Result<(Row, MpmEnergy)> {
        let e = self.mpm.energy();
        let s = shape(&self.mpm);
        let row = Row {
            runout: s.runout,
            front: s.front,
            height: s.height,
            kinetic: e.kinetic,
            values: vec![
                e.kinetic,
                e.potential,
                e.elastic,
                e.plastic,
                e.boundary_normal,
                e.boundary_friction,
                e.damping,
                self.budget(&e),
            ],
        };
        Ok((row, e))
    }
    fn write_frame(
        &self,
        _: &MpmEnergy,
        format: &VtkFormat,
        dir: &Path,
        k: usize,
        _: f64,
        pvd: &mut PvdSeries,
    ) -> Result<()> {
        write_frame(&self.mpm, &self.volumes, format, dir, k, pvd)
    }
    fn advance(&mut self) -> Result<()> {
        self.mpm.steps(self.series_steps)
    }
    fn tally(&self, e: &MpmEnergy) -> Tally {
        Tally {
            steps: self.mpm.step_count(),
            dt: self.mpm.dt(),
            particles: self.mpm.points.len(),
            energy_budget_error: self.budget(e),
            energy: e.budget(&self.e0),
        }
    }
    fn summary(&self, collapse: CollapseOutcome) -> MpmCollapseSummary {
        let n = self.mpm.points.len();
        MpmCollapseSummary {
            collapse,
            grains: n,
            packing_fraction: None,
            deposition_wall_time_s: 0.0,
            solver: M::SOLVER.into(),
            points: n,
            cells: [self.mpm.grid.nx, self.mpm.grid.ny],
            cell_size: self.mpm.grid.h,
        }
    }
}

/// The plan of the run of `scenario` for a column of initial `height` and potential energy
/// `potential` (at t = 0).
fn plan(scenario: &MpmScenario, height: f64, potential: f64) -> Plan<'_> {
    let ts = &scenario.time;
    Plan {
        name: &scenario.name,
        l_i: scenario.column.width,
        h_i: height,
        gravity: scenario.gravity[0].hypot(scenario.gravity[1]),
        potential,
        series_interval_tc: ts.series_interval_tc,
        frame_interval_tc: ts.frame_interval_tc,
        end_tc: ts.end_tc,
        rest_kinetic_fraction: ts.rest_kinetic_fraction,
        rest_duration_tc: ts.rest_duration_tc,
        vtk: scenario.vtk,
    }
}

/// The column of a system `mpm` built for `scenario`.
fn column_of<'a, M: PointOutput>(
    scenario: &'a MpmScenario,
    mpm: Mpm<M>,
    height: f64,
    tau_c: f64,
) -> (MpmColumn<M>, Plan<'a>) {
    let g = scenario.gravity[0].hypot(scenario.gravity[1]);
    let y: Vec<f64> = mpm.points.pos.iter().map(|p| p[1]).collect();
    let plan = plan(scenario, height, rest_scale(&mpm.points.mass, &y, g));
    let series_steps = steps_per_row(scenario.time.series_interval_tc, tau_c, mpm.dt());
    let e0 = mpm.energy();
    (
        MpmColumn {
            mpm,
            e0,
            series_steps,
            volumes: Vec::new(),
        },
        plan,
    )
}

/// Build the column of `scenario` with a closed-form law: the MPM system and the run's plan.
pub fn column(scenario: &MpmScenario) -> Result<(MpmColumn, Plan<'_>)> {
    let (mpm, d) = scenario.build()?;
    Ok(column_of(scenario, mpm, d.height, d.tau_c))
}

/// Run the collapse described by `scenario`, writing into `out_dir` (created if missing).
/// Returns the summary also written to `summary.json`. A representative-volume material is
/// prepared first (the volume every point starts from).
pub fn run_column_collapse(
    scenario: &MpmScenario,
    out_dir: &Path,
    progress: Progress,
) -> Result<MpmCollapseSummary> {
    run_column_collapse_with(scenario, out_dir, &[], Control::default(), progress)
}

/// [`run_column_collapse`], checkpointing, stopping and resuming as `control` says (a resumed
/// run takes its column, representative volumes included, from the checkpoint), and with
/// every frame the grains of the representative volumes of the points nearest `volumes` in
/// the initial column (m; each within a cell of a point): `volume_<k>_<frame>.vtu`, part
/// 2 + k of `series.pvd`, centred on the point.
pub fn run_column_collapse_with(
    scenario: &MpmScenario,
    out_dir: &Path,
    volumes: &[[f64; 2]],
    control: Control,
    progress: Progress,
) -> Result<MpmCollapseSummary> {
    check_volumes(scenario, volumes)?;
    let d = scenario.derive()?;
    let plan_of = |height, potential| plan(scenario, height, potential);
    match &d.material {
        Law::Continuum(m) => {
            let start = || {
                let mpm = scenario.build_with(*m, &d, |_| [0.0; 4])?;
                Ok(column_of(scenario, mpm, d.height, d.tau_c))
            };
            run_resumable(Kind::Mpm, start, Ok, plan_of, out_dir, control, progress)
        }
        Law::Volume(v) => {
            let start = || {
                let material = v.material()?;
                let geostatic = scenario.geostatic(&d, material.density(), v.k0);
                let mpm = scenario.build_with(material, &d, geostatic)?;
                let chosen = nearest_points(&mpm, volumes)?;
                let (mut column, plan) = column_of(scenario, mpm, d.height, d.tau_c);
                column.volumes = chosen;
                Ok((column, plan))
            };
            run_resumable(Kind::Mpm, start, Ok, plan_of, out_dir, control, progress)
        }
    }
}

/// Refuses, before anything is prepared or written, places of `--rve-frames` (`volumes`) in a
/// scenario whose points hold no grains, or outside its initial column.
pub fn check_volumes(scenario: &MpmScenario, volumes: &[[f64; 2]]) -> Result<()> {
    let d = scenario.derive()?;
    match &d.material {
        Law::Continuum(_) if !volumes.is_empty() => Err(Error::Other(
            "--rve-frames: the points of this scenario hold no grains (material.model is not \
             \"rve\")"
                .into(),
        )),
        Law::Continuum(_) => Ok(()),
        Law::Volume(_) => check_places(
            volumes,
            scenario.column.width,
            d.height,
            scenario.mpm.cell_size,
        ),
    }
}

/// Refuses, before anything is prepared, a place outside the initial column `width` × `height`
/// widened by a cell size `h`.
fn check_places(wanted: &[[f64; 2]], width: f64, height: f64, h: f64) -> Result<()> {
    match wanted
        .iter()
        .find(|w| !((-h..=width + h).contains(&w[0]) && (-h..=height + h).contains(&w[1])))
    {
        Some(w) => Err(Error::Other(format!(
            "--rve-frames: ({}, {}) m is outside the initial column (0–{width} m × 0–{height} m)",
            w[0], w[1]
        ))),
        None => Ok(()),
    }
}

/// The initial positions of the points nearest `wanted`; refuses a place farther than a cell
/// size from every point.
fn nearest_points<M: Material>(mpm: &Mpm<M>, wanted: &[[f64; 2]]) -> Result<Vec<[f64; 2]>> {
    let h = mpm.grid.h;
    let dist2 = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    wanted
        .iter()
        .map(|&w| {
            let best = mpm
                .points
                .pos0
                .iter()
                .copied()
                .min_by(|a, b| dist2(*a, w).total_cmp(&dist2(*b, w)));
            match best {
                Some(x) if dist2(x, w) <= h * h => Ok(x),
                _ => Err(Error::Other(format!(
                    "--rve-frames: no material point within a cell size ({h:e} m) of ({}, {}) m \
                     in the initial column",
                    w[0], w[1]
                ))),
            }
        })
        .collect()
}
