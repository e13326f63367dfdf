//! The input options as every front end names them ([`INPUT_OPTIONS`]: the command line's
//! flags, the Python `read` keywords) and [`ReadOptions::from_texts`], which reads them from
//! text as the settings are read ([`crate::pipeline::schema`]).

use super::field::{Derive, DomainKind, MaskRule, ReadOptions};
use crate::domain::{MAX_SPACING, MIN_SPACING};
use crate::error::{Error, Result};
use std::path::PathBuf;

/// One input option.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputOption {
    /// Its name in the library and the Python keywords (`fill_missing`); the command line's
    /// flag is the name with dashes, except `x_column`, which is `--x`.
    pub name: &'static str,
    /// What the command line's help shows as its value.
    pub value_name: &'static str,
    /// `true` or `false` (a flag on the command line).
    pub switch: bool,
    /// The names it takes, when it is a choice.
    pub choices: Option<&'static [&'static str]>,
    /// One sentence for every front end's help.
    pub help: &'static str,
}

impl InputOption {
    /// The command line's flag without its dashes.
    pub fn flag(&self) -> String {
        match self.name {
            "x_column" => "x".into(),
            name => name.replace('_', "-"),
        }
    }
}

const fn option(name: &'static str, value_name: &'static str, help: &'static str) -> InputOption {
    InputOption { name, value_name, switch: false, choices: None, help }
}

/// Every input option, in the order the help lists them.
pub const INPUT_OPTIONS: &[InputOption] = &[
    InputOption {
        choices: Some(DomainKind::NAMES),
        ..option(
            "domain",
            "KIND",
            "Read the input as a series, a grid or a mesh (default: by extension; a CSV whose first line is three or more numbers is a grid matrix).",
        )
    },
    option("column", "NAME", "Series: the value column, a header name or a 0-based index (default: the last numeric column)."),
    option(
        "x_column",
        "COLUMN",
        "Series: the x column, a header name, an index or `none` (default: the first column if it holds dates or is named x, t, time or date).",
    ),
    option(
        "array",
        "NAME",
        "The point array of a VTK file, the array of a .npz or a PLY vertex property (default: the only scalar array, or with derive the only vector array); on a mesh also `x`, `y` or `z`.",
    ),
    option(
        "spacing",
        "DX,DY[,DZ]",
        "Grid spacing dx,dy or volume spacing dx,dy,dz, overriding the file's (may be negative: rows running down).",
    ),
    InputOption {
        choices: Some(Derive::NAMES),
        ..option("derive", "SCALAR", "Grids and volumes: smooth a scalar derived from a velocity field (a 2- or 3-component array, or u and v).")
    },
    option("u", "FILE", "Grids: the x velocity component file (with v and derive, instead of an input file)."),
    option("v", "FILE", "Grids: the y velocity component file."),
    InputOption {
        switch: true,
        ..option(
            "fill_missing",
            "",
            "Fill missing samples (NaN, empty CSV cells) instead of refusing them: harmonically on grids and meshes, linearly in x on series.",
        )
    },
    option("values", "FILE", "Meshes: the field as one value per vertex and line of a text file."),
    option(
        "mask",
        "ARRAY",
        "Grids and volumes: smooth only where this point array of the input is non-zero (the outside is written unchanged).",
    ),
    option("mask_below", "V", "Grids and volumes: smooth only where the value is at least V (below V, and NaN, is outside)."),
];

/// `dx,dy` or `dx,dy,dz`, each with `MIN_SPACING ≤ |d| ≤ MAX_SPACING`.
///
/// # Errors
/// A setting error (`spacing`) for anything else.
pub fn parse_spacing(text: &str) -> Result<Vec<f64>> {
    let bad = || {
        Error::setting(
            "spacing",
            format!(
                "`{text}` must be two numbers dx,dy (grids) or three dx,dy,dz (volumes) with \
                 {MIN_SPACING:e} ≤ |d| ≤ {MAX_SPACING:e}"
            ),
        )
    };
    let parts: Vec<f64> =
        text.split(',').map(|p| p.trim().parse::<f64>()).collect::<std::result::Result<_, _>>().map_err(|_| bad())?;
    if !(2..=3).contains(&parts.len()) || parts.iter().any(|d| !(MIN_SPACING..=MAX_SPACING).contains(&d.abs())) {
        return Err(bad());
    }
    Ok(parts)
}

impl ReadOptions {
    /// The options from `(name, text)` pairs as the front ends give them ([`INPUT_OPTIONS`]'
    /// names; switches `true` or `false`).
    ///
    /// # Errors
    /// A usage error for an unknown name, `u` without `v` (or the reverse), `mask` with
    /// `mask_below`; a setting error naming the option for a text that does not parse.
    pub fn from_texts<'a>(given: impl IntoIterator<Item = (&'a str, &'a str)>) -> Result<Self> {
        let mut o = ReadOptions::default();
        let (mut u, mut v, mut below) = (None, None, None);
        for (name, text) in given {
            let Some(spec) = INPUT_OPTIONS.iter().find(|s| s.name == name) else {
                let names: Vec<&str> = INPUT_OPTIONS.iter().map(|s| s.name).collect();
                return Err(Error::Usage(format!(
                    "unknown input option `{name}` (the options are {})",
                    names.join(", ")
                )));
            };
            let text = text.trim();
            match spec.name {
                "domain" => o.domain = text.parse().map_err(|e: Error| Error::setting("domain", e.to_string()))?,
                "column" => o.column = Some(text.to_string()),
                "x_column" => o.x_column = Some(text.to_string()),
                "array" => o.array = Some(text.to_string()),
                "spacing" => o.spacing = Some(parse_spacing(text)?),
                "derive" => o.derive = Some(text.parse().map_err(|e: Error| Error::setting("derive", e.to_string()))?),
                "u" => u = Some(PathBuf::from(text)),
                "v" => v = Some(PathBuf::from(text)),
                "fill_missing" => {
                    o.fill_missing = match text {
                        "true" => true,
                        "false" => false,
                        _ => return Err(Error::setting("fill_missing", format!("`{text}` is not true or false"))),
                    }
                }
                "values" => o.values = Some(PathBuf::from(text)),
                "mask" => o.mask = Some(MaskRule::Array(text.to_string())),
                _ => match text.parse::<f64>() {
                    Ok(t) if t.is_finite() => below = Some(t),
                    _ => return Err(Error::setting("mask_below", format!("must be a finite number, got `{text}`"))),
                },
            }
        }
        o.uv = match (u, v) {
            (Some(u), Some(v)) => Some((u, v)),
            (None, None) => None,
            _ => return Err(Error::Usage("u and v are given together (the two velocity components)".into())),
        };
        if let Some(t) = below {
            if o.mask.is_some() {
                return Err(Error::Usage("give mask or mask_below, not both".into()));
            }
            o.mask = Some(MaskRule::Below(t));
        }
        Ok(o)
    }
}
