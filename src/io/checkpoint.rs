//! Checkpoint files: the state of a run, saved so that `granflow resume` continues it.
//!
//! A checkpoint is one file `checkpoint_<step>.ckpt` in the run's output folder:
//!
//! | bytes     | content                                                                |
//! |-----------|------------------------------------------------------------------------|
//! | 0–19      | the magic text `granflow checkpoint\n`                                 |
//! | 20–23     | format version ([`FORMAT_VERSION`]), u32 little-endian                 |
//! | 24–31     | body length in bytes, u64 little-endian                                |
//! | 32–35     | CRC-32 (IEEE) of the body, u32 little-endian                           |
//! | 36–       | body: the [`Header`], then the run's state, each in `postcard` form     |
//!
//! A file is written whole under a temporary name and renamed ([`write_atomic_bytes`]), and
//! only the two newest checkpoints of a folder are kept. Reading checks, in order, the magic,
//! the format version, the length (a truncated file), the checksum (a corrupt one), then the
//! header against the run that asks (same granflow version, kind and scenario text), so that a
//! state is never restored into a run it was not taken from.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use super::write_atomic_bytes;
use crate::{Error, Result};

/// The first bytes of every checkpoint.
const MAGIC: &[u8; 20] = b"granflow checkpoint\n";
/// Version of the layout above and of the states' encoding; a file of another is refused.
pub const FORMAT_VERSION: u32 = 3;
/// Bytes before the body.
const PREAMBLE: usize = MAGIC.len() + 4 + 8 + 4;
/// Checkpoints a folder keeps (the newest ones).
const KEEP: usize = 2;

/// What a checkpoint says of itself, checked before its state is used.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// granflow version that wrote it (`CARGO_PKG_VERSION`): another build may compute
    /// differently, so a resumed run would not continue the same trajectory.
    pub granflow: String,
    /// Scenario kind (`fluid`, `dem`, …).
    pub kind: String,
    /// [`scenario_hash`] of the scenario text the run was started with.
    pub scenario_hash: u64,
    /// Steps the run had taken (in the scale that sets its clock).
    pub step: u64,
    /// Simulated time (s).
    pub time: f64,
    /// Simulated seconds between checkpoints, as the run was started (`--checkpoint-every`).
    pub every: Option<f64>,
}

impl Header {
    /// A header for a run of `kind` from scenario text hashed to `scenario_hash`.
    pub fn new(kind: &str, scenario_hash: u64, step: u64, time: f64, every: Option<f64>) -> Self {
        Header {
            granflow: env!("CARGO_PKG_VERSION").into(),
            kind: kind.into(),
            scenario_hash,
            step,
            time,
            every,
        }
    }
}

/// FNV-1a (64 bit) of a scenario's text: the identity of the scenario a checkpoint belongs to.
pub fn scenario_hash(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Path of the checkpoint of `step` in `dir`.
fn file_of(dir: &Path, step: u64) -> PathBuf {
    dir.join(format!("checkpoint_{step:012}.ckpt"))
}

/// The checkpoints in `dir`, oldest first, with their steps (from their names).
pub fn list(dir: &Path) -> Result<Vec<(u64, PathBuf)>> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
        let path = entry.map_err(|e| Error::io(dir, e))?.path();
        let step = path
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(|n| n.strip_prefix("checkpoint_"))
            .and_then(|n| n.strip_suffix(".ckpt"))
            .and_then(|n| n.parse::<u64>().ok());
        if let Some(step) = step {
            found.push((step, path));
        }
    }
    found.sort();
    Ok(found)
}

/// Write the checkpoint of `header.step` with `state` into `dir` atomically, then delete all
/// but the two newest checkpoints there. Returns the file written.
pub fn write<S: Serialize>(dir: &Path, header: &Header, state: &S) -> Result<PathBuf> {
    let path = file_of(dir, header.step);
    let encode = |e: postcard::Error| Error::Other(format!("checkpoint {}: {e}", path.display()));
    let mut body = postcard::to_stdvec(header).map_err(encode)?;
    body.extend(postcard::to_stdvec(state).map_err(encode)?);
    let mut bytes = Vec::with_capacity(PREAMBLE + body.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(body.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(&body).to_le_bytes());
    bytes.extend_from_slice(&body);
    write_atomic_bytes(&path, &bytes)?;
    let all = list(dir)?;
    for (_, old) in &all[..all.len().saturating_sub(KEEP)] {
        std::fs::remove_file(old).map_err(|e| Error::io(old, e))?;
    }
    Ok(path)
}

/// Delete every checkpoint in `dir` (a run that completed has no use for them).
pub fn remove_all(dir: &Path) -> Result<()> {
    for (_, path) in list(dir)? {
        std::fs::remove_file(&path).map_err(|e| Error::io(&path, e))?;
    }
    Ok(())
}

/// A checkpoint read back: its header and state, the file, and the newer checkpoints that
/// could not be read (each with the reason), which a caller should report.
#[derive(Debug)]
pub struct Loaded<S> {
    /// The checked header.
    pub header: Header,
    /// The run's state.
    pub state: S,
    /// The file it came from.
    pub path: PathBuf,
    /// Newer checkpoints passed over as unreadable: "file: reason".
    pub skipped: Vec<String>,
}

/// Read the newest usable checkpoint in `dir` of a run of `kind` whose scenario text hashes
/// to `scenario_hash`. A newest file that is truncated or corrupt is passed over for the one
/// before it (and named in [`Loaded::skipped`]); a checkpoint of another scenario, kind,
/// format or granflow version is refused outright, as is a folder without a usable one.
pub fn read_latest<S: DeserializeOwned>(
    dir: &Path,
    kind: &str,
    scenario_hash: u64,
) -> Result<Loaded<S>> {
    let mut skipped = Vec::new();
    for (_, path) in list(dir)?.into_iter().rev() {
        match read(&path, kind, scenario_hash) {
            Ok((header, state)) => {
                return Ok(Loaded {
                    header,
                    state,
                    path,
                    skipped,
                })
            }
            Err(Unusable::Damaged(why)) => skipped.push(format!("{}: {why}", path.display())),
            Err(Unusable::Other(why)) => {
                return Err(Error::Other(format!(
                    "cannot resume from {}: {why}",
                    path.display()
                )))
            }
        }
    }
    let why = if skipped.is_empty() {
        "there is no checkpoint in it (a run writes them with --checkpoint-every, and when \
         stopped by SIGINT or SIGTERM)"
            .to_string()
    } else {
        format!("no checkpoint in it can be read: {}", skipped.join("; "))
    };
    Err(Error::Other(format!(
        "cannot resume the run in {}: {why}",
        dir.display()
    )))
}

/// Why a checkpoint cannot be used: damaged (truncated, corrupt: an older one may do), or
/// written by another run or build (no older one will do either).
enum Unusable {
    Damaged(String),
    Other(String),
}

/// Read and check one checkpoint file.
fn read<S: DeserializeOwned>(
    path: &Path,
    kind: &str,
    scenario_hash: u64,
) -> std::result::Result<(Header, S), Unusable> {
    let bytes = std::fs::read(path).map_err(|e| Unusable::Damaged(e.to_string()))?;
    if bytes.len() < PREAMBLE || &bytes[..MAGIC.len()] != MAGIC {
        return Err(Unusable::Damaged(
            "not a granflow checkpoint (its first bytes are not `granflow checkpoint`)".into(),
        ));
    }
    let word = |at: usize, n: usize| {
        bytes[at..at + n]
            .iter()
            .rev()
            .fold(0u64, |v, &b| v << 8 | b as u64)
    };
    let version = word(20, 4) as u32;
    if version != FORMAT_VERSION {
        return Err(Unusable::Other(format!(
            "it has checkpoint format {version}, this granflow reads format {FORMAT_VERSION}"
        )));
    }
    let (len, crc) = (word(24, 8), word(32, 4) as u32);
    let body = &bytes[PREAMBLE..];
    if body.len() as u64 != len {
        return Err(Unusable::Damaged(format!(
            "truncated: {} bytes of state where its preamble announces {len}",
            body.len()
        )));
    }
    if crc32fast::hash(body) != crc {
        return Err(Unusable::Damaged(
            "corrupt: its checksum does not match its contents".into(),
        ));
    }
    let undecodable = |e: postcard::Error| Unusable::Damaged(format!("undecodable: {e}"));
    let (header, rest): (Header, _) = postcard::take_from_bytes(body).map_err(undecodable)?;
    let ours = env!("CARGO_PKG_VERSION");
    if header.granflow != ours {
        return Err(Unusable::Other(format!(
            "it was written by granflow {}, this is {ours}; a run continues only with the build \
             that started it",
            header.granflow
        )));
    }
    if header.kind != kind {
        return Err(Unusable::Other(format!(
            "it holds a `{}` run, the scenario is a `{kind}` one",
            header.kind
        )));
    }
    if header.scenario_hash != scenario_hash {
        return Err(Unusable::Other(
            "it was taken from another scenario text: the run's scenario.toml was changed \
             since (start a new run instead)"
                .into(),
        ));
    }
    let state = postcard::from_bytes(rest).map_err(undecodable)?;
    Ok((header, state))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(step: u64) -> Header {
        Header::new(
            "fluid",
            scenario_hash("kind = \"fluid\""),
            step,
            step as f64,
            None,
        )
    }

    #[test]
    fn a_checkpoint_reads_back_and_only_the_two_newest_are_kept() {
        let dir = tempfile::tempdir().unwrap();
        for step in [10, 20, 30] {
            write(dir.path(), &header(step), &vec![step as f64; 3]).unwrap();
        }
        let steps: Vec<u64> = list(dir.path()).unwrap().iter().map(|c| c.0).collect();
        assert_eq!(steps, [20, 30]);
        let l: Loaded<Vec<f64>> =
            read_latest(dir.path(), "fluid", header(0).scenario_hash).unwrap();
        assert_eq!((l.header, l.state), (header(30), vec![30.0; 3]));
        assert!(l.skipped.is_empty());
    }

    #[test]
    fn a_damaged_newest_checkpoint_falls_back_to_the_one_before() {
        let dir = tempfile::tempdir().unwrap();
        let hash = header(0).scenario_hash;
        write(dir.path(), &header(10), &1.0f64).unwrap();
        let newest = write(dir.path(), &header(20), &2.0f64).unwrap();
        let mut bytes = std::fs::read(&newest).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        std::fs::write(&newest, &bytes).unwrap();
        let l: Loaded<f64> = read_latest(dir.path(), "fluid", hash).unwrap();
        assert_eq!((l.header.step, l.state), (10, 1.0));
        assert!(l.skipped[0].contains("corrupt"), "{:?}", l.skipped);
        // Truncate both: nothing left to resume from, and the message says why for each.
        for (_, p) in list(dir.path()).unwrap() {
            let b = std::fs::read(&p).unwrap();
            std::fs::write(&p, &b[..b.len() - 3]).unwrap();
        }
        let e = read_latest::<f64>(dir.path(), "fluid", hash)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("truncated") && e.contains("checkpoint_000000000010"),
            "{e}"
        );
    }

    #[test]
    fn a_checkpoint_of_another_scenario_kind_or_format_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let hash = header(0).scenario_hash;
        let path = write(dir.path(), &header(10), &1.0f64).unwrap();
        let e = read_latest::<f64>(dir.path(), "fluid", hash ^ 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("another scenario text"), "{e}");
        let e = read_latest::<f64>(dir.path(), "dem", hash)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`fluid` run"), "{e}");
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[20] = 9;
        std::fs::write(&path, &bytes).unwrap();
        let e = read_latest::<f64>(dir.path(), "fluid", hash)
            .unwrap_err()
            .to_string();
        assert!(e.contains("format 9"), "{e}");
        std::fs::write(&path, b"not a checkpoint at all, just text").unwrap();
        let e = read_latest::<f64>(dir.path(), "fluid", hash)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a granflow checkpoint"), "{e}");
    }
}
