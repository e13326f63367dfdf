#![no_main]
//! Fuzz target: PNG images as grids.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(toposmooth::io::grid::read_raster(&common::as_file(data, "png")));
});
