//! Linear finite elements on a series (the 1D cotangent Laplacian).

use super::sparse::{from_triplets, Sparse};
use crate::domain::Series;
use faer::sparse::Triplet;

/// Stiffness `K = −L` (`#V × #V`) of piecewise-linear elements on a non-uniform series:
/// `K[i][i+1] = −1/h_i`, `K[i][i] = 1/h_{i−1} + 1/h_i`, so `fᵀ K f = ∫ f′²` exactly for the
/// piecewise-linear interpolant. Symmetric, positive semi-definite, `K·1 = 0`.
///
/// See also [`series_mass`].
pub fn series_stiffness(series: &Series) -> Sparse {
    let n = series.x().len();
    let mut t = Vec::with_capacity(4 * n);
    for (i, h) in series.spacings().into_iter().enumerate() {
        let w = 1.0 / h;
        t.push(Triplet::new(i, i, w));
        t.push(Triplet::new(i + 1, i + 1, w));
        t.push(Triplet::new(i, i + 1, -w));
        t.push(Triplet::new(i + 1, i, -w));
    }
    from_triplets(n, n, &t)
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
    use crate::operators::sparse::mul_vec;

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
