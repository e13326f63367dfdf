//! `toposmooth mesh`: a triangle mesh of the inside of a 2D outline (JSON, SVG or PNG mask),
//! by constrained Delaunay refinement with an area bound and an angle bound.

use super::{check_distinct, check_png_name, sig6, stage_plot};
use crate::apps::outline::{check_settings, read_outline, triangulate};
use crate::domain::triangle_area;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::io::export::stage_mesh;
use crate::io::mesh::{stage_obj, stage_off};
use crate::plot::plot_triangulation;
use std::path::PathBuf;
use std::time::Instant;

/// Options of `mesh`.
#[derive(Clone, Debug)]
pub struct MeshOutlineArgs {
    /// The outline: .json, .svg or .png (see [`read_outline`]).
    pub input: PathBuf,
    /// The mesh: .obj, .off, .ply, .vtu or .vtp.
    pub output: PathBuf,
    /// Largest triangle area (default: the outline's bounding-box area / 2000).
    pub max_area: Option<f64>,
    /// Smallest angle in degrees.
    pub min_angle: f64,
    /// PNG picture of the triangulation.
    pub plot: Option<PathBuf>,
}

/// Runs `mesh`; returns the summary printed on standard output.
pub fn mesh_outline(args: &MeshOutlineArgs) -> Result<String> {
    check_distinct(&[args.input.as_path()], &[("-o", Some(&args.output)), ("--plot", args.plot.as_deref())])?;
    let ext = args.output.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if !["obj", "off", "ply", "vtu", "vtp"].contains(&ext.as_str()) {
        return Err(Error::Usage(format!(
            "{}: write the mesh as .obj, .off, .ply, .vtu or .vtp",
            args.output.display()
        )));
    }
    check_png_name(args.plot.as_deref())?;
    check_settings(args.max_area, args.min_angle)?;
    let start = Instant::now();
    let outline = read_outline(&args.input)?;
    let read_seconds = start.elapsed().as_secs_f64();
    let t = Instant::now();
    let mesh = triangulate(&outline, args.max_area, args.min_angle).map_err(|e| e.in_file(&args.input))?;
    let mesh_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (positions, faces) = (mesh.positions(), mesh.faces());
    let mut staged = vec![match ext.as_str() {
        "obj" => stage_obj(&args.output, positions, faces)?,
        "off" => stage_off(&args.output, positions, faces)?,
        _ => stage_mesh(&args.output, &mesh, &[])?,
    }];
    let (tri, smallest) = mesh.smallest_angle();
    let areas: Vec<f64> =
        faces.iter().map(|t| triangle_area(positions[t[0]], positions[t[1]], positions[t[2]])).collect();
    let largest = areas.iter().cloned().fold(0.0, f64::max);
    let total: f64 = areas.iter().sum();
    if let Some(plot) = &args.plot {
        let title = format!(
            "{}: {} vertices, {} triangles, smallest angle {:.1}°",
            args.input.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
            mesh.n_vertices(),
            faces.len(),
            smallest
        );
        staged.push(stage_plot(plot, |tmp| plot_triangulation(tmp, positions, faces, &title))?);
    }
    let write_seconds = t.elapsed().as_secs_f64();
    crate::io::commit_all(staged)?;
    let holes = outline.loops.len() - 1;
    let sharp = if smallest < args.min_angle { " (below the limit: a corner of the outline is sharper)" } else { "" };
    let max_area = args.max_area.map(sig6).unwrap_or_else(|| {
        let (lo, hi) = outline.bounds();
        format!("{} (bounding box / 2000)", sig6((hi[0] - lo[0]) * (hi[1] - lo[1]) / 2000.0))
    });
    let plot_line = args.plot.as_ref().map(|p| format!("wrote {}\n", p.display())).unwrap_or_default();
    Ok(format!(
        "{}: outline of {} corners in {} loop{} (the outer boundary{}), area {}\n\
         mesh: {}\n\
         triangle area ≤ {max_area}: largest {}, total {}\n\
         smallest angle {smallest:.2}° at triangle {tri} (limit {}°){sharp}\n\
         seconds: read {read_seconds:.3}, mesh {mesh_seconds:.3}, write {write_seconds:.3}, total {:.3}\n\
         wrote {}\n{plot_line}",
        args.input.display(),
        outline.n_points(),
        outline.loops.len(),
        if outline.loops.len() == 1 { "" } else { "s" },
        match holes {
            0 => String::new(),
            1 => " and 1 hole".into(),
            h => format!(" and {h} holes"),
        },
        sig6(outline.area()),
        mesh.describe(),
        sig6(largest),
        sig6(total),
        args.min_angle,
        start.elapsed().as_secs_f64(),
        args.output.display()
    ))
}
