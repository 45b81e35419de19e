//! Fluid scenarios (`kind = "fluid"`): a lattice Boltzmann flow in a box with edges and
//! obstacles.
//!
//! * [`spec`]: the file's schema, its checks and the derived lattice quantities;
//! * [`initial`]: the initial state, uniform or fields given by expressions of x and y;
//! * [`run`]: the runner (`granflow run`: VTK frames, time series, summary);
//! * [`bench`](mod@bench): `granflow bench lbm`;
//! * [`validation`]: the LBM validation cases.

pub mod bench;
pub mod initial;
pub mod run;
pub mod spec;
pub mod validation;

pub use spec::*;
