//! Clarabel on the monotone QP, with the fixed entries eliminated.

use crate::error::{Error, Result};
use crate::operators::Sparse;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus,
};

/// The problem: `min ½ fᵀ P f + qᵀ f` s.t. `f_i = fixed_i` where given and
/// `f_j − f_i ≥ margin` for every `(i, j)` in `edges`.
pub struct MonotoneQp<'a> {
    /// `#V × #V` symmetric positive semi-definite (positive definite on the free block).
    pub p: &'a Sparse,
    /// Linear term, `#V`.
    pub q: &'a [f64],
    /// Fixed values, `#V` (`None` = free).
    pub fixed: &'a [Option<f64>],
    /// Ordered pairs `(i, j)`: `f_j − f_i ≥ margin`. Pairs of two fixed entries are ignored.
    pub edges: &'a [(usize, usize)],
    /// ε > 0.
    pub margin: f64,
}

/// Solver settings.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct QpSettings {
    /// Largest number of interior-point iterations. {200}
    pub max_iter: u32,
    /// Feasibility and gap tolerance (Clarabel's tol_feas, tol_gap_abs/rel). {1e-8}
    pub tolerance: f64,
}

impl Default for QpSettings {
    fn default() -> Self {
        QpSettings {
            max_iter: 200,
            tolerance: 1e-8,
        }
    }
}

/// How the solver ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum SolveStatus {
    /// Converged to the requested accuracy.
    Solved,
    /// Converged to a reduced accuracy.
    AlmostSolved,
    /// Stopped at the iteration limit with a point.
    MaxIterations,
    /// Stopped early (numerical trouble, no progress) with a point.
    Stalled,
    /// No constraint and no free variable needed the solver.
    Trivial,
}

/// A returned point (all entries, fixed ones set exactly) and how it was obtained.
#[derive(Clone, Debug)]
pub struct QpSolution {
    /// `#V` values.
    pub x: Vec<f64>,
    /// Solver outcome.
    pub status: SolveStatus,
    /// Interior-point iterations.
    pub iterations: u32,
}

/// Solves the monotone QP with Clarabel (faer's sparse LDLᵀ inside).
///
/// # Errors
/// [`Error::NoSolution`] when the solver returns no usable point (infeasibility
/// certificates, non-finite output).
pub fn solve_monotone_qp(qp: &MonotoneQp<'_>, settings: &QpSettings) -> Result<QpSolution> {
    let n = qp.q.len();
    assert_eq!(qp.fixed.len(), n);
    assert_eq!(qp.p.nrows(), n);
    let mut slot = vec![usize::MAX; n];
    let mut free = Vec::new();
    for (i, f) in qp.fixed.iter().enumerate() {
        if f.is_none() {
            slot[i] = free.len();
            free.push(i);
        }
    }
    let mut x: Vec<f64> = qp.fixed.iter().map(|f| f.unwrap_or(0.0)).collect();
    if free.is_empty() {
        return Ok(QpSolution {
            x,
            status: SolveStatus::Trivial,
            iterations: 0,
        });
    }
    let nf = free.len();
    // P_FF (upper triangle) and q_F + P_FX x_X
    let mut qf: Vec<f64> = free.iter().map(|&i| qp.q[i]).collect();
    let (cp, ri, val) = (
        qp.p.symbolic().col_ptr(),
        qp.p.symbolic().row_idx(),
        qp.p.val(),
    );
    let mut pi = Vec::new();
    let mut pj = Vec::new();
    let mut pv = Vec::new();
    for j in 0..n {
        for k in cp[j]..cp[j + 1] {
            let i = ri[k];
            let v = val[k];
            match (slot[i], slot[j]) {
                (usize::MAX, _) => {}
                (si, usize::MAX) => qf[si] += v * x[j],
                (si, sj) => {
                    if si <= sj {
                        pi.push(si);
                        pj.push(sj);
                        pv.push(v);
                    }
                }
            }
        }
    }
    // scale the objective so that its diagonal is of order one
    let diag_mean = {
        let mut s = 0.0;
        for k in 0..pi.len() {
            if pi[k] == pj[k] {
                s += pv[k];
            }
        }
        (s / nf as f64).max(f64::MIN_POSITIVE)
    };
    pv.iter_mut().for_each(|v| *v /= diag_mean);
    qf.iter_mut().for_each(|v| *v /= diag_mean);
    let p = CscMatrix::new_from_triplets(nf, nf, pi, pj, pv);
    // rows: f_i − f_j + s = −ε, s ≥ 0  ⇔  f_j − f_i ≥ ε
    let (mut ai, mut aj, mut av, mut b) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for &(i, j) in qp.edges {
        let row = b.len();
        match (qp.fixed[i], qp.fixed[j]) {
            (Some(_), Some(_)) => continue,
            (None, None) => {
                ai.extend([row, row]);
                aj.extend([slot[i], slot[j]]);
                av.extend([1.0, -1.0]);
                b.push(-qp.margin);
            }
            (Some(fi), None) => {
                ai.push(row);
                aj.push(slot[j]);
                av.push(-1.0);
                b.push(-qp.margin - fi);
            }
            (None, Some(fj)) => {
                ai.push(row);
                aj.push(slot[i]);
                av.push(1.0);
                b.push(fj - qp.margin);
            }
        }
    }
    let m = b.len();
    let a = CscMatrix::new_from_triplets(m, nf, ai, aj, av);
    let cones = [NonnegativeConeT(m)];
    let solver_settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(settings.max_iter)
        .tol_feas(settings.tolerance)
        .tol_gap_abs(settings.tolerance)
        .tol_gap_rel(settings.tolerance)
        .direct_solve_method("faer".to_string())
        .build()
        .map_err(|e| Error::NoSolution {
            path: None,
            status: format!("bad solver settings: {e:?}"),
        })?;
    let mut solver = DefaultSolver::new(&p, &qf, &a, &b, &cones, solver_settings).map_err(|e| {
        Error::NoSolution {
            path: None,
            status: format!("solver setup failed: {e}"),
        }
    })?;
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
                status: format!("{other:?} after {} iterations", sol.iterations),
            })
        }
    };
    if sol.x.iter().any(|v| !v.is_finite()) {
        return Err(Error::NoSolution {
            path: None,
            status: format!("{:?} with non-finite values", sol.status),
        });
    }
    for (k, &i) in free.iter().enumerate() {
        x[i] = sol.x[k];
    }
    Ok(QpSolution {
        x,
        status,
        iterations: sol.iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::operators::Sparse;
    use faer::sparse::Triplet;

    #[test]
    fn projects_onto_a_monotone_chain() {
        // min Σ (f_i − h_i)² with f_0 = 0, f_3 = 3 fixed and f increasing: h = [0, 2, 1, 3]
        let p = Sparse::try_new_from_triplets(
            4,
            4,
            &(0..4).map(|i| Triplet::new(i, i, 1.0)).collect::<Vec<_>>(),
        )
        .unwrap();
        let q = [0.0, -2.0, -1.0, -3.0];
        let fixed = [Some(0.0), None, None, Some(3.0)];
        let edges = [(0, 1), (1, 2), (2, 3)];
        let sol = solve_monotone_qp(
            &MonotoneQp {
                p: &p,
                q: &q,
                fixed: &fixed,
                edges: &edges,
                margin: 1e-6,
            },
            &QpSettings::default(),
        )
        .unwrap();
        assert!(matches!(
            sol.status,
            SolveStatus::Solved | SolveStatus::AlmostSolved
        ));
        // isotonic regression pools 2 and 1 at 1.5 (then the margin splits them)
        assert!(
            (sol.x[1] - 1.5).abs() < 1e-4 && (sol.x[2] - 1.5).abs() < 1e-4,
            "{:?}",
            sol.x
        );
        assert!(sol.x[2] - sol.x[1] > 0.5e-6);
        assert_eq!((sol.x[0], sol.x[3]), (0.0, 3.0));
    }
}
