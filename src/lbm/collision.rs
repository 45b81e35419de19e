//! Collision operators: BGK and MRT, each optionally with the Smagorinsky sub-grid model,
//! and Guo's forcing term.
//!
//! All operators act on `L` cells at once (`f[i][lane]`), so the lane loop vectorises.
//!
//! **BGK** (seed eq. 5.3) with Guo, Zheng & Shi (2002) forcing:
//!
//! f_i* = f_i − ω (f_i − f_i^eq(ρ, u)) + (1 − ω/2) w_i [3(e_i − u)·F + 9(e_i·u)(e_i·F)],
//! with ρ = Σ f_i, u = (Σ f_i e_i + F/2)/ρ, ω = 1/τ.
//!
//! **MRT** (seed eq. 5.15–5.23; moments and equilibria of Lallemand & Luo 2000):
//! m = M f with m = (ρ, e, ε, j_x, q_x, j_y, q_y, p_xx, p_xy), and
//!
//! m* = m − S (m − m^eq) + (I − S/2) M G,   f* = M⁻¹ m*,
//!
//! e^eq = ρ(−2 + 3|u|²), ε^eq = ρ(1 − 3|u|²), j^eq = ρu, q^eq = −ρu,
//! p_xx^eq = ρ(u_x² − u_y²), p_xy^eq = ρ u_x u_y,
//! S = diag(0, s_e, s_ε, 0, s_q, 0, s_q, s_ν, s_ν), s_ν = 1/τ. The forcing moments M G of Guo's
//! term are (0, 6u·F, −6u·F, F_x, −F_x, F_y, −F_y, 2(u_xF_x − u_yF_y), u_xF_y + u_yF_x).
//! (The seed's printed equilibria 5.21–5.22 are garbled; these are the moments of the
//! equilibrium above, checked in the tests.)
//!
//! **Smagorinsky** (seed eq. 5.37–5.42): ν_t = (C h)² S̄ with S̄ = √(S_ij S_ij). The strain rate
//! is local: S_ij = −Π_ij^neq / (2ρ c_s² τ*), with Π^neq = Σ e_i e_i (f_i − f_i^eq). Solving
//! τ* = τ + 3ν_t for τ* gives τ* = ½ [τ + √(τ² + 18 C² |Π^neq| / ρ)], |Π| = √(Π_ij Π_ij).

use super::d2q9::{Q, W};
use super::real::Real;

/// Relaxation rates of the non-hydrodynamic MRT moments (s_ν comes from τ).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct MrtRates {
    /// Rate of the energy moment e (bulk viscosity).
    pub s_e: f64,
    /// Rate of the energy-square moment ε.
    pub s_eps: f64,
    /// Rate of the energy-flux moments q_x, q_y.
    pub s_q: f64,
}

impl MrtRates {
    /// Lallemand & Luo (2000) rates s_e = 1.64, s_ε = 1.54, with s_q from the "magic"
    /// combination Λ = (1/s_ν − ½)(1/s_q − ½) = 3/16, which puts half-way bounce-back walls
    /// exactly half-way for every τ: s_q = 8(2 − s_ν)/(8 − s_ν).
    pub fn standard(tau: f64) -> Self {
        let s_nu = 1.0 / tau;
        MrtRates {
            s_e: 1.64,
            s_eps: 1.54,
            s_q: 8.0 * (2.0 - s_nu) / (8.0 - s_nu),
        }
    }
}

/// Which collision operator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CollisionModel {
    /// Single relaxation time (Bhatnagar–Gross–Krook).
    Bgk,
    /// Multiple relaxation times in the D2Q9 moment basis.
    Mrt(MrtRates),
}

/// A collision operator with its parameters, in lattice units.
#[derive(Clone, Debug)]
pub struct Collider<T> {
    /// The operator.
    pub model: CollisionModel,
    /// Relaxation time τ of the molecular viscosity.
    pub tau: f64,
    /// Smagorinsky constant C, if LES is on.
    pub smagorinsky: Option<f64>,
    /// Uniform body force density (lattice units), F = ρ g for a gravity-like force.
    pub force: [f64; 2],
    omega: T,
    tau_t: T,
    les_k: T,
    fx: T,
    fy: T,
    s: [T; 3],
}

impl<T: Real> Collider<T> {
    /// A collider for relaxation time `tau`, optional Smagorinsky constant and a uniform
    /// body force density `force` (lattice units).
    pub fn new(model: CollisionModel, tau: f64, smagorinsky: Option<f64>, force: [f64; 2]) -> Self {
        let s = match model {
            CollisionModel::Bgk => [T::zero(); 3],
            CollisionModel::Mrt(r) => [T::c(r.s_e), T::c(r.s_eps), T::c(r.s_q)],
        };
        Collider {
            model,
            tau,
            smagorinsky,
            force,
            omega: T::c(1.0 / tau),
            tau_t: T::c(tau),
            les_k: T::c(18.0 * smagorinsky.unwrap_or(0.0).powi(2)),
            fx: T::c(force[0]),
            fy: T::c(force[1]),
            s,
        }
    }

    /// Collide `L` cells in place.
    #[inline(always)]
    pub fn collide<const L: usize>(&self, f: &mut [[T; L]; Q]) {
        let forced = self.force != [0.0, 0.0];
        match (self.model, self.smagorinsky.is_some(), forced) {
            (CollisionModel::Bgk, false, false) => self.bgk::<L, false, false>(f),
            (CollisionModel::Bgk, false, true) => self.bgk::<L, false, true>(f),
            (CollisionModel::Bgk, true, false) => self.bgk::<L, true, false>(f),
            (CollisionModel::Bgk, true, true) => self.bgk::<L, true, true>(f),
            (CollisionModel::Mrt(_), false, false) => self.mrt::<L, false, false>(f),
            (CollisionModel::Mrt(_), false, true) => self.mrt::<L, false, true>(f),
            (CollisionModel::Mrt(_), true, false) => self.mrt::<L, true, false>(f),
            (CollisionModel::Mrt(_), true, true) => self.mrt::<L, true, true>(f),
        }
    }

    /// Relaxation rate 1/τ*, with τ* from the Smagorinsky model when `LES`.
    #[inline(always)]
    fn rate<const LES: bool>(&self, rho: T, pxx: T, pyy: T, pxy: T) -> T {
        if LES {
            let two = T::c(2.0);
            let pi = (pxx * pxx + pyy * pyy + two * pxy * pxy).sqrt();
            let tau =
                T::c(0.5) * (self.tau_t + (self.tau_t * self.tau_t + self.les_k * pi / rho).sqrt());
            T::one() / tau
        } else {
            self.omega
        }
    }

    /// BGK on `L` lanes. Opposite directions share the even part of the equilibrium,
    /// f_i^eq = w_i ρ (1 − 1.5|u|² + 4.5 (e_i·u)²) ± 3 w_i ρ e_i·u, which halves the work.
    #[inline(always)]
    fn bgk<const L: usize, const LES: bool, const FORCE: bool>(&self, f: &mut [[T; L]; Q]) {
        let (half, one, three, c45, c15, nine) = (
            T::c(0.5),
            T::one(),
            T::c(3.0),
            T::c(4.5),
            T::c(1.5),
            T::c(9.0),
        );
        let third = T::c(1.0 / 3.0);
        let (w0, w1, w5) = (T::c(W[0]), T::c(W[1]), T::c(W[5]));
        let (fx, fy) = if FORCE {
            (self.fx, self.fy)
        } else {
            (T::zero(), T::zero())
        };
        for l in 0..L {
            let g: [T; Q] = [
                f[0][l], f[1][l], f[2][l], f[3][l], f[4][l], f[5][l], f[6][l], f[7][l], f[8][l],
            ];
            let rho = g[0] + g[1] + g[2] + g[3] + g[4] + g[5] + g[6] + g[7] + g[8];
            let jx = g[1] - g[3] + g[5] - g[6] - g[7] + g[8];
            let jy = g[2] - g[4] + g[5] + g[6] - g[7] - g[8];
            let inv = one / rho;
            let (ux, uy) = if FORCE {
                ((jx + half * fx) * inv, (jy + half * fy) * inv)
            } else {
                (jx * inv, jy * inv)
            };
            let omega = if LES {
                let pxx = g[1] + g[3] + g[5] + g[6] + g[7] + g[8] - rho * (third + ux * ux);
                let pyy = g[2] + g[4] + g[5] + g[6] + g[7] + g[8] - rho * (third + uy * uy);
                let pxy = g[5] - g[6] + g[7] - g[8] - rho * ux * uy;
                self.rate::<true>(rho, pxx, pyy, pxy)
            } else {
                self.omega
            };
            let keep = one - omega;
            let base = one - c15 * (ux * ux + uy * uy);
            // ω w_i ρ for the three weight classes, and 3× it for the odd part.
            let (r0, r1, r5) = (omega * w0 * rho, omega * w1 * rho, omega * w5 * rho);
            let (t1, t5) = (three * r1, three * r5);
            f[0][l] = keep * g[0] + r0 * base;
            // (i, ī, e_i·u, ω w ρ, 3 ω w ρ) for the four opposite pairs; fused multiply–adds.
            macro_rules! pair {
                ($i:literal, $o:literal, $cu:expr, $r:expr, $t:expr) => {{
                    let cu = $cu;
                    let even = $r * c45.mul_add(cu * cu, base);
                    let odd = $t * cu;
                    f[$i][l] = keep.mul_add(g[$i], even + odd);
                    f[$o][l] = keep.mul_add(g[$o], even - odd);
                }};
            }
            pair!(1, 3, ux, r1, t1);
            pair!(2, 4, uy, r1, t1);
            pair!(5, 7, ux + uy, r5, t5);
            pair!(6, 8, uy - ux, r5, t5);
            if FORCE {
                // Guo: (1 − ω/2) w_i [3(e_i − u)·F + 9(e_i·u)(e_i·F)].
                let fk = one - half * omega;
                let uf = ux * fx + uy * fy;
                let cu = [
                    T::zero(),
                    ux,
                    uy,
                    -ux,
                    -uy,
                    ux + uy,
                    uy - ux,
                    -ux - uy,
                    ux - uy,
                ];
                let cf = [
                    T::zero(),
                    fx,
                    fy,
                    -fx,
                    -fy,
                    fx + fy,
                    fy - fx,
                    -fx - fy,
                    fx - fy,
                ];
                let w = [w0, w1, w1, w1, w1, w5, w5, w5, w5];
                macro_rules! guo {
                    ($($i:literal),*) => {$(
                        f[$i][l] = f[$i][l] + fk * w[$i] * (three * (cf[$i] - uf) + nine * cu[$i] * cf[$i]);
                    )*};
                }
                guo!(0, 1, 2, 3, 4, 5, 6, 7, 8);
            }
            f[0][l] = rest_from_mass(rho, f, l);
        }
    }

    #[inline(always)]
    fn mrt<const L: usize, const LES: bool, const FORCE: bool>(&self, f: &mut [[T; L]; Q]) {
        let (half, one, two, three, four, six) = (
            T::c(0.5),
            T::one(),
            T::c(2.0),
            T::c(3.0),
            T::c(4.0),
            T::c(6.0),
        );
        let [s_e, s_eps, s_q] = self.s;
        let (fx, fy) = if FORCE {
            (self.fx, self.fy)
        } else {
            (T::zero(), T::zero())
        };
        let (i9, i36, i6, i12, i4) = (
            T::c(1.0 / 9.0),
            T::c(1.0 / 36.0),
            T::c(1.0 / 6.0),
            T::c(1.0 / 12.0),
            T::c(0.25),
        );
        for l in 0..L {
            let g: [T; Q] = std::array::from_fn(|i| f[i][l]);
            let axes = g[1] + g[2] + g[3] + g[4];
            let diag = g[5] + g[6] + g[7] + g[8];
            let rho = g[0] + axes + diag;
            let e = -four * g[0] - axes + two * diag;
            let eps = four * g[0] - two * axes + diag;
            let jx = g[1] - g[3] + g[5] - g[6] - g[7] + g[8];
            let qx = -two * g[1] + two * g[3] + g[5] - g[6] - g[7] + g[8];
            let jy = g[2] - g[4] + g[5] + g[6] - g[7] - g[8];
            let qy = -two * g[2] + two * g[4] + g[5] + g[6] - g[7] - g[8];
            let pxx = g[1] - g[2] + g[3] - g[4];
            let pxy = g[5] - g[6] + g[7] - g[8];

            let inv = one / rho;
            let (ux, uy) = if FORCE {
                ((jx + half * fx) * inv, (jy + half * fy) * inv)
            } else {
                (jx * inv, jy * inv)
            };
            let u2 = ux * ux + uy * uy;
            // Non-equilibrium parts of the moments.
            let e_n = e - rho * (three * u2 - two);
            let eps_n = eps - rho * (one - three * u2);
            let qx_n = qx + rho * ux;
            let qy_n = qy + rho * uy;
            let pxx_n = pxx - rho * (ux * ux - uy * uy);
            let pxy_n = pxy - rho * ux * uy;
            let s_nu = if LES {
                let a = e_n * i6;
                let b = half * pxx_n;
                self.rate::<true>(rho, a + b, a - b, pxy_n)
            } else {
                self.omega
            };
            // Post-collision moments, plus the forcing moments M G when forced.
            let mut e = e - s_e * e_n;
            let mut eps = eps - s_eps * eps_n;
            let mut qx = qx - s_q * qx_n;
            let mut qy = qy - s_q * qy_n;
            let mut pxx = pxx - s_nu * pxx_n;
            let mut pxy = pxy - s_nu * pxy_n;
            let (mut jx, mut jy) = (jx, jy);
            if FORCE {
                let uf = ux * fx + uy * fy;
                e = e + (one - half * s_e) * six * uf;
                eps = eps - (one - half * s_eps) * six * uf;
                jx = jx + fx;
                jy = jy + fy;
                qx = qx - (one - half * s_q) * fx;
                qy = qy - (one - half * s_q) * fy;
                pxx = pxx + (one - half * s_nu) * two * (ux * fx - uy * fy);
                pxy = pxy + (one - half * s_nu) * (ux * fy + uy * fx);
            }
            // f = M⁻¹ m = Mᵀ diag(1/9, 1/36, 1/36, 1/6, 1/12, 1/6, 1/12, 1/4, 1/4) m.
            let a = rho * i9;
            let b = e * i36;
            let c = eps * i36;
            let d = jx * i6;
            let gq = qx * i12;
            let h = jy * i6;
            let k = qy * i12;
            let p = pxx * i4;
            let s = pxy * i4;
            let ax = a - b - two * c;
            let dg = a + two * b + c;
            f[0][l] = a - four * b + four * c;
            f[1][l] = ax + d - two * gq + p;
            f[2][l] = ax + h - two * k - p;
            f[3][l] = ax - d + two * gq + p;
            f[4][l] = ax - h + two * k - p;
            f[5][l] = dg + d + gq + h + k + s;
            f[6][l] = dg - d - gq + h + k - s;
            f[7][l] = dg - d - gq - h - k + s;
            f[8][l] = dg + d + gq - h - k - s;
            f[0][l] = rest_from_mass(rho, f, l);
        }
    }
}

/// f₀* = ρ − Σ_{i≥1} f_i*: collision conserves mass exactly in exact arithmetic; computing the
/// rest population from the others makes it so in floating point too (the rounded weights sum
/// to 1 + δ, δ ≈ −5.6e-17, which otherwise biases the mass by δ every step).
#[inline(always)]
fn rest_from_mass<T: Real, const L: usize>(rho: T, f: &[[T; L]; Q], l: usize) -> T {
    rho - (((f[1][l] + f[2][l]) + (f[3][l] + f[4][l]))
        + ((f[5][l] + f[6][l]) + (f[7][l] + f[8][l])))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lbm::d2q9::{equilibrium, moments, CX, CY};
    use approx::assert_relative_eq;

    /// The D2Q9 moment matrix M (Lallemand & Luo 2000). Seed eq. 5.20 prints the last row
    /// (p_xy) as (0 0 0 0 0 1 1 1 1); the correct row is e_x e_y = (0 0 0 0 0 1 −1 1 −1).
    const M: [[f64; Q]; Q] = [
        [1., 1., 1., 1., 1., 1., 1., 1., 1.],
        [-4., -1., -1., -1., -1., 2., 2., 2., 2.],
        [4., -2., -2., -2., -2., 1., 1., 1., 1.],
        [0., 1., 0., -1., 0., 1., -1., -1., 1.],
        [0., -2., 0., 2., 0., 1., -1., -1., 1.],
        [0., 0., 1., 0., -1., 1., 1., -1., -1.],
        [0., 0., -2., 0., 2., 1., 1., -1., -1.],
        [0., 1., -1., 1., -1., 0., 0., 0., 0.],
        [0., 0., 0., 0., 0., 1., -1., 1., -1.],
    ];

    fn mul(f: &[f64; Q]) -> [f64; Q] {
        std::array::from_fn(|r| (0..Q).map(|i| M[r][i] * f[i]).sum())
    }

    #[test]
    fn mrt_equilibrium_moments_are_moments_of_the_equilibrium() {
        let (rho, ux, uy) = (1.03, 0.04, -0.07);
        let m = mul(&equilibrium(rho, ux, uy));
        let u2 = ux * ux + uy * uy;
        let expect = [
            rho,
            rho * (-2.0 + 3.0 * u2),
            rho * (1.0 - 3.0 * u2),
            rho * ux,
            -rho * ux,
            rho * uy,
            -rho * uy,
            rho * (ux * ux - uy * uy),
            rho * ux * uy,
        ];
        for r in 0..Q {
            assert!(
                (m[r] - expect[r]).abs() < 1e-14,
                "moment {r}: {} vs {}",
                m[r],
                expect[r]
            );
        }
    }

    #[test]
    fn guo_forcing_moments() {
        let (ux, uy, fx, fy) = (0.05, -0.02, 1e-3, 2e-3);
        let g: [f64; Q] = std::array::from_fn(|i| {
            let (cx, cy) = (CX[i] as f64, CY[i] as f64);
            W[i] * (3.0 * ((cx - ux) * fx + (cy - uy) * fy)
                + 9.0 * (cx * ux + cy * uy) * (cx * fx + cy * fy))
        });
        let m = mul(&g);
        let uf = ux * fx + uy * fy;
        let expect = [
            0.0,
            6.0 * uf,
            -6.0 * uf,
            fx,
            -fx,
            fy,
            -fy,
            2.0 * (ux * fx - uy * fy),
            ux * fy + uy * fx,
        ];
        for r in 0..Q {
            assert!(
                (m[r] - expect[r]).abs() < 1e-16,
                "moment {r}: {} vs {}",
                m[r],
                expect[r]
            );
        }
    }

    fn perturbed() -> [f64; Q] {
        let mut f = equilibrium(1.02, 0.05, -0.03);
        for (i, v) in f.iter_mut().enumerate() {
            *v *= 1.0 + 0.01 * ((i * 7 % 5) as f64 - 2.0);
        }
        f
    }

    /// Collision conserves mass and changes momentum by exactly the force, for every operator.
    #[test]
    fn collision_conserves_mass_and_adds_the_force() {
        let force = [1e-4, -3e-4];
        for model in [
            CollisionModel::Bgk,
            CollisionModel::Mrt(MrtRates::standard(0.8)),
        ] {
            for les in [None, Some(0.1)] {
                let f0 = perturbed();
                let c = Collider::<f64>::new(model, 0.8, les, force);
                let mut lanes: [[f64; 1]; Q] = std::array::from_fn(|i| [f0[i]]);
                c.collide(&mut lanes);
                let f1: [f64; Q] = std::array::from_fn(|i| lanes[i][0]);
                let (r0, x0, y0) = moments(&f0);
                let (r1, x1, y1) = moments(&f1);
                assert_relative_eq!(r1, r0, max_relative = 1e-14);
                assert_relative_eq!(x1, x0 + force[0], epsilon = 1e-15);
                assert_relative_eq!(y1, y0 + force[1], epsilon = 1e-15);
            }
        }
    }

    /// With s_e = s_ε = s_q = s_ν = 1/τ, MRT is BGK.
    #[test]
    fn mrt_with_equal_rates_is_bgk() {
        let tau = 0.7;
        let rates = MrtRates {
            s_e: 1.0 / tau,
            s_eps: 1.0 / tau,
            s_q: 1.0 / tau,
        };
        let f0 = perturbed();
        let mut a: [[f64; 1]; Q] = std::array::from_fn(|i| [f0[i]]);
        let mut b = a;
        Collider::<f64>::new(CollisionModel::Bgk, tau, None, [1e-4, 2e-4]).collide(&mut a);
        Collider::<f64>::new(CollisionModel::Mrt(rates), tau, None, [1e-4, 2e-4]).collide(&mut b);
        for i in 0..Q {
            assert_relative_eq!(a[i][0], b[i][0], max_relative = 1e-13);
        }
    }

    /// An equilibrium at rest is a fixed point of every operator without force.
    #[test]
    fn equilibrium_is_a_fixed_point() {
        let f0 = equilibrium(1.0, 0.02, 0.01);
        for model in [
            CollisionModel::Bgk,
            CollisionModel::Mrt(MrtRates::standard(0.6)),
        ] {
            let mut a: [[f64; 1]; Q] = std::array::from_fn(|i| [f0[i]]);
            Collider::<f64>::new(model, 0.6, Some(0.1), [0.0; 2]).collide(&mut a);
            for i in 0..Q {
                assert_relative_eq!(a[i][0], f0[i], max_relative = 1e-13);
            }
        }
    }
}
