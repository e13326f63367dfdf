//! Series as pandas writes them (tests/fixtures/pandas, written by pandas and numpy
//! themselves): missing values filled, time-zone-aware timestamps, `;` and tab separators,
//! decimal commas, the x column's name kept in the output.

mod common;

use common::{scratch, succeeds, text, toposmooth};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pandas").join(name).display().to_string()
}

fn write(dir: &Path, name: &str, content: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p.display().to_string()
}

/// An output CSV: its header and its rows of cells.
fn read_output(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(str::to_string).collect();
    (header, lines.map(|l| l.split(',').map(str::to_string).collect()).collect())
}

fn num(cell: &str) -> f64 {
    cell.parse().unwrap_or_else(|_| panic!("`{cell}` is not a number"))
}

/// The (x, value) cells of a fixture written by pandas with `,` (values as pandas wrote them).
fn pandas_rows(name: &str) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(fixture(name)).unwrap();
    text.lines().skip(1).map(|l| l.split_once(',').map(|(a, b)| (a.to_string(), b.to_string())).unwrap()).collect()
}

#[test]
fn fill_missing_fills_a_series_linearly_and_marks_the_filled_samples() {
    let dir = scratch("series-fill");
    let input = fixture("berlin_dst.csv");
    let out = dir.join("out.csv");
    let report = dir.join("run.json");
    let o = toposmooth(&["smooth", &input, "-o", &out.display().to_string()]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("berlin_dst.csv") && text(&o).contains("line 2") && text(&o).contains("--fill-missing"));
    let o = succeeds(&[
        "smooth",
        &input,
        "--fill-missing",
        "-o",
        &out.display().to_string(),
        "--report",
        &report.display().to_string(),
    ]);
    assert!(text(&o).contains("5 missing samples filled linearly in x"), "{}", text(&o));
    let rows = pandas_rows("berlin_dst.csv");
    let missing: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].1.is_empty()).collect();
    assert_eq!(missing, [0, 1, 7, 8, 23]);
    let (header, cells) = read_output(&out);
    assert_eq!(header, ["x", "input", "output", "u", "role", "filled"], "pandas' unnamed index is written as x");
    assert_eq!(cells.len(), rows.len());
    for (i, (row, (x, v))) in cells.iter().zip(&rows).enumerate() {
        assert_eq!(&row[0], x, "x as pandas wrote it");
        assert_eq!(row[5], if missing.contains(&i) { "1" } else { "0" }, "filled at {i}");
        if !v.is_empty() {
            assert_eq!(num(&row[1]).to_bits(), num(v).to_bits(), "given input at {i}");
        }
        if missing.contains(&i) {
            assert!(row[4] != "min" && row[4] != "max", "filled sample {i} is kept: {row:?}");
        }
    }
    // inside: linear between 00:00+02:00 and 02:00+01:00, which are three hours apart (x is
    // in days since 1970: an hour is known to about 1e-10 of itself)
    let (a, b) = (num(&rows[6].1), num(&rows[9].1));
    for (i, t) in [(7, 1.0 / 3.0), (8, 2.0 / 3.0)] {
        assert!((num(&cells[i][1]) - (a + (b - a) * t)).abs() < 1e-9, "{i}: {}", cells[i][1]);
    }
    // ends: the nearest given value
    assert!((num(&cells[0][1]) - num(&rows[2].1)).abs() < 1e-12);
    assert!((num(&cells[23][1]) - num(&rows[22].1)).abs() < 1e-12);
    let r = common::json(&report);
    assert_eq!(r["filled_missing"], 5);
    assert_eq!(r["filled_samples"], serde_json::json!([0, 1, 7, 8, 23]));
    let o = succeeds(&["verify", &out.display().to_string(), "--input", &input]);
    assert!(text(&o).contains("input matches"), "{}", text(&o));
}

#[test]
fn filled_samples_never_become_kept_extrema() {
    let dir = scratch("series-fill-kept");
    // filled with the nearest value, sample 0 would be the first of a plateau at the global
    // minimum, and sample 6 the last of one at the global maximum
    let input = write(&dir, "ends.csv", "t,v\n0,\n1,\n2,1\n3,5\n4,2\n5,8\n6,\n");
    let out = dir.join("out.csv");
    let o = out.display().to_string();
    succeeds(&["smooth", &input, "--fill-missing", "--persistence", "1%", "-o", &o]);
    let (header, cells) = read_output(&out);
    assert_eq!(header, ["t", "input", "output", "u", "role", "filled"]);
    let roles: Vec<&str> = cells.iter().map(|r| r[4].as_str()).collect();
    assert_eq!(roles, ["end", "", "min", "max", "min", "max", "end"]);
    // the kept extrema keep the given values; the filled ends stay by their neighbours
    assert_eq!((num(&cells[2][2]), num(&cells[5][2])), (1.0, 8.0));
    assert!(num(&cells[0][2]) > 1.0 && num(&cells[6][2]) < 8.0);
    // an explicit list naming a filled sample is refused
    let e = toposmooth(&["smooth", &input, "--fill-missing", "--keep-min", "0", "--keep-max", "5", "-o", &o]);
    assert_eq!(e.status.code(), Some(3), "{}", text(&e));
    assert!(text(&e).contains("ends.csv") && text(&e).contains("sample 0 (t = 0)") && text(&e).contains("filled"));
    // verify rejects a file whose kept extremum is marked filled
    let tampered = std::fs::read_to_string(&out).unwrap().replacen(",min,0", ",min,1", 1);
    let bad = write(&dir, "bad.csv", &tampered);
    let v = toposmooth(&["verify", &bad]);
    assert_eq!(v.status.code(), Some(1), "{}", text(&v));
    assert!(text(&v).contains("sample 2") && text(&v).contains("filled"), "{}", text(&v));
}

#[test]
fn semicolons_tabs_and_decimal_commas_read_as_the_comma_file() {
    let dir = scratch("series-dialects");
    let outputs: Vec<PathBuf> = ["berlin_dst.csv", "berlin_dst_semicolon.csv", "berlin_dst.tsv"]
        .iter()
        .map(|name| {
            let out = dir.join(format!("{name}.out.csv"));
            succeeds(&["smooth", &fixture(name), "--fill-missing", "-o", &out.display().to_string()]);
            out
        })
        .collect();
    let first = std::fs::read(&outputs[0]).unwrap();
    for o in &outputs[1..] {
        assert!(std::fs::read(o).unwrap() == first, "{} differs from the comma file's output", o.display());
    }
    // a numeric x column with decimal commas: x written back with points, named as in the file
    let a = dir.join("depth.out.csv");
    let b = dir.join("depth_semicolon.out.csv");
    succeeds(&["smooth", &fixture("depth.csv"), "--x", "depth", "-o", &a.display().to_string()]);
    succeeds(&["smooth", &fixture("depth_semicolon.csv"), "--x", "depth", "-o", &b.display().to_string()]);
    let (header, cells) = read_output(&b);
    assert_eq!(header, ["depth", "input", "output", "u", "role"]);
    assert_eq!((cells[1][0].as_str(), cells[1][1].as_str()), ("1.25", "2.25"));
    assert_eq!(std::fs::read_to_string(&a).unwrap(), std::fs::read_to_string(&b).unwrap());
}

#[test]
fn aware_timestamps_count_at_their_instant() {
    use toposmooth::io::import::ReadOptions;
    let read = |name: &str, fill: bool| {
        let options = ReadOptions { fill_missing: fill, ..Default::default() };
        let p = fixture(name);
        toposmooth::io::import::read(Some(Path::new(&p)), &options).unwrap()
    };
    // `Z` and `+00:00` name the same instants, twelve hours apart
    for name in ["utc_z.csv", "utc_offset.csv"] {
        let f = read(name, false);
        let axis = f.axis.unwrap();
        assert_eq!(axis.x_name, "time");
        let first = 16436.0; // 2015-01-01 is day 16436 since 1970-01-01
        for (i, x) in axis.x.iter().enumerate() {
            assert_eq!(*x, first + 0.5 * i as f64, "{name}: sample {i}");
        }
    }
    // the clocks go back: 02:00+02:00 is an hour before 02:00+01:00, every step is an hour
    let f = read("berlin_dst.csv", true);
    let x = f.axis.unwrap().x;
    assert_eq!(x.len(), 24);
    for w in x.windows(2) {
        assert!((w[1] - w[0] - 1.0 / 24.0).abs() < 1e-9, "{w:?}");
    }
    // an uneven gap across the change: 02:00+02:00 lies 2 of the 3.5 hours from
    // 00:00+02:00 (value 1) to 02:30+01:00 (value 8), so it is filled with 1 + 7 · 4/7
    let f = read("uneven_gap.csv", true);
    assert!((f.values[2] - 5.0).abs() < 1e-9, "{}", f.values[2]);
    // a column that mixes aware and naive times is refused at the first line that differs
    let o = toposmooth(&["smooth", &fixture("mixed_aware_naive.csv"), "-o", "never.csv"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(
        text(&o).contains("mixed_aware_naive.csv") && text(&o).contains("line 3") && text(&o).contains("line 2"),
        "{}",
        text(&o)
    );
    assert!(!Path::new("never.csv").exists());
}

#[test]
fn the_x_column_keeps_its_name() {
    let dir = scratch("series-x-name");
    let out = dir.join("out.csv");
    succeeds(&["smooth", &fixture("utc_z.csv"), "-o", &out.display().to_string(), "--persistence", "1%"]);
    let (header, cells) = read_output(&out);
    assert_eq!(header, ["time", "input", "output", "u", "role"]);
    assert_eq!(cells[0][0], "2015-01-01T00:00:00Z");
    succeeds(&["verify", &out.display().to_string(), "--input", &fixture("utc_z.csv")]);
    // no x column: `x` and the sample indices
    let plain = write(&dir, "plain.csv", "v\n3\n1\n4\n1.5\n5\n");
    succeeds(&["smooth", &plain, "-o", &out.display().to_string()]);
    let (header, cells) = read_output(&out);
    assert_eq!((header[0].as_str(), cells[4][0].as_str()), ("x", "4"));
}
