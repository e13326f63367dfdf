//! Which domain a file holds: by its extension, and a CSV by its first line.

use super::field::DomainKind;
use crate::error::{Error, Result};
use std::path::Path;

pub(super) fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Whether a grid file is a raster image (PNG, TIFF): its row 0 is the image's top row, placed
/// at the largest y as ParaView places it ([`raster_grid`]).
pub fn is_raster(path: &Path) -> bool {
    matches!(extension(path).as_str(), "png" | "tif" | "tiff")
}

/// Whether a file is read as a grid.
pub fn is_grid_file(path: &Path, kind: DomainKind) -> Result<bool> {
    Ok(match kind {
        DomainKind::Series | DomainKind::Mesh => false,
        DomainKind::Grid => true,
        DomainKind::Auto => match extension(path).as_str() {
            "vti" | "vtk" | "npy" | "npz" | "png" | "tif" | "tiff" | "nii" => true,
            _ if crate::io::export::is_nifti(path) => true,
            _ => {
                let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.into(), source })?;
                crate::io::content::expect_text(path, &bytes, "CSV text")?;
                let text = String::from_utf8_lossy(&bytes);
                let text = text.trim_start_matches('\u{feff}');
                let dialect = crate::io::csv_dialect::sniff(text);
                let first = text.lines().map(str::trim).find(|l| !l.is_empty()).unwrap_or("");
                let cells: Vec<&str> = first.split(char::from(dialect.delimiter)).collect();
                cells.len() >= 3 && cells.iter().all(|c| dialect.number(c).is_some())
            }
        },
    })
}
