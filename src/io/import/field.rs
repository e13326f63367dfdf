//! What reading gives: the input options ([`ReadOptions`], with the domain kind, the derived
//! scalar and the mask rule) and the field with its domain ([`Field`]), through the readers'
//! own results ([`FieldInput`]).

use crate::domain::{Grid2d, Grid3d};
use crate::error::Result;
use crate::io::export::Carried;
use crate::io::series_csv::{SeriesCsv, SeriesCsvOptions};
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

named_enum!(
    Derive,
    "derived scalar",
    [
        (Derive::Vorticity, "vorticity"),
        (Derive::Magnitude, "magnitude"),
        (Derive::VorticityMagnitude, "vorticity-magnitude"),
        (Derive::VorticityX, "vorticity-x"),
        (Derive::VorticityY, "vorticity-y"),
        (Derive::VorticityZ, "vorticity-z"),
    ]
);

/// How to read a file: the input options of every front end (the command line's `--domain`,
/// `--column`, `--x`, `--array`, `--spacing`, `--derive`, `--u`/`--v`, `--fill-missing`,
/// `--values`, `--mask`, `--mask-below`; [`INPUT_OPTIONS`] names them, and
/// [`ReadOptions::from_texts`] reads them as text). The default reads the file as its
/// extension and content say, with the file's own spacing and its only scalar array.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReadOptions {
    /// Series, grid or mesh; by default from the extension (and a CSV's first line).
    pub domain: DomainKind,
    /// Series (CSV): the value column, a header name or a 0-based index (default: the last
    /// numeric column).
    pub column: Option<String>,
    /// Series (CSV): the x column, a header name, an index or `none` (default: the first
    /// column if it holds dates or is named x, t, time or date).
    pub x_column: Option<String>,
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
    /// Grids and volumes: smooth only the pixels or voxels inside this mask.
    pub mask: Option<MaskRule>,
}

impl ReadOptions {
    /// The series reader's options.
    pub(super) fn csv(&self) -> SeriesCsvOptions {
        SeriesCsvOptions { column: self.column.clone(), x_column: self.x_column.clone(), ..Default::default() }
    }
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

named_enum!(
    DomainKind,
    "domain",
    [
        (DomainKind::Auto, "auto"),
        (DomainKind::Series, "series"),
        (DomainKind::Grid, "grid"),
        (DomainKind::Mesh, "mesh")
    ]
);

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

/// A field as its reader gives it, before [`FieldInput::into_field`] makes its domain.
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

/// The x axis of a series as read: coordinates, their text and where they came from.
#[derive(Clone, Debug)]
pub struct SeriesAxis {
    /// x coordinates (days for dates).
    pub x: Vec<f64>,
    /// The x column's text per row, written back out.
    pub x_text: crate::io::series_csv::XText,
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
