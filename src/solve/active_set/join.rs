//! The join step of an outer iteration: violated rows enter the working set, the most
//! violated first and those within [`JOIN_SHARE`] of the worst ([`SETTLED_JOIN_SHARE`] once
//! the working set has settled: [`share_after`]), merging distinct clusters (never closing a
//! cycle among them), swapping out a tree row where a row closes a cycle inside one cluster,
//! or a bound where two anchored clusters are pulled together.

use super::clusters::{find, Forest, Labels};
use super::rows::{Row, RowKind};

/// A row joins the working set when violated by more than this (unit values; the margin
/// repair closes smaller violations).
pub(super) const ADD_ABOVE: f64 = 1e-10;
/// Violated rows join the working set when violated by at least this share of the worst
/// violation: the others are mostly relieved by the same solve (joining every violated row
/// merges clusters the next solve splits again: at 48³ 88 outer and 8,696 conjugate-gradient
/// iterations with all of them, 35 and 2,412 with a share of 10⁻²).
pub(super) const JOIN_SHARE: f64 = 0.03;
/// Once an outer iteration changes fewer rows than this share of the variables, the working
/// set has settled, and the next join takes the rows violated by at least
/// [`SETTLED_JOIN_SHARE`] of the worst: most of the late outer iterations had changed a few
/// hundred rows each while thousands stayed violated below 3 % of the worst (the 128³ bench:
/// 72 outer iterations, 40 of them changing fewer than 1,000 rows, each a pass over all
/// 2.1 million variables). With it: 36; the tie-heavy 64³ volume 112 → 61, the masked fMRI
/// frame 91 → 53 (docs/performance.md §3). Joining every violated row there (a share of 0)
/// left the fMRI frame stuck on four rows between anchored clusters and handed over. Not
/// settled either: an outer iteration whose join left more violated rows waiting inside
/// clusters it merged than it changed rows (the tie-heavy 96³ volume, whose joins and cuts
/// alternate on one large tied cluster: 374 → 391 outer iterations without this condition,
/// 321 with it).
pub(super) const SETTLED_CHANGES: f64 = 1e-2;
/// The join share once the working set has settled ([`SETTLED_CHANGES`]).
pub(super) const SETTLED_JOIN_SHARE: f64 = 3e-4;

/// The join share after the outer iteration whose join was `last` ([`JOIN_SHARE`] before the
/// first), for `n` variables.
pub(super) fn share_after(last: Option<&Joined>, n: usize) -> f64 {
    match last {
        Some(j) if (j.changed as f64) < SETTLED_CHANGES * n as f64 && j.waited_inside() <= j.changed => {
            SETTLED_JOIN_SHARE
        }
        _ => JOIN_SHARE,
    }
}

/// What the join step did.
pub(super) struct Joined {
    /// Working-set changes this iteration, those before the join step included.
    pub(super) changed: usize,
    /// Swaps: a row in, a tree row or a bound out.
    pub(super) swaps: usize,
    /// Violated rows that could not join, by reason: a cycle row whose path crosses a row
    /// another swap took out, a cycle row with no rising tree row on its path, a row inside a
    /// cluster merged this iteration, a row between two anchored clusters, a bound on an
    /// anchored cluster.
    pub(super) stuck: [usize; 5],
    /// The largest violation (0 when none).
    pub(super) worst: f64,
    /// Rows violated by more than [`ADD_ABOVE`].
    pub(super) violated: usize,
}

impl Joined {
    /// Violated rows left waiting inside a cluster merged this iteration.
    pub(super) fn waited_inside(&self) -> usize {
        self.stuck[2]
    }
}

/// The join step on the working set `in_set` (multipliers `z`, the trees `forest` walked) at
/// the point `x`; `changed` counts the changes made before it this iteration, `tabu` how
/// often each row joined two anchored clusters, and `share` is the join share of the worst
/// violation.
pub(super) fn join(
    rows: &[Row],
    in_set: &mut [bool],
    z: &mut [f64],
    x: &[f64],
    forest: &Forest,
    tabu: &mut [u8],
    (mut changed, share): (usize, f64),
) -> Joined {
    let n = x.len();
    // the clusters after the cuts: labels are union-find roots, so the tables below run
    // over variables
    // the labels on one thread, the violated rows (in row order, then by violation, a stable
    // sort) on the other: the same on any number of threads
    let (cl, violated) = crate::parallel::join(
        || Labels::new(n, rows, in_set),
        || {
            let mut violated = violated_rows(rows, in_set, x);
            violated.sort_by(|a, b| b.0.total_cmp(&a.0));
            violated
        },
    );
    let worst = violated.first().map_or(0.0, |v| v.0);
    let joining = violated.partition_point(|v| v.0 >= share * worst);
    let nc = n;
    let mut parent: Vec<u32> = (0..nc as u32).collect();
    let anchor_row = cl.anchor_row;
    let mut anchored: Vec<bool> = anchor_row.iter().map(|&k| k != usize::MAX).collect();
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
        if beyond.is_some_and(|v| violation < share * v) {
            break;
        }
        let before = changed;
        match rows[k].kind() {
            RowKind::Pair(i, j, _) if cl.label[i] == cl.label[j] => {
                // a cycle in one cluster: the row replaces a tree row on its path
                // several per cluster when their paths share no row a swap took out:
                // each such path is then the new tree's path too (at 48³ of a quantised
                // volume, one swap per cluster took 76 iterations for the last 240 rows)
                // the tree row that goes out: the one on the path that runs the way i → j does,
                // x rising along it, with the smallest multiplier (swapping it for the row
                // keeps the tree's equalities consistent with every row on the cycle)
                let c = cl.label[i] as usize;
                let mut crosses = reanchored[c];
                let mut rising: Option<usize> = None;
                forest.walk_path(i, j, |row, rises| {
                    crosses |= taken_out[row];
                    if rises && rising.is_none_or(|b| z[row] < z[b]) {
                        rising = Some(row);
                    }
                });
                if crosses {
                    stuck[0] += 1;
                    continue;
                }
                if let Some(out) = rising {
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
            RowKind::Pair(i, j, _) => {
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
            RowKind::Bound(v, _, _) => {
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
    Joined { changed, swaps, stuck, worst, violated: violated.len() }
}

/// The rows outside `in_set` violated by more than [`ADD_ABOVE`] at `x`, as (violation, row)
/// in row order; made on contiguous pieces of the rows one a thread and put together in order.
fn violated_rows(rows: &[Row], in_set: &[bool], x: &[f64]) -> Vec<(f64, usize)> {
    let mut pieces: Vec<(usize, Vec<(f64, usize)>)> =
        (0..rows.len().div_ceil(ROWS_PIECE)).map(|p| (p * ROWS_PIECE, Vec::new())).collect();
    crate::parallel::for_each_mut(&mut pieces, 1, |(first, out)| {
        let end = (*first + ROWS_PIECE).min(rows.len());
        out.extend(
            (*first..end).filter(|&k| !in_set[k]).map(|k| (rows[k].violation(x), k)).filter(|&(v, _)| v > ADD_ABOVE),
        );
    });
    let mut all = Vec::with_capacity(pieces.iter().map(|p| p.1.len()).sum());
    pieces.into_iter().for_each(|(_, p)| all.extend(p));
    all
}

/// Rows per piece of [`violated_rows`].
const ROWS_PIECE: usize = 1 << 18;
