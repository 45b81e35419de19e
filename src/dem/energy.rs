//! Energy bookkeeping.
//!
//! E_total = K_t + K_r + V_g + E_el + D − W_ext is conserved, with
//! * K_t = Σ ½ m |v|², K_r = Σ ½ J ω² (kinetic, translational and rotational);
//! * V_g = −Σ m **g**·**x** (gravitational potential, zero at the origin);
//! * E_el = Σ_contacts ½k_n δ² + ½k_t ξ_t² + ½k_r θ_r² (springs, current state);
//! * D = cumulative dissipation by the normal dashpot (Σ c_n v_n² Δt), by friction (tangential
//!   dashpot and sliding), by rolling resistance (dashpot and rolling slip), and by the
//!   optional global damping of seed eq. 5.57 (Σ c |v|² Δt);
//! * W_ext = cumulative work of external loads (e.g. hydrodynamic forces), Σ **F**_f·**v** Δt + T_f ω Δt.
//!
//! Velocities in the dissipation and work sums are the mid-step ones of velocity Verlet (those
//! the forces are evaluated with), so the balance closes to O(Δt²) per contact event.

use serde::Serialize;

use crate::analysis::runout::EnergyBudget;

/// Energies of a DEM system at one instant (state terms) and since the start (cumulative terms).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Energy {
    /// Translational kinetic energy Σ ½ m |v|².
    pub kinetic: f64,
    /// Rotational kinetic energy Σ ½ J ω².
    pub rotational: f64,
    /// Gravitational potential −Σ m **g**·**x**.
    pub potential: f64,
    /// Normal springs Σ ½ k_n δ².
    pub elastic_normal: f64,
    /// Tangential springs Σ ½ k_t ξ_t².
    pub elastic_tangential: f64,
    /// Rolling springs Σ ½ k_r θ_r².
    pub elastic_rolling: f64,
    /// Cumulative dissipation of the normal dashpots.
    pub dissipated_normal: f64,
    /// Cumulative dissipation of tangential dashpots and Coulomb sliding.
    pub dissipated_friction: f64,
    /// Cumulative dissipation of rolling dashpots and rolling slip.
    pub dissipated_rolling: f64,
    /// Cumulative dissipation of the global (seed eq. 5.57) damping.
    pub dissipated_global: f64,
    /// Cumulative work done on the grains by external loads.
    pub work_external: f64,
}

impl Energy {
    /// Elastic energy in all springs.
    pub fn elastic(&self) -> f64 {
        self.elastic_normal + self.elastic_tangential + self.elastic_rolling
    }

    /// All dissipation so far.
    pub fn dissipated(&self) -> f64 {
        self.dissipated_normal
            + self.dissipated_friction
            + self.dissipated_rolling
            + self.dissipated_global
    }

    /// K_t + K_r.
    pub fn kinetic_total(&self) -> f64 {
        self.kinetic + self.rotational
    }

    /// Mechanical energy now: K_t + K_r + V_g + E_el.
    pub fn mechanical(&self) -> f64 {
        self.kinetic_total() + self.potential + self.elastic()
    }

    /// The conserved total: mechanical + dissipated − external work.
    pub fn total(&self) -> f64 {
        self.mechanical() + self.dissipated() - self.work_external
    }

    /// Where the potential energy released since `start` went (collisions = normal dashpots,
    /// friction = tangential dashpots and sliding, rolling, global damping).
    pub fn budget(&self, start: &Energy) -> EnergyBudget {
        EnergyBudget {
            potential_released: start.potential - self.potential,
            kinetic: self.kinetic_total(),
            elastic: self.elastic(),
            collision: self.dissipated_normal - start.dissipated_normal,
            friction: self.dissipated_friction - start.dissipated_friction,
            rolling: self.dissipated_rolling - start.dissipated_rolling,
            plastic: 0.0,
            damping: self.dissipated_global - start.dissipated_global,
        }
    }
}
