#![no_main]
//! Fuzz target: Wavefront OBJ meshes, validated.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(toposmooth::io::mesh::read_trimesh(&common::as_file(data, "obj")));
});
