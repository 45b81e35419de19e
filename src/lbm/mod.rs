//! D2Q9 lattice Boltzmann fluid solver (seed sections 5.1–5.3).
//!
//! * [`d2q9`]: velocity set, weights, equilibrium.
//! * [`collision`]: BGK, MRT, Smagorinsky LES, Guo forcing.
//! * [`lattice`]: population storage (structure of arrays) and the in-place AA stream–collide.
//! * [`backend`]: CPU or GPU.
//! * [`boundary`]: periodic, half-way bounce-back (resting or moving), Zou–He edges.
//! * [`obstacle`]: shapes, interpolated bounce-back, momentum-exchange forces.
//! * [`covered`]: the hook through which a coupling method collides the cells its solids
//!   cover (partially saturated cells live in `crate::coupling::psm`, Ladd's bounce-back in
//!   `crate::coupling::ladd`).
//! * `gpu` (feature `gpu`): the same step on a GPU through wgpu.
//! * [`solver`]: the solver in time, built from an [`LbmSetup`].
//! * [`observation`]: the sums and probes a run watches between frames.

pub mod backend;
pub mod boundary;
pub mod collision;
pub mod covered;
pub mod d2q9;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod lattice;
pub mod observation;
pub mod obstacle;
pub mod real;
pub mod simd;
pub mod solver;

pub use backend::Backend;
pub use boundary::{Edge, Edges};
pub use collision::{Collider, CollisionModel, MrtRates};
pub use covered::{CoveredCells, UNCOVERED};
pub use lattice::Lattice;
pub use observation::Observation;
pub use obstacle::{Obstacle, Obstacles, Shape};
pub use real::{Populations, Real};
pub use solver::{Fluid, FluidModel, Lbm, LbmSetup, LbmState, Macroscopic, STOP_MACH};
