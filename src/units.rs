//! SI ↔ lattice unit conversion for the LBM, in one type.
//!
//! The lattice has spacing Δx (m), step Δt (s) and reference density ρ₀ (kg/m³). Lattice
//! quantities are dimensionless; a 2-D run is per unit depth. With c_s² = 1/3 (lattice):
//!
//! | quantity | SI → lattice |
//! |---|---|
//! | velocity | u* = u Δt/Δx |
//! | kinematic viscosity | ν* = ν Δt/Δx², τ = 3ν* + ½ |
//! | acceleration | g* = g Δt²/Δx |
//! | density | ρ* = ρ/ρ₀ |
//! | pressure (gauge) | p = ρ₀ (Δx/Δt)² c_s² (ρ* − 1) |
//! | force per unit depth | F = F* ρ₀ Δx³/Δt² |
//! | time | t = n Δt |
//!
//! The relaxation time belongs to the same type: τ and Δt are tied by the viscosity,
//! τ = 3νΔt/Δx² + ½ (seed eq. 5.9–5.11), so a lattice is set by Δx, ρ₀, ν and one of τ or Δt,
//! and the solver reads both from here.
//!
//! ```
//! use granflow::units::Units;
//! // Water (ν = 1e-6 m²/s) on a 1 mm lattice at τ = 0.8: Δt = (τ − ½)Δx²/(3ν) = 0.1 s.
//! let u = Units::from_tau(1e-3, 0.8, 1e-6, 1000.0);
//! assert!((u.dt - 0.1).abs() < 1e-12);
//! // 1 cm/s in lattice units: u* = u Δt/Δx = 0.01 × 0.1 / 1e-3 = 1 (far too fast to run).
//! assert!((u.velocity_to_lattice(0.01) - 1.0).abs() < 1e-12);
//! assert!((u.tau - 0.8).abs() < 1e-12);
//! assert!((u.viscosity() - 1e-6).abs() < 1e-18);
//! ```

use serde::Serialize;

/// Lattice speed of sound squared, c_s² = 1/3 (lattice units).
pub const CS2: f64 = 1.0 / 3.0;

/// Conversion between SI and lattice units for one lattice, with its relaxation time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Units {
    /// Lattice spacing Δx in metres.
    pub dx: f64,
    /// Time step Δt in seconds.
    pub dt: f64,
    /// Reference density ρ₀ in kg/m³ (lattice density 1).
    pub rho0: f64,
    /// Relaxation time τ = 3νΔt/Δx² + ½ of the fluid's kinematic viscosity ν.
    pub tau: f64,
}

impl Units {
    /// Units for a given time step: τ = 3νΔt/Δx² + ½ (seed eq. 5.9).
    pub fn from_dt(dx: f64, dt: f64, nu: f64, rho0: f64) -> Self {
        Units {
            dx,
            dt,
            rho0,
            tau: 3.0 * (nu * dt / (dx * dx)) + 0.5,
        }
    }

    /// Units for a given relaxation time: Δt = (τ − ½) Δx² / (3ν) (seed eq. 5.11). `tau` is
    /// then recomputed from Δt, so that it is the τ of the lattice as stored.
    pub fn from_tau(dx: f64, tau: f64, nu: f64, rho0: f64) -> Self {
        Units::from_dt(dx, (tau - 0.5) * dx * dx / (3.0 * nu), nu, rho0)
    }

    /// Lattice units (Δx = Δt = ρ₀ = 1) at relaxation time `tau`: a run in lattice units,
    /// ν = (τ − ½)/3.
    pub fn lattice(tau: f64) -> Self {
        Units {
            dx: 1.0,
            dt: 1.0,
            rho0: 1.0,
            tau,
        }
    }

    /// Kinematic viscosity ν = (τ − ½)/3 · Δx²/Δt (m²/s).
    pub fn viscosity(&self) -> f64 {
        (self.tau - 0.5) / 3.0 * self.dx * self.dx / self.dt
    }

    /// Lattice velocity u* = u Δt/Δx.
    pub fn velocity_to_lattice(&self, u: f64) -> f64 {
        u * self.dt / self.dx
    }

    /// SI velocity u = u* Δx/Δt.
    pub fn velocity_to_si(&self, u: f64) -> f64 {
        u * self.dx / self.dt
    }

    /// Lattice viscosity ν* = ν Δt/Δx².
    pub fn viscosity_to_lattice(&self, nu: f64) -> f64 {
        nu * self.dt / (self.dx * self.dx)
    }

    /// Lattice acceleration g* = g Δt²/Δx (force per unit mass).
    pub fn acceleration_to_lattice(&self, g: f64) -> f64 {
        g * self.dt * self.dt / self.dx
    }

    /// Gauge pressure in Pa from lattice density: p = ρ₀ (Δx/Δt)² c_s² (ρ* − 1) (seed eq. 5.7).
    pub fn pressure_to_si(&self, rho_lattice: f64) -> f64 {
        self.rho0 * (self.dx / self.dt).powi(2) * CS2 * (rho_lattice - 1.0)
    }

    /// Lattice density from gauge pressure in Pa, the inverse of [`Units::pressure_to_si`].
    pub fn pressure_to_lattice_density(&self, p: f64) -> f64 {
        1.0 + p / (self.rho0 * (self.dx / self.dt).powi(2) * CS2)
    }

    /// Density in kg/m³ from lattice density: ρ = ρ₀ ρ*.
    pub fn density_to_si(&self, rho_lattice: f64) -> f64 {
        self.rho0 * rho_lattice
    }

    /// Force per unit depth in N/m from lattice force: F = F* ρ₀ Δx³/Δt².
    pub fn force_to_si(&self, f: f64) -> f64 {
        f * self.rho0 * self.dx.powi(3) / (self.dt * self.dt)
    }

    /// Torque per unit depth in N·m/m from lattice torque: T = T* ρ₀ Δx⁴/Δt².
    pub fn torque_to_si(&self, t: f64) -> f64 {
        t * self.rho0 * self.dx.powi(4) / (self.dt * self.dt)
    }

    /// Vorticity in 1/s from lattice vorticity: ω = ω*/Δt.
    pub fn rate_to_si(&self, w: f64) -> f64 {
        w / self.dt
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn tau_round_trip() {
        let u = Units::from_tau(0.01, 0.8, 1e-3, 1000.0);
        assert_relative_eq!(u.tau, 0.8, max_relative = 1e-14);
        assert_relative_eq!(u.viscosity(), 1e-3, max_relative = 1e-14);
        let v = Units::from_dt(0.01, u.dt, 1e-3, 1000.0);
        assert_eq!(u, v);
    }

    #[test]
    fn pressure_round_trip() {
        let u = Units::from_dt(1e-3, 1e-4, 1e-6, 1000.0);
        let rho = u.pressure_to_lattice_density(123.4);
        assert_relative_eq!(u.pressure_to_si(rho), 123.4, max_relative = 1e-12);
    }

    #[test]
    fn velocity_round_trip() {
        let u = Units::from_dt(2e-3, 5e-4, 1e-6, 1.0);
        assert_relative_eq!(u.velocity_to_si(u.velocity_to_lattice(0.3)), 0.3);
        // 0.3 m/s over 2 mm in 0.5 ms is 0.075 cells per step.
        assert_relative_eq!(u.velocity_to_lattice(0.3), 0.075, max_relative = 1e-14);
    }
}
