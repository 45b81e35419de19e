//! Post-processing: spectral analysis of time series (shedding frequencies).

pub mod spectrum;
