//! `toposmooth bench`: time per stage and peak memory on random-walk series.
//!
//! Each size runs in a child process (`bench --single N`) so that its peak resident memory
//! (VmHWM) is its own.

use crate::constraints::EdgeSet;
use crate::domain::Series;
use crate::error::{Error, Result};
use crate::operators::Energy;
use crate::pipeline::{smooth, SmoothSettings};
use crate::solve::{Method, QpSettings};
use crate::topology::Selection;
use std::time::Instant;

/// Options of `bench`.
#[derive(Clone, Debug)]
pub struct BenchArgs {
    /// Series lengths.
    pub sizes: Vec<usize>,
    /// Energy.
    pub energy: Energy,
    /// Persistence threshold as a fraction of the range.
    pub persistence: f64,
    /// Constraint set.
    pub edges: EdgeSet,
    /// RNG seed.
    pub seed: u64,
    /// Run one size in this process and print one JSON line.
    pub single: Option<usize>,
    /// QP solver.
    pub method: Method,
}

/// A Gaussian random walk of `n` steps from a fixed seed (splitmix64 + Box–Muller).
pub fn random_walk(n: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut v = 0.0;
    (0..n)
        .map(|_| {
            let (a, b) = (next().max(f64::MIN_POSITIVE), next());
            v += (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos();
            v
        })
        .collect()
}

fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map(|kib| kib / 1024.0)
        .unwrap_or(f64::NAN)
}

/// Runs the benchmark; returns the table (or one JSON line with `single`).
pub fn bench(args: &BenchArgs) -> Result<String> {
    if let Some(&n) = args.single.iter().chain(&args.sizes).find(|&&n| n < 2) {
        return Err(Error::Usage(format!("bench sizes must be at least 2 samples, got {n}")));
    }
    if let Some(n) = args.single {
        let h = random_walk(n, args.seed);
        let settings = SmoothSettings {
            selection: Selection::Relative(args.persistence),
            energy: args.energy.clone(),
            edges: args.edges,
            qp: QpSettings { method: args.method, ..Default::default() },
            ..Default::default()
        };
        let t = Instant::now();
        let r = smooth(&Series::uniform(n), &h, &settings)?;
        let total = t.elapsed().as_secs_f64();
        let rep = &r.report;
        let line = serde_json::json!({
            "n": n,
            "input_extrema": rep.input_minima + rep.input_maxima,
            "kept": rep.kept.len(),
            "constraints": rep.constraints,
            "iterations": rep.solver_iterations,
            "solver": rep.solver,
            "fallback": rep.solver_fallback,
            "status": format!("{:?}", rep.solver_status),
            "certified": rep.certificate.passed,
            "seconds": rep.seconds,
            "total": total,
            "peak_rss_mib": peak_rss_mib(),
        });
        return Ok(format!("{line}\n"));
    }
    let exe = std::env::current_exe().map_err(|source| Error::Io { path: "current executable".into(), source })?;
    let order = args.energy.terms.iter().map(|(k, w)| format!("{k}:{w}")).collect::<Vec<_>>().join(",");
    let mut out = String::from(
        "| samples | input extrema | kept | constraints | iterations | persistence s | representative s | operators s | constraints s | solve s | repair s | verify s | total s | peak MiB |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for &n in &args.sizes {
        let child = std::process::Command::new(&exe)
            .args(["bench", "--single", &n.to_string(), "--order", &order, "--seed", &args.seed.to_string()])
            .args(["--persistence", &format!("{}%", args.persistence * 100.0)])
            .args(["--edges", if args.edges == EdgeSet::All { "all" } else { "minimal" }])
            .args(["--solver", if args.method == Method::Clarabel { "clarabel" } else { "structured" }])
            .output()
            .map_err(|source| Error::Io { path: exe.clone(), source })?;
        if !child.status.success() {
            return Err(Error::input(format!(
                "bench of {n} samples failed: {}",
                String::from_utf8_lossy(&child.stderr).trim()
            )));
        }
        let v: serde_json::Value =
            serde_json::from_slice(&child.stdout).map_err(|e| Error::input(format!("bench output: {e}")))?;
        let s = &v["seconds"];
        let f = |x: &serde_json::Value| x.as_f64().unwrap_or(f64::NAN);
        out += &format!(
            "| {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.0} |\n",
            n,
            v["input_extrema"],
            v["kept"],
            v["constraints"],
            v["iterations"],
            f(&s["persistence"]),
            f(&s["representative"]),
            f(&s["operators"]),
            f(&s["constraints"]),
            f(&s["solve"]),
            f(&s["repair"]),
            f(&s["verify"]),
            f(&v["total"]),
            f(&v["peak_rss_mib"])
        );
    }
    Ok(out)
}
