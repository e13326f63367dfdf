//! 0-dimensional persistence of sublevel and superlevel sets on the vertex–edge graph.
//!
//! Vertices enter in SoS order; a vertex with no processed neighbour starts a component
//! (a minimum is born); a vertex joining several components merges them and, by the elder
//! rule, every younger component dies there with persistence `h(merge) − h(birth)`. The
//! oldest component of each connected part of the domain never dies (persistence = +inf).
//! Superlevel persistence is the same on the reversed order and gives the maxima.
//!
//! ```
//! use toposmooth::{domain::Series, topology::sublevel_pairs};
//! let h = [0.0, 3.0, 1.0, 2.0, -1.0];
//! let pairs = sublevel_pairs(&Series::uniform(5), &h);
//! // minimum 2 (value 1) dies at maximum 3 (value 2): persistence 1
//! let p = pairs.iter().find(|p| p.extremum == 2).unwrap();
//! assert_eq!((p.partner, p.persistence), (Some(3), 1.0));
//! ```

use crate::domain::{sos_sort, Domain, PairingRule};
use petgraph::unionfind::UnionFind;

/// One extremum and the vertex where its component dies.
#[derive(Clone, Debug, PartialEq)]
pub struct Pair {
    /// The extremum (a minimum for sublevel pairs, a maximum for superlevel pairs).
    pub extremum: usize,
    /// The merge vertex where it dies; `None` for the essential extremum of a component.
    pub partner: Option<usize>,
    /// `|h(partner) − h(extremum)|`, or `+inf` for an essential extremum.
    pub persistence: f64,
}

/// Sublevel pairs: one per SoS minimum, in order of birth.
pub fn sublevel_pairs<D: Domain>(domain: &D, values: &[f64]) -> Vec<Pair> {
    let order = sos_sort(values);
    union_find_pairs(domain, values, &order)
}

/// Superlevel pairs: one per SoS maximum, in order of birth (highest first).
pub fn superlevel_pairs<D: Domain>(domain: &D, values: &[f64]) -> Vec<Pair> {
    let mut order = sos_sort(values);
    order.reverse();
    union_find_pairs(domain, values, &order)
}

fn union_find_pairs<D: Domain>(domain: &D, values: &[f64], order: &[usize]) -> Vec<Pair> {
    let n = domain.n_vertices();
    assert_eq!(values.len(), n, "one value per vertex");
    let mut rank = vec![usize::MAX; n]; // position in `order`, MAX = not yet entered
    let mut uf = UnionFind::<usize>::new(n);
    // birth vertex (oldest extremum) of the component whose representative is the key
    let mut oldest = vec![usize::MAX; n];
    let mut pair_of = vec![usize::MAX; n]; // index into `pairs` of each extremum
    let mut pairs: Vec<Pair> = Vec::new();
    let mut roots: Vec<usize> = Vec::with_capacity(8);
    for (pos, &v) in order.iter().enumerate() {
        rank[v] = pos;
        roots.clear();
        for w in domain.neighbors(v) {
            if rank[w] != usize::MAX {
                let r = uf.find_mut(w);
                if !roots.contains(&r) {
                    roots.push(r);
                }
            }
        }
        if roots.is_empty() {
            oldest[v] = v;
            pair_of[v] = pairs.len();
            pairs.push(Pair { extremum: v, partner: None, persistence: f64::INFINITY });
            continue;
        }
        // the elder component survives: its oldest extremum entered first
        let elder = *roots.iter().min_by_key(|&&r| rank[oldest[r]]).expect("non-empty");
        let survivor = oldest[elder];
        for &r in &roots {
            let born = oldest[r];
            if born != survivor {
                let p = &mut pairs[pair_of[born]];
                p.partner = Some(v);
                p.persistence = (values[v] - values[born]).abs();
            }
        }
        for &r in &roots {
            uf.union(r, v);
        }
        let r = uf.find_mut(v);
        oldest[r] = survivor;
    }
    pairs
}

/// Numbers of SoS minima and SoS maxima (series ends included): a local test per vertex.
pub fn count_sos_extrema<D: Domain>(domain: &D, values: &[f64]) -> (usize, usize) {
    let (mut minima, mut maxima) = (0, 0);
    for v in 0..domain.n_vertices() {
        if domain.neighbors(v).all(|w| crate::domain::sos_greater(values, w, v)) {
            minima += 1;
        } else if domain.neighbors(v).all(|w| crate::domain::sos_less(values, w, v)) {
            maxima += 1;
        }
    }
    (minima, maxima)
}

/// Kind of an extremum in an [`extrema_table`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum ExtremumKind {
    /// SoS minimum.
    Min,
    /// SoS maximum.
    Max,
    /// Endpoint maximum of a series: it never merges components, so it has no persistence.
    End,
}

/// One row of the `extrema` listing.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ExtremumInfo {
    /// Vertex index.
    pub index: usize,
    /// Minimum, maximum or series end.
    pub kind: ExtremumKind,
    /// Input value.
    pub value: f64,
    /// Persistence; `None` for ends and `Some(inf)` for essential extrema (JSON: null).
    #[cfg_attr(feature = "serde", serde(serialize_with = "finite_or_null"))]
    pub persistence: Option<f64>,
    /// The vertex it is paired with (where it dies, or the minimum that dies at it).
    pub partner: Option<usize>,
    /// Whether it is also a strict extremum of the raw values (no equal neighbour).
    pub strict: bool,
    /// Whether it is an endpoint of a series (fewer neighbours; a minimum there still has a
    /// persistence, a maximum there is an `End`).
    pub endpoint: bool,
}

#[cfg(feature = "serde")]
fn finite_or_null<S: serde::Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match v {
        Some(x) if x.is_finite() => s.serialize_f64(*x),
        _ => s.serialize_none(),
    }
}

/// Every SoS extremum with its persistence and strictness, sorted by index (SPEC.md).
///
/// On a path ([`PairingRule::Path`]) maxima take the persistence of the sublevel pair that
/// dies at them and endpoint maxima are [`ExtremumKind::End`]; elsewhere maxima come from
/// superlevel persistence.
pub fn extrema_table<D: Domain>(domain: &D, values: &[f64]) -> Vec<ExtremumInfo> {
    let n = domain.n_vertices();
    let strict = |v: usize, lower: bool| {
        domain.neighbors(v).all(|w| if lower { values[w] > values[v] } else { values[w] < values[v] })
    };
    let path = domain.pairing_rule() == PairingRule::Path;
    let is_endpoint = |v: usize| path && (v == 0 || v + 1 == n);
    let mut rows = Vec::new();
    for p in sublevel_pairs(domain, values) {
        rows.push(ExtremumInfo {
            index: p.extremum,
            kind: ExtremumKind::Min,
            value: values[p.extremum],
            persistence: Some(p.persistence),
            partner: p.partner,
            strict: strict(p.extremum, true),
            endpoint: is_endpoint(p.extremum),
        });
    }
    match domain.pairing_rule() {
        PairingRule::Path => {
            let mut dies_at = vec![None; n];
            for r in &rows {
                if let Some(m) = r.partner {
                    dies_at[m] = Some((r.index, r.persistence));
                }
            }
            for v in 0..n {
                let is_max = domain.neighbors(v).all(|w| crate::domain::sos_less(values, w, v));
                if !is_max {
                    continue;
                }
                let (partner, persistence, kind) = match dies_at[v] {
                    Some((m, p)) => (Some(m), p, ExtremumKind::Max),
                    None => (None, None, ExtremumKind::End),
                };
                rows.push(ExtremumInfo {
                    index: v,
                    kind,
                    value: values[v],
                    persistence,
                    partner,
                    strict: strict(v, false),
                    endpoint: is_endpoint(v),
                });
            }
        }
        PairingRule::Surface => {
            for p in superlevel_pairs(domain, values) {
                rows.push(ExtremumInfo {
                    index: p.extremum,
                    kind: ExtremumKind::Max,
                    value: values[p.extremum],
                    persistence: Some(p.persistence),
                    partner: p.partner,
                    strict: strict(p.extremum, false),
                    endpoint: false,
                });
            }
        }
    }
    rows.sort_by_key(|r| r.index);
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Series;

    #[test]
    fn elder_rule_on_a_series() {
        // minima at 0 (0.0), 2 (1.0), 4 (-1.0); maxima at 1 (3.0), 3 (2.0)
        let h = [0.0, 3.0, 1.0, 2.0, -1.0];
        let s = Series::uniform(5);
        let pairs = sublevel_pairs(&s, &h);
        assert_eq!(pairs.len(), 3);
        let get = |m| pairs.iter().find(|p| p.extremum == m).unwrap().clone();
        assert_eq!(get(4).persistence, f64::INFINITY);
        assert_eq!(get(2).partner, Some(3));
        assert_eq!(get(0).partner, Some(1));
        assert_eq!(get(0).persistence, 3.0);
        let maxima = superlevel_pairs(&s, &h);
        assert_eq!(maxima.iter().find(|p| p.extremum == 1).unwrap().persistence, f64::INFINITY);
    }

    #[test]
    fn ties_give_zero_persistence_extrema() {
        // plateau: vertices 1 and 2 equal; SoS makes 1 a minimum... and 2 not
        let h = [2.0, 1.0, 1.0, 3.0, 1.0, 2.0];
        let pairs = sublevel_pairs(&Series::uniform(6), &h);
        let mins: Vec<usize> = pairs.iter().map(|p| p.extremum).collect();
        assert!(mins.contains(&1) && mins.contains(&4) && !mins.contains(&2));
        // minimum 4 (value 1, younger by index) dies at 3 with persistence 2
        let p4 = pairs.iter().find(|p| p.extremum == 4).unwrap();
        assert_eq!((p4.partner, p4.persistence), (Some(3), 2.0));
    }

    #[test]
    fn two_bumps_on_a_grid() {
        use crate::domain::Grid2d;
        // bumps of height 1 at (10, 8) and 0.5 at (10, 24) on a 21 × 33 grid; the saddle
        // between them sits near (10, 16) at about exp(−64/σ²) ≈ small
        let g = Grid2d::new(33, 21).unwrap();
        let h: Vec<f64> = (0..g.n_vertices())
            .map(|v| {
                let (r, c) = g.row_col(v);
                let d = |cr: f64, cc: f64| ((r as f64 - cr).powi(2) + (c as f64 - cc).powi(2)) / 30.0;
                (-d(10.0, 8.0)).exp() + 0.5 * (-d(10.0, 24.0)).exp()
            })
            .collect();
        let maxima = superlevel_pairs(&g, &h);
        assert_eq!(maxima.len(), 2, "{maxima:?}");
        let small = maxima.iter().find(|p| p.extremum == g.index(10, 24)).expect("small bump");
        let saddle = small.partner.expect("dies");
        assert_eq!(g.row_col(saddle).0, 10, "the saddle lies on the line between the bumps");
        assert!((small.persistence - (h[g.index(10, 24)] - h[saddle])).abs() < 1e-15);
        // oracle: the highest level at which both peaks lie in one component of {h ≥ level}
        let connected = |level: f64| {
            let mut seen = vec![false; g.n_vertices()];
            let mut stack = vec![g.index(10, 8)];
            seen[stack[0]] = true;
            while let Some(v) = stack.pop() {
                for w in g.neighbors(v) {
                    if !seen[w] && h[w] >= level {
                        seen[w] = true;
                        stack.push(w);
                    }
                }
            }
            seen[g.index(10, 24)]
        };
        let mut levels = h.clone();
        levels.sort_by(f64::total_cmp);
        let merge = levels.iter().rev().find(|&&l| connected(l)).copied().unwrap();
        assert_eq!(h[saddle], merge);
        assert!(small.persistence > 0.3 && small.persistence < 0.4, "{}", small.persistence);
        let big = maxima.iter().find(|p| p.extremum == g.index(10, 8)).unwrap();
        assert_eq!(big.persistence, f64::INFINITY);
        // minima: every corner region of the boundary is low; the global one never dies
        let minima = sublevel_pairs(&g, &h);
        assert_eq!(minima.iter().filter(|p| p.partner.is_none()).count(), 1);
        let t = extrema_table(&g, &h);
        assert_eq!(t.iter().filter(|r| r.kind == ExtremumKind::Max).count(), 2);
        assert!(t.iter().all(|r| !r.endpoint));
    }

    #[test]
    fn table_lists_ends_and_strictness() {
        let h = [5.0, 1.0, 1.0, 3.0, 0.0, 4.0];
        let t = extrema_table(&Series::uniform(6), &h);
        let kinds: Vec<(usize, ExtremumKind)> = t.iter().map(|r| (r.index, r.kind)).collect();
        assert_eq!(
            kinds,
            vec![
                (0, ExtremumKind::End),
                (1, ExtremumKind::Min),
                (3, ExtremumKind::Max),
                (4, ExtremumKind::Min),
                (5, ExtremumKind::End)
            ]
        );
        assert!(!t[1].strict, "vertex 1 ties with vertex 2");
        assert_eq!(count_sos_extrema(&Series::uniform(6), &h), (2, 3));
        assert!(t[2].strict);
        assert_eq!(t[2].persistence, Some(2.0));
    }
}
