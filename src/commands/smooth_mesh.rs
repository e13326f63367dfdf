//! `toposmooth smooth` on a triangle mesh: run the pipeline, write .vtu / .vtp / .ply, the
//! complex as .vtp, and the report.

use super::critical_output::{complex_polydata, kept_markers, role_codes};
use super::input::MeshInput;
use super::sig6;
use super::smooth_args::{fit_and_solver_lines, surface_seconds_line, SmoothArgs};
use crate::domain::{Domain, TriMesh};
use crate::error::{Error, Result};
use crate::io::mesh::stage_ply;
use crate::io::vtk::{stage_vtp, stage_vtu, PolyData};
use crate::io::{stage_json, Staged};
use crate::pipeline::{smooth as run_pipeline, Report, Smoothed};
use crate::plot::{plot_mesh_fields, GridPanel};
use crate::topology::Role;
use std::path::Path;
use std::time::Instant;

#[derive(serde::Serialize)]
struct MeshRunReport<'a> {
    input_file: String,
    field: &'a str,
    vertices: usize,
    triangles: usize,
    components: usize,
    boundary_loops: usize,
    genus: Option<i64>,
    negative_cotangent_edges: usize,
    reading_notes: &'a [String],
    output_file: String,
    read_seconds: f64,
    write_seconds: f64,
    total_seconds: f64,
    saddles: Option<usize>,
    separatrices: Option<usize>,
    #[serde(flatten)]
    report: &'a Report,
}

/// Checks before any work that `path` names a mesh output format (`.vtu`, `.vtp`, `.ply`).
///
/// # Errors
/// [`Error::Usage`] naming the path.
pub fn check_mesh_output(path: &Path) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if ["vtu", "vtp", "ply"].contains(&ext.as_str()) {
        Ok(())
    } else {
        Err(Error::Usage(format!("{}: a mesh output is written as .vtu, .vtp or .ply", path.display())))
    }
}

/// Stages the mesh output (`.vtu`, `.vtp` or `.ply`) with the arrays `input`, `smoothed`,
/// `representative`, `role` (SPEC.md formats).
pub fn stage_mesh_output(path: &Path, mesh: &TriMesh, arrays: &[(&str, &[f64])]) -> Result<Staged> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "vtu" => stage_vtu(path, mesh.positions(), mesh.faces(), arrays),
        "vtp" => stage_vtp(
            path,
            &PolyData {
                points: mesh.positions().to_vec(),
                polys: mesh.faces().to_vec(),
                point_arrays: arrays.iter().map(|(n, v)| (n.to_string(), v.to_vec())).collect(),
                ..Default::default()
            },
        ),
        "ply" => stage_ply(path, mesh.positions(), mesh.faces(), arrays),
        _ => Err(Error::Usage(format!("{}: a mesh output is written as .vtu, .vtp or .ply", path.display()))),
    }
}

fn stage_output(path: &Path, data: &MeshInput, result: &Smoothed) -> Result<Staged> {
    let roles = role_codes(&result.roles);
    let filled: Option<Vec<f64>> = data.filled.as_ref().map(|m| m.iter().map(|&b| f64::from(u8::from(b))).collect());
    let mut arrays: Vec<(&str, &[f64])> =
        vec![("input", &data.values), ("smoothed", &result.output), ("representative", &result.u), ("role", &roles)];
    if let Some(f) = &filled {
        arrays.push(("filled", f));
    }
    stage_mesh_output(path, &data.mesh, &arrays)
}

/// Runs the pipeline on a mesh field and writes everything asked for.
pub fn smooth_mesh(args: &SmoothArgs, data: MeshInput, start: Instant) -> Result<String> {
    let read_seconds = start.elapsed().as_secs_f64();
    let mesh = &data.mesh;
    let h = &data.values;
    let result = run_pipeline(mesh, h, &args.settings).map_err(|e| e.in_file(&data.path))?;
    let t = Instant::now();
    let mut staged = vec![stage_output(&args.output, &data, &result)?];
    if let Some(path) = &args.complex {
        let Some(ms) = &result.complex else {
            return Err(Error::Internal {
                path: Some(data.path.clone()),
                message: format!("no Morse-Smale complex to write ({})", result.report.representative),
            });
        };
        staged.push(stage_vtp(path, &complex_polydata(&|v| mesh.point(v), h, &result.roles, ms))?);
    }
    let r = &result.report;
    let kmin = r.kept.iter().filter(|k| k.role == Role::Min).count();
    let kmax = r.kept.len() - kmin;
    let mut hidden = 0;
    if let Some(path) = &args.plot {
        let markers = kept_markers(&result.roles);
        let (lo, hi) = crate::domain::value_range(h);
        let name = data.path.file_name().unwrap_or_default().to_string_lossy().to_string();
        let panels = [
            GridPanel { title: format!("input: {} minima, {} maxima", r.input_minima, r.input_maxima), values: h },
            GridPanel { title: format!("smoothed: {kmin} minima, {kmax} maxima (certified)"), values: &result.output },
        ];
        let title = format!("{name} — {} (RMS change {})", data.description, sig6(r.rms_deviation));
        staged.push(super::stage_plot(path, |p| {
            hidden = plot_mesh_fields(
                p,
                mesh.positions(),
                mesh.faces(),
                &panels,
                &markers,
                &title,
                args.view,
                lo < 0.0 && hi > 0.0,
            )?;
            Ok(())
        })?);
    }
    let write_seconds = t.elapsed().as_secs_f64();
    let negative = crate::operators::negative_cotan_edges(mesh.positions(), mesh.faces());
    if let Some(path) = &args.report {
        let run = MeshRunReport {
            input_file: data.path.display().to_string(),
            field: &data.description,
            vertices: mesh.n_vertices(),
            triangles: mesh.faces().len(),
            components: mesh.n_components(),
            boundary_loops: mesh.boundary_loops(),
            genus: mesh.is_orientable().then(|| mesh.genus()),
            negative_cotangent_edges: negative,
            reading_notes: &data.notes,
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
    for n in &data.notes {
        text += &format!("note: {n}\n");
    }
    if let Some(f) = &data.filled {
        text += &format!("filled {} missing (NaN) values harmonically\n", f.iter().filter(|&&b| b).count());
    }
    text += &format!(
        "{}: {} on a mesh of {} ({negative} interior edges with negative cotangent weight); {} minima and {} maxima in the input (SoS, boundary included)\n",
        data.path.display(),
        data.description,
        mesh.describe(),
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
    if args.plot.is_some() && hidden > 0 {
        text += &format!("plot: {hidden} kept extrema face away from the camera (try --view)\n");
    }
    for p in [&args.complex, &args.plot, &args.report].into_iter().flatten() {
        wrote.push(p.display().to_string());
    }
    text += &format!("wrote {}\n", wrote.join(", "));
    Ok(text)
}
