//! The paper's separatrix representative on a triangulated surface, with the repairs that make
//! it hold on real data (released separatrices, kept extrema moved outward).

use crate::error::ConstructionError;
use crate::topology::{KeptSet, Role};

/// The separatrix representative on a surface (paper section 3.3, after Weinkauf, Gingold &
/// Sorkine 2010): kept extrema and surviving saddles at their input values, every vertex on a
/// separatrix linearly interpolated by arc length between its saddle and its extremum (the
/// smallest such value on merged descending separatrices, the largest on ascending ones,
/// NOTES.md 7; a vertex claimed by both stays free), harmonic elsewhere with the Laplacian
/// `k`, whose off-diagonal weights must be ≤ 0 so that the maximum principle holds.
///
/// Where separatrix values contradict each other (a prescribed vertex becomes a spurious
/// extremum or a free one flat), those vertices and their prescribed neighbours are released
/// to the harmonic fill and the solve repeated. Around a kept extremum that is not strict the
/// release widens ring by ring; with `move_kept` the extremum's value is moved outward instead
/// (`outward_moves`; u's values at kept extrema may be rescaled, SPEC). Returns u and what
/// was changed.
///
/// # Errors
/// A message when the harmonic solve fails; the caller checks the result with the
/// certificate and falls back when it does not pass.
pub fn separatrix_representative<D: crate::domain::Domain>(
    domain: &D,
    h: &[f64],
    kept: &KeptSet,
    ms: &crate::topology::morse_smale::MorseSmale,
    k: &crate::operators::Sparse,
    move_kept: bool,
    analyses: &mut crate::linalg::Analyses,
) -> std::result::Result<(Vec<f64>, Repairs), ConstructionError> {
    let n = h.len();
    let prescribed = interpolated_separatrices(domain, h, kept, ms);
    // Where the interpolated separatrices contradict each other (a separatrix vertex or a
    // saddle ends up below or above all its neighbours, or a free vertex between them is
    // flat), release the separatrices through those vertices (and through their prescribed
    // neighbours) to the harmonic fill and solve again.
    let separatrices: Vec<&[usize]> = ms.descending.iter().chain(&ms.ascending).map(|s| &s.path[..]).collect();
    let mut through: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, p) in separatrices.iter().enumerate() {
        for &v in p.iter() {
            through[v].push(i);
        }
    }
    let mut dirichlet = crate::operators::Dirichlet::new(k, analyses)?;
    let mut released = vec![false; n];
    let mut reach: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    let mut gone = vec![false; separatrices.len()];
    let mut count = 0;
    let (mut moved, mut pinned) = (std::collections::BTreeSet::new(), std::collections::BTreeSet::new());
    let unit = {
        let (lo, hi) = crate::domain::value_range(h);
        hi - lo
    };
    let mut prescribed = prescribed;
    for round in 1..=MAX_RELEASE_ROUNDS {
        if crate::progress::cancelled() {
            return Err(ConstructionError::Unfit("cancelled".into()));
        }
        let fixed: Vec<Option<f64>> = (0..n).map(|v| if released[v] { None } else { prescribed[v] }).collect();
        let u = dirichlet.solve(&fixed)?;
        let bad = failing(domain, kept, &u);
        crate::progress::update("representative", || {
            format!("separatrix round {round}: {} vertices fail, {count} released so far", bad.len())
        });
        let repairs = Repairs { released: count, moved: moved.len(), pinned: pinned.len() };
        if bad.is_empty() {
            return Ok((u, repairs));
        }
        let mut progress = false;
        if move_kept {
            // failing kept extrema move outward instead of releasing the rings around them
            for (v, value) in outward_moves(domain, kept, &fixed, &u, &mut dirichlet, k, unit)? {
                if kept.roles[v].is_fixed() {
                    moved.insert(v);
                } else {
                    pinned.insert(v);
                }
                prescribed[v] = Some(value);
                released[v] = false;
                progress = true;
            }
        }
        let release = |w: usize, released: &mut Vec<bool>, count: &mut usize| {
            if fixed[w].is_some() && !kept.roles[w].is_fixed() && !released[w] {
                released[w] = true;
                *count += 1;
                true
            } else {
                false
            }
        };
        for &v in &bad {
            // around a failing kept extremum the release reaches one ring further each round
            // (its free neighbours can stay above a kept maximum while prescribed vertices
            // farther out hold them up; doubling the radius instead made the retina image
            // release too much and fall back to the harmonic representative)
            let around: Vec<usize> = if kept.roles[v].is_fixed() {
                if move_kept {
                    continue;
                }
                // widen until the rings hold a vertex still prescribed (at most 64 rings)
                let r = reach.entry(v).or_insert(0);
                loop {
                    *r += 1;
                    let ring = rings(domain, v, *r);
                    if *r >= 64 || ring.iter().any(|&w| fixed[w].is_some() && !kept.roles[w].is_fixed()) {
                        break ring;
                    }
                }
            } else {
                std::iter::once(v).chain(domain.neighbors(v)).collect()
            };
            for w in around {
                if fixed[w].is_none() {
                    continue;
                }
                progress |= release(w, &mut released, &mut count);
                // a saddle stays while it has separatrices; a separatrix vertex takes its
                // whole separatrix with it
                if ms.saddles.binary_search(&w).is_err() {
                    for &s in &through[w] {
                        if !std::mem::replace(&mut gone[s], true) {
                            for &x in separatrices[s] {
                                if ms.saddles.binary_search(&x).is_err() {
                                    progress |= release(x, &mut released, &mut count);
                                }
                            }
                        }
                    }
                }
            }
        }
        if !progress {
            return Ok((u, repairs));
        }
    }
    Err(ConstructionError::Unfit(format!(
        "separatrix vertices still contradict each other after {MAX_RELEASE_ROUNDS} rounds of releasing them"
    )))
}

/// The separatrices' values: each vertex of a descending (ascending) separatrix linearly
/// interpolated by arc length between its saddle and its extremum, the smallest (largest)
/// where several meet, kept extrema and saddles at their values; `None` elsewhere and where
/// a descending and an ascending separatrix meet.
fn interpolated_separatrices<D: crate::domain::Domain>(
    domain: &D,
    h: &[f64],
    kept: &KeptSet,
    ms: &crate::topology::morse_smale::MorseSmale,
) -> Vec<Option<f64>> {
    let n = h.len();
    let mut down = vec![f64::INFINITY; n];
    let mut up = vec![f64::NEG_INFINITY; n];
    let dist = |a: usize, b: usize| {
        let (p, q) = (domain.point(a), domain.point(b));
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    let paint = |sep: &crate::topology::morse_smale::Separatrix, target: &mut Vec<f64>, lower: bool| {
        let p = &sep.path;
        let total: f64 = p.windows(2).map(|w| dist(w[0], w[1])).sum();
        let (hs, he) = (h[sep.saddle], h[*p.last().expect("non-empty")]);
        let mut run = 0.0;
        for (i, &v) in p.iter().enumerate() {
            if i > 0 {
                run += dist(p[i - 1], v);
            }
            let t = if total > 0.0 { run / total } else { 1.0 };
            let value = hs + (he - hs) * t;
            target[v] = if lower { target[v].min(value) } else { target[v].max(value) };
        }
    };
    for s in &ms.descending {
        paint(s, &mut down, true);
    }
    for s in &ms.ascending {
        paint(s, &mut up, false);
    }
    (0..n)
        .map(|v| {
            if kept.roles[v].is_fixed() || ms.saddles.binary_search(&v).is_ok() {
                Some(h[v])
            } else {
                match (down[v].is_finite(), up[v].is_finite()) {
                    (true, false) => Some(down[v]),
                    (false, true) => Some(up[v]),
                    _ => None,
                }
            }
        })
        .collect()
}

/// The vertices where `u` fails the representative's order: a free vertex that is not
/// regular, a kept extremum that is not strict.
fn failing<D: crate::domain::Domain>(domain: &D, kept: &KeptSet, u: &[f64]) -> Vec<usize> {
    (0..u.len())
        .filter(|&v| match kept.roles[v] {
            Role::Other => !is_regular(domain, u, v),
            Role::Min => domain.neighbors(v).any(|w| u[w] <= u[v]),
            Role::Max => domain.neighbors(v).any(|w| u[w] >= u[v]),
            _ => false,
        })
        .collect()
}

/// What [`separatrix_representative`] changed in the paper's construction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Repairs {
    /// Prescribed vertices released to the harmonic fill (counted each time).
    pub released: usize,
    /// Kept extrema whose value was moved outward.
    pub moved: usize,
    /// Free vertices prescribed between a kept extremum and its other neighbours.
    pub pinned: usize,
}

/// New values for the kept extrema that are not strict in the fill `u` of `fixed`, each
/// moved outward (a maximum up, a minimum down) far enough to clear its neighbours. This
/// mends what releasing cannot: the fill holding a kept extremum's free neighbours beyond it
/// from prescribed values farther out (a kept minimum beside lower harmonic values). The fill
/// is linear in the fixed values: a second solve with each failing value moved by `unit`
/// gives the fraction of the move each neighbour follows, and the move clears the farthest
/// neighbour with a quarter to spare. A free neighbour that follows (almost) fully is given a
/// value (pinned) instead, halfway to its farthest other neighbour.
fn outward_moves<D: crate::domain::Domain>(
    domain: &D,
    kept: &KeptSet,
    fixed: &[Option<f64>],
    u: &[f64],
    dirichlet: &mut crate::operators::Dirichlet,
    k: &crate::operators::Sparse,
    unit: f64,
) -> std::result::Result<Vec<(usize, f64)>, ConstructionError> {
    // +1 for a maximum (moves up), −1 for a minimum
    let outward = |v: usize| if kept.roles[v] == Role::Max { 1.0 } else { -1.0 };
    let failing: Vec<usize> = (0..u.len())
        .filter(|&v| {
            matches!(kept.roles[v], Role::Min | Role::Max)
                && domain.neighbors(v).any(|w| outward(v) * (u[w] - u[v]) >= 0.0)
        })
        .collect();
    if failing.is_empty() {
        return Ok(Vec::new());
    }
    let mut moved = fixed.to_vec();
    for &v in &failing {
        moved[v] = Some(u[v] + outward(v) * unit);
    }
    let u1 = dirichlet.solve(&moved)?;
    let mut out = Vec::new();
    for &v in &failing {
        let s = outward(v);
        let mut step: f64 = 0.0;
        for w in domain.neighbors(v) {
            let behind = s * (u[w] - u[v]);
            if behind < 0.0 {
                continue;
            }
            // w follows the move by this fraction (a prescribed neighbour does not follow)
            let follow = (s * (u1[w] - u[w]) / unit).max(0.0);
            // the fill makes w an average of kept extrema of v's type alone (a grid's corner
            // between two kept maxima, with the 5-point stencil): no move clears it
            let held = fixed[w].is_none() && {
                let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
                (cp[w]..cp[w + 1]).all(|p| ri[p] == w || val[p] == 0.0 || kept.roles[ri[p]] == kept.roles[v])
            };
            if follow < MAX_FOLLOW && !held {
                step = step.max(behind / (1.0 - follow));
                continue;
            }
            // held (almost) only by moved extrema, w cannot be cleared: it is prescribed
            // halfway between v and its farthest other neighbour on the inner side, if any
            let inner = domain.neighbors(w).filter(|&x| x != v).map(|x| s * u[x]).fold(f64::INFINITY, f64::min);
            if inner < s * u[v] && fixed[w].is_none() && kept.roles[w] == Role::Other {
                out.push((w, 0.5 * (u[v] + s * inner)));
            }
        }
        out.push((v, u[v] + s * (1.25 * step + 1e-9 * unit)));
    }
    Ok(out)
}

/// A free neighbour that follows a kept extremum's outward move by this fraction or more is
/// prescribed instead of being outrun ([`outward_moves`]).
const MAX_FOLLOW: f64 = 0.9;

/// Vertices within `radius` rings of `v` (itself included).
fn rings<D: crate::domain::Domain>(domain: &D, v: usize, radius: usize) -> Vec<usize> {
    let mut seen = std::collections::HashSet::from([v]);
    let mut out = vec![v];
    let mut frontier = vec![v];
    for _ in 0..radius {
        let mut next = Vec::new();
        for &x in &frontier {
            for y in domain.neighbors(x) {
                if seen.insert(y) {
                    next.push(y);
                }
            }
        }
        out.extend(&next);
        frontier = next;
    }
    out
}

/// Rounds of releasing contradicting separatrices (each one harmonic solve) before the
/// caller falls back to another representative.
const MAX_RELEASE_ROUNDS: usize = 16;

fn is_regular<D: crate::domain::Domain>(domain: &D, u: &[f64], v: usize) -> bool {
    let (mut lower, mut higher) = (false, false);
    for w in domain.neighbors(v) {
        lower |= u[w] < u[v];
        higher |= u[w] > u[v];
    }
    lower && higher
}
