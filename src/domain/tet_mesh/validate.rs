//! Checks of a tetrahedral mesh as read: the elements (counts, coordinates, indices, volumes,
//! duplicates, unused and coincident vertices), the triangles (at most two tetrahedra each),
//! the edges (one fan each) and the vertices (one ball each). Messages name the first
//! offending elements; each error carries the first as its [`Location`].

use crate::domain::vec3::signed_volume6;
use crate::domain::vec3::{norm, sub};
use crate::error::{Error, Location, Result};

/// At most this many offending elements are named in a message.
const SHOW: usize = 5;

fn list<T: std::fmt::Display>(items: &[T]) -> String {
    let shown: Vec<String> = items.iter().take(SHOW).map(|x| x.to_string()).collect();
    if items.len() > SHOW {
        format!("{}, … ({} in all)", shown.join(", "), items.len())
    } else {
        shown.join(", ")
    }
}

/// The six edges of a tetrahedron as pairs of its corners; edge `m` of tetrahedron `t` is the
/// edge-corner `6t + m`.
const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Local edge index of the corners `i ≠ j` (in `0..4`).
fn pair_index(i: usize, j: usize) -> usize {
    let (i, j) = (i.min(j), i.max(j));
    PAIRS.iter().position(|&p| p == (i, j)).expect("two distinct corners")
}

/// Position of vertex `v` among the corners of `tet`.
fn corner(tet: &[usize; 4], v: usize) -> usize {
    tet.iter().position(|&x| x == v).expect("a corner of the tetrahedron")
}

/// `6 ×` the largest absolute volume that counts as zero for a tetrahedron whose longest edge
/// is `longest`.
///
/// Zero volume is judged against the tetrahedron's own size: `|6V| ≤ 10⁻¹² L³`, `L` its
/// longest edge (a regular tetrahedron has `6V = L³/√2`, so this refuses shapes ~10¹² times
/// flatter). An exact orientation predicate (Shewchuk's orient3d) was not chosen: it only
/// refuses exactly coplanar corners and lets through slivers whose volume is rounding noise,
/// whose gradients and dihedral cotangents (the stiffness) are then meaningless. The
/// threshold also makes the sign of the double-precision determinant trustworthy: computed
/// from the edge vectors, its rounding error is at most about `10⁻¹⁵ L³`, far below
/// `10⁻¹² L³`, so the orientation repair never reorients a tetrahedron because of rounding.
/// It is per tetrahedron (not relative to the bounding box, as for triangles), so a finely
/// meshed region of a large domain is not refused.
fn zero_volume6(longest: f64) -> f64 {
    1e-12 * longest * longest * longest
}

/// Checks the elements; returns the bounding-box diagonal (the domain's diameter bound).
pub(super) fn check_elements(positions: &[[f64; 3]], tets: &[[usize; 4]]) -> Result<f64> {
    let n = positions.len();
    if n == 0 || tets.is_empty() {
        return Err(Error::input(format!(
            "the mesh has {n} vertices and {} tetrahedra: it needs at least one tetrahedron",
            tets.len()
        )));
    }
    let bad: Vec<usize> = (0..n).filter(|&v| positions[v].iter().any(|x| !x.is_finite())).collect();
    if !bad.is_empty() {
        return Err(
            Error::input(format!("non-finite coordinates at vertices {}", list(&bad))).at(Location::Vertex(bad[0]))
        );
    }
    let refuse = |bad: &[usize], what: &str| -> Result<()> {
        match bad.first() {
            None => Ok(()),
            Some(&t) => {
                Err(Error::input(format!("tetrahedra {} {what} (e.g. tetrahedron {t} = {:?})", list(bad), tets[t]))
                    .at(Location::Tetrahedron(t)))
            }
        }
    };
    let bad: Vec<usize> = (0..tets.len()).filter(|&t| tets[t].iter().any(|&v| v >= n)).collect();
    refuse(&bad, &format!("use a vertex index beyond the {n} vertices"))?;
    let bad: Vec<usize> = (0..tets.len()).filter(|&t| PAIRS.iter().any(|&(i, j)| tets[t][i] == tets[t][j])).collect();
    refuse(&bad, "repeat a corner")?;
    let bad: Vec<usize> = (0..tets.len())
        .filter(|&t| {
            let p = tets[t].map(|v| positions[v]);
            let longest = PAIRS.iter().map(|&(i, j)| norm(sub(p[i], p[j]))).fold(0.0, f64::max);
            signed_volume6(p[0], p[1], p[2], p[3]).abs() <= zero_volume6(longest)
        })
        .collect();
    refuse(&bad, "have zero volume (degenerate: coplanar or coincident corners)")?;
    let dups = crate::domain::cells::duplicate_cells(tets);
    if let Some(&(first, _)) = dups.first() {
        let shown: Vec<String> = dups.iter().map(|(t, first)| format!("{t} (= {first})")).collect();
        return Err(Error::input(format!("duplicate tetrahedra {} (the same corners)", list(&shown)))
            .at(Location::Tetrahedron(first)));
    }
    let bad = crate::domain::cells::unused_vertices(n, tets);
    if !bad.is_empty() {
        return Err(
            Error::input(format!("vertices {} are used by no tetrahedron", list(&bad))).at(Location::Vertex(bad[0]))
        );
    }
    let pairs = crate::domain::cells::coincident_vertices(positions);
    if let Some(&(first, _)) = pairs.first() {
        let shown: Vec<String> = pairs.iter().map(|(a, b)| format!("{a} and {b}")).collect();
        return Err(Error::input(format!(
            "vertices at the same position: {} (merge duplicate vertices first)",
            list(&shown)
        ))
        .at(Location::Vertex(first)));
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    Ok(norm(sub(hi, lo)))
}

/// Sorts `(key, payload)` items by key: a counting sort on the key's first (smallest) vertex,
/// then each short bucket (linear time on a mesh; no hashing).
fn bucket_sort<K: Ord + Copy>(n: usize, items: Vec<(K, usize)>, first: impl Fn(&K) -> usize) -> Vec<(K, usize)> {
    let mut start = vec![0usize; n + 1];
    for it in &items {
        start[first(&it.0) + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let Some(&filler) = items.first() else { return items };
    let mut fill = start.clone();
    let mut sorted = vec![filler; items.len()];
    for it in items {
        let f = first(&it.0);
        sorted[fill[f]] = it;
        fill[f] += 1;
    }
    for v in 0..n {
        sorted[start[v]..start[v + 1]].sort_unstable();
    }
    sorted
}

/// The triangles of a mesh and the tetrahedra on each.
pub(super) struct FaceTable {
    /// Triangles (corners sorted), sorted.
    pub faces: Vec<[usize; 3]>,
    /// The one or two tetrahedra on each triangle (second `usize::MAX`: a boundary triangle).
    pub face_tets: Vec<[usize; 2]>,
}

/// The triangles and their tetrahedra.
///
/// # Errors
/// A triangle on more than two tetrahedra.
pub(super) fn face_table(n: usize, tets: &[[usize; 4]]) -> Result<FaceTable> {
    let mut keyed: Vec<([usize; 3], usize)> = Vec::with_capacity(4 * tets.len());
    for (t, tet) in tets.iter().enumerate() {
        let mut s = *tet;
        s.sort_unstable();
        for k in 0..4 {
            let mut face = [0usize; 3];
            let mut m = 0;
            for (c, &v) in s.iter().enumerate() {
                if c != k {
                    face[m] = v;
                    m += 1;
                }
            }
            keyed.push((face, t));
        }
    }
    let keyed = bucket_sort(n, keyed, |f| f[0]);
    let mut faces = Vec::with_capacity(keyed.len() / 2 + 1);
    let mut face_tets = Vec::with_capacity(keyed.len() / 2 + 1);
    let mut bad: Vec<String> = Vec::new();
    let mut first_bad = None;
    let mut i = 0;
    while i < keyed.len() {
        let key = keyed[i].0;
        let mut j = i + 1;
        while j < keyed.len() && keyed[j].0 == key {
            j += 1;
        }
        if j - i > 2 {
            let on: Vec<String> = keyed[i..j].iter().map(|x| x.1.to_string()).collect();
            bad.push(format!("{}–{}–{} (tetrahedra {})", key[0], key[1], key[2], on.join(", ")));
            first_bad.get_or_insert(key[0]);
        }
        faces.push(key);
        face_tets.push([keyed[i].1, if j - i >= 2 { keyed[i + 1].1 } else { usize::MAX }]);
        i = j;
    }
    if let Some(v) = first_bad {
        return Err(
            Error::input(format!("triangles on more than two tetrahedra: {}", list(&bad))).at(Location::Vertex(v))
        );
    }
    Ok(FaceTable { faces, face_tets })
}

/// The edges of a mesh.
pub(super) struct EdgeTable {
    /// Edges `(a, b)` with `a < b`, sorted.
    pub edges: Vec<(usize, usize)>,
    /// The edge of every edge-corner `6t + m` (edge `PAIRS[m]` of tetrahedron `t`).
    pub corner_edge: Vec<usize>,
}

/// The edges and the edge of each tetrahedron's sides.
pub(super) fn edge_table(n: usize, tets: &[[usize; 4]]) -> EdgeTable {
    let mut keyed: Vec<((usize, usize), usize)> = Vec::with_capacity(6 * tets.len());
    for (t, tet) in tets.iter().enumerate() {
        for (m, &(i, j)) in PAIRS.iter().enumerate() {
            let (a, b) = (tet[i], tet[j]);
            keyed.push(((a.min(b), a.max(b)), 6 * t + m));
        }
    }
    let keyed = bucket_sort(n, keyed, |e| e.0);
    let mut edges: Vec<(usize, usize)> = Vec::with_capacity(keyed.len() / 4 + 1);
    let mut corner_edge = vec![0usize; 6 * tets.len()];
    for (key, c) in keyed {
        if edges.last() != Some(&key) {
            edges.push(key);
        }
        corner_edge[c] = edges.len() - 1;
    }
    EdgeTable { edges, corner_edge }
}

fn root(p: &mut [usize], mut x: usize) -> usize {
    while p[x] != x {
        p[x] = p[p[x]];
        x = p[x];
    }
    x
}

fn unite(p: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (root(p, a), root(p, b));
    if ra != rb {
        p[ra] = rb;
    }
}

/// Checks that the tetrahedra around every edge form one fan, and those around every vertex
/// one ball (a half-ball at the boundary), joined through shared triangles.
///
/// Around an edge, with every triangle on at most two tetrahedra, one connected fan is a
/// manifold edge (its link is a path or a cycle). Around a vertex, the tetrahedra must be
/// connected, and then their link (the triangles opposite the vertex) is a connected surface
/// (the fans make it one); it is a sphere (an interior vertex) or a disk (a vertex on the
/// boundary) exactly when its Euler characteristic — edges at the vertex − triangles at the
/// vertex + tetrahedra at the vertex — is 2 or 1. A cone over an annulus or a torus passes the
/// connectivity test but not this one.
///
/// # Errors
/// The edges with more than one fan, else the vertices whose tetrahedra are not connected,
/// else the vertices whose link is not a sphere or a disk.
pub(super) fn check_fans(n: usize, tets: &[[usize; 4]], faces: &FaceTable, edges: &EdgeTable) -> Result<()> {
    let nt = tets.len();
    // edge-corners 6t + m and vertex-corners 4t + k, joined across every interior triangle
    let mut edge_parent: Vec<usize> = (0..6 * nt).collect();
    let mut vertex_parent: Vec<usize> = (0..4 * nt).collect();
    for (face, &[t1, t2]) in faces.faces.iter().zip(&faces.face_tets) {
        if t2 == usize::MAX {
            continue;
        }
        let (a, b) = (&tets[t1], &tets[t2]);
        for &v in face {
            unite(&mut vertex_parent, 4 * t1 + corner(a, v), 4 * t2 + corner(b, v));
        }
        for (x, y) in [(face[0], face[1]), (face[0], face[2]), (face[1], face[2])] {
            let ea = 6 * t1 + pair_index(corner(a, x), corner(a, y));
            let eb = 6 * t2 + pair_index(corner(b, x), corner(b, y));
            unite(&mut edge_parent, ea, eb);
        }
    }
    let ne = edges.edges.len();
    let (mut fans, mut around) = (vec![0u32; ne], vec![0u32; ne]);
    for c in 0..6 * nt {
        let e = edges.corner_edge[c];
        around[e] += 1;
        if root(&mut edge_parent, c) == c {
            fans[e] += 1;
        }
    }
    let bad: Vec<usize> = (0..ne).filter(|&e| fans[e] > 1).collect();
    if let Some(&first) = bad.first() {
        let shown: Vec<String> = bad
            .iter()
            .map(|&e| {
                format!("{}–{} ({} fans of {} tetrahedra)", edges.edges[e].0, edges.edges[e].1, fans[e], around[e])
            })
            .collect();
        return Err(Error::input(format!(
            "non-manifold edges (their tetrahedra do not form one fan through shared triangles): {}",
            list(&shown)
        ))
        .at(Location::Vertex(edges.edges[first].0)));
    }
    let mut balls = vec![0u32; n];
    for c in 0..4 * nt {
        if root(&mut vertex_parent, c) == c {
            balls[tets[c / 4][c % 4]] += 1;
        }
    }
    let bad: Vec<usize> = (0..n).filter(|&v| balls[v] > 1).collect();
    if !bad.is_empty() {
        return Err(Error::input(format!(
            "non-manifold vertices {} (their tetrahedra are not connected through shared triangles)",
            list(&bad)
        ))
        .at(Location::Vertex(bad[0])));
    }
    // the Euler characteristic of every vertex's link, and whether it has a boundary
    let mut chi = vec![0i64; n];
    let mut on_boundary = vec![false; n];
    for &(a, b) in &edges.edges {
        chi[a] += 1;
        chi[b] += 1;
    }
    for (face, t) in faces.faces.iter().zip(&faces.face_tets) {
        for &v in face {
            chi[v] -= 1;
            on_boundary[v] |= t[1] == usize::MAX;
        }
    }
    for tet in tets {
        for &v in tet {
            chi[v] += 1;
        }
    }
    let bad: Vec<usize> = (0..n).filter(|&v| chi[v] != if on_boundary[v] { 1 } else { 2 }).collect();
    if !bad.is_empty() {
        let shown: Vec<String> = bad
            .iter()
            .map(|&v| {
                format!(
                    "{v} ({} vertex, link Euler characteristic {})",
                    if on_boundary[v] { "boundary" } else { "interior" },
                    chi[v]
                )
            })
            .collect();
        return Err(Error::input(format!(
            "non-manifold vertices {} (their tetrahedra do not form a ball: the link must be a sphere, Euler characteristic 2, or at the boundary a disk, 1)",
            list(&shown)
        ))
        .at(Location::Vertex(bad[0])));
    }
    Ok(())
}
