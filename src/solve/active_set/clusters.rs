//! The clusters a working set makes: a label and an offset per variable, an anchor or an
//! unknown per cluster.

use super::rows::Row;

pub(super) const NONE: u32 = u32::MAX;

/// The clusters of a working set: a label per variable, its offset from the cluster's value
/// (the tree rows hold as equalities, margin included: `x_j = x_i + ε`), per cluster its
/// anchored value (a bound row in the set) or its index among the unknowns.
pub(super) struct Clusters {
    pub(super) label: Vec<u32>,
    pub(super) offset: Vec<f64>,
    pub(super) anchor: Vec<Option<f64>>,
    pub(super) unknown: Vec<u32>,
    pub(super) n_unknowns: usize,
}

pub(super) fn find(parent: &mut [u32], mut v: u32) -> u32 {
    while parent[v as usize] != v {
        let p = parent[v as usize];
        parent[v as usize] = parent[p as usize];
        v = p;
    }
    v
}

impl Clusters {
    pub(super) fn new(n: usize, rows: &[Row], in_set: &[bool]) -> Clusters {
        // the forest's adjacency
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
        let mut adj = vec![(0usize, 0.0f64); deg[n]];
        let mut at = deg.clone();
        for (row, _) in rows.iter().zip(in_set).filter(|(_, &s)| s) {
            if let Row::Pair(i, j, b) = *row {
                // x_i − x_j = b: from i, j lies at −b; from j, i at +b
                adj[at[i]] = (j, -b);
                at[i] += 1;
                adj[at[j]] = (i, b);
                at[j] += 1;
            }
        }
        let mut label = vec![NONE; n];
        let mut offset = vec![0.0; n];
        let mut queue = Vec::new();
        let mut count = 0u32;
        for root in 0..n {
            if label[root] != NONE {
                continue;
            }
            label[root] = count;
            queue.clear();
            queue.push(root);
            let mut head = 0;
            while head < queue.len() {
                let v = queue[head];
                head += 1;
                for &(w, step) in &adj[deg[v]..deg[v + 1]] {
                    if label[w] == NONE {
                        label[w] = count;
                        offset[w] = offset[v] + step;
                        queue.push(w);
                    }
                }
            }
            count += 1;
        }
        let mut anchor: Vec<Option<f64>> = vec![None; count as usize];
        for (row, _) in rows.iter().zip(in_set).filter(|(_, &s)| s) {
            if let Row::Bound(v, a, b) = *row {
                anchor[label[v] as usize] = Some(a * b - offset[v]);
            }
        }
        let mut unknown = vec![NONE; anchor.len()];
        let mut n_unknowns = 0;
        for (c, a) in anchor.iter().enumerate() {
            if a.is_none() {
                unknown[c] = n_unknowns as u32;
                n_unknowns += 1;
            }
        }
        Clusters { label, offset, anchor, unknown, n_unknowns }
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
