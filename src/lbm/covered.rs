//! Cells a solid covers: the hook through which a fluid–solid coupling method changes the
//! collision of the nodes its solids cover, inside the lattice's fused stream–collide step.
//!
//! The lattice streams a covered cell as the fluid node it is, collides it with the fluid
//! collision C(g) of [`super::collision`], and then hands the pre-collision populations g and
//! C(g) to [`CoveredCells::apply`], which returns the final post-collision populations and the
//! momentum its term gave the fluid. The method itself (e.g. partially saturated cells,
//! `crate::coupling::psm`) lives with the coupling; the lattice knows only this contract.

use super::d2q9::Q;
use super::real::Real;

/// The entry of a lane that no covered cell occupies ([`CoveredCells::apply`]).
pub const UNCOVERED: usize = usize::MAX;

/// The covered cells of one step and the collision term a coupling method applies to them.
pub trait CoveredCells<T: Real>: Sync {
    /// Cell indices y·nx + x, ascending and unique.
    fn cells(&self) -> &[u32];

    /// Whether the fluid collision of entry `k` has weight 0 (the term replaces it, e.g. a
    /// fully covered cell): a chunk of such cells skips the fluid collision.
    fn replaces_collision(&self, k: usize) -> bool;

    /// Apply the term on `L` lanes: lane l is entry `entries[l]` of [`CoveredCells::cells`],
    /// or a fluid node when it is [`UNCOVERED`] (its `post` must come back unchanged, bit for
    /// bit); `g` holds the pre-collision populations, `post` the fluid collision C(g) on entry
    /// and the post-collision populations on return; `force` is the body force the collision
    /// used (lattice units). Returns the momentum the term gave the fluid in each lane (any
    /// value in an uncovered lane). Lanes may repeat an entry (padding); each lane must be
    /// computed from its own data only.
    fn apply<const L: usize>(
        &self,
        entries: &[usize; L],
        g: &[[T; L]; Q],
        post: &mut [[T; L]; Q],
        force: [f64; 2],
    ) -> [[f64; L]; 2];
}
