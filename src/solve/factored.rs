//! The normal equations of the factored formulation `P = FᵀF + diag(d)` in double-double
//! arithmetic ([`Dd`]; faer's `fx128` for its simplicial factorisation).
//!
//! An assembled `P` of condition κ carries rounding errors of `10⁻¹⁶ κ` relative to its
//! smallest eigenvalues, so its gradient `P x + q` is noise once κ nears 10¹⁶ and the gap bound
//! (which needs the gradient to about `10⁻⁸` of the data term's) long before. Formed from `F` in
//! double-double, the normal matrix and the gradient `Fᵀ(F x + g) + d∘x + q_d` keep about 32
//! digits, and the iterate is kept to that precision too; the auxiliary variables `t = F x + g`
//! come out rounded, for the gap bound of the factored form (`½‖F x + g − t‖²` is then the
//! rounding of `t` alone).
//!
//! Each solve is mixed-precision iterative refinement: the normal matrix rounded to double is
//! factorised by the crate's Cholesky (supernodal, two-way), and the residual of every
//! correction is formed in double-double, until it is below 10⁻²⁶ of the right-hand side. Where
//! that stalls (the rounded matrix is not positive definite, or its errors exceed its smallest
//! eigenvalues: κ beyond about 10¹⁴), the normal matrix is factorised in double-double itself
//! (simplicial: faer's dense kernels are for native floats only), from then on. A banded
//! normal matrix (a series) is factorised in double-double from the start ([`Banded`]).
//! [`Rounded`] runs the iteration itself in double, with this gradient and this solve.

use super::banded::Banded;
use super::newton::{normal_band, Normal as Pattern, Objective, Rows};
use super::problem::{ReducedFactor, ReducedQp};
use crate::linalg;
use crate::linalg::double_double::{from_fx128, to_fx128, Dd};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::fx128;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky};
use faer::sparse::SparseColMatRef;
use faer::{Conj, Par, Side, Spec};

/// The diagonal shifts tried, in turn, when a double-double factorisation finds the normal
/// matrix not positive definite (rounding at its smallest eigenvalues).
const SHIFTS: [f64; 4] = [0.0, 1e-24, 1e-18, 1e-12];

/// Refinement steps per solve before it counts as stalled.
const REFINEMENT_STEPS: usize = 12;
/// Relative residual at which a refined solve stops.
const REFINED: f64 = 1e-26;

/// The double-double factorisation, made the first time refinement stalls.
struct Exact {
    symbolic: SymbolicCholesky<usize>,
    l: Vec<fx128>,
    mem: MemBuffer,
}

/// The factored objective and its normal matrix, in double-double.
pub(super) struct Normal<'r> {
    f: &'r ReducedFactor,
    d: Vec<Dd>,
    q: Vec<Dd>,
    /// The normal matrix's sparse pattern (`None` when it is banded).
    pattern: Option<Pattern>,
    /// `F_FᵀF_F + diag(d)` on the pattern, or in the band.
    base: Vec<Dd>,
    /// The normal matrix of the last factorisation, and rounded to double.
    vals: Vec<Dd>,
    rounded: Vec<f64>,
    /// Its double-precision Cholesky factor (`None` for a banded pattern, factorised in
    /// double-double only).
    spd: Option<linalg::SpdFactor>,
    /// Whether `spd` holds the last normal matrix (its rounding is positive definite).
    spd_ok: bool,
    exact: Option<Exact>,
    /// A banded normal matrix (a series): assembled in its band and factorised in
    /// double-double from the start ([`Banded`]: about n·b² products, below a few refinement
    /// steps').
    banded: Option<Banded<Dd>>,
    t: std::cell::RefCell<Vec<Dd>>,
}

impl<'r> Normal<'r> {
    /// The pattern of `P + AᵀWA` (P's on the free variables and the constrained pairs), `F`'s
    /// Gram matrix on it in double-double, and its symbolic factorisation
    /// ([`linalg::analyse`]).
    ///
    /// # Errors
    /// A message if `FᵀF` has an entry outside `P`'s pattern or the analysis fails.
    pub(super) fn new(
        r: &'r ReducedQp,
        f: &'r ReducedFactor,
    ) -> std::result::Result<Normal<'r>, crate::error::NumericalError> {
        let zero = Dd::from(0.0);
        // the rows of F (column, double-double entry), each in column order: one counting pass
        // over its columns (a vector per row held 0.1 kB each)
        let (fcp, fri) = (f.f.symbolic().col_ptr(), f.f.symbolic().row_idx());
        let mut start = vec![0usize; f.f.nrows() + 1];
        for &i in fri {
            start[i + 1] += 1;
        }
        for i in 0..f.f.nrows() {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut entries = vec![(0usize, zero); fri.len()];
        for j in 0..f.f.ncols() {
            for p in fcp[j]..fcp[j + 1] {
                entries[fill[fri[p]]] = (j, f.entry(p));
                fill[fri[p]] += 1;
            }
        }
        drop(fill);
        // a banded normal matrix (a series) straight in its band, as the assembled form's
        let band = normal_band(r, &r.rows);
        let pattern = match band {
            Some(_) => None,
            None => Some(Pattern::new(r, &r.rows)),
        };
        let find = |i: usize, j: usize| -> std::result::Result<usize, String> {
            let outside = || format!("the factor couples variables {i} and {j}, which the assembled energy does not");
            match (&pattern, band) {
                (Some(pattern), _) => {
                    let (cp, ri) = (pattern.symbolic.col_ptr(), pattern.symbolic.row_idx());
                    ri[cp[j]..cp[j + 1]].binary_search(&i).map(|p| cp[j] + p).map_err(|_| outside())
                }
                (None, Some(b)) if j - i <= b => Ok(Banded::<Dd>::at(b, i, j)),
                _ => Err(outside()),
            }
        };
        let len = match (&pattern, band) {
            (Some(pattern), _) => pattern.symbolic.row_idx().len(),
            (None, b) => r.n * (b.unwrap_or(0) + 1),
        };
        let mut base = vec![zero; len];
        for row in start.windows(2).map(|w| &entries[w[0]..w[1]]) {
            for &(i, a) in row {
                for &(j, b) in row {
                    if i <= j {
                        base[find(i, j)?] += a * b;
                    }
                }
            }
        }
        for (j, &d) in r.d.iter().enumerate() {
            base[find(j, j)?] += Dd::from(d);
        }
        drop(entries);
        let banded = band.map(|b| Banded::of_band(r.n, b));
        // the double factor and its rounded matrix only where refinement may use them
        let spd = match &pattern {
            None => None,
            Some(pattern) => {
                Some(linalg::SpdFactor::new(std::sync::Arc::new(linalg::analyse(pattern.symbolic.as_ref())?))?)
            }
        };
        let rounded = if spd.is_some() { vec![0.0; base.len()] } else { Vec::new() };
        Ok(Normal {
            f,
            d: r.d.iter().map(|&v| Dd::from(v)).collect(),
            q: r.q_free.iter().map(|&v| Dd::from(v)).collect(),
            vals: if banded.is_some() { Vec::new() } else { base.clone() },
            rounded,
            base,
            pattern,
            spd,
            spd_ok: false,
            exact: None,
            banded,
            t: std::cell::RefCell::new(vec![zero; f.f.nrows()]),
        })
    }

    /// `y = N x` for the normal matrix `vals` on `pattern` (upper triangle stored), in
    /// double-double.
    fn multiply(pattern: &Pattern, vals: &[Dd], x: &[Dd], y: &mut [Dd]) {
        y.iter_mut().for_each(|v| *v = Dd::from(0.0));
        let (cp, ri) = (pattern.symbolic.col_ptr(), pattern.symbolic.row_idx());
        for (j, &xj) in x.iter().enumerate() {
            for (&i, &a) in ri[cp[j]..cp[j + 1]].iter().zip(&vals[cp[j]..cp[j + 1]]) {
                y[i] += a * xj;
                if i != j {
                    y[j] += a * x[i];
                }
            }
        }
    }

    /// Factorises the last normal matrix in double-double (once refinement has stalled).
    fn factor_exact(&mut self) -> std::result::Result<(), crate::error::NumericalError> {
        let Some(pattern) = self.pattern.as_ref() else {
            return Err("a banded normal matrix has no sparse pattern to factorise".into());
        };
        if self.exact.is_none() {
            let symbolic = linalg::analyse_simplicial(pattern.symbolic.as_ref())?;
            let mem = MemBuffer::try_new(StackReq::any_of(&[
                symbolic.factorize_numeric_llt_scratch::<fx128>(Par::Seq, Spec::default()),
                symbolic.solve_in_place_scratch::<fx128>(1, Par::Seq),
            ]))
            .map_err(|_| "out of memory for the double-double Cholesky workspace".to_string())?;
            let l = vec![fx128::from(0.0); symbolic.len_val()];
            self.exact = Some(Exact { symbolic, l, mem });
        }
        let e = self.exact.as_mut().expect("made above");
        for reg in SHIFTS {
            let mut vals: Vec<fx128> = self.vals.iter().map(|&v| to_fx128(v)).collect();
            if reg > 0.0 {
                for &d in &pattern.pos_diag {
                    vals[d] += fx128::from(reg);
                }
            }
            let a = SparseColMatRef::new(pattern.symbolic.as_ref(), &vals);
            let ok = e
                .symbolic
                .factorize_numeric_llt(
                    &mut e.l,
                    a,
                    Side::Upper,
                    Default::default(),
                    Par::Seq,
                    MemStack::new(&mut e.mem),
                    Spec::default(),
                )
                .is_ok();
            if ok {
                return Ok(());
            }
        }
        Err("the double-double normal matrix is not positive definite".into())
    }

    /// `t = F x + g`.
    fn auxiliary_into(&self, x: &[Dd], t: &mut [Dd]) {
        let f = &self.f.f;
        for (t, &g) in t.iter_mut().zip(&self.f.g) {
            *t = Dd::from(g);
        }
        let (cp, ri) = (f.symbolic().col_ptr(), f.symbolic().row_idx());
        for (j, &xj) in x.iter().enumerate() {
            for p in cp[j]..cp[j + 1] {
                t[ri[p]] += self.f.entry(p) * xj;
            }
        }
    }
}

impl Objective<Dd> for Normal<'_> {
    /// `Fᵀ(F x + g) + d∘x + q_d`.
    fn gradient(&mut self, x: &[Dd], out: &mut [Dd]) {
        let mut t = std::mem::take(&mut *self.t.borrow_mut());
        self.auxiliary_into(x, &mut t);
        let f = &self.f.f;
        let (cp, ri) = (f.symbolic().col_ptr(), f.symbolic().row_idx());
        for (j, o) in out.iter_mut().enumerate() {
            let mut acc = self.q[j] + self.d[j] * x[j];
            for p in cp[j]..cp[j + 1] {
                acc += self.f.entry(p) * t[ri[p]];
            }
            *o = acc;
        }
        *self.t.borrow_mut() = t;
    }

    /// `F_FᵀF_F + diag(d) + Aᵀ diag(w) A` in double-double, and its rounding factorised in
    /// double (or in double-double once refinement has stalled).
    fn factor(&mut self, rows: &Rows, w: &[Dd]) -> std::result::Result<(), crate::error::NumericalError> {
        if let Some(banded) = &mut self.banded {
            let b = banded.width();
            let at = |i: usize, j: usize| Banded::<Dd>::at(b, i.min(j), i.max(j));
            let band = banded.band_mut();
            band.copy_from_slice(&self.base);
            // each row's entries are +1 and −1: `w a aᵀ` adds w on the diagonal, −w off it
            for (k, &wk) in w.iter().enumerate() {
                let ([c1, c2], _, len) = rows.row(k);
                band[at(c1, c1)] += wk;
                if len == 2 {
                    band[at(c2, c2)] += wk;
                    band[at(c1, c2)] -= wk;
                }
            }
            // the same regularisation as the general factorisation's, if it must
            for reg in SHIFTS {
                if banded.factor_band(Dd::from(reg)) {
                    return Ok(());
                }
            }
            return Err("the double-double normal matrix is not positive definite".into());
        }
        let Some(pattern) = self.pattern.as_ref() else {
            return Err("the normal matrix has neither a band nor a sparse pattern".into());
        };
        self.vals.copy_from_slice(&self.base);
        for (k, &wk) in w.iter().enumerate() {
            let [p1, p2, p12] = pattern.pos_row[k];
            self.vals[p1] += wk;
            if rows.is_pair(k) {
                self.vals[p2] += wk;
                self.vals[p12] -= wk;
            }
        }
        if self.exact.is_some() {
            return self.factor_exact();
        }
        for (r, v) in self.rounded.iter_mut().zip(&self.vals) {
            *r = v.to_f64();
        }
        let Some(spd) = self.spd.as_mut() else {
            return self.factor_exact();
        };
        let a = SparseColMatRef::new(pattern.symbolic.as_ref(), &self.rounded);
        self.spd_ok = spd.factor(a).is_ok();
        if !self.spd_ok {
            return self.factor_exact();
        }
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [Dd]) {
        if let Some(banded) = &self.banded {
            banded.solve_in_place(rhs);
            return;
        }
        let n = rhs.len();
        if let (None, true, Some(spd), Some(pattern)) =
            (&self.exact, self.spd_ok, self.spd.as_mut(), self.pattern.as_ref())
        {
            let norm = |v: &[Dd]| v.iter().fold(0.0f64, |a, x| a.max(x.to_f64().abs()));
            let target = REFINED * norm(rhs);
            let mut x = vec![Dd::from(0.0); n];
            let mut r = rhs.to_vec();
            let mut nx = vec![Dd::from(0.0); n];
            let mut d = vec![0.0f64; n];
            let mut last = f64::INFINITY;
            for _ in 0..REFINEMENT_STEPS {
                for (di, ri) in d.iter_mut().zip(&r) {
                    *di = ri.to_f64();
                }
                spd.solve_in_place(&mut d);
                for (xi, &di) in x.iter_mut().zip(&d) {
                    *xi += Dd::from(di);
                }
                Self::multiply(pattern, &self.vals, &x, &mut nx);
                for i in 0..n {
                    r[i] = rhs[i] - nx[i];
                }
                let now = norm(&r);
                if now <= target {
                    rhs.copy_from_slice(&x);
                    return;
                }
                if now > 0.5 * last {
                    break;
                }
                last = now;
            }
            // stalled: the double factor is too far from the matrix; exact from now on
            if self.factor_exact().is_err() {
                rhs.copy_from_slice(&x);
                return;
            }
        }
        if let Some(e) = &mut self.exact {
            let mut wide: Vec<fx128> = rhs.iter().map(|&v| to_fx128(v)).collect();
            let m = faer::MatMut::from_column_major_slice_mut(&mut wide, n, 1);
            LltRef::new(&e.symbolic, &e.l).solve_in_place_with_conj(Conj::No, m, Par::Seq, MemStack::new(&mut e.mem));
            for (r, w) in rhs.iter_mut().zip(wide) {
                *r = from_fx128(w);
            }
        }
    }

    fn auxiliary(&self, x: &[Dd]) -> Option<Vec<f64>> {
        let mut t = vec![Dd::from(0.0); self.f.f.nrows()];
        self.auxiliary_into(x, &mut t);
        Some(t.iter().map(|t| t.to_f64()).collect())
    }
}

/// The factored objective for an iteration in double, for a QP with a data term: the gradient
/// `Fᵀ(F x + g) + d∘x + q_d` formed in double-double at the double iterate and rounded, the
/// normal matrix factorised and solved as [`Normal`] does, the direction rounded.
///
/// What the double-double form is for is the gradient: an assembled `P` of condition κ
/// evaluates it with errors of `10⁻¹⁶ κ |x|`, where this one is exact up to its rounding
/// (`10⁻¹⁶ |∇φ|`), and the gap bound squares that residual over the data diagonal. The
/// iterate itself loses nothing that matters in double (the objective at the rounded optimum
/// is `½ δᵀPδ` above it, `δ ≈ 10⁻¹⁶ |x|`: about `10⁻³² κ` of the data term), nor do the slacks.
/// The multipliers do, at large κ: they grow like `κ·d·|x|`, and in double `Aᵀz` is resolved to
/// `10⁻¹⁶ |z|` only, which floors `ρ = ∇φ + Aᵀz` and the bound's `½ Σ ρ²/d` (at κ = 10¹³ the
/// gap stalled at 3·10⁻³ of the data term): hence [`super::settings::DOUBLE_DOUBLE_ABOVE`].
/// Keeping everything in double-double below it made a series of 10⁶ samples cost 7× the
/// assembled form per iteration (issue 38's "conditioning cliff").
pub(super) struct Rounded<'r> {
    inner: Normal<'r>,
    x: Vec<Dd>,
    out: Vec<Dd>,
    w: Vec<Dd>,
}

impl<'r> Rounded<'r> {
    pub(super) fn new(inner: Normal<'r>, n: usize, m: usize) -> Rounded<'r> {
        let zero = Dd::from(0.0);
        Rounded { inner, x: vec![zero; n], out: vec![zero; n], w: vec![zero; m] }
    }
}

fn widen(from: &[f64], to: &mut [Dd]) {
    for (t, &f) in to.iter_mut().zip(from) {
        *t = Dd::from(f);
    }
}

fn round(from: &[Dd], to: &mut [f64]) {
    for (t, f) in to.iter_mut().zip(from) {
        *t = f.to_f64();
    }
}

impl Objective<f64> for Rounded<'_> {
    fn gradient(&mut self, x: &[f64], out: &mut [f64]) {
        widen(x, &mut self.x);
        self.inner.gradient(&self.x, &mut self.out);
        round(&self.out, out);
    }

    fn factor(&mut self, rows: &Rows, w: &[f64]) -> std::result::Result<(), crate::error::NumericalError> {
        widen(w, &mut self.w);
        self.inner.factor(rows, &self.w)
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        widen(rhs, &mut self.out);
        self.inner.solve_in_place(&mut self.out);
        round(&self.out, rhs);
    }

    fn auxiliary(&self, x: &[f64]) -> Option<Vec<f64>> {
        let x: Vec<Dd> = x.iter().map(|&v| Dd::from(v)).collect();
        self.inner.auxiliary(&x)
    }
}
