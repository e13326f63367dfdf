//! The outline a shape is meshed from: loops of points, checked, cleaned and measured.

use crate::error::{Error, Result};

/// Largest distance between an SVG curve and the polyline that replaces it, as a fraction of
/// the diagonal of the drawing's bounding box (the corners and control points of all its
/// visible filled shapes, in user units).
pub const CURVE_TOLERANCE: f64 = 1e-3;
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
pub(super) fn loop_name(k: usize) -> String {
    if k == 0 {
        "the outer boundary".into()
    } else {
        format!("hole {k}")
    }
}

/// Twice the signed area of a polygon (positive when counter-clockwise).
pub(super) fn signed_area2(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (p, q) = (poly[i], poly[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum()
}

pub(super) fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    use robust::Coord;
    robust::orient2d(Coord { x: a[0], y: a[1] }, Coord { x: b[0], y: b[1] }, Coord { x: c[0], y: c[1] })
}

/// Whether `r`, collinear with segment `pq`, lies on it (endpoints included).
pub(super) fn within(p: [f64; 2], q: [f64; 2], r: [f64; 2]) -> bool {
    p[0].min(q[0]) <= r[0] && r[0] <= p[0].max(q[0]) && p[1].min(q[1]) <= r[1] && r[1] <= p[1].max(q[1])
}

/// Where two segments that share no endpoint meet: crossing at one interior point, or touching
/// (an endpoint on the other segment, or overlapping). `None` when they are apart.
pub(super) fn meet(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]) -> Option<([f64; 2], bool)> {
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
pub(super) fn inside(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
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
pub(super) fn short(v: f64) -> String {
    format!("{v:.5e}").parse::<f64>().map(|r| format!("{r}")).unwrap_or_else(|_| v.to_string())
}

pub(super) fn fmt_point(p: [f64; 2]) -> String {
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
        self.validate_named(&loop_name)
    }

    /// [`Outline::validate`] with messages naming loop `k` as `loop_name(k)`.
    pub(super) fn validate_named(&self, loop_name: &dyn Fn(usize) -> String) -> Result<()> {
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
        self.check_intersections(loop_name)?;
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
    fn check_intersections(&self, loop_name: &dyn Fn(usize) -> String) -> Result<()> {
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

pub(super) fn clean_loop(l: &[[f64; 2]]) -> Vec<[f64; 2]> {
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
