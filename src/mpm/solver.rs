//! The explicit MPM step: particle-to-grid (P2G), grid momentum update with boundary
//! conditions, grid-to-particle (G2P), stress update. Three orderings (Bardenhagen 2002,
//! Sulsky et al. 1995), selected by [`Scheme`]:
//!
//! ```text
//! USF:  P2G m, p → v_i = p_i/m_i (BC) → Δε from v_i, σ update → P2G f → grid update → G2P
//! USL:  P2G m, p, f → grid update → G2P (v_p, x_p) and Δε from v_i^{n+1}, σ update
//! MUSL: P2G m, p, f → grid update → G2P v_p → P2G p again → v_i = p_i/m_i (BC) → Δε, σ, x_p
//! ```
//!
//! with, for point p and node i (weights N_ip and gradients ∇N_ip of [`super::shape`]):
//!
//! * m_i = Σ_p N_ip m_p,  p_i = Σ_p N_ip m_p v_p,
//!   f_i = Σ_p (−V_p σ_p·∇N_ip + N_ip m_p g);
//! * local non-viscous damping (Cundall), when α > 0: f_i ← f_i − α |f_i| sign(v_i) per
//!   component (used only to reach static equilibrium, e.g. `mpm-selfweight`);
//! * v_i^{n+1} = v_i + Δt f_i/m_i, then the walls ([`super::boundary`]); the walls that act
//!   on each node (a unilateral friction wall only where the node moves into it) are the
//!   step's contact state, which MUSL re-applies to the re-mapped velocity: a node held on a
//!   wall by the update stays on it (v_n = 0) there, even where the re-mapped FLIP velocities
//!   move away from the wall (releasing it let a compressed point on the floor compress
//!   itself further each step, and be ejected);
//! * FLIP velocity v_p ← v_p + Σ_i N_ip (v_i^{n+1} − v_i) (optionally blended with PIC,
//!   [`MpmParams::pic_fraction`]), position x_p ← x_p + Δt Σ_i N_ip v_i^{n+1};
//! * or, with [`Transfer::Apic`] (affine PIC, Jiang et al. 2015): P2G momentum
//!   p_i = Σ_p N_ip m_p (v_p + B_p D_p⁻¹ (x_i − x_p)), G2P v_p = Σ_i N_ip v_i^{n+1},
//!   B_p = Σ_i N_ip v_i^{n+1} ⊗ (x_i − x_p), with D_p = Σ_i N_ip (x_i − x_p) ⊗ (x_i − x_p)
//!   (diagonal for tensor-product weights). D_p depends on the point's place in its cell for
//!   uGIMP (it is h²/4 I only for quadratic B-splines), so B_p is stored and D_p⁻¹ taken at the
//!   position of each P2G: then the angular momentum Σ_p m_p (x_p × v_p + B_p,yx − B_p,xy)
//!   equals the grid's Σ_i m_i x_i × v_i after P2G and after G2P, and is conserved to
//!   round-off without external torques. uGIMP only (for the hat, D_p = 0 on a node line);
//! * velocity gradient L = Σ_i v_i ⊗ ∇N_ip, Δε = Δt sym L, spin Δω = Δt ½(L_xy − L_yx),
//!   F ← (I + Δt L) F, V = det F · V₀, σ ← material(σ, Δε, Δω).
//!
//! Energy bookkeeping ([`MpmEnergy`]): kinetic and potential energy of the points; elastic
//! energy ½ σ:C⁻¹:σ V; plastic dissipation = stress work Σ σ_mid:Δε V − elastic energy; the
//! work taken out by wall impulses, D = −m_i Δv_i·(v_i^{n+1} + v_i^n)/2 per constrained node
//! and step (normal part: impact; tangential part: friction; zero for a node held at rest);
//! local damping work α|f|·|v|Δt. What is left, E_total(t) − E_total(0), is the scheme's own
//! numerical dissipation (the FLIP/PIC transfers), reported as the budget error.
//!
//! Traction (pressure) loads on boundary faces of points ([`Traction`]): the force
//! f = −p L₀ cof(F) N (Nanson: cof F = J F⁻ᵀ; N the face's outward unit normal in the reference
//! configuration, ±x or ±y; L₀ = 2 l_p the face's reference length) is added to the nodal
//! forces as the exact integral of the nodal functions over the face,
//! f_i = f · N_i(x_p + l_p N) along the normal (the hat at the face line) × S_i(y_p) along the
//! face (the uGIMP weight of a segment of length 2 l_p, = (1/2l_p)∫ N_i dy over the face). The
//! load is the same for both shape kinds; with uGIMP it is the exact boundary term of the
//! internal force, Σ_p V_p ∇S_ip = ∮ N_i n dΓ, so a uniformly stressed body held by its
//! boundary tractions is in exact discrete equilibrium wherever its edges lie. Applied serially
//! (boundary points only). Their work f·Δx_face is booked (`MpmEnergy::traction`).
//!
//! Time step: Δt ≤ C h/c with c = √((K + 4G/3)/ρ) the P-wave speed and C the Courant number;
//! a larger step is refused (Error::Config on `time.dt`).
//!
//! Parallel P2G without races or atomics: points are binned by the node column where their
//! stencil starts into stripes of W = 4 columns; a stripe writes only node columns
//! [sW, sW + W + 2), so all even stripes can scatter at once into disjoint slices of the
//! (x-major) node arrays, then all odd ones. The points themselves are re-sorted into cell
//! order every `resort_every` steps, so each stripe walks memory in order.

use rayon::prelude::*;

use super::grid::{Grid, NodeSums};
use super::material::{Material, MaterialModel, MaterialState, Stress};
use super::points::{PermuteScratch, Points};
use super::shape::{weights_1d, ShapeKind};
use crate::{Error, Result};

/// Update scheme (order of stress update and momentum update).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Scheme {
    /// Update stress first (from the velocities mapped at the start of the step).
    Usf,
    /// Update stress last (from the updated grid velocities).
    Usl,
    /// Modified USL: stress from velocities re-mapped from the updated point momenta.
    Musl,
}

/// Solver parameters.
#[derive(Clone, Debug)]
pub struct MpmParams {
    /// Shape functions.
    pub shape: ShapeKind,
    /// Update scheme.
    pub scheme: Scheme,
    /// Gravity (m/s²).
    pub gravity: [f64; 2],
    /// Courant number C of Δt_max = C h/c.
    pub courant: f64,
    /// Time step (s); `None`: C h/c.
    pub dt: Option<f64>,
    /// Local damping coefficient α ∈ [0, 1) (0: none).
    pub damping: f64,
    /// PIC fraction β ∈ [0, 1] of the point velocity update,
    /// v_p ← (1 − β)(v_p + Σ N Δv_i) + β Σ N v_i^{n+1} (0: pure FLIP). PIC damps the
    /// velocity modes the grid cannot see (the FLIP null space) and dissipates energy, which
    /// then shows in the energy budget error; momentum stays exact either way.
    pub pic_fraction: f64,
    /// Re-sort the points into cell order every this many steps.
    pub resort_every: u64,
}

/// Energies (J per m of thickness) of the MPM system.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MpmEnergy {
    /// Σ ½ m_p |v_p|².
    pub kinetic: f64,
    /// Σ m_p (−g · x_p) (zero at the origin; with g = (0, −g): Σ m g y).
    pub potential: f64,
    /// Σ V_p ½ σ_p : C⁻¹ : σ_p.
    pub elastic: f64,
    /// Plastic dissipation: stress work (including the initial elastic energy) − elastic energy.
    pub plastic: f64,
    /// Work taken out by the walls' normal impulses (impact), −Σ m Δv_n·v_mid.
    pub boundary_normal: f64,
    /// Work taken out by wall friction, −Σ m Δv_t·v_mid.
    pub boundary_friction: f64,
    /// Work of the local damping forces.
    pub damping: f64,
    /// Work done on the material by the traction loads (an input, not a dissipation).
    pub traction: f64,
}

impl MpmEnergy {
    /// Mechanical energy: kinetic + potential + elastic.
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.potential + self.elastic
    }
    /// Everything booked as dissipated.
    pub fn dissipated(&self) -> f64 {
        self.plastic + self.boundary_normal + self.boundary_friction + self.damping
    }
    /// Mechanical + dissipated − traction work (constant up to the scheme's own numerical
    /// dissipation).
    pub fn total(&self) -> f64 {
        self.mechanical() + self.dissipated() - self.traction
    }

    /// Where the potential energy released since `start` went (collision = inelastic wall
    /// impacts, friction = wall friction, plastic flow, local damping).
    pub fn budget(&self, start: &MpmEnergy) -> crate::analysis::runout::EnergyBudget {
        crate::analysis::runout::EnergyBudget {
            potential_released: start.potential - self.potential,
            kinetic: self.kinetic,
            elastic: self.elastic,
            collision: self.boundary_normal - start.boundary_normal,
            friction: self.boundary_friction - start.boundary_friction,
            rolling: 0.0,
            plastic: self.plastic - start.plastic,
            damping: self.damping - start.damping,
        }
    }
}

/// Velocity transfer between points and grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Transfer {
    /// FLIP, blended with PIC by [`MpmParams::pic_fraction`].
    Flip,
    /// Affine particle-in-cell (no tuning parameter; see the module doc).
    Apic,
}

impl Transfer {
    /// Refuses APIC with standard MPM shape functions (D_p is singular on node lines) or with
    /// a PIC fraction > 0 (APIC has none), naming the scenario field.
    pub fn check(self, shape: ShapeKind, pic_fraction: f64) -> Result<()> {
        if self == Transfer::Apic {
            if shape != ShapeKind::Gimp {
                return Err(Error::config(
                    "mpm.transfer",
                    "APIC needs uGIMP shape functions (with the hat D_p = 0 on node lines)",
                ));
            }
            if pic_fraction != 0.0 {
                return Err(Error::config(
                    "mpm.pic_fraction",
                    "must be 0 with the APIC transfer",
                ));
            }
        }
        Ok(())
    }
}

/// A pressure load on one boundary face of a point's domain (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Traction {
    /// Index of the point (kept valid when the points are re-sorted).
    pub point: u32,
    /// Outward unit normal of the face in the reference configuration: ±x or ±y.
    pub normal: [f64; 2],
    /// Pressure on the face (Pa, compression positive).
    pub pressure: f64,
}

/// Columns per stripe of the parallel P2G.
const STRIPE: usize = 4;
/// Points per parallel work item of the point loops.
const CHUNK: usize = 512;

/// The MPM system.
#[derive(Clone, Debug)]
pub struct Mpm {
    /// Background grid.
    pub grid: Grid,
    /// Material points.
    pub points: Points,
    /// Constitutive law (one material for all points).
    pub material: MaterialModel,
    /// Parameters.
    pub params: MpmParams,
    dt: f64,
    time: f64,
    steps: u64,
    booked: [f64; 3],
    order: Vec<u32>,
    stripe_start: Vec<usize>,
    stripe_of: Vec<u32>,
    perm: Vec<u32>,
    scratch: PermuteScratch,
    mass_eps: f64,
    /// Each point's stencil at the start of the step (computed once in `bin`, used by every
    /// pass of the step: the positions move only at the end of the last pass).
    stencils: Vec<Stencil>,
    tractions: Vec<Traction>,
    traction_work: f64,
    transfer: Transfer,
    /// Force and point position of each traction as applied this step.
    traction_applied: Vec<([f64; 2], [f64; 2])>,
    inverse: Vec<u32>,
}

/// Stencil of a point: first node (i, j) and 1-D weights and derivatives.
#[derive(Clone, Copy, Debug, Default)]
struct Stencil {
    i0: i64,
    j0: i64,
    wx: [f64; 3],
    gx: [f64; 3],
    wy: [f64; 3],
    gy: [f64; 3],
}

#[inline(always)]
fn stencil(shape: ShapeKind, origin: [f64; 2], h: f64, p: [f64; 2], lp: f64) -> Stencil {
    let (i0, wx, gx) = weights_1d(shape, p[0] - origin[0], h, lp);
    let (j0, wy, gy) = weights_1d(shape, p[1] - origin[1], h, lp);
    Stencil {
        i0,
        j0,
        wx,
        gx,
        wy,
        gy,
    }
}

/// The CFL limit C h/c, c = √((K + 4G/3)/ρ).
pub fn cfl_step(material: &MaterialModel, h: f64, courant: f64) -> f64 {
    courant * h / (material.p_wave_modulus() / material.density()).sqrt()
}

/// What a point loop does.
#[derive(Clone, Copy, PartialEq, Eq)]
enum PointPass {
    /// FLIP velocity update only (MUSL, first pass).
    Velocity,
    /// Velocity, position and stress from v_i^{n+1} (USL).
    All,
    /// Stress from `vel_map` only (USF, before forces).
    StressFromMap,
    /// Stress from `vel_map` and position from v_i^{n+1} (MUSL, second pass).
    StressFromMapAndMove,
    /// Velocity and position (USF, last pass).
    VelocityAndMove,
}

impl Mpm {
    /// Assemble a system. Refuses (naming `time.dt`) a step above the CFL limit, a Courant
    /// number outside (0, 1], damping outside [0, 1), more than 8 walls, or points outside
    /// the grid's interior.
    pub fn new(
        grid: Grid,
        points: Points,
        material: MaterialModel,
        params: MpmParams,
    ) -> Result<Self> {
        if !(params.courant > 0.0 && params.courant <= 1.0) {
            return Err(Error::config(
                "mpm.courant",
                format!("must be in (0, 1], got {}", params.courant),
            ));
        }
        if !(params.damping >= 0.0 && params.damping < 1.0) {
            return Err(Error::config(
                "mpm.damping",
                format!("must be in [0, 1), got {}", params.damping),
            ));
        }
        if !(params.pic_fraction >= 0.0 && params.pic_fraction <= 1.0) {
            return Err(Error::config(
                "mpm.pic_fraction",
                format!("must be in [0, 1], got {}", params.pic_fraction),
            ));
        }
        if grid.walls.len() > 8 {
            return Err(Error::Other("at most 8 walls".into()));
        }
        let limit = cfl_step(&material, grid.h, params.courant);
        let dt = match params.dt {
            Some(dt) if !(dt > 0.0 && dt.is_finite()) => {
                return Err(Error::config("time.dt", format!("must be finite and > 0, got {dt}")))
            }
            Some(dt) if dt > limit => {
                return Err(Error::config(
                    "time.dt",
                    format!(
                        "Δt = {dt:e} s exceeds the CFL limit {limit:e} s = C h/c with C = {}, h = {} m, \
                         c = √((K + 4G/3)/ρ) = {:.4} m/s",
                        params.courant,
                        grid.h,
                        (material.p_wave_modulus() / material.density()).sqrt()
                    ),
                ))
            }
            Some(dt) => dt,
            None => limit,
        };
        let n = points.len();
        let mass_eps = 1e-14 * points.mass.iter().fold(0.0f64, |a, &m| a.max(m));
        let nstripes = (grid.nx + 1).div_ceil(STRIPE);
        let mut mpm = Mpm {
            grid,
            points,
            material,
            params: params.clone(),
            dt,
            time: 0.0,
            steps: 0,
            booked: [0.0; 3],
            order: vec![0; n],
            stripe_start: vec![0; nstripes + 1],
            stripe_of: vec![0; n],
            perm: Vec::with_capacity(n),
            scratch: PermuteScratch::default(),
            mass_eps,
            stencils: vec![Stencil::default(); n],
            tractions: Vec::new(),
            traction_work: 0.0,
            transfer: Transfer::Flip,
            traction_applied: Vec::new(),
            inverse: Vec::new(),
        };
        // The stress work starts at the initial elastic energy (so plastic = work − elastic).
        for p in 0..n {
            mpm.points.work[p] =
                mpm.points.vol[p] * mpm.material.elastic_energy_density(&mpm.points.stress[p]);
        }
        mpm.resort();
        mpm.bin()?;
        Ok(mpm)
    }

    /// Choose the velocity transfer. APIC is refused with standard MPM shape functions (D_p is
    /// singular on node lines) or a PIC fraction > 0 (APIC has none), naming the field.
    pub fn set_transfer(&mut self, transfer: Transfer) -> Result<()> {
        transfer.check(self.params.shape, self.params.pic_fraction)?;
        self.transfer = transfer;
        for b in self.points.affine.iter_mut() {
            *b = [0.0; 4];
        }
        Ok(())
    }

    /// The velocity transfer in use.
    pub fn transfer(&self) -> Transfer {
        self.transfer
    }

    /// Total angular momentum about the origin (per m), Σ_p m_p (x_p × v_p + B_p,yx − B_p,xy)
    /// (the affine term is zero with FLIP/PIC).
    pub fn angular_momentum(&self) -> f64 {
        let p = &self.points;
        (0..p.len())
            .map(|q| {
                let (x, v, b) = (p.pos[q], p.vel[q], p.affine[q]);
                p.mass[q] * (x[0] * v[1] - x[1] * v[0] + b[2] - b[1])
            })
            .sum()
    }

    /// The time step in use (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.steps
    }

    /// Set the initial stress of every point (and its stress work to the elastic energy).
    pub fn set_stress(&mut self, f: impl Fn([f64; 2]) -> Stress) {
        for p in 0..self.points.len() {
            self.points.stress[p] = f(self.points.pos[p]);
            self.points.work[p] =
                self.points.vol[p] * self.material.elastic_energy_density(&self.points.stress[p]);
        }
    }

    /// Add pressure loads on boundary faces of points. Refuses a point index out of range, a
    /// normal that is not ±x or ±y, a pressure that is not finite, or a face outside the grid.
    pub fn add_tractions(&mut self, loads: impl IntoIterator<Item = Traction>) -> Result<()> {
        for t in loads {
            if t.point as usize >= self.points.len() {
                return Err(Error::Other(format!(
                    "traction on point {} of {}",
                    t.point,
                    self.points.len()
                )));
            }
            let axis_aligned = matches!(
                t.normal,
                [1.0, 0.0] | [-1.0, 0.0] | [0.0, 1.0] | [0.0, -1.0]
            );
            if !axis_aligned || !t.pressure.is_finite() {
                return Err(Error::Other(format!(
                    "traction normal must be ±x or ±y and the pressure finite, got {:?}, {}",
                    t.normal, t.pressure
                )));
            }
            self.tractions.push(t);
        }
        self.bin()
    }

    /// The traction loads (point indices as the points are ordered now).
    pub fn tractions(&self) -> &[Traction] {
        &self.tractions
    }

    /// Force of a traction load and its face's node stencil (first node and 1-D weights).
    #[inline]
    fn traction_force(&self, t: &Traction) -> ([f64; 2], Stencil) {
        let q = t.point as usize;
        let g = &self.grid;
        let (x, lp, f) = (
            self.points.pos[q],
            self.points.half_size[q],
            self.points.def_grad[q],
        );
        // cof F = J F⁻ᵀ = [[F_yy, −F_yx], [−F_xy, F_xx]] with F = (xx, xy, yx, yy).
        let n = t.normal;
        let cn = [f[3] * n[0] - f[2] * n[1], -f[1] * n[0] + f[0] * n[1]];
        let scale = -t.pressure * 2.0 * lp;
        let force = [scale * cn[0], scale * cn[1]];
        // Face line along the normal: hat weights; along the face: uGIMP weights.
        let hat = |c: f64| -> (i64, [f64; 3]) {
            let r = c / g.h;
            let i = r.floor();
            (i as i64, [1.0 - (r - i), r - i, 0.0])
        };
        let local = [x[0] - g.origin[0], x[1] - g.origin[1]];
        let mut st = Stencil::default();
        if n[0] != 0.0 {
            (st.i0, st.wx) = hat(local[0] + n[0] * lp);
            (st.j0, st.wy, _) = weights_1d(ShapeKind::Gimp, local[1], g.h, lp);
        } else {
            (st.i0, st.wx, _) = weights_1d(ShapeKind::Gimp, local[0], g.h, lp);
            (st.j0, st.wy) = hat(local[1] + n[1] * lp);
        }
        (force, st)
    }

    /// Add the traction forces to the nodal forces (after a force P2G).
    fn scatter_tractions(&mut self) {
        let nny = self.grid.ny + 1;
        self.traction_applied.clear();
        for k in 0..self.tractions.len() {
            let (f, st) = self.traction_force(&self.tractions[k]);
            let x = self.face_centre(&self.tractions[k]);
            self.traction_applied.push((f, x));
            for a in 0..3 {
                for b in 0..3 {
                    let w = st.wx[a] * st.wy[b];
                    let node = (st.i0 as usize + a) * nny + st.j0 as usize + b;
                    self.grid.sums[node][3] += w * f[0];
                    self.grid.sums[node][4] += w * f[1];
                }
            }
        }
    }

    /// Centre of a traction's face in the current configuration, x_p + F N l_p.
    fn face_centre(&self, t: &Traction) -> [f64; 2] {
        let q = t.point as usize;
        let (x, f, lp, n) = (
            self.points.pos[q],
            self.points.def_grad[q],
            self.points.half_size[q],
            t.normal,
        );
        [
            x[0] + lp * (f[0] * n[0] + f[1] * n[1]),
            x[1] + lp * (f[2] * n[0] + f[3] * n[1]),
        ]
    }

    /// Book the work of the traction forces over the step, f · Δx_face with f as applied and
    /// the displacement of the face centre x_p + F N l_p (nodal velocities are not used: nodes
    /// that hold a sliver of a point's domain have tiny masses and unreliable velocities, and
    /// booking f·v at the nodes over-counted the work by ≈ 30 % in the biaxial test).
    fn book_traction_work(&mut self) {
        let mut work = 0.0;
        for (t, (f, x0)) in self.tractions.iter().zip(&self.traction_applied) {
            let x = self.face_centre(t);
            work += f[0] * (x[0] - x0[0]) + f[1] * (x[1] - x0[1]);
        }
        self.traction_work += work;
    }

    /// Re-sort the points into cell order (x-major, as the nodes).
    fn resort(&mut self) {
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

    /// Bin the points into stripes by the node column where their stencil starts; checks that
    /// every point is finite and its stencil inside the grid.
    fn bin(&mut self) -> Result<()> {
        let g = &self.grid;
        let shape = self.params.shape;
        let ns = self.stripe_start.len() - 1;
        self.stripe_start.iter_mut().for_each(|c| *c = 0);
        let (origin, h) = (g.origin, g.h);
        self.stencils
            .par_iter_mut()
            .zip(self.points.pos.par_iter())
            .zip(self.points.half_size.par_iter())
            .for_each(|((st, &x), &lp)| *st = stencil(shape, origin, h, x, lp));
        for (p, (&x, st)) in self.points.pos.iter().zip(&self.stencils).enumerate() {
            let ok = x[0].is_finite()
                && x[1].is_finite()
                && st.i0 >= 0
                && st.j0 >= 0
                && st.i0 + 2 <= g.nx as i64
                && st.j0 + 2 <= g.ny as i64;
            if !ok {
                let c = [
                    ((x[0] - g.origin[0]) / g.h).max(0.0) as usize,
                    ((x[1] - g.origin[1]) / g.h).max(0.0) as usize,
                ];
                return Err(Error::Unstable {
                    step: self.steps,
                    time: self.time,
                    x: c[0],
                    y: c[1],
                    reason: format!(
                        "material point {p} at ({:e}, {:e}) m is not finite or left the grid",
                        x[0], x[1]
                    ),
                });
            }
            let s = st.i0 as usize / STRIPE;
            self.stripe_of[p] = s as u32;
            self.stripe_start[s + 1] += 1;
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
    // The stencil loops index several 3-arrays (weights, gradients, offsets) by node.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn p2g(&mut self, mass: bool, force: bool, momentum: bool) {
        // The transfer is a const parameter so the FLIP path carries no APIC branches.
        if self.transfer == Transfer::Apic && (mass || momentum) {
            self.p2g_with::<true>(mass, force, momentum)
        } else {
            self.p2g_with::<false>(mass, force, momentum)
        }
    }

    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn p2g_with<const APIC: bool>(&mut self, mass: bool, force: bool, momentum: bool) {
        let g = &mut self.grid;
        let nny = g.ny + 1;
        let pts = &self.points;
        let grav = self.params.gravity;
        let (order, starts) = (&self.order, &self.stripe_start);
        let stencils = &self.stencils;
        let ns = starts.len() - 1;
        let apic = APIC;
        let (origin, h) = (g.origin, g.h);
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
                .for_each(|(k, chunk): (usize, &mut [NodeSums])| {
                    let s = 2 * k + phase;
                    if s >= ns {
                        return;
                    }
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
                        if apic {
                            let x = pts.pos[q];
                            let (mut ddx, mut ddy) = (0.0, 0.0);
                            for k in 0..3 {
                                dx[k] = origin[0] + (st.i0 + k as i64) as f64 * h - x[0];
                                dy[k] = origin[1] + (st.j0 + k as i64) as f64 * h - x[1];
                                ddx += st.wx[k] * dx[k] * dx[k];
                                ddy += st.wy[k] * dy[k] * dy[k];
                            }
                            let bm = pts.affine[q];
                            c = [bm[0] / ddx, bm[1] / ddy, bm[2] / ddx, bm[3] / ddy];
                        }
                        for a in 0..3 {
                            let base = (st.i0 + a as i64 - col0) as usize * nny + st.j0 as usize;
                            for b in 0..3 {
                                let w = st.wx[a] * st.wy[b];
                                let node = &mut chunk[base + b];
                                if mass {
                                    node[0] += w * m;
                                }
                                if apic {
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
                });
        }
    }

    /// Grid velocities from momenta: `vel` = p/m (unconstrained; the FLIP reference) and, when
    /// `into_map`, `vel_map` = p/m with the walls applied (energy not booked: the momentum is
    /// not changed). With `remap` (MUSL, after the momentum update) the walls keep the contact
    /// state that the update gave each node ([`Grid::constrain_remap`]): the re-mapped field
    /// stands for the same v^{n+1}, so a node that the update held on a unilateral wall is
    /// held there, not released because the re-mapped FLIP velocities point away from it.
    fn grid_velocity(&mut self, into_map: bool, remap: bool) {
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
    fn grid_update(&mut self) {
        let g = &mut self.grid;
        let (eps, dt, alpha) = (self.mass_eps, self.dt, self.params.damping);
        let walls = &g.walls;
        let e = g
            .vel_new
            .par_iter_mut()
            .zip(g.vel.par_iter())
            .zip(g.sums.par_iter())
            .zip(g.walls_mask.par_iter())
            .zip(g.contact.par_iter_mut())
            .map(|((((vn, v), s), &mask), engaged)| {
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
            })
            .reduce(|| [0.0; 3], |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
        for (b, v) in self.booked.iter_mut().zip(e) {
            *b += v;
        }
    }

    /// One loop over the points (parallel in chunks), see [`PointPass`].
    #[inline(always)]
    fn point_pass(&mut self, pass: PointPass) -> Result<()> {
        // The transfer is a const parameter so the FLIP path carries no APIC branches.
        if self.transfer == Transfer::Apic {
            self.point_pass_with::<true>(pass)
        } else {
            self.point_pass_with::<false>(pass)
        }
    }

    #[inline(always)]
    fn point_pass_with<const APIC: bool>(&mut self, pass: PointPass) -> Result<()> {
        let g = &self.grid;
        let (h, origin, nny) = (g.h, g.origin, g.ny + 1);
        let (vold, vnew) = (&g.vel, &g.vel_new);
        let vstrain = match pass {
            PointPass::All => &g.vel_new,
            _ => &g.vel_map,
        };
        let dt = self.dt;
        let pic = self.params.pic_fraction;
        let apic = APIC;
        let mat = &self.material;
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
        let stencils = &self.stencils;
        let p = &mut self.points;
        let bad = (
            p.pos.par_chunks_mut(CHUNK),
            p.vel.par_chunks_mut(CHUNK),
            p.def_grad.par_chunks_mut(CHUNK),
            p.vol.par_chunks_mut(CHUNK),
            p.stress.par_chunks_mut(CHUNK),
            p.state.par_chunks_mut(CHUNK),
            p.work.par_chunks_mut(CHUNK),
            p.vol0.par_chunks(CHUNK),
            stencils.par_chunks(CHUNK),
            p.affine.par_chunks_mut(CHUNK),
        )
            .into_par_iter()
            .enumerate()
            .map(
                |(k, (pos, vel, fg, vol, sig, state, work, vol0, sts, aff))| {
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
                                if do_x || pic > 0.0 || apic {
                                    xn[0] += w * vnew[n][0];
                                    xn[1] += w * vnew[n][1];
                                }
                                if apic && do_v {
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
                        if do_v && apic {
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
                                bad = Some((k * CHUNK + q, format!("det F = {j:e} ≤ 0")));
                            }
                            fg[q] = fnew;
                            let vnew_ = j * vol0[q];
                            let de = [dt * l[0], dt * l[3], 0.5 * dt * (l[1] + l[2])];
                            let spin = 0.5 * dt * (l[1] - l[2]);
                            let s0 = sig[q];
                            let s1 = mat.update_stress(&s0, &de, spin, dt, &mut state[q]);
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
                },
            )
            .find_any(|b| b.is_some())
            .flatten();
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

    /// One explicit step of the chosen scheme.
    pub fn step(&mut self) -> Result<()> {
        if self.params.resort_every > 0
            && self.steps.is_multiple_of(self.params.resort_every)
            && self.steps > 0
        {
            self.resort();
        }
        self.bin()?;
        match self.params.scheme {
            Scheme::Usf => {
                self.p2g(true, false, false);
                self.grid_velocity(true, false);
                self.point_pass(PointPass::StressFromMap)?;
                self.p2g(false, true, false);
                self.scatter_tractions();
                self.grid_velocity(false, false);
                self.grid_update();
                self.point_pass(PointPass::VelocityAndMove)?;
            }
            Scheme::Usl => {
                self.p2g(true, true, false);
                self.scatter_tractions();
                self.grid_velocity(false, false);
                self.grid_update();
                self.point_pass(PointPass::All)?;
            }
            Scheme::Musl => {
                self.p2g(true, true, false);
                self.scatter_tractions();
                self.grid_velocity(false, false);
                self.grid_update();
                self.point_pass(PointPass::Velocity)?;
                self.p2g(false, false, true);
                self.grid_velocity(true, true);
                self.point_pass(PointPass::StressFromMapAndMove)?;
            }
        }
        if !self.tractions.is_empty() {
            self.book_traction_work();
        }
        self.time += self.dt;
        self.steps += 1;
        Ok(())
    }

    /// Take `n` steps.
    pub fn steps(&mut self, n: u64) -> Result<()> {
        for _ in 0..n {
            self.step()?;
        }
        Ok(())
    }

    /// Advance by `dt` seconds in steps of at most the solver's step.
    pub fn advance_by(&mut self, dt: f64) -> Result<()> {
        let (n, h) = crate::scale::substeps(dt, self.dt);
        let keep = self.dt;
        self.dt = h;
        let r = self.steps(n);
        self.dt = keep;
        r
    }

    /// The energies now.
    pub fn energy(&self) -> MpmEnergy {
        let p = &self.points;
        let gv = self.params.gravity;
        let mat = &self.material;
        let s = (0..p.len())
            .into_par_iter()
            .map(|q| {
                let v = p.vel[q];
                let m = p.mass[q];
                let el = p.vol[q] * mat.elastic_energy_density(&p.stress[q]);
                [
                    0.5 * m * (v[0] * v[0] + v[1] * v[1]),
                    -m * (gv[0] * p.pos[q][0] + gv[1] * p.pos[q][1]),
                    el,
                    p.work[q] - el,
                ]
            })
            .reduce(
                || [0.0; 4],
                |a, b| [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]],
            );
        MpmEnergy {
            kinetic: s[0],
            potential: s[1],
            elastic: s[2],
            plastic: s[3],
            boundary_normal: self.booked[0],
            boundary_friction: self.booked[1],
            damping: self.booked[2],
            traction: self.traction_work,
        }
    }

    /// Total point mass and momentum.
    pub fn mass_momentum(&self) -> (f64, [f64; 2]) {
        let p = &self.points;
        let mut m = 0.0;
        let mut mv = [0.0; 2];
        for q in 0..p.len() {
            m += p.mass[q];
            mv[0] += p.mass[q] * p.vel[q][0];
            mv[1] += p.mass[q] * p.vel[q][1];
        }
        (m, mv)
    }

    /// Total nodal mass and momentum after the last P2G (momentum as last mapped).
    pub fn grid_mass_momentum(&self) -> (f64, [f64; 2]) {
        let mut m = 0.0;
        let mut mv = [0.0; 2];
        for s in &self.grid.sums {
            m += s[0];
            mv[0] += s[1];
            mv[1] += s[2];
        }
        (m, mv)
    }

    /// Map mass and momentum to the grid now (for diagnostics and output).
    pub fn map_to_grid(&mut self) -> Result<()> {
        self.bin()?;
        self.p2g(true, false, false);
        self.grid_velocity(false, false);
        Ok(())
    }

    /// Mean stress p = (σ_xx + σ_yy + σ_zz)/3 and von Mises equivalent deviatoric stress
    /// q = √(3/2 s:s) of a point.
    pub fn invariants(s: &Stress) -> (f64, f64) {
        let p = (s[0] + s[1] + s[3]) / 3.0;
        let d = [s[0] - p, s[1] - p, s[3] - p];
        let j2 = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + s[2] * s[2];
        (p, (3.0 * j2).sqrt())
    }

    /// The material state of point `q`.
    pub fn state(&self, q: usize) -> MaterialState {
        self.points.state[q]
    }
}
