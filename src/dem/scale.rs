//! [`Scale`] implementation: the DEM as a submodel the fluid or MPM drivers can advance with
//! their own, larger step. `advance(dt)` sub-cycles n = ⌈dt/Δt_D⌉ steps of size dt/n
//! ([`crate::scale::substeps`], seed eq. 5.61) with the external loads (e.g. hydrodynamic
//! force and torque, seed eq. 5.53–5.54) held fixed.

use super::solver::{Dem, ExternalLoads};
use crate::scale::Scale;
use crate::Result;

/// What the DEM shows the other scales: grain kinematics, written into reused buffers.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct GrainView {
    /// Centres x.
    pub x: Vec<f64>,
    /// Centres y.
    pub y: Vec<f64>,
    /// Velocities x.
    pub vx: Vec<f64>,
    /// Velocities y.
    pub vy: Vec<f64>,
    /// Angular velocities.
    pub omega: Vec<f64>,
    /// Radii.
    pub radius: Vec<f64>,
}

impl Scale for Dem {
    type Input = ExternalLoads;
    type Output = GrainView;
    type Snapshot = Box<Dem>;

    fn time(&self) -> f64 {
        Dem::time(self)
    }

    /// The step in use, λ Δt_cr or the scenario's smaller one (seed eq. 5.60).
    fn max_dt(&self) -> f64 {
        self.dt()
    }

    fn advance(&mut self, input: &ExternalLoads, dt: f64) -> Result<()> {
        self.advance_with(dt, Some(input))
    }

    /// New external loads: the forces of the last step (used by the next half-kick) are
    /// re-evaluated with them, so a load held over Δt gives exactly the impulse F Δt.
    fn input_changed(&mut self) {
        self.invalidate_forces();
    }

    fn observe(&self, out: &mut GrainView) {
        let g = &self.grains;
        out.x.clone_from(&g.x);
        out.y.clone_from(&g.y);
        out.vx.clone_from(&g.vx);
        out.vy.clone_from(&g.vy);
        out.omega.clone_from(&g.omega);
        out.radius.clone_from(&g.radius);
    }

    fn snapshot(&self) -> Box<Dem> {
        Box::new(self.clone())
    }

    fn restore(&mut self, snapshot: Box<Dem>) {
        *self = *snapshot;
    }
}
