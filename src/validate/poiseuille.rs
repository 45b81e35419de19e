//! poiseuille (placeholder; being written).
use super::{Check, Fidelity};
use crate::Result;
/// Run the case.
pub fn run(_f: Fidelity) -> Result<Vec<Check>> {
    Err(crate::Error::Other(
        "poiseuille: not implemented yet".into(),
    ))
}
