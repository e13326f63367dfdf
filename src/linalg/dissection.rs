//! Nested dissection by BFS level structures: from a pseudo-peripheral vertex, one BFS level
//! separates the levels before it from those after it, so it is a vertex separator of any
//! graph; each part is ordered before its separator, small parts by faer's AMD.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

/// Compressed columns from buckets: `rows[start[j]..start[j + 1]]` holds column `j`'s row
/// indices in any order, repeats allowed. Returns the column pointers and the sorted, distinct
/// row indices of every column.
pub fn compress_columns(start: &[usize], rows: &mut [usize]) -> (Vec<usize>, Vec<usize>) {
    let n = start.len() - 1;
    let mut col_ptr = vec![0usize; n + 1];
    let mut row_idx = Vec::with_capacity(rows.len());
    for j in 0..n {
        let col = &mut rows[start[j]..start[j + 1]];
        col.sort_unstable();
        let first = row_idx.len();
        for &i in col.iter() {
            if row_idx.len() == first || row_idx[row_idx.len() - 1] != i {
                row_idx.push(i);
            }
        }
        col_ptr[j + 1] = row_idx.len();
    }
    (col_ptr, row_idx)
}

/// An undirected graph in compressed adjacency form (no self loops).
pub struct Graph {
    xadj: Vec<usize>,
    adj: Vec<usize>,
}

impl Graph {
    /// The graph of a symmetric pattern given by one triangle (or both) in column form;
    /// diagonal entries are ignored, duplicate edges are harmless.
    pub fn from_pattern(a: SymbolicSparseColMatRef<'_, usize>) -> Graph {
        let n = a.ncols();
        let (cp, ri) = (a.col_ptr(), a.row_idx());
        let col = |j: usize| &ri[cp[j]..a.col_range(j).end];
        let mut deg = vec![0usize; n + 1];
        for j in 0..n {
            for &i in col(j) {
                if i != j {
                    deg[i + 1] += 1;
                    deg[j + 1] += 1;
                }
            }
        }
        for j in 0..n {
            deg[j + 1] += deg[j];
        }
        let mut fill = deg.clone();
        let mut adj = vec![0usize; deg[n]];
        for j in 0..n {
            for &i in col(j) {
                if i != j {
                    adj[fill[i]] = j;
                    fill[i] += 1;
                    adj[fill[j]] = i;
                    fill[j] += 1;
                }
            }
        }
        // sorted and deduplicated (a full symmetric pattern lists every edge twice)
        let (xadj, adj) = compress_columns(&deg, &mut adj);
        Graph { xadj, adj }
    }

    /// Number of vertices.
    pub fn n(&self) -> usize {
        self.xadj.len() - 1
    }

    fn neighbours(&self, v: usize) -> &[usize] {
        &self.adj[self.xadj[v]..self.xadj[v + 1]]
    }
}

/// Working state of the dissection: `owner[v]` is the part a vertex still belongs to
/// (`u32::MAX` once placed), BFS bookkeeping reuses stamped arrays.
struct Dissect<'g> {
    g: &'g Graph,
    owner: Vec<u32>,
    next_part: u32,
    stamp: Vec<u32>,
    cur: u32,
    level: Vec<u32>,
    queue: Vec<usize>,
    local: Vec<usize>,
}

const PLACED: u32 = u32::MAX;

impl Dissect<'_> {
    fn new_part(&mut self) -> u32 {
        self.next_part += 1;
        self.next_part
    }

    /// BFS from `root` inside part `p`; fills `queue` in visit order, returns the start of
    /// each level (plus the end) in `queue`.
    fn bfs(&mut self, root: usize, p: u32) -> Vec<usize> {
        self.cur += 1;
        let cur = self.cur;
        self.queue.clear();
        self.queue.push(root);
        self.stamp[root] = cur;
        self.level[root] = 0;
        let mut bounds = vec![0usize];
        let mut head = 0;
        while head < self.queue.len() {
            let v = self.queue[head];
            let lv = self.level[v];
            for &u in self.g.neighbours(v) {
                if self.owner[u] == p && self.stamp[u] != cur {
                    self.stamp[u] = cur;
                    self.level[u] = lv + 1;
                    self.queue.push(u);
                }
            }
            head += 1;
            if head < self.queue.len() && self.level[self.queue[head]] != lv {
                bounds.push(head);
            }
        }
        bounds.push(self.queue.len());
        bounds
    }

    /// Vertices of part `p` split into connected components (each becomes a new part).
    fn components(&mut self, verts: &[usize], p: u32) -> Vec<(u32, Vec<usize>)> {
        let mut comps = Vec::new();
        for &v in verts {
            if self.owner[v] != p {
                continue;
            }
            self.bfs(v, p);
            let q = self.new_part();
            let comp = self.queue.clone();
            for &u in &comp {
                self.owner[u] = q;
            }
            comps.push((q, comp));
        }
        comps
    }

    /// Orders a small part in positions `out[lo..lo + verts.len()]` by AMD on its subgraph.
    fn leaf(&mut self, verts: &[usize], out: &mut [usize], lo: usize) {
        let k = verts.len();
        for v in verts {
            self.owner[*v] = PLACED;
        }
        if k <= 3 {
            out[lo..lo + k].copy_from_slice(verts);
            return;
        }
        for (li, &v) in verts.iter().enumerate() {
            self.local[v] = li;
        }
        let mut cp = vec![0usize; k + 1];
        let mut ri = Vec::new();
        for (li, &v) in verts.iter().enumerate() {
            for &u in self.g.neighbours(v) {
                // neighbours already placed or in other parts are not in this leaf
                if self.stamp_leaf(u, verts) {
                    ri.push(self.local[u]);
                }
            }
            ri.push(li);
            ri[cp[li]..].sort_unstable();
            cp[li + 1] = ri.len();
        }
        let sub = SymbolicSparseColMatRef::new_checked(k, k, &cp, None, &ri);
        let mut fwd = vec![0usize; k];
        let mut inv = vec![0usize; k];
        let mut mem = MemBuffer::new(amd::order_maybe_unsorted_scratch::<usize>(k, ri.len()));
        match amd::order_maybe_unsorted(&mut fwd, &mut inv, sub, amd::Control::default(), MemStack::new(&mut mem)) {
            Ok(_) => {
                for (i, &f) in fwd.iter().enumerate() {
                    out[lo + i] = verts[f];
                }
            }
            Err(_) => out[lo..lo + k].copy_from_slice(verts),
        }
    }

    /// Whether `u` belongs to the leaf being ordered (its vertices were just marked placed
    /// and given local indices).
    fn stamp_leaf(&self, u: usize, verts: &[usize]) -> bool {
        self.owner[u] == PLACED && self.local[u] < verts.len() && verts[self.local[u]] == u
    }
}

/// The separator level of a level structure (level starts `bounds`, `len` vertices): smallest
/// `|S| / (|A| |B|)` among fairly balanced levels, as (score, level).
fn best_level(bounds: &[usize], len: usize, min_fraction: f64) -> (f64, usize) {
    let nlev = bounds.len() - 1;
    let mut best = (f64::INFINITY, nlev / 2);
    for k in 1..nlev.saturating_sub(1) {
        let a = bounds[k] as f64;
        let s = (bounds[k + 1] - bounds[k]) as f64;
        let b = len as f64 - a - s;
        if a.min(b) < min_fraction * len as f64 {
            continue;
        }
        let score = s / (a * b);
        if score < best.0 {
            best = (score, k);
        }
    }
    best
}

/// Smallest share of the vertices in each part at the top level of the dissection.
const TOP_BALANCE: f64 = 0.45;

#[cfg(test)]
/// A nested-dissection ordering of `g`: `perm[new] = old`. Parts of at most `leaf_size`
/// vertices are ordered by AMD.
pub fn nested_dissection(g: &Graph, leaf_size: usize) -> Vec<usize> {
    nested_dissection_split(g, leaf_size).0
}

#[cfg(test)]
/// [`nested_dissection`] and, when the whole graph was bisected at the top (it is connected
/// and not a near-clique), the sizes `[a, b]` of the two parts: `perm[..a]` is one part,
/// `perm[a..a + b]` the other, `perm[a + b..]` the separator between them, and no edge joins
/// the two parts. Above [`PARALLEL_DISSECTION_MIN`] vertices the two top parts are dissected
/// side by side (the result is the same as one after the other).
pub fn nested_dissection_split(g: &Graph, leaf_size: usize) -> (Vec<usize>, Option<[usize; 2]>) {
    dissection(g, leaf_size, g.n() >= PARALLEL_DISSECTION_MIN)
}

pub(super) fn dissection(g: &Graph, leaf_size: usize, parallel: bool) -> (Vec<usize>, Option<[usize; 2]>) {
    let n = g.n();
    let mut out = vec![0usize; n];
    let mut d = Dissect::new(g, 0);
    let leaf_size = leaf_size.max(1);
    let all: Vec<usize> = (0..n).collect();
    if n <= leaf_size {
        d.run(vec![(0, all, 0)], &mut out, 0, leaf_size);
        return (out, None);
    }
    // the top level is split evenly: its two parts are factorised side by side
    let bounds = d.bfs(0, 0);
    let connected = d.queue.len() == n;
    let Some((pa, part_a, pb, part_b, sep)) = connected.then(|| d.bisect(0, bounds, TOP_BALANCE)).flatten() else {
        // not connected, or (nearly) a clique: no top split
        let mut d = Dissect::new(g, 0);
        d.run(vec![(0, all, 0)], &mut out, 0, leaf_size);
        return (out, None);
    };
    let (la, lb) = (part_a.len(), part_b.len());
    out[la + lb..].copy_from_slice(&sep);
    let (out_a, rest) = out.split_at_mut(la);
    let out_b = &mut rest[..lb];
    if parallel {
        // the other part with its own bookkeeping and part numbers, on another thread where
        // the cap allows one (the ordering is the same either way)
        let mut d2 = Dissect { owner: d.owner.clone(), ..Dissect::new(g, u32::MAX / 2) };
        crate::parallel::join(
            || d.run(vec![(pa, part_a, 0)], out_a, 0, leaf_size),
            move || d2.run(vec![(pb, part_b, la)], out_b, la, leaf_size),
        );
    } else {
        d.run(vec![(pa, part_a, 0)], out_a, 0, leaf_size);
        d.run(vec![(pb, part_b, la)], out_b, la, leaf_size);
    }
    (out, Some([la, lb]))
}

/// Graphs at least this large are dissected on two threads below the top level (below it the
/// second thread costs more than it saves).
pub(super) const PARALLEL_DISSECTION_MIN: usize = 100_000;

impl<'g> Dissect<'g> {
    fn new(g: &'g Graph, first_part: u32) -> Dissect<'g> {
        let n = g.n();
        Dissect {
            g,
            owner: vec![0; n],
            next_part: first_part,
            stamp: vec![0; n],
            cur: 0,
            level: vec![0; n],
            queue: Vec::new(),
            local: vec![0; n],
        }
    }

    /// Dissects the parts on `stack` (part, vertices, first output position), writing
    /// position `i` to `out[i - base]`.
    fn run(&mut self, mut stack: Vec<(u32, Vec<usize>, usize)>, out: &mut [usize], base: usize, leaf_size: usize) {
        while let Some((p, verts, lo)) = stack.pop() {
            let len = verts.len();
            if len == 0 {
                continue;
            }
            if len <= leaf_size {
                self.leaf(&verts, out, lo - base);
                continue;
            }
            // BFS from any vertex; a part that is not connected is split into its components
            let bounds = self.bfs(verts[0], p);
            if self.queue.len() < len {
                let mut at = lo;
                for (q, c) in self.components(&verts, p) {
                    let l = c.len();
                    stack.push((q, c, at));
                    at += l;
                }
                continue;
            }
            let Some((pa, part_a, pb, part_b, sep)) = self.bisect(p, bounds, 0.2) else {
                // (nearly) a clique: nothing to dissect
                self.leaf(&verts, out, lo - base);
                continue;
            };
            let (la, lb) = (part_a.len(), part_b.len());
            out[lo + la + lb - base..lo + len - base].copy_from_slice(&sep);
            stack.push((pa, part_a, lo));
            stack.push((pb, part_b, lo + la));
        }
    }

    /// Bisects the connected part `p` whose BFS from one of its vertices just gave `bounds`
    /// (and `queue`), each side with at least `min_fraction` of it where a level allows:
    /// `(part a, its vertices, part b, its vertices, separator)`, owners updated; `None` for a
    /// (near) clique.
    #[allow(clippy::type_complexity)]
    fn bisect(
        &mut self,
        p: u32,
        mut bounds: Vec<usize>,
        min_fraction: f64,
    ) -> Option<(u32, Vec<usize>, u32, Vec<usize>, Vec<usize>)> {
        let len = self.queue.len();
        let first = self.queue[0];
        // pseudo-peripheral root: repeat BFS from a minimum-degree vertex of the last level;
        // every level structure met is a candidate and the best separator level wins
        let mut ecc = bounds.len() - 2;
        let mut best = (best_level(&bounds, len, min_fraction), first);
        let mut last = (first, bounds.clone());
        for _ in 0..4 {
            let far = &self.queue[bounds[bounds.len() - 2]..];
            let cand = *far.iter().min_by_key(|&&v| self.g.neighbours(v).len()).expect("non-empty level");
            let b2 = self.bfs(cand, p);
            let l2 = best_level(&b2, len, min_fraction);
            if l2.0 < best.0 .0 {
                best = (l2, cand);
            }
            last = (cand, b2.clone());
            if b2.len() - 2 > ecc {
                ecc = b2.len() - 2;
                bounds = b2;
            } else {
                break;
            }
        }
        let bounds = if last.0 == best.1 { last.1 } else { self.bfs(best.1, p) };
        let nlev = bounds.len() - 1;
        if nlev < 3 {
            return None;
        }
        let k = best_level(&bounds, len, min_fraction).1;
        let (pa, pb) = (self.new_part(), self.new_part());
        let order = std::mem::take(&mut self.queue);
        let kl = k as u32;
        let mut part_a = Vec::with_capacity(bounds[k]);
        let mut part_b = Vec::with_capacity(len - bounds[k + 1]);
        let mut sep = Vec::with_capacity(bounds[k + 1] - bounds[k]);
        part_a.extend_from_slice(&order[..bounds[k]]);
        part_b.extend_from_slice(&order[bounds[k + 1]..]);
        // a level vertex with no neighbour beyond the level can join A
        for &v in &order[bounds[k]..bounds[k + 1]] {
            let touches_b = self.g.neighbours(v).iter().any(|&u| self.owner[u] == p && self.level[u] > kl);
            if touches_b {
                sep.push(v);
            } else {
                part_a.push(v);
            }
        }
        self.queue = order;
        for &v in &part_a {
            self.owner[v] = pa;
        }
        for &v in &part_b {
            self.owner[v] = pb;
        }
        for &v in &sep {
            self.owner[v] = PLACED;
        }
        Some((pa, part_a, pb, part_b, sep))
    }
}

/// The inverse of a permutation.
pub fn inverse(perm: &[usize]) -> Vec<usize> {
    let mut inv = vec![0usize; perm.len()];
    for (i, &p) in perm.iter().enumerate() {
        inv[p] = i;
    }
    inv
}
