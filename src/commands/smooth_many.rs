//! `toposmooth smooth A B … --out-dir DIR` and `toposmooth smooth series.pvd --out-dir DIR`:
//! every input smoothed as `smooth` does it, one output each under the input's file name (or
//! its stem with `--out-format`), and a ParaView collection of the outputs. Consecutive inputs
//! on the same domain (the time steps of one simulation) share its smoother: the operators and
//! analyses are built once, and every output is the one a run on that input alone writes.

use super::smooth::smooth_shared;
use super::smooth_args::SmoothArgs;
use super::{check_distinct, path_key, shown};
use crate::error::{Error, Result};
use crate::io::vtk::{read_pvd, stage_pvd, CollectionEntry};
use std::path::{Path, PathBuf};

/// The inputs, their time steps, and the collection's name (a `.pvd` input keeps its own).
fn expand(inputs: &[PathBuf]) -> Result<(Vec<CollectionEntry>, String)> {
    let is_pvd = |p: &Path| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("pvd"));
    match inputs {
        [one] if is_pvd(one) => {
            let name = one.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            Ok((read_pvd(one)?, name))
        }
        _ => {
            if let Some(p) = inputs.iter().find(|p| is_pvd(p)) {
                return Err(Error::Usage(format!("{}: a .pvd collection is the only input when given", p.display())));
            }
            let entries = inputs.iter().enumerate().map(|(k, p)| CollectionEntry { time: k as f64, file: p.clone() });
            Ok((entries.collect(), "collection.pvd".into()))
        }
    }
}

/// The output of `input` in `dir`: its file name, or its stem with the extension `format`.
fn output_of(input: &Path, dir: &Path, format: Option<&str>) -> Result<PathBuf> {
    let name = match format {
        None => input.file_name().map(PathBuf::from),
        // the stem's own dots stay (flow.0001.vti -> flow.0001.vtu)
        Some(ext) => input.file_stem().map(|s| {
            let mut name = s.to_os_string();
            name.push(".");
            name.push(ext.trim_start_matches('.'));
            PathBuf::from(name)
        }),
    };
    name.map(|n| dir.join(n)).ok_or_else(|| Error::Usage(format!("{}: not a file name", input.display())))
}

/// Runs `smooth` on every input into `dir`; returns the summary (one block per input, then
/// the files written).
///
/// # Errors
/// Usage errors before any work: an option that writes one file per run (`--plot`,
/// `--complex`, `--diagram`, `--report`, `-o`), a missing directory, two inputs with one
/// output name, an output that is an input. Then the first input that fails, named.
pub fn smooth_many(args: &SmoothArgs, inputs: &[PathBuf], dir: &Path, format: Option<&str>) -> Result<String> {
    let single = [
        ("--plot", args.plot.is_some()),
        ("--complex", args.complex.is_some()),
        ("--diagram", args.diagram.is_some()),
        ("--report", args.report.is_some()),
        ("--u/--v", args.read.uv.is_some()),
        ("--values", args.read.values.is_some()),
    ];
    if let Some((flag, _)) = single.iter().find(|(_, given)| *given) {
        return Err(Error::Usage(format!(
            "{flag} writes or reads one file per run: with --out-dir, smooth one input at a time to use it"
        )));
    }
    if inputs.iter().any(|p| p.as_os_str() == "-") {
        return Err(Error::Usage("the standard input (`-`) is one input: use -o with it, not --out-dir".into()));
    }
    if !dir.is_dir() {
        return Err(Error::Usage(format!("--out-dir {}: the directory does not exist", dir.display())));
    }
    let (entries, pvd_name) = expand(inputs)?;
    let outputs: Vec<PathBuf> = entries.iter().map(|e| output_of(&e.file, dir, format)).collect::<Result<_>>()?;
    let keys: Vec<PathBuf> = outputs.iter().map(|o| path_key(o)).collect();
    for (j, k) in keys.iter().enumerate() {
        if let Some(i) = keys[..j].iter().position(|other| other == k) {
            return Err(Error::Usage(format!(
                "{} and {} would both be written to {}",
                entries[i].file.display(),
                entries[j].file.display(),
                outputs[j].display()
            )));
        }
    }
    let vtk = outputs.iter().all(|o| {
        let ext = o.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        matches!(ext.as_str(), "vti" | "vtu" | "vtp" | "vtk")
    });
    let pvd = dir.join(&pvd_name);
    // every output against every input, and the collection, before any work
    let mut ins: Vec<&Path> = entries.iter().map(|e| e.file.as_path()).collect();
    // a .pvd input is an input too: the new collection may not replace it
    ins.extend(inputs.iter().map(PathBuf::as_path));
    let input_keys: Vec<PathBuf> = ins.iter().map(|p| path_key(p)).collect();
    if let Some(j) = keys.iter().position(|k| input_keys.contains(k)) {
        return Err(Error::Usage(format!("the output {} is also an input", outputs[j].display())));
    }
    check_distinct(&ins, &[("the collection", vtk.then_some(pvd.as_path()))])?;

    let mut shared = None;
    let mut text = String::new();
    let n = entries.len();
    for (k, (entry, output)) in entries.iter().zip(&outputs).enumerate() {
        super::progress::line(&format!("input {} of {n}: {}", k + 1, entry.file.display()));
        let one = SmoothArgs { input: Some(entry.file.clone()), output: output.clone(), ..args.clone() };
        let summary = smooth_shared(&one, Some(&mut shared))?;
        text += &format!("[{} of {n}] {summary}", k + 1);
    }
    if vtk {
        let written: Vec<CollectionEntry> =
            entries.iter().zip(&outputs).map(|(e, o)| CollectionEntry { time: e.time, file: o.clone() }).collect();
        stage_pvd(&pvd, &written)?.commit()?;
        text += &format!("wrote {n} outputs to {} and the collection {}\n", shown(dir), shown(&pvd));
    } else {
        text += &format!("wrote {n} outputs to {}\n", shown(dir));
    }
    Ok(text)
}
