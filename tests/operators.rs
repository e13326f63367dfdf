//! The operators' invariants on every bundled mesh and grid (not one): K·1 = 0, K symmetric,
//! ΣM = area, E₁ of a linear function = its exact Dirichlet energy, (K f)_i = 0 at interior
//! vertices of a planar domain for linear f; for the stiffness and the fills' Laplacian.

mod common;

use common::dataset;
use std::path::Path;
use toposmooth::domain::{Domain, Grid2d, TriMesh};
use toposmooth::io::import::{read, read_trimesh, Derive, DomainKind, ReadOptions};
use toposmooth::operators::{
    cotan_stiffness, grid_mass, grid_stiffness, lumped_mass, positive_cotan_stiffness, Sparse,
};

/// Every bundled mesh.
const MESHES: [&str; 5] = ["bunny.obj", "spot.obj", "mountain.obj", "penguin.obj", "horse_silhouette_2d.obj"];
/// Every bundled grid.
const GRIDS: [&str; 6] = [
    "karman_vortex_street_vorticity_65x513.csv",
    "karman_vortex_street_ttk_example1.vti",
    "retina_microaneurysms_102x102.csv",
    "soapfilm_piv_vorticity_63x63.csv",
    "volcano_maunga_whau_61x87.csv",
    "soapfilm_piv_u_63x63.csv",
];

/// `y = K x` (K stored with both triangles).
fn apply(k: &Sparse, x: &[f64]) -> Vec<f64> {
    let (cp, ri, v) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let mut y = vec![0.0; k.nrows()];
    for j in 0..k.ncols() {
        for p in cp[j]..cp[j + 1] {
            y[ri[p]] += v[p] * x[j];
        }
    }
    y
}

/// The largest |K_ij − K_ji| and the largest |K_ij|.
fn asymmetry(k: &Sparse) -> (f64, f64) {
    let (cp, ri, v) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let mut entries = std::collections::HashMap::new();
    let mut biggest = 0.0f64;
    for j in 0..k.ncols() {
        for p in cp[j]..cp[j + 1] {
            *entries.entry((ri[p], j)).or_insert(0.0) += v[p];
            biggest = biggest.max(v[p].abs());
        }
    }
    let worst = entries
        .iter()
        .map(|(&(i, j), &a)| (a - entries.get(&(j, i)).copied().unwrap_or(0.0)).abs())
        .fold(0.0, f64::max);
    (worst, biggest)
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

/// Checks one Laplacian `k` of `name`: K·1 = 0 and symmetry, relative to its largest entry.
fn laplacian_invariants(name: &str, k: &Sparse) {
    let (worst, biggest) = asymmetry(k);
    assert!(biggest > 0.0, "{name}: empty operator");
    assert!(worst <= 1e-14 * biggest, "{name}: K is not symmetric ({worst:e} against {biggest:e})");
    let row_sums = apply(k, &vec![1.0; k.nrows()]);
    assert!(max_abs(&row_sums) <= 1e-12 * biggest, "{name}: K·1 = {:e}", max_abs(&row_sums));
}

fn mesh(file: &str) -> TriMesh {
    read_trimesh(Path::new(&dataset(file))).unwrap().0
}

#[test]
fn every_bundled_mesh_has_exact_operators() {
    let mut planar = 0;
    for file in MESHES {
        let m = mesh(file);
        let (p, t) = (m.positions(), m.faces());
        let k = cotan_stiffness(p, t);
        laplacian_invariants(file, &k);
        laplacian_invariants(&format!("{file} (fills)"), &positive_cotan_stiffness(p, t));
        // ΣM = area, and E₁(a·x) = Σ_T area_T |a projected on T|² (the linear function
        // restricted to each triangle is linear there: P1 reproduces it exactly)
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        };
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let a = [0.3, -1.1, 0.7];
        let (mut area, mut energy) = (0.0, 0.0);
        for tri in t {
            let n = cross(sub(p[tri[1]], p[tri[0]]), sub(p[tri[2]], p[tri[0]]));
            let twice = dot(n, n).sqrt();
            let an = dot(a, n) / twice;
            area += 0.5 * twice;
            energy += 0.5 * twice * (dot(a, a) - an * an);
        }
        let mass: f64 = lumped_mass(p, t).iter().sum();
        assert!((mass - area).abs() <= 1e-12 * area, "{file}: ΣM = {mass} against area {area}");
        let f: Vec<f64> = p.iter().map(|&q| dot(a, q)).collect();
        let e1: f64 = f.iter().zip(apply(&k, &f)).map(|(x, y)| x * y).sum();
        assert!((e1 - energy).abs() <= 1e-9 * energy, "{file}: E₁(a·x) = {e1} against {energy}");
        // planar meshes: K f = 0 at interior vertices for linear f
        if p.iter().all(|q| q[2] == 0.0) {
            planar += 1;
            let kf = apply(&k, &f);
            // boundary vertices: on an edge of one triangle only
            let mut count = std::collections::HashMap::new();
            for tri in t {
                for e in 0..3 {
                    let (u, w) = (tri[e], tri[(e + 1) % 3]);
                    *count.entry((u.min(w), u.max(w))).or_insert(0) += 1;
                }
            }
            let boundary: std::collections::HashSet<usize> =
                count.iter().filter(|(_, &c)| c == 1).flat_map(|(&(u, w), _)| [u, w]).collect();
            assert!(!boundary.is_empty(), "{file}: a planar mesh has a boundary");
            let scale = max_abs(&f) * asymmetry(&k).1;
            for v in (0..m.n_vertices()).filter(|v| !boundary.contains(v)) {
                assert!(kf[v].abs() <= 1e-10 * scale, "{file}: (K f)_{v} = {:e}", kf[v]);
            }
        }
    }
    assert_eq!(planar, 1, "the horse silhouette is the planar one");
}

fn grid(file: &str) -> Grid2d {
    let path = dataset(file);
    // the Kármán .vti holds velocity: read as its vorticity, as the README runs it
    let derive = file.ends_with(".vti").then_some(Derive::Vorticity);
    let options = ReadOptions { domain: DomainKind::Grid, derive, fill_missing: true, ..Default::default() };
    match read(Some(Path::new(&path)), &options).unwrap().domain {
        toposmooth::AnyDomain::Grid(g) => g,
        _ => panic!("{file} is not a grid"),
    }
}

#[test]
fn every_bundled_grid_has_exact_operators() {
    for file in GRIDS {
        let plain = grid(file);
        // as read, and with an anisotropic signed spacing (a flipped image)
        let flipped = Grid2d::with_geometry(plain.nx(), plain.ny(), [0.7, -1.9], [3.0, 1.0]).unwrap();
        for (what, g) in [("as read", plain), ("spacing (0.7, −1.9)", flipped)] {
            let name = format!("{file} {what}");
            let k = grid_stiffness(&g);
            laplacian_invariants(&name, &k);
            let [dx, dy] = g.spacing();
            let area = (g.nx() - 1) as f64 * dx.abs() * (g.ny() - 1) as f64 * dy.abs();
            let mass: f64 = grid_mass(&g).iter().sum();
            assert!((mass - area).abs() <= 1e-12 * area, "{name}: ΣM = {mass} against {area}");
            let a = [0.4, -1.3];
            let f: Vec<f64> = (0..g.n_vertices())
                .map(|v| {
                    let q = g.point(v);
                    a[0] * q[0] + a[1] * q[1]
                })
                .collect();
            let e1: f64 = f.iter().zip(apply(&k, &f)).map(|(x, y)| x * y).sum();
            let exact = (a[0] * a[0] + a[1] * a[1]) * area;
            assert!((e1 - exact).abs() <= 1e-9 * exact, "{name}: E₁(a·x) = {e1} against {exact}");
            let kf = apply(&k, &f);
            let scale = max_abs(&f) * asymmetry(&k).1;
            for r in 1..g.ny() - 1 {
                for c in 1..g.nx() - 1 {
                    let v = g.index(r, c);
                    assert!(kf[v].abs() <= 1e-10 * scale, "{name}: (K f) at ({r}, {c}) = {:e}", kf[v]);
                }
            }
        }
    }
}
