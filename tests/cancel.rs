//! Stopping a run: a cancellation token cancelled from another thread while a 300 × 300 noisy
//! grid is being solved ends the run with `Error::Cancelled` (the library, and the command run
//! in process as the Python package runs it, which leaves no temporary and no output); the
//! progress of a finished run reaches 1 and stays within [0, 1].

mod common;

use std::sync::mpsc::{channel, Sender};
use std::sync::{Arc, Mutex};
use toposmooth::progress::{cancellable, observe, CancelToken, Observer};
use toposmooth::{Error, Grid2d, Selection, SmoothSettings};

/// Sends each stage's name when it begins; records every fraction told.
struct Watch {
    began: Mutex<Sender<String>>,
    fractions: Mutex<Vec<(String, f64)>>,
}

impl Observer for Watch {
    fn begin(&self, stage: &str) {
        let _ = self.began.lock().unwrap().send(stage.to_string());
    }
    fn update(&self, _: &str, _: &str) {}
    fn end(&self, _: &str, _: f64, _: &str) {}
    fn fraction(&self, stage: &str, done: f64) {
        self.fractions.lock().unwrap().push((stage.to_string(), done));
    }
}

fn noisy(n: usize) -> Vec<f64> {
    let noise = common::uniform(11, n * n);
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64 / n as f64, (i / n) as f64 / n as f64);
            (6.0 * x).sin() * (5.0 * y).cos() + 0.3 * noise[i]
        })
        .collect()
}

/// Runs `work` under a token that another thread cancels as soon as the stage `at` begins.
fn cancelled_at<R: Send>(at: &'static str, work: impl FnOnce() -> R + Send) -> (R, Vec<String>) {
    let (tx, rx) = channel();
    let watch = Arc::new(Watch { began: Mutex::new(tx), fractions: Mutex::new(Vec::new()) });
    let token = CancelToken::new();
    let canceller = {
        let token = token.clone();
        std::thread::spawn(move || {
            let mut seen = Vec::new();
            for stage in rx {
                seen.push(stage.clone());
                if stage == at {
                    token.cancel();
                }
            }
            seen
        })
    };
    let out =
        std::thread::scope(|s| s.spawn(|| cancellable(token.clone(), || observe(watch.clone(), work))).join().unwrap());
    drop(watch); // closes the channel
    (out, canceller.join().unwrap())
}

#[test]
fn a_grid_run_cancelled_from_another_thread_during_the_solve_ends_cancelled() {
    let n = 300;
    let h = noisy(n);
    let settings = SmoothSettings { selection: Selection::Relative(0.01), ..Default::default() };
    let grid = Grid2d::new(n, n).unwrap();
    let (out, stages) = cancelled_at("solve", || toposmooth::smooth(&grid, &h, &settings));
    assert!(matches!(out, Err(Error::Cancelled)), "{:?}", out.map(|o| o.report.solver_iterations));
    assert!(stages.contains(&"solve".to_string()), "{stages:?}");
    assert!(!stages.contains(&"certificate".to_string()), "stopped before the certificate: {stages:?}");
    assert_eq!(Error::Cancelled.exit_code(), 130);
}

#[test]
fn a_command_cancelled_in_process_leaves_no_temporary_and_no_output() {
    let dir = common::scratch("cancel-in-process");
    let n = 300;
    let rows: Vec<String> =
        noisy(n).chunks(n).map(|r| r.iter().map(|v| format!("{v}")).collect::<Vec<_>>().join(",")).collect();
    let input = dir.join("noise.csv");
    std::fs::write(&input, rows.join("\n") + "\n").unwrap();
    let out = dir.join("out.vti");
    let report = dir.join("run.json");
    let args: Vec<String> = ["smooth", input.to_str().unwrap(), "-o", out.to_str().unwrap()]
        .iter()
        .chain(&["--persistence", "1%", "--report", report.to_str().unwrap()])
        .map(|s| s.to_string())
        .collect();
    let (result, stages) = cancelled_at("solve", || toposmooth::commands::cli::run_args(&args));
    assert!(matches!(result, Err(Error::Cancelled)), "{result:?}");
    assert!(stages.contains(&"solve".to_string()), "{stages:?}");
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name != "noise.csv")
        .collect();
    assert!(left.is_empty(), "nothing but the input is left: {left:?}");
}

#[test]
fn a_token_cancelled_before_the_run_stops_it_at_once_and_an_uncancelled_one_changes_nothing() {
    let (n, h) = (40, noisy(40));
    let grid = Grid2d::new(n, n).unwrap();
    let settings = SmoothSettings { selection: Selection::Relative(0.05), ..Default::default() };
    let token = CancelToken::new();
    let plain = toposmooth::smooth(&grid, &h, &settings).unwrap();
    let held = cancellable(token.clone(), || toposmooth::smooth(&grid, &h, &settings)).unwrap();
    assert_eq!(plain.output, held.output, "a token never cancelled changes nothing");
    token.cancel();
    assert!(matches!(cancellable(token, || toposmooth::smooth(&grid, &h, &settings)), Err(Error::Cancelled)));
    // outside `cancellable` no token is checked
    assert!(toposmooth::smooth(&grid, &h, &settings).is_ok());
}

#[test]
fn the_solve_s_fraction_stays_within_0_and_1_and_reaches_1() {
    let (n, h) = (60, noisy(60));
    let grid = Grid2d::new(n, n).unwrap();
    let settings = SmoothSettings { selection: Selection::Relative(0.02), ..Default::default() };
    let (tx, _rx) = channel();
    let watch = Arc::new(Watch { began: Mutex::new(tx), fractions: Mutex::new(Vec::new()) });
    let out = observe(watch.clone(), || toposmooth::smooth(&grid, &h, &settings)).unwrap();
    assert!(out.report.certificate.passed);
    let solve: Vec<f64> = watch.fractions.lock().unwrap().iter().filter(|(s, _)| s == "solve").map(|f| f.1).collect();
    assert!(solve.len() >= 3, "one per iteration: {solve:?}");
    assert!(solve.iter().all(|f| (0.0..=1.0).contains(f)), "{solve:?}");
    assert_eq!(solve[0], 0.0, "the first iterate is where the scale starts");
    assert_eq!(solve.iter().copied().fold(0.0, f64::max), 1.0, "the target is reached: {solve:?}");
}
