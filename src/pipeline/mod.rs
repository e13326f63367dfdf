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

mod report;
mod settings;
mod smoothable;

use crate::constraints::{activity, choose_margin, constraint_edges, margin_cap, max_margin_or_conflict};
use crate::domain::{sos_sort, Domain};
use crate::error::{Error, Result};
use crate::linalg::Analyses;
use crate::operators::{
    plus_diagonal, polyharmonic, polyharmonic_factor, quadratic_form_without_diagonal, Factor, Sparse,
};
use crate::solve::{
    condition_estimate, meet_margin, repair, solve_monotone_qp_with, Bound, Formulation, Method, MonotoneQp,
    FACTORED_ABOVE,
};
use crate::topology::morse_smale::MorseSmale;
use crate::topology::{count_sos_extrema, select, Role};
use crate::verify::certify;
use report::{fit_report, FitInputs};
pub use report::{EnergyReport, FitReport, Report, RunSettings, StageSeconds, ACTIVE_WARNING};
pub use settings::{
    default_smooth_length, SmoothSettings, SMOOTH_LENGTH_EDGES, SMOOTH_LENGTH_FRACTION, SMOOTH_LENGTH_KEPT_SPACING,
};
pub use smoothable::{Representative, RepresentativeChoice, Smoothable};
use std::time::Instant;

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

    /// The harmonic fills' Laplacian ([`Smoothable::own_fill_stiffness`], else the stiffness).
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

/// [`smooth`] on a domain chosen at run time.
///
/// # Errors
/// As [`smooth`].
pub fn smooth_any(domain: &crate::domain::AnyDomain, h: &[f64], settings: &SmoothSettings) -> Result<Smoothed> {
    use crate::domain::AnyDomain;
    match domain {
        AnyDomain::Series(d) => smooth(d, h, settings),
        AnyDomain::Grid(d) => smooth(d, h, settings),
        AnyDomain::Mesh(d) => smooth(d, h, settings),
    }
}

/// [`smooth`] with the harmonic fills' analysis taken from `analyses` (made, for instance, by
/// the geodesic distance the field came from). For memory, `analyses` is cleared before the
/// solve (a million-vertex Laplacian's analysis is hundreds of MiB) and holds only the
/// solver's normal-matrix analysis on return; a [`crate::smoother::Smoother`] keeps them all.
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
    smooth_on(domain, &mut DomainOperators::new(domain), h, settings, analyses, false)
}

/// The pipeline on a domain whose operators are built; `keep_analyses`: the fills' analysis
/// stays in `analyses` through the solve (else it is dropped first, for memory).
pub(crate) fn smooth_on<D: Smoothable + Sync>(
    domain: &D,
    ops: &mut DomainOperators,
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
        return Err(Error::input(format!("sharp vertex {v} is out of range (the input has {n} vertices)"))
            .at(crate::error::Location::Vertex(v)));
    }
    let mut seconds = StageSeconds::default();

    let t = Instant::now();
    let kept = select(domain, h, &settings.selection)?;
    let (input_minima, input_maxima) = count_sos_extrema(domain, h);
    seconds.persistence = t.elapsed().as_secs_f64();

    let (ell, smooth_length_rule) = match settings.smooth_length {
        Some(fraction) => (fraction * domain.diameter(), format!("{fraction} of the diameter, as given")),
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
    // the two-thread permission of the analyses made on the other core
    let split = analyses.split_allowed();
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
    };
    // The energy and the solver's analysis of its normal matrix need only the kept set: they
    // are built on the other core while the complex and the representative are.
    let operators = || -> Result<Operators> {
        let m = &ops.mass;
        let weights: Vec<f64> = settings
            .energy
            .terms
            .iter()
            .map(|&(order, _)| settings.smooth_weight.unwrap_or(ell.powi(2 * order as i32)))
            .collect();
        let q_energy = polyharmonic(k, m, &settings.energy, &weights);
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
            domain.stiffness_factor(k).and_then(|k1| polyharmonic_factor(k, &k1, m, &settings.energy, &weights))
        } else {
            None
        };
        Ok(Operators { weights, data_diag, factor, p, q, condition })
    };
    let (representative_result, (operators_result, operators_seconds, prepared)) = std::thread::scope(|scope| {
        let background = scope.spawn(|| {
            let t = Instant::now();
            let ops = operators();
            let seconds = t.elapsed().as_secs_f64();
            let prepared = match (&ops, settings.qp.method) {
                // a failed analysis is redone (and reported) by the solver itself
                (Ok(o), Method::Structured) if o.factor.is_none() => crate::solve::prepare(&o.p, &fixed, split).ok(),
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
    let Operators { weights, data_diag, factor, p, q, condition } = operators_result?;
    let m = &ops.mass;
    seconds.operators = operators_seconds;
    let gd = settings.data_weight;
    // the fills' Laplacian analysis is not needed again: free it before the solver runs, whose
    // factor storage was made beside the representative (the two together set the peak)
    if !keep_analyses {
        analyses.clear();
        // and the mesh's own fills' Laplacian with it
        ops.own_fill = None;
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
        (range, eps, gd, m),
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
