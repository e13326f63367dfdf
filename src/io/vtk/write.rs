//! The `.vti`, `.vtp` and `.vtu` writers: zlib-compressed, base64 inline; the tool's own
//! arrays Float64, arrays carried through from the input in their own type.

use super::data::{cell, input, Cells, PointArray, Scalar};
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

/// An array to write: its name, the type it is written in (every value exact in it), its
/// components and its values, components interleaved.
#[derive(Clone, Copy, Debug)]
pub struct OutArray<'a> {
    /// The name.
    pub name: &'a str,
    /// The type written.
    pub ty: Scalar,
    /// Components per tuple.
    pub components: usize,
    /// `tuples · components` values.
    pub values: &'a [f64],
}

impl<'a> OutArray<'a> {
    /// A Float64 scalar array.
    pub fn float64(name: &'a str, values: &'a [f64]) -> Self {
        OutArray { name, ty: Scalar::F64, components: 1, values }
    }

    /// An array as read, under `name`, in its own type.
    pub fn carried(a: &'a PointArray, name: &'a str) -> Self {
        OutArray { name, ty: a.ty, components: a.components, values: &a.values }
    }
}

/// Checks the names (distinct, printable) and lengths (`tuples` each) of one section.
fn check_section(path: &Path, what: &str, arrays: &[OutArray], tuples: usize) -> Result<()> {
    let mut seen = Vec::new();
    for a in arrays {
        check_name(path, a.name, &mut seen)?;
        if a.components == 0 || a.values.len() != tuples * a.components {
            return Err(input(
                path,
                format!(
                    "{what} array `{}` has {} values for {tuples} {}s of {} components",
                    a.name,
                    a.values.len(),
                    if what == "cell" { "cell" } else { "point" },
                    a.components
                ),
            ));
        }
    }
    Ok(())
}

/// A `<PointData>` or `<CellData>` section; `active` names its active scalars.
fn write_section(w: &mut dyn Write, tag: &str, arrays: &[OutArray], active: Option<&str>) -> std::io::Result<()> {
    match active {
        Some(name) => writeln!(w, "      <{tag} Scalars=\"{}\">", xml_escape(name))?,
        None => writeln!(w, "      <{tag}>")?,
    }
    for a in arrays {
        let mut raw = Vec::with_capacity(a.values.len() * 8);
        a.ty.encode(a.values, false, &mut raw);
        write_array(w, "        ", a.ty.xml_name(), a.name, a.components, &raw)?;
    }
    writeln!(w, "      </{tag}>")
}

/// Owned Float64 scalar arrays to write.
fn float64_of(arrays: &[(String, Vec<f64>)]) -> Vec<OutArray<'_>> {
    arrays.iter().map(|(n, v)| OutArray::float64(n, v)).collect()
}

/// Float64 scalar arrays, the first of them the active scalars.
fn float64_arrays<'a>(arrays: &[(&'a str, &'a [f64])]) -> (Vec<OutArray<'a>>, Option<&'a str>) {
    (arrays.iter().map(|(n, v)| OutArray::float64(n, v)).collect(), arrays.first().map(|(n, _)| *n))
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
    let (point, active) = float64_arrays(arrays);
    stage_vti_arrays(path, ImageBox::flat(nx, ny, spacing, origin), &point, &[], active)
}

/// The points of an image: counts, spacing and origin along x, y and z (a 2D image has one
/// point along z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageBox {
    /// Points along x, y and z.
    pub dims: [usize; 3],
    /// Spacing along x, y and z.
    pub spacing: [f64; 3],
    /// Position of point (0, 0, 0).
    pub origin: [f64; 3],
}

impl ImageBox {
    /// A 2D image in the plane z = 0.
    pub fn flat(nx: usize, ny: usize, spacing: [f64; 2], origin: [f64; 2]) -> ImageBox {
        ImageBox { dims: [nx, ny, 1], spacing: [spacing[0], spacing[1], 1.0], origin: [origin[0], origin[1], 0.0] }
    }
    /// The image of a grid, in the grid's plane: one point along the plane's normal, at its
    /// level.
    pub fn of_grid(g: &crate::domain::Grid2d) -> ImageBox {
        let plane = g.plane();
        let mut b = ImageBox { dims: [1; 3], spacing: [1.0; 3], origin: [0.0; 3] };
        for (k, &a) in plane.axes.iter().enumerate() {
            b.dims[a] = [g.nx(), g.ny()][k];
            b.spacing[a] = g.spacing()[k];
            b.origin[a] = g.origin()[k];
        }
        b.origin[plane.normal()] = plane.level;
        b
    }
    /// Points.
    pub fn points(&self) -> usize {
        self.dims.iter().product()
    }
    /// Cells: the product over the axes of `n − 1`, an axis of one point counting as 1.
    pub fn cells(&self) -> usize {
        self.dims.iter().map(|&d| d.saturating_sub(1).max(1)).product()
    }
}

/// Stages a `.vti` image with point and cell arrays of any type (cells: [`ImageBox::cells`]
/// tuples, x fastest); `active` names the active scalars.
///
/// # Errors
/// As [`stage_vti`].
pub fn stage_vti_arrays(
    path: &Path,
    b: ImageBox,
    point: &[OutArray],
    cells: &[OutArray],
    active: Option<&str>,
) -> Result<Staged> {
    let [nx, ny, nz] = b.dims;
    if nx == 0 || ny == 0 || nz == 0 {
        return Err(input(path, format!("cannot write an image of {nx} × {ny} × {nz} points")));
    }
    let (spacing, origin) = (b.spacing, b.origin);
    if spacing.iter().chain(&origin).any(|v| !v.is_finite()) {
        return Err(input(path, format!("spacing {spacing:?} and origin {origin:?} must be finite")));
    }
    check_section(path, "point", point, b.points())?;
    check_section(path, "cell", cells, b.cells())?;
    let f = crate::io::format_f64;
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("ImageData"))?;
        let extent = format!("0 {} 0 {} 0 {}", nx - 1, ny - 1, nz - 1);
        writeln!(
            w,
            "  <ImageData WholeExtent=\"{extent}\" Origin=\"{} {} {}\" Spacing=\"{} {} {}\" Direction=\"1 0 0 0 1 0 0 0 1\">",
            f(origin[0]),
            f(origin[1]),
            f(origin[2]),
            f(spacing[0]),
            f(spacing[1]),
            f(spacing[2])
        )?;
        writeln!(w, "    <Piece Extent=\"{extent}\">")?;
        write_section(w, "PointData", point, active)?;
        write_section(w, "CellData", cells, None)?;
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
    if let Some(k) = poly.lines.iter().position(Vec::is_empty) {
        return Err(input(path, format!("line {k} has no points")));
    }
    let mut cells = Cells::default();
    let mut push = |corners: &[usize], ty: u8| {
        cells.connectivity.extend_from_slice(corners);
        cells.offsets.push(cells.connectivity.len());
        cells.types.push(ty);
    };
    for &v in &poly.verts {
        push(&[v], cell::VERTEX);
    }
    for line in &poly.lines {
        push(line, if line.len() == 2 { cell::LINE } else { cell::POLY_LINE });
    }
    for t in &poly.polys {
        push(t, cell::TRIANGLE);
    }
    let (point, cell_arrays) = (float64_of(&poly.point_arrays), float64_of(&poly.cell_arrays));
    let active = point.first().map(|a| a.name);
    stage_vtp_cells(path, &poly.points, &cells, (&point, &cell_arrays), active)
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
    let (point, active) = float64_arrays(arrays);
    stage_vtu_cells(path, points, &triangle_cells(triangles), (&point, &[]), active)
}

/// Triangles as cells.
pub fn triangle_cells(triangles: &[[usize; 3]]) -> Cells {
    Cells {
        types: vec![cell::TRIANGLE; triangles.len()],
        offsets: (0..=triangles.len()).map(|k| 3 * k).collect(),
        connectivity: triangles.iter().flatten().copied().collect(),
    }
}

/// Tetrahedra as cells.
pub fn tet_cells(tets: &[[usize; 4]]) -> Cells {
    Cells {
        types: vec![cell::TETRA; tets.len()],
        offsets: (0..=tets.len()).map(|k| 4 * k).collect(),
        connectivity: tets.iter().flatten().copied().collect(),
    }
}

/// Checks the points and the cells' corners.
fn check_geometry(path: &Path, points: &[[f64; 3]], cells: &Cells) -> Result<()> {
    let n = points.len();
    if let Some(i) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(input(path, format!("point {i} has a non-finite coordinate {:?}", points[i])));
    }
    for c in 0..cells.len() {
        if let Some(&v) = cells.corners(c).iter().find(|&&v| v >= n) {
            return Err(input(
                path,
                format!("cell {c} = {:?} refers to point {v}, but there are {n} points", cells.corners(c)),
            ));
        }
    }
    Ok(())
}

/// Checks the points, the cells' corners and the arrays' lengths of a mesh output.
fn check_mesh(
    path: &Path,
    points: &[[f64; 3]],
    cells: &Cells,
    (point, cell): (&[OutArray], &[OutArray]),
) -> Result<()> {
    check_geometry(path, points, cells)?;
    check_section(path, "point", point, points.len())?;
    check_section(path, "cell", cell, cells.len())
}

/// Stages a `.vtu` unstructured grid of any cells with point and cell arrays of any type
/// (`arrays`: point, cell); `active` names the active point scalars.
///
/// # Errors
/// As [`stage_vtu`].
pub fn stage_vtu_cells(
    path: &Path,
    points: &[[f64; 3]],
    cells: &Cells,
    (point, cell_arrays): (&[OutArray], &[OutArray]),
    active: Option<&str>,
) -> Result<Staged> {
    let n = points.len();
    check_mesh(path, points, cells, (point, cell_arrays))?;
    let coords: Vec<f64> = points.iter().flatten().copied().collect();
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("UnstructuredGrid"))?;
        writeln!(w, "  <UnstructuredGrid>")?;
        writeln!(w, "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">", cells.len())?;
        write_section(w, "PointData", point, active)?;
        write_section(w, "CellData", cell_arrays, None)?;
        write_points(w, &coords)?;
        writeln!(w, "      <Cells>")?;
        write_array(w, "        ", "Int64", "connectivity", 1, &i64_bytes(&cells.connectivity))?;
        write_array(w, "        ", "Int64", "offsets", 1, &i64_bytes(&cells.offsets[1..]))?;
        write_array(w, "        ", "UInt8", "types", 1, &cells.types)?;
        writeln!(w, "      </Cells>")?;
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </UnstructuredGrid>")?;
        writeln!(w, "</VTKFile>")
    })
}

/// Stages a `.vtp` poly data file of surface, line and vertex cells with point and cell
/// arrays of any type (`arrays`: point, cell). Cells are written in VTK's poly data order
/// (vertices, lines, polygons, strips; their cell arrays permuted alike), pixels as quads.
///
/// # Errors
/// As [`stage_vtu`]; a volume cell, which poly data cannot hold.
pub fn stage_vtp_cells(
    path: &Path,
    points: &[[f64; 3]],
    cells: &Cells,
    (point, cell_arrays): (&[OutArray], &[OutArray]),
    active: Option<&str>,
) -> Result<Staged> {
    let n = points.len();
    check_mesh(path, points, cells, (point, cell_arrays))?;
    let section = |t: u8| match t {
        cell::VERTEX | cell::POLY_VERTEX => Some(0),
        cell::LINE | cell::POLY_LINE => Some(1),
        cell::TRIANGLE | cell::POLYGON | cell::PIXEL | cell::QUAD => Some(2),
        cell::TRIANGLE_STRIP => Some(3),
        _ => None,
    };
    if let Some(c) = (0..cells.len()).find(|&c| section(cells.types[c]).is_none()) {
        return Err(input(
            path,
            format!("cell {c} is a {}: poly data (.vtp) holds no volume cells; write .vtu", cell::name(cells.types[c])),
        ));
    }
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_by_key(|&c| section(cells.types[c]));
    let permuted: Vec<Vec<f64>> = cell_arrays
        .iter()
        .map(|a| order.iter().flat_map(|&c| &a.values[c * a.components..(c + 1) * a.components]).copied().collect())
        .collect();
    let cell_out: Vec<OutArray> =
        cell_arrays.iter().zip(&permuted).map(|(a, v)| OutArray { values: v, ..*a }).collect();
    let mut sections: [(Vec<usize>, Vec<usize>); 4] = Default::default();
    for &c in &order {
        let corners = cells.corners(c);
        let (conn, ends) = &mut sections[section(cells.types[c]).unwrap_or(2)];
        if cells.types[c] == cell::PIXEL && corners.len() == 4 {
            conn.extend([corners[0], corners[1], corners[3], corners[2]]);
        } else {
            conn.extend_from_slice(corners);
        }
        ends.push(conn.len());
    }
    let coords: Vec<f64> = points.iter().flatten().copied().collect();
    let count = |k: usize| sections[k].1.len();
    stage(path, |w| {
        writeln!(w, "{XML_HEAD}")?;
        writeln!(w, "{}", file_open("PolyData"))?;
        writeln!(w, "  <PolyData>")?;
        writeln!(
            w,
            "    <Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{}\" NumberOfLines=\"{}\" NumberOfStrips=\"{}\" NumberOfPolys=\"{}\">",
            count(0),
            count(1),
            count(3),
            count(2)
        )?;
        write_section(w, "PointData", point, active)?;
        write_section(w, "CellData", &cell_out, None)?;
        write_points(w, &coords)?;
        for (k, tag) in ["Verts", "Lines", "Polys", "Strips"].iter().enumerate() {
            let (conn, ends) = &sections[k];
            if ends.is_empty() {
                continue;
            }
            writeln!(w, "      <{tag}>")?;
            write_array(w, "        ", "Int64", "connectivity", 1, &i64_bytes(conn))?;
            write_array(w, "        ", "Int64", "offsets", 1, &i64_bytes(ends))?;
            writeln!(w, "      </{tag}>")?;
        }
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </PolyData>")?;
        writeln!(w, "</VTKFile>")
    })
}
