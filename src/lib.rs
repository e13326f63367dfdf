//! # toposmooth
//!
//! Smooth a scalar field while controlling its extrema: the output has exactly the kept
//! minima and maxima, at their places and input values, and a certificate proves it
//! (Jacobson, Weinkauf & Sorkine 2012, "Smooth Shape-Aware Functions with Controlled Extrema").
//!
//! Layers (arrow = "is used by"): `domain → {operators, topology} → representative →
//! constraints → solve → verify → pipeline → smoother → cli`; `io` and `plot` see the domains
//! and the results only.
//!
//! What a program needs is at the root: the domains ([`Grid2d`], [`Series`], [`TriMesh`],
//! [`AnyDomain`]), the one-off [`smooth`] / [`smooth_any`] and the [`Smoother`] /
//! [`AnySmoother`] for many fields on one domain, their settings ([`SmoothSettings`],
//! [`Selection`], [`Energy`], [`EdgeSet`], [`QpSettings`], [`RepresentativeChoice`]), the
//! results ([`Smoothed`], [`Report`], [`Role`]), the independent check ([`certify`],
//! [`Certificate`]) and the errors ([`Error`], [`ErrorKind`], [`Location`]). The readers and
//! writers are in [`io`] (`io::export` for any domain's results), the applications (weights,
//! deformation, colour diffusion, geodesic distance) in `apps`; the linear algebra, the
//! representative functions and the command-line tool are internal.
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

#[macro_use]
mod named;

#[cfg(feature = "serde")]
pub mod apps;
pub mod domain;
pub mod error;
pub mod operators;
pub mod topology;

pub use constraints::EdgeSet;
pub use domain::{AnyDomain, Domain, Grid2d, Series, TriMesh};
pub use error::{ConstructionError, Error, ErrorKind, Location, NumericalError, Result};
pub use linalg::Analyses;
pub use operators::Energy;
pub use pipeline::{
    smooth, smooth_any, smooth_masked, smooth_masked_grid, Report, RepresentativeChoice, SmoothSettings, Smoothed,
};
pub use smoother::{AnySmoother, Smoother};
pub use solve::{Formulation, Method, QpSettings};
pub use topology::{Role, Selection};
pub use verify::{certify, certify_any, Certificate};
/// The command-line tool's commands (the binary's implementation, not a library interface).
#[cfg(feature = "cli")]
#[doc(hidden)]
pub mod commands;
pub mod constraints;
pub mod derive;
pub mod io;
pub(crate) mod linalg;
pub mod memory;
pub mod parallel;
pub mod pipeline;
#[cfg(feature = "plot")]
pub mod plot;
pub mod progress;
pub(crate) mod representative;
pub mod series_fill;
pub mod smoother;
pub mod solve;
pub mod verify;
