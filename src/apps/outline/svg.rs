//! Outlines from SVG: shapes and paths as closed polygons (see [`super::read_outline`]).

use super::shape::CURVE_SEGMENTS;
use crate::error::{Error, Result};
use quick_xml::events::{BytesStart, Event};

type Loops = Vec<Vec<[f64; 2]>>;

/// An affine map `(x, y) ↦ (a x + c y + e, b x + d y + f)` as `[a, b, c, d, e, f]`.
type Affine = [f64; 6];

const IDENTITY: Affine = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0];

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

fn apply(m: Affine, p: [f64; 2]) -> [f64; 2] {
    [m[0] * p[0] + m[2] * p[1] + m[4], m[1] * p[0] + m[3] * p[1] + m[5]]
}

/// Elements whose content is not drawn where it stands.
const HIDDEN: [&[u8]; 7] = [b"defs", b"clipPath", b"mask", b"symbol", b"pattern", b"marker", b"metadata"];

/// Reads every shape of an SVG document as closed loops, in document order, y negated.
pub(super) fn read_svg(bytes: &[u8]) -> Result<Loops> {
    let line_of = |pos: u64| bytes[..(pos as usize).min(bytes.len())].iter().filter(|&&b| b == b'\n').count() + 1;
    let mut reader = quick_xml::Reader::from_reader(bytes);
    // open elements: their transform, and whether they are hidden
    let mut stack: Vec<(Affine, bool)> = vec![(IDENTITY, false)];
    let mut loops: Loops = Vec::new();
    let mut saw_svg = false;
    loop {
        let pos = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| Error::input(format!("malformed XML near line {}: {e}", line_of(reader.error_position()))))?;
        let (e, empty) = match &event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                if stack.len() > 1 {
                    stack.pop();
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let name = e.local_name().as_ref().to_vec();
        let at = |m: &dyn std::fmt::Display| {
            Error::input(format!("line {}: <{}>: {m}", line_of(pos), String::from_utf8_lossy(&name)))
        };
        saw_svg |= name == b"svg";
        let (parent, hidden_above) = *stack.last().unwrap_or(&(IDENTITY, false));
        let attrs = attributes(e).map_err(|m| at(&m))?;
        let get = |key: &str| attrs.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str());
        let own = match get("transform") {
            Some(t) => parse_transform(t).map_err(|m| at(&m))?,
            None => IDENTITY,
        };
        let m = compose(parent, own);
        let hidden = hidden_above || HIDDEN.contains(&name.as_slice());
        if !empty {
            stack.push((m, hidden));
        }
        if hidden {
            continue;
        }
        let number = |key: &str| -> Result<f64> {
            match get(key) {
                None => Ok(0.0),
                Some(v) => length(v).ok_or_else(|| at(&format!("`{key}=\"{v}\"` is not a number in user units"))),
            }
        };
        let mut shapes: Loops = Vec::new();
        match name.as_slice() {
            b"polygon" | b"polyline" => {
                let values = numbers(get("points").unwrap_or("")).map_err(|m| at(&m))?;
                if values.len() % 2 == 1 {
                    return Err(at(&format!("`points` holds an odd number of values ({})", values.len())));
                }
                shapes.push(values.chunks(2).map(|c| [c[0], c[1]]).collect());
            }
            b"path" => shapes = path(get("d").unwrap_or("")).map_err(|m| at(&m))?,
            b"rect" => {
                let (x, y, w, h) = (number("x")?, number("y")?, number("width")?, number("height")?);
                if number("rx")? != 0.0 || number("ry")? != 0.0 {
                    return Err(at(&"rounded rectangles (rx, ry) are not supported: convert the shape to a path"));
                }
                shapes.push(vec![[x, y], [x + w, y], [x + w, y + h], [x, y + h]]);
            }
            b"circle" | b"ellipse" => {
                let (cx, cy) = (number("cx")?, number("cy")?);
                let (rx, ry) =
                    if name == b"circle" { (number("r")?, number("r")?) } else { (number("rx")?, number("ry")?) };
                let n = 4 * CURVE_SEGMENTS;
                shapes.push(
                    (0..n)
                        .map(|k| {
                            let t = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                            [cx + rx * t.cos(), cy + ry * t.sin()]
                        })
                        .collect(),
                );
            }
            b"use" => return Err(at(&"<use> clones are not supported: unlink them (make them real paths) first")),
            _ => {}
        }
        for s in shapes {
            // a lone moveto draws nothing
            if s.len() >= 2 {
                loops.push(s.into_iter().map(|p| apply(m, p)).map(|[x, y]| [x, -y]).collect());
            }
        }
    }
    if !saw_svg {
        return Err(Error::input("not an SVG document (no <svg> element)"));
    }
    if loops.is_empty() {
        return Err(Error::input("no shape found (polygon, polyline, path, rect, circle or ellipse)"));
    }
    Ok(loops)
}

fn attributes(e: &BytesStart) -> Result<Vec<(String, String)>> {
    e.attributes()
        .map(|a| {
            let a = a.map_err(|err| Error::input(format!("malformed attribute: {err}")))?;
            let key = String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned();
            let value = match a.unescape_value() {
                Ok(v) => v.into_owned(),
                Err(_) => String::from_utf8_lossy(&a.value).into_owned(),
            };
            Ok((key, value))
        })
        .collect()
}

/// A length in user units: a number, optionally with `px`.
fn length(v: &str) -> Option<f64> {
    let v = v.trim();
    v.strip_suffix("px").unwrap_or(v).trim().parse::<f64>().ok().filter(|x| x.is_finite())
}

/// Reads numbers and flags from SVG attribute text (`1.5-2e3.5`, commas or spaces between).
struct Cursor<'a> {
    s: &'a [u8],
    i: usize,
}

impl Cursor<'_> {
    fn skip(&mut self) {
        while self.i < self.s.len() && (self.s[self.i].is_ascii_whitespace() || self.s[self.i] == b',') {
            self.i += 1;
        }
    }

    fn done(&mut self) -> bool {
        self.skip();
        self.i >= self.s.len()
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip();
        self.s.get(self.i).copied()
    }

    fn number(&mut self) -> Option<f64> {
        self.skip();
        let start = self.i;
        let s = self.s;
        let mut i = self.i;
        if i < s.len() && (s[i] == b'+' || s[i] == b'-') {
            i += 1;
        }
        let digits = |i: &mut usize| {
            let from = *i;
            while *i < s.len() && s[*i].is_ascii_digit() {
                *i += 1;
            }
            *i > from
        };
        let mut any = digits(&mut i);
        if i < s.len() && s[i] == b'.' {
            i += 1;
            any |= digits(&mut i);
        }
        if !any {
            return None;
        }
        if i < s.len() && (s[i] == b'e' || s[i] == b'E') {
            let mut j = i + 1;
            if j < s.len() && (s[j] == b'+' || s[j] == b'-') {
                j += 1;
            }
            if digits(&mut j) {
                i = j;
            }
        }
        let v = std::str::from_utf8(&s[start..i]).ok()?.parse::<f64>().ok()?;
        self.i = i;
        v.is_finite().then_some(v)
    }

    /// An arc flag: a single `0` or `1` (they may be written without separators).
    fn flag(&mut self) -> Option<bool> {
        self.skip();
        let f = match self.s.get(self.i) {
            Some(b'0') => false,
            Some(b'1') => true,
            _ => return None,
        };
        self.i += 1;
        Some(f)
    }
}

fn numbers(text: &str) -> Result<Vec<f64>> {
    let mut c = Cursor { s: text.as_bytes(), i: 0 };
    let mut out = Vec::new();
    while !c.done() {
        out.push(c.number().ok_or_else(|| Error::input(format!("`{}` is not a number", rest(&c))))?);
    }
    Ok(out)
}

fn rest(c: &Cursor) -> String {
    let tail = String::from_utf8_lossy(&c.s[c.i..]);
    tail.chars().take(12).collect()
}

/// Parses a `transform` list: matrix, translate, scale, rotate, skewX, skewY (or `none`).
fn parse_transform(text: &str) -> Result<Affine> {
    let t = text.trim();
    if t.is_empty() || t == "none" {
        return Ok(IDENTITY);
    }
    let mut m = IDENTITY;
    let mut s = t;
    while !s.trim_start_matches(|c: char| c.is_whitespace() || c == ',').is_empty() {
        s = s.trim_start_matches(|c: char| c.is_whitespace() || c == ',');
        let open = s.find('(').ok_or_else(|| Error::input(format!("cannot handle transform `{text}`")))?;
        let close = s
            .find(')')
            .ok_or_else(|| Error::input(format!("cannot handle transform `{text}` (no closing parenthesis)")))?;
        let name = s[..open].trim();
        let args = numbers(&s[open + 1..close]).map_err(|e| Error::input(format!("transform `{text}`: {e}")))?;
        let bad = || Error::input(format!("cannot handle transform `{text}`: {name} with {} values", args.len()));
        let rad = |a: f64| a.to_radians();
        let step: Affine = match (name, args.as_slice()) {
            ("matrix", [a, b, c, d, e, f]) => [*a, *b, *c, *d, *e, *f],
            ("translate", [x]) => [1.0, 0.0, 0.0, 1.0, *x, 0.0],
            ("translate", [x, y]) => [1.0, 0.0, 0.0, 1.0, *x, *y],
            ("scale", [k]) => [*k, 0.0, 0.0, *k, 0.0, 0.0],
            ("scale", [x, y]) => [*x, 0.0, 0.0, *y, 0.0, 0.0],
            ("rotate", [a]) => {
                let (sn, cs) = rad(*a).sin_cos();
                [cs, sn, -sn, cs, 0.0, 0.0]
            }
            ("rotate", [a, cx, cy]) => {
                let (sn, cs) = rad(*a).sin_cos();
                let r = [cs, sn, -sn, cs, 0.0, 0.0];
                compose([1.0, 0.0, 0.0, 1.0, *cx, *cy], compose(r, [1.0, 0.0, 0.0, 1.0, -cx, -cy]))
            }
            ("skewX", [a]) => [1.0, 0.0, rad(*a).tan(), 1.0, 0.0, 0.0],
            ("skewY", [a]) => [1.0, rad(*a).tan(), 0.0, 1.0, 0.0, 0.0],
            ("matrix" | "translate" | "scale" | "rotate" | "skewX" | "skewY", _) => return Err(bad()),
            _ => return Err(Error::input(format!("cannot handle transform `{text}` (unknown `{name}`)"))),
        };
        m = compose(m, step);
        s = &s[close + 1..];
    }
    Ok(m)
}

/// Points of a cubic Bézier after `p0`, at t = 1/n, …, 1.
fn cubic(p0: [f64; 2], c1: [f64; 2], c2: [f64; 2], p: [f64; 2], out: &mut Vec<[f64; 2]>) {
    for k in 1..=CURVE_SEGMENTS {
        let t = k as f64 / CURVE_SEGMENTS as f64;
        let u = 1.0 - t;
        let (a, b, c, d) = (u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t);
        out.push([0, 1].map(|i| a * p0[i] + b * c1[i] + c * c2[i] + d * p[i]));
    }
}

fn quadratic(p0: [f64; 2], c: [f64; 2], p: [f64; 2], out: &mut Vec<[f64; 2]>) {
    for k in 1..=CURVE_SEGMENTS {
        let t = k as f64 / CURVE_SEGMENTS as f64;
        let u = 1.0 - t;
        out.push([0, 1].map(|i| u * u * p0[i] + 2.0 * u * t * c[i] + t * t * p[i]));
    }
}

/// An elliptical arc (SVG 1.1 implementation notes F.6.5–F.6.6: radii scaled up when too small).
#[allow(clippy::too_many_arguments)]
fn arc(p0: [f64; 2], rx: f64, ry: f64, phi_deg: f64, large: bool, sweep: bool, p: [f64; 2], out: &mut Vec<[f64; 2]>) {
    if p0 == p {
        return;
    }
    let (mut rx, mut ry) = (rx.abs(), ry.abs());
    if rx == 0.0 || ry == 0.0 {
        out.push(p);
        return;
    }
    let (sn, cs) = phi_deg.to_radians().sin_cos();
    let (dx, dy) = ((p0[0] - p[0]) / 2.0, (p0[1] - p[1]) / 2.0);
    let (x1, y1) = (cs * dx + sn * dy, -sn * dx + cs * dy);
    let lambda = (x1 * x1) / (rx * rx) + (y1 * y1) / (ry * ry);
    if lambda > 1.0 {
        rx *= lambda.sqrt();
        ry *= lambda.sqrt();
    }
    let num = (rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1).max(0.0);
    let den = rx * rx * y1 * y1 + ry * ry * x1 * x1;
    let mut coef = if den > 0.0 { (num / den).sqrt() } else { 0.0 };
    if large == sweep {
        coef = -coef;
    }
    let (cx1, cy1) = (coef * rx * y1 / ry, -coef * ry * x1 / rx);
    let (cx, cy) = (cs * cx1 - sn * cy1 + (p0[0] + p[0]) / 2.0, sn * cx1 + cs * cy1 + (p0[1] + p[1]) / 2.0);
    let angle = |ux: f64, uy: f64, vx: f64, vy: f64| (ux * vy - uy * vx).atan2(ux * vx + uy * vy);
    let (ux, uy) = ((x1 - cx1) / rx, (y1 - cy1) / ry);
    let (vx, vy) = ((-x1 - cx1) / rx, (-y1 - cy1) / ry);
    let theta1 = angle(1.0, 0.0, ux, uy);
    let mut delta = angle(ux, uy, vx, vy);
    let tau = 2.0 * std::f64::consts::PI;
    if !sweep && delta > 0.0 {
        delta -= tau;
    } else if sweep && delta < 0.0 {
        delta += tau;
    }
    for k in 1..CURVE_SEGMENTS {
        let t = theta1 + delta * k as f64 / CURVE_SEGMENTS as f64;
        let (x, y) = (rx * t.cos(), ry * t.sin());
        out.push([cs * x - sn * y + cx, sn * x + cs * y + cy]);
    }
    out.push(p);
}

/// The subpaths of a path's `d`, each a closed loop (open subpaths are closed as SVG fills them).
fn path(d: &str) -> Result<Loops> {
    let mut c = Cursor { s: d.as_bytes(), i: 0 };
    let mut loops: Loops = Vec::new();
    let mut current: Vec<[f64; 2]> = Vec::new();
    let (mut cur, mut start) = ([0.0f64; 2], [0.0f64; 2]);
    let mut command: Option<u8> = None;
    let mut started = false;
    // the last control point of a cubic (for S) or quadratic (for T) command
    let (mut last_cubic, mut last_quad): (Option<[f64; 2]>, Option<[f64; 2]>) = (None, None);
    while !c.done() {
        let next = c.peek().unwrap_or(b' ');
        if next.is_ascii_alphabetic() {
            c.i += 1;
            command = Some(next);
        } else if command.is_none() {
            return Err(Error::input(format!("`d` must start with a moveto (M or m), found `{}`", rest(&c))));
        }
        let cmd = command.unwrap_or(b'M');
        if !started && !matches!(cmd, b'M' | b'm') {
            return Err(Error::input(format!("`d` must start with a moveto (M or m), found `{}`", cmd as char)));
        }
        started = true;
        let relative = cmd.is_ascii_lowercase();
        let base = if relative { cur } else { [0.0, 0.0] };
        let fail =
            |c: &Cursor| Error::input(format!("`d`: command {} needs more numbers at `{}`", cmd as char, rest(c)));
        let num = |c: &mut Cursor| c.number().ok_or_else(|| fail(c));
        let point = |c: &mut Cursor| -> Result<[f64; 2]> {
            let x = num(c)?;
            let y = num(c)?;
            Ok([base[0] + x, base[1] + y])
        };
        let (mut cubic_ctrl, mut quad_ctrl) = (None, None);
        if current.is_empty() && !matches!(cmd, b'M' | b'm' | b'Z' | b'z') {
            current.push(cur);
        }
        match cmd.to_ascii_uppercase() {
            b'M' => {
                let p = point(&mut c)?;
                if current.len() >= 2 {
                    loops.push(std::mem::take(&mut current));
                }
                current.clear();
                current.push(p);
                cur = p;
                start = p;
                // further coordinate pairs are linetos
                command = Some(if relative { b'l' } else { b'L' });
            }
            b'Z' => {
                if current.len() >= 2 {
                    loops.push(std::mem::take(&mut current));
                }
                current.clear();
                cur = start;
                // numbers after Z without a command are an error
                command = None;
                if !c.done() && !c.peek().is_some_and(|b| b.is_ascii_alphabetic()) {
                    return Err(Error::input(format!("`d`: numbers after Z need a command, at `{}`", rest(&c))));
                }
            }
            b'L' => {
                cur = point(&mut c)?;
                current.push(cur);
            }
            b'H' => {
                cur = [num(&mut c)? + base[0], cur[1]];
                current.push(cur);
            }
            b'V' => {
                cur = [cur[0], num(&mut c)? + base[1]];
                current.push(cur);
            }
            b'C' | b'S' => {
                let c1 = if cmd.eq_ignore_ascii_case(&b'C') {
                    point(&mut c)?
                } else {
                    last_cubic.map_or(cur, |q| [2.0 * cur[0] - q[0], 2.0 * cur[1] - q[1]])
                };
                let c2 = point(&mut c)?;
                let p = point(&mut c)?;
                cubic(cur, c1, c2, p, &mut current);
                cubic_ctrl = Some(c2);
                cur = p;
            }
            b'Q' | b'T' => {
                let q = if cmd.eq_ignore_ascii_case(&b'Q') {
                    point(&mut c)?
                } else {
                    last_quad.map_or(cur, |q| [2.0 * cur[0] - q[0], 2.0 * cur[1] - q[1]])
                };
                let p = point(&mut c)?;
                quadratic(cur, q, p, &mut current);
                quad_ctrl = Some(q);
                cur = p;
            }
            b'A' => {
                let (rx, ry, phi) = (num(&mut c)?, num(&mut c)?, num(&mut c)?);
                let large = c.flag().ok_or_else(|| fail(&c))?;
                let sweep = c.flag().ok_or_else(|| fail(&c))?;
                let p = point(&mut c)?;
                arc(cur, rx, ry, phi, large, sweep, p, &mut current);
                cur = p;
            }
            other => return Err(Error::input(format!("`d`: unknown command `{}`", other as char))),
        }
        last_cubic = cubic_ctrl;
        last_quad = quad_ctrl;
    }
    if current.len() >= 2 {
        loops.push(current);
    }
    Ok(loops)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(p, q)| (p[0] - q[0]).abs() < 1e-9 && (p[1] - q[1]).abs() < 1e-9)
    }

    #[test]
    fn relative_and_absolute_path_commands() {
        // a 10 × 10 square with a 2 × 2 square hole, written with relative commands
        let loops = path("m 0,0 h 10 v 10 h -10 z M2 2l2 0 0 2-2 0Z").unwrap();
        assert_eq!(loops.len(), 2);
        assert!(close(&loops[0], &[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]), "{:?}", loops[0]);
        assert!(close(&loops[1], &[[2.0, 2.0], [4.0, 2.0], [4.0, 4.0], [2.0, 4.0]]), "{:?}", loops[1]);
        // implicit lineto after a relative moveto, numbers run together, V and H absolute
        let loops = path("m1 1 2 0 0 2 H1V1z m5-1 1.5.5-1.5.5").unwrap();
        assert!(close(&loops[0], &[[1.0, 1.0], [3.0, 1.0], [3.0, 3.0], [1.0, 3.0], [1.0, 1.0]]), "{:?}", loops[0]);
        // after z the current point is the subpath's start: m5-1 from (1, 1)
        assert!(close(&loops[1], &[[6.0, 0.0], [7.5, 0.5], [6.0, 1.0]]), "{:?}", loops[1]);
        // a subpath drawn after Z without a moveto starts at the previous start
        let loops = path("M0 0 L4 0 L4 4 Z L-4 0 L-4 -4").unwrap();
        assert!(close(&loops[1], &[[0.0, 0.0], [-4.0, 0.0], [-4.0, -4.0]]));
    }

    #[test]
    fn curves_are_flattened() {
        // a half circle arc of radius 1 from (1, 0) to (-1, 0), closed by a line
        let loops = path("M1 0 A1 1 0 0 1 -1 0 Z").unwrap();
        assert_eq!(loops[0].len(), 1 + CURVE_SEGMENTS);
        assert!(loops[0].iter().all(|p| ((p[0] * p[0] + p[1] * p[1]).sqrt() - 1.0).abs() < 1e-12));
        // sweep = 1 turns towards positive angles: the arc passes through (0, 1)
        assert!(loops[0].iter().any(|p| (p[0]).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12), "{:?}", loops[0]);
        // cubic and smooth cubic; quadratic and smooth quadratic end where they should
        let loops = path("M0 0 C0 1 1 1 1 0 S2 -1 2 0 Q3 1 4 0 t2 0 z").unwrap();
        let l = &loops[0];
        assert_eq!(l.len(), 1 + 4 * CURVE_SEGMENTS);
        for (k, end) in [[1.0, 0.0], [2.0, 0.0], [4.0, 0.0], [6.0, 0.0]].iter().enumerate() {
            assert!(close(&[l[(k + 1) * CURVE_SEGMENTS]], &[*end]), "{k}: {:?}", l[(k + 1) * CURVE_SEGMENTS]);
        }
        // the smooth cubic reflects the control point (1, 1) about (1, 0): its midpoint is below
        assert!(l[CURVE_SEGMENTS + CURVE_SEGMENTS / 2][1] < 0.0);
        assert!(path("M0 0 L1").unwrap_err().to_string().contains("needs more numbers"));
        assert!(path("L0 0 1 1").unwrap_err().to_string().contains("moveto"));
        assert!(path("M0 0 X1 1").unwrap_err().to_string().contains("unknown command"));
    }

    #[test]
    fn documents_with_transforms_and_hidden_shapes() {
        let svg = r#"<?xml version="1.0"?>
<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
  <defs><rect x="0" y="0" width="1" height="1"/></defs>
  <g transform="translate(10, 20) scale(2)">
    <polygon points="0,0 10,0 10,10 0,10"/>
    <path transform="rotate(90 5 5)" d="M4 4 h2 v2 h-2 z"/>
  </g>
  <circle cx="0" cy="0" r="1" transform="matrix(1 0 0 1 100 100)"/>
</svg>"#;
        let loops = read_svg(svg.as_bytes()).unwrap();
        assert_eq!(loops.len(), 3);
        // y negated
        assert!(close(&loops[0], &[[10.0, -20.0], [30.0, -20.0], [30.0, -40.0], [10.0, -40.0]]), "{:?}", loops[0]);
        // rotating the small square by 90° about its centre (5, 5) maps (4, 4) to (6, 4)
        assert!(close(&loops[1][..1], &[[22.0, -28.0]]), "{:?}", loops[1]);
        assert_eq!(loops[2].len(), 4 * CURVE_SEGMENTS);
        assert!(close(&loops[2][..1], &[[101.0, -100.0]]));
        for (text, needle) in [
            (r#"<svg><path transform="perspective(1)" d="M0 0 L1 0 L0 1z"/></svg>"#, "cannot handle transform"),
            (r##"<svg><use href="#a"/></svg>"##, "<use>"),
            (r#"<svg><rect width="1" height="1" rx="0.2"/></svg>"#, "rounded"),
            (r#"<svg><polygon points="0 0 1"/></svg>"#, "odd number"),
            (r#"<svg><g/></svg>"#, "no shape"),
            (r#"<html/>"#, "not an SVG"),
        ] {
            let e = read_svg(text.as_bytes()).unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
        let e = read_svg(b"<svg>\n<path d=\"M0 0 Lx\"/></svg>").unwrap_err().to_string();
        assert!(e.starts_with("line 2: <path>"), "{e}");
    }
}
