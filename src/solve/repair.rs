//! Restoring strict order after an interior-point solve (NOTES.md 3).

/// What the repair changed.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
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
    // `strictly_below(a, b)` is false for NaN too, so NaN counts as a violation
    let strictly_below = |a: f64, b: f64| a.partial_cmp(&b) == Some(std::cmp::Ordering::Less);
    let violated = |f: &[f64]| edges.iter().filter(|&&(i, j)| !strictly_below(f[i], f[j])).count();
    let mut summary = RepairSummary { violated_edges: violated(f), ..Default::default() };
    if summary.violated_edges == 0 {
        return summary;
    }
    let original = f.to_vec();
    let passes = Passes::new(f.len(), fixed, edges, order);
    summary.sweeps = passes.run(
        f,
        strictly_below,
        |v| (v + delta).max(v.next_up()),
        |v| (v - delta).min(v.next_down()),
        |_, v| v,
        |f| violated(f) == 0,
    );
    (summary.changed_vertices, summary.max_change) = changes(&original, f);
    summary
}

/// What [`meet_margin`] changed.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
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
    use crate::linalg::double_double::Dd;
    let d = Dd::from(b) - Dd::from(a) - Dd::from(m);
    d.hi > 0.0 || (d.hi == 0.0 && d.lo >= 0.0)
}

/// Moves free vertices so that the returned point is feasible for the QP as written: `f_j −
/// f_i ≥ margin` on every edge `(i, j)` and every bound, exactly (the interior-point solution
/// meets its rows only to its tolerance, so active rows come back a rounding short). Passes in
/// `order` (a topological order of the edges) lift each free `f_j` to the smallest double a
/// margin above its in-edges, passes in reverse lower it below its out-edges, each held inside
/// its bounds; fixed values never change. At most 4 sweeps.
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
    let passes = Passes::new(n, fixed, edges, order);
    passes.run(
        f,
        |a, b| meets(a, b, margin),
        |a| {
            let mut t = a + margin;
            while !meets(a, t, margin) {
                t = t.next_up();
            }
            t
        },
        |b| {
            let mut t = b - margin;
            while !meets(t, b, margin) {
                t = t.next_down();
            }
            t
        },
        |v, x| x.max(lower[v]).min(upper[v]),
        |f| feasible(f),
    );
    summary.met = feasible(f);
    (summary.changed_vertices, summary.max_change) = changes(&original, f);
    summary
}

/// Each vertex's neighbours along one direction of the edges, in the edges' order, in one
/// array (a vector per vertex: at 10⁷ samples, twenty million allocations).
struct Adjacency {
    start: Vec<usize>,
    to: Vec<usize>,
}

impl Adjacency {
    /// `to` listed under `from` for every edge, as `pair(edge)` gives them.
    fn new(n: usize, edges: &[(usize, usize)], pair: impl Fn(&(usize, usize)) -> (usize, usize)) -> Adjacency {
        let mut start = vec![0usize; n + 1];
        for e in edges {
            start[pair(e).0 + 1] += 1;
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let mut fill = start[..n].to_vec();
        let mut to = vec![0usize; edges.len()];
        for e in edges {
            let (from, t) = pair(e);
            to[fill[from]] = t;
            fill[from] += 1;
        }
        Adjacency { start, to }
    }

    fn of(&self, v: usize) -> &[usize] {
        &self.to[self.start[v]..self.start[v + 1]]
    }
}

/// The in- and out-edges of every vertex, for passes in a topological order.
struct Passes<'a> {
    preds: Adjacency,
    succs: Adjacency,
    fixed: &'a [bool],
    order: &'a [usize],
}

impl<'a> Passes<'a> {
    fn new(n: usize, fixed: &'a [bool], edges: &[(usize, usize)], order: &'a [usize]) -> Self {
        let preds = Adjacency::new(n, edges, |&(i, j)| (j, i));
        let succs = Adjacency::new(n, edges, |&(i, j)| (i, j));
        Passes { preds, succs, fixed, order }
    }

    /// Up to 4 sweeps: forward, each free `f_v` not `ok` above its highest in-edge is set to
    /// `above(it)`; backward, one not `ok` below its lowest out-edge to `below(it)`; every free
    /// value through `clamp` after its turn; stops when `done`. Returns the sweeps run.
    fn run(
        &self,
        f: &mut [f64],
        ok: impl Fn(f64, f64) -> bool,
        above: impl Fn(f64) -> f64,
        below: impl Fn(f64) -> f64,
        clamp: impl Fn(usize, f64) -> f64,
        done: impl Fn(&[f64]) -> bool,
    ) -> usize {
        for sweep in 1..=4 {
            for &v in self.order.iter().filter(|&&v| !self.fixed[v]) {
                if let Some(lo) = self.preds.of(v).iter().map(|&p| f[p]).reduce(f64::max) {
                    if !ok(lo, f[v]) {
                        f[v] = above(lo);
                    }
                }
                f[v] = clamp(v, f[v]);
            }
            for &v in self.order.iter().rev().filter(|&&v| !self.fixed[v]) {
                if let Some(hi) = self.succs.of(v).iter().map(|&s| f[s]).reduce(f64::min) {
                    if !ok(f[v], hi) {
                        f[v] = below(hi);
                    }
                }
                f[v] = clamp(v, f[v]);
            }
            if done(f) {
                return sweep;
            }
        }
        4
    }
}

/// How many entries changed, and the largest change.
fn changes(original: &[f64], f: &[f64]) -> (usize, f64) {
    original.iter().zip(f).filter(|(a, b)| a != b).fold((0, 0.0), |(c, m), (a, b)| (c + 1, f64::max(m, (a - b).abs())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_margin_test_is_exact() {
        // against faer's fx128 (the test's former arithmetic) and against cases decided by
        // the last bit: b − a equal to m, one ulp of m above and below it
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..100_000 {
            let a = next() * 2.0 - 1.0;
            let m = next() * 1e-3;
            let b = [a + m, (a + m).next_up(), (a + m).next_down(), next()][(next() * 4.0) as usize % 4];
            let d = faer::fx128::from(b) - faer::fx128::from(a) - faer::fx128::from(m);
            assert_eq!(meets(a, b, m), d.0 > 0.0 || (d.0 == 0.0 && d.1 >= 0.0), "{a:e} {b:e} {m:e}");
        }
        let (a, m) = (0.1, 0.2);
        let b = 0.30000000000000004; // 0.1 + 0.2 rounded up: b − a exceeds m by a hair
        assert!(meets(a, b, m) && !meets(a, b.next_down().next_down(), m));
    }

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
