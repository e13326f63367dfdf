//! Sparse Cholesky for the rest of the crate (the harmonic fill of `operators`, the
//! interior-point solver of `solve`): fill-reducing orderings computed from the matrix graph
//! alone, and the choice of sequential or parallel factorisation.
//!
//! Nested dissection (`dissection`) bisects the graph recursively by BFS level structures: from a
//! pseudo-peripheral vertex, one BFS level separates the levels before it from those after
//! it, so it is a vertex separator of any graph. Each part is ordered before its separator,
//! small parts by faer's AMD. On planar-like graphs (grids, triangulated meshes) this
//! gives far less fill and fewer flops than minimum degree at large n (about 20 % at a million vertices with
//! the 19-point pattern of a bilaplacian).
//! `analyse` orders a pattern with both this ordering and AMD and keeps the cheapest
//! factorisation: AMD, nested dissection, or nested dissection's two halves side by side
//! (`two_way`); from `ND_ONLY_N` unknowns on it computes AMD only when the two-way split is
//! not possible.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Par, Side, Spec};

mod analyses;
mod cost;
mod dissection;
pub mod double_double;
pub mod multigrid;
pub(crate) mod two_way;

pub use analyses::{solve_spd, Analyses, SpdSolver};
pub(crate) use cost::{factor_flops, touch_pages};
#[cfg(test)]
use dissection::nested_dissection;
pub(crate) use dissection::{compress_columns, inverse, Graph};
use dissection::{dissection, PARALLEL_DISSECTION_MIN};

/// Above this size the factorisation is supernodal: faer's automatic choice kept the
/// simplicial one for bilaplacian patterns of a few thousand unknowns, where supernodal
/// factors are faster (docs/performance.md, "constants").
const SUPERNODAL_MIN_N: usize = 1000;

fn params(n: usize) -> CholeskySymbolicParams<'static> {
    CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: if n >= SUPERNODAL_MIN_N {
            faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL
        } else {
            faer::sparse::linalg::SupernodalThreshold::AUTO
        },
        ..Default::default()
    }
}

/// Graphs below this size are ordered by AMD only.
const ND_MIN_N: usize = 2000;
/// Graphs at least this large are ordered by nested dissection only: there AMD costs seconds
/// and its factors need several times the flops of the two-way one on every pattern measured
/// (docs/performance.md, "constants").
const ND_ONLY_N: usize = 200_000;
/// Parts at most this large are ordered by AMD inside the dissection.
const ND_LEAF: usize = 128;

/// Patterns whose every entry lies within this many places of the diagonal (a series' energy
/// of order k and its constraints: k places) are factorised in their own order, simplicial:
/// no fill outside the band and about n·b² flops, where nested dissection of a path ordered
/// 10⁶ unknowns in 1 s and factorised them with supernodes of a few columns (a series of 10⁶
/// samples: 0.7 s per interior-point iteration, docs/performance.md).
pub(crate) const BANDED_MAX: usize = 8;

/// The band of the upper-triangular pattern `a` (the largest distance of an entry from the
/// diagonal) if it is at most [`BANDED_MAX`]: such a pattern is factorised in its own order, at
/// about n·b² flops.
pub(crate) fn band(a: SymbolicSparseColMatRef<'_, usize>) -> Option<usize> {
    let b = (0..a.ncols()).map(|j| a.row_idx_of_col(j).map(|i| j.saturating_sub(i)).max().unwrap_or(0)).max();
    let b = b.unwrap_or(0);
    (b <= BANDED_MAX).then_some(b)
}

/// The banded analysis of `a` ([`BANDED_MAX`]), if it is banded.
fn banded(
    a: SymbolicSparseColMatRef<'_, usize>,
) -> Option<std::result::Result<SymbolicCholesky<usize>, NumericalError>> {
    band(a).map(|_| {
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: faer::sparse::linalg::SupernodalThreshold::FORCE_SIMPLICIAL,
            ..Default::default()
        };
        factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Identity, params)
            .map_err(|e| crate::error::NumericalError(format!("symbolic Cholesky: {e:?}")))
    })
}

/// Parallelism for a numeric factorisation: sequential below
/// [`crate::parallel::parallel_factor_flops`], else faer's global setting under the caller's cap.
pub(crate) fn parallelism_for(s: &SymbolicCholesky<usize>) -> Par {
    if factor_flops(s) < crate::parallel::parallel_factor_flops() {
        Par::Seq
    } else {
        crate::parallel::faer_par()
    }
}

pub use crate::error::NumericalError;

/// Solves `A x = b` once for a symmetric positive definite `A` given by its upper triangle
/// (`b` is overwritten by `x`), with AMD: for a single factorisation the nested-dissection
/// ordering costs more than it saves. `Err` if `A` is not numerically positive definite.
pub(crate) fn solve_spd_once(
    a: SparseColMatRef<'_, usize, f64>,
    b: &mut [f64],
) -> std::result::Result<(), NumericalError> {
    let n = a.ncols();
    let s = factorize_symbolic_cholesky(a.symbolic(), Side::Upper, SymmetricOrdering::Amd, Default::default())
        .map_err(|e| format!("symbolic Cholesky: {e:?}"))?;
    let s: &SymbolicCholesky<usize> = &s;
    let par = parallelism_for(s);
    let mut l = vec![0.0f64; s.len_val()];
    let mut mem = MemBuffer::try_new(StackReq::any_of(&[
        s.factorize_numeric_llt_scratch::<f64>(par, Spec::default()),
        s.solve_in_place_scratch::<f64>(1, par),
    ]))
    .map_err(|_| "out of memory for the Cholesky workspace".to_string())?;
    s.factorize_numeric_llt(&mut l, a, Side::Upper, Default::default(), par, MemStack::new(&mut mem), Spec::default())
        .map_err(|e| format!("{e:?}"))?;
    let rhs = faer::MatMut::from_column_major_slice_mut(b, n, 1);
    LltRef::new(s, &l).solve_in_place_with_conj(Conj::No, rhs, par, MemStack::new(&mut mem));
    Ok(())
}

/// The pattern (upper triangle with diagonal) of a matrix given by triplets; for tests and
/// callers that build matrices by hand.
#[cfg(test)]
pub(crate) fn upper_pattern(n: usize, edges: &[(usize, usize)]) -> faer::sparse::SymbolicSparseColMat<usize> {
    let mut cols: Vec<Vec<usize>> = (0..n).map(|j| vec![j]).collect();
    for &(i, j) in edges {
        let (lo, hi) = (i.min(j), i.max(j));
        cols[hi].push(lo);
    }
    let mut cp = vec![0usize];
    let mut ri = Vec::new();
    for c in &mut cols {
        c.sort_unstable();
        c.dedup();
        ri.extend_from_slice(c);
        cp.push(ri.len());
    }
    faer::sparse::SymbolicSparseColMat::new_checked(n, n, cp, None, ri)
}

/// How a fixed pattern is factorised: one faer factorisation (AMD or nested dissection,
/// sequential or faer's parallel kernels), or two halves side by side ([`two_way`]).
pub(crate) enum Analysis {
    /// One factorisation.
    Single {
        /// faer's analysis.
        symbolic: Box<SymbolicCholesky<usize>>,
        /// Parallelism of its numeric factorisation.
        par: Par,
    },
    /// The two parts of the top-level dissection on two threads.
    TwoWay(Box<two_way::Symbolic>),
}

impl Analysis {
    /// The bytes a factorisation of this analysis allocates ([`SpdFactor::new`]): the factor's
    /// values and faer's scratch (the two-way plan: both halves, their coupling blocks and the
    /// separator's dense factor), known before any of it is allocated.
    pub(crate) fn numeric_bytes(&self) -> u64 {
        let f64s = |n: usize| 8 * n as u64;
        match self {
            Analysis::Single { symbolic, par } => {
                let scratch = StackReq::any_of(&[
                    symbolic.factorize_numeric_llt_scratch::<f64>(*par, Spec::default()),
                    symbolic.solve_in_place_scratch::<f64>(1, *par),
                ]);
                f64s(symbolic.len_val()) + scratch.size_bytes() as u64
            }
            Analysis::TwoWay(s) => s.numeric_bytes(),
        }
    }
}

/// Speed-up of faer's parallel kernels on this machine's two cores, for factors above
/// [`PARALLEL_MIN_FLOPS`] (measured on the largest bench mesh: docs/performance.md).
const PARALLEL_SPEEDUP: f64 = 1.33;
/// Below this many factor flops faer's parallel kernels were slower than sequential ones.
const PARALLEL_MIN_FLOPS: f64 = 2e10;

/// Analyses the upper-triangular pattern `a` of a symmetric positive definite matrix: nested
/// dissection and AMD side by side, then the cheapest of AMD, nested dissection on one
/// factorisation, and nested dissection's two halves on two threads (estimated time: flops on
/// the critical path). From [`ND_ONLY_N`] unknowns on, nested dissection alone. Without
/// The plan depends on the pattern only: its two halves run on two threads where
/// [`crate::parallel::threads`] allows it, one after the other otherwise, with the same result.
///
/// # Errors
/// A message if faer's analysis fails.
pub(crate) fn analyse(a: SymbolicSparseColMatRef<'_, usize>) -> std::result::Result<Analysis, NumericalError> {
    plan(a, true)
}

/// [`analyse`], with or without the two-way plan (tests compare the single ones).
fn plan(a: SymbolicSparseColMatRef<'_, usize>, two_way: bool) -> std::result::Result<Analysis, NumericalError> {
    let n = a.ncols();
    let single = |symbolic: SymbolicCholesky<usize>| {
        let par = parallelism_for(&symbolic);
        Analysis::Single { symbolic: Box::new(symbolic), par }
    };
    let amd = || {
        factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Amd, params(n))
            .map_err(|e| crate::error::NumericalError(format!("symbolic Cholesky: {e:?}")))
    };
    if n < ND_MIN_N {
        return Ok(single(amd()?));
    }
    if let Some(band) = banded(a) {
        return Ok(single(band?));
    }
    let nd = || -> Result<Result<two_way::Symbolic, SymbolicCholesky<usize>>, NumericalError> {
        // the dissection's own second thread only where the factorisation may use one
        let g = Graph::from_pattern(a);
        let (perm, top) = dissection(&g, ND_LEAF, n >= PARALLEL_DISSECTION_MIN);
        if let Some(t) = top.filter(|_| two_way).and_then(|sizes| two_way::Symbolic::new(a, &perm, sizes)) {
            return Ok(Ok(t));
        }
        let inv = inverse(&perm);
        let p = PermRef::new_checked(&perm, &inv, n);
        factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Custom(p), params(n))
            .map(Err)
            .map_err(|e| crate::error::NumericalError(format!("symbolic Cholesky: {e:?}")))
    };
    if n >= ND_ONLY_N {
        // AMD is compared only where there is no two-way split (a disconnected pattern, a
        // forbidden split): the measurements above are against the split
        return Ok(match nd()? {
            Ok(two) => Analysis::TwoWay(Box::new(two)),
            Err(nd) => {
                let amd = amd()?;
                single(if factor_flops(&nd) < factor_flops(&amd) { nd } else { amd })
            }
        });
    }
    let (nd, amd) = crate::parallel::join(nd, amd);
    let (amd, nd) = (amd?, nd?);
    let time = |s: &SymbolicCholesky<usize>| {
        let f = factor_flops(s);
        if f < PARALLEL_MIN_FLOPS {
            f
        } else {
            f / PARALLEL_SPEEDUP
        }
    };
    Ok(match nd {
        Ok(two) if two.critical_flops() < time(&amd) => Analysis::TwoWay(Box::new(two)),
        Ok(_) => single(amd),
        Err(nd) if factor_flops(&nd) < factor_flops(&amd) => single(nd),
        Err(_) => single(amd),
    })
}

/// The cheaper of AMD and nested dissection for one simplicial factorisation of `a` (never
/// supernodal, whose dense kernels faer provides for native floats only, nor the two-way
/// split): for factorisations in double-double arithmetic.
///
/// # Errors
/// A message if faer's analysis fails.
pub(crate) fn analyse_simplicial(
    a: SymbolicSparseColMatRef<'_, usize>,
) -> std::result::Result<SymbolicCholesky<usize>, NumericalError> {
    let n = a.ncols();
    let params = |_| CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: faer::sparse::linalg::SupernodalThreshold::FORCE_SIMPLICIAL,
        ..Default::default()
    };
    let amd = factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Amd, params(n))
        .map_err(|e| format!("symbolic Cholesky: {e:?}"))?;
    if n < ND_MIN_N {
        return Ok(amd);
    }
    if let Some(band) = banded(a) {
        return band;
    }
    let (perm, _) = dissection(&Graph::from_pattern(a), ND_LEAF, false);
    let inv = inverse(&perm);
    let p = PermRef::new_checked(&perm, &inv, n);
    let nd = factorize_symbolic_cholesky(a, Side::Upper, SymmetricOrdering::Custom(p), params(n))
        .map_err(|e| format!("symbolic Cholesky: {e:?}"))?;
    Ok(if factor_flops(&nd) < factor_flops(&amd) { nd } else { amd })
}

/// Numeric storage for one [`Analysis`].
enum Numeric {
    Single { l: Vec<f64>, mem: MemBuffer },
    TwoWay(Box<two_way::TwoWay>),
}

impl Numeric {
    fn new(analysis: &Analysis) -> std::result::Result<Numeric, NumericalError> {
        Ok(match analysis {
            Analysis::Single { symbolic, par } => Numeric::Single {
                l: vec![0.0; symbolic.len_val()],
                mem: MemBuffer::try_new(StackReq::any_of(&[
                    symbolic.factorize_numeric_llt_scratch::<f64>(*par, Spec::default()),
                    symbolic.solve_in_place_scratch::<f64>(1, *par),
                ]))
                .map_err(|_| "out of memory for the Cholesky workspace".to_string())?,
            },
            Analysis::TwoWay(s) => Numeric::TwoWay(Box::new(two_way::TwoWay::new(s)?)),
        })
    }

    /// Writes one value per memory page of the factor's storage, so that the operating system
    /// maps those pages now, beside other work, instead of during the first factorisation (a
    /// million-unknown factor is about a GiB of freshly zeroed pages, whose faults doubled
    /// that factorisation's time).
    fn touch(&mut self) {
        match self {
            Numeric::Single { l, .. } => touch_pages(l),
            Numeric::TwoWay(t) => t.touch(),
        }
    }
}

/// A factorisation's numeric storage made in advance, possibly on another thread
/// ([`Workspace::new`]), with its pages already mapped; [`SpdFactor::with_workspace`] uses it.
pub(crate) struct Workspace(Numeric);

impl Workspace {
    /// Storage for factorisations of `analysis`, every page of the factor's values (and of the
    /// two-way blocks) touched; faer's scratch buffers are left to the first factorisation.
    ///
    /// # Errors
    /// A message if it cannot be allocated.
    pub(crate) fn new(analysis: &Analysis) -> std::result::Result<Workspace, NumericalError> {
        let mut numeric = Numeric::new(analysis)?;
        numeric.touch();
        Ok(Workspace(numeric))
    }
}

/// A Cholesky factorisation of matrices with one analysed pattern: [`SpdFactor::factor`]
/// refactors the values, [`SpdFactor::solve_in_place`] solves with the last factor.
pub(crate) struct SpdFactor {
    analysis: std::sync::Arc<Analysis>,
    numeric: Numeric,
}

impl SpdFactor {
    /// Workspace for `analysis`.
    ///
    /// # Errors
    /// A message if the workspace cannot be allocated.
    pub fn new(analysis: std::sync::Arc<Analysis>) -> std::result::Result<SpdFactor, NumericalError> {
        let numeric = Numeric::new(&analysis)?;
        Ok(SpdFactor { analysis, numeric })
    }

    /// Factorisations of `analysis` in storage made for it by [`Workspace::new`].
    pub(crate) fn with_workspace(analysis: std::sync::Arc<Analysis>, workspace: Workspace) -> SpdFactor {
        SpdFactor { analysis, numeric: workspace.0 }
    }

    /// Factorises `a` (upper triangle, the analysed pattern).
    ///
    /// # Errors
    /// A message if `a` is not numerically positive definite.
    pub fn factor(&mut self, a: SparseColMatRef<'_, usize, f64>) -> std::result::Result<(), NumericalError> {
        match (&*self.analysis, &mut self.numeric) {
            (Analysis::Single { symbolic, par }, Numeric::Single { l, mem }) => symbolic
                .factorize_numeric_llt(l, a, Side::Upper, Default::default(), *par, MemStack::new(mem), Spec::default())
                .map(|_| ())
                .map_err(|e| NumericalError(format!("{e:?}"))),
            (Analysis::TwoWay(s), Numeric::TwoWay(t)) => t.factor(s, a.val()),
            _ => unreachable!("numeric storage made for its analysis"),
        }
    }

    /// Overwrites `b` with `A⁻¹ b` for the last factorised `A`.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        match (&*self.analysis, &mut self.numeric) {
            (Analysis::Single { symbolic, par }, Numeric::Single { l, mem }) => {
                let n = b.len();
                let rhs = faer::MatMut::from_column_major_slice_mut(b, n, 1);
                LltRef::new(symbolic, l).solve_in_place_with_conj(Conj::No, rhs, *par, MemStack::new(mem));
            }
            (Analysis::TwoWay(s), Numeric::TwoWay(t)) => t.solve_in_place(s, b),
            _ => unreachable!("numeric storage made for its analysis"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2-ring stencil on an `nx × ny` grid (the pattern of a bilaplacian).
    fn grid_edges(nx: usize, ny: usize, ring2: bool) -> Vec<(usize, usize)> {
        let mut e = Vec::new();
        let id = |x: usize, y: usize| y * nx + x;
        for y in 0..ny {
            for x in 0..nx {
                let offs: &[(isize, isize)] =
                    if ring2 { &[(1, 0), (0, 1), (1, 1), (1, -1), (2, 0), (0, 2)] } else { &[(1, 0), (0, 1)] };
                for &(dx, dy) in offs {
                    let (x2, y2) = (x as isize + dx, y as isize + dy);
                    if x2 >= 0 && y2 >= 0 && (x2 as usize) < nx && (y2 as usize) < ny {
                        e.push((id(x, y), id(x2 as usize, y2 as usize)));
                    }
                }
            }
        }
        e
    }

    /// [`analyse`] restricted to one factorisation (AMD or nested dissection).
    fn single_analysis(a: SymbolicSparseColMatRef<'_, usize>) -> SymbolicCholesky<usize> {
        match plan(a, false).unwrap() {
            Analysis::Single { symbolic, .. } => *symbolic,
            Analysis::TwoWay(_) => panic!("split forbidden"),
        }
    }

    fn is_permutation(p: &[usize]) -> bool {
        let mut seen = vec![false; p.len()];
        p.iter().all(|&i| i < p.len() && !std::mem::replace(&mut seen[i], true))
    }

    #[test]
    fn dissection_is_a_permutation_including_disconnected_graphs() {
        for (nx, ny, ring2) in [(1, 1, false), (7, 3, true), (40, 30, false), (50, 50, true)] {
            let a = upper_pattern(nx * ny, &grid_edges(nx, ny, ring2));
            let g = Graph::from_pattern(a.as_ref());
            for leaf in [1, 8, 64] {
                assert!(is_permutation(&nested_dissection(&g, leaf)));
            }
        }
        // two grids side by side, plus isolated vertices
        let mut e = grid_edges(20, 20, true);
        e.extend(grid_edges(15, 10, false).into_iter().map(|(i, j)| (i + 400, j + 400)));
        let a = upper_pattern(400 + 150 + 5, &e);
        let g = Graph::from_pattern(a.as_ref());
        assert!(is_permutation(&nested_dissection(&g, 16)));
    }

    #[test]
    fn dissection_on_two_threads_is_the_same_as_on_one() {
        for (nx, ny, ring2) in [(120, 100, true), (90, 70, false)] {
            let a = upper_pattern(nx * ny, &grid_edges(nx, ny, ring2));
            let g = Graph::from_pattern(a.as_ref());
            let (one, top1) = dissection(&g, ND_LEAF, false);
            let (two, top2) = dissection(&g, ND_LEAF, true);
            assert!(is_permutation(&one) && top1.is_some());
            assert_eq!(top1, top2);
            assert!(one == two, "{nx}x{ny}: the orderings differ");
        }
    }

    #[test]
    fn dissection_beats_amd_on_a_grid() {
        let (nx, ny) = (120, 100);
        let a = upper_pattern(nx * ny, &grid_edges(nx, ny, true));
        let perm = nested_dissection(&Graph::from_pattern(a.as_ref()), ND_LEAF);
        let inv = inverse(&perm);
        let p = PermRef::new_checked(&perm, &inv, nx * ny);
        let nd = factorize_symbolic_cholesky(a.as_ref(), Side::Upper, SymmetricOrdering::Custom(p), Default::default())
            .unwrap();
        let amd =
            factorize_symbolic_cholesky(a.as_ref(), Side::Upper, SymmetricOrdering::Amd, Default::default()).unwrap();
        assert!(nd.len_val() < amd.len_val(), "nd {} amd {}", nd.len_val(), amd.len_val());
        assert!(factor_flops(&nd) < factor_flops(&amd));
        let best = single_analysis(a.as_ref());
        assert_eq!(best.len_val(), nd.len_val());
    }

    /// A diagonally dominant SPD matrix on `a`'s pattern with off-diagonal entries of varying
    /// size: values aligned with `a`'s entries.
    fn spd_values(a: SymbolicSparseColMatRef<'_, usize>) -> Vec<f64> {
        let n = a.ncols();
        let (cp, ri) = (a.col_ptr(), a.row_idx());
        let mut deg = vec![0.0; n];
        let off = |i: usize, j: usize| -1.0 - ((i * 7 + j * 3) % 5) as f64 * 0.5;
        for j in 0..n {
            for &i in &ri[cp[j]..cp[j + 1]] {
                if i != j {
                    deg[i] -= off(i, j);
                    deg[j] -= off(i, j);
                }
            }
        }
        (0..n)
            .flat_map(|j| ri[cp[j]..cp[j + 1]].iter().map(move |&i| (i, j)))
            .map(|(i, j)| if i == j { deg[j] + 0.01 } else { off(i, j) })
            .collect()
    }

    /// Largest entry of `b − A x` for `A` given by its upper triangle.
    fn residual(a: SymbolicSparseColMatRef<'_, usize>, vals: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let (cp, ri) = (a.col_ptr(), a.row_idx());
        let mut r = b.to_vec();
        for j in 0..a.ncols() {
            for (p, &i) in ri[cp[j]..cp[j + 1]].iter().enumerate() {
                let v = vals[cp[j] + p];
                r[i] -= v * x[j];
                if i != j {
                    r[j] -= v * x[i];
                }
            }
        }
        r.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn two_way_factorisation_solves_like_one_factorisation() {
        for (nx, ny, ring2) in [(70, 50, true), (90, 40, false), (45, 45, true)] {
            let n = nx * ny;
            let a = upper_pattern(n, &grid_edges(nx, ny, ring2));
            let vals = spd_values(a.as_ref());
            let analysis = analyse(a.as_ref()).unwrap();
            let Analysis::TwoWay(t) = &analysis else { panic!("{nx}x{ny}: a grid is split in two") };
            // the separator is a thin cut: one or two grid lines across
            assert!(t.separator_len() <= 3 * nx.max(ny), "separator {}", t.separator_len());
            let mut f = SpdFactor::new(std::sync::Arc::new(analysis)).unwrap();
            f.factor(SparseColMatRef::new(a.as_ref(), &vals)).unwrap();
            for seed in 0..3 {
                let b: Vec<f64> = (0..n).map(|i| ((i * (seed + 3)) as f64 * 0.37).sin()).collect();
                let mut x = b.clone();
                f.solve_in_place(&mut x);
                let r = residual(a.as_ref(), &vals, &x, &b);
                assert!(r < 1e-9, "{nx}x{ny}: residual {r:e}");
            }
            // not positive definite: an error, not a wrong answer
            let mut bad = vals.clone();
            let diag = a.col_ptr()[n / 2 + 1] - 1;
            bad[diag] = -1.0;
            assert!(f.factor(SparseColMatRef::new(a.as_ref(), &bad)).is_err());
        }
    }

    #[test]
    fn a_disconnected_pattern_is_factorised_whole() {
        // two grids side by side: no top separator, so one factorisation; it still solves
        let mut e = grid_edges(50, 40, true);
        e.extend(grid_edges(30, 30, false).into_iter().map(|(i, j)| (i + 2000, j + 2000)));
        let n = 2000 + 900;
        let a = upper_pattern(n, &e);
        let analysis = analyse(a.as_ref()).unwrap();
        assert!(matches!(analysis, Analysis::Single { .. }));
        let vals = spd_values(a.as_ref());
        let mut f = SpdFactor::new(std::sync::Arc::new(analysis)).unwrap();
        f.factor(SparseColMatRef::new(a.as_ref(), &vals)).unwrap();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).cos()).collect();
        let mut x = b.clone();
        f.solve_in_place(&mut x);
        assert!(residual(a.as_ref(), &vals, &x, &b) < 1e-9);
    }

    #[test]
    fn two_way_split_is_refused_when_the_parts_touch_or_on_request() {
        let (nx, ny) = (60, 40);
        let n = nx * ny;
        let a = upper_pattern(n, &grid_edges(nx, ny, true));
        // parts = first and second half of the rows, "separator" = the last row: they touch
        let perm: Vec<usize> = (0..n).collect();
        assert!(two_way::Symbolic::new(a.as_ref(), &perm, [n / 2, n / 2 - nx]).is_none());
        assert!(matches!(plan(a.as_ref(), false).unwrap(), Analysis::Single { .. }));
    }

    #[test]
    fn the_chosen_ordering_factorises_and_solves() {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::sparse::linalg::cholesky::LltRef;
        use faer::sparse::SparseColMatRef;
        let (nx, ny) = (70, 50);
        let n = nx * ny;
        let a = upper_pattern(n, &grid_edges(nx, ny, true));
        // values: off-diagonal −1, diagonal degree + 1 (SPD, diagonally dominant)
        let (cp, ri) = (a.col_ptr(), a.row_idx());
        let mut deg = vec![0.0; n];
        for j in 0..n {
            for &i in &ri[cp[j]..cp[j + 1]] {
                if i != j {
                    deg[i] += 1.0;
                    deg[j] += 1.0;
                }
            }
        }
        let vals: Vec<f64> = (0..n)
            .flat_map(|j| ri[cp[j]..cp[j + 1]].iter().map(move |&i| (i, j)))
            .map(|(i, j)| if i == j { deg[j] + 1.0 } else { -1.0 })
            .collect();
        let s = single_analysis(a.as_ref());
        assert!(s.perm().is_some());
        let par = faer::Par::Seq;
        let mut l = vec![0.0; s.len_val()];
        let mut mem = MemBuffer::new(s.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
        let mat = SparseColMatRef::new(a.as_ref(), &vals);
        s.factorize_numeric_llt(
            &mut l,
            mat,
            Side::Upper,
            Default::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .unwrap();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x = b.clone();
        let mut mem = MemBuffer::new(s.solve_in_place_scratch::<f64>(1, par));
        LltRef::new(&s, &l).solve_in_place_with_conj(
            faer::Conj::No,
            faer::MatMut::from_column_major_slice_mut(&mut x, n, 1),
            par,
            MemStack::new(&mut mem),
        );
        // residual of the symmetric matrix stored by its upper triangle
        let mut r = b.clone();
        for j in 0..n {
            for (p, &i) in ri[cp[j]..cp[j + 1]].iter().enumerate() {
                let v = vals[cp[j] + p];
                r[i] -= v * x[j];
                if i != j {
                    r[j] -= v * x[i];
                }
            }
        }
        assert!(r.iter().all(|v| v.abs() < 1e-10), "residual {:e}", r.iter().fold(0.0f64, |a, v| a.max(v.abs())));
    }
}
