//! The monotone QP: `min ½ fᵀ P f + qᵀ f` with some entries of f fixed and `f_j − f_i ≥ ε`
//! on given pairs, solved by Clarabel; and the repair of a returned point (NOTES.md 3).
//!
//! This layer knows matrices, vectors and index pairs only: no domain, no mesh.

mod qp;
mod repair;

pub use qp::{solve_monotone_qp, MonotoneQp, QpSettings, QpSolution, SolveStatus};
pub use repair::{repair, RepairSummary};
