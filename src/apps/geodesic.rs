//! Geodesic distance on a triangle mesh by the heat method (Crane, Weischedel & Wardetzky
//! 2013, "Geodesics in heat"): diffuse heat from the sources for a short time
//! `t = (mean edge length)²`, normalise its gradient per triangle, and recover the distance
//! whose gradient fits that unit field best (a Poisson problem).
//!
//! Both sparse systems, `M + t K` and `K` with the sources pinned (identity rows), have the
//! pattern of the cotangent stiffness `K`: one symbolic Cholesky analysis (faer) serves both
//! numeric factorisations. Boundaries get the natural (Neumann) condition. The distance is 0
//! at the sources; its error against exact distances is measured in the tests and docs.

use crate::domain::vec3::{cross, dot, sub};
use crate::domain::TriMesh;
use crate::error::{Error, Result};
use crate::linalg::SpdSolver;
use crate::operators::{cotan_stiffness, lumped_mass, Sparse};

/// Seconds spent in the stages of [`heat_geodesic`], and the heat time used.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct GeodesicSeconds {
    /// The heat time as a multiple of (mean edge length)²: 1 unless the heat underflowed far
    /// from the sources (very fine meshes), then 4, 16, … until it reaches every vertex.
    pub time_scale: f64,
    /// Operators and the symbolic analysis.
    pub setup: f64,
    /// Heat step: factorisation and solve.
    pub heat: f64,
    /// Normalised gradient and its divergence.
    pub field: f64,
    /// Poisson step: factorisation and solve.
    pub poisson: f64,
}

/// Upper-triangle pattern and values of `a + diag(d)` scaled, with rows/columns `pinned`
/// replaced by identity ones.
fn upper(
    k: &Sparse,
    scale: f64,
    diag: &[f64],
    pinned: &[bool],
) -> (faer::sparse::SymbolicSparseColMat<usize>, Vec<f64>) {
    let n = k.nrows();
    let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let mut col_ptr = vec![0usize];
    let mut rows = Vec::new();
    let mut values = Vec::new();
    for j in 0..n {
        for p in cp[j]..cp[j + 1] {
            let i = ri[p];
            if i > j {
                continue;
            }
            rows.push(i);
            values.push(if pinned[i] || pinned[j] {
                if i == j {
                    1.0
                } else {
                    0.0
                }
            } else {
                scale * val[p] + if i == j { diag[i] } else { 0.0 }
            });
        }
        col_ptr.push(rows.len());
    }
    (faer::sparse::SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows), values)
}

/// Geodesic distance from `sources` (vertex indices) to every vertex of `mesh`.
///
/// # Errors
/// A message for no source, a source out of range, or a factorisation failure (a component
/// with no source gets no finite distance: refused).
pub fn heat_geodesic(mesh: &TriMesh, sources: &[usize]) -> Result<(Vec<f64>, GeodesicSeconds)> {
    heat_geodesic_with(mesh, sources, &mut crate::linalg::Analyses::default())
}

/// [`heat_geodesic`] with the Laplacian's analysis taken from and kept in `analyses` (the
/// smoothing of the distance that follows reuses it for its harmonic fills).
///
/// # Errors
/// As [`heat_geodesic`].
pub fn heat_geodesic_with(
    mesh: &TriMesh,
    sources: &[usize],
    analyses: &mut crate::linalg::Analyses,
) -> Result<(Vec<f64>, GeodesicSeconds)> {
    let t0 = std::time::Instant::now();
    let mut seconds = GeodesicSeconds::default();
    let p = mesh.positions();
    let tris = mesh.faces();
    let n = p.len();
    check_sources(mesh, sources)?;
    let k = cotan_stiffness(p, tris);
    let m = lumped_mass(p, tris);
    let h = mean_edge_length(p, tris);
    let time = h * h;
    let none = vec![false; n];
    let (pattern, heat_values) = upper(&k, time, &m, &none);
    let mut solver = SpdSolver::new(pattern.as_ref(), analyses)?;
    seconds.setup = t0.elapsed().as_secs_f64();
    let factor_failed = |e: crate::error::NumericalError| {
        let (worst, angle) = mesh.smallest_angle();
        Error::input(format!(
            "the sparse Cholesky factorisation failed ({e}): the mesh has nearly degenerate triangles \
             (smallest angle {angle:.2e}° in triangle {worst})"
        ))
    };

    // heat: (M + tK) u = δ_sources. With t = h² the heat decays like exp(−d²/4t): on a fine
    // mesh it underflows far from the sources, where the normalised gradient is then
    // undefined; t grows ×4 until every vertex gets heat.
    let t = std::time::Instant::now();
    let mut scale = 1.0;
    let mut heat_values = heat_values;
    let u = loop {
        let mut u = vec![0.0; n];
        for &s in sources {
            u[s] = 1.0;
        }
        solver
            .solve(faer::sparse::SparseColMatRef::new(pattern.as_ref(), &heat_values), &mut u)
            .map_err(factor_failed)?;
        let top = u.iter().fold(0.0f64, |a, &v| a.max(v));
        let cold = u.iter().filter(|&&v| v.is_nan() || v <= 1e-250 * top).count();
        if cold == 0 {
            break u;
        }
        if scale >= 4f64.powi(10) {
            return Err(Error::input(format!("the heat does not reach {cold} vertices even with t = {scale} h²")));
        }
        scale *= 4.0;
        heat_values = upper(&k, time * scale, &m, &none).1;
    };
    seconds.time_scale = scale;
    seconds.heat = t.elapsed().as_secs_f64();

    // X = −∇u/|∇u| per triangle, then its integrated divergence at the vertices
    let t = std::time::Instant::now();
    let div = unit_gradient_divergence(p, tris, &u);
    seconds.field = t.elapsed().as_secs_f64();

    // Poisson: L φ = ∇·X with L = −K, sources pinned at 0
    let t = std::time::Instant::now();
    let mut pinned = vec![false; n];
    for &s in sources {
        pinned[s] = true;
    }
    let (_, poisson_values) = upper(&k, 1.0, &vec![0.0; n], &pinned);
    let mut phi: Vec<f64> = (0..n).map(|i| if pinned[i] { 0.0 } else { div[i] }).collect();
    solver
        .solve(faer::sparse::SparseColMatRef::new(pattern.as_ref(), &poisson_values), &mut phi)
        .map_err(factor_failed)?;
    seconds.poisson = t.elapsed().as_secs_f64();
    // K φ = div gives −φ of L φ = div: distances grow away from the sources
    for (i, v) in phi.iter_mut().enumerate() {
        *v = if pinned[i] { 0.0 } else { -*v };
    }
    // the rows of pinned vertices' neighbours still hold their K entries to the pinned ones
    // (values 0): nothing to correct
    Ok((phi, seconds))
}

/// Every source a vertex, and every component with one (else its distance is infinite).
fn check_sources(mesh: &TriMesh, sources: &[usize]) -> Result<()> {
    let n = mesh.positions().len();
    if sources.is_empty() {
        return Err(Error::input("no source vertex"));
    }
    if let Some(&s) = sources.iter().find(|&&s| s >= n) {
        return Err(Error::input(format!("source vertex {s} is out of range (the mesh has {n} vertices)")));
    }
    let comps = mesh.components();
    let mut reached = vec![false; mesh.n_components()];
    for &s in sources {
        reached[comps[s]] = true;
    }
    if let Some(c) = reached.iter().position(|r| !r) {
        let v = comps.iter().position(|&x| x == c).unwrap_or(0);
        return Err(Error::input(format!(
            "component {c} (vertex {v}, …) has no source: its distance would be infinite"
        )));
    }
    Ok(())
}

/// The mean edge length (edges counted once per triangle side).
fn mean_edge_length(p: &[[f64; 3]], tris: &[[usize; 3]]) -> f64 {
    let mut total = 0.0;
    let mut count = 0usize;
    for t in tris {
        for e in 0..3 {
            let d = sub(p[t[(e + 1) % 3]], p[t[e]]);
            total += dot(d, d).sqrt();
            count += 1;
        }
    }
    total / count as f64
}

/// The integrated divergence at the vertices of `X = −∇u/|∇u|`, per triangle (zero where the
/// gradient vanishes).
fn unit_gradient_divergence(p: &[[f64; 3]], tris: &[[usize; 3]], u: &[f64]) -> Vec<f64> {
    let mut div = vec![0.0; p.len()];
    for tri in tris {
        let [a, b, c] = tri.map(|v| p[v]);
        let normal = cross(sub(b, a), sub(c, a));
        let area2 = dot(normal, normal).sqrt();
        let nrm = normal.map(|x| x / area2);
        // ∇u = Σ u_i (N × e_i) / (2A), e_i the edge opposite i, counter-clockwise
        let mut grad = [0.0; 3];
        for k in 0..3 {
            let e = sub(p[tri[(k + 2) % 3]], p[tri[(k + 1) % 3]]);
            let g = cross(nrm, e);
            for d in 0..3 {
                grad[d] += u[tri[k]] * g[d] / area2;
            }
        }
        let len = dot(grad, grad).sqrt();
        if len == 0.0 || !len.is_finite() {
            continue;
        }
        let x = grad.map(|g| -g / len);
        // ∇·X at i: ½ Σ cot θ1 (e1 · X) + cot θ2 (e2 · X)
        for k in 0..3 {
            let (i, j, l) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let (pi, pj, pl) = (p[i], p[j], p[l]);
            let e1 = sub(pj, pi);
            let e2 = sub(pl, pi);
            let cot = |a: [f64; 3], b: [f64; 3]| dot(a, b) / dot(cross(a, b), cross(a, b)).sqrt();
            let cot_l = cot(sub(pi, pl), sub(pj, pl)); // angle at l, opposite e1
            let cot_j = cot(sub(pi, pj), sub(pl, pj)); // angle at j, opposite e2
            div[i] += 0.5 * (cot_l * dot(e1, x) + cot_j * dot(e2, x));
        }
    }
    div
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::shapes;

    #[test]
    fn distance_on_a_sphere_is_close_to_the_great_circle_distance() {
        let m = shapes::sphere(1.0, 60, 120);
        let p = m.positions();
        // the north pole, and a vertex on the equator (no symmetry of the mesh helps there)
        let equator = (0..p.len()).find(|&v| p[v][2].abs() < 1e-9).unwrap();
        for source in [0, equator] {
            let (d, _) = heat_geodesic(&m, &[source]).unwrap();
            let mut worst: f64 = 0.0;
            let mut mean = 0.0;
            for (v, &dist) in d.iter().enumerate() {
                let exact = dot(p[v], p[source]).clamp(-1.0, 1.0).acos();
                worst = worst.max((dist - exact).abs());
                mean += (dist - exact).abs() / d.len() as f64;
            }
            eprintln!(
                "sphere 60×120, source {source}: mean error {mean:.4}, max {worst:.4} (radius 1, max distance π)"
            );
            assert!(mean < 0.03 && worst < 0.08, "source {source}: mean {mean} max {worst}");
            assert_eq!(d[source], 0.0);
        }
    }

    #[test]
    fn the_heat_reaches_every_vertex_of_a_fine_mesh() {
        // a long thin strip of many small triangles: with t = h² the heat underflows at the far end
        let (nx, ny) = (800, 3);
        let p: Vec<[f64; 3]> = (0..nx * ny).map(|v| [(v % nx) as f64, (v / nx) as f64, 0.0]).collect();
        let mut t = Vec::new();
        for r in 0..ny - 1 {
            for c in 0..nx - 1 {
                let v = r * nx + c;
                t.push([v, v + 1, v + nx + 1]);
                t.push([v, v + nx + 1, v + nx]);
            }
        }
        let m = TriMesh::new(p, t).unwrap();
        let (d, s) = heat_geodesic(&m, &[0]).unwrap();
        assert!(s.time_scale > 1.0, "{}", s.time_scale);
        let far = nx - 1;
        assert!((d[far] - far as f64).abs() / (far as f64) < 0.05, "distance {} for {far}", d[far]);
        assert!(d.windows(2).take(nx - 1).all(|w| w[1] > w[0]), "increasing along the strip");
    }

    #[test]
    fn bad_sources_are_refused() {
        let m = shapes::disk(4, 12, &[]);
        assert!(heat_geodesic(&m, &[]).is_err());
        assert!(heat_geodesic(&m, &[10_000]).unwrap_err().to_string().contains("out of range"));
    }
}
