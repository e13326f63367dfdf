//! Harmonic interpolation: `K u = 0` at free vertices, given values at fixed ones.

use super::sparse::Sparse;
use crate::linalg::solve_spd_once;
use faer::sparse::Triplet;

/// Solves `(K u)_i = 0` for every free vertex `i` with `u_j = fixed_j` where given (Dirichlet
/// problem), by sparse Cholesky of `K_FF` (faer). With non-positive off-diagonal weights (a
/// Laplacian obeying the maximum principle) every free value lies between the fixed values
/// it is connected to.
///
/// # Errors
/// A message if `K_FF` is not positive definite (a free part with no fixed vertex).
pub fn dirichlet_solve(k: &Sparse, fixed: &[Option<f64>]) -> Result<Vec<f64>, String> {
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
                (si, sj) if si <= sj => t.push(Triplet::new(si, sj, val[p])),
                _ => {}
            }
        }
    }
    let a = Sparse::try_new_from_triplets(nf, nf, &t).map_err(|e| format!("{e:?}"))?;
    solve_spd_once(a.as_ref(), &mut rhs)
        .map_err(|_| "a free part of the domain touches no fixed vertex".to_string())?;
    for (k, &i) in free.iter().enumerate() {
        u[i] = rhs[k];
    }
    Ok(u)
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
    }
}
