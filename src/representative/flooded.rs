//! The flooded representative: the data itself with every cancelled basin flooded to its
//! spill value, plateaus made strict in flood order.

use crate::topology::{KeptSet, Role};

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
