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

use crate::constraints::{choose_margin, constraint_edges, margin_cap, max_margin, EdgeSet};
use crate::domain::{sos_sort, Domain, Grid2d, Series, TriMesh};
use crate::error::{Error, Result};
use crate::operators::{
    cotan_stiffness, dirichlet_solve, grid_mass, grid_stiffness, lumped_mass, plus_diagonal, polyharmonic,
    positive_cotan_stiffness, quadratic_form, quadratic_form_without_diagonal, series_mass, series_stiffness, Energy,
    Sparse,
};
use crate::representative::{flooded_representative, separatrix_representative, series_representative};
use crate::solve::{repair, solve_monotone_qp, Method, MonotoneQp, QpSettings, RepairSummary, SolveStatus};
use crate::topology::morse_smale::MorseSmale;
use crate::topology::{count_sos_extrema, select, KeptExtremum, KeptSet, Role, Selection};
use crate::verify::{certify, Certificate};
use std::time::Instant;

/// Which representative function to build on surfaces (series always use the linear one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
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
    /// Construction used, with the reasons for any fallback.
    pub name: String,
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
        self.stiffness()
    }
    /// A function with exactly the kept extrema (checked by the pipeline), built by the
    /// first construction in the order `choice` prefers that is not `excluded` (kind and
    /// why: the pipeline excludes one whose order makes the constraints infeasible).
    fn representative(
        &self,
        h: &[f64],
        kept: &KeptSet,
        choice: RepresentativeChoice,
        k: &Sparse,
        excluded: &[(&'static str, String)],
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
        _: RepresentativeChoice,
        _: &Sparse,
        _: &[(&'static str, String)],
    ) -> Result<Representative> {
        let u = series_representative(self, h, kept)?;
        Ok(Representative { u, kind: "linear", name: "linear".into(), complex: None })
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

/// The representative on a triangulated surface: the chosen construction (the complex is
/// built either way, for `--complex`); if it fails its check, the other one, then the flooded
/// one (NOTES.md 9). `k` is the Laplacian of the harmonic fills (non-negative weights).
fn surface_representative<D: Domain>(
    domain: &D,
    h: &[f64],
    kept: &KeptSet,
    choice: RepresentativeChoice,
    k: &Sparse,
    excluded: &[(&'static str, String)],
) -> Result<Representative> {
    let mut why: Vec<String> = excluded.iter().map(|(kind, e)| format!("{kind} representative: {e}")).collect();
    let skip = |kind: &str| excluded.iter().any(|(x, _)| *x == kind);
    let complex = match MorseSmale::new(domain, h, kept) {
        Ok(ms) => Some(ms),
        Err(e) => {
            why.push(format!("Morse-Smale complex: {e}"));
            None
        }
    };
    let released = std::cell::Cell::new(0);
    let one_sided_saddles = std::cell::Cell::new(0);
    let merged_used: std::cell::RefCell<Option<MorseSmale>> = std::cell::RefCell::new(None);
    // the matched saddles first; if u fails its check, once more with the one-sided saddles
    // (a kept boundary extremum's partner is often one: without its separatrices the cells
    // beside it reach along the boundary to values beyond it)
    let separatrix = |why: &mut Vec<String>| -> Option<Vec<f64>> {
        let matched = complex.as_ref()?;
        let merged = matched.with_one_sided();
        let mut first_failure = None;
        for (attempt, ms) in std::iter::once(matched).chain(merged.as_ref()).enumerate() {
            match separatrix_representative(domain, h, kept, ms, k) {
                Ok((u, r)) => {
                    let c = certify(domain, &u, &kept.roles, None);
                    if c.passed {
                        released.set(r);
                        if attempt > 0 {
                            // the one-sided saddles are never matched ones
                            one_sided_saddles.set(ms.saddles.len() - matched.saddles.len());
                            *merged_used.borrow_mut() = Some(ms.clone());
                        }
                        return Some(u);
                    }
                    first_failure.get_or_insert(format!("separatrix representative: {}", c.summary()));
                }
                Err(e) => {
                    first_failure.get_or_insert(format!("separatrix representative: {e}"));
                }
            }
        }
        why.extend(first_failure);
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
    let order: [&'static str; 3] = match choice {
        RepresentativeChoice::Separatrix => ["separatrix", "harmonic", "flooded"],
        RepresentativeChoice::Harmonic => ["harmonic", "separatrix", "flooded"],
        RepresentativeChoice::Flooded => ["flooded", "separatrix", "harmonic"],
    };
    let build = |name: &str, why: &mut Vec<String>| match name {
        "separatrix" => separatrix(why),
        "harmonic" => harmonic(why),
        _ => flooded(why),
    };
    let named = |name: &str, why: &[String]| {
        let mut name = name.to_string();
        if name == "separatrix" && one_sided_saddles.get() > 0 {
            name = format!("separatrix with {} one-sided saddles", one_sided_saddles.get());
        }
        if name.starts_with("separatrix") && released.get() > 0 {
            name =
                format!("{name} ({} contradicting separatrix vertices released to the harmonic fill)", released.get());
        }
        if why.is_empty() {
            name
        } else {
            format!("{name} (fallback: {})", why.join("; "))
        }
    };
    for kind in order {
        if skip(kind) {
            continue;
        }
        if let Some(u) = build(kind, &mut why) {
            // --complex writes the separatrices u was built from
            let complex = if kind == "separatrix" { merged_used.take().or(complex) } else { complex };
            return Ok(Representative { u, kind, name: named(kind, &why), complex });
        }
    }
    Err(Error::Representative { path: None, message: why.join("; ") })
}

impl Smoothable for TriMesh {
    fn stiffness(&self) -> Sparse {
        cotan_stiffness(self.positions(), self.faces())
    }
    fn mass(&self) -> Vec<f64> {
        lumped_mass(self.positions(), self.faces())
    }
    fn fill_stiffness(&self) -> Sparse {
        positive_cotan_stiffness(self.positions(), self.faces())
    }
    /// As on grids, but the harmonic fills use [`positive_cotan_stiffness`]: cotangent
    /// weights of obtuse triangles can be negative and break the maximum principle the
    /// representative relies on (paper section 5); `k` (the energy's) is not used.
    fn representative(
        &self,
        h: &[f64],
        kept: &KeptSet,
        choice: RepresentativeChoice,
        _k: &Sparse,
        excluded: &[(&'static str, String)],
    ) -> Result<Representative> {
        surface_representative(self, h, kept, choice, &self.fill_stiffness(), excluded)
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
        choice: RepresentativeChoice,
        k: &Sparse,
        excluded: &[(&'static str, String)],
    ) -> Result<Representative> {
        surface_representative(self, h, kept, choice, k, excluded)
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
    /// Smoothing length ℓ as a fraction of the domain's diameter. {0.01}
    pub smooth_length: f64,
    /// Constraint set. {minimal}
    pub edges: EdgeSet,
    /// Solver settings.
    pub qp: QpSettings,
    /// Representative function on surfaces. {separatrix}
    pub representative: RepresentativeChoice,
}

impl Default for SmoothSettings {
    fn default() -> Self {
        SmoothSettings {
            selection: Selection::Relative(0.05),
            energy: Energy::order(2),
            data_weight: 1.0,
            smooth_weight: None,
            smooth_length: 0.01,
            edges: EdgeSet::Minimal,
            qp: QpSettings::default(),
            representative: RepresentativeChoice::Separatrix,
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
        if !(self.smooth_length.is_finite() && self.smooth_length > 0.0) {
            return Err(Error::Usage(format!("--smooth-length must be finite and > 0, got {}", self.smooth_length)));
        }
        Ok(())
    }
}

/// Seconds per stage.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
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
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct EnergyReport {
    /// Σ γ_k w_k E_k(f).
    pub smoothness: f64,
    /// γD Σ M_ii (f_i − h_i)².
    pub data: f64,
    /// Their sum (the objective).
    pub total: f64,
}

/// The settings of a run as the report records them.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
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
    /// Representative requested (surfaces).
    pub representative: RepresentativeChoice,
}

/// Everything a run measured, written by `--report`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
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
    /// What the repair changed.
    pub repair: RepairSummary,
    /// Which representative was used (and why a fallback was needed).
    pub representative: String,
    /// Certificate of u (items 1, 2, 4).
    pub representative_certificate: Certificate,
    /// Certificate of the output (items 1–4).
    pub certificate: Certificate,
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
    factor: Option<Sparse>,
    p: Sparse,
    q: Vec<f64>,
}

/// Smooths `h` on `domain` keeping exactly the selected extrema; returns only certified output.
///
/// # Errors
/// Input and usage errors (exit 3, 2), an unrealizable explicit list (3), a representative
/// that fails its check (1), no solver point (4), an output that fails the certificate even
/// after repair (1).
pub fn smooth<D: Smoothable + Sync>(domain: &D, h: &[f64], settings: &SmoothSettings) -> Result<Smoothed> {
    settings.validate()?;
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

    let k = domain.stiffness();
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
            let rep = domain.representative(h, &kept, settings.representative, &k, &excluded)?;
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
            let margins = max_margin(&rep.u, &edges, &fixed, Some(margin_cap(1.0, resolution)))
                .and_then(|eps_max| Ok((eps_max, choose_margin(eps_max, 1.0, resolution)?)));
            seconds.constraints += t.elapsed().as_secs_f64();
            match margins {
                Ok((eps_max, eps)) => {
                    return Ok((rep.u, rep.name, rep.complex, representative_certificate, edges, eps_max, eps));
                }
                Err(e @ Error::Infeasible { .. })
                    if settings.selection.by_persistence() && rep.kind != "linear" && rep.kind != "flooded" =>
                {
                    excluded.push((rep.kind, e.to_string()));
                }
                Err(e) => return Err(e),
            }
        }
    };
    // The energy and the solver's analysis of its normal matrix need only the kept set: they
    // are built on the other core while the complex and the representative are.
    let operators = || -> Result<Operators> {
        let m = domain.mass();
        let ell = settings.smooth_length * domain.diameter();
        let weights: Vec<f64> = settings
            .energy
            .terms
            .iter()
            .map(|&(order, _)| settings.smooth_weight.unwrap_or(ell.powi(2 * order as i32)))
            .collect();
        let q_energy = polyharmonic(&k, &m, &settings.energy, &weights);
        let gd = settings.data_weight;
        let data_diag: Vec<f64> = m.iter().map(|mi| gd * mi).collect();
        let factor = match settings.qp.method {
            Method::ClarabelAuxiliary => Some(energy_factor(&k, &m, &settings.energy, &weights, &q_energy)?),
            _ => None,
        };
        // P = energy + data diagonal, in the energy's storage (one matrix of the size of a
        // bilaplacian less: 300 MiB at a million vertices)
        let p = plus_diagonal(q_energy, &data_diag);
        let q: Vec<f64> = (0..n).map(|i| -gd * m[i] * z[i]).collect();
        Ok(Operators { m, weights, data_diag, factor, p, q })
    };
    let (representative_result, (operators_result, operators_seconds, prepared)) = std::thread::scope(|scope| {
        let background = scope.spawn(|| {
            let t = Instant::now();
            let ops = operators();
            let seconds = t.elapsed().as_secs_f64();
            let prepared = match (&ops, settings.qp.method) {
                // a failed analysis is redone (and reported) by the solver itself
                (Ok(o), Method::Structured) => crate::solve::prepare(&o.p, &fixed).ok(),
                _ => None,
            };
            (ops, seconds, prepared)
        });
        let rep = representative_stage();
        (rep, background.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
    });
    let (u, representative, complex, representative_certificate, edges, eps_max, eps) = representative_result?;
    let Operators { m, weights, data_diag, factor, p, q } = operators_result?;
    seconds.operators = operators_seconds;
    let gd = settings.data_weight;
    let ell = settings.smooth_length * domain.diameter();
    // the fills' Laplacian analysis is not needed again: free it before the solver runs (the
    // solver's factor storage was made beside the representative: 1000² peak 2.93 → 3.06 GiB)
    crate::linalg::forget_solver_analysis();
    if let Some(prepared) = prepared {
        prepared.install();
    }

    let t = Instant::now();
    let hint: Vec<f64> = u.iter().map(|v| (v - lo) / range).collect();
    let u_margin = edges.iter().map(|&(i, j)| u[j] - u[i]).fold(f64::INFINITY, f64::min);
    let qp = MonotoneQp {
        p: &p,
        q: &q,
        fixed: &fixed,
        edges: &edges,
        margin: eps,
        hint: Some(&hint),
        factored: factor.as_ref().map(|f| (f, &data_diag[..])),
    };
    let sol = solve_monotone_qp(&qp, &settings.qp)?;
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
            smooth_length: [settings.smooth_length, ell],
            edge_set: settings.edges,
            margin: [eps * range, eps_max * range],
            u_margin,
            solver: settings.qp.clone(),
            representative: settings.representative,
        },
        constraints: edges.len(),
        kept: kept.kept.clone(),
        warnings: kept.warnings.clone(),
        seconds,
        energy: EnergyReport { smoothness, data, total: smoothness + data },
        rms_deviation: (sq / n as f64).sqrt(),
        max_deviation,
        solver_status: sol.status,
        solver_iterations: sol.iterations,
        solver: sol.method,
        solver_fallback: sol.fallback.clone(),
        repair: repair_summary,
        representative,
        representative_certificate,
        certificate,
    };
    Ok(Smoothed { output: f, u, roles: kept.roles, report, complex })
}

/// `F` with `FᵀF` equal to the energy matrix, for the appendix formulation: order 2 only,
/// `F = √γ M^{−1/2} K` (checked against `q_energy` on a test vector).
fn energy_factor(k: &Sparse, m: &[f64], energy: &Energy, weights: &[f64], q_energy: &Sparse) -> Result<Sparse> {
    if energy.terms.len() != 1 || energy.terms[0].0 != 2 || !energy.sharp.is_empty() {
        return Err(Error::Usage(
            "--solver clarabel-auxiliary supports a single order-2 energy without --sharp".into(),
        ));
    }
    let w = weights[0] * energy.terms[0].1;
    let mut triplets = Vec::new();
    let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    for j in 0..k.ncols() {
        for p in cp[j]..cp[j + 1] {
            triplets.push(faer::sparse::Triplet::new(ri[p], j, (w / m[ri[p]]).sqrt() * val[p]));
        }
    }
    let f = Sparse::try_new_from_triplets(k.nrows(), k.ncols(), &triplets)
        .map_err(|e| Error::input(format!("energy factor: {e:?}")))?;
    let x: Vec<f64> = (0..k.ncols()).map(|i| ((i * 7919) % 101) as f64 / 101.0).collect();
    let fx: Vec<f64> = {
        let mut y = vec![0.0; f.nrows()];
        let (cp, ri, val) = (f.symbolic().col_ptr(), f.symbolic().row_idx(), f.val());
        for j in 0..f.ncols() {
            for p in cp[j]..cp[j + 1] {
                y[ri[p]] += val[p] * x[j];
            }
        }
        y
    };
    let (a, b) = (fx.iter().map(|v| v * v).sum::<f64>(), quadratic_form(q_energy, &x));
    if (a - b).abs() > 1e-8 * b.abs().max(1e-300) {
        return Err(Error::Representative {
            path: None,
            message: format!("internal error: FᵀF differs from the energy matrix ({a} vs {b})"),
        });
    }
    Ok(f)
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
