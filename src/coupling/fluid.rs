//! The fluid with moving solids in it: the LBM plus the coupling methods' state (partially
//! saturated cells, Ladd's boundary links), as one [`Scale`] whose input is what the solids
//! cover ([`SolidCover`], SI) and whose output is the force on them ([`CellForces`], SI).
//!
//! One lattice step collides the covered cells with the partially saturated blend
//! ([`super::psm`]) and then bounces the populations back on Ladd's links
//! ([`super::ladd`]); with neither it is the plain fluid step.
//!
//! The lattice steps on the CPU, or on a GPU ([`CoupledFluid::on`], feature `gpu`) with the
//! blend in the kernel ([`super::psm::collision::DEVICE_TERM`]): then per coupled step the
//! covered cells go up and their exchanged momenta come back, and the populations stay on the
//! device. Ladd's links run on the CPU only.

use std::borrow::Cow;
use std::ops::Deref;

use rayon::prelude::*;

use super::ladd::{BounceLinks, LinkCover, LinkForces};
use super::psm::{weighting, PartialCells};
use crate::lbm::{Backend, Lbm, LbmState, Real};
use crate::scale::Scale;
use crate::units::Units;
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

/// The lattice of a coupled fluid, on the back end it steps on (one per fluid: the variants'
/// sizes do not matter).
#[allow(clippy::large_enum_variant)]
enum Lattices<T> {
    Cpu(Lbm<T>),
    #[cfg(feature = "gpu")]
    Gpu(crate::lbm::gpu::GpuFluid<T>),
}

/// The fluid's solver as it stands ([`CoupledFluid::lbm`]).
pub enum LbmRef<'a, T> {
    /// Stepping on the CPU.
    Cpu(&'a Lbm<T>),
    /// The host copy of a fluid on a GPU, brought up to date.
    #[cfg(feature = "gpu")]
    Gpu(std::cell::Ref<'a, Lbm<T>>),
}

impl<T> Deref for LbmRef<'_, T> {
    type Target = Lbm<T>;
    fn deref(&self) -> &Lbm<T> {
        match self {
            LbmRef::Cpu(l) => l,
            #[cfg(feature = "gpu")]
            LbmRef::Gpu(l) => l,
        }
    }
}

/// Momentum exchanged per covered cell summed over the steps of an advance, and their number.
type ExchangeSum = (Vec<[f64; 2]>, u64);

/// The LBM and the state of the coupling methods between it and the solids.
pub struct CoupledFluid<T> {
    /// The fluid.
    fluid: Lattices<T>,
    /// Cells partially covered by moving solids (empty: none).
    pub partial: PartialCells<T>,
    /// Momentum the solid term gave the fluid at each covered cell in the last step (lattice
    /// units), in the order of [`PartialCells::cells`]; the force on the solid is its negative.
    /// On a GPU the device keeps the sums instead (read back by [`Scale::observe`]).
    pub exchange: Vec<[f64; 2]>,
    /// Momentum exchanged per covered cell summed over the steps of the last
    /// [`Scale::advance`], and their number (the sum is kept only for more than one step;
    /// for one, [`CoupledFluid::exchange`] is that step's).
    exchange_sum: ExchangeSum,
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
    exchange_sum: ExchangeSum,
    ladd: BounceLinks,
}

impl<T: Real> CoupledFluid<T> {
    /// The fluid `lbm` with no solid in it yet, stepping on the CPU.
    pub fn new(lbm: Lbm<T>) -> Self {
        CoupledFluid {
            fluid: Lattices::Cpu(lbm),
            partial: PartialCells::new(),
            exchange: Vec::new(),
            exchange_sum: (Vec::new(), 0),
            ladd: BounceLinks::default(),
        }
    }

    /// The same fluid on `backend`: on `gpu` its populations move to the device, which then
    /// also blends the covered cells; back on `cpu` they come home. Fails with the reason when
    /// the back end is not built, finds no adapter or lacks something the fluid uses.
    pub fn on(self, backend: Backend) -> Result<Self> {
        backend.check().map_err(Error::Other)?;
        if backend == self.backend() {
            return Ok(self);
        }
        let (exchange, exchange_sum) = self.exchange_state();
        // One arm in a build without the GPU back end.
        #[allow(clippy::infallible_destructuring_match)]
        let lbm = match self.fluid {
            Lattices::Cpu(l) => l,
            #[cfg(feature = "gpu")]
            Lattices::Gpu(g) => g.into_host(),
        };
        let fluid = match backend {
            Backend::Cpu => Lattices::Cpu(lbm),
            #[cfg(feature = "gpu")]
            Backend::Gpu => {
                let gpu = crate::lbm::gpu::Gpu::new().map_err(Error::Other)?;
                let term = super::psm::collision::DEVICE_TERM;
                Lattices::Gpu(
                    crate::lbm::gpu::GpuFluid::with_term(&gpu, lbm, Some(&term))
                        .map_err(Error::Other)?,
                )
            }
            #[cfg(not(feature = "gpu"))]
            Backend::Gpu => unreachable!("refused by Backend::check"),
        };
        let mut moved = CoupledFluid { fluid, ..self };
        moved.set_exchange(exchange, exchange_sum);
        Ok(moved)
    }

    /// The back end the lattice steps on.
    pub fn backend(&self) -> Backend {
        match self.fluid {
            Lattices::Cpu(_) => Backend::Cpu,
            #[cfg(feature = "gpu")]
            Lattices::Gpu(_) => Backend::Gpu,
        }
    }

    /// The fluid's solver, up to date (on a GPU: its host copy, downloaded when behind).
    pub fn lbm(&self) -> LbmRef<'_, T> {
        match &self.fluid {
            Lattices::Cpu(l) => LbmRef::Cpu(l),
            #[cfg(feature = "gpu")]
            Lattices::Gpu(g) => LbmRef::Gpu(g.host()),
        }
    }

    /// The fluid's units (without bringing a GPU's host copy up to date).
    pub fn units(&self) -> Units {
        match &self.fluid {
            Lattices::Cpu(l) => l.units,
            #[cfg(feature = "gpu")]
            Lattices::Gpu(g) => crate::lbm::Fluid::units(g),
        }
    }

    /// A copy of the state that changes as it runs.
    pub fn state(&self) -> CoupledFluidState<T> {
        let (exchange, exchange_sum) = self.exchange_state();
        CoupledFluidState {
            lbm: self.lbm().state(),
            partial: self.partial.clone(),
            exchange,
            exchange_sum,
            ladd: self.ladd.clone(),
        }
    }

    /// Continue from a state taken by [`CoupledFluid::state`] of a fluid built the same way.
    pub fn set_state(&mut self, s: CoupledFluidState<T>) -> Result<()> {
        self.set_lbm_state(s.lbm)?;
        self.partial = s.partial;
        self.ladd = s.ladd;
        self.set_exchange(s.exchange, s.exchange_sum);
        Ok(())
    }

    /// Continue the lattice from `s` (on a GPU: uploaded).
    fn set_lbm_state(&mut self, s: LbmState) -> Result<()> {
        match &mut self.fluid {
            Lattices::Cpu(l) => l.set_state(s),
            #[cfg(feature = "gpu")]
            Lattices::Gpu(g) => crate::lbm::Fluid::set_state(g, s),
        }
    }

    /// [`CoupledFluid::exchange`] and the exchange sum as the CPU keeps them (from the device's
    /// sums on a GPU; the last step's own exchange is not needed to continue a sum).
    fn exchange_state(&self) -> (Vec<[f64; 2]>, ExchangeSum) {
        match self.exchange_sums() {
            (sums, 1) => (sums.into_owned(), (Vec::new(), self.exchange_sum.1)),
            (sums, k) => (self.exchange.clone(), (sums.into_owned(), k)),
        }
    }

    /// Set what [`CoupledFluid::exchange_state`] returned, with the cover of
    /// [`CoupledFluid::partial`] (on a GPU both go to the device, which holds the sums).
    fn set_exchange(&mut self, exchange: Vec<[f64; 2]>, exchange_sum: ExchangeSum) {
        self.exchange = exchange;
        self.exchange_sum = exchange_sum;
        self.upload_cover();
        #[cfg(feature = "gpu")]
        if let Lattices::Gpu(g) = &mut self.fluid {
            let sums = match self.exchange_sum.1 {
                0 | 1 => &self.exchange,
                _ => &self.exchange_sum.0,
            };
            g.lattice_mut().set_covered_exchange::<T>(sums);
        }
    }

    /// The momentum each covered cell's solid term gave the fluid (lattice units), summed
    /// over the steps of the last advance, and their number (at least 1): on the CPU from
    /// [`CoupledFluid::exchange`] or the step sum, on a GPU the device's sums (read back).
    fn exchange_sums(&self) -> (Cow<'_, [[f64; 2]]>, u64) {
        let k = self.exchange_sum.1.max(1);
        match &self.fluid {
            Lattices::Cpu(_) if k == 1 => (Cow::Borrowed(&self.exchange), 1),
            Lattices::Cpu(_) => (Cow::Borrowed(&self.exchange_sum.0), k),
            #[cfg(feature = "gpu")]
            Lattices::Gpu(g) => (Cow::Owned(g.lattice().covered_exchange::<T>()), k),
        }
    }

    /// Put the covered cells on the device (a fluid on a GPU; nothing on the CPU).
    fn upload_cover(&mut self) {
        #[cfg(feature = "gpu")]
        if let Lattices::Gpu(g) = &mut self.fluid {
            let values = self.partial.device_values();
            g.lattice_mut().set_cover(&self.partial.cells, &values);
        }
    }

    /// One lattice step: covered cells collide as partially saturated cells, then Ladd's links
    /// bounce back.
    pub fn step(&mut self) {
        // Cells pushed by hand since the last cover get an exchange entry too.
        self.exchange.resize(self.partial.len(), [0.0; 2]);
        match &mut self.fluid {
            Lattices::Cpu(lbm) => {
                let links = &mut self.ladd;
                lbm.step_covered(&self.partial, &mut self.exchange, |lat, was_even| {
                    if !links.is_empty() {
                        links.bounce(lat, was_even);
                    }
                });
            }
            #[cfg(feature = "gpu")]
            Lattices::Gpu(g) => crate::lbm::Fluid::steps(g, 1),
        }
    }

    /// Set the covered cells from a solid cover in SI: B = B(ε, τ) of [`weighting`] with the
    /// molecular τ, velocities converted to lattice units; the exchange is zeroed.
    /// Cells must be ascending.
    pub fn set_cover(&mut self, cover: &SolidCover) {
        let units = self.units();
        let p = &mut self.partial;
        let (tau, n) = (units.tau, cover.cells.len());
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
        self.upload_cover();
    }

    /// Set Ladd's boundary links from a solid cover (on the CPU only: fails on a GPU).
    pub fn set_links(&mut self, links: &LinkCover) -> Result<()> {
        match &mut self.fluid {
            Lattices::Cpu(lbm) => {
                self.ladd.set(&mut lbm.lattice, links, &lbm.units);
                Ok(())
            }
            #[cfg(feature = "gpu")]
            Lattices::Gpu(_) => Err(Error::Other(
                "Ladd's bounce-back (coupling.method = \"ladd\") runs on the CPU only: use \
                 backend = \"cpu\", or the partially saturated cells"
                    .into(),
            )),
        }
    }

    /// Total fluid momentum (lattice units, see [`Lbm::momentum`]); nodes inside solids under
    /// Ladd's bounce-back are not fluid and not counted.
    pub fn momentum(&self) -> [f64; 2] {
        let ladd = &self.ladd;
        self.lbm().momentum(|c| ladd.is_inside(c))
    }
}

impl<T: Real> Scale for CoupledFluid<T> {
    /// The cells moving solids cover (an empty cover: a plain fluid).
    type Input = SolidCover;
    /// Force on the solid in each covered cell, averaged over the last advance.
    type Output = CellForces;
    type Snapshot = LbmState;

    fn time(&self) -> f64 {
        let steps = match &self.fluid {
            Lattices::Cpu(l) => l.steps,
            #[cfg(feature = "gpu")]
            Lattices::Gpu(g) => crate::lbm::Fluid::step_count(g),
        };
        steps as f64 * self.units().dt
    }
    /// The lattice step: the fluid advances in whole lattice steps.
    fn max_dt(&self) -> f64 {
        self.units().dt
    }
    /// Advance by `dt`, which must be a whole number of lattice steps (within 1e-9).
    fn advance(&mut self, input: &SolidCover, dt: f64) -> Result<()> {
        let units = self.units();
        let n = dt / units.dt;
        let k = n.round();
        if (n - k).abs() > 1e-9 * n.max(1.0) || k < 1.0 {
            return Err(Error::Other(format!(
                "LBM advance: dt = {dt:e} s is not a whole number of lattice steps ({:e} s)",
                units.dt
            )));
        }
        self.set_cover(input);
        if !(input.links.is_empty() && self.ladd.is_empty()) {
            self.set_links(&input.links)?;
        }
        let steps = k as u64;
        let on_cpu = self.backend() == Backend::Cpu;
        let (sum, count) = &mut self.exchange_sum;
        sum.clear();
        if steps > 1 && on_cpu {
            sum.resize(input.cells.len(), [0.0; 2]);
        }
        *count = steps;
        for _ in 0..steps {
            self.step();
            // On a GPU the device sums the steps' exchange itself.
            if steps > 1 && on_cpu {
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
        let (sum, count) = self.exchange_sums();
        let k = count as f64;
        let u = self.units();
        sum.par_iter()
            .map(|s| (-u.force_to_si(s[0] / k), -u.force_to_si(s[1] / k)))
            .unzip_into_vecs(&mut out.fx, &mut out.fy);
        self.ladd.observe(&u, &mut out.links);
    }
    fn snapshot(&self) -> LbmState {
        self.lbm().state()
    }
    fn restore(&mut self, s: LbmState) {
        self.set_lbm_state(s)
            .expect("a snapshot of this fluid restores into it");
    }
}
