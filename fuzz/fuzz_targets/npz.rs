#![no_main]
//! Fuzz target: NumPy .npz archives.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(toposmooth::io::npz::read_npz(&common::as_file(data, "npz")));
});
