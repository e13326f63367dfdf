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
    let inv_dsum: Vec<f64> = dsum.iter().map(|d| 1.0 / d.max(f64::MIN_POSITIVE)).collect();
    let inv_diag: Vec<f64> = diag.iter().map(|d| 1.0 / d).collect();
    let measure = |r: &[f64]| 0.5 * r.iter().zip(&inv_dsum).map(|(r, w)| r * r * w).sum::<f64>();
    let mut zv: Vec<f64> = r.iter().zip(&inv_diag).map(|(r, w)| r * w).collect();
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
            obj.apply(&dir, &mut hd);
        } else {
            for (xv, &u) in xs.iter_mut().zip(&of_vertex) {
                *xv = if u == NONE { 0.0 } else { dir[u as usize] };
            }
            obj.apply(&xs, &mut px);
            gather(&of_vertex, &px, &mut hd);
        }
        let dhd = dot(&dir, &hd);
        if dhd <= 0.0 || !dhd.is_finite() {
            break;
        }
        let alpha = rz / dhd;
        // one pass: the step, the residual, its preconditioned form and both sums
        let (rz_new, rd) = step(alpha, (&mut y, &mut r, &mut zv), (&dir, &hd), (&inv_diag, &inv_dsum));
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

/// Sums side by side in a product or a step: one running sum per lane, the lanes added in a
/// fixed order at the end (a single running sum made each pass wait on its additions).
const LANES: usize = 4;

/// `aᵀb`, in [`LANES`] running sums.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; LANES];
    let (a4, b4) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let tail: f64 = a4.remainder().iter().zip(b4.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in a4.zip(b4) {
        for l in 0..LANES {
            acc[l] += x[l] * y[l];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// The conjugate-gradient step: `y += α p`, `r −= α H p`, `z = r / diag`; returns `rᵀz` and
/// `Σ r² / D` (each in [`LANES`] running sums).
fn step(
    alpha: f64,
    (y, r, z): (&mut [f64], &mut [f64], &mut [f64]),
    (p, hp): (&[f64], &[f64]),
    (inv_diag, inv_dsum): (&[f64], &[f64]),
) -> (f64, f64) {
    let (mut rz, mut rd) = ([0.0; LANES], [0.0; LANES]);
    let whole = y.len() / LANES * LANES;
    let one = |k: usize,
               l: usize,
               y: &mut [f64],
               r: &mut [f64],
               z: &mut [f64],
               rz: &mut [f64; LANES],
               rd: &mut [f64; LANES]| {
        y[k] += alpha * p[k];
        r[k] -= alpha * hp[k];
        z[k] = r[k] * inv_diag[k];
        rz[l] += r[k] * z[k];
        rd[l] += r[k] * r[k] * inv_dsum[k];
    };
    for b in (0..whole).step_by(LANES) {
        for l in 0..LANES {
            one(b + l, l, y, r, z, &mut rz, &mut rd);
        }
    }
    for k in whole..y.len() {
        one(k, k - whole, y, r, z, &mut rz, &mut rd);
    }
    ((rz[0] + rz[1]) + (rz[2] + rz[3]), (rd[0] + rd[1]) + (rd[2] + rd[3]))
}
