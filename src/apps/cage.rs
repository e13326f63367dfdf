//! Cage weights for 2D shapes (SPEC.md "Fixed regions"; DeRose & Meyer's harmonic
//! coordinates, made smooth and monotone): the cage polygon's interior is triangulated, each
//! cage vertex gets one function whose boundary values are its hat function along the cage
//! (1 at the vertex, linear to 0 at its neighbours, 0 on the rest), solved and certified on
//! that triangulation, then interpolated onto the shape (reported, not certified).

use super::outline::{triangulate, Outline, MAX_TRIANGLES};
use super::weights::{weights_prescribed, WeightSettings, Weights};
use crate::domain::{Domain, TriMesh};
use crate::error::{Error, Result};

/// Cage weights on the cage's triangulation and on the shape.
#[derive(Clone, Debug)]
pub struct CageWeights {
    /// The triangulated cage interior (its first vertices are the cage's corners).
    pub cage_mesh: TriMesh,
    /// The certified functions there (one per cage vertex).
    pub weights: Weights,
    /// Raw functions interpolated onto the shape's vertices.
    pub raw_on_shape: Vec<Vec<f64>>,
    /// Normalised functions interpolated onto the shape's vertices (a partition of unity).
    pub normalised_on_shape: Vec<Vec<f64>>,
    /// Largest |Σ_j w_j c_j − p| over the shape (linear reproduction of the normalised weights).
    pub reproduction_error: f64,
}

/// Hat-function boundary values: for every vertex of `mesh` on the cage polygon, `(edge, t)`
/// with the vertex at `(1 − t) c_edge + t c_{edge+1}`.
fn boundary_parameters(mesh: &TriMesh, cage: &[[f64; 2]]) -> Vec<Option<(usize, f64)>> {
    let m = cage.len();
    let tol = 1e-9 * mesh.diameter();
    mesh.positions()
        .iter()
        .map(|p| {
            (0..m).find_map(|e| {
                let (a, b) = (cage[e], cage[(e + 1) % m]);
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let l2 = dx * dx + dy * dy;
                let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0);
                let (qx, qy) = (a[0] + t * dx, a[1] + t * dy);
                ((p[0] - qx).hypot(p[1] - qy) <= tol).then_some((e, t))
            })
        })
        .collect()
}

/// Even–odd point-in-polygon test.
fn inside(p: [f64; 2], poly: &[[f64; 2]]) -> bool {
    let mut c = false;
    let m = poly.len();
    for i in 0..m {
        let (a, b) = (poly[i], poly[(i + 1) % m]);
        if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
            c = !c;
        }
    }
    c
}

/// Barycentric interpolation of per-vertex `values` of `mesh` at `points`: the containing
/// triangle is found through a uniform grid of triangle bounding boxes.
fn interpolate(mesh: &TriMesh, fields: &[Vec<f64>], points: &[[f64; 3]]) -> Result<Vec<Vec<f64>>> {
    let pos = mesh.positions();
    let tris = mesh.faces();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in pos {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let cells = ((tris.len() as f64).sqrt().ceil() as usize).max(1);
    let size = [(hi[0] - lo[0]) / cells as f64, (hi[1] - lo[1]) / cells as f64];
    let cell_of = |x: f64, k: usize| (((x - lo[k]) / size[k]).floor().max(0.0) as usize).min(cells - 1);
    let mut grid: Vec<Vec<usize>> = vec![Vec::new(); cells * cells];
    for (t, tri) in tris.iter().enumerate() {
        let xs = tri.map(|v| pos[v][0]);
        let ys = tri.map(|v| pos[v][1]);
        let (c0, c1) = (
            cell_of(xs.iter().copied().fold(f64::INFINITY, f64::min), 0),
            cell_of(xs.iter().copied().fold(f64::NEG_INFINITY, f64::max), 0),
        );
        let (r0, r1) = (
            cell_of(ys.iter().copied().fold(f64::INFINITY, f64::min), 1),
            cell_of(ys.iter().copied().fold(f64::NEG_INFINITY, f64::max), 1),
        );
        for r in r0..=r1 {
            for c in c0..=c1 {
                grid[r * cells + c].push(t);
            }
        }
    }
    let mut out: Vec<Vec<f64>> = vec![vec![0.0; points.len()]; fields.len()];
    for (i, p) in points.iter().enumerate() {
        let cands = &grid[cell_of(p[1], 1) * cells + cell_of(p[0], 0)];
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        for &t in cands {
            let [a, b, c] = tris[t].map(|v| pos[v]);
            let d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            let l1 = ((b[0] - p[0]) * (c[1] - p[1]) - (b[1] - p[1]) * (c[0] - p[0])) / d;
            let l2 = ((c[0] - p[0]) * (a[1] - p[1]) - (c[1] - p[1]) * (a[0] - p[0])) / d;
            let l = [l1, l2, 1.0 - l1 - l2];
            let worst = l.iter().copied().fold(f64::INFINITY, f64::min);
            if best.is_none_or(|b| worst > b.0) {
                best = Some((worst, t, l));
            }
        }
        let Some((worst, t, l)) = best.filter(|b| b.0 > -1e-9) else {
            return Err(Error::input(format!(
                "shape vertex {i} at ({}, {}) lies outside the cage's triangulation",
                p[0], p[1]
            )));
        };
        let _ = worst;
        let l = l.map(|x| x.max(0.0));
        let s: f64 = l.iter().sum();
        for (f, o) in fields.iter().zip(out.iter_mut()) {
            o[i] = (0..3).map(|k| l[k] * f[tris[t][k]]).sum::<f64>() / s;
        }
    }
    Ok(out)
}

/// Checks a requested largest triangle area of the cage's triangulation (finite, > 0).
///
/// # Errors
/// [`Error::Setting`] naming `cage_max_area`.
pub fn check_max_area(max_area: Option<f64>) -> Result<()> {
    match max_area {
        Some(a) if !(a.is_finite() && a > 0.0) => {
            let shown = if a != 0.0 && a.is_finite() && (a.abs() < 1e-4 || a.abs() > 1e9) {
                format!("{a:e}")
            } else {
                format!("{a}")
            };
            Err(Error::setting("cage_max_area", format!("must be finite and > 0, got {shown}")))
        }
        _ => Ok(()),
    }
}

/// Computes cage weights for the planar `shape`.
///
/// # Errors
/// A shape that is not planar, a cage that is not a simple polygon or does not enclose every
/// shape vertex (input errors naming the first vertex outside), and the errors of
/// [`weights_prescribed`].
pub fn cage_weights(
    shape: &TriMesh,
    cage: &[[f64; 2]],
    max_area: Option<f64>,
    settings: &WeightSettings,
) -> Result<CageWeights> {
    if !shape.is_planar() {
        return Err(Error::input("cages are 2D: the shape must lie in the plane z = 0"));
    }
    let outline = Outline { loops: vec![cage.to_vec()] }.cleaned();
    if outline.loops[0].len() != cage.len() {
        return Err(Error::input("the cage repeats a corner: give each corner once"));
    }
    outline.validate().map_err(|e| Error::input(format!("the cage is not a simple polygon: {e}")))?;
    if let Some(v) = shape.positions().iter().position(|p| !inside([p[0], p[1]], cage)) {
        let p = shape.positions()[v];
        return Err(Error::input(format!(
            "the cage does not enclose the shape: vertex {v} at ({}, {}) lies outside it",
            p[0], p[1]
        )));
    }
    let mean_area = shape
        .faces()
        .iter()
        .map(|t| {
            crate::domain::triangle_area(shape.positions()[t[0]], shape.positions()[t[1]], shape.positions()[t[2]])
        })
        .sum::<f64>()
        / shape.faces().len() as f64;
    check_max_area(max_area)?;
    let area = max_area.unwrap_or(mean_area);
    let estimate = outline.area() / area;
    if estimate > MAX_TRIANGLES {
        return Err(Error::setting(
            "cage_max_area",
            format!(
                "a largest triangle area of {area:e}{} asks for about {estimate:.3e} triangles in the cage (at most {MAX_TRIANGLES:e}): raise it",
                if max_area.is_none() { " (the shape's mean)" } else { "" }
            ),
        ));
    }
    let cage_mesh = triangulate(&outline, Some(area), 25.0)?;
    let params = boundary_parameters(&cage_mesh, cage);
    let m = cage.len();
    let prescribed: Vec<Vec<Option<f64>>> = (0..m)
        .map(|j| {
            params
                .iter()
                .map(|p| {
                    p.map(|(e, t)| {
                        if e == j {
                            1.0 - t
                        } else if (e + 1) % m == j {
                            t
                        } else {
                            0.0
                        }
                    })
                })
                .collect()
        })
        .collect();
    let weights = weights_prescribed(&cage_mesh, &prescribed, settings)?;
    // raw and normalised functions interpolated together: each shape vertex is located once
    let fields: Vec<Vec<f64>> =
        weights.functions.iter().map(|f| f.raw.clone()).chain(weights.normalised.iter().cloned()).collect();
    let mut on_shape = interpolate(&cage_mesh, &fields, shape.positions())?;
    let normalised_on_shape = on_shape.split_off(m);
    let raw_on_shape = on_shape;
    let reproduction_error = shape
        .positions()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (x, y) = (0..m).fold((0.0, 0.0), |(x, y), j| {
                (x + normalised_on_shape[j][i] * cage[j][0], y + normalised_on_shape[j][i] * cage[j][1])
            });
            (x - p[0]).hypot(y - p[1])
        })
        .fold(0.0, f64::max);
    Ok(CageWeights { cage_mesh, weights, raw_on_shape, normalised_on_shape, reproduction_error })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::shapes;

    #[test]
    fn a_square_cage_around_a_disk() {
        let disk = shapes::disk(6, 24, &[]);
        let cage = [[-1.5, -1.5], [1.5, -1.5], [1.5, 1.5], [-1.5, 1.5]];
        let c = cage_weights(&disk, &cage, Some(0.02), &WeightSettings::default()).unwrap();
        assert_eq!(c.weights.functions.len(), 4);
        for f in &c.weights.functions {
            assert!(f.certificate.passed, "{}", f.certificate.summary());
            assert_eq!(f.raw[f.handle], 1.0); // the cage corner is vertex j
            assert_eq!((f.certificate.strict_minima, f.certificate.strict_maxima), (1, 1));
        }
        for i in 0..disk.n_vertices() {
            let s: f64 = c.normalised_on_shape.iter().map(|w| w[i]).sum();
            assert!((s - 1.0).abs() < 1e-9);
            assert!(c.raw_on_shape.iter().all(|w| (0.0..=1.0).contains(&w[i])));
        }
        // by symmetry the centre is weighted nearly equally (the triangulation is not symmetric)
        assert!(
            c.normalised_on_shape.iter().all(|w| (w[0] - 0.25).abs() < 1e-2),
            "{:?}",
            c.normalised_on_shape.iter().map(|w| w[0]).collect::<Vec<_>>()
        );
        // biharmonic functions with hat boundary values do not reproduce linear functions...
        assert!(c.reproduction_error > 0.05, "{}", c.reproduction_error);
        // ...harmonic ones (order 1: DeRose & Meyer's harmonic coordinates) do
        let h = cage_weights(&disk, &cage, Some(0.02), &WeightSettings { order: 1, ..Default::default() }).unwrap();
        assert!(h.weights.functions.iter().all(|f| f.certificate.passed));
        assert!(h.reproduction_error < 1e-3, "{}", h.reproduction_error);
    }

    #[test]
    fn a_cage_that_does_not_enclose_the_shape_is_an_error() {
        let disk = shapes::disk(4, 16, &[]);
        let small = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]];
        let e = cage_weights(&disk, &small, None, &WeightSettings::default()).unwrap_err().to_string();
        assert!(e.contains("does not enclose"), "{e}");
        let bowtie = [[-2.0, -2.0], [2.0, 2.0], [2.0, -2.0], [-2.0, 2.0]];
        assert!(cage_weights(&disk, &bowtie, None, &WeightSettings::default()).is_err());
    }
}
