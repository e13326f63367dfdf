//! The command-line tool on triangle meshes: the geodesic + keep-all-maxima workflow on the
//! bundled spot and mountain meshes (the paper's figure 13), every mesh output format,
//! `verify`, and the input errors of the mesh readers and validation.

mod common;

use common::{dataset, mesh_extrema, scratch, text, toposmooth};
use std::path::Path;
use toposmooth::io::mesh::read_mesh;

#[test]
fn geodesic_distance_keeps_all_its_maxima_on_spot_and_mountain() {
    let dir = scratch("geodesic");
    for (mesh, ext) in [("spot.obj", "vtu"), ("mountain.obj", "ply")] {
        let dist = dir.join(format!("{mesh}.dist.vtu")).display().to_string();
        let out = dir.join(format!("{mesh}.smooth.{ext}")).display().to_string();
        let complex = dir.join(format!("{mesh}.complex.vtp")).display().to_string();
        let o = toposmooth(&["geodesic", &dataset(mesh), "--source", "0", "-o", &dist]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        let d = read_mesh(Path::new(&dist)).unwrap();
        let h = d.array("distance").unwrap().values;
        assert_eq!(h[0], 0.0);
        assert!(h.iter().all(|&x| x >= 0.0), "{mesh}: distances are non-negative");
        let png = dir.join(format!("{mesh}.png")).display().to_string();
        let o = toposmooth(&[
            "smooth",
            &dist,
            "--array",
            "distance",
            "--keep-all-maxima",
            "--representative",
            "separatrix",
            "-o",
            &out,
            "--complex",
            &complex,
            "--plot",
            &png,
            "--view",
            "150,20",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        // the separatrix representative, asked for, stands on both (on the mountain with the
        // one-sided saddles of its kept boundary maxima; the harmonic fallback fitted 5× worse)
        let said = text(&o);
        assert!(said.contains("representative: separatrix") && !said.contains("fallback"), "{said}");
        let rms: f64 = said.split("RMS deviation ").nth(1).and_then(|r| r.split(',').next()).unwrap().parse().unwrap();
        assert!(rms < 0.06, "{mesh}: RMS {rms}");
        let img = image::open(&png).unwrap().to_rgb8();
        assert!(img.width() > 1000 && img.height() > 600);
        // the picture is not blank: many coloured (non-grey) pixels
        let coloured = img.pixels().filter(|p| p.0.iter().max().unwrap() - p.0.iter().min().unwrap() > 40).count();
        assert!(coloured > 50_000, "{coloured}");
        // independent check: the output has the input's maxima of persistence > 0 (all of
        // them: every maximum of a distance field is kept) and the source as only minimum
        let r = read_mesh(Path::new(&out)).unwrap();
        let f = r.array("smoothed").unwrap().values;
        let (in_min, in_max, _) = mesh_extrema(d.positions.len(), &d.triangles, &h);
        let (mins, maxs, flat) = mesh_extrema(r.positions.len(), &r.triangles, &f);
        assert!(flat.is_empty());
        assert_eq!(mins, vec![0], "{mesh}: the source is the only minimum (input had {in_min:?})");
        assert!(maxs.iter().all(|m| in_max.contains(m)), "{mesh}: no new maximum");
        assert_eq!(maxs, in_max, "{mesh}: every maximum of the distance is kept");
        for &m in &maxs {
            assert_eq!(f[m].to_bits(), h[m].to_bits(), "{mesh}: maxima keep their values");
        }
        let v = toposmooth(&["verify", &out, "--input", &dist, "--array", "distance"]);
        assert_eq!(v.status.code(), Some(0), "{}", text(&v));
        assert!(std::fs::metadata(&complex).unwrap().len() > 100);
    }
}

#[test]
fn a_coordinate_or_a_values_file_is_the_field() {
    let dir = scratch("mesh-fields");
    let mesh = dataset("bunny.obj");
    let out = dir.join("b.vtp").display().to_string();
    let o = toposmooth(&["smooth", &mesh, "--array", "y", "--persistence", "10%", "-o", &out]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_eq!(toposmooth(&["verify", &out]).status.code(), Some(0));
    // tampering with the smoothed array is caught: raise a free vertex above all its neighbours
    let m = read_mesh(Path::new(&out)).unwrap();
    let n = m.positions.len();
    let get = |name: &str| m.array(name).unwrap().values;
    let (input, mut smoothed, u, role) = (get("input"), get("smoothed"), get("representative"), get("role"));
    let v = (0..n).find(|&v| role[v] == 0.0).unwrap();
    smoothed[v] = 1e9;
    let bad = dir.join("tampered.ply");
    let arrays: Vec<(&str, &[f64])> =
        vec![("input", &input), ("smoothed", &smoothed), ("representative", &u), ("role", &role)];
    toposmooth::io::mesh::stage_ply(&bad, &m.positions, &m.triangles, &arrays).unwrap().commit().unwrap();
    let o = toposmooth(&["verify", &bad.display().to_string()]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains(&format!("vertex {v}")), "{}", text(&o));
    // the same field from a values file: the y coordinates in the OBJ file's own vertex order
    let obj = std::fs::read_to_string(&mesh).unwrap();
    let values: String = obj
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| format!("{}\n", l.split_whitespace().nth(2).unwrap()))
        .collect();
    let file = dir.join("y.txt");
    std::fs::write(&file, values).unwrap();
    let out2 = dir.join("b2.vtu").display().to_string();
    let o =
        toposmooth(&["smooth", &mesh, "--values", &file.display().to_string(), "--persistence", "10%", "-o", &out2]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let a = read_mesh(Path::new(&out2)).unwrap().array("smoothed").unwrap().values;
    let b = m.array("smoothed").unwrap().values;
    assert_eq!(a, b, "--values and --array y give the same result");
    // a values file of the wrong length
    std::fs::write(&file, "1\n2\n").unwrap();
    let o = toposmooth(&["smooth", &mesh, "--values", &file.display().to_string(), "-o", &out2]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("y.txt") && text(&o).contains("2 values"), "{}", text(&o));
}

#[test]
fn broken_meshes_are_input_errors_naming_the_file_and_the_elements() {
    let dir = scratch("mesh-errors");
    let cases: [(&str, &str, &str); 5] = [
        ("nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n", "non-finite coordinates at vertices 1"),
        (
            "bowtie.off",
            "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n-1 0 0\n-1 -1 0\n3 0 1 2\n3 0 3 4\n",
            "non-manifold vertices 0",
        ),
        (
            "fin.off",
            "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 1 4\n",
            "non-manifold edges",
        ),
        ("flat.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n", "zero area"),
        ("lonely.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n5 5 5\n3 0 1 2\n", "used by no triangle"),
    ];
    for (name, content, needle) in cases {
        let p = dir.join(name);
        std::fs::write(&p, content).unwrap();
        let o = toposmooth(&["extrema", &p.display().to_string(), "--array", "x"]);
        assert_eq!(o.status.code(), Some(3), "{name}: {}", text(&o));
        assert!(text(&o).contains(name) && text(&o).contains(needle), "{name}: {}", text(&o));
    }
    // a mesh file is not a smoothing output
    let o = toposmooth(&["verify", &dataset("bunny.obj")]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("bunny.obj") && text(&o).contains(".vtu"), "{}", text(&o));
    // geodesic: a source out of range
    let o = toposmooth(&[
        "geodesic",
        &dataset("bunny.obj"),
        "--source",
        "99999",
        "-o",
        &dir.join("d.vtu").display().to_string(),
    ]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("out of range"));
    assert!(!dir.join("d.vtu").exists());
}

#[test]
fn missing_values_on_a_mesh_are_refused_or_filled() {
    let dir = scratch("mesh-fill");
    let mesh = dataset("bunny.obj");
    let n = read_mesh(Path::new(&mesh)).unwrap().positions.len();
    // the y coordinate with three holes
    let obj = std::fs::read_to_string(&mesh).unwrap();
    let mut ys: Vec<String> =
        obj.lines().filter(|l| l.starts_with("v ")).map(|l| l.split_whitespace().nth(2).unwrap().to_string()).collect();
    assert_eq!(ys.len(), n);
    for v in [10, 500, 2000] {
        ys[v] = "nan".into();
    }
    let file = dir.join("holes.txt");
    std::fs::write(&file, ys.join("\n")).unwrap();
    let out = dir.join("f.vtu").display().to_string();
    let f = file.display().to_string();
    let o = toposmooth(&["smooth", &mesh, "--values", &f, "-o", &out]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("holes.txt") && text(&o).contains("3 non-finite values"), "{}", text(&o));
    let o = toposmooth(&["smooth", &mesh, "--values", &f, "--fill-missing", "--persistence", "10%", "-o", &out]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let r = read_mesh(Path::new(&out)).unwrap();
    let filled = r.array("filled").unwrap().values;
    assert_eq!(filled.iter().filter(|&&x| x == 1.0).count(), 3);
    assert_eq!((filled[10], filled[500], filled[2000]), (1.0, 1.0, 1.0));
    let input = r.array("input").unwrap().values;
    assert!(input.iter().all(|x| x.is_finite()));
    let v = toposmooth(&["verify", &out, "--input", &mesh, "--values", &f, "--fill-missing"]);
    assert_eq!(v.status.code(), Some(0), "{}", text(&v));
}
