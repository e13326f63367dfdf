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
    /// Partners of kept extrema that are saddles of one structure only (on a boundary the
    /// cones sit above the domain in the descending structure and below it in the ascending
    /// one), with their separatrices of both families: the descending ones first, as `(true,
    /// path)`, then the ascending ones. Not in the lists above; [`MorseSmale::with_boundary`]
    /// merges them.
    pub boundary: Vec<(bool, Separatrix)>,
    /// Seconds spent building the two discrete gradients and simplifying them.
    pub seconds: [f64; 2],
}

impl MorseSmale {
    /// Builds both discrete gradients, cancels every extremum the kept set does not keep,
    /// matches the surviving saddles and traces their separatrices.
    ///
    /// # Errors
    /// A description of a cancellation that failed (never expected for persistence sets).
    pub fn new<D: Domain>(domain: &D, values: &[f64], kept: &KeptSet) -> Result<Self, String> {
        let t = std::time::Instant::now();
        let complex = std::sync::Arc::new(super::gradient::Complex::new(domain));
        let mut down = DiscreteGradient::on(complex.clone(), values, Direction::Descending);
        let mut up = DiscreteGradient::on(complex, values, Direction::Ascending);
        let built = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let keep_min: Vec<bool> = kept.roles.iter().map(|&r| r == Role::Min).collect();
        let (low_pairs, high_pairs) = (sublevel_pairs(domain, values), superlevel_pairs(domain, values));
        down.simplify(&low_pairs, &keep_min)?;
        let keep_max: Vec<bool> = kept.roles.iter().map(|&r| r == Role::Max).collect();
        up.simplify(&high_pairs, &keep_max)?;
        let (ds, us) = (down.saddles(), up.saddles());
        let in_down: std::collections::HashSet<usize> = ds.iter().map(|s| s.vertex).collect();
        let in_up: std::collections::HashSet<usize> = us.iter().map(|s| s.vertex).collect();
        // partners of kept extrema that are saddles of one structure only (boundary saddles:
        // the cones sit above the domain in one structure, below it in the other)
        let one_sided: Vec<usize> = low_pairs
            .iter()
            .filter(|p| keep_min[p.extremum])
            .chain(high_pairs.iter().filter(|p| keep_max[p.extremum]))
            .filter_map(|p| p.partner)
            .filter(|v| in_down.contains(v) != in_up.contains(v) && !kept.roles[*v].is_fixed())
            .collect();
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
        let mut boundary = Vec::new();
        for &v in &one_sided {
            let (own, other, own_is_down) = if in_down.contains(&v) { (&down, &up, true) } else { (&up, &down, false) };
            let list = if own_is_down { &ds } else { &us };
            for s in list.iter().filter(|s| s.vertex == v) {
                for path in own.separatrices(s).into_iter().filter(|p| p.len() > 1) {
                    boundary.push((own_is_down, Separatrix { saddle: v, path }));
                }
            }
            let path = other.vertex_path(v);
            if path.len() > 1 {
                boundary.push((!own_is_down, Separatrix { saddle: v, path }));
            }
        }
        boundary.sort_by_key(|(down, _)| !*down);
        Ok(MorseSmale { descending, ascending, boundary, saddles, seconds: [built, t.elapsed().as_secs_f64()] })
    }

    /// The complex with the one-sided boundary saddles and their separatrices merged in
    /// (`None` when there are none).
    pub fn with_boundary(&self) -> Option<MorseSmale> {
        if self.boundary.is_empty() {
            return None;
        }
        let mut merged = self.clone();
        for (down, sep) in &self.boundary {
            merged.saddles.push(sep.saddle);
            if *down {
                merged.descending.push(sep.clone());
            } else {
                merged.ascending.push(sep.clone());
            }
        }
        merged.saddles.sort_unstable();
        merged.saddles.dedup();
        merged.boundary.clear();
        Some(merged)
    }
}
