//! Piecewise-linear (P1) finite elements on tetrahedra: the stiffness, the lumped mass, the
//! positive-weight stiffness for harmonic fills, and the per-tetrahedron gradient.
//!
//! On a tetrahedron with corners `p₀ … p₃` and edge vectors `eₖ = pₖ − p₀`, the gradients of
//! the barycentric coordinates are the rows of `[e₁ e₂ e₃]⁻¹`: `∇φ₁ = (e₂ × e₃) / D`,
//! `∇φ₂ = (e₃ × e₁) / D`, `∇φ₃ = (e₁ × e₂) / D`, `∇φ₀ = −(∇φ₁ + ∇φ₂ + ∇φ₃)`, with
//! `D = e₁ · (e₂ × e₃) = 6 × (signed volume)`. Writing `cᵢ = D ∇φᵢ`, the element stiffness is
//! `vol · ∇φᵢ · ∇φⱼ = cᵢ · cⱼ / (6 |D|)`, whatever the orientation.

use super::cotan::EdgeMatrix;
use super::factor::Factor;
use super::sparse::{scale_rows, Sparse};
use crate::domain::vec3::{cross, dot, sub};
use faer::sparse::Triplet;

/// Corner pairs of a tetrahedron's six edges.
const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// `cᵢ = D ∇φᵢ` for the four corners and `D` (six times the signed volume).
fn scaled_gradients(positions: &[[f64; 3]], tet: &[usize; 4]) -> ([[f64; 3]; 4], f64) {
    let p0 = positions[tet[0]];
    let (e1, e2, e3) = (sub(positions[tet[1]], p0), sub(positions[tet[2]], p0), sub(positions[tet[3]], p0));
    let (c1, c2, c3) = (cross(e2, e3), cross(e3, e1), cross(e1, e2));
    let c0 = [-(c1[0] + c2[0] + c3[0]), -(c1[1] + c2[1] + c3[1]), -(c1[2] + c2[2] + c3[2])];
    ([c0, c1, c2, c3], dot(e1, c1))
}

/// Every tetrahedron's edge `ij` with its weight `w = −vol ∇φᵢ · ∇φⱼ` (the edge's share of
/// `−K_ij`); an edge appears once per tetrahedron on it.
fn edge_weights<'a>(
    positions: &'a [[f64; 3]],
    tets: &'a [[usize; 4]],
) -> impl Iterator<Item = (usize, usize, f64)> + 'a {
    tets.iter().flat_map(move |tet| {
        let (c, d) = scaled_gradients(positions, tet);
        let scale = 1.0 / (6.0 * d.abs());
        PAIRS.into_iter().map(move |(i, j)| (tet[i], tet[j], -dot(c[i], c[j]) * scale))
    })
}

/// Stiffness `K = −L` (`#V × #V`) of piecewise-linear elements on tetrahedra:
/// `K_ij = Σ_T vol(T) ∇φᵢ · ∇φⱼ` over the tetrahedra on edge ij and `K_ii = −Σ_j K_ij`, so
/// `fᵀKf = ∫|∇f|²` for the interpolant, `K` is symmetric positive semi-definite and `K·1 = 0`.
///
/// Equivalently (the dihedral-cotangent form, the 3D analogue of the cotangent formula)
/// `K_ij = −(1/6) Σ_T l_kl cot θ_kl`, with `kl` the edge of `T` opposite `ij`, `l_kl` its
/// length and `θ_kl` the dihedral angle of `T` at it (Alexa, Herholz, Kohlbrenner and
/// Sorkine-Hornung, "Properties of Laplace operators for tetrahedral meshes", SGP 2020, eq. 3;
/// the test below checks the two forms agree). Obtuse dihedral angles give positive
/// off-diagonal entries.
///
/// The pattern is every edge both ways and the diagonal, as [`super::cotan_stiffness`]'s:
/// an edge whose weight sums to zero (the face and body diagonals of
/// [`crate::domain::TetMesh::box_grid`]) keeps an explicit zero entry.
///
/// # Panics
/// If a tetrahedron indexes past `positions` (callers validate meshes first).
pub fn tet_stiffness(positions: &[[f64; 3]], tets: &[[usize; 4]]) -> Sparse {
    let mut k = EdgeMatrix::new(positions.len(), tets);
    for (i, j, w) in edge_weights(positions, tets) {
        k.add_edge(i, j, w);
    }
    k.finish()
}

/// Stiffness with the edge weights `w_ij = −K_ij` of [`tet_stiffness`] clamped from below at
/// `10⁻³ ×` their mean absolute value over the mesh's edges: every weight is strictly
/// positive, so a harmonic function is at each free vertex a strict weighted average of all
/// its neighbours (the discrete maximum principle on the neighbour graph), which obtuse
/// dihedral angles break in the plain stiffness. The tetrahedral counterpart of
/// [`super::positive_cotan_stiffness`], for harmonic fills.
pub fn positive_tet_stiffness(positions: &[[f64; 3]], tets: &[[usize; 4]]) -> Sparse {
    let mut k = EdgeMatrix::new(positions.len(), tets);
    for (i, j, w) in edge_weights(positions, tets) {
        k.add_upper(i, j, w);
    }
    k.finish_clamped()
}

/// Lumped (barycentric) mass: a quarter of the volume of every tetrahedron at each of its
/// corners; sums to the mesh's volume.
pub fn tet_lumped_mass(positions: &[[f64; 3]], tets: &[[usize; 4]]) -> Vec<f64> {
    let mut m = vec![0.0; positions.len()];
    for tet in tets {
        let quarter = scaled_gradients(positions, tet).1.abs() / 24.0;
        for &v in tet {
            m[v] += quarter;
        }
    }
    m
}

/// `G` (`3·#T × #V`: the x, y, z components of tetrahedron `t`'s gradient in rows
/// `3t..3t+3`) and the volume of each tetrahedron: `Gᵀ diag(vol) G = K` ([`tet_stiffness`]).
pub fn tet_gradient_operator(positions: &[[f64; 3]], tets: &[[usize; 4]]) -> (Sparse, Vec<f64>) {
    let mut t = Vec::with_capacity(12 * tets.len());
    let mut volumes = Vec::with_capacity(tets.len());
    for (k, tet) in tets.iter().enumerate() {
        let (c, d) = scaled_gradients(positions, tet);
        volumes.push(d.abs() / 6.0);
        for (i, ci) in c.iter().enumerate() {
            for (axis, x) in ci.iter().enumerate() {
                t.push(Triplet::new(3 * k + axis, tet[i], x / d));
            }
        }
    }
    let g = Sparse::try_new_from_triplets(3 * tets.len(), positions.len(), &t).expect("valid gradient triplets");
    (g, volumes)
}

/// `F = vol^{½} G` (`3·#T × #V`, three rows `√vol ∇φ` per tetrahedron): `FᵀF = K`, the
/// tetrahedral stiffness, for any tetrahedra (obtuse dihedral angles too, where
/// [`super::edge_factor`] has no real square root). The first-order factor of a tetrahedral
/// mesh's energy in the factored form.
pub fn tet_gradient_factor(positions: &[[f64; 3]], tets: &[[usize; 4]]) -> Factor {
    let (g, volumes) = tet_gradient_operator(positions, tets);
    let root: Vec<f64> = (0..g.nrows()).map(|r| volumes[r / 3].sqrt()).collect();
    Factor::exact(scale_rows(&g, &root))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{Domain, TetMesh};
    use crate::operators::quadratic_form;
    use crate::operators::sparse::mul_vec;
    use faer::Mat;

    fn irregular() -> TetMesh {
        TetMesh::jittered_box(5, 4, 6, [0.7, 1.1, 0.4], 0.05, 3)
    }

    fn interior(m: &TetMesh) -> Vec<bool> {
        let mut boundary = vec![false; m.n_vertices()];
        for f in m.boundary_faces() {
            for &v in f {
                boundary[v] = true;
            }
        }
        boundary.into_iter().map(|b| !b).collect()
    }

    fn assert_symmetric(k: &Mat<f64>, tol: f64) {
        for i in 0..k.nrows() {
            for j in 0..i {
                assert!((k[(i, j)] - k[(j, i)]).abs() <= tol, "({i}, {j})");
            }
        }
    }

    /// Off-diagonal pattern of a column: the mesh's neighbours (and the diagonal).
    fn pattern(k: &Sparse, j: usize) -> Vec<usize> {
        let (cp, ri) = (k.symbolic().col_ptr(), k.symbolic().row_idx());
        ri[cp[j]..cp[j + 1]].to_vec()
    }

    #[test]
    fn stiffness_is_symmetric_with_zero_row_sums_on_the_edges() {
        let m = irregular();
        let k = tet_stiffness(m.positions(), m.tets());
        let d = k.to_dense();
        let scale = (0..m.n_vertices()).map(|v| d[(v, v)]).fold(0.0, f64::max);
        assert_symmetric(&d, 1e-14 * scale);
        for s in mul_vec(&k, &vec![1.0; m.n_vertices()]) {
            assert!(s.abs() <= 1e-13 * scale, "{s}");
        }
        for v in 0..m.n_vertices() {
            let mut expected: Vec<usize> = m.neighbors(v).chain([v]).collect();
            expected.sort_unstable();
            assert_eq!(pattern(&k, v), expected, "column {v}");
        }
        // jittered: some dihedral angles are obtuse, giving positive off-diagonal entries
        assert!(m.edges().iter().any(|&(i, j)| d[(i, j)] > 0.0));
        // positive semi-definite: fᵀKf ≥ 0 for a few rough functions
        for seed in 0..4 {
            let f: Vec<f64> = (0..m.n_vertices()).map(|v| ((v * 7919 + seed * 104729) % 101) as f64 - 50.0).collect();
            assert!(quadratic_form(&k, &f) > 0.0);
        }
    }

    #[test]
    fn stiffness_is_exact_for_linear_functions() {
        let m = irregular();
        let k = tet_stiffness(m.positions(), m.tets());
        let inside = interior(&m);
        assert!(inside.iter().filter(|&&b| b).count() >= 20);
        for a in [[1.0, 0.0, 0.0], [0.3, -2.0, 1.5], [0.0, 0.0, -4.0]] {
            let g: Vec<f64> = m.positions().iter().map(|p| dot(a, *p) + 0.25).collect();
            let kg = mul_vec(&k, &g);
            let scale: f64 = kg.iter().fold(0.0, |s, x| s.max(x.abs()));
            assert!(scale > 0.1, "the boundary rows see the gradient");
            for v in 0..m.n_vertices() {
                if inside[v] {
                    assert!(kg[v].abs() <= 1e-12 * scale, "linear precision at {v}: {}", kg[v]);
                }
            }
            // ∫|∇g|² = |a|² · volume, on all vertices
            let e = quadratic_form(&k, &g);
            let exact = dot(a, a) * m.volume();
            assert!((e - exact).abs() <= 1e-12 * exact, "{e} vs {exact}");
        }
    }

    #[test]
    fn stiffness_is_the_dihedral_cotangent_formula() {
        let p = vec![[0.1, 0.2, -0.3], [1.3, 0.1, 0.2], [0.4, 1.7, 0.1], [0.2, 0.5, 0.9]];
        for tet in [[0, 1, 2, 3], [0, 2, 1, 3]] {
            let k = tet_stiffness(&p, &[tet]).to_dense();
            for (i, j) in PAIRS {
                let (k_, l) =
                    ((0..4).find(|&x| x != i && x != j).unwrap(), (0..4).rev().find(|&x| x != i && x != j).unwrap());
                // dihedral angle at edge kl between the faces (k, l, i) and (k, l, j)
                let e = sub(p[l], p[k_]);
                let ee = dot(e, e);
                let perp = |q: [f64; 3]| {
                    let r = sub(q, p[k_]);
                    let s = dot(r, e) / ee;
                    [r[0] - s * e[0], r[1] - s * e[1], r[2] - s * e[2]]
                };
                let (u, w) = (perp(p[i]), perp(p[j]));
                let cot = dot(u, w) / crate::domain::vec3::norm(cross(u, w));
                let expected = -ee.sqrt() * cot / 6.0;
                assert!((k[(i, j)] - expected).abs() < 1e-14, "({i}, {j}): {} vs {expected}", k[(i, j)]);
            }
        }
    }

    #[test]
    fn box_grid_stiffness_is_the_seven_point_stencil() {
        let (dx, dy, dz) = (0.5, 2.0, 3.0);
        let (nx, ny, nz) = (5, 4, 4);
        let m = TetMesh::box_grid(nx, ny, nz, [dx, dy, dz]);
        let k = tet_stiffness(m.positions(), m.tets()).to_dense();
        let index = |i: usize, j: usize, l: usize| i + nx * (j + ny * l);
        let weights = [dy * dz / dx, dx * dz / dy, dx * dy / dz];
        let scale = weights.iter().fold(0.0f64, |s, &w| s.max(w));
        for l in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let v = index(i, j, l);
                    let c = [i, j, l];
                    let on_face =
                        [c[0] == 0 || c[0] == nx - 1, c[1] == 0 || c[1] == ny - 1, c[2] == 0 || c[2] == nz - 1];
                    for u in m.neighbors(v) {
                        let q = m.point(u);
                        let p = m.point(v);
                        let delta = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                        let axes: Vec<usize> = (0..3).filter(|&a| delta[a] != 0.0).collect();
                        if axes.len() > 1 {
                            assert!(k[(v, u)].abs() <= 1e-12 * scale, "diagonal edge {v}–{u}: {}", k[(v, u)]);
                            continue;
                        }
                        // an axis edge: each of its tetrahedra (volume dx·dy·dz/6) adds vol/h²,
                        // so the weight is (dual area)/length = dy·dz/dx (x edges) on the six
                        // tetrahedra of an interior edge, half on the three of an edge in a
                        // face; an edge along the box's rim lies on one or two (the split is
                        // not symmetric there, but every tetrahedron still adds vol/h²)
                        let a = axes[0];
                        let on = m.tets().iter().filter(|t| t.contains(&u) && t.contains(&v)).count();
                        let rim = (0..3).filter(|&b| b != a && on_face[b]).count();
                        match rim {
                            0 => assert_eq!(on, 6, "{v}–{u}"),
                            1 => assert_eq!(on, 3, "{v}–{u}"),
                            _ => assert!(on == 1 || on == 2, "{v}–{u}"),
                        }
                        let expected = -weights[a] * on as f64 / 6.0;
                        assert!((k[(v, u)] - expected).abs() <= 1e-12 * scale, "{v}–{u}: {} vs {expected}", k[(v, u)]);
                    }
                    if !on_face.iter().any(|&b| b) {
                        let diag = 2.0 * (weights[0] + weights[1] + weights[2]);
                        assert!((k[(v, v)] - diag).abs() <= 1e-12 * scale, "{v}: {} vs {diag}", k[(v, v)]);
                    }
                }
            }
        }
    }

    #[test]
    fn positive_stiffness_clamps_the_weights() {
        let m = irregular();
        let (p, t) = (m.positions(), m.tets());
        let (k, kp) = (tet_stiffness(p, t).to_dense(), positive_tet_stiffness(p, t));
        let edges = m.edges();
        let mean = edges.iter().map(|&(i, j)| k[(i, j)].abs()).sum::<f64>() / edges.len() as f64;
        let floor = 1e-3 * mean;
        let d = kp.to_dense();
        let mut clamped = 0;
        for &(i, j) in &edges {
            let w = -k[(i, j)];
            assert!(-d[(i, j)] >= floor * (1.0 - 1e-12), "{i}–{j}");
            assert_eq!(d[(i, j)], d[(j, i)]);
            if w >= floor {
                assert!((d[(i, j)] - k[(i, j)]).abs() <= 1e-15 * mean, "{i}–{j} kept");
            } else {
                assert!((-d[(i, j)] - floor).abs() <= 1e-12 * floor, "{i}–{j} clamped");
                clamped += 1;
            }
        }
        assert!(clamped > 0, "the jitter makes some weights negative");
        for s in mul_vec(&kp, &vec![1.0; m.n_vertices()]) {
            assert!(s.abs() <= 1e-12 * mean);
        }
    }

    #[test]
    fn lumped_mass_is_a_quarter_of_each_volume() {
        let m = irregular();
        let mass = tet_lumped_mass(m.positions(), m.tets());
        assert!((mass.iter().sum::<f64>() - m.volume()).abs() <= 1e-13 * m.volume());
        assert!((m.volume() - 4.0 * 0.7 * 3.0 * 1.1 * 5.0 * 0.4).abs() <= 1e-12);
        let (dx, dy, dz) = (0.5, 2.0, 3.0);
        let b = TetMesh::box_grid(4, 4, 3, [dx, dy, dz]);
        let mass = tet_lumped_mass(b.positions(), b.tets());
        let inside = interior(&b);
        for v in 0..b.n_vertices() {
            if inside[v] {
                assert!((mass[v] - dx * dy * dz).abs() <= 1e-14, "{v}: {}", mass[v]);
            }
        }
        assert_eq!(inside.iter().filter(|&&x| x).count(), 4);
        // a corner of the box on six tetrahedra (the (0,0,0) corner of its cube): a cube's quarter
        assert!((mass[0] - dx * dy * dz / 4.0).abs() <= 1e-14, "{}", mass[0]);
    }

    #[test]
    fn the_gradient_factor_squares_to_the_stiffness() {
        let m = TetMesh::jittered_box(4, 3, 3, [1.0, 0.8, 1.2], 0.05, 11);
        let (p, t) = (m.positions(), m.tets());
        let f = tet_gradient_factor(p, t);
        assert_eq!((f.matrix.nrows(), f.matrix.ncols()), (3 * t.len(), m.n_vertices()));
        let fd = f.matrix.to_dense();
        let ftf = fd.transpose() * &fd;
        let k = tet_stiffness(p, t).to_dense();
        for i in 0..k.nrows() {
            for j in 0..k.ncols() {
                assert!((ftf[(i, j)] - k[(i, j)]).abs() <= 1e-13, "({i}, {j})");
            }
        }
        // a linear function has the same gradient on every tetrahedron
        let (g, vol) = tet_gradient_operator(p, t);
        let a = [2.0, -3.0, 0.5];
        let lin: Vec<f64> = p.iter().map(|q| dot(a, *q) - 1.0).collect();
        for (r, x) in mul_vec(&g, &lin).iter().enumerate() {
            assert!((x - a[r % 3]).abs() < 1e-12, "row {r}: {x}");
        }
        assert!((vol.iter().sum::<f64>() - m.volume()).abs() < 1e-12);
    }
}
