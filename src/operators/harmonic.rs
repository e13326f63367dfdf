//! Harmonic interpolation: `K u = 0` at free vertices, given values at fixed ones.

use super::sparse::Sparse;
use crate::linalg::{solve_spd, Analyses};
use faer::sparse::Triplet;

/// Solves `(K u)_i = 0` for every free vertex `i` with `u_j = fixed_j` where given (Dirichlet
/// problem), by sparse Cholesky of `K_FF` (faer). With non-positive off-diagonal weights (a
/// Laplacian obeying the maximum principle) every free value lies between the fixed values
/// it is connected to.
///
/// # Errors
/// A message if `K_FF` is not positive definite (a free part with no fixed vertex).
pub fn dirichlet_solve(
    k: &Sparse,
    fixed: &[Option<f64>],
) -> std::result::Result<Vec<f64>, crate::error::NumericalError> {
    dirichlet_solve_with(k, fixed, None)
}

/// [`dirichlet_solve`] with the analysis of `K_FF` taken from and kept in `analyses` when
/// given (the same fixed set solved again).
///
/// # Errors
/// As [`dirichlet_solve`].
pub fn dirichlet_solve_with(
    k: &Sparse,
    fixed: &[Option<f64>],
    analyses: Option<&mut Analyses>,
) -> std::result::Result<Vec<f64>, crate::error::NumericalError> {
    let n = k.nrows();
    assert_eq!(fixed.len(), n);
    let mut slot = vec![usize::MAX; n];
    let mut free = Vec::new();
    for i in 0..n {
        if fixed[i].is_none() {
            slot[i] = free.len();
            free.push(i);
        }
    }
    let mut u: Vec<f64> = fixed.iter().map(|f| f.unwrap_or(0.0)).collect();
    if free.is_empty() {
        return Ok(u);
    }
    let nf = free.len();
    let mut rhs = vec![0.0; nf];
    let mut t = Vec::new();
    let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    for j in 0..n {
        for p in cp[j]..cp[j + 1] {
            let i = ri[p];
            match (slot[i], slot[j]) {
                (usize::MAX, _) => {}
                (si, usize::MAX) => rhs[si] -= val[p] * u[j],
                (si, sj) if si == sj || (si < sj && val[p] != 0.0) => t.push(Triplet::new(si, sj, val[p])),
                _ => {}
            }
        }
    }
    let a = Sparse::try_new_from_triplets(nf, nf, &t).map_err(|e| format!("{e:?}"))?;
    solve_spd(a.as_ref(), &mut rhs, analyses)
        .map_err(|_| "a free part of the domain touches no fixed vertex".to_string())?;
    for (k, &i) in free.iter().enumerate() {
        u[i] = rhs[k];
    }
    Ok(u)
}

/// Repeated Dirichlet problems on one Laplacian with changing fixed sets: the matrix keeps
/// its pattern (fixed rows and columns become identity rows and explicit zeros; entries that
/// are exactly zero in the Laplacian are left out), so the Cholesky analysis is done once.
pub struct Dirichlet<'a> {
    k: &'a Sparse,
    /// Upper-triangle entries of `k` as (row, column, position in `k`'s values).
    upper: Vec<(usize, usize, usize)>,
    pattern: faer::sparse::SymbolicSparseColMat<usize>,
    solver: crate::linalg::SpdSolver,
}

impl<'a> Dirichlet<'a> {
    /// Analyses `k`'s pattern (square, symmetric, with every diagonal entry present), or
    /// takes its analysis from `analyses`.
    ///
    /// # Errors
    /// A message if the analysis fails.
    pub fn new(
        k: &'a Sparse,
        analyses: &mut crate::linalg::Analyses,
    ) -> std::result::Result<Self, crate::error::NumericalError> {
        let (upper, pattern) = Self::pattern(k);
        let solver = crate::linalg::SpdSolver::new(pattern.as_ref(), analyses)?;
        Ok(Dirichlet { k, upper, pattern, solver })
    }

    /// The upper-triangle entries of `k` the solves use, as (row, column, position in `k`'s
    /// values), and their pattern.
    fn pattern(k: &Sparse) -> (Vec<(usize, usize, usize)>, faer::sparse::SymbolicSparseColMat<usize>) {
        let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
        let mut upper = Vec::new();
        let mut col_ptr = Vec::with_capacity(k.ncols() + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for j in 0..k.ncols() {
            for (off, &i) in ri[cp[j]..cp[j + 1]].iter().enumerate() {
                // an exact zero (a grid's diagonal edge) only widens the factor: a grid's
                // Laplacian is then the 5-point stencil (7 entries a column otherwise)
                if i == j || (i < j && val[cp[j] + off] != 0.0) {
                    upper.push((i, j, cp[j] + off));
                    row_idx.push(i);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let n = k.nrows();
        (upper, faer::sparse::SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx))
    }

    /// The solution of `(K u)_i = 0` at free vertices with `u_j = fixed_j` where given.
    ///
    /// # Errors
    /// A message if a free part touches no fixed vertex.
    pub fn solve(&mut self, fixed: &[Option<f64>]) -> std::result::Result<Vec<f64>, crate::error::NumericalError> {
        let n = self.k.nrows();
        let val = self.k.val();
        let mut rhs: Vec<f64> = fixed.iter().map(|f| f.unwrap_or(0.0)).collect();
        let mut values = Vec::with_capacity(self.upper.len());
        for &(i, j, p) in &self.upper {
            values.push(match (fixed[i], fixed[j]) {
                (None, None) => val[p],
                (Some(_), Some(_)) if i == j => 1.0,
                (None, Some(uj)) => {
                    rhs[i] -= val[p] * uj;
                    0.0
                }
                (Some(ui), None) => {
                    rhs[j] -= val[p] * ui;
                    0.0
                }
                _ => 0.0,
            });
        }
        let a = faer::sparse::SparseColMatRef::new(self.pattern.as_ref(), &values);
        self.solver.solve(a, &mut rhs).map_err(|_| "a free part of the domain touches no fixed vertex".to_string())?;
        for (i, f) in fixed.iter().enumerate().take(n) {
            if let Some(v) = f {
                rhs[i] = *v;
            }
        }
        Ok(rhs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Grid2d;
    use crate::operators::grid_stiffness;

    #[test]
    fn linear_boundary_values_give_a_linear_function() {
        let g = Grid2d::with_geometry(5, 4, [0.5, 2.0], [0.0, 0.0]).unwrap();
        let k = grid_stiffness(&g);
        let f = |v: usize| {
            let [x, y] = g.position(v);
            2.0 * x - y
        };
        let fixed: Vec<Option<f64>> = (0..20)
            .map(|v| {
                let (r, c) = g.row_col(v);
                (r == 0 || r == 3 || c == 0 || c == 4).then(|| f(v))
            })
            .collect();
        let u = dirichlet_solve(&k, &fixed).unwrap();
        for (v, x) in u.iter().enumerate() {
            assert!((x - f(v)).abs() < 1e-12);
        }
        assert!(dirichlet_solve(&k, &vec![None; 20]).is_err());
        // the reusable solver gives the same answers for changing fixed sets
        let mut d = Dirichlet::new(&k, &mut Analyses::default()).unwrap();
        let u2 = d.solve(&fixed).unwrap();
        assert!(u.iter().zip(&u2).all(|(a, b)| (a - b).abs() < 1e-12));
        let mut fewer = fixed.clone();
        fewer[1] = None;
        fewer[19] = None;
        let (a, b) = (dirichlet_solve(&k, &fewer).unwrap(), d.solve(&fewer).unwrap());
        assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12));
        assert!(d.solve(&vec![None; 20]).is_err());
    }
}
