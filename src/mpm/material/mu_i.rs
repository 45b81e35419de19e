//! Mohr–Coulomb with a rate-dependent friction angle: the μ(I) rheology of dense granular
//! flow (GDR MiDi 2004; Jop, Forterre & Pouliquen 2006) in the plane-strain Mohr–Coulomb of
//! [`super::mohr_coulomb`], as Dunatunga & Kamrin (2015) put μ(I) in an MPM.
//!
//! Each update takes the friction angle of the point's inertial number,
//!
//! sin φ(I) = sin φ_s + (sin φ_2 − sin φ_s)/(I_0/I + 1),  I = min(γ̇ d/√(p/ρ_s), I_max),
//!
//! with γ̇ = √((Δε_xx − Δε_yy)² + (2Δε_xy)²)/Δt the largest in-plane shear strain rate (γ̇ of a
//! simple shear), p = −(σ_xx + σ_yy)/2 the in-plane pressure at the start of the step, d the
//! grain diameter and ρ_s the grain density; a stress-free point (p ≤ 0) takes I = I_max.
//! I_max is the end of the dense-flow range in which the law was measured: beyond I ≈ 0.5 the
//! DEM's shear cell is a granular gas (normal-stress ratio σ_xx/σ_yy 2–6, coordination < 0.2)
//! whose friction stops rising, so the fit is not carried past it. sin φ is
//! the 2-D Mohr–Coulomb friction (σ₁ − σ₃)/(σ₁ + σ₃), the quantity the DEM's periodic shear
//! cell measures (`granflow shear`, [`crate::scenario::dem::shear`]), so its fitted law can be used as
//! it is. At I → 0 this is the rate-independent Mohr–Coulomb of angle φ_s; the dilatancy
//! angle, cohesion and tension cut-off are as there.

use super::mohr_coulomb::MohrCoulomb;
use super::{Failure, Material, MaterialState, Strain, Stress};

/// The μ(I) Mohr–Coulomb material.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct MuIMohrCoulomb {
    /// The rate-independent material at φ_s (elasticity, ψ, c, σ_t and the I → 0 limit).
    base: MohrCoulomb,
    sin_s: f64,
    sin_2: f64,
    i_0: f64,
    /// I_max: I is held at it above (and for a stress-free point).
    i_max: f64,
    /// d √ρ_s, so that I = γ̇ d √ρ_s/√p.
    d_sqrt_rho: f64,
}

impl MuIMohrCoulomb {
    /// From the rate-independent material at φ_s, the angle φ_2 (rad, φ_s ≤ φ_2 < π/2), I_0
    /// and I_max (> 0), the grain diameter d (m) and grain density ρ_s (kg/m³); the scenario
    /// checks the ranges.
    pub fn new(
        base: MohrCoulomb,
        phi_2: f64,
        [i_0, i_max]: [f64; 2],
        diameter: f64,
        grain_density: f64,
    ) -> Self {
        MuIMohrCoulomb {
            sin_s: base.friction_angle().sin(),
            sin_2: phi_2.sin(),
            base,
            i_0,
            i_max,
            d_sqrt_rho: diameter * grain_density.sqrt(),
        }
    }

    /// The rate-independent material at φ_s.
    pub fn base(&self) -> &MohrCoulomb {
        &self.base
    }

    /// Inertial number of a step with strain increment `de` over `dt` from stress `s`.
    #[inline]
    pub fn inertial_number(&self, s: &Stress, de: &Strain, dt: f64) -> f64 {
        let p = -0.5 * (s[0] + s[1]);
        let g = ((de[0] - de[1]).powi(2) + 4.0 * de[2] * de[2]).sqrt() / dt;
        if p > 0.0 {
            g * self.d_sqrt_rho / p.sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// sin φ(I) (module doc), I held at I_max above it (also I = ∞).
    #[inline]
    pub fn sin_phi(&self, i: f64) -> f64 {
        let i = i.min(self.i_max);
        self.sin_s + (self.sin_2 - self.sin_s) * i / (i + self.i_0)
    }
}

impl Material for MuIMohrCoulomb {
    type State = MaterialState;
    #[inline(always)]
    fn update_stress(
        &self,
        stress: &Stress,
        de: &Strain,
        spin: f64,
        dt: f64,
        state: &mut MaterialState,
    ) -> Result<Stress, Failure> {
        let i = self.inertial_number(stress, de, dt);
        let sin_phi = self.sin_phi(i);
        if sin_phi == self.sin_s {
            return Ok(self.base.update(stress, de, spin, state).0);
        }
        let b = &self.base;
        let m = MohrCoulomb::new(
            *b.elastic(),
            sin_phi.asin(),
            b.dilatancy_angle(),
            b.cohesion(),
            b.tension_cutoff(),
        );
        Ok(m.update(stress, de, spin, state).0)
    }
    fn density(&self) -> f64 {
        self.base.density()
    }
    fn p_wave_modulus(&self) -> f64 {
        self.base.p_wave_modulus()
    }
    fn elastic_energy_density(&self, s: &Stress, state: &MaterialState) -> f64 {
        self.base.elastic_energy_density(s, state)
    }
}

#[cfg(test)]
mod tests {
    use super::super::LinearElastic;
    use super::*;

    fn material() -> MuIMohrCoulomb {
        let el = LinearElastic {
            density: 1500.0,
            youngs_modulus: 1e7,
            poisson_ratio: 0.3,
        };
        let base = MohrCoulomb::new(el, 20f64.to_radians(), 0.0, 0.0, 0.0);
        MuIMohrCoulomb::new(base, 30f64.to_radians(), [0.3, 3.0], 1e-3, 2500.0)
    }

    /// Steady simple shear at a prescribed rate: the stress ratio settles on the yield surface
    /// of φ(I), (σ₁ − σ₃)/(σ₁ + σ₃) = sin φ(I), with I computed from the settled pressure,
    /// to 1e-6; at a very slow rate, on φ_s.
    #[test]
    fn simple_shear_settles_on_the_friction_of_its_inertial_number() {
        let m = material();
        for (gdot, dt) in [(1e-3, 1e-2), (50.0, 1e-5), (500.0, 1e-6)] {
            // Start isotropic at 1 kPa, shear with ε_xy = γ̇Δt/2 and no volume change.
            let mut s: Stress = [-1e3, -1e3, 0.0, -1e3];
            let mut st = MaterialState::default();
            let de = [0.0, 0.0, 0.5 * gdot * dt];
            for _ in 0..200_000 {
                s = m.update_stress(&s, &de, 0.0, dt, &mut st).unwrap();
            }
            let p = -0.5 * (s[0] + s[1]);
            let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
            let i = m.inertial_number(&s, &de, dt);
            assert!((i - gdot * 1e-3 / (p / 2500.0).sqrt()).abs() < 1e-12 * i.max(1e-30));
            let want = m.sin_phi(i);
            assert!(st.yielding, "γ̇ = {gdot}: still elastic");
            assert!(
                (r / p - want).abs() < 1e-6,
                "γ̇ = {gdot}: {} vs {want}",
                r / p
            );
            if gdot < 1.0 {
                assert!((want - 20f64.to_radians().sin()).abs() < 1e-6);
            } else {
                assert!(want > 20f64.to_radians().sin() + 0.01);
            }
        }
    }

    /// The law's limits: sin φ_s at I = 0, halfway to sin φ_2 at I = I_0, and above I_max = 10 I_0
    /// (and for a stress-free point) held at its value there, (10 sin φ_2 + sin φ_s)/11.
    #[test]
    fn limits_of_the_law() {
        let m = material();
        let (s, s2) = (20f64.to_radians().sin(), 30f64.to_radians().sin());
        let top = (10.0 * s2 + s) / 11.0;
        assert!((m.sin_phi(0.0) - s).abs() < 1e-15);
        assert!((m.sin_phi(0.3) - 0.5 * (s + s2)).abs() < 1e-15);
        for i in [3.0, 30.0, f64::INFINITY] {
            assert!((m.sin_phi(i) - top).abs() < 1e-15, "I = {i}");
        }
        assert!(m.sin_phi(2.9) < top);
        let free = m.inertial_number(&[0.0; 4], &[0.0, 0.0, 1e-6], 1e-5);
        assert!(free.is_infinite());
    }
}
