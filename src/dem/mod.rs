//! Discrete element method for disks and convex polygons (seed eq. 5.55–5.61).
//!
//! * [`grains`]: the grains (disks or convex polygons) as a structure of arrays;
//! * [`shape`]: the shared polygon table and polygon mass properties;
//! * [`contact`]: the contact law (linear spring-dashpot normal force with the damping set by a
//!   restitution coefficient, tangential spring with history and Coulomb cap, rolling
//!   resistance) and the critical step of one spring;
//! * [`params`]: the parameters of a system (contact laws, gravity, step rule, skin);
//! * [`time_step`]: the DEM time step Δt_D = λ Δt_cr, derived in one place;
//! * [`walls`]: half-planes and line segments;
//! * [`neighbours`]: uniform-grid cell list and Verlet neighbour list with contact history
//!   (disk–disk and disk–straight-wall pairs);
//! * [`detect_rapier`]: rapier2d-backed detection for every shape (polygon grains and walls);
//! * [`shape_contacts`]: contact history and forces of the pairs rapier finds;
//! * [`solver`]: the system [`Dem`] and its velocity-Verlet step;
//! * [`energy`]: the energy budget;
//! * [`stress`]: per-grain Love–Weber stress tensor;
//! * [`packing`]: reproducible packings (gravity deposition, hexagonal);
//! * [`shear_cell`]: the bi-periodic Lees–Edwards simple-shear cell;
//! * [`periodic_cell`]: the bi-periodic cell under any imposed velocity gradient (the
//!   representative volume of the multi-scale material) and its preparation;
//! * [`scale`]: the [`crate::scale::Scale`] implementation (sub-cycling `advance`).

pub mod contact;
pub mod detect_rapier;
pub mod energy;
pub mod grains;
pub mod neighbours;
pub mod packing;
pub mod params;
pub mod periodic_cell;
pub mod scale;
pub mod shape;
pub mod shape_contacts;
pub mod shear_cell;
pub mod solver;
pub mod stress;
pub mod time_step;
pub mod walls;

pub use contact::{damping_ratio, restitution_of, ContactParams};
pub use energy::Energy;
pub use grains::Grains;
pub use params::DemParams;
pub use solver::{Dem, ExternalLoads, Overlap, OVERLAP_LIMIT};
pub use time_step::{critical_step, TimeStep};
pub use walls::Wall;
