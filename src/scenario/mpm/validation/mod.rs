//! MPM validation cases (`granflow validate mpm-…`), each a list of [`Check`]s with the
//! reference and tolerance it is held to.
//!
//! * [`selfweight`]: elastic column under gravity (roller sides, fixed base), damped to rest:
//!   σ_yy = −ρ g (H − Y) at every point (Y its initial height), within 2 % of ρgH (issue 4).
//! * [`mc_biaxial`]: plane-strain biaxial compression of one Mohr–Coulomb material point at
//!   constant confining stress σ₃ (strain driven, lateral stress held by iteration): peak
//!   σ₁ = σ₃(1+sin φ)/(1−sin φ) + 2c cos φ/(1−sin φ) within 1 % for φ = 20°, 30°, 40° and
//!   c = 0, 10 kPa; with ψ = 0 no volume change during plastic flow (to round-off), and with
//!   ψ = 10° the dilation rate Δε_v/|Δε_axial| = 2 sin ψ/(1 − sin ψ). Then the same on the
//!   grid ([`biaxial_on_grid`]): a 4 × 8-cell sample of points between smooth rigid platens
//!   (roller base, moving-roller top), confined by pressure loads σ₃ on its lateral faces,
//!   loaded quasi-statically: peak ⟨σ₁⟩ within 1 %, ⟨σ_xx⟩ = −σ₃ within 0.5 %, with ψ = 0
//!   |Δε_v/Δε_axial| ≤ 2e-3 in plastic flow (0.5 % of the ψ = 10° rate, which is checked to
//!   2 %), energy budget closed to 0.5 % of the work of platen and face loads.
//! * [`cell_crossing`]: points crossing cells, standard MPM vs uGIMP (Bardenhagen & Kober 2004
//!   is the reason GIMP exists). Three set-ups:
//!   - pre-stressed translation (the set-up, gated; [`prestressed_translation`]): an
//!     elastic block with uniform stress held by pressure loads on its faces, moving rigidly
//!     across cells; exact: σ = σ₀, v = v₀. Standard MPM's RMS |σ − σ₀| is measured, uGIMP's
//!     must be round-off (≤ 1e-9 p) and ≥ 10× smaller.
//!   - gravity translation (reported): an elastic block resting on a frictionless
//!     floor under gravity, settled, then translated horizontally at 0.25 m/s across cells; the
//!     RMS deviation of σ_yy from its settled value. Both kinds stay within ~1 % of ρgH and
//!     GIMP is only ≈ 2× quieter: with a regular point lattice the crossing error needs a
//!     stress gradient *along* the motion, and here the gradient (gravity) is across it.
//!   - compaction (gated): a soft elastic column (E = 1e5 Pa, ν = 0, ρ = 1000, H = 1 m,
//!     h = 0.05 m, roller sides, fixed base) compacting ≈ 10 % under its own weight, so its
//!     points cross cells along the stress gradient, damped to rest; RMS of
//!     |σ_yy − (−ρg(H − Y))|/ρgH over points. uGIMP within 2 %, and at least 10× below
//!     standard MPM.
//! * [`conservation`]: a free Mohr–Coulomb block with a rotating, shearing velocity field and
//!   no gravity or walls: nodal mass = point mass to round-off, total momentum constant to
//!   round-off (Σ_i ∇N_ip = 0 and Σ_i N_ip = 1 make the internal forces sum to zero), for USF,
//!   USL and MUSL, and MUSL with 5 % PIC.
//! * [`sliding_block`] (`mpm-friction`): a block sliding on a Coulomb-frictional floor
//!   decelerates at μg (rigid-body reference, 3 %).

use crate::mpm::boundary::{Side, Wall, WallKind};
use crate::mpm::grid::Grid;
use crate::mpm::material::{LinearElastic, MaterialModel, MaterialState, MohrCoulomb};
use crate::mpm::points::Points;
use crate::mpm::shape::ShapeKind;
use crate::mpm::solver::{Mpm, MpmParams, Scheme, Traction, Transfer};
use crate::report::{Check, Fidelity};
use crate::Result;

mod conservation;
mod crossing;
mod stress;

pub use conservation::{conservation, rotating_disk, sliding_block, DiskSpin};
pub use crossing::{
    block_tractions, cell_crossing, compaction_error, crossing_noise, prestressed_translation,
    TranslationNoise,
};
pub use stress::{biaxial_on_grid, mc_biaxial, selfweight, GridBiaxial};

fn elastic(density: f64, e: f64, nu: f64) -> LinearElastic {
    LinearElastic {
        density,
        youngs_modulus: e,
        poisson_ratio: nu,
    }
}

/// A block [0, w] × [0, hgt] with `n`×`n` points per cell of size `h`, on a grid with `pad`
/// cells of margin on every side.
#[allow(clippy::too_many_arguments)]
fn block(
    w: f64,
    hgt: f64,
    h: f64,
    n: usize,
    pad: [usize; 4],
    walls: Vec<Wall>,
    material: MaterialModel,
    params: MpmParams,
) -> Result<Mpm> {
    let mut pts = Points::default();
    pts.fill_rect([0.0, 0.0], [w, hgt], h, n, material_density(&material));
    let nx = (w / h).round() as usize + pad[0] + pad[1];
    let ny = (hgt / h).round() as usize + pad[2] + pad[3];
    let grid = Grid::new(
        nx,
        ny,
        h,
        [-(pad[0] as f64) * h, -(pad[2] as f64) * h],
        walls,
    );
    Mpm::new(grid, pts, material, params)
}

/// A column's walls: rollers at x = 0 and x = `w`, a fixed base at y = 0.
fn column_walls(w: f64) -> Vec<Wall> {
    vec![
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
            kind: WallKind::Fixed,
        },
    ]
}

fn material_density(m: &MaterialModel) -> f64 {
    use crate::mpm::material::Material;
    m.density()
}

fn params(shape: ShapeKind, scheme: Scheme, g: f64, damping: f64) -> MpmParams {
    MpmParams {
        shape,
        scheme,
        gravity: [0.0, -g],
        courant: 0.5,
        dt: None,
        damping,
        pic_fraction: 0.0,
        resort_every: 20,
    }
}
