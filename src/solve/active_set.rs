//! An active-set iteration for the monotone QP that never factorises: the route for volumes,
//! where one Cholesky factorisation of the normal matrix costs more than the whole run may
//! (NOTES.md 6; docs/volumes.md, "Speed").
//!
//! The working set `S` holds rows taken as equalities: a pair row joins two variables into
//! one cluster (one value), a bound row fixes its variable's cluster at the bound. With `S`
//! fixed the QP is unconstrained over the cluster values, `min ½ yᵀCᵀPCy + …`, solved by
//! conjugate gradients preconditioned by the clusters' diagonal (one product with P per
//! iteration, nothing factorised). The rows of `S` in a cluster form a spanning tree, and the
//! multipliers follow from stationarity: on the tree each row's is the gradient summed over
//! the subtree it cuts off. Where that gives a negative one, the cluster's multipliers are
//! taken instead as a maximum flow over all its tight rows (a cluster's tight rows form
//! cycles, and a tree's multipliers are one of many): if the flow carries the whole
//! imbalance the multipliers are non-negative and the cluster stays; if not, the cluster
//! splits along the minimum cut, the one split the gradient pulls apart. Violated rows
//! within [`JOIN_SHARE`] of the worst join `S` (merging two clusters, never closing a
//! cycle), and the iteration stops when nothing joins or leaves and the gap bound of
//! [`super::optimality`] — `Σ s⁺z + ½ Σ ρ²/d` with the data term's diagonal `d` — is below
//! the tolerance. Inside a cluster the values step by the margin along the tree's rows; a row
//! that closes a cycle in a cluster may miss its margin by a few ε, which the caller's margin
//! repair restores, and the certificate and the gap of the output as written decide.

use super::flow::Network;
use super::problem::ReducedQp;
use super::settings::QpSettings;
use super::status::{Outcome, SolveStatus};
use crate::error::NumericalError;

/// Outer iterations at most.
const MAX_OUTER: u32 = 200;
/// Conjugate-gradient iterations per solve at most.
const MAX_CG: usize = 5000;
/// A row joins the working set when violated by more than this (unit values; the margin
/// repair closes smaller violations).
const ADD_ABOVE: f64 = 1e-10;
/// The iteration ends as stalled when the same working-set size, violated count and number
/// of changes come back this many times within [`CYCLE_WINDOW`] outer iterations.
const CYCLE_REPEATS: usize = 4;
/// See [`CYCLE_REPEATS`].
const CYCLE_WINDOW: usize = 20;
/// The iteration ends as stalled, not solved, when rows stay violated by more than this
/// many margins with nothing left to change. Smaller ones the margin repair closes, moving
/// vertices by at most the violation, and the pipeline checks the gap of the output as
/// written (the structured solver runs when it misses the fit's target). At 4 margins a
/// tie-heavy 48³ volume stalled on one row between two anchored clusters violated by 5.4
/// margins, its gap 1.7 × 10⁻⁸ of the data term, and was handed over (170 s, 1.8 GiB).
const STUCK_SHARE: f64 = 16.0;
/// Violated rows join the working set when violated by at least this share of the worst
/// violation: the others are mostly relieved by the same solve (joining every violated row
/// merges clusters the next solve splits again: at 48³ 88 outer and 8,696 conjugate-gradient
/// iterations with all of them, 35 and 2,412 with a share of 10⁻²).
const JOIN_SHARE: f64 = 0.03;
/// The first solve stops at this fraction of the data term.
const FIRST_TOLERANCE: f64 = 1e-3;
/// After a change of the working set the next solve stops at this share of the current gap
/// (relative to the data term), between the final tolerance and [`LOOSEST_TOLERANCE`]: at
/// 32³ this halves the conjugate-gradient iterations of a fixed tenth-per-iteration schedule
/// at the same outer count, where 10⁻³ of the gap stalls the iteration.
const GAP_SHARE: f64 = 1e-2;
/// The loosest solve after the first.
const LOOSEST_TOLERANCE: f64 = 1e-4;

/// What the iteration did, beside the point.
pub(super) struct ActiveSetOutcome {
    pub(super) outcome: Outcome,
    /// Conjugate-gradient iterations over all solves.
    pub(super) cg_iterations: usize,
}

/// P (both triangles, exact zeros dropped) in compressed rows.
struct Csr {
    ptr: Vec<usize>,
    col: Vec<u32>,
    val: Vec<f64>,
}

impl Csr {
    fn from_upper(n: usize, p: &[(usize, usize, f64)]) -> Csr {
        let mut count = vec![0usize; n + 1];
        for &(i, j, v) in p {
            if v != 0.0 {
                count[i + 1] += 1;
                if i != j {
                    count[j + 1] += 1;
                }
            }
        }
        for k in 0..n {
            count[k + 1] += count[k];
        }
        let ptr = count.clone();
        let nnz = ptr[n];
        let (mut col, mut val) = (vec![0u32; nnz], vec![0.0; nnz]);
        let mut at = count;
        for &(i, j, v) in p {
            if v != 0.0 {
                col[at[i]] = j as u32;
                val[at[i]] = v;
                at[i] += 1;
                if i != j {
                    col[at[j]] = i as u32;
                    val[at[j]] = v;
                    at[j] += 1;
                }
            }
        }
        Csr { ptr, col, val }
    }

    fn rows_into(&self, start: usize, x: &[f64], y: &mut [f64]) {
        for (k, yi) in y.iter_mut().enumerate() {
            let i = start + k;
            let mut acc = 0.0;
            for p in self.ptr[i]..self.ptr[i + 1] {
                acc += self.val[p] * x[self.col[p] as usize];
            }
            *yi = acc;
        }
    }

    /// `y = P x`, the rows split between the threads the cap allows.
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        let n = y.len();
        if n < 20_000 || crate::parallel::threads() < 2 {
            return self.rows_into(0, x, y);
        }
        // split where the stored entries halve
        let half = self.ptr[n] / 2;
        let mid = self.ptr.partition_point(|&p| p < half).clamp(1, n - 1);
        let (a, b) = y.split_at_mut(mid);
        crate::parallel::join(|| self.rows_into(0, x, a), || self.rows_into(mid, x, b));
    }
}

/// One constraint row of the reduced QP.
#[derive(Clone, Copy)]
enum Row {
    /// `x_i − x_j ≤ b` (b = −ε).
    Pair(usize, usize, f64),
    /// `a x_v ≤ b` with `a = ±1`: as an equality, `x_v = a b`.
    Bound(usize, f64, f64),
}

impl Row {
    /// `aᵀx − b`.
    fn violation(&self, x: &[f64]) -> f64 {
        -self.slack(x)
    }

    /// `b − aᵀx` as written (margin included).
    fn slack(&self, x: &[f64]) -> f64 {
        match *self {
            Row::Pair(i, j, b) => b - (x[i] - x[j]),
            Row::Bound(v, a, b) => b - a * x[v],
        }
    }
}

fn rows_of(r: &ReducedQp) -> std::result::Result<Vec<Row>, NumericalError> {
    let mut rows = Vec::with_capacity(r.m());
    let mut k = 0;
    while k < r.a_row.len() {
        let at = r.a_row[k];
        let two = k + 1 < r.a_row.len() && r.a_row[k + 1] == at;
        if two {
            let (i, j) = (r.a_col[k], r.a_col[k + 1]);
            match (r.a_val[k], r.a_val[k + 1]) {
                (a, b) if a == 1.0 && b == -1.0 => rows.push(Row::Pair(i, j, r.b[at])),
                (a, b) if a == -1.0 && b == 1.0 => rows.push(Row::Pair(j, i, r.b[at])),
                _ => return Err("a row is not a difference of two variables".into()),
            }
            k += 2;
        } else {
            let a = r.a_val[k];
            if a != 1.0 && a != -1.0 {
                return Err("a bound row has a coefficient other than ±1".into());
            }
            rows.push(Row::Bound(r.a_col[k], a, r.b[at]));
            k += 1;
        }
        if rows.len() != at + 1 {
            return Err("the rows are not stored in order".into());
        }
    }
    if rows.len() != r.m() {
        return Err("a row has no entry".into());
    }
    Ok(rows)
}

const NONE: u32 = u32::MAX;

/// The clusters of a working set: a label per variable, its offset from the cluster's value
/// (the tree rows hold as equalities, margin included: `x_j = x_i + ε`), per cluster its
/// anchored value (a bound row in the set) or its index among the unknowns.
struct Clusters {
    label: Vec<u32>,
    offset: Vec<f64>,
    anchor: Vec<Option<f64>>,
    unknown: Vec<u32>,
    n_unknowns: usize,
}

fn find(parent: &mut [u32], mut v: u32) -> u32 {
    while parent[v as usize] != v {
        let p = parent[v as usize];
        parent[v as usize] = parent[p as usize];
        v = p;
    }
    v
}

impl Clusters {
    fn new(n: usize, rows: &[Row], in_set: &[bool]) -> Clusters {
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

    fn expand(&self, y: &[f64], x: &mut [f64]) {
        for ((xv, &c), o) in x.iter_mut().zip(&self.label).zip(&self.offset) {
            *xv = o + match self.anchor[c as usize] {
                Some(a) => a,
                None => y[self.unknown[c as usize] as usize],
            };
        }
    }

    /// `x` with the unknowns' values from `y` and the anchored ones at 0 (for products).
    fn expand_unknowns(&self, y: &[f64], x: &mut [f64]) {
        for (xv, &c) in x.iter_mut().zip(&self.label) {
            let u = self.unknown[c as usize];
            *xv = if u == NONE { 0.0 } else { y[u as usize] };
        }
    }

    fn gather(&self, x: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        for (xv, &c) in x.iter().zip(&self.label) {
            let u = self.unknown[c as usize];
            if u != NONE {
                out[u as usize] += xv;
            }
        }
    }
}

/// The objective's pieces the iteration needs.
struct Objective<'a> {
    p: Csr,
    q: &'a [f64],
    d: &'a [f64],
    q_free: &'a [f64],
}

impl Objective<'_> {
    fn gradient(&self, x: &[f64], g: &mut [f64]) {
        self.p.apply(x, g);
        g.iter_mut().zip(self.q).for_each(|(g, q)| *g += q);
    }

    /// `½ Σ (d x + q_free)² / d`.
    fn data_term(&self, x: &[f64]) -> f64 {
        x.iter()
            .zip(self.d)
            .zip(self.q_free)
            .filter(|((_, &d), _)| d > 0.0)
            .map(|((&x, &d), &q)| (d * x + q).powi(2) / d)
            .sum::<f64>()
            * 0.5
    }
}

/// Conjugate gradients on the cluster values: `x` in and out (its cluster means are the start),
/// until `½ Σ_c r_c² / D_c ≤ tolerance` (r the cluster residual, D the cluster's data
/// diagonal). Returns the iterations.
fn solve_clustered(obj: &Objective<'_>, cl: &Clusters, x: &mut [f64], tolerance: f64) -> usize {
    let n = x.len();
    let nu = cl.n_unknowns;
    if nu == 0 {
        cl.expand(&[], x);
        return 0;
    }
    // start: cluster means; weights D_c; Jacobi diagonal of CᵀPC
    let mut y = vec![0.0; nu];
    let mut size = vec![0.0; nu];
    let mut dsum = vec![0.0; nu];
    for (v, xv) in x.iter().enumerate() {
        let u = cl.unknown[cl.label[v] as usize];
        if u != NONE {
            y[u as usize] += xv - cl.offset[v];
            size[u as usize] += 1.0;
            dsum[u as usize] += obj.d[v];
        }
    }
    y.iter_mut().zip(&size).for_each(|(y, s)| *y /= s);
    let mut diag = vec![0.0; nu];
    for i in 0..n {
        let ci = cl.label[i];
        let u = cl.unknown[ci as usize];
        if u == NONE {
            continue;
        }
        for p in obj.p.ptr[i]..obj.p.ptr[i + 1] {
            if cl.label[obj.p.col[p] as usize] == ci {
                diag[u as usize] += obj.p.val[p];
            }
        }
    }
    let mut xs = vec![0.0; n];
    let mut px = vec![0.0; n];
    // r = −Cᵀ∇φ(C y + anchors)
    cl.expand(&y, x);
    obj.gradient(x, &mut px);
    let mut r = vec![0.0; nu];
    cl.gather(&px, &mut r);
    r.iter_mut().for_each(|v| *v = -*v);
    let measure = |r: &[f64]| 0.5 * r.iter().zip(&dsum).map(|(r, d)| r * r / d.max(f64::MIN_POSITIVE)).sum::<f64>();
    let mut zv: Vec<f64> = r.iter().zip(&diag).map(|(r, d)| r / d).collect();
    let mut dir = zv.clone();
    let mut rz: f64 = r.iter().zip(&zv).map(|(a, b)| a * b).sum();
    let mut hd = vec![0.0; nu];
    let mut it = 0;
    while it < MAX_CG && measure(&r) > tolerance {
        if it % 32 == 31 && crate::progress::cancelled() {
            break;
        }
        cl.expand_unknowns(&dir, &mut xs);
        obj.p.apply(&xs, &mut px);
        cl.gather(&px, &mut hd);
        let dhd: f64 = dir.iter().zip(&hd).map(|(a, b)| a * b).sum();
        if dhd <= 0.0 || !dhd.is_finite() {
            break;
        }
        let alpha = rz / dhd;
        for k in 0..nu {
            y[k] += alpha * dir[k];
            r[k] -= alpha * hd[k];
        }
        zv.iter_mut().zip(&r).zip(&diag).for_each(|((z, r), d)| *z = r / d);
        let rz_new: f64 = r.iter().zip(&zv).map(|(a, b)| a * b).sum();
        let beta = rz_new / rz;
        rz = rz_new;
        dir.iter_mut().zip(&zv).for_each(|(p, z)| *p = z + beta * *p);
        it += 1;
    }
    cl.expand(&y, x);
    it
}

/// The working set's trees as the multipliers walked them: each variable's row to its parent
/// (`usize::MAX` at a root) and its depth.
struct Forest {
    parent_row: Vec<usize>,
    depth: Vec<u32>,
}

impl Forest {
    /// Calls `visit(row, rises)` for each tree row on the path from `i` to `j` (one tree),
    /// `rises` when `x` rises along it in the direction `i → j`.
    fn walk_path(&self, rows: &[Row], mut i: usize, mut j: usize, mut visit: impl FnMut(usize, bool)) {
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

    /// The tree row on the path from `i` to `j` that runs the way `i → j` does, `x` rising
    /// along it, with the smallest multiplier: swapping it for the row `i → j` keeps the
    /// tree's equalities consistent with every row on the cycle.
    fn rising_row_on_path(&self, rows: &[Row], z: &[f64], i: usize, j: usize) -> Option<usize> {
        let mut best: Option<usize> = None;
        self.walk_path(rows, i, j, |k, rises| {
            if rises && best.is_none_or(|b| z[k] < z[b]) {
                best = Some(k);
            }
        });
        best
    }
}

/// The gradient with each unanchored cluster's sum spread back over it in proportion to the
/// data diagonal (the conjugate gradients leave a residual of their tolerance): what the
/// multipliers of a cluster's rows must balance.
fn balanced_gradient(cl: &Clusters, g: &[f64], d: &[f64]) -> Vec<f64> {
    let nc = cl.anchor.len();
    let (mut gsum, mut dsum) = (vec![0.0; nc], vec![0.0; nc]);
    for (v, &c) in cl.label.iter().enumerate() {
        gsum[c as usize] += g[v];
        dsum[c as usize] += d[v];
    }
    cl.label
        .iter()
        .enumerate()
        .map(|(v, &c)| {
            let c = c as usize;
            if cl.anchor[c].is_none() && dsum[c] > 0.0 {
                g[v] - gsum[c] * d[v] / dsum[c]
            } else {
                g[v]
            }
        })
        .collect()
}

/// The multipliers of the working set's rows by stationarity on each tree (zero elsewhere).
fn tree_multipliers(rows: &[Row], in_set: &[bool], cl: &Clusters, balanced: &[f64], z: &mut [f64]) -> Forest {
    let n = balanced.len();
    z.iter_mut().for_each(|v| *v = 0.0);
    // adjacency of the set's pair rows, the anchor row of each anchored cluster
    let mut deg = vec![0usize; n + 1];
    let mut anchor_row = vec![usize::MAX; cl.anchor.len()];
    for (k, row) in rows.iter().enumerate().filter(|(k, _)| in_set[*k]) {
        match *row {
            Row::Pair(i, j, _) => {
                deg[i + 1] += 1;
                deg[j + 1] += 1;
            }
            Row::Bound(v, _, _) => anchor_row[cl.label[v] as usize] = k,
        }
    }
    for v in 0..n {
        deg[v + 1] += deg[v];
    }
    let mut adj = vec![0usize; deg[n]];
    let mut at = deg.clone();
    for (k, row) in rows.iter().enumerate().filter(|(k, _)| in_set[*k]) {
        if let Row::Pair(i, j, _) = *row {
            adj[at[i]] = k;
            at[i] += 1;
            adj[at[j]] = k;
            at[j] += 1;
        }
    }
    let nc = cl.anchor.len();
    let mut acc = balanced.to_vec();
    // breadth-first from each cluster's root (the anchor row's variable when anchored)
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut parent_row = vec![usize::MAX; n];
    let mut depth = vec![0u32; n];
    let mut root_of = vec![usize::MAX; nc];
    for (c, &k) in anchor_row.iter().enumerate() {
        if k != usize::MAX {
            if let Row::Bound(v, _, _) = rows[k] {
                root_of[c] = v;
            }
        }
    }
    for v in 0..n {
        let c = cl.label[v] as usize;
        if root_of[c] == usize::MAX {
            root_of[c] = v;
        }
    }
    for &root in &root_of {
        if root == usize::MAX || seen[root] {
            continue;
        }
        seen[root] = true;
        let start = order.len();
        order.push(root);
        let mut head = start;
        while head < order.len() {
            let v = order[head];
            head += 1;
            for &k in &adj[deg[v]..deg[v + 1]] {
                let Row::Pair(i, j, _) = rows[k] else { continue };
                let w = if i == v { j } else { i };
                if !seen[w] {
                    seen[w] = true;
                    parent_row[w] = k;
                    depth[w] = depth[v] + 1;
                    order.push(w);
                }
            }
        }
    }
    // leaves to roots: a row's multiplier carries its subtree's gradient
    for &v in order.iter().rev() {
        let k = parent_row[v];
        if k == usize::MAX {
            let c = cl.label[v] as usize;
            if anchor_row[c] != usize::MAX {
                if let Row::Bound(_, a, _) = rows[anchor_row[c]] {
                    z[anchor_row[c]] = -a * acc[v];
                }
            }
            continue;
        }
        let Row::Pair(i, j, _) = rows[k] else { unreachable!("tree rows are pairs") };
        // stationarity at v: acc_v + a_kv z_k = 0, a = +1 at i, −1 at j
        let (a_v, parent) = if v == i { (1.0, j) } else { (-1.0, i) };
        z[k] = -a_v * acc[v];
        acc[parent] += acc[v];
    }
    Forest { parent_row, depth }
}

/// A row is tight (an arc of the multipliers' network) within this of its bound.
const TIGHT: f64 = 1e-10;

/// Multipliers for the clusters marked in `marked` as a non-negative flow over all their
/// tight rows, tree rows or not: stationarity `g + Aᵀz = 0` asks each variable to send out
/// `−g` (balanced) along rows `x_i ≤ x_j − ε` from `i` to `j`, an anchor row taking or giving
/// the cluster's sum. Where no such flow exists the minimum cut's source side is a set the
/// objective falls by raising (or its complement, by lowering) with every tight row
/// respected: the tree rows across it leave the set, splitting the cluster once, for good.
/// A tree row's negative multiplier alone says nothing of this when tight rows close cycles,
/// and dropping it there only has the row rejoin (the cycling of 48³ volumes). Returns the
/// rows dropped.
#[allow(clippy::too_many_arguments)]
fn flow_multipliers(
    rows: &[Row],
    in_set: &mut [bool],
    cl: &Clusters,
    balanced: &[f64],
    x: &[f64],
    d: &[f64],
    marked: &[bool],
    significant: f64,
    z: &mut [f64],
) -> usize {
    let n = x.len();
    let nc = cl.anchor.len();
    let mut node = vec![NONE; n];
    let mut count = 2usize; // 0 the source, 1 the sink
    let mut scale = 0.0f64;
    for v in 0..n {
        if marked[cl.label[v] as usize] {
            node[v] = count as u32;
            count += 1;
            scale = scale.max(balanced[v].abs());
        }
    }
    if count == 2 || scale == 0.0 {
        return 0;
    }
    let eps = 1e-14 * scale;
    let mut net = Network::new(count);
    let (source, sink) = (0, 1);
    // per cluster: the sum to send out, the supply arcs, the smallest data diagonal
    let mut sum = vec![0.0; nc];
    let mut dmin = vec![f64::INFINITY; nc];
    let mut supply: Vec<(u32, usize, f64)> = Vec::new();
    for v in 0..n {
        if node[v] == NONE {
            continue;
        }
        let c = cl.label[v] as usize;
        let out = -balanced[v];
        sum[c] += out;
        dmin[c] = dmin[c].min(d[v]);
        if out > 0.0 {
            supply.push((c as u32, net.add_arc(source, node[v] as usize, out), out));
        } else if out < 0.0 {
            net.add_arc(node[v] as usize, sink, -out);
        }
    }
    let mut arcs: Vec<(usize, usize)> = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        match *row {
            Row::Pair(i, j, _) => {
                if node[i] == NONE || cl.label[i] != cl.label[j] || !(in_set[k] || row.slack(x).abs() <= TIGHT) {
                    continue;
                }
                arcs.push((k, net.add_arc(node[i] as usize, node[j] as usize, f64::INFINITY)));
            }
            Row::Bound(v, a, _) if in_set[k] && node[v] != NONE => {
                let c = cl.label[v] as usize;
                let hub = net.add_node();
                if a > 0.0 {
                    // x_v ≤ b: the anchor takes what the cluster sends out
                    arcs.push((k, net.add_arc(node[v] as usize, hub, f64::INFINITY)));
                    supply_or_demand(&mut net, &mut supply, hub, sink, sum[c].max(0.0), None);
                } else {
                    arcs.push((k, net.add_arc(hub, node[v] as usize, f64::INFINITY)));
                    supply_or_demand(&mut net, &mut supply, source, hub, (-sum[c]).max(0.0), Some(c as u32));
                }
            }
            Row::Bound(..) => {}
        }
    }
    net.max_flow(source, sink, eps);
    let mut deficit = vec![0.0; nc];
    for &(c, a, cap) in &supply {
        deficit[c as usize] += cap - net.flow(a);
    }
    let cut: Vec<bool> = (0..nc).map(|c| marked[c] && deficit[c] * deficit[c] / dmin[c] > significant).collect();
    let side = net.reachable(source, eps);
    let mut dropped = 0;
    for &(k, a) in &arcs {
        z[k] = net.flow(a);
        if let Row::Pair(i, j, _) = rows[k] {
            if in_set[k] && cut[cl.label[i] as usize] && side[node[i] as usize] != side[node[j] as usize] {
                in_set[k] = false;
                z[k] = 0.0;
                dropped += 1;
            }
        }
    }
    dropped
}

/// An arc `from → to` of capacity `cap`, recorded as supply of cluster `c` when it leaves the
/// source.
fn supply_or_demand(
    net: &mut Network,
    supply: &mut Vec<(u32, usize, f64)>,
    from: usize,
    to: usize,
    cap: f64,
    c: Option<u32>,
) {
    let a = net.add_arc(from, to, cap);
    if let Some(c) = c {
        supply.push((c, a, cap));
    }
}

/// `Σ max(s, 0) z⁺ + ½ Σ ρ²/d` with `ρ = g + Aᵀz⁺` (all in the reduced units).
fn gap_bound(rows: &[Row], x: &[f64], z: &[f64], g: &[f64], d: &[f64]) -> f64 {
    let mut rho = g.to_vec();
    let mut complementarity = 0.0;
    for (row, &zk) in rows.iter().zip(z) {
        let zk = zk.max(0.0);
        if zk == 0.0 {
            continue;
        }
        complementarity += row.slack(x).max(0.0) * zk;
        match *row {
            Row::Pair(i, j, _) => {
                rho[i] += zk;
                rho[j] -= zk;
            }
            Row::Bound(v, a, _) => rho[v] += a * zk,
        }
    }
    complementarity + 0.5 * rho.iter().zip(d).map(|(r, d)| r * r / d).sum::<f64>()
}

/// Runs the iteration from `hint` (or the data's target); needs a data term at every
/// variable (the gap bound and the conjugate gradients' start).
pub(super) fn solve(
    r: &ReducedQp,
    hint: Option<&[f64]>,
    settings: &QpSettings,
) -> std::result::Result<ActiveSetOutcome, NumericalError> {
    if !r.gap_bound || r.factor.is_some() {
        return Err("the active-set iteration needs the assembled energy with a data term everywhere".into());
    }
    if r.n >= NONE as usize {
        return Err("too many variables for the active-set iteration".into());
    }
    let n = r.n;
    let rows = rows_of(r)?;
    let obj = Objective { p: Csr::from_upper(n, &r.p), q: &r.q, d: &r.d, q_free: &r.q_free };
    let mut x: Vec<f64> = match hint {
        Some(h) => h.to_vec(),
        None => r.q_free.iter().zip(&r.d).map(|(q, d)| -q / d).collect(),
    };
    let mut in_set = vec![false; rows.len()];
    let mut z = vec![0.0; rows.len()];
    let mut g = vec![0.0; n];
    let final_tolerance = 0.1 * settings.gap_tolerance;
    let mut relative = FIRST_TOLERANCE;
    let mut cg_iterations = 0;
    let mut status = SolveStatus::MaxIterations;
    let mut outer = 0;
    let mut history: Vec<(usize, usize, usize)> = Vec::new();
    let margin = rows.iter().map(|r| if let Row::Pair(_, _, b) = *r { -b } else { 0.0 }).fold(0.0, f64::max);
    let stuck_above = (STUCK_SHARE * margin).max(ADD_ABOVE);
    // how often a row joined two anchored clusters (an anchor left for it): twice at most,
    // once per anchor, as the next cut tends to undo it
    let mut tabu = vec![0u8; rows.len()];
    let mut first_gap = None;
    while outer < MAX_OUTER {
        if crate::progress::cancelled() {
            return Err("cancelled".into());
        }
        outer += 1;
        let t0 = std::time::Instant::now();
        let cl = Clusters::new(n, &rows, &in_set);
        let data = obj.data_term(&x).max(f64::MIN_POSITIVE);
        let t1 = std::time::Instant::now();
        cg_iterations += solve_clustered(&obj, &cl, &mut x, relative * data);
        let t2 = std::time::Instant::now();
        obj.gradient(&x, &mut g);
        let balanced = balanced_gradient(&cl, &g, &r.d);
        let forest = tree_multipliers(&rows, &in_set, &cl, &balanced, &mut z);
        let data = obj.data_term(&x).max(f64::MIN_POSITIVE);
        let target = settings.gap_tolerance * data;
        // leave: an anchor whose multiplier is negative (the whole cluster moves off its
        // bound); a cluster with a negative tree multiplier gets its multipliers as a flow
        // over all its tight rows, and splits along the cut where there is none
        let in_count = in_set.iter().filter(|&&s| s).count().max(1);
        let significant = final_tolerance * data / in_count as f64;
        let mut changed = 0usize;
        let mut marked = vec![false; cl.anchor.len()];
        let mut unanchored = vec![false; cl.anchor.len()];
        for (k, row) in rows.iter().enumerate() {
            if in_set[k] && z[k] < 0.0 {
                match *row {
                    Row::Pair(i, j, _) if z[k] * z[k] / r.d[i].min(r.d[j]) > significant => {
                        marked[cl.label[i] as usize] = true;
                    }
                    Row::Bound(v, _, _) if z[k] * z[k] / r.d[v] > significant => {
                        unanchored[cl.label[v] as usize] = true;
                        in_set[k] = false;
                        z[k] = 0.0;
                        changed += 1;
                    }
                    _ => {}
                }
            }
        }
        marked.iter_mut().zip(&unanchored).for_each(|(m, &u)| *m &= !u);
        let t3 = std::time::Instant::now();
        let drops = flow_multipliers(&rows, &mut in_set, &cl, &balanced, &x, &r.d, &marked, significant, &mut z);
        changed += drops;
        let t4 = std::time::Instant::now();
        // join: violated rows, the most violated first, merging distinct clusters only
        let cl = Clusters::new(n, &rows, &in_set);
        let mut violated: Vec<(f64, usize)> = rows
            .iter()
            .enumerate()
            .filter(|(k, _)| !in_set[*k])
            .map(|(k, row)| (row.violation(&x), k))
            .filter(|&(v, _)| v > ADD_ABOVE)
            .collect();
        violated.sort_by(|a, b| b.0.total_cmp(&a.0));
        let worst = violated.first().map_or(0.0, |v| v.0);
        let joining = violated.partition_point(|v| v.0 >= JOIN_SHARE * worst);
        let nc = cl.anchor.len();
        let mut parent: Vec<u32> = (0..nc as u32).collect();
        let mut anchored: Vec<bool> = cl.anchor.iter().map(Option::is_some).collect();
        let mut anchor_row = vec![usize::MAX; nc];
        for (k, row) in rows.iter().enumerate().filter(|(k, _)| in_set[*k]) {
            if let Row::Bound(v, _, _) = *row {
                anchor_row[cl.label[v] as usize] = k;
            }
        }
        // a cluster's anchor changes by one swap per iteration at most, and not beside a swap
        // in its tree; the tree rows that swaps took out this iteration
        let mut swapped = vec![false; nc];
        let mut reanchored = vec![false; nc];
        let mut taken_out = vec![false; rows.len()];
        let mut swaps = 0usize;
        let mut stuck = [0usize; 5];
        // the rows within the share of the worst; when none of those could join, the rows
        // within the share of the worst one that can (rows stuck at the top would otherwise
        // let one row join per iteration)
        let mut beyond: Option<f64> = None;
        for (rank, &(violation, k)) in violated.iter().enumerate() {
            if rank == joining && changed > 0 {
                break;
            }
            if beyond.is_some_and(|v| violation < JOIN_SHARE * v) {
                break;
            }
            let before = changed;
            match rows[k] {
                Row::Pair(i, j, _) if cl.label[i] == cl.label[j] => {
                    // a cycle in one cluster: the row replaces a tree row on its path
                    // several per cluster when their paths share no row a swap took out:
                    // each such path is then the new tree's path too (at 48³ of a quantised
                    // volume, one swap per cluster took 76 iterations for the last 240 rows)
                    let c = cl.label[i] as usize;
                    let mut crosses = reanchored[c];
                    forest.walk_path(&rows, i, j, |row, _| crosses |= taken_out[row]);
                    if crosses {
                        stuck[0] += 1;
                        continue;
                    }
                    if let Some(out) = forest.rising_row_on_path(&rows, &z, i, j) {
                        swapped[c] = true;
                        taken_out[out] = true;
                        in_set[out] = false;
                        in_set[k] = true;
                        swaps += 1;
                        changed += 1;
                    } else {
                        stuck[1] += 1;
                    }
                }
                Row::Pair(i, j, _) => {
                    let (ci, cj) = (cl.label[i], cl.label[j]);
                    let (a, b) = (find(&mut parent, ci), find(&mut parent, cj));
                    if a != b && !(anchored[a as usize] && anchored[b as usize]) {
                        parent[a as usize] = b;
                        anchored[b as usize] |= anchored[a as usize];
                        in_set[k] = true;
                        changed += 1;
                    } else if a != b
                        && tabu[k] < 2
                        && (a, b) == (ci, cj)
                        && !swapped[ci as usize]
                        && !swapped[cj as usize]
                        && anchor_row[ci as usize] != usize::MAX
                        && anchor_row[cj as usize] != usize::MAX
                    {
                        // two clusters on their bounds that the row pulls together: one
                        // leaves its bound, the row joins them; the bound holding its cluster
                        // less leaves first, the other one if the row comes back
                        let (ri, rj) = (anchor_row[ci as usize], anchor_row[cj as usize]);
                        let (weaker, stronger) = if z[ri] <= z[rj] { (ri, rj) } else { (rj, ri) };
                        let out = if tabu[k] == 0 { weaker } else { stronger };
                        in_set[out] = false;
                        z[out] = 0.0;
                        in_set[k] = true;
                        tabu[k] += 1;
                        parent[a as usize] = b;
                        swapped[ci as usize] = true;
                        swapped[cj as usize] = true;
                        reanchored[ci as usize] = true;
                        reanchored[cj as usize] = true;
                        swaps += 1;
                        changed += 2;
                    } else {
                        stuck[if a == b { 2 } else { 3 }] += 1;
                    }
                }
                Row::Bound(v, _, _) => {
                    let c = cl.label[v] as usize;
                    let a = find(&mut parent, cl.label[v]);
                    if !anchored[a as usize] {
                        anchored[a as usize] = true;
                        in_set[k] = true;
                        changed += 1;
                    } else if anchor_row[c] != usize::MAX && !swapped[c] {
                        // a second bound on an anchored cluster, violated (by the offsets
                        // inside the cluster): it anchors the cluster instead
                        swapped[c] = true;
                        reanchored[c] = true;
                        in_set[anchor_row[c]] = false;
                        in_set[k] = true;
                        swaps += 1;
                        changed += 1;
                    } else {
                        stuck[4] += 1;
                    }
                }
            }
            if changed > before && rank >= joining && beyond.is_none() {
                beyond = Some(violation);
            }
        }
        let gap = gap_bound(&rows, &x, &z, &g, &r.d);
        let t5 = std::time::Instant::now();
        crate::progress::update("solve", || {
            format!(
                "active set {outer}: {} rows in, {} violated (worst {worst:.1e}), gap {:.1e} of the data (target {:.0e})",
                in_set.iter().filter(|&&s| s).count(),
                violated.len(),
                gap / data,
                settings.gap_tolerance
            )
        });
        let first = *first_gap.get_or_insert(gap / data);
        crate::progress::fraction("solve", crate::progress::log_fraction(first, gap / data, settings.gap_tolerance));
        if std::env::var_os("TOPOSMOOTH_TRACE_ACTIVE").is_some() {
            eprintln!(
                "active set {outer}: {} rows in, {changed} changed ({swaps} swaps, {drops} cut), {} violated (worst {worst:.1e}, stuck {stuck:?} above {stuck_above:.1e}), gap/data {:.1e}, cg {cg_iterations}; ms clusters {} cg {} multipliers {} flow {} join {}",
                in_set.iter().filter(|&&s| s).count(),
                violated.len(),
                gap / data,
                (t1 - t0).as_millis(),
                (t2 - t1).as_millis(),
                (t3 - t2).as_millis(),
                (t4 - t3).as_millis(),
                (t5 - t4).as_millis()
            );
        }
        // a working set that keeps coming back (a swap undone by the next cut) is a cycle
        let state = (in_set.iter().filter(|&&s| s).count(), violated.len(), changed);
        history.push(state);
        if history.iter().rev().take(CYCLE_WINDOW).filter(|&&h| h == state).count() >= CYCLE_REPEATS {
            status = SolveStatus::Stalled;
            break;
        }
        if changed == 0 {
            // every violated row is stuck where nothing else changed: not a solution
            if worst > stuck_above {
                status = SolveStatus::Stalled;
                break;
            }
            if gap <= target {
                status = SolveStatus::Solved;
                break;
            }
            if relative <= final_tolerance {
                status = SolveStatus::Stalled;
                break;
            }
            relative = final_tolerance;
        } else {
            // the next solve need only be as exact as the current gap deserves
            relative = (GAP_SHARE * gap / data).clamp(final_tolerance, LOOSEST_TOLERANCE);
        }
    }
    let z = z.iter().map(|v| v.max(0.0)).collect();
    Ok(ActiveSetOutcome { outcome: Outcome { x, z, y: None, status, iterations: outer }, cg_iterations })
}
