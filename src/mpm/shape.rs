//! Shape functions of the background grid: standard MPM (bilinear hat) and uGIMP
//! (Bardenhagen & Kober 2004, the generalised interpolation material point method with a
//! constant particle domain).
//!
//! In 1-D, with d = x_p − x_i the distance from node i to the point, h the cell size and l_p
//! the half-width of the point's domain (uGIMP: l_p is set at the start and **not updated**
//! as the material deforms):
//!
//! ```text
//!  standard MPM:   S(d) = 1 − |d|/h                   |d| < h
//!
//!  uGIMP:          S(d) = 1 − (d² + l_p²)/(2 h l_p)    |d| < l_p
//!                  S(d) = 1 − |d|/h                    l_p ≤ |d| < h − l_p
//!                  S(d) = (h + l_p − |d|)²/(4 h l_p)   h − l_p ≤ |d| < h + l_p
//!                  S(d) = 0                            otherwise
//!
//!  support of node i (uGIMP), seen from the point:
//!
//!        node i−1            node i             node i+1
//!           o------------------o------------------o
//!       |<-l_p->|                          |<-l_p->|
//!       x_i − h − l_p                      x_i + h + l_p
//!           S rises quadratically, is the hat between, and falls quadratically:
//!           a point of width 2 l_p touches up to 3 nodes per direction.
//! ```
//!
//! The gradient is dS/dd (the derivative of S with respect to the point position). In 2-D
//! the weights are tensor products: N_i = S(d_x) S(d_y), ∇N_i = (S′(d_x) S(d_y), S(d_x) S′(d_y)).
//! Both kinds use one 3 × 3 node stencil per point, starting at node
//! ⌊(x_p − l_p)/h⌋ (uGIMP) or ⌊x_p/h⌋ (standard; its third node has weight 0), so the update
//! loops are the same for both.

use serde::{Deserialize, Serialize};

/// Which shape functions the grid uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// Standard MPM: bilinear hat functions of the point position (cell-crossing noise).
    Standard,
    /// uGIMP: the hat convolved with the point's constant domain of half-width l_p.
    Gimp,
}

/// Nodes per direction in a point's stencil.
pub const STENCIL: usize = 3;

/// Value and derivative of the 1-D uGIMP function at distance `d`, for cell `h` and half-width
/// `lp` (0 < lp ≤ h/2).
#[inline(always)]
pub fn gimp_1d(d: f64, h: f64, lp: f64) -> (f64, f64) {
    let a = d.abs();
    let s = d.signum();
    if a < lp {
        (1.0 - (d * d + lp * lp) / (2.0 * h * lp), -d / (h * lp))
    } else if a < h - lp {
        (1.0 - a / h, -s / h)
    } else if a < h + lp {
        let r = h + lp - a;
        (r * r / (4.0 * h * lp), -s * r / (2.0 * h * lp))
    } else {
        (0.0, 0.0)
    }
}

/// Value and derivative of the 1-D hat function at distance `d`.
#[inline(always)]
pub fn hat_1d(d: f64, h: f64) -> (f64, f64) {
    let a = d.abs();
    if a < h {
        (1.0 - a / h, -d.signum() / h)
    } else {
        (0.0, 0.0)
    }
}

/// First stencil node index and the 3 weights and derivatives along one direction, for a
/// point at grid coordinate `x` (m, measured from the grid origin).
#[inline(always)]
pub fn weights_1d(kind: ShapeKind, x: f64, h: f64, lp: f64) -> (i64, [f64; 3], [f64; 3]) {
    let mut w = [0.0; 3];
    let mut g = [0.0; 3];
    match kind {
        ShapeKind::Gimp => {
            let i0 = ((x - lp) / h).floor() as i64;
            for k in 0..3 {
                let d = x - (i0 + k as i64) as f64 * h;
                (w[k], g[k]) = gimp_1d(d, h, lp);
            }
            (i0, w, g)
        }
        ShapeKind::Standard => {
            let i0 = (x / h).floor() as i64;
            for k in 0..2 {
                let d = x - (i0 + k as i64) as f64 * h;
                (w[k], g[k]) = hat_1d(d, h);
            }
            (i0, w, g)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const H: f64 = 0.1;

    fn positions() -> Vec<f64> {
        (0..997)
            .map(|k| 0.3 + 0.7 * k as f64 / 996.0 * H * 3.0)
            .collect()
    }

    /// Σ_i S_i = 1 and Σ_i S′_i = 0 at every position, both kinds (to round-off).
    #[test]
    fn partition_of_unity_and_zero_gradient_sum() {
        for kind in [ShapeKind::Standard, ShapeKind::Gimp] {
            for lp in [H / 8.0, H / 4.0, H / 2.0] {
                for x in positions() {
                    let (_, w, g) = weights_1d(kind, x, H, lp);
                    let sw: f64 = w.iter().sum();
                    let sg: f64 = g.iter().sum();
                    assert!((sw - 1.0).abs() < 1e-12, "{kind:?} x={x} Σw={sw}");
                    assert!(sg.abs() < 1e-9, "{kind:?} x={x} Σg={sg}");
                    assert!(w.iter().all(|&v| v >= 0.0));
                }
            }
        }
    }

    /// The stencil reproduces linear fields: Σ_i S_i x_i = x_p (both kinds).
    #[test]
    fn linear_completeness() {
        for kind in [ShapeKind::Standard, ShapeKind::Gimp] {
            for x in positions() {
                let (i0, w, g) = weights_1d(kind, x, H, H / 4.0);
                let xi = |k: usize| (i0 + k as i64) as f64 * H;
                let r: f64 = (0..3).map(|k| w[k] * xi(k)).sum();
                let dr: f64 = (0..3).map(|k| g[k] * xi(k)).sum();
                assert!((r - x).abs() < 1e-12 && (dr - 1.0).abs() < 1e-9);
            }
        }
    }

    /// Derivatives against central differences of the value (away from the kinks).
    #[test]
    fn gradient_matches_finite_differences() {
        let e = 1e-7;
        for lp in [H / 4.0, H / 3.0] {
            for k in 0..400 {
                let d = -1.6 * H + 3.2 * H * (k as f64 + 0.37) / 400.0;
                let fd = (gimp_1d(d + e, H, lp).0 - gimp_1d(d - e, H, lp).0) / (2.0 * e);
                assert!((fd - gimp_1d(d, H, lp).1).abs() < 1e-5 / H, "d={d}");
                let fd = (hat_1d(d + e, H).0 - hat_1d(d - e, H).0) / (2.0 * e);
                if (d.abs() - H).abs() > 2.0 * e && d.abs() > 2.0 * e {
                    assert!((fd - hat_1d(d, H).1).abs() < 1e-5 / H);
                }
            }
        }
    }

    /// uGIMP is C¹: value and slope continuous at the breakpoints |d| = l_p, h − l_p, h + l_p
    /// (what removes the cell-crossing force jump), unlike the hat at d = 0.
    #[test]
    fn gimp_is_continuously_differentiable() {
        let lp = H / 4.0;
        for b in [lp, H - lp, H + lp] {
            for s in [-1.0, 1.0] {
                let (a, c) = (gimp_1d(s * b - 1e-12, H, lp), gimp_1d(s * b + 1e-12, H, lp));
                assert!(
                    (a.0 - c.0).abs() < 1e-9 && (a.1 - c.1).abs() < 1e-8,
                    "b={b}"
                );
            }
        }
        assert!((hat_1d(-1e-12, H).1 - hat_1d(1e-12, H).1).abs() > 1.0);
    }
}
