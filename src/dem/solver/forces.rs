//! Steps 3–5 of the DEM step ([`super`]): the neighbour lists, the parallel force pass over
//! fixed chunks of grains, and the kick pass that sums each grain's forces in a fixed order
//! and applies the second half-kick (and, within a run, the next step's first half-kick and
//! drift).

use rayon::prelude::*;

use super::*;
use crate::dem::params::min_image;

impl Dem {
    /// Steps 3–5: rebuild the lists if needed, evaluate all forces at the current positions
    /// and velocities (springs advance by `dt_hist`, 0: evaluate without advancing;
    /// dissipation accrues over `dt_hist`) and apply the second half-kick
    /// **v** += `kick`·**F**^end/m (`kick` = ½Δt; 0: no kick).
    ///
    /// Two parallel passes over fixed chunks of [`GRAIN_CHUNK`] grains. The pair list is
    /// sorted by first grain, so a chunk owns a contiguous run of pairs (and of wall pairs).
    /// *Force pass*: each chunk writes the body forces of its grains, resolves its pairs and
    /// wall pairs and adds each force straight to its grains; the force of a pair on a second
    /// grain beyond the chunk is queued, in pair order, in the chunk's own buffer. *Kick
    /// pass*: each chunk adds the queued forces on its grains (earlier chunks in order, each
    /// buffer in order) and the rapier contacts, then kicks. Every grain's force is thus
    /// summed in an order fixed by the pair list and the chunk size, whatever the thread
    /// count; there is no per-pair force array and no per-grain pair index to gather through.
    ///
    /// `next`: the step size of a following step of the same run, whose first half-kick and
    /// drift (with this step's events applied first) then happen in the kick pass.
    pub(super) fn compute_forces(
        &mut self,
        dt_hist: f64,
        loads: Option<&ExternalLoads>,
        kick: f64,
        next: Option<f64>,
    ) {
        if self.moved {
            self.moved = false;
            self.wall_travel = 0.0;
            if let Some([a, b]) = self.params.periodic_x {
                for x in &mut self.grains.x {
                    *x = a + (*x - a).rem_euclid(b - a);
                }
            }
            self.detector.build(
                &self.grains,
                &self.walls,
                self.params.periodic_x,
                &mut self.pairs,
                &mut self.wall_pairs,
            );
        }
        if dt_hist == 0.0 || self.vxp.len() != self.grains.len() {
            self.vxp.clone_from(&self.grains.vx);
            self.vyp.clone_from(&self.grains.vy);
            self.wp.clone_from(&self.grains.omega);
        }
        let n = self.grains.len();
        debug_assert!(self.pairs.first.len() == n + 1 && self.wall_pairs.first.len() == n + 1);
        let nch = n.div_ceil(GRAIN_CHUNK);
        if self.events.len() < nch {
            self.events.resize_with(nch, Vec::new);
            self.wall_events.resize_with(nch, Vec::new);
            self.queued.resize_with(nch, Vec::new);
            self.cand.resize_with(nch, Vec::new);
        }
        self.event_chunks = [nch, nch];
        self.parts.resize(nch, Part::default());

        // Force pass.
        let g = &mut self.grains;
        let (x, y, vx, vy, om) = (&g.x[..], &g.y[..], &g.vx[..], &g.vy[..], &g.omega[..]);
        let (rad, m) = (&g.radius[..], &g.mass[..]);
        let (vxp, vyp, wp) = (&self.vxp[..], &self.vyp[..], &self.wp[..]);
        let (law, wlaw, walls) = (self.grain_law, self.wall_law, &self.walls);
        let wall_v = &self.wall_velocity[..];
        let pl = &mut self.pairs;
        let wl = &mut self.wall_pairs;
        let (pi, pj, first) = (&pl.i[..], &pl.j[..], &pl.first[..]);
        let (wg, ww, wfirst) = (&wl.grain[..], &wl.wall[..], &wl.first[..]);
        let grav = self.params.gravity;
        let period = self.params.period();
        let alpha = self.params.global_damping;
        let empty: &[f64] = &[];
        let (lx, ly, lt) = match loads {
            Some(l) => (&l.fx[..], &l.fy[..], &l.torque[..]),
            None => (empty, empty, empty),
        };
        let span = Span {
            c0: 0,
            p0: 0,
            w0: 0,
            fx: &mut g.fx,
            fy: &mut g.fy,
            tq: &mut g.torque,
            state: &mut pl.state,
            flags: &mut pl.flags,
            wstate: &mut wl.state,
            events: &mut self.events[..nch],
            wevents: &mut self.wall_events[..nch],
            queued: &mut self.queued[..nch],
            cand: &mut self.cand[..nch],
            parts: &mut self.parts[..nch],
        };
        let inputs = ForceInputs {
            x,
            y,
            vx,
            vy,
            om,
            rad,
            m,
            vxp,
            vyp,
            wp,
            law,
            wlaw,
            walls,
            wall_v,
            pi,
            pj,
            wg,
            ww,
            grav,
            period,
            alpha,
            lx,
            ly,
            lt,
            dt_hist,
        };
        let force_pass = |s: Span| force_chunk(s, &inputs);
        for_each_chunk(span, first, wfirst, &force_pass);
        let total = self.parts.iter().fold(Part::default(), |a, b| a.merge(b));
        // Which earlier chunks queued forces for each chunk.
        self.reach_from.clear();
        self.reach_from.extend(0..nch as u32);
        for (c, p) in self.parts.iter().enumerate() {
            for r in c + 1..=(p.reach as usize).min(nch - 1) {
                self.reach_from[r] = self.reach_from[r].min(c as u32);
            }
        }
        // Contacts through rapier (polygon grains or walls), summed per grain.
        let mut total = total;
        if let Some(sc) = self.shapes.as_mut() {
            let vp = (&self.vxp[..], &self.vyp[..], &self.wp[..]);
            let (gl, wl) = (&self.grain_law, &self.wall_law);
            let s = sc.evaluate(&self.grains, &self.walls, vp, gl, wl, dt_hist);
            total = total.add_shapes(&s);
        }
        let sf: &[[f64; 3]] = self.shapes.as_ref().map_or(&[], |s| s.grain_force());
        // Kick pass: queued forces from earlier chunks, rapier contacts, second half-kick; in
        // a run, then this step's events on the chunk's grains and the next kick and drift.
        let g = &mut self.grains;
        let n = g.len();
        let (im, ij) = (&self.inv_mass[..], &self.inv_inertia[..]);
        let (queued, reach_from) = (&self.queued, &self.reach_from);
        let (events, wevents) = (&self.events[..nch], &self.wall_events[..nch]);
        let (xr, yr, lim) = self.detector.reference();
        let drift = next.map(|dt| Drift::new(dt, n, xr, yr, lim));
        let moved = chunks(g, &mut self.vxp, &mut self.vyp, &mut self.wp)
            .enumerate()
            .map(|(c, mut k)| {
                let (fx, fy, tq) = (&mut *k.fx, &mut *k.fy, &mut *k.tq);
                let (a, len) = (c * GRAIN_CHUNK, fx.len());
                let from = reach_from[c] as usize;
                for q in queued[from..c].iter().flatten() {
                    let l = (q.j as usize).wrapping_sub(a);
                    if l < len {
                        fx[l] += q.f[0];
                        fy[l] += q.f[1];
                        tq[l] += q.f[2];
                    }
                }
                for l in 0..len {
                    let i = a + l;
                    if let Some(q) = sf.get(i) {
                        fx[l] += q[0];
                        fy[l] += q[1];
                        tq[l] += q[2];
                    }
                    k.vx[l] += kick * im[i] * fx[l];
                    k.vy[l] += kick * im[i] * fy[l];
                    k.w[l] += kick * ij[i] * tq[l];
                }
                let Some(drift) = &drift else {
                    return false;
                };
                // This step's events on the chunk's grains, in the order of the serial loop
                // (`apply_events`): grain pairs by chunk and pair, then wall pairs.
                for e in events[from..=c].iter().flatten().chain(&wevents[c]) {
                    e.apply_to_chunk(a, fx, fy, tq);
                }
                drift.apply(a, &mut k, im, ij)
            })
            .reduce(|| false, |a, b| a || b);
        if let Some(d) = &drift {
            self.moved |= moved || !d.has_reference;
        }
        let b = &mut self.budget;
        b.elastic_normal = total.e_n;
        b.elastic_tangential = total.e_t;
        b.elastic_rolling = total.e_r;
        b.dissipated_normal += total.d_n;
        b.dissipated_friction += total.d_f;
        b.dissipated_rolling += total.d_r;
        b.dissipated_global += total.d_glob * dt_hist;
        b.work_external += total.w_ext * dt_hist;
        self.contacts = total.contacts as usize;
        self.deepest = self.deepest.deeper(total.deepest);
        if dt_hist > 0.0 {
            self.contact_steps += total.contacts as u64;
        }
        self.forces_valid = true;
    }
}

/// One grain chunk's arrays as the integrator passes see them: positions, velocities, angle,
/// the predictor velocities v* of the dashpots, and the force, torque.
pub(super) struct Chunk<'a> {
    x: &'a mut [f64],
    y: &'a mut [f64],
    vx: &'a mut [f64],
    vy: &'a mut [f64],
    th: &'a mut [f64],
    w: &'a mut [f64],
    vxp: &'a mut [f64],
    vyp: &'a mut [f64],
    wp: &'a mut [f64],
    fx: &'a mut [f64],
    fy: &'a mut [f64],
    tq: &'a mut [f64],
}

/// The grains (and their predictor velocities) in chunks of [`GRAIN_CHUNK`].
pub(super) fn chunks<'a>(
    g: &'a mut Grains,
    vxp: &'a mut [f64],
    vyp: &'a mut [f64],
    wp: &'a mut [f64],
) -> impl IndexedParallelIterator<Item = Chunk<'a>> {
    let c = GRAIN_CHUNK;
    g.x.par_chunks_mut(c)
        .zip(g.y.par_chunks_mut(c))
        .zip(g.vx.par_chunks_mut(c))
        .zip(g.vy.par_chunks_mut(c))
        .zip(g.angle.par_chunks_mut(c))
        .zip(g.omega.par_chunks_mut(c))
        .zip(vxp.par_chunks_mut(c))
        .zip(vyp.par_chunks_mut(c))
        .zip(wp.par_chunks_mut(c))
        .zip(g.fx.par_chunks_mut(c))
        .zip(g.fy.par_chunks_mut(c))
        .zip(g.torque.par_chunks_mut(c))
        .map(
            |(((((((((((x, y), vx), vy), th), w), vxp), vyp), wp), fx), fy), tq)| Chunk {
                x,
                y,
                vx,
                vy,
                th,
                w,
                vxp,
                vyp,
                wp,
                fx,
                fy,
                tq,
            },
        )
}

/// Steps 1–2 of a step of size `dt` and the skin check of step 3.
pub(super) struct Drift<'a> {
    dt: f64,
    /// Positions at the last list build and the squared skin/2.
    xr: &'a [f64],
    yr: &'a [f64],
    lim: f64,
    /// Whether the reference positions are those of these grains (else rebuild).
    pub(super) has_reference: bool,
}

impl<'a> Drift<'a> {
    pub(super) fn new(dt: f64, n: usize, xr: &'a [f64], yr: &'a [f64], lim: f64) -> Self {
        Drift {
            dt,
            xr,
            yr,
            lim,
            has_reference: xr.len() == n,
        }
    }

    /// First half-kick with the chunk's forces, drift and predictor velocities of the chunk
    /// starting at grain `o`; whether a grain of it moved more than skin/2 since the last
    /// list build (or is not finite).
    pub(super) fn apply(&self, o: usize, k: &mut Chunk, im: &[f64], ij: &[f64]) -> bool {
        let (dt, h, len) = (self.dt, 0.5 * self.dt, k.x.len());
        let (im, ij) = (&im[o..o + len], &ij[o..o + len]);
        for l in 0..len {
            let (ax, ay, al) = (
                h * im[l] * k.fx[l],
                h * im[l] * k.fy[l],
                h * ij[l] * k.tq[l],
            );
            k.vx[l] += ax;
            k.vy[l] += ay;
            k.w[l] += al;
            k.x[l] += dt * k.vx[l];
            k.y[l] += dt * k.vy[l];
            k.th[l] += dt * k.w[l];
            k.vxp[l] = k.vx[l] + ax;
            k.vyp[l] = k.vy[l] + ay;
            k.wp[l] = k.w[l] + al;
        }
        if !self.has_reference {
            return true;
        }
        let (xr, yr) = (&self.xr[o..o + len], &self.yr[o..o + len]);
        let mut far = false;
        for l in 0..len {
            let (dx, dy) = (k.x[l] - xr[l], k.y[l] - yr[l]);
            let r2 = dx * dx + dy * dy;
            // A non-finite grain forces a rebuild too.
            far |= r2 > self.lim || r2.is_nan();
        }
        far
    }
}

/// A force queued by one chunk's force pass for a grain of a later chunk.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct JForce {
    /// The grain (second grain of the pair).
    j: u32,
    /// [F_x, F_y, torque] on it.
    f: [f64; 3],
}

/// The force pass's mutable data for a run of whole grain chunks `c0..c0 + parts.len()`: their
/// grains' force slots, the pairs and wall pairs whose (first) grain lies in them, and one
/// output buffer of each kind per chunk.
struct Span<'a> {
    /// First chunk.
    c0: usize,
    /// First pair of the run.
    p0: usize,
    /// First wall pair of the run.
    w0: usize,
    fx: &'a mut [f64],
    fy: &'a mut [f64],
    tq: &'a mut [f64],
    state: &'a mut [ContactState],
    flags: &'a mut [u8],
    wstate: &'a mut [ContactState],
    events: &'a mut [Vec<Event>],
    wevents: &'a mut [Vec<Event>],
    queued: &'a mut [Vec<JForce>],
    cand: &'a mut [Vec<u32>],
    parts: &'a mut [Part],
}

impl Span<'_> {
    /// Split before chunk `c` (c0 < c < c0 + chunks); `first`/`wfirst` index the pairs and wall
    /// pairs by grain.
    fn split(self, c: usize, first: &[u32], wfirst: &[u32]) -> (Self, Self) {
        let (k, gr) = (c - self.c0, (c - self.c0) * GRAIN_CHUNK);
        let p = first[c * GRAIN_CHUNK] as usize;
        let w = wfirst[c * GRAIN_CHUNK] as usize;
        let (fx0, fx1) = self.fx.split_at_mut(gr);
        let (fy0, fy1) = self.fy.split_at_mut(gr);
        let (tq0, tq1) = self.tq.split_at_mut(gr);
        let (s0, s1) = self.state.split_at_mut(p - self.p0);
        let (f0, f1) = self.flags.split_at_mut(p - self.p0);
        let (ws0, ws1) = self.wstate.split_at_mut(w - self.w0);
        let (e0, e1) = self.events.split_at_mut(k);
        let (we0, we1) = self.wevents.split_at_mut(k);
        let (q0, q1) = self.queued.split_at_mut(k);
        let (c0, c1) = self.cand.split_at_mut(k);
        let (pa0, pa1) = self.parts.split_at_mut(k);
        (
            Span {
                c0: self.c0,
                p0: self.p0,
                w0: self.w0,
                fx: fx0,
                fy: fy0,
                tq: tq0,
                state: s0,
                flags: f0,
                wstate: ws0,
                events: e0,
                wevents: we0,
                queued: q0,
                cand: c0,
                parts: pa0,
            },
            Span {
                c0: c,
                p0: p,
                w0: w,
                fx: fx1,
                fy: fy1,
                tq: tq1,
                state: s1,
                flags: f1,
                wstate: ws1,
                events: e1,
                wevents: we1,
                queued: q1,
                cand: c1,
                parts: pa1,
            },
        )
    }
}

/// Run `f` on every chunk of `s`, one [`Span`] of one chunk each, splitting in halves with
/// `rayon::join` (no allocation; which thread runs a chunk does not change what it computes).
fn for_each_chunk<F: Fn(Span) + Sync>(s: Span, first: &[u32], wfirst: &[u32], f: &F) {
    match s.parts.len() {
        0 => {}
        1 => f(s),
        n => {
            let mid = s.c0 + n / 2;
            let (a, b) = s.split(mid, first, wfirst);
            rayon::join(
                || for_each_chunk(a, first, wfirst, f),
                || for_each_chunk(b, first, wfirst, f),
            );
        }
    }
}

/// What the force pass reads: the grains' state, the contact laws and walls, the pair lists,
/// the body forces and external loads, and the step over which springs advance.
#[derive(Clone, Copy)]
struct ForceInputs<'a> {
    x: &'a [f64],
    y: &'a [f64],
    vx: &'a [f64],
    vy: &'a [f64],
    om: &'a [f64],
    rad: &'a [f64],
    m: &'a [f64],
    vxp: &'a [f64],
    vyp: &'a [f64],
    wp: &'a [f64],
    law: Law,
    wlaw: Law,
    walls: &'a [Wall],
    wall_v: &'a [[f64; 2]],
    pi: &'a [u32],
    pj: &'a [u32],
    wg: &'a [u32],
    ww: &'a [u32],
    grav: [f64; 2],
    period: Option<f64>,
    alpha: f64,
    lx: &'a [f64],
    ly: &'a [f64],
    lt: &'a [f64],
    dt_hist: f64,
}

crate::exec::simd::multiversion! {
    /// The force pass of one chunk of grains (`s`), see [`Dem::compute_forces`]; compiled for
    /// this CPU's vector extensions ([`crate::exec::simd`]).
    fn force_chunk(s: Span<'_>, inputs: &ForceInputs<'_>) {
        let ForceInputs {
            x,
            y,
            vx,
            vy,
            om,
            rad,
            m,
            vxp,
            vyp,
            wp,
            law,
            wlaw,
            walls,
            wall_v,
            pi,
            pj,
            wg,
            ww,
            grav,
            period,
            alpha,
            lx,
            ly,
            lt,
            dt_hist,
        } = *inputs;
        let (c, a, len) = (s.c0, s.c0 * GRAIN_CHUNK, s.fx.len());
        let (fx, fy, tq) = (s.fx, s.fy, s.tq);
        let (ev, wev, queue) = (&mut s.events[0], &mut s.wevents[0], &mut s.queued[0]);
        ev.clear();
        wev.clear();
        queue.clear();
        let mut part = Part {
            reach: c as u32,
            ..Part::default()
        };
        // Gravity, global damping (predictor velocity) and external loads; their work
        // over the step uses Δx = Δt v_½.
        for k in 0..len {
            let i = a + k;
            fx[k] = m[i] * grav[0];
            fy[k] = m[i] * grav[1];
            tq[k] = 0.0;
            if alpha != 0.0 {
                fx[k] -= alpha * m[i] * vxp[i];
                fy[k] -= alpha * m[i] * vyp[i];
                part.d_glob += alpha * m[i] * (vxp[i] * vx[i] + vyp[i] * vy[i]);
            }
            if !lx.is_empty() {
                fx[k] += lx[i];
                part.w_ext += lx[i] * vx[i];
            }
            if !ly.is_empty() {
                fy[k] += ly[i];
                part.w_ext += ly[i] * vy[i];
            }
            if !lt.is_empty() {
                tq[k] += lt[i];
                part.w_ext += lt[i] * om[i];
            }
        }
        let (state, flags) = (s.state, s.flags);
        let (p0, end) = (s.p0, a + len);
        let (ci, cj) = (&pi[p0..p0 + state.len()], &pj[p0..p0 + state.len()]);
        // Most pairs of a Verlet list are apart now and were apart at the last
        // evaluation: skip them in a tight first pass.
        let cand = candidates(ci, cj, flags, x, y, rad, period, &mut s.cand[0]);
        for &k in cand {
            let k = k as usize;
            let (i, j) = (ci[k] as usize, cj[k] as usize);
            let (dx, dy) = (min_image(x[j] - x[i], period), y[j] - y[i]);
            let (ri, rj) = (rad[i], rad[j]);
            let d2 = dx * dx + dy * dy;
            let rs = ri + rj;
            let d = d2.sqrt();
            let (nx, ny) = if d > 0.0 {
                (dx / d, dy / d)
            } else {
                (1.0, 0.0)
            };
            let (tx, ty) = (-ny, nx);
            // Mid-step (current) and predictor relative velocities.
            let (dvx, dvy) = (vx[i] - vx[j], vy[i] - vy[j]);
            let (wi, wj) = (om[i], om[j]);
            let (ex, ey) = (vxp[i] - vxp[j], vyp[i] - vyp[j]);
            let (pwi, pwj) = (wp[i], wp[j]);
            let (mi, mj) = (m[i], m[j]);
            let motion = Motion {
                delta: rs - d,
                u: [dvx * nx + dvy * ny, ex * nx + ey * ny],
                v_t: [
                    dvx * tx + dvy * ty + wi * ri + wj * rj,
                    ex * tx + ey * ty + pwi * ri + pwj * rj,
                ],
                w: [wi - wj, pwi - pwj],
                m_eff: mi * mj / (mi + mj),
                r_eff: ri * rj / rs,
            };
            let r = law.resolve(&motion, &mut state[k], dt_hist);
            flags[k] = if r.touching { PAIR_TOUCHING } else { 0 };
            part.deepest = part.deepest.deeper(Overlap {
                relative: motion.delta / ri.min(rj),
                i: i as u32,
                j: j as u32,
            });
            let [an, at, ar] = r.apply;
            let (f0, f1) = (-an * nx + at * tx, -an * ny + at * ty);
            let li = i - a;
            fx[li] += f0;
            fy[li] += f1;
            tq[li] += ri * at + ar;
            if j < end {
                let lj = j - a;
                fx[lj] -= f0;
                fy[lj] -= f1;
                tq[lj] += rj * at - ar;
            } else {
                queue.push(JForce {
                    j: j as u32,
                    f: [-f0, -f1, rj * at - ar],
                });
                part.reach = part.reach.max((j / GRAIN_CHUNK) as u32);
            }
            if r.event {
                let s = &state[k];
                let (dn, dt, dm) = (s.f_n - an, s.f_t - at, s.m_r - ar);
                ev.push(Event {
                    i: i as u32,
                    j: j as u32,
                    d: [
                        -dn * nx + dt * tx,
                        -dn * ny + dt * ty,
                        ri * dt + dm,
                        rj * dt - dm,
                    ],
                });
            }
            part = part.add(&r);
        }
        let (wstate, w0) = (s.wstate, s.w0);
        for k in 0..wstate.len() {
            let (i, wi) = (wg[w0 + k] as usize, ww[w0 + k] as usize);
            let (dist, [nx, ny]) = walls[wi].distance([x[i], y[i]]);
            let ri = rad[i];
            if dist >= ri && !wstate[k].touching() {
                continue;
            }
            let (tx, ty) = (-ny, nx);
            let (w, w1) = (om[i], wp[i]);
            // Velocities relative to the wall (at rest unless it was set moving).
            let [ux, uy] = wall_v.get(wi).copied().unwrap_or([0.0; 2]);
            let (rx, ry, rxp, ryp) = (vx[i] - ux, vy[i] - uy, vxp[i] - ux, vyp[i] - uy);
            let motion = Motion {
                delta: ri - dist,
                u: [rx * nx + ry * ny, rxp * nx + ryp * ny],
                v_t: [rx * tx + ry * ty + w * ri, rxp * tx + ryp * ty + w1 * ri],
                w: [w, w1],
                m_eff: m[i],
                r_eff: ri,
            };
            let r = wlaw.resolve(&motion, &mut wstate[k], dt_hist);
            part.deepest = part.deepest.deeper(Overlap {
                relative: motion.delta / ri,
                i: i as u32,
                j: u32::MAX,
            });
            let [an, at, ar] = r.apply;
            let li = i - a;
            fx[li] += -an * nx + at * tx;
            fy[li] += -an * ny + at * ty;
            tq[li] += ri * at + ar;
            if r.event {
                let st = &wstate[k];
                let (dn, dt, dm) = (st.f_n - an, st.f_t - at, st.m_r - ar);
                wev.push(Event {
                    i: i as u32,
                    j: u32::MAX,
                    d: [-dn * nx + dt * tx, -dn * ny + dt * ty, ri * dt + dm, 0.0],
                });
            }
            part = part.add(&r);
        }
        s.parts[0] = part;
    }
}

/// The pairs (indices into `pi`/`pj`) whose grains overlap now or overlapped at the last
/// evaluation (`flags`), written into `buf` without a branch per pair (≈ 90 % of the pairs
/// of a Verlet list are apart, in no predictable pattern). Kept out of line so that this loop
/// has the registers to itself; one loop per case of `period`, so that the aperiodic one has
/// no minimal image in it (a branch per pair there cost ≈ 4 % of the DEM benchmark).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn candidates<'b>(
    pi: &[u32],
    pj: &[u32],
    flags: &[u8],
    x: &[f64],
    y: &[f64],
    rad: &[f64],
    period: Option<f64>,
    buf: &'b mut Vec<u32>,
) -> &'b [u32] {
    let p = Pairs {
        pi,
        pj,
        flags,
        x,
        y,
        rad,
    };
    match period {
        None => p.near(|dx| dx, buf),
        Some(l) => p.near(|dx| dx - l * (dx / l).round(), buf),
    }
}

/// The pair list and the grains, as [`candidates`] reads them.
struct Pairs<'a> {
    pi: &'a [u32],
    pj: &'a [u32],
    flags: &'a [u8],
    x: &'a [f64],
    y: &'a [f64],
    rad: &'a [f64],
}

impl Pairs<'_> {
    /// [`candidates`] with the separation along x mapped by `image`.
    #[inline(always)]
    fn near<'b>(&self, image: impl Fn(f64) -> f64, buf: &'b mut Vec<u32>) -> &'b [u32] {
        let Pairs {
            pi,
            pj,
            flags,
            x,
            y,
            rad,
        } = *self;
        let n = pi.len().min(pj.len()).min(flags.len());
        if buf.len() < n {
            buf.resize(n, 0);
        }
        let mut c = 0;
        for k in 0..n {
            let (i, j) = (pi[k] as usize, pj[k] as usize);
            let (dx, dy) = (image(x[j] - x[i]), y[j] - y[i]);
            let rs = rad[i] + rad[j];
            let d2 = dx * dx + dy * dy;
            // A NaN distance counts as near, so the force loop sees (and propagates) it.
            let near = d2 < rs * rs || d2.is_nan();
            buf[c] = k as u32;
            c += usize::from(near | (flags[k] & PAIR_TOUCHING != 0));
        }
        &buf[..c]
    }
}
