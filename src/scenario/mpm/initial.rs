//! The material points' initial state (`[initial]` of an MPM file): velocity and Cauchy
//! stress, each component a number or an expression of the position (x, y) in m, evaluated at
//! every point's starting position. Without it the points start at rest, at zero stress with a
//! closed-form law and at the geostatic stress of `material.k0` with the `rve` model.
//!
//! A geostatic start, σ_yy = −ρ g (H − y), σ_xx = σ_zz = K₀ σ_yy, puts an elastic column in
//! equilibrium with its weight from the first step instead of letting it drop and ring; a
//! velocity field starts a block moving (the APIC affine matrices start at zero, so an
//! `apic` transfer sees the field's gradient from the first grid update on).

use serde::{Deserialize, Serialize};

use crate::mpm::material::Stress;
use crate::scenario::field::{FieldValue, Scalar};
use crate::{Error, Result};

/// `[initial]`: the points' velocity and stress at t = 0.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MpmInitialSpec {
    /// Velocity (u, v) in m/s, each a number or an expression of x, y (m). Absent: at rest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<[FieldValue; 2]>,
    /// Cauchy stress (σ_xx, σ_yy, σ_xy, σ_zz) in Pa, tension positive, each a number or an
    /// expression of x, y (m), e.g. `"-1600*9.81*(0.1 - y)"` for σ_yy of a column 0.1 m tall
    /// of bulk density 1600 kg/m³. Absent: zero. Not with the `rve` model, whose points start
    /// at the geostatic stress of `material.k0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress: Option<[FieldValue; 4]>,
}

const VELOCITY_KEYS: [&str; 2] = ["initial.velocity[0]", "initial.velocity[1]"];
const STRESS_KEYS: [&str; 4] = [
    "initial.stress[0]",
    "initial.stress[1]",
    "initial.stress[2]",
    "initial.stress[3]",
];

/// The compiled `[initial]` table.
pub struct MpmInitial {
    velocity: Option<[Scalar; 2]>,
    stress: Option<[Scalar; 4]>,
}

impl MpmInitialSpec {
    /// Compile the expressions; one that does not parse or uses a variable other than x and y
    /// is refused naming its key.
    pub fn compile(&self) -> Result<MpmInitial> {
        let velocity = match &self.velocity {
            Some(v) => Some([
                Scalar::new(VELOCITY_KEYS[0], &v[0])?,
                Scalar::new(VELOCITY_KEYS[1], &v[1])?,
            ]),
            None => None,
        };
        let stress = match &self.stress {
            Some(s) => {
                let mut parts = Vec::with_capacity(4);
                for (key, v) in STRESS_KEYS.iter().zip(s) {
                    parts.push(Scalar::new(key, v)?);
                }
                parts.try_into().ok()
            }
            None => None,
        };
        Ok(MpmInitial { velocity, stress })
    }
}

/// `parts` at `x` (NaN where an expression cannot be evaluated).
fn at<const N: usize>(parts: &[Scalar; N], x: [f64; 2]) -> [f64; N] {
    std::array::from_fn(|k| parts[k].at(0, x[0], x[1]))
}

impl MpmInitial {
    /// Every given component finite at every position; the first that is not is refused
    /// naming its key and the point.
    pub fn check(&self, positions: &[[f64; 2]]) -> Result<()> {
        let given = self
            .velocity
            .iter()
            .flatten()
            .chain(self.stress.iter().flatten());
        for s in given {
            if let Some(x) = positions.iter().find(|x| !s.at(0, x[0], x[1]).is_finite()) {
                return Err(Error::config(
                    s.key,
                    format!(
                        "not finite at the material point at x = {} m, y = {} m",
                        x[0], x[1]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Whether a stress is given.
    pub fn has_stress(&self) -> bool {
        self.stress.is_some()
    }

    /// The stress (xx, yy, xy, zz) at `x`, if given.
    pub fn stress(&self, x: [f64; 2]) -> Option<Stress> {
        self.stress.as_ref().map(|p| at(p, x))
    }

    /// The velocity at `x`, if given.
    pub fn velocity(&self, x: [f64; 2]) -> Option<[f64; 2]> {
        self.velocity.as_ref().map(|p| at(p, x))
    }
}
