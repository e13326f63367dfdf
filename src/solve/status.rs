//! How a solve ended: the status, the solution in the problem's variables, and a back end's
//! raw outcome.

use super::settings::{Formulation, Method};

/// How the solver ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
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
    /// Multipliers (≥ 0) of the constraint rows in [`super::constraint_rows`] order, in the units of
    /// the problem as given.
    pub z: Vec<f64>,
    /// With the factored formulation: the auxiliary variables `t ≈ F f` (the equality rows'
    /// multipliers), for the gap bound.
    pub y: Option<Vec<f64>>,
    /// Solver outcome.
    pub status: SolveStatus,
    /// Interior-point iterations (active-set iteration: outer iterations).
    pub iterations: u32,
    /// Conjugate-gradient iterations over all solves of the active-set iteration (0 otherwise).
    pub inner_iterations: usize,
    /// The solver that produced the point.
    pub method: Method,
    /// The formulation used ([`Formulation::Assembled`] or [`Formulation::Factored`]).
    pub formulation: Formulation,
    /// Condition estimate of `diag(d)^{-½} P diag(d)^{-½}` on the free entries (with a data
    /// term): `1 + λ_max(diag(d)⁻¹ Q)`, by power iteration.
    pub condition: Option<f64>,
    /// Why the structured solver handed over to Clarabel, if it did.
    pub fallback: Option<String>,
    /// The interior-point route's predicted peak (the process's resident memory when it was
    /// predicted plus what the route allocates), when it ran.
    pub predicted_peak: Option<u64>,
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
