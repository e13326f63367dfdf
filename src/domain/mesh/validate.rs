//! Checks of a triangle mesh as read: the elements (counts, coordinates, indices, areas,
//! duplicates, unused and coincident vertices), the edges (at most two triangles each) and the
//! vertices (one fan each). Messages name the first offending elements; each error carries the
//! first as its [`Location`].

use crate::domain::vec3::{cross, norm, sub};
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

/// Area of a triangle given by its corner positions.
pub fn triangle_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    0.5 * norm(cross(sub(b, a), sub(c, a)))
}

/// The edges of a mesh and the triangles on each.
pub(super) struct EdgeTable {
    /// Edges `(a, b)` with `a < b`, sorted.
    pub edges: Vec<(usize, usize)>,
    /// The one or two triangles of each edge (`usize::MAX`: none, a boundary edge).
    pub edge_tris: Vec<[usize; 2]>,
    /// The edge of every corner's outgoing side (corner `3t + k`: side `k` of triangle `t`).
    pub side_edge: Vec<usize>,
}

impl EdgeTable {
    /// The edge `{a, b}` of triangle `t` (its sides as read: orientation repairs reorder corners).
    pub fn edge_of(&self, t: usize, a: usize, b: usize) -> usize {
        let key = (a.min(b), a.max(b));
        *self.side_edge[3 * t..3 * t + 3].iter().find(|&&e| self.edges[e] == key).expect("a side of the triangle")
    }
}

/// Checks the elements; returns the bounding-box diagonal (the scale of "zero area").
pub(super) fn check_elements(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Result<f64> {
    let n = positions.len();
    if n == 0 || triangles.is_empty() {
        return Err(Error::input(format!(
            "the mesh has {n} vertices and {} triangles: it needs at least one triangle",
            triangles.len()
        )));
    }
    let bad: Vec<usize> = (0..n).filter(|&v| positions[v].iter().any(|x| !x.is_finite())).collect();
    if !bad.is_empty() {
        return Err(
            Error::input(format!("non-finite coordinates at vertices {}", list(&bad))).at(Location::Vertex(bad[0]))
        );
    }
    let bad: Vec<usize> = (0..triangles.len()).filter(|&t| triangles[t].iter().any(|&v| v >= n)).collect();
    if !bad.is_empty() {
        return Err(Error::input(format!(
            "triangles {} use a vertex index beyond the {n} vertices (e.g. triangle {} = {:?})",
            list(&bad),
            bad[0],
            triangles[bad[0]]
        ))
        .at(Location::Triangle(bad[0])));
    }
    let bad: Vec<usize> = (0..triangles.len())
        .filter(|&t| {
            let [a, b, c] = triangles[t];
            a == b || b == c || a == c
        })
        .collect();
    if !bad.is_empty() {
        return Err(Error::input(format!(
            "triangles {} repeat a vertex (e.g. triangle {} = {:?})",
            list(&bad),
            bad[0],
            triangles[bad[0]]
        ))
        .at(Location::Triangle(bad[0])));
    }
    // zero area relative to the mesh's scale (bounding-box diagonal)
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diameter = norm(sub(hi, lo));
    let bad: Vec<usize> = (0..triangles.len())
        .filter(|&t| {
            let [a, b, c] = triangles[t];
            triangle_area(positions[a], positions[b], positions[c]) <= 1e-14 * diameter * diameter
        })
        .collect();
    if !bad.is_empty() {
        return Err(Error::input(format!(
            "triangles {} have zero area (degenerate: collinear or coincident corners)",
            list(&bad)
        ))
        .at(Location::Triangle(bad[0])));
    }
    let dups = crate::domain::cells::duplicate_cells(triangles);
    if let Some(&(first, _)) = dups.first() {
        let shown: Vec<String> = dups.iter().map(|(t, first)| format!("{t} (= {first})")).collect();
        return Err(Error::input(format!("duplicate triangles {}", list(&shown))).at(Location::Triangle(first)));
    }
    let bad = crate::domain::cells::unused_vertices(n, triangles);
    if !bad.is_empty() {
        return Err(
            Error::input(format!("vertices {} are used by no triangle", list(&bad))).at(Location::Vertex(bad[0]))
        );
    }
    let pairs = crate::domain::cells::coincident_vertices(positions);
    if let Some(&(first, _)) = pairs.first() {
        let shown: Vec<String> = pairs.iter().map(|(a, b)| format!("{a} and {b}")).collect();
        return Err(Error::input(format!(
            "vertices at the same position: {} (a triangle soup? merge duplicate vertices first)",
            list(&shown)
        ))
        .at(Location::Vertex(first)));
    }
    Ok(diameter)
}

/// The edges and their triangles, from the sorted half-edges (no hashing: this is the hot
/// part of reading a large mesh).
///
/// # Errors
/// An edge on more than two triangles.
pub(super) fn edge_table(n: usize, triangles: &[[usize; 3]]) -> Result<EdgeTable> {
    let nt = triangles.len();
    let mut half: Vec<(usize, usize, usize)> = Vec::with_capacity(3 * nt);
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            half.push((a.min(b), a.max(b), 3 * t + k));
        }
    }
    // counting sort by the smaller vertex, then each short bucket: the order of sorting the
    // triples, in linear time
    let mut start = vec![0usize; n + 1];
    for h in &half {
        start[h.0 + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut sorted = vec![(0usize, 0usize, 0usize); half.len()];
    let mut fill = start.clone();
    for &h in &half {
        sorted[fill[h.0]] = h;
        fill[h.0] += 1;
    }
    for v in 0..n {
        sorted[start[v]..start[v + 1]].sort_unstable();
    }
    let half = sorted;
    let mut edges: Vec<(usize, usize)> = Vec::with_capacity(3 * nt / 2 + 1);
    let mut edge_tris: Vec<[usize; 2]> = Vec::with_capacity(3 * nt / 2 + 1);
    let mut side_edge = vec![0usize; 3 * nt];
    let mut bad: Vec<String> = Vec::new();
    let mut first_bad = None;
    let mut i = 0;
    while i < half.len() {
        let (a, b, c) = half[i];
        let mut j = i + 1;
        while j < half.len() && (half[j].0, half[j].1) == (a, b) {
            j += 1;
        }
        if j - i > 2 {
            bad.push(format!("{a}–{b} ({} triangles)", j - i));
            first_bad.get_or_insert(a);
        }
        for h in &half[i..j] {
            side_edge[h.2] = edges.len();
        }
        edges.push((a, b));
        edge_tris.push([c / 3, if j - i >= 2 { half[i + 1].2 / 3 } else { usize::MAX }]);
        i = j;
    }
    if let Some(v) = first_bad {
        return Err(Error::input(format!("non-manifold edges (on more than two triangles): {}", list(&bad)))
            .at(Location::Vertex(v)));
    }
    Ok(EdgeTable { edges, edge_tris, side_edge })
}

/// Checks that the corners (vertex, triangle) at each vertex, joined across its interior
/// edges, form one group: more than one is more than one fan.
///
/// # Errors
/// The vertices with more than one fan.
pub(super) fn check_fans(n: usize, triangles: &[[usize; 3]], table: &EdgeTable) -> Result<()> {
    let nt = triangles.len();
    let corner = |v: usize, t: usize| 3 * t + triangles[t].iter().position(|&x| x == v).expect("corner");
    let mut parent: Vec<usize> = (0..3 * nt).collect();
    fn root(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for (e, &(a, b)) in table.edges.iter().enumerate() {
        let [t1, t2] = table.edge_tris[e];
        if t2 == usize::MAX {
            continue;
        }
        for v in [a, b] {
            let (r1, r2) = (root(&mut parent, corner(v, t1)), root(&mut parent, corner(v, t2)));
            if r1 != r2 {
                parent[r1] = r2;
            }
        }
    }
    let mut fans = vec![0u32; n];
    for c in 0..3 * nt {
        if root(&mut parent, c) == c {
            fans[triangles[c / 3][c % 3]] += 1;
        }
    }
    let bad: Vec<usize> = (0..n).filter(|&v| fans[v] > 1).collect();
    if !bad.is_empty() {
        return Err(Error::input(format!(
            "non-manifold vertices {} (their triangles form more than one fan)",
            list(&bad)
        ))
        .at(Location::Vertex(bad[0])));
    }
    Ok(())
}
