//! Cotangent stiffness and lumped mass on triangles (grids and meshes), and the
//! positive-weight variant for harmonic fills.

use super::sparse::{from_triplets, Sparse};
use crate::domain::vec3::{cross, dot, norm, sub};
use crate::domain::Grid2d;
use faer::sparse::Triplet;

fn cross_norm(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm(cross(a, b))
}

/// Stiffness `K = −L` (`#V × #V`) of piecewise-linear elements on triangles:
/// `K[i][j] = −½ (cot α_ij + cot β_ij)` over the (one or two) angles opposite edge ij and
/// `K[i][i] = −Σ_j K[i][j]`, so `fᵀKf = ∫|∇f|²` for the interpolant and `K·1 = 0`.
/// Obtuse angles give positive off-diagonal entries (negative cotangent weights).
///
/// # Panics
/// If a triangle indexes past `positions` (callers validate meshes first).
/// Ref: Pinkall & Polthier 1993.
pub fn cotan_stiffness(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Sparse {
    let n = positions.len();
    let mut t = Vec::with_capacity(12 * triangles.len());
    for tri in triangles {
        for k in 0..3 {
            let (i, j, o) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let (a, b) = (sub(positions[i], positions[o]), sub(positions[j], positions[o]));
            let w = 0.5 * dot(a, b) / cross_norm(a, b);
            t.push(Triplet::new(i, j, -w));
            t.push(Triplet::new(j, i, -w));
            t.push(Triplet::new(i, i, w));
            t.push(Triplet::new(j, j, w));
        }
    }
    from_triplets(n, n, &t)
}

/// Stiffness with the cotangent edge weights `w_ij = ½ (cot α_ij + cot β_ij)` clamped from
/// below at `10⁻³ ×` their mean over the mesh's edges: every weight is strictly positive, so
/// a harmonic function is at each free vertex a strict weighted average of *all* its
/// neighbours (the discrete maximum principle on SPEC's neighbour graph: a free vertex is
/// regular unless all its neighbours are equal). The plain cotangent weights of obtuse
/// triangles can be negative and break that principle (paper section 5); this is the
/// Laplacian of the representative's fills, the energy keeps [`cotan_stiffness`].
pub fn positive_cotan_stiffness(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Sparse {
    let n = positions.len();
    let weights = edge_weights(positions, triangles);
    let mean = weights.iter().map(|e| e.2.abs()).sum::<f64>() / weights.len().max(1) as f64;
    let floor = 1e-3 * mean;
    let mut t = Vec::with_capacity(4 * weights.len());
    for &(i, j, w, _) in &weights {
        let w = w.max(floor);
        t.push(Triplet::new(i, j, -w));
        t.push(Triplet::new(j, i, -w));
        t.push(Triplet::new(i, i, w));
        t.push(Triplet::new(j, j, w));
    }
    from_triplets(n, n, &t)
}

/// Cotangent weight of every edge `(i, j, w_ij, triangles on it)`, `i < j`, sorted (a
/// deterministic order, so that sums do not depend on hashing).
fn edge_weights(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Vec<(usize, usize, f64, u8)> {
    let mut half: Vec<(usize, usize, f64)> = Vec::with_capacity(3 * triangles.len());
    for tri in triangles {
        for k in 0..3 {
            let (i, j, o) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let (a, b) = (sub(positions[i], positions[o]), sub(positions[j], positions[o]));
            half.push((i.min(j), i.max(j), 0.5 * dot(a, b) / cross_norm(a, b)));
        }
    }
    half.sort_by_key(|e| (e.0, e.1));
    let mut out: Vec<(usize, usize, f64, u8)> = Vec::with_capacity(half.len() / 2 + 1);
    for (i, j, w) in half {
        match out.last_mut() {
            Some(e) if e.0 == i && e.1 == j => {
                e.2 += w;
                e.3 += 1;
            }
            _ => out.push((i, j, w, 1)),
        }
    }
    out
}

/// Number of interior edges whose cotangent weight is negative (obtuse opposite angles).
pub fn negative_cotan_edges(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> usize {
    edge_weights(positions, triangles).iter().filter(|e| e.3 == 2 && e.2 < 0.0).count()
}

/// Lumped (barycentric) mass: a third of the area of every triangle at each of its vertices.
pub fn lumped_mass(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Vec<f64> {
    let mut m = vec![0.0; positions.len()];
    for tri in triangles {
        let area =
            0.5 * cross_norm(sub(positions[tri[1]], positions[tri[0]]), sub(positions[tri[2]], positions[tri[0]]));
        for &v in tri {
            m[v] += area / 3.0;
        }
    }
    m
}

fn grid_geometry(grid: &Grid2d) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let positions = (0..crate::domain::Domain::n_vertices(grid))
        .map(|v| {
            let p = grid.position(v);
            [p[0], p[1], 0.0]
        })
        .collect();
    (positions, grid.triangles().collect())
}

/// Cotangent stiffness of the triangulated grid with spacing |dx|, |dy|: every diagonal
/// weight is exactly 0 (both opposite angles are right angles), so this is the 5-point
/// stencil with weights `|dy|/|dx|` (horizontal) and `|dx|/|dy|` (vertical) (NOTES.md 4).
pub fn grid_stiffness(grid: &Grid2d) -> Sparse {
    let (p, t) = grid_geometry(grid);
    cotan_stiffness(&p, &t)
}

/// Lumped mass of the triangulated grid; sums to the grid's area `(nx−1)|dx| · (ny−1)|dy|`.
pub fn grid_mass(grid: &Grid2d) -> Vec<f64> {
    let (p, t) = grid_geometry(grid);
    lumped_mass(&p, &t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Domain;
    use crate::operators::quadratic_form;
    use crate::operators::sparse::mul_vec;

    #[test]
    fn grid_stiffness_is_the_five_point_stencil() {
        let g = Grid2d::with_geometry(5, 4, [0.5, -2.0], [0.0, 0.0]).unwrap();
        let k = grid_stiffness(&g).to_dense();
        let v = g.index(1, 2);
        assert!((k[(v, g.index(1, 1))] + 2.0 / 0.5).abs() < 1e-12, "horizontal |dy|/|dx|");
        assert!((k[(v, g.index(0, 2))] + 0.5 / 2.0).abs() < 1e-12, "vertical |dx|/|dy|");
        assert!(k[(v, g.index(0, 1))].abs() < 1e-12, "diagonal weight 0");
        assert!((k[(v, v)] - 2.0 * (4.0 + 0.25)).abs() < 1e-12);
        for s in mul_vec(&grid_stiffness(&g), &vec![1.0; g.n_vertices()]) {
            assert!(s.abs() < 1e-12);
        }
        let m = grid_mass(&g);
        assert!((m.iter().sum::<f64>() - 4.0 * 0.5 * 3.0 * 2.0).abs() < 1e-12);
    }

    #[test]
    fn dirichlet_energy_of_a_linear_function_is_exact() {
        // f = 3x − y on a scaled grid: ∫|∇f|² = 10 · area
        let g = Grid2d::with_geometry(6, 5, [0.2, 0.3], [0.0, 0.0]).unwrap();
        let f: Vec<f64> = (0..g.n_vertices()).map(|v| 3.0 * g.position(v)[0] - g.position(v)[1]).collect();
        let area = 5.0 * 0.2 * 4.0 * 0.3;
        assert!((quadratic_form(&grid_stiffness(&g), &f) - 10.0 * area).abs() < 1e-10);
    }

    #[test]
    fn obtuse_triangles_give_negative_weights() {
        // an obtuse triangle: the edge opposite the obtuse angle gets a positive K entry
        let p = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.2, 0.0]];
        let k = cotan_stiffness(&p, &[[0, 1, 2]]).to_dense();
        assert!(k[(0, 1)] > 0.0);
        assert!(k[(0, 2)] < 0.0);
    }
}
