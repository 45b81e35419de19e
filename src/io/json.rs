//! JSON summaries (`summary.json`, `fits.json`).

use std::path::Path;

use crate::Result;

/// Serialises `value` as pretty-printed JSON (with a trailing newline) to `path`, atomically
/// through [`write_atomic`](super::write_atomic).
///
/// A serialisation failure (e.g. a map with non-string keys) is reported as
/// [`Error::Io`](crate::Error::Io) naming `path`, and leaves any previous file untouched.
pub fn write_json<T: serde::Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    super::write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Serialize)]
    struct Summary {
        runout: f64,
        steps: u64,
        name: &'static str,
    }

    #[test]
    fn writes_pretty_json() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.json");
        let s = Summary {
            runout: 0.1 + 0.2,
            steps: 42,
            name: "a2",
        };
        write_json(&path, &s).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("\n  \"steps\": 42"), "{text}");
        assert!(text.ends_with("}\n"));
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["runout"].as_f64().unwrap(), 0.1 + 0.2);
        assert_eq!(v["name"], "a2");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn serialisation_error_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.json");
        let mut m = std::collections::BTreeMap::new();
        m.insert((1, 2), 3.0);
        assert!(write_json(&path, &m).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
