#![no_main]
//! Fuzz target: the JSON formats: handles, poses, colours.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    common::check(toposmooth::apps::handles::parse_handles(&text));
    common::check(toposmooth::apps::skinning::parse_pose(&text));
    common::check(toposmooth::apps::diffuse::parse_colors(&text));
});
