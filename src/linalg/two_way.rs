//! Sparse Cholesky on two cores by the top level of a nested dissection.
//!
//! The dissection splits the unknowns into parts `A`, `B` and a separator `S` with no entry
//! between `A` and `B`. Each part is factorised with the separator appended,
//! `M_A = [N_AA N_AS; N_SA N_SS] = L_A L_Aᵀ` (and `M_B` likewise), on its own core. The
//! trailing `S × S` block `T_A` of `L_A` satisfies `T_A T_Aᵀ = N_SS − N_SA N_AA⁻¹ N_AS`, so the
//! Schur complement of both parts is the dense `Σ = T_A T_Aᵀ + T_B T_Bᵀ − N_SS = L_Σ L_Σᵀ`, and
//! `N = L Lᵀ` with `L = [L_AA 0 0; 0 L_BB 0; X_A X_B L_Σ]` in the order (A, B, S), where `L_AA`
//! and `X_A` are the leading blocks of `L_A`. A solve runs the parts' triangular solves side by
//! side (see [`TwoWay::solve_in_place`]).
//!
//! faer's supernodal factorisation parallelises inside its dense blocks only, which on two
//! cores paid off for the largest factors alone (1.33× at 10¹¹ flops); splitting the
//! elimination tree at its root gives both cores independent work at every size. The price is
//! the separator's dense block factorised three times (`|S|³/3` flops each) and two dense
//! products, small beside the parts for planar-like graphs (`|S| ~ √n`).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::matmul::triangular::BlockStructure;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Accum, Conj, Mat, MatMut, Par, Side, Spec};

/// One part with the separator appended: its unknowns, the upper pattern of `M` in local
/// order (part first, separator last) and where each entry comes from in `N`'s values.
struct Half {
    verts: Vec<usize>,
    pattern: SymbolicSparseColMat<usize>,
    /// (u32: a million-unknown bilaplacian has 2·10⁷ entries; N's values fit far below 2³².)
    src: Vec<u32>,
    symbolic: SymbolicCholesky<usize>,
}

/// The analysis of a two-way factorisation of a fixed pattern.
pub struct Symbolic {
    n: usize,
    halves: [Half; 2],
    sep: Vec<usize>,
    /// Entries of `N` inside `S × S` as (row, column) in separator order with row ≥ column,
    /// and their position in `N`'s values.
    sep_entries: Vec<(usize, usize, usize)>,
}

impl Symbolic {
    /// Analyses the upper pattern `a` of `N` given an ordering `perm` (`perm[new] = old`) whose
    /// first `sizes[0]` and next `sizes[1]` unknowns are two parts with no entry between them
    /// and whose rest is the separator. `None` when that does not hold or faer's analysis fails.
    pub fn new(a: SymbolicSparseColMatRef<'_, usize>, perm: &[usize], sizes: [usize; 2]) -> Option<Symbolic> {
        let n = a.ncols();
        let [la, lb] = sizes;
        if la == 0 || lb == 0 || la + lb >= n || perm.len() != n {
            return None;
        }
        // side of each unknown (0, 1: parts, 2: separator) and its local index there
        let mut side = vec![2u8; n];
        let mut local = vec![0usize; n];
        for (k, &v) in perm.iter().enumerate() {
            let (s, l) = if k < la {
                (0, k)
            } else if k < la + lb {
                (1, k - la)
            } else {
                (2, k - la - lb)
            };
            side[v] = s;
            local[v] = l;
        }
        let sep: Vec<usize> = perm[la + lb..].to_vec();
        let ls = sep.len();
        let sizes_local = [la, lb];
        let mut triplets: [Vec<(usize, usize, usize)>; 2] = [Vec::new(), Vec::new()];
        let mut sep_entries = Vec::new();
        let ri = a.row_idx();
        for j in 0..n {
            let range = a.col_range(j);
            for (pos, &i) in (range.start..).zip(&ri[range.clone()]) {
                let (si, sj) = (side[i], side[j]);
                match (si, sj) {
                    (2, 2) => {
                        let (li, lj) = (local[i], local[j]);
                        sep_entries.push((li.max(lj), li.min(lj), pos));
                        for h in 0..2 {
                            let base = sizes_local[h];
                            triplets[h].push(((base + li).min(base + lj), (base + li).max(base + lj), pos));
                        }
                    }
                    (0, 1) | (1, 0) => return None,
                    _ => {
                        let h = if si == 2 { sj } else { si } as usize;
                        let base = sizes_local[h];
                        let at = |v: usize| if side[v] == 2 { base + local[v] } else { local[v] };
                        let (li, lj) = (at(i), at(j));
                        triplets[h].push((li.min(lj), li.max(lj), pos));
                    }
                }
            }
        }
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let half = |h: usize, mut t: Vec<(usize, usize, usize)>| -> Option<Half> {
            let m = sizes_local[h] + ls;
            t.sort_unstable_by_key(|&(i, j, _)| (j, i));
            let mut col_ptr = vec![0usize; m + 1];
            for &(_, j, _) in &t {
                col_ptr[j + 1] += 1;
            }
            for j in 0..m {
                col_ptr[j + 1] += col_ptr[j];
            }
            let row_idx: Vec<usize> = t.iter().map(|&(i, _, _)| i).collect();
            let src = t.iter().map(|&(_, _, p)| u32::try_from(p).ok()).collect::<Option<Vec<u32>>>()?;
            let pattern = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
            let symbolic =
                factorize_symbolic_cholesky(pattern.as_ref(), Side::Upper, SymmetricOrdering::Identity, params).ok()?;
            if !matches!(symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_)) {
                return None;
            }
            let verts: Vec<usize> = if h == 0 { perm[..la].to_vec() } else { perm[la..la + lb].to_vec() };
            Some(Half { verts, pattern, src, symbolic })
        };
        // the two halves side by side
        let [t0, t1] = triplets;
        let (h0, h1) = crate::parallel::join(|| half(0, t0), || half(1, t1));
        Some(Symbolic { n, halves: [h0?, h1?], sep, sep_entries })
    }

    #[cfg(test)]
    /// Size of the separator.
    pub fn separator_len(&self) -> usize {
        self.sep.len()
    }

    /// Flops of the larger part's factorisation (with the separator) and product `T Tᵀ`, then of
    /// the dense Schur complement (assembly and Cholesky): the critical path on two cores.
    pub fn critical_flops(&self) -> f64 {
        let s = self.sep.len() as f64;
        let dense = s * s * s / 3.0;
        let part = self.halves.iter().map(|h| super::cost::factor_flops(&h.symbolic)).fold(0.0, f64::max);
        part + dense + dense / 1.5
    }
}

/// Numeric buffers of one half.
struct HalfNumeric {
    values: Vec<f64>,
    l: Vec<f64>,
    mem: MemBuffer,
    /// The trailing block `T` (lower triangle, zero above).
    t: Mat<f64>,
    work: Vec<f64>,
}

impl Symbolic {
    /// The bytes [`TwoWay::new`] allocates for this analysis.
    pub fn numeric_bytes(&self) -> u64 {
        let ls = self.sep.len();
        let f64s = |n: usize| 8 * n as u64;
        let halves: u64 = self
            .halves
            .iter()
            .map(|h| {
                let req = StackReq::any_of(&[
                    h.symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::default()),
                    supernodal(h).solve_in_place_scratch::<f64>(1, Par::Seq),
                ]);
                f64s(h.src.len())
                    + f64s(h.symbolic.len_val())
                    + req.size_bytes() as u64
                    + f64s(ls * ls)
                    + f64s(h.pattern.ncols())
            })
            .sum();
        let sigma = faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(
            ls,
            crate::parallel::faer_par(),
            Spec::default(),
        );
        halves + 2 * f64s(ls * ls) + sigma.size_bytes() as u64
    }
}

/// A two-way factorisation: numeric values for a [`Symbolic`].
pub struct TwoWay {
    halves: [HalfNumeric; 2],
    /// `T_A T_Aᵀ`, then `Σ`, then `L_Σ` (lower triangles).
    sigma: Mat<f64>,
    /// `T_B T_Bᵀ` (lower triangle).
    gram: Mat<f64>,
    sigma_mem: MemBuffer,
}

fn supernodal(h: &Half) -> &faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky<usize> {
    match h.symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(s) => s,
        SymbolicCholeskyRaw::Simplicial(_) => unreachable!("checked in Symbolic::new"),
    }
}

impl TwoWay {
    /// Workspace for `s`.
    ///
    /// # Errors
    /// A message if the workspace cannot be allocated.
    pub fn new(s: &Symbolic) -> std::result::Result<TwoWay, crate::error::NumericalError> {
        let ls = s.sep.len();
        let oom = |_| "out of memory for the Cholesky workspace".to_string();
        let mut halves = Vec::with_capacity(2);
        for h in &s.halves {
            let m = h.pattern.ncols();
            let req = StackReq::any_of(&[
                h.symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::default()),
                supernodal(h).solve_in_place_scratch::<f64>(1, Par::Seq),
            ]);
            halves.push(HalfNumeric {
                values: vec![0.0; h.src.len()],
                l: vec![0.0; h.symbolic.len_val()],
                mem: MemBuffer::try_new(req).map_err(oom)?,
                t: Mat::zeros(ls, ls),
                work: vec![0.0; m],
            });
        }
        let par = crate::parallel::faer_par();
        let sigma_mem = MemBuffer::try_new(faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(
            ls,
            par,
            Spec::default(),
        ))
        .map_err(oom)?;
        let h1 = halves.pop().expect("two halves");
        let h0 = halves.pop().expect("two halves");
        Ok(TwoWay { halves: [h0, h1], sigma: Mat::zeros(ls, ls), gram: Mat::zeros(ls, ls), sigma_mem })
    }

    /// Maps every page of the storage now (see [`super::Workspace`]).
    pub(super) fn touch(&mut self) {
        for h in &mut self.halves {
            super::cost::touch_pages(&mut h.values);
            super::cost::touch_pages(&mut h.l);
            super::cost::touch_pages(&mut h.work);
            touch_mat(&mut h.t);
        }
        touch_mat(&mut self.sigma);
        touch_mat(&mut self.gram);
    }

    /// Factorises `N` given by `values` (aligned with the analysed pattern).
    ///
    /// # Errors
    /// A message if `N` is not numerically positive definite.
    pub fn factor(&mut self, s: &Symbolic, values: &[f64]) -> std::result::Result<(), crate::error::NumericalError> {
        let [n0, n1] = &mut self.halves;
        let [h0, h1] = &s.halves;
        let (sigma, gram) = (&mut self.sigma, &mut self.gram);
        let (r0, r1) =
            crate::parallel::join(|| factor_half(h0, n0, values, sigma), || factor_half(h1, n1, values, gram));
        r0?;
        r1?;
        let ls = s.sep.len();
        for j in 0..ls {
            for i in j..ls {
                self.sigma[(i, j)] += self.gram[(i, j)];
            }
        }
        for &(i, j, p) in &s.sep_entries {
            self.sigma[(i, j)] -= values[p];
        }
        faer::linalg::cholesky::llt::factor::cholesky_in_place(
            self.sigma.as_mut(),
            LltRegularization::default(),
            crate::parallel::faer_par(),
            MemStack::new(&mut self.sigma_mem),
            Spec::default(),
        )
        .map_err(|e| format!("the separator's Schur complement is not positive definite: {e:?}"))?;
        Ok(())
    }

    /// Overwrites `rhs` (length `n`, original order) with `N⁻¹ rhs`.
    ///
    /// Forward: `L_A [y_A; t_A] = [r_A; 0]` gives `T_A t_A = −X_A y_A`, so the separator's
    /// right-hand side is `r_S + T_A t_A + T_B t_B`; `x_S = Σ⁻¹` of it. Backward:
    /// `L_Aᵀ [x_A; x_S] = [y_A; T_Aᵀ x_S]` returns `x_A`.
    pub fn solve_in_place(&mut self, s: &Symbolic, rhs: &mut [f64]) {
        debug_assert_eq!(rhs.len(), s.n);
        let ls = s.sep.len();
        let [n0, n1] = &mut self.halves;
        let [h0, h1] = &s.halves;
        let rhs_ro: &[f64] = rhs;
        let (g0, g1) = crate::parallel::join(|| forward_half(h0, n0, rhs_ro, ls), || forward_half(h1, n1, rhs_ro, ls));
        let mut xs = Mat::<f64>::zeros(ls, 1);
        for k in 0..ls {
            xs[(k, 0)] = rhs[s.sep[k]] + g0[k] + g1[k];
        }
        let par = Par::Seq;
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(self.sigma.as_ref(), xs.as_mut(), par);
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(
            self.sigma.as_ref().transpose(),
            xs.as_mut(),
            par,
        );
        let xs_ref = xs.as_ref();
        crate::parallel::join(|| backward_half(h0, n0, xs_ref), || backward_half(h1, n1, xs_ref));
        for (h, num) in s.halves.iter().zip(&self.halves) {
            for (k, &v) in h.verts.iter().enumerate() {
                rhs[v] = num.work[k];
            }
        }
        for k in 0..ls {
            rhs[s.sep[k]] = xs[(k, 0)];
        }
    }
}

fn touch_mat(m: &mut Mat<f64>) {
    for j in 0..m.ncols() {
        for i in (0..m.nrows()).step_by(512) {
            m[(i, j)] = std::hint::black_box(0.0);
        }
    }
}

/// Gathers a half's values, factorises it, extracts `T` and writes `T Tᵀ` to `gram`.
fn factor_half(
    h: &Half,
    num: &mut HalfNumeric,
    values: &[f64],
    gram: &mut Mat<f64>,
) -> std::result::Result<(), crate::error::NumericalError> {
    for (v, &p) in num.values.iter_mut().zip(&h.src) {
        *v = values[p as usize];
    }
    h.symbolic
        .factorize_numeric_llt(
            &mut num.l,
            SparseColMatRef::new(h.pattern.as_ref(), &num.values),
            Side::Upper,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut num.mem),
            Spec::default(),
        )
        .map_err(|e| format!("{e:?}"))?;
    let sn = supernodal(h);
    let first = h.verts.len();
    let t = &mut num.t;
    t.fill(0.0);
    let llt = SupernodalLltRef::new(sn, &num.l);
    for k in (0..sn.n_supernodes()).rev() {
        let node = llt.supernode(k);
        let (start, val) = (node.start(), node.val());
        let ncols = val.ncols();
        if start + ncols <= first {
            break;
        }
        let pattern = node.pattern();
        for c in 0..ncols {
            let col = start + c;
            if col < first {
                continue;
            }
            for r in c..ncols {
                t[(start + r - first, col - first)] = val[(r, c)];
            }
            for (q, &row) in pattern.iter().enumerate() {
                t[(row - first, col - first)] = val[(ncols + q, c)];
            }
        }
    }
    faer::linalg::matmul::triangular::matmul(
        gram.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Replace,
        num.t.as_ref(),
        BlockStructure::TriangularLower,
        num.t.as_ref().transpose(),
        BlockStructure::TriangularUpper,
        1.0,
        Par::Seq,
    );
    Ok(())
}

/// `L [y; t] = [r_part; 0]`; returns `T t` (= `−X y`).
fn forward_half(h: &Half, num: &mut HalfNumeric, rhs: &[f64], ls: usize) -> Vec<f64> {
    let first = h.verts.len();
    for (k, &v) in h.verts.iter().enumerate() {
        num.work[k] = rhs[v];
    }
    num.work[first..].iter_mut().for_each(|v| *v = 0.0);
    let llt = SupernodalLltRef::new(supernodal(h), &num.l);
    llt.l_solve_with_conj(
        Conj::No,
        MatMut::from_column_major_slice_mut(&mut num.work, first + ls, 1),
        Par::Seq,
        MemStack::new(&mut num.mem),
    );
    let mut g = Mat::<f64>::zeros(ls, 1);
    let tail = faer::MatRef::from_column_major_slice(&num.work[first..], ls, 1);
    faer::linalg::matmul::triangular::matmul(
        g.as_mut(),
        BlockStructure::Rectangular,
        Accum::Replace,
        num.t.as_ref(),
        BlockStructure::TriangularLower,
        tail,
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
    (0..ls).map(|k| g[(k, 0)]).collect()
}

/// `Lᵀ [x; x_S] = [y; Tᵀ x_S]`, leaving `x` in the first entries of the work vector.
fn backward_half(h: &Half, num: &mut HalfNumeric, xs: faer::MatRef<'_, f64>) {
    let first = h.verts.len();
    let ls = xs.nrows();
    let mut w = Mat::<f64>::zeros(ls, 1);
    faer::linalg::matmul::triangular::matmul(
        w.as_mut(),
        BlockStructure::Rectangular,
        Accum::Replace,
        num.t.as_ref().transpose(),
        BlockStructure::TriangularUpper,
        xs,
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
    for k in 0..ls {
        num.work[first + k] = w[(k, 0)];
    }
    let llt = SupernodalLltRef::new(supernodal(h), &num.l);
    llt.l_transpose_solve_with_conj(
        Conj::No,
        MatMut::from_column_major_slice_mut(&mut num.work, first + ls, 1),
        Par::Seq,
        MemStack::new(&mut num.mem),
    );
}
