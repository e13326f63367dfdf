//! Reading any supported file into a domain and a field, beside [`crate::io::export`], which
//! writes them: a series (CSV, a NumPy 1-D array), a grid or a volume (.vti, legacy .vtk,
//! .npy, .npz, CSV matrix, PNG, TIFF, NIfTI, or two velocity components) or a mesh (.obj,
//! .off, .ply, .vtu, .vtp, legacy .vtk), with the input options of every front end applied
//! ([`ReadOptions`]: the array or column, the spacing, a derived scalar, a mask, the filling
//! of missing samples). The command-line tool, the Python package's `read` and the other
//! front ends read files only through [`read`].
//!
//! ```no_run
//! use toposmooth::io::import::{read, ReadOptions};
//! let opts = ReadOptions { fill_missing: true, spacing: Some(vec![0.31248, -0.31248]), ..Default::default() };
//! let field = read(Some("datasets/soapfilm_piv_vorticity_63x63.csv".as_ref()), &opts)?;
//! assert_eq!(field.values.len(), 63 * 63);
//! # Ok::<(), toposmooth::Error>(())
//! ```

mod field;
mod image;
mod mesh;
mod options;
mod series;
mod sniff;
mod stream;
#[cfg(test)]
mod tests;

pub use field::{
    Derive, DomainKind, Field, FieldInput, GridInput, ImageInput, MaskRule, MeshInput, ReadOptions, SeriesAxis,
    SeriesInput, VolumeInput,
};
pub use image::read_grid;
pub use mesh::read_mesh_field;
pub use options::{parse_spacing, InputOption, INPUT_OPTIONS};
pub use series::read_series_input;
pub use sniff::{is_grid_file, is_raster};

use crate::error::{Error, Result};
use crate::io::mesh::is_mesh_file;
pub use crate::io::mesh::read_trimesh;
use crate::io::npy_input::is_numpy;
use std::path::Path;

/// Reads the field of `path` with `options` applied: a series, a grid, a volume or a mesh, as
/// [`ReadOptions::domain`] (by default the extension and the content) says. `-` reads the
/// standard input (CSV or NPY), a FIFO or a device is read once; `None` reads the velocity
/// files of [`ReadOptions::uv`].
///
/// # Errors
/// Input errors naming the file and the problem (unreadable, malformed, a missing array or
/// column, NaN without `fill_missing`, a series whose x does not increase), usage errors for
/// options that contradict each other or the file (a spacing on a series, a derivation a
/// grid has not).
pub fn read(path: Option<&Path>, options: &ReadOptions) -> Result<Field> {
    let name =
        path.map(Path::to_path_buf).unwrap_or_else(|| options.uv.as_ref().map(|(u, _)| u.clone()).unwrap_or_default());
    read_field(path, options)?.into_field(&name)
}

/// [`read`] before the field's domain is made: the reader's own result.
///
/// # Errors
/// As [`read`].
pub fn read_field(path: Option<&Path>, options: &ReadOptions) -> Result<FieldInput> {
    let once = path.map(stream::ReadOnce::of).transpose()?.flatten();
    let Some(once) = once else {
        return read_field_from(path, options);
    };
    let name = once.name();
    match read_field_from(Some(once.path()), options) {
        Ok(FieldInput::Grid(g)) => Ok(FieldInput::Grid(GridInput { path: name, ..g })),
        Ok(FieldInput::Mesh(m)) => Ok(FieldInput::Mesh(MeshInput { path: name, ..m })),
        Ok(FieldInput::Volume(v)) => Ok(FieldInput::Volume(VolumeInput { path: name, ..v })),
        Ok(series) => Ok(series),
        Err(e) => Err(e.renamed(once.path(), &name)),
    }
}

fn read_field_from(path: Option<&Path>, grid: &ReadOptions) -> Result<FieldInput> {
    let (kind, csv) = (grid.domain, &grid.csv());
    let grid_wanted = grid.uv.is_some() || grid.derive.is_some() || grid.array.is_some();
    if let Some(p) = path {
        crate::io::content::check_extension(p)?;
        let mesh = match kind {
            DomainKind::Mesh => true,
            DomainKind::Auto => is_mesh_file(p),
            _ => false,
        };
        if mesh {
            return Ok(FieldInput::Mesh(read_mesh_field(p, grid)?));
        }
    }
    if let Some(v) = &grid.values {
        return Err(Error::Usage(format!("--values {} is for meshes", v.display())));
    }
    if let Some(p) = path.filter(|p| is_numpy(p) && kind != DomainKind::Grid) {
        if grid.derive.is_none() && grid.uv.is_none() {
            if let Some(series) = series::numpy_series(p, kind, csv, grid)? {
                return Ok(FieldInput::Series(series));
            }
        }
    }
    match path {
        Some(p) if !is_grid_file(p, kind)? => {
            if grid_wanted || grid.spacing.is_some() {
                return Err(Error::Usage(format!(
                    "{} is read as a series; --array, --spacing, --derive and --u/--v are for grids (use --domain grid for a CSV matrix)",
                    p.display()
                )));
            }
            read_series_input(p, csv, grid.fill_missing).map(FieldInput::Series)
        }
        Some(p) if grid.uv.is_some() => {
            Err(Error::Usage(format!("give either an input file ({}) or --u and --v, not both", p.display())))
        }
        Some(p) => read_grid(p, grid),
        None => match &grid.uv {
            Some(_) => read_grid(Path::new(""), grid),
            None => Err(Error::Usage("no input file".into())),
        },
    }
}
