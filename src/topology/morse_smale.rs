//! The simplified Morse–Smale complex: kept extrema, the saddles that survive in both the
//! descending and the ascending discrete gradient (matched by their PL saddle vertex,
//! NOTES.md 7), and their separatrices as vertex paths.

use super::gradient::{Direction, DiscreteGradient};
use super::{sublevel_pairs, superlevel_pairs, KeptSet, Role};
use crate::domain::Domain;

/// One separatrix: a saddle vertex and the vertex path from it to a kept extremum.
#[derive(Clone, Debug, PartialEq)]
pub struct Separatrix {
    /// The PL saddle vertex it starts at.
    pub saddle: usize,
    /// Vertices from the saddle (first) to the extremum (last).
    pub path: Vec<usize>,
}

/// The complex the representative function is built from.
#[derive(Clone, Debug, PartialEq)]
pub struct MorseSmale {
    /// Saddle vertices surviving in both structures.
    pub saddles: Vec<usize>,
    /// Separatrices descending to kept minima.
    pub descending: Vec<Separatrix>,
    /// Separatrices ascending to kept maxima.
    pub ascending: Vec<Separatrix>,
    /// Partners of kept extrema that are saddles of one structure only — on the boundary (the
    /// cones sit above the domain in the descending structure and below it in the ascending
    /// one) and at degenerate interior saddles the other structure cancelled with an extremum
    /// it did not keep — with their separatrices of both families: the descending ones first,
    /// as `(true, path)`, then the ascending ones. Not in the lists above;
    /// [`MorseSmale::with_one_sided`] merges them.
    pub one_sided: Vec<(bool, Separatrix)>,
    /// Seconds spent building the two discrete gradients and simplifying them.
    pub seconds: [f64; 2],
}

impl MorseSmale {
    /// Builds both discrete gradients, cancels every extremum the kept set does not keep,
    /// matches the surviving saddles and traces their separatrices.
    ///
    /// # Errors
    /// A description of a cancellation that failed (never expected for persistence sets).
    pub fn new<D: Domain>(domain: &D, values: &[f64], kept: &KeptSet) -> Result<Self, crate::error::ConstructionError> {
        let t = std::time::Instant::now();
        let complex = std::sync::Arc::new(super::gradient::Complex::new(domain));
        let mut down = DiscreteGradient::on(complex.clone(), values, Direction::Descending);
        let mut up = DiscreteGradient::on(complex, values, Direction::Ascending);
        let built = t.elapsed().as_secs_f64();
        let stop = || crate::error::ConstructionError::Unfit("cancelled".into());
        if crate::progress::cancelled() {
            return Err(stop());
        }
        let t = std::time::Instant::now();
        let keep_min: Vec<bool> = kept.roles.iter().map(|&r| r == Role::Min).collect();
        let (low_pairs, high_pairs) = (sublevel_pairs(domain, values), superlevel_pairs(domain, values));
        down.simplify(&low_pairs, &keep_min)?;
        let keep_max: Vec<bool> = kept.roles.iter().map(|&r| r == Role::Max).collect();
        up.simplify(&high_pairs, &keep_max)?;
        if crate::progress::cancelled() {
            return Err(stop());
        }
        let (ds, us) = (down.saddles(), up.saddles());
        let in_down: std::collections::HashSet<usize> = ds.iter().map(|s| s.vertex).collect();
        let in_up: std::collections::HashSet<usize> = us.iter().map(|s| s.vertex).collect();
        // partners of kept extrema that are saddles of one structure only
        let mut one_sided_saddles: Vec<usize> = low_pairs
            .iter()
            .filter(|p| keep_min[p.extremum])
            .chain(high_pairs.iter().filter(|p| keep_max[p.extremum]))
            .filter_map(|p| p.partner)
            .filter(|v| in_down.contains(v) != in_up.contains(v) && !kept.roles[*v].is_fixed())
            .collect();
        one_sided_saddles.sort_unstable();
        one_sided_saddles.dedup();
        let mut saddles: Vec<usize> =
            ds.iter().map(|s| s.vertex).filter(|v| in_up.contains(v) && !kept.roles[*v].is_fixed()).collect();
        saddles.sort_unstable();
        saddles.dedup();
        let trace = |g: &DiscreteGradient, list: &[super::gradient::Saddle]| -> Vec<Separatrix> {
            list.iter()
                .filter(|s| saddles.binary_search(&s.vertex).is_ok())
                .flat_map(|s| g.separatrices(s).map(|path| Separatrix { saddle: s.vertex, path }))
                .collect()
        };
        let (descending, ascending) = (trace(&down, &ds), trace(&up, &us));
        // a one-sided saddle: its separatrices in the structure it is a saddle of, and for the
        // other family the V-path from it in the other structure
        let mut one_sided = Vec::new();
        for &v in &one_sided_saddles {
            let (own, other, own_is_down) = if in_down.contains(&v) { (&down, &up, true) } else { (&up, &down, false) };
            let list = if own_is_down { &ds } else { &us };
            for s in list.iter().filter(|s| s.vertex == v) {
                for path in own.separatrices(s).into_iter().filter(|p| p.len() > 1) {
                    one_sided.push((own_is_down, Separatrix { saddle: v, path }));
                }
            }
            let path = other.vertex_path(v);
            if path.len() > 1 {
                one_sided.push((!own_is_down, Separatrix { saddle: v, path }));
            }
        }
        one_sided.sort_by_key(|(down, _)| !*down);
        Ok(MorseSmale { descending, ascending, one_sided, saddles, seconds: [built, t.elapsed().as_secs_f64()] })
    }

    /// The complex with the one-sided saddles and their separatrices merged in
    /// (`None` when there are none).
    pub fn with_one_sided(&self) -> Option<MorseSmale> {
        if self.one_sided.is_empty() {
            return None;
        }
        let mut merged = self.clone();
        for (down, sep) in &self.one_sided {
            merged.saddles.push(sep.saddle);
            if *down {
                merged.descending.push(sep.clone());
            } else {
                merged.ascending.push(sep.clone());
            }
        }
        merged.saddles.sort_unstable();
        merged.saddles.dedup();
        merged.one_sided.clear();
        Some(merged)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Grid2d;
    use crate::topology::{select, Selection};

    /// One-sided saddles come mostly from the cones (on the boundary); every separatrix
    /// (matched or one-sided) runs from its saddle to a kept extremum of its family's type.
    #[test]
    fn one_sided_saddles_reach_kept_extrema() {
        let (mut with_one_sided, mut outer, mut inner) = (0, 0, 0);
        for seed in 0..200u64 {
            let (nx, ny) = (5 + (seed % 11) as usize, 4 + (seed % 7) as usize);
            let mut state = seed;
            let h: Vec<f64> = (0..nx * ny)
                .map(|v| {
                    state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    let (x, y) = ((v % nx) as f64 / nx as f64, (v / nx) as f64 / ny as f64);
                    (6.0 * x).sin() * (5.0 * y).cos() + 0.3 * (state >> 11) as f64 / (1u64 << 53) as f64
                })
                .collect();
            let g = Grid2d::new(nx, ny).unwrap();
            let kept =
                select(&g, &h, &Selection::Count { minima: 1 + (seed % 4) as usize, maxima: 1 + (seed % 3) as usize })
                    .unwrap();
            let ms = MorseSmale::new(&g, &h, &kept).unwrap();
            let on_boundary = |v: usize| v.is_multiple_of(nx) || v % nx == nx - 1 || v / nx == 0 || v / nx == ny - 1;
            for (down, sep) in &ms.one_sided {
                if on_boundary(sep.saddle) {
                    outer += 1;
                } else {
                    inner += 1;
                }
                assert!(ms.saddles.binary_search(&sep.saddle).is_err(), "seed {seed}: also matched");
                let end = *sep.path.last().unwrap();
                assert_eq!(kept.roles[end], if *down { Role::Min } else { Role::Max }, "seed {seed}");
            }
            let merged = ms.with_one_sided();
            assert_eq!(merged.is_some(), !ms.one_sided.is_empty());
            if let Some(m) = merged {
                with_one_sided += 1;
                assert_eq!(
                    m.descending.len() + m.ascending.len(),
                    ms.descending.len() + ms.ascending.len() + ms.one_sided.len()
                );
                for s in m.descending.iter() {
                    assert_eq!(kept.roles[*s.path.last().unwrap()], Role::Min);
                }
                for s in m.ascending.iter() {
                    assert_eq!(kept.roles[*s.path.last().unwrap()], Role::Max);
                }
            }
        }
        eprintln!("{with_one_sided} fields with one-sided saddles; their separatrices: {outer} from boundary vertices, {inner} inside");
        assert!(with_one_sided > 20, "{with_one_sided} of 200 fields have one-sided saddles");
        assert!(outer > inner, "mostly the cones' doing: {outer} on the boundary, {inner} inside");
    }
}
