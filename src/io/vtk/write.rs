//! The `.vti`, `.vtp` and `.vtu` writers: every array Float64, zlib-compressed, base64 inline.

use super::data::input;
use crate::error::Result;
use crate::io::{stage, Staged};
use std::io::Write;
use std::path::Path;

const BLOCK: usize = 1 << 15;

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

pub(super) fn b64_encode(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let v =
            (u32::from(c[0]) << 16) | (u32::from(*c.get(1).unwrap_or(&0)) << 8) | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                out.push(T[(v >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The base64 text of one zlib-compressed array in VTK's layout (UInt64 header words,
/// little-endian): the header `[blocks, block size, last block size, compressed sizes...]`
/// encoded on its own, then the compressed blocks.
/// zlib level 1: Float64 fields gain little from harder compression (level 6 took 4.6× longer
/// on a 25,600-vertex mesh, 0.115 s against 0.025 s, for a file 4.5 % smaller).
fn compressed_b64(raw: &[u8]) -> std::io::Result<String> {
    let blocks: Vec<Vec<u8>> = raw
        .chunks(BLOCK)
        .map(|chunk| {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            z.write_all(chunk)?;
            z.finish()
        })
        .collect::<std::io::Result<_>>()?;
    let last = if raw.is_empty() { 0 } else { raw.len() - (raw.len() - 1) / BLOCK * BLOCK };
    let mut header: Vec<u64> = vec![blocks.len() as u64, BLOCK as u64, if last == BLOCK { 0 } else { last as u64 }];
    header.extend(blocks.iter().map(|b| b.len() as u64));
    let header: Vec<u8> = header.iter().flat_map(|v| v.to_le_bytes()).collect();
    Ok(b64_encode(&header) + &b64_encode(&blocks.concat()))
}

fn f64_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn i64_bytes(values: &[usize]) -> Vec<u8> {
    values.iter().flat_map(|&v| (v as i64).to_le_bytes()).collect()
}

fn write_array(w: &mut dyn Write, indent: &str, ty: &str, name: &str, comps: usize, raw: &[u8]) -> std::io::Result<()> {
    let name = if name.is_empty() { String::new() } else { format!(" Name=\"{}\"", xml_escape(name)) };
    writeln!(w, "{indent}<DataArray type=\"{ty}\"{name} NumberOfComponents=\"{comps}\" format=\"binary\">")?;
    writeln!(w, "{indent}  {}", compressed_b64(raw)?)?;
    writeln!(w, "{indent}</DataArray>")
}

/// A `<PointData>` or `<CellData>` section of Float64 arrays, the first one the active scalars.
fn write_section(w: &mut dyn Write, tag: &str, arrays: &[(&str, &[f64])]) -> std::io::Result<()> {
    match arrays.first() {
        Some((first, _)) => writeln!(w, "      <{tag} Scalars=\"{}\">", xml_escape(first))?,
        None => writeln!(w, "      <{tag}>")?,
    }
    for (name, values) in arrays {
        write_array(w, "        ", "Float64", name, 1, &f64_bytes(values))?;
    }
    writeln!(w, "      </{tag}>")
}

/// The `<Points>` section: Float64 triples.
fn write_points(w: &mut dyn Write, coords: &[f64]) -> std::io::Result<()> {
    writeln!(w, "      <Points>")?;
    write_array(w, "        ", "Float64", "Points", 3, &f64_bytes(coords))?;
    writeln!(w, "      </Points>")
}

const XML_HEAD: &str = "<?xml version=\"1.0\"?>";

fn file_open(kind: &str) -> String {
    format!(
        "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" \
         compressor=\"vtkZLibDataCompressor\">"
    )
}

fn check_name(path: &Path, name: &str, seen: &mut Vec<String>) -> Result<()> {
    if name.chars().any(char::is_control) {
        return Err(input(path, format!("array name {name:?} contains control characters")));
    }
    if seen.iter().any(|s| s == name) {
        return Err(input(path, format!("two arrays are named `{name}`")));
    }
    seen.push(name.to_string());
    Ok(())
}

/// Stages a `.vti` image of `nx × ny` points (x fastest, row 0 at `origin`) with one Float64
/// scalar point array per entry of `arrays`, zlib-compressed and base64-encoded inline; the
/// first array is marked as the active scalars. Values (NaN included) round-trip bit for bit
/// through [`super::read_image`] and VTK. Spacing is written as given (see the `io::vtk` module notes on
/// negative spacing).
///
/// # Errors
/// Input errors naming the file: fewer than 1 point along an axis, an array whose length is
/// not `nx · ny`, duplicate names, non-finite spacing or origin. I/O errors while writing.
pub fn stage_vti(
    path: &Path,
    nx: usize,
    ny: usize,
    spacing: [f64; 2],
    origin: [f64; 2],
    arrays: &[(&str, &[f64])],
) -> Result<Staged> {
    if nx == 0 || ny == 0 {
        return Err(input(path, format!("cannot write an image of {nx} × {ny} points")));
    }
    if spacing.iter().chain(&origin).any(|v| !v.is_finite()) {
        return Err(input(path, format!("spacing {spacing:?} and origin {origin:?} must be finite")));
    }
    let mut seen = Vec::new();
    for (name, values) in arrays {
        check_name(path, name, &mut seen)?;
        if values.len() != nx * ny {
            return Err(input(path, format!("array `{name}` has {} values for {nx} × {ny} points", values.len())));
        }
    }
    let f = crate::io::format_f64;
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("ImageData"))?;
        let extent = format!("0 {} 0 {} 0 0", nx - 1, ny - 1);
        writeln!(
            w,
            "  <ImageData WholeExtent=\"{extent}\" Origin=\"{} {} 0\" Spacing=\"{} {} 1\" Direction=\"1 0 0 0 1 0 0 0 1\">",
            f(origin[0]),
            f(origin[1]),
            f(spacing[0]),
            f(spacing[1])
        )?;
        writeln!(w, "    <Piece Extent=\"{extent}\">")?;
        match arrays.first() {
            Some((first, _)) => writeln!(w, "      <PointData Scalars=\"{}\">", xml_escape(first))?,
            None => writeln!(w, "      <PointData>")?,
        }
        for (name, values) in arrays {
            write_array(w, "        ", "Float64", name, 1, &f64_bytes(values))?;
        }
        writeln!(w, "      </PointData>")?;
        writeln!(w, "      <CellData>")?;
        writeln!(w, "      </CellData>")?;
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </ImageData>")?;
        writeln!(w, "</VTKFile>")
    })
}

/// Points, vertex cells and polylines to write as VTK XML PolyData (`.vtp`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyData {
    /// Point positions.
    pub points: Vec<[f64; 3]>,
    /// One vertex cell per entry: the index of its point.
    pub verts: Vec<usize>,
    /// One polyline cell per entry: its point indices in order (at least one).
    pub lines: Vec<Vec<usize>>,
    /// Triangles.
    pub polys: Vec<[usize; 3]>,
    /// Scalar point data: one value per point.
    pub point_arrays: Vec<(String, Vec<f64>)>,
    /// Scalar cell data in VTK's cell order: one value per vertex cell, then one per line,
    /// then one per triangle.
    pub cell_arrays: Vec<(String, Vec<f64>)>,
}

/// Stages a `.vtp` file of `poly`: Float64 points and data arrays, Int64 connectivity and
/// offsets, zlib-compressed and base64-encoded inline.
///
/// # Errors
/// Input errors naming the file: a cell referring to a missing point, an empty line, an
/// array of the wrong length, duplicate array names, a non-finite coordinate. I/O errors.
pub fn stage_vtp(path: &Path, poly: &PolyData) -> Result<Staged> {
    let n = poly.points.len();
    if let Some(i) = poly.points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(input(path, format!("point {i} has a non-finite coordinate {:?}", poly.points[i])));
    }
    if let Some(&v) = poly.verts.iter().find(|&&v| v >= n) {
        return Err(input(path, format!("a vertex cell refers to point {v}, but there are {n} points")));
    }
    for (k, line) in poly.lines.iter().enumerate() {
        if line.is_empty() {
            return Err(input(path, format!("line {k} has no points")));
        }
        if let Some(&v) = line.iter().find(|&&v| v >= n) {
            return Err(input(path, format!("line {k} refers to point {v}, but there are {n} points")));
        }
    }
    if let Some((k, t)) = poly.polys.iter().enumerate().find(|(_, t)| t.iter().any(|&v| v >= n)) {
        return Err(input(path, format!("triangle {k} = {t:?} refers to a missing point (there are {n} points)")));
    }
    let cells = poly.verts.len() + poly.lines.len() + poly.polys.len();
    let mut seen = Vec::new();
    for (name, values) in &poly.point_arrays {
        check_name(path, name, &mut seen)?;
        if values.len() != n {
            return Err(input(path, format!("point array `{name}` has {} values for {n} points", values.len())));
        }
    }
    let mut seen = Vec::new();
    for (name, values) in &poly.cell_arrays {
        check_name(path, name, &mut seen)?;
        if values.len() != cells {
            return Err(input(
                path,
                format!(
                    "cell array `{name}` has {} values for {cells} cells ({} vertices + {} lines + {} triangles)",
                    values.len(),
                    poly.verts.len(),
                    poly.lines.len(),
                    poly.polys.len()
                ),
            ));
        }
    }
    let coords: Vec<f64> = poly.points.iter().flatten().copied().collect();
    let vert_offsets: Vec<usize> = (1..=poly.verts.len()).collect();
    let line_conn: Vec<usize> = poly.lines.concat();
    let line_offsets: Vec<usize> = poly
        .lines
        .iter()
        .scan(0, |acc, l| {
            *acc += l.len();
            Some(*acc)
        })
        .collect();
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("PolyData"))?;
        writeln!(w, "  <PolyData>")?;
        writeln!(
            w,
            "    <Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{}\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" NumberOfPolys=\"{}\">",
            poly.verts.len(),
            poly.lines.len(),
            poly.polys.len()
        )?;
        for (tag, arrays) in [("PointData", &poly.point_arrays), ("CellData", &poly.cell_arrays)] {
            let arrays: Vec<(&str, &[f64])> = arrays.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect();
            write_section(w, tag, &arrays)?;
        }
        write_points(w, &coords)?;
        // empty cell lists are left out (VTK reads that as none; vtkio fails on empty arrays)
        let poly_conn: Vec<usize> = poly.polys.iter().flatten().copied().collect();
        let poly_offsets: Vec<usize> = (1..=poly.polys.len()).map(|k| 3 * k).collect();
        for (tag, conn, offsets) in [
            ("Verts", &poly.verts, &vert_offsets),
            ("Lines", &line_conn, &line_offsets),
            ("Polys", &poly_conn, &poly_offsets),
        ] {
            if conn.is_empty() {
                continue;
            }
            writeln!(w, "      <{tag}>")?;
            write_array(w, "        ", "Int64", "connectivity", 1, &i64_bytes(conn))?;
            write_array(w, "        ", "Int64", "offsets", 1, &i64_bytes(offsets))?;
            writeln!(w, "      </{tag}>")?;
        }
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </PolyData>")?;
        writeln!(w, "</VTKFile>")
    })
}

/// Stages a `.vtu` unstructured grid of triangles (VTK_TRIANGLE cells) with one Float64
/// scalar point array per entry of `arrays` (the first marked active), zlib-compressed and
/// base64-encoded inline; values round-trip bit for bit.
///
/// # Errors
/// Input errors naming the file: a triangle referring to a missing point, an array of the
/// wrong length, duplicate names, a non-finite coordinate. I/O errors.
pub fn stage_vtu(
    path: &Path,
    points: &[[f64; 3]],
    triangles: &[[usize; 3]],
    arrays: &[(&str, &[f64])],
) -> Result<Staged> {
    let n = points.len();
    if let Some(i) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(input(path, format!("point {i} has a non-finite coordinate {:?}", points[i])));
    }
    if let Some((k, t)) = triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&v| v >= n)) {
        return Err(input(path, format!("triangle {k} = {t:?} refers to a missing point (there are {n} points)")));
    }
    let mut seen = Vec::new();
    for (name, values) in arrays {
        check_name(path, name, &mut seen)?;
        if values.len() != n {
            return Err(input(path, format!("point array `{name}` has {} values for {n} points", values.len())));
        }
    }
    let coords: Vec<f64> = points.iter().flatten().copied().collect();
    let conn: Vec<usize> = triangles.iter().flatten().copied().collect();
    let offsets: Vec<usize> = (1..=triangles.len()).map(|k| 3 * k).collect();
    let types = vec![5u8; triangles.len()];
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("UnstructuredGrid"))?;
        writeln!(w, "  <UnstructuredGrid>")?;
        writeln!(w, "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">", triangles.len())?;
        write_section(w, "PointData", arrays)?;
        write_points(w, &coords)?;
        writeln!(w, "      <Cells>")?;
        write_array(w, "        ", "Int64", "connectivity", 1, &i64_bytes(&conn))?;
        write_array(w, "        ", "Int64", "offsets", 1, &i64_bytes(&offsets))?;
        write_array(w, "        ", "UInt8", "types", 1, &types)?;
        writeln!(w, "      </Cells>")?;
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </UnstructuredGrid>")?;
        writeln!(w, "</VTKFile>")
    })
}
