#![no_main]
//! Fuzz target: legacy .vtk files as images and as meshes.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(toposmooth::io::vtk::read_image(&common::as_file(data, "vtk")));
    common::check(toposmooth::io::mesh::read_trimesh(&common::as_file(data, "vtk")));
});
