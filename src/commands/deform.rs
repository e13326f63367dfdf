//! `toposmooth deform MESH --weights weights.vtu --transforms pose.json -o posed.obj`: linear
//! blend or dual-quaternion skinning with the weights `weights` wrote.

use super::sig6;
use crate::apps::skinning::{check_transforms, parse_pose, skin_named, Skinning, Transform};
use crate::domain::TriMesh;
use crate::error::{Error, Result};
use crate::io::import::read_trimesh;
use crate::io::Staged;
use crate::plot::{plot_mesh_fields, GridPanel, MeshView};
use std::path::PathBuf;

/// Options of `deform`.
#[derive(Clone, Debug)]
pub struct DeformArgs {
    /// The rest mesh.
    pub input: PathBuf,
    /// The weights file (`weight_<name>` arrays, as `weights` writes them).
    pub weights: PathBuf,
    /// pose.json.
    pub transforms: PathBuf,
    /// Posed mesh (.obj, .off, .ply, .vtu, .vtp).
    pub output: PathBuf,
    /// LBS or DQS.
    pub skinning: Skinning,
    /// Rest and posed shapes side by side.
    pub plot: Option<PathBuf>,
    /// Camera of the picture.
    pub view: MeshView,
}

/// The normalised weight arrays `weight_<name>` of a weights file (not `_raw`), by name.
fn read_weights(args: &DeformArgs, mesh: &TriMesh) -> Result<Vec<(String, Vec<f64>)>> {
    let (wmesh, data) = read_trimesh(&args.weights)?;
    if wmesh.positions().len() != mesh.positions().len() || wmesh.faces() != mesh.faces() {
        return Err(Error::input(format!(
            "the weights were computed on another mesh ({} vertices, {} triangles; {} has {} and {})",
            wmesh.positions().len(),
            wmesh.faces().len(),
            args.input.display(),
            mesh.positions().len(),
            mesh.faces().len()
        ))
        .in_file(&args.weights));
    }
    let out: Vec<(String, Vec<f64>)> = data
        .arrays
        .iter()
        .filter_map(|a| {
            let name = a.name.strip_prefix("weight_")?;
            (!name.ends_with("_raw") && !name.ends_with("_interpolated") && a.components == 1)
                .then(|| (name.to_string(), a.values.clone()))
        })
        .collect();
    if out.len() < 2 {
        return Err(Error::input(format!(
            "{} weight_<name> arrays found, at least two needed (write them with `toposmooth weights`)",
            out.len()
        ))
        .in_file(&args.weights));
    }
    Ok(out)
}

/// Runs `deform`.
pub fn deform(args: &DeformArgs) -> Result<String> {
    super::check_distinct(
        &[args.input.as_path(), args.weights.as_path(), args.transforms.as_path()],
        &[("-o", Some(&args.output)), ("--plot", args.plot.as_deref())],
    )?;
    let ext = args.output.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if !["obj", "off", "ply", "vtu", "vtp"].contains(&ext.as_str()) {
        return Err(Error::Usage(format!(
            "{}: a posed mesh is written as .obj, .off, .ply, .vtu or .vtp",
            args.output.display()
        )));
    }
    let (mesh, _) = read_trimesh(&args.input)?;
    let weights = read_weights(args, &mesh)?;
    let text = std::fs::read_to_string(&args.transforms)
        .map_err(|source| Error::Io { path: args.transforms.clone(), source })?;
    let pose = parse_pose(&text).map_err(|e| e.in_file(&args.transforms))?;
    if let Some((name, _)) = pose.iter().find(|(n, _)| !weights.iter().any(|(w, _)| w == n)) {
        let known: Vec<&str> = weights.iter().map(|(n, _)| n.as_str()).collect();
        return Err(Error::input(format!(
            "transform `{name}` names no handle of {} (handles: {})",
            args.weights.display(),
            known.join(", ")
        ))
        .in_file(&args.transforms));
    }
    let mut notes = Vec::new();
    let transforms: Vec<Transform> = weights
        .iter()
        .map(|(name, _)| match pose.iter().find(|(n, _)| n == name) {
            Some((_, t)) => *t,
            None => {
                notes.push(format!("handle `{name}` has no transform: it stays at rest"));
                Transform::identity()
            }
        })
        .collect();
    let names: Vec<&str> = weights.iter().map(|(n, _)| n.as_str()).collect();
    let w: Vec<Vec<f64>> = weights.iter().map(|(_, v)| v.clone()).collect();
    // a transform's problems belong to the pose file, everything else to the weights
    check_transforms(&transforms, &names, args.skinning).map_err(|e| e.in_file(&args.transforms))?;
    let (posed, warnings) =
        skin_named(mesh.positions(), &w, &transforms, &names, args.skinning).map_err(|e| e.in_file(&args.weights))?;
    let posed_mesh = TriMesh::new(posed.clone(), mesh.faces().to_vec());
    let mut staged: Vec<Staged> = vec![stage_geometry(&args.output, &posed, mesh.faces())?];
    if let Some(path) = &args.plot {
        staged.push(stage_picture(path, args, &mesh, &posed, &w, &transforms, &names)?);
    }
    crate::io::commit_all(staged)?;
    let max_move = mesh
        .positions()
        .iter()
        .zip(&posed)
        .map(|(a, b)| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt())
        .fold(0.0, f64::max);
    let mut text = String::new();
    for n in notes.iter().chain(&warnings) {
        text += &format!("warning: {n}\n");
    }
    if let Err(e) = posed_mesh {
        text += &format!("warning: the posed mesh fails validation: {e}\n");
    }
    text += &format!(
        "{}: {} vertices posed by {} handles ({:?}); largest displacement {}\n",
        args.input.display(),
        mesh.positions().len(),
        weights.len(),
        args.skinning,
        sig6(max_move)
    );
    text += &super::wrote_line([Some(&args.output), args.plot.as_ref()]);
    Ok(text)
}

/// The picture: rest and posed meshes side by side in one scene, coloured by the weight of
/// the most moved handle.
fn stage_picture(
    path: &std::path::Path,
    args: &DeformArgs,
    mesh: &TriMesh,
    posed: &[[f64; 3]],
    w: &[Vec<f64>],
    transforms: &[Transform],
    names: &[&str],
) -> Result<Staged> {
    // the most moved handle colours the picture
    let moved = transforms
        .iter()
        .enumerate()
        .map(|(h, t)| {
            let d: f64 = (0..3)
                .flat_map(|r| (0..4).map(move |c| (r, c)))
                .map(|(r, c)| {
                    let id = if r == c { 1.0 } else { 0.0 };
                    (t.0[r][c] - id).powi(2)
                })
                .sum();
            (h, d)
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0, |x| x.0);
    // rest and posed meshes side by side in one scene
    let (lo, hi) = bounds(mesh.positions());
    let shift = 1.25 * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let (pl, _) = bounds(posed);
    let dx = shift + lo[0] - pl[0];
    let mut positions = mesh.positions().to_vec();
    positions.extend(posed.iter().map(|p| [p[0] + dx, p[1], p[2]]));
    let nv = mesh.positions().len();
    let mut tris = mesh.faces().to_vec();
    tris.extend(mesh.faces().iter().map(|t| t.map(|v| v + nv)));
    let mut values = w[moved].clone();
    values.extend_from_slice(&w[moved]);
    let panel = [GridPanel {
        title: format!("rest | posed ({:?}), coloured by weight_{}", args.skinning, names[moved]),
        values: &values,
    }];
    let title = format!(
        "{} posed by {}",
        args.input.file_name().unwrap_or_default().to_string_lossy(),
        args.transforms.display()
    );
    super::stage_plot(path, |p| {
        plot_mesh_fields(p, &positions, &tris, &panel, &[], &title, args.view, false)?;
        Ok(())
    })
}

/// Stages a mesh without arrays in the format its extension names, read back before commit
/// (certificate item 5: the same positions bit for bit and as many triangles).
fn stage_geometry(path: &std::path::Path, positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Result<Staged> {
    use crate::io::mesh::{stage_obj, stage_off, stage_ply};
    use crate::io::vtk::{stage_vtp, stage_vtu, PolyData};
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let staged = match ext.as_str() {
        "obj" => stage_obj(path, positions, triangles),
        "off" => stage_off(path, positions, triangles),
        "ply" => stage_ply(path, positions, triangles, &[]),
        "vtu" => stage_vtu(path, positions, triangles, &[]),
        "vtp" => {
            stage_vtp(path, &PolyData { points: positions.to_vec(), polys: triangles.to_vec(), ..Default::default() })
        }
        _ => {
            Err(Error::Usage(format!("{}: a posed mesh is written as .obj, .off, .ply, .vtu or .vtp", path.display())))
        }
    }?;
    crate::io::export::check_mesh_written(&staged, positions, triangles, &[])?;
    Ok(staged)
}

fn bounds(p: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in p {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    (lo, hi)
}
