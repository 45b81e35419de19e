//! Fluid–grain coupling (issue 6): the validation cases at test fidelity, and the PSM step's
//! equivalence with the plain fluid step when no solid is present.

use granflow::coupling::CoupledFluid;
use granflow::lbm::{CollisionModel, Edge, Edges, FluidModel, Lattice, Lbm, MrtRates, Obstacles};
use granflow::units::Units;

use crate::common::assert_passes;

#[test]
#[ignore = "heavy tier (≈ 40 s on 2 cores): cargo test -- --ignored"]
fn psm_cylinder_array() {
    assert_passes("psm-cylinder-array");
}

#[test]
fn coupling_momentum() {
    assert_passes("coupling-momentum");
}

#[test]
fn settling_disk() {
    assert_passes("settling-disk");
}

/// Covered cells with B = 0 collide exactly as plain fluid nodes: a lattice whose every
/// other cell (bulk, next to walls and on Zou–He edges) is "covered" with B = 0 matches the
/// plain step bit for bit over odd and even steps, for BGK and MRT with LES and forcing.
fn zero_weight_matches_plain<T: granflow::lbm::Real>(model: CollisionModel, les: Option<f64>) {
    let (nx, ny) = (23, 17);
    let mut solid = vec![false; nx * ny];
    for y in 6..9 {
        for x in 9..12 {
            solid[y * nx + x] = true;
        }
    }
    let edges = Edges {
        left: Edge::Velocity(vec![[0.02, 0.0]; ny]),
        right: Edge::Pressure(1.0),
        bottom: Edge::Wall { velocity: [0.0; 2] },
        top: Edge::Wall {
            velocity: [0.01, 0.0],
        },
    };
    let make = || {
        let mut lat = Lattice::<T>::new(nx, ny, edges.clone(), solid.clone()).unwrap();
        lat.fill(|x, y| {
            (
                1.0 + 0.001 * (x as f64),
                0.01 * (y as f64 / ny as f64),
                0.003,
            )
        });
        CoupledFluid::new(Lbm::new(
            lat,
            FluidModel {
                collision: model,
                smagorinsky: les,
                body_force: [1e-5, -2e-5],
            },
            Obstacles::default(),
            Units::lattice(0.7),
        ))
    };
    let (mut plain, mut covered) = (make(), make());
    for c in (0..nx * ny).step_by(2) {
        covered.partial.push(c as u32, 0.0, [0.05, -0.05]);
    }
    for _ in 0..7 {
        plain.step();
        covered.step();
    }
    for c in 0..nx * ny {
        let (a, b) = (
            plain.lbm().lattice.populations(c),
            covered.lbm().lattice.populations(c),
        );
        assert_eq!(a, b, "cell {c}");
    }
    assert!(covered.exchange.iter().all(|e| *e == [0.0, 0.0]));
}

#[test]
fn zero_weight_is_the_plain_step() {
    zero_weight_matches_plain::<f64>(CollisionModel::Bgk, None);
    zero_weight_matches_plain::<f64>(CollisionModel::Mrt(MrtRates::standard(0.7)), Some(0.1));
    zero_weight_matches_plain::<f32>(CollisionModel::Bgk, Some(0.1));
}

#[test]
#[ignore = "heavy tier (≈ 10 s on 2 cores): cargo test -- --ignored"]
fn drafting_kissing_tumbling() {
    assert_passes("dkt");
}
