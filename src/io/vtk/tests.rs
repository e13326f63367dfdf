//! Tests of the VTK readers and writers.

use super::write::b64_encode;
use super::*;
use std::io::Write;

fn dir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("toposmooth-vtk-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn example1() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/karman_vortex_street_ttk_example1.vti")
}

/// Example 3 lives in the shared data folder beside the repository (or in datasets/).
fn example3() -> Option<std::path::PathBuf> {
    let name = "uncertain_karman_vortex_street_ttk_example3.vti";
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    [root.join("datasets").join(name), root.join("../shared/data").join(name)].into_iter().find(|p| p.exists())
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn values(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|i| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            match i % 11 {
                0 => -0.0,
                1 => 5e-324,
                2 => f64::MAX,
                _ => f64::from_bits(s >> 2) * if s & 1 == 0 { 1.0 } else { -1.0 },
            }
        })
        .collect()
}

#[test]
fn reads_karman_example1() {
    let img = read_image(&example1()).unwrap();
    assert_eq!((img.nx, img.ny), (513, 65));
    assert_eq!((img.spacing, img.origin), ([1.0, 1.0], [0.0, 0.0]));
    assert_eq!(img.names(), ["Vectors_"]);
    let v = img.array("Vectors_").unwrap();
    assert_eq!(v.components, 3);
    assert_eq!(v.values.len(), 513 * 65 * 3);
    assert!(v.component(2).iter().all(|&z| z == 0.0), "z velocity is 0 in a 2D flow");
    assert!(v.values.iter().all(|x| x.is_finite()));
    let mag = v.magnitude();
    // the obstacle: velocity exactly 0 on the block x = 30..=35, y = 30..=35 less its 4
    // corners (a rounded cylinder), and nowhere else
    let zero: Vec<(usize, usize)> = (0..mag.len()).filter(|&k| mag[k] == 0.0).map(|k| (k % 513, k / 513)).collect();
    let corner = |x: usize, y: usize| (x == 30 || x == 35) && (y == 30 || y == 35);
    let block: Vec<(usize, usize)> =
        (30..=35).flat_map(|y| (30..=35).map(move |x| (x, y))).filter(|&(x, y)| !corner(x, y)).collect();
    assert_eq!(zero, block);
    // values as decoded independently (Python zlib + base64)
    let k = (32 * 513 + 100) * 3;
    assert_eq!((v.values[k], v.values[k + 1]), (0.8997898101806641, -0.32171547412872314));
    assert!((v.values.iter().sum::<f64>() - 33401.93146558964).abs() < 1e-8);
    // the free stream moves
    assert!(mag[32 * 513 + 500] > 0.1 && mag[5 * 513 + 5] > 0.1);
    // max velocity within the RangeMax the file advertises
    let max = mag.iter().cloned().fold(0.0, f64::max);
    assert!((max - 1.3748271724).abs() < 1e-9, "{max}");
    assert!(img.grid().is_ok());
    let e = img.array("vorticity").unwrap_err().to_string();
    assert!(e.contains("`vorticity`") && e.contains("`Vectors_`"), "{e}");
}

#[test]
fn reads_uncertain_example3() {
    let Some(p) = example3() else {
        eprintln!("skipped: uncertain_karman_vortex_street_ttk_example3.vti is not in datasets/ or ../shared/data/");
        return;
    };
    let img = read_image(&p).unwrap();
    assert_eq!((img.nx, img.ny), (513, 65));
    assert_eq!(img.names(), ["lowerBoundField", "upperBoundField"]);
    let lo = img.array("lowerBoundField").unwrap();
    let hi = img.array("upperBoundField").unwrap();
    assert_eq!((lo.components, hi.components), (1, 1));
    assert_eq!(lo.values.len(), 513 * 65);
    assert!(lo.values.iter().zip(&hi.values).all(|(l, h)| l <= h), "lower ≤ upper everywhere");
    assert!(lo.values.iter().zip(&hi.values).any(|(l, h)| l < h), "the bounds are not all equal");
    // Float32 data: every value is exactly an f32
    assert!(lo.values.iter().all(|&v| (v as f32) as f64 == v));
    assert_eq!(lo.values[0] as f32, f32::from_le_bytes([0x0f, 0x00, 0x80, 0x3f]));
}

#[test]
fn vti_round_trip_bits_and_geometry() {
    let d = dir();
    let (nx, ny) = (37, 23); // 851 doubles: several zlib blocks
    let a = values(nx * ny, 1);
    let mut b = values(nx * ny, 2);
    b[5] = f64::NAN;
    let many = values(5000, 3)[..5000].to_vec();
    for (name, spacing, origin) in [("g.vti", [0.1, 0.3], [-1.7, 1e-9]), ("neg.vti", [-0.5, 2.0], [3.0, 0.0])] {
        let p = d.join(name);
        let staged = stage_vti(&p, nx, ny, spacing, origin, &[("f & <g>", &a), ("b", &b)]).unwrap();
        assert!(!p.exists());
        staged.commit().unwrap();
        let img = read_image(&p).unwrap();
        assert_eq!((img.nx, img.ny, img.spacing, img.origin), (nx, ny, spacing, origin));
        assert_eq!(img.names(), ["f & <g>", "b"]);
        assert_eq!(bits(&img.arrays[0].values), bits(&a));
        assert_eq!(bits(&img.arrays[1].values), bits(&b));
        // the data set as written: extent from 0, z spacing 1, no direction
        let ds = read_dataset(&p).unwrap();
        let g = ds.image.unwrap();
        assert_eq!(g.extent, [0, nx as i64 - 1, 0, ny as i64 - 1, 0, 0]);
        assert_eq!((g.origin, g.spacing), ([origin[0], origin[1], 0.0], [spacing[0], spacing[1], 1.0]));
    }
    // a large array over many blocks
    let p = d.join("big.vti");
    stage_vti(&p, 100, 50, [1.0, 1.0], [0.0, 0.0], &[("m", &many)]).unwrap().commit().unwrap();
    assert_eq!(bits(&read_image(&p).unwrap().arrays[0].values), bits(&many));
    // argument errors
    let e = stage_vti(&p, 10, 10, [1.0, 1.0], [0.0, 0.0], &[("m", &many)]).err().unwrap().to_string();
    assert!(e.contains("big.vti") && e.contains("`m`"), "{e}");
    let e = stage_vti(&p, 100, 50, [f64::NAN, 1.0], [0.0, 0.0], &[]).err().unwrap().to_string();
    assert!(e.contains("finite"), "{e}");
}

// ---- hand-built .vti files in every layout -------------------------------------------

#[derive(Clone, Copy, Debug)]
enum Layout {
    Ascii,
    Binary,
    Base64Appended,
    RawAppended,
}

#[derive(Clone, Copy, Debug)]
struct Spec {
    big: bool,
    header64: bool,
    zlib: bool,
    layout: Layout,
    /// Header and data base64-encoded as one stream instead of two.
    joint: bool,
}

fn encode(ty: &str, v: f64, big: bool) -> Vec<u8> {
    macro_rules! e {
        ($t:ty) => {
            if big {
                (v as $t).to_be_bytes().to_vec()
            } else {
                (v as $t).to_le_bytes().to_vec()
            }
        };
    }
    match ty {
        "Int8" => e!(i8),
        "UInt8" => e!(u8),
        "Int16" => e!(i16),
        "UInt16" => e!(u16),
        "Int32" => e!(i32),
        "UInt32" => e!(u32),
        "Int64" => e!(i64),
        "UInt64" => e!(u64),
        "Float32" => e!(f32),
        "Float64" => e!(f64),
        _ => panic!("{ty}"),
    }
}

fn block(s: Spec, raw: &[u8]) -> (Vec<u8>, Vec<u8>) {
    let word = |v: usize| match (s.header64, s.big) {
        (true, true) => (v as u64).to_be_bytes().to_vec(),
        (true, false) => (v as u64).to_le_bytes().to_vec(),
        (false, true) => (v as u32).to_be_bytes().to_vec(),
        (false, false) => (v as u32).to_le_bytes().to_vec(),
    };
    if !s.zlib {
        return (word(raw.len()), raw.to_vec());
    }
    let bs = 64;
    let blocks: Vec<Vec<u8>> = raw
        .chunks(bs)
        .map(|c| {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            z.write_all(c).unwrap();
            z.finish().unwrap()
        })
        .collect();
    let last = raw.len() % bs;
    let mut header = [word(blocks.len()), word(bs), word(last)].concat();
    for b in &blocks {
        header.extend(word(b.len()));
    }
    (header, blocks.concat())
}

fn vti(s: Spec, extent: &str, arrays: &[(&str, &str, usize, &[f64])]) -> Vec<u8> {
    let mut x = String::from("<?xml version=\"1.0\"?>\n");
    x += &format!(
        "<VTKFile type=\"ImageData\" version=\"{}\" byte_order=\"{}\"{}{}>\n",
        if s.header64 { "1.0" } else { "0.1" },
        if s.big { "BigEndian" } else { "LittleEndian" },
        if s.header64 { " header_type=\"UInt64\"" } else { "" },
        if s.zlib { " compressor=\"vtkZLibDataCompressor\"" } else { "" },
    );
    x += &format!("<ImageData WholeExtent=\"{extent}\" Origin=\"10 20 0\" Spacing=\"0.5 0.25 1\">\n");
    x += &format!("<Piece Extent=\"{extent}\">\n<PointData>\n");
    let mut appended: Vec<u8> = Vec::new();
    for (ty, name, comps, vals) in arrays {
        let raw: Vec<u8> = vals.iter().flat_map(|&v| encode(ty, v, s.big)).collect();
        let (header, data) = block(s, &raw);
        let b64 = if s.joint {
            b64_encode(&[header.clone(), data.clone()].concat())
        } else {
            b64_encode(&header) + &b64_encode(&data)
        };
        let open = format!("<DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\"");
        match s.layout {
            Layout::Ascii => {
                let text: Vec<String> = vals
                    .iter()
                    .map(|v| if ty.starts_with("Float") { format!("{v:?}") } else { format!("{}", *v as i64) })
                    .collect();
                x += &format!("{open} format=\"ascii\">\n  {}\n</DataArray>\n", text.join(" "));
            }
            Layout::Binary => x += &format!("{open} format=\"binary\">\n  {b64}\n</DataArray>\n"),
            Layout::Base64Appended => {
                x += &format!("{open} format=\"appended\" offset=\"{}\"/>\n", appended.len());
                appended.extend(b64.as_bytes());
            }
            Layout::RawAppended => {
                x += &format!("{open} format=\"appended\" offset=\"{}\"/>\n", appended.len());
                appended.extend(header);
                appended.extend(data);
            }
        }
    }
    x += "</PointData>\n<CellData>\n</CellData>\n</Piece>\n</ImageData>\n";
    let mut out = x.into_bytes();
    if matches!(s.layout, Layout::Base64Appended | Layout::RawAppended) {
        let enc = if matches!(s.layout, Layout::RawAppended) { "raw" } else { "base64" };
        out.extend(format!("<AppendedData encoding=\"{enc}\">\n   _").as_bytes());
        out.extend(appended);
        out.extend(b"\n</AppendedData>\n");
    }
    out.extend(b"</VTKFile>\n");
    out
}

#[test]
fn reads_every_vti_layout_and_type() {
    let d = dir();
    let (nx, ny) = (5, 3);
    let n = nx * ny;
    let f64s = values(n, 9);
    let f32s: Vec<f64> = (0..n).map(|i| i as f64 * 0.5 - 3.0).collect();
    let ints: Vec<f64> = (0..n * 2).map(|i| i as f64 * 3.0 - 40.0).collect(); // fits in Int8
    let small: Vec<f64> = (0..n).map(|i| (i * 17 % 256) as f64).collect();
    let big_u: Vec<f64> = (0..n).map(|i| (1u64 << 40) as f64 + i as f64).collect();
    let types = ["Int8", "Int16", "Int32", "Int64"];
    let mut k = 0;
    for layout in [Layout::Ascii, Layout::Binary, Layout::Base64Appended, Layout::RawAppended] {
        for big in [false, true] {
            for header64 in [false, true] {
                for zlib in [false, true] {
                    for joint in [false, true] {
                        if joint && matches!(layout, Layout::Ascii | Layout::RawAppended) {
                            continue;
                        }
                        let s = Spec { big, header64, zlib, layout, joint };
                        let ity = types[k % 4];
                        k += 1;
                        let arrays: [(&str, &str, usize, &[f64]); 6] = [
                            ("Float64", "d", 1, &f64s),
                            ("Float32", "s", 1, &f32s),
                            (ity, "i", 2, &ints),
                            ("UInt8", "u8", 1, &small),
                            ("UInt16", "u16", 1, &small),
                            ("UInt64", "u64", 1, &big_u),
                        ];
                        let arrays = if matches!(layout, Layout::Ascii) { &arrays[1..] } else { &arrays[..] };
                        let p = d.join(format!("layout{k}.vti"));
                        std::fs::write(&p, vti(s, "2 6 -1 1 0 0", arrays)).unwrap();
                        let img = read_image(&p).unwrap_or_else(|e| panic!("{s:?}: {e}"));
                        assert_eq!((img.nx, img.ny), (nx, ny), "{s:?}");
                        // the extent starts at (2, -1): the first point is shifted
                        assert_eq!(img.origin, [11.0, 19.75], "{s:?}");
                        assert_eq!(img.spacing, [0.5, 0.25]);
                        for (arr, (_, name, comps, vals)) in img.arrays.iter().zip(arrays) {
                            assert_eq!((&arr.name[..], arr.components), (*name, *comps), "{s:?}");
                            assert_eq!(bits(&arr.values), bits(vals), "{s:?} {name}");
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn reads_legacy_structured_points() {
    let d = dir();
    let head = "# vtk DataFile Version 3.0\nlegacy test\n";
    let geometry = "DATASET STRUCTURED_POINTS\nDIMENSIONS 3 2 1\nORIGIN 0.1 -2.5 0\nSPACING 0.1 0.3 1\n";
    let ascii = format!(
        "{head}ASCII\n{geometry}POINT_DATA 6\nSCALARS height double 1\nLOOKUP_TABLE default\n\
         1.5 2 3 4 5 6.25\nVECTORS vel float\n1 0 0 2 0 0 3 0 0 4 0 0 5 0 0 6 0 0\n\
         FIELD FieldData 1\ntemp 2 6 int\n1 2 3 4 5 6 7 8 9 10 11 12\n"
    );
    let p = d.join("a.vtk");
    std::fs::write(&p, ascii).unwrap();
    let img = read_image(&p).unwrap();
    assert_eq!((img.nx, img.ny, img.origin, img.spacing), (3, 2, [0.1, -2.5], [0.1, 0.3]));
    assert_eq!(img.names(), ["height", "vel", "temp"]);
    assert_eq!(img.arrays[0].values, vec![1.5, 2.0, 3.0, 4.0, 5.0, 6.25]);
    assert_eq!(img.arrays[1].components, 3);
    assert_eq!(img.arrays[1].component(0), vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    assert_eq!((img.arrays[2].components, img.arrays[2].values[11]), (2, 12.0));

    let h: Vec<f64> = values(6, 4);
    let mut bin =
        format!("{head}BINARY\n{geometry}POINT_DATA 6\nSCALARS h double\nLOOKUP_TABLE default\n").into_bytes();
    bin.extend(h.iter().flat_map(|v| v.to_be_bytes()));
    bin.extend(b"\n");
    let p = d.join("b.vtk");
    std::fs::write(&p, &bin).unwrap();
    let img = read_image(&p).unwrap();
    assert_eq!(bits(&img.array("h").unwrap().values), bits(&h));
    // errors: truncated binary data, 3D dimensions, cell data only
    let p = d.join("cut.vtk");
    std::fs::write(&p, &bin[..bin.len() - 20]).unwrap();
    let e = read_image(&p).unwrap_err().to_string();
    assert!(e.contains("cut.vtk") && e.contains("truncated"), "{e}");
    let p = d.join("3d.vtk");
    std::fs::write(&p, format!("{head}ASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 8\nSCALARS s float\nLOOKUP_TABLE default\n1 2 3 4 5 6 7 8\n")).unwrap();
    let e = read_image(&p).unwrap_err().to_string();
    assert!(e.contains("3d.vtk") && e.contains("along z"), "{e}");
    let p = d.join("cells.vtk");
    std::fs::write(&p, format!("{head}ASCII\n{geometry}CELL_DATA 2\nSCALARS c float\nLOOKUP_TABLE default\n1 2\n"))
        .unwrap();
    let e = read_image(&p).unwrap_err().to_string();
    assert!(e.contains("cells.vtk") && e.contains("`c`"), "{e}");
}

fn edited(name: &str, from: &str, to: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(example1()).unwrap();
    assert!(text.contains(from), "{from}");
    let p = dir().join(name);
    std::fs::write(&p, text.replace(from, to)).unwrap();
    p
}

fn error_of(p: &Path) -> String {
    let e = read_image(p).unwrap_err().to_string();
    let name = p.file_name().unwrap().to_str().unwrap();
    assert!(e.contains(name), "the error names the file: {e}");
    e
}

#[test]
fn bad_vti_files_give_clear_errors() {
    let d = dir();
    // truncated: Example 1 (appended base64) cut in half
    let bytes = std::fs::read(example1()).unwrap();
    let p = d.join("half.vti");
    std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
    assert!(error_of(&p).contains("truncated"));
    // truncated inline binary data, and raw appended data
    let n = 6 * 4;
    let v = values(n, 5);
    let s = Spec { big: false, header64: true, zlib: true, layout: Layout::Binary, joint: false };
    let file = vti(s, "0 5 0 3 0 0", &[("Float64", "v", 1, &v)]);
    let p = d.join("inline-half.vti");
    std::fs::write(&p, &file[..file.len() * 3 / 5]).unwrap();
    assert!(error_of(&p).contains("truncated"));
    let s = Spec { layout: Layout::RawAppended, zlib: false, ..s };
    let file = vti(s, "0 5 0 3 0 0", &[("Float64", "v", 1, &v)]);
    let cut = file.len() - "\n</AppendedData>\n</VTKFile>\n".len() - 9;
    let p = d.join("raw-half.vti");
    std::fs::write(&p, &file[..cut]).unwrap();
    assert!(error_of(&p).contains("truncated"));
    // wrong sizes: components or extent edited
    let p = edited("comps.vti", "NumberOfComponents=\"3\"", "NumberOfComponents=\"2\"");
    let e = error_of(&p);
    assert!(e.contains("`Vectors_`") && e.contains("bytes"), "{e}");
    let p = edited("extent.vti", "0 512 0 64 0 0", "0 511 0 64 0 0");
    let e = error_of(&p);
    assert!(e.contains("33280 points") && e.contains("`Vectors_`"), "{e}");
    // unknown compressor; zlib data labelled lz4
    let p = edited("foo.vti", "vtkZLibDataCompressor", "vtkFooDataCompressor");
    let e = error_of(&p);
    assert!(e.contains("vtkFooDataCompressor") && e.contains("vtkLZ4DataCompressor"), "{e}");
    let p = edited("lz4.vti", "vtkZLibDataCompressor", "vtkLZ4DataCompressor");
    let e = error_of(&p);
    assert!(e.contains("`Vectors_`") && e.contains("does not decompress"), "{e}");
    // an extent that the data does not fill; a 3D image (written by VTK); a line
    let p = edited("3d.vti", "0 512 0 64 0 0", "0 512 0 64 0 3");
    let e = error_of(&p);
    assert!(e.contains("`Vectors_`") && e.contains("133380 points"), "{e}");
    let vol = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/vtk/vol.appended-raw-zlib-u64.vti");
    let e = read_image(&vol).unwrap_err().to_string();
    assert!(e.contains("vol.appended-raw-zlib-u64.vti") && e.contains("3 points along z"), "{e}");
    let p = edited("thin.vti", "0 512 0 64 0 0", "0 512 0 0 0 0");
    let e = error_of(&p);
    assert!(e.contains("`Vectors_`") && e.contains("513 points"), "{e}");
    // corrupt base64, non-numeric ascii, string array, cell data only, not VTK, not ImageData
    let p = edited("b64.vti", "_GQAAAACAAAAY", "_GQAAAAC*AAAY");
    assert!(error_of(&p).contains("base64"));
    let s = Spec { big: false, header64: false, zlib: false, layout: Layout::Ascii, joint: false };
    let text = String::from_utf8(vti(s, "0 1 0 1 0 0", &[("Float64", "a", 1, &[1.0, 2.0, 3.0, 4.0])])).unwrap();
    let p = d.join("text.vti");
    std::fs::write(&p, text.replace("3.0", "x3")).unwrap();
    let e = error_of(&p);
    assert!(e.contains("`x3`") && e.contains("`a`"), "{e}");
    let p = d.join("short-ascii.vti");
    std::fs::write(&p, text.replace("3.0 4.0", "3.0")).unwrap();
    assert!(error_of(&p).contains("3 values"));
    let p = d.join("string.vti");
    std::fs::write(&p, text.replace("type=\"Float64\"", "type=\"String\"")).unwrap();
    assert!(error_of(&p).contains("String"));
    let p = d.join("cells.vti");
    // 3 × 3 points, 4 cells: the array fits the cells
    let cells = String::from_utf8(vti(s, "0 2 0 2 0 0", &[("Float64", "a", 1, &[1.0, 2.0, 3.0, 4.0])])).unwrap();
    std::fs::write(
        &p,
        cells.replace("<PointData>", "<PointData>\n</PointData>\n<CellData>").replacen(
            "</PointData>\n<CellData>\n</CellData>",
            "</CellData>",
            1,
        ),
    )
    .unwrap();
    let e = error_of(&p);
    assert!(e.contains("cell data only") && e.contains("`a`"), "{e}");
    let p = d.join("poly.vti");
    std::fs::write(&p, text.replace("type=\"ImageData\"", "type=\"PolyData\"")).unwrap();
    assert!(error_of(&p).contains("PolyData"));
    let p = d.join("junk.vti");
    std::fs::write(&p, b"hello").unwrap();
    assert!(error_of(&p).contains("VTK"));
    // missing file: an I/O error naming it
    let e = read_image(&d.join("missing.vti")).unwrap_err();
    assert!(matches!(e, Error::Io { .. }) && e.to_string().contains("missing.vti"), "{e}");
}

#[test]
fn vtp_is_valid_poly_data() {
    let poly = PolyData {
        points: vec![[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [2.0, 0.25, 1.0], [0.1, 0.2, 0.3]],
        verts: vec![0, 3],
        lines: vec![vec![0, 1, 2], vec![3, 1]],
        point_arrays: vec![("value".into(), vec![1.0, 2.0, 3.0, 4.0])],
        cell_arrays: vec![("kind".into(), vec![0.0, 2.0, 7.0, 8.0])],
        polys: Vec::new(),
    };
    let p = dir().join("mesh.vtp");
    stage_vtp(&p, &poly).unwrap().commit().unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    for needle in ["type=\"PolyData\"", "NumberOfVerts=\"2\"", "NumberOfLines=\"2\"", "<Verts>", "<Lines>"] {
        assert!(text.contains(needle), "{needle}");
    }
    let ds = read_dataset(&p).unwrap();
    assert_eq!(ds.points, poly.points);
    // verts, then lines, in VTK's cell order
    assert_eq!(ds.cells.types, vec![cell::VERTEX, cell::VERTEX, cell::POLY_LINE, cell::LINE]);
    assert_eq!(ds.cells.connectivity, vec![0, 3, 0, 1, 2, 3, 1]);
    assert_eq!(ds.cells.offsets, vec![0, 1, 2, 5, 7]);
    assert_eq!((ds.point_data[0].name.as_str(), &ds.point_data[0].values), ("value", &poly.point_arrays[0].1));
    assert_eq!(ds.cell_data.iter().map(|a| a.name.as_str()).collect::<Vec<_>>(), ["kind"]);
    // empty cell lists are valid too
    let only_points = PolyData { points: poly.points.clone(), ..Default::default() };
    let q = dir().join("points.vtp");
    stage_vtp(&q, &only_points).unwrap().commit().unwrap();
    let ds = read_dataset(&q).unwrap();
    assert_eq!((ds.points.len(), ds.cells.len()), (4, 0));
    // argument errors
    let bad = PolyData { lines: vec![vec![0, 9]], ..poly.clone() };
    let e = stage_vtp(&p, &bad).err().unwrap().to_string();
    assert!(e.contains("mesh.vtp") && e.contains("point 9"), "{e}");
    let bad = PolyData { cell_arrays: vec![("kind".into(), vec![1.0])], ..poly };
    let e = stage_vtp(&p, &bad).err().unwrap().to_string();
    assert!(e.contains("`kind`") && e.contains("4 cells"), "{e}");
}

#[test]
fn malformed_markup_points_at_its_byte() {
    let path = dir().join("malformed.vti");
    std::fs::write(&path, "<VTKFile type=\"ImageData\">\n<ImageData WholeExtent=\"0 1 0 1 0 0\"></Piece>").unwrap();
    let e = read_image(&path).unwrap_err();
    assert!(e.to_string().contains("malformed XML near byte"), "{e}");
    assert!(matches!(e.location(), Some(crate::error::Location::Byte(b)) if b > 20), "{:?}", e.location());
}
