//! The SVG source before usvg reads it: the geometry of every shape checked (usvg skips an
//! invalid shape without a word), and every shape given a name that its path keeps through
//! usvg, so that messages can point at the element.

use crate::error::{Error, Result};
use std::collections::HashMap;
use usvg::roxmltree::{Document, Node, ParsingOptions};

pub(super) const SVG_NS: &str = "http://www.w3.org/2000/svg";

/// The elements that become paths, and `<use>`, whose clones usvg leaves without an id.
const NAMED: [&str; 8] = ["rect", "circle", "ellipse", "line", "polyline", "polygon", "path", "use"];

/// The id given to a shape that has none (no stylesheet selects it).
const SYNTHETIC: &str = "__toposmooth_shape_";

/// The source as usvg reads it: an `xmlns` added to a root `<svg>` without one, and an id to
/// every shape and `<use>` without one; `names` maps each of their ids to the element's name
/// in messages: `<tag id="…"> at line L, column C`, or `<tag> at line L, column C`.
pub(super) struct Prepared {
    pub text: String,
    pub names: HashMap<String, String>,
}

/// The XML options usvg itself uses.
pub(super) fn xml_options<'a>() -> ParsingOptions<'a> {
    ParsingOptions { allow_dtd: true, ..ParsingOptions::default() }
}

/// Checks every shape's geometry and names the shapes (see [`Prepared`]).
///
/// # Errors
/// Malformed XML, a root element other than `<svg>`, and invalid geometry: an attribute that
/// is not a length or number, a negative width, height or radius, a number that is not finite
/// (or beyond the 32-bit floats usvg computes with), malformed `points`, `d` or `transform`.
pub(super) fn prepare(text: &str) -> Result<Prepared> {
    let doc =
        Document::parse_with_options(text, xml_options()).map_err(|e| Error::input(format!("malformed XML: {e}")))?;
    let root = doc.root_element();
    if root.tag_name().name() != "svg" {
        return Err(Error::input(format!(
            "not an SVG document (no <svg> element: the root is <{}>)",
            root.tag_name().name()
        )));
    }
    let mut inserts: Vec<(usize, String)> = Vec::new();
    let bare = root.tag_name().namespace().is_none();
    if bare {
        inserts.push((name_end(text, root), format!(" xmlns=\"{SVG_NS}\"")));
    }
    let mut names = HashMap::new();
    for node in doc.descendants().filter(Node::is_element) {
        let ns = node.tag_name().namespace();
        if !(ns == Some(SVG_NS) || (bare && ns.is_none())) {
            continue;
        }
        let tag = node.tag_name().name();
        let pos = doc.text_pos_at(node.range().start);
        let at = format!("at line {}, column {}", pos.row, pos.col);
        let name = match node.attribute("id") {
            Some(id) => format!("<{tag} id=\"{id}\"> {at}"),
            None => format!("<{tag}> {at}"),
        };
        check_element(node, tag).map_err(|m| Error::input(format!("{name}: {m}")))?;
        if !NAMED.contains(&tag) {
            continue;
        }
        let id = match node.attribute("id") {
            Some(id) => id.to_string(),
            None => {
                let id = format!("{SYNTHETIC}{}", inserts.len());
                inserts.push((name_end(text, node), format!(" id=\"{id}\"")));
                id
            }
        };
        names.entry(id).or_insert(name);
    }
    let mut out = String::with_capacity(text.len() + inserts.iter().map(|(_, s)| s.len()).sum::<usize>());
    let mut from = 0;
    for (at, s) in &inserts {
        out.push_str(&text[from..*at]);
        out.push_str(s);
        from = *at;
    }
    out.push_str(&text[from..]);
    Ok(Prepared { text: out, names })
}

/// The byte just after an element's tag name in the source.
fn name_end(text: &str, node: Node) -> usize {
    let start = node.range().start + 1;
    let len = text[start..].find(|c: char| c.is_whitespace() || c == '/' || c == '>').unwrap_or(0);
    start + len
}

/// A number usvg can compute with: finite as a 32-bit float.
fn finite(v: f64) -> bool {
    v.is_finite() && v.abs() <= f32::MAX as f64
}

fn check_element(node: Node, tag: &str) -> std::result::Result<(), String> {
    if let Some(t) = node.attribute("transform") {
        let m = t.parse::<svgtypes::Transform>().map_err(|e| format!("`transform=\"{t}\"` cannot be read ({e})"))?;
        if ![m.a, m.b, m.c, m.d, m.e, m.f].into_iter().all(finite) {
            return Err(format!("`transform=\"{t}\"` is not finite"));
        }
    }
    let (lengths, nonnegative): (&[&str], &[&str]) = match tag {
        "rect" => (&["x", "y", "width", "height", "rx", "ry"], &["width", "height", "rx", "ry"]),
        "circle" => (&["cx", "cy", "r"], &["r"]),
        "ellipse" => (&["cx", "cy", "rx", "ry"], &["rx", "ry"]),
        "line" => (&["x1", "y1", "x2", "y2"], &[]),
        "polygon" | "polyline" => return check_points(node.attribute("points").unwrap_or("")),
        "path" => return check_path(node.attribute("d").unwrap_or("")),
        _ => return Ok(()),
    };
    for &key in lengths {
        let Some(v) = node.attribute(key) else { continue };
        if (key == "rx" || key == "ry") && v.trim() == "auto" {
            continue;
        }
        let length = v.parse::<svgtypes::Length>().map_err(|_| match v.trim().parse::<f64>() {
            Ok(x) if !x.is_finite() => format!("`{key}=\"{v}\"` is not a finite number"),
            _ => format!("`{key}=\"{v}\"` is not a length (a number with an optional unit)"),
        })?;
        if !finite(length.number) {
            return Err(format!("`{key}=\"{v}\"` is not a finite number"));
        }
        if length.number < 0.0 && nonnegative.contains(&key) {
            let what = if key.starts_with('r') { "a radius" } else { "a size" };
            return Err(format!("`{key}=\"{v}\"` is negative: {what} must be 0 or more"));
        }
    }
    Ok(())
}

fn check_points(text: &str) -> std::result::Result<(), String> {
    let mut n = 0;
    for v in svgtypes::NumberListParser::from(text) {
        let v = v.map_err(|e| format!("`points` cannot be read ({e})"))?;
        if !finite(v) {
            return Err(format!("`points` holds a number that is not finite ({v})"));
        }
        n += 1;
    }
    if n % 2 == 1 {
        return Err(format!("`points` holds an odd number of values ({n})"));
    }
    Ok(())
}

fn check_path(d: &str) -> std::result::Result<(), String> {
    use svgtypes::PathSegment as S;
    for (k, segment) in svgtypes::PathParser::from(d).enumerate() {
        let segment = segment.map_err(|e| format!("`d` cannot be read after command {k} ({e})"))?;
        let numbers: Vec<f64> = match segment {
            S::MoveTo { x, y, .. } | S::LineTo { x, y, .. } | S::SmoothQuadratic { x, y, .. } => vec![x, y],
            S::HorizontalLineTo { x, .. } => vec![x],
            S::VerticalLineTo { y, .. } => vec![y],
            S::CurveTo { x1, y1, x2, y2, x, y, .. } => vec![x1, y1, x2, y2, x, y],
            S::SmoothCurveTo { x2, y2, x, y, .. } => vec![x2, y2, x, y],
            S::Quadratic { x1, y1, x, y, .. } => vec![x1, y1, x, y],
            S::EllipticalArc { rx, ry, x_axis_rotation, x, y, .. } => vec![rx, ry, x_axis_rotation, x, y],
            S::ClosePath { .. } => vec![],
        };
        if let Some(v) = numbers.into_iter().find(|&v| !finite(v)) {
            return Err(format!("`d`: command {k} holds a number that is not finite ({v})"));
        }
    }
    Ok(())
}
