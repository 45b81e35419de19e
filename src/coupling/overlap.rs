//! Exact area of a disk inside an axis-aligned rectangle: the solid fraction of a lattice cell
//! covered by a grain (Noble & Torczynski's ε, not a 0/1 mask).
//!
//! With coordinates relative to the disk centre and s(X) = √(r² − X²), the area of the disk
//! below y and left of x is
//!
//! A(x, y) = ∫_{−r}^{x} [min(y, s) + s]₊ dX,
//!
//! which splits at |X| = a = √(r² − y²) into pieces with the antiderivative
//! S(X) = ∫_{−r}^{X} s = ½ [X s(X) + r² asin(X/r)] + π r²/4. The area in the rectangle
//! [x₀, x₁] × [y₀, y₁] is A(x₁, y₁) − A(x₀, y₁) − A(x₁, y₀) + A(x₀, y₀).

use std::f64::consts::FRAC_PI_2;

/// ∫_{−r}^{X} √(r² − t²) dt for X clamped to [−r, r].
fn chord_integral(x: f64, r: f64) -> f64 {
    let x = x.clamp(-r, r);
    let s = (r * r - x * x).max(0.0).sqrt();
    0.5 * (x * s + r * r * ((x / r).clamp(-1.0, 1.0).asin() + FRAC_PI_2))
}

/// ∫_u^v √(r² − t²) dt over [u, v] (zero when v ≤ u), both clamped to [−r, r].
fn band(u: f64, v: f64, r: f64) -> f64 {
    if v <= u {
        0.0
    } else {
        chord_integral(v, r) - chord_integral(u, r)
    }
}

/// Area of the disk of radius `r` centred at the origin in the quadrant X ≤ x, Y ≤ y.
pub fn quadrant(x: f64, y: f64, r: f64) -> f64 {
    if x <= -r || y <= -r {
        return 0.0;
    }
    if y >= r {
        return 2.0 * band(-r, x, r);
    }
    let a = (r * r - y * y).sqrt();
    // Length of [−a, a] ∩ (−∞, x].
    let inner = (x.min(a) + a).max(0.0);
    let middle = y * inner + band(-a, x.min(a), r);
    if y >= 0.0 {
        // |X| > a: the whole chord 2s lies below y.
        middle + 2.0 * band(-r, x.min(-a), r) + 2.0 * band(a, x.min(r), r)
    } else {
        middle
    }
}

/// Area of the disk (centre `c`, radius `r`) inside the rectangle [x0, x1] × [y0, y1].
pub fn disk_rect(c: [f64; 2], r: f64, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let (ax, bx, ay, by) = (x0 - c[0], x1 - c[0], y0 - c[1], y1 - c[1]);
    // Rectangle fully inside the disk: the exact area, free of cancellation.
    let inside = |x: f64, y: f64| x * x + y * y <= r * r;
    if inside(ax, ay) && inside(ax, by) && inside(bx, ay) && inside(bx, by) {
        return (x1 - x0) * (y1 - y0);
    }
    // Nearest point of the rectangle to the centre outside the disk: no overlap.
    let (nx, ny) = (ax.max(0.0).min(bx), ay.max(0.0).min(by));
    if nx * nx + ny * ny >= r * r {
        return 0.0;
    }
    let a = quadrant(bx, by, r) - quadrant(ax, by, r) - quadrant(bx, ay, r) + quadrant(ax, ay, r);
    a.clamp(0.0, (x1 - x0) * (y1 - y0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn quadrant_limits() {
        let r = 1.3;
        assert!((quadrant(r, r, r) - PI * r * r).abs() < 1e-14);
        assert!((quadrant(0.0, 0.0, r) - PI * r * r / 4.0).abs() < 1e-14);
        assert!((quadrant(0.0, r, r) - PI * r * r / 2.0).abs() < 1e-14);
        assert!((quadrant(r, 0.0, r) - PI * r * r / 2.0).abs() < 1e-14);
        assert_eq!(quadrant(-r, 0.5, r), 0.0);
    }

    /// Summed over the cells of a lattice, the areas give π r² to 1e-12 relative, for
    /// off-centre disks of several sizes.
    #[test]
    fn cells_sum_to_the_disk_area() {
        for (cx, cy, r) in [
            (10.0, 10.0, 3.0),
            (10.37, 9.81, 4.3),
            (20.5, 20.5, 12.25),
            (15.1, 14.9, 0.4),
        ] {
            let mut sum = 0.0;
            for j in 0..45 {
                for i in 0..45 {
                    let (x, y) = (i as f64, j as f64);
                    sum += disk_rect([cx, cy], r, x, x + 1.0, y, y + 1.0);
                }
            }
            let exact = PI * r * r;
            assert!(
                ((sum - exact) / exact).abs() < 1e-12,
                "r = {r}: {sum} vs {exact}"
            );
        }
    }

    /// Symmetric placements give symmetric areas; a cell inside the disk is fully covered.
    #[test]
    fn symmetric_cases() {
        let r = 2.0;
        let c = [0.0, 0.0];
        // The four cells around the centre are inside; quarter of the annulus beyond is the rest.
        assert_eq!(disk_rect(c, r, 0.0, 1.0, 0.0, 1.0), 1.0);
        let q1 = disk_rect(c, r, 1.0, 2.0, 0.0, 1.0);
        let q2 = disk_rect(c, r, 0.0, 1.0, 1.0, 2.0);
        let q3 = disk_rect(c, r, -2.0, -1.0, -1.0, 0.0);
        assert!(
            (q1 - q2).abs() < 1e-14 && (q1 - q3).abs() < 1e-14,
            "{q1} {q2} {q3}"
        );
        // Cell [1,2]×[0,1] of a r = 2 disk: ∫₁² min(1, √(4 − x²)) dx = (√3 − 1) + ∫_√3^2 √(4 − x²) dx
        // = (√3 − 1) + [x s/2 + 2 asin(x/2)]_√3^2 = √3 − 1 + π/3 − √3/2.
        let exact = 3f64.sqrt() / 2.0 - 1.0 + PI / 3.0;
        assert!((q1 - exact).abs() < 1e-14, "{q1} vs {exact}");
        // A cell split in half by the centre line of a large disk.
        let half = disk_rect([0.5, 0.0], 100.0, 0.0, 1.0, -0.5, 0.5);
        assert!((half - 1.0).abs() < 1e-12);
        let edge = disk_rect([0.0, 0.0], 1.0, 1.0 - 1e-9, 2.0, -1.0, 1.0);
        assert!((0.0..1e-12).contains(&edge));
        // A small disk centred on the line x = 0.5: the right half-disk lies in [0.5, 1] × [0, 1].
        let small = disk_rect([0.5, 0.5], 0.2, 0.5, 1.0, 0.0, 1.0);
        assert!((small - PI * 0.04 / 2.0).abs() < 1e-15);
    }

    /// Agrees with midpoint-rule sampling on cells cut by the circle.
    #[test]
    fn agrees_with_sampling() {
        let (c, r) = ([3.3, 2.7], 2.1);
        let m = 400;
        for (i, j) in [(4, 2), (1, 1), (3, 4), (5, 3)] {
            let exact = disk_rect(c, r, i as f64, i as f64 + 1.0, j as f64, j as f64 + 1.0);
            let mut hits = 0;
            for a in 0..m {
                for b in 0..m {
                    let x = i as f64 + (a as f64 + 0.5) / m as f64 - c[0];
                    let y = j as f64 + (b as f64 + 0.5) / m as f64 - c[1];
                    if x * x + y * y < r * r {
                        hits += 1;
                    }
                }
            }
            let sampled = hits as f64 / (m * m) as f64;
            // Sampling error ≈ perimeter in the cell / m ≈ 1/400.
            assert!(
                (exact - sampled).abs() < 3e-3,
                "cell ({i},{j}): {exact} vs {sampled}"
            );
        }
    }
}
