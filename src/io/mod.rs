//! Reading and writing files. Every output goes to a temporary file in the target's directory
//! and is renamed into place, so a failed run never leaves a half-written file.

pub mod content;
pub mod csv_dialect;
#[cfg(all(feature = "io-vtk", feature = "io-npz"))]
pub mod export;
pub mod grid;
#[cfg(feature = "io-vtk")]
pub mod mesh;
mod npy_header;
pub mod npy_input;
pub mod npz;
pub mod series_csv;
pub mod series_output;
pub mod timestamps;
#[cfg(feature = "io-vtk")]
pub mod vtk;

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The marker in the message of a reader that failed internally (a panic caught while
/// reading a file): the file is reported as bad input, the message says it is our bug.
pub const READER_FAILURE: &str = "[reader failure]";

/// Runs a reader on `path`, turning a panic inside it into an input error naming the file
/// (exit 3) that carries [`READER_FAILURE`]. Errors are given the file name.
///
/// # Errors
/// The reader's errors, and the caught panic.
pub fn guarded<T>(path: &Path, read: impl FnOnce() -> Result<T>) -> Result<T> {
    let read = || {
        // the tests' way into this branch (a reader that panics)
        if std::env::var_os("TOPOSMOOTH_DEBUG_PANIC").is_some_and(|v| v == "reader") {
            panic!("TOPOSMOOTH_DEBUG_PANIC=reader");
        }
        read()
    };
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(read)) {
        Ok(r) => r.map_err(|e| e.in_file(path)),
        Err(payload) => {
            let what = crate::error::take_last_panic().unwrap_or_else(|| panic_text(&*payload));
            Err(Error::input(format!(
                "{READER_FAILURE} the reader failed on this file ({what}): the file is malformed in a way \
                 toposmooth does not describe yet; please report it with the file"
            ))
            .in_file(path))
        }
    }
}

/// The text a panic was raised with.
pub fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "no message".into())
}

/// A complete file waiting under a temporary sibling name: [`Staged::commit`] renames it into
/// place; dropped uncommitted, it is removed. Staging every output of a command before
/// committing any means a failure leaves no output behind.
#[must_use = "a staged file is removed unless committed"]
pub struct Staged {
    tmp: PathBuf,
    path: PathBuf,
    committed: bool,
}

impl Staged {
    /// Renames the temporary file over the target.
    pub fn commit(mut self) -> Result<()> {
        std::fs::rename(&self.tmp, &self.path).map_err(|source| Error::Io { path: self.path.clone(), source })?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Stages `path`: `create` writes the complete temporary file at the path it is given.
pub fn stage_with(path: &Path, create: impl FnOnce(&Path) -> std::io::Result<()>) -> Result<Staged> {
    let staged = Staged { tmp: temp_sibling(path), path: path.to_path_buf(), committed: false };
    create(&staged.tmp).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    Ok(staged)
}

/// Stages `path`: `fill` writes the content, which is flushed and synced.
pub fn stage(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<Staged> {
    stage_with(path, |tmp| {
        let file = std::fs::File::create(tmp)?;
        let mut w = std::io::BufWriter::new(file);
        fill(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()
    })
}

/// Writes `path` atomically: [`stage`] then [`Staged::commit`].
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    stage(path, fill)?.commit()
}

/// A temporary name next to `path` (same directory, so the rename is atomic).
pub fn temp_sibling(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into());
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

#[cfg(feature = "serde")]
/// Stages a value as pretty JSON.
pub fn stage_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<Staged> {
    stage(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value).map_err(std::io::Error::other)?;
        writeln!(w)
    })
}

/// Shortest text that reads back to the same double (Rust's `Debug` for f64).
pub fn format_f64(v: f64) -> String {
    format!("{v:?}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shortest_round_trip() {
        for v in [0.1, 1.0 / 3.0, 1e-300, 6.02e23, -0.0, 123_456_789.123_456_78, f64::MIN_POSITIVE] {
            let s = format_f64(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
    }

    #[test]
    fn atomic_write_leaves_nothing_on_failure() {
        let dir = std::env::temp_dir().join(format!("toposmooth-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("x.txt");
        let r = write_atomic(&target, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert!(!target.exists());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        write_atomic(&target, |w| w.write_all(b"ok")).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "ok");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
