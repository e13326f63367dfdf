//! The pieces of the interior-point method's Newton system that both arithmetics share: the
//! constraint rows, the normal matrix's pattern (and its analysis made in advance), the
//! objective's interface and the arithmetic itself (`f64` or double-double).

use super::problem::ReducedQp;
pub(super) use super::problem::Rows;
use super::problem::ABSENT;
use crate::linalg as ordering;
use crate::linalg::double_double::Dd;
use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};

/// Upper-triangular pattern of `N` and where each contribution lands in its value array.
pub(super) struct Normal {
    pub(super) symbolic: SymbolicSparseColMat<usize>,
    /// Position of each P triplet.
    pub(super) pos_p: Vec<usize>,
    /// Per row: positions of (c1,c1), (c2,c2), (c1,c2) (the last two unused for one-entry rows).
    pub(super) pos_row: Vec<[usize; 3]>,
    /// Position of each diagonal entry.
    pub(super) pos_diag: Vec<usize>,
}

/// Upper-triangular pattern, every diagonal entry included, of the pairs `(i, j)` with
/// `i ≤ j` (duplicates merged): column pointers and sorted row indices.
fn upper_pattern(n: usize, pairs: impl Iterator<Item = (usize, usize)> + Clone) -> (Vec<usize>, Vec<usize>) {
    let mut count = vec![0usize; n + 1];
    for (_, j) in pairs.clone() {
        count[j + 1] += 1;
    }
    for j in 0..n {
        count[j + 1] += count[j] + 1;
    }
    let mut fill = count.clone();
    let mut rows = vec![0usize; count[n]];
    for j in 0..n {
        rows[fill[j]] = j;
        fill[j] += 1;
    }
    for (i, j) in pairs {
        rows[fill[j]] = i;
        fill[j] += 1;
    }
    ordering::compress_columns(&count, &mut rows)
}

impl Normal {
    pub(super) fn new(r: &ReducedQp, constraint_rows: &Rows) -> Normal {
        let n = r.n;
        let rows = constraint_rows.pairs().map(|(a, b)| (a.min(b), a.max(b)));
        let (col_ptr, row_idx) = upper_pattern(n, r.p.entries().map(|(i, j, _)| (i, j)).chain(rows));
        let find = |i: usize, j: usize| {
            col_ptr[j] + row_idx[col_ptr[j]..col_ptr[j + 1]].binary_search(&i).expect("in pattern")
        };
        let pos_p = r.p.entries().map(|(i, j, _)| find(i, j)).collect();
        let pos_row = (0..constraint_rows.len())
            .map(|k| {
                let (c, _, len) = constraint_rows.row(k);
                if len == 2 {
                    [find(c[0], c[0]), find(c[1], c[1]), find(c[0].min(c[1]), c[0].max(c[1]))]
                } else {
                    let d = find(c[0], c[0]);
                    [d, d, d]
                }
            })
            .collect();
        let pos_diag = (0..n).map(|j| find(j, j)).collect();
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Normal { symbolic, pos_p, pos_row, pos_diag }
    }
}

/// The half-width of the normal matrix `P + AᵀWA` of `r` with constraint rows `rows` if every
/// entry of P and every row lies within [`ordering::BANDED_MAX`] places of the diagonal (a
/// series): the same test as [`ordering::band`] on its pattern, made without the pattern, so
/// that a banded normal matrix is assembled straight into its band (at 10⁷ samples the pattern
/// and its position tables held 1.5 GB).
pub(super) fn normal_band(r: &ReducedQp, rows: &Rows) -> Option<usize> {
    let p = r.p.width();
    let a = rows.pairs().map(|(a, b)| a.abs_diff(b)).max();
    let b = p.max(a.unwrap_or(0));
    (b <= ordering::BANDED_MAX).then_some(b)
}

/// The analysis of a normal matrix made before its constraints are known: from the pattern of
/// `P` on the free variables alone. The constrained pairs of a monotone QP are edges of the
/// domain, inside the pattern of any energy built on its Laplacian, so the normal matrix's
/// pattern is that one and the structured solver, given it, finds this analysis ready.
pub struct Prepared {
    pattern: SymbolicSparseColMat<usize>,
    analysis: ordering::Analysis,
    /// The factor's storage, its pages mapped in advance.
    workspace: Option<ordering::Workspace>,
}

impl Prepared {
    /// Analyses the pattern of the upper triangle of `P` on the free variables (`slot[i]`:
    /// index of variable `i` among the free ones, `usize::MAX` if fixed; `n` free ones).
    ///
    /// # Errors
    /// A message if the analysis fails.
    /// The storage is made only if `fits` its size in bytes.
    pub fn new(
        p: SymbolicSparseColMatRef<'_, usize>,
        slot: &[usize],
        n: usize,
        fits: impl FnOnce(u64) -> bool,
    ) -> std::result::Result<Prepared, crate::error::NumericalError> {
        let (cp, ri) = (p.col_ptr(), p.row_idx());
        let pairs = (0..p.ncols()).flat_map(|j| {
            ri[cp[j]..p.col_range(j).end].iter().filter_map(move |&i| {
                let (si, sj) = (slot[i], slot[j]);
                (si != usize::MAX && sj != usize::MAX && si <= sj).then_some((si, sj))
            })
        });
        let (col_ptr, row_idx) = upper_pattern(n, pairs);
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let analysis = ordering::analyse(pattern.as_ref())?;
        // without it (faer's scratch could not be allocated, or it would not fit the budget) the
        // solver makes the storage, or refuses to
        // (and a banded pattern, a series, gets its own factor in the solver: none made here)
        let banded = ordering::band(pattern.as_ref()).is_some();
        let workspace =
            if !banded && fits(analysis.numeric_bytes()) { ordering::Workspace::new(&analysis).ok() } else { None };
        Ok(Prepared { pattern, analysis, workspace })
    }

    /// The analysed pattern.
    #[cfg(test)]
    pub(crate) fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        self.pattern.as_ref()
    }

    /// Keeps the analysis in `analyses` and returns the storage made for it.
    pub(super) fn keep_in(
        self,
        analyses: &mut ordering::Analyses,
    ) -> Option<(std::sync::Arc<ordering::Analysis>, ordering::Workspace)> {
        let analysis = std::sync::Arc::new(self.analysis);
        analyses.keep(self.pattern, analysis.clone());
        self.workspace.map(|w| (analysis, w))
    }
}

/// The arithmetic of an interior-point run: `f64`, or double-double ([`Dd`]) for the factored
/// form of an ill-conditioned QP, where every residual and right-hand side must keep the digits
/// that `P`'s condition number takes from the solve.
pub(super) trait Real:
    Copy
    + Send
    + Sync
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
    + std::ops::Neg<Output = Self>
    + std::ops::AddAssign
    + std::ops::SubAssign
{
    /// Whether [`Real::div_by`] uses its reciprocal (else the iteration keeps none: any
    /// vector of the right length stands in for it).
    const RECIPROCALS: bool;
    fn of(x: f64) -> Self;
    fn to_f64(self) -> f64;
    /// `self / den`, given `inv = 1 / den`: a division in double, a product with the
    /// reciprocal in double-double (a division there costs about ten products, and the
    /// iteration divides by the same slacks and data diagonal many times per step).
    fn div_by(self, den: Self, inv: Self) -> Self;
    /// `v` in this arithmetic: borrowed in double (a copy of a vector of 10⁷ rows is 80 MB).
    fn lift(v: &[f64]) -> std::borrow::Cow<'_, [Self]>;
    /// `v` in this arithmetic, owned: `v` itself in double.
    fn lift_vec(v: Vec<f64>) -> Vec<Self>;
}

impl Real for f64 {
    const RECIPROCALS: bool = false;
    fn lift(v: &[f64]) -> std::borrow::Cow<'_, [Self]> {
        std::borrow::Cow::Borrowed(v)
    }
    fn lift_vec(v: Vec<f64>) -> Vec<Self> {
        v
    }
    fn of(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn div_by(self, den: Self, _inv: Self) -> Self {
        self / den
    }
}

impl Real for Dd {
    const RECIPROCALS: bool = true;
    fn lift(v: &[f64]) -> std::borrow::Cow<'_, [Self]> {
        std::borrow::Cow::Owned(v.iter().map(|&x| Dd::from(x)).collect())
    }
    fn lift_vec(v: Vec<f64>) -> Vec<Self> {
        v.into_iter().map(Dd::from).collect()
    }
    #[inline(always)]
    fn of(x: f64) -> Self {
        Dd::from(x)
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        Dd::to_f64(self)
    }
    #[inline(always)]
    fn div_by(self, _den: Self, inv: Self) -> Self {
        self * inv
    }
}

pub(super) fn max<T: Real>(a: T, b: T) -> T {
    if b > a {
        b
    } else {
        a
    }
}

impl Rows {
    /// `out = A x`.
    pub(super) fn ax<T: Real>(&self, x: &[T], out: &mut [T]) {
        let ends = self.ends();
        crate::parallel::split_mut(out, |offset, out| {
            for (o, &[a, b]) in out.iter_mut().zip(&ends[offset..]) {
                *o = match (a, b) {
                    (a, ABSENT) => x[a as usize],
                    (ABSENT, b) => -x[b as usize],
                    (a, b) => x[a as usize] - x[b as usize],
                };
            }
        });
    }

    /// `out = Aᵀ z`.
    pub(super) fn atz<T: Real>(&self, z: &[T], out: &mut [T]) {
        out.iter_mut().for_each(|v| *v = T::of(0.0));
        for (&zk, &[a, b]) in z.iter().zip(self.ends()) {
            if a != ABSENT {
                out[a as usize] += zk;
            }
            if b != ABSENT {
                out[b as usize] -= zk;
            }
        }
    }
}

/// The objective's part of the Newton system: its gradient at the iterate and the
/// factorisation of `P + AᵀWA`.
pub(super) trait Objective<T: Real> {
    /// `out = ∇φ(x)`.
    fn gradient(&mut self, x: &[T], out: &mut [T]);
    /// Factorises `P + Aᵀ diag(w) A`.
    fn factor(&mut self, rows: &Rows, w: &[T]) -> std::result::Result<(), crate::error::NumericalError>;
    /// Overwrites `rhs` with the last factorised matrix's inverse times it.
    fn solve_in_place(&mut self, rhs: &mut [T]);
    /// The auxiliary variables `t = F x + g` (factored form), rounded.
    fn auxiliary(&self, x: &[T]) -> Option<Vec<f64>>;
    /// `½ rᵀ P⁻¹ r`, for the gap of a QP without a data term (no `P ⪰ diag(d)` to bound it
    /// by): `None` where the objective cannot solve with `P` alone.
    fn energy_dual(&mut self, _r: &[T]) -> Option<f64> {
        None
    }
}
