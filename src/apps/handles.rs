//! Handles of the no-data mode (SPEC.md, "Fixed regions"): points, bones, vertex lists and
//! 2D cages, read from `handles.json` and resolved to vertex sets of a mesh.
//!
//! ```
//! use toposmooth::apps::handles::{parse_handles, resolve, HandleFile};
//! use toposmooth::domain::shapes;
//! let mesh = shapes::disk(6, 24, &[]);
//! let file = parse_handles(r#"{"handles": [{"name": "a", "point": [-0.9, 0]}, {"name": "b", "vertices": [0]}]}"#)?;
//! let HandleFile::Handles(handles) = file else { unreachable!() };
//! let sets = resolve(&mesh, &handles)?;
//! assert_eq!(sets[1], vec![0]);
//! # Ok::<(), toposmooth::Error>(())
//! ```

use crate::domain::vec3::{cross, dot, norm, sub};
use crate::domain::{Domain, TriMesh};
use crate::error::{Error, Result};

/// The shape of one handle.
#[derive(Clone, Debug, PartialEq)]
pub enum HandleShape {
    /// A point: snaps to the nearest vertex.
    Point([f64; 3]),
    /// A segment: every vertex within `radius` of it (nearest bone wins).
    Bone {
        /// End points.
        ends: [[f64; 3]; 2],
        /// Reach.
        radius: f64,
    },
    /// Explicit vertex indices (a painted region).
    Vertices(Vec<usize>),
}

/// A named handle.
#[derive(Clone, Debug, PartialEq)]
pub struct Handle {
    /// Name (used in array names: `weight_<name>`).
    pub name: String,
    /// What it selects.
    pub shape: HandleShape,
}

/// The contents of a handles file.
#[derive(Clone, Debug, PartialEq)]
pub enum HandleFile {
    /// Point, bone and region handles.
    Handles(Vec<Handle>),
    /// A closed 2D polygon around the shape: one function per cage vertex.
    Cage(Vec<[f64; 2]>),
}

fn point_of(v: &serde_json::Value, what: &str) -> Result<[f64; 3]> {
    let a = v.as_array().ok_or_else(|| Error::input(format!("{what} must be an array [x, y] or [x, y, z]")))?;
    if !(a.len() == 2 || a.len() == 3) {
        return Err(Error::input(format!("{what} has {} coordinates, expected 2 or 3", a.len())));
    }
    let mut p = [0.0; 3];
    for (k, c) in a.iter().enumerate() {
        p[k] = c
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| Error::input(format!("{what}: coordinate {k} is not a finite number")))?;
    }
    Ok(p)
}

/// Parses `handles.json` text (SPEC.md, "Formats").
///
/// # Errors
/// Malformed JSON, unknown handle kinds, missing or repeated names, bad coordinates, fewer
/// than two handles (cages: fewer than three vertices).
pub fn parse_handles(text: &str) -> Result<HandleFile> {
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| Error::input(format!("not valid JSON: {e}")))?;
    if v.get("cage").is_some() && v.get("handles").is_some() {
        return Err(Error::input("the file has both \"cage\" and \"handles\": give one"));
    }
    if let Some(cage) = v.get("cage") {
        let pts = cage.as_array().ok_or_else(|| Error::input("\"cage\" must be an array of [x, y] points"))?;
        let mut out = Vec::with_capacity(pts.len());
        for (k, p) in pts.iter().enumerate() {
            let q = point_of(p, &format!("cage vertex {k}"))?;
            if q[2] != 0.0 {
                return Err(Error::input(format!("cage vertex {k} has z = {} (cages are 2D)", q[2])));
            }
            out.push([q[0], q[1]]);
        }
        if out.len() < 3 {
            return Err(Error::input(format!("a cage needs at least 3 vertices, got {}", out.len())));
        }
        return Ok(HandleFile::Cage(out));
    }
    let list = v
        .get("handles")
        .and_then(|h| h.as_array())
        .ok_or_else(|| Error::input("expected {\"handles\": [...]} or {\"cage\": [...]}"))?;
    let mut handles: Vec<Handle> = Vec::with_capacity(list.len());
    for (k, h) in list.iter().enumerate() {
        let name = h
            .get("name")
            .and_then(|n| n.as_str())
            .ok_or_else(|| Error::input(format!("handle {k} has no \"name\"")))?
            .to_string();
        check_name(&name).map_err(|e| Error::input(format!("handle {k}: {e}")))?;
        if handles.iter().any(|o| o.name == name) {
            return Err(Error::input(format!("two handles are named `{name}`")));
        }
        let what = format!("handle `{name}`");
        let shape = if let Some(p) = h.get("point") {
            HandleShape::Point(point_of(p, &format!("{what} point"))?)
        } else if let Some(b) = h.get("bone") {
            let ends = b
                .as_array()
                .filter(|e| e.len() == 2)
                .ok_or_else(|| Error::input(format!("{what}: \"bone\" must be two points")))?;
            let radius = h
                .get("radius")
                .and_then(|r| r.as_f64())
                .ok_or_else(|| Error::input(format!("{what}: a bone needs a \"radius\" (its reach)")))?;
            if !(radius.is_finite() && radius > 0.0) {
                return Err(Error::input(format!("{what}: radius must be finite and > 0, got {radius}")));
            }
            HandleShape::Bone {
                ends: [
                    point_of(&ends[0], &format!("{what} bone end 0"))?,
                    point_of(&ends[1], &format!("{what} bone end 1"))?,
                ],
                radius,
            }
        } else if let Some(vs) = h.get("vertices") {
            let a = vs.as_array().ok_or_else(|| Error::input(format!("{what}: \"vertices\" must be an array")))?;
            let mut out = Vec::with_capacity(a.len());
            for x in a {
                out.push(
                    x.as_u64()
                        .ok_or_else(|| Error::input(format!("{what}: vertex `{x}` is not a non-negative integer")))?
                        as usize,
                );
            }
            if out.is_empty() {
                return Err(Error::input(format!("{what}: the vertex list is empty")));
            }
            HandleShape::Vertices(out)
        } else {
            return Err(Error::input(format!("{what} has none of \"point\", \"bone\", \"vertices\"")));
        };
        handles.push(Handle { name, shape });
    }
    if handles.len() < 2 {
        return Err(Error::input(format!(
            "at least two handles are needed (got {}): a single handle's weight is the constant 1",
            handles.len()
        )));
    }
    Ok(HandleFile::Handles(handles))
}

/// A handle (or colour point) name becomes part of array names (`weight_<name>_raw`, PLY
/// properties): ASCII letters, digits, `_` and `-`, not ending in `_raw` or `_interpolated`
/// (the suffixes of the other arrays).
///
/// # Errors
/// A message saying what is wrong with the name.
pub fn check_name(name: &str) -> Result<()> {
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Err(Error::input(format!(
            "name `{name}` must be non-empty ASCII letters, digits, `_` or `-` (it names arrays)"
        )));
    }
    if name.ends_with("_raw") || name.ends_with("_interpolated") {
        return Err(Error::input(format!(
            "name `{name}` must not end in `_raw` or `_interpolated` (suffixes of other arrays)"
        )));
    }
    Ok(())
}

/// Squared distance from `p` to the segment `a b`.
fn segment_distance2(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 { (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    let q = [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]];
    let d = sub(p, q);
    dot(d, d)
}

/// Distance from `p` to the triangle `a b c`.
fn triangle_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let n = cross(sub(b, a), sub(c, a));
    let nn = dot(n, n);
    if nn > 0.0 {
        // inside the prism over the triangle: the distance to the plane
        let inside = [(a, b), (b, c), (c, a)].iter().all(|&(x, y)| dot(cross(sub(y, x), sub(p, x)), n) >= 0.0);
        if inside {
            return dot(sub(p, a), n).abs() / nn.sqrt();
        }
    }
    [(a, b), (b, c), (c, a)].iter().map(|&(x, y)| segment_distance2(p, x, y)).fold(f64::INFINITY, f64::min).sqrt()
}

/// Mean edge length of a domain.
pub fn mean_edge_length<D: Domain>(d: &D) -> f64 {
    let edges = d.edges();
    let sum: f64 = edges.iter().map(|&(i, j)| norm(sub(d.point(i), d.point(j)))).sum();
    sum / edges.len().max(1) as f64
}

/// The vertex sets of the handles on `mesh`, in handle order, each sorted.
///
/// # Errors
/// (SPEC.md) a point farther than one mean edge length from the surface (planar meshes:
/// outside the shape); a bone reaching no vertex; a vertex index out of range; two handles
/// sharing a vertex (bones excepted: a vertex within reach of several bones goes to the
/// nearest, ties by handle order); a mesh component without a handle.
pub fn resolve(mesh: &TriMesh, handles: &[Handle]) -> Result<Vec<Vec<usize>>> {
    let n = mesh.n_vertices();
    let pos = mesh.positions();
    let h = mean_edge_length(mesh);
    // a flat mesh (every vertex at one z): points must lie inside the shape
    let z0 = pos.first().map_or(0.0, |p| p[2]);
    let planar = pos.iter().all(|p| p[2] == z0);
    let mut owner: Vec<Option<usize>> = vec![None; n];
    let mut sets: Vec<Vec<usize>> = vec![Vec::new(); handles.len()];
    let claim = |v: usize, k: usize, owner: &mut Vec<Option<usize>>| -> Result<()> {
        if let Some(o) = owner[v] {
            if o != k {
                return Err(Error::input(format!(
                    "handles `{}` and `{}` both select vertex {v}",
                    handles[o].name, handles[k].name
                )));
            }
        }
        owner[v] = Some(k);
        Ok(())
    };
    // bones first: each vertex within reach goes to its nearest bone
    let mut best: Vec<(f64, usize)> = vec![(f64::INFINITY, usize::MAX); n];
    for (k, handle) in handles.iter().enumerate() {
        if let HandleShape::Bone { ends, radius } = &handle.shape {
            let mut any = false;
            for v in 0..n {
                let d2 = segment_distance2(pos[v], ends[0], ends[1]);
                if d2 <= radius * radius {
                    any = true;
                    if d2 < best[v].0 {
                        best[v] = (d2, k);
                    }
                }
            }
            if !any {
                return Err(Error::input(format!(
                    "handle `{}`: no vertex lies within {radius} of the bone (the nearest is {:.6} away)",
                    handle.name,
                    (0..n).map(|v| segment_distance2(pos[v], ends[0], ends[1])).fold(f64::INFINITY, f64::min).sqrt()
                )));
            }
        }
    }
    for v in 0..n {
        if best[v].1 != usize::MAX {
            owner[v] = Some(best[v].1);
        }
    }
    for (k, handle) in handles.iter().enumerate() {
        match &handle.shape {
            HandleShape::Bone { .. } => {}
            HandleShape::Vertices(list) => {
                for &v in list {
                    if v >= n {
                        return Err(Error::input(format!(
                            "handle `{}`: vertex {v} is out of range (the mesh has {n} vertices)",
                            handle.name
                        )));
                    }
                    claim(v, k, &mut owner)?;
                }
            }
            HandleShape::Point(p) => {
                // on a flat mesh a point given in 2D (z = 0) lies in the mesh's plane
                let p = &if planar && p[2] == 0.0 { [p[0], p[1], z0] } else { *p };
                let v = (0..n)
                    .min_by(|&a, &b| norm(sub(pos[a], *p)).total_cmp(&norm(sub(pos[b], *p))))
                    .expect("a mesh has vertices");
                let d = mesh
                    .faces()
                    .iter()
                    .map(|t| triangle_distance(*p, pos[t[0]], pos[t[1]], pos[t[2]]))
                    .fold(f64::INFINITY, f64::min);
                let limit = if planar { 1e-9 * mesh.diameter() } else { h };
                if d > limit {
                    return Err(Error::input(format!(
                        "handle `{}`: the point {:?} is {} from the {} (limit {})",
                        handle.name,
                        p,
                        d,
                        if planar { "shape: it lies outside" } else { "surface" },
                        if planar { "inside the shape".to_string() } else { format!("one mean edge length, {h}") }
                    )));
                }
                claim(v, k, &mut owner)?;
            }
        }
    }
    for (v, o) in owner.iter().enumerate() {
        if let Some(k) = *o {
            sets[k].push(v);
        }
    }
    if let Some(k) = sets.iter().position(|s| s.is_empty()) {
        return Err(Error::input(format!(
            "handle `{}`: every vertex within its reach is nearer to another bone (or is another handle's)",
            handles[k].name
        )));
    }
    // every component needs a handle
    let comp = mesh.components();
    let mut has = vec![false; mesh.n_components()];
    for v in 0..n {
        if owner[v].is_some() {
            has[comp[v]] = true;
        }
    }
    if let Some(c) = has.iter().position(|x| !x) {
        let v = (0..n).find(|&v| comp[v] == c).unwrap_or(0);
        return Err(Error::input(format!(
            "mesh component {c} (containing vertex {v}) has no handle: its weights would be undetermined"
        )));
    }
    Ok(sets)
}

/// `count` (at least 2) vertices spread over the points by farthest-point sampling, from the
/// point farthest from the centroid (the bench's and the tests' point handles).
pub fn farthest_points(p: &[[f64; 3]], count: usize) -> Vec<usize> {
    let n = p.len();
    if n == 0 {
        return Vec::new();
    }
    let c = p.iter().fold([0.0; 3], |a, q| [a[0] + q[0], a[1] + q[1], a[2] + q[2]]).map(|x| x / n as f64);
    let d2 = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>();
    let first = (0..n).max_by(|&a, &b| d2(p[a], c).total_cmp(&d2(p[b], c))).unwrap_or(0);
    let mut chosen = vec![first];
    let mut dist: Vec<f64> = (0..n).map(|v| d2(p[v], p[first])).collect();
    while chosen.len() < count.max(2).min(n) {
        let next = (0..n).max_by(|&a, &b| dist[a].total_cmp(&dist[b])).unwrap_or(0);
        chosen.push(next);
        for v in 0..n {
            dist[v] = dist[v].min(d2(p[v], p[next]));
        }
    }
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::shapes;

    fn handles(text: &str) -> Vec<Handle> {
        match parse_handles(text).unwrap() {
            HandleFile::Handles(h) => h,
            HandleFile::Cage(_) => panic!("not handles"),
        }
    }

    #[test]
    fn parses_every_kind_and_rejects_bad_files() {
        let h = handles(
            r#"{"handles": [{"name": "head", "point": [0, 0, 1]}, {"name": "arm", "bone": [[0,0,0],[1,0,0]], "radius": 0.1},
                {"name": "tail", "vertices": [3, 4]}]}"#,
        );
        assert_eq!(h.len(), 3);
        assert_eq!(h[0].shape, HandleShape::Point([0.0, 0.0, 1.0]));
        assert!(matches!(h[1].shape, HandleShape::Bone { radius, .. } if radius == 0.1));
        assert_eq!(h[2].shape, HandleShape::Vertices(vec![3, 4]));
        assert!(
            matches!(parse_handles(r#"{"cage": [[0,0],[1,0],[1,1]]}"#).unwrap(), HandleFile::Cage(c) if c.len() == 3)
        );
        for bad in [
            "",
            "{}",
            r#"{"handles": [{"name": "a", "point": [0,0]}]}"#,
            r#"{"handles": [{"name": "a", "point": [0,0]}, {"name": "a", "point": [1,0]}]}"#,
            r#"{"handles": [{"name": "a", "point": [0]}, {"name": "b", "point": [1,0]}]}"#,
            r#"{"handles": [{"name": "a", "bone": [[0,0],[1,0]]}, {"name": "b", "point": [1,0]}]}"#,
            r#"{"handles": [{"name": "a", "vertices": [-1]}, {"name": "b", "point": [1,0]}]}"#,
            r#"{"handles": [{"name": "a b", "point": [0,0]}, {"name": "b", "point": [1,0]}]}"#,
            r#"{"cage": [[0,0],[1,0]]}"#,
        ] {
            assert!(parse_handles(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn resolves_points_bones_and_lists_with_the_spec_errors() {
        let mesh = shapes::disk(8, 32, &[]); // unit disk, vertex 0 at the centre
        let h = handles(
            r#"{"handles": [{"name": "c", "point": [0.01, 0]}, {"name": "bar", "bone": [[0.5,-0.2],[0.5,0.2]], "radius": 0.15},
                {"name": "rim", "bone": [[0.55,-0.2],[0.55,0.2]], "radius": 0.15}]}"#,
        );
        let sets = resolve(&mesh, &h).unwrap();
        assert_eq!(sets[0], vec![0]);
        assert!(!sets[1].is_empty() && !sets[2].is_empty());
        for &v in &sets[1] {
            let p = mesh.positions()[v];
            assert!((p[0] - 0.5).abs() <= (p[0] - 0.55).abs()); // nearest bone wins
        }
        let err = |text: &str| resolve(&mesh, &handles(text)).unwrap_err().to_string();
        assert!(
            err(r#"{"handles": [{"name": "a", "point": [2, 0]}, {"name": "b", "point": [0,0]}]}"#).contains("outside")
        );
        assert!(err(r#"{"handles": [{"name": "a", "point": [0.001, 0]}, {"name": "b", "point": [0,0]}]}"#)
            .contains("both select vertex 0"));
        assert!(err(r#"{"handles": [{"name": "a", "vertices": [0, 1]}, {"name": "b", "vertices": [1]}]}"#)
            .contains("both select vertex 1"));
        assert!(err(r#"{"handles": [{"name": "a", "vertices": [100000]}, {"name": "b", "vertices": [1]}]}"#)
            .contains("out of range"));
        assert!(err(
            r#"{"handles": [{"name": "a", "bone": [[5,5],[6,5]], "radius": 0.1}, {"name": "b", "vertices": [1]}]}"#
        )
        .contains("no vertex"));
    }

    #[test]
    fn a_flat_mesh_off_the_z0_plane_still_refuses_points_outside_it() {
        let d = shapes::disk(4, 16, &[]);
        let lifted: Vec<[f64; 3]> = d.positions().iter().map(|p| [p[0], p[1], 5.0]).collect();
        let mesh = TriMesh::new(lifted, d.faces().to_vec()).unwrap();
        let ok = handles(r#"{"handles": [{"name": "a", "point": [0.5, 0]}, {"name": "b", "point": [-0.5, 0, 5]}]}"#);
        assert_eq!(resolve(&mesh, &ok).unwrap().len(), 2);
        let out = handles(r#"{"handles": [{"name": "a", "point": [1.3, 0]}, {"name": "b", "point": [-0.5, 0]}]}"#);
        assert!(resolve(&mesh, &out).unwrap_err().to_string().contains("outside"));
    }

    #[test]
    fn a_component_without_a_handle_is_an_error() {
        let a = shapes::disk(3, 12, &[]);
        let (mut pos, mut tris) = (a.positions().to_vec(), a.faces().to_vec());
        let off = pos.len();
        pos.extend(a.positions().iter().map(|p| [p[0] + 5.0, p[1], p[2]]));
        tris.extend(a.faces().iter().map(|t| [t[0] + off, t[1] + off, t[2] + off]));
        let mesh = TriMesh::new(pos, tris).unwrap();
        let h = handles(r#"{"handles": [{"name": "a", "vertices": [0]}, {"name": "b", "vertices": [1]}]}"#);
        assert!(resolve(&mesh, &h).unwrap_err().to_string().contains("has no handle"));
    }
}
