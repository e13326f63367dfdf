//! Any domain's results as files, and back: the one place that knows which formats hold a
//! series', a grid's or a mesh's output (SPEC.md "Formats"), how the verifiable arrays
//! `input`, `smoothed`, `representative`, `role` are laid out in each, and how the kept
//! critical points and separatrices become VTK PolyData.

use super::grid::stage_grid_csv;
use super::mesh::{stage_ply, MeshData};
use super::npz::{read_npz_nd, stage_npy, stage_npy_shaped, stage_npz, stage_npz_shaped};
use super::series_csv::{stage_series_output, SeriesColumns, XText};
use super::series_output::read_series_output_with;
use super::vtk::{
    read_any_image, read_dataset, stage_legacy, stage_vti_arrays, stage_vtp, stage_vtp_cells, stage_vtu_cells,
    tet_cells, triangle_cells, AnyImage, Cells, ImageBox, LegacyGeometry, OutArray, PointArray, PolyData, Scalar,
};
use super::Staged;
use crate::domain::{AnyDomain, Domain, Grid2d, Grid3d, Series, TriMesh};
use crate::error::{Error, Result};
use crate::topology::morse_smale::MorseSmale;
use crate::topology::Role;
use std::path::Path;

/// Extensions of a series' output.
pub const SERIES_OUTPUTS: &[&str] = &["csv"];
/// Extensions of a grid's output (`.npy` and `.csv` hold the smoothed array only).
pub const GRID_OUTPUTS: &[&str] = &["vti", "vtk", "npz", "npy", "csv"];
/// Extensions of a mesh's output.
pub const MESH_OUTPUTS: &[&str] = &["vtu", "vtp", "vtk", "ply"];
/// Extensions of a tetrahedral mesh's output (VTK unstructured grids).
pub const TET_OUTPUTS: &[&str] = &["vtu", "vtk"];
/// Extensions of a volume's output (`.npy` and NIfTI hold the smoothed array only; `.npy` of
/// shape (nz, ny, nx)).
pub const VOLUME_OUTPUTS: &[&str] = &["vti", "vtk", "npz", "npy", "nii", "nii.gz"];

/// Whether a name is a NIfTI file's: `.nii` or `.nii.gz` (any case).
pub fn is_nifti(path: &Path) -> bool {
    let name = path.file_name().map(|n| n.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    name.ends_with(".nii") || name.ends_with(".nii.gz")
}

fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// The format an output of `domain` at `path` is written in: its extension; for a stream
/// (`-`, a FIFO or a device such as `/dev/stdout`) without one, the domain's streamable
/// format: CSV for a series, NPY for a grid (a mesh has none: its name must say).
fn format_of(path: &Path, domain: &AnyDomain) -> String {
    if is_nifti(path) {
        return if extension(path) == "gz" { "nii.gz".into() } else { "nii".into() };
    }
    let e = extension(path);
    if !e.is_empty() || !super::staging::is_stream(path) {
        return e;
    }
    match domain {
        AnyDomain::Series(_) => "csv".into(),
        AnyDomain::Grid(_) | AnyDomain::Volume(_) => "npy".into(),
        AnyDomain::Mesh(_) | AnyDomain::Tets(_) => e,
    }
}

/// The output extensions of a domain, and how to name the domain in a message.
fn formats(domain: &AnyDomain) -> (&'static [&'static str], &'static str) {
    match domain {
        AnyDomain::Series(_) => (SERIES_OUTPUTS, "a series"),
        AnyDomain::Grid(_) => (GRID_OUTPUTS, "a grid"),
        AnyDomain::Mesh(_) => (MESH_OUTPUTS, "a mesh"),
        AnyDomain::Volume(_) => (VOLUME_OUTPUTS, "a volume"),
        AnyDomain::Tets(_) => (TET_OUTPUTS, "a tetrahedral mesh"),
    }
}

fn check_extension(path: &Path, allowed: &[&str], what: &str) -> Result<()> {
    if allowed.contains(&extension(path).as_str()) {
        return Ok(());
    }
    Err(format_error(path, allowed, what))
}

/// The error for an output extension that `what` has no format for.
fn format_error(path: &Path, allowed: &[&str], what: &str) -> Error {
    Error::Usage(format!(
        "{}: the output of {what} is written as {}",
        path.display(),
        allowed.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(", ")
    ))
}

fn mesh_format_error(path: &Path) -> Error {
    format_error(path, MESH_OUTPUTS, "a mesh")
}

/// Checks before any work that `path` names an output format of `domain`.
///
/// # Errors
/// [`Error::Usage`] naming the path and the formats there are.
pub fn check_output(path: &Path, domain: &AnyDomain) -> Result<()> {
    let (allowed, what) = formats(domain);
    if allowed.contains(&format_of(path, domain).as_str()) {
        return Ok(());
    }
    Err(format_error(path, allowed, what))
}

/// Checks before any work that `path` names a mesh output format (`.vtu`, `.vtp`, `.ply`).
///
/// # Errors
/// [`Error::Usage`] naming the path.
pub fn check_mesh_output(path: &Path) -> Result<()> {
    check_extension(path, MESH_OUTPUTS, "a mesh")
}

/// Checks that the complex can be written at `path` (`.vtp`; grids, meshes and volumes).
///
/// # Errors
/// [`Error::Usage`] for a series (it has no separatrices) or another extension.
pub fn check_complex_output(path: &Path, domain: &AnyDomain) -> Result<()> {
    if let AnyDomain::Series(_) = domain {
        return Err(Error::setting("complex", "is for grids, meshes and volumes (a series has no separatrices)"));
    }
    check_extension(path, &["vtp"], "the complex")
}

/// Role codes as Float64 (SPEC.md: −1 kept min, +1 kept max, 2 fixed, 3 end, 0 other).
pub fn role_codes(roles: &[Role]) -> Vec<f64> {
    roles.iter().map(|r| f64::from(r.code())).collect()
}

/// What a VTK input carries besides the field, passed through to VTK outputs as a VTK filter
/// passes its input's arrays.
#[derive(Clone, Debug, Default)]
pub struct Carried {
    /// Every point array of the input, in file order and type.
    pub point: Vec<PointArray>,
    /// The input's cells as the file gives them (meshes); `None` writes the triangles.
    pub cells: Option<Cells>,
    /// Every cell array of the input (one tuple per cell of `cells`; images: per pixel).
    pub cell: Vec<PointArray>,
    /// The point array the field is (not a derivation of it): the output gives the smoothed
    /// field that name, in place of the input's array.
    pub source: Option<String>,
    /// A NIfTI input's voxel-to-world affine (rows of a 3 × 4 matrix), for NIfTI outputs.
    pub affine: Option<[[f64; 4]; 3]>,
}

/// The names the tool's own arrays take in a VTK output.
const OWN_ARRAYS: [&str; 6] = ["input", "smoothed", "representative", "role", "filled", "mask"];

/// The point arrays of a VTK output: the smoothed field under the input array's name (or
/// `output_array`) first, as the active scalars, then `smoothed`, `input`, `representative`,
/// `role` (and `filled`), then every other input array unchanged, renamed `<name>_input` where
/// its name is taken. Returns each array's name and where its values come from.
fn vtk_point_plan(
    own: &[(&str, &[f64])],
    carried: Option<&Carried>,
    output_array: Option<&str>,
) -> Vec<(String, Source)> {
    let source = carried.and_then(|c| c.source.as_deref());
    let primary = output_array.or(source).filter(|p| !OWN_ARRAYS.contains(p));
    let mut plan: Vec<(String, Source)> = Vec::new();
    if let Some(p) = primary {
        plan.push((p.to_string(), Source::Smoothed));
    }
    plan.extend(own.iter().enumerate().map(|(k, (n, _))| (n.to_string(), Source::Own(k))));
    for (k, a) in carried.map(|c| c.point.as_slice()).unwrap_or_default().iter().enumerate() {
        if output_array.is_none() && Some(a.name.as_str()) == source {
            // the smoothed field takes its place
            continue;
        }
        let mut name = a.name.clone();
        while plan.iter().any(|(n, _)| *n == name) || OWN_ARRAYS.contains(&name.as_str()) {
            name += "_input";
        }
        plan.push((name, Source::Carried(k)));
    }
    plan
}

/// The active scalars of a planned output: the smoothed field, under the input array's name
/// when it has one, else `smoothed`.
fn active_of(plan: &[(String, Source)]) -> &str {
    plan.iter().find(|(_, s)| *s == Source::Smoothed).map_or("smoothed", |(n, _)| n.as_str())
}

/// Where a planned output array's values come from.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    Smoothed,
    Own(usize),
    Carried(usize),
}

/// The planned arrays.
fn planned<'a>(
    plan: &'a [(String, Source)],
    own: &[(&'a str, &'a [f64])],
    smoothed: &'a [f64],
    carried: Option<&'a Carried>,
) -> Vec<OutArray<'a>> {
    plan.iter()
        .map(|(name, src)| match *src {
            Source::Smoothed => OutArray::float64(name, smoothed),
            Source::Own(k) => OutArray::float64(name, own[k].1),
            Source::Carried(k) => OutArray::carried(&carried.expect("planned from it").point[k], name),
        })
        .collect()
}

/// The verifiable arrays of a smoothing result.
pub struct Results<'a> {
    /// The values smoothed (after deriving and filling).
    pub input: &'a [f64],
    /// The certified output.
    pub smoothed: &'a [f64],
    /// The representative function.
    pub representative: &'a [f64],
    /// Role per vertex.
    pub roles: &'a [Role],
    /// Vertices whose input was filled (`--fill-missing`), when any were.
    pub filled: Option<&'a [bool]>,
    /// What the input carries besides the field (VTK inputs), for VTK outputs.
    pub carried: Option<&'a Carried>,
    /// The name of the smoothed field in VTK outputs (`--output-array`), instead of the input
    /// array's.
    pub output_array: Option<&'a str>,
    /// Volumes smoothed inside a mask: the voxels the domain holds (written as `mask`, 1
    /// inside, so that `verify` rebuilds the domain).
    pub mask: Option<&'a [bool]>,
}

/// Stages a smoothing result at `path` in the format its extension names: a series as
/// `X,input,output,u,role[,filled]` CSV (`x_axis`: the x column's header and its text as read,
/// dates as dates; `x` and the indices without); a grid as
/// `.vti` or `.npz` (every array) or `.npy` / CSV (the smoothed array); a mesh as `.vtu`, `.vtp`
/// or `.ply` (every array).
///
/// # Errors
/// Usage errors for an extension the domain has no format for; I/O errors naming the file.
pub fn stage_results(path: &Path, domain: &AnyDomain, x_axis: Option<(&str, &XText)>, r: &Results) -> Result<Staged> {
    check_output(path, domain)?;
    let roles = role_codes(r.roles);
    let filled: Option<Vec<f64>> = r.filled.map(|m| m.iter().map(|&b| f64::from(u8::from(b))).collect());
    let mut arrays: Vec<(&str, &[f64])> =
        vec![("input", r.input), ("smoothed", r.smoothed), ("representative", r.representative), ("role", &roles)];
    if let Some(f) = &filled {
        arrays.push(("filled", f));
    }
    let mask: Option<Vec<f64>> = r.mask.map(|m| m.iter().map(|&b| f64::from(u8::from(b))).collect());
    if let Some(m) = &mask {
        arrays.push(("mask", m));
    }
    match domain {
        AnyDomain::Series(s) => {
            let index = XText::Index(s.n_vertices());
            let (x_name, x_text) = x_axis.unwrap_or(("x", &index));
            let out = SeriesColumns {
                x_name,
                x_text,
                input: r.input,
                output: r.smoothed,
                u: r.representative,
                roles: r.roles,
                filled: r.filled,
            };
            stage_series_output(path, &out)
        }
        AnyDomain::Grid(g) => match format_of(path, domain).as_str() {
            e @ ("vti" | "vtk") => {
                let plan = vtk_point_plan(&arrays, r.carried, r.output_array);
                let point = planned(&plan, &arrays, r.smoothed, r.carried);
                let cells: Vec<OutArray> = carried_cells(r.carried);
                let b = ImageBox::of_grid(g);
                if e == "vti" {
                    stage_vti_arrays(path, b, &point, &cells, Some(active_of(&plan)))
                } else {
                    stage_legacy(path, &LegacyGeometry::Image(b), (&point, &cells), Some(active_of(&plan)))
                }
            }
            "npz" => stage_npz(path, g.ny(), g.nx(), &arrays),
            "npy" => stage_npy(path, g.ny(), g.nx(), r.smoothed),
            _ => stage_grid_csv(path, g.nx(), r.smoothed),
        },
        AnyDomain::Mesh(m) => match extension(path).as_str() {
            "vtu" | "vtp" | "vtk" => stage_cells(path, m.positions(), || triangle_cells(m.faces()), &arrays, r),
            _ => stage_mesh(path, m, &arrays),
        },
        // `.vtu` or legacy `.vtk` (check_output refused the rest)
        AnyDomain::Tets(m) => stage_cells(path, m.positions(), || tet_cells(m.tets()), &arrays, r),
        AnyDomain::Volume(g) => match format_of(path, domain).as_str() {
            e @ ("vti" | "vtk") => {
                let plan = vtk_point_plan(&arrays, r.carried, r.output_array);
                let point = planned(&plan, &arrays, r.smoothed, r.carried);
                let cells: Vec<OutArray> = carried_cells(r.carried);
                let b = ImageBox { dims: g.dims(), spacing: g.spacing(), origin: g.origin() };
                if e == "vti" {
                    stage_vti_arrays(path, b, &point, &cells, Some(active_of(&plan)))
                } else {
                    stage_legacy(path, &LegacyGeometry::Image(b), (&point, &cells), Some(active_of(&plan)))
                }
            }
            "npz" => stage_npz_shaped(path, &[g.nz(), g.ny(), g.nx()], &arrays),
            #[cfg(feature = "io-nifti")]
            "nii" | "nii.gz" => {
                let affine = r.carried.and_then(|c| c.affine).unwrap_or_else(|| volume_affine(g));
                super::nifti::stage_nifti(path, g.dims(), g.spacing().map(f64::abs), &affine, r.smoothed)
            }
            _ => stage_npy_shaped(path, &[g.nz(), g.ny(), g.nx()], r.smoothed),
        },
    }
}

/// A mesh's result as a VTK unstructured output (`.vtu`, `.vtp`, legacy `.vtk`): the input's
/// cells and cell arrays when it carried them (as a VTK filter passes them), else `own` cells.
fn stage_cells(
    path: &Path,
    positions: &[[f64; 3]],
    own: impl FnOnce() -> Cells,
    arrays: &[(&str, &[f64])],
    r: &Results,
) -> Result<Staged> {
    let plan = vtk_point_plan(arrays, r.carried, r.output_array);
    let point = planned(&plan, arrays, r.smoothed, r.carried);
    let own_cells;
    let (cells, cell_arrays) = match r.carried.and_then(|c| c.cells.as_ref()) {
        Some(cells) => (cells, carried_cells(r.carried)),
        None => {
            own_cells = own();
            (&own_cells, Vec::new())
        }
    };
    let active = Some(active_of(&plan));
    match extension(path).as_str() {
        "vtu" => stage_vtu_cells(path, positions, cells, (&point, &cell_arrays), active),
        "vtp" => stage_vtp_cells(path, positions, cells, (&point, &cell_arrays), active),
        _ => {
            let geometry = LegacyGeometry::Unstructured { points: positions, cells };
            stage_legacy(path, &geometry, (&point, &cell_arrays), active)
        }
    }
}

/// The affine of a volume grid as VTK places its points: origin + (i·dx, j·dy, k·dz), signs
/// kept.
pub fn volume_affine(g: &Grid3d) -> [[f64; 4]; 3] {
    let (s, o) = (g.spacing(), g.origin());
    [[s[0], 0.0, 0.0, o[0]], [0.0, s[1], 0.0, o[1]], [0.0, 0.0, s[2], o[2]]]
}

/// The input's cell arrays, unchanged.
fn carried_cells(carried: Option<&Carried>) -> Vec<OutArray<'_>> {
    carried.map(|c| c.cell.iter().map(|a| OutArray::carried(a, &a.name)).collect()).unwrap_or_default()
}

/// Certificate item 5 (SPEC.md): the staged output, read back from its temporary with the
/// format's own reader, holds the certified arrays bit for bit (`smoothed` always; `input`,
/// `representative` and the roles where the format holds them). Run before committing, so a
/// file that would not read back as certified is never put in place.
///
/// # Errors
/// [`Error::Uncertified`] naming the target and the first vertex that reads back differently;
/// the reader's errors.
pub fn check_written(staged: &Staged, domain: &AnyDomain, r: &Results) -> Result<()> {
    let target = staged.target();
    let tmp = staged.temp_path();
    let fail = |what: &str, i: Option<usize>| Error::Uncertified {
        path: Some(target.to_path_buf()),
        message: format!(
            "certificate item 5: the file as written reads back with {what}{}",
            i.map(|i| format!(" (first at {})", domain.describe_vertex(i))).unwrap_or_default()
        ),
    };
    let differs = |a: &[f64], b: &[f64]| -> Option<Option<usize>> {
        if a.len() != b.len() {
            return Some(None);
        }
        a.iter().zip(b).position(|(x, y)| x.to_bits() != y.to_bits()).map(Some)
    };
    let reread = |e: Error| match e {
        Error::Io { source, .. } => Error::Io { path: target.to_path_buf(), source },
        other => fail(&format!("an error: {other}"), None),
    };
    let smoothed_only = match (domain, format_of(target, domain).as_str()) {
        (AnyDomain::Grid(_), "npy") => Some(super::grid::read_npy(tmp).map_err(reread)?.values),
        (AnyDomain::Grid(_), "csv") => Some(super::grid::read_grid_csv(tmp).map_err(reread)?.values),
        #[cfg(feature = "io-nifti")]
        (AnyDomain::Volume(g), "nii" | "nii.gz") => {
            let v = super::nifti::read_nifti(tmp).map_err(reread)?;
            if v.dims != g.dims() {
                return Err(fail(&format!("dimensions {:?}", v.dims), None));
            }
            Some(v.values)
        }
        (AnyDomain::Volume(g), "npy") => {
            let bytes = std::fs::read(tmp).map_err(|source| reread(Error::Io { path: tmp.to_path_buf(), source }))?;
            let (shape, values) = super::npz::decode_npy_nd(&bytes).map_err(reread)?;
            if shape != [g.nz(), g.ny(), g.nx()] {
                return Err(fail(&format!("shape {}", super::npz::shape_text(&shape)), None));
            }
            Some(values)
        }
        _ => None,
    };
    if let Some(values) = smoothed_only {
        return match differs(&values, r.smoothed) {
            Some(i) => Err(fail("other smoothed values", i)),
            None => Ok(()),
        };
    }
    let stored = read_results(tmp).map_err(reread)?;
    for (what, read, certified) in [
        ("other smoothed values", &stored.smoothed, r.smoothed),
        ("another input", &stored.input, r.input),
        ("another representative", &stored.representative, r.representative),
    ] {
        if let Some(i) = differs(read, certified) {
            return Err(fail(what, i));
        }
    }
    if stored.roles != r.roles {
        let i = stored.roles.iter().zip(r.roles).position(|(a, b)| a != b);
        return Err(fail("other roles", i));
    }
    Ok(())
}

/// Stages a mesh with per-vertex arrays as `.vtu`, `.vtp` or `.ply`.
///
/// # Errors
/// Usage errors for another extension; I/O errors naming the file.
pub fn stage_mesh(path: &Path, mesh: &TriMesh, arrays: &[(&str, &[f64])]) -> Result<Staged> {
    let staged = stage_mesh_unchecked(path, mesh, arrays)?;
    check_mesh_written(&staged, mesh.positions(), mesh.faces(), arrays)?;
    Ok(staged)
}

/// Certificate item 5 for the mesh outputs of every command (weights, geodesic distance,
/// colours, deformations): the staged file, read back with its format's reader, holds the
/// positions, as many triangles and every array bit for bit.
///
/// # Errors
/// [`Error::Uncertified`] naming the target and what reads back differently.
pub fn check_mesh_written(
    staged: &Staged,
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
    arrays: &[(&str, &[f64])],
) -> Result<()> {
    let target = staged.target();
    let fail = |what: String| Error::Uncertified {
        path: Some(target.to_path_buf()),
        message: format!("certificate item 5: the file as written reads back with {what}"),
    };
    let data = super::mesh::read_mesh(staged.temp_path()).map_err(|e| fail(format!("an error: {e}")))?;
    let bits = |p: &[[f64; 3]]| p.iter().flatten().map(|v| v.to_bits()).collect::<Vec<u64>>();
    if bits(&data.positions) != bits(positions) {
        return Err(fail("other vertex positions".into()));
    }
    if data.triangles.len() != triangles.len() {
        return Err(fail(format!("{} triangles instead of {}", data.triangles.len(), triangles.len())));
    }
    for (name, values) in arrays {
        let read = data.arrays.iter().find(|a| a.name == *name).ok_or_else(|| fail(format!("no array `{name}`")))?;
        let same = read.values.len() == values.len()
            && read.values.iter().zip(*values).all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            return Err(fail(format!("other values in `{name}`")));
        }
    }
    Ok(())
}

fn stage_mesh_unchecked(path: &Path, mesh: &TriMesh, arrays: &[(&str, &[f64])]) -> Result<Staged> {
    match extension(path).as_str() {
        "vtu" => super::vtk::stage_vtu(path, mesh.positions(), mesh.faces(), arrays),
        "vtp" => stage_vtp(
            path,
            &PolyData {
                points: mesh.positions().to_vec(),
                polys: mesh.faces().to_vec(),
                point_arrays: arrays.iter().map(|(n, v)| (n.to_string(), v.to_vec())).collect(),
                ..Default::default()
            },
        ),
        "ply" => stage_ply(path, mesh.positions(), mesh.faces(), arrays),
        "vtk" => {
            let cells = triangle_cells(mesh.faces());
            let geometry = LegacyGeometry::Unstructured { points: mesh.positions(), cells: &cells };
            let point: Vec<OutArray> = arrays.iter().map(|(n, v)| OutArray::float64(n, v)).collect();
            stage_legacy(path, &geometry, (&point, &[]), arrays.first().map(|(n, _)| *n))
        }
        _ => Err(mesh_format_error(path)),
    }
}

/// Stages the critical points and the kept complex at `path` as `.vtp` in TTK's layout
/// ([`super::ttk`]): one vertex cell per critical vertex of the input's persistence pairs
/// (extrema and merge saddles, cancelled ones included; a series' end maxima, unpaired, are
/// left out), then, on surfaces, one polyline per separatrix of the kept complex `ms`
/// (volumes and tetrahedral meshes have no separatrices here: `ms` is `None` and only the
/// critical points are written). Point data: `CriticalType` (in volumes the saddle a minimum
/// dies at is a 1-saddle, the one a maximum dies at a 2-saddle, a vertex that is both is
/// degenerate, 4), `ttkVertexScalarField`, `input` (the value), `Persistence` and
/// `PairIdentifier` of the vertex's diagram pair (the ids of `--diagram`; NaN and −1 for
/// regular vertices on separatrices), `Kept` (UInt8: a kept extremum, a saddle of the kept
/// complex, or in a volume the saddle of a pair whose extremum is kept). Cell data:
/// `SeparatrixType` (−1 on vertex cells), `SourceId` and `DestinationId` (the saddle's and the
/// extremum's vertex; the vertex itself and −1 on vertex cells).
///
/// # Errors
/// As [`check_complex_output`]; I/O errors naming the file.
pub fn stage_complex(
    path: &Path,
    domain: &AnyDomain,
    h: &[f64],
    roles: &[Role],
    ms: Option<&MorseSmale>,
) -> Result<Staged> {
    use super::ttk::critical;
    check_complex_output(path, domain)?;
    let pairs = super::ttk::diagram_of(domain, h);
    let place = |v: usize| super::ttk::point_of(domain, v);
    // each vertex's critical type and diagram pair (the first pair that names it); a vertex
    // named as a 1-saddle and as a 2-saddle is degenerate
    let mut critical_of: std::collections::BTreeMap<usize, (i32, usize)> = std::collections::BTreeMap::new();
    let mut saddles: std::collections::HashSet<usize> =
        ms.map(|ms| ms.saddles.iter().copied().collect()).unwrap_or_default();
    for (i, p) in pairs.iter().enumerate() {
        for k in 0..2 {
            let entry = critical_of.entry(p.vertices[k]).or_insert((p.types[k], i));
            if entry.0 != p.types[k] {
                entry.0 = critical::DEGENERATE;
            }
        }
        if ms.is_none() && p.finite && matches!(roles[p.extremum], Role::Min | Role::Max) {
            saddles.insert(p.vertices[usize::from(p.extremum == p.vertices[0])]);
        }
    }
    let mut slot = std::collections::HashMap::new();
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut vertex_of: Vec<usize> = Vec::new();
    let mut id = |v: usize, points: &mut Vec<[f64; 3]>, vertex_of: &mut Vec<usize>| -> usize {
        *slot.entry(v).or_insert_with(|| {
            points.push(place(v));
            vertex_of.push(v);
            points.len() - 1
        })
    };
    let mut cells = Cells::default();
    let (mut sep_type, mut source, mut destination) = (Vec::new(), Vec::new(), Vec::new());
    for &v in critical_of.keys() {
        cells.connectivity.push(id(v, &mut points, &mut vertex_of));
        cells.offsets.push(cells.connectivity.len());
        cells.types.push(super::vtk::cell::VERTEX);
        sep_type.push(-1.0);
        source.push(v as f64);
        destination.push(-1.0);
    }
    for (list, t) in ms.iter().flat_map(|ms| [(&ms.descending, 0.0), (&ms.ascending, 1.0)]) {
        for sep in list {
            for &v in &sep.path {
                cells.connectivity.push(id(v, &mut points, &mut vertex_of));
            }
            cells.offsets.push(cells.connectivity.len());
            cells.types.push(super::vtk::cell::POLY_LINE);
            sep_type.push(t);
            source.push(sep.saddle as f64);
            destination.push(sep.path.last().map_or(-1.0, |&v| v as f64));
        }
    }
    let mut arrays: [Vec<f64>; 6] = Default::default();
    for &v in &vertex_of {
        let (t, pair) = critical_of.get(&v).copied().unwrap_or((critical::REGULAR, usize::MAX));
        let kept = matches!(roles[v], Role::Min | Role::Max) || saddles.contains(&v);
        arrays[0].push(f64::from(t));
        arrays[1].push(v as f64);
        arrays[2].push(h[v]);
        arrays[3].push(pairs.get(pair).map_or(f64::NAN, |p| p.persistence()));
        arrays[4].push(if pair == usize::MAX { -1.0 } else { pair as f64 });
        arrays[5].push(f64::from(u8::from(kept && t != critical::REGULAR)));
    }
    let id_type = if domain.n_vertices() > i32::MAX as usize { Scalar::I64 } else { Scalar::I32 };
    let typed = |name, ty, values| OutArray { name, ty, components: 1, values };
    let point = [
        typed("CriticalType", Scalar::I32, &arrays[0][..]),
        typed("ttkVertexScalarField", id_type, &arrays[1]),
        typed("input", Scalar::F64, &arrays[2]),
        typed("Persistence", Scalar::F64, &arrays[3]),
        typed("PairIdentifier", id_type, &arrays[4]),
        typed("Kept", Scalar::U8, &arrays[5]),
    ];
    let cell = [
        typed("SeparatrixType", Scalar::I32, &sep_type[..]),
        typed("SourceId", id_type, &source),
        typed("DestinationId", id_type, &destination),
    ];
    stage_vtp_cells(path, &points, &cells, (&point, &cell), Some("input"))
}

/// A smoothing result read back from its file (for `verify`).
#[derive(Clone, Debug)]
pub struct Stored {
    /// The domain: a series of the file's length, the grid with the file's geometry (`.npz`:
    /// unit spacing), the validated mesh.
    pub domain: AnyDomain,
    /// The `input` array.
    pub input: Vec<f64>,
    /// The `smoothed` array (the series' `output` column).
    pub smoothed: Vec<f64>,
    /// The `representative` array (the series' `u` column).
    pub representative: Vec<f64>,
    /// The roles decoded from the `role` array or column.
    pub roles: Vec<Role>,
    /// Series: the samples the `filled` column marks, when it has one.
    pub filled: Option<Vec<bool>>,
    /// Volumes and grids smoothed inside a mask: the voxels of the domain (the `mask` array,
    /// non-zero).
    pub mask: Option<Vec<bool>>,
}

/// Reads a result that [`stage_results`] wrote: `.vti`, `.npz`, a mesh (`.vtu`, `.vtp`,
/// `.ply`) or a series CSV (any other extension).
///
/// # Errors
/// I/O and input errors naming the file: a missing array, a role code that is none of SPEC's.
pub fn read_results(path: &Path) -> Result<Stored> {
    let legacy_image = extension(path) == "vtk" && read_dataset(path)?.image.is_some();
    match extension(path).as_str() {
        "vti" | "vtk" if extension(path) == "vti" || legacy_image => {
            let (domain, arrays) = match read_any_image(path)? {
                AnyImage::Flat(img) => {
                    let grid = img.grid().map_err(|e| e.in_file(path))?;
                    (AnyDomain::Grid(grid), img.arrays)
                }
                AnyImage::Volume(v) => {
                    let grid = Grid3d::with_geometry(v.dims, v.spacing, v.origin).map_err(|e| e.in_file(path))?;
                    (AnyDomain::Volume(grid), v.arrays)
                }
            };
            let names = arrays.iter().map(|a| a.name.clone()).collect();
            let arrays = arrays.into_iter().filter(|a| a.components == 1).map(|a| (a.name, a.values)).collect();
            stored(path, domain, names, arrays)
        }
        "npz" => {
            let arrays = read_npz_nd(path)?;
            let Some((_, shape, _)) = arrays.first() else {
                return Err(Error::input("the archive holds no arrays").in_file(path));
            };
            let shape = shape.clone();
            let domain = match shape.as_slice() {
                [ny, nx] => AnyDomain::Grid(Grid2d::new(*nx, *ny).map_err(|e| e.in_file(path))?),
                [nz, ny, nx] => AnyDomain::Volume(Grid3d::new(*nx, *ny, *nz).map_err(|e| e.in_file(path))?),
                _ => {
                    return Err(Error::input(format!(
                        "the arrays have shape {}: a verifiable archive holds 2D (ny, nx) or 3D (nz, ny, nx) arrays",
                        super::npz::shape_text(&shape)
                    ))
                    .in_file(path))
                }
            };
            if let Some((name, s, _)) = arrays.iter().find(|(_, s, _)| *s != shape) {
                return Err(Error::input(format!(
                    "array `{name}` has shape {}, the first {}",
                    super::npz::shape_text(s),
                    super::npz::shape_text(&shape)
                ))
                .in_file(path));
            }
            let names = arrays.iter().map(|(n, _, _)| n.clone()).collect();
            stored(path, domain, names, arrays.into_iter().map(|(n, _, v)| (n, v)).collect())
        }
        e if MESH_OUTPUTS.contains(&e) => {
            let (mesh, data) = super::mesh::read_any_mesh(path)?;
            results_on_mesh(path, mesh.into_domain(), &data)
        }
        _ => {
            let out = read_series_output_with(path, false)?;
            let domain = AnyDomain::Series(Series::uniform(out.input.len()));
            Ok(Stored {
                domain,
                input: out.input,
                smoothed: out.output,
                representative: out.u,
                roles: out.roles,
                filled: out.filled,
                mask: None,
            })
        }
    }
}

/// The result arrays of a mesh already read.
///
/// # Errors
/// As [`read_results`]; an array that is not one scalar per vertex.
pub fn results_on_mesh(path: &Path, mesh: AnyDomain, data: &MeshData) -> Result<Stored> {
    let n = mesh.n_vertices();
    let mut arrays = Vec::new();
    for a in data.arrays.iter().filter(|a| VERIFIABLE.contains(&a.name.as_str())) {
        if a.components != 1 || a.values.len() != n {
            return Err(Error::input(format!(
                "array `{}` has {} components ({} values for {n} vertices); a scalar is needed",
                a.name,
                a.components,
                a.values.len()
            ))
            .in_file(path));
        }
        arrays.push((a.name.clone(), a.values.clone()));
    }
    let names = data.arrays.iter().map(|a| a.name.clone()).collect();
    stored(path, mesh, names, arrays)
}

/// The arrays a verifiable output holds.
const VERIFIABLE: [&str; 4] = ["input", "smoothed", "representative", "role"];

/// The four verifiable arrays from `arrays`; `names` are the file's arrays, for the message.
fn stored(path: &Path, domain: AnyDomain, names: Vec<String>, mut arrays: Vec<(String, Vec<f64>)>) -> Result<Stored> {
    let mut take = |name: &str| -> Result<Vec<f64>> {
        match arrays.iter().position(|(n, _)| n == name) {
            Some(i) => Ok(arrays.swap_remove(i).1),
            None => Err(Error::input(format!(
                "no array `{name}` (a verifiable output holds input, smoothed, representative, role; found {})",
                names.join(", ")
            ))
            .in_file(path)),
        }
    };
    let (input, smoothed, representative, role) =
        (take("input")?, take("smoothed")?, take("representative")?, take("role")?);
    let mask = match arrays.iter().position(|(n, _)| n == "mask") {
        Some(i) if matches!(domain, AnyDomain::Volume(_) | AnyDomain::Grid(_)) => {
            let m = arrays.swap_remove(i).1;
            if m.len() != role.len() {
                return Err(Error::input(format!("the `mask` array has {} values for {} voxels", m.len(), role.len()))
                    .in_file(path));
            }
            Some(m.iter().map(|&x| x != 0.0 && !x.is_nan()).collect())
        }
        _ => None,
    };
    let roles = role
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            Role::from_code(c).ok_or_else(|| {
                Error::input(format!("role {c} at {} is not one of −1, 0, 1, 2, 3", domain.describe_vertex(i)))
                    .in_file(path)
            })
        })
        .collect::<Result<Vec<Role>>>()?;
    Ok(Stored { domain, input, smoothed, representative, roles, filled: None, mask })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_domain_names_its_own_formats() {
        let grid = AnyDomain::Grid(Grid2d::new(3, 2).unwrap());
        let series = AnyDomain::Series(Series::uniform(4));
        assert!(check_output(Path::new("a.VTI"), &grid).is_ok());
        let e = check_output(Path::new("a.vtu"), &grid).unwrap_err().to_string();
        assert!(e.contains("a.vtu: the output of a grid is written as .vti, .vtk, .npz, .npy, .csv"), "{e}");
        assert!(check_output(Path::new("a.csv"), &series).is_ok());
        assert!(check_output(Path::new("a.vti"), &series).is_err());
        assert!(check_complex_output(Path::new("c.vtp"), &series).is_err());
        assert!(check_complex_output(Path::new("c.vtp"), &grid).is_ok());
        assert!(check_complex_output(Path::new("c.vtu"), &grid).is_err());
    }

    #[test]
    fn a_mesh_output_that_reads_back_otherwise_is_refused() {
        let mesh = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap();
        let dir = std::env::temp_dir().join(format!("toposmooth-readback-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let d = [0.0, 1.0, 2.0, 0.1 + 0.2];
        for ext in ["vtu", "vtp", "ply", "vtk"] {
            let path = dir.join(format!("m.{ext}"));
            let staged = stage_mesh(&path, &mesh, &[("distance", &d)]).unwrap();
            // the same file, its array one ulp off: the check reads the bits, not a rounding
            let off = [0.0, 1.0, 2.0, (0.1 + 0.2f64).next_up()];
            let other = stage_mesh_unchecked(&dir.join(format!("o.{ext}")), &mesh, &[("distance", &off)]).unwrap();
            std::fs::copy(other.temp_path(), staged.temp_path()).unwrap();
            let e = check_mesh_written(&staged, mesh.positions(), mesh.faces(), &[("distance", &d)])
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("certificate item 5") && e.contains("`distance`") && e.contains(&format!("m.{ext}")),
                "{e}"
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_grid_result_reads_back_as_written() {
        let dir = std::env::temp_dir().join(format!("toposmooth-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let grid = Grid2d::with_geometry(3, 2, [0.5, -2.0], [1.0, 4.0]).unwrap();
        let domain = AnyDomain::Grid(grid);
        let h = [0.0, 1.0, 2.0, 3.0, 4.0, 5.5];
        let roles = [Role::Min, Role::Other, Role::Other, Role::Other, Role::Other, Role::Max];
        let r = Results {
            input: &h,
            smoothed: &h,
            representative: &h,
            roles: &roles,
            filled: None,
            carried: None,
            output_array: None,
            mask: None,
        };
        for ext in ["vti", "npz"] {
            let path = dir.join(format!("r.{ext}"));
            stage_results(&path, &domain, None, &r).unwrap().commit().unwrap();
            let back = read_results(&path).unwrap();
            assert_eq!((back.input, back.roles.as_slice()), (h.to_vec(), roles.as_slice()), "{ext}");
            let AnyDomain::Grid(g) = back.domain else { panic!("{ext}: not a grid") };
            assert_eq!((g.nx(), g.ny()), (3, 2));
            if ext == "vti" {
                assert_eq!((g.spacing(), g.origin()), ([0.5, -2.0], [1.0, 4.0]));
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
