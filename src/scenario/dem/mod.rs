//! DEM scenarios (`kind = "dem"`): the column collapse of a polydisperse disk packing, and the
//! material tests run on its grains.
//!
//! * [`spec`]: the file's schema and its checks ([`DemScenario`]);
//! * [`biaxial`]: `granflow biaxial`, the material's peak and critical-state friction angles;
//! * [`rve_biaxial`]: the same test on a bi-periodic representative volume
//!   (`--periodic-packing-fraction`) and the `rve-biaxial` validation case;
//! * [`shear`]: `granflow shear`, its μ(I) by periodic simple shear;
//! * [`bench`](mod@bench): `granflow bench dem` (the LAMMPS `in.gran2d.lmp` case);
//! * [`validation`], [`validation_polygon`]: the DEM validation cases.
//!
//! The collapse itself runs in [`super::collapse`].

pub mod bench;
pub mod biaxial;
pub mod rve_biaxial;
pub mod shear;
pub mod spec;
pub mod validation;
pub mod validation_polygon;

pub use spec::*;
