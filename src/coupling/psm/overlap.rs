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

/// One horizontal cell edge y = j − c_y of a disk's bounding box, with what
/// [`quadrant`] needs there: a = √(r² − y²) and the chord integrals at ±a (only for |y| < r).
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
struct RowEdge {
    y: f64,
    a: f64,
    c_a: f64,
    c_minus_a: f64,
}

/// The unit cells of one disk, [i, i+1] × [j, j+1] for the cells (i, j) of its bounding box,
/// with the chord integrals at the cell edges computed once per disk: neighbouring cells share
/// their edges, so a disk costs about 3 × (its diameter in cells) `asin`s instead of several
/// per cell. [`DiskCells::area`] is bit for bit [`disk_rect`] of the same cell.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct DiskCells {
    r: f64,
    i0: i64,
    j0: i64,
    /// x = i − c_x and ∫_{−r}^{x} s at the vertical edges i0 ..= i1 + 1.
    cols: Vec<(f64, f64)>,
    /// The horizontal edges j0 ..= j1 + 1.
    rows: Vec<RowEdge>,
    /// Chord integrals at −r and r.
    c_ends: [f64; 2],
}

impl DiskCells {
    /// Prepare the cells i0 ..= i1, j0 ..= j1 of the disk (centre `c`, radius `r`, in cell
    /// units); keeps the buffers.
    pub fn set(&mut self, c: [f64; 2], r: f64, [i0, i1]: [i64; 2], [j0, j1]: [i64; 2]) {
        self.r = r;
        self.i0 = i0;
        self.j0 = j0;
        self.c_ends = [chord_integral(-r, r), chord_integral(r, r)];
        self.cols.clear();
        self.cols.extend((i0..=i1 + 1).map(|i| {
            let x = i as f64 - c[0];
            (x, chord_integral(x, r))
        }));
        self.rows.clear();
        self.rows.extend((j0..=j1 + 1).map(|j| {
            let y = j as f64 - c[1];
            if y > -r && y < r {
                let a = (r * r - y * y).sqrt();
                RowEdge {
                    y,
                    a,
                    c_a: chord_integral(a, r),
                    c_minus_a: chord_integral(-a, r),
                }
            } else {
                RowEdge {
                    y,
                    ..RowEdge::default()
                }
            }
        }));
    }

    /// Area of the disk in cell (i, j) of the prepared box, as [`disk_rect`] computes it.
    pub fn area(&self, i: i64, j: i64) -> f64 {
        let r = self.r;
        let (ci, cj) = ((i - self.i0) as usize, (j - self.j0) as usize);
        let ((ax, cax), (bx, cbx)) = (self.cols[ci], self.cols[ci + 1]);
        let (ey0, ey1) = (&self.rows[cj], &self.rows[cj + 1]);
        let (ay, by) = (ey0.y, ey1.y);
        let inside = |x: f64, y: f64| x * x + y * y <= r * r;
        if inside(ax, ay) && inside(ax, by) && inside(bx, ay) && inside(bx, by) {
            return 1.0;
        }
        let (nx, ny) = (ax.max(0.0).min(bx), ay.max(0.0).min(by));
        if nx * nx + ny * ny >= r * r {
            return 0.0;
        }
        let q = |x: f64, cx: f64, e: &RowEdge| self.quadrant(x, cx, e);
        let a = q(bx, cbx, ey1) - q(ax, cax, ey1) - q(bx, cbx, ey0) + q(ax, cax, ey0);
        a.clamp(0.0, 1.0)
    }

    /// [`quadrant`] at x (with its chord integral `cx`) and the edge `e`, from the stored
    /// chord integrals.
    fn quadrant(&self, x: f64, cx: f64, e: &RowEdge) -> f64 {
        let (r, y) = (self.r, e.y);
        let [c_minus_r, c_r] = self.c_ends;
        // ∫_u^v s from the integrals at u and v (zero when v ≤ u), as `band`.
        let band = |u: f64, v: f64, cu: f64, cv: f64| if v <= u { 0.0 } else { cv - cu };
        if x <= -r || y <= -r {
            return 0.0;
        }
        if y >= r {
            return 2.0 * band(-r, x, c_minus_r, cx);
        }
        let a = e.a;
        // The integral at min(x, b) is the one at x or at b.
        let at_min = |b: f64, cb: f64| if x < b { (x, cx) } else { (b, cb) };
        let (xa, c_xa) = at_min(a, e.c_a);
        let inner = (xa + a).max(0.0);
        let middle = y * inner + band(-a, xa, e.c_minus_a, c_xa);
        if y >= 0.0 {
            let (xl, c_xl) = at_min(-a, e.c_minus_a);
            let (xr, c_xr) = at_min(r, c_r);
            middle + 2.0 * band(-r, xl, c_minus_r, c_xl) + 2.0 * band(a, xr, e.c_a, c_xr)
        } else {
            middle
        }
    }
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

    /// The per-disk cache gives exactly the areas of `disk_rect`, bit for bit, over the
    /// bounding boxes of disks of many sizes and offsets (including cells touching the circle
    /// at a corner and disks smaller than a cell).
    #[test]
    fn disk_cells_match_disk_rect_bit_for_bit() {
        let mut cells = DiskCells::default();
        let mut n = 0;
        for k in 0..400 {
            let t = k as f64;
            let (cx, cy) = (
                50.0 + (t * 0.618_034).fract() * 3.0,
                40.0 + (t * 0.414_214).fract(),
            );
            let r = [0.3, 0.5, 1.0, 2.0, 4.7, 10.25, 21.3][k % 7] + (t * 0.271_828).fract();
            let (i0, i1) = ((cx - r).floor() as i64, (cx + r).floor() as i64);
            let (j0, j1) = ((cy - r).floor() as i64, (cy + r).floor() as i64);
            cells.set([cx, cy], r, [i0, i1], [j0, j1]);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let (x, y) = (i as f64, j as f64);
                    let exact = disk_rect([cx, cy], r, x, x + 1.0, y, y + 1.0);
                    assert_eq!(cells.area(i, j).to_bits(), exact.to_bits(), "{k} {i} {j}");
                    n += (exact > 0.0 && exact < 1.0) as usize;
                }
            }
        }
        assert!(n > 10_000, "only {n} cut cells");
        // Integer centres and radii: edges through the centre and tangent to the circle.
        cells.set([10.0, 10.0], 3.0, [7, 13], [7, 13]);
        for j in 7..=13 {
            for i in 7..=13 {
                let (x, y) = (i as f64, j as f64);
                let exact = disk_rect([10.0, 10.0], 3.0, x, x + 1.0, y, y + 1.0);
                assert_eq!(cells.area(i, j).to_bits(), exact.to_bits());
            }
        }
    }
}
