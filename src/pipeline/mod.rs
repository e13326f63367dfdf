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
pub mod schema;
mod settings;
mod smoothable;
mod stages;

use crate::domain::{Domain, MaskedGrid, MaskedVolume, Restriction};
use crate::error::{Error, Result};
use crate::linalg::Analyses;
use crate::operators::Sparse;
use crate::progress::Stage;
use crate::solve::{policy, solve_monotone_qp_with, Bound, Method, MonotoneQp};
use crate::topology::morse_smale::MorseSmale;
use crate::topology::{count_sos_extrema, select, Role};
use crate::verify::certify;
pub use report::{EnergyReport, FitReport, MemoryReport, Report, RunSettings, StageSeconds, ACTIVE_WARNING};
pub use settings::{
    default_smooth_length, SmoothSettings, SMOOTH_LENGTH_EDGES, SMOOTH_LENGTH_FRACTION, SMOOTH_LENGTH_KEPT_SPACING,
};
#[cfg(feature = "serde")]
pub(crate) use smoothable::energy_on_edges;
pub use smoothable::{Representative, RepresentativeChoice, RepresentativeKind, Smoothable};
use stages::{build_operators, order_representative, output_of, Operators, Ordered, Problem, Run};
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
    crate::with_domain!(domain, d => smooth(d, h, settings))
}

/// The simplified Morse–Smale complex of `h` for the kept set of `selection`, as the separatrix
/// representative builds it: for `--complex` when another representative was used (grids and
/// triangle meshes).
///
/// # Errors
/// As the selection, and an internal error if the complex cannot be built.
pub fn complex_of(
    domain: &crate::domain::AnyDomain,
    h: &[f64],
    selection: &crate::topology::Selection,
) -> Result<MorseSmale> {
    crate::with_domain!(domain, d => {
        let kept = select(d, h, selection)?;
        let stage = Stage::begin("complex");
        let ms = MorseSmale::new(d, h, &kept).map_err(|e| Error::internal(format!("Morse-Smale complex: {e}")))?;
        stage.end(|| format!("{} saddles, {} separatrices", ms.saddles.len(), ms.descending.len() + ms.ascending.len()));
        Ok(ms)
    })
}

/// [`smooth`] on a volume restricted to a mask: the pipeline runs on the
/// [`MaskedVolume`]'s tetrahedra and its outputs come back on the whole grid, the outside
/// (and inside voxels on no inside tetrahedron) unchanged with role [`Role::Other`]. Explicit
/// kept voxels and sharp vertices are grid indices, as are the report's kept extrema; the
/// fit and the active fraction are the domain's.
///
/// # Errors
/// As [`smooth`]; an explicit kept voxel or sharp vertex outside the domain is an input
/// error naming it.
pub fn smooth_masked(masked: &MaskedVolume, h: &[f64], settings: &SmoothSettings) -> Result<Smoothed> {
    let g = masked.grid();
    let name = |v: usize| {
        let [i, j, k] = g.ijk(v);
        format!("voxel {v} (i {i}, j {j}, k {k})")
    };
    smooth_inside(masked.mesh(), masked, &name, h, settings)
}

/// [`smooth_masked`] on a 2D grid: the pipeline runs on the [`MaskedGrid`]'s triangle mesh
/// (its Morse–Smale complex and separatrix representative included).
///
/// # Errors
/// As [`smooth_masked`].
pub fn smooth_masked_grid(masked: &MaskedGrid, h: &[f64], settings: &SmoothSettings) -> Result<Smoothed> {
    let g = masked.grid();
    let name = |v: usize| {
        let (r, c) = g.row_col(v);
        format!("pixel {v} (row {r}, column {c})")
    };
    smooth_inside(masked.mesh(), masked, &name, h, settings)
}

/// The pipeline on `domain`, whose vertices are the grid points `on` holds, with inputs and
/// outputs on the whole grid.
fn smooth_inside<D: Smoothable + Sync>(
    domain: &D,
    on: &Restriction,
    name: &dyn Fn(usize) -> String,
    h: &[f64],
    settings: &SmoothSettings,
) -> Result<Smoothed> {
    let (n, voxels) = (on.used().len(), on.voxels());
    if h.len() != n {
        return Err(Error::input(format!("the field has {} values, the grid {n}", h.len())));
    }
    let mut vertex = vec![usize::MAX; n];
    for (i, &v) in voxels.iter().enumerate() {
        vertex[v] = i;
    }
    let inner = |list: &[usize], what: &str| -> Result<Vec<usize>> {
        list.iter()
            .map(|&v| match vertex.get(v) {
                Some(&i) if i != usize::MAX => Ok(i),
                Some(_) => Err(Error::input(format!("{what} {} lies outside the mask's domain", name(v)))
                    .at(crate::error::Location::Vertex(v))),
                None => Err(Error::input(format!("{what} {v} is out of range (the grid has {n} points)"))),
            })
            .collect()
    };
    let mut local = settings.clone();
    if let crate::topology::Selection::Explicit { minima, maxima } = &settings.selection {
        local.selection = crate::topology::Selection::Explicit {
            minima: inner(minima, "kept minimum")?,
            maxima: inner(maxima, "kept maximum")?,
        };
    }
    local.energy.sharp = inner(&settings.energy.sharp, "sharp vertex")?;
    let mut out = smooth(domain, &on.restrict(h), &local)?;
    out.output = on.extend(&out.output, h);
    out.u = on.extend(&out.u, h);
    out.roles = on.extend(&out.roles, &vec![Role::Other; n]);
    for k in &mut out.report.kept {
        k.index = voxels[k.index];
    }
    // the grid's complex is not the mesh's: a complex on mesh vertices would misname them
    out.complex = None;
    Ok(out)
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

/// [`smooth_on`] again with the interior-point method, `why` the active-set point was not
/// taken (in the report's `solver_fallback`).
fn structured_again<D: Smoothable + Sync>(
    domain: &D,
    ops: &mut DomainOperators,
    h: &[f64],
    settings: &SmoothSettings,
    analyses: &mut Analyses,
    keep_analyses: bool,
    why: String,
) -> Result<Smoothed> {
    let structured = SmoothSettings {
        qp: crate::solve::QpSettings { method: Method::Structured, ..settings.qp.clone() },
        ..settings.clone()
    };
    policy::announce_hand_over(&why, Method::Structured);
    ops.own_fill = domain.own_fill_stiffness();
    let mut again = smooth_on(domain, ops, h, &structured, analyses, keep_analyses)?;
    again.report.solver_fallback = Some(match again.report.solver_fallback.take() {
        Some(more) => format!("{why}; {more}"),
        None => why,
    });
    Ok(again)
}

/// The pipeline on a domain whose operators are built; `keep_analyses`: the fills' analysis
/// stays in `analyses` through the solve (else it is dropped first, for memory). Runs under
/// the settings' thread cap; a run cancelled ([`crate::progress::cancelled`]) ends with
/// [`Error::Cancelled`] whatever stage noticed it.
pub(crate) fn smooth_on<D: Smoothable + Sync>(
    domain: &D,
    ops: &mut DomainOperators,
    h: &[f64],
    settings: &SmoothSettings,
    analyses: &mut Analyses,
    keep_analyses: bool,
) -> Result<Smoothed> {
    let mut run = || {
        crate::progress::checkpoint()?;
        smooth_stages(domain, ops, h, settings, analyses, keep_analyses)
    };
    let out = match settings.threads {
        Some(n) => crate::parallel::with_threads(n, run),
        None => run(),
    };
    crate::progress::settle(out)
}

/// The stages of [`smooth_on`].
fn smooth_stages<D: Smoothable + Sync>(
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
    let chosen;
    let settings = match settings.qp.method {
        Method::Auto => {
            let method = policy::route(Method::Auto, n, domain.solid());
            chosen =
                SmoothSettings { qp: crate::solve::QpSettings { method, ..settings.qp.clone() }, ..settings.clone() };
            &chosen
        }
        _ => settings,
    };
    let mut seconds = StageSeconds::default();

    let stage = Stage::begin("selection");
    let kept = select(domain, h, &settings.selection)?;
    crate::progress::checkpoint()?;
    let extrema = count_sos_extrema(domain, h);
    seconds.persistence = stage.end(|| {
        format!(
            "{} of {} minima and {} of {} maxima kept",
            kept.minima().len(),
            extrema.0,
            kept.maxima().len(),
            extrema.1
        )
    });
    let length = match settings.smooth_length {
        Some(fraction) => (fraction * domain.diameter(), format!("{fraction} of the diameter, as given")),
        None => default_smooth_length(domain, &kept),
    };
    check_fixed_neighbours(domain, h, &kept.roles)?;
    let problem = Problem::new(h, &kept);

    // The energy and the solver's analysis of its normal matrix need only the kept set: they
    // are built on the other core while the complex and the representative are (after a
    // representative that costs nothing, on every core).
    let fill = ops.fill();
    let mut representative = || {
        let stage = Stage::begin("representative");
        let ordered = order_representative(domain, &problem, settings, fill, analyses, &mut seconds);
        if let Ok(o) = &ordered {
            stage.end(|| format!("{}, {} constraint edges", o.name, o.edges.len()));
        }
        ordered
    };
    let energy = || {
        let t = Instant::now();
        let built = build_operators(domain, (&ops.stiffness, &ops.mass), settings, length.0, &problem);
        let seconds = t.elapsed().as_secs_f64();
        let prepared = match (&built, settings.qp.method) {
            // a failed analysis is redone (and reported) by the solver itself
            (Ok(o), Method::Structured) if o.factor.is_none() => {
                o.p.stored()
                    .and_then(|p| crate::solve::prepare(p, &problem.fixed, settings.qp.memory_limit).ok().flatten())
            }
            _ => None,
        };
        (built, seconds, prepared)
    };
    let (ordered, (operators, operators_seconds, prepared)) = if domain.light_representative() {
        let ordered = representative();
        (ordered, energy())
    } else {
        crate::parallel::join(representative, energy)
    };
    let ordered = ordered?;
    let operators = operators?;
    crate::progress::checkpoint()?;
    seconds.operators = operators_seconds;
    // the fills' Laplacian analysis is not needed again: free it before the solver runs, whose
    // factor storage was made beside the representative (the two together set the peak)
    if !keep_analyses {
        analyses.clear();
        // and the mesh's own fills' Laplacian with it
        ops.own_fill = None;
    }

    let stage = Stage::begin("solve");
    let sol = solve_qp(&problem, &ordered, (&operators, &ops.stiffness), settings, analyses, prepared)?;
    seconds.solve = stage.end(|| format!("{:?} after {} iterations", sol.status, sol.iterations));
    let peak_after_solve = crate::memory::peak_resident();

    let t = Instant::now();
    let (f, margin_repair, strictness_repair) = output_of(&sol.x, &problem, &ordered);
    seconds.repair = t.elapsed().as_secs_f64();

    crate::progress::checkpoint()?;
    let stage = Stage::begin("certificate");
    let certificate = certify(domain, &f, &kept.roles, Some(h));
    seconds.verify = stage.end(|| if certificate.passed { "passed".into() } else { "FAILED".into() });
    // an active-set point (one that stalled, say) whose repaired output does not certify is
    // solved again by the interior-point method
    if !certificate.passed && sol.method == Method::ActiveSet {
        let why = format!(
            "the active-set output ({:?} after {} outer iterations), after the margin repair moved {} vertices by up to {:.1e}, did not certify: {}",
            sol.status,
            sol.iterations,
            margin_repair.changed_vertices,
            margin_repair.max_change,
            certificate.summary()
        );
        return structured_again(domain, ops, h, settings, analyses, keep_analyses, why);
    }
    if !certificate.passed {
        return Err(Error::Uncertified {
            path: None,
            message: format!(
                "{} (solver {:?} after {} iterations; repair changed {} vertices)",
                certificate.summary(),
                sol.status,
                sol.iterations,
                strictness_repair.changed_vertices
            ),
        });
    }
    let run = Run {
        problem: &problem,
        ordered: &ordered,
        operators: &operators,
        mass: &ops.mass,
        settings,
        sol: &sol,
        f: &f,
        extrema,
        length,
        repairs: (margin_repair, strictness_repair),
        diameter: domain.diameter(),
        budget: crate::memory::Budget::of(settings.qp.memory_limit),
        peak_after_solve,
    };
    let report = run.report(seconds, certificate);
    // the active-set point is checked as written, after the margin repair: one further from
    // the optimum than the fit's target is solved again by the interior-point method
    if sol.method == Method::ActiveSet && report.fit.gap_over_data.is_some_and(|g| g > policy::ACTIVE_SET_FIT) {
        let why = format!(
            "the active-set output ({:?} after {} outer iterations), after the margin repair moved {} vertices by up to {:.1e}, was {:.1e} × the data term from the optimum",
            sol.status,
            sol.iterations,
            report.margin_repair.changed_vertices,
            report.margin_repair.max_change,
            report.fit.gap_over_data.unwrap_or(f64::NAN)
        );
        return structured_again(domain, ops, h, settings, analyses, keep_analyses, why);
    }
    let Ordered { u, complex, .. } = ordered;
    Ok(Smoothed { output: f, u, roles: kept.roles, report, complex })
}

/// The QP in units of the input's range, started from the representative.
fn solve_qp(
    problem: &Problem,
    ordered: &Ordered,
    (operators, stiffness): (&Operators, &crate::operators::Sparse),
    settings: &SmoothSettings,
    analyses: &mut Analyses,
    prepared: Option<crate::solve::Prepared>,
) -> Result<crate::solve::QpSolution> {
    let scale = problem.scale;
    let hint: Vec<f64> = ordered.u.iter().map(|&v| scale.unit(v)).collect();
    let unit_bounds: Vec<Bound> = ordered.bounds.iter().map(|b| Bound { value: scale.unit(b.value), ..*b }).collect();
    let qp = MonotoneQp {
        p: operators.p.quadratic(),
        q: &operators.q,
        fixed: &problem.fixed,
        edges: &ordered.edges,
        margin: ordered.eps,
        bounds: &unit_bounds,
        data: Some(&operators.data_diag),
        hint: Some(&hint),
        factor: operators.factor.as_ref(),
        condition: operators.condition,
        second_order: operators
            .row_scale
            .as_deref()
            .map(|row_scale| crate::solve::SecondOrder { k: stiffness, row_scale }),
    };
    solve_monotone_qp_with(&qp, &settings.qp, analyses, prepared)
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
