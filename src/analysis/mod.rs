//! Post-processing: spectral analysis of time series (shedding frequencies) and the run-out
//! history of a column collapse and its run-out laws.

pub mod powerlaw;
pub mod runout;
pub mod spectrum;
