//! Ladd's modified bounce-back on moving solids (Ladd 1994; seed eq. 5.45–5.49), the
//! alternative to partially saturated cells, the whole method in one place:
//!
//! * [`map`]: grains → boundary links, inside, covered and uncovered nodes; link forces and
//!   covering impulses → force and torque per grain;
//! * [`links`]: the bounce-back on the lattice's links after each stream–collide step, the
//!   momentum exchanged across them, and the refill of uncovered nodes.

pub mod links;
pub mod map;

pub use links::{BounceLinks, LinkCover, LinkForces};
pub use map::LaddMap;
