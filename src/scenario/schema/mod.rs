//! The JSON Schema of each kind of scenario file, generated from the very types the parser
//! reads (`schemars` derives it from their fields, serde attributes and doc comments), and the
//! Markdown key reference made from that schema ([`markdown`]): `granflow schema KIND`
//! prints either, and docs/scenario-keys.md is the reference of every kind.
//!
//! The schema is JSON Schema draft 07 rather than schemars' default 2020-12: the validator in
//! Taplo (the TOML language server of VS Code's Even Better TOML) reads draft 07, not 2020-12.
//! It describes a TOML file as its JSON conversion, as those language servers see it: tables
//! are objects, arrays arrays. Two things are tidied after generation, both because
//! TOML has no null: an optional key (`Option<T>`, absent if not given) is `T`, not "`T` or
//! null", and no default is null. Descriptions are the doc comments, with their line breaks
//! joined and rustdoc links written as plain code.

mod markdown;

pub use markdown::{document, markdown};

use schemars::generate::SchemaSettings;
use serde_json::{Map, Value};

use super::ScenarioFile;

/// How an editor is pointed at the schema of `kind`: said in its top-level description.
fn editors(kind: &str) -> String {
    format!(
        "Scenario files are TOML; this schema describes a file as its JSON conversion (tables \
         as objects, arrays of tables as arrays). An editor with a TOML language server that \
         reads JSON Schemas completes and checks the keys with it, e.g. VS Code with Even \
         Better TOML (the Taplo language server): save the schema (`granflow schema {kind} > \
         {kind}.schema.json`) and either put the directive `#:schema ./{kind}.schema.json` in \
         the comments at the top of the TOML file, before its first key (a path relative to \
         that file, or a URL), or map files to it in VS Code's settings.json: \
         `\"evenBetterToml.schema.associations\": {{ \"<regular expression matching the \
         file's URI>\": \"<absolute URI of the schema, e.g. file:///…>\" }}`."
    )
}

/// The JSON Schema (draft 07) of the scenario files of `T`'s kind: its `kind` key may only be
/// that kind, every table refuses unknown keys as the parser does, and the top-level
/// description says how an editor uses it.
pub fn of<T: ScenarioFile>() -> Value {
    let generator = SchemaSettings::draft07().into_generator();
    let mut root = generator.into_root_schema_for::<T>().to_value();
    tidy(&mut root);
    let kind = T::KIND.name();
    let object = root
        .as_object_mut()
        .expect("schemars makes an object schema of a struct");
    if let Some(Value::Object(properties)) = object.get_mut("properties") {
        properties.insert(
            "kind".into(),
            serde_json::json!({
                "description": format!("`\"{kind}\"`: what the file describes (its first line)."),
                "type": "string",
                "const": kind,
            }),
        );
    }
    // `Kind` was referenced only by the `kind` key just replaced.
    if let Some(Value::Object(definitions)) = object.get_mut("definitions") {
        definitions.remove("Kind");
    }
    let doc = object
        .get("description")
        .and_then(Value::as_str)
        .unwrap_or_default()
        .to_owned();
    object.insert(
        "title".into(),
        Value::String(format!("granflow scenario file, kind = \"{kind}\"")),
    );
    object.insert(
        "description".into(),
        Value::String(format!(
            "{doc}\n\n{} The key reference, made from this schema, is docs/scenario-keys.md.",
            editors(kind)
        )),
    );
    root
}

/// Tidy a generated schema for TOML, recursively: no null types or defaults, no `format`
/// (informative only, e.g. "double"), descriptions as prose.
fn tidy(schema: &mut Value) {
    match schema {
        Value::Object(object) => {
            tidy_object(object);
            object.values_mut().for_each(tidy);
        }
        Value::Array(items) => items.iter_mut().for_each(tidy),
        _ => {}
    }
}

fn tidy_object(object: &mut Map<String, Value>) {
    object.remove("format");
    if object.get("default") == Some(&Value::Null) {
        object.remove("default");
    }
    if let Some(Value::Array(types)) = object.get_mut("type") {
        types.retain(|t| t != "null");
        if types.len() == 1 {
            let single = types.remove(0);
            object.insert("type".into(), single);
        }
    }
    let null = serde_json::json!({ "type": "null" });
    for key in ["anyOf", "oneOf"] {
        if let Some(Value::Array(options)) = object.get_mut(key) {
            let before = options.len();
            options.retain(|o| o != &null);
            // `T or null` is `T`: kept as an `allOf` of one, since a `$ref` takes no siblings.
            if options.len() == 1 && before == 2 {
                let options = object.remove(key).expect("just seen");
                object.insert("allOf".into(), options);
            }
        }
    }
    if let Some(Value::String(description)) = object.get_mut("description") {
        *description = prose(description);
    }
}

/// A doc comment as prose: the lines of each paragraph joined, rustdoc links (`` [`a::B`] ``)
/// written as code (`` `a::B` ``, without a leading `crate::`).
fn prose(doc: &str) -> String {
    let paragraphs: Vec<String> = doc
        .split("\n\n")
        .map(|p| {
            p.lines()
                .map(str::trim)
                .filter(|l| !l.is_empty())
                .collect::<Vec<_>>()
                .join(" ")
        })
        .filter(|p| !p.is_empty())
        .collect();
    let text = paragraphs.join("\n\n");
    let mut out = String::with_capacity(text.len());
    let mut rest = text.as_str();
    while let Some(start) = rest.find("[`") {
        let Some(len) = rest[start..].find("`]") else {
            break;
        };
        let end = start + len + 2;
        out.push_str(&rest[..start]);
        if rest[end..].starts_with('(') {
            // A Markdown link with a target, `[text](url)`, stays as it is.
            out.push_str(&rest[start..end]);
        } else {
            let path = &rest[start + 2..end - 2];
            out.push('`');
            out.push_str(path.strip_prefix("crate::").unwrap_or(path));
            out.push('`');
        }
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prose_joins_lines_and_unlinks() {
        assert_eq!(
            prose("A [`crate::lbm::MrtRates`]\nrate (1/s).\n\nSecond\n paragraph."),
            "A `lbm::MrtRates` rate (1/s).\n\nSecond paragraph."
        );
    }

    #[test]
    fn optional_keys_lose_null() {
        let mut s = serde_json::json!({
            "type": ["number", "null"],
            "default": null,
            "format": "double",
            "properties": { "m": { "anyOf": [{ "$ref": "#/definitions/M" }, { "type": "null" }] } }
        });
        tidy(&mut s);
        assert_eq!(
            s,
            serde_json::json!({
                "type": "number",
                "properties": { "m": { "allOf": [{ "$ref": "#/definitions/M" }] } }
            })
        );
    }
}
