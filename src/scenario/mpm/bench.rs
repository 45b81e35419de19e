//! `granflow bench mpm`: throughput of the MPM step on a collapsing column, in material
//! point-steps per second (the unit of Taichi's MLS-MPM figures).
//!
//! Set-up: the column-collapse material (E = 1.98 MPa, ν = 0.23, φ = 22.2°, ψ = 0,
//! ρ = 1925 kg/m³), cell h = 2 mm, 2 × 2 points per cell, a column of w × 2w cells with
//! 8 w² ≈ N points, in a box 4w + 4 cells long with frictional floor and back wall (μ = 0.466);
//! MUSL, Courant 0.5. After 20 warm-up steps, `repeats` runs of `steps` steps are timed; the
//! median is reported. The column collapses while it is timed, so the points move across cells
//! as in a real run.

use std::time::Instant;

use serde::Serialize;

use crate::mpm::boundary::{Side, Wall, WallKind};
use crate::mpm::grid::Grid;
use crate::mpm::material::{LinearElastic, MaterialModel, MohrCoulomb};
use crate::mpm::points::Points;
use crate::mpm::shape::ShapeKind;
use crate::mpm::solver::{Mpm, MpmParams, Scheme};
use crate::{Error, Result};

/// Result of `granflow bench mpm`.
#[derive(Clone, Debug, Serialize)]
pub struct MpmBench {
    /// Material point-steps per second (median of the repeats).
    pub point_steps_per_s: f64,
    /// Number of material points.
    pub points: usize,
    /// Grid cells (x, y).
    pub cells: [usize; 2],
    /// Steps per repeat.
    pub steps: u64,
    /// Threads used.
    pub threads: usize,
    /// `"gimp"` or `"standard"`.
    pub shape: String,
    /// `"musl"`.
    pub scheme: String,
    /// Point-steps per second of every repeat.
    pub samples: Vec<f64>,
}

/// The benchmark column with about `n` points.
pub fn column(n: usize, shape: ShapeKind) -> Result<Mpm> {
    let h = 2e-3;
    let w = ((n as f64 / 8.0).sqrt().round() as usize).max(2);
    let (nx, ny) = (4 * w + 4, 2 * w + 6);
    let friction = WallKind::Friction { mu: 0.466 };
    let walls = vec![
        Wall {
            side: Side::Bottom,
            position: 0.0,
            kind: friction,
        },
        Wall {
            side: Side::Left,
            position: 0.0,
            kind: friction,
        },
        Wall {
            side: Side::Right,
            position: (nx - 4) as f64 * h,
            kind: friction,
        },
    ];
    let grid = Grid::new(nx, ny, h, [-2.0 * h, -2.0 * h], walls);
    let elastic = LinearElastic {
        density: 1925.0,
        youngs_modulus: 1.98e6,
        poisson_ratio: 0.23,
    };
    let material = MaterialModel::MohrCoulomb(MohrCoulomb::new(
        elastic,
        22.2f64.to_radians(),
        0.0,
        0.0,
        0.0,
    ));
    let mut pts = Points::default();
    pts.fill_rect([0.0, 0.0], [w as f64 * h, 2.0 * w as f64 * h], h, 2, 1925.0);
    let params = MpmParams {
        shape,
        scheme: Scheme::Musl,
        gravity: [0.0, -9.81],
        courant: 0.5,
        dt: None,
        damping: 0.0,
        pic_fraction: 0.0,
        resort_every: 20,
    };
    Mpm::new(grid, pts, material, params)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Run the benchmark on `threads` threads (0: rayon's default).
pub fn mpm(
    points: usize,
    steps: u64,
    threads: usize,
    repeats: usize,
    shape: ShapeKind,
) -> Result<MpmBench> {
    if points < 32 || steps == 0 || repeats == 0 {
        return Err(Error::Other(
            "bench mpm: need points ≥ 32 and steps, repeats ≥ 1".into(),
        ));
    }
    crate::exec::on_threads(threads, || {
        let mut mpm = column(points, shape)?;
        mpm.steps(20)?;
        let n = mpm.points.len();
        let mut samples = Vec::new();
        for _ in 0..repeats {
            let t0 = Instant::now();
            mpm.steps(steps)?;
            samples.push(n as f64 * steps as f64 / t0.elapsed().as_secs_f64());
        }
        let all = samples.clone();
        Ok(MpmBench {
            point_steps_per_s: median(&mut samples),
            points: n,
            cells: [mpm.grid.nx, mpm.grid.ny],
            steps,
            threads: rayon::current_num_threads(),
            shape: format!("{shape:?}").to_lowercase(),
            scheme: "musl".into(),
            samples: all,
        })
    })
}
