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
mod svg;

use crate::domain::TriMesh;
use crate::error::{Error, Result};
use spade::{AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};
use std::collections::HashSet;
use std::path::Path;

/// Straight segments that replace each SVG curve command (C, S, Q, T, A).
pub const CURVE_SEGMENTS: usize = 16;
/// Douglas–Peucker tolerance, in pixels, for the boundary traced from a PNG mask.
pub const TRACE_TOLERANCE: f64 = 0.75;
/// Default smallest angle of the refinement, in degrees.
pub const DEFAULT_MIN_ANGLE: f64 = 25.0;
/// Largest angle limit accepted, in degrees: Delaunay refinement is only guaranteed to end
/// for limits up to about 30° (spade's documentation); a little more usually works.
pub const MAX_MIN_ANGLE: f64 = 34.0;
/// Without a maximum area, triangles are at most the outer boundary's bounding-box area over this.
pub const DEFAULT_AREA_DIVISOR: f64 = 2000.0;
/// Largest number of triangles a maximum area may ask for (shape area / maximum area).
pub const MAX_TRIANGLES: f64 = 5e6;

/// A polygon outline: `loops[0]` the outer boundary, the rest holes; each loop a closed polygon
/// without the repeated first point.
///
/// Loops may run either way round. Coordinates are in the units of the file they came from
/// (SVG user units, PNG pixels), with y pointing up.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outline {
    /// The outer boundary, then the holes: each a list of `[x, y]` corners.
    pub loops: Vec<Vec<[f64; 2]>>,
}

/// How messages name loop `k`.
fn loop_name(k: usize) -> String {
    if k == 0 {
        "the outer boundary".into()
    } else {
        format!("hole {k}")
    }
}

/// Twice the signed area of a polygon (positive when counter-clockwise).
fn signed_area2(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (p, q) = (poly[i], poly[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum()
}

fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    use robust::Coord;
    robust::orient2d(Coord { x: a[0], y: a[1] }, Coord { x: b[0], y: b[1] }, Coord { x: c[0], y: c[1] })
}

/// Whether `r`, collinear with segment `pq`, lies on it (endpoints included).
fn within(p: [f64; 2], q: [f64; 2], r: [f64; 2]) -> bool {
    p[0].min(q[0]) <= r[0] && r[0] <= p[0].max(q[0]) && p[1].min(q[1]) <= r[1] && r[1] <= p[1].max(q[1])
}

/// Where two segments that share no endpoint meet: crossing at one interior point, or touching
/// (an endpoint on the other segment, or overlapping). `None` when they are apart.
fn meet(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]) -> Option<([f64; 2], bool)> {
    let (d1, d2, d3, d4) = (orient(p, q, r), orient(p, q, s), orient(r, s, p), orient(r, s, q));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        let t = d3 / (d3 - d4);
        return Some(([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])], true));
    }
    for (d, a, b, x) in [(d1, p, q, r), (d2, p, q, s), (d3, r, s, p), (d4, r, s, q)] {
        if d == 0.0 && within(a, b, x) {
            return Some((x, false));
        }
    }
    None
}

/// Whether `p` is inside the polygon (winding number, exact orientation tests; `p` must not
/// lie on its boundary).
fn inside(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let n = poly.len();
    let mut winding = 0i64;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if a[1] <= p[1] {
            if b[1] > p[1] && orient(a, b, p) > 0.0 {
                winding += 1;
            }
        } else if b[1] <= p[1] && orient(a, b, p) < 0.0 {
            winding -= 1;
        }
    }
    winding != 0
}

/// A number rounded to 6 significant digits, in its shortest form (for messages).
fn short(v: f64) -> String {
    format!("{v:.5e}").parse::<f64>().map(|r| format!("{r}")).unwrap_or_else(|_| v.to_string())
}

fn fmt_point(p: [f64; 2]) -> String {
    format!("({}, {})", short(p[0]), short(p[1]))
}

impl Outline {
    /// Number of corners over all loops.
    pub fn n_points(&self) -> usize {
        self.loops.iter().map(Vec::len).sum()
    }

    /// Area inside the outer boundary and outside the holes (meaningful for a valid outline).
    pub fn area(&self) -> f64 {
        self.loops
            .iter()
            .enumerate()
            .map(|(k, l)| if k == 0 { 0.5 * signed_area2(l).abs() } else { -0.5 * signed_area2(l).abs() })
            .sum()
    }

    /// Lower-left and upper-right corners of the outer boundary's bounding box.
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in self.loops.first().into_iter().flatten() {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// The same outline without repeated consecutive corners (a closing point equal to the
    /// first one included).
    pub fn cleaned(&self) -> Outline {
        Outline { loops: self.loops.iter().map(|l| clean_loop(l)).collect() }
    }

    /// Checks what triangulation needs: at least one loop; at least 3 corners per loop, all
    /// finite; no two edges crossing, touching or overlapping (within a loop or between
    /// loops); every hole inside the outer boundary and outside every other hole.
    ///
    /// # Errors
    /// [`Error::Input`] naming the loop, and for intersections the two edges (edge `i` runs
    /// from corner `i` to corner `i + 1`, 0-based) and where they meet.
    pub fn validate(&self) -> Result<()> {
        if self.loops.is_empty() {
            return Err(Error::input("the outline has no loop"));
        }
        for (k, l) in self.loops.iter().enumerate() {
            if l.len() < 3 {
                return Err(Error::input(format!(
                    "{} has {} corner{}; a loop needs at least 3 distinct corners",
                    loop_name(k),
                    l.len(),
                    if l.len() == 1 { "" } else { "s" }
                )));
            }
            if let Some(i) = l.iter().position(|p| !(p[0].is_finite() && p[1].is_finite())) {
                return Err(Error::input(format!("{}: corner {i} is not finite ({:?})", loop_name(k), l[i])));
            }
        }
        self.check_intersections()?;
        let outer = &self.loops[0];
        for (h, hole) in self.loops.iter().enumerate().skip(1) {
            if !inside(outer, hole[0]) {
                return Err(Error::input(format!(
                    "{} is not inside the outer boundary (its corner 0 is at {})",
                    loop_name(h),
                    fmt_point(hole[0])
                )));
            }
        }
        for a in 1..self.loops.len() {
            for b in a + 1..self.loops.len() {
                let (la, lb) = (&self.loops[a], &self.loops[b]);
                if inside(lb, la[0]) {
                    return Err(Error::input(format!(
                        "{} lies inside {}: holes must be apart",
                        loop_name(a),
                        loop_name(b)
                    )));
                }
                if inside(la, lb[0]) {
                    return Err(Error::input(format!(
                        "{} lies inside {}: holes must be apart",
                        loop_name(b),
                        loop_name(a)
                    )));
                }
            }
        }
        Ok(())
    }

    /// No two edges meet except consecutive edges at their shared corner. Edges are swept in
    /// order of their smallest x; only pairs whose x and y ranges overlap are tested.
    fn check_intersections(&self) -> Result<()> {
        struct Edge {
            k: usize,
            i: usize,
            p: [f64; 2],
            q: [f64; 2],
            x: [f64; 2],
            y: [f64; 2],
        }
        let mut edges: Vec<Edge> = Vec::with_capacity(self.n_points());
        for (k, l) in self.loops.iter().enumerate() {
            for i in 0..l.len() {
                let (p, q) = (l[i], l[(i + 1) % l.len()]);
                edges.push(Edge {
                    k,
                    i,
                    p,
                    q,
                    x: [p[0].min(q[0]), p[0].max(q[0])],
                    y: [p[1].min(q[1]), p[1].max(q[1])],
                });
            }
        }
        edges.sort_by(|a, b| a.x[0].total_cmp(&b.x[0]));
        let name = |e: &Edge| {
            let n = self.loops[e.k].len();
            format!("edge {} (corners {}→{}) of {}", e.i, e.i, (e.i + 1) % n, loop_name(e.k))
        };
        let mut found: Option<(usize, usize, usize, usize, String)> = None;
        for a in 0..edges.len() {
            let ea = &edges[a];
            for eb in edges[a + 1..].iter().take_while(|e| e.x[0] <= ea.x[1]) {
                if eb.y[0] > ea.y[1] || eb.y[1] < ea.y[0] {
                    continue;
                }
                let (first, second) = if (ea.k, ea.i) < (eb.k, eb.i) { (ea, eb) } else { (eb, ea) };
                let n = self.loops[first.k].len();
                let adjacent = first.k == second.k && (second.i == first.i + 1 || (first.i == 0 && second.i == n - 1));
                let message = if adjacent {
                    // consecutive edges share a corner s; they may not double back over each other
                    let (s, u, v, corner) = if second.i == first.i + 1 {
                        (first.q, first.p, second.q, second.i)
                    } else {
                        (first.p, first.q, second.p, 0)
                    };
                    let back =
                        orient(s, u, v) == 0.0 && (u[0] - s[0]) * (v[0] - s[0]) + (u[1] - s[1]) * (v[1] - s[1]) > 0.0;
                    if !back {
                        continue;
                    }
                    format!(
                        "the outline intersects itself: {} and {} overlap (the outline doubles back at corner {corner}, {})",
                        name(first),
                        name(second),
                        fmt_point(s)
                    )
                } else {
                    match meet(first.p, first.q, second.p, second.q) {
                        None => continue,
                        Some((at, crossing)) => format!(
                            "the outline intersects itself: {} {} {} at {}",
                            name(first),
                            if crossing { "crosses" } else { "touches" },
                            name(second),
                            fmt_point(at)
                        ),
                    }
                };
                // report the pair that comes first in loop and edge order
                let key = (first.k, first.i, second.k, second.i);
                if found.as_ref().is_none_or(|f| key < (f.0, f.1, f.2, f.3)) {
                    found = Some((key.0, key.1, key.2, key.3, message));
                }
            }
        }
        match found {
            Some((.., message)) => Err(Error::input(message)),
            None => Ok(()),
        }
    }
}

fn clean_loop(l: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(l.len());
    for &p in l {
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

/// Reads an outline; the format follows the extension:
///
/// - `.json`: `{"outline": [[x, y], ...], "holes": [[[x, y], ...], ...]}` (`holes` optional;
///   `cage` is accepted for `outline`, as in `handles.json`).
/// - `.svg`: `<polygon>`, `<polyline>`, `<path>` (M, L, H, V, Z, and the curves C, S, Q, T, A
///   flattened into [`CURVE_SEGMENTS`] segments each; absolute and relative), `<rect>`,
///   `<circle>`, `<ellipse>`, with `transform` attributes applied. Every subpath and shape is a
///   closed loop (as SVG fills them); the first is the outer boundary, later ones are holes.
///   Coordinates are the SVG's user units with y negated (SVG's y points down), so the shape
///   stays upright; the `viewBox` is not applied. Shapes inside `<defs>`, `<clipPath>`,
///   `<mask>`, `<symbol>`, `<pattern>` and `<marker>` are ignored.
/// - `.png`: a mask. Inside are the pixels with alpha ≥ 50 %; without an alpha channel (or
///   when every pixel is opaque) the dark ones (grey level < 50 %). The boundary of the
///   largest 4-connected inside region (islands elsewhere are dropped) is traced along pixel
///   edges, holes included, and simplified by Douglas–Peucker with tolerance
///   [`TRACE_TOLERANCE`] pixels. Coordinates are pixel corners with y up: pixel (row r,
///   column c) of an image h rows high covers `[c, c + 1] × [h − 1 − r, h − r]`, so the image
///   spans `[0, w] × [0, h]`. Where two inside pixels touch only at a corner, each boundary
///   passing there is moved a quarter pixel into its own pixel, so loops never touch.
///
/// Repeated consecutive corners (and a last corner equal to the first) are dropped. The
/// outline is not validated here: [`triangulate`] does it.
///
/// # Errors
/// Input errors naming the file: an unknown extension, malformed content, SVG features that
/// cannot be read (`<use>`, rounded rectangles, unknown transforms), a PNG with no inside
/// pixel. I/O errors.
pub fn read_outline(path: &Path) -> Result<Outline> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let loops = match ext.as_str() {
        "json" => read_json(&bytes),
        "svg" => svg::read_svg(&bytes),
        "png" => png::read_png(&bytes),
        other => Err(format!("`.{other}` is not an outline format (json, svg, png)")),
    }
    .map_err(|m| Error::input(m).in_file(path))?;
    let outline = Outline { loops }.cleaned();
    if outline.loops.is_empty() {
        return Err(Error::input("the file holds no outline").in_file(path));
    }
    Ok(outline)
}

fn read_json(bytes: &[u8]) -> std::result::Result<Vec<Vec<[f64; 2]>>, String> {
    const FORM: &str = r#"{"outline": [[x, y], ...], "holes": [[[x, y], ...], ...]}"#;
    let value: serde_json::Value = serde_json::from_slice(bytes).map_err(|e| format!("not valid JSON: {e}"))?;
    let obj = value.as_object().ok_or_else(|| format!("the outline must be a JSON object {FORM}"))?;
    if let Some(key) = obj.keys().find(|k| !["outline", "cage", "holes"].contains(&k.as_str())) {
        return Err(format!("unknown key `{key}`; expected {FORM}"));
    }
    let (key, outer) = match (obj.get("outline"), obj.get("cage")) {
        (Some(o), None) => ("outline", o),
        (None, Some(c)) => ("cage", c),
        (Some(_), Some(_)) => return Err("give either `outline` or `cage`, not both".into()),
        (None, None) => return Err(format!("no `outline` key; expected {FORM}")),
    };
    let points = |v: &serde_json::Value, what: &str| -> std::result::Result<Vec<[f64; 2]>, String> {
        let list = v.as_array().ok_or_else(|| format!("{what} must be a list of [x, y] points"))?;
        list.iter()
            .enumerate()
            .map(|(i, p)| match p.as_array().map(|a| a.iter().map(|x| x.as_f64()).collect::<Vec<_>>()) {
                Some(c) if c.len() == 2 && c.iter().all(Option::is_some) => {
                    Ok([c[0].unwrap_or_default(), c[1].unwrap_or_default()])
                }
                _ => Err(format!("{what}: point {i} is `{p}`, not [x, y]")),
            })
            .collect()
    };
    let mut loops = vec![points(outer, &format!("`{key}`"))?];
    if let Some(holes) = obj.get("holes") {
        let list = holes.as_array().ok_or("`holes` must be a list of loops [[[x, y], ...], ...]")?;
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
/// [`Error::Usage`] naming the setting.
pub fn check_settings(max_area: Option<f64>, min_angle_deg: f64) -> Result<()> {
    if let Some(a) = max_area {
        if !(a.is_finite() && a > 0.0) {
            return Err(Error::Usage(format!("--max-area must be a positive number, got {a}")));
        }
    }
    if !(min_angle_deg.is_finite() && (0.0..=MAX_MIN_ANGLE).contains(&min_angle_deg)) {
        return Err(Error::Usage(format!(
            "--min-angle must be between 0 and {MAX_MIN_ANGLE} degrees (refinement may not end above ~30°), got {min_angle_deg}"
        )));
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
/// [`Error::Usage`] for settings out of range ([`check_settings`]) or a `max_area` asking for
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
        return Err(Error::Usage(format!(
            "--max-area {max_area} asks for more than {estimate:.3e} triangles over an area of {}; at most {MAX_TRIANGLES:e} are made: raise it",
            short(outline.area())
        )));
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
