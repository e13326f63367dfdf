//! The reduced QP's constraint rows as the active-set iteration reads them.

use super::super::problem::{constraint_rows_iter, MonotoneQp, Row as QpRow};

/// One constraint row of the reduced QP, in 16 bytes (at 256³ the 31.9 million rows took 1.0
/// GB as an enum of two indices of a word and a value): `x_a − x_b ≤ rhs`, or for a bound
/// `±x_a ≤ rhs` with `b` [`UPPER`] (`+`) or [`LOWER`] (`−`). Read through [`Row::kind`].
#[derive(Clone, Copy)]
pub(super) struct Row {
    a: u32,
    b: u32,
    rhs: f64,
}

/// [`Row::b`] of a bound `x_a ≤ rhs`.
const UPPER: u32 = u32::MAX;
/// [`Row::b`] of a bound `−x_a ≤ rhs`.
const LOWER: u32 = u32::MAX - 1;

/// A row as the iteration reads it.
#[derive(Clone, Copy)]
pub(super) enum RowKind {
    /// `x_i − x_j ≤ b` (b = −ε).
    Pair(usize, usize, f64),
    /// `a x_v ≤ b` with `a = ±1`: as an equality, `x_v = a b`.
    Bound(usize, f64, f64),
}

impl Row {
    /// `x_i − x_j ≤ b` (variables below [`LOWER`], which the iteration checks).
    pub(super) fn pair(i: usize, j: usize, b: f64) -> Row {
        debug_assert!(i < LOWER as usize && j < LOWER as usize);
        Row { a: i as u32, b: j as u32, rhs: b }
    }

    /// `a x_v ≤ b` for `a = ±1`.
    pub(super) fn bound(v: usize, a: f64, b: f64) -> Row {
        debug_assert!(v < LOWER as usize && a.abs() == 1.0);
        Row { a: v as u32, b: if a > 0.0 { UPPER } else { LOWER }, rhs: b }
    }

    /// The row's kind, ends and values.
    #[inline]
    pub(super) fn kind(self) -> RowKind {
        match self.b {
            UPPER => RowKind::Bound(self.a as usize, 1.0, self.rhs),
            LOWER => RowKind::Bound(self.a as usize, -1.0, self.rhs),
            b => RowKind::Pair(self.a as usize, b as usize, self.rhs),
        }
    }

    /// `aᵀx − b`.
    pub(super) fn violation(&self, x: &[f64]) -> f64 {
        -self.slack(x)
    }

    /// `b − aᵀx` as written (margin included).
    pub(super) fn slack(&self, x: &[f64]) -> f64 {
        match self.kind() {
            RowKind::Pair(i, j, b) => b - (x[i] - x[j]),
            RowKind::Bound(v, a, b) => b - a * x[v],
        }
    }
}

/// The reduced QP's rows (as `problem::reduce` writes them: fixed values substituted, in the
/// order of [`constraint_rows`]), `slot[v]` being `v`'s index among the free variables.
pub(super) fn rows_of(qp: &MonotoneQp<'_>, slot: &[usize]) -> Vec<Row> {
    let eps = qp.margin;
    constraint_rows_iter(qp)
        .map(|row| match row {
            // f_j − f_i ≥ ε  ⇔  f_i − f_j ≤ −ε
            QpRow::Pair(i, j) => match (qp.fixed[i], qp.fixed[j]) {
                (None, None) => Row::pair(slot[i], slot[j], -eps),
                (Some(fi), _) => Row::bound(slot[j], -1.0, -eps - fi),
                (None, Some(fj)) => Row::bound(slot[i], 1.0, fj - eps),
            },
            QpRow::Upper(v, c) => Row::bound(slot[v], 1.0, c),
            QpRow::Lower(v, c) => Row::bound(slot[v], -1.0, -c),
        })
        .collect()
}
