//! The clusters a working set makes: a label and an offset per variable, an anchor or an
//! unknown per cluster, and the spanning trees the multipliers walk.

use super::rows::{Row, RowKind};

pub(super) const NONE: u32 = u32::MAX;

/// The working set's trees, breadth first from each cluster's root (its anchor row's variable
/// when anchored, else its first variable): each variable's step up and its depth.
pub(super) struct Forest {
    pub(super) up: Vec<Up>,
    pub(super) depth: Vec<u32>,
    /// The variables cluster by cluster, each cluster's in breadth-first order from its root.
    pub(super) order: Vec<usize>,
}

/// A variable's step up its tree: the row to its parent, which side of the row it is (the
/// row's top bit: set when the variable is the first of `Pair(i, j, _)`), and its parent;
/// [`Up::ROOT`] at a root. One record per variable, so that a search touches one place.
#[derive(Clone, Copy)]
pub(super) struct Up {
    row: u32,
    parent: u32,
}

impl Up {
    const FIRST: u32 = 1 << 31;
    pub(super) const ROOT: Up = Up { row: NONE, parent: NONE };

    /// The row to the parent, `None` at a root.
    pub(super) fn row(self) -> Option<usize> {
        (self.row != NONE).then_some((self.row & !Up::FIRST) as usize)
    }

    pub(super) fn parent(self) -> usize {
        self.parent as usize
    }

    /// Whether the variable is its row's first (`i` of `Pair(i, j, _)`).
    pub(super) fn is_first(self) -> bool {
        self.row & Up::FIRST != 0
    }
}

impl Forest {
    /// Calls `visit(row, rises)` for each tree row on the path from `i` to `j` (one tree),
    /// `rises` when `x` rises along it in the direction `i → j`.
    pub(super) fn walk_path(&self, mut i: usize, mut j: usize, mut visit: impl FnMut(usize, bool)) {
        // Pair(a, b) is x_a − x_b ≤ −ε: x rises from a to b. Walking up from i, a row rises
        // along i → j when i's side is its a; walking up from j, when j's side is its b.
        while i != j {
            let (v, from_i) = if self.depth[i] >= self.depth[j] { (i, true) } else { (j, false) };
            let up = self.up[v];
            let Some(k) = up.row() else { return };
            visit(k, up.is_first() == from_i);
            if from_i {
                i = up.parent();
            } else {
                j = up.parent();
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

/// The rows in the working set with their indices, in row order.
fn in_set_rows<'a>(rows: &'a [Row], in_set: &'a [bool]) -> impl Iterator<Item = (usize, &'a Row)> + 'a {
    rows.iter().enumerate().zip(in_set).filter(|(_, &s)| s).map(|(r, _)| r)
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
        for (_, row) in in_set_rows(rows, in_set) {
            if let RowKind::Pair(i, j, _) = row.kind() {
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
        for (k, row) in in_set_rows(rows, in_set) {
            if let RowKind::Bound(v, _, _) = row.kind() {
                anchor_row[label[v] as usize] = k;
            }
        }
        Labels { label, anchor_row }
    }
}

/// A row of the working set as seen from one of its variables: the variable across it and
/// that variable's offset from this one.
#[derive(Clone, Copy)]
struct Across {
    /// The row, its top bit set when `to` is its first variable (as in [`Up`]).
    row: u32,
    to: u32,
    step: f64,
}

impl Clusters {
    pub(super) fn new(n: usize, rows: &[Row], in_set: &[bool]) -> Clusters {
        // the forest's adjacency: per variable its rows in the set, in row order, each with
        // the variable across it and that variable's offset from this one (x_i − x_j = b:
        // from i, j lies at −b; from j, i at +b), so that the searches below never look up
        // the rows themselves
        let mut deg = vec![0u32; n + 1];
        for (_, row) in in_set_rows(rows, in_set) {
            if let RowKind::Pair(i, j, _) = row.kind() {
                deg[i + 1] += 1;
                deg[j + 1] += 1;
            }
        }
        for v in 0..n {
            deg[v + 1] += deg[v];
        }
        let mut adj = vec![Across { row: 0, to: 0, step: 0.0 }; deg[n] as usize];
        let mut at = deg.clone();
        for (k, row) in in_set_rows(rows, in_set) {
            if let RowKind::Pair(i, j, b) = row.kind() {
                adj[at[i] as usize] = Across { row: k as u32, to: j as u32, step: -b };
                at[i] += 1;
                adj[at[j] as usize] = Across { row: k as u32 | Up::FIRST, to: i as u32, step: b };
                at[j] += 1;
            }
        }
        drop(at);
        let adjacent = |v: usize| &adj[deg[v] as usize..deg[v + 1] as usize];
        let mut label = vec![NONE; n];
        let mut offset = vec![0.0; n];
        // rows and variables are counted in u32, the row's top bit marking its side
        assert!(rows.len() < Up::FIRST as usize && n < NONE as usize, "more rows or variables than the clusters count");
        let mut up = vec![Up::ROOT; n];
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
                for a in adjacent(v) {
                    let w = a.to as usize;
                    if label[w] == NONE {
                        label[w] = count;
                        offset[w] = offset[v] + a.step;
                        up[w] = Up { row: a.row, parent: v as u32 };
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
        for (k, row) in in_set_rows(rows, in_set) {
            if let RowKind::Bound(v, a, b) = row.kind() {
                anchor[label[v] as usize] = Some(a * b - offset[v]);
                anchor_row[label[v] as usize] = k;
            }
        }
        // an anchored cluster's tree runs from its anchor's variable: breadth first again
        // from there, over the cluster's own stretch of `order`
        let mut seen = Vec::new();
        for (c, &k) in anchor_row.iter().enumerate() {
            let Some(RowKind::Bound(root, _, _)) = rows.get(k).map(|r| r.kind()) else { continue };
            if order[first[c]] == root {
                continue;
            }
            if seen.is_empty() {
                seen = vec![false; n];
            }
            let (start, end) = (first[c], first[c + 1]);
            seen[root] = true;
            up[root] = Up::ROOT;
            depth[root] = 0;
            order[start] = root;
            let (mut head, mut tail) = (start, start + 1);
            while head < tail {
                let v = order[head];
                head += 1;
                for a in adjacent(v) {
                    let w = a.to as usize;
                    if !seen[w] {
                        seen[w] = true;
                        up[w] = Up { row: a.row, parent: v as u32 };
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
        Clusters { label, offset, anchor, anchor_row, unknown, n_unknowns, forest: Forest { up, depth, order } }
    }

    /// `x = C y + anchors + offsets`, on contiguous pieces one a thread.
    pub(super) fn expand(&self, y: &[f64], x: &mut [f64]) {
        crate::parallel::split_mut(x, |off, piece| {
            for ((xv, &c), o) in piece.iter_mut().zip(&self.label[off..]).zip(&self.offset[off..]) {
                *xv = o + match self.anchor[c as usize] {
                    Some(a) => a,
                    None => y[self.unknown[c as usize] as usize],
                };
            }
        });
    }
}
