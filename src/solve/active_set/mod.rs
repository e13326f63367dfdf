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
//! taken instead as a maximum flow over all its tight or violated rows (a cluster's tight
//! rows form cycles, and a tree's multipliers are one of many): if the flow carries the whole
//! imbalance the multipliers are non-negative and the cluster stays; if not, the cluster
//! splits along the minimum cut, the one split the gradient pulls apart. Violated rows
//! within [`join::JOIN_SHARE`] of the worst (a smaller share once few rows change) join `S`
//! (merging two clusters, never closing a cycle), and the iteration stops when nothing joins
//! or leaves and the gap bound of [`super::optimality`] — `Σ s⁺z + ½ Σ ρ²/d` with the data term's diagonal `d` — is below
//! the tolerance. Inside a cluster the values step by the margin along the tree's rows; a row
//! that closes a cycle in a cluster may miss its margin by a few ε, which the caller's margin
//! repair restores, and the certificate and the gap of the output as written decide.

mod clusters;
mod join;
mod multipliers;
mod objective;
mod operator;
mod rows;

use super::problem::{MonotoneQp, ReducedQp};
use super::settings::QpSettings;
use super::status::{Outcome, SolveStatus};
use crate::error::NumericalError;
use clusters::{Clusters, NONE};
use join::{join, share_after, Joined, ADD_ABOVE};
use multipliers::{balanced_gradient, flow_multipliers, gap_bound, tree_multipliers};
use objective::{solve_clustered, Objective, MULTIGRID_AFTER, MULTIGRID_SOON};
use operator::{RowClasses, TwoPass};
use rows::{rows_of, Row, RowKind};

/// Outer iterations at most. The tie-heavy 96³ volume (`bench --single 96x96x96q`) needed 407
/// (2026-12-05: at 200 it still had 86,747 rows violated, and the interior-point route it
/// would hand over to does not fit, 32.8 GiB predicted) and 445 later, until its plateaus
/// were made strict in the flood's order (2026-12-07): 106.
const MAX_OUTER: u32 = 500;
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
/// The first solve stops at this fraction of the data term.
const FIRST_TOLERANCE: f64 = 1e-3;
/// After a change of the working set the next solve stops at this share of the current gap
/// (relative to the data term), between the final tolerance and [`LOOSEST_TOLERANCE`]: at
/// 32³ this halves the conjugate-gradient iterations of a fixed tenth-per-iteration schedule
/// at the same outer count, where 10⁻³ of the gap stalls the iteration.
const GAP_SHARE: f64 = 1e-2;
/// The loosest solve after the first, relative to the data term. Looser ones were measured
/// (2026-12-06, docs/performance.md §3): 10⁻² cuts the conjugate-gradient iterations at 128³
/// from 2,578 to 1,596 (77.9–80.7 → 61.1–64.0 s), but the tie-heavy 96³ volume then ends at
/// the outer limit (a hand-over predicted past the memory, exit 3); 10⁻² for the first 15
/// outer iterations only takes the tie-heavy 64³ from 61 to 101 outer iterations; 10⁻³ takes
/// it to 108 and has the tie-heavy 72³ handed over.
const LOOSEST_TOLERANCE: f64 = 1e-4;

/// What the iteration did, beside the point.
pub(super) struct ActiveSetOutcome {
    pub(super) outcome: Outcome,
    /// Conjugate-gradient iterations over all solves.
    pub(super) cg_iterations: usize,
}

/// Bytes the iteration's operands take, at most, before they are made, for `n` variables, `m`
/// rows and `p_entries` stored entries of P's upper triangle: the rows (16 bytes each, made one
/// at a time from the problem's rows), the row classes' tables (12 bytes an entry of both
/// triangles when no row repeats, as on a mesh; a grid's few hundred classes take next to
/// nothing) and per variable its class, slot and cursor; with the product in two
/// passes over a stiffness of `(vertices, entries)` ([`TwoPass`]), per vertex its intermediate
/// value and inner class (12), per variable its outer class and the three test vectors of its
/// check (28), and both passes' tables (12 bytes an entry each when no row
/// repeats). P's made columns ([`super::Quadratic::Columns`], `made` with the threads that
/// make them) add each thread's workspace (12 bytes a vertex) and its block of rows (at most
/// 16 bytes an entry of a block's share of both triangles).
#[must_use]
pub(crate) fn operand_bytes(
    n: usize,
    m: usize,
    p_entries: usize,
    two_pass: Option<(usize, usize)>,
    made: Option<usize>,
) -> u64 {
    let (n, m, p) = (n as u64, m as u64, p_entries as u64);
    let two_pass = two_pass.map_or(0, |(v, k)| 12 * v as u64 + 28 * n + 24 * k as u64);
    let made = made
        .map_or(0, |threads| threads as u64 * (12 * n + 16 * (2 * p).min(40 * crate::operators::COLUMN_BLOCK as u64)));
    16 * m + 12 * (2 * p) + 20 * (n + 1) + two_pass + made
}

/// Bytes the iteration allocates beside its operands, at most, for `n` variables and `m` rows,
/// phase by phase (clusters, trees and unknowns never outnumber the variables; the set's pair
/// rows form a forest, so fewer than the variables): throughout, the point, the gradient, the
/// rows' flags and multipliers (16 a variable, 10 a row) and the clusters with their trees (60
/// a variable); the conjugate gradients' vectors, unknown map and each unknown's variables
/// (100); the flow network when every cluster is marked and every row is an arc (nodes,
/// terminals, supplies, cut sides: 198 a variable, and 12 more where the clusters are shared
/// out between two networks: a node and a cluster map per network, the clusters' sizes; arcs
/// with their reverses, doubled by the vectors' growth, the arc list and the flows handed
/// back: 112 a row); the join's labels, tables and violated list (27 a variable, 33 a row);
/// the clusters' construction (41). The flow's phase is the largest: 16 + 60 + 8 + 210 per
/// variable, 10 + 112 per row, rounded up.
#[must_use]
pub(crate) fn iteration_bytes(n: usize, m: usize) -> u64 {
    let (n, m) = (n as u64, m as u64);
    300 * n + 125 * m
}

/// P and the constraint rows in the iteration's own forms ([`RowClasses`], [`Row`]).
pub(super) struct Operands {
    p: RowClasses,
    two_pass: Option<TwoPass>,
    rows: Vec<Row>,
}

impl Operands {
    /// Made from the problem itself for its reduced QP `r` (reduced over `free`, made without
    /// triplets: `problem::reduce_with`): P's row classes from P's columns, the rows from the
    /// constraint rows, as the reduced QP's triplets and rows would give them. Needs the
    /// assembled energy with a data term at every variable (the gap bound and the conjugate
    /// gradients' start).
    pub(super) fn new(
        qp: &MonotoneQp<'_>,
        free: &[usize],
        r: &ReducedQp,
    ) -> std::result::Result<Operands, NumericalError> {
        if !r.gap_bound || r.factor.is_some() {
            return Err("the active-set iteration needs the assembled energy with a data term everywhere".into());
        }
        if r.n >= NONE as usize {
            return Err("too many variables for the active-set iteration".into());
        }
        let mut slot = vec![usize::MAX; qp.q.len()];
        for (k, &v) in free.iter().enumerate() {
            slot[v] = k;
        }
        let rows = rows_of(qp, &slot);
        let p = RowClasses::from_columns(qp.p, free, &slot, r.scale)?;
        let two_pass = qp.second_order.and_then(|e| two_pass(&e, r, &p, free, &slot));
        Ok(Operands { p, two_pass, rows })
    }
}

/// P's product in two passes over the stiffness ([`TwoPass`]) for the energy `e`, if it agrees
/// with P's rows on a test vector to `TWO_PASS_AGREEMENT` of the products' size (else `None`:
/// P's own rows multiply).
fn two_pass(
    e: &super::problem::SecondOrder<'_>,
    r: &ReducedQp,
    p: &RowClasses,
    free: &[usize],
    slot: &[usize],
) -> Option<TwoPass> {
    let t = TwoPass::new(e.k, e.row_scale, r.scale, free, slot).ok()?;
    // a fixed pseudo-random test vector (xorshift)
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let x: Vec<f64> = (0..free.len())
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
    p.apply(&x, &mut a);
    t.apply(&x, &r.d, &mut b);
    let size = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let off = a.iter().zip(&b).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    (off <= TWO_PASS_AGREEMENT * size).then_some(t)
}

/// How closely [`TwoPass`]'s product must agree with P's rows (relative to the largest entry
/// of the product) to replace them: rounding only.
const TWO_PASS_AGREEMENT: f64 = 1e-12;

/// Runs the iteration from `hint` (or the data's target) on the reduced QP `r` whose P and
/// rows `operands` hold.
pub(super) fn solve(
    r: &ReducedQp,
    operands: Operands,
    hint: Option<&[f64]>,
    settings: &QpSettings,
) -> std::result::Result<ActiveSetOutcome, NumericalError> {
    let n = r.n;
    let Operands { p, two_pass, rows } = operands;
    if std::env::var_os("TOPOSMOOTH_TRACE_ACTIVE").is_some() {
        let product = if two_pass.is_some() { "two passes over K" } else { "P's rows" };
        eprintln!(
            "active set: {n} variables, {} rows, P in {} row classes, product by {product}",
            rows.len(),
            p.classes()
        );
    }
    let budget = Some(crate::memory::Budget::of(settings.memory_limit));
    let obj = Objective { p, two_pass, budget, q: &r.q, d: &r.d, q_free: &r.q_free };
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
    let margin = rows.iter().map(|r| if let RowKind::Pair(_, _, b) = r.kind() { -b } else { 0.0 }).fold(0.0, f64::max);
    let stuck_above = (STUCK_SHARE * margin).max(ADD_ABOVE);
    // how often a row joined two anchored clusters (an anchor left for it): twice at most,
    // once per anchor, as the next cut tends to undo it
    let mut tabu = vec![0u8; rows.len()];
    let mut first_gap = None;
    let mut last_join: Option<Joined> = None;
    let mut multigrid_after = MULTIGRID_AFTER;
    while outer < MAX_OUTER {
        if crate::progress::cancelled() {
            return Err("cancelled".into());
        }
        outer += 1;
        let t0 = std::time::Instant::now();
        let cl = Clusters::new(n, &rows, &in_set);
        let data = obj.data_term(&x).max(f64::MIN_POSITIVE);
        let t1 = std::time::Instant::now();
        let (iterations, multigrid) = solve_clustered(&obj, &cl, &mut x, relative * data, multigrid_after);
        cg_iterations += iterations;
        multigrid_after = if multigrid { MULTIGRID_SOON } else { MULTIGRID_AFTER };
        let t2 = std::time::Instant::now();
        obj.gradient(&x, &mut g);
        let balanced = balanced_gradient(&cl, &g, &r.d);
        tree_multipliers(&rows, &cl, &balanced, &mut z);
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
                match row.kind() {
                    RowKind::Pair(i, j, _) if z[k] * z[k] / r.d[i].min(r.d[j]) > significant => {
                        marked[cl.label[i] as usize] = true;
                    }
                    RowKind::Bound(v, _, _) if z[k] * z[k] / r.d[v] > significant => {
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
        let share = share_after(last_join.as_ref(), n);
        let joined = join(&rows, &mut in_set, &mut z, &x, &cl.forest, &mut tabu, (changed, share));
        let Joined { changed, swaps, stuck, worst, violated } = joined;
        last_join = Some(joined);
        let gap = gap_bound(&rows, &x, &z, &g, &r.d);
        let t5 = std::time::Instant::now();
        crate::progress::update("solve", || {
            format!(
                "active set {outer}: {} rows in, {} violated (worst {worst:.1e}), gap {:.1e} of the data (target {:.0e})",
                in_set.iter().filter(|&&s| s).count(),
                violated,
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
                violated,
                gap / data,
                (t1 - t0).as_millis(),
                (t2 - t1).as_millis(),
                (t3 - t2).as_millis(),
                (t4 - t3).as_millis(),
                (t5 - t4).as_millis()
            );
        }
        // a working set that keeps coming back (a swap undone by the next cut) is a cycle
        let state = (in_set.iter().filter(|&&s| s).count(), violated, changed);
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
