//! NumPy input: which array of a `.npy` file or an `.npz` archive a command reads, and as
//! what. A 1-D array is a series (x = 0, 1, 2, …), a 2-D array of shape `(ny, nx)` a grid.
//! Without `--array`, an `.npz` gives its only 2-D array (its only 1-D array when it has no
//! 2-D one, or when a series is asked for); otherwise the message lists the arrays.

use super::grid::GridField;
use super::npz::{decode_npy_nd, shape_text, NdArray};
use crate::error::{Error, Result};
use std::path::Path;

/// What the command wants from the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wanted {
    /// Whatever the array is (a 2-D one first).
    Any,
    /// A series (1-D).
    Series,
    /// A grid (2-D).
    Grid,
}

/// An array read from a NumPy file, as a series or a grid.
#[derive(Clone, Debug, PartialEq)]
pub enum NumpyField {
    /// A 1-D array: its name and values (NaN where missing).
    Series {
        /// The array's name (`values` for a `.npy`).
        name: String,
        /// The values.
        values: Vec<f64>,
    },
    /// A 2-D array.
    Grid(GridField),
    /// A 3-D array of shape (nz, ny, nx), at least 2 along each axis.
    Volume {
        /// The array's name.
        name: String,
        /// The grid (unit spacing, origin 0).
        grid: crate::domain::Grid3d,
        /// The values, x fastest.
        values: Vec<f64>,
    },
}

/// Whether a path names a NumPy file (`.npy`, `.npz`).
pub fn is_numpy(path: &Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    ext == "npy" || ext == "npz"
}

/// The arrays of a NumPy file: one named `values` for a `.npy`, the members of an `.npz`.
fn arrays(path: &Path) -> Result<Vec<NdArray>> {
    let npz = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("npz"));
    if npz {
        #[cfg(feature = "io-npz")]
        return super::npz::read_npz_nd(path);
        #[cfg(not(feature = "io-npz"))]
        return Err(Error::input("reading .npz archives needs the io-npz feature").in_file(path));
    }
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let (shape, values) = decode_npy_nd(&bytes).map_err(|e| e.in_file(path))?;
    Ok(vec![("values".to_string(), shape, values)])
}

fn listing(arrays: &[NdArray]) -> String {
    arrays.iter().map(|(n, s, _)| format!("`{n}` {}", shape_text(s))).collect::<Vec<_>>().join(", ")
}

/// Reads the array `name` (or the one that fits, see the module documentation) of a NumPy
/// file as a series or a grid.
///
/// # Errors
/// Input errors naming the file: no such array, no array that fits, an array that is
/// neither 1-D nor 2-D, or not what was wanted, an infinite value, a series of fewer than 2
/// or a grid of fewer than 2 × 2 samples; a usage error when several arrays fit.
pub fn read_numpy(path: &Path, name: Option<&str>, wanted: Wanted) -> Result<NumpyField> {
    let err = |msg: String| Error::input(msg).in_file(path);
    let mut all = arrays(path)?;
    let at = match name {
        Some(name) => all
            .iter()
            .position(|(n, _, _)| n == name)
            .ok_or_else(|| err(format!("no array named `{name}`; the file has {}", listing(&all))))?,
        None => {
            let dims = |d: usize| (0..all.len()).filter(|&i| all[i].1.len() == d).collect::<Vec<_>>();
            let fits = match wanted {
                Wanted::Series => dims(1),
                Wanted::Grid if !dims(2).is_empty() => dims(2),
                Wanted::Grid => dims(3),
                Wanted::Any if !dims(2).is_empty() => dims(2),
                Wanted::Any if !dims(3).is_empty() => dims(3),
                Wanted::Any => dims(1),
            };
            match fits.as_slice() {
                [one] => *one,
                [] => {
                    let what = match wanted {
                        Wanted::Series => "no 1-D array (a series)",
                        Wanted::Grid => "no 2-D (grid) or 3-D (volume) array",
                        Wanted::Any => "no 1-D (series), 2-D (grid) or 3-D (volume) array",
                    };
                    return Err(err(format!("{what}; the file has {}", listing(&all))));
                }
                _ => {
                    let several: Vec<_> = fits.iter().map(|&i| all[i].clone()).collect();
                    return Err(Error::Usage(format!(
                        "{}: several arrays fit, choose one with --array: {}",
                        path.display(),
                        listing(&several)
                    )));
                }
            }
        }
    };
    let (name, shape, values) = all.swap_remove(at);
    if let Some(i) = values.iter().position(|v| v.is_infinite()) {
        return Err(err(format!("array `{name}`: value {} at flat index {i} is infinite", values[i])));
    }
    // SPEC.md: a volume with one axis of extent 1 is a 2D grid over the other two, with two a
    // series (the C-order layout is unchanged by dropping unit axes)
    let mut shape = shape;
    if shape.len() == 3 && shape.contains(&1) && shape.iter().product::<usize>() > 1 {
        shape.retain(|&d| d != 1);
    }
    match (shape.as_slice(), wanted) {
        (&[nz, ny, nx], Wanted::Any | Wanted::Grid) => {
            let grid = crate::domain::Grid3d::new(nx, ny, nz).map_err(|e| e.in_file(path))?;
            Ok(NumpyField::Volume { name, grid, values })
        }
        (&[n], Wanted::Any | Wanted::Series) => {
            if n < 2 {
                return Err(err(format!("array `{name}`: a series needs at least 2 samples, found {n}")));
            }
            Ok(NumpyField::Series { name, values })
        }
        (&[ny, nx], Wanted::Any | Wanted::Grid) => {
            let grid = crate::domain::Grid2d::new(nx, ny).map_err(|e| e.in_file(path))?;
            Ok(NumpyField::Grid(GridField { grid, values, array: name }))
        }
        (s, _) => {
            let is = match s.len() {
                1 => "1-D (a series)",
                2 => "2-D (a grid)",
                3 => "3-D (a volume)",
                _ => "neither 1-D (a series), 2-D (a grid) nor 3-D (a volume)",
            };
            let want = match wanted {
                Wanted::Series => "; a series is read from a 1-D array",
                Wanted::Grid => "; a grid is read from a 2-D array, a volume from a 3-D one",
                Wanted::Any => "",
            };
            Err(err(format!("array `{name}` has shape {}: {is}{want}", shape_text(s))))
        }
    }
}
