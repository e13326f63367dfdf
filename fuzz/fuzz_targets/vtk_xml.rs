#![no_main]
//! Fuzz target: VTK XML files (.vti, .vtp, .vtu) as images and as meshes.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(toposmooth::io::vtk::read_image(&common::as_file(data, "vti")));
    common::check(toposmooth::io::mesh::read_trimesh(&common::as_file(data, "vtu")));
});
