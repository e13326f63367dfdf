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

/// From this many rows the band is factorised from both ends at once (below, from the top
/// only). The choice depends on the size alone, so that every thread count gives the same
/// factor and the same bits.
const TWO_WAY_FROM: usize = 1 << 14;

/// The factor of a symmetric banded matrix `A` (half-width `b`).
///
/// Small matrices: `A = L D Lᵀ` from the top. From [`TWO_WAY_FROM`] rows, a twisted
/// factorisation that puts both cores on it: the rows are split into a top part `T = 0..p`,
/// a separator `S = p..p + b` and a bottom part `B = p + b..n`, which `S` decouples. `A_TT`
/// is factorised from the top, `A_BB` from the bottom (as the reversed matrix's top), both at
/// once, and `S` takes the Schur complement `A_SS − A_ST A_TT⁻¹ A_TS − A_SB A_BB⁻¹ A_BS`
/// (dense, `b × b`: only the `b` rows of each part next to `S` touch it). A solve runs the two
/// parts' forward sweeps at once, solves on `S`, then the two backward sweeps at once. At
/// 10⁷ samples the factorisation and the four solves of an interior-point iteration were
/// sequential chains of dependent products (one row after the other), most of an iteration
/// in double-double.
pub(super) struct Banded<T> {
    n: usize,
    b: usize,
    /// The matrix as a band: `a[j·(b + 1) + t]` is the entry `(j − b + t, j)`, `t = b` the diagonal.
    a: Vec<T>,
    /// The top part's factor (all rows when the matrix is not split).
    top: Part<T>,
    /// The bottom part's factor in reversed row order, and the separator.
    split: Option<Split<T>>,
}

/// `L D Lᵀ` of a band of `n` rows: row `j` of `L` left of the diagonal (columns `j − b .. j`,
/// those before column 0 zero) and `1 / D`.
struct Part<T> {
    l: Vec<T>,
    inv_d: Vec<T>,
}

/// The bottom part and the separator of the two-way factorisation.
struct Split<T> {
    /// The first separator row `p` (the top part has `p` rows, the bottom `n − p − b`).
    p: usize,
    bottom: Part<T>,
    /// `Z = L⁻¹ A_XS` of each part on its last `b` rows (next to `S`): `b × b`, row-major,
    /// rows in the part's own order, columns in `S`'s natural order.
    z_top: Vec<T>,
    z_bottom: Vec<T>,
    /// The Schur complement's `L D Lᵀ`, dense `b × b` (row-major, unit lower), and `1 / D`.
    s_l: Vec<T>,
    s_inv_d: Vec<T>,
}

impl<T: Real> Part<T> {
    fn new(n: usize, b: usize) -> Part<T> {
        let zero = T::of(0.0);
        Part { l: vec![zero; n * b], inv_d: vec![zero; n] }
    }

    /// Factorises the band whose row `j`, entry `t`, is `a(j, t)` (the layout of
    /// [`Banded::band_mut`]: the entry `(j − b + t, j)`) plus `shift` on the diagonal; `false`
    /// if a pivot is not positive.
    fn factor(&mut self, a: impl Fn(usize, usize) -> T, b: usize, shift: T) -> bool {
        let n = self.inv_d.len();
        let zero = T::of(0.0);
        let one = T::of(1.0);
        // row j of L·D, columns j − b .. j, scratch
        let mut ld = vec![zero; b];
        for j in 0..n {
            let first = j.saturating_sub(b);
            let row = j * b;
            for k in first..j {
                // L_jk = (A_kj − Σ_{p<k} L_jp D_p L_kp) / D_k
                let mut s = a(j, b - (j - k));
                for p in first..k {
                    s -= ld[p + b - j] * self.l[k * b + p + b - k];
                }
                ld[k + b - j] = s;
                self.l[row + k + b - j] = s * self.inv_d[k];
            }
            let mut d = a(j, b) + shift;
            for k in first..j {
                d -= ld[k + b - j] * self.l[row + k + b - j];
            }
            if d.partial_cmp(&zero) != Some(std::cmp::Ordering::Greater) {
                return false;
            }
            self.inv_d[j] = one / d;
        }
        true
    }

    /// `x ← L⁻¹ x`.
    #[allow(clippy::needless_range_loop)] // rows of the band and entries of x indexed together
    fn forward(&self, b: usize, x: &mut [T]) {
        for j in 0..x.len() {
            let first = j.saturating_sub(b);
            let mut s = x[j];
            for k in first..j {
                s -= self.l[j * b + k + b - j] * x[k];
            }
            x[j] = s;
        }
    }

    /// `x ← L⁻ᵀ D⁻¹ x`.
    #[allow(clippy::needless_range_loop)] // rows of the band and entries of x indexed together
    fn backward(&self, b: usize, x: &mut [T]) {
        let n = x.len();
        for j in (0..n).rev() {
            // the farthest rows first: the row just solved (j + 1) ends the dependent chain
            let mut s = x[j] * self.inv_d[j];
            for i in (j + 1..(j + b + 1).min(n)).rev() {
                s -= self.l[i * b + j + b - i] * x[i];
            }
            x[j] = s;
        }
    }

    /// `Z = L⁻¹ C` on the last `b` rows, `C` the `b` columns of the coupling to the separator
    /// given on those rows (`c[r·b + s]`, row `r` of the last `b`): `L` restricted to them is
    /// the trailing unit lower triangle, which alone maps them.
    fn last_rows_solve(&self, b: usize, c: &[T]) -> Vec<T> {
        let n = self.inv_d.len();
        let mut z = c.to_vec();
        for r in 0..b {
            let j = n - b + r;
            for k in 0..r {
                let lk = self.l[j * b + (n - b + k) + b - j];
                for s in 0..b {
                    z[r * b + s] = z[r * b + s] - lk * z[k * b + s];
                }
            }
        }
        z
    }
}

impl<T: Real + Send + Sync> Banded<T> {
    /// Storage for `n × n` matrices within `b` places of the diagonal, filled through
    /// [`Banded::band_mut`].
    pub(super) fn of_band(n: usize, b: usize) -> Banded<T> {
        let zero = T::of(0.0);
        let a = vec![zero; n * (b + 1)];
        if n < TWO_WAY_FROM.max(4 * b + 4) {
            return Banded { n, b, a, top: Part::new(n, b), split: None };
        }
        let p = n / 2;
        let nb = n - p - b;
        let split = Split {
            p,
            bottom: Part::new(nb, b),
            z_top: vec![zero; b * b],
            z_bottom: vec![zero; b * b],
            s_l: vec![zero; b * b],
            s_inv_d: vec![zero; b],
        };
        Banded { n, b, a, top: Part::new(p, b), split: Some(split) }
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
    #[allow(clippy::needless_range_loop)] // the separator's dense b × b entries indexed together
    pub(super) fn factor_band(&mut self, shift: T) -> bool {
        let (n, b) = (self.n, self.b);
        let a = &self.a;
        let natural = |j: usize, t: usize| a[j * (b + 1) + t];
        let Some(split) = self.split.as_mut() else {
            return self.top.factor(natural, b, shift);
        };
        let p = split.p;
        let nb = n - p - b;
        // the bottom part reversed: its row j, entry t, is the matrix's (n−1−j, n−1−j + b − t)
        let reversed = |j: usize, t: usize| {
            let (row, col) = (n - 1 - j, n - 1 - j + b - t);
            if col < n {
                a[Self::at(b, row, col)]
            } else {
                T::of(0.0)
            }
        };
        let (top, bottom) = (&mut self.top, &mut split.bottom);
        let (ok_top, ok_bottom) =
            crate::parallel::join(|| top.factor(natural, b, shift), || bottom.factor(reversed, b, shift));
        if !(ok_top && ok_bottom) {
            return false;
        }
        // the couplings of each part's last b rows to S, and Z = L⁻¹ C on them
        let entry = |i: usize, j: usize| {
            let (i, j) = (i.min(j), i.max(j));
            if j - i > b {
                T::of(0.0)
            } else {
                a[Self::at(b, i, j)]
            }
        };
        let mut c = vec![T::of(0.0); b * b];
        for r in 0..b {
            for s in 0..b {
                c[r * b + s] = entry(p - b + r, p + s);
            }
        }
        split.z_top = self.top.last_rows_solve(b, &c);
        for r in 0..b {
            // the reversed bottom's row nb − b + r is the matrix's row p + b + (b − 1 − r)
            for s in 0..b {
                c[r * b + s] = entry(p + 2 * b - 1 - r, p + s);
            }
        }
        split.z_bottom = split.bottom.last_rows_solve(b, &c);
        // S = A_SS − Zᵀ D⁻¹ Z of both parts, then its dense L D Lᵀ
        let mut schur = vec![T::of(0.0); b * b];
        for i in 0..b {
            for j in 0..b {
                let mut v = entry(p + i, p + j);
                if i == j {
                    v += shift;
                }
                for r in 0..b {
                    v -= split.z_top[r * b + i] * self.top.inv_d[p - b + r] * split.z_top[r * b + j];
                    v -= split.z_bottom[r * b + i] * split.bottom.inv_d[nb - b + r] * split.z_bottom[r * b + j];
                }
                schur[i * b + j] = v;
            }
        }
        let one = T::of(1.0);
        let mut pivots = vec![T::of(0.0); b];
        for j in 0..b {
            let mut d = schur[j * b + j];
            for k in 0..j {
                d -= split.s_l[j * b + k] * split.s_l[j * b + k] * pivots[k];
            }
            if d.partial_cmp(&T::of(0.0)) != Some(std::cmp::Ordering::Greater) {
                return false;
            }
            pivots[j] = d;
            split.s_inv_d[j] = one / d;
            split.s_l[j * b + j] = one;
            for i in j + 1..b {
                let mut v = schur[i * b + j];
                for k in 0..j {
                    v -= split.s_l[i * b + k] * split.s_l[j * b + k] * pivots[k];
                }
                split.s_l[i * b + j] = v * split.s_inv_d[j];
            }
        }
        true
    }

    /// Overwrites `x` with the factorised matrix's inverse times it.
    #[allow(clippy::needless_range_loop)] // the separator's dense b × b entries indexed together
    pub(super) fn solve_in_place(&self, x: &mut [T]) {
        let b = self.b;
        let Some(split) = &self.split else {
            self.top.forward(b, x);
            self.top.backward(b, x);
            return;
        };
        let p = split.p;
        let (xt, rest) = x.split_at_mut(p);
        let (xs, xb) = rest.split_at_mut(b);
        // the bottom part in its own (reversed) order
        xb.reverse();
        crate::parallel::join(|| self.top.forward(b, xt), || split.bottom.forward(b, xb));
        // the separator's right-hand side, its solve
        let (nt, nb) = (xt.len(), xb.len());
        for s in 0..b {
            let mut v = xs[s];
            for r in 0..b {
                v -= split.z_top[r * b + s] * self.top.inv_d[nt - b + r] * xt[nt - b + r];
                v -= split.z_bottom[r * b + s] * split.bottom.inv_d[nb - b + r] * xb[nb - b + r];
            }
            xs[s] = v;
        }
        for i in 0..b {
            for k in 0..i {
                xs[i] -= split.s_l[i * b + k] * xs[k];
            }
        }
        for i in 0..b {
            xs[i] = xs[i] * split.s_inv_d[i];
        }
        for i in (0..b).rev() {
            for k in i + 1..b {
                xs[i] -= split.s_l[k * b + i] * xs[k];
            }
        }
        // each part less its coupling to the separator, then its backward sweep
        for r in 0..b {
            for s in 0..b {
                xt[nt - b + r] -= split.z_top[r * b + s] * xs[s];
                xb[nb - b + r] -= split.z_bottom[r * b + s] * xs[s];
            }
        }
        crate::parallel::join(|| self.top.backward(b, xt), || split.bottom.backward(b, xb));
        xb.reverse();
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
    fn factor<T: Real + Send + Sync>(
        f: &mut Banded<T>,
        p: &faer::sparse::SymbolicSparseColMat<usize>,
        v: &[T],
        shift: T,
    ) -> bool {
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

    /// A symmetric band of half-width `b`, diagonally dominant, with varying entries.
    fn band<T: Real + Send + Sync>(n: usize, b: usize) -> (Banded<T>, Vec<f64>) {
        let mut f = Banded::<T>::of_band(n, b);
        let mut full = vec![0.0; n * (b + 1)];
        let band = f.band_mut();
        for j in 0..n {
            for i in j.saturating_sub(b)..=j {
                let v = if i == j {
                    2.0 * b as f64 + 0.5 + (j as f64 * 0.13).sin().abs()
                } else {
                    ((i * 7 + j) as f64).cos()
                };
                band[Banded::<T>::at(b, i, j)] = T::of(v);
                full[Banded::<T>::at(b, i, j)] = v;
            }
        }
        (f, full)
    }

    #[test]
    fn the_two_way_factor_solves_to_rounding_with_the_same_bits_on_every_thread_count() {
        for b in 1..=4 {
            let n = TWO_WAY_FROM + 13 * b;
            let (mut f, full) = band::<f64>(n, b);
            assert!(f.split.is_some(), "n = {n} is split");
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 1e-4 * i as f64).collect();
            let mut rhs = vec![0.0; n];
            for j in 0..n {
                for i in j.saturating_sub(b)..=j {
                    let a = full[Banded::<f64>::at(b, i, j)];
                    rhs[i] += a * x[j];
                    if i != j {
                        rhs[j] += a * x[i];
                    }
                }
            }
            let solve = |f: &mut Banded<f64>, threads: usize| {
                crate::parallel::with_threads(threads, || {
                    assert!(f.factor_band(0.0));
                    let mut y = rhs.clone();
                    f.solve_in_place(&mut y);
                    y
                })
            };
            let y1 = solve(&mut f, 1);
            let err = y1.iter().zip(&x).fold(0.0f64, |a, (y, x)| a.max((y - x).abs()));
            assert!(err < 1e-12, "b = {b}: error {err:e}");
            let y2 = solve(&mut f, 2);
            assert!(y1.iter().zip(&y2).all(|(a, c)| a.to_bits() == c.to_bits()), "b = {b}: bits differ");
            // in double-double, against the same matrix
            let (mut fq, _) = band::<Dd>(n, b);
            assert!(fq.factor_band(Dd::from(0.0)));
            let mut yq: Vec<Dd> = rhs.iter().map(|&a| Dd::from(a)).collect();
            fq.solve_in_place(&mut yq);
            let err = yq.iter().zip(&x).fold(0.0f64, |a, (y, x)| a.max((y.to_f64() - x).abs()));
            assert!(err < 1e-14, "b = {b}, double-double: error {err:e}");
            // indefinite: refused whether the failing pivot is in a part or in the separator
            assert!(!f.factor_band(-1e3));
            let p = f.split.as_ref().unwrap().p;
            let diag = Banded::<f64>::at(b, p, p);
            let keep = f.band_mut()[diag];
            f.band_mut()[diag] = -1.0;
            assert!(!f.factor_band(0.0), "b = {b}: a negative separator pivot");
            f.band_mut()[diag] = keep;
            assert!(f.factor_band(0.0));
        }
    }
}
