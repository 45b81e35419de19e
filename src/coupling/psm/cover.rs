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

use super::overlap::DiskCells;
use crate::coupling::fluid::{CellForces, SolidCover};
use crate::dem::scale::GrainView;
use crate::dem::ExternalLoads;

/// Grains per parallel chunk of the rasterisation.
const GRAIN_CHUNK: usize = 64;
/// Lattice rows per band of the parallel per-cell pass.
const BAND_ROWS: usize = 8;
/// Bands per group: a group sums its bands one after another in one accumulator, which so
/// stays in cache (a dense accumulator over the whole lattice was re-read from memory every
/// step).
const GROUP_BANDS: usize = 8;

/// The lattice the disks are drawn on.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
struct Piece {
    cell: u32,
    grain: u32,
    eps: f64,
    /// x_n − x_k (m), before wrapping.
    r: [f64; 2],
}

/// Rasterises disks as partially saturated cells and sums cell forces per grain.
///
/// Per-cell sums are accumulated in one band-sized array per group of [`GROUP_BANDS`] bands
/// (cleared as the band's covered cells are read out), so a step allocates nothing once the
/// buffers have grown and needs no sort of the pieces.
///
/// Everything runs in parallel without locks: the overlaps are computed per chunk of
/// [`GRAIN_CHUNK`] grains and filed by band of [`BAND_ROWS`] lattice rows
/// (`pieces[chunk × bands + band]`); the per-cell sums then run per group of bands (a band
/// owns its cells), and the force sums per chunk (a chunk owns its grains). Within a cell the
/// pieces are summed in grain order, and within a grain in band order, whatever the thread
/// count.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct DiskCover {
    /// The lattice.
    pub grid: Grid,
    /// Hydrodynamic radius factor κ = r/R ∈ (0, 1].
    pub radius_factor: f64,
    /// Overlaps of each chunk of [`GRAIN_CHUNK`] grains in each band of [`BAND_ROWS`] rows,
    /// at `chunk × bands + band`.
    pieces: Vec<Vec<Piece>>,
    /// The cells each band covered in the last cover, with their sums.
    bands: Vec<BandCells>,
    /// Per group of [`GROUP_BANDS`] bands, Σ_k ε_nk, Σ_k ε_nk u_x, Σ_k ε_nk u_y over the cells
    /// of one band (zero between uses).
    acc: Vec<Vec<[f64; 3]>>,
    /// Cover slot of each cell (dense; valid for covered cells).
    slot_of: Vec<u32>,
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
        let bands = grid.ny.div_ceil(BAND_ROWS);
        Ok(DiskCover {
            grid,
            radius_factor,
            pieces: Vec::new(),
            bands: vec![BandCells::default(); bands],
            acc: vec![vec![[0.0; 3]; BAND_ROWS * grid.nx]; bands.div_ceil(GROUP_BANDS)],
            slot_of: vec![u32::MAX; n],
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
        self.grains = g.x.len();
        let chunks = g.x.len().div_ceil(GRAIN_CHUNK);
        let bands = self.bands.len();
        if self.pieces.len() < chunks * bands {
            self.pieces.resize_with(chunks * bands, Vec::new);
        }
        // Overlaps in parallel over chunks of grains, filed by band.
        let kappa = self.radius_factor;
        self.pieces[..chunks * bands]
            .par_chunks_mut(bands)
            .enumerate()
            .for_each(|(ch, bufs)| {
                bufs.iter_mut().for_each(Vec::clear);
                let mut disk = DiskCells::default();
                let k1 = ((ch + 1) * GRAIN_CHUNK).min(g.x.len());
                for k in ch * GRAIN_CHUNK..k1 {
                    let r = kappa * g.radius[k] / dx;
                    let (cx, cy) = (g.x[k] / dx, g.y[k] / dx);
                    let (i0, i1) = ((cx - r).floor() as i64, (cx + r).floor() as i64);
                    let (j0, j1) = ((cy - r).floor() as i64, (cy + r).floor() as i64);
                    disk.set([cx, cy], r, [i0, i1], [j0, j1]);
                    for j in j0..=j1 {
                        let Some(jj) = wrap(j, ny, periodic[1]) else {
                            continue;
                        };
                        let buf = &mut bufs[jj / BAND_ROWS];
                        for i in i0..=i1 {
                            let Some(ii) = wrap(i, nx, periodic[0]) else {
                                continue;
                            };
                            let (x, y) = (i as f64, j as f64);
                            let eps = disk.area(i, j);
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
        // Per band: sum the pieces per cell (grains may share cells), then list the covered
        // cells in ascending order by a scan of the band, clearing the accumulator.
        let band_len = BAND_ROWS * nx;
        let pieces = &self.pieces;
        self.bands
            .par_chunks_mut(GROUP_BANDS)
            .zip(self.acc.par_iter_mut())
            .enumerate()
            .for_each(|(group, (out, acc))| {
                for (i, band) in out.iter_mut().enumerate() {
                    band.clear();
                    let b = group * GROUP_BANDS + i;
                    if (0..chunks).all(|ch| pieces[ch * bands + b].is_empty()) {
                        continue;
                    }
                    let c0 = b * band_len;
                    for ch in 0..chunks {
                        for p in &pieces[ch * bands + b] {
                            let k = p.grain as usize;
                            let w = g.omega[k];
                            let a = &mut acc[p.cell as usize - c0];
                            a[0] += p.eps;
                            a[1] += p.eps * (g.vx[k] - w * p.r[1]);
                            a[2] += p.eps * (g.vy[k] + w * p.r[0]);
                        }
                    }
                    let len = band_len.min(nx * ny - c0);
                    for (c, a) in acc[..len].iter_mut().enumerate() {
                        if a[0] > 0.0 {
                            band.push((c0 + c) as u32, *a);
                            *a = [0.0; 3];
                        }
                    }
                }
            });
        // Output: each band fills its slice of the cover (offsets from the band counts).
        let total: usize = self.bands.iter().map(|b| b.cells.len()).sum();
        out.cells.resize(total, 0);
        out.eps.resize(total, 0.0);
        out.ux.resize(total, 0.0);
        out.uy.resize(total, 0.0);
        self.total.resize(total, 0.0);
        let mut slices = Vec::with_capacity(bands);
        let (mut cells, mut eps, mut ux, mut uy, mut tot) = (
            &mut out.cells[..],
            &mut out.eps[..],
            &mut out.ux[..],
            &mut out.uy[..],
            &mut self.total[..],
        );
        let mut offset = 0;
        for band in &self.bands {
            let n = band.cells.len();
            let (c, rc) = std::mem::take(&mut cells).split_at_mut(n);
            let (e, re) = std::mem::take(&mut eps).split_at_mut(n);
            let (x, rx) = std::mem::take(&mut ux).split_at_mut(n);
            let (y, ry) = std::mem::take(&mut uy).split_at_mut(n);
            let (s, rs) = std::mem::take(&mut tot).split_at_mut(n);
            slices.push((offset, c, e, x, y, s));
            (cells, eps, ux, uy, tot) = (rc, re, rx, ry, rs);
            offset += n;
        }
        self.slot_of
            .par_chunks_mut(band_len)
            .zip(self.bands.par_iter())
            .zip(slices.into_par_iter())
            .enumerate()
            .for_each(|(b, ((slot_of, band), (off, c, e, x, y, s)))| {
                let c0 = b * band_len;
                c.copy_from_slice(&band.cells);
                x.copy_from_slice(&band.ux);
                y.copy_from_slice(&band.uy);
                s.copy_from_slice(&band.total);
                for (k, (&cell, &t)) in band.cells.iter().zip(&band.total).enumerate() {
                    slot_of[cell as usize - c0] = (off + k) as u32;
                    e[k] = t.min(1.0);
                }
            });
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
        // Per chunk of grains (a chunk owns its grains and their pieces).
        let bands = self.bands.len();
        let chunks = self.grains.div_ceil(GRAIN_CHUNK);
        let (slot_of, total) = (&self.slot_of, &self.total);
        self.pieces[..chunks * bands]
            .par_chunks(bands)
            .zip(loads.fx.par_chunks_mut(GRAIN_CHUNK))
            .zip(loads.fy.par_chunks_mut(GRAIN_CHUNK))
            .zip(loads.torque.par_chunks_mut(GRAIN_CHUNK))
            .enumerate()
            .for_each(|(ch, (((bufs, lx), ly), lt))| {
                let k0 = ch * GRAIN_CHUNK;
                for p in bufs.iter().flatten() {
                    let s = slot_of[p.cell as usize] as usize;
                    let share = p.eps / total[s];
                    let (fx, fy) = (share * forces.fx[s], share * forces.fy[s]);
                    let k = p.grain as usize - k0;
                    lx[k] += fx;
                    ly[k] += fy;
                    lt[k] += p.r[0] * fy - p.r[1] * fx;
                }
            });
    }
}

/// The covered cells of one band, ascending: Σ_k ε_nk and the solid velocity
/// Σ_k ε_nk u_nk / Σ_k ε_nk.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
struct BandCells {
    cells: Vec<u32>,
    total: Vec<f64>,
    ux: Vec<f64>,
    uy: Vec<f64>,
}

impl BandCells {
    fn clear(&mut self) {
        self.cells.clear();
        self.total.clear();
        self.ux.clear();
        self.uy.clear();
    }

    /// Add cell `cell` from its sums [Σ ε, Σ ε u_x, Σ ε u_y].
    fn push(&mut self, cell: u32, a: [f64; 3]) {
        self.cells.push(cell);
        self.total.push(a[0]);
        self.ux.push(a[1] / a[0]);
        self.uy.push(a[2] / a[0]);
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
