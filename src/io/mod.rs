//! Reading and writing files: [`import`] reads any supported file into a domain and a field,
//! [`export`] writes any domain's results. Every output is written to a locked temporary file
//! and put in place only when complete ([`staging`]), so a failed run never leaves a
//! half-written file.

pub mod content;
pub mod csv_dialect;
#[cfg(all(feature = "io-vtk", feature = "io-npz"))]
pub mod export;
pub mod grid;
#[cfg(all(feature = "io-vtk", feature = "io-npz", feature = "image"))]
pub mod import;
#[cfg(feature = "io-vtk")]
pub mod mesh;
#[cfg(feature = "io-nifti")]
pub mod nifti;
mod npy_header;
pub mod npy_input;
pub mod npz;
pub mod series_csv;
pub mod series_output;
pub mod staging;
pub mod timestamps;
#[cfg(all(feature = "io-vtk", feature = "io-npz"))]
pub mod ttk;
#[cfg(feature = "io-vtk")]
pub mod vtk;

use crate::error::{Error, Result};
pub use staging::{commit_all, reserve, stage, stage_with, write_atomic, Staged};
use std::path::Path;

/// The marker in the message of a reader that failed internally (a panic caught while
/// reading a file): the file is reported as bad input, the message says it is our bug.
pub const READER_FAILURE: &str = "[reader failure]";

/// Runs a reader on `path`, turning a panic inside it into an input error naming the file
/// (exit 3) that carries [`READER_FAILURE`]. Errors are given the file name.
///
/// # Errors
/// The reader's errors, and the caught panic.
pub fn guarded<T>(path: &Path, read: impl FnOnce() -> Result<T>) -> Result<T> {
    let read = || {
        // the tests' way into this branch (a reader that panics)
        if std::env::var_os("TOPOSMOOTH_DEBUG_PANIC").is_some_and(|v| v == "reader") {
            panic!("TOPOSMOOTH_DEBUG_PANIC=reader");
        }
        read()
    };
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(read)) {
        Ok(r) => r.map_err(|e| e.in_file(path)),
        Err(payload) => {
            let what = crate::error::take_last_panic().unwrap_or_else(|| panic_text(&*payload));
            Err(Error::input(format!(
                "{READER_FAILURE} the reader failed on this file ({what}): the file is malformed in a way \
                 toposmooth does not describe yet; please report it with the file"
            ))
            .in_file(path))
        }
    }
}

/// The text a panic was raised with.
pub fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "no message".into())
}

#[cfg(feature = "serde")]
/// Stages a value as pretty JSON.
pub fn stage_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<Staged> {
    stage(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value).map_err(std::io::Error::other)?;
        writeln!(w)
    })
}

/// The decimal digits of `v`, written into `buf` (nothing allocated: the allocator's failure
/// path uses it).
pub fn decimal(v: usize, buf: &mut [u8; 20]) -> &[u8] {
    let (mut k, mut v) = (buf.len(), v);
    loop {
        k -= 1;
        buf[k] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    &buf[k..]
}

/// Shortest text that reads back to the same double (Rust's `Debug` for f64).
pub fn format_f64(v: f64) -> String {
    let mut text = String::new();
    push_f64(&mut text, v);
    text
}

/// Appends [`format_f64`]'s text of `v` to `text`. Between 10⁻⁴ and 10¹⁶ in size (and at 0),
/// where its layout is `Debug`'s (digits, a point, at least one decimal), by `zmij`, about
/// three times faster (the 3·10⁷ values of a 10⁷-sample series' output took 5 CPU s); the
/// digits are the shortest that read back to the same bits either way, and where two such
/// texts are equally close (a value with few bits below its point, such as 2⁴⁶ + 0.625)
/// the two may end in a different last digit. Elsewhere `Debug` itself (`1e-5`, `1e16`).
pub fn push_f64(text: &mut String, v: f64) {
    if v == 0.0 || (1e-4..1e16).contains(&v.abs()) {
        text.push_str(zmij::Buffer::new().format_finite(v));
    } else {
        use std::fmt::Write as _;
        let _ = write!(text, "{v:?}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_digits() {
        for v in [0usize, 7, 10, 1234, usize::MAX] {
            assert_eq!(decimal(v, &mut [0u8; 20]), v.to_string().as_bytes());
        }
    }

    #[test]
    fn shortest_round_trip() {
        for v in [0.1, 1.0 / 3.0, 1e-300, 6.02e23, -0.0, 123_456_789.123_456_78, f64::MIN_POSITIVE] {
            let s = format_f64(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
    }

    /// `Debug`'s text on either side of the range handed to `zmij` and inside it, and the
    /// same bits read back from random doubles of every size; where the digits differ from
    /// `Debug`'s it is only in the last one, between two equally close texts.
    #[test]
    fn the_fast_text_is_debug_s_and_reads_back() {
        let fixed = [0.0, -0.0, 1.0, -2.5, 0.1, 1e-4, 9.99e-5, 1.5e-5, 1e15, 9.999e15, 1e16, 1e300, 5e-324];
        for v in fixed.into_iter().chain([f64::NAN, f64::INFINITY, f64::NEG_INFINITY]) {
            assert_eq!(format_f64(v), format!("{v:?}"), "{v:?}");
        }
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut ties = 0;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            for v in [f64::from_bits(x), ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 1e3] {
                if !v.is_finite() {
                    continue;
                }
                let (fast, debug) = (format_f64(v), format!("{v:?}"));
                assert_eq!(fast.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{fast}");
                if fast != debug {
                    ties += 1;
                    assert_eq!(fast.len(), debug.len(), "{fast} {debug}");
                    assert_eq!(fast[..fast.len() - 1], debug[..debug.len() - 1], "{fast} {debug}");
                }
            }
        }
        assert!(ties < 100, "{ties} texts differ from Debug's");
    }
}
