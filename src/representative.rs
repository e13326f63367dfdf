//! The representative function u: a function with exactly the kept extrema whose edge
//! orientation the output must follow (paper section 3.3).
//!
//! On a series the 1D Morse-Smale complex's separatrices are the intervals between
//! consecutive kept extrema: u is linear in x on each of them, between the kept input values
//! (the harmonic solution with those Dirichlet values), and strictly monotone from each end
//! of the series to the nearest kept extremum.
//! (The test `series_u_is_linear_between_the_kept_extrema` shows it on five samples.)

use crate::domain::{Domain, Series};
use crate::error::{ConstructionError, Error, Result};
use crate::topology::{KeptSet, Role};

/// Builds u on a series from the kept set: linear in x between consecutive kept extrema,
/// strictly monotone from each free end to the nearest kept extremum (the end takes the
/// extreme input value of its stretch, or a typical slope if the data gives none), then
/// made strictly monotone in floating point by one pass each way.
///
/// # Errors
/// Infeasible (exit 3) if two consecutive kept extrema have values so close that double
/// precision has fewer distinct numbers between them than there are samples between them.
pub fn series_representative(series: &Series, h: &[f64], kept: &KeptSet) -> Result<Vec<f64>> {
    let x = series.x();
    let n = x.len();
    assert_eq!(h.len(), n);
    let anchors: Vec<(usize, Role)> = kept.kept.iter().map(|k| (k.index, k.role)).collect();
    let mut u = h.to_vec();
    if anchors.is_empty() {
        return Err(Error::Representative { path: None, message: "no kept extremum".into() });
    }
    let (lo, hi) = crate::domain::value_range(h);
    let slope = (hi - lo) / series.diameter();
    // free ends: the end opposite in type to the nearest kept extremum, inside [lo, hi]
    let end_value = |stretch: &[f64], anchor: f64, role: Role, fallback: f64| {
        end_value(stretch, anchor, role, fallback).clamp(lo, hi)
    };
    let (first, first_role) = anchors[0];
    if first > 0 {
        let end = end_value(&h[..=first], h[first], first_role, slope * (x[first] - x[0]));
        let end = with_room(h[first], end, first);
        linear(&mut u, x, 0, first, end, h[first]);
    }
    let (last, last_role) = anchors[anchors.len() - 1];
    if last + 1 < n {
        let end = end_value(&h[last..], h[last], last_role, slope * (x[n - 1] - x[last]));
        let end = with_room(h[last], end, n - 1 - last);
        linear(&mut u, x, last, n - 1, h[last], end);
    }
    for w in anchors.windows(2) {
        let (a, b) = (w[0].0, w[1].0);
        let missing = b - a - 1;
        if (floats_between(h[a], h[b]) as u128) < missing as u128 {
            return Err(Error::infeasible(format!(
                "kept extrema {a} (value {:e}) and {b} (value {:e}) are too close: double precision has fewer than the {missing} distinct values a strictly monotone path between them needs",
                h[a], h[b]
            )));
        }
        linear(&mut u, x, a, b, h[a], h[b]);
    }
    strictify(&mut u, &anchors);
    Ok(u)
}

fn end_value(stretch: &[f64], anchor: f64, role: Role, fallback: f64) -> f64 {
    let fallback = if fallback > 0.0 { fallback } else { 1.0 };
    if role == Role::Min {
        let m = stretch.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        if m > anchor {
            m
        } else {
            anchor + fallback
        }
    } else {
        let m = stretch.iter().cloned().fold(f64::INFINITY, f64::min);
        if m < anchor {
            m
        } else {
            anchor - fallback
        }
    }
}

/// The free end's value moved away from the anchor, if needed, so that at least `4 (len + 2)`
/// doubles lie between them: room for a strictly monotone stretch of `len` edges.
fn with_room(anchor: f64, end: f64, len: usize) -> f64 {
    let gap = (end - anchor).abs();
    let top = anchor.abs().max(end.abs()) + gap;
    let ulp = top.next_up() - top;
    let need = 4.0 * (len as f64 + 2.0) * ulp;
    if gap >= need {
        end
    } else {
        anchor + (end - anchor).signum() * need
    }
}

/// u linear in x on [a, b] from ua to ub (endpoints set exactly).
fn linear(u: &mut [f64], x: &[f64], a: usize, b: usize, ua: f64, ub: f64) {
    let len = x[b] - x[a];
    for i in a..=b {
        let t = (x[i] - x[a]) / len;
        u[i] = ua + (ub - ua) * t;
    }
    u[a] = ua;
    u[b] = ub;
}

/// Number of doubles strictly between a and b.
fn floats_between(a: f64, b: f64) -> u64 {
    // monotone map of doubles to integers; −0 and +0 share one key
    let key = |x: f64| {
        let bits = (if x == 0.0 { 0.0 } else { x }).to_bits();
        if bits >> 63 == 1 {
            (!bits) + 1
        } else {
            bits | (1 << 63)
        }
    };
    let (ka, kb) = (key(a), key(b));
    ka.abs_diff(kb).saturating_sub(1)
}

/// Rounding in `linear` can create ties on long, nearly flat stretches: push each stretch to
/// strict monotonicity with one pass towards each of its fixed ends.
fn strictify(u: &mut [f64], anchors: &[(usize, Role)]) {
    let n = u.len();
    let mut stretches: Vec<(usize, usize)> = anchors.windows(2).map(|w| (w[0].0, w[1].0)).collect();
    if anchors[0].0 > 0 {
        stretches.push((0, anchors[0].0));
    }
    if anchors[anchors.len() - 1].0 + 1 < n {
        stretches.push((anchors[anchors.len() - 1].0, n - 1));
    }
    for (a, b) in stretches {
        let up = u[b] > u[a];
        let step = |v: f64, toward_up: bool| {
            if toward_up {
                v.next_up()
            } else {
                v.next_down()
            }
        };
        for i in a + 1..b {
            let bound = step(u[i - 1], up);
            if (up && u[i] < bound) || (!up && u[i] > bound) {
                u[i] = bound;
            }
        }
        for i in (a + 1..b).rev() {
            let bound = step(u[i + 1], !up);
            if (up && u[i] > bound) || (!up && u[i] < bound) {
                u[i] = bound;
            }
        }
    }
}

/// The separatrix representative on a surface (paper section 3.3, after Weinkauf, Gingold &
/// Sorkine 2010): kept extrema and surviving saddles at their input values, every vertex on a
/// separatrix linearly interpolated by arc length between its saddle and its extremum (the
/// smallest such value on merged descending separatrices, the largest on ascending ones,
/// NOTES.md 7; a vertex claimed by both stays free), harmonic elsewhere with the Laplacian
/// `k`, whose off-diagonal weights must be ≤ 0 so that the maximum principle holds.
///
/// Where separatrix values contradict each other (a prescribed vertex becomes a spurious
/// extremum or a free one flat), those vertices and their prescribed neighbours are released
/// to the harmonic fill and the solve repeated. Around a kept extremum that is not strict the
/// release widens ring by ring; with `move_kept` the extremum's value is moved outward instead
/// (`outward_moves`; u's values at kept extrema may be rescaled, SPEC). Returns u and what
/// was changed.
///
/// # Errors
/// A message when the harmonic solve fails; the caller checks the result with the
/// certificate and falls back when it does not pass.
pub fn separatrix_representative<D: crate::domain::Domain>(
    domain: &D,
    h: &[f64],
    kept: &KeptSet,
    ms: &crate::topology::morse_smale::MorseSmale,
    k: &crate::operators::Sparse,
    move_kept: bool,
    analyses: &mut crate::linalg::Analyses,
) -> std::result::Result<(Vec<f64>, Repairs), ConstructionError> {
    let n = h.len();
    let prescribed = interpolated_separatrices(domain, h, kept, ms);
    // Where the interpolated separatrices contradict each other (a separatrix vertex or a
    // saddle ends up below or above all its neighbours, or a free vertex between them is
    // flat), release the separatrices through those vertices (and through their prescribed
    // neighbours) to the harmonic fill and solve again.
    let separatrices: Vec<&[usize]> = ms.descending.iter().chain(&ms.ascending).map(|s| &s.path[..]).collect();
    let mut through: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, p) in separatrices.iter().enumerate() {
        for &v in p.iter() {
            through[v].push(i);
        }
    }
    let mut dirichlet = crate::operators::Dirichlet::new(k, analyses)?;
    let mut released = vec![false; n];
    let mut reach: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    let mut gone = vec![false; separatrices.len()];
    let mut count = 0;
    let (mut moved, mut pinned) = (std::collections::BTreeSet::new(), std::collections::BTreeSet::new());
    let unit = {
        let (lo, hi) = crate::domain::value_range(h);
        hi - lo
    };
    let mut prescribed = prescribed;
    for round in 1..=MAX_RELEASE_ROUNDS {
        if crate::progress::cancelled() {
            return Err(ConstructionError::Unfit("cancelled".into()));
        }
        let fixed: Vec<Option<f64>> = (0..n).map(|v| if released[v] { None } else { prescribed[v] }).collect();
        let u = dirichlet.solve(&fixed)?;
        let bad = failing(domain, kept, &u);
        crate::progress::update("representative", || {
            format!("separatrix round {round}: {} vertices fail, {count} released so far", bad.len())
        });
        let repairs = Repairs { released: count, moved: moved.len(), pinned: pinned.len() };
        if bad.is_empty() {
            return Ok((u, repairs));
        }
        let mut progress = false;
        if move_kept {
            // failing kept extrema move outward instead of releasing the rings around them
            for (v, value) in outward_moves(domain, kept, &fixed, &u, &mut dirichlet, k, unit)? {
                if kept.roles[v].is_fixed() {
                    moved.insert(v);
                } else {
                    pinned.insert(v);
                }
                prescribed[v] = Some(value);
                released[v] = false;
                progress = true;
            }
        }
        let release = |w: usize, released: &mut Vec<bool>, count: &mut usize| {
            if fixed[w].is_some() && !kept.roles[w].is_fixed() && !released[w] {
                released[w] = true;
                *count += 1;
                true
            } else {
                false
            }
        };
        for &v in &bad {
            // around a failing kept extremum the release reaches one ring further each round
            // (its free neighbours can stay above a kept maximum while prescribed vertices
            // farther out hold them up; doubling the radius instead made the retina image
            // release too much and fall back to the harmonic representative)
            let around: Vec<usize> = if kept.roles[v].is_fixed() {
                if move_kept {
                    continue;
                }
                // widen until the rings hold a vertex still prescribed (at most 64 rings)
                let r = reach.entry(v).or_insert(0);
                loop {
                    *r += 1;
                    let ring = rings(domain, v, *r);
                    if *r >= 64 || ring.iter().any(|&w| fixed[w].is_some() && !kept.roles[w].is_fixed()) {
                        break ring;
                    }
                }
            } else {
                std::iter::once(v).chain(domain.neighbors(v)).collect()
            };
            for w in around {
                if fixed[w].is_none() {
                    continue;
                }
                progress |= release(w, &mut released, &mut count);
                // a saddle stays while it has separatrices; a separatrix vertex takes its
                // whole separatrix with it
                if ms.saddles.binary_search(&w).is_err() {
                    for &s in &through[w] {
                        if !std::mem::replace(&mut gone[s], true) {
                            for &x in separatrices[s] {
                                if ms.saddles.binary_search(&x).is_err() {
                                    progress |= release(x, &mut released, &mut count);
                                }
                            }
                        }
                    }
                }
            }
        }
        if !progress {
            return Ok((u, repairs));
        }
    }
    Err(ConstructionError::Unfit(format!(
        "separatrix vertices still contradict each other after {MAX_RELEASE_ROUNDS} rounds of releasing them"
    )))
}

/// The separatrices' values: each vertex of a descending (ascending) separatrix linearly
/// interpolated by arc length between its saddle and its extremum, the smallest (largest)
/// where several meet, kept extrema and saddles at their values; `None` elsewhere and where
/// a descending and an ascending separatrix meet.
fn interpolated_separatrices<D: crate::domain::Domain>(
    domain: &D,
    h: &[f64],
    kept: &KeptSet,
    ms: &crate::topology::morse_smale::MorseSmale,
) -> Vec<Option<f64>> {
    let n = h.len();
    let mut down = vec![f64::INFINITY; n];
    let mut up = vec![f64::NEG_INFINITY; n];
    let dist = |a: usize, b: usize| {
        let (p, q) = (domain.point(a), domain.point(b));
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    let paint = |sep: &crate::topology::morse_smale::Separatrix, target: &mut Vec<f64>, lower: bool| {
        let p = &sep.path;
        let total: f64 = p.windows(2).map(|w| dist(w[0], w[1])).sum();
        let (hs, he) = (h[sep.saddle], h[*p.last().expect("non-empty")]);
        let mut run = 0.0;
        for (i, &v) in p.iter().enumerate() {
            if i > 0 {
                run += dist(p[i - 1], v);
            }
            let t = if total > 0.0 { run / total } else { 1.0 };
            let value = hs + (he - hs) * t;
            target[v] = if lower { target[v].min(value) } else { target[v].max(value) };
        }
    };
    for s in &ms.descending {
        paint(s, &mut down, true);
    }
    for s in &ms.ascending {
        paint(s, &mut up, false);
    }
    (0..n)
        .map(|v| {
            if kept.roles[v].is_fixed() || ms.saddles.binary_search(&v).is_ok() {
                Some(h[v])
            } else {
                match (down[v].is_finite(), up[v].is_finite()) {
                    (true, false) => Some(down[v]),
                    (false, true) => Some(up[v]),
                    _ => None,
                }
            }
        })
        .collect()
}

/// The vertices where `u` fails the representative's order: a free vertex that is not
/// regular, a kept extremum that is not strict.
fn failing<D: crate::domain::Domain>(domain: &D, kept: &KeptSet, u: &[f64]) -> Vec<usize> {
    (0..u.len())
        .filter(|&v| match kept.roles[v] {
            Role::Other => !is_regular(domain, u, v),
            Role::Min => domain.neighbors(v).any(|w| u[w] <= u[v]),
            Role::Max => domain.neighbors(v).any(|w| u[w] >= u[v]),
            _ => false,
        })
        .collect()
}

/// What [`separatrix_representative`] changed in the paper's construction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Repairs {
    /// Prescribed vertices released to the harmonic fill (counted each time).
    pub released: usize,
    /// Kept extrema whose value was moved outward.
    pub moved: usize,
    /// Free vertices prescribed between a kept extremum and its other neighbours.
    pub pinned: usize,
}

/// New values for the kept extrema that are not strict in the fill `u` of `fixed`, each
/// moved outward (a maximum up, a minimum down) far enough to clear its neighbours. This
/// mends what releasing cannot: the fill holding a kept extremum's free neighbours beyond it
/// from prescribed values farther out (a kept minimum beside lower harmonic values). The fill
/// is linear in the fixed values: a second solve with each failing value moved by `unit`
/// gives the fraction of the move each neighbour follows, and the move clears the farthest
/// neighbour with a quarter to spare. A free neighbour that follows (almost) fully is given a
/// value (pinned) instead, halfway to its farthest other neighbour.
fn outward_moves<D: crate::domain::Domain>(
    domain: &D,
    kept: &KeptSet,
    fixed: &[Option<f64>],
    u: &[f64],
    dirichlet: &mut crate::operators::Dirichlet,
    k: &crate::operators::Sparse,
    unit: f64,
) -> std::result::Result<Vec<(usize, f64)>, ConstructionError> {
    // +1 for a maximum (moves up), −1 for a minimum
    let outward = |v: usize| if kept.roles[v] == Role::Max { 1.0 } else { -1.0 };
    let failing: Vec<usize> = (0..u.len())
        .filter(|&v| {
            matches!(kept.roles[v], Role::Min | Role::Max)
                && domain.neighbors(v).any(|w| outward(v) * (u[w] - u[v]) >= 0.0)
        })
        .collect();
    if failing.is_empty() {
        return Ok(Vec::new());
    }
    let mut moved = fixed.to_vec();
    for &v in &failing {
        moved[v] = Some(u[v] + outward(v) * unit);
    }
    let u1 = dirichlet.solve(&moved)?;
    let mut out = Vec::new();
    for &v in &failing {
        let s = outward(v);
        let mut step: f64 = 0.0;
        for w in domain.neighbors(v) {
            let behind = s * (u[w] - u[v]);
            if behind < 0.0 {
                continue;
            }
            // w follows the move by this fraction (a prescribed neighbour does not follow)
            let follow = (s * (u1[w] - u[w]) / unit).max(0.0);
            // the fill makes w an average of kept extrema of v's type alone (a grid's corner
            // between two kept maxima, with the 5-point stencil): no move clears it
            let held = fixed[w].is_none() && {
                let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
                (cp[w]..cp[w + 1]).all(|p| ri[p] == w || val[p] == 0.0 || kept.roles[ri[p]] == kept.roles[v])
            };
            if follow < MAX_FOLLOW && !held {
                step = step.max(behind / (1.0 - follow));
                continue;
            }
            // held (almost) only by moved extrema, w cannot be cleared: it is prescribed
            // halfway between v and its farthest other neighbour on the inner side, if any
            let inner = domain.neighbors(w).filter(|&x| x != v).map(|x| s * u[x]).fold(f64::INFINITY, f64::min);
            if inner < s * u[v] && fixed[w].is_none() && kept.roles[w] == Role::Other {
                out.push((w, 0.5 * (u[v] + s * inner)));
            }
        }
        out.push((v, u[v] + s * (1.25 * step + 1e-9 * unit)));
    }
    Ok(out)
}

/// A free neighbour that follows a kept extremum's outward move by this fraction or more is
/// prescribed instead of being outrun ([`outward_moves`]).
const MAX_FOLLOW: f64 = 0.9;

/// Vertices within `radius` rings of `v` (itself included).
fn rings<D: crate::domain::Domain>(domain: &D, v: usize, radius: usize) -> Vec<usize> {
    let mut seen = std::collections::HashSet::from([v]);
    let mut out = vec![v];
    let mut frontier = vec![v];
    for _ in 0..radius {
        let mut next = Vec::new();
        for &x in &frontier {
            for y in domain.neighbors(x) {
                if seen.insert(y) {
                    next.push(y);
                }
            }
        }
        out.extend(&next);
        frontier = next;
    }
    out
}

/// Rounds of releasing contradicting separatrices (each one harmonic solve) before the
/// caller falls back to another representative.
const MAX_RELEASE_ROUNDS: usize = 16;

fn is_regular<D: crate::domain::Domain>(domain: &D, u: &[f64], v: usize) -> bool {
    let (mut lower, mut higher) = (false, false);
    for w in domain.neighbors(v) {
        lower |= u[w] < u[v];
        higher |= u[w] > u[v];
    }
    lower && higher
}

/// The data's own simplification as a representative (NOTES.md 9, after Tierny & Pascucci
/// 2012): a priority flood from the kept minima visits the vertices upwards and gives every
/// vertex at least the next double above the vertex visited before it, so cancelled basins are
/// raised to their spill level and ties are broken in visiting order; a flood from the kept
/// maxima does the same downwards. Every vertex but a seed is reached from a visited neighbour
/// with a strictly smaller (larger) value, so after the two floods only kept extrema remain
/// (repeated a few times if the second flood undid the first). Kept values are unchanged; the
/// plateaus get increments of one unit in the last place, keeping the flood order.
///
/// Returns `None` if the floods do not settle (the caller's check reports it).
pub fn flooded_representative<D: crate::domain::Domain>(domain: &D, h: &[f64], kept: &KeptSet) -> Option<Vec<f64>> {
    let mut g = h.to_vec();
    for _ in 0..8 {
        flood(domain, &mut g, kept, Role::Min);
        flood(domain, &mut g, kept, Role::Max);
        if crate::verify::certify(domain, &g, &kept.roles, None).passed {
            return Some(g);
        }
    }
    None
}

/// Priority flood from the kept extrema of one type (see [`flooded_representative`]).
fn flood<D: crate::domain::Domain>(domain: &D, g: &mut [f64], kept: &KeptSet, role: Role) {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let up = role == Role::Min;
    // a total order on finite doubles: their bits made monotone (descending for maxima)
    let key = |x: f64| {
        let x = if up { x } else { -x };
        let b = (if x == 0.0 { 0.0 } else { x }).to_bits();
        if b >> 63 == 1 {
            !b
        } else {
            b | (1 << 63)
        }
    };
    let n = g.len();
    // a vertex's value changes only when it is popped, so its key is the same whoever pushes
    // it: each vertex is pushed once (the order is that of pushing it from every neighbour)
    let mut queued = vec![false; n];
    let mut heap = BinaryHeap::with_capacity(n);
    for (v, &gv) in g.iter().enumerate() {
        if kept.roles[v] == role {
            heap.push(Reverse((key(gv), 0u8, v)));
            queued[v] = true;
        }
    }
    let mut last: Option<f64> = None;
    while let Some(Reverse((_, _, v))) = heap.pop() {
        if kept.roles[v] != role {
            if let Some(l) = last {
                g[v] = if up { g[v].max(l.next_up()) } else { g[v].min(l.next_down()) };
            }
        }
        last = Some(g[v]);
        for w in domain.neighbors(v) {
            if !queued[w] {
                queued[w] = true;
                heap.push(Reverse((key(g[w]), 1u8, w)));
            }
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn series_u_is_linear_between_the_kept_extrema() {
        use crate::topology::{select, Selection};
        let h = [0.0, 2.0, 1.0, 3.0, 2.5];
        let s = Series::uniform(5);
        let kept = select(&s, &h, &Selection::Explicit { minima: vec![0], maxima: vec![3] }).unwrap();
        let u = series_representative(&s, &h, &kept).unwrap();
        assert_eq!(u[..4], [0.0, 1.0, 2.0, 3.0]);
        assert!(u[4] < 3.0); // free end below the kept maximum
    }

    use super::*;
    use crate::topology::{select, Selection};

    #[test]
    fn counts_doubles() {
        assert_eq!(floats_between(1.0, 1.0f64.next_up()), 0);
        assert_eq!(floats_between(1.0, 1.0f64.next_up().next_up()), 1);
        assert_eq!(floats_between((-0.0f64).next_down(), 0.0f64.next_up()), 1); // just zero
    }

    #[test]
    fn too_close_kept_values_are_infeasible() {
        let a = 1.0;
        let b = a + 2.0 * f64::EPSILON; // one double strictly between
        let h = [a, 0.5 * (a + b), a, a, b];
        let s = Series::uniform(5);
        let kept = select(&s, &h, &Selection::Explicit { minima: vec![0], maxima: vec![4] });
        // vertex 0 must be a minimum of the input: it is (SoS), vertex 4 the global maximum
        let kept = kept.unwrap();
        let e = series_representative(&s, &h, &kept).unwrap_err();
        assert_eq!(e.exit_code(), 3, "{e}");
    }

    #[test]
    fn free_ends_get_room_for_a_strict_stretch() {
        // the left end is only two doubles above the kept minimum at 4 (review finding)
        let e = f64::EPSILON;
        let h = [1.0 + 2.0 * e, 1.0 + e, 1.0 + e, 1.0 + e, 1.0, 5.0, 0.0];
        let s = Series::uniform(7);
        let kept = select(&s, &h, &Selection::Relative(0.05)).unwrap();
        assert_eq!((kept.minima(), kept.maxima()), (vec![4, 6], vec![5]));
        let u = series_representative(&s, &h, &kept).unwrap();
        assert!(u[..5].windows(2).all(|w| w[0] > w[1]), "{u:?}");
    }

    #[test]
    fn tight_but_representable_stretch_becomes_strict() {
        let a = 1.0;
        let b = a + 4.0 * f64::EPSILON; // three doubles between: exactly enough for 3 samples
        let h = [a, a, a, a, b];
        let s = Series::uniform(5);
        let kept = select(&s, &h, &Selection::Explicit { minima: vec![0], maxima: vec![4] }).unwrap();
        let u = series_representative(&s, &h, &kept).unwrap();
        assert!(u.windows(2).all(|w| w[0] < w[1]), "{u:?}");
    }
}
