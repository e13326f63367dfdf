//! Every crasher the fuzzers found (tests/corpus/TARGET/*) goes through the reader of its
//! target again: refused or read, never a panic, never a caught panic reported.

use std::path::Path;
use toposmooth::io::READER_FAILURE;

/// Runs the reader of fuzz target `target` on `path` (a copy with the target's extension).
fn read(target: &str, data: &[u8], scratch: &Path) -> Option<String> {
    use toposmooth::apps::{diffuse, handles, outline, skinning};
    use toposmooth::io::{grid, mesh, npz, series_csv, vtk};
    let file = |ext: &str| {
        let p = scratch.join(format!("input.{ext}"));
        std::fs::write(&p, data).unwrap();
        p
    };
    let err = |r: Result<(), toposmooth::Error>| r.err().map(|e| e.to_string());
    let text = String::from_utf8_lossy(data);
    let errors: Vec<Option<String>> = match target {
        "vtk_xml" => {
            vec![err(vtk::read_image(&file("vti")).map(drop)), err(mesh::read_trimesh(&file("vtu")).map(drop))]
        }
        "vtk_legacy" => {
            vec![err(vtk::read_image(&file("vtk")).map(drop)), err(mesh::read_trimesh(&file("vtk")).map(drop))]
        }
        "obj" | "off" | "ply" => vec![err(mesh::read_trimesh(&file(target)).map(drop))],
        "npy" => vec![err(grid::read_npy(&file("npy")).map(drop))],
        "npz" => vec![err(npz::read_npz(&file("npz")).map(drop))],
        "grid_csv" => vec![err(grid::read_grid_csv(&file("csv")).map(drop))],
        "series_csv" => {
            vec![err(series_csv::read_series(&file("csv"), &series_csv::SeriesCsvOptions::default()).map(drop))]
        }
        "png" => vec![err(grid::read_raster(&file("png")).map(drop))],
        "tiff" => vec![err(grid::read_raster(&file("tif")).map(drop))],
        "mask_png" => vec![err(outline::read_outline(&file("png")).map(drop))],
        "svg" => vec![err(outline::read_outline(&file("svg")).map(drop))],
        "json" => vec![
            err(handles::parse_handles(&text).map(drop)),
            err(skinning::parse_pose(&text).map(drop)),
            err(diffuse::parse_colors(&text).map(drop)),
        ],
        other => panic!("tests/corpus/{other}: no such fuzz target"),
    };
    errors.into_iter().flatten().find(|e| e.contains(READER_FAILURE))
}

#[test]
fn every_crasher_is_now_refused_or_read_without_a_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let scratch = std::env::temp_dir().join(format!("toposmooth-corpus-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).unwrap();
    let mut failures = Vec::new();
    let mut count = 0;
    for dir in std::fs::read_dir(&root).unwrap().map(|e| e.unwrap().path()).filter(|p| p.is_dir()) {
        let target = dir.file_name().unwrap().to_string_lossy().into_owned();
        for file in std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()) {
            count += 1;
            if let Some(e) = read(&target, &std::fs::read(&file).unwrap(), &scratch) {
                failures.push(format!("{}: {e}", file.display()));
            }
        }
    }
    std::fs::remove_dir_all(&scratch).unwrap();
    assert!(failures.is_empty(), "{} of {count} crashers still fail:\n{}", failures.len(), failures.join("\n"));
}
