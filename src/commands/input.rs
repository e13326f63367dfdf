//! Reading the field a command works on: a series (CSV) or a grid (.vti, legacy .vtk, .npy,
//! CSV matrix, PNG, TIFF, or two velocity components), with the grid options `--array`,
//! `--spacing`, `--derive` and `--fill-missing` applied.

use crate::derive::{describe_missing, fill_missing, fill_missing_with, magnitude, vorticity};
use crate::domain::{Grid2d, Grid3d};
use crate::error::{Error, Result};
use crate::io::export::Carried;
use crate::io::grid::{raster_grid, read_grid_csv, read_raster, GridField};
use crate::io::mesh::is_mesh_file;
pub use crate::io::mesh::read_trimesh;
use crate::io::mesh::AnyMesh;
use crate::io::npy_input::{is_numpy, read_numpy, NumpyField, Wanted};
use crate::io::series_csv::{read_series, SeriesCsv, SeriesCsvOptions};
use crate::io::vtk::{read_any_image, AnyImage};
use crate::series_fill::fill_missing_series;
use std::path::{Path, PathBuf};

/// What kind of domain a file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum DomainKind {
    /// Decide from the extension; a CSV is a grid when its first line is three or more
    /// numbers (a matrix without header), else a series.
    #[default]
    Auto,
    /// A series (CSV).
    Series,
    /// A grid.
    Grid,
    /// A triangle mesh (.obj, .off, .ply, .vtu, .vtp).
    Mesh,
}

/// A scalar to derive from a velocity field.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Derive {
    /// ω = ∂v/∂x − ∂u/∂y (2D grids).
    Vorticity,
    /// |(u, v)| or |(u, v, w)|.
    Magnitude,
    /// |∇ × (u, v, w)| (volumes).
    #[serde(rename = "vorticity-magnitude")]
    #[cfg_attr(feature = "cli", value(name = "vorticity-magnitude"))]
    VorticityMagnitude,
    /// (∇ × (u, v, w))ₓ = ∂w/∂y − ∂v/∂z (volumes).
    #[serde(rename = "vorticity-x")]
    #[cfg_attr(feature = "cli", value(name = "vorticity-x"))]
    VorticityX,
    /// (∇ × (u, v, w))_y = ∂u/∂z − ∂w/∂x (volumes).
    #[serde(rename = "vorticity-y")]
    #[cfg_attr(feature = "cli", value(name = "vorticity-y"))]
    VorticityY,
    /// (∇ × (u, v, w))_z = ∂v/∂x − ∂u/∂y (volumes).
    #[serde(rename = "vorticity-z")]
    #[cfg_attr(feature = "cli", value(name = "vorticity-z"))]
    VorticityZ,
}

impl Derive {
    /// The derivation's name as the command line spells it.
    pub fn name(self) -> &'static str {
        match self {
            Derive::Vorticity => "vorticity",
            Derive::Magnitude => "magnitude",
            Derive::VorticityMagnitude => "vorticity-magnitude",
            Derive::VorticityX => "vorticity-x",
            Derive::VorticityY => "vorticity-y",
            Derive::VorticityZ => "vorticity-z",
        }
    }
}

/// How to read a grid.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GridOptions {
    /// Point array to read from a VTK file (default: the only scalar array, or with
    /// `derive` the only vector array).
    pub array: Option<String>,
    /// Spacing `(dx, dy)` or, for a volume, `(dx, dy, dz)`, overriding the file's.
    pub spacing: Option<Vec<f64>>,
    /// Derive a scalar from a velocity field.
    pub derive: Option<Derive>,
    /// Velocity components from two grid files (with `derive`).
    pub uv: Option<(PathBuf, PathBuf)>,
    /// Fill NaN samples harmonically instead of refusing them.
    pub fill_missing: bool,
    /// Meshes: one value per vertex from a text file (one per line) instead of an array.
    pub values: Option<PathBuf>,
    /// Volumes: smooth only the voxels inside this mask.
    pub mask: Option<MaskRule>,
}

/// Which voxels a mask holds inside.
#[derive(Clone, Debug, PartialEq)]
pub enum MaskRule {
    /// Those where this array of the input file is non-zero (`--mask ARRAY`).
    Array(String),
    /// Those whose value is at least this (`--mask-below V`: below it is outside; NaN is
    /// outside).
    Below(f64),
}

/// A field on an image grid, ready to smooth: a 2D grid ([`GridInput`]) or a volume
/// ([`VolumeInput`]).
#[derive(Clone, Debug)]
pub struct ImageInput<G> {
    /// The grid with its spacing and origin.
    pub grid: G,
    /// The values to smooth (after deriving and filling).
    pub values: Vec<f64>,
    /// What the values are: the array read or the derivation.
    pub description: String,
    /// Samples filled by `--fill-missing` (true), when any were.
    pub filled: Option<Vec<bool>>,
    /// The file the grid came from (the first velocity file with `--u/--v`).
    pub path: PathBuf,
    /// A VTK image's arrays (or a NIfTI file's affine), for outputs that carry them through.
    pub carried: Option<Carried>,
    /// What reading found worth saying (an oblique NIfTI affine).
    pub notes: Vec<String>,
    /// The pixels or voxels inside `--mask` / `--mask-below`, when given.
    pub mask: Option<Vec<bool>>,
}

/// A 2D grid field ready to smooth.
pub type GridInput = ImageInput<Grid2d>;

/// A volume field ready to smooth.
pub type VolumeInput = ImageInput<Grid3d>;

/// A field on a triangle mesh, ready to smooth.
#[derive(Clone, Debug)]
pub struct MeshInput {
    /// The validated mesh (orientation repaired where needed): triangles, or tetrahedra.
    pub mesh: crate::io::mesh::AnyMesh,
    /// The values to smooth.
    pub values: Vec<f64>,
    /// What the values are: the array read, the coordinate or the values file.
    pub description: String,
    /// What reading and validation changed (polygons split, triangles flipped).
    pub notes: Vec<String>,
    /// Vertices filled by `--fill-missing` (true), when any were.
    pub filled: Option<Vec<bool>>,
    /// The mesh file.
    pub path: PathBuf,
    /// A mesh file's arrays and cells, for VTK outputs that carry them through.
    pub carried: Option<Carried>,
}

/// A series ready to smooth.
#[derive(Clone, Debug)]
pub struct SeriesInput {
    /// The series as read, its missing values filled (`--fill-missing`).
    pub data: SeriesCsv,
    /// Samples filled by `--fill-missing` (true), when any were.
    pub filled: Option<Vec<bool>>,
}

/// A field read by a command.
#[derive(Clone, Debug)]
pub enum FieldInput {
    /// A series.
    Series(SeriesInput),
    /// A grid.
    Grid(GridInput),
    /// A field on a triangle mesh.
    Mesh(MeshInput),
    /// A volume.
    Volume(VolumeInput),
}

/// Reads the field on a mesh: `--values FILE`, `--array NAME` (a vertex array or the
/// coordinate `x`, `y`, `z`), or the file's only scalar vertex array.
///
/// # Errors
/// Input errors naming the file: unreadable or invalid mesh, no or several candidate
/// arrays, a values file of the wrong length, non-finite values.
pub fn read_mesh_field(path: &Path, opts: &GridOptions) -> Result<MeshInput> {
    if opts.derive.is_some() || opts.uv.is_some() || opts.spacing.is_some() {
        return Err(Error::Usage(format!("{}: --derive, --u/--v and --spacing are for grids", path.display())));
    }
    let (mesh, data) = crate::io::mesh::read_any_mesh(path)?;
    let n = data.positions.len();
    let (mut values, description, source): (Vec<f64>, String, PathBuf) = match (&opts.values, &opts.array) {
        (Some(_), Some(_)) => return Err(Error::Usage("give --values or --array, not both".into())),
        (Some(file), None) => {
            let text = std::fs::read_to_string(file).map_err(|source| Error::Io { path: file.clone(), source })?;
            let mut values = Vec::with_capacity(n);
            for (l, line) in text.lines().enumerate() {
                let t = line.trim();
                if t.is_empty() || t.starts_with('#') {
                    continue;
                }
                let v: f64 = t.parse().map_err(|_| {
                    Error::input(format!("line {}: `{t}` is not a number", l + 1))
                        .at(crate::error::Location::Line(l + 1))
                        .in_file(file)
                })?;
                values.push(v);
            }
            if values.len() != n {
                return Err(Error::input(format!(
                    "{} values for the {n} vertices of {}",
                    values.len(),
                    path.display()
                ))
                .in_file(file));
            }
            (values, format!("values from {}", file.display()), file.clone())
        }
        (None, Some(name)) => {
            let a = data.array(name).map_err(|e| e.in_file(path))?;
            if a.components != 1 {
                return Err(Error::input(format!(
                    "array `{name}` has {} components; a scalar is needed",
                    a.components
                ))
                .in_file(path));
            }
            (a.values, name.clone(), path.to_path_buf())
        }
        (None, None) => {
            let scalars: Vec<&crate::io::vtk::PointArray> = data.arrays.iter().filter(|a| a.components == 1).collect();
            match scalars.as_slice() {
                [one] => (one.values.clone(), one.name.clone(), path.to_path_buf()),
                [] => {
                    return Err(Error::input(
                        "the mesh carries no scalar vertex array: give the field with --values FILE or --array x|y|z",
                    )
                    .in_file(path))
                }
                _ => {
                    return Err(Error::Usage(format!(
                        "{}: several vertex arrays fit, choose one with --array: {}",
                        path.display(),
                        data.names().join(", ")
                    )))
                }
            }
        }
    };
    let bad: Vec<usize> = (0..n).filter(|&v| !values[v].is_finite()).collect();
    let infinite = bad.iter().any(|&v| values[v].is_infinite());
    let mut filled = None;
    if !bad.is_empty() {
        if opts.fill_missing && !infinite {
            let k = match &mesh {
                AnyMesh::Tri(m) => crate::operators::positive_cotan_stiffness(m.positions(), m.faces()),
                AnyMesh::Tet(m) => crate::operators::positive_tet_stiffness(m.positions(), m.tets()),
            };
            crate::derive::fill_missing_with(&k, &mut values).map_err(|e| e.in_file(&source))?;
            let mut mask = vec![false; n];
            bad.iter().for_each(|&v| mask[v] = true);
            filled = Some(mask);
        } else {
            let shown: Vec<String> = bad.iter().take(5).map(|v| v.to_string()).collect();
            return Err(Error::input(format!(
                "{} non-finite values (first at vertices {}){}",
                bad.len(),
                shown.join(", "),
                if infinite { "" } else { "; --fill-missing fills NaN harmonically" }
            ))
            .in_file(&source));
        }
    }
    let mut notes = data.notes.clone();
    notes.extend(mesh.repairs().iter().cloned());
    if let AnyMesh::Tri(m) = &mesh {
        notes.extend(m.sliver_warning());
    }
    // the field is the array of that name unless it came from a values file or a coordinate
    let source =
        (opts.values.is_none() && data.arrays.iter().any(|a| a.name == description)).then(|| description.clone());
    let carried = Some(Carried { point: data.arrays, cells: data.cells, cell: data.cell_arrays, source, affine: None });
    Ok(MeshInput { mesh, values, description, notes, filled, path: path.to_path_buf(), carried })
}

fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Whether a grid file is a raster image (PNG, TIFF): its row 0 is the image's top row, placed
/// at the largest y as ParaView places it ([`raster_grid`]).
pub fn is_raster(path: &Path) -> bool {
    matches!(extension(path).as_str(), "png" | "tif" | "tiff")
}

/// Whether a file is read as a grid.
pub fn is_grid_file(path: &Path, kind: DomainKind) -> Result<bool> {
    Ok(match kind {
        DomainKind::Series | DomainKind::Mesh => false,
        DomainKind::Grid => true,
        DomainKind::Auto => match extension(path).as_str() {
            "vti" | "vtk" | "npy" | "npz" | "png" | "tif" | "tiff" | "nii" => true,
            _ if crate::io::export::is_nifti(path) => true,
            _ => {
                let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.into(), source })?;
                crate::io::content::expect_text(path, &bytes, "CSV text")?;
                let text = String::from_utf8_lossy(&bytes);
                let text = text.trim_start_matches('\u{feff}');
                let dialect = crate::io::csv_dialect::sniff(text);
                let first = text.lines().map(str::trim).find(|l| !l.is_empty()).unwrap_or("");
                let cells: Vec<&str> = first.split(char::from(dialect.delimiter)).collect();
                cells.len() >= 3 && cells.iter().all(|c| dialect.number(c).is_some())
            }
        },
    })
}

/// An input that can be read only once (`-` for the standard input, a FIFO, a character
/// device), read once into a temporary file that the readers (which sniff, then read) open
/// as often as they need; removed when dropped.
struct ReadOnce {
    tmp: PathBuf,
    original: PathBuf,
}

impl Drop for ReadOnce {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.tmp);
    }
}

impl ReadOnce {
    /// Copies `path` when it is `-`, a FIFO or a character device; `None` for a file.
    fn of(path: &Path) -> Result<Option<ReadOnce>> {
        use std::io::Read;
        use std::os::unix::fs::FileTypeExt;
        let stdin = path.as_os_str() == "-";
        if !stdin {
            match std::fs::metadata(path) {
                Ok(m) if m.file_type().is_fifo() || m.file_type().is_char_device() => {}
                _ => return Ok(None),
            }
        }
        let io = |source| Error::Io { path: path.to_path_buf(), source };
        let mut bytes = Vec::new();
        if stdin {
            std::io::stdin().lock().read_to_end(&mut bytes).map_err(io)?;
        } else {
            std::fs::File::open(path).and_then(|mut f| f.read_to_end(&mut bytes)).map_err(io)?;
        }
        // the name's extension, else the content's: NPY by its magic, CSV otherwise
        let ext = match path.extension().and_then(|e| e.to_str()) {
            Some(e) if !e.is_empty() => e.to_string(),
            _ if bytes.starts_with(b"\x93NUMPY") => "npy".into(),
            _ => "csv".into(),
        };
        let nonce: u64 =
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64);
        let tmp = std::env::temp_dir().join(format!("toposmooth-input-{}-{nonce:x}.{ext}", std::process::id()));
        let write = std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp);
        write
            .and_then(|mut f| std::io::Write::write_all(&mut f, &bytes))
            .map_err(|source| Error::Io { path: tmp.clone(), source })?;
        Ok(Some(ReadOnce { tmp, original: path.to_path_buf() }))
    }

    /// What a message calls the input.
    fn name(&self) -> PathBuf {
        if self.original.as_os_str() == "-" {
            PathBuf::from("standard input")
        } else {
            self.original.clone()
        }
    }
}

/// Reads the field of a command: a series or a grid, by [`is_grid_file`]. `-` reads the
/// standard input (CSV or NPY); a FIFO is read once.
///
/// # Errors
/// As the readers, naming the input as given.
pub fn read_field(
    path: Option<&Path>,
    kind: DomainKind,
    csv: &SeriesCsvOptions,
    grid: &GridOptions,
) -> Result<FieldInput> {
    let once = path.map(ReadOnce::of).transpose()?.flatten();
    let Some(once) = once else {
        return read_field_from(path, kind, csv, grid);
    };
    let name = once.name();
    match read_field_from(Some(&once.tmp), kind, csv, grid) {
        Ok(FieldInput::Grid(g)) => Ok(FieldInput::Grid(GridInput { path: name, ..g })),
        Ok(FieldInput::Mesh(m)) => Ok(FieldInput::Mesh(MeshInput { path: name, ..m })),
        Ok(FieldInput::Volume(v)) => Ok(FieldInput::Volume(VolumeInput { path: name, ..v })),
        Ok(series) => Ok(series),
        Err(e) => Err(e.renamed(&once.tmp, &name)),
    }
}

fn read_field_from(
    path: Option<&Path>,
    kind: DomainKind,
    csv: &SeriesCsvOptions,
    grid: &GridOptions,
) -> Result<FieldInput> {
    let grid_wanted = grid.uv.is_some() || grid.derive.is_some() || grid.array.is_some();
    if let Some(p) = path {
        crate::io::content::check_extension(p)?;
        let mesh = match kind {
            DomainKind::Mesh => true,
            DomainKind::Auto => is_mesh_file(p),
            _ => false,
        };
        if mesh {
            return Ok(FieldInput::Mesh(read_mesh_field(p, grid)?));
        }
    }
    if let Some(v) = &grid.values {
        return Err(Error::Usage(format!("--values {} is for meshes", v.display())));
    }
    if let Some(p) = path.filter(|p| is_numpy(p) && kind != DomainKind::Grid) {
        if grid.derive.is_none() && grid.uv.is_none() {
            if let Some(series) = numpy_series(p, kind, csv, grid)? {
                return Ok(FieldInput::Series(series));
            }
        }
    }
    match path {
        Some(p) if !is_grid_file(p, kind)? => {
            if grid_wanted || grid.spacing.is_some() {
                return Err(Error::Usage(format!(
                    "{} is read as a series; --array, --spacing, --derive and --u/--v are for grids (use --domain grid for a CSV matrix)",
                    p.display()
                )));
            }
            read_series_input(p, csv, grid.fill_missing).map(FieldInput::Series)
        }
        Some(p) if grid.uv.is_some() => {
            Err(Error::Usage(format!("give either an input file ({}) or --u and --v, not both", p.display())))
        }
        Some(p) => read_grid(p, grid),
        None => match &grid.uv {
            Some(_) => read_grid(Path::new(""), grid),
            None => Err(Error::Usage("no input file".into())),
        },
    }
}

/// Reads a series from CSV; with `fill_missing` its missing values (empty cells, NaN) are
/// filled linearly in x ([`fill_missing_series`]) instead of refused.
///
/// # Errors
/// As [`read_series`]; every value missing.
pub fn read_series_input(path: &Path, csv: &SeriesCsvOptions, fill_missing: bool) -> Result<SeriesInput> {
    let options = SeriesCsvOptions { allow_missing: fill_missing, ..csv.clone() };
    let mut data = read_series(path, &options)?;
    let mut filled = None;
    if data.values.iter().any(|v| v.is_nan()) {
        let mask = fill_missing_series(&data.x, &mut data.values).map_err(|e| e.in_file(path))?;
        filled = Some(mask);
    }
    Ok(SeriesInput { data, filled })
}

/// A NumPy file's 1-D array as a series (x = 0, 1, 2, …), filled with `--fill-missing`; `None`
/// when the file's array is a grid (and `kind` allows one).
fn numpy_series(
    path: &Path,
    kind: DomainKind,
    csv: &SeriesCsvOptions,
    grid: &GridOptions,
) -> Result<Option<SeriesInput>> {
    let wanted = if kind == DomainKind::Series { Wanted::Series } else { Wanted::Any };
    let NumpyField::Series { name, mut values } = read_numpy(path, grid.array.as_deref(), wanted)? else {
        return Ok(None);
    };
    if csv.column.is_some() || csv.x_column.is_some() || grid.spacing.is_some() {
        return Err(Error::Usage(format!(
            "{}: a NumPy series is its array, on x = 0, 1, 2, …: --column, --x and --spacing do not apply (choose the array with --array)",
            path.display()
        )));
    }
    let n = values.len();
    let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let mut filled = None;
    if let Some(i) = values.iter().position(|v| v.is_nan()) {
        if !grid.fill_missing {
            let count = values.iter().filter(|v| v.is_nan()).count();
            return Err(Error::input(format!(
                "array `{name}`: {count} missing (NaN) values, the first at index {i}; --fill-missing fills them linearly"
            ))
            .in_file(path));
        }
        filled = Some(fill_missing_series(&x, &mut values).map_err(|e| e.in_file(path))?);
    }
    let data = SeriesCsv {
        column: name,
        values,
        x_text: (0..n).map(|i| i.to_string()).collect(),
        x,
        x_name: "x".into(),
        x_source: crate::io::series_csv::XSource::Index,
    };
    Ok(Some(SeriesInput { data, filled }))
}

/// The points of an image as read: a 2D grid or a volume.
#[derive(Clone, Debug, PartialEq)]
enum Geometry {
    Flat(Grid2d),
    Volume(Grid3d),
}

impl Geometry {
    fn dims_text(&self) -> String {
        match self {
            Geometry::Flat(g) => format!("{} × {}", g.nx(), g.ny()),
            Geometry::Volume(g) => format!("{} × {} × {}", g.nx(), g.ny(), g.nz()),
        }
    }
    fn dims(&self) -> Vec<usize> {
        match self {
            Geometry::Flat(g) => vec![g.nx(), g.ny()],
            Geometry::Volume(g) => g.dims().to_vec(),
        }
    }
}

/// One array of a raw read: name, components, values.
struct Raw {
    geometry: Geometry,
    arrays: Vec<(String, usize, Vec<f64>)>,
    /// Arrays of the file that are not numeric: "`name` (type)".
    skipped: Vec<String>,
    /// The array a VTK file marks as its active scalars.
    active: Option<String>,
    /// A VTK image's arrays as read.
    carried: Option<Carried>,
    /// What reading found worth saying (an oblique affine).
    notes: Vec<String>,
}

fn read_raw(path: &Path, array: Option<&str>) -> Result<Raw> {
    let from_field = |f: GridField| Raw {
        arrays: vec![(f.array, 1, f.values)],
        geometry: Geometry::Flat(f.grid),
        skipped: Vec::new(),
        active: None,
        carried: None,
        notes: Vec::new(),
    };
    crate::io::content::check_extension(path)?;
    if crate::io::export::is_nifti(path) {
        return read_nifti_raw(path);
    }
    match extension(path).as_str() {
        "vti" | "vtk" => {
            let (geometry, arrays, cell, skipped, active, notes) = match read_any_image(path)? {
                AnyImage::Flat(img) => {
                    let grid = img.grid().map_err(|e| e.in_file(path))?;
                    (Geometry::Flat(grid), img.arrays, img.cell_arrays, img.skipped, img.active_scalars, img.notes)
                }
                AnyImage::Volume(v) => {
                    let grid = Grid3d::with_geometry(v.dims, v.spacing, v.origin).map_err(|e| e.in_file(path))?;
                    (Geometry::Volume(grid), v.arrays, v.cell_arrays, v.skipped, v.active_scalars, v.notes)
                }
            };
            let listed = arrays.iter().map(|a| (a.name.clone(), a.components, a.values.clone())).collect();
            let carried = Carried { point: arrays, cells: None, cell, source: None, affine: None };
            Ok(Raw { geometry, arrays: listed, skipped, active, carried: Some(carried), notes })
        }
        "npy" | "npz" => match read_numpy(path, array, Wanted::Grid)? {
            NumpyField::Grid(f) => Ok(from_field(f)),
            NumpyField::Volume { name, grid, values } => Ok(Raw {
                arrays: vec![(name, 1, values)],
                geometry: Geometry::Volume(grid),
                skipped: Vec::new(),
                active: None,
                carried: None,
                notes: Vec::new(),
            }),
            NumpyField::Series { name, .. } => {
                Err(Error::input(format!("array `{name}` is 1-D: a series, not a grid")).in_file(path))
            }
        },
        "png" | "tif" | "tiff" => read_raster(path).map(from_field),
        _ => read_grid_csv(path).map(from_field),
    }
}

/// A NIfTI volume: |pixdim| as spacing, the affine's translation as origin, the affine
/// itself carried to NIfTI outputs; one axis of extent 1 makes a 2D grid over the others.
#[cfg(feature = "io-nifti")]
fn read_nifti_raw(path: &Path) -> Result<Raw> {
    let v = crate::io::nifti::read_nifti(path)?;
    let mut notes = Vec::new();
    if v.oblique {
        notes.push(format!(
            "the {} affine is oblique: the volume is smoothed on its voxel grid (spacing |pixdim|, origin the \
             affine's translation); NIfTI outputs carry the affine, VTK outputs are axis-aligned",
            v.affine_source
        ));
    }
    let origin = v.origin();
    let name = "values".to_string();
    let flat: Vec<usize> = (0..3).filter(|&a| v.dims[a] > 1).collect();
    let geometry = match flat.as_slice() {
        [_, _, _] => Geometry::Volume(Grid3d::with_geometry(v.dims, v.spacing, origin).map_err(|e| e.in_file(path))?),
        &[a, b] => Geometry::Flat(
            Grid2d::with_geometry(v.dims[a], v.dims[b], [v.spacing[a], v.spacing[b]], [origin[a], origin[b]])
                .and_then(|g| g.in_plane(crate::domain::Plane { axes: [a, b], level: origin[3 - a - b] }))
                .map_err(|e| e.in_file(path))?,
        ),
        _ => {
            return Err(Error::input(format!(
                "the volume is {} × {} × {}: a grid needs at least two axes of 2 or more voxels",
                v.dims[0], v.dims[1], v.dims[2]
            ))
            .in_file(path))
        }
    };
    let carried = Carried { affine: Some(v.affine), source: Some(name.clone()), ..Carried::default() };
    Ok(Raw {
        geometry,
        arrays: vec![(name, 1, v.values)],
        skipped: Vec::new(),
        active: None,
        carried: Some(carried),
        notes,
    })
}

#[cfg(not(feature = "io-nifti"))]
fn read_nifti_raw(path: &Path) -> Result<Raw> {
    Err(Error::input("reading NIfTI files needs the io-nifti feature").in_file(path))
}

/// The geometry with `--spacing` applied: the file's origin kept, except for a raster, whose
/// spacing is its pixel size with the top row kept at the top ([`raster_grid`]).
fn with_spacing(path: &Path, geometry: &Geometry, spacing: Option<&[f64]>) -> Result<Geometry> {
    let Some(s) = spacing else {
        return Ok(geometry.clone());
    };
    match (geometry, s) {
        (Geometry::Flat(grid), &[dx, dy]) if is_raster(path) => {
            raster_grid(grid.nx(), grid.ny(), [dx, dy]).map(Geometry::Flat).map_err(|e| e.in_file(path))
        }
        (Geometry::Flat(grid), &[dx, dy]) => Grid2d::with_geometry(grid.nx(), grid.ny(), [dx, dy], grid.origin())
            .and_then(|g| g.in_plane(grid.plane()))
            .map(Geometry::Flat)
            .map_err(|e| e.in_file(path)),
        (Geometry::Volume(grid), &[dx, dy, dz]) => Grid3d::with_geometry(grid.dims(), [dx, dy, dz], grid.origin())
            .map(Geometry::Volume)
            .map_err(|e| e.in_file(path)),
        (Geometry::Flat(_), _) => Err(Error::Usage(format!(
            "{}: --spacing takes two numbers dx,dy for a 2D grid, got {}",
            path.display(),
            s.len()
        ))),
        (Geometry::Volume(_), _) => Err(Error::Usage(format!(
            "{}: --spacing takes three numbers dx,dy,dz for a volume, got {}",
            path.display(),
            s.len()
        ))),
    }
}

fn pick<'a>(path: &Path, raw: &'a Raw, name: Option<&str>, vector: bool) -> Result<&'a (String, usize, Vec<f64>)> {
    let listing = || {
        raw.arrays
            .iter()
            .map(|(n, c, _)| format!("`{n}` ({c} component{})", if *c == 1 { "" } else { "s" }))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(name) = name {
        return raw.arrays.iter().find(|(n, _, _)| n == name).ok_or_else(|| {
            let quoted = format!("`{name}` (");
            match raw.skipped.iter().find(|s| s.starts_with(&quoted)) {
                Some(s) => Error::input(format!("point array {s} does not hold numbers")),
                None => Error::input(format!("no point array named `{name}`; the file has {}", listing())),
            }
            .in_file(path)
        });
    }
    let fits: Vec<&(String, usize, Vec<f64>)> =
        raw.arrays.iter().filter(|(_, c, _)| if vector { *c == 2 || *c == 3 } else { *c == 1 }).collect();
    // as a VTK filter does: the active scalars when they fit
    if let Some(active) = raw.active.as_deref().and_then(|a| fits.iter().find(|(n, _, _)| n == a)) {
        if !vector {
            return Ok(active);
        }
    }
    match fits.as_slice() {
        [one] => Ok(one),
        [] => Err(Error::input(format!(
            "no {} point array; the file has {}",
            if vector { "vector (2 or 3 components)" } else { "scalar" },
            if raw.arrays.is_empty() { "none".to_string() } else { listing() }
        ))
        .in_file(path)),
        _ => {
            Err(Error::Usage(format!("{}: several arrays fit, choose one with --array: {}", path.display(), listing())))
        }
    }
}

/// Reads a grid or a volume with its options applied: array choice, spacing, derivation,
/// NaN policy.
///
/// # Errors
/// Input errors naming the file (unreadable, missing array, different grid sizes of `--u`
/// and `--v`, NaN without `--fill-missing`, a derivation the domain has not), usage errors
/// for contradictory options.
pub fn read_grid(path: &Path, opts: &GridOptions) -> Result<FieldInput> {
    let mut carried = None;
    let mut notes = Vec::new();
    let spacing = opts.spacing.as_deref();
    let (geometry, mut values, description, source) = match (&opts.uv, opts.derive) {
        (Some(_), None) => return Err(Error::Usage("--u and --v need --derive vorticity|magnitude".into())),
        (Some((pu, pv)), Some(d)) => {
            let (ru, rv) = (read_raw(pu, opts.array.as_deref())?, read_raw(pv, opts.array.as_deref())?);
            if ru.geometry.dims() != rv.geometry.dims() {
                return Err(Error::input(format!(
                    "{} is {} but {} is {}",
                    pu.display(),
                    ru.geometry.dims_text(),
                    pv.display(),
                    rv.geometry.dims_text()
                )));
            }
            if let Geometry::Volume(_) = ru.geometry {
                return Err(Error::Usage(format!(
                    "{}: --u and --v give a 2D velocity; a volume's velocity is one 3-component array",
                    pu.display()
                )));
            }
            let a = pick(pu, &ru, opts.array.as_deref(), false)?;
            let b = pick(pv, &rv, opts.array.as_deref(), false)?;
            let geometry = with_spacing(pu, &ru.geometry, spacing)?;
            let Geometry::Flat(grid) = &geometry else { unreachable!("checked above") };
            let values = derive(pu, grid, d, &a.2, &b.2)?;
            (geometry, values, format!("{} of ({}, {})", d.name(), pu.display(), pv.display()), pu.clone())
        }
        (None, Some(d)) => {
            let raw = read_raw(path, opts.array.as_deref())?;
            let a = pick(path, &raw, opts.array.as_deref(), true)?;
            if a.1 != 2 && a.1 != 3 {
                return Err(Error::input(format!(
                    "--derive needs a vector array (2 or 3 components); `{}` has {}",
                    a.0, a.1
                ))
                .in_file(path));
            }
            let component = |k: usize| -> Vec<f64> { a.2.iter().skip(k).step_by(a.1).copied().collect() };
            let geometry = with_spacing(path, &raw.geometry, spacing)?;
            let values = match &geometry {
                Geometry::Flat(grid) => derive(path, grid, d, &component(0), &component(1))?,
                Geometry::Volume(grid) => {
                    if a.1 != 3 {
                        return Err(Error::input(format!(
                            "--derive on a volume needs a 3-component vector array; `{}` has {}",
                            a.0, a.1
                        ))
                        .in_file(path));
                    }
                    derive_volume(path, grid, d, [&component(0), &component(1), &component(2)])?
                }
            };
            let description = format!("{} of {}", d.name(), a.0);
            // the file's arrays move into the output's carried arrays, not copied
            carried = raw.carried;
            notes = raw.notes;
            (geometry, values, description, path.to_path_buf())
        }
        (None, None) => {
            let raw = read_raw(path, opts.array.as_deref())?;
            let a = pick(path, &raw, opts.array.as_deref(), false)?;
            if a.1 != 1 {
                return Err(Error::input(format!(
                    "`{}` has {} components; smooth a scalar array, or use --derive ({})",
                    a.0,
                    a.1,
                    match raw.geometry {
                        Geometry::Flat(_) => "vorticity or magnitude",
                        Geometry::Volume(_) => "vorticity-magnitude, vorticity-x|y|z or magnitude",
                    }
                ))
                .in_file(path));
            }
            let geometry = with_spacing(path, &raw.geometry, spacing)?;
            let (name, values) = (a.0.clone(), a.2.clone());
            carried = raw.carried.map(|c| Carried { source: Some(name.clone()), ..c });
            notes = raw.notes;
            (geometry, values, name, path.to_path_buf())
        }
    };
    let inside = match &opts.mask {
        None => None,
        Some(rule) => Some(mask_of(&source, rule, &values, carried.as_ref())?),
    };
    // NaN outside the mask is background, not missing data
    let probe: Option<Vec<f64>> =
        inside.as_ref().map(|m| values.iter().zip(m).map(|(&v, &i)| if i { v } else { 0.0 }).collect());
    let checked = probe.as_deref().unwrap_or(&values);
    let missing = match &geometry {
        Geometry::Flat(grid) => describe_missing(grid, checked, 5),
        Geometry::Volume(grid) => describe_missing_in_volume(grid, checked, 5),
    };
    let mut filled = None;
    if let Some(what) = missing {
        if !opts.fill_missing {
            let whose = if opts.derive.is_some() {
                format!(
                    "the derived {description} has {what} (a missing vector makes the derivative missing wherever its stencil uses it)"
                )
            } else {
                what
            };
            return Err(
                Error::input(format!("{whose}; pass --fill-missing to fill them harmonically")).in_file(&source)
            );
        }
        let background: Vec<bool> = match &inside {
            Some(m) => values.iter().zip(m).map(|(v, &i)| v.is_nan() && !i).collect(),
            None => vec![false; values.len()],
        };
        let mask: Vec<bool> = values.iter().zip(&background).map(|(v, &b)| v.is_nan() && !b).collect();
        match &geometry {
            Geometry::Flat(grid) => fill_missing(grid, &mut values),
            Geometry::Volume(grid) => fill_missing_with(&crate::operators::volume_stiffness(grid), &mut values),
        }
        .map_err(|e| e.in_file(&source))?;
        for (v, &b) in values.iter_mut().zip(&background) {
            if b {
                *v = f64::NAN;
            }
        }
        filled = Some(mask);
    }
    Ok(match geometry {
        Geometry::Flat(grid) => FieldInput::Grid(GridInput {
            grid,
            values,
            description,
            filled,
            path: source,
            carried,
            notes,
            mask: inside,
        }),
        Geometry::Volume(grid) => FieldInput::Volume(VolumeInput {
            grid,
            values,
            description,
            filled,
            path: source,
            carried,
            notes,
            mask: inside,
        }),
    })
}

/// The voxels (pixels) inside a mask: where the named array of the file (a carried VTK array, or
/// another array of the `.npz`) is non-zero, or where the field is at least the threshold.
fn mask_of(path: &Path, rule: &MaskRule, values: &[f64], carried: Option<&Carried>) -> Result<Vec<bool>> {
    let inside = match rule {
        MaskRule::Below(t) => values.iter().map(|v| *v >= *t).collect(),
        MaskRule::Array(name) => {
            let array: Vec<f64> = match carried.and_then(|c| c.point.iter().find(|a| &a.name == name)) {
                Some(a) if a.components == 1 => a.values.clone(),
                Some(a) => {
                    return Err(Error::input(format!(
                        "the mask array `{name}` has {} components; a mask is one value per voxel",
                        a.components
                    ))
                    .in_file(path))
                }
                None if extension(path) == "npz" => match read_numpy(path, Some(name), Wanted::Grid)? {
                    NumpyField::Volume { values, .. } => values,
                    _ => return Err(Error::input(format!("the mask array `{name}` is not a volume")).in_file(path)),
                },
                None => {
                    let found = carried
                        .map(|c| c.point.iter().map(|a| format!("`{}`", a.name)).collect::<Vec<_>>().join(", "))
                        .filter(|t| !t.is_empty())
                        .unwrap_or_else(|| "no other arrays".into());
                    return Err(Error::input(format!(
                        "no point array `{name}` for --mask (the file holds {found}; --mask-below V masks by value)"
                    ))
                    .in_file(path));
                }
            };
            if array.len() != values.len() {
                return Err(Error::input(format!(
                    "the mask array `{name}` has {} values, the volume {} voxels",
                    array.len(),
                    values.len()
                ))
                .in_file(path));
            }
            array.iter().map(|&m| m != 0.0 && !m.is_nan()).collect()
        }
    };
    Ok(inside)
}

/// The first few missing samples of a volume as `(i, j, k)` text.
fn describe_missing_in_volume(grid: &Grid3d, values: &[f64], limit: usize) -> Option<String> {
    crate::derive::describe_missing_with(values, limit, |v| {
        let [i, j, k] = grid.ijk(v);
        format!("(i {i}, j {j}, k {k})")
    })
}

/// A 2D grid's derived scalar.
fn derive(path: &Path, grid: &Grid2d, d: Derive, u: &[f64], v: &[f64]) -> Result<Vec<f64>> {
    match d {
        Derive::Vorticity => Ok(vorticity(grid, u, v)),
        Derive::Magnitude => Ok(magnitude(u, v)),
        _ => Err(Error::Usage(format!(
            "{}: --derive {} is for volumes; on a 2D grid use vorticity (the signed ∂v/∂x − ∂u/∂y) or magnitude",
            path.display(),
            d.name()
        ))),
    }
}

/// A volume's derived scalar (central differences, one-sided at the boundary, signed spacing).
fn derive_volume(path: &Path, grid: &Grid3d, d: Derive, uvw: [&[f64]; 3]) -> Result<Vec<f64>> {
    use crate::derive::{curl, magnitude3};
    Ok(match d {
        Derive::Magnitude => magnitude3(uvw),
        Derive::VorticityMagnitude => {
            let w = curl(grid, uvw);
            magnitude3([&w[0], &w[1], &w[2]])
        }
        Derive::VorticityX => curl(grid, uvw)[0].clone(),
        Derive::VorticityY => curl(grid, uvw)[1].clone(),
        Derive::VorticityZ => curl(grid, uvw)[2].clone(),
        Derive::Vorticity => {
            return Err(Error::Usage(format!(
                "{}: --derive vorticity is the signed 2D vorticity; on a volume use vorticity-magnitude or \
                 vorticity-x, vorticity-y, vorticity-z (the curl's components)",
                path.display()
            )))
        }
    })
}

/// The x axis of a series as read: coordinates, their text and where they came from.
#[derive(Clone, Debug)]
pub struct SeriesAxis {
    /// x coordinates (days for dates).
    pub x: Vec<f64>,
    /// The x column's text per row, written back out.
    pub x_text: Vec<String>,
    /// The x column's header, written back out.
    pub x_name: String,
    /// Where x came from.
    pub source: crate::io::series_csv::XSource,
}

/// A field read by a command, whatever its domain.
#[derive(Clone, Debug)]
pub struct Field {
    /// The domain.
    pub domain: crate::domain::AnyDomain,
    /// The values to smooth (after deriving and filling).
    pub values: Vec<f64>,
    /// The file read (the first velocity file with `--u/--v`).
    pub path: PathBuf,
    /// What the values are: the column, the array read or the derivation.
    pub description: String,
    /// Vertices filled by `--fill-missing` (true), when any were.
    pub filled: Option<Vec<bool>>,
    /// What reading and validation changed (meshes: polygons split, triangles flipped).
    pub notes: Vec<String>,
    /// Series: the x axis as read.
    pub axis: Option<SeriesAxis>,
    /// What the input carries besides the field, for VTK outputs.
    pub carried: Option<Carried>,
    /// Volumes: the voxels inside `--mask` / `--mask-below`, when given.
    pub mask: Option<Vec<bool>>,
}

impl FieldInput {
    /// The field with its domain as an [`crate::domain::AnyDomain`]; `path` names a series' file.
    ///
    /// # Errors
    /// A series whose x coordinates do not increase (input error naming the file).
    pub fn into_field(self, path: &Path) -> Result<Field> {
        use crate::domain::{AnyDomain, Series};
        Ok(match self {
            FieldInput::Series(SeriesInput { data, filled }) => Field {
                mask: None,
                domain: AnyDomain::Series(Series::with_coordinates(data.x.clone()).map_err(|e| e.in_file(path))?),
                values: data.values,
                path: if path.as_os_str() == "-" { PathBuf::from("standard input") } else { path.to_path_buf() },
                description: data.column,
                filled,
                notes: Vec::new(),
                axis: Some(SeriesAxis { x: data.x, x_text: data.x_text, x_name: data.x_name, source: data.x_source }),
                carried: None,
            },
            FieldInput::Grid(g) => Field {
                mask: g.mask,
                domain: AnyDomain::Grid(g.grid),
                values: g.values,
                path: g.path,
                description: g.description,
                filled: g.filled,
                notes: g.notes,
                axis: None,
                carried: g.carried,
            },
            FieldInput::Volume(v) => Field {
                mask: v.mask,
                domain: AnyDomain::Volume(v.grid),
                values: v.values,
                path: v.path,
                description: v.description,
                filled: v.filled,
                notes: v.notes,
                axis: None,
                carried: v.carried,
            },
            FieldInput::Mesh(m) => Field {
                mask: None,
                domain: m.mesh.into_domain(),
                values: m.values,
                path: m.path,
                description: m.description,
                filled: m.filled,
                notes: m.notes,
                axis: None,
                carried: m.carried,
            },
        })
    }
}
