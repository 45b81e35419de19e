//! Run-out history of a column collapse, shared by the DEM and MPM runners so both report the
//! same quantities.

/// Spreading has stopped once the run-out stays within this fraction of L_i of its final value.
pub const STOP_TOLERANCE: f64 = 0.01;

/// End of spreading: the first time after which every run-out in `history` (t, L) stays
/// within `tol` of the last one (0 for an empty history).
pub fn spreading_end(history: &[(f64, f64)], tol: f64) -> f64 {
    let Some(&(t_end, l_f)) = history.last() else {
        return 0.0;
    };
    history
        .iter()
        .rev()
        .take_while(|&&(_, l)| (l - l_f).abs() <= tol)
        .last()
        .map_or(t_end, |&(t, _)| t)
}

#[cfg(test)]
mod tests {
    use super::spreading_end;

    #[test]
    fn spreading_ends_when_the_runout_settles() {
        let h = [
            (0.0, 1.0),
            (1.0, 2.0),
            (2.0, 2.9),
            (3.0, 3.02),
            (4.0, 2.99),
            (5.0, 3.0),
        ];
        assert_eq!(spreading_end(&h, 0.05), 3.0);
        assert_eq!(spreading_end(&h, 0.001), 5.0);
        assert_eq!(spreading_end(&h, 10.0), 0.0);
        assert_eq!(spreading_end(&[], 0.1), 0.0);
    }
}
