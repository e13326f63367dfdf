//! The QP's matrix for an energy of one term of order 2, `P = c·K D M D K + diag(data)` (`D =
//! M⁻¹` off the sharp vertices, 0 at them), made one column at a time instead of stored.
//!
//! A volume's bilaplacian stores 25 entries a column (408 bytes a voxel with its indices: 850
//! MB at 128³, 6.8 GB at 256³), and the active-set iteration, which makes its own forms of P
//! once, does not read it again: held through the solve it was 42 % of the run's heap. Each
//! column here is summed in the order [`super::polyharmonic_products`] sums it and then scaled
//! and shifted as [`super::plus_diagonal`] does, so every entry is the same bits as the
//! assembled matrix's (tested).

use super::polyharmonic::Energy;
use super::sparse::Sparse;

/// Items (columns, or rows made from them) per block of [`Blocks`]: on 2 threads at 128³ 2.1
/// million columns in 128 rounds of two blocks, each block's rows and values 3 MB. At 2¹⁶ a
/// block's buffers, grown by doubling, were 34 MB a thread, and at 64³ the report's passes
/// set the run's heap peak (188 against 142 MB during the solve).
pub const COLUMN_BLOCK: usize = 1 << 13;

/// `P = c·K D M D K + diag(data)`, its columns made as they are read.
#[derive(Clone, Debug)]
pub struct BilaplacianColumns<'a> {
    k: &'a Sparse,
    m: &'a [f64],
    /// `1 / m`, 0 at sharp vertices.
    d: Vec<f64>,
    /// The term's weight times its scale.
    c: f64,
    data: Vec<f64>,
}

/// A column's rows (increasing) and values, and the workspace that makes them.
#[derive(Clone, Debug, Default)]
pub struct Column {
    /// Row indices, increasing.
    pub rows: Vec<usize>,
    /// The entries at `rows`.
    pub vals: Vec<f64>,
    work: Vec<f64>,
    /// The call that last saw each row (so that no mark needs clearing between columns).
    mark: Vec<u32>,
    calls: u32,
}

impl<'a> BilaplacianColumns<'a> {
    /// The matrix of `energy` with term scales `scale` on stiffness `k` and lumped mass `m`,
    /// plus `diag(data)`, if the energy has exactly one term of non-zero weight and it is of
    /// order 2 (else `None`: the matrix is assembled). Also `None` when a column of `k` lacks
    /// its diagonal entry or the vertices do not fit the workspace's 32-bit marks.
    #[must_use]
    pub fn new(k: &'a Sparse, m: &'a [f64], energy: &Energy, scale: &[f64], data: &[f64]) -> Option<Self> {
        let n = k.nrows();
        if m.len() != n || data.len() != n || scale.len() != energy.terms.len() || n >= u32::MAX as usize {
            return None;
        }
        let mut terms = energy.terms.iter().zip(scale).filter(|(t, s)| t.1 * **s != 0.0);
        let (&(order, w), &s) = terms.next()?;
        if order != 2 || terms.next().is_some() {
            return None;
        }
        let (cp, ri) = (k.symbolic().col_ptr(), k.symbolic().row_idx());
        if !(0..n).all(|j| ri[cp[j]..cp[j + 1]].binary_search(&j).is_ok()) {
            return None;
        }
        let mut d: Vec<f64> = m.iter().map(|x| 1.0 / x).collect();
        for &v in &energy.sharp {
            d[v] = 0.0;
        }
        Some(BilaplacianColumns { k, m, d, c: w * s, data: data.to_vec() })
    }

    /// Order of the matrix.
    #[must_use]
    pub fn n(&self) -> usize {
        self.d.len()
    }

    /// The data diagonal.
    #[must_use]
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// A workspace for [`Self::column`] (12 bytes a vertex; any column may be made in it any
    /// number of times, in any order).
    #[must_use]
    pub fn workspace(&self) -> Column {
        Column { rows: Vec::new(), vals: Vec::new(), work: vec![0.0; self.n()], mark: vec![0; self.n()], calls: 0 }
    }

    /// Column `j` into `out.rows` and `out.vals`.
    pub fn column(&self, j: usize, out: &mut Column) {
        let (cp, ri, v) = (self.k.symbolic().col_ptr(), self.k.symbolic().row_idx(), self.k.val());
        let (d, m) = (&self.d, self.m);
        // a column made twice in one workspace must not find its own marks
        out.calls = out.calls.wrapping_add(1);
        if out.calls == 0 {
            out.mark.iter_mut().for_each(|m| *m = 0);
            out.calls = 1;
        }
        let stamp = out.calls;
        out.rows.clear();
        out.vals.clear();
        for p in cp[j]..cp[j + 1] {
            let kk = ri[p];
            // K's exact zeros off the diagonal add nothing to the products (they are skipped)
            if v[p] == 0.0 && kk != j {
                continue;
            }
            let b = (v[p] * d[kk]) * m[kk];
            for q in cp[kk]..cp[kk + 1] {
                let i = ri[q];
                if v[q] == 0.0 && i != kk {
                    continue;
                }
                if out.mark[i] != stamp {
                    out.mark[i] = stamp;
                    out.work[i] = 0.0;
                    out.rows.push(i);
                }
                out.work[i] += (v[q] * d[kk]) * b;
            }
        }
        out.rows.sort_unstable();
        for &i in &out.rows {
            out.vals.push(self.finish(i, j, out.work[i]));
        }
    }

    /// `visit(i)` for every row `i` of column `j`'s pattern (the rows [`Self::column`] makes,
    /// some more than once), its values not made.
    pub fn pattern_rows(&self, j: usize, mut visit: impl FnMut(usize)) {
        let (cp, ri, v) = (self.k.symbolic().col_ptr(), self.k.symbolic().row_idx(), self.k.val());
        for p in cp[j]..cp[j + 1] {
            let kk = ri[p];
            if v[p] == 0.0 && kk != j {
                continue;
            }
            for q in cp[kk]..cp[kk + 1] {
                let i = ri[q];
                if v[q] == 0.0 && i != kk {
                    continue;
                }
                visit(i);
            }
        }
    }

    /// The entry at row `i` of column `j` (`None` outside the pattern): the same sum as
    /// [`Self::column`]'s, term by term.
    #[must_use]
    pub fn entry(&self, i: usize, j: usize) -> Option<f64> {
        let (cp, ri, v) = (self.k.symbolic().col_ptr(), self.k.symbolic().row_idx(), self.k.val());
        let (d, m) = (&self.d, self.m);
        let mut sum = 0.0;
        let mut found = false;
        for p in cp[j]..cp[j + 1] {
            let kk = ri[p];
            if v[p] == 0.0 && kk != j {
                continue;
            }
            let Ok(at) = ri[cp[kk]..cp[kk + 1]].binary_search(&i) else {
                continue;
            };
            let q = cp[kk] + at;
            if v[q] == 0.0 && i != kk {
                continue;
            }
            let b = (v[p] * d[kk]) * m[kk];
            found = true;
            sum += (v[q] * d[kk]) * b;
        }
        found.then(|| self.finish(i, j, sum))
    }

    /// An upper bound on the stored entries of all columns: the pushes their sums take (each
    /// column's entries at most the terms it sums), `Σ_k |column k of K|²`.
    #[must_use]
    pub fn pushes_at_most(&self) -> usize {
        let cp = self.k.symbolic().col_ptr();
        (0..self.n()).map(|k| (cp[k + 1] - cp[k]).pow(2)).sum()
    }

    /// Items `0..n` made by `make(item, work, rows, values)` (appending the item's output) in
    /// blocks on up to the cap's threads, read in increasing order by [`Blocks::item`]: the same
    /// outputs as made one after the other, each thread with its own workspace (12 bytes a
    /// vertex).
    pub fn blocks<F>(&self, n: usize, make: F) -> Blocks<'_, 'a, F>
    where
        F: Fn(usize, &mut Column, &mut Vec<usize>, &mut Vec<f64>) + Sync,
    {
        let threads = if n >= 2 * COLUMN_BLOCK { crate::parallel::threads() } else { 1 };
        let buffers = (0..threads)
            .map(|_| Buffer {
                first: 0,
                end: 0,
                start: Vec::new(),
                rows: Vec::new(),
                vals: Vec::new(),
                work: self.workspace(),
            })
            .collect();
        Blocks { _columns: self, make, n, buffers, round_end: 0 }
    }

    /// `visit(j, rows, values)` for every column `j` in order, the columns made in
    /// [`Self::blocks`].
    pub fn for_each_column(&self, mut visit: impl FnMut(usize, &[usize], &[f64])) {
        let mut blocks = self.blocks(self.n(), |j, work, rows, vals| {
            self.column(j, work);
            rows.extend_from_slice(&work.rows);
            vals.extend_from_slice(&work.vals);
        });
        for j in 0..self.n() {
            let (rows, vals) = blocks.item(j);
            visit(j, rows, vals);
        }
    }

    /// The diagonal entry of column `j`.
    #[must_use]
    pub fn diagonal(&self, j: usize) -> f64 {
        self.entry(j, j).expect("every column holds its diagonal (checked when made)")
    }

    /// A column's sum as the assembled matrix stores it: added onto a zeroed value, scaled by
    /// `c` (plus the zero diagonal of that scaling), then the data diagonal added.
    #[inline]
    fn finish(&self, i: usize, j: usize, sum: f64) -> f64 {
        let mut value = 0.0;
        value += sum;
        let value = self.c * value + 0.0;
        if i == j {
            value + self.data[j]
        } else {
            value
        }
    }

    /// `w += P v` in two passes over K, `c·K (d∘d∘m∘(K v)) + data∘v` (on up to the cap's
    /// threads): the matrix's product up to rounding, for estimates (the condition), not for
    /// the certificate.
    /// `t` is the passes' intermediate vector (resized to the order).
    pub fn add_product(&self, v: &[f64], w: &mut [f64], t: &mut Vec<f64>) {
        let (cp, ri, kv) = (self.k.symbolic().col_ptr(), self.k.symbolic().row_idx(), self.k.val());
        // K is symmetric: column i is row i
        let row = |i: usize, x: &[f64]| -> f64 { (cp[i]..cp[i + 1]).map(|p| kv[p] * x[ri[p]]).sum() };
        t.resize(self.n(), 0.0);
        crate::parallel::split_mut(t, |offset, t| {
            for (ti, i) in t.iter_mut().zip(offset..) {
                *ti = row(i, v) * (self.d[i] * self.d[i] * self.m[i] * self.c);
            }
        });
        crate::parallel::split_mut(w, |offset, w| {
            for (wi, i) in w.iter_mut().zip(offset..) {
                *wi += row(i, t) + self.data[i] * v[i];
            }
        });
    }
}

/// A thread's block of made items.
struct Buffer {
    first: usize,
    end: usize,
    /// Where each item's output starts in `rows` and `vals`.
    start: Vec<usize>,
    rows: Vec<usize>,
    vals: Vec<f64>,
    work: Column,
}

/// Items made in blocks ([`BilaplacianColumns::blocks`]), read in increasing order.
pub struct Blocks<'c, 'a, F> {
    _columns: &'c BilaplacianColumns<'a>,
    make: F,
    n: usize,
    buffers: Vec<Buffer>,
    /// The end of the items made so far.
    round_end: usize,
}

impl<F> Blocks<'_, '_, F>
where
    F: Fn(usize, &mut Column, &mut Vec<usize>, &mut Vec<f64>) + Sync,
{
    /// Item `i`'s output (`i` at least the last item read: the next round of blocks is made
    /// when `i` passes this one's).
    ///
    /// # Panics
    /// If `i` is below the round's items or not below `n`.
    pub fn item(&mut self, i: usize) -> (&[usize], &[f64]) {
        assert!(i < self.n, "item {i} of {}", self.n);
        while i >= self.round_end {
            let mut next = self.round_end;
            for b in &mut self.buffers {
                b.first = next;
                b.end = (next + COLUMN_BLOCK).min(self.n);
                next = b.end;
            }
            self.round_end = next;
            let make = &self.make;
            crate::parallel::for_each_mut(&mut self.buffers, 1, |b| {
                b.start.clear();
                b.rows.clear();
                b.vals.clear();
                for item in b.first..b.end {
                    b.start.push(b.rows.len());
                    make(item, &mut b.work, &mut b.rows, &mut b.vals);
                }
                b.start.push(b.rows.len());
            });
        }
        let b = self.buffers.iter().find(|b| (b.first..b.end).contains(&i)).expect("item in this round");
        let k = i - b.first;
        let range = b.start[k]..b.start[k + 1];
        (&b.rows[range.clone()], &b.vals[range])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::operators::{
        grid_mass, grid_stiffness, plus_diagonal, polyharmonic_products, volume_mass, volume_stiffness,
    };

    /// Every column and entry the same bits as the assembled `plus_diagonal(products, data)`,
    /// on a grid (whose stiffness holds exact zeros on its diagonal edges), a volume and a
    /// grid with sharp vertices; the fast product agrees with the stored one to rounding.
    #[test]
    fn columns_and_entries_are_the_assembled_matrix_s_bits() {
        let grid = crate::domain::Grid2d::with_geometry(9, 7, [1.0, 0.5], [0.0; 2]).unwrap();
        let volume = crate::domain::Grid3d::with_geometry([5, 4, 6], [1.0, 2.0, 0.5], [0.0; 3]).unwrap();
        let (gk, gm) = (grid_stiffness(&grid), grid_mass(&grid));
        let (vk, vm) = (volume_stiffness(&volume), volume_mass(&volume));
        let mut sharp = Energy::order(2);
        sharp.sharp = vec![3, 20, 40];
        for (k, m, energy) in [(&gk, &gm, Energy::order(2)), (&vk, &vm, Energy::order(2)), (&gk, &gm, sharp)] {
            let n = m.len();
            let data: Vec<f64> = (0..n).map(|i| 0.1 + (i % 5) as f64 * 0.03).collect();
            let scale = [2.7];
            let stored = plus_diagonal(polyharmonic_products(k, m, &energy, &scale), &data);
            let gen = BilaplacianColumns::new(k, m, &energy, &scale, &data).expect("one term of order 2");
            let (cp, ri, v) = (stored.symbolic().col_ptr(), stored.symbolic().row_idx(), stored.val());
            let mut col = gen.workspace();
            for j in 0..n {
                gen.column(j, &mut col);
                assert_eq!(col.rows, &ri[cp[j]..cp[j + 1]], "column {j}'s rows");
                let mut pattern = Vec::new();
                gen.pattern_rows(j, |i| pattern.push(i));
                pattern.sort_unstable();
                pattern.dedup();
                assert_eq!(pattern, col.rows, "column {j}'s pattern");
                let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&col.vals), bits(&v[cp[j]..cp[j + 1]]), "column {j}'s values");
                for (&i, &value) in col.rows.iter().zip(&col.vals) {
                    assert_eq!(gen.entry(i, j).map(f64::to_bits), Some(value.to_bits()));
                }
            }
            // made again, out of order, in the same workspace: the same column
            for j in [n / 2, 0, n / 2] {
                gen.column(j, &mut col);
                assert_eq!(col.rows, &ri[cp[j]..cp[j + 1]], "column {j} made again");
                assert_eq!(col.vals, &v[cp[j]..cp[j + 1]]);
            }
            assert_eq!(gen.entry(0, n - 1), None);
            let x: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.4).collect();
            let mut fast = vec![0.0; n];
            gen.add_product(&x, &mut fast, &mut Vec::new());
            let exact = crate::operators::sparse::mul_vec(&stored, &x);
            let size = exact.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (a, b) in fast.iter().zip(&exact) {
                assert!((a - b).abs() <= 1e-12 * size, "{a} against {b}");
            }
        }
        // a blend, or one term of another order, is assembled
        let e = Energy { terms: vec![(1, 0.5), (2, 1.0)], sharp: vec![] };
        assert!(BilaplacianColumns::new(&gk, &gm, &e, &[1.0, 1.0], &gm).is_none());
        assert!(BilaplacianColumns::new(&gk, &gm, &Energy::order(3), &[1.0], &gm).is_none());
        // a zero weight leaves the other term alone
        assert!(BilaplacianColumns::new(&gk, &gm, &e, &[0.0, 1.0], &gm).is_some());
    }

    /// What the report reads of P — the certificate's gap (in double-double), the energy and
    /// the smoothness — is the same bits from made columns as from the stored matrix, and the
    /// condition estimate (by the two-pass product) the same to rounding.
    #[test]
    fn the_report_reads_the_same_from_made_columns() {
        use crate::solve::{condition_estimate, optimality, MonotoneQp, Quadratic};
        let volume = crate::domain::Grid3d::with_geometry([9, 8, 7], [1.0, 1.0, 1.0], [0.0; 3]).unwrap();
        let (k, m) = (volume_stiffness(&volume), volume_mass(&volume));
        let n = m.len();
        let data: Vec<f64> = m.iter().map(|v| 0.7 * v).collect();
        let energy = Energy::order(2);
        let stored = plus_diagonal(polyharmonic_products(&k, &m, &energy, &[3.0]), &data);
        let made = BilaplacianColumns::new(&k, &m, &energy, &[3.0], &data).unwrap();
        let q: Vec<f64> = (0..n).map(|i| -data[i] * ((i % 13) as f64 * 0.1)).collect();
        let mut fixed = vec![None; n];
        fixed[17] = Some(0.5);
        let edges: Vec<(usize, usize)> = (0..n - 1).filter(|i| i % 9 != 8).map(|i| (i, i + 1)).collect();
        let f: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3 + ((i * 31) % 7) as f64 * 1e-4).collect();
        let z: Vec<f64> = (0..edges.len()).map(|k| ((k * 17) % 5) as f64 * 0.01).collect();
        let qp = |p: Quadratic<'_>| -> crate::solve::Optimality {
            let problem = MonotoneQp {
                p,
                q: &q,
                fixed: &fixed,
                edges: &edges,
                margin: 1e-4,
                bounds: &[],
                data: Some(&data),
                hint: None,
                factor: None,
                condition: None,
                second_order: None,
            };
            optimality(&problem, &f, &z, None)
        };
        let (a, b) = (qp(Quadratic::Stored(&stored)), qp(Quadratic::Columns(&made)));
        assert_eq!(a.gap.to_bits(), b.gap.to_bits());
        assert_eq!(a.energy.to_bits(), b.energy.to_bits());
        assert_eq!(a.dual_residual.to_bits(), b.dual_residual.to_bits());
        let (sa, sb) = (
            Quadratic::Stored(&stored).quadratic_form_without_diagonal(&data, &f),
            Quadratic::Columns(&made).quadratic_form_without_diagonal(&data, &f),
        );
        assert_eq!(sa.to_bits(), sb.to_bits());
        assert_eq!(sa.to_bits(), crate::operators::quadratic_form_without_diagonal(&stored, &data, &f).to_bits());
        // the gap's pass makes the same form
        assert_eq!(
            (a.smoothness.map(f64::to_bits), b.smoothness.map(f64::to_bits)),
            (Some(sa.to_bits()), Some(sa.to_bits()))
        );
        let (ca, cb) = (
            condition_estimate(Quadratic::Stored(&stored), &data, &fixed).unwrap(),
            condition_estimate(Quadratic::Columns(&made), &data, &fixed).unwrap(),
        );
        assert!((ca - cb).abs() <= 1e-9 * ca, "{ca} against {cb}");
    }
}
