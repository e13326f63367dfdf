//! The objective as the iteration uses it and the conjugate gradients on the cluster values.

use super::clusters::{Clusters, NONE};
use super::operator::{RowClasses, TwoPass};

/// Conjugate-gradient iterations per solve at most.
const MAX_CG: usize = 5000;

/// The objective's pieces the iteration needs.
pub(super) struct Objective<'a> {
    /// P's rows: its diagonal and each cluster's, and its product where `two_pass` is absent.
    pub(super) p: RowClasses,
    /// P's product over the stiffness, where the energy is of order 2.
    pub(super) two_pass: Option<TwoPass>,
    /// The memory budget the multigrid's hierarchy must fit in beside what the process holds
    /// (`None`: no hierarchy is made).
    pub(super) budget: Option<crate::memory::Budget>,
    pub(super) q: &'a [f64],
    pub(super) d: &'a [f64],
    pub(super) q_free: &'a [f64],
}

impl Objective<'_> {
    /// `y = P x`.
    pub(super) fn apply(&self, x: &[f64], y: &mut [f64]) {
        match &self.two_pass {
            Some(t) => t.apply(x, self.d, y),
            None => self.p.apply(x, y),
        }
    }

    pub(super) fn gradient(&self, x: &[f64], g: &mut [f64]) {
        self.apply(x, g);
        g.iter_mut().zip(self.q).for_each(|(g, q)| *g += q);
    }

    /// `½ Σ (d x + q_free)² / d`.
    pub(super) fn data_term(&self, x: &[f64]) -> f64 {
        x.iter()
            .zip(self.d)
            .zip(self.q_free)
            .filter(|((_, &d), _)| d > 0.0)
            .map(|((&x, &d), &q)| (d * x + q).powi(2) / d)
            .sum::<f64>()
            * 0.5
    }
}

/// Unknowns per block of the conjugate gradients' passes: each block's sums are made alone and
/// the blocks' sums added in order, so every sum is the same on any number of threads.
const BLOCK: usize = 1 << 12;
/// Blocks from which a pass of the conjugate gradients is shared between threads (a thread's
/// start costs about as much as a pass over 30,000 unknowns).
const PARALLEL_BLOCKS: usize = 8;

/// Each unknown's variables in increasing order: `list[start[u]..start[u + 1]]`.
struct Members {
    start: Vec<u32>,
    list: Vec<u32>,
}

impl Members {
    fn new(of_vertex: &[u32], nu: usize) -> Members {
        let mut start = vec![0u32; nu + 1];
        for &u in of_vertex.iter().filter(|&&u| u != NONE) {
            start[u as usize + 1] += 1;
        }
        for u in 0..nu {
            start[u + 1] += start[u];
        }
        let mut at = start[..nu].to_vec();
        let mut list = vec![0u32; start[nu] as usize];
        for (v, &u) in of_vertex.iter().enumerate().filter(|(_, &u)| u != NONE) {
            list[at[u as usize] as usize] = v as u32;
            at[u as usize] += 1;
        }
        Members { start, list }
    }

    fn of(&self, u: usize) -> &[u32] {
        &self.list[self.start[u] as usize..self.start[u + 1] as usize]
    }
}

/// Conjugate gradients on the cluster values: `x` in and out (its cluster means are the start),
/// until `½ Σ_c r_c² / D_c ≤ tolerance` (r the cluster residual, D the cluster's data
/// diagonal). Returns the iterations. Every pass but the product runs over blocks of
/// [`BLOCK`] unknowns, shared between threads. Preconditioned by the clusters' diagonal;
/// a solve that has not converged after `multigrid_after` iterations ([`MULTIGRID_AFTER`],
/// or [`MULTIGRID_SOON`] after a solve that needed it) goes on from where it is,
/// preconditioned by a V-cycle of smoothed-aggregation multigrid on `CᵀPC` assembled (if
/// its hierarchy fits in the budget); also says whether it did.
pub(super) fn solve_clustered(
    obj: &Objective<'_>,
    cl: &Clusters,
    x: &mut [f64],
    tolerance: f64,
    multigrid_after: usize,
) -> (usize, bool) {
    let n = x.len();
    let nu = cl.n_unknowns;
    if nu == 0 {
        cl.expand(&[], x);
        return (0, false);
    }
    // each variable's unknown (NONE when anchored); the identity when no row is in the set
    let mut of_vertex = vec![0u32; n];
    crate::parallel::split_mut(&mut of_vertex, |off, piece| {
        piece.iter_mut().zip(&cl.label[off..]).for_each(|(u, &c)| *u = cl.unknown[c as usize]);
    });
    let identity = nu == n && of_vertex.iter().enumerate().all(|(v, &u)| u as usize == v);
    let members = (!identity).then(|| Members::new(&of_vertex, nu));
    // start: cluster means; weights 1 / D_c; Jacobi weights 1 / diag(CᵀPC)
    let (mut y, inv_dsum, inv_diag) = unknowns_start(obj, cl, x, members.as_ref());
    let mut xs = if identity { Vec::new() } else { vec![0.0; n] };
    let mut px = vec![0.0; n];
    // r = −Cᵀ∇φ(C y + anchors)
    cl.expand(&y, x);
    obj.gradient(x, &mut px);
    let mut r = vec![0.0; nu];
    match &members {
        Some(m) => crate::parallel::split_mut(&mut r, |off, piece| {
            for (k, r) in piece.iter_mut().enumerate() {
                *r = -m.of(off + k).iter().fold(0.0, |s, &v| s + px[v as usize]);
            }
        }),
        None => r.iter_mut().zip(&px).for_each(|(r, p)| *r = -p),
    }
    // the V-cycle's solve, `None` (nothing changed) when its hierarchy cannot be made
    let use_multigrid = |y: &mut [f64], r: &mut [f64], x: &mut [f64], done: usize| {
        let it = multigrid_cg(obj, &of_vertex, members.as_ref(), (y, r), &inv_dsum, tolerance)?;
        cl.expand(y, x);
        Some(done + it)
    };
    let measure = |r: &[f64]| 0.5 * r.iter().zip(&inv_dsum).map(|(r, w)| r * r * w).sum::<f64>();
    let mut dir: Vec<f64> = r.iter().zip(&inv_diag).map(|(r, w)| r * w).collect();
    if !identity {
        scatter(&dir, &of_vertex, &mut xs);
    }
    let mut rz: f64 = r.iter().zip(&dir).map(|(a, b)| a * b).sum();
    let mut hd = vec![0.0; nu];
    let mut it = 0;
    let mut m = measure(&r);
    while it < MAX_CG && m > tolerance {
        if it % 32 == 31 && crate::progress::cancelled() {
            break;
        }
        if it == multigrid_after && nu >= MULTIGRID_FROM {
            // a slow solve: the V-cycle takes over from here
            if let Some(it) = use_multigrid(&mut y, &mut r, x, it) {
                return (it, true);
            }
        }
        let dhd = if identity {
            obj.apply(&dir, &mut hd);
            dot_blocks(&dir, &hd)
        } else {
            obj.apply(&xs, &mut px);
            gather_dot(&mut hd, &dir, &px, members.as_ref().expect("members where C is not the identity"))
        };
        if dhd <= 0.0 || !dhd.is_finite() {
            break;
        }
        let alpha = rz / dhd;
        // one pass: the step, the residual and both sums
        let (rz_new, rd) = step_blocks(alpha, (&mut y, &mut r), (&dir, &hd), (&inv_diag, &inv_dsum));
        m = 0.5 * rd;
        let beta = rz_new / rz;
        rz = rz_new;
        // the preconditioned residual r / diag made again here rather than stored by the step
        // (the same bits; one vector less through memory)
        crate::parallel::split_mut(&mut dir, |off, piece| {
            piece.iter_mut().zip(r[off..].iter().zip(&inv_diag[off..])).for_each(|(p, (r, w))| *p = r * w + beta * *p);
        });
        if !identity {
            scatter(&dir, &of_vertex, &mut xs);
        }
        it += 1;
    }
    cl.expand(&y, x);
    (it, false)
}

/// Iterations of a diagonal-preconditioned solve after which the V-cycle takes over (on
/// systems of at least [`MULTIGRID_FROM`] unknowns). The 128³ bench volume's solves take at
/// most 370; the 1000² bench grid's first ones, at a smoothing length of 12 mean edges, did
/// not converge in 5,000, and its last ones take a handful, where building the hierarchy
/// would cost more than the solve (docs/performance.md §3).
pub(super) const MULTIGRID_AFTER: usize = 500;
/// [`MULTIGRID_AFTER`] for the solve after one that needed the V-cycle: the 1000² bench
/// grid's solves need it for dozens of rounds in a row, and its last ones converge in fewer.
pub(super) const MULTIGRID_SOON: usize = 50;
/// Unknowns below which the diagonal preconditioner stays.
const MULTIGRID_FROM: usize = 10_000;

/// Bytes the multigrid's solve allocates at most for `n` variables, `nu` unknowns and `e`
/// stored entries of P (both triangles), which bound `CᵀPC`'s: `CᵀPC` (12 an entry, 8 a row)
/// and its pieces while it is made (as much again); the prolongation (12 an entry, at most
/// one more per row than `CᵀPC`'s), its transpose (12, and 8 a row) and its pieces; the coarser
/// levels (no more entries than the finest: their operator complexity was 1.04–1.3 on the
/// bench grids); per unknown five work vectors and the conjugate gradients' three (64, on
/// levels of fewer unknowns than the finest together), and per variable the expanded
/// vector and its product (16).
#[must_use]
pub(crate) fn multigrid_bytes(n: usize, nu: usize, e: usize) -> u64 {
    let (n, nu, e) = (n as u64, nu as u64, e as u64);
    24 * e + 16 * nu + 40 * (e + nu) + 12 * e + 2 * 64 * nu + 16 * n
}

/// The conjugate gradients from `y` (the residual `r` at it) preconditioned by a V-cycle of
/// [`crate::linalg::multigrid::Hierarchy`] on `CᵀPC` assembled, until `½ Σ r² w ≤ tolerance`;
/// returns the iterations, or `None` (with `y` and `r` untouched) when there is no budget,
/// when [`multigrid_bytes`] would not fit in it beside what the process holds, or when a level
/// is found not positive definite.
fn multigrid_cg(
    obj: &Objective<'_>,
    of_vertex: &[u32],
    members: Option<&Members>,
    (y, r): (&mut [f64], &mut [f64]),
    w: &[f64],
    tolerance: f64,
) -> Option<usize> {
    use crate::linalg::multigrid::{Csr, Hierarchy};
    let nu = y.len();
    let budget = obj.budget.as_ref()?;
    let need = multigrid_bytes(of_vertex.len(), nu, obj.p.entries());
    if budget.in_use().saturating_add(need).saturating_add(budget.kernel_reserve()) > budget.bytes {
        return None;
    }
    let t0 = std::time::Instant::now();
    let a = Csr::from_rows(nu, nu, |u, out| {
        let single = [u as u32];
        let of = members.map_or(&single[..], |m| m.of(u));
        for &v in of {
            for (j, p) in obj.p.row(v as usize) {
                let c = of_vertex[j];
                if c != NONE {
                    out.push((c, p));
                }
            }
        }
    });
    let mut h = Hierarchy::new(a)?;
    let t1 = std::time::Instant::now();
    // CᵀPC's products as the diagonal's iterations make them (expand, P, gather), which read
    // far less memory than its stored entries
    let n = of_vertex.len();
    let (mut xs, mut px) = (vec![0.0; if members.is_some() { n } else { 0 }], vec![0.0; n]);
    let mut product = |v: &[f64], out: &mut [f64]| match members {
        None => obj.apply(v, out),
        Some(m) => {
            scatter(v, of_vertex, &mut xs);
            obj.apply(&xs, &mut px);
            crate::parallel::split_mut(out, |off, piece| {
                for (k, o) in piece.iter_mut().enumerate() {
                    *o = m.of(off + k).iter().fold(0.0, |s, &v| s + px[v as usize]);
                }
            });
        }
    };
    let measure = |r: &[f64]| 0.5 * r.iter().zip(w).map(|(r, w)| r * r * w).sum::<f64>();
    let mut z = vec![0.0; nu];
    h.apply_with(Some(&mut product), r, &mut z);
    let mut dir = z.clone();
    let mut rz = dot_blocks(r, &z);
    let mut hd = vec![0.0; nu];
    let mut it = 0;
    while it < MAX_CG && measure(r) > tolerance {
        if it % 32 == 31 && crate::progress::cancelled() {
            break;
        }
        product(&dir, &mut hd);
        let dhd = dot_blocks(&dir, &hd);
        if dhd <= 0.0 || !dhd.is_finite() {
            break;
        }
        let alpha = rz / dhd;
        crate::parallel::split_mut2(y, r, |off, y, r| {
            for k in 0..y.len() {
                y[k] += alpha * dir[off + k];
                r[k] -= alpha * hd[off + k];
            }
        });
        h.apply_with(Some(&mut product), r, &mut z);
        let rz_new = dot_blocks(r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        crate::parallel::split_mut(&mut dir, |off, d| {
            d.iter_mut().zip(&z[off..]).for_each(|(d, z)| *d = z + beta * *d);
        });
        it += 1;
    }
    if std::env::var_os("TOPOSMOOTH_TRACE_ACTIVE").is_some() {
        eprintln!(
            "multigrid: levels {:?}, hierarchy {} ms, {it} iterations in {} ms",
            h.sizes(),
            (t1 - t0).as_millis(),
            t1.elapsed().as_millis()
        );
    }
    Some(it)
}

/// Per unknown (on blocks of [`BLOCK`] unknowns, shared between threads): the mean of its
/// variables' `x − offset`, the inverse of their data diagonal's sum and the inverse of its
/// diagonal in CᵀPC, each summed over its variables in increasing order (one variable per
/// unknown when `members` is absent); the same bits on any number of threads.
fn unknowns_start(
    obj: &Objective<'_>,
    cl: &Clusters,
    x: &[f64],
    members: Option<&Members>,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let nu = cl.n_unknowns;
    let (mut y, mut inv_dsum, mut inv_diag) = (vec![0.0; nu], vec![0.0; nu], vec![0.0; nu]);
    type Part<'a> = (usize, &'a mut [f64], &'a mut [f64], &'a mut [f64]);
    let mut parts: Vec<Part<'_>> = y
        .chunks_mut(BLOCK)
        .zip(inv_dsum.chunks_mut(BLOCK))
        .zip(inv_diag.chunks_mut(BLOCK))
        .enumerate()
        .map(|(b, ((y, w), g))| (b * BLOCK, y, w, g))
        .collect();
    crate::parallel::for_each_mut(&mut parts, PARALLEL_BLOCKS, |(first, y, inv_dsum, inv_diag)| {
        for k in 0..y.len() {
            let u = *first + k;
            let one = [u as u32];
            let of = members.map_or(&one[..], |m| m.of(u));
            let (mut sum, mut dsum) = (0.0, 0.0);
            for &v in of {
                let v = v as usize;
                sum += x[v] - cl.offset[v];
                dsum += obj.d[v];
            }
            let diag = if let [i] = *of {
                // a cluster of one: its diagonal alone
                obj.p.diagonal(i as usize)
            } else {
                let mut diag = 0.0;
                for &i in of {
                    let i = i as usize;
                    for (j, v) in obj.p.row(i) {
                        if cl.label[j] == cl.label[i] {
                            diag += v;
                        }
                    }
                }
                diag
            };
            y[k] = sum / of.len() as f64;
            inv_dsum[k] = 1.0 / dsum.max(f64::MIN_POSITIVE);
            inv_diag[k] = 1.0 / diag;
        }
    });
    drop(parts);
    (y, inv_dsum, inv_diag)
}

/// `xs[v] = dir[u]` for each variable `v` of unknown `u`, 0 at anchored ones.
fn scatter(dir: &[f64], of_vertex: &[u32], xs: &mut [f64]) {
    crate::parallel::split_mut(xs, |off, piece| {
        for (xv, &u) in piece.iter_mut().zip(&of_vertex[off..]) {
            *xv = if u == NONE { 0.0 } else { dir[u as usize] };
        }
    });
}

/// `hd = Cᵀ px` (per unknown its variables' sum, in their order); returns `dirᵀ hd` in
/// [`LANES`] running sums per block of [`BLOCK`] unknowns, the blocks' sums added in order.
fn gather_dot(hd: &mut [f64], dir: &[f64], px: &[f64], members: &Members) -> f64 {
    let mut parts: Vec<(usize, &mut [f64], f64)> =
        hd.chunks_mut(BLOCK).enumerate().map(|(b, c)| (b * BLOCK, c, 0.0)).collect();
    crate::parallel::for_each_mut(&mut parts, PARALLEL_BLOCKS, |(first, hd, sum)| {
        *sum = lane_sum(hd.iter_mut().enumerate().map(|(k, h)| {
            let u = *first + k;
            *h = members.of(u).iter().fold(0.0, |s, &v| s + px[v as usize]);
            dir[u] * *h
        }));
    });
    parts.iter().fold(0.0, |s, p| s + p.2)
}

/// `aᵀb` in [`LANES`] running sums per block of [`BLOCK`] entries, the blocks' sums added in
/// order (the same bits on any number of threads).
fn dot_blocks(a: &[f64], b: &[f64]) -> f64 {
    let mut parts: Vec<(usize, f64)> = (0..a.len().div_ceil(BLOCK)).map(|k| (k * BLOCK, 0.0)).collect();
    crate::parallel::for_each_mut(&mut parts, PARALLEL_BLOCKS, |(first, sum)| {
        let end = (*first + BLOCK).min(a.len());
        *sum = lane_sum(a[*first..end].iter().zip(&b[*first..end]).map(|(x, y)| x * y));
    });
    parts.iter().fold(0.0, |s, p| s + p.1)
}

/// The sum of `terms` in [`LANES`] running sums (term `k` to lane `k mod LANES`), the lanes
/// added in a fixed order.
fn lane_sum(terms: impl Iterator<Item = f64>) -> f64 {
    let mut acc = [0.0; LANES];
    for (k, t) in terms.enumerate() {
        acc[k % LANES] += t;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// [`step`] over blocks of [`BLOCK`] unknowns, shared between threads; the blocks' sums added
/// in order.
fn step_blocks(
    alpha: f64,
    (y, r): (&mut [f64], &mut [f64]),
    (p, hp): (&[f64], &[f64]),
    (inv_diag, inv_dsum): (&[f64], &[f64]),
) -> (f64, f64) {
    type Part<'a> = (usize, (&'a mut [f64], &'a mut [f64]), (f64, f64));
    let mut parts: Vec<Part<'_>> = y
        .chunks_mut(BLOCK)
        .zip(r.chunks_mut(BLOCK))
        .enumerate()
        .map(|(b, (y, r))| (b * BLOCK, (y, r), (0.0, 0.0)))
        .collect();
    crate::parallel::for_each_mut(&mut parts, PARALLEL_BLOCKS, |(first, (y, r), sums)| {
        let range = *first..*first + y.len();
        *sums =
            step(alpha, (y, r), (&p[range.clone()], &hp[range.clone()]), (&inv_diag[range.clone()], &inv_dsum[range]));
    });
    parts.iter().fold((0.0, 0.0), |(a, b), p| (a + p.2 .0, b + p.2 .1))
}

/// Sums side by side in a product or a step: one running sum per lane, the lanes added in a
/// fixed order at the end (a single running sum made each pass wait on its additions).
const LANES: usize = 4;

/// The conjugate-gradient step: `y += α p`, `r −= α H p`; returns `rᵀz` with `z = r / diag`
/// (not stored) and `Σ r² / D` (each in [`LANES`] running sums).
fn step(
    alpha: f64,
    (y, r): (&mut [f64], &mut [f64]),
    (p, hp): (&[f64], &[f64]),
    (inv_diag, inv_dsum): (&[f64], &[f64]),
) -> (f64, f64) {
    let (mut rz, mut rd) = ([0.0; LANES], [0.0; LANES]);
    let whole = y.len() / LANES * LANES;
    let one = |k: usize, l: usize, y: &mut [f64], r: &mut [f64], rz: &mut [f64; LANES], rd: &mut [f64; LANES]| {
        y[k] += alpha * p[k];
        r[k] -= alpha * hp[k];
        let z = r[k] * inv_diag[k];
        rz[l] += r[k] * z;
        rd[l] += r[k] * r[k] * inv_dsum[k];
    };
    for b in (0..whole).step_by(LANES) {
        for l in 0..LANES {
            one(b + l, l, y, r, &mut rz, &mut rd);
        }
    }
    for k in whole..y.len() {
        one(k, k - whole, y, r, &mut rz, &mut rd);
    }
    ((rz[0] + rz[1]) + (rz[2] + rz[3]), (rd[0] + rd[1]) + (rd[2] + rd[3]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::with_threads;

    /// Values in (−0.5, 0.5) from a fixed seed (xorshift).
    fn values(n: usize, mut state: u64) -> Vec<f64> {
        (0..n)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// A fourth-order system on a grid (`K K + c I`, 5-point K) whose diagonal-preconditioned
    /// solve would need thousands of iterations, with pairs of variables joined into clusters:
    /// the V-cycle takes over after [`MULTIGRID_AFTER`] iterations, the solve reaches its
    /// tolerance, and the same bits come out on 1, 2 and 3 threads.
    #[test]
    fn a_slow_solve_hands_its_preconditioning_to_the_v_cycle_and_converges() {
        use super::super::operator::RowClasses;
        use super::super::rows::Row;
        let (w, h) = (150, 120);
        let n = w * h;
        let c = 1e-5;
        // K's rows, then the upper triangle of K K + c I sorted by column, then row
        let k_row = |i: usize| {
            let (x, y) = (i % w, i / w);
            let mut row = vec![];
            for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                if nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h {
                    row.push((ny as usize * w + nx as usize, -1.0));
                }
            }
            let deg = row.len() as f64;
            row.push((i, deg));
            row
        };
        let mut upper = std::collections::BTreeMap::new();
        for i in 0..n {
            for (j, a) in k_row(i) {
                for (l, b) in k_row(j) {
                    if i <= l {
                        *upper.entry((l, i)).or_insert(0.0) += a * b;
                    }
                }
            }
            *upper.entry((i, i)).or_insert(0.0) += c;
        }
        let triplets: Vec<(usize, usize, f64)> = upper.iter().map(|(&(col, row), &v)| (row, col, v)).collect();
        let d = vec![c; n];
        let q: Vec<f64> = values(n, 9);
        let q_free = q.clone();
        let run = |budget: Option<u64>| {
            let obj = Objective {
                p: RowClasses::from_upper(n, &triplets).unwrap(),
                two_pass: None,
                budget: budget.map(|b| crate::memory::Budget::of(Some(b))),
                q: &q,
                d: &d,
                q_free: &q_free,
            };
            // every 7th variable joined to its right-hand neighbour one margin below
            let rows: Vec<Row> =
                (0..n).filter(|i| i % 7 == 0 && i % w + 1 < w).map(|i| Row::pair(i + 1, i, -1e-3)).collect();
            let in_set = vec![true; rows.len()];
            let cl = Clusters::new(n, &rows, &in_set);
            let mut x = vec![0.0; n];
            let (it, multigrid) = solve_clustered(&obj, &cl, &mut x, 1e-12, MULTIGRID_AFTER);
            assert_eq!(multigrid, budget == Some(u64::MAX), "{it} iterations");
            // the gradient summed per cluster, measured as the solve measures it
            let mut g = vec![0.0; n];
            obj.gradient(&x, &mut g);
            let mut sums = std::collections::BTreeMap::new();
            for v in 0..n {
                let e = sums.entry(cl.label[v]).or_insert((0.0, 0.0));
                e.0 += g[v];
                e.1 += d[v];
            }
            let measure: f64 = sums.values().map(|(r, w)| 0.5 * r * r / w).sum();
            (it, measure, x)
        };
        let runs: Vec<_> = (1..=3).map(|t| with_threads(t, || run(Some(u64::MAX)))).collect();
        let (it, measure, _) = &runs[0];
        // the diagonal's iterations, then the V-cycle's: far fewer than the diagonal needs
        // alone (with no budget for the hierarchy, or one too small for it)
        assert!(*it > MULTIGRID_AFTER && *it < MULTIGRID_AFTER + 300, "{it} iterations");
        for budget in [None, Some(1 << 20)] {
            let (alone, _, _) = run(budget);
            assert!(alone > 3 * it, "{alone} iterations without the V-cycle, {it} with it");
        }
        assert!(*measure <= 2e-12, "measure {measure:e}");
        for (t, r) in runs.iter().enumerate().skip(1) {
            assert!(r == &runs[0], "1 and {} threads differ", t + 1);
        }
    }

    /// The passes over blocks give the same bits on 1, 2 and 3 threads (long enough to be
    /// shared out), and the sums they make (the gather's per unknown, the dot's and the step's)
    /// agree with plain sums to rounding.
    #[test]
    fn block_passes_give_the_same_bits_on_any_thread_count_and_the_plain_sums() {
        let (n, nu) = (300_001, 200_003);
        // unknowns of one or more variables in no particular order, every 40,000th variable
        // anchored unless the fix-up below gives it an unknown
        let mut of_vertex: Vec<u32> = (0..n).map(|v| ((v as u64 * 2_654_435_761) % nu as u64) as u32).collect();
        of_vertex.iter_mut().step_by(40_000).for_each(|u| *u = NONE);
        let mut seen = vec![false; nu];
        of_vertex.iter().filter(|&&u| u != NONE).for_each(|&u| seen[u as usize] = true);
        for (u, _) in seen.iter().enumerate().filter(|(_, &s)| !s) {
            of_vertex[u] = u as u32; // every unknown keeps a variable
        }
        let members = Members::new(&of_vertex, nu);
        let px = values(n, 1);
        let dir = values(nu, 2);
        let runs: Vec<_> = (1..=3)
            .map(|t| {
                with_threads(t, || {
                    let mut hd = vec![0.0; nu];
                    let dhd = gather_dot(&mut hd, &dir, &px, &members);
                    let (mut y, mut r) = (values(nu, 3), values(nu, 4));
                    let inv: Vec<f64> = values(nu, 5).iter().map(|v| 1.0 + v.abs()).collect();
                    let sums = step_blocks(0.7, (&mut y, &mut r), (&dir, &hd), (&inv, &inv));
                    let mut xs = vec![1.0; n];
                    scatter(&dir, &of_vertex, &mut xs);
                    let dot = dot_blocks(&dir, &hd);
                    (hd, dhd, y, r, sums, dot, xs)
                })
            })
            .collect();
        for (t, run) in runs.iter().enumerate().skip(1) {
            assert!(run == &runs[0], "1 and {} threads differ", t + 1);
        }
        let (hd, dhd, y, r, (rz, rd), dot, xs) = &runs[0];
        let mut plain = vec![0.0; nu];
        for (v, &u) in of_vertex.iter().enumerate() {
            if u != NONE {
                plain[u as usize] += px[v];
                assert_eq!(xs[v], dir[u as usize]);
            } else {
                assert_eq!(xs[v], 0.0);
            }
        }
        assert_eq!(hd, &plain, "each unknown's sum runs over its variables in their order");
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        let plain_dot: f64 = dir.iter().zip(&plain).map(|(a, b)| a * b).sum();
        assert!(close(*dhd, plain_dot) && close(*dot, plain_dot), "{dhd} {dot} {plain_dot}");
        let (y0, r0) = (values(nu, 3), values(nu, 4));
        let inv: Vec<f64> = values(nu, 5).iter().map(|v| 1.0 + v.abs()).collect();
        for u in 0..nu {
            assert_eq!(y[u], y0[u] + 0.7 * dir[u]);
            assert_eq!(r[u], r0[u] - 0.7 * hd[u]);
        }
        let plain_rz: f64 = r.iter().zip(&inv).map(|(a, w)| a * (a * w)).sum();
        let plain_rd: f64 = r.iter().zip(&inv).map(|(a, w)| a * a * w).sum();
        assert!(close(*rz, plain_rz) && close(*rd, plain_rd));
    }
}
