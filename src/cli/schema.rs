//! `granflow schema`: the JSON Schema of a kind of scenario file, or the Markdown key
//! reference made from it (docs/scenario-keys.md is `granflow schema all --markdown`).

use std::process::ExitCode;

use anyhow::Result;
use serde_json::Value;

use granflow::scenario::continuum::ContinuumScenario;
use granflow::scenario::dem::DemScenario;
use granflow::scenario::fluid::Scenario;
use granflow::scenario::granular::GranularScenario;
use granflow::scenario::mpm::MpmScenario;
use granflow::scenario::schema;
use granflow::scenario::submerged::SubmergedScenario;
use granflow::scenario::Kind;
use granflow::sweep::SweepSpec;

/// The JSON Schema of the files of `kind`.
fn of(kind: Kind) -> Value {
    match kind {
        Kind::Fluid => schema::of::<Scenario>(),
        Kind::Dem => schema::of::<DemScenario>(),
        Kind::Mpm => schema::of::<MpmScenario>(),
        Kind::Submerged => schema::of::<SubmergedScenario>(),
        Kind::Granular => schema::of::<GranularScenario>(),
        Kind::Continuum => schema::of::<ContinuumScenario>(),
        Kind::Sweep => schema::of::<SweepSpec>(),
    }
}

/// Print the schema of `kind` (pretty JSON), or with `markdown` its key reference; `None`:
/// every kind, which only the Markdown reference can be (one document, a section each).
pub fn schema(kind: Option<Kind>, markdown: bool) -> Result<ExitCode> {
    let text = match (kind, markdown) {
        (Some(k), false) => format!("{}\n", serde_json::to_string_pretty(&of(k))?),
        (Some(k), true) => schema::markdown(&of(k)),
        (None, true) => schema::document(&Kind::ALL.map(of)),
        (None, false) => anyhow::bail!(
            "`all` is only for --markdown (one reference of every kind); a JSON Schema is of \
             one kind: name it (fluid, dem, mpm, submerged, granular or sweep)"
        ),
    };
    print!("{text}");
    Ok(ExitCode::SUCCESS)
}
