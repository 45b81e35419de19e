//! MPM scenarios (`kind = "mpm"`): the GIMPM column collapse, with a closed-form law or a DEM
//! representative volume at each point (`model = "rve"`).
//!
//! * [`spec`]: the file's schema and its checks ([`MpmScenario`]);
//! * [`bench`](mod@bench): `granflow bench mpm`;
//! * [`bench_rve`]: `granflow bench rve`, the cost of the representative-volume material;
//! * [`validation`]: the MPM validation cases.
//!
//! The collapse itself runs in [`super::collapse`].

pub mod bench;
pub mod bench_rve;
pub mod initial;
pub mod spec;
pub mod validation;

pub use spec::*;
