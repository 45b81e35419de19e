//! A reader of the VTK XML files granflow writes (appended raw data, UInt64 headers, no
//! compression, zlib or LZ4), for the tests: the XML text and every `DataArray` decoded to
//! `f64`. It follows VTK's file format description, not granflow's writer, so a round trip
//! through it checks the bytes the writer lays out. (`tests/suite/io_vtk.rs` also has VTK itself
//! read the files when the `vtk` Python package is there.)

use std::io::Read;
use std::path::Path;

/// One data array: its attributes and values.
#[derive(Clone, Debug)]
pub struct Array {
    /// `Name` (empty if absent).
    pub name: String,
    /// `type`, e.g. `Float64`.
    pub ty: String,
    /// `NumberOfComponents`.
    pub ncomp: usize,
    /// The values, converted to f64.
    pub values: Vec<f64>,
}

/// A file read back: its XML (up to the appended data) and its arrays in file order.
pub struct VtkFile {
    pub xml: String,
    pub arrays: Vec<Array>,
}

impl VtkFile {
    /// The array called `name`; panics if there is none or more than one.
    pub fn array(&self, name: &str) -> &Array {
        let mut found = self.arrays.iter().filter(|a| a.name == name);
        let a = found.next().unwrap_or_else(|| panic!("no array {name}"));
        assert!(found.next().is_none(), "two arrays {name}");
        a
    }
}

/// The value of attribute `key` in the tag `tag` (its text between `<` and `>`).
pub fn attr<'a>(tag: &'a str, key: &str) -> Option<&'a str> {
    let pat = format!(" {key}=\"");
    let a = tag.find(&pat)? + pat.len();
    Some(&tag[a..a + tag[a..].find('"')?])
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// Read `path`, decoding every data array.
pub fn read(path: &Path) -> VtkFile {
    let bytes = std::fs::read(path).unwrap();
    let open = b"<AppendedData encoding=\"raw\">";
    let at = bytes
        .windows(open.len())
        .position(|w| w == open)
        .unwrap_or_else(|| panic!("{}: no raw appended data", path.display()));
    let xml = String::from_utf8(bytes[..at].to_vec()).unwrap();
    let underscore = at + bytes[at..].iter().position(|&b| b == b'_').unwrap();
    let data = &bytes[underscore + 1..];
    let root = &xml[xml.find("<VTKFile").unwrap()..];
    let root = &root[..root.find('>').unwrap()];
    assert_eq!(attr(root, "header_type"), Some("UInt64"));
    assert_eq!(attr(root, "byte_order"), Some("LittleEndian"));
    let compressor = attr(root, "compressor");
    let mut arrays = Vec::new();
    for piece in xml.split("<DataArray").skip(1) {
        let tag = &piece[..piece.find('>').unwrap()];
        assert_eq!(attr(tag, "format"), Some("appended"), "{tag}");
        let offset: usize = attr(tag, "offset").unwrap().parse().unwrap();
        let raw = block(&data[offset..], compressor);
        let ty = attr(tag, "type").unwrap().to_string();
        let values = match ty.as_str() {
            "Float64" => raw
                .chunks(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect(),
            "Float32" => raw
                .chunks(4)
                .map(|c| f64::from(f32::from_le_bytes(c.try_into().unwrap())))
                .collect(),
            "Int64" => raw
                .chunks(8)
                .map(|c| i64::from_le_bytes(c.try_into().unwrap()) as f64)
                .collect(),
            "UInt8" => raw.iter().map(|&b| f64::from(b)).collect(),
            t => panic!("type {t}"),
        };
        arrays.push(Array {
            name: attr(tag, "Name").unwrap_or("").to_string(),
            ty,
            ncomp: attr(tag, "NumberOfComponents").unwrap().parse().unwrap(),
            values,
        });
    }
    VtkFile { xml, arrays }
}

/// The bytes of the block at the start of `b`.
fn block(b: &[u8], compressor: Option<&str>) -> Vec<u8> {
    let Some(compressor) = compressor else {
        let n = u64_at(b, 0) as usize;
        return b[8..8 + n].to_vec();
    };
    let (nblocks, size, last) = (
        u64_at(b, 0) as usize,
        u64_at(b, 8) as usize,
        u64_at(b, 16) as usize,
    );
    let mut at = 24 + 8 * nblocks;
    let mut out = Vec::new();
    for k in 0..nblocks {
        let c = u64_at(b, 24 + 8 * k) as usize;
        let chunk = &b[at..at + c];
        at += c;
        let full = if k + 1 == nblocks && last != 0 {
            last
        } else {
            size
        };
        let mut plain = match compressor {
            "vtkZLibDataCompressor" => {
                let mut v = Vec::new();
                flate2::read::ZlibDecoder::new(chunk)
                    .read_to_end(&mut v)
                    .unwrap();
                v
            }
            "vtkLZ4DataCompressor" => lz4_flex::block::decompress(chunk, full).unwrap(),
            c => panic!("compressor {c}"),
        };
        assert_eq!(plain.len(), full, "chunk {k}");
        out.append(&mut plain);
    }
    out
}
