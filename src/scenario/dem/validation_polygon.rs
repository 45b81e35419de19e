//! Validation of the rapier2d-backed detection and of polygon grains (`granflow validate
//! dem-polygon`), one [`Check`] per measured quantity; `tests/suite/dem_rapier.rs` runs the same
//! measurements.
//!
//! | quantity | claim | reference |
//! |---|---|---|
//! | [`measure_detector_agreement`] | rapier's collision pipeline and the cell list find the same disk contacts (grain–grain and grain–wall) with the same δ and **n**: abs(Δδ)/R ≤ 1e-12, abs(Δ**n**) ≤ 1e-12 | same f64 geometry (issue 3) |
//! | [`measure_resting_square`] | a square at rest on the floor: Σf_n = m g (1e-9), no rotation (1e-12) | statics; symmetry |
//! | [`measure_square_incline`] | square on a rough incline: sticks below atan μ (creep < 1e-6 m in 0.6 s); above, a/g = sin θ − μ cos θ within 0.5 % | block on a rough incline (Newton, Coulomb) |
//! | [`measure_flat_impact`] | a square falling flat on the floor (two contact points) rebounds with the set e within 1 %, e = 0.3, 0.5, 0.9 | linear spring-dashpot, as `dem-restitution` |
//! | [`measure_polygon_collision`] | off-centre square–triangle collision with friction: momentum (1e-13) and angular momentum Σ(**x** × m**v** + Jω) (1e-12) to round-off | Newton's third law |
//! | [`measure_disk_wedge`] | frictionless disk on a polygon wall of slope 30°: a/g = sin θ within 0.5 % | Newton |
//! | [`measure_pile_budget`] | settling mixed pile (polygons, disks, polygon wall): initial = current + dissipated within 1 % of the dissipated | energy conservation |

use crate::dem::contact::ContactParams;
use crate::dem::detect_rapier::{cell_list_contacts, Contact, Coverage, RapierDetector};
use crate::dem::grains::Grains;
use crate::dem::packing::SplitMix64;
use crate::dem::shape::Polygons;
use crate::dem::walls::Wall;
use crate::dem::{Dem, DemParams};
use crate::report::{Check, Fidelity};
use crate::Result;

const CASE: &str = "dem-polygon";
const G: f64 = 9.81;

/// Walls of the detector cross-check: floor, box sides, a slanted segment and a slanted plane
/// x + y ≤ 34 cutting the upper right corner of the 20 × 20 box.
pub fn test_walls() -> Vec<Wall> {
    let s = 0.5f64.sqrt();
    vec![
        Wall::floor(0.0),
        Wall::left(0.0),
        Wall::right(20.0),
        Wall::Segment {
            a: [3.0, 14.0],
            b: [16.5, 11.0],
        },
        Wall::Plane {
            point: [17.0, 17.0],
            normal: [-s, -s],
        },
    ]
}

/// Random polydisperse disks (R uniform in [0.3, 0.7], areal density 1) in the box of
/// [`test_walls`], overlapping: a centre may come as close as half the radius sum to another
/// centre and half the radius to a wall (closer, the normal (**q** − **c**)/abs(**q** − **c**) is
/// ill-conditioned, round-off ε abs(**c**)/abs(**q** − **c**), in both detectors); random angles.
pub fn random_packing(seed: u64, n: usize) -> Grains {
    let walls = test_walls();
    let mut rng = SplitMix64::new(seed);
    let mut g = Grains::with_capacity(n);
    let mut tries = 0;
    while g.len() < n && tries < 100 * n {
        tries += 1;
        let r = 0.3 + 0.4 * rng.uniform();
        let (x, y) = (0.1 + 19.8 * rng.uniform(), 0.1 + 19.8 * rng.uniform());
        if walls.iter().any(|w| w.distance([x, y]).0 < 0.5 * r) {
            continue;
        }
        let ok = (0..g.len()).all(|k| {
            let (dx, dy) = (g.x[k] - x, g.y[k] - y);
            (dx * dx + dy * dy).sqrt() > 0.5 * (g.radius[k] + r)
        });
        if ok {
            let i = g.push_disk(x, y, r, 1.0);
            g.angle[i] = 6.0 * rng.uniform();
        }
    }
    g
}

/// Agreement of the two detectors on one random packing: (worst abs(Δδ)/(R_i + R_j) (R_i for a
/// wall), worst abs(Δ**n**), grain–grain contacts, grain–wall contacts, walls touched). Every
/// contact (δ > 0) of either list must be in the other, or this is an error.
pub fn measure_detector_agreement(seed: u64, n: usize) -> Result<(f64, f64, usize, usize, usize)> {
    let walls = test_walls();
    let g = random_packing(seed, n);
    let skin = 0.2;
    let cl = cell_list_contacts(&g, &walls, skin, skin);
    let mut det = RapierDetector::new(Coverage::All, skin);
    let mut rp: Vec<Contact> = Vec::new();
    det.detect(&g, &walls, &mut rp);
    let find = |l: &[Contact], c: &Contact| l.iter().find(|d| (d.i, d.j) == (c.i, c.j)).copied();
    let (mut n_gg, mut n_gw, mut worst_d, mut worst_n) = (0, 0, 0.0f64, 0.0f64);
    for (a, b, name) in [(&cl, &rp, "rapier"), (&rp, &cl, "the cell list")] {
        for c in a.iter().filter(|c| c.delta > 0.0) {
            let d = find(b, c).ok_or_else(|| {
                crate::Error::Other(format!("seed {seed}: {name} misses contact {c:?}"))
            })?;
            let i = c.i as usize;
            let scale = g.radius[i] + c.wall().map_or_else(|| g.radius[c.j as usize], |_| 0.0);
            worst_d = worst_d.max((c.delta - d.delta).abs() / scale);
            worst_n = worst_n.max(
                ((c.normal[0] - d.normal[0]).powi(2) + (c.normal[1] - d.normal[1]).powi(2)).sqrt(),
            );
            if c.wall().is_some() {
                n_gw += 1;
            } else {
                n_gg += 1;
            }
        }
    }
    let touched = (0..walls.len())
        .filter(|&w| cl.iter().any(|c| c.delta > 0.0 && c.wall() == Some(w)))
        .count();
    // Each contact was counted once from each side.
    Ok((worst_d, worst_n, n_gg / 2, n_gw / 2, touched))
}

/// Contact law with friction μ, restitution e, k_t = 2/7 k_n.
pub fn frictional(k_n: f64, mu: f64, e: f64) -> ContactParams {
    ContactParams {
        k_t: 2.0 / 7.0 * k_n,
        friction: mu,
        restitution: e,
        ..ContactParams::elastic(k_n)
    }
}

/// A unit square (areal density 1: m = 1, J = 1/6) with its centre at (0, `y0`) on the floor
/// y = 0, gravity `grav`, law `c` for grain–grain and grain–wall.
pub fn square_on_floor(c: ContactParams, grav: [f64; 2], y0: f64) -> Result<Dem> {
    let mut g = Grains::new();
    let s = g
        .polygons
        .add(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], "square")?;
    g.push_polygon(0.0, y0, 0.0, s, 1.0);
    Dem::new(g, vec![Wall::floor(0.0)], DemParams::new(c, c, grav))
}

/// Square dropped flat from 5 % of its side onto the floor (k_n = 1e5, e = 0.3, μ = 0.5),
/// after 1 s: (Σf_n/(m g) − 1, y − (½ − δ) with δ = mg/(2k_n) per corner, max abs(ω),
/// abs(angle), contact points).
pub fn measure_resting_square() -> Result<(f64, f64, f64, f64, usize)> {
    let k_n = 1e5;
    let mut dem = square_on_floor(frictional(k_n, 0.5, 0.3), [0.0, -G], 0.55)?;
    let mut max_w = 0.0f64;
    for _ in 0..(1.0 / dem.dt()) as u64 {
        dem.step();
        max_w = max_w.max(dem.grains.omega[0].abs());
    }
    let f_n = dem
        .shape_contacts()
        .map_or(0.0, |s| s.wall_normal_force(0, 0));
    let delta = G / (2.0 * k_n);
    Ok((
        f_n / G - 1.0,
        dem.grains.y[0] - (0.5 - delta),
        max_w,
        dem.grains.angle[0].abs(),
        dem.contact_count(),
    ))
}

/// Unit square on a rough floor (μ, k_n = 1e5, e = 0.3) with gravity tilted by `theta_deg`,
/// starting at its static overlap: (a/g measured from the velocity along the slope between
/// 0.3 s and 0.9 s, the velocity at 0.9 s, the displacement between 0.3 s and 0.9 s).
pub fn measure_square_incline(theta_deg: f64, mu: f64) -> Result<(f64, f64, f64)> {
    let k_n = 1e5;
    let th = theta_deg.to_radians();
    let grav = [G * th.sin(), -G * th.cos()];
    let delta = G * th.cos() / (2.0 * k_n);
    let mut dem = square_on_floor(frictional(k_n, mu, 0.3), grav, 0.5 - delta)?;
    let dt = dem.dt();
    dem.steps((0.3 / dt) as u64);
    let (v1, t1, x1) = (dem.grains.vx[0], dem.time(), dem.grains.x[0]);
    dem.steps((0.6 / dt) as u64);
    let (v2, t2, x2) = (dem.grains.vx[0], dem.time(), dem.grains.x[0]);
    Ok(((v2 - v1) / (t2 - t1) / G, v2, x2 - x1))
}

/// A unit square falling flat onto the floor at 1 m/s (k_n = 1e5, restitution `e`, no
/// gravity, no friction): the rebound speed. Its two corner points share the mass (m/2 each),
/// so the pair behaves as one spring-dashpot 2k_n on m with the set damping ratio.
pub fn measure_flat_impact(e: f64) -> Result<f64> {
    let c = ContactParams {
        restitution: e,
        ..ContactParams::elastic(1e5)
    };
    let mut dem = square_on_floor(c, [0.0, 0.0], 0.52)?;
    dem.grains.vy[0] = -1.0;
    let mut touched = false;
    for _ in 0..1_000_000 {
        dem.step();
        if dem.contact_count() > 0 {
            touched = true;
        } else if touched {
            return Ok(dem.grains.vy[0]);
        }
    }
    Err(crate::Error::Other("flat impact did not end".into()))
}

/// Off-centre collision of a unit square (density 1) and a rotated triangle (density 2.5)
/// with friction (μ = 0.4, e = 0.6), no gravity, 3 s: (worst abs(Δ**p**)/p₀, worst
/// abs(ΔL)/(p₀·1 m) with L = Σ(**x** × m**v** + Jω), steps in contact, contacts at the end,
/// final ω of the square). p₀ = Σ m abs(**v**) at the start.
pub fn measure_polygon_collision() -> Result<(f64, f64, usize, usize, f64)> {
    let mut g = Grains::new();
    let sq = g
        .polygons
        .add(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], "square")?;
    let tri = g
        .polygons
        .add(&[[0.0, 0.0], [1.2, 0.1], [0.3, 0.9]], "triangle")?;
    let a = g.push_polygon(0.0, 0.0, 0.0, sq, 1.0);
    let b = g.push_polygon(2.0, 0.35, 0.7, tri, 2.5);
    g.vx[a] = 1.0;
    g.vx[b] = -0.5;
    g.vy[b] = 0.1;
    g.omega[b] = 0.3;
    let scale = g.mass[a] * 1.0 + g.mass[b] * (0.5f64.powi(2) + 0.1f64.powi(2)).sqrt();
    let c = frictional(1e4, 0.4, 0.6);
    let mut dem = Dem::new(g, vec![], DemParams::new(c, c, [0.0, 0.0]))?;
    let mom = |d: &Dem| {
        let g = &d.grains;
        let p = g.momentum();
        let l: f64 = (0..g.len())
            .map(|i| g.mass[i] * (g.x[i] * g.vy[i] - g.y[i] * g.vx[i]) + g.inertia[i] * g.omega[i])
            .sum();
        [p[0], p[1], l]
    };
    let m0 = mom(&dem);
    let (mut touched, mut worst_p, mut worst_l) = (0, 0.0f64, 0.0f64);
    for _ in 0..(3.0 / dem.dt()) as u64 {
        dem.step();
        touched += usize::from(dem.contact_count() > 0);
        let m = mom(&dem);
        worst_p = worst_p.max((m[0] - m0[0]).abs().max((m[1] - m0[1]).abs()) / scale);
        worst_l = worst_l.max((m[2] - m0[2]).abs() / scale);
    }
    Ok((
        worst_p,
        worst_l,
        touched,
        dem.contact_count(),
        dem.grains.omega[a],
    ))
}

/// Frictionless disk (R = 0.5, density 1) sliding down a polygon wall (a wedge of slope 30°),
/// k_n = 1e5, e = 0.3: (a/g from the velocity along the slope between 0.2 s and 0.7 s, abs(ω)
/// at the end, contacts at the end).
pub fn measure_disk_wedge() -> Result<(f64, f64, usize)> {
    let th = 30f64.to_radians();
    let (l, r, k_n) = (20.0, 0.5, 1e5);
    let wedge = Wall::polygon(
        &[[0.0, -1.0], [l, -1.0], [l, 0.0], [0.0, l * th.tan()]],
        "wedge",
    )?;
    let mut g = Grains::new();
    let (nx, ny) = (th.sin(), th.cos());
    let (x0, m) = (2.0, std::f64::consts::PI * r * r);
    let y0 = (l - x0) * th.tan();
    // Start at the static overlap m g cos θ/k_n.
    let s = r - m * G * ny / k_n;
    g.push_disk(x0 + s * nx, y0 + s * ny, r, 1.0);
    let c = ContactParams {
        restitution: 0.3,
        ..ContactParams::elastic(k_n)
    };
    let mut dem = Dem::new(g, vec![wedge], DemParams::new(c, c, [0.0, -G]))?;
    let along = |d: &Dem| d.grains.vx[0] * th.cos() - d.grains.vy[0] * th.sin();
    dem.steps((0.2 / dem.dt()) as u64);
    let (v1, t1) = (along(&dem), dem.time());
    dem.steps((0.5 / dem.dt()) as u64);
    let (v2, t2) = (along(&dem), dem.time());
    Ok((
        (v2 - v1) / (t2 - t1) / G,
        dem.grains.omega[0].abs(),
        dem.contact_count(),
    ))
}

/// Settling of a mixed pile in a 6-wide box with a triangular polygon wall on the floor: 30
/// grains (squares, triangles, pentagons, disks; random angles and spins), k_n = 2e4, e = 0.5,
/// μ = 0.5, rolling resistance for disks, `time` simulated seconds at Δt = λΔt_cr. Returns
/// (abs(E_tot(end) − E_tot(0))/D, K_end/D, whether a grain touched the polygon wall, history
/// handovers between feature pairs, touching points lost without a successor).
pub fn measure_pile_budget(time: f64, lambda: f64) -> Result<(f64, f64, bool, u64, u64)> {
    let mut g = Grains::new();
    let sq = g
        .polygons
        .add(&Polygons::regular(4, 0.35 * 2f64.sqrt(), 0.0), "square")?;
    let tri = g
        .polygons
        .add(&Polygons::regular(3, 0.5, 0.0), "triangle")?;
    let pent = g
        .polygons
        .add(&Polygons::regular(5, 0.45, 0.0), "pentagon")?;
    let mut rng = SplitMix64::new(11);
    for r in 0..6 {
        for c in 0..5 {
            let (x, y) = (0.7 + 1.15 * c as f64, 1.6 + 1.15 * r as f64);
            let th = 6.0 * rng.uniform();
            let i = match (r * 5 + c) % 4 {
                0 => g.push_polygon(x, y, th, sq, 1.0),
                1 => g.push_polygon(x, y, th, tri, 1.0),
                2 => g.push_polygon(x, y, th, pent, 1.0),
                _ => g.push_disk(x, y, 0.35 + 0.1 * rng.uniform(), 1.0),
            };
            g.vx[i] = rng.uniform() - 0.5;
            g.omega[i] = 2.0 * (rng.uniform() - 0.5);
        }
    }
    let walls = vec![
        Wall::floor(0.0),
        Wall::left(0.0),
        Wall::right(6.0),
        Wall::polygon(&[[2.0, -0.1], [4.0, -0.1], [3.0, 0.8]], "bump")?,
    ];
    let c = ContactParams {
        rolling_stiffness: 50.0,
        rolling_damping: 0.5,
        rolling_friction: 0.1,
        ..frictional(2e4, 0.5, 0.5)
    };
    let mut p = DemParams::new(c, c, [0.0, -G]);
    p.lambda = lambda;
    let mut dem = Dem::new(g, walls, p)?;
    let e0 = dem.energy();
    let mut poly_wall = false;
    for _ in 0..(time / dem.dt()) as u64 {
        dem.step();
        poly_wall |= dem.shape_contacts().is_some_and(|sc| {
            sc.found
                .iter()
                .any(|c| c.delta > 0.0 && c.wall() == Some(3))
        });
    }
    let e = dem.energy();
    let d = e.dissipated();
    let (handed, lost) = dem
        .shape_contacts()
        .map_or((0, 0), |sc| (sc.handovers, sc.lost));
    Ok((
        (e.total() - e0.total()).abs() / d,
        e.kinetic_total() / d,
        poly_wall,
        handed,
        lost,
    ))
}

/// `dem-polygon`: every quantity of the module table.
pub fn polygons(_f: Fidelity) -> Result<Vec<Check>> {
    let mut out = Vec::new();
    let (mut wd, mut wn, mut gg, mut gw) = (0.0f64, 0.0f64, usize::MAX, usize::MAX);
    for seed in 1..=5 {
        let (d, n, a, b, touched) = measure_detector_agreement(seed, 500)?;
        (wd, wn, gg, gw) = (wd.max(d), wn.max(n), gg.min(a), gw.min(b));
        out.push(Check::at_least(
            CASE,
            &format!("seed {seed}: walls touched"),
            touched as f64,
            test_walls().len() as f64,
        ));
    }
    out.push(Check::at_most(
        CASE,
        "rapier vs cell list: max |Δδ|/R",
        wd,
        1e-12,
    ));
    out.push(Check::at_most(
        CASE,
        "rapier vs cell list: max |Δn|",
        wn,
        1e-12,
    ));
    out.push(Check::at_least(
        CASE,
        "fewest grain-grain contacts of a seed",
        gg as f64,
        300.0,
    ));
    out.push(Check::at_least(
        CASE,
        "fewest grain-wall contacts of a seed",
        gw as f64,
        20.0,
    ));
    let (f, y, w, th, n) = measure_resting_square()?;
    out.push(Check::abs(
        CASE,
        "resting square: sum f_n/(m g) - 1",
        f,
        0.0,
        1e-9,
    ));
    out.push(Check::abs(
        CASE,
        "resting square: y - (1/2 - mg/2k_n)",
        y,
        0.0,
        1e-9,
    ));
    out.push(Check::at_most(
        CASE,
        "resting square: max |omega| (rad/s)",
        w,
        1e-12,
    ));
    out.push(Check::at_most(
        CASE,
        "resting square: |angle| (rad)",
        th,
        1e-12,
    ));
    out.push(Check::abs(
        CASE,
        "resting square: contact points",
        n as f64,
        2.0,
        0.0,
    ));
    let mu = 0.5;
    let (_, v, dx) = measure_square_incline(20.0, mu)?;
    out.push(Check::at_most(
        CASE,
        "square, 20° < atan 0.5: |v| at 0.9 s (m/s)",
        v.abs(),
        1e-5,
    ));
    out.push(Check::at_most(
        CASE,
        "square, 20°: creep over 0.6 s (m)",
        dx.abs(),
        1e-6,
    ));
    let th = 35f64.to_radians();
    let (a, _, _) = measure_square_incline(35.0, mu)?;
    out.push(Check::rel(
        CASE,
        "square, 35° > atan 0.5: a/g = sin θ − μ cos θ",
        a,
        th.sin() - mu * th.cos(),
        5e-3,
    ));
    for e in [0.3, 0.5, 0.9] {
        out.push(Check::rel(
            CASE,
            &format!("flat square impact on the floor: rebound, e = {e}"),
            measure_flat_impact(e)?,
            e,
            1e-2,
        ));
    }
    let (dp, dl, touched, n_end, w) = measure_polygon_collision()?;
    out.push(Check::at_most(CASE, "polygon collision: |Δp|/p", dp, 1e-13));
    // L is conserved exactly by the scheme: in a kick Σ x×F + T = 0 for torques r×F about the
    // common contact point; in a drift Δ(x × m v) = Δt v × m v = 0. So round-off only.
    out.push(Check::at_most(
        CASE,
        "polygon collision: |ΔL|/(p·1 m)",
        dl,
        1e-12,
    ));
    out.push(Check::at_least(
        CASE,
        "polygon collision: steps in contact",
        touched as f64,
        10.0,
    ));
    out.push(Check::abs(
        CASE,
        "polygon collision: contacts after",
        n_end as f64,
        0.0,
        0.0,
    ));
    out.push(Check::at_least(
        CASE,
        "polygon collision: |ω| of the square after",
        w.abs(),
        1e-3,
    ));
    let (a, w, n) = measure_disk_wedge()?;
    out.push(Check::rel(
        CASE,
        "disk on 30° polygon wedge: a/g = sin θ",
        a,
        0.5,
        5e-3,
    ));
    out.push(Check::at_most(
        CASE,
        "disk on polygon wedge: |omega| (rad/s)",
        w,
        1e-12,
    ));
    out.push(Check::abs(
        CASE,
        "disk on polygon wedge: contacts",
        n as f64,
        1.0,
        0.0,
    ));
    let (err, k, touched, _, _) = measure_pile_budget(3.0, 0.1)?;
    out.push(Check::at_most(CASE, "mixed pile: |ΔE_tot|/D", err, 1e-2));
    out.push(Check::at_most(
        CASE,
        "mixed pile: K_end/D (settled)",
        k,
        1e-3,
    ));
    out.push(Check::at_least(
        CASE,
        "mixed pile: polygon wall touched",
        f64::from(u8::from(touched)),
        1.0,
    ));
    Ok(out)
}
