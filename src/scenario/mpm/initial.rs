//! The material points' initial state (`[initial]` of an MPM file): velocity and Cauchy
//! stress, each component a number or an expression of the position (x, y) in m, evaluated at
//! every point's starting position. Without it the points start at rest, at zero stress with a
//! closed-form law and at the geostatic stress of `material.k0` with the `rve` model.
//!
//! A geostatic start, σ_yy = −ρ g (H − y), σ_xx = σ_zz = K₀ σ_yy, puts an elastic column in
//! equilibrium with its weight from the first step instead of letting it drop and ring; a
//! velocity field starts a block moving, and with the `apic` transfer the points' affine
//! matrices start at the field's gradient (the expressions' derivatives), so that the first
//! transfer to the grid carries it: a rigid rotation or any affine field reaches the grid
//! exactly ([`Mpm::set_velocity_gradient`]).

use serde::{Deserialize, Serialize};

use crate::mpm::material::Stress;
use crate::mpm::{Material, Mpm};
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
        Ok(MpmInitial {
            velocity: compile(&VELOCITY_KEYS, self.velocity.as_ref())?,
            stress: compile(&STRESS_KEYS, self.stress.as_ref())?,
        })
    }
}

/// The components of one field, each read from its key.
fn compile<const N: usize>(
    keys: &[&'static str; N],
    values: Option<&[FieldValue; N]>,
) -> Result<Option<[Scalar; N]>> {
    let Some(values) = values else {
        return Ok(None);
    };
    let parts: Vec<Scalar> = keys
        .iter()
        .zip(values)
        .map(|(key, v)| Scalar::new(key, v))
        .collect::<Result<_>>()?;
    // N keys zipped with N values: the length is N.
    Ok(parts.try_into().ok())
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

    /// The stress (xx, yy, xy, zz) at `x`, if given.
    pub fn stress(&self, x: [f64; 2]) -> Option<Stress> {
        self.stress.as_ref().map(|p| at(p, x))
    }

    /// The velocity at `x`, if given.
    pub fn velocity(&self, x: [f64; 2]) -> Option<[f64; 2]> {
        self.velocity.as_ref().map(|p| at(p, x))
    }
}

/// Start the points of `mpm` at the stress and velocity `[initial]` gives (`spec`), the stress
/// it does not give from `fallback`, at rest where it gives no velocity; a value that is not
/// finite at a point is refused naming its key.
pub fn start<M: Material>(
    mpm: &mut Mpm<M>,
    spec: Option<&MpmInitialSpec>,
    fallback: impl Fn([f64; 2]) -> Stress + Sync,
) -> Result<()> {
    let Some(given) = spec.map(MpmInitialSpec::compile).transpose()? else {
        return mpm.set_stress(fallback);
    };
    given.check(&mpm.points.pos)?;
    mpm.set_stress(|x| given.stress(x).unwrap_or_else(|| fallback(x)))?;
    let p = &mut mpm.points;
    for (v, &x) in p.vel.iter_mut().zip(&p.pos) {
        if let Some(u) = given.velocity(x) {
            *v = u;
        }
    }
    if let Some(parts) = &given.velocity {
        mpm.set_velocity_gradient(|x| {
            let [u, v] = parts;
            [
                u.at(1, x[0], x[1]),
                u.at(2, x[0], x[1]),
                v.at(1, x[0], x[1]),
                v.at(2, x[0], x[1]),
            ]
        });
    }
    Ok(())
}
