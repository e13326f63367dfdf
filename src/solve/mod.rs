//! The monotone QP: `min ½ fᵀ P f + qᵀ f` with some entries of f fixed and `f_j − f_i ≥ ε`
//! on given pairs; a structured interior-point solver, Clarabel, and the repair of a returned
//! point (NOTES.md 3).
//!
//! This layer knows matrices, vectors and index pairs only: no domain, no mesh.

mod bounded;
mod clarabel;
mod ipm;
mod qp;
mod repair;

pub use bounded::solve_bounded_partition;
pub use ipm::Prepared;
pub use qp::{prepare, solve_monotone_qp, Method, MonotoneQp, QpSettings, QpSolution, ReducedQp, SolveStatus};
pub use repair::{repair, RepairSummary};
