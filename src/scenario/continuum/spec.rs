//! The continuum scenario file (`kind = "continuum"`): an MPM problem of any geometry, as
//! data — a rectangular domain (optionally periodic in x) with a wall condition on each side
//! that has one, regions filled with material points, gravity in any direction (optionally
//! turning at a constant rate: a tilting table), and the points' initial stress and velocity.
//!
//! The grid covers the domain with cells of `mpm.cell_size` (the domain's sides whole numbers
//! of cells) and two cells of images or ghosts beyond each side. A region is filled with
//! n × n points per cell (`mpm.points_per_cell`) on the lattice of the domain's cells: a
//! lattice site belongs to the material when it lies inside any `[[fill]]` region, so
//! overlapping regions give one material and a region's edges follow the lattice.
//!
//! Every physical value must be given: there are no defaults (`deny_unknown_fields` refuses
//! misspelt keys). [`ContinuumScenario::derive`] refuses bad values naming the TOML path.

use serde::{Deserialize, Serialize};

use crate::io::VtkFormat;
use crate::lbm::obstacle::Shape;
use crate::mpm::boundary::{Side, Wall, WallKind};
use crate::mpm::grid::Grid;
use crate::mpm::material::{Material, MaterialModel};
use crate::mpm::points::Points;
use crate::mpm::solver::{cfl_step, Mpm};
use crate::scenario::granular::spec::region_vertices;
use crate::scenario::mpm::initial::{start, MpmInitialSpec};
use crate::scenario::mpm::spec::{check_wall, point_memory, Law, MaterialSpec, MpmSpec};
use crate::scenario::{positive, Kind, ScenarioFile};
use crate::{Error, Result};

/// Most material points or grid cells a continuum scenario may hold.
const MAX_POINTS: f64 = 1e7;

/// An MPM scenario of any geometry, as read from TOML. All values SI (angles in degrees).
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContinuumScenario {
    /// `"continuum"`: what the file describes.
    pub kind: Kind,
    /// Short name used in outputs.
    pub name: String,
    /// One line saying what the case is.
    pub description: String,
    /// Gravitational acceleration **g** = [g_x, g_y] (m/s²) at t = 0, any direction; [0, 0]
    /// for none. With periodic x and g_x ≠ 0 the points' potential energy −m **g**·**x** uses
    /// their positions wrapped into the period (it jumps when a point crosses an end).
    pub gravity: [f64; 2],
    /// Gravity turning at a constant rate (`[tilt]`, optional): a tilting table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tilt: Option<TiltSpec>,
    /// The domain and its sides.
    pub domain: DomainSpec,
    /// Regions filled with material points (`[[fill]]`, at least one).
    pub fill: Vec<RegionSpec>,
    /// The constitutive law (`elastic`, `mohr_coulomb` or `mu_i`).
    pub material: MaterialSpec,
    /// The points' initial velocity and stress (`[initial]`, optional: at rest, unstressed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<MpmInitialSpec>,
    /// Discretisation.
    pub mpm: MpmSpec,
    /// Time step, end and output intervals.
    pub time: ContinuumTimeSpec,
    /// How VTK frames are written (`[vtk]`, optional: zlib-compressed, f64, if absent).
    #[serde(default)]
    pub vtk: VtkFormat,
}

/// A tilting table: the gravity vector keeps its magnitude and turns towards +x at a constant
/// rate, θ(t) = min(θ₀ + ω t, θ_end), **g** = |**g**| (sin θ, −cos θ), where θ₀ is the angle of
/// `gravity` from −y (positive towards +x). The run reports the onset of sliding: the first
/// time-series row where the points' mean velocity along x exceeds `onset_speed`.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TiltSpec {
    /// ω (degrees per second, > 0).
    pub rate_deg_per_s: f64,
    /// θ_end (degrees from −y, above θ₀ and below 90): the table stops turning there.
    pub until_deg: f64,
    /// Mean velocity along x (m/s, > 0) that marks the onset of sliding.
    pub onset_speed: f64,
}

/// The domain: [x0, x1] × [y0, y1], each side a whole number of cells.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DomainSpec {
    /// [x0, x1] (m).
    pub x: [f64; 2],
    /// [y0, y1] (m).
    pub y: [f64; 2],
    /// Periodic in x: a point leaving through x1 comes back through x0 and the material is
    /// continuous across the ends (an infinite slope, a shear layer). No `left` or `right`
    /// wall then.
    pub periodic_x: bool,
    /// Wall condition at x = x0 (`{ kind = "fixed" | "roller" }` or
    /// `{ kind = "friction", mu = … }`); absent: open (points may not leave the domain).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left: Option<WallKind>,
    /// Wall condition at x = x1; absent: open.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub right: Option<WallKind>,
    /// Wall condition at y = y0; absent: open.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bottom: Option<WallKind>,
    /// Wall condition at y = y1; absent: open.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top: Option<WallKind>,
}

/// A region of material: exactly one of `rectangle` and `polygon`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RegionSpec {
    /// Lower-left and upper-right corners (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rectangle: Option<[[f64; 2]; 2]>,
    /// A simple polygon: its vertices (m), in either order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 2]>>,
}

/// Time stepping and outputs (s).
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContinuumTimeSpec {
    /// Time step (s); omitted: C h/c. A larger one than C h/c is refused.
    pub dt: Option<f64>,
    /// End of the run (s).
    pub end: f64,
    /// Interval between VTK frames (s).
    pub frame_interval: f64,
    /// Interval between time-series rows (s).
    pub series_interval: f64,
}

/// What [`ContinuumScenario::derive`] computes.
#[derive(Clone, Debug)]
pub struct DerivedContinuum {
    /// The material.
    pub material: MaterialModel,
    /// Cells of the domain (x, y).
    pub cells: [usize; 2],
    /// The material points at t = 0.
    pub points: Points,
    /// The step (s): `time.dt` or C h/c.
    pub dt: f64,
    /// θ₀, the angle of `gravity` from −y (degrees, positive towards +x).
    pub angle_deg: f64,
    /// |**g**| (m/s²).
    pub g_abs: f64,
}

impl ScenarioFile for ContinuumScenario {
    const KIND: Kind = Kind::Continuum;
}

/// The angle of `g` from −y (degrees, positive towards +x).
pub fn angle_deg(g: [f64; 2]) -> f64 {
    g[0].atan2(-g[1]).to_degrees()
}

/// The number of cells of size `h` in `[a, b]`, if whole (to 1e-6 of a cell).
fn cells_in(a: f64, b: f64, h: f64) -> Option<usize> {
    let n = (b - a) / h;
    (n >= 1.0 && (n - n.round()).abs() < 1e-6).then(|| n.round() as usize)
}

impl ContinuumScenario {
    /// Check every value and derive the set-up (the points included).
    pub fn derive(&self) -> Result<DerivedContinuum> {
        let g = self.gravity;
        if !(g[0].is_finite() && g[1].is_finite()) {
            return Err(Error::config("gravity", "must be finite"));
        }
        let g_abs = g[0].hypot(g[1]);
        let angle_deg = angle_deg(g);
        if let Some(t) = &self.tilt {
            positive("tilt.rate_deg_per_s", t.rate_deg_per_s)?;
            positive("tilt.onset_speed", t.onset_speed)?;
            if g_abs == 0.0 {
                return Err(Error::config(
                    "tilt",
                    "needs a gravity to turn (gravity is zero)",
                ));
            }
            if !(t.until_deg > angle_deg && t.until_deg < 90.0) {
                return Err(Error::config(
                    "tilt.until_deg",
                    format!(
                        "must lie between the angle of gravity from −y, {angle_deg:.3}°, and 90°, \
                         got {}",
                        t.until_deg
                    ),
                ));
            }
        }
        let material = match self.material.build()? {
            Law::Continuum(m) => m,
            Law::Volume(_) => {
                return Err(Error::config(
                    "material.model",
                    "the rve model is for column-collapse (`kind = \"mpm\"`) files",
                ))
            }
        };
        if let Some(initial) = &self.initial {
            initial.compile()?;
        }
        self.mpm.check()?;
        let h = self.mpm.cell_size;
        let dm = &self.domain;
        let mut cells = [0; 2];
        for (k, (key, [a, b])) in [("domain.x", dm.x), ("domain.y", dm.y)]
            .into_iter()
            .enumerate()
        {
            if !(a.is_finite() && b.is_finite() && b > a) {
                return Err(Error::config(
                    key,
                    format!("must be [low, high], got [{a}, {b}]"),
                ));
            }
            cells[k] = cells_in(a, b, h).ok_or_else(|| {
                Error::config(
                    key,
                    format!(
                        "{} m is not a whole number of cells of mpm.cell_size = {h} m",
                        b - a
                    ),
                )
            })?;
        }
        if (cells[0] + 4) as f64 * (cells[1] + 4) as f64 > MAX_POINTS {
            return Err(Error::config(
                "mpm.cell_size",
                format!("{h} m gives more than {MAX_POINTS:e} grid cells: choose larger cells"),
            ));
        }
        for (key, w) in self.sides() {
            if let Some(w) = w {
                check_wall(key, &w)?;
                if dm.periodic_x && matches!(key, "domain.left" | "domain.right") {
                    return Err(Error::config(
                        key,
                        "a domain periodic in x has no left or right wall",
                    ));
                }
            }
        }
        if self.fill.is_empty() {
            return Err(Error::config(
                "fill",
                "give at least one region of material",
            ));
        }
        let regions: Vec<Shape> = self
            .fill
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let field = format!("fill[{k}]");
                let vertices = region_vertices(&field, r.rectangle, r.polygon.as_deref())?;
                let inside = vertices.iter().all(|v| {
                    (dm.x[0]..=dm.x[1]).contains(&v[0]) && (dm.y[0]..=dm.y[1]).contains(&v[1])
                });
                if !inside {
                    return Err(Error::config(field, "must lie inside the domain"));
                }
                Ok(Shape::Polygon { vertices })
            })
            .collect::<Result<_>>()?;
        let n = self.mpm.points_per_cell;
        if cells[0] as f64 * cells[1] as f64 * (n * n) as f64 > MAX_POINTS {
            return Err(Error::config(
                "mpm.points_per_cell",
                format!("the domain holds more than {MAX_POINTS:e} point sites: fewer points"),
            ));
        }
        let mut points = Points::default();
        points.fill_where(
            [dm.x[0], dm.y[0]],
            [dm.x[1], dm.y[1]],
            h,
            n,
            material.density(),
            |p| regions.iter().any(|r| r.contains(p)),
        );
        if points.is_empty() {
            return Err(Error::config(
                "fill",
                format!("the regions hold no point of the lattice of {n} × {n} points per cell"),
            ));
        }
        let limit = cfl_step(&material, h, self.mpm.courant);
        let dt = match self.time.dt {
            Some(dt) => {
                positive("time.dt", dt)?;
                if dt > limit {
                    return Err(Error::config(
                        "time.dt",
                        format!("Δt = {dt:e} s exceeds the CFL limit C h/c = {limit:e} s"),
                    ));
                }
                dt
            }
            None => limit,
        };
        let t = &self.time;
        positive("time.end", t.end)?;
        positive("time.frame_interval", t.frame_interval)?;
        positive("time.series_interval", t.series_interval)?;
        Ok(DerivedContinuum {
            material,
            cells,
            points,
            dt,
            angle_deg,
            g_abs,
        })
    }

    /// The four sides' conditions, with their keys.
    fn sides(&self) -> [(&'static str, Option<WallKind>); 4] {
        let d = &self.domain;
        [
            ("domain.left", d.left),
            ("domain.right", d.right),
            ("domain.bottom", d.bottom),
            ("domain.top", d.top),
        ]
    }

    /// The gravity vector at time `t` (s): `gravity`, turned by the `[tilt]` if any.
    pub fn gravity_at(&self, d: &DerivedContinuum, t: f64) -> [f64; 2] {
        match &self.tilt {
            None => self.gravity,
            Some(tilt) => {
                let theta = (d.angle_deg + tilt.rate_deg_per_s * t)
                    .min(tilt.until_deg)
                    .to_radians();
                [d.g_abs * theta.sin(), -d.g_abs * theta.cos()]
            }
        }
    }

    /// The solver at t = 0.
    pub fn build(&self, d: &DerivedContinuum) -> Result<Mpm> {
        let h = self.mpm.cell_size;
        let dm = &self.domain;
        let [nx, ny] = d.cells;
        let ends = [
            dm.x[0],
            dm.x[0] + nx as f64 * h,
            dm.y[0],
            dm.y[0] + ny as f64 * h,
        ];
        let walls: Vec<Wall> = [Side::Left, Side::Right, Side::Bottom, Side::Top]
            .into_iter()
            .zip(ends)
            .zip(self.sides())
            .filter_map(|((side, position), (_, kind))| {
                kind.map(|kind| Wall {
                    side,
                    position,
                    kind,
                })
            })
            .collect();
        let origin = [dm.x[0] - 2.0 * h, dm.y[0] - 2.0 * h];
        let mut grid = Grid::new(nx + 4, ny + 4, h, origin, walls);
        if dm.periodic_x {
            grid = grid.with_period_x(2, nx)?;
        }
        let params = self.mpm.params(self.gravity, Some(d.dt));
        let mut mpm = Mpm::new(grid, d.points.clone(), d.material, params)?;
        mpm.set_transfer(self.mpm.transfer)?;
        start(&mut mpm, self.initial.as_ref(), |_| [0.0; 4])?;
        Ok(mpm)
    }

    /// Estimated peak memory of a run (bytes).
    pub fn memory_bytes(d: &DerivedContinuum) -> usize {
        point_memory(d.points.len())
    }
}
