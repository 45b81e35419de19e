//! Continuum scenarios of any geometry (`kind = "continuum"`): an MPM domain with a condition
//! on each side or periodic in x, regions of material, gravity in any direction and turning
//! at a constant rate (a tilting table), and the points' initial stress and velocity as data,
//! so a slope, a layer or a block is a scenario file, not code.
//!
//! * [`spec`]: the file's schema and its checks ([`ContinuumScenario`]);
//! * [`run`]: the run and its outputs ([`run::run_continuum`]);
//! * [`slope`]: the `mpm-slope` case (the onset of sliding of an infinite slope on a tilting
//!   table against tan φ / tan β = 1).

pub mod run;
pub mod slope;
pub mod spec;

pub use spec::*;

use crate::Result;

impl ContinuumScenario {
    /// What `granflow check` prints: the points, grid, sides, gravity, step and memory.
    pub fn check_report(&self) -> Result<String> {
        let d = self.derive()?;
        let dm = &self.domain;
        let side = |w: Option<crate::mpm::WallKind>| match w {
            None => "open".to_string(),
            Some(w) => format!("{w:?}").to_lowercase(),
        };
        let sides = if dm.periodic_x {
            format!(
                "periodic in x; bottom {}, top {}",
                side(dm.bottom),
                side(dm.top)
            )
        } else {
            format!(
                "left {}, right {}, bottom {}, top {}",
                side(dm.left),
                side(dm.right),
                side(dm.bottom),
                side(dm.top)
            )
        };
        let tilt = match &self.tilt {
            Some(t) => format!(
                "turning from {:.3}° at {}°/s to {}°, onset at a mean speed of {} m/s",
                d.angle_deg, t.rate_deg_per_s, t.until_deg, t.onset_speed
            ),
            None => "fixed".into(),
        };
        Ok(format!(
            "scenario        {} — {} (continuum)\n\
             points          {} from {} region(s)\n\
             grid            {} × {} cells of {} m over [{}, {}] × [{}, {}] m\n\
             sides           {sides}\n\
             gravity         [{}, {}] m/s² ({:.3}° from −y), {tilt}\n\
             dt              {:.4e} s\n\
             run             {} s, {} steps\n\
             memory          {}\n\
             ok\n",
            self.name,
            self.description,
            d.points.len(),
            self.fill.len(),
            d.cells[0],
            d.cells[1],
            self.mpm.cell_size,
            dm.x[0],
            dm.x[1],
            dm.y[0],
            dm.y[1],
            self.gravity[0],
            self.gravity[1],
            d.angle_deg,
            d.dt,
            self.time.end,
            (self.time.end / d.dt).ceil(),
            crate::exec::memory_line(Self::memory_bytes(&d)),
        ))
    }
}

impl run::ContinuumSummary {
    /// The line `granflow run` ends with.
    pub fn done_line(&self) -> String {
        let onset = match (self.onset_deg, self.onset_time) {
            (Some(a), Some(t)) => format!("; sliding from {a:.2}° (t = {t:.3} s)"),
            _ => String::new(),
        };
        format!(
            "done: {} points, t = {:.4} s after {} steps, kinetic energy {:.4e} J/m, gravity at \
             {:.2}° from −y{onset}, {:.1} s wall",
            self.points,
            self.end_time,
            self.steps,
            self.kinetic_energy,
            self.tilt_deg,
            self.wall_time_s
        )
    }
}
