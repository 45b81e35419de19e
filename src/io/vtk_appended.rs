//! The VTK XML file body in *appended raw binary* form, optionally compressed.
//!
//! Every data array is one block of the `<AppendedData encoding="raw">` section that follows
//! the XML header, referenced by its byte `offset` from the `_` that opens the section. With
//! `header_type="UInt64"` a block is, as VTK's `vtkXMLDataParser` reads it:
//! - uncompressed: `[n]` then the `n` bytes of the array;
//! - compressed: `[b, s, r, c₀ … c_{b−1}]` then the `b` compressed chunks, where the array's
//!   bytes were cut into chunks of `s` bytes (the last one `r` bytes, `r = 0` when it is full)
//!   and chunk `k` compressed on its own to `c_k` bytes, by zlib (`vtkZLibDataCompressor`) or
//!   LZ4's block format (`vtkLZ4DataCompressor`).
//!
//! Chunks are compressed in parallel (rayon); the output does not depend on the thread count.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::pvd::xml_escape;

/// How VTK frames are written: the `[vtk]` table of a scenario.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct VtkFormat {
    /// Compression of the data arrays (default zlib).
    #[serde(default)]
    pub compression: Compression,
    /// Precision of the field values and point coordinates (default f64, exact).
    #[serde(default)]
    pub precision: Precision,
}

/// Compression of VTK data arrays.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Compression {
    /// Raw bytes.
    None,
    /// zlib (deflate) at level 6, which VTK reads since 5.x and ParaView since 3.x.
    #[default]
    Zlib,
    /// LZ4 block format: ≈ 5–10× faster to write than zlib, larger files; VTK ≥ 8.2 and
    /// ParaView ≥ 5.6 read it.
    Lz4,
}

/// Precision of the floating-point values in VTK files.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
// Named apart from the populations' precision in the schemas that have both.
#[schemars(rename = "VtkPrecision")]
pub enum Precision {
    /// `Float64`: the values as computed, bit for bit.
    #[default]
    F64,
    /// `Float32`: half the bytes, ≈ 7 significant digits (rounded to nearest).
    F32,
}

/// Bytes of one compression chunk (VTK's default is 32 KiB; a larger chunk keeps the header
/// short and gives rayon pieces worth a thread).
const CHUNK: usize = 1 << 18;

/// zlib level: flate2's default, the usual trade-off of size against time.
const ZLIB_LEVEL: u32 = 6;

/// A VTK XML file under construction: the XML text and the appended data after it.
pub(super) struct Body {
    format: VtkFormat,
    xml: String,
    data: Vec<u8>,
}

impl Body {
    /// A file of data set `kind` (`ImageData`, `UnstructuredGrid`), open at its data set
    /// element, which carries `attrs`.
    pub(super) fn new(format: VtkFormat, kind: &str, attrs: &str) -> Self {
        let compressor = match format.compression {
            Compression::None => "",
            Compression::Zlib => r#" compressor="vtkZLibDataCompressor""#,
            Compression::Lz4 => r#" compressor="vtkLZ4DataCompressor""#,
        };
        let xml = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"{kind}\" version=\"1.0\" \
             byte_order=\"LittleEndian\" header_type=\"UInt64\"{compressor}>\n  <{kind}{attrs}>\n"
        );
        Body {
            format,
            xml,
            data: Vec::new(),
        }
    }

    /// Append a line of XML (an opening or closing tag) at `depth` levels of indentation.
    pub(super) fn tag(&mut self, depth: usize, tag: &str) {
        for _ in 0..depth {
            self.xml.push_str("  ");
        }
        self.xml.push_str(tag);
        self.xml.push('\n');
    }

    /// Append a floating-point `DataArray` of `ncomp` components per tuple, `name`, at the
    /// file's precision.
    pub(super) fn reals(
        &mut self,
        depth: usize,
        name: &str,
        ncomp: usize,
        values: impl Iterator<Item = f64>,
    ) {
        let (ty, bytes) = match self.format.precision {
            Precision::F64 => ("Float64", values.flat_map(f64::to_le_bytes).collect()),
            Precision::F32 => (
                "Float32",
                values.flat_map(|x| (x as f32).to_le_bytes()).collect(),
            ),
        };
        self.array(depth, ty, name, ncomp, bytes);
    }

    /// Append an `Int64` array of one component (connectivity, offsets).
    pub(super) fn int64s(&mut self, depth: usize, name: &str, values: impl Iterator<Item = i64>) {
        let bytes = values.flat_map(i64::to_le_bytes).collect();
        self.array(depth, "Int64", name, 1, bytes);
    }

    /// Append a `UInt8` array of one component (cell types).
    pub(super) fn uint8s(&mut self, depth: usize, name: &str, values: Vec<u8>) {
        self.array(depth, "UInt8", name, 1, values);
    }

    /// Append a `DataArray` of VTK type `ty`, `ncomp` components per tuple, `name`, whose
    /// little-endian values are `bytes`.
    fn array(&mut self, depth: usize, ty: &str, name: &str, ncomp: usize, bytes: Vec<u8>) {
        let name = match name {
            "" => String::new(),
            n => format!(" Name=\"{}\"", xml_escape(n)),
        };
        let tag = format!(
            "<DataArray type=\"{ty}\"{name} NumberOfComponents=\"{ncomp}\" format=\"appended\" \
             offset=\"{}\"/>",
            self.data.len()
        );
        self.tag(depth, &tag);
        self.block(&bytes);
    }

    /// Append `bytes` as one block of the appended data (see the module documentation).
    fn block(&mut self, bytes: &[u8]) {
        let compress: fn(&[u8]) -> Vec<u8> = match self.format.compression {
            Compression::None => {
                self.data
                    .extend_from_slice(&(bytes.len() as u64).to_le_bytes());
                self.data.extend_from_slice(bytes);
                return;
            }
            Compression::Zlib => zlib,
            Compression::Lz4 => lz4_flex::block::compress,
        };
        let chunks: Vec<Vec<u8>> = bytes.par_chunks(CHUNK).map(compress).collect();
        let header = [
            chunks.len() as u64,
            CHUNK as u64,
            (bytes.len() % CHUNK) as u64,
        ];
        let sizes = chunks.iter().map(|c| c.len() as u64);
        for h in header.into_iter().chain(sizes) {
            self.data.extend_from_slice(&h.to_le_bytes());
        }
        for c in &chunks {
            self.data.extend_from_slice(c);
        }
    }

    /// Close the data set element (`kind`) and write the whole file to `out`.
    pub(super) fn finish(
        mut self,
        kind: &str,
        out: &mut dyn std::io::Write,
    ) -> std::io::Result<()> {
        self.tag(1, &format!("</{kind}>"));
        self.xml.push_str("  <AppendedData encoding=\"raw\">\n   _");
        out.write_all(self.xml.as_bytes())?;
        out.write_all(&self.data)?;
        out.write_all(b"\n  </AppendedData>\n</VTKFile>\n")
    }
}

/// One chunk compressed by zlib.
fn zlib(chunk: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::ZlibEncoder::new(
        Vec::with_capacity(chunk.len() / 2),
        flate2::Compression::new(ZLIB_LEVEL),
    );
    // Writing to a Vec cannot fail.
    e.write_all(chunk).expect("zlib into memory");
    e.finish().expect("zlib into memory")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The compressed block header: chunk count, chunk size, partial last chunk, then the
    /// compressed sizes, whose sum is what follows.
    #[test]
    fn compressed_block_header() {
        for (len, partial) in [
            (0, 0),
            (CHUNK, 0),
            (CHUNK + 5, 5),
            (3 * CHUNK - 1, CHUNK - 1),
        ] {
            let mut b = Body::new(
                VtkFormat {
                    compression: Compression::Zlib,
                    precision: Precision::F64,
                },
                "ImageData",
                "",
            );
            let bytes: Vec<u8> = (0..len).map(|k| (k % 251) as u8).collect();
            b.block(&bytes);
            let h: Vec<u64> = b
                .data
                .chunks(8)
                .take(3)
                .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
                .collect();
            let n = len.div_ceil(CHUNK);
            assert_eq!(h, [n as u64, CHUNK as u64, partial as u64], "{len} bytes");
            let sizes: u64 = b.data[24..24 + 8 * n]
                .chunks(8)
                .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
                .sum();
            assert_eq!(b.data.len() as u64, 24 + 8 * n as u64 + sizes);
        }
    }
}
