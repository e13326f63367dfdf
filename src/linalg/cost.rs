//! What a factorisation costs: its flops, and the pages of its storage mapped in advance.

use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};

/// Flops of the Cholesky factorisation described by `s` (Σ over columns of count²).
pub(crate) fn factor_flops(s: &SymbolicCholesky<usize>) -> f64 {
    match s.raw() {
        SymbolicCholeskyRaw::Simplicial(f) => {
            let cp = f.col_ptr();
            (0..f.ncols()).map(|j| ((cp[j + 1] - cp[j]) as f64).powi(2)).sum()
        }
        SymbolicCholeskyRaw::Supernodal(f) => {
            let (b, e, rp) = (f.supernode_begin(), f.supernode_end(), f.col_ptr_for_row_idx());
            let mut flops = 0.0;
            for s in 0..f.n_supernodes() {
                let below = (rp[s + 1] - rp[s]) as f64;
                for j in b[s]..e[s] {
                    flops += ((e[s] - j) as f64 + below).powi(2);
                }
            }
            flops
        }
    }
}

/// Writes a zero into every 4 KiB page of `v` (through `black_box`, so that it is not
/// optimised away for memory known to be zero).
pub(crate) fn touch_pages(v: &mut [f64]) {
    for i in (0..v.len()).step_by(512) {
        v[i] = std::hint::black_box(0.0);
    }
}
