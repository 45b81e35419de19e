//! Validation of Ladd's modified bounce-back coupling ([`crate::coupling::ladd`]), on the set-ups of the
//! partially saturated cells ([`crate::scenario::submerged::validation`]) so the two methods compare directly.
//!
//! * `ladd-cylinder-array`: a fixed grain in a periodic cell, Stokes drag against Sangani &
//!   Acrivos (1982) (5 % at d ≥ 20 cells, as for PSM).
//! * `ladd-settling-disk`: a disk settling in a closed channel 4d wide against Faxén's drag
//!   and the PSM terminal velocity.
//! * `ladd-momentum`: fluid + grain momentum in a closed periodic box, with and without the
//!   covering/uncovering impulses.

use crate::coupling::{CellForces, CoupledFluid, Grid, LaddMap, SolidCover};
use crate::dem::scale::GrainView;
use crate::lbm::{Backend, CollisionModel, FluidModel, Lbm, MrtRates, Real};
use crate::report::{Check, Fidelity, Plot, Report, Series};
use crate::scenario::fluid::validation::SANGANI_ACRIVOS;
use crate::scenario::submerged::validation::{
    momentum_box_with, periodic_fluid, settling_disk, settling_disk_with, Settling,
};
use crate::{Error, Result};

/// Steady Stokes flow past a fixed grain under Ladd's bounce-back.
#[derive(Clone, Copy, Debug)]
pub struct LaddDrag {
    /// Nominal solid fraction πr²/l².
    pub phi: f64,
    /// Solid fraction of the node mask, N_inside/l².
    pub phi_nodes: f64,
    /// Grain diameter in cells.
    pub diameter: f64,
    /// F/(μU) = f l²/(μU), U the superficial velocity Σ_outside u / l².
    pub drag: f64,
    /// Force on the grain over the body force on the outside fluid, f N_outside: 1 in a
    /// steady state.
    pub balance: f64,
    /// Steps run.
    pub steps: u64,
}

/// Run a fixed grain (centre of the cell) of nominal solid fraction `phi` to steady state
/// (driven by a body force f, as [`crate::scenario::submerged::validation::array_drag`]), with the force chosen
/// so that the superficial velocity is about `speed` (lattice units).
pub fn ladd_array_drag<T: Real>(
    l: usize,
    phi: f64,
    model: CollisionModel,
    tau: f64,
    speed: f64,
) -> Result<LaddDrag> {
    let nu = (tau - 0.5) / 3.0;
    let f = speed * nu * 50.0 / (l * l) as f64;
    let mut lbm: CoupledFluid<T> = periodic_fluid(l, model, tau, None, [f, 0.0])?;
    let r = l as f64 * (phi / std::f64::consts::PI).sqrt();
    let grid = Grid {
        nx: l,
        ny: l,
        dx: 1.0,
        periodic: [true, true],
    };
    let mut map = LaddMap::new(grid, 1.0)?;
    let grain = GrainView {
        x: vec![0.5 * l as f64],
        y: vec![0.5 * l as f64],
        vx: vec![0.0],
        vy: vec![0.0],
        omega: vec![0.0],
        radius: vec![r],
    };
    let mut cover = SolidCover::default();
    map.cover(&grain, &mut cover);
    lbm.set_links(&cover.links)?;
    let n = l * l;
    let n_inside = cover.links.inside.len();
    let mean_u = |f: &CoupledFluid<T>| {
        (0..n)
            .filter(|&c| !f.ladd.is_inside(c))
            .map(|c| f.lbm().cell(c).1)
            .sum::<f64>()
            / n as f64
    };
    let (every, max_steps) = (500, 400_000);
    let (mut u_last, mut steps) = (0.0, 0);
    let mut force;
    loop {
        let s0 = lbm.ladd.total_force()[0] * lbm.ladd.steps as f64;
        for _ in 0..every {
            lbm.step();
        }
        steps += every;
        force = (lbm.ladd.total_force()[0] * lbm.ladd.steps as f64 - s0) / every as f64;
        let u = mean_u(&lbm);
        if !u.is_finite() {
            return Err(Error::Other(format!(
                "ladd-cylinder-array: unstable at Φ = {phi}"
            )));
        }
        // Steady: as for PSM, U changes by less than 1e-7 over 500 steps (1e-5 in f32).
        let tol = if T::NAME == "f32" { 1e-5 } else { 1e-7 };
        let done = ((u - u_last) / u).abs() < tol;
        u_last = u;
        if done || steps >= max_steps {
            break;
        }
    }
    let mu = nu;
    Ok(LaddDrag {
        phi,
        phi_nodes: n_inside as f64 / n as f64,
        diameter: 2.0 * r,
        drag: f * n as f64 / (mu * u_last),
        balance: force / (f * (n - n_inside) as f64),
        steps,
    })
}

/// `ladd-cylinder-array`: Sangani–Acrivos drag with Ladd's bounce-back.
pub fn cylinder_array(fidelity: Fidelity) -> Result<Report> {
    let case = "ladd-cylinder-array";
    // As psm-cylinder-array: the smallest grain (Φ = 0.05) spans 20.2 cells at l = 80.
    let l = match fidelity {
        Fidelity::Test => 80,
        Fidelity::Full => 160,
    };
    let tau = 1.0;
    let mrt = CollisionModel::Mrt(MrtRates::standard(tau));
    let mut runs: Vec<(&str, CollisionModel, bool, f64, f64)> = Vec::new();
    for (phi, reference) in SANGANI_ACRIVOS {
        runs.push(("BGK f64", CollisionModel::Bgk, false, phi, reference));
        if fidelity == Fidelity::Full || phi == 0.2 {
            runs.push(("MRT f64", mrt, false, phi, reference));
            runs.push(("BGK f32", CollisionModel::Bgk, true, phi, reference));
        }
    }
    let mut checks = Vec::new();
    let mut pts = Vec::new();
    for (name, model, single, phi, reference) in runs {
        // U ≈ 1e-4 (Stokes; Re = U d/ν ≤ 0.07). In f32 U ≈ 1e-3 (Re ≤ 0.24 at l = 80; the
        // f64 drag at Φ = 0.2 changes by 0.007 % from 1e-4 to 1e-3) and l = 80 in both
        // fidelities: the body force per step (∝ U/l²) must stay well above the f32
        // round-off of the populations (≈ 0.1 · 6e-8). Measured at Φ = 0.2: U ≈ 1e-4, l = 80:
        // balance 1.0085 (a plain periodic f32 fluid gains 1.030× the nominal momentum);
        // l = 160: balance 1.17, drag −15 %; U ≈ 1e-3, l = 160: balance 0.981, drag +1.8 %;
        // U ≈ 1e-3, l = 80: balance 0.9978, drag +0.5 %.
        let m = if single {
            ladd_array_drag::<f32>(80, phi, model, tau, 1e-3)?
        } else {
            ladd_array_drag::<f64>(l, phi, model, tau, 1e-4)?
        };
        if name == "BGK f64" {
            pts.push((phi, m.drag));
        }
        // Gate of issue 6 (as for PSM): 5 %.
        checks.push(Check::rel(
            case,
            &format!(
                "F/(μU) at Φ = {phi}, {name}, d = {:.1} cells (L = {})",
                m.diameter,
                if single { 80 } else { l }
            ),
            m.drag,
            reference,
            0.05,
        ));
        // Steady momentum balance: link force = body force on the outside fluid; 0.5 % as
        // for PSM (residual transient at the stopping criterion, f32 round-off).
        checks.push(Check::abs(
            case,
            &format!("grain force / body force at Φ = {phi}, {name}"),
            m.balance,
            1.0,
            0.005,
        ));
        // The node mask's solid fraction differs from the nominal one (a staircase disk);
        // shown, not gated.
        checks.push(Check::report(
            case,
            &format!("N_inside/L² at Φ = {phi}, {name}"),
            m.phi_nodes,
            phi,
        ));
    }
    let plot = Plot::new(
        "ladd-cylinder-array-drag",
        "Periodic cylinder array, Ladd's bounce-back",
        "solid fraction Φ",
        "F / (μU)",
    )
    .log(false, true)
    .with(Series::markers(
        "Sangani & Acrivos 1982",
        SANGANI_ACRIVOS.to_vec(),
    ))
    .with(Series::markers("Ladd, BGK f64", pts));
    Ok(Report {
        checks,
        plots: vec![plot],
    })
}

/// `ladd-settling-disk`: terminal velocity with Ladd's bounce-back against Faxén and PSM.
pub fn settling(fidelity: Fidelity) -> Result<Report> {
    let case = "ladd-settling-disk";
    let sizes: &[usize] = match fidelity {
        Fidelity::Test => &[10, 20],
        Fidelity::Full => &[10, 20, 40],
    };
    let ladd = |d| {
        settling_disk_with::<f64, _>(d, 0.2, CollisionModel::Bgk, Backend::Cpu, |g| {
            LaddMap::new(g, 1.0)
        })
    };
    let runs: Vec<Settling> = sizes.iter().map(|&d| ladd(d)).collect::<Result<_>>()?;
    let psm = settling_disk::<f64>(20, 0.2, CollisionModel::Bgk)?;
    let mut checks = Vec::new();
    for s in &runs {
        checks.push(Check::report(
            case,
            &format!("u_t/u_Faxén at d = {} cells (Re = {:.3})", s.d, s.re),
            s.u_t,
            1.0,
        ));
    }
    let n = runs.len();
    let (a, b) = (&runs[n - 2], &runs[n - 1]);
    if fidelity == Fidelity::Full {
        // Issue 6: the change between d = 20 and d = 40 at most 2 %.
        checks.push(Check::at_most(
            case,
            &format!("|Δu_t|/u_t between d = {} and d = {}", a.d, b.d),
            ((b.u_t - a.u_t) / b.u_t).abs(),
            0.02,
        ));
    } else {
        checks.push(Check::report(
            case,
            &format!("|Δu_t|/u_t between d = {} and d = {}", a.d, b.d),
            ((b.u_t - a.u_t) / b.u_t).abs(),
            0.02,
        ));
    }
    let d20 = runs.iter().find(|s| s.d == 20).expect("d = 20 is run");
    // Faxén's Stokes drag between two walls (Re = 0.2): 2 % at d = 20, as for PSM.
    checks.push(Check::rel(
        case,
        "u_t/u_Faxén at d = 20 cells",
        d20.u_t,
        1.0,
        0.02,
    ));
    // Convergence: the staircase disk of the bounce-back converges at first order (error
    // ratio ½ per doubling; measured 0.49 from d = 10 to 20); gated at 0.6.
    checks.push(Check::at_most(
        case,
        &format!("|u_t/u_F − 1| at d = {} over that at d = {}", b.d, a.d),
        (b.u_t - 1.0).abs() / (a.u_t - 1.0).abs(),
        0.6,
    ));
    // The PSM terminal velocity at the same d (settling-disk), shown: the two methods
    // approach Faxén from opposite sides (Ladd below, PSM above), so their ratio carries
    // both errors.
    checks.push(Check::report(
        case,
        &format!("u_t(Ladd)/u_t(PSM) at d = 20 (PSM: {:.4} u_F)", psm.u_t),
        d20.u_t / psm.u_t,
        1.0,
    ));
    let mut plot = Plot::new(
        "ladd-settling-disk",
        "Disk settling in a channel 4d wide, Ladd's bounce-back (density ratio 2, Re ≈ 0.2)",
        "t ν / d²",
        "v / u_Faxén",
    );
    for s in runs {
        plot = plot.with(Series::line(&format!("Ladd, d = {} cells", s.d), s.history));
    }
    plot = plot
        .with(Series::line("PSM, d = 20 cells", psm.history))
        .with(Series::line("Faxén (Stokes)", vec![(0.0, 1.0), (3.0, 1.0)]));
    Ok(Report {
        checks,
        plots: vec![plot],
    })
}

/// `ladd-momentum`: fluid + grain momentum in a closed periodic box (the `coupling-momentum`
/// set-up) with Ladd's bounce-back.
pub fn momentum(fidelity: Fidelity) -> Result<Report> {
    let case = "ladd-momentum";
    let steps = match fidelity {
        Fidelity::Test => 400,
        Fidelity::Full => 4000,
    };
    let mut checks = Vec::new();
    for (name, model, les) in [
        ("BGK f64", CollisionModel::Bgk, None),
        (
            "MRT+LES f64",
            CollisionModel::Mrt(MrtRates::standard(0.8)),
            Some(0.1),
        ),
    ] {
        let (p0, dev, pf) =
            momentum_box_with::<f64, _>(model, les, steps, Backend::Cpu, |g| LaddMap::new(g, 1.0))?;
        let p = p0[0].hypot(p0[1]);
        // With the covering/uncovering impulses every momentum the fluid loses or gains is
        // the grains': round-off, gated as for PSM at 1e-10.
        checks.push(Check::at_most(
            case,
            &format!("max |Δp|/|p₀| over {steps} steps, {name}, with impulses"),
            dev / p,
            1e-10,
        ));
        checks.push(Check::at_least(
            case,
            &format!("fluid share of the momentum after {steps} steps, {name}"),
            pf[0].hypot(pf[1]) / p,
            0.1,
        ));
    }
    // Seed eq. 5.45–5.49 alone (no impulses): momentum appears and disappears with the nodes
    // the grains cover and uncover. Reported; it must be well above round-off, else the
    // impulses would be idle.
    let (p0, dev, _) =
        momentum_box_with::<f64, _>(CollisionModel::Bgk, None, steps, Backend::Cpu, |g| {
            Ok(LaddMap::new(g, 1.0)?.with_impulses(false))
        })?;
    let rel = dev / p0[0].hypot(p0[1]);
    checks.push(Check::report(
        case,
        &format!("max |Δp|/|p₀| over {steps} steps, BGK f64, without impulses"),
        rel,
        0.0,
    ));
    checks.push(Check::at_least(
        case,
        "drift without impulses (shows they matter)",
        rel,
        1e-6,
    ));
    Ok(Report {
        checks,
        plots: Vec::new(),
    })
}

/// Drag on a disk of diameter `d` cells towed at constant velocity `u` (lattice units) along
/// the axis of a closed channel 4d wide and 16d long (walls all round, BGK f64, τ = 0.8), the
/// grain mapped by `map`: per-step force F_x(t) over the last `window` steps, as (mean,
/// standard deviation). The disk crosses one cell every 1/u steps, so covering/uncovering
/// shows up as a fluctuation at that period.
pub fn towed_disk_force<M>(
    d: usize,
    u: f64,
    window: u64,
    map: impl FnOnce(Grid) -> Result<M>,
) -> Result<(f64, f64)>
where
    M: TowMap,
{
    use crate::lbm::{Edges, Lattice, Obstacles};
    use crate::scale::Scale;
    let (nx, ny) = (16 * d, 4 * d);
    let edges = Edges::closed();
    let lat = Lattice::<f64>::new(nx, ny, edges, vec![false; nx * ny])
        .map_err(|e| Error::Other(format!("lattice: {e}")))?;
    let mut lbm = CoupledFluid::new(Lbm::new(
        lat,
        FluidModel {
            collision: CollisionModel::Bgk,
            smagorinsky: None,
            body_force: [0.0; 2],
        },
        Obstacles::default(),
        crate::units::Units::lattice(0.8),
    ));
    let grid = Grid {
        nx,
        ny,
        dx: 1.0,
        periodic: [false, false],
    };
    let mut m = map(grid)?;
    let mut g = GrainView {
        x: vec![3.0 * d as f64],
        y: vec![0.5 * ny as f64 + 0.237],
        vx: vec![u],
        vy: vec![0.0],
        omega: vec![0.0],
        radius: vec![0.5 * d as f64],
    };
    // Towed over 10d: the last `window` steps are measured.
    let steps = (10.0 * d as f64 / u) as u64;
    let (mut input, mut out) = (SolidCover::default(), CellForces::default());
    let mut loads = crate::dem::ExternalLoads::default();
    let mut f = Vec::with_capacity(window as usize);
    for s in 0..steps {
        m.draw(&g, &mut input);
        lbm.advance(&input, 1.0)?;
        lbm.observe(&mut out);
        m.sum(&out, &mut loads);
        if s + window >= steps {
            f.push(loads.fx[0]);
        }
        g.x[0] += u;
    }
    crate::lbm::Fluid::check_stable(&*lbm.lbm(), 0.3)?;
    let mean = f.iter().sum::<f64>() / f.len() as f64;
    let var = f.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / f.len() as f64;
    Ok((mean, var.sqrt()))
}

/// A map that can tow a grain without a DEM: draw grains, sum forces (one grain).
pub trait TowMap {
    /// Grains → fluid input.
    fn draw(&mut self, g: &GrainView, out: &mut SolidCover);
    /// Fluid output → loads of the grains drawn last.
    fn sum(&self, f: &crate::coupling::CellForces, loads: &mut crate::dem::ExternalLoads);
}

impl TowMap for LaddMap {
    fn draw(&mut self, g: &GrainView, out: &mut SolidCover) {
        self.cover(g, out);
    }
    fn sum(&self, f: &crate::coupling::CellForces, loads: &mut crate::dem::ExternalLoads) {
        self.loads(f, self.grains(), loads);
    }
}

impl TowMap for crate::coupling::DiskCover {
    fn draw(&mut self, g: &GrainView, out: &mut SolidCover) {
        self.cover(g, out);
    }
    fn sum(&self, f: &crate::coupling::CellForces, loads: &mut crate::dem::ExternalLoads) {
        self.loads(f, self.grains(), loads);
    }
}

/// `ladd-force-noise`: drag on a towed disk, mean and fluctuation, Ladd (with and without
/// impulses) against PSM.
pub fn force_noise(fidelity: Fidelity) -> Result<Report> {
    let case = "ladd-force-noise";
    let d = match fidelity {
        Fidelity::Test => 10,
        Fidelity::Full => 20,
    };
    let u = 0.01;
    let window = 1000;
    let psm = towed_disk_force(d, u, window, |g| crate::coupling::DiskCover::new(g, 1.0))?;
    let ladd = towed_disk_force(d, u, window, |g| LaddMap::new(g, 1.0))?;
    let bare = towed_disk_force(d, u, window, |g| {
        Ok(LaddMap::new(g, 1.0)?.with_impulses(false))
    })?;
    let mut checks = Vec::new();
    for (name, (mean, sd)) in [
        ("PSM", psm),
        ("Ladd with impulses", ladd),
        ("Ladd without impulses", bare),
    ] {
        checks.push(Check::report(
            case,
            &format!("{name}: mean drag / PSM mean drag, d = {d}, u = {u}"),
            mean / psm.0,
            1.0,
        ));
        checks.push(Check::report(
            case,
            &format!("{name}: std of the per-step drag / |mean drag|"),
            sd / mean.abs(),
            0.0,
        ));
    }
    // The mean drag of the two methods: they differ at first order in Δx/d through their
    // effective hydrodynamic radius (settling-disk at d = 10: Ladd 0.965, PSM 1.027 of
    // Faxén's velocity, 6 % apart); 10 % at d = 10.
    checks.push(Check::rel(
        case,
        &format!("Ladd mean drag / PSM mean drag, d = {d}"),
        ladd.0 / psm.0,
        1.0,
        0.1,
    ));
    Ok(Report {
        checks,
        plots: Vec::new(),
    })
}
