//! VTK XML output: `.vti` images (the LBM lattice, MPM grid) and `.vtu` point and line sets
//! (DEM grains, material points, contact force chains).
//!
//! Files are little-endian VTK XML with the data arrays in the *appended raw binary* section
//! (`header_type="UInt64"`), compressed by zlib (the default) or LZ4, or not at all, and
//! with floating-point values as `Float64` (exact, the default) or `Float32`: see
//! [`VtkFormat`], the `[vtk]` table of a scenario. VTK and ParaView read all of them
//! directly. 2-D data is embedded in 3-D: points get `z = 0` and vectors a zero third
//! component, as ParaView expects.

use std::collections::HashSet;
use std::path::Path;

use super::pvd::xml_escape;
use super::vtk_appended::Body;
pub use super::vtk_appended::{Compression, Precision, VtkFormat};
use crate::{Error, Result};

/// A uniform 2-D grid of `nx` × `ny` cells.
///
/// Cell `(i, j)` spans `[origin[0] + i·spacing[0], origin[0] + (i+1)·spacing[0]]` ×
/// `[origin[1] + j·spacing[1], origin[1] + (j+1)·spacing[1]]`; the grid has
/// `(nx + 1) × (ny + 1)` points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageGrid {
    /// Number of cells along x.
    pub nx: usize,
    /// Number of cells along y.
    pub ny: usize,
    /// Coordinates of the lower-left corner of cell `(0, 0)`.
    pub origin: [f64; 2],
    /// Cell size along x and y.
    pub spacing: [f64; 2],
}

impl ImageGrid {
    /// Number of cells, `nx · ny`.
    pub fn num_cells(&self) -> usize {
        self.nx * self.ny
    }
}

/// The values of one output field.
#[derive(Clone, Copy, Debug)]
pub enum FieldData<'a> {
    /// One value per cell (or point).
    Scalar(&'a [f64]),
    /// One 2-D vector per cell (or point); written with three components, `z = 0`.
    Vector(&'a [[f64; 2]]),
    /// One 2 × 2 tensor per cell (or point), row-major `[xx, xy, yx, yy]`; written as a 3 × 3
    /// tensor (nine components) with the z row and column zero.
    Tensor(&'a [[f64; 4]]),
}

impl FieldData<'_> {
    /// Number of elements (cells or points) the field covers.
    pub fn len(&self) -> usize {
        match self {
            FieldData::Scalar(v) => v.len(),
            FieldData::Vector(v) => v.len(),
            FieldData::Tensor(v) => v.len(),
        }
    }

    /// Whether the field has no elements.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A named output field, e.g. `Field { name: "velocity", data: FieldData::Vector(&u) }`.
#[derive(Clone, Copy, Debug)]
pub struct Field<'a> {
    /// Array name shown in ParaView. Must be non-empty and unique within one call.
    pub name: &'a str,
    /// The values.
    pub data: FieldData<'a>,
}

impl<'a> Field<'a> {
    /// A scalar field.
    pub fn scalar(name: &'a str, values: &'a [f64]) -> Self {
        Field {
            name,
            data: FieldData::Scalar(values),
        }
    }

    /// A 2-D vector field.
    pub fn vector(name: &'a str, values: &'a [[f64; 2]]) -> Self {
        Field {
            name,
            data: FieldData::Vector(values),
        }
    }

    /// A 2 × 2 tensor field, row-major `[xx, xy, yx, yy]`.
    pub fn tensor(name: &'a str, values: &'a [[f64; 4]]) -> Self {
        Field {
            name,
            data: FieldData::Tensor(values),
        }
    }
}

/// Checks the lengths and names of `fields` (`what` is "cell" or "point"; `n` values each).
fn check_fields(path: &Path, what: &str, fields: &[Field], n: usize) -> Result<()> {
    let mut seen = HashSet::new();
    for f in fields {
        let bad = |reason: String| Err(Error::Other(format!("{}: {reason}", path.display())));
        if f.name.is_empty() {
            return bad(format!("a {what} field has an empty name"));
        }
        if !seen.insert(f.name) {
            return bad(format!("{what} field `{}` is given twice", f.name));
        }
        if f.data.len() != n {
            return bad(format!(
                "{what} field `{}` has {} values, expected {n} (one per {what})",
                f.name,
                f.data.len()
            ));
        }
    }
    Ok(())
}

/// Appends `fields` as the `PointData` or `CellData` element (`element`) of a piece, the
/// first scalar, vector and tensor field marked active.
fn write_fields(body: &mut Body, element: &str, fields: &[Field]) {
    let mut active = String::new();
    for (attr, kind) in [("Scalars", 0), ("Vectors", 1), ("Tensors", 2)] {
        let first = fields.iter().find(|f| {
            matches!(
                (kind, f.data),
                (0, FieldData::Scalar(_)) | (1, FieldData::Vector(_)) | (2, FieldData::Tensor(_))
            )
        });
        if let Some(f) = first {
            active.push_str(&format!(" {attr}=\"{}\"", xml_escape(f.name)));
        }
    }
    body.tag(3, &format!("<{element}{active}>"));
    for f in fields {
        let (name, d) = (f.name, 4);
        match f.data {
            FieldData::Scalar(v) => body.reals(d, name, 1, v.iter().copied()),
            FieldData::Vector(v) => {
                body.reals(d, name, 3, v.iter().flat_map(|&[x, y]| [x, y, 0.0]));
            }
            FieldData::Tensor(v) => {
                let t = v
                    .iter()
                    .flat_map(|&[xx, xy, yx, yy]| [xx, xy, 0.0, yx, yy, 0.0, 0.0, 0.0, 0.0]);
                body.reals(d, name, 9, t);
            }
        }
    }
    body.tag(3, &format!("</{element}>"));
}

/// Writes `body` (data set `kind`) to `path` through [`write_atomic`](super::write_atomic).
fn write_body(path: &Path, kind: &str, body: Body) -> Result<()> {
    super::write_atomic(path, |w| body.finish(kind, w))
}

/// Writes a VTK XML ImageData file (`.vti`) for `grid`, with `cell_fields` as CELL data.
///
/// Each field holds `nx · ny` values indexed row-major with x fastest: cell `(i, j)` is at
/// `j · nx + i`. The whole extent is `0 nx 0 ny 0 0` in points. Scalar fields get one
/// component, vector fields three (`z = 0`), tensors nine; the first of each is marked active.
/// Origin and spacing are written in full (`{:e}`, shortest round-trip form).
///
/// Returns [`Error::Other`] naming the field if a field does not have `nx · ny` values, if two
/// fields share a name, or if the grid is empty or has a non-positive or non-finite spacing.
/// The file is written atomically.
pub fn write_vti(
    path: &Path,
    grid: &ImageGrid,
    cell_fields: &[Field],
    format: &VtkFormat,
) -> Result<()> {
    let bad = |reason: String| Err(Error::Other(format!("{}: {reason}", path.display())));
    if grid.nx == 0 || grid.ny == 0 {
        return bad(format!(
            "image grid has no cells ({} x {})",
            grid.nx, grid.ny
        ));
    }
    if i32::try_from(grid.nx).is_err() || i32::try_from(grid.ny).is_err() {
        return bad(format!(
            "image grid {} x {} is too large for VTK extents",
            grid.nx, grid.ny
        ));
    }
    if !grid.spacing.iter().all(|d| d.is_finite() && *d > 0.0)
        || !grid.origin.iter().all(|o| o.is_finite())
    {
        return bad(format!(
            "image grid origin {:?} / spacing {:?} must be finite and the spacing positive",
            grid.origin, grid.spacing
        ));
    }
    check_fields(path, "cell", cell_fields, grid.num_cells())?;
    let extent = format!("0 {} 0 {} 0 0", grid.nx, grid.ny);
    let [ox, oy] = grid.origin;
    let [dx, dy] = grid.spacing;
    let attrs =
        format!(" WholeExtent=\"{extent}\" Origin=\"{ox:e} {oy:e} 0\" Spacing=\"{dx:e} {dy:e} 1\"");
    let mut body = Body::new(*format, IMAGE, &attrs);
    body.tag(2, &format!("<Piece Extent=\"{extent}\">"));
    body.tag(3, "<PointData/>");
    write_fields(&mut body, "CellData", cell_fields);
    body.tag(2, "</Piece>");
    write_body(path, IMAGE, body)
}

/// The data set element of a `.vti` file.
const IMAGE: &str = "ImageData";
/// The data set element of a `.vtu` file.
const UNSTRUCTURED: &str = "UnstructuredGrid";
/// VTK's cell type numbers (`vtkCellType.h`).
const VTK_VERTEX: u8 = 1;
const VTK_LINE: u8 = 3;

/// Writes a VTK XML UnstructuredGrid file (`.vtu`) of 2-D `points` (written with `z = 0`).
///
/// The cells are
/// - one `VTK_VERTEX` per point (cell `k` is point `k`) when `lines` is empty — e.g. DEM grains
///   with per-grain data;
/// - otherwise one `VTK_LINE` per entry of `lines`, each a pair of point indices — e.g. contact
///   force chains between grain centres.
///
/// `point_fields` must have one value per point and `cell_fields` one value per cell (so per
/// point when `lines` is empty). Coordinates and values are written at the format's
/// precision, connectivity and offsets as `Int64`, cell types as `UInt8`.
///
/// An empty `points` slice gives a valid empty data set (zero points, zero cells), which VTK
/// reads; fields must then be empty too.
///
/// Returns [`Error::Other`] naming the field if a field has the wrong length or a duplicate
/// name, or if a line refers to a point that does not exist. The file is written atomically.
pub fn write_vtu_points(
    path: &Path,
    points: &[[f64; 2]],
    point_fields: &[Field],
    lines: &[[u32; 2]],
    cell_fields: &[Field],
    format: &VtkFormat,
) -> Result<()> {
    let n = points.len();
    if let Some((k, l)) = lines
        .iter()
        .enumerate()
        .find(|(_, l)| l.iter().any(|&p| p as usize >= n))
    {
        return Err(Error::Other(format!(
            "{}: line {k} joins points {} and {}, but there are only {n} points",
            path.display(),
            l[0],
            l[1]
        )));
    }
    let (connectivity, per_cell, cell_type): (Vec<i64>, i64, u8) = if lines.is_empty() {
        ((0..n as i64).collect(), 1, VTK_VERTEX)
    } else {
        let ends = lines
            .iter()
            .flat_map(|&[a, b]| [i64::from(a), i64::from(b)]);
        (ends.collect(), 2, VTK_LINE)
    };
    let ncells = connectivity.len() / per_cell as usize;
    check_fields(path, "point", point_fields, n)?;
    check_fields(path, "cell", cell_fields, ncells)?;
    let mut body = Body::new(*format, UNSTRUCTURED, "");
    body.tag(
        2,
        &format!("<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{ncells}\">"),
    );
    write_fields(&mut body, "PointData", point_fields);
    write_fields(&mut body, "CellData", cell_fields);
    body.tag(3, "<Points>");
    let coords = points.iter().flat_map(|&[x, y]| [x, y, 0.0]);
    body.reals(4, "Points", 3, coords);
    body.tag(3, "</Points>");
    body.tag(3, "<Cells>");
    body.int64s(4, "connectivity", connectivity.into_iter());
    body.int64s(4, "offsets", (1..=ncells as i64).map(|k| per_cell * k));
    body.uint8s(4, "types", vec![cell_type; ncells]);
    body.tag(3, "</Cells>");
    body.tag(2, "</Piece>");
    write_body(path, UNSTRUCTURED, body)
}

#[cfg(test)]
mod tests {
    use super::*;

    const F: VtkFormat = VtkFormat {
        compression: Compression::Zlib,
        precision: Precision::F64,
    };

    fn grid() -> ImageGrid {
        ImageGrid {
            nx: 3,
            ny: 2,
            origin: [0.5, -1.0],
            spacing: [0.25, 0.125],
        }
    }

    #[test]
    fn vti_rejects_wrong_length_naming_the_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.vti");
        let rho = [1.0; 6];
        let u = [[0.0; 2]; 5];
        let err = write_vti(
            &path,
            &grid(),
            &[Field::scalar("rho", &rho), Field::vector("velocity", &u)],
            &F,
        )
        .unwrap_err();
        match err {
            Error::Other(m) => assert!(m.contains("`velocity`") && m.contains("expected 6"), "{m}"),
            e => panic!("{e:?}"),
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn vti_rejects_duplicate_names_and_empty_grid() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.vti");
        let rho = [1.0; 6];
        assert!(write_vti(
            &path,
            &grid(),
            &[Field::scalar("rho", &rho), Field::scalar("rho", &rho)],
            &F
        )
        .is_err());
        let empty = ImageGrid { nx: 0, ..grid() };
        assert!(write_vti(&path, &empty, &[], &F).is_err());
        let flat = ImageGrid {
            spacing: [0.0, 1.0],
            ..grid()
        };
        assert!(write_vti(&path, &flat, &[], &F).is_err());
    }

    #[test]
    fn vtu_rejects_bad_line_and_cell_field_length() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.vtu");
        let pts = [[0.0, 0.0], [1.0, 0.0]];
        assert!(write_vtu_points(&path, &pts, &[], &[[0, 2]], &[], &F).is_err());
        let f = [1.0, 2.0];
        // Two lines' worth of values for one line.
        let err = write_vtu_points(
            &path,
            &pts,
            &[],
            &[[0, 1]],
            &[Field::scalar("force", &f)],
            &F,
        )
        .unwrap_err();
        assert!(matches!(err, Error::Other(ref m) if m.contains("`force`")));
        // Without lines the cells are the points, so the same field fits.
        write_vtu_points(&path, &pts, &[], &[], &[Field::scalar("force", &f)], &F).unwrap();
    }
}
