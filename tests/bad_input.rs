//! Bad input across the readers and commands, run through the tool as a user runs it. Each
//! case asserts the exit status, that the message names the file, that no panic text
//! reaches the user, and that nothing is left beside the input: no output, no temporary.
//! A few files a reader once panicked on must be read (exit 0), with no panic text either.
//!
//! Many cases are real VTK files (tests/fixtures/vtk, written by VTK 9.7) with one thing
//! broken, the way files get broken: cut short, a header word overwritten, an attribute
//! edited.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/vtk").join(name)).unwrap()
}

fn dataset(name: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets").join(name)).unwrap()
}

/// `bytes` with the first `from` replaced by `to`.
fn edit(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let at = bytes.windows(from.len()).position(|w| w == from.as_bytes()).unwrap_or_else(|| panic!("`{from}` absent"));
    [&bytes[..at], to.as_bytes(), &bytes[at + from.len()..]].concat()
}

/// `bytes` with the byte at `at` (from the start of the appended data when `appended`) changed.
fn flip_appended(bytes: &[u8], offset: usize) -> Vec<u8> {
    let marker = bytes.windows(2).position(|w| w == b">\n").unwrap();
    let start = bytes.windows(13).position(|w| w == b"<AppendedData").unwrap();
    let underscore = start + bytes[start..].iter().position(|&b| b == b'_').unwrap();
    assert!(marker < underscore);
    let mut out = bytes.to_vec();
    out[underscore + 1 + offset] ^= 0x5a;
    out
}

fn cut(bytes: &[u8], keep: f64) -> Vec<u8> {
    bytes[..(bytes.len() as f64 * keep) as usize].to_vec()
}

struct Case {
    file: &'static str,
    bytes: Vec<u8>,
    /// Output file name (in the same directory) for `smooth`, or other arguments.
    args: Vec<String>,
    code: i32,
    needle: &'static str,
    env: Option<(&'static str, &'static str)>,
}

fn smooth(file: &'static str, bytes: Vec<u8>, out: &str, code: i32, needle: &'static str) -> Case {
    Case { file, bytes, args: vec!["smooth".into(), file.into(), "-o".into(), out.into()], code, needle, env: None }
}

fn with_args(mut case: Case, args: &[&str]) -> Case {
    case.args.extend(args.iter().map(|a| a.to_string()));
    case
}

fn vtk_xml_cases() -> Vec<Case> {
    let raw = fixture("img.appended-raw-zlib-u64.vti");
    let ascii = fixture("img.ascii.vti");
    let b64 = fixture("img.binary-zlib-u32.vti");
    let lz4 = fixture("img.appended-raw-lz4-u64.vti");
    let lzma = fixture("img.appended-raw-lzma-u64.vti");
    let none = fixture("img.appended-raw-none-u64.vti");
    let vtp = fixture("surf.ascii.vtp");
    let vtu = fixture("surf.ascii.vtu");
    let zlib_vtu = fixture("surf.binary-zlib-u64.vtu");
    let o = "out.vti";
    let m = "out.vtp";
    vec![
        smooth("cut.vti", cut(&raw, 0.5), o, 3, "truncated"),
        smooth("cut-markup.vti", cut(&ascii, 0.1), o, 3, "cut-markup.vti"),
        smooth("blocks.vti", flip_appended(&raw, 0), o, 3, "`f`"),
        smooth("last-block.vti", flip_appended(&raw, 18), o, 3, "`f`"),
        smooth("zlib-data.vti", flip_appended(&raw, 40), o, 3, "decompress"),
        smooth("lz4-size.vti", flip_appended(&lz4, 24), o, 3, "`f`"),
        smooth("lzma-data.vti", flip_appended(&lzma, 40), o, 3, "decompress"),
        smooth("raw-size.vti", flip_appended(&none, 3), o, 3, "`f`"),
        smooth("text.vti", edit(&ascii, "1.113525328317434", "abc"), o, 3, "`abc`"),
        smooth("short.vti", edit(&ascii, "1.113525328317434", ""), o, 3, "values"),
        smooth(
            "comps.vti",
            edit(&ascii, "NumberOfComponents=\"3\"", "NumberOfComponents=\"0\""),
            o,
            3,
            "NumberOfComponents",
        ),
        smooth(
            "type.vti",
            edit(&ascii, "type=\"Float64\" Name=\"f\"", "type=\"Float128\" Name=\"f\""),
            o,
            3,
            "Float128",
        ),
        smooth("format.vti", edit(&ascii, "format=\"ascii\"", "format=\"weird\""), o, 3, "weird"),
        smooth("offset.vti", edit(&raw, "offset=\"0\"", "offset=\"99999999\""), o, 3, "offset 99999999"),
        smooth("marker.vti", edit(&raw, "   _", "   X"), o, 3, "`_` marker"),
        smooth("order.vti", edit(&raw, "LittleEndian", "MiddleEndian"), o, 3, "MiddleEndian"),
        smooth("header.vti", edit(&raw, "header_type=\"UInt64\"", "header_type=\"UInt16\""), o, 3, "UInt16"),
        smooth("compressor.vti", edit(&raw, "vtkZLibDataCompressor", "vtkZstdDataCompressor"), o, 3, "vtkZstd"),
        smooth("parallel.vti", edit(&ascii, "type=\"ImageData\"", "type=\"PImageData\""), o, 3, "parallel"),
        smooth("structured.vti", edit(&ascii, "type=\"ImageData\"", "type=\"StructuredGrid\""), o, 3, "StructuredGrid"),
        smooth("oblique.vti", fixture("img_oblique.ascii.vti"), o, 3, "oblique"),
        smooth(
            "extent.vti",
            edit(&edit(&ascii, "0 6 0 4 0 0", "0 -1 0 4 0 0"), "0 6 0 4 0 0", "0 -1 0 4 0 0"),
            o,
            3,
            "extent",
        ),
        smooth("spacing.vti", edit(&ascii, "Spacing=\"0.5 0.25 1\"", "Spacing=\"0.5 x 1\""), o, 3, "Spacing"),
        smooth("origin.vti", edit(&ascii, "Origin=\"1 -2 0\"", "Origin=\"1 -2\""), o, 3, "Origin"),
        smooth("b64-char.vti", edit(&b64, "AQAAAACAAAAY", "AQAA*ACAAAAY"), o, 3, "base64"),
        smooth("empty.vti", Vec::new(), o, 3, "empty"),
        smooth("garbage.vti", (0..=255u8).cycle().take(700).collect(), o, 3, "garbage.vti"),
        smooth("int64.vti", edit(&ascii, "type=\"Float64\" Name=\"f\"", "type=\"Int64\" Name=\"f\""), o, 3, "`f`"),
        smooth("big-int.vti", int64_beyond_2_53(), o, 3, "2^53"),
        smooth("conn.vtp", edit(&vtp, "0 1 7", "0 1 700"), m, 3, "point 700"),
        smooth("offsets.vtp", edit(&vtp, "NumberOfPolys=\"48\"", "NumberOfPolys=\"49\""), m, 3, "offsets"),
        smooth("points.vtp", edit(&vtp, "NumberOfPoints=\"35\"", "NumberOfPoints=\"36\""), m, 3, "points"),
        smooth(
            "point-comps.vtp",
            edit(&vtp, "Name=\"Points\" NumberOfComponents=\"3\"", "Name=\"Points\" NumberOfComponents=\"2\""),
            m,
            3,
            "components",
        ),
        smooth("types.vtu", edit(&vtu, "Name=\"types\"", "Name=\"kinds\""), m, 3, "`types`"),
        // tetrahedral meshes are read; their errors name the tetrahedron or the cell
        with_args(
            smooth(
                "tet-corner.vtu",
                edit(&fixture("tets.ascii.vtu"), "4 1 10 0 0 4", "4 1 10 4 0 4"),
                "o.vtu",
                3,
                "tetrahedron 0 = [4, 1, 10, 4]",
            ),
            &["--array", "f"],
        ),
        with_args(
            smooth(
                "hex.vtu",
                edit(&fixture("tets.ascii.vtu"), ">\n          10 10", ">\n          12 10"),
                "o.vtu",
                3,
                "cell 0 is a hexahedron",
            ),
            &["--array", "f"],
        ),
        smooth(
            "short-f.vtu",
            edit(&vtu, "Name=\"f\" format=\"ascii\"", "Name=\"f\" NumberOfComponents=\"2\" format=\"ascii\""),
            m,
            3,
            "`f` holds 35 values, 70 are needed",
        ),
        // the last of f's 35 values dropped
        with_args(
            smooth(
                "short-values.vtu",
                edit(&vtu, " 1.9509410424509204\n", "\n"),
                m,
                3,
                "`f` holds 34 values, 35 are needed",
            ),
            &["--array", "f"],
        ),
        // the compression header of f (inline base64: one block of 32768 bytes, the last of
        // 280, 291 compressed) overwritten to declare blocks of 1 TiB
        smooth(
            "tib-header.vtu",
            edit(&zlib_vtu, &base64(&words(&[1, 32768, 280, 291])), &base64(&words(&[1, 1 << 40, 1 << 40, 291]))),
            m,
            3,
            "`f` holds 1099511627776 bytes",
        ),
        smooth("8-gb.vti", image_declaring_8_gb(), o, 3, "`f` holds 8589934592 bytes"),
    ]
}

fn words(ws: &[u64]) -> Vec<u8> {
    ws.iter().flat_map(|w| w.to_le_bytes()).collect()
}

fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            out.push(if i <= chunk.len() { ABC[((n >> (18 - 6 * i)) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

/// An 8 MB image that declares 8 GiB: 32768 × 32768 Float64 points (a proper 2D extent) in
/// 8192 zlib blocks of 1 MiB of zeros, all present. Read whole it would take 8 GiB; the cap
/// refuses it from the header. The test holds 1 MiB of zeros and the file (8 MB).
fn image_declaring_8_gb() -> Vec<u8> {
    use std::io::Write;
    const BLOCKS: usize = 8192;
    let mut zeros = Vec::new();
    let mut e = flate2::write::ZlibEncoder::new(&mut zeros, flate2::Compression::best());
    e.write_all(&vec![0u8; 1 << 20]).unwrap();
    e.finish().unwrap();
    let mut f = b"<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" \
        header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n<ImageData WholeExtent=\"0 32767 0 32767 0 0\" \
        Origin=\"0 0 0\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 32767 0 32767 0 0\">\n<PointData Scalars=\"f\">\n\
        <DataArray type=\"Float64\" Name=\"f\" format=\"appended\" offset=\"0\"/>\n</PointData>\n</Piece>\n\
        </ImageData>\n<AppendedData encoding=\"raw\">\n_"
        .to_vec();
    f.extend_from_slice(&words(&[BLOCKS as u64, 1 << 20, 1 << 20]));
    f.extend_from_slice(&words(&[zeros.len() as u64; BLOCKS]));
    for _ in 0..BLOCKS {
        f.extend_from_slice(&zeros);
    }
    f.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    f
}

/// An image whose Int64 array holds 2^53 + 1, which no double holds.
fn int64_beyond_2_53() -> Vec<u8> {
    let mut values = vec!["1".to_string(); 35];
    values[7] = "9007199254740993".into();
    format!(
        "<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 6 0 4 0 0\"><Piece><PointData>\
         <DataArray type=\"Int64\" Name=\"n\" format=\"ascii\">{}</DataArray></PointData></Piece></ImageData></VTKFile>",
        values.join(" ")
    )
    .into_bytes()
}

fn legacy_cases() -> Vec<Case> {
    let img = fixture("img.legacy-ascii-v51.vtk");
    let bin = fixture("img.legacy-binary-v51.vtk");
    let poly = fixture("surf.legacy-polydata-ascii-v42.vtk");
    let ugrid = fixture("surf.legacy-ugrid-ascii-v51.vtk");
    let o = "out.vti";
    let m = "out.vtp";
    vec![
        smooth("noheader.vtk", edit(&img, "# vtk DataFile", "# vtx DataFile"), o, 3, "noheader.vtk"),
        smooth("mode.vtk", edit(&img, "ASCII", "EBCDIC"), o, 3, "EBCDIC"),
        smooth("rect.vtk", edit(&img, "STRUCTURED_POINTS", "RECTILINEAR_GRID"), o, 3, "RECTILINEAR_GRID"),
        smooth("dims.vtk", edit(&img, "DIMENSIONS 7 5 1", "DIMENSIONS 7 -5 1"), o, 3, "DIMENSIONS"),
        smooth("pointdata.vtk", edit(&img, "POINT_DATA 35", "POINT_DATA 36"), o, 3, "POINT_DATA 36"),
        smooth("scalars.vtk", edit(&img, "SCALARS f double", "SCALARS f quadruple"), o, 3, "quadruple"),
        smooth("attr.vtk", edit(&img, "VECTORS", "VECTORZ"), o, 3, "VECTORZ"),
        smooth("field.vtk", edit(&img, "label 1 35 int", "label 1 34 int"), o, 3, "34 tuples"),
        smooth("value.vtk", edit(&img, "LOOKUP_TABLE default\n1.1135", "LOOKUP_TABLE default\nx.1135"), o, 3, "line"),
        smooth("cut.vtk", cut(&bin, 0.6), o, 3, "truncated"),
        smooth("polys.vtk", edit(&poly, "POLYGONS 48 192", "POLYGONS 48 191"), m, 3, "POLYGONS"),
        smooth("celltypes.vtk", edit(&ugrid, "CELL_TYPES", "CELL_TYPEZ"), m, 3, "celltypes.vtk"),
        smooth(
            "offsets.vtk",
            edit(&ugrid, "OFFSETS vtktypeint64\n0 ", "OFFSETS vtktypeint64\n1 "),
            m,
            3,
            "first offset",
        ),
        smooth("corner.vtk", edit(&poly, "3 0 1 7", "3 0 1 70"), m, 3, "point 70"),
    ]
}

fn other_reader_cases() -> Vec<Case> {
    let obj = dataset("spot.obj");
    let square = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n".to_vec();
    let m = "out.vtp";
    vec![
        smooth("range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n".to_vec(), m, 3, "out of range"),
        smooth("nan.obj", edit(&square, "v 1 1 0", "v nan 1 0"), m, 3, "nan.obj"),
        smooth("cut.obj", cut(&obj, 0.999), m, 3, "cut.obj"),
        smooth("unused.obj", [&square[..], b"v 5 5 5\n"].concat(), m, 3, "unused.obj"),
        smooth("short.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n".to_vec(), m, 3, "short.off"),
        smooth(
            "noface.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n".to_vec(),
            m,
            3,
            "noface.ply",
        ),
        smooth("x.stl", b"solid x\nendsolid x\n".to_vec(), m, 3, "x.stl"),
        smooth("ragged.csv", b"1,2,3\n4,5\n6,7,8\n".to_vec(), "out.csv", 3, "ragged.csv"),
        smooth("nan-grid.csv", b"1,2,3\n4,nan,6\n7,8,9\n".to_vec(), "out.csv", 3, "nan-grid.csv"),
        smooth("text.csv", b"v\n1\n2\nthree\n4\n".to_vec(), "out.csv", 3, "text.csv"),
        smooth("empty.csv", Vec::new(), "out.csv", 3, "empty.csv"),
        smooth("big.csv", b"v\n1e308\n-1.7e308\n1.5e308\n-1e308\n1.2e308\n".to_vec(), "out.csv", 3, "overflows"),
        smooth("flat.csv", b"v\n2\n2\n2\n2\n".to_vec(), "out.csv", 3, "constant"),
        smooth("cut.npy", cut(&npy_3x3(), 0.8), "out.npy", 3, "cut.npy"),
        smooth("magic.npy", edit(&npy_3x3(), "NUMPY", "NUMPX"), "out.npy", 3, "magic.npy"),
        smooth("cut.png", cut(&dataset("horse_mask.png"), 0.5), "out.npy", 3, "cut.png"),
        smooth("fake.png", b"1,2,3\n4,5,6\n7,8,9\n".to_vec(), "out.npy", 3, "fake.png"),
    ]
}

/// A 3 × 3 float64 .npy file.
fn npy_3x3() -> Vec<u8> {
    let header = "{'descr': '<f8', 'fortran_order': False, 'shape': (3, 3), }";
    let mut h = header.to_string();
    while !(10 + h.len() + 1).is_multiple_of(64) {
        h.push(' ');
    }
    h.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(h.len() as u16).to_le_bytes());
    out.extend_from_slice(h.as_bytes());
    for v in [1.0f64, 5.0, 2.0, 4.0, 0.0, 6.0, 3.0, 7.0, 8.0] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

fn panic_cases() -> Vec<Case> {
    let vti = fixture("img.ascii.vti");
    let mut reader = smooth("panic.vti", vti.clone(), "out.vti", 3, "[reader failure]");
    reader.env = Some(("TOPOSMOOTH_DEBUG_PANIC", "reader"));
    let mut internal = smooth("internal.vti", vti, "out.vti", 1, "[internal failure]");
    internal.env = Some(("TOPOSMOOTH_DEBUG_PANIC", "internal"));
    internal.needle = "[internal failure]";
    vec![reader, internal]
}

/// Files the VTK reader once panicked on ("capacity overflow", with a backtrace, reaching the
/// user): they are read, and no panic text reaches standard error.
fn once_panicked_cases() -> Vec<Case> {
    let read = |file: &'static str, fixture_name: &str| {
        with_args(smooth(file, fixture(fixture_name), "out.vtp", 0, ""), &["--array", "f"])
    };
    vec![
        read("pyvista.vtp", "surf.pyvista-default.vtp"),
        read("empty-sections.vtp", "surf_empty_sections.binary-zlib-u32.vtp"),
        read("empty-sections-appended.vtp", "surf_empty_sections.appended-base64-zlib-u64.vtp"),
        read("inline-zlib.vtp", "surf.binary-zlib-u32.vtp"),
    ]
}

fn run(dir: &Path, case: &Case) -> Result<(), String> {
    let path: PathBuf = dir.join(case.file);
    std::fs::write(&path, &case.bytes).unwrap();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_toposmooth"));
    cmd.current_dir(dir).args(&case.args).env_remove("RUST_BACKTRACE");
    if case.file.ends_with(".vti") || case.file.ends_with(".vtk") {
        cmd.args(["--array", "f"]);
    }
    if let Some((k, v)) = case.env {
        cmd.env(k, v);
    }
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let code = out.status.code().unwrap_or(-1);
    let left: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != case.file)
        .collect();
    std::fs::remove_file(&path).unwrap();
    for f in &left {
        let _ = std::fs::remove_file(dir.join(f));
    }
    if code != case.code {
        return Err(format!("exit {code} instead of {}: {err}", case.code));
    }
    for panic_text in ["panicked", "RUST_BACKTRACE", "backtrace", "thread '"] {
        if err.contains(panic_text) {
            return Err(format!("panic text `{panic_text}` in: {err}"));
        }
    }
    if case.code == 0 {
        return Ok(());
    }
    // an internal failure is not about a file
    let names_file = err.contains(case.file) || case.code == 1;
    if !names_file || !err.contains(case.needle) {
        return Err(format!("the message lacks `{}` or `{}`: {err}", case.file, case.needle));
    }
    // the progress lines of stages that ended before the error (`read: 0.01 s (…)`) may come first
    let progress = |l: &str| {
        l.split_once(": ").is_some_and(|(stage, rest)| {
            ["read", "selection", "complex", "representative", "solve", "certificate", "write", "weights"]
                .contains(&stage)
                && rest.starts_with(|c: char| c.is_ascii_digit())
        })
    };
    if err.trim().lines().filter(|l| !progress(l)).count() != 1 {
        return Err(format!("more than one line: {err}"));
    }
    if !left.is_empty() {
        return Err(format!("left behind: {left:?}"));
    }
    Ok(())
}

#[test]
fn bad_input_gets_one_clear_line_and_leaves_nothing() {
    let dir = common::scratch("bad-input");
    let cases: Vec<Case> =
        [vtk_xml_cases(), legacy_cases(), other_reader_cases(), panic_cases(), once_panicked_cases()]
            .into_iter()
            .flatten()
            .collect();
    let failing = cases.iter().filter(|c| c.code != 0).count();
    assert!(failing >= 60, "{failing} bad-input cases");
    let failures: Vec<String> =
        cases.iter().filter_map(|c| run(&dir, c).err().map(|e| format!("{}: {e}", c.file))).collect();
    assert!(failures.is_empty(), "{} of {} cases fail:\n{}", failures.len(), cases.len(), failures.join("\n"));
}
