//! Sparse Cholesky for the rest of the crate (the harmonic fill of `operators`, the
//! interior-point solver of `solve`): fill-reducing orderings computed from the matrix graph
//! alone, and the choice of sequential or parallel factorisation.
//!
//! [`nested_dissection`] bisects the graph recursively by BFS level structures: from a
//! pseudo-peripheral vertex, one BFS level separates the levels before it from those after
//! it, so it is a vertex separator of any graph. Each part is ordered before its separator,
//! small parts by faer's AMD. On planar-like graphs (grids, triangulated meshes) this
//! gives far less fill and fewer flops than minimum degree at large n (about 20 % at a million vertices with
//! the 19-point pattern of a bilaplacian).
//! [`analyse`] orders a pattern with both this ordering and AMD and keeps the cheapest
//! factorisation: AMD, nested dissection, or nested dissection's two halves side by side
//! ([`two_way`]); from [`ND_ONLY_N`] unknowns on it computes AMD only when the two-way split is
//! not possible.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, Par, Side, Spec};

pub mod two_way;

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

/// A nested-dissection ordering of `g`: `perm[new] = old`. Parts of at most `leaf_size`
/// vertices are ordered by AMD.
pub fn nested_dissection(g: &Graph, leaf_size: usize) -> Vec<usize> {
    nested_dissection_split(g, leaf_size).0
}

/// [`nested_dissection`] and, when the whole graph was bisected at the top (it is connected
/// and not a near-clique), the sizes `[a, b]` of the two parts: `perm[..a]` is one part,
/// `perm[a..a + b]` the other, `perm[a + b..]` the separator between them, and no edge joins
/// the two parts. Above [`PARALLEL_DISSECTION_MIN`] vertices the two top parts are dissected
/// side by side (the result is the same as one after the other).
pub fn nested_dissection_split(g: &Graph, leaf_size: usize) -> (Vec<usize>, Option<[usize; 2]>) {
    dissection(g, leaf_size, g.n() >= PARALLEL_DISSECTION_MIN)
}

fn dissection(g: &Graph, leaf_size: usize, parallel: bool) -> (Vec<usize>, Option<[usize; 2]>) {
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
        // the other part on another thread, with its own bookkeeping and part numbers
        let mut d2 = Dissect { owner: d.owner.clone(), ..Dissect::new(g, u32::MAX / 2) };
        std::thread::scope(|scope| {
            let other = scope.spawn(move || d2.run(vec![(pb, part_b, la)], out_b, la, leaf_size));
            d.run(vec![(pa, part_a, 0)], out_a, 0, leaf_size);
            other.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
        });
    } else {
        d.run(vec![(pa, part_a, 0)], out_a, 0, leaf_size);
        d.run(vec![(pb, part_b, la)], out_b, la, leaf_size);
    }
    (out, Some([la, lb]))
}

/// Graphs at least this large are dissected on two threads below the top level (below it the
/// second thread costs more than it saves).
const PARALLEL_DISSECTION_MIN: usize = 100_000;

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

/// Flops of the Cholesky factorisation described by `s` (Σ over columns of count²).
pub fn factor_flops(s: &SymbolicCholesky<usize>) -> f64 {
    match s.raw() {
        SymbolicCholeskyRaw::Simplicial(f) => {
            let cp = f.col_ptr();
            (0..f.ncols()).map(|j| ((cp[j + 1] - cp[j]) as f64).powi(2)).sum()
        }
        SymbolicCholeskyRaw::Supernodal(f) => {
            let (b, e, rp) = (f.supernode_begin(), f.supernode_end(), f.col_ptr_for_row_idx());
            let mut flops = 0.0;
            for s in 0..f.n_supernodes() {
                let below = (rp[s + 1] - rp[s]) as f64;
                for j in b[s]..e[s] {
                    flops += ((e[s] - j) as f64 + below).powi(2);
                }
            }
            flops
        }
    }
}

/// Above this size the factorisation is supernodal: faer's automatic choice kept the
/// simplicial one for bilaplacian patterns of a few thousand unknowns, where supernodal
/// factors are faster (docs/performance.md, "constants").
const SUPERNODAL_MIN_N: usize = 1000;

fn params(n: usize) -> CholeskySymbolicParams<'static> {
    CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: if n >= SUPERNODAL_MIN_N {
            faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL
        } else {
            faer::sparse::linalg::SupernodalThreshold::AUTO
        },
        ..Default::default()
    }
}

/// Graphs below this size are ordered by AMD only.
const ND_MIN_N: usize = 2000;
/// Graphs at least this large are ordered by nested dissection only: there AMD costs seconds
/// and its factors need several times the flops of the two-way one on every pattern measured
/// (docs/performance.md, "constants").
const ND_ONLY_N: usize = 200_000;
/// Parts at most this large are ordered by AMD inside the dissection.
const ND_LEAF: usize = 128;

/// Parallelism for a numeric factorisation: sequential below about 2e10 factor flops (on
/// 2 cores rayon only paid off for the largest factors measured), else faer's global setting.
pub fn parallelism_for(s: &SymbolicCholesky<usize>) -> Par {
    if factor_flops(s) < 2e10 {
        Par::Seq
    } else {
        faer::get_global_parallelism()
    }
}

/// Solves `A x = b` once for a symmetric positive definite `A` given by its upper triangle
/// (`b` is overwritten by `x`), with AMD: for a single factorisation the nested-dissection
/// ordering costs more than it saves. `Err` if `A` is not numerically positive definite.
pub fn solve_spd_once(a: SparseColMatRef<'_, usize, f64>, b: &mut [f64]) -> Result<(), String> {
    let n = a.ncols();
    let s = factorize_symbolic_cholesky(a.symbolic(), Side::Upper, SymmetricOrdering::Amd, Default::default())
        .map_err(|e| format!("symbolic Cholesky: {e:?}"))?;
    let s: &SymbolicCholesky<usize> = &s;
    let par = parallelism_for(s);
    let mut l = vec![0.0f64; s.len_val()];
    let mut mem = MemBuffer::try_new(StackReq::any_of(&[
        s.factorize_numeric_llt_scratch::<f64>(par, Spec::default()),
        s.solve_in_place_scratch::<f64>(1, par),
    ]))
    .map_err(|_| "out of memory for the Cholesky workspace".to_string())?;
    s.factorize_numeric_llt(&mut l, a, Side::Upper, Default::default(), par, MemStack::new(&mut mem), Spec::default())
        .map_err(|e| format!("{e:?}"))?;
    let rhs = faer::MatMut::from_column_major_slice_mut(b, n, 1);
    LltRef::new(s, &l).solve_in_place_with_conj(Conj::No, rhs, par, MemStack::new(&mut mem));
    Ok(())
}

/// The pattern (upper triangle with diagonal) of a matrix given by triplets; for tests and
/// callers that build matrices by hand.
pub fn upper_pattern(n: usize, edges: &[(usize, usize)]) -> SymbolicSparseColMat<usize> {
    let mut cols: Vec<Vec<usize>> = (0..n).map(|j| vec![j]).collect();
    for &(i, j) in edges {
        let (lo, hi) = (i.min(j), i.max(j));
        cols[hi].push(lo);
    }
    let mut cp = vec![0usize];
    let mut ri = Vec::new();
    for c in &mut cols {
        c.sort_unstable();
        c.dedup();
        ri.extend_from_slice(c);
        cp.push(ri.len());
    }
    SymbolicSparseColMat::new_checked(n, n, cp, None, ri)
}

/// How a fixed pattern is factorised: one faer factorisation (AMD or nested dissection,
/// sequential or faer's parallel kernels), or two halves side by side ([`two_way`]).
pub enum Analysis {
    /// One factorisation.
    Single {
        /// faer's analysis.
        symbolic: Box<SymbolicCholesky<usize>>,
        /// Parallelism of its numeric factorisation.
        par: Par,
    },
    /// The two parts of the top-level dissection on two threads.
    TwoWay(Box<two_way::Symbolic>),
}

/// Speed-up of faer's parallel kernels on this machine's two cores, for factors above
/// [`PARALLEL_MIN_FLOPS`] (measured on the largest bench mesh: docs/performance.md).
const PARALLEL_SPEEDUP: f64 = 1.33;
/// Below this many factor flops faer's parallel kernels were slower than sequential ones.
const PARALLEL_MIN_FLOPS: f64 = 2e10;

/// Analyses the upper-triangular pattern `a` of a symmetric positive definite matrix: nested
/// dissection and AMD side by side, then the cheapest of AMD, nested dissection on one
/// factorisation, and nested dissection's two halves on two threads (estimated time: flops on
/// the critical path). From [`ND_ONLY_N`] unknowns on, nested dissection alone. Without
/// `split_allowed` (callers that already run one problem per core) no two-thread plan.
///
/// # Errors
/// A message if faer's analysis fails.
pub fn analyse(a: SymbolicSparseColMatRef<'_, usize>, split_allowed: bool) -> Result<Analysis, String> {
    let n = a.ncols();
    let single = |symbolic: SymbolicCholesky<usize>| {
        let par = parallelism_for(&symbolic);
        Analysis::Single { symbolic: Box::new(symbolic), par }
    };
    let amd = || {
        factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Amd, params(n))
            .map_err(|e| format!("symbolic Cholesky: {e:?}"))
    };
    if n < ND_MIN_N {
        return Ok(single(amd()?));
    }
    let nd = || -> Result<Result<two_way::Symbolic, SymbolicCholesky<usize>>, String> {
        // the dissection's own second thread only where the factorisation may use one
        let g = Graph::from_pattern(a);
        let (perm, top) = dissection(&g, ND_LEAF, split_allowed && n >= PARALLEL_DISSECTION_MIN);
        if let Some(t) = top.filter(|_| split_allowed).and_then(|sizes| two_way::Symbolic::new(a, &perm, sizes)) {
            return Ok(Ok(t));
        }
        let inv = inverse(&perm);
        let p = PermRef::new_checked(&perm, &inv, n);
        factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Custom(p), params(n))
            .map(Err)
            .map_err(|e| format!("symbolic Cholesky: {e:?}"))
    };
    if n >= ND_ONLY_N {
        // AMD is compared only where there is no two-way split (a disconnected pattern, a
        // forbidden split): the measurements above are against the split
        return Ok(match nd()? {
            Ok(two) => Analysis::TwoWay(Box::new(two)),
            Err(nd) => {
                let amd = amd()?;
                single(if factor_flops(&nd) < factor_flops(&amd) { nd } else { amd })
            }
        });
    }
    let (amd, nd) = std::thread::scope(|scope| {
        let other = scope.spawn(amd);
        let nd = nd();
        (other.join().unwrap_or_else(|e| std::panic::resume_unwind(e)), nd)
    });
    let (amd, nd) = (amd?, nd?);
    let time = |s: &SymbolicCholesky<usize>| {
        let f = factor_flops(s);
        if f < PARALLEL_MIN_FLOPS {
            f
        } else {
            f / PARALLEL_SPEEDUP
        }
    };
    Ok(match nd {
        Ok(two) if two.critical_flops() < time(&amd) => Analysis::TwoWay(Box::new(two)),
        Ok(_) => single(amd),
        Err(nd) if factor_flops(&nd) < factor_flops(&amd) => single(nd),
        Err(_) => single(amd),
    })
}

/// The cheaper of AMD and nested dissection for one simplicial factorisation of `a` (never
/// supernodal, whose dense kernels faer provides for native floats only, nor the two-way
/// split): for factorisations in double-double arithmetic.
///
/// # Errors
/// A message if faer's analysis fails.
pub fn analyse_simplicial(a: SymbolicSparseColMatRef<'_, usize>) -> Result<SymbolicCholesky<usize>, String> {
    let n = a.ncols();
    let params = |_| CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: faer::sparse::linalg::SupernodalThreshold::FORCE_SIMPLICIAL,
        ..Default::default()
    };
    let amd = factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Amd, params(n))
        .map_err(|e| format!("symbolic Cholesky: {e:?}"))?;
    if n < ND_MIN_N {
        return Ok(amd);
    }
    let (perm, _) = dissection(&Graph::from_pattern(a), ND_LEAF, false);
    let inv = inverse(&perm);
    let p = PermRef::new_checked(&perm, &inv, n);
    let nd = factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Custom(p), params(n))
        .map_err(|e| format!("symbolic Cholesky: {e:?}"))?;
    Ok(if factor_flops(&nd) < factor_flops(&amd) { nd } else { amd })
}

/// Numeric storage for one [`Analysis`].
enum Numeric {
    Single { l: Vec<f64>, mem: MemBuffer },
    TwoWay(Box<two_way::TwoWay>),
}

impl Numeric {
    fn new(analysis: &Analysis) -> Result<Numeric, String> {
        Ok(match analysis {
            Analysis::Single { symbolic, par } => Numeric::Single {
                l: vec![0.0; symbolic.len_val()],
                mem: MemBuffer::try_new(StackReq::any_of(&[
                    symbolic.factorize_numeric_llt_scratch::<f64>(*par, Spec::default()),
                    symbolic.solve_in_place_scratch::<f64>(1, *par),
                ]))
                .map_err(|_| "out of memory for the Cholesky workspace".to_string())?,
            },
            Analysis::TwoWay(s) => Numeric::TwoWay(Box::new(two_way::TwoWay::new(s)?)),
        })
    }

    /// Writes one value per memory page of the factor's storage, so that the operating system
    /// maps those pages now, beside other work, instead of during the first factorisation (a
    /// million-unknown factor is about a GiB of freshly zeroed pages, whose faults doubled
    /// that factorisation's time).
    fn touch(&mut self) {
        match self {
            Numeric::Single { l, .. } => touch_pages(l),
            Numeric::TwoWay(t) => t.touch(),
        }
    }
}

/// Writes a zero into every 4 KiB page of `v` (through `black_box`, so that it is not
/// optimised away for memory known to be zero).
pub(crate) fn touch_pages(v: &mut [f64]) {
    for i in (0..v.len()).step_by(512) {
        v[i] = std::hint::black_box(0.0);
    }
}

/// A factorisation's numeric storage made in advance, possibly on another thread
/// ([`Workspace::new`]), with its pages already mapped; [`SpdFactor::with_workspace`] uses it.
pub(crate) struct Workspace(Numeric);

impl Workspace {
    /// Storage for factorisations of `analysis`, every page of the factor's values (and of the
    /// two-way blocks) touched; faer's scratch buffers are left to the first factorisation.
    ///
    /// # Errors
    /// A message if it cannot be allocated.
    pub(crate) fn new(analysis: &Analysis) -> Result<Workspace, String> {
        let mut numeric = Numeric::new(analysis)?;
        numeric.touch();
        Ok(Workspace(numeric))
    }
}

/// A Cholesky factorisation of matrices with one analysed pattern: [`SpdFactor::factor`]
/// refactors the values, [`SpdFactor::solve_in_place`] solves with the last factor.
pub struct SpdFactor {
    analysis: std::rc::Rc<Analysis>,
    numeric: Numeric,
}

impl SpdFactor {
    /// Workspace for `analysis`.
    ///
    /// # Errors
    /// A message if the workspace cannot be allocated.
    pub fn new(analysis: std::rc::Rc<Analysis>) -> Result<SpdFactor, String> {
        let numeric = Numeric::new(&analysis)?;
        Ok(SpdFactor { analysis, numeric })
    }

    /// Factorisations of `analysis` in storage made for it by [`Workspace::new`].
    pub(crate) fn with_workspace(analysis: std::rc::Rc<Analysis>, workspace: Workspace) -> SpdFactor {
        SpdFactor { analysis, numeric: workspace.0 }
    }

    /// Factorises `a` (upper triangle, the analysed pattern).
    ///
    /// # Errors
    /// A message if `a` is not numerically positive definite.
    pub fn factor(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), String> {
        match (&*self.analysis, &mut self.numeric) {
            (Analysis::Single { symbolic, par }, Numeric::Single { l, mem }) => symbolic
                .factorize_numeric_llt(l, a, Side::Upper, Default::default(), *par, MemStack::new(mem), Spec::default())
                .map(|_| ())
                .map_err(|e| format!("{e:?}")),
            (Analysis::TwoWay(s), Numeric::TwoWay(t)) => t.factor(s, a.val()),
            _ => unreachable!("numeric storage made for its analysis"),
        }
    }

    /// Overwrites `b` with `A⁻¹ b` for the last factorised `A`.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        match (&*self.analysis, &mut self.numeric) {
            (Analysis::Single { symbolic, par }, Numeric::Single { l, mem }) => {
                let n = b.len();
                let rhs = faer::MatMut::from_column_major_slice_mut(b, n, 1);
                LltRef::new(symbolic, l).solve_in_place_with_conj(Conj::No, rhs, *par, MemStack::new(mem));
            }
            (Analysis::TwoWay(s), Numeric::TwoWay(t)) => t.solve_in_place(s, b),
            _ => unreachable!("numeric storage made for its analysis"),
        }
    }
}

/// [`solve_spd_once`], or with the analysis taken from and kept in `analyses` when given (a
/// pattern solved again and again: the weight functions' fills and gaps).
///
/// # Errors
/// As [`solve_spd_once`].
pub fn solve_spd(
    a: SparseColMatRef<'_, usize, f64>,
    b: &mut [f64],
    analyses: Option<&mut Analyses>,
) -> Result<(), String> {
    match analyses {
        None => solve_spd_once(a, b),
        Some(analyses) => SpdSolver::new(a.symbolic(), analyses)?.solve(a, b),
    }
}

/// The analyses a sequence of factorisations reuses, held by the caller: the last patterns
/// analysed with their analyses (a run's geodesic distance and harmonic fills share the
/// Laplacian's, the weight functions of a thread their normal matrix's), and whether an
/// analysis may plan a factorisation over two threads. Nothing is kept anywhere else.
pub struct Analyses {
    split_allowed: bool,
    /// Most recent last; at most [`Analyses::KEPT`].
    kept: Vec<(SymbolicSparseColMat<usize>, std::rc::Rc<Analysis>)>,
}

impl Default for Analyses {
    fn default() -> Self {
        Analyses::new(true)
    }
}

impl Analyses {
    /// Patterns kept at once (a Laplacian, the energy and a normal matrix).
    const KEPT: usize = 3;

    /// An empty store; `split_allowed`: see [`analyse`].
    pub fn new(split_allowed: bool) -> Self {
        Analyses { split_allowed, kept: Vec::new() }
    }

    /// The analysis of `pattern`: a kept one for the same pattern, else a new one, then kept.
    ///
    /// # Errors
    /// A message if the analysis fails or the pattern cannot be copied.
    pub fn of(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<std::rc::Rc<Analysis>, String> {
        let same = |a: &SymbolicSparseColMat<usize>| {
            a.nrows() == pattern.nrows() && a.col_ptr() == pattern.col_ptr() && a.row_idx() == pattern.row_idx()
        };
        if let Some(at) = self.kept.iter().position(|(q, _)| same(q)) {
            let entry = self.kept.remove(at);
            let analysis = entry.1.clone();
            self.kept.push(entry);
            return Ok(analysis);
        }
        let analysis = std::rc::Rc::new(analyse(pattern, self.split_allowed)?);
        self.keep(pattern.to_owned().map_err(|e| format!("{e:?}"))?, analysis.clone());
        Ok(analysis)
    }

    /// Keeps `analysis` (made elsewhere, e.g. on another thread) as the one of `pattern`.
    pub fn keep(&mut self, pattern: SymbolicSparseColMat<usize>, analysis: std::rc::Rc<Analysis>) {
        if self.kept.len() == Self::KEPT {
            self.kept.remove(0);
        }
        self.kept.push((pattern, analysis));
    }

    /// Drops every kept analysis (a million-vertex Laplacian's is hundreds of MiB).
    pub fn clear(&mut self) {
        self.kept.clear();
    }

    /// Whether analyses made here may plan two-thread factorisations.
    pub fn split_allowed(&self) -> bool {
        self.split_allowed
    }
}

/// A sparse SPD solver for a fixed pattern: the analysis ([`analyse`]) is done once, each
/// [`SpdSolver::solve`] refactors the values and solves (for repeated solves with the same
/// pattern and different values).
pub struct SpdSolver {
    f: SpdFactor,
}

impl SpdSolver {
    /// Analyses the upper-triangular pattern, or takes its analysis from `analyses`.
    ///
    /// # Errors
    /// A message if the analysis or the workspace allocation fails.
    pub fn new(pattern: SymbolicSparseColMatRef<'_, usize>, analyses: &mut Analyses) -> Result<Self, String> {
        let analysis = analyses.of(pattern)?;
        Ok(SpdSolver { f: SpdFactor::new(analysis)? })
    }

    /// Factors `a` (upper triangle, the analysed pattern) and overwrites `b` with `a⁻¹ b`.
    ///
    /// # Errors
    /// A message if `a` is not positive definite.
    pub fn solve(&mut self, a: SparseColMatRef<'_, usize, f64>, b: &mut [f64]) -> Result<(), String> {
        self.f.factor(a)?;
        self.f.solve_in_place(b);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2-ring stencil on an `nx × ny` grid (the pattern of a bilaplacian).
    fn grid_edges(nx: usize, ny: usize, ring2: bool) -> Vec<(usize, usize)> {
        let mut e = Vec::new();
        let id = |x: usize, y: usize| y * nx + x;
        for y in 0..ny {
            for x in 0..nx {
                let offs: &[(isize, isize)] =
                    if ring2 { &[(1, 0), (0, 1), (1, 1), (1, -1), (2, 0), (0, 2)] } else { &[(1, 0), (0, 1)] };
                for &(dx, dy) in offs {
                    let (x2, y2) = (x as isize + dx, y as isize + dy);
                    if x2 >= 0 && y2 >= 0 && (x2 as usize) < nx && (y2 as usize) < ny {
                        e.push((id(x, y), id(x2 as usize, y2 as usize)));
                    }
                }
            }
        }
        e
    }

    /// [`analyse`] restricted to one factorisation (AMD or nested dissection).
    fn single_analysis(a: SymbolicSparseColMatRef<'_, usize>) -> SymbolicCholesky<usize> {
        match analyse(a, false).unwrap() {
            Analysis::Single { symbolic, .. } => *symbolic,
            Analysis::TwoWay(_) => panic!("split forbidden"),
        }
    }

    fn is_permutation(p: &[usize]) -> bool {
        let mut seen = vec![false; p.len()];
        p.iter().all(|&i| i < p.len() && !std::mem::replace(&mut seen[i], true))
    }

    #[test]
    fn dissection_is_a_permutation_including_disconnected_graphs() {
        for (nx, ny, ring2) in [(1, 1, false), (7, 3, true), (40, 30, false), (50, 50, true)] {
            let a = upper_pattern(nx * ny, &grid_edges(nx, ny, ring2));
            let g = Graph::from_pattern(a.as_ref());
            for leaf in [1, 8, 64] {
                assert!(is_permutation(&nested_dissection(&g, leaf)));
            }
        }
        // two grids side by side, plus isolated vertices
        let mut e = grid_edges(20, 20, true);
        e.extend(grid_edges(15, 10, false).into_iter().map(|(i, j)| (i + 400, j + 400)));
        let a = upper_pattern(400 + 150 + 5, &e);
        let g = Graph::from_pattern(a.as_ref());
        assert!(is_permutation(&nested_dissection(&g, 16)));
    }

    #[test]
    fn dissection_on_two_threads_is_the_same_as_on_one() {
        for (nx, ny, ring2) in [(120, 100, true), (90, 70, false)] {
            let a = upper_pattern(nx * ny, &grid_edges(nx, ny, ring2));
            let g = Graph::from_pattern(a.as_ref());
            let (one, top1) = dissection(&g, ND_LEAF, false);
            let (two, top2) = dissection(&g, ND_LEAF, true);
            assert!(is_permutation(&one) && top1.is_some());
            assert_eq!(top1, top2);
            assert!(one == two, "{nx}x{ny}: the orderings differ");
        }
    }

    #[test]
    fn dissection_beats_amd_on_a_grid() {
        let (nx, ny) = (120, 100);
        let a = upper_pattern(nx * ny, &grid_edges(nx, ny, true));
        let perm = nested_dissection(&Graph::from_pattern(a.as_ref()), ND_LEAF);
        let inv = inverse(&perm);
        let p = PermRef::new_checked(&perm, &inv, nx * ny);
        let nd = factorize_symbolic_cholesky(a.as_ref(), Side::Upper, SymmetricOrdering::Custom(p), Default::default())
            .unwrap();
        let amd =
            factorize_symbolic_cholesky(a.as_ref(), Side::Upper, SymmetricOrdering::Amd, Default::default()).unwrap();
        assert!(nd.len_val() < amd.len_val(), "nd {} amd {}", nd.len_val(), amd.len_val());
        assert!(factor_flops(&nd) < factor_flops(&amd));
        let best = single_analysis(a.as_ref());
        assert_eq!(best.len_val(), nd.len_val());
    }

    /// A diagonally dominant SPD matrix on `a`'s pattern with off-diagonal entries of varying
    /// size: values aligned with `a`'s entries.
    fn spd_values(a: SymbolicSparseColMatRef<'_, usize>) -> Vec<f64> {
        let n = a.ncols();
        let (cp, ri) = (a.col_ptr(), a.row_idx());
        let mut deg = vec![0.0; n];
        let off = |i: usize, j: usize| -1.0 - ((i * 7 + j * 3) % 5) as f64 * 0.5;
        for j in 0..n {
            for &i in &ri[cp[j]..cp[j + 1]] {
                if i != j {
                    deg[i] -= off(i, j);
                    deg[j] -= off(i, j);
                }
            }
        }
        (0..n)
            .flat_map(|j| ri[cp[j]..cp[j + 1]].iter().map(move |&i| (i, j)))
            .map(|(i, j)| if i == j { deg[j] + 0.01 } else { off(i, j) })
            .collect()
    }

    /// Largest entry of `b − A x` for `A` given by its upper triangle.
    fn residual(a: SymbolicSparseColMatRef<'_, usize>, vals: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let (cp, ri) = (a.col_ptr(), a.row_idx());
        let mut r = b.to_vec();
        for j in 0..a.ncols() {
            for (p, &i) in ri[cp[j]..cp[j + 1]].iter().enumerate() {
                let v = vals[cp[j] + p];
                r[i] -= v * x[j];
                if i != j {
                    r[j] -= v * x[i];
                }
            }
        }
        r.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn two_way_factorisation_solves_like_one_factorisation() {
        for (nx, ny, ring2) in [(70, 50, true), (90, 40, false), (45, 45, true)] {
            let n = nx * ny;
            let a = upper_pattern(n, &grid_edges(nx, ny, ring2));
            let vals = spd_values(a.as_ref());
            let analysis = analyse(a.as_ref(), true).unwrap();
            let Analysis::TwoWay(t) = &analysis else { panic!("{nx}x{ny}: a grid is split in two") };
            // the separator is a thin cut: one or two grid lines across
            assert!(t.separator_len() <= 3 * nx.max(ny), "separator {}", t.separator_len());
            let mut f = SpdFactor::new(std::rc::Rc::new(analysis)).unwrap();
            f.factor(SparseColMatRef::new(a.as_ref(), &vals)).unwrap();
            for seed in 0..3 {
                let b: Vec<f64> = (0..n).map(|i| ((i * (seed + 3)) as f64 * 0.37).sin()).collect();
                let mut x = b.clone();
                f.solve_in_place(&mut x);
                let r = residual(a.as_ref(), &vals, &x, &b);
                assert!(r < 1e-9, "{nx}x{ny}: residual {r:e}");
            }
            // not positive definite: an error, not a wrong answer
            let mut bad = vals.clone();
            let diag = a.col_ptr()[n / 2 + 1] - 1;
            bad[diag] = -1.0;
            assert!(f.factor(SparseColMatRef::new(a.as_ref(), &bad)).is_err());
        }
    }

    #[test]
    fn a_disconnected_pattern_is_factorised_whole() {
        // two grids side by side: no top separator, so one factorisation; it still solves
        let mut e = grid_edges(50, 40, true);
        e.extend(grid_edges(30, 30, false).into_iter().map(|(i, j)| (i + 2000, j + 2000)));
        let n = 2000 + 900;
        let a = upper_pattern(n, &e);
        let analysis = analyse(a.as_ref(), true).unwrap();
        assert!(matches!(analysis, Analysis::Single { .. }));
        let vals = spd_values(a.as_ref());
        let mut f = SpdFactor::new(std::rc::Rc::new(analysis)).unwrap();
        f.factor(SparseColMatRef::new(a.as_ref(), &vals)).unwrap();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).cos()).collect();
        let mut x = b.clone();
        f.solve_in_place(&mut x);
        assert!(residual(a.as_ref(), &vals, &x, &b) < 1e-9);
    }

    #[test]
    fn two_way_split_is_refused_when_the_parts_touch_or_on_request() {
        let (nx, ny) = (60, 40);
        let n = nx * ny;
        let a = upper_pattern(n, &grid_edges(nx, ny, true));
        // parts = first and second half of the rows, "separator" = the last row: they touch
        let perm: Vec<usize> = (0..n).collect();
        assert!(two_way::Symbolic::new(a.as_ref(), &perm, [n / 2, n / 2 - nx]).is_none());
        assert!(matches!(analyse(a.as_ref(), false).unwrap(), Analysis::Single { .. }));
    }

    #[test]
    fn the_chosen_ordering_factorises_and_solves() {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::sparse::linalg::cholesky::LltRef;
        use faer::sparse::SparseColMatRef;
        let (nx, ny) = (70, 50);
        let n = nx * ny;
        let a = upper_pattern(n, &grid_edges(nx, ny, true));
        // values: off-diagonal −1, diagonal degree + 1 (SPD, diagonally dominant)
        let (cp, ri) = (a.col_ptr(), a.row_idx());
        let mut deg = vec![0.0; n];
        for j in 0..n {
            for &i in &ri[cp[j]..cp[j + 1]] {
                if i != j {
                    deg[i] += 1.0;
                    deg[j] += 1.0;
                }
            }
        }
        let vals: Vec<f64> = (0..n)
            .flat_map(|j| ri[cp[j]..cp[j + 1]].iter().map(move |&i| (i, j)))
            .map(|(i, j)| if i == j { deg[j] + 1.0 } else { -1.0 })
            .collect();
        let s = single_analysis(a.as_ref());
        assert!(s.perm().is_some());
        let par = faer::Par::Seq;
        let mut l = vec![0.0; s.len_val()];
        let mut mem = MemBuffer::new(s.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
        let mat = SparseColMatRef::new(a.as_ref(), &vals);
        s.factorize_numeric_llt(
            &mut l,
            mat,
            Side::Upper,
            Default::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .unwrap();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x = b.clone();
        let mut mem = MemBuffer::new(s.solve_in_place_scratch::<f64>(1, par));
        LltRef::new(&s, &l).solve_in_place_with_conj(
            faer::Conj::No,
            faer::MatMut::from_column_major_slice_mut(&mut x, n, 1),
            par,
            MemStack::new(&mut mem),
        );
        // residual of the symmetric matrix stored by its upper triangle
        let mut r = b.clone();
        for j in 0..n {
            for (p, &i) in ri[cp[j]..cp[j + 1]].iter().enumerate() {
                let v = vals[cp[j] + p];
                r[i] -= v * x[j];
                if i != j {
                    r[j] -= v * x[i];
                }
            }
        }
        assert!(r.iter().all(|v| v.abs() < 1e-10), "residual {:e}", r.iter().fold(0.0f64, |a, v| a.max(v.abs())));
    }
}
