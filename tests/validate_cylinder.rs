//! The cylinder validation cases at test fidelity: Schäfer–Turek 2D-1, the Sangani–Acrivos
//! periodic array and the seed's vortex-shedding case. Every check of each case must pass, and
//! every case returns at least one figure with data.

use granflow::validate::{self, Check, Fidelity};

fn run_case(name: &str) {
    let t = std::time::Instant::now();
    let report = validate::run(name, Fidelity::Test).unwrap_or_else(|e| panic!("{name}: {e}"));
    let checks = &report.checks;
    println!("{name}: {:.1} s", t.elapsed().as_secs_f64());
    for c in checks {
        println!(
            "  {:<55} {:>12.6} ref {:>10.5} tol {:>8.3e} {}",
            c.quantity,
            c.value,
            c.reference,
            c.tolerance,
            if c.pass { "ok" } else { "FAIL" }
        );
    }
    let failed: Vec<&Check> = checks.iter().filter(|c| !c.pass).collect();
    assert!(!checks.is_empty(), "{name}: no checks");
    assert!(failed.is_empty(), "{name}: failing checks: {failed:#?}");
    assert!(!report.plots.is_empty(), "{name}: no plots");
    for p in &report.plots {
        assert!(
            !p.series.is_empty(),
            "{name}: plot {} has no series",
            p.name
        );
        for s in &p.series {
            assert!(
                !s.points.is_empty(),
                "{name}: plot {}, series {} is empty",
                p.name,
                s.label
            );
        }
    }
}

#[test]
fn cylinder_2d1() {
    run_case("cylinder-2d1");
}

#[test]
fn cylinder_array() {
    run_case("cylinder-array");
}

#[test]
fn shedding() {
    run_case("shedding");
}
