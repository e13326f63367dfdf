//! The whole method on one field: select the kept extrema, build u, assemble the energy,
//! constrain, solve, repair, certify (paper sections 3.1–3.4).
//!
//! ```
//! use toposmooth::{domain::Series, pipeline::{smooth, SmoothSettings}, topology::Selection};
//! let h: Vec<f64> = (0..40).map(|i| i as f64 + if i % 2 == 0 { 0.3 } else { -0.3 }).collect();
//! let settings = SmoothSettings { selection: Selection::Relative(0.5), ..Default::default() };
//! let out = smooth(&Series::uniform(40), &h, &settings)?;
//! assert!(out.report.certificate.passed);
//! assert!(out.output.windows(2).all(|w| w[0] < w[1])); // the noisy ramp became monotone
//! # Ok::<(), toposmooth::Error>(())
//! ```

use crate::constraints::{
    activity, choose_margin, constraint_edges, margin_cap, max_margin_or_conflict, Activity, EdgeSet,
};
use crate::domain::{sos_sort, Domain, Grid2d, Series, TriMesh};
use crate::error::{Error, Result};
use crate::linalg::Analyses;
use crate::operators::{
    cotan_stiffness, dirichlet_solve, edge_factor, gradient_factor, grid_mass, grid_stiffness, lumped_mass,
    plus_diagonal, polyharmonic, polyharmonic_factor, positive_cotan_stiffness, quadratic_form_without_diagonal,
    series_mass, series_stiffness, Energy, Factor, Sparse,
};
use crate::representative::{flooded_representative, separatrix_representative, series_representative, Repairs};
use crate::solve::{
    condition_estimate, meet_margin, optimality, repair, solve_monotone_qp_with, Bound, Formulation, MarginSummary,
    Method, MonotoneQp, QpSettings, RepairSummary, SolveStatus, FACTORED_ABOVE,
};
use crate::topology::morse_smale::MorseSmale;
use crate::topology::{count_sos_extrema, select, KeptExtremum, KeptSet, Role, Selection};
use crate::verify::{certify, Certificate};
use std::time::Instant;

/// Which representative function to build on surfaces (series always use the linear one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum RepresentativeChoice {
    /// Separatrices interpolated, harmonic elsewhere (paper section 3.3).
    #[default]
    Separatrix,
    /// Harmonic: kept minima at the data's minimum, kept maxima at its maximum.
    Harmonic,
    /// The data itself with every cancelled basin flooded to its spill value (Tierny &
    /// Pascucci 2012; NOTES.md 9), plateaus made strict in flood order.
    Flooded,
}

/// A representative function, the construction that produced it and the complex it used.
#[derive(Clone, Debug)]
pub struct Representative {
    /// Values per vertex.
    pub u: Vec<f64>,
    /// Construction used: `linear`, `separatrix`, `harmonic` or `flooded`.
    pub kind: &'static str,
    /// Construction used, with its variant (one-sided saddles, released vertices).
    pub name: String,
    /// Why each construction tried before it was not used (automatic choice only).
    pub fallbacks: Vec<String>,
    /// The simplified Morse–Smale complex (surfaces).
    pub complex: Option<MorseSmale>,
}

/// A domain the pipeline can smooth on: it supplies its operators and its representative.
pub trait Smoothable: Domain {
    /// Stiffness `K = −L`.
    fn stiffness(&self) -> Sparse;
    /// Lumped mass (diagonal, > 0).
    fn mass(&self) -> Vec<f64>;
    /// The Laplacian of harmonic fills: non-negative weights on the domain's own edges, so
    /// that the maximum principle holds (the energy's stiffness where that already holds).
    fn fill_stiffness(&self) -> Sparse {
        self.own_fill_stiffness().unwrap_or_else(|| self.stiffness())
    }
    /// The fills' Laplacian where it differs from [`Smoothable::stiffness`], else `None`.
    fn own_fill_stiffness(&self) -> Option<Sparse> {
        None
    }
    /// `F₁` with `F₁ᵀF₁ = k` (the stiffness): one row per edge of positive weight, or `None`
    /// when a weight is negative and the domain has no other square root.
    fn stiffness_factor(&self, k: &Sparse) -> Option<Factor> {
        edge_factor(k)
    }
    /// A function with exactly the kept extrema (checked by the pipeline), built by the
    /// first construction in the order `choice` prefers that is not `excluded` (kind and
    /// why: the pipeline excludes one whose order makes the constraints infeasible); `fill`
    /// is [`Smoothable::fill_stiffness`], the factorisations' analyses are in `analyses`.
    fn representative(
        &self,
        h: &[f64],
        kept: &KeptSet,
        choice: Option<RepresentativeChoice>,
        fill: &Sparse,
        excluded: &[(&'static str, String)],
        analyses: &mut Analyses,
    ) -> Result<Representative>;
}

impl Smoothable for Series {
    fn stiffness(&self) -> Sparse {
        series_stiffness(self)
    }
    fn mass(&self) -> Vec<f64> {
        series_mass(self)
    }
    fn representative(
        &self,
        h: &[f64],
        kept: &KeptSet,
        _: Option<RepresentativeChoice>,
        _: &Sparse,
        _: &[(&'static str, String)],
        _: &mut Analyses,
    ) -> Result<Representative> {
        let u = series_representative(self, h, kept)?;
        Ok(Representative { u, kind: "linear", name: "linear".into(), fallbacks: Vec::new(), complex: None })
    }
}

/// The harmonic representative: kept minima at the data's minimum, kept maxima at its
/// maximum, harmonic elsewhere with `k` (non-negative weights: the maximum principle holds).
fn harmonic_representative(h: &[f64], kept: &KeptSet, k: &Sparse) -> std::result::Result<Vec<f64>, String> {
    let (lo, hi) = crate::domain::value_range(h);
    let fixed: Vec<Option<f64>> = kept
        .roles
        .iter()
        .map(|r| match r {
            Role::Min => Some(lo),
            Role::Max => Some(hi),
            _ => None,
        })
        .collect();
    dirichlet_solve(k, &fixed)
}

/// The representative on a triangulated surface (the complex is built either way, for
/// `--complex`). A construction the user chose is built or refused (its check failing is an
/// error naming the vertices); the automatic choice tries the separatrix one, then the
/// harmonic one, then the flooded one (NOTES.md 9), and records why each one before was not
/// used. `k` is the Laplacian of the harmonic fills (non-negative weights).
fn surface_representative<D: Domain>(
    domain: &D,
    h: &[f64],
    kept: &KeptSet,
    choice: Option<RepresentativeChoice>,
    k: &Sparse,
    excluded: &[(&'static str, String)],
    analyses: &mut Analyses,
) -> Result<Representative> {
    let analyses = std::cell::RefCell::new(analyses);
    let mut why: Vec<String> = excluded.iter().map(|(kind, e)| format!("{kind} representative: {e}")).collect();
    let skip = |kind: &str| excluded.iter().any(|(x, _)| *x == kind);
    let complex = match MorseSmale::new(domain, h, kept) {
        Ok(ms) => Some(ms),
        Err(e) => {
            why.push(format!("Morse-Smale complex: {e}"));
            None
        }
    };
    let repairs = std::cell::Cell::new(Repairs::default());
    let one_sided_saddles = std::cell::Cell::new(0);
    let merged_used: std::cell::RefCell<Option<MorseSmale>> = std::cell::RefCell::new(None);
    // the matched saddles first; if u fails its check, once more with the one-sided saddles
    // (a kept boundary extremum's partner is often one: without its separatrices the cells
    // beside it reach along the boundary to values beyond it); then both again with failing
    // kept extrema moved outward instead of released around (few-valued data: a kept minimum
    // beside free vertices the fill holds below it). u is built from the values with their
    // ties broken as the complex broke them (SoS): a saddle and an extremum of equal input
    // value no longer give a flat separatrix.
    let separatrix = |why: &mut Vec<String>| -> Option<Vec<f64>> {
        let matched = complex.as_ref()?;
        let merged = matched.with_one_sided();
        let untied = crate::domain::sos_untied(h);
        let complexes: Vec<&MorseSmale> = std::iter::once(matched).chain(merged.as_ref()).collect();
        let attempts = [false, true].into_iter().flat_map(|moving| complexes.iter().map(move |&ms| (ms, moving)));
        // the failure of the last attempt (the most mended one) is the one reported
        let mut last_failure = None;
        for (ms, move_kept) in attempts {
            match separatrix_representative(domain, &untied, kept, ms, k, move_kept, &mut analyses.borrow_mut()) {
                Ok((u, r)) => {
                    let c = certify(domain, &u, &kept.roles, None);
                    if c.passed {
                        repairs.set(r);
                        if !std::ptr::eq(ms, matched) {
                            // the one-sided saddles are never matched ones
                            one_sided_saddles.set(ms.saddles.len() - matched.saddles.len());
                            *merged_used.borrow_mut() = Some(ms.clone());
                        }
                        return Some(u);
                    }
                    last_failure = Some(format!("separatrix representative: {}", c.summary()));
                }
                Err(e) => last_failure = Some(format!("separatrix representative: {e}")),
            }
        }
        why.extend(last_failure);
        None
    };
    let harmonic = |why: &mut Vec<String>| -> Option<Vec<f64>> {
        match harmonic_representative(h, kept, k) {
            Ok(u) => {
                let c = certify(domain, &u, &kept.roles, None);
                if c.passed {
                    return Some(u);
                }
                why.push(format!("harmonic representative: {}", c.summary()));
            }
            Err(e) => why.push(format!("harmonic representative: {e}")),
        }
        None
    };
    let flooded = |why: &mut Vec<String>| -> Option<Vec<f64>> {
        let u = flooded_representative(domain, h, kept);
        if u.is_none() {
            why.push("flooded representative: the floods did not settle".into());
        }
        u
    };
    let order: &[&'static str] = match choice {
        None => &["separatrix", "harmonic", "flooded"],
        Some(RepresentativeChoice::Separatrix) => &["separatrix"],
        Some(RepresentativeChoice::Harmonic) => &["harmonic"],
        Some(RepresentativeChoice::Flooded) => &["flooded"],
    };
    if choice.is_some() {
        // the complex is only for --complex when the user chose the construction
        why.clear();
    }
    let build = |name: &str, why: &mut Vec<String>| match name {
        "separatrix" => separatrix(why),
        "harmonic" => harmonic(why),
        _ => flooded(why),
    };
    let named = |name: &str| {
        let mut name = name.to_string();
        if name == "separatrix" && one_sided_saddles.get() > 0 {
            name = format!("separatrix with {} one-sided saddles", one_sided_saddles.get());
        }
        if !name.starts_with("separatrix") {
            return name;
        }
        let r = repairs.get();
        let mut changes = Vec::new();
        if r.released > 0 {
            changes.push(format!("{} contradicting separatrix vertices released to the harmonic fill", r.released));
        }
        let plural = |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        if r.moved > 0 {
            changes.push(format!("{} moved outward", plural(r.moved, "kept value", "kept values")));
        }
        if r.pinned > 0 {
            changes.push(format!("{} pinned beside them", plural(r.pinned, "free vertex", "free vertices")));
        }
        if !changes.is_empty() {
            name = format!("{name} ({})", changes.join(", "));
        }
        name
    };
    for &kind in order {
        if skip(kind) {
            continue;
        }
        if let Some(u) = build(kind, &mut why) {
            // --complex writes the separatrices u was built from
            let complex = if kind == "separatrix" { merged_used.take().or(complex) } else { complex };
            return Ok(Representative { u, kind, name: named(kind), fallbacks: why, complex });
        }
    }
    let message = match choice {
        Some(_) => format!("{} (requested explicitly: not replaced by another construction)", why.join("; ")),
        None => why.join("; "),
    };
    Err(Error::Representative { path: None, message })
}

impl Smoothable for TriMesh {
    fn stiffness(&self) -> Sparse {
        cotan_stiffness(self.positions(), self.faces())
    }
    fn mass(&self) -> Vec<f64> {
        lumped_mass(self.positions(), self.faces())
    }
    fn own_fill_stiffness(&self) -> Option<Sparse> {
        Some(positive_cotan_stiffness(self.positions(), self.faces()))
    }
    /// One row per edge when every cotangent weight is ≥ 0, else the area-weighted triangle
    /// gradients (three rows per triangle).
    fn stiffness_factor(&self, k: &Sparse) -> Option<Factor> {
        edge_factor(k).or_else(|| Some(gradient_factor(self.positions(), self.faces())))
    }
    /// As on grids, but the harmonic fills use [`positive_cotan_stiffness`] (`fill`):
    /// cotangent weights of obtuse triangles can be negative and break the maximum principle
    /// the representative relies on (paper section 5).
    fn representative(
        &self,
        h: &[f64],
        kept: &KeptSet,
        choice: Option<RepresentativeChoice>,
        fill: &Sparse,
        excluded: &[(&'static str, String)],
        analyses: &mut Analyses,
    ) -> Result<Representative> {
        surface_representative(self, h, kept, choice, fill, excluded, analyses)
    }
}

impl Smoothable for Grid2d {
    fn stiffness(&self) -> Sparse {
        grid_stiffness(self)
    }
    fn mass(&self) -> Vec<f64> {
        grid_mass(self)
    }
    fn representative(
        &self,
        h: &[f64],
        kept: &KeptSet,
        choice: Option<RepresentativeChoice>,
        fill: &Sparse,
        excluded: &[(&'static str, String)],
        analyses: &mut Analyses,
    ) -> Result<Representative> {
        surface_representative(self, h, kept, choice, fill, excluded, analyses)
    }
}

/// Settings of a smoothing run. Defaults follow SPEC.md.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothSettings {
    /// Which extrema survive. {persistence ≥ 5 % of the range}
    pub selection: Selection,
    /// Smoothness energy: orders, blend weights, sharp vertices. {order 2}
    pub energy: Energy,
    /// γD, weight of the mass-weighted data term Σ M_ii (f_i − h_i)². {1}
    pub data_weight: f64,
    /// γL for every energy term; `None` means ℓ^(2k) per order k. {None}
    pub smooth_weight: Option<f64>,
    /// Smoothing length ℓ as a fraction of the domain's diameter; `None` chooses it from the
    /// domain and the kept extrema ([`default_smooth_length`]). {None}
    pub smooth_length: Option<f64>,
    /// Constraint set. {minimal}
    pub edges: EdgeSet,
    /// Solver settings.
    pub qp: QpSettings,
    /// Representative function on surfaces; `None` chooses automatically (separatrix, then
    /// harmonic, then flooded, each fallback reported). {None}
    pub representative: Option<RepresentativeChoice>,
}

impl Default for SmoothSettings {
    fn default() -> Self {
        SmoothSettings {
            selection: Selection::Relative(0.05),
            energy: Energy::order(2),
            data_weight: 1.0,
            smooth_weight: None,
            smooth_length: None,
            edges: EdgeSet::Minimal,
            qp: QpSettings::default(),
            representative: None,
        }
    }
}

impl SmoothSettings {
    /// Checks the settings.
    pub fn validate(&self) -> Result<()> {
        self.energy.validate()?;
        if !(self.data_weight.is_finite() && self.data_weight >= 0.0) {
            return Err(Error::Usage(format!("--data-weight must be finite and ≥ 0, got {}", self.data_weight)));
        }
        if let Some(w) = self.smooth_weight {
            if !(w.is_finite() && w > 0.0) {
                return Err(Error::Usage(format!("--smooth-weight must be finite and > 0, got {w}")));
            }
        }
        if let Some(l) = self.smooth_length {
            if !(l.is_finite() && l > 0.0) {
                return Err(Error::Usage(format!("--smooth-length must be finite and > 0, got {l}")));
            }
        }
        Ok(())
    }
}

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
    pub selection: String,
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
    /// Interior-point iterations.
    pub solver_iterations: u32,
    /// The solver that produced the point.
    pub solver: Method,
    /// Why the structured solver handed over to Clarabel, if it did.
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
struct FitInputs<'a> {
    p: &'a Sparse,
    data_diag: &'a [f64],
    h: &'a [f64],
    fixed: &'a [bool],
    edges: &'a [(usize, usize)],
    bounds: &'a [Bound],
}

/// The gap bound of the certified output `f` in the field's units: the solver's multipliers
/// (and auxiliary variables) mapped from values scaled to [0, 1] (by `range`, margin `eps`
/// scaled, data weight `gd`, mass `m`).
fn fit_report(
    qp: &FitInputs<'_>,
    f: &[f64],
    sol: &crate::solve::QpSolution,
    factor: Option<&Factor>,
    (range, eps, gd, m): (f64, f64, f64, &[f64]),
) -> FitReport {
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
    FitReport {
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
    }
}

/// A certified result.
#[derive(Clone, Debug)]
pub struct Smoothed {
    /// The output f (certified).
    pub output: Vec<f64>,
    /// The representative u.
    pub u: Vec<f64>,
    /// Role of each vertex.
    pub roles: Vec<Role>,
    /// What was measured.
    pub report: Report,
    /// The simplified Morse–Smale complex the representative was built from (surfaces).
    pub complex: Option<MorseSmale>,
}

/// The energy's matrices, built beside the representative.
struct Operators {
    m: Vec<f64>,
    weights: Vec<f64>,
    data_diag: Vec<f64>,
    factor: Option<Factor>,
    p: Sparse,
    q: Vec<f64>,
    condition: Option<f64>,
}

/// The operators of a domain that do not depend on the field: stiffness, lumped mass and the
/// harmonic fills' Laplacian (stored only where it differs from the stiffness).
pub struct DomainOperators {
    /// `K = −L`.
    pub stiffness: Sparse,
    /// Lumped mass.
    pub mass: Vec<f64>,
    own_fill: Option<Sparse>,
}

impl DomainOperators {
    /// Builds them for `domain`.
    pub fn new<D: Smoothable>(domain: &D) -> Self {
        DomainOperators { stiffness: domain.stiffness(), mass: domain.mass(), own_fill: domain.own_fill_stiffness() }
    }

    /// The harmonic fills' Laplacian ([`Smoothable::fill_stiffness`]).
    pub fn fill(&self) -> &Sparse {
        self.own_fill.as_ref().unwrap_or(&self.stiffness)
    }
}

/// Smooths `h` on `domain` keeping exactly the selected extrema; returns only certified output.
///
/// # Errors
/// Input and usage errors (exit 3, 2), an unrealizable explicit list (3), a representative
/// that fails its check (1), no solver point (4), an output that fails the certificate even
/// after repair (1).
pub fn smooth<D: Smoothable + Sync>(domain: &D, h: &[f64], settings: &SmoothSettings) -> Result<Smoothed> {
    smooth_with(domain, h, settings, &mut Analyses::default())
}

/// [`smooth`] with the factorisations' analyses taken from and kept in `analyses`: the harmonic
/// fills' Laplacian (made, for instance, by the geodesic distance the field came from), and
/// the solver's normal matrix, kept for the next field with the same fixed set. The fills'
/// analysis is dropped before the solve (a million-vertex Laplacian's is hundreds of MiB).
///
/// # Errors
/// As [`smooth`].
pub fn smooth_with<D: Smoothable + Sync>(
    domain: &D,
    h: &[f64],
    settings: &SmoothSettings,
    analyses: &mut Analyses,
) -> Result<Smoothed> {
    settings.validate()?;
    smooth_on(domain, &DomainOperators::new(domain), h, settings, analyses, false)
}

/// The pipeline on a domain whose operators are built; `keep_analyses`: the fills' analysis
/// stays in `analyses` through the solve (else it is dropped first, for memory).
pub(crate) fn smooth_on<D: Smoothable + Sync>(
    domain: &D,
    ops: &DomainOperators,
    h: &[f64],
    settings: &SmoothSettings,
    analyses: &mut Analyses,
    keep_analyses: bool,
) -> Result<Smoothed> {
    let n = domain.n_vertices();
    if h.len() != n {
        return Err(Error::input(format!("the field has {} values, the domain {n} vertices", h.len())));
    }
    if let Some(&v) = settings.energy.sharp.iter().find(|&&v| v >= n) {
        return Err(Error::input(format!("--sharp vertex {v} is out of range (the input has {n} vertices)")));
    }
    let mut seconds = StageSeconds::default();

    let t = Instant::now();
    let kept = select(domain, h, &settings.selection)?;
    let (input_minima, input_maxima) = count_sos_extrema(domain, h);
    seconds.persistence = t.elapsed().as_secs_f64();

    let (ell, smooth_length_rule) = match settings.smooth_length {
        Some(fraction) => (fraction * domain.diameter(), format!("--smooth-length {fraction} of the diameter")),
        None => default_smooth_length(domain, &kept),
    };
    let k = &ops.stiffness;
    let (lo, hi) = crate::domain::value_range(h);
    let range = hi - lo;
    let z: Vec<f64> = h.iter().map(|v| (v - lo) / range).collect();
    let fixed: Vec<Option<f64>> = (0..n).map(|i| kept.roles[i].is_fixed().then_some(z[i])).collect();
    check_fixed_neighbours(domain, h, &kept.roles)?;
    let magnitude = h.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let resolution = (magnitude.next_up() - magnitude) / range;
    // A representative whose order makes the constraints infeasible (the harmonic one can
    // order a high kept minimum below a low kept maximum) gives way to the next construction;
    // for a kept set chosen by persistence the flooded one always fits the data's order.
    let mut representative_stage = || -> Result<_> {
        let mut excluded: Vec<(&'static str, String)> = Vec::new();
        loop {
            let t = Instant::now();
            let rep = domain.representative(h, &kept, settings.representative, ops.fill(), &excluded, analyses)?;
            if let Some(ms) = &rep.complex {
                seconds.complex = ms.seconds[0];
                seconds.simplify = ms.seconds[1];
            }
            let representative_certificate = certify(domain, &rep.u, &kept.roles, None);
            if !representative_certificate.passed {
                return Err(Error::Representative { path: None, message: representative_certificate.summary() });
            }
            seconds.representative += t.elapsed().as_secs_f64() - seconds.complex - seconds.simplify;
            let t = Instant::now();
            let edges = constraint_edges(domain, &rep.u, &fixed, settings.edges);
            let bounds = free_end_bounds(domain, &rep.u, &kept.roles, (lo, hi));
            let scaled: Vec<(usize, f64, bool)> =
                bounds.iter().map(|b| (b.vertex, (b.value - lo) / range, b.upper)).collect();
            let describe = |v: usize| {
                let what = match kept.roles[v] {
                    Role::Min => "kept minimum",
                    Role::Max => "kept maximum",
                    Role::End => "free end",
                    _ => "vertex",
                };
                format!("{what} {v} (value {})", h[v])
            };
            let margins = max_margin_or_conflict(&rep.u, &edges, &fixed, &scaled, Some(margin_cap(1.0, resolution)))
                .map_err(|(a, w)| {
                    Error::infeasible(format!(
                        "its order runs a path upward from the {} to the {}, which is not higher: no strict function with the kept values follows it",
                        describe(a),
                        describe(w)
                    ))
                })
                .and_then(|eps_max| Ok((eps_max, choose_margin(eps_max, 1.0, resolution)?)));
            seconds.constraints += t.elapsed().as_secs_f64();
            match margins {
                Ok((eps_max, eps)) => {
                    let name = (rep.name, rep.fallbacks);
                    return Ok((rep.u, name, rep.complex, representative_certificate, edges, bounds, eps_max, eps));
                }
                Err(e @ Error::Infeasible { .. })
                    if settings.representative.is_none()
                        && settings.selection.by_persistence()
                        && rep.kind != "linear"
                        && rep.kind != "flooded" =>
                {
                    excluded.push((rep.kind, e.to_string()));
                }
                Err(Error::Infeasible { path, message }) if settings.representative.is_some() => {
                    return Err(Error::Infeasible {
                        path,
                        message: format!(
                            "the data cannot follow the {} representative: {message} (it was requested explicitly, so no other construction replaces it)",
                            rep.kind
                        ),
                    })
                }
                Err(e) => return Err(e),
            }
        }
    };
    // The energy and the solver's analysis of its normal matrix need only the kept set: they
    // are built on the other core while the complex and the representative are.
    let operators = || -> Result<Operators> {
        let m = ops.mass.clone();
        let weights: Vec<f64> = settings
            .energy
            .terms
            .iter()
            .map(|&(order, _)| settings.smooth_weight.unwrap_or(ell.powi(2 * order as i32)))
            .collect();
        let q_energy = polyharmonic(k, &m, &settings.energy, &weights);
        let gd = settings.data_weight;
        let data_diag: Vec<f64> = m.iter().map(|mi| gd * mi).collect();
        // P = energy + data diagonal, in the energy's storage (one matrix of the size of a
        // bilaplacian less: 300 MiB at a million vertices)
        let p = plus_diagonal(q_energy, &data_diag);
        let q: Vec<f64> = (0..n).map(|i| -gd * m[i] * z[i]).collect();
        // the factored form where the assembled one would lose the digits the gap needs
        let condition = condition_estimate(&p, &data_diag, &fixed);
        let factored = match (settings.qp.method, settings.qp.formulation) {
            (Method::ClarabelAuxiliary, _) | (_, Formulation::Factored) => true,
            (_, Formulation::Assembled) => false,
            (_, Formulation::Auto) => condition.is_some_and(|c| c > FACTORED_ABOVE),
        };
        // without a data term there is no estimate: the factor is made for a retry should the
        // assembled normal matrix lose its definiteness
        let factor = if factored || condition.is_none() {
            domain.stiffness_factor(k).and_then(|k1| polyharmonic_factor(k, &k1, &m, &settings.energy, &weights))
        } else {
            None
        };
        Ok(Operators { m, weights, data_diag, factor, p, q, condition })
    };
    let (representative_result, (operators_result, operators_seconds, prepared)) = std::thread::scope(|scope| {
        let background = scope.spawn(|| {
            let t = Instant::now();
            let ops = operators();
            let seconds = t.elapsed().as_secs_f64();
            let prepared = match (&ops, settings.qp.method) {
                // a failed analysis is redone (and reported) by the solver itself
                (Ok(o), Method::Structured) if o.factor.is_none() => crate::solve::prepare(&o.p, &fixed).ok(),
                _ => None,
            };
            (ops, seconds, prepared)
        });
        let rep = representative_stage();
        (rep, background.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
    });
    let (
        u,
        (representative, representative_fallbacks),
        complex,
        representative_certificate,
        edges,
        bounds,
        eps_max,
        eps,
    ) = representative_result?;
    let Operators { m, weights, data_diag, factor, p, q, condition } = operators_result?;
    seconds.operators = operators_seconds;
    let gd = settings.data_weight;
    // the fills' Laplacian analysis is not needed again: free it before the solver runs, whose
    // factor storage was made beside the representative (the two together set the peak)
    if !keep_analyses {
        analyses.clear();
    }

    let t = Instant::now();
    let hint: Vec<f64> = u.iter().map(|v| (v - lo) / range).collect();
    let u_margin = edges.iter().map(|&(i, j)| u[j] - u[i]).fold(f64::INFINITY, f64::min);
    let scaled_bounds: Vec<Bound> = bounds.iter().map(|b| Bound { value: (b.value - lo) / range, ..*b }).collect();
    let qp = MonotoneQp {
        p: &p,
        q: &q,
        fixed: &fixed,
        edges: &edges,
        margin: eps,
        bounds: &scaled_bounds,
        data: Some(&data_diag),
        hint: Some(&hint),
        factor: factor.as_ref(),
        condition,
    };
    let sol = solve_monotone_qp_with(&qp, &settings.qp, analyses, prepared)?;
    seconds.solve = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let mut f: Vec<f64> = sol.x.iter().map(|v| lo + range * v).collect();
    let is_fixed: Vec<bool> = kept.roles.iter().map(|r| r.is_fixed()).collect();
    for i in 0..n {
        if is_fixed[i] {
            f[i] = h[i];
        }
    }
    let order = sos_sort(&u);
    // the solver meets its rows to its tolerance: the margin is met exactly first, so that the
    // point is feasible for the QP as written and its gap bound a distance bound; if that
    // cannot be done, strictness alone
    let margin_summary = meet_margin(&mut f, &is_fixed, &edges, &order, eps * range, &bounds);
    let repair_summary = repair(&mut f, &is_fixed, &edges, &order, 0.25 * eps * range);
    seconds.repair = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let certificate = certify(domain, &f, &kept.roles, Some(h));
    seconds.verify = t.elapsed().as_secs_f64();
    if !certificate.passed {
        return Err(Error::Uncertified {
            path: None,
            message: format!(
                "{} (solver {:?} after {} iterations; repair changed {} vertices)",
                certificate.summary(),
                sol.status,
                sol.iterations,
                repair_summary.changed_vertices
            ),
        });
    }

    let fit = fit_report(
        &FitInputs { p: &p, data_diag: &data_diag, h, fixed: &is_fixed, edges: &edges, bounds: &bounds },
        &f,
        &sol,
        factor.as_ref(),
        (range, eps, gd, &m),
    );
    let constraint_activity = activity(&f, &edges, &is_fixed, eps * range);
    let mut warnings = kept.warnings.clone();
    for why in &representative_fallbacks {
        warnings.push(format!("representative fallback (the {representative} one is used): {why}"));
    }
    if constraint_activity.active_fraction > ACTIVE_WARNING {
        warnings.push(format!(
            "{:.0} % of the free vertices sit on an active constraint (largest terrace {} vertices): where the smoothing fights the constraints, lower --smooth-length; where the selection cancels large features, the output is held flat there by design",
            100.0 * constraint_activity.active_fraction,
            constraint_activity.largest_terrace
        ));
    }
    let smoothness = quadratic_form_without_diagonal(&p, &data_diag, &f);
    let data: f64 = gd * (0..n).map(|i| m[i] * (f[i] - h[i]).powi(2)).sum::<f64>();
    let sq: f64 = (0..n).map(|i| (f[i] - h[i]).powi(2)).sum();
    let max_deviation = (0..n).map(|i| (f[i] - h[i]).abs()).fold(0.0, f64::max);
    let report = Report {
        vertices: n,
        input_minima,
        input_maxima,
        settings: RunSettings {
            selection: format!("{:?}", settings.selection),
            threshold: kept.threshold,
            energy: settings.energy.clone(),
            data_weight: gd,
            smooth_weights: weights,
            smooth_length: [ell / domain.diameter(), ell],
            smooth_length_rule,
            edge_set: settings.edges,
            margin: [eps * range, eps_max * range],
            u_margin,
            solver: settings.qp.clone(),
            representative: settings.representative,
        },
        constraints: edges.len(),
        kept: kept.kept.clone(),
        warnings,
        seconds,
        energy: EnergyReport { smoothness, data, total: smoothness + data },
        rms_deviation: (sq / n as f64).sqrt(),
        max_deviation,
        solver_status: sol.status,
        solver_iterations: sol.iterations,
        solver: sol.method,
        solver_fallback: sol.fallback.clone(),
        repair: repair_summary,
        margin_repair: margin_summary,
        fit,
        activity: constraint_activity,
        representative,
        representative_fallbacks,
        representative_certificate,
        certificate,
    };
    Ok(Smoothed { output: f, u, roles: kept.roles, report, complex })
}

/// Fraction of the diameter the default smoothing length starts from.
pub const SMOOTH_LENGTH_FRACTION: f64 = 0.01;
/// The default ℓ is at least this many mean edge lengths (sample spacings).
pub const SMOOTH_LENGTH_EDGES: f64 = 2.0;
/// On series the default ℓ is at most this fraction of the median spacing of consecutive
/// kept extrema (below 1/π: the kept oscillation stays in the pass band at every order).
pub const SMOOTH_LENGTH_KEPT_SPACING: f64 = 0.3;

/// The default smoothing length and the rule that set it (SPEC.md, "Defaults"):
/// `ℓ = max(2 h̄, 1 % of the diameter)` with `h̄` the mean edge length (sample spacing); on a
/// series the 1 % is capped at 0.3 × the median x-distance S between consecutive kept extrema,
/// so that dense kept extrema are not smoothed against: without constraints the energy is the
/// low-pass filter `1/(1 + (ℓω)^{2k})`, and a kept oscillation of half-period S (ω = π/S) stays
/// in its pass band at every order when `πℓ < S`.
pub fn default_smooth_length<D: Domain>(domain: &D, kept: &KeptSet) -> (f64, String) {
    let edges = domain.edges();
    let mean_edge = edges
        .iter()
        .map(|&(i, j)| {
            let (a, b) = (domain.point(i), domain.point(j));
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .sum::<f64>()
        / edges.len().max(1) as f64;
    let diameter = domain.diameter();
    let floor = SMOOTH_LENGTH_EDGES * mean_edge;
    let mut base = SMOOTH_LENGTH_FRACTION * diameter;
    let mut why = format!("1 % of the diameter ({})", short(base));
    if domain.pairing_rule() == crate::domain::PairingRule::Path {
        let mut at: Vec<f64> = kept.kept.iter().map(|k| domain.point(k.index)[0]).collect();
        at.sort_by(f64::total_cmp);
        let mut gaps: Vec<f64> = at.windows(2).map(|w| w[1] - w[0]).collect();
        if !gaps.is_empty() {
            gaps.sort_by(f64::total_cmp);
            let median = gaps[gaps.len() / 2];
            let cap = SMOOTH_LENGTH_KEPT_SPACING * median;
            if cap < base {
                base = cap;
                why = format!("0.3 × the median spacing of the kept extrema ({})", short(median));
            }
        }
    }
    if base < floor {
        (floor, format!("2 mean edge lengths ({}; {why} is shorter)", short(mean_edge)))
    } else {
        (base, why)
    }
}

/// `x` to 4 significant digits.
fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{x:.decimals$}")
}

/// The bounds that keep a series' free ends inside `[lo, hi]`, the input's range (SPEC.md,
/// certificate item 2), where they can bind: an end above its neighbour in u (it rises from a
/// kept minimum) stays below `hi`, one below its neighbour above `lo`.
fn free_end_bounds<D: Domain>(domain: &D, u: &[f64], roles: &[Role], (lo, hi): (f64, f64)) -> Vec<Bound> {
    (0..roles.len())
        .filter(|&v| roles[v] == Role::End)
        .filter_map(|v| {
            let w = domain.neighbors(v).next()?;
            let upper = crate::domain::sos_less(u, w, v);
            Some(Bound { vertex: v, value: if upper { hi } else { lo }, upper })
        })
        .collect()
}

/// Two adjacent fixed vertices of different roles must differ in value (SPEC.md).
fn check_fixed_neighbours<D: Domain>(domain: &D, h: &[f64], roles: &[Role]) -> Result<()> {
    for v in 0..domain.n_vertices() {
        if !roles[v].is_fixed() {
            continue;
        }
        for w in domain.neighbors(v) {
            if w > v && roles[w].is_fixed() && roles[w] != roles[v] && h[w] == h[v] {
                return Err(Error::infeasible(format!(
                    "adjacent kept extrema {v} and {w} have the same value {}: both cannot be strict",
                    h[v]
                )));
            }
        }
    }
    Ok(())
}
