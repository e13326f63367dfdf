//! Linear constraints of the smoothing QP (paper eq. 13–14, SPEC.md "Constraint sets").
//!
//! Every constrained edge is oriented by the representative u (i → j when (u_i, i) < (u_j, j))
//! and asks `f_j − f_i ≥ ε`. Sorting the vertices by (u, index) is therefore a topological
//! order of the constraint graph, which gives the largest feasible margin in linear time per
//! trial (NOTES.md 2): with fixed values, `f_j − f_i ≥ ε` on a DAG is feasible iff every
//! directed path of `L` edges from a fixed a to a fixed b has `f_b − f_a ≥ L·ε`.
//!
//! ```
//! use toposmooth::{constraints::{constraint_edges, max_margin, EdgeSet}, domain::Series};
//! let u = [0.0, 1.0, 2.0, 3.0];
//! let fixed = [Some(0.0), None, None, Some(3.0)];
//! let edges = constraint_edges(&Series::uniform(4), &u, &fixed, EdgeSet::Minimal);
//! assert_eq!(edges, vec![(0, 1), (1, 2), (2, 3)]);
//! let eps = max_margin(&u, &edges, &fixed, None).unwrap();
//! assert!((eps - 1.0).abs() < 1e-6); // 3 edges across a rise of 3
//! ```

use crate::domain::{sos_less, sos_sort, Domain};
use crate::error::{Error, Result};

/// Which edges carry an ordering constraint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum EdgeSet {
    /// Per free vertex its lowest and highest neighbour in u, plus every edge between a fixed
    /// and a free vertex.
    #[default]
    Minimal,
    /// Every edge with at least one free end.
    All,
}

named_enum!(EdgeSet, "edge set", [(EdgeSet::Minimal, "minimal"), (EdgeSet::All, "all")]);

/// Constrained edges `(i, j)` meaning `f_j − f_i ≥ ε`, sorted and without duplicates.
pub fn constraint_edges<D: Domain>(domain: &D, u: &[f64], fixed: &[Option<f64>], set: EdgeSet) -> Vec<(usize, usize)> {
    let n = domain.n_vertices();
    let orient = |a: usize, b: usize| if sos_less(u, a, b) { (a, b) } else { (b, a) };
    let mut edges = Vec::new();
    for v in 0..n {
        match set {
            EdgeSet::All => {
                for w in domain.neighbors(v) {
                    if v < w && (fixed[v].is_none() || fixed[w].is_none()) {
                        edges.push(orient(v, w));
                    }
                }
            }
            EdgeSet::Minimal => {
                if fixed[v].is_some() {
                    for w in domain.neighbors(v) {
                        if fixed[w].is_none() {
                            edges.push(orient(v, w));
                        }
                    }
                    continue;
                }
                let mut low: Option<usize> = None;
                let mut high: Option<usize> = None;
                for w in domain.neighbors(v) {
                    if low.is_none_or(|l| sos_less(u, w, l)) {
                        low = Some(w);
                    }
                    if high.is_none_or(|h| sos_less(u, h, w)) {
                        high = Some(w);
                    }
                }
                for w in low.into_iter().chain(high) {
                    edges.push(orient(v, w));
                }
            }
        }
    }
    sorted_unique(edges, n)
}

/// `edges` sorted and without repeats, as `sort_unstable` and `dedup` would leave them: by
/// their first vertex in one counting pass, then each vertex's few edges by the second (at 10⁷
/// samples of a series the comparison sort of 2·10⁷ pairs took a second).
fn sorted_unique(edges: Vec<(usize, usize)>, n: usize) -> Vec<(usize, usize)> {
    let mut start = vec![0usize; n + 1];
    for &(a, _) in &edges {
        start[a + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut out = vec![(0usize, 0usize); edges.len()];
    for e in edges {
        out[fill[e.0]] = e;
        fill[e.0] += 1;
    }
    drop(fill);
    let mut kept = 0;
    for v in 0..n {
        let bucket = &mut out[start[v]..start[v + 1]];
        bucket.sort_unstable();
        let mut last = None;
        for k in start[v]..start[v + 1] {
            let e = out[k];
            if last != Some(e) {
                out[kept] = e;
                kept += 1;
                last = Some(e);
            }
        }
    }
    out.truncate(kept);
    out.shrink_to_fit();
    out
}

/// Largest ε for which `f_j − f_i ≥ ε` on every edge is feasible with the fixed values
/// (`+inf` when no path joins two fixed vertices), to a relative precision of 1e-6. With
/// `cap = Some(c)`, the search stops at `2c` when that is feasible (all that
/// [`choose_margin`] needs to know).
///
/// # Errors
/// Infeasible if even ε = 0 is infeasible: an edge path runs from a fixed value down to a
/// smaller one (u disagrees with the fixed values).
pub fn max_margin(u: &[f64], edges: &[(usize, usize)], fixed: &[Option<f64>], cap: Option<f64>) -> Result<f64> {
    max_margin_bounded(u, edges, fixed, &[], cap)
}

/// [`max_margin`] with one-sided bounds on free vertices, `(vertex, value, upper)`: `f_v ≤
/// value` when `upper`, else `f_v ≥ value` (a series' free end held inside the data's range).
/// A lower bound starts paths like a fixed value; an upper bound ends them like one.
///
/// # Errors
/// As [`max_margin`].
pub fn max_margin_bounded(
    u: &[f64],
    edges: &[(usize, usize)],
    fixed: &[Option<f64>],
    bounds: &[(usize, f64, bool)],
    cap: Option<f64>,
) -> Result<f64> {
    max_margin_or_conflict(u, edges, fixed, bounds, cap).map_err(|(a, w)| {
        Error::infeasible(format!(
            "the representative orders a path upward from vertex {a} to vertex {w}, whose fixed value (or bound) is not higher: no function increasing along it takes these values"
        ))
    })
}

/// The margin tests' pass: the vertices in u's order, the edges out of each vertex (those of
/// `v` are `succ[start[v]..start[v + 1]]`), the fixed values and bounds.
struct Sweep<'a> {
    order: &'a [usize],
    start: Vec<usize>,
    succ: Vec<usize>,
    fixed: &'a [Option<f64>],
    lower: &'a [f64],
    upper: &'a [f64],
}

impl<'a> Sweep<'a> {
    fn new(
        order: &'a [usize],
        edges: &[(usize, usize)],
        fixed: &'a [Option<f64>],
        lower: &'a [f64],
        upper: &'a [f64],
    ) -> Sweep<'a> {
        let n = order.len();
        let mut start = vec![0usize; n + 1];
        for &(a, _) in edges {
            start[a + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut succ = vec![0usize; edges.len()];
        for &(a, b) in edges {
            succ[fill[a]] = b;
            fill[a] += 1;
        }
        Sweep { order, start, succ, fixed, lower, upper }
    }

    /// For each margin ε of `eps`, in one pass over the vertices in u's order: `Some((a, w))`,
    /// the first fixed (or upper-bounded) vertex `w` whose value the lowest values rising by ε
    /// along the edges from a fixed (or lower-bounded) vertex `a` exceed, or `None` when ε is
    /// feasible. Each margin's values and answer are those of a pass of its own.
    fn run<const K: usize>(&self, eps: [f64; K]) -> [Option<(usize, usize)>; K] {
        let (fixed, lower, upper) = (self.fixed, self.lower, self.upper);
        let n = fixed.len();
        let mut lo: Vec<[f64; K]> = (0..n).map(|v| [fixed[v].unwrap_or(lower[v]); K]).collect();
        // where each vertex's lower bound starts (a fixed or lower-bounded vertex)
        let mut from: Vec<[usize; K]> = (0..n).map(|v| [v; K]).collect();
        let mut found: [Option<(usize, usize)>; K] = [None; K];
        let mut open = K;
        for &v in self.order {
            let base = lo[v];
            if base.iter().all(|&b| b == f64::NEG_INFINITY) {
                continue;
            }
            for &w in &self.succ[self.start[v]..self.start[v + 1]] {
                for k in 0..K {
                    if found[k].is_some() || base[k] == f64::NEG_INFINITY {
                        continue;
                    }
                    let cand = base[k] + eps[k];
                    let fails = match fixed[w] {
                        Some(fw) => cand > fw,
                        None if cand > upper[w] => true,
                        None => {
                            if cand > lo[w][k] {
                                lo[w][k] = cand;
                                from[w][k] = from[v][k];
                            }
                            false
                        }
                    };
                    if fails {
                        found[k] = Some((from[v][k], w));
                        open -= 1;
                        if open == 0 {
                            return found;
                        }
                    }
                }
            }
        }
        found
    }
}

/// [`max_margin_bounded`], or the conflict that makes even ε = 0 infeasible: `(a, w)`, a
/// fixed (or lower-bounded) vertex and a fixed (or upper-bounded) vertex joined by a path the
/// order of u runs up, whose values do not rise.
///
/// # Errors
/// The conflicting pair.
pub fn max_margin_or_conflict(
    u: &[f64],
    edges: &[(usize, usize)],
    fixed: &[Option<f64>],
    bounds: &[(usize, f64, bool)],
    cap: Option<f64>,
) -> std::result::Result<f64, (usize, usize)> {
    max_margin_along(&sos_sort(u), edges, fixed, bounds, cap)
}

/// [`max_margin_or_conflict`] with u's order given: `order` lists the vertices as
/// [`sos_sort`] of u does (a representative made in that order hands it over: at 128³ the
/// sort took about 0.15 s).
///
/// # Errors
/// As [`max_margin_or_conflict`].
pub fn max_margin_along(
    order: &[usize],
    edges: &[(usize, usize)],
    fixed: &[Option<f64>],
    bounds: &[(usize, f64, bool)],
    cap: Option<f64>,
) -> std::result::Result<f64, (usize, usize)> {
    let n = order.len();
    let mut upper = vec![f64::INFINITY; n];
    let mut lower = vec![f64::NEG_INFINITY; n];
    for &(v, value, is_upper) in bounds {
        if fixed[v].is_none() {
            if is_upper {
                upper[v] = upper[v].min(value);
            } else {
                lower[v] = lower[v].max(value);
            }
        }
    }
    let sweep = Sweep::new(order, edges, fixed, &lower, &upper);
    let (fmin, fmax) = crate::domain::value_range(fixed.iter().flatten().chain(bounds.iter().map(|b| &b.1)));
    let span = if fmax > fmin { fmax - fmin } else { 1.0 };
    // the usual case: the cap of `choose_margin` is feasible twice over; one pass decides it
    // and ε = 0 together (at 128³ each pass took about 0.35 s)
    match cap.filter(|&c| c < span) {
        Some(cap) => {
            let [at_zero, at_cap] = sweep.run([0.0, 2.0 * cap]);
            if let Some(pair) = at_zero {
                return Err(pair);
            }
            if at_cap.is_none() {
                return Ok(2.0 * cap);
            }
        }
        None => {
            if let [Some(pair)] = sweep.run([0.0]) {
                return Err(pair);
            }
        }
    }
    if let [None, at_twice] = sweep.run([span, 2.0 * span + 1.0]) {
        // a path of one edge between fixed values already allows the whole span: no bound
        // short of it matters; report +inf when no fixed pair is linked at all
        return Ok(if at_twice.is_none() { f64::INFINITY } else { span });
    }
    let violated = |eps: f64| sweep.run([eps])[0];
    // halve until feasible, then bisect to a relative precision of 1e-6
    let (mut ok, mut bad) = (0.0f64, span);
    while ok == 0.0 {
        let mid = 0.5 * bad;
        if mid < f64::MIN_POSITIVE {
            return Ok(0.0);
        }
        if violated(mid).is_none() {
            ok = mid;
        } else {
            bad = mid;
        }
    }
    while bad - ok > 1e-6 * ok {
        let mid = 0.5 * (ok + bad);
        if violated(mid).is_none() {
            ok = mid;
        } else {
            bad = mid;
        }
    }
    Ok(ok)
}

/// Relative cap of the margin: `1e-6` of the value range.
pub const MARGIN_CAP: f64 = 1e-6;

/// Largest margin [`choose_margin`] uses: `1e-6` of the range, but never below 8 × the spacing
/// of doubles at the field's magnitude.
pub fn margin_cap(range: f64, resolution: f64) -> f64 {
    (MARGIN_CAP * range).max(8.0 * resolution)
}

/// The margin used: half the largest feasible one, and at most `1e-6` of the value range (or
/// 8 × `resolution` if that is larger: data far from zero with a small range).
///
/// Half keeps u's constraint set strictly feasible with slack on every path (so an
/// interior-point solver starts and ends inside); 1e-6 of the range is 100× the solver's
/// feasibility tolerance (1e-8 after the values are scaled to unit range), so the tolerance
/// cannot turn a constrained edge into a tie, while a slope of 1e-6·range per edge is far
/// below anything visible.
///
/// `resolution` is the spacing of doubles at the field's largest magnitude, in the same
/// units as the margin.
///
/// # Errors
/// Infeasible (exit 3) when the margin is not above 4 × `resolution`: floating point cannot
/// represent a strict function with the kept values along the longest constrained path.
pub fn choose_margin(max_margin: f64, range: f64, resolution: f64) -> Result<f64> {
    let eps = (0.5 * max_margin).min(margin_cap(range, resolution));
    if eps.partial_cmp(&(4.0 * resolution)) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::infeasible(format!(
            "the kept values leave a margin of {eps:e} per edge, not above 4 × the spacing of doubles ({resolution:e}): no strict function in double precision"
        )));
    }
    Ok(eps)
}

/// How much of the output the constraints hold: the constrained edges whose output rises by
/// less than 10 margins are *active*; flat steps of the smoothing fight the constraints there.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Activity {
    /// Share of the free vertices with an incident active edge.
    pub active_fraction: f64,
    /// Connected sets of at least 3 free vertices joined by active edges (terraces: staircases
    /// of margin-sized steps).
    pub terraces: usize,
    /// Vertices of the largest terrace (0 when there is none).
    pub largest_terrace: usize,
}

/// [`Activity`] of `f` on the constrained `edges` with margin `eps` (in `f`'s units).
pub fn activity(f: &[f64], edges: &[(usize, usize)], fixed: &[bool], eps: f64) -> Activity {
    let n = f.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    let mut active = vec![false; n];
    for &(i, j) in edges {
        if f[j] - f[i] < 10.0 * eps {
            active[i] |= !fixed[i];
            active[j] |= !fixed[j];
            if !fixed[i] && !fixed[j] {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a] = b;
            }
        }
    }
    let free = fixed.iter().filter(|&&x| !x).count();
    let mut size = vec![0usize; n];
    for (v, _) in active.iter().enumerate().filter(|(_, &a)| a) {
        let r = root(&mut parent, v);
        size[r] += 1;
    }
    let big: Vec<usize> = size.into_iter().filter(|&s| s >= 3).collect();
    Activity {
        active_fraction: active.iter().filter(|&&a| a).count() as f64 / free.max(1) as f64,
        terraces: big.len(),
        largest_terrace: big.iter().copied().max().unwrap_or(0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Series;

    /// Margins tested together in one pass answer as each alone does, conflicts included:
    /// on random orders of a grid's edges with fixed values and bounds, at margins from
    /// feasible to far past the largest.
    #[test]
    fn margins_tested_together_answer_as_each_alone() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (nx, ny) = (9, 7);
        let n = nx * ny;
        let (mut conflicts, mut feasible) = (0, 0);
        for _ in 0..40 {
            let u: Vec<f64> = (0..n).map(|_| (next() % 1000) as f64).collect();
            let mut edges = Vec::new();
            for v in 0..n {
                for w in [v + 1, v + nx] {
                    if w < n && (w != v + 1 || w % nx != 0) {
                        edges.push(if sos_less(&u, v, w) { (v, w) } else { (w, v) });
                    }
                }
            }
            let mut fixed = vec![None; n];
            for _ in 0..6 {
                let v = (next() % n as u64) as usize;
                // mostly the order's own values (feasible), sometimes against it
                fixed[v] = Some(if next() % 4 == 0 { (next() % 1000) as f64 } else { u[v] });
            }
            let (lower, mut upper) = (vec![f64::NEG_INFINITY; n], vec![f64::INFINITY; n]);
            upper[(next() % n as u64) as usize] = 500.0;
            let order = sos_sort(&u);
            let sweep = Sweep::new(&order, &edges, &fixed, &lower, &upper);
            for pair in [[0.0, 0.5], [0.5, 3.0], [3.0, 40.0], [40.0, 0.0]] {
                let together = sweep.run(pair);
                let alone = [sweep.run([pair[0]])[0], sweep.run([pair[1]])[0]];
                assert_eq!(together, alone, "margins {pair:?}");
                conflicts += alone.iter().filter(|a| a.is_some()).count();
                feasible += alone.iter().filter(|a| a.is_none()).count();
            }
        }
        // both answers occur, so the comparison saw lanes that stop and lanes that go on
        assert!(conflicts > 20 && feasible > 20, "{conflicts} conflicts, {feasible} feasible");
    }

    #[test]
    fn the_counting_sort_leaves_the_edges_as_a_comparison_sort_and_dedup_do() {
        let n = 97;
        // repeats, both orientations, empty and crowded vertices
        let mut state = 12345u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n as u64) as usize
        };
        let edges: Vec<(usize, usize)> = (0..2000).map(|_| (next() / 3, next())).collect();
        let mut expected = edges.clone();
        expected.sort_unstable();
        expected.dedup();
        let got = sorted_unique(edges, n);
        assert_eq!(got, expected);
        assert!(got.len() < 2000 && got.capacity() == got.len());
        assert!(sorted_unique(Vec::new(), 3).is_empty());
    }

    #[test]
    fn minimal_set_adds_all_edges_at_fixed_vertices() {
        let u = [3.0, 0.0, 1.0, 2.0, 5.0, 4.0];
        let fixed = [None, Some(0.0), None, None, Some(5.0), None];
        let e = constraint_edges(&Series::uniform(6), &u, &fixed, EdgeSet::Minimal);
        assert_eq!(e, vec![(1, 0), (1, 2), (2, 3), (3, 4), (5, 4)]);
        let all = constraint_edges(&Series::uniform(6), &u, &fixed, EdgeSet::All);
        assert_eq!(all, e);
    }

    #[test]
    fn margin_is_the_tightest_path() {
        // fixed 0 at vertex 0 and 1 at vertex 4: 4 edges ⇒ ε_max = 0.25
        let u = [0.0, 0.1, 0.2, 0.3, 1.0];
        let fixed = [Some(0.0), None, None, None, Some(1.0)];
        let e = constraint_edges(&Series::uniform(5), &u, &fixed, EdgeSet::Minimal);
        let m = max_margin(&u, &e, &fixed, None).unwrap();
        assert_eq!(max_margin(&u, &e, &fixed, Some(0.01)).unwrap(), 0.02);
        assert!((m - 0.25).abs() < 1e-6, "{m}");
        assert_eq!(choose_margin(m, 1.0, f64::EPSILON).unwrap(), 1e-6);
        assert!(choose_margin(1e-20, 1.0, f64::EPSILON).is_err());
        // tiny but representable margins are found, not rounded to zero
        let fixed = [Some(0.0), None, None, None, Some(1e-13)];
        let m = max_margin(&u, &e, &fixed, None).unwrap();
        assert!((m - 0.25e-13).abs() < 1e-6 * 0.25e-13, "{m}");
        // u disagreeing with the fixed values
        let bad = [Some(1.0), None, None, None, Some(0.0)];
        assert!(max_margin(&u, &e, &bad, None).is_err());
    }

    #[test]
    fn active_edges_and_terraces_are_counted_on_free_vertices() {
        // 0 fixed, then a staircase 1-2-3-4 of margin steps, then a steep rise, 6 fixed
        let eps = 1e-3;
        let f = [0.0, 0.5, 0.5 + eps, 0.5 + 2.0 * eps, 0.5 + 3.0 * eps, 0.9, 1.0];
        let fixed = [true, false, false, false, false, false, true];
        let edges: Vec<(usize, usize)> = (0..6).map(|i| (i, i + 1)).collect();
        let a = activity(&f, &edges, &fixed, eps);
        assert_eq!((a.terraces, a.largest_terrace), (1, 4));
        assert!((a.active_fraction - 4.0 / 5.0).abs() < 1e-12, "{a:?}");
        // two active vertices only: no terrace; a fixed end does not join one
        let g = [0.0, eps, 0.5, 0.6, 0.7, 0.8, 1.0];
        let b = activity(&g, &edges, &fixed, eps);
        assert_eq!((b.terraces, b.largest_terrace), (0, 0));
        assert!((b.active_fraction - 1.0 / 5.0).abs() < 1e-12, "{b:?}");
    }

    #[test]
    fn an_upper_bound_ends_paths_like_a_fixed_value() {
        // fixed 0 at vertex 0, a free end at vertex 3 held below 0.3: 3 edges ⇒ ε_max = 0.1
        let u = [0.0, 1.0, 2.0, 3.0];
        let fixed = [Some(0.0), None, None, None];
        let e = constraint_edges(&Series::uniform(4), &u, &fixed, EdgeSet::Minimal);
        assert_eq!(max_margin(&u, &e, &fixed, None).unwrap(), f64::INFINITY);
        let m = max_margin_bounded(&u, &e, &fixed, &[(3, 0.3, true)], None).unwrap();
        assert!((m - 0.1).abs() < 1e-6, "{m}");
        // a bound below the fixed value: infeasible
        assert!(max_margin_bounded(&u, &e, &fixed, &[(3, -1.0, true)], None).is_err());
    }

    #[test]
    fn unlinked_fixed_values_give_an_unbounded_margin() {
        let u = [0.0, 1.0, 2.0];
        let fixed = [Some(0.0), None, None];
        let e = constraint_edges(&Series::uniform(3), &u, &fixed, EdgeSet::Minimal);
        assert_eq!(max_margin(&u, &e, &fixed, None).unwrap(), f64::INFINITY);
    }
}
