//! Contacts found by the rapier detector (any pair with a polygon grain, and disk–polygon-wall
//! pairs): contact history and forces, with the same contact law as the disk fast path
//! ([`super::contact::Law::resolve`]) but the contact point as lever arm.
//!
//! For a contact point **p** with unit normal **n** (from i towards j), tangent
//! **t** = (−n_y, n_x) and lever arms **r**_i = **p** − **x**_i, **r**_j = **p** − **x**_j, the
//! velocity of i relative to j at the contact point is
//! **v**_rel = **v**_i + ω_i × **r**_i − **v**_j − ω_j × **r**_j (ω × **r** = ω(−r_y, r_x)), split
//! into u = **v**_rel·**n** and v_t = **v**_rel·**t**. The law gives (f_n, f_t, M); the force on i is
//! **F**_i = −f_n **n** + f_t **t**, on j −**F**_i; the torques are T_i = **r**_i × **F**_i + M and
//! T_j = −**r**_j × **F**_i − M (for disks, **r**_i = R_i**n** and **r**_j = −R_j**n** give back the
//! cell-list torques R_i f_t + M and R_j f_t − M). m_eff = m_i m_j/(m_i + m_j) (m_i for a wall).
//!
//! Rolling resistance is off for any contact with a polygon grain (an angular grain resists
//! rolling by its shape; the rolling spring models the shape of round grains): the law is used
//! with k_r = 0 there, and as given for disk–polygon-wall contacts (R_eff = R_i).
//!
//! A face–face contact (e.g. a square lying on the floor) is two manifold points, each a
//! spring-dashpot with its own history (key: the feature ids of the two sides). Each of the n
//! points of a pair in contact (δ > 0, or ending this step) takes the effective mass m_eff/n:
//! its dashpot c_n = 2ξ√(k_n m_eff/n) and its implicit solve then see the share of the mass
//! it carries, so n parallel points damp like one contact of stiffness n k_n on m_eff
//! (ξ unchanged, so a flat impact rebounds with the set e; with m_eff per point the damping
//! ratio would be √n ξ: e = 0.5 gave 0.365). History is carried from
//! one step to the next by a linear merge of the sorted contact lists (no hashing).
//! A point whose feature pair changed while touching (as two faces slide, the clipping points
//! switch between vertices of either polygon) hands its history to the nearest new point of the
//! same pair; a touching point with no successor loses it without an end-of-contact trapezoid.
//!
//! The loop is serial (polygon systems are small here); its cost is dominated by rapier.

use super::contact::{ContactOut, ContactState, Event, Law, Motion};
use super::detect_rapier::{Contact, Coverage, RapierDetector};
use super::grains::Grains;
use super::walls::Wall;

/// Sums of one evaluation (energies of the springs now, dissipation over the step).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShapeSums {
    /// Normal spring energy.
    pub e_n: f64,
    /// Tangential spring energy.
    pub e_t: f64,
    /// Rolling spring energy.
    pub e_r: f64,
    /// Dissipated by normal damping.
    pub d_n: f64,
    /// Dissipated by friction.
    pub d_f: f64,
    /// Dissipated by rolling resistance.
    pub d_r: f64,
    /// Touching contact points.
    pub contacts: usize,
}

/// Contact points of the rapier-detected pairs with their history.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ShapeContacts {
    det: RapierDetector,
    /// Contacts of the last evaluation, sorted by (i, j, key).
    pub found: Vec<Contact>,
    /// Contact state per entry of `found`.
    pub state: Vec<ContactState>,
    /// Force on i of each entry of `found` applied in the last second half-kick [F_x, F_y].
    pub force: Vec<[f64; 2]>,
    old: Vec<Contact>,
    old_state: Vec<ContactState>,
    events: Vec<Event>,
    /// Sum per grain of this evaluation's forces [F_x, F_y, torque] (the second half-kick's
    /// F^end, like the pair lists' `out`).
    per_grain: Vec<[f64; 3]>,
    /// Points in contact of each entry's pair (the mass share 1/n).
    share: Vec<u32>,
    /// Scratch of the history merge: old entries matched; new entries without a key match.
    used: Vec<bool>,
    fresh: Vec<u32>,
    /// Histories handed from a point to a new point of the same pair (feature change), total.
    pub handovers: u64,
    /// Touching points that vanished from rapier's manifolds without a successor, total.
    pub lost: u64,
}

impl ShapeContacts {
    /// Contacts of the pairs the cell list does not handle, with points up to `prediction`
    /// apart reported (the Verlet skin).
    pub fn new(prediction: f64) -> Self {
        ShapeContacts {
            det: RapierDetector::new(Coverage::Complement, prediction),
            found: Vec::new(),
            state: Vec::new(),
            force: Vec::new(),
            old: Vec::new(),
            old_state: Vec::new(),
            events: Vec::new(),
            per_grain: Vec::new(),
            share: Vec::new(),
            used: Vec::new(),
            fresh: Vec::new(),
            handovers: 0,
            lost: 0,
        }
    }

    /// Detect, carry history over, resolve every contact over a step `h` (0: evaluate only)
    /// and sum the forces per grain into [`ShapeContacts::grain_force`], which the solver's
    /// per-grain gather adds. `vp` are the predictor velocities (x, y, ω) of the solver.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &mut self,
        g: &Grains,
        walls: &[Wall],
        vp: (&[f64], &[f64], &[f64]),
        grain_law: &Law,
        wall_law: &Law,
        h: f64,
    ) -> ShapeSums {
        std::mem::swap(&mut self.old, &mut self.found);
        std::mem::swap(&mut self.old_state, &mut self.state);
        self.det.detect(g, walls, &mut self.found);
        // History: both lists sorted by (i, j, key).
        self.state.clear();
        self.used.clear();
        self.used.resize(self.old.len(), false);
        self.fresh.clear();
        let mut o = 0;
        for (p, c) in self.found.iter().enumerate() {
            let k = c.order();
            while o < self.old.len() && self.old[o].order() < k {
                o += 1;
            }
            self.state
                .push(if o < self.old.len() && self.old[o].order() == k {
                    self.used[o] = true;
                    self.old_state[o]
                } else {
                    self.fresh.push(p as u32);
                    ContactState::default()
                });
        }
        // A point whose feature pair changed (e.g. a clipping vertex of one polygon handing
        // over to one of the other as they slide) keeps the history of the nearest point of
        // the same pair that was touching and found no match.
        let mut o = 0;
        for &p in &self.fresh {
            let c = self.found[p as usize];
            while o < self.old.len() && (self.old[o].i, self.old[o].j) < (c.i, c.j) {
                o += 1;
            }
            let mut best = (f64::INFINITY, usize::MAX);
            let mut q = o;
            while q < self.old.len() && (self.old[q].i, self.old[q].j) == (c.i, c.j) {
                if !self.used[q] && self.old_state[q].touching() {
                    let (dx, dy) = (
                        self.old[q].point[0] - c.point[0],
                        self.old[q].point[1] - c.point[1],
                    );
                    if dx * dx + dy * dy < best.0 {
                        best = (dx * dx + dy * dy, q);
                    }
                }
                q += 1;
            }
            if best.1 != usize::MAX {
                self.used[best.1] = true;
                self.state[p as usize] = self.old_state[best.1];
                self.handovers += 1;
            }
        }
        for (u, st) in self.used.iter().zip(&self.old_state) {
            if !u && st.touching() {
                self.lost += 1;
            }
        }
        // Points in contact per pair (groups of equal (i, j) are contiguous).
        self.share.clear();
        self.share.resize(self.found.len(), 1);
        let mut a = 0;
        while a < self.found.len() {
            let pair = (self.found[a].i, self.found[a].j);
            let mut b = a;
            let mut n = 0;
            while b < self.found.len() && (self.found[b].i, self.found[b].j) == pair {
                n += u32::from(self.found[b].delta > 0.0 || self.state[b].touching());
                b += 1;
            }
            self.share[a..b].fill(n.max(1));
            a = b;
        }
        self.force.clear();
        self.events.clear();
        self.per_grain.clear();
        self.per_grain.resize(g.len(), [0.0; 3]);
        let (vxp, vyp, wp) = vp;
        let mut sums = ShapeSums::default();
        for ((c, st), &share) in self
            .found
            .iter()
            .zip(self.state.iter_mut())
            .zip(self.share.iter())
        {
            let i = c.i as usize;
            let wall = c.wall();
            let [nx, ny] = c.normal;
            let (tx, ty) = (-ny, nx);
            let ri = [c.point[0] - g.x[i], c.point[1] - g.y[i]];
            // Velocities of the contact point on i minus on j: [current, predictor].
            let mut vr = [
                [g.vx[i] - g.omega[i] * ri[1], g.vy[i] + g.omega[i] * ri[0]],
                [vxp[i] - wp[i] * ri[1], vyp[i] + wp[i] * ri[0]],
            ];
            let mut w = [g.omega[i], wp[i]];
            let (law, m_eff, r_eff, rj);
            if let Some(_w) = wall {
                law = if g.is_disk(i) {
                    *wall_law
                } else {
                    Law {
                        k_r: 0.0,
                        ..*wall_law
                    }
                };
                m_eff = g.mass[i];
                r_eff = g.radius[i];
                rj = [0.0; 2];
            } else {
                let j = c.j as usize;
                let r = [c.point[0] - g.x[j], c.point[1] - g.y[j]];
                vr[0][0] -= g.vx[j] - g.omega[j] * r[1];
                vr[0][1] -= g.vy[j] + g.omega[j] * r[0];
                vr[1][0] -= vxp[j] - wp[j] * r[1];
                vr[1][1] -= vyp[j] + wp[j] * r[0];
                w = [w[0] - g.omega[j], w[1] - wp[j]];
                law = if g.is_disk(i) && g.is_disk(j) {
                    *grain_law
                } else {
                    Law {
                        k_r: 0.0,
                        ..*grain_law
                    }
                };
                let (mi, mj) = (g.mass[i], g.mass[j]);
                m_eff = mi * mj / (mi + mj);
                r_eff = g.radius[i] * g.radius[j] / (g.radius[i] + g.radius[j]);
                rj = r;
            }
            let motion = Motion {
                delta: c.delta,
                u: [vr[0][0] * nx + vr[0][1] * ny, vr[1][0] * nx + vr[1][1] * ny],
                v_t: [vr[0][0] * tx + vr[0][1] * ty, vr[1][0] * tx + vr[1][1] * ty],
                w,
                m_eff: m_eff / f64::from(share),
                r_eff,
            };
            let r: ContactOut = law.resolve(&motion, st, h);
            let cross = |a: [f64; 2], f: [f64; 2]| a[0] * f[1] - a[1] * f[0];
            let [an, at, ar] = r.apply;
            let f = [-an * nx + at * tx, -an * ny + at * ty];
            self.force.push(f);
            let q = &mut self.per_grain[i];
            q[0] += f[0];
            q[1] += f[1];
            q[2] += cross(ri, f) + ar;
            let j = if wall.is_some() { u32::MAX } else { c.j };
            if j != u32::MAX {
                let q = &mut self.per_grain[j as usize];
                q[0] -= f[0];
                q[1] -= f[1];
                q[2] += -cross(rj, f) - ar;
            }
            if r.event {
                let (dn, dt, dm) = (st.f_n - an, st.f_t - at, st.m_r - ar);
                let d = [-dn * nx + dt * tx, -dn * ny + dt * ty];
                self.events.push(Event {
                    i: c.i,
                    j,
                    d: [d[0], d[1], cross(ri, d) + dm, -cross(rj, d) - dm],
                });
            }
            sums.e_n += r.e_normal;
            sums.e_t += r.e_tangential;
            sums.e_r += r.e_rolling;
            sums.d_n += r.d_normal;
            sums.d_f += r.d_friction;
            sums.d_r += r.d_rolling;
            sums.contacts += usize::from(r.touching);
        }
        sums
    }

    /// Contact force and torque per grain of the last evaluation, [F_x, F_y, T] (empty before
    /// the first).
    pub fn grain_force(&self) -> &[[f64; 3]] {
        &self.per_grain
    }

    /// Turn the forces of onset/end steps from **F**^end into **F**_{k+1} (after the kick).
    pub fn apply_events(&self, g: &mut Grains) {
        for ev in &self.events {
            ev.apply(g);
        }
    }

    /// Total normal force on grain `i` from its contacts with wall `w` at the last evaluation
    /// (Σ f_n of the touching points), for tests and output.
    pub fn wall_normal_force(&self, i: usize, w: usize) -> f64 {
        self.found
            .iter()
            .zip(&self.state)
            .filter(|(c, _)| c.i as usize == i && c.wall() == Some(w))
            .map(|(_, s)| s.f_n)
            .sum()
    }
}
