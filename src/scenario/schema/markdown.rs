//! The Markdown key reference of a kind, made from its JSON Schema ([`super::of`]): one table
//! per TOML table of the file, each key with its dotted path, type, whether it is required,
//! and its description (with its units); enumerations list their values.
//!
//! A table chosen by a tag key (`[material]` by `model`, an edge by `type`) is one table: the
//! tag's row lists the variants, and each other key says under which of them it is read.

use serde_json::{Map, Value};

/// The reference of the kind whose schema is `schema` ([`super::of`]): a `##` section, with
/// one `###` table per TOML table.
pub fn markdown(schema: &Value) -> String {
    let empty = Map::new();
    let walker = Walker {
        definitions: schema
            .get("definitions")
            .and_then(Value::as_object)
            .unwrap_or(&empty),
    };
    let kind = schema
        .pointer("/properties/kind/const")
        .and_then(Value::as_str)
        .unwrap_or("?");
    let doc = schema
        .get("description")
        .and_then(Value::as_str)
        .and_then(|d| d.split("\n\n").next())
        .unwrap_or_default();
    let mut sections = Vec::new();
    walker.table(schema, &Table::top(), &mut sections);
    let mut text = format!(
        "## `kind = \"{kind}\"`\n\n{}\n\nJSON Schema: `granflow schema {kind}`.\n",
        cell(doc)
    );
    for s in sections {
        text.push('\n');
        text.push_str(&s.render());
    }
    text
}

/// A TOML table being described: its header and the prefix of its keys.
struct Table {
    /// `Top level`, `` `[lbm]` `` or `` `[[obstacles]]` ``.
    heading: String,
    /// What precedes a key's name in its dotted path: `""`, `lbm.` or `obstacles[].`.
    prefix: String,
    /// Under which tag value it exists, e.g. `` with `model = "rve"` ``.
    condition: Option<String>,
}

impl Table {
    fn top() -> Table {
        Table {
            heading: "Top level".into(),
            prefix: String::new(),
            condition: None,
        }
    }

    /// The table at key `name` of this one, an array of tables if `array`.
    fn child(&self, name: &str, array: bool, condition: Option<String>) -> Table {
        let path = format!("{}{name}", self.prefix);
        let (heading, prefix) = if array {
            (format!("`[[{path}]]`"), format!("{path}[]."))
        } else {
            (format!("`[{path}]`"), format!("{path}."))
        };
        let condition = match (&self.condition, condition) {
            (Some(a), Some(b)) => Some(format!("{a}, {b}")),
            (a, b) => b.or_else(|| a.clone()),
        };
        Table {
            heading,
            prefix,
            condition,
        }
    }
}

/// One section of the reference: a table's heading, its note and its keys.
struct Section {
    heading: String,
    note: String,
    rows: Vec<Row>,
}

/// One key: dotted path, type, whether required, description.
#[derive(Clone, PartialEq)]
struct Row {
    key: String,
    ty: String,
    required: String,
    description: String,
}

impl Section {
    fn render(&self) -> String {
        let mut text = format!("### {}\n\n", self.heading);
        if !self.note.is_empty() {
            text.push_str(&cell(&self.note));
            text.push_str("\n\n");
        }
        text.push_str("| Key | Type | Required | Description |\n|---|---|---|---|\n");
        for r in &self.rows {
            text.push_str(&format!(
                "| `{}` | {} | {} | {} |\n",
                r.key,
                cell(&r.ty),
                cell(&r.required),
                cell(&r.description)
            ));
        }
        text
    }
}

/// Text for one table cell: on one line, `|` escaped.
fn cell(text: &str) -> String {
    text.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .replace('|', "\\|")
}

/// A JSON value as TOML would write it, in code quotes: `"zlib"`, `0.5`.
fn code(v: &Value) -> String {
    format!("`{v}`")
}

/// "a", "a or b", "a, b or c".
fn or_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

/// Walks a schema, resolving its references into the definitions.
struct Walker<'a> {
    definitions: &'a Map<String, Value>,
}

impl<'a> Walker<'a> {
    /// The schema behind `$ref`s and one-element `allOf`s.
    fn resolve(&self, mut s: &'a Value) -> &'a Value {
        loop {
            if let Some(r) = s.get("$ref").and_then(Value::as_str) {
                let name = r.rsplit('/').next().unwrap_or(r);
                match self.definitions.get(name) {
                    Some(d) => s = d,
                    None => return s,
                }
            } else if let Some([one]) = s.get("allOf").and_then(Value::as_array).map(Vec::as_slice)
            {
                s = one;
            } else {
                return s;
            }
        }
    }

    /// The first description met from `s` inwards: a field's doc before its type's.
    fn description(&self, mut s: &'a Value) -> String {
        loop {
            if let Some(d) = s.get("description").and_then(Value::as_str) {
                return d.to_owned();
            }
            let inner = match s.get("$ref").and_then(Value::as_str) {
                Some(r) => self.definitions.get(r.rsplit('/').next().unwrap_or(r)),
                None => s
                    .get("allOf")
                    .and_then(Value::as_array)
                    .filter(|a| a.len() == 1)
                    .map(|a| &a[0]),
            };
            match inner {
                Some(i) => s = i,
                None => return String::new(),
            }
        }
    }

    /// The alternatives of a union (`oneOf` or `anyOf`), resolved.
    fn alternatives(&self, s: &'a Value) -> Option<Vec<&'a Value>> {
        let r = self.resolve(s);
        let list = r
            .get("oneOf")
            .or_else(|| r.get("anyOf"))
            .and_then(Value::as_array)?;
        Some(list.iter().map(|a| self.resolve(a)).collect())
    }

    /// The values of a string enumeration with their docs: `enum`, or a union of `const`s.
    fn enumeration(&self, s: &'a Value) -> Option<Vec<(Value, String)>> {
        let r = self.resolve(s);
        if let Some(values) = r.get("enum").and_then(Value::as_array) {
            return Some(values.iter().map(|v| (v.clone(), String::new())).collect());
        }
        if let Some(c) = r.get("const") {
            return Some(vec![(c.clone(), String::new())]);
        }
        let alternatives = self.alternatives(s)?;
        alternatives
            .iter()
            .map(|a| {
                let doc = a.get("description").and_then(Value::as_str).unwrap_or("");
                a.get("const").map(|c| (c.clone(), doc.to_owned()))
            })
            .collect()
    }

    /// The tag key of a union of tables (the key every variant fixes with a `const`) and the
    /// variants as (tag value, variant schema).
    fn tagged(&self, s: &'a Value) -> Option<(String, Vec<(Value, &'a Value)>)> {
        let variants = self.alternatives(s)?;
        let first = variants.first()?.get("properties")?.as_object()?;
        let tag = first.iter().find_map(|(name, p)| {
            let fixed = |v: &Value| {
                v.get("properties")
                    .and_then(|ps| ps.get(name))
                    .and_then(|p| p.get("const"))
                    .is_some()
            };
            (p.get("const").is_some() && variants.iter().all(|v| fixed(v))).then(|| name.clone())
        })?;
        let list = variants
            .iter()
            .map(|v| (v["properties"][&tag]["const"].clone(), *v))
            .collect();
        Some((tag, list))
    }

    /// Whether `s` is a TOML table: of named keys (a struct or a tagged union of them), or a
    /// map whose keys are the user's.
    fn is_table(&self, s: &'a Value) -> bool {
        self.resolve(s).get("properties").is_some()
            || self.map_values(s).is_some()
            || self.tagged(s).is_some()
    }

    /// The value schema of a map (a table whose keys the user chooses).
    fn map_values(&self, s: &'a Value) -> Option<&'a Value> {
        let r = self.resolve(s);
        if r.get("properties").is_some() {
            return None;
        }
        r.get("additionalProperties").filter(|v| v.is_object())
    }

    /// The items of an array of tables.
    fn table_items(&self, s: &'a Value) -> Option<&'a Value> {
        let r = self.resolve(s);
        let items = r.get("items")?;
        (r.get("type") == Some(&Value::from("array")) && self.is_table(items)).then_some(items)
    }

    /// The type of a key, as a reader says it: `number`, `"bgk" or "mrt"`, `array of 2 ×
    /// number`, `table`.
    fn type_text(&self, s: &'a Value) -> String {
        if self.is_table(s) {
            return "table".into();
        }
        if let Some(values) = self.enumeration(s) {
            let names: Vec<String> = values.iter().map(|(v, _)| code(v)).collect();
            return or_list(&names);
        }
        if let Some(alternatives) = self.alternatives(s) {
            let names: Vec<String> = alternatives.iter().map(|a| self.type_text(a)).collect();
            return or_list(&names);
        }
        let r = self.resolve(s);
        let names: Vec<String> = match r.get("type") {
            Some(Value::String(t)) => vec![t.clone()],
            Some(Value::Array(ts)) => ts
                .iter()
                .filter_map(Value::as_str)
                .map(Into::into)
                .collect(),
            _ => vec!["any value".into()],
        };
        let one = |t: &str| -> String {
            match t {
                "array" => self.array_text(r),
                "object" => "table".into(),
                "integer" if r.get("minimum").and_then(Value::as_f64) == Some(0.0) => {
                    "integer ≥ 0".into()
                }
                t => t.into(),
            }
        };
        or_list(&names.iter().map(|t| one(t)).collect::<Vec<_>>())
    }

    /// `array of tables`, or `non-empty array of tables` where at least one is needed.
    fn tables_text(&self, s: &'a Value) -> String {
        match self.resolve(s).get("minItems").and_then(Value::as_u64) {
            Some(n) if n > 0 => "non-empty array of tables".into(),
            _ => "array of tables".into(),
        }
    }

    /// `array of 2 × number`, `array of tables`, `non-empty array of number or string`.
    fn array_text(&self, r: &'a Value) -> String {
        let Some(items) = r.get("items") else {
            return "array".into();
        };
        if self.is_table(items) {
            return "array of tables".into();
        }
        let mut item = self.type_text(items);
        if item.contains(' ') {
            item = format!("({item})");
        }
        let min = r.get("minItems").and_then(Value::as_u64);
        let max = r.get("maxItems").and_then(Value::as_u64);
        match (min, max) {
            (Some(a), Some(b)) if a == b => format!("array of {a} × {item}"),
            (Some(1), _) => format!("non-empty array of {item}"),
            (Some(a), _) if a > 1 => format!("array of ≥ {a} × {item}"),
            _ => format!("array of {item}"),
        }
    }

    /// A key's description, with its enumeration's values and their docs.
    fn row_description(&self, s: &'a Value) -> String {
        let mut text = self.description(s);
        let values = match self.resolve(s).get("items") {
            Some(items) => self.enumeration(items),
            None => self.enumeration(s),
        };
        if let Some(values) = values.filter(|v| v.iter().any(|(_, d)| !d.is_empty())) {
            let listed: Vec<String> = values
                .iter()
                .map(|(v, d)| format!("{}: {}", code(v), d))
                .collect();
            text = format!("{text} Values: {}", listed.join(" "));
        }
        text
    }

    /// Whether a key is required, from its table's `required` and its default.
    fn required_text(&self, required: bool, s: &'a Value) -> String {
        if required {
            return "yes".into();
        }
        match s.get("default") {
            Some(d @ (Value::Number(_) | Value::String(_) | Value::Bool(_))) => {
                format!("no (default {})", code(d))
            }
            Some(Value::Array(a)) if a.is_empty() => "no (default none)".into(),
            _ => "no".into(),
        }
    }

    /// The section of `table` (schema `s`), then those of the tables in it.
    fn table(&self, s: &'a Value, table: &Table, sections: &mut Vec<Section>) {
        let r = self.resolve(s);
        let mut note = Vec::new();
        if !table.prefix.is_empty() {
            note.push(self.type_doc(s));
        }
        if let Some(c) = &table.condition {
            note.push(format!("Only {c}."));
        }
        match r.get("minProperties").and_then(Value::as_u64) {
            Some(1) => note.push("At least one key.".into()),
            Some(n) if n > 1 => note.push(format!("At least {n} keys.")),
            _ => {}
        }
        note.retain(|n| !n.is_empty());
        let note = note.join(" ");
        let index = sections.len();
        sections.push(Section {
            heading: table.heading.clone(),
            note,
            rows: Vec::new(),
        });
        let mut children = Vec::new();
        let rows = if let Some((tag, variants)) = self.tagged(s) {
            self.union_rows(table, &tag, &variants, &mut children)
        } else if let Some(values) = self.map_values(s) {
            vec![Row {
                key: format!("{}<key>", table.prefix),
                ty: self.type_text(values),
                required: "no".into(),
                description: self.row_description(values),
            }]
        } else {
            self.struct_rows(table, r, None, &mut children)
        };
        sections[index].rows = rows;
        for (child, schema) in children {
            self.table(schema, &child, sections);
        }
    }

    /// The doc of a table's type (its definition's description, not the field's).
    fn type_doc(&self, s: &'a Value) -> String {
        let r = self.resolve(s);
        r.get("description")
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_owned()
    }

    /// The rows of a struct's keys, in the order of the schema (alphabetical); `condition` is
    /// the tag value it is the variant of, if any. Its sub-tables go to `children`.
    fn struct_rows(
        &self,
        table: &Table,
        r: &'a Value,
        condition: Option<&str>,
        children: &mut Vec<(Table, &'a Value)>,
    ) -> Vec<Row> {
        let required: Vec<&str> = r
            .get("required")
            .and_then(Value::as_array)
            .map(|a| a.iter().filter_map(Value::as_str).collect())
            .unwrap_or_default();
        let mut rows = Vec::new();
        let Some(properties) = r.get("properties").and_then(Value::as_object) else {
            return rows;
        };
        for (name, p) in properties {
            let is_required = required.contains(&name.as_str());
            let mut row = Row {
                key: format!("{}{name}", table.prefix),
                ty: self.type_text(p),
                required: self.required_text(is_required, p),
                description: self.row_description(p),
            };
            if let Some(c) = condition {
                row.required = if is_required {
                    format!("if {c}")
                } else {
                    format!("{} ({c})", row.required)
                };
            }
            let child_condition = condition.map(|c| format!("with {c}"));
            if self.is_table(p) {
                children.push((table.child(name, false, child_condition), p));
            } else if let Some(items) = self.table_items(p) {
                row.ty = self.tables_text(p);
                children.push((table.child(name, true, child_condition), items));
            }
            rows.push(row);
        }
        rows
    }

    /// The rows of a tagged union: the tag, then each variant's keys; a key the same in
    /// several variants is one row naming them all.
    fn union_rows(
        &self,
        table: &Table,
        tag: &str,
        variants: &[(Value, &'a Value)],
        children: &mut Vec<(Table, &'a Value)>,
    ) -> Vec<Row> {
        let values: Vec<String> = variants.iter().map(|(v, _)| code(v)).collect();
        let docs: Vec<String> = variants
            .iter()
            .map(|(v, s)| {
                let doc = s.get("description").and_then(Value::as_str).unwrap_or("");
                format!("{}: {doc}", code(v))
            })
            .collect();
        let mut rows = vec![Row {
            key: format!("{}{tag}", table.prefix),
            ty: or_list(&values),
            required: "yes".into(),
            description: format!("Selects the variant: {}", docs.join(" ")),
        }];
        // (row without its condition, the tag values it appears under, required in each).
        let mut merged: Vec<(Row, Vec<String>, bool)> = Vec::new();
        for (value, schema) in variants {
            let condition = format!("`{tag} = {value}`");
            let required = schema
                .get("required")
                .and_then(Value::as_array)
                .cloned()
                .unwrap_or_default();
            let properties = schema.get("properties").and_then(Value::as_object);
            for (name, p) in properties.into_iter().flatten() {
                if name == tag {
                    continue;
                }
                let is_required = required.contains(&Value::from(name.as_str()));
                let mut row = Row {
                    key: format!("{}{name}", table.prefix),
                    ty: self.type_text(p),
                    required: self.required_text(is_required, p),
                    description: self.row_description(p),
                };
                if self.is_table(p) {
                    children.push((
                        table.child(name, false, Some(format!("with {condition}"))),
                        p,
                    ));
                } else if let Some(items) = self.table_items(p) {
                    row.ty = self.tables_text(p);
                    children.push((
                        table.child(name, true, Some(format!("with {condition}"))),
                        items,
                    ));
                }
                match merged
                    .iter_mut()
                    .find(|(r, _, req)| *r == row && *req == is_required)
                {
                    Some((_, under, _)) => under.push(code(value)),
                    None => merged.push((row, vec![code(value)], is_required)),
                }
            }
        }
        // By key; a key's variants in their order.
        merged.sort_by(|a, b| a.0.key.cmp(&b.0.key));
        for (mut row, under, is_required) in merged {
            let when = if under.len() == variants.len() {
                None
            } else if let [one] = under.as_slice() {
                Some(format!("`{tag}` = {one}"))
            } else {
                Some(format!("`{tag}` = {}", or_list(&under)))
            };
            row.required = match (when, is_required) {
                (None, _) => row.required,
                (Some(w), true) => format!("if {w}"),
                (Some(w), false) => format!("{} (if {w})", row.required),
            };
            rows.push(row);
        }
        rows
    }
}

/// The whole reference: a title, how it is made and read, then each kind's section
/// ([`markdown`] of each of `schemas`).
pub fn document(schemas: &[Value]) -> String {
    let mut text = String::from(
        "# Scenario keys\n\n\
         <!-- Generated from the scenario types: do not edit. Regenerate with\n     \
         cargo run --release -- schema all --markdown > docs/scenario-keys.md\n     \
         (tests/suite/schema.rs fails while this file differs from what the binary prints). -->\n\n\
         Every key of every kind of scenario file, made from the JSON Schema that \
         `granflow schema KIND` prints, itself generated from the types the parser reads, \
         so this page and the parser cannot disagree. How the files are written, and why, \
         is in [scenario-format.md](scenario-format.md).\n\n\
         One table per TOML table of the file: the key's dotted path (`a[].b` is key `b` of \
         each table of the array of tables `[[a]]`), its type, whether it must be given, and \
         its description with its units (SI unless said). A table chosen by a tag key \
         (`[material]` by `model`, an edge of `[boundaries]` by `type`) lists every variant's \
         keys, each saying under which value of the tag it is read. Unknown keys are refused \
         in every table.\n",
    );
    for s in schemas {
        text.push('\n');
        text.push_str(&markdown(s));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A kind with a tagged table (`[law]` by `model`), one of whose variants holds a table.
    fn schema() -> Value {
        serde_json::json!({
            "description": "A test kind.\n\nEditor notes.",
            "properties": {
                "kind": { "const": "test", "type": "string" },
                "law": { "allOf": [{ "$ref": "#/definitions/Law" }], "description": "The law." },
                "n": { "type": "integer", "minimum": 0, "description": "Count |n|." }
            },
            "required": ["kind", "law"],
            "definitions": {
                "Law": {
                    "description": "A law, by `model`.",
                    "oneOf": [
                        {
                            "description": "Elastic.",
                            "properties": {
                                "model": { "const": "elastic", "type": "string" },
                                "e": { "type": "number", "description": "Modulus (Pa)." }
                            },
                            "required": ["model", "e"]
                        },
                        {
                            "description": "Grains.",
                            "properties": {
                                "model": { "const": "grains", "type": "string" },
                                "e": { "type": "number", "description": "Modulus (Pa)." },
                                "size": { "$ref": "#/definitions/Size" }
                            },
                            "required": ["model", "e", "size"]
                        }
                    ]
                },
                "Size": {
                    "description": "Sizes.",
                    "properties": { "d": { "type": "array", "items": { "type": "number" },
                        "minItems": 2, "maxItems": 2, "description": "Diameters (m)." } },
                    "required": ["d"]
                }
            }
        })
    }

    #[test]
    fn tagged_tables_merge_their_variants_keys() {
        let text = markdown(&schema());
        assert!(
            text.starts_with("## `kind = \"test\"`\n\nA test kind.\n"),
            "{text}"
        );
        assert!(!text.contains("Editor notes"), "{text}");
        // A key of every variant is one row, required without condition.
        assert!(
            text.contains("| `law.e` | number | yes | Modulus (Pa). |"),
            "{text}"
        );
        assert!(
            text.contains("| `law.size` | table | if `model` = `\"grains\"` | Sizes. |"),
            "{text}"
        );
        assert!(text.contains("| `law.model` | `\"elastic\"` or `\"grains\"` | yes |"));
        assert!(text.contains("### `[law.size]`\n\nSizes. Only with `model = \"grains\"`."));
        assert!(text.contains("| `law.size.d` | array of 2 × number | yes | Diameters (m). |"));
        // Pipes in a description are escaped; an optional key says so.
        assert!(
            text.contains("| `n` | integer ≥ 0 | no | Count \\|n\\|. |"),
            "{text}"
        );
    }
}
