//! GIMPM on a grid periodic in x: a body across the ends of the period moves as the same body
//! in the middle, and a periodic box without walls keeps its momentum.

use granflow::mpm::{
    Grid, LinearElastic, MaterialModel, MohrCoulomb, Mpm, MpmParams, Points, Scheme, ShapeKind,
    Side, Transfer, Wall, WallKind,
};

const H: f64 = 0.01;
/// Cells in the period.
const PERIOD: usize = 12;

fn params(gravity: [f64; 2]) -> MpmParams {
    MpmParams {
        shape: ShapeKind::Gimp,
        scheme: Scheme::Musl,
        gravity,
        courant: 0.5,
        dt: None,
        damping: 0.0,
        pic_fraction: 0.0,
        resort_every: 10,
    }
}

/// A grid periodic over x ∈ [0, PERIOD h) with two columns of images on each side.
fn periodic_grid(walls: Vec<Wall>) -> Grid {
    Grid::new(PERIOD + 4, 10, H, [-2.0 * H, -2.0 * H], walls)
        .with_period_x(2, PERIOD)
        .unwrap()
}

/// A Mohr–Coulomb block 4 × 3 cells from x = `x0` sliding down a friction floor under a
/// tilted gravity (APIC, MUSL, yielding at the floor).
fn sliding_block(x0: f64) -> Mpm {
    let floor = Wall {
        side: Side::Bottom,
        position: 0.0,
        kind: WallKind::Friction { mu: 0.3 },
    };
    let mut pts = Points::default();
    pts.fill_rect([x0, 0.0], [x0 + 4.0 * H, 3.0 * H], H, 2, 2000.0);
    let elastic = LinearElastic {
        density: 2000.0,
        youngs_modulus: 1e6,
        poisson_ratio: 0.3,
    };
    let mc = MohrCoulomb::new(elastic, 30f64.to_radians(), 0.0, 0.0, 0.0);
    let mut mpm = Mpm::new(
        periodic_grid(vec![floor]),
        pts,
        MaterialModel::MohrCoulomb(mc),
        params([4.0, -9.0]),
    )
    .unwrap();
    mpm.set_transfer(Transfer::Apic).unwrap();
    mpm
}

/// A point's reference position, displacement, velocity and stress.
type PointRow = ([f64; 2], [f64; 2], [f64; 2], [f64; 4]);

/// Points sorted by their reference position (x taken modulo the period, less `shift`), with
/// their displacement from it, velocity and stress.
fn by_reference(mpm: &Mpm, shift: f64) -> Vec<PointRow> {
    let l = PERIOD as f64 * H;
    let p = &mpm.points;
    let mut v: Vec<_> = (0..p.len())
        .map(|q| {
            let r = [(p.pos0[q][0] - shift).rem_euclid(l), p.pos0[q][1]];
            let d = [p.pos[q][0] - p.pos0[q][0], p.pos[q][1] - p.pos0[q][1]];
            (r, d, p.vel[q], p.stress[q])
        })
        .collect();
    v.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    v
}

/// The same block started across the ends of the period (x from 10 h to 14 h ≡ 2 h) and in
/// the middle (from 4 h) ends at the same displacement, velocity and stress after 1500 steps,
/// point by point, to round-off (the sums at the nodes add the same terms in another order).
#[test]
fn a_block_across_the_period_ends_moves_as_in_the_middle() {
    let (mut middle, mut across) = (sliding_block(4.0 * H), sliding_block(10.0 * H));
    assert_eq!(middle.dt(), across.dt());
    let wrapped = across.points.pos.iter().filter(|x| x[0] < 2.0 * H).count();
    assert_eq!(
        wrapped,
        across.points.len() / 2,
        "half the block starts across the end"
    );
    for _ in 0..1500 {
        middle.step().unwrap();
        across.step().unwrap();
    }
    let (a, b) = (by_reference(&middle, 0.0), by_reference(&across, 6.0 * H));
    assert_eq!(a.len(), b.len());
    let moved = a.iter().map(|p| p.1[0]).fold(0.0f64, f64::max);
    assert!(moved > 2.0 * H, "the block slid {moved} m");
    for (p, q) in a.iter().zip(&b) {
        // Displacements from the reference positions agree (the wrap moves both).
        for c in 0..2 {
            assert!(
                (p.1[c] - q.1[c]).abs() < 1e-9,
                "displacement {p:?} vs {q:?}"
            );
            assert!((p.2[c] - q.2[c]).abs() < 1e-9, "velocity {p:?} vs {q:?}");
        }
        for c in 0..2 {
            assert!((p.0[c] - q.0[c]).abs() < 1e-12, "reference {p:?} vs {q:?}");
        }
        for c in 0..4 {
            assert!((p.3[c] - q.3[c]).abs() < 1e-6, "stress {p:?} vs {q:?}");
        }
    }
}

/// An elastic body filling the period, in a box without walls or gravity, stirred by a
/// velocity field: total momentum stays at its start to round-off (1e-12 of Σ m |v|), and the
/// grid, its images not counted, holds the points' mass.
#[test]
fn a_periodic_box_keeps_its_momentum() {
    let mut pts = Points::default();
    pts.fill_rect([0.0, 0.0], [PERIOD as f64 * H, 4.0 * H], H, 2, 1000.0);
    for (v, x) in pts.vel.iter_mut().zip(&pts.pos) {
        let k = 2.0 * std::f64::consts::PI / (PERIOD as f64 * H);
        *v = [0.5 + 0.2 * (k * x[0]).sin(), 0.1 * (k * x[0]).cos()];
    }
    let material = MaterialModel::Elastic(LinearElastic {
        density: 1000.0,
        youngs_modulus: 1e5,
        poisson_ratio: 0.25,
    });
    let mut mpm = Mpm::new(periodic_grid(vec![]), pts, material, params([0.0; 2])).unwrap();
    let (m, p0) = mpm.mass_momentum();
    let scale: f64 = (0..mpm.points.len())
        .map(|q| mpm.points.mass[q] * mpm.points.vel[q][0].hypot(mpm.points.vel[q][1]))
        .sum();
    for _ in 0..1000 {
        mpm.step().unwrap();
    }
    let (_, p1) = mpm.mass_momentum();
    for c in 0..2 {
        assert!((p1[c] - p0[c]).abs() < 1e-12 * scale, "{p0:?} → {p1:?}");
    }
    let (mg, _) = mpm.grid_mass_momentum();
    assert!((mg - m).abs() < 1e-12 * m, "grid {mg} vs points {m}");
    let l = PERIOD as f64 * H;
    assert!(mpm.points.pos.iter().all(|x| (0.0..l).contains(&x[0])));
    let travelled = mpm.time() * 0.5;
    assert!(
        travelled > l,
        "the body crossed the ends ({travelled} m of {l} m)"
    );
}

/// Walls on the sides of a periodic grid, or a period without room for its images, are
/// refused.
#[test]
fn a_period_needs_its_images_and_no_side_walls() {
    let side = Wall {
        side: Side::Left,
        position: 0.0,
        kind: WallKind::Roller,
    };
    let e = Grid::new(16, 10, H, [-2.0 * H; 2], vec![side])
        .with_period_x(2, PERIOD)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no left or right walls"), "{e}");
    let e = Grid::new(14, 10, H, [-2.0 * H; 2], vec![])
        .with_period_x(2, PERIOD)
        .unwrap_err()
        .to_string();
    assert!(e.contains("two columns of images"), "{e}");
}
