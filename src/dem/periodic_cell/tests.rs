use super::*;
use crate::dem::packing::SizeDistribution;

/// A glass-bead-like material per unit depth (d = 0.92–1.38 mm, ρ_s = 2500 kg/m³,
/// k_n/p₀ ≈ 5000 at p₀ = 2 kPa), as the collapse's grains (also the material of the
/// representative-volume tests in `crate::coupling::rve`).
pub(crate) fn glass_beads(grains: usize, phi: f64, seed: u64) -> Preparation {
    let contact = ContactParams {
        k_n: 1e7,
        k_t: 1e7,
        restitution: 0.75,
        gamma_n: 0.0,
        gamma_t: 0.0,
        friction: 0.5,
        rolling_stiffness: 0.0,
        rolling_damping: 0.0,
        rolling_friction: 0.0,
    };
    let m_min = 2500.0 * std::f64::consts::PI * 0.46e-3f64.powi(2);
    // Critical step of the tangential spring (the stiffer one, 3k_t on m/3), λ = 0.2.
    let dt = 0.2 * 2.0 * (m_min / (3.0 * contact.k_t)).sqrt();
    Preparation {
        grains,
        diameter: [0.92e-3, 1.38e-3],
        distribution: SizeDistribution::Uniform,
        density: 2500.0,
        thickness: 1.0,
        contact,
        dt,
        skin: 0.2e-3,
        pressure: 2e3,
        packing_fraction: phi,
        tolerance: 0.01,
        inertial_number: 1e-3,
        seed,
    }
}

fn preparation(grains: usize, phi: f64) -> Preparation {
    glass_beads(grains, phi, 7)
}

fn norm(t: &Tensor) -> f64 {
    t.norm()
}

/// A periodic chain of four touching disks along x, compressed affinely along x: by symmetry
/// the disks stay at rest, every contact carries f = k_n δ with δ = d − s (s the spacing) and
/// the stress is σ_xx = −k_n δ/L_y (per unit depth), σ_yy = σ_xy = 0. Frictionless and
/// undamped, the work fed in equals the stored energy 4 · ½k_n δ² (trapezoid error O(h)).
#[test]
fn a_periodic_chain_carries_the_spring_force() {
    let k = 1e3;
    let contact = ContactParams::elastic(k);
    let mut c = PeriodicCell::new(
        vec![0.5, 1.5, 2.5, 3.5],
        vec![1.0; 4],
        vec![0.5; 4],
        1.0,
        1.0,
        Tensor::new(4.0, 0.0, 0.0, 3.0),
        &contact,
        1e-3,
        0.1,
    );
    let grad = Tensor::new(-1e-2, 0.0, 0.0, 0.0);
    c.deform(&grad, 1000, 1e-3).unwrap();
    let s = c.cell()[(0, 0)] / 4.0;
    let delta = 1.0 - s;
    let sigma = c.stress();
    let expect = -k * delta / 3.0;
    assert!(
        (sigma[(0, 0)] - expect).abs() < 1e-9 * expect.abs(),
        "{sigma} vs {expect}"
    );
    assert!(sigma[(1, 1)].abs() < 1e-12 && sigma[(0, 1)].abs() < 1e-12);
    let e = c.energy();
    let stored = 4.0 * 0.5 * k * delta * delta;
    assert!((e.stored - stored).abs() < 1e-12 * stored);
    assert!(e.kinetic < 1e-20, "the chain moved: K = {}", e.kinetic);
    // Trapezoid rule on a geometric spacing: relative error ≈ h ε̇ = 1e-5.
    assert!(
        (e.work - stored).abs() < 1e-4 * stored,
        "W = {} vs U = {stored}",
        e.work
    );
    assert_eq!(c.coordination(), 2.0);
    let f = c.fabric();
    assert!((f[(0, 0)] - 1.0).abs() < 1e-12 && f[(1, 1)].abs() < 1e-12);
}

/// The preparation reaches p₀ within 1 % at rest, the packing fraction within its tolerance,
/// and refuses targets outside what the procedure reaches, saying the range.
#[test]
fn preparation_reaches_the_target_pressure_and_packing() {
    let c = &prepared();
    let p = -0.5 * c.stress().trace();
    assert!((p - 2e3).abs() < 0.01 * 2e3, "p = {p}");
    assert!(
        (c.packing_fraction() - 0.80).abs() <= 0.01,
        "φ = {}",
        c.packing_fraction()
    );
    assert!(c.coordination() > 2.5, "z = {}", c.coordination());
    let low = preparation(64, 0.5).run().unwrap_err();
    assert!(low.contains("below the loosest"), "{low}");
    let high = preparation(64, 0.95).run().unwrap_err();
    assert!(high.contains("above the densest"), "{high}");
}

/// One packing shared by the tests (the preparation is the slow part).
fn prepared() -> PeriodicCell {
    static CELL: std::sync::OnceLock<PeriodicCell> = std::sync::OnceLock::new();
    CELL.get_or_init(|| preparation(64, 0.80).run().unwrap().cell)
        .clone()
}

/// Compressed along y by 0.5 % at fixed width (uniaxial strain): a deviatoric stress, sliding
/// contacts, and the contacts kept (an isochoric path liquefies this loose packing).
fn sheared() -> PeriodicCell {
    let mut c = prepared();
    let dt = c.dt();
    let n = (0.005 / dt).ceil() as u64;
    c.deform(&Tensor::new(0.0, 0.0, 0.0, -1.0), n, dt).unwrap();
    c
}

/// A rigid rotation turns the stress to R σ Rᵀ and the fabric alike (both re-evaluated from
/// the rotated grains), and changes no scalar of the state (to round-off).
#[test]
fn a_rigid_rotation_turns_the_stress_and_nothing_else() {
    let mut c = sheared();
    c.forces(0.0, false);
    let (s0, f0, e0, z0, phi0) = (
        c.stress(),
        c.fabric(),
        c.energy(),
        c.coordination(),
        c.packing_fraction(),
    );
    assert!(
        (s0[(0, 0)] - s0[(1, 1)]).abs() > 0.05 * norm(&s0),
        "no deviator: {s0}"
    );
    let angle = 0.7;
    c.rotate(angle);
    c.forces(0.0, false);
    let (s, co) = angle.sin_cos();
    let r = Tensor::new(co, -s, s, co);
    let expect = r * s0 * r.transpose();
    assert!(
        norm(&(c.stress() - expect)) < 1e-10 * norm(&s0),
        "{} vs {expect}",
        c.stress()
    );
    assert!(norm(&(c.fabric() - r * f0 * r.transpose())) < 1e-12);
    assert_eq!(c.coordination(), z0);
    assert!((c.packing_fraction() - phi0).abs() < 1e-12);
    let e = c.energy();
    assert!((e.kinetic - e0.kinetic).abs() < 1e-12 * e0.stored);
    assert!(
        (e.stored - e0.stored).abs() < 1e-10 * e0.stored,
        "{e:?} {e0:?}"
    );
}

/// Energy balance over the uniaxial path of [`sheared`], with friction: work in = ΔK + ΔU + dissipated within
/// 1 % of the work (the integrator's own error, contact onsets, is far smaller).
#[test]
fn work_in_equals_stored_plus_dissipated() {
    let c0 = prepared();
    let e0 = c0.energy();
    let c = sheared();
    let e = c.energy();
    let work = e.work - e0.work;
    let balance =
        (e.stored - e0.stored) + (e.kinetic - e0.kinetic) + (e.dissipated - e0.dissipated);
    assert!(work > 0.0);
    assert!(
        (work - balance).abs() < 0.01 * work,
        "W = {work}, ΔE + D = {balance}"
    );
}

/// A simple shear far enough to skew the cell past its reduced basis: the basis is reduced
/// (the lattice of images is the same, so the stress is continuous), the energy still
/// balances, and the shear stress resists the shear.
#[test]
fn simple_shear_reduces_the_basis_and_keeps_the_balance() {
    let mut c = prepared();
    let e0 = c.energy();
    let dt = c.dt();
    let gdot = 2.0;
    // γ = 0.6: the cell's second side leans by 0.6 L_y, past ½ L_x, so at least one reduction.
    // A slight compression (3 % over the path) keeps the loose packing from liquefying.
    let n = (0.6 / (gdot * dt)).ceil() as u64;
    c.deform(&Tensor::new(0.0, gdot, 0.0, -0.05 * gdot), n, dt)
        .unwrap();
    let (a, b) = (c.cell().column(0), c.cell().column(1));
    assert!(a.dot(&b).abs() <= 0.5 * a.norm_squared().min(b.norm_squared()) + 1e-15);
    let e = c.energy();
    let work = e.work - e0.work;
    let balance =
        (e.stored - e0.stored) + (e.kinetic - e0.kinetic) + (e.dissipated - e0.dissipated);
    assert!(
        (work - balance).abs() < 0.01 * work,
        "W = {work}, ΔE + D = {balance}"
    );
    // Shear stress of the right sign (resists the shear): σ_xy > 0 in tension-positive terms.
    assert!(
        c.stress()[(0, 1)] > 0.0,
        "{} {}",
        c.stress(),
        c.coordination()
    );
}

/// Changing to another basis of the same lattice changes nothing the grains see.
#[test]
fn another_basis_of_the_same_lattice_gives_the_same_forces() {
    let mut c = sheared();
    c.forces(0.0, false);
    let s0 = c.stress();
    c.cell *= Tensor::new(1.0, 1.0, 0.0, 1.0);
    assert!(c.reduce());
    c.wrap();
    c.build();
    c.forces(0.0, false);
    assert!(norm(&(c.stress() - s0)) < 1e-10 * norm(&s0));
}

/// The servo holds only a compression: a zero pressure, a tension on one axis or a
/// non-finite target is refused at once, without a step.
#[test]
fn the_servo_refuses_what_it_cannot_hold() {
    let prep = preparation(32, 0.8);
    let mut cell = prep.dilute().unwrap();
    for target in [
        Target::Pressure(0.0),
        Target::Pressure(f64::NAN),
        Target::Normal([-100.0, 500.0]),
    ] {
        let err = prep.servo().hold(&mut cell, target).unwrap_err();
        assert!(err.contains("only under compression"), "{target:?}: {err}");
    }
    assert_eq!(cell.steps(), 0);
}

/// The glass beads with rolling resistance (k_r ≈ k_n r²/2.5, a damper well below critical,
/// μ_r = 0.1), so that re-tiling is checked on loaded rolling springs too.
fn with_rolling(c: &mut PeriodicCell) {
    c.set_law(&ContactParams {
        rolling_stiffness: 1.0,
        rolling_damping: 1e-6,
        rolling_friction: 0.1,
        ..preparation(1, 0.8).contact
    });
}

/// Re-tiling describes the same packing: re-evaluated from the mapped contact springs, every
/// grain and its copy feel the force and torque the grain felt before (to round-off), the
/// stress, fabric, coordination and packing fraction are unchanged, and the energies double.
/// A wrong sign of a turned-over rolling spring shows in the torques.
#[test]
fn a_retiled_cell_is_the_same_packing() {
    let mut c = prepared();
    with_rolling(&mut c);
    let dt = c.dt();
    // Shear with compression: skewed cell, sliding contacts, loaded rolling springs.
    c.deform(
        &Tensor::new(0.0, 1.0, 0.0, -0.5),
        (0.01 / dt).ceil() as u64,
        dt,
    )
    .unwrap();
    c.forces(0.0, false);
    assert!(c.state.iter().any(|s| s.touching() && s.m_r.abs() > 0.0));
    let (n, s0, fab0, z0, phi0, e0) = (
        c.len(),
        c.stress(),
        c.fabric(),
        c.coordination(),
        c.packing_fraction(),
        c.energy(),
    );
    let f0 = c.f.clone();
    c.retile();
    assert_eq!((c.len(), c.tiles()), (2 * n, 2));
    c.forces(0.0, false);
    assert!(
        norm(&(c.stress() - s0)) < 1e-10 * norm(&s0),
        "{} vs {s0}",
        c.stress()
    );
    assert!(norm(&(c.fabric() - fab0)) < 1e-12);
    assert_eq!(c.coordination(), z0);
    assert!((c.packing_fraction() - phi0).abs() < 1e-12);
    // The copies' positions carry a round-off ε|x| ≈ 1e-18 m beside overlaps f/k_n ≈ 1e-9 m:
    // forces agree to ≈ 1e-9 of the largest; a turned-over rolling moment that kept its sign
    // would be off by 2 m_r ≈ 1e-3 of the largest torque.
    for k in 0..3 {
        let scale = f0.iter().fold(0.0f64, |a, f| a.max(f[k].abs()));
        for (i, fi) in f0.iter().enumerate() {
            for copy in [i, i + n] {
                assert!(
                    (c.f[copy][k] - fi[k]).abs() < 1e-7 * scale,
                    "grain {i} (as {copy}), component {k}: {} vs {}",
                    c.f[copy][k],
                    fi[k]
                );
            }
        }
    }
    let e = c.energy();
    assert!((e.stored - 2.0 * e0.stored).abs() < 1e-10 * e0.stored);
    assert!((e.kinetic - 2.0 * e0.kinetic).abs() < 1e-10 * e0.kinetic.max(1e-300));
    assert_eq!(e.work, 2.0 * e0.work);
}

/// Stretched along x and squeezed along y at constant area until it is thinner than two
/// cut-offs across y, the cell re-tiles instead of stopping: twice the grains, the packing
/// fraction kept (the path is isochoric), and the energy still balances over the whole path
/// (work in = ΔK + ΔU + dissipated within 1 %, as for [`work_in_equals_stored_plus_dissipated`]:
/// re-tiling doubles every term at once).
#[test]
fn a_cell_stretched_thin_is_retiled_and_keeps_the_balance() {
    let mut c = prepared();
    with_rolling(&mut c);
    let (n, phi0) = (c.len(), c.packing_fraction());
    let dt = c.dt();
    let rate = 20.0;
    let mut strain = 0.0;
    while c.tiles() == 1 {
        assert!(strain < 2.0, "no re-tiling by a strain of {strain}");
        let e0 = c.energy();
        let k = (0.05 / (rate * dt)).ceil() as u64;
        c.deform(&Tensor::new(rate, 0.0, 0.0, -rate), k, dt)
            .unwrap();
        strain += k as f64 * rate * dt;
        if c.tiles() == 2 {
            let e = c.energy();
            let work = e.work - 2.0 * e0.work;
            let balance = (e.stored - 2.0 * e0.stored)
                + (e.kinetic - 2.0 * e0.kinetic)
                + (e.dissipated - 2.0 * e0.dissipated);
            assert!(
                (work - balance).abs() < 0.01 * work.abs(),
                "over the re-tiling: W = {work}, ΔE + D = {balance}"
            );
        }
    }
    assert_eq!(c.len(), 2 * n);
    // det(I + hL) = 1 − (h ε̇)² per step: the area drifts by h ε̇ × strain ≈ 1e-4.
    assert!((c.packing_fraction() - phi0).abs() < 1e-3 * phi0);
    let (a, b) = (c.cell().column(0), c.cell().column(1));
    let width = (c.area() / a.norm()).min(c.area() / b.norm());
    assert!(width > 2.0 * c.cutoff, "{width} m across after re-tiling");
}
