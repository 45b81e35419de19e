//! The μ(I) test of a DEM material: periodic simple shear ([`crate::dem::shear_cell`]) at a
//! set of inertial numbers, the steady friction and solid fraction of each, and the fit of
//! Jop, Forterre & Pouliquen (2006) to the 2-D Mohr–Coulomb friction,
//!
//! sin φ(I) = sin φ_s + (sin φ_2 − sin φ_s)/(I_0/I + 1),
//!
//! the law a plane-strain continuum of that material takes (`[material] model =
//! "mohr_coulomb"` with a `mu_i` table, [`crate::mpm::material`]). For each I_0 on a
//! logarithmic grid the two others follow by linear least squares; the I_0 of the least
//! residual is kept (`fit_mu_i`).
//!
//! Preparation: the grains are placed on a square lattice (spacing 1.05 d_max, jittered) and
//! compressed isotropically at the rate of I = 0.02 until the mean stress reaches P, with the
//! preparation's contact laws (frictionless: a dense start); then the material's laws are
//! swapped in and the shear starts, with the height on the barostat. The steady state is the
//! mean over the second half of the strain, after the dilatancy transient.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;
use serde::Serialize;

use crate::dem::contact::ContactParams;
use crate::dem::packing::{SizeDistribution, SplitMix64};
use crate::dem::shear_cell::{Cell, ShearPoint};
use crate::dem::{DemParams, TimeStep};
use crate::io::csv::CsvWriter;
use crate::io::json::write_json;
use crate::io::plot::write_svg;
use crate::report::{Plot, Series};
use crate::scenario::dem::spec::DemScenario;
use crate::{Error, Result};

/// Verlet skin as a fraction of the mean diameter.
const SKIN: f64 = 0.3;
/// Records per unit of shear strain.
const RECORDS_PER_STRAIN: f64 = 50.0;
/// Gain β of the barostat ε̇_yy = β γ̇ (σ_yy − P)/P (module doc of `shear_cell`).
const BAROSTAT_GAIN: f64 = 0.3;
/// Inertial number of the isotropic compression of the preparation.
const PREP_INERTIAL_NUMBER: f64 = 0.02;

/// One shear test.
#[derive(Clone, Debug)]
pub struct ShearSpec {
    /// Number of grains.
    pub grains: usize,
    /// Diameters (m) and their distribution.
    pub d_min: f64,
    /// See `d_min`.
    pub d_max: f64,
    /// See `d_min`.
    pub distribution: SizeDistribution,
    /// Grain density ρ_s (kg/m³) and axial length t of the disks (m).
    pub density: f64,
    /// See `density`.
    pub thickness: f64,
    /// The grains' contact laws.
    pub contact: ContactParams,
    /// Contact laws of the preparation's compression (e.g. frictionless for a dense start).
    pub prep_contact: ContactParams,
    /// Normal stress P (Pa).
    pub pressure: f64,
    /// Inertial number of the shear, γ̇ = I √(P/ρ_s)/d̄.
    pub inertial_number: f64,
    /// Shear strain γ at which the test ends; the steady state is the mean over its second
    /// half.
    pub strain: f64,
    /// Random seed of the sizes and the initial lattice's jitter.
    pub seed: u64,
    /// Time step as a fraction of the contact's critical step (e.g. 0.1).
    pub lambda: f64,
}

/// The steady state of one test.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ShearResult {
    /// Grains, mean diameter d̄ (m), shear rate γ̇ (1/s).
    pub grains: usize,
    /// See `grains`.
    pub d_mean: f64,
    /// See `grains`.
    pub shear_rate: f64,
    /// Imposed inertial number and the measured ones, I (from σ_yy) and I_p (from p).
    pub inertial_number_target: f64,
    /// See `inertial_number_target`.
    pub inertial_number: f64,
    /// See `inertial_number_target`.
    pub inertial_number_p: f64,
    /// Means over the second half of the strain.
    pub mean: ShearPoint,
    /// μ = τ/σ_yy and sin φ of the means; standard deviations of the block values about them.
    pub mu: f64,
    /// See `mu`.
    pub mu_sd: f64,
    /// See `mu`.
    pub sin_phi: f64,
    /// See `mu`.
    pub sin_phi_sd: f64,
    /// Slope of the least-squares fit of the mean velocity profile u_x(y), over γ̇ (1 for a
    /// homogeneous shear), and the largest deviation of the binned profile from the line,
    /// over γ̇ L_y.
    pub profile_slope: f64,
    /// See `profile_slope`.
    pub profile_deviation: f64,
    /// Cell width and mean height in the steady state (m).
    pub width: f64,
    /// See `width`.
    pub height: f64,
    /// Time step (s), steps in all, simulated time of the preparation and of the shear (s).
    pub dt: f64,
    /// See `dt`.
    pub steps: u64,
    /// See `dt`.
    pub preparation_time: f64,
    /// See `dt`.
    pub shear_time: f64,
    /// Block means, every 1/50 of strain.
    pub points: Vec<ShearPoint>,
}

impl ShearResult {
    /// One line with the steady state.
    pub fn done_line(&self) -> String {
        format!(
            "I = {:.4} (I_p {:.4}, target {}): μ = {:.4} ± {:.4}, sin φ = {:.4} ± {:.4} \
             (φ = {:.2}°), solid fraction {:.4}, z = {:.2}, σ_xx/σ_yy = {:.3}, profile slope \
             {:.3} (deviation {:.3}), {} steps",
            self.inertial_number,
            self.inertial_number_p,
            self.inertial_number_target,
            self.mu,
            self.mu_sd,
            self.sin_phi,
            self.sin_phi_sd,
            self.sin_phi.asin().to_degrees(),
            self.mean.packing_fraction,
            self.mean.coordination,
            self.mean.sigma_xx / self.mean.sigma_yy,
            self.profile_slope,
            self.profile_deviation,
            self.steps
        )
    }
}

impl ShearSpec {
    /// The test of a collapse scenario's material (its grains and grain–grain contact laws),
    /// `grains` of them at normal stress `pressure` and inertial number `inertial_number`, to
    /// shear strain `strain`, sizes drawn from `seed`; the preparation is frictionless.
    pub fn from_scenario(
        s: &DemScenario,
        grains: usize,
        pressure: f64,
        inertial_number: f64,
        strain: f64,
        seed: Option<u64>,
    ) -> Result<Self> {
        let d = s.derive()?;
        let contact = d.params.grain;
        Ok(ShearSpec {
            grains,
            d_min: s.grains.d_min,
            d_max: s.grains.d_max,
            distribution: d.column.distribution,
            density: s.grains.density,
            thickness: s.grains.thickness,
            contact,
            prep_contact: ContactParams {
                friction: 0.0,
                rolling_friction: 0.0,
                ..contact
            },
            pressure,
            inertial_number,
            strain,
            seed: seed.unwrap_or(d.column.seed),
            lambda: s.time.lambda,
        })
    }

    /// Refuse values that cannot give a test, naming the field.
    pub fn check(&self) -> Result<()> {
        for (field, v) in [
            ("shear.pressure", self.pressure),
            ("shear.inertial_number", self.inertial_number),
            ("shear.strain", self.strain),
            ("shear.density", self.density),
            ("shear.thickness", self.thickness),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(Error::config(field, format!("must be > 0, got {v}")));
            }
        }
        if self.grains < 100 {
            return Err(Error::config(
                "shear.grains",
                format!("need at least 100 grains, got {}", self.grains),
            ));
        }
        if self.inertial_number > 1.0 {
            return Err(Error::config(
                "shear.inertial_number",
                format!(
                    "must be ≤ 1 (beyond it the flow is a dilute gas), got {}",
                    self.inertial_number
                ),
            ));
        }
        if self.strain < 1.0 {
            return Err(Error::config(
                "shear.strain",
                format!(
                    "must be ≥ 1 so the second half is past the transient, got {}",
                    self.strain
                ),
            ));
        }
        self.contact.check("shear.contact")
    }
}

/// Draw the sizes and place the grains on a jittered square lattice (spacing 1.05 d_max):
/// positions, radii and the side of the square cell.
fn lattice(spec: &ShearSpec) -> (Vec<f64>, Vec<f64>, Vec<f64>, f64) {
    let mut rng = SplitMix64::new(spec.seed);
    let n = spec.grains;
    let side = (n as f64).sqrt().ceil() as usize;
    let s = 1.05 * spec.d_max;
    let (mut x, mut y, mut r) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..n {
        let d = spec.distribution.sample(&mut rng, spec.d_min, spec.d_max);
        let jitter = 0.02 * spec.d_max;
        x.push(((k % side) as f64 + 0.5) * s + jitter * (rng.uniform() - 0.5));
        y.push(((k / side) as f64 + 0.5) * s + jitter * (rng.uniform() - 0.5));
        r.push(0.5 * d);
    }
    (x, y, r, side as f64 * s)
}

/// Run one test; `progress` gets (strain records done, records in all).
pub fn run_shear(spec: &ShearSpec, progress: crate::exec::Progress) -> Result<ShearResult> {
    spec.check()?;
    let (x, y, r, side) = lattice(spec);
    let n = r.len();
    let d_mean = 2.0 * r.iter().sum::<f64>() / n as f64;
    let rho = spec.density;
    let m_min = r
        .iter()
        .map(|r| rho * std::f64::consts::PI * r * r * spec.thickness);
    let m_min = m_min.fold(f64::INFINITY, f64::min);
    let mut p = DemParams::new(spec.contact, spec.contact, [0.0; 2]);
    p.lambda = spec.lambda;
    let r_min = r.iter().copied().fold(f64::INFINITY, f64::min);
    let dt = TimeStep::new(&p, m_min, 0.5 * m_min * r_min * r_min)
        .map_err(|e| e.within("shear"))?
        .dt;
    let mut cell = Cell::new(
        x,
        y,
        r,
        rho,
        spec.thickness,
        side,
        side,
        &spec.prep_contact,
        dt,
        SKIN * d_mean,
    );
    let pressure = spec.pressure;
    let rate_of = |i: f64| i * (pressure / rho).sqrt() / d_mean;
    // Preparation: isotropic compression at a fixed rate until the mean stress reaches P.
    let compress = rate_of(PREP_INERTIAL_NUMBER);
    let prep_limit = 10.0 / compress;
    while cell.pressure() < pressure {
        cell.step(-compress, -compress);
        let t = cell.steps as f64 * dt;
        if !cell.finite() || t > prep_limit {
            return Err(Error::Other(format!(
                "shear-cell preparation did not reach P = {pressure} Pa within {t:.3e} s \
                 (packing fraction {:.3})",
                cell.packing_fraction()
            )));
        }
    }
    let preparation_time = cell.steps as f64 * dt;
    cell.set_law(&spec.contact);
    // Shear with the height on the barostat (module doc of `shear_cell`).
    let gdot = rate_of(spec.inertial_number);
    cell.set_shear_rate(gdot);
    let total = (spec.strain * RECORDS_PER_STRAIN).ceil() as u64;
    let steps_per_record = ((1.0 / RECORDS_PER_STRAIN) / (gdot * dt)).ceil().max(1.0) as u64;
    let mut points = Vec::with_capacity(total as usize);
    let bins = PROFILE_BINS;
    let mut profile = vec![[0.0; 2]; bins];
    let shear_start = cell.steps;
    for rec in 0..total {
        let mut mean = ShearPoint::default();
        for _ in 0..steps_per_record {
            let s_yy = -cell.stress().0[(1, 1)];
            let rate = (BAROSTAT_GAIN * gdot * (s_yy - pressure) / pressure).clamp(-gdot, gdot);
            cell.step(0.0, rate);
            mean.add(&cell.point(0.0), 1.0 / steps_per_record as f64);
        }
        let bounded = mean.sigma_yy.abs() < 1e3 * pressure;
        if !cell.finite() || !bounded {
            return Err(Error::Other(format!(
                "shear cell unstable at γ = {:.3} (σ_yy = {:.3e} Pa): lower the time step",
                (cell.steps - shear_start) as f64 * dt * gdot,
                mean.sigma_yy
            )));
        }
        mean.strain = (cell.steps - shear_start) as f64 * dt * gdot;
        if 2 * rec >= total {
            cell.add_profile(&mut profile);
        }
        points.push(mean);
        progress(rec + 1, total);
    }
    let steady: Vec<&ShearPoint> = points.iter().skip(points.len() / 2).collect();
    let w = 1.0 / steady.len() as f64;
    let mut mean = ShearPoint::default();
    steady.iter().for_each(|p| mean.add(p, w));
    mean.strain = points.last().map_or(0.0, |p| p.strain);
    let sd = |f: fn(&ShearPoint) -> f64, m: f64| {
        (steady.iter().map(|p| (f(p) - m).powi(2)).sum::<f64>() * w).sqrt()
    };
    let (mu, sin_phi) = (mean.mu(), mean.sin_phi());
    let (profile_slope, profile_deviation) = profile_fit(&profile, gdot * cell.ly);
    let p2 = 0.5 * (mean.sigma_xx + mean.sigma_yy);
    Ok(ShearResult {
        grains: n,
        d_mean,
        shear_rate: gdot,
        inertial_number_target: spec.inertial_number,
        inertial_number: gdot * d_mean / (mean.sigma_yy / rho).sqrt(),
        inertial_number_p: gdot * d_mean / (p2 / rho).sqrt(),
        mean,
        mu,
        mu_sd: sd(ShearPoint::mu, mu),
        sin_phi,
        sin_phi_sd: sd(ShearPoint::sin_phi, sin_phi),
        profile_slope,
        profile_deviation,
        width: cell.lx,
        // The height that holds the grains at the mean solid fraction.
        height: cell.ly * cell.packing_fraction() / mean.packing_fraction,
        dt,
        steps: cell.steps,
        preparation_time,
        shear_time: (cell.steps - shear_start) as f64 * dt,
        points,
    })
}

/// Bins of the velocity profile.
const PROFILE_BINS: usize = 10;

/// Least-squares slope of the binned profile (Σ u_x and count per bin of y/L_y) over the
/// mean one, and the largest deviation of a bin mean from the line; both in units of
/// `jump` = γ̇ L_y, the velocity jump across the cell.
fn profile_fit(profile: &[[f64; 2]], jump: f64) -> (f64, f64) {
    let pts: Vec<(f64, f64)> = profile
        .iter()
        .enumerate()
        .filter(|(_, b)| b[1] > 0.0)
        .map(|(k, b)| ((k as f64 + 0.5) / profile.len() as f64, b[0] / b[1]))
        .collect();
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let slope = sxy / sxx;
    let dev = pts
        .iter()
        .map(|p| (p.1 - my - slope * (p.0 - mx)).abs())
        .fold(0.0, f64::max);
    (slope / jump, dev / jump)
}

/// The fit sin φ(I) = s_s + (s_2 − s_s)/(I_0/I + 1) (module doc).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MuIFit {
    /// sin φ_s, sin φ_2, I_0.
    pub sin_phi_s: f64,
    /// See `sin_phi_s`.
    pub sin_phi_2: f64,
    /// See `sin_phi_s`.
    pub i_0: f64,
    /// φ_s and φ_2 (degrees).
    pub phi_s_deg: f64,
    /// See `phi_s_deg`.
    pub phi_2_deg: f64,
    /// Root-mean-square residual of sin φ.
    pub rms: f64,
    /// Whether the best I_0 is at an end of the grid (the data do not bound it).
    pub i_0_at_grid_end: bool,
}

impl MuIFit {
    /// sin φ at inertial number `i`.
    pub fn sin_phi(&self, i: f64) -> f64 {
        self.sin_phi_s + (self.sin_phi_2 - self.sin_phi_s) * i / (i + self.i_0)
    }
}

/// I_0 grid of the fit: 241 values, logarithmic over [10⁻³, 10].
const I0_GRID: (f64, f64, usize) = (1e-3, 10.0, 241);

/// Fit the law to (I, sin φ) points (at least 3): for each I_0 of the grid, linear least
/// squares on the basis (1, I/(I + I_0)); the I_0 of the least residual.
pub fn fit_mu_i(points: &[(f64, f64)]) -> Result<MuIFit> {
    if points.len() < 3 {
        return Err(Error::Other(format!(
            "the μ(I) fit needs at least 3 inertial numbers, got {}",
            points.len()
        )));
    }
    let (lo, hi, k) = I0_GRID;
    let mut best: Option<(f64, f64, f64, f64, usize)> = None;
    for g in 0..k {
        let i0 = lo * (hi / lo).powf(g as f64 / (k - 1) as f64);
        // Normal equations of s = a + b q, q = I/(I + I_0).
        let n = points.len() as f64;
        let (mut sq, mut sqq, mut ss, mut sqs) = (0.0, 0.0, 0.0, 0.0);
        for &(i, s) in points {
            let q = i / (i + i0);
            sq += q;
            sqq += q * q;
            ss += s;
            sqs += q * s;
        }
        let det = n * sqq - sq * sq;
        let b = (n * sqs - sq * ss) / det;
        let a = (ss - b * sq) / n;
        let res: f64 = points
            .iter()
            .map(|&(i, s)| (s - a - b * i / (i + i0)).powi(2))
            .sum();
        if best.is_none_or(|x| res < x.0) {
            best = Some((res, a, a + b, i0, g));
        }
    }
    let (res, s_s, s_2, i_0, g) = best.expect("a non-empty grid");
    Ok(MuIFit {
        sin_phi_s: s_s,
        sin_phi_2: s_2,
        i_0,
        phi_s_deg: s_s.asin().to_degrees(),
        phi_2_deg: s_2.clamp(-1.0, 1.0).asin().to_degrees(),
        rms: (res / points.len() as f64).sqrt(),
        i_0_at_grid_end: g == 0 || g == k - 1,
    })
}

/// What `granflow shear` measured: every test and the fit.
#[derive(Clone, Debug, Serialize)]
pub struct MuIResult {
    /// Normal stress P (Pa).
    pub pressure: f64,
    /// The tests, by increasing I.
    pub tests: Vec<ShearResult>,
    /// The fit to (I_p, sin φ), if there were at least 3 tests.
    pub fit: Option<MuIFit>,
}

/// Run the tests (in parallel, one per inertial number) and write, into `out_dir`,
/// `shear_<k>.csv` (the block means of test k), `mu_i.csv` (one row per test), `summary.json`
/// and `mu_i.svg`. Nothing is written if a test fails.
///
/// `progress` gets (‰ done, 1000), called from this thread every 0.2 s: the shear records done
/// by each test, weighted by the test's share of the shear steps, which goes as 1/I (at a
/// fixed strain and time step the shear takes γ/(γ̇ Δt) steps, γ̇ = I √(P/ρ)/d; the
/// preparation, the same for every test, is not counted).
pub fn run_mu_i_to(
    specs: &[ShearSpec],
    out_dir: &Path,
    progress: crate::exec::Progress,
) -> Result<MuIResult> {
    for s in specs {
        s.check()?;
    }
    let share: Vec<f64> = specs.iter().map(|s| 1.0 / s.inertial_number).collect();
    let per_mille = 1e3 / share.iter().sum::<f64>();
    let done: Vec<AtomicU64> = specs.iter().map(|_| AtomicU64::new(0)).collect();
    let mut tests = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            specs
                .par_iter()
                .enumerate()
                .map(|(k, s)| {
                    run_shear(s, &mut |i, n| {
                        let d = per_mille * share[k] * i as f64 / n.max(1) as f64;
                        done[k].store(d as u64, Ordering::Relaxed);
                    })
                })
                .collect::<Result<Vec<_>>>()
        });
        while !worker.is_finished() {
            progress(done.iter().map(|d| d.load(Ordering::Relaxed)).sum(), 1000);
            std::thread::sleep(std::time::Duration::from_millis(200));
        }
        worker.join().expect("a shear test panicked")
    })?;
    progress(1000, 1000);
    tests.sort_by(|a, b| a.inertial_number_p.total_cmp(&b.inertial_number_p));
    let pts: Vec<(f64, f64)> = tests
        .iter()
        .map(|t| (t.inertial_number_p, t.sin_phi))
        .collect();
    let fit = if pts.len() >= 3 {
        Some(fit_mu_i(&pts)?)
    } else {
        None
    };
    let r = MuIResult {
        pressure: specs.first().map_or(f64::NAN, |s| s.pressure),
        tests,
        fit,
    };
    write_outputs(&r, out_dir)?;
    Ok(r)
}

fn write_outputs(r: &MuIResult, out: &Path) -> Result<()> {
    crate::io::run_dir::create(out)?;
    let cols = [
        "strain",
        "sigma_xx",
        "sigma_yy",
        "tau",
        "mu",
        "sin_phi",
        "packing_fraction",
        "coordination",
    ];
    for (k, t) in r.tests.iter().enumerate() {
        let mut csv = CsvWriter::create(&out.join(format!("shear_{k}.csv")), &cols)?;
        for p in &t.points {
            csv.row(&[
                p.strain,
                p.sigma_xx,
                p.sigma_yy,
                p.tau,
                p.mu(),
                p.sin_phi(),
                p.packing_fraction,
                p.coordination,
            ])?;
        }
    }
    let mut csv = CsvWriter::create(
        &out.join("mu_i.csv"),
        &[
            "inertial_number_target",
            "inertial_number",
            "inertial_number_p",
            "mu",
            "mu_sd",
            "sin_phi",
            "sin_phi_sd",
            "packing_fraction",
            "coordination",
            "sigma_xx_over_sigma_yy",
            "profile_slope",
            "profile_deviation",
        ],
    )?;
    for t in &r.tests {
        csv.row(&[
            t.inertial_number_target,
            t.inertial_number,
            t.inertial_number_p,
            t.mu,
            t.mu_sd,
            t.sin_phi,
            t.sin_phi_sd,
            t.mean.packing_fraction,
            t.mean.coordination,
            t.mean.sigma_xx / t.mean.sigma_yy,
            t.profile_slope,
            t.profile_deviation,
        ])?;
    }
    write_json(&out.join("summary.json"), r)?;
    let title = match &r.fit {
        Some(f) => format!(
            "periodic simple shear, P = {:.0} Pa: φ_s = {:.1}°, φ_2 = {:.1}°, I_0 = {:.3}",
            r.pressure, f.phi_s_deg, f.phi_2_deg, f.i_0
        ),
        None => format!("periodic simple shear, P = {:.0} Pa", r.pressure),
    };
    let mut plot = Plot::new(
        "mu_i",
        &title,
        "inertial number I_p",
        "sin φ, μ = τ/σ_yy, solid fraction",
    );
    plot.log_x = true;
    let of = |f: fn(&ShearResult) -> f64| -> Vec<(f64, f64)> {
        r.tests
            .iter()
            .map(|t| (t.inertial_number_p, f(t)))
            .collect()
    };
    plot.series.push(Series::markers(
        "sin φ (Mohr–Coulomb, 2-D)",
        of(|t| t.sin_phi),
    ));
    plot.series
        .push(Series::markers("μ = τ/σ_yy", of(|t| t.mu)));
    plot.series.push(Series::markers(
        "solid fraction",
        of(|t| t.mean.packing_fraction),
    ));
    if let (Some(f), Some(a), Some(b)) = (&r.fit, r.tests.first(), r.tests.last()) {
        let (a, b) = (a.inertial_number_p, b.inertial_number_p);
        let line = (0..=40)
            .map(|k| {
                let i = a * (b / a).powf(k as f64 / 40.0);
                (i, f.sin_phi(i))
            })
            .collect();
        plot.series.push(Series::line("fit sin φ(I)", line));
    }
    write_svg(&plot, &out.join("mu_i.svg"))
}
