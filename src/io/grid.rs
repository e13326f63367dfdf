//! 2D scalar fields on grids: CSV matrices, NumPy `.npy`, grayscale PNG and TIFF (8/16-bit
//! integers and 32/64-bit floats). Row 0 is the first row the file stores (SPEC.md); NaN is
//! kept (measured fields have holes: the caller decides), infinities are errors.
//!
//! Rasters (PNG, TIFF) are placed as ParaView's image readers place them: pixel (row r,
//! column c) at `(c·dx, (ny−1−r)·dy)` with pixel size dx, dy (1, 1 unless `--spacing` says
//! otherwise), so the image's top row has the largest y ([`raster_grid`]). Indices stay the
//! file's order (row 0 is the top row, as numpy reads the image).

use crate::domain::Grid2d;
use crate::error::{Error, Result};
use std::path::Path;

/// A field read from a file: its grid and one value per vertex in storage order.
#[derive(Clone, Debug, PartialEq)]
pub struct GridField {
    /// The grid (spacing 1 and origin 0 unless the file carries them).
    pub grid: Grid2d,
    /// `nx · ny` values, row by row; NaN marks missing samples.
    pub values: Vec<f64>,
    /// Name of the array read.
    pub array: String,
}

fn err(path: &Path, msg: String) -> Error {
    Error::input(msg).in_file(path)
}

fn io_err(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.to_path_buf(), source }
}

fn finish(path: &Path, nx: usize, ny: usize, values: Vec<f64>, array: String) -> Result<GridField> {
    if let Some(i) = values.iter().position(|v| v.is_infinite()) {
        return Err(err(path, format!("value at row {}, column {} is infinite", i / nx.max(1), i % nx.max(1))));
    }
    let grid = Grid2d::new(nx, ny).map_err(|e| e.in_file(path))?;
    Ok(GridField { grid, values, array })
}

/// The grid of an `nx × ny` raster with pixel size `[dx, dy]`: row 0 (the image's top row) at
/// y = (ny−1)·dy, each next row dy lower, column c at x = c·dx — where ParaView's PNG and TIFF
/// readers put the pixels (they store the bottom row first at y = 0).
///
/// # Errors
/// A grid smaller than 2 × 2 or a spacing out of range.
pub fn raster_grid(nx: usize, ny: usize, pixel: [f64; 2]) -> Result<Grid2d> {
    let top = ny.saturating_sub(1) as f64 * pixel[1];
    Grid2d::with_geometry(nx, ny, [pixel[0], -pixel[1]], [0.0, top])
}

#[cfg(feature = "image")]
fn finish_raster(path: &Path, nx: usize, ny: usize, values: Vec<f64>) -> Result<GridField> {
    let f = finish(path, nx, ny, values, "gray".into())?;
    let grid = raster_grid(nx, ny, [1.0, 1.0]).map_err(|e| e.in_file(path))?;
    Ok(GridField { grid, ..f })
}

/// Reads a CSV matrix: one grid row per line, numbers or `NaN` separated by `,`, `;` or tabs
/// (sniffed; decimal commas with `;` or tabs). A first line with no number at all is taken as
/// a header and skipped.
///
/// # Errors
/// Input errors naming the file and line: rows of different lengths, a cell that is not a
/// number, an infinite value, fewer than 2 rows or columns.
pub fn read_grid_csv(path: &Path) -> Result<GridField> {
    let bytes = std::fs::read(path).map_err(|e| io_err(path, e))?;
    super::content::expect_text(path, &bytes, "a CSV matrix (text)")?;
    let text = String::from_utf8(bytes)
        .map_err(|e| err(path, format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to())))?;
    let dialect = super::csv_dialect::sniff(text.trim_start_matches('\u{feff}'));
    let sep = char::from(dialect.delimiter);
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut nx = 0;
    for (k, line) in text.lines().enumerate() {
        let line = line.trim().trim_start_matches('\u{feff}');
        if line.is_empty() {
            continue;
        }
        let cells: Vec<&str> = line.split(sep).map(str::trim).collect();
        let parsed: Vec<Option<f64>> = cells.iter().map(|c| dialect.number(c)).collect();
        if rows.is_empty() && nx == 0 && parsed.iter().all(Option::is_none) {
            nx = usize::MAX; // header skipped; the next row sets the width
            continue;
        }
        if let Some(j) = parsed.iter().position(Option::is_none) {
            return Err(err(path, format!("line {}: cell {} (`{}`) is not a number", k + 1, j + 1, cells[j])));
        }
        if nx == 0 || nx == usize::MAX {
            nx = cells.len();
        } else if cells.len() != nx {
            return Err(err(path, format!("line {}: {} values, the first row has {nx}", k + 1, cells.len())));
        }
        rows.push(parsed.into_iter().map(|v| v.expect("checked")).collect());
    }
    if rows.is_empty() {
        return Err(err(path, "the file holds no grid rows".into()));
    }
    let ny = rows.len();
    finish(path, nx, ny, rows.concat(), "values".into())
}

/// Reads a 2D NumPy array of shape `(ny, nx)` (C or Fortran order; float, integer or bool).
///
/// # Errors
/// Input errors: not an .npy file, a shape that is not 2D, an unsupported dtype, truncated data.
pub fn read_npy(path: &Path) -> Result<GridField> {
    let bytes = std::fs::read(path).map_err(|e| io_err(path, e))?;
    let ([ny, nx], values) = super::npz::decode_npy(&bytes).map_err(|e| e.in_file(path))?;
    finish(path, nx, ny, values, "values".into())
}

#[cfg(feature = "image")]
/// Reads a grayscale raster: PNG (8/16-bit, via `image`) or TIFF (8/16/32-bit integers and
/// 32/64-bit floats, via `tiff`). Colour images are refused rather than guessed at.
///
/// # Errors
/// Input errors: unreadable or truncated image, colour pixels, unsupported sample type.
pub fn read_raster(path: &Path) -> Result<GridField> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if ext == "tif" || ext == "tiff" {
        return read_tiff(path);
    }
    let img = image::ImageReader::open(path)
        .map_err(|e| io_err(path, e))?
        .with_guessed_format()
        .map_err(|e| io_err(path, e))?
        .decode()
        .map_err(|e| err(path, format!("cannot decode the image: {e}")))?;
    let (nx, ny) = (img.width() as usize, img.height() as usize);
    let values: Vec<f64> = match img {
        image::DynamicImage::ImageLuma8(b) => b.into_raw().into_iter().map(f64::from).collect(),
        image::DynamicImage::ImageLuma16(b) => b.into_raw().into_iter().map(f64::from).collect(),
        other => {
            return Err(err(
                path,
                format!("expected a grayscale image, found {:?}: convert it to grayscale first", other.color()),
            ))
        }
    };
    finish_raster(path, nx, ny, values)
}

#[cfg(feature = "image")]
fn read_tiff(path: &Path) -> Result<GridField> {
    use tiff::decoder::{Decoder, DecodingResult};
    use tiff::ColorType;
    let file = std::fs::File::open(path).map_err(|e| io_err(path, e))?;
    let bad = |e: tiff::TiffError| err(path, format!("cannot decode the TIFF: {e}"));
    let mut dec = Decoder::new(std::io::BufReader::new(file)).map_err(bad)?;
    let (w, h) = dec.dimensions().map_err(bad)?;
    match dec.colortype().map_err(bad)? {
        ColorType::Gray(_) => {}
        other => return Err(err(path, format!("expected a single-channel (grayscale) TIFF, found {other:?}"))),
    }
    let values: Vec<f64> = match dec.read_image().map_err(bad)? {
        DecodingResult::U8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F64(v) => v,
        _ => return Err(err(path, "unsupported TIFF sample type".into())),
    };
    let (nx, ny) = (w as usize, h as usize);
    if values.len() != nx * ny {
        return Err(err(path, format!("{} samples for {nx} × {ny} pixels", values.len())));
    }
    finish_raster(path, nx, ny, values)
}

/// Stages a CSV matrix: one grid row per line, shortest round-trip numbers (a single-array
/// export for scripts; not verifiable alone, SPEC.md).
///
/// # Errors
/// The temporary file cannot be written.
pub fn stage_grid_csv(path: &Path, nx: usize, values: &[f64]) -> Result<super::Staged> {
    super::stage(path, |w| {
        for row in values.chunks(nx) {
            let line: Vec<String> = row.iter().map(|&v| super::format_f64(v)).collect();
            writeln!(w, "{}", line.join(","))?;
        }
        Ok(())
    })
}

#[cfg(all(test, feature = "image"))]
mod tests {
    use super::*;
    use crate::domain::Domain;

    fn dir() -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("toposmooth-grid-io-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A version-1.0 .npy file built by hand from its documented layout.
    fn npy_bytes(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
        let mut header = format!(
            "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}",
            if fortran { "True" } else { "False" }
        );
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend((header.len() as u16).to_le_bytes());
        out.extend(header.as_bytes());
        out.extend(data);
        out
    }

    #[test]
    fn csv_matrix_with_nan_and_header() {
        let p = dir().join("m.csv");
        std::fs::write(&p, "a,b,c\n1,2,3\n4,NaN,6\n").unwrap();
        let f = read_grid_csv(&p).unwrap();
        assert_eq!((f.grid.nx(), f.grid.ny()), (3, 2));
        assert_eq!(f.values[0..3], [1.0, 2.0, 3.0]);
        assert!(f.values[4].is_nan());
        for (name, body, needle) in [
            ("ragged.csv", "1,2,3\n4,5\n", "line 2"),
            ("text.csv", "1,2\n3,x\n", "`x`"),
            ("inf.csv", "1,2\n3,inf\n", "infinite"),
            ("row.csv", "1,2,3\n", "at least 2"),
            ("empty.csv", "", "no grid rows"),
        ] {
            let p = dir().join(name);
            std::fs::write(&p, body).unwrap();
            let e = read_grid_csv(&p).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains(needle), "{name}: {e}");
        }
    }

    #[test]
    fn npy_in_both_orders_and_dtypes() {
        let d = dir();
        let data: Vec<u8> = [1.0f64, 2.0, 3.0, 4.0, 5.0, 6.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(d.join("c.npy"), npy_bytes("<f8", false, "(2, 3)", &data)).unwrap();
        let c = read_npy(&d.join("c.npy")).unwrap();
        assert_eq!((c.grid.nx(), c.grid.ny()), (3, 2));
        assert_eq!(c.values, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        // the same matrix stored column by column
        let f: Vec<u8> = [1.0f64, 4.0, 2.0, 5.0, 3.0, 6.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(d.join("f.npy"), npy_bytes("<f8", true, "(2, 3)", &f)).unwrap();
        assert_eq!(read_npy(&d.join("f.npy")).unwrap().values, c.values);
        let i: Vec<u8> = [7i16, -1, 0, 2].iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(d.join("i.npy"), npy_bytes("<i2", false, "(2, 2)", &i)).unwrap();
        assert_eq!(read_npy(&d.join("i.npy")).unwrap().values, vec![7.0, -1.0, 0.0, 2.0]);
        std::fs::write(d.join("1d.npy"), npy_bytes("<f8", false, "(6,)", &data)).unwrap();
        assert!(read_npy(&d.join("1d.npy")).unwrap_err().to_string().contains("2D"));
        std::fs::write(d.join("short.npy"), npy_bytes("<f8", false, "(2, 3)", &data[..40])).unwrap();
        assert!(read_npy(&d.join("short.npy")).is_err());
        std::fs::write(d.join("junk.npy"), b"not numpy").unwrap();
        assert!(read_npy(&d.join("junk.npy")).unwrap_err().to_string().contains("junk.npy"));
    }

    #[test]
    fn grayscale_png_and_tiff() {
        let d = dir();
        let img =
            image::ImageBuffer::<image::Luma<u16>, _>::from_fn(4, 3, |x, y| image::Luma([(x + 10 * y) as u16 * 1000]));
        img.save(d.join("g.png")).unwrap();
        let g = read_raster(&d.join("g.png")).unwrap();
        assert_eq!((g.grid.nx(), g.grid.ny(), g.grid.n_vertices()), (4, 3, 12));
        assert_eq!(g.values[g.grid.index(2, 1)], 21_000.0, "row 2 is the third stored row");
        // placed as ParaView's PNG reader places it: the top row (row 0) at y = 2, the bottom at 0
        assert_eq!((g.grid.origin(), g.grid.spacing()), ([0.0, 2.0], [1.0, -1.0]));
        image::RgbImage::new(3, 3).save(d.join("rgb.png")).unwrap();
        assert!(read_raster(&d.join("rgb.png")).unwrap_err().to_string().contains("grayscale"));
        // a float TIFF, the usual elevation format
        let file = std::fs::File::create(d.join("f.tif")).unwrap();
        let mut enc = tiff::encoder::TiffEncoder::new(file).unwrap();
        let data: Vec<f32> = (0..6).map(|v| v as f32 * 0.5).collect();
        enc.write_image::<tiff::encoder::colortype::Gray32Float>(3, 2, &data).unwrap();
        let t = read_raster(&d.join("f.tif")).unwrap();
        assert_eq!(t.values, vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5]);
        assert_eq!((t.grid.spacing(), t.grid.origin()), ([1.0, -1.0], [0.0, 1.0]));
        std::fs::write(d.join("trunc.tif"), &std::fs::read(d.join("f.tif")).unwrap()[..20]).unwrap();
        assert!(read_raster(&d.join("trunc.tif")).is_err());
    }
}
