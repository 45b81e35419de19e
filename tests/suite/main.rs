//! The integration tests, one test binary (one link of the library instead of one per file,
//! and one pool of test threads across every file).
//!
//! Two tiers. `cargo test` runs the default tier: every test that takes a few seconds. The
//! heavier ones (validation cases at test size, whole sweeps, the resume-to-the-same-bits runs,
//! the submerged pore-pressure pair, ParaView rendering) are marked `#[ignore]` with the
//! reason `heavy tier`; `cargo test -- --ignored` runs them, and CI runs both tiers.

mod common;

mod architecture;
mod chute;
mod cli;
mod collapse_study;
mod conservation_properties;
mod continuum;
mod coupling;
mod coupling_ladd;
mod dem;
mod dem_biaxial;
mod dem_rapier;
mod dem_scenario;
mod dem_shear;
mod fuzz_scenarios;
#[cfg(feature = "gpu")]
mod gpu;
mod granular;
mod io_vtk;
mod models;
#[cfg(feature = "mpi")]
mod mpi;
mod mpm;
mod mpm_periodic;
mod multiscale;
// Xvfb and its sockets: Unix only.
#[cfg(unix)]
mod paraview;
mod resume;
mod schema;
mod submerged;
mod validate_lbm;
