//! Couplings between the scales: every map from one solver to another lives here, and no
//! solver names another.
//!
//! Fluid ↔ solid (seed section 5.4): the LBM fluid and a solid scale (DEM grains now, MPM
//! points later) advanced together.
//!
//! * [`fluid`]: [`CoupledFluid`], the LBM with the coupling methods' state, as the fluid
//!   [`Scale`] whose input is what the solids cover ([`SolidCover`]) and whose output is the
//!   force on them ([`CellForces`]);
//! * [`psm`]: partially saturated cells (Noble–Torczynski), the whole method;
//! * [`ladd`]: Ladd's modified bounce-back, the whole method;
//! * [`driver`]: the coupled step over two [`Scale`]s, with the solid sub-cycled by the one
//!   rule of [`crate::scale::substeps`] and the hydrodynamic force held (seed eq. 5.61).
//!
//! Continuum ↔ grains: [`rve`], the DEM representative volume as the material of the MPM's
//! points ([`RveMaterial`]).
//!
//! Buoyancy enters through reduced gravity (1 − ρ_f/ρ_s) g on the grains (seed eq. 5.57); the
//! fluid then carries no gravity, so there is no hydrostatic pressure to resolve.

pub mod driver;
pub mod fluid;
pub mod ladd;
pub mod psm;
pub mod rve;

pub use driver::{Coupled, Exchange, Exchanged};
pub use fluid::{CellForces, CoupledFluid, CoupledFluidState, SolidCover};
pub use ladd::LaddMap;
pub use psm::{DiskCover, Grid};
pub use rve::RveMaterial;

use crate::dem::scale::GrainView;
use crate::dem::ExternalLoads;
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
