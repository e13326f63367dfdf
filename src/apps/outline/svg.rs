//! Outlines from SVG as drawn (see [`super::read_outline`]): usvg resolves the document (CSS,
//! `display`, `visibility`, units, `<use>`, transforms, basic shapes as paths), and every
//! visible filled path becomes closed polygons, curves flattened within [`CURVE_TOLERANCE`].

mod check;

use super::shape::{loop_name, Outline, CURVE_TOLERANCE};
use crate::error::{Error, Result};
use std::collections::HashMap;
use usvg::tiny_skia_path::{PathSegment, Point};

type Loops = Vec<Vec<[f64; 2]>>;

/// An affine map `(x, y) ↦ (a x + c y + e, b x + d y + f)` as `[a, b, c, d, e, f]`.
type Affine = [f64; 6];

/// `m ∘ n`: apply `n` first.
fn compose(m: Affine, n: Affine) -> Affine {
    [
        m[0] * n[0] + m[2] * n[1],
        m[1] * n[0] + m[3] * n[1],
        m[0] * n[2] + m[2] * n[3],
        m[1] * n[2] + m[3] * n[3],
        m[0] * n[4] + m[2] * n[5] + m[4],
        m[1] * n[4] + m[3] * n[5] + m[5],
    ]
}

fn apply(m: Affine, p: Point) -> [f64; 2] {
    let (x, y) = (p.x as f64, p.y as f64);
    [m[0] * x + m[2] * y + m[4], m[1] * x + m[3] * y + m[5]]
}

/// A piece of a subpath after its start point, in output coordinates.
#[derive(Clone, Copy, Debug)]
enum Piece {
    Line([f64; 2]),
    Quad([f64; 2], [f64; 2]),
    Cubic([f64; 2], [f64; 2], [f64; 2]),
}

/// A subpath: its start and its pieces; `source` names the element it comes from.
struct Subpath {
    start: [f64; 2],
    pieces: Vec<Piece>,
    source: String,
}

/// Reads the visible filled shapes of an SVG document as closed loops, in document order: in
/// the root's user units (the `viewBox` undone), transforms applied, y negated. The loops are
/// validated ([`Outline::validate`]) with messages naming the elements.
pub(super) fn read_svg(bytes: &[u8]) -> Result<Loops> {
    if bytes.starts_with(&[0x1f, 0x8b]) {
        return Err(Error::input("a compressed SVG (.svgz) is not read: decompress it first"));
    }
    let text = std::str::from_utf8(bytes).map_err(|e| Error::input(format!("not UTF-8 text: {e}")))?;
    let prepared = check::prepare(text)?;
    let doc = usvg::roxmltree::Document::parse_with_options(&prepared.text, check::xml_options())
        .map_err(|e| Error::input(format!("malformed XML: {e}")))?;
    let tree = usvg::Tree::from_xmltree(&doc, &usvg::Options::default())
        .map_err(|e| Error::input(format!("usvg cannot read the document: {e}")))?;
    let to_user = user_units(doc.root_element(), tree.size())?;
    let mut subpaths = Vec::new();
    let mut unfilled = 0;
    collect(tree.root(), to_user, (&prepared.names, None), &mut subpaths, &mut unfilled);
    if subpaths.is_empty() {
        let why = if unfilled > 0 {
            format!(
                "{unfilled} visible shape{} without fill (fill=\"none\")",
                if unfilled == 1 { " is" } else { "s are" }
            )
        } else {
            "none of polygon, polyline, path, rect, circle or ellipse is displayed".to_string()
        };
        return Err(Error::input(format!(
            "no shape found that is drawn filled ({why}); hidden shapes (display:none, visibility:hidden, <defs>) do not count"
        )));
    }
    let tolerance = CURVE_TOLERANCE * diagonal(&subpaths);
    let loops: Loops = subpaths.iter().map(|s| flatten(s, tolerance)).collect();
    let names: Vec<&str> = subpaths.iter().map(|s| s.source.as_str()).collect();
    Outline { loops: loops.clone() }.cleaned().validate_named(&|k| format!("{} ({})", loop_name(k), names[k]))?;
    Ok(loops)
}

/// The map from usvg's coordinates (the viewport's, after the root's `viewBox`) back to the
/// root's user units, with y negated.
fn user_units(root: usvg::roxmltree::Node, size: usvg::Size) -> Result<Affine> {
    let flip = [1.0, 0.0, 0.0, -1.0, 0.0, 0.0];
    let Some(vb) = root.attribute("viewBox").and_then(|v| v.parse::<svgtypes::ViewBox>().ok()) else {
        return Ok(flip);
    };
    if !(vb.w > 0.0 && vb.h > 0.0) {
        return Ok(flip);
    }
    let aspect: svgtypes::AspectRatio =
        root.attribute("preserveAspectRatio").and_then(|v| v.parse().ok()).unwrap_or_default();
    let (w, h) = (size.width() as f64, size.height() as f64);
    let (mut sx, mut sy) = (w / vb.w, h / vb.h);
    if aspect.align != svgtypes::Align::None {
        let s = if aspect.slice { sx.max(sy) } else { sx.min(sy) };
        (sx, sy) = (s, s);
    }
    // the free space, and how much of it lies before the view box (as usvg aligns it)
    let (fx, fy) = (w - vb.w * sx, h - vb.h * sy);
    use svgtypes::Align as A;
    let (ax, ay) = match aspect.align {
        A::None | A::XMinYMin => (0.0, 0.0),
        A::XMidYMin => (0.5, 0.0),
        A::XMaxYMin => (1.0, 0.0),
        A::XMinYMid => (0.0, 0.5),
        A::XMidYMid => (0.5, 0.5),
        A::XMaxYMid => (1.0, 0.5),
        A::XMinYMax => (0.0, 1.0),
        A::XMidYMax => (0.5, 1.0),
        A::XMaxYMax => (1.0, 1.0),
    };
    let (tx, ty) = (-vb.x * sx + ax * fx, -vb.y * sy + ay * fy);
    // the inverse of (x, y) ↦ (sx x + tx, sy y + ty), then y negated
    Ok(compose(flip, [1.0 / sx, 0.0, 0.0, 1.0 / sy, -tx / sx, -ty / sy]))
}

/// The subpaths of the visible filled paths under `group`, in document order; counts the
/// visible paths without fill. A path is named after its element, or when usvg left it without
/// an id, after the `<use>` that cloned it (`names.1`, the innermost); paths that come from
/// neither (markers, the root's `background-color`) are left out, as are images and text.
fn collect(
    group: &usvg::Group,
    to_user: Affine,
    names: (&HashMap<String, String>, Option<&str>),
    out: &mut Vec<Subpath>,
    unfilled: &mut usize,
) {
    for node in group.children() {
        let path = match node {
            usvg::Node::Group(g) => {
                let inner = names.0.get(g.id()).map(|n| format!("a clone by {n}"));
                collect(g, to_user, (names.0, inner.as_deref().or(names.1)), out, unfilled);
                continue;
            }
            usvg::Node::Path(p) => p,
            usvg::Node::Image(_) | usvg::Node::Text(_) => continue,
        };
        let Some(name) = names.0.get(path.id()).map(String::as_str).or(names.1) else { continue };
        if !path.is_visible() {
            continue;
        }
        if path.fill().is_none() {
            *unfilled += 1;
            continue;
        }
        let t = path.abs_transform();
        let m = compose(to_user, [t.sx, t.ky, t.kx, t.sy, t.tx, t.ty].map(f64::from));
        let first = out.len();
        subpaths(path.data(), m, out);
        let count = out.len() - first;
        for (k, s) in out[first..].iter_mut().enumerate() {
            s.source = if count == 1 { name.to_string() } else { format!("{name}, subpath {}", k + 1) };
        }
    }
}

/// The subpaths of a path's data mapped by `m`, but those that enclose nothing: a lone moveto,
/// or straight lines through fewer than 3 distinct points (a `<line>`).
fn subpaths(data: &usvg::tiny_skia_path::Path, m: Affine, out: &mut Vec<Subpath>) {
    let finish = |s: Option<Subpath>, out: &mut Vec<Subpath>| {
        let Some(s) = s else { return };
        let curved = s.pieces.iter().any(|p| !matches!(p, Piece::Line(_)));
        let mut distinct = vec![s.start];
        for p in &s.pieces {
            if let Piece::Line(q) = p {
                if !distinct.contains(q) && distinct.len() < 3 {
                    distinct.push(*q);
                }
            }
        }
        if curved || distinct.len() >= 3 {
            out.push(s);
        }
    };
    let mut current: Option<Subpath> = None;
    for segment in data.segments() {
        let piece = match segment {
            PathSegment::MoveTo(p) => {
                finish(current.take(), out);
                current = Some(Subpath { start: apply(m, p), pieces: Vec::new(), source: String::new() });
                continue;
            }
            PathSegment::LineTo(p) => Piece::Line(apply(m, p)),
            PathSegment::QuadTo(c, p) => Piece::Quad(apply(m, c), apply(m, p)),
            PathSegment::CubicTo(c1, c2, p) => Piece::Cubic(apply(m, c1), apply(m, c2), apply(m, p)),
            PathSegment::Close => {
                finish(current.take(), out);
                continue;
            }
        };
        if let Some(s) = current.as_mut() {
            s.pieces.push(piece);
        }
    }
    finish(current.take(), out);
}

/// The diagonal of the bounding box of every start, corner and control point.
fn diagonal(subpaths: &[Subpath]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut add = |p: [f64; 2]| {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    };
    for s in subpaths {
        add(s.start);
        for piece in &s.pieces {
            match *piece {
                Piece::Line(p) => add(p),
                Piece::Quad(c, p) => [c, p].into_iter().for_each(&mut add),
                Piece::Cubic(c1, c2, p) => [c1, c2, p].into_iter().for_each(&mut add),
            }
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// Segments for a curve whose second derivative is at most `bound` in size: linear
/// interpolation at n equal steps of t is off by at most `bound / (8 n²)`.
fn steps(bound: f64, tolerance: f64) -> usize {
    const MOST: f64 = 10_000.0;
    if tolerance.is_nan() || tolerance <= 0.0 {
        return 1;
    }
    (bound / (8.0 * tolerance)).sqrt().ceil().clamp(1.0, MOST) as usize
}

fn norm(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (a[0] - 2.0 * b[0] + c[0]).hypot(a[1] - 2.0 * b[1] + c[1])
}

/// The subpath as a polygon: lines kept, each curve replaced by the points at equal steps of
/// its parameter, as many as keep the polygon within `tolerance` of the curve.
fn flatten(s: &Subpath, tolerance: f64) -> Vec<[f64; 2]> {
    let mut out = vec![s.start];
    let mut cur = s.start;
    for piece in &s.pieces {
        match *piece {
            Piece::Line(p) => {
                out.push(p);
                cur = p;
            }
            Piece::Quad(c, p) => {
                // B'' = 2 (P0 − 2 P1 + P2)
                let n = steps(2.0 * norm(cur, c, p), tolerance);
                for k in 1..=n {
                    let t = k as f64 / n as f64;
                    let u = 1.0 - t;
                    out.push([0, 1].map(|i| u * u * cur[i] + 2.0 * u * t * c[i] + t * t * p[i]));
                }
                cur = p;
            }
            Piece::Cubic(c1, c2, p) => {
                // B'' = 6 ((1 − t)(P0 − 2 P1 + P2) + t (P1 − 2 P2 + P3))
                let n = steps(6.0 * norm(cur, c1, c2).max(norm(c1, c2, p)), tolerance);
                for k in 1..=n {
                    let t = k as f64 / n as f64;
                    let u = 1.0 - t;
                    let (a, b, c, d) = (u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t);
                    out.push([0, 1].map(|i| a * cur[i] + b * c1[i] + c * c2[i] + d * p[i]));
                }
                cur = p;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests;
