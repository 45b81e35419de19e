//! The uniform background grid: `nx` × `ny` cells of size h, (nx + 1)(ny + 1) nodes, stored
//! x-major (node (i, j) at i·(ny + 1) + j) so a band of node columns is one contiguous slice
//! (what the race-free parallel particle-to-grid transfer splits on).

use super::boundary::Wall;

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
