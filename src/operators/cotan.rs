//! Cotangent stiffness and lumped mass on triangles (grids and meshes), and the
//! positive-weight variant for harmonic fills.

use super::sparse::Sparse;
use crate::domain::vec3::{cross, dot, norm, sub};
use crate::domain::Grid2d;

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
    let mut k = EdgeMatrix::new(positions.len(), triangles);
    for (i, j, w) in corner_weights(positions, triangles) {
        k.add_edge(i, j, w);
    }
    k.finish()
}

/// Stiffness with the cotangent edge weights `w_ij = ½ (cot α_ij + cot β_ij)` clamped from
/// below at `10⁻³ ×` their mean over the mesh's edges: every weight is strictly positive, so
/// a harmonic function is at each free vertex a strict weighted average of *all* its
/// neighbours (the discrete maximum principle on SPEC's neighbour graph: a free vertex is
/// regular unless all its neighbours are equal). The plain cotangent weights of obtuse
/// triangles can be negative and break that principle (paper section 5); this is the
/// Laplacian of the representative's fills, the energy keeps [`cotan_stiffness`].
pub fn positive_cotan_stiffness(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Sparse {
    let mut k = EdgeMatrix::new(positions.len(), triangles);
    for (i, j, w) in corner_weights(positions, triangles) {
        k.add_upper(i, j, w);
    }
    k.finish_clamped()
}

/// Every triangle's side `ij` with half the cotangent of the angle opposite it: `(i, j, ½ cot)`;
/// an interior edge appears twice, once from each triangle.
fn corner_weights<'a>(
    positions: &'a [[f64; 3]],
    triangles: &'a [[usize; 3]],
) -> impl Iterator<Item = (usize, usize, f64)> + 'a {
    triangles.iter().flat_map(move |tri| {
        (0..3).map(move |c| {
            let (i, j, o) = (tri[c], tri[(c + 1) % 3], tri[(c + 2) % 3]);
            let (a, b) = (sub(positions[i], positions[o]), sub(positions[j], positions[o]));
            (i, j, 0.5 * dot(a, b) / cross_norm(a, b))
        })
    })
}

/// A symmetric matrix on the vertex adjacency of a list of triangles (or tetrahedra: any
/// cells whose corners are pairwise joined by edges; every edge both ways, every diagonal
/// entry), assembled in place: the pattern is built once by counting and each
/// weight lands at its entry by a binary search in a column of a few entries (no triplet
/// list to sort: a tenth of the memory traffic).
pub(super) struct EdgeMatrix {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    diag: Vec<usize>,
    val: Vec<f64>,
}

impl EdgeMatrix {
    pub(super) fn new<const N: usize>(n: usize, cells: &[[usize; N]]) -> EdgeMatrix {
        // each corner lists the other corners of its cell, plus every diagonal entry
        let mut count = vec![1usize; n + 1];
        count[0] = 0;
        for cell in cells {
            for &v in cell {
                count[v + 1] += N - 1;
            }
        }
        for j in 0..n {
            count[j + 1] += count[j];
        }
        let mut fill = count.clone();
        let mut rows = vec![0usize; count[n]];
        for j in 0..n {
            rows[fill[j]] = j;
            fill[j] += 1;
        }
        for cell in cells {
            for c in 0..N {
                let v = cell[c];
                for d in 1..N {
                    rows[fill[v] + d - 1] = cell[(c + d) % N];
                }
                fill[v] += N - 1;
            }
        }
        let (col_ptr, row_idx) = crate::linalg::compress_columns(&count, &mut rows);
        let diag =
            (0..n).map(|j| col_ptr[j] + row_idx[col_ptr[j]..col_ptr[j + 1]].partition_point(|&i| i < j)).collect();
        let val = vec![0.0; row_idx.len()];
        EdgeMatrix { col_ptr, row_idx, diag, val }
    }

    /// Position of entry `(i, j)` (in the pattern by construction).
    fn position(&self, i: usize, j: usize) -> usize {
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        a + self.row_idx[a..b].binary_search(&i).expect("an edge of the cells")
    }

    /// `−w` at `(i, j)` and `(j, i)`, `+w` at both diagonal entries.
    pub(super) fn add_edge(&mut self, i: usize, j: usize, w: f64) {
        let (p, q) = (self.position(i, j), self.position(j, i));
        self.val[p] -= w;
        self.val[q] -= w;
        self.val[self.diag[i]] += w;
        self.val[self.diag[j]] += w;
    }

    /// `+w` at the upper entry of edge `ij` only (summing an edge's weight over its cells).
    pub(super) fn add_upper(&mut self, i: usize, j: usize, w: f64) {
        let p = self.position(i.min(j), i.max(j));
        self.val[p] += w;
    }

    /// `(i, j, position)` of every off-diagonal entry with `i < j`.
    fn upper_off_diagonal(&self) -> Vec<(usize, usize, usize)> {
        let mut out = Vec::with_capacity(self.row_idx.len() / 2);
        for j in 0..self.col_ptr.len() - 1 {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[p];
                if i < j {
                    out.push((i, j, p));
                }
            }
        }
        out
    }

    /// Off-diagonal entries holding weights `w` become `−w`, the diagonal `Σ w`.
    fn diagonal_from_off_diagonal(&mut self) {
        let n = self.diag.len();
        for j in 0..n {
            let mut sum = 0.0;
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                if p != self.diag[j] {
                    sum += self.val[p];
                    self.val[p] = -self.val[p];
                }
            }
            self.val[self.diag[j]] = sum;
        }
    }

    /// The stiffness of the summed edge weights (from [`EdgeMatrix::add_upper`]) clamped from
    /// below at `10⁻³ ×` their mean absolute value over the edges: off-diagonal entries `−w`,
    /// the diagonal `Σ w` (see [`positive_cotan_stiffness`]).
    pub(super) fn finish_clamped(mut self) -> Sparse {
        // every edge's summed weight, clamped, then the diagonal from the clamped weights
        let edges = self.upper_off_diagonal();
        let mean = edges.iter().map(|&(_, _, p)| self.val[p].abs()).sum::<f64>() / edges.len().max(1) as f64;
        let floor = 1e-3 * mean;
        for (i, j, p) in edges {
            let w = self.val[p].max(floor);
            self.val[p] = w;
            let q = self.position(j, i);
            self.val[q] = w;
        }
        self.diagonal_from_off_diagonal();
        self.finish()
    }

    pub(super) fn finish(self) -> Sparse {
        let n = self.diag.len();
        let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(n, n, self.col_ptr, None, self.row_idx);
        Sparse::new(symbolic, self.val)
    }
}

/// Cotangent weight of every edge `(i, j, w_ij, triangles on it)`, `i < j`, sorted (a
/// deterministic order, so that sums do not depend on hashing).
fn edge_weights(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Vec<(usize, usize, f64, u8)> {
    let mut half: Vec<(usize, usize, f64)> =
        corner_weights(positions, triangles).map(|(i, j, w)| (i.min(j), i.max(j), w)).collect();
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
