//! Stiffness and lumped mass of piecewise-linear elements on the volume grid's Freudenthal
//! tetrahedra, in closed form.
//!
//! In the tetrahedron that walks from a cube's first corner along axes a, b, c (lengths
//! h_a, h_b, h_c), the barycentric gradients are −e_a/h_a, e_a/h_a − e_b/h_b,
//! e_b/h_b − e_c/h_c and e_c/h_c: only the three axis-aligned edges of the walk have a
//! non-zero product, `vol·∇φ_i·∇φ_j = −V/(6 h²)` (V = h_a h_b h_c). Summed over the six
//! tetrahedra, the cube's four a-edges get `V/(3 h_a²)` at the two offsets on the cube's
//! diagonal plane ((0,0) and (1,1) in the other two axes) and `V/(6 h_a²)` at the other two;
//! the diagonal edges get exactly 0. Inside, an a-edge lies in four cubes and weighs
//! `V/h_a²` (`dy·dz/dx` for x): the finite-element stiffness is exactly the 7-point stencil at
//! any spacing, and it is assembled here without one floating-point operation per tetrahedron.

use super::sparse::Sparse;
use crate::domain::{Domain, Grid3d};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// The weight `V / h_a²` of a full interior a-edge, with spacing magnitudes.
fn axis_weights(g: &Grid3d) -> [f64; 3] {
    let h = g.spacing().map(f64::abs);
    let v = h[0] * h[1] * h[2];
    [0, 1, 2].map(|a| v / (h[a] * h[a]))
}

/// Sum of the cubes' contributions to the a-edge from `p` to `p + e_a`.
fn axis_edge_weight(g: &Grid3d, p: [usize; 3], a: usize, w: f64) -> f64 {
    let n = g.dims();
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let mut sum = 0.0;
    for ob in 0..2 {
        for oc in 0..2 {
            // the cube whose first corner is p − o_b e_b − o_c e_c
            let inside = |axis: usize, o: usize| p[axis] >= o && p[axis] - o + 1 < n[axis];
            if inside(b, ob) && inside(c, oc) {
                sum += if ob == oc { w / 3.0 } else { w / 6.0 };
            }
        }
    }
    sum
}

/// Stiffness `K = −L` of the volume grid (`#V × #V`): the 7-point stencil with boundary
/// weights from the cubes present. SPEC's diagonal neighbours, whose weights are exactly
/// zero, are not stored (15 entries a column would be twice the 7 used: 0.27 GB at 128³);
/// the routes that need every constraint pair in the energy's pattern take
/// [`volume_edge_pattern`].
pub fn volume_stiffness(g: &Grid3d) -> Sparse {
    let n = g.n_vertices();
    let w = axis_weights(g);
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut row_idx = Vec::with_capacity(7 * n);
    let mut val = Vec::with_capacity(7 * n);
    col_ptr.push(0);
    let mut entries: Vec<(usize, f64)> = Vec::with_capacity(15);
    for v in 0..n {
        entries.clear();
        let p = g.ijk(v);
        let mut diagonal = 0.0;
        for (d, u) in g.offset_neighbours(v) {
            let axis = (0..3).find(|&a| d[a] != 0 && d.iter().filter(|&&x| x != 0).count() == 1);
            // a diagonal neighbour's weight is exactly zero
            let Some(a) = axis else { continue };
            // the edge's first corner: the one with the smaller coordinate
            let start = if d[a] > 0 { p } else { g.ijk(u) };
            let value = -axis_edge_weight(g, start, a, w[a]);
            diagonal -= value;
            entries.push((u, value));
        }
        entries.push((v, diagonal));
        entries.sort_unstable_by_key(|e| e.0);
        for &(r, x) in &entries {
            row_idx.push(r);
            val.push(x);
        }
        col_ptr.push(row_idx.len());
    }
    // SAFETY-free: the pattern is sorted and in range by construction
    let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    SparseColMat::new(symbolic, val)
}

/// SPEC's 14 neighbours of each voxel and the voxel itself as a pattern of zeros: where every
/// constraint pair of the grid lies.
pub(crate) fn volume_edge_pattern(g: &Grid3d) -> Sparse {
    let n = g.n_vertices();
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut row_idx = Vec::with_capacity(15 * n);
    col_ptr.push(0);
    let mut rows: Vec<usize> = Vec::with_capacity(15);
    for v in 0..n {
        rows.clear();
        rows.extend(g.offset_neighbours(v).into_iter().map(|(_, u)| u));
        rows.push(v);
        rows.sort_unstable();
        row_idx.extend_from_slice(&rows);
        col_ptr.push(row_idx.len());
    }
    let val = vec![0.0; row_idx.len()];
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx), val)
}

/// Lumped mass of the volume grid: a quarter of each tetrahedron's volume to each corner. A
/// cube's first and last corners lie on all six of its tetrahedra (V/4 each), the other six
/// corners on two (V/12); an interior vertex gets V. Sums to the grid's volume.
pub fn volume_mass(g: &Grid3d) -> Vec<f64> {
    let h = g.spacing().map(f64::abs);
    let v = h[0] * h[1] * h[2];
    let n = g.dims();
    (0..g.n_vertices())
        .map(|x| {
            let p = g.ijk(x);
            let mut m = 0.0;
            for o in 0..8usize {
                let o = [o & 1, (o >> 1) & 1, (o >> 2) & 1];
                let inside = (0..3).all(|a| p[a] >= o[a] && p[a] - o[a] + 1 < n[a]);
                if inside {
                    m += if o == [0, 0, 0] || o == [1, 1, 1] { v / 4.0 } else { v / 12.0 };
                }
            }
            m
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::operators::quadratic_form;
    use crate::operators::sparse::mul_vec;

    /// The stiffness summed tetrahedron by tetrahedron from the barycentric gradients.
    fn from_tetrahedra(g: &Grid3d) -> Vec<std::collections::HashMap<usize, f64>> {
        let mut k = vec![std::collections::HashMap::new(); g.n_vertices()];
        for t in g.tetrahedra() {
            let p = t.map(|v| g.position(v));
            let e = [1, 2, 3].map(|c| [0, 1, 2].map(|a| p[c][a] - p[0][a]));
            let cross = |a: [f64; 3], b: [f64; 3]| {
                [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
            };
            let det = e[0][0] * cross(e[1], e[2])[0] + e[0][1] * cross(e[1], e[2])[1] + e[0][2] * cross(e[1], e[2])[2];
            // gradients of φ1..φ3 are the rows of the inverse of [e1 e2 e3]ᵀ
            let grads123 = [cross(e[1], e[2]), cross(e[2], e[0]), cross(e[0], e[1])].map(|c| c.map(|x| x / det));
            let g0 = [0, 1, 2].map(|a| -(grads123[0][a] + grads123[1][a] + grads123[2][a]));
            let grads = [g0, grads123[0], grads123[1], grads123[2]];
            let vol = det / 6.0;
            for a in 0..4 {
                for b in 0..4 {
                    let d: f64 = (0..3).map(|x| grads[a][x] * grads[b][x]).sum();
                    *k[t[a]].entry(t[b]).or_insert(0.0) += vol * d;
                }
            }
        }
        k
    }

    #[test]
    fn the_closed_form_is_the_tetrahedra_s_stiffness_and_the_7_point_stencil() {
        let g = Grid3d::with_geometry([4, 3, 5], [0.5, -2.0, 3.0], [0.0; 3]).unwrap();
        let k = volume_stiffness(&g);
        let dense = k.to_dense();
        let reference = from_tetrahedra(&g);
        for v in 0..g.n_vertices() {
            for w in 0..g.n_vertices() {
                let r = reference[v].get(&w).copied().unwrap_or(0.0);
                assert!((dense[(v, w)] - r).abs() < 1e-12 * 20.0, "({v}, {w}): {} vs {r}", dense[(v, w)]);
            }
        }
        let c = g.index(1, 1, 2);
        let (dx, dy, dz) = (0.5, 2.0, 3.0);
        assert!((dense[(c, g.index(2, 1, 2))] + dy * dz / dx).abs() < 1e-12);
        assert!((dense[(c, g.index(1, 0, 2))] + dx * dz / dy).abs() < 1e-12);
        assert!((dense[(c, g.index(1, 1, 3))] + dx * dy / dz).abs() < 1e-12);
        // diagonal neighbours: exactly zero, and not stored; the edge pattern holds them
        assert_eq!(dense[(c, g.index(2, 2, 3))], 0.0);
        assert_eq!(dense[(c, g.index(2, 2, 2))], 0.0);
        let column =
            |a: &Sparse| a.symbolic().row_idx()[a.symbolic().col_ptr()[c]..a.symbolic().col_ptr()[c + 1]].to_vec();
        assert_eq!(column(&k).len(), 7);
        let edges = volume_edge_pattern(&g);
        let mut expected: Vec<usize> = g.neighbors(c).chain([c]).collect();
        expected.sort_unstable();
        assert_eq!(column(&edges), expected);
        assert_eq!(expected.len(), 15);
        for s in mul_vec(&k, &vec![1.0; g.n_vertices()]) {
            assert!(s.abs() < 1e-12);
        }
        // ∫|∇f|² of a linear function: |a|² × volume
        let f: Vec<f64> =
            (0..g.n_vertices()).map(|v| 3.0 * g.position(v)[0] - g.position(v)[1] + 0.5 * g.position(v)[2]).collect();
        let volume = 1.5 * 4.0 * 12.0;
        assert!((quadratic_form(&k, &f) - (9.0 + 1.0 + 0.25) * volume).abs() < 1e-9);
    }

    #[test]
    fn mass_is_the_tetrahedra_s_quarter_volumes() {
        let g = Grid3d::with_geometry([4, 3, 5], [0.5, -2.0, 3.0], [0.0; 3]).unwrap();
        let m = volume_mass(&g);
        let mut reference = vec![0.0; g.n_vertices()];
        for t in g.tetrahedra() {
            for v in t {
                reference[v] += 3.0 / 24.0;
            }
        }
        for (a, b) in m.iter().zip(&reference) {
            assert!((a - b).abs() < 1e-12);
        }
        assert!((m.iter().sum::<f64>() - 1.5 * 4.0 * 12.0).abs() < 1e-9);
        assert_eq!(m[g.index(1, 1, 1)], 3.0);
    }
}
