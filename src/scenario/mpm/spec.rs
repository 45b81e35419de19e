//! The MPM column-collapse scenario (Lajeunesse et al. 2005 as simulated with GIMPM in the seed
//! thesis): TOML types, checks, and the set-up derived from them.
//!
//! Geometry as the DEM scenario (`models/column_collapse/dem_a*.toml`), so the two compare: a
//! box with a floor at y = 0, a back wall at x = 0 and an end wall at x = `column.box_length`
//! (placed on the first grid line at or beyond it); a column of width L_i and height
//! H_i = a L_i against the back wall, released at t = 0 (no gate; the column starts
//! unstressed, as in the thesis). τ_c = √(H_i/g).
//!
//! The column is filled with n × n points per cell (`mpm.points_per_cell`), each of volume
//! (h/n)² and uGIMP half-width h/(2n); the grid has 2 ghost cells outside the walls and 4
//! cells of head room above the column. L_i and H_i must be multiples of the cell size h.
//!
//! Every physical value must be given: there are no defaults (`deny_unknown_fields` also
//! refuses misspelt keys). [`MpmScenario::derive`] refuses bad values with the TOML path named;
//! [`crate::mpm::Mpm::new`] refuses a step above the CFL limit, naming `time.dt`.

use serde::{Deserialize, Serialize};

use crate::dem::periodic_cell::Preparation;
use crate::dem::{DemParams, TimeStep};
use crate::io::VtkFormat;
use crate::mpm::boundary::{Side, Wall, WallKind};
use crate::mpm::grid::Grid;
use crate::mpm::material::{LinearElastic, MaterialModel, MohrCoulomb, MuIMohrCoulomb};
use crate::mpm::points::Points;
use crate::mpm::shape::ShapeKind;
use crate::mpm::solver::{Mpm, MpmParams, Scheme, Transfer};
use crate::scenario::collapse::collapse_gravity;
use crate::scenario::dem::spec::{ContactSpec, GrainsSpec};
use crate::scenario::mpm::initial::{start, MpmInitialSpec};
use crate::scenario::{non_negative, positive, Kind, ScenarioFile};
use crate::{Error, Result};

/// An MPM column-collapse scenario, as read from TOML. All values SI (angles in degrees).
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MpmScenario {
    /// `"mpm"`: what the file describes.
    pub kind: Kind,
    /// Short name used in outputs.
    pub name: String,
    /// One line saying what the case is (and how it was scaled).
    pub description: String,
    /// Gravitational acceleration **g** = [g_x, g_y] (m/s²), pointing into the floor (g_y < 0);
    /// tilted, |g| (sin θ, −cos θ), for a collapse on a plane inclined by θ.
    pub gravity: [f64; 2],
    /// The continuum's constitutive law.
    pub material: MaterialSpec,
    /// Column and box geometry.
    pub column: MpmColumn,
    /// Discretisation.
    pub mpm: MpmSpec,
    /// Wall conditions.
    pub walls: WallsSpec,
    /// The points' initial velocity and stress (`[initial]`, optional: at rest; zero stress
    /// with a closed-form law, geostatic with `rve`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<MpmInitialSpec>,
    /// Time step, outputs, stop.
    pub time: MpmTimeSpec,
    /// How VTK frames are written (`[vtk]`, optional: zlib-compressed, f64, if absent).
    #[serde(default)]
    pub vtk: VtkFormat,
}

/// Constitutive law, chosen by `model`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum MaterialSpec {
    /// Linear isotropic elasticity.
    LinearElastic {
        /// Density ρ (kg/m³).
        density: f64,
        /// Young's modulus E (Pa).
        youngs_modulus: f64,
        /// Poisson's ratio ν.
        poisson_ratio: f64,
    },
    /// Mohr–Coulomb, non-associated, with tension cut-off.
    MohrCoulomb {
        /// Density ρ (kg/m³).
        density: f64,
        /// Young's modulus E (Pa).
        youngs_modulus: f64,
        /// Poisson's ratio ν.
        poisson_ratio: f64,
        /// Friction angle φ (degrees).
        friction_angle_deg: f64,
        /// Dilatancy angle ψ (degrees).
        dilatancy_angle_deg: f64,
        /// Cohesion c (Pa).
        cohesion: f64,
        /// Tension cut-off σ_t (Pa).
        tension_cutoff: f64,
    },
    /// Mohr–Coulomb with the μ(I) friction of dense granular flow
    /// ([`crate::mpm::material::mu_i`]): sin φ(I) = sin φ_s + (sin φ_2 − sin φ_s)/(I_0/I + 1),
    /// I = γ̇ d/√(p/ρ_s); `granflow shear` measures the three for a DEM material.
    MohrCoulombMuI {
        /// Density ρ (kg/m³).
        density: f64,
        /// Young's modulus E (Pa).
        youngs_modulus: f64,
        /// Poisson's ratio ν.
        poisson_ratio: f64,
        /// Quasi-static friction angle φ_s (degrees).
        friction_angle_deg: f64,
        /// Friction angle φ_2 at large I (degrees, ≥ φ_s).
        friction_angle_2_deg: f64,
        /// I_0: the inertial number at which sin φ is halfway from φ_s to φ_2.
        inertial_number_0: f64,
        /// I_max: the end of the measured dense-flow range; I is held at it above.
        inertial_number_max: f64,
        /// Grain diameter d (m) and grain density ρ_s (kg/m³) of the inertial number.
        grain_diameter: f64,
        /// See `grain_diameter`.
        grain_density: f64,
        /// Dilatancy angle ψ (degrees).
        dilatancy_angle_deg: f64,
        /// Cohesion c (Pa).
        cohesion: f64,
        /// Tension cut-off σ_t (Pa).
        tension_cutoff: f64,
    },
    /// A DEM representative volume at every point ([`crate::coupling::RveMaterial`]): the
    /// grains and contact law of a DEM material, a packing prepared once at `packing_fraction`
    /// and `pressure`, copied to every point and driven there to the geostatic stress with
    /// lateral ratio `k0`.
    Rve {
        /// Disks per volume.
        grains: usize,
        /// Target packing fraction φ of the prepared volume, in (0, 0.91).
        packing_fraction: f64,
        /// Isotropic confining pressure p₀ of the prepared volume (Pa, > 0), from which every
        /// point's copy is driven to its geostatic stress (choose the body's mean).
        pressure: f64,
        /// Lateral stress ratio K₀ of the initial geostatic state, σ_xx = K₀ σ_yy with
        /// σ_yy = −ρ g (H − y) (> 0; Jáky's K₀ = 1 − sin φ for a deposited soil).
        k0: f64,
        /// Seed of the sizes and the dilute start.
        seed: u64,
        /// Safety factor λ of the DEM step Δt = λ Δt_cr (seed eq. 5.60).
        lambda: f64,
        /// Verlet skin as a fraction of the largest diameter.
        skin_fraction: f64,
        /// Grain sizes, density and axial length (as a DEM scenario's `[grains]`).
        grain: GrainsSpec,
        /// Grain–grain contact law (as a DEM scenario's `[grain_contact]`).
        contact: ContactSpec,
    },
}

/// The material a scenario's `[material]` gives: a closed-form law, or the preparation of the
/// representative volume whose copies are the points' laws.
#[derive(Clone, Debug)]
pub enum Law {
    /// Elastic, Mohr–Coulomb or μ(I).
    Continuum(MaterialModel),
    /// The DEM volume, not prepared yet (preparing takes seconds to minutes).
    Volume(Volume),
}

/// A representative volume to prepare, and the initial state its copies are driven to.
#[derive(Clone, Debug)]
pub struct Volume {
    /// The preparation of the template packing.
    pub preparation: Preparation,
    /// Lateral stress ratio K₀ of the points' initial geostatic state.
    pub k0: f64,
}

impl Volume {
    /// Prepare the packing (seconds to minutes): the material of the points. A packing the
    /// preparation cannot make is refused naming `material.packing_fraction`.
    pub fn material(&self) -> Result<crate::coupling::RveMaterial> {
        crate::coupling::RveMaterial::prepare(&self.preparation)
            .map_err(|why| Error::config("material.packing_fraction", why))
    }
}

/// Column and box.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MpmColumn {
    /// Initial width L_i (m).
    pub width: f64,
    /// Aspect ratio a = H_i/L_i.
    pub aspect_ratio: f64,
    /// Box length (m): the end wall's x.
    pub box_length: f64,
}

/// Discretisation.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MpmSpec {
    /// Cell size h (m).
    pub cell_size: f64,
    /// Points per cell along each direction, n (n² per cell).
    pub points_per_cell: usize,
    /// `"gimp"` or `"standard"`.
    pub shape: ShapeKind,
    /// `"usf"`, `"usl"` or `"musl"`.
    pub scheme: Scheme,
    /// Courant number C of Δt_max = C h/c.
    pub courant: f64,
    /// Local damping α (0: none; a collapse should use 0).
    pub damping: f64,
    /// Velocity transfer: `"flip"` (blended with PIC by `pic_fraction`) or `"apic"` (affine
    /// PIC, Jiang et al. 2015; uGIMP only, `pic_fraction` must be 0).
    pub transfer: Transfer,
    /// PIC fraction β of the velocity update (0: pure FLIP), see
    /// [`crate::mpm::MpmParams::pic_fraction`].
    pub pic_fraction: f64,
    /// Re-sort the points into cell order every this many steps (performance only).
    pub resort_every: u64,
}

impl MpmSpec {
    /// Check every value (fields named under `mpm.`).
    pub fn check(&self) -> Result<()> {
        positive("mpm.cell_size", self.cell_size)?;
        if !(1..=8).contains(&self.points_per_cell) {
            return Err(Error::config(
                "mpm.points_per_cell",
                format!(
                    "must be 1..=8 (points per cell per direction), got {}",
                    self.points_per_cell
                ),
            ));
        }
        if !(self.courant > 0.0 && self.courant <= 1.0) {
            return Err(Error::config(
                "mpm.courant",
                format!("must be in (0, 1], got {}", self.courant),
            ));
        }
        if !(self.damping >= 0.0 && self.damping < 1.0) {
            return Err(Error::config(
                "mpm.damping",
                format!("must be in [0, 1), got {}", self.damping),
            ));
        }
        self.transfer.check(self.shape, self.pic_fraction)
    }

    /// The solver parameters under `gravity`, with the step `dt` (else C h/c).
    pub fn params(&self, gravity: [f64; 2], dt: Option<f64>) -> MpmParams {
        MpmParams {
            shape: self.shape,
            scheme: self.scheme,
            gravity,
            courant: self.courant,
            dt,
            damping: self.damping,
            pic_fraction: self.pic_fraction,
            resort_every: self.resort_every,
        }
    }
}

/// Conditions of the three walls.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallsSpec {
    /// Floor y = 0.
    pub base: WallKind,
    /// Back wall x = 0.
    pub back: WallKind,
    /// End wall x = box_length.
    pub end: WallKind,
}

/// Time stepping, outputs, stop.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MpmTimeSpec {
    /// Time step (s); omitted: C h/c. A larger one than C h/c is refused.
    pub dt: Option<f64>,
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

/// What [`MpmScenario::derive`] computes.
#[derive(Clone, Debug)]
pub struct DerivedMpm {
    /// The material.
    pub material: Law,
    /// H_i = a L_i (m).
    pub height: f64,
    /// τ_c = √(H_i/g) (s).
    pub tau_c: f64,
    /// Number of material points.
    pub points: usize,
    /// Grid cells (x, y).
    pub cells: [usize; 2],
    /// CFL limit C h/c (s); for a volume, estimated before it is prepared (the run uses
    /// the prepared packing's affine modulus).
    pub dt_cfl: f64,
    /// P-wave speed c = √((K + 4G/3)/ρ) (m/s); for a volume, the estimate of `dt_cfl`.
    pub wave_speed: f64,
}

/// Refuses a friction wall with μ < 0, naming `field.mu`.
pub(crate) fn check_wall(field: &str, w: &WallKind) -> Result<()> {
    if let WallKind::Friction { mu } = w {
        non_negative(&format!("{field}.mu"), *mu)?;
    }
    Ok(())
}

fn elastic(field: &str, density: f64, e: f64, nu: f64) -> Result<LinearElastic> {
    positive(&format!("{field}.density"), density)?;
    positive(&format!("{field}.youngs_modulus"), e)?;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(Error::config(
            format!("{field}.poisson_ratio"),
            format!("must be in (−1, 0.5), got {nu}"),
        ));
    }
    Ok(LinearElastic {
        density,
        youngs_modulus: e,
        poisson_ratio: nu,
    })
}

impl MaterialSpec {
    /// The material, with its values checked (fields named under `material.`).
    pub fn build(&self) -> Result<Law> {
        Ok(match self {
            MaterialSpec::Rve {
                grains,
                packing_fraction,
                pressure,
                k0,
                seed,
                lambda,
                skin_fraction,
                grain,
                contact,
            } => {
                positive("material.k0", *k0)?;
                Law::Volume(Volume {
                    preparation: volume(
                        "material",
                        *grains,
                        *packing_fraction,
                        *pressure,
                        *seed,
                        *lambda,
                        *skin_fraction,
                        grain,
                        contact,
                    )?,
                    k0: *k0,
                })
            }
            m => Law::Continuum(m.continuum()?),
        })
    }

    /// A closed-form law (not `rve`).
    fn continuum(&self) -> Result<MaterialModel> {
        Ok(match *self {
            MaterialSpec::Rve { .. } => unreachable!("handled by build"),
            MaterialSpec::LinearElastic {
                density,
                youngs_modulus,
                poisson_ratio,
            } => {
                MaterialModel::Elastic(elastic("material", density, youngs_modulus, poisson_ratio)?)
            }
            MaterialSpec::MohrCoulomb {
                density,
                youngs_modulus,
                poisson_ratio,
                friction_angle_deg,
                dilatancy_angle_deg,
                cohesion,
                tension_cutoff,
            } => MaterialModel::MohrCoulomb(mohr_coulomb(
                elastic("material", density, youngs_modulus, poisson_ratio)?,
                friction_angle_deg,
                dilatancy_angle_deg,
                cohesion,
                tension_cutoff,
            )?),
            MaterialSpec::MohrCoulombMuI {
                density,
                youngs_modulus,
                poisson_ratio,
                friction_angle_deg,
                friction_angle_2_deg,
                inertial_number_0,
                inertial_number_max,
                grain_diameter,
                grain_density,
                dilatancy_angle_deg,
                cohesion,
                tension_cutoff,
            } => {
                let base = mohr_coulomb(
                    elastic("material", density, youngs_modulus, poisson_ratio)?,
                    friction_angle_deg,
                    dilatancy_angle_deg,
                    cohesion,
                    tension_cutoff,
                )?;
                if !(friction_angle_2_deg >= friction_angle_deg && friction_angle_2_deg < 90.0) {
                    return Err(Error::config(
                        "material.friction_angle_2_deg",
                        format!(
                            "must be in [φ_s = {friction_angle_deg}, 90), got {friction_angle_2_deg}"
                        ),
                    ));
                }
                for (field, v) in [
                    ("material.inertial_number_0", inertial_number_0),
                    ("material.inertial_number_max", inertial_number_max),
                    ("material.grain_diameter", grain_diameter),
                    ("material.grain_density", grain_density),
                ] {
                    if !(v > 0.0 && v.is_finite()) {
                        return Err(Error::config(field, format!("must be > 0, got {v}")));
                    }
                }
                MaterialModel::MuI(MuIMohrCoulomb::new(
                    base,
                    friction_angle_2_deg.to_radians(),
                    [inertial_number_0, inertial_number_max],
                    grain_diameter,
                    grain_density,
                ))
            }
        })
    }
}

/// The preparation of a representative volume, every value checked (fields named under
/// `table.`, e.g. `material`): the MPM's `rve` model and the periodic biaxial test.
#[allow(clippy::too_many_arguments)]
pub(crate) fn volume(
    table: &str,
    grains: usize,
    packing_fraction: f64,
    pressure: f64,
    seed: u64,
    lambda: f64,
    skin_fraction: f64,
    grain: &GrainsSpec,
    contact: &ContactSpec,
) -> Result<Preparation> {
    let key = |k: &str| format!("{table}.{k}");
    if grains < 16 {
        return Err(Error::config(
            key("grains"),
            format!("a representative volume needs at least 16 grains, got {grains}"),
        ));
    }
    if !(packing_fraction > 0.0 && packing_fraction < 0.91) {
        return Err(Error::config(
            key("packing_fraction"),
            format!("must be in (0, 0.91) (disks pack at most at 0.907), got {packing_fraction}"),
        ));
    }
    positive(&key("pressure"), pressure)?;
    positive(&key("skin_fraction"), skin_fraction)?;
    positive(&key("grain.d_min"), grain.d_min)?;
    positive(&key("grain.density"), grain.density)?;
    positive(&key("grain.thickness"), grain.thickness)?;
    if !(grain.d_max >= grain.d_min && grain.d_max.is_finite()) {
        return Err(Error::config(
            key("grain.d_max"),
            format!("must be ≥ d_min = {}, got {}", grain.d_min, grain.d_max),
        ));
    }
    let law = contact.params();
    law.check(&key("contact"))?;
    let mut params = DemParams::new(law, law, [0.0; 2]);
    params.lambda = lambda;
    let areal = grain.density * grain.thickness;
    let dt = TimeStep::of_disk(&params, grain.d_min, areal)
        .map_err(|e| e.within(table))?
        .dt;
    Ok(Preparation {
        grains,
        diameter: [grain.d_min, grain.d_max],
        distribution: grain.distribution.into(),
        density: grain.density,
        thickness: grain.thickness,
        contact: law,
        dt,
        skin: skin_fraction * grain.d_max,
        pressure,
        packing_fraction,
        tolerance: 0.005,
        inertial_number: 1e-3,
        seed,
    })
}

/// Estimated P-wave modulus of a packing before it exists: the affine modulus of
/// [`crate::dem::periodic_cell::PeriodicCell::affine_modulus`] for an isotropic fabric
/// (⟨n_x⁴⟩ = 3/8, ⟨n_x² n_y²⟩ = 1/8), z = 4 contacts per grain and branch lengths d̄:
/// C ≈ φ (3k_n + k_t)/(π t).
fn volume_modulus(p: &Preparation) -> f64 {
    p.packing_fraction * (3.0 * p.contact.k_n + p.contact.k_t)
        / (std::f64::consts::PI * p.thickness)
}

/// The Mohr–Coulomb material, its angles (degrees) and strengths checked.
fn mohr_coulomb(
    el: LinearElastic,
    friction_angle_deg: f64,
    dilatancy_angle_deg: f64,
    cohesion: f64,
    tension_cutoff: f64,
) -> Result<MohrCoulomb> {
    if !(friction_angle_deg > 0.0 && friction_angle_deg < 90.0) {
        return Err(Error::config(
            "material.friction_angle_deg",
            format!("must be in (0, 90), got {friction_angle_deg}"),
        ));
    }
    if !(dilatancy_angle_deg >= 0.0 && dilatancy_angle_deg <= friction_angle_deg) {
        return Err(Error::config(
            "material.dilatancy_angle_deg",
            format!("must be in [0, φ = {friction_angle_deg}], got {dilatancy_angle_deg}"),
        ));
    }
    non_negative("material.cohesion", cohesion)?;
    non_negative("material.tension_cutoff", tension_cutoff)?;
    Ok(MohrCoulomb::new(
        el,
        friction_angle_deg.to_radians(),
        dilatancy_angle_deg.to_radians(),
        cohesion,
        tension_cutoff,
    ))
}

/// n if `v` is within 1e-6 of the integer n ≥ 1.
/// Most material points or grid cells a scenario may ask for (far beyond any machine's memory
/// at ≈ 1.4 KiB per point, so only a mistyped cell size reaches it).
const MAX_POINTS: f64 = 1e12;

fn whole(v: f64) -> Option<usize> {
    let n = v.round();
    ((v - n).abs() < 1e-6 * v.max(1.0) && n >= 1.0).then_some(n as usize)
}

impl ScenarioFile for MpmScenario {
    const KIND: Kind = Kind::Mpm;
}

impl MpmScenario {
    /// Check every value and derive the set-up (see the module doc for what is refused).
    pub fn derive(&self) -> Result<DerivedMpm> {
        let g_abs = collapse_gravity(self.gravity)?;
        let material = self.material.build()?;
        if let Some(initial) = &self.initial {
            initial.compile()?;
            if initial.stress.is_some() && matches!(material, Law::Volume(_)) {
                return Err(Error::config(
                    "initial.stress",
                    "the rve model's points start at the geostatic stress of material.k0",
                ));
            }
        }
        let c = &self.column;
        positive("column.width", c.width)?;
        positive("column.aspect_ratio", c.aspect_ratio)?;
        positive("column.box_length", c.box_length)?;
        if c.box_length <= c.width {
            return Err(Error::config(
                "column.box_length",
                format!(
                    "must exceed the column width {} m, got {} m",
                    c.width, c.box_length
                ),
            ));
        }
        let m = &self.mpm;
        m.check()?;
        let height = c.aspect_ratio * c.width;
        let h = m.cell_size;
        let (Some(wc), Some(hc)) = (whole(c.width / h), whole(height / h)) else {
            return Err(Error::config(
                "mpm.cell_size",
                format!(
                    "the column {} m × {} m must be a whole number of cells of {} m",
                    c.width, height, h
                ),
            ));
        };
        let cells_x = (c.box_length / h).ceil();
        let points = (wc as f64) * (hc as f64) * (m.points_per_cell as f64).powi(2);
        if points > MAX_POINTS || cells_x * (hc as f64) > MAX_POINTS {
            return Err(Error::config(
                "mpm.cell_size",
                format!(
                    "{h} m gives {points:.3e} points and {:.3e} grid cells, more than the \
                     {MAX_POINTS:e} a run can hold: choose larger cells",
                    cells_x * hc as f64
                ),
            ));
        }
        check_wall("walls.base", &self.walls.base)?;
        check_wall("walls.back", &self.walls.back)?;
        check_wall("walls.end", &self.walls.end)?;
        let t = &self.time;
        if let Some(dt) = t.dt {
            positive("time.dt", dt)?;
        }
        positive("time.frame_interval_tc", t.frame_interval_tc)?;
        positive("time.series_interval_tc", t.series_interval_tc)?;
        positive("time.end_tc", t.end_tc)?;
        positive("time.rest_kinetic_fraction", t.rest_kinetic_fraction)?;
        positive("time.rest_duration_tc", t.rest_duration_tc)?;
        let (modulus, density) = match &material {
            Law::Continuum(m) => {
                use crate::mpm::material::Material;
                (m.p_wave_modulus(), m.density())
            }
            Law::Volume(v) => {
                let p = &v.preparation;
                (volume_modulus(p), p.density * p.packing_fraction)
            }
        };
        let wave_speed = (modulus / density).sqrt();
        let dt_cfl = m.courant * h / wave_speed;
        if let Some(dt) = t.dt {
            if dt > dt_cfl {
                return Err(Error::config(
                    "time.dt",
                    format!("Δt = {dt:e} s exceeds the CFL limit C h/c = {dt_cfl:e} s"),
                ));
            }
        }
        let n = m.points_per_cell;
        Ok(DerivedMpm {
            material,
            height,
            tau_c: (height / g_abs).sqrt(),
            points: wc * hc * n * n,
            cells: [cells_x as usize + 4, hc + 6],
            dt_cfl,
            wave_speed,
        })
    }

    /// Build the solver at t = 0 with a closed-form law (the `rve` model is built by
    /// [`MpmScenario::build_with`] once its volume is prepared).
    pub fn build(&self) -> Result<(Mpm, DerivedMpm)> {
        let d = self.derive()?;
        let Law::Continuum(material) = d.material.clone() else {
            return Err(Error::config(
                "material.model",
                "the rve model needs its volume prepared first (build_with)",
            ));
        };
        Ok((self.build_with(material, &d, |_| [0.0; 4])?, d))
    }

    /// The geostatic stress of the column at rest, σ_yy = −ρ |g_y| (H − y), σ_xx = K₀ σ_yy,
    /// σ_zz = ½(σ_xx + σ_yy), for a bulk density ρ (under a tilted gravity, the stress of
    /// its normal component alone: the column is not at rest then).
    pub fn geostatic(
        &self,
        d: &DerivedMpm,
        density: f64,
        k0: f64,
    ) -> impl Fn([f64; 2]) -> crate::mpm::material::Stress + Sync {
        let (g, height) = (-self.gravity[1], d.height);
        move |x| {
            let yy = -density * g * (height - x[1]);
            [k0 * yy, yy, 0.0, 0.5 * (1.0 + k0) * yy]
        }
    }

    /// Build the solver at t = 0 with `material`, every point starting from
    /// [`crate::mpm::Material::initial_state`] at the stress `[initial]` gives at its position,
    /// or else the stress `initial` gives (zero for the closed-form laws), and at the velocity
    /// `[initial]` gives (else at rest).
    pub fn build_with<M: crate::mpm::Material>(
        &self,
        material: M,
        d: &DerivedMpm,
        initial: impl Fn([f64; 2]) -> crate::mpm::material::Stress + Sync,
    ) -> Result<Mpm<M>> {
        let h = self.mpm.cell_size;
        let end = (self.column.box_length / h).ceil() * h;
        let walls = vec![
            Wall {
                side: Side::Bottom,
                position: 0.0,
                kind: self.walls.base,
            },
            Wall {
                side: Side::Left,
                position: 0.0,
                kind: self.walls.back,
            },
            Wall {
                side: Side::Right,
                position: end,
                kind: self.walls.end,
            },
        ];
        let grid = Grid::new(d.cells[0], d.cells[1], h, [-2.0 * h, -2.0 * h], walls);
        let mut pts = Points::default();
        pts.fill_rect(
            [0.0, 0.0],
            [self.column.width, d.height],
            h,
            self.mpm.points_per_cell,
            material.density(),
        );
        let params = self.mpm.params(self.gravity, self.time.dt);
        let mut mpm = Mpm::new(grid, pts, material, params)?;
        mpm.set_transfer(self.mpm.transfer)?;
        start(&mut mpm, self.initial.as_ref(), initial)?;
        Ok(mpm)
    }
}

/// Memory per grain of the points' representative volumes (bytes; a volume re-tiled when
/// stretched thin holds twice its grains from then on). Measured as the peak resident size
/// (`/usr/bin/time`) of `rve_a1` to 0.02 τ_c on one thread with 100 and 400 points
/// (20 000 and 80 000 grains): 13.0 and 30.9 MiB, 314 bytes per grain between them; with
/// [`DerivedMpm::memory_bytes`] the estimate gives 14.2 and 33.0 MiB.
pub const RVE_BYTES_PER_GRAIN: usize = 320;

impl DerivedMpm {
    /// Estimated peak memory (bytes) of the run: 8 MiB + 1.4 KiB per point (points, the grid
    /// at 4 points per cell, a frame being written), and for representative volumes
    /// [`RVE_BYTES_PER_GRAIN`] per grain of all the points' volumes. Measured as the peak
    /// resident size (`/usr/bin/time`) of `mpm_a2` at its cell size and half of it, to
    /// 0.05 τ_c: 17.8 MiB for 8192 points, 49.9 MiB for 32 768; the estimate gives 19 and
    /// 53 MiB.
    pub fn memory_bytes(&self) -> usize {
        let volumes = match &self.material {
            Law::Volume(v) => self
                .points
                .saturating_mul(v.preparation.grains)
                .saturating_mul(RVE_BYTES_PER_GRAIN),
            Law::Continuum(_) => 0,
        };
        point_memory(self.points).saturating_add(volumes)
    }
}

/// Estimated peak memory (bytes) of an MPM run with closed-form laws: 8 MiB + 1.4 KiB per
/// point (see [`DerivedMpm::memory_bytes`]).
pub fn point_memory(points: usize) -> usize {
    (8usize << 20).saturating_add(points.saturating_mul(1434))
}
