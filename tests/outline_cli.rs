//! `toposmooth mesh`: outlines from JSON, SVG and PNG triangulated by the command-line tool,
//! the meshes read back with toposmooth's own reader, and the errors of bad outlines.

mod common;

use common::{scratch, text, toposmooth};
use std::path::Path;
use toposmooth::domain::{triangle_area, TriMesh};
use toposmooth::io::mesh::read_mesh;

/// The mesh written at `path`, validated, and its total area.
fn read_back(path: &Path) -> (TriMesh, f64) {
    let data = read_mesh(path).unwrap_or_else(|e| panic!("{e}"));
    let mesh = TriMesh::new(data.positions, data.triangles).unwrap();
    let p = mesh.positions();
    let area = mesh.faces().iter().map(|t| triangle_area(p[t[0]], p[t[1]], p[t[2]])).sum();
    (mesh, area)
}

#[test]
fn a_json_outline_with_a_hole_is_meshed_and_reads_back() {
    let dir = scratch("outline-json");
    let input = dir.join("frame.json");
    std::fs::write(
        &input,
        r#"{"outline": [[0, 0], [2, 0], [2, 2], [0, 2]], "holes": [[[0.5, 0.5], [1, 0.5], [1, 1], [0.5, 1]]]}"#,
    )
    .unwrap();
    let (obj, png) = (dir.join("frame.obj"), dir.join("frame.png"));
    let o = toposmooth(&[
        "mesh",
        input.to_str().unwrap(),
        "-o",
        obj.to_str().unwrap(),
        "--max-area",
        "0.01",
        "--min-angle",
        "28",
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let out = text(&o);
    assert!(out.contains("1 hole") && out.contains("genus 0") && out.contains("wrote"), "{out}");
    let (mesh, area) = read_back(&obj);
    assert!((area - 3.75).abs() < 1e-12, "{area}");
    assert_eq!((mesh.boundary_loops(), mesh.euler_characteristic()), (2, 0));
    assert!(mesh.faces().len() >= 375);
    assert!(mesh.smallest_angle().1 >= 28.0 - 1e-9);
    let img = image::open(&png).unwrap().to_rgb8();
    assert!(img.width() > 500 && img.height() > 500);
    // the other formats hold the same mesh
    for ext in ["off", "ply", "vtu", "vtp"] {
        let path = dir.join(format!("frame.{ext}"));
        let o = toposmooth(&["mesh", input.to_str().unwrap(), "-o", path.to_str().unwrap(), "--max-area", "0.01"]);
        assert_eq!(o.status.code(), Some(0), "{ext}: {}", text(&o));
        let (m, a) = read_back(&path);
        assert!((a - 3.75).abs() < 1e-12, "{ext}: {a}");
        assert_eq!(m.euler_characteristic(), 0, "{ext}");
    }
}

#[test]
fn an_svg_drawing_is_meshed_with_its_holes() {
    let dir = scratch("outline-svg");
    let input = dir.join("plate.svg");
    // a 10 × 10 plate (relative commands) with a 3 × 3 square hole and a round hole (64-gon)
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10">
  <path d="m0 0 h10 v10 h-10 z M2 2 h3 v3 h-3 z" fill-rule="evenodd"/>
  <circle cx="7" cy="7" r="1.5"/>
</svg>"#;
    std::fs::write(&input, svg).unwrap();
    let obj = dir.join("plate.obj");
    let o = toposmooth(&["mesh", input.to_str().unwrap(), "-o", obj.to_str().unwrap(), "--max-area", "0.2"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let (mesh, area) = read_back(&obj);
    let n = 64.0;
    let disk = 0.5 * n * 1.5f64.powi(2) * (2.0 * std::f64::consts::PI / n).sin();
    assert!((area - (100.0 - 9.0 - disk)).abs() < 1e-9, "{area}");
    assert_eq!((mesh.boundary_loops(), mesh.euler_characteristic()), (3, -1));
    // y is negated: the plate spans y in [-10, 0]
    let ys: Vec<f64> = mesh.positions().iter().map(|p| p[1]).collect();
    assert_eq!(ys.iter().cloned().fold(f64::INFINITY, f64::min), -10.0);
    assert_eq!(ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max), 0.0);
}

#[test]
fn a_png_mask_is_meshed() {
    let dir = scratch("outline-png");
    let input = dir.join("ring.png");
    // a dark annulus on white, no alpha channel: radii 30 and 12
    let img = image::GrayImage::from_fn(80, 80, |x, y| {
        let d = ((x as f64 + 0.5 - 40.0).powi(2) + (y as f64 + 0.5 - 40.0).powi(2)).sqrt();
        image::Luma([if (12.0..=30.0).contains(&d) { 0 } else { 255 }])
    });
    img.save(&input).unwrap();
    let ply = dir.join("ring.ply");
    let o = toposmooth(&["mesh", input.to_str().unwrap(), "-o", ply.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let (mesh, area) = read_back(&ply);
    let ring = std::f64::consts::PI * (30.0f64.powi(2) - 12.0f64.powi(2));
    assert!((area - ring).abs() < 0.03 * ring, "{area} vs {ring}");
    assert_eq!((mesh.boundary_loops(), mesh.euler_characteristic()), (2, 0));
}

#[test]
fn bad_outlines_and_settings_are_refused() {
    let dir = scratch("outline-errors");
    let bowtie = dir.join("bowtie.json");
    std::fs::write(&bowtie, r#"{"outline": [[0, 0], [1, 1], [1, 0], [0, 1]]}"#).unwrap();
    let out = dir.join("bowtie.obj");
    let o = toposmooth(&["mesh", bowtie.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let msg = String::from_utf8_lossy(&o.stderr);
    assert!(msg.contains("bowtie.json") && msg.contains("edge 0") && msg.contains("crosses edge 2"), "{msg}");
    assert!(!out.exists(), "no output for a failed run");
    let outside = dir.join("outside.json");
    std::fs::write(&outside, r#"{"outline": [[0, 0], [1, 0], [1, 1], [0, 1]], "holes": [[[2, 2], [3, 2], [3, 3]]]}"#)
        .unwrap();
    let o = toposmooth(&["mesh", outside.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("outside.json") && text(&o).contains("not inside"), "{}", text(&o));
    let square = dir.join("square.json");
    std::fs::write(&square, r#"{"outline": [[0, 0], [1, 0], [1, 1], [0, 1]]}"#).unwrap();
    for args in [
        vec!["-o", "x.stl"],
        vec!["-o", out.to_str().unwrap(), "--min-angle", "50"],
        vec!["-o", out.to_str().unwrap(), "--max-area", "-1"],
        vec!["-o", out.to_str().unwrap(), "--plot", "x.jpg"],
        vec!["-o", square.to_str().unwrap()],
    ] {
        let mut all = vec!["mesh", square.to_str().unwrap()];
        all.extend(args.iter());
        let o = toposmooth(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o));
    }
}
