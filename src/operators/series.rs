//! Linear finite elements on a series (the 1D cotangent Laplacian).

use super::sparse::Sparse;
use crate::domain::Series;

/// Stiffness `K = −L` (`#V × #V`) of piecewise-linear elements on a non-uniform series:
/// `K[i][i+1] = −1/h_i`, `K[i][i] = 1/h_{i−1} + 1/h_i`, so `fᵀ K f = ∫ f′²` exactly for the
/// piecewise-linear interpolant. Symmetric, positive semi-definite, `K·1 = 0`.
///
/// See also [`series_mass`].
pub fn series_stiffness(series: &Series) -> Sparse {
    let n = series.x().len();
    let w: Vec<f64> = series.spacings().into_iter().map(|h| 1.0 / h).collect();
    // tridiagonal, built column by column: rows j − 1, j, j + 1
    let mut col_ptr = Vec::with_capacity(n + 1);
    let (mut row_idx, mut val) = (Vec::with_capacity(3 * n), Vec::with_capacity(3 * n));
    col_ptr.push(0);
    for j in 0..n {
        // the intervals left and right of sample j (0 past an end: w + 0 is w exactly)
        let before = if j > 0 { w[j - 1] } else { 0.0 };
        let after = if j + 1 < n { w[j] } else { 0.0 };
        if j > 0 {
            row_idx.push(j - 1);
            val.push(-before);
        }
        row_idx.push(j);
        val.push(before + after);
        if j + 1 < n {
            row_idx.push(j + 1);
            val.push(-after);
        }
        col_ptr.push(row_idx.len());
    }
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    Sparse::new(symbolic, val)
}

/// Lumped (diagonal) mass: half of each adjacent interval, `M_ii = (h_{i−1} + h_i)/2`;
/// `Σ M_ii` is the length of the series. All entries are > 0 since `x` strictly increases.
pub fn series_mass(series: &Series) -> Vec<f64> {
    let n = series.x().len();
    let mut m = vec![0.0; n];
    for (i, h) in series.spacings().into_iter().enumerate() {
        m[i] += 0.5 * h;
        m[i + 1] += 0.5 * h;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::operators::quadratic_form;
    use crate::operators::sparse::{from_triplets, mul_vec};

    #[test]
    fn stiffness_is_the_sum_of_its_intervals() {
        // against the element-by-element assembly it replaces, entry for entry
        let s = Series::with_coordinates(vec![0.0, 0.5, 2.0, 2.25, 7.0]).unwrap();
        let mut t = Vec::new();
        for (i, h) in s.spacings().into_iter().enumerate() {
            let w = 1.0 / h;
            t.extend(
                [(i, i, w), (i + 1, i + 1, w), (i, i + 1, -w), (i + 1, i, -w)]
                    .map(|(a, b, v)| faer::sparse::Triplet::new(a, b, v)),
            );
        }
        let assembled = from_triplets(5, 5, &t);
        let k = series_stiffness(&s);
        assert_eq!(k.symbolic().col_ptr(), assembled.symbolic().col_ptr());
        assert_eq!(k.symbolic().row_idx(), assembled.symbolic().row_idx());
        assert_eq!(k.val(), assembled.val());
    }

    #[test]
    fn stiffness_is_the_dirichlet_energy() {
        let s = Series::with_coordinates(vec![0.0, 0.5, 2.0, 2.25]).unwrap();
        let k = series_stiffness(&s);
        for v in mul_vec(&k, &[1.0; 4]) {
            assert!(v.abs() < 1e-12);
        }
        // f = x² sampled: ∫ (f')² of the interpolant = Σ (Δf)²/h
        let f: Vec<f64> = s.x().iter().map(|x| x * x).collect();
        let exact: f64 = s.x().windows(2).map(|w| (w[1] * w[1] - w[0] * w[0]).powi(2) / (w[1] - w[0])).sum();
        assert!((quadratic_form(&k, &f) - exact).abs() < 1e-12 * exact);
        let m = series_mass(&s);
        assert!((m.iter().sum::<f64>() - 2.25).abs() < 1e-15);
        assert_eq!(m[0], 0.25);
    }
}
