//! The objective as the iteration uses it and the conjugate gradients on the cluster values.

use super::clusters::{Clusters, NONE};
use super::operator::RowClasses;

/// Conjugate-gradient iterations per solve at most.
const MAX_CG: usize = 5000;
/// The conjugate gradients' vectors go to the threads in blocks of this many entries, and
/// their sums are summed per block, then over the blocks in order: the same bits for every
/// thread count.
const BLOCK: usize = 4096;

/// Each unknown's variables, in increasing order: where they start in the list (one more at
/// the end), and the list.
fn members_of(of_vertex: &[u32], nu: usize) -> (Vec<usize>, Vec<u32>) {
    let mut start = vec![0usize; nu + 1];
    for &u in of_vertex.iter().filter(|&&u| u != NONE) {
        start[u as usize + 1] += 1;
    }
    for k in 0..nu {
        start[k + 1] += start[k];
    }
    let mut at = start.clone();
    let mut members = vec![0u32; start[nu]];
    for (v, &u) in of_vertex.iter().enumerate().filter(|(_, &u)| u != NONE) {
        members[at[u as usize]] = v as u32;
        at[u as usize] += 1;
    }
    (start, members)
}

/// Unknowns from which the conjugate gradients' vector steps are split between threads: a
/// split costs a thread's start (tens of microseconds), which the 64³ bench volume's steps
/// (262,144 unknowns, 2.5 ms an iteration) did not win back; the 96³ one's gained 13 %.
const PARALLEL_UNKNOWNS: usize = 1 << 19;

/// `f` on each block, split between the threads when `parallel`; the results in order.
fn map_blocks<W: Send, R: Send>(blocks: &mut [W], parallel: bool, f: &(impl Fn(&mut W) -> R + Sync)) -> Vec<R> {
    if parallel {
        crate::parallel::map_items(blocks, f)
    } else {
        blocks.iter_mut().map(f).collect()
    }
}

/// `Σ f(block)` over the blocks, added in the blocks' order (see [`map_blocks`]).
fn block_sum<W: Send>(blocks: &mut [W], parallel: bool, f: &(impl Fn(&mut W) -> f64 + Sync)) -> f64 {
    map_blocks(blocks, parallel, f).iter().sum()
}

/// The objective's pieces the iteration needs.
pub(super) struct Objective<'a> {
    pub(super) p: RowClasses,
    pub(super) q: &'a [f64],
    pub(super) d: &'a [f64],
    pub(super) q_free: &'a [f64],
}

impl Objective<'_> {
    pub(super) fn gradient(&self, x: &[f64], g: &mut [f64]) {
        self.p.apply(x, g);
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

/// Conjugate gradients on the cluster values: `x` in and out (its cluster means are the start),
/// until `½ Σ_c r_c² / D_c ≤ tolerance` (r the cluster residual, D the cluster's data
/// diagonal). Returns the iterations.
pub(super) fn solve_clustered(obj: &Objective<'_>, cl: &Clusters, x: &mut [f64], tolerance: f64) -> usize {
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
        for (j, v) in obj.p.row(i) {
            if cl.label[j] == ci {
                diag[u as usize] += v;
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
    // each variable's unknown (NONE when anchored), and each unknown's variables in order;
    // none of it when no row is in the set (the unknowns are the variables)
    let of_vertex: Vec<u32> = cl.label.iter().map(|&c| cl.unknown[c as usize]).collect();
    let identity = nu == n && of_vertex.iter().enumerate().all(|(v, &u)| u as usize == v);
    let (members_start, members) = if identity { (Vec::new(), Vec::new()) } else { members_of(&of_vertex, nu) };
    let parallel = nu >= PARALLEL_UNKNOWNS;
    let mut it = 0;
    let mut m = measure(&r);
    while it < MAX_CG && m > tolerance {
        if it % 32 == 31 && crate::progress::cancelled() {
            break;
        }
        // hd = CᵀPC dir, and dirᵀhd
        let dhd: f64 = if identity {
            obj.p.apply(&dir, &mut hd);
            let mut parts: Vec<_> = dir.chunks(BLOCK).zip(hd.chunks(BLOCK)).collect();
            block_sum(&mut parts, parallel, &|(d, h)| d.iter().zip(h.iter()).map(|(a, b)| a * b).sum())
        } else {
            let dir = &dir;
            let mut parts: Vec<_> = xs.chunks_mut(BLOCK).zip(of_vertex.chunks(BLOCK)).collect();
            map_blocks(&mut parts, parallel, &|(xs, of)| {
                for (xv, &u) in xs.iter_mut().zip(of.iter()) {
                    *xv = if u == NONE { 0.0 } else { dir[u as usize] };
                }
            });
            obj.p.apply(&xs, &mut px);
            let (px, start, members) = (&px, &members_start, &members);
            let mut parts: Vec<_> = hd.chunks_mut(BLOCK).zip(dir.chunks(BLOCK)).enumerate().collect();
            block_sum(&mut parts, parallel, &|(b, (hd, dir))| {
                let mut dhd = 0.0;
                for (k, (h, d)) in hd.iter_mut().zip(dir.iter()).enumerate() {
                    let u = *b * BLOCK + k;
                    // the members' values added in their order, as a scatter over them would
                    let mut acc = 0.0;
                    for &v in &members[start[u]..start[u + 1]] {
                        acc += px[v as usize];
                    }
                    *h = acc;
                    dhd += d * acc;
                }
                dhd
            })
        };
        if dhd <= 0.0 || !dhd.is_finite() {
            break;
        }
        let alpha = rz / dhd;
        // one pass: the step, the residual, its preconditioned form and both sums
        let mut parts: Vec<_> = y
            .chunks_mut(BLOCK)
            .zip(r.chunks_mut(BLOCK))
            .zip(zv.chunks_mut(BLOCK))
            .zip(dir.chunks(BLOCK).zip(hd.chunks(BLOCK)).zip(diag.chunks(BLOCK).zip(dsum.chunks(BLOCK))))
            .collect();
        let sums = map_blocks(&mut parts, parallel, &|(((y, r), zv), ((dir, hd), (diag, dsum)))| {
            let (mut rz, mut rd) = (0.0, 0.0);
            for k in 0..y.len() {
                y[k] += alpha * dir[k];
                r[k] -= alpha * hd[k];
                zv[k] = r[k] / diag[k];
                rz += r[k] * zv[k];
                rd += r[k] * r[k] / dsum[k].max(f64::MIN_POSITIVE);
            }
            (rz, rd)
        });
        let (rz_new, rd) = sums.iter().fold((0.0, 0.0), |(a, b), (c, d)| (a + c, b + d));
        m = 0.5 * rd;
        let beta = rz_new / rz;
        rz = rz_new;
        let mut parts: Vec<_> = dir.chunks_mut(BLOCK).zip(zv.chunks(BLOCK)).collect();
        map_blocks(&mut parts, parallel, &|(p, z)| p.iter_mut().zip(z.iter()).for_each(|(p, z)| *p = z + beta * *p));
        it += 1;
    }
    cl.expand(&y, x);
    it
}
