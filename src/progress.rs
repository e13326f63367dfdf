//! Progress of the stages that can take long (the complex, the representative's rounds, the
//! solver's iterations with their gap, and how far each is where that is known), told to an
//! [`Observer`] the caller installs for the calling thread with [`observe`]. Without one
//! nothing is formatted and nothing is printed: the library never writes to a terminal
//! itself; the command-line tool draws the bars.
//!
//! A run can be stopped: the caller holds a [`CancelToken`], installs it with [`cancellable`]
//! and cancels it from any thread (a signal handler, a "stop" button); the run checks it
//! between stages and inside every iterative loop ([`checkpoint`]) and ends with
//! [`Error::Cancelled`], having written nothing.
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

use crate::error::{Error, Result};
use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
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
    /// How far the stage is, from 0 to 1, where that is known: the solver's gap on a log
    /// scale from its first iterate to its target, the functions of `weights` done, the
    /// inputs of a batch. It may go back (a solver handing over to another).
    fn fraction(&self, _stage: &str, _done: f64) {}
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

/// A flag the caller holds to stop a run: clones share it, [`CancelToken::cancel`] may be
/// called from any thread (also from a signal handler's thread: it only stores a flag).
#[derive(Clone, Debug, Default)]
pub struct CancelToken(Arc<AtomicBool>);

impl CancelToken {
    /// A token not cancelled.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks every run holding this token to stop at its next check.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether [`CancelToken::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

thread_local! {
    static TOKEN: RefCell<Option<CancelToken>> = const { RefCell::new(None) };
}

/// Runs `work` with `token` checked by the runs on this thread (and the threads they split
/// into with [`crate::parallel::join`]); the token in place before is restored afterwards.
pub fn cancellable<R>(token: CancelToken, work: impl FnOnce() -> R) -> R {
    with_token(Some(token), work)
}

/// The token installed on this thread, to carry into a thread the work splits into.
pub(crate) fn token() -> Option<CancelToken> {
    TOKEN.with(|t| t.borrow().clone())
}

/// Runs `work` with `token` (or none) installed on this thread.
pub(crate) fn with_token<R>(token: Option<CancelToken>, work: impl FnOnce() -> R) -> R {
    struct Restore(Option<CancelToken>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            TOKEN.with(|t| *t.borrow_mut() = previous);
        }
    }
    let _restore = Restore(TOKEN.with(|t| std::mem::replace(&mut *t.borrow_mut(), token)));
    work()
}

/// Whether the run on this thread was cancelled.
pub fn cancelled() -> bool {
    TOKEN.with(|t| t.borrow().as_ref().is_some_and(CancelToken::is_cancelled))
}

/// `Err(Error::Cancelled)` once the run on this thread is cancelled: called between stages
/// and in every iterative loop.
///
/// # Errors
/// [`Error::Cancelled`].
pub fn checkpoint() -> Result<()> {
    if cancelled() {
        Err(Error::Cancelled)
    } else {
        Ok(())
    }
}

/// A run's result, [`Error::Cancelled`] if the run was cancelled: a loop that stops on the
/// token ends with its own error (a solver's "stopped"), which must not reach the caller as
/// a failure, nor start a fallback.
pub(crate) fn settle<T>(result: Result<T>) -> Result<T> {
    match result {
        Err(_) if cancelled() => Err(Error::Cancelled),
        r => r,
    }
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

    /// Tells how far the stage is (0 to 1).
    pub fn fraction(&self, done: f64) {
        if let Some(o) = &self.observer {
            o.fraction(self.name, done.clamp(0.0, 1.0));
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

/// Tells the current stage's observer (if any) how far it is, as [`update`] does.
pub(crate) fn fraction(stage: &'static str, done: f64) {
    if let Some(o) = current() {
        o.fraction(stage, done.clamp(0.0, 1.0));
    }
}

/// How far a value that falls on a log scale from `first` towards `target` is (0 at `first`,
/// 1 at or below `target`): an interior-point gap, a largest violation.
pub(crate) fn log_fraction(first: f64, now: f64, target: f64) -> f64 {
    if !(first > target && target > 0.0 && now.is_finite()) {
        return if now <= target { 1.0 } else { 0.0 };
    }
    ((first / now.max(target)).ln() / (first / target).ln()).clamp(0.0, 1.0)
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

    #[test]
    fn a_token_is_seen_on_its_thread_and_the_threads_a_run_splits_into_and_restored_after() {
        let token = CancelToken::new();
        assert!(checkpoint().is_ok(), "no token: never cancelled");
        let seen = cancellable(token.clone(), || {
            assert!(checkpoint().is_ok());
            token.cancel();
            let (here, there) = crate::parallel::with_threads(2, || crate::parallel::join(cancelled, cancelled));
            let elsewhere = std::thread::spawn(cancelled).join().unwrap();
            (here, there, elsewhere, checkpoint())
        });
        assert_eq!((seen.0, seen.1, seen.2), (true, true, false), "join's threads see it, a bare thread does not");
        assert!(matches!(seen.3, Err(Error::Cancelled)));
        assert!(!cancelled() && checkpoint().is_ok(), "restored after the run");
        assert!(matches!(settle::<()>(Err(Error::internal("x"))), Err(Error::Internal { .. })), "not cancelled");
        let r = cancellable(token, || settle::<()>(Err(Error::internal("stopped"))));
        assert!(matches!(r, Err(Error::Cancelled)), "a cancelled run's own error is Cancelled");
        assert_eq!(log_fraction(1e4, 1e4, 1e-6), 0.0);
        assert!((log_fraction(1e4, 1e-1, 1e-6) - 0.5).abs() < 1e-12);
        assert_eq!(log_fraction(1e4, 1e-9, 1e-6), 1.0);
    }
}
