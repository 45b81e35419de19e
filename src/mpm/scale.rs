//! [`Scale`] implementation: the MPM continuum as a submodel; `advance(dt)` sub-cycles steps of
//! at most the CFL step ([`crate::scale::substeps`]).

use super::material::Material;
use super::solver::Mpm;
use crate::scale::Scale;
use crate::Result;

/// What the MPM shows the other scales: point positions, velocities and volumes.
#[derive(Clone, Debug, Default)]
pub struct PointView {
    /// Positions (m).
    pub pos: Vec<[f64; 2]>,
    /// Velocities (m/s).
    pub vel: Vec<[f64; 2]>,
    /// Volumes (m³ per m).
    pub vol: Vec<f64>,
}

impl<M: Material + Clone + 'static> Scale for Mpm<M> {
    type Input = ();
    type Output = PointView;
    type Snapshot = Box<Mpm<M>>;

    fn time(&self) -> f64 {
        Mpm::time(self)
    }
    /// The step in use (≤ C h/c).
    fn max_dt(&self) -> f64 {
        self.dt()
    }
    fn advance(&mut self, _: &(), dt: f64) -> Result<()> {
        self.advance_by(dt)
    }
    fn observe(&self, out: &mut PointView) {
        out.pos.clone_from(&self.points.pos);
        out.vel.clone_from(&self.points.vel);
        out.vol.clone_from(&self.points.vol);
    }
    fn snapshot(&self) -> Box<Mpm<M>> {
        Box::new(self.clone())
    }
    fn restore(&mut self, s: Box<Mpm<M>>) {
        *self = *s;
    }
}
