//! The DEM representative volume as the constitutive law of an MPM material point (FEM×DEM,
//! Guo & Zhao 2014; MPM×DEM, Liang & Zhao 2019; seed section 4.1, figure 4.1): each point
//! carries a bi-periodic grain packing ([`PeriodicCell`]) and asks it for its stress.
//!
//! **One MPM step of one point**, given the strain increment Δε = Δt sym L and the spin
//! increment Δω = Δt ½(L_xy − L_yx) of [`crate::mpm::material`]:
//!
//! 1. the cell turns rigidly by the material rotation of the step, θ = −Δω counter-clockwise
//!    ([`PeriodicCell::rotate`]: grains, cell, velocities and forces, exactly, so the stress
//!    turns to R σ Rᵀ and nothing else changes — the law is objective by construction);
//! 2. the cell deforms homogeneously with the stretching D = Δε/Δt over the step's duration Δt,
//!    in n = ⌈Δt/Δt_DEM⌉ DEM sub-steps ([`crate::scale::substeps`], the one sub-cycling rule):
//!    the grains follow the affine map and relax through their contacts, so the volume lives on
//!    the same clock as the continuum and its inertial number is the physical one;
//! 3. the point's stress is the cell's Love–Weber stress with the kinetic part (tension
//!    positive), symmetrised: σ_xy = ½(σ_xy + σ_yx); the out-of-plane σ_zz of a 2-D packing is
//!    taken as the in-plane mean ½(σ_xx + σ_yy) (it enters only the reported invariants).
//!
//! A point's state is its cell (grains, velocities, contact springs, cell matrix): moved, not
//! copied, when the points are re-sorted, and copied whole by the MPM's snapshot, so a redone
//! step restores it. A volume stretched thinner than two contact cut-offs is re-tiled (twice
//! the grains, the same packing; [`PeriodicCell`]); a cell that fails (grains through each
//! other, stretched past its re-tiling limit, a state no longer finite) fails the point's
//! update with the reason.
//!
//! **Initial state.** Every point starts from a copy of one prepared packing (a
//! [`crate::dem::periodic_cell::Preparation`] at the target packing fraction and isotropic
//! pressure p₀), driven by the preparation's [`Servo`] to the normal stresses the scenario
//! asks of that point, (σ_xx, σ_yy) (a column's geostatic σ_yy = −ρ g (H − y), σ_xx = K₀ σ_yy),
//! and rested there; the point starts with the stress the volume then carries (its normal
//! stresses within 1 % of the target's mean pressure, its shear stress its own). Volumes of
//! different points are driven in parallel. A target with tension or a shear stress beyond the
//! servo's tolerance is refused.
//!
//! **Continuum constants.** The density is the packing's bulk density ρ_s φ; the P-wave modulus
//! for the CFL step is the packing's affine (Voigt) modulus, an upper bound of its stiffness.

use crate::dem::periodic_cell::{PeriodicCell, Preparation, Servo, Target, Tensor};
use crate::mpm::material::{Failure, Material, Strain, Stress};
use crate::scale::substeps;

/// The representative-volume material: one prepared packing, copied to every point and
/// driven to the point's initial stress.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RveMaterial {
    template: PeriodicCell,
    servo: Servo,
    density: f64,
    p_wave: f64,
}

impl RveMaterial {
    /// The material of points that start as copies of `template`, driven to their initial
    /// stress by `servo`. Refuses an empty packing or one without contacts (no stiffness).
    pub fn new(template: PeriodicCell, servo: Servo) -> Result<Self, String> {
        if template.is_empty() {
            return Err("the representative volume holds no grain".into());
        }
        let p_wave = template.affine_modulus();
        if p_wave.is_nan() || p_wave <= 0.0 {
            return Err("the representative volume has no contacts (no stiffness)".into());
        }
        Ok(RveMaterial {
            density: template.bulk_density(),
            p_wave,
            template,
            servo,
        })
    }

    /// Prepare the packing of `prep` and make it the material, with `prep`'s servo.
    pub fn prepare(prep: &Preparation) -> Result<Self, String> {
        RveMaterial::new(prep.run()?.cell, prep.servo())
    }

    /// A point's state as prepared, with its stress: the template itself (no servo).
    pub fn start(&self) -> (PeriodicCell, Stress) {
        (self.template.clone(), point_stress(&self.template))
    }

    /// The packing every point starts from.
    pub fn template(&self) -> &PeriodicCell {
        &self.template
    }

    /// DEM sub-steps one point takes in an MPM step of `dt`.
    pub fn substeps(&self, dt: f64) -> u64 {
        substeps(dt, self.template.dt()).0
    }
}

/// A cell's stress in the MPM's layout (xx, yy, xy, zz), see the module doc.
pub fn point_stress(cell: &PeriodicCell) -> Stress {
    let s = cell.stress();
    let (xx, yy) = (s[(0, 0)], s[(1, 1)]);
    [xx, yy, 0.5 * (s[(0, 1)] + s[(1, 0)]), 0.5 * (xx + yy)]
}

impl Material for RveMaterial {
    type State = PeriodicCell;
    /// Each point runs a simulation: one point per parallel task.
    const POINTS_PER_TASK: usize = 1;

    fn update_stress(
        &self,
        _stress: &Stress,
        de: &Strain,
        spin: f64,
        dt: f64,
        cell: &mut PeriodicCell,
    ) -> Result<Stress, Failure> {
        if cell.is_empty() {
            return Err(
                "the point has no representative volume (its initial state was not set)".into(),
            );
        }
        cell.rotate(-spin);
        let stretching = Tensor::new(de[0], de[2], de[2], de[1]) / dt;
        let (n, h) = substeps(dt, cell.dt());
        cell.deform(&stretching, n, h)
            .map_err(|why| format!("representative volume: {why}"))?;
        Ok(point_stress(cell))
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn p_wave_modulus(&self) -> f64 {
        self.p_wave
    }

    /// The energy in the cell's springs per unit volume.
    fn elastic_energy_density(&self, _stress: &Stress, cell: &PeriodicCell) -> f64 {
        if cell.is_empty() {
            return 0.0;
        }
        cell.energy().stored / (cell.area() * cell.thickness())
    }

    /// The template driven to the normal stresses of `stress` (see the module doc).
    fn initial_state(&self, stress: &Stress) -> Result<(PeriodicCell, Stress), Failure> {
        let [xx, yy, xy, _] = *stress;
        if !(xx < 0.0 && yy < 0.0) {
            return Err(format!(
                "a representative volume starts under compression on both axes, asked for \
                 σ_xx = {xx:e}, σ_yy = {yy:e} Pa"
            ));
        }
        let pt = -0.5 * (xx + yy);
        if xy.abs() > 0.01 * pt {
            return Err(format!(
                "a representative volume starts from normal stresses (the servo holds σ_xx and \
                 σ_yy), asked for σ_xy = {xy:e} Pa beside p = {pt:e} Pa"
            ));
        }
        let mut cell = self.template.clone();
        self.servo
            .hold(&mut cell, Target::Normal([-xx, -yy]))
            .map_err(|why| format!("its representative volume: {why}"))?;
        let s = point_stress(&cell);
        Ok((cell, s))
    }
}

#[cfg(test)]
mod tests;
