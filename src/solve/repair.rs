//! Restoring strict order after an interior-point solve (NOTES.md 3).

/// What the repair changed.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct RepairSummary {
    /// Constrained edges that were not strictly increasing before the repair.
    pub violated_edges: usize,
    /// Free vertices whose value changed.
    pub changed_vertices: usize,
    /// Largest absolute change.
    pub max_change: f64,
    /// Sweeps (one forward and one backward pass each) that were run.
    pub sweeps: usize,
}

/// Makes `f_j > f_i` hold on every edge `(i, j)` by moving free vertices only.
///
/// `order` must be a topological order of the edges (e.g. vertices sorted by (u, index)).
/// A forward pass lifts each free `f_j` to at least `max f_i + δ` over its in-edges and a
/// backward pass lowers each free `f_i` to at most `min f_j − δ` over its out-edges (δ the
/// given step, or one ulp where that is smaller than the spacing of doubles). Fixed values
/// never change, so kept values stay bit for bit; the passes repeat (at most 4 sweeps) until
/// no edge is violated. Whether that succeeded is for the certificate to decide.
pub fn repair(f: &mut [f64], fixed: &[bool], edges: &[(usize, usize)], order: &[usize], delta: f64) -> RepairSummary {
    let n = f.len();
    // `strictly_below(a, b)` is false for NaN too, so NaN counts as a violation
    let strictly_below = |a: f64, b: f64| a.partial_cmp(&b) == Some(std::cmp::Ordering::Less);
    let violated = |f: &[f64]| edges.iter().filter(|&&(i, j)| !strictly_below(f[i], f[j])).count();
    let mut summary = RepairSummary { violated_edges: violated(f), ..Default::default() };
    if summary.violated_edges == 0 {
        return summary;
    }
    let original = f.to_vec();
    let mut preds: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut succs: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(i, j) in edges {
        preds[j].push(i);
        succs[i].push(j);
    }
    let above = |v: f64| (v + delta).max(v.next_up());
    let below = |v: f64| (v - delta).min(v.next_down());
    for _ in 0..4 {
        summary.sweeps += 1;
        for &v in order {
            if fixed[v] {
                continue;
            }
            if let Some(lo) = preds[v].iter().map(|&p| f[p]).reduce(f64::max) {
                if !strictly_below(lo, f[v]) {
                    f[v] = above(lo);
                }
            }
        }
        for &v in order.iter().rev() {
            if fixed[v] {
                continue;
            }
            if let Some(hi) = succs[v].iter().map(|&s| f[s]).reduce(f64::min) {
                if !strictly_below(f[v], hi) {
                    f[v] = below(hi);
                }
            }
        }
        if violated(f) == 0 {
            break;
        }
    }
    for (a, b) in original.iter().zip(f.iter()) {
        if a != b {
            summary.changed_vertices += 1;
            summary.max_change = summary.max_change.max((a - b).abs());
        }
    }
    summary
}

/// What [`meet_margin`] changed.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct MarginSummary {
    /// Whether every constrained edge now has `f_j − f_i ≥ margin` and every bound holds, in
    /// exact arithmetic on the doubles.
    pub met: bool,
    /// Free vertices whose value changed.
    pub changed_vertices: usize,
    /// Largest absolute change.
    pub max_change: f64,
}

/// `b − a ≥ m` exactly for doubles a, b, m (the difference of two doubles is exact in
/// double-double).
fn meets(a: f64, b: f64, m: f64) -> bool {
    let d = faer::fx128::from(b) - faer::fx128::from(a) - faer::fx128::from(m);
    d.0 > 0.0 || (d.0 == 0.0 && d.1 >= 0.0)
}

/// Moves free vertices so that the returned point is feasible for the QP as written: `f_j −
/// f_i ≥ margin` on every edge `(i, j)` and every bound, exactly (the interior-point solution
/// meets its rows only to its tolerance, so active rows come back a rounding short). Passes in
/// `order` (a topological order of the edges) lift each free `f_j` to its in-edges plus the
/// margin, passes in reverse lower it below its out-edges; fixed values never change. At most
/// 4 sweeps.
pub fn meet_margin(
    f: &mut [f64],
    fixed: &[bool],
    edges: &[(usize, usize)],
    order: &[usize],
    margin: f64,
    bounds: &[super::Bound],
) -> MarginSummary {
    let n = f.len();
    let mut upper = vec![f64::INFINITY; n];
    let mut lower = vec![f64::NEG_INFINITY; n];
    for b in bounds {
        if b.upper {
            upper[b.vertex] = upper[b.vertex].min(b.value);
        } else {
            lower[b.vertex] = lower[b.vertex].max(b.value);
        }
    }
    let feasible = |f: &[f64]| {
        edges.iter().all(|&(i, j)| meets(f[i], f[j], margin))
            && (0..n).all(|v| fixed[v] || (f[v] <= upper[v] && f[v] >= lower[v]))
    };
    let mut summary = MarginSummary { met: feasible(f), ..Default::default() };
    if summary.met {
        return summary;
    }
    let original = f.to_vec();
    let mut preds: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut succs: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(i, j) in edges {
        preds[j].push(i);
        succs[i].push(j);
    }
    let above = |a: f64| {
        let mut t = a + margin;
        while !meets(a, t, margin) {
            t = t.next_up();
        }
        t
    };
    let below = |b: f64| {
        let mut t = b - margin;
        while !meets(t, b, margin) {
            t = t.next_down();
        }
        t
    };
    for _ in 0..4 {
        for &v in order {
            if fixed[v] {
                continue;
            }
            for &p in &preds[v] {
                if !meets(f[p], f[v], margin) {
                    f[v] = above(f[p]);
                }
            }
            f[v] = f[v].max(lower[v]).min(upper[v]);
        }
        for &v in order.iter().rev() {
            if fixed[v] {
                continue;
            }
            for &s in &succs[v] {
                if !meets(f[v], f[s], margin) {
                    f[v] = below(f[s]);
                }
            }
            f[v] = f[v].min(upper[v]).max(lower[v]);
        }
        if feasible(f) {
            summary.met = true;
            break;
        }
    }
    for (a, b) in original.iter().zip(f.iter()) {
        if a != b {
            summary.changed_vertices += 1;
            summary.max_change = summary.max_change.max((a - b).abs());
        }
    }
    summary
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lifts_ties_and_keeps_fixed_values() {
        let mut f = vec![0.0, 1.0, 1.0, 0.999_999_999, 2.0];
        let fixed = [true, false, false, false, true];
        let edges = [(0, 1), (1, 2), (2, 3), (3, 4)];
        let s = repair(&mut f, &fixed, &edges, &[0, 1, 2, 3, 4], 1e-9);
        assert_eq!(s.violated_edges, 2);
        assert!(f.windows(2).all(|w| w[0] < w[1]), "{f:?}");
        assert_eq!((f[0], f[4]), (0.0, 2.0));
        assert!(s.max_change < 1e-8);
    }

    #[test]
    fn the_margin_is_met_exactly_within_the_bounds() {
        // a chain 0 → 1 → 2 → 3 with fixed ends; the middle a rounding short of the margin
        let m = 0.1;
        let mut f = vec![0.0, 0.1 - 1e-17, 0.2, 1.0];
        let fixed = [true, false, false, true];
        let edges = [(0, 1), (1, 2), (2, 3)];
        let s = meet_margin(&mut f, &fixed, &edges, &[0, 1, 2, 3], m, &[]);
        assert!(s.met && s.changed_vertices >= 1, "{s:?} {f:?}");
        assert!(edges.iter().all(|&(i, j)| meets(f[i], f[j], m)), "{f:?}");
        assert_eq!((f[0], f[3]), (0.0, 1.0));
        // a free end bounded above: lifted by its in-edge, then held at the bound, the edge
        // lowered behind it
        let mut g = vec![0.0, 0.55, 0.6];
        let fixed = [true, false, false];
        let bound = [crate::solve::Bound { vertex: 2, value: 0.6, upper: true }];
        let s = meet_margin(&mut g, &fixed, &[(0, 1), (1, 2)], &[0, 1, 2], m, &bound);
        assert!(s.met, "{s:?} {g:?}");
        assert!(g[2] <= 0.6 && meets(g[1], g[2], m) && meets(g[0], g[1], m), "{g:?}");
    }
}
