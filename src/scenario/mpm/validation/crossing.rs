//! `mpm-cell-crossing`: points crossing cells, standard MPM against uGIMP (see [`super`]).

use super::*;

/// RMS over time and points of (σ_yy − σ_yy,settled)/ρgH while the settled block translates
/// at `v0` for `cells_moved` cells (or as long as it would take, when v0 = 0), the largest,
/// and the RMS over points of the settled σ_xx/ρgH (the stress that multiplies the jumping
/// ∂N/∂x of standard MPM when the block moves along x).
pub fn crossing_noise(shape: ShapeKind, cells_moved: f64, v0: f64) -> Result<(f64, f64, f64)> {
    let (rho, g, h) = (1000.0, 9.81, 0.05);
    let (w, hgt) = (8.0 * h, 4.0 * h);
    let walls = vec![Wall {
        side: Side::Bottom,
        position: 0.0,
        kind: WallKind::Roller,
    }];
    let mat = MaterialModel::Elastic(elastic(rho, 1e6, 0.3));
    let pad = [2, cells_moved.ceil() as usize + 3, 2, 3];
    let mut mpm = block(
        w,
        hgt,
        h,
        2,
        pad,
        walls,
        mat,
        params(shape, Scheme::Musl, g, 0.3),
    )?;
    // Keep the point order fixed, so point k is compared with its own settled stress.
    mpm.params.resort_every = 0;
    // Settle: 1.5 s with damping (≈ 300 periods of the block's vertical mode).
    let settle = (1.5 / mpm.dt()).ceil() as u64;
    mpm.steps(settle)?;
    let reference: Vec<f64> = mpm.points.stress.iter().map(|s| s[1]).collect();
    let sxx = (mpm.points.stress.iter().map(|s| s[0] * s[0]).sum::<f64>()
        / mpm.points.len() as f64)
        .sqrt()
        / (rho * g * hgt);
    mpm.params.damping = 0.0;
    for v in mpm.points.vel.iter_mut() {
        *v = [v0, 0.0];
    }
    let steps = (cells_moved * h / 0.25 / mpm.dt()).ceil() as u64;
    let (mut sum2, mut count, mut worst) = (0.0, 0usize, 0.0f64);
    let scale = rho * g * hgt;
    for _ in 0..steps {
        mpm.step()?;
        for (s, r) in mpm.points.stress.iter().zip(&reference) {
            let e = (s[1] - r) / scale;
            sum2 += e * e;
            worst = worst.max(e.abs());
            count += 1;
        }
    }
    Ok(((sum2 / count as f64).sqrt(), worst, sxx))
}

/// Pressure loads on the boundary faces of the points of a block [lo, hi] filled by
/// [`Points::fill_rect`]: `px` on the faces normal to x, `py` on those normal to y (a corner
/// point gets both).
pub fn block_tractions(
    points: &Points,
    lo: [f64; 2],
    hi: [f64; 2],
    px: f64,
    py: f64,
) -> Vec<Traction> {
    let mut out = Vec::new();
    for (q, (x, &lp)) in points.pos.iter().zip(&points.half_size).enumerate() {
        let tol = 1e-6 * lp;
        let mut face = |normal: [f64; 2], pressure: f64| {
            out.push(Traction {
                point: q as u32,
                normal,
                pressure,
            })
        };
        if (x[0] - lp - lo[0]).abs() < tol {
            face([-1.0, 0.0], px);
        }
        if (x[0] + lp - hi[0]).abs() < tol {
            face([1.0, 0.0], px);
        }
        if (x[1] - lp - lo[1]).abs() < tol {
            face([0.0, -1.0], py);
        }
        if (x[1] + lp - hi[1]).abs() < tol {
            face([0.0, 1.0], py);
        }
    }
    out
}

/// Noise of a uniformly pre-stressed elastic block translating rigidly across cells.
#[derive(Clone, Copy, Debug)]
pub struct TranslationNoise {
    /// RMS over steps and points of |σ − σ₀|/p (xx, yy, xy components).
    pub stress_rms: f64,
    /// Largest |σ − σ₀|/p.
    pub stress_max: f64,
    /// RMS over steps and points of |v − v₀|/|v₀|.
    pub velocity_rms: f64,
}

/// The cell-crossing set-up made to show the effect: an elastic block (8 × 4 cells,
/// 2 × 2 points per cell, no gravity, no walls) with a uniform initial stress
/// σ₀ = (−p, −p/2, 0), held by pressure loads p and p/2 on its faces ([`Traction`]), moving
/// rigidly at v₀ = (0.25, 0.125) m/s across `cells_moved` cells in x. The exact solution is
/// σ = σ₀ and v = v₀ for all time. Standard MPM's internal force at the nodes near the edges
/// is piecewise constant in the block position (a point counts with its whole volume in the
/// cell where its centre is) and jumps when a point crosses a node, while the face load moves
/// smoothly: the imbalance makes spurious velocities and stresses. uGIMP integrates the
/// internal force over the point domains, which tile the block, so its boundary term equals
/// the face load wherever the edges lie.
pub fn prestressed_translation(shape: ShapeKind, cells_moved: f64) -> Result<TranslationNoise> {
    let (rho, h, p) = (1000.0, 0.05, 1e3);
    let v0 = [0.25, 0.125];
    let (w, hgt) = (8.0 * h, 4.0 * h);
    let mat = MaterialModel::Elastic(elastic(rho, 1e6, 0.3));
    let up = (0.5 * cells_moved).ceil() as usize;
    let pad = [2, cells_moved.ceil() as usize + 3, 2, up + 3];
    let mut mpm = block(
        w,
        hgt,
        h,
        2,
        pad,
        vec![],
        mat,
        params(shape, Scheme::Musl, 0.0, 0.0),
    )?;
    let s0 = [-p, -0.5 * p, 0.0, -0.3 * 1.5 * p];
    mpm.set_stress(|_| s0)?;
    let loads = block_tractions(&mpm.points, [0.0, 0.0], [w, hgt], p, 0.5 * p);
    mpm.add_tractions(loads)?;
    for v in mpm.points.vel.iter_mut() {
        *v = v0;
    }
    let speed = (v0[0] * v0[0] + v0[1] * v0[1]).sqrt();
    let steps = (cells_moved * h / v0[0] / mpm.dt()).ceil() as u64;
    let (mut s2, mut v2, mut worst, mut count) = (0.0, 0.0, 0.0f64, 0usize);
    for _ in 0..steps {
        mpm.step()?;
        for (s, v) in mpm.points.stress.iter().zip(&mpm.points.vel) {
            let e2 =
                ((s[0] - s0[0]).powi(2) + (s[1] - s0[1]).powi(2) + 2.0 * (s[2] - s0[2]).powi(2))
                    / (p * p);
            s2 += e2;
            worst = worst.max(e2.sqrt());
            v2 += ((v[0] - v0[0]).powi(2) + (v[1] - v0[1]).powi(2)) / (speed * speed);
            count += 1;
        }
    }
    Ok(TranslationNoise {
        stress_rms: (s2 / count as f64).sqrt(),
        stress_max: worst,
        velocity_rms: (v2 / count as f64).sqrt(),
    })
}

/// A soft elastic column (roller sides, fixed base) compacting under its own weight so its
/// points move down across cells, damped to rest: (RMS, max) over points of
/// |σ_yy − (−ρg(H − Y))|/ρgH, and the base strain.
pub fn compaction_error(shape: ShapeKind, youngs: f64) -> Result<(f64, f64)> {
    let (rho, g, hgt, h) = (1000.0, 9.81, 1.0, 0.05);
    let w = 2.0 * h;
    let walls = column_walls(w);
    let mat = MaterialModel::Elastic(elastic(rho, youngs, 0.0));
    let mut mpm = block(
        w,
        hgt,
        h,
        2,
        [2, 2, 2, 3],
        walls,
        mat,
        params(shape, Scheme::Musl, g, 0.3),
    )?;
    let period = 4.0 * hgt / (youngs / rho).sqrt();
    mpm.steps((40.0 * period / mpm.dt()).ceil() as u64)?;
    let scale = rho * g * hgt;
    let (mut worst, mut sum2) = (0.0f64, 0.0);
    for q in 0..mpm.points.len() {
        let e = (mpm.points.stress[q][1] + rho * g * (hgt - mpm.points.pos0[q][1])).abs() / scale;
        worst = worst.max(e);
        sum2 += e * e;
    }
    Ok(((sum2 / mpm.points.len() as f64).sqrt(), worst))
}

/// `mpm-cell-crossing`: see the module doc.
pub fn cell_crossing(fidelity: Fidelity) -> Result<Vec<Check>> {
    let case = "mpm-cell-crossing";
    let moved = match fidelity {
        Fidelity::Test => 2.0,
        Fidelity::Full => 6.0,
    };
    // The set-up: a pre-stressed block translating rigidly (gated).
    let ps = prestressed_translation(ShapeKind::Standard, moved)?;
    let pg = prestressed_translation(ShapeKind::Gimp, moved)?;
    // A block resting on a frictionless floor under gravity, translating (reported).
    let (std_rms, std_max, std_sxx) = crossing_noise(ShapeKind::Standard, moved, 0.25)?;
    let (gimp_rms, gimp_max, _) = crossing_noise(ShapeKind::Gimp, moved, 0.25)?;
    // E = 1e5 Pa: base strain ρgH/E ≈ 0.1, the top points move down ≈ one cell.
    let (cstd_rms, cstd_max) = compaction_error(ShapeKind::Standard, 1e5)?;
    let (cgimp_rms, cgimp_max) = compaction_error(ShapeKind::Gimp, 1e5)?;
    let pre = format!("pre-stressed block translating {moved} cells");
    Ok(vec![
        Check::report(
            case,
            &format!("{pre}: standard MPM RMS |σ − σ₀|/p"),
            ps.stress_rms,
            0.0,
        ),
        Check::report(
            case,
            &format!("{pre}: standard MPM max |σ − σ₀|/p"),
            ps.stress_max,
            0.0,
        ),
        Check::report(
            case,
            &format!("{pre}: standard MPM RMS |v − v₀|/|v₀|"),
            ps.velocity_rms,
            0.0,
        ),
        // uGIMP: exact discrete equilibrium (point domains tile the block, the face load is
        // the exact boundary term), so only round-off is left.
        Check::at_most(
            case,
            &format!("{pre}: uGIMP RMS |σ − σ₀|/p (round-off)"),
            pg.stress_rms,
            1e-9,
        ),
        Check::report(
            case,
            &format!("{pre}: uGIMP max |σ − σ₀|/p"),
            pg.stress_max,
            0.0,
        ),
        Check::at_most(
            case,
            &format!("{pre}: uGIMP RMS |v − v₀|/|v₀| (round-off)"),
            pg.velocity_rms,
            1e-9,
        ),
        Check::at_least(
            case,
            &format!("{pre}: RMS stress noise ratio standard / uGIMP"),
            ps.stress_rms / pg.stress_rms.max(f64::MIN_POSITIVE),
            10.0,
        ),
        Check::report(
            case,
            "gravity block translation: settled RMS σ_xx/ρgH (standard MPM)",
            std_sxx,
            0.0,
        ),
        Check::report(
            case,
            "gravity block translation: standard MPM RMS Δσ_yy/ρgH while crossing cells",
            std_rms,
            0.0,
        ),
        Check::report(
            case,
            "gravity block translation: standard MPM max |Δσ_yy|/ρgH",
            std_max,
            0.0,
        ),
        Check::report(
            case,
            "gravity block translation: uGIMP RMS Δσ_yy/ρgH while crossing cells",
            gimp_rms,
            0.0,
        ),
        Check::report(
            case,
            "gravity block translation: uGIMP max |Δσ_yy|/ρgH",
            gimp_max,
            0.0,
        ),
        Check::report(
            case,
            "gravity block translation: RMS noise ratio standard / uGIMP",
            std_rms / gimp_rms,
            10.0,
        ),
        Check::report(
            case,
            "compaction: standard MPM RMS |σ_yy − σ_exact|/ρgH",
            cstd_rms,
            0.0,
        ),
        Check::report(
            case,
            "compaction: standard MPM max |σ_yy − σ_exact|/ρgH",
            cstd_max,
            0.0,
        ),
        Check::at_most(
            case,
            "compaction: uGIMP RMS |σ_yy − σ_exact|/ρgH",
            cgimp_rms,
            0.02,
        ),
        Check::report(
            case,
            "compaction: uGIMP max |σ_yy − σ_exact|/ρgH",
            cgimp_max,
            0.0,
        ),
        Check::at_least(
            case,
            "compaction: RMS error ratio standard / uGIMP",
            cstd_rms / cgimp_rms,
            10.0,
        ),
    ])
}
