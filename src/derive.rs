//! Scalar fields derived from measured grid data before smoothing: vorticity and speed of a
//! velocity field, and harmonic filling of missing (NaN) samples.
//!
//! Derivatives use the signed spacing (SPEC.md: PIV rows often run downwards, dy < 0, and
//! vorticity keeps its physical sign): second-order central differences inside, first-order
//! one-sided differences at the boundary, as `numpy.gradient` does. A missing sample makes
//! every derivative whose stencil touches it missing, and a rejected vector has no vorticity
//! of its own: a NaN velocity makes the vorticity NaN there and at its left, right, upper and
//! lower neighbours (the bundled PIV vorticity was made the same way: 774 missing cells from
//! 353 rejected vectors).
//!
//! ```
//! use toposmooth::{derive::vorticity, domain::Grid2d};
//! // solid-body rotation u = −y, v = x has vorticity 2 everywhere
//! let g = Grid2d::with_geometry(4, 3, [0.5, 0.5], [0.0, 0.0])?;
//! let (u, v): (Vec<f64>, Vec<f64>) = (0..12).map(|i| {
//!     let (x, y) = ((i % 4) as f64 * 0.5, (i / 4) as f64 * 0.5);
//!     (-y, x)
//! }).unzip();
//! assert!(vorticity(&g, &u, &v).iter().all(|w| (w - 2.0).abs() < 1e-12));
//! # Ok::<(), toposmooth::Error>(())
//! ```
//!
//! On a volume, [`curl`] gives the vorticity vector ∇ × (u, v, w) with the same differences
//! along x, y and z.

use crate::domain::{Grid2d, Grid3d};
use crate::error::{Error, Result};
use crate::operators::{dirichlet_solve, grid_stiffness};

/// ∂f/∂x (along columns, spacing dx) and ∂f/∂y (along rows, spacing dy) at every vertex.
pub fn gradient(grid: &Grid2d, f: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (nx, ny) = (grid.nx(), grid.ny());
    let [dx, dy] = grid.spacing();
    let d = |a: f64, b: f64, h: f64| (b - a) / h;
    let mut fx = vec![0.0; nx * ny];
    let mut fy = vec![0.0; nx * ny];
    for r in 0..ny {
        for c in 0..nx {
            let i = r * nx + c;
            fx[i] = match c {
                0 => d(f[i], f[i + 1], dx),
                _ if c == nx - 1 => d(f[i - 1], f[i], dx),
                _ => d(f[i - 1], f[i + 1], 2.0 * dx),
            };
            fy[i] = match r {
                0 => d(f[i], f[i + nx], dy),
                _ if r == ny - 1 => d(f[i - nx], f[i], dy),
                _ => d(f[i - nx], f[i + nx], 2.0 * dy),
            };
        }
    }
    (fx, fy)
}

/// Vorticity ω = ∂v/∂x − ∂u/∂y of the velocity (u, v); missing where the vector itself or
/// one its stencil uses is missing.
pub fn vorticity(grid: &Grid2d, u: &[f64], v: &[f64]) -> Vec<f64> {
    let (vx, _) = gradient(grid, v);
    let (_, uy) = gradient(grid, u);
    (0..u.len()).map(|i| if u[i].is_nan() || v[i].is_nan() { f64::NAN } else { vx[i] - uy[i] }).collect()
}

/// Speed |(u, v)|.
pub fn magnitude(u: &[f64], v: &[f64]) -> Vec<f64> {
    u.iter().zip(v).map(|(a, b)| a.hypot(*b)).collect()
}

/// ∂f/∂x_a along each axis a of a volume (signed spacing; central inside, one-sided at the
/// boundary).
pub fn gradient3(grid: &Grid3d, f: &[f64]) -> [Vec<f64>; 3] {
    let n = grid.dims();
    let h = grid.spacing();
    let stride = [1, n[0], n[0] * n[1]];
    let mut out = [vec![0.0; f.len()], vec![0.0; f.len()], vec![0.0; f.len()]];
    for (v, _) in f.iter().enumerate() {
        let p = grid.ijk(v);
        for a in 0..3 {
            let s = stride[a];
            out[a][v] = if p[a] == 0 {
                (f[v + s] - f[v]) / h[a]
            } else if p[a] + 1 == n[a] {
                (f[v] - f[v - s]) / h[a]
            } else {
                (f[v + s] - f[v - s]) / (2.0 * h[a])
            };
        }
    }
    out
}

/// The curl ∇ × (u, v, w) of a volume's velocity, component by component (x, y, z); NaN
/// wherever a vector its stencils use is missing.
pub fn curl(grid: &Grid3d, [u, v, w]: [&[f64]; 3]) -> [Vec<f64>; 3] {
    let [ux, uy, uz] = gradient3(grid, u);
    let [vx, vy, vz] = gradient3(grid, v);
    let [wx, wy, wz] = gradient3(grid, w);
    let _ = (ux, vy, wz);
    let missing = |i: usize| u[i].is_nan() || v[i].is_nan() || w[i].is_nan();
    let masked = |c: Vec<f64>| -> Vec<f64> {
        c.into_iter().enumerate().map(|(i, x)| if missing(i) { f64::NAN } else { x }).collect()
    };
    let n = u.len();
    [
        masked((0..n).map(|i| wy[i] - vz[i]).collect()),
        masked((0..n).map(|i| uz[i] - wx[i]).collect()),
        masked((0..n).map(|i| vx[i] - uy[i]).collect()),
    ]
}

/// |(u, v, w)|.
pub fn magnitude3([u, v, w]: [&[f64]; 3]) -> Vec<f64> {
    (0..u.len()).map(|i| (u[i] * u[i] + v[i] * v[i] + w[i] * w[i]).sqrt()).collect()
}

/// The first few missing samples as `(row r, column c)` text.
pub fn describe_missing(grid: &Grid2d, values: &[f64], limit: usize) -> Option<String> {
    describe_missing_with(values, limit, |i| {
        let (r, c) = grid.row_col(i);
        format!("(row {r}, column {c})")
    })
}

/// The count of missing (NaN) samples and the first `limit` of them, each named by `name`;
/// `None` when there are none.
pub fn describe_missing_with(values: &[f64], limit: usize, name: impl Fn(usize) -> String) -> Option<String> {
    let missing: Vec<usize> = values.iter().enumerate().filter(|(_, v)| v.is_nan()).map(|(i, _)| i).collect();
    if missing.is_empty() {
        return None;
    }
    let first: Vec<String> = missing.iter().take(limit).map(|&i| name(i)).collect();
    Some(format!(
        "{} missing (NaN) samples, first {}{}",
        missing.len(),
        first.join(", "),
        if missing.len() > limit { ", …" } else { "" }
    ))
}

/// Fills missing (NaN) samples by harmonic interpolation from the others (5-point Laplacian
/// with the grid's spacing: every filled value lies between known values around its hole);
/// returns how many were filled.
///
/// # Errors
/// Every sample is missing.
pub fn fill_missing(grid: &Grid2d, values: &mut [f64]) -> Result<usize> {
    fill_missing_with(&grid_stiffness(grid), values)
}

/// [`fill_missing`] with any Laplacian `k` of non-negative weights (meshes: the
/// positive-weight cotangent one).
///
/// # Errors
/// Every value missing, or a connected part with no known value.
pub fn fill_missing_with(k: &crate::operators::Sparse, values: &mut [f64]) -> Result<usize> {
    let fixed: Vec<Option<f64>> = values.iter().map(|&v| (!v.is_nan()).then_some(v)).collect();
    let count = fixed.iter().filter(|f| f.is_none()).count();
    if count == 0 {
        return Ok(0);
    }
    if count == values.len() {
        return Err(Error::input("every sample is missing (NaN): nothing to fill from"));
    }
    let known = crate::domain::value_range(values.iter().filter(|v| !v.is_nan()));
    if known.0 == known.1 {
        // a constant stays exactly constant (a solve would add rounding noise, i.e. extrema)
        values.iter_mut().for_each(|v| *v = known.0);
        return Ok(count);
    }
    let filled = dirichlet_solve(k, &fixed)
        .map_err(|_| Error::input("fill: a connected part of the domain has no known value to fill from (all NaN)"))?;
    values.copy_from_slice(&filled);
    Ok(count)
}

#[cfg(test)]
mod tests {
    #[test]
    fn curl_of_a_rotation_and_a_shear_with_signed_spacing() {
        // rotation about z (u = −y, v = x, w = 0) has curl (0, 0, 2); the shear u = z has
        // curl (0, 1, 0); a negative dy is honoured (positions run downwards in y)
        let g = Grid3d::with_geometry([4, 5, 3], [0.5, -0.25, 2.0], [1.0, 2.0, 3.0]).unwrap();
        let n = 4 * 5 * 3;
        let at = |v: usize| g.world(v);
        let u: Vec<f64> = (0..n).map(|v| -at(v)[1] + at(v)[2]).collect();
        let w_: Vec<f64> = (0..n).map(|v| at(v)[0]).collect();
        let zero = vec![0.0; n];
        let c = curl(&g, [&u, &w_, &zero]);
        for ((x, y), z) in c[0].iter().zip(&c[1]).zip(&c[2]) {
            assert!(x.abs() < 1e-12 && (y - 1.0).abs() < 1e-12 && (z - 2.0).abs() < 1e-12);
        }
        let m = magnitude3([&c[0], &c[1], &c[2]]);
        assert!((m[7] - 5f64.sqrt()).abs() < 1e-12);
    }

    use super::*;

    #[test]
    fn derivatives_are_exact_for_quadratics_inside_and_linears_everywhere() {
        let g = Grid2d::with_geometry(6, 5, [0.5, -2.0], [0.0, 0.0]).unwrap();
        let pos = |i: usize| ((i % 6) as f64 * 0.5, (i / 6) as f64 * -2.0);
        let lin: Vec<f64> = (0..30).map(|i| 3.0 * pos(i).0 - 0.5 * pos(i).1).collect();
        let (fx, fy) = gradient(&g, &lin);
        assert!(fx.iter().all(|d| (d - 3.0).abs() < 1e-12));
        assert!(fy.iter().all(|d| (d + 0.5).abs() < 1e-12), "negative dy keeps the physical sign");
        let quad: Vec<f64> = (0..30).map(|i| pos(i).0 * pos(i).0).collect();
        let (fx, _) = gradient(&g, &quad);
        for r in 0..5 {
            for c in 1..5 {
                let i = r * 6 + c;
                assert!((fx[i] - 2.0 * pos(i).0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn nan_spreads_through_the_stencil_only() {
        let g = Grid2d::new(5, 5).unwrap();
        let mut u = vec![1.0; 25];
        let v = vec![0.0; 25];
        u[12] = f64::NAN; // centre
        let w = vorticity(&g, &u, &v);
        let bad: Vec<usize> = (0..25).filter(|&i| w[i].is_nan()).collect();
        // ∂u/∂y at rows 1 and 3 of column 2 use u[12]; the centre has no vector
        assert_eq!(bad, vec![7, 12, 17]);
        assert!(magnitude(&u, &v)[12].is_nan());
    }

    #[test]
    fn harmonic_fill_stays_within_the_known_values() {
        let g = Grid2d::new(7, 6).unwrap();
        let mut f: Vec<f64> = (0..42).map(|i| (i % 7) as f64 + 0.1 * (i / 7) as f64).collect();
        let truth = f.clone();
        for i in [8, 9, 15, 16, 0, 1, 7] {
            f[i] = f64::NAN;
        }
        assert!(describe_missing(&g, &f, 2).unwrap().starts_with("7 missing (NaN) samples, first (row 0, column 0)"));
        assert_eq!(fill_missing(&g, &mut f).unwrap(), 7);
        // the hole touches the boundary (Neumann there): every filled value lies within the
        // known values around it
        let (lo, hi) = (truth[2].min(truth[14]), truth[23].max(truth[17]));
        for i in [8, 9, 15, 16, 0, 1, 7] {
            assert!(f[i] > lo - 1e-12 && f[i] < hi + 1e-12, "{i}: {}", f[i]);
        }
        // an interior hole in a linear field is filled exactly (5-point stencil)
        let mut f = truth.clone();
        for i in [8, 9, 15, 16, 24] {
            f[i] = f64::NAN;
        }
        assert_eq!(fill_missing(&g, &mut f).unwrap(), 5);
        for i in 0..42 {
            assert!((f[i] - truth[i]).abs() < 1e-9, "{i}: {} vs {}", f[i], truth[i]);
        }
        let mut all = vec![f64::NAN; 42];
        assert!(fill_missing(&g, &mut all).is_err());
        // one known value fills everything with exactly that value
        let mut one = vec![f64::NAN; 42];
        one[17] = 0.1;
        assert_eq!(fill_missing(&g, &mut one).unwrap(), 41);
        assert!(one.iter().all(|&v| v == 0.1));
    }
}
