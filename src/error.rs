//! Errors of the library and the exit codes of the command-line tool (SPEC.md, "Exit status").
//!
//! Bad input, settings and infeasible requests are `Err` values; a solver outcome that cannot
//! be certified is an `Err` too, so no caller can print success for it.

use std::path::{Path, PathBuf};

/// Result with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong, grouped by the exit status it maps to.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Unreadable or malformed input (exit 3). `path` names the file when one is known.
    #[error("{}{message}", prefix(path))]
    Input {
        /// File the input came from, if any.
        path: Option<PathBuf>,
        /// The first offending element, when the error has one (the message names it too).
        at: Option<Location>,
        /// What is wrong, with the first offending rows or vertices.
        message: String,
    },
    /// The requested kept set is not realizable by any strict function, or needs a margin
    /// floating point cannot represent (exit 3).
    #[error("{}infeasible request: {message}", prefix(path))]
    Infeasible {
        /// File the input came from, if any.
        path: Option<PathBuf>,
        /// The first vertex in conflict, when one is.
        at: Option<Location>,
        /// Which extrema conflict.
        message: String,
    },
    /// Invalid combination of settings (exit 2).
    #[error("usage: {0}")]
    Usage(String),
    /// A setting out of range or not applicable to the domain (exit 2). `setting` is the
    /// library's name for it (a field of the settings, as the Python keywords spell it); the
    /// command-line tool words it as its flag ([`Error::setting`] makes one).
    #[error("usage: {setting}: {message}")]
    Setting {
        /// The setting's name in the library (`data_weight`, `pairs`, `max_area`, …).
        setting: &'static str,
        /// What is wrong with it, without naming it.
        message: String,
    },
    /// The representative function could not be built for a kept set chosen by persistence:
    /// always our bug or a numerical failure (exit 1).
    #[error("{}representative function failed: {message}", prefix(path))]
    Representative {
        /// File the input came from, if any.
        path: Option<PathBuf>,
        /// What failed.
        message: String,
    },
    /// A failure on valid input that is our bug or a numerical failure: an internal check
    /// that did not hold, a factorisation of a well-posed system that failed (exit 1).
    #[error("{}internal error: {message}", prefix(path))]
    Internal {
        /// File the input came from, if any.
        path: Option<PathBuf>,
        /// What failed.
        message: String,
    },
    /// The solver returned a point that does not pass the certificate, even after repair (exit 1).
    #[error("{}output NOT certified: {message}", prefix(path))]
    Uncertified {
        /// File the input came from, if any.
        path: Option<PathBuf>,
        /// The failed certificate items and the offending vertices.
        message: String,
    },
    /// The solver returned no point at all (exit 4).
    #[error("{}solver returned no solution: {status}", prefix(path))]
    NoSolution {
        /// File the input came from, if any.
        path: Option<PathBuf>,
        /// Solver status as text.
        status: String,
    },
    /// A route whose predicted peak passes the memory budget, refused before its work (exit 3).
    #[error("{}not enough memory: {message}", prefix(path))]
    Memory {
        /// File the input came from, if any.
        path: Option<PathBuf>,
        /// What would need how much, and the budget.
        message: String,
        /// The predicted peak, bytes.
        predicted: u64,
        /// The budget, bytes.
        budget: u64,
    },
    /// The run was cancelled: the caller's [`crate::progress::CancelToken`], or SIGINT in the
    /// command-line tool (exit 130). Nothing is left behind.
    #[error("cancelled")]
    Cancelled,
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
}

/// A factorisation, solve or solver iteration that failed (faer's words, or the interior-point
/// method's: no convergence, a vanishing step). On a well-posed system it is a numerical
/// failure (a pivot lost to rounding, memory), never bad input: callers report it as
/// an internal error or fall back to another solver.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct NumericalError(pub String);

impl From<String> for NumericalError {
    fn from(message: String) -> Self {
        NumericalError(message)
    }
}

impl From<&str> for NumericalError {
    fn from(message: &str) -> Self {
        NumericalError(message.to_string())
    }
}

impl From<NumericalError> for Error {
    fn from(e: NumericalError) -> Self {
        Error::internal(e.0)
    }
}

/// Why a construction the pipeline may fall back from (a representative function, an ordered
/// harmonic function) could not be made: the reason is reported beside the fallback.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConstructionError {
    /// A linear solve failed.
    #[error(transparent)]
    Numerical(#[from] NumericalError),
    /// The construction does not fit the data or the domain (what, where).
    #[error("{0}")]
    Unfit(String),
}

/// Where in the input an error is: the element a program can point at (a viewer selecting the
/// vertex, an editor jumping to the line).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Location {
    /// A vertex (sample) of the domain, 0-based.
    Vertex(usize),
    /// A triangle (face) of a mesh, 0-based in file order.
    Triangle(usize),
    /// A tetrahedron of a volume mesh, 0-based in file order.
    Tetrahedron(usize),
    /// A line of a text file, 1-based.
    Line(usize),
    /// A byte offset in a file, 0-based.
    Byte(u64),
}

/// What kind of failure an [`Error`] is: one kind per exit status of SPEC.md's "Exit status"
/// (and the failures behind it), for callers that branch on it rather than on the message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// Invalid settings (exit 2).
    Usage,
    /// A file could not be read or written (exit 3).
    Io,
    /// Unreadable or malformed input (exit 3).
    Input,
    /// A kept set no strict function realizes, proven without the representative (exit 3).
    Infeasible,
    /// An output that fails its certificate (exit 1).
    Uncertified,
    /// Our bug or a numerical failure on valid input, the representative's included (exit 1).
    Internal,
    /// The solver returned no point (exit 4).
    NoSolution,
    /// The run was cancelled (exit 130, as a shell reports SIGINT).
    Cancelled,
    /// A run predicted past the memory budget, refused before the work (exit 3).
    Memory,
}

impl ErrorKind {
    /// Exit status of the command-line tool for this kind (SPEC.md).
    pub fn exit_code(self) -> i32 {
        match self {
            ErrorKind::Uncertified | ErrorKind::Internal => 1,
            ErrorKind::Usage => 2,
            ErrorKind::Input | ErrorKind::Infeasible | ErrorKind::Io | ErrorKind::Memory => 3,
            ErrorKind::NoSolution => 4,
            ErrorKind::Cancelled => 130,
        }
    }
}

fn prefix(path: &Option<PathBuf>) -> String {
    match path {
        Some(p) => format!("{}: ", p.display()),
        None => String::new(),
    }
}

impl Error {
    /// An input error without a file (the caller attaches one with [`Error::in_file`]).
    pub fn input(message: impl Into<String>) -> Self {
        Error::Input { path: None, at: None, message: message.into() }
    }

    /// A setting error ([`Error::Setting`]).
    pub fn setting(setting: &'static str, message: impl Into<String>) -> Self {
        Error::Setting { setting, message: message.into() }
    }

    /// An internal error without a file.
    pub fn internal(message: impl Into<String>) -> Self {
        Error::Internal { path: None, message: message.into() }
    }

    /// Records where the error is (input and infeasibility errors; others are unchanged).
    #[must_use]
    pub fn at(mut self, location: Location) -> Self {
        if let Error::Input { at, .. } | Error::Infeasible { at, .. } = &mut self {
            *at = Some(location);
        }
        self
    }

    /// Where the error is, when it names an element.
    pub fn location(&self) -> Option<Location> {
        match self {
            Error::Input { at, .. } | Error::Infeasible { at, .. } => *at,
            _ => None,
        }
    }

    /// An infeasibility error without a file.
    pub fn infeasible(message: impl Into<String>) -> Self {
        Error::Infeasible { path: None, at: None, message: message.into() }
    }

    /// The error with the file `from` called `to` (in its path and its message): a temporary
    /// copy of the input named as the user gave it.
    pub fn renamed(self, from: &Path, to: &Path) -> Self {
        let (from_text, to_text) = (from.display().to_string(), to.display().to_string());
        let text = |m: String| m.replace(&from_text, &to_text);
        let file = |p: Option<PathBuf>| p.map(|p| if p == from { to.to_path_buf() } else { p });
        match self {
            Error::Input { path, at, message } => Error::Input { path: file(path), at, message: text(message) },
            Error::Infeasible { path, at, message } => {
                Error::Infeasible { path: file(path), at, message: text(message) }
            }
            Error::Representative { path, message } => {
                Error::Representative { path: file(path), message: text(message) }
            }
            Error::Internal { path, message } => Error::Internal { path: file(path), message: text(message) },
            Error::Uncertified { path, message } => Error::Uncertified { path: file(path), message: text(message) },
            Error::NoSolution { path, status } => Error::NoSolution { path: file(path), status: text(status) },
            Error::Usage(m) => Error::Usage(text(m)),
            Error::Setting { setting, message } => Error::Setting { setting, message: text(message) },
            Error::Cancelled => Error::Cancelled,
            Error::Memory { path, message, predicted, budget } => {
                Error::Memory { path: file(path), message: text(message), predicted, budget }
            }
            Error::Io { path, source } => {
                Error::Io { path: if path == from { to.to_path_buf() } else { path }, source }
            }
        }
    }

    /// Attaches `file` to an error that does not name one yet.
    pub fn in_file(mut self, file: impl Into<PathBuf>) -> Self {
        match &mut self {
            Error::Input { path, .. }
            | Error::Infeasible { path, .. }
            | Error::Representative { path, .. }
            | Error::Internal { path, .. }
            | Error::Uncertified { path, .. }
            | Error::Memory { path, .. }
            | Error::NoSolution { path, .. } => {
                if path.is_none() {
                    *path = Some(file.into());
                }
            }
            Error::Usage(_) | Error::Setting { .. } | Error::Io { .. } | Error::Cancelled => {}
        }
        self
    }

    /// The kind of failure.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::Usage(_) | Error::Setting { .. } => ErrorKind::Usage,
            Error::Io { .. } => ErrorKind::Io,
            Error::Input { .. } => ErrorKind::Input,
            Error::Infeasible { .. } => ErrorKind::Infeasible,
            Error::Uncertified { .. } => ErrorKind::Uncertified,
            Error::Representative { .. } | Error::Internal { .. } => ErrorKind::Internal,
            Error::NoSolution { .. } => ErrorKind::NoSolution,
            Error::Cancelled => ErrorKind::Cancelled,
            Error::Memory { .. } => ErrorKind::Memory,
        }
    }

    /// The file the error names, if any.
    pub fn path(&self) -> Option<&std::path::Path> {
        match self {
            Error::Input { path, .. }
            | Error::Infeasible { path, .. }
            | Error::Representative { path, .. }
            | Error::Internal { path, .. }
            | Error::Uncertified { path, .. }
            | Error::Memory { path, .. }
            | Error::NoSolution { path, .. } => path.as_deref(),
            Error::Io { path, .. } => Some(path),
            Error::Usage(_) | Error::Setting { .. } | Error::Cancelled => None,
        }
    }

    /// Exit status of the command-line tool for this error (SPEC.md).
    pub fn exit_code(&self) -> i32 {
        self.kind().exit_code()
    }
}

/// Where and why the last panic happened, as the command-line tool's panic hook records it
/// (`None` where no hook records panics): [`crate::io::guarded`] and the tool's top level
/// put it in their one-line messages instead of the panic's own text.
pub(crate) static LAST_PANIC: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// The last panic recorded by the hook, taken.
pub(crate) fn take_last_panic() -> Option<String> {
    LAST_PANIC.lock().ok().and_then(|mut p| p.take())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_has_the_exit_status_of_the_spec() {
        let io = Error::Io { path: "f".into(), source: std::io::Error::other("x") };
        let cases = [
            (Error::Usage("u".into()), ErrorKind::Usage, 2),
            (Error::setting("data_weight", "must be ≥ 0"), ErrorKind::Usage, 2),
            (io, ErrorKind::Io, 3),
            (Error::input("i"), ErrorKind::Input, 3),
            (Error::infeasible("f"), ErrorKind::Infeasible, 3),
            (Error::Uncertified { path: None, message: "c".into() }, ErrorKind::Uncertified, 1),
            (Error::internal("b"), ErrorKind::Internal, 1),
            (Error::Representative { path: None, message: "r".into() }, ErrorKind::Internal, 1),
            (Error::NoSolution { path: None, status: "s".into() }, ErrorKind::NoSolution, 4),
            (Error::Cancelled, ErrorKind::Cancelled, 130),
            (Error::Memory { path: None, message: "m".into(), predicted: 2, budget: 1 }, ErrorKind::Memory, 3),
        ];
        for (e, kind, code) in cases {
            assert_eq!((e.kind(), e.exit_code()), (kind, code), "{e}");
        }
        let e = Error::internal("check").in_file("a.vti");
        assert_eq!(e.path(), Some(std::path::Path::new("a.vti")));
        assert_eq!(e.to_string(), "a.vti: internal error: check");
    }
}
