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
use crate::lbm::{CoveredCells, Real, UNCOVERED};

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

    /// The partially saturated blend ([`blend`]) with each lane's B and u_s; an uncovered
    /// lane takes B = 0, which leaves it as the fluid collision made it: (1 − 0) C + 0 (…) = C.
    #[inline(always)]
    fn apply<const L: usize>(
        &self,
        entries: &[usize; L],
        g: &[[T; L]; Q],
        post: &mut [[T; L]; Q],
        force: [f64; 2],
    ) -> [[f64; L]; 2] {
        let (mut b, mut us) = ([T::zero(); L], [[T::zero(); L]; 2]);
        for (l, &k) in entries.iter().enumerate() {
            if k != UNCOVERED {
                b[l] = self.b[k];
                us[0][l] = self.ux[k];
                us[1][l] = self.uy[k];
            }
        }
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
/// Evaluated in the populations' precision, arranged so that f32 loses no more than the
/// populations' own rounding (the GPU kernel's [`DEVICE_TERM`] is the same arrangement):
///
/// * the two equilibria's common w_i ρ cancels by hand,
///   f_i^eq(ρ, u_s) − f_ī^eq(ρ, u) = w_i ρ [3 e_i·(u_s + u) + 4.5 ((e_i·u_s)² − (e_i·u)²)
///   − 1.5 (|u_s|² − |u|²)] =: s_i, a small number computed without subtracting O(w_i ρ)
///   terms, so that g_i + Ω_i^s = g_ī + s_i;
/// * the momentum j = Σ g e is summed as differences of opposite populations,
///   j_x = (g₁ − g₃) + (g₅ − g₇) + (g₈ − g₆), each exact in floating point for nearly equal
///   values, and the exchange as B Σ Ω_i^s e_i = B (Σ_i s_i e_i − 2 j).
///
/// Written naively (two full equilibria subtracted in f32), the round-off biased the grain
/// force by about 1 % in the slow flow of `psm-cylinder-array`; this arrangement keeps f32
/// within 1e-5 of the f64 result at u ~ 1e-4 (test `f32_blend_keeps_the_f64_exchange`) and
/// runs the f32 blend on twice the vector lanes of f64.
#[inline(always)]
pub fn blend<T: Real, const L: usize>(
    g: &[[T; L]; Q],
    post: &mut [[T; L]; Q],
    b: &[T; L],
    us: &[[T; L]; 2],
    force: [f64; 2],
) -> [[f64; L]; 2] {
    let (hx, hy) = (T::c(0.5 * force[0]), T::c(0.5 * force[1]));
    let (c15, c3, c45, two) = (T::c(1.5), T::c(3.0), T::c(4.5), T::c(2.0));
    // Lane loops innermost, so they vectorise.
    let z = [T::zero(); L];
    let (mut rho, mut ux, mut uy, mut jx, mut jy, mut du2) = (z, z, z, z, z, z);
    for l in 0..L {
        let f = |i: usize| g[i][l];
        let r = f(0) + f(1) + f(2) + f(3) + f(4) + f(5) + f(6) + f(7) + f(8);
        let mx = (f(1) - f(3)) + (f(5) - f(7)) + (f(8) - f(6));
        let my = (f(2) - f(4)) + (f(5) - f(7)) + (f(6) - f(8));
        rho[l] = r;
        jx[l] = mx;
        jy[l] = my;
        ux[l] = (mx + hx) / r;
        uy[l] = (my + hy) / r;
        let (sx, sy) = (us[0][l], us[1][l]);
        du2[l] = c15 * ((sx * sx + sy * sy) - (ux[l] * ux[l] + uy[l] * uy[l]));
    }
    let (mut ax, mut ay) = (z, z);
    for i in 0..Q {
        let o = OPP[i];
        let (cx, cy, w) = (T::c(CX[i] as f64), T::c(CY[i] as f64), T::c(W[i]));
        for l in 0..L {
            let cu = cx * ux[l] + cy * uy[l];
            let cs = cx * us[0][l] + cy * us[1][l];
            let s = w * rho[l] * (c3 * (cs + cu) + c45 * (cs * cs - cu * cu) - du2[l]);
            post[i][l] = (T::one() - b[l]) * post[i][l] + b[l] * (g[o][l] + s);
            ax[l] = ax[l] + cx * s;
            ay[l] = ay[l] + cy * s;
        }
    }
    [
        std::array::from_fn(|l| (b[l] * (ax[l] - two * jx[l])).f64()),
        std::array::from_fn(|l| (b[l] * (ay[l] - two * jy[l])).f64()),
    ]
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

    /// In f32 the blend keeps the exchange of the f64 blend in a slow flow (u ~ 1e-4, where
    /// the exchange is ~1e-5 and the populations ~0.1): relative error below 1e-5. Two full
    /// equilibria subtracted in f32 miss by 4e-5 to 6e-5 here (round-off of w ρ, 6e-8 of ~0.1
    /// per direction).
    #[test]
    fn f32_blend_keeps_the_f64_exchange() {
        let mut f0 = equilibrium(1.001, 1.2e-4, -0.7e-4);
        for (i, v) in f0.iter_mut().enumerate() {
            *v += 1e-7 * ((i * 5 % 7) as f64 - 3.0);
        }
        // The f32 populations, exactly, in both precisions.
        let g32: [[f32; 1]; Q] = std::array::from_fn(|i| [f0[i] as f32]);
        let g64: [[f64; 1]; Q] = std::array::from_fn(|i| [g32[i][0] as f64]);
        let (b, us, force) = (0.37, [2.1e-4, 0.6e-4], [3e-7, -1e-7]);
        let c32 = Collider::<f32>::new(CollisionModel::Bgk, 0.9, None, force);
        let c64 = Collider::<f64>::new(CollisionModel::Bgk, 0.9, None, force);
        let (mut p32, mut p64) = (g32, g64);
        c32.collide(&mut p32);
        c64.collide(&mut p64);
        let d32 = blend(
            &g32,
            &mut p32,
            &[b as f32],
            &[[us[0] as f32], [us[1] as f32]],
            force,
        );
        let d64 = blend(&g64, &mut p64, &[b], &[[us[0]], [us[1]]], force);
        for k in 0..2 {
            let rel = ((d32[k][0] - d64[k][0]) / d64[k][0]).abs();
            assert!(
                rel < 1e-5,
                "exchange {k}: f32 {} vs f64 {} ({rel:e})",
                d32[k][0],
                d64[k][0]
            );
        }
        for i in 0..Q {
            assert_relative_eq!(p32[i][0] as f64, p64[i][0], max_relative = 1e-6);
        }
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
