//! The command-line tool: commands, exit codes and error messages (SPEC.md "Exit status").

mod common;

use common::{dataset, scratch, text, toposmooth};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, content: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p.display().to_string()
}

#[test]
fn smooth_then_verify_the_exchange_rate() {
    let dir = scratch("fx");
    let out = dir.join("fx.csv").display().to_string();
    let report = dir.join("run.json").display().to_string();
    let fx = dataset("fx_eur_per_usd_daily_1999_2017.csv");
    let o = toposmooth(&["smooth", &fx, "-o", &out, "--persistence", "2%", "--report", &report]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("certified"));
    let v = toposmooth(&["verify", &out, "--input", &fx]);
    assert_eq!(v.status.code(), Some(0), "{}", text(&v));
    let r = common::json(&report);
    assert_eq!(r["certificate"]["passed"], true);
    assert_eq!(r["vertices"], 4754);
    assert!(r["kept"].as_array().unwrap().len() >= 2);
    assert!(r["seconds"]["solve"].as_f64().unwrap() >= 0.0);
    // the x column keeps its dates
    let csv = std::fs::read_to_string(&out).unwrap();
    assert!(csv.starts_with("date,input,output,u,role\n1999-01-04,0.8466,0.8466,"), "{}", &csv[..80]);

    // tamper: a spurious maximum in the output is caught, and so is a changed input column
    let mut lines: Vec<String> = csv.lines().map(str::to_string).collect();
    let row = (2..lines.len() - 1).find(|&i| lines[i].ends_with(',')).unwrap();
    let mut cells: Vec<String> = lines[row].split(',').map(str::to_string).collect();
    cells[2] = "100".into();
    lines[row] = cells.join(",");
    let bad = write(&dir, "bad.csv", &(lines.join("\n") + "\n"));
    let v = toposmooth(&["verify", &bad]);
    assert_eq!(v.status.code(), Some(1), "{}", text(&v));
    assert!(text(&v).contains("spurious maximum") && text(&v).contains("bad.csv"), "{}", text(&v));
    // roles that would hide extrema are rejected
    for (name, body) in [
        ("interior_end.csv", "x,input,output,u,role\n0,0,0,0,min\n1,3,3,3,end\n2,1,1,1,end\n3,9,9,9,max\n"),
        ("fixed.csv", "x,input,output,u,role\n0,0,0,0,min\n1,5,5,5,fixed\n2,5,5,5,fixed\n3,3,3,3,\n4,9,9,9,max\n"),
    ] {
        let f = write(&dir, name, body);
        let v = toposmooth(&["verify", &f]);
        assert_eq!(v.status.code(), Some(1), "{name}: {}", text(&v));
    }
    let seattle = dataset("seattle_weather_daily_2012_2015.csv");
    let v = toposmooth(&["verify", &out, "--input", &seattle, "--column", "temp_max"]);
    assert_eq!(v.status.code(), Some(1), "{}", text(&v));
}

fn is_png(path: &Path) -> bool {
    std::fs::read(path).map(|b| b.starts_with(b"\x89PNG\r\n\x1a\n") && b.len() > 1000).unwrap_or(false)
}

#[test]
fn plots_are_written_as_png() {
    let dir = scratch("plots");
    let fx = dataset("fx_eur_per_usd_daily_1999_2017.csv");
    let (out, fig, diag) = (dir.join("o.csv"), dir.join("smooth.png"), dir.join("diagram.png"));
    let o = toposmooth(&[
        "smooth",
        &fx,
        "-o",
        out.to_str().unwrap(),
        "--persistence",
        "8%",
        "--plot",
        fig.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(is_png(&fig));
    let o = toposmooth(&["extrema", &fx, "--plot", diag.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(is_png(&diag));
    let bad = dir.join("figure.jpg");
    let out2 = dir.join("o2.csv");
    let o = toposmooth(&["smooth", &fx, "-o", out2.to_str().unwrap(), "--plot", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(!bad.exists() && !out2.exists(), "nothing written");
    // a report that cannot be written leaves no CSV and no plot behind
    let (out3, fig3) = (dir.join("o3.csv"), dir.join("f3.png"));
    let report = dir.join("no-such-dir").join("r.json");
    let o = toposmooth(&[
        "smooth",
        &fx,
        "-o",
        out3.to_str().unwrap(),
        "--plot",
        fig3.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    // checked before any work: a usage error
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("no-such-dir does not exist"), "{}", text(&o));
    assert!(!out3.exists() && !fig3.exists(), "nothing committed");
    let tmp_left = std::fs::read_dir(&dir).unwrap().flatten().any(|e| {
        let n = e.file_name().to_string_lossy().into_owned();
        n.ends_with(".tmp") || n.starts_with(".toposmooth-")
    });
    assert!(!tmp_left);
    // outputs that collide with each other or with the input are usage errors
    let same = dir.join("same.png");
    let o = toposmooth(&["smooth", &fx, "-o", same.to_str().unwrap(), "--plot", same.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let o = toposmooth(&["smooth", &fx, "-o", &fx]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

#[test]
fn seattle_by_column_name_and_pairs() {
    let dir = scratch("sea");
    let out = dir.join("sea.csv").display().to_string();
    let o = toposmooth(&[
        "smooth",
        &dataset("seattle_weather_daily_2012_2015.csv"),
        "--column",
        "temp_max",
        "--pairs",
        "8",
        "--order",
        "3",
        "-o",
        &out,
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("`temp_max`"), "{}", text(&o));
    assert!(text(&o).contains("kept 9 minima and 8 maxima"), "{}", text(&o));
    assert_eq!(toposmooth(&["verify", &out]).status.code(), Some(0));
}

#[test]
fn extrema_lists_json() {
    let dir = scratch("ext");
    let f = write(&dir, "s.csv", "v\n0\n3\n1\n2\n-1\n");
    let o = toposmooth(&["extrema", &f, "--json"]);
    assert!(o.status.success(), "{}", text(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["sos_minima"], 3);
    assert_eq!(j["sos_maxima"], 2); // the interior maxima 1 and 3; no end is a maximum here
    let rows = j["extrema"].as_array().unwrap();
    let m = rows.iter().find(|r| r["index"] == 2).unwrap();
    assert_eq!(m["persistence"], 1.0);
    let e = rows.iter().find(|r| r["index"] == 4).unwrap();
    assert!(e["persistence"].is_null(), "essential minimum: null");
    // x as a number (the sample index here); dates also as the file's text
    assert_eq!((m["x"].as_f64(), e["x"].as_f64()), (Some(2.0), Some(4.0)));
    assert!(m.get("x_text").is_none());
    let dated = write(&dir, "d.csv", "date,v\n2020-01-01,0\n2020-01-03,3\n2020-01-04,1\n2020-01-05,2\n2020-01-07,-1\n");
    let j: serde_json::Value = serde_json::from_slice(&toposmooth(&["extrema", &dated, "--json"]).stdout).unwrap();
    let m = j["extrema"].as_array().unwrap().iter().find(|r| r["index"] == 2).unwrap().clone();
    // dates: x in days since 1970-01-01 (2020-01-04 is day 18,265)
    assert_eq!((m["x"].as_f64(), m["x_text"].as_str()), (Some(18265.0), Some("2020-01-04")), "{m}");
    let o = toposmooth(&["extrema", &f]);
    assert!(text(&o).contains("strict"), "{}", text(&o));
}

fn assert_input_error(args: &[&str], needles: &[&str], out: Option<&PathBuf>) {
    let o = toposmooth(args);
    assert_eq!(o.status.code(), Some(3), "{args:?}: {}", text(&o));
    for n in needles {
        assert!(text(&o).contains(n), "{args:?}: `{n}` not in {}", text(&o));
    }
    if let Some(p) = out {
        assert!(!p.exists(), "no output on failure");
        let leftovers: Vec<_> = std::fs::read_dir(p.parent().unwrap())
            .unwrap()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with(".toposmooth-"))
            .collect();
        assert!(leftovers.is_empty());
    }
}

#[test]
fn input_errors_exit_3_naming_the_file() {
    let dir = scratch("err");
    let out = dir.join("out.csv");
    let o = out.display().to_string();
    let nan = write(&dir, "nan.csv", "v\n1\n2\nNaN\n0\n");
    assert_input_error(&["smooth", &nan, "-o", &o], &["nan.csv", "line 4", "not finite"], Some(&out));
    let empty = write(&dir, "empty.csv", "");
    assert_input_error(&["smooth", &empty, "-o", &o], &["empty.csv", "empty"], Some(&out));
    let constant = write(&dir, "const.csv", "1\n1\n1\n");
    assert_input_error(&["smooth", &constant, "-o", &o], &["const.csv", "constant"], Some(&out));
    let good = write(&dir, "good.csv", "v\n0\n2\n5\n2\n0.5\n1\n1.5\n1\n0.2\n");
    assert_input_error(&["smooth", &good, "--column", "w", "-o", &o], &["good.csv", "no column `w`"], Some(&out));
    assert_input_error(
        &["smooth", &good, "--keep-min", "4,8", "--keep-max", "2", "-o", &o],
        &["good.csv", "4 and 8"],
        Some(&out),
    );
    assert_input_error(
        &["smooth", &good, "--keep-min", "3", "--keep-max", "2", "-o", &o],
        &["vertex 3", "not a local minimum"],
        Some(&out),
    );
    assert_input_error(
        &["smooth", &good, "--keep-min", "4", "--keep-max", "99", "-o", &o],
        &["out of range"],
        Some(&out),
    );
    assert_input_error(
        &["smooth", &good, "--sharp", "17", "-o", &o],
        &["good.csv", "sharp vertex 17", "out of range"],
        Some(&out),
    );
    let missing = dir.join("nope.csv").display().to_string();
    assert_input_error(&["smooth", &missing, "-o", &o], &["nope.csv"], Some(&out));
    let unsorted = write(&dir, "dates.csv", "date,v\n2010-01-02,1\n2010-01-01,2\n2010-01-03,0\n");
    assert_input_error(&["smooth", &unsorted, "-o", &o], &["dates.csv", "line 3", "strictly increase"], Some(&out));
    let ragged = write(&dir, "ragged.csv", "a,b\n1,2\n3\n");
    assert_input_error(&["extrema", &ragged], &["ragged.csv"], None);
    // explicit list that is fine is certified and written
    let ok = toposmooth(&["smooth", &good, "--keep-min", "4", "--keep-max", "2,6", "-o", &o]);
    assert!(ok.status.success(), "{}", text(&ok));
    assert!(out.exists());
}

#[test]
fn usage_errors_exit_2() {
    let dir = scratch("usage");
    let good = write(&dir, "g.csv", "0\n2\n1\n3\n");
    let o = dir.join("o.csv").display().to_string();
    for args in [
        vec!["smooth", &good, "-o", &o, "--persistence", "0"],
        vec!["smooth", &good, "-o", &o, "--persistence", "abc"],
        vec!["smooth", &good, "-o", &o, "--order", "7"],
        vec!["smooth", &good, "-o", &o, "--order", "2:-1"],
        vec!["smooth", &good, "-o", &o, "--persistence", "5%", "--pairs", "2"],
        vec!["smooth", &good, "-o", &o, "--keep-min", "0"],
        vec!["smooth", &good, "-o", &o, "--max-iter", "0"],
        vec!["smooth", &good, "-o", &o, "--data-weight", "-1"],
        vec!["smooth", &good],
        vec!["frobnicate"],
    ] {
        let out = toposmooth(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", text(&out));
    }
}

#[test]
fn reports_carry_the_version_the_command_line_and_a_structured_selection() {
    let dir = scratch("provenance");
    let out = dir.join("v.vti").display().to_string();
    let report = dir.join("run.json").display().to_string();
    let piv = dataset("soapfilm_piv_vorticity_63x63.csv");
    let args = ["smooth", &piv, "--fill-missing", "-o", &out, "--persistence", "5%", "--report", &report];
    let o = toposmooth(&args);
    assert!(o.status.success(), "{}", text(&o));
    let r = common::json(&report);
    assert_eq!(r["tool"], "toposmooth");
    assert_eq!(r["version"], env!("CARGO_PKG_VERSION"));
    let line: Vec<&str> = r["command_line"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
    assert_eq!(&line[1..], &args[..], "the arguments as given");
    assert_eq!(r["settings"]["selection"], serde_json::json!({"rule": "relative", "fraction_of_range": 0.05}));
    // each kept extremum with its position: grid vertex index = row · 63 + column, spacing 1
    let kept = r["kept"].as_array().unwrap();
    assert!(!kept.is_empty());
    for k in kept {
        let i = k["index"].as_u64().unwrap();
        let p: Vec<f64> = k["point"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        assert_eq!(p, [(i % 63) as f64, (i / 63) as f64, 0.0], "{k}");
    }
    let o = toposmooth(&[
        "smooth",
        &piv,
        "--fill-missing",
        "-o",
        &out,
        "--minima",
        "2",
        "--maxima",
        "3",
        "--report",
        &report,
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let r = common::json(&report);
    assert_eq!(r["settings"]["selection"], serde_json::json!({"rule": "count", "minima": 2, "maxima": 3}));
}
