//! Submerged scenarios (`kind = "submerged"`): the column collapse of DEM grains in an LBM
//! liquid.
//!
//! * [`spec`]: the file's schema and its checks ([`SubmergedScenario`]);
//! * [`bench`](mod@bench): `granflow bench coupled` (seed Table 5.3 size);
//! * [`validation`], [`validation_ladd`]: the coupling validation cases (partially saturated
//!   cells, Ladd's bounce-back).
//!
//! The collapse itself runs in [`super::collapse`].

pub mod bench;
pub mod spec;
pub mod validation;
pub mod validation_ladd;

pub use spec::*;
