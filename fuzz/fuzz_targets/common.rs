//! Shared by the fuzz targets: the input as a file (the readers take paths, as the tool
//! does), and the rule every target checks: a reader may refuse the input, never panic,
//! and never report a panic it caught ([`toposmooth::io::READER_FAILURE`]).

use std::path::PathBuf;

#[allow(dead_code)]
/// Writes `data` to this process's scratch file with extension `ext`.
pub fn as_file(data: &[u8], ext: &str) -> PathBuf {
    let dir = std::env::var_os("TOPOSMOOTH_FUZZ_DIR").map(PathBuf::from).unwrap_or_else(std::env::temp_dir);
    let path = dir.join(format!("toposmooth-fuzz-{}.{ext}", std::process::id()));
    std::fs::write(&path, data).expect("scratch file");
    path
}

/// Panics (a crash for the fuzzer) if a reader's error reports a caught panic.
pub fn check<T>(result: toposmooth::Result<T>) {
    if let Err(e) = result {
        let text = e.to_string();
        assert!(!text.contains(toposmooth::io::READER_FAILURE), "a reader panicked: {text}");
    }
}
