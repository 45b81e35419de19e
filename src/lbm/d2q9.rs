//! The D2Q9 velocity set (seed eq. 5.1, 5.5) and its equilibrium (eq. 5.4, with the `+` the seed
//! drops before the quadratic term).
//!
//! ```text
//!   6   2   5        e₀ = (0,0)
//!     \ | /          e₁ = (1,0)  e₂ = (0,1)  e₃ = (−1,0)  e₄ = (0,−1)
//!   3 — 0 — 1        e₅ = (1,1)  e₆ = (−1,1) e₇ = (−1,−1) e₈ = (1,−1)
//!     / | \
//!   7   4   8        w₀ = 4/9, w₁…₄ = 1/9, w₅…₈ = 1/36
//! ```

/// Number of discrete velocities.
pub const Q: usize = 9;
/// x components of the lattice velocities.
pub const CX: [i32; Q] = [0, 1, 0, -1, 0, 1, -1, -1, 1];
/// y components of the lattice velocities.
pub const CY: [i32; Q] = [0, 0, 1, 0, -1, 1, 1, -1, -1];
/// Lattice weights w_i.
pub const W: [f64; Q] = [
    4.0 / 9.0,
    1.0 / 9.0,
    1.0 / 9.0,
    1.0 / 9.0,
    1.0 / 9.0,
    1.0 / 36.0,
    1.0 / 36.0,
    1.0 / 36.0,
    1.0 / 36.0,
];
/// Index of the opposite direction: e_{OPP[i]} = −e_i.
pub const OPP: [usize; Q] = [0, 3, 4, 1, 2, 7, 8, 5, 6];

/// Second-order equilibrium
/// f_i^eq = w_i ρ [1 + 3 e_i·u + (9/2)(e_i·u)² − (3/2) u·u] (lattice units, c_s² = 1/3).
pub fn equilibrium(rho: f64, ux: f64, uy: f64) -> [f64; Q] {
    let usq = 1.5 * (ux * ux + uy * uy);
    std::array::from_fn(|i| {
        let cu = 3.0 * (CX[i] as f64 * ux + CY[i] as f64 * uy);
        W[i] * rho * (1.0 + cu + 0.5 * cu * cu - usq)
    })
}

/// Density and momentum of a population set: ρ = Σ f_i, j = Σ f_i e_i (seed eq. 5.6).
pub fn moments(f: &[f64; Q]) -> (f64, f64, f64) {
    let mut rho = 0.0;
    let mut jx = 0.0;
    let mut jy = 0.0;
    for i in 0..Q {
        rho += f[i];
        jx += f[i] * CX[i] as f64;
        jy += f[i] * CY[i] as f64;
    }
    (rho, jx, jy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn opposite_directions_are_opposite() {
        for i in 0..Q {
            assert_eq!(CX[OPP[i]], -CX[i]);
            assert_eq!(CY[OPP[i]], -CY[i]);
        }
    }

    #[test]
    fn equilibrium_has_the_right_moments() {
        // Σ f^eq = ρ, Σ f^eq e = ρu, Σ f^eq e_a e_b = ρ/3 δ_ab + ρ u_a u_b (exactly, for D2Q9).
        let (rho, ux, uy) = (1.07, 0.03, -0.05);
        let f = equilibrium(rho, ux, uy);
        let (r, jx, jy) = moments(&f);
        assert_relative_eq!(r, rho, max_relative = 1e-14);
        assert_relative_eq!(jx, rho * ux, max_relative = 1e-13);
        assert_relative_eq!(jy, rho * uy, max_relative = 1e-13);
        let pxx: f64 = (0..Q).map(|i| f[i] * (CX[i] * CX[i]) as f64).sum();
        let pxy: f64 = (0..Q).map(|i| f[i] * (CX[i] * CY[i]) as f64).sum();
        assert_relative_eq!(pxx, rho / 3.0 + rho * ux * ux, max_relative = 1e-13);
        assert_relative_eq!(pxy, rho * ux * uy, max_relative = 1e-12);
    }
}
