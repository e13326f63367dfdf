//! The command-line tool's commands: reading files, running the pipeline, printing, writing.
//! `main.rs` only parses arguments into these option structs and maps errors to exit codes.

pub mod alloc;
mod bench;
pub mod cli;
mod deform;
mod diffuse;
mod extrema;
mod geodesic;
mod mesh_outline;
pub mod progress;
pub mod settings_args;
mod smooth;
mod smooth_args;
mod smooth_many;
mod verify;
mod weights;

pub use bench::{bench, bench_weights, quantised_phantom3, BenchArgs, BenchCase};
pub use deform::{deform, DeformArgs};
pub use diffuse::{diffuse, DiffuseArgs};
pub use extrema::{extrema, ExtremaArgs};
pub use geodesic::{geodesic, GeodesicArgs};
pub use mesh_outline::{mesh_outline, MeshOutlineArgs};
pub use smooth::smooth;
pub use smooth_args::SmoothArgs;
pub use smooth_many::smooth_many;
pub use verify::{verify, VerifyArgs};
pub use weights::{weights, WeightsArgs};

use crate::error::{Error, Result};
use crate::io::series_csv::XSource;
use crate::plot::XAxis;
use crate::topology::Selection;
use std::path::Path;

/// Parses `--persistence`: `5%` (relative to the value range) or `0.3` (absolute).
///
/// # Errors
/// As [`crate::topology::selection::parse_threshold`].
pub fn parse_persistence(s: &str) -> Result<Selection> {
    crate::topology::selection::parse_threshold(s)
}

/// The marker of the message the tool prints when it panics outside a reader (a bug: exit 1).
pub const INTERNAL_FAILURE: &str = "[internal failure]";

/// Makes panics silent (no panic text reaches the user): the hook records where and why, and
/// [`catch_panics`] or [`crate::io::guarded`] report it in one line.
pub fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        let text = crate::io::panic_text(info.payload());
        if let Ok(mut last) = crate::error::LAST_PANIC.lock() {
            *last = Some(format!("{text}{at}"));
        }
    }));
}

/// How long the run has after SIGINT to stop at its next check before it is ended as SIGTERM
/// ends it (a factorisation in progress is not interrupted).
pub const INTERRUPT_GRACE: std::time::Duration = std::time::Duration::from_secs(5);

/// The first SIGINT cancels the run (the returned token, which the command runs under): it
/// stops at its next check, removes its temporaries and exits with 130 ([`Error::Cancelled`]).
/// A second SIGINT, [`INTERRUPT_GRACE`] without the run stopping, SIGTERM or SIGHUP remove the
/// temporaries at once (waiting for outputs being renamed into place, so a command's outputs
/// are never left half old, half new) and end the tool as the signal would have ended it.
pub fn install_interrupt_handler() -> crate::progress::CancelToken {
    let token = crate::progress::CancelToken::new();
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let end = |signal: i32| -> ! {
            crate::io::staging::remove_temporaries();
            let _ = signal_hook::low_level::emulate_default_handler(signal);
            std::process::exit(128 + signal);
        };
        if let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
            let token = token.clone();
            std::thread::spawn(move || {
                for signal in signals.forever() {
                    if signal == SIGINT && !token.is_cancelled() {
                        token.cancel();
                        std::thread::spawn(move || {
                            std::thread::sleep(INTERRUPT_GRACE);
                            end(SIGINT)
                        });
                        continue;
                    }
                    end(signal)
                }
            });
        }
    }
    token
}

/// The exit status of a process ended by SIGPIPE, which the tool returns when its standard
/// output is closed early (`toposmooth extrema f.csv | head -1`).
pub const BROKEN_PIPE_STATUS: i32 = 141;

/// Ends a run: removes any temporary still held, prints the summary on standard output or the
/// error on standard error, and returns the exit status. A closed standard output (or a
/// closed FIFO given as an output) ends quietly with [`BROKEN_PIPE_STATUS`].
pub fn finish(result: Result<String>) -> i32 {
    use std::io::Write;
    crate::io::staging::remove_temporaries();
    match result {
        Ok(text) if crate::io::staging::writes_stdout() => {
            // an output went to the standard output: the summary goes beside it, to standard error
            let _ = std::io::stderr().write_all(text.as_bytes());
            0
        }
        Ok(text) => {
            let mut out = std::io::stdout().lock();
            match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
                Ok(()) => 0,
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => BROKEN_PIPE_STATUS,
                Err(e) => {
                    let _ = writeln!(std::io::stderr(), "error: writing the standard output: {e}");
                    crate::error::ErrorKind::Io.exit_code()
                }
            }
        }
        Err(Error::Io { source, .. }) if source.kind() == std::io::ErrorKind::BrokenPipe => BROKEN_PIPE_STATUS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {}", cli_message(&e));
            e.exit_code()
        }
    }
}

/// Runs the tool, turning a panic into an internal error (exit 1) carrying
/// [`INTERNAL_FAILURE`].
///
/// # Errors
/// The run's errors, and the caught panic.
pub fn catch_panics(run: impl FnOnce() -> Result<String>) -> Result<String> {
    let run = || {
        if std::env::var_os("TOPOSMOOTH_DEBUG_PANIC").is_some_and(|v| v == "internal") {
            panic!("TOPOSMOOTH_DEBUG_PANIC=internal");
        }
        run()
    };
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).unwrap_or_else(|payload| {
        let what = crate::error::take_last_panic().unwrap_or_else(|| crate::io::panic_text(&*payload));
        Err(Error::internal(format!(
            "{INTERNAL_FAILURE} toposmooth failed ({what}); this is a bug in toposmooth: please report it"
        )))
    })
}

/// An error as the command line words it: a setting the library names (`data_weight`) is
/// named by its flag (`--data-weight`).
pub fn cli_message(e: &Error) -> String {
    match e {
        Error::Setting { setting, message } => format!("usage: {}: {message}", flag(setting)),
        Error::Cancelled => "cancelled (interrupted); no partial output or temporary file is left".into(),
        e => e.to_string(),
    }
}

/// The flag of a setting of the library.
fn flag(setting: &str) -> String {
    match setting {
        "all_extrema" => "--keep-all-maxima/--keep-all-minima".into(),
        "count" => "--minima/--maxima".into(),
        s => format!("--{}", s.replace('_', "-")),
    }
}

/// A number rounded to 6 significant digits, printed in its shortest form (for tables).
pub fn sig6(v: f64) -> String {
    if v != 0.0 && v.abs() < 1e-4 {
        return format!("{:.5e}", v).parse::<f64>().map(|r| format!("{r:e}")).unwrap_or_else(|_| v.to_string());
    }
    format!("{:.5e}", v).parse::<f64>().map(|r| format!("{r}")).unwrap_or_else(|_| v.to_string())
}

/// Parses a comma-separated list of vertex indices.
pub fn parse_indices(s: &str) -> Result<Vec<usize>> {
    s.split(',')
        .filter(|p| !p.trim().is_empty())
        .map(|p| p.trim().parse::<usize>().map_err(|_| Error::Usage(format!("`{p}` in `{s}` is not a vertex index"))))
        .collect()
}

/// The plot's x axis for a series read from CSV, and x shifted to start at 0 for dates.
fn x_axis(source: &XSource, x: &[f64]) -> (XAxis, Vec<f64>) {
    match source {
        XSource::Index => (XAxis::Numeric("sample".into()), x.to_vec()),
        XSource::Numeric(name) => (XAxis::Numeric(name.clone()), x.to_vec()),
        XSource::Dates(_, first) => {
            let x0 = x[0].floor();
            (XAxis::DaysSince(*first), x.iter().map(|v| v - x0).collect())
        }
    }
}

/// Plots are PNG files: checked before any work so that a bad name writes nothing. A stream
/// without an extension (`-`, a FIFO, `/dev/null`) takes PNG.
fn check_png_name(path: Option<&Path>) -> Result<()> {
    match path {
        Some(p) if p.extension().is_none() && crate::io::staging::is_stream(p) => Ok(()),
        Some(p) if !p.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("png")) => {
            Err(Error::Usage(format!("{}: plots are written as PNG; use a .png name", p.display())))
        }
        _ => Ok(()),
    }
}

/// Draws a plot into a staged temporary file (see [`crate::io::Staged`]).
fn stage_plot(
    path: &Path,
    draw: impl FnOnce(&mut dyn std::io::Write) -> std::result::Result<(), crate::plot::PlotError>,
) -> Result<crate::io::Staged> {
    check_png_name(Some(path))?;
    crate::io::stage(path, |w| draw(w).map_err(|e| std::io::Error::other(e.to_string())))
}

/// A JSON report with what reproduces it first: the tool, its version and the full command
/// line (arguments as given; bytes that are not UTF-8 replaced).
#[derive(serde::Serialize)]
struct WithProvenance<'a, T: serde::Serialize> {
    tool: &'static str,
    version: &'static str,
    command_line: Vec<String>,
    #[serde(flatten)]
    report: &'a T,
}

/// Stages a command's JSON report (see [`WithProvenance`]).
fn stage_report<T: serde::Serialize>(path: &Path, report: &T) -> Result<crate::io::Staged> {
    let command_line = std::env::args_os().map(|a| a.to_string_lossy().into_owned()).collect();
    crate::io::stage_json(
        path,
        &WithProvenance { tool: "toposmooth", version: env!("CARGO_PKG_VERSION"), command_line, report },
    )
}

/// An output's name for the summary: `-` is the standard output.
pub(crate) fn shown(path: &Path) -> String {
    if path.as_os_str() == "-" {
        "standard output".into()
    } else {
        path.display().to_string()
    }
}

/// The line listing the files written (the given paths, skipping `None`).
fn wrote_line<'a>(paths: impl IntoIterator<Item = Option<&'a std::path::PathBuf>>) -> String {
    let names: Vec<String> = paths.into_iter().flatten().map(|p| shown(p)).collect();
    format!("wrote {}\n", names.join(", "))
}

/// Output paths must differ from each other and from the inputs (symbolic links resolved; a
/// character device such as `/dev/null` may take several outputs), and each must be writable:
/// checked, and each output's temporary reserved ([`crate::io::reserve`]), before any work, so
/// that a typo costs nothing and no output is half written.
fn check_distinct(inputs: &[&Path], outputs: &[(&str, Option<&Path>)]) -> Result<()> {
    let key = path_key;
    let mut seen: Vec<(&str, std::path::PathBuf)> = inputs.iter().map(|p| ("an input", key(p))).collect();
    let mut reserve = Vec::new();
    for (name, p) in outputs {
        if let Some(p) = p {
            // a directory, socket or missing directory: refused by `reserve` below
            let k = key(p);
            if let Some((other, _)) = seen.iter().find(|(_, s)| *s == k) {
                if !is_char_device(p) {
                    return Err(Error::Usage(format!("{name} {} is also {other}", p.display())));
                }
            }
            seen.push((name, k));
            reserve.push(*p);
        }
    }
    crate::io::reserve(&reserve)
}

/// A path with its links and its directory resolved (a new file: its directory's), to compare
/// outputs with inputs.
fn path_key(p: &Path) -> std::path::PathBuf {
    std::fs::canonicalize(p)
        .or_else(|_| {
            // a new file: resolve its directory
            let parent = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
            std::fs::canonicalize(parent).map(|d| d.join(p.file_name().unwrap_or_default()))
        })
        .unwrap_or_else(|_| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()))
}

/// Whether `path` is a character device (`/dev/null`): it can take several outputs.
fn is_char_device(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        std::fs::metadata(path).is_ok_and(|m| m.file_type().is_char_device())
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn persistence_and_indices() {
        assert_eq!(parse_persistence("5%").unwrap(), Selection::Relative(0.05));
        assert_eq!(parse_persistence("0.25").unwrap(), Selection::Absolute(0.25));
        assert!(parse_persistence("-1").is_err());
        assert!(parse_persistence("abc").is_err());
        assert!(parse_persistence("0%").is_err());
        assert_eq!(parse_indices("1, 5,9").unwrap(), vec![1, 5, 9]);
        assert_eq!(sig6(1.8600000000000003), "1.86");
        assert_eq!(sig6(0.011692000000000001), "0.011692");
        assert!(parse_indices("1,x").is_err());
        let e = Error::setting("data_weight", "must be finite and ≥ 0, got -1");
        assert_eq!(cli_message(&e), "usage: --data-weight: must be finite and ≥ 0, got -1");
        assert_eq!(cli_message(&Error::setting("count", "x")), "usage: --minima/--maxima: x");
    }
}
