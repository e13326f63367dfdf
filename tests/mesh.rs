//! Scalar fields on triangle meshes: the discrete gradient's Euler relation on closed and
//! open surfaces of genus 0 and 1, smoothing certified on a sphere, a torus and a disk with
//! holes, and the maximum principle of the representative's Laplacian on obtuse triangles.

mod common;

use common::{mesh_extrema, uniform};
use toposmooth::domain::{shapes, Domain, TriMesh};
use toposmooth::operators::{cotan_stiffness, dirichlet_solve, negative_cotan_edges, positive_cotan_stiffness};
use toposmooth::pipeline::{smooth, SmoothSettings};
use toposmooth::topology::gradient::{Direction, DiscreteGradient};
use toposmooth::topology::{count_sos_extrema, Role, Selection};

fn meshes() -> Vec<(&'static str, TriMesh)> {
    vec![
        ("sphere", shapes::sphere(1.0, 20, 32)),
        ("torus", shapes::torus(3.0, 1.0, 24, 12)),
        ("disk", shapes::disk(8, 24, &[])),
        ("disk with two holes", shapes::disk(14, 40, &[([0.45, 0.0], 0.2), ([-0.45, 0.1], 0.2)])),
    ]
}

/// A smooth field with a few bumps plus noise, or a few-valued field full of ties.
fn field(m: &TriMesh, seed: u64, noise: f64, ties: bool) -> Vec<f64> {
    let r = uniform(seed, m.n_vertices());
    (0..m.n_vertices())
        .map(|v| {
            if ties {
                return (r[v] * 4.0).floor();
            }
            let [x, y, z] = m.point(v);
            (2.0 * x).sin() * (1.5 * y + 0.3).cos() + 0.5 * z + noise * (r[v] - 0.5)
        })
        .collect()
}

#[test]
fn critical_cells_satisfy_the_euler_relation_on_every_surface() {
    for (name, m) in meshes() {
        // coning closes every boundary loop: χ(coned) = χ + loops
        let chi = m.euler_characteristic() + m.boundary_loops() as i64;
        for seed in 0..40u64 {
            let h = field(&m, seed, 0.5, seed % 3 == 0);
            for dir in [Direction::Descending, Direction::Ascending] {
                let g = DiscreteGradient::new(&m, &h, dir);
                assert!(g.is_complete(), "{name} seed {seed}");
                assert_eq!(g.euler_characteristic(), chi, "{name} seed {seed} {dir:?}: {:?}", g.critical_counts());
                // the critical vertices are the SoS extrema, boundary ones included
                let (minima, maxima) = count_sos_extrema(&m, &h);
                let count = if dir == Direction::Descending { minima } else { maxima };
                assert_eq!(g.critical_vertices().len(), count, "{name} seed {seed} {dir:?}");
            }
        }
    }
}

#[test]
fn noisy_fields_are_simplified_and_certified_on_every_surface() {
    for (name, m) in meshes() {
        for (seed, frac) in [(1u64, 0.1), (2, 0.3)] {
            let h = field(&m, seed, 0.4, false);
            let before = mesh_extrema(m.n_vertices(), m.faces(), &h);
            assert!(before.0.len() + before.1.len() > 20, "{name}: noisy input");
            let settings = SmoothSettings { selection: Selection::Relative(frac), ..Default::default() };
            let out = smooth(&m, &h, &settings).unwrap_or_else(|e| panic!("{name}: {e}"));
            let (mins, maxs, flat) = mesh_extrema(m.n_vertices(), m.faces(), &out.output);
            assert!(flat.is_empty(), "{name}: flat {flat:?}");
            let n = m.n_vertices();
            assert_eq!(mins, (0..n).filter(|&v| out.roles[v] == Role::Min).collect::<Vec<_>>(), "{name}");
            assert_eq!(maxs, (0..n).filter(|&v| out.roles[v] == Role::Max).collect::<Vec<_>>(), "{name}");
            assert!(mins.len() + maxs.len() < before.0.len() + before.1.len(), "{name}");
            for &v in mins.iter().chain(&maxs) {
                assert_eq!(out.output[v].to_bits(), h[v].to_bits());
            }
            eprintln!(
                "{name} {frac}: {}+{} → {}+{}, {}",
                before.0.len(),
                before.1.len(),
                mins.len(),
                maxs.len(),
                out.report.representative
            );
        }
    }
}

#[test]
fn random_fields_with_ties_on_a_holed_disk_always_certify() {
    let m = shapes::disk(8, 20, &[([0.4, 0.0], 0.2)]);
    let mut kinds = std::collections::BTreeMap::new();
    for seed in 0..150u64 {
        let h = field(&m, seed, [0.1, 0.5, 3.0][(seed % 3) as usize], seed % 4 == 3);
        let frac = [0.05, 0.2, 0.5][(seed / 3 % 3) as usize];
        let out = smooth(&m, &h, &SmoothSettings { selection: Selection::Relative(frac), ..Default::default() })
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let (mins, maxs, flat) = mesh_extrema(m.n_vertices(), m.faces(), &out.output);
        assert!(flat.is_empty(), "seed {seed}");
        assert_eq!(mins, (0..m.n_vertices()).filter(|&v| out.roles[v] == Role::Min).collect::<Vec<_>>());
        assert_eq!(maxs, (0..m.n_vertices()).filter(|&v| out.roles[v] == Role::Max).collect::<Vec<_>>());
        *kinds.entry(out.report.representative.split(' ').next().unwrap().to_string()).or_insert(0) += 1;
    }
    eprintln!("{kinds:?}");
}

/// A fan of thin triangles around a vertex pushed close to one side: many obtuse angles.
fn obtuse_mesh() -> TriMesh {
    let mut p = vec![[0.0, 0.0, 0.0]];
    let k = 24;
    for ring in 1..=6 {
        for j in 0..k {
            let a = 2.0 * std::f64::consts::PI * (j as f64 + 0.5 * (ring % 2) as f64) / k as f64;
            // strongly anisotropic: squash x by 8
            let r = ring as f64 / 6.0;
            p.push([r * a.cos() / 8.0, r * a.sin(), 0.0]);
        }
    }
    let id = |ring: usize, j: usize| if ring == 0 { 0 } else { 1 + (ring - 1) * k + j % k };
    let mut t = Vec::new();
    for j in 0..k {
        t.push([0, id(1, j), id(1, j + 1)]);
    }
    for ring in 1..6 {
        for j in 0..k {
            if ring % 2 == 1 {
                t.push([id(ring, j), id(ring + 1, j), id(ring + 1, j + 1)]);
                t.push([id(ring, j), id(ring + 1, j + 1), id(ring, j + 1)]);
            } else {
                t.push([id(ring, j), id(ring + 1, j), id(ring, j + 1)]);
                t.push([id(ring, j + 1), id(ring + 1, j), id(ring + 1, j + 1)]);
            }
        }
    }
    TriMesh::new(p, t).unwrap()
}

#[test]
fn obtuse_triangles_break_the_cotangent_maximum_principle_but_not_the_positive_one() {
    let m = obtuse_mesh();
    let neg = negative_cotan_edges(m.positions(), m.faces());
    assert!(neg > 20, "{neg} negative weights");
    // boundary values 0 and 1 on two halves of the rim, harmonic inside
    let n = m.n_vertices();
    let rim_start = n - 24;
    let fixed: Vec<Option<f64>> =
        (0..n).map(|v| (v >= rim_start).then(|| if m.point(v)[1] > 0.0 { 1.0 } else { 0.0 })).collect();
    let count_bad = |u: &[f64]| {
        let (mins, maxs, flat) = mesh_extrema(n, m.faces(), u);
        mins.iter().chain(&maxs).chain(&flat).filter(|&&v| v < rim_start).count()
            + u.iter().filter(|&&x| !(0.0..=1.0).contains(&x)).count()
    };
    let plain = dirichlet_solve(&cotan_stiffness(m.positions(), m.faces()), &fixed).unwrap();
    let positive = dirichlet_solve(&positive_cotan_stiffness(m.positions(), m.faces()), &fixed).unwrap();
    eprintln!("negative weights {neg}; defects: cotangent {}, positive {}", count_bad(&plain), count_bad(&positive));
    assert!(count_bad(&plain) > 0, "the plain cotangent Laplacian should violate the maximum principle here");
    assert_eq!(count_bad(&positive), 0);
}

/// mountain.obj: 13,549 interior edges with negative cotangent weight. A harmonic fill of
/// boundary values with the plain cotangent Laplacian creates interior extrema there; the
/// positive-weight one creates none.
#[test]
fn negative_cotangent_weights_matter_on_the_mountain() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/mountain.obj");
    let data = toposmooth::io::mesh::read_mesh(&path).unwrap();
    let m = TriMesh::new(data.positions, data.triangles).unwrap();
    assert_eq!(negative_cotan_edges(m.positions(), m.faces()), 13_549);
    let n = m.n_vertices();
    // boundary vertices: those on an edge with one triangle
    let mut count = std::collections::HashMap::new();
    for t in m.faces() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut boundary = vec![false; n];
    for (&(a, b), &c) in &count {
        if c == 1 {
            boundary[a] = true;
            boundary[b] = true;
        }
    }
    // boundary values: a smooth function of the position around the rim
    let fixed: Vec<Option<f64>> = (0..n)
        .map(|v| {
            let p = m.point(v);
            boundary[v].then(|| (0.3 * p[0]).sin() + (0.2 * p[2]).cos())
        })
        .collect();
    let defects = |u: &[f64]| {
        let (mins, maxs, flat) = mesh_extrema(n, m.faces(), u);
        mins.iter().chain(&maxs).chain(&flat).filter(|&&v| !boundary[v]).count()
    };
    let plain = dirichlet_solve(&cotan_stiffness(m.positions(), m.faces()), &fixed).unwrap();
    let positive = dirichlet_solve(&positive_cotan_stiffness(m.positions(), m.faces()), &fixed).unwrap();
    let (dp, dq) = (defects(&plain), defects(&positive));
    eprintln!("mountain harmonic fill: interior extrema or flat vertices: cotangent {dp}, positive weights {dq}");
    assert!(dp > 0);
    assert_eq!(dq, 0);
}
