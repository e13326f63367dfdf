//! Simulation of simplicity: vertices ordered by the pair (value, index) (SPEC.md).

use std::cmp::Ordering;

/// `(values[a], a) < (values[b], b)`. Values must be finite (checked when a field is read).
#[inline]
pub fn sos_less(values: &[f64], a: usize, b: usize) -> bool {
    match values[a].partial_cmp(&values[b]) {
        Some(Ordering::Less) => true,
        Some(Ordering::Greater) => false,
        _ => a < b,
    }
}

/// `(values[a], a) > (values[b], b)`.
#[inline]
pub fn sos_greater(values: &[f64], a: usize, b: usize) -> bool {
    a != b && !sos_less(values, a, b)
}

/// `(min, max)` of the values (`(+inf, −inf)` when there are none).
pub fn value_range<'a>(values: impl IntoIterator<Item = &'a f64>) -> (f64, f64) {
    values.into_iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)))
}

/// Vertex indices sorted ascending by (value, index): a total order, hence a topological
/// order of every edge orientation defined by it.
pub fn sos_sort(values: &[f64]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..values.len()).collect();
    // partial_cmp, as in `sos_less`: −0 and +0 are equal values, ordered by index
    idx.sort_unstable_by(|&a, &b| values[a].partial_cmp(&values[b]).unwrap_or(Ordering::Equal).then(a.cmp(&b)));
    idx
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ties_are_broken_by_index() {
        let v = [1.0, 1.0, 0.5];
        assert!(sos_less(&v, 0, 1));
        assert!(!sos_less(&v, 1, 0));
        assert!(sos_greater(&v, 1, 0));
        assert!(!sos_greater(&v, 1, 1));
        assert_eq!(sos_sort(&v), vec![2, 0, 1]);
        // signed zeros are one value: index decides, consistently with sos_less
        let z = [0.0, -0.0, 0.0];
        assert_eq!(sos_sort(&z), vec![0, 1, 2]);
        assert!(sos_less(&z, 0, 1) && sos_less(&z, 1, 2));
    }
}
