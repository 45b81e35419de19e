//! A DEM domain periodic in x, rough walls of fixed disks, and the chute built from them:
//! a collision across the period's ends is the same collision as in the middle (to round-off
//! of the shifted coordinates), grains that stream through the ends keep the momentum of a
//! periodic box, the chute model checks and refuses bad periodic input by key, and
//! `chute-bagnold` runs at the test size (heavy tier).

use granflow::dem::{ContactParams, Dem, DemParams, Grains};
use granflow::scenario::granular::GranularScenario;
use granflow::scenario::ScenarioFile;

/// A frictional law with damping and rolling resistance, so every part of the contact is used.
fn law() -> ContactParams {
    ContactParams {
        restitution: 0.6,
        friction: 0.4,
        rolling_stiffness: 0.02,
        rolling_damping: 1e-4,
        rolling_friction: 0.1,
        ..ContactParams::elastic(2e3)
    }
}

/// Two disks (R = 0.5 and 0.4) at `xa`, `xb`, approaching each other obliquely and spinning,
/// in a domain periodic over [0, 10), no gravity, no walls.
fn pair(xa: f64, xb: f64) -> Dem {
    let mut g = Grains::new();
    g.push_disk(xa, 1.0, 0.5, 1.0);
    g.push_disk(xb, 1.3, 0.4, 1.0);
    g.vx[0] = 1.0;
    g.vy[0] = 0.2;
    g.vx[1] = -0.5;
    g.omega[1] = 3.0;
    let mut p = DemParams::new(law(), law(), [0.0, 0.0]);
    p.periodic_x = Some([0.0, 10.0]);
    Dem::new(g, vec![], p).unwrap()
}

/// The same oblique, frictional collision with the pair straddling the period's ends (the
/// first grain at x = 9.3, the second at 0.2 = 10.2 − 10) and in the middle (4.3, 5.2): after
/// the collision the velocities and spins agree to 1e-12 and the positions, shifted by 5, to
/// 1e-9 (the coordinates differ, so the arithmetic differs in the last bits), and the grains
/// did touch.
#[test]
fn a_collision_across_the_ends_is_the_collision_in_the_middle() {
    let mut across = pair(9.3, 0.2);
    let mut middle = pair(4.3, 5.2);
    let before = middle.grains.vx.clone();
    for _ in 0..20 {
        across.steps(200);
        middle.steps(200);
    }
    assert!(
        (middle.grains.vx[0] - before[0]).abs() > 0.1,
        "the grains must have collided"
    );
    for (a, m) in [
        (&across.grains.vx, &middle.grains.vx),
        (&across.grains.vy, &middle.grains.vy),
        (&across.grains.omega, &middle.grains.omega),
    ] {
        for k in 0..2 {
            assert!((a[k] - m[k]).abs() < 1e-12, "{a:?} vs {m:?}");
        }
    }
    // Positions: the middle pair's shifted by 5 (9.3 = 4.3 + 5, 0.2 = 5.2 + 5 − 10), modulo
    // the period.
    for k in 0..2 {
        let d = (across.grains.x[k] - middle.grains.x[k] - 5.0).rem_euclid(10.0);
        let dy = (across.grains.y[k] - middle.grains.y[k]).abs();
        assert!(
            d.min(10.0 - d) + dy < 1e-9,
            "grain {k}: {} vs {}, dy {dy}",
            across.grains.x[k],
            middle.grains.x[k]
        );
    }
}

/// 400 grains in a box periodic in x, floor and lid, no gravity, streaming at random
/// velocities: after 20 000 steps many have crossed the ends, the x-momentum (no wall pushes
/// along x: frictionless floor and lid) is conserved to round-off, and the positions stay
/// within a skin of the period.
#[test]
fn a_periodic_box_keeps_its_momentum_and_its_grains() {
    let mut g = Grains::new();
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for k in 0..400 {
        let (i, j) = (k % 40, k / 40);
        g.push_disk(0.5 + i as f64, 0.6 + j as f64, 0.3 + 0.15 * rnd(), 1.0);
        g.vx[k] = 2.0 * rnd() - 0.5;
        g.vy[k] = 2.0 * rnd() - 1.0;
    }
    let grain = ContactParams {
        friction: 0.4,
        restitution: 0.8,
        ..ContactParams::elastic(2e3)
    };
    let wall = ContactParams {
        friction: 0.0,
        ..grain
    };
    let mut p = DemParams::new(grain, wall, [0.0, 0.0]);
    p.periodic_x = Some([0.0, 40.0]);
    let walls = vec![
        granflow::dem::Wall::floor(0.0),
        granflow::dem::Wall::Plane {
            point: [0.0, 10.2],
            normal: [0.0, -1.0],
        },
    ];
    let mut dem = Dem::new(g, walls, p).unwrap();
    let momentum = |d: &Dem| -> f64 { (0..400).map(|k| d.grains.mass[k] * d.grains.vx[k]).sum() };
    let p0 = momentum(&dem);
    let x0 = dem.grains.x.clone();
    let mut travelled = vec![0.0; 400];
    for _ in 0..100 {
        let before = dem.grains.x.clone();
        dem.steps(200);
        for k in 0..400 {
            let dx = dem.grains.x[k] - before[k];
            travelled[k] += dx - 40.0 * (dx / 40.0).round();
        }
    }
    let crossed = (0..400)
        .filter(|&k| x0[k] + travelled[k] < 0.0 || x0[k] + travelled[k] >= 40.0)
        .count();
    assert!(crossed > 50, "only {crossed} grains crossed an end");
    let scale: f64 = (0..400)
        .map(|k| dem.grains.mass[k] * dem.grains.vx[k].abs())
        .sum();
    assert!(
        (momentum(&dem) - p0).abs() < 1e-12 * scale,
        "{} vs {p0}",
        momentum(&dem)
    );
    assert!(dem.contact_steps() > 0);
    let skin = 0.2 * 2.0 * 0.45;
    assert!(dem.grains.x.iter().all(|&x| x > -skin && x < 40.0 + skin));
}

fn chute() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/dem/chute.toml"
    ))
    .unwrap()
}

/// The chute model derives: grains inside the period, the row of 32 bumps with its images
/// across the ends; bad periodic input (a period reversed, too short, or not holding the
/// grains) is refused naming the key.
#[test]
fn the_chute_model_checks_and_bad_periodic_input_is_refused() {
    let s = GranularScenario::from_toml(&chute()).unwrap();
    let d = s.derive().unwrap();
    assert!(d.grains.len() > 500);
    assert_eq!(d.params.periodic_x, Some([0.0, 0.036]));
    // 32 bumps, and the first three and the last three repeated one period beyond (within
    // R_b + 2 d_max = 3.3 mm of an end: bump centres at 0.56, 1.69, 2.81 mm from it).
    assert_eq!(d.walls.len(), 32 + 3 + 3);
    let cases: &[(&str, &str, &str)] = &[
        (
            "periodic_x = [0.0, 0.036]",
            "periodic_x = [0.036, 0.0]",
            "periodic_x",
        ),
        (
            "periodic_x = [0.0, 0.036]",
            "periodic_x = [0.0, 0.030]",
            "periodic_x",
        ),
        ("count = 32", "count = 0", "wall[0].bumps.count"),
        (
            "diameter = 1.125e-3",
            "diameter = -1.0",
            "wall[0].bumps.diameter",
        ),
        ("bins = 60", "bins = 0", "profile.bins"),
        ("start = 6.0", "start = 20.0", "profile.start"),
        (
            "bumps = {",
            "segment = [[0.0, 0.0], [0.036, 0.0]]\nbumps = {",
            "wall[0]",
        ),
    ];
    for (from, to, field) in cases {
        let text = chute();
        assert!(text.contains(from), "{from}");
        let e = GranularScenario::from_toml(&text.replacen(from, to, 1))
            .and_then(|s| s.derive().map(|_| ()))
            .unwrap_err()
            .to_string();
        assert!(e.contains(field), "{to}: {e}");
    }
    // A period too short for the cell list is refused by `check` already, not at the run.
    let short = chute().replacen("periodic_x = [0.0, 0.036]", "periodic_x = [0.0, 0.004]", 1);
    let e = GranularScenario::from_toml(&short)
        .and_then(|s| s.derive().map(|_| ()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("periodic_x") && e.contains("at least 3"), "{e}");
}

/// `chute-bagnold` at the test size (a chute 16 bumps long, 8 s, averaged over 4–8 s).
#[test]
#[ignore = "heavy tier (≈ 100 s on 2 cores): cargo test -- --ignored"]
fn chute_bagnold_at_the_test_size() {
    crate::common::assert_passes("chute-bagnold");
}
