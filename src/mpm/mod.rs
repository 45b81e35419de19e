//! Generalised interpolation material point method (GIMPM), explicit, 2-D plane strain, with
//! Mohr–Coulomb plasticity (thesis chapter 4; Bardenhagen & Kober 2004; Sulsky et al. 1995).
//!
//! * [`shape`]: uGIMP and standard MPM shape functions (node support sketched there);
//! * [`grid`]: the background grid (x-major node arrays), optionally periodic in x;
//! * [`points`]: material points as a structure of arrays;
//! * [`boundary`]: fixed, roller and Coulomb-frictional walls on grid nodes;
//! * [`material`]: the material contract `update_stress(σ, Δε, Δω, state) → σ` (Jaumann
//!   rate) and its laws: linear elastic, Mohr–Coulomb (non-associated, tension cut-off);
//! * [`solver`]: the explicit step (USF / USL / MUSL), CFL step, energy bookkeeping;
//! * [`scale`]: the [`crate::scale::Scale`] implementation.

pub mod boundary;
pub mod grid;
pub mod material;
pub mod points;
pub mod scale;
pub mod shape;
pub mod solver;

pub use boundary::{Side, Wall, WallKind};
pub use grid::Grid;
pub use material::{LinearElastic, Material, MaterialModel, MaterialState, MohrCoulomb};
pub use points::Points;
pub use shape::ShapeKind;
pub use solver::{cfl_step, Mpm, MpmEnergy, MpmParams, Scheme, Traction, Transfer};
