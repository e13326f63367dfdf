//! Inputs that can be read only once (the standard input, a FIFO, a device), copied to a
//! temporary file the readers can open as often as they need.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// An input that can be read only once (`-` for the standard input, a FIFO, a character
/// device), read once into a temporary file that the readers (which sniff, then read) open
/// as often as they need; removed when dropped.
pub(super) struct ReadOnce {
    tmp: PathBuf,
    original: PathBuf,
}

impl Drop for ReadOnce {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.tmp);
    }
}

impl ReadOnce {
    /// Copies `path` when it is `-`, a FIFO or a character device; `None` for a file.
    pub(super) fn of(path: &Path) -> Result<Option<ReadOnce>> {
        use std::io::Read;
        use std::os::unix::fs::FileTypeExt;
        let stdin = path.as_os_str() == "-";
        if !stdin {
            match std::fs::metadata(path) {
                Ok(m) if m.file_type().is_fifo() || m.file_type().is_char_device() => {}
                _ => return Ok(None),
            }
        }
        let io = |source| Error::Io { path: path.to_path_buf(), source };
        let mut bytes = Vec::new();
        if stdin {
            std::io::stdin().lock().read_to_end(&mut bytes).map_err(io)?;
        } else {
            std::fs::File::open(path).and_then(|mut f| f.read_to_end(&mut bytes)).map_err(io)?;
        }
        // the name's extension, else the content's: NPY by its magic, CSV otherwise
        let ext = match path.extension().and_then(|e| e.to_str()) {
            Some(e) if !e.is_empty() => e.to_string(),
            _ if bytes.starts_with(b"\x93NUMPY") => "npy".into(),
            _ => "csv".into(),
        };
        let nonce: u64 =
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64);
        let tmp = std::env::temp_dir().join(format!("toposmooth-input-{}-{nonce:x}.{ext}", std::process::id()));
        let write = std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp);
        write
            .and_then(|mut f| std::io::Write::write_all(&mut f, &bytes))
            .map_err(|source| Error::Io { path: tmp.clone(), source })?;
        Ok(Some(ReadOnce { tmp, original: path.to_path_buf() }))
    }

    /// The temporary copy the readers open.
    pub(super) fn path(&self) -> &Path {
        &self.tmp
    }

    /// What a message calls the input.
    pub(super) fn name(&self) -> PathBuf {
        if self.original.as_os_str() == "-" {
            PathBuf::from("standard input")
        } else {
            self.original.clone()
        }
    }
}
