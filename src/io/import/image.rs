//! Grids and volumes: the image formats read into one geometry and its arrays, then the
//! options applied (the array, the spacing, a derived scalar, the mask, missing samples).

use super::field::{Derive, FieldInput, GridInput, MaskRule, ReadOptions, VolumeInput};
use super::sniff::{extension, is_raster};
use crate::derive::{describe_missing, fill_missing, fill_missing_with, magnitude, vorticity};
use crate::domain::{Grid2d, Grid3d};
use crate::error::{Error, Result};
use crate::io::export::Carried;
use crate::io::grid::{raster_grid, read_grid_csv, read_raster, GridField};
use crate::io::npy_input::{read_numpy, NumpyField, Wanted};
use crate::io::vtk::{read_any_image, AnyImage};
use std::path::Path;

/// The points of an image as read: a 2D grid or a volume.
#[derive(Clone, Debug, PartialEq)]
enum Geometry {
    Flat(Grid2d),
    Volume(Grid3d),
}

impl Geometry {
    fn dims_text(&self) -> String {
        match self {
            Geometry::Flat(g) => format!("{} × {}", g.nx(), g.ny()),
            Geometry::Volume(g) => format!("{} × {} × {}", g.nx(), g.ny(), g.nz()),
        }
    }
    fn dims(&self) -> Vec<usize> {
        match self {
            Geometry::Flat(g) => vec![g.nx(), g.ny()],
            Geometry::Volume(g) => g.dims().to_vec(),
        }
    }
}

/// One array of a raw read: name, components, values.
struct Raw {
    geometry: Geometry,
    arrays: Vec<(String, usize, Vec<f64>)>,
    /// Arrays of the file that are not numeric: "`name` (type)".
    skipped: Vec<String>,
    /// The array a VTK file marks as its active scalars.
    active: Option<String>,
    /// A VTK image's arrays as read.
    carried: Option<Carried>,
    /// What reading found worth saying (an oblique affine).
    notes: Vec<String>,
}

fn read_raw(path: &Path, array: Option<&str>) -> Result<Raw> {
    let from_field = |f: GridField| Raw {
        arrays: vec![(f.array, 1, f.values)],
        geometry: Geometry::Flat(f.grid),
        skipped: Vec::new(),
        active: None,
        carried: None,
        notes: Vec::new(),
    };
    crate::io::content::check_extension(path)?;
    if crate::io::export::is_nifti(path) {
        return read_nifti_raw(path);
    }
    match extension(path).as_str() {
        "vti" | "vtk" => {
            let (geometry, arrays, cell, skipped, active, notes) = match read_any_image(path)? {
                AnyImage::Flat(img) => {
                    let grid = img.grid().map_err(|e| e.in_file(path))?;
                    (Geometry::Flat(grid), img.arrays, img.cell_arrays, img.skipped, img.active_scalars, img.notes)
                }
                AnyImage::Volume(v) => {
                    let grid = Grid3d::with_geometry(v.dims, v.spacing, v.origin).map_err(|e| e.in_file(path))?;
                    (Geometry::Volume(grid), v.arrays, v.cell_arrays, v.skipped, v.active_scalars, v.notes)
                }
            };
            let listed = arrays.iter().map(|a| (a.name.clone(), a.components, a.values.clone())).collect();
            let carried = Carried { point: arrays, cells: None, cell, source: None, affine: None };
            Ok(Raw { geometry, arrays: listed, skipped, active, carried: Some(carried), notes })
        }
        "npy" | "npz" => match read_numpy(path, array, Wanted::Grid)? {
            NumpyField::Grid(f) => Ok(from_field(f)),
            NumpyField::Volume { name, grid, values } => Ok(Raw {
                arrays: vec![(name, 1, values)],
                geometry: Geometry::Volume(grid),
                skipped: Vec::new(),
                active: None,
                carried: None,
                notes: Vec::new(),
            }),
            NumpyField::Series { name, .. } => {
                Err(Error::input(format!("array `{name}` is 1-D: a series, not a grid")).in_file(path))
            }
        },
        "png" | "tif" | "tiff" => read_raster(path).map(from_field),
        _ => read_grid_csv(path).map(from_field),
    }
}

/// A NIfTI volume: |pixdim| as spacing, the affine's translation as origin, the affine
/// itself carried to NIfTI outputs; one axis of extent 1 makes a 2D grid over the others.
#[cfg(feature = "io-nifti")]
fn read_nifti_raw(path: &Path) -> Result<Raw> {
    let v = crate::io::nifti::read_nifti(path)?;
    let mut notes = Vec::new();
    if v.oblique {
        notes.push(format!(
            "the {} affine is oblique: the volume is smoothed on its voxel grid (spacing |pixdim|, origin the \
             affine's translation); NIfTI outputs carry the affine, VTK outputs are axis-aligned",
            v.affine_source
        ));
    }
    let origin = v.origin();
    let name = "values".to_string();
    let flat: Vec<usize> = (0..3).filter(|&a| v.dims[a] > 1).collect();
    let geometry = match flat.as_slice() {
        [_, _, _] => Geometry::Volume(Grid3d::with_geometry(v.dims, v.spacing, origin).map_err(|e| e.in_file(path))?),
        &[a, b] => Geometry::Flat(
            Grid2d::with_geometry(v.dims[a], v.dims[b], [v.spacing[a], v.spacing[b]], [origin[a], origin[b]])
                .and_then(|g| g.in_plane(crate::domain::Plane { axes: [a, b], level: origin[3 - a - b] }))
                .map_err(|e| e.in_file(path))?,
        ),
        _ => {
            return Err(Error::input(format!(
                "the volume is {} × {} × {}: a grid needs at least two axes of 2 or more voxels",
                v.dims[0], v.dims[1], v.dims[2]
            ))
            .in_file(path))
        }
    };
    let carried = Carried { affine: Some(v.affine), source: Some(name.clone()), ..Carried::default() };
    Ok(Raw {
        geometry,
        arrays: vec![(name, 1, v.values)],
        skipped: Vec::new(),
        active: None,
        carried: Some(carried),
        notes,
    })
}

#[cfg(not(feature = "io-nifti"))]
fn read_nifti_raw(path: &Path) -> Result<Raw> {
    Err(Error::input("reading NIfTI files needs the io-nifti feature").in_file(path))
}

/// The geometry with `--spacing` applied: the file's origin kept, except for a raster, whose
/// spacing is its pixel size with the top row kept at the top ([`raster_grid`]).
fn with_spacing(path: &Path, geometry: &Geometry, spacing: Option<&[f64]>) -> Result<Geometry> {
    let Some(s) = spacing else {
        return Ok(geometry.clone());
    };
    match (geometry, s) {
        (Geometry::Flat(grid), &[dx, dy]) if is_raster(path) => {
            raster_grid(grid.nx(), grid.ny(), [dx, dy]).map(Geometry::Flat).map_err(|e| e.in_file(path))
        }
        (Geometry::Flat(grid), &[dx, dy]) => Grid2d::with_geometry(grid.nx(), grid.ny(), [dx, dy], grid.origin())
            .and_then(|g| g.in_plane(grid.plane()))
            .map(Geometry::Flat)
            .map_err(|e| e.in_file(path)),
        (Geometry::Volume(grid), &[dx, dy, dz]) => Grid3d::with_geometry(grid.dims(), [dx, dy, dz], grid.origin())
            .map(Geometry::Volume)
            .map_err(|e| e.in_file(path)),
        (Geometry::Flat(_), _) => Err(Error::Usage(format!(
            "{}: --spacing takes two numbers dx,dy for a 2D grid, got {}",
            path.display(),
            s.len()
        ))),
        (Geometry::Volume(_), _) => Err(Error::Usage(format!(
            "{}: --spacing takes three numbers dx,dy,dz for a volume, got {}",
            path.display(),
            s.len()
        ))),
    }
}

fn pick<'a>(path: &Path, raw: &'a Raw, name: Option<&str>, vector: bool) -> Result<&'a (String, usize, Vec<f64>)> {
    let listing = || {
        raw.arrays
            .iter()
            .map(|(n, c, _)| format!("`{n}` ({c} component{})", if *c == 1 { "" } else { "s" }))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(name) = name {
        return raw.arrays.iter().find(|(n, _, _)| n == name).ok_or_else(|| {
            let quoted = format!("`{name}` (");
            match raw.skipped.iter().find(|s| s.starts_with(&quoted)) {
                Some(s) => Error::input(format!("point array {s} does not hold numbers")),
                None => Error::input(format!("no point array named `{name}`; the file has {}", listing())),
            }
            .in_file(path)
        });
    }
    let fits: Vec<&(String, usize, Vec<f64>)> =
        raw.arrays.iter().filter(|(_, c, _)| if vector { *c == 2 || *c == 3 } else { *c == 1 }).collect();
    // as a VTK filter does: the active scalars when they fit
    if let Some(active) = raw.active.as_deref().and_then(|a| fits.iter().find(|(n, _, _)| n == a)) {
        if !vector {
            return Ok(active);
        }
    }
    match fits.as_slice() {
        [one] => Ok(one),
        [] => Err(Error::input(format!(
            "no {} point array; the file has {}",
            if vector { "vector (2 or 3 components)" } else { "scalar" },
            if raw.arrays.is_empty() { "none".to_string() } else { listing() }
        ))
        .in_file(path)),
        _ => {
            Err(Error::Usage(format!("{}: several arrays fit, choose one with --array: {}", path.display(), listing())))
        }
    }
}

/// Reads a grid or a volume with its options applied: array choice, spacing, derivation,
/// NaN policy.
///
/// # Errors
/// Input errors naming the file (unreadable, missing array, different grid sizes of `--u`
/// and `--v`, NaN without `--fill-missing`, a derivation the domain has not), usage errors
/// for contradictory options.
pub fn read_grid(path: &Path, opts: &ReadOptions) -> Result<FieldInput> {
    let mut carried = None;
    let mut notes = Vec::new();
    let spacing = opts.spacing.as_deref();
    let (geometry, mut values, description, source) = match (&opts.uv, opts.derive) {
        (Some(_), None) => return Err(Error::Usage("--u and --v need --derive vorticity|magnitude".into())),
        (Some((pu, pv)), Some(d)) => {
            let (ru, rv) = (read_raw(pu, opts.array.as_deref())?, read_raw(pv, opts.array.as_deref())?);
            if ru.geometry.dims() != rv.geometry.dims() {
                return Err(Error::input(format!(
                    "{} is {} but {} is {}",
                    pu.display(),
                    ru.geometry.dims_text(),
                    pv.display(),
                    rv.geometry.dims_text()
                )));
            }
            if let Geometry::Volume(_) = ru.geometry {
                return Err(Error::Usage(format!(
                    "{}: --u and --v give a 2D velocity; a volume's velocity is one 3-component array",
                    pu.display()
                )));
            }
            let a = pick(pu, &ru, opts.array.as_deref(), false)?;
            let b = pick(pv, &rv, opts.array.as_deref(), false)?;
            let geometry = with_spacing(pu, &ru.geometry, spacing)?;
            let Geometry::Flat(grid) = &geometry else { unreachable!("checked above") };
            let values = derive(pu, grid, d, &a.2, &b.2)?;
            (geometry, values, format!("{} of ({}, {})", d.name(), pu.display(), pv.display()), pu.clone())
        }
        (None, Some(d)) => {
            let raw = read_raw(path, opts.array.as_deref())?;
            let a = pick(path, &raw, opts.array.as_deref(), true)?;
            if a.1 != 2 && a.1 != 3 {
                return Err(Error::input(format!(
                    "--derive needs a vector array (2 or 3 components); `{}` has {}",
                    a.0, a.1
                ))
                .in_file(path));
            }
            let component = |k: usize| -> Vec<f64> { a.2.iter().skip(k).step_by(a.1).copied().collect() };
            let geometry = with_spacing(path, &raw.geometry, spacing)?;
            let values = match &geometry {
                Geometry::Flat(grid) => derive(path, grid, d, &component(0), &component(1))?,
                Geometry::Volume(grid) => {
                    if a.1 != 3 {
                        return Err(Error::input(format!(
                            "--derive on a volume needs a 3-component vector array; `{}` has {}",
                            a.0, a.1
                        ))
                        .in_file(path));
                    }
                    derive_volume(path, grid, d, [&component(0), &component(1), &component(2)])?
                }
            };
            let description = format!("{} of {}", d.name(), a.0);
            // the file's arrays move into the output's carried arrays, not copied
            carried = raw.carried;
            notes = raw.notes;
            (geometry, values, description, path.to_path_buf())
        }
        (None, None) => {
            let raw = read_raw(path, opts.array.as_deref())?;
            let a = pick(path, &raw, opts.array.as_deref(), false)?;
            if a.1 != 1 {
                return Err(Error::input(format!(
                    "`{}` has {} components; smooth a scalar array, or use --derive ({})",
                    a.0,
                    a.1,
                    match raw.geometry {
                        Geometry::Flat(_) => "vorticity or magnitude",
                        Geometry::Volume(_) => "vorticity-magnitude, vorticity-x|y|z or magnitude",
                    }
                ))
                .in_file(path));
            }
            let geometry = with_spacing(path, &raw.geometry, spacing)?;
            let (name, values) = (a.0.clone(), a.2.clone());
            carried = raw.carried.map(|c| Carried { source: Some(name.clone()), ..c });
            notes = raw.notes;
            (geometry, values, name, path.to_path_buf())
        }
    };
    let inside = match &opts.mask {
        None => None,
        Some(rule) => Some(mask_of(&source, rule, &values, carried.as_ref())?),
    };
    // NaN outside the mask is background, not missing data
    let probe: Option<Vec<f64>> =
        inside.as_ref().map(|m| values.iter().zip(m).map(|(&v, &i)| if i { v } else { 0.0 }).collect());
    let checked = probe.as_deref().unwrap_or(&values);
    let missing = match &geometry {
        Geometry::Flat(grid) => describe_missing(grid, checked, 5),
        Geometry::Volume(grid) => describe_missing_in_volume(grid, checked, 5),
    };
    let mut filled = None;
    if let Some(what) = missing {
        if !opts.fill_missing {
            let whose = if opts.derive.is_some() {
                format!(
                    "the derived {description} has {what} (a missing vector makes the derivative missing wherever its stencil uses it)"
                )
            } else {
                what
            };
            return Err(
                Error::input(format!("{whose}; pass --fill-missing to fill them harmonically")).in_file(&source)
            );
        }
        let background: Vec<bool> = match &inside {
            Some(m) => values.iter().zip(m).map(|(v, &i)| v.is_nan() && !i).collect(),
            None => vec![false; values.len()],
        };
        let mask: Vec<bool> = values.iter().zip(&background).map(|(v, &b)| v.is_nan() && !b).collect();
        match &geometry {
            Geometry::Flat(grid) => fill_missing(grid, &mut values),
            Geometry::Volume(grid) => fill_missing_with(&crate::operators::volume_stiffness(grid), &mut values),
        }
        .map_err(|e| e.in_file(&source))?;
        for (v, &b) in values.iter_mut().zip(&background) {
            if b {
                *v = f64::NAN;
            }
        }
        filled = Some(mask);
    }
    Ok(match geometry {
        Geometry::Flat(grid) => FieldInput::Grid(GridInput {
            grid,
            values,
            description,
            filled,
            path: source,
            carried,
            notes,
            mask: inside,
        }),
        Geometry::Volume(grid) => FieldInput::Volume(VolumeInput {
            grid,
            values,
            description,
            filled,
            path: source,
            carried,
            notes,
            mask: inside,
        }),
    })
}

/// The voxels (pixels) inside a mask: where the named array of the file (a carried VTK array, or
/// another array of the `.npz`) is non-zero, or where the field is at least the threshold.
fn mask_of(path: &Path, rule: &MaskRule, values: &[f64], carried: Option<&Carried>) -> Result<Vec<bool>> {
    let inside = match rule {
        MaskRule::Below(t) => values.iter().map(|v| *v >= *t).collect(),
        MaskRule::Array(name) => {
            let array: Vec<f64> = match carried.and_then(|c| c.point.iter().find(|a| &a.name == name)) {
                Some(a) if a.components == 1 => a.values.clone(),
                Some(a) => {
                    return Err(Error::input(format!(
                        "the mask array `{name}` has {} components; a mask is one value per voxel",
                        a.components
                    ))
                    .in_file(path))
                }
                None if extension(path) == "npz" => match read_numpy(path, Some(name), Wanted::Grid)? {
                    NumpyField::Volume { values, .. } => values,
                    _ => return Err(Error::input(format!("the mask array `{name}` is not a volume")).in_file(path)),
                },
                None => {
                    let found = carried
                        .map(|c| c.point.iter().map(|a| format!("`{}`", a.name)).collect::<Vec<_>>().join(", "))
                        .filter(|t| !t.is_empty())
                        .unwrap_or_else(|| "no other arrays".into());
                    return Err(Error::input(format!(
                        "no point array `{name}` for --mask (the file holds {found}; --mask-below V masks by value)"
                    ))
                    .in_file(path));
                }
            };
            if array.len() != values.len() {
                return Err(Error::input(format!(
                    "the mask array `{name}` has {} values, the volume {} voxels",
                    array.len(),
                    values.len()
                ))
                .in_file(path));
            }
            array.iter().map(|&m| m != 0.0 && !m.is_nan()).collect()
        }
    };
    Ok(inside)
}

/// The first few missing samples of a volume as `(i, j, k)` text.
fn describe_missing_in_volume(grid: &Grid3d, values: &[f64], limit: usize) -> Option<String> {
    crate::derive::describe_missing_with(values, limit, |v| {
        let [i, j, k] = grid.ijk(v);
        format!("(i {i}, j {j}, k {k})")
    })
}

/// A 2D grid's derived scalar.
fn derive(path: &Path, grid: &Grid2d, d: Derive, u: &[f64], v: &[f64]) -> Result<Vec<f64>> {
    match d {
        Derive::Vorticity => Ok(vorticity(grid, u, v)),
        Derive::Magnitude => Ok(magnitude(u, v)),
        _ => Err(Error::Usage(format!(
            "{}: --derive {} is for volumes; on a 2D grid use vorticity (the signed ∂v/∂x − ∂u/∂y) or magnitude",
            path.display(),
            d.name()
        ))),
    }
}

/// A volume's derived scalar (central differences, one-sided at the boundary, signed spacing).
fn derive_volume(path: &Path, grid: &Grid3d, d: Derive, uvw: [&[f64]; 3]) -> Result<Vec<f64>> {
    use crate::derive::{curl, magnitude3};
    Ok(match d {
        Derive::Magnitude => magnitude3(uvw),
        Derive::VorticityMagnitude => {
            let w = curl(grid, uvw);
            magnitude3([&w[0], &w[1], &w[2]])
        }
        Derive::VorticityX => curl(grid, uvw)[0].clone(),
        Derive::VorticityY => curl(grid, uvw)[1].clone(),
        Derive::VorticityZ => curl(grid, uvw)[2].clone(),
        Derive::Vorticity => {
            return Err(Error::Usage(format!(
                "{}: --derive vorticity is the signed 2D vorticity; on a volume use vorticity-magnitude or \
                 vorticity-x, vorticity-y, vorticity-z (the curl's components)",
                path.display()
            )))
        }
    })
}
