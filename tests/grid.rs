//! The pipeline on grids (issue 4, in progress): library level.

mod common;

use common::uniform;
use toposmooth::domain::Grid2d;
use toposmooth::pipeline::{smooth, SmoothSettings};
use toposmooth::topology::{Role, Selection};

/// Strict extrema and flat vertices of a grid field, from SPEC's 6-neighbour rule written out
/// here independently of the crate.
fn grid_extrema(nx: usize, ny: usize, f: &[f64]) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let (mut mins, mut maxs, mut flat) = (vec![], vec![], vec![]);
    for r in 0..ny as isize {
        for c in 0..nx as isize {
            let v = (r as usize) * nx + c as usize;
            let nb: Vec<f64> = [(0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (1, 1)]
                .iter()
                .map(|(dr, dc)| (r + dr, c + dc))
                .filter(|&(rr, cc)| rr >= 0 && rr < ny as isize && cc >= 0 && cc < nx as isize)
                .map(|(rr, cc)| f[rr as usize * nx + cc as usize])
                .collect();
            let lower = nb.iter().filter(|&&w| w < f[v]).count();
            let higher = nb.iter().filter(|&&w| w > f[v]).count();
            if higher == nb.len() {
                mins.push(v);
            } else if lower == nb.len() {
                maxs.push(v);
            } else if lower == 0 || higher == 0 {
                flat.push(v);
            }
        }
    }
    (mins, maxs, flat)
}

fn bumps(nx: usize, ny: usize, noise: f64, seed: u64) -> Vec<f64> {
    let r = uniform(seed, nx * ny);
    (0..nx * ny)
        .map(|v| {
            let (y, x) = ((v / nx) as f64, (v % nx) as f64);
            let g = |cx: f64, cy: f64, s: f64| (-((x - cx).powi(2) + (y - cy).powi(2)) / s).exp();
            g(nx as f64 * 0.3, ny as f64 * 0.5, 30.0) + 0.6 * g(nx as f64 * 0.7, ny as f64 * 0.4, 20.0)
                - 0.5 * g(nx as f64 * 0.5, ny as f64 * 0.8, 25.0)
                + noise * (r[v] - 0.5)
        })
        .collect()
}

#[test]
fn noisy_bumps_keep_exactly_the_persistent_extrema() {
    let (nx, ny) = (40, 30);
    let g = Grid2d::new(nx, ny).unwrap();
    let h = bumps(nx, ny, 0.1, 5);
    let before = grid_extrema(nx, ny, &h);
    assert!(before.0.len() + before.1.len() > 100, "noisy input");
    let out = smooth(&g, &h, &SmoothSettings { selection: Selection::Relative(0.2), ..Default::default() }).unwrap();
    let (mins, maxs, flat) = grid_extrema(nx, ny, &out.output);
    assert!(flat.is_empty());
    let kept_min: Vec<usize> = (0..nx * ny).filter(|&v| out.roles[v] == Role::Min).collect();
    let kept_max: Vec<usize> = (0..nx * ny).filter(|&v| out.roles[v] == Role::Max).collect();
    assert_eq!(mins, kept_min);
    assert_eq!(maxs, kept_max);
    assert!(kept_max.len() >= 2 && !kept_min.is_empty());
    for &v in kept_min.iter().chain(&kept_max) {
        assert_eq!(out.output[v].to_bits(), h[v].to_bits());
    }
    eprintln!("representative: {}", out.report.representative);
}

/// Every persistence-chosen set certifies (SPEC: exit 0), with the separatrix representative
/// or, where it fails its check, the flooded one; every output is checked by the counter above.
#[test]
fn random_grids_certify_or_say_why() {
    let mut stats = std::collections::BTreeMap::new();
    for seed in 0..400u64 {
        let (nx, ny) = (3 + (seed % 13) as usize, 3 + (seed / 13 % 11) as usize);
        let g = Grid2d::new(nx, ny).unwrap();
        // smooth bumps with noise, or few-valued random fields full of ties
        let h = if seed % 5 == 4 {
            uniform(seed, nx * ny).iter().map(|v| (v * 4.0).floor()).collect()
        } else {
            bumps(nx, ny, [0.0, 0.05, 0.3, 2.0][(seed % 4) as usize], seed)
        };
        if h.iter().all(|&v| v == h[0]) {
            continue;
        }
        let frac = [0.05, 0.2, 0.5][(seed % 3) as usize];
        match smooth(&g, &h, &SmoothSettings { selection: Selection::Relative(frac), ..Default::default() }) {
            Ok(out) => {
                let (mins, maxs, flat) = grid_extrema(nx, ny, &out.output);
                assert!(flat.is_empty());
                assert_eq!(mins, (0..nx * ny).filter(|&v| out.roles[v] == Role::Min).collect::<Vec<_>>());
                assert_eq!(maxs, (0..nx * ny).filter(|&v| out.roles[v] == Role::Max).collect::<Vec<_>>());
                let kind = out.report.representative.split(' ').next().unwrap().to_string();
                *stats.entry(kind).or_insert(0) += 1;
            }
            Err(e) => {
                *stats.entry(format!("exit {}", e.exit_code())).or_insert(0) += 1;
                eprintln!("seed {seed}: {e}");
            }
        }
    }
    eprintln!("{stats:?}");
    assert!(stats.keys().all(|k| !k.starts_with("exit")), "every persistence-chosen set certifies: {stats:?}");
    // the separatrix representative does most of the work; its share can only go up
    assert!(*stats.get("separatrix").unwrap_or(&0) >= 300, "{stats:?}");
}
