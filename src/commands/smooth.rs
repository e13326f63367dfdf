//! `toposmooth smooth`: the whole pipeline on a file of any domain, with the output, the
//! complex, the figure and the report.

use super::smooth_args::{fit_and_solver_lines, seconds_line, SmoothArgs};
use super::{check_distinct, check_png_name, sig6, stage_plot, x_axis};
use crate::domain::{AnyDomain, Domain};
use crate::error::{Error, Result};
use crate::io::export::{check_complex_output, check_output, check_written, stage_complex, stage_results, Results};
use crate::io::import::{read_field, Field};
use crate::io::Staged;
use crate::pipeline::{smooth_any, Report, Smoothed};
use crate::plot::{plot_grid_fields, plot_mesh_fields, plot_series, GridMarker, GridPanel, GridPlotOptions, Marker};
use crate::smoother::AnySmoother;
use crate::topology::Role;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What the report says about the domain, beside the pipeline's [`Report`].
#[derive(serde::Serialize)]
#[serde(untagged)]
enum DomainFacts<'a> {
    Series {
        column: &'a str,
    },
    Grid {
        columns: usize,
        rows: usize,
        spacing: [f64; 2],
        origin: [f64; 2],
    },
    Mesh {
        triangles: usize,
        components: usize,
        boundary_loops: usize,
        genus: Option<i64>,
        negative_cotangent_edges: usize,
        reading_notes: &'a [String],
    },
    Volume {
        dims: [usize; 3],
        spacing: [f64; 3],
        origin: [f64; 3],
    },
    Tets {
        tetrahedra: usize,
        components: usize,
        boundary_triangles: usize,
        euler_characteristic: i64,
        volume: f64,
        reading_notes: &'a [String],
    },
}

/// The JSON report of a run: the files, the domain, the seconds around the pipeline's.
#[derive(serde::Serialize)]
struct RunReport<'a> {
    input_file: String,
    field: &'a str,
    #[serde(flatten)]
    domain: DomainFacts<'a>,
    filled_missing: usize,
    /// The filled samples (vertex indices), when any were.
    filled_samples: Vec<usize>,
    output_file: String,
    read_seconds: f64,
    write_seconds: f64,
    total_seconds: f64,
    saddles: Option<usize>,
    separatrices: Option<usize>,
    #[serde(flatten)]
    report: &'a Report,
}

/// Runs `smooth`; returns the summary printed on standard output.
pub fn smooth(args: &SmoothArgs) -> Result<String> {
    smooth_shared(args, None)
}

/// The domain of the previous input of `smooth_many` and its smoother, reused when the next
/// input is on the same domain (the results are those of one-off runs).
pub(super) struct Shared {
    domain: AnyDomain,
    smoother: AnySmoother,
}

/// Whether two point sets hold the same coordinates bit for bit.
fn same_bits(a: &[[f64; 3]], b: &[[f64; 3]]) -> bool {
    a.len() == b.len() && a.iter().flatten().zip(b.iter().flatten()).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Whether two domains are the same: the same series coordinates, grid geometry or mesh.
fn same_domain(a: &AnyDomain, b: &AnyDomain) -> bool {
    match (a, b) {
        (AnyDomain::Series(a), AnyDomain::Series(b)) => a == b,
        (AnyDomain::Grid(a), AnyDomain::Grid(b)) => a == b,
        (AnyDomain::Volume(a), AnyDomain::Volume(b)) => a == b,
        (AnyDomain::Mesh(a), AnyDomain::Mesh(b)) => a.faces() == b.faces() && same_bits(a.positions(), b.positions()),
        (AnyDomain::Tets(a), AnyDomain::Tets(b)) => a.tets() == b.tets() && same_bits(a.positions(), b.positions()),
        _ => false,
    }
}

/// [`smooth`], reusing `shared`'s smoother when given (inputs of `smooth_many`).
pub(super) fn smooth_shared(args: &SmoothArgs, shared: Option<&mut Option<Shared>>) -> Result<String> {
    check_png_name(args.plot.as_deref())?;
    let input_path = args.input.clone().or_else(|| args.read.uv.as_ref().map(|(u, _)| u.clone())).unwrap_or_default();
    let mut inputs: Vec<&Path> = args.input.iter().map(PathBuf::as_path).collect();
    if let Some((u, v)) = &args.read.uv {
        inputs.extend([u.as_path(), v.as_path()]);
    }
    if let Some(values) = &args.read.values {
        inputs.push(values.as_path());
    }
    check_distinct(
        &inputs,
        &[
            ("-o", Some(&args.output)),
            ("--plot", args.plot.as_deref()),
            ("--report", args.report.as_deref()),
            ("--complex", args.complex.as_deref()),
            ("--diagram", args.diagram.as_deref()),
        ],
    )?;
    if let Some(d) = &args.diagram {
        crate::io::ttk::check_diagram_output(d)?;
    }
    // the pairs and critical points would be the whole grid's, background included
    if args.read.mask.is_some() {
        if let Some(flag) = [("--complex", args.complex.is_some()), ("--diagram", args.diagram.is_some())]
            .into_iter()
            .find_map(|(flag, given)| given.then_some(flag))
        {
            return Err(Error::Usage(format!(
                "{flag} is not written for a run inside a mask (--mask, --mask-below) yet: the diagram and the critical points would be the whole grid's"
            )));
        }
    }
    let start = Instant::now();
    let mut field = read_field(args.input.as_deref(), &args.read)?.into_field(&input_path)?;
    if let Some(c) = &args.complex {
        check_complex_output(c, &field.domain)?;
    }
    check_output(&args.output, &field.domain)?;
    check_output_array(args.output_array.as_deref())?;
    if matches!(field.domain, AnyDomain::Volume(_))
        && args.settings.representative == Some(crate::pipeline::RepresentativeChoice::Separatrix)
    {
        return Err(Error::Usage(format!(
            "{}: --representative separatrix is for series, grids and triangle meshes: on volumes use flooded or \
             harmonic (docs/volumes.md)",
            field.path.display()
        )));
    }
    if args.read.mask.is_some() && !matches!(field.domain, AnyDomain::Grid(_) | AnyDomain::Volume(_)) {
        return Err(Error::Usage(format!(
            "{}: --mask and --mask-below restrict grids and volumes; this input is {}",
            field.path.display(),
            field.domain.describe()
        )));
    }
    if args.isolines > 0 && !matches!(field.domain, AnyDomain::Grid(_)) {
        return Err(Error::setting("isolines", "draws on a grid's figure only; this input is not a grid"));
    }
    let read_seconds = start.elapsed().as_secs_f64();
    super::progress::line(&format!("read: {:.2} s ({})", read_seconds, read_line(&field)));
    let filled_samples: Vec<usize> =
        field.filled.as_ref().map(|m| (0..m.len()).filter(|&i| m[i]).collect()).unwrap_or_default();
    check_explicit_not_filled(&field, &args.settings.selection, &filled_samples)?;
    // a mask's domain: the volume's tetrahedra or the grid's triangles inside it
    enum Masked {
        Volume(crate::domain::MaskedVolume),
        Grid(crate::domain::MaskedGrid),
    }
    let masked = match (&field.mask, &field.domain) {
        (Some(inside), AnyDomain::Volume(g)) => {
            Some(Masked::Volume(crate::domain::MaskedVolume::new(g, inside).map_err(|e| e.in_file(&field.path))?))
        }
        (Some(inside), AnyDomain::Grid(g)) => {
            Some(Masked::Grid(crate::domain::MaskedGrid::new(g, inside).map_err(|e| e.in_file(&field.path))?))
        }
        _ => None,
    };
    if let Some(m) = &masked {
        let line = match m {
            Masked::Volume(m) => m.describe(),
            Masked::Grid(m) => m.describe(),
        };
        super::progress::line(&line);
        field.notes.push(line);
    }
    let result = match (shared, &masked) {
        (_, Some(Masked::Volume(m))) => crate::pipeline::smooth_masked(m, &field.values, &args.settings),
        (_, Some(Masked::Grid(m))) => crate::pipeline::smooth_masked_grid(m, &field.values, &args.settings),
        (None, None) => smooth_any(&field.domain, &field.values, &args.settings),
        (Some(slot), None) => {
            if !slot.as_ref().is_some_and(|s| same_domain(&s.domain, &field.domain)) {
                let smoother = AnySmoother::new(field.domain.clone(), args.settings.clone())
                    .map_err(|e| e.in_file(&field.path))?;
                *slot = Some(Shared { domain: field.domain.clone(), smoother });
            }
            slot.as_mut().expect("set above").smoother.smooth(&field.values)
        }
    }
    .map_err(|e| e.in_file(&field.path))?;
    if let (AnyDomain::Series(_), Some(&i)) =
        (&field.domain, filled_samples.iter().find(|&&i| matches!(result.roles[i], Role::Min | Role::Max)))
    {
        return Err(Error::Internal {
            path: Some(field.path.clone()),
            message: format!("the filled sample {i} came out a kept extremum (the fill should prevent it)"),
        });
    }

    let t = Instant::now();
    let write_stage = crate::progress::Stage::begin("write");
    // every output is staged first and committed together at the end
    let results = Results {
        input: &field.values,
        smoothed: &result.output,
        representative: &result.u,
        roles: &result.roles,
        filled: field.filled.as_deref(),
        carried: field.carried.as_ref(),
        output_array: args.output_array.as_deref(),
        mask: masked.as_ref().map(|m| match m {
            Masked::Volume(m) => m.used(),
            Masked::Grid(m) => m.used(),
        }),
    };
    let x_axis = field.axis.as_ref().map(|a| (a.x_name.as_str(), &a.x_text));
    let output = stage_results(&args.output, &field.domain, x_axis, &results)?;
    check_written(&output, &field.domain, &results).map_err(|e| e.in_file(&field.path))?;
    let mut staged = vec![output];
    // surfaces write the kept complex's separatrices (built here when the representative did
    // not need it); volumes only the critical points
    let built = match (&args.complex, &result.complex) {
        (Some(_), None) if field.domain.dimension() == 2 => Some(
            crate::pipeline::complex_of(&field.domain, &field.values, &args.settings.selection)
                .map_err(|e| e.in_file(&field.path))?,
        ),
        _ => None,
    };
    let complex = result.complex.as_ref().or(built.as_ref());
    if let Some(path) = &args.complex {
        staged.push(stage_complex(path, &field.domain, &field.values, &result.roles, complex)?);
    }
    if let Some(path) = &args.diagram {
        let pairs = crate::io::ttk::diagram_of(&field.domain, &field.values);
        staged.push(crate::io::ttk::stage_diagram(path, &field.domain, &pairs, &result.roles)?);
    }
    let mut hidden = 0;
    if let Some(path) = &args.plot {
        let (figure, h) = stage_figure(path, args, &field, &result)?;
        staged.push(figure);
        hidden = h;
    }
    let write_seconds = t.elapsed().as_secs_f64();
    let filled = filled_samples.len();
    let negative = match &field.domain {
        AnyDomain::Mesh(m) => crate::operators::negative_cotan_edges(m.positions(), m.faces()),
        _ => 0,
    };
    if let Some(path) = &args.report {
        let run = RunReport {
            input_file: field.path.display().to_string(),
            field: &field.description,
            domain: facts(&field, negative),
            filled_missing: filled,
            filled_samples,
            output_file: args.output.display().to_string(),
            read_seconds,
            write_seconds,
            total_seconds: start.elapsed().as_secs_f64(),
            saddles: complex.map(|c| c.saddles.len()),
            separatrices: complex.map(|c| c.descending.len() + c.ascending.len()),
            report: &result.report,
        };
        staged.push(super::stage_report(path, &run)?);
    }
    let files = staged.len();
    crate::io::commit_all(staged)?;
    write_stage.end(|| format!("{files} file{}", if files == 1 { "" } else { "s" }));

    Ok(summary(
        args,
        &field,
        &result,
        [filled, negative, hidden],
        [read_seconds, write_seconds, start.elapsed().as_secs_f64()],
    ))
}

/// `--output-array` may not take a name of the tool's own arrays, nor be empty.
fn check_output_array(name: Option<&str>) -> Result<()> {
    match name {
        Some(n) if n.is_empty() || n.chars().any(char::is_control) => {
            Err(Error::setting("output-array", "needs a printable, non-empty name"))
        }
        Some(n @ ("input" | "smoothed" | "representative" | "role" | "filled")) => Err(Error::setting(
            "output-array",
            format!(
                "`{n}` is one of the arrays the output always holds (input, smoothed, representative, role, filled)"
            ),
        )),
        _ => Ok(()),
    }
}

/// An explicit kept list (`--keep-min`, `--keep-max`) may not name a filled sample: its value
/// is not the input's.
fn check_explicit_not_filled(field: &Field, selection: &crate::topology::Selection, filled: &[usize]) -> Result<()> {
    let crate::topology::Selection::Explicit { minima, maxima } = selection else {
        return Ok(());
    };
    match minima.iter().chain(maxima).find(|i| filled.binary_search(i).is_ok()) {
        Some(&i) => Err(Error::input(format!(
            "{} was filled by --fill-missing: a kept extremum must be a sample the file gives",
            sample_name(field, i)
        ))
        .in_file(&field.path)),
        None => Ok(()),
    }
}

/// A sample or vertex for messages: a series' sample with its x as written.
fn sample_name(field: &Field, i: usize) -> String {
    match &field.axis {
        Some(a) => format!("sample {i} ({} = {})", a.x_name, a.x_text.get(i)),
        None => field.domain.describe_vertex(i),
    }
}

/// What `smooth` prints: warnings and notes, the input, the kept set, the certificate, fit and
/// solver, the seconds (`[read, write, total]`) and the files written; `counts`: samples
/// filled, interior edges of negative cotangent weight, kept extrema hidden from the camera.
fn summary(args: &SmoothArgs, field: &Field, result: &Smoothed, counts: [usize; 3], seconds: [f64; 3]) -> String {
    let [filled, negative, hidden] = counts;
    let [read_seconds, write_seconds, total_seconds] = seconds;
    let r = &result.report;
    let mut text = String::new();
    for w in &r.warnings {
        text += &format!("warning: {w}\n");
    }
    for n in &field.notes {
        text += &format!("note: {n}\n");
    }
    text += &input_line(field, r, filled, negative);
    let kmin = r.kept.iter().filter(|k| k.role == Role::Min).count();
    text += &format!(
        "kept {kmin} minima and {} maxima{}; representative: {}\n",
        r.kept.len() - kmin,
        r.settings.threshold.map(|t| format!(" (persistence ≥ {})", sig6(t))).unwrap_or_default(),
        r.representative
    );
    text += &fit_and_solver_lines(r);
    text += &seconds_line(&field.domain, read_seconds, &r.seconds, write_seconds, total_seconds);
    if hidden > 0 {
        text += &format!("plot: {hidden} kept extrema face away from the camera (try --view)\n");
    }
    let mut wrote = vec![super::shown(&args.output)];
    for p in [&args.complex, &args.diagram, &args.plot, &args.report].into_iter().flatten() {
        wrote.push(super::shown(p));
    }
    text += &format!("wrote {}\n", wrote.join(", "));
    text
}

fn facts(field: &Field, negative: usize) -> DomainFacts<'_> {
    match &field.domain {
        AnyDomain::Series(_) => DomainFacts::Series { column: &field.description },
        AnyDomain::Grid(g) => {
            DomainFacts::Grid { columns: g.nx(), rows: g.ny(), spacing: g.spacing(), origin: g.origin() }
        }
        AnyDomain::Mesh(m) => DomainFacts::Mesh {
            triangles: m.faces().len(),
            components: m.n_components(),
            boundary_loops: m.boundary_loops(),
            genus: m.is_orientable().then(|| m.genus()),
            negative_cotangent_edges: negative,
            reading_notes: &field.notes,
        },
        AnyDomain::Volume(g) => DomainFacts::Volume { dims: g.dims(), spacing: g.spacing(), origin: g.origin() },
        AnyDomain::Tets(m) => DomainFacts::Tets {
            tetrahedra: m.tets().len(),
            components: m.n_components(),
            boundary_triangles: m.boundary_faces().len(),
            euler_characteristic: m.euler_characteristic(),
            volume: m.volume(),
            reading_notes: &field.notes,
        },
    }
}

/// What was read, for the progress line printed before the work starts.
fn read_line(field: &Field) -> String {
    let path = field.path.display();
    match &field.domain {
        AnyDomain::Series(d) => format!("{path}: {} samples of `{}`", d.n_vertices(), field.description),
        AnyDomain::Grid(g) => {
            format!("{path}: grid {} × {} ({} vertices) of `{}`", g.nx(), g.ny(), g.n_vertices(), field.description)
        }
        AnyDomain::Mesh(m) => format!(
            "{path}: mesh of {} vertices and {} triangles, field `{}`",
            m.n_vertices(),
            m.faces().len(),
            field.description
        ),
        AnyDomain::Volume(g) => format!(
            "{path}: volume {} × {} × {} ({} vertices) of `{}`",
            g.nx(),
            g.ny(),
            g.nz(),
            g.n_vertices(),
            field.description
        ),
        AnyDomain::Tets(m) => format!(
            "{path}: tetrahedral mesh of {} vertices and {} tetrahedra, field `{}`",
            m.n_vertices(),
            m.tets().len(),
            field.description
        ),
    }
}

/// The summary's first line: the file, the field, the domain and the input's extrema.
fn input_line(field: &Field, r: &Report, filled: usize, negative: usize) -> String {
    let path = field.path.display();
    let extrema = format!("{} minima and {} maxima in the input", r.input_minima, r.input_maxima);
    match &field.domain {
        AnyDomain::Series(_) => {
            let filled_note = match field.filled.as_ref() {
                Some(mask) if filled > 0 => {
                    let which: Vec<String> =
                        (0..mask.len()).filter(|&i| mask[i]).take(5).map(|i| sample_name(field, i)).collect();
                    format!(
                        "; {filled} missing samples filled linearly in x ({}{}), none of them kept",
                        which.join(", "),
                        if filled > 5 { ", …" } else { "" }
                    )
                }
                _ => String::new(),
            };
            format!(
                "{path}: {} samples of `{}`, {extrema} (SoS, ends included){filled_note}\n",
                r.vertices, field.description
            )
        }
        AnyDomain::Grid(g) => format!(
            "{path}: {} of a {} × {} grid (spacing {}, {}){}; {extrema} (SoS, boundary included)\n",
            field.description,
            g.nx(),
            g.ny(),
            sig6(g.spacing()[0]),
            sig6(g.spacing()[1]),
            if filled > 0 { format!(", {filled} missing samples filled harmonically") } else { String::new() },
        ),
        AnyDomain::Mesh(m) => format!(
            "{}{path}: {} on a mesh of {} ({} interior edges with negative cotangent weight); {extrema} (SoS, boundary included)\n",
            if filled > 0 { format!("filled {filled} missing (NaN) values harmonically\n") } else { String::new() },
            field.description,
            m.describe(),
            negative,
        ),
        AnyDomain::Volume(g) => {
            let s = g.spacing();
            format!(
                "{path}: {} of a {} × {} × {} volume (spacing {}, {}, {}){}; {extrema} (SoS, boundary included)\n",
                field.description,
                g.nx(),
                g.ny(),
                g.nz(),
                sig6(s[0]),
                sig6(s[1]),
                sig6(s[2]),
                if filled > 0 { format!(", {filled} missing samples filled harmonically") } else { String::new() },
            )
        }
        AnyDomain::Tets(m) => format!(
            "{}{path}: {} on a tetrahedral mesh of {}; {extrema} (SoS, boundary included)\n",
            if filled > 0 { format!("filled {filled} missing (NaN) values harmonically\n") } else { String::new() },
            field.description,
            m.describe(),
        ),
    }
}

/// The kept extrema as plot markers.
fn kept_markers(roles: &[Role]) -> Vec<GridMarker> {
    roles
        .iter()
        .enumerate()
        .filter_map(|(i, r)| match r {
            Role::Min => Some(GridMarker { index: i, is_max: false }),
            Role::Max => Some(GridMarker { index: i, is_max: true }),
            _ => None,
        })
        .collect()
}

/// Stages the figure: the series over x, or input and output side by side as heat maps
/// (grids) or shaded views (meshes). Returns it with the number of kept extrema hidden from
/// the mesh camera.
fn stage_figure(path: &Path, args: &SmoothArgs, field: &Field, result: &Smoothed) -> Result<(Staged, usize)> {
    let r = &result.report;
    let h = &field.values;
    let name = field.path.file_name().unwrap_or_default().to_string_lossy().to_string();
    let (lo, hi) = crate::domain::value_range(h);
    let kmin = r.kept.iter().filter(|k| k.role == Role::Min).count();
    let kmax = r.kept.len() - kmin;
    let panels = [
        GridPanel { title: format!("input: {} minima, {} maxima", r.input_minima, r.input_maxima), values: h },
        GridPanel { title: format!("smoothed: {kmin} minima, {kmax} maxima (certified)"), values: &result.output },
    ];
    let title = format!("{name} — {} (RMS change {})", field.description, sig6(r.rms_deviation));
    let mut hidden = 0;
    let staged = match &field.domain {
        AnyDomain::Series(_) => {
            let axis = field.axis.as_ref().ok_or_else(|| Error::Internal {
                path: Some(field.path.clone()),
                message: "a series without its x axis".into(),
            })?;
            let (x_axis, x) = x_axis(&axis.source, &axis.x);
            let markers: Vec<Marker> =
                kept_markers(&result.roles).into_iter().map(|m| Marker { index: m.index, is_max: m.is_max }).collect();
            let title = format!(
                "{name} — {}: {} of {} extrema kept, certified (RMS change {:.3e})",
                field.description,
                r.kept.len(),
                r.input_minima + r.input_maxima,
                r.rms_deviation
            );
            stage_plot(path, |p| {
                plot_series(p, &x, &x_axis, &field.description, h, &result.output, &markers, &title, (1400, 700))
            })?
        }
        AnyDomain::Grid(g) => {
            let options = GridPlotOptions {
                isolines: args.isolines,
                diverging: lo < 0.0 && hi > 0.0,
                origin: g.origin(),
                spacing: g.spacing(),
                range: None,
                // an image in the x-z or y-z plane is drawn with the file's axes
                axes: g.plane().axes.map(|a| ["x", "y", "z"][a]),
            };
            let markers = kept_markers(&result.roles);
            stage_plot(path, |p| plot_grid_fields(p, g.nx(), g.ny(), &panels, &markers, &title, &options))?
        }
        AnyDomain::Mesh(_) | AnyDomain::Tets(_) => {
            // a tetrahedral mesh shows its boundary surface; kept extrema inside it are hidden
            let (positions, faces) = match &field.domain {
                AnyDomain::Tets(m) => (m.positions(), m.boundary_faces()),
                AnyDomain::Mesh(m) => (m.positions(), m.faces()),
                _ => unreachable!("matched above"),
            };
            let markers = kept_markers(&result.roles);
            stage_plot(path, |p| {
                hidden =
                    plot_mesh_fields(p, positions, faces, &panels, &markers, &title, args.view, lo < 0.0 && hi > 0.0)?;
                Ok(())
            })?
        }
        AnyDomain::Volume(g) => {
            let markers = kept_markers(&result.roles);
            let plot = crate::plot::VolumePlot {
                dims: g.dims(),
                spacing: g.spacing(),
                origin: g.origin(),
                panels: &panels,
                markers: &markers,
                title: &title,
                isolines: args.isolines,
                diverging: lo < 0.0 && hi > 0.0,
            };
            stage_plot(path, |p| crate::plot::plot_volume_slices(p, &plot))?
        }
    };
    Ok((staged, hidden))
}
