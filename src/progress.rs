//! Progress of the stages that can take long (the complex, the representative's rounds, the
//! solver's iterations with their gap), told to an [`Observer`] the caller installs for the
//! calling thread with [`observe`]. Without one nothing is formatted and nothing is printed:
//! the library never writes to a terminal itself; the command-line tool draws the bars.
//!
//! ```
//! use std::sync::{Arc, Mutex};
//! use toposmooth::progress::{observe, Observer};
//! use toposmooth::{domain::Series, pipeline::{smooth, SmoothSettings}, topology::Selection};
//!
//! #[derive(Default)]
//! struct Stages(Mutex<Vec<String>>);
//! impl Observer for Stages {
//!     fn begin(&self, _: &str) {}
//!     fn update(&self, _: &str, _: &str) {}
//!     fn end(&self, stage: &str, _: f64, _: &str) { self.0.lock().unwrap().push(stage.to_string()) }
//! }
//! let h: Vec<f64> = (0..40).map(|i| i as f64 + if i % 2 == 0 { 0.3 } else { -0.3 }).collect();
//! let settings = SmoothSettings { selection: Selection::Relative(0.5), ..Default::default() };
//! let stages = Arc::new(Stages::default());
//! observe(stages.clone(), || smooth(&Series::uniform(40), &h, &settings))?;
//! assert_eq!(*stages.0.lock().unwrap(), ["selection", "representative", "solve", "certificate"]);
//! # Ok::<(), toposmooth::Error>(())
//! ```

use std::cell::RefCell;
use std::sync::Arc;
use std::time::Instant;

/// Receives the stages of a run as they happen. Calls come from the thread that installed
/// the observer (the solver's own callbacks included).
pub trait Observer: Send + Sync {
    /// A stage begins (`"complex"`, `"representative"`, `"solve"`, …).
    fn begin(&self, stage: &str);
    /// What the stage is doing now (a round, an iteration and its gap).
    fn update(&self, stage: &str, message: &str);
    /// The stage ended after `seconds` with `summary` (possibly empty).
    fn end(&self, stage: &str, seconds: f64, summary: &str);
    /// The stage stopped on an error (the error itself is reported by the caller).
    fn abandon(&self, _stage: &str) {}
}

thread_local! {
    static CURRENT: RefCell<Option<Arc<dyn Observer>>> = const { RefCell::new(None) };
}

/// Runs `work` with `observer` told the stages that run on this thread; the observer in place
/// before (if any) is restored afterwards, also when `work` panics.
pub fn observe<R>(observer: Arc<dyn Observer>, work: impl FnOnce() -> R) -> R {
    struct Restore(Option<Arc<dyn Observer>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            CURRENT.with(|c| *c.borrow_mut() = previous);
        }
    }
    let _restore = Restore(CURRENT.with(|c| c.borrow_mut().replace(observer)));
    work()
}

/// The observer installed on this thread.
pub(crate) fn current() -> Option<Arc<dyn Observer>> {
    CURRENT.with(|c| c.borrow().clone())
}

/// A stage in progress: [`Stage::end`] tells its summary; dropped without it (an error on the
/// way), it is abandoned.
pub struct Stage {
    name: &'static str,
    observer: Option<Arc<dyn Observer>>,
    start: Instant,
}

impl Stage {
    /// Begins stage `name` for the observer of this thread (if any).
    pub fn begin(name: &'static str) -> Self {
        let observer = current();
        if let Some(o) = &observer {
            o.begin(name);
        }
        Stage { name, observer, start: Instant::now() }
    }

    /// Tells what the stage does now; `message` is formatted only when someone listens.
    pub fn update(&self, message: impl FnOnce() -> String) {
        if let Some(o) = &self.observer {
            o.update(self.name, &message());
        }
    }

    /// Ends the stage with `summary`; returns its seconds.
    pub fn end(mut self, summary: impl FnOnce() -> String) -> f64 {
        let seconds = self.start.elapsed().as_secs_f64();
        if let Some(o) = self.observer.take() {
            o.end(self.name, seconds, &summary());
        }
        seconds
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        if let Some(o) = self.observer.take() {
            o.abandon(self.name);
        }
    }
}

/// Tells the current stage's observer (if any) `message` without holding a [`Stage`]: for
/// code deep inside a stage (the solver's iterations).
pub(crate) fn update(stage: &'static str, message: impl FnOnce() -> String) {
    if let Some(o) = current() {
        o.update(stage, &message());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[derive(Default)]
    struct Log(Mutex<Vec<String>>);
    impl Observer for Log {
        fn begin(&self, stage: &str) {
            self.0.lock().unwrap().push(format!("begin {stage}"));
        }
        fn update(&self, stage: &str, message: &str) {
            self.0.lock().unwrap().push(format!("{stage}: {message}"));
        }
        fn end(&self, stage: &str, _: f64, summary: &str) {
            self.0.lock().unwrap().push(format!("end {stage} {summary}"));
        }
        fn abandon(&self, stage: &str) {
            self.0.lock().unwrap().push(format!("abandon {stage}"));
        }
    }

    #[test]
    fn stages_reach_the_installed_observer_and_only_on_its_thread() {
        let log = Arc::new(Log::default());
        observe(log.clone(), || {
            let s = Stage::begin("solve");
            s.update(|| "iteration 1".into());
            update("solve", || "iteration 2".into());
            std::thread::spawn(|| update("solve", || "elsewhere".into())).join().unwrap();
            s.end(|| "done".into());
            drop(Stage::begin("write"));
        });
        // outside `observe` nothing is told, and nothing formatted
        update("solve", || panic!("formatted without an observer"));
        assert_eq!(
            *log.0.lock().unwrap(),
            [
                "begin solve",
                "solve: iteration 1",
                "solve: iteration 2",
                "end solve done",
                "begin write",
                "abandon write"
            ]
        );
    }
}
