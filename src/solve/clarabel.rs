//! Clarabel (faer's sparse LDLᵀ inside) on the reduced QP.

use super::qp::{MonotoneQp, QpSettings, ReducedQp, SolveStatus};
use crate::error::{Error, Result};
use crate::operators::Sparse;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus, SupportedConeT, ZeroConeT,
};

/// Solves `min ½ xᵀPx + qᵀx` s.t. `Ax ≤ b` (as `Ax + s = b`, `s ≥ 0`).
///
/// # Errors
/// [`Error::NoSolution`] for infeasibility certificates and non-finite output.
pub fn solve(r: &ReducedQp, settings: &QpSettings) -> Result<(Vec<f64>, SolveStatus, u32)> {
    let (pi, pj, pv): (Vec<usize>, Vec<usize>, Vec<f64>) = {
        let mut a = (Vec::with_capacity(r.p.len()), Vec::with_capacity(r.p.len()), Vec::with_capacity(r.p.len()));
        for &(i, j, v) in &r.p {
            a.0.push(i);
            a.1.push(j);
            a.2.push(v);
        }
        a
    };
    let p = CscMatrix::new_from_triplets(r.n, r.n, pi, pj, pv);
    let a = CscMatrix::new_from_triplets(r.m(), r.n, r.a_row.clone(), r.a_col.clone(), r.a_val.clone());
    let cones = [NonnegativeConeT(r.m())];
    run(&p, &r.q, &a, &r.b, &cones, settings)
}

/// The paper's appendix formulation: variables `(x, t)` with `t = F_free x + F_fixed f_fixed`
/// as equality rows, objective `½ xᵀ diag(d_free) x + ½ tᵀt + qᵀx` (the same scale as `r`),
/// and the inequality rows of `r`. Returns the free variables.
///
/// # Errors
/// As [`solve`].
pub fn solve_auxiliary(
    r: &ReducedQp,
    f: &Sparse,
    d: &[f64],
    qp: &MonotoneQp<'_>,
    free: &[usize],
    settings: &QpSettings,
) -> Result<(Vec<f64>, SolveStatus, u32)> {
    let n = qp.q.len();
    let (nf, rows) = (r.n, f.nrows());
    let mut slot = vec![usize::MAX; n];
    for (k, &i) in free.iter().enumerate() {
        slot[i] = k;
    }
    // P: diag(d_free) on x and the identity on t, divided by the scale of r
    let (mut pi, mut pj, mut pv) = (Vec::new(), Vec::new(), Vec::new());
    for (k, &i) in free.iter().enumerate() {
        if d[i] != 0.0 {
            pi.push(k);
            pj.push(k);
            pv.push(d[i] / r.scale);
        }
    }
    for t in 0..rows {
        pi.push(nf + t);
        pj.push(nf + t);
        pv.push(1.0 / r.scale);
    }
    let p = CscMatrix::new_from_triplets(nf + rows, nf + rows, pi, pj, pv);
    // the linear term of r carries P_FX x_X; here only the data part of it belongs to x (the
    // energy part lives in the equality rows' right-hand side)
    let mut q = vec![0.0; nf + rows];
    for (k, &i) in free.iter().enumerate() {
        q[k] = qp.q[i] / r.scale;
    }
    // rows: equalities F_free x − t = −F_fixed f_fixed, then r's inequalities
    let (mut ai, mut aj, mut av) = (Vec::new(), Vec::new(), Vec::new());
    let mut b = vec![0.0; rows];
    let (cp, ri, val) = (f.symbolic().col_ptr(), f.symbolic().row_idx(), f.val());
    for j in 0..n {
        for k in cp[j]..cp[j + 1] {
            match (slot[j], qp.fixed[j]) {
                (usize::MAX, Some(v)) => b[ri[k]] -= val[k] * v,
                (sj, _) => {
                    ai.push(ri[k]);
                    aj.push(sj);
                    av.push(val[k]);
                }
            }
        }
    }
    for t in 0..rows {
        ai.push(t);
        aj.push(nf + t);
        av.push(-1.0);
    }
    for (k, &row) in r.a_row.iter().enumerate() {
        ai.push(rows + row);
        aj.push(r.a_col[k]);
        av.push(r.a_val[k]);
    }
    b.extend_from_slice(&r.b);
    let a = CscMatrix::new_from_triplets(rows + r.m(), nf + rows, ai, aj, av);
    let cones = [ZeroConeT(rows), NonnegativeConeT(r.m())];
    let (x, status, it) = run(&p, &q, &a, &b, &cones, settings)?;
    Ok((x[..nf].to_vec(), status, it))
}

pub(super) fn run(
    p: &CscMatrix<f64>,
    q: &[f64],
    a: &CscMatrix<f64>,
    b: &[f64],
    cones: &[SupportedConeT<f64>],
    settings: &QpSettings,
) -> Result<(Vec<f64>, SolveStatus, u32)> {
    let tol = settings.tolerance.max(1e-10);
    let solver_settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(settings.max_iter)
        .tol_feas(tol)
        .tol_gap_abs(tol)
        .tol_gap_rel(tol)
        .direct_solve_method("faer".to_string())
        .build()
        .map_err(|e| Error::NoSolution { path: None, status: format!("bad solver settings: {e:?}") })?;
    let mut solver = DefaultSolver::new(p, q, a, b, cones, solver_settings)
        .map_err(|e| Error::NoSolution { path: None, status: format!("solver setup failed: {e}") })?;
    solver.solve();
    let sol = &solver.solution;
    let status = match sol.status {
        SolverStatus::Solved => SolveStatus::Solved,
        SolverStatus::AlmostSolved => SolveStatus::AlmostSolved,
        SolverStatus::MaxIterations | SolverStatus::MaxTime => SolveStatus::MaxIterations,
        SolverStatus::NumericalError | SolverStatus::InsufficientProgress => SolveStatus::Stalled,
        other => {
            return Err(Error::NoSolution {
                path: None,
                status: format!("Clarabel: {other:?} after {} iterations", sol.iterations),
            })
        }
    };
    if sol.x.iter().any(|v| !v.is_finite()) {
        return Err(Error::NoSolution {
            path: None,
            status: format!("Clarabel: {:?} with non-finite values", sol.status),
        });
    }
    Ok((sol.x.clone(), status, sol.iterations))
}
