//! Boundary conditions on grid nodes: straight walls along grid lines, each constraining the
//! nodes on and behind it (the wall node row and the ghost nodes outside the domain).
//!
//! With n the unit normal pointing into the material and v the nodal velocity after the
//! momentum update, v_n = v·n, v_t = v − v_n n:
//!
//! * `Fixed`: v = 0.
//! * `Roller`: v_n = 0 (bilateral, frictionless).
//! * `Friction { mu }`: unilateral Coulomb contact, as the thesis applies to the channel base
//!   and back wall: if v_n < 0 (moving into the wall) the normal velocity is removed,
//!   Δv_n = −v_n, and the tangential speed is reduced by at most μ Δv_n:
//!   v_t ← v_t · max(0, 1 − μ Δv_n/|v_t|) (the impulse m Δv_t is bounded by μ m Δv_n);
//!   separating nodes (v_n ≥ 0) are free.
//!
//! The kinetic energy each constraint takes out, ½ m (|v_before|² − |v_after|²), is returned
//! so the energy budget can book it (tangential part: friction; normal part: impact).

use serde::{Deserialize, Serialize};

/// Kind of a wall.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", deny_unknown_fields)]
pub enum WallKind {
    /// No motion.
    Fixed,
    /// No normal motion, free tangential motion.
    Roller,
    /// Unilateral contact with Coulomb friction μ.
    Friction {
        /// Coulomb friction coefficient μ between wall and material.
        mu: f64,
    },
}

/// Which side of the domain a wall bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// x = position, material at larger x.
    Left,
    /// x = position, material at smaller x.
    Right,
    /// y = position, material above.
    Bottom,
    /// y = position, material below.
    Top,
}

/// A wall on a grid line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wall {
    /// Which side.
    pub side: Side,
    /// Coordinate of the wall line (m); nodes at or beyond it are constrained.
    pub position: f64,
    /// Condition.
    pub kind: WallKind,
}

impl Wall {
    /// Inward unit normal.
    pub fn normal(&self) -> [f64; 2] {
        match self.side {
            Side::Left => [1.0, 0.0],
            Side::Right => [-1.0, 0.0],
            Side::Bottom => [0.0, 1.0],
            Side::Top => [0.0, -1.0],
        }
    }

    /// Whether a node at `x` is on or behind the wall (tolerance `eps`).
    pub fn holds(&self, x: [f64; 2], eps: f64) -> bool {
        match self.side {
            Side::Left => x[0] <= self.position + eps,
            Side::Right => x[0] >= self.position - eps,
            Side::Bottom => x[1] <= self.position + eps,
            Side::Top => x[1] >= self.position - eps,
        }
    }

    /// Apply the condition to velocity `v` of a node of mass `m`; returns the kinetic energy
    /// removed, split into (normal, tangential) parts.
    #[inline]
    pub fn apply(&self, v: &mut [f64; 2], m: f64) -> (f64, f64) {
        let n = self.normal();
        let vn = v[0] * n[0] + v[1] * n[1];
        let vt = [v[0] - vn * n[0], v[1] - vn * n[1]];
        let vt2 = vt[0] * vt[0] + vt[1] * vt[1];
        match self.kind {
            WallKind::Fixed => {
                *v = [0.0; 2];
                (0.5 * m * vn * vn, 0.5 * m * vt2)
            }
            WallKind::Roller => {
                *v = vt;
                (0.5 * m * vn * vn, 0.0)
            }
            WallKind::Friction { mu } => {
                if vn >= 0.0 {
                    return (0.0, 0.0);
                }
                let dvn = -vn;
                let speed = vt2.sqrt();
                let scale = if speed > 0.0 {
                    (1.0 - mu * dvn / speed).max(0.0)
                } else {
                    0.0
                };
                *v = [vt[0] * scale, vt[1] * scale];
                (0.5 * m * vn * vn, 0.5 * m * vt2 * (1.0 - scale * scale))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coulomb: the tangential impulse equals μ × the normal impulse while sliding, and
    /// sticking takes all tangential velocity; separation is free; energy is booked.
    #[test]
    fn coulomb_wall_limits_the_tangential_impulse() {
        let w = Wall {
            side: Side::Bottom,
            position: 0.0,
            kind: WallKind::Friction { mu: 0.5 },
        };
        let mut v = [2.0, -1.0];
        let (en, et) = w.apply(&mut v, 3.0);
        assert_eq!(v, [1.5, 0.0]);
        assert!((en - 1.5).abs() < 1e-15 && (et - 0.5 * 3.0 * (4.0 - 2.25)).abs() < 1e-12);
        let mut v = [0.2, -1.0];
        w.apply(&mut v, 1.0);
        assert_eq!(v, [0.0, 0.0]);
        let mut v = [0.2, 1.0];
        assert_eq!(w.apply(&mut v, 1.0), (0.0, 0.0));
        assert_eq!(v, [0.2, 1.0]);
        let r = Wall {
            side: Side::Left,
            position: 0.0,
            kind: WallKind::Roller,
        };
        let mut v = [0.3, -0.4];
        r.apply(&mut v, 1.0);
        assert_eq!(v, [0.0, -0.4]);
    }
}
