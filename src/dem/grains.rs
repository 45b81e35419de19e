//! Grains as a structure of arrays: one `Vec<f64>` per field, index `i` is grain `i`.
//!
//! Disks of radius R and mass m (per unit depth when the scenario is 2-D plane; any consistent
//! mass unit otherwise) with moment of inertia J = ½ m R² (solid disk). The equations of motion
//! are seed eq. 5.55–5.57: m a = F_c + F_f + m g − c v, J θ̈ = T_c + T_f.

use super::shape::{Polygons, DISK};

/// Grains (disks or convex polygons), structure of arrays.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Grains {
    /// Centre x (m).
    pub x: Vec<f64>,
    /// Centre y (m).
    pub y: Vec<f64>,
    /// Velocity x (m/s).
    pub vx: Vec<f64>,
    /// Velocity y (m/s).
    pub vy: Vec<f64>,
    /// Rotation angle θ (rad, counter-clockwise).
    pub angle: Vec<f64>,
    /// Angular velocity ω = θ̇ (rad/s, counter-clockwise).
    pub omega: Vec<f64>,
    /// Radius R (m).
    pub radius: Vec<f64>,
    /// Mass m.
    pub mass: Vec<f64>,
    /// Moment of inertia J = ½ m R².
    pub inertia: Vec<f64>,
    /// Total force x of the last force evaluation (contacts, gravity, external, damping).
    pub fx: Vec<f64>,
    /// Total force y of the last force evaluation.
    pub fy: Vec<f64>,
    /// Total torque of the last force evaluation.
    pub torque: Vec<f64>,
    /// Shape of each grain: [`DISK`] or an index into [`Grains::polygons`].
    pub shape: Vec<u32>,
    /// Shared table of polygon shapes (empty for an all-disk system).
    pub polygons: Polygons,
}

impl Grains {
    /// No grains.
    pub fn new() -> Self {
        Self::default()
    }

    /// Room for `n` grains without reallocation.
    pub fn with_capacity(n: usize) -> Self {
        let v = || Vec::with_capacity(n);
        Grains {
            x: v(),
            y: v(),
            vx: v(),
            vy: v(),
            angle: v(),
            omega: v(),
            radius: v(),
            mass: v(),
            inertia: v(),
            fx: v(),
            fy: v(),
            torque: v(),
            shape: Vec::with_capacity(n),
            polygons: Polygons::default(),
        }
    }

    /// Number of grains.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are no grains.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Append a disk at rest with centre (x, y), radius `r` and mass `m`; J = ½ m r².
    /// Returns its index.
    pub fn push(&mut self, x: f64, y: f64, r: f64, m: f64) -> usize {
        self.x.push(x);
        self.y.push(y);
        self.vx.push(0.0);
        self.vy.push(0.0);
        self.angle.push(0.0);
        self.omega.push(0.0);
        self.radius.push(r);
        self.mass.push(m);
        self.inertia.push(0.5 * m * r * r);
        self.fx.push(0.0);
        self.fy.push(0.0);
        self.torque.push(0.0);
        self.shape.push(DISK);
        self.x.len() - 1
    }

    /// Append a convex polygon grain of shape `s` (index into [`Grains::polygons`]) with its
    /// centroid at (x, y), rotated by `angle`, of areal density `rho`: m = ρA, J = ρJ_A,
    /// R = bounding radius. Returns its index.
    pub fn push_polygon(&mut self, x: f64, y: f64, angle: f64, s: u32, rho: f64) -> usize {
        let p = &self.polygons;
        let (m, j, r) = (
            rho * p.area[s as usize],
            rho * p.polar[s as usize],
            p.bound[s as usize],
        );
        let i = self.push(x, y, r, m);
        self.inertia[i] = j;
        self.angle[i] = angle;
        self.shape[i] = s;
        i
    }

    /// Whether grain `i` is a disk.
    #[inline(always)]
    pub fn is_disk(&self, i: usize) -> bool {
        self.shape.get(i).is_none_or(|&s| s == DISK)
    }

    /// Vertices of polygon grain `i` in the world frame, **x**_i + R(θ_i) **v**_k (body-frame
    /// vertices **v**_k of its shape, in order); none for a disk.
    pub fn world_vertices(&self, i: usize) -> impl Iterator<Item = [f64; 2]> + '_ {
        let body: &[[f64; 2]] = if self.is_disk(i) {
            &[]
        } else {
            self.polygons.vertices(self.shape[i] as usize)
        };
        let (sin, cos) = self.angle[i].sin_cos();
        let (x, y) = (self.x[i], self.y[i]);
        body.iter()
            .map(move |v| [x + cos * v[0] - sin * v[1], y + sin * v[0] + cos * v[1]])
    }

    /// Area of grain `i` (m², or m² per unit depth): πR² for a disk, its shape's area for a
    /// polygon.
    pub fn grain_area(&self, i: usize) -> f64 {
        if self.is_disk(i) {
            std::f64::consts::PI * self.radius[i] * self.radius[i]
        } else {
            self.polygons.area[self.shape[i] as usize]
        }
    }

    /// Largest x and y reached by grain `i`: the centre plus R for a disk, the largest vertex
    /// coordinates for a polygon.
    pub fn upper_extent(&self, i: usize) -> [f64; 2] {
        if self.is_disk(i) {
            return [self.x[i] + self.radius[i], self.y[i] + self.radius[i]];
        }
        self.world_vertices(i).fold([f64::NEG_INFINITY; 2], |m, v| {
            [m[0].max(v[0]), m[1].max(v[1])]
        })
    }

    /// Whether some grain is a polygon.
    pub fn has_polygons(&self) -> bool {
        self.shape.iter().any(|&s| s != DISK)
    }

    /// Append a disk of areal density `rho` (mass per unit area, so m = ρ π r²).
    pub fn push_disk(&mut self, x: f64, y: f64, r: f64, rho: f64) -> usize {
        self.push(x, y, r, rho * std::f64::consts::PI * r * r)
    }

    /// Smallest grain mass (∞ if empty).
    pub fn min_mass(&self) -> f64 {
        self.mass.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// Smallest moment of inertia (∞ if empty).
    pub fn min_inertia(&self) -> f64 {
        self.inertia.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// Largest radius (0 if empty).
    pub fn max_radius(&self) -> f64 {
        self.radius.iter().copied().fold(0.0, f64::max)
    }

    /// Bring every grain to rest: velocities and angular velocities set to 0.
    pub fn stop(&mut self) {
        self.vx
            .iter_mut()
            .chain(self.vy.iter_mut())
            .chain(self.omega.iter_mut())
            .for_each(|v| *v = 0.0);
    }

    /// Total linear momentum Σ m v.
    pub fn momentum(&self) -> [f64; 2] {
        let mut p = [0.0; 2];
        for i in 0..self.len() {
            p[0] += self.mass[i] * self.vx[i];
            p[1] += self.mass[i] * self.vy[i];
        }
        p
    }

    /// Keep the grains whose entry of `keep` is true, in their order (the polygon table is
    /// unchanged). `keep` has one entry per grain.
    pub fn retain(&mut self, keep: &[bool]) {
        assert_eq!(keep.len(), self.len(), "one keep flag per grain");
        for v in [
            &mut self.x,
            &mut self.y,
            &mut self.vx,
            &mut self.vy,
            &mut self.angle,
            &mut self.omega,
            &mut self.radius,
            &mut self.mass,
            &mut self.inertia,
            &mut self.fx,
            &mut self.fy,
            &mut self.torque,
        ] {
            compact(v, keep);
        }
        compact(&mut self.shape, keep);
    }

    /// Total grain area: Σ π R² over disks plus the polygons' areas.
    pub fn area(&self) -> f64 {
        (0..self.len()).map(|i| self.grain_area(i)).sum()
    }
}

/// Keep the entries of `v` whose flag in `keep` is true, in order.
pub(crate) fn compact<T: Copy>(v: &mut Vec<T>, keep: &[bool]) {
    let mut k = 0;
    for i in 0..v.len() {
        if keep[i] {
            v[k] = v[i];
            k += 1;
        }
    }
    v.truncate(k);
}
