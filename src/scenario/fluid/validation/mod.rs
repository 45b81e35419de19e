//! LBM validation cases: channel flows, decaying vortices, conservation, cavities and
//! cylinders, each against an analytic solution, a published table or a conservation law.

pub mod cavity;
pub mod conservation;
pub mod cylinder;
pub mod les;
pub mod poiseuille;
pub mod taylor_green;

pub(crate) use cylinder::SANGANI_ACRIVOS;
