//! The objective as the iteration uses it and the conjugate gradients on the cluster values.

use super::clusters::{Clusters, NONE};
use super::operator::RowClasses;

/// Conjugate-gradient iterations per solve at most.
const MAX_CG: usize = 5000;

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
    // each variable's unknown (NONE when anchored); the identity when no row is in the set
    let of_vertex: Vec<u32> = cl.label.iter().map(|&c| cl.unknown[c as usize]).collect();
    let identity = nu == n && of_vertex.iter().enumerate().all(|(v, &u)| u as usize == v);
    // start: cluster means; weights D_c; Jacobi diagonal of CᵀPC
    let mut y = vec![0.0; nu];
    let mut size = vec![0.0; nu];
    let mut dsum = vec![0.0; nu];
    for (v, xv) in x.iter().enumerate() {
        let u = of_vertex[v];
        if u != NONE {
            y[u as usize] += xv - cl.offset[v];
            size[u as usize] += 1.0;
            dsum[u as usize] += obj.d[v];
        }
    }
    y.iter_mut().zip(&size).for_each(|(y, s)| *y /= s);
    let mut diag = vec![0.0; nu];
    for (i, &u) in of_vertex.iter().enumerate() {
        if u == NONE {
            continue;
        }
        if size[u as usize] == 1.0 {
            // a cluster of one: its diagonal alone (the same sum, in the same order)
            diag[u as usize] = obj.p.diagonal(i);
            continue;
        }
        for (j, v) in obj.p.row(i) {
            if cl.label[j] == cl.label[i] {
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
    gather(&of_vertex, &px, &mut r);
    r.iter_mut().for_each(|v| *v = -*v);
    let measure = |r: &[f64]| 0.5 * r.iter().zip(&dsum).map(|(r, d)| r * r / d.max(f64::MIN_POSITIVE)).sum::<f64>();
    let mut zv: Vec<f64> = r.iter().zip(&diag).map(|(r, d)| r / d).collect();
    let mut dir = zv.clone();
    let mut rz: f64 = r.iter().zip(&zv).map(|(a, b)| a * b).sum();
    let mut hd = vec![0.0; nu];
    let mut it = 0;
    let mut m = measure(&r);
    while it < MAX_CG && m > tolerance {
        if it % 32 == 31 && crate::progress::cancelled() {
            break;
        }
        if identity {
            obj.p.apply(&dir, &mut hd);
        } else {
            for (xv, &u) in xs.iter_mut().zip(&of_vertex) {
                *xv = if u == NONE { 0.0 } else { dir[u as usize] };
            }
            obj.p.apply(&xs, &mut px);
            gather(&of_vertex, &px, &mut hd);
        }
        let dhd: f64 = dir.iter().zip(&hd).map(|(a, b)| a * b).sum();
        if dhd <= 0.0 || !dhd.is_finite() {
            break;
        }
        let alpha = rz / dhd;
        // one pass: the step, the residual, its preconditioned form and both sums (each
        // summed in index order, as separate passes would)
        let (mut rz_new, mut rd) = (0.0, 0.0);
        for k in 0..nu {
            y[k] += alpha * dir[k];
            r[k] -= alpha * hd[k];
            zv[k] = r[k] / diag[k];
            rz_new += r[k] * zv[k];
            rd += r[k] * r[k] / dsum[k].max(f64::MIN_POSITIVE);
        }
        m = 0.5 * rd;
        let beta = rz_new / rz;
        rz = rz_new;
        dir.iter_mut().zip(&zv).for_each(|(p, z)| *p = z + beta * *p);
        it += 1;
    }
    cl.expand(&y, x);
    it
}

/// `out[u] = Σ values[v]` over the variables `v` of unknown `u`, in their order (anchored
/// variables, NONE, are left out).
fn gather(of_vertex: &[u32], values: &[f64], out: &mut [f64]) {
    out.iter_mut().for_each(|o| *o = 0.0);
    for (&value, &u) in values.iter().zip(of_vertex) {
        if u != NONE {
            out[u as usize] += value;
        }
    }
}
