//! Tetrahedral meshes (SPEC.md, "Tetrahedral mesh"): tetrahedra over 3D vertices; neighbours
//! are the vertices sharing an edge.
//!
//! [`TetMesh::new`] validates what the rest of the crate relies on and says what it found:
//! finite coordinates, indices in range, no repeated corner, no zero-volume or duplicate
//! tetrahedron, every vertex used, no two vertices at one position, every triangle on at most
//! two tetrahedra, the tetrahedra around every edge forming one fan and those around every
//! vertex one ball (or half-ball at the boundary), so the boundary is a closed triangle surface.
//! Inverted tetrahedra (negative signed volume) are reoriented and reported in
//! [`TetMesh::repairs`]. Duplicate positions are an error, as for [`super::TriMesh`]: merging
//! them would glue vertices that carry their own field values.
//!
//! ```
//! use toposmooth::domain::{Domain, TetMesh};
//! // two tetrahedra sharing the triangle 1–2–3
//! let m = TetMesh::new(
//!     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]],
//!     vec![[0, 1, 2, 3], [1, 2, 3, 4]],
//! )?;
//! assert_eq!(m.neighbors(0).collect::<Vec<_>>(), vec![1, 2, 3]);
//! assert_eq!(m.boundary_faces().len(), 6);
//! assert_eq!(m.euler_characteristic(), 1);
//! # Ok::<(), toposmooth::Error>(())
//! ```

use super::{Domain, PairingRule};
use crate::error::Result;

mod shapes;
#[cfg(test)]
mod tests;
mod validate;

/// Corners of the outward-oriented face opposite each corner of a positively oriented
/// tetrahedron `[0, 1, 2, 3]` (`(b − a) × (c − a)` points away from the opposite corner).
const OUTWARD: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

pub(crate) use crate::domain::vec3::signed_volume6;

/// A validated tetrahedral mesh with its vertex adjacency and boundary surface.
#[derive(Clone, Debug)]
pub struct TetMesh {
    positions: Vec<[f64; 3]>,
    /// Positively oriented (inverted ones were reoriented).
    tets: Vec<[usize; 4]>,
    /// Neighbours of vertex v: `adj[start[v]..start[v + 1]]`, sorted.
    start: Vec<usize>,
    adj: Vec<usize>,
    n_edges: usize,
    n_faces: usize,
    boundary_faces: Vec<[usize; 3]>,
    components: Vec<usize>,
    n_components: usize,
    diameter: f64,
    volume: f64,
    repairs: Vec<String>,
}

impl TetMesh {
    /// Validates and builds a mesh (vertex indices 0-based). Messages name the first
    /// offending vertices or tetrahedra; the caller adds the file name. Each error carries
    /// the first offending element as its [`crate::Location`] (a vertex, or a tetrahedron).
    ///
    /// # Errors
    /// [`crate::Error::Input`] for: no tetrahedron, a non-finite coordinate, an index out of
    /// range, a tetrahedron repeating a corner, a zero-volume tetrahedron, a duplicate
    /// tetrahedron (the same corners in any order), an unused vertex, two vertices at one
    /// position, a triangle on more than two tetrahedra, an edge whose tetrahedra form more
    /// than one fan, a vertex whose tetrahedra are not connected through shared triangles or
    /// do not form a ball (a half-ball at the boundary).
    pub fn new(positions: Vec<[f64; 3]>, tets: Vec<[usize; 4]>) -> Result<TetMesh> {
        TetMesh::build(positions, tets, true)
    }

    /// A tetrahedral complex: validated as [`TetMesh::new`] does except that edges and
    /// vertices may be non-manifold (tetrahedra meeting only at an edge or a vertex), as the
    /// tetrahedra of a masked volume do. Neighbours, operators, persistence and the
    /// certificate need no manifold; the boundary triangles are those on one tetrahedron.
    pub(crate) fn complex(positions: Vec<[f64; 3]>, tets: Vec<[usize; 4]>) -> Result<TetMesh> {
        TetMesh::build(positions, tets, false)
    }

    fn build(positions: Vec<[f64; 3]>, mut tets: Vec<[usize; 4]>, manifold: bool) -> Result<TetMesh> {
        let n = positions.len();
        let diameter = validate::check_elements(&positions, &tets)?;
        // orient first: the tables below only see vertex sets, the boundary faces need corners
        let mut inverted = Vec::new();
        let mut volume = 0.0;
        for (t, tet) in tets.iter_mut().enumerate() {
            let [a, b, c, d] = tet.map(|v| positions[v]);
            let v6 = signed_volume6(a, b, c, d);
            if v6 < 0.0 {
                tet.swap(2, 3);
                inverted.push(t);
            }
            volume += v6.abs() / 6.0;
        }
        let faces = validate::face_table(n, &tets)?;
        let edges = validate::edge_table(n, &tets);
        if manifold {
            validate::check_fans(n, &tets, &faces, &edges)?;
        }
        let mut repairs = Vec::new();
        if let Some(&first) = inverted.first() {
            let (count, noun) = (inverted.len(), if inverted.len() == 1 { "tetrahedron" } else { "tetrahedra" });
            repairs.push(format!(
                "{count} inverted {noun} reoriented (the first: {first}): two corners swapped to make the signed volume positive"
            ));
        }
        let boundary_faces = faces
            .faces
            .iter()
            .zip(&faces.face_tets)
            .filter(|(_, t)| t[1] == usize::MAX)
            .map(|(f, t)| {
                let tet = tets[t[0]];
                let k = (0..4).find(|&k| !f.contains(&tet[k])).expect("a corner off the face");
                OUTWARD[k].map(|c| tet[c])
            })
            .collect();
        let (components, n_components) = components(n, &tets);
        let (start, adj) = super::cells::adjacency(n, &edges.edges);
        Ok(TetMesh {
            positions,
            tets,
            start,
            adj,
            n_edges: edges.edges.len(),
            n_faces: faces.faces.len(),
            boundary_faces,
            components,
            n_components,
            diameter,
            volume,
            repairs,
        })
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Tetrahedra, every one positively oriented (`(b − a) × (c − a) · (d − a) > 0` for
    /// `[a, b, c, d]`; inverted ones were reoriented by swapping their last two corners).
    pub fn tets(&self) -> &[[usize; 4]] {
        &self.tets
    }

    /// Triangles on exactly one tetrahedron, oriented outward (`(b − a) × (c − a)` points out
    /// of the mesh), in the order of their sorted corners.
    pub fn boundary_faces(&self) -> &[[usize; 3]] {
        &self.boundary_faces
    }

    /// Number of edges.
    pub fn n_edges(&self) -> usize {
        self.n_edges
    }

    /// Number of triangles (interior and boundary).
    pub fn n_faces(&self) -> usize {
        self.n_faces
    }

    /// Number of connected components.
    pub fn n_components(&self) -> usize {
        self.n_components
    }

    /// Component of each vertex (numbered in the order of their first tetrahedron).
    pub fn components(&self) -> &[usize] {
        &self.components
    }

    /// `V − E + F − T` (1 for each component that is a ball).
    pub fn euler_characteristic(&self) -> i64 {
        self.positions.len() as i64 - self.n_edges as i64 + self.n_faces as i64 - self.tets.len() as i64
    }

    /// Total volume.
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// What validation repaired (empty when nothing).
    pub fn repairs(&self) -> &[String] {
        &self.repairs
    }

    /// One line: vertices, tetrahedra, components, boundary triangles, Euler characteristic.
    pub fn describe(&self) -> String {
        format!(
            "{} vertices, {} tetrahedra, {} component{}, {} boundary triangles, Euler characteristic {}",
            self.positions.len(),
            self.tets.len(),
            self.n_components,
            if self.n_components == 1 { "" } else { "s" },
            self.boundary_faces.len(),
            self.euler_characteristic()
        )
    }
}

impl Domain for TetMesh {
    fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    fn neighbors(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        self.adj[self.start[v]..self.start[v + 1]].iter().copied()
    }

    /// Minima from sublevel sets, maxima from superlevel sets, as on a surface: the
    /// union-find pairing works on any neighbour graph.
    fn pairing_rule(&self) -> PairingRule {
        PairingRule::Surface
    }

    /// The bounding-box diagonal (a bound of the largest distance between two vertices).
    fn diameter(&self) -> f64 {
        self.diameter
    }

    fn point(&self, v: usize) -> [f64; 3] {
        self.positions[v]
    }

    // `triangles` keeps the default (none): it feeds the 2D discrete gradient.
}

/// The component of every vertex through the tetrahedra, numbered in the order of the first
/// tetrahedron of each, and their number.
fn components(n: usize, tets: &[[usize; 4]]) -> (Vec<usize>, usize) {
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for tet in tets {
        for &v in &tet[1..] {
            let (a, b) = (root(&mut parent, tet[0]), root(&mut parent, v));
            if a != b {
                parent[a] = b;
            }
        }
    }
    let mut label = vec![usize::MAX; n];
    let mut count = 0;
    for tet in tets {
        let r = root(&mut parent, tet[0]);
        if label[r] == usize::MAX {
            label[r] = count;
            count += 1;
        }
    }
    ((0..n).map(|v| label[root(&mut parent, v)]).collect(), count)
}
