//! An independent reference for the smoothing QP on a series: the energy rebuilt from
//! docs/method.md as dense matrices in double-double arithmetic (faer's `fx128`, about 32
//! digits), the constraints from the kept extrema alone, and a primal active-set method that
//! ends on the exact KKT conditions. Small problems only (dense, a few dozen samples).

#![allow(dead_code, clippy::needless_range_loop)]

use faer::fx128;

type Dd = fx128;

fn dd(x: f64) -> Dd {
    fx128::from(x)
}

fn f64_of(x: Dd) -> f64 {
    x.0 + x.1
}

fn zero() -> Dd {
    dd(0.0)
}

/// A dense matrix in double-double.
#[derive(Clone)]
struct Mat {
    n: usize,
    m: usize,
    a: Vec<Dd>,
}

impl Mat {
    fn zeros(n: usize, m: usize) -> Mat {
        Mat { n, m, a: vec![zero(); n * m] }
    }
    fn at(&self, i: usize, j: usize) -> Dd {
        self.a[i * self.m + j]
    }
    fn set(&mut self, i: usize, j: usize, v: Dd) {
        self.a[i * self.m + j] = v;
    }
    fn add(&mut self, i: usize, j: usize, v: Dd) {
        self.a[i * self.m + j] += v;
    }
    fn mul(&self, b: &Mat) -> Mat {
        let mut c = Mat::zeros(self.n, b.m);
        for i in 0..self.n {
            for k in 0..self.m {
                let aik = self.at(i, k);
                if aik == zero() {
                    continue;
                }
                for j in 0..b.m {
                    c.add(i, j, aik * b.at(k, j));
                }
            }
        }
        c
    }
    fn scale_rows(&self, d: &[Dd]) -> Mat {
        let mut c = self.clone();
        for i in 0..self.n {
            for j in 0..self.m {
                c.set(i, j, d[i] * self.at(i, j));
            }
        }
        c
    }
}

/// Solves `A x = b` by Gaussian elimination with partial pivoting (`None` if singular).
fn solve(mut a: Mat, mut b: Vec<Dd>) -> Option<Vec<Dd>> {
    let n = a.n;
    let abs = |x: Dd| if x < zero() { -x } else { x };
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| abs(a.at(i, c)).partial_cmp(abs(a.at(j, c))).unwrap())?;
        if a.at(p, c) == zero() {
            return None;
        }
        if p != c {
            for j in 0..n {
                let (x, y) = (a.at(c, j), a.at(p, j));
                a.set(c, j, y);
                a.set(p, j, x);
            }
            b.swap(c, p);
        }
        let piv = a.at(c, c);
        for i in c + 1..n {
            let f = a.at(i, c) / piv;
            if f == zero() {
                continue;
            }
            for j in c..n {
                let v = a.at(i, j) - f * a.at(c, j);
                a.set(i, j, v);
            }
            let v = b[i] - f * b[c];
            b[i] = v;
        }
    }
    let mut x = vec![zero(); n];
    for i in (0..n).rev() {
        let mut s = b[i];
        for j in i + 1..n {
            s -= a.at(i, j) * x[j];
        }
        x[i] = s / a.at(i, i);
    }
    Some(x)
}

/// The optimum of a [`SeriesQp`]: rounded, and in double-double.
pub struct Optimum {
    /// Rounded to double.
    pub f: Vec<f64>,
    exact: Vec<Dd>,
}

/// The smoothing problem on a series, in the field's units: `J(f) = Σ_t γ_t fᵀ Q_{k_t} f + γD Σ
/// M_ii (f_i − h_i)²` with `Q_1 = K`, `Q_k = K (M⁻¹K)^{k−1}` (linear elements on the
/// coordinates, lumped mass), kept samples fixed at `h`, `f_j − f_i ≥ ε` along every edge
/// oriented from each kept minimum up to its neighbouring kept maxima (and from a kept
/// extremum to the free end beyond it), free ends inside `[min h, max h]`.
pub struct SeriesQp {
    n: usize,
    h: Vec<f64>,
    q: Mat,
    mass: Vec<f64>,
    gd: f64,
    fixed: Vec<bool>,
    /// `(i, j)`: `f_j − f_i ≥ ε`.
    rows: Vec<(usize, usize)>,
    eps: f64,
    /// `(v, bound, upper)`.
    bounds: Vec<(usize, f64, bool)>,
}

impl SeriesQp {
    /// `minima` and `maxima`: the kept extrema (sample indices); `terms`: `(order, γ)`.
    pub fn new(
        x: &[f64],
        h: &[f64],
        minima: &[usize],
        maxima: &[usize],
        terms: &[(u8, f64)],
        gd: f64,
        eps: f64,
    ) -> SeriesQp {
        let n = x.len();
        let mut k = Mat::zeros(n, n);
        let mut mass = vec![0.0; n];
        for i in 0..n - 1 {
            let w = dd(1.0) / (dd(x[i + 1]) - dd(x[i]));
            k.add(i, i, w);
            k.add(i + 1, i + 1, w);
            k.add(i, i + 1, -w);
            k.add(i + 1, i, -w);
            mass[i] += 0.5 * (x[i + 1] - x[i]);
            mass[i + 1] += 0.5 * (x[i + 1] - x[i]);
        }
        let minv: Vec<Dd> = mass.iter().map(|&m| dd(1.0) / dd(m)).collect();
        let mut q = Mat::zeros(n, n);
        for &(order, gamma) in terms {
            let mut qk = k.clone();
            for _ in 1..order {
                qk = qk.mul(&k.scale_rows(&minv));
            }
            for (a, b) in q.a.iter_mut().zip(&qk.a) {
                *a += dd(gamma) * *b;
            }
        }
        let mut kept: Vec<(usize, bool)> =
            minima.iter().map(|&i| (i, false)).chain(maxima.iter().map(|&i| (i, true))).collect();
        kept.sort_unstable();
        let mut fixed = vec![false; n];
        for &(i, _) in &kept {
            fixed[i] = true;
        }
        // orientation: up towards each kept maximum, down towards each kept minimum
        let mut rows = Vec::new();
        let (first, first_max) = kept[0];
        for i in 0..first {
            // beyond a kept maximum the free end descends (its value rises towards the maximum)
            rows.push(if first_max { (i, i + 1) } else { (i + 1, i) });
        }
        for w in kept.windows(2) {
            let ((a, _), (b, b_max)) = (w[0], w[1]);
            for i in a..b {
                rows.push(if b_max { (i, i + 1) } else { (i + 1, i) });
            }
        }
        let (last, last_max) = kept[kept.len() - 1];
        for i in last..n - 1 {
            rows.push(if last_max { (i + 1, i) } else { (i, i + 1) });
        }
        let (lo, hi) = h.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        let mut bounds = Vec::new();
        if first > 0 {
            bounds.push(if first_max { (0, lo, false) } else { (0, hi, true) });
        }
        if last + 1 < n {
            bounds.push(if last_max { (n - 1, lo, false) } else { (n - 1, hi, true) });
        }
        SeriesQp { n, h: h.to_vec(), q, mass, gd, fixed, rows, eps, bounds }
    }

    /// `J(f)`, rounded.
    pub fn objective(&self, f: &[f64]) -> f64 {
        f64_of(self.objective_dd(&f.iter().map(|&v| dd(v)).collect::<Vec<_>>()))
    }

    /// `J(f) − J*` for the optimum `best` of [`SeriesQp::solve`], the difference taken in
    /// double-double at the optimum's own double-double values.
    pub fn excess(&self, f: &[f64], best: &Optimum) -> f64 {
        let f: Vec<Dd> = f.iter().map(|&v| dd(v)).collect();
        f64_of(self.objective_dd(&f) - self.objective_dd(&best.exact))
    }

    fn objective_dd(&self, f: &[Dd]) -> Dd {
        let mut e = zero();
        for i in 0..self.n {
            let mut row = zero();
            for j in 0..self.n {
                row += self.q.at(i, j) * f[j];
            }
            e += f[i] * row;
            let d = f[i] - dd(self.h[i]);
            e += dd(self.gd * self.mass[i]) * d * d;
        }
        e
    }

    /// The data term `γD Σ M_ii (f_i − h_i)²`.
    pub fn data_term(&self, f: &[f64]) -> f64 {
        (0..self.n).map(|i| self.gd * self.mass[i] * (f[i] - self.h[i]).powi(2)).sum()
    }

    /// `‖f − g‖_M`.
    pub fn mass_distance(&self, f: &[f64], g: &[f64]) -> f64 {
        (0..self.n).map(|i| self.mass[i] * (f[i] - g[i]).powi(2)).sum::<f64>().sqrt()
    }

    /// Whether `f` meets every row and bound (exactly) and the fixed values.
    pub fn feasible(&self, f: &[f64]) -> bool {
        self.rows.iter().all(|&(i, j)| dd(f[j]) - dd(f[i]) - dd(self.eps) >= zero())
            && self.bounds.iter().all(|&(v, b, up)| if up { f[v] <= b } else { f[v] >= b })
            && (0..self.n).all(|i| !self.fixed[i] || f[i] == self.h[i])
    }

    /// The optimum by a primal active-set method in double-double, from the feasible `start`
    /// (fixed samples at their values). Panics if it does not end on the KKT conditions.
    pub fn solve(&self, start: &[f64]) -> Optimum {
        assert!(self.feasible(start), "the start is not feasible");
        let free: Vec<usize> = (0..self.n).filter(|&i| !self.fixed[i]).collect();
        let nf = free.len();
        let mut slot = vec![usize::MAX; self.n];
        for (k, &i) in free.iter().enumerate() {
            slot[i] = k;
        }
        // constraints a·x ≤ b on the free variables (fixed values moved to b)
        let mut cons: Vec<(Vec<(usize, f64)>, Dd)> = Vec::new();
        for &(i, j) in &self.rows {
            // f_i − f_j ≤ −ε
            let mut a = Vec::new();
            let mut b = -dd(self.eps);
            for (v, s) in [(i, 1.0), (j, -1.0)] {
                if self.fixed[v] {
                    b -= dd(s * self.h[v]);
                } else {
                    a.push((slot[v], s));
                }
            }
            if !a.is_empty() {
                cons.push((a, b));
            }
        }
        for &(v, bound, up) in &self.bounds {
            if !self.fixed[v] {
                cons.push(if up { (vec![(slot[v], 1.0)], dd(bound)) } else { (vec![(slot[v], -1.0)], -dd(bound)) });
            }
        }
        // Hessian H = 2(Q + γD M) and linear term c on the free block
        let mut hm = Mat::zeros(nf, nf);
        let mut c = vec![zero(); nf];
        for (a, &i) in free.iter().enumerate() {
            for j in 0..self.n {
                let v = dd(2.0) * self.q.at(i, j);
                if self.fixed[j] {
                    c[a] += v * dd(self.h[j]);
                } else {
                    hm.add(a, slot[j], v);
                }
            }
            hm.add(a, a, dd(2.0 * self.gd * self.mass[i]));
            c[a] -= dd(2.0 * self.gd * self.mass[i] * self.h[i]);
        }
        let ax = |a: &[(usize, f64)], x: &[Dd]| a.iter().fold(zero(), |s, &(k, v)| s + dd(v) * x[k]);
        let mut x: Vec<Dd> = free.iter().map(|&i| dd(start[i])).collect();
        let tiny = dd(1e-28);
        let mut work: Vec<usize> = (0..cons.len()).filter(|&r| cons[r].1 - ax(&cons[r].0, &x) <= tiny).collect();
        for _ in 0..10 * (nf + cons.len()) {
            // the equality-constrained step: [H Aᵀ; A 0] [p; λ] = [−(Hx + c); 0]
            let w = work.len();
            let mut kkt = Mat::zeros(nf + w, nf + w);
            let mut rhs = vec![zero(); nf + w];
            for a in 0..nf {
                let mut g = c[a];
                for b in 0..nf {
                    kkt.set(a, b, hm.at(a, b));
                    g += hm.at(a, b) * x[b];
                }
                rhs[a] = -g;
            }
            for (r, &ci) in work.iter().enumerate() {
                for &(k, v) in &cons[ci].0 {
                    kkt.set(nf + r, k, dd(v));
                    kkt.set(k, nf + r, dd(v));
                }
            }
            let sol = solve(kkt, rhs).expect("a regular KKT system");
            let (p, lambda) = sol.split_at(nf);
            let pmax = p.iter().fold(0.0f64, |m, v| m.max(f64_of(*v).abs()));
            let xmax = x.iter().fold(1.0f64, |m, v| m.max(f64_of(*v).abs()));
            if pmax <= 1e-26 * xmax {
                // stationary on the working set: optimal if every multiplier is ≥ 0
                match (0..w).min_by(|&a, &b| lambda[a].partial_cmp(lambda[b]).unwrap()) {
                    Some(r) if lambda[r] < dd(-1e-24) => {
                        work.remove(r);
                        continue;
                    }
                    _ => {
                        let mut exact: Vec<Dd> = start.iter().map(|&v| dd(v)).collect();
                        for (k, &i) in free.iter().enumerate() {
                            exact[i] = x[k];
                        }
                        return Optimum { f: exact.iter().map(|&v| f64_of(v)).collect(), exact };
                    }
                }
            }
            // the longest step along p that keeps every other row
            let mut alpha = dd(1.0);
            let mut blocking = None;
            for (r, (a, b)) in cons.iter().enumerate() {
                if work.contains(&r) {
                    continue;
                }
                let ap = ax(a, p);
                if ap > zero() {
                    let t = (*b - ax(a, &x)) / ap;
                    if t < alpha {
                        alpha = t;
                        blocking = Some(r);
                    }
                }
            }
            for k in 0..nf {
                x[k] += alpha * p[k];
            }
            if let Some(r) = blocking {
                work.push(r);
            }
        }
        panic!("the active-set method did not end");
    }
}
