//! Validation of the fluid–grain coupling (run by `granflow validate <case>` and the tests).
//!
//! * `psm-cylinder-array`: a fixed grain in a periodic cell as partially saturated cells,
//!   Stokes drag against Sangani & Acrivos (1982), F/(μU) within 5 % for Φ = 0.05–0.4 with
//!   the grain ≥ 20 cells across (issue 6).
//! * `settling-disk`: a disk settling in a closed channel 4d wide: terminal velocity converges
//!   with d (≤ 2 % between the two finest) and matches Faxén's Stokes drag within 2 %.
//! * `dkt`: drafting–kissing–tumbling of two disks (Glowinski set-up): all three occur.
//! * `coupling-momentum`: grains moving through a fluid at rest in a closed periodic box
//!   without gravity: total momentum of fluid + grains is conserved to 1e-10 relative.

use crate::coupling::{Coupled, CoupledFluid, DiskCover, Exchange, Grid, SolidCover};
use crate::dem::{ContactParams, Dem, DemParams, Grains};
use crate::lbm::{
    Backend, CollisionModel, Edges, FluidModel, Lattice, Lbm, MrtRates, Obstacles, Real,
};
use crate::report::{Check, Fidelity, Plot, Report, Series, MAX_PLOT_POINTS};
use crate::scenario::fluid::validation::SANGANI_ACRIVOS;
use crate::units::Units;
use crate::{Error, Result};

/// A periodic `l × l` lattice in lattice units (Δx = Δt = ρ₀ = 1) with a uniform body force.
pub(crate) fn periodic_fluid<T: Real>(
    l: usize,
    model: CollisionModel,
    tau: f64,
    les: Option<f64>,
    force: [f64; 2],
) -> Result<CoupledFluid<T>> {
    let lat = Lattice::<T>::new(l, l, Edges::periodic(), vec![false; l * l])
        .map_err(|e| Error::Other(format!("lattice: {e}")))?;
    Ok(CoupledFluid::new(Lbm::new(
        lat,
        FluidModel {
            collision: model,
            smagorinsky: les,
            body_force: force,
        },
        Obstacles::default(),
        Units::lattice(tau),
    )))
}

/// Steady Stokes flow past a fixed grain of solid fraction Φ in a periodic `l × l` cell.
#[derive(Clone, Copy, Debug)]
pub struct ArrayDrag {
    /// Exact solid fraction Σε/l² (= πr²/l² to round-off).
    pub phi: f64,
    /// Grain diameter in cells.
    pub diameter: f64,
    /// F/(μU) = f l²/(μ U), U the mean velocity over the whole cell (superficial velocity).
    pub drag: f64,
    /// Force on the grain / body force on the fluid Σ(1 − B) f: 1 in a steady state.
    pub balance: f64,
    /// Steps run.
    pub steps: u64,
}

/// Run a fixed grain (centre of the cell) of nominal solid fraction `phi` to steady state.
///
/// The flow is driven by a body force f on the fluid (weighted 1 − B in covered cells, as the
/// fluid part of the PSM collision carries it), which is a mean pressure gradient G = f; by
/// Sangani & Acrivos's convention F = G l² is the force per grain, so F/(μU) = f l²/(μU).
pub fn array_drag<T: Real>(
    l: usize,
    phi: f64,
    model: CollisionModel,
    tau: f64,
    les: Option<f64>,
) -> Result<ArrayDrag> {
    let nu = (tau - 0.5) / 3.0;
    // U ≈ f l²/(μ · F/(μU)): keep U ~ 1e-4 (Stokes, Re = U d/ν ≪ 1).
    let f = 1e-4 * nu * 50.0 / (l * l) as f64;
    let mut lbm = periodic_fluid::<T>(l, model, tau, les, [f, 0.0])?;
    let r = l as f64 * (phi / std::f64::consts::PI).sqrt();
    let grid = Grid {
        nx: l,
        ny: l,
        dx: 1.0,
        periodic: [true, true],
    };
    let mut map = DiskCover::new(grid, 1.0)?;
    let grain = crate::dem::scale::GrainView {
        x: vec![0.5 * l as f64],
        y: vec![0.5 * l as f64],
        vx: vec![0.0],
        vy: vec![0.0],
        omega: vec![0.0],
        radius: vec![r],
    };
    let mut cover = SolidCover::default();
    map.cover(&grain, &mut cover);
    lbm.set_cover(&cover);
    let phi_exact = cover.eps.iter().sum::<f64>() / (l * l) as f64;
    let fluid_weight: f64 = (l * l) as f64 - lbm.partial.b.iter().map(|b| b.f64()).sum::<f64>();
    let n = l * l;
    let mean_u = |f: &CoupledFluid<T>| {
        let l = f.lbm();
        (0..n).map(|c| l.cell(c).1).sum::<f64>() / n as f64
    };
    let (every, max_steps) = (500, 400_000);
    let (mut u_last, mut steps) = (0.0, 0);
    loop {
        for _ in 0..every {
            lbm.step();
        }
        steps += every;
        let u = mean_u(&lbm);
        if !u.is_finite() {
            return Err(Error::Other(format!(
                "psm-cylinder-array: unstable at Φ = {phi}"
            )));
        }
        // Steady: U changes by less than 1e-7 over 500 steps (1e-5 in f32, whose round-off
        // in U is of that order).
        let tol = if T::NAME == "f32" { 1e-5 } else { 1e-7 };
        let done = ((u - u_last) / u).abs() < tol;
        u_last = u;
        if done || steps >= max_steps {
            break;
        }
    }
    let drag_on_grain: f64 = -lbm.exchange.iter().map(|e| e[0]).sum::<f64>();
    let mu = nu; // ρ = 1
    Ok(ArrayDrag {
        phi: phi_exact,
        diameter: 2.0 * r,
        drag: f * n as f64 / (mu * u_last),
        balance: drag_on_grain / (f * fluid_weight),
        steps,
    })
}

/// `psm-cylinder-array`: Sangani–Acrivos drag with partially saturated cells.
pub fn psm_cylinder_array(fidelity: Fidelity) -> Result<Report> {
    let case = "psm-cylinder-array";
    // The smallest grain (Φ = 0.05) spans 2·80·√(0.05/π) = 20.2 cells.
    let l = match fidelity {
        Fidelity::Test => 80,
        Fidelity::Full => 160,
    };
    let tau = 1.0;
    let mrt = CollisionModel::Mrt(MrtRates::standard(tau));
    // Every Φ with f64 BGK; MRT and f32 at every Φ in full, at Φ = 0.2 in the test suite.
    let mut runs: Vec<(&str, CollisionModel, bool, f64, f64)> = Vec::new();
    for (phi, reference) in SANGANI_ACRIVOS {
        runs.push(("BGK f64", CollisionModel::Bgk, false, phi, reference));
        if fidelity == Fidelity::Full || phi == 0.2 {
            runs.push(("MRT f64", mrt, false, phi, reference));
            runs.push(("BGK f32", CollisionModel::Bgk, true, phi, reference));
        }
    }
    let mut checks = Vec::new();
    let (mut bgk, mut mrt_pts, mut f32_pts) = (Vec::new(), Vec::new(), Vec::new());
    for (name, model, single, phi, reference) in runs {
        let m = if single {
            array_drag::<f32>(l, phi, model, tau, None)?
        } else {
            array_drag::<f64>(l, phi, model, tau, None)?
        };
        match (model, single) {
            (_, true) => f32_pts.push((phi, m.drag)),
            (CollisionModel::Bgk, false) => bgk.push((phi, m.drag)),
            _ => mrt_pts.push((phi, m.drag)),
        }
        // Gate of issue 6: 5 %.
        checks.push(Check::rel(
            case,
            &format!("F/(μU) at Φ = {phi}, {name}, d = {:.1} cells", m.diameter),
            m.drag,
            reference,
            0.05,
        ));
        // Steady momentum balance, 0.5 %: exact in a steady state; the margin covers the
        // residual transient at the stopping criterion (and f32 round-off).
        checks.push(Check::abs(
            case,
            &format!("grain force / body force at Φ = {phi}, {name}"),
            m.balance,
            1.0,
            0.005,
        ));
        // The exact overlap gives the nominal Φ to round-off.
        checks.push(Check::abs(
            case,
            &format!("Σε/L² at Φ = {phi}, {name}"),
            m.phi,
            phi,
            1e-12,
        ));
    }
    let plot = Plot::new(
        "psm-cylinder-array-drag",
        "Periodic cylinder array, partially saturated cells",
        "solid fraction Φ",
        "F / (μU)",
    )
    .log(false, true)
    .with(Series::markers(
        "Sangani & Acrivos 1982",
        SANGANI_ACRIVOS.to_vec(),
    ))
    .with(Series::markers("PSM, BGK f64", bgk))
    .with(Series::markers("PSM, MRT f64", mrt_pts))
    .with(Series::markers("PSM, BGK f32", f32_pts));
    Ok(Report {
        checks,
        plots: vec![plot],
    })
}

/// Total momentum (SI per unit depth) of fluid + grains of a coupled system (nodes inside
/// grains under Ladd's bounce-back are not fluid).
pub fn total_momentum<T: Real, M>(c: &Coupled<CoupledFluid<T>, Dem, M>) -> [f64; 2] {
    let u = c.fluid.units();
    let k = u.rho0 * u.dx.powi(3) / u.dt;
    let pf = c.fluid.momentum();
    let pg = c.solid.grains.momentum();
    [pf[0] * k + pg[0], pf[1] * k + pg[1]]
}

/// Grains of density ratio 2 moving (and spinning) through a fluid at rest in a periodic
/// 64 × 64 box without gravity, two of them colliding; `steps` coupled steps.
/// Returns (initial momentum, largest deviation of the total momentum from it, fluid
/// momentum at the end). The fluid steps on `backend`; the grains are mapped onto it by
/// `map(grid)`.
pub fn momentum_box_with<T: Real, M: Exchange<CoupledFluid<T>, Dem>>(
    model: CollisionModel,
    les: Option<f64>,
    steps: u64,
    backend: Backend,
    map: impl FnOnce(Grid) -> Result<M>,
) -> Result<([f64; 2], f64, [f64; 2])> {
    let l = 64;
    let tau = 0.8;
    let fluid = periodic_fluid::<T>(l, model, tau, les, [0.0; 2])?.on(backend)?;
    let mut g = Grains::new();
    // Areal density 2 (fluid 1), lattice units.
    g.push_disk(20.0, 32.0, 6.0, 2.0);
    g.push_disk(40.0, 33.0, 6.0, 2.0);
    g.push_disk(32.0, 12.0, 5.0, 2.0);
    g.vx[0] = 0.02;
    g.vx[1] = -0.01;
    g.vy[2] = 0.015;
    g.omega[2] = 0.004;
    let k_n = 50.0;
    let params = DemParams::new(
        ContactParams::elastic(k_n),
        ContactParams::elastic(k_n),
        [0.0; 2],
    );
    let dem = Dem::new(g, Vec::new(), params)?;
    let grid = Grid {
        nx: l,
        ny: l,
        dx: 1.0,
        periodic: [true, true],
    };
    let mut c = Coupled::new(fluid, dem, map(grid)?);
    let p0 = total_momentum(&c);
    let mut dev: f64 = 0.0;
    for _ in 0..steps {
        c.step()?;
        let p = total_momentum(&c);
        dev = dev.max((p[0] - p0[0]).hypot(p[1] - p0[1]));
    }
    Ok((p0, dev, c.fluid.momentum()))
}

/// `coupling-momentum`: fluid + grain momentum in a closed periodic box to 1e-10 relative.
pub fn momentum(fidelity: Fidelity) -> Result<Report> {
    momentum_on(fidelity, Backend::Cpu)
}

/// [`momentum`] with the fluid on `backend`.
pub fn momentum_on(fidelity: Fidelity, backend: Backend) -> Result<Report> {
    let case = "coupling-momentum";
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
        let (p0, dev, pf) = momentum_box_with::<f64, _>(model, les, steps, backend, |grid| {
            DiskCover::new(grid, 1.0)
        })?;
        let p = p0[0].hypot(p0[1]);
        checks.push(Check::at_most(
            case,
            &format!("max |Δp|/|p₀| over {steps} steps, {name}"),
            dev / p,
            1e-10,
        ));
        // The exchange is not idle: the grains have handed a good part of their momentum to
        // the fluid (Δx = Δt = ρ₀ = 1, so the lattice momentum is the SI one).
        checks.push(Check::at_least(
            case,
            &format!("fluid share of the momentum after {steps} steps, {name}"),
            pf[0].hypot(pf[1]) / p,
            0.1,
        ));
    }
    Ok(Report {
        checks,
        plots: Vec::new(),
    })
}

/// Faxén's drag on a cylinder moving along the mid-plane between two parallel walls
/// (Stokes flow; Happel & Brenner 1965, eq. 7-4.38 as usually quoted):
/// F/(μU) = 4π / (ln(l/a) − 0.9157 + 1.7244 (a/l)² − 1.7302 (a/l)⁴ + 2.4056 (a/l)⁶
/// − 4.5913 (a/l)⁸), with a the radius and l the half-width of the channel.
pub fn faxen_drag(a_over_l: f64) -> f64 {
    let k = a_over_l;
    let k2 = k * k;
    4.0 * std::f64::consts::PI
        / (-(k.ln()) - 0.9157 + 1.7244 * k2 - 1.7302 * k2 * k2 + 2.4056 * k2.powi(3)
            - 4.5913 * k2.powi(4))
}

/// A disk settling in a closed box.
#[derive(Clone, Debug)]
pub struct Settling {
    /// Diameter in cells.
    pub d: usize,
    /// Terminal velocity in units of the Stokes–Faxén velocity u_F (the velocity at which
    /// Faxén's drag balances the submerged weight).
    pub u_t: f64,
    /// Reynolds number u_t d/ν.
    pub re: f64,
    /// (t ν/d², v/u_F) history.
    pub history: Vec<(f64, f64)>,
    /// Coupled steps.
    pub steps: u64,
}

/// One disk of diameter `d` cells and density ratio 2, released at rest on the axis of a
/// closed box 4d wide and 16d tall (walls on all sides), 3d below the top; gravity set so
/// that Faxén's Stokes velocity u_F gives Re_F = u_F d/ν = `re_f`. Runs at τ = 0.8 (diffusive
/// scaling: the same dimensionless problem at every d) until the velocity changes by less
/// than 1e-4 relative over 0.05 d²/ν, or the disk is 3d above the floor.
pub fn settling_disk<T: Real>(d: usize, re_f: f64, model: CollisionModel) -> Result<Settling> {
    settling_disk_with::<T, _>(d, re_f, model, Backend::Cpu, |grid| {
        DiskCover::new(grid, 1.0)
    })
}

/// [`settling_disk`] with the fluid on `backend` and the grain mapped onto it by `map(grid)`.
pub fn settling_disk_with<T: Real, M: Exchange<CoupledFluid<T>, Dem>>(
    d: usize,
    re_f: f64,
    model: CollisionModel,
    backend: Backend,
    map: impl FnOnce(Grid) -> Result<M>,
) -> Result<Settling> {
    let tau = 0.8;
    let nu = (tau - 0.5) / 3.0;
    let (nx, ny) = (4 * d, 16 * d);
    let edges = Edges::closed();
    let lat = Lattice::<T>::new(nx, ny, edges, vec![false; nx * ny])
        .map_err(|e| Error::Other(format!("lattice: {e}")))?;
    let fluid = CoupledFluid::new(Lbm::new(
        lat,
        FluidModel {
            collision: model,
            smagorinsky: None,
            body_force: [0.0; 2],
        },
        Obstacles::default(),
        Units::lattice(tau),
    ))
    .on(backend)?;
    let a = 0.5 * d as f64;
    let (rho_s, rho_f) = (2.0, 1.0);
    let u_f = re_f * nu / d as f64;
    // Submerged weight (ρ_s − ρ_f) π a² g = μ u_F · Faxén drag; the grain carries reduced
    // gravity (1 − ρ_f/ρ_s) g (seed eq. 5.57).
    let drag = faxen_drag(a / (2.0 * d as f64));
    let g = nu * rho_f * u_f * drag / ((rho_s - rho_f) * std::f64::consts::PI * a * a);
    let mut grains = Grains::new();
    grains.push_disk(0.5 * nx as f64, (ny - 3 * d) as f64, a, rho_s);
    let k_n = 1e3;
    let params = DemParams::new(
        ContactParams::elastic(k_n),
        ContactParams::elastic(k_n),
        crate::coupling::reduced_gravity([0.0, -g], rho_f, rho_s),
    );
    let dem = Dem::new(grains, Vec::new(), params)?;
    let grid = Grid {
        nx,
        ny,
        dx: 1.0,
        periodic: [false, false],
    };
    let mut c = Coupled::new(fluid, dem, map(grid)?);
    let t_unit = (d * d) as f64 / nu;
    let window = ((0.05 * t_unit) as u64).max(1);
    let mut history = Vec::new();
    let mut last = 0.0;
    let mut steps = 0;
    loop {
        for _ in 0..window {
            c.step()?;
        }
        steps += window;
        crate::lbm::Fluid::check_stable(&*c.fluid.lbm(), 0.3)?;
        let v = -c.solid.grains.vy[0];
        history.push((steps as f64 / t_unit, v / u_f));
        let settled = ((v - last) / v).abs() < 1e-4;
        last = v;
        if settled || c.solid.grains.y[0] < 3.0 * d as f64 {
            break;
        }
    }
    Ok(Settling {
        d,
        u_t: last / u_f,
        re: last * d as f64 / nu,
        history,
        steps,
    })
}

/// `settling-disk`: terminal velocity of a disk in a closed channel 4d wide, converging with
/// resolution and against Faxén's Stokes drag (Re_F = 0.2).
pub fn settling(fidelity: Fidelity) -> Result<Report> {
    settling_on(fidelity, Backend::Cpu)
}

/// [`settling`] with the fluid on `backend`.
pub fn settling_on(fidelity: Fidelity, backend: Backend) -> Result<Report> {
    let case = "settling-disk";
    let sizes: &[usize] = match fidelity {
        Fidelity::Test => &[10, 20],
        Fidelity::Full => &[10, 20, 40],
    };
    let mut runs = Vec::new();
    for &d in sizes {
        runs.push(settling_disk_with::<f64, _>(
            d,
            0.2,
            CollisionModel::Bgk,
            backend,
            |grid| DiskCover::new(grid, 1.0),
        )?);
    }
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
        // Test fidelity (d = 10, 20; the 2 % gate above needs d = 40): the change is
        // reported, and the error against Faxén must at least halve from d = 10 to d = 20
        // (first-order convergence or better; PSM is second order away from the interface).
        checks.push(Check::report(
            case,
            &format!("|Δu_t|/u_t between d = {} and d = {}", a.d, b.d),
            ((b.u_t - a.u_t) / b.u_t).abs(),
            0.02,
        ));
        checks.push(Check::at_most(
            case,
            &format!("|u_t/u_F − 1| at d = {} over that at d = {}", b.d, a.d),
            (b.u_t - 1.0).abs() / (a.u_t - 1.0).abs(),
            0.5,
        ));
    }
    // Faxén's drag between two walls (Stokes limit; Re = 0.2 here, where the inertial
    // correction is well below 1 %): the finest run within 2 %.
    checks.push(Check::rel(
        case,
        &format!("u_t/u_Faxén at d = {} cells", b.d),
        b.u_t,
        1.0,
        0.02,
    ));
    let mut plot = Plot::new(
        "settling-disk",
        "Disk settling in a channel 4d wide (density ratio 2, Re ≈ 0.2)",
        "t ν / d²",
        "v / u_Faxén",
    );
    for s in runs {
        plot = plot.with(Series::line(&format!("d = {} cells", s.d), s.history));
    }
    plot = plot.with(Series::line("Faxén (Stokes)", vec![(0.0, 1.0), (3.0, 1.0)]));
    Ok(Report {
        checks,
        plots: vec![plot],
    })
}

/// Drafting–kissing–tumbling of two disks (Glowinski et al. 2001 set-up, as in Wang, Guo &
/// Mi 2014): box 2 cm × 8 cm, walls all round; disks d = 0.2 cm, ρ_p = `rho_p` (1010 kg/m³);
/// water (ρ = 1000 kg/m³, ν = 1e-6 m²/s); centres (1.0, 6.8) cm (leading) and (0.999, 7.2) cm
/// (trailing); g = 9.81 m/s². `d_cells` cells per diameter, MRT, τ = `tau`.
#[derive(Clone, Debug)]
pub struct Dkt {
    /// Times (s), x and y (m) of both disks, one row per sample: (t, x₀, y₀, x₁, y₁).
    pub track: Vec<[f64; 5]>,
    /// Smallest surface gap (m) and its time (s).
    pub min_gap: (f64, f64),
    /// First time the trailing disk is below the leading one (s), if it happened.
    pub tumble: Option<f64>,
    /// Lattice spacing (m).
    pub dx: f64,
}

/// Run the DKT set-up until `t_end` seconds (or a disk comes within one diameter of the
/// floor).
pub fn dkt_run(d_cells: usize, rho_p: f64, tau: f64, t_end: f64) -> Result<Dkt> {
    let (w, h, d, nu, rho_f, g) = (0.02, 0.08, 0.002, 1e-6, 1000.0, 9.81);
    let dx = d / d_cells as f64;
    let (nx, ny) = ((w / dx).round() as usize, (h / dx).round() as usize);
    let units = Units::from_tau(dx, tau, nu, rho_f);
    let edges = Edges::closed();
    let lat = Lattice::<f64>::new(nx, ny, edges, vec![false; nx * ny])
        .map_err(|e| Error::Other(format!("lattice: {e}")))?;
    let fluid = CoupledFluid::new(Lbm::new(
        lat,
        FluidModel {
            collision: CollisionModel::Mrt(MrtRates::standard(tau)),
            smagorinsky: None,
            body_force: [0.0; 2],
        },
        Obstacles::default(),
        units,
    ));
    let mut grains = Grains::new();
    // Grain 0 leads (lower), grain 1 trails (upper).
    grains.push_disk(0.01, 0.068, 0.5 * d, rho_p);
    grains.push_disk(0.00999, 0.072, 0.5 * d, rho_p);
    // Stiff enough that the overlap at 1 cm/s is ≈ 0.1 cell; e = 0.5 (the contact stands in
    // for the unresolved lubrication film).
    let mut contact = ContactParams::elastic(1e3);
    contact.restitution = 0.5;
    let params = DemParams::new(
        contact,
        contact,
        crate::coupling::reduced_gravity([0.0, -g], rho_f, rho_p),
    );
    let dem = Dem::new(grains, Vec::new(), params)?;
    let grid = Grid {
        nx,
        ny,
        dx,
        periodic: [false, false],
    };
    let mut c = Coupled::new(fluid, dem, DiskCover::new(grid, 1.0)?);
    let steps = (t_end / units.dt).ceil() as u64;
    let every = ((0.002 / units.dt).round() as u64).max(1);
    let mut out = Dkt {
        track: Vec::new(),
        min_gap: (f64::INFINITY, 0.0),
        tumble: None,
        dx,
    };
    for s in 1..=steps {
        c.step()?;
        let gr = &c.solid.grains;
        let t = s as f64 * units.dt;
        let gap = (gr.x[1] - gr.x[0]).hypot(gr.y[1] - gr.y[0]) - d;
        if gap < out.min_gap.0 {
            out.min_gap = (gap, t);
        }
        if out.tumble.is_none() && gr.y[1] < gr.y[0] {
            out.tumble = Some(t);
        }
        if s % every == 0 {
            crate::lbm::Fluid::check_stable(&*c.fluid.lbm(), 0.3)?;
            out.track.push([t, gr.x[0], gr.y[0], gr.x[1], gr.y[1]]);
        }
        if gr.y[0].min(gr.y[1]) < 1.5 * d {
            break;
        }
    }
    Ok(out)
}

/// `dkt`: drafting, kissing and tumbling all occur; kiss and tumble times reported.
pub fn dkt(fidelity: Fidelity) -> Result<Report> {
    let case = "dkt";
    let (d_cells, t_end) = match fidelity {
        Fidelity::Test => (12, 3.0),
        Fidelity::Full => (24, 6.0),
    };
    let r = dkt_run(d_cells, 1010.0, 0.55, t_end)?;
    let (gap, t_kiss) = r.min_gap;
    // Drafting: before the kiss the trailing disk falls faster than the leader.
    let mut draft: f64 = 0.0;
    for w in r.track.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b[0] > t_kiss {
            break;
        }
        let dt = b[0] - a[0];
        let (v0, v1) = ((a[2] - b[2]) / dt, (a[4] - b[4]) / dt);
        if v0 > 0.0 {
            draft = draft.max(v1 / v0);
        }
    }
    let d = 0.002;
    let scale = (d / 9.81f64).sqrt();
    let mut checks = vec![
        Check::at_least(
            case,
            "drafting: largest v_trailing/v_leading before the kiss",
            draft,
            1.1,
        ),
        // Kissing: the surfaces come closer than one lattice cell.
        Check::at_most(case, "kissing: smallest gap / Δx", gap / r.dx, 1.0),
        // The seed reports the kiss at t/√(D/g) ≈ 25 for its own, loosely described set-up;
        // shown beside ours, not gated.
        Check::report(
            case,
            &format!("kiss time t/√(D/g) (t_kiss = {t_kiss:.3} s)"),
            t_kiss / scale,
            25.0,
        ),
    ];
    match r.tumble {
        Some(t) => checks.push(Check::at_least(
            case,
            &format!(
                "tumbling: order inverts after the kiss, t_tumble − t_kiss (s) \
                 (t_tumble = {t:.3} s)"
            ),
            t - t_kiss,
            0.0,
        )),
        None => checks.push(Check::at_least(
            case,
            &format!("tumbling: order inverts by t_end = {t_end} s (did not: value −1)"),
            -1.0,
            0.0,
        )),
    }
    let pick = |k: usize| -> Vec<(f64, f64)> {
        r.track.iter().map(|row| (row[0], row[k] * 100.0)).collect()
    };
    let plots = vec![
        Plot::new(
            "dkt-y",
            "Drafting, kissing, tumbling: heights",
            "t (s)",
            "y (cm)",
        )
        .with(Series::line("leading disk", pick(2)).decimated(MAX_PLOT_POINTS))
        .with(Series::line("trailing disk", pick(4)).decimated(MAX_PLOT_POINTS)),
        Plot::new(
            "dkt-x",
            "Drafting, kissing, tumbling: lateral positions",
            "t (s)",
            "x (cm)",
        )
        .with(Series::line("leading disk", pick(1)).decimated(MAX_PLOT_POINTS))
        .with(Series::line("trailing disk", pick(3)).decimated(MAX_PLOT_POINTS)),
    ];
    Ok(Report { checks, plots })
}
