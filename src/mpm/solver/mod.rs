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
use super::material::{Material, MaterialModel, Stress};
use super::points::{PermuteScratch, Points};
use super::shape::{weights_1d, Shape1d, ShapeKind};
use crate::{Error, Result};

mod transfer;

/// Update scheme (order of stress update and momentum update).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
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
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
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
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
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
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
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
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
/// Points per parallel work item of the point loops (the stress update uses the material's
/// own [`Material::POINTS_PER_TASK`]).
const CHUNK: usize = 512;

/// The MPM system, generic over its constitutive law `M` (the built-in laws by default).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "M: serde::Serialize, M::State: serde::Serialize",
    deserialize = "M: serde::Deserialize<'de>, M::State: serde::Deserialize<'de>"
))]
pub struct Mpm<M: Material = MaterialModel> {
    /// Background grid.
    pub grid: Grid,
    /// Material points.
    pub points: Points<M::State>,
    /// Constitutive law (one material for all points).
    pub material: M,
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
    scratch: PermuteScratch<M::State>,
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
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
struct Stencil {
    i0: i64,
    j0: i64,
    wx: [f64; 3],
    gx: [f64; 3],
    wy: [f64; 3],
    gy: [f64; 3],
}

impl Stencil {
    /// APIC's node offsets x_i − x_p of the point at `x` (per direction, the stencil's three
    /// node columns and rows) and its inertia D_p = diag(Σ_i N_ip (x_i − x_p)²), which is
    /// diagonal for a tensor-product shape: C_p = B_p D_p⁻¹ (Jiang et al. 2015).
    #[inline(always)]
    fn apic_offsets(
        &self,
        x: [f64; 2],
        origin: [f64; 2],
        h: f64,
    ) -> ([f64; 3], [f64; 3], [f64; 2]) {
        let (mut dx, mut dy, mut d) = ([0.0; 3], [0.0; 3], [0.0; 2]);
        for k in 0..3 {
            dx[k] = origin[0] + (self.i0 + k as i64) as f64 * h - x[0];
            dy[k] = origin[1] + (self.j0 + k as i64) as f64 * h - x[1];
            d[0] += self.wx[k] * dx[k] * dx[k];
            d[1] += self.wy[k] * dy[k] * dy[k];
        }
        (dx, dy, d)
    }
}

/// The stencil of the point at `p` whose shape along both directions is `s`.
#[inline(always)]
fn stencil(s: Shape1d, origin: [f64; 2], p: [f64; 2]) -> Stencil {
    let (i0, wx, gx) = s.weights(p[0] - origin[0]);
    let (j0, wy, gy) = s.weights(p[1] - origin[1]);
    Stencil {
        i0,
        j0,
        wx,
        gx,
        wy,
        gy,
    }
}

/// The stencils `out` of the points at `x` with half-sizes `lp`.
#[inline(always)]
fn stencils(
    shape: ShapeKind,
    origin: [f64; 2],
    h: f64,
    x: &[[f64; 2]],
    lp: &[f64],
    out: &mut [Stencil],
) {
    let inv_h = 1.0 / h;
    for ((st, &x), &lp) in out.iter_mut().zip(x).zip(lp) {
        *st = stencil(Shape1d::with_inverse(shape, h, inv_h, lp), origin, x);
    }
}

/// The CFL limit C h/c, c = √((K + 4G/3)/ρ).
pub fn cfl_step(material: &impl Material, h: f64, courant: f64) -> f64 {
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

impl<M: Material> Mpm<M> {
    /// Assemble a system. Refuses (naming `time.dt`) a step above the CFL limit, a Courant
    /// number outside (0, 1], damping outside [0, 1), more than 8 walls, or points outside
    /// the grid's interior.
    pub fn new(
        grid: Grid,
        points: Points<M::State>,
        material: M,
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
            let pts = &mut mpm.points;
            pts.work[p] = pts.vol[p]
                * mpm
                    .material
                    .elastic_energy_density(&pts.stress[p], &pts.state[p]);
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

    /// Start the APIC affine matrices from the velocity gradient `grad(x)` = (∂u/∂x, ∂u/∂y,
    /// ∂v/∂x, ∂v/∂y) at each point: B_p = C_p D_p with C_p = ∇v(x_p) and D_p the point's
    /// inertia ([`Stencil::apic_offsets`]), the inverse of the point-to-grid transfer's C_p =
    /// B_p D_p⁻¹, so that the first transfer carries the field's affine part (an affine field
    /// reaches the grid exactly). Nothing to set with FLIP/PIC, which have no affine term.
    pub fn set_velocity_gradient(&mut self, grad: impl Fn([f64; 2]) -> [f64; 4]) {
        if self.transfer != Transfer::Apic {
            return;
        }
        let (origin, h) = (self.grid.origin, self.grid.h);
        let p = &mut self.points;
        for ((b, &x), st) in p.affine.iter_mut().zip(&p.pos).zip(&self.stencils) {
            let (_, _, d) = st.apic_offsets(x, origin, h);
            let c = grad(x);
            *b = [c[0] * d[0], c[1] * d[1], c[2] * d[0], c[3] * d[1]];
        }
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

    /// Set the initial stress of every point (and its stress work to the elastic energy),
    /// with the state the material starts a point with at that stress
    /// ([`Material::initial_state`]; the stress a point really starts with may differ for a
    /// representative volume). Refuses a stress the material cannot start from, naming the
    /// point.
    pub fn set_stress(&mut self, f: impl Fn([f64; 2]) -> Stress + Sync) -> Result<()> {
        let material = &self.material;
        let p = &mut self.points;
        let started: Vec<_> = p
            .pos
            .par_iter()
            .map(|&x| material.initial_state(&f(x)))
            .collect();
        for (q, s) in started.into_iter().enumerate() {
            let (state, stress) = s.map_err(|why| {
                Error::Other(format!(
                    "initial stress of material point {q} at {:?}: {why}",
                    p.pos[q]
                ))
            })?;
            p.work[q] = p.vol[q] * material.elastic_energy_density(&stress, &state);
            p.stress[q] = stress;
            p.state[q] = state;
        }
        Ok(())
    }

    /// Add pressure loads on boundary faces of points. Refuses a point index out of range, a
    /// normal that is not ±x or ±y, a pressure that is not finite, or a face outside the grid.
    pub fn add_tractions(&mut self, loads: impl IntoIterator<Item = Traction>) -> Result<()> {
        if self.grid.period_x.is_some() {
            return Err(Error::Other(
                "traction loads on a grid periodic in x are not supported".into(),
            ));
        }
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
        let s = crate::exec::ordered_sum(p.len(), CHUNK, |q| {
            let v = p.vel[q];
            let m = p.mass[q];
            let el = p.vol[q] * mat.elastic_energy_density(&p.stress[q], &p.state[q]);
            [
                0.5 * m * (v[0] * v[0] + v[1] * v[1]),
                -m * (gv[0] * p.pos[q][0] + gv[1] * p.pos[q][1]),
                el,
                p.work[q] - el,
            ]
        });
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

    /// Total nodal mass and momentum after the last P2G (momentum as last mapped; a periodic
    /// grid's images not counted).
    pub fn grid_mass_momentum(&self) -> (f64, [f64; 2]) {
        let mut m = 0.0;
        let mut mv = [0.0; 2];
        let g = &self.grid;
        for s in (0..g.nodes()).filter(|&n| g.owns(n)).map(|n| &g.sums[n]) {
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

    /// The material state of point `q`.
    pub fn state(&self, q: usize) -> &M::State {
        &self.points.state[q]
    }
}
