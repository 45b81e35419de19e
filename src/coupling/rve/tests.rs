use super::*;
use crate::dem::periodic_cell::tests::glass_beads;
use crate::mpm::{Grid, Mpm, MpmParams, Points, Scheme, ShapeKind, Side, Wall, WallKind};

/// One material for the tests: 64 glass-bead-like disks per unit depth at φ = 0.80, p₀ = 2 kPa
/// (the periodic cell's test material).
fn material() -> RveMaterial {
    static M: std::sync::OnceLock<RveMaterial> = std::sync::OnceLock::new();
    M.get_or_init(|| RveMaterial::prepare(&glass_beads(64, 0.80, 11)).unwrap())
        .clone()
}

fn norm(s: &Stress) -> f64 {
    (s[0] * s[0] + s[1] * s[1] + 2.0 * s[2] * s[2]).sqrt()
}

/// A point compressed along y at fixed width by `steps` increments of `de` over `dt` each.
fn compressed(m: &RveMaterial, steps: usize, de: f64, dt: f64) -> (PeriodicCell, Stress) {
    let (mut cell, mut s) = m.start();
    for _ in 0..steps {
        s = m
            .update_stress(&s, &[0.0, -de, 0.0], 0.0, dt, &mut cell)
            .unwrap();
    }
    (cell, s)
}

/// Objectivity: a rigid rotation (Δε = 0, Δω ≠ 0) on a stressed volume turns its stress to
/// R σ Rᵀ and changes nothing else: beside a twin that takes the same step without the
/// rotation, the stress agrees to 1e-10 of its size once turned back, and so do the packing
/// fraction, coordination and stored energy.
#[test]
fn a_rigid_rotation_turns_the_stress_and_nothing_else() {
    let m = material();
    let dt = 10.0 * m.template().dt();
    let (cell, s) = compressed(&m, 100, 2e-5, dt);
    assert!((s[0] - s[1]).abs() > 0.05 * norm(&s), "no deviator: {s:?}");
    let (mut a, mut b) = (cell.clone(), cell);
    let sa = m.update_stress(&s, &[0.0; 3], 0.0, dt, &mut a).unwrap();
    let spin = -0.4; // Δω = −θ: a counter-clockwise turn by 0.4 rad
    let sb = m.update_stress(&s, &[0.0; 3], spin, dt, &mut b).unwrap();
    let (sn, cs) = (0.4f64).sin_cos();
    let r = Tensor::new(cs, -sn, sn, cs);
    let ta = Tensor::new(sa[0], sa[2], sa[2], sa[1]);
    let turned = r * ta * r.transpose();
    let tb = Tensor::new(sb[0], sb[2], sb[2], sb[1]);
    assert!((turned - tb).norm() < 1e-10 * norm(&sa), "{turned} vs {tb}");
    assert!((sb[3] - sa[3]).abs() < 1e-10 * norm(&sa));
    assert!((a.packing_fraction() - b.packing_fraction()).abs() < 1e-12);
    assert_eq!(a.coordination(), b.coordination());
    let (ea, eb) = (a.energy(), b.energy());
    assert!((ea.stored - eb.stored).abs() < 1e-9 * ea.stored);
}

/// Consistency: an MPM block of volume points in confined compression (rollers at the sides,
/// platens at top and base: every node prescribed, so the velocity field is homogeneous)
/// reproduces, at every point, the stress path of one standalone volume driven by the same
/// strain increments. The increments agree to round-off (the grid's velocity gradient of a
/// linear field); the DEM could amplify a round-off difference over the steps, but after 60
/// steps the largest difference is 7e-13 of the stress (measured), gated at 1e-10. The stress work
/// the MPM books for a point equals what the point's volume stored and dissipated.
#[test]
fn an_mpm_block_reproduces_the_standalone_volume() {
    let m = material();
    let h = 0.02;
    // One cell, so every node the points reach lies on or behind a wall: the motion is
    // prescribed everywhere (a free interior node would let the packing's own small shear
    // stress shear the block). Both platens move in, so the points move away from the ghost
    // node rows behind them, whose prescribed velocity is not the linear field's.
    let (w, hgt) = (h, h);
    let speed = 1e-2;
    let walls = vec![
        Wall {
            side: Side::Left,
            position: 0.0,
            kind: WallKind::Roller,
        },
        Wall {
            side: Side::Right,
            position: w,
            kind: WallKind::Roller,
        },
        Wall {
            side: Side::Bottom,
            position: 0.0,
            kind: WallKind::Platen { speed: 0.5 * speed },
        },
        Wall {
            side: Side::Top,
            position: hgt,
            kind: WallKind::Platen { speed: 0.5 * speed },
        },
    ];
    let mut pts = Points::default();
    pts.fill_rect([0.0, 0.0], [w, hgt], h, 2, m.density());
    for q in 0..pts.len() {
        pts.vel[q] = [0.0, speed * (0.5 - pts.pos[q][1] / hgt)];
    }
    let dt = 10.0 * m.template().dt();
    let params = MpmParams {
        shape: ShapeKind::Gimp,
        scheme: Scheme::Musl,
        gravity: [0.0, 0.0],
        courant: 1.0,
        dt: Some(dt),
        damping: 0.0,
        pic_fraction: 0.0,
        resort_every: 0,
    };
    let grid = Grid::new(5, 5, h, [-2.0 * h, -2.0 * h], walls);
    let mut mpm = Mpm::new(grid, pts, m.clone(), params).unwrap();
    // The template's own normal stresses: every point starts as the template (the servo has
    // nothing to do).
    let s0 = point_stress(m.template());
    mpm.set_stress(|_| [s0[0], s0[1], 0.0, s0[3]]).unwrap();
    assert_eq!(
        mpm.state(0).steps(),
        m.template().steps(),
        "the servo moved the template"
    );
    let work0 = mpm.points.work[0];
    let (mut alone, mut s) = m.start();
    let e0 = alone.energy();
    let de = speed / hgt * dt;
    let steps = 60;
    for _ in 0..steps {
        mpm.step().unwrap();
        s = m
            .update_stress(&s, &[0.0, -de, 0.0], 0.0, dt, &mut alone)
            .unwrap();
    }
    assert!(-s[1] > 1.3 * 2e3, "the path did not load the volume: {s:?}");
    let worst = (0..mpm.points.len())
        .map(|q| {
            let p = mpm.points.stress[q];
            norm(&[p[0] - s[0], p[1] - s[1], p[2] - s[2], 0.0]) / norm(&s)
        })
        .fold(0.0, f64::max);
    assert!(worst < 1e-10, "largest relative difference {worst:e}");
    // Energy: the stress work the MPM books for a point, Σ σ_mid : Δε V (plus the initial
    // stored energy), against the volume's own books scaled to the point's volume, V/(A t):
    // work fed in = Δ(stored + kinetic) + dissipated, within 1 %.
    let cell = mpm.state(0);
    let e = cell.energy();
    let scale = mpm.points.vol[0] / (cell.area() * cell.thickness());
    let booked = mpm.points.work[0] - work0;
    let balance =
        (e.stored - e0.stored) + (e.kinetic - e0.kinetic) + (e.dissipated - e0.dissipated);
    assert!(booked > 0.0);
    assert!(
        (booked - scale * balance).abs() < 0.01 * booked,
        "MPM work {booked:e} J/m vs the volume's ΔE + D {:e} J/m",
        scale * balance
    );
}

/// A failing volume fails the point's update with the reason.
#[test]
fn a_failing_volume_names_the_reason() {
    let m = material();
    let dt = 10.0 * m.template().dt();
    let (mut cell, s) = m.start();
    // A 40 % compression in one step drives grains through each other.
    let err = m
        .update_stress(&s, &[-0.4, -0.4, 0.0], 0.0, dt, &mut cell)
        .unwrap_err();
    assert!(
        err.contains("representative volume") && err.contains("overlap"),
        "{err}"
    );
    let mut empty = PeriodicCell::default();
    assert!(m.update_stress(&s, &[0.0; 3], 0.0, dt, &mut empty).is_err());
}

/// Initial state: a point asked for an anisotropic geostatic stress (σ_yy = −3 kPa,
/// σ_xx = K₀ σ_yy with K₀ = 0.7, from the template at p₀ = 2 kPa) starts with its normal
/// stresses within the servo's 1 % of the target's mean pressure, at rest; one asked for
/// tension or shear is refused with the reason.
#[test]
fn a_point_starts_at_the_normal_stresses_asked() {
    let m = material();
    let target = [-0.7 * 3e3, -3e3, 0.0, -0.85 * 3e3];
    let (cell, s) = m.initial_state(&target).unwrap();
    let pt = 0.85 * 3e3;
    for (got, want) in [(s[0], target[0]), (s[1], target[1])] {
        assert!((got - want).abs() < 0.01 * pt, "{got} Pa for {want} Pa");
    }
    assert!(s[2].abs() < 0.1 * pt, "shear {s:?}");
    let e = cell.energy();
    assert!(e.kinetic < 1e-6 * e.stored, "not at rest: {e:?}");
    // Unloading below the template's pressure as well.
    let (_, s) = m.initial_state(&[-500.0, -800.0, 0.0, -650.0]).unwrap();
    assert!(
        (s[0] + 500.0).abs() < 6.5 && (s[1] + 800.0).abs() < 6.5,
        "{s:?}"
    );
    let tension = m.initial_state(&[100.0, -3e3, 0.0, 0.0]).unwrap_err();
    assert!(tension.contains("compression"), "{tension}");
    let shear = m.initial_state(&[-3e3, -3e3, 500.0, -3e3]).unwrap_err();
    assert!(shear.contains("σ_xy"), "{shear}");
}
