//! Series: a CSV column (with its x column or dates) or a NumPy 1-D array, missing values
//! filled linearly in x when asked.

use super::field::{DomainKind, ReadOptions, SeriesInput};
use crate::error::{Error, Result};
use crate::io::npy_input::{read_numpy, NumpyField, Wanted};
use crate::io::series_csv::{read_series, SeriesCsv, SeriesCsvOptions};
use crate::series_fill::fill_missing_series;
use std::path::Path;

/// Reads a series from CSV; with `fill_missing` its missing values (empty cells, NaN) are
/// filled linearly in x ([`fill_missing_series`]) instead of refused.
///
/// # Errors
/// As [`read_series`]; every value missing.
pub fn read_series_input(path: &Path, csv: &SeriesCsvOptions, fill_missing: bool) -> Result<SeriesInput> {
    let options = SeriesCsvOptions { allow_missing: fill_missing, ..csv.clone() };
    let mut data = read_series(path, &options)?;
    let mut filled = None;
    if data.values.iter().any(|v| v.is_nan()) {
        let mask = fill_missing_series(&data.x, &mut data.values).map_err(|e| e.in_file(path))?;
        filled = Some(mask);
    }
    Ok(SeriesInput { data, filled })
}

/// A NumPy file's 1-D array as a series (x = 0, 1, 2, …), filled with `--fill-missing`; `None`
/// when the file's array is a grid (and `kind` allows one).
pub(super) fn numpy_series(
    path: &Path,
    kind: DomainKind,
    csv: &SeriesCsvOptions,
    grid: &ReadOptions,
) -> Result<Option<SeriesInput>> {
    let wanted = if kind == DomainKind::Series { Wanted::Series } else { Wanted::Any };
    let NumpyField::Series { name, mut values } = read_numpy(path, grid.array.as_deref(), wanted)? else {
        return Ok(None);
    };
    if csv.column.is_some() || csv.x_column.is_some() || grid.spacing.is_some() {
        return Err(Error::Usage(format!(
            "{}: a NumPy series is its array, on x = 0, 1, 2, …: --column, --x and --spacing do not apply (choose the array with --array)",
            path.display()
        )));
    }
    let n = values.len();
    let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let mut filled = None;
    if let Some(i) = values.iter().position(|v| v.is_nan()) {
        if !grid.fill_missing {
            let count = values.iter().filter(|v| v.is_nan()).count();
            return Err(Error::input(format!(
                "array `{name}`: {count} missing (NaN) values, the first at index {i}; --fill-missing fills them linearly"
            ))
            .in_file(path));
        }
        filled = Some(fill_missing_series(&x, &mut values).map_err(|e| e.in_file(path))?);
    }
    let data = SeriesCsv {
        column: name,
        values,
        x_text: crate::io::series_csv::XText::Index(n),
        x,
        x_name: "x".into(),
        x_source: crate::io::series_csv::XSource::Index,
    };
    Ok(Some(SeriesInput { data, filled }))
}
