//! Bagnold's velocity profile of a steady, uniform granular flow down an incline.
//!
//! With the local rheology μ(I) and a uniform solid fraction, the shear stress
//! τ = ρ φ g sin θ (h − z) and the pressure P = ρ φ g cos θ (h − z) have a constant ratio, so
//! I = γ̇ d / √(P/ρ) is uniform and γ̇ ∝ √(h − z): integrated from the base,
//! u(z) = u_s + A (h^{3/2} − (h − z)^{3/2}) (Bagnold 1954; Silbert et al. 2001; GDR MiDi
//! 2004), z the height above the base, h the flow depth, u_s the slip on the base.
//!
//! [`fit`] measures h from the solid-fraction profile (the height where φ falls to half its
//! bulk value), fits u_s and A by least squares over the bulk slices, and reports the largest
//! deviation relative to the fitted surface speed; it also fits the exponent n of
//! u_s + A (h^n − (h − z)^n) freely (3/2 for Bagnold, 1 for a linear profile) and a straight
//! line, for contrast.

use super::powerlaw::least_squares;

/// The fraction of the depth, from the base and from the surface, left out of the bulk.
pub const BULK_MARGIN: f64 = 0.15;

/// A fit of Bagnold's profile (all lengths in m, speeds in m/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BagnoldFit {
    /// Flow depth h above the base.
    pub depth: f64,
    /// Bulk solid fraction (median over the middle third of the occupied slices).
    pub bulk_fraction: f64,
    /// Slip speed u_s on the base.
    pub slip: f64,
    /// Amplitude A (m^{-1/2} s^{-1}).
    pub amplitude: f64,
    /// Fitted speed at the surface, u_s + A h^{3/2}.
    pub surface_speed: f64,
    /// Largest |u − u_fit| over the bulk slices, relative to `surface_speed`.
    pub max_deviation: f64,
    /// The same for the best straight line u = a + b z.
    pub linear_deviation: f64,
    /// Exponent n of the best u_s + A (h^n − (h − z)^n), searched over 0.5–3 in steps of 0.01.
    pub free_exponent: f64,
    /// Bulk slices used.
    pub slices: usize,
}

/// Fit Bagnold's profile to slices at heights `y` (ascending) with solid fractions `phi` and
/// mean speeds `u` along the slope, above a base at `y_base`. `None` when no surface is found
/// (φ never falls below half its bulk value) or fewer than 5 slices lie in the bulk.
pub fn fit(y: &[f64], phi: &[f64], u: &[f64], y_base: f64) -> Option<BagnoldFit> {
    let above: Vec<usize> = (0..y.len()).filter(|&k| y[k] > y_base).collect();
    // Bulk solid fraction: the median over the middle third of the occupied slices.
    let occupied: Vec<usize> = above.iter().copied().filter(|&k| phi[k] > 0.0).collect();
    let (&first, &last) = (occupied.first()?, occupied.last()?);
    let median = |ks: &[usize]| -> Option<f64> {
        let mut v: Vec<f64> = ks.iter().map(|&k| phi[k]).collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied()
    };
    let mid: Vec<usize> = (first..=last)
        .filter(|&k| {
            let t = (k - first) as f64 / (last - first).max(1) as f64;
            (0.33..=0.67).contains(&t)
        })
        .collect();
    let phi_b = median(&mid)?;
    // The surface: the first slice above the densest part where φ < φ_b / 2, interpolated.
    let top = (first..=last).rev().find(|&k| phi[k] >= 0.5 * phi_b)?;
    let next = (top + 1 < y.len()).then_some(top + 1)?;
    let (p0, p1) = (phi[top], phi[next]);
    let s = (p0 - 0.5 * phi_b) / (p0 - p1);
    let depth = y[top] + s * (y[next] - y[top]) - y_base;
    let bulk: Vec<usize> = above
        .iter()
        .copied()
        .filter(|&k| {
            let z = (y[k] - y_base) / depth;
            (BULK_MARGIN..=1.0 - BULK_MARGIN).contains(&z) && u[k].is_finite()
        })
        .collect();
    if bulk.len() < 5 {
        return None;
    }
    let z: Vec<f64> = bulk.iter().map(|&k| y[k] - y_base).collect();
    let ub: Vec<f64> = bulk.iter().map(|&k| u[k]).collect();
    let shape = |n: f64| -> Vec<f64> {
        z.iter()
            .map(|z| depth.powf(n) - (depth - z).powf(n))
            .collect()
    };
    // u = u_s + A g(z) by least squares; the fit and its sum of squared residuals.
    let lsq = |g: &[f64]| {
        let (b, _, ssr) = least_squares(&[vec![1.0; g.len()], g.to_vec()], &ub);
        (b[0], b[1], ssr)
    };
    let deviation = |g: &[f64], c: (f64, f64), scale: f64| {
        g.iter()
            .zip(&ub)
            .map(|(g, u)| (c.0 + c.1 * g - u).abs() / scale)
            .fold(0.0, f64::max)
    };
    let g = shape(1.5);
    let (slip, amplitude, _) = lsq(&g);
    let surface_speed = slip + amplitude * depth.powf(1.5);
    let max_deviation = deviation(&g, (slip, amplitude), surface_speed);
    let (a, b, _) = lsq(&z);
    let linear_deviation = deviation(&z, (a, b), surface_speed);
    let free_exponent = (50..=300)
        .map(|k| 0.01 * k as f64)
        .map(|n| (n, lsq(&shape(n)).2))
        .min_by(|p, q| p.1.total_cmp(&q.1))
        .map(|p| p.0)?;
    Some(BagnoldFit {
        depth,
        bulk_fraction: phi_b,
        slip,
        amplitude,
        surface_speed,
        max_deviation,
        linear_deviation,
        free_exponent,
        slices: bulk.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slices of a layer h = 20 deep at φ = 0.8 (φ falling linearly to 0 over one slice at the
    /// surface) with the speed profile `u`.
    fn layer(u: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let y: Vec<f64> = (0..60).map(|k| 0.5 * k as f64 + 0.25).collect();
        let phi = y
            .iter()
            .map(|&y| (0.8 * (20.25 - y) / 0.5).clamp(0.0, 0.8))
            .collect();
        let u = y.iter().map(|&y| u(y.min(20.0))).collect();
        (y, phi, u)
    }

    /// An exact Bagnold profile is recovered: depth to a slice's fraction, u_s and A to
    /// round-off, exponent 3/2, zero deviation; a straight line fitted to it misses by more.
    #[test]
    fn exact_bagnold_profile_is_recovered() {
        let h: f64 = 20.0;
        let (y, phi, u) = layer(|z| 0.1 + 0.02 * (h.powf(1.5) - (h - z).powf(1.5)));
        let f = fit(&y, &phi, &u, 0.0).unwrap();
        assert!((f.depth - 20.0).abs() < 0.3, "{}", f.depth);
        assert!((f.bulk_fraction - 0.8).abs() < 1e-12);
        assert!(f.max_deviation < 0.01, "{f:?}");
        assert!((f.free_exponent - 1.5).abs() <= 0.05, "{f:?}");
        assert!(f.linear_deviation > 2.0 * f.max_deviation, "{f:?}");
    }

    /// A linear profile gives exponent 1, not 3/2.
    #[test]
    fn linear_profile_is_told_apart() {
        let (y, phi, u) = layer(|z| 0.1 + 0.05 * z);
        let f = fit(&y, &phi, &u, 0.0).unwrap();
        assert!((f.free_exponent - 1.0).abs() <= 0.02, "{f:?}");
        assert!(f.linear_deviation < 1e-12, "{f:?}");
    }
}
