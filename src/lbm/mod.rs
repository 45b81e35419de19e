//! D2Q9 lattice Boltzmann fluid solver (seed sections 5.1–5.3).
//!
//! * [`d2q9`]: velocity set, weights, equilibrium.
//! * [`collision`]: BGK, MRT, Smagorinsky LES, Guo forcing.
//! * [`lattice`]: population storage (structure of arrays) and the in-place AA stream–collide.
//! * [`boundary`]: periodic, half-way bounce-back (resting or moving), Zou–He edges.
//! * [`obstacle`]: shapes, interpolated bounce-back, momentum-exchange forces.
//! * [`partial`]: partially saturated cells (Noble–Torczynski) for moving solids.
//! * [`ladd`]: Ladd's modified bounce-back for moving solids (the alternative to [`partial`]).
//! * [`solver`]: the solver in time, its [`Scale`](crate::scale::Scale) implementation.

pub mod boundary;
pub mod collision;
pub mod d2q9;
pub mod ladd;
pub mod lattice;
pub mod obstacle;
pub mod partial;
pub mod real;
pub mod solver;

pub use boundary::{Edge, Edges};
pub use collision::{Collider, CollisionModel, MrtRates};
pub use ladd::{BounceLinks, LinkCover, LinkForces};
pub use lattice::Lattice;
pub use obstacle::{Obstacle, Obstacles, Shape};
pub use partial::{CellForces, PartialCells, SolidCover};
pub use real::Real;
pub use solver::{Fluid, Lbm, Macroscopic};
