//! The reduced QP's constraint rows as the active-set iteration reads them.

use super::super::problem::{constraint_rows, MonotoneQp, Row as QpRow};

/// One constraint row of the reduced QP.
#[derive(Clone, Copy)]
pub(super) enum Row {
    /// `x_i − x_j ≤ b` (b = −ε).
    Pair(usize, usize, f64),
    /// `a x_v ≤ b` with `a = ±1`: as an equality, `x_v = a b`.
    Bound(usize, f64, f64),
}

impl Row {
    /// `aᵀx − b`.
    pub(super) fn violation(&self, x: &[f64]) -> f64 {
        -self.slack(x)
    }

    /// `b − aᵀx` as written (margin included).
    pub(super) fn slack(&self, x: &[f64]) -> f64 {
        match *self {
            Row::Pair(i, j, b) => b - (x[i] - x[j]),
            Row::Bound(v, a, b) => b - a * x[v],
        }
    }
}

/// The reduced QP's rows (as `problem::reduce` writes them: fixed values substituted, in the
/// order of [`constraint_rows`]), `slot[v]` being `v`'s index among the free variables.
pub(super) fn rows_of(qp: &MonotoneQp<'_>, slot: &[usize]) -> Vec<Row> {
    let eps = qp.margin;
    constraint_rows(qp)
        .into_iter()
        .map(|row| match row {
            // f_j − f_i ≥ ε  ⇔  f_i − f_j ≤ −ε
            QpRow::Pair(i, j) => match (qp.fixed[i], qp.fixed[j]) {
                (None, None) => Row::Pair(slot[i], slot[j], -eps),
                (Some(fi), _) => Row::Bound(slot[j], -1.0, -eps - fi),
                (None, Some(fj)) => Row::Bound(slot[i], 1.0, fj - eps),
            },
            QpRow::Upper(v, c) => Row::Bound(slot[v], 1.0, c),
            QpRow::Lower(v, c) => Row::Bound(slot[v], -1.0, -c),
        })
        .collect()
}
