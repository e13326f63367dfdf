//! The settings of a run and the default smoothing length.

use crate::constraints::EdgeSet;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::operators::Energy;
use crate::solve::QpSettings;
use crate::topology::{KeptSet, Selection};

use super::smoothable::RepresentativeChoice;

/// Settings of a smoothing run. Defaults follow SPEC.md; every field is a setting of
/// [`super::schema::SETTINGS`], which the front ends are made from (the selection is several).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct SmoothSettings {
    /// Which extrema survive. {persistence ≥ 5 % of the range}
    pub selection: Selection,
    /// Smoothness energy: orders, blend weights, sharp vertices. {order 2}
    pub energy: Energy,
    /// γD, weight of the mass-weighted data term Σ M_ii (f_i − h_i)². {1}
    pub data_weight: f64,
    /// γL for every energy term; `None` means ℓ^(2k) per order k. {None}
    pub smooth_weight: Option<f64>,
    /// Smoothing length ℓ as a fraction of the domain's diameter; `None` chooses it from the
    /// domain and the kept extrema ([`default_smooth_length`]). {None}
    pub smooth_length: Option<f64>,
    /// Constraint set. {minimal}
    pub edges: EdgeSet,
    /// Solver settings.
    pub qp: QpSettings,
    /// Representative function on surfaces; `None` chooses automatically (separatrix, then
    /// harmonic, then flooded, each fallback reported). {None}
    pub representative: Option<RepresentativeChoice>,
    /// At most this many threads for the run; `None` keeps the caller's cap
    /// ([`crate::parallel::with_threads`], every core by default). Results do not depend on it. {None}
    pub threads: Option<usize>,
}

impl Default for SmoothSettings {
    fn default() -> Self {
        SmoothSettings {
            selection: Selection::Relative(0.05),
            energy: Energy::order(2),
            data_weight: 1.0,
            smooth_weight: None,
            smooth_length: None,
            edges: EdgeSet::Minimal,
            qp: QpSettings::default(),
            representative: None,
            threads: None,
        }
    }
}

impl SmoothSettings {
    /// Checks the settings.
    pub fn validate(&self) -> Result<()> {
        self.energy.validate()?;
        if !(self.data_weight.is_finite() && self.data_weight >= 0.0) {
            return Err(Error::setting("data_weight", format!("must be finite and ≥ 0, got {}", self.data_weight)));
        }
        if let Some(w) = self.smooth_weight {
            if !(w.is_finite() && w > 0.0) {
                return Err(Error::setting("smooth_weight", format!("must be finite and > 0, got {w}")));
            }
        }
        if self.threads == Some(0) {
            return Err(Error::setting("threads", "must be at least 1, got 0"));
        }
        if let Some(l) = self.smooth_length {
            if !(l.is_finite() && l > 0.0) {
                return Err(Error::setting("smooth_length", format!("must be finite and > 0, got {l}")));
            }
        }
        Ok(())
    }
}

/// Fraction of the diameter the default smoothing length starts from.
pub const SMOOTH_LENGTH_FRACTION: f64 = 0.01;
/// The default ℓ is at least this many mean edge lengths (sample spacings).
pub const SMOOTH_LENGTH_EDGES: f64 = 2.0;
/// On series the default ℓ is at most this fraction of the median spacing of consecutive
/// kept extrema (below 1/π: the kept oscillation stays in the pass band at every order).
pub const SMOOTH_LENGTH_KEPT_SPACING: f64 = 0.3;

/// The default smoothing length and the rule that set it (SPEC.md, "Defaults"):
/// `ℓ = max(2 h̄, 1 % of the diameter)` with `h̄` the mean edge length (sample spacing); on a
/// series the 1 % is capped at 0.3 × the median x-distance S between consecutive kept extrema,
/// so that dense kept extrema are not smoothed against: without constraints the energy is the
/// low-pass filter `1/(1 + (ℓω)^{2k})`, and a kept oscillation of half-period S (ω = π/S) stays
/// in its pass band at every order when `πℓ < S`.
pub fn default_smooth_length<D: Domain>(domain: &D, kept: &KeptSet) -> (f64, String) {
    let edges = domain.edges();
    let mean_edge = edges
        .iter()
        .map(|&(i, j)| {
            let (a, b) = (domain.point(i), domain.point(j));
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .sum::<f64>()
        / edges.len().max(1) as f64;
    let diameter = domain.diameter();
    let floor = SMOOTH_LENGTH_EDGES * mean_edge;
    let mut base = SMOOTH_LENGTH_FRACTION * diameter;
    let mut why = format!("1 % of the diameter ({})", short(base));
    if domain.pairing_rule() == crate::domain::PairingRule::Path {
        let mut at: Vec<f64> = kept.kept.iter().map(|k| domain.point(k.index)[0]).collect();
        at.sort_by(f64::total_cmp);
        let mut gaps: Vec<f64> = at.windows(2).map(|w| w[1] - w[0]).collect();
        if !gaps.is_empty() {
            gaps.sort_by(f64::total_cmp);
            let median = gaps[gaps.len() / 2];
            let cap = SMOOTH_LENGTH_KEPT_SPACING * median;
            if cap < base {
                base = cap;
                why = format!("0.3 × the median spacing of the kept extrema ({})", short(median));
            }
        }
    }
    if base < floor {
        (floor, format!("2 mean edge lengths ({}; {why} is shorter)", short(mean_edge)))
    } else {
        (base, why)
    }
}

/// `x` to 4 significant digits.
fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{x:.decimals$}")
}
