//! Output files: VTK (`.vti` images, `.vtu` point/line sets), ParaView collections (`.pvd`),
//! CSV time series, JSON summaries and SVG figures; and the checkpoints a run resumes from
//! ([`checkpoint`]).
//!
//! Every whole-file writer goes through [`write_atomic`]: the data is written to a hidden
//! temporary file beside the target, synced, and renamed over it, so a run killed mid-write
//! never leaves a truncated file behind. Files that grow ([`CsvWriter`]) flush after each row
//! instead, so a killed run keeps every complete row.

pub mod atomic;
pub mod checkpoint;
pub mod csv;
pub mod json;
pub mod plot;
pub mod pvd;
pub mod run_dir;
pub mod vtk;
mod vtk_appended;

pub use atomic::{write_atomic, write_atomic_bytes};
pub use csv::{CsvTable, CsvWriter};
pub use json::write_json;
pub use plot::{write_png, write_svg};
pub use pvd::{PvdEntry, PvdSeries};
pub use vtk::{
    write_vti, write_vtu_points, Compression, Field, FieldData, ImageGrid, Precision, VtkFormat,
};
