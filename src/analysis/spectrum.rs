//! Spectral estimates of a sampled signal.
//!
//! [`dominant_frequency`] finds the strongest periodic component of a uniformly sampled
//! series: the mean is removed, a Hann window w_n = ½[1 − cos(2πn/N)] applied, the series
//! zero-padded to [`PAD`]× the next power of two and transformed with rustfft; the peak bin
//! k of the one-sided power spectrum P_k = |X_k|² is refined by a parabola through
//! (ln P_{k−1}, ln P_k, ln P_{k+1}), whose vertex is at
//!
//! δ = ½ (ln P_{k−1} − ln P_{k+1}) / (ln P_{k−1} − 2 ln P_k + ln P_{k+1}),
//!
//! giving f = (k + δ) / (M Δt) for an M-point transform. For a Hann-windowed sine the
//! log-parabola is exact to a few 10⁻³ of a bin.

use rustfft::{num_complex::Complex, FftPlanner};

/// Zero-padding factor applied on top of rounding the length up to a power of two.
pub const PAD: usize = 4;

/// Frequency (in 1/units of `dt`) of the largest peak of the spectrum of `samples` taken every
/// `dt`, excluding the zero bin. `None` if there are fewer than 8 samples, `dt` is not positive,
/// or the signal is constant.
pub fn dominant_frequency(samples: &[f64], dt: f64) -> Option<f64> {
    let n = samples.len();
    if n < 8 || dt.is_nan() || dt <= 0.0 {
        return None;
    }
    let power = power_spectrum(samples);
    let m = (power.len() - 1) * 2; // transform length
    let (k, &pk) = power
        .iter()
        .enumerate()
        .skip(1)
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if pk.is_nan() || pk <= 0.0 {
        return None;
    }
    let delta = if k + 1 < power.len() {
        vertex_offset(power[k - 1], pk, power[k + 1])
    } else {
        0.0
    };
    Some((k as f64 + delta) / (m as f64 * dt))
}

/// One-sided power spectrum |X_k|², k = 0..=M/2, of the mean-removed, Hann-windowed,
/// zero-padded series (M = [`PAD`] × the next power of two ≥ N).
pub fn power_spectrum(samples: &[f64]) -> Vec<f64> {
    let n = samples.len();
    let mean = samples.iter().sum::<f64>() / n as f64;
    let m = n.next_power_of_two() * PAD;
    let mut buf: Vec<Complex<f64>> = (0..m)
        .map(|j| {
            if j < n {
                let w = 0.5 * (1.0 - (2.0 * std::f64::consts::PI * j as f64 / n as f64).cos());
                Complex::new(w * (samples[j] - mean), 0.0)
            } else {
                Complex::new(0.0, 0.0)
            }
        })
        .collect();
    FftPlanner::new().plan_fft_forward(m).process(&mut buf);
    buf[..=m / 2].iter().map(|c| c.norm_sqr()).collect()
}

/// Vertex of the parabola through (−1, ln a), (0, ln b), (1, ln c), in bins from the middle one;
/// 0 where the logarithms are undefined or the points are not a maximum.
fn vertex_offset(a: f64, b: f64, c: f64) -> f64 {
    if [a, b, c].iter().any(|v| v.is_nan() || *v <= 0.0) {
        return 0.0;
    }
    let (la, lb, lc) = (a.ln(), b.ln(), c.ln());
    let den = la - 2.0 * lb + lc;
    if den < 0.0 {
        (0.5 * (la - lc) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(f: f64, dt: f64, n: usize, phase: f64, offset: f64) -> Vec<f64> {
        (0..n)
            .map(|j| offset + (2.0 * std::f64::consts::PI * f * j as f64 * dt + phase).sin())
            .collect()
    }

    /// A sine between bins, with an offset, comes back within 0.5 % (the shedding case's need).
    #[test]
    fn recovers_a_sine_frequency() {
        for (f, n, phase) in [(3.37, 500, 0.3), (0.1234, 3000, 1.9), (12.9, 257, -0.7)] {
            let dt = 0.01;
            let got = dominant_frequency(&sine(f, dt, n, phase, 2.5), dt).unwrap();
            assert!((got - f).abs() < 5e-3 * f, "f = {f}: got {got}");
        }
    }

    /// The larger of two tones wins, and noise-free harmonics do not pull it.
    #[test]
    fn picks_the_strongest_tone() {
        let dt = 0.05;
        let s: Vec<f64> = (0..800)
            .map(|j| {
                let t = j as f64 * dt;
                (2.0 * std::f64::consts::PI * 0.71 * t).sin()
                    + 0.3 * (2.0 * std::f64::consts::PI * 1.42 * t).cos()
            })
            .collect();
        let got = dominant_frequency(&s, dt).unwrap();
        assert!((got - 0.71).abs() < 5e-3 * 0.71, "got {got}");
    }

    #[test]
    fn refuses_degenerate_input() {
        assert_eq!(dominant_frequency(&[1.0; 4], 1.0), None);
        assert_eq!(dominant_frequency(&[1.0; 64], 1.0), None);
        assert_eq!(dominant_frequency(&sine(1.0, 0.1, 64, 0.0, 0.0), 0.0), None);
    }
}
