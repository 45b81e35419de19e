//! # granflow
//!
//! A 2-D multi-scale framework for granular flows, dry and submerged. Three solvers share one
//! crate and meet through the [`scale::Scale`] trait:
//!
//! | scale | module | method |
//! |---|---|---|
//! | grain | [`dem`] | discrete elements: disks, spring-dashpot contacts, friction, rolling resistance |
//! | continuum | [`mpm`] | generalised-interpolation MPM (uGIMP), USF/USL/MUSL, Mohr–Coulomb |
//! | fluid | [`lbm`] | D2Q9 lattice Boltzmann, BGK / MRT, Smagorinsky LES |
//!
//! [`coupling`] links them: partially saturated cells or Ladd's bounce-back couple DEM grains
//! to the LBM fluid, in a driver over two [`scale::Scale`]s with sub-cycling.
//!
//! The crate has two storeys (docs/architecture.md):
//!
//! * **physics**: [`lbm`], [`dem`], [`mpm`], [`coupling`], on [`scale`], [`units`], [`error`]
//!   and the shared helpers [`analysis`], [`report`], [`exec`]. It knows nothing of files or
//!   the command line;
//! * **scenarios**: [`scenario`] (the file of each kind, its runner, bench and validation
//!   cases) and [`sweep`] (studies over many scenarios), writing through [`io`].
//!
//! All inputs are SI. [`units::Units`] converts between SI and lattice units, with the formula
//! in each method's documentation.
//!
//! A fluid scenario from TOML, run for a few steps:
//!
//! ```
//! use granflow::scenario::{fluid::Scenario, ScenarioFile};
//! let text = std::fs::read_to_string(
//!     concat!(env!("CARGO_MANIFEST_DIR"), "/models/lbm/poiseuille.toml"),
//! )?;
//! let scenario = Scenario::from_toml(&text)?;
//! let (mut fluid, derived) = scenario.build()?;
//! assert!(derived.units.tau > 0.5 && derived.mach < 0.3);
//! fluid.steps(100);
//! fluid.check_stable(0.5)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub mod analysis;
pub mod coupling;
pub mod dem;
pub mod error;
pub mod exec;
pub mod io;
pub mod lbm;
pub mod mpm;
pub mod report;
pub mod scale;
pub mod scenario;
pub mod sweep;
pub mod units;

pub use error::{Error, Result};
