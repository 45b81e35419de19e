//! Scenario files: TOML, SI units, `deny_unknown_fields`, no silent defaults for physics.
//!
//! [`Scenario::from_file`] parses; [`Scenario::derive`] checks every value and derives the
//! lattice quantities ([`Derived`]), refusing — with the field named — anything unstable or
//! meaningless. `granflow check` prints the result. The format is documented in
//! `docs/scenario-format.md`; every file under `models/` is parsed and checked by the tests.

mod fluid;

pub use fluid::*;

use std::path::Path;

use crate::{Error, Result};

impl Scenario {
    /// Parse a scenario file.
    pub fn from_file(path: &Path) -> Result<Self> {
        read_toml(path)
    }

    /// Parse scenario text.
    pub fn from_toml(text: &str) -> Result<Self> {
        parse_toml(text)
    }
}

/// Refuse `v` unless it is finite and > 0, naming `field` (the scenario key).
pub(crate) fn positive(field: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::config(
            field,
            format!("must be a finite positive number (> 0), got {v}"),
        ))
    }
}

/// Refuse `v` unless it is finite and ≥ 0, naming `field` (the scenario key).
pub(crate) fn non_negative(field: &str, v: f64) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(Error::config(
            field,
            format!("must be finite and ≥ 0, got {v}"),
        ))
    }
}

/// Parse TOML text into a scenario type; the error carries the parser's message, which names
/// the line and the key (unknown, missing or mistyped).
pub fn parse_toml<T: serde::de::DeserializeOwned>(text: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| Error::Parse {
        path: "<text>".into(),
        message: e.to_string(),
    })
}

/// Read and parse a scenario file (see [`parse_toml`]); errors name the file.
pub fn read_toml<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_toml(&text).map_err(|e| match e {
        Error::Parse { message, .. } => Error::Parse {
            path: path.to_path_buf(),
            message,
        },
        other => other,
    })
}
