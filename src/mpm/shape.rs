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

/// The 1-D shape function of a point along one direction: the kind, the cell size h and the
/// point's half-width l_p, with 1/h and 1/(h l_p) kept so that the per-step stencils multiply
/// rather than divide (the stencils were 15 % of a step's time with the quotients).
#[derive(Clone, Copy, Debug)]
pub struct Shape1d {
    kind: ShapeKind,
    h: f64,
    lp: f64,
    inv_h: f64,
    inv_hlp: f64,
}

impl Shape1d {
    /// For cell `h` and half-width `lp` (uGIMP: 0 < lp ≤ h/2; unused by the hat).
    #[inline(always)]
    pub fn new(kind: ShapeKind, h: f64, lp: f64) -> Self {
        Self::with_inverse(kind, h, 1.0 / h, lp)
    }

    /// As [`Shape1d::new`] with 1/h given (one quotient per point instead of two).
    #[inline(always)]
    pub fn with_inverse(kind: ShapeKind, h: f64, inv_h: f64, lp: f64) -> Self {
        Shape1d {
            kind,
            h,
            lp,
            inv_h,
            inv_hlp: inv_h / lp,
        }
    }

    /// Value and derivative of the 1-D uGIMP function at distance `d` (the definition, piece
    /// by piece; [`Shape1d::weights`] evaluates it on a stencil).
    pub fn gimp(&self, d: f64) -> (f64, f64) {
        let Shape1d {
            h,
            lp,
            inv_h,
            inv_hlp,
            ..
        } = *self;
        let a = d.abs();
        let s = d.signum();
        if a < lp {
            (1.0 - 0.5 * (d * d + lp * lp) * inv_hlp, -d * inv_hlp)
        } else if a < h - lp {
            (1.0 - a * inv_h, -s * inv_h)
        } else if a < h + lp {
            let r = h + lp - a;
            (0.25 * r * r * inv_hlp, -0.5 * s * r * inv_hlp)
        } else {
            (0.0, 0.0)
        }
    }

    /// Value and derivative of the 1-D hat function at distance `d`.
    pub fn hat(&self, d: f64) -> (f64, f64) {
        let a = d.abs();
        if a < self.h {
            (1.0 - a * self.inv_h, -d.signum() * self.inv_h)
        } else {
            (0.0, 0.0)
        }
    }

    /// First stencil node index and the 3 weights and derivatives, for a point at grid
    /// coordinate `x` (m, measured from the grid origin).
    ///
    /// uGIMP: with i₀ = ⌊(x − l_p)/h⌋ and t = x − i₀ h ∈ [l_p, h + l_p), each node can only be
    /// in two pieces of [`Shape1d::gimp`]: node i₀ (d = t) in the hat or the outer piece,
    /// node i₀ + 1 (d = t − h ∈ [l_p − h, l_p)) in the inner or the hat piece, node i₀ + 2
    /// (|d| = 2h − t) in the outer piece or beyond the support. The hat: t ∈ [0, h) from
    /// i₀ = ⌊x/h⌋, weights 1 − t/h and t/h.
    #[inline(always)]
    pub fn weights(&self, x: f64) -> (i64, [f64; 3], [f64; 3]) {
        let Shape1d {
            h,
            lp,
            inv_h,
            inv_hlp,
            ..
        } = *self;
        match self.kind {
            ShapeKind::Gimp => {
                let i0 = ((x - lp) * inv_h).floor();
                let t = x - i0 * h;
                // Node i₀: the outer piece's r = h + l_p − t, the hat where r > 2 l_p.
                let r0 = (h + lp - t).max(0.0);
                let (w0, g0) = if r0 > 2.0 * lp {
                    (1.0 - t * inv_h, -inv_h)
                } else {
                    (0.25 * r0 * r0 * inv_hlp, -0.5 * r0 * inv_hlp)
                };
                // Node i₀ + 1: inner where d > −l_p, else the hat at |d| = −d.
                let d1 = t - h;
                let (w1, g1) = if d1 > -lp {
                    (1.0 - 0.5 * (d1 * d1 + lp * lp) * inv_hlp, -d1 * inv_hlp)
                } else {
                    (1.0 + d1 * inv_h, inv_h)
                };
                // Node i₀ + 2: the outer piece's r = h + l_p − (2h − t), zero where r ≤ 0.
                let r2 = (t + lp - h).max(0.0);
                let (w2, g2) = (0.25 * r2 * r2 * inv_hlp, 0.5 * r2 * inv_hlp);
                (i0 as i64, [w0, w1, w2], [g0, g1, g2])
            }
            ShapeKind::Standard => {
                let i0 = (x * inv_h).floor();
                // The product by 1/h can round x/h up to the next node: f a hair below 0.
                let f = ((x - i0 * h) * inv_h).max(0.0);
                (i0 as i64, [1.0 - f, f, 0.0], [-inv_h, inv_h, 0.0])
            }
        }
    }
}

/// First stencil node index and the 3 weights and derivatives along one direction, for a
/// point at grid coordinate `x` (m, measured from the grid origin).
#[inline(always)]
pub fn weights_1d(kind: ShapeKind, x: f64, h: f64, lp: f64) -> (i64, [f64; 3], [f64; 3]) {
    Shape1d::new(kind, h, lp).weights(x)
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

    /// The stencil's weights and derivatives are the shape functions of the distances to its
    /// three nodes, to round-off (the stencil selects the pieces a node can be in).
    #[test]
    fn stencil_evaluates_the_shape_functions() {
        for lp in [H / 8.0, H / 4.0, H / 2.0] {
            for kind in [ShapeKind::Standard, ShapeKind::Gimp] {
                let shape = Shape1d::new(kind, H, lp);
                for x in positions() {
                    let (i0, w, g) = shape.weights(x);
                    for k in 0..3 {
                        let d = x - (i0 + k as i64) as f64 * H;
                        let (wk, gk) = match kind {
                            ShapeKind::Gimp => shape.gimp(d),
                            ShapeKind::Standard => shape.hat(d),
                        };
                        assert!((w[k] - wk).abs() < 1e-12, "{kind:?} x={x} node {k}");
                        // The hat's slope jumps at |d| = 0 and h: no check there.
                        let kink = kind == ShapeKind::Standard
                            && (d.abs() < 1e-9 || (d.abs() - H).abs() < 1e-9);
                        assert!(
                            kink || (g[k] - gk).abs() < 1e-9 / H,
                            "{kind:?} x={x} node {k}"
                        );
                    }
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
                let (gimp, hat) = (
                    Shape1d::new(ShapeKind::Gimp, H, lp),
                    Shape1d::new(ShapeKind::Standard, H, lp),
                );
                let fd = (gimp.gimp(d + e).0 - gimp.gimp(d - e).0) / (2.0 * e);
                assert!((fd - gimp.gimp(d).1).abs() < 1e-5 / H, "d={d}");
                let fd = (hat.hat(d + e).0 - hat.hat(d - e).0) / (2.0 * e);
                if (d.abs() - H).abs() > 2.0 * e && d.abs() > 2.0 * e {
                    assert!((fd - hat.hat(d).1).abs() < 1e-5 / H);
                }
            }
        }
    }

    /// uGIMP is C¹: value and slope continuous at the breakpoints |d| = l_p, h − l_p, h + l_p
    /// (what removes the cell-crossing force jump), unlike the hat at d = 0.
    #[test]
    fn gimp_is_continuously_differentiable() {
        let lp = H / 4.0;
        let gimp = Shape1d::new(ShapeKind::Gimp, H, lp);
        let hat = Shape1d::new(ShapeKind::Standard, H, lp);
        for b in [lp, H - lp, H + lp] {
            for s in [-1.0, 1.0] {
                let (a, c) = (gimp.gimp(s * b - 1e-12), gimp.gimp(s * b + 1e-12));
                assert!(
                    (a.0 - c.0).abs() < 1e-9 && (a.1 - c.1).abs() < 1e-8,
                    "b={b}"
                );
            }
        }
        assert!((hat.hat(-1e-12).1 - hat.hat(1e-12).1).abs() > 1.0);
    }
}
