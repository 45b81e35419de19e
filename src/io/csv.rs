//! Append-only CSV time series, flushed row by row.

use std::fs::File;
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// Formats a number so that parsing the text gives back exactly the same `f64`: Rust's
/// shortest round-trip representation, in plain decimal for magnitudes in `[1e-5, 1e16)` (and
/// zero) and in exponent form (`1.5e-7`) otherwise. Non-finite values print as `NaN`, `inf`,
/// `-inf`.
pub(crate) fn format_f64(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-5..1e16).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A numeric CSV table read back (e.g. a run's `timeseries.csv`): column names and rows.
#[derive(Clone, Debug, Default)]
pub struct CsvTable {
    /// Column names from the header line.
    pub header: Vec<String>,
    /// Rows of numbers (a field that does not parse reads as NaN).
    pub rows: Vec<Vec<f64>>,
}

impl CsvTable {
    /// Reads `path`: a header line, then comma-separated numbers.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let mut lines = text.lines();
        let header = lines
            .next()
            .map(|h| h.split(',').map(str::to_owned).collect())
            .unwrap_or_default();
        let rows = lines
            .filter(|l| !l.is_empty())
            .map(|l| {
                l.split(',')
                    .map(|v| v.parse().unwrap_or(f64::NAN))
                    .collect()
            })
            .collect();
        Ok(CsvTable { header, rows })
    }

    /// The values of column `name` (`None` if there is no such column).
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.header.iter().position(|h| h == name)?;
        Some(
            self.rows
                .iter()
                .map(|r| r.get(k).copied().unwrap_or(f64::NAN))
                .collect(),
        )
    }
}

/// A CSV file written one row at a time, e.g. `timeseries.csv`.
///
/// The header is written on [`create`](CsvWriter::create); each [`row`](CsvWriter::row) must
/// have exactly one value per column. Numbers are written with Rust's shortest round-trip
/// representation (parsing the text gives back the identical `f64`), using exponent notation
/// for very small or very large magnitudes. The file is flushed after the header and after every
/// row, so a run killed at any point leaves every complete row on disk.
#[derive(Debug)]
pub struct CsvWriter {
    path: PathBuf,
    columns: usize,
    /// The file, written a whole line at a time (no buffer to flush).
    out: File,
    line: String,
    /// Bytes in the file so far (header and rows).
    len: u64,
}

impl CsvWriter {
    /// Creates (or truncates) the file at `path` and writes the `header` line.
    ///
    /// Column names must be non-empty and must not contain commas, quotes or line breaks;
    /// otherwise [`Error::Other`] is returned and no file is created.
    pub fn create(path: &Path, header: &[&str]) -> Result<Self> {
        if header.is_empty() {
            return Err(Error::Other(format!(
                "CSV {}: the header has no columns",
                path.display()
            )));
        }
        for name in header {
            if name.is_empty() || name.contains([',', '"', '\n', '\r']) {
                return Err(Error::Other(format!(
                    "CSV {}: column name {name:?} is empty or contains a comma, quote or line \
                     break",
                    path.display()
                )));
            }
        }
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        let mut writer = CsvWriter {
            path: path.to_path_buf(),
            columns: header.len(),
            out: file,
            line: String::new(),
            len: 0,
        };
        writer.line = header.join(",");
        writer.line.push('\n');
        writer.write_line()?;
        Ok(writer)
    }

    /// Appends one row and flushes it to the file.
    ///
    /// Returns [`Error::Other`] (writing nothing) if `values` does not have one entry per header
    /// column.
    pub fn row(&mut self, values: &[f64]) -> Result<()> {
        if values.len() != self.columns {
            return Err(Error::Other(format!(
                "CSV {}: row has {} values but the header has {} columns",
                self.path.display(),
                values.len(),
                self.columns
            )));
        }
        self.line.clear();
        for (k, v) in values.iter().enumerate() {
            if k > 0 {
                self.line.push(',');
            }
            self.line.push_str(&format_f64(*v));
        }
        self.line.push('\n');
        self.write_line()
    }

    /// Continue the file at `path` of a run that is resumed: its first `len` bytes (its length
    /// when the run's checkpoint was taken, [`CsvWriter::bytes_written`]) are kept, what a later part of
    /// the interrupted run appended is cut off, and rows of `columns` values follow. A file
    /// shorter than `len` is refused.
    pub fn reopen(path: &Path, columns: usize, len: u64) -> Result<Self> {
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| Error::io(path, e))?;
        let have = file.metadata().map_err(|e| Error::io(path, e))?.len();
        if have < len {
            return Err(Error::Other(format!(
                "{}: {have} bytes, shorter than the {len} the checkpoint recorded",
                path.display()
            )));
        }
        let mut file = file;
        file.set_len(len)
            .and_then(|()| file.seek(SeekFrom::End(0)))
            .map_err(|e| Error::io(path, e))?;
        Ok(CsvWriter {
            path: path.to_path_buf(),
            columns,
            out: file,
            line: String::new(),
            len,
        })
    }

    /// Bytes written to the file so far (all flushed).
    pub fn bytes_written(&self) -> u64 {
        self.len
    }

    /// Number of columns in the header (and in every row).
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Append the line in one write; one that fails part-way (a full disk) is cut off again,
    /// so the file holds whole rows only.
    fn write_line(&mut self) -> Result<()> {
        let written = self.out.write_all(self.line.as_bytes());
        if let Err(e) = written {
            let _ = self
                .out
                .set_len(self.len)
                .and_then(|()| self.out.seek(SeekFrom::End(0)));
            return Err(Error::io(&self.path, e));
        }
        self.len += self.line.len() as u64;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_header_and_rows() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ts.csv");
        let mut w = CsvWriter::create(&path, &["t", "runout", "height"]).unwrap();
        assert_eq!(w.columns(), 3);
        w.row(&[0.0, 1.5, 0.1]).unwrap();
        w.row(&[1e-7, -2.0, 1.0 / 3.0]).unwrap();
        // Flushed after each row: readable before the writer is dropped.
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            "t,runout,height\n0,1.5,0.1\n1e-7,-2,0.3333333333333333\n"
        );
        // Round trip exactly.
        let last: Vec<f64> = text
            .lines()
            .nth(2)
            .unwrap()
            .split(',')
            .map(|s| s.parse().unwrap())
            .collect();
        assert_eq!(last, vec![1e-7, -2.0, 1.0 / 3.0]);
    }

    #[test]
    fn refuses_wrong_row_length() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ts.csv");
        let mut w = CsvWriter::create(&path, &["a", "b"]).unwrap();
        let err = w.row(&[1.0, 2.0, 3.0]).unwrap_err();
        assert!(
            matches!(err, Error::Other(ref m) if m.contains("3 values") && m.contains("2 columns"))
        );
        assert!(w.row(&[1.0]).is_err());
        w.row(&[1.0, 2.0]).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n1,2\n");
    }

    #[test]
    fn refuses_bad_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ts.csv");
        assert!(CsvWriter::create(&path, &[]).is_err());
        assert!(CsvWriter::create(&path, &["a,b"]).is_err());
        assert!(!path.exists());
    }

    #[test]
    fn format_round_trips() {
        for x in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-5,
            9.99e-6,
            1e16,
            123456789.123,
            f64::MIN_POSITIVE,
            f64::MAX,
            -5e-324,
            std::f64::consts::PI,
        ] {
            let s = format_f64(x);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
        assert_eq!(format_f64(f64::NAN), "NaN");
        assert_eq!(format_f64(f64::INFINITY), "inf");
    }
}
