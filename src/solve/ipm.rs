//! A primal–dual interior-point method (Mehrotra predictor–corrector) that exploits the
//! structure of the reduced QP `min ½ xᵀPx + qᵀx` s.t. `Ax ≤ b`.
//!
//! Every row of A has one or two entries (an ordering constraint on an edge), so the normal
//! matrix `N = P + Aᵀ W A` (`W = diag(z/s)`) has the pattern of P plus the constrained pairs,
//! known before the first iteration. faer's sparse Cholesky analyses that pattern once
//! (ordering — nested dissection or AMD, whichever needs fewer flops, see `crate::linalg` —
//! elimination tree, supernodes) and only refactors the values at each iteration:
//! one factorisation and two to four solves per iteration, instead of an LDLᵀ of the full
//! `(n + m) × (n + m)` KKT system. Starting from the representative u (feasible for every
//! row) the iteration count stays low. It stops on the gap bound of [`super::optimality`]
//! against the data term; the factored form (ill-conditioned P) runs the same iteration in
//! double-double ([`super::factored`]). Whatever it returns, the certificate decides the
//! topology and the gap bound of the output as written decides the fit.

use super::banded::Banded;
use super::newton::{max, normal_band, Normal, Objective, Prepared, Real, Rows};
use super::problem::{ReducedQp, UpperP};
use super::settings::QpSettings;
use super::status::{Outcome, SolveStatus};
use crate::linalg as ordering;
use crate::parallel::{split_mut, split_mut2};
use faer::sparse::SparseColMatRef;
use std::borrow::Cow;

/// Centrality correctors per iteration at most: each costs one solve and saves iterations,
/// each a factorisation (docs/performance.md, "constants").
const CORRECTORS: usize = 2;
/// How much longer than the corrected predictor's step a corrector aims.
const CORRECTOR_STEP: f64 = 0.3;

/// `P` assembled; normal equations in double precision.
struct Assembled<'r> {
    r: &'r ReducedQp,
    factor: Factorised,
    /// `P` alone factorised, for [`Objective::energy_dual`] (made the first time it is asked).
    energy: Option<Energy>,
}

/// How the assembled normal matrix is stored and factorised.
enum Factorised {
    /// On its sparse pattern, by faer's Cholesky with the pattern's analysis.
    Spd { normal: Normal, analysis: std::sync::Arc<ordering::Analysis>, factor: ordering::SpdFactor, vals: Vec<f64> },
    /// A banded matrix (a series), assembled straight into its band and factorised by the
    /// band's own `LDLᵀ` ([`Banded`]: faer's simplicial factorisation and solves of a
    /// pentadiagonal matrix cost several times its n·b² products).
    Banded(Banded<f64>),
}

impl Factorised {
    /// Assembles `P + AᵀWA` (`w` empty: P alone) plus `reg` on the diagonal and factorises it;
    /// `false` if it is not numerically positive definite. Each entry sums P's triplets, then
    /// the rows' products, in their order, on either storage.
    fn assemble_and_factor(&mut self, r: &ReducedQp, rows: &Rows, w: &[f64], reg: f64) -> bool {
        match self {
            Factorised::Spd { normal, factor, vals, .. } => {
                fill_pattern(normal, vals, r, rows, w, reg);
                factor.factor(SparseColMatRef::new(normal.symbolic.as_ref(), vals)).is_ok()
            }
            Factorised::Banded(banded) => {
                fill_band(banded, r, rows, w, reg);
                banded.factor_band(0.0)
            }
        }
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        match self {
            Factorised::Spd { factor, .. } => factor.solve_in_place(rhs),
            Factorised::Banded(banded) => banded.solve_in_place(rhs),
        }
    }
}

impl Objective<f64> for Assembled<'_> {
    fn gradient(&mut self, x: &[f64], out: &mut [f64]) {
        out.iter_mut().zip(&self.r.q).for_each(|(o, q)| *o = *q);
        self.r.p.add_product(x, out);
    }

    /// With a growing diagonal shift if the matrix is not numerically positive definite.
    fn factor(&mut self, rows: &Rows, w: &[f64]) -> std::result::Result<(), crate::error::NumericalError> {
        let mut reg = 0.0;
        for attempt in 0..4 {
            if self.factor.assemble_and_factor(self.r, rows, w, reg) {
                return Ok(());
            }
            reg = if attempt == 0 { 1e-12 } else { reg * 1e3 };
        }
        Err("the normal matrix is not positive definite".into())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        self.factor.solve_in_place(rhs);
    }

    fn auxiliary(&self, _: &[f64]) -> Option<Vec<f64>> {
        None
    }

    fn energy_dual(&mut self, r: &[f64]) -> Option<f64> {
        if self.energy.is_none() {
            let no_rows = Rows::default();
            let energy = match &self.factor {
                Factorised::Spd { normal, analysis, .. } => {
                    let mut vals = vec![0.0; normal.symbolic.row_idx().len()];
                    fill_pattern(normal, &mut vals, self.r, &no_rows, &[], 0.0);
                    let mut f = ordering::SpdFactor::new(analysis.clone()).ok()?;
                    f.factor(SparseColMatRef::new(normal.symbolic.as_ref(), &vals)).ok()?;
                    Energy::Spd(f)
                }
                Factorised::Banded(b) => {
                    let mut e = Banded::of_band(self.r.n, b.width());
                    fill_band(&mut e, self.r, &no_rows, &[], 0.0);
                    if !e.factor_band(0.0) {
                        return None;
                    }
                    Energy::Banded(e)
                }
            };
            self.energy = Some(energy);
        }
        let mut y = r.to_vec();
        match self.energy.as_mut()? {
            Energy::Spd(f) => f.solve_in_place(&mut y),
            Energy::Banded(b) => b.solve_in_place(&mut y),
        }
        Some(0.5 * r.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>())
    }
}

/// `P` alone factorised, on the normal matrix's storage.
enum Energy {
    Spd(ordering::SpdFactor),
    Banded(Banded<f64>),
}

/// Fills `vals` on the normal matrix's pattern with `P + AᵀWA` plus `reg` on the diagonal: each
/// entry sums P's triplets, then the rows' products, in their order.
fn fill_pattern(normal: &Normal, vals: &mut [f64], r: &ReducedQp, rows: &Rows, w: &[f64], reg: f64) {
    vals.iter_mut().for_each(|v| *v = 0.0);
    for (k, (_, _, v)) in r.p.entries().enumerate() {
        vals[normal.pos_p[k]] += v;
    }
    // each row's entries are +1 and −1: `w a aᵀ` adds w on the diagonal, −w off it
    for (k, (&wk, &[p1, p2, p12])) in w.iter().zip(&normal.pos_row).enumerate() {
        vals[p1] += wk;
        if rows.is_pair(k) {
            vals[p2] += wk;
            vals[p12] -= wk;
        }
    }
    if reg > 0.0 {
        for &d in &normal.pos_diag {
            vals[d] += reg;
        }
    }
}

/// Fills `banded` with `P + AᵀWA` (`w` empty: P alone) plus `reg` on the diagonal: each entry
/// sums P's triplets, then the rows' products, in their order (as on a sparse pattern).
fn fill_band(banded: &mut Banded<f64>, r: &ReducedQp, rows: &Rows, w: &[f64], reg: f64) {
    let b = banded.width();
    let at = |i: usize, j: usize| Banded::<f64>::at(b, i.min(j), i.max(j));
    let band = banded.band_mut();
    match &r.p {
        // the same layout: each entry is 0 + its value, as summed from triplets
        UpperP::Band { width, values } if *width == b => band.copy_from_slice(values),
        p => {
            band.iter_mut().for_each(|v| *v = 0.0);
            for (i, j, v) in p.entries() {
                band[at(i, j)] += v;
            }
        }
    }
    for (k, &wk) in w.iter().enumerate() {
        let ([c1, c2], _, len) = rows.row(k);
        band[at(c1, c1)] += wk;
        if len == 2 {
            band[at(c2, c2)] += wk;
            band[at(c1, c2)] -= wk;
        }
    }
    if reg > 0.0 {
        for j in 0..r.n {
            band[at(j, j)] += reg;
        }
    }
}

/// The largest relative change of the iterate in one step at which the solver may stop (the
/// values are scaled to [0, 1]: 1e-5 of the range, ten default margins).
const STEP_TOLERANCE: f64 = 1e-5;
/// Iterations without a halving of the best gap bound after which the solver stops with
/// what it has (the bound has reached its rounding floor).
const STALL_ITERATIONS: u32 = 8;

/// The complementarity's share of the gap bound below which the bound sits on its rounding
/// floor (the dual residual's part, which further steps cannot lower): from there the best point
/// is kept, and returned if the steps break down or stall.
const FLOOR_COMPLEMENTARITY: f64 = 1e-2;

/// The growth of the gap bound over the best point kept that counts as a breakdown.
const BREAKDOWN_GROWTH: f64 = 1e3;
/// Coordinate-descent sweeps over the multipliers per iteration (20 and 100 gave the same
/// bound as 5 on the 300² benchmark grid, each about 5 × below the solver's own; 2 instead of
/// 5 gave the same iterations on every case measured, bounds within 1–6 %, and a 10⁷-sample
/// series' solve 38.7 → 33.2 s: docs/performance.md, "constants").
const POLISH_SWEEPS: usize = 2;

/// Solves the reduced QP; `Err(reason)` when it cannot (the caller falls back to Clarabel).
///
/// Stops when the rows are met to `settings.tolerance`, the last step moved no value by more
/// than [`STEP_TOLERANCE`], and — with a data term — the gap bound
/// `Ĝ = Σ max(s, 0) z + ½ Σ ρ²/d` (s = b − Ax, ρ = ∇φ + Aᵀz, d the data diagonal: P ⪰
/// diag(d)), with the multipliers polished for the point, is below `settings.gap_tolerance` ×
/// the data term; without one, when `sᵀz + ½ρᵀP⁻¹ρ` (P factorised alone) is below it × the
/// energy, or — where P alone cannot be factorised — when the mean complementarity is 10×
/// below the feasibility tolerance. The factored form forms its gradient in double-double, and
/// keeps the whole iteration in it above [`super::settings::DOUBLE_DOUBLE_ABOVE`].
///
/// The normal matrix's analysis comes from `analyses` (and is kept there for the next solve
/// on the same pattern); `prepared`, made in advance, is kept there first.
pub(super) fn solve(
    r: &ReducedQp,
    assembly: Option<Assembly>,
    hint: Option<Vec<f64>>,
    settings: &QpSettings,
    analyses: &mut ordering::Analyses,
    prepared: Option<Prepared>,
) -> std::result::Result<Outcome, crate::error::NumericalError> {
    let spare = prepared.and_then(|p| p.keep_in(analyses));
    match &r.factor {
        Some(factor) => {
            drop(spare);
            let rows = &r.rows;
            let objective = super::factored::Normal::new(r, factor)?;
            if factor.double_iteration {
                let mut objective = super::factored::Rounded::new(objective, r.n, r.m());
                run::<f64, _>(r, rows, &mut objective, hint, settings)
            } else {
                let mut objective = objective;
                run::<crate::linalg::double_double::Dd, _>(r, rows, &mut objective, hint, settings)
            }
        }
        None => {
            let Assembly { normal } = match assembly {
                Some(assembly) => assembly,
                None => Assembly::new(r)?,
            };
            let factor = match normal {
                // a banded pattern (a series) needs no analysis (faer's symbolic factorisation of
                // 10⁷ samples took seconds and 300 MB)
                NormalForm::Band(b) => Factorised::Banded(Banded::of_band(r.n, b)),
                NormalForm::Pattern(normal) => {
                    let analysis = analyses.of(normal.symbolic.as_ref())?;
                    let spare = spare.filter(|(a, _)| std::sync::Arc::ptr_eq(a, &analysis));
                    let factor = match spare {
                        Some((_, workspace)) => ordering::SpdFactor::with_workspace(analysis.clone(), workspace),
                        None => ordering::SpdFactor::new(analysis.clone())?,
                    };
                    let vals = vec![0.0f64; normal.symbolic.row_idx().len()];
                    Factorised::Spd { normal, analysis, factor, vals }
                }
            };
            let mut objective = Assembled { r, factor, energy: None };
            run::<f64, _>(r, &r.rows, &mut objective, hint, settings)
        }
    }
}

/// The assembled normal matrix's storage plan: its sparse pattern, or the half-width of its
/// band.
enum NormalForm {
    Pattern(Normal),
    Band(usize),
}

/// The assembled form's normal-matrix form, made once for both the memory prediction and the
/// solve (at 10⁷ samples of a series its pattern took seconds).
pub(super) struct Assembly {
    normal: NormalForm,
}

impl Assembly {
    fn new(r: &ReducedQp) -> std::result::Result<Assembly, crate::error::NumericalError> {
        let rows = &r.rows;
        if rows.len() != r.m() {
            return Err("the reduced QP was made without its rows".into());
        }
        let normal = match normal_band(r, rows) {
            Some(b) => NormalForm::Band(b),
            None => NormalForm::Pattern(Normal::new(r, rows)),
        };
        Ok(Assembly { normal })
    }
}

/// The bytes the structured solver allocates for `r` (the assembled form) beyond what the
/// caller holds, known before it allocates them: the normal matrix's factor and faer's
/// scratch (from its analysis, made here and kept in `analyses`, where [`solve`] takes it; a
/// banded matrix's own factor from its band, with no analysis and no pattern),
/// the normal matrix's values and pattern, the rows, and the iterate's vectors; with the rows
/// and the pattern made for it, which [`solve`] takes. `None` for the factored form, whose
/// double-double storage is not predicted yet.
///
/// # Errors
/// A message if the analysis fails.
pub(super) fn predicted_bytes(
    r: &ReducedQp,
    analyses: &mut ordering::Analyses,
) -> std::result::Result<Option<(u64, Assembly)>, crate::error::NumericalError> {
    if r.factor.is_some() {
        return Ok(None);
    }
    let assembly = Assembly::new(r)?;
    let (n, m) = (r.n as u64, r.m() as u64);
    // about 14 vectors of n and 18 of m in the iteration (the rows are the reduced QP's), one
    // of each more for the best point on the gap bound's rounding floor
    let vectors = 8 * (15 * n + 19 * m);
    let matrix_bytes = match &assembly.normal {
        // the band's own LDLᵀ: the band, L and 1/D (n·(b + 1), n·b and n values)
        NormalForm::Band(b) => 8 * n * (2 * *b as u64 + 2),
        NormalForm::Pattern(normal) => {
            // values and row indices of the normal matrix, its position tables
            let nnz = normal.symbolic.row_idx().len() as u64;
            16 * nnz
                + 8 * (n + 1)
                + 8 * (r.p.len() as u64 + 4 * m + n)
                + analyses.of(normal.symbolic.as_ref())?.numeric_bytes()
        }
    };
    Ok(Some((matrix_bytes + vectors, assembly)))
}

/// The primal–dual iterate: `x`, the slacks `s = b − Ax` and the multipliers `z`.
struct Iterate<T> {
    x: Vec<T>,
    s: Vec<T>,
    z: Vec<T>,
}

/// The starting point from `x`: slacks of x (shifted to be positive), multipliers at the scale
/// of the objective's gradient, which they must balance (each row of A has entries ±1): 3 ×
/// mean |P x + q| (unit multipliers took about twice the iterations, docs/performance.md,
/// "constants"), then both balanced.
fn starting_point<T: Real, O: Objective<T>>(rows: &Rows, objective: &mut O, x: Vec<T>, b: &[T]) -> Iterate<T> {
    let (n, m) = (x.len(), b.len());
    let (zero, of) = (T::of(0.0), T::of);
    let mut s = vec![zero; m];
    rows.ax(&x, &mut s);
    for (sk, bk) in s.iter_mut().zip(b) {
        *sk = *bk - *sk;
    }
    let mut g = vec![zero; n];
    objective.gradient(&x, &mut g);
    let gmean = g.iter().map(|a| a.to_f64().abs()).sum::<f64>() / n.max(1) as f64;
    let path = path_multiplier_scale(rows, &g).map_or(0.0, |y| PATH_MULTIPLIER_SHARE * y);
    let z0 = (3.0 * gmean).max(path).max(1e-12);
    let mut z = vec![of(z0); m];
    let smin = s.iter().map(|v| v.to_f64()).fold(f64::INFINITY, f64::min);
    if smin <= 0.0 {
        s.iter_mut().for_each(|v| *v += of(-1.5 * smin + 1e-3));
    }
    let sz: f64 = s.iter().zip(&z).map(|(a, b)| (*a * *b).to_f64()).sum();
    let (ssum, zsum): (f64, f64) = (s.iter().map(|v| v.to_f64()).sum(), z.iter().map(|v| v.to_f64()).sum());
    s.iter_mut().for_each(|v| *v += of(0.5 * sz / zsum));
    z.iter_mut().for_each(|v| *v += of(0.5 * sz / ssum));
    Iterate { x, s, z }
}

/// The share of [`path_multiplier_scale`] the starting multipliers take at least. A walk of
/// 10⁷ samples at a smoothing length of 20 samples has multipliers at its optimum 30 × the mean
/// gradient at u (the sums of the gradient over terraces thousands of samples long), where
/// 3 × took 19 iterations, 10 steps below 0.3 at first; from 0.03, 0.1 and 0.3 of the scale
/// (0.3 × = 130 × the mean gradient) 14, 12 and 12. On the bench series, EUR/USD, a 10⁶ walk
/// and a tie-heavy sensor series the scale × 0.1 is below 0.06 × the mean gradient and changes
/// nothing (docs/performance.md, "constants").
const PATH_MULTIPLIER_SHARE: f64 = 0.1;

/// On a path (every row with two ends joins consecutive variables: a series), the mean size of
/// the multipliers that balance the gradient `g` at the start on their own: along each run of
/// variables joined by rows, stationarity makes the multiplier of the row after variable `i`
/// the gradient summed over the run up to `i` plus a constant, taken here as the one that
/// centres the sums (the run's end rows to fixed neighbours take up the rest). `None` off a
/// path.
fn path_multiplier_scale<T: Real>(rows: &Rows, g: &[T]) -> Option<f64> {
    let n = g.len();
    // per variable, whether a row joins it to the next one
    let mut joined = vec![false; n];
    for (a, b) in rows.pairs() {
        if a.abs_diff(b) != 1 {
            return None;
        }
        joined[a.min(b)] = true;
    }
    let (mut total, mut count) = (0.0, 0usize);
    let mut run: Vec<f64> = Vec::new();
    let mut centre = |run: &mut Vec<f64>| {
        let mean = run.iter().sum::<f64>() / run.len().max(1) as f64;
        total += run.iter().map(|y| (y - mean).abs()).sum::<f64>();
        count += run.len();
        run.clear();
    };
    let mut sum = 0.0;
    for (i, &joined) in joined.iter().enumerate() {
        sum += g[i].to_f64();
        if joined {
            run.push(sum);
        } else {
            centre(&mut run);
            sum = 0.0;
        }
    }
    centre(&mut run);
    (count > 0).then(|| total / count as f64)
}

/// The residuals of an iterate: dual `rd = ∇φ + Aᵀz`, primal `rp = Ax + s − b`, the true
/// slacks `b − Ax`, and their scaled norms.
struct Residuals<T> {
    rd: Vec<T>,
    rp: Vec<T>,
    slack: Vec<T>,
    /// Mean complementarity `sᵀz / m`, in `T` and in double.
    mu_t: T,
    mu: f64,
    /// Largest primal residual ÷ (1 + |b|∞), largest dual residual ÷ (1 + |q|∞).
    pres: f64,
    dres: f64,
    /// Without a data term: the objective `φ(x) = ½ xᵀ(∇φ + q)` (up to the fixed part's constant).
    phi: f64,
}

/// What the stopping test decided.
enum Verdict {
    /// Stop with this status, reporting the polished multipliers (with a data term) or `z`.
    Stop(SolveStatus),
    /// Go on; if the next factorisation fails, stop with this status (the point reached
    /// already meets the targets except for the step: z/s beyond 10¹⁶ × the data diagonal
    /// cancels in double precision once the gap is tiny), or fail when `None`.
    Go(Option<SolveStatus>),
}

/// Where the stopping test is: the iterate, its residuals, whether the last step was small,
/// the iteration.
struct At<'a, T> {
    it: &'a Iterate<T>,
    res: &'a Residuals<T>,
    small_step: bool,
    iteration: u32,
}

impl<T> Clone for At<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for At<'_, T> {}

/// The gap bound's history: the best value and the iteration it was reached, for the stall test.
struct Progress {
    best_gap: f64,
    best_at: u32,
    /// The last test's gap bound and its target.
    gap: f64,
    target: f64,
    /// Whether the last bound sat on its rounding floor (see [`FLOOR_COMPLEMENTARITY`]).
    on_floor: bool,
    /// The first gap (relative to its target's base): where the reported fraction starts.
    first: Option<f64>,
}

impl Progress {
    /// Tells the observer how far the relative gap `gap` is from the first towards `target`.
    fn tell(&mut self, gap: f64, target: f64) {
        if gap.is_finite() {
            let first = *self.first.get_or_insert(gap);
            crate::progress::fraction("solve", crate::progress::log_fraction(first, gap, target));
        }
    }
}

/// The constants of the stopping tests.
struct Targets<'r, T: Clone> {
    tol: f64,
    /// Without a data term: the mean complementarity 10× below the feasibility tolerance (the
    /// objective is flat along many directions; with the correctors μ ≤ tol was reached while
    /// sᵀz was still 5× larger than without them).
    tol_mu: f64,
    gap_tolerance: f64,
    d: Cow<'r, [T]>,
    /// `1 / d`, for [`Real::div_by`] (`d` itself where it uses none).
    inv_d: Cow<'r, [T]>,
    q_free: Cow<'r, [T]>,
    d_sum: f64,
}

/// The best point on the gap bound's rounding floor: `x`, its polished multipliers, its bound
/// and the bound's target.
struct BestPoint<T> {
    x: Vec<T>,
    z: Vec<T>,
    gap: f64,
    target: f64,
}

impl<T> BestPoint<T> {
    /// The status of stopping with this point: as the stopping test would give it, else
    /// stalled, its bound reported as it is.
    fn status(&self) -> SolveStatus {
        status_within(self.gap, self.target).unwrap_or(SolveStatus::Stalled)
    }
}

/// The status a point with gap bound `gap` (its rows met) may stop with: solved within the
/// target, almost within 100 × it.
fn status_within(gap: f64, target: f64) -> Option<SolveStatus> {
    if gap <= target {
        Some(SolveStatus::Solved)
    } else if gap <= 1e2 * target {
        Some(SolveStatus::AlmostSolved)
    } else {
        None
    }
}

/// The interior-point iteration in arithmetic `T`.
#[allow(clippy::needless_range_loop)] // parallel arrays indexed together
fn run<T: Real, O: Objective<T>>(
    r: &ReducedQp,
    rows: &Rows,
    objective: &mut O,
    hint: Option<Vec<f64>>,
    settings: &QpSettings,
) -> std::result::Result<Outcome, crate::error::NumericalError> {
    let (n, m) = (r.n, r.m());
    let zero = T::of(0.0);
    let of = T::of;
    let b = T::lift(&r.b);
    let x: Vec<T> = match hint {
        Some(h) => T::lift_vec(h),
        None => vec![zero; n],
    };
    let finish = |x: &[T], z: &[T], status: SolveStatus, iterations: u32, objective: &O| Outcome {
        x: x.iter().map(|v| v.to_f64()).collect(),
        z: z.iter().map(|v| v.to_f64()).collect(),
        y: objective.auxiliary(x),
        status,
        iterations,
    };
    if m == 0 {
        let mut x = x;
        objective.factor(rows, &[])?;
        let mut rhs = vec![zero; n];
        objective.gradient(&x, &mut rhs);
        rhs.iter_mut().for_each(|v| *v = -*v);
        objective.solve_in_place(&mut rhs);
        for i in 0..n {
            x[i] += rhs[i];
        }
        return Ok(finish(&x, &[], SolveStatus::Solved, 1, objective));
    }
    let mut point = starting_point(rows, objective, x, &b);
    let bnorm = 1.0 + r.b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let qnorm = 1.0 + r.q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let targets = Targets {
        tol: settings.tolerance,
        tol_mu: 0.1 * settings.tolerance,
        gap_tolerance: settings.gap_tolerance,
        d: T::lift(&r.d),
        inv_d: if T::RECIPROCALS { Cow::Owned(r.d.iter().map(|&v| of(1.0) / of(v)).collect()) } else { T::lift(&r.d) },
        q_free: T::lift(&r.q_free),
        d_sum: r.d.iter().sum(),
    };
    let mut res = Residuals {
        rd: vec![zero; n],
        rp: vec![zero; m],
        slack: vec![zero; m],
        mu_t: zero,
        mu: 0.0,
        pres: 0.0,
        dres: 0.0,
        phi: 0.0,
    };
    let mut w = vec![zero; m];
    // the slacks' reciprocals only where the arithmetic uses them
    let (one, mut inv_s) = (of(1.0), if T::RECIPROCALS { vec![zero; m] } else { Vec::new() });
    // the correctors' second direction is free between two steps: the residuals' scratch and
    // the polished multipliers with their ρ live there (at 10⁷ rows, 0.24 GB not allocated)
    let mut newton = Newton::new(n, m);
    let mut last = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut last_step = f64::INFINITY;
    let mut progress =
        Progress { best_gap: f64::INFINITY, best_at: 0, gap: f64::INFINITY, target: 0.0, on_floor: false, first: None };
    // the barrier weights `z / s`, with the slacks' reciprocals where the arithmetic uses them
    let weights = |point: &Iterate<T>, w: &mut [T], inv_s: &mut [T]| {
        let (s, z) = (&point.s, &point.z);
        if T::RECIPROCALS {
            split_mut2(w, inv_s, |offset, w, inv_s| {
                for (j, k) in (offset..offset + w.len()).enumerate() {
                    inv_s[j] = one / s[k];
                    w[j] = z[k].div_by(s[k], inv_s[j]);
                }
            });
        } else {
            split_mut(w, |offset, w| {
                for (wk, k) in w.iter_mut().zip(offset..) {
                    *wk = z[k].div_by(s[k], s[k]);
                }
            });
        }
    };
    // whether the last step was onto the rows (see [`Newton::onto_rows`]), and how many rows
    // may stay short of their margin without one
    let mut corrected = false;
    let short_rows = SHORT_ROWS + m / SHORT_ROWS_PER;
    // the best point on the bound's rounding floor, made when the floor is first reached
    let mut best: Option<BestPoint<T>> = None;
    for it in 0..settings.max_iter {
        if crate::progress::cancelled() {
            return Err(crate::error::NumericalError(format!("cancelled at iteration {it}")));
        }
        residuals(r, rows, objective, &point, &b, (bnorm, qnorm), &mut res, &mut newton.dx2);
        last = (res.pres, res.dres, res.mu);
        if !(res.pres.is_finite() && res.dres.is_finite() && res.mu.is_finite()) {
            if let Some(b) = &best {
                return Ok(finish(&b.x, &b.z, b.status(), it, objective));
            }
            return Err(crate::error::NumericalError(format!("non-finite iterate at iteration {it}")));
        }
        let xmax = point.x.iter().fold(0.0f64, |a, v| a.max(v.to_f64().abs()));
        let small_step = last_step <= STEP_TOLERANCE * (1.0 + xmax);
        let at = At { it: &point, res: &res, small_step, iteration: it };
        let (verdict, reported_z) = if r.gap_bound {
            verdict_with_data(rows, &at, &targets, &mut progress, (&mut newton.dz2, &mut newton.dx2))
        } else {
            (verdict_without_data(r, objective, &at, &targets, &mut progress), None)
        };
        let fallback_status = match verdict {
            Verdict::Stop(status) if corrected || res.slack.iter().filter(|v| **v < zero).count() <= short_rows => {
                return Ok(finish(&point.x, reported_z.unwrap_or(&point.z), status, it, objective))
            }
            Verdict::Stop(status) => {
                // rows met only to the tolerance: one step onto them, or this point as it is
                corrected = true;
                weights(&point, &mut w, &mut inv_s);
                if objective.factor(rows, &w).is_err() {
                    return Ok(finish(&point.x, &newton.dz2, status, it, objective));
                }
                newton.onto_rows(rows, objective, &res.rp, &w);
                last_step = newton.advance_onto_rows(&mut point);
                continue;
            }
            Verdict::Go(fallback) => {
                if progress.on_floor && best.as_ref().is_none_or(|b| progress.gap < b.gap) {
                    let b = best.get_or_insert_with(|| BestPoint {
                        x: vec![zero; n],
                        z: vec![zero; m],
                        gap: f64::INFINITY,
                        target: 0.0,
                    });
                    b.x.copy_from_slice(&point.x);
                    b.z.copy_from_slice(&newton.dz2);
                    (b.gap, b.target) = (progress.gap, progress.target);
                }
                // past the best point on the floor: broken down (weights z/s past what the
                // arithmetic resolves), or no better for as long as the stall test waits
                if let Some(b) = &best {
                    if progress.gap > BREAKDOWN_GROWTH * b.gap || it >= progress.best_at + STALL_ITERATIONS {
                        return Ok(finish(&b.x, &b.z, b.status(), it, objective));
                    }
                }
                fallback
            }
        };
        weights(&point, &mut w, &mut inv_s);
        if let Err(e) = objective.factor(rows, &w) {
            return match (fallback_status, &best) {
                (Some(status), _) => Ok(finish(&point.x, &point.z, status, it, objective)),
                (None, Some(b)) => Ok(finish(&b.x, &b.z, b.status(), it, objective)),
                (None, None) => Err(e),
            };
        }
        let inv = if T::RECIPROCALS { &inv_s[..] } else { &point.s[..] };
        let alpha = newton.step(rows, objective, &point, &res, (&w, inv));
        if alpha < 1e-12 {
            if let Some(b) = &best {
                return Ok(finish(&b.x, &b.z, b.status(), it, objective));
            }
            return Err(crate::error::NumericalError(format!("step length {alpha:e} at iteration {it}")));
        }
        last_step = newton.advance(&mut point, alpha);
    }
    if let Some(b) = &best {
        return Ok(finish(&b.x, &b.z, b.status(), settings.max_iter, objective));
    }
    let (pres, dres, mu) = last;
    let tol = targets.tol;
    if pres <= 1e3 * tol && (r.gap_bound || (dres <= 1e3 * tol && mu <= 1e3 * tol)) {
        return Ok(finish(&point.x, &point.z, SolveStatus::AlmostSolved, settings.max_iter, objective));
    }
    Err(crate::error::NumericalError(format!(
        "no convergence in {} iterations (primal {pres:.1e}, dual {dres:.1e}, gap {mu:.1e})",
        settings.max_iter
    )))
}

/// Computes the residuals of `it` into `res`.
#[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
fn residuals<T: Real, O: Objective<T>>(
    r: &ReducedQp,
    rows: &Rows,
    objective: &mut O,
    it: &Iterate<T>,
    b: &[T],
    (bnorm, qnorm): (f64, f64),
    res: &mut Residuals<T>,
    tmp_n: &mut [T],
) {
    let m = it.s.len();
    let (zero, of) = (T::of(0.0), T::of);
    let x = &it.x;
    objective.gradient(x, &mut res.rd);
    res.phi = if r.gap_bound {
        0.0
    } else {
        0.5 * x.iter().zip(res.rd.iter().zip(&r.q)).map(|(x, (g, q))| (*x * (*g + of(*q))).to_f64()).sum::<f64>()
    };
    rows.atz(&it.z, tmp_n);
    let tmp_n = &*tmp_n;
    split_mut(&mut res.rd, |offset, rd| {
        for (r, i) in rd.iter_mut().zip(offset..) {
            *r += tmp_n[i];
        }
    });
    rows.ax(x, &mut res.slack);
    let s = &it.s;
    split_mut2(&mut res.rp, &mut res.slack, |offset, rp, slack| {
        for (j, k) in (offset..offset + rp.len()).enumerate() {
            rp[j] = slack[j] + s[k] - b[k];
            slack[j] = b[k] - slack[j];
        }
    });
    res.mu_t = it.s.iter().zip(&it.z).fold(zero, |a, (&s, &z)| a + s * z) / of(m as f64);
    res.mu = res.mu_t.to_f64();
    res.pres = res.rp.iter().fold(0.0f64, |a, v| a.max(v.to_f64().abs())) / bnorm;
    res.dres = res.rd.iter().fold(0.0f64, |a, v| a.max(v.to_f64().abs())) / qnorm;
}

/// The stopping test with a data term: the gap bound `Ĝ = Σ max(s, 0) z + ½ Σ ρ²/d` with the
/// multipliers polished for the point (coordinate descent on the bound: the interior z of rows
/// far from active still carries complementarity the point no longer needs; about one
/// iteration less on the benchmark grids) against the data term. Returns the verdict and the
/// polished multipliers, reported when it stops.
fn verdict_with_data<'s, T: Real>(
    rows: &Rows,
    at: &At<'_, T>,
    t: &Targets<T>,
    progress: &mut Progress,
    (polished, rho): (&'s mut [T], &mut [T]),
) -> (Verdict, Option<&'s [T]>) {
    let At { it, res, small_step, iteration } = *at;
    let (zero, of) = (T::of(0.0), T::of);
    let (x, z, d, inv_d) = (&it.x, &it.z, &t.d, &t.inv_d);
    let pres = res.pres;
    let comp = res.slack.iter().zip(z).fold(zero, |a, (&s, &z)| a + max(s, zero) * z);
    let stat = (0..x.len()).fold(zero, |a, i| a + (res.rd[i] * res.rd[i]).div_by(d[i], inv_d[i]));
    let gap = (comp + of(0.5) * stat).to_f64();
    let data = (0..x.len()).fold(zero, |a, i| {
        let e = d[i] * x[i] + t.q_free[i];
        a + (e * e).div_by(d[i], inv_d[i])
    });
    let data = (0.5 * data.to_f64()).max(1e-20 * t.d_sum);
    // the polished multipliers and their ρ in storage kept across iterations (at 10⁷ rows two
    // fresh vectors an iteration were seconds of page faults)
    polished.copy_from_slice(z);
    let gap = if pres <= t.tol {
        rho.copy_from_slice(&res.rd);
        gap.min(polish_multipliers(rows, &res.slack, (d, inv_d), rho, polished, POLISH_SWEEPS).to_f64())
    } else {
        gap
    };
    let target = t.gap_tolerance * data;
    (progress.gap, progress.target) = (gap, target);
    progress.on_floor = pres <= t.tol && comp.to_f64() <= FLOOR_COMPLEMENTARITY * gap;
    crate::progress::update("solve", || {
        format!(
            "iteration {iteration}: gap {:.1e} of the data (target {:.0e}), primal residual {pres:.1e}",
            gap / data,
            t.gap_tolerance
        )
    });
    progress.tell(gap / data, t.gap_tolerance);
    if pres <= t.tol && small_step && gap <= target {
        return (Verdict::Stop(SolveStatus::Solved), Some(&*polished));
    }
    let fallback = if pres > t.tol { None } else { status_within(gap, target) };
    if gap < 0.5 * progress.best_gap {
        (progress.best_gap, progress.best_at) = (gap, iteration);
    } else if pres <= t.tol && iteration >= progress.best_at + STALL_ITERATIONS && gap <= 1e2 * target {
        // the bound has reached its rounding floor, within 100× the target
        return (Verdict::Stop(SolveStatus::AlmostSolved), Some(&*polished));
    }
    (Verdict::Go(fallback), None)
}

/// The stopping test without a data term: the gap `sᵀz + ½ ρᵀP⁻¹ρ` against the energy
/// `½ fᵀQf` (P factorised once, and solved with only once the rows are met, where it can
/// decide), or, where P cannot be solved alone, the mean complementarity.
fn verdict_without_data<T: Real, O: Objective<T>>(
    r: &ReducedQp,
    objective: &mut O,
    at: &At<'_, T>,
    t: &Targets<T>,
    progress: &mut Progress,
) -> Verdict {
    let At { it, res, small_step, iteration } = *at;
    let zero = T::of(0.0);
    let (pres, dres, mu) = (res.pres, res.dres, res.mu);
    let energy = res.phi + r.constant;
    let gap = (pres <= t.tol)
        .then(|| objective.energy_dual(&res.rd))
        .flatten()
        .map(|dual| res.slack.iter().zip(&it.z).map(|(s, z)| (max(*s, zero) * *z).to_f64()).sum::<f64>() + dual);
    let target = t.gap_tolerance * energy.abs().max(1e-300);
    crate::progress::update("solve", || match gap {
        Some(gap) => format!(
            "iteration {iteration}: gap {:.1e} of the energy (target {:.0e}), primal residual {pres:.1e}",
            gap / energy.abs().max(1e-300),
            t.gap_tolerance
        ),
        None => format!("iteration {iteration}: primal residual {pres:.1e}, complementarity {mu:.1e}"),
    });
    if let Some(gap) = gap {
        progress.tell(gap / energy.abs().max(1e-300), t.gap_tolerance);
    }
    let converged = match gap {
        Some(gap) => pres <= t.tol && small_step && gap <= target,
        None => pres <= t.tol && dres <= t.tol && mu <= t.tol_mu,
    };
    if converged {
        return Verdict::Stop(SolveStatus::Solved);
    }
    // the rows met and the complementarity gone: the dual part ½ρᵀP⁻¹ρ of the bound can sit on
    // the rounding floor of ρ amplified by P⁻¹ (k = 4: Ĝ ÷ energy ≈ 10⁻⁴ with μ ≈ 10⁻²⁵), and the
    // next factorisation can fail there; the point is kept rather than handed to another solver
    let settled = pres <= t.tol && mu <= t.tol_mu;
    if let Some(gap) = gap {
        if gap < 0.5 * progress.best_gap {
            (progress.best_gap, progress.best_at) = (gap, iteration);
        } else if settled && iteration >= progress.best_at + STALL_ITERATIONS {
            return Verdict::Stop(SolveStatus::AlmostSolved);
        }
    }
    Verdict::Go(settled.then_some(SolveStatus::AlmostSolved))
}

/// The Newton step's storage: the direction `(dx, ds, dz)` for the complementarity target
/// `rc`, and a second one for the centrality correctors.
struct Newton<T> {
    dx: Vec<T>,
    ds: Vec<T>,
    dz: Vec<T>,
    rc: Vec<T>,
    dx2: Vec<T>,
    ds2: Vec<T>,
    dz2: Vec<T>,
    rc2: Vec<T>,
    tmp_m: Vec<T>,
}

/// The largest step in `[0, 1]` along `d` that keeps `v` non-negative.
fn max_step<T: Real>(v: &[T], d: &[T]) -> f64 {
    let zero = T::of(0.0);
    v.iter().zip(d).fold(1.0f64, |a, (&v, &d)| if d < zero { a.min(-v.to_f64() / d.to_f64()) } else { a })
}

/// A stopping point with more rows than `SHORT_ROWS + m / SHORT_ROWS_PER` short of their
/// margin (true slack `b − Ax` negative: the rows are met to the tolerance only) takes one step
/// onto the rows first ([`Newton::onto_rows`]). At the stop, the Kármán street had 1,492 rows
/// short by up to 8.6·10⁻¹² (of the unit range) and the walk of 10⁷ samples 1.5 million by
/// up to 1.6·10⁻¹²: the margin repair then moved 2,008 and 2.2 million vertices and the
/// output's gap bound grew 4.5·10⁻⁸ → 3.0·10⁻⁷ and 1.3·10⁻⁷ → 2.3·10⁻⁶ of the data term; with
/// the step, nothing moves and the bounds are 2.1·10⁻⁷ and 4.3·10⁻⁸. A handful of short rows
/// (mountain 4 by 4·10⁻¹⁴, spot @1 7 by 7·10⁻¹³) move a few vertices by a rounding and leave
/// the bound as it is: not worth a factorisation.
const SHORT_ROWS: usize = 16;
/// See [`SHORT_ROWS`].
const SHORT_ROWS_PER: usize = 1000;

/// The share of the rows whose slack or multiplier may cross zero at the predictor's step
/// that sets the centring (Mehrotra's `σ = (μ_aff / μ)³`).
///
/// The largest step keeping every component positive is held to 0.1–0.6 on the grids by one to
/// five rows out of 10⁵–10⁶ (the flooded representative's 1000² bench: 46 iterations, most
/// with σ of 0.1–0.6); the step at which 1 % of the rows cross aims the corrector at a small
/// σμ, which its own step (to the boundary) and the centrality correctors then approach:
/// 1000² 46 → 33 iterations, 300² 25 → 20, 150 × 100 18 → 14, the Kármán street 26 → 23, the
/// 10⁶-sample series 11 → 10, spot 7 → 6 (docs/performance.md, "constants").
const PREDICTOR_CROSSING: f64 = 1e-2;

/// Buckets of the predictor's step: the top 7 mantissa bits of each binade between 2⁻²⁷ and
/// 1 (relative resolution below 1 %).
const STEP_BUCKET_SHIFT: u32 = 45;
const STEP_BUCKET_FLOOR: f64 = 1.0 / 134_217_728.0; // 2⁻²⁷

/// The predictor's step for the centring: the largest `α ≤ 1` (to the resolution of
/// [`STEP_BUCKET_SHIFT`]) at which at most [`PREDICTOR_CROSSING`] × m of the components of
/// `s + α ds` and `z + α dz` are negative. A histogram of the steps to zero, no sort and no
/// storage per row.
fn predictor_step<T: Real>(s: &[T], ds: &[T], z: &[T], dz: &[T]) -> f64 {
    let base = STEP_BUCKET_FLOOR.to_bits() >> STEP_BUCKET_SHIFT;
    let buckets = ((1.0f64.to_bits() >> STEP_BUCKET_SHIFT) - base) as usize;
    let mut count = vec![0u32; buckets + 1];
    let zero = T::of(0.0);
    for (v, d) in s.iter().zip(ds).chain(z.iter().zip(dz)) {
        if *d < zero {
            let ratio = -v.to_f64() / d.to_f64();
            if ratio < 1.0 {
                let key = (ratio.to_bits() >> STEP_BUCKET_SHIFT).saturating_sub(base) as usize;
                count[key.min(buckets)] += 1;
            }
        }
    }
    let allowed = (PREDICTOR_CROSSING * s.len() as f64) as u64;
    let mut crossed = 0u64;
    for (key, &c) in count.iter().enumerate() {
        crossed += u64::from(c);
        if crossed > allowed {
            return if key == 0 { 0.0 } else { f64::from_bits((key as u64 + base) << STEP_BUCKET_SHIFT) };
        }
    }
    1.0
}

impl<T: Real> Newton<T> {
    fn new(n: usize, m: usize) -> Self {
        let zero = T::of(0.0);
        let (vn, vm) = (|| vec![zero; n], || vec![zero; m]);
        Newton { dx: vn(), ds: vm(), dz: vm(), rc: vm(), dx2: vn(), ds2: vm(), dz2: vm(), rc2: vm(), tmp_m: vm() }
    }

    /// Mehrotra's predictor and corrector, then Gondzio's multiple centrality correctors (aim
    /// at a longer step, push the complementarity products of that trial point back into
    /// [0.1, 10] × σμ and keep the corrected direction if its step grows; one solve each, no
    /// factorisation). Returns the step length; the direction is in `dx`, `ds`, `dz`.
    #[allow(clippy::needless_range_loop)] // parallel arrays indexed together
    fn step<O: Objective<T>>(
        &mut self,
        rows: &Rows,
        objective: &mut O,
        it: &Iterate<T>,
        res: &Residuals<T>,
        (w, inv_s): (&[T], &[T]),
    ) -> f64 {
        let (zero, of) = (T::of(0.0), T::of);
        let m = it.s.len();
        let (s, z) = (&it.s, &it.z);
        let tmp_m = &mut self.tmp_m;
        // one Newton direction for complementarity target rc (s∘z − rc → 0)
        let (rp, rd) = (&res.rp, &res.rd);
        let mut direction = |rc: &[T], dx: &mut Vec<T>, ds: &mut Vec<T>, dz: &mut Vec<T>| {
            split_mut(tmp_m, |offset, tmp| {
                for (t, k) in tmp.iter_mut().zip(offset..) {
                    *t = w[k] * rp[k] - rc[k].div_by(s[k], inv_s[k]);
                }
            });
            rows.atz(tmp_m, dx);
            split_mut(dx, |offset, dx| {
                for (d, i) in dx.iter_mut().zip(offset..) {
                    *d = -rd[i] - *d;
                }
            });
            objective.solve_in_place(dx);
            rows.ax(dx, ds);
            split_mut2(dz, ds, |offset, dz, ds| {
                for (j, k) in (offset..offset + dz.len()).enumerate() {
                    let adx = ds[j];
                    dz[j] = w[k] * (adx + rp[k]) - rc[k].div_by(s[k], inv_s[k]);
                    ds[j] = -rp[k] - adx;
                }
            });
        };
        // predictor
        split_mut(&mut self.rc, |offset, rc| {
            for (r, k) in rc.iter_mut().zip(offset..) {
                *r = s[k] * z[k];
            }
        });
        direction(&self.rc, &mut self.dx, &mut self.ds, &mut self.dz);
        let alpha_aff = predictor_step(s, &self.ds, z, &self.dz);
        let a_aff = of(alpha_aff);
        let mu_aff =
            (0..m).fold(zero, |a, k| a + (s[k] + a_aff * self.ds[k]) * (z[k] + a_aff * self.dz[k])).to_f64() / m as f64;
        let sigma = (mu_aff / res.mu).powi(3).clamp(0.0, 1.0);
        let sigma_mu = of(sigma) * res.mu_t;
        // corrector
        let (ds, dz) = (&self.ds, &self.dz);
        split_mut(&mut self.rc, |offset, rc| {
            for (r, k) in rc.iter_mut().zip(offset..) {
                *r = s[k] * z[k] + ds[k] * dz[k] - sigma_mu;
            }
        });
        direction(&self.rc, &mut self.dx, &mut self.ds, &mut self.dz);
        let mut alpha_max = max_step(s, &self.ds).min(max_step(z, &self.dz));
        let (lo, hi) = (of(0.1) * sigma_mu, of(10.0) * sigma_mu);
        for _ in 0..CORRECTORS {
            if alpha_max >= 1.0 {
                break;
            }
            let trial = of((alpha_max + CORRECTOR_STEP).min(1.0));
            let (ds, dz, rc) = (&self.ds, &self.dz, &self.rc);
            split_mut(&mut self.rc2, |offset, rc2| {
                for (r2, k) in rc2.iter_mut().zip(offset..) {
                    let v = (s[k] + trial * ds[k]) * (z[k] + trial * dz[k]);
                    let t = if v < lo {
                        lo - v
                    } else if v > hi {
                        max(hi - v, -hi)
                    } else {
                        zero
                    };
                    *r2 = rc[k] - t;
                }
            });
            direction(&self.rc2, &mut self.dx2, &mut self.ds2, &mut self.dz2);
            let a2 = max_step(s, &self.ds2).min(max_step(z, &self.dz2));
            if a2 >= alpha_max + 0.1 * CORRECTOR_STEP {
                std::mem::swap(&mut self.dx, &mut self.dx2);
                std::mem::swap(&mut self.ds, &mut self.ds2);
                std::mem::swap(&mut self.dz, &mut self.dz2);
                std::mem::swap(&mut self.rc, &mut self.rc2);
                alpha_max = a2;
            } else {
                break;
            }
        }
        (0.99 * alpha_max).min(1.0)
    }

    /// The step onto the rows from a point that meets them only to the tolerance, where some
    /// true slacks `b − Ax` are negative (`s` is positive, `rp = Ax + s − b` is not zero): the
    /// Newton direction for the primal residual alone (no dual residual, the complementarity
    /// products held), `N dx = −Aᵀ(W rp)`, `ds = −rp − A dx`. On the rows the barrier holds
    /// (W large) it moves x by about `rp` and leaves their slacks as they are; on the others
    /// it hardly moves x. Without it the margin repair lifts whole runs of active rows by the
    /// sum of their shortfalls, and the gap bound of the output grows with the condition
    /// number (a walk of 10⁷ samples: 2.2 million vertices moved, Ĝ 3·10⁻⁷ → 2.3·10⁻⁶).
    fn onto_rows<O: Objective<T>>(&mut self, rows: &Rows, objective: &mut O, rp: &[T], w: &[T]) {
        for ((t, &wk), &r) in self.tmp_m.iter_mut().zip(w).zip(rp) {
            *t = wk * r;
        }
        rows.atz(&self.tmp_m, &mut self.dx);
        self.dx.iter_mut().for_each(|v| *v = -*v);
        objective.solve_in_place(&mut self.dx);
        rows.ax(&self.dx, &mut self.ds);
        for (d, &r) in self.ds.iter_mut().zip(rp) {
            *d = -r - *d;
        }
    }

    /// Takes the step of [`Self::onto_rows`] whole, each slack kept at least a thousandth of
    /// its value; returns the largest change of x.
    fn advance_onto_rows(&self, it: &mut Iterate<T>) -> f64 {
        let mut last_step = 0.0f64;
        for (xi, &dx) in it.x.iter_mut().zip(&self.dx) {
            last_step = last_step.max(dx.to_f64().abs());
            *xi += dx;
        }
        let floor = T::of(1e-3);
        for k in 0..it.s.len() {
            it.s[k] = max(it.s[k] + self.ds[k], floor * it.s[k]);
        }
        last_step
    }

    /// Moves `it` by `alpha` along the direction; returns the largest change of x.
    fn advance(&self, it: &mut Iterate<T>, alpha: f64) -> f64 {
        let a = T::of(alpha);
        let mut last_step = 0.0f64;
        for (xi, &dx) in it.x.iter_mut().zip(&self.dx) {
            let dxi = a * dx;
            last_step = last_step.max(dxi.to_f64().abs());
            *xi += dxi;
        }
        let (ds, dz) = (&self.ds, &self.dz);
        split_mut2(&mut it.s, &mut it.z, |offset, s, z| {
            for (j, k) in (offset..offset + s.len()).enumerate() {
                s[j] += a * ds[k];
                z[j] += a * dz[k];
            }
        });
        last_step
    }
}

/// The normal matrix's pattern [`solve`] analyses for `r`.
#[cfg(test)]
pub(crate) fn normal_pattern(r: &ReducedQp) -> faer::sparse::SymbolicSparseColMat<usize> {
    Normal::new(r, &r.rows).symbolic
}

/// Coordinate descent on the gap bound `Σ max(s, 0) z + ½ Σ ρ²/d` over the multipliers
/// `z ≥ 0` for a fixed point (ρ = ∇φ + Aᵀz updated in place): returns the bound reached.
fn polish_multipliers<T: Real>(
    rows: &Rows,
    slack: &[T],
    (d, inv_d): (&[T], &[T]),
    rho: &mut [T],
    z: &mut [T],
    sweeps: usize,
) -> T {
    let zero = T::of(0.0);
    for _ in 0..sweeps {
        for k in 0..z.len() {
            let s = max(slack[k], zero);
            let ([c0, c1], [v0, v1], len) = rows.row(k);
            let (mut grad, mut curv) =
                (s + (T::of(v0) * rho[c0]).div_by(d[c0], inv_d[c0]), T::of(v0 * v0).div_by(d[c0], inv_d[c0]));
            if len == 2 {
                grad += (T::of(v1) * rho[c1]).div_by(d[c1], inv_d[c1]);
                curv += T::of(v1 * v1).div_by(d[c1], inv_d[c1]);
            }
            let new = max(z[k] - grad / curv, zero);
            let delta = new - z[k];
            if delta != zero {
                z[k] = new;
                rho[c0] += T::of(v0) * delta;
                if len == 2 {
                    rho[c1] += T::of(v1) * delta;
                }
            }
        }
    }
    let comp = slack.iter().zip(z.iter()).fold(zero, |a, (&s, &z)| a + max(s, zero) * z);
    let stat = (0..rho.len()).fold(zero, |a, i| a + (rho[i] * rho[i]).div_by(d[i], inv_d[i]));
    comp + T::of(0.5) * stat
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_predictor_step_lets_one_percent_of_the_components_cross() {
        let m = 1000;
        // every slack reaches zero at 0.8, every multiplier at 0.9, except `blocking` slacks at 0.1
        let step = |blocking: usize| {
            let s = vec![1.0; m];
            let ds: Vec<f64> = (0..m).map(|k| if k < blocking { -10.0 } else { -1.25 }).collect();
            let (z, dz) = (vec![0.9; m], vec![-1.0; m]);
            predictor_step(&s, &ds, &z, &dz)
        };
        // five rows (0.5 %) cross: the step is the rest's, to the buckets' resolution below it
        let a = step(5);
        assert!(a <= 0.8 && a > 0.8 * (1.0 - 1.0 / 64.0), "{a}");
        // 10 rows may cross, 11 may not
        assert!(step(10) > 0.79, "{}", step(10));
        let a = step(11);
        assert!(a <= 0.1 && a > 0.1 * (1.0 - 1.0 / 64.0), "{a}");
        // nothing reaches zero before a full step
        assert_eq!(predictor_step(&[1.0; 4], &[-0.5; 4], &[1.0; 4], &[1.0; 4]), 1.0);
        // a few rows of a small problem: no crossing allowed, the largest step as before
        let a = predictor_step(&[1.0, 1.0], &[-4.0, 1.0], &[1.0, 1.0], &[0.0, 0.0]);
        assert!(a <= 0.25 && a > 0.25 * (1.0 - 1.0 / 64.0), "{a}");
    }

    #[test]
    fn the_path_multipliers_scale_is_the_centred_runs_sums_mean() {
        let mut rows = Rows::default();
        // runs 0–1–2 and 3–4 (no row between 2 and 3), a bound on 2, orientations mixed
        rows.push(&[(0, 1.0), (1, -1.0)]);
        rows.push(&[(2, 1.0), (1, -1.0)]);
        rows.push(&[(2, -1.0)]);
        rows.push(&[(3, 1.0), (4, -1.0)]);
        let g = [1.0, 1.0, 1.0, 2.0, 2.0];
        // rows after 0, 1 and 3: sums 1, 2 (centred ∓0.5) and 2 (centred 0): 1 / 3
        let scale = path_multiplier_scale(&rows, &g).unwrap();
        assert!((scale - 1.0 / 3.0).abs() < 1e-15, "{scale}");
        // a row across two places is not a path's
        rows.push(&[(0, 1.0), (2, -1.0)]);
        assert_eq!(path_multiplier_scale(&rows, &g), None);
        // bounds alone: no run
        let mut bounds = Rows::default();
        bounds.push(&[(0, 1.0)]);
        assert_eq!(path_multiplier_scale(&bounds, &g), None);
    }

    /// A reduced QP on a path of `n` variables: a pentadiagonal P (the upper triangle, sorted by
    /// column), rows on consecutive pairs and a few bounds, or one row spanning `wide` places.
    fn path_qp(n: usize, wide: Option<usize>) -> ReducedQp {
        let mut p = Vec::new();
        for j in 0..n {
            for i in j.saturating_sub(2)..=j {
                p.push((i, j, if i == j { 6.0 + 0.1 * (j % 7) as f64 } else { -1.5 + 0.01 * (i + j) as f64 }));
            }
        }
        let mut rows = Rows::default();
        for k in 0..n - 1 {
            let s = if (k / 5) % 2 == 0 { 1.0 } else { -1.0 };
            rows.push(&[(k, s), (k + 1, -s)]);
        }
        for c in [0, n / 2] {
            rows.push(&[(c, -1.0)]);
        }
        if let Some(w) = wide {
            rows.push(&[(0, 1.0), (w, -1.0)]);
        }
        let m = rows.len();
        ReducedQp {
            n,
            p: UpperP::Triplets(p),
            q: vec![0.0; n],
            rows,
            b: vec![0.0; m],
            d: vec![1.0; n],
            q_free: vec![0.0; n],
            gap_bound: true,
            factor: None,
            scale: 1.0,
            constant: 0.0,
        }
    }

    #[test]
    fn a_band_assembled_without_a_pattern_factorises_as_the_pattern_s_values() {
        let n = 300;
        let r = path_qp(n, None);
        let rows = &r.rows;
        assert_eq!(normal_band(&r, rows), Some(2));
        let w: Vec<f64> = (0..r.m()).map(|k| 10f64.powf(((k * 37) % 17) as f64 - 8.0)).collect();
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.31).sin()).collect();
        // the pattern's way: values on the normal pattern, copied into the band by position
        let normal = Normal::new(&r, rows);
        assert_eq!(ordering::band(normal.symbolic.as_ref()), Some(2));
        let mut vals = vec![0.0; normal.symbolic.row_idx().len()];
        fill_pattern(&normal, &mut vals, &r, rows, &w, 0.0);
        let mut old = Banded::<f64>::of_band(n, 2);
        let (cp, ri) = (normal.symbolic.col_ptr(), normal.symbolic.row_idx());
        for j in 0..n {
            for p in cp[j]..cp[j + 1] {
                old.band_mut()[Banded::<f64>::at(2, ri[p], j)] = vals[p];
            }
        }
        assert!(old.factor_band(0.0));
        let mut expected = rhs.clone();
        old.solve_in_place(&mut expected);
        // straight into the band
        let mut new = Factorised::Banded(Banded::of_band(n, 2));
        assert!(new.assemble_and_factor(&r, rows, &w, 0.0));
        let mut got = rhs.clone();
        new.solve_in_place(&mut got);
        assert!(got.iter().zip(&expected).all(|(a, b)| a.to_bits() == b.to_bits()));
        // and it solves the matrix: N x = rhs checked through the rows and P
        let mut nx = vec![0.0; n];
        r.p.add_product(&got, &mut nx);
        let mut ax = vec![0.0; r.m()];
        rows.ax(&got, &mut ax);
        let wax: Vec<f64> = ax.iter().zip(&w).map(|(a, w)| a * w).collect();
        let mut atwax = vec![0.0; n];
        rows.atz(&wax, &mut atwax);
        let err = (0..n).fold(0.0f64, |a, i| a.max((nx[i] + atwax[i] - rhs[i]).abs()));
        assert!(err < 1e-6, "residual {err:e}");
        // a row spanning more than the band's limit: the sparse pattern
        let wide = path_qp(n, Some(ordering::BANDED_MAX + 1));
        assert_eq!(normal_band(&wide, &wide.rows), None);
        let edge = path_qp(n, Some(ordering::BANDED_MAX));
        assert_eq!(normal_band(&edge, &edge.rows), Some(ordering::BANDED_MAX));
    }

    #[test]
    fn p_as_its_band_gives_the_triplets_entries_products_and_normal_band_bit_for_bit() {
        let n = 300;
        let r = path_qp(n, None);
        let UpperP::Triplets(t) = &r.p else { unreachable!("path_qp makes triplets") };
        let mut values = vec![0.0; n * 3];
        for &(i, j, v) in t {
            values[Banded::<f64>::at(2, i, j)] += v;
        }
        let banded = ReducedQp { p: UpperP::Band { width: 2, values }, ..path_qp(n, None) };
        assert_eq!(banded.p.len(), t.len());
        assert_eq!(banded.p.width(), 2);
        assert!(banded.p.entries().eq(t.iter().copied()));
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).cos() * 1e3).collect();
        let (mut a, mut b) = (vec![0.25; n], vec![0.25; n]);
        r.p.add_product(&x, &mut a);
        banded.p.add_product(&x, &mut b);
        assert!(a.iter().zip(&b).all(|(a, b)| a.to_bits() == b.to_bits()));
        let w: Vec<f64> = (0..r.m()).map(|k| 10f64.powf(((k * 37) % 17) as f64 - 8.0)).collect();
        let (mut fa, mut fb) = (Banded::<f64>::of_band(n, 2), Banded::<f64>::of_band(n, 2));
        fill_band(&mut fa, &r, &r.rows, &w, 1e-9);
        fill_band(&mut fb, &banded, &banded.rows, &w, 1e-9);
        assert!(fa.band_mut().iter().zip(fb.band_mut().iter()).all(|(a, b)| a.to_bits() == b.to_bits()));
        // a wider normal band (a row spanning 5 places) places P's band inside it
        let (rw, bw) = (path_qp(n, Some(5)), ReducedQp { p: banded.p.clone(), ..path_qp(n, Some(5)) });
        assert_eq!((normal_band(&rw, &rw.rows), normal_band(&bw, &bw.rows)), (Some(5), Some(5)));
        let w: Vec<f64> = (0..rw.m()).map(|k| 1.0 + k as f64).collect();
        let (mut fa, mut fb) = (Banded::<f64>::of_band(n, 5), Banded::<f64>::of_band(n, 5));
        fill_band(&mut fa, &rw, &rw.rows, &w, 0.0);
        fill_band(&mut fb, &bw, &bw.rows, &w, 0.0);
        assert!(fa.band_mut().iter().zip(fb.band_mut().iter()).all(|(a, b)| a.to_bits() == b.to_bits()));
        // long enough to be split over threads: the same bits on 1, 2 and 3
        let n = 3 * crate::parallel::SPLIT_FROM + 7;
        let r = path_qp(n, None);
        let UpperP::Triplets(t) = &r.p else { unreachable!("path_qp makes triplets") };
        let mut values = vec![0.0; n * 3];
        for &(i, j, v) in t {
            values[Banded::<f64>::at(2, i, j)] += v;
        }
        let banded = UpperP::Band { width: 2, values };
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() * 1e2 + 1e-3 * i as f64).collect();
        let mut expected = vec![-0.5; n];
        r.p.add_product(&x, &mut expected);
        for threads in [1, 2, 3] {
            let mut got = vec![-0.5; n];
            crate::parallel::with_threads(threads, || banded.add_product(&x, &mut got));
            assert!(got.iter().zip(&expected).all(|(a, b)| a.to_bits() == b.to_bits()), "{threads} threads");
        }
    }
}
