//! The periodic simple-shear cell (`granflow::dem::shear_cell`) and the μ(I) test built on it
//! (`granflow::scenario::dem::shear`).

use granflow::dem::contact::ContactParams;
use granflow::dem::shear_cell::Cell;
use granflow::scenario::dem::shear::{fit_mu_i, run_shear, ShearResult, ShearSpec};
use granflow::scenario::dem::DemScenario;
use granflow::scenario::ScenarioFile;

const K: f64 = 1.6e4;
const T: f64 = 1e-3;

fn contact(friction: f64, restitution: f64) -> ContactParams {
    ContactParams {
        k_t: K,
        friction,
        restitution,
        ..ContactParams::elastic(K)
    }
}

/// A compressed hexagonal crystal of equal disks (radius R, spacing a < 2R) filling the cell
/// through its periodic images: every disk has six contacts of force k(2R − a), so the
/// Love–Weber stress is isotropic, σ = √3 k (2R − a)/(a t) (per contact f a/2 n⊗n over the
/// disk's cell area √3a²/2, Σ n⊗n = 3I), with no shear stress, to round-off.
#[test]
fn compressed_hexagonal_crystal_has_the_analytic_stress() {
    let (r, a) = (0.5e-3, 0.99e-3);
    let (nx, ny) = (8, 10);
    let (mut x, mut y) = (Vec::new(), Vec::new());
    let h = a * 3f64.sqrt() / 2.0;
    for row in 0..ny {
        for col in 0..nx {
            x.push((col as f64 + 0.25 + 0.5 * (row % 2) as f64) * a);
            y.push((row as f64 + 0.5) * h);
        }
    }
    let n = x.len();
    let (lx, ly) = (nx as f64 * a, ny as f64 * h);
    let cell = Cell::new(
        x,
        y,
        vec![r; n],
        2500.0,
        T,
        lx,
        ly,
        &contact(0.5, 0.75),
        1e-7,
        1e-4,
    );
    let (s, z) = cell.stress();
    let want = 3f64.sqrt() * K * (2.0 * r - a) / (a * T);
    println!("σ = {s:?}, want {want}, z = {z}");
    assert!((z - 6.0).abs() < 1e-12, "every disk has six contacts");
    // Tension positive: the compressed lattice has σ_xx = σ_yy = −want.
    assert!((-s[(0, 0)] / want - 1.0).abs() < 1e-10 && (-s[(1, 1)] / want - 1.0).abs() < 1e-10);
    assert!(s[(0, 1)].abs() < 1e-10 * want && s[(1, 0)].abs() < 1e-10 * want);
}

/// Lees–Edwards images move with the shear: two disks meeting head-on (along y) through the
/// top and bottom boundaries of a sheared cell, with x velocities that differ by exactly the
/// image's γ̇ L_y, see no tangential motion. So their x velocities stay as they were (a wrong
/// image velocity would drive the friction with a slip of γ̇ L_y = 0.2 m/s), the y momentum
/// is conserved to round-off, and they rebound with the contact law's restitution (e = 0.75,
/// within 1 % at λ ≈ 0.1, docs/dev/dem-status.md).
#[test]
fn a_collision_through_the_sheared_boundary_sees_the_image_velocity() {
    let (r, l) = (0.5e-3, 20e-3);
    let gdot = 10.0;
    let x = vec![5e-3, 5e-3];
    let y = vec![l - 1.2 * r, 1.2 * r];
    let mut cell = Cell::new(
        x,
        y,
        vec![r; 2],
        2500.0,
        T,
        l,
        l,
        &contact(0.5, 0.75),
        5e-7,
        2e-4,
    );
    cell.set_shear_rate(gdot);
    let (u, jump) = (0.2, gdot * l);
    // Grain 0, near the top, moves up; grain 1, near the bottom, moves down, so grain 1's
    // image in the cell above (at x_1 + Δ, Δ = 0 now, moving at v_1 + γ̇ L_y) comes down
    // onto grain 0, with the same x velocity: a head-on impact, 0.4 R apart.
    cell.set_velocity(0, [0.3, u]);
    cell.set_velocity(1, [0.3 - jump, -u]);
    let py0: f64 = [0, 1].iter().map(|&i| cell.grain(i)[3]).sum::<f64>();
    for _ in 0..4000 {
        cell.step(0.0, 0.0);
    }
    let (g0, g1) = (cell.grain(0), cell.grain(1));
    println!("after: {g0:?} {g1:?}");
    assert!(
        (g0[2] - 0.3).abs() < 1e-12,
        "x velocity of grain 0: {}",
        g0[2]
    );
    assert!(
        (g1[2] - (0.3 - jump)).abs() < 1e-12,
        "x velocity of grain 1: {}",
        g1[2]
    );
    assert!((g0[3] + g1[3] - py0).abs() < 1e-15);
    let e = (g0[3] - g1[3]).abs() / (2.0 * u);
    assert!(g0[3] < 0.0 && (e / 0.75 - 1.0).abs() < 0.01, "rebound {e}");
}

fn collapse_material(inertial_number: f64) -> ShearResult {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse/dem_a2.toml");
    let s = DemScenario::from_file(&path).unwrap();
    let spec = ShearSpec::from_scenario(&s, 300, 1000.0, inertial_number, 4.0, None).unwrap();
    run_shear(&spec, &mut |_, _| {}).unwrap()
}

/// The collapse models' grains in steady simple shear at P = 1 kPa, 300 grains, γ = 4, at
/// I = 0.01 (≈ 5 s) and 0.1 (≈ 1 s). Gates (measured values in brackets):
/// * the barostat holds the normal stress: mean σ_yy within 5 % of P over the second half
///   (0.99–1.01 P at 1000 grains, 300 grains fluctuate more);
/// * the mean flow is the imposed one: profile slope within 10 % of γ̇ (0.92–1.07);
/// * at I = 0.01 the flow is near quasi-static: its sin φ lies within 2.5° of the biaxial
///   test's critical-state angle of the same material, 19.7° ± 0.9° (docs/collapse-study.md;
///   the 300-grain blocks scatter by ±0.05 in sin φ) [0.33–0.35];
/// * GDR MiDi (2004) and da Cruz et al. (2005): the friction rises and the solid fraction
///   falls with I — by more than 0.04 in sin φ [0.09–0.10] and 0.005 in solid fraction
///   [0.012–0.015] from I = 0.01 to 0.1.
#[test]
#[ignore = "heavy tier (≈ 20 s on 2 cores): cargo test -- --ignored"]
fn friction_rises_and_density_falls_with_the_inertial_number() {
    let (slow, fast) = std::thread::scope(|s| {
        let a = s.spawn(|| collapse_material(0.01));
        let b = s.spawn(|| collapse_material(0.1));
        (a.join().unwrap(), b.join().unwrap())
    });
    for r in [&slow, &fast] {
        println!("{}", r.done_line());
        assert!(
            (r.mean.sigma_yy / 1000.0 - 1.0).abs() < 0.05,
            "σ_yy {}",
            r.mean.sigma_yy
        );
        assert!(
            (r.profile_slope - 1.0).abs() < 0.1,
            "profile {}",
            r.profile_slope
        );
    }
    let (lo, hi) = (
        (19.7f64 - 2.5).to_radians().sin(),
        (19.7f64 + 2.5).to_radians().sin(),
    );
    assert!(
        slow.sin_phi > lo && slow.sin_phi < hi,
        "quasi-static sin φ {}",
        slow.sin_phi
    );
    assert!(fast.sin_phi > slow.sin_phi + 0.04);
    assert!(fast.mean.packing_fraction < slow.mean.packing_fraction - 0.005);
}

/// The fit recovers the law it was given: points of sin φ(I) = 0.34 + (0.5 − 0.34)/(0.2/I + 1)
/// at seven I from 10⁻³ to 1 give back the three parameters, I_0 to the grid's spacing (1.7 %
/// per step, 241 values over four decades).
#[test]
fn the_mu_i_fit_recovers_its_law() {
    let law = |i: f64| 0.34 + 0.16 * i / (i + 0.2);
    let pts: Vec<(f64, f64)> = [1e-3, 3e-3, 0.01, 0.03, 0.1, 0.3, 1.0]
        .iter()
        .map(|&i| (i, law(i)))
        .collect();
    let f = fit_mu_i(&pts).unwrap();
    println!("{f:?}");
    assert!((f.i_0 / 0.2 - 1.0).abs() < 0.02);
    assert!((f.sin_phi_s - 0.34).abs() < 2e-3 && (f.sin_phi_2 - 0.5).abs() < 5e-3);
    assert!(!f.i_0_at_grid_end);
    assert!(fit_mu_i(&pts[..2]).is_err());
}
