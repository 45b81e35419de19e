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

use super::dem::{energy_values, plan, shape, write_frame, Shape};
use super::{rest_scale, run_resumable, Column, Plan, Resumable, Row, Tally};
use crate::analysis::runout::CollapseOutcome;
use crate::coupling::{
    reduced_gravity, CellForces, Coupled, CoupledFluid, CoupledFluidState, DiskCover, Exchange,
    Exchanged, Grid, LaddMap, SolidCover,
};
use crate::dem::packing::deposit_column;
use crate::dem::scale::GrainView;
use crate::dem::{Dem, Energy, ExternalLoads, Wall};
use crate::exec::Progress;
use crate::io::{write_vti, Field, ImageGrid, PvdSeries, VtkFormat};
use crate::lbm::{Edges, Fluid, FluidModel, Lattice, Lbm, Macroscopic, Obstacles, Real, STOP_MACH};
use crate::scale::Scale;
use crate::scenario::checkpointing::Control;
use crate::scenario::fluid::Precision;
use crate::scenario::submerged::spec::{CouplingMethod, DerivedSubmerged, SubmergedScenario};
use crate::scenario::Kind;
use crate::units::CS2;
use crate::{Error, Result};

/// The grain ↔ lattice map for disks of axial length `thickness`: the lattice's forces per
/// metre of depth × thickness are the forces on the grains (N, N·m). Partially saturated
/// cells through `cover`, or Ladd's bounce-back links through `ladd` when set (`cover` then
/// only gives the solid fraction written to the frames).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
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
    control: Control,
    progress: crate::exec::Progress,
) -> Result<SubmergedSummary> {
    let d = scenario.derive()?;
    match scenario.coupling.precision {
        Precision::F32 => run_typed::<f32>(scenario, &d, out_dir, control, progress),
        Precision::F64 => run_typed::<f64>(scenario, &d, out_dir, control, progress),
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
        c.fluid.lbm().macroscopic_into(&mut self.m);
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

    fn write(
        &self,
        u: &crate::units::Units,
        hydro: f64,
        depth: f64,
        format: &VtkFormat,
        path: &Path,
    ) -> Result<()> {
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
            format,
        )
    }
}

/// The time-series columns after the geometry: the DEM's energies with the reduced gravity
/// (no budget: the fluid's work is not tracked) and the fluid's.
const COLUMNS: &[&str] = &[
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
];

/// A submerged column: the grains and the liquid, coupled.
pub struct SubmergedColumn<'a, T: Real> {
    scenario: &'a SubmergedScenario,
    derived: &'a DerivedSubmerged,
    /// The coupled fluid and grains.
    pub coupled: Coupled<CoupledFluid<T>, Dem, SlabCover>,
    fields: FluidFields,
    e0: Energy,
    /// Coupled steps per time-series row.
    series_steps: u64,
    /// (t, base excess pore pressure) of every row.
    pore: Vec<(f64, f64)>,
    max_mach: f64,
    h_i: f64,
    packing_fraction: f64,
    deposition_wall_time_s: f64,
}

impl<T: Real> Column for SubmergedColumn<'_, T> {
    type Shape = Shape;
    type Summary = SubmergedSummary;

    fn columns(&self) -> &'static [&'static str] {
        COLUMNS
    }
    fn time(&self) -> f64 {
        self.coupled.steps as f64 * self.derived.units.dt
    }
    fn measure(&mut self) -> Result<(Row, Shape)> {
        let t = self.time();
        let u = self.derived.units;
        let c = &mut self.coupled;
        self.fields.refresh(c);
        let e = c.solid.energy();
        let s = shape(&c.solid);
        let p_base = self.fields.base(&u);
        let mach = self.fields.max_mach();
        self.max_mach = self.max_mach.max(mach);
        let loads = c.solid_input();
        // `+ 0.0`: an empty sum is −0.0 (before the first step).
        let drag_x = loads.fx.iter().sum::<f64>() + 0.0;
        let drag_y = loads.fy.iter().sum::<f64>() + 0.0;
        self.pore.push((t, p_base));
        let row = Row {
            runout: s.runout,
            front: s.front,
            height: s.height,
            kinetic: e.kinetic_total(),
            values: energy_values(&e)
                .into_iter()
                .chain([
                    p_base,
                    drag_x,
                    drag_y,
                    self.fields.kinetic(&u, self.scenario.grains.thickness),
                    mach,
                ])
                .collect(),
        };
        Ok((row, s))
    }
    fn write_frame(
        &self,
        s: &Shape,
        format: &VtkFormat,
        dir: &Path,
        k: usize,
        t: f64,
        pvd: &mut PvdSeries,
    ) -> Result<()> {
        let sc = self.scenario;
        write_frame(
            &self.coupled.solid,
            &s.contacts,
            sc.grains.thickness,
            (format, dir),
            (k, t),
            pvd,
        )?;
        let name = format!("fluid_{k:06}.vti");
        let hydro = -sc.fluid.density * sc.gravity[1];
        self.fields.write(
            &self.derived.units,
            hydro,
            sc.fluid.depth,
            format,
            &dir.join(&name),
        )?;
        pvd.add(t, 2, &name)
    }
    fn advance(&mut self) -> Result<()> {
        for _ in 0..self.series_steps {
            self.coupled.step()?;
        }
        Fluid::check_stable(&*self.coupled.fluid.lbm(), STOP_MACH)
    }
    fn tally(&self, _: &Shape) -> Tally {
        let c = &self.coupled;
        Tally {
            steps: c.steps,
            dt: self.derived.units.dt,
            particles: c.solid.grains.len(),
            energy_budget_error: f64::NAN,
            // The grains' budget; what the liquid took is in the DEM's external work.
            energy: c.solid.energy().budget(&self.e0),
        }
    }
    fn summary(&self, collapse: CollapseOutcome) -> SubmergedSummary {
        let (sc, d, c) = (self.scenario, self.derived, &self.coupled);
        let (f, u) = (&sc.fluid, d.units);
        let tau_c = (self.h_i / sc.gravity[0].hypot(sc.gravity[1])).sqrt();
        let sound = u.dx / (3f64.sqrt() * u.dt);
        let t_a = 2.0 * sc.column.box_length.max(f.depth) / sound;
        let mean_until = |t1: f64| {
            let v: Vec<f64> = self
                .pore
                .iter()
                .filter(|p| p.0 > 0.0 && p.0 <= t1)
                .map(|p| p.1)
                .collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64
        };
        let [nx, ny] = d.cells;
        let mlups = (nx * ny) as f64 * c.steps as f64 / collapse.wall_time_s.max(1e-9) / 1e6;
        SubmergedSummary {
            collapse,
            grains: c.solid.grains.len(),
            packing_fraction: self.packing_fraction,
            deposition_wall_time_s: self.deposition_wall_time_s,
            fluid: FluidSummary {
                method: sc.coupling.method,
                radius_factor: sc.coupling.radius_factor,
                density: f.density,
                viscosity: f.viscosity,
                cells: d.cells,
                dx: u.dx,
                dt: u.dt,
                tau: u.tau,
                precision: T::NAME,
                subcycles: c.last_subcycles,
                reduced_gravity: d.reduced_gravity,
                mach_design: d.mach,
                max_mach: self.max_mach,
                pressure_scale: (sc.grains.density - f.density)
                    * self.packing_fraction
                    * -sc.gravity[1]
                    * self.h_i,
                acoustic_period_tc: t_a / tau_c,
                pore_pressure_early_mean: mean_until(t_a),
                pore_pressure_early_mean_2ta: mean_until(2.0 * t_a),
                mlups,
            },
        }
    }
}

/// Deposit the column of `scenario` dry, fill the tank and couple grains and liquid: the
/// system and the run's plan.
pub fn column<'a, T: Real>(
    scenario: &'a SubmergedScenario,
    d: &'a DerivedSubmerged,
) -> Result<(SubmergedColumn<'a, T>, Plan<'a>)> {
    let t0 = Instant::now();
    let deposit = deposit_column(&d.dem.column)?;
    let deposition_wall_time_s = t0.elapsed().as_secs_f64();
    let h_i = deposit.height;
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
    let walls = vec![
        Wall::floor(0.0),
        Wall::left(0.0),
        Wall::right(scenario.column.box_length),
    ];
    let mut params = d.dem.params.clone();
    params.gravity = reduced_gravity(scenario.gravity, f.density, scenario.grains.density);
    let dem = Dem::new(deposit.grains, walls, params)?;
    let mut column = assemble(scenario, d, dem, h_i)?;
    column.packing_fraction = deposit.packing_fraction;
    column.deposition_wall_time_s = deposition_wall_time_s;
    column.coupled.solid.refresh_forces();
    column.e0 = column.coupled.solid.energy();
    // The rest test's scale under the reduced gravity the grains feel.
    let solid = &column.coupled.solid;
    let g_red = solid.params().gravity[0].hypot(solid.params().gravity[1]);
    let potential = rest_scale(&solid.grains.mass, &solid.grains.y, g_red);
    let plan = submerged_plan(scenario, h_i, potential);
    Ok((column, plan))
}

/// The plan of the run of `scenario` for a column of initial height `h_i` and potential energy
/// `potential`.
fn submerged_plan(scenario: &SubmergedScenario, h_i: f64, potential: f64) -> Plan<'_> {
    let l_i = scenario.column.width;
    plan(
        &scenario.name,
        [l_i, h_i],
        scenario.gravity[0].hypot(scenario.gravity[1]),
        potential,
        &scenario.time,
        scenario.vtk,
    )
}

/// The grains `dem` (deposited, released) of a column `h_i` high in the tank of `scenario`,
/// coupled to the liquid at rest; its energy scale `e0` is left for the caller to set.
fn assemble<'a, T: Real>(
    scenario: &'a SubmergedScenario,
    d: &'a DerivedSubmerged,
    dem: Dem,
    h_i: f64,
) -> Result<SubmergedColumn<'a, T>> {
    let l_i = scenario.column.width;
    let gmag = scenario.gravity[0].hypot(scenario.gravity[1]);
    let [nx, ny] = d.cells;
    let u = d.units;
    let edges = Edges::closed();
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
    ))
    .on(scenario.coupling.backend)
    .map_err(|e| Error::config("coupling.backend", e.to_string()))?;
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
    let c = Coupled::new(fluid, dem, map);
    let ts = &scenario.time;
    let tau_c = (h_i / gmag).sqrt();
    let series_steps = ((ts.series_interval_tc * tau_c / u.dt).round() as u64).max(1);
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
    let fields = FluidFields {
        m: Macroscopic::default(),
        eps: vec![0.0; nx * ny],
        cover: SolidCover::default(),
        view: GrainView::default(),
        strip,
    };
    Ok(SubmergedColumn {
        scenario,
        derived: d,
        coupled: c,
        fields,
        e0: Energy::default(),
        series_steps,
        pore: Vec::new(),
        max_mach: 0.0,
        h_i,
        packing_fraction: 0.0,
        deposition_wall_time_s: 0.0,
    })
}

/// What a checkpoint holds of a submerged column: the grains, the liquid, the map between
/// them and what they last exchanged, and the column's own bookkeeping (the scenario and the
/// lattice's layout come from the run's scenario).
#[derive(Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "T: Serialize",
    deserialize = "T: serde::de::DeserializeOwned"
))]
pub struct SubmergedState<T> {
    fluid: CoupledFluidState<T>,
    dem: Dem,
    map: SlabCover,
    exchanged: Exchanged<SolidCover, CellForces, ExternalLoads, GrainView>,
    e0: Energy,
    series_steps: u64,
    pore: Vec<(f64, f64)>,
    max_mach: f64,
    h_i: f64,
    packing_fraction: f64,
    deposition_wall_time_s: f64,
}

impl<T: Real> Resumable for SubmergedColumn<'_, T> {
    type Saved<'s>
        = SubmergedState<T>
    where
        Self: 's;
    type Loaded = SubmergedState<T>;
    fn saved(&self) -> SubmergedState<T> {
        let c = &self.coupled;
        SubmergedState {
            fluid: c.fluid.state(),
            dem: c.solid.clone(),
            map: c.map.clone(),
            exchanged: c.exchanged(),
            e0: self.e0,
            series_steps: self.series_steps,
            pore: self.pore.clone(),
            max_mach: self.max_mach,
            h_i: self.h_i,
            packing_fraction: self.packing_fraction,
            deposition_wall_time_s: self.deposition_wall_time_s,
        }
    }
}

/// The column of `scenario` as a checkpoint saved it.
fn restore<'a, T: Real>(
    scenario: &'a SubmergedScenario,
    d: &'a DerivedSubmerged,
    s: SubmergedState<T>,
) -> Result<SubmergedColumn<'a, T>> {
    let mut column = assemble(scenario, d, s.dem, s.h_i)?;
    let c = &mut column.coupled;
    c.fluid.set_state(s.fluid)?;
    c.map = s.map;
    c.set_exchanged(s.exchanged);
    column.e0 = s.e0;
    column.series_steps = s.series_steps;
    column.pore = s.pore;
    column.max_mach = s.max_mach;
    column.packing_fraction = s.packing_fraction;
    column.deposition_wall_time_s = s.deposition_wall_time_s;
    Ok(column)
}

fn run_typed<T: Real>(
    scenario: &SubmergedScenario,
    d: &DerivedSubmerged,
    out_dir: &Path,
    control: Control,
    progress: Progress,
) -> Result<SubmergedSummary> {
    let start = || column::<T>(scenario, d);
    let restore = |s| restore::<T>(scenario, d, s);
    let plan_of = |h_i, potential| submerged_plan(scenario, h_i, potential);
    run_resumable(
        Kind::Submerged,
        start,
        restore,
        plan_of,
        out_dir,
        control,
        progress,
    )
}
