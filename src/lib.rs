//! # toposmooth
//!
//! Smooth a scalar field while controlling its extrema: the output has exactly the kept
//! minima and maxima, at their places and input values, and a certificate proves it
//! (Jacobson, Weinkauf & Sorkine 2012, "Smooth Shape-Aware Functions with Controlled Extrema").
//!
//! Layers (arrow = "is used by"): `domain → {operators, topology} → representative →
//! constraints → solve → verify → pipeline → cli`; `io` and `plot` see only `domain` and the
//! pipeline's report.
#![warn(missing_docs)]

pub mod apps;
pub mod domain;
pub mod error;
pub mod operators;
pub mod topology;

pub use error::{Error, Result};
pub mod commands;
pub mod constraints;
pub mod derive;
pub mod harmonic_order;
pub mod io;
pub mod linalg;
pub mod pipeline;
pub mod plot;
pub mod representative;
pub mod solve;
pub mod verify;
