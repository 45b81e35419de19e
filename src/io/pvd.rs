//! ParaView collection files (`series.pvd`) listing one data file per frame.

use std::path::{Path, PathBuf};

use super::csv::format_f64;
use crate::{Error, Result};

/// Escapes the five XML special characters for use inside a double-quoted attribute value.
pub(super) fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// One frame of a [`PvdSeries`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PvdEntry {
    /// Simulated time of the frame, in seconds.
    pub time: f64,
    /// Part index: frames at the same time with different parts (e.g. the fluid `.vti` as part
    /// 0 and the grains `.vtu` as part 1) are shown together.
    pub part: usize,
    /// File name relative to the directory holding `series.pvd`.
    pub file: String,
}

/// A ParaView time series: the file `series.pvd` in an output directory, listing every frame
/// written so far.
///
/// The file is rewritten atomically (see [`write_atomic`](super::write_atomic)) after each
/// [`add`](PvdSeries::add). Call `add` only once the frame's data file is completely written;
/// a run killed at any moment then leaves a valid `series.pvd` that lists only complete frames.
/// The format is
///
/// ```xml
/// <?xml version="1.0"?>
/// <VTKFile type="Collection" version="0.1">
///   <Collection>
///     <DataSet timestep="0.001" part="0" file="fluid_000001.vti"/>
///   </Collection>
/// </VTKFile>
/// ```
///
/// with times written in shortest round-trip form.
#[derive(Clone, Debug)]
pub struct PvdSeries {
    path: PathBuf,
    entries: Vec<PvdEntry>,
}

impl PvdSeries {
    /// Name of the collection file inside the output directory.
    pub const FILE_NAME: &'static str = "series.pvd";

    /// A new, empty series that will be written to `dir/series.pvd`. Nothing is written until
    /// the first [`add`](PvdSeries::add); an existing file there is replaced at that point.
    pub fn new(dir: &Path) -> Self {
        PvdSeries {
            path: dir.join(Self::FILE_NAME),
            entries: Vec::new(),
        }
    }

    /// The series of a resumed run: the frames it had written when its checkpoint was taken
    /// (nothing is written until the next [`add`](PvdSeries::add)).
    pub fn resume(dir: &Path, entries: Vec<PvdEntry>) -> Self {
        PvdSeries {
            path: dir.join(Self::FILE_NAME),
            entries,
        }
    }

    /// Records a frame (its simulated `time` in seconds, its `part` index, and its `file` name
    /// relative to the series directory) and rewrites `series.pvd` atomically.
    ///
    /// Returns [`Error::Other`] for a non-finite time or an empty file name (the entry is not
    /// recorded), and [`Error::Io`] if the file cannot be written (the entry stays recorded and
    /// will be written with the next successful `add`).
    pub fn add(&mut self, time: f64, part: usize, file: &str) -> Result<()> {
        if !time.is_finite() {
            return Err(Error::Other(format!(
                "{}: frame time {time} is not finite",
                self.path.display()
            )));
        }
        if file.is_empty() {
            return Err(Error::Other(format!(
                "{}: empty file name for the frame at t = {time}",
                self.path.display()
            )));
        }
        self.entries.push(PvdEntry {
            time,
            part,
            file: file.to_owned(),
        });
        self.write()
    }

    /// Writes the current list of frames to `series.pvd` atomically.
    pub fn write(&self) -> Result<()> {
        super::write_atomic_bytes(&self.path, self.to_xml().as_bytes())
    }

    /// The XML text of the collection.
    pub fn to_xml(&self) -> String {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  \
             <Collection>\n",
        );
        for e in &self.entries {
            s.push_str(&format!(
                "    <DataSet timestep=\"{}\" part=\"{}\" file=\"{}\"/>\n",
                format_f64(e.time),
                e.part,
                xml_escape(&e.file)
            ));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        s
    }

    /// The frames recorded so far, in the order they were added.
    pub fn entries(&self) -> &[PvdEntry] {
        &self.entries
    }

    /// Path of the collection file (`dir/series.pvd`).
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_adds() {
        let dir = tempfile::tempdir().unwrap();
        let mut pvd = PvdSeries::new(dir.path());
        assert!(!pvd.path().exists());
        pvd.add(0.0, 0, "fluid_000000.vti").unwrap();
        pvd.add(0.5, 0, "fluid_000001.vti").unwrap();
        pvd.add(1e-7, 1, "a&b<c>.vtu").unwrap();
        let text = std::fs::read_to_string(dir.path().join("series.pvd")).unwrap();
        assert!(text.starts_with("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\""));
        assert_eq!(text.matches("<DataSet ").count(), 3);
        assert!(text.contains(r#"<DataSet timestep="0.5" part="0" file="fluid_000001.vti"/>"#));
        assert!(text.contains(r#"<DataSet timestep="1e-7" part="1" file="a&amp;b&lt;c&gt;.vtu"/>"#));
        assert!(text.trim_end().ends_with("</Collection>\n</VTKFile>"));
        // Only series.pvd in the directory: no temp file left behind.
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("series.pvd")]);
        assert_eq!(pvd.entries().len(), 3);
    }

    #[test]
    fn refuses_bad_entries() {
        let dir = tempfile::tempdir().unwrap();
        let mut pvd = PvdSeries::new(dir.path());
        assert!(pvd.add(f64::NAN, 0, "a.vti").is_err());
        assert!(pvd.add(0.0, 0, "").is_err());
        assert!(pvd.entries().is_empty());
        assert!(!pvd.path().exists());
    }
}
