//! The field on a triangle or tetrahedral mesh: a vertex array, a coordinate or a values file.

use super::field::{MeshInput, ReadOptions};
use crate::error::{Error, Result};
use crate::io::export::Carried;
use crate::io::mesh::AnyMesh;
use std::path::{Path, PathBuf};

/// Reads the field on a mesh: `--values FILE`, `--array NAME` (a vertex array or the
/// coordinate `x`, `y`, `z`), or the file's only scalar vertex array.
///
/// # Errors
/// Input errors naming the file: unreadable or invalid mesh, no or several candidate
/// arrays, a values file of the wrong length, non-finite values.
pub fn read_mesh_field(path: &Path, opts: &ReadOptions) -> Result<MeshInput> {
    if opts.derive.is_some() || opts.uv.is_some() || opts.spacing.is_some() {
        return Err(Error::Usage(format!("{}: --derive, --u/--v and --spacing are for grids", path.display())));
    }
    let (mesh, data) = crate::io::mesh::read_any_mesh(path)?;
    let n = data.positions.len();
    let (mut values, description, source): (Vec<f64>, String, PathBuf) = match (&opts.values, &opts.array) {
        (Some(_), Some(_)) => return Err(Error::Usage("give --values or --array, not both".into())),
        (Some(file), None) => {
            let text = std::fs::read_to_string(file).map_err(|source| Error::Io { path: file.clone(), source })?;
            let mut values = Vec::with_capacity(n);
            for (l, line) in text.lines().enumerate() {
                let t = line.trim();
                if t.is_empty() || t.starts_with('#') {
                    continue;
                }
                let v: f64 = t.parse().map_err(|_| {
                    Error::input(format!("line {}: `{t}` is not a number", l + 1))
                        .at(crate::error::Location::Line(l + 1))
                        .in_file(file)
                })?;
                values.push(v);
            }
            if values.len() != n {
                return Err(Error::input(format!(
                    "{} values for the {n} vertices of {}",
                    values.len(),
                    path.display()
                ))
                .in_file(file));
            }
            (values, format!("values from {}", file.display()), file.clone())
        }
        (None, Some(name)) => {
            let a = data.array(name).map_err(|e| e.in_file(path))?;
            if a.components != 1 {
                return Err(Error::input(format!(
                    "array `{name}` has {} components; a scalar is needed",
                    a.components
                ))
                .in_file(path));
            }
            (a.values, name.clone(), path.to_path_buf())
        }
        (None, None) => {
            let scalars: Vec<&crate::io::vtk::PointArray> = data.arrays.iter().filter(|a| a.components == 1).collect();
            match scalars.as_slice() {
                [one] => (one.values.clone(), one.name.clone(), path.to_path_buf()),
                [] => {
                    return Err(Error::input(
                        "the mesh carries no scalar vertex array: give the field with --values FILE or --array x|y|z",
                    )
                    .in_file(path))
                }
                _ => {
                    return Err(Error::Usage(format!(
                        "{}: several vertex arrays fit, choose one with --array: {}",
                        path.display(),
                        data.names().join(", ")
                    )))
                }
            }
        }
    };
    let bad: Vec<usize> = (0..n).filter(|&v| !values[v].is_finite()).collect();
    let infinite = bad.iter().any(|&v| values[v].is_infinite());
    let mut filled = None;
    if !bad.is_empty() {
        if opts.fill_missing && !infinite {
            let k = match &mesh {
                AnyMesh::Tri(m) => crate::operators::positive_cotan_stiffness(m.positions(), m.faces()),
                AnyMesh::Tet(m) => crate::operators::positive_tet_stiffness(m.positions(), m.tets()),
            };
            crate::derive::fill_missing_with(&k, &mut values).map_err(|e| e.in_file(&source))?;
            let mut mask = vec![false; n];
            bad.iter().for_each(|&v| mask[v] = true);
            filled = Some(mask);
        } else {
            let shown: Vec<String> = bad.iter().take(5).map(|v| v.to_string()).collect();
            return Err(Error::input(format!(
                "{} non-finite values (first at vertices {}){}",
                bad.len(),
                shown.join(", "),
                if infinite { "" } else { "; --fill-missing fills NaN harmonically" }
            ))
            .in_file(&source));
        }
    }
    let mut notes = data.notes.clone();
    notes.extend(mesh.repairs().iter().cloned());
    if let AnyMesh::Tri(m) = &mesh {
        notes.extend(m.sliver_warning());
    }
    // the field is the array of that name unless it came from a values file or a coordinate
    let source =
        (opts.values.is_none() && data.arrays.iter().any(|a| a.name == description)).then(|| description.clone());
    let carried = Some(Carried { point: data.arrays, cells: data.cells, cell: data.cell_arrays, source, affine: None });
    Ok(MeshInput { mesh, values, description, notes, filled, path: path.to_path_buf(), carried })
}
