//! Obstacles: shapes rasterised onto the lattice, their boundary links, interpolated
//! bounce-back and the hydrodynamic force and torque by momentum exchange.
//!
//! A cell is solid when its centre lies inside a shape. Every link from a fluid node x_f to a
//! solid node x_b = x_f + e_i is recorded with q = |x_w − x_f| / |e_i| ∈ (0, 1], x_w the wall
//! crossing on the link (found exactly for circles, by bisection for other shapes).
//!
//! **Interpolated bounce-back** (Yu, Mei, Luo & Shyy 2003; seed eq. 5.51, at rest): after the
//! step, the population returning to x_f is replaced by
//!
//! f_ī(x_f, t+1) = [ (1 − q) f_i*(x_f − e_i) + q f_i*(x_f) + q f_ī*(x_f) ] / (1 + q),
//!
//! the starred values post-collision at t. Where x_f − e_i is not fluid the link falls back to
//! half-way bounce-back. Half-way bounce-back (q = ½ regardless of the shape) is the default.
//!
//! **Momentum exchange** (Ladd 1994; seed eq. 5.52): the force on the obstacle in one step is
//! F = Σ_links e_i [f_i*(x_f) + f_ī(x_f, t+1)], the torque T = Σ (x_w − x_c) × F_link.

use super::d2q9::{CX, CY, OPP, Q};
use super::lattice::Lattice;
use super::real::Real;

/// An obstacle shape in lattice coordinates (cell (x, y) has its centre at (x + ½, y + ½)).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Axis-aligned rectangle.
    Rectangle {
        /// Lower-left corner.
        min: [f64; 2],
        /// Upper-right corner.
        max: [f64; 2],
    },
    /// Disk.
    Circle {
        /// Centre.
        center: [f64; 2],
        /// Radius.
        radius: f64,
    },
    /// Simple polygon (any orientation; even–odd rule).
    Polygon {
        /// Vertices in order.
        vertices: Vec<[f64; 2]>,
    },
}

impl Shape {
    /// Is point `p` inside?
    pub fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Shape::Rectangle { min, max } => {
                p[0] >= min[0] && p[0] <= max[0] && p[1] >= min[1] && p[1] <= max[1]
            }
            Shape::Circle { center, radius } => {
                let (dx, dy) = (p[0] - center[0], p[1] - center[1]);
                dx * dx + dy * dy <= radius * radius
            }
            Shape::Polygon { vertices } => {
                let mut inside = false;
                let m = vertices.len();
                for k in 0..m {
                    let (a, b) = (vertices[k], vertices[(k + 1) % m]);
                    if (a[1] > p[1]) != (b[1] > p[1]) {
                        let xc = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                        if p[0] < xc {
                            inside = !inside;
                        }
                    }
                }
                inside
            }
        }
    }

    /// Reference point for torques: centre of a circle or rectangle, vertex mean of a polygon.
    pub fn centre(&self) -> [f64; 2] {
        match self {
            Shape::Rectangle { min, max } => [0.5 * (min[0] + max[0]), 0.5 * (min[1] + max[1])],
            Shape::Circle { center, .. } => *center,
            Shape::Polygon { vertices } => {
                let m = vertices.len() as f64;
                let s = vertices
                    .iter()
                    .fold([0.0, 0.0], |a, v| [a[0] + v[0], a[1] + v[1]]);
                [s[0] / m, s[1] / m]
            }
        }
    }

    /// Bounding box (min, max).
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Shape::Rectangle { min, max } => (*min, *max),
            Shape::Circle { center, radius } => (
                [center[0] - radius, center[1] - radius],
                [center[0] + radius, center[1] + radius],
            ),
            Shape::Polygon { vertices } => vertices.iter().fold(
                ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
                |(lo, hi), v| {
                    (
                        [lo[0].min(v[0]), lo[1].min(v[1])],
                        [hi[0].max(v[0]), hi[1].max(v[1])],
                    )
                },
            ),
        }
    }

    /// Fraction q ∈ (0, 1] of the link from outside point `a` to inside point `a + e` at which
    /// the boundary is crossed.
    pub fn crossing(&self, a: [f64; 2], e: [f64; 2]) -> f64 {
        if let Shape::Circle { center, radius } = self {
            // |a + q e − c|² = r², smallest root.
            let d = [a[0] - center[0], a[1] - center[1]];
            let aa = e[0] * e[0] + e[1] * e[1];
            let bb = 2.0 * (d[0] * e[0] + d[1] * e[1]);
            let cc = d[0] * d[0] + d[1] * d[1] - radius * radius;
            let disc = (bb * bb - 4.0 * aa * cc).max(0.0);
            return ((-bb - disc.sqrt()) / (2.0 * aa)).clamp(1e-6, 1.0);
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if self.contains([a[0] + mid * e[0], a[1] + mid * e[1]]) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        (0.5 * (lo + hi)).max(1e-6)
    }
}

/// An obstacle: a shape and how its wall is treated.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Name used in outputs.
    pub name: String,
    /// Geometry in lattice coordinates.
    pub shape: Shape,
    /// Interpolated (Yu 2003) instead of half-way bounce-back.
    pub interpolated: bool,
}

/// A fluid–solid link.
#[derive(Clone, Debug)]
pub(crate) struct Link {
    /// Fluid node x_f.
    pub cell: u32,
    /// Direction into the solid.
    pub dir: u8,
    /// Owning obstacle.
    owner: u16,
    /// Wall distance fraction.
    pub q: f64,
    /// x_f − e_i when it is a fluid node.
    behind: Option<u32>,
    /// Torque arm x_w − x_c.
    arm: [f64; 2],
}

/// All obstacles of a lattice with their links and the last step's forces.
#[derive(Clone, Debug, Default)]
pub struct Obstacles {
    /// The obstacles.
    pub list: Vec<Obstacle>,
    links: Vec<Link>,
    /// Force on each obstacle in the last step (lattice units).
    pub force: Vec<[f64; 2]>,
    /// Torque on each obstacle in the last step (lattice units).
    pub torque: Vec<f64>,
    /// Scratch: the momentum each link exchanged in the last step.
    exchanged: Vec<f64>,
}

impl Obstacles {
    /// A set of obstacles, not yet linked to a lattice.
    pub fn new(list: Vec<Obstacle>) -> Self {
        Obstacles {
            list,
            ..Default::default()
        }
    }

    /// Rasterise: the solid mask (`solid[y·nx + x]`) of the obstacles on an `nx × ny` lattice.
    pub fn mask(&self, nx: usize, ny: usize) -> Vec<bool> {
        let mut solid = vec![false; nx * ny];
        for ob in &self.list {
            let (lo, hi) = ob.shape.bounds();
            let x0 = (lo[0] - 1.0).floor().max(0.0) as usize;
            let y0 = (lo[1] - 1.0).floor().max(0.0) as usize;
            let x1 = ((hi[0] + 1.0).ceil().max(0.0) as usize).min(nx);
            let y1 = ((hi[1] + 1.0).ceil().max(0.0) as usize).min(ny);
            for y in y0..y1 {
                for x in x0..x1 {
                    if ob.shape.contains([x as f64 + 0.5, y as f64 + 0.5]) {
                        solid[y * nx + x] = true;
                    }
                }
            }
        }
        solid
    }

    /// Find the links of every obstacle on `lat` (whose solid mask came from [`Obstacles::mask`]).
    pub fn link<T: Real>(&mut self, lat: &Lattice<T>) {
        let (nx, ny) = (lat.nx as i64, lat.ny as i64);
        let px = lat.edges().left == super::boundary::Edge::Periodic;
        let py = lat.edges().bottom == super::boundary::Edge::Periodic;
        let wrap = |x: i64, y: i64| -> Option<usize> {
            let x = if px { x.rem_euclid(nx) } else { x };
            let y = if py { y.rem_euclid(ny) } else { y };
            (x >= 0 && x < nx && y >= 0 && y < ny).then(|| (y * nx + x) as usize)
        };
        self.links.clear();
        for c in 0..lat.len() {
            if lat.is_solid(c) {
                continue;
            }
            let (x, y) = ((c as i64) % nx, (c as i64) / nx);
            for i in 1..Q {
                let Some(b) = wrap(x + CX[i] as i64, y + CY[i] as i64) else {
                    continue;
                };
                if !lat.is_solid(b) {
                    continue;
                }
                let e = [CX[i] as f64, CY[i] as f64];
                // Shapes lie inside the domain (the scenario check refuses points outside), so
                // the wrapped solid node's centre identifies the owner.
                let bc = [(b as i64 % nx) as f64 + 0.5, (b as i64 / nx) as f64 + 0.5];
                let owner = self.list.iter().position(|o| o.shape.contains(bc));
                // The fluid node seen from the solid node (unwrapped across a periodic edge).
                let a = [bc[0] - e[0], bc[1] - e[1]];
                let Some(owner) = owner else { continue };
                let ob = &self.list[owner];
                let q = if ob.interpolated {
                    ob.shape.crossing(a, e)
                } else {
                    0.5
                };
                let behind = wrap(x - CX[i] as i64, y - CY[i] as i64).filter(|&k| !lat.is_solid(k));
                let cen = ob.shape.centre();
                let arm = [a[0] + q * e[0] - cen[0], a[1] + q * e[1] - cen[1]];
                self.links.push(Link {
                    cell: c as u32,
                    dir: i as u8,
                    owner: owner as u16,
                    q,
                    behind: behind.map(|k| k as u32),
                    arm,
                });
            }
        }
        self.force = vec![[0.0; 2]; self.list.len()];
        self.torque = vec![0.0; self.list.len()];
    }

    /// After a step of parity `was_even`: apply interpolated bounce-back on interpolated links
    /// and record force and torque by momentum exchange.
    pub fn after_step<T: Real>(&mut self, lat: &mut Lattice<T>, was_even: bool) {
        let mut exchanged = std::mem::take(&mut self.exchanged);
        exchanged.clear();
        exchanged.extend(self.links.iter().map(|link| {
            let (c, i) = (link.cell as usize, link.dir as usize);
            let o = OPP[i];
            // f_i*(x_f): after either parity it sits in A[x_f][ī].
            let out = lat.slot(o, c);
            let back = match self.interpolated_behind(link) {
                Some(k) => {
                    let k = k as usize;
                    let (in_behind, out_rev) = if was_even {
                        (lat.slot(o, k), lat.slot(i, c))
                    } else {
                        (lat.slot(i, c), lat.slot(o, k))
                    };
                    let q = T::c(link.q);
                    let v = ((T::one() - q) * in_behind + q * out + q * out_rev) / (T::one() + q);
                    lat.set_slot(o, c, v);
                    v
                }
                None => out,
            };
            (out + back).f64()
        }));
        self.set_loads(&exchanged);
        self.exchanged = exchanged;
    }

    /// Force and torque from the momentum `exchanged[l]` = f_i*(x_f) + f_ī(x_f) across each
    /// link l in the last step: F = Σ m e_i, T = Σ (x_w − x_c) × m e_i, summed in link order.
    pub(crate) fn set_loads(&mut self, exchanged: &[f64]) {
        for f in &mut self.force {
            *f = [0.0; 2];
        }
        for t in &mut self.torque {
            *t = 0.0;
        }
        for (link, &m) in self.links.iter().zip(exchanged) {
            let i = link.dir as usize;
            let df = [m * CX[i] as f64, m * CY[i] as f64];
            let k = link.owner as usize;
            self.force[k][0] += df[0];
            self.force[k][1] += df[1];
            self.torque[k] += link.arm[0] * df[1] - link.arm[1] * df[0];
        }
    }

    /// The fluid node behind `link` (x_f − e_i) when the link is interpolated (Yu 2003) and
    /// that node is fluid; `None`: half-way bounce-back.
    pub(crate) fn interpolated_behind(&self, link: &Link) -> Option<u32> {
        link.behind
            .filter(|_| self.list[link.owner as usize].interpolated)
    }

    /// The fluid–solid links.
    #[cfg(feature = "gpu")]
    pub(crate) fn links(&self) -> &[Link] {
        &self.links
    }

    /// Number of fluid–solid links.
    pub fn link_count(&self) -> usize {
        self.links.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_contain_their_centre_and_not_far_points() {
        let shapes = [
            Shape::Rectangle {
                min: [1.0, 1.0],
                max: [3.0, 2.0],
            },
            Shape::Circle {
                center: [2.0, 1.5],
                radius: 0.7,
            },
            Shape::Polygon {
                vertices: vec![[1.0, 1.0], [3.0, 1.0], [2.0, 2.5]],
            },
        ];
        for s in &shapes {
            assert!(s.contains(s.centre()), "{s:?}");
            assert!(!s.contains([10.0, 10.0]));
        }
    }

    /// Regression (review finding): a link from x = nx − 1 across a periodic edge into a shape
    /// touching x = 0 must get q and the torque arm of the wrapped geometry.
    #[test]
    fn links_across_a_periodic_edge() {
        use crate::lbm::{Edges, Lattice};
        let mut obs = Obstacles::new(vec![Obstacle {
            name: "block".into(),
            shape: Shape::Rectangle {
                min: [0.0, 2.0],
                max: [2.5, 5.0],
            },
            interpolated: true,
        }]);
        let solid = obs.mask(10, 8);
        let lat = Lattice::<f64>::new(10, 8, Edges::periodic(), solid).unwrap();
        obs.link(&lat);
        let across: Vec<&Link> = obs
            .links
            .iter()
            .filter(|l| l.cell as usize % 10 == 9 && l.dir == 1)
            .collect();
        assert!(!across.is_empty());
        for l in across {
            assert!((l.q - 0.5).abs() < 1e-9, "q = {}", l.q);
            assert!((l.arm[0] - (-1.25)).abs() < 1e-9, "arm = {:?}", l.arm);
        }
    }

    #[test]
    fn circle_crossing_is_exact_and_bisection_agrees() {
        let c = Shape::Circle {
            center: [0.0, 0.0],
            radius: 1.0,
        };
        // From (1.6, 0) towards −x: crosses at x = 1, q = 0.6.
        assert!((c.crossing([1.6, 0.0], [-1.0, 0.0]) - 0.6).abs() < 1e-12);
        let p = Shape::Polygon {
            vertices: vec![[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]],
        };
        assert!((p.crossing([1.25, 0.3], [-1.0, 0.0]) - 0.25).abs() < 1e-9);
    }
}
