//! The output folder of a run. A folder a run writes into is marked with [`MARKER`] when it is
//! created, so that a later command can tell a granflow run folder from any other folder:
//! a new run refuses a folder that already holds files unless asked to replace it
//! ([`prepare`] with `replace`), and then deletes only a marked folder's contents. A run
//! therefore never mixes its frames with an older run's, and `--force` cannot empty a folder
//! granflow did not write.

use std::fs;
use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// File that marks a folder as a granflow run's output.
pub const MARKER: &str = ".granflow-run";

/// Create `dir` (and its parents) if needed and mark it as a run folder.
pub fn create(dir: &Path) -> Result<()> {
    fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let marker = dir.join(MARKER);
    if !marker.exists() {
        let text = format!(
            "granflow {} output folder: `--force` may replace everything in it\n",
            env!("CARGO_PKG_VERSION")
        );
        fs::write(&marker, text).map_err(|e| Error::io(&marker, e))?;
    }
    Ok(())
}

/// Check, before a run starts, that it may write into `dir`: a folder that does not exist yet
/// (nothing is created here) or an empty one (the marker aside) is taken as it is; a folder
/// that holds files is refused, unless `replace` is set and the folder is marked as a granflow
/// run's ([`MARKER`]), in which case its contents are deleted. Then the folder (or, if it does not exist, the
/// nearest existing folder above it) must accept a new file: a probe file is written and
/// removed, so an unwritable place is refused now rather than when the first frame is due.
pub fn prepare(dir: &Path, replace: bool) -> Result<()> {
    if dir.exists() {
        if !dir.is_dir() {
            return Err(refusal(dir, "it exists and is not a folder"));
        }
        let entries = list(dir)?;
        if entries
            .iter()
            .any(|e| e.file_name() != Some(MARKER.as_ref()))
        {
            if !dir.join(MARKER).exists() {
                return Err(refusal(
                    dir,
                    format!(
                        "it holds {} entries and is not a granflow run folder (no {MARKER}); \
                         choose a new or empty folder (--force replaces only run folders)",
                        entries.len()
                    ),
                ));
            }
            if !replace {
                return Err(refusal(
                    dir,
                    "it holds an earlier run; pass --force to replace it (everything in the \
                     folder is deleted) or choose another folder",
                ));
            }
            for e in entries {
                let gone = if e.is_dir() {
                    fs::remove_dir_all(&e)
                } else {
                    fs::remove_file(&e)
                };
                gone.map_err(|err| Error::io(&e, err))?;
            }
        }
        probe(dir)
    } else {
        let mut above = dir.parent();
        while let Some(p) = above {
            let p = if p.as_os_str().is_empty() {
                Path::new(".")
            } else {
                p
            };
            if p.exists() {
                if !p.is_dir() {
                    return Err(refusal(dir, format!("{} is not a folder", p.display())));
                }
                return probe(p);
            }
            above = p.parent();
        }
        Ok(())
    }
}

fn refusal(dir: &Path, reason: impl Into<String>) -> Error {
    Error::Output {
        path: dir.to_path_buf(),
        reason: reason.into(),
    }
}

fn list(dir: &Path) -> Result<Vec<PathBuf>> {
    fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .map(|e| e.map(|e| e.path()).map_err(|e| Error::io(dir, e)))
        .collect()
}

/// Write and remove a small file in `dir`.
fn probe(dir: &Path) -> Result<()> {
    let p = dir.join(format!(".granflow-probe-{}", std::process::id()));
    fs::write(&p, b"probe")
        .and_then(|_| fs::remove_file(&p))
        .map_err(|e| refusal(dir, format!("{} is not writable: {e}", dir.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A new folder is not created by `prepare`; an empty one is taken; a run folder is refused
    /// without `replace` and emptied with it; a folder without the marker is never emptied.
    #[test]
    fn refuses_and_replaces_only_run_folders() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("a/b");
        prepare(&dir, false).unwrap();
        assert!(!dir.exists());
        create(&dir).unwrap();
        prepare(&dir, false).unwrap();
        fs::write(dir.join("frame_000009.vtu"), "old").unwrap();
        fs::create_dir(dir.join("case")).unwrap();
        let err = prepare(&dir, false).unwrap_err().to_string();
        assert!(err.contains("--out") && err.contains("--force"), "{err}");
        assert!(dir.join("frame_000009.vtu").exists());
        prepare(&dir, true).unwrap();
        assert_eq!(list(&dir).unwrap(), Vec::<PathBuf>::new());
        let mine = tmp.path().join("mine");
        fs::create_dir(&mine).unwrap();
        fs::write(mine.join("thesis.tex"), "keep").unwrap();
        let err = prepare(&mine, true).unwrap_err().to_string();
        assert!(err.contains("not a granflow run folder"), "{err}");
        assert!(mine.join("thesis.tex").exists());
        let file = tmp.path().join("file");
        fs::write(&file, "x").unwrap();
        assert!(prepare(&file, true).is_err() && prepare(&file.join("sub"), false).is_err());
    }
}
