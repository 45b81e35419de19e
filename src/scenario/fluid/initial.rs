//! The fluid's initial state (`[initial]`): velocity and gauge pressure as numbers or as
//! expressions of the position (x, y) in m, e.g. a Taylor–Green vortex
//! `velocity = ["-U*cos(k*x)*sin(k*y)", ...]` written out with numbers.
//!
//! A uniform state starts every cell at the equilibrium f_i^eq(ρ₀, **u**). A field given by
//! expressions starts each cell at its centre ((i + ½)Δx, (j + ½)Δx) with the Chapman–Enskog
//! populations of that flow (lattice units, ρ* = 1 + p/(ρ₀ c_s²)):
//!
//! f_i = f_i^eq(ρ*, **u***) − (τ w_i ρ*/c_s²) Q_iαβ S*_αβ,  Q_iαβ = e_iα e_iβ − c_s² δ_αβ,
//!
//! with the strain rate S_αβ = ½(∂_α u_β + ∂_β u_α) differentiated exactly from the expressions
//! (S* = S Δt), so a smooth flow starts without the pressure and stress transient an
//! equilibrium start would give (Skordos 1993; Mei et al. 2006, "Consistent initial conditions
//! for lattice Boltzmann simulations"). τ is the molecular relaxation time (the eddy viscosity
//! of a Smagorinsky run is not in it).

use serde::{Deserialize, Serialize};

use crate::lbm::d2q9::{equilibrium, CX, CY, Q, W};
pub use crate::scenario::field::FieldValue;
use crate::scenario::field::Scalar;
use crate::units::{Units, CS2};
use crate::{Error, Result};

/// Initial state: velocity (m/s) and gauge pressure (Pa), each uniform or a field.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Initial velocity (u, v) in m/s, each a number or an expression of x, y.
    pub velocity: [FieldValue; 2],
    /// Initial gauge pressure p in Pa (a number or an expression of x, y; density
    /// ρ = ρ₀ + p/c_s², c_s = Δx/(√3 Δt)). Absent: the fluid starts at its density ρ₀.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<FieldValue>,
}

impl InitialSpec {
    /// The velocity if it is uniform (and the pressure absent or zero): the start is then the
    /// equilibrium at ρ₀ and this velocity.
    pub fn uniform_velocity(&self) -> Option<[f64; 2]> {
        let uniform_pressure = matches!(self.pressure, None | Some(FieldValue::Uniform(0.0)));
        match (&self.velocity, uniform_pressure) {
            ([FieldValue::Uniform(u), FieldValue::Uniform(v)], true) => Some([*u, *v]),
            _ => None,
        }
    }

    /// The field, compiled; expressions that do not parse, use a variable other than x and y,
    /// or give a non-finite value at a cell centre are refused naming the key.
    pub fn field(&self, cells: [usize; 2], dx: f64) -> Result<InitialField> {
        let field = InitialField {
            velocity: [
                Scalar::new("initial.velocity[0]", &self.velocity[0])?,
                Scalar::new("initial.velocity[1]", &self.velocity[1])?,
            ],
            pressure: match &self.pressure {
                Some(p) => Scalar::new("initial.pressure", p)?,
                None => Scalar::new("initial.pressure", &FieldValue::Uniform(0.0))?,
            },
        };
        field.check_finite(cells, dx)?;
        Ok(field)
    }
}

/// The compiled initial field of a lattice.
pub struct InitialField {
    velocity: [Scalar; 2],
    pressure: Scalar,
}

/// Centre of cell `i` along one axis (m).
fn centre(i: usize, dx: f64) -> f64 {
    (i as f64 + 0.5) * dx
}

impl InitialField {
    /// Velocity (m/s) at (x, y) m.
    pub fn velocity(&self, x: f64, y: f64) -> [f64; 2] {
        [self.velocity[0].at(0, x, y), self.velocity[1].at(0, x, y)]
    }

    /// Largest speed over the cell centres (m/s).
    pub fn max_speed(&self, cells: [usize; 2], dx: f64) -> f64 {
        let mut m: f64 = 0.0;
        for j in 0..cells[1] {
            for i in 0..cells[0] {
                let [u, v] = self.velocity(centre(i, dx), centre(j, dx));
                m = m.max(u.hypot(v));
            }
        }
        m
    }

    /// Every part finite at every cell centre.
    fn check_finite(&self, cells: [usize; 2], dx: f64) -> Result<()> {
        for s in self.velocity.iter().chain([&self.pressure]) {
            for j in 0..cells[1] {
                for i in 0..cells[0] {
                    let (x, y) = (centre(i, dx), centre(j, dx));
                    if !(0..3).all(|k| s.at(k, x, y).is_finite()) {
                        return Err(Error::config(
                            s.key,
                            format!(
                                "the field or its gradient is not finite at the centre of cell \
                                 ({i}, {j}), x = {x} m, y = {y} m"
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The populations of cell (i, j) in lattice units (module doc).
    pub fn populations(&self, units: &Units, i: usize, j: usize) -> [f64; Q] {
        let (x, y) = (centre(i, units.dx), centre(j, units.dx));
        let [u, v] = self.velocity(x, y).map(|c| units.velocity_to_lattice(c));
        let rho = units.pressure_to_lattice_density(self.pressure.at(0, x, y));
        // ∂u_α/∂x_β Δt: the lattice velocity gradient.
        let grad = |s: &Scalar, k: usize| s.at(k, x, y) * units.dt;
        let sxx = grad(&self.velocity[0], 1);
        let syy = grad(&self.velocity[1], 2);
        let sxy = 0.5 * (grad(&self.velocity[0], 2) + grad(&self.velocity[1], 1));
        let feq = equilibrium(rho, u, v);
        std::array::from_fn(|q| {
            let (cx, cy) = (CX[q] as f64, CY[q] as f64);
            let qs = (cx * cx - CS2) * sxx + (cy * cy - CS2) * syy + 2.0 * cx * cy * sxy;
            feq[q] - units.tau * W[q] * rho / CS2 * qs
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(text: &str) -> Result<InitialSpec> {
        toml::from_str(text).map_err(|e| Error::config("initial", e.to_string()))
    }

    /// The populations carry the density, velocity and the strain rate they were built from:
    /// Σf = ρ*, Σf e = ρ* u*, and Π^neq = Σ (f − f^eq) e e = −2 τ c_s² ρ* S* (Chapman–Enskog),
    /// to round-off (1e-12).
    #[test]
    fn populations_have_the_field_moments() {
        let s = spec(
            "velocity = [\"1.0e-2*sin(2*x)*cos(y)\", \"-0.02*cos(2*x)*sin(y)\"]\n\
             pressure = \"3*x*y\"",
        )
        .unwrap();
        let units = Units::from_tau(0.01, 0.8, 1e-4, 1000.0);
        let field = s.field([20, 20], 0.01).unwrap();
        let (i, j) = (7, 12);
        let f = field.populations(&units, i, j);
        let (x, y) = (centre(i, 0.01), centre(j, 0.01));
        let rho: f64 = f.iter().sum();
        let ux: f64 = (0..Q).map(|q| f[q] * CX[q] as f64).sum::<f64>() / rho;
        let uy: f64 = (0..Q).map(|q| f[q] * CY[q] as f64).sum::<f64>() / rho;
        assert!((rho - units.pressure_to_lattice_density(3.0 * x * y)).abs() < 1e-12);
        let u_si = 0.01 * (2.0 * x).sin() * y.cos();
        assert!((ux - units.velocity_to_lattice(u_si)).abs() < 1e-12);
        let v_si = -0.02 * (2.0 * x).cos() * y.sin();
        assert!((uy - units.velocity_to_lattice(v_si)).abs() < 1e-12);
        let feq = equilibrium(rho, ux, uy);
        let pi_xy: f64 = (0..Q)
            .map(|q| (f[q] - feq[q]) * (CX[q] * CY[q]) as f64)
            .sum();
        let dudy = -0.01 * (2.0 * x).sin() * y.sin();
        let dvdx = 0.04 * (2.0 * x).sin() * y.sin();
        let sxy = 0.5 * (dudy + dvdx) * units.dt;
        assert!((pi_xy + 2.0 * units.tau * CS2 * rho * sxy).abs() < 1e-12);
    }

    #[test]
    fn bad_expressions_are_refused_by_key() {
        let e = spec("velocity = [0.0, \"sin(z)\"]")
            .unwrap()
            .field([4, 4], 0.1);
        let msg = e.err().unwrap().to_string();
        assert!(
            msg.contains("initial.velocity[1]") && msg.contains("`z`"),
            "{msg}"
        );
        let e = spec("velocity = [0.0, 0.0]\npressure = \"ln(x - 1)\"")
            .unwrap()
            .field([4, 4], 0.1);
        let msg = e.err().unwrap().to_string();
        assert!(
            msg.contains("initial.pressure") && msg.contains("not finite"),
            "{msg}"
        );
        let e = spec("velocity = [\"2*(x\", 0.0]")
            .unwrap()
            .field([4, 4], 0.1);
        assert!(e.err().unwrap().to_string().contains("initial.velocity[0]"));
        assert!(spec("velocity = [true, 0.0]").is_err());
    }
}
