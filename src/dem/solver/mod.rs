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
//! Forces are computed in parallel over fixed chunks of grains, each chunk resolving the pairs
//! whose first grain it holds and adding their forces straight to its grains; a force on a
//! grain of a later chunk is queued and added by that chunk in the kick pass. Every grain's
//! force is summed in an order fixed by the pair list and the chunk size, so results do not
//! depend on the number of threads. Within a run of several steps ([`Dem::steps`],
//! [`Dem::advance_with`]) step 5 of one step, its events and steps 1–2 of the next use the
//! same forces, so they are one pass over the grains (the events of each grain applied in the
//! same order as the serial loop would: the results are bit for bit those of single steps).
//!
//! Time step: seed eq. 5.59–5.60, Δt = λ Δt_cr with λ = 0.1 by default, derived in one place,
//! [`super::time_step::TimeStep`].

use rayon::prelude::*;

use super::contact::{ContactOut, ContactState, Event, Law, Motion};
use super::detect_rapier::RapierDetector;
use super::energy::Energy;
use super::grains::Grains;
use super::neighbours::{Detector, PairList, WallList, PAIR_TOUCHING};
use super::params::DemParams;
use super::shape_contacts::{ShapeContacts, ShapeSums};
use super::time_step::TimeStep;
use super::walls::Wall;
use crate::{Error, Result};

mod forces;
mod remove;

use forces::{chunks, Drift, JForce};

/// Grains per parallel chunk of the integrator loops and of the force pass (whose chunk owns
/// the pairs and wall pairs of its grains). Fixed, so that the order in which a grain's forces
/// are summed does not depend on the thread count.
const GRAIN_CHUNK: usize = 1024;

/// External loads held during [`Dem::advance_with`] (e.g. hydrodynamic force and torque from
/// the fluid, seed eq. 5.53–5.54). Empty vectors mean none.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ExternalLoads {
    /// Force x per grain.
    pub fx: Vec<f64>,
    /// Force y per grain.
    pub fy: Vec<f64>,
    /// Torque per grain.
    pub torque: Vec<f64>,
}

/// Per-chunk sums of one force evaluation.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
struct Part {
    e_n: f64,
    e_t: f64,
    e_r: f64,
    d_n: f64,
    d_f: f64,
    d_r: f64,
    contacts: f64,
    /// Power of the global damping, Σ α m **v*** · **v**_½.
    d_glob: f64,
    /// Power of the external loads, Σ **F**_ext · **v**_½.
    w_ext: f64,
    /// Last chunk that this chunk queued forces for (itself if none).
    reach: u32,
    /// Deepest overlap δ/min(R_i, R_j) of the pass and its pair (j = `u32::MAX`: a wall).
    deepest: Overlap,
}

/// An overlap δ relative to the smaller radius of the pair, and the pair.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Overlap {
    /// δ/min(R_i, R_j) (δ/R_i for a wall).
    pub relative: f64,
    /// Grain i.
    pub i: u32,
    /// Grain j, or `u32::MAX` for a wall.
    pub j: u32,
}

impl Overlap {
    #[inline(always)]
    fn deeper(self, o: Overlap) -> Overlap {
        if o.relative > self.relative {
            o
        } else {
            self
        }
    }
}

/// Overlap δ/min(R_i, R_j) beyond which a run stops as unstable: the grains are passing
/// through each other (time step too large or stiffness too low for the impact speeds).
pub const OVERLAP_LIMIT: f64 = 0.5;

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
        self.d_glob += o.d_glob;
        self.w_ext += o.w_ext;
        self.deepest = self.deepest.deeper(o.deepest);
        self
    }
}

/// A DEM system: grains, walls, contact laws, neighbour lists, clock and energy budget.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
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
    /// Per grain chunk: sums of the last force pass.
    parts: Vec<Part>,
    /// Per grain chunk: forces of its pairs on grains of later chunks, in pair order.
    queued: Vec<Vec<JForce>>,
    /// Per grain chunk r: the first chunk whose `queued` may hold forces on grains of r.
    reach_from: Vec<u32>,
    /// Per grain chunk: scratch list of its pairs that touch or touched (see [`candidates`]).
    cand: Vec<Vec<u32>>,
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
    /// Onset/end events of the last force evaluation, one reused buffer per grain chunk.
    events: Vec<Vec<Event>>,
    wall_events: Vec<Vec<Event>>,
    /// Chunks of `events` / `wall_events` filled by the last evaluation.
    event_chunks: [usize; 2],
    forces_valid: bool,
    /// Elastic energies (state) and cumulative dissipation/work; kinetic and potential are
    /// filled in by [`Dem::energy`].
    budget: Energy,
    contacts: usize,
    /// Deepest overlap of the disk contacts since the start of the last
    /// [`Dem::advance_with`] (or since creation).
    deepest: Overlap,
    /// Touching pairs summed over the steps taken.
    contact_steps: u64,
    /// Pairs the cell list does not handle (polygon grains, polygon walls), through rapier;
    /// `None` for an all-disk system with straight walls.
    shapes: Option<ShapeContacts>,
    /// Velocity of each wall (m/s), empty while all are at rest ([`Dem::set_wall_velocity`]).
    wall_velocity: Vec<[f64; 2]>,
    /// Largest distance a wall has translated since the last list build (m).
    wall_travel: f64,
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
        let TimeStep {
            critical: dt_cr,
            dt,
        } = TimeStep::of_grains(&params, &grains).map_err(|e| e.within("dem"))?;
        let skin = params.skin_fraction * 2.0 * grains.max_radius().max(f64::MIN_POSITIVE);
        params.check_period(&grains, "dem.periodic_x")?;
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
            queued: Vec::new(),
            reach_from: Vec::new(),
            cand: Vec::new(),
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
            deepest: Overlap::default(),
            contact_steps: 0,
            wall_velocity: Vec::new(),
            wall_travel: 0.0,
        })
    }

    /// Let wall `k` translate at velocity `v` (m/s) from now on: at every step it moves by
    /// **v** Δt, and its contacts see the relative velocity of grain and wall (the normal and
    /// tangential dashpots and the tangential spring use **v**_grain − **v**). Plane and
    /// segment walls of an all-disk system only. The walls' work on the grains is not booked
    /// in [`Energy::work_external`], so the budget of a system with a moving wall does not close.
    pub fn set_wall_velocity(&mut self, k: usize, v: [f64; 2]) -> Result<()> {
        let field = format!("dem.walls[{k}]");
        let Some(w) = self.walls.get(k) else {
            return Err(Error::config(field, "no such wall"));
        };
        if !w.is_straight() || self.shapes.is_some() {
            return Err(Error::config(
                field,
                "only plane and segment walls of an all-disk system can move",
            ));
        }
        if !v.iter().all(|c| c.is_finite()) {
            return Err(Error::config(field, "wall velocity must be finite"));
        }
        self.wall_velocity.resize(self.walls.len(), [0.0; 2]);
        self.wall_velocity[k] = v;
        Ok(())
    }

    /// Translate the moving walls by **v** `dt`; once one has gone skin/2 since the last
    /// list build, the lists are rebuilt before the next force evaluation (grains and walls
    /// then together moved less than the skin, so no contact is missed).
    fn move_walls(&mut self, dt: f64) {
        if self.wall_velocity.is_empty() {
            return;
        }
        let mut fastest: f64 = 0.0;
        for (w, v) in self.walls.iter_mut().zip(&self.wall_velocity) {
            w.translate([v[0] * dt, v[1] * dt]);
            fastest = fastest.max(v[0].hypot(v[1]));
        }
        self.wall_travel += fastest * dt;
        if self.wall_travel > 0.5 * self.detector.skin {
            self.moved = true;
        }
    }

    /// The time step Δt in use (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Critical step Δt_cr of seed eq. 5.59 (s), see [`super::time_step::critical_step`].
    pub fn critical_dt(&self) -> f64 {
        self.dt_cr
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

    /// Deepest overlap δ/min(R_i, R_j) of the disk contacts over the steps since the start of
    /// the last [`Dem::advance_with`] (or since creation); that call fails when it exceeds
    /// [`OVERLAP_LIMIT`].
    pub fn deepest_overlap(&self) -> Overlap {
        self.deepest
    }

    /// Contacts summed over all steps taken (contacts per step × steps).
    pub fn contact_steps(&self) -> u64 {
        self.contact_steps
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

    /// Overlapping contacts of each grain at the last force evaluation (grain–grain,
    /// grain–wall and the rapier detector's): the grain's coordination number; zero marks a
    /// rattler, a grain that carries no load.
    pub fn contacts_per_grain(&self) -> Vec<u32> {
        let mut z = vec![0u32; self.grains.len()];
        let pl = &self.pairs;
        for p in 0..pl.i.len() {
            if pl.flags[p] & PAIR_TOUCHING != 0 {
                z[pl.i[p] as usize] += 1;
                z[pl.j[p] as usize] += 1;
            }
        }
        let wl = &self.wall_pairs;
        for p in 0..wl.grain.len() {
            if wl.state[p].touching() {
                z[wl.grain[p] as usize] += 1;
            }
        }
        if let Some(sc) = &self.shapes {
            for (c, st) in sc.found.iter().zip(&sc.state) {
                if st.touching() {
                    z[c.i as usize] += 1;
                    if c.wall().is_none() {
                        z[c.j as usize] += 1;
                    }
                }
            }
        }
        z
    }

    /// Kinetic energy K_t + K_r of the grains with at least one contact
    /// ([`Dem::contacts_per_grain`]): the motion of the load-carrying skeleton. A rattler's
    /// spin is left out: no contact damps it, so it would keep a packing's total kinetic
    /// energy from ever falling to a rest threshold.
    pub fn loaded_kinetic_energy(&self) -> f64 {
        let g = &self.grains;
        let z = self.contacts_per_grain();
        (0..g.len())
            .filter(|&i| z[i] > 0)
            .map(|i| {
                0.5 * g.mass[i] * (g.vx[i] * g.vx[i] + g.vy[i] * g.vy[i])
                    + 0.5 * g.inertia[i] * g.omega[i] * g.omega[i]
            })
            .sum()
    }

    /// Full energy budget now (see [`Energy`]).
    pub fn energy(&self) -> Energy {
        let g = &self.grains;
        let grav = self.params.gravity;
        let [k, r, p] = crate::exec::ordered_sum(g.len(), GRAIN_CHUNK, |i| {
            let m = g.mass[i];
            [
                0.5 * m * (g.vx[i] * g.vx[i] + g.vy[i] * g.vy[i]),
                0.5 * g.inertia[i] * g.omega[i] * g.omega[i],
                -m * (grav[0] * g.x[i] + grav[1] * g.y[i]),
            ]
        });
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
        self.run(n, self.dt, None);
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
        self.deepest = Overlap::default();
        self.run(n, h, loads);
        if let Some(i) = (0..self.grains.len())
            .find(|&i| !(self.grains.x[i].is_finite() && self.grains.y[i].is_finite()))
        {
            return Err(Error::Other(format!(
                "DEM unstable at step {} (t = {:.6e} s): grain {i} has a non-finite position",
                self.steps, self.time
            )));
        }
        let o = self.deepest;
        if o.relative > OVERLAP_LIMIT {
            let with = if o.j == u32::MAX {
                "a wall".to_string()
            } else {
                format!("grain {}", o.j)
            };
            return Err(Error::Other(format!(
                "DEM unstable at step {} (t = {:.6e} s): grain {} overlaps {with} by {:.3} of \
                 the smaller radius (limit {OVERLAP_LIMIT}): the grains are passing through \
                 each other; lower the time step or raise the stiffness",
                self.steps, self.time, o.i, o.relative
            )));
        }
        Ok(())
    }

    /// One velocity-Verlet step of size `dt` (see the module documentation).
    pub fn step_dt(&mut self, dt: f64, loads: Option<&ExternalLoads>) {
        self.run(1, dt, loads);
    }

    /// `n` velocity-Verlet steps of size `dt`. Between two steps the second half-kick, the
    /// events and the next first half-kick and drift are one pass (not with rapier contacts,
    /// whose events are applied by [`ShapeContacts`]).
    fn run(&mut self, n: u64, dt: f64, loads: Option<&ExternalLoads>) {
        if n == 0 {
            return;
        }
        if !self.forces_valid || self.inv_mass.len() != self.grains.len() {
            self.evaluate_from_scratch(loads);
        }
        self.kick_drift(dt);
        for k in 1..=n {
            self.move_walls(dt);
            let fused = k < n && self.shapes.is_none();
            self.compute_forces(dt, loads, 0.5 * dt, fused.then_some(dt));
            if !fused {
                self.apply_events();
            }
            self.time += dt;
            self.steps += 1;
            if !fused && k < n {
                self.kick_drift(dt);
            }
        }
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
        self.compute_forces(0.0, loads, 0.0, None);
    }

    /// Steps 1–2: first half-kick and drift; also finds whether some grain moved more than
    /// skin/2 since the last list build (step 3), in the same pass.
    fn kick_drift(&mut self, dt: f64) {
        let g = &mut self.grains;
        let n = g.len();
        self.vxp.resize(n, 0.0);
        self.vyp.resize(n, 0.0);
        self.wp.resize(n, 0.0);
        let (im, ij) = (&self.inv_mass[..], &self.inv_inertia[..]);
        let (xr, yr, lim) = self.detector.reference();
        let drift = Drift::new(dt, n, xr, yr, lim);
        if !drift.has_reference {
            self.moved = true;
        }
        let moved = chunks(g, &mut self.vxp, &mut self.vyp, &mut self.wp)
            .enumerate()
            .map(|(c, mut k)| drift.apply(c * GRAIN_CHUNK, &mut k, im, ij))
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
}
