//! Fuzzing what a user writes: every model file, mutated at random (a key deleted, a value
//! replaced by one of another type or a number out of range — NaN, ±∞, 0, negative, huge —,
//! an unknown key added), and arbitrary text, go through what `granflow check` does (parse
//! by kind, check every value, derive). Nothing may panic, and every refusal must name the key
//! it refuses (a `Config` error with its field, or the TOML parser's message, which shows the
//! line and the key).
//!
//! The tests run a bounded number of cases (`PROPTEST_CASES`, 64 by default here), each run
//! from a new random seed. For a long campaign, e.g. a million mutations and a million texts
//! (≈ 6 minutes on 2 cores; the test profile is optimised and keeps the overflow checks, which
//! a `--release` build would drop):
//!
//! ```sh
//! PROPTEST_CASES=1000000 cargo test --test fuzz_scenarios
//! ```

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use proptest::prelude::*;
use toml::Value;

use granflow::scenario::continuum::ContinuumScenario;
use granflow::scenario::dem::DemScenario;
use granflow::scenario::fluid::Scenario;
use granflow::scenario::granular::GranularScenario;
use granflow::scenario::mpm::MpmScenario;
use granflow::scenario::submerged::SubmergedScenario;
use granflow::scenario::{kind_of, Kind, ScenarioFile};

/// Every scenario and sweep file the project ships (`models/**.toml`), with its text.
fn models() -> &'static [(PathBuf, String)] {
    static MODELS: OnceLock<Vec<(PathBuf, String)>> = OnceLock::new();
    MODELS.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
        let mut found = Vec::new();
        for dir in std::fs::read_dir(&root).unwrap() {
            for f in std::fs::read_dir(dir.unwrap().path()).unwrap() {
                let path = f.unwrap().path();
                if path.extension().is_some_and(|e| e == "toml") {
                    let text = std::fs::read_to_string(&path).unwrap();
                    found.push((path, text));
                }
            }
        }
        found.sort();
        assert!(found.len() > 30, "{} model files", found.len());
        found
    })
}

/// A copy of `models/column_collapse/`, where a mutated sweep file is written beside the
/// base scenarios it names.
fn sweep_dir() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        for (path, text) in models() {
            if path.parent().unwrap().ends_with("column_collapse") {
                std::fs::write(dir.path().join(path.file_name().unwrap()), text).unwrap();
            }
        }
        dir
    })
    .path()
}

/// What `granflow check` does with a scenario text, without printing.
fn check(text: &str) -> granflow::Result<()> {
    match kind_of(text)? {
        Kind::Fluid => Scenario::from_toml(text)?.derive().map(|_| ()),
        Kind::Dem => DemScenario::from_toml(text)?.derive().map(|_| ()),
        Kind::Mpm => MpmScenario::from_toml(text)?.derive().map(|d| {
            d.memory_bytes();
        }),
        Kind::Submerged => SubmergedScenario::from_toml(text)?
            .check_report()
            .map(|_| ()),
        Kind::Granular => GranularScenario::from_toml(text)?
            .check_report()
            .map(|_| ()),
        Kind::Continuum => ContinuumScenario::from_toml(text)?
            .check_report()
            .map(|_| ()),
        Kind::Sweep => {
            let path = sweep_dir().join(format!("fuzz_{:?}.toml", std::thread::current().id()));
            std::fs::write(&path, text).unwrap();
            let (_, cases) = granflow::sweep::read_sweep(&path)?;
            cases.iter().try_for_each(|c| check(&c.scenario))
        }
    }
}

/// Does a refusal say which key it refuses?
fn names_a_key(e: &granflow::Error) -> bool {
    match e {
        granflow::Error::Config { field, .. } => !field.is_empty(),
        // The TOML parser names the field in backticks, or shows the line with the key.
        granflow::Error::Parse { message, .. } => {
            message.contains('`') || message.contains("TOML parse error at line")
        }
        _ => false,
    }
}

/// A value of any TOML type, numbers out of every range included.
fn value() -> impl Strategy<Value = Value> {
    let special = prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(0.0),
        Just(-0.0),
        Just(-1.0),
        Just(1e300),
        Just(-1e300),
        Just(1e-300),
        Just(0.5),
        Just(1e9),
    ];
    prop_oneof![
        special.prop_map(Value::Float),
        any::<f64>().prop_map(Value::Float),
        prop_oneof![
            Just(0i64),
            Just(-1),
            Just(1),
            Just(i64::MAX),
            Just(i64::MIN),
            any::<i64>()
        ]
        .prop_map(Value::Integer),
        any::<bool>().prop_map(Value::Boolean),
        "[a-z_]{0,8}".prop_map(Value::String),
        prop::collection::vec(any::<f64>().prop_map(Value::Float), 0..4).prop_map(Value::Array),
        Just(Value::Table(toml::Table::new())),
    ]
}

/// One mutation; `at` picks the key (modulo the number of keys of the file).
#[derive(Clone, Debug)]
enum Mutation {
    Delete {
        at: usize,
    },
    Replace {
        at: usize,
        value: Value,
    },
    Unknown {
        at: usize,
        name: String,
        value: Value,
    },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(|at| Mutation::Delete { at }),
        (any::<usize>(), value()).prop_map(|(at, value)| Mutation::Replace { at, value }),
        (any::<usize>(), "[a-z]{1,6}", value()).prop_map(|(at, name, value)| Mutation::Unknown {
            at,
            name,
            value
        }),
    ]
}

/// The path of every key (tables and array elements included) of `v`.
fn paths(v: &Value, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Table(t) => {
            for (k, child) in t {
                prefix.push(k.clone());
                out.push(prefix.clone());
                paths(child, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                prefix.push(format!("#{i}"));
                out.push(prefix.clone());
                paths(child, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

/// The value at `path` and its parent's handle to it.
fn apply(root: &mut Value, path: &[String], m: &Mutation) {
    let (last, parent) = path.split_last().unwrap();
    let mut v = root;
    for p in parent {
        v = match (v, p.strip_prefix('#')) {
            (Value::Array(a), Some(i)) => &mut a[i.parse::<usize>().unwrap()],
            (Value::Table(t), None) => t.get_mut(p).unwrap(),
            _ => unreachable!(),
        };
    }
    match (v, last.strip_prefix('#'), m) {
        (Value::Table(t), None, Mutation::Delete { .. }) => {
            t.remove(last);
        }
        (Value::Array(a), Some(i), Mutation::Delete { .. }) => {
            a.remove(i.parse::<usize>().unwrap());
        }
        (Value::Table(t), None, Mutation::Replace { value, .. }) => {
            t.insert(last.clone(), value.clone());
        }
        (Value::Array(a), Some(i), Mutation::Replace { value, .. }) => {
            a[i.parse::<usize>().unwrap()] = value.clone();
        }
        (Value::Table(t), None, Mutation::Unknown { name, value, .. }) => {
            if let Some(Value::Table(inner)) = t.get_mut(last) {
                inner.insert(format!("{name}_unknown"), value.clone());
            } else {
                t.insert(format!("{name}_unknown"), value.clone());
            }
        }
        _ => {}
    }
}

/// Mutate model file `file` (modulo their number) by `mutations`; the text written back.
fn mutated(file: usize, mutations: &[Mutation]) -> String {
    let (_, text) = &models()[file % models().len()];
    let mut root = Value::Table(text.parse::<toml::Table>().unwrap());
    for m in mutations {
        let mut all = Vec::new();
        paths(&root, &mut Vec::new(), &mut all);
        let at = match m {
            Mutation::Delete { at }
            | Mutation::Replace { at, .. }
            | Mutation::Unknown { at, .. } => *at,
        };
        if let Some(path) = (!all.is_empty()).then(|| &all[at % all.len()]) {
            apply(&mut root, &path.clone(), m);
        }
    }
    toml::to_string(&root).unwrap()
}

fn config(default_cases: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(default_cases);
    ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// The unmutated model files all pass `check`: the mutations start from valid input.
#[test]
fn every_model_file_passes_check() {
    for (path, text) in models() {
        check(text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn a_mutated_model_file_is_checked_without_panic_and_a_refusal_names_its_key(
        file in any::<usize>(),
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        let text = mutated(file, &mutations);
        let outcome = std::panic::catch_unwind(|| check(&text));
        let outcome = outcome.unwrap_or_else(|_| panic!("check panicked on:\n{text}"));
        if let Err(e) = outcome {
            prop_assert!(names_a_key(&e), "refusal without a key: {e}\n---\n{text}");
        }
    }

    #[test]
    fn arbitrary_text_is_refused_without_panic(text in "(?s).{0,400}") {
        let outcome = std::panic::catch_unwind(|| check(&text));
        prop_assert!(outcome.is_ok(), "check panicked on {text:?}");
    }
}
