//! The DEM system and its time step.
//!
//! Integration is velocity Verlet (as in LAMMPS's `nve/sphere`), chosen over semi-implicit
//! Euler because it is time-reversible and symplectic for the conservative part (springs,
//! gravity), so an elastic gas keeps its energy without drift, and because it evaluates the
//! forces once per step like Euler does:
//!
//! 1. **v** ← **v** + ½Δt **F**/m, ω ← ω + ½Δt T/J (forces of the previous step);
//! 2. **x** ← **x** + Δt **v**, θ ← θ + Δt ω;
//! 3. rebuild the neighbour list if some grain moved more than skin/2 since the last build;
//! 4. **F**, T from contacts, gravity, external loads and global damping, evaluated with the new
//!    positions: springs advance with the mid-step velocities **v**_½ (exact mid-point rule);
//!    each contact's own normal dashpot is implicit and everything else uses the predictor
//!    **v*** = **v**_½ + ½Δt **F**_k/m (see [`crate::dem::contact`]: plain velocity Verlet,
//!    feeding **v**_½ to the dashpot as LAMMPS does, misses e by 3.6 % at λ = 0.1, the
//!    predictor alone by 1.3 %, this scheme by ≤ 0.6 %, falling 4× per halving of Δt);
//! 5. **v** ← **v** + ½Δt **F**^end/m, ω ← ω + ½Δt T^end/J, where **F**^end is **F** except for
//!    contacts that began or ended inside the step, whose impulse is the trapezoid over the
//!    part of the step they existed; those contacts are collected as sparse *events*, and
//!    after the kick the force arrays are set to the true **F**_{k+1}, from which the next step
//!    starts.
//!
//! Forces are computed per contact in parallel into per-pair slots and then gathered per
//! grain in parallel (each grain sums its own pairs in a fixed order), so results do not
//! depend on the number of threads.
//!
//! Time step: seed eq. 5.59–5.60, Δt = λ Δt_cr with λ = 0.1 by default; see [`critical_step`].

use rayon::prelude::*;

use super::contact::{self, ContactOut, ContactParams, Event, Law, Motion};
use super::detect_rapier::RapierDetector;
use super::energy::Energy;
use super::grains::Grains;
use super::neighbours::{Detector, PairList, WallList, PAIR_ACTIVE, PAIR_TOUCHING};
use super::shape_contacts::{ShapeContacts, ShapeSums};
use super::walls::Wall;
use crate::{Error, Result};

/// Pairs per parallel chunk of the force loop.
const PAIR_CHUNK: usize = 2048;
/// Grains per parallel chunk of the integrator loops.
const GRAIN_CHUNK: usize = 1024;

/// Parameters of a DEM system, SI.
#[derive(Clone, Debug, PartialEq)]
pub struct DemParams {
    /// Grain–grain contact law.
    pub grain: ContactParams,
    /// Grain–wall contact law.
    pub wall: ContactParams,
    /// Gravitational acceleration **g** (m/s²).
    pub gravity: [f64; 2],
    /// Time step; `None` takes λ Δt_cr. A value above λ Δt_cr is refused.
    pub dt: Option<f64>,
    /// Safety factor λ of seed eq. 5.60 (0.1 in the seed).
    pub lambda: f64,
    /// Verlet skin as a fraction of the largest grain diameter (e.g. 0.2).
    pub skin_fraction: f64,
    /// Global damping rate α (1/s) of seed eq. 5.57, c = α m; 0 = off (the default).
    pub global_damping: f64,
}

impl DemParams {
    /// Parameters with `grain` and `wall` laws, gravity, automatic step, λ = 0.1, skin 0.2 d_max,
    /// no global damping.
    pub fn new(grain: ContactParams, wall: ContactParams, gravity: [f64; 2]) -> Self {
        DemParams {
            grain,
            wall,
            gravity,
            dt: None,
            lambda: 0.1,
            skin_fraction: 0.2,
            global_damping: 0.0,
        }
    }
}

/// Critical time step of the system: seed eq. 5.59, Δt_cr = 2(√(1 + ξ²) − ξ)/ω, taken as the
/// smallest over the springs present, each with the inertia it moves:
/// * normal, grain–grain and grain–wall: ω = √(k_n/m_min) (the seed's choice), ξ the normal
///   damping ratio (from e, plus γ_n m_min/(2√(k_n m_min)));
/// * tangential: ω = √(3k_t/m_min) — the contact point of a disk (J = ½mR²) has effective mass
///   m/3 — with ξ = 0;
/// * rolling: ω = √(k_r/J_min), ξ = 0.
///
/// Returns ∞ if there are no grains.
pub fn critical_step(p: &DemParams, m_min: f64, j_min: f64) -> f64 {
    if !m_min.is_finite() {
        return f64::INFINITY;
    }
    let mut dt = f64::INFINITY;
    for c in [&p.grain, &p.wall] {
        let xi = c.damping_ratio() + c.gamma_n * m_min / (2.0 * (c.k_n * m_min).sqrt());
        dt = dt.min(contact::critical_step(c.k_n, m_min, xi));
        if c.k_t > 0.0 {
            dt = dt.min(contact::critical_step(3.0 * c.k_t, m_min, 0.0));
        }
        if c.rolling_stiffness > 0.0 {
            dt = dt.min(contact::critical_step(c.rolling_stiffness, j_min, 0.0));
        }
    }
    dt
}

/// Smallest effective mass of a polygon grain at a contact point (∞ if none):
/// m_c = 1/(1/m + R_b²/J), R_b the bounding radius — a point on a rotating body is lighter than
/// its mass (a disk's contact point has m/3 tangentially, which [`critical_step`] already
/// builds in through 3k_t). Passed as m_min for polygons, it makes the normal and tangential
/// critical steps conservative.
fn polygon_contact_mass(g: &Grains) -> f64 {
    (0..g.len())
        .filter(|&i| !g.is_disk(i))
        .map(|i| 1.0 / (1.0 / g.mass[i] + g.radius[i] * g.radius[i] / g.inertia[i]))
        .fold(f64::INFINITY, f64::min)
}

/// External loads held during [`Dem::advance_with`] (e.g. hydrodynamic force and torque from
/// the fluid, seed eq. 5.53–5.54). Empty vectors mean none.
#[derive(Clone, Debug, Default)]
pub struct ExternalLoads {
    /// Force x per grain.
    pub fx: Vec<f64>,
    /// Force y per grain.
    pub fy: Vec<f64>,
    /// Torque per grain.
    pub torque: Vec<f64>,
}

/// Per-chunk sums of one force evaluation.
#[derive(Clone, Copy, Debug, Default)]
struct Part {
    e_n: f64,
    e_t: f64,
    e_r: f64,
    d_n: f64,
    d_f: f64,
    d_r: f64,
    contacts: f64,
}

impl Part {
    #[inline(always)]
    fn add(mut self, o: &ContactOut) -> Self {
        self.e_n += o.e_normal;
        self.e_t += o.e_tangential;
        self.e_r += o.e_rolling;
        self.d_n += o.d_normal;
        self.d_f += o.d_friction;
        self.d_r += o.d_rolling;
        self.contacts += f64::from(u8::from(o.touching));
        self
    }

    fn add_shapes(mut self, o: &ShapeSums) -> Self {
        self.e_n += o.e_n;
        self.e_t += o.e_t;
        self.e_r += o.e_r;
        self.d_n += o.d_n;
        self.d_f += o.d_f;
        self.d_r += o.d_r;
        self.contacts += o.contacts as f64;
        self
    }

    fn merge(mut self, o: &Part) -> Self {
        self.e_n += o.e_n;
        self.e_t += o.e_t;
        self.e_r += o.e_r;
        self.d_n += o.d_n;
        self.d_f += o.d_f;
        self.d_r += o.d_r;
        self.contacts += o.contacts;
        self
    }
}

/// A DEM system: grains, walls, contact laws, neighbour lists, clock and energy budget.
#[derive(Clone, Debug)]
pub struct Dem {
    /// The grains.
    pub grains: Grains,
    /// The walls.
    pub walls: Vec<Wall>,
    params: DemParams,
    grain_law: Law,
    wall_law: Law,
    dt: f64,
    dt_cr: f64,
    time: f64,
    steps: u64,
    detector: Detector,
    pairs: PairList,
    wall_pairs: WallList,
    parts: Vec<Part>,
    gparts: Vec<[f64; 2]>,
    /// 1/m and 1/J per grain, refreshed whenever the forces are re-evaluated from scratch
    /// ([`Dem::invalidate_forces`]).
    inv_mass: Vec<f64>,
    inv_inertia: Vec<f64>,
    /// Whether some grain moved more than skin/2 since the last list build (found in the
    /// drift, so the check costs no extra pass).
    moved: bool,
    /// End-of-step velocity estimates v* (x, y, ω) for the dashpots.
    vxp: Vec<f64>,
    vyp: Vec<f64>,
    wp: Vec<f64>,
    /// Onset/end events of the last force evaluation, one reused buffer per pair chunk.
    events: Vec<Vec<Event>>,
    wall_events: Vec<Vec<Event>>,
    /// Chunks of `events` / `wall_events` filled by the last evaluation.
    event_chunks: [usize; 2],
    forces_valid: bool,
    /// Elastic energies (state) and cumulative dissipation/work; kinetic and potential are
    /// filled in by [`Dem::energy`].
    budget: Energy,
    contacts: usize,
    /// Pairs the cell list does not handle (polygon grains, polygon walls), through rapier;
    /// `None` for an all-disk system with straight walls.
    shapes: Option<ShapeContacts>,
}

impl Dem {
    /// Build a system; checks every parameter and the time step (seed eq. 5.59–5.60) and
    /// refuses a step above λ Δt_cr, naming the critical value.
    pub fn new(grains: Grains, walls: Vec<Wall>, params: DemParams) -> Result<Self> {
        params.grain.check("dem.grain")?;
        params.wall.check("dem.wall")?;
        for (k, w) in walls.iter().enumerate() {
            w.check(&format!("dem.walls[{k}]"))?;
        }
        if !params.gravity.iter().all(|g| g.is_finite()) {
            return Err(Error::config("dem.gravity", "must be finite"));
        }
        if !(params.lambda > 0.0 && params.lambda <= 1.0) {
            return Err(Error::config(
                "dem.lambda",
                format!("must be in (0, 1], got {}", params.lambda),
            ));
        }
        if !(params.skin_fraction > 0.0 && params.skin_fraction.is_finite()) {
            return Err(Error::config(
                "dem.skin_fraction",
                format!("must be > 0, got {}", params.skin_fraction),
            ));
        }
        if !(params.global_damping >= 0.0 && params.global_damping.is_finite()) {
            return Err(Error::config(
                "dem.global_damping",
                format!("must be ≥ 0, got {}", params.global_damping),
            ));
        }
        for k in 0..grains.len() {
            let ok = grains.radius[k] > 0.0 && grains.mass[k] > 0.0 && grains.inertia[k] > 0.0;
            let finite = [
                grains.x[k],
                grains.y[k],
                grains.vx[k],
                grains.vy[k],
                grains.omega[k],
            ]
            .iter()
            .all(|v| v.is_finite());
            if !ok || !finite {
                return Err(Error::config(
                    format!("dem.grains[{k}]"),
                    "radius, mass and inertia must be > 0 and the state finite",
                ));
            }
        }
        let dt_cr = critical_step(
            &params,
            grains.min_mass().min(polygon_contact_mass(&grains)),
            grains.min_inertia(),
        );
        let dt_max = params.lambda * dt_cr;
        let dt = match params.dt {
            Some(dt) if !(dt > 0.0 && dt.is_finite()) => {
                return Err(Error::config("dem.dt", format!("must be > 0, got {dt}")));
            }
            Some(dt) if dt > dt_max * (1.0 + 1e-12) => {
                return Err(Error::config(
                    "dem.dt",
                    format!(
                        "Δt = {dt:.4e} s exceeds λ·Δt_cr = {dt_max:.4e} s (Δt_cr = {dt_cr:.4e} s by seed eq. 5.59, λ = {}); \
                         use at most {dt_max:.4e} s",
                        params.lambda
                    ),
                ));
            }
            Some(dt) => dt,
            None if dt_max.is_finite() => dt_max,
            None => {
                return Err(Error::config(
                    "dem.dt",
                    "no grains: give the step explicitly",
                ))
            }
        };
        let skin = params.skin_fraction * 2.0 * grains.max_radius().max(f64::MIN_POSITIVE);
        let shapes = RapierDetector::needed(&grains, &walls).then(|| ShapeContacts::new(skin));
        Ok(Dem {
            shapes,
            grain_law: Law::from(&params.grain),
            wall_law: Law::from(&params.wall),
            grains,
            walls,
            params,
            dt,
            dt_cr,
            time: 0.0,
            steps: 0,
            detector: Detector::new(skin),
            pairs: PairList::default(),
            wall_pairs: WallList::default(),
            parts: Vec::new(),
            gparts: Vec::new(),
            inv_mass: Vec::new(),
            inv_inertia: Vec::new(),
            moved: true,
            vxp: Vec::new(),
            vyp: Vec::new(),
            wp: Vec::new(),
            events: Vec::new(),
            wall_events: Vec::new(),
            event_chunks: [0, 0],
            forces_valid: false,
            budget: Energy::default(),
            contacts: 0,
        })
    }

    /// The time step Δt in use (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Critical step Δt_cr of seed eq. 5.59 (s), see [`critical_step`].
    pub fn critical_dt(&self) -> f64 {
        self.dt_cr
    }

    /// Largest step allowed, λ Δt_cr.
    pub fn max_dt(&self) -> f64 {
        self.params.lambda * self.dt_cr
    }

    /// The parameters.
    pub fn params(&self) -> &DemParams {
        &self.params
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.steps
    }

    /// Contacts (overlapping pairs, grain–grain and grain–wall) at the last force evaluation.
    pub fn contact_count(&self) -> usize {
        self.contacts
    }

    /// Neighbour-list builds so far.
    pub fn list_builds(&self) -> u64 {
        self.detector.builds
    }

    /// Grain–grain pairs in the neighbour list (with history and last forces).
    pub fn pairs(&self) -> &PairList {
        &self.pairs
    }

    /// Contacts found by the rapier detector (polygon grains, polygon walls); `None` when the
    /// system needs none.
    pub fn shape_contacts(&self) -> Option<&ShapeContacts> {
        self.shapes.as_ref()
    }

    /// Grain–wall pairs in the neighbour list.
    pub fn wall_pairs(&self) -> &WallList {
        &self.wall_pairs
    }

    /// Full energy budget now (see [`Energy`]).
    pub fn energy(&self) -> Energy {
        let g = &self.grains;
        let grav = self.params.gravity;
        let (k, r, p) = (0..g.len())
            .into_par_iter()
            .with_min_len(GRAIN_CHUNK)
            .map(|i| {
                let m = g.mass[i];
                (
                    0.5 * m * (g.vx[i] * g.vx[i] + g.vy[i] * g.vy[i]),
                    0.5 * g.inertia[i] * g.omega[i] * g.omega[i],
                    -m * (grav[0] * g.x[i] + grav[1] * g.y[i]),
                )
            })
            .reduce(|| (0.0, 0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
        let mut e = self.budget;
        if !self.forces_valid {
            // Springs not evaluated yet: history is zero except normal overlap.
            let mut c = self.clone();
            c.evaluate_from_scratch(None);
            e = c.budget;
        }
        e.kinetic = k;
        e.rotational = r;
        e.potential = p;
        e
    }

    /// Evaluate the forces at the current state without advancing anything (e.g. before
    /// reading contact forces of a system built by hand); a no-op if they are current.
    pub fn refresh_forces(&mut self) {
        if !self.forces_valid {
            self.evaluate_from_scratch(None);
        }
    }

    /// Mark the forces stale after editing [`Dem::grains`] by hand (positions, velocities);
    /// the next step re-evaluates them before moving.
    pub fn invalidate_forces(&mut self) {
        self.forces_valid = false;
    }

    /// One step of size [`Dem::dt`] without external loads.
    pub fn step(&mut self) {
        self.step_dt(self.dt, None);
    }

    /// `n` steps of size [`Dem::dt`].
    pub fn steps(&mut self, n: u64) {
        for _ in 0..n {
            self.step_dt(self.dt, None);
        }
    }

    /// Advance by `dt` (any size) in ⌈dt/Δt⌉ equal sub-steps no larger than [`Dem::dt`]
    /// (seed eq. 5.61), with `loads` held fixed. Refuses loads of the wrong length.
    pub fn advance_with(&mut self, dt: f64, loads: Option<&ExternalLoads>) -> Result<()> {
        if let Some(l) = loads {
            let n = self.grains.len();
            for (name, v) in [("fx", &l.fx), ("fy", &l.fy), ("torque", &l.torque)] {
                if !v.is_empty() && v.len() != n {
                    return Err(Error::Other(format!(
                        "external load `{name}` has {} values for {n} grains",
                        v.len()
                    )));
                }
            }
        }
        if !(dt >= 0.0 && dt.is_finite()) {
            return Err(Error::Other(format!("cannot advance DEM by {dt} s")));
        }
        if dt == 0.0 {
            return Ok(());
        }
        let (n, h) = crate::scale::substeps(dt, self.dt);
        for _ in 0..n {
            self.step_dt(h, loads);
        }
        if let Some(i) = (0..self.grains.len())
            .find(|&i| !(self.grains.x[i].is_finite() && self.grains.y[i].is_finite()))
        {
            return Err(Error::Other(format!(
                "DEM unstable at step {} (t = {:.6e} s): grain {i} has a non-finite position",
                self.steps, self.time
            )));
        }
        Ok(())
    }

    /// One velocity-Verlet step of size `dt` (see the module documentation).
    pub fn step_dt(&mut self, dt: f64, loads: Option<&ExternalLoads>) {
        if !self.forces_valid || self.inv_mass.len() != self.grains.len() {
            self.evaluate_from_scratch(loads);
        }
        self.kick_drift(dt);
        self.compute_forces(dt, loads, 0.5 * dt);
        self.apply_events();
        self.time += dt;
        self.steps += 1;
    }

    /// Forces at the current state without advancing the springs, after the grains were
    /// edited by hand (or at the start): masses and positions are read afresh.
    fn evaluate_from_scratch(&mut self, loads: Option<&ExternalLoads>) {
        let g = &self.grains;
        self.inv_mass.clear();
        self.inv_mass.extend(g.mass.iter().map(|m| 1.0 / m));
        self.inv_inertia.clear();
        self.inv_inertia.extend(g.inertia.iter().map(|j| 1.0 / j));
        self.moved = self.detector.needs_rebuild(g);
        self.compute_forces(0.0, loads, 0.0);
    }

    /// Steps 1–2: first half-kick and drift; also finds whether some grain moved more than
    /// skin/2 since the last list build (step 3), in the same pass.
    fn kick_drift(&mut self, dt: f64) {
        let h = 0.5 * dt;
        let g = &mut self.grains;
        let n = g.len();
        self.vxp.resize(n, 0.0);
        self.vyp.resize(n, 0.0);
        self.wp.resize(n, 0.0);
        let (im, ij) = (&self.inv_mass, &self.inv_inertia);
        let (fx, fy, tq) = (&g.fx, &g.fy, &g.torque);
        let (xr, yr, lim) = self.detector.reference();
        if xr.len() != n {
            self.moved = true;
        }
        let moved = g
            .x
            .par_chunks_mut(GRAIN_CHUNK)
            .zip(g.y.par_chunks_mut(GRAIN_CHUNK))
            .zip(g.vx.par_chunks_mut(GRAIN_CHUNK))
            .zip(g.vy.par_chunks_mut(GRAIN_CHUNK))
            .zip(g.angle.par_chunks_mut(GRAIN_CHUNK))
            .zip(g.omega.par_chunks_mut(GRAIN_CHUNK))
            .zip(self.vxp.par_chunks_mut(GRAIN_CHUNK))
            .zip(self.vyp.par_chunks_mut(GRAIN_CHUNK))
            .zip(self.wp.par_chunks_mut(GRAIN_CHUNK))
            .enumerate()
            .map(|(c, ((((((((x, y), vx), vy), th), w), vxp), vyp), wp))| {
                let (o, len) = (c * GRAIN_CHUNK, x.len());
                let (im, ij) = (&im[o..o + len], &ij[o..o + len]);
                let (fx, fy, tq) = (&fx[o..o + len], &fy[o..o + len], &tq[o..o + len]);
                for k in 0..len {
                    let (ax, ay, al) = (h * im[k] * fx[k], h * im[k] * fy[k], h * ij[k] * tq[k]);
                    vx[k] += ax;
                    vy[k] += ay;
                    w[k] += al;
                    x[k] += dt * vx[k];
                    y[k] += dt * vy[k];
                    th[k] += dt * w[k];
                    vxp[k] = vx[k] + ax;
                    vyp[k] = vy[k] + ay;
                    wp[k] = w[k] + al;
                }
                if xr.len() != n {
                    return true;
                }
                let (xr, yr) = (&xr[o..o + len], &yr[o..o + len]);
                let mut far = false;
                for k in 0..len {
                    let (dx, dy) = (x[k] - xr[k], y[k] - yr[k]);
                    let r2 = dx * dx + dy * dy;
                    // A non-finite grain forces a rebuild too.
                    far |= r2 > lim || r2.is_nan();
                }
                far
            })
            .reduce(|| false, |a, b| a || b);
        self.moved |= moved;
    }

    /// Turn the force arrays from **F**^end (just used by the second half-kick) into the true
    /// **F**_{k+1} for the next step: add the sparse onset/end differences, in pair order.
    fn apply_events(&mut self) {
        let g = &mut self.grains;
        let lists = [
            &self.events[..self.event_chunks[0]],
            &self.wall_events[..self.event_chunks[1]],
        ];
        for ev in lists.into_iter().flatten().flatten() {
            ev.apply(g);
        }
        if let Some(sc) = &self.shapes {
            sc.apply_events(g);
        }
    }

    /// Steps 3–5: rebuild the lists if needed, evaluate all forces at the current positions
    /// and velocities (springs advance by `dt_hist`, 0: evaluate without advancing;
    /// dissipation accrues over `dt_hist`) and, in the same pass over the grains, apply the
    /// second half-kick **v** += `kick`·**F**^end/m (`kick` = ½Δt; 0: no kick).
    fn compute_forces(&mut self, dt_hist: f64, loads: Option<&ExternalLoads>, kick: f64) {
        if self.moved {
            self.moved = false;
            self.detector.build(
                &self.grains,
                &self.walls,
                &mut self.pairs,
                &mut self.wall_pairs,
            );
        }
        if dt_hist == 0.0 || self.vxp.len() != self.grains.len() {
            self.vxp.clone_from(&self.grains.vx);
            self.vyp.clone_from(&self.grains.vy);
            self.wp.clone_from(&self.grains.omega);
        }
        let g = &self.grains;
        let (vxp, vyp, wp) = (&self.vxp, &self.vyp, &self.wp);
        let law = self.grain_law;
        let (pi, pj) = (&self.pairs.i, &self.pairs.j);
        let nch = self.pairs.state.len().div_ceil(PAIR_CHUNK);
        if self.events.len() < nch {
            self.events.resize_with(nch, Vec::new);
        }
        self.event_chunks[0] = nch;
        self.pairs
            .state
            .par_chunks_mut(PAIR_CHUNK)
            .zip(self.pairs.out.par_chunks_mut(PAIR_CHUNK))
            .zip(self.pairs.flags.par_chunks_mut(PAIR_CHUNK))
            .zip(self.events[..nch].par_iter_mut())
            .enumerate()
            .map(|(c, (((state, out), flags), ev))| {
                ev.clear();
                let o = c * PAIR_CHUNK;
                let mut part = Part::default();
                for k in 0..state.len() {
                    let (i, j) = (pi[o + k] as usize, pj[o + k] as usize);
                    let (dx, dy) = (g.x[j] - g.x[i], g.y[j] - g.y[i]);
                    let (ri, rj) = (g.radius[i], g.radius[j]);
                    let d2 = dx * dx + dy * dy;
                    let rs = ri + rj;
                    if d2 >= rs * rs && flags[k] & PAIR_TOUCHING == 0 {
                        // Apart now and at the previous evaluation.
                        flags[k] = 0;
                        continue;
                    }
                    let d = d2.sqrt();
                    let (nx, ny) = if d > 0.0 {
                        (dx / d, dy / d)
                    } else {
                        (1.0, 0.0)
                    };
                    let (tx, ty) = (-ny, nx);
                    // Mid-step (current) and predictor relative velocities.
                    let (dvx, dvy) = (g.vx[i] - g.vx[j], g.vy[i] - g.vy[j]);
                    let (wi, wj) = (g.omega[i], g.omega[j]);
                    let (ex, ey) = (vxp[i] - vxp[j], vyp[i] - vyp[j]);
                    let (pwi, pwj) = (wp[i], wp[j]);
                    let (mi, mj) = (g.mass[i], g.mass[j]);
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
                    flags[k] = PAIR_ACTIVE | if r.touching { PAIR_TOUCHING } else { 0 };
                    let [an, at, ar] = r.apply;
                    out[k] = [
                        -an * nx + at * tx,
                        -an * ny + at * ty,
                        ri * at + ar,
                        rj * at - ar,
                    ];
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
                part
            })
            .collect_into_vec(&mut self.parts);
        let mut total = self.parts.iter().fold(Part::default(), |a, b| a.merge(b));
        let wlaw = self.wall_law;
        let walls = &self.walls;
        let wg = &self.wall_pairs.grain;
        let ww = &self.wall_pairs.wall;
        let nch = self.wall_pairs.state.len().div_ceil(PAIR_CHUNK);
        if self.wall_events.len() < nch {
            self.wall_events.resize_with(nch, Vec::new);
        }
        self.event_chunks[1] = nch;
        self.wall_pairs
            .state
            .par_chunks_mut(PAIR_CHUNK)
            .zip(self.wall_pairs.out.par_chunks_mut(PAIR_CHUNK))
            .zip(self.wall_events[..nch].par_iter_mut())
            .enumerate()
            .map(|(c, ((state, out), ev))| {
                ev.clear();
                let o = c * PAIR_CHUNK;
                let mut part = Part::default();
                for k in 0..state.len() {
                    let i = wg[o + k] as usize;
                    let (s, [nx, ny]) = walls[ww[o + k] as usize].distance([g.x[i], g.y[i]]);
                    let ri = g.radius[i];
                    if s >= ri && !state[k].touching() {
                        out[k] = [0.0; 3];
                        continue;
                    }
                    let (tx, ty) = (-ny, nx);
                    let (w, w1) = (g.omega[i], wp[i]);
                    let motion = Motion {
                        delta: ri - s,
                        u: [g.vx[i] * nx + g.vy[i] * ny, vxp[i] * nx + vyp[i] * ny],
                        v_t: [
                            g.vx[i] * tx + g.vy[i] * ty + w * ri,
                            vxp[i] * tx + vyp[i] * ty + w1 * ri,
                        ],
                        w: [w, w1],
                        m_eff: g.mass[i],
                        r_eff: ri,
                    };
                    let r = wlaw.resolve(&motion, &mut state[k], dt_hist);
                    let [an, at, ar] = r.apply;
                    out[k] = [-an * nx + at * tx, -an * ny + at * ty, ri * at + ar];
                    if r.event {
                        let st = &state[k];
                        let (dn, dt, dm) = (st.f_n - an, st.f_t - at, st.m_r - ar);
                        ev.push(Event {
                            i: i as u32,
                            j: u32::MAX,
                            d: [-dn * nx + dt * tx, -dn * ny + dt * ty, ri * dt + dm, 0.0],
                        });
                    }
                    part = part.add(&r);
                }
                part
            })
            .collect_into_vec(&mut self.parts);
        total = self.parts.iter().fold(total, |a, b| a.merge(b));
        // Contacts through rapier (polygon grains or walls), summed per grain for the gather.
        if let Some(sc) = self.shapes.as_mut() {
            let vp = (&self.vxp[..], &self.vyp[..], &self.wp[..]);
            let (gl, wl) = (&self.grain_law, &self.wall_law);
            let s = sc.evaluate(&self.grains, &self.walls, vp, gl, wl, dt_hist);
            total = total.add_shapes(&s);
        }
        let sf: &[[f64; 3]] = self.shapes.as_ref().map_or(&[], |s| s.grain_force());
        // Gather per grain: gravity, global damping, external loads, contacts; then kick.
        let grav = self.params.gravity;
        let alpha = self.params.global_damping;
        let (pl, wl) = (&self.pairs, &self.wall_pairs);
        let g = &mut self.grains;
        let (m, x_vx, x_vy) = (&g.mass, &self.vxp, &self.vyp);
        let (im, ij) = (&self.inv_mass, &self.inv_inertia);
        let empty: &[f64] = &[];
        let (lx, ly, lt) = match loads {
            Some(l) => (&l.fx[..], &l.fy[..], &l.torque[..]),
            None => (empty, empty, empty),
        };
        g.fx.par_chunks_mut(GRAIN_CHUNK)
            .zip(g.fy.par_chunks_mut(GRAIN_CHUNK))
            .zip(g.torque.par_chunks_mut(GRAIN_CHUNK))
            .zip(g.vx.par_chunks_mut(GRAIN_CHUNK))
            .zip(g.vy.par_chunks_mut(GRAIN_CHUNK))
            .zip(g.omega.par_chunks_mut(GRAIN_CHUNK))
            .enumerate()
            .map(|(c, (((((fx, fy), tq), h_vx), h_vy), h_w))| {
                let o = c * GRAIN_CHUNK;
                let (mut d_glob, mut w_ext) = (0.0, 0.0);
                for k in 0..fx.len() {
                    let i = o + k;
                    // Predictor velocity for the damping force; its work and that of
                    // the (held) external loads over the step use Δx = Δt v_½.
                    let (vx, vy) = (x_vx[i], x_vy[i]);
                    let (ux, uy, w) = (h_vx[k], h_vy[k], h_w[k]);
                    let mut f = [
                        m[i] * grav[0] - alpha * m[i] * vx,
                        m[i] * grav[1] - alpha * m[i] * vy,
                    ];
                    let mut t = 0.0;
                    d_glob += alpha * m[i] * (vx * ux + vy * uy);
                    if !lx.is_empty() {
                        f[0] += lx[i];
                        w_ext += lx[i] * ux;
                    }
                    if !ly.is_empty() {
                        f[1] += ly[i];
                        w_ext += ly[i] * uy;
                    }
                    if !lt.is_empty() {
                        t += lt[i];
                        w_ext += lt[i] * w;
                    }
                    if i + 1 < pl.first.len() {
                        for p in pl.first[i] as usize..pl.first[i + 1] as usize {
                            if pl.flags[p] & PAIR_ACTIVE != 0 {
                                let q = &pl.out[p];
                                f[0] += q[0];
                                f[1] += q[1];
                                t += q[2];
                            }
                        }
                        for &p in &pl.as_j[pl.j_start[i] as usize..pl.j_start[i + 1] as usize] {
                            if pl.flags[p as usize] & PAIR_ACTIVE != 0 {
                                let q = &pl.out[p as usize];
                                f[0] -= q[0];
                                f[1] -= q[1];
                                t += q[3];
                            }
                        }
                    }
                    if i + 1 < wl.first.len() {
                        for p in wl.first[i] as usize..wl.first[i + 1] as usize {
                            let q = &wl.out[p];
                            f[0] += q[0];
                            f[1] += q[1];
                            t += q[2];
                        }
                    }
                    if let Some(q) = sf.get(i) {
                        f[0] += q[0];
                        f[1] += q[1];
                        t += q[2];
                    }
                    fx[k] = f[0];
                    fy[k] = f[1];
                    tq[k] = t;
                    h_vx[k] += kick * im[i] * f[0];
                    h_vy[k] += kick * im[i] * f[1];
                    h_w[k] += kick * ij[i] * t;
                }
                [d_glob, w_ext]
            })
            .collect_into_vec(&mut self.gparts);
        let (d_glob, w_ext) = self
            .gparts
            .iter()
            .fold((0.0, 0.0), |a, b| (a.0 + b[0], a.1 + b[1]));
        let b = &mut self.budget;
        b.elastic_normal = total.e_n;
        b.elastic_tangential = total.e_t;
        b.elastic_rolling = total.e_r;
        b.dissipated_normal += total.d_n;
        b.dissipated_friction += total.d_f;
        b.dissipated_rolling += total.d_r;
        b.dissipated_global += d_glob * dt_hist;
        b.work_external += w_ext * dt_hist;
        self.contacts = total.contacts as usize;
        self.forces_valid = true;
    }
}
