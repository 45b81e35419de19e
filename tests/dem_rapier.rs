//! rapier2d-backed detection and polygon grains: the rapier detector against the cell list on
//! random disk packings, and polygon physics (resting square, frictional incline, momentum in a
//! polygon–polygon collision).

use granflow::dem::detect_rapier::{cell_list_contacts, Contact, Coverage, RapierDetector};
use granflow::dem::packing::SplitMix64;
use granflow::dem::shape::Polygons;
use granflow::dem::{ContactParams, Dem, DemParams, Grains, Wall};

/// Walls of the property test: box sides, floor, a slanted segment and a slanted plane.
fn test_walls() -> Vec<Wall> {
    let s = 0.5f64.sqrt();
    vec![
        Wall::floor(0.0),
        Wall::left(0.0),
        Wall::right(20.0),
        Wall::Segment {
            a: [3.0, 14.0],
            b: [16.5, 11.0],
        },
        // Slanted ceiling-corner plane x + y ≤ 34 (normal into the domain).
        Wall::Plane {
            point: [17.0, 17.0],
            normal: [-s, -s],
        },
    ]
}

/// Random polydisperse disks (R uniform in [0.3, 0.7]) in the 20 × 20 box, some overlapping
/// (a new disk may overlap the others by up to half their radius sum), some overlapping the
/// walls (by up to half the radius); random angles.
fn random_packing(seed: u64, n: usize) -> Grains {
    let walls = test_walls();
    let mut rng = SplitMix64::new(seed);
    let mut g = Grains::with_capacity(n);
    let mut tries = 0;
    while g.len() < n && tries < 100 * n {
        tries += 1;
        let r = 0.3 + 0.4 * rng.uniform();
        let (x, y) = (0.1 + 19.8 * rng.uniform(), 0.1 + 19.8 * rng.uniform());
        // Centre at least R/2 from every wall, as from other centres below: the normal is
        // (q − c)/|q − c|, whose round-off is ε|c|/|q − c|, so a centre almost on a wall makes
        // both detectors' normals uncertain well beyond 1e-12 (seen: |q − c| = 3.6e-4 R).
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

/// The property test of issue 3: on random disk packings (5 seeds, polydisperse, overlapping,
/// with walls) rapier's collision pipeline and the cell list find the same contacts (δ > 0),
/// with the same overlaps and normals. Tolerance: |Δδ| ≤ 1e-12 (R_i + R_j) and |Δ**n**| ≤ 1e-12:
/// both compute the same f64 geometry (centre distance, plane/segment projection), so they
/// agree to a few ulps; rapier rotates its normal by the collider's angle, which is a few ulps
/// more.
#[test]
fn rapier_and_cell_list_agree_on_disks() {
    let walls = test_walls();
    for seed in 1..=5u64 {
        let g = random_packing(seed, 500);
        let skin = 0.2;
        let cl = cell_list_contacts(&g, &walls, skin, skin);
        let mut det = RapierDetector::new(Coverage::All, skin);
        let mut rp: Vec<Contact> = Vec::new();
        det.detect(&g, &walls, &mut rp);
        // One point per disk pair.
        assert!(rp.windows(2).all(|w| (w[0].i, w[0].j) != (w[1].i, w[1].j)));
        let find =
            |l: &[Contact], c: &Contact| l.iter().find(|d| (d.i, d.j) == (c.i, c.j)).copied();
        let (mut n_gg, mut n_gw, mut worst_d, mut worst_n) = (0, 0, 0.0f64, 0.0f64);
        for (a, b, name) in [(&cl, &rp, "rapier"), (&rp, &cl, "cell list")] {
            for c in a.iter().filter(|c| c.delta > 0.0) {
                let d = find(b, c)
                    .unwrap_or_else(|| panic!("seed {seed}: {name} misses contact {c:?}"));
                let i = c.i as usize;
                let scale = g.radius[i] + c.wall().map_or_else(|| g.radius[c.j as usize], |_| 0.0);
                let ed = (c.delta - d.delta).abs() / scale;
                let en = ((c.normal[0] - d.normal[0]).powi(2)
                    + (c.normal[1] - d.normal[1]).powi(2))
                .sqrt();
                assert!(
                    ed <= 1e-12 && en <= 1e-12,
                    "seed {seed}: {c:?} vs {d:?}; grain ({:e}, {:e}, {:e}, {:e})",
                    g.x[i],
                    g.y[i],
                    g.radius[i],
                    g.angle[i]
                );
                worst_d = worst_d.max(ed);
                worst_n = worst_n.max(en);
                if c.wall().is_some() {
                    n_gw += 1;
                } else {
                    n_gg += 1;
                }
            }
        }
        println!(
            "seed {seed}: {} disks, {} grain–grain and {} grain–wall contacts, \
             worst |Δδ|/R = {worst_d:.1e}, |Δn| = {worst_n:.1e}",
            g.len(),
            n_gg / 2,
            n_gw / 2
        );
        // Not vacuous: many contacts of both kinds, every wall touched.
        assert!(
            n_gg / 2 > 300 && n_gw / 2 > 20,
            "seed {seed}: {n_gg} {n_gw}"
        );
        for w in 0..walls.len() {
            assert!(
                cl.iter().any(|c| c.delta > 0.0 && c.wall() == Some(w)),
                "seed {seed}: wall {w} untouched"
            );
        }
    }
}

/// Per pair type: in a mixed system the cell list holds disk–disk pairs only, the rapier
/// detector (Complement) every pair with a polygon and no disk–disk or disk–straight-wall pair;
/// an all-disk system has no rapier detector at all.
#[test]
fn detector_picked_per_pair_type() {
    let mut g = random_packing(7, 200);
    let sq = g
        .polygons
        .add(
            &Polygons::regular(4, 0.5, 0.25 * std::f64::consts::PI),
            "sq",
        )
        .unwrap();
    let tri = g
        .polygons
        .add(&Polygons::regular(3, 0.6, 0.1), "tri")
        .unwrap();
    for k in 0..g.len() {
        if k % 3 == 1 {
            g.shape[k] = if k % 2 == 0 { sq } else { tri };
        }
    }
    let walls = test_walls();
    let p = DemParams::new(
        ContactParams::elastic(1e4),
        ContactParams::elastic(1e4),
        [0.0, 0.0],
    );
    let dem_disks = Dem::new(random_packing(7, 200), walls.clone(), p.clone()).unwrap();
    assert!(dem_disks.shape_contacts().is_none());
    let mut dem = Dem::new(g, walls, p).unwrap();
    dem.step();
    let g = &dem.grains;
    let pl = dem.pairs();
    assert!(!pl.i.is_empty());
    for k in 0..pl.i.len() {
        assert!(g.is_disk(pl.i[k] as usize) && g.is_disk(pl.j[k] as usize));
    }
    for k in 0..dem.wall_pairs().grain.len() {
        assert!(g.is_disk(dem.wall_pairs().grain[k] as usize));
    }
    let sc = dem.shape_contacts().unwrap();
    let touching = sc.found.iter().filter(|c| c.delta > 0.0).count();
    assert!(touching > 50, "{touching}");
    for c in &sc.found {
        let (i, poly_i) = (c.i as usize, !g.is_disk(c.i as usize));
        let poly_j = c.wall().is_none() && !g.is_disk(c.j as usize);
        assert!(poly_i || poly_j, "disk pair {i}–{} in the rapier list", c.j);
    }
}

/// A unit square of density 1 (m = 1, J = 1/6) and its system on a floor, with gravity
/// `grav`, the contact law `c` for grain–grain and grain–wall.
fn square_on_floor(c: ContactParams, grav: [f64; 2], y0: f64) -> Dem {
    let mut g = Grains::new();
    let s = g
        .polygons
        .add(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], "sq")
        .unwrap();
    g.push_polygon(0.0, y0, 0.0, s, 1.0);
    Dem::new(g, vec![Wall::floor(0.0)], DemParams::new(c, c, grav)).unwrap()
}

fn frictional(k_n: f64, mu: f64, e: f64) -> ContactParams {
    ContactParams {
        k_t: 2.0 / 7.0 * k_n,
        friction: mu,
        restitution: e,
        ..ContactParams::elastic(k_n)
    }
}

/// A square dropped flat onto the floor comes to rest without rotating, and the floor carries
/// its weight: Σ f_n = m g (relative 1e-9: at rest the dashpots carry nothing), each of the two
/// corner springs δ = mg/(2k_n); angle and ω zero by symmetry (1e-12, round-off).
#[test]
fn square_rests_on_floor() {
    let (k_n, g0) = (1e5, 9.81);
    let mut dem = square_on_floor(frictional(k_n, 0.5, 0.3), [0.0, -g0], 0.55);
    let steps = (1.0 / dem.dt()) as u64;
    let mut max_w = 0.0f64;
    for _ in 0..steps {
        dem.step();
        max_w = max_w.max(dem.grains.omega[0].abs());
    }
    let g = &dem.grains;
    let fn_sum = dem.shape_contacts().unwrap().wall_normal_force(0, 0);
    let delta = g0 / (2.0 * k_n);
    println!(
        "resting square: Σf_n/mg − 1 = {:.2e}, y − (½ − δ) = {:.2e}, max |ω| = {max_w:.1e}, \
         angle = {:.1e}",
        fn_sum / g0 - 1.0,
        g.y[0] - (0.5 - delta),
        g.angle[0]
    );
    assert!((fn_sum / g0 - 1.0).abs() < 1e-9);
    assert!((g.y[0] - (0.5 - delta)).abs() < 1e-9 * delta.max(1.0));
    assert!(max_w < 1e-12 && g.angle[0].abs() < 1e-12);
    assert_eq!(dem.contact_count(), 2);
}

/// Square on a frictional incline of angle θ (gravity tilted by θ, floor fixed): below
/// atan μ it sticks (velocity → 0), above it slides with a/g = sin θ − μ cos θ (the block
/// on a rough incline; both corners slide, Σf_t = μΣf_n = μ m g cos θ). Gate 0.5 % (issue 3).
#[test]
fn square_on_frictional_incline() {
    let (k_n, g0, mu) = (1e5, 9.81, 0.5);
    for theta_deg in [20.0f64, 35.0] {
        let th = theta_deg.to_radians();
        let grav = [g0 * th.sin(), -g0 * th.cos()];
        let delta = g0 * th.cos() / (2.0 * k_n);
        let mut dem = square_on_floor(frictional(k_n, mu, 0.3), grav, 0.5 - delta);
        let dt = dem.dt();
        let n1 = (0.3 / dt) as u64;
        let n2 = (0.6 / dt) as u64;
        dem.steps(n1);
        let (v1, t1, x1) = (dem.grains.vx[0], dem.time(), dem.grains.x[0]);
        dem.steps(n2);
        let (v2, t2, x2) = (dem.grains.vx[0], dem.time(), dem.grains.x[0]);
        let a = (v2 - v1) / (t2 - t1) / g0;
        if th.tan() < mu {
            println!(
                "θ = {theta_deg}°: sticks, v = {v2:.2e}, creep {:.2e} over {:.2} s, angle {:.2e}",
                x2 - x1,
                t2 - t1,
                dem.grains.angle[0]
            );
            assert!(
                v2.abs() < 1e-6 && (x2 - x1).abs() < 1e-6,
                "v = {v2}, dx = {}",
                x2 - x1
            );
        } else {
            let want = th.sin() - mu * th.cos();
            println!(
                "θ = {theta_deg}°: a/g = {a:.6} (want {want:.6}, rel. {:.1e}), angle {:.2e}",
                a / want - 1.0,
                dem.grains.angle[0]
            );
            assert!((a / want - 1.0).abs() < 5e-3);
        }
    }
}

/// Two polygons (a square and a rotated triangle) collide off-centre with friction and
/// damping, no gravity: linear momentum is conserved to round-off (the pair force is applied
/// ±, in one evaluation), angular momentum Σ(**x** × m**v** + Jω) too up to the integrator
/// (torques **r**_i × **F** about the same contact point).
#[test]
fn polygon_collision_conserves_momentum() {
    let mut g = Grains::new();
    let sq = g
        .polygons
        .add(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], "sq")
        .unwrap();
    let tri = g
        .polygons
        .add(&[[0.0, 0.0], [1.2, 0.1], [0.3, 0.9]], "tri")
        .unwrap();
    let a = g.push_polygon(0.0, 0.0, 0.0, sq, 1.0);
    let b = g.push_polygon(2.0, 0.35, 0.7, tri, 2.5);
    g.vx[a] = 1.0;
    g.vx[b] = -0.5;
    g.vy[b] = 0.1;
    g.omega[b] = 0.3;
    let c = frictional(1e4, 0.4, 0.6);
    let mut dem = Dem::new(g, vec![], DemParams::new(c, c, [0.0, 0.0])).unwrap();
    let mom = |d: &Dem| {
        let g = &d.grains;
        let p = g.momentum();
        let l: f64 = (0..g.len())
            .map(|i| g.mass[i] * (g.x[i] * g.vy[i] - g.y[i] * g.vx[i]) + g.inertia[i] * g.omega[i])
            .sum();
        [p[0], p[1], l]
    };
    let m0 = mom(&dem);
    let scale = 1.0 * 1.0 + dem.grains.mass[b] * 0.5;
    let (mut touched, mut worst_p, mut worst_l) = (0, 0.0f64, 0.0f64);
    for _ in 0..(3.0 / dem.dt()) as u64 {
        dem.step();
        touched += usize::from(dem.contact_count() > 0);
        let m = mom(&dem);
        worst_p = worst_p.max((m[0] - m0[0]).abs().max((m[1] - m0[1]).abs()) / scale);
        worst_l = worst_l.max((m[2] - m0[2]).abs() / scale);
    }
    println!(
        "polygon collision: {touched} steps in contact, |Δp|/p = {worst_p:.1e}, |ΔL|/(p·1) = {worst_l:.1e}, \
         final ω = {:.3}, {:.3}",
        dem.grains.omega[a], dem.grains.omega[b]
    );
    assert!(touched > 10 && dem.contact_count() == 0);
    assert!(
        dem.grains.omega[a].abs() > 1e-3,
        "off-centre impact must spin the square"
    );
    assert!(worst_p < 1e-13, "{worst_p}");
    assert!(worst_l < 1e-6, "{worst_l}");
}

/// Detection cost per step for 20 000 disks (the `in.gran2d.lmp` block: hexagonal, d uniform in
/// [0.8, 1.0], spacing 0.97 so some touch), rapier's collision pipeline (all pairs) against the
/// cell list. Indicative only (shared machine): run with
/// `cargo test --release --test dem_rapier detection_timing -- --ignored --nocapture`.
#[test]
#[ignore]
fn detection_timing() {
    use granflow::dem::neighbours::{Detector, PairList, WallList};
    use granflow::dem::packing::{hex_block, SizeDistribution};
    use std::time::Instant;
    let mut g = hex_block(
        0.5,
        0.5,
        200,
        100,
        0.97,
        [0.8, 1.0],
        SizeDistribution::Uniform,
        1.0,
        3,
    );
    let walls = vec![Wall::floor(0.0), Wall::left(0.0), Wall::right(200.0)];
    let skin = 0.2;
    let mut rng = SplitMix64::new(9);
    let mut jiggle = |g: &mut Grains| {
        for i in 0..g.len() {
            g.x[i] += 1e-3 * (rng.uniform() - 0.5);
            g.y[i] += 1e-3 * (rng.uniform() - 0.5);
        }
    };
    let steps = 20;
    let mut det = RapierDetector::new(Coverage::All, skin);
    let mut out = Vec::new();
    let t = Instant::now();
    det.detect(&g, &walls, &mut out);
    let first = t.elapsed().as_secs_f64();
    let mut t_r = 0.0;
    for _ in 0..steps {
        jiggle(&mut g);
        let t = Instant::now();
        det.detect(&g, &walls, &mut out);
        t_r += t.elapsed().as_secs_f64();
    }
    let touching = out.iter().filter(|c| c.delta > 0.0).count();
    let mut cl = Detector::new(skin);
    let (mut pl, mut wl) = (PairList::default(), WallList::default());
    cl.build(&g, &walls, &mut pl, &mut wl);
    let mut t_c = 0.0;
    for _ in 0..steps {
        jiggle(&mut g);
        let t = Instant::now();
        cl.build(&g, &walls, &mut pl, &mut wl);
        t_c += t.elapsed().as_secs_f64();
    }
    println!(
        "{} disks, {touching} touching points: rapier2d-f64 collision pipeline {:.2} ms/step \
         (first build {:.1} ms), cell list full rebuild {:.2} ms/step, {} threads",
        g.len(),
        1e3 * t_r / steps as f64,
        1e3 * first,
        1e3 * t_c / steps as f64,
        rayon::current_num_threads()
    );
}

/// Energy budget of a settling mixed pile (squares, triangles, pentagons and disks, random
/// angles) in a box with a polygon wall (a triangular bump), with damping, friction and rolling
/// resistance (disks): initial = current + dissipated within 1 % of the dissipated energy (the
/// gate of the disk budget, issue 3). Each channel is booked as the discrete work of its force
/// at the contact point, so the lever arm of polygon contacts enters the friction work.
#[test]
fn polygon_pile_energy_budget() {
    let mut g = Grains::new();
    let sq = g
        .polygons
        .add(&Polygons::regular(4, 0.35 * 2f64.sqrt(), 0.0), "sq")
        .unwrap();
    let tri = g
        .polygons
        .add(&Polygons::regular(3, 0.5, 0.0), "tri")
        .unwrap();
    let pent = g
        .polygons
        .add(&Polygons::regular(5, 0.45, 0.0), "pent")
        .unwrap();
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
        Wall::polygon(&[[2.0, -0.1], [4.0, -0.1], [3.0, 0.8]], "bump").unwrap(),
    ];
    let c = ContactParams {
        rolling_stiffness: 50.0,
        rolling_damping: 0.5,
        rolling_friction: 0.1,
        ..frictional(2e4, 0.5, 0.5)
    };
    let mut dem = Dem::new(g, walls, DemParams::new(c, c, [0.0, -9.81])).unwrap();
    let e0 = dem.energy();
    let steps = (3.0 / dem.dt()) as u64;
    let (mut max_contacts, mut poly_wall) = (0, false);
    for _ in 0..steps {
        dem.step();
        max_contacts = max_contacts.max(dem.contact_count());
        let sc = dem.shape_contacts().unwrap();
        poly_wall |= sc
            .found
            .iter()
            .any(|c| c.delta > 0.0 && c.wall() == Some(3));
    }
    let e = dem.energy();
    let d = e.dissipated();
    let err = (e.total() - e0.total()).abs() / d;
    println!(
        "mixed pile: {steps} steps, ≤ {max_contacts} contacts, D = {d:.4e} \
         (n {:.3e}, f {:.3e}, r {:.3e}), K_end/D = {:.1e}, |ΔE_tot|/D = {err:.2e}",
        e.dissipated_normal,
        e.dissipated_friction,
        e.dissipated_rolling,
        e.kinetic_total() / d
    );
    assert!(poly_wall, "no grain touched the polygon wall");
    assert!(d > 0.5 * (e0.total() - e.potential), "pile did not settle");
    assert!(err < 1e-2, "{err}");
}

/// A frictionless disk on a polygon wall (a wedge of slope θ = 30°), contacts through rapier:
/// a/g = sin θ within 0.5 % (Newton), no rotation (frictionless: ω = 0 to round-off).
#[test]
fn disk_on_polygon_wedge() {
    let th = 30f64.to_radians();
    let (l, r) = (20.0, 0.5);
    // Wedge with its top face from (0, l tan θ) down to (l, 0).
    let wedge = Wall::polygon(
        &[[0.0, -1.0], [l, -1.0], [l, 0.0], [0.0, l * th.tan()]],
        "wedge",
    )
    .unwrap();
    let mut g = Grains::new();
    let (nx, ny) = (th.sin(), th.cos());
    let x0 = 2.0;
    let y0 = (l - x0) * th.tan();
    let k_n = 1e5;
    let delta = 9.81 * ny / k_n; // static overlap m g cos θ/k_n, m = π r²
    let m = std::f64::consts::PI * r * r;
    g.push_disk(x0 + (r - delta * m) * nx, y0 + (r - delta * m) * ny, r, 1.0);
    let c = ContactParams {
        restitution: 0.3,
        ..ContactParams::elastic(k_n)
    };
    let mut dem = Dem::new(g, vec![wedge], DemParams::new(c, c, [0.0, -9.81])).unwrap();
    assert!(dem.shape_contacts().is_some());
    dem.steps((0.2 / dem.dt()) as u64);
    let (v1, t1) = (
        dem.grains.vx[0] * th.cos() - dem.grains.vy[0] * th.sin(),
        dem.time(),
    );
    dem.steps((0.5 / dem.dt()) as u64);
    let (v2, t2) = (
        dem.grains.vx[0] * th.cos() - dem.grains.vy[0] * th.sin(),
        dem.time(),
    );
    let a = (v2 - v1) / (t2 - t1) / 9.81;
    println!(
        "disk on polygon wedge: a/g = {a:.6} (sin θ = {:.6}), ω = {:.1e}, contacts {}",
        th.sin(),
        dem.grains.omega[0],
        dem.contact_count()
    );
    assert_eq!(dem.contact_count(), 1);
    assert!((a / th.sin() - 1.0).abs() < 5e-3);
    // The lever arm is the contact point (midpoint of the surface points), parallel to n up
    // to round-off, so ω stays at round-off level.
    assert!(dem.grains.omega[0].abs() < 1e-12);
}
