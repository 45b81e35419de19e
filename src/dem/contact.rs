//! The contact law: linear spring-dashpot normal force, tangential spring with history and a
//! Coulomb cap, and rolling resistance (rolling spring + dashpot, capped moment).
//!
//! For one contact with unit normal **n** (from grain i towards grain j, or towards the wall),
//! tangent **t** = (−n_y, n_x), overlap δ > 0 and relative velocity of the contact point
//! (i relative to j) split into v_n = **v**_rel·**n** (> 0 approaching) and v_t = **v**_rel·**t**:
//!
//! * normal (seed eq. 5.58 plus a dashpot): f_n = k_n δ + c_n v_n, with
//!   c_n = 2ξ√(m_eff k_n) + m_eff γ_n, m_eff = m_i m_j/(m_i + m_j) (m_i for a wall), and
//!   ξ = −ln e/√(π² + ln² e) for a restitution coefficient e (REFERENCES, DEM). The force is
//!   **not** clipped at zero: the contact lasts until δ returns to 0, so the dashpot may pull
//!   briefly at the end of an impact. With that definition the rebound ratio of a head-on
//!   impact is exactly e = exp(−πξ/√(1 − ξ²)) (the solution of the damped oscillator at the
//!   end of its half period); clipping the force would end the contact earlier and give a
//!   larger e.
//! * tangential: the spring elongation ξ_t (a scalar along **t**, so it follows the rotating
//!   contact frame in 2-D) is advanced ξ_t' = ξ_t + v_t Δt; the trial force is
//!   f_t = −k_t ξ_t' − c_t v_t with c_t = m_eff γ_t; if |f_t| > μ|f_n| the contact slides:
//!   f_t = ±μ|f_n| and the spring is reset to the cap, ξ_t = −f_t/k_t.
//! * rolling (Ai et al. 2011, type C, as in the seed thesis: spring k_r, dashpot c_r): with
//!   ω_rel = ω_i − ω_j, θ_r' = θ_r + ω_rel Δt, M = −k_r θ_r' − c_r ω_rel; if |M| > μ_r R_eff |f_n|
//!   (R_eff = R_i R_j/(R_i + R_j), R_i for a wall) the moment is capped and the spring reset to
//!   the cap, θ_r = −M/k_r. M acts on i and −M on j.
//!
//! Force on i: **F**_i = −f_n **n** + f_t **t**; torque on i: R_i f_t + M; on j: −**F**_i and
//! R_j f_t − M.
//!
//! Contact onset and end inside a step. The dashpot force jumps at onset (to c_n v_n) and at
//! the end (from the tensile c_n v_n to 0); velocity Verlet applies the force evaluated at t_k
//! over [t_k − ½Δt, t_k + ½Δt], so a jump at a random instant inside the step is a first-order
//! error (measured: 3–5 % in e at λ = 0.1). The force loop therefore passes two fractions:
//! θ_in = δ_k/(δ_k − δ_{k−1}) at the first step of a contact (linear interpolation of the
//! overlap; 1 otherwise), by which the springs' first increment is scaled, and the dashpot
//! weight w = a_in + a_out − 1 ∈ [0, 1] with a_in = min(1, ½ + θ_in) and
//! a_out = min(1, ½ + δ_k/(−v_n Δt)) when separating (1 otherwise): the fraction of the
//! interval during which the contact exists. This restores second-order convergence of e.
//! When a contact opens with a loaded tangential or rolling spring, the energy left in it
//! is counted as dissipated by friction or rolling.
//!
//! Energy bookkeeping per contact and step: the elastic energy is the state function
//! ½k_n δ² + ½k_t ξ_t² + ½k_r θ_r²; the energy the contact absorbs from the grains in a step is
//! taken at the mid-point of the spring (½k(ξ'² − ξ²)) plus the dashpot power c v² Δt, and
//! what the spring does not keep after a capped (sliding) step is dissipated:
//! D_slide = ½k_t(ξ_t'² − ξ_t,new²), D_roll = ½k_r(θ_r'² − θ_r,new²).

/// Parameters of one contact type (grain–grain or grain–wall), SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactParams {
    /// Normal stiffness k_n (N/m, or N/m per unit depth in plane 2-D).
    pub k_n: f64,
    /// Tangential stiffness k_t.
    pub k_t: f64,
    /// Coefficient of restitution e ∈ (0, 1]; sets the normal damping ratio ξ.
    pub restitution: f64,
    /// Extra normal damping per unit effective mass γ_n (1/s), as LAMMPS's gran/hooke; 0 usually.
    pub gamma_n: f64,
    /// Tangential damping per unit effective mass γ_t (1/s); 0 usually.
    pub gamma_t: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// Rolling spring k_r (N·m/rad); 0 switches rolling resistance off.
    pub rolling_stiffness: f64,
    /// Rolling dashpot c_r (N·m·s/rad).
    pub rolling_damping: f64,
    /// Rolling friction coefficient μ_r (moment cap μ_r R_eff |f_n|).
    pub rolling_friction: f64,
}

impl ContactParams {
    /// Elastic frictionless contact of stiffness `k_n` (e = 1, everything else 0).
    pub fn elastic(k_n: f64) -> Self {
        ContactParams {
            k_n,
            k_t: 0.0,
            restitution: 1.0,
            gamma_n: 0.0,
            gamma_t: 0.0,
            friction: 0.0,
            rolling_stiffness: 0.0,
            rolling_damping: 0.0,
            rolling_friction: 0.0,
        }
    }

    /// Check every value; `prefix` is the TOML path used in the error (e.g. `dem.grain`).
    pub fn check(&self, prefix: &str) -> crate::Result<()> {
        let err = |f: &str, why: String| Err(crate::Error::config(format!("{prefix}.{f}"), why));
        let fields = [
            ("k_n", self.k_n),
            ("k_t", self.k_t),
            ("gamma_n", self.gamma_n),
            ("gamma_t", self.gamma_t),
            ("friction", self.friction),
            ("rolling_stiffness", self.rolling_stiffness),
            ("rolling_damping", self.rolling_damping),
            ("rolling_friction", self.rolling_friction),
        ];
        for (name, v) in fields {
            if !v.is_finite() || v < 0.0 {
                return err(name, format!("must be finite and ≥ 0, got {v}"));
            }
        }
        if self.k_n <= 0.0 {
            return err("k_n", format!("must be > 0, got {}", self.k_n));
        }
        if !(self.restitution > 0.0 && self.restitution <= 1.0) {
            return err(
                "restitution",
                format!("must be in (0, 1], got {}", self.restitution),
            );
        }
        Ok(())
    }

    /// Normal damping ratio ξ = −ln e/√(π² + ln² e) (REFERENCES, DEM).
    pub fn damping_ratio(&self) -> f64 {
        damping_ratio(self.restitution)
    }
}

/// Damping ratio ξ = −ln e/√(π² + ln² e) of a linear spring-dashpot that gives restitution e.
pub fn damping_ratio(e: f64) -> f64 {
    let l = e.ln();
    -l / (std::f64::consts::PI.powi(2) + l * l).sqrt()
}

/// Restitution e = exp(−πξ/√(1 − ξ²)) of a linear spring-dashpot of damping ratio ξ < 1.
pub fn restitution_of(xi: f64) -> f64 {
    (-std::f64::consts::PI * xi / (1.0 - xi * xi).sqrt()).exp()
}

/// Critical step of seed eq. 5.59: Δt_cr = 2(√(1 + ξ²) − ξ)/ω, ω = √(k/m).
pub fn critical_step(k: f64, m: f64, xi: f64) -> f64 {
    let omega = (k / m).sqrt();
    2.0 * ((1.0 + xi * xi).sqrt() - xi) / omega
}

/// A contact law with the constants of [`ContactParams`] precomputed for the force loop.
#[derive(Clone, Copy, Debug)]
pub struct Law {
    /// k_n.
    pub k_n: f64,
    /// k_t.
    pub k_t: f64,
    /// 2ξ√k_n, so that c_n = this·√m_eff + γ_n m_eff.
    pub damp_sqrt: f64,
    /// γ_n.
    pub gamma_n: f64,
    /// γ_t.
    pub gamma_t: f64,
    /// μ.
    pub mu: f64,
    /// k_r.
    pub k_r: f64,
    /// c_r.
    pub c_r: f64,
    /// μ_r.
    pub mu_r: f64,
}

impl From<&ContactParams> for Law {
    fn from(p: &ContactParams) -> Self {
        Law {
            k_n: p.k_n,
            k_t: p.k_t,
            damp_sqrt: 2.0 * p.damping_ratio() * p.k_n.sqrt(),
            gamma_n: p.gamma_n,
            gamma_t: p.gamma_t,
            mu: p.friction,
            k_r: p.rolling_stiffness,
            c_r: p.rolling_damping,
            mu_r: p.rolling_friction,
        }
    }
}

/// What one contact gives in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactOut {
    /// Normal force magnitude f_n (repulsive > 0).
    pub f_n: f64,
    /// Tangential force f_t along **t** on grain i.
    pub f_t: f64,
    /// Rolling moment M on grain i.
    pub m_r: f64,
    /// Energy stored in the normal spring, ½k_n δ².
    pub e_normal: f64,
    /// Energy stored in the tangential spring, ½k_t ξ_t².
    pub e_tangential: f64,
    /// Energy stored in the rolling spring, ½k_r θ_r².
    pub e_rolling: f64,
    /// Dissipated by the normal dashpot this step, c_n v_n² Δt.
    pub d_normal: f64,
    /// Dissipated by the tangential dashpot and by sliding this step.
    pub d_friction: f64,
    /// Dissipated by the rolling dashpot and rolling slip this step.
    pub d_rolling: f64,
}

impl Law {
    /// Resolve one contact. `hist` = [ξ_t, θ_r] is read and updated; `dt` is the step over which
    /// the springs advance (0 for a force evaluation that must not advance the history).
    /// `v_n` is the normal approach speed at the end of the step (it drives the dashpot);
    /// `v_t` and `w_rel` hold [mid-step, end-of-step] values: the springs advance with the
    /// mid-step value (ξ' = ξ + v_t,½ Δt is then exact to O(Δt³)), the dashpots use the
    /// end-of-step one (see [`crate::dem::solver`] for why).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn resolve(
        &self,
        delta: f64,
        v_n: f64,
        v_t: [f64; 2],
        w_rel: [f64; 2],
        m_eff: f64,
        r_eff: f64,
        hist: &mut [f64; 2],
        dt: f64,
        frac: [f64; 2],
    ) -> ContactOut {
        // frac[0]: fraction θ_in of this step the contact existed (1 except at onset): the
        // springs advance by v θ_in Δt. frac[1]: weight w of the dashpots, the fraction of the
        // interval [t − ½Δt, t + ½Δt] over which this force acts (see the module doc).
        let (dt_s, wd) = (dt * frac[0], frac[1]);
        // [0]: mid-step value (advances the springs); [1]: end-of-step estimate (dashpots).
        let (v_t, v_t1) = (v_t[0], v_t[1]);
        let (w_rel, w_rel1) = (w_rel[0], w_rel[1]);
        let c_n = self.damp_sqrt * m_eff.sqrt() + self.gamma_n * m_eff;
        let c_n = wd * c_n;
        let f_n = self.k_n * delta + c_n * v_n;
        let mut out = ContactOut {
            f_n,
            e_normal: 0.5 * self.k_n * delta * delta,
            d_normal: c_n * v_n * v_n * dt,
            ..ContactOut::default()
        };
        if self.k_t > 0.0 {
            let c_t = wd * self.gamma_t * m_eff;
            let xi_old = hist[0];
            let xi = xi_old + v_t * dt_s;
            let mut f_t = -self.k_t * xi - c_t * v_t1;
            let cap = self.mu * f_n.abs();
            let xi_new = if f_t.abs() > cap {
                f_t = cap.copysign(f_t);
                -f_t / self.k_t
            } else {
                xi
            };
            hist[0] = xi_new;
            out.f_t = f_t;
            out.e_tangential = 0.5 * self.k_t * xi_new * xi_new;
            out.d_friction = 0.5 * self.k_t * (xi * xi - xi_new * xi_new) + c_t * v_t1 * v_t1 * dt;
        }
        if self.k_r > 0.0 {
            let th = hist[1] + w_rel * dt_s;
            let c_r = wd * self.c_r;
            let mut m = -self.k_r * th - c_r * w_rel1;
            let cap = self.mu_r * r_eff * f_n.abs();
            let th_new = if m.abs() > cap {
                m = cap.copysign(m);
                -m / self.k_r
            } else {
                th
            };
            hist[1] = th_new;
            out.m_r = m;
            out.e_rolling = 0.5 * self.k_r * th_new * th_new;
            out.d_rolling =
                0.5 * self.k_r * (th * th - th_new * th_new) + c_r * w_rel1 * w_rel1 * dt;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damping_ratio_inverts_restitution() {
        for e in [0.1, 0.3, 0.5, 0.75, 0.95, 1.0] {
            assert!(
                (restitution_of(damping_ratio(e)) - e).abs() < 1e-14,
                "e = {e}"
            );
        }
    }

    #[test]
    fn coulomb_cap_resets_spring() {
        let p = ContactParams {
            k_t: 100.0,
            friction: 0.5,
            ..ContactParams::elastic(1000.0)
        };
        let law = Law::from(&p);
        let mut h = [0.0; 2];
        // δ = 0.01 → f_n = 10, cap 5; a tangential slip of 1 would ask for 100.
        let o = law.resolve(
            0.01, 0.0, [1.0; 2], [0.0; 2], 1.0, 1.0, &mut h, 1.0, [1.0; 2],
        );
        assert!((o.f_t + 5.0).abs() < 1e-12);
        assert!((h[0] - 0.05).abs() < 1e-12);
        assert!((o.d_friction - 0.5 * 100.0 * (1.0 - 0.05 * 0.05)).abs() < 1e-9);
    }
}
