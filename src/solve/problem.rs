//! The monotone QP as posed (`MonotoneQp`: energy, linear term, fixed entries, ordered pairs,
//! bounds) and as the solvers see it (`ReducedQp`: the free variables only, one row per
//! constraint).

use crate::linalg::double_double::Dd;
use crate::operators::{BilaplacianColumns, Column, Factor, Sparse};

/// A one-sided bound on one entry: `f_v ≤ value` (`upper`) or `f_v ≥ value`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    /// The entry.
    pub vertex: usize,
    /// The bound.
    pub value: f64,
    /// `f_v ≤ value` when true, `f_v ≥ value` when false.
    pub upper: bool,
}

/// The problem: `min ½ fᵀ P f + qᵀ f` s.t. `f_i = fixed_i` where given,
/// `f_j − f_i ≥ margin` for every `(i, j)` in `edges`, and the `bounds`.
pub struct MonotoneQp<'a> {
    /// `#V × #V` symmetric positive semi-definite (positive definite on the free block).
    pub p: Quadratic<'a>,
    /// Linear term, `#V`. With `data`, `q = −diag(data)·c` for the data's target `c`.
    pub q: &'a [f64],
    /// Fixed values, `#V` (`None` = free).
    pub fixed: &'a [Option<f64>],
    /// Ordered pairs `(i, j)`: `f_j − f_i ≥ margin`. Pairs of two fixed entries are ignored.
    pub edges: &'a [(usize, usize)],
    /// ε > 0.
    pub margin: f64,
    /// One-sided bounds on free entries (bounds on fixed entries are ignored).
    pub bounds: &'a [Bound],
    /// The data term's diagonal `d` (`#V`, ≥ 0): `P = Q + diag(d)` with `Q ⪰ 0`, so `P ⪰
    /// diag(d)`. With `d > 0` at every free entry the optimality gap is bounded without a
    /// solve ([`super::optimality`]) and the solver stops on it.
    pub data: Option<&'a [f64]>,
    /// A point that satisfies every constraint (the representative u), `#V`, if known: the
    /// structured solver starts there.
    pub hint: Option<&'a [f64]>,
    /// `F` with `P = FᵀF + diag(data)` (`rows × #V`), for the factored formulation: the
    /// paper's appendix, auxiliary variables `t = F f`, with the square root of `P`'s
    /// condition number.
    pub factor: Option<&'a Factor>,
    /// [`super::condition_estimate`] of this problem if already known (else estimated here).
    pub condition: Option<f64>,
    /// P's energy as `K diag(s) K` (order 2), for products in two passes over `K`'s stencil
    /// (the active-set iteration), if known.
    pub second_order: Option<SecondOrder<'a>>,
}

/// P as the solvers read it: a stored matrix (both triangles), or the matrix of an order-2
/// energy made column by column as it is read ([`BilaplacianColumns`]: the same entries, the
/// same bits, nothing stored: for the active set, which makes its own forms of P once, and a
/// series, whose solver reads it once into its band).
#[derive(Clone, Copy, Debug)]
pub enum Quadratic<'a> {
    /// Compressed columns, both triangles.
    Stored(&'a Sparse),
    /// Made column by column.
    Columns(&'a BilaplacianColumns<'a>),
}

impl<'a> From<&'a Sparse> for Quadratic<'a> {
    fn from(p: &'a Sparse) -> Self {
        Quadratic::Stored(p)
    }
}

impl Quadratic<'_> {
    /// The order of the matrix.
    #[must_use]
    pub fn n(&self) -> usize {
        match self {
            Quadratic::Stored(p) => p.ncols(),
            Quadratic::Columns(c) => c.n(),
        }
    }

    /// The stored matrix, if it is one.
    #[must_use]
    pub fn stored(&self) -> Option<&Sparse> {
        match self {
            Quadratic::Stored(p) => Some(p),
            Quadratic::Columns(_) => None,
        }
    }

    /// A workspace for [`Self::column`] (empty for a stored matrix).
    #[must_use]
    pub fn workspace(&self) -> Column {
        match self {
            Quadratic::Stored(_) => Column::default(),
            Quadratic::Columns(c) => c.workspace(),
        }
    }

    /// Column `j`'s rows (increasing) and values, from storage or made in `work`.
    pub fn column<'s>(&'s self, j: usize, work: &'s mut Column) -> (&'s [usize], &'s [f64]) {
        match self {
            Quadratic::Stored(p) => {
                let (cp, ri) = (p.symbolic().col_ptr(), p.symbolic().row_idx());
                (&ri[cp[j]..cp[j + 1]], &p.val()[cp[j]..cp[j + 1]])
            }
            Quadratic::Columns(c) => {
                c.column(j, work);
                (&work.rows, &work.vals)
            }
        }
    }

    /// `visit(j, rows, values)` for every column `j` in order (made columns made in blocks on
    /// up to the cap's threads: [`BilaplacianColumns::for_each_column`]).
    pub fn for_each_column(&self, mut visit: impl FnMut(usize, &[usize], &[f64])) {
        match self {
            Quadratic::Stored(p) => {
                let (cp, ri, v) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
                for j in 0..p.ncols() {
                    visit(j, &ri[cp[j]..cp[j + 1]], &v[cp[j]..cp[j + 1]]);
                }
            }
            Quadratic::Columns(c) => c.for_each_column(visit),
        }
    }

    /// The largest `|slot[i] − slot[j]|` over the entries `(i, j)` of the pattern with both
    /// slots in use (not `usize::MAX`), if it is at most `limit` (`None` past it: the search
    /// stops at the first such entry). Made columns are not made: their patterns come from K.
    #[must_use]
    pub fn slot_width_at_most(&self, slot: &[usize], limit: usize) -> Option<usize> {
        let mut width = 0usize;
        for (j, &sj) in slot.iter().enumerate() {
            if sj == usize::MAX {
                continue;
            }
            let mut wide = false;
            let mut widen = |i: usize| {
                if slot[i] != usize::MAX {
                    let d = slot[i].abs_diff(sj);
                    wide |= d > limit;
                    width = width.max(d);
                }
            };
            match self {
                Quadratic::Stored(p) => {
                    let (cp, ri) = (p.symbolic().col_ptr(), p.symbolic().row_idx());
                    ri[cp[j]..cp[j + 1]].iter().for_each(|&i| widen(i));
                }
                Quadratic::Columns(c) => c.pattern_rows(j, widen),
            }
            if wide {
                return None;
            }
        }
        Some(width)
    }

    /// The entry at row `i` of column `j` (`None` outside the pattern).
    #[must_use]
    pub fn entry(&self, i: usize, j: usize) -> Option<f64> {
        match self {
            Quadratic::Stored(p) => {
                let (cp, ri) = (p.symbolic().col_ptr(), p.symbolic().row_idx());
                ri[cp[j]..cp[j + 1]].binary_search(&i).ok().map(|at| p.val()[cp[j] + at])
            }
            Quadratic::Columns(c) => c.entry(i, j),
        }
    }

    /// An upper bound on the entries of the columns of `free` in the rows of `free` that lie
    /// on or above the diagonal (the stored count, or for made columns half the pushes their
    /// sums take, plus the diagonal): what a reduction's upper triangle may hold.
    #[must_use]
    pub fn upper_entries_at_most(&self, free: &[usize]) -> usize {
        match self {
            Quadratic::Stored(p) => {
                let (cp, ri) = (p.symbolic().col_ptr(), p.symbolic().row_idx());
                let mut is_free = vec![false; p.ncols()];
                free.iter().for_each(|&v| is_free[v] = true);
                free.iter().map(|&j| ri[cp[j]..cp[j + 1]].iter().filter(|&&i| i <= j && is_free[i]).count()).sum()
            }
            Quadratic::Columns(c) => {
                let pushes = c.pushes_at_most();
                pushes / 2 + c.n()
            }
        }
    }

    /// `fᵀ (P − diag(d)) f` for a P that holds `diag(d)` in its diagonal entries: `d` is taken
    /// off each diagonal entry before it is used, so a large `d` does not swamp the rest by
    /// cancellation.
    #[must_use]
    pub fn quadratic_form_without_diagonal(&self, d: &[f64], f: &[f64]) -> f64 {
        let mut s = 0.0;
        self.for_each_column(|j, rows, vals| {
            for (&i, &v) in rows.iter().zip(vals) {
                let aij = if i == j { v - d[j] } else { v };
                s += f[i] * aij * f[j];
            }
        });
        s
    }
}

/// An energy of order 2 as its stiffness and the scales between: `Q = K diag(row_scale) K`
/// (`row_scale = c / m` with the term's weight `c` and the lumped mass `m`, 0 at sharp
/// vertices), so that `P = Q + diag(data)`.
#[derive(Clone, Copy, Debug)]
pub struct SecondOrder<'a> {
    /// The stiffness, `#V × #V`, symmetric.
    pub k: &'a Sparse,
    /// `#V`.
    pub row_scale: &'a [f64],
}

/// One constraint row of a [`MonotoneQp`] (fixed values substituted when it is reduced).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Row {
    /// `f_j − f_i ≥ margin`.
    Pair(usize, usize),
    /// `f_v ≥ value`.
    Lower(usize, f64),
    /// `f_v ≤ value`.
    Upper(usize, f64),
}

/// The rows that constrain a free entry, in the order of the solver's multipliers: the
/// edges with a free end, then the bounds of free entries.
pub fn constraint_rows(qp: &MonotoneQp<'_>) -> Vec<Row> {
    constraint_rows_iter(qp).collect()
}

/// [`constraint_rows`] one at a time (at 256³ the list is 31.9 million rows of 24 bytes).
pub fn constraint_rows_iter<'q>(qp: &'q MonotoneQp<'_>) -> impl Iterator<Item = Row> + 'q {
    let free = move |v: usize| qp.fixed[v].is_none();
    qp.edges.iter().filter(move |&&(i, j)| free(i) || free(j)).map(|&(i, j)| Row::Pair(i, j)).chain(
        qp.bounds.iter().filter(move |b| free(b.vertex)).map(|b| {
            if b.upper {
                Row::Upper(b.vertex, b.value)
            } else {
                Row::Lower(b.vertex, b.value)
            }
        }),
    )
}

/// The factored objective on the free variables: `½‖F x + g‖² + ½ xᵀ diag(d) x + q_dᵀ x`
/// (`q_d` is [`ReducedQp::q_free`]), scaled like [`ReducedQp`].
pub struct ReducedFactor {
    /// `F` restricted to the free columns, rounded to double.
    pub f: Sparse,
    /// The remainder of each stored entry of `f` (double-double entries).
    pub lo: Vec<f64>,
    /// `F_X x_X`: the fixed columns' contribution.
    pub g: Vec<f64>,
    /// Whether the interior-point iteration may run in double with the gradient formed in
    /// double-double (a data term and a condition estimate up to
    /// [`super::settings::DOUBLE_DOUBLE_ABOVE`]); else it runs in double-double throughout.
    pub double_iteration: bool,
}

impl ReducedFactor {
    /// Stored entry `p` of `f` in double-double.
    #[inline]
    pub fn entry(&self, p: usize) -> Dd {
        Dd { hi: self.f.val()[p], lo: self.lo[p] }
    }
}

/// The QP on the free variables: `min ½ xᵀ P x + qᵀ x` s.t. `A x ≤ b`, objective scaled so
/// that the mean diagonal of P is 1. Rows have one or two entries and are stored in order.
pub struct ReducedQp {
    /// Number of free variables.
    pub n: usize,
    /// Upper triangle of P (row ≤ col), column by column; empty, as A's entries are, when made
    /// for the active set (`reduce_with`).
    pub p: UpperP,
    /// Linear term.
    pub q: Vec<f64>,
    /// The rows of A (none, as P's triplets, when made for the active set: `reduce_with`).
    pub rows: Rows,
    /// Right-hand side, one per row.
    pub b: Vec<f64>,
    /// The data diagonal on the free variables (zeros without a data term).
    pub d: Vec<f64>,
    /// `q` on the free variables without the fixed ones' coupling `P_FX x_X`: the data term's
    /// linear part `−d ∘ c`, so that the data term is `½ Σ (d x + q_free)² / d` up to a
    /// constant.
    pub q_free: Vec<f64>,
    /// Whether `d > 0` at every free variable: `P ⪰ diag(d)` then bounds the gap without a
    /// solve.
    pub gap_bound: bool,
    /// The factored form, when the formulation is factored.
    pub factor: Option<ReducedFactor>,
    /// The factor the objective was divided by.
    pub scale: f64,
    /// `½ x_Xᵀ P_XX x_X` (scaled): the objective of the fixed part, so that `φ(x) + constant`
    /// is `½ fᵀPf + qᵀf` of the whole vector (less the fixed part's linear term).
    pub constant: f64,
}

/// The upper triangle of a reduced QP's P, column by column and each column's rows rising: as
/// triplets, or as its band when every entry lies within [`crate::linalg::BANDED_MAX`] places
/// of the diagonal (a series: `b + 1` values a column instead of `b + 1` triplets of 24 bytes;
/// at 10⁷ samples 240 MB instead of 720).
#[derive(Clone, Debug)]
pub enum UpperP {
    /// `(row, column, value)`, sorted by column then row.
    Triplets(Vec<(usize, usize, f64)>),
    /// The entry `(i, j)`, `j − width ≤ i ≤ j`, at [`place`] (the layout of the structured
    /// solver's band); a place where P has no entry holds 0, one
    /// before the first row (`i < 0`) is never read.
    Band { width: usize, values: Vec<f64> },
}

/// Where the entry `(i, j)`, `i ≤ j ≤ i + width`, is in [`UpperP::Band`]'s values: column by
/// column, `width + 1` places each, the diagonal last — the structured solver's band layout
/// (`solve::banded`, which depends on this module; the two are tested equal in `solve::ipm`).
#[inline]
fn place(width: usize, i: usize, j: usize) -> usize {
    j * (width + 1) + width - (j - i)
}

impl Default for UpperP {
    fn default() -> UpperP {
        UpperP::Triplets(Vec::new())
    }
}

impl UpperP {
    /// The entries as triplets would give them: column by column, rows rising (a band's places
    /// without an entry of P as zeros).
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize, f64)> + Clone + '_ {
        let (triplets, band): (&[(usize, usize, f64)], _) = match self {
            UpperP::Triplets(t) => (t, None),
            UpperP::Band { width, values } => (&[], Some((*width, &values[..]))),
        };
        triplets.iter().copied().chain(band.into_iter().flat_map(|(w, values)| {
            (0..values.len() / (w + 1))
                .flat_map(move |j| (j.saturating_sub(w)..=j).map(move |i| (i, j, values[place(w, i, j)])))
        }))
    }

    /// The number of entries [`UpperP::entries`] gives.
    pub fn len(&self) -> usize {
        match self {
            UpperP::Triplets(t) => t.len(),
            UpperP::Band { width, values } => {
                let (w, n) = (*width, values.len() / (*width + 1));
                n * (w + 1) - w.min(n) * (w.min(n) + 1) / 2
            }
        }
    }

    /// The largest distance of an entry from the diagonal (a band's width).
    pub fn width(&self) -> usize {
        match self {
            UpperP::Triplets(t) => t.iter().map(|&(i, j, _)| i.abs_diff(j)).max().unwrap_or(0),
            UpperP::Band { width, .. } => *width,
        }
    }

    /// `out += P x` (both triangles), each entry of `out` summed in the order of
    /// [`UpperP::entries`] whatever the storage.
    #[allow(clippy::needless_range_loop)] // a row's places in the band and in x indexed together
    pub fn add_product(&self, x: &[f64], out: &mut [f64]) {
        match self {
            UpperP::Triplets(t) => {
                for &(i, j, v) in t {
                    out[i] += v * x[j];
                    if i != j {
                        out[j] += v * x[i];
                    }
                }
            }
            UpperP::Band { width, values } => {
                // row by row, each row's products in the order the columns give them (its
                // column's entries above the diagonal, the diagonal, then its row's entries in
                // the columns after it): the same sums, on contiguous pieces one a thread
                let w = *width;
                let n = values.len() / (w + 1);
                let at = |i: usize, j: usize| values[place(w, i, j)];
                crate::parallel::split_mut(out, |offset, out| {
                    for (o, i) in out.iter_mut().zip(offset..) {
                        let mut sum = *o;
                        for k in i.saturating_sub(w)..i {
                            sum += at(k, i) * x[k];
                        }
                        sum += at(i, i) * x[i];
                        for j in i + 1..(i + w + 1).min(n) {
                            sum += at(i, j) * x[j];
                        }
                        *o = sum;
                    }
                });
            }
        }
    }

    fn scale_by(&mut self, by: f64) {
        match self {
            UpperP::Triplets(t) => t.iter_mut().for_each(|t| t.2 /= by),
            UpperP::Band { values, .. } => values.iter_mut().for_each(|v| *v /= by),
        }
    }
}

/// The constraint rows of a reduced QP. Every row is an ordering constraint on an edge or a
/// bound, so its entries are `+1` and `−1`: row `k` is `x[a] − x[b]` for `[a, b] = ends[k]`,
/// one end [`ABSENT`] for a bound (`x[a]` or `−x[b]`). Eight bytes a row (at 10⁷ rows the
/// columns, values and lengths stored apart were 330 MB, and every product with A read them).
#[derive(Clone, Debug, Default)]
pub struct Rows {
    ends: Vec<[u32; 2]>,
}

/// A row's missing end.
pub const ABSENT: u32 = u32::MAX;

/// The largest number of variables rows can index.
pub const MAX_VARIABLES: usize = ABSENT as usize;

impl Rows {
    pub(super) fn with_capacity(m: usize) -> Rows {
        Rows { ends: Vec::with_capacity(m) }
    }

    /// Appends the row with these entries: one or two, `+1` and `−1`, on variables below
    /// [`MAX_VARIABLES`] (what the reduction makes).
    pub(super) fn push(&mut self, entries: &[(usize, f64)]) {
        let end =
            |c: usize| u32::try_from(c).ok().filter(|&c| c != ABSENT).expect("a variable index below MAX_VARIABLES");
        debug_assert!(
            entries.iter().all(|e| e.1.abs() == 1.0) && (entries.len() == 1 || entries[0].1 == -entries[1].1)
        );
        let row = match *entries {
            [(c, v)] if v > 0.0 => [end(c), ABSENT],
            [(c, _)] => [ABSENT, end(c)],
            [(c1, v1), (c2, _)] if v1 > 0.0 => [end(c1), end(c2)],
            [(c1, _), (c2, _)] => [end(c2), end(c1)],
            _ => unreachable!("a row has one or two entries"),
        };
        self.ends.push(row);
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// The ends `[a, b]` of every row (`x[a] − x[b]`, [`ABSENT`] for a missing one).
    pub fn ends(&self) -> &[[u32; 2]] {
        &self.ends
    }

    /// Whether row `k` has two entries (an edge, not a bound).
    #[inline]
    pub fn is_pair(&self, k: usize) -> bool {
        !self.ends[k].contains(&ABSENT)
    }

    /// The ends `(a, b)` of the rows with two entries, in order.
    pub fn pairs(&self) -> impl Iterator<Item = (usize, usize)> + Clone + '_ {
        self.ends.iter().filter(|e| !e.contains(&ABSENT)).map(|&[a, b]| (a as usize, b as usize))
    }

    /// Row `k` as columns, values and length: `([a, b], [1, −1], 2)` for a pair, `([c, c],
    /// [±1, 0], 1)` for a bound.
    #[inline]
    pub fn row(&self, k: usize) -> ([usize; 2], [f64; 2], usize) {
        match self.ends[k] {
            [a, ABSENT] => ([a as usize, a as usize], [1.0, 0.0], 1),
            [ABSENT, b] => ([b as usize, b as usize], [-1.0, 0.0], 1),
            [a, b] => ([a as usize, b as usize], [1.0, -1.0], 2),
        }
    }

    /// Every entry as `(row, column, value)`, row by row.
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize, f64)> + Clone + '_ {
        (0..self.len()).flat_map(move |k| {
            let (c, v, len) = self.row(k);
            (0..len).map(move |l| (k, c[l], v[l]))
        })
    }
}

impl ReducedQp {
    /// Number of rows.
    pub fn m(&self) -> usize {
        self.b.len()
    }
}

/// Eliminates the fixed variables: `P_FF`, `q_F + P_FX x_X`, one row per constraint row.
pub(super) fn reduce(qp: &MonotoneQp<'_>, free: &[usize]) -> ReducedQp {
    reduce_with(qp, free, true).0
}

/// [`reduce`], with P's triplets and A's entries left empty unless `triplets` (a route that
/// makes its own forms of them from `qp`: the active set; at 128³ they are 0.9 GB), and the
/// number of entries in P's reduced upper triangle.
pub(super) fn reduce_with(qp: &MonotoneQp<'_>, free: &[usize], triplets: bool) -> (ReducedQp, usize) {
    let n = qp.q.len();
    let mut slot = vec![usize::MAX; n];
    for (k, &i) in free.iter().enumerate() {
        slot[i] = k;
    }
    let xfix = |i: usize| qp.fixed[i].unwrap_or(0.0);
    let mut q: Vec<f64> = free.iter().map(|&i| qp.q[i]).collect();
    let nf = free.len();
    // a band when every free entry lies near the diagonal (a series), else triplets
    let made = matches!(qp.p, Quadratic::Columns(_));
    let width = if triplets { qp.p.slot_width_at_most(&slot, crate::linalg::BANDED_MAX) } else { None };
    // the upper triangle of a symmetric pattern: half the off-diagonal entries and the diagonal
    let capacity = qp.p.stored().map_or(0, |p| p.val().len() / 2 + n);
    let mut p = Vec::with_capacity(if triplets && width.is_none() { capacity } else { 0 });
    let mut band = width.map(|w| vec![0.0; nf * (w + 1)]);
    let (mut upper, mut diag) = (0usize, Vec::with_capacity(if triplets { 0 } else { nf }));
    let mut constant = 0.0;
    let mut visit = |j: usize, ri: &[usize], val: &[f64]| {
        for (k, &i) in ri.iter().enumerate() {
            match (slot[i], slot[j]) {
                (usize::MAX, usize::MAX) => constant += 0.5 * xfix(i) * val[k] * xfix(j),
                (usize::MAX, _) => {}
                (si, usize::MAX) => q[si] += val[k] * xfix(j),
                (si, sj) if si <= sj => {
                    upper += 1;
                    match (&mut band, width) {
                        (Some(band), Some(w)) => band[place(w, si, sj)] += val[k],
                        _ if triplets => p.push((si, sj, val[k])),
                        _ if si == sj => diag.push(val[k]),
                        _ => {}
                    }
                }
                _ => {}
            }
        }
    };
    // without triplets a free column gives its diagonal only (all that is read of it): made
    // columns are then made for the fixed vertices alone; with them, in blocks on every core
    if made && triplets {
        qp.p.for_each_column(&mut visit);
    } else {
        // made columns' workspace only where a column is made one at a time (12 bytes a vertex)
        let mut work = qp.p.workspace();
        for (j, &sj) in slot.iter().enumerate() {
            if made && sj != usize::MAX {
                let diagonal = qp.p.entry(j, j).unwrap_or(0.0);
                visit(j, &[j], &[diagonal]);
            } else {
                let (rows, vals) = qp.p.column(j, &mut work);
                visit(j, rows, vals);
            }
        }
    }
    if made && !triplets {
        upper = qp.p.upper_entries_at_most(free);
    }
    let mut p = match (band, width) {
        (Some(values), Some(width)) => UpperP::Band { width, values },
        _ => UpperP::Triplets(p),
    };
    let diag: f64 = match &p {
        _ if !triplets => diag.iter().sum(),
        UpperP::Triplets(t) => t.iter().filter(|t| t.0 == t.1).map(|t| t.2).sum(),
        UpperP::Band { width, values } => values.iter().skip(*width).step_by(width + 1).sum(),
    };
    let scale = (diag / nf as f64).max(f64::MIN_POSITIVE);
    p.scale_by(scale);
    q.iter_mut().for_each(|v| *v /= scale);
    let d: Vec<f64> = free.iter().map(|&i| qp.data.map_or(0.0, |d| d[i]) / scale).collect();
    let q_free: Vec<f64> = free.iter().map(|&i| qp.q[i] / scale).collect();
    let gap_bound = d.iter().all(|&v| v > 0.0);
    let mut r = ReducedQp {
        n: nf,
        p,
        q,
        rows: Rows::default(),
        b: vec![],
        d,
        q_free,
        gap_bound,
        factor: None,
        scale,
        constant: constant / scale,
    };
    let m = constraint_rows_iter(qp).count();
    r.b.reserve_exact(m);
    if triplets {
        r.rows = Rows::with_capacity(m);
    }
    for row in constraint_rows_iter(qp) {
        let mut push = |entries: &[(usize, f64)]| {
            if triplets {
                r.rows.push(entries);
            }
        };
        // f_j − f_i ≥ ε  ⇔  f_i − f_j ≤ −ε
        match row {
            Row::Pair(i, j) => match (qp.fixed[i], qp.fixed[j]) {
                (None, None) => {
                    push(&[(slot[i], 1.0), (slot[j], -1.0)]);
                    r.b.push(-qp.margin);
                }
                (Some(fi), _) => {
                    push(&[(slot[j], -1.0)]);
                    r.b.push(-qp.margin - fi);
                }
                (None, Some(fj)) => {
                    push(&[(slot[i], 1.0)]);
                    r.b.push(fj - qp.margin);
                }
            },
            Row::Upper(v, c) => {
                push(&[(slot[v], 1.0)]);
                r.b.push(c);
            }
            Row::Lower(v, c) => {
                push(&[(slot[v], -1.0)]);
                r.b.push(-c);
            }
        }
    }
    (r, upper)
}

/// Divides the objective of `r` by a further `by` (its `scale` becomes `scale · by`).
pub(super) fn rescale(r: &mut ReducedQp, by: f64) {
    r.p.scale_by(by);
    r.constant /= by;
    for v in r.q.iter_mut().chain(r.d.iter_mut()).chain(r.q_free.iter_mut()) {
        *v /= by;
    }
    r.scale *= by;
}

/// The factored objective on the free variables, scaled like the reduced QP (`F / √scale`),
/// in double-double.
pub(super) fn reduce_factor(qp: &MonotoneQp<'_>, f: &Factor, free: &[usize], scale: f64) -> ReducedFactor {
    let n = qp.q.len();
    let mut slot = vec![usize::MAX; n];
    for (k, &i) in free.iter().enumerate() {
        slot[i] = k;
    }
    let inv_root = Dd::from(1.0) / Dd::from(scale).sqrt();
    let m = &f.matrix;
    let mut g = vec![Dd::ZERO; m.nrows()];
    let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
    let mut col_ptr = vec![0usize];
    let (mut row_idx, mut val, mut lo) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..n {
        match qp.fixed[j] {
            Some(v) => {
                for p in cp[j]..cp[j + 1] {
                    g[ri[p]] += f.entry(p) * Dd::from(v) * inv_root;
                }
            }
            None => {
                for (p, &i) in (cp[j]..cp[j + 1]).zip(&ri[cp[j]..cp[j + 1]]) {
                    let e = f.entry(p) * inv_root;
                    let hi = e.to_f64();
                    row_idx.push(i);
                    val.push(hi);
                    lo.push((e - Dd::from(hi)).hi);
                }
                col_ptr.push(row_idx.len());
            }
        }
    }
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(m.nrows(), free.len(), col_ptr, None, row_idx);
    ReducedFactor {
        f: Sparse::new(symbolic, val),
        lo,
        g: g.iter().map(|v| v.to_f64()).collect(),
        double_iteration: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::operators::{plus_diagonal, polyharmonic_products, volume_mass, volume_stiffness, Energy};

    /// The reductions from made columns are those from the stored matrix, bit for bit: with
    /// P's triplets (what a route taking over from the active set rebuilds) and without them
    /// (the active set's own: the fixed vertices' coupling, the scale, the constant), with the
    /// same rows and right-hand sides.
    #[test]
    fn made_columns_reduce_as_the_stored_matrix() {
        let g = crate::domain::Grid3d::with_geometry([11, 9, 8], [1.0, 0.7, 1.2], [0.0; 3]).unwrap();
        let (k, m) = (volume_stiffness(&g), volume_mass(&g));
        let n = m.len();
        let data: Vec<f64> = m.iter().map(|v| 0.4 * v).collect();
        let energy = Energy::order(2);
        let stored = plus_diagonal(polyharmonic_products(&k, &m, &energy, &[5.0]), &data);
        let made = BilaplacianColumns::new(&k, &m, &energy, &[5.0], &data).unwrap();
        let q: Vec<f64> = (0..n).map(|i| -data[i] * ((i * 13 % 17) as f64 * 0.05)).collect();
        let mut fixed = vec![None; n];
        for (v, value) in [(3, 0.2), (250, 0.9), (700, 0.1)] {
            fixed[v] = Some(value);
        }
        let edges: Vec<(usize, usize)> = (0..n - 1).filter(|i| i % 11 != 10).map(|i| (i, i + 1)).collect();
        let bounds = [Bound { vertex: 5, value: 1.0, upper: true }];
        let free: Vec<usize> = (0..n).filter(|&v| fixed[v].is_none()).collect();
        let problem = |p: Quadratic<'_>| {
            let qp = MonotoneQp {
                p,
                q: &q,
                fixed: &fixed,
                edges: &edges,
                margin: 1e-5,
                bounds: &bounds,
                data: Some(&data),
                hint: None,
                factor: None,
                condition: None,
                second_order: None,
            };
            [true, false].map(|triplets| reduce_with(&qp, &free, triplets))
        };
        let (a, b) = (problem(Quadratic::Stored(&stored)), problem(Quadratic::Columns(&made)));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for ((ra, ua), (rb, ub)) in a.iter().zip(&b) {
            assert_eq!(bits(&ra.q), bits(&rb.q));
            assert_eq!(bits(&ra.b), bits(&rb.b));
            assert_eq!(bits(&ra.d), bits(&rb.d));
            assert_eq!(ra.scale.to_bits(), rb.scale.to_bits());
            assert_eq!(ra.constant.to_bits(), rb.constant.to_bits());
            assert_eq!(ra.rows.ends(), rb.rows.ends());
            let entries = |r: &ReducedQp| r.p.entries().map(|(i, j, v)| (i, j, v.to_bits())).collect::<Vec<_>>();
            assert_eq!(entries(ra), entries(rb));
            assert!(ub >= ua, "the made columns' count {ub} bounds the stored {ua}");
        }
        assert!(a[0].1 > 0 && a[0].0.p.len() == a[0].1);
    }
}
