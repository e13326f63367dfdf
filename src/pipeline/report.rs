//! What a run measured: stage seconds, the settings used, the fit (gap certificate, active
//! share, terraces) and the certificate.

use crate::constraints::{Activity, EdgeSet};
use crate::operators::{Energy, Factor};
use crate::solve::{
    optimality, Bound, Formulation, MarginSummary, Method, MonotoneQp, QpSettings, RepairSummary, SolveStatus,
};
use crate::topology::KeptExtremum;
use crate::verify::Certificate;

use super::smoothable::RepresentativeChoice;

/// Active fraction above which a run warns that the smoothing fights the constraints.
pub const ACTIVE_WARNING: f64 = 0.25;

/// Seconds per stage.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct StageSeconds {
    /// Persistence and selection of the kept set.
    pub persistence: f64,
    /// Discrete gradients of the input (surfaces).
    pub complex: f64,
    /// Their simplification to the kept set (surfaces).
    pub simplify: f64,
    /// Representative function and its check (complex excluded).
    pub representative: f64,
    /// Stiffness, mass and energy matrices.
    pub operators: f64,
    /// Constraint edges and margin.
    pub constraints: f64,
    /// QP solve.
    pub solve: f64,
    /// Rounding repair.
    pub repair: f64,
    /// Certificate.
    pub verify: f64,
}

/// Energies of the output.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct EnergyReport {
    /// Σ γ_k w_k E_k(f).
    pub smoothness: f64,
    /// γD Σ M_ii (f_i − h_i)².
    pub data: f64,
    /// Their sum (the objective).
    pub total: f64,
}

/// The settings of a run as the report records them.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RunSettings {
    /// The selection as given.
    pub selection: crate::topology::Selection,
    /// Absolute persistence threshold applied, if any.
    pub threshold: Option<f64>,
    /// Smoothness energy: orders, weights, sharp vertices.
    pub energy: Energy,
    /// γD.
    pub data_weight: f64,
    /// γ per energy term.
    pub smooth_weights: Vec<f64>,
    /// ℓ as a fraction of the diameter, and in the domain's units.
    pub smooth_length: [f64; 2],
    /// How ℓ was chosen.
    pub smooth_length_rule: String,
    /// Constraint set.
    pub edge_set: EdgeSet,
    /// Margin ε (in the field's units) and the largest feasible one (a lower bound, twice the
    /// cap, when that was already feasible).
    pub margin: [f64; 2],
    /// Smallest increment of u along a constrained edge (field units): u itself is a feasible
    /// point of the QP when this is ≥ the margin (the QP is feasible either way).
    pub u_margin: f64,
    /// Solver settings as requested.
    pub solver: QpSettings,
    /// Representative requested (surfaces; `null`: automatic).
    pub representative: Option<RepresentativeChoice>,
}

/// Everything a run measured, written by `--report`.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Report {
    /// Number of samples or vertices.
    pub vertices: usize,
    /// SoS minima of the input.
    pub input_minima: usize,
    /// SoS maxima of the input (series ends included).
    pub input_maxima: usize,
    /// The settings the run used, with the derived values.
    pub settings: RunSettings,
    /// Number of constrained edges.
    pub constraints: usize,
    /// Kept extrema.
    pub kept: Vec<KeptExtremum>,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Seconds per stage.
    pub seconds: StageSeconds,
    /// Energies of the output.
    pub energy: EnergyReport,
    /// Root mean square of f − h.
    pub rms_deviation: f64,
    /// Largest |f − h|.
    pub max_deviation: f64,
    /// Solver outcome.
    pub solver_status: SolveStatus,
    /// Interior-point iterations (the active-set iteration: outer iterations).
    pub solver_iterations: u32,
    /// Conjugate-gradient iterations of the active-set iteration (0 for the others).
    pub solver_inner_iterations: usize,
    /// The solver that produced the point.
    pub solver: Method,
    /// Why the first solver handed over (to Clarabel, or from the active-set iteration to
    /// the structured solver), if it did.
    pub solver_fallback: Option<String>,
    /// What the repair of strictness changed (after the margin was met, nothing).
    pub repair: RepairSummary,
    /// What meeting the margin exactly changed (the solver meets it to its tolerance).
    pub margin_repair: MarginSummary,
    /// How close the output is to the QP's optimum.
    pub fit: FitReport,
    /// How much of the output the constraints hold (active edges: a rise below 10 margins).
    pub activity: Activity,
    /// Which representative was used.
    pub representative: String,
    /// Why each automatic choice before it was not used (empty when the first one was).
    pub representative_fallbacks: Vec<String>,
    /// Certificate of u (items 1, 2, 4).
    pub representative_certificate: Certificate,
    /// Certificate of the output (items 1–4).
    pub certificate: Certificate,
    /// The memory budget and what the run used of it.
    pub memory: MemoryReport,
}

/// The memory budget and the process's memory around the solve.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MemoryReport {
    /// The budget, bytes.
    pub budget: u64,
    /// Where the budget comes from (the limit given, the cgroup's, ulimit -v, the machine's).
    pub budget_source: String,
    /// The interior-point route's predicted peak (resident memory then plus what it
    /// allocates), bytes, when it ran.
    pub predicted_peak: Option<u64>,
    /// The process's peak resident memory when the solve ended, bytes (0 where unknown).
    pub peak_after_solve: u64,
}

/// How close the output is to the optimum of the QP it solves (SPEC.md, end of "Exit status"),
/// in the units of [`EnergyReport`]: `J(f) = Σ γ_k w_k E_k(f) + γD Σ M_ii (f_i − h_i)²`.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct FitReport {
    /// Ĝ ≥ J(f) − J*, from the multipliers and the residual (no solve); `null` when some free
    /// vertex has no data weight.
    pub gap: Option<f64>,
    /// Ĝ ÷ the data term of f.
    pub gap_over_data: Option<f64>,
    /// Without a data term (`--data-weight 0`): the gap `sᵀz + ½ρᵀP⁻¹ρ` (one solve with the
    /// energy's matrix) ÷ the energy of f.
    pub gap_over_energy: Option<f64>,
    /// ‖f − f*‖_M ≤ √(Ĝ / γD) (mass-weighted; `null` when the output is not feasible for the
    /// QP as written, see `why_no_bound`).
    pub distance_bound: Option<f64>,
    /// The bound as a root-mean-square distance (÷ √ΣM) relative to the value range: what
    /// "optimal to" means in the summary.
    pub relative_distance_bound: Option<f64>,
    /// The smallest slack `f_j − f_i − ε` over the constrained edges (and bounds), in the
    /// field's units.
    pub min_slack: f64,
    /// `max(0, −min_slack)`: how far the output violates the QP's rows.
    pub primal_residual: f64,
    /// `√(rᵀM⁻¹r / (4 γD))` for the stationarity residual r = ∇J(f) + Aᵀz (in √J units).
    pub dual_residual: f64,
    /// Complementarity `sᵀz` (J units).
    pub complementarity: f64,
    /// Condition estimate of the QP's matrix scaled by the data term (`1 + 4^k (ℓ/h)^{2k}`
    /// for one order k; `null` without a data weight everywhere).
    pub condition: Option<f64>,
    /// `assembled` or `factored`.
    pub formulation: Formulation,
    /// Why no distance is claimed, if none is.
    pub why_no_bound: Option<String>,
}

impl FitReport {
    /// One line for the summary: "optimal to X of the range" or why not.
    pub fn summary(&self) -> String {
        let cond = self.condition.map(|c| format!(", condition {c:.1e}")).unwrap_or_default();
        let form = match self.formulation {
            Formulation::Factored => ", factored",
            _ => "",
        };
        match (self.relative_distance_bound, self.gap_over_data) {
            (Some(d), Some(g)) => format!(
                "optimal to {d:.1e} of the range (RMS distance to the QP's optimum, certified: gap bound {:.2e} = {g:.1e} × the data term{cond}{form})",
                self.gap.unwrap_or(0.0)
            ),
            (None, Some(g)) => format!(
                "gap bound {:.2e} = {g:.1e} × the data term, no distance claimed: {}{cond}{form}",
                self.gap.unwrap_or(0.0),
                self.why_no_bound.as_deref().unwrap_or("")
            ),
            (None, None) if self.gap_over_energy.is_some() => format!(
                "gap {:.2e} = {:.1e} × the energy (no data term; {}){cond}{form}",
                self.gap.unwrap_or(0.0),
                self.gap_over_energy.unwrap_or(0.0),
                self.why_no_bound.as_deref().unwrap_or("")
            ),
            _ => format!("no optimality bound: {}{cond}{form}", self.why_no_bound.as_deref().unwrap_or("")),
        }
    }
}

/// The QP in the field's units, for [`fit_report`].
pub(super) struct FitInputs<'a> {
    pub(super) p: crate::solve::Quadratic<'a>,
    pub(super) data_diag: &'a [f64],
    pub(super) h: &'a [f64],
    pub(super) fixed: &'a [bool],
    pub(super) edges: &'a [(usize, usize)],
    pub(super) bounds: &'a [Bound],
}

/// The gap bound of the certified output `f` in the field's units: the solver's multipliers
/// (and auxiliary variables) mapped from values scaled to [0, 1] (by `range`, margin `eps`
/// scaled, data weight `gd`, mass `m`); with `fᵀ(P − diag(data))f` where its pass made it.
pub(super) fn fit_report(
    qp: &FitInputs<'_>,
    f: &[f64],
    sol: &crate::solve::QpSolution,
    factor: Option<&Factor>,
    (range, eps, gd, m): (f64, f64, f64, &[f64]),
) -> (FitReport, Option<f64>) {
    let n = f.len();
    let q: Vec<f64> = (0..n).map(|i| -qp.data_diag[i] * qp.h[i]).collect();
    let fixed: Vec<Option<f64>> = (0..n).map(|i| qp.fixed[i].then_some(qp.h[i])).collect();
    let problem = MonotoneQp {
        p: qp.p,
        q: &q,
        fixed: &fixed,
        edges: qp.edges,
        margin: eps * range,
        bounds: qp.bounds,
        data: Some(qp.data_diag),
        hint: None,
        factor: sol.y.as_ref().and(factor),
        condition: sol.condition,
        second_order: None,
    };
    // multipliers and t = F f scale with the values (f = lo + range·x; F·1 = 0 up to the
    // rounding of F's entries, which is left in ½‖F f − y‖²: carried into y it would enter ρ
    // through Fᵀ, amplified by ‖F‖)
    let z: Vec<f64> = sol.z.iter().map(|v| v * range).collect();
    let y: Option<Vec<f64>> = sol.y.as_ref().map(|y| y.iter().map(|t| t * range).collect());
    let o = optimality(&problem, f, &z, y.as_deref());
    let bounded = o.gap.is_finite();
    let mass: f64 = (0..n).filter(|&i| !qp.fixed[i]).map(|i| m[i]).sum();
    // J = 2φ + const, so Ĝ_J = 2 Ĝ_φ; ‖f − f*‖_M = ‖f − f*‖_D / √γD ≤ √(2 Ĝ_φ / γD)
    let distance = o.distance.filter(|_| gd > 0.0 && !o.by_solve).map(|d| d / gd.sqrt());
    let why_no_bound = if !bounded {
        Some("the energy's matrix could not be solved with (no data term)".to_string())
    } else if o.by_solve {
        Some("without a data term the distance is bounded in the energy's norm only".to_string())
    } else if o.min_slack < 0.0 {
        Some(format!(
            "the output violates a constraint row by {:.1e} (rounding at the margin), so it is not feasible for the QP as written",
            -o.min_slack
        ))
    } else {
        None
    };
    let report = FitReport {
        gap: bounded.then_some(2.0 * o.gap),
        gap_over_data: (bounded && o.data > 0.0).then(|| o.gap / o.data),
        gap_over_energy: (bounded && o.by_solve && o.energy > 0.0).then(|| o.gap / o.energy),
        distance_bound: distance,
        relative_distance_bound: distance.map(|d| d / mass.max(f64::MIN_POSITIVE).sqrt() / range),
        min_slack: o.min_slack,
        primal_residual: (-o.min_slack).max(0.0),
        dual_residual: o.dual_residual,
        complementarity: 2.0 * o.complementarity,
        condition: sol.condition,
        formulation: sol.formulation,
        why_no_bound,
    };
    (report, o.smoothness)
}
