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
use crate::domain::{sos_sort, Domain, Grid2d, Series};
use crate::error::{Error, Result};
use crate::operators::{
    dirichlet_solve, grid_mass, grid_stiffness, polyharmonic, quadratic_form, scaled_plus_diagonal, series_mass,
    series_stiffness, Energy, Sparse,
};
use crate::representative::{flooded_representative, separatrix_representative, series_representative};
use crate::solve::{repair, solve_monotone_qp, Method, MonotoneQp, QpSettings, RepairSummary, SolveStatus};
use crate::topology::morse_smale::MorseSmale;
use crate::topology::{count_sos_extrema, select, KeptExtremum, KeptSet, Role, Selection};
use crate::verify::{certify, Certificate};
use std::time::Instant;

/// A domain the pipeline can smooth on: it supplies its operators and its representative.
pub trait Smoothable: Domain {
    /// Stiffness `K = −L`.
    fn stiffness(&self) -> Sparse;
    /// Lumped mass (diagonal, > 0).
    fn mass(&self) -> Vec<f64>;
    /// A function with exactly the kept extrema (checked by the pipeline), and the name of
    /// the construction that produced it.
    fn representative(&self, h: &[f64], kept: &KeptSet) -> Result<(Vec<f64>, String)>;
}

impl Smoothable for Series {
    fn stiffness(&self) -> Sparse {
        series_stiffness(self)
    }
    fn mass(&self) -> Vec<f64> {
        series_mass(self)
    }
    fn representative(&self, h: &[f64], kept: &KeptSet) -> Result<(Vec<f64>, String)> {
        Ok((series_representative(self, h, kept)?, "linear".into()))
    }
}

impl Smoothable for Grid2d {
    fn stiffness(&self) -> Sparse {
        grid_stiffness(self)
    }
    fn mass(&self) -> Vec<f64> {
        grid_mass(self)
    }
    /// The separatrix representative; if it fails its check, the harmonic one (0 at kept
    /// minima, 1 at kept maxima, rescaled to the data's range).
    fn representative(&self, h: &[f64], kept: &KeptSet) -> Result<(Vec<f64>, String)> {
        let k = grid_stiffness(self);
        let mut why = Vec::new();
        match MorseSmale::new(self, h, kept).and_then(|ms| separatrix_representative(self, h, kept, &ms, &k)) {
            Ok(u) => {
                let c = certify(self, &u, &kept.roles, None);
                if c.passed {
                    return Ok((u, "separatrix".into()));
                }
                why.push(format!("separatrix representative: {}", c.summary()));
            }
            Err(e) => why.push(format!("separatrix representative: {e}")),
        }
        match flooded_representative(self, h, kept) {
            Some(u) => return Ok((u, format!("flooded (fallback: {})", why.join("; ")))),
            None => why.push("flooded representative: the floods did not settle".into()),
        }
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
        match dirichlet_solve(&k, &fixed) {
            Ok(u) => {
                let c = certify(self, &u, &kept.roles, None);
                if c.passed {
                    return Ok((u, format!("harmonic (fallback: {})", why.join("; "))));
                }
                why.push(format!("harmonic representative: {}", c.summary()));
            }
            Err(e) => why.push(format!("harmonic representative: {e}")),
        }
        Err(Error::Representative { path: None, message: why.join("; ") })
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
    /// Representative function and its check.
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
}

/// Smooths `h` on `domain` keeping exactly the selected extrema; returns only certified output.
///
/// # Errors
/// Input and usage errors (exit 3, 2), an unrealizable explicit list (3), a representative
/// that fails its check (1), no solver point (4), an output that fails the certificate even
/// after repair (1).
pub fn smooth<D: Smoothable>(domain: &D, h: &[f64], settings: &SmoothSettings) -> Result<Smoothed> {
    settings.validate()?;
    let n = domain.n_vertices();
    if h.len() != n {
        return Err(Error::input(format!("the field has {} values, the domain {n} vertices", h.len())));
    }
    if let Some(&v) = settings.energy.sharp.iter().find(|&&v| v >= n) {
        return Err(Error::Usage(format!("sharp vertex {v} is out of range (the input has {n} vertices)")));
    }
    let mut seconds = StageSeconds::default();

    let t = Instant::now();
    let kept = select(domain, h, &settings.selection)?;
    let (input_minima, input_maxima) = count_sos_extrema(domain, h);
    seconds.persistence = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let (u, representative) = domain.representative(h, &kept)?;
    let representative_certificate = certify(domain, &u, &kept.roles, None);
    if !representative_certificate.passed {
        return Err(Error::Representative { path: None, message: representative_certificate.summary() });
    }
    seconds.representative = t.elapsed().as_secs_f64();

    // work in units where the field spans [0, 1]
    let t = Instant::now();
    let (lo, hi) = crate::domain::value_range(h);
    let range = hi - lo;
    let z: Vec<f64> = h.iter().map(|v| (v - lo) / range).collect();
    let k = domain.stiffness();
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
    let p = scaled_plus_diagonal(&q_energy, 1.0, &data_diag);
    let q: Vec<f64> = (0..n).map(|i| -gd * m[i] * z[i]).collect();
    seconds.operators = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let fixed: Vec<Option<f64>> = (0..n).map(|i| kept.roles[i].is_fixed().then_some(z[i])).collect();
    let edges = constraint_edges(domain, &u, &fixed, settings.edges);
    check_fixed_neighbours(domain, h, &kept.roles)?;
    let magnitude = h.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let resolution = (magnitude.next_up() - magnitude) / range;
    let eps_max = max_margin(&u, &edges, &fixed, Some(margin_cap(1.0, resolution)))?;
    let eps = choose_margin(eps_max, 1.0, resolution)?;
    seconds.constraints = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let hint: Vec<f64> = u.iter().map(|v| (v - lo) / range).collect();
    let u_margin = edges.iter().map(|&(i, j)| u[j] - u[i]).fold(f64::INFINITY, f64::min);
    let qp = MonotoneQp { p: &p, q: &q, fixed: &fixed, edges: &edges, margin: eps, hint: Some(&hint) };
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

    let smoothness = quadratic_form(&q_energy, &f);
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
    Ok(Smoothed { output: f, u, roles: kept.roles, report })
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
