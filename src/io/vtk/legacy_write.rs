//! The legacy `.vtk` writer: binary (big-endian, as the legacy format requires), structured
//! points for images and unstructured grids for meshes, every array in its own type. The
//! active scalars are a `SCALARS` attribute; the other arrays follow in a `FIELD` block, as
//! VTK's own legacy writer lays them out. Version 4.2 headers (`CELLS n size` with counts),
//! which every VTK since 4 reads.

use super::data::{input, Cells};
use super::write::OutArray;
use crate::error::Result;
use crate::io::{stage, Staged};
use std::io::Write;
use std::path::Path;

/// What the legacy file holds.
pub enum LegacyGeometry<'a> {
    /// `nx × ny` points from `origin` with `spacing` (x fastest).
    #[allow(missing_docs)]
    Image(super::write::ImageBox),
    /// Points and cells.
    #[allow(missing_docs)]
    Unstructured { points: &'a [[f64; 3]], cells: &'a Cells },
}

/// A name as the legacy format stores it: bytes outside `!`..`~`, and `%`, as `%XX`.
fn encoded(name: &str) -> String {
    name.bytes()
        .map(|b| if (b'!'..=b'~').contains(&b) && b != b'%' { (b as char).to_string() } else { format!("%{b:02X}") })
        .collect()
}

fn big_endian(a: &OutArray) -> Vec<u8> {
    let mut raw = Vec::with_capacity(a.values.len() * a.ty.size());
    a.ty.encode(a.values, true, &mut raw);
    raw
}

/// One attribute section: the active scalars (when named and scalar) as `SCALARS`, the rest
/// as one `FIELD` block.
fn section(
    w: &mut dyn Write,
    tag: &str,
    tuples: usize,
    arrays: &[OutArray],
    active: Option<&str>,
) -> std::io::Result<()> {
    if arrays.is_empty() {
        return Ok(());
    }
    writeln!(w, "{tag} {tuples}")?;
    let scalars = active.and_then(|n| arrays.iter().position(|a| a.name == n && a.components == 1));
    if let Some(k) = scalars {
        let a = &arrays[k];
        writeln!(w, "SCALARS {} {} 1", encoded(a.name), a.ty.legacy_name())?;
        writeln!(w, "LOOKUP_TABLE default")?;
        w.write_all(&big_endian(a))?;
        writeln!(w)?;
    }
    let rest: Vec<&OutArray> = arrays.iter().enumerate().filter(|(k, _)| Some(*k) != scalars).map(|(_, a)| a).collect();
    if !rest.is_empty() {
        writeln!(w, "FIELD FieldData {}", rest.len())?;
        for a in rest {
            writeln!(w, "{} {} {tuples} {}", encoded(a.name), a.components, a.ty.legacy_name())?;
            w.write_all(&big_endian(a))?;
            writeln!(w)?;
        }
    }
    Ok(())
}

/// Stages a binary legacy `.vtk` file of `geometry` with point and cell arrays (`arrays`:
/// point, cell); `active` names the active point scalars.
///
/// # Errors
/// Input errors naming the file: arrays of the wrong length, cells referring to missing
/// points, non-finite coordinates, cell indices beyond the format's Int32; I/O errors.
pub fn stage_legacy(
    path: &Path,
    geometry: &LegacyGeometry,
    (point, cell): (&[OutArray], &[OutArray]),
    active: Option<&str>,
) -> Result<Staged> {
    let (n, m) = match geometry {
        LegacyGeometry::Image(b) => (b.points(), b.cells()),
        LegacyGeometry::Unstructured { points, cells } => (points.len(), cells.len()),
    };
    for (what, arrays, tuples) in [("point", point, n), ("cell", cell, m)] {
        for a in arrays {
            if a.components == 0 || a.values.len() != tuples * a.components {
                return Err(input(
                    path,
                    format!("{what} array `{}` has {} values for {tuples} tuples", a.name, a.values.len()),
                ));
            }
        }
    }
    if let LegacyGeometry::Unstructured { points, cells } = geometry {
        if let Some(i) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(input(path, format!("point {i} has a non-finite coordinate {:?}", points[i])));
        }
        if let Some(c) = (0..cells.len()).find(|&c| cells.corners(c).iter().any(|&v| v >= points.len())) {
            return Err(input(path, format!("cell {c} refers to a missing point")));
        }
        if points.len() > i32::MAX as usize || cells.connectivity.len() + cells.len() > i32::MAX as usize {
            return Err(input(path, "too many points or cells for a legacy file's Int32 indices: write .vtu"));
        }
    }
    let f = crate::io::format_f64;
    stage(path, |w| {
        writeln!(w, "# vtk DataFile Version 4.2")?;
        writeln!(w, "written by toposmooth {}", env!("CARGO_PKG_VERSION"))?;
        writeln!(w, "BINARY")?;
        match geometry {
            LegacyGeometry::Image(b) => {
                let ([nx, ny, nz], s, o) = (b.dims, b.spacing, b.origin);
                writeln!(w, "DATASET STRUCTURED_POINTS")?;
                writeln!(w, "DIMENSIONS {nx} {ny} {nz}")?;
                writeln!(w, "SPACING {} {} {}", f(s[0]), f(s[1]), f(s[2]))?;
                writeln!(w, "ORIGIN {} {} {}", f(o[0]), f(o[1]), f(o[2]))?;
            }
            LegacyGeometry::Unstructured { points, cells } => {
                writeln!(w, "DATASET UNSTRUCTURED_GRID")?;
                writeln!(w, "POINTS {} double", points.len())?;
                let coords: Vec<u8> = points.iter().flatten().flat_map(|v| v.to_be_bytes()).collect();
                w.write_all(&coords)?;
                writeln!(w)?;
                writeln!(w, "CELLS {} {}", cells.len(), cells.len() + cells.connectivity.len())?;
                let mut raw = Vec::with_capacity(4 * (cells.len() + cells.connectivity.len()));
                for c in 0..cells.len() {
                    let corners = cells.corners(c);
                    raw.extend_from_slice(&(corners.len() as i32).to_be_bytes());
                    for &v in corners {
                        raw.extend_from_slice(&(v as i32).to_be_bytes());
                    }
                }
                w.write_all(&raw)?;
                writeln!(w)?;
                writeln!(w, "CELL_TYPES {}", cells.len())?;
                let types: Vec<u8> = cells.types.iter().flat_map(|&t| i32::from(t).to_be_bytes()).collect();
                w.write_all(&types)?;
                writeln!(w)?;
            }
        }
        section(w, "POINT_DATA", n, point, active)?;
        section(w, "CELL_DATA", m, cell, None)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_outside_printable_ascii_are_percent_encoded() {
        assert_eq!(encoded("a b%c"), "a%20b%25c");
        assert_eq!(encoded("é"), "%C3%A9");
    }
}
