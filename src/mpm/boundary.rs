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
//! * `Platen { speed }`: a smooth rigid platen moving along its inward normal at `speed`
//!   (m/s, positive into the material): v_n = speed, v_t free (a moving roller, used for
//!   displacement-controlled loading in `mpm-mc-biaxial`). Its nodes stay on the wall's grid
//!   line while the material moves, so it is meant for small platen travel (≪ h · cells).
//!   Not a scenario option (not deserialised).
//!
//! Each constraint returns the velocity change it made, split into its normal and tangential
//! parts, so the solver can book the work of the constraint impulse (see
//! [`super::solver`]: D = −m Δv·(v^{n+1} + v^n)/2, the midpoint rule that makes the nodal
//! kinetic energy balance exact; a wall holding a node at rest does no work).

use serde::{Deserialize, Serialize};

/// Kind of a wall.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
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
    /// Smooth rigid platen moving along the inward normal at `speed` (m/s).
    #[serde(skip)]
    Platen {
        /// Normal velocity into the material (m/s).
        speed: f64,
    },
}

/// Which side of the domain a wall bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
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
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Wall {
    /// Which side.
    pub side: Side,
    /// Coordinate of the wall line (m); nodes at or beyond it are constrained.
    pub position: f64,
    /// Condition.
    #[serde(with = "kind_state")]
    pub kind: WallKind,
}

/// [`WallKind`] in a checkpoint: every variant (the platen too), externally tagged, where the
/// scenario files' form is tagged by a `kind` key (which compact binary formats cannot read
/// back).
mod kind_state {
    use super::WallKind;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    enum State {
        Fixed,
        Roller,
        Friction(f64),
        Platen(f64),
    }

    pub fn serialize<S: Serializer>(k: &WallKind, s: S) -> Result<S::Ok, S::Error> {
        match *k {
            WallKind::Fixed => State::Fixed,
            WallKind::Roller => State::Roller,
            WallKind::Friction { mu } => State::Friction(mu),
            WallKind::Platen { speed } => State::Platen(speed),
        }
        .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<WallKind, D::Error> {
        Ok(match State::deserialize(d)? {
            State::Fixed => WallKind::Fixed,
            State::Roller => WallKind::Roller,
            State::Friction(mu) => WallKind::Friction { mu },
            State::Platen(speed) => WallKind::Platen { speed },
        })
    }
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

    /// Whether the condition acts on a node moving at `v` (the momentum update's velocity):
    /// always, except for a unilateral `Friction` wall, which acts only while the node moves
    /// into it (v_n < 0).
    #[inline]
    pub fn engages(&self, v: [f64; 2]) -> bool {
        match self.kind {
            WallKind::Friction { .. } => {
                let n = self.normal();
                v[0] * n[0] + v[1] * n[1] < 0.0
            }
            _ => true,
        }
    }

    /// The condition on a re-mapped velocity (MUSL) of a node whose contact state the momentum
    /// update of the same step decided (`engaged`, see [`Wall::engages`]): a unilateral wall in
    /// contact keeps the node on it (v_n = 0) even where the re-mapped v_n ≥ 0, since the
    /// nodal velocity v^{n+1} it re-maps has v_n = 0 there; otherwise as [`Wall::apply`].
    #[inline]
    pub fn apply_engaged(&self, v: &mut [f64; 2], engaged: bool) -> ([f64; 2], [f64; 2]) {
        if let WallKind::Friction { .. } = self.kind {
            let n = self.normal();
            let vn = v[0] * n[0] + v[1] * n[1];
            if engaged && vn >= 0.0 {
                *v = [v[0] - vn * n[0], v[1] - vn * n[1]];
                return ([-vn * n[0], -vn * n[1]], [0.0; 2]);
            }
        }
        self.apply(v)
    }

    /// Apply the condition to the velocity `v` of a node; returns the velocity change, split
    /// into (normal, tangential) parts.
    #[inline]
    pub fn apply(&self, v: &mut [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let n = self.normal();
        let vn = v[0] * n[0] + v[1] * n[1];
        let vt = [v[0] - vn * n[0], v[1] - vn * n[1]];
        let dn = [-vn * n[0], -vn * n[1]];
        match self.kind {
            WallKind::Fixed => {
                *v = [0.0; 2];
                (dn, [-vt[0], -vt[1]])
            }
            WallKind::Roller => {
                *v = vt;
                (dn, [0.0; 2])
            }
            WallKind::Platen { speed } => {
                *v = [vt[0] + speed * n[0], vt[1] + speed * n[1]];
                ([dn[0] + speed * n[0], dn[1] + speed * n[1]], [0.0; 2])
            }
            WallKind::Friction { mu } => {
                if vn >= 0.0 {
                    return ([0.0; 2], [0.0; 2]);
                }
                let speed = (vt[0] * vt[0] + vt[1] * vt[1]).sqrt();
                let scale = if speed > 0.0 {
                    (1.0 - mu * (-vn) / speed).max(0.0)
                } else {
                    0.0
                };
                *v = [vt[0] * scale, vt[1] * scale];
                (dn, [vt[0] * (scale - 1.0), vt[1] * (scale - 1.0)])
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coulomb: the tangential impulse equals μ × the normal impulse while sliding, and
    /// sticking takes all tangential velocity; separation is free; the changes are reported.
    #[test]
    fn coulomb_wall_limits_the_tangential_impulse() {
        let w = Wall {
            side: Side::Bottom,
            position: 0.0,
            kind: WallKind::Friction { mu: 0.5 },
        };
        let mut v = [2.0, -1.0];
        let (dn, dt) = w.apply(&mut v);
        assert_eq!(v, [1.5, 0.0]);
        assert_eq!((dn, dt), ([0.0, 1.0], [-0.5, 0.0]));
        let mut v = [0.2, -1.0];
        w.apply(&mut v);
        assert_eq!(v, [0.0, 0.0]);
        let mut v = [0.2, 1.0];
        assert_eq!(w.apply(&mut v), ([0.0; 2], [0.0; 2]));
        assert_eq!(v, [0.2, 1.0]);
        let r = Wall {
            side: Side::Left,
            position: 0.0,
            kind: WallKind::Roller,
        };
        let mut v = [0.3, -0.4];
        r.apply(&mut v);
        assert_eq!(v, [0.0, -0.4]);
    }

    /// A friction wall engaged by the momentum update holds a re-mapped velocity that separates
    /// (v_n ≥ 0) on the wall; not engaged, it leaves it free; approaching, it acts as `apply`.
    #[test]
    fn engaged_friction_wall_holds_the_remapped_velocity() {
        let w = Wall {
            side: Side::Bottom,
            position: 0.0,
            kind: WallKind::Friction { mu: 0.5 },
        };
        assert!(w.engages([0.3, -0.1]) && !w.engages([0.3, 0.1]));
        let mut v = [0.3, 0.7];
        assert_eq!(w.apply_engaged(&mut v, true), ([0.0, -0.7], [0.0; 2]));
        assert_eq!(v, [0.3, 0.0]);
        let mut v = [0.3, 0.7];
        assert_eq!(w.apply_engaged(&mut v, false), ([0.0; 2], [0.0; 2]));
        assert_eq!(v, [0.3, 0.7]);
        let (mut a, mut b) = ([2.0, -1.0], [2.0, -1.0]);
        assert_eq!(w.apply_engaged(&mut a, true), w.apply(&mut b));
        assert_eq!(a, b);
        let r = Wall {
            side: Side::Left,
            position: 0.0,
            kind: WallKind::Roller,
        };
        assert!(r.engages([1.0, 0.0]));
    }

    /// A platen sets the normal velocity (into the material) and leaves the tangential one;
    /// the reported normal change is what it imposed.
    #[test]
    fn platen_prescribes_the_normal_velocity() {
        let w = Wall {
            side: Side::Top,
            position: 1.0,
            kind: WallKind::Platen { speed: 0.01 },
        };
        let mut v = [0.2, 0.5];
        let (dn, dt) = w.apply(&mut v);
        assert_eq!(v, [0.2, -0.01]);
        assert_eq!((dn, dt), ([0.0, -0.51], [0.0; 2]));
    }
}
