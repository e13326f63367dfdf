//! `toposmooth mesh`: outlines from JSON, SVG and PNG triangulated by the command-line tool,
//! the meshes read back with toposmooth's own reader, and the errors of bad outlines.

mod common;

use common::{scratch, text, toposmooth};
use std::f64::consts::PI;
use std::path::Path;
use std::process::Output;
use toposmooth::apps::outline::CURVE_TOLERANCE;
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

/// How far the area of a flattened curved boundary can be from the exact one: usvg draws
/// elliptical arcs as cubics within 0.03 % of the largest radius `r` (at most a quarter turn
/// each, kurbo's bound), and the flattened cubics stay within `tol`, so the boundary lies in a
/// band of width `tol + 3e-4 r` along at most one ellipse's length (≤ 2π r).
fn round_bound(r: f64, tol: f64) -> f64 {
    let band = tol + 3e-4 * r;
    2.0 * PI * r * band + PI * band * band
}

/// Writes `svg` as `dir/name.svg` and meshes it into `dir/name.obj` with `--max-area`.
fn mesh_svg(dir: &Path, name: &str, svg: &str, max_area: &str) -> (Output, std::path::PathBuf) {
    let input = dir.join(format!("{name}.svg"));
    std::fs::write(&input, svg).unwrap();
    let obj = dir.join(format!("{name}.obj"));
    let o = toposmooth(&["mesh", input.to_str().unwrap(), "-o", obj.to_str().unwrap(), "--max-area", max_area]);
    (o, obj)
}

/// The number of corners the outline was read with, from the summary line.
fn corners(o: &Output) -> usize {
    let out = String::from_utf8_lossy(&o.stdout);
    let at = out.find("outline of ").expect("summary") + "outline of ".len();
    out[at..].split(' ').next().unwrap().parse().unwrap()
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
    // the circle's polygon within the flattening tolerance of a disk of radius 1.5
    let tol = CURVE_TOLERANCE * 200f64.sqrt();
    let disk = PI * 1.5f64.powi(2);
    assert!((area - (100.0 - 9.0 - disk)).abs() <= round_bound(1.5, tol), "{area}");
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

#[test]
fn hidden_shapes_are_not_part_of_the_outline() {
    let dir = scratch("outline-svg-hidden");
    // a hidden 100 × 100 square first, then the visible 20 × 20 one: the outline is the
    // visible square alone (area 400), not a frame around it (100² − 20² = 9,600)
    let visible = r#"<rect x="10" y="10" width="20" height="20"/>"#;
    for (name, hidden) in [
        ("display", r#"<rect width="100" height="100" style="display:none"/>"#.to_string()),
        ("class", r#"<style>.draft { display: none }</style><rect class="draft" width="100" height="100"/>"#.into()),
        ("visibility", r#"<g visibility="hidden"><rect width="100" height="100"/></g>"#.into()),
        ("defs", r#"<defs><rect width="100" height="100"/></defs>"#.into()),
    ] {
        let svg = format!(r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">{hidden}{visible}</svg>"#);
        let (o, obj) = mesh_svg(&dir, name, &svg, "1");
        assert_eq!(o.status.code(), Some(0), "{name}: {}", text(&o));
        let (mesh, area) = read_back(&obj);
        assert!((area - 400.0).abs() < 1e-9, "{name}: {area}");
        assert_eq!((mesh.boundary_loops(), mesh.euler_characteristic()), (1, 1), "{name}");
        assert_eq!(corners(&o), 4, "{name}");
        let xs: Vec<f64> = mesh.positions().iter().map(|p| p[0]).collect();
        assert_eq!(xs.iter().cloned().fold(f64::INFINITY, f64::min), 10.0, "{name}");
        assert_eq!(xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max), 30.0, "{name}");
    }
    // `visibility` is inherited but a child may be visible again; a hidden-only drawing is an error
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg"><g visibility="hidden"><rect width="100" height="100"/><rect x="10" y="10" width="20" height="20" visibility="visible"/></g></svg>"#;
    let (o, obj) = mesh_svg(&dir, "again", svg, "1");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!((read_back(&obj).1 - 400.0).abs() < 1e-9);
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg"><rect width="100" height="100" display="none"/></svg>"#;
    let (o, _) = mesh_svg(&dir, "nothing", svg, "1");
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("nothing.svg") && text(&o).contains("no shape found"), "{}", text(&o));
}

#[test]
fn use_clones_are_drawn() {
    let dir = scratch("outline-svg-use");
    // a 60 × 30 plate with two round holes of radius 5 cloned from <defs> (href and xlink:href)
    let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" viewBox="0 0 60 30">
  <defs><circle id="hole" r="5"/></defs>
  <rect width="60" height="30"/>
  <use href="#hole" x="15" y="15"/>
  <use xlink:href="#hole" transform="translate(45 15)"/>
</svg>"##;
    let (o, obj) = mesh_svg(&dir, "plate", svg, "0.5");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let (mesh, area) = read_back(&obj);
    let tol = CURVE_TOLERANCE * 60f64.hypot(30.0);
    let exact = 1800.0 - 2.0 * PI * 25.0;
    assert!((area - exact).abs() <= 2.0 * round_bound(5.0, tol), "{area} vs {exact}");
    assert_eq!((mesh.boundary_loops(), mesh.euler_characteristic()), (3, -1));
    // every vertex near a hole is on or outside its circle (chords cut inside by at most tol)
    for p in mesh.positions() {
        for c in [[15.0, -15.0], [45.0, -15.0]] {
            let d = (p[0] - c[0]).hypot(p[1] - c[1]);
            assert!(d >= 5.0 - tol - 3e-3, "{p:?} is {d} from {c:?}");
        }
    }
}

#[test]
fn lengths_in_mm_and_other_units_are_user_units() {
    let dir = scratch("outline-svg-units");
    // a 300 × 100 mm page whose user unit is the millimetre; absolute units inside are CSS
    // units of the user space (1 in = 96, 1 pt = 4/3, 1 mm = 96 / 25.4), % of the viewBox
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="300mm" height="100mm" viewBox="0 0 300 100">
  <rect width="300" height="100"/>
  <rect x="5mm" y="10" width="1in" height="36pt"/>
  <rect x="150" y="25%" width="2.54cm" height="10%"/>
</svg>"#;
    let (o, obj) = mesh_svg(&dir, "page", svg, "20");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let (mesh, area) = read_back(&obj);
    let exact = 300.0 * 100.0 - 96.0 * 48.0 - 96.0 * 10.0;
    assert!((area - exact).abs() < 1e-5 * exact, "{area} vs {exact}");
    assert_eq!((mesh.boundary_loops(), corners(&o)), (3, 12));
    let p = mesh.positions();
    let has = |x: f64, y: f64| p.iter().any(|q| (q[0] - x).abs() < 1e-4 && (q[1] - y).abs() < 1e-4);
    // the page in millimetres, not in CSS pixels (300 mm = 1133.9 px)
    assert!(has(300.0, -100.0) && has(0.0, 0.0));
    assert!(has(5.0 * 96.0 / 25.4, -10.0) && has(5.0 * 96.0 / 25.4 + 96.0, -58.0));
    assert!(has(246.0, -35.0));
}

#[test]
fn a_rounded_rectangle_has_its_area() {
    let dir = scratch("outline-svg-rounded");
    for (name, rx, ry, attrs) in [
        ("circular", 5.0, 5.0, r#"rx="5""#),
        ("elliptical", 8.0, 4.0, r#"rx="8" ry="4""#),
        ("clamped", 20.0, 10.0, r#"rx="30""#),
    ] {
        let svg = format!(r#"<svg xmlns="http://www.w3.org/2000/svg"><rect width="40" height="20" {attrs}/></svg>"#);
        let (o, obj) = mesh_svg(&dir, name, &svg, "0.5");
        assert_eq!(o.status.code(), Some(0), "{name}: {}", text(&o));
        let (mesh, area) = read_back(&obj);
        // the rectangle less four corners, each a square less a quarter ellipse
        let exact = 800.0 - (4.0 - PI) * rx * ry;
        let tol = CURVE_TOLERANCE * 40f64.hypot(20.0);
        assert!((area - exact).abs() <= round_bound(rx.max(ry), tol), "{name}: {area} vs {exact}");
        assert_eq!(mesh.boundary_loops(), 1);
        // on circular corners, as many corners as the tolerance needs and not twice as many: a
        // chord of a circle of radius r that is within tol of it spans at most 2 acos(1 − tol / r)
        let needed = |r: f64| (PI / 2.0 / (2.0 * (1.0 - tol / r).acos())).ceil() as usize;
        let at_least = if rx == ry { 4 * needed(rx) } else { 8 };
        let at_most = 4 * (2 * needed(rx.min(ry)) + 2);
        let n = corners(&o);
        assert!(n >= at_least && n <= at_most, "{name}: {n} corners, not in {at_least}..={at_most}");
    }
}

#[test]
fn transforms_are_applied() {
    let dir = scratch("outline-svg-transform");
    // a 100 × 100 plate; a 20 × 10 rectangle stretched ×2 in x, turned 30° about (50, 40); an
    // ellipse sheared by x' = x + y/2 − 42.5 (centre kept at (20, 85))
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
  <rect width="100" height="100"/>
  <g transform="translate(50 40) rotate(30)"><rect x="-10" y="-5" width="20" height="10" transform="scale(2 1)"/></g>
  <ellipse cx="20" cy="85" rx="6" ry="3" transform="matrix(1 0 0.5 1 -42.5 0)"/>
</svg>"#;
    let (o, obj) = mesh_svg(&dir, "plate", svg, "5");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let (mesh, area) = read_back(&obj);
    let tol = CURVE_TOLERANCE * 100.0 * 2f64.sqrt();
    // areas: scale(2 1) doubles the rectangle, rotations and the shear (determinant 1) keep areas
    let exact = 10000.0 - 400.0 - PI * 18.0;
    assert!((area - exact).abs() <= 1e-3 + round_bound(6.0 * 1.3, tol), "{area} vs {exact}");
    assert_eq!(mesh.boundary_loops(), 3);
    // the corner (10, 5) of the small rectangle: (20, 5) turned by 30° and moved, y negated
    let (s, c) = (PI / 6.0).sin_cos();
    let corner = [50.0 + 20.0 * c - 5.0 * s, -(40.0 + 20.0 * s + 5.0 * c)];
    let p = mesh.positions();
    assert!(p.iter().any(|q| (q[0] - corner[0]).abs() < 1e-4 && (q[1] - corner[1]).abs() < 1e-4), "{corner:?}");
    // the sheared ellipse (its largest radius at most 1.3 × 6): vertices on its boundary map
    // back onto the ellipse
    let on_ellipse = p.iter().filter(|q| q[1] < -75.0).filter(|q| {
        let y = -q[1];
        let x = q[0] - 0.5 * y + 42.5;
        let e = ((x - 20.0) / 6.0).powi(2) + ((y - 85.0) / 3.0).powi(2);
        (e - 1.0).abs() < 0.02
    });
    assert!(on_ellipse.count() >= 16);
}

#[test]
fn bad_svg_geometry_is_an_error_naming_the_element() {
    let dir = scratch("outline-svg-bad");
    let page = |shape: &str| {
        format!("<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 20 20\">\n  <rect width=\"20\" height=\"20\"/>\n  {shape}\n</svg>")
    };
    for (name, shape, needles) in [
        (
            "negative",
            r#"<circle id="bolt" cx="5" cy="5" r="-3"/>"#,
            vec![r#"<circle id="bolt"> at line 3"#, r#"`r="-3"` is negative"#],
        ),
        (
            "width",
            r#"<rect x="2" y="2" width="-5" height="4"/>"#,
            vec!["<rect> at line 3, column 3", r#"`width="-5"` is negative"#],
        ),
        (
            "infinite",
            r#"<ellipse cx="5" cy="5" rx="1e999" ry="1"/>"#,
            vec!["<ellipse> at line 3", "not a finite number"],
        ),
        ("path", r#"<path id="slot" d="M2 2 h4 v"/>"#, vec![r#"<path id="slot"> at line 3"#, "`d` cannot be read"]),
        (
            "crossing",
            r#"<polygon id="bowtie" points="2,2 8,8 8,2 2,8"/>"#,
            vec![r#"hole 1 (<polygon id="bowtie"> at line 3, column 3)"#, "crosses"],
        ),
        (
            "outside",
            r#"<circle cx="30" cy="5" r="2"/>"#,
            vec!["hole 1 (<circle> at line 3, column 3) is not inside the outer boundary"],
        ),
    ] {
        let (o, obj) = mesh_svg(&dir, name, &page(shape), "1");
        assert_eq!(o.status.code(), Some(3), "{name}: {}", text(&o));
        let msg = String::from_utf8_lossy(&o.stderr);
        assert!(msg.contains(&format!("{name}.svg")), "{name}: {msg}");
        for n in needles {
            assert!(msg.contains(n), "{name}: `{n}` not in {msg}");
        }
        assert!(!msg.contains("panicked") && !obj.exists(), "{name}: {msg}");
    }
}
