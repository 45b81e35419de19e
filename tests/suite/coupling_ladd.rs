//! Ladd's modified bounce-back coupling (issue 6, seed eq. 5.45–5.49): the validation cases
//! at test fidelity, and the selectable map in the same coupled driver as PSM.

use granflow::coupling::{Coupled, CoupledFluid, Grid, LaddMap};
use granflow::dem::{ContactParams, Dem, DemParams, Grains};
use granflow::lbm::{CollisionModel, Edges, FluidModel, Lattice, Lbm, MrtRates, Obstacles};
use granflow::units::Units;

use crate::common::assert_passes;

#[test]
#[ignore = "heavy tier (≈ 20 s on 2 cores): cargo test -- --ignored"]
fn ladd_cylinder_array() {
    assert_passes("ladd-cylinder-array");
}

#[test]
fn ladd_settling_disk() {
    assert_passes("ladd-settling-disk");
}

#[test]
fn ladd_momentum() {
    assert_passes("ladd-momentum");
}

#[test]
fn ladd_force_noise() {
    assert_passes("ladd-force-noise");
}

/// `Coupled<Lbm<f32>, Dem, LaddMap>` with MRT + LES: a grain moving and spinning through a
/// closed box slows down (the fluid takes its momentum), the run stays finite, and the
/// nodes it leaves are refilled (no node stays inside after it has gone).
#[test]
fn ladd_f32_mrt_les_in_the_driver() {
    let (nx, ny) = (48, 40);
    let lat = Lattice::<f32>::new(nx, ny, Edges::closed(), vec![false; nx * ny]).unwrap();
    let fluid = CoupledFluid::new(Lbm::new(
        lat,
        FluidModel {
            collision: CollisionModel::Mrt(MrtRates::standard(0.6)),
            smagorinsky: Some(0.1),
            body_force: [0.0; 2],
        },
        Obstacles::default(),
        Units::lattice(0.6),
    ));
    let mut g = Grains::new();
    g.push_disk(14.0, 20.0, 5.0, 2.0);
    g.vx[0] = 0.03;
    g.omega[0] = 0.002;
    let params = DemParams::new(
        ContactParams::elastic(50.0),
        ContactParams::elastic(50.0),
        [0.0; 2],
    );
    let dem = Dem::new(g, Vec::new(), params).unwrap();
    let grid = Grid {
        nx,
        ny,
        dx: 1.0,
        periodic: [false, false],
    };
    let mut c = Coupled::new(fluid, dem, LaddMap::new(grid, 1.0).unwrap());
    let x0 = c.solid.grains.x[0];
    for _ in 0..300 {
        c.step().unwrap();
    }
    granflow::lbm::Fluid::check_stable(&*c.fluid.lbm(), 0.3).unwrap();
    let gr = &c.solid.grains;
    println!(
        "x − x0 = {}, vx = {}, ω = {}",
        gr.x[0] - x0,
        gr.vx[0],
        gr.omega[0]
    );
    // Moved right by cells (nodes covered and uncovered), slowed down by the fluid but not
    // stopped or reversed.
    assert!(gr.x[0] > x0 + 2.0, "x = {}", gr.x[0]);
    assert!(gr.vx[0] > 0.0 && gr.vx[0] < 0.03, "vx = {}", gr.vx[0]);
    assert!(gr.omega[0].abs() < 0.002, "ω = {}", gr.omega[0]);
    // The inside nodes are those of the disk where it is now.
    let inside = c.map.inside();
    for &k in inside {
        let (x, y) = (
            (k as usize % nx) as f64 + 0.5,
            (k as usize / nx) as f64 + 0.5,
        );
        assert!((x - gr.x[0]).hypot(y - gr.y[0]) <= 5.0 + 0.5);
    }
    assert!(c.fluid.ladd.inside().len() == inside.len());
}
