//! The `Smoother`: many fields on one domain give exactly what one-off runs give, on a
//! series, a grid and a mesh, with the domain's operators and analyses reused.

mod common;

use common::uniform;
use toposmooth::domain::{shapes, Domain, Grid2d, Series};
use toposmooth::pipeline::{smooth, SmoothSettings, Smoothable};
use toposmooth::smoother::{AnyDomain, AnySmoother, Smoother};
use toposmooth::topology::Selection;

/// Fields `step = 0, 1, 2` of a moving pattern plus noise on `domain`.
fn fields<D: Domain>(domain: &D, seed: u64) -> Vec<Vec<f64>> {
    (0..3)
        .map(|step| {
            let r = uniform(seed + step, domain.n_vertices());
            (0..domain.n_vertices())
                .map(|v| {
                    let [x, y, z] = domain.point(v);
                    let t = step as f64 * 0.7;
                    (1.3 * x + t).sin() * (0.9 * y - 0.5 * t).cos() + 0.3 * z + 0.2 * (r[v] - 0.5)
                })
                .collect()
        })
        .collect()
}

fn check<D: Smoothable + Sync + Clone>(name: &str, domain: D, settings: SmoothSettings, seed: u64) {
    let fields = fields(&domain, seed);
    let mut smoother = Smoother::new(domain.clone(), settings.clone()).unwrap();
    for (step, h) in fields.iter().enumerate() {
        let reused = smoother.smooth(h).unwrap();
        let alone = smooth(&domain, h, &settings).unwrap();
        assert!(reused.report.certificate.passed, "{name} step {step}");
        assert_eq!(reused.report.solver_iterations, alone.report.solver_iterations, "{name} step {step}");
        assert_eq!(reused.output, alone.output, "{name} step {step}: the outputs differ");
        assert_eq!(reused.roles, alone.roles, "{name} step {step}");
    }
}

#[test]
fn many_fields_on_one_domain_give_the_one_off_results() {
    let relative = |t: f64| SmoothSettings { selection: Selection::Relative(t), ..Default::default() };
    let x: Vec<f64> = (0..400).map(|i| i as f64 * 0.05).collect();
    check("series", Series::with_coordinates(x).unwrap(), relative(0.1), 1);
    check("grid", Grid2d::new(40, 30).unwrap(), relative(0.15), 2);
    check("sphere", shapes::sphere(1.0, 16, 24), relative(0.15), 3);
}

#[test]
fn a_field_of_the_wrong_size_is_an_input_error_and_the_smoother_goes_on() {
    let grid = Grid2d::new(20, 10).unwrap();
    let h = fields(&grid, 4).remove(0);
    let mut smoother = Smoother::new(grid, SmoothSettings::default()).unwrap();
    let e = smoother.smooth(&h[..150]).unwrap_err();
    assert_eq!(e.exit_code(), 3, "{e}");
    assert!(e.to_string().contains("150 values"), "{e}");
    assert!(smoother.smooth(&h).unwrap().report.certificate.passed);
}

#[test]
fn the_run_time_domain_smoother_is_the_generic_one() {
    let grid = Grid2d::new(30, 20).unwrap();
    let settings = SmoothSettings { selection: Selection::Relative(0.15), ..Default::default() };
    let h = fields(&grid, 5);
    let mut any = AnySmoother::new(AnyDomain::Grid(grid.clone()), settings.clone()).unwrap();
    let mut generic = Smoother::new(grid, settings).unwrap();
    assert_eq!(any.n_vertices(), 600);
    for f in &h {
        assert_eq!(any.smooth(f).unwrap().output, generic.smooth(f).unwrap().output);
    }
}

#[test]
fn a_smoother_can_move_to_another_thread() {
    fn send<T: Send>(_: &T) {}
    let grid = Grid2d::new(30, 20).unwrap();
    let h = fields(&grid, 6).remove(0);
    let mut smoother = Smoother::new(grid, SmoothSettings::default()).unwrap();
    send(&smoother);
    let first = smoother.smooth(&h).unwrap().output;
    let again = std::thread::spawn(move || smoother.smooth(&h).unwrap().output).join().unwrap();
    assert_eq!(first, again);
    let any = AnySmoother::new(AnyDomain::Series(Series::uniform(50)), SmoothSettings::default()).unwrap();
    send(&any);
}

/// Results do not depend on the thread count: one thread runs every parallel part (the
/// representative beside the solver's analysis, nested dissection's halves, the two-way
/// factorisation) one after the other, with the plans chosen from the problem alone. The
/// 120 × 90 grid (10,800 unknowns) is past the size where nested dissection and the two-way
/// plan are considered; weights run their functions on 1 and 2 workers.
/// Every thread count gives the same bits, faer's parallel kernels included: every
/// factorisation is made parallel here and faer's pool allowed four threads, on two cores.
#[test]
fn results_are_bit_identical_for_1_2_3_and_4_threads_with_parallel_kernels() {
    use toposmooth::parallel::{set_parallel_factor_flops, with_threads};
    faer::set_global_parallelism(faer::Par::rayon(4));
    set_parallel_factor_flops(0.0);
    let grid = Grid2d::new(100, 80).unwrap();
    let settings = SmoothSettings { selection: Selection::Relative(0.1), ..Default::default() };
    let h = &fields(&grid, 5)[0];
    let runs: Vec<_> = (1..=4).map(|t| with_threads(t, || smooth(&grid, h, &settings).unwrap())).collect();
    set_parallel_factor_flops(toposmooth::parallel::PARALLEL_FACTOR_FLOPS);
    for (t, r) in runs.iter().enumerate().skip(1) {
        assert!(r.report.certificate.passed);
        assert_eq!(runs[0].output, r.output, "1 and {} threads give different outputs", t + 1);
        assert_eq!(runs[0].u, r.u);
    }
}

#[test]
fn results_are_bit_identical_for_one_and_two_threads() {
    use toposmooth::parallel::with_threads;
    let grid = Grid2d::new(120, 90).unwrap();
    let settings = SmoothSettings { selection: Selection::Relative(0.1), ..Default::default() };
    for h in fields(&grid, 11).iter().take(2) {
        let one = with_threads(1, || smooth(&grid, h, &settings).unwrap());
        let two = with_threads(2, || smooth(&grid, h, &settings).unwrap());
        assert!(one.report.certificate.passed);
        assert_eq!(one.output, two.output, "the outputs differ between 1 and 2 threads");
        assert_eq!((one.u, one.roles), (two.u, two.roles));
    }
    use toposmooth::apps::weights::{weights, WeightSettings};
    let sheet = Grid2d::new(70, 50).unwrap();
    let handles = vec![vec![0], vec![69], vec![70 * 49 + 35]];
    let run = |threads: usize| {
        let s = WeightSettings { threads, ..Default::default() };
        with_threads(threads, || weights(&sheet, &handles, &s).unwrap())
    };
    let (one, two) = (run(1), run(2));
    for (a, b) in one.functions.iter().zip(&two.functions) {
        assert!(a.certificate.passed);
        assert_eq!(a.raw, b.raw, "weight {} differs between 1 and 2 threads", a.handle);
    }
}

/// A long series takes the routes that split work between threads: the interior-point
/// iteration's vector loops (from `parallel::SPLIT_FROM` entries), the band factorised from both
/// ends (from 2¹⁴ rows) and the output formatted in blocks; in double (assembled) and in
/// double-double (factored), every thread count gives the same bits.
#[test]
fn a_long_series_is_bit_identical_for_1_2_and_3_threads_in_both_forms() {
    use toposmooth::parallel::{with_threads, SPLIT_FROM};
    use toposmooth::solve::Formulation;
    let n = SPLIT_FROM + 1234;
    let steps = uniform(42, n);
    let mut h = Vec::with_capacity(n);
    let mut v = 0.0;
    for s in steps {
        v += s - 0.5;
        h.push(v);
    }
    let series = Series::uniform(n);
    for formulation in [Formulation::Assembled, Formulation::Factored] {
        let mut settings = SmoothSettings { selection: Selection::Relative(0.05), ..Default::default() };
        settings.qp.formulation = formulation;
        let runs: Vec<_> = (1..=3).map(|t| with_threads(t, || smooth(&series, &h, &settings).unwrap())).collect();
        assert!(runs[0].report.certificate.passed, "{formulation:?}");
        for (t, r) in runs.iter().enumerate().skip(1) {
            assert_eq!(runs[0].output, r.output, "{formulation:?}: 1 and {} threads differ", t + 1);
        }
    }
}
