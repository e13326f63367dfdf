//! `toposmooth smooth`: the whole pipeline on a file, with output, plot and report.

use super::input::{read_field, FieldInput};
use super::smooth_args::{fit_and_solver_lines, SmoothArgs};
use super::{check_distinct, check_png_name, sig6, stage_plot, x_axis};
use crate::domain::Series;
use crate::error::{Error, Result};
use crate::io::series_csv::{stage_series_output, SeriesCsv, SeriesOutput};
use crate::io::stage_json;
use crate::pipeline::{smooth as run_pipeline, Report};
use crate::plot::{plot_series, Marker};
use crate::topology::Role;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(serde::Serialize)]
struct RunReport<'a> {
    input_file: String,
    column: &'a str,
    output_file: String,
    read_seconds: f64,
    write_seconds: f64,
    total_seconds: f64,
    #[serde(flatten)]
    report: &'a Report,
}

/// Runs `smooth`; returns the summary printed on standard output.
pub fn smooth(args: &SmoothArgs) -> Result<String> {
    check_png_name(args.plot.as_deref())?;
    let input_path = args.input.clone().or_else(|| args.grid.uv.as_ref().map(|(u, _)| u.clone())).unwrap_or_default();
    let mut inputs: Vec<&Path> = args.input.iter().map(PathBuf::as_path).collect();
    if let Some((u, v)) = &args.grid.uv {
        inputs.extend([u.as_path(), v.as_path()]);
    }
    if let Some(values) = &args.grid.values {
        inputs.push(values.as_path());
    }
    check_distinct(
        &inputs,
        &[
            ("-o", Some(&args.output)),
            ("--plot", args.plot.as_deref()),
            ("--report", args.report.as_deref()),
            ("--complex", args.complex.as_deref()),
        ],
    )?;
    let start = Instant::now();
    let field = read_field(args.input.as_deref(), args.kind, &args.csv, &args.grid)?;
    match field {
        FieldInput::Series(data) => {
            if args.complex.is_some() {
                return Err(Error::Usage("--complex is for grids (a series has no separatrices)".into()));
            }
            check_output_extension(&args.output, &["csv"], "a series")?;
            smooth_series(args, &input_path, data, start)
        }
        FieldInput::Grid(data) => {
            check_output_extension(&args.output, &["vti", "npz", "npy", "csv"], "a grid")?;
            if let Some(c) = &args.complex {
                check_output_extension(c, &["vtp"], "--complex")?;
            }
            super::smooth_grid::smooth_grid(args, data, start)
        }
        FieldInput::Mesh(data) => {
            check_output_extension(&args.output, &["vtu", "vtp", "ply"], "a mesh")?;
            if let Some(c) = &args.complex {
                check_output_extension(c, &["vtp"], "--complex")?;
            }
            super::smooth_mesh::smooth_mesh(args, data, start)
        }
    }
}

fn check_output_extension(path: &Path, allowed: &[&str], what: &str) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if allowed.contains(&ext.as_str()) {
        Ok(())
    } else {
        Err(Error::Usage(format!(
            "{}: the output of {what} is written as {}",
            path.display(),
            allowed.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(", ")
        )))
    }
}

fn smooth_series(args: &SmoothArgs, input: &Path, data: SeriesCsv, start: Instant) -> Result<String> {
    let series = Series::with_coordinates(data.x.clone()).map_err(|e| e.in_file(input))?;
    let read_seconds = start.elapsed().as_secs_f64();
    let result = run_pipeline(&series, &data.values, &args.settings).map_err(|e| e.in_file(input))?;
    let t = Instant::now();
    let out = SeriesOutput {
        x_text: data.x_text.clone(),
        input: data.values.clone(),
        output: result.output.clone(),
        u: result.u.clone(),
        roles: result.roles.clone(),
    };
    // every output is staged first and committed together at the end
    let mut staged = vec![stage_series_output(&args.output, &out)?];
    if let Some(path) = &args.plot {
        let (axis, x) = x_axis(&data.x_source, &data.x);
        let markers: Vec<Marker> = result
            .roles
            .iter()
            .enumerate()
            .filter_map(|(i, r)| match r {
                Role::Min => Some(Marker { index: i, is_max: false }),
                Role::Max => Some(Marker { index: i, is_max: true }),
                _ => None,
            })
            .collect();
        let r = &result.report;
        let title = format!(
            "{} — {}: {} of {} extrema kept, certified (RMS change {:.3e})",
            input.file_name().unwrap_or_default().to_string_lossy(),
            data.column,
            r.kept.len(),
            r.input_minima + r.input_maxima,
            r.rms_deviation
        );
        staged.push(stage_plot(path, |p| {
            plot_series(p, &x, &axis, &data.column, &data.values, &result.output, &markers, &title, (1400, 700))
        })?);
    }
    let write_seconds = t.elapsed().as_secs_f64();
    let r = &result.report;
    if let Some(path) = &args.report {
        let run = RunReport {
            input_file: input.display().to_string(),
            column: &data.column,
            output_file: args.output.display().to_string(),
            read_seconds,
            write_seconds,
            total_seconds: start.elapsed().as_secs_f64(),
            report: r,
        };
        staged.push(stage_json(path, &run)?);
    }
    for s in staged {
        s.commit()?;
    }
    let s = &r.seconds;
    let mut text = String::new();
    for w in &r.warnings {
        text += &format!("warning: {w}\n");
    }
    let kmin = r.kept.iter().filter(|k| k.role == Role::Min).count();
    text += &format!(
        "{}: {} samples of `{}`, {} minima and {} maxima in the input (SoS, ends included)\n",
        input.display(),
        r.vertices,
        data.column,
        r.input_minima,
        r.input_maxima
    );
    text += &format!(
        "kept {} minima and {} maxima{}\n",
        kmin,
        r.kept.len() - kmin,
        r.settings.threshold.map(|t| format!(" (persistence ≥ {})", sig6(t))).unwrap_or_default()
    );
    text += &fit_and_solver_lines(r);
    text += &format!(
        "seconds: read {:.3}, persistence {:.3}, representative {:.3}, operators {:.3}, constraints {:.3}, solve {:.3}, repair {:.3}, verify {:.3}, write {:.3}, total {:.3}\n",
        read_seconds, s.persistence, s.representative, s.operators, s.constraints, s.solve, s.repair, s.verify, write_seconds,
        start.elapsed().as_secs_f64()
    );
    text += &format!("wrote {}", args.output.display());
    if let Some(p) = &args.plot {
        text += &format!(", {}", p.display());
    }
    if let Some(p) = &args.report {
        text += &format!(", {}", p.display());
    }
    text.push('\n');
    Ok(text)
}
