//! Grains onto boundary links and link forces back: the map for Ladd's modified bounce-back
//! (seed eq. 5.45–5.49), the alternative to [`crate::coupling::psm::DiskCover`]'s partially saturated cells.
//!
//! * **To the fluid.** A node is inside grain k when its centre lies in the disk of
//!   hydrodynamic radius r = κR (κ = r/R); where disks overlap the node goes to the grain
//!   with the lower index. Every link from an outside node x_f to an inside node
//!   x_b = x_f + e_i is a boundary link with the wall velocity of its grain at the link
//!   mid-point, u_b = v + ω × (x_f + e_i/2 − X) (eq. 5.46). The map remembers last step's
//!   inside nodes, so it also lists the nodes a grain newly covers and those it uncovers; an
//!   uncovered node is refilled by the fluid at equilibrium with the velocity its grain has
//!   there, v + ω × (x_n − X), and the mean density of its outside neighbours
//!   ([`super::links`]).
//! * **To the grains.** The fluid returns the force across each link; grain k takes
//!   F_k = Σ F_link and T_k = Σ (x_f + e_i/2 − X) × F_link over its links (eq. 5.47–5.49).
//!   With `impulses` (the default) the grain also takes the momentum of the nodes it covered
//!   and gives the momentum of the nodes it uncovered (Aidun, Lu & Ding 1998), with the arm
//!   x_n − X: fluid + grain momentum is then conserved to round-off. Without them the map is
//!   seed eq. 5.45–5.49 alone, and covering/uncovering creates or destroys momentum.
//!
//! Periodic lattice edges wrap (arms by the minimum image); on other edges nodes outside the
//! lattice are dropped. Node (i, j) has its centre at ((i + ½)Δx, (j + ½)Δx).

use crate::coupling::driver::Exchange;
use crate::coupling::fluid::{CellForces, SolidCover};
use crate::coupling::psm::Grid;
use crate::dem::scale::GrainView;
use crate::dem::ExternalLoads;
use crate::lbm::d2q9::{CX, CY, Q};
use crate::scale::Scale;

/// No grain.
const NONE: u32 = u32::MAX;

/// Maps disks onto Ladd boundary links and sums link forces per grain.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct LaddMap {
    /// The lattice.
    pub grid: Grid,
    /// Hydrodynamic radius factor κ = r/R ∈ (0, 1].
    pub radius_factor: f64,
    /// Hand covered / uncovered nodes' momentum to the grains (Aidun, Lu & Ding 1998).
    pub impulses: bool,
    /// Grain owning each node now (dense; `NONE` outside).
    owner: Vec<u32>,
    /// … and at the previous cover.
    owner_prev: Vec<u32>,
    /// Inside nodes now and at the previous cover, ascending.
    inside: Vec<u32>,
    inside_prev: Vec<u32>,
    /// Grain and torque arm (m) of each link, covered node and uncovered node.
    link_grain: Vec<u32>,
    link_arm: Vec<[f64; 2]>,
    covered_grain: Vec<u32>,
    covered_arm: Vec<[f64; 2]>,
    uncovered_grain: Vec<u32>,
    uncovered_arm: Vec<[f64; 2]>,
    /// Grains seen by the last cover.
    grains: usize,
}

impl LaddMap {
    /// A map onto `grid` with hydrodynamic radius factor κ = r/R ∈ (0, 1], with the
    /// covering/uncovering impulses.
    pub fn new(grid: Grid, radius_factor: f64) -> crate::Result<Self> {
        if !(radius_factor > 0.0 && radius_factor <= 1.0) {
            return Err(crate::Error::config(
                "coupling.radius_factor",
                format!("r/R must be in (0, 1], got {radius_factor}"),
            ));
        }
        let n = grid.nx * grid.ny;
        Ok(LaddMap {
            grid,
            radius_factor,
            impulses: true,
            owner: vec![NONE; n],
            owner_prev: vec![NONE; n],
            inside: Vec::new(),
            inside_prev: Vec::new(),
            link_grain: Vec::new(),
            link_arm: Vec::new(),
            covered_grain: Vec::new(),
            covered_arm: Vec::new(),
            uncovered_grain: Vec::new(),
            uncovered_arm: Vec::new(),
            grains: 0,
        })
    }

    /// The same map with the covering/uncovering impulses on or off.
    pub fn with_impulses(mut self, on: bool) -> Self {
        self.impulses = on;
        self
    }

    /// Inside nodes of the last cover, ascending.
    pub fn inside(&self) -> &[u32] {
        &self.inside
    }

    /// Number of boundary links of the last cover.
    pub fn links(&self) -> usize {
        self.link_grain.len()
    }

    /// Number of grains the last cover saw.
    pub fn grains(&self) -> usize {
        self.grains
    }

    /// x_n − X (m) for node `c` and grain `k`, by the minimum image on periodic axes.
    fn arm(&self, c: usize, g: &GrainView, k: usize) -> [f64; 2] {
        let Grid {
            nx,
            ny,
            dx,
            periodic,
        } = self.grid;
        let mut r = [
            ((c % nx) as f64 + 0.5) * dx - g.x[k],
            ((c / nx) as f64 + 0.5) * dx - g.y[k],
        ];
        for (a, (len, p)) in [(nx, periodic[0]), (ny, periodic[1])]
            .into_iter()
            .enumerate()
        {
            if p {
                let l = len as f64 * dx;
                r[a] -= l * (r[a] / l).round();
            }
        }
        r
    }

    /// Write the boundary links, inside, covered and uncovered nodes into `out.links` (SI
    /// velocities); the partially saturated cells of `out` are left empty.
    pub fn cover(&mut self, g: &GrainView, out: &mut SolidCover) {
        let Grid {
            nx,
            ny,
            dx,
            periodic,
        } = self.grid;
        out.cells.clear();
        out.eps.clear();
        out.ux.clear();
        out.uy.clear();
        let lc = &mut out.links;
        lc.clear();
        // The previous cover becomes `_prev`; the one before it is wiped from `owner`.
        std::mem::swap(&mut self.owner, &mut self.owner_prev);
        std::mem::swap(&mut self.inside, &mut self.inside_prev);
        for &c in &self.inside {
            self.owner[c as usize] = NONE;
        }
        self.inside.clear();
        self.grains = g.x.len();
        for k in 0..g.x.len() {
            let r = self.radius_factor * g.radius[k] / dx;
            let (cx, cy) = (g.x[k] / dx, g.y[k] / dx);
            // Nodes with centre (i + ½, j + ½) within r.
            let (i0, i1) = ((cx - r - 0.5).ceil() as i64, (cx + r - 0.5).floor() as i64);
            let (j0, j1) = ((cy - r - 0.5).ceil() as i64, (cy + r - 0.5).floor() as i64);
            for j in j0..=j1 {
                let Some(jj) = wrap(j, ny, periodic[1]) else {
                    continue;
                };
                let ry = j as f64 + 0.5 - cy;
                for i in i0..=i1 {
                    let Some(ii) = wrap(i, nx, periodic[0]) else {
                        continue;
                    };
                    let rx = i as f64 + 0.5 - cx;
                    let c = jj * nx + ii;
                    if rx * rx + ry * ry <= r * r && self.owner[c] == NONE {
                        self.owner[c] = k as u32;
                        self.inside.push(c as u32);
                    }
                }
            }
        }
        self.inside.sort_unstable();
        let vel =
            |k: usize, r: [f64; 2]| [g.vx[k] - g.omega[k] * r[1], g.vy[k] + g.omega[k] * r[0]];
        self.link_grain.clear();
        self.link_arm.clear();
        self.covered_grain.clear();
        self.covered_arm.clear();
        for &c in &self.inside {
            let cu = c as usize;
            let k = self.owner[cu] as usize;
            lc.inside.push(c);
            if self.owner_prev[cu] == NONE {
                lc.covered.push(c);
                self.covered_grain.push(k as u32);
                self.covered_arm.push(self.arm(cu, g, k));
            }
            let (x, y) = ((cu % nx) as i64, (cu / nx) as i64);
            let rb = self.arm(cu, g, k);
            // A node more than √2 cells inside its disk has all eight neighbours inside it:
            // no link.
            let deep = (self.radius_factor * g.radius[k] / dx - 1.5).max(0.0) * dx;
            if rb[0] * rb[0] + rb[1] * rb[1] < deep * deep {
                continue;
            }
            for i in 1..Q {
                // The outside node x_f = x_b − e_i.
                let (Some(fx), Some(fy)) = (
                    wrap(x - CX[i] as i64, nx, periodic[0]),
                    wrap(y - CY[i] as i64, ny, periodic[1]),
                ) else {
                    continue;
                };
                let f = fy * nx + fx;
                if self.owner[f] != NONE {
                    continue;
                }
                // Mid-point x_f + e_i/2 = x_b − e_i/2.
                let arm = [
                    rb[0] - 0.5 * CX[i] as f64 * dx,
                    rb[1] - 0.5 * CY[i] as f64 * dx,
                ];
                let u = vel(k, arm);
                lc.cell.push(f as u32);
                lc.dir.push(i as u8);
                lc.ux.push(u[0]);
                lc.uy.push(u[1]);
                self.link_grain.push(k as u32);
                self.link_arm.push(arm);
            }
        }
        self.uncovered_grain.clear();
        self.uncovered_arm.clear();
        for idx in 0..self.inside_prev.len() {
            let c = self.inside_prev[idx] as usize;
            if self.owner[c] != NONE {
                continue;
            }
            let k = self.owner_prev[c] as usize;
            let (u, arm) = if k < g.x.len() {
                let arm = self.arm(c, g, k);
                (vel(k, arm), arm)
            } else {
                ([0.0; 2], [0.0; 2])
            };
            lc.uncovered.push(c as u32);
            lc.fill_ux.push(u[0]);
            lc.fill_uy.push(u[1]);
            self.uncovered_grain.push(k as u32);
            self.uncovered_arm.push(arm);
        }
    }

    /// Sum the link forces of the last [`LaddMap::cover`] per grain (seed eq. 5.47–5.49), and
    /// with [`LaddMap::impulses`] the covering/uncovering momenta, into `loads` (N/m, N·m/m)
    /// for `n` grains.
    pub fn loads(&self, forces: &CellForces, n: usize, loads: &mut ExternalLoads) {
        for v in [&mut loads.fx, &mut loads.fy, &mut loads.torque] {
            v.clear();
            v.resize(n, 0.0);
        }
        let f = &forces.links;
        if f.fx.len() != self.link_grain.len() {
            // The fluid has not stepped with this cover yet: no force.
            return;
        }
        let mut add = |k: u32, arm: [f64; 2], fx: f64, fy: f64| {
            let k = k as usize;
            if k < n {
                loads.fx[k] += fx;
                loads.fy[k] += fy;
                loads.torque[k] += arm[0] * fy - arm[1] * fx;
            }
        };
        for l in 0..self.link_grain.len() {
            add(self.link_grain[l], self.link_arm[l], f.fx[l], f.fy[l]);
        }
        if self.impulses
            && f.covered.len() == self.covered_grain.len()
            && f.uncovered.len() == self.uncovered_grain.len()
        {
            for (j, p) in f.covered.iter().enumerate() {
                add(self.covered_grain[j], self.covered_arm[j], p[0], p[1]);
            }
            for (j, p) in f.uncovered.iter().enumerate() {
                add(self.uncovered_grain[j], self.uncovered_arm[j], p[0], p[1]);
            }
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

impl<F, S> Exchange<F, S> for LaddMap
where
    F: Scale<Input = SolidCover, Output = CellForces>,
    S: Scale<Input = ExternalLoads, Output = GrainView>,
{
    fn to_fluid(&mut self, solid: &GrainView, fluid_in: &mut SolidCover) {
        self.cover(solid, fluid_in);
    }
    fn to_solid(&mut self, fluid: &CellForces, solid_in: &mut ExternalLoads) {
        let n = self.grains;
        self.loads(fluid, n, solid_in);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    /// Inside nodes are those with centre in the disk (also across a periodic corner);
    /// every link leaves an outside node for an inside one; wall velocities include
    /// rotation at the mid-point; moving the grain covers and uncovers the right nodes.
    #[test]
    fn links_cover_and_uncover() {
        let grid = Grid {
            nx: 20,
            ny: 16,
            dx: 0.5,
            periodic: [true, true],
        };
        let mut map = LaddMap::new(grid, 1.0).unwrap();
        let mut out = SolidCover::default();
        let (v, w) = ([0.1, -0.2], 0.3);
        let g = one(0.1, 7.9, 2.3, v, w);
        map.cover(&g, &mut out);
        let lc = &out.links;
        let inside = |c: usize| lc.inside.binary_search(&(c as u32)).is_ok();
        let mut count = 0;
        for c in 0..20 * 16 {
            let r = map.arm(c, &g, 0);
            assert_eq!(
                inside(c),
                r[0] * r[0] + r[1] * r[1] <= 2.3 * 2.3,
                "cell {c}"
            );
            count += inside(c) as usize;
        }
        assert_eq!(count, lc.inside.len());
        assert_eq!(lc.covered, lc.inside);
        assert!(!lc.cell.is_empty());
        for k in 0..lc.cell.len() {
            let (c, i) = (lc.cell[k] as usize, lc.dir[k] as usize);
            assert!(!inside(c));
            let (x, y) = (
                (c % 20) as i64 + CX[i] as i64,
                (c / 20) as i64 + CY[i] as i64,
            );
            let b = (y.rem_euclid(16) * 20 + x.rem_euclid(20)) as usize;
            assert!(inside(b));
            let rf = map.arm(c, &g, 0);
            let m = [rf[0] + 0.25 * CX[i] as f64, rf[1] + 0.25 * CY[i] as f64];
            assert!((lc.ux[k] - (v[0] - w * m[1])).abs() < 1e-14);
            assert!((lc.uy[k] - (v[1] + w * m[0])).abs() < 1e-14);
        }
        // Move by one cell in x: the nodes entering are covered, those left uncovered.
        let before = lc.inside.clone();
        let g2 = one(0.6, 7.9, 2.3, v, w);
        map.cover(&g2, &mut out);
        let lc = &out.links;
        for &c in &lc.covered {
            assert!(before.binary_search(&c).is_err());
        }
        assert!(!lc.covered.is_empty() && !lc.uncovered.is_empty());
        for (k, &c) in lc.uncovered.iter().enumerate() {
            assert!(before.binary_search(&c).is_ok() && lc.inside.binary_search(&c).is_err());
            let r = map.arm(c as usize, &g2, 0);
            assert!((lc.fill_ux[k] - (v[0] - w * r[1])).abs() < 1e-14);
        }
        assert_eq!(
            before.len() + lc.covered.len() - lc.uncovered.len(),
            lc.inside.len()
        );
        assert!(LaddMap::new(grid, 0.0).is_err());
    }

    /// Forces sum per grain with torque about the centre; the impulses only when on.
    #[test]
    fn loads_sum_links_and_impulses() {
        let grid = Grid {
            nx: 32,
            ny: 32,
            dx: 1.0,
            periodic: [false, false],
        };
        let mut map = LaddMap::new(grid, 1.0).unwrap();
        let mut out = SolidCover::default();
        map.cover(&one(16.0, 16.0, 5.0, [0.0; 2], 0.0), &mut out);
        let n = out.links.cell.len();
        let mut f = CellForces::default();
        f.links.fx = vec![1.0; n];
        f.links.fy = vec![0.0; n];
        f.links.covered = vec![[0.0, 2.0]; out.links.covered.len()];
        f.links.uncovered = Vec::new();
        let mut l = ExternalLoads::default();
        map.loads(&f, 1, &mut l);
        assert!((l.fx[0] - n as f64).abs() < 1e-12);
        assert!((l.fy[0] - 2.0 * out.links.covered.len() as f64).abs() < 1e-12);
        // Symmetric disk about its centre: no torque from a uniform force.
        assert!(l.torque[0].abs() < 1e-9);
        let off = map.clone().with_impulses(false);
        off.loads(&f, 1, &mut l);
        assert_eq!(l.fy[0], 0.0);
    }
}
