//! The time-averaged profile across y of a granular run (`[profile]`, [`ProfileSpec`]): solid
//! fraction and mean velocity per horizontal slice, written to `profile.csv`.
//!
//! A disk of radius R centred at height y_c covers, of the slice [y_a, y_b],
//! A = S(y_b − y_c) − S(y_a − y_c) with S(h) = R² arccos(−h/R) + h √(R² − h²) the disk's area
//! below the height h above its centre (0 for h ≤ −R, π R² for h ≥ R). Per slice b, summed over
//! the grains whose centre lies in the rectangle's x-range and over the samples:
//! φ_b = Σ A_ib / (W Δy n_samples), (u_b, v_b) = Σ A_ib **v**_i / Σ A_ib.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::spec::ProfileSpec;
use crate::dem::Grains;
use crate::io::CsvWriter;
use crate::Result;

/// Sums of a profile over the samples taken so far.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Profile {
    spec: ProfileSpec,
    /// Per slice: Σ A (m²).
    area: Vec<f64>,
    /// Per slice: Σ A u, Σ A v (m³/s).
    flux: Vec<[f64; 2]>,
    /// Samples taken.
    samples: u64,
}

/// Area of a disk of radius `r` below the height `h` above its centre.
fn area_below(h: f64, r: f64) -> f64 {
    if h <= -r {
        0.0
    } else if h >= r {
        std::f64::consts::PI * r * r
    } else {
        r * r * (-h / r).acos() + h * (r * r - h * h).sqrt()
    }
}

/// One slice of a profile: its centre height and the averages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slice {
    /// Height of the slice's centre (m).
    pub y: f64,
    /// Solid (area) fraction φ.
    pub solid_fraction: f64,
    /// Area-weighted mean velocity (m/s); NaN in a slice no grain crossed.
    pub velocity: [f64; 2],
}

impl Profile {
    /// An empty profile over `spec`'s slices.
    pub fn new(spec: ProfileSpec) -> Self {
        let n = spec.bins as usize;
        Profile {
            spec,
            area: vec![0.0; n],
            flux: vec![[0.0; 2]; n],
            samples: 0,
        }
    }

    /// Whether a sample is due at time `t` (s after the release).
    pub fn due(&self, t: f64) -> bool {
        t >= self.spec.start
    }

    /// Add the grains' present state.
    pub fn sample(&mut self, g: &Grains) {
        let [lo, hi] = self.spec.rectangle;
        let n = self.area.len();
        let dy = (hi[1] - lo[1]) / n as f64;
        for i in 0..g.len() {
            let (x, y, r) = (g.x[i], g.y[i], g.radius[i]);
            if !(x >= lo[0] && x < hi[0] && y >= lo[1] && y < hi[1]) {
                continue;
            }
            let first = (((y - r - lo[1]) / dy).floor().max(0.0)) as usize;
            let last = ((((y + r - lo[1]) / dy).floor()) as usize).min(n - 1);
            for b in first..=last {
                let ya = lo[1] + b as f64 * dy;
                let a = area_below(ya + dy - y, r) - area_below(ya - y, r);
                self.area[b] += a;
                self.flux[b][0] += a * g.vx[i];
                self.flux[b][1] += a * g.vy[i];
            }
        }
        self.samples += 1;
    }

    /// The averaged slices, bottom to top.
    pub fn slices(&self) -> Vec<Slice> {
        let [lo, hi] = self.spec.rectangle;
        let n = self.area.len();
        let dy = (hi[1] - lo[1]) / n as f64;
        let cell = (hi[0] - lo[0]) * dy * self.samples.max(1) as f64;
        (0..n)
            .map(|b| Slice {
                y: lo[1] + (b as f64 + 0.5) * dy,
                solid_fraction: self.area[b] / cell,
                velocity: [
                    self.flux[b][0] / self.area[b],
                    self.flux[b][1] / self.area[b],
                ],
            })
            .collect()
    }

    /// Write `profile.csv`: `y` (m, slice centre), `solid_fraction`, `u`, `v` (m/s), one row
    /// per slice, and `samples` (the same on every row).
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut csv = CsvWriter::create(path, &["y", "solid_fraction", "u", "v", "samples"])?;
        for s in self.slices() {
            csv.row(&[
                s.y,
                s.solid_fraction,
                s.velocity[0],
                s.velocity[1],
                self.samples as f64,
            ])?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// S(h) is the disk's area below h: ½ π R² at the centre, the whole disk above it; a
    /// disk's slices sum to its area.
    #[test]
    fn disk_area_in_slices_sums_to_the_disk() {
        let r = 0.7;
        let pi = std::f64::consts::PI;
        assert!((area_below(0.0, r) - 0.5 * pi * r * r).abs() < 1e-15);
        assert_eq!(area_below(r, r), pi * r * r);
        let mut g = Grains::new();
        g.push_disk(0.5, 1.234, r, 1.0);
        g.vx[0] = 2.0;
        let mut p = Profile::new(ProfileSpec {
            rectangle: [[0.0, 0.0], [2.0, 3.0]],
            bins: 7,
            start: 0.0,
        });
        p.sample(&g);
        let total: f64 = p.area.iter().sum();
        assert!((total - pi * r * r).abs() < 1e-12, "{total}");
        let s = p.slices();
        // φ = (the disk's area in the slice) / (W Δy) ≤ 1 (its chord, 1.4, is narrower than
        // W = 2), the velocity the grain's.
        assert!(s.iter().all(|s| s.solid_fraction <= 1.0 + 1e-12));
        assert!(s
            .iter()
            .filter(|s| s.solid_fraction > 0.0)
            .all(|s| (s.velocity[0] - 2.0).abs() < 1e-12 && s.velocity[1] == 0.0));
    }
}
