//! The fluid solver: a lattice, its collision operator and obstacles, advanced in time; and
//! the precision-erased [`Fluid`] interface the CLI and the coupling drivers use.

use super::collision::Collider;
use super::d2q9::{CX, CY, Q};
use super::ladd::BounceLinks;
use super::lattice::Lattice;
use super::obstacle::Obstacles;
use super::partial::{self, CellForces, PartialCells, SolidCover};
use super::real::Real;
use crate::scale::Scale;
use crate::units::{Units, CS2};
use crate::{Error, Result};

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
    /// Cells partially covered by moving solids (empty: a plain fluid).
    pub partial: PartialCells<T>,
    /// Momentum exchanged per covered cell summed over the steps of the last
    /// [`Scale::advance`], and their number (the sum is kept only for more than one step;
    /// for one, [`PartialCells::exchange`] is that step's).
    exchange_sum: (Vec<[f64; 2]>, u64),
    /// Boundary links of moving solids under Ladd's bounce-back (empty: none).
    pub ladd: BounceLinks,
}

impl<T: Real> Lbm<T> {
    /// Assemble a solver; links the obstacles to the lattice.
    pub fn new(
        mut lattice: Lattice<T>,
        collider: Collider<T>,
        mut obstacles: Obstacles,
        units: Units,
    ) -> Self {
        obstacles.link(&lattice);
        lattice.set_body_force(collider.force);
        Lbm {
            lattice,
            collider,
            obstacles,
            units,
            steps: 0,
            partial: PartialCells::new(),
            exchange_sum: (Vec::new(), 0),
            ladd: BounceLinks::default(),
        }
    }

    /// One lattice step; cells in [`Lbm::partial`] collide as partially saturated cells.
    pub fn step(&mut self) {
        let was_even = self.lattice.next_is_even();
        if self.partial.is_empty() {
            self.lattice.step(&self.collider);
        } else {
            self.lattice.step_partial(&self.collider, &mut self.partial);
        }
        if !self.ladd.is_empty() {
            self.ladd.bounce(&mut self.lattice, was_even);
        }
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

    /// Set the covered cells from a solid cover in SI: B = B(ε, τ) of
    /// [`partial::weighting`] with the molecular τ, velocities converted to lattice units.
    /// Cells must be ascending.
    pub fn set_cover(&mut self, cover: &SolidCover) {
        use rayon::prelude::*;
        let p = &mut self.partial;
        let (tau, units, n) = (self.collider.tau, &self.units, cover.cells.len());
        p.cells.clear();
        p.cells.extend_from_slice(&cover.cells);
        // Resized (a cover changes little between steps), then overwritten in one pass.
        p.b.resize(n, T::zero());
        p.ux.resize(n, T::zero());
        p.uy.resize(n, T::zero());
        p.exchange.resize(n, [0.0; 2]);
        (
            &mut p.b,
            &mut p.ux,
            &mut p.uy,
            &mut p.exchange,
            &cover.eps,
            &cover.ux,
            &cover.uy,
        )
            .into_par_iter()
            .for_each(|(b, ux, uy, ex, &e, &vx, &vy)| {
                *b = T::c(partial::weighting(e, tau));
                *ux = T::c(units.velocity_to_lattice(vx));
                *uy = T::c(units.velocity_to_lattice(vy));
                *ex = [0.0; 2];
            });
    }

    /// Total fluid momentum Σ_cells Σ_i f_i e_i (lattice units, pre-collision, without the
    /// half-force shift), accumulated in f64. Nodes inside solids under Ladd's bounce-back
    /// ([`Lbm::ladd`]) are not fluid and not counted.
    pub fn momentum(&self) -> [f64; 2] {
        use rayon::prelude::*;
        let lat = &self.lattice;
        (0..lat.len())
            .into_par_iter()
            .filter(|&c| !lat.is_solid(c) && !self.ladd.is_inside(c))
            .map(|c| {
                let f = lat.populations(c);
                let mut j = [0.0; 2];
                for i in 0..Q {
                    j[0] += f[i].f64() * CX[i] as f64;
                    j[1] += f[i].f64() * CY[i] as f64;
                }
                j
            })
            .reduce(|| [0.0; 2], |a, b| [a[0] + b[0], a[1] + b[1]])
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
    /// Advance `n` lattice steps.
    fn steps(&mut self, n: u64);
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
    /// Stop with [`Error::Unstable`] if a cell is NaN, ρ ≤ 0 or Mach > `max_mach`.
    fn check_stable(&self, max_mach: f64) -> Result<()>;
    /// Bytes of population storage.
    fn bytes(&self) -> usize;
    /// `"f32"` or `"f64"`.
    fn precision(&self) -> &'static str;
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
}

/// A full copy of a fluid state.
#[derive(Clone)]
pub struct LbmSnapshot<T> {
    populations: Vec<T>,
    next_even: bool,
    steps: u64,
    force: Vec<[f64; 2]>,
    torque: Vec<f64>,
}

impl<T: Real> Scale for Lbm<T> {
    /// The cells moving solids cover (an empty cover: a plain fluid).
    type Input = SolidCover;
    /// Force on the solid in each covered cell, averaged over the last advance.
    type Output = CellForces;
    type Snapshot = LbmSnapshot<T>;

    fn time(&self) -> f64 {
        self.steps as f64 * self.units.dt
    }
    fn max_dt(&self) -> f64 {
        self.units.dt
    }
    /// Advance by `dt`, which must be a whole number of lattice steps (within 1e-9).
    fn advance(&mut self, input: &SolidCover, dt: f64) -> Result<()> {
        let n = dt / self.units.dt;
        let k = n.round();
        if (n - k).abs() > 1e-9 * n.max(1.0) || k < 1.0 {
            return Err(Error::Other(format!(
                "LBM advance: dt = {dt:e} s is not a whole number of lattice steps ({:e} s)",
                self.units.dt
            )));
        }
        self.set_cover(input);
        if !(input.links.is_empty() && self.ladd.is_empty()) {
            self.ladd.set(&mut self.lattice, &input.links, &self.units);
        }
        let steps = k as u64;
        let (sum, count) = &mut self.exchange_sum;
        sum.clear();
        if steps > 1 {
            sum.resize(input.cells.len(), [0.0; 2]);
        }
        *count = steps;
        for _ in 0..steps {
            self.step();
            if steps > 1 {
                use rayon::prelude::*;
                self.exchange_sum
                    .0
                    .par_iter_mut()
                    .zip(self.partial.exchange.par_iter())
                    .for_each(|(s, e)| {
                        s[0] += e[0];
                        s[1] += e[1];
                    });
            }
        }
        Ok(())
    }
    /// Force on the solid per covered cell, F = −Δp (N/m), seed eq. 5.53.
    fn observe(&self, out: &mut CellForces) {
        // One step: its own exchange; several: their sum.
        let (sum, count) = match self.exchange_sum {
            (_, 0 | 1) => (&self.partial.exchange, 1),
            (ref sum, k) => (sum, k),
        };
        let k = count as f64;
        use rayon::prelude::*;
        let u = &self.units;
        sum.par_iter()
            .map(|s| (-u.force_to_si(s[0] / k), -u.force_to_si(s[1] / k)))
            .unzip_into_vecs(&mut out.fx, &mut out.fy);
        self.ladd.observe(&self.units, &mut out.links);
    }
    fn snapshot(&self) -> LbmSnapshot<T> {
        let (populations, next_even) = self.lattice.state();
        LbmSnapshot {
            populations,
            next_even,
            steps: self.steps,
            force: self.obstacles.force.clone(),
            torque: self.obstacles.torque.clone(),
        }
    }
    fn restore(&mut self, s: LbmSnapshot<T>) {
        self.lattice.set_state(s.populations, s.next_even);
        self.steps = s.steps;
        self.obstacles.force = s.force;
        self.obstacles.torque = s.torque;
    }
}
