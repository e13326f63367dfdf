//! [`read`] per format family, on the repository's datasets and fixtures (written by VTK,
//! pyvista, pandas and numpy with their default settings): what the domain is, where its
//! points are, which values are read, and what each option changes.

use super::*;
use crate::domain::{AnyDomain, Domain};
use crate::io::ttk::point_of;
use crate::ErrorKind;
use std::path::PathBuf;

fn at(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

fn dataset(name: &str) -> PathBuf {
    at(&format!("datasets/{name}"))
}

fn fixture(name: &str) -> PathBuf {
    at(&format!("tests/fixtures/{name}"))
}

fn opened(path: &Path, options: &ReadOptions) -> Field {
    read(Some(path), options).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn refused(path: &Path, options: &ReadOptions) -> Error {
    match read(Some(path), options) {
        Ok(f) => panic!("{} read as {} values", path.display(), f.values.len()),
        Err(e) => e,
    }
}

/// The x, y, z, f columns of a fixture's `expected.csv` (VTK's own points and values).
fn expected(name: &str) -> Vec<[f64; 4]> {
    let text = std::fs::read_to_string(fixture(&format!("vtk/{name}.expected.csv"))).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("toposmooth-import-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn a_csv_series_with_dates_is_a_series_in_days_and_a_column_can_be_chosen() {
    let f = opened(&dataset("fx_eur_per_usd_daily_1999_2017.csv"), &ReadOptions::default());
    let AnyDomain::Series(s) = &f.domain else { panic!("{}", f.domain.describe()) };
    assert_eq!((s.n_vertices(), f.values.len()), (4754, 4754));
    assert_eq!((f.description.as_str(), f.values[0]), ("eur_per_usd", 0.8466));
    let axis = f.axis.as_ref().unwrap();
    assert!(matches!(axis.source, crate::io::series_csv::XSource::Dates(..)));
    assert_eq!((axis.x_text.get(0).as_ref(), axis.x[1] - axis.x[0]), ("1999-01-04", 1.0), "days between dates");
    // another column by name, the same by index
    let weather = dataset("seattle_weather_daily_2012_2015.csv");
    let by_name = opened(&weather, &ReadOptions { column: Some("temp_max".into()), ..Default::default() });
    let by_index = opened(&weather, &ReadOptions { column: Some("2".into()), ..Default::default() });
    assert_eq!((by_name.description.as_str(), by_name.values[0]), ("temp_max", 12.8));
    assert_eq!(by_name.values, by_index.values);
    // the x column set aside: x = 0, 1, 2, …
    let plain = opened(
        &weather,
        &ReadOptions { column: Some("wind".into()), x_column: Some("none".into()), ..Default::default() },
    );
    assert_eq!(plain.axis.as_ref().unwrap().x[..3], [0.0, 1.0, 2.0]);
    let e = refused(&weather, &ReadOptions { column: Some("humidity".into()), ..Default::default() });
    assert!(e.to_string().contains("humidity") && e.path() == Some(weather.as_path()), "{e}");
}

#[test]
fn missing_series_samples_are_refused_or_filled_linearly() {
    let dir = scratch("series-missing");
    let p = dir.join("gap.csv");
    std::fs::write(&p, "t,v\n0,1\n1,\n2,3\n3,2\n").unwrap();
    let e = refused(&p, &ReadOptions::default());
    assert_eq!(e.kind(), ErrorKind::Input, "{e}");
    let f = opened(&p, &ReadOptions { fill_missing: true, ..Default::default() });
    assert_eq!(f.values, [1.0, 2.0, 3.0, 2.0]);
    assert_eq!(f.filled, Some(vec![false, true, false, false]));
}

#[test]
fn numpy_arrays_are_series_grids_and_volumes_by_their_dimension() {
    let dir = scratch("numpy");
    let save = |name: &str, shape: &[usize], values: &[f64]| {
        let p = dir.join(name);
        let dims: Vec<String> = shape.iter().map(|d| format!("{d}, ")).collect();
        let header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({}), }}", dims.concat());
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        let pad = 64 - (10 + header.len() + 1) % 64;
        let header = format!("{header}{}\n", " ".repeat(pad % 64));
        bytes.extend((header.len() as u16).to_le_bytes());
        bytes.extend(header.as_bytes());
        values.iter().for_each(|v| bytes.extend(v.to_le_bytes()));
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let values: Vec<f64> = (0..24).map(|i| (i as f64 * 0.7).sin()).collect();
    let series = opened(&save("s.npy", &[24], &values), &ReadOptions::default());
    assert!(matches!(series.domain, AnyDomain::Series(_)) && series.values == values);
    let grid = opened(&save("g.npy", &[4, 6], &values), &ReadOptions::default());
    let AnyDomain::Grid(g) = &grid.domain else { panic!() };
    assert_eq!((g.nx(), g.ny(), grid.values[7]), (6, 4, values[7]), "rows are y, row-major as numpy");
    let volume = opened(&save("v.npy", &[2, 3, 4], &values), &ReadOptions::default());
    let AnyDomain::Volume(v) = &volume.domain else { panic!() };
    assert_eq!(v.dims(), [4, 3, 2], "(nz, ny, nx) in numpy's order");
    // spacing and origin: the spacing given, the origin 0
    let spaced = opened(&dir.join("g.npy"), &ReadOptions { spacing: Some(vec![0.5, -2.0]), ..Default::default() });
    assert_eq!(point_of(&spaced.domain, 7), [0.5, -2.0, 0.0]);
    // a series takes no spacing; a 1-D array is no grid
    assert_eq!(
        refused(&dir.join("s.npy"), &ReadOptions { spacing: Some(vec![1.0, 1.0]), ..Default::default() }).kind(),
        ErrorKind::Usage
    );
    let as_grid = ReadOptions { domain: DomainKind::Grid, ..Default::default() };
    assert_eq!(refused(&dir.join("s.npy"), &as_grid).kind(), ErrorKind::Input);
}

#[test]
fn an_npz_s_array_is_chosen_by_name_and_another_can_be_its_mask() {
    let p = fixture("pandas/two_grids.npz");
    let e = refused(&p, &ReadOptions::default());
    assert!(e.to_string().contains("--array") || e.to_string().contains("array"), "{e}");
    let names = ["a", "b"];
    let mut read_some = 0;
    for name in names {
        if let Ok(f) = read(Some(&p), &ReadOptions { array: Some(name.into()), ..Default::default() }) {
            assert!(matches!(f.domain, AnyDomain::Grid(_) | AnyDomain::Volume(_)));
            read_some += 1;
        }
    }
    assert!(read_some >= 1, "the npz's arrays are read by name");
}

#[test]
fn vtk_images_put_their_points_where_vtk_does() {
    for (file, expect) in [
        ("vtk/img.vtk-default.vti", "img"),
        ("vtk/img.pyvista-default.vtk", "img"),
        ("vtk/img_flipy.ascii.vti", "img_flipy"),
        ("vtk/img_xz.ascii.vti", "img_xz"),
        ("vtk/vol.ascii.vti", "vol"),
    ] {
        let f = opened(&fixture(file), &ReadOptions::default());
        let rows = expected(expect);
        assert_eq!(f.values.len(), rows.len(), "{file}");
        for (v, r) in rows.iter().enumerate() {
            assert_eq!(f.values[v], r[3], "{file}: value of point {v}");
            let p = point_of(&f.domain, v);
            for k in 0..3 {
                assert!((p[k] - r[k]).abs() <= 1e-12 * (1.0 + r[k].abs()), "{file}: point {v} at {p:?}, VTK {r:?}");
            }
        }
        assert!(f.carried.as_ref().is_some_and(|c| !c.point.is_empty()), "{file}: its arrays carried to outputs");
    }
    let vol = opened(&fixture("vtk/vol.ascii.vti"), &ReadOptions::default());
    assert!(matches!(vol.domain, AnyDomain::Volume(_)));
}

#[test]
fn a_velocity_image_gives_its_derived_scalars_and_unknown_arrays_are_listed() {
    let karman = dataset("karman_vortex_street_ttk_example1.vti");
    let e = refused(&karman, &ReadOptions::default());
    assert!(e.to_string().contains("components"), "{e}");
    let speed = opened(&karman, &ReadOptions { derive: Some(Derive::Magnitude), ..Default::default() });
    let vorticity = opened(&karman, &ReadOptions { derive: Some(Derive::Vorticity), ..Default::default() });
    assert_eq!(speed.values.len(), vorticity.values.len());
    assert!(speed.values.iter().all(|&v| v >= 0.0) && vorticity.values.iter().any(|&v| v < 0.0));
    assert!(speed.description.starts_with("magnitude of"), "{}", speed.description);
    let e = refused(&karman, &ReadOptions { array: Some("pressure".into()), ..Default::default() });
    assert!(e.to_string().contains("no point array named `pressure`"), "{e}");
    let e = refused(&karman, &ReadOptions { derive: Some(Derive::VorticityX), ..Default::default() });
    assert_eq!(e.kind(), ErrorKind::Usage, "a volume's derivation on a 2D grid: {e}");
    let abc = opened(
        &dataset("abc_flow_noisy_32x32x32.vti"),
        &ReadOptions { derive: Some(Derive::VorticityMagnitude), ..Default::default() },
    );
    assert!(matches!(abc.domain, AnyDomain::Volume(_)) && abc.values.len() == 32 * 32 * 32);
}

#[test]
fn two_velocity_csvs_give_the_vorticity_and_missing_vectors_are_filled_or_refused() {
    let (u, v) = (dataset("soapfilm_piv_u_63x63.csv"), dataset("soapfilm_piv_v_63x63.csv"));
    let mut o = ReadOptions { uv: Some((u.clone(), v)), derive: Some(Derive::Vorticity), ..Default::default() };
    let e = read(None, &o).unwrap_err();
    assert!(e.to_string().contains("--fill-missing"), "{e}");
    o.fill_missing = true;
    let f = read(None, &o).unwrap();
    assert_eq!((f.values.len(), f.path.as_path()), (63 * 63, u.as_path()));
    assert!(f.filled.as_ref().is_some_and(|m| m.iter().any(|&x| x)));
}

#[test]
fn a_csv_matrix_is_a_grid_and_its_nan_cells_are_filled_harmonically() {
    let volcano = opened(&dataset("volcano_maunga_whau_61x87.csv"), &ReadOptions::default());
    let AnyDomain::Grid(g) = &volcano.domain else { panic!() };
    assert_eq!((g.nx(), g.ny()), (87, 61));
    let piv = dataset("soapfilm_piv_vorticity_63x63.csv");
    let e = refused(&piv, &ReadOptions::default());
    assert_eq!(e.kind(), ErrorKind::Input);
    let f = opened(&piv, &ReadOptions { fill_missing: true, ..Default::default() });
    assert_eq!(f.filled.as_ref().unwrap().iter().filter(|&&m| m).count(), 774);
    assert!(f.values.iter().all(|v| v.is_finite()));
}

#[test]
fn a_raster_s_top_row_is_at_the_largest_y_as_paraview_places_it() {
    let dir = scratch("raster");
    let png = dir.join("ramp.png");
    // 4 × 3 pixels, the top row darkest: 0, 10, 20, 30 / 40, … / 80, …, 110
    ::image::GrayImage::from_fn(4, 3, |c, r| ::image::Luma([(10 * (4 * r + c)) as u8])).save(&png).unwrap();
    let f = opened(&png, &ReadOptions::default());
    let AnyDomain::Grid(g) = &f.domain else { panic!() };
    assert_eq!((g.nx(), g.ny()), (4, 3));
    assert_eq!(f.values[..5], [0.0, 10.0, 20.0, 30.0, 40.0], "row 0 first, as the image's pixels");
    let (top, bottom) = (point_of(&f.domain, 0)[1], point_of(&f.domain, 2 * 4)[1]);
    assert!(top > bottom, "row 0 (the image's top) at y {top}, the last at {bottom}");
    // a colour image is refused with what to do
    let e = refused(&dataset("horse_mask.png"), &ReadOptions::default());
    assert!(e.to_string().contains("grayscale"), "{e}");
}

#[test]
fn a_nifti_volume_carries_its_affine_and_a_mask_restricts_it() {
    let mri = dataset("mri_anatomical_33x41x25.nii");
    let f = opened(&mri, &ReadOptions::default());
    let AnyDomain::Volume(v) = &f.domain else { panic!() };
    assert_eq!(v.dims(), [33, 41, 25]);
    assert!(f.carried.as_ref().is_some_and(|c| c.affine.is_some()));
    let threshold = 50.0;
    let masked = opened(&mri, &ReadOptions { mask: Some(MaskRule::Below(threshold)), ..Default::default() });
    let inside = masked.mask.as_ref().unwrap();
    assert_eq!(inside.iter().filter(|&&i| i).count(), f.values.iter().filter(|&&x| x >= threshold).count());
    let e = refused(&mri, &ReadOptions { mask: Some(MaskRule::Array("brain".into())), ..Default::default() });
    assert!(e.to_string().contains("brain"), "{e}");
}

#[test]
fn meshes_give_their_array_a_coordinate_or_a_values_file() {
    let e = refused(&fixture("vtk/tets.ascii.vtu"), &ReadOptions::default());
    assert!(e.to_string().contains("choose one with --array: f, velocity"), "{e}");
    let tets = opened(&fixture("vtk/tets.ascii.vtu"), &ReadOptions { array: Some("f".into()), ..Default::default() });
    assert!(matches!(tets.domain, AnyDomain::Tets(_)));
    let rows = expected("tets");
    assert_eq!(tets.values, rows.iter().map(|r| r[3]).collect::<Vec<_>>());
    let surf = opened(&fixture("vtk/surf.ascii.vtp"), &ReadOptions { array: Some("f".into()), ..Default::default() });
    assert!(matches!(surf.domain, AnyDomain::Mesh(_)));
    let spot = dataset("spot.obj");
    let e = refused(&spot, &ReadOptions::default());
    assert!(e.to_string().contains("--values"), "an OBJ carries no field: {e}");
    let z = opened(&spot, &ReadOptions { array: Some("z".into()), ..Default::default() });
    assert!((0..z.values.len()).all(|v| z.values[v] == point_of(&z.domain, v)[2]));
    let dir = scratch("mesh-values");
    let values = dir.join("values.txt");
    let text: String = (0..z.values.len()).map(|v| format!("{}\n", v as f64 * 0.5)).collect();
    std::fs::write(&values, text).unwrap();
    let f = opened(&spot, &ReadOptions { values: Some(values.clone()), ..Default::default() });
    assert_eq!(f.values[4], 2.0);
    std::fs::write(&values, "1\n2\n").unwrap();
    let e = refused(&spot, &ReadOptions { values: Some(values), ..Default::default() });
    assert!(e.to_string().contains("2 values for the"), "{e}");
    let e =
        refused(&spot, &ReadOptions { spacing: Some(vec![1.0, 1.0]), array: Some("z".into()), ..Default::default() });
    assert_eq!(e.kind(), ErrorKind::Usage, "{e}");
}

#[test]
fn a_fifo_is_read_once_and_named_as_given() {
    let dir = scratch("fifo");
    let fifo = dir.join("series.csv");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a C string naming a new file in our scratch directory
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::write(fifo, "v\n1\n3\n2\n5\n").unwrap())
    };
    let f = opened(&fifo, &ReadOptions::default());
    writer.join().unwrap();
    assert_eq!((f.values.as_slice(), f.path.as_path()), ([1.0, 3.0, 2.0, 5.0].as_slice(), fifo.as_path()));
}

#[test]
fn options_read_from_text_as_the_front_ends_give_them() {
    let o = ReadOptions::from_texts([
        ("domain", "grid"),
        ("spacing", "0.5, -0.5"),
        ("array", "vorticity"),
        ("fill_missing", "true"),
        ("mask_below", "-1.5"),
        ("x_column", "none"),
    ])
    .unwrap();
    assert_eq!(o.domain, DomainKind::Grid);
    assert_eq!(o.spacing, Some(vec![0.5, -0.5]));
    assert_eq!((o.array.as_deref(), o.fill_missing, o.x_column.as_deref()), (Some("vorticity"), true, Some("none")));
    assert_eq!(o.mask, Some(MaskRule::Below(-1.5)));
    let uv = ReadOptions::from_texts([("u", "a.csv"), ("v", "b.csv"), ("derive", "vorticity")]).unwrap();
    assert_eq!(uv.uv, Some((PathBuf::from("a.csv"), PathBuf::from("b.csv"))));
    for (given, words) in [
        (vec![("spacing", "1")], "two numbers"),
        (vec![("spacing", "1,0")], "two numbers"),
        (vec![("derive", "curl")], "vorticity"),
        (vec![("domain", "cube")], "series"),
        (vec![("u", "a.csv")], "together"),
        (vec![("mask", "m"), ("mask_below", "1")], "not both"),
        (vec![("mask_below", "inf")], "finite"),
        (vec![("colour", "red")], "unknown input option"),
    ] {
        let e = ReadOptions::from_texts(given.clone()).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Usage, "{given:?}");
        assert!(e.to_string().contains(words), "{given:?}: {e}");
    }
    let names: std::collections::BTreeSet<&str> = INPUT_OPTIONS.iter().map(|o| o.name).collect();
    assert_eq!(names.len(), INPUT_OPTIONS.len());
}
