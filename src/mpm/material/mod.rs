//! Constitutive laws behind one interface, [`Material::update_stress`]: given the Cauchy
//! stress at the start of a step, the strain increment Δε = Δt·sym(∇v), the spin increment
//! Δω = Δt·½(∂v_x/∂y − ∂v_y/∂x) and the step Δt (for rate-dependent laws), return the stress
//! at the end of the step.
//!
//! Objectivity (Jaumann rate): the law sees the stress rotated with the material,
//! σ* = σ + Δt(W σ − σ W) with W = [[0, Δω], [−Δω, 0]]/Δt, i.e.
//! σ*_xx = σ_xx + 2Δω σ_xy, σ*_yy = σ_yy − 2Δω σ_xy, σ*_xy = σ_xy + Δω(σ_yy − σ_xx),
//! and adds its constitutive increment to σ*. Plane strain: Δε_zz = 0, σ_zz is kept.
//!
//! Sign convention: tension positive (geomechanics' compression-positive numbers appear in
//! the validation with a minus sign).

pub mod elastic;
pub mod mohr_coulomb;
pub mod mu_i;

pub use elastic::LinearElastic;
pub use mohr_coulomb::MohrCoulomb;
pub use mu_i::MuIMohrCoulomb;

/// Plane-strain Cauchy stress (Pa): xx, yy, xy, zz.
pub type Stress = [f64; 4];

/// Strain increment (tensor components): xx, yy, xy (= ½ γ_xy). zz is 0 in plane strain.
pub type Strain = [f64; 3];

/// Per-point history of the built-in laws (no heap object per point: one of these per point,
/// stored in a `Vec` beside the other point arrays).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MaterialState {
    /// Accumulated equivalent plastic shear strain, Σ √(2/3 Δε^p_dev : Δε^p_dev).
    pub plastic_strain: f64,
    /// Accumulated plastic volumetric strain Σ tr Δε^p (positive: dilation).
    pub plastic_volumetric: f64,
    /// Whether the last update was plastic.
    pub yielding: bool,
}

/// Why a point's stress update failed (the solver adds which point, where and when).
pub type Failure = String;

/// The material contract (cb-geo's `compute_stress`, with the spin passed for objectivity).
///
/// A law carries its own per-point state type: a few numbers for Mohr–Coulomb
/// ([`MaterialState`]), a whole grain packing for a DEM representative volume (which lives
/// outside `mpm/`, in `crate::multiscale`). The MPM solver is generic over the law, so the
/// built-in laws keep a hot loop without virtual calls.
pub trait Material: Sync + Send {
    /// The per-point history (moved, never copied, when the points are re-sorted).
    type State: Clone + Default + Send + Sync + std::fmt::Debug;
    /// Points per parallel task of the stress update: many for a cheap closed-form law, one for
    /// a law that runs a simulation per point.
    const POINTS_PER_TASK: usize = 512;

    /// Stress after a step of `dt` with strain increment `dstrain` and spin increment `spin`;
    /// a failure says why (e.g. a representative volume that went unstable).
    fn update_stress(
        &self,
        stress: &Stress,
        dstrain: &Strain,
        spin: f64,
        dt: f64,
        state: &mut Self::State,
    ) -> Result<Stress, Failure>;
    /// Mass density ρ (kg/m³).
    fn density(&self) -> f64;
    /// P-wave modulus K + 4G/3 (Pa), for the CFL step.
    fn p_wave_modulus(&self) -> f64;
    /// Stored (elastic) energy density (J/m³) of a point at `stress` with `state`:
    /// ½ σ : C⁻¹ : σ for the continuum laws.
    fn elastic_energy_density(&self, stress: &Stress, state: &Self::State) -> f64;
    /// The state a point starts with at the initial stress `stress`, and the stress it really
    /// starts with (the built-in laws take any stress; a representative volume starts from a
    /// packing whose own stress it reports).
    fn initial_state(&self, stress: &Stress) -> Result<(Self::State, Stress), Failure> {
        Ok((Self::State::default(), *stress))
    }
}

/// Mean stress p = (σ_xx + σ_yy + σ_zz)/3 and von Mises equivalent deviatoric stress
/// q = √(3/2 s:s) of a stress.
pub fn invariants(s: &Stress) -> (f64, f64) {
    let p = (s[0] + s[1] + s[3]) / 3.0;
    let d = [s[0] - p, s[1] - p, s[3] - p];
    let j2 = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + s[2] * s[2];
    (p, (3.0 * j2).sqrt())
}

/// Jaumann co-rotation of `s` by the spin increment `w` (see the module doc).
#[inline(always)]
pub fn jaumann(s: &Stress, w: f64) -> Stress {
    [
        s[0] + 2.0 * w * s[2],
        s[1] - 2.0 * w * s[2],
        s[2] + w * (s[1] - s[0]),
        s[3],
    ]
}

/// The materials a scenario can choose (enum dispatch keeps the hot loop free of virtual
/// calls).
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub enum MaterialModel {
    /// Linear isotropic elasticity.
    Elastic(LinearElastic),
    /// Mohr–Coulomb elastic–perfectly plastic.
    MohrCoulomb(MohrCoulomb),
    /// Mohr–Coulomb with the friction angle of the μ(I) rheology.
    MuI(MuIMohrCoulomb),
}

impl Material for MaterialModel {
    type State = MaterialState;
    #[inline(always)]
    fn update_stress(
        &self,
        stress: &Stress,
        dstrain: &Strain,
        spin: f64,
        dt: f64,
        state: &mut MaterialState,
    ) -> Result<Stress, Failure> {
        match self {
            MaterialModel::Elastic(m) => m.update_stress(stress, dstrain, spin, dt, state),
            MaterialModel::MohrCoulomb(m) => m.update_stress(stress, dstrain, spin, dt, state),
            MaterialModel::MuI(m) => m.update_stress(stress, dstrain, spin, dt, state),
        }
    }
    fn density(&self) -> f64 {
        match self {
            MaterialModel::Elastic(m) => m.density(),
            MaterialModel::MohrCoulomb(m) => m.density(),
            MaterialModel::MuI(m) => m.density(),
        }
    }
    fn p_wave_modulus(&self) -> f64 {
        match self {
            MaterialModel::Elastic(m) => m.p_wave_modulus(),
            MaterialModel::MohrCoulomb(m) => m.p_wave_modulus(),
            MaterialModel::MuI(m) => m.p_wave_modulus(),
        }
    }
    fn elastic_energy_density(&self, stress: &Stress, state: &MaterialState) -> f64 {
        match self {
            MaterialModel::Elastic(m) => m.elastic_energy_density(stress, state),
            MaterialModel::MohrCoulomb(m) => m.elastic_energy_density(stress, state),
            MaterialModel::MuI(m) => m.elastic_energy_density(stress, state),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pure rotation (Δε = 0) only turns the stress: its invariants are unchanged to first
    /// order, and a rotation by 90° in small steps swaps σ_xx and σ_yy.
    #[test]
    fn jaumann_rotates_the_stress() {
        let mut s: Stress = [-3.0, -1.0, 0.0, -2.0];
        let n = 100_000;
        let w = std::f64::consts::FRAC_PI_2 / n as f64;
        for _ in 0..n {
            s = jaumann(&s, w);
        }
        assert!((s[0] + 1.0).abs() < 1e-4 && (s[1] + 3.0).abs() < 1e-4 && s[2].abs() < 1e-4);
    }
}
