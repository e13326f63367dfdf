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
        down.simplify(&sublevel_pairs(domain, values), &keep_min)?;
        let keep_max: Vec<bool> = kept.roles.iter().map(|&r| r == Role::Max).collect();
        up.simplify(&superlevel_pairs(domain, values), &keep_max)?;
        let (ds, us) = (down.saddles(), up.saddles());
        let mut saddles: Vec<usize> = ds
            .iter()
            .map(|s| s.vertex)
            .filter(|v| us.iter().any(|u| u.vertex == *v) && !kept.roles[*v].is_fixed())
            .collect();
        saddles.sort_unstable();
        saddles.dedup();
        let trace = |g: &DiscreteGradient, list: &[super::gradient::Saddle]| -> Vec<Separatrix> {
            list.iter()
                .filter(|s| saddles.binary_search(&s.vertex).is_ok())
                .flat_map(|s| g.separatrices(s).map(|path| Separatrix { saddle: s.vertex, path }))
                .collect()
        };
        let (descending, ascending) = (trace(&down, &ds), trace(&up, &us));
        Ok(MorseSmale { descending, ascending, saddles, seconds: [built, t.elapsed().as_secs_f64()] })
    }
}
