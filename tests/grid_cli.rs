//! The command-line tool on grids: the bundled measured and simulated fields, every output
//! format, `verify`, and the input errors of the grid readers.

mod common;

use common::{dataset, grid_extrema, scratch, text, toposmooth};
use std::path::{Path, PathBuf};
use toposmooth::io::npz::read_npz;

fn path(dir: &Path, name: &str) -> String {
    dir.join(name).display().to_string()
}

/// A CSV matrix as numbers (NaN kept).
fn read_matrix(p: &str) -> (usize, Vec<f64>) {
    let text = std::fs::read_to_string(p).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(|c| c.trim().parse().unwrap()).collect())
        .collect();
    (rows[0].len(), rows.concat())
}

/// The arrays of an .npz output by name.
fn npz(p: &str) -> std::collections::HashMap<String, ([usize; 2], Vec<f64>)> {
    read_npz(Path::new(p)).unwrap().into_iter().map(|(n, s, v)| (n, (s, v))).collect()
}

/// Checks an .npz output with the independent counter: exactly the kept extrema, no flat
/// vertex, kept values equal to the input. Returns (kept minima, kept maxima).
fn check_output(p: &str) -> (usize, usize) {
    let a = npz(p);
    let ([ny, nx], f) = &a["smoothed"];
    let (input, role) = (&a["input"].1, &a["role"].1);
    let (mins, maxs, flat) = grid_extrema(*nx, *ny, f);
    assert!(flat.is_empty(), "flat vertices {flat:?}");
    assert_eq!(mins, (0..nx * ny).filter(|&v| role[v] == -1.0).collect::<Vec<_>>());
    assert_eq!(maxs, (0..nx * ny).filter(|&v| role[v] == 1.0).collect::<Vec<_>>());
    for &v in mins.iter().chain(&maxs) {
        assert_eq!(f[v].to_bits(), input[v].to_bits());
    }
    (mins.len(), maxs.len())
}

#[test]
fn piv_vorticity_with_holes_keeps_nine_minima_and_four_maxima() {
    let dir = scratch("piv");
    let piv = dataset("soapfilm_piv_vorticity_63x63.csv");
    // holes are refused by default, naming the file and the first cells
    let o = toposmooth(&["smooth", &piv, "-o", &path(&dir, "refused.vti"), "--minima", "9", "--maxima", "4"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(
        text(&o).contains("soapfilm_piv_vorticity_63x63.csv") && text(&o).contains("774 missing (NaN)"),
        "{}",
        text(&o)
    );
    assert!(!dir.join("refused.vti").exists());

    let (vti, npz_out, vtp, png, json) = (
        path(&dir, "piv.vti"),
        path(&dir, "piv.npz"),
        path(&dir, "piv.vtp"),
        path(&dir, "piv.png"),
        path(&dir, "run.json"),
    );
    let common = ["--fill-missing", "--minima", "9", "--maxima", "4", "--spacing", "0.31248,-0.31248"];
    let mut args =
        vec!["smooth", piv.as_str(), "-o", vti.as_str(), "--complex", &vtp, "--plot", &png, "--report", &json];
    args.extend(common);
    let o = toposmooth(&args);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("774 missing samples filled"), "{}", text(&o));
    let v = toposmooth(&["verify", &vti]);
    assert_eq!(v.status.code(), Some(0), "{}", text(&v));
    for f in [&vtp, &png] {
        assert!(std::fs::metadata(f).unwrap().len() > 1000, "{f}");
    }
    let r = common::json(&json);
    assert_eq!(r["filled_missing"], 774);
    assert_eq!(r["certificate"]["passed"], true);
    assert!(r["saddles"].as_u64().unwrap() >= 1);

    let mut args = vec!["smooth", piv.as_str(), "-o", npz_out.as_str()];
    args.extend(common);
    assert!(toposmooth(&args).status.success());
    assert_eq!(check_output(&npz_out), (9, 4));
    // the filled input keeps every measured value bit for bit
    let (_, raw) = read_matrix(&piv);
    let input = &npz(&npz_out)["input"].1;
    assert!(raw.iter().zip(input).all(|(a, b)| a.is_nan() || a.to_bits() == b.to_bits()));
    let v = toposmooth(&["verify", &npz_out, "--input", &piv, "--fill-missing", "--spacing", "0.31248,-0.31248"]);
    assert_eq!(v.status.code(), Some(0), "{}", text(&v));
}

/// The Kármán street at the defaults stops with 1,492 rows met only to the solver's
/// tolerance (true slacks down to −8.6·10⁻¹² of the range): without the step onto the rows the
/// margin repair moved 2,008 vertices and the gap bound of the output grew 7× past the
/// solver's own.
#[test]
fn the_solver_s_stopping_point_needs_no_margin_repair() {
    let dir = scratch("onto-rows");
    let (out, json) = (path(&dir, "k.npz"), path(&dir, "k.json"));
    let karman = dataset("karman_vortex_street_vorticity_65x513.csv");
    let o = toposmooth(&["smooth", &karman, "-o", &out, "--report", &json]);
    assert!(o.status.success(), "{}", text(&o));
    let r = common::json(&json);
    assert_eq!(r["margin_repair"]["met"], true);
    assert_eq!(r["margin_repair"]["changed_vertices"], 0, "{}", r["margin_repair"]);
    let gap = r["fit"]["gap_over_data"].as_f64().unwrap();
    // the solver stops at 3·10⁻⁷ of the data term; the written output is that point
    assert!(gap <= 3e-7, "gap bound {gap:e} of the data term");
}

#[test]
fn derived_vorticity_matches_the_bundled_fields() {
    // PIV: u and v on a grid whose rows run downwards
    let dir = scratch("derive");
    let out = path(&dir, "w.npz");
    let (u, v) = (dataset("soapfilm_piv_u_63x63.csv"), dataset("soapfilm_piv_v_63x63.csv"));
    let o = toposmooth(&[
        "smooth",
        "--u",
        &u,
        "--v",
        &v,
        "--derive",
        "vorticity",
        "--spacing",
        "0.31248,-0.31248",
        "--fill-missing",
        "-o",
        &out,
        "--minima",
        "9",
        "--maxima",
        "4",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let (_, reference) = read_matrix(&dataset("soapfilm_piv_vorticity_63x63.csv"));
    let a = npz(&out);
    let (input, filled) = (&a["input"].1, &a["filled"].1);
    let mut compared = 0;
    for i in 0..reference.len() {
        assert_eq!(reference[i].is_nan(), filled[i] == 1.0, "NaN spreads through the stencil as numpy's does: {i}");
        if reference[i].is_finite() {
            // u and v carry 6 decimals (±5e-7 m/s): a central difference over 0.625 mm
            // carries ±1.6e-6 (m/s)/mm; the vorticity itself reaches about 0.1
            assert!((input[i] - reference[i]).abs() <= 2e-6, "{i}: {} vs {}", input[i], reference[i]);
            compared += 1;
        }
    }
    assert_eq!(compared, 3195);

    // the Kármán vortex street: a 3-component vector array in an appended, zlib-compressed .vti
    let out = path(&dir, "karman.npz");
    let vti = dataset("karman_vortex_street_ttk_example1.vti");
    let o = toposmooth(&["smooth", &vti, "--derive", "vorticity", "--persistence", "5%", "-o", &out]);
    assert!(o.status.success(), "{}", text(&o));
    let (nx, reference) = read_matrix(&dataset("karman_vortex_street_vorticity_65x513.csv"));
    assert_eq!(nx, 513);
    let a = npz(&out);
    assert_eq!(a["input"].0, [65, 513]);
    // the reference went through a text round trip with 6 significant digits
    let worst = a["input"].1.iter().zip(&reference).map(|(w, r)| (w - r).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-6, "largest difference {worst} (vorticity range about 1.6)");
    let (kmin, kmax) = check_output(&out);
    assert!(kmin >= 5 && kmax >= 5, "the vortices survive: {kmin} minima, {kmax} maxima");
}

#[test]
fn elevation_formats_and_representatives() {
    let dir = scratch("volcano");
    let volcano = dataset("volcano_maunga_whau_61x87.csv");
    let (nx, h) = read_matrix(&volcano);
    let ny = h.len() / nx;
    let mut rms = Vec::new();
    for rep in ["separatrix", "harmonic", "flooded"] {
        let (npz_out, json) = (path(&dir, &format!("{rep}.npz")), path(&dir, &format!("{rep}.json")));
        let o = toposmooth(&[
            "smooth",
            &volcano,
            "-o",
            &npz_out,
            "--persistence",
            "3%",
            "--representative",
            rep,
            "--report",
            &json,
            "--spacing",
            "10,10",
        ]);
        assert!(o.status.success(), "{}", text(&o));
        check_output(&npz_out);
        let r = common::json(&json);
        assert!(r["representative"].as_str().unwrap().starts_with(rep), "{}", r["representative"]);
        rms.push(r["rms_deviation"].as_f64().unwrap());
    }
    assert!(rms.iter().all(|r| *r > 0.0 && *r < 5.0), "{rms:?}");
    // the flooded representative is the data outside the flooded basins (up to the ulps that
    // order the ties of these integer elevations), and fits closest
    let flooded = &npz(&path(&dir, "flooded.npz"))["representative"].1;
    let untouched = flooded.iter().zip(&h).filter(|(a, b)| (*a - *b).abs() <= 1e-9 * b.abs()).count();
    assert!(untouched * 2 > h.len(), "{untouched} of {} vertices keep their value", h.len());
    assert!(rms[2] < rms[0] && rms[2] < rms[1], "{rms:?}");
    // single-array exports hold the same smoothed values (the default is the flooded one)
    let (npy, csv) = (path(&dir, "s.npy"), path(&dir, "s.csv"));
    for out in [&npy, &csv] {
        let o = toposmooth(&["smooth", &volcano, "-o", out, "--persistence", "3%", "--spacing", "10,10"]);
        assert!(o.status.success(), "{}", text(&o));
    }
    let smoothed = &npz(&path(&dir, "flooded.npz"))["smoothed"].1;
    let (cnx, from_csv) = read_matrix(&csv);
    assert_eq!((cnx, from_csv.len()), (nx, nx * ny));
    assert!(from_csv.iter().zip(smoothed).all(|(a, b)| a.to_bits() == b.to_bits()));
    let bytes = std::fs::read(&npy).unwrap();
    let arr = npyz::NpyFile::new(&bytes[..]).unwrap();
    assert_eq!(arr.shape(), &[ny as u64, nx as u64]);
    assert!(arr.into_vec::<f64>().unwrap().iter().zip(smoothed).all(|(a, b)| a.to_bits() == b.to_bits()));
    // .npy exports are not verifiable alone
    assert_eq!(toposmooth(&["verify", &npy]).status.code(), Some(2));
}

#[test]
fn verify_catches_a_tampered_grid_output() {
    let dir = scratch("tamper");
    let retina = dataset("retina_microaneurysms_102x102.csv");
    let out = path(&dir, "r.npz");
    let o = toposmooth(&["smooth", &retina, "-o", &out, "--persistence", "10%", "--representative", "separatrix"]);
    assert!(o.status.success(), "{}", text(&o));
    // the widening release around failing kept extrema lets the separatrix representative
    // stand here (docs/grids.md, section 5): asked for, it is built, not refused
    assert!(text(&o).contains("representative: separatrix (") && !text(&o).contains("fallback"), "{}", text(&o));
    assert_eq!(toposmooth(&["verify", &out, "--input", &retina]).status.code(), Some(0));
    let a = npz(&out);
    let ([ny, nx], f) = a["smoothed"].clone();
    let role = &a["role"].1;
    // raise one free interior vertex above all its neighbours: a spurious maximum
    let v = (nx + 1..nx * ny - nx - 1).find(|&v| role[v] == 0.0 && v % nx != 0 && v % nx != nx - 1).unwrap();
    let mut g = f.clone();
    g[v] = f.iter().cloned().fold(f64::MIN, f64::max) + 1.0;
    let names = ["input", "smoothed", "representative", "role"];
    let arrays: Vec<(&str, &[f64])> =
        names.iter().map(|&n| (n, if n == "smoothed" { &g[..] } else { &a[n].1[..] })).collect();
    let bad = path(&dir, "bad.npz");
    toposmooth::io::npz::stage_npz(Path::new(&bad), ny, nx, &arrays).unwrap().commit().unwrap();
    let o = toposmooth(&["verify", &bad]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("NOT certified"), "{}", text(&o));
}

#[test]
fn extrema_lists_grid_extrema_from_every_reader() {
    let dir = scratch("extrema");
    let volcano = dataset("volcano_maunga_whau_61x87.csv");
    let o = toposmooth(&["extrema", &volcano, "--json", "--plot", &path(&dir, "d.png")]);
    assert!(o.status.success(), "{}", text(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (nx, h) = read_matrix(&volcano);
    let (mins, maxs, _) = grid_extrema(nx, h.len() / nx, &h);
    assert_eq!(j["grid"], serde_json::json!([87, 61]));
    assert_eq!(j["strict_minima"].as_u64().unwrap() as usize, mins.len());
    assert_eq!(j["strict_maxima"].as_u64().unwrap() as usize, maxs.len());
    // each extremum's place as numbers, not text: row, column and position (origin 0, spacing 1)
    for e in j["extrema"].as_array().unwrap() {
        let i = e["index"].as_u64().unwrap() as usize;
        let (r, c) = (i / nx, i % nx);
        assert_eq!((e["row"].as_u64(), e["col"].as_u64()), (Some(r as u64), Some(c as u64)), "{e}");
        assert_eq!(e["position"], serde_json::json!([c as f64, r as f64]), "{e}");
        assert!(e.get("x").is_none(), "{e}");
    }
    // the same field as .npy (written by the tool) lists the same extrema
    let npy = path(&dir, "v.npy");
    let npz_out = path(&dir, "v.npz");
    assert!(toposmooth(&["smooth", &volcano, "-o", &npz_out]).status.success());
    let input = npz(&npz_out)["input"].1.clone();
    toposmooth::io::npz::stage_npy(Path::new(&npy), h.len() / nx, nx, &input).unwrap().commit().unwrap();
    let o2 = toposmooth(&["extrema", &npy, "--json"]);
    let j2: serde_json::Value = serde_json::from_slice(&o2.stdout).unwrap();
    assert_eq!(j2["extrema"], j["extrema"]);
}

fn write(dir: &Path, name: &str, content: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p
}

#[test]
fn grid_reader_errors_name_the_file_and_the_problem() {
    let dir = scratch("readers");
    let vti = std::fs::read(dataset("karman_vortex_street_ttk_example1.vti")).unwrap();
    let cases: Vec<(PathBuf, Vec<&str>, &str)> = vec![
        (write(&dir, "truncated.vti", &vti[..vti.len() / 2]), vec!["--derive", "vorticity"], "truncated.vti"),
        (write(&dir, "ragged.csv", b"1,2,3\n4,5\n"), vec![], "line 2"),
        (write(&dir, "text.csv", b"1,2,3\n4,x,6\n"), vec![], "not a number"),
        (write(&dir, "nan.csv", b"1,2,3\n4,NaN,6\n7,8,9\n"), vec![], "1 missing (NaN)"),
        (write(&dir, "one-row.csv", b"1,2,3\n"), vec![], "at least 2"),
        (write(&dir, "empty.npy", b""), vec![], "empty.npy"),
    ];
    for (file, extra, needle) in cases {
        let f = file.display().to_string();
        let mut args = vec!["extrema", f.as_str()];
        args.extend(extra);
        let o = toposmooth(&args);
        assert_eq!(o.status.code(), Some(3), "{f}: {}", text(&o));
        assert!(
            text(&o).contains(needle) && text(&o).contains(file.file_name().unwrap().to_str().unwrap()),
            "{f}: {}",
            text(&o)
        );
    }
    // a wrong array name lists the arrays there are
    let karman = dataset("karman_vortex_street_ttk_example1.vti");
    let o = toposmooth(&["extrema", &karman, "--array", "pressure"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("Vectors_"), "{}", text(&o));
    // a vector array without --derive
    let o = toposmooth(&["extrema", &karman]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    // an unknown compressor
    let s = String::from_utf8_lossy(&vti).replace("vtkZLibDataCompressor", "vtkMadeUpCompressor");
    let f = write(&dir, "compressor.vti", s.as_bytes()).display().to_string();
    let o = toposmooth(&["extrema", &f, "--derive", "vorticity"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("compressor.vti") && text(&o).contains("vtkMadeUpCompressor"), "{}", text(&o));
    // wrong sizes: the extent says more points than the data holds
    let s = String::from_utf8_lossy(&vti).replace("0 512 0 64 0 0", "0 600 0 64 0 0");
    let f = write(&dir, "extent.vti", s.as_bytes()).display().to_string();
    let o = toposmooth(&["extrema", &f, "--derive", "vorticity"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("extent.vti"), "{}", text(&o));
    // a spacing the operators cannot represent, from the file and from the command line
    let s = String::from_utf8_lossy(&vti).replace("Spacing=\"1 1 1\"", "Spacing=\"1e300 1e300 1\"");
    let f = write(&dir, "huge.vti", s.as_bytes()).display().to_string();
    let o = toposmooth(&["extrema", &f, "--derive", "vorticity"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("huge.vti") && text(&o).contains("spacing"), "{}", text(&o));
    let csv = write(&dir, "small.csv", b"1,2,3\n4,0,6\n7,8,9\n").display().to_string();
    let o = toposmooth(&["extrema", &csv, "--spacing", "1e300,1"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    // trailing bytes after an .npy array's data
    let npy = dir.join("long.npy");
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    let header = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }";
    let padded = format!("{header:<117}\n");
    bytes.extend((padded.len() as u16).to_le_bytes());
    bytes.extend(padded.as_bytes());
    for v in [1.0f64, 2.0, 3.0, 0.5, 9.0] {
        bytes.extend(v.to_le_bytes());
    }
    std::fs::write(&npy, &bytes).unwrap();
    let o = toposmooth(&["extrema", &npy.display().to_string()]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("long.npy") && text(&o).contains("8 bytes after"), "{}", text(&o));
    bytes.truncate(bytes.len() - 8);
    std::fs::write(&npy, &bytes).unwrap();
    let o = toposmooth(&["extrema", &npy.display().to_string()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

#[test]
fn outputs_never_overwrite_inputs_or_half_write() {
    let dir = scratch("collide");
    let (u, v) = (path(&dir, "u.csv"), path(&dir, "v.csv"));
    std::fs::copy(dataset("soapfilm_piv_u_63x63.csv"), &u).unwrap();
    std::fs::copy(dataset("soapfilm_piv_v_63x63.csv"), &v).unwrap();
    let before = std::fs::read(&v).unwrap();
    let base =
        ["smooth", "--derive", "vorticity", "--u", &u, "--v", &v, "--fill-missing", "--minima", "9", "--maxima", "4"];
    let mut args = base.to_vec();
    args.extend(["-o", &v]);
    let o = toposmooth(&args);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert_eq!(std::fs::read(&v).unwrap(), before, "the --v input is untouched");
    // a symbolic link to the input is the input
    #[cfg(unix)]
    {
        let link = path(&dir, "link.csv");
        std::os::unix::fs::symlink(&u, &link).unwrap();
        let o = toposmooth(&["smooth", &link, "-o", &u, "--domain", "grid", "--fill-missing"]);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    }
    // an output that is a directory is refused before anything is written
    let plot_dir = path(&dir, "plot.png");
    std::fs::create_dir(&plot_dir).unwrap();
    let vti = path(&dir, "w.vti");
    let mut args = base.to_vec();
    args.extend(["-o", &vti, "--plot", &plot_dir]);
    let o = toposmooth(&args);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(!Path::new(&vti).exists(), "no output left behind");
    // the derived field's holes are reported as the derived field's
    let o = toposmooth(&["extrema", "--derive", "vorticity", "--u", &u, "--v", &v]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(text(&o).contains("derived vorticity") && text(&o).contains("774 missing"), "{}", text(&o));
    // verify --input re-reads with the spacing the .vti carries
    let piv = dataset("soapfilm_piv_vorticity_63x63.csv");
    let o = toposmooth(&[
        "smooth",
        &piv,
        "--fill-missing",
        "--spacing",
        "0.31248,-0.31248",
        "--minima",
        "9",
        "--maxima",
        "4",
        "-o",
        &vti,
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let o = toposmooth(&["verify", &vti, "--input", &piv, "--fill-missing"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

/// Item 5 of issue 15: a representative given with `--representative` is built or refused,
/// never replaced. A plateau at 8 with a dip to 5 beside a plain at 2 with a bump to 4: the
/// harmonic representative (0 at every kept minimum, 1 at every kept maximum) runs up from the
/// dip (a kept minimum at 5) to the bump (a kept maximum at 4), which no strict function with
/// those values can follow: exit 3 naming both. On few-valued random grids an explicit
/// separatrix representative certifies as itself or exits 1 naming the vertices, and the
/// automatic choice names every fallback in the summary and the report.
#[test]
fn an_explicit_representative_is_built_or_refused() {
    let dir = scratch("explicit-representative");
    let (nx, ny) = (20, 10);
    let mut rows = vec![vec![0.0f64; nx]; ny];
    for (r, row) in rows.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            let g = |cx: f64, cy: f64| (-((c as f64 - cx).powi(2) + (r as f64 - cy).powi(2)) / 2.0).exp();
            *v = if c < 10 { 8.0 - 3.0 * g(7.0, 5.0) } else { 2.0 + 2.0 * g(12.0, 5.0) };
        }
    }
    rows[9][0] = 10.0;
    rows[0][19] = 0.0;
    let csv = path(&dir, "plateau.csv");
    let body: Vec<String> =
        rows.iter().map(|r| r.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(",")).collect();
    std::fs::write(&csv, body.join("\n") + "\n").unwrap();
    let out = path(&dir, "out.npz");
    let o = toposmooth(&["smooth", &csv, "-o", &out, "--persistence", "15%", "--representative", "harmonic"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let msg = text(&o);
    let (dip, bump) = (5 * nx + 7, 5 * nx + 12);
    assert!(
        msg.contains(&format!("kept minimum {dip} (value 5)"))
            && msg.contains(&format!("kept maximum {bump} (value 4)")),
        "{msg}"
    );
    assert!(!Path::new(&out).exists(), "no output written");
    // few-valued grids
    let (mut explicit_ok, mut explicit_refused, mut fallbacks) = (0, 0, 0);
    for seed in 0..40u64 {
        let r = common::uniform(seed + 1000, 80);
        let (gx, gy) = (5 + (seed % 6) as usize, 4 + (seed % 5) as usize);
        let body: Vec<String> = (0..gy)
            .map(|y| (0..gx).map(|x| format!("{}", (r[(y * gx + x) % 80] * 4.0).floor())).collect::<Vec<_>>().join(","))
            .collect();
        let g = path(&dir, &format!("g{seed}.csv"));
        std::fs::write(&g, body.join("\n") + "\n").unwrap();
        let json = path(&dir, &format!("g{seed}.json"));
        let o = toposmooth(&["smooth", &g, "-o", &out, "--representative", "separatrix", "--report", &json]);
        match o.status.code() {
            Some(0) => {
                let rep = common::json(&json);
                assert!(
                    rep["representative"].as_str().unwrap().starts_with("separatrix"),
                    "seed {seed}: {}",
                    rep["representative"]
                );
                assert_eq!(rep["representative_fallbacks"].as_array().unwrap().len(), 0, "seed {seed}");
                explicit_ok += 1;
            }
            Some(1) => {
                let m = text(&o);
                assert!(m.contains("separatrix representative") && m.contains("vertex"), "seed {seed}: {m}");
                assert!(m.contains("requested explicitly"), "seed {seed}: {m}");
                explicit_refused += 1;
            }
            c => panic!("seed {seed}: exit {c:?}: {}", text(&o)),
        }
        let o = toposmooth(&["smooth", &g, "-o", &out, "--report", &json]);
        assert!(o.status.success(), "seed {seed}: {}", text(&o));
        let rep = common::json(&json);
        let used = rep["representative"].as_str().unwrap();
        let named = rep["representative_fallbacks"].as_array().unwrap();
        // the automatic choice starts with the flooded one: any other names why it was not used
        if !used.starts_with("flooded") {
            fallbacks += 1;
            assert!(!named.is_empty(), "seed {seed}: {used} without a named fallback");
            assert!(text(&o).contains("representative fallback"), "seed {seed}: {}", text(&o));
        }
        check_output(&out);
    }
    assert_eq!(explicit_ok + explicit_refused, 40);
    eprintln!("explicit separatrix: {explicit_ok} built, {explicit_refused} refused; automatic fallbacks {fallbacks}");
}

/// An ASCII `.vti` of `nx × ny` points at origin `o` with spacing `d`, one Float64 array `h`
/// sampled from `f(x, y)`.
fn ascii_vti(nx: usize, ny: usize, o: [f64; 2], d: [f64; 2], f: impl Fn(f64, f64) -> f64) -> String {
    let values: Vec<String> =
        (0..nx * ny).map(|i| f(o[0] + (i % nx) as f64 * d[0], o[1] + (i / nx) as f64 * d[1]).to_string()).collect();
    let (ex, ey) = (nx - 1, ny - 1);
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\">\n\
         <ImageData WholeExtent=\"0 {ex} 0 {ey} 0 0\" Origin=\"{} {} 0\" Spacing=\"{} {} 1\">\n\
         <Piece Extent=\"0 {ex} 0 {ey} 0 0\"><PointData Scalars=\"h\">\n\
         <DataArray type=\"Float64\" Name=\"h\" format=\"ascii\">{}</DataArray>\n\
         </PointData></Piece></ImageData></VTKFile>\n",
        o[0],
        o[1],
        d[0],
        d[1],
        values.join(" ")
    )
}

/// The coloured (not grey, black or white) pixels down column `x` of a figure, top first.
fn coloured_down(img: &image::RgbImage, x: u32) -> Vec<[u8; 3]> {
    let grey = |p: &[u8; 3]| p.iter().max().unwrap() - p.iter().min().unwrap() < 12;
    (0..img.height()).map(|y| img.get_pixel(x, y).0).filter(|p| !grey(p)).collect()
}

#[test]
fn heat_maps_put_larger_y_on_top_as_paraview_does() {
    // h = y + x/10 on 30 × 20 points; stored with dy = +1 and, rows reversed, with dy = −1
    let root = scratch("plot_orientation");
    let h = |x: f64, y: f64| y + x / 10.0;
    let mut figures = Vec::new();
    for (sub, o, d) in [("up", [0.0, 0.0], [1.0, 1.0]), ("down", [0.0, 19.0], [1.0, -1.0])] {
        let dir = root.join(sub);
        std::fs::create_dir_all(&dir).unwrap();
        let vti = write(&dir, "ramp.vti", ascii_vti(30, 20, o, d, h).as_bytes());
        let (out, png) = (path(&dir, "out.vti"), path(&dir, "fig.png"));
        let r = toposmooth(&["smooth", &vti.display().to_string(), "-o", &out, "--plot", &png]);
        assert!(r.status.success(), "{}", text(&r));
        figures.push(image::open(&png).unwrap().to_rgb8());
    }
    let (w, _) = figures[0].dimensions();
    // down the middle of the input panel (the left one): high values (viridis yellow) on top
    let column = coloured_down(&figures[0], w / 4);
    let (top, bottom) = (column[0], column[column.len() - 1]);
    assert!(top[0] > 150 && top[1] > 150 && top[2] < 120, "top is the high colour: {top:?}");
    assert!(bottom[2] > bottom[1] && bottom[0] < 120, "bottom is the low colour: {bottom:?}");
    // the same physical field gives the same input panel, axes included (the title row and the
    // smoothed panel hold the run's own numbers)
    let same =
        (60..figures[0].height()).all(|y| (0..w / 2).all(|x| figures[0].get_pixel(x, y) == figures[1].get_pixel(x, y)));
    assert!(same, "dy = +1 and dy = -1 draw the same picture");
    std::fs::remove_dir_all(&root).ok();
}

#[test]
fn a_png_keeps_its_look_in_the_heat_map() {
    // a grey ramp bright at the image's top row, dark at its bottom
    let dir = scratch("plot_png_look");
    let img = image::GrayImage::from_fn(40, 30, |x, y| image::Luma([(250 - y * 8 + x % 3) as u8]));
    let src = dir.join("ramp.png");
    img.save(&src).unwrap();
    let (out, png) = (path(&dir, "out.vti"), path(&dir, "fig.png"));
    let r = toposmooth(&["smooth", &src.display().to_string(), "-o", &out, "--plot", &png]);
    assert!(r.status.success(), "{}", text(&r));
    let fig = image::open(&png).unwrap().to_rgb8();
    let column = coloured_down(&fig, fig.width() / 4);
    let (top, bottom) = (column[0], column[column.len() - 1]);
    assert!(top[0] > 150 && top[1] > 150 && top[2] < 120, "the image's bright top row stays on top: {top:?}");
    assert!(bottom[2] > bottom[1] && bottom[0] < 120, "{bottom:?}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The dark (text) pixels of `img` in the rectangle `xs × ys`.
fn dark_pixels(img: &image::RgbImage, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> usize {
    ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 100))
        .count()
}

#[test]
fn heat_maps_have_axes_in_the_file_coordinates() {
    // cac0d08 drew the panels with no axes at all: nothing told where x and y were, and two
    // files with the same values at other coordinates gave the same picture
    let root = scratch("plot_axes");
    let h = |x: f64, y: f64| (x / 7.0).sin() + (y / 5.0).cos();
    let mut figures = Vec::new();
    for (sub, o, d) in [("near", [0.0, 0.0], [1.0, 1.0]), ("far", [5000.0, -300.0], [2.5, 4.0])] {
        let dir = root.join(sub);
        std::fs::create_dir_all(&dir).unwrap();
        // the same values at each index: only the coordinates differ
        let vti =
            write(&dir, "wave.vti", ascii_vti(40, 30, o, d, |x, y| h((x - o[0]) / d[0], (y - o[1]) / d[1])).as_bytes());
        let (out, png) = (path(&dir, "out.vti"), path(&dir, "fig.png"));
        let r = toposmooth(&["smooth", &vti.display().to_string(), "-o", &out, "--plot", &png]);
        assert!(r.status.success(), "{}", text(&r));
        figures.push(image::open(&png).unwrap().to_rgb8());
    }
    let img = &figures[0];
    let (w, ht) = img.dimensions();
    let coloured = |p: &[u8; 3]| p.iter().max().unwrap() - p.iter().min().unwrap() >= 12;
    // the input panel: its left edge along the middle row, its bottom edge down its middle column
    let left = (0..w).find(|&x| coloured(&img.get_pixel(x, ht / 2).0)).unwrap();
    let bottom = (0..ht).rev().find(|&y| coloured(&img.get_pixel(left + 40, y).0)).unwrap();
    // markers may overhang the panel by their radius: labels are looked for beyond that
    assert!(left > 20, "room for y tick labels left of the panel (left edge at {left})");
    assert!(dark_pixels(img, 0..left - 10, 0..ht) > 100, "y tick labels left of the panel");
    assert!(dark_pixels(img, left..w / 2, bottom + 10..ht) > 100, "x tick labels below the panel");
    // the labels are the file's coordinates: the two figures differ left of and below the panel
    let differ = |xs: std::ops::Range<u32>, ys: std::ops::Range<u32>| {
        ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
            .any(|(x, y)| figures[0].get_pixel(x, y) != figures[1].get_pixel(x, y))
    };
    assert!(differ(0..left - 10, 60..ht), "the y labels follow the origin and spacing");
    assert!(differ(left..w / 2, bottom + 10..ht), "the x labels follow the origin and spacing");
    std::fs::remove_dir_all(&root).ok();
}

#[test]
fn a_band_of_cancelled_pairs_stays_light_grey_in_the_diagram() {
    // 50 × 50 noise: 725 pairs, 3 minima and 1 maximum kept at 70 %. cac0d08 drew each
    // cancelled pair as a hollow circle in the kept pairs' blue or red, 18,000 coloured pixels
    // each way, a band that looked kept; now they are small light-grey crosses
    let dir = scratch("diagram_band");
    let v = common::uniform(3, 50 * 50);
    let rows: Vec<String> =
        v.chunks(50).map(|r| r.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(",")).collect();
    let csv = write(&dir, "noise.csv", (rows.join("\n") + "\n").as_bytes());
    let png = path(&dir, "d.png");
    let o = toposmooth(&["extrema", &csv.display().to_string(), "--plot", &png, "--persistence", "70%"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("kept at persistence"), "{}", text(&o));
    let img = image::open(&png).unwrap().to_rgb8();
    let blue = img.pixels().filter(|p| p[2] > 150 && p[0] < 90 && p[1] < 120).count();
    let red = img.pixels().filter(|p| p[0] > 150 && p[1] < 90 && p[2] < 90).count();
    let light = img.pixels().filter(|p| p[0] == p[1] && p[1] == p[2] && (160..=190).contains(&p[0])).count();
    // the kept dots, the essential pairs' triangles and the legend's marks: a few hundred pixels
    assert!(blue < 1500, "blue pixels: {blue}");
    assert!(red < 1500, "red pixels: {red}");
    assert!(light > 3000, "light grey pixels: {light}");
    std::fs::remove_dir_all(&dir).ok();
}
