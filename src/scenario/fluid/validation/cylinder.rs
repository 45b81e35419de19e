//! Flow past cylinders: Schäfer–Turek 2D-1 (steady drag, pressure drop, recirculation),
//! the Sangani–Acrivos periodic array (Stokes drag), and the seed's vortex-shedding case
//! (onset of shedding, Strouhal number).
//!
//! Forces come from momentum exchange on the cylinder (`Lbm::obstacles.force`), averaged over
//! an even and an odd AA step, and are converted to SI per unit depth with
//! [`Units::force_to_si`](crate::units::Units::force_to_si).

use crate::analysis::spectrum::dominant_frequency;
use crate::lbm::{Backend, Fluid, Lbm};
use crate::report::{Check, Fidelity, Plot, Report, Series, MAX_PLOT_POINTS};
use crate::scenario::fluid::{Derived, EdgeSpec, ObstacleSpec, Scenario};
use crate::scenario::ScenarioFile;
use crate::{Error, Result};

const TOML_2D1: &str = include_str!("../../../../models/lbm/cylinder_2d1.toml");
const TOML_ARRAY: &str = include_str!("../../../../models/lbm/cylinder_array.toml");
const TOML_RE55: &str = include_str!("../../../../models/lbm/shedding_re55.toml");
const TOML_RE112: &str = include_str!("../../../../models/lbm/shedding_re112.toml");

// ---------------------------------------------------------------------------------------------
// Shared helpers
// ---------------------------------------------------------------------------------------------

/// A cylinder in a channel with a parabolic velocity inlet, in SI units.
#[derive(Clone, Copy, Debug)]
struct Channel {
    /// Cylinder diameter D.
    d: f64,
    /// Cylinder centre.
    center: [f64; 2],
    /// Centre-line inflow velocity U_m.
    u_max: f64,
    /// Mean inflow velocity Ū = 2U_m/3 (parabola).
    u_mean: f64,
    /// Fluid density ρ.
    rho: f64,
}

impl Channel {
    fn of(scn: &Scenario) -> Result<Self> {
        let (center, radius) = circle(scn)?;
        let u_max = match &scn.boundaries.left {
            EdgeSpec::Velocity { velocity, .. } => velocity[0],
            _ => {
                return Err(Error::Other(format!(
                    "{}: the left edge must be a velocity inlet",
                    scn.name
                )))
            }
        };
        Ok(Channel {
            d: 2.0 * radius,
            center,
            u_max,
            u_mean: 2.0 * u_max / 3.0,
            rho: scn.fluid.density,
        })
    }

    /// Force coefficient 2F/(ρŪ²D) of a force per unit depth F (N/m).
    fn coefficient(&self, f: f64) -> f64 {
        2.0 * f / (self.rho * self.u_mean * self.u_mean * self.d)
    }
}

/// Centre and radius of the scenario's first obstacle, which must be a circle.
fn circle(scn: &Scenario) -> Result<([f64; 2], f64)> {
    match scn.obstacles.first() {
        Some(ObstacleSpec::Circle { center, radius, .. }) => Ok((*center, *radius)),
        _ => Err(Error::Other(format!(
            "{}: the first obstacle must be a circle",
            scn.name
        ))),
    }
}

/// Refine the lattice by `factor` at constant lattice velocity (acoustic scaling): Δx and Δt
/// shrink by `factor`, so ν* and τ − ½ grow by it.
fn refine(scn: &mut Scenario, factor: f64) {
    scn.domain.dx /= factor;
    match (scn.time.tau, scn.time.dt) {
        (Some(tau), _) => scn.time.tau = Some(0.5 + factor * (tau - 0.5)),
        (None, Some(dt)) => scn.time.dt = Some(dt / factor),
        (None, None) => {}
    }
}

/// Advance `n` steps (n ≥ 2) and return the obstacle force (lattice units) averaged over the
/// last two steps, one even and one odd, which removes the AA pattern's step-parity wobble.
fn advance(lbm: &mut dyn Fluid, n: u64) -> [f64; 2] {
    lbm.steps(n.saturating_sub(1));
    let a = lbm.obstacle_loads().0[0];
    lbm.steps(1);
    let b = lbm.obstacle_loads().0[0];
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}

/// Stop with [`Error::Unstable`] if the run blew up.
fn stable(lbm: &dyn Fluid) -> Result<()> {
    lbm.check_stable(0.5)
}

/// A channel flow on either back end, with the solid map its profiles skip.
struct ChannelFlow {
    fluid: Box<dyn Fluid>,
    solid: Vec<bool>,
    cells: [usize; 2],
}

impl ChannelFlow {
    /// The scenario's fluid in f64, started by `start` on the host, then moved onto the
    /// scenario's back end.
    fn build(scn: &Scenario, d: &Derived, start: impl FnOnce(&mut Lbm<f64>)) -> Result<Self> {
        let mut lbm = scn.build_typed::<f64>(d)?;
        start(&mut lbm);
        let solid = lbm.lattice.solid().to_vec();
        Ok(ChannelFlow {
            fluid: scn.on_backend(lbm)?,
            solid,
            cells: d.cells,
        })
    }

    /// (x, ρ, u_x) of each cell column on the horizontal line at height `y` (SI), linearly
    /// interpolated between the two bracketing rows; `None` where either cell is solid.
    fn axial_profile(&self, y: f64) -> Vec<Option<(f64, f64, f64)>> {
        let ([nx, ny], dx) = (self.cells, self.fluid.units().dx);
        let s = (y / dx - 0.5).clamp(0.0, (ny - 1) as f64);
        let j0 = (s.floor() as usize).min(ny - 2);
        let t = s - j0 as f64;
        (0..nx)
            .map(|i| {
                let (c0, c1) = (j0 * nx + i, (j0 + 1) * nx + i);
                if self.solid[c0] || self.solid[c1] {
                    return None;
                }
                let (r0, u0, _) = self.fluid.cell_state(c0);
                let (r1, u1, _) = self.fluid.cell_state(c1);
                Some((
                    (i as f64 + 0.5) * dx,
                    (1.0 - t) * r0 + t * r1,
                    (1.0 - t) * u0 + t * u1,
                ))
            })
            .collect()
    }
}

/// Lattice density at `x` on an axial profile: linear between the bracketing columns when both
/// are fluid (bilinear overall), otherwise extrapolated linearly from the two nearest fluid
/// columns on the side `side` (−1: smaller x, +1: larger x), as at a body's surface.
fn density_at(profile: &[Option<(f64, f64, f64)>], dx: f64, x: f64, side: i64) -> Option<f64> {
    let s = x / dx - 0.5;
    let i0 = s.floor() as i64;
    let get = |i: i64| {
        usize::try_from(i)
            .ok()
            .and_then(|i| profile.get(i).copied().flatten())
    };
    if let (Some(a), Some(b)) = (get(i0), get(i0 + 1)) {
        let t = s - i0 as f64;
        return Some((1.0 - t) * a.1 + t * b.1);
    }
    let start = if side < 0 { i0 } else { i0 + 1 };
    let first = (0..4)
        .map(|k| start + side * k)
        .find(|&i| get(i).is_some())?;
    let (a, b) = (get(first)?, get(first + side)?);
    Some(a.1 + (x - a.0) * (b.1 - a.1) / (b.0 - a.0))
}

// ---------------------------------------------------------------------------------------------
// Schäfer–Turek 2D-1
// ---------------------------------------------------------------------------------------------

/// Schäfer & Turek (1996) reference values, DFG benchmark 2D-1 (spectral values where given,
/// else the centre of the published interval).
mod st {
    /// Drag coefficient (interval 5.57–5.59; spectral 5.5795).
    pub const CD: f64 = 5.5795;
    /// Lift coefficient (interval 0.0104–0.0110; spectral 0.010619).
    pub const CL: f64 = 0.010619;
    /// Pressure difference p(0.15, 0.2) − p(0.25, 0.2) in Pa (0.1172–0.1176; spectral 0.11752).
    pub const DP: f64 = 0.11752;
    /// Recirculation length in m (interval 0.0842–0.0852).
    pub const LA: f64 = 0.0847;
}

/// 2D-1 quantities, instantaneous or averaged over a window.
#[derive(Clone, Copy, Debug, Default)]
struct Sample2d1 {
    cd: f64,
    cl: f64,
    /// Δp in Pa.
    dp: f64,
    /// L_a in m (NaN without backflow).
    la: f64,
}

impl Sample2d1 {
    fn add(self, o: Sample2d1, w: f64) -> Self {
        Sample2d1 {
            cd: self.cd + w * o.cd,
            cl: self.cl + w * o.cl,
            dp: self.dp + w * o.dp,
            la: self.la + w * o.la,
        }
    }
}

/// Schäfer–Turek 2D-1: c_D within 1 % of 5.58 and Δp within 2 % at D ≥ 40 cells (Test: 40,
/// Full: 80); L_a and c_L reported.
pub fn run_2d1(fidelity: Fidelity) -> Result<Report> {
    run_2d1_on(fidelity, Backend::Cpu)
}

/// Schäfer–Turek 2D-1 on `backend`.
pub fn run_2d1_on(fidelity: Fidelity, backend: Backend) -> Result<Report> {
    let mut scn = Scenario::from_toml(TOML_2D1)?;
    scn.lbm.backend = backend;
    if fidelity == Fidelity::Full {
        refine(&mut scn, 2.0);
    }
    let ch = Channel::of(&scn)?;
    let d = scn.derive()?;
    let mut flow = ChannelFlow::build(&scn, &d, |lbm| start_as_channel_flow(lbm, &d, ch.u_max))?;
    let (m, drift, history) = run_to_steady(&mut flow, &d, &ch)?;
    let case = "cylinder-2d1";
    let cells = ch.d / d.units.dx;
    let plots = plots_2d1(&flow, &d, &ch, history, cells);
    let checks = vec![
        // Gate of the issue: 1 % at D ≥ 40 cells (the published interval is ±0.2 %).
        Check::rel(case, "drag coefficient c_D", m.cd, st::CD, 0.01),
        // Gate of the issue: 2 % at D ≥ 40 cells (published interval ±0.2 %).
        Check::rel(case, "pressure difference Δp (Pa)", m.dp, st::DP, 0.02),
        Check::report(case, "recirculation length L_a (m)", m.la, st::LA),
        // LBM codes converge slowly in c_L (docs/validation.md): reported only.
        Check::report(case, "lift coefficient c_L", m.cl, st::CL),
        // The gates hold "at D ≥ 40 cells".
        Check::at_least(case, "cylinder diameter in cells", cells, 40.0),
        // Steady state reached: the window-mean c_D changed by less than the stopping criterion
        // (a run that hit `time.end` first fails here).
        Check::at_most(
            case,
            "relative change of window-mean c_D",
            drift,
            STEADY_TOL,
        ),
    ];
    Ok(Report { checks, plots })
}

/// c_D against time beside the reference, and u_x on the centre line behind the cylinder with
/// the reference end of the recirculation zone.
fn plots_2d1(
    flow: &ChannelFlow,
    d: &Derived,
    ch: &Channel,
    history: Vec<(f64, f64)>,
    cells: f64,
) -> Vec<Plot> {
    let t_end = history.last().map_or(0.0, |p| p.0);
    let means: Vec<(f64, f64)> = history
        .chunks(WINDOW_SAMPLES as usize)
        .map(|w| {
            let n = w.len() as f64;
            w.iter()
                .fold((0.0, 0.0), |(t, c), p| (t + p.0 / n, c + p.1 / n))
        })
        .collect();
    let drag = Plot::new(
        "cylinder-2d1-drag",
        &format!("Schäfer–Turek 2D-1, D = {cells:.0} cells: drag coefficient"),
        "t (s)",
        "c_D",
    )
    // The start's sound waves swing c_D far beyond this; the range shows the approach.
    .y_range(0.85 * st::CD, 1.15 * st::CD)
    .with(Series::line("LBM, samples", history).decimated(MAX_PLOT_POINTS))
    .with(Series::line(
        "Schäfer & Turek 1996 (5.5795)",
        vec![(0.0, st::CD), (t_end, st::CD)],
    ))
    .with(Series::markers("LBM, mean over one acoustic period", means));
    let rear = ch.center[0] + 0.5 * ch.d;
    let wake: Vec<(f64, f64)> = flow
        .axial_profile(ch.center[1])
        .into_iter()
        .flatten()
        .filter(|p| p.0 > rear)
        .map(|p| (p.0 - rear, d.units.velocity_to_si(p.2)))
        .collect();
    let wake_plot = Plot::new(
        "cylinder-2d1-wake",
        "Schäfer–Turek 2D-1: u_x on y = 0.2 m behind the cylinder",
        "x − x_rear (m)",
        "u_x (m/s)",
    )
    .with(Series::line("LBM", wake).decimated(MAX_PLOT_POINTS))
    .with(Series::markers(
        "recirculation end L_a = 0.0847 m (Schäfer & Turek)",
        vec![(st::LA, 0.0)],
    ));
    vec![drag, wake_plot]
}

/// Relative change of the window-mean c_D between two windows below which the 2D-1 flow
/// counts as steady: 20× below the 1 % gate.
const STEADY_TOL: f64 = 5e-4;

/// (t in s, c_D) of every sample of a 2D-1 run.
type History = Vec<(f64, f64)>;

/// Samples per averaging window.
const WINDOW_SAMPLES: u64 = 32;

/// Initialise the channel as plane Poiseuille flow with its linear pressure drop, the fastest
/// way to the steady state (the inflow parabola everywhere, zero inside the cylinder).
fn start_as_channel_flow(lbm: &mut Lbm<f64>, d: &Derived, u_max_si: f64) {
    let [nx, ny] = d.cells;
    let um = d.units.velocity_to_lattice(u_max_si);
    // dp/dx = −8μU_m/H² (lattice, ρ = 1): ρ(x) = 1 + 3·8ν*U_m (x_out − x)/H².
    let grad = 8.0 * d.nu_lattice * um / (ny * ny) as f64;
    lbm.lattice.fill(|x, y| {
        let t = (y as f64 + 0.5) / ny as f64;
        (
            1.0 + 3.0 * grad * ((nx - 1 - x) as f64),
            4.0 * um * t * (1.0 - t),
            0.0,
        )
    });
}

/// Step in windows of one acoustic period of the channel, T = 4L/c_s (a quarter-wave between
/// the reflecting velocity inlet and the pressure outlet), averaging [`WINDOW_SAMPLES`] evenly
/// spaced samples, which cancels the sound waves the start leaves behind; stop when the
/// window-mean c_D changes by less than [`STEADY_TOL`] or at `time.end`. Returns the last
/// window's means, the relative change and the history (t in s, c_D) of every sample.
fn run_to_steady(
    flow: &mut ChannelFlow,
    d: &Derived,
    ch: &Channel,
) -> Result<(Sample2d1, f64, History)> {
    let period = 4.0 * d.cells[0] as f64 / crate::units::CS2.sqrt();
    let every = ((period / WINDOW_SAMPLES as f64).round() as u64).max(2);
    let (mut steps, mut last, mut drift) = (0, Sample2d1::default(), f64::INFINITY);
    let mut history = Vec::new();
    while steps < d.steps {
        let mut mean = Sample2d1::default();
        for k in 1..=WINDOW_SAMPLES {
            let f = advance(flow.fluid.as_mut(), every);
            let sample = sample_2d1(flow, d, ch, f)?;
            history.push(((steps + k * every) as f64 * d.units.dt, sample.cd));
            mean = mean.add(sample, 1.0 / WINDOW_SAMPLES as f64);
        }
        steps += every * WINDOW_SAMPLES;
        stable(flow.fluid.as_ref())?;
        drift = ((mean.cd - last.cd) / mean.cd).abs();
        last = mean;
        if drift < STEADY_TOL {
            break;
        }
    }
    Ok((last, drift, history))
}

/// c_D, c_L from the force `f` (lattice), Δp and L_a from the current fields.
fn sample_2d1(flow: &ChannelFlow, d: &Derived, ch: &Channel, f: [f64; 2]) -> Result<Sample2d1> {
    let profile = flow.axial_profile(ch.center[1]);
    let (front, rear) = (ch.center[0] - 0.5 * ch.d, ch.center[0] + 0.5 * ch.d);
    let p = |x: f64, side: i64| -> Result<f64> {
        density_at(&profile, d.units.dx, x, side)
            .map(|r| d.units.pressure_to_si(r))
            .ok_or_else(|| Error::Other(format!("cylinder-2d1: no fluid cells near x = {x} m")))
    };
    Ok(Sample2d1 {
        cd: ch.coefficient(d.units.force_to_si(f[0])),
        cl: ch.coefficient(d.units.force_to_si(f[1])),
        dp: p(front, -1)? - p(rear, 1)?,
        la: recirculation_end(&profile, rear).map_or(f64::NAN, |x| x - rear),
    })
}

/// First x behind `rear` where u_x on the profile turns from negative back to positive
/// (linear interpolation between the two columns), or `None` if there is no backflow.
fn recirculation_end(profile: &[Option<(f64, f64, f64)>], rear: f64) -> Option<f64> {
    let fluid: Vec<(f64, f64)> = profile
        .iter()
        .flatten()
        .filter(|p| p.0 > rear)
        .map(|p| (p.0, p.2))
        .collect();
    if fluid.first()?.1 >= 0.0 {
        return None;
    }
    fluid
        .windows(2)
        .find(|w| w[0].1 < 0.0 && w[1].1 >= 0.0)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            a.0 - a.1 * (b.0 - a.0) / (b.1 - a.1)
        })
}

// ---------------------------------------------------------------------------------------------
// Sangani–Acrivos periodic array
// ---------------------------------------------------------------------------------------------

/// Sangani & Acrivos (1982), square array, dimensionless drag F/(μU) per solid fraction Φ.
pub(crate) const SANGANI_ACRIVOS: [(f64, f64); 4] =
    [(0.05, 15.56), (0.1, 24.83), (0.2, 51.53), (0.4, 217.89)];

/// Steady drag of one array cell.
#[derive(Clone, Copy, Debug)]
struct ArrayDrag {
    /// Discretised solid fraction Φ_d (solid cells / all cells).
    phi: f64,
    /// F/(μU) with F = F_measured/(1 − Φ_d) and U the superficial velocity.
    drag: f64,
    /// F_measured / (body force on the fluid): 1 in a steady state that conserves momentum.
    balance: f64,
}

/// Sangani–Acrivos periodic square array: F/(μU) within 3 % for Φ = 0.05, 0.1, 0.2, 0.4.
pub fn run_array(fidelity: Fidelity) -> Result<Report> {
    run_array_on(fidelity, Backend::Cpu)
}

/// The periodic cylinder array on `backend`.
pub fn run_array_on(fidelity: Fidelity, backend: Backend) -> Result<Report> {
    let mut base = Scenario::from_toml(TOML_ARRAY)?;
    base.lbm.backend = backend;
    if fidelity == Fidelity::Full {
        refine(&mut base, 2.0);
    }
    let case = "cylinder-array";
    let mut checks = Vec::new();
    let (mut interpolated, mut halfway) = (Vec::new(), Vec::new());
    for (phi, reference) in SANGANI_ACRIVOS {
        let m = array_drag(&base, phi, true)?;
        interpolated.push((phi, m.drag));
        // Gate of the issue: 3 % (docs/validation.md: a stair-stepped cylinder lands within 2–4 %;
        // the interpolated wall sits on the true circle and should do better).
        checks.push(Check::rel(
            case,
            &format!("F/(μU) at Φ = {phi}, interpolated wall"),
            m.drag,
            reference,
            0.03,
        ));
        checks.push(Check::report(
            case,
            &format!("discretised Φ for Φ = {phi}"),
            m.phi,
            phi,
        ));
        // Steady momentum balance: drag = body force on the fluid, to 1 % (exact in a steady
        // state that conserves momentum; the margin covers the residual transient).
        checks.push(Check::abs(
            case,
            &format!("drag / body force at Φ = {phi}"),
            m.balance,
            1.0,
            0.01,
        ));
        let stairs = array_drag(&base, phi, false)?;
        halfway.push((phi, stairs.drag));
        checks.push(Check::report(
            case,
            &format!("F/(μU) at Φ = {phi}, half-way bounce-back"),
            stairs.drag,
            reference,
        ));
    }
    let plot = Plot::new(
        "cylinder-array-drag",
        "Periodic square array of cylinders: Stokes drag",
        "solid fraction Φ",
        "F / (μU)",
    )
    .log(false, true)
    .with(Series::markers(
        "Sangani & Acrivos 1982",
        SANGANI_ACRIVOS.to_vec(),
    ))
    .with(Series::markers("LBM, interpolated wall", interpolated))
    .with(Series::markers("LBM, half-way bounce-back", halfway));
    Ok(Report {
        checks,
        plots: vec![plot],
    })
}

/// Run one array cell of nominal solid fraction `phi` to steady state, with interpolated or
/// half-way bounce-back on the cylinder.
fn array_drag(base: &Scenario, phi: f64, interpolate: bool) -> Result<ArrayDrag> {
    let mut scn = base.clone();
    let side = scn.domain.size[0];
    if let Some(ObstacleSpec::Circle {
        radius,
        interpolated,
        ..
    }) = scn.obstacles.first_mut()
    {
        *radius = side * (phi / std::f64::consts::PI).sqrt();
        *interpolated = interpolate;
    }
    let d = scn.derive()?;
    let lbm = scn.build_typed::<f64>(&d)?;
    let n = lbm.lattice.len();
    let fluid: Vec<usize> = (0..n).filter(|&c| !lbm.lattice.is_solid(c)).collect();
    let mut lbm = scn.on_backend(lbm)?;
    let superficial =
        |lbm: &dyn Fluid| fluid.iter().map(|&c| lbm.cell_state(c).1).sum::<f64>() / n as f64;
    let every = 500;
    let mut u_last = 0.0;
    let mut steps = 0;
    let mut force = [0.0; 2];
    while steps < d.steps {
        force = advance(lbm.as_mut(), every);
        steps += every;
        stable(lbm.as_ref())?;
        let u = superficial(lbm.as_ref());
        let done = ((u - u_last) / u).abs() < 1e-6;
        u_last = u;
        if done {
            break;
        }
    }
    let f = d.force_lattice[0];
    let phi_d = 1.0 - fluid.len() as f64 / n as f64;
    let mu = d.nu_lattice; // ρ* = 1
    Ok(ArrayDrag {
        phi: phi_d,
        drag: force[0] / (1.0 - phi_d) / (mu * u_last),
        balance: force[0] / (f * fluid.len() as f64),
    })
}

// ---------------------------------------------------------------------------------------------
// Vortex shedding (seed section 5.3, Table 5.2)
// ---------------------------------------------------------------------------------------------

/// Seed Table 5.2: Strouhal number f D/U_max at Re 112 (LBM and FVM of Breuer et al. 2000).
const SEED_ST_112: f64 = 0.141;
/// Seed Table 5.2: Strouhal number at Re 55.
const SEED_ST_55: f64 = 0.117;

/// Lift history of a shedding run.
#[derive(Clone, Debug)]
struct LiftSeries {
    /// Sample interval in s.
    dt: f64,
    /// c_L samples.
    cl: Vec<f64>,
}

impl LiftSeries {
    /// Half the peak-to-peak c_L over the samples in the fraction [a, b) of the run.
    fn amplitude(&self, a: f64, b: f64) -> f64 {
        let n = self.cl.len() as f64;
        let s = &self.cl[(a * n) as usize..(b * n) as usize];
        let (lo, hi) = s
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        0.5 * (hi - lo)
    }

    /// Dominant frequency (Hz) of the second half of the record.
    fn frequency(&self) -> Option<f64> {
        dominant_frequency(&self.cl[self.cl.len() / 2..], self.dt)
    }
}

/// Run a shedding scenario, perturbed at the start, and record c_L.
fn lift_history(scn: &Scenario) -> Result<(Channel, LiftSeries)> {
    let ch = Channel::of(scn)?;
    let d = scn.derive()?;
    let mut lbm = scn.build_typed::<f64>(&d)?;
    start_perturbed(&mut lbm, &d, &ch);
    let mut lbm = scn.on_backend(lbm)?;
    let every = d.series_every.max(2);
    let mut cl = Vec::new();
    for k in 0..d.steps / every {
        let f = advance(lbm.as_mut(), every);
        cl.push(ch.coefficient(d.units.force_to_si(f[1])));
        if k % 64 == 0 {
            stable(lbm.as_ref())?;
        }
    }
    stable(lbm.as_ref())?;
    Ok((
        ch,
        LiftSeries {
            dt: every as f64 * d.units.dt,
            cl,
        },
    ))
}

/// Start from the inflow parabola with a small antisymmetric kick: a transverse velocity of
/// 5 % of U_m in a Gaussian blob one diameter behind the cylinder. Without it the symmetric
/// lattice would only leave the symmetric (unstable) state through round-off.
fn start_perturbed(lbm: &mut Lbm<f64>, d: &Derived, ch: &Channel) {
    let ny = d.cells[1];
    let dx = d.units.dx;
    let um = d.units.velocity_to_lattice(ch.u_max);
    let (cx, cy) = (ch.center[0] + ch.d, ch.center[1]);
    lbm.lattice.fill(|x, y| {
        let t = (y as f64 + 0.5) / ny as f64;
        let (px, py) = ((x as f64 + 0.5) * dx - cx, (y as f64 + 0.5) * dx - cy);
        let blob = (-(px * px + py * py) / (ch.d * ch.d)).exp();
        (1.0, 4.0 * um * t * (1.0 - t), 0.05 * um * blob)
    });
}

/// Seed section 5.3: no sustained shedding at Re 55, shedding at Re 112; St reported beside
/// Table 5.2.
pub fn run_shedding(fidelity: Fidelity) -> Result<Report> {
    run_shedding_on(fidelity, Backend::Cpu)
}

/// The shedding case on `backend`.
pub fn run_shedding_on(fidelity: Fidelity, backend: Backend) -> Result<Report> {
    let mut lo = Scenario::from_toml(TOML_RE55)?;
    let mut hi = Scenario::from_toml(TOML_RE112)?;
    lo.lbm.backend = backend;
    hi.lbm.backend = backend;
    if fidelity == Fidelity::Full {
        refine(&mut lo, 2.0);
        refine(&mut hi, 2.0);
    }
    let case = "shedding";
    let (ch_lo, calm) = lift_history(&lo)?;
    let (ch_hi, shed) = lift_history(&hi)?;
    let (a_calm, a_shed) = (calm.amplitude(0.75, 1.0), shed.amplitude(0.75, 1.0));
    let st =
        |s: &LiftSeries, ch: &Channel, u: f64| s.frequency().map_or(f64::NAN, |f| f * ch.d / u);
    let history = |s: &LiftSeries| -> Vec<(f64, f64)> {
        (s.cl.iter().enumerate())
            .map(|(k, &c)| ((k + 1) as f64 * s.dt, c))
            .collect()
    };
    let plot = Plot::new(
        "shedding-lift",
        "Cylinder in a channel: lift coefficient",
        "t (s)",
        "c_L",
    )
    .with(Series::line("Re 112", history(&shed)).decimated(MAX_PLOT_POINTS))
    .with(Series::line("Re 55", history(&calm)).decimated(MAX_PLOT_POINTS));
    let checks = vec![
        // Shedding at Re 112 (seed Fig. 5.12c): a clear oscillation, c_L amplitude ≥ 0.1 over the
        // last quarter (confined cylinders near Re 100 shed with c_L amplitudes of 0.3–1) ...
        Check::at_least(case, "c_L amplitude at Re 112, last quarter", a_shed, 0.1),
        // ... that is sustained: the last quarter keeps ≥ 90 % of the third quarter's amplitude.
        Check::at_least(
            case,
            "c_L amplitude ratio at Re 112, 4th/3rd quarter",
            a_shed / shed.amplitude(0.5, 0.75),
            0.9,
        ),
        // No vortex street at Re 55 (seed Fig. 5.12a). This set-up is marginally unstable there
        // (a weak oscillation grows slowly; the seed, too, reports a St at Re 55), so the gate is
        // that the Re 55 wake stays weak: below a fifth of the Re 112 amplitude at equal times.
        Check::at_most(
            case,
            "c_L amplitude ratio Re 55 / Re 112, last quarter",
            a_calm / a_shed,
            0.2,
        ),
        Check::report(
            case,
            "c_L amplitude growth at Re 55, 4th/3rd quarter",
            a_calm / calm.amplitude(0.5, 0.75),
            1.0,
        ),
        // Seed eq. 5.44 defines St = f D/U_max (centre-line inflow velocity); Table 5.2.
        Check::report(
            case,
            "Strouhal number f D/U_max at Re 112",
            st(&shed, &ch_hi, ch_hi.u_max),
            SEED_ST_112,
        ),
        Check::report(
            case,
            "Strouhal number f D/U_max at Re 55",
            st(&calm, &ch_lo, ch_lo.u_max),
            SEED_ST_55,
        ),
        // The Re 112 frequency with the mean inflow velocity Ū (the velocity of the seed's Re).
        Check::report(
            case,
            "Strouhal number f D/Ū at Re 112",
            st(&shed, &ch_hi, ch_hi.u_mean),
            SEED_ST_112,
        ),
    ];
    Ok(Report {
        checks,
        plots: vec![plot],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recirculation_end_interpolates_the_sign_change() {
        let p = vec![
            None,
            Some((1.0, 1.0, -0.2)),
            Some((2.0, 1.0, -0.1)),
            Some((3.0, 1.0, 0.1)),
        ];
        assert!((recirculation_end(&p, 0.5).unwrap() - 2.5).abs() < 1e-12);
        let q = vec![Some((1.0, 1.0, 0.2)), Some((2.0, 1.0, 0.1))];
        assert_eq!(recirculation_end(&q, 0.5), None);
    }

    #[test]
    fn density_is_interpolated_or_extrapolated_from_fluid() {
        // Columns at x = 0.5, 1.5, 2.5, 3.5 (dx = 1); column 2 solid; ρ = 1 + x.
        let p: Vec<_> = [0.5, 1.5, 2.5, 3.5]
            .iter()
            .enumerate()
            .map(|(i, &x)| (i != 2).then_some((x, 1.0 + x, 0.0)))
            .collect();
        assert!((density_at(&p, 1.0, 1.0, -1).unwrap() - 2.0).abs() < 1e-12);
        assert!((density_at(&p, 1.0, 2.0, -1).unwrap() - 3.0).abs() < 1e-12);
    }

    #[test]
    fn every_model_parses_and_derives() {
        for t in [TOML_2D1, TOML_ARRAY, TOML_RE55, TOML_RE112] {
            Scenario::from_toml(t).unwrap().derive().unwrap();
        }
    }
}
