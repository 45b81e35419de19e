//! Every scenario under `models/` parses and passes `derive()` (the `check` command).

use std::path::Path;

use granflow::scenario::fluid::Scenario;
use granflow::scenario::ScenarioFile;

fn toml_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            toml_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "toml") {
            out.push(p);
        }
    }
}

#[test]
fn every_model_file_parses_and_checks() {
    let mut files = Vec::new();
    toml_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("models/lbm"),
        &mut files,
    );
    assert!(!files.is_empty());
    for f in files {
        let s = Scenario::from_file(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        s.derive()
            .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
    }
}
