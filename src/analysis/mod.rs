//! Analysis of simulation outputs (run-out, energy budgets, spectra).
//!
//! Placeholder so that `pub mod analysis;` in `lib.rs` compiles on the `dem` branch; the
//! module itself is being written on `main`, whose version replaces this file on merge.
