//! The monotone QP: `min ½ fᵀ P f + qᵀ f` with some entries of f fixed and `f_j − f_i ≥ ε`
//! on given pairs; a structured interior-point solver, Clarabel, and the repair of a returned
//! point (NOTES.md 3).
//!
//! This layer knows matrices, vectors and index pairs only: no domain, no mesh.

mod bounded;
mod clarabel;
mod condition;
mod factored;
mod ipm;
mod optimality;
mod qp;
mod repair;

pub use bounded::solve_bounded_partition;
pub use condition::condition_estimate;
pub use ipm::Prepared;
pub use optimality::{optimality, Optimality};
pub use qp::{
    constraint_rows, prepare, solve_monotone_qp, Bound, Formulation, Method, MonotoneQp, QpSettings, QpSolution,
    ReducedQp, Row, SolveStatus, FACTORED_ABOVE,
};
pub use repair::{meet_margin, repair, MarginSummary, RepairSummary};
