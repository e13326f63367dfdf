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

use super::problem::{constraint_rows_iter, MonotoneQp, Row};
use crate::linalg::double_double::Dd;

/// The gap bound of a point and what it is made of, in the units of the QP as given.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Optimality {
    /// Ĝ ≥ φ(f) − φ*. Without a data term on every free entry, `sᵀz + ½ ρᵀP⁻¹ρ` by one solve
    /// with `P` (infinite if that fails).
    pub gap: f64,
    /// Whether `gap` needed that solve (no data term): `distance` is then in the norm of `P`.
    pub by_solve: bool,
    /// `φ(f) − qᵀf` restricted to the quadratic part, `½ fᵀPf`: what the gap is measured
    /// against without a data term.
    pub energy: f64,
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
    /// `‖f − f*‖_D ≤ √(2 Ĝ)` (`‖f − f*‖_P` when `by_solve`), when f is feasible (`None` when
    /// some slack is negative).
    pub distance: Option<f64>,
    /// `fᵀ(P − diag(data))f` as [`super::Quadratic::quadratic_form_without_diagonal`] sums it
    /// (the same bits), made in the gradient's pass over P's columns where the gradient reads
    /// them (not in the factored form), with a data term.
    pub smoothness: Option<f64>,
}

fn dd(x: f64) -> Dd {
    Dd::from(x)
}

/// `a · b` exactly.
fn product(a: f64, b: f64) -> Dd {
    dd(a) * dd(b)
}

fn round(x: Dd) -> f64 {
    x.to_f64()
}

/// The gap bound of `f` (`#V`, fixed entries at their values) with multipliers `z` (one per
/// row of [`super::problem::constraint_rows`], clamped at 0) and, in the factored form, auxiliary variables
/// `y` (one per row of `qp.factor`).
///
/// # Panics
/// If the lengths disagree with the problem.
pub fn optimality(qp: &MonotoneQp<'_>, f: &[f64], z: &[f64], y: Option<&[f64]>) -> Optimality {
    optimality_with(qp, f, z, y, None)
}

/// [`optimality`]; without a data term the solve with `P` takes its analysis from and keeps
/// it in `analyses` when given.
///
/// # Panics
/// As [`optimality`].
pub fn optimality_with(
    qp: &MonotoneQp<'_>,
    f: &[f64],
    z: &[f64],
    y: Option<&[f64]>,
    analyses: Option<&mut crate::linalg::Analyses>,
) -> Optimality {
    let n = qp.q.len();
    assert_eq!(f.len(), n);
    // the rows as they are read (at 10⁷ samples their list was 0.24 GB)
    let m = constraint_rows_iter(qp).count();
    assert_eq!(z.len(), m);
    let free: Vec<bool> = qp.fixed.iter().map(Option::is_none).collect();
    let (mut rho, auxiliary_residual, forms) = gradient(qp, f, y);
    let (complementarity, min_slack) = rows_into(qp, constraint_rows_iter(qp), f, z, &mut rho);
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
    let mut stationarity = round(stationarity);
    let by_solve = !bounded;
    if by_solve {
        // no data term: ½ ρᵀP⁻¹ρ by one solve with P on the free entries
        stationarity = solve_with_p(qp, &free, &rho, analyses).unwrap_or(f64::INFINITY);
    }
    let gap = complementarity + 0.5 * stationarity + 0.5 * auxiliary_residual * auxiliary_residual;
    let energy = forms.map_or_else(|| half_energy(qp.p, f), |(half, _)| half);
    let min_slack = if m == 0 { 0.0 } else { min_slack };
    Optimality {
        gap,
        by_solve,
        energy,
        data: 0.5 * round(data),
        min_slack,
        complementarity,
        dual_residual: stationarity.sqrt(),
        auxiliary_residual,
        distance: (gap.is_finite() && min_slack >= 0.0).then(|| (2.0 * gap.max(0.0)).sqrt()),
        smoothness: forms.and_then(|(_, smoothness)| smoothness),
    }
}

/// The objective's gradient at `f` in double-double, `ρ = P f + q` (or, factored, `D f + q +
/// Fᵀ y` with the auxiliary residual `|F f − y|`), over all entries (only the free ones count);
/// with `P f`, in the same pass over P's columns, [`half_energy`] and (with a data term)
/// [`Optimality::smoothness`], each summed as its own pass would (a pass of P's made columns
/// at 10⁷ samples is a second).
#[allow(clippy::type_complexity)]
fn gradient(qp: &MonotoneQp<'_>, f: &[f64], y: Option<&[f64]>) -> (Vec<Dd>, f64, Option<(f64, Option<f64>)>) {
    let n = qp.q.len();
    let mut rho = vec![dd(0.0); n];
    let mut auxiliary_residual = 0.0;
    match (y, qp.factor) {
        (Some(y), Some(factor)) => {
            let m = &factor.matrix;
            assert_eq!(y.len(), m.nrows());
            let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
            // F f − y
            let mut r: Vec<Dd> = y.iter().map(|&t| -dd(t)).collect();
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
            for (j, r) in rho.iter_mut().enumerate() {
                *r = dd(qp.q[j]);
            }
            let (mut e, mut smoothness) = (dd(0.0), 0.0);
            let d = qp.data;
            qp.p.for_each_column(|j, ri, v| {
                for (&i, &v) in ri.iter().zip(v) {
                    rho[i] += product(v, f[j]);
                    e += product(v, f[i]) * dd(f[j]);
                    if let Some(d) = d {
                        let aij = if i == j { v - d[j] } else { v };
                        smoothness += f[i] * aij * f[j];
                    }
                }
            });
            return (rho, auxiliary_residual, Some((0.5 * round(e), d.map(|_| smoothness))));
        }
    }
    (rho, auxiliary_residual, None)
}

/// Adds `Aᵀz` into `ρ`; returns the complementarity `Σ s z` and the smallest slack
/// `s = b − A f` (z clipped at 0).
fn rows_into(qp: &MonotoneQp<'_>, rows: impl Iterator<Item = Row>, f: &[f64], z: &[f64], rho: &mut [Dd]) -> (Dd, f64) {
    let mut complementarity = dd(0.0);
    let mut min_slack = f64::INFINITY;
    for (row, &zk) in rows.zip(z) {
        let zk = zk.max(0.0);
        // s = b − A f, and Aᵀz into ρ
        let s = match row {
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
    (complementarity, min_slack)
}

/// `½ fᵀ P f` in double-double (P holds both triangles).
fn half_energy(p: super::problem::Quadratic<'_>, f: &[f64]) -> f64 {
    let mut e = dd(0.0);
    p.for_each_column(|j, ri, v| {
        for (&i, &v) in ri.iter().zip(v) {
            e += product(v, f[i]) * dd(f[j]);
        }
    });
    0.5 * round(e)
}

/// `ρ_Fᵀ P_FF⁻¹ ρ_F` for the free entries (`None` if `P_FF` is not numerically positive
/// definite).
fn solve_with_p(
    qp: &MonotoneQp<'_>,
    free: &[bool],
    rho: &[Dd],
    analyses: Option<&mut crate::linalg::Analyses>,
) -> Option<f64> {
    let n = free.len();
    let mut slot = vec![usize::MAX; n];
    let mut nf = 0;
    for (i, &is_free) in free.iter().enumerate() {
        if is_free {
            slot[i] = nf;
            nf += 1;
        }
    }
    let mut t = Vec::new();
    qp.p.for_each_column(|j, ri, v| {
        for (&i, &v) in ri.iter().zip(v) {
            let (si, sj) = (slot[i], slot[j]);
            if si != usize::MAX && sj != usize::MAX && si <= sj {
                t.push(faer::sparse::Triplet::new(si, sj, v));
            }
        }
    });
    let upper = crate::operators::Sparse::try_new_from_triplets(nf, nf, &t).ok()?;
    let r: Vec<f64> = (0..n).filter(|&i| free[i]).map(|i| round(rho[i])).collect();
    let mut y = r.clone();
    crate::linalg::solve_spd(upper.as_ref(), &mut y, analyses).ok()?;
    Some(r.iter().zip(&y).map(|(a, b)| a * b).sum())
}
