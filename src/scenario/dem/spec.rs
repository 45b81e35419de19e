//! The DEM column-collapse scenario (Lajeunesse et al. 2005, as simulated in the seed thesis):
//! TOML types, checks, and the quantities derived from them.
//!
//! Set-up: a box with a floor at y = 0, a left wall at x = 0 and a right wall at
//! x = `column.box_length`. A column of width L_i is deposited by gravity against the left wall
//! behind a gate at x = L_i ([`crate::dem::packing::deposit_column`]); its height is
//! H_i ≈ a·L_i. At t = 0 the gate is removed and the column collapses; τ_c = √(H_i/g).
//!
//! Grains are disks of diameter d (uniform by volume between d_min and d_max, as in the
//! thesis) and of axial length `grains.thickness`, so m = ρ π d²/4 · thickness and
//! J = ½ m R². The contact stiffnesses are per grain (N/m).
//!
//! The number of grains is N = round(φ_est · a L_i² / ⟨π d²/4⟩), with ⟨d²⟩ = d_min d_max for the
//! by-volume distribution (its exact mean) and φ_est = `column.packing_estimate`; the deposited
//! height then gives the actual H_i and a, both reported.
//!
//! Every physical value must be given: there are no defaults (`deny_unknown_fields` also
//! refuses misspelt keys). [`DemScenario::derive`] refuses bad values with the TOML path named.

use serde::{Deserialize, Serialize};

use crate::dem::contact::ContactParams;
use crate::dem::packing::{ColumnSpec, SizeDistribution};
use crate::dem::{DemParams, TimeStep};
use crate::io::VtkFormat;
use crate::scenario::collapse::collapse_gravity;
use crate::scenario::{non_negative, positive, Kind, ScenarioFile};
use crate::{Error, Result};

/// A DEM column-collapse scenario, as read from TOML. All values SI.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DemScenario {
    /// `"dem"`: what the file describes.
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
    /// Deposition of the initial column.
    pub deposition: DepositionSpec,
    /// Time step, output intervals, stop criterion.
    pub time: DemTimeSpec,
    /// How VTK frames are written (`[vtk]`, optional: zlib-compressed, f64, if absent).
    #[serde(default)]
    pub vtk: VtkFormat,
}

/// Grain sizes and material.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GrainsSpec {
    /// Smallest diameter d_min (m).
    pub d_min: f64,
    /// Largest diameter d_max (m).
    pub d_max: f64,
    /// `"uniform_by_volume"` (the thesis) or `"uniform"` (in number).
    pub distribution: Distribution,
    /// Material density ρ (kg/m³).
    pub density: f64,
    /// Axial length of the disks (m): m = ρ π d²/4 · thickness.
    pub thickness: f64,
    /// Regular convex polygons of this many sides (3–12) instead of disks: each has the area
    /// of the disk of its drawn diameter d (circumradius (d/2) √(2π / (n sin(2π/n)))), at a
    /// random orientation; contacts by rapier2d. Omitted: disks. Not in `submerged` files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sides: Option<usize>,
}

impl GrainsSpec {
    /// Refuse (naming the `grains.` field) a non-positive size, density or thickness and
    /// d_max < d_min.
    pub fn check(&self) -> Result<()> {
        positive("grains.d_min", self.d_min)?;
        positive("grains.d_max", self.d_max)?;
        positive("grains.density", self.density)?;
        positive("grains.thickness", self.thickness)?;
        if let Some(n) = self.sides {
            if !(3..=12).contains(&n) {
                return Err(Error::config(
                    "grains.sides",
                    format!("regular polygons of 3 to 12 sides, got {n}"),
                ));
            }
        }
        if self.d_max < self.d_min {
            return Err(Error::config(
                "grains.d_max",
                format!("must be ≥ d_min = {}, got {}", self.d_min, self.d_max),
            ));
        }
        Ok(())
    }
}

/// Diameter distribution, see [`SizeDistribution`].
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Distribution {
    /// Uniform in number.
    Uniform,
    /// Equal grain area per diameter interval (p(d) ∝ d⁻² in 2-D).
    UniformByVolume,
}

/// Column and box.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColumnGeometry {
    /// Initial width L_i (m).
    pub width: f64,
    /// Target aspect ratio a = H_i/L_i.
    pub aspect_ratio: f64,
    /// Expected packing fraction φ_est of the deposit, used to choose the number of grains.
    pub packing_estimate: f64,
    /// Box length (m): the right wall's x. Must exceed the expected run-out.
    pub box_length: f64,
}

/// One contact law (see [`ContactParams`]).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Normal stiffness k_n (N/m).
    pub k_n: f64,
    /// Tangential stiffness k_t (N/m).
    pub k_t: f64,
    /// Restitution coefficient e ∈ (0, 1].
    pub restitution: f64,
    /// Coulomb friction μ.
    pub friction: f64,
    /// Rolling spring k_r (N·m/rad); 0: no rolling resistance.
    pub rolling_stiffness: f64,
    /// Rolling dashpot c_r (N·m·s/rad).
    pub rolling_damping: f64,
    /// Rolling friction μ_r (moment cap μ_r R_eff |f_n|).
    pub rolling_friction: f64,
}

impl ContactSpec {
    /// The solver's parameters (no extra γ_n, γ_t damping).
    pub fn params(&self) -> ContactParams {
        ContactParams {
            k_n: self.k_n,
            k_t: self.k_t,
            restitution: self.restitution,
            gamma_n: 0.0,
            gamma_t: 0.0,
            friction: self.friction,
            rolling_stiffness: self.rolling_stiffness,
            rolling_damping: self.rolling_damping,
            rolling_friction: self.rolling_friction,
        }
    }
}

/// Deposition of the initial column.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DepositionSpec {
    /// Grain–grain friction during deposition: 0 gives a dense column, ≈ the grain value a
    /// loose one.
    pub friction: f64,
    /// Grain–grain rolling-friction cap μ_r during deposition (used where `rolling_stiffness`
    /// is not 0): the grain value, or above it for a column looser than friction alone makes.
    /// When either value differs from `grain_contact`, the deposit then settles again under
    /// the grain laws before the release ([`ColumnSpec::relax`]).
    pub rolling_friction: f64,
    /// Settling velocity v_s (m/s) of a sedimentation: when given, the grains fall against a
    /// drag −m (g/v_s) **v** (global damping α = g/v_s, seed eq. 5.57), so none falls faster
    /// than v_s and each lands gently where its friction holds it, as in a column left to
    /// settle after fluidisation (Rondon et al. 2011). The deposit then settles again under
    /// the undamped grain laws. Absent: the grains fall freely (dry pluviation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settling_velocity: Option<f64>,
    /// Rest: kinetic energy per grain below this fraction of m̄ g d̄.
    pub rest_fraction: f64,
    /// Give up after this simulated time (s).
    pub max_time: f64,
}

/// Time stepping, outputs, stop.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DemTimeSpec {
    /// Safety factor λ of seed eq. 5.60 (Δt = λ Δt_cr); at most 0.1 is advised.
    pub lambda: f64,
    /// Interval between VTK frames, in units of τ_c.
    pub frame_interval_tc: f64,
    /// Interval between time-series rows, in units of τ_c.
    pub series_interval_tc: f64,
    /// Give up after this time, in units of τ_c.
    pub end_tc: f64,
    /// Rest: kinetic energy below this fraction of the initial potential energy above the floor…
    pub rest_kinetic_fraction: f64,
    /// …for this long, in units of τ_c.
    pub rest_duration_tc: f64,
}

/// What [`DemScenario::derive`] computes.
#[derive(Clone, Debug)]
pub struct DerivedDem {
    /// Solver parameters for the collapse.
    pub params: DemParams,
    /// The deposition to run (its `params` carry the deposition friction).
    pub column: ColumnSpec,
    /// Number of grains N.
    pub grains: usize,
    /// Target initial height a·L_i (m).
    pub target_height: f64,
    /// Target τ_c = √(a L_i/g) (s); the run uses the deposited height's.
    pub target_tau_c: f64,
    /// The DEM step of the smallest grain (the run's, up to the drawn sizes).
    pub time_step: TimeStep,
}

impl From<Distribution> for SizeDistribution {
    fn from(d: Distribution) -> Self {
        match d {
            Distribution::Uniform => SizeDistribution::Uniform,
            Distribution::UniformByVolume => SizeDistribution::UniformByVolume,
        }
    }
}

impl ScenarioFile for DemScenario {
    const KIND: Kind = Kind::Dem;
}

impl DemScenario {
    /// Check every value and derive the solver set-up. Refuses, naming the field: non-positive
    /// sizes, densities, stiffnesses or intervals; d_max < d_min; a column narrower than
    /// 4 d_max; a box not longer than the column; φ_est outside (0.5, 0.91); λ outside (0, 1];
    /// deposition friction or rolling friction < 0; a settling velocity ≤ 0; and (through
    /// [`crate::dem::Dem::new`] later) a step above λ Δt_cr.
    pub fn derive(&self) -> Result<DerivedDem> {
        let g_abs = collapse_gravity(self.gravity)?;
        let g = &self.grains;
        g.check()?;
        let c = &self.column;
        positive("column.width", c.width)?;
        positive("column.aspect_ratio", c.aspect_ratio)?;
        positive("column.box_length", c.box_length)?;
        if c.width < 4.0 * g.d_max {
            return Err(Error::config(
                "column.width",
                format!(
                    "must hold at least 4 grains of d_max = {} m, got {} m",
                    g.d_max, c.width
                ),
            ));
        }
        if c.box_length <= c.width {
            return Err(Error::config(
                "column.box_length",
                format!(
                    "must exceed the column width {} m, got {} m",
                    c.width, c.box_length
                ),
            ));
        }
        if !(c.packing_estimate > 0.5 && c.packing_estimate < 0.91) {
            return Err(Error::config(
                "column.packing_estimate",
                format!(
                    "must be in (0.5, 0.91) (2-D disk packings), got {}",
                    c.packing_estimate
                ),
            ));
        }
        let grain = self.grain_contact.params();
        let wall = self.wall_contact.params();
        grain.check("grain_contact")?;
        wall.check("wall_contact")?;
        let d = &self.deposition;
        non_negative("deposition.friction", d.friction)?;
        non_negative("deposition.rolling_friction", d.rolling_friction)?;
        if let Some(v) = d.settling_velocity {
            positive("deposition.settling_velocity", v)?;
        }
        positive("deposition.rest_fraction", d.rest_fraction)?;
        positive("deposition.max_time", d.max_time)?;
        let t = &self.time;
        positive("time.frame_interval_tc", t.frame_interval_tc)?;
        positive("time.series_interval_tc", t.series_interval_tc)?;
        positive("time.end_tc", t.end_tc)?;
        positive("time.rest_kinetic_fraction", t.rest_kinetic_fraction)?;
        positive("time.rest_duration_tc", t.rest_duration_tc)?;
        let mean_d2 = match g.distribution {
            Distribution::UniformByVolume => g.d_min * g.d_max,
            Distribution::Uniform => {
                (g.d_min * g.d_min + g.d_min * g.d_max + g.d_max * g.d_max) / 3.0
            }
        };
        let target_height = c.aspect_ratio * c.width;
        let n = (c.packing_estimate * c.width * target_height
            / (std::f64::consts::FRAC_PI_4 * mean_d2))
            .round() as usize;
        if n < 10 {
            return Err(Error::config(
                "column.width",
                format!("the column holds only {n} grains; make it larger"),
            ));
        }
        let mut params = DemParams::new(grain, wall, self.gravity);
        params.lambda = t.lambda;
        // The step of the smallest grain: what the run will take (from the actual grains).
        let time_step = TimeStep::of_disk(&params, g.d_min, g.density * g.thickness)
            .map_err(|e| e.within("time"))?;
        let mut dep = params.clone();
        dep.grain.friction = d.friction;
        dep.grain.rolling_friction = d.rolling_friction;
        dep.global_damping = d.settling_velocity.map_or(0.0, |v| g_abs / v);
        let relax =
            (dep.grain != params.grain || dep.global_damping != 0.0).then(|| params.clone());
        let column = ColumnSpec {
            x0: 0.0,
            width: c.width,
            grains: n,
            diameter: [g.d_min, g.d_max],
            distribution: g.distribution.into(),
            density: g.density * g.thickness,
            params: dep,
            relax,
            seed: self.seed,
            rest_fraction: d.rest_fraction,
            max_time: d.max_time,
            sides: g.sides,
        };
        Ok(DerivedDem {
            params,
            column,
            grains: n,
            target_height,
            target_tau_c: (target_height / g_abs).sqrt(),
            time_step,
        })
    }
}

/// Estimated peak memory (bytes) of a DEM column collapse of `grains` disks:
/// 8 MiB + 2 KiB per grain (state, neighbour and contact lists, a frame being written).
/// Measured as the peak resident size (`/usr/bin/time`) of `dem_a2` widened to 1542, 6168 and
/// 13 878 grains, run to 0.05 τ_c after the deposition: 9.3, 17.7 and 31.6 MiB; the estimate
/// gives 11, 20 and 35 MiB.
pub fn dem_memory(grains: usize) -> usize {
    (8usize << 20).saturating_add(grains.saturating_mul(2048))
}
