//! `toposmooth verify`: re-check an output file from what it carries, independently of `smooth`.

use crate::domain::{AnyDomain, Domain};
use crate::error::{Error, Result};
use crate::io::export::{read_results, results_on_mesh, Stored, MESH_OUTPUTS};
use crate::io::import::{read_field, DomainKind, ReadOptions};
use crate::topology::Role;
use crate::verify::certify_any;
use std::path::{Path, PathBuf};

/// Options of `verify`.
#[derive(Clone, Debug)]
pub struct VerifyArgs {
    /// The output file to check.
    pub file: PathBuf,
    /// The original input, to compare with the file's input column.
    pub input: Option<PathBuf>,
    /// How to read the original input (its domain is the file's).
    pub read: ReadOptions,
}

/// Runs `verify`: `Ok(text)` when the file is certified, [`Error::Uncertified`] (exit 1) when not.
pub fn verify(args: &VerifyArgs) -> Result<String> {
    let ext = args.file.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    crate::io::content::check_extension(&args.file)?;
    match ext.as_str() {
        // a legacy .vtk is a mesh's output or a grid's
        e if MESH_OUTPUTS.contains(&e) && (e != "vtk" || crate::io::mesh::is_mesh_file(&args.file)) => {
            let (mesh, data) = crate::io::mesh::read_any_mesh(&args.file)?;
            let mesh = match mesh {
                crate::io::mesh::AnyMesh::Tri(m) => m,
                tets => return verify_results(args, results_on_mesh(&args.file, tets.into_domain(), &data)?),
            };
            if data.arrays.iter().any(|a| a.name.starts_with("weight_") && a.name.ends_with("_raw")) {
                return verify_weights(args, &mesh, &data);
            }
            if data.arrays.iter().any(|a| a.name.starts_with("weight_") && a.name.ends_with("_interpolated")) {
                return Err(Error::Usage(format!(
                    "{}: cage weights interpolated onto a shape are reported, not certified; verify the cage file `weights` wrote beside it (<output>_cage.vtu)",
                    args.file.display()
                )));
            }
            verify_results(args, results_on_mesh(&args.file, AnyDomain::Mesh(mesh), &data)?)
        }
        "obj" | "off" if crate::io::mesh::is_mesh_file(&args.file) => Err(Error::Usage(format!(
            "{}: a mesh file holds no smoothing output; verify the .vtu, .vtp or .ply that `smooth` wrote",
            args.file.display()
        ))),
        "png" | "tif" | "tiff" => Err(Error::Usage(format!(
            "{}: an image holds no smoothing output (plots are views, not certified arrays); verify the .csv, .vti, .npz, .vtu, .vtp or .ply that `smooth` wrote",
            args.file.display()
        ))),
        "npy" => Err(Error::Usage(format!(
            "{}: a .npy export holds the smoothed array only and cannot be verified alone; verify the .vti or .npz output",
            args.file.display()
        ))),
        _ => verify_results(args, read_results(&args.file)?),
    }
}

/// Checks a smoothing result read back from its file, on any domain: the input matches the
/// original (when given), the roles are those a smoothing output carries, and the smoothed
/// and representative arrays have exactly the kept extrema.
fn verify_results(args: &VerifyArgs, out: Stored) -> Result<String> {
    let d = &out.domain;
    let series = matches!(d, AnyDomain::Series(_));
    let mut problems = Vec::new();
    if let Some(orig) = &args.input {
        problems.extend(compare_input(args, orig, &out)?);
    }
    let n = out.roles.len();
    for (i, &role) in out.roles.iter().enumerate() {
        let allowed = match role {
            Role::End => series && (i == 0 || i + 1 == n),
            Role::Fixed => false,
            _ => true,
        };
        if !allowed {
            problems.push(format!(
                "{} has role {} ({}): smoothing outputs keep extrema only{}",
                d.describe_vertex(i),
                role.code(),
                role.label(),
                if role == Role::End { " (and series their two ends)" } else { "" }
            ));
            break;
        }
    }
    if let Some(i) = out.filled.as_ref().and_then(|f| {
        (0..n).find(|&i| f.get(i).copied().unwrap_or(false) && matches!(out.roles[i], Role::Min | Role::Max))
    }) {
        problems.push(format!(
            "{} is a kept {} but was filled (column `filled`): a kept extremum must be a sample the input gives",
            d.describe_vertex(i),
            out.roles[i].label()
        ));
    }
    if out.filled.as_ref().is_some_and(|f| f.len() != n) {
        problems.push("the `filled` column does not have one entry per sample".into());
    }
    if !out.roles.contains(&Role::Min) || !out.roles.contains(&Role::Max) {
        problems.push("the role array keeps no minimum or no maximum".into());
    }
    let unchanged = |v: usize| {
        out.roles[v] == Role::Other
            && out.smoothed[v].to_bits() == out.input[v].to_bits()
            && out.representative[v].to_bits() == out.input[v].to_bits()
    };
    // a masked volume or grid: the domain is the mask's tetrahedra or triangles, the rest
    // written unchanged
    let masked = match (&out.mask, d) {
        (Some(mask), AnyDomain::Volume(g)) => {
            let m = crate::domain::MaskedVolume::new(g, mask).map_err(|e| e.in_file(&args.file))?;
            Some(certify_masked(m.mesh(), &m, &out, "voxels"))
        }
        (Some(mask), AnyDomain::Grid(g)) => {
            let m = crate::domain::MaskedGrid::new(g, mask).map_err(|e| e.in_file(&args.file))?;
            Some(certify_masked(m.mesh(), &m, &out, "pixels"))
        }
        _ => None,
    };
    let (cert, ucert, within) = match masked {
        Some((used, cert, ucert, within)) => {
            if let Some(v) = (0..n).find(|&v| !used[v] && !unchanged(v)) {
                problems.push(format!(
                    "{} lies outside the mask's domain but is not written unchanged with role 0",
                    d.describe_vertex(v)
                ));
            }
            (cert, ucert, within)
        }
        None => (
            certify_any(d, &out.smoothed, &out.roles, Some(&out.input)),
            certify_any(d, &out.representative, &out.roles, None),
            String::new(),
        ),
    };
    if !cert.passed {
        problems.push(format!("smoothed: {}", cert.summary()));
    }
    if !ucert.passed {
        problems.push(format!("representative: {}", ucert.summary()));
    }
    if !problems.is_empty() {
        return Err(Error::Uncertified { path: Some(args.file.clone()), message: problems.join("; ") });
    }
    let kmin = out.roles.iter().filter(|&&r| r == Role::Min).count();
    let kmax = out.roles.iter().filter(|&&r| r == Role::Max).count();
    Ok(format!(
        "{}: {} ({}{within}, {kmin} minima and {kmax} maxima kept at their input values, representative consistent{})\n",
        args.file.display(),
        cert.summary(),
        d.describe(),
        if args.input.is_some() { ", input matches" } else { "" }
    ))
}

/// The certificates of a masked result's smoothed and representative arrays on the mask's
/// domain, the domain's grid points, and the summary's words for it.
fn certify_masked<D: crate::domain::Domain>(
    mesh: &D,
    on: &crate::domain::Restriction,
    out: &Stored,
    points: &str,
) -> (Vec<bool>, crate::Certificate, crate::Certificate, String) {
    let roles = on.restrict(&out.roles);
    (
        on.used().to_vec(),
        crate::verify::certify(mesh, &on.restrict(&out.smoothed), &roles, Some(&on.restrict(&out.input))),
        crate::verify::certify(mesh, &on.restrict(&out.representative), &roles, None),
        format!(" inside a mask of {} {points}", on.voxels().len()),
    )
}

/// Compares the result's `input` with the original file read as the result's domain. A `.vti`
/// carries the spacing the input was read with (the harmonic fill and derived quantities
/// depend on it), so a grid original is read with it unless `--spacing` says otherwise.
fn compare_input(args: &VerifyArgs, orig: &Path, out: &Stored) -> Result<Option<String>> {
    let mut opts = args.read.clone();
    let kind = match &out.domain {
        AnyDomain::Series(_) => {
            // the file says which samples were filled: the original is read with them filled
            opts.fill_missing |= out.filled.is_some();
            DomainKind::Series
        }
        AnyDomain::Grid(g) => {
            let vti = args.file.extension().is_some_and(|e| e.eq_ignore_ascii_case("vti"));
            if opts.spacing.is_none() && vti {
                opts.spacing = Some(g.spacing().to_vec());
            }
            DomainKind::Grid
        }
        AnyDomain::Volume(g) => {
            let vti = args.file.extension().is_some_and(|e| e.eq_ignore_ascii_case("vti"));
            if opts.spacing.is_none() && vti {
                opts.spacing = Some(g.spacing().to_vec());
            }
            DomainKind::Grid
        }
        AnyDomain::Mesh(_) | AnyDomain::Tets(_) => DomainKind::Mesh,
    };
    opts.domain = kind;
    let original = read_field(Some(orig), &opts)?.into_field(orig)?;
    let (file, o) = (args.file.display(), orig.display());
    let same = match (&original.domain, &out.domain) {
        (AnyDomain::Series(a), AnyDomain::Series(b)) => a.n_vertices() == b.n_vertices(),
        (AnyDomain::Grid(a), AnyDomain::Grid(b)) => (a.nx(), a.ny()) == (b.nx(), b.ny()),
        (AnyDomain::Volume(a), AnyDomain::Volume(b)) => a.dims() == b.dims(),
        (AnyDomain::Mesh(a), AnyDomain::Mesh(b)) => a.n_vertices() == b.n_vertices() && a.faces() == b.faces(),
        (AnyDomain::Tets(a), AnyDomain::Tets(b)) => a.n_vertices() == b.n_vertices() && a.tets() == b.tets(),
        _ => false,
    };
    if !same {
        return Ok(Some(format!("{o} is a {}, {file} a {}", original.domain.describe(), out.domain.describe())));
    }
    Ok((0..out.input.len()).find(|&i| original.values[i].to_bits() != out.input[i].to_bits()).map(|i| {
        format!(
            "input differs from {o} at {}: {} vs {}",
            out.domain.describe_vertex(i),
            out.input[i],
            original.values[i]
        )
    }))
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
        let check = check_weight_function(mesh, name, &raw, &u, &role, &bad)?;
        structure.push((name.clone(), check.prescribed, role));
        problems.extend(check.problems);
        lines.extend(check.line);
    }
    problems.extend(structure_problems(mesh, &structure));
    // a diffusion output: every colour inside the box of the colours at the handles
    match colours_outside(data, &structure, n) {
        Some(0) => lines.push("colours inside the handles' box".into()),
        Some(outside) => {
            problems.push(format!("{outside} vertices have colours outside the box of the colours at the handles"))
        }
        None => {}
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

/// What [`check_weight_function`] found.
struct FunctionCheck {
    /// The prescribed values (roles −1, 1, 2).
    prescribed: Vec<Option<f64>>,
    problems: Vec<String>,
    /// The summary line (none when nothing is prescribed).
    line: Option<String>,
}

/// One function of a weights file: its prescribed values (roles −1, 1, 2) in `raw` span
/// exactly [0, 1], roles ±1 sit at the extreme values, and `raw` and `u` pass the no-data
/// certificate. Returns the prescribed values, the problems and the summary line.
fn check_weight_function(
    mesh: &crate::domain::TriMesh,
    name: &str,
    raw: &[f64],
    u: &[f64],
    role: &[f64],
    bad: &dyn Fn(String) -> Error,
) -> Result<FunctionCheck> {
    use crate::verify::{certify_no_data, RegionKind};
    let n = raw.len();
    let mut problems = Vec::new();
    let mut prescribed = vec![None; n];
    for v in 0..n {
        match Role::from_code(role[v]) {
            Some(Role::Min | Role::Max | Role::Fixed) => prescribed[v] = Some(raw[v]),
            Some(Role::Other) => {}
            _ => return Err(bad(format!("role_{name}: {} at vertex {v} is not one of −1, 0, 1, 2", role[v]))),
        }
    }
    let vals: Vec<f64> = prescribed.iter().flatten().copied().collect();
    if vals.is_empty() {
        return Ok(FunctionCheck { prescribed, problems: vec![format!("{name}: no prescribed vertex")], line: None });
    }
    let (lo, hi) = vals.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    if lo != 0.0 || hi != 1.0 {
        problems.push(format!(
            "{name}: the prescribed values span [{lo}, {hi}]; a weight function is 1 on its handle and 0 on the others"
        ));
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
    let c = certify_no_data(mesh, raw, &prescribed, kind);
    if !c.passed {
        problems.push(format!("weight_{name}_raw: {}", c.summary()));
    }
    let cu = certify_no_data(mesh, u, &prescribed, kind);
    if !cu.passed {
        problems.push(format!("u_{name}: {}", cu.summary()));
    }
    let line = format!("{name}: {} minimum and {} maximum regions", c.strict_minima, c.strict_maxima);
    Ok(FunctionCheck { prescribed, problems, line: Some(line) })
}

/// A diffusion output's vertices whose colour lies outside the per-channel box of the colours
/// at the handles (`None`: the file has no colours).
fn colours_outside(data: &crate::io::mesh::MeshData, structure: &[FixedSet], n: usize) -> Option<usize> {
    let (Ok(r), Ok(g), Ok(b)) = (data.array("red"), data.array("green"), data.array("blue")) else {
        return None;
    };
    let rgb = [r.values, g.values, b.values];
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (_, prescribed, _) in structure {
        for v in (0..n).filter(|&v| prescribed[v] == Some(1.0)) {
            for ch in 0..3 {
                lo[ch] = lo[ch].min(rgb[ch][v]);
                hi[ch] = hi[ch].max(rgb[ch][v]);
            }
        }
    }
    Some((0..n).filter(|&v| (0..3).any(|ch| !(rgb[ch][v] >= lo[ch] && rgb[ch][v] <= hi[ch]))).count())
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
