//! The command line: its arguments (clap) turned into the commands' arguments. The binary
//! (`src/main.rs`) calls [`main`]; the Python package runs a command in its own process with
//! [`run_args`].

use crate::apps::skinning::Skinning;
use crate::apps::weights::WeightMethod;
use crate::commands::settings_args::{SelectionArgs, SettingsArgs};
use crate::commands::{self, BenchArgs, ExtremaArgs, SmoothArgs, VerifyArgs};
use crate::constraints::EdgeSet;
use crate::io::import::{Derive, DomainKind, MaskRule, ReadOptions};
use crate::operators::Energy;
use crate::pipeline::RepresentativeChoice;
use crate::plot::MeshView;
use crate::solve::Method;
use crate::topology::Selection;
use crate::{Error, Result};
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// Smooth scalar fields keeping exactly the extrema you choose, with a certificate.
#[derive(Parser)]
#[command(name = "toposmooth", version, about, long_about = None)]
struct Cli {
    /// No progress on standard error (the stages, the input's summary); errors and warnings
    /// are still printed.
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the extrema with their persistence and strictness; draw the persistence diagram.
    Extrema {
        /// Input: a series (CSV), a grid (.vti, .vtk, .npy, CSV matrix, PNG, TIFF) or a mesh
        /// (.obj, .off, .ply, .vtu, .vtp, legacy .vtk polydata).
        #[arg(required_unless_present = "u")]
        input: Option<PathBuf>,
        #[command(flatten)]
        csv: CsvArgs,
        #[command(flatten)]
        grid: GridCli,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Persistence diagram PNG.
        #[arg(long, value_name = "PNG")]
        plot: Option<PathBuf>,
        /// Persistence diagram in TTK's layout (.vtu): one line cell per pair, threshold on
        /// `Persistence` in ParaView to select pairs.
        #[arg(long, value_name = "VTU")]
        diagram: Option<PathBuf>,
        /// Which extrema are marked kept (the rules of `smooth`).
        #[command(flatten)]
        selection: SelectionArgs,
    },
    /// Smooth a series keeping exactly the selected extrema; certify the output.
    Smooth(Box<SmoothCli>),
    /// Re-check an output file of `smooth` (or a weights file of `weights`/`diffuse`) from what it carries.
    Verify {
        /// Output file of `smooth`: series CSV (x,input,output,u,role), .vti, .npz, .vtu, .vtp
        /// or .ply.
        file: PathBuf,
        /// The original input: check the file's input array against it (read with the same
        /// options as for `smooth`).
        #[arg(long, value_name = "FILE")]
        input: Option<PathBuf>,
        #[command(flatten)]
        csv: CsvArgs,
        #[command(flatten)]
        grid: GridCli,
    },
    /// Geodesic distance on a triangle mesh from source vertices (heat method).
    Geodesic {
        /// Mesh: .obj, .off, .ply, .vtu, .vtp.
        input: PathBuf,
        /// Source vertex indices (0-based, comma-separated).
        #[arg(long, value_name = "V")]
        source: String,
        /// Output mesh with the point array `distance` (.vtu, .vtp, .ply).
        #[arg(short, long)]
        output: PathBuf,
        /// JSON report with per-stage seconds.
        #[arg(long, value_name = "JSON")]
        report: Option<PathBuf>,
    },
    /// Weight functions for handles on a mesh (no data): 1 on a handle, 0 on the others, no
    /// other extremum (monotone, certified), normalised to a partition of unity.
    Weights(Box<WeightsCli>),
    /// Pose a mesh with its weights: linear blend (lbs) or dual-quaternion (dqs) skinning.
    Deform {
        /// The rest mesh.
        input: PathBuf,
        /// Weights file written by `weights` (arrays weight_<name>).
        #[arg(long, value_name = "FILE")]
        weights: PathBuf,
        /// pose.json: {"transforms": {"name": [[a,b,c,tx],[d,e,f,ty],[g,h,i,tz]], ...}}.
        #[arg(long, value_name = "JSON")]
        transforms: PathBuf,
        /// Posed mesh: .obj, .off, .ply, .vtu, .vtp.
        #[arg(short, long)]
        output: PathBuf,
        /// Skinning method.
        #[arg(long, value_enum, default_value_t = Skinning::Lbs)]
        skinning: Skinning,
        /// Rest and posed shapes side by side.
        #[arg(long, value_name = "PNG")]
        plot: Option<PathBuf>,
        /// Camera of the picture: azimuth and elevation in degrees.
        #[arg(long, value_name = "AZ,EL")]
        view: Option<String>,
    },
    /// Colour diffusion from coloured points over an image's shape (alpha) or a mesh, with
    /// monotone weights: no pixel leaves the per-channel box of the given colours.
    Diffuse {
        /// An image (PNG, TIFF; alpha ≥ 128 is the shape) or a mesh (.obj, .off, .ply, .vtu, .vtp).
        input: PathBuf,
        /// colors.json: {"points": [{"pixel": [col, row], "rgb": [r, g, b]}, ...]} ("vertex" or
        /// "point" on meshes).
        #[arg(long, value_name = "JSON")]
        colors: PathBuf,
        /// Output: PNG for an image; .vtu, .vtp or .ply (arrays red, green, blue) for a mesh.
        #[arg(short, long)]
        output: PathBuf,
        /// Where an image's Float64 weights go (.vtu, .vtp, .ply); default <output>_weights.vtu.
        #[arg(long, value_name = "FILE")]
        weights: Option<PathBuf>,
        /// Polyharmonic order k.
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=4))]
        order: u8,
        /// Weights: monotone (convex blend, certified) or unconstrained etc. for comparison.
        #[arg(long, value_enum, default_value_t = WeightMethod::Monotone)]
        method: WeightMethod,
        /// Picture: the image enlarged with the colour points drawn, or the coloured mesh.
        #[arg(long, value_name = "PNG")]
        plot: Option<PathBuf>,
        /// Camera of a mesh picture: azimuth and elevation in degrees.
        #[arg(long, value_name = "AZ,EL")]
        view: Option<String>,
        /// JSON report.
        #[arg(long, value_name = "JSON")]
        report: Option<PathBuf>,
    },
    /// Triangulate the inside of a 2D outline (constrained Delaunay refinement): a polygon with
    /// holes from JSON, the shapes of an SVG, or the largest region of a PNG mask.
    Mesh {
        /// Outline: .json (`{"outline": [[x, y], ...], "holes": [[[x, y], ...], ...]}`), .svg
        /// (the visible filled shapes as drawn, CSS, units, <use> and transforms resolved: the
        /// first subpath is the outer boundary, later ones holes; user units, y negated) or .png (inside: alpha ≥ 50 %, or dark pixels without alpha;
        /// pixel-corner coordinates, y up).
        input: PathBuf,
        /// Output mesh: .obj, .off, .ply, .vtu or .vtp (z = 0).
        #[arg(short, long)]
        output: PathBuf,
        /// Largest triangle area [default: the outline's bounding-box area / 2000].
        #[arg(long, value_name = "A")]
        max_area: Option<f64>,
        /// Smallest angle in degrees (0 to 34; sharper corners of the outline itself stay).
        #[arg(long, value_name = "DEG", default_value_t = 25.0, allow_hyphen_values = true)]
        min_angle: f64,
        /// Picture of the triangulation (PNG).
        #[arg(long, value_name = "PNG")]
        plot: Option<PathBuf>,
    },
    /// Benchmark on random-walk series, noisy grids and meshes: seconds per stage and peak memory.
    Bench {
        /// Series lengths `N`, grid sizes `NXxNY` and volume sizes `NXxNYxNZ` (both keep 7 minima and
        /// 6 maxima) and mesh files
        /// `MESH[@levels]` (midpoint-subdivided; geodesic from vertex 0, every maximum kept).
        #[arg(long, value_delimiter = ',', default_value = "1000,10000,100000,1000000")]
        sizes: Vec<String>,
        /// Benchmark weight functions instead: mesh files `MESH[@levels]` (4 point handles by
        /// farthest-point sampling; orders from --weight-orders).
        #[arg(long, value_delimiter = ',', value_name = "MESH[@LEVELS]")]
        weights: Vec<String>,
        /// Orders for --weights.
        #[arg(long, value_delimiter = ',', default_value = "2,3,4")]
        weight_orders: Vec<u8>,
        /// Energy order or blend.
        #[arg(long, default_value = "2")]
        order: String,
        /// Persistence threshold (percent of the range).
        #[arg(long, default_value = "1%")]
        persistence: String,
        /// Constraint set.
        #[arg(long, value_enum, default_value_t = EdgeSet::Minimal)]
        edges: EdgeSet,
        /// RNG seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// QP solver.
        #[arg(long, value_enum, default_value_t = Method::Auto)]
        solver: Method,
        /// Representative function on grids and meshes (default: automatic).
        #[arg(long, value_enum)]
        representative: Option<RepresentativeChoice>,
        /// Fields per case through one `Smoother` (the case's field, then the same with a smooth
        /// wave of 1 % of its range added): one row each.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000))]
        fields: u32,
        /// Run one size in this process and print one JSON line.
        #[arg(long, hide = true)]
        single: Option<String>,
    },
}

#[derive(Args)]
struct GridCli {
    /// Read the input as a series, a grid or a mesh (default: by extension — .obj, .off, .ply,
    /// .vtu, .vtp are meshes; a CSV whose first line is three or more numbers is a grid matrix).
    #[arg(long, value_enum, default_value_t = DomainKind::Auto)]
    domain: DomainKind,
    /// Point array of a VTK file or PLY vertex property (default: the only scalar array, or
    /// with --derive the only vector array); on a mesh also `x`, `y` or `z`.
    #[arg(long, value_name = "NAME")]
    array: Option<String>,
    /// Grid spacing `dx,dy`, volume spacing `dx,dy,dz` (overrides the file's; may be negative,
    /// e.g. rows running down).
    #[arg(long, value_name = "DX,DY[,DZ]", allow_hyphen_values = true)]
    spacing: Option<String>,
    /// Grid: smooth a scalar derived from a velocity field (a 2- or 3-component array, or
    /// --u and --v).
    #[arg(long, value_enum)]
    derive: Option<Derive>,
    /// Grid: x velocity component file (with --v and --derive, instead of an input file).
    #[arg(long = "u", value_name = "FILE", requires_all = ["v", "derive"])]
    u: Option<PathBuf>,
    /// Grid: y velocity component file.
    #[arg(long = "v", value_name = "FILE", requires = "u")]
    v: Option<PathBuf>,
    /// Fill missing samples (NaN, empty CSV cells) instead of refusing them: harmonically on
    /// grids and meshes, linearly in x on series (ends: the nearest value); filled samples are
    /// never kept extrema, and the output marks them (`filled`).
    #[arg(long)]
    fill_missing: bool,
    /// Mesh: the field as one value per vertex and line of a text file (instead of --array;
    /// `--array x|y|z` takes a coordinate).
    #[arg(long, value_name = "FILE")]
    values: Option<PathBuf>,
    /// Volume or grid: smooth only the voxels where this point array of the input is non-zero
    /// (the domain is the tetrahedra, or triangles, whose corners are all inside; the rest is
    /// written unchanged, role 0, and the output's `mask` array says which voxels the domain
    /// holds).
    #[arg(long, value_name = "ARRAY", conflicts_with = "mask_below")]
    mask: Option<String>,
    /// Volume or grid: smooth only the voxels whose value is at least V (below V, and NaN,
    /// is outside), as --mask does.
    #[arg(long, value_name = "V", allow_negative_numbers = true)]
    mask_below: Option<f64>,
}

impl GridCli {
    /// The input options with `csv`'s columns.
    fn options(&self, csv: &CsvArgs) -> Result<ReadOptions> {
        let spacing = self.spacing.as_deref().map(crate::io::import::parse_spacing).transpose()?;
        Ok(ReadOptions {
            domain: self.domain,
            column: csv.column.clone(),
            x_column: csv.x_column.clone(),
            array: self.array.clone(),
            spacing,
            derive: self.derive,
            uv: self.u.clone().zip(self.v.clone()),
            fill_missing: self.fill_missing,
            values: self.values.clone(),
            mask: match (&self.mask, self.mask_below) {
                (Some(name), _) => Some(MaskRule::Array(name.clone())),
                (None, Some(v)) if v.is_finite() => Some(MaskRule::Below(v)),
                (None, Some(v)) => return Err(Error::setting("mask_below", format!("must be finite, got {v}"))),
                (None, None) => None,
            },
        })
    }
}

#[derive(Args)]
struct CsvArgs {
    /// Value column: header name or 0-based index (default: the last numeric column).
    #[arg(long)]
    column: Option<String>,
    /// x column: header name, index or `none` (default: the first column if it holds dates
    /// or is named x, t, time or date).
    #[arg(long = "x", value_name = "COLUMN")]
    x_column: Option<String>,
}

fn parse_view(view: Option<&str>) -> Result<MeshView> {
    match view {
        None => Ok(MeshView::default()),
        Some(text) => {
            let parts: Vec<f64> = text.split(',').filter_map(|p| p.trim().parse().ok()).collect();
            match parts.as_slice() {
                [az, el] if az.is_finite() && el.is_finite() => Ok(MeshView { azimuth: *az, elevation: *el }),
                _ => Err(Error::Usage(format!("--view `{text}` is not two angles AZ,EL in degrees"))),
            }
        }
    }
}

#[derive(Args)]
struct WeightsCli {
    /// Mesh: .obj, .off, .ply, .vtu, .vtp (a planar mesh for 2D shapes).
    input: PathBuf,
    /// handles.json: points, bones, vertex lists, or a 2D cage (SPEC.md formats).
    #[arg(long, value_name = "JSON")]
    handles: PathBuf,
    /// Output mesh (.vtu, .vtp, .ply) with weight_<name>, weight_<name>_raw, u_<name>, role_<name>.
    #[arg(short, long)]
    output: PathBuf,
    /// Polyharmonic order k.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=4))]
    order: u8,
    /// monotone: no spurious extremum (certified); bounded: BBW (0 ≤ w ≤ 1, partition of
    /// unity); unconstrained: plain polyharmonic; harmonic: Laplace.
    #[arg(long, value_enum, default_value_t = WeightMethod::Monotone)]
    method: WeightMethod,
    /// Also run the other three methods and report their spurious extrema.
    #[arg(long)]
    compare: bool,
    /// Constraint set of the monotone method.
    #[arg(long, value_enum, default_value_t = EdgeSet::Minimal)]
    edges: EdgeSet,
    /// Worker threads (the functions are independent).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u16).range(1..=256))]
    threads: u16,
    /// Picture: the normalised weights of up to 4 handles (with --compare: handle 0 by method).
    #[arg(long, value_name = "PNG")]
    plot: Option<PathBuf>,
    /// Camera of the picture: azimuth and elevation in degrees.
    #[arg(long, value_name = "AZ,EL")]
    view: Option<String>,
    /// JSON report: per function certificate, spurious extrema, iterations, seconds.
    #[arg(long, value_name = "JSON")]
    report: Option<PathBuf>,
    /// Cages: the certified functions on the cage's triangulation [default: <output>_cage.vtu].
    #[arg(long, value_name = "FILE")]
    cage_output: Option<PathBuf>,
    /// Cages: largest triangle area of the cage's triangulation [default: the shape's mean].
    #[arg(long, value_name = "A")]
    cage_max_area: Option<f64>,
}

#[derive(Args)]
struct SmoothCli {
    /// Input: a series (CSV), a grid (.vti, .vtk, .npy, CSV matrix, PNG, TIFF) or a mesh
    /// (.obj, .off, .ply, .vtu, .vtp, legacy .vtk polydata).
    /// Several inputs (or a ParaView collection, .pvd) are smoothed one by one into
    /// `--out-dir`, each under its own file name, with a .pvd of the outputs; inputs on one
    /// domain share its analysis.
    #[arg(required_unless_present = "u", num_args = 1.., value_name = "INPUT")]
    input: Vec<PathBuf>,
    /// Output: a series CSV (x,input,output,u,role); for grids .vti or .npz (verifiable:
    /// input, smoothed, representative, role) or .npy / CSV (the smoothed array only); for
    /// meshes .vtu, .vtp or .ply (verifiable, the same arrays). VTK outputs (.vti, .vtu, .vtp)
    /// also carry every point and cell array of a VTK input, and give the smoothed field the
    /// input array's name as the active scalars.
    #[arg(short, long, required_unless_present = "out_dir", conflicts_with = "out_dir")]
    output: Option<PathBuf>,
    /// Directory for the outputs of several inputs (one each, the input's file name, or its
    /// stem with `--out-format`), plus `collection.pvd` (or the input collection's name) when
    /// the outputs are VTK files.
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,
    /// With `--out-dir`: the outputs' extension (e.g. vti, vtu, npz), instead of the inputs'.
    #[arg(long, value_name = "EXT", requires = "out_dir")]
    out_format: Option<String>,
    /// The name of the smoothed field in VTK outputs, instead of the input array's (which is
    /// then carried through unchanged).
    #[arg(long, value_name = "NAME")]
    output_array: Option<String>,
    /// The input's persistence diagram in TTK's layout (.vtu), pairs marked `Kept`.
    #[arg(long, value_name = "VTU")]
    diagram: Option<PathBuf>,
    #[command(flatten)]
    csv: CsvArgs,
    #[command(flatten)]
    grid: GridCli,
    /// Critical points and, on grids and meshes, the kept separatrices as VTK PolyData (.vtp,
    /// TTK's layout; volumes with TTK's 3D codes).
    #[arg(long, value_name = "VTP")]
    complex: Option<PathBuf>,
    /// Mesh plot: camera azimuth and elevation in degrees (y up).
    #[arg(long, value_name = "AZ,EL", allow_hyphen_values = true)]
    view: Option<String>,
    /// Grid plot: number of isolines, 0 to 1000 (0: none; grids only).
    #[arg(long, default_value_t = 0, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=1000))]
    isolines: usize,
    /// The run's settings: the selection, the energy, the solver (the library's schema).
    #[command(flatten)]
    settings: SettingsArgs,
    /// Figure: series input (grey), output and kept extrema; grids as heat maps side by side.
    #[arg(long, value_name = "PNG")]
    plot: Option<PathBuf>,
    /// JSON report: settings, kept extrema, seconds per stage, energy, deviations, certificate.
    #[arg(long, value_name = "JSON")]
    report: Option<PathBuf>,
}

fn smooth_args(c: SmoothCli) -> Result<SmoothArgs> {
    let settings = c.settings.settings()?;
    Ok(SmoothArgs {
        input: c.input.first().cloned(),
        read: c.grid.options(&c.csv)?,
        complex: c.complex,
        isolines: c.isolines,
        view: parse_view(c.view.as_deref())?,
        output: c.output.unwrap_or_default(),
        settings,
        plot: c.plot,
        report: c.report,
        output_array: c.output_array,
        diagram: c.diagram,
    })
}

/// One input to `-o`, or several (a list or a `.pvd` collection) to `--out-dir`.
fn smooth_command(c: SmoothCli) -> Result<String> {
    let (inputs, out_dir, out_format) = (c.input.clone(), c.out_dir.clone(), c.out_format.clone());
    let collection = inputs.len() == 1 && inputs[0].extension().is_some_and(|e| e.eq_ignore_ascii_case("pvd"));
    let args = smooth_args(c)?;
    if out_format.is_some() && out_dir.is_none() {
        // clap's `requires` is not checked when -o, which conflicts with --out-dir, is given
        return Err(Error::Usage("--out-format names the outputs of --out-dir; with -o the name is -o's".into()));
    }
    match out_dir {
        Some(dir) => commands::smooth_many(&args, &inputs, &dir, out_format.as_deref()),
        None if inputs.len() > 1 || collection => Err(Error::Usage(format!(
            "{} inputs{}: write them with --out-dir DIR (one output each), not -o",
            inputs.len(),
            if collection { " (a .pvd collection)" } else { "" }
        ))),
        None => commands::smooth(&args),
    }
}

fn run(cli: Cli) -> Result<String> {
    match cli.command {
        Command::Extrema { input, csv, grid, json, plot, diagram, selection } => commands::extrema(&ExtremaArgs {
            input,
            read: grid.options(&csv)?,
            json,
            plot,
            diagram,
            selection: selection.selection()?,
        }),
        Command::Smooth(c) => smooth_command(*c),
        Command::Geodesic { input, source, output, report } => commands::geodesic(&commands::GeodesicArgs {
            input,
            sources: commands::parse_indices(&source)?,
            output,
            report,
        }),
        Command::Weights(c) => commands::weights(&commands::WeightsArgs {
            input: c.input,
            handles: c.handles,
            output: c.output,
            settings: crate::apps::weights::WeightSettings {
                order: c.order,
                method: c.method,
                edges: c.edges,
                threads: usize::from(c.threads),
                ..Default::default()
            },
            compare: c.compare,
            plot: c.plot,
            view: parse_view(c.view.as_deref())?,
            report: c.report,
            cage_output: c.cage_output,
            cage_max_area: c.cage_max_area,
        }),
        Command::Deform { input, weights, transforms, output, skinning, plot, view } => {
            commands::deform(&commands::DeformArgs {
                input,
                weights,
                transforms,
                output,
                skinning,
                plot,
                view: parse_view(view.as_deref())?,
            })
        }
        Command::Diffuse { input, colors, output, weights, order, method, plot, view, report } => {
            commands::diffuse(&commands::DiffuseArgs {
                input,
                colors,
                output,
                weights,
                settings: crate::apps::weights::WeightSettings { order, method, ..Default::default() },
                plot,
                report,
                view: parse_view(view.as_deref())?,
            })
        }
        Command::Mesh { input, output, max_area, min_angle, plot } => {
            commands::mesh_outline(&commands::MeshOutlineArgs { input, output, max_area, min_angle, plot })
        }
        Command::Verify { file, input, csv, grid } => {
            commands::verify(&VerifyArgs { file, input, read: grid.options(&csv)? })
        }
        Command::Bench { weights, weight_orders, .. } if !weights.is_empty() => {
            commands::bench_weights(&weights, &weight_orders, 4)
        }
        Command::Bench { sizes, order, persistence, edges, seed, single, solver, representative, fields, .. } => {
            let persistence = match commands::parse_persistence(&persistence)? {
                Selection::Relative(r) => r,
                _ => return Err(Error::Usage("bench takes --persistence as a percentage".into())),
            };
            commands::bench(&BenchArgs {
                cases: sizes.iter().map(|s| commands::BenchCase::parse(s)).collect::<Result<_>>()?,
                energy: Energy::parse(&order)?,
                persistence,
                edges,
                seed,
                single,
                method: solver,
                representative,
                fields: fields as usize,
            })
        }
    }
}

/// The tool's `main`: installs the panic hook and the interrupt handler, parses `args` (the
/// program's name first), runs the command with progress on standard error and returns the
/// exit status (SPEC.md), after printing the result or the error.
pub fn main(args: impl IntoIterator<Item = std::ffi::OsString>) -> i32 {
    commands::install_panic_hook();
    let interrupted = commands::install_interrupt_handler();
    let cli = Cli::parse_from(args);
    // a benchmark's table is its progress
    let quiet = cli.quiet || matches!(cli.command, Command::Bench { .. });
    let mode = commands::progress::ProgressMode::detect(quiet);
    commands::finish(commands::progress::with_progress(mode, || {
        crate::progress::cancellable(interrupted, || commands::catch_panics(|| run(cli)))
    }))
}

/// Runs one command in this process without progress, signal handlers or a panic hook (for
/// the Python package: its interpreter keeps its own), returning what the tool would print on
/// standard output. `args` are the arguments after the program's name.
///
/// # Errors
/// A usage error with clap's message for arguments it refuses (`--help` and `--version`
/// included: their text is the message), else the command's error.
pub fn run_args(args: &[String]) -> Result<String> {
    let argv = std::iter::once("toposmooth".to_string()).chain(args.iter().cloned());
    let cli = Cli::try_parse_from(argv).map_err(|e| Error::Usage(e.render().to_string().trim_end().to_string()))?;
    // a command that fails, panics or is cancelled before writing leaves no reserved temporary
    struct Discard;
    impl Drop for Discard {
        fn drop(&mut self) {
            crate::io::staging::discard_reserved();
        }
    }
    let _discard = Discard;
    crate::progress::settle(run(cli))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::schema::{Kind, SETTINGS};
    use crate::pipeline::SmoothSettings;
    use clap::CommandFactory;

    /// The flags of `smooth` that are neither settings of the run nor input options: what to
    /// write and how to draw it.
    const OUTPUTS: &[&str] = &[
        "quiet",
        "help",
        "version",
        "input",
        "output",
        "out-dir",
        "out-format",
        "output-array",
        "diagram",
        "complex",
        "view",
        "isolines",
        "plot",
        "report",
    ];

    fn input_flags() -> Vec<String> {
        crate::io::import::INPUT_OPTIONS.iter().map(|o| o.flag()).collect()
    }

    fn subcommand(name: &str) -> clap::Command {
        Cli::command().find_subcommand(name).expect("the subcommand").clone()
    }

    #[test]
    fn smooth_has_exactly_the_schema_s_settings_as_flags() {
        let smooth = subcommand("smooth");
        let mut seen = Vec::new();
        for arg in smooth.get_arguments() {
            let id = arg.get_id().as_str();
            let flag = arg.get_long().unwrap_or(id).to_string();
            match SETTINGS.iter().find(|s| s.flag() == flag) {
                None => assert!(
                    OUTPUTS.contains(&flag.as_str()) || input_flags().contains(&flag),
                    "`smooth --{flag}` is neither a setting of pipeline::schema, an input option of \
                     io::import::INPUT_OPTIONS nor an output: add it to the schema (the flag is made from it)"
                ),
                Some(s) => {
                    seen.push(s.name);
                    assert_eq!(id, s.name, "--{flag}");
                    assert!(arg.get_default_values().is_empty(), "--{flag}: the default is the schema's");
                    let help = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
                    assert!(help.starts_with(s.help), "--{flag}: the help is the schema's");
                    if let (Some(d), false) = (s.default, s.kind == Kind::Switch) {
                        assert!(help.ends_with(&format!("[default: {d}]")), "--{flag}: {help}");
                    }
                    let choices: Vec<String> =
                        arg.get_possible_values().iter().map(|v| v.get_name().to_string()).collect();
                    match s.kind {
                        Kind::Choice(names) => assert_eq!(choices, names, "--{flag}"),
                        _ => assert!(choices.is_empty(), "--{flag}"),
                    }
                }
            }
        }
        let names: Vec<&str> = SETTINGS.iter().map(|s| s.name).collect();
        assert_eq!(seen, names, "every setting of the schema is a flag of smooth, in the schema's order");
        let extrema = subcommand("extrema");
        let selection: Vec<&str> = extrema
            .get_arguments()
            .filter_map(|a| SETTINGS.iter().find(|s| a.get_long() == Some(&s.flag())))
            .map(|s| s.name)
            .collect();
        assert_eq!(selection, crate::topology::selection::SELECTION_SETTINGS);
    }

    #[test]
    fn the_commands_that_read_a_field_take_every_input_option_of_the_library() {
        let mut options = input_flags();
        options.sort();
        for name in ["smooth", "extrema", "verify"] {
            let mut flags: Vec<String> = subcommand(name)
                .get_arguments()
                .filter_map(|a| a.get_long())
                .map(String::from)
                .filter(|f| options.contains(f))
                .collect();
            flags.sort();
            assert_eq!(flags, options, "{name}");
        }
    }

    /// clap's names of the library's enums are their own (`named_enum!`): one spelling.
    #[test]
    fn every_enum_the_command_line_takes_is_spelt_as_the_library_spells_it() {
        fn names<T: clap::ValueEnum>() -> Vec<String> {
            T::value_variants().iter().filter_map(|v| v.to_possible_value()).map(|p| p.get_name().to_string()).collect()
        }
        use crate::apps::{skinning::Skinning, weights::WeightMethod};
        assert_eq!(names::<EdgeSet>(), EdgeSet::NAMES);
        assert_eq!(names::<Method>(), Method::NAMES);
        assert_eq!(names::<crate::solve::Formulation>(), crate::solve::Formulation::NAMES);
        assert_eq!(names::<RepresentativeChoice>(), RepresentativeChoice::NAMES);
        assert_eq!(names::<DomainKind>(), DomainKind::NAMES);
        assert_eq!(names::<Derive>(), Derive::NAMES);
        assert_eq!(names::<WeightMethod>(), WeightMethod::NAMES);
        assert_eq!(names::<Skinning>(), Skinning::NAMES);
        for name in Derive::NAMES {
            assert_eq!(name.parse::<Derive>().unwrap().to_string(), *name);
        }
    }

    fn settings_of(args: &[&str]) -> Result<SmoothSettings> {
        let argv = ["toposmooth", "smooth", "in.csv", "-o", "out.csv"].iter().chain(args).copied();
        let cli = Cli::try_parse_from(argv).map_err(|e| Error::Usage(e.to_string()))?;
        match cli.command {
            Command::Smooth(c) => smooth_args(*c).map(|a| a.settings),
            _ => unreachable!(),
        }
    }

    #[test]
    fn flags_give_the_settings_the_library_reads_from_their_text() {
        assert_eq!(settings_of(&[]).unwrap(), SmoothSettings::default());
        let s =
            settings_of(&["--minima", "9", "--maxima", "4", "--order", "3", "--data-weight", "0.5", "--threads", "1"])
                .unwrap();
        let texts = [("minima", "9"), ("maxima", "4"), ("order", "3"), ("data_weight", "0.5"), ("threads", "1")];
        assert_eq!(s, SmoothSettings::from_texts(texts).unwrap());
        assert!(settings_of(&["--keep-all-maxima"]).unwrap().selection == crate::topology::Selection::AllMaxima);
        // clap refuses two rules and half a pair; the library a value out of range, with its flag
        for bad in [&["--persistence", "5%", "--pairs", "2"][..], &["--minima", "2"], &["--edges", "some"]] {
            assert_eq!(settings_of(bad).unwrap_err().kind(), crate::ErrorKind::Usage, "{bad:?}");
        }
        let e = settings_of(&["--data-weight", "-1"]).unwrap_err();
        assert_eq!(commands::cli_message(&e), "usage: --data-weight: must be finite and ≥ 0, got -1");
    }
}
