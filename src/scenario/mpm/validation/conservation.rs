//! `mpm-conservation` and `mpm-friction`: mass and momentum to round-off, Coulomb sliding
//! (see [`super`]).

use super::*;

/// `mpm-conservation`: see the module doc.
pub fn conservation(fidelity: Fidelity) -> Result<Vec<Check>> {
    let case = "mpm-conservation";
    let steps = match fidelity {
        Fidelity::Test => 300,
        Fidelity::Full => 900,
    };
    let mut out = Vec::new();
    for (scheme, pic) in [
        (Scheme::Usf, 0.0),
        (Scheme::Usl, 0.0),
        (Scheme::Musl, 0.0),
        (Scheme::Musl, 0.05),
    ] {
        let h = 0.02;
        let mat = MaterialModel::MohrCoulomb(MohrCoulomb::new(
            elastic(1800.0, 1e6, 0.25),
            30f64.to_radians(),
            5f64.to_radians(),
            100.0,
            50.0,
        ));
        let mut mpm = block(
            0.2,
            0.1,
            h,
            2,
            [8, 8, 8, 8],
            vec![],
            mat,
            MpmParams {
                pic_fraction: pic,
                ..params(ShapeKind::Gimp, scheme, 0.0, 0.0)
            },
        )?;
        let (xc, yc) = (0.1, 0.05);
        for (v, x) in mpm.points.vel.iter_mut().zip(&mpm.points.pos) {
            *v = [
                0.3 - 2.0 * (x[1] - yc) + 1.5 * x[1],
                0.1 + 2.0 * (x[0] - xc),
            ];
        }
        let (m0, p0) = mpm.mass_momentum();
        mpm.steps(steps)?;
        let (m1, p1) = mpm.mass_momentum();
        let (mg, _) = mpm.grid_mass_momentum();
        let vscale = 0.5;
        let dp = ((p1[0] - p0[0]).powi(2) + (p1[1] - p0[1]).powi(2)).sqrt() / (m0 * vscale);
        let e = mpm.energy();
        let name = format!("{scheme:?} (PIC fraction {pic})");
        out.push(Check::at_most(
            case,
            &format!("{name}: |M_points(end) − M_points(0)|/M"),
            ((m1 - m0) / m0).abs(),
            0.0,
        ));
        out.push(Check::at_most(
            case,
            &format!("{name}: |M_nodes − M_points|/M"),
            ((mg - m1) / m1).abs(),
            1e-13,
        ));
        out.push(Check::at_most(
            case,
            &format!("{name}: |P(end) − P(0)| / (M·0.5 m/s) after {steps} steps"),
            dp,
            1e-12,
        ));
        out.push(Check::report(
            case,
            &format!("{name}: plastic dissipation / initial kinetic energy"),
            e.plastic / (0.5 * m0 * 0.25),
            0.0,
        ));
    }
    // APIC: linear momentum on the same block, and angular momentum of a spinning disk.
    let steps_disk = steps * 3;
    let flip = rotating_disk(Transfer::Flip, 0.0, steps_disk)?;
    let pic = rotating_disk(Transfer::Flip, 1.0, steps_disk)?;
    let apic = rotating_disk(Transfer::Apic, 0.0, steps_disk)?;
    let r = format!(
        "elastic disk spinning at 2 rad/s, {steps_disk} steps ({:.2} rad)",
        apic.angle
    );
    out.push(Check::at_most(
        case,
        &format!("{r}, APIC: |L(end) − L(0)|/L(0), L = Σ m (x × v + B_yx − B_xy)"),
        apic.angular_momentum_change,
        1e-12,
    ));
    out.push(Check::at_most(
        case,
        &format!("{r}, APIC: |P(end) − P(0)| / (M·ωR)"),
        apic.momentum_change,
        1e-12,
    ));
    for (name, d) in [("FLIP", &flip), ("PIC", &pic), ("APIC", &apic)] {
        if name != "APIC" {
            out.push(Check::report(
                case,
                &format!("{r}, {name}: |L(end) − L(0)|/L(0)"),
                d.angular_momentum_change,
                0.0,
            ));
        }
        out.push(Check::report(
            case,
            &format!("{r}, {name}: point kinetic energy at the end / at the start"),
            d.kinetic_ratio,
            1.0,
        ));
    }
    // PIC loses the rotation's energy to the grid; APIC keeps it (Jiang et al. 2015).
    out.push(Check::at_least(
        case,
        &format!("{r}: kinetic energy lost, PIC / APIC"),
        (1.0 - pic.kinetic_ratio) / (1.0 - apic.kinetic_ratio).abs().max(f64::MIN_POSITIVE),
        10.0,
    ));
    Ok(out)
}

/// What [`rotating_disk`] measures.
#[derive(Clone, Copy, Debug)]
pub struct DiskSpin {
    /// |L(end) − L(0)|/|L(0)| (about the disk centre).
    pub angular_momentum_change: f64,
    /// |P(end) − P(0)|/(M ω R).
    pub momentum_change: f64,
    /// Σ ½ m v² at the end over at the start.
    pub kinetic_ratio: f64,
    /// Rigid-rotation angle ω t over the run (rad).
    pub angle: f64,
}

/// An elastic disk (R = 0.1 m, h = 0.02 m, 2 × 2 points per cell, E = 1 MPa, ρ = 1000) in rigid
/// rotation at ω = 2 rad/s about its centre, no gravity, no walls, uGIMP, MUSL.
pub fn rotating_disk(transfer: Transfer, pic: f64, steps: u64) -> Result<DiskSpin> {
    let (h, r, omega, rho): (f64, f64, f64, f64) = (0.02, 0.1, 2.0, 1000.0);
    let mut pts = Points::default();
    let d = h / 2.0;
    let n = (r / d).round() as i64;
    for i in -n..n {
        for j in -n..n {
            let x = [(i as f64 + 0.5) * d, (j as f64 + 0.5) * d];
            if x[0] * x[0] + x[1] * x[1] <= r * r {
                pts.push(x, d * d, rho, 0.5 * d);
            }
        }
    }
    let cells = 2 * (r / h).round() as usize + 8;
    let grid = Grid::new(cells, cells, h, [-(cells as f64) * h / 2.0; 2], vec![]);
    let mat = MaterialModel::Elastic(elastic(rho, 1e6, 0.3));
    let mut mpm = Mpm::new(
        grid,
        pts,
        mat,
        MpmParams {
            pic_fraction: pic,
            ..params(ShapeKind::Gimp, Scheme::Musl, 0.0, 0.0)
        },
    )?;
    mpm.set_transfer(transfer)?;
    for (v, x) in mpm.points.vel.iter_mut().zip(&mpm.points.pos) {
        *v = [-omega * x[1], omega * x[0]];
    }
    let kinetic = |m: &Mpm| m.energy().kinetic;
    let (m0, p0) = mpm.mass_momentum();
    let (l0, k0) = (mpm.angular_momentum(), kinetic(&mpm));
    mpm.steps(steps)?;
    let (_, p1) = mpm.mass_momentum();
    let dp = ((p1[0] - p0[0]).powi(2) + (p1[1] - p0[1]).powi(2)).sqrt() / (m0 * omega * r);
    Ok(DiskSpin {
        angular_momentum_change: ((mpm.angular_momentum() - l0) / l0).abs(),
        momentum_change: dp,
        kinetic_ratio: kinetic(&mpm) / k0,
        angle: omega * mpm.time(),
    })
}

/// A block sliding on a Coulomb-frictional floor (μ = 0.3) from v₀ = 0.5 m/s after settling
/// under gravity: rigid-body mechanics gives the deceleration μg, so the centre-of-mass
/// velocity v₀ − μgt at t = 0.1 s and the sliding distance v₀²/(2μg). Tolerance 3 % (the
/// block is elastic and rings a little as it is released; the wall acts on grid nodes).
pub fn sliding_block(_: Fidelity) -> Result<Vec<Check>> {
    let case = "mpm-friction";
    let (rho, g, h, mu, v0) = (1000.0, 9.81, 0.02, 0.3, 0.5);
    let walls = vec![Wall {
        side: Side::Bottom,
        position: 0.0,
        kind: WallKind::Friction { mu },
    }];
    let mat = MaterialModel::Elastic(elastic(rho, 1e6, 0.3));
    let mut mpm = block(
        0.2,
        0.1,
        h,
        2,
        [2, 6, 2, 3],
        walls,
        mat,
        params(ShapeKind::Gimp, Scheme::Musl, g, 0.3),
    )?;
    mpm.steps((0.5 / mpm.dt()).ceil() as u64)?;
    mpm.params.damping = 0.0;
    for v in mpm.points.vel.iter_mut() {
        *v = [v0, 0.0];
    }
    let com = |m: &Mpm| {
        let (mut mx, mut mv, mut mt) = (0.0, 0.0, 0.0);
        for q in 0..m.points.len() {
            mx += m.points.mass[q] * m.points.pos[q][0];
            mv += m.points.mass[q] * m.points.vel[q][0];
            mt += m.points.mass[q];
        }
        (mx / mt, mv / mt)
    };
    let (x0, _) = com(&mpm);
    let t1 = 0.1;
    let n1 = (t1 / mpm.dt()).round() as u64;
    mpm.steps(n1)?;
    let t1 = n1 as f64 * mpm.dt();
    let (_, v1) = com(&mpm);
    let stop = v0 / (mu * g);
    mpm.steps(((stop + 0.1) / mpm.dt()).ceil() as u64 - n1)?;
    let (x2, v2) = com(&mpm);
    Ok(vec![
        Check::rel(
            case,
            "centre-of-mass velocity at t = 0.1 s (m/s)",
            v1,
            v0 - mu * g * t1,
            0.03,
        ),
        Check::rel(
            case,
            "sliding distance (m)",
            x2 - x0,
            v0 * v0 / (2.0 * mu * g),
            0.03,
        ),
        Check::at_most(
            case,
            "|velocity| 0.1 s after the analytic stop (m/s)",
            v2.abs(),
            0.01,
        ),
    ])
}
