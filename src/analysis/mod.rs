//! Post-processing: spectral analysis of time series (shedding frequencies) and the run-out
//! history of a column collapse.

pub mod runout;
pub mod spectrum;
