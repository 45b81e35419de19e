//! The sweep file (`granflow sweep <sweep.toml>`): a base scenario per solver and the fields to
//! vary, expanded into one fully resolved scenario per case.
//!
//! ```toml
//! kind = "sweep"
//! name = "sweep_quick"
//! description = "…"
//!
//! [solvers]                    # base scenarios, relative to this file
//! dem = "dem_a2.toml"
//! mpm = "mpm_a2.toml"
//!
//! [set]                        # optional: fixed overrides for every case
//! "dem.time.end_tc" = 12.0
//!
//! [[vary]]                     # one dimension; its lists vary together (same length)
//! "column.aspect_ratio" = [0.5, 1, 2]
//! "column.width" = [0.055, 0.039, 0.031]
//!
//! [[vary]]                     # a second dimension: the cases are the Cartesian product
//! "dem.grain_contact.friction" = [0.3, 0.53]
//! ```
//!
//! A key is a dotted path to a field of the base scenario (`column.aspect_ratio`), or the same
//! prefixed by a solver name (`dem.grain_contact.friction`) to apply to that solver only. The
//! field must exist in the base (so a misspelt path is an error, not a silently ignored
//! setting), and the value must be a scalar of the same kind (a number for a number). Each
//! case's scenario is then read by the solver's own parser, with its checks.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Value;

use crate::scenario::{Kind, ScenarioFile};
use crate::{Error, Result};

/// The solvers a sweep can run.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    /// The DEM column collapse (`dem::run`).
    Dem,
    /// The MPM column collapse (`mpm::run`).
    Mpm,
    /// The MPM column collapse with a DEM representative volume at every point (an MPM file
    /// with `material.model = "rve"`).
    Rve,
}

impl Solver {
    /// Every solver, in case order.
    pub const ALL: [Solver; 3] = [Solver::Dem, Solver::Mpm, Solver::Rve];

    /// `"dem"`, `"mpm"` or `"rve"`.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Dem => "dem",
            Solver::Mpm => "mpm",
            Solver::Rve => "rve",
        }
    }
}

/// The sweep file as written.
#[derive(Clone, Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// `"sweep"`: what the file describes.
    pub kind: Kind,
    /// Sweep name.
    pub name: String,
    /// One line on what it is for.
    pub description: String,
    /// Base scenario per solver, relative to the sweep file.
    #[schemars(schema_with = "solvers_schema")]
    pub solvers: BTreeMap<Solver, PathBuf>,
    /// Fixed overrides applied to every case (path → value).
    #[serde(default)]
    #[schemars(schema_with = "set_schema")]
    pub set: BTreeMap<String, Value>,
    /// The varied dimensions (path → values; the lists of one table vary together).
    #[schemars(schema_with = "vary_schema")]
    pub vary: Vec<BTreeMap<String, Vec<Value>>>,
}

/// `[solvers]`: one optional key per [`Solver`], its name, each a path (at least one).
fn solvers_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
    let solver = <Solver as schemars::JsonSchema>::json_schema(generator);
    let variants = solver.get("oneOf").and_then(|v| v.as_array());
    let mut properties = serde_json::Map::new();
    for s in Solver::ALL {
        let doc = variants
            .into_iter()
            .flatten()
            .find(|v| v.get("const").and_then(|c| c.as_str()) == Some(s.name()))
            .and_then(|v| v.get("description"))
            .and_then(|d| d.as_str())
            .unwrap_or_default();
        let description = format!("Path of the base scenario, relative to this file. {doc}");
        properties.insert(
            s.name().to_owned(),
            serde_json::json!({ "type": "string", "description": description }),
        );
    }
    schemars::json_schema!({
        "type": "object",
        "properties": properties,
        "additionalProperties": false,
        "minProperties": 1,
    })
}

/// A value the sweep puts into a base scenario: a number, a string or a boolean, where the base
/// has the same kind of scalar ([`set_field`]).
fn scalar_schema() -> serde_json::Value {
    serde_json::json!({ "type": ["number", "string", "boolean"] })
}

/// What a key of `[set]` or `[[vary]]` is.
const PATH_KEY: &str = "The key is a dotted path to a value of the base scenario \
    (`column.width`), or the same after a solver's name to change that solver's base only \
    (`dem.grain_contact.friction`); the value must be of the same kind as the base's (a number \
    for a number, a string for a string, a boolean for a boolean).";

/// `[set]`: dotted path → value.
fn set_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
    schemars::json_schema!({
        "type": "object",
        "additionalProperties": { "description": PATH_KEY, "allOf": [scalar_schema()] },
    })
}

/// `[[vary]]`: at least one table of dotted path → non-empty list of values.
fn vary_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
    schemars::json_schema!({
        "type": "array",
        "minItems": 1,
        "items": {
            "type": "object",
            "minProperties": 1,
            "additionalProperties": {
                "description": format!("{PATH_KEY} The lists of one table have the same length: \
                    case k takes the k-th value of each."),
                "type": "array",
                "minItems": 1,
                "items": scalar_schema(),
            },
        },
    })
}

/// One case: a solver and its resolved scenario.
#[derive(Clone, Debug)]
pub struct Case {
    /// Folder name, e.g. `dem_a0.5` or `mpm_a2_friction0.3`.
    pub name: String,
    /// The solver.
    pub solver: Solver,
    /// The resolved scenario (TOML text, with `name` set to the case name).
    pub scenario: String,
    /// The varied values of this case, (path, value) per dimension's first key.
    pub labels: Vec<(String, Value)>,
}

impl Case {
    /// Parse the case's scenario as its solver's kind and derive it (what `granflow check`
    /// does for a file): a bad value is refused naming the case and the key.
    pub fn check(&self) -> Result<()> {
        match self.solver {
            Solver::Dem => crate::scenario::dem::DemScenario::from_toml(&self.scenario)?
                .derive()
                .map(|_| ()),
            solver => crate::scenario::mpm::MpmScenario::from_toml(&self.scenario)?
                .derive()
                .and_then(|d| {
                    let rve = matches!(d.material, crate::scenario::mpm::spec::Law::Volume(_));
                    if rve == (solver == Solver::Rve) {
                        Ok(())
                    } else {
                        Err(err(
                            "material.model",
                            "the `rve` solver takes MPM files with model = \"rve\", the `mpm` \
                             solver the others",
                        ))
                    }
                }),
        }
        .map_err(|e| Error::Other(format!("case `{}`: {e}", self.name)))
    }
}

impl ScenarioFile for SweepSpec {
    const KIND: Kind = Kind::Sweep;
}

/// Reads and expands a sweep file into its cases (in solver, then dimension order).
pub fn read_sweep(path: &Path) -> Result<(SweepSpec, Vec<Case>)> {
    let spec = SweepSpec::from_file(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let cases = expand(&spec, dir)?;
    Ok((spec, cases))
}

fn err(field: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::config(field, reason)
}

/// Splits `key` into (solver it is limited to, path in the scenario).
fn split(key: &str) -> (Option<Solver>, &str) {
    for s in Solver::ALL {
        if let Some(rest) = key.strip_prefix(s.name()).and_then(|r| r.strip_prefix('.')) {
            return (Some(s), rest);
        }
    }
    (None, key)
}

/// Sets the existing field at dotted `path` of `table` to `value` (same kind of scalar).
fn set_field(
    table: &mut toml::Table,
    path: &str,
    value: &Value,
) -> std::result::Result<(), String> {
    let mut parts = path.split('.').peekable();
    let mut t = table;
    while let Some(part) = parts.next() {
        let Some(slot) = t.get_mut(part) else {
            return Err(format!("the base scenario has no field `{part}` here"));
        };
        if parts.peek().is_none() {
            let same = matches!(
                (&*slot, value),
                (
                    Value::Float(_) | Value::Integer(_),
                    Value::Float(_) | Value::Integer(_)
                ) | (Value::String(_), Value::String(_))
                    | (Value::Boolean(_), Value::Boolean(_))
            );
            if !same {
                return Err(format!(
                    "cannot put {} where the base has {}",
                    value.type_str(),
                    slot.type_str()
                ));
            }
            *slot = value.clone();
            return Ok(());
        }
        t = match slot {
            Value::Table(inner) => inner,
            other => return Err(format!("`{part}` is a {}, not a table", other.type_str())),
        };
    }
    Err("empty path".into())
}

/// Short form of a path for case names: its last segment, `a` for `aspect_ratio`.
fn short(path: &str) -> &str {
    match path.rsplit('.').next().unwrap_or(path) {
        "aspect_ratio" => "a",
        s => s,
    }
}

fn show(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Float(f) => format!("{f}"),
        other => other.to_string(),
    }
}

/// Expands `spec` into its cases; base paths are relative to `dir`.
pub fn expand(spec: &SweepSpec, dir: &Path) -> Result<Vec<Case>> {
    if spec.solvers.is_empty() {
        return Err(err(
            "solvers",
            "name at least one base scenario (dem, mpm, rve)",
        ));
    }
    if spec.vary.is_empty() {
        return Err(err("vary", "give at least one [[vary]] table"));
    }
    for (d, dim) in spec.vary.iter().enumerate() {
        let mut lens = dim.values().map(Vec::len);
        let n = lens.next().unwrap_or(0);
        if n == 0 || lens.any(|m| m != n) {
            return Err(err(
                format!("vary[{d}]"),
                "needs at least one path, each with the same (non-zero) number of values",
            ));
        }
    }
    let mut cases = Vec::new();
    for (&solver, base) in &spec.solvers {
        let base_path = dir.join(base);
        let text = std::fs::read_to_string(&base_path).map_err(|e| {
            err(
                format!("solvers.{}", solver.name()),
                format!("cannot read {}: {e}", base_path.display()),
            )
        })?;
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            err(format!("solvers.{}", solver.name()), e.to_string())
        })?;
        let mine = |key: &str| match split(key) {
            (Some(s), p) if s == solver => Some(p.to_owned()),
            (Some(_), _) => None,
            (None, p) => Some(p.to_owned()),
        };
        let mut fixed = table;
        for (key, value) in &spec.set {
            if let Some(p) = mine(key) {
                set_field(&mut fixed, &p, value).map_err(|r| {
                    err(
                        format!("set.\"{key}\""),
                        format!("{r} ({})", base.display()),
                    )
                })?;
            }
        }
        // Dimensions that concern this solver, as (keys, number of values).
        let dims: Vec<&BTreeMap<String, Vec<Value>>> = spec
            .vary
            .iter()
            .filter(|dim| dim.keys().any(|k| mine(k).is_some()))
            .collect();
        let total: usize = dims
            .iter()
            .map(|d| d.values().next().map_or(1, Vec::len))
            .product();
        for index in 0..total {
            let mut t = fixed.clone();
            let (mut rest, mut name, mut labels) = (index, solver.name().to_owned(), Vec::new());
            for dim in &dims {
                let n = dim.values().next().map_or(1, Vec::len);
                let k = rest % n;
                rest /= n;
                let mut first = true;
                for (key, values) in dim.iter() {
                    let Some(p) = mine(key) else { continue };
                    set_field(&mut t, &p, &values[k]).map_err(|r| {
                        err(
                            format!("vary.\"{key}\""),
                            format!("{r} ({})", base.display()),
                        )
                    })?;
                    if first {
                        name.push_str(&format!("_{}{}", short(&p), show(&values[k])));
                        labels.push((p.clone(), values[k].clone()));
                        first = false;
                    }
                }
            }
            t.insert("name".into(), Value::String(name.clone()));
            cases.push(Case {
                name,
                solver,
                scenario: toml::to_string(&t).map_err(|e| Error::Other(e.to_string()))?,
                labels,
            });
        }
    }
    let mut names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return Err(err(
            "vary",
            format!("two cases would share the name `{}`", w[0]),
        ));
    }
    Ok(cases)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(text: &str) -> SweepSpec {
        toml::from_str(text).unwrap()
    }

    fn write(dir: &Path, name: &str, text: &str) {
        std::fs::write(dir.join(name), text).unwrap();
    }

    #[test]
    fn expands_zipped_and_crossed_dimensions_per_solver() {
        let dir = tempfile::tempdir().unwrap();
        write(dir.path(), "d.toml", "name = \"d\"\n[column]\naspect_ratio = 2\nwidth = 0.1\n[grain_contact]\nfriction = 0.5\n");
        write(
            dir.path(),
            "m.toml",
            "name = \"m\"\n[column]\naspect_ratio = 2\nwidth = 0.1\n",
        );
        let s = spec(
            r#"
            kind = "sweep"
            name = "s"
            description = "x"
            [solvers]
            dem = "d.toml"
            mpm = "m.toml"
            [set]
            "column.width" = 0.2
            [[vary]]
            "column.aspect_ratio" = [0.5, 4]
            "mpm.column.width" = [0.3, 0.4]
            [[vary]]
            "dem.grain_contact.friction" = [0.1, 0.2, 0.3]
            "#,
        );
        let cases = expand(&s, dir.path()).unwrap();
        let names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "dem_a0.5_friction0.1",
                "dem_a4_friction0.1",
                "dem_a0.5_friction0.2",
                "dem_a4_friction0.2",
                "dem_a0.5_friction0.3",
                "dem_a4_friction0.3",
                "mpm_a0.5",
                "mpm_a4"
            ]
        );
        let t: toml::Table = cases[3].scenario.parse().unwrap();
        assert_eq!(t["name"].as_str(), Some("dem_a4_friction0.2"));
        assert_eq!(t["column"]["aspect_ratio"].as_integer(), Some(4));
        assert_eq!(t["column"]["width"].as_float(), Some(0.2));
        assert_eq!(t["grain_contact"]["friction"].as_float(), Some(0.2));
        let m: toml::Table = cases[7].scenario.parse().unwrap();
        assert_eq!(m["column"]["width"].as_float(), Some(0.4));
    }

    #[test]
    fn refuses_unknown_paths_mismatched_kinds_and_ragged_lists() {
        let dir = tempfile::tempdir().unwrap();
        write(
            dir.path(),
            "d.toml",
            "name = \"d\"\n[column]\naspect_ratio = 2\n",
        );
        let base =
            "kind = \"sweep\"\nname = \"s\"\ndescription = \"x\"\n[solvers]\ndem = \"d.toml\"\n";
        let msg = |extra: &str| {
            expand(&spec(&format!("{base}{extra}")), dir.path())
                .unwrap_err()
                .to_string()
        };
        let m = msg("[[vary]]\n\"column.aspectratio\" = [1.0]\n");
        assert!(
            m.contains("column.aspectratio") && m.contains("no field"),
            "{m}"
        );
        let m = msg("[[vary]]\n\"column.aspect_ratio\" = [\"tall\"]\n");
        assert!(m.contains("cannot put string"), "{m}");
        let m = msg("[[vary]]\n\"column.aspect_ratio\" = [1.0, 2.0]\n\"name\" = [\"x\"]\n");
        assert!(m.contains("vary[0]"), "{m}");
        let bad: std::result::Result<SweepSpec, _> = toml::from_str(&format!(
            "{base}typo = 1\n[[vary]]\n\"column.aspect_ratio\" = [1.0]\n"
        ));
        assert!(bad.is_err());
    }
}
