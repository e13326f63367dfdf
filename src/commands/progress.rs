//! The tool's progress on standard error: on a terminal, a spinner for the stage in progress
//! (how far it is, where known, and what it does now: the round, the iteration and its gap)
//! above which each finished stage stays as one line; elsewhere (a log, a pipe) one line per
//! finished stage and, once a stage has run for [`LINES_AFTER`], a line each time it passes a
//! further tenth of its work, and a line at least every [`LINES_EVERY`] while it runs (what it
//! last said, how far it is: a log of a long run is never silent). `--quiet` silences both.

use crate::progress::Observer;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::HashMap;
use std::io::{IsTerminal, Write};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// How long a stage runs before a log gets lines of its progress.
pub const LINES_AFTER: Duration = Duration::from_secs(1);

/// The longest a log goes without a line while a stage runs (`TOPOSMOOTH_LOG_EVERY` seconds
/// overrides it, for tests).
pub const LINES_EVERY: Duration = Duration::from_secs(10);

fn lines_every() -> Duration {
    std::env::var("TOPOSMOOTH_LOG_EVERY")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .map_or(LINES_EVERY, Duration::from_secs_f64)
}

/// A stage in progress as the log lines follow it: when it began, what it last said, the
/// tenth of its work last printed (and the fraction itself), when its last line was printed.
struct Running {
    since: Instant,
    message: String,
    tenth: i64,
    fraction: Option<f64>,
    last_line: Instant,
}

/// How progress is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProgressMode {
    /// Nothing.
    Quiet,
    /// One line per finished stage.
    Lines,
    /// A spinner and a line per finished stage.
    Bar,
}

impl ProgressMode {
    /// `Quiet` when asked, `Bar` when standard error is a terminal, `Lines` otherwise.
    pub fn detect(quiet: bool) -> Self {
        if quiet {
            ProgressMode::Quiet
        } else if std::io::stderr().is_terminal() {
            ProgressMode::Bar
        } else {
            ProgressMode::Lines
        }
    }
}

/// The observer the tool installs for a command.
pub struct Stderr {
    mode: ProgressMode,
    /// The spinner and the stages open (nested: the complex inside the representative).
    state: Mutex<(Option<ProgressBar>, Vec<String>)>,
    /// The stages open, for the log's lines and the spinner's percentage.
    running: Mutex<HashMap<String, Running>>,
}

impl Stderr {
    /// An observer showing progress in `mode`.
    pub fn new(mode: ProgressMode) -> Arc<Self> {
        Arc::new(Stderr { mode, state: Mutex::new((None, Vec::new())), running: Mutex::new(HashMap::new()) })
    }

    /// Prints `text` as a line of its own (the input's summary), above the spinner if any.
    pub fn line(&self, text: &str) {
        if self.mode == ProgressMode::Quiet {
            return;
        }
        let state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match &state.0 {
            Some(bar) => bar.println(text),
            None => {
                let _ = writeln!(std::io::stderr(), "{text}");
            }
        }
    }

    /// The lines of the stages that have printed nothing for `every` (a log's heartbeat): the
    /// stage, how long it has run, how far it is and what it last said.
    fn stale(&self, every: Duration) -> Vec<String> {
        let mut running = self.running.lock().unwrap_or_else(|e| e.into_inner());
        let mut lines: Vec<(Instant, String)> = running
            .iter_mut()
            .filter(|(_, r)| r.last_line.elapsed() >= every)
            .map(|(stage, r)| {
                r.last_line = Instant::now();
                let mut line = format!("{stage}: running for {}", seconds_text(r.since.elapsed().as_secs_f64()));
                if let Some(f) = r.fraction {
                    line.push_str(&format!(", {:.0} %", 100.0 * f));
                }
                if !r.message.is_empty() {
                    line.push_str(&format!(" ({})", r.message));
                }
                (r.since, line)
            })
            .collect();
        lines.sort();
        lines.into_iter().map(|(_, l)| l).collect()
    }

    /// Removes the spinner (before an error or the summary is printed).
    pub fn clear(&self) {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(bar) = state.0.take() {
            bar.finish_and_clear();
        }
        state.1.clear();
    }
}

impl Observer for Stderr {
    fn begin(&self, stage: &str) {
        if self.mode != ProgressMode::Quiet {
            let mut running = self.running.lock().unwrap_or_else(|e| e.into_inner());
            let now = Instant::now();
            let r = Running { since: now, message: String::new(), tenth: -1, fraction: None, last_line: now };
            running.insert(stage.to_string(), r);
        }
        if self.mode != ProgressMode::Bar {
            return;
        }
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        state.1.push(stage.to_string());
        let bar = state.0.get_or_insert_with(|| {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template("{spinner} {prefix}: {wide_msg} [{elapsed}]")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.enable_steady_tick(Duration::from_millis(120));
            bar
        });
        bar.set_prefix(stage.to_string());
        bar.set_message("");
    }

    fn update(&self, stage: &str, message: &str) {
        if self.mode == ProgressMode::Quiet {
            return;
        }
        let tenth = {
            let mut running = self.running.lock().unwrap_or_else(|e| e.into_inner());
            running.get_mut(stage).map(|r| {
                r.message = message.to_string();
                r.tenth
            })
        };
        if self.mode != ProgressMode::Bar {
            return;
        }
        let message = match tenth {
            Some(t) if t >= 0 => format!("{} % · {message}", (t * 10).min(100)),
            _ => message.to_string(),
        };
        let state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(bar) = &state.0 {
            bar.set_prefix(stage.to_string());
            bar.set_message(message.to_string());
        }
    }

    fn fraction(&self, stage: &str, done: f64) {
        if self.mode == ProgressMode::Quiet {
            return;
        }
        let tenth = (done.clamp(0.0, 1.0) * 10.0).floor() as i64;
        let line = {
            let mut running = self.running.lock().unwrap_or_else(|e| e.into_inner());
            let Some(r) = running.get_mut(stage) else { return };
            r.fraction = Some(done);
            // the log prints each tenth once, the furthest reached; the spinner shows the fraction
            // now (it may go back: a solver handing over to another)
            let passed = tenth > r.tenth;
            r.tenth = if passed || self.mode == ProgressMode::Bar { tenth } else { r.tenth };
            (self.mode == ProgressMode::Lines && passed && r.since.elapsed() >= LINES_AFTER).then(|| {
                r.last_line = Instant::now();
                let elapsed = seconds_text(r.since.elapsed().as_secs_f64());
                match r.message.is_empty() {
                    true => format!("{stage}: {} % after {elapsed}", tenth * 10),
                    false => format!("{stage}: {} % after {elapsed} ({})", tenth * 10, r.message),
                }
            })
        };
        if let Some(line) = line {
            let _ = writeln!(std::io::stderr(), "{line}");
        }
    }

    fn end(&self, stage: &str, seconds: f64, summary: &str) {
        self.running.lock().unwrap_or_else(|e| e.into_inner()).remove(stage);
        let text = if summary.is_empty() {
            format!("{stage}: {}", seconds_text(seconds))
        } else {
            format!("{stage}: {} ({summary})", seconds_text(seconds))
        };
        match self.mode {
            ProgressMode::Quiet => {}
            ProgressMode::Lines => {
                let _ = writeln!(std::io::stderr(), "{text}");
            }
            ProgressMode::Bar => {
                let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
                if let Some(i) = state.1.iter().rposition(|s| s == stage) {
                    state.1.remove(i);
                }
                let outer = state.1.last().cloned();
                if let Some(bar) = &state.0 {
                    bar.println(&text);
                    if let Some(outer) = outer {
                        bar.set_prefix(outer);
                        bar.set_message("");
                    }
                }
                if state.1.is_empty() {
                    // no spinner between stages
                    if let Some(bar) = state.0.take() {
                        bar.finish_and_clear();
                    }
                }
            }
        }
    }

    fn abandon(&self, stage: &str) {
        self.running.lock().unwrap_or_else(|e| e.into_inner()).remove(stage);
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = state.1.iter().rposition(|s| s == stage) {
            state.1.remove(i);
        }
        if state.1.is_empty() {
            if let Some(bar) = state.0.take() {
                bar.finish_and_clear();
            }
        }
    }
}

static INSTALLED: OnceLock<Arc<Stderr>> = OnceLock::new();

/// Runs `work` with progress shown in `mode` (the tool's commands: once per process).
pub fn with_progress<R>(mode: ProgressMode, work: impl FnOnce() -> R) -> R {
    let observer = INSTALLED.get_or_init(|| Stderr::new(mode)).clone();
    // a log's heartbeat: a thread that prints the stages silent for `lines_every`
    let done = Arc::new((Mutex::new(false), std::sync::Condvar::new()));
    let heartbeat = (mode == ProgressMode::Lines).then(|| {
        let (observer, done, every) = (observer.clone(), done.clone(), lines_every());
        let tick = (every / 4).clamp(Duration::from_millis(20), Duration::from_secs(1));
        std::thread::spawn(move || loop {
            let stop = done.0.lock().unwrap_or_else(|e| e.into_inner());
            let (stop, _) = done.1.wait_timeout_while(stop, tick, |d| !*d).unwrap_or_else(|e| e.into_inner());
            if *stop {
                break;
            }
            drop(stop);
            for line in observer.stale(every) {
                let _ = writeln!(std::io::stderr(), "{line}");
            }
        })
    });
    let out = crate::progress::observe(observer.clone(), work);
    *done.0.lock().unwrap_or_else(|e| e.into_inner()) = true;
    done.1.notify_all();
    if let Some(h) = heartbeat {
        let _ = h.join();
    }
    observer.clear();
    out
}

/// Prints `text` on standard error as progress does (nothing with `--quiet`): the input's
/// summary before the work starts.
pub fn line(text: &str) {
    match INSTALLED.get() {
        Some(o) => o.line(text),
        None => eprintln!("{text}"),
    }
}

/// Seconds as a person reads them: `0.42 s`, `3.1 s`, `2 min 05 s`.
fn seconds_text(s: f64) -> String {
    if s < 10.0 {
        format!("{s:.2} s")
    } else if s < 100.0 {
        format!("{s:.1} s")
    } else {
        let whole = s.round() as u64;
        format!("{} min {:02} s", whole / 60, whole % 60)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_read_as_a_person_reads_them() {
        assert_eq!(seconds_text(0.4249), "0.42 s");
        assert_eq!(seconds_text(31.26), "31.3 s");
        assert_eq!(seconds_text(125.4), "2 min 05 s");
    }
}
