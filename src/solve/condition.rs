//! How ill-conditioned the smoothing QP is: an estimate of the condition number of
//! `diag(d)^{-½} P diag(d)^{-½}` on the free variables, for a `P = Q + diag(d)` with `Q ⪰ 0`.
//!
//! Its smallest eigenvalue is at least 1 (`P ⪰ diag(d)`) and close to 1 whenever some smooth
//! function is nearly free of energy, so the largest eigenvalue is the estimate: for an energy
//! of order k with smoothing length ℓ on spacings h it is about `1 + 4^k (ℓ/h)^{2k}`.

use super::problem::ReducedQp;

/// Power iterations: the Rayleigh quotient of the largest eigenvalue, from a start with random
/// signs (the top eigenvector oscillates at the grid scale), settles within a few per cent.
const ITERATIONS: usize = 16;

/// `λ_max(diag(d)^{-½} P diag(d)^{-½})` by power iteration, or `None` without a data term on
/// every free variable.
pub(super) fn estimate(r: &ReducedQp) -> Option<f64> {
    if !r.gap_bound || r.n == 0 {
        return None;
    }
    Some(power(&r.d, |v, w| r.p.add_product(v, w)))
}

/// `estimate` on the free block of a full `P` (upper and lower triangle stored) with data
/// diagonal `d`, before the problem is reduced: `None` unless `d > 0` at every free entry.
///
/// Made columns ([`super::Quadratic::Columns`]) are multiplied in two passes over their
/// stiffness (the same matrix up to rounding, which an estimate does not see).
pub fn condition_estimate(p: super::Quadratic<'_>, d: &[f64], fixed: &[Option<f64>]) -> Option<f64> {
    let free: Vec<usize> = (0..d.len()).filter(|&i| fixed[i].is_none()).collect();
    if free.is_empty() || free.iter().any(|&i| d[i].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)) {
        return None;
    }
    let mut slot = vec![usize::MAX; d.len()];
    for (k, &i) in free.iter().enumerate() {
        slot[i] = k;
    }
    let df: Vec<f64> = free.iter().map(|&i| d[i]).collect();
    let p = match p {
        super::Quadratic::Stored(p) => p,
        super::Quadratic::Columns(c) => {
            let scratch = std::cell::RefCell::new((vec![0.0; d.len()], vec![0.0; d.len()], Vec::new()));
            return Some(power(&df, |v, w| {
                let (x, y, t) = &mut *scratch.borrow_mut();
                for (&i, &vi) in free.iter().zip(v) {
                    x[i] = vi;
                }
                y.iter_mut().for_each(|a| *a = 0.0);
                c.add_product(x, y, t);
                for (wk, &i) in w.iter_mut().zip(&free) {
                    *wk += y[i];
                }
            }));
        }
    };
    let (cp, ri, val) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
    // P is stored whole and symmetric, so column j is row j: each entry of `w` gathers its
    // own row, on contiguous pieces one a thread (the same sums for any thread count)
    Some(power(&df, |v, w| {
        crate::parallel::split_mut(w, |offset, w| {
            for (wk, &j) in w.iter_mut().zip(&free[offset..]) {
                let mut sum = 0.0;
                for q in cp[j]..cp[j + 1] {
                    let si = slot[ri[q]];
                    if si != usize::MAX {
                        sum += val[q] * v[si];
                    }
                }
                *wk += sum;
            }
        });
    }))
}

/// Power iteration on `diag(d)^{-½} A diag(d)^{-½}` for `w += A v` given by `apply`.
fn power(d: &[f64], apply: impl Fn(&[f64], &mut [f64])) -> f64 {
    let n = d.len();
    let root: Vec<f64> = d.iter().map(|d| 1.0 / d.sqrt()).collect();
    // a fixed pseudo-random ±1 start (xorshift), reproducible
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut v: Vec<f64> = (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            if state & 1 == 0 {
                1.0
            } else {
                -1.0
            }
        })
        .collect();
    let mut w = vec![0.0; n];
    let mut lambda = 1.0f64;
    for _ in 0..ITERATIONS {
        let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            break;
        }
        // u = v / ‖v‖; apply to D^{-½} u, scale by D^{-½}: w = S u
        v.iter_mut().zip(&root).for_each(|(a, r)| *a *= r / norm);
        w.iter_mut().for_each(|a| *a = 0.0);
        apply(&v, &mut w);
        w.iter_mut().zip(&root).for_each(|(a, r)| *a *= r);
        // the Rayleigh quotient uᵀ S u, with u = v / root
        let quotient: f64 = w.iter().zip(v.iter().zip(&root)).map(|(a, (b, r))| a * b / r).sum();
        lambda = lambda.max(quotient);
        std::mem::swap(&mut v, &mut w);
    }
    lambda.max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Series;
    use crate::operators::{plus_diagonal, polyharmonic, series_mass, series_stiffness, Energy};

    #[test]
    fn the_estimate_follows_four_to_the_k_times_the_length_ratio() {
        // uniform unit spacing: λ_max(M⁻¹K) → 4, so λ_max(D^{-½}PD^{-½}) → 1 + γ 4^k
        let s = Series::uniform(400);
        let (k, m) = (series_stiffness(&s), series_mass(&s));
        let fixed = vec![None; 400];
        for order in 1..=3u8 {
            let gamma = 10f64.powi(2 * order as i32); // ℓ = 10 samples
            let p = plus_diagonal(polyharmonic(&k, &m, &Energy::order(order), &[gamma]), &m);
            let est = condition_estimate((&p).into(), &m, &fixed).unwrap();
            let expected = 1.0 + gamma * 4f64.powi(order as i32);
            assert!(est <= expected * 1.05 && est >= expected * 0.7, "order {order}: {est:e} against {expected:e}");
        }
        // no data weight at a free vertex: no estimate
        let mut d = m.clone();
        d[3] = 0.0;
        assert!(condition_estimate((&series_stiffness(&s)).into(), &d, &fixed).is_none());
    }
}
