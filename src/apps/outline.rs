//! 2D shapes from outlines: read a polygon outline (JSON, SVG or a PNG mask) and triangulate its
//! interior by constrained Delaunay refinement (Ruppert's and Chew's algorithms as implemented
//! by the `spade` crate), so that 2D deformation and diffusion can start from a drawing.
//!
//! An [`Outline`] is a list of closed polygons: `loops[0]` is the outer boundary and the others
//! are holes. [`triangulate`] checks it ([`Outline::validate`]: no crossing or touching edges,
//! holes inside the outer boundary and apart from each other) and meshes the region inside the
//! outer boundary and outside every hole with triangles no larger than a given area and, away
//! from sharp corners of the outline itself, no angle smaller than a given limit.
//!
//! ```
//! use toposmooth::apps::outline::{triangulate, Outline};
//! let square = Outline { loops: vec![vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]] };
//! let mesh = triangulate(&square, Some(0.01), 25.0)?;
//! assert_eq!(mesh.boundary_loops(), 1);
//! assert!(mesh.faces().len() >= 100);
//! # Ok::<(), toposmooth::Error>(())
//! ```

mod png;
mod shape;
mod svg;

use shape::{fmt_point, loop_name, orient, short};
pub use shape::{
    Outline, CURVE_TOLERANCE, DEFAULT_AREA_DIVISOR, DEFAULT_MIN_ANGLE, MAX_MIN_ANGLE, MAX_TRIANGLES, TRACE_TOLERANCE,
};

use crate::domain::TriMesh;
use crate::error::{Error, Result};
use spade::{AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};
use std::collections::HashSet;
use std::path::Path;

/// Reads an outline; the format follows the extension:
///
/// - `.json`: `{"outline": [[x, y], ...], "holes": [[[x, y], ...], ...]}` (`holes` optional;
///   `cage` is accepted for `outline`, as in `handles.json`).
/// - `.svg`: the document as drawn, read with usvg (CSS in `<style>` and `style`, `display`,
///   `visibility`, units (mm, cm, in, pt, pc, %, em), `<use>`, `<symbol>`, nested `<svg>`,
///   transforms; `<rect>` with `rx`/`ry`, `<circle>`, `<ellipse>`, `<polygon>`, `<polyline>`,
///   `<path>`). Every visible filled shape counts (not those with `fill="none"`, nor text,
///   images, markers, strokes; `clip-path` and `mask` are not applied); each of its subpaths
///   is a closed loop (as SVG fills them), the first the outer boundary and later ones holes,
///   whatever the `fill-rule`. Subpaths that enclose nothing (a `<line>`, two points) are left
///   out. Curves are flattened into points at equal parameter steps, as many as keep each
///   within [`CURVE_TOLERANCE`] × the diagonal of the drawing's bounding box (its corners and
///   control points); usvg draws elliptical arcs as cubics of at most a quarter turn, within
///   0.03 % of the radius. Coordinates are the root's user units (the `viewBox` mapping to
///   the page undone, so a drawing in mm stays in mm) with y negated (SVG's y points down),
///   so the shape stays upright. usvg computes in 32-bit floats (about 7 significant digits).
///   The loops are validated when read ([`Outline::validate`]), with messages naming the
///   SVG element of each loop.
/// - `.png`: a mask. Inside are the pixels with alpha ≥ 50 %; without an alpha channel (or
///   when every pixel is opaque) the dark ones (grey level < 50 %). The boundary of the
///   largest 4-connected inside region (islands elsewhere are dropped) is traced along pixel
///   edges, holes included, and simplified by Douglas–Peucker with tolerance
///   [`TRACE_TOLERANCE`] pixels. Coordinates are pixel corners with y up: pixel (row r,
///   column c) of an image h rows high covers `[c, c + 1] × [h − 1 − r, h − r]`, so the image
///   spans `[0, w] × [0, h]`. Where two inside pixels touch only at a corner, each boundary
///   passing there is moved a quarter pixel into its own pixel, so loops never touch.
///
/// Repeated consecutive corners (and a last corner equal to the first) are dropped. JSON and
/// PNG outlines are not validated here: [`triangulate`] does it.
///
/// # Errors
/// Input errors naming the file: an unknown extension, malformed content, a PNG with no inside
/// pixel; in an SVG, invalid geometry naming the element (its id, tag, line and column): a
/// negative width, height or radius, a number that is not finite, malformed `points`, `d` or
/// `transform`, no visible filled shape, loops that cross, touch or nest wrongly. I/O errors.
pub fn read_outline(path: &Path) -> Result<Outline> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let loops = match ext.as_str() {
        "json" => read_json(&bytes),
        "svg" => svg::read_svg(&bytes),
        "png" => png::read_png(&bytes),
        other => Err(Error::input(format!("`.{other}` is not an outline format (json, svg, png)"))),
    }
    .map_err(|e| e.in_file(path))?;
    let outline = Outline { loops }.cleaned();
    if outline.loops.is_empty() {
        return Err(Error::input("the file holds no outline").in_file(path));
    }
    Ok(outline)
}

fn read_json(bytes: &[u8]) -> Result<Vec<Vec<[f64; 2]>>> {
    const FORM: &str = r#"{"outline": [[x, y], ...], "holes": [[[x, y], ...], ...]}"#;
    let value: serde_json::Value =
        serde_json::from_slice(bytes).map_err(|e| Error::input(format!("not valid JSON: {e}")))?;
    let obj = value.as_object().ok_or_else(|| Error::input(format!("the outline must be a JSON object {FORM}")))?;
    if let Some(key) = obj.keys().find(|k| !["outline", "cage", "holes"].contains(&k.as_str())) {
        return Err(Error::input(format!("unknown key `{key}`; expected {FORM}")));
    }
    let (key, outer) = match (obj.get("outline"), obj.get("cage")) {
        (Some(o), None) => ("outline", o),
        (None, Some(c)) => ("cage", c),
        (Some(_), Some(_)) => return Err(Error::input("give either `outline` or `cage`, not both")),
        (None, None) => return Err(Error::input(format!("no `outline` key; expected {FORM}"))),
    };
    let points = |v: &serde_json::Value, what: &str| -> Result<Vec<[f64; 2]>> {
        let list = v.as_array().ok_or_else(|| Error::input(format!("{what} must be a list of [x, y] points")))?;
        list.iter()
            .enumerate()
            .map(|(i, p)| match p.as_array().map(|a| a.iter().map(|x| x.as_f64()).collect::<Vec<_>>()) {
                Some(c) if c.len() == 2 && c.iter().all(Option::is_some) => {
                    Ok([c[0].unwrap_or_default(), c[1].unwrap_or_default()])
                }
                _ => Err(Error::input(format!("{what}: point {i} is `{p}`, not [x, y]"))),
            })
            .collect()
    };
    let mut loops = vec![points(outer, &format!("`{key}`"))?];
    if let Some(holes) = obj.get("holes") {
        let list =
            holes.as_array().ok_or_else(|| Error::input("`holes` must be a list of loops [[[x, y], ...], ...]"))?;
        for (h, hole) in list.iter().enumerate() {
            loops.push(points(hole, &format!("`holes` loop {h} (hole {})", h + 1))?);
        }
    }
    Ok(loops)
}

/// Checks the meshing settings: `max_area` (if given) finite and positive, `min_angle_deg` in
/// `0..=`[`MAX_MIN_ANGLE`].
///
/// # Errors
/// [`Error::Setting`] naming the setting.
pub fn check_settings(max_area: Option<f64>, min_angle_deg: f64) -> Result<()> {
    if let Some(a) = max_area {
        if !(a.is_finite() && a > 0.0) {
            return Err(Error::setting("max_area", format!("must be a positive number, got {a}")));
        }
    }
    if !(min_angle_deg.is_finite() && (0.0..=MAX_MIN_ANGLE).contains(&min_angle_deg)) {
        return Err(Error::setting(
            "min_angle",
            format!(
                "must be between 0 and {MAX_MIN_ANGLE} degrees (refinement may not end above ~30°), got {min_angle_deg}"
            ),
        ));
    }
    Ok(())
}

/// Validates the outline ([`Outline::validate`]), then triangulates its interior by
/// constrained Delaunay refinement (spade): every triangle has area at most `max_area` (`None`:
/// the outer boundary's bounding-box area / [`DEFAULT_AREA_DIVISOR`]) and no angle below
/// `min_angle_deg` ([`DEFAULT_MIN_ANGLE`] is a good choice), except where the outline itself
/// has a sharper corner. The outside and the holes get no triangle.
///
/// The mesh lies in the plane z = 0 with counter-clockwise triangles. Its first vertices are
/// the outline's corners, loop by loop and in order; refinement adds vertices after them,
/// also on the boundary (which keeps its shape: split edges stay on the outline's segments).
/// The caller reports the counts and [`TriMesh::smallest_angle`].
///
/// # Errors
/// [`Error::Setting`] for settings out of range ([`check_settings`]) or a `max_area` asking for
/// more than [`MAX_TRIANGLES`] triangles; [`Error::Input`] for an invalid outline, a
/// coordinate the triangulation cannot take (|x| above about 1e60 or below 1e-42, other
/// than 0), or a refinement that stops at its vertex limit (sharp corners of the outline with
/// a high angle limit).
pub fn triangulate(outline: &Outline, max_area: Option<f64>, min_angle_deg: f64) -> Result<TriMesh> {
    check_settings(max_area, min_angle_deg)?;
    let outline = outline.cleaned();
    outline.validate()?;
    let (lo, hi) = outline.bounds();
    let max_area = max_area.unwrap_or((hi[0] - lo[0]) * (hi[1] - lo[1]) / DEFAULT_AREA_DIVISOR);
    let estimate = outline.area() / max_area;
    if estimate > MAX_TRIANGLES {
        return Err(Error::setting(
            "max_area",
            format!(
                "{max_area} asks for more than {estimate:.3e} triangles over an area of {}; at most {MAX_TRIANGLES:e} are made: raise it",
                short(outline.area())
            ),
        ));
    }
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut handles = Vec::with_capacity(outline.loops.len());
    for (k, l) in outline.loops.iter().enumerate() {
        let mut hs = Vec::with_capacity(l.len());
        for (i, p) in l.iter().enumerate() {
            let h = cdt.insert(Point2::new(p[0], p[1])).map_err(|e| {
                Error::input(format!(
                    "{}: corner {i} at {} cannot be triangulated ({e:?}: coordinates must be 0 or between about 1e-42 and 1e60 in size; rescale the outline)",
                    loop_name(k),
                    fmt_point(*p)
                ))
            })?;
            hs.push(h);
        }
        handles.push(hs);
    }
    let n_input = outline.n_points();
    if cdt.num_vertices() != n_input {
        return Err(Error::input("two corners of the outline are at the same position"));
    }
    for (k, hs) in handles.iter().enumerate() {
        for i in 0..hs.len() {
            if cdt.try_add_constraint(hs[i], hs[(i + 1) % hs.len()]).is_empty() {
                return Err(Error::input(format!("edge {i} of {} meets another edge of the outline", loop_name(k))));
            }
        }
    }
    let budget = 10 * n_input + (4.0 * estimate).ceil() as usize + 1000;
    let params = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .with_max_allowed_area(max_area)
        .with_angle_limit(AngleLimit::from_deg(min_angle_deg))
        .with_max_additional_vertices(budget);
    let result = cdt.refine(params);
    if !result.refinement_complete {
        return Err(Error::input(format!(
            "the refinement stopped at its limit of {budget} added vertices before every triangle had area ≤ {} and angles ≥ {min_angle_deg}°: lower --min-angle (sharp corners of the outline keep asking for more) or raise --max-area",
            short(max_area)
        )));
    }
    let excluded: HashSet<_> = result.excluded_faces.into_iter().collect();
    let kept: Vec<[usize; 3]> = cdt
        .inner_faces()
        .filter(|f| !excluded.contains(&f.fix()))
        .map(|f| f.vertices().map(|v| v.fix().index()))
        .collect();
    let mut index = vec![usize::MAX; cdt.num_vertices()];
    for t in &kept {
        for &v in t {
            index[v] = 0;
        }
    }
    let mut positions = Vec::new();
    for (v, handle) in cdt.vertices().enumerate() {
        if index[v] == 0 {
            index[v] = positions.len();
            let p = handle.position();
            positions.push([p.x, p.y, 0.0]);
        }
    }
    let triangles: Vec<[usize; 3]> = kept
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| index[v]);
            let (pa, pb, pc) = (positions[a], positions[b], positions[c]);
            if orient([pa[0], pa[1]], [pb[0], pb[1]], [pc[0], pc[1]]) < 0.0 {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect();
    TriMesh::new(positions, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::triangle_area;

    fn square(x0: f64, y0: f64, s: f64) -> Vec<[f64; 2]> {
        vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]]
    }

    fn areas(m: &TriMesh) -> Vec<f64> {
        let p = m.positions();
        m.faces().iter().map(|t| triangle_area(p[t[0]], p[t[1]], p[t[2]])).collect()
    }

    fn signed(m: &TriMesh) -> Vec<f64> {
        let p = m.positions();
        m.faces()
            .iter()
            .map(|t| {
                let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
                (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
            })
            .collect()
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("toposmooth-outline-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d.join(name)
    }

    #[test]
    fn unit_square_meets_the_area_and_angle_bounds() {
        let o = Outline { loops: vec![square(0.0, 0.0, 1.0)] };
        for (max_area, limit) in [(0.01, 25.0), (0.002, 30.0), (0.05, 20.0)] {
            let m = triangulate(&o, Some(max_area), limit).unwrap();
            let a = areas(&m);
            assert!(a.iter().all(|&x| x <= max_area), "largest {}", a.iter().cloned().fold(0.0, f64::max));
            let total: f64 = a.iter().sum();
            assert!((total - 1.0).abs() < 1e-12, "{total}");
            assert!(a.len() as f64 >= 1.0 / max_area);
            let (_, smallest) = m.smallest_angle();
            assert!(smallest >= limit - 1e-9, "{smallest} < {limit}");
            assert!(signed(&m).iter().all(|&s| s > 0.0), "counter-clockwise");
            assert!(m.is_planar());
            assert_eq!((m.n_components(), m.boundary_loops(), m.euler_characteristic()), (1, 1, 1));
            // the outline's corners come first
            assert_eq!(&m.positions()[..4], &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        }
        // the default area: bounding box / 2000
        let m = triangulate(&o, None, DEFAULT_MIN_ANGLE).unwrap();
        assert!(areas(&m).iter().all(|&x| x <= 1.0 / DEFAULT_AREA_DIVISOR));
        // the orientation of the input does not matter
        let mut cw = square(0.0, 0.0, 1.0);
        cw.reverse();
        let m = triangulate(&Outline { loops: vec![cw] }, Some(0.01), 25.0).unwrap();
        assert!(signed(&m).iter().all(|&s| s > 0.0));
    }

    #[test]
    fn square_with_a_square_hole() {
        let o = Outline { loops: vec![square(0.0, 0.0, 1.0), square(0.3, 0.4, 0.25)] };
        let m = triangulate(&o, Some(0.005), 25.0).unwrap();
        let total: f64 = areas(&m).iter().sum();
        assert!((total - (1.0 - 0.0625)).abs() < 1e-12, "{total}");
        assert_eq!(m.euler_characteristic(), 0);
        assert_eq!(m.boundary_loops(), 2);
        assert_eq!(m.n_components(), 1);
        // no triangle inside the hole
        let p = m.positions();
        for t in m.faces() {
            let c = [0, 1].map(|k| (p[t[0]][k] + p[t[1]][k] + p[t[2]][k]) / 3.0);
            assert!(!(c[0] > 0.3 && c[0] < 0.55 && c[1] > 0.4 && c[1] < 0.65), "{c:?}");
        }
        // the hole's boundary: boundary edges with both ends on the hole's square
        let on_hole = |q: [f64; 3]| {
            let (x, y) = (q[0], q[1]);
            (0.3..=0.55).contains(&x) && (0.4..=0.65).contains(&y)
        };
        let mut count = std::collections::HashMap::new();
        for t in m.faces() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let hole_edges: Vec<_> = count.iter().filter(|(e, &c)| c == 1 && on_hole(p[e.0]) && on_hole(p[e.1])).collect();
        let len: f64 = hole_edges
            .iter()
            .map(|(e, _)| ((p[e.0][0] - p[e.1][0]).powi(2) + (p[e.0][1] - p[e.1][1]).powi(2)).sqrt())
            .sum();
        assert!((len - 1.0).abs() < 1e-12, "hole perimeter {len}");
    }

    #[test]
    fn a_bowtie_is_an_error_naming_its_edges() {
        let o = Outline { loops: vec![vec![[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]] };
        let e = triangulate(&o, None, 25.0).unwrap_err();
        let msg = e.to_string();
        assert_eq!(e.exit_code(), 3);
        assert!(msg.contains("edge 0 (corners 0→1) of the outer boundary"), "{msg}");
        assert!(msg.contains("crosses edge 2 (corners 2→3)") && msg.contains("(0.5, 0.5)"), "{msg}");
        // touching: a corner on another edge; doubling back; a repeated corner
        let touch = Outline { loops: vec![vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [1.0, 0.0], [0.0, 2.0]]] };
        let msg = touch.validate().unwrap_err().to_string();
        assert!(msg.contains("touches") && msg.contains("(1, 0)"), "{msg}");
        let spike = Outline { loops: vec![vec![[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [1.0, 1.0]]] };
        let msg = spike.validate().unwrap_err().to_string();
        assert!(msg.contains("overlap"), "{msg}");
        let repeat =
            Outline { loops: vec![vec![[0.0, 0.0], [1.0, 1.0], [2.0, 0.0], [2.0, 2.0], [1.0, 1.0], [0.0, 2.0]]] };
        assert!(repeat.validate().unwrap_err().to_string().contains("touches"));
        // a hole crossing the outer boundary
        let o = Outline { loops: vec![square(0.0, 0.0, 1.0), square(0.5, 0.5, 1.0)] };
        let msg = o.validate().unwrap_err().to_string();
        assert!(msg.contains("of the outer boundary crosses") && msg.contains("of hole 1"), "{msg}");
    }

    #[test]
    fn holes_outside_or_nested_are_errors() {
        let o = Outline { loops: vec![square(0.0, 0.0, 1.0), square(2.0, 0.0, 0.5)] };
        let e = triangulate(&o, None, 25.0).unwrap_err();
        assert_eq!(e.exit_code(), 3);
        assert!(e.to_string().contains("hole 1 is not inside the outer boundary"), "{e}");
        let o = Outline { loops: vec![square(0.0, 0.0, 4.0), square(1.0, 1.0, 2.0), square(1.5, 1.5, 0.5)] };
        assert!(o.validate().unwrap_err().to_string().contains("hole 2 lies inside hole 1"));
        let o = Outline { loops: vec![vec![[0.0, 0.0], [1.0, 0.0]]] };
        assert!(o.validate().unwrap_err().to_string().contains("at least 3"));
        let o = Outline { loops: vec![vec![[0.0, 0.0], [1.0, 0.0], [f64::NAN, 1.0]]] };
        assert!(o.validate().unwrap_err().to_string().contains("not finite"));
    }

    #[test]
    fn settings_out_of_range_are_usage_errors() {
        let o = Outline { loops: vec![square(0.0, 0.0, 1.0)] };
        for (a, angle) in [(Some(0.0), 25.0), (Some(-1.0), 25.0), (Some(f64::NAN), 25.0), (None, 40.0), (None, -1.0)] {
            assert_eq!(triangulate(&o, a, angle).unwrap_err().exit_code(), 2, "{a:?} {angle}");
        }
        let e = triangulate(&o, Some(1e-9), 25.0).unwrap_err();
        assert!(e.to_string().contains("raise it"), "{e}");
    }

    #[test]
    fn json_outlines_with_holes_are_read() {
        let p = scratch("ring.json");
        std::fs::write(&p, r#"{"outline": [[0,0],[4,0],[4,4],[0,4],[0,0]], "holes": [[[1,1],[1,2],[2,2],[2,1]]]}"#)
            .unwrap();
        let o = read_outline(&p).unwrap();
        assert_eq!(o.loops.len(), 2);
        assert_eq!(o.loops[0].len(), 4, "the repeated first point is dropped");
        assert_eq!(o.area(), 15.0);
        let m = triangulate(&o, Some(0.1), 25.0).unwrap();
        assert!((areas(&m).iter().sum::<f64>() - 15.0).abs() < 1e-12);
        let cage = scratch("cage.json");
        std::fs::write(&cage, r#"{"cage": [[0,0],[1,0],[0,1]]}"#).unwrap();
        assert_eq!(read_outline(&cage).unwrap().loops, vec![vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]]);
        for (name, text, needle) in [
            ("bad1.json", "[1, 2]", "JSON object"),
            ("bad2.json", r#"{"outline": [[0,0],[1],[0,1]]}"#, "point 1 is `[1]`"),
            ("bad3.json", r#"{"outline": [[0,0],[1,0],[0,1]], "hole": []}"#, "unknown key `hole`"),
            ("bad4.json", "{", "not valid JSON"),
            ("bad.txt", "x", "not an outline format"),
        ] {
            let p = scratch(name);
            std::fs::write(&p, text).unwrap();
            let e = read_outline(&p).unwrap_err();
            assert_eq!(e.exit_code(), 3);
            assert!(e.to_string().contains(needle) && e.to_string().contains(name), "{e}");
        }
    }

    #[test]
    fn a_traced_disk_has_the_disk_area() {
        let (w, h, r, c) = (100u32, 90u32, 35.0f64, [48.3, 44.7]);
        let img = image::RgbaImage::from_fn(w, h, |x, y| {
            let d = ((x as f64 + 0.5 - c[0]).powi(2) + (y as f64 + 0.5 - c[1]).powi(2)).sqrt();
            image::Rgba([0, 0, 0, if d <= r { 255 } else { 0 }])
        });
        let p = scratch("disk.png");
        img.save(&p).unwrap();
        let o = read_outline(&p).unwrap();
        assert_eq!(o.loops.len(), 1);
        let m = triangulate(&o, Some(5.0), 25.0).unwrap();
        let total: f64 = areas(&m).iter().sum();
        let disk = std::f64::consts::PI * r * r;
        assert!((total - disk).abs() < 0.03 * disk, "{total} vs {disk}");
        assert!(areas(&m).iter().all(|&a| a <= 5.0));
        // y up: the disk's centre, in pixel-corner coordinates, is at (cx, h − cy)
        let (lo, hi) = o.bounds();
        let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
        assert!((centre[0] - c[0]).abs() < 1.0 && (centre[1] - (h as f64 - c[1])).abs() < 1.0, "{centre:?}");
    }
}
