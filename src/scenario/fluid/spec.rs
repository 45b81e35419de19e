//! The fluid (LBM) scenario: types, checks and derived lattice quantities.

use serde::{Deserialize, Serialize};

pub use super::initial::{FieldValue, InitialField, InitialSpec};
use crate::io::VtkFormat;
use crate::lbm::{CollisionModel, Edge, Edges, FluidModel, LbmSetup, MrtRates, Obstacle, Shape};
use crate::scenario::{lattice_units, positive, Kind, ScenarioFile};
use crate::units::{Units, CS2};
use crate::{Error, Result};

/// A fluid scenario, as read from TOML. All values SI.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// `"fluid"`: what the file describes.
    pub kind: Kind,
    /// Short name used in outputs.
    pub name: String,
    /// One line saying what the case is.
    pub description: String,
    /// Fluid properties.
    pub fluid: FluidSpec,
    /// Rectangular domain and lattice spacing.
    pub domain: DomainSpec,
    /// Time step, duration and output intervals.
    pub time: TimeSpec,
    /// Numerical method.
    pub lbm: LbmSpec,
    /// Conditions on the four edges.
    pub boundaries: BoundarySpec,
    /// Initial state.
    pub initial: InitialSpec,
    /// Body force per unit mass (m/s²), e.g. a driving pressure gradient G/ρ or gravity.
    pub body_acceleration: [f64; 2],
    /// Reference scales for Reynolds and Mach numbers and normalised outputs.
    pub reference: ReferenceSpec,
    /// Solid obstacles (none if absent).
    #[serde(default)]
    pub obstacles: Vec<ObstacleSpec>,
    /// Pressure/velocity probes written to the time series (none if absent).
    #[serde(default)]
    pub probes: Vec<ProbeSpec>,
    /// How VTK frames are written (`[vtk]`, optional: zlib-compressed, f64, if absent).
    #[serde(default)]
    pub vtk: VtkFormat,
}

impl ScenarioFile for Scenario {
    const KIND: Kind = Kind::Fluid;
}

/// Fluid properties.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FluidSpec {
    /// Density ρ in kg/m³.
    pub density: f64,
    /// Kinematic viscosity ν in m²/s.
    pub viscosity: f64,
}

/// Domain [0, size_x] × [0, size_y] divided into square cells of side dx.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DomainSpec {
    /// Size in metres; each must be a whole number of cells.
    pub size: [f64; 2],
    /// Lattice spacing Δx in metres.
    pub dx: f64,
}

/// Time stepping. Give exactly one of `tau` or `dt`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Relaxation time τ (> ½); sets Δt = (τ − ½) Δx²/(3ν).
    pub tau: Option<f64>,
    /// Time step Δt in seconds; sets τ = ½ + 3νΔt/Δx².
    pub dt: Option<f64>,
    /// Simulated duration in seconds.
    pub end: f64,
    /// Interval between VTK frames in seconds.
    pub frame_interval: f64,
    /// Interval between time-series rows in seconds.
    pub series_interval: f64,
}

/// Collision operator.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum CollisionKind {
    /// Single relaxation time.
    Bgk,
    /// Multiple relaxation times (Lallemand & Luo 2000).
    Mrt,
}

/// Floating-point precision of the populations.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// 4-byte floats: half the memory traffic.
    F32,
    /// 8-byte floats.
    F64,
}

/// Numerical method.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LbmSpec {
    /// `"bgk"` or `"mrt"`.
    pub collision: CollisionKind,
    /// `"f32"` or `"f64"`.
    pub precision: Precision,
    /// Where the lattice steps: `"cpu"` (the default) or `"gpu"` (a build with the `gpu`
    /// feature; every edge type and obstacles; f64 needs an adapter with SHADER_F64).
    #[serde(default)]
    pub backend: crate::lbm::Backend,
    /// Smagorinsky constant C (seed eq. 5.38, ≈ 0.03 there); absent: no LES.
    pub smagorinsky: Option<f64>,
    /// MRT rates of the non-hydrodynamic moments; absent: [`MrtRates::standard`].
    pub mrt: Option<MrtSpec>,
}

/// MRT relaxation rates, each in (0, 2).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MrtSpec {
    /// Energy moment.
    pub s_e: f64,
    /// Energy-square moment.
    pub s_eps: f64,
    /// Energy-flux moments.
    pub s_q: f64,
}

impl MrtSpec {
    /// The MRT rates a scenario asks for: `spec` if given, else [`MrtRates::standard`] for τ;
    /// `None` for BGK. Rates given with BGK, or outside (0, 2), are refused naming
    /// `<table>.mrt.<rate>`.
    pub fn resolve(
        spec: Option<MrtSpec>,
        collision: CollisionKind,
        tau: f64,
        table: &str,
    ) -> Result<Option<MrtRates>> {
        let rates = match (collision, spec) {
            (CollisionKind::Bgk, Some(_)) => {
                return Err(Error::config(
                    format!("{table}.mrt"),
                    format!("MRT rates given but {table}.collision = \"bgk\""),
                ))
            }
            (CollisionKind::Bgk, None) => return Ok(None),
            (CollisionKind::Mrt, Some(m)) => MrtRates {
                s_e: m.s_e,
                s_eps: m.s_eps,
                s_q: m.s_q,
            },
            (CollisionKind::Mrt, None) => MrtRates::standard(tau),
        };
        for (name, v) in [
            ("s_e", rates.s_e),
            ("s_eps", rates.s_eps),
            ("s_q", rates.s_q),
        ] {
            if !(v > 0.0 && v < 2.0) {
                return Err(Error::config(
                    format!("{table}.mrt.{name}"),
                    format!("relaxation rate {v} must lie in (0, 2)"),
                ));
            }
        }
        Ok(Some(rates))
    }
}

/// Edge conditions.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// x = 0.
    pub left: EdgeSpec,
    /// x = L_x.
    pub right: EdgeSpec,
    /// y = 0.
    pub bottom: EdgeSpec,
    /// y = L_y.
    pub top: EdgeSpec,
}

/// Velocity profile along a Zou–He velocity edge.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// The same velocity on every node.
    Uniform,
    /// Parabola vanishing at both ends of the edge, `velocity` at its centre.
    Parabolic,
}

/// One edge condition.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum EdgeSpec {
    /// Wraps to the opposite edge.
    Periodic,
    /// No-slip wall at rest (half-way bounce-back).
    Wall,
    /// Wall sliding at `velocity` (m/s), e.g. a cavity lid.
    MovingWall {
        /// Wall velocity in m/s.
        velocity: [f64; 2],
    },
    /// Zou–He velocity condition.
    Velocity {
        /// Velocity in m/s (the centre value for a parabolic profile).
        velocity: [f64; 2],
        /// Profile along the edge.
        profile: Profile,
    },
    /// Zou–He pressure condition.
    Pressure {
        /// Gauge pressure in Pa.
        pressure: f64,
    },
}

/// Reference scales.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Characteristic (largest expected) speed U in m/s: sets the Mach check and Re = UL/ν.
    pub velocity: f64,
    /// Characteristic length L in m.
    pub length: f64,
}

/// A solid obstacle.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum ObstacleSpec {
    /// Disk.
    Circle {
        /// Name in outputs.
        name: String,
        /// Centre in m.
        center: [f64; 2],
        /// Radius in m.
        radius: f64,
        /// Interpolated bounce-back (Yu 2003) instead of half-way.
        interpolated: bool,
    },
    /// Axis-aligned rectangle.
    Rectangle {
        /// Name in outputs.
        name: String,
        /// Lower-left corner in m.
        min: [f64; 2],
        /// Upper-right corner in m.
        max: [f64; 2],
        /// Interpolated bounce-back.
        interpolated: bool,
    },
    /// Polygon.
    Polygon {
        /// Name in outputs.
        name: String,
        /// Vertices in m.
        vertices: Vec<[f64; 2]>,
        /// Interpolated bounce-back.
        interpolated: bool,
    },
}

/// A point probe.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// Name in the time-series header.
    pub name: String,
    /// Position in m.
    pub position: [f64; 2],
}

/// Everything derived from a scenario, in lattice units where not said otherwise.
#[derive(Clone, Debug, Serialize)]
pub struct Derived {
    /// SI ↔ lattice conversion.
    pub units: Units,
    /// Cells along x and y.
    pub cells: [usize; 2],
    /// Lattice viscosity ν* = (τ − ½)/3.
    pub nu_lattice: f64,
    /// Reference velocity in lattice units.
    pub u_lattice: f64,
    /// Lattice Mach number u*/c_s of the reference velocity.
    pub mach: f64,
    /// Reynolds number UL/ν.
    pub reynolds: f64,
    /// Steps to reach `time.end`.
    pub steps: u64,
    /// Steps between frames.
    pub frame_every: u64,
    /// Steps between time-series rows.
    pub series_every: u64,
    /// Body force density in lattice units (ρ* = 1).
    pub force_lattice: [f64; 2],
    /// Estimated peak memory of a run (bytes), [`fluid_memory`].
    pub memory_bytes: usize,
    /// MRT rates in use, if MRT.
    pub mrt: Option<MrtRates>,
}

/// Largest lattice Mach number `check` accepts.
pub const MAX_MACH: f64 = 0.3;

fn whole_cells(field: &str, size: f64, dx: f64) -> Result<usize> {
    let n = size / dx;
    let k = n.round();
    if (n - k).abs() > 1e-6 * k.max(1.0) || k < 3.0 {
        return Err(Error::config(
            field,
            format!("{size} m is not a whole number (≥ 3) of cells of dx = {dx} m ({n:.4} cells)"),
        ));
    }
    Ok(k as usize)
}

fn inside(field: &str, p: [f64; 2], size: [f64; 2]) -> Result<()> {
    if p[0] >= 0.0 && p[0] <= size[0] && p[1] >= 0.0 && p[1] <= size[1] {
        Ok(())
    } else {
        Err(Error::config(
            field,
            format!(
                "point ({}, {}) m lies outside the domain [0, {}] × [0, {}] m",
                p[0], p[1], size[0], size[1]
            ),
        ))
    }
}

impl Scenario {
    /// Check every value and derive the lattice quantities; the error names the field.
    pub fn derive(&self) -> Result<Derived> {
        positive("fluid.density", self.fluid.density)?;
        positive("fluid.viscosity", self.fluid.viscosity)?;
        positive("domain.dx", self.domain.dx)?;
        positive("domain.size[0]", self.domain.size[0])?;
        positive("domain.size[1]", self.domain.size[1])?;
        let nx = whole_cells("domain.size[0]", self.domain.size[0], self.domain.dx)?;
        let ny = whole_cells("domain.size[1]", self.domain.size[1], self.domain.dx)?;
        crate::scenario::check_cells("domain.dx", nx, ny)?;
        let (dx, nu, rho) = (self.domain.dx, self.fluid.viscosity, self.fluid.density);
        let units = lattice_units("time", dx, self.time.tau, self.time.dt, nu, rho)?;
        let tau = units.tau;
        positive("time.end", self.time.end)?;
        positive("time.frame_interval", self.time.frame_interval)?;
        positive("time.series_interval", self.time.series_interval)?;
        positive("reference.velocity", self.reference.velocity)?;
        positive("reference.length", self.reference.length)?;
        let cs = CS2.sqrt();
        let u_lattice = units.velocity_to_lattice(self.reference.velocity);
        let mach = u_lattice / cs;
        if mach > MAX_MACH {
            return Err(Error::config(
                "reference.velocity",
                format!(
                    "lattice Mach number {mach:.3} > {MAX_MACH} (u* = {u_lattice:.4}): reduce the time step (tau or dt) or refine dx"
                ),
            ));
        }
        // Every prescribed velocity must also respect the Mach limit.
        let check_u = |field: &str, u: [f64; 2]| -> Result<()> {
            let m = units.velocity_to_lattice(u[0].hypot(u[1])) / cs;
            if !(u[0].is_finite() && u[1].is_finite()) {
                return Err(Error::config(field, "must be finite"));
            }
            if m > MAX_MACH {
                return Err(Error::config(
                    field,
                    format!("lattice Mach number {m:.3} > {MAX_MACH}"),
                ));
            }
            Ok(())
        };
        match self.initial.uniform_velocity() {
            Some(u) => check_u("initial.velocity", u)?,
            None => {
                let speed = self.initial.field([nx, ny], dx)?.max_speed([nx, ny], dx);
                check_u("initial.velocity", [speed, 0.0])?;
            }
        }
        for (name, e) in self.edges_named() {
            match e {
                EdgeSpec::MovingWall { velocity } => {
                    check_u(&format!("boundaries.{name}.velocity"), *velocity)?;
                    // Half-way bounce-back of a wall moving through itself adds or removes mass.
                    let normal = if name == "left" || name == "right" {
                        velocity[0]
                    } else {
                        velocity[1]
                    };
                    if normal != 0.0 {
                        return Err(Error::config(
                            format!("boundaries.{name}.velocity"),
                            "a moving wall may only slide along itself: the normal component must be 0",
                        ));
                    }
                }
                EdgeSpec::Velocity { velocity, .. } => {
                    check_u(&format!("boundaries.{name}.velocity"), *velocity)?
                }
                EdgeSpec::Pressure { pressure } if !pressure.is_finite() => {
                    return Err(Error::config(
                        format!("boundaries.{name}.pressure"),
                        "must be finite",
                    ))
                }
                _ => {}
            }
        }
        let edges = self.edges(&units, nx, ny);
        edges
            .check()
            .map_err(|(f, why)| Error::config(format!("boundaries.{f}"), why))?;
        if let Some(c) = self.lbm.smagorinsky {
            if !(c.is_finite() && c >= 0.0) {
                return Err(Error::config(
                    "lbm.smagorinsky",
                    format!("must be ≥ 0, got {c}"),
                ));
            }
        }
        let mrt = MrtSpec::resolve(self.lbm.mrt, self.lbm.collision, tau, "lbm")?;
        for (k, ob) in self.obstacles.iter().enumerate() {
            let field = format!("obstacles[{k}]");
            match ob {
                ObstacleSpec::Circle { center, radius, .. } => {
                    positive(&format!("{field}.radius"), *radius)?;
                    for p in [
                        [center[0] - radius, center[1] - radius],
                        [center[0] + radius, center[1] + radius],
                    ] {
                        inside(&format!("{field}.center"), p, self.domain.size)?;
                    }
                }
                ObstacleSpec::Rectangle { min, max, .. } => {
                    inside(&format!("{field}.min"), *min, self.domain.size)?;
                    inside(&format!("{field}.max"), *max, self.domain.size)?;
                    if !(max[0] > min[0] && max[1] > min[1]) {
                        return Err(Error::config(
                            format!("{field}.max"),
                            "must exceed min in x and y",
                        ));
                    }
                }
                ObstacleSpec::Polygon { vertices, .. } => {
                    if vertices.len() < 3 {
                        return Err(Error::config(
                            format!("{field}.vertices"),
                            "a polygon needs at least 3 vertices",
                        ));
                    }
                    for (j, v) in vertices.iter().enumerate() {
                        inside(&format!("{field}.vertices[{j}]"), *v, self.domain.size)?;
                    }
                }
            }
        }
        for (k, p) in self.probes.iter().enumerate() {
            inside(
                &format!("probes[{k}].position"),
                p.position,
                self.domain.size,
            )?;
        }
        let force_lattice = [
            units.acceleration_to_lattice(self.body_acceleration[0]),
            units.acceleration_to_lattice(self.body_acceleration[1]),
        ];
        if !(force_lattice[0].is_finite() && force_lattice[1].is_finite()) {
            return Err(Error::config("body_acceleration", "must be finite"));
        }
        let steps_for = |field: &str, t: f64| -> Result<u64> {
            let s = (t / units.dt).round().max(1.0);
            if s > 1e12 {
                return Err(Error::config(field, format!("{s:.3e} steps is too many")));
            }
            Ok(s as u64)
        };
        let bytes = match self.lbm.precision {
            Precision::F32 => 4,
            Precision::F64 => 8,
        };
        self.lbm
            .backend
            .check()
            .map_err(|e| Error::config("lbm.backend", e))?;
        Ok(Derived {
            units,
            cells: [nx, ny],
            nu_lattice: (tau - 0.5) / 3.0,
            u_lattice,
            mach,
            reynolds: self.reference.velocity * self.reference.length / nu,
            steps: steps_for("time.end", self.time.end)?,
            frame_every: steps_for("time.frame_interval", self.time.frame_interval)?,
            series_every: steps_for("time.series_interval", self.time.series_interval)?,
            force_lattice,
            memory_bytes: fluid_memory(nx * ny, bytes),
            mrt,
        })
    }

    fn edges_named(&self) -> [(&'static str, &EdgeSpec); 4] {
        let b = &self.boundaries;
        [
            ("left", &b.left),
            ("right", &b.right),
            ("bottom", &b.bottom),
            ("top", &b.top),
        ]
    }

    /// The edge conditions in lattice units.
    pub fn edges(&self, units: &Units, nx: usize, ny: usize) -> Edges {
        let conv = |e: &EdgeSpec, len: usize| -> Edge {
            match e {
                EdgeSpec::Periodic => Edge::Periodic,
                EdgeSpec::Wall => Edge::Wall { velocity: [0.0; 2] },
                EdgeSpec::MovingWall { velocity } => Edge::Wall {
                    velocity: [
                        units.velocity_to_lattice(velocity[0]),
                        units.velocity_to_lattice(velocity[1]),
                    ],
                },
                EdgeSpec::Velocity { velocity, profile } => {
                    let u = [
                        units.velocity_to_lattice(velocity[0]),
                        units.velocity_to_lattice(velocity[1]),
                    ];
                    Edge::Velocity(
                        (0..len)
                            .map(|k| {
                                let s = match profile {
                                    Profile::Uniform => 1.0,
                                    // Nodes at (k + ½)/len of the edge; zero at the edge ends.
                                    Profile::Parabolic => {
                                        let t = (k as f64 + 0.5) / len as f64;
                                        4.0 * t * (1.0 - t)
                                    }
                                };
                                [u[0] * s, u[1] * s]
                            })
                            .collect(),
                    )
                }
                EdgeSpec::Pressure { pressure } => {
                    Edge::Pressure(units.pressure_to_lattice_density(*pressure))
                }
            }
        };
        let b = &self.boundaries;
        Edges {
            left: conv(&b.left, ny),
            right: conv(&b.right, ny),
            bottom: conv(&b.bottom, nx),
            top: conv(&b.top, nx),
        }
    }

    /// The obstacles in lattice coordinates.
    pub fn lattice_obstacles(&self, units: &Units) -> Vec<Obstacle> {
        let s = |p: [f64; 2]| [p[0] / units.dx, p[1] / units.dx];
        self.obstacles
            .iter()
            .map(|o| match o {
                ObstacleSpec::Circle {
                    name,
                    center,
                    radius,
                    interpolated,
                } => Obstacle {
                    name: name.clone(),
                    shape: Shape::Circle {
                        center: s(*center),
                        radius: radius / units.dx,
                    },
                    interpolated: *interpolated,
                },
                ObstacleSpec::Rectangle {
                    name,
                    min,
                    max,
                    interpolated,
                } => Obstacle {
                    name: name.clone(),
                    shape: Shape::Rectangle {
                        min: s(*min),
                        max: s(*max),
                    },
                    interpolated: *interpolated,
                },
                ObstacleSpec::Polygon {
                    name,
                    vertices,
                    interpolated,
                } => Obstacle {
                    name: name.clone(),
                    shape: Shape::Polygon {
                        vertices: vertices.iter().map(|v| s(*v)).collect(),
                    },
                    interpolated: *interpolated,
                },
            })
            .collect()
    }

    /// The collision model.
    pub fn collision_model(&self, d: &Derived) -> CollisionModel {
        match d.mrt {
            None => CollisionModel::Bgk,
            Some(r) => CollisionModel::Mrt(r),
        }
    }
}

impl Scenario {
    /// Build the solver in precision `T` (whatever `lbm.precision` says), initialised to the
    /// equilibrium at ρ₀ and a uniform `initial.velocity`, or to the `[initial]` field
    /// ([`InitialField::populations`]).
    pub fn build_typed<T: crate::lbm::Real>(&self, d: &Derived) -> Result<crate::lbm::Lbm<T>> {
        let mut lbm = self
            .lbm_setup(d)
            .build()
            .map_err(|e| Error::config("boundaries", e))?;
        if self.initial.uniform_velocity().is_none() {
            let field = self.initial.field(d.cells, d.units.dx)?;
            lbm.lattice
                .fill_populations(|i, j| field.populations(&d.units, i, j));
        }
        Ok(lbm)
    }

    /// The fluid this scenario describes, in lattice terms.
    pub fn lbm_setup(&self, d: &Derived) -> LbmSetup {
        let [nx, ny] = d.cells;
        LbmSetup {
            cells: d.cells,
            units: d.units,
            model: FluidModel {
                collision: self.collision_model(d),
                smagorinsky: self.lbm.smagorinsky,
                body_force: d.force_lattice,
            },
            edges: self.edges(&d.units, nx, ny),
            obstacles: self.lattice_obstacles(&d.units),
            initial_velocity: self
                .initial
                .uniform_velocity()
                .unwrap_or_default()
                .map(|u| d.units.velocity_to_lattice(u)),
        }
    }

    /// The solver in f64 whatever `lbm.precision` says (as the validation cases run), on the
    /// file's back end.
    pub fn build_f64(&self, d: &Derived) -> Result<Box<dyn crate::lbm::Fluid>> {
        self.on_backend(self.build_typed::<f64>(d)?)
    }

    /// `lbm`, built from this file, moved onto the file's back end.
    pub fn on_backend<T: crate::lbm::Real>(
        &self,
        lbm: crate::lbm::Lbm<T>,
    ) -> Result<Box<dyn crate::lbm::Fluid>> {
        self.lbm
            .backend
            .fluid(lbm)
            .map_err(|e| Error::config("lbm.backend", e))
    }

    /// Check, derive and build the solver in the scenario's precision.
    pub fn build(&self) -> Result<(Box<dyn crate::lbm::Fluid>, Derived)> {
        let d = self.derive()?;
        let fluid = match self.lbm.precision {
            Precision::F32 => self.on_backend(self.build_typed::<f32>(&d)?)?,
            Precision::F64 => self.on_backend(self.build_typed::<f64>(&d)?)?,
        };
        Ok((fluid, d))
    }

    /// Cell index containing SI point `p`.
    pub fn cell_at(&self, d: &Derived, p: [f64; 2]) -> usize {
        let x = ((p[0] / d.units.dx) as usize).min(d.cells[0] - 1);
        let y = ((p[1] / d.units.dx) as usize).min(d.cells[1] - 1);
        y * d.cells[0] + x
    }
}

/// Estimated peak memory (bytes) of a fluid run of `cells` cells with populations of
/// `bytes` bytes: 70 MiB + (295 + 9 `bytes`) per cell. The populations (9 per cell, one copy)
/// are a fifth of it; the peak is reached while a frame is written (its fields, the XML model
/// and the base64 text in memory at once). Measured as the peak resident size
/// (`/usr/bin/time`) of 20-step cavity runs writing three frames: 158, 462 and 1504 MiB at
/// 512², 1024² and 2048² cells with f64 populations, 149 and 427 MiB at 512² and 1024² with
/// f32; the estimate gives 162, 437 and 1538 MiB, and 153 and 401 MiB (within 6 %).
pub fn fluid_memory(cells: usize, bytes: usize) -> usize {
    (70 << 20) + cells * (295 + 9 * bytes)
}
