//! Discrete element method for disks and convex polygons (seed eq. 5.55–5.61).
//!
//! * [`bench`]: the `granflow bench dem` case (LAMMPS `in.gran2d.lmp`);
//! * [`biaxial`]: biaxial compression of a packing, the material's friction angle;
//! * [`grains`]: the grains (disks or convex polygons) as a structure of arrays;
//! * [`shape`]: the shared polygon table and polygon mass properties;
//! * [`contact`]: the contact law (linear spring-dashpot normal force with the damping set by a
//!   restitution coefficient, tangential spring with history and Coulomb cap, rolling
//!   resistance) and the critical time step;
//! * [`walls`]: half-planes and line segments;
//! * [`neighbours`]: uniform-grid cell list and Verlet neighbour list with contact history
//!   (disk–disk and disk–straight-wall pairs);
//! * [`detect_rapier`]: rapier2d-backed detection for every shape (polygon grains and walls);
//! * [`shape_contacts`]: contact history and forces of the pairs rapier finds;
//! * [`solver`]: the system [`Dem`] and its velocity-Verlet step;
//! * [`energy`]: the energy budget;
//! * [`stress`]: per-grain Love–Weber stress tensor;
//! * [`packing`]: reproducible packings (gravity deposition, hexagonal);
//! * [`scale`]: the [`crate::scale::Scale`] implementation (sub-cycling `advance`);
//! * [`validation`]: validation cases (restitution, incline, conservation, energy budget);
//! * [`validation_polygon`]: rapier detector against the cell list, polygon physics;
//! * [`scenario`]: the column-collapse scenario (TOML) and its checks;
//! * [`run`]: the column-collapse runner (VTK series, time series, summary).

pub mod bench;
pub mod biaxial;
pub mod contact;
pub mod detect_rapier;
pub mod energy;
pub mod grains;
pub mod mu_i;
pub mod neighbours;
pub mod packing;
pub mod run;
pub mod scale;
pub mod scenario;
pub mod shape;
pub mod shape_contacts;
pub mod shear_cell;
pub mod solver;
pub mod stress;
pub mod validation;
pub mod validation_polygon;
pub mod walls;

pub use contact::{damping_ratio, restitution_of, ContactParams};
pub use energy::Energy;
pub use grains::Grains;
pub use solver::{critical_step, Dem, DemParams, ExternalLoads, Overlap, OVERLAP_LIMIT};
pub use walls::Wall;
