//! VTK files: reading 2D image data (XML `.vti` and legacy `.vtk` `STRUCTURED_POINTS`) and
//! writing `.vti` image data and `.vtp` poly data that ParaView and VTK open.
//!
//! The XML reader is our own (quick-xml for the markup): it reads every layout VTK writes,
//! including raw appended data, which vtkio cannot read. Legacy files are parsed with vtkio;
//! their origin and spacing are re-read from the header text as f64 because vtkio keeps them
//! as f32. The writers are our own too, because vtkio stores origin and spacing as f32: ours
//! write them as the shortest decimal text that reads back to the same double, and every
//! array as Float64, zlib-compressed, base64-encoded inline (header type UInt64), so values
//! round-trip bit for bit.
//!
//! Spacing is written as given, negative included: VTK 9 reads a negative spacing as a grid
//! laid out in the negative direction of that axis (older readers may refuse it).

mod data;
mod legacy;
mod write;
mod xml;

pub use data::{ImageData, PointArray};
pub use write::{stage_vti, stage_vtp, stage_vtu, PolyData};

use crate::error::{Error, Result};
use std::path::Path;

/// Reads a 2D image: VTK XML ImageData (`.vti`; ascii, inline binary, appended base64 or raw;
/// uncompressed or `vtkZLibDataCompressor`; UInt32 or UInt64 headers; either byte order; any
/// numeric type) or a legacy `.vtk` `STRUCTURED_POINTS` data set (ASCII or big-endian BINARY;
/// `SCALARS`, `VECTORS`, `NORMALS`, `TEXTURE_COORDINATES`, `TENSORS`, `FIELD` point data). The
/// format is recognised from the content, not the extension. Only point data is read.
///
/// # Errors
/// Input errors naming the file: not a VTK file, a data set that is not image data, more than
/// one point along z, fewer than 2 points along x or y, several pieces, truncated or corrupt
/// data, array sizes that do not match the extent, an unsupported compressor or data type,
/// non-numeric values, cell data only. I/O errors for an unreadable file.
pub fn read_image(path: &Path) -> Result<ImageData> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    let head = bytes[start..].strip_prefix(b"\xef\xbb\xbf").unwrap_or(&bytes[start..]);
    let result = if head.starts_with(b"# vtk DataFile") {
        legacy::read_legacy(&bytes)
    } else if head.starts_with(b"<") {
        xml::read_xml(&bytes)
    } else {
        Err(Error::input(
            "neither a VTK XML file (`<?xml ...` / `<VTKFile ...`) nor a legacy VTK file (`# vtk DataFile ...`)",
        ))
    };
    result.map_err(|e| e.in_file(path))
}

#[cfg(test)]
mod tests;
