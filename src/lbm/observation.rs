//! What a run watches between frames: domain-wide sums over the fluid cells and the state of a
//! few probed cells, reduced where the populations live (on a GPU: on the device, so that a
//! time-series row or a stability check reads back a few numbers, not the lattice).

use crate::units::CS2;

/// Domain-wide quantities of the fluid cells and the state of chosen cells, lattice units,
/// with u = (Σ f e + F/2)/ρ as [`super::Lbm::cell`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Observation {
    /// Σ ρ.
    pub mass: f64,
    /// Σ ½ ρ |u|².
    pub kinetic_energy: f64,
    /// max |u|.
    pub max_speed: f64,
    /// min ρ (+∞ without fluid cells).
    pub min_density: f64,
    /// (ρ, u_x, u_y) of each probed cell; a solid cell reads (1, 0, 0).
    pub probes: Vec<(f64, f64, f64)>,
}

/// Partial sums of one part of the lattice: Σρ, Σ ½ρ|u|², max |u|², min ρ.
pub type Partial = [f64; 4];

impl Observation {
    /// The partial of nothing.
    pub const EMPTY: Partial = [0.0, 0.0, 0.0, f64::INFINITY];

    /// Add cell (ρ, u_x, u_y) to a partial.
    pub fn add_cell(p: Partial, (rho, ux, uy): (f64, f64, f64)) -> Partial {
        let u2 = ux * ux + uy * uy;
        [
            p[0] + rho,
            p[1] + 0.5 * rho * u2,
            p[2].max(u2),
            p[3].min(rho),
        ]
    }

    /// Combine two partials (sums added, extremes kept).
    pub fn combine(a: Partial, b: Partial) -> Partial {
        [a[0] + b[0], a[1] + b[1], a[2].max(b[2]), a[3].min(b[3])]
    }

    /// The observation of partials combined in their order, and the probes.
    pub fn from_partials(
        parts: impl IntoIterator<Item = Partial>,
        probes: Vec<(f64, f64, f64)>,
    ) -> Self {
        let p = parts.into_iter().fold(Self::EMPTY, Self::combine);
        Observation {
            mass: p[0],
            kinetic_energy: p[1],
            max_speed: p[2].sqrt(),
            min_density: p[3],
            probes,
        }
    }

    /// No cell is NaN, has ρ ≤ 0 or a lattice Mach number |u|/c_s above `max_mach`: the test
    /// of [`super::Lbm::find_instability`] on the reduced values (a NaN anywhere makes the
    /// sums NaN).
    pub fn is_stable(&self, max_mach: f64) -> bool {
        self.mass.is_finite()
            && self.kinetic_energy.is_finite()
            && self.min_density > 0.0
            && self.max_speed / CS2.sqrt() <= max_mach
    }
}
