//! Every scenario under `models/` declares its kind, parses as that kind and passes
//! `derive()` (the `check` command); every case of every sweep file does too.

use std::path::Path;

use granflow::scenario::continuum::ContinuumScenario;
use granflow::scenario::dem::DemScenario;
use granflow::scenario::fluid::Scenario;
use granflow::scenario::granular::GranularScenario;
use granflow::scenario::mpm::MpmScenario;
use granflow::scenario::submerged::SubmergedScenario;
use granflow::scenario::{kind_of_file, Kind, ScenarioFile};

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

#[test]
fn every_model_file_declares_its_kind_and_checks_as_it() {
    let mut files = Vec::new();
    toml_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("models"),
        &mut files,
    );
    let mut seen = std::collections::BTreeSet::new();
    for f in &files {
        let kind = kind_of_file(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        seen.insert(kind.name());
        let checked = match kind {
            Kind::Fluid => Scenario::from_file(f).and_then(|s| s.derive()).map(|_| ()),
            Kind::Dem => DemScenario::from_file(f)
                .and_then(|s| s.derive())
                .map(|_| ()),
            Kind::Mpm => MpmScenario::from_file(f)
                .and_then(|s| s.derive())
                .map(|_| ()),
            Kind::Submerged => SubmergedScenario::from_file(f)
                .and_then(|s| s.derive())
                .map(|_| ()),
            Kind::Granular => GranularScenario::from_file(f)
                .and_then(|s| s.derive())
                .map(|_| ()),
            Kind::Continuum => ContinuumScenario::from_file(f)
                .and_then(|s| s.check_report())
                .map(|_| ()),
            // Every case of a sweep (its base with the sweep's keys set) checks as its kind.
            Kind::Sweep => granflow::sweep::read_sweep(f)
                .and_then(|(_, cases)| cases.iter().try_for_each(|c| c.check())),
        };
        if let Err(e) = checked {
            panic!("{}: {e}", f.display());
        }
    }
    assert_eq!(
        seen.len(),
        Kind::ALL.len(),
        "every kind has a model file: {seen:?}"
    );
}
