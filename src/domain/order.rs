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
///
/// A stable radix sort of the values' order-preserving bit patterns, the indices in
/// increasing order to begin with (so ties stay in index order): at 10⁷ samples a comparison
/// sort took 1.2 s, and a run sorts three fields. −0 sorts as +0 (equal values, as in
/// [`sos_less`]).
pub fn sos_sort(values: &[f64]) -> Vec<usize> {
    let mut keyed: Vec<(u64, usize)> = values.iter().enumerate().map(|(i, &v)| (order_key(v), i)).collect();
    radsort::sort_by_key(&mut keyed, |&(key, _)| key);
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// A key whose unsigned order is the order of finite doubles, −0 and +0 equal.
#[inline]
fn order_key(v: f64) -> u64 {
    let bits = (v + 0.0).to_bits(); // −0 + 0 = +0
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
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
    fn the_radix_order_is_the_comparison_order() {
        // negatives, both zeros, subnormals, huge values and ties by the thousand
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let special = [0.0, -0.0, 5e-324, -5e-324, f64::MIN_POSITIVE, -f64::MAX, f64::MAX, 1.0, -1.0];
        let v: Vec<f64> = (0..20_000)
            .map(|i| match next() % 4 {
                0 => special[i % special.len()],
                1 => (next() % 50) as f64 - 25.0,
                2 => f64::from_bits(next() >> 2) * if next() % 2 == 0 { 1.0 } else { -1.0 },
                _ => ((next() % 1000) as f64 - 500.0) * 1e-3,
            })
            .collect();
        let mut expected: Vec<usize> = (0..v.len()).collect();
        expected.sort_by(|&a, &b| v[a].partial_cmp(&v[b]).unwrap_or(Ordering::Equal).then(a.cmp(&b)));
        assert_eq!(sos_sort(&v), expected);
        assert!(expected.windows(2).all(|w| sos_less(&v, w[0], w[1])));
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
