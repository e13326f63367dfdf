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

use super::newton::{max, Normal, Objective, Prepared, Real, Rows};
use super::problem::ReducedQp;
use super::settings::QpSettings;
use super::status::{Outcome, SolveStatus};
use crate::linalg as ordering;
use faer::sparse::SparseColMatRef;

/// Centrality correctors per iteration at most: each costs one solve and saves iterations,
/// each a factorisation (docs/performance.md, "constants").
const CORRECTORS: usize = 2;
/// How much longer than the corrected predictor's step a corrector aims.
const CORRECTOR_STEP: f64 = 0.3;

/// `P` assembled; normal equations in double precision.
struct Assembled<'r> {
    r: &'r ReducedQp,
    normal: Normal,
    analysis: std::sync::Arc<ordering::Analysis>,
    spd: ordering::SpdFactor,
    vals: Vec<f64>,
    /// `P` alone factorised (on the normal matrix's pattern), for [`Objective::energy_dual`].
    energy: Option<ordering::SpdFactor>,
}

impl Objective<f64> for Assembled<'_> {
    fn gradient(&mut self, x: &[f64], out: &mut [f64]) {
        out.iter_mut().zip(&self.r.q).for_each(|(o, q)| *o = *q);
        for &(i, j, v) in &self.r.p {
            out[i] += v * x[j];
            if i != j {
                out[j] += v * x[i];
            }
        }
    }

    /// With a growing diagonal shift if the matrix is not numerically positive definite.
    fn factor(&mut self, rows: &Rows, w: &[f64]) -> std::result::Result<(), crate::error::NumericalError> {
        let (normal, vals) = (&self.normal, &mut self.vals);
        let mut reg = 0.0;
        for attempt in 0..4 {
            vals.iter_mut().for_each(|v| *v = 0.0);
            for (k, &(_, _, v)) in self.r.p.iter().enumerate() {
                vals[normal.pos_p[k]] += v;
            }
            for (k, &wk) in w.iter().enumerate() {
                let [p1, p2, p12] = normal.pos_row[k];
                let [a1, a2] = rows.vals[k];
                vals[p1] += wk * a1 * a1;
                if rows.len[k] == 2 {
                    vals[p2] += wk * a2 * a2;
                    vals[p12] += wk * a1 * a2;
                }
            }
            if reg > 0.0 {
                for &d in &normal.pos_diag {
                    vals[d] += reg;
                }
            }
            let mat = SparseColMatRef::new(normal.symbolic.as_ref(), vals);
            match self.spd.factor(mat) {
                Ok(()) => return Ok(()),
                Err(_) => reg = if attempt == 0 { 1e-12 } else { reg * 1e3 },
            }
        }
        Err("the normal matrix is not positive definite".into())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        self.spd.solve_in_place(rhs);
    }

    fn auxiliary(&self, _: &[f64]) -> Option<Vec<f64>> {
        None
    }

    fn energy_dual(&mut self, r: &[f64]) -> Option<f64> {
        if self.energy.is_none() {
            let mut vals = vec![0.0; self.vals.len()];
            for (k, &(_, _, v)) in self.r.p.iter().enumerate() {
                vals[self.normal.pos_p[k]] += v;
            }
            let mut f = ordering::SpdFactor::new(self.analysis.clone()).ok()?;
            f.factor(SparseColMatRef::new(self.normal.symbolic.as_ref(), &vals)).ok()?;
            self.energy = Some(f);
        }
        let mut y = r.to_vec();
        self.energy.as_mut()?.solve_in_place(&mut y);
        Some(0.5 * r.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>())
    }
}

/// The largest relative change of the iterate in one step at which the solver may stop (the
/// values are scaled to [0, 1]: 1e-5 of the range, ten default margins).
const STEP_TOLERANCE: f64 = 1e-5;
/// Iterations without a halving of the best gap bound after which the solver stops with
/// what it has (the bound has reached its rounding floor).
const STALL_ITERATIONS: u32 = 8;
/// Coordinate-descent sweeps over the multipliers per iteration (20 and 100 gave the same
/// bound as 5 on the 300² benchmark grid, each about 5 × below the solver's own).
const POLISH_SWEEPS: usize = 5;

/// Solves the reduced QP; `Err(reason)` when it cannot (the caller falls back to Clarabel).
///
/// Stops when the rows are met to `settings.tolerance`, the last step moved no value by more
/// than [`STEP_TOLERANCE`], and — with a data term — the gap bound
/// `Ĝ = Σ max(s, 0) z + ½ Σ ρ²/d` (s = b − Ax, ρ = ∇φ + Aᵀz, d the data diagonal: P ⪰
/// diag(d)), with the multipliers polished for the point, is below `settings.gap_tolerance` ×
/// the data term; without one, when `sᵀz + ½ρᵀP⁻¹ρ` (P factorised alone) is below it × the
/// energy, or — where P alone cannot be factorised — when the mean complementarity is 10×
/// below the feasibility tolerance. The factored form runs in double-double throughout.
///
/// The normal matrix's analysis comes from `analyses` (and is kept there for the next solve
/// on the same pattern); `prepared`, made in advance, is kept there first.
pub(super) fn solve(
    r: &ReducedQp,
    hint: Option<&[f64]>,
    settings: &QpSettings,
    analyses: &mut ordering::Analyses,
    prepared: Option<Prepared>,
) -> std::result::Result<Outcome, crate::error::NumericalError> {
    let spare = prepared.and_then(|p| p.keep_in(analyses));
    let rows = Rows::new(r)?;
    match &r.factor {
        Some(factor) => {
            drop(spare);
            let split = analyses.split_allowed();
            let mut objective = super::factored::Normal::new(r, factor, &rows.cols, &rows.len, split)?;
            run::<faer::fx128, _>(r, &rows, &mut objective, hint, settings)
        }
        None => {
            let normal = Normal::new(r, &rows.cols, &rows.len);
            let analysis = analyses.of(normal.symbolic.as_ref())?;
            let spare = spare.filter(|(a, _)| std::sync::Arc::ptr_eq(a, &analysis));
            let spd = match spare {
                Some((_, workspace)) => ordering::SpdFactor::with_workspace(analysis.clone(), workspace),
                None => ordering::SpdFactor::new(analysis.clone())?,
            };
            let vals = vec![0.0f64; normal.symbolic.row_idx().len()];
            let mut objective = Assembled { r, normal, analysis, spd, vals, energy: None };
            run::<f64, _>(r, &rows, &mut objective, hint, settings)
        }
    }
}

/// The interior-point iteration in arithmetic `T`.
fn run<T: Real, O: Objective<T>>(
    r: &ReducedQp,
    rows: &Rows,
    objective: &mut O,
    hint: Option<&[f64]>,
    settings: &QpSettings,
) -> std::result::Result<Outcome, crate::error::NumericalError> {
    let (n, m) = (r.n, r.m());
    let zero = T::of(0.0);
    let of = T::of;
    let b: Vec<T> = r.b.iter().map(|&v| of(v)).collect();
    let mut x: Vec<T> = match hint {
        Some(h) => h.iter().map(|&v| of(v)).collect(),
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
    // starting point: slacks of x (shifted to be positive), multipliers below, then balanced
    let mut s = vec![zero; m];
    rows.ax(&x, &mut s);
    for (sk, bk) in s.iter_mut().zip(&b) {
        *sk = *bk - *sk;
    }
    // multipliers at the scale of the objective's gradient at the start, which they must
    // balance (each row of A has entries ±1): 3 × mean |P x + q|; unit multipliers took about
    // twice the iterations (docs/performance.md, "constants")
    let mut g = vec![zero; n];
    objective.gradient(&x, &mut g);
    let gmean = g.iter().map(|a| a.to_f64().abs()).sum::<f64>() / n.max(1) as f64;
    let z0 = (3.0 * gmean).max(1e-12);
    let mut z = vec![of(z0); m];
    let smin = s.iter().map(|v| v.to_f64()).fold(f64::INFINITY, f64::min);
    if smin <= 0.0 {
        s.iter_mut().for_each(|v| *v += of(-1.5 * smin + 1e-3));
    }
    let sz: f64 = s.iter().zip(&z).map(|(a, b)| (*a * *b).to_f64()).sum();
    let (ssum, zsum): (f64, f64) = (s.iter().map(|v| v.to_f64()).sum(), z.iter().map(|v| v.to_f64()).sum());
    s.iter_mut().for_each(|v| *v += of(0.5 * sz / zsum));
    z.iter_mut().for_each(|v| *v += of(0.5 * sz / ssum));

    let bnorm = 1.0 + r.b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let qnorm = 1.0 + r.q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let tol = settings.tolerance;
    // without a data term: the mean complementarity 10× below the feasibility tolerance (the
    // objective is flat along many directions; with the correctors μ ≤ tol was reached while
    // sᵀz was still 5× larger than without them)
    let tol_mu = 0.1 * tol;
    let has_data = r.gap_bound;
    let d: Vec<T> = r.d.iter().map(|&v| of(v)).collect();
    let q_free: Vec<T> = r.q_free.iter().map(|&v| of(v)).collect();
    let d_sum: f64 = r.d.iter().sum();
    let (mut rd, mut rp, mut tmp_n, mut tmp_m) = (vec![zero; n], vec![zero; m], vec![zero; n], vec![zero; m]);
    let (mut dx, mut ds, mut dz, mut rc) = (vec![zero; n], vec![zero; m], vec![zero; m], vec![zero; m]);
    let (mut dx2, mut ds2, mut dz2, mut rc2) = (vec![zero; n], vec![zero; m], vec![zero; m], vec![zero; m]);
    let mut slack = vec![zero; m];
    let mut w = vec![zero; m];
    let step = |v: &[T], d: &[T]| {
        v.iter().zip(d).fold(1.0f64, |a, (&v, &d)| if d < zero { a.min((-v / d).to_f64()) } else { a })
    };
    let mut last = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut last_step = f64::INFINITY;
    let (mut best_gap, mut best_at) = (f64::INFINITY, 0u32);
    // the outcome if the next factorisation fails: the point reached, when it already meets
    // the targets except for the step (z/s beyond 10¹⁶ × the data diagonal cancels in double
    // precision once the gap is tiny)
    let mut fallback_status: Option<SolveStatus>;
    for it in 0..settings.max_iter {
        // residuals
        objective.gradient(&x, &mut rd);
        // φ(x) = ½ xᵀ(∇φ + q), the objective (up to the fixed part's constant)
        let phi = if has_data {
            0.0
        } else {
            0.5 * x.iter().zip(rd.iter().zip(&r.q)).map(|(x, (g, q))| (*x * (*g + of(*q))).to_f64()).sum::<f64>()
        };
        rows.atz(&z, &mut tmp_n);
        for i in 0..n {
            rd[i] += tmp_n[i];
        }
        rows.ax(&x, &mut slack);
        for k in 0..m {
            rp[k] = slack[k] + s[k] - b[k];
            slack[k] = b[k] - slack[k];
        }
        let mu_t = s.iter().zip(&z).fold(zero, |a, (&s, &z)| a + s * z) / of(m as f64);
        let mu = mu_t.to_f64();
        let pres = rp.iter().fold(0.0f64, |a, v| a.max(v.to_f64().abs())) / bnorm;
        let dres = rd.iter().fold(0.0f64, |a, v| a.max(v.to_f64().abs())) / qnorm;
        last = (pres, dres, mu);
        if !(pres.is_finite() && dres.is_finite() && mu.is_finite()) {
            return Err(crate::error::NumericalError(format!("non-finite iterate at iteration {it}")));
        }
        let xmax = x.iter().fold(0.0f64, |a, v| a.max(v.to_f64().abs()));
        let small_step = last_step <= STEP_TOLERANCE * (1.0 + xmax);
        if has_data {
            let comp = slack.iter().zip(&z).fold(zero, |a, (&s, &z)| a + max(s, zero) * z);
            let stat = rd.iter().zip(&d).fold(zero, |a, (&g, &d)| a + g * g / d);
            let gap = (comp + of(0.5) * stat).to_f64();
            let data = (0..n).fold(zero, |a, i| {
                let e = d[i] * x[i] + q_free[i];
                a + e * e / d[i]
            });
            let data = (0.5 * data.to_f64()).max(1e-20 * d_sum);
            // the multipliers polished for this point (coordinate descent on the bound): the
            // interior z of rows far from active still carries complementarity the point no
            // longer needs; about one iteration less on the benchmark grids
            let mut polished = z.clone();
            let gap = if pres <= tol {
                let mut rho = rd.clone();
                gap.min(polish_multipliers(rows, &slack, &d, &mut rho, &mut polished, POLISH_SWEEPS).to_f64())
            } else {
                gap
            };
            if pres <= tol && small_step && gap <= settings.gap_tolerance * data {
                return Ok(finish(&x, &polished, SolveStatus::Solved, it, objective));
            }
            fallback_status = if pres > tol {
                None
            } else if gap <= settings.gap_tolerance * data {
                Some(SolveStatus::Solved)
            } else if gap <= 1e2 * settings.gap_tolerance * data {
                Some(SolveStatus::AlmostSolved)
            } else {
                None
            };
            if gap < 0.5 * best_gap {
                (best_gap, best_at) = (gap, it);
            } else if pres <= tol && it >= best_at + STALL_ITERATIONS && gap <= 1e2 * settings.gap_tolerance * data {
                // the bound has reached its rounding floor, within 100× the target
                return Ok(finish(&x, &polished, SolveStatus::AlmostSolved, it, objective));
            }
        } else {
            // without a data term: the gap sᵀz + ½ ρᵀP⁻¹ρ against the energy ½ fᵀQf (P
            // factorised once), or, where P cannot be solved alone, the mean complementarity
            let energy = phi + r.constant;
            // (one solve with P: only once the rows are met, where it can decide)
            let gap = (pres <= tol)
                .then(|| objective.energy_dual(&rd))
                .flatten()
                .map(|dual| slack.iter().zip(&z).map(|(s, z)| (max(*s, zero) * *z).to_f64()).sum::<f64>() + dual);
            let target = settings.gap_tolerance * energy.abs().max(1e-300);
            let converged = match gap {
                Some(gap) => pres <= tol && small_step && gap <= target,
                None => pres <= tol && dres <= tol && mu <= tol_mu,
            };
            if converged {
                return Ok(finish(&x, &z, SolveStatus::Solved, it, objective));
            }
            // the rows met and the complementarity gone: the dual part ½ρᵀP⁻¹ρ of the bound
            // can sit on the rounding floor of ρ amplified by P⁻¹ (k = 4: Ĝ ÷ energy ≈ 10⁻⁴
            // with μ ≈ 10⁻²⁵), and the next factorisation can fail there; the point is kept
            // rather than handed to another solver
            let settled = pres <= tol && mu <= tol_mu;
            fallback_status = settled.then_some(SolveStatus::AlmostSolved);
            if let Some(gap) = gap {
                if gap < 0.5 * best_gap {
                    (best_gap, best_at) = (gap, it);
                } else if settled && it >= best_at + STALL_ITERATIONS {
                    return Ok(finish(&x, &z, SolveStatus::AlmostSolved, it, objective));
                }
            }
        }
        for k in 0..m {
            w[k] = z[k] / s[k];
        }
        if let Err(e) = objective.factor(rows, &w) {
            return match fallback_status {
                Some(status) => Ok(finish(&x, &z, status, it, objective)),
                None => Err(e),
            };
        }
        // one Newton direction for complementarity target rc (s∘z − rc → 0)
        let mut direction = |rc: &[T], dx: &mut Vec<T>, ds: &mut Vec<T>, dz: &mut Vec<T>| {
            for k in 0..m {
                tmp_m[k] = w[k] * rp[k] - rc[k] / s[k];
            }
            rows.atz(&tmp_m, dx);
            for i in 0..n {
                dx[i] = -rd[i] - dx[i];
            }
            objective.solve_in_place(dx);
            rows.ax(dx, ds);
            for k in 0..m {
                let adx = ds[k];
                dz[k] = w[k] * (adx + rp[k]) - rc[k] / s[k];
                ds[k] = -rp[k] - adx;
            }
        };
        // predictor
        for k in 0..m {
            rc[k] = s[k] * z[k];
        }
        direction(&rc, &mut dx, &mut ds, &mut dz);
        let alpha_aff = step(&s, &ds).min(step(&z, &dz)).min(1.0);
        let a_aff = of(alpha_aff);
        let mu_aff = (0..m).fold(zero, |a, k| a + (s[k] + a_aff * ds[k]) * (z[k] + a_aff * dz[k])).to_f64() / m as f64;
        let sigma = (mu_aff / mu).powi(3).min(1.0);
        let sigma_mu = of(sigma) * mu_t;
        // corrector
        for k in 0..m {
            rc[k] = s[k] * z[k] + ds[k] * dz[k] - sigma_mu;
        }
        direction(&rc, &mut dx, &mut ds, &mut dz);
        let mut alpha_max = step(&s, &ds).min(step(&z, &dz));
        // Gondzio's multiple centrality correctors: aim at a longer step, push the
        // complementarity products of that trial point back into [0.1, 10] × σμ and keep the
        // corrected direction if its step grows. One solve each, no factorisation.
        let (lo, hi) = (of(0.1) * sigma_mu, of(10.0) * sigma_mu);
        for _ in 0..CORRECTORS {
            if alpha_max >= 1.0 {
                break;
            }
            let trial = of((alpha_max + CORRECTOR_STEP).min(1.0));
            for k in 0..m {
                let v = (s[k] + trial * ds[k]) * (z[k] + trial * dz[k]);
                let t = if v < lo {
                    lo - v
                } else if v > hi {
                    max(hi - v, -hi)
                } else {
                    zero
                };
                rc2[k] = rc[k] - t;
            }
            direction(&rc2, &mut dx2, &mut ds2, &mut dz2);
            let a2 = step(&s, &ds2).min(step(&z, &dz2));
            if a2 >= alpha_max + 0.1 * CORRECTOR_STEP {
                std::mem::swap(&mut dx, &mut dx2);
                std::mem::swap(&mut ds, &mut ds2);
                std::mem::swap(&mut dz, &mut dz2);
                std::mem::swap(&mut rc, &mut rc2);
                alpha_max = a2;
            } else {
                break;
            }
        }
        let alpha = (0.99 * alpha_max).min(1.0);
        if alpha < 1e-12 {
            return Err(crate::error::NumericalError(format!("step length {alpha:e} at iteration {it}")));
        }
        let a = of(alpha);
        last_step = 0.0;
        for i in 0..n {
            let dxi = a * dx[i];
            last_step = last_step.max(dxi.to_f64().abs());
            x[i] += dxi;
        }
        for k in 0..m {
            s[k] += a * ds[k];
            z[k] += a * dz[k];
        }
    }
    let (pres, dres, mu) = last;
    if pres <= 1e3 * tol && (has_data || (dres <= 1e3 * tol && mu <= 1e3 * tol)) {
        return Ok(finish(&x, &z, SolveStatus::AlmostSolved, settings.max_iter, objective));
    }
    Err(crate::error::NumericalError(format!(
        "no convergence in {} iterations (primal {pres:.1e}, dual {dres:.1e}, gap {mu:.1e})",
        settings.max_iter
    )))
}

/// The normal matrix's pattern [`solve`] analyses for `r`.
#[cfg(test)]
pub(crate) fn normal_pattern(r: &ReducedQp) -> faer::sparse::SymbolicSparseColMat<usize> {
    let mut row_cols = vec![[0usize; 2]; r.m()];
    let mut row_len = vec![0u8; r.m()];
    for k in 0..r.a_row.len() {
        let row = r.a_row[k];
        row_cols[row][row_len[row] as usize] = r.a_col[k];
        row_len[row] += 1;
    }
    Normal::new(r, &row_cols, &row_len).symbolic
}

/// Coordinate descent on the gap bound `Σ max(s, 0) z + ½ Σ ρ²/d` over the multipliers
/// `z ≥ 0` for a fixed point (ρ = ∇φ + Aᵀz updated in place): returns the bound reached.
fn polish_multipliers<T: Real>(rows: &Rows, slack: &[T], d: &[T], rho: &mut [T], z: &mut [T], sweeps: usize) -> T {
    let zero = T::of(0.0);
    for _ in 0..sweeps {
        for k in 0..z.len() {
            let s = max(slack[k], zero);
            let [c0, c1] = rows.cols[k];
            let [v0, v1] = rows.vals[k];
            let (mut grad, mut curv) = (s + T::of(v0) * rho[c0] / d[c0], T::of(v0 * v0) / d[c0]);
            if rows.len[k] == 2 {
                grad += T::of(v1) * rho[c1] / d[c1];
                curv += T::of(v1 * v1) / d[c1];
            }
            let new = max(z[k] - grad / curv, zero);
            let delta = new - z[k];
            if delta != zero {
                z[k] = new;
                rho[c0] += T::of(v0) * delta;
                if rows.len[k] == 2 {
                    rho[c1] += T::of(v1) * delta;
                }
            }
        }
    }
    let comp = slack.iter().zip(z.iter()).fold(zero, |a, (&s, &z)| a + max(s, zero) * z);
    let stat = rho.iter().zip(d).fold(zero, |a, (&g, &d)| a + g * g / d);
    comp + T::of(0.5) * stat
}
