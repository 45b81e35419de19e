//! Round trips of the VTK writers through vtkio's own reader.
//!
//! Set `GRANFLOW_KEEP_IO_FILES=<dir>` to keep copies of the written files (e.g. to open them
//! with `scripts/check_vtk.py`).

use std::path::Path;

use granflow::io::{write_vti, write_vtu_points, Field, ImageGrid, PvdSeries};
use vtkio::model::{Attribute, CellType, DataSet, ElementType, Extent, Piece, VertexNumbers};
use vtkio::Vtk;

fn keep(dir: &Path) {
    if let Some(out) = std::env::var_os("GRANFLOW_KEEP_IO_FILES") {
        let out = Path::new(&out);
        std::fs::create_dir_all(out).unwrap();
        for e in std::fs::read_dir(dir).unwrap() {
            let e = e.unwrap();
            std::fs::copy(e.path(), out.join(e.file_name())).unwrap();
        }
    }
}

/// The named array in `attrs`: (element type, values as f64).
fn array(attrs: &[Attribute], name: &str) -> (ElementType, Vec<f64>) {
    for a in attrs {
        if let Attribute::DataArray(d) = a {
            if d.name == name {
                return (d.elem.clone(), d.data.clone().into_vec::<f64>().unwrap());
            }
        }
    }
    panic!("no array {name} in {attrs:?}");
}

#[test]
fn vti_round_trips_through_vtkio() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fluid_000000.vti");
    let grid = ImageGrid {
        nx: 3,
        ny: 2,
        origin: [0.5, -1.0],
        spacing: [0.25, 0.125],
    };
    // Values that are not exact in f32, to check Float64 really is written.
    let rho: Vec<f64> = (0..6).map(|k| 1.0 + 0.1 * k as f64 + 1e-12).collect();
    let u: Vec<[f64; 2]> = (0..6)
        .map(|k| [k as f64 / 3.0, -(k as f64) * std::f64::consts::PI])
        .collect();
    write_vti(
        &path,
        &grid,
        &[
            Field::scalar("density", &rho),
            Field::vector("velocity", &u),
        ],
    )
    .unwrap();
    // Only the file: the temp file is gone.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(r#"WholeExtent="0 3 0 2 0 0""#), "{text}");
    assert!(!text.contains("compressor"), "{text}");

    let vtk = Vtk::import(&path).unwrap();
    let DataSet::ImageData {
        extent,
        origin,
        spacing,
        pieces,
        ..
    } = vtk.data
    else {
        panic!("not image data: {:?}", vtk.data)
    };
    assert_eq!(extent, Extent::Ranges([0..=3, 0..=2, 0..=0]));
    assert_eq!(extent.clone().into_dims(), [4, 3, 1]); // points
    assert_eq!(origin, [0.5, -1.0, 0.0]);
    assert_eq!(spacing, [0.25, 0.125, 1.0]);
    assert_eq!(pieces.len(), 1);

    // vtkio 0.7.0-rc2's reader counts the cells of an image as (nx-1)(ny-1)(nz-1) points, i.e.
    // zero for a flat 2-D image, and silently drops every cell array (VTK itself counts 6). To
    // check the values with vtkio's decoder anyway, read the same bytes with the z extent
    // widened to one cell layer: the arrays then have the expected length of 6.
    let widened = text.replace(r#"Extent="0 3 0 2 0 0""#, r#"Extent="0 3 0 2 0 1""#);
    assert_eq!(widened.matches(r#"Extent="0 3 0 2 0 1""#).count(), 2);
    let vtk = Vtk::parse_xml(widened.as_bytes()).unwrap();
    let DataSet::ImageData { pieces, .. } = vtk.data else {
        panic!("not image data")
    };
    let Piece::Inline(piece) = &pieces[0] else {
        panic!("piece not inline")
    };
    assert!(piece.data.point.is_empty());
    assert_eq!(piece.data.cell.len(), 2);
    let (elem, got) = array(&piece.data.cell, "density");
    assert_eq!(elem.num_comp(), 1);
    assert_eq!(got, rho); // exact
    let (elem, got) = array(&piece.data.cell, "velocity");
    assert_eq!(elem.num_comp(), 3);
    let want: Vec<f64> = u.iter().flat_map(|&[x, y]| [x, y, 0.0]).collect();
    assert_eq!(got, want);
    keep(dir.path());
}

#[test]
fn vtu_lines_round_trip_through_vtkio() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chains_000000.vtu");
    let points = [[0.0, 0.0], [1.0, 0.1], [2.0, -0.3], [1.0 / 3.0, 7.5]];
    let radius = [0.5, 0.25, 0.125, 0.1 + 0.2];
    let vel = [[1.0, 2.0], [3.0, 4.0], [-1e-9, 0.0], [0.1, 0.7]];
    let lines = [[0u32, 1], [1, 2], [2, 3], [3, 0], [0, 2]];
    let force = [10.0, 20.5, 0.3, 1e6, 2.0 / 3.0];
    let normal = [[1.0, 0.0], [0.0, 1.0], [0.6, 0.8], [-0.6, 0.8], [0.1, 0.2]];
    write_vtu_points(
        &path,
        &points,
        &[
            Field::scalar("radius", &radius),
            Field::vector("velocity", &vel),
        ],
        &lines,
        &[
            Field::scalar("force", &force),
            Field::vector("normal", &normal),
        ],
    )
    .unwrap();
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    let vtk = Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid: {:?}", vtk.data)
    };
    let Piece::Inline(piece) = &pieces[0] else {
        panic!("piece not inline")
    };
    let pts: Vec<f64> = piece.points.clone().into_vec::<f64>().unwrap();
    let want: Vec<f64> = points.iter().flat_map(|&[x, y]| [x, y, 0.0]).collect();
    assert_eq!(pts, want);
    assert_eq!(piece.cells.types, vec![CellType::Line; 5]);
    let (conn, offs) = piece.cells.cell_verts.clone().into_xml();
    assert_eq!(conn, vec![0, 1, 1, 2, 2, 3, 3, 0, 0, 2]);
    assert_eq!(offs, vec![2, 4, 6, 8, 10]);
    assert_eq!(array(&piece.data.point, "radius").1, radius);
    let (elem, got) = array(&piece.data.point, "velocity");
    assert_eq!(elem, ElementType::Vectors);
    assert_eq!(
        got,
        vel.iter()
            .flat_map(|&[x, y]| [x, y, 0.0])
            .collect::<Vec<_>>()
    );
    assert_eq!(array(&piece.data.cell, "force").1, force);
    assert_eq!(
        array(&piece.data.cell, "normal").1,
        normal
            .iter()
            .flat_map(|&[x, y]| [x, y, 0.0])
            .collect::<Vec<_>>()
    );
    keep(dir.path());
}

#[test]
fn vtu_vertices_round_trip_through_vtkio() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("grains_000000.vtu");
    let points = [[0.0, 0.0], [1.0, 0.1], [2.0, -0.3]];
    let radius = [0.5, 0.25, 0.125];
    let id = [0.0, 1.0, 2.0];
    let stress = [[1.0, 2.0, 3.0, 4.0], [-1e5, 0.5, 0.25, 1.0 / 3.0], [0.0; 4]];
    write_vtu_points(
        &path,
        &points,
        &[
            Field::scalar("radius", &radius),
            Field::tensor("stress", &stress),
        ],
        &[],
        &[Field::scalar("id", &id)],
    )
    .unwrap();
    let vtk = Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let Piece::Inline(piece) = &pieces[0] else {
        panic!("piece not inline")
    };
    assert_eq!(piece.cells.types, vec![CellType::Vertex; 3]);
    match piece.cells.cell_verts.clone() {
        v @ VertexNumbers::XML { .. } => {
            assert_eq!(v.into_xml(), (vec![0, 1, 2], vec![1, 2, 3]))
        }
        v => panic!("{v:?}"),
    }
    assert_eq!(array(&piece.data.point, "radius").1, radius);
    // 2 × 2 tensors come back as 3 × 3 with a zero z row and column.
    let (elem, got) = array(&piece.data.point, "stress");
    assert_eq!(elem, ElementType::Tensors);
    let want: Vec<f64> = stress
        .iter()
        .flat_map(|&[a, b, c, d]| [a, b, 0.0, c, d, 0.0, 0.0, 0.0, 0.0])
        .collect();
    assert_eq!(got, want);
    assert_eq!(array(&piece.data.cell, "id").1, id);
    keep(dir.path());
}

/// A complete output directory: two frames of two parts each, listed in series.pvd.
#[test]
fn series_of_frames() {
    let dir = tempfile::tempdir().unwrap();
    let grid = ImageGrid {
        nx: 4,
        ny: 3,
        origin: [0.0, 0.0],
        spacing: [0.1, 0.1],
    };
    let mut pvd = PvdSeries::new(dir.path());
    for frame in 0..2 {
        let t = 0.5 * frame as f64;
        let rho: Vec<f64> = (0..12).map(|k| 1.0 + t * k as f64).collect();
        let name = format!("fluid_{frame:06}.vti");
        write_vti(
            &dir.path().join(&name),
            &grid,
            &[Field::scalar("density", &rho)],
        )
        .unwrap();
        pvd.add(t, 0, &name).unwrap();
        let pts = [[0.1 + t, 0.1], [0.3, 0.2 + t]];
        let name = format!("grains_{frame:06}.vtu");
        write_vtu_points(
            &dir.path().join(&name),
            &pts,
            &[Field::scalar("radius", &[0.05, 0.05])],
            &[],
            &[],
        )
        .unwrap();
        pvd.add(t, 1, &name).unwrap();
    }
    let text = std::fs::read_to_string(dir.path().join("series.pvd")).unwrap();
    assert_eq!(text.matches("<DataSet ").count(), 4);
    let mut names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "fluid_000000.vti",
            "fluid_000001.vti",
            "grains_000000.vtu",
            "grains_000001.vtu",
            "series.pvd"
        ]
    );
    // Every listed file is readable.
    for e in pvd.entries() {
        Vtk::import(dir.path().join(&e.file)).unwrap();
    }
    if let Some(out) = std::env::var_os("GRANFLOW_KEEP_IO_FILES") {
        let out = Path::new(&out).join("series");
        std::fs::create_dir_all(&out).unwrap();
        for n in names {
            std::fs::copy(dir.path().join(&n), out.join(&n)).unwrap();
        }
    }
}

/// An empty frame (no grains) is still a valid file.
#[test]
fn empty_vtu_is_valid() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("empty_000000.vtu");
    write_vtu_points(&path, &[], &[Field::scalar("radius", &[])], &[], &[]).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains(r#"<Piece NumberOfPoints="0" NumberOfCells="0">"#),
        "{text}"
    );
    let vtk = Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let Piece::Inline(piece) = &pieces[0] else {
        panic!("piece not inline")
    };
    assert_eq!(piece.num_points(), 0);
    assert_eq!(piece.cells.num_cells(), 0);
    keep(dir.path());
}
