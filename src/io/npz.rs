//! NumPy files: 2D float64 arrays as `.npy`, several of them as an `.npz` archive (what
//! `numpy.savez` writes: a zip of `NAME.npy` members, here deflate-compressed), and reading
//! any `.npz` of 2D numeric arrays back.
//!
//! Arrays have shape `(ny, nx)` in C order: element `(r, c)` is grid vertex `r · nx + c`, so
//! `numpy.load(f)["smoothed"][r, c]` is the value at row `r`, column `c` of the grid.

use super::{stage, Staged};
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

fn input(path: &Path, msg: impl Into<String>) -> Error {
    Error::input(msg).in_file(path)
}

fn check_shape(path: &Path, what: &str, shape: &[usize], len: usize) -> Result<()> {
    if shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d)) != Some(len) {
        return Err(input(path, format!("{what} has {len} values for shape {}", shape_text(shape))));
    }
    Ok(())
}

fn write_npy(w: &mut dyn Write, shape: &[usize], values: &[f64]) -> std::io::Result<()> {
    use npyz::WriterBuilder;
    let shape: Vec<u64> = shape.iter().map(|&d| d as u64).collect();
    let mut writer = npyz::WriteOptions::<f64>::new().default_dtype().shape(&shape).writer(w).begin_nd()?;
    writer.extend(values.iter().copied())?;
    writer.finish()
}

/// Stages a `.npy` file: a little-endian float64 array of shape `(ny, nx)`, C order.
///
/// # Errors
/// An input error when `values.len() != ny · nx`; I/O errors while writing.
pub fn stage_npy(path: &Path, ny: usize, nx: usize, values: &[f64]) -> Result<Staged> {
    stage_npy_shaped(path, &[ny, nx], values)
}

/// Stages a `.npy` file: a little-endian float64 array of the given shape, C order (a
/// volume: `(nz, ny, nx)`).
///
/// # Errors
/// An input error when `values.len()` is not the shape's product; I/O errors while writing.
pub fn stage_npy_shaped(path: &Path, shape: &[usize], values: &[f64]) -> Result<Staged> {
    check_shape(path, "the array", shape, values.len())?;
    stage(path, |w| write_npy(w, shape, values))
}

#[cfg(feature = "io-npz")]
/// Stages a `.npz` archive with one little-endian float64 array of shape `(ny, nx)` (C order)
/// per entry of `arrays`, stored as member `NAME.npy` (deflate-compressed), so that
/// `numpy.load(path)[NAME]` returns it.
///
/// # Errors
/// Input errors: an array whose length is not `ny · nx`, an empty, duplicate or path-like
/// name. I/O errors while writing.
pub fn stage_npz(path: &Path, ny: usize, nx: usize, arrays: &[(&str, &[f64])]) -> Result<Staged> {
    stage_npz_shaped(path, &[ny, nx], arrays)
}

#[cfg(feature = "io-npz")]
/// [`stage_npz`] with arrays of any one shape (a volume: `(nz, ny, nx)`).
///
/// # Errors
/// As [`stage_npz`].
pub fn stage_npz_shaped(path: &Path, shape: &[usize], arrays: &[(&str, &[f64])]) -> Result<Staged> {
    let mut seen: Vec<&str> = Vec::new();
    for (name, values) in arrays {
        if name.is_empty() || name.contains(['/', '\\', '\0']) {
            return Err(input(path, format!("array name {name:?} cannot be a member name of an .npz archive")));
        }
        if seen.contains(name) {
            return Err(input(path, format!("two arrays are named `{name}`")));
        }
        seen.push(name);
        check_shape(path, &format!("array `{name}`"), shape, values.len())?;
    }
    super::stage_with(path, |w| {
        use zip::write::SimpleFileOptions;
        let mut zip = zip::ZipWriter::new(w);
        for (name, values) in arrays {
            let options = SimpleFileOptions::default()
                .compression_method(zip::CompressionMethod::Deflated)
                .large_file(values.len() as u64 * 8 + 4096 >= u64::from(u32::MAX));
            zip.start_file(npyz::npz::file_name_from_array_name(name), options)?;
            write_npy(&mut zip, shape, values)?;
        }
        zip.finish()?;
        Ok(())
    })
}

/// One array of an `.npz` archive: its name, shape `[ny, nx]` and values in C order.
pub type NpzArray = (String, [usize; 2], Vec<f64>);

/// One array of a NumPy file of any number of dimensions: its name, shape and values in C order.
pub type NdArray = (String, Vec<usize>, Vec<f64>);

#[cfg(feature = "io-npz")]
/// Reads every array of an `.npz` archive: `(name, [ny, nx], values)` in archive order, with
/// values converted to f64 and Fortran-ordered arrays rearranged to C order (row by row).
/// Members whose names do not end in `.npy` are skipped, as `numpy.load` does.
///
/// # Errors
/// Input errors naming the file (and the array): not a zip archive, a truncated or corrupt
/// member, an array that is not 2D, an unsupported dtype, an archive with no arrays. I/O
/// errors for an unreadable file.
pub fn read_npz(path: &Path) -> Result<Vec<NpzArray>> {
    read_npz_nd(path)?
        .into_iter()
        .map(|(name, shape, values)| match shape.as_slice() {
            &[ny, nx] => Ok((name, [ny, nx], values)),
            _ => Err(input(
                path,
                format!("array `{name}`: expected a 2D array (rows, columns), found shape {}", shape_text(&shape)),
            )),
        })
        .collect()
}

/// Decodes a whole `.npy` file held in memory: a 2D numeric or boolean array as
/// `([ny, nx], values in C order)`.
///
/// # Errors
/// As [`decode_npy_nd`]; an array that is not 2D.
pub fn decode_npy(bytes: &[u8]) -> Result<([usize; 2], Vec<f64>)> {
    let (shape, values) = decode_npy_nd(bytes)?;
    match shape.as_slice() {
        &[ny, nx] => Ok(([ny, nx], values)),
        _ => Err(Error::input(format!("expected a 2D array (rows, columns), found shape {}", shape_text(&shape)))),
    }
}

/// A shape as numpy prints it: `(3, 4)`, `(8,)`, `()`.
pub fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")),
    }
}

/// Decodes a whole `.npy` file held in memory, of any number of dimensions: its shape and its
/// values in C order (Fortran-ordered arrays rearranged). Floats (16 bits excepted), integers
/// and booleans of either byte order, as `numpy.save` writes them.
///
/// # Errors
/// Input errors: not an .npy file, a dtype that holds no real numbers (complex, strings,
/// dates, objects), truncated data or bytes after it.
pub fn decode_npy_nd(bytes: &[u8]) -> Result<(Vec<usize>, Vec<f64>)> {
    use npyz::{DType, Order, TypeChar};
    super::npy_header::check(bytes)?;
    let npy = npyz::NpyFile::new(bytes).map_err(|e| Error::input(format!("not a readable .npy array: {e}")))?;
    let shape: Vec<usize> = npy.shape().iter().map(|&d| d as usize).collect();
    let order = npy.order();
    let dtype = npy.dtype();
    let unsupported = |why: &str| {
        Error::input(format!(
            "unsupported dtype {}{why}: toposmooth reads real numbers (float, int, bool)",
            dtype.descr()
        ))
    };
    let DType::Plain(ts) = &dtype else {
        return Err(unsupported(" (a structured array)"));
    };
    let bad = |e: std::io::Error| Error::input(format!("cannot read the data (truncated?): {e}"));
    let count = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    // the data must end where the file ends: trailing bytes mean a wrong header or a
    // concatenated file
    let data_start = match bytes.get(6) {
        Some(1) => bytes.get(8..10).map(|h| 10 + u16::from_le_bytes([h[0], h[1]]) as usize),
        Some(_) => bytes.get(8..12).map(|h| 12 + u32::from_le_bytes([h[0], h[1], h[2], h[3]]) as usize),
        None => None,
    };
    let expected = count.and_then(|k| k.checked_mul(ts.size_field() as usize));
    if let (Some(start), Some(len)) = (data_start, expected) {
        if bytes.len() > start.saturating_add(len) {
            return Err(Error::input(format!(
                "{} bytes after the {len} bytes of data the header describes (shape {}, dtype {})",
                bytes.len() - start - len,
                shape_text(&shape),
                dtype.descr()
            )));
        }
    }
    let values: Vec<f64> = match (ts.type_char(), ts.size_field()) {
        (TypeChar::Float, 8) => npy.into_vec::<f64>().map_err(bad)?,
        (TypeChar::Float, 4) => npy.into_vec::<f32>().map_err(bad)?.into_iter().map(f64::from).collect(),
        (TypeChar::Int, 1) => npy.into_vec::<i8>().map_err(bad)?.into_iter().map(f64::from).collect(),
        (TypeChar::Int, 2) => npy.into_vec::<i16>().map_err(bad)?.into_iter().map(f64::from).collect(),
        (TypeChar::Int, 4) => npy.into_vec::<i32>().map_err(bad)?.into_iter().map(f64::from).collect(),
        (TypeChar::Int, 8) => npy.into_vec::<i64>().map_err(bad)?.into_iter().map(|v| v as f64).collect(),
        (TypeChar::Uint, 1) => npy.into_vec::<u8>().map_err(bad)?.into_iter().map(f64::from).collect(),
        (TypeChar::Uint, 2) => npy.into_vec::<u16>().map_err(bad)?.into_iter().map(f64::from).collect(),
        (TypeChar::Uint, 4) => npy.into_vec::<u32>().map_err(bad)?.into_iter().map(f64::from).collect(),
        (TypeChar::Uint, 8) => npy.into_vec::<u64>().map_err(bad)?.into_iter().map(|v| v as f64).collect(),
        (TypeChar::Bool, 1) => npy.into_vec::<bool>().map_err(bad)?.into_iter().map(|b| b as u8 as f64).collect(),
        (TypeChar::Complex, _) => return Err(unsupported(" (complex)")),
        (TypeChar::DateTime | TypeChar::TimeDelta, _) => return Err(unsupported(" (dates or durations)")),
        (TypeChar::ByteStr | TypeChar::UnicodeStr, _) => return Err(unsupported(" (strings)")),
        _ => return Err(unsupported("")),
    };
    if Some(values.len()) != count {
        return Err(Error::input(format!("{} values for shape {}", values.len(), shape_text(&shape))));
    }
    let values = match order {
        Order::C => values,
        Order::Fortran => fortran_to_c(&shape, &values),
    };
    Ok((shape, values))
}

/// Rearranges values stored with the first index fastest (Fortran order) to C order.
fn fortran_to_c(shape: &[usize], values: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(values.len());
    let mut index = vec![0usize; shape.len()];
    for _ in 0..values.len() {
        // the Fortran position of the C multi-index
        let (mut at, mut stride) = (0, 1);
        for (k, &i) in index.iter().enumerate() {
            at += i * stride;
            stride *= shape[k];
        }
        out.push(values[at]);
        // the next C multi-index: last index fastest
        for k in (0..shape.len()).rev() {
            index[k] += 1;
            if index[k] < shape[k] {
                break;
            }
            index[k] = 0;
        }
    }
    out
}

#[cfg(feature = "io-npz")]
/// Reads every array of an `.npz` archive, of any number of dimensions: `(name, shape,
/// values in C order)` in archive order. Members whose names do not end in `.npy` are
/// skipped, as `numpy.load` does.
///
/// # Errors
/// Input errors naming the file (and the array): not a zip archive, a truncated or corrupt
/// member, an unsupported dtype, an archive with no arrays. I/O errors for an unreadable file.
pub fn read_npz_nd(path: &Path) -> Result<Vec<NdArray>> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let mut archive = zip::ZipArchive::new(std::io::BufReader::new(file))
        .map_err(|e| input(path, format!("not a readable .npz (zip) archive: {e}")))?;
    let mut out = Vec::new();
    for i in 0..archive.len() {
        let mut member = archive
            .by_index(i)
            .map_err(|e| input(path, format!("cannot read member {} of the archive: {e}", i + 1)))?;
        let Some(name) = npyz::npz::array_name_from_file_name(member.name()).map(str::to_string) else {
            continue;
        };
        let mut bytes = Vec::with_capacity(member.size().min(1 << 30) as usize);
        std::io::Read::read_to_end(&mut member, &mut bytes)
            .map_err(|e| input(path, format!("array `{name}`: cannot read it: {e}")))?;
        let (shape, values) = decode_npy_nd(&bytes).map_err(|m| input(path, format!("array `{name}`: {m}")))?;
        out.push((name, shape, values));
    }
    if out.is_empty() {
        return Err(input(path, "the archive holds no .npy arrays"));
    }
    Ok(out)
}

#[cfg(all(test, feature = "io-npz"))]
mod tests {
    use super::*;

    fn dir() -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("toposmooth-npz-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// Deterministic values covering awkward doubles (no NaN: NaN != NaN is checked by bits).
    fn values(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        (0..n)
            .map(|i| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                match i % 7 {
                    0 => -0.0,
                    1 => f64::MIN_POSITIVE / 3.0,
                    _ => (s >> 11) as f64 / (1u64 << 53) as f64 * 2e3 - 1e3,
                }
            })
            .collect()
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    #[test]
    fn npy_round_trip_bits() {
        let p = dir().join("a.npy");
        let v = values(5 * 3, 1);
        stage_npy(&p, 5, 3, &v).unwrap().commit().unwrap();
        let bytes = std::fs::read(&p).unwrap();
        let (shape, back) = decode_npy(&bytes).unwrap();
        assert_eq!(shape, [5, 3]);
        assert_eq!(bits(&back), bits(&v));
        // the crate's own .npy reader agrees (nx = 3 columns, ny = 5 rows)
        let f = crate::io::grid::read_npy(&p).unwrap();
        assert_eq!((f.grid.nx(), f.grid.ny()), (3, 5));
        assert_eq!(bits(&f.values), bits(&v));
        let e = stage_npy(&p, 4, 3, &v).err().unwrap().to_string();
        assert!(e.contains("a.npy") && e.contains("15 values"), "{e}");
    }

    #[test]
    fn npz_round_trip_bits() {
        let p = dir().join("out.npz");
        let (ny, nx) = (7, 4);
        let names = ["input", "smoothed", "representative", "role"];
        let data: Vec<Vec<f64>> = (0..4).map(|k| values(ny * nx, k + 10)).collect();
        let arrays: Vec<(&str, &[f64])> = names.iter().zip(&data).map(|(n, v)| (*n, v.as_slice())).collect();
        let staged = stage_npz(&p, ny, nx, &arrays).unwrap();
        assert!(!p.exists(), "nothing at the final path before commit");
        staged.commit().unwrap();
        let back = read_npz(&p).unwrap();
        assert_eq!(back.len(), 4);
        for ((name, shape, vals), (want_name, want)) in back.iter().zip(&arrays) {
            assert_eq!(name, want_name);
            assert_eq!(*shape, [ny, nx]);
            assert_eq!(bits(vals), bits(want));
        }
        // bad arguments
        let short = vec![0.0; 3];
        let e = stage_npz(&p, ny, nx, &[("a", &short)]).err().unwrap().to_string();
        assert!(e.contains("out.npz") && e.contains("`a`"), "{e}");
        let e = stage_npz(&p, ny, nx, &[("a", &data[0]), ("a", &data[1])]).err().unwrap().to_string();
        assert!(e.contains("two arrays"), "{e}");
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

    fn zip_of(path: &Path, members: &[(&str, Vec<u8>)], method: zip::CompressionMethod) {
        let mut z = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
        for (name, bytes) in members {
            z.start_file(*name, zip::write::SimpleFileOptions::default().compression_method(method)).unwrap();
            z.write_all(bytes).unwrap();
        }
        z.finish().unwrap();
    }

    #[test]
    fn any_dimension_and_fortran_order_in_three() {
        // shape (2, 3, 2): C-order value = 100 i + 10 j + k, stored with i fastest
        let mut fortran = Vec::new();
        for k in 0..2 {
            for j in 0..3 {
                for i in 0..2 {
                    fortran.extend((100.0 * i as f64 + 10.0 * j as f64 + k as f64).to_le_bytes());
                }
            }
        }
        let (shape, v) = decode_npy_nd(&npy_bytes("<f8", true, "(2, 3, 2)", &fortran)).unwrap();
        assert_eq!(shape, [2, 3, 2]);
        let want: Vec<f64> = (0..12).map(|f| (100 * (f / 6) + 10 * (f / 2 % 3) + f % 2) as f64).collect();
        assert_eq!(v, want);
        let one: Vec<u8> = [1.0f64, 2.0].iter().flat_map(|x| x.to_be_bytes()).collect();
        assert_eq!(decode_npy_nd(&npy_bytes(">f8", false, "(2,)", &one)).unwrap(), (vec![2], vec![1.0, 2.0]));
        let e = decode_npy(&npy_bytes(">f8", false, "(2,)", &one)).unwrap_err().to_string();
        assert!(e.contains("2D") && e.contains("(2,)"), "{e}");
        let c = decode_npy_nd(&npy_bytes("<c16", false, "(1,)", &[0; 16])).unwrap_err().to_string();
        assert!(c.contains("complex"), "{c}");
        assert_eq!(shape_text(&[]), "()");
    }

    #[test]
    fn npz_dtypes_and_fortran_order() {
        let p = dir().join("mixed.npz");
        let f32s: Vec<u8> = [1.5f32, -2.0, 3.25, 4.0, 5.0, 6.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        // (2, 3) matrix [[1, 2, 3], [4, 5, 6]] stored column by column, big-endian int32
        let fort: Vec<u8> = [1i32, 4, 2, 5, 3, 6].iter().flat_map(|v| v.to_be_bytes()).collect();
        let u8s = vec![0u8, 255, 7, 9];
        zip_of(
            &p,
            &[
                ("f.npy", npy_bytes("<f4", false, "(2, 3)", &f32s)),
                ("notes.txt", b"skipped".to_vec()),
                ("i.npy", npy_bytes(">i4", true, "(2, 3)", &fort)),
                ("u.npy", npy_bytes("|u1", false, "(2, 2)", &u8s)),
            ],
            zip::CompressionMethod::Stored,
        );
        let back = read_npz(&p).unwrap();
        let names: Vec<&str> = back.iter().map(|(n, _, _)| n.as_str()).collect();
        assert_eq!(names, ["f", "i", "u"]);
        assert_eq!(back[0].2, vec![1.5, -2.0, 3.25, 4.0, 5.0, 6.0]);
        assert_eq!((back[1].1, back[1].2.clone()), ([2, 3], vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
        assert_eq!(back[2].2, vec![0.0, 255.0, 7.0, 9.0]);
    }

    #[test]
    fn npz_errors_name_file_and_problem() {
        let d = dir();
        // truncated archive: cut a valid one in half
        let good = d.join("good.npz");
        let v = values(40 * 30, 3);
        stage_npz(&good, 40, 30, &[("x", &v)]).unwrap().commit().unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let cut = d.join("cut.npz");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let e = read_npz(&cut).unwrap_err().to_string();
        assert!(e.contains("cut.npz") && e.contains("zip"), "{e}");
        // a member whose .npy data is short
        let data: Vec<u8> = [1.0f64, 2.0, 3.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let short = d.join("short.npz");
        zip_of(&short, &[("s.npy", npy_bytes("<f8", false, "(2, 3)", &data))], zip::CompressionMethod::Deflated);
        let e = read_npz(&short).unwrap_err().to_string();
        assert!(e.contains("short.npz") && e.contains("`s`"), "{e}");
        // not 2D
        let one = d.join("one.npz");
        zip_of(&one, &[("v.npy", npy_bytes("<f8", false, "(3,)", &data))], zip::CompressionMethod::Stored);
        let e = read_npz(&one).unwrap_err().to_string();
        assert!(e.contains("2D") && e.contains("`v`"), "{e}");
        // unsupported dtype
        let c = d.join("complex.npz");
        zip_of(&c, &[("z.npy", npy_bytes("<c16", false, "(1, 1)", &[0; 16]))], zip::CompressionMethod::Stored);
        let e = read_npz(&c).unwrap_err().to_string();
        assert!(e.contains("dtype"), "{e}");
        // no arrays, not a zip, missing file
        let none = d.join("none.npz");
        zip_of(&none, &[("a.txt", b"x".to_vec())], zip::CompressionMethod::Stored);
        assert!(read_npz(&none).unwrap_err().to_string().contains("no .npy arrays"));
        let junk = d.join("junk.npz");
        std::fs::write(&junk, b"not a zip at all").unwrap();
        assert!(read_npz(&junk).unwrap_err().to_string().contains("junk.npz"));
        let e = read_npz(&d.join("missing.npz")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }) && e.to_string().contains("missing.npz"), "{e}");
    }
}
