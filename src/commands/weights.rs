//! `toposmooth weights MESH --handles handles.json -o weights.vtu`: one weight function per
//! handle, certified (monotone), normalised, written with u and roles; `--compare` adds the
//! spurious-extremum counts of the other three methods.

use super::sig6;
use crate::apps::handles::{parse_handles, resolve, HandleFile};
use crate::apps::weights::{weights as compute, WeightMethod, WeightSettings, Weights};
use crate::domain::{Domain, TriMesh};
use crate::error::{Error, Result};
use crate::io::import::read_trimesh;
use crate::io::Staged;
use crate::plot::{plot_mesh_fields, GridMarker, GridPanel, MeshView};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of `weights`.
#[derive(Clone, Debug)]
pub struct WeightsArgs {
    /// The mesh.
    pub input: PathBuf,
    /// handles.json.
    pub handles: PathBuf,
    /// Output .vtu, .vtp or .ply.
    pub output: PathBuf,
    /// Order, method, solver, threads.
    pub settings: WeightSettings,
    /// Also run the other three methods and count their spurious extrema.
    pub compare: bool,
    /// Picture of the weights.
    pub plot: Option<PathBuf>,
    /// Camera of the picture.
    pub view: MeshView,
    /// Report JSON.
    pub report: Option<PathBuf>,
    /// Cages: where the certified functions on the cage's triangulation go.
    pub cage_output: Option<PathBuf>,
    /// Cages: largest triangle area of the cage's triangulation (default: the shape's mean).
    pub cage_max_area: Option<f64>,
}

#[derive(serde::Serialize)]
struct FunctionReport<'a> {
    name: &'a str,
    handle_vertices: usize,
    #[serde(flatten)]
    function: &'a crate::apps::weights::WeightFunction,
}

#[derive(serde::Serialize)]
struct MethodSummary {
    method: WeightMethod,
    spurious_exact: Vec<usize>,
    spurious_tolerance_1e9: Vec<usize>,
    certified: Vec<bool>,
    below_zero: usize,
    above_one: usize,
    seconds_per_function: f64,
}

#[derive(serde::Serialize)]
struct WeightsReport<'a> {
    input_file: String,
    handles_file: String,
    vertices: usize,
    triangles: usize,
    settings: &'a WeightSettings,
    functions: Vec<FunctionReport<'a>>,
    max_normalisation_change: f64,
    raw_sum_range: [f64; 2],
    operator_seconds: f64,
    function_seconds: f64,
    total_seconds: f64,
    comparison: Vec<MethodSummary>,
}

fn summary(method: WeightMethod, w: &Weights) -> MethodSummary {
    let count = |pred: &dyn Fn(f64) -> bool| -> usize {
        w.functions.iter().map(|f| f.raw.iter().filter(|&&x| pred(x)).count()).sum()
    };
    MethodSummary {
        method,
        spurious_exact: w.functions.iter().map(|f| f.spurious.exact).collect(),
        spurious_tolerance_1e9: w.functions.iter().map(|f| f.spurious.tolerance_1e9).collect(),
        certified: w.functions.iter().map(|f| f.certificate.passed).collect(),
        below_zero: count(&|x| x < 0.0),
        above_one: count(&|x| x > 1.0),
        seconds_per_function: w.functions.iter().map(|f| f.seconds).sum::<f64>() / w.functions.len() as f64,
    }
}

/// Role codes of one function (SPEC.md): a prescribed vertex that is a region on its own is a
/// kept maximum (value 1) or minimum (value 0); every other prescribed vertex is a fixed region
/// member (2), as are single vertices at other values (a cage's boundary).
pub fn weight_roles<D: crate::domain::Domain>(domain: &D, prescribed: &[Option<f64>]) -> Vec<f64> {
    let mut r: Vec<f64> = prescribed.iter().map(|p| if p.is_some() { 2.0 } else { 0.0 }).collect();
    for region in crate::verify::fixed_regions(domain, prescribed) {
        if let [v] = region[..] {
            match prescribed[v] {
                Some(1.0) => r[v] = 1.0,
                Some(0.0) => r[v] = -1.0,
                _ => {}
            }
        }
    }
    r
}

/// Stages a weights file: per handle `weight_<name>`, `weight_<name>_raw`, `u_<name>`,
/// `role_<name>` (SPEC.md formats).
pub fn stage_weights(path: &Path, mesh: &TriMesh, names: &[String], w: &Weights) -> Result<Staged> {
    let owned = weight_arrays(mesh, names, w);
    let arrays: Vec<(&str, &[f64])> = owned.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect();
    crate::io::export::stage_mesh(path, mesh, &arrays)
}

/// The arrays of a weights file per handle (SPEC.md formats): `weight_<name>` (normalised),
/// `weight_<name>_raw`, `u_<name>`, `role_<name>`.
pub fn weight_arrays(mesh: &TriMesh, names: &[String], w: &Weights) -> Vec<(String, Vec<f64>)> {
    let mut owned: Vec<(String, Vec<f64>)> = Vec::new();
    for (h, f) in w.functions.iter().enumerate() {
        let name = &names[h];
        owned.push((format!("weight_{name}"), w.normalised[h].clone()));
        owned.push((format!("weight_{name}_raw"), f.raw.clone()));
        owned.push((format!("u_{name}"), f.u.clone()));
        owned.push((format!("role_{name}"), weight_roles(mesh, &f.prescribed)));
    }
    owned
}

/// Runs `weights`.
pub fn weights(args: &WeightsArgs) -> Result<String> {
    let start = Instant::now();
    let cage_path = cage_output_path(args);
    super::check_distinct(
        &[args.input.as_path(), args.handles.as_path()],
        &[
            ("-o", Some(&args.output)),
            ("--plot", args.plot.as_deref()),
            ("--report", args.report.as_deref()),
            ("--cage-output", Some(&cage_path)),
        ],
    )?;
    crate::apps::cage::check_max_area(args.cage_max_area)?;
    crate::io::export::check_mesh_output(&args.output)?;
    if let Some(c) = &args.cage_output {
        crate::io::export::check_mesh_output(c)?;
    }
    let (mesh, _) = read_trimesh(&args.input)?;
    let text =
        std::fs::read_to_string(&args.handles).map_err(|source| Error::Io { path: args.handles.clone(), source })?;
    let file = parse_handles(&text).map_err(|e| e.in_file(&args.handles))?;
    let list = match file {
        HandleFile::Handles(list) => list,
        HandleFile::Cage(cage) => return run_cage(args, &mesh, &cage, start),
    };
    let sets = resolve(&mesh, &list).map_err(|e| e.in_file(&args.handles))?;
    let names: Vec<String> = list.iter().map(|h| h.name.clone()).collect();
    run_weights(args, &mesh, &names, &sets, start)
}

/// Where a cage's certified functions go: `--cage-output` or `<output>_cage.vtu`.
fn cage_output_path(args: &WeightsArgs) -> PathBuf {
    args.cage_output.clone().unwrap_or_else(|| {
        let stem = args.output.file_stem().unwrap_or_default().to_string_lossy().to_string();
        args.output.with_file_name(format!("{stem}_cage.vtu"))
    })
}

/// Cage weights: certified on the cage's triangulation (written to `--cage-output`, default
/// `<output>_cage.vtu`, verifiable), interpolated onto the shape (`weight_<j>` normalised,
/// `weight_<j>_interpolated` raw; reported, not certified).
fn run_cage(args: &WeightsArgs, shape: &TriMesh, cage: &[[f64; 2]], start: Instant) -> Result<String> {
    if args.compare {
        return Err(Error::Usage(
            "--compare is for handles; a cage's weights are compared on its own triangulation".into(),
        ));
    }
    if !shape.is_planar() {
        return Err(Error::input("a cage needs a planar shape (every vertex at z = 0)").in_file(&args.input));
    }
    let c = crate::apps::cage::cage_weights(shape, cage, args.cage_max_area, &args.settings)
        .map_err(|e| e.in_file(&args.handles))?;
    let names: Vec<String> = (0..cage.len()).map(|j| j.to_string()).collect();
    let cage_path = cage_output_path(args);
    let cage_mesh = &c.cage_mesh;
    let m = cage.len();
    let mut staged = vec![stage_weights(&cage_path, cage_mesh, &names, &c.weights)?];
    let mut owned: Vec<(String, Vec<f64>)> = Vec::new();
    for j in 0..m {
        owned.push((format!("weight_{j}"), c.normalised_on_shape[j].clone()));
        owned.push((format!("weight_{j}_interpolated"), c.raw_on_shape[j].clone()));
    }
    let arrays: Vec<(&str, &[f64])> = owned.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect();
    staged.push(crate::io::export::stage_mesh(&args.output, shape, &arrays)?);
    if let Some(path) = &args.plot {
        let shown = m.min(4);
        let panels: Vec<GridPanel> = (0..shown)
            .map(|j| GridPanel { title: format!("weight_{j} (cage vertex {j})"), values: &c.normalised_on_shape[j] })
            .collect();
        let title = format!("cage weights on {}, order {}", args.input.display(), args.settings.order);
        staged.push(super::stage_plot(path, |p| {
            plot_mesh_fields(
                p,
                shape.positions(),
                shape.faces(),
                &panels,
                &[],
                &title,
                MeshView { azimuth: 0.0, elevation: 90.0 },
                false,
            )?;
            Ok(())
        })?);
    }
    if let Some(path) = &args.report {
        #[derive(serde::Serialize)]
        struct CageReport<'a> {
            input_file: String,
            cage_file: String,
            cage_vertices: usize,
            cage_mesh_vertices: usize,
            cage_mesh_triangles: usize,
            settings: &'a WeightSettings,
            functions: &'a [crate::apps::weights::WeightFunction],
            max_normalisation_change: f64,
            linear_reproduction_error: f64,
            total_seconds: f64,
        }
        staged.push(super::stage_report(
            path,
            &CageReport {
                input_file: args.input.display().to_string(),
                cage_file: args.handles.display().to_string(),
                cage_vertices: m,
                cage_mesh_vertices: cage_mesh.n_vertices(),
                cage_mesh_triangles: cage_mesh.faces().len(),
                settings: &args.settings,
                functions: &c.weights.functions,
                max_normalisation_change: c.weights.max_normalisation_change,
                linear_reproduction_error: c.reproduction_error,
                total_seconds: start.elapsed().as_secs_f64(),
            },
        )?);
    }
    crate::io::commit_all(staged)?;
    let w = &c.weights;
    let certified = w.functions.iter().filter(|f| f.certificate.passed).count();
    let spurious: usize = w.functions.iter().map(|f| f.spurious.exact).sum();
    let mut text = format!(
        "{}: cage of {m} vertices around a shape of {}; cage interior triangulated: {}\n",
        args.handles.display(),
        shape.describe(),
        cage_mesh.describe()
    );
    text += &format!(
        "{certified} of {m} {} functions of order {} certified on the cage triangulation, {spurious} spurious extrema; largest normalisation change {}; linear reproduction error on the shape {}\n",
        format!("{:?}", args.settings.method).to_lowercase(),
        args.settings.order,
        sig6(w.max_normalisation_change),
        sig6(c.reproduction_error)
    );
    text += &format!("seconds: {}\n", sig6(start.elapsed().as_secs_f64()));
    text += &super::wrote_line([Some(&args.output), Some(&cage_path), args.plot.as_ref(), args.report.as_ref()]);
    Ok(text)
}

/// The weights of resolved handles on a mesh, written as `args` asks.
pub fn run_weights(
    args: &WeightsArgs,
    mesh: &TriMesh,
    names: &[String],
    sets: &[Vec<usize>],
    start: Instant,
) -> Result<String> {
    let w = compute(mesh, sets, &args.settings).map_err(|e| e.in_file(&args.input))?;
    let mut comparison = vec![summary(args.settings.method, &w)];
    let mut others: Vec<(WeightMethod, Weights)> = Vec::new();
    if args.compare {
        for method in
            [WeightMethod::Monotone, WeightMethod::Bounded, WeightMethod::Unconstrained, WeightMethod::Harmonic]
        {
            if method != args.settings.method {
                let o = compute(mesh, sets, &WeightSettings { method, ..args.settings.clone() })
                    .map_err(|e| e.in_file(&args.input))?;
                comparison.push(summary(method, &o));
                others.push((method, o));
            }
        }
    }
    let mut staged = vec![stage_weights(&args.output, mesh, names, &w)?];
    if let Some(path) = &args.plot {
        let markers: Vec<GridMarker> =
            sets.iter().flat_map(|s| s.iter().map(|&v| GridMarker { index: v, is_max: true })).collect();
        let (panels, title): (Vec<GridPanel>, String) = if others.is_empty() {
            let shown = names.len().min(4);
            (
                (0..shown)
                    .map(|h| GridPanel {
                        title: format!("weight_{} ({:?})", names[h], args.settings.method).to_lowercase(),
                        values: &w.normalised[h],
                    })
                    .collect(),
                format!(
                    "{} weights, order {}{}",
                    format!("{:?}", args.settings.method).to_lowercase(),
                    args.settings.order,
                    if names.len() > 4 { format!(" (first 4 of {} handles)", names.len()) } else { String::new() }
                ),
            )
        } else {
            let mut p = vec![GridPanel {
                title: format!("{:?}: {} spurious", args.settings.method, w.functions[0].spurious.exact).to_lowercase(),
                values: &w.functions[0].raw,
            }];
            for (m, o) in &others {
                p.push(GridPanel {
                    title: format!("{m:?}: {} spurious", o.functions[0].spurious.exact).to_lowercase(),
                    values: &o.functions[0].raw,
                });
            }
            (p, format!("raw weight of handle `{}`, order {}, by method", names[0], args.settings.order))
        };
        staged.push(super::stage_plot(path, |p| {
            plot_mesh_fields(p, mesh.positions(), mesh.faces(), &panels, &markers, &title, args.view, false)?;
            Ok(())
        })?);
    }
    if let Some(path) = &args.report {
        let report = WeightsReport {
            input_file: args.input.display().to_string(),
            handles_file: args.handles.display().to_string(),
            vertices: mesh.n_vertices(),
            triangles: mesh.faces().len(),
            settings: &args.settings,
            functions: w
                .functions
                .iter()
                .enumerate()
                .map(|(h, f)| FunctionReport { name: &names[h], handle_vertices: sets[h].len(), function: f })
                .collect(),
            max_normalisation_change: w.max_normalisation_change,
            raw_sum_range: w.raw_sum_range,
            operator_seconds: w.operator_seconds,
            function_seconds: w.function_seconds,
            total_seconds: start.elapsed().as_secs_f64(),
            comparison,
        };
        staged.push(super::stage_report(path, &report)?);
    }
    finish(args, mesh, names, sets, &w, &others, staged, start)
}

#[allow(clippy::too_many_arguments)]
fn finish(
    args: &WeightsArgs,
    mesh: &TriMesh,
    names: &[String],
    sets: &[Vec<usize>],
    w: &Weights,
    others: &[(WeightMethod, Weights)],
    staged: Vec<Staged>,
    start: Instant,
) -> Result<String> {
    crate::io::commit_all(staged)?;
    let method = format!("{:?}", args.settings.method).to_lowercase();
    let mut text = format!(
        "{}: {} handles on a mesh of {}; {method} weights of order {}\n",
        args.input.display(),
        names.len(),
        mesh.describe(),
        args.settings.order
    );
    for (h, f) in w.functions.iter().enumerate() {
        text += &format!(
            "  {:<14} {:>5} handle vertices, {:>5} filled: {}; {} spurious (exact), {} (1e-9); {} iterations{}, {} s\n",
            names[h],
            sets[h].len(),
            f.filled,
            if f.certificate.passed {
                "certified".to_string()
            } else {
                format!("NOT certified ({})", f.certificate.failure_count)
            },
            f.spurious.exact,
            f.spurious.tolerance_1e9,
            f.solver_iterations,
            f.gap_over_energy.map(|g| format!(" (gap {g:.1e} × the energy)")).unwrap_or_default(),
            sig6(f.seconds)
        );
    }
    text += &format!(
        "normalised to a partition of unity: raw sums in [{}, {}], largest change {}\n",
        sig6(w.raw_sum_range[0]),
        sig6(w.raw_sum_range[1]),
        sig6(w.max_normalisation_change)
    );
    for (m, o) in others {
        let exact: Vec<String> = o.functions.iter().map(|f| f.spurious.exact.to_string()).collect();
        let tol: Vec<String> = o.functions.iter().map(|f| f.spurious.tolerance_1e9.to_string()).collect();
        text += &format!(
            "compare {:<13} spurious extrema per function: exact [{}], 1e-9 [{}]; {} s per function\n",
            format!("{m:?}").to_lowercase(),
            exact.join(", "),
            tol.join(", "),
            sig6(o.functions.iter().map(|f| f.seconds).sum::<f64>() / o.functions.len() as f64)
        );
    }
    text += &format!(
        "seconds: operators {}, functions {} ({} threads), total {}\n",
        sig6(w.operator_seconds),
        sig6(w.function_seconds),
        args.settings.threads,
        sig6(start.elapsed().as_secs_f64())
    );
    text += &super::wrote_line([Some(&args.output), args.plot.as_ref(), args.report.as_ref()]);
    Ok(text)
}
