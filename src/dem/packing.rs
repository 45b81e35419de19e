//! Reproducible packings: a polydisperse column deposited under gravity, and a hexagonal
//! block. Randomness comes from [`SplitMix64`] (Steele, Lea & Flood 2014), so a seed fixes the
//! packing on every machine and thread count.

use super::contact::ContactParams;
use super::grains::Grains;
use super::params::DemParams;
use super::shape::Polygons;
use super::solver::Dem;
use super::walls::Wall;
use crate::{Error, Result};

/// SplitMix64 generator: x ← x + 0x9E3779B97F4A7C15, output = mix(x) (Steele et al. 2014).
#[derive(Clone, Copy, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64 { state: seed }
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// How diameters are drawn between d_min and d_max.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SizeDistribution {
    /// Uniform in number: p(d) = 1/(d_max − d_min) (LAMMPS benchmark).
    Uniform,
    /// Uniform by volume — in 2-D by area, d² p(d) constant, so p(d) ∝ d⁻²: each diameter
    /// interval holds the same grain area (the thesis's "uniform by volume"). Inverse CDF:
    /// d = 1/(1/d_min − u(1/d_min − 1/d_max)).
    UniformByVolume,
}

impl SizeDistribution {
    /// Draw one diameter.
    pub fn sample(self, rng: &mut SplitMix64, d_min: f64, d_max: f64) -> f64 {
        let u = rng.uniform();
        match self {
            SizeDistribution::Uniform => d_min + u * (d_max - d_min),
            SizeDistribution::UniformByVolume => {
                1.0 / (1.0 / d_min - u * (1.0 / d_min - 1.0 / d_max))
            }
        }
    }
}

/// Area of a disk of radius r below the line at height h above its centre:
/// A(h) = r²(π − arccos(h/r)) + h√(r² − h²), h clamped to [−r, r].
pub fn disk_area_below(r: f64, h: f64) -> f64 {
    let h = h.clamp(-r, r);
    r * r * (std::f64::consts::PI - (h / r).acos()) + h * (r * r - h * h).max(0.0).sqrt()
}

/// Solid fraction of the strip [x0, x1] × [y_a, y_b]: Σ (grain area between the two lines)
/// / ((x1 − x0)(y_b − y_a)). Grains are assumed to lie between x0 and x1 (walls).
pub fn strip_fraction(g: &Grains, x0: f64, x1: f64, y_a: f64, y_b: f64) -> f64 {
    let a: f64 = (0..g.len())
        .map(|i| {
            if g.is_disk(i) {
                disk_area_below(g.radius[i], y_b - g.y[i])
                    - disk_area_below(g.radius[i], y_a - g.y[i])
            } else {
                let v: Vec<[f64; 2]> = g.world_vertices(i).collect();
                polygon_area_below(&v, y_b) - polygon_area_below(&v, y_a)
            }
        })
        .sum();
    a / ((x1 - x0) * (y_b - y_a))
}

/// Area of the part of a convex polygon (vertices in order) below y = `h`: the polygon clipped
/// by the half-plane y ≤ h (Sutherland–Hodgman: keep the vertices below, add the crossing of
/// each edge with the line), then the shoelace formula.
pub fn polygon_area_below(v: &[[f64; 2]], h: f64) -> f64 {
    let mut clipped = Vec::with_capacity(v.len() + 2);
    for k in 0..v.len() {
        let (p, q) = (v[k], v[(k + 1) % v.len()]);
        if p[1] <= h {
            clipped.push(p);
        }
        if (p[1] - h) * (q[1] - h) < 0.0 {
            let t = (h - p[1]) / (q[1] - p[1]);
            clipped.push([p[0] + t * (q[0] - p[0]), h]);
        }
    }
    if clipped.len() < 3 {
        return 0.0;
    }
    crate::dem::shape::polygon_props(&clipped).area.abs()
}

/// Hexagonal block: `nx` × `ny` sites of a triangular lattice of spacing `spacing`
/// (rows `spacing·√3/2` apart, odd rows shifted by half a spacing), lower-left site at
/// (`x0`, `y0`), diameters from `dist` in [d_min, d_max] (≤ spacing, so no overlaps),
/// areal density `rho`.
#[allow(clippy::too_many_arguments)]
pub fn hex_block(
    x0: f64,
    y0: f64,
    nx: usize,
    ny: usize,
    spacing: f64,
    d: [f64; 2],
    dist: SizeDistribution,
    rho: f64,
    seed: u64,
) -> Grains {
    let mut rng = SplitMix64::new(seed);
    let mut g = Grains::with_capacity(nx * ny);
    let dy = spacing * 3f64.sqrt() / 2.0;
    for j in 0..ny {
        let shift = if j % 2 == 1 { 0.5 * spacing } else { 0.0 };
        for i in 0..nx {
            let di = dist.sample(&mut rng, d[0], d[1]);
            g.push_disk(
                x0 + shift + i as f64 * spacing,
                y0 + j as f64 * dy,
                0.5 * di,
                rho,
            );
        }
    }
    g
}

/// A column to deposit: grains dropped from a loose lattice between two walls onto a floor.
#[derive(Clone, Debug)]
pub struct ColumnSpec {
    /// Left wall x (m).
    pub x0: f64,
    /// Column width (m): right wall at x0 + width.
    pub width: f64,
    /// Number of grains.
    pub grains: usize,
    /// Smallest and largest diameter (m).
    pub diameter: [f64; 2],
    /// Diameter distribution (the thesis: uniform by volume).
    pub distribution: SizeDistribution,
    /// Areal density (kg/m² in plane 2-D).
    pub density: f64,
    /// Contact laws during deposition. Friction controls the packing: μ = 0 gives a dense
    /// packing, μ ≈ 0.5 a loose one; a rolling-friction cap above the material's holds the
    /// fall in still looser arches.
    pub params: DemParams,
    /// The material's own laws, when they differ from `params`: once at rest, the column
    /// settles again between the same walls under these (contact history cleared, as at the
    /// release), so the deposit handed to the collapse is one that these laws hold.
    pub relax: Option<DemParams>,
    /// Seed of the size draw and the lattice jitter.
    pub seed: u64,
    /// Rest criterion: deposition stops when the kinetic energy per grain falls below this
    /// fraction of m̄ g d̄ (e.g. 1e-8).
    pub rest_fraction: f64,
    /// Give up after this simulated time (s).
    pub max_time: f64,
    /// Regular convex polygons of this many sides instead of disks, each of the area of the
    /// disk of its drawn diameter (circumradius R = (d/2) √(2π / (n sin(2π/n)))) at a random
    /// orientation; `None`: disks.
    pub sides: Option<usize>,
}

/// Circumradius of the regular `n`-gon of the area of a disk of radius `r`: A = (n/2) R²
/// sin(2π/n) = π r².
pub fn equal_area_circumradius(n: usize, r: f64) -> f64 {
    let n = n as f64;
    r * (2.0 * std::f64::consts::PI / (n * (2.0 * std::f64::consts::PI / n).sin())).sqrt()
}

/// A deposited column.
#[derive(Clone, Debug)]
pub struct Column {
    /// The grains at rest (velocities zeroed).
    pub grains: Grains,
    /// Height of the highest grain top above the floor (m).
    pub height: f64,
    /// Solid fraction of the strip from d_max above the floor to 2 d_max below the top.
    pub packing_fraction: f64,
    /// Simulated deposition time (s).
    pub settle_time: f64,
}

/// Deposit a column by gravity to rest. Grains start on a square lattice of pitch 1.1 d_max
/// filling the width, jittered by 0.05 d_max, with the floor at y = 0, and fall under
/// `spec.params` (gravity included) until the kinetic energy per grain is below
/// `rest_fraction`·m̄ g d̄; then, if `spec.relax` is given, settle to rest again under it (for
/// at least 20 √(d̄/g) when the deposition was damped).
pub fn deposit_column(spec: &ColumnSpec) -> Result<Column> {
    let [d_min, d_max] = spec.diameter;
    if !(d_min > 0.0 && d_max >= d_min) {
        return Err(Error::config(
            "packing.diameter",
            format!("need 0 < d_min ≤ d_max, got {d_min}, {d_max}"),
        ));
    }
    // Polygons are placed by their circumcircle, so that none overlaps at the start.
    let bound = spec.sides.map_or(1.0, |n| equal_area_circumradius(n, 1.0));
    let pitch = 1.1 * d_max * bound;
    let per_row = (spec.width / pitch).floor() as usize;
    if per_row == 0 || spec.grains == 0 {
        return Err(Error::config(
            "packing.width",
            format!("width {} holds no grain of diameter {d_max}", spec.width),
        ));
    }
    let mut rng = SplitMix64::new(spec.seed);
    let mut g = Grains::with_capacity(spec.grains);
    for k in 0..spec.grains {
        let (col, row) = (k % per_row, k / per_row);
        let d = spec.distribution.sample(&mut rng, d_min, d_max);
        let jx = 0.05 * d_max * (2.0 * rng.uniform() - 1.0);
        let x =
            spec.x0 + 0.5 * (spec.width - per_row as f64 * pitch) + (col as f64 + 0.5) * pitch + jx;
        let y = (row as f64 + 0.5) * pitch;
        match spec.sides {
            None => {
                g.push_disk(x, y, 0.5 * d, spec.density);
            }
            Some(n) => {
                let v = Polygons::regular(n, equal_area_circumradius(n, 0.5 * d), 0.0);
                let s = g.polygons.add(&v, "grains.sides")?;
                let angle = 2.0 * std::f64::consts::PI * rng.uniform() / n as f64;
                g.push_polygon(x, y, angle, s, spec.density);
            }
        }
    }
    let walls = vec![
        Wall::floor(0.0),
        Wall::left(spec.x0),
        Wall::right(spec.x0 + spec.width),
    ];
    let gmag = spec.params.gravity[0].hypot(spec.params.gravity[1]);
    let mean_m = g.mass.iter().sum::<f64>() / g.len() as f64;
    let mean_d = 2.0 * g.radius.iter().sum::<f64>() / g.len() as f64;
    let rest = Rest {
        kinetic: spec.rest_fraction * mean_m * gmag * mean_d * g.len() as f64,
        check_time: 0.01 * (mean_d / gmag.max(f64::MIN_POSITIVE)).sqrt(),
        max_time: spec.max_time,
    };
    // Free fall of the top row to the floor, before which no rest is accepted.
    let fall = (2.0 * (spec.grains / per_row + 1) as f64 * pitch / gmag).sqrt();
    let mut dem = Dem::new(g, walls, spec.params.clone())?;
    rest.settle(&mut dem, fall, "deposition")?;
    let mut settle_time = dem.time();
    if let Some(material) = &spec.relax {
        let walls = dem.walls.clone();
        dem = Dem::new(dem.grains, walls, material.clone())?;
        dem.refresh_forces();
        // After a damped deposition (sedimentation) every grain is slow by construction, also
        // one the drag alone was holding: give such a grain 20 √(d̄/g) to fall before the rest
        // counts (it falls d̄ in √(2 d̄/g)). Undamped deposits came to rest on their contacts.
        let min_time = if spec.params.global_damping > 0.0 {
            20.0 * (mean_d / gmag).sqrt()
        } else {
            0.0
        };
        rest.settle(
            &mut dem,
            min_time,
            "relaxation under the material's contact laws",
        )?;
        settle_time += dem.time();
    }
    let mut g = dem.grains;
    g.stop();
    let height = (0..g.len())
        .map(|i| g.y[i] + g.radius[i])
        .fold(0.0, f64::max);
    let (ya, yb) = (d_max, height - 2.0 * d_max);
    let packing_fraction = if yb > ya {
        strip_fraction(&g, spec.x0, spec.x0 + spec.width, ya, yb)
    } else {
        f64::NAN
    };
    Ok(Column {
        grains: g,
        height,
        packing_fraction,
        settle_time,
    })
}

/// When a settling column counts as at rest.
struct Rest {
    /// Total kinetic energy below which the column is at rest (J).
    kinetic: f64,
    /// Interval between checks (s).
    check_time: f64,
    /// Give up after this simulated time (s).
    max_time: f64,
}

impl Rest {
    /// Step `dem` until its kinetic energy is below the limit, not before `min_time`; every
    /// 15 s of wall time a line on standard error says how far it is (the end is the rest,
    /// which cannot be foreseen: the line gives the kinetic energy against the limit).
    fn settle(&self, dem: &mut Dem, min_time: f64, stage: &str) -> Result<()> {
        let check = ((self.check_time / dem.dt()).ceil() as u64).max(1);
        let mut heartbeat = crate::exec::Heartbeat::new();
        while dem.time() < self.max_time {
            dem.steps(check);
            let k = dem.energy().kinetic_total();
            if !k.is_finite() {
                return Err(Error::Other(format!("{stage} went unstable")));
            }
            if heartbeat.due() {
                eprintln!(
                    "{stage}: {:.3} s simulated (at most {} s), kinetic energy {:.1} × the rest \
                     level",
                    dem.time(),
                    self.max_time,
                    k / self.kinetic
                );
            }
            if dem.time() > min_time && k < self.kinetic {
                return Ok(());
            }
        }
        Err(Error::Other(format!(
            "{stage} did not come to rest within {} s",
            self.max_time
        )))
    }
}

/// Convenience: contact parameters for deposition with friction `mu` (all else from `p`).
pub fn with_friction(p: &DemParams, mu: f64) -> DemParams {
    let mut q = p.clone();
    q.grain = ContactParams {
        friction: mu,
        ..q.grain
    };
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix_reference_values() {
        // First outputs for seed 1234567 (reference implementation by S. Vigna, prng.di.unimi.it).
        let mut r = SplitMix64::new(1234567);
        assert_eq!(r.next_u64(), 6457827717110365317);
        assert_eq!(r.next_u64(), 3203168211198807973);
    }

    /// The equal-area n-gon: its shoelace area is π r² to round-off for n = 3…12.
    #[test]
    fn equal_area_polygon_has_the_disk_area() {
        for n in 3..=12 {
            let v = Polygons::regular(n, equal_area_circumradius(n, 0.7), 0.3);
            let a = crate::dem::shape::polygon_props(&v).area;
            assert!(
                (a / (std::f64::consts::PI * 0.49) - 1.0).abs() < 1e-12,
                "n = {n}: {a}"
            );
        }
    }

    /// Clipping: a unit square [0, 1]² has y·1 below y; a triangle (0,0), (2,0), (0,2) has
    /// 2 − (2 − h)²/2 below h; all or nothing outside (exact to round-off).
    #[test]
    fn polygon_area_below_a_line() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        for h in [0.1, 0.5, 0.9] {
            assert!((polygon_area_below(&square, h) - h).abs() < 1e-15);
        }
        assert_eq!(polygon_area_below(&square, -0.1), 0.0);
        assert!((polygon_area_below(&square, 1.5) - 1.0).abs() < 1e-15);
        let tri = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        for h in [0.3, 1.0, 1.7] {
            let want = 2.0 - (2.0f64 - h).powi(2) / 2.0;
            assert!((polygon_area_below(&tri, h) - want).abs() < 1e-14);
        }
    }

    #[test]
    fn disk_area_below_limits() {
        let r = 2.0;
        assert!((disk_area_below(r, 5.0) - std::f64::consts::PI * 4.0).abs() < 1e-12);
        assert_eq!(disk_area_below(r, -5.0), 0.0);
        assert!((disk_area_below(r, 0.0) - std::f64::consts::PI * 2.0).abs() < 1e-12);
    }

    #[test]
    fn by_volume_draw_follows_its_cdf() {
        // p(d) ∝ d⁻² on [a, b]: F(d) = (1/a − 1/d)/(1/a − 1/b); F(1.15) = 0.6 for [0.92, 1.38],
        // and the mean of d² is a·b (uniform area per diameter interval). 10⁶ draws: binomial
        // σ of the fraction ≈ 5e-4.
        let mut rng = SplitMix64::new(1);
        let (n, mut below, mut d2) = (1_000_000, 0usize, 0.0);
        for _ in 0..n {
            let d = SizeDistribution::UniformByVolume.sample(&mut rng, 0.92, 1.38);
            assert!((0.92..=1.38).contains(&d));
            below += usize::from(d < 1.15);
            d2 += d * d;
        }
        assert!((below as f64 / n as f64 - 0.6).abs() < 3e-3);
        assert!((d2 / n as f64 / (0.92 * 1.38) - 1.0).abs() < 3e-3);
    }
}
