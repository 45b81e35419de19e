//! The submerged column-collapse scenario: the DEM collapse tables of
//! [`crate::scenario::dem::DemScenario`] plus a `[fluid]` table (the liquid filling the tank)
//! and a `[coupling]` table (method, hydrodynamic radius, lattice), all SI.
//!
//! Set-up: the DEM box (floor at y = 0, left wall at x = 0, right wall at
//! x = `column.box_length`) is a closed tank filled with liquid up to `fluid.depth`: the
//! lattice covers [0, box_length] × [0, depth] with no-slip walls on all four edges (the top
//! is a lid, not a free surface). The column is deposited dry under the full gravity g (the
//! same deposit as the dry scenario with the same seed), then released in the liquid. The
//! grains feel the reduced gravity (1 − ρ_f/ρ_s) g (buoyancy, seed eq. 5.57) and the
//! hydrodynamic force and torque of the partially saturated cells (seed eq. 5.53–5.54); the
//! liquid carries no gravity, so its pressure is the excess pore pressure p − p_hydrostatic.
//!
//! Forces: the lattice is 2-D (forces per metre of depth); a grain is a disk of axial length
//! `grains.thickness`, so the force on it is the lattice force × thickness (its mass is
//! ρ π d²/4 · thickness).
//!
//! Lattice: Δx = `coupling.dx`; give exactly one of `coupling.tau` (Δt = (τ − ½)Δx²/(3ν)) or
//! `coupling.dt` (τ = ½ + 3νΔt/Δx²). The velocity scale for the Mach number is
//! U = √(g′ H_i) with H_i = a L_i and g′ the reduced gravity (the speed scale of the collapse;
//! the run checks the actual largest Mach number at every time-series row).
//! The DEM takes n_s = ⌊Δt/Δt_D⌋ + 1 sub-steps per lattice step (seed eq. 5.61).

use serde::{Deserialize, Serialize};

use crate::io::VtkFormat;
use crate::scale::substeps;
use crate::scenario::collapse::collapse_gravity;
use crate::scenario::dem::{
    ColumnGeometry, ContactSpec, DemScenario, DemTimeSpec, DepositionSpec, DerivedDem, GrainsSpec,
};
use crate::scenario::fluid::{CollisionKind, MrtSpec, Precision, MAX_MACH};
use crate::scenario::{lattice_units, positive, Kind, ScenarioFile};
use crate::units::{Units, CS2};
use crate::{Error, Result};

/// A submerged column collapse, as read from TOML. All values SI.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SubmergedScenario {
    /// `"submerged"`: what the file describes.
    pub kind: Kind,
    /// Short name used in outputs.
    pub name: String,
    /// One line saying what the case is (and how it was scaled).
    pub description: String,
    /// Gravitational acceleration **g** = [g_x, g_y] (m/s²), pointing into the floor (g_y < 0);
    /// tilted, |g| (sin θ, −cos θ), for a collapse on a plane inclined by θ.
    pub gravity: [f64; 2],
    /// Seed of the size draw and the deposition lattice.
    pub seed: u64,
    /// Grain sizes and material.
    pub grains: GrainsSpec,
    /// Column and box geometry.
    pub column: ColumnGeometry,
    /// Grain–grain contact law.
    pub grain_contact: ContactSpec,
    /// Grain–wall contact law.
    pub wall_contact: ContactSpec,
    /// Deposition of the initial column (dry, full gravity).
    pub deposition: DepositionSpec,
    /// Output intervals and stop criterion (in τ_c = √(H_i/g), g the full gravity).
    pub time: DemTimeSpec,
    /// The liquid.
    pub fluid: LiquidSpec,
    /// Fluid–grain coupling and lattice.
    pub coupling: CouplingSpec,
    /// How VTK frames are written (`[vtk]`, optional: zlib-compressed, f64, if absent).
    #[serde(default)]
    pub vtk: VtkFormat,
}

/// The liquid filling the tank.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LiquidSpec {
    /// Density ρ_f (kg/m³); must be below the grain density.
    pub density: f64,
    /// Kinematic viscosity ν (m²/s).
    pub viscosity: f64,
    /// Height of the liquid-filled tank (m): the lattice's top lid. Must be a whole number of
    /// cells and exceed the column height.
    pub depth: f64,
}

/// How grains and fluid exchange momentum.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum CouplingMethod {
    /// Partially saturated cells (Noble & Torczynski 1998, seed eq. 5.50–5.54).
    Psm,
    /// Ladd's modified bounce-back on the links into the grains (seed eq. 5.45–5.49), with
    /// the momentum of covered and uncovered nodes handed to the grain
    /// ([`crate::coupling::LaddMap`]).
    Ladd,
}

/// Coupling and lattice parameters.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CouplingSpec {
    /// `"psm"` or `"ladd"`.
    pub method: CouplingMethod,
    /// Hydrodynamic radius factor κ = r/R ∈ (0, 1] (0.7–0.95 in the thesis).
    pub radius_factor: f64,
    /// Lattice spacing Δx (m).
    pub dx: f64,
    /// Relaxation time τ (> ½); give this or `dt`.
    pub tau: Option<f64>,
    /// Lattice time step Δt (s); give this or `tau`.
    pub dt: Option<f64>,
    /// `"f32"` or `"f64"` populations.
    pub precision: Precision,
    /// `"bgk"` or `"mrt"`.
    pub collision: CollisionKind,
    /// MRT rates of the non-hydrodynamic moments `{ s_e, s_eps, s_q }`; absent:
    /// [`crate::lbm::MrtRates::standard`] (s_q from the magic Λ = 3/16, which near τ = ½
    /// leaves the energy fluxes almost unrelaxed: s_q = 0.020 at τ = 0.5038). Only with
    /// `"mrt"`.
    pub mrt: Option<MrtSpec>,
    /// Smagorinsky constant C_s (seed eq. 5.38); absent: no LES.
    pub smagorinsky: Option<f64>,
    /// Where the lattice steps: `"cpu"` (the default) or `"gpu"` (a build with the `gpu`
    /// feature; the partially saturated cells are blended on the device, the grains step on
    /// the CPU; `method = "psm"` only; f64 needs an adapter with SHADER_F64).
    #[serde(default)]
    pub backend: crate::lbm::Backend,
}

/// What [`SubmergedScenario::derive`] computes.
#[derive(Clone, Debug)]
pub struct DerivedSubmerged {
    /// The DEM set-up (its `params.gravity` is the full g; the run uses the reduced one).
    pub dem: DerivedDem,
    /// Reduced gravity g′ = (1 − ρ_f/ρ_s) g (m/s²).
    pub reduced_gravity: f64,
    /// SI ↔ lattice units (ρ₀ = ρ_f) and τ.
    pub units: Units,
    /// Lattice cells along x and y.
    pub cells: [usize; 2],
    /// Velocity scale U = √(g′ a L_i) (m/s).
    pub u_ref: f64,
    /// Lattice Mach number U Δt/Δx / c_s.
    pub mach: f64,
    /// Smallest grain diameter in cells (hydrodynamic: κ d_min/Δx).
    pub d_min_cells: f64,
    /// DEM step λ Δt_cr for the smallest grain (s).
    pub dt_dem: f64,
    /// DEM sub-steps per lattice step, ⌊Δt/Δt_D⌋ + 1.
    pub subcycles: u64,
    /// Grain Reynolds number U d_mean/ν.
    pub reynolds_grain: f64,
    /// Estimated peak memory of a run (bytes), [`submerged_memory`].
    pub memory_bytes: usize,
    /// Collision model of the lattice.
    pub model: crate::lbm::CollisionModel,
}

impl ScenarioFile for SubmergedScenario {
    const KIND: Kind = Kind::Submerged;
}

impl SubmergedScenario {
    /// The DEM part alone: the dry scenario of the same geometry and deposit.
    pub fn dem_part(&self) -> DemScenario {
        DemScenario {
            kind: Kind::Dem,
            name: self.name.clone(),
            description: self.description.clone(),
            gravity: self.gravity,
            seed: self.seed,
            grains: self.grains.clone(),
            column: self.column.clone(),
            grain_contact: self.grain_contact,
            wall_contact: self.wall_contact,
            deposition: self.deposition.clone(),
            time: self.time.clone(),
            vtk: self.vtk,
        }
    }

    /// Check every value and derive the coupled set-up. Refuses, naming the field: anything
    /// the DEM scenario refuses; a liquid not lighter than the grains; non-positive ν, depth,
    /// Δx; a tank not a whole number of cells or not deeper than the column; r/R outside
    /// (0, 1]; a hydrodynamic diameter below 4 cells; neither or both of τ and Δt; τ ≤ ½;
    /// a lattice Mach number above [`MAX_MACH`]; C_s ≤ 0.
    pub fn derive(&self) -> Result<DerivedSubmerged> {
        if self.grains.sides.is_some() {
            return Err(Error::config(
                "grains.sides",
                "polygon grains are not coupled to the fluid (the partially saturated cells \
                 cover disks): leave the key out for disks",
            ));
        }
        let dem = self.dem_part().derive()?;
        let f = &self.fluid;
        let c = &self.coupling;
        c.backend
            .check()
            .map_err(|e| Error::config("coupling.backend", e))?;
        if c.backend == crate::lbm::Backend::Gpu && c.method == CouplingMethod::Ladd {
            return Err(Error::config(
                "coupling.backend",
                "Ladd's bounce-back runs on the CPU only: use backend = \"cpu\", or \
                 method = \"psm\" on the GPU",
            ));
        }
        positive("fluid.density", f.density)?;
        positive("fluid.viscosity", f.viscosity)?;
        positive("fluid.depth", f.depth)?;
        if f.density >= self.grains.density {
            return Err(Error::config(
                "fluid.density",
                format!(
                    "must be below the grain density {} kg/m³ (the grains would not sink), got {}",
                    self.grains.density, f.density
                ),
            ));
        }
        if !(c.radius_factor > 0.0 && c.radius_factor <= 1.0) {
            return Err(Error::config(
                "coupling.radius_factor",
                format!("r/R must be in (0, 1], got {}", c.radius_factor),
            ));
        }
        positive("coupling.dx", c.dx)?;
        if let Some(cs) = c.smagorinsky {
            positive("coupling.smagorinsky", cs)?;
        }
        let whole = |field: &str, len: f64| -> Result<usize> {
            let n = len / c.dx;
            let k = n.round();
            if k < 4.0 || (n - k).abs() > 1e-6 * n {
                return Err(Error::config(
                    field,
                    format!(
                        "must be a whole number (≥ 4) of cells of dx = {} m, got {len} m = {n} cells",
                        c.dx
                    ),
                ));
            }
            Ok(k as usize)
        };
        let nx = whole("column.box_length", self.column.box_length)?;
        let ny = whole("fluid.depth", f.depth)?;
        crate::scenario::check_cells("coupling.dx", nx, ny)?;
        if f.depth <= dem.target_height + self.grains.d_max {
            return Err(Error::config(
                "fluid.depth",
                format!(
                    "must exceed the column height a·L_i + d_max = {} m, got {} m",
                    dem.target_height + self.grains.d_max,
                    f.depth
                ),
            ));
        }
        let d_min_cells = c.radius_factor * self.grains.d_min / c.dx;
        if d_min_cells < 4.0 {
            return Err(Error::config(
                "coupling.dx",
                format!(
                    "the smallest hydrodynamic diameter r/R·d_min spans {d_min_cells:.2} cells; need ≥ 4"
                ),
            ));
        }
        let units = lattice_units("coupling", c.dx, c.tau, c.dt, f.viscosity, f.density)?;
        let tau = units.tau;
        let g_red = (1.0 - f.density / self.grains.density) * collapse_gravity(self.gravity)?;
        let u_ref = (g_red * dem.target_height).sqrt();
        let mach = units.velocity_to_lattice(u_ref) / CS2.sqrt();
        if mach > MAX_MACH {
            return Err(Error::config(
                "coupling.dt",
                format!(
                    "lattice Mach number {mach:.3} of the collapse speed √(g′H) = {u_ref:.3} m/s exceeds {MAX_MACH}: reduce tau/dt or refine dx"
                ),
            ));
        }
        // DEM step for the smallest grain (the run takes it from the actual grains).
        let dt_dem = dem.time_step.dt;
        let subcycles = substeps(units.dt, dt_dem).0;
        let bytes = match c.precision {
            Precision::F32 => 4,
            Precision::F64 => 8,
        };
        let model = match MrtSpec::resolve(c.mrt, c.collision, tau, "coupling")? {
            Some(rates) => crate::lbm::CollisionModel::Mrt(rates),
            None => crate::lbm::CollisionModel::Bgk,
        };
        let d_mean = (self.grains.d_min * self.grains.d_max).sqrt();
        Ok(DerivedSubmerged {
            dem,
            reduced_gravity: g_red,
            units,
            cells: [nx, ny],
            u_ref,
            mach,
            d_min_cells,
            dt_dem,
            subcycles,
            reynolds_grain: u_ref * d_mean / f.viscosity,
            memory_bytes: submerged_memory(nx * ny, bytes),
            model,
        })
    }
}

impl SubmergedScenario {
    /// What `granflow check` prints: the derived quantities, one per line, ending in `ok`.
    pub fn check_report(&self) -> Result<String> {
        let d = self.derive()?;
        let u = &d.units;
        let c = &self.coupling;
        let mut r = String::new();
        let mut line = |k: &str, v: String| r.push_str(&format!("{k:<16}{v}\n"));
        line(
            "scenario",
            format!(
                "{} — {} (submerged column collapse)",
                self.name, self.description
            ),
        );
        line("grains", format!("{}", d.dem.grains));
        line(
            "column",
            format!(
                "L_i = {:.4e} m, target H_i = {:.4e} m, τ_c = {:.4e} s",
                self.column.width, d.dem.target_height, d.dem.target_tau_c
            ),
        );
        line(
            "liquid",
            format!(
                "ρ_f = {} kg/m³, ν = {:.3e} m²/s, depth {} m; g′ = (1 − ρ_f/ρ_s) g = {:.4} m/s²",
                self.fluid.density, self.fluid.viscosity, self.fluid.depth, d.reduced_gravity
            ),
        );
        line(
            "coupling",
            format!("{:?}, r/R = {}", c.method, c.radius_factor),
        );
        line(
            "cells",
            format!(
                "{} × {} = {} (dx = {:.4e} m; hydrodynamic d_min = {:.2} cells)",
                d.cells[0],
                d.cells[1],
                d.cells[0] * d.cells[1],
                u.dx,
                d.d_min_cells
            ),
        );
        line("tau", format!("{:.6}", d.units.tau));
        line("dt (lattice)", format!("{:.4e} s", u.dt));
        line(
            "Mach (lattice)",
            format!(
                "{:.4} for U = √(g′H_i) = {:.4} m/s (limit {MAX_MACH})",
                d.mach, d.u_ref
            ),
        );
        line("Re (grain)", format!("{:.2} (U d/ν)", d.reynolds_grain));
        line(
            "dt (DEM)",
            format!(
                "{:.4e} s (λ Δt_cr, smallest grain); {} sub-steps per lattice step",
                d.dt_dem, d.subcycles
            ),
        );
        line(
            "collision",
            format!(
                "{:?}{}{} {:?}",
                c.collision,
                match d.model {
                    crate::lbm::CollisionModel::Mrt(r) => format!(
                        " (s_e = {}, s_eps = {}, s_q = {:.4})",
                        r.s_e, r.s_eps, r.s_q
                    ),
                    crate::lbm::CollisionModel::Bgk => String::new(),
                },
                c.smagorinsky
                    .map_or(String::new(), |cs| format!(" + Smagorinsky C = {cs}")),
                c.precision
            ),
        );
        let steps = (self.time.end_tc * d.dem.target_tau_c / u.dt).ceil();
        line(
            "steps",
            format!(
                "≤ {steps} lattice steps ({} τ_c), ≤ {} DEM steps",
                self.time.end_tc,
                steps * d.subcycles as f64
            ),
        );
        line("memory", crate::exec::memory_line(d.memory_bytes));
        r.push_str("ok\n");
        Ok(r)
    }
}

/// Estimated peak memory (bytes) of a submerged run on `cells` lattice cells with populations
/// of `bytes` bytes: 20 MiB + (344 + 9 `bytes`) per cell; the grains (thousands) are
/// negligible beside the lattice. The populations (9 per cell, AA pattern: one copy) and the
/// cover's per-cell sums and slots (28 bytes) are a fifth of it; the peak is reached while a
/// frame is written. Measured as the peak resident size (`/usr/bin/time`) of runs to
/// 0.05 τ_c: `dense_a0.8` (81 920 cells, f64) 46 MiB, `dense_a0.8_thesis` (2 048 000 cells,
/// f32) 763 MiB; the estimate gives 53 and 763 MiB.
pub fn submerged_memory(cells: usize, bytes: usize) -> usize {
    (20 << 20) + cells * (344 + 9 * bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text() -> String {
        std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/models/submerged/dense_a0.8.toml"
        ))
        .unwrap()
    }

    #[test]
    fn model_file_derives() {
        let s = SubmergedScenario::from_toml(&text()).unwrap();
        let d = s.derive().unwrap();
        assert!(d.units.tau > 0.5 && d.mach <= MAX_MACH);
        assert_eq!(d.subcycles, crate::scale::substeps(d.units.dt, d.dt_dem).0);
        assert!(d.units.dt / d.subcycles as f64 <= d.dt_dem);
    }

    #[test]
    fn refuses_bad_values_naming_the_field() {
        let cases = [
            (
                "radius_factor = 0.8",
                "radius_factor = 1.2",
                "coupling.radius_factor",
            ),
            ("density = 1010.0", "density = 3000.0", "fluid.density"),
            ("method = \"psm\"", "method = \"ibm\"", "method"),
            (
                "viscosity = 1.19e-5",
                "viscosity = -1.19e-5",
                "fluid.viscosity",
            ),
            ("dx = 2.5e-4", "dx = 2.6e-4", "column.box_length"),
            ("tau = 0.53", "tau = 0.9", "coupling.dt"),
        ];
        for (from, to, field) in cases {
            let t = text();
            assert!(t.contains(from), "{from}");
            let e = SubmergedScenario::from_toml(&t.replacen(from, to, 1))
                .and_then(|s| s.derive().map(|_| ()))
                .unwrap_err()
                .to_string();
            assert!(e.contains(field), "{field}: {e}");
        }
        // Both τ and Δt.
        let t = text().replacen("[coupling]", "[coupling]\ndt = 1e-5", 1);
        let e = SubmergedScenario::from_toml(&t)
            .unwrap()
            .derive()
            .unwrap_err()
            .to_string();
        assert!(e.contains("exactly one"), "{e}");
        // Unknown key.
        let t = text().replacen("[fluid]", "[fluid]\ncolour = 1", 1);
        assert!(SubmergedScenario::from_toml(&t).is_err());
    }
}
