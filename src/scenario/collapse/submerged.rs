//! Runner of the submerged column collapse ([`SubmergedScenario`]): deposit the column dry,
//! fill the tank, remove the gate, and advance the LBM fluid and the DEM grains together
//! ([`Coupled`], partially saturated cells, sub-cycled DEM) until the mass is at rest.
//!
//! Output folder:
//! * `series.pvd`: per frame, at one time, `grains_NNNNNN.vtu` (part 0, as the dry DEM
//!   runner writes it), `contacts_NNNNNN.vtu` (part 1, force chains) and `fluid_NNNNNN.vti`
//!   (part 2, cell data: `velocity` (m/s), `pressure` (Pa: hydrostatic ρ_f g (depth − y) +
//!   excess), `excess_pore_pressure` (Pa), `vorticity` (1/s), `solid_fraction` ε), so
//!   ParaView shows fluid and grains together. Every file is written to a temporary name and
//!   renamed.
//! * `timeseries.csv`: the DEM collapse columns (run-out, front, height, energies with the
//!   reduced gravity g′) and `pore_pressure_base` (Pa), `drag_x`, `drag_y` (N), `fluid_kinetic`
//!   (J), `max_mach`.
//! * `summary.json`: the collapse outcome ([`CollapseOutcome`], `energy_budget_error` null:
//!   the work of the fluid is not tracked), grains, packing, and the fluid set-up and pore
//!   pressure means ([`FluidSummary`]).
//!
//! **Excess pore pressure under the column** (`pore_pressure_base`): the mean of
//! p_e = c_s² (ρ − 1) (lattice, converted to Pa) over the lattice cells whose centre lies in the
//! strip 0 < x < L_i, 0 < y < d_max at the base of the initial column, each cell weighted by
//! its fluid fraction 1 − ε. With reduced gravity the liquid carries no hydrostatic pressure, so
//! its pressure is the excess pore pressure itself (the mean over the closed tank stays 0: mass
//! is conserved).
//!
//! **Drag on the mass** (`drag_x`, `drag_y`): the hydrodynamic force summed over all grains,
//! Σ_k F_k (N; lattice force per metre × `grains.thickness`), as held during the last coupled
//! step. Buoyancy is not in it (it is in g′).
//!
//! A NaN, ρ ≤ 0 or a lattice Mach number above [`crate::lbm::STOP_MACH`] in any cell stops the
//! run with [`Error::Unstable`] (checked at every time-series row); `summary.json` is not
//! written then, the frames so far are kept.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use crate::analysis::runout::{CollapseOutcome, CollapseRecord};
use crate::coupling::{
    reduced_gravity, CellForces, Coupled, CoupledFluid, DiskCover, Exchange, Grid, LaddMap,
    SolidCover,
};
use crate::dem::packing::deposit_column;
use crate::dem::scale::GrainView;
use crate::dem::{Dem, ExternalLoads, Wall};
use crate::io::{write_json, write_vti, CsvWriter, Field, ImageGrid, PvdSeries};
use crate::lbm::{Edge, Edges, Fluid, FluidModel, Lattice, Lbm, Macroscopic, Obstacles, Real};
use crate::scale::Scale;
use crate::scenario::collapse::dem::{shape, write_frame};
use crate::scenario::fluid::Precision;
use crate::scenario::submerged::spec::{CouplingMethod, DerivedSubmerged, SubmergedScenario};
use crate::units::CS2;
use crate::{Error, Result};

/// The grain ↔ lattice map for disks of axial length `thickness`: the lattice's forces per
/// metre of depth × thickness are the forces on the grains (N, N·m). Partially saturated
/// cells through `cover`, or Ladd's bounce-back links through `ladd` when set (`cover` then
/// only gives the solid fraction written to the frames).
#[derive(Clone, Debug)]
pub struct SlabCover {
    /// The disk ↔ cell map.
    pub cover: DiskCover,
    /// Ladd's link map, used instead of `cover` for the exchange when set.
    pub ladd: Option<LaddMap>,
    /// Axial length of the disks (m).
    pub thickness: f64,
}

impl<F, S> Exchange<F, S> for SlabCover
where
    F: Scale<Input = SolidCover, Output = CellForces>,
    S: Scale<Input = ExternalLoads, Output = GrainView>,
{
    fn to_fluid(&mut self, solid: &GrainView, fluid_in: &mut SolidCover) {
        match &mut self.ladd {
            Some(l) => Exchange::<F, S>::to_fluid(l, solid, fluid_in),
            None => self.cover.cover(solid, fluid_in),
        }
    }
    fn to_solid(&mut self, fluid: &CellForces, solid_in: &mut ExternalLoads) {
        match &mut self.ladd {
            Some(l) => Exchange::<F, S>::to_solid(l, fluid, solid_in),
            None => {
                let n = self.cover.grains();
                self.cover.loads(fluid, n, solid_in);
            }
        }
        let w = self.thickness;
        for v in [&mut solid_in.fx, &mut solid_in.fy, &mut solid_in.torque] {
            v.iter_mut().for_each(|x| *x *= w);
        }
    }
}

/// Fluid part of `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct FluidSummary {
    /// Coupling method.
    pub method: CouplingMethod,
    /// r/R.
    pub radius_factor: f64,
    /// Liquid density (kg/m³) and kinematic viscosity (m²/s).
    pub density: f64,
    /// Kinematic viscosity (m²/s).
    pub viscosity: f64,
    /// Lattice cells [nx, ny].
    pub cells: [usize; 2],
    /// Δx (m).
    pub dx: f64,
    /// Lattice Δt (s) = the coupled step.
    pub dt: f64,
    /// τ.
    pub tau: f64,
    /// `"f32"` / `"f64"`.
    pub precision: &'static str,
    /// DEM sub-steps per lattice step.
    pub subcycles: u64,
    /// Reduced gravity g′ (m/s²).
    pub reduced_gravity: f64,
    /// Lattice Mach number of the collapse speed √(g′H) (design value).
    pub mach_design: f64,
    /// Largest lattice Mach number seen at a time-series row.
    pub max_mach: f64,
    /// Pressure scale (ρ_s − ρ_f) φ g H_i (Pa): the buoyant weight of the column per area.
    pub pressure_scale: f64,
    /// Period of the slowest acoustic mode of the closed tank, T_a = 2 max(L_box, depth)/c_s
    /// with c_s = Δx/(√3 Δt) the lattice sound speed, in τ_c. The weakly compressible liquid
    /// sloshes at this period; means over it remove that mode from the pore pressure.
    pub acoustic_period_tc: f64,
    /// Mean base excess pore pressure over 0 < t ≤ T_a (Pa): the "early" value.
    pub pore_pressure_early_mean: f64,
    /// Mean base excess pore pressure over 0 < t ≤ 2 T_a (Pa).
    pub pore_pressure_early_mean_2ta: f64,
    /// Lattice updates per second over the run (millions).
    pub mlups: f64,
}

/// What a submerged collapse run reports (`summary.json`).
#[derive(Clone, Debug, Serialize)]
pub struct SubmergedSummary {
    /// L_f, ΔL, H_f, stop time, … (the keys every collapse runner writes).
    #[serde(flatten)]
    pub collapse: CollapseOutcome,
    /// Number of grains.
    pub grains: usize,
    /// Packing fraction of the deposited column (interior strip).
    pub packing_fraction: f64,
    /// Wall time of the deposition (s).
    pub deposition_wall_time_s: f64,
    /// The liquid and the coupling.
    pub fluid: FluidSummary,
}

impl SubmergedSummary {
    /// The one-line result `granflow run` prints.
    pub fn done_line(&self) -> String {
        let c = &self.collapse;
        format!(
            "done: a = {:.3}, L_f/L_i − 1 = {:.3}, H_f/L_i = {:.3}, spreading stopped at {:.2} τ_c, {} at {:.2} τ_c, {} grains, packing {:.3}, base pore pressure mean over the first acoustic period ({:.2} τ_c) {:.3e} Pa, over two {:.3e} Pa, {:.1} s wall",
            c.aspect_ratio,
            c.delta_l,
            c.h_f_over_l_i,
            c.stop_time_tc,
            if c.at_rest { "at rest" } else { "end time reached" },
            c.rest_time_tc,
            self.grains,
            self.packing_fraction,
            self.fluid.acoustic_period_tc,
            self.fluid.pore_pressure_early_mean,
            self.fluid.pore_pressure_early_mean_2ta,
            c.wall_time_s
        )
    }
}

/// Run the submerged collapse described by `scenario`, writing into `out_dir` (created if
/// missing). Returns the summary also written to `summary.json`.
pub fn run_submerged(
    scenario: &SubmergedScenario,
    out_dir: &Path,
    progress: crate::exec::Progress,
) -> Result<SubmergedSummary> {
    let d = scenario.derive()?;
    match scenario.coupling.precision {
        Precision::F32 => run_typed::<f32>(scenario, &d, out_dir, progress),
        Precision::F64 => run_typed::<f64>(scenario, &d, out_dir, progress),
    }
}

/// The fluid frame's cell fields (SI) and the base pore pressure.
struct FluidFields {
    m: Macroscopic,
    eps: Vec<f64>,
    cover: SolidCover,
    view: GrainView,
    /// Cells of the base strip under the initial column.
    strip: Vec<usize>,
}

impl FluidFields {
    /// Refresh the macroscopic fields and ε (from the grains as they are now).
    fn refresh<T: Real>(&mut self, c: &mut Coupled<CoupledFluid<T>, Dem, SlabCover>) {
        c.fluid.lbm.macroscopic_into(&mut self.m);
        c.solid.observe(&mut self.view);
        c.map.cover.cover(&self.view, &mut self.cover);
        self.eps.iter_mut().for_each(|e| *e = 0.0);
        for (k, &cell) in self.cover.cells.iter().enumerate() {
            self.eps[cell as usize] = self.cover.eps[k];
        }
    }

    /// Excess pore pressure (Pa) of cell `c`.
    fn excess(&self, u: &crate::units::Units, c: usize) -> f64 {
        u.pressure_to_si(self.m.rho[c])
    }

    /// Mean excess pore pressure over the base strip, weighted by 1 − ε (0 if all solid).
    fn base(&self, u: &crate::units::Units) -> f64 {
        let (mut s, mut w) = (0.0, 0.0);
        for &c in &self.strip {
            let f = 1.0 - self.eps[c];
            s += f * self.excess(u, c);
            w += f;
        }
        if w > 0.0 {
            s / w
        } else {
            0.0
        }
    }

    /// Largest lattice Mach number |u|/c_s over the fluid.
    fn max_mach(&self) -> f64 {
        let m = &self.m;
        (0..m.ux.len())
            .map(|c| m.ux[c].hypot(m.uy[c]))
            .fold(0.0, f64::max)
            / CS2.sqrt()
    }

    /// Fluid kinetic energy Σ ½ ρ |u|² (1 − ε) Δx² × thickness (J).
    fn kinetic(&self, u: &crate::units::Units, thickness: f64) -> f64 {
        let m = &self.m;
        let v = u.velocity_to_si(1.0);
        let rho = u.density_to_si(1.0);
        (0..m.ux.len())
            .map(|c| 0.5 * m.rho[c] * (m.ux[c].powi(2) + m.uy[c].powi(2)) * (1.0 - self.eps[c]))
            .sum::<f64>()
            * rho
            * v
            * v
            * u.dx
            * u.dx
            * thickness
    }

    fn write(&self, u: &crate::units::Units, hydro: f64, depth: f64, path: &Path) -> Result<()> {
        let (nx, ny) = (self.m.nx, self.m.ny);
        let v = u.velocity_to_si(1.0);
        let vel: Vec<[f64; 2]> = (0..nx * ny)
            .map(|c| [self.m.ux[c] * v, self.m.uy[c] * v])
            .collect();
        let excess: Vec<f64> = (0..nx * ny).map(|c| self.excess(u, c)).collect();
        let pressure: Vec<f64> = (0..nx * ny)
            .map(|c| excess[c] + hydro * (depth - ((c / nx) as f64 + 0.5) * u.dx))
            .collect();
        let vort: Vec<f64> = self
            .m
            .vorticity()
            .into_iter()
            .map(|w| u.rate_to_si(w))
            .collect();
        write_vti(
            path,
            &ImageGrid {
                nx,
                ny,
                origin: [0.0, 0.0],
                spacing: [u.dx, u.dx],
            },
            &[
                Field::vector("velocity", &vel),
                Field::scalar("pressure", &pressure),
                Field::scalar("excess_pore_pressure", &excess),
                Field::scalar("vorticity", &vort),
                Field::scalar("solid_fraction", &self.eps),
            ],
        )
    }
}

fn run_typed<T: Real>(
    scenario: &SubmergedScenario,
    d: &DerivedSubmerged,
    out_dir: &Path,
    progress: crate::exec::Progress,
) -> Result<SubmergedSummary> {
    std::fs::create_dir_all(out_dir).map_err(|e| Error::io(out_dir, e))?;
    let t0 = Instant::now();
    let column = deposit_column(&d.dem.column)?;
    let deposition_wall_time_s = t0.elapsed().as_secs_f64();
    let (l_i, h_i) = (scenario.column.width, column.height);
    let f = &scenario.fluid;
    if h_i + scenario.grains.d_max > f.depth {
        return Err(Error::config(
            "fluid.depth",
            format!(
                "the deposited column is {h_i} m high; the tank must be deeper than {} m",
                h_i + scenario.grains.d_max
            ),
        ));
    }
    let gmag = scenario.gravity;
    let tau_c = (h_i / gmag).sqrt();
    let walls = vec![
        Wall::floor(0.0),
        Wall::left(0.0),
        Wall::right(scenario.column.box_length),
    ];
    let mut params = d.dem.params.clone();
    params.gravity = reduced_gravity([0.0, -gmag], f.density, scenario.grains.density);
    let dem = Dem::new(column.grains, walls, params)?;
    let [nx, ny] = d.cells;
    let u = d.units;
    let wall = Edge::Wall { velocity: [0.0; 2] };
    let edges = Edges {
        left: wall.clone(),
        right: wall.clone(),
        bottom: wall.clone(),
        top: wall,
    };
    let lattice = Lattice::<T>::new(nx, ny, edges, vec![false; nx * ny])
        .map_err(|e| Error::Other(format!("lattice: {e}")))?;
    let fluid = CoupledFluid::new(Lbm::new(
        lattice,
        FluidModel {
            collision: d.model,
            smagorinsky: scenario.coupling.smagorinsky,
            body_force: [0.0; 2],
        },
        Obstacles::default(),
        u,
    ));
    let grid = Grid {
        nx,
        ny,
        dx: u.dx,
        periodic: [false, false],
    };
    let r = scenario.coupling.radius_factor;
    let map = SlabCover {
        cover: DiskCover::new(grid, r)?,
        ladd: match scenario.coupling.method {
            CouplingMethod::Psm => None,
            CouplingMethod::Ladd => Some(LaddMap::new(grid, r)?),
        },
        thickness: scenario.grains.thickness,
    };
    let mut c = Coupled::new(fluid, dem, map);
    c.solid.refresh_forces();
    let e0 = c.solid.energy();
    let ts = &scenario.time;
    let dt = u.dt;
    let series_steps = ((ts.series_interval_tc * tau_c / dt).round() as u64).max(1);
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
            "pore_pressure_base",
            "drag_x",
            "drag_y",
            "fluid_kinetic",
            "max_mach",
        ],
    )?;
    let strip: Vec<usize> = (0..nx * ny)
        .filter(|&cell| {
            let (x, y) = (
                ((cell % nx) as f64 + 0.5) * u.dx,
                ((cell / nx) as f64 + 0.5) * u.dx,
            );
            x < l_i && y < scenario.grains.d_max
        })
        .collect();
    if strip.is_empty() {
        return Err(Error::config(
            "coupling.dx",
            "no lattice cell centre lies in the base strip under the column",
        ));
    }
    let mut ff = FluidFields {
        m: Macroscopic::default(),
        eps: vec![0.0; nx * ny],
        cover: SolidCover::default(),
        view: GrainView::default(),
        strip,
    };
    let mut pvd = PvdSeries::new(out_dir);
    let rest_limit = ts.rest_kinetic_fraction * e0.potential;
    let (mut rest_since, mut at_rest) = (None::<f64>, false);
    let (mut row, mut frame) = (0u64, 0usize);
    let mut history = Vec::new();
    let mut pore = Vec::new();
    let mut max_mach: f64 = 0.0;
    let hydro = f.density * gmag;
    let t_run = Instant::now();
    let frame_out = |c: &Coupled<CoupledFluid<T>, Dem, SlabCover>,
                     ff: &FluidFields,
                     s: &crate::scenario::collapse::dem::Shape,
                     k: usize,
                     t: f64,
                     pvd: &mut PvdSeries|
     -> Result<()> {
        write_frame(&c.solid, s, scenario.grains.thickness, out_dir, k, t, pvd)?;
        let name = format!("fluid_{k:06}.vti");
        ff.write(&u, hydro, f.depth, &out_dir.join(&name))?;
        pvd.add(t, 2, &name)
    };
    let mut last;
    loop {
        let t = c.steps as f64 * dt;
        ff.refresh(&mut c);
        let e = c.solid.energy();
        let s = shape(&c.solid);
        let p_base = ff.base(&u);
        let mach = ff.max_mach();
        max_mach = max_mach.max(mach);
        let loads = c.solid_input();
        // `+ 0.0`: an empty sum is −0.0 (before the first step).
        let drag_x = loads.fx.iter().sum::<f64>() + 0.0;
        let drag_y = loads.fy.iter().sum::<f64>() + 0.0;
        history.push((t, s.runout));
        pore.push((t, p_base));
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
            p_base,
            drag_x,
            drag_y,
            ff.kinetic(&u, scenario.grains.thickness),
            mach,
        ])?;
        if row % frame_every == 0 {
            frame_out(&c, &ff, &s, frame, t, &mut pvd)?;
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
        last = s;
        progress((1e3 * t / tau_c) as u64, (1e3 * ts.end_tc) as u64);
        if at_rest || t >= ts.end_tc * tau_c {
            break;
        }
        for _ in 0..series_steps {
            c.step()?;
        }
        Fluid::check_stable(&c.fluid.lbm, crate::lbm::STOP_MACH)?;
    }
    let wall_time_s = t_run.elapsed().as_secs_f64();
    let t_end = c.steps as f64 * dt;
    if (row - 1) % frame_every != 0 {
        frame_out(&c, &ff, &last, frame, t_end, &mut pvd)?;
    }
    let grains = c.solid.grains.len();
    let collapse = CollapseOutcome::from(CollapseRecord {
        name: &scenario.name,
        l_i,
        h_i,
        gravity: gmag,
        history: &history,
        h_f: last.height,
        rest_since,
        at_rest,
        t_end,
        dt,
        steps: c.steps,
        wall_time_s,
        particles: grains,
        energy_budget_error: f64::NAN,
        // The grains' budget; what the liquid took is in the DEM's external work.
        energy: c.solid.energy().budget(&e0),
    });
    let sound = u.dx / (3f64.sqrt() * dt);
    let t_a = 2.0 * scenario.column.box_length.max(f.depth) / sound;
    let mean_until = |t1: f64| {
        let v: Vec<f64> = pore
            .iter()
            .filter(|p| p.0 > 0.0 && p.0 <= t1)
            .map(|p| p.1)
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    let summary = SubmergedSummary {
        collapse,
        grains,
        packing_fraction: column.packing_fraction,
        deposition_wall_time_s,
        fluid: FluidSummary {
            method: scenario.coupling.method,
            radius_factor: scenario.coupling.radius_factor,
            density: f.density,
            viscosity: f.viscosity,
            cells: d.cells,
            dx: u.dx,
            dt,
            tau: u.tau,
            precision: T::NAME,
            subcycles: c.last_subcycles,
            reduced_gravity: d.reduced_gravity,
            mach_design: d.mach,
            max_mach,
            pressure_scale: (scenario.grains.density - f.density)
                * column.packing_fraction
                * gmag
                * h_i,
            acoustic_period_tc: t_a / tau_c,
            pore_pressure_early_mean: mean_until(t_a),
            pore_pressure_early_mean_2ta: mean_until(2.0 * t_a),
            mlups: (nx * ny) as f64 * c.steps as f64 / wall_time_s.max(1e-9) / 1e6,
        },
    };
    write_json(&out_dir.join("summary.json"), &summary)?;
    Ok(summary)
}
