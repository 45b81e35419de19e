//! The granular scenario file (`kind = "granular"`): a DEM problem of any geometry, described
//! as data — regions filled with grains, grains listed one by one, walls (segments, convex
//! polygons, half-planes; fixed or moving), gates that hold the grains while they settle and
//! are removed at the release, and outlets that remove the grains reaching them.
//!
//! A run has two phases. *Settling* (when `[settle]` is given): every wall and gate in place,
//! no wall moving, the grains fall under gravity until the kinetic energy per grain is below
//! `rest_fraction` × m̄ |**g**| d̄; then their velocities are zeroed. *Release* (t = 0): the gates
//! go, the walls with a `velocity` start moving, and the run lasts `time.end` seconds or until
//! no grain is left. Outlets act in both phases.
//!
//! Grains are disks of diameter d (from `[grains]`: drawn between d_min and d_max for the
//! regions, given for listed grains) and axial length `grains.thickness`, so
//! m = ρ π d²/4 · thickness, J = ½ m R², as in the column collapse.

use serde::{Deserialize, Serialize};

use crate::dem::packing::{SizeDistribution, SplitMix64};
use crate::dem::params::min_image;
use crate::dem::{DemParams, Grains, TimeStep, Wall};
use crate::io::VtkFormat;
use crate::lbm::obstacle::Shape;
use crate::scenario::dem::spec::{ContactSpec, GrainsSpec};
use crate::scenario::{positive, Kind, ScenarioFile};
use crate::{Error, Result};

/// Most lattice sites a `[[fill]]` region may span (a guard against a spacing or region off by
/// orders of magnitude; at ≈ 2 KiB per grain, 10⁷ grains take ≈ 20 GiB).
const MAX_SITES: f64 = 1e7;

/// A granular scenario of any geometry, as read from TOML. All values SI.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GranularScenario {
    /// `"granular"`: what the file describes.
    pub kind: Kind,
    /// Short name used in outputs.
    pub name: String,
    /// One line saying what the case is.
    pub description: String,
    /// Gravitational acceleration **g** = [g_x, g_y] (m/s²), any direction; [0, 0] for none.
    pub gravity: [f64; 2],
    /// Seed of the size draw and the lattice jitter of the filled regions.
    pub seed: u64,
    /// Periodic in x over [x0, x1) (m), optional: a grain leaving through one end comes back
    /// through the other and grains touch across the ends (a chute, a shear flow). Disks
    /// only; the filled regions and listed grains must lie inside the period, and rows of
    /// `bumps` are repeated across its ends (other walls are not). At least 3 (d_max + skin)
    /// long.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periodic_x: Option<[f64; 2]>,
    /// Grain sizes and material.
    pub grains: GrainsSpec,
    /// Grain–grain contact law.
    pub grain_contact: ContactSpec,
    /// Grain–wall contact law.
    pub wall_contact: ContactSpec,
    /// Regions filled with grains (`[[fill]]`).
    #[serde(default)]
    pub fill: Vec<FillSpec>,
    /// Grains listed one by one (`[[grain]]`).
    #[serde(default)]
    pub grain: Vec<GrainSpec>,
    /// Walls (`[[wall]]`).
    pub wall: Vec<WallSpec>,
    /// Outlets (`[[outlet]]`): a grain whose centre enters one is removed and counted as
    /// discharged.
    #[serde(default)]
    pub outlet: Vec<OutletSpec>,
    /// A time-averaged profile across y (`[profile]`, optional): written to `profile.csv`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<ProfileSpec>,
    /// Settling before the release (`[settle]`, optional: without it the grains start as
    /// given, at t = 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle: Option<SettleSpec>,
    /// Time step, end and output intervals.
    pub time: TimeSpec,
    /// How VTK frames are written (`[vtk]`, optional: zlib-compressed, f64, if absent).
    #[serde(default)]
    pub vtk: VtkFormat,
}

/// A region filled with grains on a square lattice: sites `spacing` apart whose disk of
/// diameter `spacing` lies inside the region, each holding one grain of a diameter drawn from
/// `[grains]`, placed at random inside its site (no two grains overlap).
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FillSpec {
    /// The region as a rectangle: lower-left and upper-right corners (m). Give this or
    /// `polygon`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rectangle: Option<[[f64; 2]; 2]>,
    /// The region as a simple polygon: its vertices (m), in either order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// Lattice spacing (m), at least `grains.d_max`: 1.0–1.2 d_max gives a loose fill that
    /// settles into a packing.
    pub spacing: f64,
}

/// One grain (a disk of the `[grains]` material).
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GrainSpec {
    /// Centre (m).
    pub position: [f64; 2],
    /// Diameter (m).
    pub diameter: f64,
    /// Velocity (m/s).
    pub velocity: [f64; 2],
    /// Angular velocity (rad/s, counter-clockwise).
    pub angular_velocity: f64,
}

/// A wall: exactly one of `segment`, `polygon`, `plane`, `bumps`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    /// A rough wall: a row of fixed disks (see [`BumpsSpec`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bumps: Option<BumpsSpec>,
    /// A line segment between two points (m), both sides solid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segment: Option<[[f64; 2]; 2]>,
    /// A solid convex polygon: 3–8 vertices (m), either order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// A half-plane: the grains are on the side its normal points to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<PlaneSpec>,
    /// Velocity (m/s) from the release on (segments and planes only); absent: fixed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<[f64; 2]>,
    /// A gate: in place while the grains settle, removed at the release.
    #[serde(default)]
    pub gate: bool,
}

/// A rough wall: `count` fixed disks of diameter `diameter` with centres evenly spaced along
/// the segment from `from` to `to`, at `from + (k + ½)(to − from)/count`, k = 0 … count − 1
/// (so rows laid end to end, or across a whole period, keep the spacing). A grain meets them
/// with the wall contact law.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BumpsSpec {
    /// Start of the row (m).
    pub from: [f64; 2],
    /// End of the row (m).
    pub to: [f64; 2],
    /// Diameter of each disk (m).
    pub diameter: f64,
    /// Number of disks (1–100 000).
    pub count: u32,
}

/// A profile across y, averaged over time from `start` to the end of the run: the grains whose
/// centre lies in `rectangle` are binned by the height of their centre into `bins` equal
/// slices; per slice the solid fraction φ = Σ (area of the disk within the slice) / (slice
/// area) and the area-weighted mean velocity (u, v) = Σ A_ib **v**_i / Σ A_ib, sampled at
/// every time-series row.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProfileSpec {
    /// Lower-left and upper-right corners (m).
    pub rectangle: [[f64; 2]; 2],
    /// Number of slices (1–10 000).
    pub bins: u32,
    /// Start of the average (s after the release).
    pub start: f64,
}

/// A half-plane wall.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// A point on its line (m).
    pub point: [f64; 2],
    /// Normal pointing to the grains' side (any length but zero).
    pub normal: [f64; 2],
}

/// An outlet: the grains whose centre is inside the rectangle are removed.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OutletSpec {
    /// Lower-left and upper-right corners (m).
    pub rectangle: [[f64; 2]; 2],
}

/// Settling before the release.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SettleSpec {
    /// At rest: kinetic energy per grain below this fraction of m̄ |**g**| d̄.
    pub rest_fraction: f64,
    /// Give up (an error) after this simulated time (s).
    pub max_time: f64,
}

/// Time stepping and outputs (s of simulated time after the release).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Safety factor λ of seed eq. 5.60 (Δt = λ Δt_cr); at most 0.1 is advised.
    pub lambda: f64,
    /// End of the run (s after the release).
    pub end: f64,
    /// Interval between VTK frames (s).
    pub frame_interval: f64,
    /// Interval between time-series rows (s).
    pub series_interval: f64,
    /// End the run earlier, once the outlets have removed this fraction of the mass present
    /// at the release (optional; in (0, 1]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_discharged_fraction: Option<f64>,
}

/// What [`GranularScenario::derive`] builds.
#[derive(Clone, Debug)]
pub struct DerivedGranular {
    /// Solver parameters.
    pub params: DemParams,
    /// The grains, at their starting places.
    pub grains: Grains,
    /// The walls that stay after the release, each with its velocity.
    pub walls: Vec<(Wall, Option<[f64; 2]>)>,
    /// The gates (removed at the release).
    pub gates: Vec<Wall>,
    /// The outlets: lower-left and upper-right corners.
    pub outlets: Vec<[[f64; 2]; 2]>,
    /// The DEM step.
    pub time_step: TimeStep,
}

impl ScenarioFile for GranularScenario {
    const KIND: Kind = Kind::Granular;
}

fn finite(field: &str, v: &[f64]) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Error::config(field, "must be finite"))
    }
}

/// A rectangle given as two corners: lower-left strictly below and left of upper-right.
fn rectangle(field: &str, r: [[f64; 2]; 2]) -> Result<[[f64; 2]; 2]> {
    finite(field, r.as_flattened())?;
    if !(r[1][0] > r[0][0] && r[1][1] > r[0][1]) {
        return Err(Error::config(
            field,
            format!("the first corner must be the lower-left one, below and left of the second, got {r:?}"),
        ));
    }
    Ok(r)
}

impl GranularScenario {
    /// Check every value and build the grains and walls. Refuses, naming the field:
    /// non-positive sizes, densities or intervals; a wall or region given with none or two
    /// shapes; a degenerate rectangle, segment or polygon; a moving polygon or gate; a lattice
    /// spacing below d_max or a region that holds no site; a listed grain's diameter outside
    /// [d_min, d_max] or a listed grain overlapping another; no grains at all; λ outside (0, 1].
    pub fn derive(&self) -> Result<DerivedGranular> {
        finite("gravity", &self.gravity)?;
        let g = &self.grains;
        g.check()?;
        let rho = g.density * g.thickness;
        let mut grains = Grains::new();
        let mut rng = SplitMix64::new(self.seed);
        let dist: SizeDistribution = g.distribution.into();
        for (k, f) in self.fill.iter().enumerate() {
            self.fill_region(&format!("fill[{k}]"), f, dist, &mut rng, &mut grains)?;
        }
        let first_listed = grains.len();
        for (k, s) in self.grain.iter().enumerate() {
            let field = format!("grain[{k}]");
            finite(&field, &[s.position[0], s.position[1]])?;
            finite(&field, &[s.velocity[0], s.velocity[1], s.angular_velocity])?;
            if !(s.diameter >= g.d_min && s.diameter <= g.d_max) {
                return Err(Error::config(
                    format!("{field}.diameter"),
                    format!(
                        "must be within [grains.d_min, grains.d_max] = [{}, {}] m (the step is \
                         set for that range), got {}",
                        g.d_min, g.d_max, s.diameter
                    ),
                ));
            }
            let i = grains.push_disk(s.position[0], s.position[1], 0.5 * s.diameter, rho);
            grains.vx[i] = s.velocity[0];
            grains.vy[i] = s.velocity[1];
            grains.omega[i] = s.angular_velocity;
        }
        if grains.is_empty() {
            return Err(Error::config(
                "fill",
                "the scenario has no grains: give a [[fill]] region or [[grain]] entries",
            ));
        }
        let (walls, gates) = self.walls()?;
        let outlets = self
            .outlet
            .iter()
            .enumerate()
            .map(|(k, o)| rectangle(&format!("outlet[{k}].rectangle"), o.rectangle))
            .collect::<Result<Vec<_>>>()?;
        let grain = self.grain_contact.params();
        let wall = self.wall_contact.params();
        grain.check("grain_contact")?;
        wall.check("wall_contact")?;
        if let Some(s) = &self.settle {
            positive("settle.rest_fraction", s.rest_fraction)?;
            positive("settle.max_time", s.max_time)?;
            if self.gravity == [0.0, 0.0] {
                return Err(Error::config(
                    "settle",
                    "grains cannot settle without gravity; remove [settle] or give a gravity",
                ));
            }
        }
        let t = &self.time;
        positive("time.end", t.end)?;
        positive("time.frame_interval", t.frame_interval)?;
        positive("time.series_interval", t.series_interval)?;
        if let Some(f) = t.stop_discharged_fraction {
            if !(f > 0.0 && f <= 1.0) {
                return Err(Error::config(
                    "time.stop_discharged_fraction",
                    format!("must be in (0, 1], got {f}"),
                ));
            }
            if outlets.is_empty() {
                return Err(Error::config(
                    "time.stop_discharged_fraction",
                    "the scenario has no [[outlet]] to discharge through",
                ));
            }
        }
        if let Some(p) = &self.profile {
            rectangle("profile.rectangle", p.rectangle)?;
            if !(1..=10_000).contains(&p.bins) {
                return Err(Error::config(
                    "profile.bins",
                    format!("must be in 1–10 000, got {}", p.bins),
                ));
            }
            if !(p.start >= 0.0 && p.start < t.end) {
                return Err(Error::config(
                    "profile.start",
                    format!("must be in [0, time.end = {}) s, got {}", t.end, p.start),
                ));
            }
        }
        let mut params = DemParams::new(grain, wall, self.gravity);
        params.lambda = t.lambda;
        params.periodic_x = self.periodic_x;
        params.check_period(&grains, "periodic_x")?;
        if let Some([a, b]) = self.periodic_x {
            let slack = 1e-12 * (b - a);
            let outside = |k: usize| {
                grains.x[k] - grains.radius[k] < a - slack
                    || grains.x[k] + grains.radius[k] > b + slack
            };
            if let Some(k) = (0..grains.len()).find(|&k| outside(k)) {
                return Err(Error::config(
                    "periodic_x",
                    format!(
                        "grain {k} at x = {:.6e} m is not inside the period [{a}, {b}] (the \
                         [[fill]] regions and [[grain]] entries must lie within it)",
                        grains.x[k]
                    ),
                ));
            }
        }
        check_listed_apart(&grains, first_listed, params.period())?;
        let time_step = TimeStep::of_grains(&params, &grains).map_err(|e| e.within("time"))?;
        Ok(DerivedGranular {
            params,
            grains,
            walls,
            gates,
            outlets,
            time_step,
        })
    }

    /// Fill region `f` (named `field`) with grains on its lattice.
    fn fill_region(
        &self,
        field: &str,
        f: &FillSpec,
        dist: SizeDistribution,
        rng: &mut SplitMix64,
        grains: &mut Grains,
    ) -> Result<()> {
        let [d_min, d_max] = [self.grains.d_min, self.grains.d_max];
        let rho = self.grains.density * self.grains.thickness;
        positive(&format!("{field}.spacing"), f.spacing)?;
        if f.spacing < d_max {
            return Err(Error::config(
                format!("{field}.spacing"),
                format!("must be ≥ grains.d_max = {d_max} m, got {}", f.spacing),
            ));
        }
        let vertices = region_vertices(field, f.rectangle, f.polygon.as_deref())?;
        let (lo, hi) = bounds(&vertices);
        let region = Shape::Polygon {
            vertices: vertices.clone(),
        };
        let s = f.spacing;
        let sites = ((hi[0] - lo[0]) / s) * ((hi[1] - lo[1]) / s);
        if sites > MAX_SITES {
            return Err(Error::config(
                format!("{field}.spacing"),
                format!(
                    "the region spans about {sites:.3e} lattice sites of spacing {s} m, more than \
                     the {MAX_SITES:.0e} grains a scenario may hold"
                ),
            ));
        }
        let before = grains.len();
        let mut y = lo[1] + 0.5 * s;
        while y <= hi[1] - 0.5 * s {
            let mut x = lo[0] + 0.5 * s;
            while x <= hi[0] - 0.5 * s {
                if region.contains([x, y]) && edge_distance(&vertices, [x, y]) >= 0.5 * s {
                    let d = dist.sample(rng, d_min, d_max);
                    let room = 0.5 * (s - d);
                    let jx = room * (2.0 * rng.uniform() - 1.0);
                    let jy = room * (2.0 * rng.uniform() - 1.0);
                    grains.push_disk(x + jx, y + jy, 0.5 * d, rho);
                }
                x += s;
            }
            y += s;
        }
        if grains.len() == before {
            return Err(Error::config(
                field,
                format!("the region holds no lattice site of spacing {s} m"),
            ));
        }
        Ok(())
    }

    /// The walls that stay (with their velocities) and the gates.
    #[allow(clippy::type_complexity)]
    fn walls(&self) -> Result<(Vec<(Wall, Option<[f64; 2]>)>, Vec<Wall>)> {
        let (mut walls, mut gates) = (Vec::new(), Vec::new());
        for (k, w) in self.wall.iter().enumerate() {
            let field = format!("wall[{k}]");
            let row = match (&w.segment, &w.polygon, &w.plane, &w.bumps) {
                (&Some([a, b]), None, None, None) => {
                    finite(&format!("{field}.segment"), &[a[0], a[1], b[0], b[1]])?;
                    if a == b {
                        return Err(Error::config(
                            format!("{field}.segment"),
                            "its two ends are the same point",
                        ));
                    }
                    vec![Wall::Segment { a, b }]
                }
                (None, Some(p), None, None) => {
                    finite(&format!("{field}.polygon"), p.as_flattened())?;
                    vec![Wall::polygon(p, &format!("{field}.polygon"))?]
                }
                (None, None, Some(pl), None) => {
                    let f = format!("{field}.plane");
                    finite(&f, &[pl.point[0], pl.point[1], pl.normal[0], pl.normal[1]])?;
                    let len = pl.normal[0].hypot(pl.normal[1]);
                    if len == 0.0 {
                        return Err(Error::config(f + ".normal", "must not be zero"));
                    }
                    vec![Wall::Plane {
                        point: pl.point,
                        normal: [pl.normal[0] / len, pl.normal[1] / len],
                    }]
                }
                (None, None, None, Some(b)) => self.bumps(&format!("{field}.bumps"), b)?,
                _ => {
                    return Err(Error::config(
                        field,
                        "give exactly one of `segment`, `polygon`, `plane` and `bumps`",
                    ))
                }
            };
            if let Some(v) = w.velocity {
                finite(&format!("{field}.velocity"), &v)?;
                if w.gate || w.polygon.is_some() || w.bumps.is_some() {
                    return Err(Error::config(
                        format!("{field}.velocity"),
                        "only segments and planes that stay after the release can move",
                    ));
                }
            }
            if w.gate {
                gates.extend(row);
            } else {
                walls.extend(row.into_iter().map(|wall| (wall, w.velocity)));
            }
        }
        if walls.iter().any(|(w, _)| !w.is_straight()) && walls.iter().any(|(_, v)| v.is_some()) {
            return Err(Error::config(
                "wall",
                "walls can move only when no wall is a polygon (the polygon walls go through the \
                 rapier detector, which holds walls at rest)",
            ));
        }
        Ok((walls, gates))
    }

    /// The disks of a row of bumps (named `field`), with their images across the ends of the
    /// period when periodic: a disk within R_b + 2 d_max of one end is repeated one period
    /// beyond the other.
    fn bumps(&self, field: &str, b: &BumpsSpec) -> Result<Vec<Wall>> {
        finite(&format!("{field}.from"), &b.from)?;
        finite(&format!("{field}.to"), &b.to)?;
        positive(&format!("{field}.diameter"), b.diameter)?;
        if !(1..=100_000).contains(&b.count) {
            return Err(Error::config(
                format!("{field}.count"),
                format!("must be in 1–100 000, got {}", b.count),
            ));
        }
        let n = f64::from(b.count);
        let r = 0.5 * b.diameter;
        let margin = r + 2.0 * self.grains.d_max;
        let mut row = Vec::new();
        for k in 0..b.count {
            let t = (f64::from(k) + 0.5) / n;
            let c = [
                b.from[0] + t * (b.to[0] - b.from[0]),
                b.from[1] + t * (b.to[1] - b.from[1]),
            ];
            row.push(Wall::Disk {
                centre: c,
                radius: r,
            });
            if let Some([x0, x1]) = self.periodic_x {
                for (near, shift) in [(c[0] - x0 < margin, x1 - x0), (x1 - c[0] < margin, x0 - x1)]
                {
                    if near {
                        row.push(Wall::Disk {
                            centre: [c[0] + shift, c[1]],
                            radius: r,
                        });
                    }
                }
            }
        }
        Ok(row)
    }
}

/// Refuse a listed grain (index `first` on) that overlaps another grain, listed or filled.
fn check_listed_apart(g: &Grains, first: usize, period: Option<f64>) -> Result<()> {
    for i in first..g.len() {
        for j in 0..i {
            let d = min_image(g.x[i] - g.x[j], period).hypot(g.y[i] - g.y[j]);
            if d < g.radius[i] + g.radius[j] {
                let other = match j.checked_sub(first) {
                    Some(k) => format!("grain[{k}]"),
                    None => "a grain of the [[fill]] regions".into(),
                };
                return Err(Error::config(
                    format!("grain[{}]", i - first),
                    format!("overlaps {other}"),
                ));
            }
        }
    }
    Ok(())
}

/// Signed area of a polygon (positive counter-clockwise).
/// The vertices of a region given as exactly one of a `rectangle` (corners, refused unless
/// lower-left then upper-right) and a `polygon` (at least 3 finite vertices enclosing an
/// area); refusals name `field`.
pub(crate) fn region_vertices(
    field: &str,
    rectangle_corners: Option<[[f64; 2]; 2]>,
    polygon: Option<&[[f64; 2]]>,
) -> Result<Vec<[f64; 2]>> {
    match (rectangle_corners, polygon) {
        (Some(r), None) => {
            let [a, b] = rectangle(&format!("{field}.rectangle"), r)?;
            Ok(vec![a, [b[0], a[1]], b, [a[0], b[1]]])
        }
        (None, Some(p)) => {
            finite(&format!("{field}.polygon"), p.as_flattened())?;
            if p.len() < 3 || polygon_area(p).abs() == 0.0 {
                return Err(Error::config(
                    format!("{field}.polygon"),
                    "needs at least 3 vertices enclosing an area",
                ));
            }
            Ok(p.to_vec())
        }
        _ => Err(Error::config(
            field,
            "give exactly one of `rectangle` and `polygon`",
        )),
    }
}

fn polygon_area(v: &[[f64; 2]]) -> f64 {
    let n = v.len();
    0.5 * (0..n)
        .map(|k| {
            let (a, b) = (v[k], v[(k + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
}

/// Lower-left and upper-right corners of the bounding box.
pub(crate) fn bounds(v: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    v.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        },
    )
}

/// Distance from `p` to the nearest edge of the polygon `v`.
fn edge_distance(v: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let n = v.len();
    (0..n)
        .map(|k| {
            let (a, b) = (v[k], v[(k + 1) % n]);
            let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
            let t =
                (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / (ex * ex + ey * ey)).clamp(0.0, 1.0);
            (a[0] + t * ex - p[0]).hypot(a[1] + t * ey - p[1])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Estimated peak memory (bytes) of a granular run of `grains` disks: as a DEM column collapse
/// ([`crate::scenario::dem::spec::dem_memory`]).
pub fn granular_memory(grains: usize) -> usize {
    crate::scenario::dem::spec::dem_memory(grains)
}
