//! Atomic whole-file writes: write a temporary file beside the target, sync it, rename it over.

use std::fs::{self, File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// The temporary file used while writing `path`: `.<filename>.tmp` in the same directory, so
/// the final rename stays within one file system and is atomic.
pub(crate) fn temp_path(path: &Path) -> Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| {
        Error::io(
            path,
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "path has no file name to write to",
            ),
        )
    })?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(".tmp");
    Ok(path.with_file_name(tmp_name))
}

/// Writes a file atomically: `write` fills a temporary file `.<filename>.tmp` in the same
/// directory (through a buffered writer), which is then flushed, synced to disk
/// (`sync_all`) and renamed onto `path`.
///
/// Readers therefore see either the old file or the complete new one, never a partial one.
/// If `write` (or any later step) fails, the temporary file is removed and `path` is left as it
/// was. Errors are reported as [`Error::Io`] naming `path`.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    let tmp = temp_path(path)?;
    let result = write_then_rename(&tmp, path, write);
    if result.is_err() {
        // Best effort: the temp file may not even exist if creating it failed.
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(|e| Error::io(path, e))
}

fn write_then_rename<F>(tmp: &Path, path: &Path, write: F) -> std::io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    let file = OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(tmp)?;
    let mut buf = BufWriter::new(file);
    write(&mut buf)?;
    buf.flush()?;
    let file: File = buf.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    drop(file);
    fs::rename(tmp, path)
}

/// Writes `bytes` to `path` atomically; see [`write_atomic`].
pub fn write_atomic_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic(path, |w| w.write_all(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_and_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        write_atomic_bytes(&path, b"first").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"first");
        write_atomic_bytes(&path, b"second").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"second");
        assert!(!temp_path(&path).unwrap().exists());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn error_in_writer_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.txt");
        let err = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        })
        .unwrap_err();
        match err {
            Error::Io { path: p, source } => {
                assert_eq!(p, path);
                assert_eq!(source.to_string(), "boom");
            }
            other => panic!("unexpected error {other:?}"),
        }
        assert!(!path.exists());
        assert!(!temp_path(&path).unwrap().exists());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn error_keeps_previous_contents() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.txt");
        write_atomic_bytes(&path, b"good").unwrap();
        assert!(write_atomic(&path, |_| Err(std::io::Error::other("boom"))).is_err());
        assert_eq!(fs::read(&path).unwrap(), b"good");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn missing_directory_is_an_io_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/dir/d.txt");
        assert!(matches!(
            write_atomic_bytes(&path, b"x"),
            Err(Error::Io { .. })
        ));
    }
}
