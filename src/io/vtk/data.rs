//! What the VTK readers return: any data set as read ([`Dataset`]), and a 2D image
//! ([`ImageData`]) made from one.

pub use super::decode::Scalar;
use crate::domain::Grid2d;
use crate::error::{Error, Result};
use std::path::Path;

/// A 2D image read from a VTK file: `nx × ny` points, x fastest (flat index `row · nx + col`,
/// row 0 = the lowest y index of the extent).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageData {
    /// Points along x.
    pub nx: usize,
    /// Points along y.
    pub ny: usize,
    /// Spacing along x and y.
    pub spacing: [f64; 2],
    /// Position of point (row 0, column 0): the file's origin shifted by the extent's start.
    pub origin: [f64; 2],
    /// The plane the image lies in (its x and y are the file's `plane.axes`).
    pub plane: crate::domain::Plane,
    /// Point data arrays, in file order.
    pub arrays: Vec<PointArray>,
    /// Cell data arrays, in file order: `(nx − 1) · (ny − 1)` tuples, x fastest.
    pub cell_arrays: Vec<PointArray>,
    /// What reading did (a Direction matrix turned into flips or a transposition).
    pub notes: Vec<String>,
    /// Point arrays that are not numeric, not read: "`name` (type)".
    pub skipped: Vec<String>,
    /// The active scalars, if the file names them.
    pub active_scalars: Option<String>,
}

/// A 3D image read from a VTK file: `dims[0] × dims[1] × dims[2]` points, x fastest (flat
/// index `i + nx·(j + ny·k)`), its axes along the physical x, y and z (a `Direction` that
/// permutes or flips them has been applied: arrays reordered, flips as negative spacings).
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeData {
    /// Points along x, y and z.
    pub dims: [usize; 3],
    /// Spacing along x, y and z (negative where the file's axis runs the other way).
    pub spacing: [f64; 3],
    /// Position of point (0, 0, 0).
    pub origin: [f64; 3],
    /// Point data arrays, in file order.
    pub arrays: Vec<PointArray>,
    /// Cell data arrays: `(nx − 1)(ny − 1)(nz − 1)` tuples, x fastest.
    pub cell_arrays: Vec<PointArray>,
    /// What reading did.
    pub notes: Vec<String>,
    /// Point arrays that are not numeric, not read: "`name` (type)".
    pub skipped: Vec<String>,
    /// The active scalars, if the file names them.
    pub active_scalars: Option<String>,
}

/// An image as a domain sees it: flat (2D) or a volume.
#[derive(Clone, Debug, PartialEq)]
pub enum AnyImage {
    /// One point along one axis: a 2D image.
    Flat(ImageData),
    /// At least two points along every axis.
    Volume(VolumeData),
}

/// A VTK data set as the file holds it, before it becomes a domain.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dataset {
    /// The image geometry of image data (`None` for poly data and unstructured grids).
    pub image: Option<ImageGeometry>,
    /// Point coordinates (empty for image data).
    pub points: Vec<[f64; 3]>,
    /// Cells (empty for image data).
    pub cells: Cells,
    /// Point data arrays, in file order.
    pub point_data: Vec<PointArray>,
    /// Cell data arrays, in file order (poly data: VTK's cell order, vertices, lines,
    /// polygons, strips).
    pub cell_data: Vec<PointArray>,
    /// Arrays that are not numeric (strings, bits), which are not read: "`name` (type)".
    pub skipped: Vec<String>,
    /// The active scalars (XML `<PointData Scalars=...>`, a legacy file's first `SCALARS`):
    /// the array a VTK filter processes when none is named.
    pub active_scalars: Option<String>,
}

/// The geometry of VTK image data: point `(i, j, k)` of the extent lies at
/// `origin + direction · (i·sx, j·sy, k·sz)`.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageGeometry {
    /// `x0 x1 y0 y1 z0 z1`, inclusive.
    pub extent: [i64; 6],
    /// `Origin`: the position of index (0, 0, 0).
    pub origin: [f64; 3],
    /// `Spacing` along the index axes.
    pub spacing: [f64; 3],
    /// Row-major 3 × 3 (VTK's `Direction` attribute order); the identity when absent.
    pub direction: [f64; 9],
}

impl ImageGeometry {
    /// Points along each axis.
    pub fn dims(&self) -> [usize; 3] {
        let e = self.extent;
        [0, 1, 2].map(|a| if e[2 * a + 1] >= e[2 * a] { (e[2 * a + 1] - e[2 * a]) as usize + 1 } else { 0 })
    }
}

/// Cells in VTK's unstructured layout: cell `c` has type `types[c]` (VTK's cell type code)
/// and corners `connectivity[offsets[c]..offsets[c + 1]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Cells {
    /// One VTK cell type code per cell (see [`cell`]).
    pub types: Vec<u8>,
    /// `types.len() + 1` offsets, starting at 0.
    pub offsets: Vec<usize>,
    /// The corners of all cells, one after another.
    pub connectivity: Vec<usize>,
}

impl Default for Cells {
    fn default() -> Self {
        Cells { types: Vec::new(), offsets: vec![0], connectivity: Vec::new() }
    }
}

impl Cells {
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.types.len()
    }

    /// Whether there is no cell.
    pub fn is_empty(&self) -> bool {
        self.types.is_empty()
    }

    /// The corners of cell `c`.
    pub fn corners(&self, c: usize) -> &[usize] {
        &self.connectivity[self.offsets[c]..self.offsets[c + 1]]
    }

    /// Appends cells given as end offsets (VTK XML's layout, no leading 0) into
    /// `connectivity`, all of type `ty`, or of the types given; indices shifted by `base`.
    ///
    /// # Errors
    /// Offsets that decrease or run past the connectivity, or a type list of another length.
    pub(crate) fn append(
        &mut self,
        connectivity: &[usize],
        ends: &[usize],
        types: CellTypes,
        base: usize,
        what: &str,
    ) -> Result<()> {
        if let CellTypes::Each(t) = &types {
            if t.len() != ends.len() {
                return Err(Error::input(format!("{what}: {} cells but {} cell types", ends.len(), t.len())));
            }
        }
        let mut start = 0usize;
        for (c, &end) in ends.iter().enumerate() {
            if end < start || end > connectivity.len() {
                return Err(Error::input(format!(
                    "{what}: the offsets of cell {c} ({start}..{end}) run outside the connectivity ({} entries)",
                    connectivity.len()
                )));
            }
            let shifted = connectivity[start..end].iter().map(|&v| v.checked_add(base));
            for v in shifted {
                self.connectivity
                    .push(v.ok_or_else(|| Error::input(format!("{what}: cell {c} has an index too large")))?);
            }
            self.offsets.push(self.connectivity.len());
            self.types.push(match &types {
                CellTypes::Each(t) => t[c],
                CellTypes::PolyData(kind) => kind.cell_type(end - start),
            });
            start = end;
        }
        Ok(())
    }
}

/// The types of cells being appended.
pub(crate) enum CellTypes {
    /// One type per cell.
    Each(Vec<u8>),
    /// Poly data cells of this section: the type follows the corner count.
    PolyData(PolySection),
}

/// The cell sections of VTK poly data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PolySection {
    Verts,
    Lines,
    Polys,
    Strips,
}

impl PolySection {
    /// VTK's cell type for a cell of `n` corners in this section.
    fn cell_type(self, n: usize) -> u8 {
        match (self, n) {
            (PolySection::Verts, 1) => cell::VERTEX,
            (PolySection::Verts, _) => cell::POLY_VERTEX,
            (PolySection::Lines, 2) => cell::LINE,
            (PolySection::Lines, _) => cell::POLY_LINE,
            (PolySection::Polys, 3) => cell::TRIANGLE,
            (PolySection::Polys, 4) => cell::QUAD,
            (PolySection::Polys, _) => cell::POLYGON,
            (PolySection::Strips, _) => cell::TRIANGLE_STRIP,
        }
    }
}

/// VTK's cell type codes (vtkCellType.h) that the readers name.
#[allow(missing_docs)]
pub mod cell {
    pub const VERTEX: u8 = 1;
    pub const POLY_VERTEX: u8 = 2;
    pub const LINE: u8 = 3;
    pub const POLY_LINE: u8 = 4;
    pub const TRIANGLE: u8 = 5;
    pub const TRIANGLE_STRIP: u8 = 6;
    pub const POLYGON: u8 = 7;
    pub const PIXEL: u8 = 8;
    pub const QUAD: u8 = 9;
    pub const TETRA: u8 = 10;

    /// A readable name for a cell type code.
    pub fn name(t: u8) -> String {
        let known = [
            "vertex",
            "poly-vertex",
            "line",
            "poly-line",
            "triangle",
            "triangle strip",
            "polygon",
            "pixel",
            "quad",
            "tetrahedron",
            "voxel",
            "hexahedron",
            "wedge",
            "pyramid",
        ];
        match t {
            1..=14 => known[usize::from(t) - 1].to_string(),
            _ => format!("type-{t}"),
        }
    }
}

/// One point (or cell) data array, converted to f64.
#[derive(Clone, Debug, PartialEq)]
pub struct PointArray {
    /// The array's name (`Name` attribute, or the legacy attribute name).
    pub name: String,
    /// Components per point.
    pub components: usize,
    /// `nx · ny · components` values, components interleaved.
    pub values: Vec<f64>,
    /// The type the file stores it in (every value is exact in it): outputs carry the array
    /// through in that type.
    pub ty: Scalar,
}

impl PointArray {
    /// Component `k` of every point.
    pub fn component(&self, k: usize) -> Vec<f64> {
        self.values.iter().skip(k).step_by(self.components.max(1)).copied().collect()
    }

    /// Euclidean norm of each point's tuple.
    pub fn magnitude(&self) -> Vec<f64> {
        self.values.chunks(self.components.max(1)).map(|t| t.iter().map(|v| v * v).sum::<f64>().sqrt()).collect()
    }
}

impl ImageData {
    /// Names of the point arrays, in file order.
    pub fn names(&self) -> Vec<&str> {
        self.arrays.iter().map(|a| a.name.as_str()).collect()
    }

    /// The point array called `name`.
    ///
    /// # Errors
    /// An input error listing the available names when there is none of that name.
    pub fn array(&self, name: &str) -> Result<&PointArray> {
        self.arrays.iter().find(|a| a.name == name).ok_or_else(|| {
            let quoted = format!("`{name}` (");
            match self.skipped.iter().find(|s| s.starts_with(&quoted)) {
                Some(s) => Error::input(format!("point array {s} does not hold numbers")),
                None => {
                    Error::input(format!("no point array named `{name}`; the file has: {}", list_names(&self.names())))
                }
            }
        })
    }

    /// The image's grid, in the image's plane.
    ///
    /// # Errors
    /// A spacing or origin that [`Grid2d::with_geometry`] refuses (zero or non-finite).
    pub fn grid(&self) -> Result<Grid2d> {
        Grid2d::with_geometry(self.nx, self.ny, self.spacing, self.origin)?.in_plane(self.plane)
    }
}

pub(super) fn list_names(names: &[&str]) -> String {
    if names.is_empty() {
        "no point arrays".into()
    } else {
        names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
    }
}

pub(super) fn input(path: &Path, msg: impl Into<String>) -> Error {
    Error::input(msg).in_file(path)
}
