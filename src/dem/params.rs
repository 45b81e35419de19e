//! The parameters of a DEM system (SI): contact laws, gravity, the time-step rule, the Verlet
//! skin and global damping.

use super::contact::ContactParams;
use super::grains::Grains;

/// Parameters of a DEM system, SI.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DemParams {
    /// Grain–grain contact law.
    pub grain: ContactParams,
    /// Grain–wall contact law.
    pub wall: ContactParams,
    /// Gravitational acceleration **g** (m/s²).
    pub gravity: [f64; 2],
    /// Time step; `None` takes λ Δt_cr. A value above λ Δt_cr is refused.
    pub dt: Option<f64>,
    /// Safety factor λ of seed eq. 5.60 (0.1 in the seed).
    pub lambda: f64,
    /// Verlet skin as a fraction of the largest grain diameter (e.g. 0.2).
    pub skin_fraction: f64,
    /// Global damping rate α (1/s) of seed eq. 5.57, c = α m; 0 = off (the default).
    pub global_damping: f64,
    /// Periodic in x over [x0, x1) (`None`: not periodic). A grain leaving through one end
    /// comes back through the other, and grains near the two ends touch through the period
    /// (minimal image, [`min_image`]). Disks only; the walls are not repeated. With g_x ≠ 0
    /// the potential energy −Σ m **g**·**x** of [`super::Energy`] uses the wrapped positions,
    /// so it jumps by m g_x L when a grain crosses an end: the energy budget of such a run does
    /// not close.
    pub periodic_x: Option<[f64; 2]>,
}

/// The minimal image of a separation `dx` along a period of length `l`:
/// dx − l · round(dx / l), in [−l/2, l/2]; `dx` itself without a period.
#[inline(always)]
pub fn min_image(dx: f64, l: Option<f64>) -> f64 {
    match l {
        Some(l) => dx - l * (dx / l).round(),
        None => dx,
    }
}

impl DemParams {
    /// Parameters with `grain` and `wall` laws, gravity, automatic step, λ = 0.1, skin 0.2 d_max,
    /// no global damping, no period.
    pub fn new(grain: ContactParams, wall: ContactParams, gravity: [f64; 2]) -> Self {
        DemParams {
            grain,
            wall,
            gravity,
            dt: None,
            lambda: 0.1,
            skin_fraction: 0.2,
            global_damping: 0.0,
            periodic_x: None,
        }
    }

    /// Length of the x period, if periodic.
    pub fn period(&self) -> Option<f64> {
        self.periodic_x.map(|[a, b]| b - a)
    }

    /// Check the period for `grains` (`field` names it in the error): finite, at least
    /// 3 (2 R_max + skin) long (the cell list's three neighbour columns then differ), and the
    /// grains all disks (the polygon detector sees no images).
    pub fn check_period(&self, grains: &Grains, field: &str) -> crate::Result<()> {
        let Some([a, b]) = self.periodic_x else {
            return Ok(());
        };
        let d_max = 2.0 * grains.max_radius();
        let reach = 3.0 * d_max * (1.0 + self.skin_fraction);
        if !(a.is_finite() && b.is_finite() && b - a >= reach) {
            return Err(crate::Error::config(
                field,
                format!(
                    "the period [{a}, {b}] must be finite and at least 3 (d_max + skin) = \
                     {reach:.4e} m long"
                ),
            ));
        }
        if grains.has_polygons() {
            return Err(crate::Error::config(
                field,
                "a periodic domain holds disks only (the polygon detector sees no images)",
            ));
        }
        Ok(())
    }
}
