//! The per-triangle gradient of piecewise-linear functions and the triangle areas: the
//! paper's appendix writes odd orders through them, `E_1(f) = (G f)ᵀ A (G f)` and
//! `E_3(f) = (G M⁻¹ K f)ᵀ A (G M⁻¹ K f)`. Since `Gᵀ A G = K` exactly (the cotangent formula),
//! these are the matrices [`super::polyharmonic`] assembles; the test below checks it.

use super::sparse::Sparse;
use crate::domain::vec3::{cross, dot, norm, sub};
use faer::sparse::Triplet;

/// `G` (`3·#T × #V`: the x, y, z components of triangle `t`'s gradient in rows `3t..3t+3`)
/// and the area of each triangle (`A` repeats each area three times).
pub fn gradient_operator(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> (Sparse, Vec<f64>) {
    let mut t = Vec::with_capacity(9 * triangles.len());
    let mut areas = Vec::with_capacity(triangles.len());
    for (k, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|v| positions[v]);
        let n = cross(sub(b, a), sub(c, a));
        let twice = norm(n);
        areas.push(0.5 * twice);
        let unit = n.map(|x| x / twice);
        // ∇φ_i = (n̂ × e_i) / (2A), e_i the edge opposite vertex i, counter-clockwise
        for (i, (p, q)) in [(b, c), (c, a), (a, b)].into_iter().enumerate() {
            let g = cross(unit, sub(q, p)).map(|x| x / twice);
            for (d, gd) in g.into_iter().enumerate() {
                t.push(Triplet::new(3 * k + d, tri[i], gd));
            }
        }
        debug_assert!(dot(unit, unit) > 0.0);
    }
    let g = Sparse::try_new_from_triplets(3 * triangles.len(), positions.len(), &t).expect("valid gradient triplets");
    (g, areas)
}

/// `F = A^{½} G` (`3·#T × #V`): `FᵀF = K`, the cotangent stiffness, for any triangles (obtuse
/// ones too, where [`super::edge_factor`] has no real square root). The first-order factor of
/// a mesh's energy in the factored form.
pub fn gradient_factor(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> super::Factor {
    let (g, areas) = gradient_operator(positions, triangles);
    let root: Vec<f64> = (0..g.nrows()).map(|r| areas[r / 3].sqrt()).collect();
    super::Factor::exact(super::sparse::scale_rows(&g, &root))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::shapes;
    use crate::operators::{cotan_stiffness, lumped_mass, polyharmonic, quadratic_form, Energy};

    fn apply(a: &Sparse, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; a.nrows()];
        let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        for j in 0..a.ncols() {
            for p in cp[j]..cp[j + 1] {
                y[ri[p]] += val[p] * x[j];
            }
        }
        y
    }

    #[test]
    fn the_appendix_forms_of_odd_orders_are_the_assembled_energies() {
        let mesh = shapes::torus(1.0, 0.35, 24, 12);
        let (p, t) = (mesh.positions(), mesh.faces());
        let (g, areas) = gradient_operator(p, t);
        let (k, m) = (cotan_stiffness(p, t), lumped_mass(p, t));
        let weighted = |v: &[f64]| -> f64 { v.iter().enumerate().map(|(r, x)| areas[r / 3] * x * x).sum() };
        for seed in 0..3u64 {
            let f: Vec<f64> =
                p.iter().map(|q| (q[0] * (seed + 1) as f64).sin() + q[1] * q[2] + 0.1 * seed as f64).collect();
            let e1 = weighted(&apply(&g, &f));
            assert!((e1 - quadratic_form(&k, &f)).abs() <= 1e-10 * e1.abs(), "{e1}");
            let lap: Vec<f64> = apply(&k, &f).iter().zip(&m).map(|(x, mi)| x / mi).collect();
            let e3 = weighted(&apply(&g, &lap));
            let q3 = polyharmonic(&k, &m, &Energy::order(3), &[1.0]);
            assert!((e3 - quadratic_form(&q3, &f)).abs() <= 1e-9 * e3.abs(), "{e3} vs {}", quadratic_form(&q3, &f));
        }
        // a linear function has the constant gradient on every triangle of a planar mesh
        let disk = shapes::disk(4, 16, &[]);
        let (g, _) = gradient_operator(disk.positions(), disk.faces());
        let f: Vec<f64> = disk.positions().iter().map(|q| 2.0 * q[0] - 3.0 * q[1]).collect();
        for (r, v) in apply(&g, &f).iter().enumerate() {
            assert!((v - [2.0, -3.0, 0.0][r % 3]).abs() < 1e-12);
        }
    }
}
