//! A harmonic representative whose *order* survives underflow (no-data mode).
//!
//! In a long appendage with no handle, the harmonic function's variation decays like
//! `exp(−π L / w)` (length L, width w): beyond `L ≈ 12 w` it is below one ulp of its value
//! and double precision shows ties and spurious extrema that the exact function does not
//! have (NOTES.md 8). Only the order of u matters to the constraints, so the values are kept
//! as exact sums of doubles (floating-point expansions, Shewchuk 1997): where vertices are
//! not strictly regular, or numerically flat at the scale they were computed at, the
//! Dirichlet problem is solved again on that region (grown by one ring) for the *deviation* from one boundary value, which double precision resolves
//! afresh, and the vertex's value becomes that boundary value plus the deviation, exactly.
//! Repeated while regions remain, up to [`MAX_LEVELS`] times. The result is returned as
//! ranks (a strictly increasing relabelling), which orient every edge as the exact sums do.

use crate::domain::Domain;
use crate::error::ConstructionError;
use crate::operators::{dirichlet_solve, Sparse};
use faer::sparse::Triplet;
use std::cmp::Ordering;

/// Most refinement levels (each resolves about 20 e-foldings of decay).
pub const MAX_LEVELS: usize = 60;

/// A vertex whose neighbours differ from it by less than this fraction of the scale its
/// value was computed at has lost its order to rounding (or is about to) and is refined.
const FLAT: f64 = 1.0 / (1u64 << 30) as f64;

/// `a + b` as `(sum, error)` exactly (Knuth's two-sum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// Adds `b` to the expansion `e` (components of increasing magnitude, non-overlapping),
/// exactly; zero components are dropped.
fn grow(e: &[f64], b: f64) -> Vec<f64> {
    let mut q = b;
    let mut out = Vec::with_capacity(e.len() + 1);
    for &x in e {
        let (s, err) = two_sum(q, x);
        if err != 0.0 {
            out.push(err);
        }
        q = s;
    }
    if q != 0.0 || out.is_empty() {
        out.push(q);
    }
    out
}

/// The exact sign of `a − b` for two expansions.
fn compare(a: &[f64], b: &[f64]) -> Ordering {
    if a.len() == 1 && b.len() == 1 {
        return a[0].partial_cmp(&b[0]).unwrap_or(Ordering::Equal);
    }
    let mut d: Vec<f64> = a.to_vec();
    for &x in b {
        d = grow(&d, -x);
    }
    let top = d.iter().rev().find(|x| **x != 0.0).copied().unwrap_or(0.0);
    top.partial_cmp(&0.0).unwrap_or(Ordering::Equal)
}

/// `a − b` rounded to a double (components summed from the smallest).
fn approx_difference(a: &[f64], b: &[f64]) -> f64 {
    let mut d: Vec<f64> = a.to_vec();
    for &x in b {
        d = grow(&d, -x);
    }
    d.iter().sum()
}

/// Free vertices that are not strictly regular under the exact order of `phi`.
fn irregular<D: Domain>(domain: &D, phi: &[Vec<f64>], fixed: &[Option<f64>]) -> Vec<usize> {
    (0..domain.n_vertices())
        .filter(|&v| {
            if fixed[v].is_some() {
                return false;
            }
            let (mut lower, mut higher) = (false, false);
            for w in domain.neighbors(v) {
                match compare(&phi[w], &phi[v]) {
                    Ordering::Less => lower = true,
                    Ordering::Greater => higher = true,
                    Ordering::Equal => {}
                }
            }
            !(lower && higher)
        })
        .collect()
}

/// The harmonic function of `k` (non-negative weights) with the fixed values, refined where
/// double precision loses its order; returns `(u, levels)`: `u` is the plain harmonic
/// solution when it is already strictly regular at every free vertex (`levels == 0`), else the
/// ranks of the refined order scaled to [0, 1].
///
/// # Errors
/// The Dirichlet solve fails, or a region stays irregular after [`MAX_LEVELS`] refinements or
/// is exactly flat (its boundary values all equal).
pub fn ordered_harmonic<D: Domain>(
    domain: &D,
    k: &Sparse,
    fixed: &[Option<f64>],
    analyses: Option<&mut crate::linalg::Analyses>,
) -> Result<(Vec<f64>, usize), ConstructionError> {
    let n = domain.n_vertices();
    let u = crate::operators::dirichlet_solve_with(k, fixed, analyses)?;
    let mut phi: Vec<Vec<f64>> = u.iter().map(|&x| vec![x]).collect();
    let spread = {
        let vals: Vec<f64> = fixed.iter().flatten().copied().collect();
        let (lo, hi) = vals.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        if hi > lo {
            hi - lo
        } else {
            1.0
        }
    };
    // the scale each vertex's value was last computed at
    let mut scale = vec![spread; n];
    let mut levels = 0;
    loop {
        if crate::progress::cancelled() {
            return Err(ConstructionError::Unfit("cancelled".into()));
        }
        let bad = irregular(domain, &phi, fixed);
        if bad.is_empty() {
            break;
        }
        let flat: Vec<usize> = (0..n)
            .filter(|&v| {
                fixed[v].is_none()
                    && domain.neighbors(v).all(|w| approx_difference(&phi[w], &phi[v]).abs() <= FLAT * scale[v])
            })
            .collect();
        if levels == MAX_LEVELS {
            return Err(ConstructionError::Unfit(format!(
                "{} vertices (first {}) are still not strictly regular after {MAX_LEVELS} refinements of the harmonic order",
                bad.len(),
                bad[0]
            )));
        }
        levels += 1;
        let in_region = region(domain, fixed, bad.iter().chain(&flat).copied().collect());
        // each connected part of the region separately
        for part in parts(domain, &in_region) {
            refine_part(domain, k, &part, &in_region, &mut phi, &mut scale)?;
        }
    }
    if levels == 0 {
        return Ok((u, 0));
    }
    let ranked = relabel(u, &phi, fixed);
    Ok((ranked, levels))
}

/// The refinement region: the vertices `front` grown by one ring of free vertices.
fn region<D: Domain>(domain: &D, fixed: &[Option<f64>], mut front: Vec<usize>) -> Vec<bool> {
    let n = domain.n_vertices();
    let mut in_region = vec![false; n];
    for &v in &front {
        in_region[v] = true;
    }
    for _ in 0..1 {
        let mut next = Vec::new();
        for &v in &front {
            for w in domain.neighbors(v) {
                if !in_region[w] && fixed[w].is_none() {
                    in_region[w] = true;
                    next.push(w);
                }
            }
        }
        front = next;
    }
    in_region
}

/// The connected parts of a region, each in breadth-first order from its smallest vertex.
fn parts<D: Domain>(domain: &D, in_region: &[bool]) -> Vec<Vec<usize>> {
    let n = domain.n_vertices();
    let mut seen = vec![false; n];
    let mut out = Vec::new();
    for s in 0..n {
        if !in_region[s] || seen[s] {
            continue;
        }
        let mut part = vec![s];
        seen[s] = true;
        let mut i = 0;
        while i < part.len() {
            let v = part[i];
            i += 1;
            for w in domain.neighbors(v) {
                if in_region[w] && !seen[w] {
                    seen[w] = true;
                    part.push(w);
                }
            }
        }
        out.push(part);
    }
    out
}

/// Solves the local Dirichlet problem on `part` ∪ its boundary with the boundary's values
/// relative to the first of them, and extends the part's values by one level.
fn refine_part<D: Domain>(
    domain: &D,
    k: &Sparse,
    part: &[usize],
    in_region: &[bool],
    phi: &mut [Vec<f64>],
    scale: &mut [f64],
) -> Result<(), ConstructionError> {
    let n = domain.n_vertices();
    let mut boundary: Vec<usize> = part.iter().flat_map(|&v| domain.neighbors(v)).filter(|&w| !in_region[w]).collect();
    boundary.sort_unstable();
    boundary.dedup();
    if boundary.is_empty() {
        return Err(ConstructionError::Unfit(format!(
            "vertex {} lies in a part of the domain that touches no handle",
            part[0]
        )));
    }
    let base = phi[boundary[0]].clone();
    let data: Vec<f64> = boundary.iter().map(|&b| approx_difference(&phi[b], &base)).collect();
    if data.iter().all(|&d| d == 0.0) {
        return Err(ConstructionError::Unfit(format!(
            "the harmonic order is exactly flat around vertex {} (all {} boundary values equal)",
            part[0],
            boundary.len()
        )));
    }
    // local Dirichlet problem on part ∪ boundary
    let mut slot = vec![usize::MAX; n];
    let mut local: Vec<usize> = part.to_vec();
    local.extend_from_slice(&boundary);
    for (j, &v) in local.iter().enumerate() {
        slot[v] = j;
    }
    let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let mut t = Vec::new();
    for &v in &local {
        for p in cp[v]..cp[v + 1] {
            let r = ri[p];
            if slot[r] != usize::MAX {
                t.push(Triplet::new(slot[r], slot[v], val[p]));
            }
        }
    }
    let m = local.len();
    let sub = Sparse::try_new_from_triplets(m, m, &t).map_err(|e| crate::error::NumericalError(format!("{e:?}")))?;
    let mut lf: Vec<Option<f64>> = vec![None; m];
    for (j, &d) in data.iter().enumerate() {
        lf[part.len() + j] = Some(d);
    }
    let x = dirichlet_solve(&sub, &lf)?;
    let part_scale = data.iter().fold(0.0f64, |a, d| a.max(d.abs()));
    for (j, &v) in part.iter().enumerate() {
        phi[v] = grow(&base, x[j]);
        scale[v] = part_scale;
    }
    Ok(())
}

/// Ranks of the refined order: fixed vertices keep their values, each run of free vertices
/// between two fixed ones in the order is spread evenly between their values.
fn relabel(u: Vec<f64>, phi: &[Vec<f64>], fixed: &[Option<f64>]) -> Vec<f64> {
    let n = u.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| compare(&phi[a], &phi[b]).then(a.cmp(&b)));
    let mut ranked = u;
    let mut i = 0;
    while i < n {
        if fixed[order[i]].is_some() {
            i += 1;
            continue;
        }
        let start = i;
        while i < n && fixed[order[i]].is_none() {
            i += 1;
        }
        let run = i - start;
        let below = if start > 0 { fixed[order[start - 1]] } else { None };
        let above = if i < n { fixed[order[i]] } else { None };
        let (a, b) = match (below, above) {
            (Some(a), Some(b)) => (a, b),
            (Some(a), None) => (a, a + 1.0),
            (None, Some(b)) => (b - 1.0, b),
            (None, None) => (0.0, 1.0),
        };
        for j in 0..run {
            ranked[order[start + j]] = a + (b - a) * (j + 1) as f64 / (run + 1) as f64;
        }
    }
    ranked
}

#[cfg(test)]
mod tests {
    use super::*;
    #[cfg_attr(not(feature = "serde"), allow(unused_imports))]
    use crate::verify::{certify_no_data, RegionKind};

    #[test]
    fn expansions_compare_exactly() {
        let a = grow(&[1.0], 1e-30);
        assert_eq!(compare(&a, &[1.0]), Ordering::Greater);
        assert_eq!(compare(&[1.0], &a), Ordering::Less);
        let b = grow(&grow(&[1.0], 1e-30), -1e-30);
        assert_eq!(compare(&b, &[1.0]), Ordering::Equal);
        assert_eq!(approx_difference(&a, &[1.0]), 1e-30);
    }

    #[test]
    #[cfg(feature = "serde")]
    fn a_long_appendage_keeps_its_order() {
        // a 20 × 20 block with the two handles, and an arm 4 pixels wide and 150 long without
        // handles: the harmonic variation along the arm falls far below one ulp
        let (w, h) = (172, 20);
        let inside: Vec<bool> = (0..w * h).map(|p| (p % w) < 20 || (8..12).contains(&(p / w))).collect();
        let pm = crate::apps::diffuse::pixel_mesh(w, h, &inside).unwrap();
        let mesh = &pm.mesh;
        let k = crate::operators::positive_cotan_stiffness(mesh.positions(), mesh.faces());
        let mut fixed = vec![None; mesh.n_vertices()];
        fixed[pm.vertex_of_pixel[2 * w + 2].unwrap()] = Some(0.0);
        fixed[pm.vertex_of_pixel[17 * w + 2].unwrap()] = Some(1.0);
        let plain = dirichlet_solve(&k, &fixed).unwrap();
        let plain_phi: Vec<Vec<f64>> = plain.iter().map(|&x| vec![x]).collect();
        assert!(!irregular(mesh, &plain_phi, &fixed).is_empty(), "the plain harmonic function should lose its order");
        let (u, levels) = ordered_harmonic(mesh, &k, &fixed, None).unwrap();
        assert!(levels >= 2, "{levels}");
        let c = certify_no_data(mesh, &u, &fixed, |v| if v == 1.0 { RegionKind::Max } else { RegionKind::Min });
        assert!(c.passed, "{}", c.summary());
        // and the plain function is kept where it already works
        let mut short = vec![None; mesh.n_vertices()];
        short[pm.vertex_of_pixel[2 * w + 2].unwrap()] = Some(0.0);
        short[pm.vertex_of_pixel[10 * w + 170].unwrap()] = Some(1.0);
        let (u, levels) = ordered_harmonic(mesh, &k, &short, None).unwrap();
        assert_eq!(levels, 0);
        assert_eq!(u, dirichlet_solve(&k, &short).unwrap());
    }
}
