//! `LDLᵀ` of a symmetric banded matrix in the iteration's arithmetic, with reciprocal pivots:
//! the normal matrix on a series, in double (the assembled form) or double-double (the
//! factored form).
//!
//! In double, faer's simplicial factorisation and solves of a pentadiagonal matrix spend
//! most of their time on the general pattern's bookkeeping (at 10⁷ samples about 0.3 s a
//! factorisation); the band's own loops do the n·b² products alone.
//!
//! faer's simplicial Cholesky in double-double divides by a pivot for every entry of the
//! factor and of each triangular solve; a double-double division costs about ten products, and
//! on a series of 10⁶ samples those divisions were a quarter of the solver's time. Here each
//! pivot is inverted once, and the factorisation and both solves multiply.

use super::newton::Real;

/// The factor: `L` unit lower triangular with `b` entries left of the diagonal per row, `D`.
pub(super) struct Banded<T> {
    n: usize,
    b: usize,
    /// Row `j` of `L` left of the diagonal, columns `j − b .. j` (entries before column 0 are 0).
    l: Vec<T>,
    /// `1 / D`.
    inv_d: Vec<T>,
    /// The matrix as a band: `a[j·(b + 1) + t]` is the entry `(j − b + t, j)`, `t = b` the diagonal.
    a: Vec<T>,
}

impl<T: Real> Banded<T> {
    /// Storage for `n × n` matrices within `b` places of the diagonal, filled through
    /// [`Banded::band_mut`].
    pub(super) fn of_band(n: usize, b: usize) -> Banded<T> {
        let zero = T::of(0.0);
        Banded { n, b, l: vec![zero; n * b], inv_d: vec![zero; n], a: vec![zero; n * (b + 1)] }
    }

    /// Where the entry `(i, j)`, `i ≤ j ≤ i + b`, is in the band of [`Banded::band_mut`].
    #[inline]
    pub(super) fn at(b: usize, i: usize, j: usize) -> usize {
        j * (b + 1) + b - (j - i)
    }

    /// The band: the entry `(i, j)`, `i ≤ j`, at [`Banded::at`]; its last values are those of
    /// the last matrix factorised.
    pub(super) fn band_mut(&mut self) -> &mut [T] {
        &mut self.a
    }

    /// The band's half-width `b`.
    pub(super) fn width(&self) -> usize {
        self.b
    }

    /// Factorises the band as filled (plus `shift` on the diagonal), leaving it as it is;
    /// `false` if a pivot is not positive.
    pub(super) fn factor_band(&mut self, shift: T) -> bool {
        let (n, b) = (self.n, self.b);
        let zero = T::of(0.0);
        let one = T::of(1.0);
        // row j of L·D, columns j − b .. j, scratch
        let mut ld = vec![zero; b];
        for j in 0..n {
            let first = j.saturating_sub(b);
            let row = j * b;
            for k in first..j {
                // L_jk = (A_kj − Σ_{p<k} L_jp D_p L_kp) / D_k
                let mut s = self.a[j * (b + 1) + b - (j - k)];
                for p in first..k {
                    s = s - ld[p + b - j] * self.l[k * b + p + b - k];
                }
                ld[k + b - j] = s;
                self.l[row + k + b - j] = s * self.inv_d[k];
            }
            let mut d = self.a[j * (b + 1) + b] + shift;
            for k in first..j {
                d = d - ld[k + b - j] * self.l[row + k + b - j];
            }
            if d.partial_cmp(&zero) != Some(std::cmp::Ordering::Greater) {
                return false;
            }
            self.inv_d[j] = one / d;
        }
        true
    }

    /// Overwrites `x` with the factorised matrix's inverse times it.
    #[allow(clippy::needless_range_loop)] // rows of the band and entries of x indexed together
    pub(super) fn solve_in_place(&self, x: &mut [T]) {
        let (n, b) = (self.n, self.b);
        for j in 0..n {
            let first = j.saturating_sub(b);
            let mut s = x[j];
            for k in first..j {
                s = s - self.l[j * b + k + b - j] * x[k];
            }
            x[j] = s;
        }
        for (xj, &inv) in x.iter_mut().zip(&self.inv_d) {
            *xj = *xj * inv;
        }
        for j in (0..n).rev() {
            let mut s = x[j];
            for i in j + 1..(j + b + 1).min(n) {
                s = s - self.l[i * b + j + b - i] * x[i];
            }
            x[j] = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::double_double::Dd;

    /// A pentadiagonal, diagonally dominant (so positive definite) matrix in upper-triangular
    /// storage.
    fn path(n: usize) -> (faer::sparse::SymbolicSparseColMat<usize>, Vec<f64>) {
        let (mut cp, mut ri, mut v) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in j.saturating_sub(2)..=j {
                ri.push(i);
                v.push(match j - i {
                    0 => 10.0 + 0.01 * j as f64,
                    1 => -3.0,
                    _ => 1.0,
                });
            }
            cp.push(ri.len());
        }
        (faer::sparse::SymbolicSparseColMat::new_checked(n, n, cp, None, ri), v)
    }

    fn multiply(p: &faer::sparse::SymbolicSparseColMat<usize>, v: &[f64], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        for j in 0..p.ncols() {
            for (&i, &a) in p.row_idx()[p.col_ptr()[j]..p.col_ptr()[j + 1]].iter().zip(&v[p.col_ptr()[j]..]) {
                y[i] += a * x[j];
                if i != j {
                    y[j] += a * x[i];
                }
            }
        }
        y
    }

    /// The factor of the pattern's values `v` plus `shift`, through the band.
    fn factor<T: Real>(f: &mut Banded<T>, p: &faer::sparse::SymbolicSparseColMat<usize>, v: &[T], shift: T) -> bool {
        let b = f.width();
        let band = f.band_mut();
        band.iter_mut().for_each(|a| *a = T::of(0.0));
        for j in 0..p.ncols() {
            for (&i, &a) in p.row_idx()[p.col_ptr()[j]..p.col_ptr()[j + 1]].iter().zip(&v[p.col_ptr()[j]..]) {
                band[Banded::<T>::at(b, i, j)] = a;
            }
        }
        f.factor_band(shift)
    }

    #[test]
    fn the_banded_factor_solves_in_double_and_in_double_double() {
        let n = 500;
        let (p, v) = path(n);
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.001 * i as f64).collect();
        let rhs = multiply(&p, &v, &x);
        let mut f = Banded::<f64>::of_band(n, 2);
        assert!(factor(&mut f, &p, &v, 0.0));
        let mut y = rhs.clone();
        f.solve_in_place(&mut y);
        let err = y.iter().zip(&x).fold(0.0f64, |a, (y, x)| a.max((y - x).abs()));
        assert!(err < 1e-9, "double: {err:e}");
        let vq: Vec<Dd> = v.iter().map(|&a| Dd::from(a)).collect();
        let mut fq = Banded::<Dd>::of_band(n, 2);
        assert!(factor(&mut fq, &p, &vq, Dd::from(0.0)));
        let mut yq: Vec<Dd> = rhs.iter().map(|&a| Dd::from(a)).collect();
        fq.solve_in_place(&mut yq);
        let err = yq.iter().zip(&x).fold(0.0f64, |a, (y, x)| a.max((y.to_f64() - x).abs()));
        assert!(err < 1e-12, "double-double: {err:e}");
        // an indefinite matrix is refused: a negative shift past the smallest eigenvalue
        assert!(!factor(&mut f, &p, &v, -20.0));
    }
}
