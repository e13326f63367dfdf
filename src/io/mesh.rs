//! Triangle meshes: OBJ, OFF, PLY ascii and binary (ply-rs-bw), VTK XML `.vtu`/`.vtp`
//! and legacy `.vtk` unstructured grids and polydata ([`super::vtk`]); written as `.vtu`, `.vtp` (see
//! [`super::vtk`]), binary PLY with Float64 vertex properties, and (geometry only) OBJ and OFF.
//!
//! Polygons with more than three corners are split into fans (reported). Per-vertex data comes
//! back as [`PointArray`]s: PLY vertex properties other than x, y, z; VTK point data. The
//! topology is validated by [`crate::domain::TriMesh::new`], not here.

use super::vtk::PointArray;
use super::{format_f64, stage, Staged};
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// A mesh as read: positions, triangles, per-vertex arrays and what reading changed.
#[derive(Clone, Debug, Default)]
pub struct MeshData {
    /// Vertex positions (2D formats get z = 0).
    pub positions: Vec<[f64; 3]>,
    /// Triangles (0-based vertex indices, not yet validated).
    pub triangles: Vec<[usize; 3]>,
    /// Tetrahedra (VTK tetra cells; 0-based, not yet validated). A file with tetrahedra is a
    /// tetrahedral mesh: its triangles, lines and vertex cells are carried, not smoothed on.
    pub tets: Vec<[usize; 4]>,
    /// Per-vertex arrays found in the file.
    pub arrays: Vec<PointArray>,
    /// What reading did to the data (fan triangulation of polygons, dropped cells).
    pub notes: Vec<String>,
    /// A VTK file's cells as the file gives them (quads, polygons, strips, vertex and line
    /// cells included): outputs write them back with their cell arrays, as a VTK filter does.
    pub cells: Option<super::vtk::Cells>,
    /// A VTK file's cell arrays, one tuple per cell of [`MeshData::cells`].
    pub cell_arrays: Vec<PointArray>,
}

/// Reads a triangle mesh and validates it.
///
/// # Errors
/// Input errors naming the file; a file of tetrahedra (the command needs a surface).
pub fn read_trimesh(path: &Path) -> Result<(crate::domain::TriMesh, MeshData)> {
    let mut data = read_mesh(path)?;
    if !data.tets.is_empty() {
        return Err(input(
            path,
            format!(
                "the file holds {} tetrahedra: this command needs a triangle surface (`smooth` and `verify` take tetrahedral meshes)",
                data.tets.len()
            ),
        ));
    }
    // the triangles move into the mesh; the positions stay for `MeshData::array("x")`
    let triangles = std::mem::take(&mut data.triangles);
    let mesh = crate::domain::TriMesh::new(data.positions.clone(), triangles).map_err(|e| e.in_file(path))?;
    Ok((mesh, data))
}

impl MeshData {
    /// Names of the per-vertex arrays, then the coordinates `x`, `y`, `z`.
    pub fn names(&self) -> Vec<String> {
        self.arrays.iter().map(|a| a.name.clone()).chain(["x", "y", "z"].map(String::from)).collect()
    }

    /// The array `name`, or the coordinate `x`, `y` or `z` (1 component).
    ///
    /// # Errors
    /// A message listing the arrays there are.
    pub fn array(&self, name: &str) -> Result<PointArray> {
        if let Some(a) = self.arrays.iter().find(|a| a.name == name) {
            return Ok(a.clone());
        }
        if let Some(k) = ["x", "y", "z"].iter().position(|c| *c == name) {
            return Ok(PointArray {
                name: name.into(),
                components: 1,
                values: self.positions.iter().map(|p| p[k]).collect(),
                ty: super::vtk::Scalar::F64,
            });
        }
        Err(Error::input(format!("no vertex array `{name}`; there are: {}", self.names().join(", "))))
    }
}

fn input(path: &Path, msg: impl Into<String>) -> Error {
    Error::input(msg).in_file(path)
}

/// A mesh as read: a triangle surface or, when the file holds tetra cells, a tetrahedral mesh.
#[derive(Clone, Debug)]
pub enum AnyMesh {
    /// Triangles.
    Tri(crate::domain::TriMesh),
    /// Tetrahedra.
    Tet(crate::domain::TetMesh),
}

impl AnyMesh {
    /// The mesh as a run-time domain.
    pub fn into_domain(self) -> crate::domain::AnyDomain {
        match self {
            AnyMesh::Tri(m) => crate::domain::AnyDomain::Mesh(m),
            AnyMesh::Tet(m) => crate::domain::AnyDomain::Tets(m),
        }
    }

    /// What validation repaired (reoriented triangles or tetrahedra).
    pub fn repairs(&self) -> &[String] {
        match self {
            AnyMesh::Tri(m) => m.repairs(),
            AnyMesh::Tet(m) => m.repairs(),
        }
    }
}

/// Reads a triangle or tetrahedral mesh (VTK files with tetra cells) and validates it.
///
/// # Errors
/// Input errors naming the file.
pub fn read_any_mesh(path: &Path) -> Result<(AnyMesh, MeshData)> {
    let mut data = read_mesh(path)?;
    if data.tets.is_empty() {
        let triangles = std::mem::take(&mut data.triangles);
        let mesh = crate::domain::TriMesh::new(data.positions.clone(), triangles).map_err(|e| e.in_file(path))?;
        return Ok((AnyMesh::Tri(mesh), data));
    }
    let tets = std::mem::take(&mut data.tets);
    let mesh = crate::domain::TetMesh::new(data.positions.clone(), tets).map_err(|e| e.in_file(path))?;
    Ok((AnyMesh::Tet(mesh), data))
}

/// Which reader a path goes to, by extension.
pub fn is_mesh_path(path: &Path) -> bool {
    matches!(extension(path).as_str(), "obj" | "off" | "ply" | "vtu" | "vtp")
}

/// Whether a file is a mesh: by extension, and for legacy `.vtk` by its `DATASET` line
/// (POLYDATA or UNSTRUCTURED_GRID; STRUCTURED_POINTS is an image).
pub fn is_mesh_file(path: &Path) -> bool {
    if is_mesh_path(path) {
        return true;
    }
    if extension(path) != "vtk" {
        return false;
    }
    let mut head = vec![0u8; 1024];
    let read = std::fs::File::open(path).and_then(|mut f| std::io::Read::read(&mut f, &mut head)).unwrap_or(0);
    let text = String::from_utf8_lossy(&head[..read]).to_ascii_uppercase();
    text.lines().any(|l| {
        let l = l.trim();
        l.starts_with("DATASET") && (l.contains("POLYDATA") || l.contains("UNSTRUCTURED_GRID"))
    })
}

fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Reads a triangle mesh; the format follows the extension (`.vtk`: legacy unstructured
/// grid or polydata).
///
/// # Errors
/// Input errors naming the file: unreadable or malformed content, indices out of range,
/// non-surface cells, no triangle. I/O errors.
pub fn read_mesh(path: &Path) -> Result<MeshData> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    if bytes.is_empty() {
        return Err(input(path, "the file is empty"));
    }
    let mut data = super::guarded(path, || match extension(path).as_str() {
        "obj" => read_obj(&bytes),
        "off" => read_off(&bytes),
        "ply" => read_ply(&bytes),
        "vtu" | "vtp" | "vtk" => read_vtk(&bytes),
        other => Err(Error::input(format!("`.{other}` is not a mesh format (obj, off, ply, vtu, vtp, vtk)"))),
    })?;
    if data.triangles.is_empty() && data.tets.is_empty() {
        return Err(input(path, "the file holds no triangle"));
    }
    let n = data.positions.len();
    if let Some((t, tet)) = data.tets.iter().enumerate().find(|(_, t)| t.iter().any(|&v| v >= n)) {
        return Err(input(
            path,
            format!("tetrahedron {t} refers to vertex {} but there are {n} vertices", tet.iter().max().unwrap_or(&0)),
        ));
    }
    if let Some((t, tri)) = data.triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&v| v >= n)) {
        return Err(input(
            path,
            format!("face {t} refers to vertex {} but there are {n} vertices", tri.iter().max().unwrap_or(&0)),
        ));
    }
    for a in &data.arrays {
        if a.values.len() != n * a.components {
            return Err(input(
                path,
                format!(
                    "array `{}` has {} values for {n} vertices × {} components",
                    a.name,
                    a.values.len(),
                    a.components
                ),
            ));
        }
    }
    data.arrays.retain(|a| !a.name.is_empty());
    Ok(data)
}

/// Splits a polygon into a fan of triangles.
fn fan(poly: &[usize], out: &mut Vec<[usize; 3]>) {
    for k in 1..poly.len().saturating_sub(1) {
        out.push([poly[0], poly[k], poly[k + 1]]);
    }
}

fn polygon_note(split: usize, notes: &mut Vec<String>) {
    if split > 0 {
        notes.push(format!("{split} polygons with more than 3 corners split into triangle fans"));
    }
}

/// OBJ: `v` lines (x y z, extra values such as colours ignored) and `f` lines (1-based or
/// negative relative indices, `v/vt/vn` forms, polygons); other statements are ignored.
/// Written here rather than with tobj: tobj numbers vertices in the order faces first use
/// them and drops unused ones, but vertex indices must follow the file (`--values`,
/// `--source`, `--keep-min` refer to them) and unused vertices must be reported.
fn read_obj(bytes: &[u8]) -> Result<MeshData> {
    let text = std::str::from_utf8(bytes).map_err(|_| Error::input("an OBJ file must be text (UTF-8)"))?;
    let mut data = MeshData::default();
    let mut split = 0;
    let mut faces: Vec<(usize, Vec<i64>, i64)> = Vec::new();
    for (l, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let mut c = [0.0f64; 3];
                for (k, slot) in c.iter_mut().enumerate() {
                    let t = tokens.next().ok_or_else(|| {
                        Error::input(format!("line {}: a vertex has {k} coordinates", l + 1))
                            .at(crate::error::Location::Line(l + 1))
                    })?;
                    *slot = t.parse().map_err(|_| {
                        Error::input(format!("line {}: `{t}` is not a number", l + 1))
                            .at(crate::error::Location::Line(l + 1))
                    })?;
                }
                data.positions.push(c);
            }
            Some("f") => {
                let idx: Vec<i64> = tokens
                    .map(|t| {
                        let v = t.split('/').next().unwrap_or("");
                        v.parse::<i64>().map_err(|_| {
                            Error::input(format!("line {}: `{t}` is not a vertex reference", l + 1))
                                .at(crate::error::Location::Line(l + 1))
                        })
                    })
                    .collect::<Result<_, _>>()?;
                faces.push((l + 1, idx, data.positions.len() as i64));
            }
            _ => {}
        }
    }
    let n = data.positions.len() as i64;
    for (line, idx, before) in faces {
        if idx.len() < 3 {
            return Err(Error::input(format!("line {line}: a face has {} corners", idx.len()))
                .at(crate::error::Location::Line(line)));
        }
        // negative indices count back from the last vertex read before the face
        let face: Vec<usize> = idx
            .iter()
            .map(|&i| {
                let v = if i > 0 { i - 1 } else { before + i };
                if i == 0 || v < 0 || v >= n {
                    Err(Error::input(format!(
                        "line {line}: vertex reference {i} is out of range (there are {n} vertices)"
                    )))
                } else {
                    Ok(v as usize)
                }
            })
            .collect::<Result<_, _>>()?;
        if face.len() > 3 {
            split += 1;
        }
        fan(&face, &mut data.triangles);
    }
    polygon_note(split, &mut data.notes);
    Ok(data)
}

/// OFF (ascii): the `OFF` keyword (optional), counts, one vertex per line (values after x y z,
/// such as colours, ignored), one face per line (`k i1 … ik`, values after them ignored).
fn read_off(bytes: &[u8]) -> Result<MeshData> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| Error::input("an OFF file must be text (binary OFF is not supported)"))?;
    // non-empty lines with their numbers, comments removed
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(l, line)| (l + 1, line.split('#').next().unwrap_or("").split_whitespace().collect::<Vec<&str>>()))
        .filter(|(_, t)| !t.is_empty());
    let (mut l, mut first) = lines.next().ok_or_else(|| Error::input("the file is empty"))?;
    if first[0] != "OFF" && first[0].ends_with("OFF") {
        return Err(Error::input(format!(
            "line {l}: `{}` variants (colours, normals, texture) are not supported; use plain OFF",
            first[0]
        )));
    }
    if first[0] == "OFF" {
        first.remove(0);
        if first.is_empty() {
            (l, first) = lines.next().ok_or_else(|| Error::input("the file ends before the counts"))?;
        }
    }
    let num = |t: &str, l: usize, what: &str| -> Result<f64> {
        t.parse::<f64>().map_err(|_| {
            Error::input(format!("line {l}: `{t}` is not a number ({what})")).at(crate::error::Location::Line(l))
        })
    };
    let count = |t: &str, l: usize, what: &str| -> Result<usize> {
        let v = num(t, l, what)?;
        if v >= 0.0 && v.fract() == 0.0 && v < 1e12 {
            Ok(v as usize)
        } else {
            Err(Error::input(format!("line {l}: {what} {v} is not a count")).at(crate::error::Location::Line(l)))
        }
    };
    if first.len() < 2 {
        return Err(Error::input(format!("line {l}: expected the vertex, face and edge counts"))
            .at(crate::error::Location::Line(l)));
    }
    let nv = count(first[0], l, "vertex count")?;
    let nf = count(first[1], l, "face count")?;
    let mut data = MeshData::default();
    for _ in 0..nv {
        let (l, t) = lines.next().ok_or_else(|| Error::input("the file ends before all vertices are read"))?;
        if t.len() < 3 {
            return Err(
                Error::input(format!("line {l}: a vertex needs 3 coordinates")).at(crate::error::Location::Line(l))
            );
        }
        data.positions.push([num(t[0], l, "x")?, num(t[1], l, "y")?, num(t[2], l, "z")?]);
    }
    let mut split = 0;
    for f in 0..nf {
        let (l, t) = lines.next().ok_or_else(|| Error::input("the file ends before all faces are read"))?;
        let k = count(t[0], l, "corner count")?;
        if k < 3 {
            return Err(Error::input(format!("line {l}: face {f} has {k} corners")).at(crate::error::Location::Line(l)));
        }
        if t.len() < k + 1 {
            return Err(Error::input(format!("line {l}: face {f} lists {} of its {k} corners", t.len() - 1))
                .at(crate::error::Location::Line(l)));
        }
        let face: Vec<usize> = t[1..=k]
            .iter()
            .map(|x| {
                let v = count(x, l, "vertex index")?;
                if v >= nv {
                    Err(Error::input(format!("line {l}: face {f} refers to vertex {v} but there are {nv} vertices"))
                        .at(crate::error::Location::Line(l)))
                } else {
                    Ok(v)
                }
            })
            .collect::<Result<_, _>>()?;
        if k > 3 {
            split += 1;
        }
        fan(&face, &mut data.triangles);
    }
    polygon_note(split, &mut data.notes);
    Ok(data)
}

fn read_ply(bytes: &[u8]) -> Result<MeshData> {
    use ply_rs_bw::ply::Property;
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let mut reader = std::io::Cursor::new(bytes);
    let ply = parser.read_ply(&mut reader).map_err(|e| Error::input(format!("cannot parse the PLY file: {e}")))?;
    let scalar = |p: &Property| -> Option<f64> {
        Some(match *p {
            Property::Char(v) => v.into(),
            Property::UChar(v) => v.into(),
            Property::Short(v) => v.into(),
            Property::UShort(v) => v.into(),
            Property::Int(v) => v.into(),
            Property::UInt(v) => v.into(),
            Property::Float(v) => v.into(),
            Property::Double(v) => v,
            _ => return None,
        })
    };
    let list = |p: &Property| -> Option<Vec<i64>> {
        Some(match p {
            Property::ListChar(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListUChar(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListShort(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListUShort(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListInt(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListUInt(v) => v.iter().map(|&x| x.into()).collect(),
            _ => return None,
        })
    };
    let vertices = ply.payload.get("vertex").ok_or_else(|| Error::input("the PLY file has no `vertex` element"))?;
    let def =
        ply.header.elements.get("vertex").ok_or_else(|| Error::input("the PLY header declares no `vertex` element"))?;
    let names: Vec<String> = def.properties.keys().cloned().collect();
    for c in ["x", "y"] {
        if !names.iter().any(|n| n == c) {
            return Err(Error::input(format!("the vertex element has no `{c}` property")));
        }
    }
    let mut data = MeshData::default();
    let mut columns: Vec<(String, Vec<f64>)> =
        names.iter().filter(|n| !["x", "y", "z"].contains(&n.as_str())).map(|n| (n.clone(), Vec::new())).collect();
    for (i, v) in vertices.iter().enumerate() {
        let get = |name: &str| -> Result<f64> {
            match v.get(name) {
                None => Ok(0.0),
                Some(p) => scalar(p).ok_or_else(|| Error::input(format!("vertex {i}: property `{name}` is a list"))),
            }
        };
        data.positions.push([get("x")?, get("y")?, get("z")?]);
        for (name, col) in &mut columns {
            if let Some(p) = v.get(name.as_str()) {
                if let Some(x) = scalar(p) {
                    col.push(x);
                }
            }
        }
    }
    let n = data.positions.len();
    for (name, values) in columns {
        if values.len() == n {
            data.arrays.push(PointArray { name, components: 1, values, ty: super::vtk::Scalar::F64 });
        }
    }
    let faces = ply.payload.get("face").ok_or_else(|| Error::input("the PLY file has no `face` element"))?;
    let mut split = 0;
    for (f, face) in faces.iter().enumerate() {
        let idx = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .ok_or_else(|| Error::input(format!("face {f} has no `vertex_indices` list")))?;
        let idx =
            list(idx).ok_or_else(|| Error::input(format!("face {f}: `vertex_indices` is not an integer list")))?;
        if idx.len() < 3 {
            return Err(Error::input(format!("face {f} has {} corners", idx.len())));
        }
        if let Some(&bad) = idx.iter().find(|&&v| v < 0 || v as usize >= n) {
            return Err(Error::input(format!("face {f} refers to vertex {bad} but there are {n} vertices")));
        }
        if idx.len() > 3 {
            split += 1;
        }
        let poly: Vec<usize> = idx.iter().map(|&v| v as usize).collect();
        fan(&poly, &mut data.triangles);
    }
    polygon_note(split, &mut data.notes);
    Ok(data)
}

/// A VTK data set's surface cells as triangles: triangles, quads, pixels and polygons (split
/// into fans), triangle strips; vertex and line cells are dropped (reported). Other cells
/// (volumes) are an error naming the first.
fn read_vtk(bytes: &[u8]) -> Result<MeshData> {
    use super::vtk::cell;
    let ds = super::vtk::parse_dataset(bytes)?;
    if ds.image.is_some() {
        return Err(Error::input(
            "the file holds image data, not a mesh: read it as a grid (--domain grid, or a .vti/.vtk image)",
        ));
    }
    let mut data = MeshData { positions: ds.points, arrays: ds.point_data, ..MeshData::default() };
    let (mut dropped, mut split) = (0usize, 0usize);
    for c in 0..ds.cells.len() {
        let corners = ds.cells.corners(c);
        let ty = ds.cells.types[c];
        match ty {
            cell::TRIANGLE | cell::QUAD | cell::POLYGON | cell::PIXEL => {
                if corners.len() < 3 || (ty == cell::TRIANGLE && corners.len() != 3) {
                    return Err(Error::input(format!(
                        "cell {c} is a {} with {} corners",
                        cell::name(ty),
                        corners.len()
                    )));
                }
                if corners.len() > 3 {
                    split += 1;
                }
                if ty == cell::PIXEL && corners.len() == 4 {
                    // a pixel's corners run (0,0) (1,0) (0,1) (1,1)
                    fan(&[corners[0], corners[1], corners[3], corners[2]], &mut data.triangles);
                } else {
                    fan(corners, &mut data.triangles);
                }
            }
            cell::TRIANGLE_STRIP => strip(corners, &mut data.triangles),
            cell::VERTEX | cell::POLY_VERTEX | cell::LINE | cell::POLY_LINE => dropped += 1,
            cell::TETRA => match corners {
                &[a, b, c, d] => data.tets.push([a, b, c, d]),
                _ => return Err(Error::input(format!("cell {c} is a tetrahedron with {} corners", corners.len()))),
            },
            other => {
                return Err(Error::input(format!(
                    "cell {c} is a {} cell: only surface cells (triangles, quads, polygons, strips) and tetrahedra are supported",
                    cell::name(other)
                )))
            }
        }
    }
    if !data.tets.is_empty() {
        // a tetrahedral mesh: its surface cells (a mesher's boundary triangles) are carried
        // through to VTK outputs but not smoothed on
        data.triangles.clear();
        dropped = ds.cells.len() - data.tets.len();
        split = 0;
    }
    polygon_note(split, &mut data.notes);
    if dropped > 0 {
        let what = if data.tets.is_empty() { "vertex and line cells" } else { "cells other than tetrahedra" };
        data.notes.push(format!("{dropped} {what} ignored"));
    }
    data.cells = Some(ds.cells);
    data.cell_arrays = ds.cell_data;
    Ok(data)
}

/// Triangles of a triangle strip (alternating orientation kept consistent).
fn strip(cell: &[usize], out: &mut Vec<[usize; 3]>) {
    for k in 0..cell.len().saturating_sub(2) {
        if k % 2 == 0 {
            out.push([cell[k], cell[k + 1], cell[k + 2]]);
        } else {
            out.push([cell[k + 1], cell[k], cell[k + 2]]);
        }
    }
}

fn check_indices(path: &Path, n: usize, triangles: &[[usize; 3]]) -> Result<()> {
    match triangles.iter().position(|t| t.iter().any(|&v| v >= n)) {
        Some(t) => Err(input(path, format!("triangle {t} refers to a vertex beyond the {n} vertices"))),
        None => Ok(()),
    }
}

/// Stages a Wavefront OBJ file: one `v x y z` line per vertex, in the shortest decimal text
/// that reads back to the same doubles, and one `f a b c` line per triangle (1-based).
///
/// # Errors
/// An input error naming the file for a vertex index out of range; I/O errors.
pub fn stage_obj(path: &Path, positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Result<Staged> {
    check_indices(path, positions.len(), triangles)?;
    stage(path, |w: &mut dyn Write| {
        writeln!(w, "# written by toposmooth: {} vertices, {} triangles", positions.len(), triangles.len())?;
        for p in positions {
            writeln!(w, "v {} {} {}", format_f64(p[0]), format_f64(p[1]), format_f64(p[2]))?;
        }
        for t in triangles {
            writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
        }
        Ok(())
    })
}

/// Stages an OFF file (ascii): counts, vertices in shortest round-trip decimals, triangles
/// as `3 a b c` (0-based).
///
/// # Errors
/// An input error naming the file for a vertex index out of range; I/O errors.
pub fn stage_off(path: &Path, positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Result<Staged> {
    check_indices(path, positions.len(), triangles)?;
    stage(path, |w: &mut dyn Write| {
        writeln!(w, "OFF\n{} {} 0", positions.len(), triangles.len())?;
        for p in positions {
            writeln!(w, "{} {} {}", format_f64(p[0]), format_f64(p[1]), format_f64(p[2]))?;
        }
        for t in triangles {
            writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
        }
        Ok(())
    })
}

/// Stages a binary little-endian PLY file: vertices with `x`, `y`, `z` and one `double`
/// property per array, faces as `uchar`/`int` lists. Values round-trip bit for bit.
///
/// # Errors
/// Input errors naming the file for arrays of the wrong length or names PLY cannot hold;
/// I/O errors.
pub fn stage_ply(
    path: &Path,
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
    arrays: &[(&str, &[f64])],
) -> Result<Staged> {
    let n = positions.len();
    for (name, values) in arrays {
        if values.len() != n {
            return Err(input(path, format!("array `{name}` has {} values for {n} vertices", values.len())));
        }
        if name.is_empty() || name.chars().any(|c| c.is_whitespace() || c.is_control()) {
            return Err(input(path, format!("`{name}` cannot be a PLY property name")));
        }
    }
    if triangles.iter().flatten().any(|&v| v > i32::MAX as usize) {
        return Err(input(path, "vertex indices beyond the 32-bit range of PLY lists"));
    }
    stage(path, |w: &mut dyn Write| {
        writeln!(w, "ply\nformat binary_little_endian 1.0\ncomment written by toposmooth")?;
        writeln!(w, "element vertex {n}\nproperty double x\nproperty double y\nproperty double z")?;
        for (name, _) in arrays {
            writeln!(w, "property double {name}")?;
        }
        writeln!(w, "element face {}\nproperty list uchar int vertex_indices\nend_header", triangles.len())?;
        for (i, p) in positions.iter().enumerate() {
            for c in p {
                w.write_all(&c.to_le_bytes())?;
            }
            for (_, values) in arrays {
                w.write_all(&values[i].to_le_bytes())?;
            }
        }
        for t in triangles {
            w.write_all(&[3u8])?;
            for &v in t {
                w.write_all(&(v as i32).to_le_bytes())?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod vtk_round_trip;
