//! The flooded representative: the data itself with every cancelled basin flooded to its
//! spill value, plateaus made strict in flood order.

use crate::topology::{KeptSet, Role};
use crate::verify::Certificate;

/// The data's own simplification as a representative (NOTES.md 9, after Tierny & Pascucci
/// 2012): a priority flood from the kept minima visits the vertices upwards and gives every
/// vertex at least the next double above the vertex visited before it, so cancelled basins are
/// raised to their spill level and ties are broken in the order the flood reached them (a
/// plateau rises with the distance from where the flood entered it); a flood from the kept
/// maxima does the same downwards. Every vertex but a seed is reached from a visited neighbour
/// with a strictly smaller (larger) value, so after the two floods only kept extrema remain
/// (repeated a few times if the second flood undid the first). Kept values are unchanged; the
/// plateaus get increments of one unit in the last place, keeping the flood order.
///
/// Returns the representative with the certificate that ended the floods and its vertices in
/// increasing order (the last flood's visits reversed; `None` where they are not u's order:
/// with ties a kept maximum may leave after neighbours the flood lowered below it), or `None`
/// if the floods do not settle (the caller's check reports it) or past 2³² vertices (a flood's
/// entries hold a vertex and a count in 32 bits each; such a field's values alone take
/// 32 GiB).
pub fn flooded_representative<D: crate::domain::Domain>(
    domain: &D,
    h: &[f64],
    kept: &KeptSet,
) -> Option<(Vec<f64>, Certificate, Option<Vec<usize>>)> {
    if u32::try_from(h.len()).is_err() {
        return None;
    }
    let mut g = h.to_vec();
    let mut order = Vec::with_capacity(h.len());
    for _ in 0..8 {
        flood(domain, &mut g, kept, Role::Min, None);
        flood(domain, &mut g, kept, Role::Max, Some(&mut order));
        let certificate = crate::verify::certify(domain, &g, &kept.roles, None);
        if certificate.passed {
            order.reverse();
            let increasing =
                order.len() == g.len() && order.windows(2).all(|w| crate::domain::sos_less(&g, w[0], w[1]));
            return Some((g, certificate, increasing.then_some(order)));
        }
    }
    None
}

/// Priority flood from the kept extrema of one type (see [`flooded_representative`]); the
/// vertices in the order it visits them in `visited`, when given.
fn flood<D: crate::domain::Domain>(
    domain: &D,
    g: &mut [f64],
    kept: &KeptSet,
    role: Role,
    mut visited: Option<&mut Vec<usize>>,
) {
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
    // equal keys leave in the order they were reached, so a plateau rises (falls) with the
    // distance from where the flood entered it, as a flat drains to its outlet in a
    // hydrological flat resolution, not in the order of the vertices' indices
    let mut queued = vec![false; n];
    // an entry is its key, the count of pushes up to it and the vertex, packed in one integer
    // (16 bytes, one comparison; a tuple of the three took 24 bytes and three): the order is
    // the key's, equal keys in the order reached
    let mut reached = 0u128;
    let mut frontier = Frontier::default();
    let entry = |gv: f64, reached: &mut u128, v: usize| {
        *reached += 1;
        (u128::from(key(gv)) << 64) | (*reached << 32) | v as u128
    };
    for (v, &gv) in g.iter().enumerate() {
        if kept.roles[v] == role {
            frontier.push(entry(gv, &mut reached, v));
            queued[v] = true;
        }
    }
    let mut last: Option<f64> = None;
    if let Some(visited) = visited.as_deref_mut() {
        visited.clear();
    }
    while let Some(e) = frontier.pop() {
        let v = e as u32 as usize;
        if let Some(visited) = visited.as_deref_mut() {
            visited.push(v);
        }
        if kept.roles[v] != role {
            if let Some(l) = last {
                g[v] = if up { g[v].max(l.next_up()) } else { g[v].min(l.next_down()) };
            }
        }
        last = Some(g[v]);
        for w in domain.neighbors(v) {
            if !queued[w] {
                queued[w] = true;
                frontier.push(entry(g[w], &mut reached, w));
            }
        }
    }
}

/// The flood's queue: its entries leave smallest first. A heap of four children a node (with
/// 16-byte entries a node's children share a cache line, and it has half the levels of a
/// binary heap). At 128³ the two floods took 1.76–2.0 s with a binary heap of (key, count,
/// vertex) tuples and 1.20–1.52 s with this one, the same order (docs/performance.md,
/// "Topology against TTK").
#[derive(Default)]
struct Frontier(dary_heap::QuaternaryHeap<std::cmp::Reverse<u128>>);

impl Frontier {
    fn push(&mut self, e: u128) {
        self.0.push(std::cmp::Reverse(e));
    }

    fn pop(&mut self) -> Option<u128> {
        self.0.pop().map(|e| e.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{Domain, Grid2d};
    use crate::topology::{select, Selection};

    /// A plateau entered from one corner rises with the graph distance from that corner (the
    /// order a flood reaches it), not with the vertices' indices.
    #[test]
    fn a_plateau_rises_with_the_distance_from_where_the_flood_entered() {
        let (nx, ny) = (6, 5);
        let g = Grid2d::new(nx, ny).unwrap();
        let n = nx * ny;
        // one minimum at the last vertex, one maximum at the first, a plateau between
        let mut h = vec![1.0; n];
        (h[n - 1], h[0]) = (0.0, 2.0);
        let kept = select(&g, &h, &Selection::Explicit { minima: vec![n - 1], maxima: vec![0] }).unwrap();
        let (u, _, order) = flooded_representative(&g, &h, &kept).unwrap();
        // graph distances from the minimum
        let mut dist = vec![usize::MAX; n];
        dist[n - 1] = 0;
        let mut queue = std::collections::VecDeque::from([n - 1]);
        while let Some(v) = queue.pop_front() {
            for w in g.neighbors(v) {
                if dist[w] == usize::MAX {
                    dist[w] = dist[v] + 1;
                    queue.push_back(w);
                }
            }
        }
        let plateau: Vec<usize> = (1..n - 1).collect();
        for &a in &plateau {
            for &b in &plateau {
                if dist[a] < dist[b] {
                    assert!(
                        u[a] < u[b],
                        "u[{a}] = {} (distance {}) not below u[{b}] = {} (distance {})",
                        u[a],
                        dist[a],
                        u[b],
                        dist[b]
                    );
                }
            }
        }
        assert!(crate::verify::certify(&g, &u, &kept.roles, None).passed);
        assert_eq!(order, Some(crate::domain::sos_sort(&u)));
    }

    /// The order handed over is u's own ([`crate::domain::sos_sort`]) on noisy fields, with
    /// ties (then it may not be handed over) and without, whose floods raise basins and
    /// plateaus.
    #[test]
    fn the_order_handed_over_is_the_representatives() {
        let (nx, ny) = (23, 17);
        let g = Grid2d::new(nx, ny).unwrap();
        let mut state = 88172645463325252u64;
        let mut handed = 0;
        for (levels, step) in [(7u64, 8.0), (50, 8.0), (1 << 20, 0.0), (1 << 30, 0.0)] {
            let h: Vec<f64> = (0..nx * ny)
                .map(|v| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    let (x, y) = ((v % nx) as f64 / nx as f64, (v / nx) as f64 / ny as f64);
                    (6.0 * x).sin() * (5.0 * y).cos() + (state % levels) as f64 / levels as f64
                })
                .map(|x| if step > 0.0 { (x * step).round() / step } else { x })
                .collect();
            let kept = select(&g, &h, &Selection::Relative(0.2)).unwrap();
            let (u, c, order) = flooded_representative(&g, &h, &kept).unwrap();
            assert!(c.passed);
            if let Some(order) = order {
                assert_eq!(order, crate::domain::sos_sort(&u));
                handed += 1;
            } else {
                // a kept maximum of a tie class lowered around it leaves after its neighbours
                assert!(step > 0.0, "no order handed over without ties ({levels} levels)");
            }
        }
        assert!(handed >= 2);
    }
}
