//! How the QP is solved: the solver, the formulation, the tolerances.

/// Which interior-point solver runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Method {
    /// The active-set iteration on volumes of at least [`ACTIVE_SET_FROM`] vertices, the
    /// structured solver elsewhere (chosen by the pipeline; the solver alone treats it as
    /// structured).
    Auto,
    /// The structured interior-point solver (normal equations, faer Cholesky with the
    /// symbolic analysis done once); Clarabel takes over if it does not converge.
    Structured,
    /// Clarabel on the full KKT system, in the formulation the structured solver would use.
    Clarabel,
    /// Clarabel on the factored formulation whatever the conditioning (the paper's appendix:
    /// variables (f, t) with t = F f as equality constraints; needs the energy's factor F).
    #[cfg_attr(feature = "serde", serde(rename = "clarabel-auxiliary"))]
    ClarabelAuxiliary,
    /// The active-set iteration with conjugate gradients: nothing factorised (volumes); needs
    /// a data term at every free entry. The structured solver takes over if it cannot run or
    /// does not converge (docs/volumes.md, "Speed").
    #[cfg_attr(feature = "serde", serde(rename = "active-set"))]
    ActiveSet,
}

named_enum!(
    Method,
    "solver",
    [
        (Method::Auto, "auto"),
        (Method::Structured, "structured"),
        (Method::Clarabel, "clarabel"),
        (Method::ClarabelAuxiliary, "clarabel-auxiliary"),
        (Method::ActiveSet, "active-set"),
    ]
);

/// How the objective enters the solver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Formulation {
    /// Factored when the condition estimate of P exceeds 10⁹ (`FACTORED_ABOVE`) and a
    /// factor is given, else assembled.
    #[default]
    Auto,
    /// P as one matrix: normal equations in double precision.
    Assembled,
    /// P = FᵀF + diag(d): the structured solver forms its normal matrix from F in
    /// double-double arithmetic and keeps the iterate in it; Clarabel gets the auxiliary
    /// variables t = F f.
    Factored,
}

named_enum!(
    Formulation,
    "formulation",
    [(Formulation::Auto, "auto"), (Formulation::Assembled, "assembled"), (Formulation::Factored, "factored")]
);

/// Condition estimate of `diag(d)^{-½} P diag(d)^{-½}` above which [`Formulation::Auto`]
/// chooses the factored form. An assembled P carries rounding errors of about `10⁻¹⁶ κ`
/// relative to its smallest eigenvalues, and the gap bound squares the gradient's: at κ = 10⁹
/// that is `10⁻¹⁴` of the data term, ample; at 10¹¹ it reaches the bound's target (10⁻⁷ of it).
pub const FACTORED_ABOVE: f64 = 1e9;

/// Condition estimate above which the factored form's interior-point iteration keeps its
/// iterate, slacks and multipliers in double-double; up to it they are kept in double and only
/// the gradient is formed in double-double ([`Formulation::Factored`]), at 2–3× the assembled
/// form's cost instead of about 10×. Measured on a random walk of 3·10⁵ samples (1 % kept):
/// at κ = 8·10⁹ and 1.3·10¹¹ both ways reach the same gap (6.9·10⁻⁸ and 2.0·10⁻⁷ of the data
/// term; the assembled form 1.4·10⁻⁶ at 1.3·10¹¹); at 3.6·10¹² (3·10⁶ samples) the double
/// iteration stalled at 2.4·10⁻⁵, and at 10¹³ its normal matrix lost definiteness (the
/// multipliers, of size κ·d·|x|, resolved in double only to 10⁻¹⁶ of that: `factored::Rounded`).
pub const DOUBLE_DOUBLE_ABOVE: f64 = 1e11;

/// Vertices from which [`Method::Auto`] takes the active-set iteration on a volume, whose
/// direct factorisation fills in as a 3D nested dissection does: on the bench volumes it is
/// faster from 8³ on (0.016 s against 0.028 s; 16³ 0.31 s against 1.0 s; 32³ 3.1 s against
/// 20.9 s; docs/volumes.md), and below 1,000 vertices both take milliseconds.
pub const ACTIVE_SET_FROM: usize = 1_000;

/// Solver settings.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct QpSettings {
    /// Largest number of interior-point iterations. {200}
    pub max_iter: u32,
    /// Feasibility tolerance on the scaled problem (values in [0, 1]). {1e-9}
    pub tolerance: f64,
    /// The structured solver stops when the gap bound is below this fraction of the data
    /// term (without a data term: of the objective's range, by the mean complementarity).
    /// {3e-7: a third of the target, 10⁻⁶, for what the output's rounding and the repair add}
    pub gap_tolerance: f64,
    /// Solver. {auto}
    pub method: Method,
    /// Formulation. {auto}
    pub formulation: Formulation,
    /// The memory budget in bytes; `None`: the machine's ([`crate::memory::machine_budget`]).
    /// A route predicted past it is refused before its work. {None}
    pub memory_limit: Option<u64>,
}

impl Default for QpSettings {
    fn default() -> Self {
        QpSettings {
            max_iter: 200,
            tolerance: 1e-9,
            gap_tolerance: 3e-7,
            method: Method::Auto,
            formulation: Formulation::Auto,
            memory_limit: None,
        }
    }
}
