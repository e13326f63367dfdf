//! The options of `smooth` and the shared lines of its summary.

use super::sig6;
use crate::domain::AnyDomain;
use crate::io::import::ReadOptions;
use crate::pipeline::{Report, SmoothSettings, StageSeconds};
use std::path::PathBuf;

/// Options of `smooth`.
#[derive(Clone, Debug)]
pub struct SmoothArgs {
    /// Input file (none when a grid comes from `--u`/`--v`).
    pub input: Option<PathBuf>,
    /// How to read it: the domain, the column or array, spacing, derivation, mask, NaN policy.
    pub read: ReadOptions,
    /// Critical points (and separatrices on surfaces) as VTK PolyData.
    pub complex: Option<PathBuf>,
    /// Isolines in the grid plot.
    pub isolines: usize,
    /// Camera of the mesh plot.
    pub view: crate::plot::MeshView,
    /// Output CSV.
    pub output: PathBuf,
    /// Pipeline settings.
    pub settings: SmoothSettings,
    /// Figure.
    pub plot: Option<PathBuf>,
    /// JSON report.
    pub report: Option<PathBuf>,
    /// The input's persistence diagram in TTK's layout (`--diagram`, `.vtu`).
    pub diagram: Option<PathBuf>,
    /// The smoothed field's name in VTK outputs (`--output-array`).
    pub output_array: Option<String>,
}

/// The certificate, deviation and solver lines of `smooth`'s summary.
pub fn fit_and_solver_lines(r: &Report) -> String {
    format!(
        "{}; RMS deviation {}, max deviation {}\n{}\nsolver {:?} {:?} in {} iterations{}{}, {} constraints, margin {:.3e}; margin met exactly by moving {} vertices (at most {:.1e}); strictness repair changed {} vertices\n",
        r.certificate.summary(),
        sig6(r.rms_deviation),
        sig6(r.max_deviation),
        r.fit.summary(),
        r.solver,
        r.solver_status,
        r.solver_iterations,
        if r.solver_inner_iterations > 0 { format!(" ({} conjugate-gradient)", r.solver_inner_iterations) } else { String::new() },
        r.solver_fallback.as_ref().map(|w| format!(" (first solver gave up: {w})")).unwrap_or_default(),
        r.constraints,
        r.settings.margin[0],
        r.margin_repair.changed_vertices,
        r.margin_repair.max_change,
        r.repair.changed_vertices
    )
}

/// The `seconds:` line of a run (series have no complex to build or simplify).
pub fn seconds_line(domain: &AnyDomain, read: f64, s: &StageSeconds, write: f64, total: f64) -> String {
    let complex = match domain {
        AnyDomain::Series(_) => String::new(),
        _ => format!("complex {:.3}, simplify {:.3}, ", s.complex, s.simplify),
    };
    format!(
        "seconds: read {read:.3}, persistence {:.3}, {complex}representative {:.3}, operators {:.3}, constraints {:.3}, solve {:.3}, repair {:.3}, verify {:.3}, write {write:.3}, total {total:.3}\n",
        s.persistence, s.representative, s.operators, s.constraints, s.solve, s.repair, s.verify
    )
}
