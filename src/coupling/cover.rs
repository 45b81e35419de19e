//! Disks onto the lattice and forces back: the map between grains and partially saturated
//! cells (seed eq. 5.53–5.54).
//!
//! * **To the fluid.** Each grain is a disk of hydrodynamic radius r = κR (κ = r/R, 0.7–0.95 in
//!   the thesis, so that 2-D packings keep connected pore space; 1 for a single grain). The
//!   solid fraction of cell n from grain k is the exact overlap area
//!   ε_nk = |disk_k ∩ cell_n| / Δx² ([`super::overlap`]); ε_n = min(1, Σ_k ε_nk). The solid
//!   velocity at the cell centre x_n includes rotation, u_s,nk = v_k + ω_k × (x_n − x_k)
//!   (seed eq. 5.46), and where grains share a cell u_s,n = Σ_k ε_nk u_s,nk / Σ_k ε_nk.
//! * **To the grains.** The fluid returns the force F_n on the solid in each covered cell;
//!   grain k takes the share ε_nk / Σ_j ε_nj of it: F_k = Σ_n (ε_nk/ε_n) F_n (eq. 5.53) and
//!   T_k = Σ_n (x_n − x_k) × (ε_nk/ε_n) F_n (eq. 5.54).
//!
//! Periodic lattice edges wrap the cells a disk covers; on other edges cells outside the
//! lattice are dropped. Lattice cell (i, j) spans [iΔx, (i+1)Δx] × [jΔx, (j+1)Δx].

use rayon::prelude::*;

use super::overlap::disk_rect;
use crate::dem::scale::GrainView;
use crate::dem::ExternalLoads;
use crate::lbm::{CellForces, SolidCover};

/// Grains per parallel chunk of the rasterisation.
const GRAIN_CHUNK: usize = 64;

/// The lattice the disks are drawn on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Cell size Δx (m).
    pub dx: f64,
    /// Periodic along x, along y.
    pub periodic: [bool; 2],
}

/// One (cell, grain) overlap.
#[derive(Clone, Copy, Debug)]
struct Piece {
    cell: u32,
    grain: u32,
    eps: f64,
    /// x_n − x_k (m), before wrapping.
    r: [f64; 2],
}

/// Rasterises disks as partially saturated cells and sums cell forces per grain.
///
/// Per-cell sums live in dense arrays over the lattice (reset cell by cell after use), so a
/// step allocates nothing once the buffers have grown and needs no sort of the pieces.
#[derive(Clone, Debug)]
pub struct DiskCover {
    /// The lattice.
    pub grid: Grid,
    /// Hydrodynamic radius factor κ = r/R ∈ (0, 1].
    pub radius_factor: f64,
    /// Overlaps of each chunk of [`GRAIN_CHUNK`] grains.
    pieces: Vec<Vec<Piece>>,
    /// Σ_k ε_nk, Σ_k ε_nk u_x, Σ_k ε_nk u_y per cell (dense; zero outside the cover).
    acc: Vec<[f64; 3]>,
    /// Cover slot of each cell (dense; valid for covered cells).
    slot_of: Vec<u32>,
    /// Cells touched by the last cover.
    touched: Vec<u32>,
    /// Σ_k ε_nk per cover slot (unclipped).
    total: Vec<f64>,
    /// Grains seen by the last cover.
    grains: usize,
}

impl DiskCover {
    /// A map onto `grid` with hydrodynamic radius factor κ = r/R ∈ (0, 1].
    pub fn new(grid: Grid, radius_factor: f64) -> crate::Result<Self> {
        if !(radius_factor > 0.0 && radius_factor <= 1.0) {
            return Err(crate::Error::config(
                "coupling.radius_factor",
                format!("r/R must be in (0, 1], got {radius_factor}"),
            ));
        }
        let n = grid.nx * grid.ny;
        Ok(DiskCover {
            grid,
            radius_factor,
            pieces: Vec::new(),
            acc: vec![[0.0; 3]; n],
            slot_of: vec![u32::MAX; n],
            touched: Vec::new(),
            total: Vec::new(),
            grains: 0,
        })
    }

    /// Write the cells the grains cover into `out` (ascending, SI velocities).
    pub fn cover(&mut self, g: &GrainView, out: &mut SolidCover) {
        let Grid {
            nx,
            ny,
            dx,
            periodic,
        } = self.grid;
        self.touched.clear();
        self.grains = g.x.len();
        // Overlaps in parallel over chunks of grains (one reused buffer per chunk), then summed
        // per cell in one serial pass (grains may share cells).
        let chunks = g.x.len().div_ceil(GRAIN_CHUNK);
        if self.pieces.len() < chunks {
            self.pieces.resize_with(chunks, Vec::new);
        }
        let kappa = self.radius_factor;
        self.pieces[..chunks]
            .par_iter_mut()
            .enumerate()
            .for_each(|(ch, buf)| {
                buf.clear();
                let k1 = ((ch + 1) * GRAIN_CHUNK).min(g.x.len());
                for k in ch * GRAIN_CHUNK..k1 {
                    let r = kappa * g.radius[k] / dx;
                    let (cx, cy) = (g.x[k] / dx, g.y[k] / dx);
                    let (i0, i1) = ((cx - r).floor() as i64, (cx + r).floor() as i64);
                    let (j0, j1) = ((cy - r).floor() as i64, (cy + r).floor() as i64);
                    for j in j0..=j1 {
                        let Some(jj) = wrap(j, ny, periodic[1]) else {
                            continue;
                        };
                        for i in i0..=i1 {
                            let Some(ii) = wrap(i, nx, periodic[0]) else {
                                continue;
                            };
                            let (x, y) = (i as f64, j as f64);
                            let eps = disk_rect([cx, cy], r, x, x + 1.0, y, y + 1.0);
                            if eps > 0.0 {
                                buf.push(Piece {
                                    cell: (jj * nx + ii) as u32,
                                    grain: k as u32,
                                    eps,
                                    r: [(x + 0.5 - cx) * dx, (y + 0.5 - cy) * dx],
                                });
                            }
                        }
                    }
                }
            });
        for p in self.pieces[..chunks].iter().flatten() {
            let k = p.grain as usize;
            let w = g.omega[k];
            let a = &mut self.acc[p.cell as usize];
            if a[0] == 0.0 {
                self.touched.push(p.cell);
            }
            a[0] += p.eps;
            a[1] += p.eps * (g.vx[k] - w * p.r[1]);
            a[2] += p.eps * (g.vy[k] + w * p.r[0]);
        }
        out.cells.clear();
        out.eps.clear();
        out.ux.clear();
        out.uy.clear();
        self.total.clear();
        // Ascending order: sort the touched cells, or scan the lattice when they are many.
        if self.touched.len() * 16 > self.acc.len() {
            self.touched.clear();
            for (c, a) in self.acc.iter().enumerate() {
                if a[0] > 0.0 {
                    self.touched.push(c as u32);
                }
            }
        } else {
            self.touched.sort_unstable();
        }
        for &c in &self.touched {
            let a = &mut self.acc[c as usize];
            self.slot_of[c as usize] = out.cells.len() as u32;
            out.cells.push(c);
            out.eps.push(a[0].min(1.0));
            out.ux.push(a[1] / a[0]);
            out.uy.push(a[2] / a[0]);
            self.total.push(a[0]);
            *a = [0.0; 3];
        }
    }

    /// Number of grains the last [`DiskCover::cover`] saw.
    pub fn grains(&self) -> usize {
        self.grains
    }

    /// Sum the cell forces of the last [`DiskCover::cover`] per grain (seed eq. 5.53–5.54)
    /// into `loads` (N/m and N·m/m) for `n` grains.
    pub fn loads(&self, forces: &CellForces, n: usize, loads: &mut ExternalLoads) {
        for v in [&mut loads.fx, &mut loads.fy, &mut loads.torque] {
            v.clear();
            v.resize(n, 0.0);
        }
        if forces.fx.len() != self.total.len() {
            // The fluid has not stepped with this cover yet: no force.
            return;
        }
        let chunks = self.grains.div_ceil(GRAIN_CHUNK);
        for p in self.pieces[..chunks].iter().flatten() {
            let s = self.slot_of[p.cell as usize] as usize;
            let share = p.eps / self.total[s];
            let (fx, fy) = (share * forces.fx[s], share * forces.fy[s]);
            let k = p.grain as usize;
            loads.fx[k] += fx;
            loads.fy[k] += fy;
            loads.torque[k] += p.r[0] * fy - p.r[1] * fx;
        }
    }
}

/// Cell index `i` on an axis of `n` cells: wrapped when periodic, `None` outside otherwise.
fn wrap(i: i64, n: usize, periodic: bool) -> Option<usize> {
    if periodic {
        Some(i.rem_euclid(n as i64) as usize)
    } else if i >= 0 && (i as usize) < n {
        Some(i as usize)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn one(x: f64, y: f64, r: f64, v: [f64; 2], w: f64) -> GrainView {
        GrainView {
            x: vec![x],
            y: vec![y],
            vx: vec![v[0]],
            vy: vec![v[1]],
            omega: vec![w],
            radius: vec![r],
        }
    }

    #[test]
    fn cover_area_radius_factor_and_wrap() {
        let grid = Grid {
            nx: 20,
            ny: 16,
            dx: 0.5,
            periodic: [true, true],
        };
        // A disk across the corner of a periodic box keeps its whole area.
        let g = one(0.1, 7.9, 2.3, [0.0; 2], 0.0);
        for kappa in [1.0, 0.8] {
            let mut map = DiskCover::new(grid, kappa).unwrap();
            let mut c = SolidCover::default();
            map.cover(&g, &mut c);
            assert!(c.cells.windows(2).all(|w| w[0] < w[1]));
            let area: f64 = c.eps.iter().sum::<f64>() * grid.dx * grid.dx;
            let exact = PI * (kappa * 2.3f64).powi(2);
            assert!(((area - exact) / exact).abs() < 1e-12, "{area} vs {exact}");
        }
        assert!(DiskCover::new(grid, 0.0).is_err() && DiskCover::new(grid, 1.1).is_err());
    }

    /// Solid velocity includes rotation; a uniform cell force gives F = Σ F_n and, on a
    /// symmetric cover, no torque; a tangential force field gives the torque Σ r × F.
    #[test]
    fn velocity_force_and_torque() {
        let grid = Grid {
            nx: 32,
            ny: 32,
            dx: 1.0,
            periodic: [false, false],
        };
        let (xc, yc) = (16.0, 16.0);
        let g = one(xc, yc, 6.0, [0.1, -0.2], 0.05);
        let mut map = DiskCover::new(grid, 1.0).unwrap();
        let mut c = SolidCover::default();
        map.cover(&g, &mut c);
        for k in 0..c.cells.len() {
            let (x, y) = (
                (c.cells[k] % 32) as f64 + 0.5,
                (c.cells[k] / 32) as f64 + 0.5,
            );
            assert!((c.ux[k] - (0.1 - 0.05 * (y - yc))).abs() < 1e-15);
            assert!((c.uy[k] - (-0.2 + 0.05 * (x - xc))).abs() < 1e-15);
        }
        let n = c.cells.len();
        let f = CellForces {
            fx: c.eps.clone(),
            fy: vec![0.0; n],
            ..Default::default()
        };
        let mut l = ExternalLoads::default();
        map.loads(&f, 1, &mut l);
        assert!((l.fx[0] - PI * 36.0).abs() < 1e-10);
        assert!(l.torque[0].abs() < 1e-10);
        // F_n = ε_n ẑ × (x_n − x_c): torque Σ ε |r|².
        let (mut fx, mut fy, mut t) = (vec![0.0; n], vec![0.0; n], 0.0);
        for k in 0..n {
            let (x, y) = (
                (c.cells[k] % 32) as f64 + 0.5 - xc,
                (c.cells[k] / 32) as f64 + 0.5 - yc,
            );
            fx[k] = -c.eps[k] * y;
            fy[k] = c.eps[k] * x;
            t += c.eps[k] * (x * x + y * y);
        }
        map.loads(
            &CellForces {
                fx,
                fy,
                ..Default::default()
            },
            1,
            &mut l,
        );
        assert!((l.torque[0] - t).abs() < 1e-9 * t);
        assert!(l.fx[0].abs() < 1e-9 && l.fy[0].abs() < 1e-9);
    }

    /// Two overlapping grains share a cell by their fractions; ε is clipped at 1.
    #[test]
    fn shared_cells() {
        let grid = Grid {
            nx: 16,
            ny: 16,
            dx: 1.0,
            periodic: [false, false],
        };
        let g = GrainView {
            x: vec![6.0, 9.0],
            y: vec![8.0, 8.0],
            vx: vec![1.0, -1.0],
            vy: vec![0.0, 0.0],
            omega: vec![0.0, 0.0],
            radius: vec![2.0, 2.0],
        };
        let mut map = DiskCover::new(grid, 1.0).unwrap();
        let mut c = SolidCover::default();
        map.cover(&g, &mut c);
        assert!(c.eps.iter().all(|&e| e > 0.0 && e <= 1.0));
        // Cell x = 7, y = 7 or 8 is the middle: covered by both, symmetric, u_s = 0.
        let k = c.cells.iter().position(|&q| q == 8 * 16 + 7).unwrap();
        assert!(c.ux[k].abs() < 1e-15);
        let n = c.cells.len();
        let mut l = ExternalLoads::default();
        map.loads(
            &CellForces {
                fx: vec![1.0; n],
                fy: vec![0.0; n],
                ..Default::default()
            },
            2,
            &mut l,
        );
        assert!((l.fx[0] + l.fx[1] - n as f64).abs() < 1e-12);
        assert!((l.fx[0] - l.fx[1]).abs() < 1e-12);
    }
}
