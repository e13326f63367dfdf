//! `toposmooth bench`: time per stage and peak memory on random-walk series and noisy grids.
//!
//! Each size runs in a child process (`bench --single N` or `NXxNY`) so that its peak resident memory
//! (VmHWM) is its own.

use crate::constraints::EdgeSet;
use crate::domain::{Grid2d, Grid3d, Series};
use crate::error::{Error, Result};
use crate::operators::Energy;
use crate::pipeline::{smooth, RepresentativeChoice, SmoothSettings, Smoothable, Smoothed};
use crate::smoother::Smoother;
use crate::solve::{Method, QpSettings};
use crate::topology::Selection;
use std::time::Instant;

/// Options of `bench`.
#[derive(Clone, Debug)]
pub struct BenchArgs {
    /// The cases, run one per child process.
    pub cases: Vec<BenchCase>,
    /// Energy.
    pub energy: Energy,
    /// Persistence threshold as a fraction of the range.
    pub persistence: f64,
    /// Constraint set.
    pub edges: EdgeSet,
    /// RNG seed.
    pub seed: u64,
    /// Run one case (`N` or `NXxNY`) in this process and print one JSON line.
    pub single: Option<String>,
    /// QP solver.
    pub method: Method,
    /// Representative function on grids and meshes.
    pub representative: Option<RepresentativeChoice>,
    /// Fields per case, smoothed by one [`crate::smoother::Smoother`] (1: the one-off path).
    pub fields: usize,
}

/// Uniform numbers in [0, 1) from a seed (splitmix64).
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A Gaussian random walk of `n` steps from a fixed seed (splitmix64 + Box–Muller).
pub fn random_walk(n: usize, seed: u64) -> Vec<f64> {
    let mut next = uniform(seed);
    let mut v = 0.0;
    (0..n)
        .map(|_| {
            let (a, b) = (next().max(f64::MIN_POSITIVE), next());
            v += (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos();
            v
        })
        .collect()
}

/// A grid field with smooth structure (a few Gaussian bumps and pits, a gentle tilt) plus
/// uniform noise of 5 % of its range: many noise extrema, a handful of persistent ones.
pub fn noisy_bumps(nx: usize, ny: usize, seed: u64) -> Vec<f64> {
    let mut next = uniform(seed);
    // (x, y, sign·height, width) in unit coordinates
    let bumps = [
        (0.2, 0.3, 1.0, 0.08),
        (0.7, 0.25, 0.8, 0.1),
        (0.45, 0.7, 0.9, 0.09),
        (0.85, 0.75, 0.6, 0.07),
        (0.15, 0.8, 0.7, 0.06),
        (0.5, 0.35, 0.75, 0.07),
        (0.35, 0.5, -0.8, 0.08),
        (0.65, 0.55, -0.9, 0.09),
        (0.9, 0.4, -0.6, 0.06),
        (0.25, 0.1, -0.7, 0.07),
        (0.75, 0.9, -0.6, 0.07),
        (0.55, 0.1, -0.5, 0.06),
    ];
    (0..nx * ny)
        .map(|v| {
            let (x, y) = ((v % nx) as f64 / (nx - 1) as f64, (v / nx) as f64 / (ny - 1) as f64);
            let smooth: f64 = bumps
                .iter()
                .map(|&(cx, cy, a, w)| a * (-((x - cx).powi(2) + (y - cy).powi(2)) / (w * w)).exp())
                .sum::<f64>()
                + 0.1 * x;
            smooth + 0.1 * (next() - 0.5)
        })
        .collect()
}

/// The volume version of [`noisy_bumps`]: twelve Gaussian bumps and pits in the unit cube, a
/// gentle tilt, and uniform noise of 5 % of the range (index `i + nx·(j + ny·k)`).
pub fn noisy_bumps3(nx: usize, ny: usize, nz: usize, seed: u64) -> Vec<f64> {
    let mut next = uniform(seed);
    // (x, y, z, sign·height, width) in unit coordinates
    let bumps = [
        (0.2, 0.3, 0.3, 1.0, 0.12),
        (0.7, 0.25, 0.6, 0.8, 0.14),
        (0.45, 0.7, 0.2, 0.9, 0.13),
        (0.85, 0.75, 0.75, 0.6, 0.11),
        (0.15, 0.8, 0.7, 0.7, 0.1),
        (0.5, 0.35, 0.8, 0.75, 0.11),
        (0.35, 0.5, 0.5, -0.8, 0.12),
        (0.65, 0.55, 0.35, -0.9, 0.13),
        (0.9, 0.4, 0.15, -0.6, 0.1),
        (0.25, 0.1, 0.85, -0.7, 0.11),
        (0.75, 0.9, 0.3, -0.6, 0.11),
        (0.55, 0.1, 0.45, -0.5, 0.1),
    ];
    let unit = |i: usize, n: usize| if n > 1 { i as f64 / (n - 1) as f64 } else { 0.5 };
    (0..nx * ny * nz)
        .map(|v| {
            let (x, y, z) = (unit(v % nx, nx), unit((v / nx) % ny, ny), unit(v / (nx * ny), nz));
            let smooth: f64 = bumps
                .iter()
                .map(|&(cx, cy, cz, a, w)| {
                    a * (-((x - cx).powi(2) + (y - cy).powi(2) + (z - cz).powi(2)) / (w * w)).exp()
                })
                .sum::<f64>()
                + 0.1 * x;
            smooth + 0.1 * (next() - 0.5)
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

/// A tie-heavy volume as a scanner writes one: a head-like ellipsoid of tissue (160, with a
/// smooth variation of ±15) holding two dark ventricles (40) and three bright spots (220),
/// on a dark background (2), plus noise (standard deviation 8 inside, 2 outside), rounded and
/// clamped to the 256 levels of uint8: a fifth of the voxels tie at 0 to 4, every level holds
/// hundreds (the brain crops that the active set once handed over on).
pub fn quantised_phantom3(nx: usize, ny: usize, nz: usize, seed: u64) -> Vec<f64> {
    let mut next = uniform(seed);
    let unit = |i: usize, n: usize| if n > 1 { i as f64 / (n - 1) as f64 } else { 0.5 };
    // (centre, semi-axes) in unit coordinates
    let inside =
        |p: [f64; 3], c: [f64; 3], r: [f64; 3]| (0..3).map(|a| ((p[a] - c[a]) / r[a]).powi(2)).sum::<f64>() <= 1.0;
    let ventricles = [([0.42, 0.5, 0.55], [0.06, 0.16, 0.09]), ([0.58, 0.5, 0.55], [0.06, 0.16, 0.09])];
    let spots = [
        ([0.3, 0.3, 0.4], [0.05, 0.05, 0.05]),
        ([0.7, 0.65, 0.35], [0.06, 0.04, 0.05]),
        ([0.5, 0.75, 0.7], [0.04, 0.06, 0.05]),
    ];
    (0..nx * ny * nz)
        .map(|v| {
            let p = [unit(v % nx, nx), unit((v / nx) % ny, ny), unit(v / (nx * ny), nz)];
            // about Gaussian: the sum of four uniforms, variance 1/3
            let noise = ((0..4).map(|_| next()).sum::<f64>() - 2.0) * 3f64.sqrt();
            let value = if inside(p, [0.5, 0.5, 0.5], [0.42, 0.36, 0.4]) {
                let base = if ventricles.iter().any(|&(c, r)| inside(p, c, r)) {
                    40.0
                } else if spots.iter().any(|&(c, r)| inside(p, c, r)) {
                    220.0
                } else {
                    160.0 + 15.0 * (5.0 * p[0]).sin() * (4.0 * p[1]).cos() * (3.0 * p[2] + 1.0).sin()
                };
                base + 8.0 * noise
            } else {
                2.0 + 2.0 * noise
            };
            value.round().clamp(0.0, 255.0)
        })
        .collect()
}

/// One benchmark case: a series of n samples, an nx × ny grid, or a mesh file.
#[derive(Clone, Debug, PartialEq)]
pub enum BenchCase {
    /// Random-walk series.
    Series(usize),
    /// Noisy bumps on a grid (columns, rows).
    Grid(usize, usize),
    /// Noisy bumps in a volume (nx, ny, nz).
    Volume(usize, usize, usize),
    /// A tie-heavy uint8 volume ([`quantised_phantom3`]), written `NXxNYxNZq`, smoothed at a
    /// persistence of 5 % of the range (as the brain crop was; `--persistence` is not used).
    Quantised(usize, usize, usize),
    /// A mesh file, midpoint-subdivided this many times: geodesic distance from vertex 0,
    /// then smoothing with every maximum kept (the paper's figure 13).
    Mesh(String, usize),
}

/// The largest bench case, in vertices: a 256³ volume (16.8 million, issue 38's size) fits,
/// as does a series of 10⁷ samples.
pub const MAX_BENCH_VERTICES: usize = 20_000_000;

impl BenchCase {
    /// Parses `N`, `NXxNY`, or a mesh path with an optional `@LEVELS` of subdivision.
    ///
    /// # Errors
    /// [`Error::Usage`] for a case that is not one, too small, or above
    /// [`MAX_BENCH_VERTICES`].
    pub fn parse(s: &str) -> Result<BenchCase> {
        let (file, levels) = match s.rsplit_once('@') {
            Some((f, l)) => (f, Some(l)),
            None => (s, None),
        };
        if crate::io::mesh::is_mesh_path(std::path::Path::new(file)) {
            let levels = match levels {
                None => 0,
                Some(l) => l
                    .parse::<usize>()
                    .ok()
                    .filter(|&l| l <= 4)
                    .ok_or_else(|| Error::Usage(format!("bench mesh `{s}`: subdivision levels 0..=4 after @")))?,
            };
            return Ok(BenchCase::Mesh(file.to_string(), levels));
        }
        let bad = || {
            Error::Usage(format!(
                "bench size `{s}` is not N (series), NXxNY (grid), NXxNYxNZ (volume), NXxNYxNZq (quantised volume) or a mesh file[@levels]"
            ))
        };
        let (s, quantised) = match s.strip_suffix('q') {
            Some(rest) => (rest, true),
            None => (s, false),
        };
        let parts: Vec<usize> =
            s.split(['x', 'X', '×']).map(|p| p.trim().parse().map_err(|_| bad())).collect::<Result<_>>()?;
        let case = match parts[..] {
            // the suffix q names a quantised volume only
            _ if quantised && parts.len() != 3 => return Err(bad()),
            [n] => BenchCase::Series(n),
            [a, b] => BenchCase::Grid(a, b),
            [a, b, c] if quantised => BenchCase::Quantised(a, b, c),
            [a, b, c] => BenchCase::Volume(a, b, c),
            _ => return Err(bad()),
        };
        match case {
            BenchCase::Series(n) if n > MAX_BENCH_VERTICES => Err(Error::Usage(format!(
                "bench series of {n} samples: at most {MAX_BENCH_VERTICES} (a run of that size takes hours)"
            ))),
            BenchCase::Grid(a, b) if a.checked_mul(b).is_none_or(|n| n > MAX_BENCH_VERTICES) => Err(Error::Usage(
                format!("bench grid {a} × {b}: at most {MAX_BENCH_VERTICES} vertices (a run of that size takes hours)"),
            )),
            BenchCase::Volume(a, b, c) | BenchCase::Quantised(a, b, c)
                if a.checked_mul(b).and_then(|ab| ab.checked_mul(c)).is_none_or(|n| n > MAX_BENCH_VERTICES) =>
            {
                Err(Error::Usage(format!(
                    "bench volume {a} × {b} × {c}: at most {MAX_BENCH_VERTICES} vertices (a run of that size takes hours)"
                )))
            }
            BenchCase::Volume(a, b, c) | BenchCase::Quantised(a, b, c) if a < 2 || b < 2 || c < 2 => {
                Err(Error::Usage(format!("bench volumes need at least 2 × 2 × 2 vertices, got {a} × {b} × {c}")))
            }
            BenchCase::Series(n) if n < 2 => {
                Err(Error::Usage(format!("bench series need at least 2 samples, got {n}")))
            }
            BenchCase::Grid(a, b) if a < 2 || b < 2 => {
                Err(Error::Usage(format!("bench grids need at least 2 × 2 vertices, got {a} × {b}")))
            }
            c => Ok(c),
        }
    }

    fn label(&self) -> String {
        match self {
            BenchCase::Series(n) => n.to_string(),
            BenchCase::Grid(a, b) => format!("{a}x{b}"),
            BenchCase::Volume(a, b, c) => format!("{a}x{b}x{c}"),
            BenchCase::Quantised(a, b, c) => format!("{a}x{b}x{c}q"),
            BenchCase::Mesh(f, 0) => f.clone(),
            BenchCase::Mesh(f, l) => format!("{f}@{l}"),
        }
    }
}

/// `h` and `fields − 1` variants (a smooth wave of 1 % of the range added), through one
/// [`Smoother`]: each result and its seconds.
fn through_smoother<D: Smoothable + Sync>(
    domain: D,
    h: &[f64],
    settings: &SmoothSettings,
    fields: usize,
) -> Result<Vec<(Smoothed, f64)>> {
    let t = Instant::now();
    let mut smoother = Smoother::new(domain, settings.clone())?;
    let (lo, hi) = crate::domain::value_range(h);
    let mut out = Vec::with_capacity(fields);
    for i in 0..fields {
        let field: Vec<f64> = if i == 0 {
            h.to_vec()
        } else {
            // a smooth change of 1 % of the range (noise would add extrema by the thousand
            // where every maximum is kept)
            let scale = smoother.domain().diameter();
            (0..h.len())
                .map(|v| {
                    let [x, y, z] = smoother.domain().point(v);
                    let phase = std::f64::consts::TAU * (x + 0.6 * y + 0.3 * z) / scale + i as f64;
                    h[v] + 0.01 * (hi - lo) * phase.sin()
                })
                .collect()
        };
        let t_field = if i == 0 { t } else { Instant::now() };
        let r = smoother.smooth(&field)?;
        out.push((r, t_field.elapsed().as_secs_f64()));
    }
    Ok(out)
}

fn run_single(case: BenchCase, args: &BenchArgs) -> Result<String> {
    let mut settings = SmoothSettings {
        selection: Selection::Relative(args.persistence),
        energy: args.energy.clone(),
        edges: args.edges,
        qp: QpSettings { method: args.method, ..Default::default() },
        representative: args.representative,
        ..Default::default()
    };
    let t = Instant::now();
    let mut extra = serde_json::json!({});
    let many = args.fields > 1;
    let (results, n): (Vec<(Smoothed, f64)>, usize) = match &case {
        BenchCase::Series(n) => {
            let h = random_walk(*n, args.seed);
            if many {
                (through_smoother(Series::uniform(*n), &h, &settings, args.fields)?, *n)
            } else {
                (vec![(smooth(&Series::uniform(*n), &h, &settings)?, f64::NAN)], *n)
            }
        }
        BenchCase::Grid(nx, ny) => {
            // the benchmark: 13 kept extrema
            settings.selection = Selection::Count { minima: 7, maxima: 6 };
            let grid = Grid2d::new(*nx, *ny)?;
            let h = noisy_bumps(*nx, *ny, args.seed);
            if many {
                (through_smoother(grid, &h, &settings, args.fields)?, nx * ny)
            } else {
                (vec![(smooth(&grid, &h, &settings)?, f64::NAN)], nx * ny)
            }
        }
        &BenchCase::Volume(nx, ny, nz) | &BenchCase::Quantised(nx, ny, nz) => {
            let h = if let BenchCase::Quantised(..) = case {
                settings.selection = Selection::Relative(0.05);
                quantised_phantom3(nx, ny, nz, args.seed)
            } else {
                settings.selection = Selection::Count { minima: 7, maxima: 6 };
                noisy_bumps3(nx, ny, nz, args.seed)
            };
            let grid = Grid3d::new(nx, ny, nz)?;
            let n = nx * ny * nz;
            if many {
                (through_smoother(grid, &h, &settings, args.fields)?, n)
            } else {
                (vec![(smooth(&grid, &h, &settings)?, f64::NAN)], n)
            }
        }
        BenchCase::Mesh(file, levels) => {
            let path = std::path::Path::new(file);
            let (mut mesh, _) = crate::io::import::read_trimesh(path)?;
            for _ in 0..*levels {
                mesh = mesh.subdivide().map_err(|e| e.in_file(path))?;
            }
            let read = t.elapsed().as_secs_f64();
            let tg = Instant::now();
            // the smoothing's harmonic fills reuse the Laplacian's analysis the heat method made
            let mut analyses = crate::linalg::Analyses::default();
            let (h, _) =
                crate::apps::geodesic::heat_geodesic_with(&mesh, &[0], &mut analyses).map_err(|e| e.in_file(path))?;
            let geodesic = tg.elapsed().as_secs_f64();
            extra = serde_json::json!({ "read": read, "geodesic": geodesic, "triangles": mesh.faces().len() });
            settings.selection = Selection::AllMaxima;
            let n = crate::domain::Domain::n_vertices(&mesh);
            if many {
                // the Smoother makes its own analyses: the geodesic's are not held beside them
                drop(analyses);
                (through_smoother(mesh, &h, &settings, args.fields).map_err(|e| e.in_file(path))?, n)
            } else {
                let out =
                    crate::pipeline::smooth_with(&mesh, &h, &settings, &mut analyses).map_err(|e| e.in_file(path))?;
                (vec![(out, f64::NAN)], n)
            }
        }
    };
    let total = t.elapsed().as_secs_f64();
    let mut lines = String::new();
    for (i, (r, seconds)) in results.iter().enumerate() {
        let rep = &r.report;
        let label = if many { format!("{} #{}", case.label(), i + 1) } else { case.label() };
        let line = serde_json::json!({
            "case": label,
            "n": n,
            "input_extrema": rep.input_minima + rep.input_maxima,
            "kept": rep.kept.len(),
            "constraints": rep.constraints,
            "iterations": rep.solver_iterations,
            "inner_iterations": rep.solver_inner_iterations,
            "solver": rep.solver,
            "fallback": rep.solver_fallback,
            "representative": rep.representative,
            "status": format!("{:?}", rep.solver_status),
            "certified": rep.certificate.passed,
            "gap_over_data": rep.fit.gap_over_data,
            "active_fraction": rep.activity.active_fraction,
            "formulation": rep.fit.formulation,
            "seconds": rep.seconds,
            "total": if many { *seconds } else { total },
            "peak_rss_mib": peak_rss_mib(),
            "extra": if i == 0 { extra.clone() } else { serde_json::json!({}) },
        });
        lines += &format!("{line}\n");
    }
    Ok(lines)
}

/// Runs the benchmark; returns the table (or one JSON line with `single`).
pub fn bench(args: &BenchArgs) -> Result<String> {
    if let Some(s) = &args.single {
        return run_single(BenchCase::parse(s)?, args);
    }
    let exe = std::env::current_exe().map_err(|source| Error::Io { path: "current executable".into(), source })?;
    let order = args.energy.terms.iter().map(|(k, w)| format!("{k}:{w}")).collect::<Vec<_>>().join(",");
    let mut out = String::from(
        "| size | input extrema | kept | constraints | iterations | Ĝ ÷ data | read s | geodesic s | persistence s | complex s | simplify s | representative s | operators s | constraints s | solve s | repair s | verify s | total s | peak MiB |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for case in &args.cases {
        let child = std::process::Command::new(&exe)
            .args(["bench", "--single", &case.label(), "--order", &order, "--seed", &args.seed.to_string()])
            .args(["--persistence", &format!("{}%", args.persistence * 100.0)])
            .args(["--edges", if args.edges == EdgeSet::All { "all" } else { "minimal" }])
            .args(["--fields", &args.fields.to_string()])
            .args([
                "--solver",
                match args.method {
                    Method::Clarabel => "clarabel",
                    Method::ClarabelAuxiliary => "clarabel-auxiliary",
                    Method::Auto => "auto",
                    Method::Structured => "structured",
                    Method::ActiveSet => "active-set",
                },
            ])
            .args(args.representative.iter().flat_map(|r| {
                [
                    "--representative",
                    match r {
                        RepresentativeChoice::Separatrix => "separatrix",
                        RepresentativeChoice::Harmonic => "harmonic",
                        RepresentativeChoice::Flooded => "flooded",
                    },
                ]
            }))
            .output()
            .map_err(|source| Error::Io { path: exe.clone(), source })?;
        if !child.status.success() {
            return Err(Error::input(format!(
                "bench of {} failed: {}",
                case.label(),
                String::from_utf8_lossy(&child.stderr).trim()
            )));
        }
        for line in String::from_utf8_lossy(&child.stdout).lines() {
            let v: serde_json::Value =
                serde_json::from_str(line).map_err(|e| Error::input(format!("bench output: {e}")))?;
            let s = &v["seconds"];
            let f = |x: &serde_json::Value| x.as_f64().unwrap_or(f64::NAN);
            out += &format!(
            "| {} | {} | {} | {} | {} | {:.1e} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.0} |\n",
            v["case"].as_str().unwrap_or_default(),
            v["input_extrema"],
            v["kept"],
            v["constraints"],
            match v["inner_iterations"].as_u64() {
                Some(cg) if cg > 0 => format!("{} ({cg} CG)", v["iterations"]),
                _ => v["iterations"].to_string(),
            },
            f(&v["gap_over_data"]),
            v["extra"]["read"].as_f64().unwrap_or(0.0),
            v["extra"]["geodesic"].as_f64().unwrap_or(0.0),
            f(&s["persistence"]),
            f(&s["complex"]),
            f(&s["simplify"]),
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
    }
    Ok(out)
}

/// `toposmooth bench --weights MESH[@levels],...`: seconds per weight function (monotone,
/// minimal edge set) for each order, with `handles` point handles placed by farthest-point
/// sampling: one thread per function as the paper measured, and the wall time of all
/// functions on 2 threads.
pub fn bench_weights(cases: &[String], orders: &[u8], handles: usize) -> Result<String> {
    use crate::apps::weights::{weights, WeightSettings};
    use crate::domain::Domain;
    let mut out = String::from(
        "| mesh | vertices | triangles | k | handles | s per function (1 thread) | iterations per function | all functions, 2 threads s | certified |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for case in cases {
        let (file, levels) = match case.rsplit_once('@') {
            Some((f, l)) => {
                (f, l.parse::<usize>().map_err(|_| Error::Usage(format!("bench `{case}`: levels after @")))?)
            }
            None => (case.as_str(), 0),
        };
        let (mut mesh, _) = crate::io::import::read_trimesh(std::path::Path::new(file))?;
        for _ in 0..levels {
            mesh = mesh.subdivide()?;
        }
        let n = mesh.n_vertices();
        let chosen = crate::apps::handles::farthest_points(mesh.positions(), handles);
        let sets: Vec<Vec<usize>> = chosen.iter().map(|&v| vec![v]).collect();
        for &k in orders {
            let one = weights(&mesh, &sets, &WeightSettings { order: k, threads: 1, ..Default::default() })?;
            let two = weights(&mesh, &sets, &WeightSettings { order: k, threads: 2, ..Default::default() })?;
            let m = one.functions.len() as f64;
            let per = one.functions.iter().map(|f| f.seconds).sum::<f64>() / m;
            let its = one.functions.iter().map(|f| f.solver_iterations as f64).sum::<f64>() / m;
            let certified = one.functions.iter().chain(&two.functions).all(|f| f.certificate.passed);
            out += &format!(
                "| {case} | {n} | {} | {k} | {} | {per:.4} | {its:.1} | {:.4} | {} |\n",
                mesh.faces().len(),
                sets.len(),
                two.function_seconds,
                if certified { "all" } else { "NO" }
            );
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quantised_suffix_names_volumes_only() {
        assert_eq!(BenchCase::parse("8x9x10q").unwrap(), BenchCase::Quantised(8, 9, 10));
        assert_eq!(BenchCase::parse("8x9x10").unwrap(), BenchCase::Volume(8, 9, 10));
        for bad in ["1000q", "30x40q", "q", "8x9x10qq", "1x9x10q"] {
            assert!(matches!(BenchCase::parse(bad), Err(Error::Usage(_))), "{bad}");
        }
        let h = quantised_phantom3(12, 10, 8, 1);
        assert_eq!(h.len(), 960);
        assert!(h.iter().all(|&v| v == v.round() && (0.0..=255.0).contains(&v)));
    }
}
