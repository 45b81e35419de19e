//! Ladd's modified bounce-back for moving solids (Ladd 1994; seed eq. 5.45–5.49), the
//! alternative to partially saturated cells ([`crate::coupling::psm`]).
//!
//! A node whose centre lies inside a solid is an **inside** node; every link from an outside
//! fluid node x_f to an inside node x_b = x_f + e_i is a **boundary link**. After each
//! stream–collide step the population that crossed the link is replaced by the one bounced
//! back from the moving wall at the link mid-point (seed eq. 5.45):
//!
//! f_ī(x_f, t + 1) = f_i*(x_f, t) − 2 w_i ρ₀ (e_i·u_b)/c_s² = f_i*(x_f, t) − 6 w_i ρ₀ (e_i·u_b),
//!
//! u_b = v + ω × (x_f + e_i/2 − X) the solid velocity at the mid-point (eq. 5.46), ρ₀ = 1 the
//! mean density (Ladd's choice, as for the lattice's moving walls). The momentum handed to the
//! solid across the link in one step is
//!
//! Δp_i = e_i [f_i*(x_f) + f_ī(x_f, t + 1)] = e_i [2 f_i*(x_f) − 6 w_i ρ₀ (e_i·u_b)]
//!
//! (eq. 5.47 with Δt = 1); force and torque on a solid are the sums over its links, the torque
//! arm being x_f + e_i/2 − X (eq. 5.48–5.49).
//!
//! **Inside nodes** stay nodes of the lattice (so the AA step is untouched and its vector path
//! keeps running): their populations are a closed interior fluid, bounced back at the same
//! links in the other direction (f_i(x_b) = f_ī*(x_b) + 6 w_i ρ₀ (e_i·u_b)), and are no part of
//! the fluid: they are not counted in [`crate::coupling::CoupledFluid::momentum`] and give the solid nothing.
//!
//! **Covering and uncovering.** When a solid moves, an outside node it now covers takes its
//! momentum Σ f e out of the fluid; a node it uncovers is refilled with the equilibrium
//! f^eq(ρ̄, u_s) at the solid velocity u_s at the node and the mean density ρ̄ of its outside
//! fluid neighbours (ρ₀ when it has none) — Aidun, Lu & Ding (1998). Both momenta are
//! reported (as `covered` / `uncovered` impulses) so a map can hand them to the solids, which
//! keeps fluid + solid momentum to round-off; mass is not conserved by either event.
//!
//! The links are independent (each owns the two slots of its pair of nodes), so the order
//! does not matter; they work with any collision operator and either precision (the
//! exchanged momentum is summed in f64).

use crate::lbm::d2q9::{equilibrium, CX, CY, OPP, Q, W};
use crate::lbm::Lattice;
use crate::lbm::Real;
use crate::units::Units;

/// What a solid scale hands the fluid for Ladd's bounce-back (SI): the boundary links, the
/// inside nodes, and the nodes covered and uncovered since the last hand-over.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct LinkCover {
    /// Outside fluid node x_f of each boundary link (y·nx + x).
    pub cell: Vec<u32>,
    /// Direction i of the link: x_f + e_i is inside a solid.
    pub dir: Vec<u8>,
    /// Solid velocity x at the link mid-point (m/s).
    pub ux: Vec<f64>,
    /// Solid velocity y at the link mid-point (m/s).
    pub uy: Vec<f64>,
    /// All inside nodes, ascending.
    pub inside: Vec<u32>,
    /// Inside nodes that were outside at the last hand-over (their momentum leaves the fluid).
    pub covered: Vec<u32>,
    /// Nodes that were inside and are now outside, ascending: refilled at equilibrium with the
    /// solid velocity at the node …
    pub uncovered: Vec<u32>,
    /// … x (m/s) …
    pub fill_ux: Vec<f64>,
    /// … and y (m/s).
    pub fill_uy: Vec<f64>,
}

impl LinkCover {
    /// No solid: a plain fluid.
    pub fn is_empty(&self) -> bool {
        self.cell.is_empty() && self.inside.is_empty() && self.uncovered.is_empty()
    }

    /// Remove everything, keeping the buffers.
    pub fn clear(&mut self) {
        for v in [
            &mut self.cell,
            &mut self.inside,
            &mut self.covered,
            &mut self.uncovered,
        ] {
            v.clear();
        }
        self.dir.clear();
        for v in [
            &mut self.ux,
            &mut self.uy,
            &mut self.fill_ux,
            &mut self.fill_uy,
        ] {
            v.clear();
        }
    }
}

/// What the fluid hands back (N per metre of depth), in the order of [`LinkCover`].
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct LinkForces {
    /// Force on the solid across each link, x, averaged over the last advance.
    pub fx: Vec<f64>,
    /// Force y.
    pub fy: Vec<f64>,
    /// Momentum each covered node took out of the fluid, divided by the advance's duration
    /// (a force on the solid held over the advance).
    pub covered: Vec<[f64; 2]>,
    /// Minus the momentum each refilled node gave the fluid, over the advance's duration.
    pub uncovered: Vec<[f64; 2]>,
}

/// The boundary links of a lattice, in lattice units, and the momentum they exchange.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct BounceLinks {
    /// Outside node x_f.
    cf: Vec<u32>,
    /// Inside node x_b = x_f + e_i (`u32::MAX`: the link is not a fluid–fluid link of the
    /// lattice, e.g. it ends at a wall, and is skipped).
    cb: Vec<u32>,
    /// Direction i.
    dir: Vec<u8>,
    /// 6 w_i ρ₀ (e_i·u_b).
    corr: Vec<f64>,
    /// Momentum given to the solid across each link, summed over the steps since
    /// [`BounceLinks::set`].
    pub sum: Vec<[f64; 2]>,
    /// Steps since [`BounceLinks::set`].
    pub steps: u64,
    /// Momentum of each covered node (taken out of the fluid at the last set).
    pub covered: Vec<[f64; 2]>,
    /// Momentum given to each refilled node at the last set.
    pub uncovered: Vec<[f64; 2]>,
    /// Inside nodes (dense mask over the lattice; empty until the first set).
    inside: Vec<bool>,
    /// Inside nodes, ascending.
    inside_list: Vec<u32>,
}

impl BounceLinks {
    /// No links and no inside nodes.
    pub fn is_empty(&self) -> bool {
        self.cf.is_empty() && self.inside_list.is_empty()
    }

    /// Number of boundary links.
    pub fn len(&self) -> usize {
        self.cf.len()
    }

    /// Is cell `c` inside a solid?
    #[inline]
    pub fn is_inside(&self, c: usize) -> bool {
        self.inside.get(c).copied().unwrap_or(false)
    }

    /// Inside nodes, ascending.
    pub fn inside(&self) -> &[u32] {
        &self.inside_list
    }

    /// Take a new cover: mark the inside nodes, take the momentum of the covered nodes out of
    /// the fluid, refill the uncovered ones at equilibrium f^eq(ρ̄, u_s), set up the links
    /// and zero the exchange sums. Velocities are converted with `units`.
    pub fn set<T: Real>(&mut self, lat: &mut Lattice<T>, cover: &LinkCover, units: &Units) {
        let n = lat.len();
        if self.inside.len() != n {
            self.inside = vec![false; n];
        }
        for &c in &self.inside_list {
            self.inside[c as usize] = false;
        }
        self.inside_list.clear();
        for &c in &cover.inside {
            self.inside[c as usize] = true;
            self.inside_list.push(c);
        }
        let momentum = |lat: &Lattice<T>, c: usize| -> ([f64; 2], f64) {
            let f = lat.populations(c);
            let (mut j, mut r) = ([0.0; 2], 0.0);
            for i in 0..Q {
                let v = f[i].f64();
                r += v;
                j[0] += v * CX[i] as f64;
                j[1] += v * CY[i] as f64;
            }
            (j, r)
        };
        self.covered.clear();
        for &c in &cover.covered {
            self.covered.push(momentum(lat, c as usize).0);
        }
        self.uncovered.clear();
        for (k, &c) in cover.uncovered.iter().enumerate() {
            let c = c as usize;
            // ρ̄ over the outside fluid neighbours that are not refilled themselves.
            let (mut sum, mut cnt) = (0.0, 0);
            for i in 1..Q {
                if let Some(nb) = lat.fluid_neighbour(c, i) {
                    if !self.inside[nb] && cover.uncovered.binary_search(&(nb as u32)).is_err() {
                        sum += momentum(lat, nb).1;
                        cnt += 1;
                    }
                }
            }
            let rho = if cnt > 0 { sum / cnt as f64 } else { 1.0 };
            let u = [
                units.velocity_to_lattice(cover.fill_ux[k]),
                units.velocity_to_lattice(cover.fill_uy[k]),
            ];
            lat.set_populations(c, &equilibrium(rho, u[0], u[1]));
            // The momentum actually stored (rounded to the lattice's precision).
            self.uncovered.push(momentum(lat, c).0);
        }
        self.cf.clear();
        self.cb.clear();
        self.dir.clear();
        self.corr.clear();
        for k in 0..cover.cell.len() {
            let (c, i) = (cover.cell[k] as usize, cover.dir[k] as usize);
            let b = lat
                .fluid_neighbour(c, i)
                .filter(|&b| self.inside[b] && !self.inside[c])
                .map_or(u32::MAX, |b| b as u32);
            let u = [
                units.velocity_to_lattice(cover.ux[k]),
                units.velocity_to_lattice(cover.uy[k]),
            ];
            self.cf.push(c as u32);
            self.cb.push(b);
            self.dir.push(i as u8);
            self.corr
                .push(6.0 * W[i] * (CX[i] as f64 * u[0] + CY[i] as f64 * u[1]));
        }
        self.sum.clear();
        self.sum.resize(self.cf.len(), [0.0; 2]);
        self.steps = 0;
    }

    /// Apply the bounce-back on every link after a step of parity `was_even` and add the
    /// exchanged momentum to [`BounceLinks::sum`].
    ///
    /// The two slots of a link: after an even step A[x_f][ī] holds f_i*(x_f) and A[x_b][i]
    /// holds f_ī*(x_b), each to be read by the other node next; after an odd step the roles of
    /// the two slots are exchanged. Either way the slot that held f_i*(x_f) gets the interior
    /// value and the other the bounced one.
    pub fn bounce<T: Real>(&mut self, lat: &mut Lattice<T>, was_even: bool) {
        for k in 0..self.cf.len() {
            if self.cb[k] == u32::MAX {
                continue;
            }
            let (cf, cb, i) = (
                self.cf[k] as usize,
                self.cb[k] as usize,
                self.dir[k] as usize,
            );
            let o = OPP[i];
            let ((sa, ca), (sb, cbb)) = if was_even {
                ((o, cf), (i, cb))
            } else {
                ((i, cb), (o, cf))
            };
            let a = lat.slot(sa, ca);
            let b = lat.slot(sb, cbb);
            let corr = self.corr[k];
            let back = T::c(a.f64() - corr);
            lat.set_slot(sb, cbb, back);
            lat.set_slot(sa, ca, T::c(b.f64() + corr));
            let m = a.f64() + back.f64();
            self.sum[k][0] += m * CX[i] as f64;
            self.sum[k][1] += m * CY[i] as f64;
        }
        self.steps += 1;
    }

    /// Force on the solids summed over all links, averaged over the steps since the last set
    /// (lattice units).
    pub fn total_force(&self) -> [f64; 2] {
        let k = self.steps.max(1) as f64;
        let s = self
            .sum
            .iter()
            .fold([0.0; 2], |a, v| [a[0] + v[0], a[1] + v[1]]);
        [s[0] / k, s[1] / k]
    }

    /// Forces per link and covering impulses (SI) over the steps since the last set.
    pub fn observe(&self, units: &Units, out: &mut LinkForces) {
        let k = self.steps.max(1) as f64;
        out.fx.clear();
        out.fy.clear();
        for s in &self.sum {
            out.fx.push(units.force_to_si(s[0] / k));
            out.fy.push(units.force_to_si(s[1] / k));
        }
        // A momentum J taken out of the fluid at the start of k steps is the force J/k held
        // over them (lattice units), given to the solid; a momentum given to the fluid, minus.
        out.covered.clear();
        for j in &self.covered {
            out.covered
                .push([units.force_to_si(j[0] / k), units.force_to_si(j[1] / k)]);
        }
        out.uncovered.clear();
        for j in &self.uncovered {
            out.uncovered
                .push([-units.force_to_si(j[0] / k), -units.force_to_si(j[1] / k)]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lbm::{Edges, Lattice};
    use approx::assert_relative_eq;

    /// Links of a disk of radius `r` centred at `c` on a periodic `l × l` lattice, all with
    /// wall velocity `u`, and its inside nodes (node centre within r).
    fn disk_links(l: usize, c: [f64; 2], r: f64, u: [f64; 2]) -> LinkCover {
        let mut lc = LinkCover::default();
        let inside = |x: usize, y: usize| {
            let (dx, dy) = (x as f64 + 0.5 - c[0], y as f64 + 0.5 - c[1]);
            dx * dx + dy * dy <= r * r
        };
        for y in 0..l {
            for x in 0..l {
                if inside(x, y) {
                    lc.inside.push((y * l + x) as u32);
                    lc.covered.push((y * l + x) as u32);
                    continue;
                }
                for i in 1..Q {
                    let (xb, yb) = (
                        (x as i64 + CX[i] as i64).rem_euclid(l as i64) as usize,
                        (y as i64 + CY[i] as i64).rem_euclid(l as i64) as usize,
                    );
                    if inside(xb, yb) {
                        lc.cell.push((y * l + x) as u32);
                        lc.dir.push(i as u8);
                        lc.ux.push(u[0]);
                        lc.uy.push(u[1]);
                    }
                }
            }
        }
        lc
    }

    /// A fixed disk with u_b = 0 is the lattice's own half-way bounce-back on a solid mask:
    /// outside populations and the momentum-exchange force agree step by step (both parities).
    #[test]
    fn resting_links_equal_the_solid_mask() {
        use crate::lbm::{Collider, CollisionModel, Obstacle, Obstacles, Shape};
        let l = 24;
        let (c, r) = ([11.3, 12.1], 5.2);
        let mut obs = Obstacles::new(vec![Obstacle {
            name: "disk".into(),
            shape: Shape::Circle {
                center: c,
                radius: r,
            },
            interpolated: false,
        }]);
        let mask = obs.mask(l, l);
        let init = |x: usize, y: usize| {
            (
                1.0 + 0.01 * (x as f64 / l as f64),
                0.02,
                -0.01 * (y as f64 / l as f64),
            )
        };
        let mut solid = Lattice::<f64>::new(l, l, Edges::periodic(), mask.clone()).unwrap();
        solid.fill(init);
        obs.link(&solid);
        let mut open = Lattice::<f64>::new(l, l, Edges::periodic(), vec![false; l * l]).unwrap();
        open.fill(init);
        let col = Collider::new(CollisionModel::Bgk, 0.7, None, [0.0; 2]);
        let lc = disk_links(l, c, r, [0.0; 2]);
        assert_eq!(
            lc.inside.iter().map(|&k| k as usize).collect::<Vec<_>>(),
            (0..l * l).filter(|&k| mask[k]).collect::<Vec<_>>()
        );
        let mut links = BounceLinks::default();
        links.set(&mut open, &lc, &Units::lattice(0.7));
        assert_eq!(links.len(), obs.link_count());
        for step in 0..6 {
            let even = solid.next_is_even();
            solid.step(&col);
            obs.after_step(&mut solid, even);
            let s0 = links.sum.clone();
            open.step(&col);
            links.bounce(&mut open, even);
            let df: [f64; 2] =
                std::array::from_fn(|a| links.sum.iter().zip(&s0).map(|(x, y)| x[a] - y[a]).sum());
            for (d, o) in df.iter().zip(&obs.force[0]) {
                assert_relative_eq!(*d, *o, epsilon = 1e-13);
            }
            for (k, &m) in mask.iter().enumerate() {
                if !m {
                    let (p, q) = (solid.populations(k), open.populations(k));
                    for i in 0..Q {
                        assert!((p[i] - q[i]).abs() < 1e-14, "step {step} cell {k} i {i}");
                    }
                }
            }
        }
    }

    /// A uniform stream at velocity U around a disk whose wall moves at U stays uniform (the
    /// wall term 6 w_i e_i·U turns f_i^eq into f_ī^eq), and the symmetric disk feels no
    /// force; with the wrong sign it would.
    #[test]
    fn wall_moving_with_the_stream_leaves_it_alone() {
        use crate::lbm::{Collider, CollisionModel, MrtRates};
        let l = 20;
        let u = [0.04, -0.025];
        for model in [
            CollisionModel::Bgk,
            CollisionModel::Mrt(MrtRates::standard(0.8)),
        ] {
            let mut lat = Lattice::<f64>::new(l, l, Edges::periodic(), vec![false; l * l]).unwrap();
            lat.fill(|_, _| (1.0, u[0], u[1]));
            let col = Collider::new(model, 0.8, None, [0.0; 2]);
            let lc = disk_links(l, [10.0, 10.0], 4.0, u);
            let mut links = BounceLinks::default();
            links.set(&mut lat, &lc, &Units::lattice(0.8));
            for _ in 0..5 {
                let even = lat.next_is_even();
                lat.step(&col);
                links.bounce(&mut lat, even);
            }
            let feq = equilibrium(1.0, u[0], u[1]);
            for c in 0..l * l {
                if !links.is_inside(c) {
                    let p = lat.populations(c);
                    for i in 0..Q {
                        assert!((p[i] - feq[i]).abs() < 1e-15, "cell {c} i {i}");
                    }
                }
            }
            let f = links.total_force();
            assert!(f[0].abs() < 1e-13 && f[1].abs() < 1e-13, "{f:?}");
        }
    }

    /// Refilled nodes take f^eq(ρ̄, u_s) with ρ̄ their outside neighbours' mean density;
    /// covered nodes report their momentum.
    #[test]
    fn cover_and_uncover() {
        let l = 8;
        let mut lat = Lattice::<f64>::new(l, l, Edges::periodic(), vec![false; l * l]).unwrap();
        lat.fill(|x, _| (1.0 + 0.01 * x as f64, 0.01, 0.0));
        let mut links = BounceLinks::default();
        let units = Units::lattice(0.8);
        let mut lc = LinkCover {
            inside: vec![27],
            covered: vec![27],
            ..Default::default()
        };
        links.set(&mut lat, &lc, &units);
        assert_relative_eq!(links.covered[0][0], 1.03 * 0.01, max_relative = 1e-12);
        lc.inside.clear();
        lc.covered.clear();
        lc.uncovered = vec![27];
        lc.fill_ux = vec![0.02];
        lc.fill_uy = vec![-0.01];
        links.set(&mut lat, &lc, &units);
        // Node 27 = (3, 3): neighbours at x = 2, 3, 4 with densities 1.02, 1.03, 1.04.
        let rho = (3.0 * 1.02 + 2.0 * 1.03 + 3.0 * 1.04) / 8.0;
        let p = lat.populations(27);
        let e = equilibrium(rho, 0.02, -0.01);
        for i in 0..Q {
            assert_relative_eq!(p[i], e[i], max_relative = 1e-14);
        }
        assert_relative_eq!(links.uncovered[0][0], rho * 0.02, max_relative = 1e-12);
        assert_relative_eq!(links.uncovered[0][1], -rho * 0.01, max_relative = 1e-12);
    }
}
