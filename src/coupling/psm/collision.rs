//! Partially saturated cells (Noble & Torczynski 1998; seed eq. 5.53–5.54): lattice nodes
//! covered by a fraction ε of a moving solid.
//!
//! Such a node stays a fluid node. Its collision blends the fluid collision with a "solid"
//! collision that drives the node towards the solid velocity u_s:
//!
//! f_i* = f_i − (1 − B)(f_i − C(f)_i) + B Ω_i^s,
//! Ω_i^s = [f_ī − f_ī^eq(ρ, u)] − [f_i − f_i^eq(ρ, u_s)],
//!
//! where C(f) is the fluid collision of [`crate::lbm::collision`] (BGK or MRT, with or without LES
//! and Guo forcing, so the fluid part of a partial node behaves exactly as in a plain node)
//! and B is Noble & Torczynski's weighting of the solid fraction,
//!
//! B(ε, τ) = ε (τ − ½) / ((1 − ε) + (τ − ½)),
//!
//! with τ the molecular relaxation time. B = 0 is a plain fluid node; B = 1 sets the
//! post-collision momentum to ρ u_s (full no-slip). The momentum the solid term gives the
//! fluid at node n in one step, Δp_n = B Σ_i Ω_i^s e_i, is accumulated per node; the force on
//! the solid is its negative (seed eq. 5.53, with C h = 1 in lattice units), and its torque
//! (x_n − x_c) × (−Δp_n) (eq. 5.54). Σ_i Ω_i^s = 0, so the solid term conserves mass.

use crate::lbm::collision::Collider;
use crate::lbm::d2q9::{equilibrium, CX, CY, OPP, Q, W};
use crate::lbm::{CoveredCells, Real};

/// The blend on the GPU: the lattice kernel's covered-cells term, (B, u_s,x, u_s,y) per cell
/// ([`PartialCells::device_values`]). In the kernel's precision, with Ω^s rearranged so that
/// f32 keeps the digits the CPU keeps in f64 (see the source).
#[cfg(feature = "gpu")]
pub const DEVICE_TERM: crate::lbm::gpu::CoveredTerm = crate::lbm::gpu::CoveredTerm {
    source: include_str!("collision.wgsl"),
    values: 3,
};

/// Noble & Torczynski's weighting B(ε, τ) = ε(τ − ½)/((1 − ε) + (τ − ½)) of the solid
/// fraction ε ∈ [0, 1] (clamped) for relaxation time τ.
pub fn weighting(eps: f64, tau: f64) -> f64 {
    let e = eps.clamp(0.0, 1.0);
    let t = tau - 0.5;
    e * t / ((1.0 - e) + t)
}

/// The partially covered cells of a lattice for one step, structure of arrays; the lattice
/// collides them through [`CoveredCells`].
///
/// `cells` must be sorted ascending and free of duplicates; the other arrays run parallel to
/// it.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct PartialCells<T> {
    /// Cell indices y·nx + x, ascending.
    pub cells: Vec<u32>,
    /// Weighting B per cell.
    pub b: Vec<T>,
    /// Solid velocity x per cell (lattice units).
    pub ux: Vec<T>,
    /// Solid velocity y per cell (lattice units).
    pub uy: Vec<T>,
}

impl<T: Real> PartialCells<T> {
    /// No covered cells.
    pub fn new() -> Self {
        PartialCells {
            cells: Vec::new(),
            b: Vec::new(),
            ux: Vec::new(),
            uy: Vec::new(),
        }
    }

    /// Number of covered cells.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// True when no cell is covered (the lattice then takes its plain fluid step).
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Remove all cells, keeping the buffers.
    pub fn clear(&mut self) {
        self.cells.clear();
        self.b.clear();
        self.ux.clear();
        self.uy.clear();
    }

    /// The values of [`DEVICE_TERM`]: (B, u_x, u_y) per cell, cell after cell.
    #[cfg(feature = "gpu")]
    pub fn device_values(&self) -> Vec<T> {
        (0..self.len())
            .flat_map(|k| [self.b[k], self.ux[k], self.uy[k]])
            .collect()
    }

    /// Append a cell (call in ascending cell order).
    pub fn push(&mut self, cell: u32, b: f64, u: [f64; 2]) {
        debug_assert!(
            self.cells.last().is_none_or(|&l| l < cell),
            "cells not ascending"
        );
        self.cells.push(cell);
        self.b.push(T::c(b));
        self.ux.push(T::c(u[0]));
        self.uy.push(T::c(u[1]));
    }
}

impl<T: Real> CoveredCells<T> for PartialCells<T> {
    fn cells(&self) -> &[u32] {
        &self.cells
    }

    /// A fully covered cell (B = 1) takes f* = g + Ω^s: its fluid collision has weight 1 − B = 0.
    fn replaces_collision(&self, k: usize) -> bool {
        self.b[k] == T::c(1.0)
    }

    /// The partially saturated blend ([`blend`]) with each lane's B and u_s.
    #[inline(always)]
    fn apply<const L: usize>(
        &self,
        entries: &[usize; L],
        g: &[[T; L]; Q],
        post: &mut [[T; L]; Q],
        force: [f64; 2],
    ) -> [[f64; L]; 2] {
        let b: [T; L] = std::array::from_fn(|l| self.b[entries[l]]);
        let us: [[T; L]; 2] = [
            std::array::from_fn(|l| self.ux[entries[l]]),
            std::array::from_fn(|l| self.uy[entries[l]]),
        ];
        blend(g, post, &b, &us, force)
    }
}

/// Collide one partially saturated node: pre-collision populations `f`, weighting `b`, solid
/// velocity `us` (lattice units). Returns the post-collision populations and the momentum
/// B Σ Ω_i^s e_i the solid term gave the fluid.
#[inline]
pub fn collide<T: Real>(
    f: &[T; Q],
    b: T,
    us: [T; 2],
    collider: &Collider<T>,
) -> ([T; Q], [f64; 2]) {
    let mut lane: [[T; 1]; Q] = std::array::from_fn(|i| [f[i]]);
    collider.collide(&mut lane);
    let g: [f64; Q] = std::array::from_fn(|i| f[i].f64());
    let (mut rho, mut jx, mut jy) = (0.0, 0.0, 0.0);
    for i in 0..Q {
        rho += g[i];
        jx += g[i] * CX[i] as f64;
        jy += g[i] * CY[i] as f64;
    }
    // The fluid velocity as the collision operator defines it, u = (Σ f e + F/2)/ρ.
    let [fx, fy] = collider.force;
    let (ux, uy) = ((jx + 0.5 * fx) / rho, (jy + 0.5 * fy) / rho);
    let feq = equilibrium(rho, ux, uy);
    let feq_s = equilibrium(rho, us[0].f64(), us[1].f64());
    let bb = b.f64();
    let mut out = [T::zero(); Q];
    let mut dp = [0.0; 2];
    for i in 0..Q {
        let o = OPP[i];
        let omega_s = (g[o] - feq[o]) - (g[i] - feq_s[i]);
        let fc = lane[i][0].f64();
        out[i] = T::c((1.0 - bb) * fc + bb * (g[i] + omega_s));
        dp[0] += bb * omega_s * CX[i] as f64;
        dp[1] += bb * omega_s * CY[i] as f64;
    }
    (out, dp)
}

/// The partially saturated blend on `L` lanes: `g` are the pre-collision populations, `post`
/// holds the fluid collision C(g) on entry and f* = (1 − B) C(g) + B (g + Ω^s) on return;
/// `force` is the body force the collision used (for u = (Σ f e + F/2)/ρ). Returns the
/// momentum B Σ Ω_i^s e_i the solid term gave each lane. Same as [`collide`], on lanes.
///
/// The blend is evaluated in f64 for either precision: Ω^s is a difference of nearly equal
/// populations, and in f32 its round-off would bias the force in slow (Stokes) flows by
/// about 1 % (measured on `psm-cylinder-array`).
#[inline(always)]
pub fn blend<T: Real, const L: usize>(
    g: &[[T; L]; Q],
    post: &mut [[T; L]; Q],
    b: &[T; L],
    us: &[[T; L]; 2],
    force: [f64; 2],
) -> [[f64; L]; 2] {
    let [fx, fy] = force;
    // Lane loops innermost, so they vectorise.
    let mut f = [[0.0f64; L]; Q];
    for i in 0..Q {
        for l in 0..L {
            f[i][l] = g[i][l].f64();
        }
    }
    let (mut ux, mut uy, mut rho) = ([0.0; L], [0.0; L], [0.0; L]);
    let (mut bu, mut bs, mut bl) = ([0.0; L], [0.0; L], [0.0; L]);
    let (mut sx, mut sy) = ([0.0; L], [0.0; L]);
    for l in 0..L {
        let r =
            f[0][l] + f[1][l] + f[2][l] + f[3][l] + f[4][l] + f[5][l] + f[6][l] + f[7][l] + f[8][l];
        let jx = f[1][l] - f[3][l] + f[5][l] - f[6][l] - f[7][l] + f[8][l];
        let jy = f[2][l] - f[4][l] + f[5][l] + f[6][l] - f[7][l] - f[8][l];
        rho[l] = r;
        ux[l] = (jx + 0.5 * fx) / r;
        uy[l] = (jy + 0.5 * fy) / r;
        sx[l] = us[0][l].f64();
        sy[l] = us[1][l].f64();
        bu[l] = 1.0 - 1.5 * (ux[l] * ux[l] + uy[l] * uy[l]);
        bs[l] = 1.0 - 1.5 * (sx[l] * sx[l] + sy[l] * sy[l]);
        bl[l] = b[l].f64();
    }
    let mut dp = [[0.0; L]; 2];
    for i in 0..Q {
        let o = OPP[i];
        let (cx, cy, w) = (CX[i] as f64, CY[i] as f64, W[i]);
        for l in 0..L {
            // f_ī^eq(ρ, u) uses e_ī = −e_i; f_i^eq(ρ, u_s).
            let cu = cx * ux[l] + cy * uy[l];
            let cs = cx * sx[l] + cy * sy[l];
            let feq_o = w * rho[l] * (bu[l] - 3.0 * cu + 4.5 * cu * cu);
            let feq_s = w * rho[l] * (bs[l] + 3.0 * cs + 4.5 * cs * cs);
            let omega_s = (f[o][l] - feq_o) - (f[i][l] - feq_s);
            post[i][l] = T::c((1.0 - bl[l]) * post[i][l].f64() + bl[l] * (f[i][l] + omega_s));
            dp[0][l] += bl[l] * omega_s * cx;
            dp[1][l] += bl[l] * omega_s * cy;
        }
    }
    dp
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lbm::collision::{CollisionModel, MrtRates};
    use crate::lbm::d2q9::moments;
    use approx::assert_relative_eq;

    fn perturbed() -> [f64; Q] {
        let mut f = equilibrium(1.02, 0.05, -0.03);
        for (i, v) in f.iter_mut().enumerate() {
            *v *= 1.0 + 0.01 * ((i * 7 % 5) as f64 - 2.0);
        }
        f
    }

    #[test]
    fn weighting_limits() {
        // B(0) = 0, B(1) = 1 for every τ; at τ = 1 and ε = ½: B = ½·½/(½ + ½) = ¼.
        for tau in [0.6, 1.0, 2.0] {
            assert_eq!(weighting(0.0, tau), 0.0);
            assert_relative_eq!(weighting(1.0, tau), 1.0, max_relative = 1e-15);
        }
        assert_relative_eq!(weighting(0.5, 1.0), 0.25, max_relative = 1e-15);
        // Monotone in ε.
        let mut last = -1.0;
        for k in 0..=100 {
            let b = weighting(k as f64 / 100.0, 0.8);
            assert!(b > last);
            last = b;
        }
    }

    /// B = 0 is the fluid collision; every B conserves mass; B = 1 sets the post-collision
    /// momentum to ρ u_s (without body force); the reported exchange is the momentum change
    /// beyond the fluid collision's.
    #[test]
    fn limits_and_conservation() {
        let f0 = perturbed();
        let (rho, jx0, jy0) = moments(&f0);
        let us = [0.02, -0.01];
        for model in [
            CollisionModel::Bgk,
            CollisionModel::Mrt(MrtRates::standard(0.8)),
        ] {
            for les in [None, Some(0.1)] {
                let c = Collider::<f64>::new(model, 0.8, les, [0.0; 2]);
                let mut plain: [[f64; 1]; Q] = std::array::from_fn(|i| [f0[i]]);
                c.collide(&mut plain);
                let (f, dp) = collide(&f0, 0.0, us, &c);
                for i in 0..Q {
                    assert_relative_eq!(f[i], plain[i][0], max_relative = 1e-15);
                }
                assert_eq!(dp, [0.0, 0.0]);
                for b in [0.3, 1.0] {
                    let (f, dp) = collide(&f0, b, us, &c);
                    let (r, jx, jy) = moments(&f);
                    assert_relative_eq!(r, rho, max_relative = 1e-14);
                    // Fluid collision conserves momentum, so the change is the exchange.
                    assert_relative_eq!(jx - jx0, dp[0], epsilon = 1e-15);
                    assert_relative_eq!(jy - jy0, dp[1], epsilon = 1e-15);
                    if b == 1.0 {
                        assert_relative_eq!(jx, rho * us[0], epsilon = 1e-15);
                        assert_relative_eq!(jy, rho * us[1], epsilon = 1e-15);
                    }
                }
            }
        }
    }

    /// The vectorised blend gives the scalar result.
    #[test]
    fn blend_matches_collide() {
        let f0 = perturbed();
        let c = Collider::<f64>::new(CollisionModel::Bgk, 0.8, None, [1e-4, -2e-4]);
        let (f1, dp1) = collide(&f0, 0.4, [0.02, 0.01], &c);
        let g: [[f64; 1]; Q] = std::array::from_fn(|i| [f0[i]]);
        let mut post = g;
        c.collide(&mut post);
        let dp = blend(&g, &mut post, &[0.4], &[[0.02], [0.01]], c.force);
        for i in 0..Q {
            assert_relative_eq!(post[i][0], f1[i], max_relative = 1e-13);
        }
        assert_relative_eq!(dp[0][0], dp1[0], epsilon = 1e-16);
        assert_relative_eq!(dp[1][0], dp1[1], epsilon = 1e-16);
    }

    /// A node at the solid's equilibrium is left alone by the solid term.
    #[test]
    fn solid_equilibrium_is_a_fixed_point() {
        let us = [0.03, 0.01];
        let f0 = equilibrium(1.0, us[0], us[1]);
        let c = Collider::<f64>::new(CollisionModel::Bgk, 0.7, None, [0.0; 2]);
        let (f, dp) = collide(&f0, 0.6, us, &c);
        for i in 0..Q {
            assert_relative_eq!(f[i], f0[i], max_relative = 1e-14);
        }
        assert!(dp[0].abs() < 1e-16 && dp[1].abs() < 1e-16);
    }
}
