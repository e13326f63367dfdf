//! Clarabel (faer's sparse LDLᵀ inside) on the reduced QP.

use super::qp::{QpSettings, ReducedQp, SolveStatus};
use crate::error::{Error, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};

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
    let mut solver = DefaultSolver::new(&p, &r.q, &a, &r.b, &cones, solver_settings)
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
