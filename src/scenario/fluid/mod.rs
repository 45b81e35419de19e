//! Fluid scenarios (`kind = "fluid"`): a lattice Boltzmann flow in a box with edges and
//! obstacles.
//!
//! * [`spec`]: the file's schema, its checks and the derived lattice quantities;
//! * [`run`]: the runner (`granflow run`: VTK frames, time series, summary);
//! * [`bench`](mod@bench): `granflow bench lbm`;
//! * [`validation`]: the LBM validation cases.

pub mod bench;
pub mod run;
pub mod spec;
pub mod validation;

pub use spec::*;
