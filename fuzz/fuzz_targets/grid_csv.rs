#![no_main]
//! Fuzz target: grid CSV files.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(toposmooth::io::grid::read_grid_csv(&common::as_file(data, "csv")));
});
