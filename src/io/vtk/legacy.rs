//! The legacy `.vtk` `STRUCTURED_POINTS` reader (vtkio, with origin and spacing re-read as f64).

use super::data::{list_names, ImageData, PointArray};
use crate::error::{Error, Result};

pub(super) fn read_legacy(bytes: &[u8]) -> Result<ImageData> {
    use vtkio::model::{Attribute, DataSet, ElementType, Extent, Piece};
    let vtk = vtkio::Vtk::parse_legacy_be(bytes).map_err(|e| {
        Error::input(format!(
            "cannot parse the legacy VTK file ({e}): it is truncated, malformed or uses a feature vtkio cannot read"
        ))
    })?;
    let DataSet::ImageData { extent, origin, spacing, pieces, .. } = vtk.data else {
        return Err(Error::input("the legacy data set is not STRUCTURED_POINTS; only image data is supported"));
    };
    let dims = match extent {
        Extent::Dims(d) => d.map(|v| v as usize),
        Extent::Ranges(r) => [r[0].clone(), r[1].clone(), r[2].clone()].map(|r| {
            if r.end() >= r.start() {
                (r.end() - r.start() + 1) as usize
            } else {
                0
            }
        }),
    };
    let [nx, ny, nz] = dims;
    if nz > 1 {
        return Err(Error::input(format!(
            "DIMENSIONS {nx} {ny} {nz}: only 2D images (one point along z) are supported"
        )));
    }
    if nx < 2 || ny < 2 || nz < 1 {
        return Err(Error::input(format!("DIMENSIONS {nx} {ny} {nz}: a 2D image needs at least 2 × 2 points")));
    }
    // vtkio keeps origin and spacing as f32: read them again as f64 from the header text
    let (origin64, spacing64) = legacy_geometry(bytes);
    let origin = origin64.unwrap_or([f64::from(origin[0]), f64::from(origin[1])]);
    let spacing = spacing64.unwrap_or([f64::from(spacing[0]), f64::from(spacing[1])]);
    let n = nx * ny;
    let mut arrays = Vec::new();
    let mut cell_names = Vec::new();
    for piece in pieces {
        let Piece::Inline(piece) = piece else {
            return Err(Error::input("the legacy file refers to external pieces"));
        };
        for attr in &piece.data.cell {
            cell_names.push(attr.name().to_string());
        }
        for attr in piece.data.point {
            let mut push = |name: String, comps: usize, buf: &vtkio::IOBuffer| -> Result<()> {
                let values = buf.cast_into::<f64>().ok_or_else(|| {
                    Error::input(format!("point array `{name}` has a data type that cannot be read as numbers"))
                })?;
                if values.len() != n * comps {
                    return Err(Error::input(format!(
                        "point array `{name}` holds {} values, but {n} points × {comps} components need {}",
                        values.len(),
                        n * comps
                    )));
                }
                arrays.push(PointArray { name, components: comps, values });
                Ok(())
            };
            match attr {
                Attribute::DataArray(da) => {
                    if matches!(da.elem, ElementType::LookupTable) {
                        continue; // a colour table, not per-point data
                    }
                    push(da.name.clone(), da.elem.num_comp() as usize, &da.data)?;
                }
                Attribute::Field { data_array, .. } => {
                    for fa in data_array {
                        push(fa.name.clone(), fa.elem as usize, &fa.data)?;
                    }
                }
            }
        }
    }
    if arrays.is_empty() {
        if cell_names.is_empty() {
            return Err(Error::input("the file has no point data"));
        }
        let names: Vec<&str> = cell_names.iter().map(String::as_str).collect();
        return Err(Error::input(format!(
            "the file has cell data only ({}); point data is needed (ParaView: Cell Data to Point Data)",
            list_names(&names)
        )));
    }
    Ok(ImageData { nx, ny, spacing, origin, arrays })
}

/// `ORIGIN` and `SPACING` (or `ASPECT_RATIO`) x and y from a legacy header, as f64.
pub(super) fn legacy_geometry(bytes: &[u8]) -> (Option<[f64; 2]>, Option<[f64; 2]>) {
    let (mut origin, mut spacing) = (None, None);
    for line in bytes.split(|&b| b == b'\n').take(64) {
        let Ok(line) = std::str::from_utf8(line) else { continue };
        let mut tok = line.split_whitespace();
        let key = tok.next().unwrap_or("").to_ascii_uppercase();
        let xy = || {
            let v: Vec<f64> = line.split_whitespace().skip(1).filter_map(|t| t.parse().ok()).collect();
            (v.len() == 3).then(|| [v[0], v[1]])
        };
        match key.as_str() {
            "ORIGIN" => origin = xy(),
            "SPACING" | "ASPECT_RATIO" => spacing = xy(),
            "POINT_DATA" | "CELL_DATA" => break,
            _ => {}
        }
    }
    (origin, spacing)
}
