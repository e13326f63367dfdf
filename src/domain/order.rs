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

/// Share of the gap to the next distinct value (the previous one for the top value) over
/// which [`sos_untied`] spreads a tie class: small, so that u stays the paper's where the
/// data has no ties (docs/grids.md section 5 has the measurements).
const TIE_SPREAD: f64 = 0.01;

/// The values with every tie broken as simulation of simplicity breaks it: strictly
/// increasing in (value, index) order, equal to the input wherever a value occurs once. The
/// `c` vertices of a tie class at x, in index order, take x + (y − x) j / (100 c)
/// (j = 0..c−1), y the next distinct value; the top class spreads downwards from the maximum
/// instead, so the range is the input's. Where doubles are too coarse for that, the next
/// double up is taken. A constant field is returned unchanged.
pub fn sos_untied(values: &[f64]) -> Vec<f64> {
    let order = sos_sort(values);
    let mut g = values.to_vec();
    let n = order.len();
    let mut start = 0;
    while start < n {
        let x = values[order[start]];
        let end = (start..n).find(|&j| values[order[j]] != x).unwrap_or(n);
        let c = end - start;
        if c > 1 {
            let class = &order[start..end];
            if end < n {
                let step = TIE_SPREAD * (values[order[end]] - x) / c as f64;
                for (j, &v) in class.iter().enumerate() {
                    g[v] = x + step * j as f64;
                }
            } else if start > 0 {
                let step = TIE_SPREAD * (x - values[order[start - 1]]) / c as f64;
                for (j, &v) in class.iter().enumerate() {
                    g[v] = x - step * (c - 1 - j) as f64;
                }
            }
        }
        start = end;
    }
    if order.iter().any(|&v| values[v] != values[order[0]]) {
        for w in order.windows(2) {
            if g[w[1]] <= g[w[0]] {
                g[w[1]] = g[w[0]].next_up();
            }
        }
    }
    g
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

    #[test]
    fn untied_values_follow_the_sos_order() {
        let v = [1.0, 0.0, 1.0, 3.0, 1.0, 3.0, 2.0];
        let g = sos_untied(&v);
        // the class at 1 spreads over 1 % of the gap to 2, the top class down from 3
        let step = TIE_SPREAD / 3.0;
        assert_eq!(g, [1.0, 0.0, 1.0 + step, 3.0 - TIE_SPREAD / 2.0, 1.0 + 2.0 * step, 3.0, 2.0]);
        assert_eq!(sos_sort(&g), sos_sort(&v));
        // doubles too coarse for the spread: the next one up, still in SoS order
        let tiny = [1.0, 1.0, 1.0, 1.0f64.next_up()];
        let g = sos_untied(&tiny);
        assert!(g.windows(2).all(|w| w[0] < w[1]), "{g:?}");
        assert_eq!(sos_untied(&[2.0, 2.0]), [2.0, 2.0]);
    }
}
