//! The normal equations of the factored formulation `P = FᵀF + diag(d)` in double-double
//! arithmetic (faer's `fx128`).
//!
//! An assembled `P` of condition κ carries rounding errors of `10⁻¹⁶ κ` relative to its
//! smallest eigenvalues, so its gradient `P x + q` is noise once κ nears 10¹⁶ and the gap bound
//! (which needs the gradient to about `10⁻⁸` of the data term's) long before. Formed from `F` in
//! double-double, the normal matrix and the gradient `Fᵀ(F x + g) + d∘x + q_d` keep about 32
//! digits, and the iterate is kept to that precision too; the auxiliary variables `t = F x + g`
//! come out rounded, for the gap bound of the factored form (`½‖F x + g − t‖²` is then the
//! rounding of `t` alone).

use super::ipm::{Normal as Pattern, Objective, Rows};
use super::qp::{ReducedFactor, ReducedQp};
use crate::linalg;
use crate::operators::Sparse;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::fx128;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky};
use faer::sparse::SparseColMatRef;
use faer::{Conj, Par, Side, Spec};

/// The factored objective and its normal matrix, in double-double.
pub(super) struct Normal<'r> {
    f: &'r ReducedFactor,
    d: Vec<fx128>,
    q: Vec<fx128>,
    pattern: Pattern,
    /// `F_FᵀF_F + diag(d)` on the pattern.
    base: Vec<fx128>,
    vals: Vec<fx128>,
    symbolic: SymbolicCholesky<usize>,
    l: Vec<fx128>,
    mem: MemBuffer,
    t: std::cell::RefCell<Vec<fx128>>,
}

/// The product of two doubles, exactly.
fn product(a: f64, b: f64) -> fx128 {
    let p = a * b;
    fx128::from(p) + fx128::from(a.mul_add(b, -p))
}

impl<'r> Normal<'r> {
    /// The pattern of `P + AᵀWA` (P's on the free variables and the constrained pairs), `F`'s
    /// Gram matrix on it in double-double, and its symbolic factorisation.
    ///
    /// # Errors
    /// A message if `FᵀF` has an entry outside `P`'s pattern or the analysis fails.
    pub(super) fn new(
        r: &'r ReducedQp,
        f: &'r ReducedFactor,
        row_cols: &[[usize; 2]],
        row_len: &[u8],
    ) -> Result<Normal<'r>, String> {
        let pattern = Pattern::new(r, row_cols, row_len);
        let (cp, ri) = (pattern.symbolic.col_ptr(), pattern.symbolic.row_idx());
        let find = |i: usize, j: usize| {
            ri[cp[j]..cp[j + 1]]
                .binary_search(&i)
                .map(|p| cp[j] + p)
                .map_err(|_| format!("the factor couples variables {i} and {j}, which the assembled energy does not"))
        };
        let mut base = vec![fx128::from(0.0); ri.len()];
        let ft: Sparse = f.f.as_ref().transpose().to_col_major().map_err(|e| format!("{e:?}"))?;
        let (tcp, tri, tv) = (ft.symbolic().col_ptr(), ft.symbolic().row_idx(), ft.val());
        for row in 0..ft.ncols() {
            let entries = tcp[row]..tcp[row + 1];
            for a in entries.clone() {
                for b in entries.clone() {
                    let (i, j) = (tri[a], tri[b]);
                    if i <= j {
                        base[find(i, j)?] += product(tv[a], tv[b]);
                    }
                }
            }
        }
        for (j, &d) in r.d.iter().enumerate() {
            base[pattern.pos_diag[j]] += fx128::from(d);
        }
        let symbolic = linalg::analyse_simplicial(pattern.symbolic.as_ref())?;
        let mem = MemBuffer::try_new(StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<fx128>(Par::Seq, Spec::default()),
            symbolic.solve_in_place_scratch::<fx128>(1, Par::Seq),
        ]))
        .map_err(|_| "out of memory for the double-double Cholesky workspace".to_string())?;
        let l = vec![fx128::from(0.0); symbolic.len_val()];
        Ok(Normal {
            f,
            d: r.d.iter().map(|&v| fx128::from(v)).collect(),
            q: r.q_free.iter().map(|&v| fx128::from(v)).collect(),
            vals: base.clone(),
            base,
            pattern,
            symbolic,
            l,
            mem,
            t: std::cell::RefCell::new(vec![fx128::from(0.0); f.f.nrows()]),
        })
    }

    /// `t = F x + g`.
    fn auxiliary_into(&self, x: &[fx128], t: &mut [fx128]) {
        let f = &self.f.f;
        for (t, &g) in t.iter_mut().zip(&self.f.g) {
            *t = fx128::from(g);
        }
        let (cp, ri, v) = (f.symbolic().col_ptr(), f.symbolic().row_idx(), f.val());
        for (j, &xj) in x.iter().enumerate() {
            for p in cp[j]..cp[j + 1] {
                t[ri[p]] += fx128::from(v[p]) * xj;
            }
        }
    }
}

impl Objective<fx128> for Normal<'_> {
    /// `Fᵀ(F x + g) + d∘x + q_d`.
    fn gradient(&mut self, x: &[fx128], out: &mut [fx128]) {
        let mut t = std::mem::take(&mut *self.t.borrow_mut());
        self.auxiliary_into(x, &mut t);
        let f = &self.f.f;
        let (cp, ri, v) = (f.symbolic().col_ptr(), f.symbolic().row_idx(), f.val());
        for (j, o) in out.iter_mut().enumerate() {
            let mut acc = self.q[j] + self.d[j] * x[j];
            for p in cp[j]..cp[j + 1] {
                acc += fx128::from(v[p]) * t[ri[p]];
            }
            *o = acc;
        }
        *self.t.borrow_mut() = t;
    }

    /// `F_FᵀF_F + diag(d) + Aᵀ diag(w) A`, with a growing diagonal shift if it is not
    /// numerically positive definite.
    fn factor(&mut self, rows: &Rows, w: &[fx128]) -> Result<(), String> {
        let mut reg = 0.0;
        for attempt in 0..4 {
            self.vals.copy_from_slice(&self.base);
            for (k, &wk) in w.iter().enumerate() {
                let [p1, p2, p12] = self.pattern.pos_row[k];
                let [a1, a2] = rows.vals[k];
                self.vals[p1] += wk * fx128::from(a1 * a1);
                if rows.len[k] == 2 {
                    self.vals[p2] += wk * fx128::from(a2 * a2);
                    self.vals[p12] += wk * fx128::from(a1 * a2);
                }
            }
            if reg > 0.0 {
                for &d in &self.pattern.pos_diag {
                    self.vals[d] += fx128::from(reg);
                }
            }
            let a = SparseColMatRef::new(self.pattern.symbolic.as_ref(), &self.vals);
            let ok = self
                .symbolic
                .factorize_numeric_llt(
                    &mut self.l,
                    a,
                    Side::Upper,
                    Default::default(),
                    Par::Seq,
                    MemStack::new(&mut self.mem),
                    Spec::default(),
                )
                .is_ok();
            if ok {
                return Ok(());
            }
            reg = if attempt == 0 { 1e-24 } else { reg * 1e6 };
        }
        Err("the double-double normal matrix is not positive definite".into())
    }

    fn solve_in_place(&mut self, rhs: &mut [fx128]) {
        let n = rhs.len();
        let m = faer::MatMut::from_column_major_slice_mut(rhs, n, 1);
        LltRef::new(&self.symbolic, &self.l).solve_in_place_with_conj(
            Conj::No,
            m,
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }

    fn auxiliary(&self, x: &[fx128]) -> Option<Vec<f64>> {
        let mut t = vec![fx128::from(0.0); self.f.f.nrows()];
        self.auxiliary_into(x, &mut t);
        Some(t.iter().map(|t| t.0 + t.1).collect())
    }
}
