//! Helpers shared by the integration tests.

pub mod vtk;

/// Run the validation case `case` at the test fidelity, print every check and assert that
/// each passes.
pub fn assert_passes(case: &str) {
    let report =
        granflow::scenario::validation::run(case, granflow::report::Fidelity::Test).expect(case);
    assert!(!report.checks.is_empty());
    for c in &report.checks {
        println!(
            "{} | {} = {:.6e} (ref {:.6e}, tol {:.1e}) {}",
            c.case, c.quantity, c.value, c.reference, c.tolerance, c.pass
        );
    }
    for c in &report.checks {
        assert!(
            c.pass,
            "{}: {} = {} vs {} ± {}",
            c.case, c.quantity, c.value, c.reference, c.tolerance
        );
    }
}
