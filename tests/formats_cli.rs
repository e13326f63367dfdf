//! NumPy input as numpy writes it (tests/fixtures/pandas, written by numpy itself: `np.save`,
//! `np.savez`, `np.savez_compressed`; float64, float32, int64, bool, big-endian, Fortran
//! order), and files whose content does not match their extension.

mod common;

use common::{scratch, succeeds, text, toposmooth};
use std::path::Path;

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pandas").join(name).display().to_string()
}

/// The `input` column of a series output.
fn input_column(path: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines().skip(1).map(|l| l.split(',').nth(1).unwrap().parse().unwrap()).collect()
}

/// What make_pandas_fixtures.py saves as the series and the grid.
const SERIES: [f64; 8] = [3.0, 1.0, 4.0, 1.5, 5.0, 9.0, 2.0, 6.0];
const GRID: [f64; 12] = [1.0, 2.0, 3.0, 2.5, 4.0, 0.5, 6.0, 1.0, 2.0, 7.0, 1.5, 3.0];

fn assert_exit(args: &[&str], code: i32, needles: &[&str]) {
    let o = toposmooth(args);
    assert_eq!(o.status.code(), Some(code), "{args:?}: {}", text(&o));
    for n in needles {
        assert!(text(&o).contains(n), "{args:?}: `{n}` not in {}", text(&o));
    }
}

#[test]
fn a_one_d_npy_is_a_series_in_every_dtype_numpy_saves() {
    let dir = scratch("npy-series");
    let out = dir.join("s.csv");
    let o = out.display().to_string();
    for (name, want) in [
        ("series_f8.npy", SERIES.to_vec()),
        ("series_f4.npy", SERIES.to_vec()),
        ("series_be.npy", SERIES.to_vec()),
        ("series_i8.npy", SERIES.iter().map(|v| v * 2.0).collect()),
        ("series.npz", SERIES.to_vec()),
    ] {
        succeeds(&["smooth", &fixture(name), "-o", &o, "--persistence", "1%"]);
        let header = std::fs::read_to_string(&out).unwrap().lines().next().unwrap().to_string();
        assert_eq!(header, "x,input,output,u,role", "{name}");
        assert_eq!(input_column(&out), want, "{name}");
        succeeds(&["verify", &o, "--input", &fixture(name)]);
    }
    // NaN is missing: refused, or filled linearly with --fill-missing
    assert_exit(&["smooth", &fixture("series_nan.npy"), "-o", &o], 3, &["series_nan.npy", "index 1", "--fill-missing"]);
    succeeds(&["smooth", &fixture("series_nan.npy"), "--fill-missing", "-o", &o]);
    let text = std::fs::read_to_string(&out).unwrap();
    let filled: Vec<&str> = text.lines().skip(1).map(|l| l.rsplit(',').next().unwrap()).collect();
    assert_eq!(filled, ["0", "1", "0", "0", "0", "1", "0", "0"]);
    assert_eq!(input_column(&out)[1], 3.5, "halfway between 3 and 4");
    // booleans are read as 0 and 1
    use toposmooth::io::npy_input::{read_numpy, NumpyField, Wanted};
    let b = read_numpy(Path::new(&fixture("series_bool.npy")), None, Wanted::Any).unwrap();
    assert_eq!(b, NumpyField::Series { name: "values".into(), values: vec![1.0, 0.0, 1.0, 1.0] });
}

#[test]
fn npz_grids_and_series_chosen_by_array() {
    use toposmooth::io::npz::read_npz;
    let dir = scratch("npz-input");
    let out = dir.join("g.npz");
    let o = out.display().to_string();
    // the only 2-D array, whatever else the archive holds; Fortran order and big-endian float32
    for name in ["grid_and_x.npz", "grid_compressed.npz", "positional.npz", "grid_fortran.npy", "grid_be_f4.npy"] {
        succeeds(&["smooth", &fixture(name), "-o", &o, "--minima", "2", "--maxima", "2"]);
        let arrays = read_npz(&out).unwrap();
        let input = arrays.iter().find(|(n, _, _)| n == "input").unwrap();
        assert_eq!((input.1, input.2.clone()), ([3, 4], GRID.to_vec()), "{name}");
    }
    // --array picks the 1-D `x` of the same archive: a series
    let s = dir.join("x.csv");
    succeeds(&["smooth", &fixture("grid_and_x.npz"), "--array", "x", "-o", &s.display().to_string()]);
    assert_eq!(input_column(&s), [0.0, 1.0, 2.0, 3.0]);
    assert_exit(
        &["smooth", &fixture("two_grids.npz"), "-o", &o],
        2,
        &["two_grids.npz", "--array", "`a` (3, 4)", "`b` (3, 4)"],
    );
    assert_exit(
        &["smooth", &fixture("two_grids.npz"), "--array", "c", "-o", &o],
        3,
        &["no array named `c`", "`a` (3, 4)"],
    );
    // a 3-D array is a volume now: this one is constant, so it has nothing to keep
    assert_exit(&["smooth", &fixture("cube.npy"), "-o", &o], 3, &["cube.npy", "constant"]);
    assert_exit(&["smooth", &fixture("complex.npy"), "-o", &o], 3, &["complex.npy", "complex"]);
    assert_exit(
        &["smooth", &fixture("series.npz"), "--domain", "grid", "-o", &o],
        3,
        &["series.npz", "no 2-D (grid) or 3-D (volume) array"],
    );
    assert!(!out.exists() || std::fs::metadata(&out).is_ok());
}

#[test]
fn content_that_does_not_match_the_extension_is_named() {
    let dir = scratch("mismatch");
    let csv_as_png = dir.join("a.png");
    std::fs::write(&csv_as_png, "x,input,output,u,role\n0,1,1,1,min\n1,2,2,2,max\n").unwrap();
    let a = csv_as_png.display().to_string();
    assert_exit(
        &["verify", &a],
        3,
        &["a.png: not a PNG image (starts with `x,input,output,u,role\\n0", "it looks like text"],
    );
    assert_exit(&["smooth", &a, "-o", &dir.join("o.csv").display().to_string()], 3, &["a.png: not a PNG image"]);
    // a real PNG given to verify holds no output; given as CSV it is not text
    let png = dir.join("real.png");
    image::GrayImage::new(3, 3).save(&png).unwrap();
    assert_exit(&["verify", &png.display().to_string()], 2, &["real.png", "holds no smoothing output"]);
    let png_as_csv = dir.join("b.csv");
    std::fs::copy(&png, &png_as_csv).unwrap();
    let b = png_as_csv.display().to_string();
    assert_exit(
        &["smooth", &b, "-o", &dir.join("o.csv").display().to_string()],
        3,
        &["b.csv: not text", "\\x89PNG", "a PNG image"],
    );
    assert_exit(&["verify", &b], 3, &["b.csv: not text", "a PNG image"]);
    // an .npz that is text, a .npy that is a zip
    let fake_npz = dir.join("c.npz");
    std::fs::write(&fake_npz, "1,2,3\n4,5,6\n").unwrap();
    assert_exit(
        &["smooth", &fake_npz.display().to_string(), "-o", &dir.join("o.npz").display().to_string()],
        3,
        &["c.npz: not a NumPy .npz archive (zip)", "text"],
    );
    let zip_as_npy = dir.join("d.npy");
    std::fs::copy(fixture("series.npz"), &zip_as_npy).unwrap();
    assert_exit(
        &["extrema", &zip_as_npy.display().to_string()],
        3,
        &["d.npy: not a NumPy .npy array", "a zip archive"],
    );
}
