//! The choice of solver for a monotone QP: the structured interior-point method in the
//! assembled or the factored form, Clarabel as its fallback or on its own.

use super::newton::Prepared;
use super::problem::{
    constraint_rows, reduce, reduce_factor, reduce_with, rescale, MonotoneQp, Quadratic, ReducedQp, MAX_VARIABLES,
};
use super::settings::{Formulation, Method, QpSettings, DOUBLE_DOUBLE_ABOVE, FACTORED_ABOVE};
use super::status::{QpSolution, SolveStatus};
use crate::error::Result;
use crate::linalg::Analyses;
use crate::operators::{Factor, Sparse};

/// Solves the monotone QP.
///
/// # Errors
/// [`crate::Error::NoSolution`] when no solver returns a usable point; a usage error for
/// [`Method::ClarabelAuxiliary`] or [`Formulation::Factored`] without a factor.
pub fn solve_monotone_qp(qp: &MonotoneQp<'_>, settings: &QpSettings) -> Result<QpSolution> {
    solve_monotone_qp_with(qp, settings, &mut Analyses::default(), None)
}

/// [`solve_monotone_qp`] for a sequence of QPs: the structured solver's analysis of the
/// normal matrix is taken from `analyses` when it holds one for the same pattern (the same
/// energy, fixed set and constrained pairs) and kept there for the next; `prepared` (made by
/// [`prepare`] beside other work) is used if the normal matrix has its pattern.
///
/// # Errors
/// As [`solve_monotone_qp`].
pub fn solve_monotone_qp_with(
    qp: &MonotoneQp<'_>,
    settings: &QpSettings,
    analyses: &mut Analyses,
    prepared: Option<Prepared>,
) -> Result<QpSolution> {
    let n = qp.q.len();
    assert_eq!(qp.fixed.len(), n);
    assert_eq!(qp.p.n(), n);
    let free: Vec<usize> = (0..n).filter(|&i| qp.fixed[i].is_none()).collect();
    if free.len() > MAX_VARIABLES {
        return Err(crate::error::Error::input(format!(
            "{} free vertices: the solver takes at most {MAX_VARIABLES}",
            free.len()
        )));
    }
    let fixed_values = || -> Vec<f64> { qp.fixed.iter().map(|f| f.unwrap_or(0.0)).collect() };
    if free.is_empty() {
        return Ok(QpSolution {
            x: fixed_values(),
            z: vec![0.0; constraint_rows(qp).len()],
            y: None,
            status: SolveStatus::Trivial,
            iterations: 0,
            inner_iterations: 0,
            method: settings.method,
            formulation: Formulation::Assembled,
            condition: None,
            fallback: None,
            predicted_peak: None,
        });
    }
    // the active set makes its own forms of P and the rows from the problem: the reduced QP
    // is made without its triplets for it (rebuilt should another route take over)
    let light = settings.method == Method::ActiveSet
        && settings.formulation != Formulation::Factored
        && qp.condition.is_some_and(|c| settings.formulation == Formulation::Assembled || c <= FACTORED_ABOVE);
    let (mut reduced, upper_entries) = reduce_with(qp, &free, !light);
    let condition = qp.condition.or_else(|| super::condition::estimate(&reduced));
    let wants_factored = match (settings.method, settings.formulation) {
        (Method::ClarabelAuxiliary, _) | (_, Formulation::Factored) => true,
        (_, Formulation::Assembled) => false,
        (_, Formulation::Auto) => condition.is_some_and(|c| c > FACTORED_ABOVE),
    };
    let forced = settings.method == Method::ClarabelAuxiliary || settings.formulation == Formulation::Factored;
    let to_factored = |reduced: &mut ReducedQp, f: &Factor| {
        // scaled by the data term rather than by P's diagonal: the variables' own block
        // (d) then has unit size beside Clarabel's static regularisation, F carries √κ
        let d_mean = reduced.d.iter().sum::<f64>() / reduced.n as f64;
        if d_mean > 0.0 {
            rescale(reduced, d_mean);
        }
        let mut factor = reduce_factor(qp, f, &free, reduced.scale);
        factor.double_iteration = reduced.gap_bound && condition.is_some_and(|c| c <= DOUBLE_DOUBLE_ABOVE);
        reduced.factor = Some(factor);
    };
    let mut formulation = match (wants_factored, qp.factor) {
        (true, Some(f)) => {
            to_factored(&mut reduced, f);
            Formulation::Factored
        }
        (true, None) if forced => {
            return Err(crate::Error::Usage(
                "the factored formulation needs the energy as FᵀF (not available for this energy)".into(),
            ))
        }
        _ => Formulation::Assembled,
    };
    // the storage made in advance is for the assembled normal matrix only
    let mut prepared = prepared.filter(|_| formulation == Formulation::Assembled);
    // the start on the free entries, made for each route that takes it (the interior point
    // keeps it as its iterate: at 10⁷ samples a copy held through the solve was 80 MB)
    let hint = || -> Option<Vec<f64>> { qp.hint.map(|h| free.iter().map(|&i| h[i]).collect()) };
    let mut fallback = None;
    // Clarabel on the reduced QP; on the paper's auxiliary form it can certify infeasibility
    // of rows that are feasible by construction (the margin was checked on u's order): a
    // 54-sample series at k = 4, κ 3.8·10¹⁰, "PrimalInfeasible after 3 iterations". Unless
    // that form was asked for, the assembled one is solved then.
    let may_assemble = settings.formulation == Formulation::Auto && settings.method != Method::ClarabelAuxiliary;
    let clarabel =
        |reduced: &mut ReducedQp, formulation: &mut Formulation| match super::clarabel::solve(reduced, settings) {
            Err(crate::Error::NoSolution { status, .. })
                if may_assemble && reduced.factor.is_some() && status.contains("Infeasible") =>
            {
                reduced.factor = None;
                *formulation = Formulation::Assembled;
                super::clarabel::solve(reduced, settings)
            }
            other => other,
        };
    let mut inner_iterations = 0;
    let mut predicted_peak = None;
    let attempt = match settings.method {
        Method::ActiveSet if formulation == Formulation::Assembled && reduced.gap_bound => {
            // the iteration's peak beside what the process holds: past the budget it is
            // refused, not started (the interior-point route would need more still)
            let budget = crate::memory::Budget::of(settings.memory_limit);
            let fits = |extra: u64| {
                let peak = budget.in_use() + extra + budget.kernel_reserve();
                if peak > budget.bytes {
                    Err(crate::memory::over_budget("the active-set iteration", peak, &budget))
                } else {
                    Ok(peak)
                }
            };
            // its operands first, then the iteration beside them, each checked before it is made
            let two_pass = qp.second_order.map(|e| (e.k.ncols(), e.k.val().len()));
            let made = matches!(qp.p, Quadratic::Columns(_)).then(crate::parallel::threads);
            let before = fits(super::active_set::operand_bytes(reduced.n, reduced.m(), upper_entries, two_pass, made))?;
            let t = std::time::Instant::now();
            let operands = super::active_set::Operands::new(qp, &free, &reduced);
            if std::env::var_os("TOPOSMOOTH_TRACE_ACTIVE").is_some() {
                eprintln!("active set: operands made in {} ms", t.elapsed().as_millis());
            }
            let outcome = match operands {
                Ok(operands) => {
                    let beside = fits(super::active_set::iteration_bytes(reduced.n, reduced.m()))?;
                    predicted_peak = Some(before.max(beside));
                    super::active_set::solve(&reduced, operands, hint().as_deref(), settings)
                }
                Err(why) => Err(why),
            };
            match outcome {
                Ok(a) if a.outcome.status == SolveStatus::Solved => {
                    inner_iterations = a.cg_iterations;
                    Some(a.outcome)
                }
                Ok(a) => {
                    crate::progress::checkpoint()?;
                    fallback = Some(format!(
                        "the active-set iteration ended {:?} after {} outer and {} conjugate-gradient iterations",
                        a.outcome.status, a.outcome.iterations, a.cg_iterations
                    ));
                    None
                }
                Err(why) => {
                    crate::progress::checkpoint()?;
                    fallback = Some(why.to_string());
                    None
                }
            }
        }
        Method::ActiveSet => {
            fallback = Some("the active-set iteration needs the assembled energy with a data term everywhere".into());
            None
        }
        _ => None,
    };
    if attempt.is_none() && light {
        // the route taking over needs the triplets
        reduced = reduce(qp, &free);
    }
    let (out, method) = match (attempt, settings.method) {
        (Some(out), _) => (out, Method::ActiveSet),
        (None, Method::Auto | Method::Structured | Method::ActiveSet) => {
            // the interior-point route's peak, predicted from its analysis before it allocates
            // (the analysis, the rows and the pattern are kept for the solve); past the budget
            // it is refused, not started
            let mut assembly = None;
            if let Some((extra, made)) = super::ipm::predicted_bytes(&reduced, analyses).ok().flatten() {
                let budget = crate::memory::Budget::of(settings.memory_limit);
                let peak = budget.in_use() + extra + budget.kernel_reserve();
                if peak > budget.bytes {
                    let what = match &fallback {
                        Some(why) => format!("{why}; the interior-point route that would take over"),
                        None => "the interior-point route".into(),
                    };
                    return Err(crate::memory::over_budget(&what, peak, &budget));
                }
                predicted_peak = Some(predicted_peak.map_or(peak, |p: u64| p.max(peak)));
                assembly = Some(made);
            }
            if let Some(why) = &fallback {
                super::policy::announce_hand_over(why, Method::Structured);
            }
            match super::ipm::solve(&reduced, assembly, hint(), settings, analyses, prepared.take()) {
                Ok(out) => (out, Method::Structured),
                // the assembled normal matrix lost its definiteness (an energy without a data
                // term, ill-conditioned on its own): the factored form in double-double next
                Err(_) if crate::progress::cancelled() => return Err(crate::Error::Cancelled),
                Err(_)
                    if formulation == Formulation::Assembled
                        && settings.formulation == Formulation::Auto
                        && qp.factor.is_some() =>
                {
                    to_factored(&mut reduced, qp.factor.expect("checked"));
                    formulation = Formulation::Factored;
                    match super::ipm::solve(&reduced, None, hint(), settings, analyses, None) {
                        Ok(out) => (out, Method::Structured),
                        Err(why) => {
                            crate::progress::checkpoint()?;
                            fallback = Some(why.to_string());
                            super::policy::announce_hand_over(&why.to_string(), Method::Clarabel);
                            (clarabel(&mut reduced, &mut formulation)?, Method::Clarabel)
                        }
                    }
                }
                Err(why) => {
                    crate::progress::checkpoint()?;
                    fallback = Some(why.to_string());
                    super::policy::announce_hand_over(&why.to_string(), Method::Clarabel);
                    (clarabel(&mut reduced, &mut formulation)?, Method::Clarabel)
                }
            }
        }
        (None, Method::Clarabel | Method::ClarabelAuxiliary) => {
            (clarabel(&mut reduced, &mut formulation)?, settings.method)
        }
    };
    // made after the solve: the solver's storage is gone by then
    let mut x = fixed_values();
    for (k, &i) in free.iter().enumerate() {
        x[i] = out.x[k];
    }
    // multipliers and auxiliary variables back in the problem's units
    let z = out.z.iter().map(|v| v.max(0.0) * reduced.scale).collect();
    let y = out.y.map(|y| y.iter().map(|v| v * reduced.scale.sqrt()).collect());
    Ok(QpSolution {
        x,
        z,
        y,
        status: out.status,
        iterations: out.iterations,
        inner_iterations,
        method,
        formulation,
        condition,
        fallback,
        predicted_peak,
    })
}

/// The structured solver's analysis of the normal matrix of a QP with energy `p` and fixed
/// entries `fixed`, made before the constraints and the linear term are known (so that it can
/// run beside the work that finds them); [`solve_monotone_qp_with`] given it uses it when
/// the normal matrix has this pattern (constrained pairs inside `p`'s pattern, as for every
/// energy built on the domain's Laplacian).
///
/// The factor's storage is made (and its pages mapped) only where it fits the memory budget
/// `memory_limit` (`None`: the machine's) beside what the process holds now: past it the
/// solver's own prediction refuses the route.
///
/// `None` when `p` is banded (a series): the solver factorises such a normal matrix by the
/// band's own `LDLᵀ`, with nothing to analyse or prepare.
///
/// # Errors
/// A message if the analysis fails.
pub fn prepare(
    p: &Sparse,
    fixed: &[Option<f64>],
    memory_limit: Option<u64>,
) -> std::result::Result<Option<Prepared>, crate::error::NumericalError> {
    if crate::linalg::band(p.symbolic()).is_some() {
        return Ok(None);
    }
    let mut slot = vec![usize::MAX; fixed.len()];
    let mut n = 0;
    for (i, f) in fixed.iter().enumerate() {
        if f.is_none() {
            slot[i] = n;
            n += 1;
        }
    }
    let budget = crate::memory::Budget::of(memory_limit);
    Prepared::new(p.symbolic(), &slot, n, |bytes| budget.in_use().saturating_add(bytes) <= budget.bytes).map(Some)
}

#[cfg(test)]
mod tests {
    use super::super::problem::UpperP;
    use super::*;
    use faer::sparse::Triplet;

    /// `P = K + I` of an `nx × ny` grid with the 4-neighbour Laplacian `K`, and its edges.
    fn grid_qp(nx: usize, ny: usize) -> (Sparse, Vec<(usize, usize)>) {
        let n = nx * ny;
        let mut t = Vec::new();
        let mut edges = Vec::new();
        for y in 0..ny {
            for x in 0..nx {
                let v = y * nx + x;
                t.push(Triplet::new(v, v, 1.0));
                for w in [(x + 1 < nx).then_some(v + 1), (y + 1 < ny).then_some(v + nx)].into_iter().flatten() {
                    edges.push((v, w));
                    t.extend([Triplet::new(v, w, -1.0), Triplet::new(w, v, -1.0)]);
                    t.extend([Triplet::new(v, v, 1.0), Triplet::new(w, w, 1.0)]);
                }
            }
        }
        (Sparse::try_new_from_triplets(n, n, &t).unwrap(), edges)
    }

    type Wave = (Sparse, Vec<(usize, usize)>, Vec<f64>, Vec<Option<f64>>);

    /// [`grid_qp`] with a linear term of waves along x and a slope along y, the first vertex
    /// fixed at −1 and the last at 2: its `P`, edges, `q` and fixed values.
    fn wave_qp(nx: usize, ny: usize) -> Wave {
        let n = nx * ny;
        let (p, edges) = grid_qp(nx, ny);
        let q = (0..n).map(|i| -(((i % nx) as f64 * 0.3).sin() + (i / nx) as f64 * 0.01)).collect();
        let mut fixed = vec![None; n];
        fixed[0] = Some(-1.0);
        fixed[n - 1] = Some(2.0);
        (p, edges, q, fixed)
    }

    /// [`wave_qp`]'s problem with a data term, its condition given (known: the active set's
    /// reduced QP is made without triplets).
    fn with_data<'a>(wave: &'a Wave, data: &'a [f64]) -> MonotoneQp<'a> {
        let (p, edges, q, fixed) = wave;
        MonotoneQp {
            p: p.into(),
            q,
            fixed,
            edges,
            margin: 1e-6,
            hint: None,
            bounds: &[],
            data: Some(data),
            factor: None,
            condition: Some(1.0),
            second_order: None,
        }
    }

    #[test]
    fn a_banded_energy_is_not_prepared_and_a_grid_s_is() {
        // a path's P = K + I is tridiagonal: the solver factorises its normal matrix by the band
        let (path, _) = grid_qp(40, 1);
        assert!(prepare(&path, &[None; 40], None).unwrap().is_none());
        let (grid, _) = grid_qp(12, 10);
        assert!(prepare(&grid, &[None; 120], None).unwrap().is_some());
    }

    #[test]
    fn a_banded_p_is_reduced_to_its_band_and_a_grid_s_to_triplets() {
        // the free upper triangle of P, scaled as the reduction scales it, entry by entry
        let expected = |p: &Sparse, free: &[usize], scale: f64| {
            let (cp, ri, val) = (p.symbolic().col_ptr(), p.symbolic().row_idx(), p.val());
            let mut e = Vec::new();
            for (sj, &j) in free.iter().enumerate() {
                for k in cp[j]..cp[j + 1] {
                    if let Ok(si) = free.binary_search(&ri[k]) {
                        if si <= sj {
                            e.push((si, sj, val[k] / scale));
                        }
                    }
                }
            }
            e
        };
        for (nx, ny) in [(40, 1), (12, 5)] {
            let mut wave = wave_qp(nx, ny);
            // a fixed vertex inside: its neighbours become neighbours in the reduced numbering
            wave.3[nx * ny / 2] = Some(0.5);
            let data = vec![0.5; nx * ny];
            let qp = MonotoneQp { condition: None, ..with_data(&wave, &data) };
            let (p, fixed) = (&wave.0, &wave.3);
            let free: Vec<usize> = (0..nx * ny).filter(|&i| fixed[i].is_none()).collect();
            let r = reduce(&qp, &free);
            let want = expected(p, &free, r.scale);
            let got: Vec<_> = r.p.entries().filter(|e| e.2 != 0.0).collect();
            assert_eq!(got, want);
            match (&r.p, ny) {
                (UpperP::Band { width: 1, values }, 1) => assert_eq!(values.len(), 2 * free.len()),
                (UpperP::Triplets(t), 5) => assert_eq!(t.len(), r.p.len()),
                (other, _) => panic!("{nx}×{ny}: {other:?}"),
            }
            // the band's places without an entry (beside the fixed vertex) are the only zeros
            assert_eq!(r.p.len() - got.len(), if ny == 1 { 1 } else { 0 });
            // made for the active set: no entries in either form
            assert_eq!(reduce_with(&qp, &free, false).0.p.len(), 0);
        }
    }

    #[test]
    fn a_prepared_analysis_matches_the_normal_matrix_and_changes_nothing() {
        let (nx, ny) = (60, 50);
        let n = nx * ny;
        let (p, edges, q, fixed) = wave_qp(nx, ny);
        // every edge increasing to the right and upwards: a monotone ramp, feasible
        let hint: Vec<f64> = (0..n).map(|i| -1.0 + 3.0 * ((i % nx) + (i / nx)) as f64 / (nx + ny - 2) as f64).collect();
        let qp = MonotoneQp {
            p: (&p).into(),
            q: &q,
            fixed: &fixed,
            edges: &edges,
            margin: 1e-6,
            hint: Some(&hint),
            bounds: &[],
            data: None,
            factor: None,
            condition: None,
            second_order: None,
        };
        let free: Vec<usize> = (0..n).filter(|&i| fixed[i].is_none()).collect();
        let reduced = reduce(&qp, &free);
        let prepared = prepare(&p, &fixed, None).unwrap().expect("a grid's P is not banded");
        let normal = super::super::ipm::normal_pattern(&reduced);
        let same = |a: faer::sparse::SymbolicSparseColMatRef<'_, usize>| {
            a.col_ptr() == normal.col_ptr() && a.row_idx() == normal.row_idx()
        };
        assert!(same(prepared.pattern()), "the prepared pattern is the normal matrix's");
        // a constrained pair outside P's pattern: a different pattern (analysed anew by the solver)
        let far = [(1, n - 2)];
        let other = reduce(&MonotoneQp { edges: &far, ..qp }, &free);
        assert!(!same(super::super::ipm::normal_pattern(&other).as_ref()));
        let settings = QpSettings::default();
        let plain = solve_monotone_qp(&qp, &settings).unwrap();
        let mut analyses = Analyses::default();
        let with = solve_monotone_qp_with(&qp, &settings, &mut analyses, prepare(&p, &fixed, None).unwrap()).unwrap();
        assert_eq!(plain.iterations, with.iterations);
        // kept for the next solve on the pattern: the same result again
        let again = solve_monotone_qp_with(&qp, &settings, &mut analyses, None).unwrap();
        assert_eq!(again.x, with.x);
        let diff = plain.x.iter().zip(&with.x).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(diff < 1e-12, "{diff:e}");
        assert!(edges.iter().all(|&(i, j)| with.x[j] - with.x[i] >= 0.5e-6));
    }

    /// The active-set route handing over (here for a free variable without a data term): the
    /// structured solver then works on the reduced QP rebuilt with the triplets the active
    /// set's went without, and gives the bits the structured route gives alone.
    #[test]
    fn a_hand_over_from_the_active_set_solves_the_rebuilt_problem() {
        let (nx, ny) = (30, 20);
        let n = nx * ny;
        let wave = wave_qp(nx, ny);
        let mut data = vec![1.0; n];
        data[n / 2] = 0.0;
        let qp = with_data(&wave, &data);
        let run = |method| solve_monotone_qp(&qp, &QpSettings { method, ..QpSettings::default() }).unwrap();
        let (handed, direct) = (run(Method::ActiveSet), run(Method::Structured));
        assert!(handed.fallback.as_deref().is_some_and(|f| f.contains("data term")), "{:?}", handed.fallback);
        assert_eq!(handed.method, Method::Structured);
        assert_eq!(handed.x, direct.x);
        assert_eq!(handed.iterations, direct.iterations);
        assert!(wave.1.iter().all(|&(i, j)| handed.x[j] - handed.x[i] >= 0.5e-6));
    }

    type Chain = (Sparse, [f64; 4], [Option<f64>; 4], [(usize, usize); 3]);

    /// min Σ (f_i − h_i)² with f_0 = 0, f_3 = 3 fixed and f increasing: h = [0, 2, 1, 3]
    fn chain() -> Chain {
        let p =
            Sparse::try_new_from_triplets(4, 4, &(0..4).map(|i| Triplet::new(i, i, 1.0)).collect::<Vec<_>>()).unwrap();
        (p, [0.0, -2.0, -1.0, -3.0], [Some(0.0), None, None, Some(3.0)], [(0, 1), (1, 2), (2, 3)])
    }

    /// [`chain`]'s QP, without a data term, from `hint`.
    fn chain_qp<'a>(
        p: &'a Sparse,
        q: &'a [f64],
        fixed: &'a [Option<f64>],
        edges: &'a [(usize, usize)],
        hint: Option<&'a [f64]>,
    ) -> MonotoneQp<'a> {
        MonotoneQp {
            p: p.into(),
            q,
            fixed,
            edges,
            margin: 1e-6,
            hint,
            bounds: &[],
            data: None,
            factor: None,
            condition: None,
            second_order: None,
        }
    }

    #[test]
    fn both_solvers_project_onto_a_monotone_chain() {
        let (p, q, fixed, edges) = chain();
        for method in [Method::Structured, Method::Clarabel] {
            for hint in [None, Some(&[0.0, 1.0, 2.0, 3.0][..])] {
                let qp = chain_qp(&p, &q, &fixed, &edges, hint);
                let sol = solve_monotone_qp(&qp, &QpSettings { method, ..Default::default() }).unwrap();
                assert_eq!(sol.method, method, "{:?}", sol.fallback);
                assert!(matches!(sol.status, SolveStatus::Solved | SolveStatus::AlmostSolved));
                // isotonic regression pools 2 and 1 at 1.5 (then the margin splits them)
                assert!((sol.x[1] - 1.5).abs() < 1e-5 && (sol.x[2] - 1.5).abs() < 1e-5, "{method:?}: {:?}", sol.x);
                assert!(sol.x[2] - sol.x[1] > 0.5e-6);
                assert_eq!((sol.x[0], sol.x[3]), (0.0, 3.0));
            }
        }
    }

    #[test]
    fn a_hand_over_says_why_in_the_solution_and_to_the_progress_observer() {
        use crate::progress::{observe, Observer};
        use std::sync::{Arc, Mutex};
        #[derive(Default)]
        struct Ends(Mutex<Vec<(String, String)>>);
        impl Observer for Ends {
            fn begin(&self, _: &str) {}
            fn update(&self, _: &str, _: &str) {}
            fn end(&self, stage: &str, _: f64, summary: &str) {
                self.0.lock().unwrap().push((stage.to_string(), summary.to_string()));
            }
        }
        // no data term: the active-set iteration cannot bound its gap and hands over
        let (p, q, fixed, edges) = chain();
        let qp = chain_qp(&p, &q, &fixed, &edges, None);
        let ends = Arc::new(Ends::default());
        let sol = observe(ends.clone(), || {
            solve_monotone_qp(&qp, &QpSettings { method: Method::ActiveSet, ..Default::default() })
        })
        .unwrap();
        assert_eq!(sol.method, Method::Structured);
        let why = sol.fallback.expect("the reason is in the solution");
        assert!(why.contains("data term"), "{why}");
        let ends = ends.0.lock().unwrap();
        assert_eq!(ends.len(), 1, "{ends:?}");
        assert_eq!(ends[0].0, "hand-over");
        assert!(ends[0].1.starts_with(&why) && ends[0].1.ends_with("the interior-point method takes over"), "{ends:?}");
    }

    #[test]
    fn the_active_set_iteration_reaches_the_interior_point_optimum() {
        // P = K² / 2 + I (a biharmonic-like energy: not an M-matrix) on a 14 × 11 grid, noisy
        // data and every edge constrained to rise with x + y, two corners fixed
        let (nx, ny) = (14, 11);
        let n = nx * ny;
        let (k, edges) = grid_qp(nx, ny);
        let kd = k.to_dense();
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let mut v: f64 = (0..n).map(|m| kd[(i, m)] * kd[(m, j)]).sum::<f64>() / 2.0;
                if i == j {
                    v += 1.0;
                }
                if v != 0.0 {
                    t.push(Triplet::new(i, j, v));
                }
            }
        }
        let p = Sparse::try_new_from_triplets(n, n, &t).unwrap();
        let ramp = |i: usize| ((i % nx) + (i / nx)) as f64 / (nx + ny - 2) as f64;
        let h: Vec<f64> = (0..n).map(|i| ramp(i) + 0.3 * ((i * 7919) % 13) as f64 / 13.0 - 0.15).collect();
        let q: Vec<f64> = h.iter().map(|v| -v).collect();
        let d = vec![1.0; n];
        let mut fixed = vec![None; n];
        fixed[0] = Some(-0.2);
        fixed[n - 1] = Some(1.2);
        let hint: Vec<f64> = (0..n).map(|i| -0.2 + 1.4 * ramp(i)).collect();
        let qp = MonotoneQp {
            p: (&p).into(),
            q: &q,
            fixed: &fixed,
            edges: &edges,
            margin: 1e-6,
            hint: Some(&hint),
            bounds: &[],
            data: Some(&d),
            factor: None,
            condition: None,
            second_order: None,
        };
        let objective = |x: &[f64]| {
            let px = &p * faer::Mat::from_fn(n, 1, |i, _| x[i]);
            (0..n).map(|i| 0.5 * x[i] * px[(i, 0)] + q[i] * x[i]).sum::<f64>()
        };
        let ipm = solve_monotone_qp(&qp, &QpSettings::default()).unwrap();
        let active = solve_monotone_qp(&qp, &QpSettings { method: Method::ActiveSet, ..Default::default() }).unwrap();
        assert_eq!(active.method, Method::ActiveSet, "{:?}", active.fallback);
        assert_eq!(active.status, SolveStatus::Solved);
        assert!(active.inner_iterations > 0);
        // the constraints bind somewhere (the data falls along the ramp), and hold to a margin
        let binding = edges.iter().filter(|&&(i, j)| ipm.x[j] - ipm.x[i] < 2e-6).count();
        assert!(binding > 5, "{binding} binding edges");
        let worst = edges.iter().map(|&(i, j)| active.x[j] - active.x[i]).fold(f64::INFINITY, f64::min);
        assert!(worst > 0.5e-6, "{worst:e}");
        let (ja, ji) = (objective(&active.x), objective(&ipm.x));
        let data: f64 = (0..n).map(|i| 0.5 * (active.x[i] - h[i]).powi(2)).sum();
        assert!((ja - ji).abs() <= 1e-6 * data, "objectives {ja} and {ji}, data term {data}");
        let diff = active.x.iter().zip(&ipm.x).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(diff < 1e-3, "{diff:e}");
    }
}
