//! # toposmooth
//!
//! Smooth a scalar field while controlling its extrema: the output has exactly the kept
//! minima and maxima, at their places and input values, and a certificate proves it
//! (Jacobson, Weinkauf & Sorkine 2012, "Smooth Shape-Aware Functions with Controlled Extrema").
//!
//! Layers (arrow = "is used by"): `domain → {operators, topology} → representative →
//! constraints → solve → verify → pipeline → cli`; `io` and `plot` see only `domain` and the
//! pipeline's report.
//!
//! A grid field smoothed with its pairs below 10 % of the range cancelled, certified:
//!
//! ```
//! use toposmooth::{Grid2d, Selection, SmoothSettings, Smoother};
//!
//! let (nx, ny) = (30, 20);
//! let h: Vec<f64> = (0..nx * ny)
//!     .map(|i| ((i % nx) as f64 * 0.5).sin() * ((i / nx) as f64 * 0.4).cos() + 0.1 * ((i * 7919 % 17) as f64 / 17.0))
//!     .collect();
//! let settings = SmoothSettings { selection: Selection::Relative(0.1), ..Default::default() };
//! let mut smoother = Smoother::new(Grid2d::new(nx, ny)?, settings)?;
//! let out = smoother.smooth(&h)?;
//! assert!(out.report.certificate.passed && out.report.fit.gap_over_data.unwrap() < 1e-6);
//! # Ok::<(), toposmooth::Error>(())
//! ```
#![warn(missing_docs)]

#[cfg(feature = "serde")]
pub mod apps;
pub mod domain;
pub mod error;
pub mod operators;
pub mod topology;

pub use domain::{Grid2d, Series, TriMesh};
pub use error::{Error, ErrorKind, Location, Result};
pub use pipeline::{smooth, SmoothSettings, Smoothed};
pub use smoother::{AnyDomain, AnySmoother, Smoother};
pub use topology::Selection;
#[cfg(feature = "cli")]
pub mod commands;
pub mod constraints;
pub mod derive;
pub mod harmonic_order;
pub mod io;
pub mod linalg;
pub mod pipeline;
#[cfg(feature = "plot")]
pub mod plot;
pub mod representative;
pub mod smoother;
pub mod solve;
pub mod verify;
