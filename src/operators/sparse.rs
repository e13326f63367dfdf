//! Small helpers on faer's compressed-column matrices.

use faer::sparse::{linalg::matmul::sparse_sparse_matmul, SparseColMat, SymbolicSparseColMat, Triplet};
use faer::Par;

/// Sparse matrix type of the crate: compressed columns, `usize` indices.
pub type Sparse = SparseColMat<usize, f64>;

/// Builds an `n × n` matrix from `(row, col, value)` triplets; duplicates are summed.
pub(crate) fn from_triplets(nrows: usize, ncols: usize, t: &[Triplet<usize, usize, f64>]) -> Sparse {
    SparseColMat::try_new_from_triplets(nrows, ncols, t).expect("triplets are in range by construction")
}

/// All stored entries as triplets.
pub(crate) fn triplets(a: &Sparse) -> Vec<Triplet<usize, usize, f64>> {
    let mut out = Vec::with_capacity(a.val().len());
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for j in 0..a.ncols() {
        for p in cp[j]..cp[j + 1] {
            out.push(Triplet::new(ri[p], j, v[p]));
        }
    }
    out
}

/// `diag(d) · A` (same pattern).
pub(crate) fn scale_rows(a: &Sparse, d: &[f64]) -> Sparse {
    scale_rows_owned(a.clone(), d)
}

/// `diag(d) · A`, scaling `a`'s values in place.
pub(crate) fn scale_rows_owned(mut a: Sparse, d: &[f64]) -> Sparse {
    let (symbolic, val) = a.parts_mut();
    for (v, &r) in val.iter_mut().zip(symbolic.row_idx()) {
        *v *= d[r];
    }
    a
}

/// `A · diag(d)`, scaling `a`'s values in place.
pub(crate) fn scale_cols_owned(mut a: Sparse, d: &[f64]) -> Sparse {
    let (symbolic, val) = a.parts_mut();
    let cp = symbolic.col_ptr();
    for (j, &dj) in d.iter().enumerate() {
        for v in &mut val[cp[j]..cp[j + 1]] {
            *v *= dj;
        }
    }
    a
}

/// `c · A + diag(d)`; the diagonal is added to the pattern where missing.
pub fn scaled_plus_diagonal(a: &Sparse, c: f64, d: &[f64]) -> Sparse {
    if holds_diagonal(a) {
        let mut out = a.clone();
        scale_and_add_diagonal(&mut out, c, d);
        out
    } else {
        with_diagonal_added(a, c, d)
    }
}

/// [`scaled_plus_diagonal`] in `a`'s own storage where its pattern holds the diagonal.
pub(crate) fn scaled_plus_diagonal_owned(mut a: Sparse, c: f64, d: &[f64]) -> Sparse {
    if holds_diagonal(&a) {
        scale_and_add_diagonal(&mut a, c, d);
        a
    } else {
        with_diagonal_added(&a, c, d)
    }
}

/// Whether every diagonal entry is in `a`'s pattern.
fn holds_diagonal(a: &Sparse) -> bool {
    let (cp, ri) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
    (0..a.nrows()).all(|j| ri[cp[j]..cp[j + 1]].contains(&j))
}

/// `A ← c · A + diag(d)` for a pattern that holds the diagonal.
fn scale_and_add_diagonal(a: &mut Sparse, c: f64, d: &[f64]) {
    let (symbolic, val) = a.parts_mut();
    let (cp, ri) = (symbolic.col_ptr(), symbolic.row_idx());
    for (j, &dj) in d.iter().enumerate() {
        for p in cp[j]..cp[j + 1] {
            val[p] = c * val[p] + if ri[p] == j { dj } else { 0.0 };
        }
    }
}

/// `c · A + diag(d)` through triplets, for a pattern missing diagonal entries.
fn with_diagonal_added(a: &Sparse, c: f64, d: &[f64]) -> Sparse {
    let n = a.nrows();
    let mut t: Vec<_> = triplets(a).into_iter().map(|t| Triplet::new(t.row, t.col, c * t.val)).collect();
    t.extend((0..n).map(|i| Triplet::new(i, i, d[i])));
    from_triplets(n, n, &t)
}

/// `A + diag(d)`, reusing `a`'s storage when its pattern holds every diagonal entry.
pub fn plus_diagonal(mut a: Sparse, d: &[f64]) -> Sparse {
    let n = a.nrows();
    let (cp, ri) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
    let diag: Option<Vec<usize>> =
        (0..n).map(|j| ri[cp[j]..cp[j + 1]].iter().position(|&i| i == j).map(|p| cp[j] + p)).collect();
    match diag {
        Some(diag) => {
            let val = a.val_mut();
            for (j, p) in diag.into_iter().enumerate() {
                val[p] += d[j];
            }
            a
        }
        None => scaled_plus_diagonal(&a, 1.0, d),
    }
}

/// `fᵀ (A − diag(d)) f` for an `A` that holds `diag(d)` in its diagonal entries (from
/// [`plus_diagonal`]): `d` is taken off each diagonal entry before it is used, so a large `d`
/// does not swamp the rest by cancellation.
pub fn quadratic_form_without_diagonal(a: &Sparse, d: &[f64], f: &[f64]) -> f64 {
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut s = 0.0;
    for j in 0..a.ncols() {
        for p in cp[j]..cp[j + 1] {
            let i = ri[p];
            let aij = if i == j { v[p] - d[j] } else { v[p] };
            s += f[i] * aij * f[j];
        }
    }
    s
}

/// `A` (sorted, distinct row indices in every column) without its off-diagonal entries that
/// are exactly zero. A structural zero adds nothing to a product but widens its pattern: on a
/// grid split along one diagonal the cotangent weight of every diagonal edge is exactly 0, and
/// without those entries a bilaplacian has 13 entries a column instead of 19, which halves the
/// flops of its Cholesky factor.
pub(crate) fn without_zeros(a: &Sparse) -> std::borrow::Cow<'_, Sparse> {
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    if !(0..a.ncols()).any(|j| (cp[j]..cp[j + 1]).any(|p| v[p] == 0.0 && ri[p] != j)) {
        return std::borrow::Cow::Borrowed(a);
    }
    let mut col_ptr = Vec::with_capacity(a.ncols() + 1);
    let (mut row_idx, mut val) = (Vec::with_capacity(ri.len()), Vec::with_capacity(ri.len()));
    col_ptr.push(0);
    for j in 0..a.ncols() {
        for p in cp[j]..cp[j + 1] {
            if v[p] != 0.0 || ri[p] == j {
                row_idx.push(ri[p]);
                val.push(v[p]);
            }
        }
        col_ptr.push(row_idx.len());
    }
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(a.nrows(), a.ncols(), col_ptr, None, row_idx);
    std::borrow::Cow::Owned(SparseColMat::new(symbolic, val))
}

/// `A` with every position of `B`'s pattern stored (as an explicit zero where `A` has none).
/// Both must have sorted, distinct row indices in every column.
pub(crate) fn with_pattern_of(a: Sparse, b: &Sparse) -> Sparse {
    let (acp, ari, av) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let (bcp, bri) = (b.symbolic().col_ptr(), b.symbolic().row_idx());
    let covered = (0..a.ncols()).all(|j| {
        let col = &ari[acp[j]..acp[j + 1]];
        bri[bcp[j]..bcp[j + 1]].iter().all(|i| col.binary_search(i).is_ok())
    });
    if covered {
        return a;
    }
    let mut col_ptr = Vec::with_capacity(a.ncols() + 1);
    let (mut row_idx, mut val) = (Vec::with_capacity(ari.len()), Vec::with_capacity(ari.len()));
    col_ptr.push(0);
    for j in 0..a.ncols() {
        let (mut p, mut q, pe, qe) = (acp[j], bcp[j], acp[j + 1], bcp[j + 1]);
        while p < pe || q < qe {
            // the smaller row next; A's entry (with its value) when both hold it
            if q == qe || (p < pe && ari[p] <= bri[q]) {
                if q < qe && ari[p] == bri[q] {
                    q += 1;
                }
                row_idx.push(ari[p]);
                val.push(av[p]);
                p += 1;
            } else {
                row_idx.push(bri[q]);
                val.push(0.0);
                q += 1;
            }
        }
        col_ptr.push(row_idx.len());
    }
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(a.nrows(), a.ncols(), col_ptr, None, row_idx);
    SparseColMat::new(symbolic, val)
}

/// `A · B`, its row indices without the spare capacity the product's pattern grew with (a
/// third of them: 0.27 GB of a series' bilaplacian at 10⁷ samples).
pub(crate) fn matmul(a: &Sparse, b: &Sparse) -> Sparse {
    let c = sparse_sparse_matmul(a.as_ref(), b.as_ref(), 1.0, Par::Seq).expect("sparse product fits in memory");
    let (symbolic, val) = c.into_parts();
    let (nrows, ncols, col_ptr, col_nnz, mut row_idx) = symbolic.into_parts();
    row_idx.shrink_to_fit();
    Sparse::new(SymbolicSparseColMat::new_checked(nrows, ncols, col_ptr, col_nnz, row_idx), val)
}

/// `fᵀ A f`.
pub fn quadratic_form(a: &Sparse, f: &[f64]) -> f64 {
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut s = 0.0;
    for j in 0..a.ncols() {
        for p in cp[j]..cp[j + 1] {
            s += f[ri[p]] * v[p] * f[j];
        }
    }
    s
}

#[cfg(test)]
/// `A · x` for a dense vector.
#[cfg(test)]
pub(crate) fn mul_vec(a: &Sparse, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; a.nrows()];
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for j in 0..a.ncols() {
        for p in cp[j]..cp[j + 1] {
            y[ri[p]] += v[p] * x[j];
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense(a: &Sparse) -> Vec<Vec<f64>> {
        let d = a.to_dense();
        (0..a.nrows()).map(|i| (0..a.ncols()).map(|j| d[(i, j)]).collect()).collect()
    }

    fn pattern(a: &Sparse) -> Vec<Vec<usize>> {
        let (cp, ri) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        (0..a.ncols()).map(|j| ri[cp[j]..cp[j + 1]].to_vec()).collect()
    }

    #[test]
    fn zeros_leave_the_pattern_and_another_pattern_joins_it() {
        // column 0: a row before and after B's; column 1: B's rows interleave A's; column 2 of
        // A is empty; column 3 of B is empty
        let t = |i, j, v| Triplet::new(i, j, v);
        let a = from_triplets(5, 4, &[t(1, 0, 2.0), t(1, 1, 1.0), t(3, 1, 0.0), t(4, 1, 3.0), t(0, 3, 4.0)]);
        let b = from_triplets(5, 4, &[t(0, 0, 9.0), t(4, 0, 9.0), t(0, 1, 9.0), t(3, 1, 9.0), t(2, 2, 9.0)]);
        let u = with_pattern_of(a.clone(), &b);
        assert_eq!(pattern(&u), vec![vec![0, 1, 4], vec![0, 1, 3, 4], vec![2], vec![0]]);
        assert_eq!(dense(&u), dense(&a), "values are A's, the added positions hold zeros");
        // nothing to add: the same matrix back
        assert_eq!(pattern(&with_pattern_of(u.clone(), &a)), pattern(&u));
        // the exact zero at (3, 1) is dropped, the diagonal kept even when zero
        let z = from_triplets(3, 3, &[t(0, 0, 0.0), t(1, 0, 0.0), t(2, 0, 1.0), t(1, 1, 2.0), t(2, 2, 1.0)]);
        let w = without_zeros(&z);
        assert_eq!(pattern(&w), vec![vec![0, 2], vec![1], vec![2]]);
        assert_eq!(dense(&w), dense(&z));
        assert!(matches!(without_zeros(&w), std::borrow::Cow::Borrowed(_)), "nothing to drop: no copy");
        assert_eq!(pattern(&without_zeros(&a)), vec![vec![1], vec![1, 4], vec![], vec![0]]);
    }
}
