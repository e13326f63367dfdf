//! Shape-aware weights with no spurious extrema (paper sections 3.3 "No initial data" and
//! 3.4): one function per handle, 1 on it, 0 on the other handles, minimising a polyharmonic
//! energy, and (monotone) with no other local extremum, certified per function; then
//! normalised to a partition of unity. `bounded`, `unconstrained` and `harmonic` are the
//! comparisons the paper makes; their spurious extrema are counted, not forbidden.
//!
//! ```
//! use toposmooth::apps::weights::{weights, WeightMethod, WeightSettings};
//! use toposmooth::domain::Grid2d;
//! let bar = Grid2d::new(12, 3)?;
//! let handles = vec![vec![bar.index(1, 0)], vec![bar.index(1, 11)]];
//! let w = weights(&bar, &handles, &WeightSettings::default())?;
//! assert!(w.functions.iter().all(|f| f.certificate.passed));
//! assert!(w.max_normalisation_change < 1e-6); // two handles on a bar: nearly a partition already
//! # Ok::<(), toposmooth::Error>(())
//! ```

use crate::constraints::{choose_margin, constraint_edges, margin_cap, max_margin, EdgeSet};
use crate::domain::sos_sort;
use crate::error::{Error, Result};
use crate::linalg::Analyses;
use crate::operators::{dirichlet_solve, Energy, Sparse};
use crate::pipeline::Smoothable;
use crate::representative::harmonic_order::ordered_harmonic;
use crate::solve::{repair, solve_bounded_partition, solve_monotone_qp_with, MonotoneQp, QpSettings, SolveStatus};
use crate::verify::{certify_no_data, spurious_components, Certificate, RegionKind};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// How each weight function is computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum WeightMethod {
    /// Polyharmonic energy with the monotonicity constraints: no spurious extremum (certified).
    #[default]
    Monotone,
    /// Bounded biharmonic weights: 0 ≤ w ≤ 1 and a partition of unity, solved jointly.
    Bounded,
    /// The plain polyharmonic solution with the handle values.
    Unconstrained,
    /// The Laplace solution (cotangent Laplacian) with the handle values.
    Harmonic,
}

named_enum!(
    WeightMethod,
    "weight method",
    [
        (WeightMethod::Monotone, "monotone"),
        (WeightMethod::Bounded, "bounded"),
        (WeightMethod::Unconstrained, "unconstrained"),
        (WeightMethod::Harmonic, "harmonic"),
    ]
);

/// Settings of a weights run.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct WeightSettings {
    /// Polyharmonic order k (1–4). {2}
    pub order: u8,
    /// Method. {monotone}
    pub method: WeightMethod,
    /// Constraint set of the monotone method (edges at the handles are always constrained). {minimal}
    pub edges: EdgeSet,
    /// Solver settings.
    pub qp: QpSettings,
    /// Worker threads for the independent functions. {2}
    pub threads: usize,
}

impl Default for WeightSettings {
    fn default() -> Self {
        WeightSettings {
            order: 2,
            method: WeightMethod::Monotone,
            edges: EdgeSet::Minimal,
            qp: QpSettings::default(),
            threads: 2,
        }
    }
}

/// Spurious extrema of a function: connected patches of non-regular free vertices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Spurious {
    /// With exact comparisons.
    pub exact: usize,
    /// Counting a neighbour as lower or higher only when it differs by more than 1e-9.
    pub tolerance_1e9: usize,
}

/// One weight function.
#[derive(Clone, Debug, serde::Serialize)]
pub struct WeightFunction {
    /// Handle index.
    pub handle: usize,
    /// The function before normalisation (the certified one, for `monotone`).
    #[serde(skip)]
    pub raw: Vec<f64>,
    /// Representative u: harmonic with non-negative weights, 1 on the handle, 0 on the others.
    #[serde(skip)]
    pub u: Vec<f64>,
    /// Prescribed values (the handles and the filled parts).
    #[serde(skip)]
    pub prescribed: Vec<Option<f64>>,
    /// Free vertices fixed by the fill rule (SPEC.md).
    pub filled: usize,
    /// Levels of extended-precision refinement the representative needed (0: the plain
    /// harmonic function was strictly regular at every free vertex; each level refines the
    /// order where double precision tied neighbours).
    pub refinements: usize,
    /// The no-data certificate of `raw` (it must pass for `monotone`; reported for the others).
    pub certificate: Certificate,
    /// Spurious extrema of `raw`.
    pub spurious: Spurious,
    /// Constrained edges (monotone).
    pub constraints: usize,
    /// Margin ε (monotone).
    pub margin: f64,
    /// Solver outcome (monotone and bounded).
    pub solver_status: Option<SolveStatus>,
    /// Interior-point iterations.
    pub solver_iterations: u32,
    /// Why the structured solver handed the problem to Clarabel, if it did.
    pub solver_fallback: Option<String>,
    /// Vertices the rounding repair changed.
    pub repaired: usize,
    /// Gap `sᵀz + ½ ρᵀP⁻¹ρ` of the monotone QP at the certified function, ÷ its energy
    /// (SPEC.md: without a data term, by one solve with the energy's matrix).
    pub gap_over_energy: Option<f64>,
    /// Seconds for this function (its representative, constraints, solve, repair, certificate).
    pub seconds: f64,
}

impl WeightFunction {
    /// A function not computed yet: the given fixed values completed by the fill rule, and
    /// its representative (harmonic with the non-negative-weight Laplacian `fill`).
    fn prepare<D: Smoothable>(
        domain: &D,
        given: &[Option<f64>],
        handle: usize,
        fill: &Sparse,
        analyses: Option<&mut Analyses>,
    ) -> Result<Self> {
        let mut prescribed = given.to_vec();
        let filled = fill_rule(domain, &mut prescribed);
        let (u, refinements) = ordered_harmonic(domain, fill, &prescribed, analyses).map_err(|e| {
            Error::Representative { path: None, message: format!("handle {handle}: harmonic representative: {e}") }
        })?;
        Ok(WeightFunction {
            handle,
            raw: Vec::new(),
            u,
            prescribed,
            filled,
            refinements,
            certificate: Certificate::default(),
            spurious: Spurious::default(),
            constraints: 0,
            margin: 0.0,
            solver_status: None,
            solver_iterations: 0,
            solver_fallback: None,
            repaired: 0,
            gap_over_energy: None,
            seconds: 0.0,
        })
    }
}

/// All weight functions of a run.
#[derive(Clone, Debug)]
pub struct Weights {
    /// One per handle, in handle order.
    pub functions: Vec<WeightFunction>,
    /// The functions divided by their sum at every vertex.
    pub normalised: Vec<Vec<f64>>,
    /// Largest |normalised − raw| over all functions and vertices.
    pub max_normalisation_change: f64,
    /// Smallest and largest sum of the raw functions at a vertex.
    pub raw_sum_range: [f64; 2],
    /// Seconds to assemble the operators.
    pub operator_seconds: f64,
    /// Wall-clock seconds of all functions together.
    pub function_seconds: f64,
}

/// The fixed values of handle `which`'s function: 1 on its vertices, 0 on the other handles,
/// then the fill rule ([`fill_rule`]). Returns the values and the number of filled vertices.
pub fn prescribed_values<D: Smoothable>(domain: &D, handles: &[Vec<usize>], which: usize) -> (Vec<Option<f64>>, usize) {
    let mut fixed = handle_values(domain.n_vertices(), handles, which);
    let filled = fill_rule(domain, &mut fixed);
    (fixed, filled)
}

/// 1 on handle `which`'s vertices, 0 on the other handles', free elsewhere.
fn handle_values(n: usize, handles: &[Vec<usize>], which: usize) -> Vec<Option<f64>> {
    let mut fixed = vec![None; n];
    for (k, set) in handles.iter().enumerate() {
        for &v in set {
            fixed[v] = Some(if k == which { 1.0 } else { 0.0 });
        }
    }
    fixed
}

/// SPEC's fill rule: a connected part of free vertices whose fixed neighbours all carry one
/// value takes that value (no strict function could fill it otherwise). Returns the number of
/// vertices filled.
pub fn fill_rule<D: Smoothable>(domain: &D, fixed: &mut [Option<f64>]) -> usize {
    let n = domain.n_vertices();
    let mut seen = vec![false; n];
    let mut filled = 0;
    for s in 0..n {
        if fixed[s].is_some() || seen[s] {
            continue;
        }
        seen[s] = true;
        let mut part = vec![s];
        let mut values: Vec<f64> = Vec::new();
        let mut k = 0;
        while k < part.len() {
            let v = part[k];
            k += 1;
            for w in domain.neighbors(v) {
                match fixed[w] {
                    Some(x) if !values.contains(&x) => values.push(x),
                    Some(_) => {}
                    None if !seen[w] => {
                        seen[w] = true;
                        part.push(w);
                    }
                    None => {}
                }
            }
        }
        if values.len() == 1 {
            for &v in &part {
                fixed[v] = Some(values[0]);
            }
            filled += part.len();
        }
    }
    filled
}

/// Operators shared by all functions of a run.
struct Operators {
    energy: Sparse,
    fill: Sparse,
    stiffness: Sparse,
}

/// Regions at 1 are maxima, at 0 minima; other prescribed values (a cage boundary) are exempt.
pub fn region_kind(v: f64) -> RegionKind {
    if v == 1.0 {
        RegionKind::Max
    } else if v == 0.0 {
        RegionKind::Min
    } else {
        RegionKind::Exempt
    }
}

/// One function by the monotone method, or the unconstrained / harmonic solve.
fn one_function<D: Smoothable>(
    domain: &D,
    prescribed: &[Option<f64>],
    which: usize,
    ops: &Operators,
    settings: &WeightSettings,
    analyses: &mut Analyses,
) -> Result<WeightFunction> {
    let t = Instant::now();
    let mut out = WeightFunction::prepare(domain, prescribed, which, &ops.fill, Some(&mut *analyses))?;
    let fixed = &out.prescribed;
    out.raw = match settings.method {
        WeightMethod::Monotone => {
            let edges = constraint_edges(domain, &out.u, fixed, settings.edges);
            let resolution = f64::EPSILON;
            let eps_max = max_margin(&out.u, &edges, fixed, Some(margin_cap(1.0, resolution)))?;
            let eps = choose_margin(eps_max, 1.0, resolution)?;
            let q = vec![0.0; domain.n_vertices()];
            let qp = MonotoneQp {
                p: (&ops.energy).into(),
                q: &q,
                fixed,
                edges: &edges,
                margin: eps,
                bounds: &[],
                data: None,
                hint: Some(&out.u),
                factor: None,
                condition: None,
                second_order: None,
            };
            let sol = solve_monotone_qp_with(&qp, &settings.qp, analyses, None)?;
            let mut f = sol.x;
            let is_fixed: Vec<bool> = fixed.iter().map(|x| x.is_some()).collect();
            let r = repair(&mut f, &is_fixed, &edges, &sos_sort(&out.u), 0.25 * eps);
            out.constraints = edges.len();
            out.margin = eps;
            out.solver_status = Some(sol.status);
            out.solver_iterations = sol.iterations;
            out.solver_fallback = sol.fallback.clone();
            out.repaired = r.changed_vertices;
            let o = crate::solve::optimality_with(&qp, &f, &sol.z, None, Some(analyses));
            out.gap_over_energy = (o.gap.is_finite() && o.energy > 0.0).then(|| o.gap / o.energy);
            f
        }
        WeightMethod::Unconstrained => dirichlet_solve(&ops.energy, fixed)
            .map_err(|e| Error::internal(format!("handle {which}: polyharmonic solve: {e}")))?,
        WeightMethod::Harmonic => dirichlet_solve(&ops.stiffness, fixed)
            .map_err(|e| Error::internal(format!("handle {which}: harmonic solve: {e}")))?,
        WeightMethod::Bounded => unreachable!("bounded weights are solved jointly"),
    };
    finish(domain, &mut out);
    out.seconds = t.elapsed().as_secs_f64();
    Ok(out)
}

/// Certificate and spurious-extremum counts of `out.raw`.
fn finish<D: Smoothable>(domain: &D, out: &mut WeightFunction) {
    out.certificate = certify_no_data(domain, &out.raw, &out.prescribed, region_kind);
    out.spurious = Spurious {
        exact: spurious_components(domain, &out.raw, &out.prescribed, 0.0),
        tolerance_1e9: spurious_components(domain, &out.raw, &out.prescribed, 1e-9),
    };
}

/// Computes one weight function per handle (vertex sets, disjoint, at least two, every
/// component of the domain touched: see [`super::handles::resolve`]) and their normalisation.
/// Functions run in parallel on `settings.threads` workers.
///
/// # Errors
/// Fewer than two handles, overlapping or out-of-range handles, an order outside 1–4 (input
/// and usage errors); a monotone function that fails its certificate (exit 1); no solver
/// point (exit 4).
pub fn weights<D: Smoothable + Sync>(domain: &D, handles: &[Vec<usize>], settings: &WeightSettings) -> Result<Weights> {
    let n = domain.n_vertices();
    if handles.len() < 2 {
        return Err(Error::input(format!("at least two handles are needed, got {}", handles.len())));
    }
    if !(1..=4).contains(&settings.order) {
        return Err(Error::setting("order", format!("must be 1, 2, 3 or 4, got {}", settings.order)));
    }
    let mut owner = vec![usize::MAX; n];
    for (k, set) in handles.iter().enumerate() {
        if set.is_empty() {
            return Err(Error::input(format!("handle {k} selects no vertex")));
        }
        for &v in set {
            if v >= n {
                return Err(Error::input(format!("handle {k}: vertex {v} is out of range ({n} vertices)")));
            }
            if owner[v] != usize::MAX && owner[v] != k {
                return Err(Error::input(format!("handles {} and {k} both select vertex {v}", owner[v])));
            }
            owner[v] = k;
        }
    }
    let prescribed: Vec<Vec<Option<f64>>> = (0..handles.len()).map(|which| handle_values(n, handles, which)).collect();
    weights_prescribed(domain, &prescribed, settings)
}

/// Weight functions with given fixed values (`prescribed[h][v]`; the fill rule is applied to
/// each): regions at 1 must be maxima, at 0 minima, other fixed values are exempt (a cage's
/// boundary). Functions run in parallel on `settings.threads` workers.
///
/// # Errors
/// As [`weights`].
pub fn weights_prescribed<D: Smoothable + Sync>(
    domain: &D,
    prescribed: &[Vec<Option<f64>>],
    settings: &WeightSettings,
) -> Result<Weights> {
    let n = domain.n_vertices();
    let t = Instant::now();
    let k = domain.stiffness();
    let m = domain.mass();
    let energy = crate::pipeline::energy_on_edges(domain, &k, &m, &Energy::order(settings.order), &[1.0]);
    let fill = domain.own_fill_stiffness().unwrap_or_else(|| k.clone());
    let ops = Operators { energy, fill, stiffness: k };
    let operator_seconds = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let count = prescribed.len();
    let functions: Vec<WeightFunction> = if settings.method == WeightMethod::Bounded {
        crate::progress::settle(bounded(domain, prescribed, &ops, settings))?
    } else {
        let next = AtomicUsize::new(0);
        let done = AtomicUsize::new(0);
        let stage = crate::progress::Stage::begin("weights");
        let threads = settings.threads.clamp(1, count);
        let inner = (crate::parallel::threads() / threads).max(1);
        let mut results: Vec<Option<Result<WeightFunction>>> = (0..count).map(|_| None).collect();
        let token = crate::progress::token();
        std::thread::scope(|s| {
            let workers: Vec<_> = (0..threads)
                .map(|_| {
                    let token = token.clone();
                    s.spawn(|| {
                        crate::progress::with_token(token, || {
                            // the cap shared among the workers (the same results for any split: the
                            // plans do not depend on the thread count); the normal matrix's
                            // analysis is shared by this thread's functions
                            crate::parallel::with_threads(inner, || {
                                let mut analyses = Analyses::new();
                                let mut mine = Vec::new();
                                loop {
                                    let h = next.fetch_add(1, Ordering::Relaxed);
                                    if h >= count {
                                        break;
                                    }
                                    if let Err(e) = crate::progress::checkpoint() {
                                        mine.push((h, Err(e)));
                                        continue;
                                    }
                                    mine.push((
                                        h,
                                        one_function(domain, &prescribed[h], h, &ops, settings, &mut analyses),
                                    ));
                                    let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                                    stage.update(|| format!("{d} of {count} functions"));
                                    stage.fraction(d as f64 / count as f64);
                                }
                                mine
                            })
                        })
                    })
                })
                .collect();
            for w in workers {
                for (h, r) in w.join().expect("a weights worker panicked") {
                    results[h] = Some(r);
                }
            }
        });
        let functions = results.into_iter().map(|r| r.expect("every handle was computed")).collect::<Result<_>>();
        let functions = crate::progress::settle(functions)?;
        stage.end(|| format!("{count} functions on {threads} threads"));
        functions
    };
    let function_seconds = t.elapsed().as_secs_f64();
    if settings.method == WeightMethod::Monotone {
        if let Some(f) = functions.iter().find(|f| !f.certificate.passed) {
            return Err(Error::Uncertified {
                path: None,
                message: format!("weight function of handle {}: {}", f.handle, f.certificate.summary()),
            });
        }
    }

    let mut normalised: Vec<Vec<f64>> = vec![vec![0.0; n]; count];
    let mut change = 0.0f64;
    let mut range = [f64::INFINITY, f64::NEG_INFINITY];
    #[allow(clippy::needless_range_loop)] // v indexes every function
    for v in 0..n {
        let sum: f64 = functions.iter().map(|f| f.raw[v]).sum();
        range = [range[0].min(sum), range[1].max(sum)];
        for (h, f) in functions.iter().enumerate() {
            let w = if sum > 0.0 { f.raw[v] / sum } else { f64::NAN };
            normalised[h][v] = w;
            change = change.max((w - f.raw[v]).abs());
        }
    }
    Ok(Weights {
        functions,
        normalised,
        max_normalisation_change: change,
        raw_sum_range: range,
        operator_seconds,
        function_seconds,
    })
}

/// The bounded biharmonic weights, all functions in one problem.
fn bounded<D: Smoothable>(
    domain: &D,
    given: &[Vec<Option<f64>>],
    ops: &Operators,
    settings: &WeightSettings,
) -> Result<Vec<WeightFunction>> {
    let t = Instant::now();
    let mut functions = Vec::with_capacity(given.len());
    for (which, g) in given.iter().enumerate() {
        functions.push(WeightFunction::prepare(domain, g, which, &ops.fill, None)?);
    }
    let fixed: Vec<Vec<Option<f64>>> = functions.iter().map(|f| f.prescribed.clone()).collect();
    let (w, status, it) = solve_bounded_partition(&ops.energy, &fixed, &settings.qp)?;
    let each = t.elapsed().as_secs_f64() / given.len() as f64;
    for (f, raw) in functions.iter_mut().zip(w) {
        f.raw = raw;
        f.solver_status = Some(status);
        f.solver_iterations = it;
        finish(domain, f);
        f.seconds = each;
    }
    Ok(functions)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{Domain, Grid2d, TriMesh};

    /// A 2D bar (rectangle 10 × 1 triangulated as a grid) with point handles at both ends
    /// and one in the middle.
    fn bar() -> (Grid2d, Vec<Vec<usize>>) {
        let g = Grid2d::new(41, 5).unwrap();
        let handles = vec![vec![g.index(2, 0)], vec![g.index(2, 20)], vec![g.index(2, 40)]];
        (g, handles)
    }

    #[test]
    fn fill_rule_fixes_parts_bounded_by_one_value() {
        // a bar with a handle that cuts it: the part beyond takes the cutting handle's value
        let g = Grid2d::new(10, 3).unwrap();
        let cut: Vec<usize> = (0..3).map(|r| g.index(r, 6)).collect();
        let handles = vec![vec![g.index(1, 0)], cut];
        let (p, filled) = prescribed_values(&g, &handles, 0);
        assert_eq!(filled, 9); // columns 7..9
        assert_eq!(p[g.index(0, 9)], Some(0.0));
        let (p, _) = prescribed_values(&g, &handles, 1);
        assert_eq!(p[g.index(2, 8)], Some(1.0));
        assert_eq!(p[g.index(2, 3)], None);
    }

    #[test]
    fn all_four_methods_on_a_bar() {
        let (g, handles) = bar();
        let mut counts = Vec::new();
        for method in
            [WeightMethod::Monotone, WeightMethod::Bounded, WeightMethod::Unconstrained, WeightMethod::Harmonic]
        {
            let w = weights(&g, &handles, &WeightSettings { method, ..Default::default() }).unwrap();
            for f in &w.functions {
                assert_eq!(f.raw[handles[f.handle][0]], 1.0);
                for (k, h) in handles.iter().enumerate() {
                    if k != f.handle {
                        assert_eq!(f.raw[h[0]], 0.0);
                    }
                }
            }
            if method != WeightMethod::Monotone {
                // these are (up to rounding) partitions of unity already
                assert!(
                    (w.raw_sum_range[0] - 1.0).abs() < 1e-6 && (w.raw_sum_range[1] - 1.0).abs() < 1e-6,
                    "{method:?}"
                );
            }
            for row in 0..g.n_vertices() {
                let s: f64 = w.normalised.iter().map(|f| f[row]).sum();
                assert!((s - 1.0).abs() < 1e-12);
            }
            counts.push((method, w.functions.iter().map(|f| f.spurious.exact).sum::<usize>()));
            if method == WeightMethod::Monotone {
                assert!(w.functions.iter().all(|f| f.certificate.passed && f.spurious.exact == 0));
            }
            if method == WeightMethod::Bounded {
                assert!(w.functions.iter().all(|f| f.raw.iter().all(|&x| (-1e-7..=1.0 + 1e-7).contains(&x))));
            }
        }
        // the biharmonic end functions overshoot below 0 beyond the middle handle: a spurious
        // minimum each; the harmonic ones are monotone on a grid (non-negative weights)
        let get = |m: WeightMethod| counts.iter().find(|c| c.0 == m).unwrap().1;
        assert!(get(WeightMethod::Unconstrained) >= 2, "{counts:?}");
        assert_eq!(get(WeightMethod::Monotone), 0);
    }

    #[test]
    fn monotone_weights_are_certified_on_a_mesh_with_obtuse_triangles() {
        // a squashed disk: many obtuse triangles, negative cotangent weights
        let d = crate::domain::shapes::disk(8, 24, &[]);
        let pos: Vec<[f64; 3]> = d.positions().iter().map(|p| [p[0], 0.2 * p[1], 0.0]).collect();
        let mesh = TriMesh::new(pos, d.faces().to_vec()).unwrap();
        let far = |x: f64| {
            (0..mesh.n_vertices())
                .min_by(|&a, &b| (mesh.positions()[a][0] - x).abs().total_cmp(&(mesh.positions()[b][0] - x).abs()))
                .unwrap()
        };
        let handles = vec![vec![far(-1.0)], vec![far(1.0)], vec![0]];
        for order in [2, 3, 4] {
            let w = weights(&mesh, &handles, &WeightSettings { order, ..Default::default() }).unwrap();
            assert!(w.functions.iter().all(|f| f.certificate.passed), "order {order}");
            // the structured solver keeps its point where the gap bound sits on its rounding
            // floor (k = 4 without a data term) instead of handing the problem to Clarabel
            for f in &w.functions {
                assert_eq!(f.solver_fallback, None, "order {order}, handle {}", f.handle);
                assert!(f.gap_over_energy.is_some_and(|g| g < 1e-3), "order {order}: {:?}", f.gap_over_energy);
            }
            assert_eq!(w.functions[0].certificate.strict_maxima, 1);
            assert_eq!(w.functions[0].certificate.strict_minima, 2);
        }
    }

    #[test]
    fn bad_handle_sets_are_errors() {
        let (g, _) = bar();
        let s = WeightSettings::default();
        assert!(weights(&g, &[vec![0]], &s).is_err());
        assert!(weights(&g, &[vec![0], vec![0]], &s).unwrap_err().to_string().contains("both select vertex 0"));
        assert!(weights(&g, &[vec![0], vec![]], &s).is_err());
        assert!(weights(&g, &[vec![0], vec![10_000]], &s).is_err());
        assert!(matches!(
            weights(&g, &[vec![0], vec![1]], &WeightSettings { order: 5, ..s }),
            Err(Error::Setting { setting: "order", .. })
        ));
    }
}
