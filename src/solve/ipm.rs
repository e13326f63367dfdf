//! A primal–dual interior-point method (Mehrotra predictor–corrector) that exploits the
//! structure of the reduced QP `min ½ xᵀPx + qᵀx` s.t. `Ax ≤ b`.
//!
//! Every row of A has one or two entries (an ordering constraint on an edge), so the normal
//! matrix `N = P + Aᵀ W A` (`W = diag(z/s)`) has the pattern of P plus the constrained pairs,
//! known before the first iteration. faer's sparse Cholesky analyses that pattern once
//! (ordering — nested dissection or AMD, whichever needs fewer flops, see `crate::linalg` —
//! elimination tree, supernodes) and only refactors the values at each iteration:
//! one factorisation and two solves per iteration, instead of an LDLᵀ of the full
//! `(n + m) × (n + m)` KKT system. Starting from the representative u (feasible for every
//! row) the iteration count stays low. Whatever it returns, the certificate decides.

use super::qp::{QpSettings, ReducedQp, SolveStatus};
use crate::linalg as ordering;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};

/// Upper-triangular pattern of `N` and where each contribution lands in its value array.
struct Normal {
    symbolic: SymbolicSparseColMat<usize>,
    /// Position of each P triplet.
    pos_p: Vec<usize>,
    /// Per row: positions of (c1,c1), (c2,c2), (c1,c2) (the last two unused for one-entry rows).
    pos_row: Vec<[usize; 3]>,
    /// Position of each diagonal entry.
    pos_diag: Vec<usize>,
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
    fn new(r: &ReducedQp, row_cols: &[[usize; 2]], row_len: &[u8]) -> Normal {
        let n = r.n;
        let rows = row_cols.iter().zip(row_len).filter(|(_, &l)| l == 2).map(|(c, _)| (c[0].min(c[1]), c[0].max(c[1])));
        let (col_ptr, row_idx) = upper_pattern(n, r.p.iter().map(|&(i, j, _)| (i, j)).chain(rows));
        let find = |i: usize, j: usize| {
            col_ptr[j] + row_idx[col_ptr[j]..col_ptr[j + 1]].binary_search(&i).expect("in pattern")
        };
        let pos_p = r.p.iter().map(|&(i, j, _)| find(i, j)).collect();
        let pos_row = row_cols
            .iter()
            .zip(row_len)
            .map(|(c, &len)| {
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

/// The analysis of a normal matrix made before its constraints are known: from the pattern of
/// `P` on the free variables alone. The constrained pairs of a monotone QP are edges of the
/// domain, inside the pattern of any energy built on its Laplacian, so the normal matrix's
/// pattern is that one and [`solve`] finds this analysis ready ([`Prepared::install`]).
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
    pub fn new(p: SymbolicSparseColMatRef<'_, usize>, slot: &[usize], n: usize) -> Result<Prepared, String> {
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
        // without it (faer's scratch could not be allocated) the solver makes the storage
        let workspace = ordering::Workspace::new(&analysis).ok();
        Ok(Prepared { pattern, analysis, workspace })
    }

    /// The analysed pattern.
    #[cfg(test)]
    pub(crate) fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        self.pattern.as_ref()
    }

    /// Makes the analysis the one [`solve`] on this thread uses for a normal matrix of this
    /// pattern.
    pub fn install(self) {
        let analysis = std::rc::Rc::new(self.analysis);
        SPARE.with(|c| *c.borrow_mut() = self.workspace.map(|w| (analysis.clone(), w)));
        LAST.with(|c| *c.borrow_mut() = Some((self.pattern, analysis)));
    }
}

/// Drops the factor storage [`Prepared::install`] made ready on this thread, for a QP that
/// needs no solve.
pub(super) fn forget_prepared_storage() {
    SPARE.with(|c| *c.borrow_mut() = None);
}

/// Centrality correctors per iteration at most. Iterations without / with 2 at the same
/// stopping rule (μ ≤ tol): 150 × 100 grid 10 / 7, 300² 11 / 8, mountain distance 7 / 6,
/// spot @1 6 / 6, Kármán street 15 / 11; with the stricter μ ≤ tol/10 now used, 9, 9, 7, 6
/// and 13.
const CORRECTORS: usize = 2;
/// How much longer than the corrected predictor's step a corrector aims.
const CORRECTOR_STEP: f64 = 0.3;

thread_local! {
    /// The last normal-equation pattern analysed on this thread (nested dissection and AMD).
    static LAST: ordering::SymbolicSlot<ordering::Analysis> = const { std::cell::RefCell::new(None) };
    /// Storage made in advance for the factorisations of one analysis in `LAST`.
    static SPARE: std::cell::RefCell<Option<(std::rc::Rc<ordering::Analysis>, ordering::Workspace)>> =
        const { std::cell::RefCell::new(None) };
}

/// Solves the reduced QP; `Err(reason)` when it cannot (the caller falls back to Clarabel).
pub fn solve(
    r: &ReducedQp,
    hint: Option<&[f64]>,
    settings: &QpSettings,
) -> Result<(Vec<f64>, SolveStatus, u32), String> {
    let (n, m) = (r.n, r.m());
    // the storage made in advance is this solve's or nobody's: not kept past an early return
    let spare = SPARE.with(|c| c.borrow_mut().take());
    // rows as (columns, values, length)
    let mut row_cols = vec![[0usize; 2]; m];
    let mut row_vals = vec![[0.0f64; 2]; m];
    let mut row_len = vec![0u8; m];
    for k in 0..r.a_row.len() {
        let row = r.a_row[k];
        let l = row_len[row] as usize;
        if l >= 2 {
            return Err(format!("row {row} has more than two entries"));
        }
        row_cols[row][l] = r.a_col[k];
        row_vals[row][l] = r.a_val[k];
        row_len[row] += 1;
    }
    let ax = |x: &[f64], out: &mut [f64]| {
        for k in 0..m {
            let mut s = row_vals[k][0] * x[row_cols[k][0]];
            if row_len[k] == 2 {
                s += row_vals[k][1] * x[row_cols[k][1]];
            }
            out[k] = s;
        }
    };
    let atz = |z: &[f64], out: &mut [f64]| {
        out.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..m {
            out[row_cols[k][0]] += row_vals[k][0] * z[k];
            if row_len[k] == 2 {
                out[row_cols[k][1]] += row_vals[k][1] * z[k];
            }
        }
    };
    let px = |x: &[f64], out: &mut [f64]| {
        out.iter_mut().for_each(|v| *v = 0.0);
        for &(i, j, v) in &r.p {
            out[i] += v * x[j];
            if i != j {
                out[j] += v * x[i];
            }
        }
    };

    let normal = Normal::new(r, &row_cols, &row_len);
    let analysis =
        ordering::cached_symbolic(&LAST, normal.symbolic.as_ref(), || ordering::analyse(normal.symbolic.as_ref()))?;
    let spare = spare.filter(|(a, _)| std::rc::Rc::ptr_eq(a, &analysis));
    let spd = std::cell::RefCell::new(match spare {
        Some((_, workspace)) => ordering::SpdFactor::with_workspace(analysis, workspace),
        None => ordering::SpdFactor::new(analysis)?,
    });
    let nnz = normal.symbolic.row_idx().len();
    let mut vals = vec![0.0f64; nnz];
    let factor = |w: &[f64], vals: &mut [f64]| -> Result<(), String> {
        let mut reg = 0.0;
        for attempt in 0..4 {
            vals.iter_mut().for_each(|v| *v = 0.0);
            for (k, &(_, _, v)) in r.p.iter().enumerate() {
                vals[normal.pos_p[k]] += v;
            }
            for k in 0..m {
                let [p1, p2, p12] = normal.pos_row[k];
                let [a1, a2] = row_vals[k];
                vals[p1] += w[k] * a1 * a1;
                if row_len[k] == 2 {
                    vals[p2] += w[k] * a2 * a2;
                    vals[p12] += w[k] * a1 * a2;
                }
            }
            if reg > 0.0 {
                for &d in &normal.pos_diag {
                    vals[d] += reg;
                }
            }
            let mat = SparseColMatRef::new(normal.symbolic.as_ref(), vals);
            match spd.borrow_mut().factor(mat) {
                Ok(()) => return Ok(()),
                Err(_) => reg = if attempt == 0 { 1e-12 } else { reg * 1e3 },
            }
        }
        Err("the normal matrix is not positive definite".into())
    };
    let solve_with = |rhs: &mut [f64]| {
        spd.borrow_mut().solve_in_place(rhs);
    };

    let mut x: Vec<f64> = hint.map(|h| h.to_vec()).unwrap_or_else(|| vec![0.0; n]);
    if m == 0 {
        factor(&[], &mut vals)?;
        let mut rhs: Vec<f64> = r.q.iter().map(|v| -v).collect();
        solve_with(&mut rhs);
        return Ok((rhs, SolveStatus::Solved, 1));
    }
    // starting point: slacks of x (shifted to be positive), multipliers below, then balanced
    let mut s = vec![0.0; m];
    ax(&x, &mut s);
    for (sk, bk) in s.iter_mut().zip(&r.b) {
        *sk = bk - *sk;
    }
    // multipliers at the scale of the objective's gradient at the start, which they must
    // balance (each row of A has entries ±1): 3 × mean |P x + q|. Against unit multipliers
    // this cut the iterations from 14 to 7 (mountain distance), 27 to 15 (Kármán vorticity),
    // 15 to 11 (300² noisy grid).
    let mut g = vec![0.0; n];
    px(&x, &mut g);
    let gmean = g.iter().zip(&r.q).map(|(a, b)| (a + b).abs()).sum::<f64>() / n.max(1) as f64;
    let z0 = (3.0 * gmean).max(1e-12);
    let mut z = vec![z0; m];
    let smin = s.iter().cloned().fold(f64::INFINITY, f64::min);
    if smin <= 0.0 {
        s.iter_mut().for_each(|v| *v += -1.5 * smin + 1e-3);
    }
    let sz: f64 = s.iter().zip(&z).map(|(a, b)| a * b).sum();
    let (ssum, zsum): (f64, f64) = (s.iter().sum(), z.iter().sum());
    s.iter_mut().for_each(|v| *v += 0.5 * sz / zsum);
    z.iter_mut().for_each(|v| *v += 0.5 * sz / ssum);

    let bnorm = 1.0 + r.b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let qnorm = 1.0 + r.q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let tol = settings.tolerance;
    // The mean complementarity must fall 10× below the feasibility tolerance: the objective is
    // flat along many directions, and with the correctors μ ≤ tol was reached while the gap
    // sᵀz was still 5× larger than without them (Kármán street, 5 %: energy 583.876 against
    // Clarabel's 583.532, 583.603 before the correctors; now 583.570 in 13 iterations, 15
    // before).
    let tol_mu = 0.1 * tol;
    let (mut rd, mut rp, mut tmp_n, mut tmp_m) = (vec![0.0; n], vec![0.0; m], vec![0.0; n], vec![0.0; m]);
    let (mut dx, mut ds, mut dz, mut rc) = (vec![0.0; n], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let (mut dx2, mut ds2, mut dz2, mut rc2) = (vec![0.0; n], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let mut w = vec![0.0; m];
    let step =
        |v: &[f64], d: &[f64]| v.iter().zip(d).fold(1.0f64, |a, (&v, &d)| if d < 0.0 { a.min(-v / d) } else { a });
    let mut last = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    for it in 0..settings.max_iter {
        // residuals
        px(&x, &mut rd);
        atz(&z, &mut tmp_n);
        for i in 0..n {
            rd[i] += r.q[i] + tmp_n[i];
        }
        ax(&x, &mut rp);
        for k in 0..m {
            rp[k] += s[k] - r.b[k];
        }
        let mu = s.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>() / m as f64;
        let pres = rp.iter().fold(0.0f64, |a, v| a.max(v.abs())) / bnorm;
        let dres = rd.iter().fold(0.0f64, |a, v| a.max(v.abs())) / qnorm;
        last = (pres, dres, mu);
        if !(pres.is_finite() && dres.is_finite() && mu.is_finite()) {
            return Err(format!("non-finite iterate at iteration {it}"));
        }
        if pres <= tol && dres <= tol && mu <= tol_mu {
            return Ok((x, SolveStatus::Solved, it));
        }
        for k in 0..m {
            w[k] = z[k] / s[k];
        }
        factor(&w, &mut vals)?;
        // one Newton direction for complementarity target rc (s∘z − rc → 0)
        let mut direction = |rc: &[f64], dx: &mut Vec<f64>, ds: &mut Vec<f64>, dz: &mut Vec<f64>| {
            for k in 0..m {
                tmp_m[k] = w[k] * rp[k] - rc[k] / s[k];
            }
            atz(&tmp_m, dx);
            for i in 0..n {
                dx[i] = -rd[i] - dx[i];
            }
            solve_with(dx);
            ax(dx, ds);
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
        let mu_aff = (0..m).map(|k| (s[k] + alpha_aff * ds[k]) * (z[k] + alpha_aff * dz[k])).sum::<f64>() / m as f64;
        let sigma = (mu_aff / mu).powi(3).min(1.0);
        // corrector
        for k in 0..m {
            rc[k] = s[k] * z[k] + ds[k] * dz[k] - sigma * mu;
        }
        direction(&rc, &mut dx, &mut ds, &mut dz);
        let mut alpha_max = step(&s, &ds).min(step(&z, &dz));
        // Gondzio's multiple centrality correctors: aim at a longer step, push the
        // complementarity products of that trial point back into [0.1, 10] × σμ and keep the
        // corrected direction if its step grows. One solve each, no factorisation.
        let (lo, hi) = (0.1 * sigma * mu, 10.0 * sigma * mu);
        for _ in 0..CORRECTORS {
            if alpha_max >= 1.0 {
                break;
            }
            let trial = (alpha_max + CORRECTOR_STEP).min(1.0);
            for k in 0..m {
                let v = (s[k] + trial * ds[k]) * (z[k] + trial * dz[k]);
                let t = if v < lo {
                    lo - v
                } else if v > hi {
                    (hi - v).max(-hi)
                } else {
                    0.0
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
            return Err(format!("step length {alpha:e} at iteration {it}"));
        }
        for i in 0..n {
            x[i] += alpha * dx[i];
        }
        for k in 0..m {
            s[k] += alpha * ds[k];
            z[k] += alpha * dz[k];
        }
    }
    let (pres, dres, mu) = last;
    if pres <= 1e3 * tol && dres <= 1e3 * tol && mu <= 1e3 * tol {
        return Ok((x, SolveStatus::AlmostSolved, settings.max_iter));
    }
    Err(format!(
        "no convergence in {} iterations (primal {pres:.1e}, dual {dres:.1e}, gap {mu:.1e})",
        settings.max_iter
    ))
}

/// The normal matrix's pattern [`solve`] analyses for `r`.
#[cfg(test)]
pub(crate) fn normal_pattern(r: &ReducedQp) -> SymbolicSparseColMat<usize> {
    let mut row_cols = vec![[0usize; 2]; r.m()];
    let mut row_len = vec![0u8; r.m()];
    for k in 0..r.a_row.len() {
        let row = r.a_row[k];
        row_cols[row][row_len[row] as usize] = r.a_col[k];
        row_len[row] += 1;
    }
    Normal::new(r, &row_cols, &row_len).symbolic
}
