//! VTK files: reading XML image data (`.vti`), poly data (`.vtp`) and unstructured grids
//! (`.vtu`) and legacy `.vtk` files (structured points, poly data, unstructured grids), and
//! writing `.vti` image data, `.vtp` poly data and `.vtu` grids that ParaView and VTK open.
//!
//! The readers are our own, for every layout VTK writes (see [`xml`] and [`legacy`]): they
//! check every declared size against the bytes present before allocating, and give errors
//! that name the file and where in it. The writers write origin and spacing as the shortest
//! decimal text that reads back to the same double, and every array as Float64,
//! zlib-compressed, base64-encoded inline (header type UInt64), so values round-trip bit for
//! bit.
//!
//! Spacing is written as given, negative included: VTK 9 reads a negative spacing as a grid
//! laid out in the negative direction of that axis (older readers may refuse it).

mod collection;
mod data;
mod decode;
mod image;
mod legacy;
mod legacy_write;
mod write;
mod xml;

pub use collection::{read_pvd, stage_pvd, CollectionEntry};
pub use data::{cell, AnyImage, Cells, Dataset, ImageData, ImageGeometry, PointArray, Scalar, VolumeData};
pub use legacy_write::{stage_legacy, LegacyGeometry};
pub use write::{
    stage_vti, stage_vti_arrays, stage_vtp, stage_vtp_cells, stage_vtu, stage_vtu_cells, tet_cells, triangle_cells,
    ImageBox, OutArray, PolyData,
};

use crate::error::{Error, Result};
use std::path::Path;

/// Reads a 2D image: VTK XML ImageData (`.vti`) or a legacy `.vtk` `STRUCTURED_POINTS` data
/// set, in any encoding VTK writes. A `Direction` that permutes or flips the axes is honoured
/// (see [`ImageData::notes`]). The format is recognised from the content, not the extension.
/// Only point data is read.
///
/// # Errors
/// Input errors naming the file: not a VTK file, a data set that is not image data, more than
/// one point along z, fewer than 2 points along x or y, an oblique direction, several pieces,
/// truncated or corrupt data, array sizes that do not match the extent, an unsupported
/// compressor or data type, non-numeric values, cell data only. I/O errors for an unreadable
/// file.
pub fn read_image(path: &Path) -> Result<ImageData> {
    let ds = read_dataset(path)?;
    image::image_of(ds).map_err(|e| e.in_file(path))
}

/// Reads a 2D image or a volume (as [`read_image`], with more than one point along z
/// allowed): a volume when every axis has at least 2 points.
///
/// # Errors
/// As [`read_image`], except for the number of points along z.
pub fn read_any_image(path: &Path) -> Result<AnyImage> {
    let ds = read_dataset(path)?;
    image::any_image_of(ds).map_err(|e| e.in_file(path))
}

/// Reads any VTK data set the readers know (XML or legacy, recognised from the content).
///
/// # Errors
/// As [`read_image`], for the file's structure and data.
pub fn read_dataset(path: &Path) -> Result<Dataset> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    super::guarded(path, || parse_dataset(&bytes))
}

/// Parses a VTK file's bytes.
///
/// # Errors
/// As [`read_dataset`], without the file name.
pub fn parse_dataset(bytes: &[u8]) -> Result<Dataset> {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    let head = bytes[start..].strip_prefix(b"\xef\xbb\xbf").unwrap_or(&bytes[start..]);
    if bytes.is_empty() {
        Err(Error::input("the file is empty"))
    } else if head.starts_with(b"# vtk DataFile") {
        legacy::read_legacy(&bytes[start..])
    } else if head.starts_with(b"<") {
        xml::read_xml(bytes)
    } else {
        Err(Error::input(
            "neither a VTK XML file (`<?xml ...` / `<VTKFile ...`) nor a legacy VTK file (`# vtk DataFile ...`)",
        ))
    }
}

#[cfg(test)]
mod tests;
