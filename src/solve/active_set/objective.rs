//! The objective as the iteration uses it: P in compressed rows and the conjugate gradients
//! on the cluster values.

use super::clusters::{Clusters, NONE};

/// Conjugate-gradient iterations per solve at most.
const MAX_CG: usize = 5000;

/// P (both triangles, exact zeros dropped) in compressed rows.
pub(super) struct Csr {
    pub(super) ptr: Vec<usize>,
    pub(super) col: Vec<u32>,
    pub(super) val: Vec<f64>,
}

impl Csr {
    pub(super) fn from_upper(n: usize, p: &[(usize, usize, f64)]) -> Csr {
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

    pub(super) fn rows_into(&self, start: usize, x: &[f64], y: &mut [f64]) {
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
    pub(super) fn apply(&self, x: &[f64], y: &mut [f64]) {
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

/// The objective's pieces the iteration needs.
pub(super) struct Objective<'a> {
    pub(super) p: Csr,
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
