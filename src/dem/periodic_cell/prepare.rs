//! Preparation of a representative volume: a packing at a target packing fraction φ and
//! isotropic confining pressure p₀.
//!
//! The disks (radii drawn from a seeded generator, [`SizeDistribution`]) start dilute, placed
//! by random sequential addition at φ = 0.4 in a square cell. The cell is compressed
//! isotropically, L = ε̇ I, by a servo on the mean pressure p = −(σ_xx + σ_yy)/2: below ½p₀
//! (the dilute start, the jamming transition) at ε̇ = −ε̇_max, with ε̇_max set by a small
//! inertial number, ε̇_max d̄ √(ρ_s/p₀) = I_prep; above, ε̇ = (p − p₀)/(K T) with K = k_n/t the
//! stiffness scale of the packing and T = 1000 Δt, capped at |ε̇| ≤ ε̇_max (proportional, so it
//! does not swing across the narrow strain window between unjammed and p₀). A stage ends when
//! p is within 1 % of p₀ and the grains are at rest: their r.m.s. fluctuation speed below
//! 10⁻⁴ √(p₀/ρ_s) (an inertial number of 10⁻⁴; a criterion on the kinetic over the stored
//! energy would not do, as their ratio grows as k_n/(p₀ t) at low pressure). Within 5 % of p₀
//! every grain is stopped every 200 steps (a quench: rattlers, grains without contacts, keep
//! their compaction speed otherwise and the packing never counts as at rest).
//!
//! The packing fraction is controlled by the friction used while compacting (the usual
//! route: frictional compaction gives loose packings, frictionless dense ones). Each
//! compaction starts from the same dilute state, rests at p₀ with the compaction friction,
//! then with the material's own friction. The material's friction gives a loose packing and
//! none the densest; a target between them is found by bisection on the compaction friction
//! (at most 10 compactions) to the first packing within the tolerance. A target looser than
//! the material's friction gives is sought the same way between that friction and
//! [`LOOSEST_FRICTION`] (the friction is restored once compacted, so the grains are the
//! material's either way). A target outside the reachable range is refused with the range.

use super::{PeriodicCell, Tensor};

/// Compaction friction of the loosest packing tried, when the material's own friction
/// (if lower) does not compact as loose as the target: frictional compaction up to
/// μ = 1 is the usual route to loose packings.
pub const LOOSEST_FRICTION: f64 = 1.0;
use crate::dem::contact::ContactParams;
use crate::dem::packing::{SizeDistribution, SplitMix64};

/// What to prepare.
#[derive(Clone, Debug)]
pub struct Preparation {
    /// Number of disks.
    pub grains: usize,
    /// Smallest and largest diameter (m).
    pub diameter: [f64; 2],
    /// How diameters are drawn between them.
    pub distribution: SizeDistribution,
    /// Grain density ρ_s (kg/m³).
    pub density: f64,
    /// Axial length t of the disks (m; 1 for forces per unit depth).
    pub thickness: f64,
    /// The material's contact law.
    pub contact: ContactParams,
    /// The DEM step (s).
    pub dt: f64,
    /// Verlet skin (m).
    pub skin: f64,
    /// Target confining pressure p₀ (Pa, compression positive).
    pub pressure: f64,
    /// Target packing fraction φ.
    pub packing_fraction: f64,
    /// Accepted |φ − φ_target|.
    pub tolerance: f64,
    /// Inertial number of the compression, I_prep.
    pub inertial_number: f64,
    /// Seed of the radii and the lattice jitter.
    pub seed: u64,
}

/// A prepared packing and what it took.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The cell at p₀ with the material's friction.
    pub cell: PeriodicCell,
    /// Friction used in the last compression stage.
    pub compaction_friction: f64,
    /// DEM steps taken.
    pub steps: u64,
}

impl Preparation {
    /// Mean diameter d̄ (m).
    fn mean_diameter(&self) -> f64 {
        0.5 * (self.diameter[0] + self.diameter[1])
    }

    /// The dilute starting cell: random sequential addition at φ = 0.4 in a square cell (each
    /// disk at the first uniformly drawn place where it overlaps none placed before).
    pub(super) fn dilute(&self) -> Result<PeriodicCell, String> {
        let mut rng = SplitMix64::new(self.seed);
        let mut r: Vec<f64> = (0..self.grains)
            .map(|_| {
                0.5 * self
                    .distribution
                    .sample(&mut rng, self.diameter[0], self.diameter[1])
            })
            .collect();
        // Largest first: the small ones find gaps more easily.
        r.sort_by(|a, b| b.total_cmp(a));
        let area: f64 = r.iter().map(|r| std::f64::consts::PI * r * r).sum();
        let l = (area / 0.4).sqrt();
        let (mut x, mut y): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
        for &ri in &r {
            let placed = (0..100_000).find_map(|_| {
                let (px, py) = (l * rng.uniform(), l * rng.uniform());
                let free = x.iter().zip(&y).zip(&r).all(|((&qx, &qy), &rj)| {
                    let dx = px - qx - l * ((px - qx) / l).round();
                    let dy = py - qy - l * ((py - qy) / l).round();
                    dx * dx + dy * dy >= (ri + rj) * (ri + rj)
                });
                free.then_some((px, py))
            });
            let (px, py) = placed.ok_or("no room for a disk in the dilute start")?;
            x.push(px);
            y.push(py);
        }
        Ok(PeriodicCell::new(
            x,
            y,
            r,
            self.density,
            self.thickness,
            Tensor::new(l, 0.0, 0.0, l),
            &self.contact,
            self.dt,
            self.skin,
        ))
    }

    /// The stress control of this preparation ([`Servo`]).
    pub fn servo(&self) -> Servo {
        Servo {
            mean_diameter: self.mean_diameter(),
            density: self.density,
            thickness: self.thickness,
            inertial_number: self.inertial_number,
            stiffness: self.contact.k_n / self.thickness,
            relax: 1000.0 * self.dt,
            dt: self.dt,
            max_steps: 50_000_000 / self.grains.max(1) as u64 + 2_000_000,
        }
    }

    /// Compact the dilute start with friction `mu` to rest at p₀, then restore the
    /// material's friction and rest at p₀ again.
    fn compact(&self, mu: f64) -> Result<PeriodicCell, String> {
        let mut cell = self.dilute()?;
        let mut law = self.contact;
        law.friction = mu;
        cell.set_law(&law);
        let (servo, p0) = (self.servo(), Target::Pressure(self.pressure));
        servo.hold(&mut cell, p0)?;
        cell.set_law(&self.contact);
        servo.hold(&mut cell, p0)?;
        Ok(cell)
    }

    /// Prepare the packing (see the module doc).
    pub fn run(&self) -> Result<Prepared, String> {
        let (target, tol, p0) = (self.packing_fraction, self.tolerance, self.pressure);
        let mu = self.contact.friction;
        let own = self.compact(mu)?;
        let phi_own = own.packing_fraction();
        let mut steps = own.steps();
        let done = |cell: PeriodicCell, friction: f64, steps: u64| Prepared {
            cell,
            compaction_friction: friction,
            steps,
        };
        if (phi_own - target).abs() <= tol {
            return Ok(done(own, mu, steps));
        }
        // The bracket: a compaction friction that gives a packing denser than the target
        // (with its cell) and one that gives a looser packing.
        let (dense_end, loose_end) = if target < phi_own {
            let mu_loose = LOOSEST_FRICTION.max(mu);
            let loosest = self.compact(mu_loose)?;
            let phi_loosest = loosest.packing_fraction();
            steps += loosest.steps();
            if (phi_loosest - target).abs() <= tol {
                return Ok(done(loosest, mu_loose, steps));
            }
            if target < phi_loosest {
                return Err(format!(
                    "packing_fraction = {target} is below the loosest packing this material \
                     reaches at p₀ = {p0:e} Pa (φ = {phi_loosest:.4}, compacted with friction \
                     {mu_loose}; {phi_own:.4} with its own)"
                ));
            }
            ((mu, own), mu_loose)
        } else {
            let dense = self.compact(0.0)?;
            let phi_dense = dense.packing_fraction();
            steps += dense.steps();
            if (phi_dense - target).abs() <= tol {
                return Ok(done(dense, 0.0, steps));
            }
            if target > phi_dense {
                return Err(format!(
                    "packing_fraction = {target} is above the densest packing reached at \
                     p₀ = {p0:e} Pa (φ = {phi_dense:.4} compacted frictionless; with the \
                     material's friction {phi_own:.4})"
                ));
            }
            ((0.0, dense), mu)
        };
        // Bisection on the compaction friction: φ falls as it rises.
        let ((mut lo, dense), mut hi) = (dense_end, loose_end);
        let mut best = (f64::INFINITY, dense, lo);
        for _ in 0..10 {
            let mid = 0.5 * (lo + hi);
            let cell = self.compact(mid)?;
            steps += cell.steps();
            let phi = cell.packing_fraction();
            if phi > target {
                lo = mid;
            } else {
                hi = mid;
            }
            if (phi - target).abs() < best.0 {
                best = ((phi - target).abs(), cell, mid);
            }
            if best.0 <= tol {
                break;
            }
        }
        let (miss, cell, friction) = best;
        if miss > tol {
            return Err(format!(
                "packing_fraction = {target} not reached within {tol} at p₀ = {p0:e} Pa: the \
                 nearest compaction gave φ = {:.4} (friction {friction:.3})",
                cell.packing_fraction()
            ));
        }
        Ok(done(cell, friction, steps))
    }
}

/// What a [`Servo`] holds (Pa, compression positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// The mean pressure p = −½(σ_xx + σ_yy), by isotropic stretching L = ε̇ I.
    Pressure(f64),
    /// Each normal stress, (σ_xx, σ_yy) = −(p_x, p_y), by L = diag(ε̇_x, ε̇_y).
    Normal([f64; 2]),
}

/// Stress control of a cell by its normal stretching rates (the module doc's servo, for the
/// mean pressure or per axis): while the mean pressure is below half the target's, p < ½ p_t,
/// the cell closes at ε̇_max; above, each controlled stress σ relaxes to its target σ_t by
/// ε̇ = (σ_t − σ)/(K T), capped at |ε̇| ≤ ε̇_max, with ε̇_max d̄ √(ρ_s/p_t) = I, K = k_n/t and
/// T = 1000 Δt. At rest when every controlled stress is within 1 % of p_t of its target and
/// the r.m.s. fluctuation speed is below 10⁻⁴ √(p_t/ρ_s); every grain is stopped every 200
/// steps within 5 %.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct Servo {
    /// Mean diameter d̄ (m).
    pub mean_diameter: f64,
    /// Grain density ρ_s (kg/m³).
    pub density: f64,
    /// Axial length t of the disks (m).
    pub thickness: f64,
    /// Inertial number I of the largest rate.
    pub inertial_number: f64,
    /// Stiffness scale K = k_n/t of the packing (Pa).
    pub stiffness: f64,
    /// Relaxation time T of the proportional control (s).
    pub relax: f64,
    /// The DEM step (s).
    pub dt: f64,
    /// Steps after which the control gives up.
    pub max_steps: u64,
}

impl Servo {
    /// Drive `cell` to `target` and rest there (see the type's doc). Refuses a target that is
    /// not a finite compression; fails if the cell does not settle within `max_steps`.
    pub fn hold(&self, cell: &mut PeriodicCell, target: Target) -> Result<(), String> {
        let (pt, shown) = match target {
            Target::Pressure(p) => (p, format!("p = {p:e} Pa")),
            Target::Normal([px, py]) => (
                if px.min(py) > 0.0 {
                    0.5 * (px + py)
                } else {
                    f64::NAN
                },
                format!("σ_xx = {:e} Pa, σ_yy = {:e} Pa", -px, -py),
            ),
        };
        if !(pt.is_finite() && pt > 0.0) {
            return Err(format!(
                "a packing is held only under compression, asked for {shown}"
            ));
        }
        let rate = self.inertial_number / (self.mean_diameter * (self.density / pt).sqrt());
        let chunk = 20;
        let start = cell.steps();
        loop {
            let s = cell.stress();
            // σ − σ_t of each controlled stress, on the diagonal (the stretching is its
            // opposite over K T).
            let miss = match target {
                Target::Pressure(p) => Tensor::identity() * (0.5 * s.trace() + p),
                Target::Normal([px, py]) => Tensor::new(s[(0, 0)] + px, 0.0, 0.0, s[(1, 1)] + py),
            };
            let off = miss.amax();
            let e = cell.energy();
            let mass = self.density * cell.packing_fraction() * cell.area() * self.thickness;
            if off < 0.01 * pt && e.kinetic < 0.5e-8 * mass * pt / self.density {
                return Ok(());
            }
            if cell.steps() - start > self.max_steps {
                return Err(format!(
                    "the packing did not settle at {shown} in {} steps (σ_xx = {:.4e}, σ_yy = \
                     {:.4e} Pa)",
                    self.max_steps,
                    s[(0, 0)],
                    s[(1, 1)]
                ));
            }
            if off < 0.05 * pt && (cell.steps() - start).is_multiple_of(10 * chunk) {
                cell.stop();
            }
            let grad = if -0.5 * s.trace() < 0.5 * pt {
                -rate * Tensor::identity()
            } else {
                (-miss / (self.stiffness * self.relax)).map(|e| e.clamp(-rate, rate))
            };
            cell.deform(&grad, chunk, self.dt)?;
        }
    }
}
