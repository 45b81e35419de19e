//! Granular scenarios of any geometry (`kind = "granular"`): regions of grains, grains listed
//! one by one, walls, gates and outlets as data, so a silo, a hopper, a chute or an obstacle
//! in a flow is a scenario file, not code.
//!
//! * [`spec`]: the file's schema and its checks ([`GranularScenario`]);
//! * [`run`]: settling, release, outlets and outputs ([`run::run_granular`]);
//! * [`profile`]: the time-averaged solid fraction and velocity across y (`profile.csv`);
//! * [`validation`]: the `silo-beverloo` case (discharge rate against orifice width);
//! * [`chute`]: the `chute-bagnold` case (velocity profile down a rough incline).

pub mod chute;
pub mod profile;
pub mod run;
pub mod spec;
pub mod validation;

pub use spec::*;

use crate::Result;

impl GranularScenario {
    /// What `granflow check` prints: the grains, walls, outlets, step and memory.
    pub fn check_report(&self) -> Result<String> {
        let d = self.derive()?;
        let gates = d.gates.len();
        let moving = d.walls.iter().filter(|(_, v)| v.is_some()).count();
        let mass: f64 = d.grains.mass.iter().sum();
        let settle = match &self.settle {
            Some(s) => format!("settle behind {gates} gate(s), at most {} s", s.max_time),
            None => "none: the grains start as listed".into(),
        };
        let periodic = match self.periodic_x {
            Some([a, b]) => format!("in x over [{a}, {b}] m"),
            None => "no".into(),
        };
        Ok(format!(
            "scenario        {} — {} (granular)\n\
             grains          {} ({:.4e} kg), from {} region(s) and {} listed\n\
             walls           {} ({} moving after the release), {} gate(s), {} outlet(s)\n\
             periodic        {periodic}\n\
             gravity         [{}, {}] m/s²\n\
             settling        {settle}\n\
             dt              {:.4e} s (λ·Δt_cr, λ = {}, Δt_cr = {:.4e} s)\n\
             run             {} s after the release, {} steps\n\
             memory          {}\n\
             ok\n",
            self.name,
            self.description,
            d.grains.len(),
            mass,
            self.fill.len(),
            self.grain.len(),
            d.walls.len(),
            moving,
            gates,
            d.outlets.len(),
            self.gravity[0],
            self.gravity[1],
            d.time_step.dt,
            d.params.lambda,
            d.time_step.critical,
            self.time.end,
            (self.time.end / d.time_step.dt).ceil(),
            crate::exec::memory_line(spec::granular_memory(d.grains.len())),
        ))
    }
}

impl run::GranularSummary {
    /// The line `granflow run` ends with.
    pub fn done_line(&self) -> String {
        let rate = self
            .discharge_rate
            .map_or("no discharge rate (window not reached)".into(), |w| {
                format!("discharge rate {w:.4e} kg/s")
            });
        format!(
            "done: {} grains at the release, {} left, {} discharged ({:.4e} kg), {rate}; \
             ended ({}) at t = {:.4} s after {} steps, {:.1} s wall",
            self.grains_at_release,
            self.grains_at_end,
            self.discharged,
            self.discharged_mass,
            self.ended,
            self.end_time,
            self.steps,
            self.wall_time_s
        )
    }
}
