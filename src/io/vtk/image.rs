//! A 2D image from VTK image data: extent, origin, spacing and `Direction` turned into a grid.
//!
//! A `Direction` that permutes and flips the axes is honoured exactly: a flip becomes a
//! negative spacing, a swap of x and y a transposition of the arrays, so every point keeps
//! the physical position VTK gives it. An oblique direction (a rotation that is not a
//! multiple of 90°) is an error: a grid's axes run along x and y.

use super::data::{list_names, AnyImage, Dataset, ImageData, PointArray, VolumeData};
use crate::error::{Error, Result};

/// The 2D image a data set holds.
///
/// # Errors
/// Input errors: not image data, more than one point along z, fewer than 2 × 2 points, an
/// oblique direction or one that tilts the image out of the x-y plane, no point data.
pub(super) fn image_of(ds: Dataset) -> Result<ImageData> {
    let g = ds
        .image
        .ok_or_else(|| Error::input("the data set is not image data (XML ImageData or legacy STRUCTURED_POINTS)"))?;
    let [nx, ny, nz] = g.dims();
    let ext = g.extent;
    let extent_text = format!("{} {} {} {} {} {}", ext[0], ext[1], ext[2], ext[3], ext[4], ext[5]);
    if nz > 1 {
        return Err(Error::input(format!(
            "the extent `{extent_text}` has {nz} points along z: only 2D images (one point along z) are supported"
        )));
    }
    if nx < 2 || ny < 2 || nz < 1 {
        return Err(Error::input(format!(
            "the extent `{extent_text}` gives {nx} × {ny} × {nz} points: a 2D image needs at least 2 × 2 points in the x-y plane"
        )));
    }
    let axes = axes_of(&g.direction)?;
    if axes[2].0 != 2 {
        return Err(Error::input(format!(
            "the Direction `{}` turns the image out of the x-y plane; only images in the x-y plane are supported",
            text(&g.direction)
        )));
    }
    let mut arrays = ds.point_data;
    let mut cell_arrays = ds.cell_data;
    let skipped = &ds.skipped;
    if arrays.is_empty() {
        return Err(no_point_data(&cell_arrays, skipped));
    }
    // index axis a lies along physical axis axes[a].0 with sign axes[a].1
    let coord = |a: usize, t: i64| g.origin[axes[a].0] + axes[a].1 * t as f64 * g.spacing[a];
    let step = |a: usize| axes[a].1 * g.spacing[a];
    let mut notes = Vec::new();
    let (nxg, nyg, spacing, origin) = if axes[0].0 == 0 {
        (nx, ny, [step(0), step(1)], [coord(0, ext[0]), coord(1, ext[2])])
    } else {
        for a in &mut arrays {
            *a = transposed(a, nx, ny);
        }
        for a in &mut cell_arrays {
            *a = transposed(a, nx - 1, ny - 1);
        }
        notes.push(format!(
            "the Direction `{}` swaps x and y: the arrays are transposed, so that the grid's x axis is the file's j axis",
            text(&g.direction)
        ));
        (ny, nx, [step(1), step(0)], [coord(1, ext[2]), coord(0, ext[0])])
    };
    let flips: Vec<&str> = [(0, "x"), (1, "y")].iter().filter(|(a, _)| axes[*a].1 < 0.0).map(|(_, n)| *n).collect();
    if !flips.is_empty() {
        notes.push(format!(
            "the Direction `{}` flips {}: written as a negative spacing",
            text(&g.direction),
            flips.join(" and ")
        ));
    }
    Ok(ImageData {
        nx: nxg,
        ny: nyg,
        spacing,
        origin,
        plane: crate::domain::Plane { axes: [0, 1], level: coord(2, ext[4]) },
        arrays,
        cell_arrays,
        notes,
        skipped: ds.skipped,
        active_scalars: ds.active_scalars,
    })
}

/// An image in the x-z or y-z plane (one point along x or y): a 2D grid over its other two
/// axes, whose points are already in the grid's order (x fastest, the flat axis contributes
/// nothing to the index). The grid's x and y are the file's two axes; outputs are written in
/// the same plane.
fn plane_of(ds: Dataset, g: &super::data::ImageGeometry) -> Result<ImageData> {
    let dims = g.dims();
    let axes = axes_of(&g.direction)?;
    if axes.iter().enumerate().any(|(a, &(p, sign))| a != p || sign < 0.0) {
        return Err(Error::input(format!(
            "the Direction `{}` of an image with one point along {}: only the identity direction is supported for images outside the x-y plane",
            text(&g.direction),
            if dims[0] == 1 { "x" } else { "y" }
        )));
    }
    if ds.point_data.is_empty() {
        return Err(no_point_data(&ds.cell_data, &ds.skipped));
    }
    let (u, v) = if dims[0] == 1 { (1, 2) } else { (0, 2) };
    let names = ["x", "y", "z"];
    let ext = g.extent;
    let start = |a: usize| g.origin[a] + ext[2 * a] as f64 * g.spacing[a];
    Ok(ImageData {
        nx: dims[u],
        ny: dims[v],
        spacing: [g.spacing[u], g.spacing[v]],
        origin: [start(u), start(v)],
        plane: crate::domain::Plane { axes: [u, v], level: start(3 - u - v) },
        arrays: ds.point_data,
        // cells of a flat image: none along the flat axis, the same order
        cell_arrays: ds.cell_data,
        notes: vec![format!(
            "the image lies in the {}-{} plane: smoothed as a 2D grid with the file's {} and {} as its x and y (image outputs lie in the same plane)",
            names[u], names[v], names[u], names[v]
        )],
        skipped: ds.skipped,
        active_scalars: ds.active_scalars,
    })
}

/// The image a data set holds: a volume when every axis has at least 2 points, a 2D grid
/// when one axis has one point ([`image_of`] in the x-y plane, else [`plane_of`]).
///
/// # Errors
/// As [`image_of`], without its limit on z.
pub(super) fn any_image_of(ds: Dataset) -> Result<AnyImage> {
    let Some(g) = ds.image.as_ref() else {
        return image_of(ds).map(AnyImage::Flat);
    };
    let dims = g.dims();
    if dims[2] > 1 && (dims[0] == 1) != (dims[1] == 1) {
        let g = g.clone();
        return plane_of(ds, &g).map(AnyImage::Flat);
    }
    if dims.iter().any(|&d| d < 2) {
        return image_of(ds).map(AnyImage::Flat);
    }
    let g = g.clone();
    let axes = axes_of(&g.direction)?;
    let mut arrays = ds.point_data;
    let mut cell_arrays = ds.cell_data;
    if arrays.is_empty() {
        return Err(no_point_data(&cell_arrays, &ds.skipped));
    }
    let ext = g.extent;
    // physical axis p is index axis `index_of[p]`
    let mut index_of = [0usize; 3];
    for (a, &(p, _)) in axes.iter().enumerate() {
        index_of[p] = a;
    }
    let out_dims = [0, 1, 2].map(|p| dims[index_of[p]]);
    let spacing = [0, 1, 2].map(|p| axes[index_of[p]].1 * g.spacing[index_of[p]]);
    let origin =
        [0, 1, 2].map(|p| g.origin[p] + axes[index_of[p]].1 * ext[2 * index_of[p]] as f64 * g.spacing[index_of[p]]);
    let mut notes = Vec::new();
    if index_of != [0, 1, 2] {
        for a in &mut arrays {
            *a = permuted(a, dims, index_of);
        }
        let cells = dims.map(|d| d - 1);
        for a in &mut cell_arrays {
            *a = permuted(a, cells, index_of);
        }
        notes.push(format!(
            "the Direction `{}` permutes the axes: the arrays are reordered so that the grid's axes are x, y and z",
            text(&g.direction)
        ));
    }
    let flips: Vec<&str> =
        [(0, "x"), (1, "y"), (2, "z")].iter().filter(|(p, _)| axes[index_of[*p]].1 < 0.0).map(|(_, n)| *n).collect();
    if !flips.is_empty() {
        notes.push(format!(
            "the Direction `{}` flips {}: written as a negative spacing",
            text(&g.direction),
            flips.join(" and ")
        ));
    }
    Ok(AnyImage::Volume(VolumeData {
        dims: out_dims,
        spacing,
        origin,
        arrays,
        cell_arrays,
        notes,
        skipped: ds.skipped,
        active_scalars: ds.active_scalars,
    }))
}

/// Why an image without point arrays cannot be smoothed: cell data only, non-numeric arrays,
/// or nothing.
fn no_point_data(cell_arrays: &[PointArray], skipped: &[String]) -> Error {
    if !cell_arrays.is_empty() {
        let names: Vec<&str> = cell_arrays.iter().map(|a| a.name.as_str()).collect();
        Error::input(format!(
            "the file has cell data only ({}); point data is needed (ParaView: Cell Data to Point Data)",
            list_names(&names)
        ))
    } else if !skipped.is_empty() {
        Error::input(format!("the file's point arrays are not numeric: {}", skipped.join(", ")))
    } else {
        Error::input("the file has no point data arrays")
    }
}

/// The array with its index axes reordered: output axis p is input axis `index_of[p]`.
fn permuted(a: &PointArray, dims: [usize; 3], index_of: [usize; 3]) -> PointArray {
    let c = a.components;
    let out_dims = [0, 1, 2].map(|p| dims[index_of[p]]);
    let stride = [1, dims[0], dims[0] * dims[1]];
    let mut values = Vec::with_capacity(a.values.len());
    for k in 0..out_dims[2] {
        for j in 0..out_dims[1] {
            for i in 0..out_dims[0] {
                let q = [i, j, k];
                let mut src = 0;
                for p in 0..3 {
                    src += q[p] * stride[index_of[p]];
                }
                values.extend_from_slice(&a.values[src * c..src * c + c]);
            }
        }
    }
    PointArray { name: a.name.clone(), components: c, values, ty: a.ty }
}

/// For each index axis, the physical axis it runs along and its sign, if the direction is a
/// signed permutation.
fn axes_of(d: &[f64; 9]) -> Result<[(usize, f64); 3]> {
    let oblique = || {
        Error::input(format!(
            "the Direction `{}` is oblique: only axis-aligned images (permutations and flips of the axes) are \
             supported; resample it in ParaView (Resample To Image)",
            text(d)
        ))
    };
    let mut axes = [(0, 1.0); 3];
    let mut used = [false; 3];
    for (a, axis) in axes.iter_mut().enumerate() {
        // column a of the row-major matrix
        let col = [d[a], d[3 + a], d[6 + a]];
        let ones: Vec<usize> = (0..3).filter(|&r| col[r].abs() == 1.0).collect();
        if ones.len() != 1 || (0..3).any(|r| r != ones[0] && col[r] != 0.0) || used[ones[0]] {
            return Err(oblique());
        }
        used[ones[0]] = true;
        *axis = (ones[0], col[ones[0]]);
    }
    Ok(axes)
}

fn text(d: &[f64; 9]) -> String {
    d.iter().map(|v| crate::io::format_f64(*v).trim_end_matches(".0").to_string()).collect::<Vec<_>>().join(" ")
}

/// The array with rows and columns exchanged: point (i, j) of an `nx × ny` image becomes
/// point (j, i) of an `ny × nx` one.
fn transposed(a: &PointArray, nx: usize, ny: usize) -> PointArray {
    let c = a.components;
    let mut values = Vec::with_capacity(a.values.len());
    for i in 0..nx {
        for j in 0..ny {
            let k = (j * nx + i) * c;
            values.extend_from_slice(&a.values[k..k + c]);
        }
    }
    PointArray { name: a.name.clone(), components: c, values, ty: a.ty }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::vtk::data::ImageGeometry;

    fn image(direction: [f64; 9]) -> Dataset {
        Dataset {
            image: Some(ImageGeometry {
                extent: [0, 2, 0, 1, 0, 0],
                origin: [1.0, -2.0, 0.0],
                spacing: [0.5, 0.25, 1.0],
                direction,
            }),
            point_data: vec![PointArray {
                name: "f".into(),
                components: 1,
                values: vec![0.0, 1.0, 2.0, 10.0, 11.0, 12.0],
                ty: crate::io::vtk::Scalar::F64,
            }],
            ..Dataset::default()
        }
    }

    /// Each point's value must sit at the physical position VTK gives it:
    /// origin + D · (i·sx, j·sy).
    fn check_positions(direction: [f64; 9]) {
        let img = image_of(image(direction)).unwrap();
        let f = &img.arrays[0].values;
        for i in 0..3 {
            for j in 0..2 {
                let (ix, jy) = (i as f64 * 0.5, j as f64 * 0.25);
                let p = [1.0 + direction[0] * ix + direction[1] * jy, -2.0 + direction[3] * ix + direction[4] * jy];
                let value = (10 * j + i) as f64;
                let k = f.iter().position(|&v| v == value).unwrap();
                let (c, r) = (k % img.nx, k / img.nx);
                let q = [img.origin[0] + c as f64 * img.spacing[0], img.origin[1] + r as f64 * img.spacing[1]];
                assert_eq!(p, q, "point ({i}, {j}) with direction {direction:?}");
            }
        }
    }

    #[test]
    fn permutations_and_flips_keep_every_point_where_vtk_puts_it() {
        for d in [
            [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0],
            [0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        ] {
            check_positions(d);
        }
        let swapped = image_of(image([0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0])).unwrap();
        assert_eq!((swapped.nx, swapped.ny), (2, 3));
        assert!(swapped.notes[0].contains("swaps x and y"), "{:?}", swapped.notes);
    }

    #[test]
    fn oblique_and_tilted_directions_are_refused() {
        let c = 0.5f64.sqrt();
        let e = image_of(image([c, -c, 0.0, c, c, 0.0, 0.0, 0.0, 1.0])).unwrap_err().to_string();
        assert!(e.contains("oblique") && e.contains("Resample To Image"), "{e}");
        let e = image_of(image([1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0])).unwrap_err().to_string();
        assert!(e.contains("out of the x-y plane"), "{e}");
        let e = image_of(image([1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0])).unwrap_err().to_string();
        assert!(e.contains("oblique"), "{e}");
    }
}
