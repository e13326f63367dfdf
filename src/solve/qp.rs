//! The monotone QP, its reduction to the free variables, and the choice of solver.

use super::ipm::Prepared;
use crate::error::Result;
use crate::operators::{Factor, Sparse};

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
    pub p: &'a Sparse,
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
}

/// Which interior-point solver runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// The structured solver of [`super::ipm`] (normal equations, faer Cholesky with the
    /// symbolic analysis done once); Clarabel takes over if it does not converge.
    Structured,
    /// Clarabel on the full KKT system, in the formulation the structured solver would use.
    Clarabel,
    /// Clarabel on the factored formulation whatever the conditioning (the paper's appendix:
    /// variables `(f, t)` with `t = F f` as equality constraints; needs
    /// [`MonotoneQp::factor`]).
    #[serde(rename = "clarabel-auxiliary")]
    ClarabelAuxiliary,
}

/// How the objective enters the solver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Formulation {
    /// Factored when `P`'s condition estimate exceeds [`FACTORED_ABOVE`] and a factor is
    /// given, else assembled.
    #[default]
    Auto,
    /// `P` as one matrix: normal equations in double precision.
    Assembled,
    /// `P = FᵀF + diag(d)`: the structured solver forms its normal matrix from `F` in
    /// double-double arithmetic and keeps the iterate in it; Clarabel gets the auxiliary
    /// variables `t = F f`.
    Factored,
}

/// Condition estimate of `diag(d)^{-½} P diag(d)^{-½}` above which [`Formulation::Auto`]
/// chooses the factored form. An assembled P carries rounding errors of about `10⁻¹⁶ κ`
/// relative to its smallest eigenvalues, and the gap bound squares the gradient's: at κ = 10⁹
/// that is `10⁻¹⁴` of the data term, ample; at 10¹¹ it reaches the bound's target (10⁻⁷ of it).
pub const FACTORED_ABOVE: f64 = 1e9;

/// Solver settings.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct QpSettings {
    /// Largest number of interior-point iterations. {200}
    pub max_iter: u32,
    /// Feasibility tolerance on the scaled problem (values in [0, 1]). {1e-9}
    pub tolerance: f64,
    /// The structured solver stops when the gap bound is below this fraction of the data
    /// term (without a data term: of the objective's range, by the mean complementarity).
    /// {3e-7: a third of the target, 10⁻⁶, for what the output's rounding and the repair add}
    pub gap_tolerance: f64,
    /// Solver. {structured}
    pub method: Method,
    /// Formulation. {auto}
    pub formulation: Formulation,
}

impl Default for QpSettings {
    fn default() -> Self {
        QpSettings {
            max_iter: 200,
            tolerance: 1e-9,
            gap_tolerance: 3e-7,
            method: Method::Structured,
            formulation: Formulation::Auto,
        }
    }
}

/// How the solver ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum SolveStatus {
    /// Converged to the requested accuracy.
    Solved,
    /// Converged to a reduced accuracy.
    AlmostSolved,
    /// Stopped at the iteration limit with a point.
    MaxIterations,
    /// Stopped early (numerical trouble, no progress) with a point.
    Stalled,
    /// No constraint and no free variable needed the solver.
    Trivial,
}

/// A returned point (all entries, fixed ones set exactly) and how it was obtained.
#[derive(Clone, Debug)]
pub struct QpSolution {
    /// `#V` values.
    pub x: Vec<f64>,
    /// Multipliers (≥ 0) of the constraint rows in [`constraint_rows`] order, in the units of
    /// the problem as given.
    pub z: Vec<f64>,
    /// With the factored formulation: the auxiliary variables `t ≈ F f` (the equality rows'
    /// multipliers), for the gap bound.
    pub y: Option<Vec<f64>>,
    /// Solver outcome.
    pub status: SolveStatus,
    /// Interior-point iterations.
    pub iterations: u32,
    /// The solver that produced the point.
    pub method: Method,
    /// The formulation used ([`Formulation::Assembled`] or [`Formulation::Factored`]).
    pub formulation: Formulation,
    /// Condition estimate of `diag(d)^{-½} P diag(d)^{-½}` on the free entries (with a data
    /// term): `1 + λ_max(diag(d)⁻¹ Q)`, by power iteration.
    pub condition: Option<f64>,
    /// Why the structured solver handed over to Clarabel, if it did.
    pub fallback: Option<String>,
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
    let free = |v: usize| qp.fixed[v].is_none();
    qp.edges
        .iter()
        .filter(|&&(i, j)| free(i) || free(j))
        .map(|&(i, j)| Row::Pair(i, j))
        .chain(qp.bounds.iter().filter(|b| free(b.vertex)).map(|b| {
            if b.upper {
                Row::Upper(b.vertex, b.value)
            } else {
                Row::Lower(b.vertex, b.value)
            }
        }))
        .collect()
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
}

impl ReducedFactor {
    /// Stored entry `p` of `f` in double-double.
    pub fn entry(&self, p: usize) -> faer::fx128 {
        faer::fx128::from(self.f.val()[p]) + faer::fx128::from(self.lo[p])
    }
}

/// The QP on the free variables: `min ½ xᵀ P x + qᵀ x` s.t. `A x ≤ b`, objective scaled so
/// that the mean diagonal of P is 1. Rows have one or two entries and are stored in order.
pub struct ReducedQp {
    /// Number of free variables.
    pub n: usize,
    /// Upper triangle of P as triplets (row ≤ col).
    pub p: Vec<(usize, usize, f64)>,
    /// Linear term.
    pub q: Vec<f64>,
    /// Row index of each entry of A (non-decreasing).
    pub a_row: Vec<usize>,
    /// Column of each entry of A.
    pub a_col: Vec<usize>,
    /// Value of each entry of A.
    pub a_val: Vec<f64>,
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

impl ReducedQp {
    /// Number of rows.
    pub fn m(&self) -> usize {
        self.b.len()
    }
}

/// Solves the monotone QP.
///
/// # Errors
/// [`crate::Error::NoSolution`] when no solver returns a usable point; a usage error for
/// [`Method::ClarabelAuxiliary`] or [`Formulation::Factored`] without a factor.
pub fn solve_monotone_qp(qp: &MonotoneQp<'_>, settings: &QpSettings) -> Result<QpSolution> {
    let n = qp.q.len();
    assert_eq!(qp.fixed.len(), n);
    assert_eq!(qp.p.nrows(), n);
    let free: Vec<usize> = (0..n).filter(|&i| qp.fixed[i].is_none()).collect();
    let mut x: Vec<f64> = qp.fixed.iter().map(|f| f.unwrap_or(0.0)).collect();
    let rows = constraint_rows(qp);
    if free.is_empty() {
        super::ipm::forget_prepared_storage();
        return Ok(QpSolution {
            x,
            z: vec![0.0; rows.len()],
            y: None,
            status: SolveStatus::Trivial,
            iterations: 0,
            method: settings.method,
            formulation: Formulation::Assembled,
            condition: None,
            fallback: None,
        });
    }
    let mut reduced = reduce(qp, &free);
    let condition = qp.condition.or_else(|| super::condition::estimate(&reduced));
    let wants_factored = match (settings.method, settings.formulation) {
        (Method::ClarabelAuxiliary, _) | (_, Formulation::Factored) => true,
        (_, Formulation::Assembled) => false,
        (_, Formulation::Auto) => condition.is_some_and(|c| c > FACTORED_ABOVE),
    };
    let forced = settings.method == Method::ClarabelAuxiliary || settings.formulation == Formulation::Factored;
    let to_factored = |reduced: &mut ReducedQp, f: &Factor| {
        // scaled by the data term rather than by P's diagonal: the variables' own block
        // (d) then has unit size beside Clarabel's static regularisation, F carries √κ
        let d_mean = reduced.d.iter().sum::<f64>() / reduced.n as f64;
        if d_mean > 0.0 {
            rescale(reduced, d_mean);
        }
        reduced.factor = Some(reduce_factor(qp, f, &free, reduced.scale));
    };
    let mut formulation = match (wants_factored, qp.factor) {
        (true, Some(f)) => {
            to_factored(&mut reduced, f);
            Formulation::Factored
        }
        (true, None) if forced => {
            return Err(crate::Error::Usage(
                "the factored formulation needs the energy as FᵀF (not available for this energy)".into(),
            ))
        }
        _ => Formulation::Assembled,
    };
    if formulation == Formulation::Factored {
        super::ipm::forget_prepared_storage();
    }
    let hint: Option<Vec<f64>> = qp.hint.map(|h| free.iter().map(|&i| h[i]).collect());
    let mut fallback = None;
    let clarabel = |reduced: &ReducedQp| super::clarabel::solve(reduced, settings);
    let (out, method) = match settings.method {
        Method::Structured => match super::ipm::solve(&reduced, hint.as_deref(), settings) {
            Ok(out) => (out, Method::Structured),
            // the assembled normal matrix lost its definiteness (an energy without a data
            // term, ill-conditioned on its own): the factored form in double-double next
            Err(_)
                if formulation == Formulation::Assembled
                    && settings.formulation == Formulation::Auto
                    && qp.factor.is_some() =>
            {
                to_factored(&mut reduced, qp.factor.expect("checked"));
                formulation = Formulation::Factored;
                match super::ipm::solve(&reduced, hint.as_deref(), settings) {
                    Ok(out) => (out, Method::Structured),
                    Err(why) => {
                        fallback = Some(why);
                        (clarabel(&reduced)?, Method::Clarabel)
                    }
                }
            }
            Err(why) => {
                fallback = Some(why);
                (clarabel(&reduced)?, Method::Clarabel)
            }
        },
        Method::Clarabel | Method::ClarabelAuxiliary => (clarabel(&reduced)?, settings.method),
    };
    for (k, &i) in free.iter().enumerate() {
        x[i] = out.x[k];
    }
    // multipliers and auxiliary variables back in the problem's units
    let z = out.z.iter().map(|v| v.max(0.0) * reduced.scale).collect();
    let y = out.y.map(|y| y.iter().map(|v| v * reduced.scale.sqrt()).collect());
    Ok(QpSolution { x, z, y, status: out.status, iterations: out.iterations, method, formulation, condition, fallback })
}

/// What a solver returns on a [`ReducedQp`].
pub(super) struct Outcome {
    /// The free variables.
    pub x: Vec<f64>,
    /// Multipliers of the rows.
    pub z: Vec<f64>,
    /// Auxiliary variables `t = F x + g` (factored formulation).
    pub y: Option<Vec<f64>>,
    /// How it ended.
    pub status: SolveStatus,
    /// Iterations.
    pub iterations: u32,
}

/// The structured solver's analysis of the normal matrix of a QP with energy `p` and fixed
/// entries `fixed`, made before the constraints and the linear term are known (so that it can
/// run beside the work that finds them); installed on the calling thread by
/// [`Prepared::install`], it is used by the next [`solve_monotone_qp`] there whose normal
/// matrix has this pattern (constrained pairs inside `p`'s pattern, as for every energy
/// built on the domain's Laplacian).
///
/// # Errors
/// A message if the analysis fails.
pub fn prepare(p: &Sparse, fixed: &[Option<f64>]) -> std::result::Result<Prepared, String> {
    let mut slot = vec![usize::MAX; fixed.len()];
    let mut n = 0;
    for (i, f) in fixed.iter().enumerate() {
        if f.is_none() {
            slot[i] = n;
            n += 1;
        }
    }
    Prepared::new(p.symbolic(), &slot, n)
}

/// Eliminates the fixed variables: `P_FF`, `q_F + P_FX x_X`, one row per constraint row.
fn reduce(qp: &MonotoneQp<'_>, free: &[usize]) -> ReducedQp {
    let n = qp.q.len();
    let mut slot = vec![usize::MAX; n];
    for (k, &i) in free.iter().enumerate() {
        slot[i] = k;
    }
    let xfix = |i: usize| qp.fixed[i].unwrap_or(0.0);
    let mut q: Vec<f64> = free.iter().map(|&i| qp.q[i]).collect();
    let (cp, ri, val) = (qp.p.symbolic().col_ptr(), qp.p.symbolic().row_idx(), qp.p.val());
    let mut p = Vec::new();
    let mut constant = 0.0;
    for j in 0..n {
        for k in cp[j]..cp[j + 1] {
            let i = ri[k];
            match (slot[i], slot[j]) {
                (usize::MAX, usize::MAX) => constant += 0.5 * xfix(i) * val[k] * xfix(j),
                (usize::MAX, _) => {}
                (si, usize::MAX) => q[si] += val[k] * xfix(j),
                (si, sj) if si <= sj => p.push((si, sj, val[k])),
                _ => {}
            }
        }
    }
    let nf = free.len();
    let diag: f64 = p.iter().filter(|t| t.0 == t.1).map(|t| t.2).sum();
    let scale = (diag / nf as f64).max(f64::MIN_POSITIVE);
    p.iter_mut().for_each(|t| t.2 /= scale);
    q.iter_mut().for_each(|v| *v /= scale);
    let d: Vec<f64> = free.iter().map(|&i| qp.data.map_or(0.0, |d| d[i]) / scale).collect();
    let q_free: Vec<f64> = free.iter().map(|&i| qp.q[i] / scale).collect();
    let gap_bound = d.iter().all(|&v| v > 0.0);
    let mut r = ReducedQp {
        n: nf,
        p,
        q,
        a_row: vec![],
        a_col: vec![],
        a_val: vec![],
        b: vec![],
        d,
        q_free,
        gap_bound,
        factor: None,
        scale,
        constant: constant / scale,
    };
    for row in constraint_rows(qp) {
        let at = r.b.len();
        let mut push = |col: usize, v: f64| {
            r.a_row.push(at);
            r.a_col.push(col);
            r.a_val.push(v);
        };
        // f_j − f_i ≥ ε  ⇔  f_i − f_j ≤ −ε
        match row {
            Row::Pair(i, j) => match (qp.fixed[i], qp.fixed[j]) {
                (None, None) => {
                    push(slot[i], 1.0);
                    push(slot[j], -1.0);
                    r.b.push(-qp.margin);
                }
                (Some(fi), _) => {
                    push(slot[j], -1.0);
                    r.b.push(-qp.margin - fi);
                }
                (None, Some(fj)) => {
                    push(slot[i], 1.0);
                    r.b.push(fj - qp.margin);
                }
            },
            Row::Upper(v, c) => {
                push(slot[v], 1.0);
                r.b.push(c);
            }
            Row::Lower(v, c) => {
                push(slot[v], -1.0);
                r.b.push(-c);
            }
        }
    }
    r
}

/// Divides the objective of `r` by a further `by` (its `scale` becomes `scale · by`).
fn rescale(r: &mut ReducedQp, by: f64) {
    r.p.iter_mut().for_each(|t| t.2 /= by);
    r.constant /= by;
    for v in r.q.iter_mut().chain(r.d.iter_mut()).chain(r.q_free.iter_mut()) {
        *v /= by;
    }
    r.scale *= by;
}

/// The factored objective on the free variables, scaled like the reduced QP (`F / √scale`),
/// in double-double.
fn reduce_factor(qp: &MonotoneQp<'_>, f: &Factor, free: &[usize], scale: f64) -> ReducedFactor {
    use faer::fx128;
    let n = qp.q.len();
    let mut slot = vec![usize::MAX; n];
    for (k, &i) in free.iter().enumerate() {
        slot[i] = k;
    }
    let inv_root = fx128::from(1.0) / fx128::from(scale).sqrt();
    let m = &f.matrix;
    let mut g = vec![fx128::from(0.0); m.nrows()];
    let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
    let mut col_ptr = vec![0usize];
    let (mut row_idx, mut val, mut lo) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..n {
        match qp.fixed[j] {
            Some(v) => {
                for p in cp[j]..cp[j + 1] {
                    g[ri[p]] += f.entry(p) * fx128::from(v) * inv_root;
                }
            }
            None => {
                for (p, &i) in (cp[j]..cp[j + 1]).zip(&ri[cp[j]..cp[j + 1]]) {
                    let e = f.entry(p) * inv_root;
                    let hi = e.0 + e.1;
                    row_idx.push(i);
                    val.push(hi);
                    lo.push((e - fx128::from(hi)).0);
                }
                col_ptr.push(row_idx.len());
            }
        }
    }
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(m.nrows(), free.len(), col_ptr, None, row_idx);
    ReducedFactor { f: Sparse::new(symbolic, val), lo, g: g.iter().map(|v| v.0 + v.1).collect() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// `P = K + I` of an `nx × ny` grid with the 4-neighbour Laplacian `K`, and its edges.
    fn grid_qp(nx: usize, ny: usize) -> (Sparse, Vec<(usize, usize)>) {
        let n = nx * ny;
        let mut t = Vec::new();
        let mut edges = Vec::new();
        for y in 0..ny {
            for x in 0..nx {
                let v = y * nx + x;
                t.push(Triplet::new(v, v, 1.0));
                for w in [(x + 1 < nx).then_some(v + 1), (y + 1 < ny).then_some(v + nx)].into_iter().flatten() {
                    edges.push((v, w));
                    t.extend([Triplet::new(v, w, -1.0), Triplet::new(w, v, -1.0)]);
                    t.extend([Triplet::new(v, v, 1.0), Triplet::new(w, w, 1.0)]);
                }
            }
        }
        (Sparse::try_new_from_triplets(n, n, &t).unwrap(), edges)
    }

    #[test]
    fn a_prepared_analysis_matches_the_normal_matrix_and_changes_nothing() {
        let (nx, ny) = (60, 50);
        let n = nx * ny;
        let (p, edges) = grid_qp(nx, ny);
        let h: Vec<f64> = (0..n).map(|i| ((i % nx) as f64 * 0.3).sin() + (i / nx) as f64 * 0.01).collect();
        let q: Vec<f64> = h.iter().map(|v| -v).collect();
        let mut fixed = vec![None; n];
        fixed[0] = Some(-1.0);
        fixed[n - 1] = Some(2.0);
        // every edge increasing to the right and upwards: a monotone ramp, feasible
        let hint: Vec<f64> = (0..n).map(|i| -1.0 + 3.0 * ((i % nx) + (i / nx)) as f64 / (nx + ny - 2) as f64).collect();
        let qp = MonotoneQp {
            p: &p,
            q: &q,
            fixed: &fixed,
            edges: &edges,
            margin: 1e-6,
            hint: Some(&hint),
            bounds: &[],
            data: None,
            factor: None,
            condition: None,
        };
        let free: Vec<usize> = (0..n).filter(|&i| fixed[i].is_none()).collect();
        let reduced = reduce(&qp, &free);
        let prepared = prepare(&p, &fixed).unwrap();
        let normal = super::super::ipm::normal_pattern(&reduced);
        let same = |a: faer::sparse::SymbolicSparseColMatRef<'_, usize>| {
            a.col_ptr() == normal.col_ptr() && a.row_idx() == normal.row_idx()
        };
        assert!(same(prepared.pattern()), "the prepared pattern is the normal matrix's");
        // a constrained pair outside P's pattern: a different pattern (analysed anew by the solver)
        let far = [(1, n - 2)];
        let other = reduce(&MonotoneQp { edges: &far, ..qp }, &free);
        assert!(!same(super::super::ipm::normal_pattern(&other).as_ref()));
        let settings = QpSettings::default();
        let plain = solve_monotone_qp(&qp, &settings).unwrap();
        prepare(&p, &fixed).unwrap().install();
        let with = solve_monotone_qp(&qp, &settings).unwrap();
        assert_eq!(plain.iterations, with.iterations);
        let diff = plain.x.iter().zip(&with.x).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(diff < 1e-12, "{diff:e}");
        assert!(edges.iter().all(|&(i, j)| with.x[j] - with.x[i] >= 0.5e-6));
    }

    #[test]
    fn both_solvers_project_onto_a_monotone_chain() {
        // min Σ (f_i − h_i)² with f_0 = 0, f_3 = 3 fixed and f increasing: h = [0, 2, 1, 3]
        let p =
            Sparse::try_new_from_triplets(4, 4, &(0..4).map(|i| Triplet::new(i, i, 1.0)).collect::<Vec<_>>()).unwrap();
        let q = [0.0, -2.0, -1.0, -3.0];
        let fixed = [Some(0.0), None, None, Some(3.0)];
        let edges = [(0, 1), (1, 2), (2, 3)];
        for method in [Method::Structured, Method::Clarabel] {
            for hint in [None, Some(&[0.0, 1.0, 2.0, 3.0][..])] {
                let qp = MonotoneQp {
                    p: &p,
                    q: &q,
                    fixed: &fixed,
                    edges: &edges,
                    margin: 1e-6,
                    hint,
                    bounds: &[],
                    data: None,
                    factor: None,
                    condition: None,
                };
                let sol = solve_monotone_qp(&qp, &QpSettings { method, ..Default::default() }).unwrap();
                assert_eq!(sol.method, method, "{:?}", sol.fallback);
                assert!(matches!(sol.status, SolveStatus::Solved | SolveStatus::AlmostSolved));
                // isotonic regression pools 2 and 1 at 1.5 (then the margin splits them)
                assert!((sol.x[1] - 1.5).abs() < 1e-5 && (sol.x[2] - 1.5).abs() < 1e-5, "{method:?}: {:?}", sol.x);
                assert!(sol.x[2] - sol.x[1] > 0.5e-6);
                assert_eq!((sol.x[0], sol.x[3]), (0.0, 3.0));
            }
        }
    }
}
