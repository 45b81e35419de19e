//! DEM validation cases, each returning one [`Check`] per measured quantity, for
//! `granflow validate` and the tests in `tests/suite/dem.rs`.
//!
//! | case | claim | reference |
//! |---|---|---|
//! | [`restitution`] | head-on grain–grain and grain–wall impacts rebound with the set e, within 1 % for e = 0.3…0.95 at λ = 0.1; the dashpot's booked dissipation equals the kinetic energy lost, within 1.5 % | linear spring-dashpot: e = exp(−πξ/√(1−ξ²)), the contact ending when δ returns to 0 (docs/references.md, linear spring-dashpot); energy conservation |
//! | [`incline`] | frictionless disk on a 45° segment: a/g = sin 45° = 0.7071 within 0.5 %, ω = 0 | Newton's second law |
//! | [`conservation`] | momentum conserved to round-off in grain–grain collisions; elastic gas in a box drifts < 0.1 % in energy over 10⁵ steps | Newton's third law; symplectic (velocity-Verlet) integration |
//! | [`energy_budget`] | settling with friction, damping and rolling resistance: initial = current + dissipated within 1 % | energy conservation |

use crate::dem::contact::ContactParams;
use crate::dem::grains::Grains;
use crate::dem::packing::SplitMix64;
use crate::dem::walls::Wall;
use crate::dem::{Dem, DemParams};
use crate::report::{Check, Fidelity};
use crate::Result;

/// Rebound ratio of a head-on impact between disks (r₁, m₁) and (r₂, m₂) approaching at
/// relative speed 1, or of disk 1 on a floor when `wall`; no gravity, no friction. The
/// contact ends when the overlap returns to zero.
pub fn measure_restitution(e: f64, r: [f64; 2], rho: f64, wall: bool, lambda: f64) -> Result<f64> {
    measure_impact(e, r, rho, wall, lambda).map(|x| x.0)
}

/// [`measure_restitution`] and the energy closure of the impact:
/// (e, |K_after + D_normal − K_before|/D_normal).
pub fn measure_impact(
    e: f64,
    r: [f64; 2],
    rho: f64,
    wall: bool,
    lambda: f64,
) -> Result<(f64, f64)> {
    let k_n = 1.0e5;
    let law = ContactParams {
        restitution: e,
        ..ContactParams::elastic(k_n)
    };
    let mut g = Grains::new();
    let (v_a, v_b);
    let walls = if wall {
        let i = g.push_disk(0.0, r[0] * 1.05, r[0], rho);
        g.vy[i] = -1.0;
        (v_a, v_b) = (1.0, 0.0);
        vec![Wall::floor(0.0)]
    } else {
        let a = g.push_disk(0.0, 0.0, r[0], rho);
        let b = g.push_disk(0.0, r[0] + r[1] + 0.05 * r[0], r[1], rho);
        g.vy[a] = 0.5;
        g.vy[b] = -0.5;
        (v_a, v_b) = (0.5, -0.5);
        Vec::new()
    };
    let mut p = DemParams::new(law, law, [0.0, 0.0]);
    p.lambda = lambda;
    let mut dem = Dem::new(g, walls, p)?;
    let k0 = dem.energy().kinetic_total();
    let mut touched = false;
    for _ in 0..1_000_000 {
        dem.step();
        if dem.contact_count() > 0 {
            touched = true;
        } else if touched {
            let g = &dem.grains;
            let v_out = if wall { g.vy[0] } else { g.vy[1] - g.vy[0] };
            let en = dem.energy();
            let d = en.dissipated_normal;
            let closure = (en.kinetic_total() + d - k0).abs() / d;
            return Ok((v_out / (v_a - v_b), closure));
        }
    }
    Err(crate::Error::Other(
        "restitution case: the impact did not end".into(),
    ))
}

/// `dem-restitution`: e = 0.3, 0.5, 0.75, 0.95 at the default step (λ = 0.1); grain–grain
/// with unequal disks (radii 1 and 0.6 mm, so m_eff ≠ m/2 and the pair's ωΔt is 1.17× the
/// λ-based one) and grain–wall; each within 1 % of the set e (issue 3 gate). The normal
/// dashpot's booked dissipation must equal the kinetic energy lost within 1.5 %: for one
/// impact the discrete-work bookkeeping of [`crate::dem::contact`] is exact except for the
/// start/end force mismatch at the onset and end steps, an O((ξωΔt)²) error whose sign and
/// size depend on where in the step the contact begins and ends (1-D scan over onset
/// phases at λ = 0.1: mean −0.1 %, worst 0.9 % for e = 0.3; measured here 0.85 %). Averaged
/// over many contacts it largely cancels ([`energy_budget`]: 6e-4). A booking that forgot the
/// onset/end trapezoids misses by 3–5 %.
pub fn restitution(_f: Fidelity) -> Result<Vec<Check>> {
    let mut out = Vec::new();
    let mut closure: f64 = 0.0;
    for e in [0.3, 0.5, 0.75, 0.95] {
        let (gg, c1) = measure_impact(e, [1.0e-3, 0.6e-3], 2500.0, false, 0.1)?;
        out.push(Check::rel(
            "dem-restitution",
            &format!("grain-grain e, set {e}"),
            gg,
            e,
            0.01,
        ));
        let (gw, c2) = measure_impact(e, [1.0e-3, 0.0], 2500.0, true, 0.1)?;
        out.push(Check::rel(
            "dem-restitution",
            &format!("grain-wall e, set {e}"),
            gw,
            e,
            0.01,
        ));
        closure = closure.max(c1).max(c2);
    }
    out.push(Check::at_most(
        "dem-restitution",
        "max |K_after + D_normal − K_before| / D_normal",
        closure,
        0.015,
    ));
    Ok(out)
}

/// Acceleration along the slope (in units of g) and largest |ω| of a frictionless disk
/// sliding down a 45° wall segment, released at the equilibrium overlap.
pub fn measure_incline() -> Result<(f64, f64)> {
    let (r, rho, g0, k_n) = (1.0e-3, 2500.0, 9.81, 1.0e5);
    let s = std::f64::consts::FRAC_1_SQRT_2;
    // Segment from (0, 0) down to (1, −1); outward normal (s, s).
    let wall = Wall::Segment {
        a: [0.0, 0.0],
        b: [1.0, -1.0],
    };
    let law = ContactParams {
        k_t: k_n,
        friction: 0.0,
        restitution: 0.5,
        ..ContactParams::elastic(k_n)
    };
    let mut g = Grains::new();
    let m = rho * std::f64::consts::PI * r * r;
    let delta = m * g0 * s / k_n;
    let q = [0.05, -0.05];
    g.push_disk(q[0] + (r - delta) * s, q[1] + (r - delta) * s, r, rho);
    let mut dem = Dem::new(g, vec![wall], DemParams::new(law, law, [0.0, -g0]))?;
    let mut w_max: f64 = 0.0;
    let t_end = 0.1;
    let n = (t_end / dem.dt()).ceil() as u64;
    for _ in 0..n {
        dem.step();
        w_max = w_max.max(dem.grains.omega[0].abs());
    }
    let t = dem.time();
    // Velocity along the slope direction (s, −s).
    let v = (dem.grains.vx[0] - dem.grains.vy[0]) * s;
    Ok((v / t / g0, w_max))
}

/// `dem-incline`: a/g = 0.7071 within 0.5 %, |ω| = 0.
pub fn incline(_f: Fidelity) -> Result<Vec<Check>> {
    let (a, w) = measure_incline()?;
    Ok(vec![
        Check::rel(
            "dem-incline",
            "a/g on a frictionless 45° plane",
            a,
            std::f64::consts::FRAC_1_SQRT_2,
            0.005,
        ),
        Check::at_most("dem-incline", "max |ω| (rad/s)", w, 1e-12),
    ])
}

/// A gas of `n` equal disks (radius `r`, areal density 1) on a square lattice of spacing
/// `4r·spacing_factor/2` inside a box [0, L]² of plane walls, random velocities of unit
/// scale, zero total momentum.
pub fn gas(n_side: usize, r: f64, spacing: f64, seed: u64) -> (Grains, Vec<Wall>, f64) {
    let mut rng = SplitMix64::new(seed);
    let mut g = Grains::with_capacity(n_side * n_side);
    let a = spacing * 2.0 * r;
    for iy in 0..n_side {
        for ix in 0..n_side {
            let k = g.push_disk(a * (ix as f64 + 0.5), a * (iy as f64 + 0.5), r, 1.0);
            g.vx[k] = 2.0 * rng.uniform() - 1.0;
            g.vy[k] = 2.0 * rng.uniform() - 1.0;
            g.omega[k] = (2.0 * rng.uniform() - 1.0) / r;
        }
    }
    let n = g.len() as f64;
    let [px, py] = g.momentum();
    let m = g.mass[0];
    for k in 0..g.len() {
        g.vx[k] -= px / (n * m);
        g.vy[k] -= py / (n * m);
    }
    let l = a * n_side as f64;
    (
        g,
        vec![
            Wall::floor(0.0),
            Wall::left(0.0),
            Wall::right(l),
            Wall::Plane {
                point: [0.0, l],
                normal: [0.0, -1.0],
            },
        ],
        l,
    )
}

/// Largest relative momentum change, |Δ**p**|/Σ m|**v**|, over `steps` steps of a free gas
/// (no walls, no gravity) with damping, friction and rolling resistance on.
pub fn measure_momentum(steps: u64) -> Result<f64> {
    let (g, _, _) = gas(12, 0.5, 1.15, 7);
    let law = ContactParams {
        k_t: 2.0 / 7.0 * 2.0e3,
        restitution: 0.7,
        friction: 0.5,
        rolling_stiffness: 10.0,
        rolling_damping: 0.05,
        rolling_friction: 0.1,
        ..ContactParams::elastic(2.0e3)
    };
    let scale: f64 = (0..g.len())
        .map(|i| g.mass[i] * g.vx[i].hypot(g.vy[i]))
        .sum();
    let p0 = g.momentum();
    let mut dem = Dem::new(g, Vec::new(), DemParams::new(law, law, [0.0, 0.0]))?;
    let mut worst: f64 = 0.0;
    let mut contacts = 0;
    for _ in 0..steps {
        dem.step();
        contacts += dem.contact_count();
        let p = dem.grains.momentum();
        worst = worst.max((p[0] - p0[0]).hypot(p[1] - p0[1]) / scale);
    }
    if contacts == 0 {
        return Err(crate::Error::Other(
            "momentum case: no collisions happened".into(),
        ));
    }
    Ok(worst)
}

/// Largest |E(t) − E(0)|/E(0) over `steps` steps of an elastic, frictionless dense gas
/// (packing fraction ≈ 0.5) in a box with gravity, and the mean number of contacts per step.
pub fn measure_energy_drift(steps: u64, lambda: f64) -> Result<(f64, f64)> {
    let (g, walls, _) = gas(14, 0.5, 1.25, 11);
    let law = ContactParams::elastic(2.0e3);
    let mut p = DemParams::new(law, law, [0.0, -0.1]);
    p.lambda = lambda;
    let mut dem = Dem::new(g, walls, p)?;
    let e0 = dem.energy();
    // Reference: the energy that can move (kinetic + potential above the floor).
    let scale = e0.kinetic_total() + e0.potential + e0.elastic();
    let mut worst: f64 = 0.0;
    let mut contacts = 0usize;
    for k in 0..steps {
        dem.step();
        contacts += dem.contact_count();
        if k % 100 == 99 || k + 1 == steps {
            let e = dem.energy();
            worst = worst.max((e.total() - e0.total()).abs() / scale);
        }
    }
    Ok((worst, contacts as f64 / steps as f64))
}

/// `dem-conservation`: momentum to round-off (1e-12 relative) over 2·10⁴ steps of
/// dissipative collisions; energy drift < 0.1 % over 10⁵ steps of an elastic gas at
/// λ = 0.03 (gated; measured 7.9e-5) and at the default λ = 0.1 (reported: each elastic
/// collision loses ≈ (ωΔt)⁴/40 of its normal energy — a restitution of 1 − 8e-5 for the
/// gas's pairs at λ = 0.1 — and the loss is systematic, so over ≈ 2·10⁵ collisions it sums
/// to ≈ 2.5 %; it falls as Δt⁴ per collision, 4e-4 at λ = 0.05).
pub fn conservation(_f: Fidelity) -> Result<Vec<Check>> {
    let dp = measure_momentum(20_000)?;
    let (de, c) = measure_energy_drift(100_000, 0.03)?;
    let (de1, _) = measure_energy_drift(100_000, 0.1)?;
    Ok(vec![
        Check::at_most(
            "dem-conservation",
            "max |Δp|/Σm|v| (dissipative gas)",
            dp,
            1e-12,
        ),
        Check::at_most(
            "dem-conservation",
            "max |ΔE|/E over 1e5 steps (elastic gas, λ = 0.03)",
            de,
            1e-3,
        ),
        Check::report(
            "dem-conservation",
            "max |ΔE|/E over 1e5 steps (elastic gas, λ = 0.1)",
            de1,
            1e-3,
        ),
        Check::report(
            "dem-conservation",
            "mean contacts per step (elastic gas)",
            c,
            0.0,
        ),
    ])
}

/// Energy budget of a settling run: a loose random cloud of polydisperse disks with friction,
/// damping and rolling resistance falls into a box and comes to rest. Returns
/// (|E_total(end) − E_total(0)|/D(end), D(end)/(E_mech(0) − E_mech,min)), with D the
/// dissipated energy.
pub fn measure_energy_budget(steps: u64, lambda: f64) -> Result<(f64, f64)> {
    measure_energy_budget_with(steps, lambda, [0.5, 0.5, 0.1, 5.0])
}

/// [`measure_energy_budget`] with [e, μ, μ_r, k_r] given.
pub fn measure_energy_budget_with(steps: u64, lambda: f64, c: [f64; 4]) -> Result<(f64, f64)> {
    let (g, walls, _) = gas(12, 0.5, 1.3, 5);
    let mut rng = SplitMix64::new(3);
    let mut g2 = Grains::with_capacity(g.len());
    for k in 0..g.len() {
        let r = 0.4 + 0.1 * rng.uniform();
        let i = g2.push_disk(g.x[k], g.y[k] + 2.0, r, 1.0);
        g2.vx[i] = g.vx[k];
        g2.vy[i] = g.vy[k];
    }
    let mut walls = walls;
    walls.pop(); // no lid
    let law = ContactParams {
        k_t: 2.0 / 7.0 * 2.0e3,
        restitution: c[0],
        friction: c[1],
        rolling_stiffness: c[3],
        rolling_damping: 0.02 * c[3] / 5.0,
        rolling_friction: c[2],
        ..ContactParams::elastic(2.0e3)
    };
    let mut p = DemParams::new(law, law, [0.0, -1.0]);
    p.lambda = lambda;
    let mut dem = Dem::new(g2, walls, p)?;
    let e0 = dem.energy();
    dem.steps(steps);
    let e = dem.energy();
    let d = e.dissipated();
    Ok(((e.total() - e0.total()).abs() / d, e.kinetic_total() / d))
}

/// `dem-energy`: the budget closes within 1 % of the dissipated energy in a settling run at
/// λ = 0.1 (issue 3 gate; measured 5.7e-4, second order in Δt: 1.7e-4 at λ = 0.05, 4.0e-5
/// at 0.025). The residual is the integrator's own error (see [`crate::dem::contact`]), since
/// each dissipation channel is booked as the discrete work of its force.
pub fn energy_budget(_f: Fidelity) -> Result<Vec<Check>> {
    let (err, k) = measure_energy_budget(40_000, 0.1)?;
    Ok(vec![
        Check::at_most(
            "dem-energy",
            "|E_total(end) − E_total(0)| / dissipated",
            err,
            0.01,
        ),
        Check::report("dem-energy", "kinetic energy left / dissipated", k, 0.0),
    ])
}
