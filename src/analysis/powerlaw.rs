//! Run-out laws ΔL = λ a^α fitted in log space, with the crossover between the two regimes of
//! the column collapse found from the data (Lajeunesse et al. 2005: ΔL = λ_s a for small a,
//! ΔL = λ_l a^α with α ≈ 2/3 for large a).
//!
//! Each fit is ordinary least squares on ln ΔL = ln λ + α ln a, solved by a QR factorisation
//! (faer). Uncertainties are one standard error from the covariance s² (XᵀX)⁻¹ with
//! s² = SSR/(n − p) (n points, p parameters); λ's is carried through ln λ (δλ = λ δ ln λ).
//! They are `None` where n = p (no degrees of freedom left).

use faer::linalg::solvers::{DenseSolveCore, SolveLstsq};
use faer::{Mat, Side};
use serde::Serialize;

/// One fitted power law ΔL = λ a^α over a range of a.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct PowerLaw {
    /// Prefactor λ.
    pub lambda: f64,
    /// One standard error of λ.
    pub lambda_err: Option<f64>,
    /// Exponent α (1 exactly where it was held fixed).
    pub alpha: f64,
    /// One standard error of α (`None` where it was held fixed).
    pub alpha_err: Option<f64>,
    /// Smallest and largest a fitted.
    pub a_range: [f64; 2],
    /// Points fitted.
    pub points: usize,
    /// Residual sum of squares in log space.
    pub ssr: f64,
}

impl PowerLaw {
    /// λ a^α.
    pub fn at(&self, a: f64) -> f64 {
        self.lambda * a.powf(self.alpha)
    }
}

/// Least squares y ≈ X β (columns of X given): β, its covariance s²(XᵀX)⁻¹ (`None` without
/// degrees of freedom) and the residual sum of squares.
pub(crate) fn least_squares(columns: &[Vec<f64>], y: &[f64]) -> (Vec<f64>, Option<Mat<f64>>, f64) {
    let (n, p) = (y.len(), columns.len());
    let x = Mat::from_fn(n, p, |i, j| columns[j][i]);
    let rhs = Mat::from_fn(n, 1, |i, _| y[i]);
    let beta = x.qr().solve_lstsq(&rhs);
    let fit = &x * &beta;
    let ssr: f64 = (0..n).map(|i| (y[i] - fit[(i, 0)]).powi(2)).sum();
    let cov = (n > p)
        .then(|| {
            let xtx = x.transpose() * &x;
            xtx.llt(Side::Lower).ok().map(|c| {
                let s2 = ssr / (n - p) as f64;
                c.inverse() * faer::Scale(s2)
            })
        })
        .flatten();
    ((0..p).map(|j| beta[(j, 0)]).collect(), cov, ssr)
}

fn range(a: &[f64]) -> [f64; 2] {
    [
        a.iter().copied().fold(f64::INFINITY, f64::min),
        a.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    ]
}

/// ΔL = λ a^α with both free (at least two points with distinct a).
pub fn fit_free(a: &[f64], dl: &[f64]) -> PowerLaw {
    let ln_a: Vec<f64> = a.iter().map(|v| v.ln()).collect();
    let ln_y: Vec<f64> = dl.iter().map(|v| v.ln()).collect();
    let (b, cov, ssr) = least_squares(&[vec![1.0; a.len()], ln_a], &ln_y);
    let lambda = b[0].exp();
    PowerLaw {
        lambda,
        lambda_err: cov.as_ref().map(|c| lambda * c[(0, 0)].sqrt()),
        alpha: b[1],
        alpha_err: cov.as_ref().map(|c| c[(1, 1)].sqrt()),
        a_range: range(a),
        points: a.len(),
        ssr,
    }
}

/// ΔL = λ a^α with α held at `alpha` (at least one point).
pub fn fit_fixed(a: &[f64], dl: &[f64], alpha: f64) -> PowerLaw {
    let y: Vec<f64> = a
        .iter()
        .zip(dl)
        .map(|(a, d)| d.ln() - alpha * a.ln())
        .collect();
    let (b, cov, ssr) = least_squares(&[vec![1.0; a.len()]], &y);
    let lambda = b[0].exp();
    PowerLaw {
        lambda,
        lambda_err: cov.as_ref().map(|c| lambda * c[(0, 0)].sqrt()),
        alpha,
        alpha_err: None,
        a_range: range(a),
        points: a.len(),
        ssr,
    }
}

/// The two-regime run-out law of one solver.
#[derive(Clone, Debug, Serialize)]
pub struct RunoutLaw {
    /// Small a: ΔL = λ a (α held at 1, the form of Lajeunesse et al. 2005).
    pub small: PowerLaw,
    /// Small a with α free too (`None` with fewer than three points).
    pub small_free: Option<PowerLaw>,
    /// Large a: ΔL = λ a^α, both free.
    pub large: PowerLaw,
    /// Crossover a_c where the two laws meet, λ_s a_c = λ_l a_c^α.
    pub crossover: f64,
    /// Whether a_c lies between the largest small-regime a and the smallest large-regime a
    /// (a consistent split; see [`fit_runout`]).
    pub crossover_between_regimes: bool,
    /// One law ΔL = λ a^α over all points, for comparison.
    pub single: PowerLaw,
}

/// Fits the two-regime law to (a, ΔL): every split of the points sorted by a into a small
/// regime (≥ 2 points, ΔL = λ_s a) and a large one (≥ 2 points, free power law) is tried.
/// Among the splits whose two laws cross between the regimes (a consistent split) the one
/// with the least total squared residual (log space) is kept; if no split is consistent, the
/// least-residual split. `None` with fewer than four usable points (ΔL > 0, a > 0).
pub fn fit_runout(a: &[f64], dl: &[f64]) -> Option<RunoutLaw> {
    let mut pts: Vec<(f64, f64)> = a
        .iter()
        .zip(dl)
        .map(|(&a, &d)| (a, d))
        .filter(|&(a, d)| a > 0.0 && d > 0.0 && a.is_finite() && d.is_finite())
        .collect();
    pts.sort_by(|p, q| p.0.total_cmp(&q.0));
    let n = pts.len();
    if n < 4 {
        return None;
    }
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.into_iter().unzip();
    // (consistent, SSR, law) per split; consistent splits first, then by SSR.
    let mut best: Option<(bool, f64, RunoutLaw)> = None;
    for k in 2..=n - 2 {
        // The large regime needs two distinct a.
        if xs[k] == xs[n - 1] {
            continue;
        }
        let small = fit_fixed(&xs[..k], &ys[..k], 1.0);
        let large = fit_free(&xs[k..], &ys[k..]);
        let ssr = small.ssr + large.ssr;
        let crossover = (large.lambda / small.lambda).powf(1.0 / (1.0 - large.alpha));
        let consistent = crossover >= xs[k - 1] && crossover <= xs[k];
        let better = best
            .as_ref()
            .is_none_or(|b| (consistent, -ssr) > (b.0, -b.1));
        if better {
            let law = RunoutLaw {
                small,
                small_free: (k >= 3).then(|| fit_free(&xs[..k], &ys[..k])),
                large,
                crossover,
                crossover_between_regimes: consistent,
                single: fit_free(&xs, &ys),
            };
            best = Some((consistent, ssr, law));
        }
    }
    best.map(|b| b.2)
}

/// The straight line y ≈ s x + c by least squares (at least two distinct x): (s, c).
pub fn linear_fit(x: &[f64], y: &[f64]) -> (f64, f64) {
    let (b, _, _) = least_squares(&[x.to_vec(), vec![1.0; x.len()]], y);
    (b[0], b[1])
}

/// y = λ (x − k)^α with λ, α and the shift k all free, as for Beverloo's law W ∝ (D − k d)^α:
/// for each trial k of `shifts` (each below the smallest x) the power law is fitted in log
/// space ([`fit_free`] on x − k), and the k with the least squared residual is kept. The
/// errors of λ and α are those of that fit (k held).
pub fn fit_shifted(x: &[f64], y: &[f64], shifts: &[f64]) -> Option<(f64, PowerLaw)> {
    let x_min = x.iter().copied().fold(f64::INFINITY, f64::min);
    shifts
        .iter()
        .filter(|&&k| k < x_min)
        .map(|&k| {
            let xs: Vec<f64> = x.iter().map(|v| v - k).collect();
            (k, fit_free(&xs, y))
        })
        .min_by(|a, b| a.1.ssr.total_cmp(&b.1.ssr))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact data on a known two-regime law is recovered to round-off, with zero residuals.
    #[test]
    fn recovers_an_exact_two_regime_law() {
        // ΔL = 1.6 a below a_c, 2.7 a^(2/3) above: they meet at a_c = (2.7/1.6)^3.
        let a = [0.3, 0.5, 1.0, 2.0, 6.0, 8.0, 10.0];
        let dl: Vec<f64> = a
            .iter()
            .map(|&a: &f64| {
                if a < 4.0 {
                    1.6 * a
                } else {
                    2.7 * a.powf(2.0 / 3.0)
                }
            })
            .collect();
        let law = fit_runout(&a, &dl).unwrap();
        assert!((law.small.lambda - 1.6).abs() < 1e-12, "{law:?}");
        assert!((law.large.alpha - 2.0 / 3.0).abs() < 1e-12, "{law:?}");
        assert!((law.large.lambda - 2.7).abs() < 1e-12, "{law:?}");
        assert!((law.crossover - (2.7f64 / 1.6).powi(3)).abs() < 1e-9);
        assert!(law.crossover_between_regimes);
        assert_eq!(law.small.points, 4);
        assert!(law.large.alpha_err.unwrap() < 1e-10);
        let free = law.small_free.unwrap();
        assert!((free.alpha - 1.0).abs() < 1e-12);
    }

    /// The standard error of a straight-line slope: for points (x, y) = (0, 0), (1, 1), (2, 1)
    /// in log space, hand-computed: β = (1/6, 1/2), SSR = 1/6, s² = 1/6, Var(α) = s²/Σ(x − x̄)²
    /// = (1/6)/2, Var(ln λ) = s²(1/n + x̄²/Σ(x − x̄)²) = (1/6)(1/3 + 1/2).
    #[test]
    fn standard_errors_match_the_textbook_formula() {
        let e = std::f64::consts::E;
        let law = fit_free(&[1.0, e, e * e], &[1.0, e, e]);
        assert!((law.alpha - 0.5).abs() < 1e-12);
        assert!((law.lambda.ln() - 1.0 / 6.0).abs() < 1e-12);
        assert!((law.ssr - 1.0 / 6.0).abs() < 1e-12);
        assert!((law.alpha_err.unwrap() - (1.0f64 / 12.0).sqrt()).abs() < 1e-12);
        let var_ln_l = (1.0 / 6.0) * (1.0 / 3.0 + 0.5);
        assert!((law.lambda_err.unwrap() - law.lambda * f64::sqrt(var_ln_l)).abs() < 1e-12);
        // Two points leave no degrees of freedom.
        assert!(fit_free(&[1.0, 2.0], &[1.0, 3.0]).alpha_err.is_none());
    }

    /// A line and a shifted power law built exactly are found again (to round-off, and to
    /// the trial grid for the shift).
    #[test]
    fn line_and_shifted_power_law_are_recovered() {
        let x = [1.0, 2.0, 3.0, 5.0];
        let y: Vec<f64> = x.iter().map(|v| 2.5 * v - 1.0).collect();
        let (s, c) = linear_fit(&x, &y);
        assert!((s - 2.5).abs() < 1e-12 && (c + 1.0).abs() < 1e-12);
        let d = [4.0, 5.0, 6.0, 8.0, 10.0];
        let w: Vec<f64> = d.iter().map(|v: &f64| 3.0 * (v - 1.5).powf(1.5)).collect();
        let shifts: Vec<f64> = (0..=40).map(|k| 0.1 * k as f64).collect();
        let (k, law) = fit_shifted(&d, &w, &shifts).unwrap();
        assert!((k - 1.5).abs() < 1e-9, "k = {k}");
        assert!((law.alpha - 1.5).abs() < 1e-9 && (law.lambda - 3.0).abs() < 1e-9);
    }
}
