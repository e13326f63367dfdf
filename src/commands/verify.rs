//! `toposmooth verify`: re-check an output file from what it carries, independently of `smooth`.

use crate::domain::Series;
use crate::error::{Error, Result};
use crate::io::series_csv::{read_series, read_series_output, SeriesCsvOptions};
use crate::topology::Role;
use crate::verify::certify;
use std::path::PathBuf;

/// Options of `verify`.
#[derive(Clone, Debug)]
pub struct VerifyArgs {
    /// The output file to check.
    pub file: PathBuf,
    /// The original input, to compare with the file's input column.
    pub input: Option<PathBuf>,
    /// Column choice for the original input.
    pub csv: SeriesCsvOptions,
}

/// Runs `verify`: `Ok(text)` when the file is certified, [`Error::Uncertified`] (exit 1) when not.
pub fn verify(args: &VerifyArgs) -> Result<String> {
    let out = read_series_output(&args.file)?;
    let n = out.input.len();
    let series = Series::uniform(n);
    let mut problems = Vec::new();
    if let Some(orig) = &args.input {
        let data = read_series(orig, &args.csv)?;
        if data.values.len() != n {
            problems.push(format!(
                "{} has {} samples, {} has {n}",
                orig.display(),
                data.values.len(),
                args.file.display()
            ));
        } else if let Some(i) = (0..n).find(|&i| data.values[i].to_bits() != out.input[i].to_bits()) {
            problems.push(format!(
                "input column differs from {} at sample {i}: {} vs {}",
                orig.display(),
                out.input[i],
                data.values[i]
            ));
        }
    }
    // roles a series output can carry: free ends only at the two ends, no fixed regions, at
    // least one kept minimum and one kept maximum
    if let Some(i) = (1..n.saturating_sub(1)).find(|&i| out.roles[i] == Role::End) {
        problems.push(format!("sample {i} is marked `end` but is not an end of the series"));
    }
    if let Some(i) = out.roles.iter().position(|&r| r == Role::Fixed) {
        problems.push(format!("sample {i} is marked `fixed`: series outputs keep extrema, not regions"));
    }
    if !out.roles.contains(&Role::Min) || !out.roles.contains(&Role::Max) {
        problems.push("the role column keeps no minimum or no maximum".into());
    }
    let cert = certify(&series, &out.output, &out.roles, Some(&out.input));
    if !cert.passed {
        problems.push(format!("output: {}", cert.summary()));
    }
    let ucert = certify(&series, &out.u, &out.roles, None);
    if !ucert.passed {
        problems.push(format!("representative u: {}", ucert.summary()));
    }
    if !problems.is_empty() {
        return Err(Error::Uncertified { path: Some(args.file.clone()), message: problems.join("; ") });
    }
    let kept = out.roles.iter().filter(|r| r.is_fixed()).count();
    Ok(format!(
        "{}: {} ({n} samples, {kept} kept extrema at their input values, u consistent{})\n",
        args.file.display(),
        cert.summary(),
        if args.input.is_some() { ", input column matches" } else { "" }
    ))
}
