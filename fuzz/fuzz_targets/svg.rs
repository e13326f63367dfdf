#![no_main]
//! Fuzz target: SVG outlines.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(toposmooth::apps::outline::read_outline(&common::as_file(data, "svg")));
});
