//! Lid-driven cavity (placeholder; being written).
use super::{Check, Fidelity};
use crate::Result;
/// Re 100.
pub fn run_re100(_f: Fidelity) -> Result<Vec<Check>> {
    Err(crate::Error::Other(
        "cavity-re100: not implemented yet".into(),
    ))
}
/// Re 1000.
pub fn run_re1000(_f: Fidelity) -> Result<Vec<Check>> {
    Err(crate::Error::Other(
        "cavity-re1000: not implemented yet".into(),
    ))
}
