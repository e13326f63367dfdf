//! Errors of the library and the exit codes of the command-line tool (SPEC.md, "Exit status").
//!
//! Bad input, settings and infeasible requests are `Err` values; a solver outcome that cannot
//! be certified is an `Err` too, so no caller can print success for it.

use std::path::PathBuf;

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
        /// What is wrong, with the first offending rows or vertices.
        message: String,
    },
    /// The requested kept set is not realizable by any strict function, or needs a margin
    /// floating point cannot represent (exit 3).
    #[error("{}infeasible request: {message}", prefix(path))]
    Infeasible {
        /// File the input came from, if any.
        path: Option<PathBuf>,
        /// Which extrema conflict.
        message: String,
    },
    /// Invalid combination of settings (exit 2).
    #[error("usage: {0}")]
    Usage(String),
    /// The representative function could not be built for a kept set chosen by persistence:
    /// always our bug or a numerical failure (exit 1).
    #[error("{}representative function failed: {message}", prefix(path))]
    Representative {
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

fn prefix(path: &Option<PathBuf>) -> String {
    match path {
        Some(p) => format!("{}: ", p.display()),
        None => String::new(),
    }
}

impl Error {
    /// An input error without a file (the caller attaches one with [`Error::in_file`]).
    pub fn input(message: impl Into<String>) -> Self {
        Error::Input { path: None, message: message.into() }
    }

    /// An infeasibility error without a file.
    pub fn infeasible(message: impl Into<String>) -> Self {
        Error::Infeasible { path: None, message: message.into() }
    }

    /// Attaches `file` to an error that does not name one yet.
    pub fn in_file(mut self, file: impl Into<PathBuf>) -> Self {
        match &mut self {
            Error::Input { path, .. }
            | Error::Infeasible { path, .. }
            | Error::Representative { path, .. }
            | Error::Uncertified { path, .. }
            | Error::NoSolution { path, .. } => {
                if path.is_none() {
                    *path = Some(file.into());
                }
            }
            Error::Usage(_) | Error::Io { .. } => {}
        }
        self
    }

    /// Exit status of the command-line tool for this error (SPEC.md).
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Uncertified { .. } | Error::Representative { .. } => 1,
            Error::Usage(_) => 2,
            Error::Input { .. } | Error::Infeasible { .. } | Error::Io { .. } => 3,
            Error::NoSolution { .. } => 4,
        }
    }
}
