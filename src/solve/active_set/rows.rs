//! The reduced QP's constraint rows as the active-set iteration reads them.

use super::super::problem::ReducedQp;
use crate::error::NumericalError;

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

pub(super) fn rows_of(r: &ReducedQp) -> std::result::Result<Vec<Row>, NumericalError> {
    let mut rows = Vec::with_capacity(r.m());
    let mut k = 0;
    while k < r.a_row.len() {
        let at = r.a_row[k];
        let two = k + 1 < r.a_row.len() && r.a_row[k + 1] == at;
        if two {
            let (i, j) = (r.a_col[k], r.a_col[k + 1]);
            match (r.a_val[k], r.a_val[k + 1]) {
                (a, b) if a == 1.0 && b == -1.0 => rows.push(Row::Pair(i, j, r.b[at])),
                (a, b) if a == -1.0 && b == 1.0 => rows.push(Row::Pair(j, i, r.b[at])),
                _ => return Err("a row is not a difference of two variables".into()),
            }
            k += 2;
        } else {
            let a = r.a_val[k];
            if a != 1.0 && a != -1.0 {
                return Err("a bound row has a coefficient other than ±1".into());
            }
            rows.push(Row::Bound(r.a_col[k], a, r.b[at]));
            k += 1;
        }
        if rows.len() != at + 1 {
            return Err("the rows are not stored in order".into());
        }
    }
    if rows.len() != r.m() {
        return Err("a row has no entry".into());
    }
    Ok(rows)
}
