//! The energy as `FᵀF` (the paper's appendix form, auxiliary variables `t = F f`), with `F`'s
//! entries in double-double.
//!
//! The factored form is for the QPs whose assembled matrix is too ill-conditioned for double
//! precision (κ beyond 10⁹). There the rounding of `F`'s own entries matters too: `F = M^{-½} K
//! M⁻¹ K` computed in double carries relative errors of 10⁻¹⁶ per entry, which perturb the
//! energy of a smooth function by about `10⁻¹⁶ ‖F‖ ‖F f‖ ‖f‖` — at κ = 10¹² already a millionth
//! of the data term. So `F` is formed from the stiffness and the mass in double-double: the
//! QP it defines is the one `K` and `M` (as computed from the geometry) define, to 32 digits.

use super::polyharmonic::{cut_edges, Energy};
use super::sparse::{without_zeros, Sparse};
use crate::linalg::double_double::Dd;

/// A sparse matrix with double-double entries: `matrix` holds them rounded to double, `lo` the
/// remainder of each stored entry.
#[derive(Clone, Debug)]
pub struct Factor {
    /// The entries rounded to double (the pattern is this matrix's).
    pub matrix: Sparse,
    /// `entry − rounded`, one per stored entry of `matrix`.
    pub lo: Vec<f64>,
}

impl Factor {
    /// Stored entry `p` (an index into `matrix`'s values) in double-double.
    #[inline]
    pub fn entry(&self, p: usize) -> Dd {
        Dd { hi: self.matrix.val()[p], lo: self.lo[p] }
    }

    /// A factor whose entries are doubles.
    pub fn exact(matrix: Sparse) -> Factor {
        let lo = vec![0.0; matrix.val().len()];
        Factor { matrix, lo }
    }

    fn from_dd(m: &DdColumns) -> Factor {
        let mut row_idx = Vec::with_capacity(m.entries.len());
        let (mut val, mut lo) = (Vec::with_capacity(m.entries.len()), Vec::with_capacity(m.entries.len()));
        for &(i, v) in &m.entries {
            row_idx.push(i);
            let hi = v.to_f64();
            val.push(hi);
            lo.push((v - Dd::from(hi)).hi);
        }
        let symbolic =
            faer::sparse::SymbolicSparseColMat::new_checked(m.nrows, m.ncols(), m.col_ptr.clone(), None, row_idx);
        Factor { matrix: Sparse::new(symbolic, val), lo }
    }
}

/// Compressed columns with double-double values, rows sorted: the entries of column `j` are
/// `entries[col_ptr[j]..col_ptr[j + 1]]` (one array, not a vector per column: at 3·10⁶
/// samples those were millions of allocations).
struct DdColumns {
    nrows: usize,
    col_ptr: Vec<usize>,
    entries: Vec<(usize, Dd)>,
}

impl DdColumns {
    fn ncols(&self) -> usize {
        self.col_ptr.len() - 1
    }

    fn col(&self, j: usize) -> &[(usize, Dd)] {
        &self.entries[self.col_ptr[j]..self.col_ptr[j + 1]]
    }

    /// The matrix of `ncols` columns whose column `j` is `column(j)`.
    fn from_columns<I: Iterator<Item = (usize, Dd)>>(
        nrows: usize,
        ncols: usize,
        mut column: impl FnMut(usize) -> I,
    ) -> DdColumns {
        let mut col_ptr = Vec::with_capacity(ncols + 1);
        col_ptr.push(0);
        let mut entries = Vec::new();
        for j in 0..ncols {
            entries.extend(column(j));
            col_ptr.push(entries.len());
        }
        entries.shrink_to_fit();
        DdColumns { nrows, col_ptr, entries }
    }

    fn of(a: &Sparse) -> DdColumns {
        let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        DdColumns::from_columns(a.nrows(), a.ncols(), |j| (cp[j]..cp[j + 1]).map(|p| (ri[p], Dd::from(v[p]))))
    }

    /// `diag(d) · self`, exact zeros dropped.
    fn scale_rows(&self, d: &[Dd]) -> DdColumns {
        let zero = Dd::from(0.0);
        DdColumns::from_columns(self.nrows, self.ncols(), |j| {
            self.col(j).iter().map(|&(i, v)| (i, d[i] * v)).filter(move |&(_, v)| v != zero)
        })
    }

    /// `self · b`.
    fn mul(&self, b: &DdColumns) -> DdColumns {
        let zero = Dd::from(0.0);
        let mut acc = vec![zero; self.nrows];
        let mut seen = vec![false; self.nrows];
        let mut rows = Vec::new();
        let mut col_ptr = Vec::with_capacity(b.ncols() + 1);
        col_ptr.push(0);
        let mut entries = Vec::new();
        for j in 0..b.ncols() {
            rows.clear();
            for &(k, bkj) in b.col(j) {
                for &(i, aik) in self.col(k) {
                    if !seen[i] {
                        seen[i] = true;
                        rows.push(i);
                    }
                    acc[i] += aik * bkj;
                }
            }
            rows.sort_unstable();
            entries.extend(rows.iter().map(|&i| (i, acc[i])).filter(|&(_, v)| v != zero));
            for &i in &rows {
                acc[i] = zero;
                seen[i] = false;
            }
            col_ptr.push(entries.len());
        }
        entries.shrink_to_fit();
        DdColumns { nrows: self.nrows, col_ptr, entries }
    }

    /// The rows with `keep[row]`, renumbered in order.
    fn select_rows(&self, keep: &[bool]) -> DdColumns {
        let mut slot = vec![usize::MAX; self.nrows];
        let mut n = 0;
        for (r, &k) in keep.iter().enumerate() {
            if k {
                slot[r] = n;
                n += 1;
            }
        }
        DdColumns::from_columns(n, self.ncols(), |j| {
            self.col(j).iter().filter(|e| keep[e.0]).map(|&(i, v)| (slot[i], v))
        })
    }

    /// Without its empty rows (itself when none is).
    fn without_empty_rows(self) -> DdColumns {
        let mut used = vec![false; self.nrows];
        for &(i, _) in &self.entries {
            used[i] = true;
        }
        if used.iter().all(|&u| u) {
            return self;
        }
        self.select_rows(&used)
    }

    /// The columns of each row: `(start, columns)` with row `i`'s columns at
    /// `columns[start[i]..start[i + 1]]`, in increasing order.
    fn row_supports(&self) -> (Vec<usize>, Vec<usize>) {
        let mut start = vec![0usize; self.nrows + 1];
        for &(i, _) in &self.entries {
            start[i + 1] += 1;
        }
        for i in 0..self.nrows {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut columns = vec![0usize; self.entries.len()];
        for j in 0..self.ncols() {
            for &(i, _) in self.col(j) {
                columns[fill[i]] = j;
                fill[i] += 1;
            }
        }
        (start, columns)
    }
}

/// `F` with one row `√w (e_i − e_j)` per edge of positive weight `w = −K_ij`: `FᵀF = K` (to
/// double-double) for a stiffness whose off-diagonal entries are all ≤ 0 and whose rows sum to
/// zero (series, grids, meshes without obtuse angles). `None` if an off-diagonal entry is
/// positive.
pub fn edge_factor(k: &Sparse) -> Option<Factor> {
    let (cp, ri, v) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let n = k.ncols();
    // the edges (i < j, in column order) are the rows; each column's entries counted first, so
    // that they are laid out in one array (a vector per column: millions of allocations)
    let mut col_ptr = vec![0usize; n + 1];
    let mut rows = 0;
    for j in 0..n {
        for p in cp[j]..cp[j + 1] {
            let i = ri[p];
            if i < j {
                if v[p] > 0.0 {
                    return None;
                }
                if v[p] < 0.0 {
                    col_ptr[i + 1] += 1;
                    col_ptr[j + 1] += 1;
                    rows += 1;
                }
            }
        }
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let mut fill = col_ptr[..n].to_vec();
    let mut entries = vec![(0usize, Dd::ZERO); col_ptr[n]];
    let mut row = 0;
    for j in 0..n {
        for p in cp[j]..cp[j + 1] {
            let i = ri[p];
            if i < j && v[p] < 0.0 {
                let r = Dd::from(-v[p]).sqrt();
                // a column's rows arrive in increasing order: its own edges to earlier columns
                // while it is visited, then those of later columns
                entries[fill[i]] = (row, r);
                fill[i] += 1;
                entries[fill[j]] = (row, -r);
                fill[j] += 1;
                row += 1;
            }
        }
    }
    Some(Factor::from_dd(&DdColumns { nrows: rows, col_ptr, entries }))
}

/// `F` with `FᵀF = Q` for the energy [`super::polyharmonic`] assembles from the same arguments,
/// the rows of every term stacked, entries in double-double. `k_factor` is a first-order
/// factor, `k_factorᵀ k_factor = K` (one row per edge from [`edge_factor`], or per triangle
/// gradient component on meshes).
///
/// Per order, with `S` dropping sharp vertices and `F₁′` the factor of `K′` (the rows of
/// `k_factor` that touch no sharp vertex):
/// `F₁ = k_factor`, `F₂ = S M^{-½} K`, `F₃ = F₁′ S M⁻¹ K`, `F₄ = M^{-½} K′ S M⁻¹ K`,
/// each term scaled by `√(weight · scale)`.
///
/// `None` when a term needs `F₁′` but `k_factor`'s rows are not single edges (a mesh whose
/// cotangent weights are not all ≥ 0, with sharp vertices and an order ≥ 3): `K′` removes
/// edges, which a triangle's gradient cannot.
pub fn polyharmonic_factor(k: &Sparse, k_factor: &Factor, m: &[f64], energy: &Energy, scale: &[f64]) -> Option<Factor> {
    assert_eq!(scale.len(), energy.terms.len());
    let n = k.nrows();
    let k = &without_zeros(k);
    let mut sharp = vec![false; n];
    for &v in &energy.sharp {
        sharp[v] = true;
    }
    let zero = Dd::from(0.0);
    let minv: Vec<Dd> = m.iter().map(|&x| Dd::from(1.0) / Dd::from(x)).collect();
    let root_minv: Vec<Dd> = minv.iter().map(|x| x.sqrt()).collect();
    let d: Vec<Dd> = (0..n).map(|i| if sharp[i] { zero } else { minv[i] }).collect();
    let root_d: Vec<Dd> = (0..n).map(|i| if sharp[i] { zero } else { root_minv[i] }).collect();
    let kd = DdColumns::of(k);
    let cut_factor = || -> Option<DdColumns> {
        let f1 = factor_dd(k_factor);
        if energy.sharp.is_empty() {
            return Some(f1);
        }
        let (support_start, support) = f1.row_supports();
        if !support_start.windows(2).all(|w| w[1] - w[0] <= 2) {
            return None;
        }
        let keep: Vec<bool> =
            support_start.windows(2).map(|w| support[w[0]..w[1]].iter().all(|&v| !sharp[v])).collect();
        Some(f1.select_rows(&keep))
    };
    // each term's rows, stacked: column j holds every term's entries of column j in turn
    let mut terms: Vec<(DdColumns, Dd, usize)> = Vec::new();
    let mut base = 0;
    for (&(order, w), &s) in energy.terms.iter().zip(scale) {
        let c = w * s;
        if c == 0.0 {
            continue;
        }
        let g = || kd.scale_rows(&d); // S M⁻¹ K
        let f = match order {
            1 => factor_dd(k_factor),
            2 => kd.scale_rows(&root_d),
            3 => cut_factor()?.mul(&g()),
            _ => {
                let k_cut =
                    if energy.sharp.is_empty() { kd.mul(&g()) } else { DdColumns::of(&cut_edges(k, &sharp)).mul(&g()) };
                k_cut.scale_rows(&root_minv)
            }
        }
        .without_empty_rows();
        let root = (Dd::from(w) * Dd::from(s)).sqrt();
        let rows = f.nrows;
        terms.push((f, root, base));
        base += rows;
    }
    if let [(f, root, _)] = &mut terms[..] {
        // one term: its columns as they are, scaled in place
        f.entries.iter_mut().for_each(|e| e.1 = *root * e.1);
        return Some(Factor::from_dd(f));
    }
    Some(Factor::from_dd(&DdColumns::from_columns(base, n, |j| {
        terms.iter().flat_map(move |(f, root, at)| f.col(j).iter().map(move |&(i, v)| (at + i, *root * v)))
    })))
}

fn factor_dd(f: &Factor) -> DdColumns {
    let (cp, ri) = (f.matrix.symbolic().col_ptr(), f.matrix.symbolic().row_idx());
    DdColumns::from_columns(f.matrix.nrows(), f.matrix.ncols(), |j| (cp[j]..cp[j + 1]).map(|p| (ri[p], f.entry(p))))
}
