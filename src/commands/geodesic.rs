//! `toposmooth geodesic`: geodesic distance from source vertices by the heat method.

use super::check_distinct;
use crate::apps::geodesic::{heat_geodesic, GeodesicSeconds};
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::io::export::stage_mesh;
use crate::io::import::read_trimesh;
use std::path::PathBuf;
use std::time::Instant;

/// Options of `geodesic`.
#[derive(Clone, Debug)]
pub struct GeodesicArgs {
    /// The mesh.
    pub input: PathBuf,
    /// Source vertices.
    pub sources: Vec<usize>,
    /// Output mesh (.vtu, .vtp, .ply) with the point array `distance`.
    pub output: PathBuf,
    /// JSON report.
    pub report: Option<PathBuf>,
}

#[derive(serde::Serialize)]
struct GeodesicReport {
    input_file: String,
    output_file: String,
    vertices: usize,
    triangles: usize,
    sources: Vec<usize>,
    max_distance: f64,
    farthest_vertex: usize,
    read_seconds: f64,
    seconds: GeodesicSeconds,
    write_seconds: f64,
    total_seconds: f64,
}

/// Runs `geodesic`; returns the summary printed on standard output.
pub fn geodesic(args: &GeodesicArgs) -> Result<String> {
    check_distinct(&[args.input.as_path()], &[("-o", Some(&args.output)), ("--report", args.report.as_deref())])?;
    let ext = args.output.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if !["vtu", "vtp", "ply"].contains(&ext.as_str()) {
        return Err(Error::Usage(format!("{}: write the distance as .vtu, .vtp or .ply", args.output.display())));
    }
    let start = Instant::now();
    let (mesh, _) = read_trimesh(&args.input)?;
    let read_seconds = start.elapsed().as_secs_f64();
    let (distance, seconds) = heat_geodesic(&mesh, &args.sources).map_err(|e| e.in_file(&args.input))?;
    let t = Instant::now();
    let (farthest, max) =
        distance.iter().enumerate().fold((0, f64::NEG_INFINITY), |a, (i, &d)| if d > a.1 { (i, d) } else { a });
    let mut staged = vec![stage_mesh(&args.output, &mesh, &[("distance", &distance)])?];
    let write_seconds = t.elapsed().as_secs_f64();
    if let Some(path) = &args.report {
        let report = GeodesicReport {
            input_file: args.input.display().to_string(),
            output_file: args.output.display().to_string(),
            vertices: mesh.n_vertices(),
            triangles: mesh.faces().len(),
            sources: args.sources.clone(),
            max_distance: max,
            farthest_vertex: farthest,
            read_seconds,
            seconds,
            write_seconds,
            total_seconds: start.elapsed().as_secs_f64(),
        };
        staged.push(super::stage_report(path, &report)?);
    }
    crate::io::commit_all(staged)?;
    let warning = mesh.sliver_warning().map(|w| format!("warning: {w}\n")).unwrap_or_default();
    Ok(format!(
        "{warning}{}: heat-method geodesic distance on a mesh of {} from {} source{} (vertex {}); largest {} at vertex {farthest}\n\
         heat time t = {} × (mean edge length)²\n\
         seconds: read {read_seconds:.3}, setup {:.3}, heat {:.3}, field {:.3}, poisson {:.3}, write {write_seconds:.3}, total {:.3}\n\
         wrote {}\n",
        args.input.display(),
        mesh.describe(),
        args.sources.len(),
        if args.sources.len() == 1 { "" } else { "s" },
        args.sources.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", "),
        super::sig6(max),
        seconds.time_scale,
        seconds.setup,
        seconds.heat,
        seconds.field,
        seconds.poisson,
        start.elapsed().as_secs_f64(),
        args.output.display()
    ))
}
