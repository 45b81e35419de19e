//! `--set KEY=VALUE`: a scenario's keys changed on the command line.
//!
//! An override is applied to the scenario's text, which is then read as the file is: an
//! unknown key or a bad value is refused by the kind's schema (`deny_unknown_fields`, the
//! checks of its `spec.rs`) with the key named, as in a file. The text keeps its comments and
//! layout, so the copy a run keeps in its output folder shows what was run, with the
//! overrides listed in a comment at its top.
//!
//! `KEY` is a dotted path of table keys (`grain_contact.friction`, `vtk.compression`); a number picks
//! an element of an array (`obstacles.0.radius`). A table that the file does not have is
//! added. `VALUE` is a TOML value (`0.4`, `2e-3`, `true`, `"lz4"`, `[0.0, -9.81]`); a bare
//! word (`mrt`) is taken as a string.

use toml_edit::{DocumentMut, Item, Table, Value};

use crate::{Error, Result};

/// One `KEY=VALUE` of the command line.
#[derive(Clone, Debug)]
pub struct Override {
    /// The dotted path, split.
    pub path: Vec<String>,
    /// The value as written.
    pub text: String,
    value: Value,
}

impl std::str::FromStr for Override {
    type Err = String;

    /// Parse `KEY=VALUE`; the message says what is wrong.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let (key, text) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}` is not KEY=VALUE (e.g. time.end=2.0)"))?;
        let (key, text) = (key.trim(), text.trim());
        let path: Vec<String> = key.split('.').map(|p| p.trim().to_string()).collect();
        if path.iter().any(|p| p.is_empty()) {
            return Err(format!(
                "`{key}`: a key is table names and a key joined by dots"
            ));
        }
        if path == ["kind"] {
            return Err("`kind` cannot be set: it says which schema reads the file".into());
        }
        Ok(Override {
            path,
            text: text.to_string(),
            value: value_of(text).map_err(|why| format!("`{key}={text}`: {why}"))?,
        })
    }
}

/// A TOML value, or a bare word as a string.
fn value_of(text: &str) -> std::result::Result<Value, String> {
    if let Ok(mut v) = text.parse::<Value>() {
        v.decor_mut().clear();
        return Ok(v);
    }
    let bare = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '+' | '/' | '.'));
    if bare {
        Ok(Value::from(text))
    } else {
        Err("the value is not a TOML value (quote a string: key=\"text\")".into())
    }
}

/// The scenario `text` with `overrides` applied, in order, and listed in a comment at its
/// top. A path through a value that is not a table or array, an array index out of range,
/// or a table replaced by a value is refused naming the key.
pub fn apply(text: &str, overrides: &[Override]) -> Result<String> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| Error::Parse {
            path: "<text>".into(),
            message: e.to_string(),
        })?;
    let mut head = String::from("# run with overrides (granflow --set):\n");
    for o in overrides {
        in_table(doc.as_table_mut(), &o.path, 0, &o.value)
            .map_err(|(at, why)| refusal(&o.path, at, why))?;
        head += &format!("#   {}={}\n", o.path.join("."), o.text);
    }
    Ok(head + &doc.to_string())
}

/// Why `path[..=at]` cannot hold the value.
type Refused = (usize, &'static str);

fn refusal(path: &[String], at: usize, why: &str) -> Error {
    Error::config(
        path.join("."),
        format!("cannot set it: `{}` {why}", path[..=at].join(".")),
    )
}

/// Set `path[at..]` in `table`, the table at `path[..at]`.
fn in_table(
    table: &mut Table,
    path: &[String],
    at: usize,
    value: &Value,
) -> std::result::Result<(), Refused> {
    let item = table.entry(&path[at]).or_insert(Item::None);
    let last = at + 1 == path.len();
    match item {
        Item::Table(_) | Item::ArrayOfTables(_) if last => {
            Err((at, "is a table: set one of its keys"))
        }
        Item::None | Item::Value(_) if last => {
            replace(item, value);
            Ok(())
        }
        Item::None => {
            *item = Item::Table(Table::new());
            let Item::Table(t) = item else { unreachable!() };
            in_table(t, path, at + 1, value)
        }
        Item::Table(t) => in_table(t, path, at + 1, value),
        Item::ArrayOfTables(a) => {
            let n = a.len();
            let t = index(&path[at + 1], n)
                .and_then(|k| a.get_mut(k))
                .ok_or((at + 1, "is not an index of the array"))?;
            if at + 2 == path.len() {
                return Err((at + 1, "is a table: set one of its keys"));
            }
            in_table(t, path, at + 2, value)
        }
        Item::Value(v) => in_value(v, path, at + 1, value),
    }
}

/// Set `path[at..]` in `v`, the inline table or array at `path[..at]`.
fn in_value(
    v: &mut Value,
    path: &[String],
    at: usize,
    value: &Value,
) -> std::result::Result<(), Refused> {
    let last = at + 1 == path.len();
    let child = match v {
        Value::InlineTable(t) => t
            .entry(&path[at])
            .or_insert_with(|| toml_edit::InlineTable::new().into()),
        Value::Array(a) => {
            let n = a.len();
            index(&path[at], n)
                .and_then(|k| a.get_mut(k))
                .ok_or((at, "is not an index of the array"))?
        }
        _ => return Err((at - 1, "is a value, not a table")),
    };
    if last {
        let decor = child.decor().clone();
        *child = value.clone();
        *child.decor_mut() = decor;
        Ok(())
    } else {
        in_value(child, path, at + 1, value)
    }
}

/// `item` (a value or nothing) becomes `value`, keeping a value's comment and spacing.
fn replace(item: &mut Item, value: &Value) {
    let mut v = value.clone();
    if let Item::Value(old) = item {
        *v.decor_mut() = old.decor().clone();
    }
    *item = Item::Value(v);
}

/// `part` as an index below `n`.
fn index(part: &str, n: usize) -> Option<usize> {
    part.parse().ok().filter(|&k| k < n)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"kind = "fluid"
body_acceleration = [8.0e-6, 0.0]

[time]
tau = 0.8 # relaxation time
end = 40.0

[boundaries]
left = { type = "periodic" }

[[obstacles]]
name = "post"
radius = 0.001
"#;

    fn with(sets: &[&str]) -> Result<toml::Table> {
        let o: Vec<Override> = sets.iter().map(|s| s.parse().unwrap()).collect();
        Ok(apply(TEXT, &o)?.parse().unwrap())
    }

    fn refused(set: &str) -> String {
        let o: Override = set.parse().unwrap();
        apply(TEXT, &[o]).unwrap_err().to_string()
    }

    /// Every kind of place a key can be in a file takes a value, and nothing else changes.
    #[test]
    fn sets_values_in_tables_inline_tables_arrays_and_new_tables() {
        let t = with(&[
            "time.tau=0.65",
            "boundaries.left.type=wall",
            "obstacles.0.radius=2e-3",
            "body_acceleration.1=-1e-6",
            "vtk.compression=\"lz4\"",
            "lbm.collision=mrt",
        ])
        .unwrap();
        assert_eq!(t["time"]["tau"].as_float(), Some(0.65));
        assert_eq!(t["time"]["end"].as_float(), Some(40.0));
        assert_eq!(t["boundaries"]["left"]["type"].as_str(), Some("wall"));
        assert_eq!(t["obstacles"][0]["radius"].as_float(), Some(2e-3));
        assert_eq!(t["obstacles"][0]["name"].as_str(), Some("post"));
        assert_eq!(t["body_acceleration"][1].as_float(), Some(-1e-6));
        assert_eq!(t["vtk"]["compression"].as_str(), Some("lz4"));
        assert_eq!(t["lbm"]["collision"].as_str(), Some("mrt"));
    }

    /// The text keeps its comments and lists the overrides at its top.
    #[test]
    fn the_text_records_the_overrides_and_keeps_comments() {
        let o: Vec<Override> = vec!["time.tau=0.65".parse().unwrap()];
        let text = apply(TEXT, &o).unwrap();
        assert!(text.starts_with("# run with overrides (granflow --set):\n#   time.tau=0.65\n"));
        assert!(text.contains("tau = 0.65 # relaxation time"), "{text}");
        assert_eq!(apply(TEXT, &[]).unwrap(), TEXT);
    }

    /// What cannot be set is refused with the key and the reason.
    #[test]
    fn impossible_paths_are_refused_naming_the_key() {
        let e = refused("time.tau.x=1");
        assert!(
            e.contains("time.tau.x") && e.contains("`time.tau` is a value"),
            "{e}"
        );
        let e = refused("obstacles.3.radius=1");
        assert!(e.contains("`obstacles.3` is not an index"), "{e}");
        let e = refused("time=1");
        assert!(e.contains("`time` is a table"), "{e}");
        let e = refused("body_acceleration.2=1");
        assert!(e.contains("`body_acceleration.2` is not an index"), "{e}");
        for (bad, why) in [
            ("time.tau", "not KEY=VALUE"),
            ("time..tau=1", "joined by dots"),
            ("kind=dem", "`kind` cannot be set"),
            ("name=two words", "not a TOML value"),
        ] {
            let e = bad.parse::<Override>().unwrap_err();
            assert!(e.contains(why), "{bad}: {e}");
        }
    }
}
