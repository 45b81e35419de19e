//! Partially saturated cells (Noble & Torczynski 1998; seed eq. 5.50–5.54), the whole method
//! in one place:
//!
//! * [`overlap`]: exact disk–square overlap area, the solid fraction ε of a lattice cell;
//! * [`cover`]: grains → covered cells (ε, solid velocity with rotation, hydrodynamic radius
//!   factor r/R) and cell forces → force and torque per grain (eq. 5.53–5.54);
//! * [`collision`]: the collision of a covered cell, the blend of the fluid collision with the
//!   solid term, which the lattice applies through [`crate::lbm::CoveredCells`].

pub mod collision;
pub mod cover;
pub mod overlap;

pub use collision::{blend, collide, weighting, PartialCells};
pub use cover::{DiskCover, Grid};
