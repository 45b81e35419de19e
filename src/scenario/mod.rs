//! The scenario storey: what a user writes and runs. Scenario files are TOML in SI units,
//! `deny_unknown_fields`, with no silent defaults for physical parameters; each says what it
//! is on its first line, `kind = "fluid" | "dem" | "mpm" | "submerged" | "granular" |
//! "continuum" | "sweep"`
//! ([`Kind`]), so a typo gets the error of the kind it is.
//!
//! Per kind, a folder holds the file's schema (`spec.rs`: parse, check every value, derive
//! what the solvers need, refusing with the field named anything unstable or meaningless),
//! its benchmark and its validation cases:
//!
//! * [`fluid`]: LBM flows (channel, cavity, cylinders) and their runner;
//! * [`dem`]: the DEM column collapse, and the material tests on its grains
//!   (`granflow biaxial`, `granflow shear`);
//! * [`mpm`]: the GIMPM column collapse;
//! * [`submerged`]: the LBM–DEM submerged collapse;
//! * [`granular`]: DEM problems of any geometry (silo, hopper, chute, obstacles): regions,
//!   walls, gates and outlets as data;
//! * [`continuum`]: MPM problems of any geometry (slopes, layers, blocks): domain, sides,
//!   regions, gravity and its tilt as data;
//! * [`collapse`]: the one column-collapse runner, for the DEM, MPM and submerged solids;
//! * [`validation`]: the registry of validation cases (`granflow validate`);
//! * [`checkpointing`]: checkpoints, resume and the stop signals ask for;
//! * [`overrides`]: keys changed on the command line (`--set`);
//! * [`schema`]: the JSON Schema of each kind and the Markdown key reference made from it
//!   (`granflow schema`).
//!
//! Studies over many scenarios are in [`crate::sweep`]. Nothing in the physics storey
//! (`lbm`, `dem`, `mpm`, `coupling`) imports this module.

pub mod checkpointing;
pub mod collapse;
pub mod continuum;
pub mod dem;
pub mod field;
pub mod fluid;
pub mod granular;
pub mod mpm;
pub mod overrides;
pub mod schema;
pub mod submerged;
pub mod validation;

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::units::Units;
use crate::{Error, Result};

/// What a scenario file describes: its top-level `kind` key.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// A lattice Boltzmann flow ([`fluid::Scenario`]).
    Fluid,
    /// A DEM column collapse ([`dem::DemScenario`]).
    Dem,
    /// A GIMPM column collapse ([`mpm::MpmScenario`]).
    Mpm,
    /// A submerged (LBM–DEM) column collapse ([`submerged::SubmergedScenario`]).
    Submerged,
    /// A DEM problem of any geometry: regions, walls, gates, outlets
    /// ([`granular::GranularScenario`]).
    Granular,
    /// An MPM problem of any geometry: domain, sides, regions, tilting gravity
    /// ([`continuum::ContinuumScenario`]).
    Continuum,
    /// A study over many collapse scenarios ([`crate::sweep::SweepSpec`]).
    Sweep,
}

impl Kind {
    /// Every kind, in the order the documentation lists them.
    pub const ALL: [Kind; 7] = [
        Kind::Fluid,
        Kind::Dem,
        Kind::Mpm,
        Kind::Submerged,
        Kind::Granular,
        Kind::Continuum,
        Kind::Sweep,
    ];

    /// The value of the `kind` key.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Fluid => "fluid",
            Kind::Dem => "dem",
            Kind::Mpm => "mpm",
            Kind::Submerged => "submerged",
            Kind::Granular => "granular",
            Kind::Continuum => "continuum",
            Kind::Sweep => "sweep",
        }
    }

    /// The kind a file without a `kind` key most likely is, from its tables (for the hint in
    /// the error; nothing is guessed silently).
    fn guess(table: &toml::Table) -> Kind {
        if table.contains_key("solvers") {
            Kind::Sweep
        } else if table.contains_key("coupling") {
            Kind::Submerged
        } else if table.contains_key("domain") {
            Kind::Continuum
        } else if table.contains_key("wall") || table.contains_key("fill") {
            Kind::Granular
        } else if table.contains_key("grains") {
            Kind::Dem
        } else if table.contains_key("material") {
            Kind::Mpm
        } else {
            Kind::Fluid
        }
    }
}

impl std::fmt::Display for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A scenario file's schema: one type per [`Kind`]. Its JSON Schema ([`schema::of`]) is
/// generated from the same type, so the key reference cannot drift from the parser.
pub trait ScenarioFile: serde::de::DeserializeOwned + schemars::JsonSchema {
    /// The `kind` its files declare.
    const KIND: Kind;

    /// Parse scenario text of this kind; a file of another kind is refused, naming both.
    fn from_toml(text: &str) -> Result<Self> {
        let kind = kind_of(text)?;
        if kind != Self::KIND {
            return Err(Error::config(
                "kind",
                format!(
                    "this is a `{kind}` file, where a `{}` file is needed",
                    Self::KIND
                ),
            ));
        }
        parse_toml(text)
    }

    /// Read and parse a scenario file of this kind; errors name the file.
    fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::from_text(&text, path)
    }

    /// Parse the text of the scenario file at `path` (as read by [`read_file`]); errors name
    /// the file.
    fn from_text(text: &str, path: &Path) -> Result<Self> {
        Self::from_toml(text).map_err(|e| in_file(e, path))
    }
}

/// The `kind` a scenario text declares. A file without one is refused with the line to add
/// (the kind its tables suggest).
pub fn kind_of(text: &str) -> Result<Kind> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| Error::Parse {
        path: "<text>".into(),
        message: e.to_string(),
    })?;
    let names = Kind::ALL.map(|k| format!("\"{k}\"")).join(", ");
    match table.get("kind") {
        None => Err(Error::config(
            "kind",
            format!(
                "missing: a scenario file says what it is on its first line, one of {names} \
                 (this one looks like `kind = \"{}\"`)",
                Kind::guess(&table)
            ),
        )),
        Some(v) => v
            .clone()
            .try_into::<Kind>()
            .map_err(|_| Error::config("kind", format!("must be one of {names}, got {v}"))),
    }
}

/// The `kind` of a scenario file; errors name the file.
pub fn kind_of_file(path: &Path) -> Result<Kind> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    kind_of(&text).map_err(|e| in_file(e, path))
}

/// The kind and text of the scenario file at `path` with the keys `overrides` changes
/// ([`overrides::apply`]); errors name the file.
pub fn read_file(path: &Path, overrides: &[overrides::Override]) -> Result<(Kind, String)> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let text = overrides::apply(&text, overrides).map_err(|e| in_file(e, path))?;
    let kind = kind_of(&text).map_err(|e| in_file(e, path))?;
    Ok((kind, text))
}

/// A parse error of `<text>` as an error of `path`.
fn in_file(e: Error, path: &Path) -> Error {
    match e {
        Error::Parse { message, .. } => Error::Parse {
            path: path.to_path_buf(),
            message,
        },
        other => other,
    }
}

/// The lattice units of a scenario: Δx, the liquid's ν and ρ, and exactly one of τ or Δt (the
/// keys `tau` and `dt` of `table`). Refuses τ ≤ ½ (given or implied) and a τ above 1000 (a
/// step far too large for the viscosity).
pub(crate) fn lattice_units(
    table: &str,
    dx: f64,
    tau: Option<f64>,
    dt: Option<f64>,
    nu: f64,
    rho: f64,
) -> Result<Units> {
    let units = match (tau, dt) {
        (Some(tau), None) => {
            if !(tau > 0.5 && tau.is_finite()) {
                return Err(Error::config(
                    format!("{table}.tau"),
                    format!("τ = {tau} must exceed ½ (ν = (τ − ½)/3 > 0)"),
                ));
            }
            Units::from_tau(dx, tau, nu, rho)
        }
        (None, Some(dt)) => {
            positive(&format!("{table}.dt"), dt)?;
            Units::from_dt(dx, dt, nu, rho)
        }
        _ => {
            return Err(Error::config(
                format!("{table}.tau"),
                "give exactly one of `tau` and `dt`",
            ))
        }
    };
    let tau = units.tau;
    if tau.is_nan() || tau <= 0.5 {
        return Err(Error::config(
            format!("{table}.dt"),
            format!("gives τ = {tau} ≤ ½"),
        ));
    }
    if tau > 1e3 {
        return Err(Error::config(
            format!("{table}.dt"),
            format!("gives τ = {tau:.3e}: the time step is far too large for this viscosity"),
        ));
    }
    Ok(units)
}

/// Refuse `v` unless it is finite and > 0, naming `field` (the scenario key).
/// Most lattice cells a scenario may ask for: ≈ 370 TB at 367 bytes per cell, so only a
/// mistyped cell size reaches it.
const MAX_CELLS: f64 = 1e12;

/// Refuses a lattice of `nx` × `ny` cells beyond [`MAX_CELLS`], naming the cell size `field`.
pub(crate) fn check_cells(field: &str, nx: usize, ny: usize) -> Result<()> {
    let n = nx as f64 * ny as f64;
    if n > MAX_CELLS {
        return Err(Error::config(
            field,
            format!("{nx} × {ny} = {n:.3e} cells, more than the {MAX_CELLS:e} a run can hold"),
        ));
    }
    Ok(())
}

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
fn parse_toml<T: serde::de::DeserializeOwned>(text: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| Error::Parse {
        path: "<text>".into(),
        message: e.to_string(),
    })
}
