//! The working set's multipliers: by stationarity on each cluster's tree, as a maximum flow
//! over a cluster's tight rows where a tree multiplier is negative (splitting the cluster
//! along the minimum cut where no flow carries its imbalance), and the gap bound they give.

use super::super::flow::Network;
use super::clusters::{Clusters, Forest, NONE};
use super::rows::{Row, RowKind};

/// The gradient with each unanchored cluster's sum spread back over it in proportion to the
/// data diagonal (the conjugate gradients leave a residual of their tolerance): what the
/// multipliers of a cluster's rows must balance.
pub(super) fn balanced_gradient(cl: &Clusters, g: &[f64], d: &[f64]) -> Vec<f64> {
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

/// The multipliers of the working set's rows by stationarity on each cluster's tree (zero
/// elsewhere), leaves to roots: a row's multiplier carries its subtree's gradient.
pub(super) fn tree_multipliers(rows: &[Row], cl: &Clusters, balanced: &[f64], z: &mut [f64]) {
    z.iter_mut().for_each(|v| *v = 0.0);
    let mut acc = balanced.to_vec();
    let Forest { up, order, .. } = &cl.forest;
    for &v in order.iter().rev() {
        let up = up[v];
        let Some(k) = up.row() else {
            let anchor = cl.anchor_row[cl.label[v] as usize];
            if let Some(RowKind::Bound(_, a, _)) = rows.get(anchor).map(|r| r.kind()) {
                z[anchor] = -a * acc[v];
            }
            continue;
        };
        // stationarity at v: acc_v + a_kv z_k = 0, a = +1 at i, −1 at j of Pair(i, j, _)
        let a_v = if up.is_first() { 1.0 } else { -1.0 };
        z[k] = -a_v * acc[v];
        acc[up.parent()] += acc[v];
    }
}

/// A row is tight (an arc of the multipliers' network) within this of its bound; a violated
/// row inside a cluster is an arc too.
const TIGHT: f64 = 1e-10;

/// Multipliers for the clusters marked in `marked` as a non-negative flow over all their
/// tight rows, tree rows or not, and the rows the cluster's offsets violate (a row closing a
/// cycle may miss its margin by a few ε): stationarity `g + Aᵀz = 0` asks each variable to
/// send out `−g` (balanced) along rows `x_i ≤ x_j − ε` from `i` to `j`, an anchor row taking
/// or giving the cluster's sum. Where no such flow exists the minimum cut's source side is a set the
/// objective falls by raising (or its complement, by lowering) with every tight row
/// respected: the tree rows across it leave the set, splitting the cluster once, for good.
/// A tree row's negative multiplier alone says nothing of this when tight rows close cycles,
/// and dropping it there only has the row rejoin (the cycling of 48³ volumes); a cut across
/// a violated row has it rejoin as well, so the cut respects those too (a violated row's
/// multiplier adds nothing to the gap bound's complementarity: the tie-heavy 64³ volume's
/// outer iterations 160 → 112). Returns the rows dropped.
#[allow(clippy::too_many_arguments)]
pub(super) fn flow_multipliers(
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
    let nc = cl.anchor.len();
    // the marked clusters with their sizes, and the residual threshold from all of them
    let mut size = vec![0u32; nc];
    let mut scale = 0.0f64;
    for (v, &c) in cl.label.iter().enumerate() {
        if marked[c as usize] {
            size[c as usize] += 1;
            scale = scale.max(balanced[v].abs());
        }
    }
    let clusters: Vec<u32> = (0..nc as u32).filter(|&c| size[c as usize] > 0).collect();
    if clusters.is_empty() || scale == 0.0 {
        return 0;
    }
    let network = Flows { rows, in_set, cl, balanced, x, d, significant, eps: 1e-14 * scale };
    let mut dropped = 0;
    for group in network.in_groups(clusters, &size) {
        for (k, flow) in group.z {
            z[k] = flow;
        }
        for k in group.dropped {
            in_set[k] = false;
            z[k] = 0.0;
            dropped += 1;
        }
    }
    dropped
}

/// Marked variables from which [`Flows::in_groups`] splits the clusters between two threads
/// (each network scans every row once more, a few milliseconds at 128³ against flows of
/// 0.1–1 s an outer iteration).
const FLOW_SPLIT_FROM: usize = 1 << 11;

/// What [`flow_multipliers`] reads, for the flows of any group of its clusters.
struct Flows<'a> {
    rows: &'a [Row],
    in_set: &'a [bool],
    cl: &'a Clusters,
    balanced: &'a [f64],
    x: &'a [f64],
    d: &'a [f64],
    significant: f64,
    /// Residuals at or below it are taken as none.
    eps: f64,
}

/// The flows of one group of clusters: each row arc's flow, and the rows the minimum cuts drop.
struct GroupFlow {
    z: Vec<(usize, f64)>,
    dropped: Vec<usize>,
}

impl Flows<'_> {
    /// The flows of `clusters` (ascending), on as many threads as the cap allows: the clusters
    /// are shared out by size between two networks, each half again while threads remain.
    /// Each cluster is its own component of whatever network holds it, with its arcs in the
    /// same order, so its flow, and the multipliers, are the same bits on every thread count.
    fn in_groups(&self, clusters: Vec<u32>, size: &[u32]) -> Vec<GroupFlow> {
        let nodes: usize = clusters.iter().map(|&c| size[c as usize] as usize).sum();
        if crate::parallel::threads() < 2 || clusters.len() < 2 || nodes < FLOW_SPLIT_FROM {
            return vec![self.group(&clusters)];
        }
        // the largest first, each to the lighter side (ties by cluster number)
        let mut by_size = clusters;
        by_size.sort_by_key(|&c| (std::cmp::Reverse(size[c as usize]), c));
        let (mut a, mut b) = ((Vec::new(), 0usize), (Vec::new(), 0usize));
        for c in by_size {
            let side = if a.1 <= b.1 { &mut a } else { &mut b };
            side.0.push(c);
            side.1 += size[c as usize] as usize;
        }
        a.0.sort_unstable();
        b.0.sort_unstable();
        let (mut first, second) = crate::parallel::join(|| self.in_groups(a.0, size), || self.in_groups(b.0, size));
        first.extend(second);
        first
    }

    /// The flows of `clusters` (ascending) on one network.
    fn group(&self, clusters: &[u32]) -> GroupFlow {
        let Flows { rows, in_set, cl, balanced, x, d, significant, eps } = *self;
        let (n, nc) = (x.len(), cl.anchor.len());
        // per cluster its place in the group (NONE outside it), so that what is kept per
        // cluster is the group's size, not the problem's
        let mut local = vec![NONE; nc];
        for (l, &c) in clusters.iter().enumerate() {
            local[c as usize] = l as u32;
        }
        // per cluster its own source and sink (a network per cluster: each flow's phases
        // search that cluster only), then a node per variable
        let mut terminals = vec![(NONE, NONE); clusters.len()];
        let mut node = vec![NONE; n];
        let mut count = 0usize;
        for v in 0..n {
            let c = local[cl.label[v] as usize] as usize;
            if c != NONE as usize {
                if terminals[c].0 == NONE {
                    terminals[c] = (count as u32, count as u32 + 1);
                    count += 2;
                }
                node[v] = count as u32;
                count += 1;
            }
        }
        let mut net = Network::new(count);
        // per cluster: the sum to send out, the supply arcs, the smallest data diagonal
        let mut sum = vec![0.0; clusters.len()];
        let mut dmin = vec![f64::INFINITY; clusters.len()];
        let mut supply: Vec<(u32, usize, f64)> = Vec::new();
        for v in 0..n {
            if node[v] == NONE {
                continue;
            }
            let c = local[cl.label[v] as usize] as usize;
            let (source, sink) = (terminals[c].0 as usize, terminals[c].1 as usize);
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
            match row.kind() {
                RowKind::Pair(i, j, _) => {
                    if node[i] == NONE || cl.label[i] != cl.label[j] || !(in_set[k] || row.slack(x) <= TIGHT) {
                        continue;
                    }
                    arcs.push((k, net.add_arc(node[i] as usize, node[j] as usize, f64::INFINITY)));
                }
                RowKind::Bound(v, a, _) if in_set[k] && node[v] != NONE => {
                    let c = local[cl.label[v] as usize] as usize;
                    let (source, sink) = (terminals[c].0 as usize, terminals[c].1 as usize);
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
                RowKind::Bound(..) => {}
            }
        }
        let mut side = vec![false; net.nodes()];
        for &(source, sink) in &terminals {
            net.max_flow(source as usize, sink as usize, eps);
            net.mark_reachable(source as usize, eps, &mut side);
        }
        let mut deficit = vec![0.0; clusters.len()];
        for &(c, a, cap) in &supply {
            deficit[c as usize] += cap - net.flow(a);
        }
        let cut = |c: usize| deficit[c] * deficit[c] / dmin[c] > significant;
        let mut out = GroupFlow { z: Vec::with_capacity(arcs.len()), dropped: Vec::new() };
        for &(k, a) in &arcs {
            if let RowKind::Pair(i, j, _) = rows[k].kind() {
                if in_set[k]
                    && cut(local[cl.label[i] as usize] as usize)
                    && side[node[i] as usize] != side[node[j] as usize]
                {
                    out.dropped.push(k);
                    continue;
                }
            }
            out.z.push((k, net.flow(a)));
        }
        out
    }
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
pub(super) fn gap_bound(rows: &[Row], x: &[f64], z: &[f64], g: &[f64], d: &[f64]) -> f64 {
    let mut rho = g.to_vec();
    let mut complementarity = 0.0;
    for (row, &zk) in rows.iter().zip(z) {
        let zk = zk.max(0.0);
        if zk == 0.0 {
            continue;
        }
        complementarity += row.slack(x).max(0.0) * zk;
        match row.kind() {
            RowKind::Pair(i, j, _) => {
                rho[i] += zk;
                rho[j] -= zk;
            }
            RowKind::Bound(v, a, _) => rho[v] += a * zk,
        }
    }
    complementarity + 0.5 * rho.iter().zip(d).map(|(r, d)| r * r / d).sum::<f64>()
}
