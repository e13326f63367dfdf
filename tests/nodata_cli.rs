//! The no-data mode from the command line: `weights` (four methods, the certificate, the
//! spurious-extremum counts, partition of unity, cages), `deform`, `diffuse`, and every error
//! path the issue names.

mod common;

use common::{dataset, mesh_extrema, scratch, succeeds, text, toposmooth};
use std::path::{Path, PathBuf};
use toposmooth::io::mesh::read_mesh;

fn write(dir: &Path, name: &str, content: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p.display().to_string()
}

/// A 2D bar [0, 10] × [0, 1] triangulated with `nx × ny` quads, as OBJ.
fn bar_obj(dir: &Path, nx: usize, ny: usize) -> String {
    let mut s = String::new();
    for j in 0..=ny {
        for i in 0..=nx {
            s += &format!("v {} {} 0\n", 10.0 * i as f64 / nx as f64, j as f64 / ny as f64);
        }
    }
    let id = |i: usize, j: usize| j * (nx + 1) + i + 1;
    for j in 0..ny {
        for i in 0..nx {
            s += &format!(
                "f {} {} {}\nf {} {} {}\n",
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j),
                id(i + 1, j + 1),
                id(i, j + 1)
            );
        }
    }
    write(dir, "bar.obj", &s)
}

/// Writes `data` (positions, triangles, arrays) as .vtu to `path`.
fn write_vtu(path: &str, data: &toposmooth::io::mesh::MeshData) {
    let arrays: Vec<(&str, &[f64])> = data.arrays.iter().map(|x| (x.name.as_str(), x.values.as_slice())).collect();
    toposmooth::io::vtk::stage_vtu(Path::new(path), &data.positions, &data.triangles, &arrays)
        .unwrap()
        .commit()
        .unwrap();
}

fn out(dir: &Path, name: &str) -> String {
    dir.join(name).display().to_string()
}

#[test]
fn four_methods_on_a_bar_with_two_point_handles() {
    let dir = scratch("nodata_bar");
    let bar = bar_obj(&dir, 60, 6);
    let handles = write(
        &dir,
        "h.json",
        r#"{"handles": [{"name": "a", "point": [2.5, 0.5]}, {"name": "b", "point": [7.5, 0.5]}]}"#,
    );
    let w = out(&dir, "w.vtu");
    let report = out(&dir, "r.json");
    succeeds(&[
        "weights",
        &bar,
        "--handles",
        &handles,
        "-o",
        &w,
        "--compare",
        "--report",
        &report,
        "--plot",
        &out(&dir, "w.png"),
    ]);
    let r = common::json(&report);
    let cmp = r["comparison"].as_array().unwrap();
    let get = |m: &str| cmp.iter().find(|c| c["method"] == m).unwrap_or_else(|| panic!("{m} missing"));
    assert_eq!(get("monotone")["spurious_exact"], serde_json::json!([0, 0]));
    assert_eq!(get("monotone")["certified"], serde_json::json!([true, true]));
    // the biharmonic functions overshoot beyond the handles: one spurious extremum at least
    let unconstrained: Vec<u64> =
        get("unconstrained")["spurious_exact"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
    assert!(unconstrained.iter().all(|&c| c >= 1), "{unconstrained:?}");
    assert!(get("unconstrained")["below_zero"].as_u64().unwrap() > 0);
    assert_eq!(get("bounded")["below_zero"], 0);
    for m in ["bounded", "harmonic"] {
        assert!(get(m)["spurious_tolerance_1e9"].is_array());
    }
    // the file: certified by verify, extrema counted independently, partition of unity
    succeeds(&["verify", &w]);
    let d = read_mesh(Path::new(&w)).unwrap();
    for name in ["a", "b"] {
        let raw = d.array(&format!("weight_{name}_raw")).unwrap().values;
        let (minima, maxima, flat) = mesh_extrema(d.positions.len(), &d.triangles, &raw);
        assert_eq!((minima.len(), maxima.len(), flat.len()), (1, 1, 0), "{name}");
        assert_eq!(raw[maxima[0]], 1.0);
    }
    let (a, b) = (d.array("weight_a").unwrap().values, d.array("weight_b").unwrap().values);
    assert!(a.iter().zip(&b).all(|(x, y)| (x + y - 1.0).abs() < 1e-12));
    // tampering is caught
    let mut tampered = d.clone();
    let k = tampered.arrays.iter().position(|x| x.name == "weight_a_raw").unwrap();
    tampered.arrays[k].values[100] = 2.0;
    let bad = out(&dir, "tampered.vtu");
    write_vtu(&bad, &tampered);
    let o = toposmooth(&["verify", &bad]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
}

#[test]
fn penguin_weights_pose_and_identity_pose() {
    let dir = scratch("nodata_penguin");
    let penguin = dataset("penguin.obj");
    let handles = dataset("penguin_handles.json");
    let w = out(&dir, "w.vtu");
    let o = succeeds(&["weights", &penguin, "--handles", &handles, "-o", &w, "--order", "3"]);
    assert!(text(&o).matches("certified;").count() >= 4, "{}", text(&o));
    // identity transforms reproduce the rest pose, both skinning methods
    let identity = write(&dir, "id.json", r#"{"transforms": {"head": [[1,0,0,0],[0,1,0,0],[0,0,1,0]]}}"#);
    let rest = read_mesh(Path::new(&penguin)).unwrap();
    for s in ["lbs", "dqs"] {
        let posed = out(&dir, &format!("id_{s}.obj"));
        succeeds(&["deform", &penguin, "--weights", &w, "--transforms", &identity, "-o", &posed, "--skinning", s]);
        let p = read_mesh(Path::new(&posed)).unwrap();
        assert_eq!(p.triangles, rest.triangles);
        let err = p
            .positions
            .iter()
            .zip(&rest.positions)
            .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "{s}: {err}");
    }
    // the bundled pose moves the flippers and not the feet
    let posed = out(&dir, "posed.obj");
    succeeds(&[
        "deform",
        &penguin,
        "--weights",
        &w,
        "--transforms",
        &dataset("penguin_pose.json"),
        "-o",
        &posed,
        "--skinning",
        "dqs",
        "--plot",
        &out(&dir, "posed.png"),
    ]);
    let p = read_mesh(Path::new(&posed)).unwrap();
    let moved = |v: usize| (0..3).map(|k| (p.positions[v][k] - rest.positions[v][k]).powi(2)).sum::<f64>().sqrt();
    assert!(moved(927) > 0.3, "left flipper tip moved {}", moved(927));
    assert!(moved(1126) < 0.05, "foot moved {}", moved(1126));
}

#[test]
fn diffusion_stays_in_the_colour_box_and_the_biharmonic_one_does_not() {
    let dir = scratch("nodata_diffuse");
    let colors = dataset("horse_colors.json");
    let png = out(&dir, "horse.png");
    succeeds(&[
        "diffuse",
        &dataset("horse_mask.png"),
        "--colors",
        &colors,
        "-o",
        &png,
        "--plot",
        &out(&dir, "plot.png"),
    ]);
    let c = common::json(&colors);
    let rgbs: Vec<[u8; 3]> = c["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let v: Vec<u8> = p["rgb"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap() as u8).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let outside = |path: &str| -> (usize, usize) {
        let img = image::open(path).unwrap().to_rgba8();
        let mut opaque = 0;
        let mut out = 0;
        for p in img.pixels() {
            if p.0[3] == 0 {
                continue;
            }
            opaque += 1;
            if (0..3).any(|ch| {
                p.0[ch] < rgbs.iter().map(|c| c[ch]).min().unwrap()
                    || p.0[ch] > rgbs.iter().map(|c| c[ch]).max().unwrap()
            }) {
                out += 1;
            }
        }
        (opaque, out)
    };
    let (opaque, out_box) = outside(&png);
    assert!(opaque > 10_000);
    assert_eq!(out_box, 0);
    // the colours are where they were put
    let img = image::open(&png).unwrap().to_rgba8();
    let p0 = &c["points"][0]["pixel"];
    let px = img.get_pixel(p0[0].as_u64().unwrap() as u32, p0[1].as_u64().unwrap() as u32);
    assert_eq!([px.0[0], px.0[1], px.0[2]], rgbs[0]);
    // the weights file is verifiable
    succeeds(&["verify", &out(&dir, "horse_weights.vtu")]);
    let bih = out(&dir, "bih.png");
    let o = succeeds(&[
        "diffuse",
        &dataset("horse_mask.png"),
        "--colors",
        &colors,
        "-o",
        &bih,
        "--method",
        "unconstrained",
    ]);
    let (_, out_bih) = outside(&bih);
    assert!(out_bih > 100, "{out_bih}");
    assert!(text(&o).contains(&format!("{out_bih} of")), "{}", text(&o));
}

#[test]
fn cage_weights_on_the_horse() {
    let dir = scratch("nodata_cage");
    let horse = dataset("horse_silhouette_2d.obj");
    let w = out(&dir, "w.vtu");
    let report = out(&dir, "r.json");
    let o = succeeds(&[
        "weights",
        &horse,
        "--handles",
        &dataset("horse_cage.json"),
        "-o",
        &w,
        "--order",
        "1",
        "--report",
        &report,
    ]);
    assert!(text(&o).contains("7 of 7 monotone functions"), "{}", text(&o));
    let r = common::json(&report);
    assert!(r["linear_reproduction_error"].as_f64().unwrap() < 1e-6);
    // the interpolated weights are not certified: verify points to the cage file
    let o = toposmooth(&["verify", &w]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("_cage.vtu"), "{}", text(&o));
    succeeds(&["verify", &out(&dir, "w_cage.vtu")]);
    let d = read_mesh(Path::new(&w)).unwrap();
    let n = d.positions.len();
    let sums: Vec<f64> =
        (0..n).map(|v| (0..7).map(|j| d.array(&format!("weight_{j}")).unwrap().values[v]).sum()).collect();
    assert!(sums.iter().all(|s| (s - 1.0).abs() < 1e-9));
}

#[test]
fn every_no_data_error_path_names_its_file() {
    let dir = scratch("nodata_errors");
    let bar = bar_obj(&dir, 20, 2);
    let w = out(&dir, "w.vtu");
    let cases: Vec<(&str, &str)> = vec![
        (r#"{"handles": [{"name": "a", "point": [2.5, 5]}, {"name": "b", "point": [7.5, 0.5]}]}"#, "outside"),
        (
            r#"{"handles": [{"name": "a", "point": [2.5, 0.5]}, {"name": "b", "point": [2.52, 0.5]}]}"#,
            "both select vertex",
        ),
        (r#"{"handles": [{"name": "a", "point": [2.5, 0.5]}]}"#, "at least two handles"),
        (r#"{"cage": [[1, -1], [3, -1], [3, 2], [1, 2]]}"#, "does not enclose"),
        (r#"{"handles": [{"name": "a", "vertices": [0, 1]}, {"name": "b", "vertices": [1]}]}"#, "both select vertex 1"),
    ];
    for (k, (json, expect)) in cases.iter().enumerate() {
        let h = write(&dir, &format!("h{k}.json"), json);
        let o = toposmooth(&["weights", &bar, "--handles", &h, "-o", &w]);
        assert_eq!(o.status.code(), Some(3), "{json}: {}", text(&o));
        assert!(text(&o).contains(expect) && text(&o).contains(&format!("h{k}.json")), "{json}: {}", text(&o));
        assert!(!Path::new(&w).exists());
    }
    // a component with no handle: two bars side by side
    let mut two = std::fs::read_to_string(&bar).unwrap();
    let nv = two.lines().filter(|l| l.starts_with("v ")).count();
    let extra: String = two
        .lines()
        .map(|l| {
            let p: Vec<&str> = l.split_whitespace().collect();
            match p[0] {
                "v" => format!("v {} {} 0\n", p[1], p[2].parse::<f64>().unwrap() + 5.0),
                _ => format!(
                    "f {} {} {}\n",
                    p[1].parse::<usize>().unwrap() + nv,
                    p[2].parse::<usize>().unwrap() + nv,
                    p[3].parse::<usize>().unwrap() + nv
                ),
            }
        })
        .collect();
    two += &extra;
    let two_path = write(&dir, "two.obj", &two);
    let h = write(
        &dir,
        "h_two.json",
        r#"{"handles": [{"name": "a", "point": [2.5, 0.5]}, {"name": "b", "point": [7.5, 0.5]}]}"#,
    );
    let o = toposmooth(&["weights", &two_path, "--handles", &h, "-o", &w]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("has no handle"), "{}", text(&o));
    // deform: a transform naming no handle; diffuse: a colour outside the shape
    let hw = write(
        &dir,
        "ok.json",
        r#"{"handles": [{"name": "a", "point": [2.5, 0.5]}, {"name": "b", "point": [7.5, 0.5]}]}"#,
    );
    succeeds(&["weights", &bar, "--handles", &hw, "-o", &w]);
    let pose = write(&dir, "pose.json", r#"{"transforms": {"c": [[1,0,0,0],[0,1,0,0],[0,0,1,0]]}}"#);
    let o = toposmooth(&["deform", &bar, "--weights", &w, "--transforms", &pose, "-o", &out(&dir, "p.obj")]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("pose.json") && text(&o).contains("`c`"), "{}", text(&o));
    let colors = write(
        &dir,
        "c.json",
        r#"{"points": [{"pixel": [0, 0], "rgb": [255, 0, 0]}, {"pixel": [100, 80], "rgb": [0, 0, 255]}]}"#,
    );
    let o = toposmooth(&["diffuse", &dataset("horse_mask.png"), "--colors", &colors, "-o", &out(&dir, "d.png")]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("outside the image's shape") && text(&o).contains("c.json"), "{}", text(&o));
    let _: PathBuf = dir;
}

#[test]
fn a_bone_across_a_bar_fills_the_part_beyond_it() {
    let dir = scratch("nodata_bone");
    let bar = bar_obj(&dir, 40, 4);
    let h = write(
        &dir,
        "h.json",
        r#"{"handles": [{"name": "tip", "point": [1, 0.5]}, {"name": "wrist", "bone": [[7, -1, 0], [7, 2, 0]], "radius": 0.2}]}"#,
    );
    let w = out(&dir, "w.vtu");
    let report = out(&dir, "r.json");
    succeeds(&["weights", &bar, "--handles", &h, "-o", &w, "--report", &report]);
    let r = common::json(&report);
    // the bone takes the columns at x = 7 (±0.2 reaches only that column of vertices: spacing 0.25);
    // the 12 columns beyond (x = 7.25 … 10) are filled, 5 vertices each
    assert_eq!(r["functions"][1]["handle_vertices"], 5);
    assert_eq!(r["functions"][0]["filled"], 60);
    assert_eq!(r["functions"][1]["filled"], 60);
    let d = read_mesh(Path::new(&w)).unwrap();
    let tip = d.array("weight_tip_raw").unwrap().values;
    let wrist = d.array("weight_wrist_raw").unwrap().values;
    for (v, p) in d.positions.iter().enumerate() {
        if p[0] > 7.1 {
            assert_eq!((tip[v], wrist[v]), (0.0, 1.0), "vertex {v} beyond the bone");
        }
    }
    succeeds(&["verify", &w]);
}

#[test]
fn diffusion_on_a_mesh_writes_colour_arrays() {
    let dir = scratch("nodata_diffuse_mesh");
    let bar = bar_obj(&dir, 40, 4);
    let colors = write(
        &dir,
        "c.json",
        r#"{"points": [{"point": [0, 0], "rgb": [255, 0, 0]}, {"vertex": 40, "rgb": [0, 0, 255]}, {"point": [5, 1], "rgb": [0, 200, 0]}]}"#,
    );
    let o_path = out(&dir, "bar_colours.ply");
    let png = out(&dir, "bar.png");
    let o = succeeds(&["diffuse", &bar, "--colors", &colors, "-o", &o_path, "--plot", &png]);
    assert!(text(&o).contains("0 of 205 vertices outside"), "{}", text(&o));
    assert!(image::open(&png).unwrap().width() > 300);
    let d = read_mesh(Path::new(&o_path)).unwrap();
    let (r, g, b) = (d.array("red").unwrap().values, d.array("green").unwrap().values, d.array("blue").unwrap().values);
    assert_eq!((r[0], g[0], b[0]), (255.0, 0.0, 0.0));
    assert_eq!((r[40], g[40], b[40]), (0.0, 0.0, 255.0));
    assert!(g.iter().all(|&x| x <= 200.0));
    succeeds(&["verify", &o_path]);
    // a colour moved outside the box is caught
    let mut d = d;
    let k = d.arrays.iter().position(|a| a.name == "green").unwrap();
    d.arrays[k].values[100] = 250.0;
    let bad_path = out(&dir, "bad_colour.vtu");
    write_vtu(&bad_path, &d);
    let o = toposmooth(&["verify", &bad_path]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    // --weights is for images
    let o = toposmooth(&["diffuse", &bar, "--colors", &colors, "-o", &o_path, "--weights", &out(&dir, "w.vtu")]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    // an image-only field on a mesh is refused
    let bad = write(
        &dir,
        "bad.json",
        r#"{"points": [{"pixel": [0, 0], "rgb": [255, 0, 0]}, {"vertex": 40, "rgb": [0, 0, 255]}]}"#,
    );
    let o = toposmooth(&["diffuse", &bar, "--colors", &bad, "-o", &o_path]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
}

#[test]
fn outputs_never_overwrite_inputs_or_each_other() {
    let dir = scratch("nodata_paths");
    let bar = bar_obj(&dir, 20, 2);
    let h = write(
        &dir,
        "h.json",
        r#"{"handles": [{"name": "a", "point": [2.5, 0.5]}, {"name": "b", "point": [7.5, 0.5]}]}"#,
    );
    let before = std::fs::read(&bar).unwrap();
    let w = out(&dir, "w.vtu");
    for args in [
        vec!["weights", &bar, "--handles", &h, "-o", &bar],
        vec!["weights", &bar, "--handles", &h, "-o", &h],
        vec!["weights", &bar, "--handles", &h, "-o", &w, "--report", &w],
        vec!["weights", &bar, "--handles", &h, "-o", &w, "--cage-output", &w],
        vec!["weights", &bar, "--handles", &h, "-o", &out(&dir, "w.txt")],
    ] {
        let o = toposmooth(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o));
        assert!(!Path::new(&w).exists());
    }
    assert_eq!(std::fs::read(&bar).unwrap(), before);
    succeeds(&["weights", &bar, "--handles", &h, "-o", &w]);
    let pose = write(&dir, "pose.json", r#"{"transforms": {"a": [[1,0,0,1],[0,1,0,0],[0,0,1,0]]}}"#);
    for target in [&bar, &w, &pose] {
        let o = toposmooth(&["deform", &bar, "--weights", &w, "--transforms", &pose, "-o", target]);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    }
    assert_eq!(std::fs::read(&bar).unwrap(), before);
    succeeds(&["verify", &w]);
}

#[test]
fn adjacent_handles_form_one_region_and_tampered_weights_fail_verify() {
    let dir = scratch("nodata_regions");
    let bar = bar_obj(&dir, 20, 2);
    // vertices 0 and 1 are adjacent: both 0 in c's function, one minimum region (role 2)
    let h = write(
        &dir,
        "h.json",
        r#"{"handles": [{"name": "a", "vertices": [0]}, {"name": "b", "vertices": [1]}, {"name": "c", "vertices": [40]}]}"#,
    );
    let w = out(&dir, "w.vtu");
    succeeds(&["weights", &bar, "--handles", &h, "-o", &w]);
    let d = read_mesh(Path::new(&w)).unwrap();
    let role_c = d.array("role_c").unwrap().values;
    assert_eq!((role_c[0], role_c[1], role_c[40]), (2.0, 2.0, 1.0));
    let role_a = d.array("role_a").unwrap().values;
    assert_eq!((role_a[0], role_a[1], role_a[40]), (1.0, -1.0, -1.0)); // different values: separate regions
    succeeds(&["verify", &w]);
    let tamper = |name: &str, f: &dyn Fn(&mut toposmooth::io::mesh::MeshData)| {
        let mut t = d.clone();
        f(&mut t);
        let path = out(&dir, name);
        write_vtu(&path, &t);
        let o = toposmooth(&["verify", &path]);
        assert_eq!(o.status.code(), Some(1), "{name}: {}", text(&o));
    };
    // a spurious maximum hidden behind role 2, and a region member marked as a lone extremum
    tamper("hidden.vtu", &|t| {
        let at = |t: &toposmooth::io::mesh::MeshData, n: &str| t.arrays.iter().position(|a| a.name == n).unwrap();
        let (raw, u, role) = (at(t, "weight_a_raw"), at(t, "u_a"), at(t, "role_a"));
        t.arrays[raw].values[30] = 0.999;
        t.arrays[u].values[30] = 0.999;
        t.arrays[role].values[30] = 2.0;
        // renormalise so that only the fixed value gives it away
        let raws: Vec<Vec<f64>> =
            ["a", "b", "c"].iter().map(|h| t.arrays[at(t, &format!("weight_{h}_raw"))].values.clone()).collect();
        for (k, h) in ["a", "b", "c"].iter().enumerate() {
            let i = at(t, &format!("weight_{h}"));
            for (v, w) in t.arrays[i].values.iter_mut().enumerate() {
                *w = raws[k][v] / (raws[0][v] + raws[1][v] + raws[2][v]);
            }
        }
    });
    tamper("lone.vtu", &|t| {
        let role = t.arrays.iter().position(|a| a.name == "role_c").unwrap();
        t.arrays[role].values[0] = -1.0;
    });
    let scale = |t: &mut toposmooth::io::mesh::MeshData| {
        for a in t.arrays.iter_mut().filter(|a| a.name == "weight_c_raw" || a.name == "u_c") {
            a.values.iter_mut().for_each(|x| *x *= 0.5);
        }
    };
    tamper("halved.vtu", &scale);
    tamper("nan.vtu", &|t| {
        let a = t.arrays.iter_mut().find(|a| a.name == "weight_a").unwrap();
        a.values[7] = f64::NAN;
    });
    tamper("swapped.vtu", &|t| {
        let i = t.arrays.iter().position(|a| a.name == "weight_a").unwrap();
        let j = t.arrays.iter().position(|a| a.name == "weight_c").unwrap();
        let (x, y) = (t.arrays[i].values.clone(), t.arrays[j].values.clone());
        t.arrays[i].values = y;
        t.arrays[j].values = x;
    });
    // names that would break array or PLY property names, two identical bones
    for (json, expect) in [
        (r#"{"handles": [{"name": "arm.l", "vertices": [0]}, {"name": "b", "vertices": [40]}]}"#, "ASCII"),
        (r#"{"handles": [{"name": "a", "vertices": [0]}, {"name": "b_raw", "vertices": [40]}]}"#, "_raw"),
        (
            r#"{"handles": [{"name": "a", "bone": [[5,0,0],[5,1,0]], "radius": 0.3}, {"name": "b", "bone": [[5,0,0],[5,1,0]], "radius": 0.3}, {"name": "c", "vertices": [0]}]}"#,
            "handle `b`",
        ),
    ] {
        let hp = write(&dir, "bad.json", json);
        let o = toposmooth(&["weights", &bar, "--handles", &hp, "-o", &out(&dir, "x.ply")]);
        assert_eq!(o.status.code(), Some(3), "{json}: {}", text(&o));
        assert!(text(&o).contains(expect) && text(&o).contains("bad.json"), "{json}: {}", text(&o));
    }
}

#[test]
fn order_four_weights_stay_with_the_structured_solver() {
    // the horse meshed as for the paper's table 1, four point handles by farthest-point
    // sampling: at k = 4 the gap bound without a data term sits on its rounding floor and the
    // last factorisation fails; the point reached is kept (before: every function was handed
    // to Clarabel, 59–200 iterations each, and came back 10³ × the energy from the optimum)
    let dir = scratch("nodata_order4");
    let mesh = out(&dir, "horse.obj");
    succeeds(&["mesh", &dataset("horse_mask.png"), "--max-area", "7.5", "-o", &mesh]);
    let p = read_mesh(Path::new(&mesh)).unwrap().positions;
    let chosen = toposmooth::apps::handles::farthest_points(&p, 4);
    let list: Vec<String> =
        chosen.iter().enumerate().map(|(i, v)| format!("{{\"name\": \"h{i}\", \"vertices\": [{v}]}}")).collect();
    let handles = write(&dir, "h.json", &format!("{{\"handles\": [{}]}}", list.join(", ")));
    let report = out(&dir, "r.json");
    succeeds(&[
        "weights",
        &mesh,
        "--handles",
        &handles,
        "--order",
        "4",
        "-o",
        &out(&dir, "w.vtu"),
        "--report",
        &report,
    ]);
    let r = common::json(&report);
    let functions = r["functions"].as_array().unwrap();
    assert_eq!(functions.len(), 4);
    for f in functions {
        assert!(f["solver_fallback"].is_null(), "{f}");
        assert!(f["solver_iterations"].as_u64().unwrap() < 50, "{f}");
        // (on its rounding floor, 10⁻⁴ here; Clarabel's output had 1.4·10³ × the energy)
        assert!(f["gap_over_energy"].as_f64().unwrap() < 1e-3, "{f}");
        assert!(f["certificate"]["passed"].as_bool().unwrap(), "{f}");
    }
}
