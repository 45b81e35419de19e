//! The parameters of a DEM system (SI): contact laws, gravity, the time-step rule, the Verlet
//! skin and global damping.

use super::contact::ContactParams;

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
}

impl DemParams {
    /// Parameters with `grain` and `wall` laws, gravity, automatic step, λ = 0.1, skin 0.2 d_max,
    /// no global damping.
    pub fn new(grain: ContactParams, wall: ContactParams, gravity: [f64; 2]) -> Self {
        DemParams {
            grain,
            wall,
            gravity,
            dt: None,
            lambda: 0.1,
            skin_fraction: 0.2,
            global_damping: 0.0,
        }
    }
}
