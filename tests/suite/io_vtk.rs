//! Round trips of the VTK writers, in every format (`[vtk]`: no compression, zlib, LZ4; f64
//! or f32), through a reader that follows VTK's file format (`tests/suite/common/vtk.rs`) and, when
//! the `vtk` Python package is installed, through VTK's own XML readers
//! (`scripts/check_vtk.py`). CI installs it and sets `GRANFLOW_REQUIRE_VTK=1`, which turns a
//! missing `vtk` into a failure instead of a skip.
//!
//! Set `GRANFLOW_KEEP_IO_FILES=<dir>` to keep copies of the written files.

use crate::common;

use std::path::{Path, PathBuf};

use common::vtk::{attr, read, VtkFile};
use granflow::io::{
    write_vti, write_vtu_points, Compression, Field, ImageGrid, Precision, PvdSeries, VtkFormat,
};

/// Every format a scenario can ask for.
fn formats() -> Vec<VtkFormat> {
    let mut all = Vec::new();
    for compression in [Compression::None, Compression::Zlib, Compression::Lz4] {
        for precision in [Precision::F64, Precision::F32] {
            all.push(VtkFormat {
                compression,
                precision,
            });
        }
    }
    all
}

/// A short tag for file names.
fn label(f: &VtkFormat) -> String {
    format!("{:?}_{:?}", f.compression, f.precision).to_lowercase()
}

/// `v` as the file holds it: exact in f64, rounded to nearest in f32.
fn stored(f: &VtkFormat, v: &[f64]) -> Vec<f64> {
    match f.precision {
        Precision::F64 => v.to_vec(),
        Precision::F32 => v.iter().map(|&x| f64::from(x as f32)).collect(),
    }
}

fn xyz(v: &[[f64; 2]]) -> Vec<f64> {
    v.iter().flat_map(|&[x, y]| [x, y, 0.0]).collect()
}

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

/// The test image: 3 × 2 cells, values not exact in f32.
struct Image {
    grid: ImageGrid,
    rho: Vec<f64>,
    u: Vec<[f64; 2]>,
}

fn image() -> Image {
    Image {
        grid: ImageGrid {
            nx: 3,
            ny: 2,
            origin: [0.5, -1.0 / 3.0],
            spacing: [0.25, 0.1],
        },
        rho: (0..6).map(|k| 1.0 + 0.1 * k as f64 + 1e-12).collect(),
        u: (0..6)
            .map(|k| [k as f64 / 3.0, -(k as f64) * std::f64::consts::PI])
            .collect(),
    }
}

fn write_image(path: &Path, im: &Image, f: &VtkFormat) {
    let fields = [
        Field::scalar("density", &im.rho),
        Field::vector("velocity", &im.u),
    ];
    write_vti(path, &im.grid, &fields, f).unwrap();
}

/// The test force chains: 4 points, 5 lines, point and cell fields.
struct Chains {
    points: Vec<[f64; 2]>,
    radius: Vec<f64>,
    vel: Vec<[f64; 2]>,
    lines: Vec<[u32; 2]>,
    force: Vec<f64>,
    normal: Vec<[f64; 2]>,
}

fn chains() -> Chains {
    Chains {
        points: vec![[0.0, 0.0], [1.0, 0.1], [2.0, -0.3], [1.0 / 3.0, 7.5]],
        radius: vec![0.5, 0.25, 0.125, 0.1 + 0.2],
        vel: vec![[1.0, 2.0], [3.0, 4.0], [-1e-9, 0.0], [0.1, 0.7]],
        lines: vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
        force: vec![10.0, 20.5, 0.3, 1e6, 2.0 / 3.0],
        normal: vec![[1.0, 0.0], [0.0, 1.0], [0.6, 0.8], [-0.6, 0.8], [0.1, 0.2]],
    }
}

fn write_chains(path: &Path, c: &Chains, f: &VtkFormat) {
    let point = [
        Field::scalar("radius", &c.radius),
        Field::vector("velocity", &c.vel),
    ];
    let cell = [
        Field::scalar("force", &c.force),
        Field::vector("normal", &c.normal),
    ];
    write_vtu_points(path, &c.points, &point, &c.lines, &cell, f).unwrap();
}

/// Grains as vertices with a 2 × 2 tensor.
const GRAINS: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.1], [2.0, -0.3]];
const STRESS: [[f64; 4]; 3] = [[1.0, 2.0, 3.0, 4.0], [-1e5, 0.5, 0.25, 0.3], [0.0; 4]];

fn write_grains(path: &Path, f: &VtkFormat) {
    let point = [
        Field::scalar("radius", &[0.5, 0.25, 0.125]),
        Field::tensor("stress", &STRESS),
    ];
    write_vtu_points(
        path,
        &GRAINS,
        &point,
        &[],
        &[Field::scalar("id", &[0.0, 1.0, 2.0])],
        f,
    )
    .unwrap();
}

fn check_image(file: &VtkFile, im: &Image, f: &VtkFormat) {
    let xml = &file.xml;
    assert!(
        xml.contains(r#"WholeExtent="0 3 0 2 0 0" Origin="5e-1 -3.333333333333333e-1 0" Spacing="2.5e-1 1e-1 1""#),
        "{xml}"
    );
    assert!(xml.contains(r#"<Piece Extent="0 3 0 2 0 0">"#), "{xml}");
    assert!(xml.contains(r#"<CellData Scalars="density" Vectors="velocity">"#));
    let real = match f.precision {
        Precision::F64 => "Float64",
        Precision::F32 => "Float32",
    };
    let rho = file.array("density");
    assert_eq!((rho.ty.as_str(), rho.ncomp), (real, 1));
    assert_eq!(rho.values, stored(f, &im.rho));
    let u = file.array("velocity");
    assert_eq!(u.ncomp, 3);
    assert_eq!(u.values, stored(f, &xyz(&im.u)));
}

#[test]
fn vti_round_trips_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let im = image();
    for f in formats() {
        let path = dir.path().join(format!("fluid_{}.vti", label(&f)));
        write_image(&path, &im, &f);
        let file = read(&path);
        check_image(&file, &im, &f);
        let compressor = attr(&file.xml, "compressor");
        let want = match f.compression {
            Compression::None => None,
            Compression::Zlib => Some("vtkZLibDataCompressor"),
            Compression::Lz4 => Some("vtkLZ4DataCompressor"),
        };
        assert_eq!(compressor, want);
    }
    // Only the files: no temporary file left.
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        formats().len()
    );
    keep(dir.path());
}

fn check_chains(file: &VtkFile, c: &Chains, f: &VtkFormat) {
    assert!(file
        .xml
        .contains(r#"<Piece NumberOfPoints="4" NumberOfCells="5">"#));
    assert_eq!(file.array("Points").values, stored(f, &xyz(&c.points)));
    let conn: Vec<f64> = c.lines.iter().flatten().map(|&p| f64::from(p)).collect();
    assert_eq!(file.array("connectivity").values, conn);
    assert_eq!(file.array("connectivity").ty, "Int64");
    assert_eq!(file.array("offsets").values, [2.0, 4.0, 6.0, 8.0, 10.0]);
    assert_eq!(file.array("types").values, [3.0; 5]); // VTK_LINE
    assert_eq!(file.array("radius").values, stored(f, &c.radius));
    assert_eq!(file.array("velocity").values, stored(f, &xyz(&c.vel)));
    assert_eq!(file.array("force").values, stored(f, &c.force));
    assert_eq!(file.array("normal").values, stored(f, &xyz(&c.normal)));
}

#[test]
fn vtu_lines_round_trip_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let c = chains();
    for f in formats() {
        let path = dir.path().join(format!("chains_{}.vtu", label(&f)));
        write_chains(&path, &c, &f);
        check_chains(&read(&path), &c, &f);
    }
    keep(dir.path());
}

fn tensor_xyz() -> Vec<f64> {
    STRESS
        .iter()
        .flat_map(|&[a, b, c, d]| [a, b, 0.0, c, d, 0.0, 0.0, 0.0, 0.0])
        .collect()
}

#[test]
fn vtu_vertices_round_trip_with_a_tensor() {
    let dir = tempfile::tempdir().unwrap();
    for f in formats() {
        let path = dir.path().join(format!("grains_{}.vtu", label(&f)));
        write_grains(&path, &f);
        let file = read(&path);
        assert!(file
            .xml
            .contains(r#"<PointData Scalars="radius" Tensors="stress">"#));
        assert_eq!(file.array("types").values, [1.0; 3]); // VTK_VERTEX
        assert_eq!(file.array("connectivity").values, [0.0, 1.0, 2.0]);
        assert_eq!(file.array("offsets").values, [1.0, 2.0, 3.0]);
        // 2 × 2 tensors are written as 3 × 3 with a zero z row and column.
        assert_eq!(file.array("stress").ncomp, 9);
        assert_eq!(file.array("stress").values, stored(&f, &tensor_xyz()));
        assert_eq!(file.array("id").values, [0.0, 1.0, 2.0]);
    }
    keep(dir.path());
}

/// A field of many equal values compresses to a small fraction, in chunks of 256 KiB: a
/// 1000 × 1000 image of f64 (8 MB per scalar) spans several chunks.
#[test]
fn large_fields_compress_across_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let n = 1000;
    let grid = ImageGrid {
        nx: n,
        ny: n,
        origin: [0.0, 0.0],
        spacing: [1e-3, 1e-3],
    };
    let rho: Vec<f64> = (0..n * n).map(|k| 1.0 + (k / 5000) as f64 * 1e-3).collect();
    let mut sizes = Vec::new();
    for compression in [Compression::None, Compression::Zlib, Compression::Lz4] {
        let f = VtkFormat {
            compression,
            precision: Precision::F64,
        };
        let path = dir.path().join(format!("big_{}.vti", label(&f)));
        write_vti(&path, &grid, &[Field::scalar("density", &rho)], &f).unwrap();
        assert_eq!(read(&path).array("density").values, rho);
        sizes.push(std::fs::metadata(&path).unwrap().len());
    }
    // Raw: 8 bytes a value and a short header; compressed: well under a tenth of it.
    assert!(sizes[0] > 8 * (n * n) as u64 && sizes[0] < 8 * (n * n) as u64 + 2000);
    assert!(
        sizes[1] < sizes[0] / 10 && sizes[2] < sizes[0] / 10,
        "{sizes:?}"
    );
}

/// A complete output directory: two frames of two parts each, listed in series.pvd.
#[test]
fn series_of_frames() {
    let dir = tempfile::tempdir().unwrap();
    let f = VtkFormat::default();
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
        let fields = [Field::scalar("density", &rho)];
        write_vti(&dir.path().join(&name), &grid, &fields, &f).unwrap();
        pvd.add(t, 0, &name).unwrap();
        let pts = [[0.1 + t, 0.1], [0.3, 0.2 + t]];
        let name = format!("grains_{frame:06}.vtu");
        let fields = [Field::scalar("radius", &[0.05, 0.05])];
        write_vtu_points(&dir.path().join(&name), &pts, &fields, &[], &[], &f).unwrap();
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
        read(&dir.path().join(&e.file));
    }
    keep(dir.path());
}

fn write_empty(path: &Path, f: &VtkFormat) {
    write_vtu_points(path, &[], &[Field::scalar("radius", &[])], &[], &[], f).unwrap();
}

/// An empty frame (no grains) is still a valid file.
#[test]
fn empty_vtu_is_valid() {
    let dir = tempfile::tempdir().unwrap();
    for f in formats() {
        let path = dir.path().join(format!("empty_{}.vtu", label(&f)));
        write_empty(&path, &f);
        let file = read(&path);
        assert!(file
            .xml
            .contains(r#"<Piece NumberOfPoints="0" NumberOfCells="0">"#));
        assert!(file.array("Points").values.is_empty());
        assert!(file.array("radius").values.is_empty());
    }
    keep(dir.path());
}

/// Whether the `vtk` Python package can be imported; a failure if not and
/// `GRANFLOW_REQUIRE_VTK=1`.
fn vtk_python() -> bool {
    let ok = std::process::Command::new("python3")
        .args(["-c", "import vtk"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var("GRANFLOW_REQUIRE_VTK").as_deref() != Ok("1"),
            "GRANFLOW_REQUIRE_VTK=1 but `python3 -c 'import vtk'` fails (pip install vtk)"
        );
        eprintln!("skipped: the `vtk` Python package is not installed (pip install vtk)");
    }
    ok
}

/// The values VTK read from `file`: (`points`, `cell_types`, point arrays, cell arrays).
fn vtk_read<'a>(dump: &'a serde_json::Value, file: &Path) -> &'a serde_json::Value {
    &dump[file.to_str().unwrap()]
}

fn values(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// VTK's own readers (`vtkXMLImageDataReader`, `vtkXMLUnstructuredGridReader`) open every
/// kind of file in every format without an error or warning, and read the values written.
#[test]
fn vtk_itself_reads_every_format() {
    if !vtk_python() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (im, c) = (image(), chains());
    let mut files: Vec<(VtkFormat, [PathBuf; 4])> = Vec::new();
    for f in formats() {
        let name = |kind: &str, ext: &str| dir.path().join(format!("{kind}_{}.{ext}", label(&f)));
        let paths = [
            name("fluid", "vti"),
            name("chains", "vtu"),
            name("grains", "vtu"),
            name("empty", "vtu"),
        ];
        write_image(&paths[0], &im, &f);
        write_chains(&paths[1], &c, &f);
        write_grains(&paths[2], &f);
        write_empty(&paths[3], &f);
        files.push((f, paths));
    }
    let json = dir.path().join("read.json");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_vtk.py");
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg("--json")
        .arg(&json)
        .args(files.iter().flat_map(|(_, p)| p.iter()))
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{log}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dump: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for (f, [fluid, chain, grains, empty]) in &files {
        let v = vtk_read(&dump, fluid);
        assert_eq!(values(&v["cell"]["density"]), stored(f, &im.rho), "{f:?}");
        assert_eq!(values(&v["cell"]["velocity"]), stored(f, &xyz(&im.u)));
        let v = vtk_read(&dump, chain);
        assert_eq!(values(&v["points"]), stored(f, &xyz(&c.points)));
        assert_eq!(values(&v["cell_types"]), [3.0; 5]);
        assert_eq!(values(&v["point"]["radius"]), stored(f, &c.radius));
        assert_eq!(values(&v["cell"]["force"]), stored(f, &c.force));
        assert_eq!(values(&v["cell"]["normal"]), stored(f, &xyz(&c.normal)));
        let v = vtk_read(&dump, grains);
        assert_eq!(values(&v["cell_types"]), [1.0; 3]);
        assert_eq!(values(&v["point"]["stress"]), stored(f, &tensor_xyz()));
        let v = vtk_read(&dump, empty);
        assert!(values(&v["points"]).is_empty());
    }
}

/// A scenario's `[vtk]` table is read in every kind; an unknown value or key is refused with
/// the key named.
#[test]
fn vtk_table_is_read_and_checked() {
    use granflow::scenario::fluid::Scenario;
    use granflow::scenario::ScenarioFile;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/lbm/cavity_re100.toml");
    let base = std::fs::read_to_string(path).unwrap();
    let with = |table: &str| Scenario::from_toml(&format!("{base}\n[vtk]\n{table}\n"));
    assert_eq!(
        Scenario::from_toml(&base).unwrap().vtk,
        VtkFormat::default()
    );
    let s = with("compression = \"lz4\"\nprecision = \"f32\"").unwrap();
    assert_eq!(
        s.vtk,
        VtkFormat {
            compression: Compression::Lz4,
            precision: Precision::F32
        }
    );
    for (table, key) in [
        ("compression = \"gzip\"", "compression"),
        ("precision = \"f16\"", "precision"),
        ("level = 9", "level"),
    ] {
        let err = with(table).unwrap_err().to_string();
        assert!(err.contains(key), "{table}: {err}");
    }
}
