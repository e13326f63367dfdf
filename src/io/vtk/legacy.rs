//! The legacy `.vtk` reader: `STRUCTURED_POINTS`, `POLYDATA` and `UNSTRUCTURED_GRID`, ASCII or
//! BINARY (big-endian), in the 4.2 cell layout (`n size` then `k v0 .. vk-1` per cell) and the
//! 5.1 one (`OFFSETS` and `CONNECTIVITY` arrays), with `SCALARS` (and their lookup tables),
//! `COLOR_SCALARS`, `VECTORS`, `NORMALS`, `TEXTURE_COORDINATES`, `TENSORS`, `GLOBAL_IDS`,
//! `PEDIGREE_IDS`, `FIELD` data and `METADATA` blocks.
//!
//! Every count is checked against the bytes left before anything of its size is allocated.

use super::data::{CellTypes, Dataset, ImageGeometry, PointArray, PolySection};
use super::decode::{parse_tokens, Numbers, Scalar, MAX_VALUES};
use crate::error::{Error, Location, Result};

/// A cursor over the file: keywords and ascii numbers as tokens, binary data as bytes.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    binary: bool,
}

impl<'a> Cursor<'a> {
    fn line_no(&self) -> usize {
        1 + self.bytes[..self.pos.min(self.bytes.len())].iter().filter(|&&b| b == b'\n').count()
    }

    /// An error at the current line.
    fn err(&self, msg: impl Into<String>) -> Error {
        let line = self.line_no();
        Error::input(format!("line {line}: {}", msg.into())).at(Location::Line(line))
    }

    fn skip_space(&mut self) {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// The next whitespace-separated token, if any.
    fn token(&mut self) -> Option<&'a str> {
        self.skip_space();
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        (self.pos > start).then(|| std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("\u{fffd}"))
    }

    fn need(&mut self, what: &str) -> Result<&'a str> {
        self.token().ok_or_else(|| self.err(format!("the file ends where {what} is expected")))
    }

    fn count(&mut self, what: &str) -> Result<usize> {
        let t = self.need(what)?;
        t.parse().map_err(|_| self.err(format!("{what} `{t}` is not a non-negative integer")))
    }

    /// The rest of the current line (after the last token read).
    fn rest_of_line(&mut self) -> &'a str {
        let start = self.pos;
        while self.pos < self.bytes.len() && self.bytes[self.pos] != b'\n' {
            self.pos += 1;
        }
        let line = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("");
        if self.pos < self.bytes.len() {
            self.pos += 1;
        }
        line.trim()
    }

    /// `count` values of type `ty`: ascii tokens, or big-endian binary right after the
    /// keyword line.
    fn values(&mut self, ty: Scalar, count: usize, what: &str) -> Result<Numbers> {
        if count > MAX_VALUES {
            return Err(self.err(format!("{what}: {count} values, more than the {MAX_VALUES} an array may hold")));
        }
        if self.binary {
            let keyword = self.pos.saturating_sub(1);
            // the data starts after the newline that ends the keyword line
            if self.pos > 0 && self.bytes.get(self.pos - 1) != Some(&b'\n') {
                self.rest_of_line();
            }
            let n =
                count.checked_mul(ty.size()).ok_or_else(|| self.err(format!("{what}: {count} values is too many")))?;
            let left = self.bytes.len() - self.pos;
            if n > left {
                let e = Error::input(format!("truncated: {what} needs {n} bytes, {left} are left"));
                return Err(self.located(e, keyword));
            }
            let v = ty.decode(&self.bytes[self.pos..self.pos + n], true);
            self.pos += n;
            Ok(v)
        } else {
            let start = self.pos;
            // a value takes at least 2 bytes with its separator: refuse absurd counts early
            if count > (self.bytes.len() - start) / 2 + 1 {
                return Err(self.err(format!("truncated: {what} needs {count} values, the file is too short")));
            }
            // the values are read where they stand, once: up to the first byte that is not text
            let rest = &self.bytes[start..];
            let text = std::str::from_utf8(rest)
                .unwrap_or_else(|e| std::str::from_utf8(&rest[..e.valid_up_to()]).unwrap_or_default());
            let (numbers, end) = parse_tokens(ty, text, count, what).map_err(|e| self.located(e, start))?;
            if numbers.len() != count {
                let e = Error::input(format!("{what} holds {} values, {count} are needed", numbers.len()));
                return Err(self.located(e, start));
            }
            self.pos = start + end;
            Ok(numbers)
        }
    }

    fn located(&self, e: Error, at: usize) -> Error {
        let line = 1 + self.bytes[..at].iter().filter(|&&b| b == b'\n').count();
        match e {
            Error::Input { path, message, .. } => {
                Error::Input { path, at: Some(Location::Line(line)), message: format!("line {line}: {message}") }
            }
            e => e,
        }
    }

    fn scalar(&mut self, what: &str) -> Result<Scalar> {
        let t = self.need(what)?;
        Scalar::from_legacy(t).ok_or_else(|| self.err(format!("{what}: `{t}` is not a numeric VTK data type")))
    }

    /// Skips a `METADATA` block: `INFORMATION n` / `COMPONENT_NAMES` lines up to a blank line.
    fn skip_metadata(&mut self) {
        self.rest_of_line();
        while self.pos < self.bytes.len() {
            let line = self.rest_of_line();
            if line.is_empty() {
                break;
            }
        }
    }
}

/// Reads a legacy VTK file.
pub(super) fn read_legacy(bytes: &[u8]) -> Result<Dataset> {
    let mut cur = Cursor { bytes, pos: 0, binary: false };
    let version = cur.rest_of_line().to_string();
    if !version.starts_with("# vtk DataFile") {
        return Err(Error::input("not a legacy VTK file (no `# vtk DataFile` line)"));
    }
    cur.rest_of_line(); // the title
    cur.binary = match cur.need("ASCII or BINARY")?.to_ascii_uppercase().as_str() {
        "ASCII" => false,
        "BINARY" => true,
        t => return Err(cur.err(format!("expected ASCII or BINARY, found `{t}`"))),
    };
    let mut ds = Dataset::default();
    let kw = cur.need("DATASET")?.to_ascii_uppercase();
    if kw != "DATASET" {
        // a file of attributes only (no geometry) is not a data set we can use
        return Err(cur.err(format!("expected DATASET, found `{kw}`")));
    }
    let kind = cur.need("the data set type")?.to_ascii_uppercase();
    match kind.as_str() {
        "STRUCTURED_POINTS" => structured_points(&mut cur, &mut ds)?,
        "POLYDATA" | "UNSTRUCTURED_GRID" => geometry(&mut cur, &mut ds, kind == "POLYDATA")?,
        other => {
            return Err(cur.err(format!(
                "the data set is {other}: only STRUCTURED_POINTS, POLYDATA and UNSTRUCTURED_GRID are read"
            )))
        }
    }
    attributes(&mut cur, &mut ds)?;
    Ok(ds)
}

/// `DIMENSIONS`, `ORIGIN`, `SPACING` (or `ASPECT_RATIO`), in any order, up to the attributes.
fn structured_points(cur: &mut Cursor, ds: &mut Dataset) -> Result<()> {
    let mut g = ImageGeometry { extent: [0; 6], origin: [0.0; 3], spacing: [1.0; 3], direction: identity() };
    let mut dims = None;
    loop {
        let save = cur.pos;
        let Some(kw) = cur.token() else { break };
        let kw = kw.to_ascii_uppercase();
        let triple = |cur: &mut Cursor, what: &str| -> Result<[f64; 3]> {
            let mut v = [0.0; 3];
            for x in &mut v {
                let t = cur.need(what)?;
                *x = t.parse().map_err(|_| cur.err(format!("{what}: `{t}` is not a number")))?;
            }
            Ok(v)
        };
        match kw.as_str() {
            "DIMENSIONS" => {
                let mut d = [0i64; 3];
                for x in &mut d {
                    let t = cur.need("DIMENSIONS")?;
                    *x = t
                        .parse()
                        .ok()
                        .filter(|&v| v >= 0)
                        .ok_or_else(|| cur.err(format!("DIMENSIONS: `{t}` is not a count")))?;
                }
                dims = Some(d);
            }
            "ORIGIN" => g.origin = triple(cur, "ORIGIN")?,
            "SPACING" | "ASPECT_RATIO" => g.spacing = triple(cur, "SPACING")?,
            "DIRECTION" => {
                let [a, b, c] = [triple(cur, "DIRECTION")?, triple(cur, "DIRECTION")?, triple(cur, "DIRECTION")?];
                g.direction = [a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]];
            }
            "METADATA" => cur.skip_metadata(),
            _ => {
                cur.pos = save;
                break;
            }
        }
    }
    let d = dims.ok_or_else(|| cur.err("STRUCTURED_POINTS without DIMENSIONS"))?;
    g.extent = [0, d[0] - 1, 0, d[1] - 1, 0, d[2] - 1];
    ds.image = Some(g);
    Ok(())
}

fn identity() -> [f64; 9] {
    [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
}

/// `POINTS` and the cell sections of poly data or an unstructured grid.
fn geometry(cur: &mut Cursor, ds: &mut Dataset, poly: bool) -> Result<()> {
    let mut pending_types: Option<Vec<u8>> = None;
    let mut grid_cells: Option<(Vec<usize>, Vec<usize>)> = None;
    loop {
        let save = cur.pos;
        let Some(kw) = cur.token() else { break };
        let kw = kw.to_ascii_uppercase();
        match kw.as_str() {
            "POINTS" => {
                let n = cur.count("the number of points")?;
                let ty = cur.scalar("POINTS")?;
                let total = n.checked_mul(3).ok_or_else(|| cur.err("too many points"))?;
                let xyz = cur.values(ty, total, "POINTS")?.into_f64("POINTS")?;
                ds.points = xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            }
            "VERTICES" | "LINES" | "POLYGONS" | "TRIANGLE_STRIPS" if poly => {
                let section = match kw.as_str() {
                    "VERTICES" => PolySection::Verts,
                    "LINES" => PolySection::Lines,
                    "POLYGONS" => PolySection::Polys,
                    _ => PolySection::Strips,
                };
                let (conn, ends) = cell_lists(cur, &kw)?;
                check_corners(cur, &conn, ds.points.len(), &kw)?;
                ds.cells.append(&conn, &ends, CellTypes::PolyData(section), 0, &kw)?;
            }
            "CELLS" if !poly => grid_cells = Some(cell_lists(cur, "CELLS")?),
            "CELL_TYPES" if !poly => {
                let n = cur.count("the number of cell types")?;
                let t = cur.values(Scalar::I32, n, "CELL_TYPES")?.into_indices("CELL_TYPES")?;
                let t: Option<Vec<u8>> = t.iter().map(|&v| u8::try_from(v).ok()).collect();
                pending_types = Some(t.ok_or_else(|| cur.err("CELL_TYPES: a type code above 255"))?);
            }
            "METADATA" => cur.skip_metadata(),
            "FIELD" => {
                // field data of the data set (not per point): read and dropped
                field(cur, None)?;
            }
            _ => {
                cur.pos = save;
                break;
            }
        }
    }
    if !poly {
        match (grid_cells, pending_types) {
            (Some((conn, ends)), Some(types)) => {
                check_corners(cur, &conn, ds.points.len(), "CELLS")?;
                ds.cells.append(&conn, &ends, CellTypes::Each(types), 0, "CELLS")?;
            }
            (Some(_), None) => return Err(cur.err("CELLS without CELL_TYPES")),
            (None, Some(_)) => return Err(cur.err("CELL_TYPES without CELLS")),
            (None, None) => {}
        }
    }
    Ok(())
}

fn check_corners(cur: &Cursor, conn: &[usize], n: usize, what: &str) -> Result<()> {
    match conn.iter().position(|&v| v >= n) {
        Some(k) => {
            Err(cur.err(format!("{what}: entry {} refers to point {}, but there are {n} points", k + 1, conn[k])))
        }
        None => Ok(()),
    }
}

/// A cell list, in either layout: `n size` then `k v0 .. vk-1` per cell (4.2), or `n+1 m`
/// then `OFFSETS type` (n+1 values) and `CONNECTIVITY type` (m values) (5.1). Returns the
/// connectivity and each cell's end offset.
fn cell_lists(cur: &mut Cursor, what: &str) -> Result<(Vec<usize>, Vec<usize>)> {
    let a = cur.count(&format!("{what}: the number of cells"))?;
    let b = cur.count(&format!("{what}: the list size"))?;
    let save = cur.pos;
    if cur.token().is_some_and(|t| t.eq_ignore_ascii_case("OFFSETS")) {
        let ty = cur.scalar("OFFSETS")?;
        let offsets = cur.values(ty, a, "OFFSETS")?.into_indices("OFFSETS")?;
        let kw = cur.need("CONNECTIVITY")?;
        if !kw.eq_ignore_ascii_case("CONNECTIVITY") {
            return Err(cur.err(format!("{what}: expected CONNECTIVITY after the offsets, found `{kw}`")));
        }
        let ty = cur.scalar("CONNECTIVITY")?;
        let conn = cur.values(ty, b, "CONNECTIVITY")?.into_indices("CONNECTIVITY")?;
        if offsets.first().is_some_and(|&o| o != 0) {
            return Err(cur.err(format!("{what}: the first offset is {}, not 0", offsets[0])));
        }
        let ends = offsets.get(1..).unwrap_or(&[]).to_vec();
        return Ok((conn, ends));
    }
    cur.pos = save;
    let list = cur.values(Scalar::I32, b, what)?.into_indices(what)?;
    let mut conn = Vec::with_capacity(list.len().saturating_sub(a));
    let mut ends = Vec::with_capacity(a.min(list.len()));
    let mut at = 0usize;
    for c in 0..a {
        let k = *list.get(at).ok_or_else(|| cur.err(format!("{what}: the list ends at cell {c} of {a}")))?;
        let corners = list
            .get(at + 1..at.saturating_add(1).saturating_add(k))
            .ok_or_else(|| cur.err(format!("{what}: cell {c} lists {k} corners past the end of the list")))?;
        conn.extend_from_slice(corners);
        ends.push(conn.len());
        at += 1 + k;
    }
    if at != list.len() {
        return Err(cur.err(format!("{what}: {a} cells use {at} of the list's {} entries", list.len())));
    }
    Ok((conn, ends))
}

/// `POINT_DATA n` and `CELL_DATA n` sections with their attributes.
fn attributes(cur: &mut Cursor, ds: &mut Dataset) -> Result<()> {
    let points = match &ds.image {
        Some(g) => g.dims().iter().product(),
        None => ds.points.len(),
    };
    // None outside a section; Some(true) in point data
    let mut in_points: Option<bool> = None;
    while let Some(kw) = cur.token() {
        let kw = kw.to_ascii_uppercase();
        match kw.as_str() {
            "POINT_DATA" | "CELL_DATA" => {
                let n = cur.count(&kw)?;
                let want = if kw == "POINT_DATA" { points } else { ds.cells.len().max(cell_count(ds)) };
                if n != want {
                    return Err(cur.err(format!("{kw} {n}, but the data set has {want}")));
                }
                in_points = Some(kw == "POINT_DATA");
            }
            "METADATA" => cur.skip_metadata(),
            _ => {
                let Some(point) = in_points else {
                    return Err(cur.err(format!("unexpected `{kw}` (expected POINT_DATA or CELL_DATA)")));
                };
                let n = if point { points } else { ds.cells.len().max(cell_count(ds)) };
                let arrays = attribute(cur, &kw, n)?;
                if point && kw == "SCALARS" && ds.active_scalars.is_none() {
                    ds.active_scalars = arrays.first().map(|a| a.name.clone());
                }
                if point {
                    ds.point_data.extend(arrays);
                } else {
                    ds.cell_data.extend(arrays);
                }
            }
        }
    }
    Ok(())
}

/// The cells of image data.
fn cell_count(ds: &Dataset) -> usize {
    ds.image.as_ref().map_or(0, |g| g.dims().iter().map(|&d| d.saturating_sub(1).max(1)).product())
}

/// One attribute of `n` tuples (a lookup table gives no array).
fn attribute(cur: &mut Cursor, kw: &str, n: usize) -> Result<Vec<PointArray>> {
    let array = |cur: &mut Cursor, name: String, comps: usize, ty: Scalar| -> Result<PointArray> {
        let what = format!("`{kw} {name}`");
        let count = n.checked_mul(comps).ok_or_else(|| cur.err(format!("{what}: too many values")))?;
        let values = cur.values(ty, count, &what)?.into_f64(&what)?;
        Ok(PointArray { name, components: comps, values, ty })
    };
    Ok(match kw {
        "SCALARS" => {
            let name = decode_name(cur.need("the SCALARS name")?);
            let ty = cur.scalar("SCALARS")?;
            let rest = cur.rest_of_line();
            let comps = match rest.split_whitespace().next() {
                None => 1,
                Some(c) => c
                    .parse()
                    .ok()
                    .filter(|&c| (1..=4).contains(&c))
                    .ok_or_else(|| cur.err(format!("SCALARS {name}: `{c}` components (1 to 4 allowed)")))?,
            };
            let save = cur.pos;
            match cur.token() {
                Some(t) if t.eq_ignore_ascii_case("LOOKUP_TABLE") => {
                    cur.need("the lookup table name")?;
                }
                _ => cur.pos = save,
            }
            vec![array(cur, name, comps, ty)?]
        }
        "LOOKUP_TABLE" => {
            cur.need("the lookup table name")?;
            let size = cur.count("the lookup table size")?;
            let ty = if cur.binary { Scalar::U8 } else { Scalar::F32 };
            cur.values(ty, size.checked_mul(4).ok_or_else(|| cur.err("LOOKUP_TABLE too large"))?, "LOOKUP_TABLE")?;
            Vec::new()
        }
        "COLOR_SCALARS" => {
            let name = decode_name(cur.need("the COLOR_SCALARS name")?);
            let comps = cur.count("the COLOR_SCALARS components")?;
            let ty = if cur.binary { Scalar::U8 } else { Scalar::F32 };
            let mut a = array(cur, name, comps, ty)?;
            if cur.binary {
                a.values.iter_mut().for_each(|v| *v /= 255.0);
            }
            vec![a]
        }
        "VECTORS" | "NORMALS" | "TENSORS" | "TENSORS6" | "GLOBAL_IDS" | "PEDIGREE_IDS" => {
            let name = decode_name(cur.need("the array name")?);
            let ty = cur.scalar(kw)?;
            let comps = match kw {
                "VECTORS" | "NORMALS" => 3,
                "TENSORS" => 9,
                "TENSORS6" => 6,
                _ => 1,
            };
            vec![array(cur, name, comps, ty)?]
        }
        "TEXTURE_COORDINATES" => {
            let name = decode_name(cur.need("the array name")?);
            let comps = cur.count("the TEXTURE_COORDINATES dimension")?;
            if !(1..=3).contains(&comps) {
                return Err(cur.err(format!("TEXTURE_COORDINATES {name}: dimension {comps} (1 to 3 allowed)")));
            }
            let ty = cur.scalar(kw)?;
            vec![array(cur, name, comps, ty)?]
        }
        "FIELD" => field(cur, Some(n))?,
        other => return Err(cur.err(format!("unknown attribute `{other}`"))),
    })
}

/// A `FIELD name k` block: `k` arrays `name components tuples type`; with `tuples`, each must
/// have that many tuples.
fn field(cur: &mut Cursor, tuples: Option<usize>) -> Result<Vec<PointArray>> {
    cur.need("the FIELD name")?;
    let k = cur.count("the number of FIELD arrays")?;
    let mut out = Vec::new();
    for _ in 0..k {
        let name = decode_name(cur.need("a FIELD array name")?);
        if name == "NULL_ARRAY" {
            continue;
        }
        let comps = cur.count(&format!("FIELD array {name}: components"))?;
        let n = cur.count(&format!("FIELD array {name}: tuples"))?;
        let ty_text = cur.need("the FIELD array type")?;
        if let Some(want) = tuples {
            if n != want {
                return Err(cur.err(format!("FIELD array {name} has {n} tuples, the data set has {want}")));
            }
        }
        let Some(ty) = Scalar::from_legacy(ty_text) else {
            return Err(cur.err(format!("FIELD array {name}: type `{ty_text}` is not numeric")));
        };
        let what = format!("FIELD array `{name}`");
        let count = n.checked_mul(comps).ok_or_else(|| cur.err(format!("{what}: too many values")))?;
        let values = cur.values(ty, count, &what)?.into_f64(&what)?;
        let save = cur.pos;
        match cur.token() {
            Some(t) if t.eq_ignore_ascii_case("METADATA") => cur.skip_metadata(),
            _ => cur.pos = save,
        }
        out.push(PointArray { name, components: comps, values, ty });
    }
    Ok(out)
}

/// VTK writes spaces and other special characters in names as `%XX`.
fn decode_name(raw: &str) -> String {
    let b = raw.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if let (b'%', Some(&h), Some(&l)) = (b[i], b.get(i + 1), b.get(i + 2)) {
            if let (Some(h), Some(l)) = (hex(h), hex(l)) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_cell_layouts_give_the_same_cells() {
        let old = b"# vtk DataFile Version 4.2\nt\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n0 0 0 1 0 0 1 1 0 0 1 0\n\
                    POLYGONS 2 8\n3 0 1 2\n3 0 2 3\n";
        let new = b"# vtk DataFile Version 5.1\nt\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n0 0 0 1 0 0 1 1 0 0 1 0\n\
                    POLYGONS 3 6\nOFFSETS vtktypeint64\n0 3 6\nCONNECTIVITY vtktypeint64\n0 1 2 0 2 3\n";
        let a = read_legacy(old).unwrap();
        let b = read_legacy(new).unwrap();
        assert_eq!(a.cells, b.cells);
        assert_eq!(a.cells.corners(1), &[0, 2, 3]);
    }

    #[test]
    fn binary_data_is_big_endian_after_the_keyword_line() {
        let mut f = b"# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\n\
                      SPACING 0.5 0.25 1\nORIGIN 1 2 0\nPOINT_DATA 4\nSCALARS my%20f double\nLOOKUP_TABLE default\n"
            .to_vec();
        for v in [1.5f64, -2.0, 3.25, 1e300] {
            f.extend_from_slice(&v.to_be_bytes());
        }
        f.extend_from_slice(b"\nMETADATA\nINFORMATION 0\n\n");
        let ds = read_legacy(&f).unwrap();
        assert_eq!(ds.point_data[0].name, "my f");
        assert_eq!(ds.point_data[0].values, vec![1.5, -2.0, 3.25, 1e300]);
        assert_eq!(ds.image.unwrap().spacing, [0.5, 0.25, 1.0]);
    }

    #[test]
    fn declared_counts_beyond_the_file_are_refused() {
        let f = b"# vtk DataFile Version 3.0\nt\nBINARY\nDATASET POLYDATA\nPOINTS 100000000 double\n\0\0\0\0";
        let e = read_legacy(f).unwrap_err().to_string();
        assert!(e.contains("line 5") && e.contains("truncated"), "{e}");
        let f = b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 100000000 double\n0 0 0\n";
        assert!(read_legacy(f).unwrap_err().to_string().contains("truncated"));
    }
}
