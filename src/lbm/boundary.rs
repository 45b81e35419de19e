//! Boundary conditions on the domain edges and the Zou–He closure.
//!
//! **Half-way bounce-back** (seed eq. 5.24): a population e_i leaving fluid node x towards a
//! wall or solid node returns as e_ī at x one step later, so the wall sits half-way between the
//! nodes: f_ī(x, t+1) = f_i*(x, t) − 2 w_i ρ₀ (e_i·u_w)/c_s², the last term for a wall moving at
//! u_w (Ladd 1994). Domain edges of type [`Edge::Wall`] put the wall on the domain boundary, half a
//! cell outside the first row of nodes.
//!
//! **Zou–He** (seed eq. 5.25–5.29): on a velocity or pressure edge the populations coming from
//! outside are unknown. With inward normal n, mass and normal momentum give
//! ρ (1 − u·n) = Σ_known f_i (1 − e_i·n) (eq. 5.28 in general form), from which ρ (velocity
//! edge) or u·n (pressure edge, tangential velocity zero) follows. Each unknown is first set by
//! bounce-back of its non-equilibrium part, f_i = f_ī + 6 w_i ρ e_i·u, and then corrected by
//! δ_i = λ + μ (e_i·t) with the smallest Σ δ_i² that restores mass and tangential momentum
//! exactly. On a straight edge this is eq. 5.29 exactly; at the corner of a Zou–He edge and a
//! wall the diagonal that crosses the wall is bounced back and the remaining unknowns take up
//! the correction, which is the corner treatment of eq. 5.30–5.33 for half-way walls.

use super::d2q9::{CX, CY, OPP, Q, W};
use super::real::Real;

/// Condition on one edge of the rectangular domain, in lattice units.
#[derive(Clone, Debug, PartialEq)]
pub enum Edge {
    /// Wrapped onto the opposite edge (which must be periodic too).
    Periodic,
    /// Half-way bounce-back wall moving tangentially at the given lattice velocity.
    Wall {
        /// Wall velocity (lattice units).
        velocity: [f64; 2],
    },
    /// Zou–He velocity inlet/outlet: one lattice velocity per edge node (bottom→top or left→right).
    Velocity(Vec<[f64; 2]>),
    /// Zou–He pressure inlet/outlet at the given lattice density.
    Pressure(f64),
}

impl Edge {
    /// Is this a Zou–He edge?
    pub fn is_zou_he(&self) -> bool {
        matches!(self, Edge::Velocity(_) | Edge::Pressure(_))
    }
}

/// The four edges of the domain.
#[derive(Clone, Debug, PartialEq)]
pub struct Edges {
    /// x = 0.
    pub left: Edge,
    /// x = L_x.
    pub right: Edge,
    /// y = 0.
    pub bottom: Edge,
    /// y = L_y.
    pub top: Edge,
}

impl Edges {
    /// All four edges periodic.
    pub fn periodic() -> Self {
        Edges {
            left: Edge::Periodic,
            right: Edge::Periodic,
            bottom: Edge::Periodic,
            top: Edge::Periodic,
        }
    }

    /// Resting walls on all four edges (a closed box, e.g. a tank).
    pub fn closed() -> Self {
        let wall = Edge::Wall { velocity: [0.0; 2] };
        Edges {
            left: wall.clone(),
            right: wall.clone(),
            bottom: wall.clone(),
            top: wall,
        }
    }

    /// Periodic in x, resting walls at the bottom and top (a channel).
    pub fn channel() -> Self {
        let wall = Edge::Wall { velocity: [0.0; 2] };
        Edges {
            left: Edge::Periodic,
            right: Edge::Periodic,
            bottom: wall.clone(),
            top: wall,
        }
    }

    /// Checks that periodic edges come in pairs and that no two Zou–He edges meet at a corner.
    /// Returns the name of the offending edge pair and the reason.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        let pairs = [
            ("left/right", &self.left, &self.right),
            ("bottom/top", &self.bottom, &self.top),
        ];
        for (name, a, b) in pairs {
            if (*a == Edge::Periodic) != (*b == Edge::Periodic) {
                return Err((
                    name,
                    "a periodic edge needs a periodic opposite edge".into(),
                ));
            }
        }
        for (x, xn) in [(&self.left, "left"), (&self.right, "right")] {
            for (y, yn) in [(&self.bottom, "bottom"), (&self.top, "top")] {
                if x.is_zou_he() && y.is_zou_he() {
                    return Err((
                        "corner",
                        format!(
                            "edges `{xn}` and `{yn}` are both Zou-He; a corner between two \
                             Zou-He edges is undetermined: make one of them a wall"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// What lies across one link of a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Neighbour {
    /// A fluid node, by cell index.
    Fluid(u32),
    /// A wall or solid node: half-way bounce-back with wall velocity number `k`
    /// (0 is at rest; see [`Lattice`](super::lattice::Lattice)'s wall table).
    Bounce(u16),
    /// Outside a Zou–He edge: incoming population unknown, outgoing one leaves.
    Open,
}

/// The prescribed value on a Zou–He node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ZouHe {
    /// Velocity (lattice units).
    Velocity([f64; 2]),
    /// Density (lattice units).
    Pressure(f64),
}

/// A Zou–He node: inward normal and prescribed value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZouHeNode {
    /// Inward unit normal (axis-aligned).
    pub normal: [i32; 2],
    /// What is prescribed.
    pub value: ZouHe,
}

/// Fill the unknown populations (bit `i` of `unknown` set) of a Zou–He node; see module docs.
///
/// `shift` is F/2, half the body force: with Guo forcing the velocity is (Σ f e + F/2)/ρ, so the
/// closure imposes the momentum j = ρu − F/2 (zero body force: j = ρu).
pub fn zou_he<T: Real>(f: &mut [T; Q], unknown: u16, node: &ZouHeNode, shift: [f64; 2]) {
    let [nx, ny] = node.normal;
    let (n, t) = ([nx as f64, ny as f64], [-ny as f64, nx as f64]);
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    let cn = |i: usize| CX[i] * nx + CY[i] * ny;
    let ct = |i: usize| CX[i] as f64 * t[0] + CY[i] as f64 * t[1];
    let is_unknown = |i: usize| unknown & (1 << i) != 0;
    // Mass and normal momentum of the unknowns coincide (all have e·n = 1):
    // ρ − Σ_known f = j·n − Σ_known f e·n, i.e. S = Σ_known f (1 − e·n) = ρ − j·n.
    let s: f64 = (0..Q)
        .filter(|&i| !is_unknown(i))
        .map(|i| f[i].f64() * (1 - cn(i)) as f64)
        .sum();
    let (rho, j) = match node.value {
        ZouHe::Velocity(u) => {
            let rho = (s - dot(shift, n)) / (1.0 - dot(u, n));
            (rho, [rho * u[0] - shift[0], rho * u[1] - shift[1]])
        }
        ZouHe::Pressure(rho) => {
            let (jn, jt) = (rho - s, -dot(shift, t));
            (rho, [jn * n[0] + jt * t[0], jn * n[1] + jt * t[1]])
        }
    };
    let mut g: [f64; Q] = std::array::from_fn(|i| f[i].f64());
    for i in (0..Q).filter(|&i| is_unknown(i)) {
        g[i] = g[OPP[i]] + 6.0 * W[i] * (CX[i] as f64 * j[0] + CY[i] as f64 * j[1]);
    }
    // Residuals of mass and tangential momentum, removed by δ_i = λ + μ t_i.
    let r_m = rho - g.iter().sum::<f64>();
    let r_t = dot(j, t) - (0..Q).map(|i| g[i] * ct(i)).sum::<f64>();
    let (mut k, mut st, mut stt) = (0.0, 0.0, 0.0);
    for i in (0..Q).filter(|&i| is_unknown(i)) {
        k += 1.0;
        st += ct(i);
        stt += ct(i) * ct(i);
    }
    let det = k * stt - st * st;
    let (lambda, mu) = if det.abs() > 1e-12 {
        ((r_m * stt - r_t * st) / det, (k * r_t - st * r_m) / det)
    } else {
        (r_m / k.max(1.0), 0.0)
    };
    for i in (0..Q).filter(|&i| is_unknown(i)) {
        f[i] = T::c(g[i] + lambda + mu * ct(i));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lbm::d2q9::{equilibrium, moments};
    use approx::assert_relative_eq;

    /// On a straight left edge the closure is seed eq. 5.29 (velocity form).
    #[test]
    fn left_velocity_edge_matches_zou_he() {
        let (ux, uy) = (0.04, 0.01);
        let mut f = equilibrium(1.01, 0.035, 0.012);
        f[3] += 1e-3;
        f[2] -= 2e-3;
        let unknown = (1 << 1) | (1 << 5) | (1 << 8);
        let mut g = f;
        zou_he(
            &mut g,
            unknown,
            &ZouHeNode {
                normal: [1, 0],
                value: ZouHe::Velocity([ux, uy]),
            },
            [0.0; 2],
        );
        let rho = (f[0] + f[2] + f[4] + 2.0 * (f[3] + f[6] + f[7])) / (1.0 - ux);
        assert_relative_eq!(g[1], f[3] + 2.0 / 3.0 * rho * ux, max_relative = 1e-13);
        assert_relative_eq!(
            g[5],
            f[7] - 0.5 * (f[2] - f[4]) + rho * ux / 6.0 + rho * uy / 2.0,
            max_relative = 1e-13
        );
        assert_relative_eq!(
            g[8],
            f[6] + 0.5 * (f[2] - f[4]) + rho * ux / 6.0 - rho * uy / 2.0,
            max_relative = 1e-13
        );
        let (r, jx, jy) = moments(&g);
        assert_relative_eq!(r, rho, max_relative = 1e-13);
        assert_relative_eq!(jx, rho * ux, max_relative = 1e-12);
        assert_relative_eq!(jy, rho * uy, max_relative = 1e-11);
    }

    /// Pressure edge on the right: prescribed density, zero tangential velocity (eq. 5.25–5.29
    /// mirrored).
    #[test]
    fn right_pressure_edge_gives_the_density() {
        let mut f = equilibrium(0.99, 0.05, 0.0);
        f[2] += 1e-3;
        let unknown = (1 << 3) | (1 << 6) | (1 << 7);
        zou_he(
            &mut f,
            unknown,
            &ZouHeNode {
                normal: [-1, 0],
                value: ZouHe::Pressure(1.0),
            },
            [0.0; 2],
        );
        let (r, _, jy) = moments(&f);
        assert_relative_eq!(r, 1.0, max_relative = 1e-14);
        assert!(jy.abs() < 1e-15);
    }

    /// Corner of a left velocity edge and a bottom wall: f_5 comes from the wall, f_1 and f_8
    /// are unknown, and the node still carries the prescribed velocity and conserves mass.
    #[test]
    fn corner_node_with_bounced_diagonal() {
        let (ux, uy) = (0.02, 0.0);
        let mut f = equilibrium(1.0, 0.02, 0.001);
        f[4] += 5e-4;
        let unknown = (1 << 1) | (1 << 8);
        zou_he(
            &mut f,
            unknown,
            &ZouHeNode {
                normal: [1, 0],
                value: ZouHe::Velocity([ux, uy]),
            },
            [0.0; 2],
        );
        let (r, jx, jy) = moments(&f);
        assert_relative_eq!(jx / r, ux, max_relative = 1e-12);
        assert!((jy / r - uy).abs() < 1e-14);
    }

    /// With a body force F the closure imposes (Σ f e + F/2)/ρ = u.
    #[test]
    fn velocity_edge_with_body_force() {
        let (u, force) = ([0.03, 0.01], [2e-4, -1e-4]);
        let mut f = equilibrium(1.0, 0.03, 0.0);
        let unknown = (1 << 1) | (1 << 5) | (1 << 8);
        let node = ZouHeNode {
            normal: [1, 0],
            value: ZouHe::Velocity(u),
        };
        zou_he(&mut f, unknown, &node, [0.5 * force[0], 0.5 * force[1]]);
        let (r, jx, jy) = moments(&f);
        assert_relative_eq!((jx + 0.5 * force[0]) / r, u[0], max_relative = 1e-12);
        assert_relative_eq!((jy + 0.5 * force[1]) / r, u[1], max_relative = 1e-12);
    }

    #[test]
    fn edge_checks() {
        let mut e = Edges::periodic();
        assert!(e.check().is_ok());
        e.left = Edge::Pressure(1.0);
        assert!(e.check().is_err());
        e.right = Edge::Pressure(1.0);
        e.bottom = Edge::Velocity(vec![[0.0; 2]; 4]);
        e.top = Edge::Wall { velocity: [0.0; 2] };
        assert_eq!(e.check().unwrap_err().0, "corner");
    }
}
