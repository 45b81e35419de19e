//! Cylinder cases (placeholder; being written).
use super::{Check, Fidelity};
use crate::Result;
/// Schäfer–Turek 2D-1.
pub fn run_2d1(_f: Fidelity) -> Result<Vec<Check>> {
    Err(crate::Error::Other(
        "cylinder-2d1: not implemented yet".into(),
    ))
}
/// Sangani–Acrivos array.
pub fn run_array(_f: Fidelity) -> Result<Vec<Check>> {
    Err(crate::Error::Other(
        "cylinder-array: not implemented yet".into(),
    ))
}
/// Shedding.
pub fn run_shedding(_f: Fidelity) -> Result<Vec<Check>> {
    Err(crate::Error::Other("shedding: not implemented yet".into()))
}
