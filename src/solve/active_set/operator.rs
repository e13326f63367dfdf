//! P as the iteration multiplies by it: rows that repeat one another stored once.
//!
//! On a grid or a volume almost every row of the energy is the same stencil — the same
//! offsets from the row to its columns and the same values in the same order — so P is kept
//! as a class per row and one table of offsets and values per class (586 classes for the
//! 262,131 rows of the 64³ bench volume). A product reads the vector, a class id and a table
//! that stays in cache instead of twelve bytes per stored entry, and sums consecutive rows of
//! one class side by side: one running sum per row over 25 entries had made the product wait
//! on its additions (docs/performance.md §3). Each row's sum runs over its entries in
//! the order compressed rows would hold them, so the products are those of the compressed
//! rows bit for bit; on a mesh, where rows rarely repeat, each row is its own class.

use crate::operators::{BilaplacianColumns, Sparse};
use crate::solve::Quadratic;
use std::collections::HashMap;

/// Rows of one class a product sums side by side.
const LANES: usize = 8;

/// A diagonal and a vector whose product a row's sum is given: `(d, v)` for `+ d ∘ v`.
type Plus<'a> = (&'a [f64], &'a [f64]);

/// Rows below which a product stays on one thread.
const PARALLEL_ROWS: usize = 20_000;

/// P (both triangles, exact zeros dropped), one class per row.
pub(super) struct RowClasses {
    /// Each row's class.
    class: Vec<u32>,
    /// Per class, where its entries start in `offset` and `value` (one more at the end).
    start: Vec<usize>,
    /// Column minus row of each class entry.
    offset: Vec<i32>,
    value: Vec<f64>,
    /// Per class its diagonal entry (its entries at offset 0 summed in order).
    diagonal: Vec<f64>,
}

impl RowClasses {
    /// From P's upper triangle as triplets sorted by column, then row (as the reduced QP
    /// stores them; errs otherwise): row `i`'s entries are column `i`'s triplets (columns up to
    /// `i`) then its own triplets in later columns, in increasing column order.
    #[cfg(test)]
    pub(super) fn from_upper(n: usize, p: &[(usize, usize, f64)]) -> Result<RowClasses, &'static str> {
        if p.len() > u32::MAX as usize {
            return Err("too many variables for the active-set iteration");
        }
        if p.windows(2).any(|w| (w[0].1, w[0].0) > (w[1].1, w[1].0)) || p.iter().any(|&(i, j, _)| i > j || j >= n) {
            return Err("P's triplets are not an upper triangle sorted by column");
        }
        // where each column's triplets start; per row its triplets in later columns
        let mut column = vec![0usize; n + 1];
        let mut later = vec![0usize; n + 1];
        for &(i, j, _) in p {
            column[j + 1] += 1;
            if i != j {
                later[i + 1] += 1;
            }
        }
        for k in 0..n {
            column[k + 1] += column[k];
            later[k + 1] += later[k];
        }
        let mut in_row = vec![0u32; later[n]];
        let mut at = later.clone();
        for (t, &(i, j, _)) in p.iter().enumerate() {
            if i != j {
                in_row[at[i]] = t as u32;
                at[i] += 1;
            }
        }
        drop(at);
        Self::from_rows(n, |i, entry| {
            for &(r, _, v) in &p[column[i]..column[i + 1]] {
                entry(r, v);
            }
            for &t in &in_row[later[i]..later[i + 1]] {
                let (_, c, v) = p[t as usize];
                entry(c, v);
            }
            Ok(())
        })
    }

    /// From P as stored whole (both triangles, a symmetric pattern, rows sorted in each
    /// column), restricted to the free variables (`slot[v]` is `v`'s index among them,
    /// `usize::MAX` when fixed) and divided by `scale`: the reduced QP's P without its
    /// triplets, each entry taken from the upper triangle (`P_ij` with `i ≤ j` from column `j`)
    /// as the triplets take them, so the same bits. Row `u`'s entries below the diagonal are
    /// column `u`'s, those above are in the columns its own entries below the diagonal name
    /// (the pattern is symmetric), each found at that column's cursor as rows advance.
    /// Made columns ([`Quadratic::Columns`]) give row `u` from column `u`'s own entries below
    /// the diagonal and, above it, from the entry of each later column at row `u`, made alone:
    /// the same values.
    pub(super) fn from_columns(
        p: Quadratic<'_>,
        free: &[usize],
        slot: &[usize],
        scale: f64,
    ) -> Result<RowClasses, &'static str> {
        let p = match p {
            Quadratic::Stored(p) => p,
            Quadratic::Columns(c) => return Self::from_made_columns(c, free, slot, scale),
        };
        let (cp, ri, val) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
        let mut cursor: Vec<usize> = cp[..p.ncols()].to_vec();
        Self::from_rows(free.len(), |u, entry| {
            let j = free[u];
            let column = cp[j]..cp[j + 1];
            for k in column.clone() {
                let s = slot[ri[k]];
                if s != usize::MAX && s <= u {
                    entry(s, val[k] / scale);
                }
            }
            for k in column {
                let c = ri[k];
                let s = slot[c];
                if s == usize::MAX || s <= u {
                    continue;
                }
                // column c's entry at row j: its rows before j are fixed or passed already
                let at = &mut cursor[c];
                while *at < cp[c + 1] && ri[*at] < j {
                    *at += 1;
                }
                if *at == cp[c + 1] || ri[*at] != j {
                    return Err("P's pattern is not symmetric");
                }
                entry(s, val[*at] / scale);
                *at += 1;
            }
            Ok(())
        })
    }

    /// [`Self::from_columns`] for made columns: each row's entries (as slots, divided by
    /// `scale`) made in blocks on up to the cap's threads, an entry outside the pattern as NaN.
    fn from_made_columns(
        p: &BilaplacianColumns<'_>,
        free: &[usize],
        slot: &[usize],
        scale: f64,
    ) -> Result<RowClasses, &'static str> {
        let mut blocks = p.blocks(free.len(), |u, work, cols, vals| {
            let j = free[u];
            p.column(j, work);
            for (&i, &v) in work.rows.iter().zip(&work.vals) {
                let s = slot[i];
                if s != usize::MAX && s <= u {
                    cols.push(s);
                    vals.push(v / scale);
                }
            }
            for &c in &work.rows {
                let s = slot[c];
                if s != usize::MAX && s > u {
                    cols.push(s);
                    vals.push(p.entry(j, c).map_or(f64::NAN, |v| v / scale));
                }
            }
        });
        Self::from_rows(free.len(), |u, entry| {
            let (cols, vals) = blocks.item(u);
            for (&c, &v) in cols.iter().zip(vals) {
                if v.is_nan() {
                    return Err("P's pattern is not symmetric");
                }
                entry(c, v);
            }
            Ok(())
        })
    }

    /// Row by row: `row(i, entry)` calls `entry(column, value)` for row `i`'s entries in
    /// increasing column order; exact zeros are dropped, and each row either matches an
    /// earlier class or appends its own. Errs when a column offset does not fit in 32 bits.
    fn from_rows(
        n: usize,
        mut row: impl FnMut(usize, &mut dyn FnMut(usize, f64)) -> Result<(), &'static str>,
    ) -> Result<RowClasses, &'static str> {
        if n > i32::MAX as usize {
            return Err("too many variables for the active-set iteration");
        }
        let mut class = vec![0u32; n];
        let mut start = vec![0usize];
        let (mut offset, mut value): (Vec<i32>, Vec<f64>) = (Vec::new(), Vec::new());
        let mut seen: HashMap<u64, u32> = HashMap::new();
        let (mut row_offset, mut row_value): (Vec<i32>, Vec<f64>) = (Vec::new(), Vec::new());
        for (i, class_i) in class.iter_mut().enumerate() {
            row_offset.clear();
            row_value.clear();
            row(i, &mut |c, v| {
                if v != 0.0 {
                    // |c − i| < n ≤ i32::MAX
                    row_offset.push((c as i64 - i as i64) as i32);
                    row_value.push(v);
                }
            })?;
            let key = row_hash(&row_offset, &row_value);
            let found = seen.get(&key).copied().filter(|&c| {
                let (a, b) = (start[c as usize], start[c as usize + 1]);
                offset[a..b] == row_offset[..]
                    && value[a..b].iter().zip(&row_value).all(|(x, y)| x.to_bits() == y.to_bits())
            });
            *class_i = match found {
                Some(c) => c,
                None => {
                    let c = start.len() - 1;
                    offset.extend_from_slice(&row_offset);
                    value.extend_from_slice(&row_value);
                    start.push(offset.len());
                    seen.entry(key).or_insert(c as u32);
                    c as u32
                }
            };
        }
        start.shrink_to_fit();
        offset.shrink_to_fit();
        value.shrink_to_fit();
        let diagonal =
            start.windows(2).map(|w| (w[0]..w[1]).filter(|&e| offset[e] == 0).fold(0.0, |a, e| a + value[e])).collect();
        Ok(RowClasses { class, start, offset, value, diagonal })
    }

    /// The classes (for the trace).
    pub(super) fn classes(&self) -> usize {
        self.start.len() - 1
    }

    /// The stored entries of both triangles (each row's entries, counted row by row).
    pub(super) fn entries(&self) -> usize {
        self.class.iter().map(|&c| self.start[c as usize + 1] - self.start[c as usize]).sum()
    }

    /// `P_ii`.
    pub(super) fn diagonal(&self, i: usize) -> f64 {
        self.diagonal[self.class[i] as usize]
    }

    /// Row `i`'s entries as (column, value), in the order the products sum them.
    pub(super) fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let c = self.class[i] as usize;
        let (a, b) = (self.start[c], self.start[c + 1]);
        self.offset[a..b].iter().zip(&self.value[a..b]).map(move |(&o, &v)| ((i as i64 + o as i64) as usize, v))
    }

    /// Rows `first..first + y.len()`: a run of consecutive rows of one class goes [`LANES`]
    /// rows at a time, each entry applied to all of them (their sums are independent, so
    /// they overlap in the pipeline and the loads are contiguous), each row still summed in
    /// its entries' order.
    fn rows_into(&self, first: usize, x: &[f64], plus: Option<Plus<'_>>, y: &mut [f64]) {
        let mut k = 0;
        while k < y.len() {
            let i = first + k;
            let c = self.class[i];
            let (a, b) = (self.start[c as usize], self.start[c as usize + 1]);
            let (offset, value) = (&self.offset[a..b], &self.value[a..b]);
            let mut run = 1;
            while k + run < y.len() && self.class[i + run] == c {
                run += 1;
            }
            let (run_end, lanes_end) = (k + run, k + run / LANES * LANES);
            while k < lanes_end {
                let i = first + k;
                let mut acc = [0.0; LANES];
                for (&o, &v) in offset.iter().zip(value) {
                    let from = (i as i64 + o as i64) as usize;
                    let xs: &[f64; LANES] = x[from..from + LANES].try_into().expect("LANES values");
                    for (acc, &xv) in acc.iter_mut().zip(xs) {
                        *acc += v * xv;
                    }
                }
                match plus {
                    Some((d, v)) => {
                        for (l, acc) in acc.iter().enumerate() {
                            y[k + l] = acc + d[i + l] * v[i + l];
                        }
                    }
                    None => y[k..k + LANES].copy_from_slice(&acc),
                }
                k += LANES;
            }
            while k < run_end {
                let i = first + k;
                let mut acc = 0.0;
                for (&o, &v) in offset.iter().zip(value) {
                    acc += v * x[(i as i64 + o as i64) as usize];
                }
                y[k] = match plus {
                    Some((d, v)) => acc + d[i] * v[i],
                    None => acc,
                };
                k += 1;
            }
        }
    }

    fn rows_into_split(&self, first: usize, x: &[f64], plus: Option<Plus<'_>>, y: &mut [f64]) {
        if y.len() < PARALLEL_ROWS || crate::parallel::threads() < 2 {
            return self.rows_into(first, x, plus, y);
        }
        let mid = y.len() / 2;
        let (a, b) = y.split_at_mut(mid);
        crate::parallel::join(
            || self.rows_into_split(first, x, plus, a),
            || self.rows_into_split(first + mid, x, plus, b),
        );
    }

    /// `y = P x`, the rows split between the threads the cap allows (each row's sum is the
    /// same whatever the split).
    pub(super) fn apply(&self, x: &[f64], y: &mut [f64]) {
        self.rows_into_split(0, x, None, y);
    }

    /// `y = P x + d ∘ v`, each row's sum then `d v` added, as [`RowClasses::apply`] followed by
    /// `y += d ∘ v` would give it.
    pub(super) fn apply_plus(&self, x: &[f64], plus: Plus<'_>, y: &mut [f64]) {
        self.rows_into_split(0, x, Some(plus), y);
    }
}

/// The energy's product in two passes over the stiffness `K` where it is of order 2:
/// `K (s ∘ (K x))` (P is `K diag(s) K + diag(d)`; the caller adds `d ∘ x`), 2 × 7 entries a
/// row on a volume's 7-point K instead of the bilaplacian's 25 (docs/performance.md §3).
/// The inner pass runs over every vertex (fixed ones too: their values are in q, not in x),
/// the outer one over the free variables; both are [`RowClasses`], so they sum rows side by
/// side as P's product does. The sums differ from P's by rounding.
pub(super) struct TwoPass {
    /// Row `v` (every vertex): `s_v K_vj` over the free `j` (columns in the free variables).
    inner: RowClasses,
    /// Row `u` (a free variable): `K_{free[u], v}` over every vertex `v`.
    outer: RowClasses,
    /// `s ∘ (K x)`, one a vertex.
    scratch: std::sync::Mutex<Vec<f64>>,
}

impl TwoPass {
    /// From the stiffness `k` (whole, symmetric) and the inner pass's row scales `s`, both
    /// divided by `scale` (the problem's).
    pub(super) fn new(
        k: &Sparse,
        row_scale: &[f64],
        scale: f64,
        free: &[usize],
        slot: &[usize],
    ) -> Result<TwoPass, &'static str> {
        let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
        let n_all = k.ncols();
        if row_scale.len() != n_all || slot.len() != n_all {
            return Err("the stiffness, its row scales and the free variables disagree in size");
        }
        // K is symmetric: column v is row v
        let inner = RowClasses::from_rows(n_all, |v, entry| {
            for q in cp[v]..cp[v + 1] {
                let s = slot[ri[q]];
                if s != usize::MAX {
                    entry(s, (row_scale[v] / scale) * val[q]);
                }
            }
            Ok(())
        })?;
        let outer = RowClasses::from_rows(free.len(), |u, entry| {
            let i = free[u];
            for q in cp[i]..cp[i + 1] {
                entry(ri[q], val[q]);
            }
            Ok(())
        })?;
        Ok(TwoPass { inner, outer, scratch: std::sync::Mutex::new(vec![0.0; n_all]) })
    }

    /// `y = K (s ∘ (K x)) + d ∘ x`, with `d` the data term's diagonal on the free variables.
    /// The data term's product is added to each row's sum in the outer pass.
    pub(super) fn apply(&self, x: &[f64], d: &[f64], y: &mut [f64]) {
        let mut t = self.scratch.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        self.inner.apply(x, &mut t);
        self.outer.apply_plus(&t, (d, x), y);
    }
}

/// A row's offsets and values mixed into 64 bits (FxHash's step).
fn row_hash(offset: &[i32], value: &[f64]) -> u64 {
    const K: u64 = 0x51_7c_c1_b7_27_22_0a_95;
    let mix = |h: u64, w: u64| (h.rotate_left(5) ^ w).wrapping_mul(K);
    let h = offset.iter().fold(offset.len() as u64, |h, &o| mix(h, o as u32 as u64));
    value.iter().fold(h, |h, v| mix(h, v.to_bits()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// P of a path of 6 variables with the same stencil inside: the inner rows share a class,
    /// and products and rows are those of P written out.
    #[test]
    fn repeated_rows_share_a_class_and_products_are_exact() {
        let n = 6;
        let mut p = Vec::new();
        for i in 0..n {
            p.push((i, i, if i == 0 || i == n - 1 { 1.5 } else { 2.5 }));
            if i + 1 < n {
                p.push((i, i + 1, -1.0));
            }
            if i + 2 < n {
                p.push((i, i + 2, 0.25));
            }
        }
        p.push((0, 4, 0.0));
        assert!(RowClasses::from_upper(n, &p).is_err(), "triplets out of column order");
        p.sort_by_key(|&(i, j, _)| (j, i));
        let rc = RowClasses::from_upper(n, &p).unwrap();
        // rows 0, 1, n−2, n−1 differ; rows 2 and 3 are the same stencil (the explicit zero
        // of row 0 is dropped)
        assert_eq!(rc.classes(), 5);
        let mut dense = vec![vec![0.0; n]; n];
        for &(i, j, v) in &p {
            dense[i][j] += v;
            if i != j {
                dense[j][i] += v;
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.1 * i as f64).collect();
        let mut y = vec![0.0; n];
        rc.apply(&x, &mut y);
        for i in 0..n {
            let expected: f64 = (0..n).map(|j| dense[i][j] * x[j]).sum();
            assert!((y[i] - expected).abs() <= 1e-14, "row {i}: {} against {expected}", y[i]);
            let row: Vec<(usize, f64)> = rc.row(i).collect();
            let written: Vec<(usize, f64)> = (0..n).filter(|&j| dense[i][j] != 0.0).map(|j| (j, dense[i][j])).collect();
            let mut sorted = row.clone();
            sorted.sort_by_key(|e| e.0);
            assert_eq!(sorted, written, "row {i}");
            assert_eq!(rc.diagonal(i), dense[i][i], "row {i}'s diagonal");
        }
    }

    /// From P stored whole, with variable 1 fixed and a scale: the classes and products of the
    /// reduced upper triangle's triplets, bit for bit, though the stored lower triangle differs
    /// from the upper one in its last bits; an entry whose mirror is missing is refused.
    #[test]
    fn columns_give_the_reduced_triplets_rows() {
        let n = 7;
        let mut t = Vec::new();
        for i in 0..n {
            t.push(faer::sparse::Triplet::new(i, i, 2.5 + 0.1 * i as f64));
            for (j, v) in [(i + 1, -1.0 / 3.0), (i + 2, 0.25)] {
                if j < n {
                    t.push(faer::sparse::Triplet::new(i, j, v));
                    // the lower triangle one ulp off: only the upper one may be read
                    t.push(faer::sparse::Triplet::new(j, i, f64::from_bits(v.to_bits() + 1)));
                }
            }
        }
        let p = Sparse::try_new_from_triplets(n, n, &t).unwrap();
        let free: Vec<usize> = (0..n).filter(|&v| v != 1).collect();
        let mut slot = vec![usize::MAX; n];
        free.iter().enumerate().for_each(|(k, &v)| slot[v] = k);
        let scale = 1.7;
        let (cp, ri, val) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
        let mut upper = Vec::new();
        for &j in &free {
            for k in cp[j]..cp[j + 1] {
                if slot[ri[k]] != usize::MAX && ri[k] <= j {
                    upper.push((slot[ri[k]], slot[j], val[k] / scale));
                }
            }
        }
        let (a, b) = (
            RowClasses::from_upper(free.len(), &upper).unwrap(),
            RowClasses::from_columns((&p).into(), &free, &slot, scale).unwrap(),
        );
        assert_eq!(a.classes(), b.classes());
        let x: Vec<f64> = (0..free.len()).map(|i| (i as f64 * 0.9).cos()).collect();
        let (mut ya, mut yb) = (vec![0.0; free.len()], vec![0.0; free.len()]);
        a.apply(&x, &mut ya);
        b.apply(&x, &mut yb);
        assert_eq!(ya, yb);
        for i in 0..free.len() {
            assert_eq!(a.row(i).collect::<Vec<_>>(), b.row(i).collect::<Vec<_>>(), "row {i}");
        }
        // an entry below the diagonal whose mirror is missing
        t.push(faer::sparse::Triplet::new(5, 0, 1.0));
        let lopsided = Sparse::try_new_from_triplets(n, n, &t).unwrap();
        assert!(RowClasses::from_columns((&lopsided).into(), &free, &slot, scale).is_err());
    }

    /// Made columns ([`BilaplacianColumns`]) of a volume's bilaplacian with three fixed vertices
    /// give the same classes, rows and products, bit for bit, as the assembled matrix stored:
    /// made in more than one block (each block's rows on its own thread) and on one.
    #[test]
    fn made_columns_give_the_stored_matrix_s_rows() {
        use crate::operators::{plus_diagonal, polyharmonic_products, volume_mass, volume_stiffness, Energy};
        let g = crate::domain::Grid3d::with_geometry([70, 60, 40], [1.0, 0.8, 1.3], [0.0; 3]).unwrap();
        let (k, m) = (volume_stiffness(&g), volume_mass(&g));
        let n = m.len();
        let data: Vec<f64> = m.iter().map(|v| 0.3 * v).collect();
        let energy = Energy::order(2);
        let stored = plus_diagonal(polyharmonic_products(&k, &m, &energy, &[6.0]), &data);
        let made = BilaplacianColumns::new(&k, &m, &energy, &[6.0], &data).unwrap();
        let free: Vec<usize> = (0..n).filter(|&v| ![0, 777, 90_001].contains(&v)).collect();
        let mut slot = vec![usize::MAX; n];
        free.iter().enumerate().for_each(|(k, &v)| slot[v] = k);
        let scale = 2.3;
        let a = RowClasses::from_columns((&stored).into(), &free, &slot, scale).unwrap();
        let x: Vec<f64> = (0..free.len()).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut ya = vec![0.0; free.len()];
        a.apply(&x, &mut ya);
        for threads in [1, 2] {
            let b = crate::parallel::with_threads(threads, || {
                RowClasses::from_columns(Quadratic::Columns(&made), &free, &slot, scale).unwrap()
            });
            assert_eq!(a.classes(), b.classes(), "{threads} threads");
            let mut yb = vec![0.0; free.len()];
            b.apply(&x, &mut yb);
            assert!(ya.iter().zip(&yb).all(|(a, b)| a.to_bits() == b.to_bits()), "{threads} threads");
            for i in (0..free.len()).step_by(997) {
                assert_eq!(a.row(i).collect::<Vec<_>>(), b.row(i).collect::<Vec<_>>(), "row {i}");
                assert_eq!(a.diagonal(i).to_bits(), b.diagonal(i).to_bits());
            }
        }
    }

    /// The product in two passes over a 7-point stiffness on a 12 × 6 × 5 box, with two fixed
    /// vertices and one sharp (its scale 0), against `K diag(s) K + diag(d)` written out and
    /// restricted to the free variables: the same to rounding.
    #[test]
    fn two_passes_over_k_give_the_assembled_product() {
        let (nx, ny, nz) = (12usize, 6usize, 5usize);
        let n = nx * ny * nz;
        let at = |x: usize, y: usize, z: usize| x + nx * (y + ny * z);
        let mut dense = vec![vec![0.0; n]; n];
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let i = at(x, y, z);
                    let mut nb = Vec::new();
                    if x > 0 {
                        nb.push(at(x - 1, y, z));
                    }
                    if x + 1 < nx {
                        nb.push(at(x + 1, y, z));
                    }
                    if y > 0 {
                        nb.push(at(x, y - 1, z));
                    }
                    if y + 1 < ny {
                        nb.push(at(x, y + 1, z));
                    }
                    if z > 0 {
                        nb.push(at(x, y, z - 1));
                    }
                    if z + 1 < nz {
                        nb.push(at(x, y, z + 1));
                    }
                    for &j in &nb {
                        dense[i][j] = -1.0;
                    }
                    dense[i][i] = nb.len() as f64;
                }
            }
        }
        let mut t = Vec::new();
        for (i, row) in dense.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    t.push(faer::sparse::Triplet::new(i, j, v));
                }
            }
        }
        let k = Sparse::try_new_from_triplets(n, n, &t).unwrap();
        let mass: Vec<f64> = (0..n).map(|i| if i == 7 { 1.5 } else { 1.25 }).collect();
        let sharp = at(4, 2, 1);
        let s: Vec<f64> = (0..n).map(|v| if v == sharp { 0.0 } else { 3.0 / mass[v] }).collect();
        let data: Vec<f64> = mass.iter().map(|m| 0.5 * m).collect();
        let fixed = [at(0, 0, 0), at(6, 1, 2)];
        let free: Vec<usize> = (0..n).filter(|v| !fixed.contains(v)).collect();
        let mut slot = vec![usize::MAX; n];
        free.iter().enumerate().for_each(|(k, &v)| slot[v] = k);
        let two = TwoPass::new(&k, &s, 1.0, &free, &slot).unwrap();
        let d: Vec<f64> = free.iter().map(|&v| data[v]).collect();
        // the inner rows inside the box repeat: far fewer classes than rows
        assert!(two.inner.classes() < n / 2, "{} classes", two.inner.classes());
        let x: Vec<f64> = (0..free.len()).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut y = vec![0.0; free.len()];
        two.apply(&x, &d, &mut y);
        for (u, &i) in free.iter().enumerate() {
            let mut expected = data[i] * x[u];
            for (w, &j) in free.iter().enumerate() {
                let kmk: f64 = (0..n).map(|v| dense[i][v] * s[v] * dense[v][j]).sum();
                expected += kmk * x[w];
            }
            assert!((y[u] - expected).abs() <= 1e-12 * (1.0 + expected.abs()), "row {u}: {} against {expected}", y[u]);
        }
        // sizes that disagree are refused
        assert!(TwoPass::new(&k, &s[1..], 1.0, &free, &slot).is_err());
    }
}
