//! Convex polygon grain shapes: one shared vertex table, one shape index per grain.
//!
//! A grain is a disk ([`DISK`]) or refers to a polygon of the table by index, so many grains of
//! the same shape share one vertex list (no heap object per grain). Vertices are stored in the
//! body frame: counter-clockwise, centroid at the origin, angle 0.
//!
//! Mass properties of a simple polygon with vertices **p**_k (k = 0…n−1, **p**_n = **p**_0,
//! counter-clockwise) and areal density ρ, with c_k = x_k y_{k+1} − x_{k+1} y_k (Green's theorem;
//! e.g. Bourke, "Calculating the area and centroid of a polygon", 1988):
//!
//! * area A = ½ Σ c_k;
//! * centroid **C** = (1/6A) Σ (**p**_k + **p**_{k+1}) c_k;
//! * polar second moment about the origin
//!   J_O = (ρ/12) Σ c_k (**p**_k·**p**_k + **p**_k·**p**_{k+1} + **p**_{k+1}·**p**_{k+1}),
//!   and about the centroid J = J_O − m|**C**|² (parallel axes), m = ρA.
//!
//! Checks: square of side a, J = m a²/6; right triangle of legs a, b, J = m(a² + b²)/18.

/// Shape index of a disk.
pub const DISK: u32 = u32::MAX;

/// Mass properties of a polygon per unit areal density.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PolygonProps {
    /// Area A.
    pub area: f64,
    /// Centroid **C** of the vertices as given.
    pub centroid: [f64; 2],
    /// Polar second moment of area about the centroid, J/ρ.
    pub polar: f64,
}

/// Area, centroid and polar second moment (about the centroid, per unit density) of the simple
/// polygon `v` (counter-clockwise; a clockwise list gives a negative area).
pub fn polygon_props(v: &[[f64; 2]]) -> PolygonProps {
    let n = v.len();
    let (mut a2, mut cx, mut cy, mut j) = (0.0, 0.0, 0.0, 0.0);
    for k in 0..n {
        let (p, q) = (v[k], v[(k + 1) % n]);
        let c = p[0] * q[1] - q[0] * p[1];
        a2 += c;
        cx += (p[0] + q[0]) * c;
        cy += (p[1] + q[1]) * c;
        j +=
            c * (p[0] * p[0] + p[1] * p[1] + p[0] * q[0] + p[1] * q[1] + q[0] * q[0] + q[1] * q[1]);
    }
    let area = 0.5 * a2;
    let centroid = [cx / (3.0 * a2), cy / (3.0 * a2)];
    let polar = j / 12.0 - area * (centroid[0] * centroid[0] + centroid[1] * centroid[1]);
    PolygonProps {
        area,
        centroid,
        polar,
    }
}

/// The shared table of polygon shapes (structure of arrays).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Polygons {
    /// Vertices of all polygons, body frame (centroid at the origin), counter-clockwise.
    pub verts: Vec<[f64; 2]>,
    /// Vertices of polygon `s` are `verts[start[s]..start[s + 1]]`.
    pub start: Vec<u32>,
    /// Area of each polygon.
    pub area: Vec<f64>,
    /// Polar second moment per unit density (about the centroid) of each polygon.
    pub polar: Vec<f64>,
    /// Bounding radius (largest vertex distance from the centroid) of each polygon.
    pub bound: Vec<f64>,
}

impl Polygons {
    /// Number of polygon shapes.
    pub fn len(&self) -> usize {
        self.area.len()
    }

    /// Whether the table is empty.
    pub fn is_empty(&self) -> bool {
        self.area.is_empty()
    }

    /// Vertices of shape `s` (body frame).
    pub fn vertices(&self, s: usize) -> &[[f64; 2]] {
        &self.verts[self.start[s] as usize..self.start[s + 1] as usize]
    }

    /// Add a convex polygon given by its vertices (any position, counter-clockwise or
    /// clockwise); it is stored counter-clockwise about its centroid. Returns its shape index,
    /// or an error naming `field` if it is not a convex polygon of ≥ 3 distinct vertices.
    pub fn add(&mut self, v: &[[f64; 2]], field: &str) -> crate::Result<u32> {
        check_convex(v, field)?;
        let p = polygon_props(v);
        let mut w: Vec<[f64; 2]> = v
            .iter()
            .map(|q| [q[0] - p.centroid[0], q[1] - p.centroid[1]])
            .collect();
        if p.area < 0.0 {
            w.reverse();
        }
        // Properties of the centred list (centroid now at round-off from 0).
        let q = polygon_props(&w);
        if self.start.is_empty() {
            self.start.push(0);
        }
        let bound = w
            .iter()
            .map(|a| (a[0] * a[0] + a[1] * a[1]).sqrt())
            .fold(0.0, f64::max);
        self.verts.extend_from_slice(&w);
        self.start.push(self.verts.len() as u32);
        self.area.push(q.area);
        self.polar.push(q.polar);
        self.bound.push(bound);
        Ok((self.area.len() - 1) as u32)
    }

    /// A regular polygon of `n` vertices on a circle of radius `r`, first vertex at angle
    /// `phase` (rad).
    pub fn regular(n: usize, r: f64, phase: f64) -> Vec<[f64; 2]> {
        (0..n)
            .map(|k| {
                let a = phase + 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }
}

/// Refuse anything but a convex polygon of ≥ 3 finite vertices with non-zero area.
pub fn check_convex(v: &[[f64; 2]], field: &str) -> crate::Result<()> {
    let err = |why: String| Err(crate::Error::config(field, why));
    if v.len() < 3 {
        return err(format!("a polygon needs ≥ 3 vertices, got {}", v.len()));
    }
    if !v.iter().flatten().all(|c| c.is_finite()) {
        return err("vertices must be finite".into());
    }
    let n = v.len();
    let a = polygon_props(v).area;
    if a.abs() <= 0.0 {
        return err("polygon has zero area".into());
    }
    let scale = v
        .iter()
        .map(|p| p[0].abs().max(p[1].abs()))
        .fold(0.0, f64::max);
    for k in 0..n {
        let (p, q, r) = (v[k], v[(k + 1) % n], v[(k + 2) % n]);
        let cross = (q[0] - p[0]) * (r[1] - q[1]) - (q[1] - p[1]) * (r[0] - q[0]);
        if cross * a.signum() <= 1e-12 * scale * scale {
            return err(format!(
                "polygon is not strictly convex at vertex {} (vertices in order, no collinear or repeated points)",
                (k + 1) % n
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Square of side a: A = a², J = m a²/6 (m = ρA, ρ = 1): exact to round-off.
    #[test]
    fn square_mass_and_inertia() {
        let a = 0.3;
        let mut t = Polygons::default();
        // Off-centre and clockwise: the table centres and re-orders it.
        let s = t
            .add(
                &[
                    [1.0, 2.0],
                    [1.0, 2.0 + a],
                    [1.0 + a, 2.0 + a],
                    [1.0 + a, 2.0],
                ],
                "sq",
            )
            .unwrap() as usize;
        let m = t.area[s];
        assert!((m - a * a).abs() < 1e-15);
        assert!((t.polar[s] - m * a * a / 6.0).abs() < 1e-15 * m * a * a);
        assert!((t.bound[s] - a / 2f64.sqrt()).abs() < 1e-15);
        let c = polygon_props(t.vertices(s)).centroid;
        assert!(c[0].abs() < 1e-15 && c[1].abs() < 1e-15);
    }

    /// Right triangle of legs a, b: A = ab/2, centroid (a/3, b/3), J = m(a² + b²)/18.
    #[test]
    fn triangle_mass_and_inertia() {
        let (a, b) = (2.0, 0.5);
        let p = polygon_props(&[[0.0, 0.0], [a, 0.0], [0.0, b]]);
        assert!((p.area - 0.5 * a * b).abs() < 1e-15);
        assert!((p.centroid[0] - a / 3.0).abs() < 1e-15 && (p.centroid[1] - b / 3.0).abs() < 1e-15);
        let m = p.area;
        assert!((p.polar - m * (a * a + b * b) / 18.0).abs() < 1e-14 * m * (a * a + b * b));
        // Equilateral triangle of side s: J = m s²/12.
        let s = 1.7;
        let v = Polygons::regular(3, s / 3f64.sqrt(), 0.3);
        let q = polygon_props(&v);
        assert!((q.polar - q.area * s * s / 12.0).abs() < 1e-13 * q.area * s * s);
    }

    #[test]
    fn refuses_non_convex() {
        let mut t = Polygons::default();
        let e = t
            .add(
                &[[0.0, 0.0], [2.0, 0.0], [1.0, 0.2], [2.0, 2.0], [0.0, 2.0]],
                "dem.shape",
            )
            .unwrap_err();
        assert!(e.to_string().contains("dem.shape"), "{e}");
        assert!(t.add(&[[0.0, 0.0], [1.0, 0.0]], "x").is_err());
        assert!(t.add(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], "x").is_err());
    }
}
