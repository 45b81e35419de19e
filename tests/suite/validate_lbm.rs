//! The fluid validation cases at test fidelity (the same runs as `granflow validate <case>`):
//! Poiseuille, Taylor–Green, conservation, LES channel, Ghia cavities, Schäfer–Turek 2D-1, the
//! Sangani–Acrivos array and the seed's shedding case. Every check of each case must pass
//! (references and tolerances are beside each check in `src/scenario/fluid/validation/`), and every case returns
//! at least one figure with data.

use granflow::report::{Check, Fidelity};
use granflow::scenario::validation;

fn run_case(name: &str) {
    let t = std::time::Instant::now();
    let report = validation::run(name, Fidelity::Test).unwrap_or_else(|e| panic!("{name}: {e}"));
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
#[ignore = "heavy tier (≈ 40 s on 2 cores): cargo test -- --ignored"]
fn poiseuille() {
    run_case("poiseuille");
}

#[test]
fn taylor_green() {
    run_case("taylor-green");
}

#[test]
#[ignore = "heavy tier (≈ 20 s on 2 cores): cargo test -- --ignored"]
fn conservation() {
    run_case("conservation");
}

#[test]
#[ignore = "heavy tier (≈ 15 s on 2 cores): cargo test -- --ignored"]
fn les_channel() {
    run_case("les-channel");
}

#[test]
fn cavity_re100() {
    run_case("cavity-re100");
}

#[test]
#[ignore = "heavy tier (≈ 20 s on 2 cores): cargo test -- --ignored"]
fn cavity_re1000() {
    run_case("cavity-re1000");
}

#[test]
#[ignore = "heavy tier (≈ 40 s on 2 cores): cargo test -- --ignored"]
fn cylinder_2d1() {
    run_case("cylinder-2d1");
}

#[test]
#[ignore = "heavy tier (≈ 40 s on 2 cores): cargo test -- --ignored"]
fn cylinder_array() {
    run_case("cylinder-array");
}

#[test]
#[ignore = "heavy tier (≈ 30 s on 2 cores): cargo test -- --ignored"]
fn shedding() {
    run_case("shedding");
}
