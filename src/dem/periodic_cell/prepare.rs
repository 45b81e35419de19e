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
//! then with the material's own friction. The material's friction gives the loosest packing
//! and none the densest; a target between them is found by bisection on the compaction
//! friction (at most 10 compactions) to the first packing within the tolerance. A target
//! outside the reachable range is refused with the range.

use super::{PeriodicCell, Tensor};
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

    /// Servo the cell to p₀ and rest (see the module doc).
    fn servo(&self, cell: &mut PeriodicCell) -> Result<(), String> {
        let p0 = self.pressure;
        let rate = self.inertial_number / (self.mean_diameter() * (self.density / p0).sqrt());
        // Stiffness scale of the packing, k_n/t, and the servo's relaxation time.
        let stiffness = self.contact.k_n / self.thickness;
        let relax = 1000.0 * self.dt;
        let chunk = 20;
        let max_steps = 50_000_000 / self.grains.max(1) as u64 + 2_000_000;
        let start = cell.steps();
        loop {
            let s = cell.stress();
            let p = -0.5 * s.trace();
            let e = cell.energy();
            // At rest: r.m.s. fluctuation speed below 10⁻⁴ √(p₀/ρ_s).
            let mass = self.density * cell.packing_fraction() * cell.area() * self.thickness;
            if (p - p0).abs() < 0.01 * p0 && e.kinetic < 0.5e-8 * mass * p0 / self.density {
                return Ok(());
            }
            if cell.steps() - start > max_steps {
                return Err(format!(
                    "the packing did not settle at p₀ = {p0:e} Pa in {max_steps} steps \
                     (p = {p:.4e} Pa)"
                ));
            }
            // Quench every 10 chunks near p₀, so rattlers stop.
            if (p - p0).abs() < 0.05 * p0 && (cell.steps() - start).is_multiple_of(10 * chunk) {
                cell.stop();
            }
            let eps = if p < 0.5 * p0 {
                -rate
            } else {
                ((p - p0) / (stiffness * relax)).clamp(-rate, rate)
            };
            cell.deform(&(eps * Tensor::identity()), chunk, self.dt)?;
        }
    }

    /// Compact the dilute start with friction `mu` to rest at p₀, then restore the
    /// material's friction and rest at p₀ again.
    fn compact(&self, mu: f64) -> Result<PeriodicCell, String> {
        let mut cell = self.dilute()?;
        let mut law = self.contact;
        law.friction = mu;
        cell.set_law(&law);
        self.servo(&mut cell)?;
        cell.set_law(&self.contact);
        self.servo(&mut cell)?;
        Ok(cell)
    }

    /// Prepare the packing (see the module doc).
    pub fn run(&self) -> Result<Prepared, String> {
        let (target, tol, p0) = (self.packing_fraction, self.tolerance, self.pressure);
        let mu = self.contact.friction;
        let loose = self.compact(mu)?;
        let phi_loose = loose.packing_fraction();
        let mut steps = loose.steps();
        let done = |cell: PeriodicCell, friction: f64, steps: u64| Prepared {
            cell,
            compaction_friction: friction,
            steps,
        };
        if (phi_loose - target).abs() <= tol {
            return Ok(done(loose, mu, steps));
        }
        if target < phi_loose {
            return Err(format!(
                "packing_fraction = {target} is below the loosest packing this material \
                 reaches at p₀ = {p0:e} Pa (φ = {phi_loose:.4}, compacted with its own friction)"
            ));
        }
        let dense = self.compact(0.0)?;
        let phi_dense = dense.packing_fraction();
        steps += dense.steps();
        if (phi_dense - target).abs() <= tol {
            return Ok(done(dense, 0.0, steps));
        }
        if target > phi_dense {
            return Err(format!(
                "packing_fraction = {target} is above the densest packing reached at \
                 p₀ = {p0:e} Pa (φ = {phi_dense:.4} compacted frictionless; the loosest is \
                 {phi_loose:.4})"
            ));
        }
        // Bisection on the compaction friction: φ falls as it rises.
        let (mut lo, mut hi) = (0.0, mu);
        let mut best = (f64::INFINITY, dense, 0.0);
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
