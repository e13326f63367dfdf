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
}
