//! The settings of a smoothing run as every front end names them: one table, [`SETTINGS`],
//! from which the command line's flags are generated (`commands/settings_args.rs`), against
//! which the Python keywords and the ParaView properties are checked by tests, and which
//! [`SmoothSettings::from_texts`] reads. A new setting is one row here, its field in
//! [`SmoothSettings`] with its arm in `apply` and `text`, and one line per front end.
//!
//! ```
//! use toposmooth::pipeline::{schema, SmoothSettings};
//! use toposmooth::{Selection, EdgeSet};
//!
//! let s = SmoothSettings::from_texts([("minima", "9"), ("maxima", "4"), ("edges", "all")])?;
//! assert_eq!(s.selection, Selection::Count { minima: 9, maxima: 4 });
//! assert_eq!(s.edges, EdgeSet::All);
//! // every setting's default, as text, reads back to the defaults
//! let defaults: Vec<(&str, &str)> = schema::SETTINGS.iter().filter_map(|d| Some((d.name, d.default?))).collect();
//! assert_eq!(SmoothSettings::from_texts(defaults)?, SmoothSettings::default());
//! # Ok::<(), toposmooth::Error>(())
//! ```

use super::smoothable::RepresentativeChoice;
use super::SmoothSettings;
use crate::constraints::EdgeSet;
use crate::error::{Error, Result};
use crate::operators::Energy;
use crate::solve::{Formulation, Method};
use crate::topology::selection::{parse_indices, parse_threshold, DEFAULT_SELECTION, SELECTION_SETTINGS};
use crate::topology::Selection;

/// What part of a run a setting belongs to (the front ends group them so).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    /// Which extrema survive (exactly one rule; [`DEFAULT_SELECTION`] when none is given).
    Selection,
    /// The energy and the data term.
    Energy,
    /// The constraints and the solver.
    Solver,
    /// How the run is carried out (threads): the results do not depend on it.
    Run,
}

/// What a setting's text holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A persistence threshold: `5%` of the value range or an absolute value, > 0.
    Threshold,
    /// A whole number in `min..=max`.
    Count {
        /// Smallest value.
        min: u64,
        /// Largest value.
        max: u64,
    },
    /// A finite real number above `min` (or at it, when `inclusive`).
    Real {
        /// Lower bound.
        min: f64,
        /// Whether `min` itself is allowed.
        inclusive: bool,
    },
    /// `true` or `false` (a flag on the command line).
    Switch,
    /// One of these names.
    Choice(&'static [&'static str]),
    /// Comma-separated vertex indices.
    Indices,
    /// A polyharmonic order 1..4, or a blend such as `1:0.2,2:1`.
    Orders,
    /// A size in bytes: `6G`, `512M`, `2.5GiB` (binary units) or a number of bytes.
    Size,
}

/// One setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    /// Its name in the library, the Python keywords and the JSON report (`data_weight`); the
    /// command line's flag is the name with dashes (`--data-weight`).
    pub name: &'static str,
    /// What the command line's help shows as its value (`W`).
    pub value_name: &'static str,
    /// One sentence (or two) for the help of every front end.
    pub help: &'static str,
    /// What its text holds, with the range.
    pub kind: Kind,
    /// The default as text; `None`: unset, chosen by the run (the help says how).
    pub default: Option<&'static str>,
    /// Its group.
    pub group: Group,
    /// The setting it is given with, as one rule (`minima` with `maxima`).
    pub partner: Option<&'static str>,
}

impl Setting {
    /// The command line's flag without its dashes: `data-weight`.
    pub fn flag(&self) -> String {
        self.name.replace('_', "-")
    }
}

const fn setting(
    name: &'static str,
    value_name: &'static str,
    kind: Kind,
    default: Option<&'static str>,
    group: Group,
    help: &'static str,
) -> Setting {
    Setting { name, value_name, help, kind, default, group, partner: None }
}

const fn paired(mut s: Setting, partner: &'static str) -> Setting {
    s.partner = Some(partner);
    s
}

const COUNT: Kind = Kind::Count { min: 0, max: u32::MAX as u64 };

/// Every setting of a smoothing run, in the order the help lists them.
pub const SETTINGS: &[Setting] = &[
    setting(
        "persistence",
        "T",
        Kind::Threshold,
        None,
        Group::Selection,
        "Keep the extrema of persistence ≥ T: `5%` of the value range or an absolute value in the field's units (the rule when none is given, at 5%).",
    ),
    setting(
        "pairs",
        "N",
        COUNT,
        None,
        Group::Selection,
        "Series: keep the N most persistent (minimum, maximum) pairs besides the global minimum.",
    ),
    paired(
        setting(
            "minima",
            "N",
            COUNT,
            None,
            Group::Selection,
            "Grids and meshes: keep the N most persistent minima (with maxima).",
        ),
        "maxima",
    ),
    paired(
        setting(
            "maxima",
            "M",
            COUNT,
            None,
            Group::Selection,
            "Grids and meshes: keep the M most persistent maxima (with minima).",
        ),
        "minima",
    ),
    paired(
        setting(
            "keep_min",
            "I,J",
            Kind::Indices,
            None,
            Group::Selection,
            "Keep exactly these minima (vertex indices, comma-separated; grids: row·nx + column), with keep_max.",
        ),
        "keep_max",
    ),
    paired(
        setting(
            "keep_max",
            "K",
            Kind::Indices,
            None,
            Group::Selection,
            "Keep exactly these maxima (vertex indices), with keep_min.",
        ),
        "keep_min",
    ),
    setting(
        "keep_all_maxima",
        "",
        Kind::Switch,
        Some("false"),
        Group::Selection,
        "Surfaces: keep every maximum of persistence > 0 and only the global minimum (geodesic distance from a source keeps its maxima).",
    ),
    setting(
        "keep_all_minima",
        "",
        Kind::Switch,
        Some("false"),
        Group::Selection,
        "Surfaces: keep every minimum of persistence > 0 and only the global maximum.",
    ),
    setting(
        "order",
        "K",
        Kind::Orders,
        Some("2"),
        Group::Energy,
        "Polyharmonic order 1..4, or a blend such as `1:0.2,2:1`.",
    ),
    setting(
        "sharp",
        "I,J",
        Kind::Indices,
        None,
        Group::Energy,
        "Vertices where orders ≥ 2 are not penalised (a spike can stay C0).",
    ),
    setting(
        "data_weight",
        "W",
        Kind::Real { min: 0.0, inclusive: true },
        Some("1"),
        Group::Energy,
        "γD, the weight of the data term (0: no data, the representative harmonic).",
    ),
    setting(
        "smooth_weight",
        "W",
        Kind::Real { min: 0.0, inclusive: false },
        None,
        Group::Energy,
        "γL for every energy term (default: ℓ^(2k) with ℓ the smoothing length).",
    ),
    setting(
        "smooth_length",
        "FRACTION",
        Kind::Real { min: 0.0, inclusive: false },
        None,
        Group::Energy,
        "Smoothing length ℓ as a fraction of the domain's diameter (the series' extent); by default max(2 mean edge lengths, 1 % of the diameter), on series at most 0.3 × the median spacing of the kept extrema (the report gives ℓ and the rule).",
    ),
    setting(
        "edges",
        "SET",
        Kind::Choice(EdgeSet::NAMES),
        Some("minimal"),
        Group::Solver,
        "Constraint set: one lower and one higher neighbour per free vertex (minimal), or every edge (all).",
    ),
    setting(
        "representative",
        "NAME",
        Kind::Choice(RepresentativeChoice::NAMES),
        None,
        Group::Solver,
        "Grids and meshes: the representative function. Given, it is built or the run fails (exit 3 when the data cannot follow its order, 1 when it fails its own check); by default the flooded one (the data with its cancelled basins flooded: closest to the data), then on surfaces the separatrix one, then harmonic, each fallback reported.",
    ),
    setting(
        "max_iter",
        "N",
        Kind::Count { min: 1, max: u32::MAX as u64 },
        Some("200"),
        Group::Solver,
        "Largest number of solver iterations.",
    ),
    setting(
        "solver",
        "NAME",
        Kind::Choice(Method::NAMES),
        Some("auto"),
        Group::Solver,
        "QP solver: auto (the active-set iteration on volumes of 1,000 vertices or more, else structured), the structured interior-point method (Clarabel takes over if it fails), Clarabel alone, or the active-set iteration with conjugate gradients, which factorises nothing and hands over to the structured solver when it does not converge.",
    ),
    setting(
        "formulation",
        "NAME",
        Kind::Choice(Formulation::NAMES),
        Some("auto"),
        Group::Solver,
        "How the energy enters the solver: assembled (normal equations in double precision), factored (FᵀF, the paper's auxiliary variables: double-double normal equations in the structured solver), or auto (factored when the condition estimate exceeds 1e9).",
    ),
    setting(
        "memory_limit",
        "SIZE",
        Kind::Size,
        None,
        Group::Run,
        "The memory the run may use (6G, 512M): a route predicted past it is refused before its work (exit 3) instead of being killed; by default the lowest of the cgroup's limit, ulimit -v and the machine's memory.",
    ),
    setting(
        "threads",
        "N",
        Kind::Count { min: 1, max: 1024 },
        None,
        Group::Run,
        "At most N threads (default: every core, or the caller's cap); results are bit-identical for every count.",
    ),
];

/// The setting named `name`.
pub fn find(name: &str) -> Option<&'static Setting> {
    SETTINGS.iter().find(|s| s.name == name)
}

impl Kind {
    /// Checks `text` against the kind and its range (a setting error naming `setting`).
    ///
    /// # Errors
    /// A setting error saying what the text should be.
    pub fn check(self, setting: &'static str, text: &str) -> Result<()> {
        let t = text.trim();
        match self {
            Kind::Threshold => parse_threshold(t).map(drop),
            Kind::Count { min, max } => match t.parse::<u64>() {
                Ok(v) if (min..=max).contains(&v) => Ok(()),
                Ok(v) => Err(Error::setting(setting, format!("must be between {min} and {max}, got {v}"))),
                Err(_) => Err(Error::setting(setting, format!("`{text}` is not a whole number ≥ {min}"))),
            },
            Kind::Real { min, inclusive } => {
                let ok = |v: f64| v.is_finite() && if inclusive { v >= min } else { v > min };
                match t.parse::<f64>() {
                    Ok(v) if ok(v) => Ok(()),
                    _ => Err(Error::setting(
                        setting,
                        format!("must be finite and {} {min}, got {text}", if inclusive { "≥" } else { ">" }),
                    )),
                }
            }
            Kind::Switch => match t {
                "true" | "false" => Ok(()),
                _ => Err(Error::setting(setting, format!("`{text}` is not true or false"))),
            },
            Kind::Choice(names) => match names.contains(&t) {
                true => Ok(()),
                false => Err(Error::setting(setting, format!("must be one of {}, got `{text}`", names.join(", ")))),
            },
            Kind::Indices => parse_indices(setting, t).map(drop),
            Kind::Orders => Energy::parse(t).map(drop),
            Kind::Size => crate::memory::parse_size(t).map(drop),
        }
    }
}

impl SmoothSettings {
    /// Settings from `(name, text)` pairs as the front ends give them: the command line's
    /// flags, the Python keywords, a JSON object's strings. Names are [`SETTINGS`]' (unknown
    /// ones are refused); what is not given keeps its default; the selection takes exactly one
    /// rule ([`Selection::from_settings`]).
    ///
    /// # Errors
    /// A usage error for an unknown name or two selection rules, a setting error naming the
    /// setting for a text of the wrong kind or out of range.
    pub fn from_texts<'a>(given: impl IntoIterator<Item = (&'a str, &'a str)>) -> Result<Self> {
        let given: Vec<(&str, &str)> = given.into_iter().collect();
        let mut settings = SmoothSettings::default();
        let mut selection = Vec::new();
        for &(name, text) in &given {
            let Some(spec) = find(name) else {
                let names: Vec<&str> = SETTINGS.iter().map(|s| s.name).collect();
                return Err(Error::Usage(format!("unknown setting `{name}` (the settings are {})", names.join(", "))));
            };
            spec.kind.check(spec.name, text)?;
            if SELECTION_SETTINGS.contains(&name) {
                selection.push((name, text));
            } else {
                settings.apply(spec.name, text.trim())?;
            }
        }
        settings.selection = match Selection::from_settings(&selection)? {
            Some(s) => s,
            None => parse_threshold(DEFAULT_SELECTION)?,
        };
        settings.validate()?;
        Ok(settings)
    }

    /// Sets the setting `name` (not a selection setting) from `text`, already checked.
    fn apply(&mut self, name: &'static str, text: &str) -> Result<()> {
        let real = || text.parse::<f64>().map_err(|_| Error::setting(name, format!("`{text}` is not a number")));
        let whole = || text.parse::<u64>().map_err(|_| Error::setting(name, format!("`{text}` is not a count")));
        match name {
            "order" => {
                let sharp = std::mem::take(&mut self.energy.sharp);
                self.energy = Energy::parse(text)?;
                self.energy.sharp = sharp;
            }
            "sharp" => self.energy.sharp = parse_indices(name, text)?,
            "data_weight" => self.data_weight = real()?,
            "smooth_weight" => self.smooth_weight = Some(real()?),
            "smooth_length" => self.smooth_length = Some(real()?),
            "edges" => self.edges = text.parse()?,
            "representative" => self.representative = Some(text.parse()?),
            "max_iter" => self.qp.max_iter = u32::try_from(whole()?).unwrap_or(u32::MAX),
            "solver" => self.qp.method = text.parse()?,
            "formulation" => self.qp.formulation = text.parse()?,
            "threads" => self.threads = Some(usize::try_from(whole()?).unwrap_or(usize::MAX)),
            "memory_limit" => self.qp.memory_limit = Some(crate::memory::parse_size(text)?),
            _ => return Err(Error::internal(format!("the setting `{name}` has no field"))),
        }
        Ok(())
    }

    /// The text of setting `name` in these settings, as [`SmoothSettings::from_texts`] reads
    /// it; `None` when it is unset (chosen by the run) or a selection setting the selection
    /// does not use.
    pub fn text(&self, name: &str) -> Option<String> {
        if SELECTION_SETTINGS.contains(&name) {
            let own = self.selection.settings().into_iter().find(|(n, _)| *n == name).map(|(_, v)| v);
            return match find(name)?.kind {
                Kind::Switch => Some(own.unwrap_or_else(|| "false".into())),
                _ => own,
            };
        }
        let list = |v: &[usize]| v.iter().map(usize::to_string).collect::<Vec<_>>().join(",");
        Some(match name {
            "order" => self.energy.orders_text(),
            "sharp" if self.energy.sharp.is_empty() => return None,
            "sharp" => list(&self.energy.sharp),
            "data_weight" => self.data_weight.to_string(),
            "smooth_weight" => self.smooth_weight?.to_string(),
            "smooth_length" => self.smooth_length?.to_string(),
            "edges" => self.edges.to_string(),
            "representative" => self.representative?.to_string(),
            "max_iter" => self.qp.max_iter.to_string(),
            "solver" => self.qp.method.to_string(),
            "formulation" => self.qp.formulation.to_string(),
            "threads" => self.threads?.to_string(),
            "memory_limit" => self.qp.memory_limit?.to_string(),
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_reads_back_its_own_text() {
        let given = [
            ("keep_min", "3, 1"),
            ("keep_max", "7"),
            ("order", "1:0.5,3:2"),
            ("sharp", "4,9"),
            ("data_weight", "0.25"),
            ("smooth_weight", "1e-6"),
            ("smooth_length", "0.02"),
            ("edges", "all"),
            ("representative", "flooded"),
            ("max_iter", "17"),
            ("solver", "active-set"),
            ("formulation", "factored"),
            ("threads", "3"),
            ("memory_limit", "1.5G"),
        ];
        let s = SmoothSettings::from_texts(given).unwrap();
        assert_eq!(s.selection, Selection::Explicit { minima: vec![3, 1], maxima: vec![7] });
        assert_eq!((s.energy.terms.clone(), s.energy.sharp.clone()), (vec![(1, 0.5), (3, 2.0)], vec![4, 9]));
        assert_eq!((s.data_weight, s.smooth_weight, s.smooth_length), (0.25, Some(1e-6), Some(0.02)));
        assert_eq!((s.edges, s.representative), (EdgeSet::All, Some(RepresentativeChoice::Flooded)));
        assert_eq!((s.qp.max_iter, s.qp.method, s.qp.formulation), (17, Method::ActiveSet, Formulation::Factored));
        assert_eq!((s.threads, s.qp.memory_limit), (Some(3), Some(3 << 29)));
        // the texts of every setting give the same settings back
        let texts: Vec<(&str, String)> = SETTINGS.iter().filter_map(|d| Some((d.name, s.text(d.name)?))).collect();
        let again = SmoothSettings::from_texts(texts.iter().map(|(n, t)| (*n, t.as_str()))).unwrap();
        assert_eq!(again, s);
        // a default text is the text of the default
        let d = SmoothSettings::default();
        for spec in SETTINGS {
            // the default selection is the threshold's rule
            let own = if spec.name == "persistence" { Some(DEFAULT_SELECTION) } else { spec.default };
            assert_eq!(d.text(spec.name).as_deref(), own, "{}", spec.name);
            if let Some(text) = spec.default {
                spec.kind.check(spec.name, text).unwrap();
            }
        }
        assert_eq!(d.selection, DEFAULT_SELECTION.parse().unwrap());
    }

    #[test]
    fn wrong_texts_name_their_setting() {
        for (name, text, words) in [
            ("data_weight", "-1", "must be finite and ≥ 0"),
            ("data_weight", "nan", "must be finite"),
            ("smooth_length", "0", "must be finite and > 0"),
            ("max_iter", "0", "between 1 and"),
            ("max_iter", "2.5", "not a whole number"),
            ("edges", "some", "one of minimal, all"),
            ("solver", "fast", "one of auto, structured"),
            ("threads", "0", "between 1 and"),
            ("keep_all_maxima", "yes", "true or false"),
        ] {
            let e = SmoothSettings::from_texts([(name, text)]).unwrap_err();
            assert!(matches!(e, Error::Setting { setting, .. } if setting == name), "{name} {text}: {e:?}");
            assert!(e.to_string().contains(words), "{name} {text}: {e}");
        }
        let e = SmoothSettings::from_texts([("order", "7")]).unwrap_err();
        assert_eq!(e.kind(), crate::ErrorKind::Usage);
        let e = SmoothSettings::from_texts([("gamma", "1")]).unwrap_err();
        assert!(e.to_string().contains("unknown setting `gamma`"), "{e}");
        let e = SmoothSettings::from_texts([("persistence", "5%"), ("pairs", "2")]).unwrap_err();
        assert!(e.to_string().contains("one selection rule"), "{e}");
    }

    #[test]
    fn partners_name_each_other_and_choices_are_the_enums_names() {
        for s in SETTINGS {
            if let Some(p) = s.partner {
                assert_eq!(find(p).and_then(|q| q.partner), Some(s.name), "{}", s.name);
                assert_eq!(find(p).map(|q| q.group), Some(Group::Selection));
            }
            assert_eq!(SELECTION_SETTINGS.contains(&s.name), s.group == Group::Selection, "{}", s.name);
        }
        assert_eq!(SETTINGS.iter().filter(|s| s.group == Group::Selection).count(), SELECTION_SETTINGS.len());
        for name in Method::NAMES {
            assert_eq!(name.parse::<Method>().unwrap().name(), *name);
        }
    }

    #[cfg(feature = "serde")]
    #[test]
    fn settings_go_through_json_and_back() {
        let s = SmoothSettings::from_texts([
            ("keep_min", "3,1"),
            ("keep_max", "7"),
            ("order", "1:0.5,3:2"),
            ("solver", "clarabel-auxiliary"),
            ("representative", "harmonic"),
            ("threads", "4"),
        ])
        .unwrap();
        let json = serde_json::to_string(&s).unwrap();
        assert!(json.contains(r#""rule":"explicit""#) && json.contains(r#""method":"clarabel-auxiliary""#), "{json}");
        assert_eq!(serde_json::from_str::<SmoothSettings>(&json).unwrap(), s);
        // what is not given keeps its default
        let partial: SmoothSettings = serde_json::from_str(r#"{"data_weight": 0.5, "edges": "all"}"#).unwrap();
        assert_eq!(partial, SmoothSettings::from_texts([("data_weight", "0.5"), ("edges", "all")]).unwrap());
        assert!(serde_json::from_str::<SmoothSettings>(r#"{"selection": {"rule": "loudest"}}"#).is_err());
    }
}
