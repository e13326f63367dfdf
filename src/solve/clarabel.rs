//! Clarabel (faer's sparse LDLᵀ inside) on the reduced QP.

use super::problem::{ReducedFactor, ReducedQp};
use super::settings::QpSettings;
use super::status::{Outcome, SolveStatus};
use crate::error::{Error, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus, SupportedConeT, ZeroConeT,
};

/// Solves `min ½ xᵀPx + qᵀx` s.t. `Ax ≤ b` (as `Ax + s = b`, `s ≥ 0`); with the factored
/// form, on the paper's appendix formulation instead ([`solve_auxiliary`]).
///
/// # Errors
/// [`Error::NoSolution`] for infeasibility certificates and non-finite output.
pub(super) fn solve(r: &ReducedQp, settings: &QpSettings) -> Result<Outcome> {
    if let Some(factor) = &r.factor {
        return solve_auxiliary(r, factor, settings);
    }
    let (pi, pj, pv): (Vec<usize>, Vec<usize>, Vec<f64>) = {
        let mut a = (Vec::with_capacity(r.p.len()), Vec::with_capacity(r.p.len()), Vec::with_capacity(r.p.len()));
        for (i, j, v) in r.p.entries() {
            a.0.push(i);
            a.1.push(j);
            a.2.push(v);
        }
        a
    };
    let p = CscMatrix::new_from_triplets(r.n, r.n, pi, pj, pv);
    let (mut ai, mut aj, mut av) = (Vec::new(), Vec::new(), Vec::new());
    for (row, col, v) in r.rows.entries() {
        ai.push(row);
        aj.push(col);
        av.push(v);
    }
    let a = CscMatrix::new_from_triplets(r.m(), r.n, ai, aj, av);
    let cones = [NonnegativeConeT(r.m())];
    let (x, z, status, iterations) = run(&p, &r.q, &a, &r.b, &cones, settings)?;
    Ok(Outcome { x, z, y: None, status, iterations })
}

/// The paper's appendix formulation: variables `(x, t)` with `t = F x + g` as equality rows,
/// objective `½ xᵀ diag(d) x + ½ tᵀt + q_freeᵀx`, and the inequality rows of `r`. Returns the
/// free variables, the inequalities' multipliers and `t`.
///
/// # Errors
/// As [`solve`].
fn solve_auxiliary(r: &ReducedQp, factor: &ReducedFactor, settings: &QpSettings) -> Result<Outcome> {
    let (nf, rows) = (r.n, factor.f.nrows());
    let (mut pi, mut pj, mut pv) = (Vec::new(), Vec::new(), Vec::new());
    for (k, &d) in r.d.iter().enumerate() {
        if d != 0.0 {
            pi.push(k);
            pj.push(k);
            pv.push(d);
        }
    }
    for t in 0..rows {
        pi.push(nf + t);
        pj.push(nf + t);
        pv.push(1.0);
    }
    let p = CscMatrix::new_from_triplets(nf + rows, nf + rows, pi, pj, pv);
    let mut q = vec![0.0; nf + rows];
    q[..nf].copy_from_slice(&r.q_free);
    // rows: equalities F x − t = −g, then r's inequalities
    let (mut ai, mut aj, mut av) = (Vec::new(), Vec::new(), Vec::new());
    let f = &factor.f;
    let (cp, ri, val) = (f.symbolic().col_ptr(), f.symbolic().row_idx(), f.val());
    for j in 0..nf {
        for k in cp[j]..cp[j + 1] {
            ai.push(ri[k]);
            aj.push(j);
            av.push(val[k]);
        }
    }
    for t in 0..rows {
        ai.push(t);
        aj.push(nf + t);
        av.push(-1.0);
    }
    for (row, col, v) in r.rows.entries() {
        ai.push(rows + row);
        aj.push(col);
        av.push(v);
    }
    let mut b: Vec<f64> = factor.g.iter().map(|g| -g).collect();
    b.extend_from_slice(&r.b);
    let a = CscMatrix::new_from_triplets(rows + r.m(), nf + rows, ai, aj, av);
    let cones = [ZeroConeT(rows), NonnegativeConeT(r.m())];
    let (x, z, status, iterations) = run(&p, &q, &a, &b, &cones, settings)?;
    Ok(Outcome { x: x[..nf].to_vec(), z: z[rows..].to_vec(), y: Some(x[nf..].to_vec()), status, iterations })
}

/// Clarabel's duality-gap tolerances (absolute and relative to the objective). Its default
/// (1e-8, and the feasibility tolerance 1e-9 used before) is relative to the whole objective,
/// which the smoothness term can outweigh the data term by 10⁵: on the EUR/USD series at k = 2
/// the gap bound was then 3 % of the data term; at 1e-14 it is 2·10⁻⁸ of it (1e-16 reaches
/// 10⁻¹¹ in twice the iterations).
const GAP_TOLERANCE: f64 = 1e-14;

pub(super) fn run(
    p: &CscMatrix<f64>,
    q: &[f64],
    a: &CscMatrix<f64>,
    b: &[f64],
    cones: &[SupportedConeT<f64>],
    settings: &QpSettings,
) -> Result<(Vec<f64>, Vec<f64>, SolveStatus, u32)> {
    let tol = settings.tolerance.max(1e-10);
    let solver_settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(settings.max_iter)
        .tol_feas(tol)
        .tol_gap_abs(GAP_TOLERANCE)
        .tol_gap_rel(GAP_TOLERANCE)
        .direct_solve_method("faer".to_string())
        .build()
        .map_err(|e| Error::NoSolution { path: None, status: format!("bad solver settings: {e:?}") })?;
    let mut solver = DefaultSolver::new(p, q, a, b, cones, solver_settings)
        .map_err(|e| Error::NoSolution { path: None, status: format!("solver setup failed: {e}") })?;
    let observer = crate::progress::current();
    if observer.is_some() || crate::progress::token().is_some() {
        // called on this thread between iterations: true stops the solver (cancelled)
        solver.set_termination_callback(move |info: &clarabel::solver::DefaultInfo<f64>| {
            if let Some(observer) = &observer {
                observer.update(
                    "solve",
                    &format!(
                        "Clarabel iteration {}: relative gap {:.1e}, primal residual {:.1e}",
                        info.iterations, info.gap_rel, info.res_primal
                    ),
                );
            }
            crate::progress::cancelled()
        });
    }
    solver.solve();
    crate::progress::checkpoint()?;
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
    Ok((sol.x.clone(), sol.z.clone(), status, sol.iterations))
}
