#![no_main]
//! Fuzz target: NumPy .npy arrays.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(toposmooth::io::grid::read_npy(&common::as_file(data, "npy")));
});
