//! `toposmooth smooth` on a grid: run the pipeline, write .vti / .npz / .npy / CSV, the
//! complex as .vtp, the heat-map figure and the report.

use super::critical_output::{complex_polydata, kept_markers, role_codes};
use super::input::GridInput;
use super::smooth_args::{fit_and_solver_lines, surface_seconds_line, SmoothArgs};
use super::{sig6, stage_plot};
use crate::domain::Grid2d;
use crate::error::Result;
use crate::io::grid::stage_grid_csv;
use crate::io::npz::{stage_npy, stage_npz};
use crate::io::vtk::{stage_vti, stage_vtp};
use crate::io::{stage_json, Staged};
use crate::pipeline::{smooth as run_pipeline, Report, Smoothed};
use crate::plot::{plot_grid_fields, GridPanel, GridPlotOptions};
use crate::topology::Role;
use std::path::Path;
use std::time::Instant;

#[derive(serde::Serialize)]
struct GridRunReport<'a> {
    input_file: String,
    field: &'a str,
    columns: usize,
    rows: usize,
    spacing: [f64; 2],
    origin: [f64; 2],
    filled_missing: usize,
    output_file: String,
    read_seconds: f64,
    write_seconds: f64,
    total_seconds: f64,
    saddles: Option<usize>,
    separatrices: Option<usize>,
    #[serde(flatten)]
    report: &'a Report,
}

/// Physical position of a vertex: origin + (c·dx, r·dy) with the signed spacing, as VTK
/// places ImageData points.
fn physical(grid: &Grid2d, v: usize) -> [f64; 3] {
    let (r, c) = grid.row_col(v);
    let ([dx, dy], [ox, oy]) = (grid.spacing(), grid.origin());
    [ox + c as f64 * dx, oy + r as f64 * dy, 0.0]
}

fn stage_output(path: &Path, grid: &Grid2d, data: &GridInput, result: &Smoothed) -> Result<Staged> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let (nx, ny) = (grid.nx(), grid.ny());
    let roles = role_codes(&result.roles);
    let filled: Option<Vec<f64>> = data.filled.as_ref().map(|m| m.iter().map(|&b| f64::from(u8::from(b))).collect());
    let mut arrays: Vec<(&str, &[f64])> =
        vec![("input", &data.values), ("smoothed", &result.output), ("representative", &result.u), ("role", &roles)];
    if let Some(f) = &filled {
        arrays.push(("filled", f));
    }
    match ext.as_str() {
        "vti" => stage_vti(path, nx, ny, grid.spacing(), grid.origin(), &arrays),
        "npz" => stage_npz(path, ny, nx, &arrays),
        "npy" => stage_npy(path, ny, nx, &result.output),
        _ => stage_grid_csv(path, nx, &result.output),
    }
}

/// Runs the pipeline on a grid and writes everything asked for.
pub fn smooth_grid(args: &SmoothArgs, data: GridInput, start: Instant) -> Result<String> {
    let read_seconds = start.elapsed().as_secs_f64();
    let grid = &data.grid;
    let h = &data.values;
    let result = run_pipeline(grid, h, &args.settings).map_err(|e| e.in_file(&data.path))?;
    let t = Instant::now();
    let mut staged = vec![stage_output(&args.output, grid, &data, &result)?];
    if let Some(path) = &args.complex {
        let Some(ms) = &result.complex else {
            return Err(crate::Error::Internal {
                path: Some(data.path.clone()),
                message: format!("no Morse-Smale complex to write ({})", result.report.representative),
            });
        };
        staged.push(stage_vtp(path, &complex_polydata(&|v| physical(grid, v), h, &result.roles, ms))?);
    }
    let r = &result.report;
    let kmin = r.kept.iter().filter(|k| k.role == Role::Min).count();
    let kmax = r.kept.len() - kmin;
    if let Some(path) = &args.plot {
        let markers = kept_markers(&result.roles);
        let (lo, hi) = crate::domain::value_range(h);
        let options = GridPlotOptions {
            isolines: args.isolines,
            diverging: lo < 0.0 && hi > 0.0,
            aspect: (grid.spacing()[1] / grid.spacing()[0]).abs(),
        };
        let name = data.path.file_name().unwrap_or_default().to_string_lossy().to_string();
        let panels = [
            GridPanel { title: format!("input: {} minima, {} maxima", r.input_minima, r.input_maxima), values: h },
            GridPanel { title: format!("smoothed: {kmin} minima, {kmax} maxima (certified)"), values: &result.output },
        ];
        let title = format!("{name} — {} (RMS change {})", data.description, sig6(r.rms_deviation));
        staged.push(stage_plot(path, |p| {
            plot_grid_fields(p, grid.nx(), grid.ny(), &panels, &markers, &title, &options)
        })?);
    }
    let write_seconds = t.elapsed().as_secs_f64();
    let filled = data.filled.as_ref().map(|m| m.iter().filter(|&&b| b).count()).unwrap_or(0);
    if let Some(path) = &args.report {
        let run = GridRunReport {
            input_file: data.path.display().to_string(),
            field: &data.description,
            columns: grid.nx(),
            rows: grid.ny(),
            spacing: grid.spacing(),
            origin: grid.origin(),
            filled_missing: filled,
            output_file: args.output.display().to_string(),
            read_seconds,
            write_seconds,
            total_seconds: start.elapsed().as_secs_f64(),
            saddles: result.complex.as_ref().map(|c| c.saddles.len()),
            separatrices: result.complex.as_ref().map(|c| c.descending.len() + c.ascending.len()),
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
    text += &format!(
        "{}: {} of a {} × {} grid (spacing {}, {}){}; {} minima and {} maxima in the input (SoS, boundary included)\n",
        data.path.display(),
        data.description,
        grid.nx(),
        grid.ny(),
        sig6(grid.spacing()[0]),
        sig6(grid.spacing()[1]),
        if filled > 0 { format!(", {filled} missing samples filled harmonically") } else { String::new() },
        r.input_minima,
        r.input_maxima
    );
    text += &format!(
        "kept {kmin} minima and {kmax} maxima{}; representative: {}\n",
        r.settings.threshold.map(|t| format!(" (persistence ≥ {})", sig6(t))).unwrap_or_default(),
        r.representative
    );
    text += &fit_and_solver_lines(r);
    text += &surface_seconds_line(read_seconds, s, write_seconds, start.elapsed().as_secs_f64());
    let mut wrote = vec![args.output.display().to_string()];
    for p in [&args.complex, &args.plot, &args.report].into_iter().flatten() {
        wrote.push(p.display().to_string());
    }
    text += &format!("wrote {}\n", wrote.join(", "));
    Ok(text)
}
