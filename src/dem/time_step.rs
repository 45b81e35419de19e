//! The DEM time step, derived in one place (seed eq. 5.59–5.60): the critical step Δt_cr of
//! the stiffest spring on the lightest body, and the step in use Δt_D = λ Δt_cr (or a smaller
//! one the caller gives). [`super::Dem::new`] takes it for its grains; a scenario estimates it
//! before the grains exist from its smallest grain ([`TimeStep::new`]); both are this code.

use super::contact;
use super::grains::Grains;
use super::params::DemParams;
use crate::{Error, Result};

/// The DEM step: Δt_cr and the step in use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeStep {
    /// Critical step Δt_cr of seed eq. 5.59 (s).
    pub critical: f64,
    /// The step in use (s): `params.dt` if given, else λ Δt_cr (seed eq. 5.60).
    pub dt: f64,
}

impl TimeStep {
    /// The step for bodies whose lightest mass is `m_min` (kg) and smallest moment of inertia
    /// `j_min` (kg·m²). Refuses λ outside (0, 1], a given step ≤ 0 or above λ Δt_cr (naming
    /// the critical value), and no step at all (no bodies and none given). Errors name the
    /// field of [`DemParams`] (`lambda`, `dt`); a caller puts them in its table with
    /// [`Error::within`].
    pub fn new(params: &DemParams, m_min: f64, j_min: f64) -> Result<Self> {
        if !(params.lambda > 0.0 && params.lambda <= 1.0) {
            return Err(Error::config(
                "lambda",
                format!("must be in (0, 1], got {}", params.lambda),
            ));
        }
        let dt_cr = critical_step(params, m_min, j_min);
        let dt_max = params.lambda * dt_cr;
        let dt = match params.dt {
            Some(dt) if !(dt > 0.0 && dt.is_finite()) => {
                return Err(Error::config("dt", format!("must be > 0, got {dt}")));
            }
            Some(dt) if dt > dt_max * (1.0 + 1e-12) => {
                return Err(Error::config(
                    "dt",
                    format!(
                        "Δt = {dt:.4e} s exceeds λ·Δt_cr = {dt_max:.4e} s (Δt_cr = {dt_cr:.4e} s by seed eq. 5.59, λ = {}); \
                         use at most {dt_max:.4e} s",
                        params.lambda
                    ),
                ));
            }
            Some(dt) => dt,
            None if dt_max.is_finite() => dt_max,
            None => return Err(Error::config("dt", "no grains: give the step explicitly")),
        };
        Ok(TimeStep {
            critical: dt_cr,
            dt,
        })
    }

    /// The step for `grains` (polygons enter with the effective mass of their contact points,
    /// `polygon_contact_mass`).
    pub fn of_grains(params: &DemParams, grains: &Grains) -> Result<Self> {
        TimeStep::new(
            params,
            grains.min_mass().min(polygon_contact_mass(grains)),
            grains.min_inertia(),
        )
    }

    /// The step for disks of diameter `d` (m) and mass per area `areal_density` (kg/m²: ρ ×
    /// axial length), the smallest grains of a size distribution: m = ρ π d²/4, J = m d²/8.
    pub fn of_disk(params: &DemParams, d: f64, areal_density: f64) -> Result<Self> {
        let m = areal_density * std::f64::consts::FRAC_PI_4 * (d * d);
        TimeStep::new(params, m, 0.5 * m * (0.5 * d).powi(2))
    }
}

/// Critical time step of the system: seed eq. 5.59, Δt_cr = 2(√(1 + ξ²) − ξ)/ω, taken as the
/// smallest over the springs present, each with the inertia it moves:
/// * normal, grain–grain and grain–wall: ω = √(k_n/m_min) (the seed's choice), ξ the normal
///   damping ratio (from e, plus γ_n m_min/(2√(k_n m_min)));
/// * tangential: ω = √(3k_t/m_min) — the contact point of a disk (J = ½mR²) has effective mass
///   m/3 — with ξ = 0;
/// * rolling: ω = √(k_r/J_min), ξ = 0.
///
/// Returns ∞ if there are no grains.
pub fn critical_step(p: &DemParams, m_min: f64, j_min: f64) -> f64 {
    if !m_min.is_finite() {
        return f64::INFINITY;
    }
    let mut dt = f64::INFINITY;
    for c in [&p.grain, &p.wall] {
        let xi = c.damping_ratio() + c.gamma_n * m_min / (2.0 * (c.k_n * m_min).sqrt());
        dt = dt.min(contact::critical_step(c.k_n, m_min, xi));
        if c.k_t > 0.0 {
            dt = dt.min(contact::critical_step(3.0 * c.k_t, m_min, 0.0));
        }
        if c.rolling_stiffness > 0.0 {
            dt = dt.min(contact::critical_step(c.rolling_stiffness, j_min, 0.0));
        }
    }
    dt
}

/// Smallest effective mass of a polygon grain at a contact point (∞ if none):
/// m_c = 1/(1/m + R_b²/J), R_b the bounding radius — a point on a rotating body is lighter than
/// its mass (a disk's contact point has m/3 tangentially, which [`critical_step`] already
/// builds in through 3k_t). Passed as m_min for polygons, it makes the normal and tangential
/// critical steps conservative.
pub(crate) fn polygon_contact_mass(g: &Grains) -> f64 {
    (0..g.len())
        .filter(|&i| !g.is_disk(i))
        .map(|i| 1.0 / (1.0 / g.mass[i] + g.radius[i] * g.radius[i] / g.inertia[i]))
        .fold(f64::INFINITY, f64::min)
}
