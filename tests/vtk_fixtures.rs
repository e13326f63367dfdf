//! Every file in tests/fixtures/vtk/ was written by VTK 9.7's own writers or by pyvista's
//! `save` with its defaults (tests/fixtures/make_fixtures.py), in every encoding they offer.
//! Each must be read exactly as VTK reads it back: the sidecar CSVs hold the points, the
//! field `f` and the cells as VTK's readers returned them.

use serde_json::Value;
use std::path::{Path, PathBuf};
use toposmooth::io::mesh::read_mesh;
use toposmooth::io::vtk::{read_dataset, read_image, Dataset};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/vtk")
}

fn manifest() -> Vec<Value> {
    let text = std::fs::read_to_string(fixtures().join("MANIFEST.json")).unwrap();
    serde_json::from_str::<Vec<Value>>(&text).unwrap()
}

/// Rows of numbers of a sidecar CSV (header skipped).
fn csv(name: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(fixtures().join(name)).unwrap();
    text.lines().skip(1).map(|l| l.split(',').map(|v| v.trim().parse::<f64>().unwrap()).collect()).collect()
}

/// Equal bit for bit when the file holds full precision, else to the 6 significant digits
/// VTK's legacy ascii writer keeps for Float32.
fn close(a: f64, b: f64, exact: bool) -> bool {
    if exact {
        a == b || (a.is_nan() && b.is_nan())
    } else {
        (a - b).abs() <= 2e-6 * (1.0 + b.abs())
    }
}

fn label(x: f64, y: f64) -> f64 {
    (10.0 * x).floor() + 100.0 * (10.0 * y).floor()
}

/// The t_<Type> arrays hold (point index % 100), less 50 for signed types.
fn check_types(
    arrays: &[(String, usize, Vec<f64>)],
    index_of_vtk_point: impl Fn(usize) -> usize,
    n: usize,
) -> Result<(), String> {
    let names = ["Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64", "Float32", "Float64"];
    for ty in names {
        let name = format!("t_{ty}");
        let (_, _, values) = arrays.iter().find(|(a, _, _)| *a == name).ok_or(format!("no array {name}"))?;
        let signed = !ty.starts_with("UInt");
        for k in 0..n {
            let want = (k % 100) as f64 - if signed { 50.0 } else { 0.0 };
            let got = values[index_of_vtk_point(k)];
            if got != want {
                return Err(format!("{name} at point {k}: {got} instead of {want}"));
            }
        }
    }
    Ok(())
}

fn check_image(path: &Path, entry: &Value) -> Result<(), String> {
    let exact = entry["exact"].as_bool().unwrap();
    let img = read_image(path).map_err(|e| e.to_string())?;
    let rows = csv(entry["expected"].as_str().unwrap());
    if img.nx * img.ny != rows.len() {
        return Err(format!("{} × {} points, VTK has {}", img.nx, img.ny, rows.len()));
    }
    let array = |name: &str| img.arrays.iter().find(|a| a.name == name);
    let mut grid_index = Vec::with_capacity(rows.len());
    for (k, row) in rows.iter().enumerate() {
        let (x, y) = (row[0], row[1]);
        let c = ((x - img.origin[0]) / img.spacing[0]).round();
        let r = ((y - img.origin[1]) / img.spacing[1]).round();
        if c < 0.0 || r < 0.0 || c as usize >= img.nx || r as usize >= img.ny {
            return Err(format!("VTK's point {k} at ({x}, {y}) lies outside the grid"));
        }
        let (c, r) = (c as usize, r as usize);
        let (gx, gy) = (img.origin[0] + c as f64 * img.spacing[0], img.origin[1] + r as f64 * img.spacing[1]);
        if (gx - x).abs() > 1e-12 * (1.0 + x.abs()) || (gy - y).abs() > 1e-12 * (1.0 + y.abs()) {
            return Err(format!("VTK's point {k} at ({x}, {y}), the grid's at ({gx}, {gy})"));
        }
        let i = r * img.nx + c;
        grid_index.push(i);
        if let Some(f) = array("f") {
            if !close(f.values[i], row[3], exact) {
                return Err(format!("f at VTK's point {k}: {} instead of {}", f.values[i], row[3]));
            }
        }
        if let Some(v) = array("velocity") {
            let want = [x, 2.0 * y, -row[2] + 0.5];
            let got = &v.values[3 * i..3 * i + 3];
            if v.components != 3 || (0..3).any(|d| !close(got[d], want[d], exact)) {
                return Err(format!("velocity at VTK's point {k}: {got:?} instead of {want:?}"));
            }
        }
        if let Some(l) = array("label") {
            if l.values[i] != label(x, y) {
                return Err(format!("label at VTK's point {k}: {} instead of {}", l.values[i], label(x, y)));
            }
        }
    }
    if entry["dataset"] == "types" {
        let arrays: Vec<_> = img.arrays.iter().map(|a| (a.name.clone(), a.components, a.values.clone())).collect();
        check_types(&arrays, |k| grid_index[k], rows.len())?;
    }
    Ok(())
}

/// Points, cells and point data of a mesh data set, against VTK's.
fn check_cells_and_points(ds: &Dataset, entry: &Value) -> Result<(), String> {
    let exact = entry["exact"].as_bool().unwrap();
    let rows = csv(entry["expected"].as_str().unwrap());
    if ds.points.len() != rows.len() {
        return Err(format!("{} points, VTK has {}", ds.points.len(), rows.len()));
    }
    let f = ds.point_data.iter().find(|a| a.name == "f");
    for (k, row) in rows.iter().enumerate() {
        if (0..3).any(|d| !close(ds.points[k][d], row[d], exact)) {
            return Err(format!("point {k}: {:?} instead of {:?}", ds.points[k], &row[..3]));
        }
        if let Some(f) = f {
            if !close(f.values[k], row[3], exact) {
                return Err(format!("f at point {k}: {} instead of {}", f.values[k], row[3]));
            }
        }
    }
    let cells = csv(entry["cells"].as_str().unwrap());
    if ds.cells.len() != cells.len() {
        return Err(format!("{} cells, VTK has {}", ds.cells.len(), cells.len()));
    }
    for (c, row) in cells.iter().enumerate() {
        let want: Vec<usize> = row[1..].iter().map(|&v| v as usize).collect();
        if f64::from(ds.cells.types[c]) != row[0] || ds.cells.corners(c) != want.as_slice() {
            return Err(format!(
                "cell {c}: type {} corners {:?}, VTK has type {} corners {want:?}",
                ds.cells.types[c],
                ds.cells.corners(c),
                row[0]
            ));
        }
    }
    if entry["dataset"] == "types" {
        let arrays: Vec<_> = ds.point_data.iter().map(|a| (a.name.clone(), a.components, a.values.clone())).collect();
        check_types(&arrays, |k| k, rows.len())?;
    }
    Ok(())
}

/// Triangles a surface's cells give: one per triangle, n − 2 per polygon or strip.
fn triangles_of(cells: &[Vec<f64>]) -> usize {
    cells
        .iter()
        .map(|c| match c[0] as u8 {
            5 => 1,
            6..=9 => c.len() - 3,
            _ => 0,
        })
        .sum()
}

fn check(entry: &Value) -> Result<(), String> {
    let file = entry["file"].as_str().unwrap();
    let path = fixtures().join(file);
    let kind = entry["kind"].as_str().unwrap();
    if entry["expect"] == "error" {
        let e = read_image(&path).err().ok_or("read, but VTK's own refusal was expected")?.to_string();
        return if e.contains(file) && e.contains("oblique") { Ok(()) } else { Err(format!("error: {e}")) };
    }
    match kind {
        "image" if entry["scope"] == "now" => check_image(&path, entry),
        "image" | "volume" => {
            // read as a data set (3D images and xz images are a later issue's domains)
            let ds = read_dataset(&path).map_err(|e| e.to_string())?;
            let dims = ds.image.as_ref().ok_or("no image geometry")?.dims();
            let want: Vec<u64> = entry["dims"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
            if dims.iter().map(|&d| d as u64).collect::<Vec<_>>() != want {
                return Err(format!("dims {dims:?} instead of {want:?}"));
            }
            let rows = csv(entry["expected"].as_str().unwrap());
            let f = &ds.point_data.iter().find(|a| a.name == "f").ok_or("no f")?.values;
            if f.len() != rows.len() || f.iter().zip(&rows).any(|(a, r)| *a != r[3]) {
                return Err("f differs from VTK's".into());
            }
            let e = read_image(&path).err().ok_or("a 2D image was made of it")?.to_string();
            if e.contains(file) {
                Ok(())
            } else {
                Err(format!("error without the file name: {e}"))
            }
        }
        "surface" | "tets" => {
            let ds = read_dataset(&path).map_err(|e| e.to_string())?;
            check_cells_and_points(&ds, entry)?;
            let mesh = read_mesh(&path);
            if kind == "tets" {
                // a tetrahedral mesh, every cell VTK wrote one of its tetrahedra; surface
                // commands refuse it naming the file
                let (m, _) = toposmooth::io::mesh::read_any_mesh(&path).map_err(|e| e.to_string())?;
                let toposmooth::io::mesh::AnyMesh::Tet(t) = m else {
                    return Err("tetrahedra read as a surface".into());
                };
                if t.tets().len() != ds.cells.len() {
                    return Err(format!("{} tetrahedra for {} cells", t.tets().len(), ds.cells.len()));
                }
                let e = toposmooth::io::mesh::read_trimesh(&path).err().ok_or("tetrahedra read as a triangle mesh")?;
                let e = e.to_string();
                return if e.contains(file) && e.contains("tetrahedra") { Ok(()) } else { Err(format!("error: {e}")) };
            }
            let mesh = mesh.map_err(|e| e.to_string())?;
            let want = triangles_of(&csv(entry["cells"].as_str().unwrap()));
            if mesh.triangles.len() != want {
                return Err(format!("{} triangles instead of {want}", mesh.triangles.len()));
            }
            Ok(())
        }
        other => Err(format!("unknown kind {other}")),
    }
}

#[test]
fn every_fixture_reads_as_vtk_wrote_it() {
    let entries = manifest();
    assert!(entries.len() >= 160, "{} fixtures", entries.len());
    let failures: Vec<String> = entries
        .iter()
        .filter_map(|e| check(e).err().map(|m| format!("{}: {m}", e["file"].as_str().unwrap())))
        .collect();
    assert!(failures.is_empty(), "{} of {} fixtures fail:\n{}", failures.len(), entries.len(), failures.join("\n"));
}

#[test]
fn the_writers_defaults_are_among_the_fixtures() {
    // what pyvista's save() and VTK's XML writers write when given no settings
    let entries = manifest();
    for (file, mode, compressor) in [
        ("surf.pyvista-default.vtp", "binary", "zlib"),
        ("img.pyvista-default.vti", "binary", "zlib"),
        ("surf.vtk-default.vtp", "appended-base64", "zlib"),
    ] {
        let e = entries.iter().find(|e| e["file"] == file).unwrap_or_else(|| panic!("{file} missing"));
        assert_eq!((e["mode"].as_str().unwrap(), e["compressor"].as_str().unwrap()), (mode, compressor), "{file}");
    }
}

#[test]
fn a_flipped_image_lands_where_vtk_puts_it() {
    // the y-flipped image: VTK puts its points at y = -2 - j·0.25, so the grid runs downwards
    let img = read_image(&fixtures().join("img_flipy.appended-raw-zlib-u64.vti")).unwrap();
    assert_eq!((img.origin[1], img.spacing[1]), (-2.0, -0.25));
    assert!(img.notes.iter().any(|n| n.contains("flips y")), "{:?}", img.notes);
    let swapped = read_image(&fixtures().join("img_swap.appended-raw-zlib-u64.vti")).unwrap();
    assert_eq!((swapped.nx, swapped.ny), (5, 7));
}

#[test]
fn the_active_scalars_are_the_default_array_as_in_a_vtk_filter() {
    for file in ["img.ascii.vti", "img.legacy-binary-v51.vtk", "img.pyvista-default.vti"] {
        let img = read_image(&fixtures().join(file)).unwrap();
        assert_eq!(img.active_scalars.as_deref(), Some("f"), "{file}");
        // three arrays, two of them scalar: the tool takes `f` without --array
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_toposmooth"))
            .args(["extrema", fixtures().join(file).to_str().unwrap()])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{file}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(text.contains("`f`") || text.contains(" f"), "{file}: {text}");
    }
}

/// Runs the tool; panics with its output unless it exits 0. (No `-q`: a build without it,
/// like cac0d08's, then fails on what the test checks, not on the flag.)
fn smooth_ok(args: &[&str]) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_toposmooth")).args(args).output().unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{args:?}: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

fn array<'a>(arrays: &'a [toposmooth::io::vtk::PointArray], name: &str) -> &'a toposmooth::io::vtk::PointArray {
    arrays
        .iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no array `{name}` among {:?}", arrays.iter().map(|a| &a.name).collect::<Vec<_>>()))
}

/// The outputs of `smooth` behave like a VTK filter's: every point and cell array of the input
/// comes through in its own type with its values, the smoothed field takes the input array's
/// name as the active scalars, the cells are the input's.
#[test]
fn vtk_outputs_carry_every_input_array_in_its_type() {
    let dir = std::env::temp_dir().join(format!("toposmooth-carry-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for input in ["types.appended-raw-zlib-u64.vti", "types.ascii.vtp", "surf.binary-zlib-u64.vtu"] {
        let ext = input.rsplit('.').next().unwrap();
        let path = fixtures().join(input);
        let out = dir.join(format!("out.{ext}"));
        smooth_ok(&[
            "smooth",
            path.to_str().unwrap(),
            "--array",
            "f",
            "--persistence",
            "20%",
            "-o",
            out.to_str().unwrap(),
        ]);
        let (a, b) = (read_dataset(&path).unwrap(), read_dataset(&out).unwrap());
        assert_eq!(b.active_scalars.as_deref(), Some("f"), "{input}");
        assert_eq!(array(&b.point_data, "f").values, array(&b.point_data, "smoothed").values, "{input}");
        assert_eq!(array(&b.point_data, "input").values, array(&a.point_data, "f").values, "{input}");
        assert_ne!(array(&b.point_data, "f").values, array(&a.point_data, "f").values, "{input}: f was smoothed");
        assert_eq!(array(&b.point_data, "f").ty, toposmooth::io::vtk::Scalar::F64);
        for x in a.point_data.iter().filter(|x| x.name != "f") {
            assert_eq!(array(&b.point_data, &x.name), x, "{input}: point array {}", x.name);
        }
        assert!(!a.cell_data.is_empty(), "{input}: the fixture has cell arrays");
        for x in &a.cell_data {
            // the cell order of the output is the input's (poly data: already VTK's order)
            assert_eq!(array(&b.cell_data, &x.name), x, "{input}: cell array {}", x.name);
        }
        assert_eq!((a.points, a.cells), (b.points, b.cells), "{input}: geometry and cells unchanged");
    }
    // --output-array names the smoothed field; the input's `f` then comes through unchanged,
    // and smoothing the tool's own output again carries its arrays as `<name>_input`
    let first = dir.join("out.vti");
    let again = dir.join("again.vti");
    smooth_ok(&[
        "smooth",
        first.to_str().unwrap(),
        "--array",
        "f",
        "--persistence",
        "20%",
        "--output-array",
        "f_smooth",
        "-o",
        again.to_str().unwrap(),
    ]);
    let (a, b) = (read_dataset(&first).unwrap(), read_dataset(&again).unwrap());
    assert_eq!(b.active_scalars.as_deref(), Some("f_smooth"));
    assert_eq!(array(&b.point_data, "f_smooth").values, array(&b.point_data, "smoothed").values);
    assert_eq!(array(&b.point_data, "f"), array(&a.point_data, "f"));
    for own in ["input", "smoothed", "representative", "role"] {
        assert_eq!(array(&b.point_data, &format!("{own}_input")).values, array(&a.point_data, own).values, "{own}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--diagram` writes TTK's persistence diagram: thresholding its `Persistence` at the
/// selection's threshold (as ParaView's Threshold does, the diagonal left out as TTK's filters
/// do) gives exactly the kept extrema; `--complex` carries TTK's critical types.
#[test]
fn thresholding_the_ttk_diagram_selects_exactly_the_kept_pairs() {
    let dir = std::env::temp_dir().join(format!("toposmooth-diagram-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let volcano = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/volcano_maunga_whau_61x87.csv");
    let (out, diagram, complex, report) = (dir.join("v.vti"), dir.join("d.vtu"), dir.join("c.vtp"), dir.join("r.json"));
    smooth_ok(&[
        "smooth",
        volcano.to_str().unwrap(),
        "--persistence",
        "5%",
        "-o",
        out.to_str().unwrap(),
        "--diagram",
        diagram.to_str().unwrap(),
        "--complex",
        complex.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    let threshold = serde_json::from_str::<Value>(&std::fs::read_to_string(&report).unwrap()).unwrap()["settings"]
        ["threshold"]
        .as_f64()
        .unwrap();
    let smoothed = read_dataset(&out).unwrap();
    // a CSV grid names no array: the smoothed field is the active scalars as `smoothed`
    assert_eq!(smoothed.active_scalars.as_deref(), Some("smoothed"));
    let roles = array(&smoothed.point_data, "role").values.clone();
    let kept: std::collections::BTreeSet<usize> = (0..roles.len()).filter(|&v| roles[v].abs() == 1.0).collect();
    assert!(kept.len() >= 2, "{kept:?}");

    let d = read_dataset(&diagram).unwrap();
    let cell = |name: &str| array(&d.cell_data, name).values.clone();
    let (id, ty, pers, finite, flag) =
        (cell("PairIdentifier"), cell("PairType"), cell("Persistence"), cell("IsFinite"), cell("Kept"));
    let vertex = &array(&d.point_data, "ttkVertexScalarField").values;
    let critical = &array(&d.point_data, "CriticalType").values;
    assert_eq!(array(&d.cell_data, "IsFinite").ty, toposmooth::io::vtk::Scalar::U8);
    assert_eq!(array(&d.point_data, "Coordinates").components, 3);
    // the diagonal last, and one essential pair (one connected grid) first
    let last = id.len() - 1;
    assert_eq!((id[last], ty[last]), (-1.0, -1.0));
    assert_eq!(finite.iter().filter(|&&f| f == 0.0).count(), 2, "the essential pair and the diagonal");
    assert_eq!((finite[0], id[0]), (0.0, 0.0));
    let mut selected = std::collections::BTreeSet::new();
    for c in 0..last {
        let [b, e] = [d.cells.corners(c)[0], d.cells.corners(c)[1]];
        // TTK's points: (birth, birth) and (birth, death)
        assert_eq!(d.points[b][0], d.points[e][0]);
        assert!((d.points[e][1] - d.points[b][0] - pers[c]).abs() <= 1e-12 * pers[c].abs().max(1.0));
        let (lo, hi) = (vertex[b] as usize, vertex[e] as usize);
        match ty[c] as i32 {
            0 => assert_eq!((critical[b], critical[e]), (0.0, if finite[c] == 1.0 { 1.0 } else { 3.0 })),
            1 => assert_eq!((critical[b], critical[e]), (1.0, 3.0)),
            t => panic!("pair type {t}"),
        }
        if pers[c] >= threshold {
            let ends: Vec<usize> = match (ty[c] as i32, finite[c] == 1.0) {
                (_, false) => vec![lo, hi],
                (0, true) => vec![lo],
                _ => vec![hi],
            };
            selected.extend(ends);
            assert_eq!(flag[c], 1.0, "pair {c} above the threshold is marked kept");
        } else {
            assert_eq!(flag[c], 0.0, "pair {c} below the threshold is not kept");
        }
    }
    assert_eq!(selected, kept, "threshold {threshold}");

    let c = read_dataset(&complex).unwrap();
    let pa = |name: &str| array(&c.point_data, name).values.clone();
    let (ct, vid, k) = (pa("CriticalType"), pa("ttkVertexScalarField"), pa("Kept"));
    let kept_in_complex: std::collections::BTreeSet<usize> =
        (0..ct.len()).filter(|&p| k[p] == 1.0 && (ct[p] == 0.0 || ct[p] == 3.0)).map(|p| vid[p] as usize).collect();
    assert_eq!(kept_in_complex, kept);
    let sep = array(&c.cell_data, "SeparatrixType").values.clone();
    assert!(sep.contains(&0.0) && sep.contains(&1.0) && sep.contains(&-1.0), "{sep:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Legacy `.vtk` output (cac0d08 refused `-o out.vtk`, exit 2): binary, big-endian, structured
/// points for an image and an unstructured grid for a surface, every input array carried and
/// the smoothed field the active scalars, read back by the crate's own legacy reader (VTK's
/// reader opens them in tests/vtk_open).
#[test]
fn legacy_vtk_outputs_carry_the_input_arrays() {
    let dir = std::env::temp_dir().join(format!("toposmooth-legacy-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (input, dataset) in
        [("types.appended-raw-zlib-u64.vti", "STRUCTURED_POINTS"), ("surf.binary-zlib-u64.vtu", "UNSTRUCTURED_GRID")]
    {
        let path = fixtures().join(input);
        let out = dir.join(format!("{input}.vtk"));
        smooth_ok(&[
            "smooth",
            path.to_str().unwrap(),
            "--array",
            "f",
            "--persistence",
            "20%",
            "-o",
            out.to_str().unwrap(),
        ]);
        let bytes = std::fs::read(&out).unwrap();
        let head: Vec<&[u8]> = bytes.split(|&b| b == b'\n').take(4).collect();
        assert!(head[0].starts_with(b"# vtk DataFile Version"), "{input}: {:?}", String::from_utf8_lossy(head[0]));
        assert_eq!(head[2], b"BINARY", "{input}");
        assert_eq!(head[3], format!("DATASET {dataset}").as_bytes(), "{input}");
        let (a, b) = (read_dataset(&path).unwrap(), read_dataset(&out).unwrap());
        assert_eq!(b.active_scalars.as_deref(), Some("f"), "{input}");
        assert_eq!(array(&b.point_data, "f").values, array(&b.point_data, "smoothed").values, "{input}");
        assert_eq!(array(&b.point_data, "input").values, array(&a.point_data, "f").values, "{input}");
        for x in a.point_data.iter().filter(|x| x.name != "f") {
            assert_eq!(array(&b.point_data, &x.name).values, x.values, "{input}: point array {}", x.name);
        }
        for x in &a.cell_data {
            assert_eq!(array(&b.cell_data, &x.name).values, x.values, "{input}: cell array {}", x.name);
        }
        assert_eq!(a.points, b.points, "{input}: the points");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--complex` in TTK's codes. cac0d08 wrote one `type` array whose ±1 meant minimum/maximum on
/// the points but descending/ascending on the lines; now points carry `CriticalType` (0
/// minimum, 1 saddle, 3 maximum, 5 regular, as TTK) and lines `SeparatrixType` (0 descending, 1
/// ascending, −1 on vertex cells), each line from its saddle to a kept extremum of that kind.
#[test]
fn the_complex_carries_ttk_critical_and_separatrix_types() {
    let dir = std::env::temp_dir().join(format!("toposmooth-complex-types-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let volcano = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/volcano_maunga_whau_61x87.csv");
    let (out, complex) = (dir.join("v.vti"), dir.join("c.vtp"));
    smooth_ok(&[
        "smooth",
        volcano.to_str().unwrap(),
        "--persistence",
        "5%",
        "-o",
        out.to_str().unwrap(),
        "--complex",
        complex.to_str().unwrap(),
    ]);
    let roles = array(&read_dataset(&out).unwrap().point_data, "role").values.clone();
    let c = read_dataset(&complex).unwrap();
    assert!(!c.point_data.iter().chain(&c.cell_data).any(|a| a.name == "type"), "no ambiguous `type` array");
    let critical = array(&c.point_data, "CriticalType");
    assert_eq!(critical.ty, toposmooth::io::vtk::Scalar::I32);
    let (ct, vid, kept) =
        (&critical.values, &array(&c.point_data, "ttkVertexScalarField").values, &array(&c.point_data, "Kept").values);
    assert!(ct.iter().all(|t| [0.0, 1.0, 3.0, 5.0].contains(t)), "{ct:?}");
    // the kept extrema are the points of type 0 and 3 marked kept, with the output's roles
    for p in 0..ct.len() {
        let v = vid[p] as usize;
        if kept[p] == 1.0 && ct[p] != 1.0 {
            assert_eq!(roles[v], if ct[p] == 0.0 { -1.0 } else { 1.0 }, "point {p} (vertex {v}) of type {}", ct[p]);
        }
    }
    let sep = array(&c.cell_data, "SeparatrixType");
    assert_eq!(sep.ty, toposmooth::io::vtk::Scalar::I32);
    let destination = &array(&c.cell_data, "DestinationId").values;
    let (mut descending, mut ascending) = (0, 0);
    for (cell, &t) in sep.values.iter().enumerate() {
        match t as i32 {
            -1 => assert_eq!(destination[cell], -1.0),
            0 => {
                descending += 1;
                assert_eq!(roles[destination[cell] as usize], -1.0, "a descending line ends at a kept minimum");
            }
            1 => {
                ascending += 1;
                assert_eq!(roles[destination[cell] as usize], 1.0, "an ascending line ends at a kept maximum");
            }
            t => panic!("separatrix type {t}"),
        }
    }
    assert!(descending > 0 && ascending > 0, "{descending} descending, {ascending} ascending");
    let _ = std::fs::remove_dir_all(&dir);
}
