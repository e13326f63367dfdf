//! The clusters a working set makes: a label and an offset per variable, an anchor or an
//! unknown per cluster, and the spanning trees the multipliers walk.

use super::rows::Row;

pub(super) const NONE: u32 = u32::MAX;

/// The working set's trees, breadth first from each cluster's root (its anchor row's variable
/// when anchored, else its first variable): each variable's row to its parent (`usize::MAX`
/// at a root) and its depth.
pub(super) struct Forest {
    pub(super) parent_row: Vec<usize>,
    pub(super) depth: Vec<u32>,
    /// The variables cluster by cluster, each cluster's in breadth-first order from its root.
    pub(super) order: Vec<usize>,
}

impl Forest {
    /// Calls `visit(row, rises)` for each tree row on the path from `i` to `j` (one tree),
    /// `rises` when `x` rises along it in the direction `i → j`.
    pub(super) fn walk_path(&self, rows: &[Row], mut i: usize, mut j: usize, mut visit: impl FnMut(usize, bool)) {
        // Pair(a, b) is x_a − x_b ≤ −ε: x rises from a to b. Walking up from i, a row rises
        // along i → j when i's side is its a; walking up from j, when j's side is its b.
        let other = |k: usize, v: usize| match rows[k] {
            Row::Pair(a, b, _) => (if a == v { b } else { a }, a == v),
            Row::Bound(..) => unreachable!("tree rows are pairs"),
        };
        while i != j {
            if self.depth[i] >= self.depth[j] {
                let k = self.parent_row[i];
                if k == usize::MAX {
                    return;
                }
                let (p, from_a) = other(k, i);
                visit(k, from_a);
                i = p;
            } else {
                let k = self.parent_row[j];
                if k == usize::MAX {
                    return;
                }
                let (p, from_a) = other(k, j);
                visit(k, !from_a);
                j = p;
            }
        }
    }
}

/// The clusters of a working set: a label per variable, its offset from the cluster's value
/// (the tree rows hold as equalities, margin included: `x_j = x_i + ε`), per cluster its
/// anchored value (a bound row in the set) or its index among the unknowns.
pub(super) struct Clusters {
    pub(super) label: Vec<u32>,
    pub(super) offset: Vec<f64>,
    pub(super) anchor: Vec<Option<f64>>,
    /// Per cluster its anchor row (`usize::MAX` when unanchored).
    pub(super) anchor_row: Vec<usize>,
    pub(super) unknown: Vec<u32>,
    pub(super) n_unknowns: usize,
    pub(super) forest: Forest,
}

pub(super) fn find(parent: &mut [u32], mut v: u32) -> u32 {
    while parent[v as usize] != v {
        let p = parent[v as usize];
        parent[v as usize] = parent[p as usize];
        v = p;
    }
    v
}

/// Each variable's cluster as its union-find root, which cluster is anchored and by which
/// row (the last bound row in the set, as [`Clusters::new`] takes it): the clusters without
/// offsets or trees, for the join step after the cuts.
pub(super) struct Labels {
    pub(super) label: Vec<u32>,
    pub(super) anchor_row: Vec<usize>,
}

impl Labels {
    pub(super) fn new(n: usize, rows: &[Row], in_set: &[bool]) -> Labels {
        let mut label: Vec<u32> = (0..n as u32).collect();
        for (row, _) in rows.iter().zip(in_set).filter(|(_, &s)| s) {
            if let Row::Pair(i, j, _) = *row {
                let (a, b) = (find(&mut label, i as u32), find(&mut label, j as u32));
                if a != b {
                    label[a as usize] = b;
                }
            }
        }
        for v in 0..n as u32 {
            label[v as usize] = find(&mut label, v);
        }
        let mut anchor_row = vec![usize::MAX; n];
        for (k, (row, _)) in rows.iter().zip(in_set).enumerate().filter(|(_, (_, &s))| s) {
            if let Row::Bound(v, _, _) = *row {
                anchor_row[label[v] as usize] = k;
            }
        }
        Labels { label, anchor_row }
    }
}

impl Clusters {
    pub(super) fn new(n: usize, rows: &[Row], in_set: &[bool]) -> Clusters {
        // the forest's adjacency: per variable its rows in the set, in row order
        let mut deg = vec![0usize; n + 1];
        for (row, _) in rows.iter().zip(in_set).filter(|(_, &s)| s) {
            if let Row::Pair(i, j, _) = *row {
                deg[i + 1] += 1;
                deg[j + 1] += 1;
            }
        }
        for v in 0..n {
            deg[v + 1] += deg[v];
        }
        let mut adj = vec![0usize; deg[n]];
        let mut at = deg.clone();
        for (k, (row, _)) in rows.iter().zip(in_set).enumerate().filter(|(_, (_, &s))| s) {
            if let Row::Pair(i, j, _) = *row {
                adj[at[i]] = k;
                at[i] += 1;
                adj[at[j]] = k;
                at[j] += 1;
            }
        }
        drop(at);
        // x_i − x_j = b: from i, j lies at −b; from j, i at +b
        let across = |k: usize, v: usize| match rows[k] {
            Row::Pair(i, j, b) => {
                if v == i {
                    (j, -b)
                } else {
                    (i, b)
                }
            }
            Row::Bound(..) => unreachable!("the adjacency holds pair rows"),
        };
        let mut label = vec![NONE; n];
        let mut offset = vec![0.0; n];
        let mut parent_row = vec![usize::MAX; n];
        let mut depth = vec![0u32; n];
        let mut order = Vec::with_capacity(n);
        let mut first = Vec::new();
        let mut count = 0u32;
        for root in 0..n {
            if label[root] != NONE {
                continue;
            }
            label[root] = count;
            first.push(order.len());
            order.push(root);
            let mut head = order.len() - 1;
            while head < order.len() {
                let v = order[head];
                head += 1;
                for &k in &adj[deg[v]..deg[v + 1]] {
                    let (w, step) = across(k, v);
                    if label[w] == NONE {
                        label[w] = count;
                        offset[w] = offset[v] + step;
                        parent_row[w] = k;
                        depth[w] = depth[v] + 1;
                        order.push(w);
                    }
                }
            }
            count += 1;
        }
        first.push(n);
        let nc = count as usize;
        let mut anchor: Vec<Option<f64>> = vec![None; nc];
        let mut anchor_row = vec![usize::MAX; nc];
        for (k, (row, _)) in rows.iter().zip(in_set).enumerate().filter(|(_, (_, &s))| s) {
            if let Row::Bound(v, a, b) = *row {
                anchor[label[v] as usize] = Some(a * b - offset[v]);
                anchor_row[label[v] as usize] = k;
            }
        }
        // an anchored cluster's tree runs from its anchor's variable: breadth first again
        // from there, over the cluster's own stretch of `order`
        let mut seen = Vec::new();
        for (c, &k) in anchor_row.iter().enumerate() {
            let Some(Row::Bound(root, _, _)) = rows.get(k).copied() else { continue };
            if order[first[c]] == root {
                continue;
            }
            if seen.is_empty() {
                seen = vec![false; n];
            }
            let (start, end) = (first[c], first[c + 1]);
            seen[root] = true;
            parent_row[root] = usize::MAX;
            depth[root] = 0;
            order[start] = root;
            let (mut head, mut tail) = (start, start + 1);
            while head < tail {
                let v = order[head];
                head += 1;
                for &k in &adj[deg[v]..deg[v + 1]] {
                    let (w, _) = across(k, v);
                    if !seen[w] {
                        seen[w] = true;
                        parent_row[w] = k;
                        depth[w] = depth[v] + 1;
                        order[tail] = w;
                        tail += 1;
                    }
                }
            }
            debug_assert_eq!(tail, end, "a cluster's tree covers its stretch");
        }
        let mut unknown = vec![NONE; nc];
        let mut n_unknowns = 0;
        for (c, a) in anchor.iter().enumerate() {
            if a.is_none() {
                unknown[c] = n_unknowns as u32;
                n_unknowns += 1;
            }
        }
        Clusters { label, offset, anchor, anchor_row, unknown, n_unknowns, forest: Forest { parent_row, depth, order } }
    }

    pub(super) fn expand(&self, y: &[f64], x: &mut [f64]) {
        for ((xv, &c), o) in x.iter_mut().zip(&self.label).zip(&self.offset) {
            *xv = o + match self.anchor[c as usize] {
                Some(a) => a,
                None => y[self.unknown[c as usize] as usize],
            };
        }
    }
}
