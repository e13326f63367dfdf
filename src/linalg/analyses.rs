//! What a caller keeps between factorisations: [`Analyses`], the last patterns analysed with
//! their analyses, and [`SpdSolver`], which factors and solves on an analysed pattern.

use super::{analyse, solve_spd_once, Analysis, SpdFactor};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};

/// `solve_spd_once`, or with the analysis taken from and kept in `analyses` when given (a
/// pattern solved again and again: the weight functions' fills and gaps).
///
/// # Errors
/// As `solve_spd_once`.
pub fn solve_spd(
    a: SparseColMatRef<'_, usize, f64>,
    b: &mut [f64],
    analyses: Option<&mut Analyses>,
) -> std::result::Result<(), crate::error::NumericalError> {
    match analyses {
        None => solve_spd_once(a, b),
        Some(analyses) => SpdSolver::new(a.symbolic(), analyses)?.solve(a, b),
    }
}

/// The analyses a sequence of factorisations reuses, held by the caller: the last patterns
/// analysed with their analyses (a run's geodesic distance and harmonic fills share the
/// Laplacian's, the weight functions of a thread their normal matrix's). Nothing is kept
/// anywhere else.
#[derive(Default)]
pub struct Analyses {
    /// Most recent last; at most [`Analyses::KEPT`].
    kept: Vec<(SymbolicSparseColMat<usize>, std::sync::Arc<Analysis>)>,
}

/// Whether two patterns are the same (sizes, column pointers and row indices).
fn same_pattern(a: SymbolicSparseColMatRef<'_, usize>, b: SymbolicSparseColMatRef<'_, usize>) -> bool {
    a.nrows() == b.nrows() && a.col_ptr() == b.col_ptr() && a.row_idx() == b.row_idx()
}

impl Analyses {
    /// Patterns kept at once (a Laplacian, the energy and a normal matrix).
    const KEPT: usize = 3;

    /// An empty store.
    pub fn new() -> Self {
        Analyses::default()
    }

    /// The analysis of `pattern`: a kept one for the same pattern, else a new one, then kept.
    ///
    /// # Errors
    /// A message if the analysis fails or the pattern cannot be copied.
    pub(crate) fn of(
        &mut self,
        pattern: SymbolicSparseColMatRef<'_, usize>,
    ) -> std::result::Result<std::sync::Arc<Analysis>, crate::error::NumericalError> {
        if let Some(at) = self.kept.iter().position(|(q, _)| same_pattern(q.as_ref(), pattern)) {
            let entry = self.kept.remove(at);
            let analysis = entry.1.clone();
            self.kept.push(entry);
            return Ok(analysis);
        }
        let analysis = std::sync::Arc::new(analyse(pattern)?);
        self.keep(pattern.to_owned().map_err(|e| format!("{e:?}"))?, analysis.clone());
        Ok(analysis)
    }

    /// Keeps `analysis` (made elsewhere, e.g. on another thread) as the one of `pattern`.
    pub(crate) fn keep(&mut self, pattern: SymbolicSparseColMat<usize>, analysis: std::sync::Arc<Analysis>) {
        // one entry per pattern: a new analysis of a kept pattern replaces the old one
        self.kept.retain(|(q, _)| !same_pattern(q.as_ref(), pattern.as_ref()));
        if self.kept.len() == Self::KEPT {
            self.kept.remove(0);
        }
        self.kept.push((pattern, analysis));
    }

    /// Drops every kept analysis (a million-vertex Laplacian's is hundreds of MiB).
    pub fn clear(&mut self) {
        self.kept.clear();
    }
}

/// A sparse SPD solver for a fixed pattern: the analysis (`analyse`) is done once, each
/// [`SpdSolver::solve`] refactors the values and solves (for repeated solves with the same
/// pattern and different values).
pub struct SpdSolver {
    f: SpdFactor,
}

impl SpdSolver {
    /// Analyses the upper-triangular pattern, or takes its analysis from `analyses`.
    ///
    /// # Errors
    /// A message if the analysis or the workspace allocation fails.
    pub fn new(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        analyses: &mut Analyses,
    ) -> std::result::Result<Self, crate::error::NumericalError> {
        let analysis = analyses.of(pattern)?;
        Ok(SpdSolver { f: SpdFactor::new(analysis)? })
    }

    /// Factors `a` (upper triangle, the analysed pattern) and overwrites `b` with `a⁻¹ b`.
    ///
    /// # Errors
    /// A message if `a` is not positive definite.
    pub fn solve(
        &mut self,
        a: SparseColMatRef<'_, usize, f64>,
        b: &mut [f64],
    ) -> std::result::Result<(), crate::error::NumericalError> {
        self.f.factor(a)?;
        self.f.solve_in_place(b);
        Ok(())
    }
}
