//! The column-collapse runners.

pub mod dem;
pub mod mpm;
pub mod submerged;
