//! Several inputs at once: `smooth A B … --out-dir DIR` and `smooth series.pvd --out-dir DIR`.
//! Each output is byte for byte the file a run on that input alone writes (the inputs on one
//! domain share its smoother), a ParaView collection lists them in order, and every misuse is
//! refused before any work.

mod common;

use common::{scratch, text, toposmooth};
use std::path::{Path, PathBuf};

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// Four time steps of a moving pattern on one 40 × 28 grid, as .npy files.
fn steps(dir: &Path) -> Vec<PathBuf> {
    (0..4)
        .map(|t| {
            let (nx, ny) = (40, 28);
            let values: Vec<f64> = (0..nx * ny)
                .map(|i| {
                    let (r, c) = ((i / nx) as f64, (i % nx) as f64);
                    ((c - 2.0 * t as f64) / 5.0).sin() * (r / 4.0).cos()
                        + 0.05 * (((i * 7919 + t * 31) % 23) as f64 / 23.0)
                })
                .collect();
            let p = dir.join(format!("step_{t}.npy"));
            toposmooth::io::npz::stage_npy(&p, ny, nx, &values).unwrap().commit().unwrap();
            p
        })
        .collect()
}

#[test]
fn every_output_is_the_single_runs_and_a_collection_lists_them() {
    let dir = scratch("many");
    let inputs = steps(&dir);
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let mut args = vec!["smooth".to_string()];
    args.extend(inputs.iter().map(|p| s(p)));
    args.extend(["--out-dir", &s(&out), "--out-format", "vti", "--persistence", "10%"].map(String::from));
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = toposmooth(&argv);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("[4 of 4]") && text(&o).contains("collection.pvd"), "{}", text(&o));
    for (t, p) in inputs.iter().enumerate() {
        let alone = dir.join(format!("alone_{t}.vti"));
        assert!(toposmooth(&["smooth", &s(p), "-o", &s(&alone), "--persistence", "10%"]).status.success());
        let batch = out.join(format!("step_{t}.vti"));
        assert_eq!(std::fs::read(&batch).unwrap(), std::fs::read(&alone).unwrap(), "step {t} differs from its own run");
        assert!(toposmooth(&["verify", &s(&batch)]).status.success());
    }
    let pvd = std::fs::read_to_string(out.join("collection.pvd")).unwrap();
    let files: Vec<&str> = pvd.split("file=\"").skip(1).map(|r| &r[..r.find('"').unwrap()]).collect();
    assert_eq!(files, ["step_0.vti", "step_1.vti", "step_2.vti", "step_3.vti"]);
    assert!(pvd.contains("timestep=\"3.0\""), "{pvd}");

    // the collection as the input: its files and time steps, into another directory
    let again = dir.join("again");
    std::fs::create_dir_all(&again).unwrap();
    let o = toposmooth(&["smooth", &s(&out.join("collection.pvd")), "--out-dir", &s(&again), "--array", "smoothed"]);
    assert!(o.status.success(), "{}", text(&o));
    let pvd2 = std::fs::read_to_string(again.join("collection.pvd")).unwrap();
    assert_eq!(pvd2, pvd, "same names, same time steps");
    assert!(toposmooth(&["verify", &s(&again.join("step_2.vti"))]).status.success());
}

#[test]
fn misuse_is_refused_before_any_work() {
    let dir = scratch("many_refused");
    let inputs = steps(&dir);
    let (a, b) = (s(&inputs[0]), s(&inputs[1]));
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let o_dir = s(&out);
    let sub = dir.join("sub");
    std::fs::create_dir_all(&sub).unwrap();
    std::fs::copy(&inputs[0], sub.join("step_0.npy")).unwrap();
    let same_name = s(&sub.join("step_0.npy"));
    let plot = s(&out.join("p.png"));
    let missing = s(&dir.join("nowhere"));
    let inputs_dir = s(&dir);
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["smooth", &a, &b, "-o", "x.vti"], "--out-dir"),
        (vec!["smooth", &a, &b, "--out-dir", &o_dir, "--plot", &plot], "--plot"),
        (vec!["smooth", &a, &same_name, "--out-dir", &o_dir], "would both be written"),
        (vec!["smooth", &a, &b, "--out-dir", &missing], "does not exist"),
        (vec!["smooth", &a, &b, "--out-dir", &inputs_dir], "is also an input"),
        (vec!["smooth", &a, &b, "--out-dir", &o_dir, "-o", "x.vti"], "cannot be used with"),
        (vec!["smooth", &a, "-o", "x.vti", "--out-format", "vti"], "--out-format"),
    ];
    for (args, needle) in cases {
        let o = toposmooth(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o));
        assert!(text(&o).contains(needle), "{args:?}: {}", text(&o));
    }
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 0, "nothing written");
    // a file that is not a collection
    let fake = dir.join("fake.pvd");
    std::fs::write(&fake, "<VTKFile type=\"ImageData\"/>").unwrap();
    let o = toposmooth(&["smooth", &s(&fake), "--out-dir", &o_dir]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("fake.pvd") && text(&o).contains("not a ParaView collection"), "{}", text(&o));
}

/// A ParaView series as ParaView saves it (`name.pvd` beside `name/name_0.vti`): written into
/// the collection's own directory, the new collection would replace the input one — refused.
/// With `--out-format`, a numbered stem keeps its dots (`flow.0001.npy` → `flow.0001.vti`).
#[test]
fn a_collection_is_never_replaced_and_numbered_names_keep_their_dots() {
    let dir = scratch("many_pvd");
    let data = dir.join("name");
    std::fs::create_dir_all(&data).unwrap();
    let steps = steps(&data);
    let numbered: Vec<PathBuf> = steps
        .iter()
        .enumerate()
        .map(|(t, p)| {
            let q = data.join(format!("flow.{:04}.npy", t + 1));
            std::fs::rename(p, &q).unwrap();
            q
        })
        .collect();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let mut args = vec!["smooth".to_string()];
    args.extend(numbered.iter().map(|p| s(p)));
    args.extend(["--out-dir", &s(&out), "--out-format", "vti"].map(String::from));
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = toposmooth(&argv);
    assert!(o.status.success(), "{}", text(&o));
    for t in 1..=4 {
        assert!(out.join(format!("flow.{t:04}.vti")).exists(), "flow.{t:04}.vti");
    }
    // the collection, its files in name/, smoothed into the collection's own directory
    let pvd = dir.join("name.pvd");
    let listed: String = (1..=4).map(|t| format!("<DataSet timestep=\"{t}\" file=\"out/flow.{t:04}.vti\"/>")).collect();
    std::fs::write(&pvd, format!("<VTKFile type=\"Collection\"><Collection>{listed}</Collection></VTKFile>")).unwrap();
    let before = std::fs::read(&pvd).unwrap();
    let o = toposmooth(&["smooth", &s(&pvd), "--out-dir", &s(&dir), "--array", "smoothed"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("name.pvd") && text(&o).contains("also an input"), "{}", text(&o));
    assert_eq!(std::fs::read(&pvd).unwrap(), before, "the input collection is untouched");
}
