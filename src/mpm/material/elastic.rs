//! Linear isotropic elasticity in plane strain (Hooke's law in rate form, Jaumann rate):
//! Δσ = λ tr(Δε) I + 2G Δε, with λ = Eν/((1+ν)(1−2ν)), G = E/(2(1+ν)), Δε_zz = 0, so
//! Δσ_zz = λ (Δε_xx + Δε_yy).

use super::{jaumann, Failure, Material, MaterialState, Strain, Stress};

/// Linear isotropic elasticity.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct LinearElastic {
    /// Density ρ (kg/m³).
    pub density: f64,
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
}

impl LinearElastic {
    /// Lamé's first parameter λ = Eν/((1+ν)(1−2ν)).
    pub fn lambda(&self) -> f64 {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    }
    /// Shear modulus G = E/(2(1+ν)).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
    /// Bulk modulus K = E/(3(1−2ν)).
    pub fn bulk_modulus(&self) -> f64 {
        self.youngs_modulus / (3.0 * (1.0 - 2.0 * self.poisson_ratio))
    }
    /// The elastic trial stress: Jaumann rotation plus Hooke's increment.
    #[inline(always)]
    pub fn trial(&self, stress: &Stress, de: &Strain, spin: f64) -> Stress {
        Self::trial_with(self.lambda(), 2.0 * self.shear_modulus(), stress, de, spin)
    }
    /// [`Self::trial`] with λ and 2G given (precomputed by the caller).
    #[inline(always)]
    pub fn trial_with(l: f64, g2: f64, stress: &Stress, de: &Strain, spin: f64) -> Stress {
        let tr = de[0] + de[1];
        let s = jaumann(stress, spin);
        [
            s[0] + l * tr + g2 * de[0],
            s[1] + l * tr + g2 * de[1],
            s[2] + g2 * de[2],
            s[3] + l * tr,
        ]
    }
    /// ½ σ : C⁻¹ : σ = [(1+ν) σ:σ − ν (tr σ)²]/(2E), with σ:σ = σ_xx² + σ_yy² + σ_zz² + 2σ_xy².
    pub fn energy_density(&self, s: &Stress) -> f64 {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        let ss = s[0] * s[0] + s[1] * s[1] + s[3] * s[3] + 2.0 * s[2] * s[2];
        let tr = s[0] + s[1] + s[3];
        ((1.0 + nu) * ss - nu * tr * tr) / (2.0 * e)
    }
}

impl Material for LinearElastic {
    type State = MaterialState;
    fn update_stress(
        &self,
        stress: &Stress,
        de: &Strain,
        spin: f64,
        _dt: f64,
        _: &mut MaterialState,
    ) -> Result<Stress, Failure> {
        Ok(self.trial(stress, de, spin))
    }
    fn density(&self) -> f64 {
        self.density
    }
    fn p_wave_modulus(&self) -> f64 {
        self.bulk_modulus() + 4.0 / 3.0 * self.shear_modulus()
    }
    fn elastic_energy_density(&self, s: &Stress, _: &MaterialState) -> f64 {
        self.energy_density(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniaxial strain ε_yy: σ_yy = (K + 4G/3) ε, σ_xx = σ_zz = λ ε; energy ½ σ_yy ε.
    #[test]
    fn uniaxial_strain_and_energy() {
        let m = LinearElastic {
            density: 1000.0,
            youngs_modulus: 1e7,
            poisson_ratio: 0.3,
        };
        let e = -1e-4;
        let s = m.trial(&[0.0; 4], &[0.0, e, 0.0], 0.0);
        assert!((s[1] - m.p_wave_modulus() * e).abs() < 1e-9 * m.youngs_modulus);
        assert!((s[0] - m.lambda() * e).abs() < 1e-12 * m.youngs_modulus);
        assert_eq!(s[0], s[3]);
        assert!((m.energy_density(&s) - 0.5 * s[1] * e).abs() < 1e-12);
    }
}
