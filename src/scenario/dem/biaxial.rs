//! Biaxial (plane-strain) compression of a disk packing: the macroscopic friction angle of a
//! DEM material, the number a Mohr–Coulomb continuum standing for that material needs.
//!
//! The sample is deposited by gravity between a floor and two side walls (the collapse
//! column's preparation, [`deposit_column`]), gravity is switched off, a lid is put on, and
//! the packing is brought to the confining stress σ₃ on the right wall and on the lid. Once at
//! rest, the grains' own contact laws replace the preparation's (contact history cleared, as at
//! a collapse's release) and the sample comes to rest again at σ₃. Then the lid moves down at
//! the constant speed ε̇ H₀, with ε̇ = I/(d̄ √(ρ_s/σ₃)) for a chosen inertial number I
//! (≤ 10⁻³ is quasi-static, GDR MiDi 2004), while the right wall keeps σ₃. All walls are
//! frictionless; the floor and the left wall stay put.
//!
//! Stresses are boundary forces per unit length and thickness t (compression positive):
//! σ₁ = F_lid/(W t), σ₃ = F_right/(H t); the mobilised friction is
//! sin φ = (σ₁ − σ₃)/(σ₁ + σ₃), the Mohr–Coulomb angle of the plane (σ₁ at failure =
//! σ₃(1 + sin φ)/(1 − sin φ), as the GIMPM's plane-strain Mohr–Coulomb). Strains: axial
//! ε₁ = 1 − H/H₀, volumetric ε_v = 1 − W H/(W₀ H₀) (compression positive).
//!
//! The right wall and, while the sample is consolidated, the lid are pistons: each has a tenth
//! of the sample's mass M and is pushed towards the grains by the target force (σ₃ times its
//! length times t), M dv/dt = F_contacts − F_target (explicit, updated every
//! [`PISTON_STEPS`] steps from the contact forces at the start of the interval, speed capped
//! at 10× the lid's). Over any stretch in which a piston does not accelerate on average, the
//! mean contact stress on it is therefore the target, with no servo gain to tune. Measured on
//! 300 grains at σ₃ = 1 kPa: σ₃ = 1000 ± 4 Pa over the shear (with the sample's mass and
//! the cap at the lid's speed, 1038 ± 72 Pa; a proportional servo on such rigid grains,
//! κ = k_n/(σ₃ t) ≈ 10⁴, let σ₃ swing by an order of magnitude).

use std::path::Path;

use serde::Serialize;

use crate::dem::contact::ContactParams;
use crate::dem::packing::{deposit_column, with_friction, ColumnSpec};
use crate::dem::walls::Wall;
use crate::dem::{Dem, DemParams};
use crate::io::csv::CsvWriter;
use crate::io::json::write_json;
use crate::io::plot::write_svg;
use crate::report::{Plot, Series};
use crate::scenario::dem::spec::DemScenario;
use crate::{Error, Result};

/// Largest inertial number of the consolidation's wall speeds.
const CONSOLIDATION_INERTIAL_NUMBER: f64 = 1e-3;
/// Recorded points in the running mean whose largest value is the peak.
pub const PEAK_POINTS: usize = 5;
/// Steps between two piston updates.
pub const PISTON_STEPS: u64 = 10;
/// Wall indices of the sample box (1: the left wall).
const FLOOR: usize = 0;
const RIGHT: usize = 2;
const LID: usize = 3;

/// A biaxial test.
#[derive(Clone, Debug)]
pub struct BiaxialSpec {
    /// Preparation: grains, sizes, areal density ρ t, deposition laws (with gravity); its
    /// `width` is the sample's, its `relax` is not used.
    pub column: ColumnSpec,
    /// The material's contact laws (the grains' and, for the walls' stiffness and
    /// restitution, the walls'); gravity is ignored.
    pub material: DemParams,
    /// Axial length t of the disks (m): forces per disk over t are forces per unit length.
    pub thickness: f64,
    /// Confining stress σ₃ (Pa).
    pub confining: f64,
    /// Inertial number I of the shear, setting ε̇ = I/(d̄ √(ρ_s/σ₃)).
    pub inertial_number: f64,
    /// Axial strain at which the test ends.
    pub final_strain: f64,
    /// Axial strain between two recorded points.
    pub record_strain: f64,
}

/// One recorded state: forces averaged over the piston intervals since the previous record.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct BiaxialPoint {
    /// Axial strain ε₁ = 1 − H/H₀.
    pub axial_strain: f64,
    /// Volumetric strain ε_v = 1 − WH/(W₀H₀) (compression positive).
    pub volumetric_strain: f64,
    /// Axial stress σ₁ (Pa), from the lid.
    pub sigma_1: f64,
    /// Axial stress from the floor (Pa): equal to `sigma_1` in a quasi-static test.
    pub sigma_1_base: f64,
    /// Lateral stress σ₃ (Pa), from the right wall.
    pub sigma_3: f64,
    /// Mobilised friction sin φ = (σ₁ − σ₃)/(σ₁ + σ₃).
    pub sin_phi: f64,
    /// Solid fraction Σ πr²/(W H).
    pub packing_fraction: f64,
}

/// What a biaxial test measured.
#[derive(Clone, Debug, Serialize)]
pub struct BiaxialResult {
    /// Grains in the sample.
    pub grains: usize,
    /// Sample width and height at the start of the shear (m).
    pub width: f64,
    /// See `width`.
    pub height: f64,
    /// Solid fraction at the start of the shear.
    pub initial_packing_fraction: f64,
    /// Axial strain rate ε̇ (1/s) and lid speed (m/s).
    pub strain_rate: f64,
    /// See `strain_rate`.
    pub lid_speed: f64,
    /// Largest running mean of the mobilised sin φ over [`PEAK_POINTS`] recorded points, and
    /// the mean strain of those points.
    pub peak_sin_phi: f64,
    /// See `peak_sin_phi`.
    pub peak_strain: f64,
    /// Mean sin φ over the second half of the axial strain (the critical state), and the
    /// standard deviation of the recorded points about it.
    pub critical_sin_phi: f64,
    /// See `critical_sin_phi`.
    pub critical_sin_phi_sd: f64,
    /// Peak and critical-state friction angles (degrees).
    pub peak_phi_deg: f64,
    /// See `peak_phi_deg`.
    pub critical_phi_deg: f64,
    /// Mean solid fraction over the second half of the axial strain.
    pub critical_packing_fraction: f64,
    /// Mean σ₃ over the second half (Pa): the confining stress held by the piston.
    pub critical_sigma_3: f64,
    /// (mean σ₁ at the lid − at the floor)/(mean σ₁ at the lid) over the second half: the
    /// sample's inertia, small in a quasi-static test.
    pub lid_floor_difference: f64,
    /// Simulated time of the preparation and of the shear (s), DEM steps in all.
    pub preparation_time: f64,
    /// See `preparation_time`.
    pub shear_time: f64,
    /// See `preparation_time`.
    pub steps: u64,
    /// The recorded curve.
    pub points: Vec<BiaxialPoint>,
}

impl BiaxialResult {
    /// One line with the friction angles, the densities, σ₃ held and the quasi-static check.
    pub fn done_line(&self) -> String {
        let end = self.points.last().map_or(f64::NAN, |p| p.volumetric_strain);
        format!(
            "critical-state φ = {:.2}° (sin φ = {:.4} ± {:.4}), peak φ = {:.2}° at ε₁ = {:.3}, \
             packing {:.4} → {:.4}, ε_v(end) = {:.4}, σ₃ held at {:.1} Pa, lid − floor σ₁ \
             {:.1e}, ε̇ = {:.3} 1/s, {} steps",
            self.critical_phi_deg,
            self.critical_sin_phi,
            self.critical_sin_phi_sd,
            self.peak_phi_deg,
            self.peak_strain,
            self.initial_packing_fraction,
            self.critical_packing_fraction,
            end,
            self.critical_sigma_3,
            self.lid_floor_difference,
            self.strain_rate,
            self.steps
        )
    }
}

/// Normal force on each wall (N) from the last force evaluation.
fn wall_forces(dem: &Dem) -> [f64; 4] {
    let mut f = [0.0; 4];
    let wl = dem.wall_pairs();
    for p in 0..wl.grain.len() {
        let st = &wl.state[p];
        if st.touching() {
            f[wl.wall[p] as usize] += st.f_n;
        }
    }
    f
}

/// Wall position: the right wall's x or the lid's y.
fn wall_coordinate(w: &Wall) -> f64 {
    match *w {
        Wall::Plane { point, normal } => {
            if normal[0] != 0.0 {
                point[0]
            } else {
                point[1]
            }
        }
        _ => f64::NAN,
    }
}

/// A wall moved by the balance of its contact force and a target force.
#[derive(Clone, Copy, Default)]
struct Piston {
    /// Velocity away from the grains (m/s).
    velocity: f64,
}

impl Piston {
    /// Velocity for the next `interval` seconds of a piston of mass `mass` with contact force
    /// `f` and target `target` (N), capped at `v_max`.
    fn velocity(&mut self, f: f64, target: f64, mass: f64, interval: f64, v_max: f64) -> f64 {
        self.velocity = (self.velocity + interval * (f - target) / mass).clamp(-v_max, v_max);
        self.velocity
    }
}

/// The sample between its walls, with its pistons.
struct Sample {
    dem: Dem,
    thickness: f64,
    solid_area: f64,
    /// Mass of each piston (kg): a tenth of the sample's, or what stability needs.
    mass: f64,
    /// Pistons of the right wall and the lid.
    piston: [Piston; 2],
}

impl Sample {
    fn width(&self) -> f64 {
        wall_coordinate(&self.dem.walls[RIGHT])
    }
    fn height(&self) -> f64 {
        wall_coordinate(&self.dem.walls[LID])
    }

    /// Run one piston interval with the right wall (and, if `lid_target` is given, the lid)
    /// driven towards the stresses; otherwise the lid moves at `lid_speed` (down > 0).
    /// Returns σ₁ (lid), σ₃ and σ₁ (floor) at the end of the interval.
    fn interval(
        &mut self,
        sigma_3: f64,
        lid_target: Option<f64>,
        lid_speed: f64,
        v_max: f64,
    ) -> Result<[f64; 3]> {
        let f = wall_forces(&self.dem);
        let (w, h, t) = (self.width(), self.height(), self.thickness);
        let span = PISTON_STEPS as f64 * self.dem.dt();
        let m = self.mass;
        let vr = self.piston[0].velocity(f[RIGHT], sigma_3 * h * t, m, span, v_max);
        let vl = match lid_target {
            Some(s1) => self.piston[1].velocity(f[LID], s1 * w * t, m, span, v_max),
            None => -lid_speed,
        };
        self.dem.set_wall_velocity(RIGHT, [vr, 0.0])?;
        self.dem.set_wall_velocity(LID, [0.0, vl])?;
        self.dem.steps(PISTON_STEPS);
        let f = wall_forces(&self.dem);
        let (w, h) = (self.width(), self.height());
        if !(w.is_finite() && h.is_finite() && f.iter().all(|v| v.is_finite())) {
            return Err(Error::Other(format!(
                "biaxial test unstable at t = {:.4e} s: a wall force or position is not finite",
                self.dem.time()
            )));
        }
        Ok([f[LID] / (w * t), f[RIGHT] / (h * t), f[FLOOR] / (w * t)])
    }

    /// Bring the sample to rest at σ₃ on the right wall and the lid: run piston intervals
    /// until, over a block of them, both mean stresses are within 1 % of σ₃ and the kinetic
    /// energy of the load-carrying grains ([`Dem::loaded_kinetic_energy`]) is below
    /// 1e-7 σ₃ d̄² t per grain. Rattlers are left out: a grain with no contact spinning freely
    /// holds its energy for ever (seen: one such grain held 84 % of a 1000-grain sample's
    /// kinetic energy, 1.6× the threshold, while the wall stresses were at σ₃ to 0.01 %).
    fn consolidate(&mut self, sigma_3: f64, d_mean: f64, v_max: f64, max_time: f64) -> Result<()> {
        let rest = 1e-7 * sigma_3 * d_mean * d_mean * self.thickness * self.dem.grains.len() as f64;
        let block = 50;
        let start = self.dem.time();
        while self.dem.time() - start < max_time {
            let mut mean = [0.0; 2];
            for _ in 0..block {
                let s = self.interval(sigma_3, Some(sigma_3), 0.0, v_max)?;
                mean[0] += s[0] / block as f64;
                mean[1] += s[1] / block as f64;
            }
            let close = mean.iter().all(|s| (s / sigma_3 - 1.0).abs() < 0.01);
            if close && self.dem.loaded_kinetic_energy() < rest {
                self.dem.set_wall_velocity(RIGHT, [0.0; 2])?;
                self.dem.set_wall_velocity(LID, [0.0; 2])?;
                self.piston[1] = Piston::default();
                return Ok(());
            }
        }
        Err(Error::Other(format!(
            "biaxial sample did not come to rest at σ₃ = {sigma_3} Pa within {max_time} s"
        )))
    }

    fn packing_fraction(&self) -> f64 {
        self.solid_area / (self.width() * self.height())
    }
}

impl BiaxialSpec {
    /// The test of a collapse scenario's material: its grains, contact laws and deposition
    /// (friction `prep_friction`, the scenario's deposition friction if `None`), `grains` of
    /// them in a sample about half as wide as high, drawn from `seed` (the scenario's if
    /// `None`).
    pub fn from_scenario(
        s: &DemScenario,
        grains: usize,
        confining: f64,
        inertial_number: f64,
        final_strain: f64,
        prep_friction: Option<f64>,
        seed: Option<u64>,
    ) -> Result<Self> {
        let d = s.derive()?;
        let mut column = d.column;
        column.seed = seed.unwrap_or(column.seed);
        if let Some(mu) = prep_friction {
            if !(mu >= 0.0 && mu.is_finite()) {
                return Err(Error::config(
                    "biaxial.prep_friction",
                    format!("must be ≥ 0, got {mu}"),
                ));
            }
            column.params = with_friction(&column.params, mu);
        }
        if grains < 100 {
            return Err(Error::config(
                "biaxial.grains",
                format!("need at least 100 grains, got {grains}"),
            ));
        }
        // Mean disk area π d_min d_max/4 for a size distribution uniform by area (the mean
        // of d² is d_min d_max), a little more for one uniform in number: either way the
        // sample comes out roughly 1 : 2 at φ ≈ 0.8.
        let area = 0.25 * std::f64::consts::PI * s.grains.d_min * s.grains.d_max;
        column.x0 = 0.0;
        column.grains = grains;
        column.width = (grains as f64 * area / (0.8 * 2.0)).sqrt();
        Ok(BiaxialSpec {
            column,
            material: d.params,
            thickness: s.grains.thickness,
            confining,
            inertial_number,
            final_strain,
            record_strain: 0.0025,
        })
    }
}

/// Run the test and write `biaxial.csv` (the curve), `summary.json` (the result) and
/// `biaxial.svg` (mobilised sin φ and ε_v against ε₁) into `out_dir`.
pub fn run_biaxial_to(
    spec: &BiaxialSpec,
    out_dir: &Path,
    progress: crate::exec::Progress,
) -> Result<BiaxialResult> {
    let r = run_biaxial(spec, progress)?;
    write_biaxial(&r, spec.confining, spec.final_strain, out_dir)?;
    Ok(r)
}

/// Write a test's `biaxial.csv`, `summary.json` and `biaxial.svg` into `out_dir` (the wall
/// test's and the periodic volume's alike).
pub fn write_biaxial(
    r: &BiaxialResult,
    confining: f64,
    final_strain: f64,
    out_dir: &Path,
) -> Result<()> {
    crate::io::run_dir::create(out_dir)?;
    let mut csv = CsvWriter::create(
        &out_dir.join("biaxial.csv"),
        &[
            "axial_strain",
            "volumetric_strain",
            "sigma_1",
            "sigma_1_base",
            "sigma_3",
            "sin_phi",
            "packing_fraction",
        ],
    )?;
    for p in &r.points {
        csv.row(&[
            p.axial_strain,
            p.volumetric_strain,
            p.sigma_1,
            p.sigma_1_base,
            p.sigma_3,
            p.sin_phi,
            p.packing_fraction,
        ])?;
    }
    write_json(&out_dir.join("summary.json"), &r)?;
    let mut plot = Plot::new(
        "biaxial",
        &format!(
            "biaxial test, σ₃ = {:.0} Pa: critical φ = {:.1}°, peak {:.1}°",
            confining, r.critical_phi_deg, r.peak_phi_deg
        ),
        "axial strain ε₁",
        "sin φ mobilised, volumetric strain ε_v",
    );
    let curve = |f: fn(&BiaxialPoint) -> f64| -> Vec<(f64, f64)> {
        r.points.iter().map(|p| (p.axial_strain, f(p))).collect()
    };
    plot.series.push(Series::line(
        "sin φ = (σ₁ − σ₃)/(σ₁ + σ₃)",
        curve(|p| p.sin_phi),
    ));
    plot.series.push(Series::line(
        "ε_v (compression > 0)",
        curve(|p| p.volumetric_strain),
    ));
    let e_end = r.points.last().map_or(final_strain, |p| p.axial_strain);
    plot.series.push(Series::line(
        "critical state (mean over the second half)",
        vec![
            (0.5 * final_strain, r.critical_sin_phi),
            (e_end, r.critical_sin_phi),
        ],
    ));
    write_svg(&plot, &out_dir.join("biaxial.svg"))
}

/// Run the test: preparation, consolidation at σ₃, shear to `final_strain`; `progress` gets
/// (recorded points, points in all).
pub fn run_biaxial(spec: &BiaxialSpec, progress: crate::exec::Progress) -> Result<BiaxialResult> {
    for (field, v) in [
        ("biaxial.confining", spec.confining),
        ("biaxial.inertial_number", spec.inertial_number),
        ("biaxial.final_strain", spec.final_strain),
        ("biaxial.record_strain", spec.record_strain),
        ("biaxial.thickness", spec.thickness),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            return Err(Error::config(field, format!("must be > 0, got {v}")));
        }
    }
    if spec.final_strain >= 0.5 {
        return Err(Error::config(
            "biaxial.final_strain",
            format!("must be below 0.5, got {}", spec.final_strain),
        ));
    }
    let column = deposit_column(&ColumnSpec {
        relax: None,
        ..spec.column.clone()
    })?;
    let mut g = column.grains;
    let n = g.len();
    let solid_area = g.area();
    let d_mean = 2.0 * g.radius.iter().sum::<f64>() / n as f64;
    let sample_mass: f64 = g.mass.iter().sum();
    let rho_s = spec.column.density / spec.thickness;
    let strain_rate = spec.inertial_number / (d_mean * (rho_s / spec.confining).sqrt());
    let width = spec.column.width;
    let x0 = spec.column.x0;
    for x in g.x.iter_mut() {
        *x -= x0;
    }
    let walls = vec![
        Wall::floor(0.0),
        Wall::left(0.0),
        Wall::right(width),
        Wall::Plane {
            point: [0.0, column.height],
            normal: [0.0, -1.0],
        },
    ];
    let frictionless = |p: &ContactParams| ContactParams {
        friction: 0.0,
        rolling_friction: 0.0,
        ..*p
    };
    // Consolidation and shear run without gravity and without a sedimentation's drag (a
    // deposition device, `deposition.settling_velocity`: it would hold the pistons' approach
    // back so that the sample never counts as at rest).
    let no_gravity = |p: &DemParams| {
        let mut q = p.clone();
        q.gravity = [0.0; 2];
        q.global_damping = 0.0;
        q.wall = frictionless(&spec.material.wall);
        q
    };
    let dem = Dem::new(g, walls, no_gravity(&spec.column.params))?;
    // Piston mass: a tenth of the sample's, but enough that the explicit update is stable
    // against the stiffness of a wall's contacts (k_n for each of up to H/d_min grains along
    // it): ω K Δt ≤ 1 with ω = √(k_n H/(d_min M)).
    let span = PISTON_STEPS as f64 * dem.dt();
    let contacts = column.height / spec.column.diameter[0];
    let mass = (0.1 * sample_mass).max(spec.material.wall.k_n * contacts * span * span);
    let mut sample = Sample {
        dem,
        thickness: spec.thickness,
        solid_area,
        mass,
        piston: [Piston::default(); 2],
    };
    // Consolidation: the lid starts at the top of the deposit, a fraction of a grain away at
    // most, so the walls need not travel far; their speed is capped at the shear's lid speed,
    // or at that of I = 1e-3 for a faster shear (so that the sample can come to rest).
    let v_max = strain_rate
        * (CONSOLIDATION_INERTIAL_NUMBER / spec.inertial_number).min(1.0)
        * column.height;
    let settle = 50.0 * d_mean / v_max;
    sample.consolidate(spec.confining, d_mean, v_max, settle)?;
    let (prep_time, prep_steps) = (sample.dem.time(), sample.dem.step_count());
    let walls = sample.dem.walls.clone();
    let mut grains = sample.dem.grains.clone();
    grains.stop();
    sample.dem = Dem::new(grains, walls, no_gravity(&spec.material))?;
    sample.piston = [Piston::default(); 2];
    sample.consolidate(spec.confining, d_mean, v_max, settle)?;

    // Shear.
    let (w0, h0) = (sample.width(), sample.height());
    let initial_packing_fraction = sample.packing_fraction();
    let lid_speed = strain_rate * h0;
    let shear_start = sample.dem.time();
    let mut points = Vec::new();
    let (mut acc, mut count) = ([0.0; 3], 0usize);
    let mut next_record = spec.record_strain;
    loop {
        let s = sample.interval(spec.confining, None, lid_speed, 10.0 * lid_speed)?;
        for (a, v) in acc.iter_mut().zip(s) {
            *a += v;
        }
        count += 1;
        let (w, h) = (sample.width(), sample.height());
        let e1 = 1.0 - h / h0;
        if e1 >= next_record {
            progress(
                (e1 / spec.record_strain) as u64,
                (spec.final_strain / spec.record_strain) as u64,
            );
            let [s1, s3, s1_base] = acc.map(|a| a / count as f64);
            points.push(BiaxialPoint {
                axial_strain: e1,
                volumetric_strain: 1.0 - w * h / (w0 * h0),
                sigma_1: s1,
                sigma_1_base: s1_base,
                sigma_3: s3,
                sin_phi: (s1 - s3) / (s1 + s3),
                packing_fraction: sample.packing_fraction(),
            });
            (acc, count) = ([0.0; 3], 0);
            next_record += spec.record_strain;
        }
        if e1 >= spec.final_strain {
            break;
        }
    }
    let shear_time = sample.dem.time() - shear_start;
    let c = Curve::of(&points, spec.final_strain);
    Ok(BiaxialResult {
        grains: n,
        width: w0,
        height: h0,
        initial_packing_fraction,
        strain_rate,
        lid_speed,
        peak_sin_phi: c.peak_sin_phi,
        peak_strain: c.peak_strain,
        critical_sin_phi: c.critical_sin_phi,
        critical_sin_phi_sd: c.critical_sin_phi_sd,
        peak_phi_deg: c.peak_sin_phi.asin().to_degrees(),
        critical_phi_deg: c.critical_sin_phi.asin().to_degrees(),
        critical_packing_fraction: c.critical_packing_fraction,
        critical_sigma_3: c.critical_sigma_3,
        lid_floor_difference: c.lid_floor_difference,
        preparation_time: prep_time + shear_start,
        shear_time,
        steps: prep_steps + sample.dem.step_count(),
        points,
    })
}

/// What a recorded curve gives: the peak (largest running mean of sin φ over [`PEAK_POINTS`]
/// records, so that one stick-slip spike does not set it) and the critical state (means over
/// the second half of the axial strain).
#[derive(Clone, Copy, Debug)]
pub struct Curve {
    /// Peak sin φ and the mean strain of its records.
    pub peak_sin_phi: f64,
    /// See `peak_sin_phi`.
    pub peak_strain: f64,
    /// Mean sin φ over the second half, and the standard deviation of the records about it.
    pub critical_sin_phi: f64,
    /// See `critical_sin_phi`.
    pub critical_sin_phi_sd: f64,
    /// Mean solid fraction and σ₃ over the second half.
    pub critical_packing_fraction: f64,
    /// See `critical_packing_fraction`.
    pub critical_sigma_3: f64,
    /// (mean σ₁ at the lid − at the floor)/(mean σ₁ at the lid) over the second half.
    pub lid_floor_difference: f64,
}

impl Curve {
    /// Read the curve of a test that ended at `final_strain`.
    pub fn of(points: &[BiaxialPoint], final_strain: f64) -> Curve {
        let (peak_strain, peak_sin_phi) = points
            .windows(PEAK_POINTS.min(points.len()).max(1))
            .map(|w| {
                let k = w.len() as f64;
                (
                    w.iter().map(|p| p.axial_strain).sum::<f64>() / k,
                    w.iter().map(|p| p.sin_phi).sum::<f64>() / k,
                )
            })
            .fold(
                (f64::NAN, f64::NEG_INFINITY),
                |a, b| if b.1 > a.1 { b } else { a },
            );
        let late: Vec<&BiaxialPoint> = points
            .iter()
            .filter(|p| p.axial_strain >= 0.5 * final_strain)
            .collect();
        let m = late.len().max(1) as f64;
        let mean = |f: fn(&BiaxialPoint) -> f64| late.iter().map(|p| f(p)).sum::<f64>() / m;
        let critical_sin_phi = mean(|p| p.sin_phi);
        let critical_sin_phi_sd = (late
            .iter()
            .map(|p| (p.sin_phi - critical_sin_phi).powi(2))
            .sum::<f64>()
            / (m - 1.0).max(1.0))
        .sqrt();
        let critical_packing_fraction = mean(|p| p.packing_fraction);
        let lid = mean(|p| p.sigma_1);
        let lid_floor_difference = (lid - mean(|p| p.sigma_1_base)) / lid;
        Curve {
            peak_sin_phi,
            peak_strain,
            critical_sin_phi,
            critical_sin_phi_sd,
            critical_packing_fraction,
            critical_sigma_3: mean(|p| p.sigma_3),
            lid_floor_difference,
        }
    }
}
