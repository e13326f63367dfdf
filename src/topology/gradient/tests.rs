//! Tests of `gradient`.

use super::*;
use crate::domain::{sos_greater, sos_less, Grid2d};

fn random_field(seed: u64, n: usize, levels: u64) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 33) % levels) as f64
        })
        .collect()
}

#[test]
fn euler_relation_and_extrema_on_random_fields_with_ties() {
    for seed in 0..300u64 {
        let (nx, ny) = (2 + (seed % 9) as usize, 2 + (seed / 9 % 7) as usize);
        let g = Grid2d::new(nx, ny).unwrap();
        let h = random_field(seed, nx * ny, 1 + seed % 6);
        for dir in [Direction::Descending, Direction::Ascending] {
            let grad = DiscreteGradient::new(&g, &h, dir);
            assert!(grad.is_complete(), "seed {seed}");
            assert_eq!(grad.euler_characteristic(), 2, "seed {seed} {dir:?}: {:?}", grad.critical_counts());
            // critical vertices are exactly the SoS extrema, boundary ones included
            let expected: Vec<usize> = (0..g.n_vertices())
                .filter(|&v| {
                    g.neighbors(v).all(|w| match dir {
                        Direction::Descending => sos_greater(&h, w, v),
                        Direction::Ascending => sos_less(&h, w, v),
                    })
                })
                .collect();
            assert_eq!(grad.critical_vertices(), expected, "seed {seed} {dir:?}");
            // V-paths from every vertex end at a critical vertex, monotonically
            for v in 0..g.n_vertices() {
                let p = grad.vertex_path(v);
                assert!(expected.contains(p.last().unwrap()));
                for w in p.windows(2) {
                    match dir {
                        Direction::Descending => assert!(sos_less(&h, w[1], w[0])),
                        Direction::Ascending => assert!(sos_greater(&h, w[1], w[0])),
                    }
                }
            }
        }
    }
}

#[test]
fn simplification_keeps_exactly_the_selected_extrema_on_random_fields_with_ties() {
    use crate::topology::{select, Role, Selection};
    let mut checked = 0;
    for seed in 0..2000u64 {
        let (nx, ny) = (2 + (seed % 11) as usize, 2 + (seed / 11 % 9) as usize);
        let g = Grid2d::new(nx, ny).unwrap();
        let h = random_field(seed * 7 + 1, nx * ny, 2 + seed % 9);
        if h.iter().all(|&v| v == h[0]) {
            continue;
        }
        let frac = [0.05, 0.2, 0.5, 0.9][(seed % 4) as usize];
        let kept = select(&g, &h, &Selection::Relative(frac)).unwrap();
        for (dir, role) in [(Direction::Descending, Role::Min), (Direction::Ascending, Role::Max)] {
            let mut grad = DiscreteGradient::new(&g, &h, dir);
            let pairs = match dir {
                Direction::Descending => crate::topology::sublevel_pairs(&g, &h),
                Direction::Ascending => crate::topology::superlevel_pairs(&g, &h),
            };
            let keep: Vec<bool> = kept.roles.iter().map(|&r| r == role).collect();
            grad.simplify(&pairs, &keep).unwrap_or_else(|e| panic!("seed {seed} {dir:?}: {e}"));
            assert!(grad.is_complete());
            assert_eq!(grad.euler_characteristic(), 2, "seed {seed}");
            let expected: Vec<usize> = (0..g.n_vertices()).filter(|&v| keep[v]).collect();
            assert_eq!(grad.critical_vertices(), expected, "seed {seed} {dir:?}");
            for s in grad.saddles() {
                for path in grad.separatrices(&s) {
                    assert!(keep[*path.last().unwrap()], "separatrix ends at a kept extremum");
                }
            }
        }
        checked += 1;
    }
    assert!(checked > 1900);
}

#[test]
fn a_saddle_has_one_critical_edge_between_two_minima() {
    // h = x² − y² on a 5 × 5 grid centred at the saddle; minima on the left/right... of −y²
    let g = Grid2d::new(5, 5).unwrap();
    let h: Vec<f64> = (0..25)
        .map(|v| {
            let (r, c) = g.row_col(v);
            let (x, y) = (c as f64 - 2.0, r as f64 - 2.0);
            x * x - y * y + 1e-3 * v as f64
        })
        .collect();
    let down = DiscreteGradient::new(&g, &h, Direction::Descending);
    let minima = down.critical_vertices();
    assert_eq!(minima.len(), 2, "{minima:?}"); // top and bottom edge midpoints region
    let saddles: Vec<[usize; 2]> = down.critical_edges().into_iter().filter(|e| e[0] < 25 && e[1] < 25).collect();
    assert_eq!(saddles.len(), 1, "{saddles:?}");
    let ends: Vec<usize> = saddles[0].iter().map(|&v| *down.vertex_path(v).last().unwrap()).collect();
    assert_ne!(ends[0], ends[1], "the saddle joins the two minima");
}
