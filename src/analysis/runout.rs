//! Run-out history and outcome of a column collapse, shared by the DEM and MPM runners so both
//! report the same quantities under the same keys (`summary.json`).

use serde::{Deserialize, Serialize};

/// Spreading has stopped once the run-out stays within this fraction of L_i of its final value.
pub const STOP_TOLERANCE: f64 = 0.01;

/// End of spreading: the first time after which every run-out in `history` (t, L) stays
/// within `tol` of the last one (0 for an empty history).
pub fn spreading_end(history: &[(f64, f64)], tol: f64) -> f64 {
    let Some(&(t_end, l_f)) = history.last() else {
        return 0.0;
    };
    history
        .iter()
        .rev()
        .take_while(|&&(_, l)| (l - l_f).abs() <= tol)
        .last()
        .map_or(t_end, |&(t, _)| t)
}

/// What every collapse run reports, whatever the solver: the common part of `summary.json`
/// (each runner adds its own keys beside these, through `#[serde(flatten)]`). Definitions:
/// docs/references.md, column collapse run-out laws; τ_c = √(H_i/g).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CollapseOutcome {
    /// Scenario name.
    pub name: String,
    /// Initial width L_i (m).
    pub l_i: f64,
    /// Initial height H_i (m).
    pub h_i: f64,
    /// Actual aspect ratio a = H_i/L_i.
    pub aspect_ratio: f64,
    /// τ_c = √(H_i/g) (s).
    pub tau_c: f64,
    /// Final run-out L_f (m).
    pub l_f: f64,
    /// Final height H_f (m).
    pub h_f: f64,
    /// ΔL = (L_f − L_i)/L_i.
    pub delta_l: f64,
    /// H_f/L_i.
    pub h_f_over_l_i: f64,
    /// End of spreading, in τ_c: from then on the run-out stays within [`STOP_TOLERANCE`] L_i
    /// of L_f ([`spreading_end`]).
    pub stop_time_tc: f64,
    /// Start of the final rest interval (kinetic-energy criterion), in τ_c.
    pub rest_time_tc: f64,
    /// Whether the run stopped at rest (false: it reached its end time).
    pub at_rest: bool,
    /// Time step (s).
    pub dt: f64,
    /// Steps of the collapse.
    pub steps: u64,
    /// Wall time of the collapse (s), preparation (deposition) excluded.
    pub wall_time_s: f64,
    /// Throughput: grains or material points × steps / wall time.
    pub particle_steps_per_s: f64,
    /// |E_total(end) − E_total(0)| / dissipated energy.
    pub energy_budget_error: f64,
    /// Where the released potential energy went, at the end of the run.
    pub energy: EnergyBudget,
}

/// The energy released by a collapse and where it went, at one instant (cumulative since the
/// release): ΔE_p = K + E_el + D_collision + D_friction + D_rolling + D_plastic + D_damping
/// plus the scheme's own numerical dissipation. Units: J for the DEM (disks of the
/// scenario's thickness), J per metre of depth for the plane-strain MPM; compare solvers
/// through [`EnergyBudget::share`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyBudget {
    /// Potential energy released, E_p(0) − E_p(t).
    pub potential_released: f64,
    /// Kinetic energy (translational + rotational).
    pub kinetic: f64,
    /// Elastic energy stored (contact springs; the continuum's strain energy).
    pub elastic: f64,
    /// Dissipated in collisions: the DEM's normal dashpots; the MPM's inelastic wall impacts.
    pub collision: f64,
    /// Dissipated by friction: the DEM's tangential dashpots and Coulomb sliding (grains and
    /// walls); the MPM's wall friction.
    pub friction: f64,
    /// Dissipated by rolling resistance (DEM).
    pub rolling: f64,
    /// Dissipated by plastic flow (MPM, Mohr–Coulomb).
    pub plastic: f64,
    /// Dissipated by artificial damping (DEM global, MPM local damping).
    pub damping: f64,
}

impl EnergyBudget {
    /// `part` as a fraction of the potential energy released (0 before anything is released).
    pub fn share(&self, part: f64) -> f64 {
        if self.potential_released > 0.0 {
            part / self.potential_released
        } else {
            0.0
        }
    }

    /// Everything booked as dissipated.
    pub fn dissipated(&self) -> f64 {
        self.collision + self.friction + self.rolling + self.plastic + self.damping
    }
}

/// What a runner measured, from which [`CollapseOutcome`] derives the rest.
#[derive(Clone, Debug)]
pub struct CollapseRecord<'a> {
    /// Scenario name.
    pub name: &'a str,
    /// Initial width L_i and height H_i (m).
    pub l_i: f64,
    /// Initial height H_i (m).
    pub h_i: f64,
    /// Gravity g (m/s²).
    pub gravity: f64,
    /// Run-out L(t) at every output row: (t, L).
    pub history: &'a [(f64, f64)],
    /// Final height (m).
    pub h_f: f64,
    /// Start of the final rest interval (s); `None` if the run never came to rest.
    pub rest_since: Option<f64>,
    /// Whether the run stopped at rest.
    pub at_rest: bool,
    /// Time at the end of the run (s).
    pub t_end: f64,
    /// Time step (s), steps taken and wall time (s).
    pub dt: f64,
    /// Steps taken.
    pub steps: u64,
    /// Wall time (s).
    pub wall_time_s: f64,
    /// Grains or material points.
    pub particles: usize,
    /// Energy budget error (see [`CollapseOutcome::energy_budget_error`]).
    pub energy_budget_error: f64,
    /// Energy released and dissipated by the end.
    pub energy: EnergyBudget,
}

impl From<CollapseRecord<'_>> for CollapseOutcome {
    fn from(r: CollapseRecord<'_>) -> Self {
        let tau_c = (r.h_i / r.gravity).sqrt();
        let l_f = r.history.last().map_or(r.l_i, |&(_, l)| l);
        CollapseOutcome {
            name: r.name.to_owned(),
            l_i: r.l_i,
            h_i: r.h_i,
            aspect_ratio: r.h_i / r.l_i,
            tau_c,
            l_f,
            h_f: r.h_f,
            delta_l: (l_f - r.l_i) / r.l_i,
            h_f_over_l_i: r.h_f / r.l_i,
            stop_time_tc: spreading_end(r.history, STOP_TOLERANCE * r.l_i) / tau_c,
            rest_time_tc: r.rest_since.unwrap_or(r.t_end) / tau_c,
            at_rest: r.at_rest,
            dt: r.dt,
            steps: r.steps,
            wall_time_s: r.wall_time_s,
            particle_steps_per_s: r.particles as f64 * r.steps as f64 / r.wall_time_s.max(1e-9),
            energy_budget_error: r.energy_budget_error,
            energy: r.energy,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::spreading_end;

    #[test]
    fn spreading_ends_when_the_runout_settles() {
        let h = [
            (0.0, 1.0),
            (1.0, 2.0),
            (2.0, 2.9),
            (3.0, 3.02),
            (4.0, 2.99),
            (5.0, 3.0),
        ];
        assert_eq!(spreading_end(&h, 0.05), 3.0);
        assert_eq!(spreading_end(&h, 0.001), 5.0);
        assert_eq!(spreading_end(&h, 10.0), 0.0);
        assert_eq!(spreading_end(&[], 0.1), 0.0);
    }
}
