//! VTK XML output through `vtkio`: `.vti` images (the LBM lattice, MPM grid) and `.vtu` point
//! and line sets (DEM grains, contact force chains).
//!
//! Files are written uncompressed, little-endian, with inline base64 `binary` data arrays
//! (`header_type="UInt64"`), which VTK and ParaView read directly. All field values and point
//! coordinates are written as `Float64`, so they round-trip exactly. 2-D data is embedded in
//! 3-D: points get `z = 0` and vectors get a zero third component, as ParaView expects.

use std::collections::HashSet;
use std::path::Path;

use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, Extent,
    ImageDataPiece, Piece, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

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

/// Checks lengths and names of `fields` (`what` is "cell" or "point") and converts them to
/// vtkio attributes.
fn attributes(path: &Path, what: &str, fields: &[Field], n: usize) -> Result<Vec<Attribute>> {
    let mut seen = HashSet::new();
    fields
        .iter()
        .map(|f| {
            if f.name.is_empty() {
                return Err(Error::Other(format!(
                    "{}: a {what} field has an empty name",
                    path.display()
                )));
            }
            if !seen.insert(f.name) {
                return Err(Error::Other(format!(
                    "{}: {what} field `{}` is given twice",
                    path.display(),
                    f.name
                )));
            }
            if f.data.len() != n {
                return Err(Error::Other(format!(
                    "{}: {what} field `{}` has {} values, expected {n} (one per {what})",
                    path.display(),
                    f.name,
                    f.data.len()
                )));
            }
            Ok(Attribute::DataArray(match f.data {
                FieldData::Scalar(v) => DataArray {
                    name: f.name.to_owned(),
                    elem: ElementType::Scalars {
                        num_comp: 1,
                        lookup_table: None,
                    },
                    data: v.to_vec().into(),
                },
                FieldData::Vector(v) => DataArray {
                    name: f.name.to_owned(),
                    elem: ElementType::Vectors,
                    data: v
                        .iter()
                        .flat_map(|&[x, y]| [x, y, 0.0])
                        .collect::<Vec<f64>>()
                        .into(),
                },
                FieldData::Tensor(v) => DataArray {
                    name: f.name.to_owned(),
                    elem: ElementType::Tensors,
                    data: v
                        .iter()
                        .flat_map(|&[xx, xy, yx, yy]| [xx, xy, 0.0, yx, yy, 0.0, 0.0, 0.0, 0.0])
                        .collect::<Vec<f64>>()
                        .into(),
                },
            }))
        })
        .collect()
}

/// Serialises `vtk` as VTK XML to `path` through [`write_atomic`](super::write_atomic). A
/// failed write (a full disk) is reported as its own I/O error, which vtkio's XML writer
/// would turn into a formatting error that does not say what happened.
fn write_xml(path: &Path, vtk: Vtk) -> Result<()> {
    super::write_atomic(path, |w| {
        let mut out = Recording {
            inner: w,
            error: None,
        };
        vtk.write_xml(&mut out).map_err(|e| {
            out.error
                .take()
                .unwrap_or_else(|| std::io::Error::other(format!("VTK XML writer: {e}")))
        })
    })
}

/// A writer that keeps the first I/O error of the writer it wraps.
struct Recording<'a> {
    inner: &'a mut dyn std::io::Write,
    error: Option<std::io::Error>,
}

impl std::io::Write for Recording<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.inner.write(buf).map_err(|e| self.keep(e))
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush().map_err(|e| self.keep(e))
    }
}

impl Recording<'_> {
    /// Keep `e` (the first one) and hand on a copy of its kind and message.
    fn keep(&mut self, e: std::io::Error) -> std::io::Error {
        let copy = std::io::Error::new(e.kind(), e.to_string());
        self.error.get_or_insert(e);
        copy
    }
}

fn new_vtk(data: DataSet) -> Vtk {
    Vtk {
        version: Version::new_xml(1, 0),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data,
    }
}

/// Writes a VTK XML ImageData file (`.vti`) for `grid`, with `cell_fields` as CELL data.
///
/// Each field holds `nx · ny` values indexed row-major with x fastest: cell `(i, j)` is at
/// `j · nx + i`. The whole extent is `0 nx 0 ny 0 0` in points. Values are written as
/// `Float64` (exact); scalar fields get one component, vector fields three (`z = 0`). The
/// first scalar and the first vector field are marked active.
///
/// `origin` and `spacing` are stored by vtkio as `f32` (about 7 significant digits); this only
/// affects where ParaView draws the grid, not the field values.
///
/// Returns [`Error::Other`] naming the field if a field does not have `nx · ny` values, if two
/// fields share a name, or if the grid is empty or has a non-positive or non-finite spacing.
/// The file is written atomically.
pub fn write_vti(path: &Path, grid: &ImageGrid, cell_fields: &[Field]) -> Result<()> {
    let bad = |reason: String| Err(Error::Other(format!("{}: {reason}", path.display())));
    if grid.nx == 0 || grid.ny == 0 {
        return bad(format!(
            "image grid has no cells ({} x {})",
            grid.nx, grid.ny
        ));
    }
    let (Ok(nx), Ok(ny)) = (i32::try_from(grid.nx), i32::try_from(grid.ny)) else {
        return bad(format!(
            "image grid {} x {} is too large for VTK extents",
            grid.nx, grid.ny
        ));
    };
    if !grid.spacing.iter().all(|d| d.is_finite() && *d > 0.0)
        || !grid.origin.iter().all(|o| o.is_finite())
    {
        return bad(format!(
            "image grid origin {:?} / spacing {:?} must be finite and the spacing positive",
            grid.origin, grid.spacing
        ));
    }
    let cell = attributes(path, "cell", cell_fields, grid.num_cells())?;
    let extent = Extent::Ranges([0..=nx, 0..=ny, 0..=0]);
    let data = DataSet::ImageData {
        extent: extent.clone(),
        origin: [grid.origin[0] as f32, grid.origin[1] as f32, 0.0],
        spacing: [grid.spacing[0] as f32, grid.spacing[1] as f32, 1.0],
        meta: None,
        pieces: vec![Piece::Inline(Box::new(ImageDataPiece {
            extent,
            data: Attributes {
                point: Vec::new(),
                cell,
            },
        }))],
    };
    write_xml(path, new_vtk(data))
}

/// Writes a VTK XML UnstructuredGrid file (`.vtu`) of 2-D `points` (written with `z = 0`).
///
/// The cells are
/// - one `VTK_VERTEX` per point (cell `k` is point `k`) when `lines` is empty — e.g. DEM grains
///   with per-grain data;
/// - otherwise one `VTK_LINE` per entry of `lines`, each a pair of point indices — e.g. contact
///   force chains between grain centres.
///
/// `point_fields` must have one value per point and `cell_fields` one value per cell (so per
/// point when `lines` is empty). Values and coordinates are written as `Float64` (exact),
/// connectivity and offsets as `UInt64`.
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
) -> Result<()> {
    let n = points.len();
    let cells = if lines.is_empty() {
        Cells {
            cell_verts: VertexNumbers::XML {
                connectivity: (0..n as u64).collect(),
                offsets: (1..=n as u64).collect(),
            },
            types: vec![CellType::Vertex; n],
        }
    } else {
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
        Cells {
            cell_verts: VertexNumbers::XML {
                connectivity: lines
                    .iter()
                    .flat_map(|&[a, b]| [u64::from(a), u64::from(b)])
                    .collect(),
                offsets: (1..=lines.len() as u64).map(|k| 2 * k).collect(),
            },
            types: vec![CellType::Line; lines.len()],
        }
    };
    let point = attributes(path, "point", point_fields, n)?;
    let cell = attributes(path, "cell", cell_fields, cells.num_cells())?;
    let data = DataSet::inline(UnstructuredGridPiece {
        points: points
            .iter()
            .flat_map(|&[x, y]| [x, y, 0.0])
            .collect::<Vec<f64>>()
            .into(),
        cells,
        data: Attributes { point, cell },
    });
    if n > 0 {
        return write_xml(path, new_vtk(data));
    }
    // vtkio leaves out `NumberOfPoints="0" NumberOfCells="0"` (it skips zero attributes), and
    // VTK then refuses the file ("returned failure for request: REQUEST_INFORMATION"). An
    // empty frame is legitimate (no grains left, say), so put the attributes back.
    let mut xml = Vec::new();
    new_vtk(data)
        .write_xml(&mut xml)
        .map_err(|e| Error::Other(format!("{}: VTK XML writer: {e}", path.display())))?;
    let xml = String::from_utf8(xml)
        .map_err(|e| Error::Other(format!("{}: VTK XML writer: {e}", path.display())))?;
    if !xml.contains("<Piece>") {
        return Err(Error::Other(format!(
            "{}: unexpected VTK XML for an empty point set",
            path.display()
        )));
    }
    let xml = xml.replacen(
        "<Piece>",
        r#"<Piece NumberOfPoints="0" NumberOfCells="0">"#,
        1,
    );
    super::write_atomic_bytes(path, xml.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

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
            &[Field::scalar("rho", &rho), Field::scalar("rho", &rho)]
        )
        .is_err());
        let empty = ImageGrid { nx: 0, ..grid() };
        assert!(write_vti(&path, &empty, &[]).is_err());
        let flat = ImageGrid {
            spacing: [0.0, 1.0],
            ..grid()
        };
        assert!(write_vti(&path, &flat, &[]).is_err());
    }

    #[test]
    fn vtu_rejects_bad_line_and_cell_field_length() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.vtu");
        let pts = [[0.0, 0.0], [1.0, 0.0]];
        assert!(write_vtu_points(&path, &pts, &[], &[[0, 2]], &[]).is_err());
        let f = [1.0, 2.0];
        // Two lines' worth of values for one line.
        let err = write_vtu_points(&path, &pts, &[], &[[0, 1]], &[Field::scalar("force", &f)])
            .unwrap_err();
        assert!(matches!(err, Error::Other(ref m) if m.contains("`force`")));
        // Without lines the cells are the points, so the same field fits.
        write_vtu_points(&path, &pts, &[], &[], &[Field::scalar("force", &f)]).unwrap();
    }
}
