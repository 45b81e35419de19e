//! The [`Scale`] trait: how the solvers meet.
//!
//! Each solver (the LBM fluid with its coupled solids, the DEM grains, the GIMPM continuum) is a
//! `Scale`: a thing with its own clock that can be advanced, observed and snapshotted. Solvers
//! never name each other; all mapping between scales lives in `crate::coupling`. The verbs
//! follow MUSCLE3's submodel loop (init → (observe → advance)* → final) and preCICE's
//! participant.
//!
//! Time steps have one meaning throughout: [`Scale::max_dt`] is the step the scale takes (the
//! LBM's lattice step, the DEM's Δt_D = λ·Δt_cr or the smaller one a scenario gives, the MPM's
//! CFL step), and anything longer is covered in the sub-steps of [`substeps`], the one
//! sub-cycling rule (used by the scales' own `advance` and by the coupling driver).

use crate::Result;

/// One physical scale of a multi-scale simulation.
pub trait Scale {
    /// What the other scales hand it each step (e.g. solid fraction and velocity for the fluid).
    type Input;
    /// What it shows the other scales, written into a reused buffer.
    type Output: Default;
    /// A full copy of its state, to roll back or checkpoint.
    type Snapshot: Clone + Send;

    /// Current simulated time in seconds.
    fn time(&self) -> f64;
    /// The step the scale takes, in seconds: the largest it can take stably and the one it
    /// uses (LBM: the lattice step; DEM: λ·Δt_cr, or the smaller step a scenario gives; MPM:
    /// the CFL step, or the smaller given one).
    fn max_dt(&self) -> f64;
    /// Advance by `dt` seconds with `input` held fixed; a scale may sub-step internally.
    fn advance(&mut self, input: &Self::Input, dt: f64) -> Result<()>;
    /// Told by a driver that the input changed since the last `advance` (e.g. new
    /// hydrodynamic loads): a scale that carries input-dependent state between steps (the
    /// DEM's end-of-step forces for its first half-kick) refreshes it. Default: nothing.
    fn input_changed(&mut self) {}
    /// Write what the other scales need into `out`.
    fn observe(&self, out: &mut Self::Output);
    /// Copy the state.
    fn snapshot(&self) -> Self::Snapshot;
    /// Restore a state taken by [`Scale::snapshot`].
    fn restore(&mut self, snapshot: Self::Snapshot);
}

/// Number of sub-steps of size at most `max_dt` needed to cover `dt`, and their size.
///
/// n = ⌈dt / max_dt⌉ (at least 1), each of size dt / n. A relative slack of 1e-9 keeps
/// `dt = k·max_dt` from producing k + 1 steps through round-off.
///
/// This is seed eq. 5.61's n_s = ⌊Δt/Δt_D⌋ + 1 wherever Δt/Δt_D is not a whole number; at a
/// whole number k the seed's rule takes k + 1 steps where k already keep Δt_s ≤ Δt_D.
pub fn substeps(dt: f64, max_dt: f64) -> (u64, f64) {
    let n = ((dt / max_dt) * (1.0 - 1e-9)).ceil().max(1.0) as u64;
    (n, dt / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn substeps_cover_dt_without_exceeding_max() {
        assert_eq!(substeps(1.0, 0.25), (4, 0.25));
        let (n, h) = substeps(1.0, 0.3);
        assert_eq!(n, 4);
        assert!((h - 0.25).abs() < 1e-15);
        assert_eq!(substeps(0.1, 1.0).0, 1);
    }
}
