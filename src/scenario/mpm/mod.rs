//! MPM scenarios (`kind = "mpm"`): the GIMPM column collapse.
//!
//! * [`spec`]: the file's schema and its checks ([`MpmScenario`]);
//! * [`bench`](mod@bench): `granflow bench mpm`;
//! * [`validation`]: the MPM validation cases.
//!
//! The collapse itself runs in [`super::collapse`].

pub mod bench;
pub mod bench_rve;
pub mod spec;
pub mod validation;

pub use spec::*;
