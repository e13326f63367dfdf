//! The stages of [`super::smooth`] between the kept set and the report: the representative
//! ordered into constraints with their margin, the energy's matrices, the solver's point made
//! an output, and the report of a certified run. The QP is solved on values scaled to the
//! input's range ([`Scale`]); everything here maps between the two once.

use super::report::{
    fit_report, EnergyReport, FitInputs, MemoryReport, Report, RunSettings, StageSeconds, ACTIVE_WARNING,
};
use super::settings::SmoothSettings;
use super::smoothable::{energy_on_edges, RepresentativeKind, Smoothable};
use crate::constraints::{activity, choose_margin, constraint_edges, margin_cap, max_margin_along};
use crate::domain::{sos_sort, Domain};
use crate::error::{Error, Result};
use crate::linalg::Analyses;
use crate::operators::{plus_diagonal, polyharmonic_factor, polyharmonic_products, BilaplacianColumns, Factor, Sparse};
use crate::solve::{
    condition_estimate, meet_margin, repair, Bound, Formulation, MarginSummary, Method, QpSolution, Quadratic,
    RepairSummary, SolveStatus, FACTORED_ABOVE,
};
use crate::topology::morse_smale::MorseSmale;
use crate::topology::{KeptSet, Role};
use crate::verify::{certify, Certificate};
use std::time::Instant;

/// The map between the field's values and the unit range `[0, 1]` of the input, where the QP,
/// its margin and the bounds live.
#[derive(Clone, Copy, Debug)]
pub(super) struct Scale {
    lo: f64,
    hi: f64,
    range: f64,
}

impl Scale {
    /// The input's range (a constant field was refused by the selection).
    fn of(h: &[f64]) -> Self {
        let (lo, hi) = crate::domain::value_range(h);
        Scale { lo, hi, range: hi - lo }
    }

    /// A value in units of the input's range.
    pub(super) fn unit(self, v: f64) -> f64 {
        (v - self.lo) / self.range
    }

    /// A unit value back in the field's units.
    fn value(self, x: f64) -> f64 {
        self.lo + self.range * x
    }
}

/// What every stage reads: the field, the kept set, the fixed values and the scale.
pub(super) struct Problem<'a> {
    pub(super) h: &'a [f64],
    pub(super) kept: &'a KeptSet,
    /// The field in units of its range.
    z: Vec<f64>,
    /// The kept extrema's values in units of the range, `None` elsewhere.
    pub(super) fixed: Vec<Option<f64>>,
    pub(super) scale: Scale,
    /// One unit in the last place of the largest |value|, in units of the range: the margin's
    /// floor.
    resolution: f64,
}

impl<'a> Problem<'a> {
    pub(super) fn new(h: &'a [f64], kept: &'a KeptSet) -> Self {
        let scale = Scale::of(h);
        let z: Vec<f64> = h.iter().map(|&v| scale.unit(v)).collect();
        let fixed = (0..h.len()).map(|i| kept.roles[i].is_fixed().then_some(z[i])).collect();
        let magnitude = h.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let resolution = (magnitude.next_up() - magnitude) / scale.range;
        Problem { h, kept, z, fixed, scale, resolution }
    }
}

/// A representative with the constraints its order gives and their margin.
pub(super) struct Ordered {
    pub(super) u: Vec<f64>,
    /// The construction, with its variant.
    pub(super) name: String,
    /// Why each construction tried before it was not used.
    fallbacks: Vec<String>,
    pub(super) complex: Option<MorseSmale>,
    certificate: Certificate,
    pub(super) edges: Vec<(usize, usize)>,
    /// Free ends' bounds in the field's units.
    pub(super) bounds: Vec<Bound>,
    /// The largest margin the order allows, and the one used (units of the range).
    eps_max: f64,
    pub(super) eps: f64,
    /// The vertices in u's order where the representative handed them over (else the
    /// output's repair sorts u again).
    order: Option<Vec<usize>>,
}

/// Builds the representative and its constraints. A representative whose order makes the
/// constraints infeasible (the harmonic one can order a high kept minimum below a low kept
/// maximum) gives way to the next construction; for a kept set chosen by persistence the
/// flooded one always fits the data's order.
pub(super) fn order_representative<D: Smoothable>(
    domain: &D,
    p: &Problem,
    settings: &SmoothSettings,
    fill: &Sparse,
    analyses: &mut Analyses,
    seconds: &mut StageSeconds,
) -> Result<Ordered> {
    let (h, kept) = (p.h, p.kept);
    let mut excluded: Vec<(RepresentativeKind, String)> = Vec::new();
    loop {
        let t = Instant::now();
        let rep = domain.representative(h, kept, settings.representative, fill, &excluded, analyses)?;
        if let Some(ms) = &rep.complex {
            seconds.complex = ms.seconds[0];
            seconds.simplify = ms.seconds[1];
        }
        let certificate = match rep.certificate {
            Some(c) => c,
            None => certify(domain, &rep.u, &kept.roles, None),
        };
        if !certificate.passed {
            return Err(Error::Representative { path: None, message: certificate.summary() });
        }
        seconds.representative += t.elapsed().as_secs_f64() - seconds.complex - seconds.simplify;
        let t = Instant::now();
        let edges = constraint_edges(domain, &rep.u, &p.fixed, settings.edges);
        let bounds = free_end_bounds(domain, &rep.u, &kept.roles, (p.scale.lo, p.scale.hi));
        let margins = margins(p, &rep.u, rep.order.as_deref(), &edges, &bounds);
        seconds.constraints += t.elapsed().as_secs_f64();
        match margins {
            Ok((eps_max, eps)) => {
                return Ok(Ordered {
                    u: rep.u,
                    name: rep.name,
                    fallbacks: rep.fallbacks,
                    complex: rep.complex,
                    certificate,
                    edges,
                    bounds,
                    eps_max,
                    eps,
                    order: rep.order,
                })
            }
            Err(e @ Error::Infeasible { .. })
                if settings.representative.is_none()
                    && settings.selection.by_persistence()
                    && !matches!(rep.kind, RepresentativeKind::Linear | RepresentativeKind::Flooded) =>
            {
                excluded.push((rep.kind, e.to_string()));
            }
            Err(Error::Infeasible { path, at, message }) if settings.representative.is_some() => {
                return Err(Error::Infeasible {
                    path,
                    at,
                    message: format!(
                        "the data cannot follow the {} representative: {message} (it was requested explicitly, so no other construction replaces it)",
                        rep.kind
                    ),
                })
            }
            Err(e) => return Err(e),
        }
    }
}

/// The vertices in u's order: `given` where the representative handed it over, else sorted.
fn sos_order<'a>(u: &[f64], given: Option<&'a [usize]>) -> std::borrow::Cow<'a, [usize]> {
    given.map_or_else(|| std::borrow::Cow::Owned(sos_sort(u)), std::borrow::Cow::Borrowed)
}

/// The largest margin the order of `u` allows on `edges` and the one used, or the path that
/// makes the order infeasible.
fn margins(
    p: &Problem,
    u: &[f64],
    order: Option<&[usize]>,
    edges: &[(usize, usize)],
    bounds: &[Bound],
) -> Result<(f64, f64)> {
    let unit_bounds: Vec<(usize, f64, bool)> =
        bounds.iter().map(|b| (b.vertex, p.scale.unit(b.value), b.upper)).collect();
    let describe = |v: usize| {
        let what = match p.kept.roles[v] {
            Role::Min => "kept minimum",
            Role::Max => "kept maximum",
            Role::End => "free end",
            _ => "vertex",
        };
        format!("{what} {v} (value {})", p.h[v])
    };
    let eps_max = max_margin_along(&sos_order(u, order), edges, &p.fixed, &unit_bounds, Some(margin_cap(1.0, p.resolution)))
        .map_err(|(a, w)| {
            Error::infeasible(format!(
                "its order runs a path upward from the {} to the {}, which is not higher: no strict function with the kept values follows it",
                describe(a),
                describe(w)
            ))
        })?;
    Ok((eps_max, choose_margin(eps_max, 1.0, p.resolution)?))
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

/// The QP's matrix P: stored, or — for the active set on an energy of one term of order 2,
/// which makes its own forms of P once — made column by column as it is read (the same bits;
/// at 128³ the stored one was 850 MB held through the solve, 42 % of its heap).
pub(super) enum EnergyMatrix<'a> {
    Stored(Sparse),
    Columns(BilaplacianColumns<'a>),
}

impl EnergyMatrix<'_> {
    /// P as the solvers read it.
    pub(super) fn quadratic(&self) -> Quadratic<'_> {
        match self {
            EnergyMatrix::Stored(p) => Quadratic::Stored(p),
            EnergyMatrix::Columns(c) => Quadratic::Columns(c),
        }
    }

    /// The stored matrix, if it is one.
    pub(super) fn stored(&self) -> Option<&Sparse> {
        match self {
            EnergyMatrix::Stored(p) => Some(p),
            EnergyMatrix::Columns(_) => None,
        }
    }
}

/// The energy's matrices, built beside the representative.
pub(super) struct Operators<'a> {
    weights: Vec<f64>,
    pub(super) data_diag: Vec<f64>,
    pub(super) factor: Option<Factor>,
    pub(super) p: EnergyMatrix<'a>,
    pub(super) q: Vec<f64>,
    pub(super) condition: Option<f64>,
    /// `s` with the energy `K diag(s) K` where it is of order 2 and the active set runs
    /// (its products then take two passes over K: [`crate::solve::SecondOrder`]).
    pub(super) row_scale: Option<Vec<f64>>,
}

/// The QP's objective for smoothing length `ell`: `P` = the energy plus the data diagonal
/// (in the energy's storage: one matrix of the size of a bilaplacian less, 300 MiB at a
/// million vertices; for the active set on one order-2 term not stored at all, its columns
/// made from `k` and `m` as they are read), `q`, and the factor `P = FᵀF + diag(d)` where the
/// assembled form would lose the digits the gap needs.
pub(super) fn build_operators<'a, D: Smoothable>(
    domain: &D,
    (k, m): (&'a Sparse, &'a [f64]),
    settings: &SmoothSettings,
    ell: f64,
    problem: &Problem,
) -> Result<Operators<'a>> {
    let n = m.len();
    let weights: Vec<f64> = settings
        .energy
        .terms
        .iter()
        .map(|&(order, _)| settings.smooth_weight.unwrap_or(ell.powi(2 * order as i32)))
        .collect();
    let gd = settings.data_weight;
    let data_diag: Vec<f64> = m.iter().map(|mi| gd * mi).collect();
    // the interior-point routes analyse P's pattern as the normal matrix's, which must hold
    // every constrained pair (every edge); the active set needs only P's non-zero products,
    // and of an energy of one order-2 term not even those stored; nor does a series, whose
    // solver reads P once into its band (its bilaplacian's pattern holds every edge)
    let active_set = settings.qp.method == Method::ActiveSet;
    let series = domain.pairing_rule() == crate::domain::PairingRule::Path;
    let made = (active_set || series).then(|| BilaplacianColumns::new(k, m, &settings.energy, &weights, &data_diag));
    let p = match made.flatten() {
        Some(columns) => EnergyMatrix::Columns(columns),
        None => {
            let q_energy = if active_set {
                polyharmonic_products(k, m, &settings.energy, &weights)
            } else {
                energy_on_edges(domain, k, m, &settings.energy, &weights)
            };
            EnergyMatrix::Stored(plus_diagonal(q_energy, &data_diag))
        }
    };
    let q: Vec<f64> = (0..n).map(|i| -gd * m[i] * problem.z[i]).collect();
    let condition = condition_estimate(p.quadratic(), &data_diag, &problem.fixed);
    let factored = match (settings.qp.method, settings.qp.formulation) {
        (Method::ClarabelAuxiliary, _) | (_, Formulation::Factored) => true,
        (_, Formulation::Assembled) => false,
        (_, Formulation::Auto) => condition.is_some_and(|c| c > FACTORED_ABOVE),
    };
    // without a data term there is no estimate: the factor is made for a retry should the
    // assembled normal matrix lose its definiteness
    let factor = if factored || condition.is_none() {
        domain.stiffness_factor(k).and_then(|k1| polyharmonic_factor(k, &k1, m, &settings.energy, &weights))
    } else {
        None
    };
    let row_scale =
        (settings.qp.method == Method::ActiveSet).then(|| second_order_scale(m, &settings.energy, &weights)).flatten();
    Ok(Operators { weights, data_diag, factor, p, q, condition, row_scale })
}

/// `s` with the energy `c K M⁻¹ K = K diag(s) K` (`s = c / m`, 0 at sharp vertices, as
/// [`crate::operators::polyharmonic`] assembles it) when its one term of non-zero weight is of
/// order 2; else `None`.
fn second_order_scale(m: &[f64], energy: &crate::operators::Energy, weights: &[f64]) -> Option<Vec<f64>> {
    let mut terms = energy.terms.iter().zip(weights).filter(|(t, s)| t.1 * **s != 0.0);
    let (&(order, w), &s) = terms.next()?;
    if order != 2 || terms.next().is_some() {
        return None;
    }
    let c = w * s;
    let mut scale: Vec<f64> = m.iter().map(|mi| c / mi).collect();
    for &v in &energy.sharp {
        scale[v] = 0.0;
    }
    Some(scale)
}

/// The solver's point `x` (unit values) as the output: in the field's units, the kept values
/// exactly the input's, the margin met exactly where it can be (so that the point is feasible
/// for the QP as written and its gap bound a distance bound), else strictness alone.
pub(super) fn output_of(x: &[f64], p: &Problem, o: &Ordered) -> (Vec<f64>, MarginSummary, RepairSummary) {
    let is_fixed: Vec<bool> = p.kept.roles.iter().map(|r| r.is_fixed()).collect();
    let mut f: Vec<f64> = x.iter().map(|&v| p.scale.value(v)).collect();
    for (i, fi) in f.iter_mut().enumerate() {
        if is_fixed[i] {
            *fi = p.h[i];
        }
    }
    let order = sos_order(&o.u, o.order.as_deref());
    let range = p.scale.range;
    let margin = meet_margin(&mut f, &is_fixed, &o.edges, &order, o.eps * range, &o.bounds);
    let strictness = repair(&mut f, &is_fixed, &o.edges, &order, 0.25 * o.eps * range);
    (f, margin, strictness)
}

/// A certified run, for its report.
pub(super) struct Run<'a> {
    pub(super) problem: &'a Problem<'a>,
    pub(super) ordered: &'a Ordered,
    pub(super) operators: &'a Operators<'a>,
    pub(super) mass: &'a [f64],
    pub(super) settings: &'a SmoothSettings,
    pub(super) sol: &'a QpSolution,
    pub(super) f: &'a [f64],
    /// SoS minima and maxima of the input.
    pub(super) extrema: (usize, usize),
    /// The smoothing length and the rule that chose it.
    pub(super) length: (f64, String),
    pub(super) repairs: (MarginSummary, RepairSummary),
    pub(super) diameter: f64,
    /// The memory budget of the run.
    pub(super) budget: crate::memory::Budget,
    /// The process's peak resident memory when the solve ended.
    pub(super) peak_after_solve: u64,
}

impl Run<'_> {
    /// What the run measured: the fit against the QP's optimum, the constraints' activity, the
    /// energies and deviations, the solver and the certificate.
    pub(super) fn report(self, seconds: StageSeconds, certificate: Certificate) -> Report {
        let (p, o, ops, settings, f) = (self.problem, self.ordered, self.operators, self.settings, self.f);
        let (h, kept, m) = (p.h, p.kept, self.mass);
        let n = h.len();
        let range = p.scale.range;
        let gd = settings.data_weight;
        let is_fixed: Vec<bool> = kept.roles.iter().map(|r| r.is_fixed()).collect();
        let (fit, smoothness) = fit_report(
            &FitInputs {
                p: ops.p.quadratic(),
                data_diag: &ops.data_diag,
                h,
                fixed: &is_fixed,
                edges: &o.edges,
                bounds: &o.bounds,
            },
            f,
            self.sol,
            ops.factor.as_ref(),
            (range, o.eps, gd, m),
        );
        let constraint_activity = activity(f, &o.edges, &is_fixed, o.eps * range);
        let mut warnings = kept.warnings.clone();
        for why in &o.fallbacks {
            warnings.push(format!("representative fallback (the {} one is used): {why}", o.name));
        }
        if constraint_activity.active_fraction > ACTIVE_WARNING {
            warnings.push(format!(
                "{:.0} % of the free vertices sit on an active constraint (largest terrace {} vertices): where the smoothing fights the constraints, lower the smoothing length; where the selection cancels large features, the output is held flat there by design",
                100.0 * constraint_activity.active_fraction,
                constraint_activity.largest_terrace
            ));
        }
        if matches!(self.sol.status, SolveStatus::Stalled | SolveStatus::MaxIterations) {
            let bound = match (fit.gap_over_data, fit.gap_over_energy) {
                (Some(g), _) => format!("{g:.1e} × the data term"),
                (None, Some(g)) => format!("{g:.1e} × the energy"),
                (None, None) => "not bounded".into(),
            };
            warnings.push(format!(
                "the solver stopped short of its target ({:?} after {} iterations): the topology is certified, the fit is optimal only to its gap bound ({bound}, target {:.0e})",
                self.sol.status, self.sol.iterations, settings.qp.gap_tolerance
            ));
        }
        // from the gap's pass over P's columns where it read them
        let smoothness =
            smoothness.unwrap_or_else(|| ops.p.quadratic().quadratic_form_without_diagonal(&ops.data_diag, f));
        let data: f64 = gd * (0..n).map(|i| m[i] * (f[i] - h[i]).powi(2)).sum::<f64>();
        let sq: f64 = (0..n).map(|i| (f[i] - h[i]).powi(2)).sum();
        let max_deviation = (0..n).map(|i| (f[i] - h[i]).abs()).fold(0.0, f64::max);
        let u_margin = o.edges.iter().map(|&(i, j)| o.u[j] - o.u[i]).fold(f64::INFINITY, f64::min);
        let (ell, smooth_length_rule) = self.length;
        let (margin_repair, repair) = self.repairs;
        Report {
            vertices: n,
            input_minima: self.extrema.0,
            input_maxima: self.extrema.1,
            settings: RunSettings {
                selection: settings.selection.clone(),
                threshold: kept.threshold,
                energy: settings.energy.clone(),
                data_weight: gd,
                smooth_weights: ops.weights.clone(),
                smooth_length: [ell / self.diameter, ell],
                smooth_length_rule,
                edge_set: settings.edges,
                margin: [o.eps * range, o.eps_max * range],
                u_margin,
                solver: settings.qp.clone(),
                representative: settings.representative,
            },
            constraints: o.edges.len(),
            kept: kept.kept.clone(),
            warnings,
            seconds,
            energy: EnergyReport { smoothness, data, total: smoothness + data },
            rms_deviation: (sq / n as f64).sqrt(),
            max_deviation,
            solver_status: self.sol.status,
            solver_iterations: self.sol.iterations,
            solver_inner_iterations: self.sol.inner_iterations,
            solver: self.sol.method,
            solver_fallback: self.sol.fallback.clone(),
            repair,
            margin_repair,
            fit,
            activity: constraint_activity,
            representative: o.name.clone(),
            representative_fallbacks: o.fallbacks.clone(),
            representative_certificate: o.certificate.clone(),
            certificate,
            memory: MemoryReport {
                budget: self.budget.bytes,
                budget_source: self.budget.source,
                predicted_peak: self.sol.predicted_peak,
                peak_after_solve: self.peak_after_solve,
            },
        }
    }
}
