//! The image data a VTK reader returns.

use crate::domain::Grid2d;
use crate::error::{Error, Result};
use std::path::Path;

/// A 2D image read from a VTK file: `nx × ny` points, x fastest (flat index `row · nx + col`,
/// row 0 = the lowest y index of the extent).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageData {
    /// Points along x.
    pub nx: usize,
    /// Points along y.
    pub ny: usize,
    /// Spacing along x and y.
    pub spacing: [f64; 2],
    /// Position of point (row 0, column 0): the file's origin shifted by the extent's start.
    pub origin: [f64; 2],
    /// Point data arrays, in file order.
    pub arrays: Vec<PointArray>,
}

/// One point data array, converted to f64.
#[derive(Clone, Debug, PartialEq)]
pub struct PointArray {
    /// The array's name (`Name` attribute, or the legacy attribute name).
    pub name: String,
    /// Components per point.
    pub components: usize,
    /// `nx · ny · components` values, components interleaved.
    pub values: Vec<f64>,
}

impl PointArray {
    /// Component `k` of every point.
    pub fn component(&self, k: usize) -> Vec<f64> {
        self.values.iter().skip(k).step_by(self.components.max(1)).copied().collect()
    }

    /// Euclidean norm of each point's tuple.
    pub fn magnitude(&self) -> Vec<f64> {
        self.values.chunks(self.components.max(1)).map(|t| t.iter().map(|v| v * v).sum::<f64>().sqrt()).collect()
    }
}

impl ImageData {
    /// Names of the point arrays, in file order.
    pub fn names(&self) -> Vec<&str> {
        self.arrays.iter().map(|a| a.name.as_str()).collect()
    }

    /// The point array called `name`.
    ///
    /// # Errors
    /// An input error listing the available names when there is none of that name.
    pub fn array(&self, name: &str) -> Result<&PointArray> {
        self.arrays.iter().find(|a| a.name == name).ok_or_else(|| {
            Error::input(format!("no point array named `{name}`; the file has: {}", list_names(&self.names())))
        })
    }

    /// The image's grid.
    ///
    /// # Errors
    /// A spacing or origin that [`Grid2d::with_geometry`] refuses (zero or non-finite).
    pub fn grid(&self) -> Result<Grid2d> {
        Grid2d::with_geometry(self.nx, self.ny, self.spacing, self.origin)
    }
}

pub(super) fn list_names(names: &[&str]) -> String {
    if names.is_empty() {
        "no point arrays".into()
    } else {
        names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
    }
}

pub(super) fn input(path: &Path, msg: impl Into<String>) -> Error {
    Error::input(msg).in_file(path)
}
