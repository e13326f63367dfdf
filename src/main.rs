//! `toposmooth`: parses the command line and calls the library's commands.

use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use toposmooth::commands::{self, BenchArgs, ExtremaArgs, SmoothArgs, VerifyArgs};
use toposmooth::constraints::EdgeSet;
use toposmooth::io::series_csv::SeriesCsvOptions;
use toposmooth::operators::Energy;
use toposmooth::pipeline::SmoothSettings;
use toposmooth::solve::{Method, QpSettings};
use toposmooth::topology::Selection;
use toposmooth::{Error, Result};

/// Smooth scalar fields keeping exactly the extrema you choose, with a certificate.
#[derive(Parser)]
#[command(name = "toposmooth", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the extrema with their persistence and strictness; draw the persistence diagram.
    Extrema {
        /// Input series (CSV).
        input: PathBuf,
        #[command(flatten)]
        csv: CsvArgs,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Persistence diagram PNG.
        #[arg(long, value_name = "PNG")]
        plot: Option<PathBuf>,
        /// Mark the extrema kept at this persistence: `5%` of the range or an absolute value.
        #[arg(long, default_value = "5%")]
        persistence: String,
    },
    /// Smooth a series keeping exactly the selected extrema; certify the output.
    Smooth(SmoothCli),
    /// Re-check an output file of `smooth` from what it carries.
    Verify {
        /// Output file of `smooth` (x,input,output,u,role).
        file: PathBuf,
        /// The original input: check the file's input column against it.
        #[arg(long, value_name = "FILE")]
        input: Option<PathBuf>,
        #[command(flatten)]
        csv: CsvArgs,
    },
    /// Benchmark on random-walk series: seconds per stage and peak memory.
    Bench {
        /// Series lengths.
        #[arg(long, value_delimiter = ',', default_values_t = [1000usize, 10_000, 100_000, 1_000_000])]
        sizes: Vec<usize>,
        /// Energy order or blend.
        #[arg(long, default_value = "2")]
        order: String,
        /// Persistence threshold (percent of the range).
        #[arg(long, default_value = "1%")]
        persistence: String,
        /// Constraint set.
        #[arg(long, value_enum, default_value_t = Edges::Minimal)]
        edges: Edges,
        /// RNG seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// QP solver.
        #[arg(long, value_enum, default_value_t = Solver::Structured)]
        solver: Solver,
        /// Run one size in this process and print one JSON line.
        #[arg(long, hide = true)]
        single: Option<usize>,
    },
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

impl CsvArgs {
    fn options(&self) -> SeriesCsvOptions {
        SeriesCsvOptions { column: self.column.clone(), x_column: self.x_column.clone() }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum Solver {
    Structured,
    Clarabel,
}

#[derive(Clone, Copy, ValueEnum)]
enum Edges {
    Minimal,
    All,
}

#[derive(Args)]
struct SmoothCli {
    /// Input series (CSV).
    input: PathBuf,
    /// Output CSV: x,input,output,u,role.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    csv: CsvArgs,
    /// Keep extrema of persistence ≥ T: `5%` of the range or an absolute value. [default: 5%]
    #[arg(long, value_name = "T", conflicts_with_all = ["pairs", "keep_min", "keep_max"])]
    persistence: Option<String>,
    /// Keep the N most persistent (minimum, maximum) pairs besides the global minimum.
    #[arg(long, value_name = "N", conflicts_with_all = ["keep_min", "keep_max"])]
    pairs: Option<usize>,
    /// Keep exactly these minima (sample indices, comma-separated); needs --keep-max.
    #[arg(long, value_name = "I,J", requires = "keep_max")]
    keep_min: Option<String>,
    /// Keep exactly these maxima (sample indices); needs --keep-min.
    #[arg(long, value_name = "K", requires = "keep_min")]
    keep_max: Option<String>,
    /// Polyharmonic order 1..4, or a blend like `1:0.2,2:1`.
    #[arg(long, default_value = "2")]
    order: String,
    /// Samples where orders ≥ 2 are not penalised (a spike can stay C0).
    #[arg(long, value_name = "I,J")]
    sharp: Option<String>,
    /// γD: weight of the data term.
    #[arg(long, default_value_t = 1.0)]
    data_weight: f64,
    /// γL for every energy term (default: ℓ^(2k) with ℓ from --smooth-length).
    #[arg(long, value_name = "W")]
    smooth_weight: Option<f64>,
    /// Smoothing length ℓ as a fraction of the series' extent.
    #[arg(long, default_value_t = 0.01)]
    smooth_length: f64,
    /// Constraint set.
    #[arg(long, value_enum, default_value_t = Edges::Minimal)]
    edges: Edges,
    /// Largest number of solver iterations.
    #[arg(long, default_value_t = 200)]
    max_iter: u32,
    /// QP solver: the structured interior-point method (Clarabel takes over if it fails), or
    /// Clarabel alone.
    #[arg(long, value_enum, default_value_t = Solver::Structured)]
    solver: Solver,
    /// Figure: input (grey), output, kept extrema.
    #[arg(long, value_name = "PNG")]
    plot: Option<PathBuf>,
    /// JSON report: settings, kept extrema, seconds per stage, energy, deviations, certificate.
    #[arg(long, value_name = "JSON")]
    report: Option<PathBuf>,
}

fn edge_set(e: Edges) -> EdgeSet {
    match e {
        Edges::Minimal => EdgeSet::Minimal,
        Edges::All => EdgeSet::All,
    }
}

fn method(s: Solver) -> Method {
    match s {
        Solver::Structured => Method::Structured,
        Solver::Clarabel => Method::Clarabel,
    }
}

fn smooth_args(c: SmoothCli) -> Result<SmoothArgs> {
    let selection = match (&c.persistence, c.pairs, &c.keep_min, &c.keep_max) {
        (Some(p), _, _, _) => commands::parse_persistence(p)?,
        (None, Some(n), _, _) => Selection::Pairs(n),
        (None, None, Some(mn), Some(mx)) => {
            Selection::Explicit { minima: commands::parse_indices(mn)?, maxima: commands::parse_indices(mx)? }
        }
        _ => commands::parse_persistence("5%")?,
    };
    let mut energy = Energy::parse(&c.order)?;
    if let Some(s) = &c.sharp {
        energy.sharp = commands::parse_indices(s)?;
    }
    let settings = SmoothSettings {
        selection,
        energy,
        data_weight: c.data_weight,
        smooth_weight: c.smooth_weight,
        smooth_length: c.smooth_length,
        edges: edge_set(c.edges),
        qp: QpSettings { max_iter: c.max_iter, method: method(c.solver), ..Default::default() },
    };
    Ok(SmoothArgs { input: c.input, csv: c.csv.options(), output: c.output, settings, plot: c.plot, report: c.report })
}

fn run(cli: Cli) -> Result<String> {
    match cli.command {
        Command::Extrema { input, csv, json, plot, persistence } => commands::extrema(&ExtremaArgs {
            input,
            csv: csv.options(),
            json,
            plot,
            selection: commands::parse_persistence(&persistence)?,
        }),
        Command::Smooth(c) => commands::smooth(&smooth_args(c)?),
        Command::Verify { file, input, csv } => commands::verify(&VerifyArgs { file, input, csv: csv.options() }),
        Command::Bench { sizes, order, persistence, edges, seed, single, solver } => {
            let persistence = match commands::parse_persistence(&persistence)? {
                Selection::Relative(r) => r,
                _ => return Err(Error::Usage("bench takes --persistence as a percentage".into())),
            };
            commands::bench(&BenchArgs {
                sizes,
                energy: Energy::parse(&order)?,
                persistence,
                edges: edge_set(edges),
                seed,
                single,
                method: method(solver),
            })
        }
    }
}

fn main() {
    match run(Cli::parse()) {
        Ok(text) => print!("{text}"),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(e.exit_code());
        }
    }
}
