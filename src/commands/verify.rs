//! `toposmooth verify`: re-check an output file from what it carries, independently of `smooth`.

use super::input::{read_grid, read_mesh_field, read_trimesh, GridOptions};
use crate::domain::{Domain, Grid2d, Series};
use crate::error::{Error, Result};
use crate::io::npz::read_npz;
use crate::io::series_csv::{read_series, read_series_output, SeriesCsvOptions};
use crate::io::vtk::read_image;
use crate::topology::Role;
use crate::verify::certify;
use std::path::{Path, PathBuf};

/// Options of `verify`.
#[derive(Clone, Debug)]
pub struct VerifyArgs {
    /// The output file to check.
    pub file: PathBuf,
    /// The original input, to compare with the file's input column.
    pub input: Option<PathBuf>,
    /// Column choice for the original input.
    pub csv: SeriesCsvOptions,
    /// How to read the original input when it is a grid.
    pub grid: GridOptions,
}

/// Runs `verify`: `Ok(text)` when the file is certified, [`Error::Uncertified`] (exit 1) when not.
pub fn verify(args: &VerifyArgs) -> Result<String> {
    let ext = args.file.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "vti" | "npz" => verify_grid(args, &ext),
        "vtu" | "vtp" | "ply" => verify_mesh(args),
        "obj" | "off" | "vtk" if crate::io::mesh::is_mesh_file(&args.file) => Err(Error::Usage(format!(
            "{}: a mesh file holds no smoothing output; verify the .vtu, .vtp or .ply that `smooth` wrote",
            args.file.display()
        ))),
        "npy" => Err(Error::Usage(format!(
            "{}: a .npy export holds the smoothed array only and cannot be verified alone; verify the .vti or .npz output",
            args.file.display()
        ))),
        _ => verify_series(args),
    }
}

/// The arrays a verifiable grid output carries.
struct GridOutput {
    grid: Grid2d,
    input: Vec<f64>,
    smoothed: Vec<f64>,
    representative: Vec<f64>,
    roles: Vec<Role>,
}

fn read_grid_output(path: &Path, ext: &str) -> Result<GridOutput> {
    let (grid, mut arrays): (Grid2d, Vec<(String, Vec<f64>)>) = if ext == "vti" {
        let img = read_image(path)?;
        let grid = Grid2d::with_geometry(img.nx, img.ny, img.spacing, img.origin).map_err(|e| e.in_file(path))?;
        (grid, img.arrays.into_iter().filter(|a| a.components == 1).map(|a| (a.name, a.values)).collect())
    } else {
        let arrays = read_npz(path)?;
        let Some((_, [ny, nx], _)) = arrays.first() else {
            return Err(Error::input("the archive holds no arrays").in_file(path));
        };
        let grid = Grid2d::new(*nx, *ny).map_err(|e| e.in_file(path))?;
        if let Some((name, shape, _)) = arrays.iter().find(|(_, s, _)| *s != [*ny, *nx]) {
            return Err(
                Error::input(format!("array `{name}` has shape {shape:?}, the first {:?}", [*ny, *nx])).in_file(path)
            );
        }
        (grid, arrays.into_iter().map(|(n, _, v)| (n, v)).collect())
    };
    let mut take = |name: &str| -> Result<Vec<f64>> {
        let names: Vec<String> = arrays.iter().map(|(n, _)| n.clone()).collect();
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
    let roles = role
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            Role::from_code(c).ok_or_else(|| {
                let (r, col) = grid.row_col(i);
                Error::input(format!("role {c} at (row {r}, column {col}) is not one of −1, 0, 1, 2, 3")).in_file(path)
            })
        })
        .collect::<Result<Vec<Role>>>()?;
    Ok(GridOutput { grid, input, smoothed, representative, roles })
}

fn verify_grid(args: &VerifyArgs, ext: &str) -> Result<String> {
    let out = read_grid_output(&args.file, ext)?;
    let g = &out.grid;
    let n = g.nx() * g.ny();
    let mut problems = Vec::new();
    if let Some(orig) = &args.input {
        // the .vti carries the spacing the input was read with (the harmonic fill and derived
        // quantities depend on it)
        let mut opts = args.grid.clone();
        if opts.spacing.is_none() && ext == "vti" {
            opts.spacing = Some(g.spacing());
        }
        let data = read_grid(orig, &opts)?;
        if (data.grid.nx(), data.grid.ny()) != (g.nx(), g.ny()) {
            problems.push(format!(
                "{} is {} × {}, {} is {} × {}",
                orig.display(),
                data.grid.nx(),
                data.grid.ny(),
                args.file.display(),
                g.nx(),
                g.ny()
            ));
        } else if let Some(i) = (0..n).find(|&i| data.values[i].to_bits() != out.input[i].to_bits()) {
            let (r, c) = g.row_col(i);
            problems.push(format!(
                "input array differs from {} at (row {r}, column {c}): {} vs {}",
                orig.display(),
                out.input[i],
                data.values[i]
            ));
        }
    }
    if let Some(i) = out.roles.iter().position(|&r| r == Role::End || r == Role::Fixed) {
        let (r, c) = g.row_col(i);
        problems
            .push(format!("(row {r}, column {c}) has role {}: grid outputs keep extrema only", out.roles[i].code()));
    }
    if !out.roles.contains(&Role::Min) || !out.roles.contains(&Role::Max) {
        problems.push("the role array keeps no minimum or no maximum".into());
    }
    let cert = certify(g, &out.smoothed, &out.roles, Some(&out.input));
    if !cert.passed {
        problems.push(format!("smoothed: {}", cert.summary()));
    }
    let ucert = certify(g, &out.representative, &out.roles, None);
    if !ucert.passed {
        problems.push(format!("representative: {}", ucert.summary()));
    }
    if !problems.is_empty() {
        return Err(Error::Uncertified { path: Some(args.file.clone()), message: problems.join("; ") });
    }
    let kmin = out.roles.iter().filter(|&&r| r == Role::Min).count();
    let kmax = out.roles.iter().filter(|&&r| r == Role::Max).count();
    Ok(format!(
        "{}: {} ({} × {} grid, {kmin} minima and {kmax} maxima kept at their input values, representative consistent{})\n",
        args.file.display(),
        cert.summary(),
        g.nx(),
        g.ny(),
        if args.input.is_some() { ", input array matches" } else { "" }
    ))
}

fn verify_series(args: &VerifyArgs) -> Result<String> {
    let out = read_series_output(&args.file)?;
    let n = out.input.len();
    let series = Series::uniform(n);
    let mut problems = Vec::new();
    if let Some(orig) = &args.input {
        let data = read_series(orig, &args.csv)?;
        if data.values.len() != n {
            problems.push(format!(
                "{} has {} samples, {} has {n}",
                orig.display(),
                data.values.len(),
                args.file.display()
            ));
        } else if let Some(i) = (0..n).find(|&i| data.values[i].to_bits() != out.input[i].to_bits()) {
            problems.push(format!(
                "input column differs from {} at sample {i}: {} vs {}",
                orig.display(),
                out.input[i],
                data.values[i]
            ));
        }
    }
    // roles a series output can carry: free ends only at the two ends, no fixed regions, at
    // least one kept minimum and one kept maximum
    if let Some(i) = (1..n.saturating_sub(1)).find(|&i| out.roles[i] == Role::End) {
        problems.push(format!("sample {i} is marked `end` but is not an end of the series"));
    }
    if let Some(i) = out.roles.iter().position(|&r| r == Role::Fixed) {
        problems.push(format!("sample {i} is marked `fixed`: series outputs keep extrema, not regions"));
    }
    if !out.roles.contains(&Role::Min) || !out.roles.contains(&Role::Max) {
        problems.push("the role column keeps no minimum or no maximum".into());
    }
    let cert = certify(&series, &out.output, &out.roles, Some(&out.input));
    if !cert.passed {
        problems.push(format!("output: {}", cert.summary()));
    }
    let ucert = certify(&series, &out.u, &out.roles, None);
    if !ucert.passed {
        problems.push(format!("representative u: {}", ucert.summary()));
    }
    if !problems.is_empty() {
        return Err(Error::Uncertified { path: Some(args.file.clone()), message: problems.join("; ") });
    }
    let kept = out.roles.iter().filter(|r| r.is_fixed()).count();
    Ok(format!(
        "{}: {} ({n} samples, {kept} kept extrema at their input values, u consistent{})\n",
        args.file.display(),
        cert.summary(),
        if args.input.is_some() { ", input column matches" } else { "" }
    ))
}

fn verify_mesh(args: &VerifyArgs) -> Result<String> {
    let (mesh, data) = read_trimesh(&args.file)?;
    if data.arrays.iter().any(|a| a.name.starts_with("weight_") && a.name.ends_with("_raw")) {
        return verify_weights(args, &mesh, &data);
    }
    if data.arrays.iter().any(|a| a.name.starts_with("weight_") && a.name.ends_with("_interpolated")) {
        return Err(Error::Usage(format!(
            "{}: cage weights interpolated onto a shape are reported, not certified; verify the cage file `weights` wrote beside it (<output>_cage.vtu)",
            args.file.display()
        )));
    }
    let n = mesh.n_vertices();
    let take = |name: &str| -> Result<Vec<f64>> {
        let a = data.array(name).map_err(|m| {
            Error::input(format!("{m} (a verifiable output holds input, smoothed, representative, role)"))
                .in_file(&args.file)
        })?;
        if a.components != 1 || a.values.len() != n {
            return Err(Error::input(format!(
                "array `{name}` has {} components ({} values for {n} vertices); a scalar is needed",
                a.components,
                a.values.len()
            ))
            .in_file(&args.file));
        }
        Ok(a.values)
    };
    let (input, smoothed, representative, role) =
        (take("input")?, take("smoothed")?, take("representative")?, take("role")?);
    let roles = role
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            Role::from_code(c).ok_or_else(|| {
                Error::input(format!("role {c} at vertex {i} is not one of −1, 0, 1, 2, 3")).in_file(&args.file)
            })
        })
        .collect::<Result<Vec<Role>>>()?;
    let mut problems = Vec::new();
    if let Some(orig) = &args.input {
        let original = read_mesh_field(orig, &args.grid)?;
        if original.mesh.n_vertices() != n || original.mesh.faces() != mesh.faces() {
            problems.push(format!("{} is not the mesh of {}", orig.display(), args.file.display()));
        } else if let Some(i) = (0..n).find(|&i| original.values[i].to_bits() != input[i].to_bits()) {
            problems.push(format!(
                "input array differs from {} at vertex {i}: {} vs {}",
                orig.display(),
                input[i],
                original.values[i]
            ));
        }
    }
    if let Some(i) = roles.iter().position(|&r| r == Role::End || r == Role::Fixed) {
        problems.push(format!("vertex {i} has role {}: smoothing outputs keep extrema only", roles[i].code()));
    }
    if !roles.contains(&Role::Min) || !roles.contains(&Role::Max) {
        problems.push("the role array keeps no minimum or no maximum".into());
    }
    let cert = certify(&mesh, &smoothed, &roles, Some(&input));
    if !cert.passed {
        problems.push(format!("smoothed: {}", cert.summary()));
    }
    let ucert = certify(&mesh, &representative, &roles, None);
    if !ucert.passed {
        problems.push(format!("representative: {}", ucert.summary()));
    }
    if !problems.is_empty() {
        return Err(Error::Uncertified { path: Some(args.file.clone()), message: problems.join("; ") });
    }
    let kmin = roles.iter().filter(|&&r| r == Role::Min).count();
    let kmax = roles.iter().filter(|&&r| r == Role::Max).count();
    Ok(format!(
        "{}: {} (mesh of {}, {kmin} minima and {kmax} maxima kept at their input values, representative consistent{})\n",
        args.file.display(),
        cert.summary(),
        mesh.describe(),
        if args.input.is_some() { ", input array matches" } else { "" }
    ))
}

/// A weights file (SPEC.md formats): per handle `weight_<name>_raw` certified against
/// `role_<name>` (prescribed vertices: roles −1, 1, 2; a region at the largest prescribed value
/// is a maximum, at the smallest a minimum, others exempt), `u_<name>` likewise, and the
/// normalised `weight_<name>` summing to 1.
fn verify_weights(
    args: &VerifyArgs,
    mesh: &crate::domain::TriMesh,
    data: &crate::io::mesh::MeshData,
) -> Result<String> {
    use crate::verify::{certify_no_data, RegionKind};
    let n = mesh.n_vertices();
    let bad = |m: String| Error::input(m).in_file(&args.file);
    let take = |name: &str| -> Result<Vec<f64>> {
        let a = data.array(name).map_err(|m| {
            bad(format!("{m} (a weights file holds weight_<name>, weight_<name>_raw, u_<name>, role_<name>)"))
        })?;
        if a.components != 1 || a.values.len() != n {
            return Err(bad(format!("array `{name}` is not one scalar per vertex")));
        }
        Ok(a.values)
    };
    let names: Vec<String> = data
        .arrays
        .iter()
        .filter_map(|a| a.name.strip_prefix("weight_").and_then(|r| r.strip_suffix("_raw")).map(str::to_string))
        .collect();
    let mut problems = Vec::new();
    let mut sums = vec![0.0; n];
    let mut raw_sums = vec![0.0; n];
    let mut pairs: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
    let mut structure: Vec<FixedSet> = Vec::new();
    let mut lines = Vec::new();
    for name in &names {
        let raw = take(&format!("weight_{name}_raw"))?;
        let u = take(&format!("u_{name}"))?;
        let role = take(&format!("role_{name}"))?;
        let normalised = take(&format!("weight_{name}"))?;
        for v in 0..n {
            sums[v] += normalised[v];
            raw_sums[v] += raw[v];
        }
        pairs.push((name.clone(), raw.clone(), normalised.clone()));
        let mut prescribed = vec![None; n];
        for v in 0..n {
            match Role::from_code(role[v]) {
                Some(Role::Min | Role::Max | Role::Fixed) => prescribed[v] = Some(raw[v]),
                Some(Role::Other) => {}
                _ => return Err(bad(format!("role_{name}: {} at vertex {v} is not one of −1, 0, 1, 2", role[v]))),
            }
        }
        structure.push((name.clone(), prescribed.clone(), role.clone()));
        let vals: Vec<f64> = prescribed.iter().flatten().copied().collect();
        if vals.is_empty() {
            problems.push(format!("{name}: no prescribed vertex"));
            continue;
        }
        let (lo, hi) = vals.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        if lo != 0.0 || hi != 1.0 {
            problems.push(format!("{name}: the prescribed values span [{lo}, {hi}]; a weight function is 1 on its handle and 0 on the others"));
        }
        for v in 0..n {
            let r = role[v];
            if (r == 1.0 && raw[v] != hi) || (r == -1.0 && raw[v] != lo) {
                problems.push(format!("{name}: vertex {v} has role {r} but value {}", raw[v]));
                break;
            }
        }
        let kind = |x: f64| {
            if x == hi {
                RegionKind::Max
            } else if x == lo {
                RegionKind::Min
            } else {
                RegionKind::Exempt
            }
        };
        let c = certify_no_data(mesh, &raw, &prescribed, kind);
        if !c.passed {
            problems.push(format!("weight_{name}_raw: {}", c.summary()));
        }
        let cu = certify_no_data(mesh, &u, &prescribed, kind);
        if !cu.passed {
            problems.push(format!("u_{name}: {}", cu.summary()));
        }
        lines.push(format!("{name}: {} minimum and {} maximum regions", c.strict_minima, c.strict_maxima));
    }
    problems.extend(structure_problems(mesh, &structure));
    // a diffusion output: every colour inside the box of the colours at the handles
    if let (Ok(r), Ok(g), Ok(b)) = (data.array("red"), data.array("green"), data.array("blue")) {
        let rgb = [r.values, g.values, b.values];
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (_, prescribed, _) in &structure {
            for v in (0..n).filter(|&v| prescribed[v] == Some(1.0)) {
                for ch in 0..3 {
                    lo[ch] = lo[ch].min(rgb[ch][v]);
                    hi[ch] = hi[ch].max(rgb[ch][v]);
                }
            }
        }
        let outside = (0..n).filter(|&v| (0..3).any(|ch| !(rgb[ch][v] >= lo[ch] && rgb[ch][v] <= hi[ch]))).count();
        if outside > 0 {
            problems.push(format!("{outside} vertices have colours outside the box of the colours at the handles"));
        } else {
            lines.push("colours inside the handles' box".into());
        }
    }
    if let Some(v) = (0..n).find(|&v| (sums[v] - 1.0).abs().is_nan() || (sums[v] - 1.0).abs() > 1e-9) {
        problems.push(format!("the normalised weights sum to {} at vertex {v}, not 1", sums[v]));
    }
    for (name, raw, normalised) in &pairs {
        if let Some(v) = (0..n).find(|&v| {
            let d = (normalised[v] - raw[v] / raw_sums[v]).abs();
            d.is_nan() || d > 1e-12
        }) {
            problems.push(format!(
                "weight_{name} at vertex {v} is {}, not weight_{name}_raw divided by the sum of the raw weights ({})",
                normalised[v],
                raw[v] / raw_sums[v]
            ));
        }
    }
    if !problems.is_empty() {
        return Err(Error::Uncertified { path: Some(args.file.clone()), message: problems.join("; ") });
    }
    Ok(format!(
        "{}: certified: {} weight functions, every free vertex regular, every handle region a strict extremum at its prescribed value; normalised weights sum to 1 ({})\n",
        args.file.display(),
        names.len(),
        lines.join("; ")
    ))
}

/// What a weights file's fixed sets must look like beyond each function's certificate, so that
/// a role code cannot hide an extremum. A cage file fixes exactly the mesh's boundary in every
/// function. Otherwise (handles) every fixed value is 0 or 1, a single-vertex region has role
/// ±1 and the members of larger regions role 2, every function keeps a free vertex, and a
/// vertex fixed in only some functions (a part filled by the fill rule) has only fixed
/// neighbours there.
/// One function of a weights file: name, prescribed values, role codes.
type FixedSet = (String, Vec<Option<f64>>, Vec<f64>);

fn structure_problems(mesh: &crate::domain::TriMesh, functions: &[FixedSet]) -> Vec<String> {
    let n = mesh.n_vertices();
    let mut edges: Vec<(usize, usize)> = mesh
        .faces()
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])].map(|(a, b)| (a.min(b), a.max(b))))
        .collect();
    edges.sort_unstable();
    let mut boundary = vec![false; n];
    let mut i = 0;
    while i < edges.len() {
        let mut j = i;
        while j < edges.len() && edges[j] == edges[i] {
            j += 1;
        }
        if j - i == 1 {
            boundary[edges[i].0] = true;
            boundary[edges[i].1] = true;
        }
        i = j;
    }
    let cage =
        boundary.iter().any(|&b| b) && functions.iter().all(|(_, p, _)| (0..n).all(|v| p[v].is_some() == boundary[v]));
    if cage {
        return Vec::new();
    }
    let mut problems = Vec::new();
    let fixed_everywhere: Vec<bool> = (0..n).map(|v| functions.iter().all(|(_, p, _)| p[v].is_some())).collect();
    for (name, prescribed, role) in functions {
        if let Some(v) = (0..n).find(|&v| prescribed[v].is_some_and(|x| x != 0.0 && x != 1.0)) {
            problems.push(format!(
                "{name}: vertex {v} is fixed at {} (handle weights fix 0 or 1 only)",
                prescribed[v].unwrap_or(f64::NAN)
            ));
            continue;
        }
        if prescribed.iter().all(Option::is_some) {
            problems.push(format!("{name}: every vertex is fixed"));
            continue;
        }
        for region in crate::verify::fixed_regions(mesh, prescribed) {
            let expect = |v: usize| match (region.len(), prescribed[v]) {
                (1, Some(1.0)) => 1.0,
                (1, _) => -1.0,
                _ => 2.0,
            };
            if let Some(&v) = region.iter().find(|&&v| role[v] != expect(v)) {
                problems.push(format!(
                    "{name}: vertex {v} has role {} but is in a fixed region of {} vertices (expected {})",
                    role[v],
                    region.len(),
                    expect(v)
                ));
                break;
            }
        }
        if let Some(v) = (0..n).find(|&v| {
            prescribed[v].is_some() && !fixed_everywhere[v] && mesh.neighbors(v).any(|w| prescribed[w].is_none())
        }) {
            problems.push(format!(
                "{name}: vertex {v} is fixed in this function only but has a free neighbour (not a part filled by the fill rule)"
            ));
        }
    }
    problems
}
