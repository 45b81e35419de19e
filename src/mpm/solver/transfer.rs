//! The transfers of the explicit step ([`super`]): sorting and binning the points, point →
//! grid (mass, momentum, forces; APIC or FLIP/PIC), the grid update with its walls, and the
//! point passes grid → point (velocity, position, strain increment and stress update).

use rayon::prelude::*;

use super::*;
use crate::exec::simd;

impl<M: Material> Mpm<M> {
    /// Re-sort the points into cell order (x-major, as the nodes).
    pub(super) fn resort(&mut self) {
        let g = &self.grid;
        let key = |p: [f64; 2]| -> usize {
            let cx = ((p[0] - g.origin[0]) / g.h)
                .floor()
                .clamp(0.0, (g.nx - 1) as f64) as usize;
            let cy = ((p[1] - g.origin[1]) / g.h)
                .floor()
                .clamp(0.0, (g.ny - 1) as f64) as usize;
            cx * g.ny + cy
        };
        let ncells = g.nx * g.ny;
        let mut count = vec![0usize; ncells + 1];
        for &p in &self.points.pos {
            count[key(p) + 1] += 1;
        }
        for c in 0..ncells {
            count[c + 1] += count[c];
        }
        self.perm.clear();
        self.perm.resize(self.points.len(), 0);
        for (k, &p) in self.points.pos.iter().enumerate() {
            let c = key(p);
            self.perm[count[c]] = k as u32;
            count[c] += 1;
        }
        let perm = std::mem::take(&mut self.perm);
        self.points.permute(&perm, &mut self.scratch);
        if !self.tractions.is_empty() {
            // Old index perm[k] is now k.
            self.inverse.resize(perm.len(), 0);
            for (k, &old) in perm.iter().enumerate() {
                self.inverse[old as usize] = k as u32;
            }
            for t in &mut self.tractions {
                t.point = self.inverse[t.point as usize];
            }
        }
        self.perm = perm;
    }

    /// Periodic in x: move every point outside the period by whole periods into it (its
    /// reference position `pos0` with it, so displacements stay continuous).
    fn wrap(&mut self) {
        let Some([x0, x1]) = self.grid.period_bounds() else {
            return;
        };
        let l = x1 - x0;
        let p = &mut self.points;
        for (x, x_ref) in p.pos.iter_mut().zip(p.pos0.iter_mut()) {
            if x[0] < x0 || x[0] >= x1 {
                let shift = l * ((x[0] - x0) / l).floor();
                x[0] -= shift;
                x_ref[0] -= shift;
                if x[0] >= x1 {
                    // Round-off of a point a hair below x0.
                    x[0] -= l;
                    x_ref[0] -= l;
                }
            }
        }
    }

    /// Bin the points into stripes by the node column where their stencil starts; checks that
    /// every point is finite and its stencil inside the grid.
    pub(super) fn bin(&mut self) -> Result<()> {
        self.wrap();
        let g = &self.grid;
        let shape = self.params.shape;
        let ns = self.stripe_start.len() - 1;
        self.stripe_start.iter_mut().for_each(|c| *c = 0);
        let (origin, h) = (g.origin, g.h);
        let (nx, ny) = (g.nx as i64, g.ny as i64);
        // Each point's stencil and stripe, in parallel; `OUTSIDE` marks a point that is not
        // finite or whose stencil leaves the grid.
        const OUTSIDE: u32 = u32::MAX;
        self.stencils
            .par_chunks_mut(CHUNK)
            .zip(self.points.pos.par_chunks(CHUNK))
            .zip(self.points.half_size.par_chunks(CHUNK))
            .zip(self.stripe_of.par_chunks_mut(CHUNK))
            .for_each(|(((sts, xs), lps), stripes)| {
                simd::dispatch!(stencils(shape, origin, h, xs, lps, sts));
                for ((stripe, st), x) in stripes.iter_mut().zip(sts.iter()).zip(xs) {
                    let inside = x[0].is_finite()
                        && x[1].is_finite()
                        && st.i0 >= 0
                        && st.j0 >= 0
                        && st.i0 + 2 <= nx
                        && st.j0 + 2 <= ny;
                    *stripe = if inside {
                        (st.i0 as usize / STRIPE) as u32
                    } else {
                        OUTSIDE
                    };
                }
            });
        for (p, &s) in self.stripe_of.iter().enumerate() {
            if s == OUTSIDE {
                let x = self.points.pos[p];
                return Err(Error::Unstable {
                    step: self.steps,
                    time: self.time,
                    x: ((x[0] - origin[0]) / h).max(0.0) as usize,
                    y: ((x[1] - origin[1]) / h).max(0.0) as usize,
                    reason: format!(
                        "material point {p} at ({:e}, {:e}) m is not finite or left the grid",
                        x[0], x[1]
                    ),
                });
            }
            self.stripe_start[s as usize + 1] += 1;
        }
        for s in 0..ns {
            self.stripe_start[s + 1] += self.stripe_start[s];
        }
        for t in &self.tractions {
            let (_, st) = self.traction_force(t);
            if st.i0 < 0 || st.j0 < 0 || st.i0 + 2 > g.nx as i64 || st.j0 + 2 > g.ny as i64 {
                return Err(Error::Unstable {
                    step: self.steps,
                    time: self.time,
                    x: st.i0.max(0) as usize,
                    y: st.j0.max(0) as usize,
                    reason: format!("the traction face of point {} left the grid", t.point),
                });
            }
        }
        // Stable scatter: within a stripe the points keep their (cell) order.
        let mut fill = std::mem::take(&mut self.perm);
        fill.clear();
        fill.extend(self.stripe_start[..ns].iter().map(|&v| v as u32));
        for p in 0..self.points.len() {
            let s = self.stripe_of[p] as usize;
            self.order[fill[s] as usize] = p as u32;
            fill[s] += 1;
        }
        self.perm = fill;
        Ok(())
    }

    /// Scatter point quantities to the nodes. `mass`: mass and momentum; `force`: internal and
    /// gravity force; `momentum`: momentum only (MUSL re-map; mass kept).
    #[inline(always)]
    pub(super) fn p2g(&mut self, mass: bool, force: bool, momentum: bool) {
        // The transfer is a const parameter so the FLIP path carries no APIC branches.
        if self.transfer == Transfer::Apic && (mass || momentum) {
            self.p2g_with::<true>(mass, force, momentum)
        } else {
            self.p2g_with::<false>(mass, force, momentum)
        }
    }

    #[inline(always)]
    pub(super) fn p2g_with<const APIC: bool>(&mut self, mass: bool, force: bool, momentum: bool) {
        let g = &mut self.grid;
        let nny = g.ny + 1;
        let ns = self.stripe_start.len() - 1;
        let scatter = Scatter {
            pts: &self.points,
            order: &self.order,
            starts: &self.stripe_start,
            stencils: &self.stencils,
            grav: self.params.gravity,
            origin: g.origin,
            h: g.h,
            nny,
            mass,
            force,
            momentum,
        };
        g.sums.par_iter_mut().for_each(|s| {
            if mass {
                s[0] = 0.0;
            }
            if mass || momentum {
                s[1] = 0.0;
                s[2] = 0.0;
            }
            if force {
                s[3] = 0.0;
                s[4] = 0.0;
            }
        });
        let chunk_len = 2 * STRIPE * nny;
        for phase in 0..2 {
            let head = (phase * STRIPE * nny).min(g.sums.len());
            g.sums[head..]
                .par_chunks_mut(chunk_len)
                .enumerate()
                // One task per stripe: a column at one end of the grid has all its stripes
                // in the first chunks, which rayon's first splits would give to one thread.
                .with_max_len(1)
                .for_each(|(k, chunk): (usize, &mut [NodeSums])| {
                    let s = 2 * k + phase;
                    if s < ns {
                        simd::dispatch!(scatter.stripe::<APIC>(s, chunk));
                    }
                });
        }
        let moved = mass || momentum;
        g.fold([mass, moved, moved, force, force]);
    }

    /// Grid velocities from momenta: `vel` = p/m (unconstrained; the FLIP reference) and, when
    /// `into_map`, `vel_map` = p/m with the walls applied (energy not booked: the momentum is
    /// not changed). With `remap` (MUSL, after the momentum update) the walls keep the contact
    /// state that the update gave each node ([`Grid::constrain_remap`]): the re-mapped field
    /// stands for the same v^{n+1}, so a node that the update held on a unilateral wall is
    /// held there, not released because the re-mapped FLIP velocities point away from it.
    pub(super) fn grid_velocity(&mut self, into_map: bool, remap: bool) {
        let g = &mut self.grid;
        let eps = self.mass_eps;
        let walls = &g.walls;
        let contact = &g.contact;
        let target = if into_map { &mut g.vel_map } else { &mut g.vel };
        target
            .par_iter_mut()
            .zip(g.sums.par_iter())
            .zip(g.walls_mask.par_iter())
            .zip(contact.par_iter())
            .for_each(|(((v, s), &mask), &engaged)| {
                if s[0] > eps {
                    *v = [s[1] / s[0], s[2] / s[0]];
                    if into_map && remap {
                        Grid::constrain_remap(walls, mask, engaged, v);
                    } else if into_map {
                        Grid::constrain(walls, mask, v);
                    }
                } else {
                    *v = [0.0; 2];
                }
            });
    }

    /// v^{n+1} = v + Δt f/m (with local damping), then the walls; books the energy removed.
    pub(super) fn grid_update(&mut self) {
        let g = &mut self.grid;
        let (eps, dt, alpha) = (self.mass_eps, self.dt, self.params.damping);
        let walls = &g.walls;
        let (period, nny) = (g.period_x, g.nny());
        let owns = |n: usize| crate::mpm::grid::owned(period, nny, n);
        let node = |vn: &mut [f64; 2], v: &[f64; 2], s: &[f64; 5], mask, engaged: &mut u8| {
            if s[0] <= eps {
                *vn = [0.0; 2];
                *engaged = 0;
                return [0.0; 3];
            }
            let mut f = [s[3], s[4]];
            let mut damp = 0.0;
            if alpha > 0.0 {
                for c in 0..2 {
                    let fd = alpha * f[c].abs() * v[c].signum();
                    f[c] -= fd;
                    damp += fd * v[c] * dt;
                }
            }
            *vn = [v[0] + dt * f[0] / s[0], v[1] + dt * f[1] / s[0]];
            let (dn, dtan, on) = Grid::constrain_tracked(walls, mask, vn);
            *engaged = on;
            // Work of the wall impulse m Δv at the midpoint velocity (v^{n+1} + v^n)/2.
            let mid = [0.5 * (vn[0] + v[0]), 0.5 * (vn[1] + v[1])];
            let en = -s[0] * (dn[0] * mid[0] + dn[1] * mid[1]);
            let et = -s[0] * (dtan[0] * mid[0] + dtan[1] * mid[1]);
            [en, et, damp]
        };
        // Booked per fixed chunk and added in order, so that the budget is the same at every
        // run ([`crate::exec::ordered_sum`]).
        let parts: Vec<[f64; 3]> = g
            .vel_new
            .par_chunks_mut(CHUNK)
            .zip(g.vel.par_chunks(CHUNK))
            .zip(g.sums.par_chunks(CHUNK))
            .zip(g.walls_mask.par_chunks(CHUNK))
            .zip(g.contact.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(c, ((((vn, v), s), mask), engaged))| {
                crate::exec::add_in_order((0..vn.len()).map(|k| {
                    let e = node(&mut vn[k], &v[k], &s[k], mask[k], &mut engaged[k]);
                    // An image node of a periodic grid does the work of its own node again.
                    if owns(c * CHUNK + k) {
                        e
                    } else {
                        [0.0; 3]
                    }
                }))
            })
            .collect();
        let e = crate::exec::add_in_order(parts);
        for (b, v) in self.booked.iter_mut().zip(e) {
            *b += v;
        }
    }

    /// One loop over the points (parallel in chunks), see [`PointPass`].
    #[inline(always)]
    pub(super) fn point_pass(&mut self, pass: PointPass) -> Result<()> {
        // The transfer is a const parameter so the FLIP path carries no APIC branches.
        if self.transfer == Transfer::Apic {
            self.point_pass_with::<true>(pass)
        } else {
            self.point_pass_with::<false>(pass)
        }
    }

    #[inline(always)]
    pub(super) fn point_pass_with<const APIC: bool>(&mut self, pass: PointPass) -> Result<()> {
        let g = &self.grid;
        let (h, origin) = (g.h, g.origin);
        let do_v = matches!(
            pass,
            PointPass::Velocity | PointPass::All | PointPass::VelocityAndMove
        );
        let do_x = matches!(
            pass,
            PointPass::All | PointPass::StressFromMapAndMove | PointPass::VelocityAndMove
        );
        let do_s = matches!(
            pass,
            PointPass::All | PointPass::StressFromMap | PointPass::StressFromMapAndMove
        );
        let chunk = if do_s { M::POINTS_PER_TASK } else { CHUNK };
        let gather = Gather {
            vold: &g.vel,
            vnew: &g.vel_new,
            vstrain: match pass {
                PointPass::All => &g.vel_new,
                _ => &g.vel_map,
            },
            material: &self.material,
            origin,
            h,
            nny: g.ny + 1,
            dt: self.dt,
            pic: self.params.pic_fraction,
            do_v,
            do_x,
            do_s,
        };
        let p = &mut self.points;
        let bad = (
            p.pos.par_chunks_mut(chunk),
            p.vel.par_chunks_mut(chunk),
            p.def_grad.par_chunks_mut(chunk),
            p.vol.par_chunks_mut(chunk),
            p.stress.par_chunks_mut(chunk),
            p.state.par_chunks_mut(chunk),
            p.work.par_chunks_mut(chunk),
            p.vol0.par_chunks(chunk),
            self.stencils.par_chunks(chunk),
            p.affine.par_chunks_mut(chunk),
        )
            .into_par_iter()
            .map(
                |(pos, vel, def_grad, vol, stress, state, work, vol0, stencils, affine)| {
                    let pts = PointChunk {
                        pos,
                        vel,
                        def_grad,
                        vol,
                        stress,
                        state,
                        work,
                        vol0,
                        stencils,
                        affine,
                    };
                    simd::dispatch!(gather.chunk::<APIC>(pts))
                },
            )
            .enumerate()
            .find_map_any(|(k, bad)| bad.map(|(q, why)| (k * chunk + q, why)));
        if let Some((q, why)) = bad {
            let x = self.points.pos[q];
            return Err(Error::Unstable {
                step: self.steps,
                time: self.time,
                x: ((x[0] - origin[0]) / h).max(0.0) as usize,
                y: ((x[1] - origin[1]) / h).max(0.0) as usize,
                reason: format!("material point {q}: {why}"),
            });
        }
        Ok(())
    }
}

/// What the point → grid scatter of a stripe reads ([`Mpm::p2g`]).
struct Scatter<'a, S> {
    pts: &'a Points<S>,
    order: &'a [u32],
    starts: &'a [usize],
    stencils: &'a [Stencil],
    grav: [f64; 2],
    origin: [f64; 2],
    h: f64,
    /// Nodes per grid column.
    nny: usize,
    mass: bool,
    force: bool,
    momentum: bool,
}

impl<S> Scatter<'_, S> {
    /// Scatter the points of stripe `s` into `chunk`, its node columns (and the next
    /// stripe's, which no other task of this phase touches): m_i += N m, p_i += N m v (APIC:
    /// v + C (x_i − x)), f_i += −V σ ∇N + N m g.
    // The stencil loops index several 3-arrays (weights, gradients, offsets) by node.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn stripe<const APIC: bool>(&self, s: usize, chunk: &mut [NodeSums]) {
        let Scatter {
            pts,
            order,
            starts,
            stencils,
            grav,
            origin,
            h,
            nny,
            mass,
            force,
            momentum,
        } = *self;
        let col0 = (s * STRIPE) as i64;
        for &q in &order[starts[s]..starts[s + 1]] {
            let q = q as usize;
            let st = &stencils[q];
            let m = pts.mass[q];
            let v = pts.vel[q];
            let vol = pts.vol[q];
            let sg = pts.stress[q];
            // APIC: C = B D⁻¹ with D = diag(Σ w_x d_x², Σ w_y d_y²) here.
            let (mut c, mut dx, mut dy) = ([0.0; 4], [0.0; 3], [0.0; 3]);
            if APIC {
                let d;
                (dx, dy, d) = st.apic_offsets(pts.pos[q], origin, h);
                let bm = pts.affine[q];
                c = [bm[0] / d[0], bm[1] / d[1], bm[2] / d[0], bm[3] / d[1]];
            }
            for a in 0..3 {
                let base = (st.i0 + a as i64 - col0) as usize * nny + st.j0 as usize;
                for b in 0..3 {
                    let w = st.wx[a] * st.wy[b];
                    let node = &mut chunk[base + b];
                    if mass {
                        node[0] += w * m;
                    }
                    if APIC {
                        let u = [
                            v[0] + c[0] * dx[a] + c[1] * dy[b],
                            v[1] + c[2] * dx[a] + c[3] * dy[b],
                        ];
                        node[1] += w * m * u[0];
                        node[2] += w * m * u[1];
                    } else if mass || momentum {
                        node[1] += w * m * v[0];
                        node[2] += w * m * v[1];
                    }
                    if force {
                        let gx = st.gx[a] * st.wy[b];
                        let gy = st.wx[a] * st.gy[b];
                        node[3] += -vol * (sg[0] * gx + sg[2] * gy) + w * m * grav[0];
                        node[4] += -vol * (sg[2] * gx + sg[1] * gy) + w * m * grav[1];
                    }
                }
            }
        }
    }
}

/// What a grid → point pass reads ([`Mpm::point_pass`]).
struct Gather<'a, M> {
    /// Grid velocity before the update (the FLIP reference).
    vold: &'a [[f64; 2]],
    /// v^{n+1}.
    vnew: &'a [[f64; 2]],
    /// The velocity whose gradient strains the points.
    vstrain: &'a [[f64; 2]],
    material: &'a M,
    origin: [f64; 2],
    h: f64,
    /// Nodes per grid column.
    nny: usize,
    dt: f64,
    pic: f64,
    /// Update the velocity.
    do_v: bool,
    /// Move the points.
    do_x: bool,
    /// Strain the points and update their stress.
    do_s: bool,
}

/// One chunk of the point arrays, as a grid → point pass changes them.
struct PointChunk<'a, S> {
    pos: &'a mut [[f64; 2]],
    vel: &'a mut [[f64; 2]],
    def_grad: &'a mut [[f64; 4]],
    vol: &'a mut [f64],
    stress: &'a mut [Stress],
    state: &'a mut [S],
    work: &'a mut [f64],
    vol0: &'a [f64],
    stencils: &'a [Stencil],
    affine: &'a mut [[f64; 4]],
}

impl<M: Material> Gather<'_, M> {
    /// Gather v^{n+1} (FLIP/PIC blend, or APIC's v and B), strain F ← (1 + Δt L) F with
    /// L = Σ v_i ⊗ ∇N, update the stress and the work, move x += Δt Σ N v^{n+1}; the first
    /// point (index in the chunk) whose update failed and why.
    #[inline(always)]
    fn chunk<const APIC: bool>(&self, pts: PointChunk<'_, M::State>) -> Option<(usize, String)> {
        let Gather {
            vold,
            vnew,
            vstrain,
            material: mat,
            origin,
            h,
            nny,
            dt,
            pic,
            do_v,
            do_x,
            do_s,
        } = *self;
        let PointChunk {
            pos,
            vel,
            def_grad: fg,
            vol,
            stress: sig,
            state,
            work,
            vol0,
            stencils: sts,
            affine: aff,
        } = pts;
        let mut bad = None;
        for q in 0..pos.len() {
            let st = &sts[q];
            let mut dv = [0.0; 2];
            let mut xn = [0.0; 2];
            let mut l = [0.0; 4];
            let mut bm = [0.0; 4];
            for a in 0..3 {
                let base = (st.i0 + a as i64) as usize * nny + st.j0 as usize;
                for b in 0..3 {
                    let n = base + b;
                    let w = st.wx[a] * st.wy[b];
                    if do_v {
                        dv[0] += w * (vnew[n][0] - vold[n][0]);
                        dv[1] += w * (vnew[n][1] - vold[n][1]);
                    }
                    if do_x || pic > 0.0 || APIC {
                        xn[0] += w * vnew[n][0];
                        xn[1] += w * vnew[n][1];
                    }
                    if APIC && do_v {
                        let d = [
                            origin[0] + (st.i0 + a as i64) as f64 * h - pos[q][0],
                            origin[1] + (st.j0 + b as i64) as f64 * h - pos[q][1],
                        ];
                        let u = vnew[n];
                        bm[0] += w * u[0] * d[0];
                        bm[1] += w * u[0] * d[1];
                        bm[2] += w * u[1] * d[0];
                        bm[3] += w * u[1] * d[1];
                    }
                    if do_s {
                        let gx = st.gx[a] * st.wy[b];
                        let gy = st.wx[a] * st.gy[b];
                        let v = vstrain[n];
                        l[0] += v[0] * gx;
                        l[1] += v[0] * gy;
                        l[2] += v[1] * gx;
                        l[3] += v[1] * gy;
                    }
                }
            }
            if do_v && APIC {
                vel[q] = xn;
                aff[q] = bm;
            } else if do_v {
                // FLIP increment, blended with the PIC velocity Σ N v^{n+1}.
                vel[q][0] = (1.0 - pic) * (vel[q][0] + dv[0]) + pic * xn[0];
                vel[q][1] = (1.0 - pic) * (vel[q][1] + dv[1]) + pic * xn[1];
            }
            if do_s {
                let f = fg[q];
                let a = [1.0 + dt * l[0], dt * l[1], dt * l[2], 1.0 + dt * l[3]];
                let fnew = [
                    a[0] * f[0] + a[1] * f[2],
                    a[0] * f[1] + a[1] * f[3],
                    a[2] * f[0] + a[3] * f[2],
                    a[2] * f[1] + a[3] * f[3],
                ];
                let j = fnew[0] * fnew[3] - fnew[1] * fnew[2];
                if (j.is_nan() || j <= 0.0) && bad.is_none() {
                    bad = Some((q, format!("det F = {j:e} ≤ 0")));
                }
                fg[q] = fnew;
                let vnew_ = j * vol0[q];
                let de = [dt * l[0], dt * l[3], 0.5 * dt * (l[1] + l[2])];
                let spin = 0.5 * dt * (l[1] - l[2]);
                let s0 = sig[q];
                let s1 = match mat.update_stress(&s0, &de, spin, dt, &mut state[q]) {
                    Ok(s1) => s1,
                    Err(why) => {
                        bad = bad.or(Some((q, why)));
                        s0
                    }
                };
                let smid = [
                    0.5 * (s0[0] + s1[0]),
                    0.5 * (s0[1] + s1[1]),
                    0.5 * (s0[2] + s1[2]),
                ];
                work[q] += 0.5
                    * (vol[q] + vnew_)
                    * (smid[0] * de[0] + smid[1] * de[1] + 2.0 * smid[2] * de[2]);
                sig[q] = s1;
                vol[q] = vnew_;
            }
            if do_x {
                pos[q][0] += dt * xn[0];
                pos[q][1] += dt * xn[1];
            }
        }
        bad
    }
}
