//! The fluid solver: a lattice, its collision operator and obstacles, advanced in time, built
//! from an [`LbmSetup`]; and the precision-erased [`Fluid`] interface the runners use.
//!
//! τ comes from the [`Units`] (τ = 3νΔt/Δx² + ½): the collision operator is built from them,
//! so the relaxation time and the time step cannot disagree.

use super::boundary::Edges;
use super::collision::{Collider, CollisionModel};
use super::covered::CoveredCells;
use super::d2q9::{CX, CY, Q};
use super::lattice::Lattice;
use super::observation::{Observation, Partial};
use super::obstacle::{Obstacle, Obstacles};
use super::real::{Populations, Real};
use crate::units::{Units, CS2};
use crate::{Error, Result};

/// Lattice Mach number |u|/c_s above which a run is stopped as unstable.
pub const STOP_MACH: f64 = 0.5;

/// The fluid's physics apart from its lattice: collision operator, LES and body force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluidModel {
    /// BGK or MRT (whose rates must be those of the units' τ).
    pub collision: CollisionModel,
    /// Smagorinsky constant C_s; `None`: no LES.
    pub smagorinsky: Option<f64>,
    /// Uniform body force density (lattice units, ρ* = 1), applied by Guo forcing.
    pub body_force: [f64; 2],
}

/// Everything a fluid is built from ([`LbmSetup::build`]): a scenario of any kind describes
/// its fluid with one of these.
#[derive(Clone, Debug)]
pub struct LbmSetup {
    /// Cells along x and y.
    pub cells: [usize; 2],
    /// Δx, Δt, ρ₀ and τ.
    pub units: Units,
    /// Collision, LES, body force.
    pub model: FluidModel,
    /// The four edges (velocities and densities in lattice units).
    pub edges: Edges,
    /// Obstacles in lattice coordinates.
    pub obstacles: Vec<Obstacle>,
    /// Initial velocity everywhere (lattice units), at unit density.
    pub initial_velocity: [f64; 2],
}

impl LbmSetup {
    /// Build the fluid in precision `T`: lattice with the obstacles' solid mask, initialised
    /// to the equilibrium at ρ* = 1 and the initial velocity. Fails with the reason when the
    /// edges are inconsistent.
    pub fn build<T: Real>(&self) -> std::result::Result<Lbm<T>, String> {
        let [nx, ny] = self.cells;
        let obstacles = Obstacles::new(self.obstacles.clone());
        let solid = obstacles.mask(nx, ny);
        let mut lattice = Lattice::<T>::new(nx, ny, self.edges.clone(), solid)?;
        let u0 = self.initial_velocity;
        lattice.fill(|_, _| (1.0, u0[0], u0[1]));
        Ok(Lbm::new(lattice, self.model, obstacles, self.units))
    }
}

/// Macroscopic fields in lattice units, one value per cell (`y·nx + x`). Solid cells hold
/// ρ = 1, u = 0.
#[derive(Clone, Debug, Default)]
pub struct Macroscopic {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Density ρ = Σ f_i.
    pub rho: Vec<f64>,
    /// Velocity u_x = (Σ f_i e_ix + F_x/2)/ρ.
    pub ux: Vec<f64>,
    /// Velocity u_y.
    pub uy: Vec<f64>,
    /// Solid mask.
    pub solid: Vec<bool>,
}

impl Macroscopic {
    /// Vorticity ω = ∂u_y/∂x − ∂u_x/∂y by central differences (one-sided at edges and next to
    /// solids), lattice units.
    pub fn vorticity(&self) -> Vec<f64> {
        let (nx, ny) = (self.nx, self.ny);
        let at = |x: usize, y: usize| y * nx + x;
        let d = |v: &[f64], c0: usize, cm: Option<usize>, cp: Option<usize>| -> f64 {
            match (cm, cp) {
                (Some(m), Some(p)) => 0.5 * (v[p] - v[m]),
                (None, Some(p)) => v[p] - v[c0],
                (Some(m), None) => v[c0] - v[m],
                (None, None) => 0.0,
            }
        };
        let ok = |c: usize| (!self.solid[c]).then_some(c);
        (0..nx * ny)
            .map(|c| {
                if self.solid[c] {
                    return 0.0;
                }
                let (x, y) = (c % nx, c / nx);
                let xm = (x > 0).then(|| at(x - 1, y)).and_then(ok);
                let xp = (x + 1 < nx).then(|| at(x + 1, y)).and_then(ok);
                let ym = (y > 0).then(|| at(x, y - 1)).and_then(ok);
                let yp = (y + 1 < ny).then(|| at(x, y + 1)).and_then(ok);
                d(&self.uy, c, xm, xp) - d(&self.ux, c, ym, yp)
            })
            .collect()
    }
}

/// What of a fluid changes as it runs (populations, parity, clock, obstacle loads): with the
/// scenario it was built from, all a checkpoint needs to continue the run bit for bit.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LbmState {
    /// The populations, padding included ([`Lattice::state`]).
    pub populations: Populations,
    /// True when the next step is even (the AA pattern's parity).
    pub next_even: bool,
    /// Steps taken.
    pub steps: u64,
    /// Force on each obstacle in the last step (lattice units).
    pub force: Vec<[f64; 2]>,
    /// Torque on each obstacle in the last step (lattice units).
    pub torque: Vec<f64>,
}

/// A D2Q9 fluid in precision `T`.
pub struct Lbm<T> {
    /// Populations, walls and edges.
    pub lattice: Lattice<T>,
    /// Collision operator.
    pub collider: Collider<T>,
    /// Obstacles with their links and forces.
    pub obstacles: Obstacles,
    /// SI ↔ lattice conversion.
    pub units: Units,
    /// Steps taken.
    pub steps: u64,
}

impl<T: Real> Lbm<T> {
    /// Assemble a solver from a lattice, the fluid's physics, its obstacles and its units (the
    /// collision relaxes at the units' τ); links the obstacles to the lattice.
    pub fn new(
        mut lattice: Lattice<T>,
        model: FluidModel,
        mut obstacles: Obstacles,
        units: Units,
    ) -> Self {
        let collider = Collider::new(
            model.collision,
            units.tau,
            model.smagorinsky,
            model.body_force,
        );
        obstacles.link(&lattice);
        lattice.set_body_force(collider.force);
        Lbm {
            lattice,
            collider,
            obstacles,
            units,
            steps: 0,
        }
    }

    /// A copy of the state that changes as the fluid runs.
    pub fn state(&self) -> LbmState {
        let (f, next_even) = self.lattice.state();
        LbmState {
            populations: T::tag(f),
            next_even,
            steps: self.steps,
            force: self.obstacles.force.clone(),
            torque: self.obstacles.torque.clone(),
        }
    }

    /// Continue from a state taken by [`Lbm::state`] of a fluid built the same way; a state of
    /// another precision, lattice size or obstacle count is refused.
    pub fn set_state(&mut self, s: LbmState) -> Result<()> {
        let precision = match &s.populations {
            Populations::F32(_) => "f32",
            Populations::F64(_) => "f64",
        };
        let f = T::untag(s.populations).ok_or_else(|| {
            Error::Other(format!(
                "the saved fluid has {precision} populations, this one {}",
                T::NAME
            ))
        })?;
        if f.len() != self.lattice.state_len() || s.force.len() != self.obstacles.force.len() {
            return Err(Error::Other(format!(
                "the saved fluid has {} population values and {} obstacles, this one {} and {}",
                f.len(),
                s.force.len(),
                self.lattice.state_len(),
                self.obstacles.force.len()
            )));
        }
        self.lattice.set_state(f, s.next_even);
        self.steps = s.steps;
        self.obstacles.force = s.force;
        self.obstacles.torque = s.torque;
        Ok(())
    }

    /// One lattice step.
    pub fn step(&mut self) {
        let was_even = self.lattice.next_is_even();
        self.lattice.step(&self.collider);
        self.obstacles.after_step(&mut self.lattice, was_even);
        self.steps += 1;
    }

    /// One lattice step in which the cells of `covered` collide with a coupling method's term
    /// ([`Lattice::step_covered`], the exchanged momentum into `exchange`), and `after_stream`
    /// (e.g. a bounce-back on moving solids) runs on the streamed lattice, with the parity of
    /// the step just taken, before the obstacles take theirs.
    pub fn step_covered<C: CoveredCells<T>>(
        &mut self,
        covered: &C,
        exchange: &mut [[f64; 2]],
        after_stream: impl FnOnce(&mut Lattice<T>, bool),
    ) {
        let was_even = self.lattice.next_is_even();
        self.lattice.step_covered(&self.collider, covered, exchange);
        after_stream(&mut self.lattice, was_even);
        self.obstacles.after_step(&mut self.lattice, was_even);
        self.steps += 1;
    }

    /// Density and velocity of fluid cell `c` (lattice units).
    pub fn cell(&self, c: usize) -> (f64, f64, f64) {
        let f = self.lattice.populations(c);
        let (mut r, mut jx, mut jy) = (0.0, 0.0, 0.0);
        for i in 0..Q {
            let v = f[i].f64();
            r += v;
            jx += v * CX[i] as f64;
            jy += v * CY[i] as f64;
        }
        let [fx, fy] = self.collider.force;
        (r, (jx + 0.5 * fx) / r, (jy + 0.5 * fy) / r)
    }

    /// Total fluid momentum Σ_cells Σ_i f_i e_i (lattice units, pre-collision, without the
    /// half-force shift), accumulated in f64, over the cells that are not solid and not
    /// `excluded` (e.g. nodes inside moving solids under Ladd's bounce-back).
    pub fn momentum(&self, excluded: impl Fn(usize) -> bool + Sync) -> [f64; 2] {
        let lat = &self.lattice;
        crate::exec::ordered_sum(lat.len(), 4096, |c| {
            let mut j = [0.0; 2];
            if !lat.is_solid(c) && !excluded(c) {
                let f = lat.populations(c);
                for i in 0..Q {
                    j[0] += f[i].f64() * CX[i] as f64;
                    j[1] += f[i].f64() * CY[i] as f64;
                }
            }
            j
        })
    }

    /// Fill `m` with the macroscopic fields.
    pub fn macroscopic_into(&self, m: &mut Macroscopic) {
        use rayon::prelude::*;
        let n = self.lattice.len();
        m.nx = self.lattice.nx;
        m.ny = self.lattice.ny;
        let vals: Vec<(f64, f64, f64)> = (0..n)
            .into_par_iter()
            .map(|c| {
                if self.lattice.is_solid(c) {
                    (1.0, 0.0, 0.0)
                } else {
                    self.cell(c)
                }
            })
            .collect();
        m.rho = vals.iter().map(|v| v.0).collect();
        m.ux = vals.iter().map(|v| v.1).collect();
        m.uy = vals.iter().map(|v| v.2).collect();
        m.solid = self.lattice.solid().to_vec();
    }

    /// Sums over the fluid cells (in chunks of rows, combined in order: the same value on any
    /// number of threads) and the state of the `probes` cells.
    pub fn observe(&self, probes: &[usize]) -> Observation {
        use rayon::prelude::*;
        let nx = self.lattice.nx;
        let rows = (4096 / nx).max(1);
        let parts: Vec<Partial> = (0..self.lattice.ny.div_ceil(rows))
            .into_par_iter()
            .map(|k| {
                let cells = k * rows * nx..((k + 1) * rows * nx).min(self.lattice.len());
                cells
                    .filter(|&c| !self.lattice.is_solid(c))
                    .fold(Observation::EMPTY, |p, c| {
                        Observation::add_cell(p, self.cell(c))
                    })
            })
            .collect();
        let probes = probes
            .iter()
            .map(|&c| {
                if self.lattice.is_solid(c) {
                    (1.0, 0.0, 0.0)
                } else {
                    self.cell(c)
                }
            })
            .collect();
        Observation::from_partials(parts, probes)
    }

    /// First cell that is NaN, has ρ ≤ 0 or lattice Mach |u|/c_s > `max_mach`.
    pub fn find_instability(&self, max_mach: f64) -> Option<(usize, String)> {
        use rayon::prelude::*;
        let cs = CS2.sqrt();
        (0..self.lattice.len()).into_par_iter().find_first(|&c| {
            if self.lattice.is_solid(c) {
                return false;
            }
            let (r, u, v) = self.cell(c);
            r.is_nan() || r <= 0.0 || !u.is_finite() || !v.is_finite() || (u * u + v * v).sqrt() / cs > max_mach
        })
        .map(|c| {
            let (r, u, v) = self.cell(c);
            let reason = if r.is_nan() || u.is_nan() || v.is_nan() {
                "NaN in the populations".to_string()
            } else if r <= 0.0 {
                format!("density {r:.3e} ≤ 0")
            } else {
                format!(
                    "lattice Mach number {:.3} > {max_mach} (|u| = {:.3e} lattice units): reduce the time step or the velocity",
                    (u * u + v * v).sqrt() / cs,
                    (u * u + v * v).sqrt()
                )
            };
            (c, reason)
        })
    }
}

/// Precision-erased fluid solver, as the CLI and drivers use it.
pub trait Fluid: Send {
    /// Advance `n` lattice steps (on a GPU: submitted, see [`Fluid::finish`]).
    fn steps(&mut self, n: u64);
    /// Wait until the steps submitted so far have run (a GPU runs them asynchronously; the
    /// observing methods wait by themselves).
    fn finish(&self) {}
    /// Steps taken so far.
    fn step_count(&self) -> u64;
    /// SI ↔ lattice conversion.
    fn units(&self) -> Units;
    /// Macroscopic fields.
    fn macroscopic(&self, m: &mut Macroscopic);
    /// Density and velocity of one fluid cell (lattice units).
    fn cell_state(&self, c: usize) -> (f64, f64, f64);
    /// Force and torque on each obstacle in the last step (lattice units).
    fn obstacle_loads(&self) -> (Vec<[f64; 2]>, Vec<f64>);
    /// Total fluid mass (lattice units).
    fn total_mass(&self) -> f64;
    /// Sums over the fluid cells and the state of the `probes` cells (see [`Observation`]).
    fn observe(&self, probes: &[usize]) -> Observation;
    /// Stop with [`Error::Unstable`] if a cell is NaN, ρ ≤ 0 or Mach > `max_mach`.
    fn check_stable(&self, max_mach: f64) -> Result<()>;
    /// Bytes of population storage.
    fn bytes(&self) -> usize;
    /// `"f32"` or `"f64"`.
    fn precision(&self) -> &'static str;
    /// A copy of the state that changes as the fluid runs ([`Lbm::state`]).
    fn state(&self) -> LbmState;
    /// Continue from a saved state ([`Lbm::set_state`]).
    fn set_state(&mut self, s: LbmState) -> Result<()>;
}

impl<T: Real> Fluid for Lbm<T> {
    fn steps(&mut self, n: u64) {
        for _ in 0..n {
            self.step();
        }
    }
    fn step_count(&self) -> u64 {
        self.steps
    }
    fn units(&self) -> Units {
        self.units
    }
    fn macroscopic(&self, m: &mut Macroscopic) {
        self.macroscopic_into(m)
    }
    fn cell_state(&self, c: usize) -> (f64, f64, f64) {
        self.cell(c)
    }
    fn obstacle_loads(&self) -> (Vec<[f64; 2]>, Vec<f64>) {
        (self.obstacles.force.clone(), self.obstacles.torque.clone())
    }
    fn total_mass(&self) -> f64 {
        self.lattice.total_mass()
    }
    fn observe(&self, probes: &[usize]) -> Observation {
        Lbm::observe(self, probes)
    }
    fn check_stable(&self, max_mach: f64) -> Result<()> {
        match self.find_instability(max_mach) {
            None => Ok(()),
            Some((c, reason)) => Err(Error::Unstable {
                step: self.steps,
                time: self.steps as f64 * self.units.dt,
                x: c % self.lattice.nx,
                y: c / self.lattice.nx,
                reason,
            }),
        }
    }
    fn bytes(&self) -> usize {
        self.lattice.bytes()
    }
    fn precision(&self) -> &'static str {
        T::NAME
    }
    fn state(&self) -> LbmState {
        Lbm::state(self)
    }
    fn set_state(&mut self, s: LbmState) -> Result<()> {
        Lbm::set_state(self, s)
    }
}
