//! Bounded biharmonic weights (Jacobson, Baran, Popović & Sorkine 2011): all functions at
//! once, `min Σ_h ½ w_hᵀ P w_h` with fixed values, `0 ≤ w_h ≤ 1` and `Σ_h w_h = 1` at every
//! vertex, by Clarabel. The comparison method of the no-data mode: no monotonicity.

use super::clarabel::run;
use super::settings::QpSettings;
use super::status::SolveStatus;
use crate::error::{Error, Result};
use crate::operators::Sparse;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{NonnegativeConeT, ZeroConeT};

/// Solves the joint problem; `fixed[h][v]` fixes function `h` at vertex `v`. Returns the
/// functions (fixed entries exact), the solver status and its iterations.
///
/// # Errors
/// [`Error::NoSolution`] when Clarabel returns no point; an input error when the fixed values
/// already violate the bounds or the partition of unity at a fully fixed vertex.
pub fn solve_bounded_partition(
    p: &Sparse,
    fixed: &[Vec<Option<f64>>],
    settings: &QpSettings,
) -> Result<(Vec<Vec<f64>>, SolveStatus, u32)> {
    let n = p.nrows();
    let hs = fixed.len();
    let mut slot = vec![vec![usize::MAX; n]; hs];
    let mut nvar = 0;
    for h in 0..hs {
        for v in 0..n {
            if fixed[h][v].is_none() {
                slot[h][v] = nvar;
                nvar += 1;
            }
        }
    }
    let mut out: Vec<Vec<f64>> = fixed.iter().map(|f| f.iter().map(|x| x.unwrap_or(0.0)).collect()).collect();
    if nvar == 0 {
        return Ok((out, SolveStatus::Trivial, 0));
    }
    let (cp, ri, val) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    let (mut pi, mut pj, mut pv) = (Vec::new(), Vec::new(), Vec::new());
    let mut q = vec![0.0; nvar];
    for h in 0..hs {
        for j in 0..n {
            for k in cp[j]..cp[j + 1] {
                let i = ri[k];
                match (slot[h][i], slot[h][j]) {
                    (usize::MAX, _) => {}
                    (si, usize::MAX) => q[si] += val[k] * out[h][j],
                    (si, sj) if si <= sj => {
                        pi.push(si);
                        pj.push(sj);
                        pv.push(val[k]);
                    }
                    _ => {}
                }
            }
        }
    }
    let diag: f64 = (0..pv.len()).filter(|&k| pi[k] == pj[k]).map(|k| pv[k]).sum();
    let scale = (diag / nvar as f64).max(f64::MIN_POSITIVE);
    pv.iter_mut().for_each(|x| *x /= scale);
    q.iter_mut().for_each(|x| *x /= scale);
    // rows: partition of unity (zero cone), then −x ≤ 0 and x ≤ 1
    let (mut ar, mut ac, mut av, mut b) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for v in 0..n {
        let fixed_sum: f64 = (0..hs).filter_map(|h| fixed[h][v]).sum();
        let free: Vec<usize> = (0..hs).filter_map(|h| (slot[h][v] != usize::MAX).then_some(slot[h][v])).collect();
        if free.is_empty() {
            if (fixed_sum - 1.0).abs() > 1e-12 {
                return Err(Error::input(format!("the fixed weights at vertex {v} sum to {fixed_sum}, not 1")));
            }
            continue;
        }
        let row = b.len();
        for s in free {
            ar.push(row);
            ac.push(s);
            av.push(1.0);
        }
        b.push(1.0 - fixed_sum);
    }
    let eq = b.len();
    for s in 0..nvar {
        ar.extend([eq + 2 * s, eq + 2 * s + 1]);
        ac.extend([s, s]);
        av.extend([-1.0, 1.0]);
        b.extend([0.0, 1.0]);
    }
    let pm = CscMatrix::new_from_triplets(nvar, nvar, pi, pj, pv);
    let am = CscMatrix::new_from_triplets(b.len(), nvar, ar, ac, av);
    let cones = [ZeroConeT(eq), NonnegativeConeT(2 * nvar)];
    let (x, _, status, it) = run(&pm, &q, &am, &b, &cones, settings)?;
    for h in 0..hs {
        for v in 0..n {
            if slot[h][v] != usize::MAX {
                out[h][v] = x[slot[h][v]];
            }
        }
    }
    Ok((out, status, it))
}
