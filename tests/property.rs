//! Property tests over random series, thresholds and orders: every run with a kept set chosen
//! by persistence certifies; explicit lists certify or exit 3; nothing panics; every
//! certificate is re-checked by the independent extremum counter in `common`.

mod common;

use common::count_series_extrema;
use proptest::prelude::*;
use toposmooth::constraints::EdgeSet;
use toposmooth::domain::{Domain, Series};
use toposmooth::operators::Energy;
use toposmooth::pipeline::{smooth, SmoothSettings, Smoothed};
use toposmooth::topology::{Role, Selection};

fn values() -> impl Strategy<Value = Vec<f64>> {
    prop_oneof![
        // few distinct values: ties and plateaus everywhere
        prop::collection::vec((0i32..5).prop_map(f64::from), 2..60),
        prop::collection::vec(-10.0f64..10.0, 2..80),
        // random walks with tiny steps
        prop::collection::vec(-1.0f64..1.0, 2..120).prop_map(|s| s
            .iter()
            .scan(0.0, |a, v| {
                *a += v * 1e-3;
                Some(*a)
            })
            .collect()),
    ]
}

fn coordinates(n: usize, seed: u64) -> Series {
    if seed.is_multiple_of(2) {
        return Series::uniform(n);
    }
    let r = common::uniform(seed, n);
    Series::with_coordinates(
        r.iter()
            .scan(0.0, |a, v| {
                *a += 0.05 + v;
                Some(*a)
            })
            .collect(),
    )
    .unwrap()
}

fn energy() -> impl Strategy<Value = Energy> {
    prop_oneof![
        Just(Energy::order(1)),
        Just(Energy::order(2)),
        Just(Energy::order(3)),
        Just(Energy::order(4)),
        Just(Energy::parse("1:0.2,2:1").unwrap()),
    ]
}

fn check_certified(h: &[f64], out: &Smoothed) -> Result<(), TestCaseError> {
    let n = h.len();
    let c = count_series_extrema(&out.output);
    prop_assert!(c.flat.is_empty(), "flat spots {:?}", c.flat);
    let kept_min: Vec<usize> = (0..n).filter(|&i| out.roles[i] == Role::Min).collect();
    let kept_max: Vec<usize> = (0..n).filter(|&i| out.roles[i] == Role::Max).collect();
    let not_end = |v: Vec<usize>| v.into_iter().filter(|&i| out.roles[i] != Role::End).collect::<Vec<_>>();
    prop_assert_eq!(not_end(c.minima), kept_min.clone());
    prop_assert_eq!(not_end(c.maxima), kept_max.clone());
    for &i in kept_min.iter().chain(&kept_max) {
        prop_assert_eq!(out.output[i].to_bits(), h[i].to_bits());
    }
    prop_assert!(out.output.iter().all(|v| v.is_finite()));
    prop_assert!(!kept_min.is_empty() && !kept_max.is_empty());
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, .. ProptestConfig::default() })]

    #[test]
    fn persistence_selections_always_certify(
        h in values(),
        frac in 0.0005f64..0.9,
        pairs in 0usize..12,
        use_pairs in any::<bool>(),
        energy in energy(),
        all_edges in any::<bool>(),
        seed in 0u64..1000,
        data_weight in prop_oneof![Just(0.0), Just(1.0), Just(100.0)],
        smooth_length in prop_oneof![Just(None), Just(Some(0.001)), Just(Some(0.01)), Just(Some(0.2))],
    ) {
        let series = coordinates(h.len(), seed);
        let constant = h.iter().all(|&v| v == h[0]);
        let selection = if use_pairs { Selection::Pairs(pairs) } else { Selection::Relative(frac) };
        let settings = SmoothSettings {
            selection,
            energy,
            edges: if all_edges { EdgeSet::All } else { EdgeSet::Minimal },
            data_weight,
            smooth_length,
            ..Default::default()
        };
        match smooth(&series, &h, &settings) {
            Ok(out) => {
                prop_assert!(!constant);
                prop_assert!(out.report.certificate.passed);
                prop_assert!(out.report.solver_fallback.is_none(), "fallback: {:?}", out.report.solver_fallback);
                check_certified(&h, &out)?;
            }
            Err(e) => {
                prop_assert!(constant, "persistence selection failed: {} (exit {})", e, e.exit_code());
                prop_assert_eq!(e.exit_code(), 3);
            }
        }
    }

    #[test]
    fn explicit_lists_certify_or_exit_3(
        h in values(),
        picks in prop::collection::vec(any::<bool>(), 120),
        energy in energy(),
    ) {
        let series = Series::uniform(h.len());
        // candidate extrema of the input in SoS order, a random subset of them
        let sos_less = |a: usize, b: usize| (h[a], a) < (h[b], b);
        let mut minima = vec![];
        let mut maxima = vec![];
        for (v, _) in picks.iter().enumerate().take(h.len()).filter(|p| *p.1) {
            if series.neighbors(v).all(|w| sos_less(v, w)) { minima.push(v); }
            else if series.neighbors(v).all(|w| sos_less(w, v)) { maxima.push(v); }
        }
        let settings = SmoothSettings { selection: Selection::Explicit { minima, maxima }, energy, ..Default::default() };
        match smooth(&series, &h, &settings) {
            Ok(out) => check_certified(&h, &out)?,
            Err(e) => prop_assert_eq!(e.exit_code(), 3, "{}", e),
        }
    }
}

/// Grids: random small fields (many with ties), persistence thresholds, counts, both
/// representatives and both constraint sets. A run certifies (checked by the independent
/// 6-neighbour counter) or stops with a clear input/infeasibility error (exit 3: kept values
/// too close for double precision); never exit 1, never a panic.
mod grids {
    use super::common::grid_extrema;
    use proptest::prelude::*;
    use toposmooth::constraints::EdgeSet;
    use toposmooth::domain::Grid2d;
    use toposmooth::pipeline::{smooth, RepresentativeChoice, SmoothSettings};
    use toposmooth::topology::{Role, Selection};

    fn field() -> impl Strategy<Value = (usize, usize, Vec<f64>)> {
        (2usize..9, 2usize..9).prop_flat_map(|(nx, ny)| {
            let n = nx * ny;
            prop_oneof![
                prop::collection::vec((0i32..4).prop_map(f64::from), n),
                prop::collection::vec(-5.0f64..5.0, n),
            ]
            .prop_map(move |v| (nx, ny, v))
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        #[test]
        fn grid_runs_certify_or_say_why(
            (nx, ny, h) in field(),
            frac in 0.01f64..0.8,
            count in proptest::option::of((1usize..4, 1usize..4)),
            harmonic in any::<bool>(),
            all_edges in any::<bool>(),
        ) {
            prop_assume!(h.iter().any(|&v| v != h[0]));
            let selection = match count {
                Some((a, b)) => Selection::Count { minima: a, maxima: b },
                None => Selection::Relative(frac),
            };
            let settings = SmoothSettings {
                selection,
                representative: harmonic.then_some(RepresentativeChoice::Harmonic),
                edges: if all_edges { EdgeSet::All } else { EdgeSet::Minimal },
                ..Default::default()
            };
            let g = Grid2d::new(nx, ny).unwrap();
            match smooth(&g, &h, &settings) {
                Ok(out) => {
                    let (mins, maxs, flat) = grid_extrema(nx, ny, &out.output);
                    prop_assert!(flat.is_empty());
                    prop_assert_eq!(mins, (0..nx * ny).filter(|&v| out.roles[v] == Role::Min).collect::<Vec<_>>());
                    prop_assert_eq!(maxs, (0..nx * ny).filter(|&v| out.roles[v] == Role::Max).collect::<Vec<_>>());
                    for (v, &hv) in h.iter().enumerate() {
                        if out.roles[v] != Role::Other {
                            prop_assert_eq!(out.output[v].to_bits(), hv.to_bits());
                        }
                    }
                }
                // an explicit harmonic representative is built or refused: exit 3 when the
                // data cannot follow its order, 1 when it fails its own check (a flat fill)
                Err(e) if harmonic && e.exit_code() == 1 => {
                    prop_assert!(e.to_string().contains("harmonic representative"), "{}", e)
                }
                Err(e) => prop_assert_eq!(e.exit_code(), 3, "{}", e),
            }
        }
    }
}
