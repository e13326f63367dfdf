//! The whole pipeline on hand-made series with known answers.

mod common;

use common::{count_series_extrema, uniform};
use toposmooth::constraints::EdgeSet;
use toposmooth::domain::Series;
use toposmooth::operators::Energy;
use toposmooth::pipeline::{smooth, SmoothSettings};
use toposmooth::solve::{Method, QpSettings};
use toposmooth::topology::{Role, Selection};

fn run(h: &[f64], selection: Selection) -> toposmooth::pipeline::Smoothed {
    let settings = SmoothSettings { selection, ..Default::default() };
    smooth(&Series::uniform(h.len()), h, &settings).expect("certified")
}

/// Kept extrema are exactly the output's strict extrema (free ends aside) and keep their values.
fn assert_exact(h: &[f64], out: &toposmooth::pipeline::Smoothed) {
    let c = count_series_extrema(&out.output);
    assert!(c.flat.is_empty(), "flat spots at {:?}", c.flat);
    let n = h.len();
    let ends = |v: &Vec<usize>| v.iter().filter(|&&i| out.roles[i] != Role::End).cloned().collect::<Vec<_>>();
    let kept_min: Vec<usize> = (0..n).filter(|&i| out.roles[i] == Role::Min).collect();
    let kept_max: Vec<usize> = (0..n).filter(|&i| out.roles[i] == Role::Max).collect();
    assert_eq!(ends(&c.minima), kept_min);
    assert_eq!(ends(&c.maxima), kept_max);
    for i in kept_min.iter().chain(&kept_max) {
        assert_eq!(out.output[*i].to_bits(), h[*i].to_bits(), "kept value at {i}");
    }
}

#[test]
fn ramp_with_noise_below_the_threshold_keeps_only_its_ends() {
    // slope 0.1 per sample, noise ±0.3: hundreds of small extrema, all of persistence < 5 % of 20
    let noise = uniform(7, 200);
    let mut h: Vec<f64> = (0..200).map(|i| 0.1 * i as f64 + 0.6 * (noise[i] - 0.5)).collect();
    h[0] -= 0.5; // clear ends: the global minimum at 0, the global maximum at 199
    h[199] += 0.5;
    let before = count_series_extrema(&h);
    assert!(before.minima.len() > 30, "the input is noisy");
    let out = run(&h, Selection::Relative(0.05));
    assert_eq!(out.report.kept.iter().map(|k| k.index).collect::<Vec<_>>(), vec![0, 199]);
    assert!(out.output.windows(2).all(|w| w[0] < w[1]), "output strictly increasing");
    assert_exact(&h, &out);
    // smoother: the total variation of the first differences drops
    let tv = |f: &[f64]| f.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]).abs()).sum::<f64>();
    assert!(tv(&out.output) < 0.2 * tv(&h), "{} vs {}", tv(&out.output), tv(&h));
}

#[test]
fn two_bumps_keep_the_large_one_at_the_threshold() {
    // bumps of height 1.0 (centre 30) and 0.3 (centre 70) on a gentle ramp
    let h: Vec<f64> = (0..100)
        .map(|i| {
            let x = i as f64;
            0.002 * x + (-(x - 30.0).powi(2) / 40.0).exp() + 0.3 * (-(x - 70.0).powi(2) / 40.0).exp()
        })
        .collect();
    // the small bump's pair has persistence ≈ 0.3 minus the dip between the bumps
    let small = run(&h, Selection::Absolute(0.35));
    let maxima: Vec<usize> = small.report.kept.iter().filter(|k| k.role == Role::Max).map(|k| k.index).collect();
    assert_eq!(maxima, vec![30]);
    assert_exact(&h, &small);
    let both = run(&h, Selection::Absolute(0.2));
    let maxima: Vec<usize> = both.report.kept.iter().filter(|k| k.role == Role::Max).map(|k| k.index).collect();
    assert_eq!(maxima, vec![30, 70]);
    assert_exact(&h, &both);
    assert!(both.report.rms_deviation < small.report.rms_deviation);
}

#[test]
fn ties_and_plateaus_leave_no_flat_spot() {
    let h = [0.0, 1.0, 1.0, 1.0, 2.0, 2.0, 1.0, 0.0, 0.0, 3.0, 3.0, 3.0];
    for sel in [Selection::Absolute(0.5), Selection::Relative(0.5), Selection::Pairs(1), Selection::Pairs(0)] {
        let out = run(&h, sel.clone());
        assert_exact(&h, &out);
        assert!(out.report.certificate.passed, "{sel:?}");
    }
}

#[test]
fn monotone_series_keeps_its_ends_and_constant_is_an_input_error() {
    let h: Vec<f64> = (0..50).map(|i| (i as f64).sqrt()).collect();
    let out = run(&h, Selection::Relative(0.05));
    assert_eq!(out.report.kept.len(), 2);
    assert!(out.output.windows(2).all(|w| w[0] < w[1]));
    let decreasing: Vec<f64> = h.iter().rev().cloned().collect();
    let out = run(&decreasing, Selection::Relative(0.05));
    assert!(out.output.windows(2).all(|w| w[0] > w[1]));
    let e = smooth(&Series::uniform(5), &[2.0; 5], &SmoothSettings::default()).unwrap_err();
    assert_eq!(e.exit_code(), 3);
    assert!(e.to_string().contains("constant"), "{e}");
}

#[test]
fn every_order_blend_and_edge_set_certifies_on_uneven_spacing() {
    let r = uniform(3, 120);
    let x: Vec<f64> = r
        .iter()
        .scan(0.0, |acc, v| {
            *acc += 0.2 + 3.0 * v;
            Some(*acc)
        })
        .collect();
    let h: Vec<f64> = x.iter().zip(uniform(4, 120)).map(|(x, n)| (x / 30.0).sin() + 0.4 * n).collect();
    let series = Series::with_coordinates(x).unwrap();
    for spec in ["1", "2", "3", "4", "1:0.2,2:1", "2:1,4:0.5"] {
        for edges in [EdgeSet::Minimal, EdgeSet::All] {
            let mut energies = vec![];
            for method in [Method::Structured, Method::Clarabel] {
                let qp = QpSettings { method, ..Default::default() };
                let settings = SmoothSettings { energy: Energy::parse(spec).unwrap(), edges, qp, ..Default::default() };
                let out = smooth(&series, &h, &settings).unwrap_or_else(|e| panic!("order {spec}: {e}"));
                assert_eq!(out.report.solver, method);
                assert_exact(&h, &out);
                energies.push(out.report.energy.total);
            }
            // both solvers reach the same optimum
            assert!((energies[0] - energies[1]).abs() <= 1e-6 * energies[1].abs().max(1e-12), "{spec}: {energies:?}");
        }
    }
}

#[test]
fn sharp_vertex_keeps_a_spike_c0() {
    // a spike at 40 on a smooth background: with the spike marked sharp the output next to it
    // stays closer to the data than without
    let mut h: Vec<f64> = (0..81).map(|i| (i as f64 / 12.0).sin() * 0.2).collect();
    h[40] = 3.0;
    for (i, v) in h.iter_mut().enumerate() {
        let d = (i as f64 - 40.0).abs();
        if d > 0.0 && d < 8.0 {
            *v += 3.0 * (1.0 - d / 8.0);
        }
    }
    let base = SmoothSettings {
        selection: Selection::Relative(0.3),
        energy: Energy::parse("1:0.2,2:1").unwrap(),
        ..Default::default()
    };
    let plain = smooth(&Series::uniform(81), &h, &base).unwrap();
    let mut sharp = base.clone();
    sharp.energy.sharp = vec![40];
    let sharp = smooth(&Series::uniform(81), &h, &sharp).unwrap();
    assert_exact(&h, &plain);
    assert_exact(&h, &sharp);
    let near = |f: &[f64]| (36..=44).map(|i| (f[i] - h[i]).abs()).sum::<f64>();
    assert!(near(&sharp.output) < 0.5 * near(&plain.output), "{} vs {}", near(&sharp.output), near(&plain.output));
}

#[test]
fn explicit_lists_certify_or_are_rejected_with_exit_3() {
    let h = [0.0, 2.0, 5.0, 2.0, 0.5, 1.0, 1.5, 1.0, 0.2];
    let ok = run(&h, Selection::Explicit { minima: vec![4], maxima: vec![2, 6] });
    assert_exact(&h, &ok);
    assert_eq!(ok.roles[0], Role::End);
    let e = smooth(
        &Series::uniform(9),
        &h,
        &SmoothSettings {
            selection: Selection::Explicit { minima: vec![4, 8], maxima: vec![2] },
            ..Default::default()
        },
    )
    .unwrap_err();
    assert_eq!(e.exit_code(), 3);
    assert!(e.to_string().contains("4 and 8"), "{e}");
}

#[test]
fn adjacent_kept_extrema_are_fine() {
    let h = [0.0, 3.0, 1.0, 4.0, 0.5, 0.6, 0.2];
    let out = run(&h, Selection::Explicit { minima: vec![0, 2], maxima: vec![1, 3] });
    assert_exact(&h, &out);
}

/// Regressions found in the review of issue 3.
mod issue3_regressions {
    use super::*;

    #[test]
    fn signed_zeros_are_one_value() {
        // −0 and +0 compare equal: the union-find and the local tests must agree (exit 1 before)
        let h = [-1.0, 0.0, -0.0, -1.0];
        let out = run(&h, Selection::Relative(0.05));
        assert_exact(&h, &out);
    }

    #[test]
    fn free_end_close_to_its_kept_minimum() {
        let e = f64::EPSILON;
        let h = [1.0 + 2.0 * e, 1.0 + e, 1.0 + e, 1.0 + e, 1.0, 5.0, 0.0];
        let out = run(&h, Selection::Relative(0.05));
        assert_exact(&h, &out);
    }

    #[test]
    fn large_offset_small_range() {
        // a counter near 1e10 moving by a few units: spacing of doubles 1.9e-6 > 1e-6 × range
        let noise = uniform(11, 300);
        let h: Vec<f64> = (0..300).map(|i| 1e10 + (i as f64 / 40.0).sin() + 0.3 * noise[i]).collect();
        let out = run(&h, Selection::Relative(0.2));
        assert_exact(&h, &out);
    }

    #[test]
    fn tiny_relative_thresholds_keep_everything_or_are_usage_errors() {
        let h = [0.0, 1.0, 0.5, 2.0];
        let tiny = |t: f64| SmoothSettings { selection: Selection::Relative(t), ..Default::default() };
        // a denormal threshold keeps every pair of positive persistence
        let out = smooth(&Series::uniform(4), &h, &tiny(1e-320)).unwrap();
        assert_eq!(out.report.kept.len(), 4);
        assert_exact(&h, &out);
        // one that underflows to zero is refused (exit 2), never a persistence-0 pair kept
        let e = smooth(&Series::uniform(4), &h, &tiny(1e-330)).unwrap_err();
        assert_eq!(e.exit_code(), 2, "{e}");
    }
}
