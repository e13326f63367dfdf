//! Polyharmonic energies of order 1..4, their blends, and sharp vertices.

use super::sparse::{
    from_triplets, matmul, scale_cols_owned, scale_rows, scale_rows_owned, scaled_plus_diagonal_owned, triplets,
    with_pattern_of, without_zeros, Sparse,
};
use crate::error::{Error, Result};
use faer::sparse::Triplet;
use std::borrow::Cow;

/// A smoothness energy: a weighted sum of polyharmonic orders (Botsch & Kobbelt 2004) and
/// the vertices where orders ≥ 2 are not penalised.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Energy {
    /// `(order k, weight)` pairs, k in 1..=4, weight ≥ 0.
    pub terms: Vec<(u8, f64)>,
    /// Sharp vertices: the Laplacian there is not penalised, so a kink can stay C0.
    pub sharp: Vec<usize>,
}

impl Energy {
    /// A single order with weight 1.
    pub fn order(k: u8) -> Self {
        Energy { terms: vec![(k, 1.0)], sharp: Vec::new() }
    }

    /// Parses `2` or a blend `1:0.2,2:1`.
    ///
    /// # Errors
    /// Usage error for an order outside 1..=4, a negative or non-finite weight, or all
    /// weights zero.
    pub fn parse(spec: &str) -> Result<Self> {
        let mut terms = Vec::new();
        for part in spec.split(',') {
            let (k, w) = match part.split_once(':') {
                Some((k, w)) => (k.trim(), w.trim()),
                None => (part.trim(), "1"),
            };
            let k: u8 =
                k.parse().map_err(|_| Error::Usage(format!("order `{k}` in `{spec}` is not an integer 1..4")))?;
            let w: f64 = w.parse().map_err(|_| Error::Usage(format!("weight `{w}` in `{spec}` is not a number")))?;
            terms.push((k, w));
        }
        let e = Energy { terms, sharp: Vec::new() };
        e.validate()?;
        Ok(e)
    }

    /// Checks orders and weights.
    pub fn validate(&self) -> Result<()> {
        for &(k, w) in &self.terms {
            if !(1..=4).contains(&k) {
                return Err(Error::Usage(format!("energy order {k} is outside 1..4")));
            }
            if !(w.is_finite() && w >= 0.0) {
                return Err(Error::Usage(format!("weight {w} of order {k} must be finite and ≥ 0")));
            }
        }
        if self.terms.iter().all(|&(_, w)| w == 0.0) {
            return Err(Error::Usage("the smoothness energy needs a positive weight".into()));
        }
        Ok(())
    }

    /// The orders as [`Energy::parse`] reads them: `2`, or `1:0.2,2:1` (sharp vertices are a
    /// setting of their own).
    pub fn orders_text(&self) -> String {
        match self.terms.as_slice() {
            [(k, w)] if *w == 1.0 => k.to_string(),
            terms => terms.iter().map(|(k, w)| format!("{k}:{w}")).collect::<Vec<_>>().join(","),
        }
    }

    /// Highest order with a positive weight.
    pub fn max_order(&self) -> u8 {
        self.terms.iter().filter(|t| t.1 > 0.0).map(|t| t.0).max().unwrap_or(1)
    }
}

impl std::str::FromStr for Energy {
    type Err = Error;

    /// [`Energy::parse`].
    fn from_str(spec: &str) -> Result<Self> {
        Energy::parse(spec)
    }
}

/// Assembles `Q = Σ_t w_t · scale_t · Q_{k_t}` (`#V × #V`, symmetric PSD) from the stiffness
/// `K = −L` and the lumped mass `M`; `scale[t]` multiplies term `t` (e.g. `ℓ^{2k}`).
///
/// `Q_1 = K`; for `k ≥ 2`, with `G = S M⁻¹ K` the Laplacian at non-sharp vertices (`S` zeroes
/// the rows of sharp vertices), `Q_k = Gᵀ Q′_{k−2} G`, where `Q′_0 = M`, `Q′_1 = K′`,
/// `Q′_2 = K′ M⁻¹ K′` and `K′` is `K` with every edge at a sharp vertex removed. Without
/// sharp vertices this is `K (M⁻¹ K)^{k−1}` (paper eq. 18).
///
/// The products skip K's entries that are exactly zero (a grid's diagonal edges), so `Q` stores
/// the structural pattern of the products of K's non-zero entries plus K's own pattern: 13
/// entries in an interior column of a grid's bilaplacian instead of the 19 of the
/// triangulation's 2-ring.
///
/// # Panics
/// If `scale.len() != energy.terms.len()`, `m.len() != K.nrows()`, or a sharp index is out of
/// range (callers validate first).
pub fn polyharmonic(k: &Sparse, m: &[f64], energy: &Energy, scale: &[f64]) -> Sparse {
    with_pattern_of(polyharmonic_products(k, m, energy, scale), k)
}

/// [`polyharmonic`] without K's own pattern added: the products' structural pattern alone. On
/// a volume K's exactly zero entries (the cube diagonals of its tetrahedra) lie outside the
/// bilaplacian's 25-point stencil, and adding them copies the whole matrix (two of 0.8 GB at
/// 128³ side by side); a route that needs no constrained pair in P's pattern (the active set)
/// takes this one.
pub(crate) fn polyharmonic_products(k: &Sparse, m: &[f64], energy: &Energy, scale: &[f64]) -> Sparse {
    assert_eq!(scale.len(), energy.terms.len());
    let n = k.nrows();
    assert_eq!(m.len(), n);
    // The products run on K's non-zero entries only; the result keeps K's whole pattern (every
    // edge of the domain), where a monotone QP's constrained pairs lie.
    let k_full = k;
    let mut k_nz = without_zeros(k_full);
    let mut sharp = vec![false; n];
    for &v in &energy.sharp {
        sharp[v] = true;
    }
    let d: Vec<f64> = (0..n).map(|i| if sharp[i] { 0.0 } else { 1.0 / m[i] }).collect();
    let minv: Vec<f64> = m.iter().map(|x| 1.0 / x).collect();
    let mut all = Vec::new();
    let mut single: Option<Sparse> = None;
    let active = energy.terms.iter().zip(scale).filter(|(t, s)| t.1 * **s != 0.0).count();
    let last = energy.terms.iter().zip(scale).rposition(|(t, s)| t.1 * *s != 0.0);
    for (t, (&(order, w), &s)) in energy.terms.iter().zip(scale).enumerate() {
        let c = w * s;
        if c == 0.0 {
            continue;
        }
        let q = match order {
            1 => k_full.clone(),
            // K D M D K in one pass, as the general products below compute it
            2 => bilaplacian(k_nz.as_ref(), &d, m),
            _ => {
                let k = k_nz.as_ref();
                let g = scale_rows(k, &d); // D K
                let k_cut = if energy.sharp.is_empty() { Cow::Borrowed(k) } else { Cow::Owned(cut_edges(k, &sharp)) };
                let inner = match order {
                    3 => matmul(&k_cut, &g),                                           // K′ G
                    _ => matmul(&k_cut, &scale_rows_owned(matmul(&k_cut, &g), &minv)), // K′ M⁻¹ K′ G
                };
                drop(k_cut);
                // K D = Gᵀ (K symmetric); the last term scales K's own copy (a volume's K
                // without its zeros is one: 0.2 GB at 128³ not held twice)
                let k_owned = if Some(t) == last {
                    std::mem::replace(&mut k_nz, Cow::Borrowed(k_full)).into_owned()
                } else {
                    k_nz.as_ref().clone()
                };
                let gt = scale_cols_owned(k_owned, &d);
                matmul(&gt, &inner)
            }
        };
        if active == 1 {
            single = Some(scaled_plus_diagonal_owned(q, c, &vec![0.0; n]));
        } else {
            all.extend(triplets(&q).into_iter().map(|t| Triplet::new(t.row, t.col, c * t.val)));
        }
    }
    single.unwrap_or_else(|| from_triplets(n, n, &all))
}

/// `(K D)(M (D K))` for a symmetric `K` (sharp vertices: `d = 0`), each entry summed as the
/// sparse product of the two scaled copies sums it (`(K_ik d_k) · ((K_kj d_k) m_k)` over `k` in
/// column `j`'s order), so the same bits, without the copies of K and the product's separate
/// symbolic pass (at 10⁷ samples of a series they were 1 GB of fresh pages).
pub(super) fn bilaplacian(k: &Sparse, d: &[f64], m: &[f64]) -> Sparse {
    let n = k.ncols();
    let (cp, ri, v) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let mut work = vec![0.0f64; n];
    let mut mark = vec![usize::MAX; n];
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0);
    let (mut row_idx, mut val) = (Vec::new(), Vec::new());
    let mut rows = Vec::new();
    for j in 0..n {
        rows.clear();
        for p in cp[j]..cp[j + 1] {
            let kk = ri[p];
            let b = (v[p] * d[kk]) * m[kk];
            for q in cp[kk]..cp[kk + 1] {
                let i = ri[q];
                if mark[i] != j {
                    mark[i] = j;
                    rows.push(i);
                }
                work[i] += (v[q] * d[kk]) * b;
            }
        }
        rows.sort_unstable();
        for &i in &rows {
            row_idx.push(i);
            // the product adds its workspace onto a zeroed value
            let mut c = 0.0;
            c += work[i];
            val.push(c);
            work[i] = 0.0;
        }
        col_ptr.push(row_idx.len());
    }
    row_idx.shrink_to_fit();
    val.shrink_to_fit();
    Sparse::new(faer::sparse::SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx), val)
}

/// `K` without the edges at sharp vertices, diagonal recomputed so that rows sum to zero.
pub(super) fn cut_edges(k: &Sparse, sharp: &[bool]) -> Sparse {
    let n = k.nrows();
    let mut diag = vec![0.0; n];
    let mut t = Vec::new();
    for e in triplets(k) {
        if e.row != e.col && !sharp[e.row] && !sharp[e.col] {
            t.push(e);
            diag[e.row] -= e.val;
        }
    }
    t.extend((0..n).map(|i| Triplet::new(i, i, diag[i])));
    from_triplets(n, n, &t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Series;
    use crate::operators::{quadratic_form, series_mass, series_stiffness};

    fn setup(x: Vec<f64>) -> (Sparse, Vec<f64>) {
        let s = Series::with_coordinates(x).unwrap();
        (series_stiffness(&s), series_mass(&s))
    }

    #[test]
    fn the_one_pass_bilaplacian_is_the_scaled_copies_product_bit_for_bit() {
        // a series with uneven spacing, and a mesh's cotangent Laplacian with sharp vertices
        let (ks, ms) = setup((0..40).map(|i| i as f64 + 0.3 * (i as f64 * 1.7).sin()).collect());
        let positions =
            [[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 1.0, 0.3], [1.1, 1.2, 0.1], [2.0, 0.3, 0.2], [2.1, 1.4, 0.0]];
        let faces = [[0, 1, 2], [1, 3, 2], [1, 4, 3], [4, 5, 3]];
        let (km, mm) =
            (crate::operators::cotan_stiffness(&positions, &faces), crate::operators::lumped_mass(&positions, &faces));
        for (k, m, sharp) in [(&ks, &ms, vec![]), (&ks, &ms, vec![3, 17]), (&km, &mm, vec![]), (&km, &mm, vec![2])] {
            let d: Vec<f64> = (0..m.len()).map(|i| if sharp.contains(&i) { 0.0 } else { 1.0 / m[i] }).collect();
            let k_nz = without_zeros(k);
            let inner = scale_rows_owned(scale_rows(k_nz.as_ref(), &d), m);
            let gt = scale_cols_owned(k_nz.as_ref().clone(), &d);
            let expected = matmul(&gt, &inner);
            let got = bilaplacian(k_nz.as_ref(), &d, m);
            assert_eq!(got.symbolic().col_ptr(), expected.symbolic().col_ptr());
            assert_eq!(got.symbolic().row_idx(), expected.symbolic().row_idx());
            assert!(got.val().iter().zip(expected.val()).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }

    #[test]
    fn orders_annihilate_constants_and_are_symmetric() {
        let (k, m) = setup(vec![0.0, 0.3, 1.0, 1.2, 2.0, 3.5, 4.0]);
        for order in 1..=4 {
            let q = polyharmonic(&k, &m, &Energy::order(order), &[1.0]);
            assert!(quadratic_form(&q, &[2.0; 7]).abs() < 1e-10, "order {order}");
            let dense = q.to_dense();
            for i in 0..7 {
                for j in 0..7 {
                    assert!((dense[(i, j)] - dense[(j, i)]).abs() < 1e-9 * (1.0 + dense[(i, j)].abs()));
                }
            }
        }
    }

    #[test]
    fn biharmonic_measures_the_laplacian() {
        // uniform unit spacing: (M⁻¹K f)_i = −(f_{i−1} − 2 f_i + f_{i+1}) inside
        let (k, m) = setup((0..6).map(|i| i as f64).collect());
        let f: Vec<f64> = (0..6).map(|i| ((i * i) as f64) / 2.0).collect(); // f'' = 1
        let q = polyharmonic(&k, &m, &Energy::order(2), &[1.0]);
        // interior: 4 vertices with Laplacian 1 and mass 1; ends: (f0 − f1)/0.5 = 1, (f5−f4)/0.5 = 9
        let ends = 0.5 * 1.0f64.powi(2) + 0.5 * 9.0f64.powi(2);
        assert!((quadratic_form(&q, &f) - (4.0 + ends)).abs() < 1e-9);
    }

    #[test]
    fn sharp_vertices_allow_a_kink() {
        let (k, m) = setup((0..9).map(|i| i as f64).collect());
        // a tent: linear up to vertex 4, linear down after it
        let f: Vec<f64> = (0..9).map(|i| 4.0 - (i as f64 - 4.0).abs()).collect();
        for order in 2..=4u8 {
            let plain = polyharmonic(&k, &m, &Energy::order(order), &[1.0]);
            let mut e = Energy::order(order);
            e.sharp = vec![0, 4, 8];
            let sharp = polyharmonic(&k, &m, &e, &[1.0]);
            assert!(quadratic_form(&plain, &f) > 1.0, "order {order}");
            assert!(quadratic_form(&sharp, &f).abs() < 1e-10, "order {order}: {}", quadratic_form(&sharp, &f));
        }
    }

    #[test]
    fn zero_weights_stay_out_of_the_products_but_every_edge_stays_in_the_pattern() {
        use crate::domain::{Domain, Grid2d};
        use crate::operators::{grid_mass, grid_stiffness};
        let g = Grid2d::with_geometry(9, 7, [0.5, -2.0], [0.0, 0.0]).unwrap();
        let (k, m) = (grid_stiffness(&g), grid_mass(&g));
        let n = g.n_vertices();
        let dk = k.to_dense();
        let mut dminv = faer::Mat::<f64>::zeros(n, n);
        for i in 0..n {
            dminv[(i, i)] = 1.0 / m[i];
        }
        let expected = &dk * &dminv * &dk;
        let q = polyharmonic(&k, &m, &Energy::order(2), &[1.0]);
        let dq = q.to_dense();
        for i in 0..n {
            for j in 0..n {
                assert!((dq[(i, j)] - expected[(i, j)]).abs() <= 1e-12 * expected[(i, j)].abs().max(1.0));
            }
        }
        // an interior column: the 13-point stencil of the squared 5-point Laplacian
        let v = g.index(4, 3);
        let col = q.symbolic().col_ptr()[v + 1] - q.symbolic().col_ptr()[v];
        assert_eq!(col, 13, "entries in column {v}");
        // every edge of the triangulation is stored, the diagonal ones (weight 0) included
        for (i, j) in g.edges() {
            let rows = &q.symbolic().row_idx()[q.symbolic().col_ptr()[j]..q.symbolic().col_ptr()[j + 1]];
            assert!(rows.binary_search(&i).is_ok(), "edge {i}-{j}");
        }
        let diagonal: Vec<(usize, usize)> = g
            .edges()
            .into_iter()
            .filter(|&(i, j)| g.row_col(i).0 != g.row_col(j).0 && g.row_col(i).1 != g.row_col(j).1)
            .collect();
        assert!(!diagonal.is_empty() && diagonal.iter().all(|&(i, j)| dk[(i, j)] == 0.0), "diagonal weights 0");
    }

    /// `‖F x‖²` against `xᵀ Q x` and `Fᵀ(F x)` against `Q x` on a few vectors.
    fn assert_factor_matches(q: &Sparse, f: &Sparse, what: &str) {
        use crate::operators::sparse::mul_vec;
        let n = q.ncols();
        for seed in 0..3usize {
            let x: Vec<f64> = (0..n).map(|i| (((i + 1) * (seed + 3) * 7919) % 1009) as f64 / 1009.0 - 0.4).collect();
            let fx = mul_vec(f, &x);
            let e: f64 = fx.iter().map(|v| v * v).sum();
            let want = quadratic_form(q, &x);
            assert!((e - want).abs() <= 1e-10 * want.abs(), "{what}: ‖Fx‖² = {e}, xᵀQx = {want}");
            let ft = f.as_ref().transpose().to_col_major().unwrap();
            let ftfx = mul_vec(&ft, &fx);
            let qx = mul_vec(q, &x);
            let scale = qx.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (a, b) in ftfx.iter().zip(&qx) {
                assert!((a - b).abs() <= 1e-10 * scale, "{what}: FᵀFx {a} vs Qx {b}");
            }
        }
    }

    #[test]
    fn the_factor_squares_to_the_energy_at_every_order_blend_and_with_sharp_samples() {
        let (k, m) = setup(vec![0.0, 0.3, 1.0, 1.2, 2.0, 3.5, 4.0, 4.1, 5.0, 6.5]);
        let k1 = crate::operators::edge_factor(&k).expect("a series has positive weights");
        assert_factor_matches(&k, &k1.matrix, "K");
        let mut energies: Vec<Energy> = (1..=4).map(Energy::order).collect();
        energies.push(Energy::parse("1:0.2,2:1,4:0.5").unwrap());
        for mut e in energies {
            let scale: Vec<f64> = e.terms.iter().map(|&(k, _)| 0.7f64.powi(2 * k as i32)).collect();
            for sharp in [vec![], vec![0, 4, 9]] {
                e.sharp = sharp;
                let q = polyharmonic(&k, &m, &e, &scale);
                let f = crate::operators::polyharmonic_factor(&k, &k1, &m, &e, &scale).expect("edge rows");
                assert_factor_matches(&q, &f.matrix, &format!("{:?} sharp {:?}", e.terms, e.sharp));
            }
        }
    }

    #[test]
    fn grids_use_edge_rows_and_obtuse_meshes_gradient_rows() {
        use crate::domain::{shapes, Grid2d};
        use crate::operators::{
            cotan_stiffness, edge_factor, gradient_factor, grid_mass, grid_stiffness, lumped_mass, polyharmonic_factor,
        };
        let g = Grid2d::with_geometry(7, 5, [0.5, -2.0], [0.0, 0.0]).unwrap();
        let (k, m) = (grid_stiffness(&g), grid_mass(&g));
        let k1 = edge_factor(&k).expect("a grid's 5-point weights are positive");
        assert_eq!(k1.matrix.nrows(), 6 * 5 + 7 * 4, "one row per axis edge, none for the zero diagonals");
        for order in 1..=4 {
            let e = Energy::order(order);
            let q = polyharmonic(&k, &m, &e, &[1.3]);
            assert_factor_matches(&q, &polyharmonic_factor(&k, &k1, &m, &e, &[1.3]).unwrap().matrix, "grid");
        }
        // a disk triangulated with obtuse triangles: negative cotangent weights
        let disk = shapes::disk(3, 7, &[]);
        let (p, t) = (disk.positions(), disk.faces());
        let (k, m) = (cotan_stiffness(p, t), lumped_mass(p, t));
        let k1 = gradient_factor(p, t);
        assert_factor_matches(&k, &k1.matrix, "mesh K");
        for order in 1..=4 {
            let mut e = Energy::order(order);
            let q = polyharmonic(&k, &m, &e, &[1.0]);
            assert_factor_matches(&q, &polyharmonic_factor(&k, &k1, &m, &e, &[1.0]).unwrap().matrix, "mesh");
            e.sharp = vec![0];
            let cut = polyharmonic_factor(&k, &k1, &m, &e, &[1.0]);
            assert_eq!(cut.is_none(), order == 3, "order {order}: F₁′ needs edge rows");
        }
    }

    #[test]
    fn blends_parse_and_validate() {
        let e = Energy::parse("1:0.2,2:1").unwrap();
        assert_eq!(e.terms, vec![(1, 0.2), (2, 1.0)]);
        assert_eq!(e.max_order(), 2);
        assert!(Energy::parse("5").is_err());
        assert!(Energy::parse("2:-1").is_err());
        assert!(Energy::parse("x").is_err());
    }
}
