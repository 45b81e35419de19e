//! The basic fluid validation cases at [`Fidelity::Test`]: every check must pass, and every
//! case returns at least one figure with data.

use granflow::validate::{self, Check, Fidelity};

fn run_case(name: &str) {
    let t = std::time::Instant::now();
    let report = validate::run(name, Fidelity::Test).unwrap_or_else(|e| panic!("{name}: {e}"));
    let checks: &[Check] = &report.checks;
    for c in checks {
        println!(
            "{:<14} {:<80} value {:>12.5e}  ref {:>12.5e}  tol {:>9.2e}  {}",
            c.case,
            c.quantity,
            c.value,
            c.reference,
            c.tolerance,
            if c.pass { "ok" } else { "FAIL" }
        );
    }
    println!("{name}: {:.1} s", t.elapsed().as_secs_f64());
    assert!(!checks.is_empty(), "{name}: no checks");
    let failed: Vec<String> = checks
        .iter()
        .filter(|c| !c.pass)
        .map(|c| {
            format!(
                "{}: {} = {:e} (reference {:e}, tolerance {:e})",
                c.case, c.quantity, c.value, c.reference, c.tolerance
            )
        })
        .collect();
    assert!(
        failed.is_empty(),
        "{name}: failed checks:\n{}",
        failed.join("\n")
    );
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
fn poiseuille() {
    run_case("poiseuille");
}

#[test]
fn taylor_green() {
    run_case("taylor-green");
}

#[test]
fn conservation() {
    run_case("conservation");
}

#[test]
fn les_channel() {
    run_case("les-channel");
}

#[test]
fn cavity_re100() {
    run_case("cavity-re100");
}

#[test]
fn cavity_re1000() {
    run_case("cavity-re1000");
}
