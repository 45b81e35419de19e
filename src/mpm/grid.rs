//! The uniform background grid: `nx` × `ny` cells of size h, (nx + 1)(ny + 1) nodes, stored
//! x-major (node (i, j) at i·(ny + 1) + j) so a band of node columns is one contiguous slice
//! (what the race-free parallel particle-to-grid transfer splits on).
//!
//! Periodic in x ([`Grid::with_period_x`]): the node columns [c₀, c₀ + n) are the period, and
//! every other column i is an image of column c₀ + (i − c₀) mod n. After each scatter the
//! images' sums are added into their column and copied back ([`Grid::fold`]), so a point near
//! one end of the period scatters into the nodes beyond it exactly as into the nodes at the
//! other end, and every image holds the same mass, momentum, force and hence velocity.

use super::boundary::{Side, Wall};
use crate::{Error, Result};

/// Whether node `n` of a grid with `nny` nodes per column and the period `period_x` is one of
/// the period's own nodes ([`Grid::owns`]).
#[inline(always)]
pub fn owned(period_x: Option<(usize, usize)>, nny: usize, n: usize) -> bool {
    period_x.is_none_or(|(c0, cells)| (c0..c0 + cells).contains(&(n / nny)))
}

/// Per-node accumulators of the particle-to-grid transfer: mass, momentum (x, y), force (x, y).
pub type NodeSums = [f64; 5];

/// The background grid.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Grid {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Cell size h (m).
    pub h: f64,
    /// Position of node (0, 0) (m).
    pub origin: [f64; 2],
    /// Mass, momentum, force per node.
    pub sums: Vec<NodeSums>,
    /// Velocity at the start of the step, p/m.
    pub vel: Vec<[f64; 2]>,
    /// Velocity after the momentum update (boundary conditions applied).
    pub vel_new: Vec<[f64; 2]>,
    /// MUSL: velocity re-mapped from the updated point momenta.
    pub vel_map: Vec<[f64; 2]>,
    /// Bit k set: wall k constrains this node.
    pub walls_mask: Vec<u8>,
    /// Bit k set: wall k acted on this node in the last momentum update (contact state of
    /// the step, see [`Wall::engages`]; re-applied to the MUSL re-mapped velocity).
    pub contact: Vec<u8>,
    /// The walls.
    pub walls: Vec<Wall>,
    /// Periodic in x: (first node column of the period c₀, columns in the period n).
    pub period_x: Option<(usize, usize)>,
}

impl Grid {
    /// A grid of `nx` × `ny` cells of size `h` with node (0, 0) at `origin`, and its walls.
    pub fn new(nx: usize, ny: usize, h: f64, origin: [f64; 2], walls: Vec<Wall>) -> Self {
        let n = (nx + 1) * (ny + 1);
        let mut walls_mask = vec![0u8; n];
        for i in 0..=nx {
            for j in 0..=ny {
                let x = [origin[0] + i as f64 * h, origin[1] + j as f64 * h];
                for (k, w) in walls.iter().enumerate() {
                    if w.holds(x, 1e-9 * h) {
                        walls_mask[i * (ny + 1) + j] |= 1 << k;
                    }
                }
            }
        }
        Grid {
            nx,
            ny,
            h,
            origin,
            sums: vec![[0.0; 5]; n],
            vel: vec![[0.0; 2]; n],
            vel_new: vec![[0.0; 2]; n],
            vel_map: vec![[0.0; 2]; n],
            walls_mask,
            contact: vec![0u8; n],
            walls,
            period_x: None,
        }
    }

    /// The same grid periodic in x over the node columns [first, first + cells) (x from
    /// origin + first·h to origin + (first + cells)·h). Refuses walls on the left or right and
    /// a period that leaves fewer than two columns of images beyond either end (a uGIMP stencil
    /// reaches h + l_p ≤ 1.5 h past a point).
    pub fn with_period_x(mut self, first: usize, cells: usize) -> Result<Self> {
        if cells == 0 || first < 2 || first + cells + 2 > self.nx {
            return Err(Error::Other(format!(
                "a period of {cells} cells from node column {first} needs two columns of images \
                 on each side of it in a grid of {} cells",
                self.nx
            )));
        }
        if self
            .walls
            .iter()
            .any(|w| matches!(w.side, Side::Left | Side::Right))
        {
            return Err(Error::Other(
                "a grid periodic in x has no left or right walls".into(),
            ));
        }
        self.period_x = Some((first, cells));
        Ok(self)
    }

    /// The x interval of the period (m), if periodic.
    pub fn period_bounds(&self) -> Option<[f64; 2]> {
        self.period_x.map(|(c0, n)| {
            let x0 = self.origin[0] + c0 as f64 * self.h;
            [x0, x0 + n as f64 * self.h]
        })
    }

    /// Whether node `n` is one of the period's own nodes (always, without a period): sums over
    /// the grid (mass, momentum, wall work) count these only.
    #[inline(always)]
    pub fn owns(&self, n: usize) -> bool {
        owned(self.period_x, self.nny(), n)
    }

    /// Periodic in x: add each image column's sums (components `which`) into its column of
    /// the period, then copy them back to the images. Nothing without a period.
    pub fn fold(&mut self, which: [bool; 5]) {
        let Some((c0, cells)) = self.period_x else {
            return;
        };
        let nny = self.nny();
        let image = |i: usize| c0 + (i + cells - c0 % cells) % cells;
        let ghosts = (0..c0).chain(c0 + cells..=self.nx);
        for i in ghosts.clone() {
            let c = image(i);
            for j in 0..nny {
                let (from, to) = (self.sums[i * nny + j], &mut self.sums[c * nny + j]);
                for k in (0..5).filter(|&k| which[k]) {
                    to[k] += from[k];
                }
            }
        }
        for i in ghosts {
            let c = image(i);
            for j in 0..nny {
                let to = self.sums[c * nny + j];
                let from = &mut self.sums[i * nny + j];
                for k in (0..5).filter(|&k| which[k]) {
                    from[k] = to[k];
                }
            }
        }
    }

    /// Nodes per column, ny + 1.
    #[inline(always)]
    pub fn nny(&self) -> usize {
        self.ny + 1
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.sums.len()
    }

    /// Position of node index `n`.
    pub fn node_pos(&self, n: usize) -> [f64; 2] {
        let (i, j) = (n / self.nny(), n % self.nny());
        [
            self.origin[0] + i as f64 * self.h,
            self.origin[1] + j as f64 * self.h,
        ]
    }

    /// As [`Grid::constrain`], also returning the walls that acted (bit k: wall k engaged, see
    /// [`Wall::engages`]; each wall sees the velocity the walls before it left).
    #[inline]
    pub fn constrain_tracked(
        walls: &[Wall],
        mask: u8,
        v: &mut [f64; 2],
    ) -> ([f64; 2], [f64; 2], u8) {
        let mut dn = [0.0; 2];
        let mut dt = [0.0; 2];
        let mut engaged = 0u8;
        if mask != 0 {
            for (k, w) in walls.iter().enumerate() {
                if mask & (1 << k) != 0 {
                    if w.engages(*v) {
                        engaged |= 1 << k;
                    }
                    let (a, b) = w.apply(v);
                    dn = [dn[0] + a[0], dn[1] + a[1]];
                    dt = [dt[0] + b[0], dt[1] + b[1]];
                }
            }
        }
        (dn, dt, engaged)
    }

    /// The walls of a node applied to a re-mapped velocity (MUSL), with the contact state
    /// `engaged` of the step's momentum update (see [`Wall::apply_engaged`]).
    #[inline]
    pub fn constrain_remap(walls: &[Wall], mask: u8, engaged: u8, v: &mut [f64; 2]) {
        if mask != 0 {
            for (k, w) in walls.iter().enumerate() {
                if mask & (1 << k) != 0 {
                    w.apply_engaged(v, engaged & (1 << k) != 0);
                }
            }
        }
    }

    /// Apply the walls of a node (bit mask `mask`) to its velocity `v`; returns the total
    /// velocity change (normal parts, tangential parts).
    #[inline]
    pub fn constrain(walls: &[Wall], mask: u8, v: &mut [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let (dn, dt, _) = Self::constrain_tracked(walls, mask, v);
        (dn, dt)
    }
}
