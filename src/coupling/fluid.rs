//! The fluid with moving solids in it: the LBM plus the coupling methods' state (partially
//! saturated cells, Ladd's boundary links), as one [`Scale`] whose input is what the solids
//! cover ([`SolidCover`], SI) and whose output is the force on them ([`CellForces`], SI).
//!
//! One lattice step collides the covered cells with the partially saturated blend
//! ([`super::psm`]) and then bounces the populations back on Ladd's links
//! ([`super::ladd`]); with neither it is the plain fluid step.

use rayon::prelude::*;

use super::ladd::{BounceLinks, LinkCover, LinkForces};
use super::psm::{weighting, PartialCells};
use crate::lbm::{Lbm, LbmState, Real};
use crate::scale::Scale;
use crate::{Error, Result};

/// What a solid scale hands the fluid (SI): the cells it covers, ascending, with the exact
/// solid fraction ε and the solid velocity at each cell centre.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SolidCover {
    /// Cell indices y·nx + x, ascending.
    pub cells: Vec<u32>,
    /// Solid fraction ε ∈ [0, 1].
    pub eps: Vec<f64>,
    /// Solid velocity x (m/s).
    pub ux: Vec<f64>,
    /// Solid velocity y (m/s).
    pub uy: Vec<f64>,
    /// Boundary links for Ladd's bounce-back ([`super::ladd`]; empty under PSM).
    pub links: LinkCover,
}

/// What the fluid hands back: the hydrodynamic force on the solid in each covered cell
/// (N per metre of depth), in the order of [`SolidCover::cells`].
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct CellForces {
    /// Force x.
    pub fx: Vec<f64>,
    /// Force y.
    pub fy: Vec<f64>,
    /// Forces across Ladd's boundary links ([`super::ladd`]; empty under PSM).
    pub links: LinkForces,
}

/// The LBM and the state of the coupling methods between it and the solids.
pub struct CoupledFluid<T> {
    /// The fluid.
    pub lbm: Lbm<T>,
    /// Cells partially covered by moving solids (empty: none).
    pub partial: PartialCells<T>,
    /// Momentum the solid term gave the fluid at each covered cell in the last step (lattice
    /// units), in the order of [`PartialCells::cells`]; the force on the solid is its negative.
    pub exchange: Vec<[f64; 2]>,
    /// Momentum exchanged per covered cell summed over the steps of the last
    /// [`Scale::advance`], and their number (the sum is kept only for more than one step;
    /// for one, [`CoupledFluid::exchange`] is that step's).
    exchange_sum: (Vec<[f64; 2]>, u64),
    /// Boundary links of moving solids under Ladd's bounce-back (empty: none).
    pub ladd: BounceLinks,
}

/// What a coupled fluid carries from step to step: the fluid's own state ([`LbmState`]), the
/// partially covered cells, the exchanged momentum and Ladd's links; with the scenario it was
/// built from, what a checkpoint needs to continue it bit for bit.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CoupledFluidState<T> {
    lbm: LbmState,
    partial: PartialCells<T>,
    exchange: Vec<[f64; 2]>,
    exchange_sum: (Vec<[f64; 2]>, u64),
    ladd: BounceLinks,
}

impl<T: Real> CoupledFluid<T> {
    /// A copy of the state that changes as it runs.
    pub fn state(&self) -> CoupledFluidState<T> {
        CoupledFluidState {
            lbm: self.lbm.state(),
            partial: self.partial.clone(),
            exchange: self.exchange.clone(),
            exchange_sum: self.exchange_sum.clone(),
            ladd: self.ladd.clone(),
        }
    }

    /// Continue from a state taken by [`CoupledFluid::state`] of a fluid built the same way.
    pub fn set_state(&mut self, s: CoupledFluidState<T>) -> Result<()> {
        self.lbm.set_state(s.lbm)?;
        self.partial = s.partial;
        self.exchange = s.exchange;
        self.exchange_sum = s.exchange_sum;
        self.ladd = s.ladd;
        Ok(())
    }

    /// The fluid `lbm` with no solid in it yet.
    pub fn new(lbm: Lbm<T>) -> Self {
        CoupledFluid {
            lbm,
            partial: PartialCells::new(),
            exchange: Vec::new(),
            exchange_sum: (Vec::new(), 0),
            ladd: BounceLinks::default(),
        }
    }

    /// One lattice step: covered cells collide as partially saturated cells, then Ladd's links
    /// bounce back.
    pub fn step(&mut self) {
        // Cells pushed by hand since the last cover get an exchange entry too.
        self.exchange.resize(self.partial.len(), [0.0; 2]);
        let links = &mut self.ladd;
        self.lbm
            .step_covered(&self.partial, &mut self.exchange, |lat, was_even| {
                if !links.is_empty() {
                    links.bounce(lat, was_even);
                }
            });
    }

    /// Set the covered cells from a solid cover in SI: B = B(ε, τ) of [`weighting`] with the
    /// molecular τ, velocities converted to lattice units; the exchange is zeroed.
    /// Cells must be ascending.
    pub fn set_cover(&mut self, cover: &SolidCover) {
        let p = &mut self.partial;
        let (tau, units, n) = (self.lbm.units.tau, &self.lbm.units, cover.cells.len());
        p.cells.clear();
        p.cells.extend_from_slice(&cover.cells);
        // Resized (a cover changes little between steps), then overwritten in one pass.
        p.b.resize(n, T::zero());
        p.ux.resize(n, T::zero());
        p.uy.resize(n, T::zero());
        self.exchange.resize(n, [0.0; 2]);
        (
            &mut p.b,
            &mut p.ux,
            &mut p.uy,
            &mut self.exchange,
            &cover.eps,
            &cover.ux,
            &cover.uy,
        )
            .into_par_iter()
            .for_each(|(b, ux, uy, ex, &e, &vx, &vy)| {
                *b = T::c(weighting(e, tau));
                *ux = T::c(units.velocity_to_lattice(vx));
                *uy = T::c(units.velocity_to_lattice(vy));
                *ex = [0.0; 2];
            });
    }

    /// Total fluid momentum (lattice units, see [`Lbm::momentum`]); nodes inside solids under
    /// Ladd's bounce-back are not fluid and not counted.
    pub fn momentum(&self) -> [f64; 2] {
        self.lbm.momentum(|c| self.ladd.is_inside(c))
    }
}

impl<T: Real> Scale for CoupledFluid<T> {
    /// The cells moving solids cover (an empty cover: a plain fluid).
    type Input = SolidCover;
    /// Force on the solid in each covered cell, averaged over the last advance.
    type Output = CellForces;
    type Snapshot = LbmState;

    fn time(&self) -> f64 {
        self.lbm.steps as f64 * self.lbm.units.dt
    }
    /// The lattice step: the fluid advances in whole lattice steps.
    fn max_dt(&self) -> f64 {
        self.lbm.units.dt
    }
    /// Advance by `dt`, which must be a whole number of lattice steps (within 1e-9).
    fn advance(&mut self, input: &SolidCover, dt: f64) -> Result<()> {
        let n = dt / self.lbm.units.dt;
        let k = n.round();
        if (n - k).abs() > 1e-9 * n.max(1.0) || k < 1.0 {
            return Err(Error::Other(format!(
                "LBM advance: dt = {dt:e} s is not a whole number of lattice steps ({:e} s)",
                self.lbm.units.dt
            )));
        }
        self.set_cover(input);
        if !(input.links.is_empty() && self.ladd.is_empty()) {
            self.ladd
                .set(&mut self.lbm.lattice, &input.links, &self.lbm.units);
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
                self.exchange_sum
                    .0
                    .par_iter_mut()
                    .zip(self.exchange.par_iter())
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
            (_, 0 | 1) => (&self.exchange, 1),
            (ref sum, k) => (sum, k),
        };
        let k = count as f64;
        let u = &self.lbm.units;
        sum.par_iter()
            .map(|s| (-u.force_to_si(s[0] / k), -u.force_to_si(s[1] / k)))
            .unzip_into_vecs(&mut out.fx, &mut out.fy);
        self.ladd.observe(&self.lbm.units, &mut out.links);
    }
    fn snapshot(&self) -> LbmState {
        self.lbm.state()
    }
    fn restore(&mut self, s: LbmState) {
        self.lbm
            .set_state(s)
            .expect("a snapshot of this fluid restores into it");
    }
}
