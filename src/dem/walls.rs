//! Fixed walls: half-planes (box sides, floor), straight line segments, fixed disks (the bumps of
//! a rough wall) and convex polygons.
//!
//! Planes, segments and disks meet disk grains through the cell list ([`super::neighbours`])
//! with the distance below; polygon walls, and every wall a polygon grain meets, go through the rapier2d
//! detector ([`super::detect_rapier`]).
//!
//! A wall reports, for a disk of centre **c**, the distance s from the centre to the wall and
//! the unit contact normal **n** pointing from the centre towards the wall; the overlap is
//! δ = R − s. The wall acts as a grain of infinite mass at rest (m_eff = m_i, R_eff = R_i).

/// A fixed wall.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Wall {
    /// The half-plane behind the line through `point` with unit `normal` pointing into the
    /// domain: s = (**c** − **p**)·**N**, **n** = −**N**. Never tunnelled: a grain found behind
    /// it is pushed back out.
    Plane {
        /// A point on the line.
        point: [f64; 2],
        /// Unit normal pointing into the domain (where the grains are).
        normal: [f64; 2],
    },
    /// The segment from `a` to `b` (both sides, rounded ends): s = |**c** − **q**| with **q** the
    /// closest point of the segment, **n** = (**q** − **c**)/s.
    Segment {
        /// First end.
        a: [f64; 2],
        /// Second end.
        b: [f64; 2],
    },
    /// A fixed disk of radius `radius` centred at `centre` (one bump of a rough wall):
    /// s = |**c** − **p**| − R_w, **n** = (**p** − **c**)/|**p** − **c**|.
    Disk {
        /// Centre.
        centre: [f64; 2],
        /// Radius (> 0).
        radius: f64,
    },
    /// A solid convex polygon (an obstacle), `vertices[..n]` in world coordinates, counter-
    /// clockwise. Contacts with it are found by the rapier2d detector only; [`Wall::distance`]
    /// reports it out of reach so the cell list never pairs it.
    Polygon {
        /// Vertices; only the first `n` are used.
        vertices: [[f64; 2]; MAX_WALL_VERTICES],
        /// Number of vertices (3 ≤ n ≤ [`MAX_WALL_VERTICES`]).
        n: u8,
    },
}

/// Most vertices of a polygon wall (the wall stays `Copy`, with no heap object).
pub const MAX_WALL_VERTICES: usize = 8;

impl Wall {
    /// Floor y = `y0` (grains above).
    pub fn floor(y0: f64) -> Self {
        Wall::Plane {
            point: [0.0, y0],
            normal: [0.0, 1.0],
        }
    }

    /// Left wall x = `x0` (grains to its right).
    pub fn left(x0: f64) -> Self {
        Wall::Plane {
            point: [x0, 0.0],
            normal: [1.0, 0.0],
        }
    }

    /// Right wall x = `x1` (grains to its left).
    pub fn right(x1: f64) -> Self {
        Wall::Plane {
            point: [x1, 0.0],
            normal: [-1.0, 0.0],
        }
    }

    /// A convex polygon wall from its vertices (either orientation, stored counter-clockwise);
    /// `field` names it in the error.
    pub fn polygon(v: &[[f64; 2]], field: &str) -> crate::Result<Self> {
        super::shape::check_convex(v, field)?;
        if v.len() > MAX_WALL_VERTICES {
            return Err(crate::Error::config(
                field,
                format!(
                    "a polygon wall has at most {MAX_WALL_VERTICES} vertices, got {}",
                    v.len()
                ),
            ));
        }
        let mut vertices = [[0.0; 2]; MAX_WALL_VERTICES];
        vertices[..v.len()].copy_from_slice(v);
        if super::shape::polygon_props(v).area < 0.0 {
            vertices[..v.len()].reverse();
        }
        Ok(Wall::Polygon {
            vertices,
            n: v.len() as u8,
        })
    }

    /// Move the wall by `d` (m), keeping its orientation.
    pub fn translate(&mut self, d: [f64; 2]) {
        let shift = |p: &mut [f64; 2]| {
            p[0] += d[0];
            p[1] += d[1];
        };
        match self {
            Wall::Plane { point, .. } => shift(point),
            Wall::Segment { a, b } => {
                shift(a);
                shift(b);
            }
            Wall::Disk { centre, .. } => shift(centre),
            Wall::Polygon { vertices, n } => vertices[..*n as usize].iter_mut().for_each(shift),
        }
    }

    /// Whether the cell list handles this wall for disks (planes, segments and disks).
    pub fn is_straight(&self) -> bool {
        !matches!(self, Wall::Polygon { .. })
    }

    /// Distance s from `c` to the wall and the unit normal **n** from `c` towards it
    /// (s = ∞ for a polygon wall, which only the rapier detector sees).
    #[inline(always)]
    pub fn distance(&self, c: [f64; 2]) -> (f64, [f64; 2]) {
        match *self {
            Wall::Plane { point, normal } => {
                let s = (c[0] - point[0]) * normal[0] + (c[1] - point[1]) * normal[1];
                (s, [-normal[0], -normal[1]])
            }
            Wall::Segment { a, b } => {
                let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
                let len2 = ex * ex + ey * ey;
                let u = if len2 > 0.0 {
                    (((c[0] - a[0]) * ex + (c[1] - a[1]) * ey) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (dx, dy) = (a[0] + u * ex - c[0], a[1] + u * ey - c[1]);
                let s = (dx * dx + dy * dy).sqrt();
                if s > 0.0 {
                    (s, [dx / s, dy / s])
                } else {
                    // Centre on the segment: push along the segment's left normal.
                    let l = len2.sqrt().max(f64::MIN_POSITIVE);
                    (0.0, [ey / l, -ex / l])
                }
            }
            Wall::Disk { centre, radius } => {
                let (dx, dy) = (centre[0] - c[0], centre[1] - c[1]);
                let d = (dx * dx + dy * dy).sqrt();
                if d > 0.0 {
                    (d - radius, [dx / d, dy / d])
                } else {
                    (-radius, [0.0, -1.0])
                }
            }
            Wall::Polygon { .. } => (f64::INFINITY, [0.0, 0.0]),
        }
    }

    /// Check the geometry; `field` names it in the error.
    pub fn check(&self, field: &str) -> crate::Result<()> {
        match *self {
            Wall::Plane { point, normal } => {
                let n = (normal[0] * normal[0] + normal[1] * normal[1]).sqrt();
                if !(point.iter().all(|v| v.is_finite()) && (n - 1.0).abs() < 1e-9) {
                    return Err(crate::Error::config(
                        field,
                        format!("plane needs a finite point and a unit normal, got |n| = {n}"),
                    ));
                }
            }
            Wall::Segment { a, b } => {
                if !(a.iter().chain(b.iter()).all(|v| v.is_finite()) && a != b) {
                    return Err(crate::Error::config(
                        field,
                        "segment needs two distinct finite end points",
                    ));
                }
            }
            Wall::Disk { centre, radius } => {
                if !(centre.iter().all(|v| v.is_finite()) && radius > 0.0 && radius.is_finite()) {
                    return Err(crate::Error::config(
                        field,
                        format!("disk needs a finite centre and a radius > 0, got R = {radius}"),
                    ));
                }
            }
            Wall::Polygon { vertices, n } => {
                if !(3..=MAX_WALL_VERTICES).contains(&(n as usize)) {
                    return Err(crate::Error::config(
                        field,
                        format!("polygon wall needs 3 to {MAX_WALL_VERTICES} vertices, got {n}"),
                    ));
                }
                super::shape::check_convex(&vertices[..n as usize], field)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_and_normal() {
        let w = Wall::Segment {
            a: [0.0, 0.0],
            b: [2.0, 0.0],
        };
        let (s, n) = w.distance([1.0, 0.5]);
        assert!((s - 0.5).abs() < 1e-15 && n == [0.0, -1.0]);
        let (s, _) = w.distance([3.0, 0.0]);
        assert!((s - 1.0).abs() < 1e-15);
        let (s, n) = Wall::floor(0.0).distance([5.0, 0.25]);
        assert!((s - 0.25).abs() < 1e-15 && n == [0.0, -1.0]);
    }
}
