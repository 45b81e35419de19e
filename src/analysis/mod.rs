//! Post-processing: spectral analysis of time series (shedding frequencies), the run-out
//! history of a column collapse and its run-out laws, and Bagnold's profile of a chute flow.

pub mod bagnold;
pub mod powerlaw;
pub mod runout;
pub mod spectrum;
