//! Plane Poiseuille flow driven by a body force (validation case `poiseuille`).
//!
//! Periodic in x, half-way bounce-back walls at y = 0 and y = H. The steady solution is
//! u(y) = g/(2ν)·y(H − y) (docs/validation.md, "Poiseuille"). Checked:
//!
//! * BGK at the "magic" τ = ½ + √3/4 reproduces the parabola to round-off (Λ = 3/16 puts the
//!   wall exactly half-way), and so does MRT at τ = 0.8 with the magic s_q when the energy
//!   moments relax at s_ν too (then it is a TRT). With the standard s_e = 1.64, s_ε = 1.54 the
//!   MRT profile carries a further error of second order in the velocity: Guo's source
//!   (1 − s_e/2)·6u·F of the energy moment leaves e^neq ∝ u_x F_x, which bounce-back couples
//!   into the wall slip (measured ≈ 8e-9 of u_max at H = 32, scaling with g²);
//! * BGK at τ = 0.8 converges at second order in the L2 norm under diffusive scaling (fixed τ);
//! * BGK and MRT at τ = 0.8 differ by the known BGK wall slip. For TRT/BGK with half-way
//!   bounce-back the numerical solution is the exact parabola of an effective width
//!   H_eff² = H² + (16Λ − 3)/3, Λ = (τ − ½)² (Ginzburg & d'Humières 2003), i.e. a uniform offset
//!   δ = g(16Λ − 3)/(24ν), δ/u_max = (16Λ − 3)/(3H²) in lattice units; MRT with
//!   Λ = 3/16 has none, so the two profiles differ by exactly δ.

use crate::lbm::Backend;
use crate::report::{Check, Fidelity, Plot, Report, Series};
use crate::scenario::fluid::{CollisionKind, MrtSpec, Scenario};
use crate::scenario::ScenarioFile;
use crate::units::CS2;
use crate::Result;

const CASE: &str = "poiseuille";
const SCENARIO: &str = include_str!("../../../../models/lbm/poiseuille.toml");
/// A τ away from the magic value, so BGK carries a wall error that must converge.
const TAU_OFF_MAGIC: f64 = 0.8;
/// Cells along x (periodic; the flow is uniform in x).
const NX: usize = 4;

/// Which collision operator a run uses.
#[derive(Clone, Copy)]
enum Collision {
    /// Single relaxation time.
    Bgk,
    /// MRT with these rates (`None`: [`crate::lbm::MrtRates::standard`], magic s_q).
    Mrt(Option<MrtSpec>),
}

/// A steady LBM profile beside the analytic one, lattice units.
struct Profile {
    /// u_x at the cell centres y + ½, y = 0 … ny − 1.
    u: Vec<f64>,
    /// g/(2ν)·y(H − y) at the same points.
    exact: Vec<f64>,
    /// Analytic u_max = gH²/(8ν).
    u_max: f64,
    /// Largest |u|/c_s on the lattice.
    mach: f64,
}

impl Profile {
    /// max |u − u_exact| / u_max.
    fn max_rel_error(&self) -> f64 {
        max_abs_diff(&self.u, &self.exact) / self.u_max
    }

    /// ‖u − u_exact‖₂ / ‖u_exact‖₂.
    fn l2_error(&self) -> f64 {
        let num: f64 = self
            .u
            .iter()
            .zip(&self.exact)
            .map(|(a, b)| (a - b).powi(2))
            .sum();
        let den: f64 = self.exact.iter().map(|b| b * b).sum();
        (num / den).sqrt()
    }
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Run the scenario with `cells` across the channel at relaxation time `tau` to `time.end`.
///
/// `collision`: BGK, or MRT with the given rates (`None`: the standard ones).
fn solve(base: &Scenario, cells: usize, tau: f64, collision: Collision) -> Result<Profile> {
    let mut sc = base.clone();
    let h = sc.domain.size[1];
    sc.domain.dx = h / cells as f64;
    sc.domain.size = [NX as f64 * sc.domain.dx, h];
    sc.time.tau = Some(tau);
    sc.time.dt = None;
    (sc.lbm.collision, sc.lbm.mrt) = match collision {
        Collision::Bgk => (CollisionKind::Bgk, None),
        Collision::Mrt(rates) => (CollisionKind::Mrt, rates),
    };
    let d = sc.derive()?;
    let mut lbm = sc.build_f64(&d)?;
    lbm.steps(d.steps);
    let [nx, ny] = d.cells;
    let (g, nu, hl) = (d.force_lattice[0], d.nu_lattice, ny as f64);
    let u: Vec<f64> = (0..ny).map(|y| lbm.cell_state(y * nx + 1).1).collect();
    let exact = (0..ny)
        .map(|y| {
            let yc = y as f64 + 0.5;
            g / (2.0 * nu) * yc * (hl - yc)
        })
        .collect();
    let speed = (0..nx * ny).map(|c| {
        let (_, ux, uy) = lbm.cell_state(c);
        ux.hypot(uy)
    });
    let mach = speed.fold(0.0, f64::max) / CS2.sqrt();
    Ok(Profile {
        u,
        exact,
        u_max: g * hl * hl / (8.0 * nu),
        mach,
    })
}

/// Least-squares slope of ln e against ln h (h ∝ 1/cells): the observed order.
pub(super) fn fitted_order(cells: &[usize], errors: &[f64]) -> f64 {
    let xs: Vec<f64> = cells.iter().map(|&n| -(n as f64).ln()).collect();
    let ys: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
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
    let magic_tau = base.time.tau.unwrap_or(0.5 + 3f64.sqrt() / 4.0);
    let cells: &[usize] = match f {
        Fidelity::Test => &[16, 32, 64],
        Fidelity::Full => &[32, 64, 128],
    };
    let mut checks = Vec::new();

    // Magic τ: exact to round-off (docs/validation.md: "at that τ the parabola is reproduced to
    // round-off"; the issue's gate is 1e-10 relative in f64).
    for &n in cells {
        let p = solve(&base, n, magic_tau, Collision::Bgk)?;
        let q = format!("BGK τ = ½ + √3/4, H = {n}: max |u − u_exact|/u_max");
        checks.push(Check::at_most(CASE, &q, p.max_rel_error(), 1e-10));
        if n == cells[0] {
            // Lattice Mach number of the coarsest run (the largest: u* ∝ Δx at fixed τ); the
            // issue asks for a small Mach number, 0.1 keeps compressibility errors ≲ Ma² = 1 %.
            checks.push(Check::at_most(
                CASE,
                &format!("lattice Mach number, H = {n}"),
                p.mach,
                0.1,
            ));
        }
    }

    // τ = 0.8: BGK converges at second order (issue: 2.0 ± 0.2 over three resolutions).
    let mut l2 = Vec::new();
    let mut bgk_mid = None;
    let mut plots = Vec::new();
    for &n in cells {
        let p = solve(&base, n, TAU_OFF_MAGIC, Collision::Bgk)?;
        if n == cells[0] {
            plots.push(profile_plot(&p, n));
        }
        checks.push(Check::report(
            CASE,
            &format!("BGK τ = 0.8, H = {n}: L2 relative error"),
            p.l2_error(),
            0.0,
        ));
        l2.push(p.l2_error());
        if n == cells[1] {
            bgk_mid = Some(p);
        }
    }
    for k in 1..cells.len() {
        let order = (l2[k - 1] / l2[k]).ln() / (cells[k] as f64 / cells[k - 1] as f64).ln();
        let q = format!("BGK τ = 0.8: L2 order, H = {} → {}", cells[k - 1], cells[k]);
        checks.push(Check::abs(CASE, &q, order, 2.0, 0.2));
    }
    checks.push(Check::abs(
        CASE,
        "BGK τ = 0.8: fitted L2 order",
        fitted_order(cells, &l2),
        2.0,
        0.2,
    ));

    // MRT at τ = 0.8 with the magic s_q and s_e = s_ε = s_ν (a TRT): exact to round-off
    // (docs/validation.md, TRT magic Λ = 3/16; the same 1e-10 as the BGK gate).
    let n = cells[1];
    let s_nu = 1.0 / TAU_OFF_MAGIC;
    let trt = MrtSpec {
        s_e: s_nu,
        s_eps: s_nu,
        s_q: crate::lbm::MrtRates::standard(TAU_OFF_MAGIC).s_q,
    };
    let p = solve(&base, n, TAU_OFF_MAGIC, Collision::Mrt(Some(trt)))?;
    let q = format!("MRT τ = 0.8, magic s_q, s_e = s_ε = s_ν, H = {n}: max |u − u_exact|/u_max");
    checks.push(Check::at_most(CASE, &q, p.max_rel_error(), 1e-10));
    // Standard MRT rates: exact up to the O(u·F) energy-moment term (module docs). 1e-7 is
    // ten times the measured 8e-9 and 5000 times below the BGK slip at τ = 0.8 it is compared
    // with next, so "MRT is exact for Poiseuille" holds at the precision that comparison needs.
    let mrt = solve(&base, n, TAU_OFF_MAGIC, Collision::Mrt(None))?;
    let q = format!("MRT τ = 0.8, standard rates, H = {n}: max |u − u_exact|/u_max");
    checks.push(Check::at_most(CASE, &q, mrt.max_rel_error(), 1e-7));

    // BGK − MRT at τ = 0.8: the BGK wall slip δ/u_max = (16Λ − 3)/(3H²) (module docs). The
    // profiles are both exact parabolas, so the difference must match δ up to the MRT error
    // above (≤ 1e-7, i.e. 2e-4 of δ); 1 % of δ is a margin far above that and far below δ.
    if let Some(bgk) = bgk_mid {
        let lambda = (TAU_OFF_MAGIC - 0.5).powi(2);
        let predicted = (3.0 - 16.0 * lambda) / (3.0 * (n * n) as f64);
        let diff = max_abs_diff(&bgk.u, &mrt.u) / mrt.u_max;
        let q = format!("τ = 0.8, H = {n}: max |u_BGK − u_MRT|/u_max vs (3 − 16Λ)/(3H²)");
        checks.push(Check::rel(CASE, &q, diff, predicted, 0.01));
    }
    plots.push(convergence_plot(cells, &l2));
    Ok(Report { checks, plots })
}

/// u(y)/u_max of a BGK τ = 0.8 run (markers) beside the parabola (line).
fn profile_plot(p: &Profile, n: usize) -> Plot {
    let h = p.u.len() as f64;
    let lbm =
        p.u.iter()
            .enumerate()
            .map(|(y, u)| ((y as f64 + 0.5) / h, u / p.u_max))
            .collect();
    let exact = (0..=100)
        .map(|k| {
            let eta = k as f64 / 100.0;
            (eta, 4.0 * eta * (1.0 - eta))
        })
        .collect();
    Plot::new(
        "poiseuille-profile",
        &format!("Poiseuille, BGK τ = 0.8, H = {n} cells"),
        "y / H",
        "u / u_max",
    )
    .with(Series::line("analytic 4(y/H)(1 − y/H)", exact))
    .with(Series::markers("LBM", lbm))
}

/// L2 error against H, log-log, with a slope −2 guide through the coarsest point.
fn convergence_plot(cells: &[usize], l2: &[f64]) -> Plot {
    let pts: Vec<(f64, f64)> = cells
        .iter()
        .map(|&n| n as f64)
        .zip(l2.iter().copied())
        .collect();
    let (h0, e0) = pts[0];
    let guide = pts
        .iter()
        .map(|&(h, _)| (h, e0 * (h0 / h).powi(2)))
        .collect();
    Plot::new(
        "poiseuille-convergence",
        "Poiseuille, BGK τ = 0.8: L2 error vs resolution",
        "H (cells)",
        "‖u − u_exact‖₂ / ‖u_exact‖₂",
    )
    .log(true, true)
    .with(Series::line("slope −2", guide))
    .with(Series::markers("LBM", pts))
}
