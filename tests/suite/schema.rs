//! `granflow schema`: the JSON Schemas of the scenario kinds are valid draft-07 schemas, every
//! file under `models/` is valid against its kind's schema, the schema refuses what the parser
//! refuses (unknown keys, missing keys, another kind), and docs/scenario-keys.md is what the
//! binary generates now, so the key reference cannot drift from the types.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// The command that writes docs/scenario-keys.md.
const REGENERATE: &str = "cargo run --release -- schema all --markdown > docs/scenario-keys.md";

const KINDS: [&str; 7] = [
    "fluid",
    "dem",
    "mpm",
    "submerged",
    "granular",
    "continuum",
    "sweep",
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Stdout of `granflow ARGS…`, which must succeed.
fn granflow(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "granflow {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// `granflow schema KIND`, parsed.
fn schema(kind: &str) -> Value {
    serde_json::from_str(&granflow(&["schema", kind])).unwrap()
}

fn toml_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            toml_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "toml") {
            out.push(p);
        }
    }
}

/// A TOML text as JSON, as an editor's language server sees it.
fn as_json(text: &str) -> Value {
    let table: toml::Table = text.parse().unwrap();
    serde_json::to_value(table).unwrap()
}

/// The validation errors of `instance` against `schema`, one line each with its path.
fn errors(schema: &Value, instance: &Value) -> Vec<String> {
    let validator = jsonschema::validator_for(schema).unwrap();
    validator
        .iter_errors(instance)
        .map(|e| format!("{}: {e}", e.instance_path()))
        .collect()
}

#[test]
fn key_reference_is_what_the_binary_generates() {
    let generated = granflow(&["schema", "all", "--markdown"]);
    let path = root().join("docs/scenario-keys.md");
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != generated {
        let line = committed
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| committed.lines().count().min(generated.lines().count()));
        panic!(
            "docs/scenario-keys.md is not what the scenario types generate now (first \
             difference at line {}: committed {:?}, generated {:?}); regenerate it with\n    \
             {REGENERATE}",
            line + 1,
            committed.lines().nth(line).unwrap_or("<end of file>"),
            generated.lines().nth(line).unwrap_or("<end of file>"),
        );
    }
    for kind in KINDS {
        assert!(
            generated.contains(&format!("## `kind = \"{kind}\"`")),
            "no section for {kind}"
        );
    }
}

#[test]
fn every_schema_is_a_draft_07_schema_for_the_toml_files() {
    for kind in KINDS {
        let s = schema(kind);
        assert_eq!(s["$schema"], "http://json-schema.org/draft-07/schema#");
        if let Err(e) = jsonschema::meta::validate(&s) {
            panic!("{kind}: not a valid schema: {e}");
        }
        assert_eq!(s["properties"]["kind"]["const"], kind);
        assert_eq!(s["additionalProperties"], false, "{kind}");
        let description = s["description"].as_str().unwrap();
        for said in ["TOML", "#:schema", "evenBetterToml.schema.associations"] {
            assert!(
                description.contains(said),
                "{kind}: {said} not in {description}"
            );
        }
    }
}

#[test]
fn every_model_file_is_valid_against_its_kinds_schema() {
    let schemas: BTreeMap<&str, Value> = KINDS.iter().map(|&k| (k, schema(k))).collect();
    let mut files = Vec::new();
    toml_files(&root().join("models"), &mut files);
    let mut seen = std::collections::BTreeSet::new();
    let mut invalid = Vec::new();
    for f in &files {
        let json = as_json(&std::fs::read_to_string(f).unwrap());
        let kind = json["kind"].as_str().unwrap_or_default().to_owned();
        let Some(schema) = schemas.get(kind.as_str()) else {
            invalid.push(format!("{}: kind {kind:?} has no schema", f.display()));
            continue;
        };
        seen.insert(kind);
        for e in errors(schema, &json) {
            invalid.push(format!("{}: {e}", f.display()));
        }
    }
    assert!(invalid.is_empty(), "{}", invalid.join("\n"));
    assert_eq!(
        seen.len(),
        KINDS.len(),
        "a model file of every kind: {seen:?}"
    );
}

#[test]
fn the_schema_refuses_what_the_parser_refuses() {
    let text = std::fs::read_to_string(root().join("models/column_collapse/dem_a2.toml")).unwrap();
    let dem = schema("dem");
    let good = as_json(&text);
    assert!(errors(&dem, &good).is_empty());

    let mut misspelt = good.clone();
    misspelt["grain_contact"]["frction"] = 0.5.into();
    let e = errors(&dem, &misspelt);
    assert!(e.iter().any(|e| e.contains("frction")), "{e:?}");

    let mut missing = good.clone();
    missing["grains"].as_object_mut().unwrap().remove("d_min");
    let e = errors(&dem, &missing);
    assert!(e.iter().any(|e| e.contains("d_min")), "{e:?}");

    let mut other_kind = good.clone();
    other_kind["kind"] = "mpm".into();
    assert!(!errors(&dem, &other_kind).is_empty());

    let mut bad_enum = good;
    bad_enum["grains"]["distribution"] = "gaussian".into();
    assert!(!errors(&dem, &bad_enum).is_empty());

    // A tagged table takes only its variant's keys.
    let mpm = schema("mpm");
    let text = std::fs::read_to_string(root().join("models/column_collapse/mpm_a2.toml")).unwrap();
    let mut wall = as_json(&text);
    wall["walls"]["base"] = serde_json::json!({ "kind": "fixed", "mu": 0.3 });
    assert!(!errors(&mpm, &wall).is_empty());
    wall["walls"]["base"] = serde_json::json!({ "kind": "friction", "mu": 0.3 });
    assert!(errors(&mpm, &wall).is_empty());

    // An initial field is a number or an expression.
    let fluid = schema("fluid");
    let text = std::fs::read_to_string(root().join("models/lbm/taylor_green.toml")).unwrap();
    let mut field = as_json(&text);
    field["initial"]["velocity"] = serde_json::json!([0, "0.1*sin(x)"]);
    assert!(errors(&fluid, &field).is_empty());
    field["initial"]["velocity"] = serde_json::json!([true, 0]);
    assert!(!errors(&fluid, &field).is_empty());
}

#[test]
fn schema_all_is_markdown_only_and_help_lists_the_kinds() {
    let out = Command::new(env!("CARGO_BIN_EXE_granflow"))
        .args(["schema", "all"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--markdown"), "{err}");

    let help = granflow(&["schema", "--help"]);
    for kind in KINDS.iter().chain(&["all"]) {
        assert!(help.contains(&format!("- {kind}:")), "{kind} not in {help}");
    }
    let one = granflow(&["schema", "mpm", "--markdown"]);
    assert!(one.starts_with("## `kind = \"mpm\"`"), "{one}");
    assert!(one.contains("| `material.model` |"), "{one}");
}
