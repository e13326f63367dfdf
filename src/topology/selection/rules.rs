//! The selection as text: SPEC.md's rules (a persistence threshold, pairs, counts of minima
//! and maxima, explicit lists, every maximum or minimum) read from the settings' names and
//! values as every front end gives them, and [`Selection`]'s `FromStr` and `Display`.

use super::Selection;
use crate::error::{Error, Result};

/// The settings that choose the kept extrema, as the front ends name them (the command line
/// with dashes: `--keep-min`).
pub const SELECTION_SETTINGS: [&str; 8] =
    ["persistence", "pairs", "minima", "maxima", "keep_min", "keep_max", "keep_all_maxima", "keep_all_minima"];

/// The rule when none is given: persistence ≥ 5 % of the value range.
pub const DEFAULT_SELECTION: &str = "5%";

/// A persistence threshold: `5%` of the value range or an absolute value, either > 0.
///
/// # Errors
/// A setting error (`persistence`) for anything else.
pub fn parse_threshold(text: &str) -> Result<Selection> {
    let t = text.trim();
    let (number, relative) = match t.strip_suffix('%') {
        Some(p) => (p.trim(), true),
        None => (t, false),
    };
    match number.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => {
            Ok(if relative { Selection::Relative(v / 100.0) } else { Selection::Absolute(v) })
        }
        Ok(_) => Err(Error::setting("persistence", format!("must be > 0, got `{text}`"))),
        Err(_) => Err(Error::setting(
            "persistence",
            format!("`{text}` is not a number > 0 (in the field's units) or a percentage of the range such as 5%"),
        )),
    }
}

/// Comma-separated vertex indices (spaces allowed, empty items skipped).
///
/// # Errors
/// A setting error naming `setting` for an item that is not a vertex index.
pub fn parse_indices(setting: &'static str, text: &str) -> Result<Vec<usize>> {
    text.split(',')
        .filter(|p| !p.trim().is_empty())
        .map(|p| {
            p.trim()
                .parse::<usize>()
                .map_err(|_| Error::setting(setting, format!("`{}` in `{text}` is not a vertex index", p.trim())))
        })
        .collect()
}

fn count(setting: &'static str, text: &str) -> Result<usize> {
    text.trim().parse::<usize>().map_err(|_| Error::setting(setting, format!("`{text}` is not a whole number ≥ 0")))
}

fn switch(setting: &'static str, text: &str) -> Result<bool> {
    match text.trim() {
        "true" => Ok(true),
        "false" => Ok(false),
        other => Err(Error::setting(setting, format!("`{other}` is not true or false"))),
    }
}

impl Selection {
    /// The selection given by its settings as `(name, text)` pairs ([`SELECTION_SETTINGS`];
    /// other names are not looked at): exactly one rule — `persistence`, `pairs`, `minima`
    /// with `maxima`, `keep_min` with `keep_max`, `keep_all_maxima` or `keep_all_minima`
    /// (`true`; `false` is as if not given) — or `None` when none is given (the caller applies
    /// [`DEFAULT_SELECTION`]).
    ///
    /// # Errors
    /// Usage errors for two rules or half a pair, setting errors for a value that does not
    /// parse.
    pub fn from_settings(given: &[(&str, &str)]) -> Result<Option<Selection>> {
        let value = |name: &str| given.iter().rev().find(|(n, _)| *n == name).map(|(_, v)| *v);
        let all_max = value("keep_all_maxima").map(|v| switch("keep_all_maxima", v)).transpose()?.unwrap_or(false);
        let all_min = value("keep_all_minima").map(|v| switch("keep_all_minima", v)).transpose()?.unwrap_or(false);
        let rules = [
            ("persistence", value("persistence").is_some()),
            ("pairs", value("pairs").is_some()),
            ("minima and maxima", value("minima").is_some() || value("maxima").is_some()),
            ("keep_min and keep_max", value("keep_min").is_some() || value("keep_max").is_some()),
            ("keep_all_maxima", all_max),
            ("keep_all_minima", all_min),
        ];
        let chosen: Vec<&str> = rules.iter().filter(|r| r.1).map(|r| r.0).collect();
        if chosen.len() > 1 {
            return Err(Error::Usage(format!("choose one selection rule, got {}", chosen.join(" and "))));
        }
        let both = |a: &'static str, b: &'static str| -> Result<(&str, &str)> {
            match (value(a), value(b)) {
                (Some(x), Some(y)) => Ok((x, y)),
                (Some(_), None) => Err(Error::setting(a, format!("needs {b} as well (the two are one rule)"))),
                (None, _) => Err(Error::setting(b, format!("needs {a} as well (the two are one rule)"))),
            }
        };
        Ok(Some(match chosen.first().copied() {
            None => return Ok(None),
            Some("persistence") => parse_threshold(value("persistence").unwrap_or_default())?,
            Some("pairs") => Selection::Pairs(count("pairs", value("pairs").unwrap_or_default())?),
            Some("minima and maxima") => {
                let (mn, mx) = both("minima", "maxima")?;
                Selection::Count { minima: count("minima", mn)?, maxima: count("maxima", mx)? }
            }
            Some("keep_min and keep_max") => {
                let (mn, mx) = both("keep_min", "keep_max")?;
                Selection::Explicit { minima: parse_indices("keep_min", mn)?, maxima: parse_indices("keep_max", mx)? }
            }
            Some("keep_all_maxima") => Selection::AllMaxima,
            _ => Selection::AllMinima,
        }))
    }

    /// The settings that give this selection, as `(name, text)` pairs that
    /// [`Selection::from_settings`] reads back (a relative threshold to within an ulp: the
    /// percentage is printed, the fraction is read as percentage ÷ 100).
    pub fn settings(&self) -> Vec<(&'static str, String)> {
        let list = |v: &[usize]| v.iter().map(usize::to_string).collect::<Vec<_>>().join(",");
        match self {
            Selection::Absolute(t) => vec![("persistence", format!("{t}"))],
            Selection::Relative(t) => vec![("persistence", format!("{}%", t * 100.0))],
            Selection::Pairs(n) => vec![("pairs", n.to_string())],
            Selection::Count { minima, maxima } => vec![("minima", minima.to_string()), ("maxima", maxima.to_string())],
            Selection::Explicit { minima, maxima } => vec![("keep_min", list(minima)), ("keep_max", list(maxima))],
            Selection::AllMaxima => vec![("keep_all_maxima", "true".into())],
            Selection::AllMinima => vec![("keep_all_minima", "true".into())],
        }
    }
}

/// `5%` or `0.3` (a threshold), or the rule's settings as `name=value` separated by `;`:
/// `pairs=3`, `minima=9;maxima=4`, `keep_min=0,6;keep_max=3`, `keep_all_maxima`.
impl std::str::FromStr for Selection {
    type Err = Error;

    fn from_str(text: &str) -> Result<Self> {
        let t = text.trim();
        if !t.contains('=') && !t.starts_with("keep_all") {
            return parse_threshold(t);
        }
        let mut given = Vec::new();
        for clause in t.split(';').map(str::trim).filter(|c| !c.is_empty()) {
            let (name, value) = clause.split_once('=').map_or((clause, "true"), |(n, v)| (n.trim(), v.trim()));
            if !SELECTION_SETTINGS.contains(&name) {
                return Err(Error::Usage(format!(
                    "`{name}` in the selection `{text}` is not one of {}",
                    SELECTION_SETTINGS.join(", ")
                )));
            }
            given.push((name, value));
        }
        Selection::from_settings(&given)?.ok_or_else(|| Error::Usage(format!("the selection `{text}` gives no rule")))
    }
}

impl std::fmt::Display for Selection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Selection::Absolute(_) | Selection::Relative(_) => f.write_str(&self.settings()[0].1),
            Selection::AllMaxima => f.write_str("keep_all_maxima"),
            Selection::AllMinima => f.write_str("keep_all_minima"),
            _ => {
                let clauses: Vec<String> = self.settings().into_iter().map(|(n, v)| format!("{n}={v}")).collect();
                f.write_str(&clauses.join(";"))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_counts_and_lists_read_back() {
        assert_eq!("5%".parse::<Selection>().unwrap(), Selection::Relative(0.05));
        assert_eq!(" 0.25 ".parse::<Selection>().unwrap(), Selection::Absolute(0.25));
        assert_eq!("minima=9;maxima=4".parse::<Selection>().unwrap(), Selection::Count { minima: 9, maxima: 4 });
        assert_eq!("pairs=3".parse::<Selection>().unwrap(), Selection::Pairs(3));
        assert_eq!(
            "keep_min=0, 6;keep_max=3".parse::<Selection>().unwrap(),
            Selection::Explicit { minima: vec![0, 6], maxima: vec![3] }
        );
        assert_eq!("keep_all_maxima".parse::<Selection>().unwrap(), Selection::AllMaxima);
        for s in [
            Selection::Absolute(0.3),
            Selection::Relative(0.05),
            Selection::Relative(0.125),
            Selection::Pairs(0),
            Selection::Count { minima: 1, maxima: 7 },
            Selection::Explicit { minima: vec![], maxima: vec![4, 2] },
            Selection::AllMinima,
        ] {
            assert_eq!(s.to_string().parse::<Selection>().unwrap(), s, "{s}");
        }
    }

    #[test]
    fn bad_rules_are_refused_naming_the_setting() {
        for (text, words) in [
            ("0", "must be > 0"),
            ("-1%", "must be > 0"),
            ("abc", "not a number"),
            ("nan", "must be > 0"),
            ("minima=3", "needs maxima"),
            ("keep_max=3", "needs keep_min"),
            ("pairs=2;persistence=5%", "one selection rule"),
            ("pairs=-2", "not a whole number"),
            ("keep_min=1,x;keep_max=2", "not a vertex index"),
            ("frobnicate=1", "not one of"),
            ("keep_all_maxima=maybe", "not true or false"),
        ] {
            let e = text.parse::<Selection>().unwrap_err();
            assert_eq!(e.kind(), crate::ErrorKind::Usage, "{text}");
            assert!(e.to_string().contains(words), "{text}: {e}");
        }
        // false is as if not given
        assert_eq!(Selection::from_settings(&[("keep_all_minima", "false")]).unwrap(), None);
        assert_eq!(Selection::from_settings(&[]).unwrap(), None);
    }
}
