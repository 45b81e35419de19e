//! Decaying Taylor–Green vortex in a periodic box (validation case `taylor-green`).
//!
//! With k = 2π/L the incompressible Navier–Stokes equations have the exact solution
//! u = −U₀cos(kx)sin(ky)e^(−2νk²t), v = U₀sin(kx)cos(ky)e^(−2νk²t),
//! p = −ρU₀²/4·(cos 2kx + cos 2ky)e^(−4νk²t) (docs/validation.md, "Taylor–Green vortex"), so the
//! kinetic energy decays as e^(−4νk²t).
//!
//! Initialisation: the file's own `[initial]` field (the analytic velocity and pressure at
//! t = 0, started with their Chapman–Enskog populations, [`crate::scenario::fluid::initial`]),
//! so there is no initial transient and the decay rate is fitted over the whole run. Checked:
//! the energy decay rate within 1 % of 4νk² at every resolution and the order of the velocity
//! error under diffusive scaling (fixed τ, same physical time) at least 1.9.

use crate::lbm::Backend;
use crate::report::{Check, Fidelity, Plot, Report, Series};
use crate::scenario::fluid::Scenario;
use crate::scenario::ScenarioFile;
use crate::Result;

const CASE: &str = "taylor-green";
const SCENARIO: &str = include_str!("../../../../models/lbm/taylor_green.toml");

/// The analytic vortex in lattice units.
#[derive(Clone, Copy)]
struct Vortex {
    /// Amplitude U₀.
    u0: f64,
    /// Wave number k = 2π/N.
    k: f64,
    /// Viscosity ν.
    nu: f64,
}

impl Vortex {
    /// (u, v) at cell (x, y) and time t (steps).
    fn velocity(&self, x: usize, y: usize, t: f64) -> (f64, f64) {
        let (kx, ky) = (self.k * (x as f64 + 0.5), self.k * (y as f64 + 0.5));
        let a = self.u0 * (-2.0 * self.nu * self.k * self.k * t).exp();
        (-a * kx.cos() * ky.sin(), a * kx.sin() * ky.cos())
    }
}

/// What one resolution gives.
struct Outcome {
    /// Fitted −d ln E/dt divided by 4νk².
    rate_ratio: f64,
    /// ‖u − u_exact‖₂/‖u_exact‖₂ at the end.
    l2_error: f64,
    /// Lattice Mach number U₀/c_s at t = 0.
    mach: f64,
    /// (t in s, E/E₀) at the samples the rate was fitted to.
    energy: Vec<(f64, f64)>,
    /// 4νk² in 1/s.
    rate_si: f64,
}

/// Run the vortex on `cells`² cells to `time.end`.
fn solve(base: &Scenario, cells: usize) -> Result<Outcome> {
    let mut sc = base.clone();
    let l = sc.reference.length;
    sc.domain.dx = l / cells as f64;
    sc.domain.size = [l, l];
    let d = sc.derive()?;
    let mut lbm = sc.build_f64(&d)?;
    let n = d.cells[0];
    let vortex = Vortex {
        u0: d.u_lattice,
        k: 2.0 * std::f64::consts::PI / n as f64,
        nu: d.nu_lattice,
    };
    let energy = |lbm: &dyn crate::lbm::Fluid| -> f64 {
        (0..n * n)
            .map(|c| {
                let (r, u, v) = lbm.cell_state(c);
                0.5 * r * (u * u + v * v)
            })
            .sum()
    };
    let sample_every = (d.steps / 32).max(1);
    let mut samples = vec![(0.0, energy(lbm.as_ref()).ln())];
    for s in 1..=d.steps {
        lbm.steps(1);
        if s % sample_every == 0 || s == d.steps {
            samples.push((s as f64, energy(lbm.as_ref()).ln()));
        }
    }
    let rate = -slope(&samples);
    let t = d.steps as f64;
    let (mut num, mut den) = (0.0, 0.0);
    for c in 0..n * n {
        let (_, u, v) = lbm.cell_state(c);
        let (ue, ve) = vortex.velocity(c % n, c / n, t);
        num += (u - ue).powi(2) + (v - ve).powi(2);
        den += ue * ue + ve * ve;
    }
    let k2 = vortex.k * vortex.k;
    let dt = d.units.dt;
    let ln_e0 = samples[0].1;
    Ok(Outcome {
        rate_ratio: rate / (4.0 * vortex.nu * k2),
        l2_error: (num / den).sqrt(),
        mach: d.mach,
        energy: samples
            .iter()
            .map(|&(s, ln_e)| (s * dt, (ln_e - ln_e0).exp()))
            .collect(),
        rate_si: 4.0 * vortex.nu * k2 / dt,
    })
}

/// Least-squares slope of y against x.
fn slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// Run the case.
pub fn run(f: Fidelity) -> Result<Report> {
    run_on(f, Backend::Cpu)
}

/// Run the case on `backend`.
pub fn run_on(f: Fidelity, backend: Backend) -> Result<Report> {
    let mut base = Scenario::from_toml(SCENARIO)?;
    base.lbm.backend = backend;
    let cells: &[usize] = match f {
        Fidelity::Test => &[16, 32, 64],
        Fidelity::Full => &[32, 64, 128],
    };
    let mut checks = Vec::new();
    let mut errors = Vec::new();
    let mut decay = Plot::new(
        "taylor-green-energy",
        "Taylor–Green vortex: kinetic energy decay",
        "t (s)",
        "E / E₀",
    )
    .log(false, true);
    for (j, &n) in cells.iter().enumerate() {
        let o = solve(&base, n)?;
        if j + 1 == cells.len() {
            let t_end = o.energy.last().map_or(0.0, |p| p.0);
            let exact = (0..=100)
                .map(|k| {
                    let t = t_end * k as f64 / 100.0;
                    (t, (-o.rate_si * t).exp())
                })
                .collect();
            decay.series.insert(0, Series::line("exp(−4νk²t)", exact));
        }
        decay = decay.with(Series::markers(&format!("LBM, N = {n}"), o.energy));
        // Issue: decay rate within 1 % of 4νk², gated at every resolution.
        let q = format!("N = {n}: energy decay rate / 4νk²");
        checks.push(Check::rel(CASE, &q, o.rate_ratio, 1.0, 0.01));
        if j == 0 {
            // Largest Mach number of the study (U₀* ∝ Δx); 0.1 keeps O(Ma²) errors ≲ 1 %.
            checks.push(Check::at_most(
                CASE,
                &format!("N = {n}: lattice Mach number U₀/c_s"),
                o.mach,
                0.1,
            ));
        }
        checks.push(Check::report(
            CASE,
            &format!("N = {n}: velocity L2 relative error"),
            o.l2_error,
            0.0,
        ));
        errors.push(o.l2_error);
    }
    // Issue: velocity error order ≥ 1.9 under diffusive scaling, gated on the least-squares
    // order over the three grids. The order of each doubling is reported: error terms of
    // different sign (initial layer, O(Ma²), O(Δx²)) make it wander by ±0.1 around 2.
    for k in 1..cells.len() {
        let order = (errors[k - 1] / errors[k]).ln() / (cells[k] as f64 / cells[k - 1] as f64).ln();
        let q = format!("velocity L2 order, N = {} → {}", cells[k - 1], cells[k]);
        checks.push(Check::report(CASE, &q, order, 2.0));
    }
    let order = super::poiseuille::fitted_order(cells, &errors);
    checks.push(Check::at_least(
        CASE,
        "velocity L2 order, least-squares fit",
        order,
        1.9,
    ));
    let pts: Vec<(f64, f64)> = cells
        .iter()
        .map(|&n| n as f64)
        .zip(errors.iter().copied())
        .collect();
    let (n0, e0) = pts[0];
    let guide = pts
        .iter()
        .map(|&(n, _)| (n, e0 * (n0 / n).powi(2)))
        .collect();
    let convergence = Plot::new(
        "taylor-green-convergence",
        "Taylor–Green vortex: velocity error vs resolution",
        "N (cells per side)",
        "‖u − u_exact‖₂ / ‖u_exact‖₂",
    )
    .log(true, true)
    .with(Series::line("slope −2", guide))
    .with(Series::markers("LBM", pts));
    Ok(Report {
        checks,
        plots: vec![decay, convergence],
    })
}
