//! Fluid–grain coupling (seed section 5.4): the LBM fluid and a solid scale (DEM grains now,
//! MPM later) advanced together.
//!
//! * [`overlap`]: exact disk–square overlap area, the solid fraction ε of a lattice cell.
//! * [`cover`]: grains → partially saturated cells (ε, solid velocity with rotation,
//!   hydrodynamic radius factor r/R) and cell forces → force and torque per grain
//!   (seed eq. 5.53–5.54). The collision of covered cells is in [`crate::lbm::partial`].
//! * [`ladd`]: grains → boundary links for Ladd's modified bounce-back (seed eq. 5.45–5.49),
//!   the alternative to partially saturated cells; link forces → force and torque per grain.
//! * [`scenario`], [`run`]: the submerged column collapse (TOML with `[fluid]` and
//!   `[coupling]` tables, `granflow check` / `granflow run`).
//! * [`driver`]: the coupled step over two [`crate::scale::Scale`]s with solid sub-cycling
//!   n_s = ⌊Δt/Δt_D⌋ + 1 and the hydrodynamic force held (seed eq. 5.61).
//!
//! Buoyancy enters through reduced gravity (1 − ρ_f/ρ_s) g on the grains (seed eq. 5.57); the
//! fluid then carries no gravity, so there is no hydrostatic pressure to resolve.

pub mod bench;
pub mod cover;
pub mod driver;
pub mod ladd;
pub mod overlap;
pub mod run;
pub mod scenario;
pub mod validation;
pub mod validation_ladd;

pub use cover::{DiskCover, Grid};
pub use driver::{subcycles, Coupled, Exchange};
pub use ladd::LaddMap;

use crate::dem::scale::GrainView;
use crate::dem::ExternalLoads;
use crate::lbm::{CellForces, SolidCover};
use crate::scale::Scale;

/// Reduced gravity (1 − ρ_f/ρ_s) g for grains of density ρ_s in a fluid of density ρ_f
/// (seed eq. 5.57: buoyancy without a hydrostatic pressure in the fluid).
pub fn reduced_gravity(g: [f64; 2], rho_fluid: f64, rho_solid: f64) -> [f64; 2] {
    let k = 1.0 - rho_fluid / rho_solid;
    [k * g[0], k * g[1]]
}

impl<F, S> Exchange<F, S> for DiskCover
where
    F: Scale<Input = SolidCover, Output = CellForces>,
    S: Scale<Input = ExternalLoads, Output = GrainView>,
{
    fn to_fluid(&mut self, solid: &GrainView, fluid_in: &mut SolidCover) {
        self.cover(solid, fluid_in);
    }
    fn to_solid(&mut self, fluid: &CellForces, solid_in: &mut ExternalLoads) {
        // The grain count is the count the last cover saw.
        let n = self.grains();
        self.loads(fluid, n, solid_in);
    }
}
