//! The monotone QP: `min ½ fᵀ P f + qᵀ f` with some entries of f fixed and `f_j − f_i ≥ ε`
//! on given pairs; a structured interior-point solver, Clarabel, and the repair of a returned
//! point (NOTES.md 3).
//!
//! This layer knows matrices, vectors and index pairs only: no domain, no mesh.

mod active_set;
mod banded;
mod bounded;
mod clarabel;
mod condition;
mod factored;
mod flow;
mod ipm;
mod newton;
mod optimality;
pub mod policy;
mod problem;
mod qp;
mod repair;
mod settings;
mod status;

pub use bounded::solve_bounded_partition;
pub use condition::condition_estimate;
pub use newton::Prepared;
pub use optimality::{optimality, optimality_with, Optimality};
pub use problem::{constraint_rows, Bound, MonotoneQp, Quadratic, Row, SecondOrder};
pub use qp::{prepare, solve_monotone_qp, solve_monotone_qp_with};
pub use repair::{meet_margin, repair, MarginSummary, RepairSummary};
pub use settings::{Formulation, Method, QpSettings, ACTIVE_SET_FROM, DOUBLE_DOUBLE_ABOVE, FACTORED_ABOVE};
pub use status::{QpSolution, SolveStatus};
