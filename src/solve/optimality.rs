//! How far a point is from the QP's optimum, bounded without solving anything (SPEC.md, end of
//! "Exit status").
//!
//! For `min φ(f) = ½ fᵀPf + qᵀf` over the free entries with rows `A f ≤ b`, multipliers `z ≥ 0`
//! and `P ⪰ D = diag(d)`, weak duality gives, with `s = b − A f` and `ρ = ∇φ(f) + Aᵀz`,
//! `φ(f) − φ* ≤ sᵀz + ½ ρᵀP⁻¹ρ ≤ Ĝ = sᵀz + ½ ρᵀD⁻¹ρ`, and `φ(f) − φ* ≥ ½‖f − f*‖²_D` when f is
//! feasible. In the factored form `P = FᵀF + D` any auxiliary vector `y` gives the same kind of
//! bound, `Ĝ = ½‖F f − y‖² + sᵀz + ½ ρᵀD⁻¹ρ` with `ρ = D f + q + Fᵀy + Aᵀz` (the dual of the
//! problem with `t = F f` as equality rows); `y = F f` is the plain bound, and the solver's own
//! `y` keeps the rounding of an ill-conditioned `P` out of ρ.
//!
//! Everything is summed in double-double, so the bound measures the point, not the arithmetic.

use super::qp::{constraint_rows, MonotoneQp, Row};
use faer::fx128;

/// The gap bound of a point and what it is made of, in the units of the QP as given.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Optimality {
    /// Ĝ ≥ φ(f) − φ* (infinite without a data term on every free entry).
    pub gap: f64,
    /// The data term `½ Σ d_i (f_i − c_i)²` (with `q = −d∘c`).
    pub data: f64,
    /// The smallest slack `b − A f` (≥ 0 when f is feasible).
    pub min_slack: f64,
    /// `sᵀz`: the complementarity part of the bound.
    pub complementarity: f64,
    /// `√(ρᵀD⁻¹ρ)`: the stationarity residual in the data term's metric.
    pub dual_residual: f64,
    /// `‖F f − y‖` (factored form; 0 otherwise).
    pub auxiliary_residual: f64,
    /// `‖f − f*‖_D ≤ √(2 Ĝ)`, when f is feasible (`None` when some slack is negative).
    pub distance: Option<f64>,
}

fn dd(x: f64) -> fx128 {
    fx128::from(x)
}

fn product(a: f64, b: f64) -> fx128 {
    let p = a * b;
    dd(p) + dd(a.mul_add(b, -p))
}

fn round(x: fx128) -> f64 {
    x.0 + x.1
}

/// The gap bound of `f` (`#V`, fixed entries at their values) with multipliers `z` (one per
/// row of [`constraint_rows`], clamped at 0) and, in the factored form, auxiliary variables
/// `y` (one per row of `qp.factor`).
///
/// # Panics
/// If the lengths disagree with the problem.
pub fn optimality(qp: &MonotoneQp<'_>, f: &[f64], z: &[f64], y: Option<&[f64]>) -> Optimality {
    let n = qp.q.len();
    assert_eq!(f.len(), n);
    let rows = constraint_rows(qp);
    assert_eq!(z.len(), rows.len());
    let free: Vec<bool> = qp.fixed.iter().map(Option::is_none).collect();
    // ρ over all entries (only the free ones count)
    let mut rho = vec![dd(0.0); n];
    let mut auxiliary_residual = 0.0;
    match (y, qp.factor) {
        (Some(y), Some(factor)) => {
            let m = &factor.matrix;
            assert_eq!(y.len(), m.nrows());
            let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
            // F f − y
            let mut r: Vec<fx128> = y.iter().map(|&t| -dd(t)).collect();
            for j in 0..n {
                for p in cp[j]..cp[j + 1] {
                    r[ri[p]] += factor.entry(p) * dd(f[j]);
                }
            }
            auxiliary_residual = r.iter().map(|t| round(*t * *t)).sum::<f64>().sqrt();
            // D f + q + Fᵀ y
            for j in 0..n {
                let d = qp.data.map_or(0.0, |d| d[j]);
                let mut acc = product(d, f[j]) + dd(qp.q[j]);
                for p in cp[j]..cp[j + 1] {
                    acc += factor.entry(p) * dd(y[ri[p]]);
                }
                rho[j] = acc;
            }
        }
        _ => {
            // P f + q
            let (cp, ri, v) = (qp.p.symbolic().col_ptr(), qp.p.symbolic().row_idx(), qp.p.val());
            for (j, r) in rho.iter_mut().enumerate() {
                *r = dd(qp.q[j]);
            }
            for j in 0..n {
                for p in cp[j]..cp[j + 1] {
                    rho[ri[p]] += product(v[p], f[j]);
                }
            }
        }
    }
    let mut complementarity = dd(0.0);
    let mut min_slack = f64::INFINITY;
    for (row, &zk) in rows.iter().zip(z) {
        let zk = zk.max(0.0);
        // s = b − A f, and Aᵀz into ρ
        let s = match *row {
            Row::Pair(i, j) => {
                rho[i] += dd(zk);
                rho[j] -= dd(zk);
                dd(f[j]) - dd(f[i]) - dd(qp.margin)
            }
            Row::Upper(v, c) => {
                rho[v] += dd(zk);
                dd(c) - dd(f[v])
            }
            Row::Lower(v, c) => {
                rho[v] -= dd(zk);
                dd(f[v]) - dd(c)
            }
        };
        min_slack = min_slack.min(round(s));
        complementarity += s * dd(zk);
    }
    let mut stationarity = dd(0.0);
    let mut data = dd(0.0);
    let mut bounded = true;
    for j in 0..n {
        let d = qp.data.map_or(0.0, |d| d[j]);
        if d > 0.0 {
            // ½ d (f − c)² = ½ (d f + q)² / d
            let e = product(d, f[j]) + dd(qp.q[j]);
            data += e * e / dd(d);
        }
        if free[j] {
            if d > 0.0 {
                stationarity += rho[j] * rho[j] / dd(d);
            } else {
                bounded = false;
            }
        }
    }
    let complementarity = round(complementarity);
    let stationarity = round(stationarity);
    let gap = if bounded {
        complementarity + 0.5 * stationarity + 0.5 * auxiliary_residual * auxiliary_residual
    } else {
        f64::INFINITY
    };
    let min_slack = if rows.is_empty() { 0.0 } else { min_slack };
    Optimality {
        gap,
        data: 0.5 * round(data),
        min_slack,
        complementarity,
        dual_residual: stationarity.sqrt(),
        auxiliary_residual,
        distance: (bounded && min_slack >= 0.0).then(|| (2.0 * gap.max(0.0)).sqrt()),
    }
}
