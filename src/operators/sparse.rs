//! Small helpers on faer's compressed-column matrices.

use faer::sparse::{linalg::matmul::sparse_sparse_matmul, SparseColMat, Triplet};
use faer::Par;

/// Sparse matrix type of the crate: compressed columns, `usize` indices.
pub type Sparse = SparseColMat<usize, f64>;

/// Builds an `n × n` matrix from `(row, col, value)` triplets; duplicates are summed.
pub(crate) fn from_triplets(
    nrows: usize,
    ncols: usize,
    t: &[Triplet<usize, usize, f64>],
) -> Sparse {
    SparseColMat::try_new_from_triplets(nrows, ncols, t)
        .expect("triplets are in range by construction")
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

/// `diag(d) · A`.
pub(crate) fn scale_rows(a: &Sparse, d: &[f64]) -> Sparse {
    let t: Vec<_> = triplets(a)
        .into_iter()
        .map(|t| Triplet::new(t.row, t.col, t.val * d[t.row]))
        .collect();
    from_triplets(a.nrows(), a.ncols(), &t)
}

/// `A · diag(d)`.
pub(crate) fn scale_cols(a: &Sparse, d: &[f64]) -> Sparse {
    let t: Vec<_> = triplets(a)
        .into_iter()
        .map(|t| Triplet::new(t.row, t.col, t.val * d[t.col]))
        .collect();
    from_triplets(a.nrows(), a.ncols(), &t)
}

/// `A · B`.
pub(crate) fn matmul(a: &Sparse, b: &Sparse) -> Sparse {
    sparse_sparse_matmul(a.as_ref(), b.as_ref(), 1.0, Par::Seq)
        .expect("sparse product fits in memory")
}

/// `fᵀ A f`.
pub fn quadratic_form(a: &Sparse, f: &[f64]) -> f64 {
    triplets(a)
        .iter()
        .map(|t| f[t.row] * t.val * f[t.col])
        .sum()
}

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
