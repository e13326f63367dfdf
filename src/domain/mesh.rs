//! Triangle meshes in 2D or 3D (SPEC.md, "Mesh"): neighbours are the vertices sharing an edge.
//!
//! [`TriMesh::new`] validates what the rest of the crate relies on and says what it found:
//! finite coordinates, indices in range, no repeated corner, no zero-area or duplicate
//! triangle, every vertex used, every edge on at most two triangles, every vertex's triangles
//! forming one fan (manifold vertices). Inconsistent orientation is repaired (triangles are
//! flipped to agree with their component's first triangle, when the component is orientable)
//! and reported in [`TriMesh::repairs`]. Duplicate positions are reported as an error: merging
//! them would glue vertices that carry their own field values.
//!
//! ```
//! use toposmooth::domain::{Domain, TriMesh};
//! // two triangles forming a square
//! let m = TriMesh::new(
//!     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
//!     vec![[0, 1, 2], [0, 2, 3]],
//! )?;
//! assert_eq!(m.neighbors(0).collect::<Vec<_>>(), vec![1, 2, 3]);
//! assert_eq!(m.boundary_loops(), 1);
//! assert_eq!(m.euler_characteristic(), 1);
//! # Ok::<(), toposmooth::Error>(())
//! ```

use super::vec3::{cross, norm, sub};
use super::{Domain, PairingRule};
use crate::error::Result;
use std::collections::HashMap;

mod connect;
mod validate;

/// A validated triangle mesh with its vertex adjacency.
#[derive(Clone, Debug)]
pub struct TriMesh {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    /// Neighbours of vertex v: `adj[start[v]..start[v + 1]]`, sorted.
    start: Vec<usize>,
    adj: Vec<usize>,
    n_edges: usize,
    boundary_loops: usize,
    components: Vec<usize>,
    n_components: usize,
    diameter: f64,
    repairs: Vec<String>,
    orientable: bool,
}

pub use validate::triangle_area;

impl TriMesh {
    /// Validates and builds a mesh (vertex indices 0-based). Messages name the first
    /// offending vertices or triangles; the caller adds the file name.
    ///
    /// # Errors
    /// [`crate::Error::Input`] for: no triangle, a non-finite coordinate, an index out of range, a
    /// triangle repeating a vertex, a zero-area triangle, a duplicate triangle, an unused
    /// vertex, two vertices at one position, an edge on more than two triangles, a vertex
    /// whose triangles form more than one fan.
    pub fn new(positions: Vec<[f64; 3]>, mut triangles: Vec<[usize; 3]>) -> Result<TriMesh> {
        let n = positions.len();
        let diameter = validate::check_elements(&positions, &triangles)?;
        let table = validate::edge_table(n, &triangles)?;
        validate::check_fans(n, &triangles, &table)?;
        let o = connect::orient(&mut triangles, &table);
        let mut repairs = Vec::new();
        if o.flipped > 0 {
            repairs.push(format!(
                "{} triangles flipped to agree in orientation with their neighbours (inconsistent orientation)",
                o.flipped
            ));
        }
        if o.non_orientable > 0 {
            repairs.push("the surface is not orientable: orientation left inconsistent across some edges".into());
        }
        let mut components = vec![0usize; n];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                components[v] = o.tri_comp[t];
            }
        }
        let (start, adj) = super::cells::adjacency(n, &table.edges);
        Ok(TriMesh {
            positions,
            triangles,
            start,
            adj,
            n_edges: table.edges.len(),
            boundary_loops: connect::boundary_loops(n, &table),
            components,
            n_components: o.n_components,
            diameter,
            repairs,
            orientable: o.non_orientable == 0,
        })
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Triangles (orientation made consistent where it was not).
    pub fn faces(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// Number of edges.
    pub fn n_edges(&self) -> usize {
        self.n_edges
    }

    /// Number of boundary loops (0 for a closed surface).
    pub fn boundary_loops(&self) -> usize {
        self.boundary_loops
    }

    /// Number of connected components.
    pub fn n_components(&self) -> usize {
        self.n_components
    }

    /// Component of each vertex.
    pub fn components(&self) -> &[usize] {
        &self.components
    }

    /// `V − E + F`.
    pub fn euler_characteristic(&self) -> i64 {
        self.positions.len() as i64 - self.n_edges as i64 + self.triangles.len() as i64
    }

    /// The triangle with the smallest angle, and that angle in degrees.
    pub fn smallest_angle(&self) -> (usize, f64) {
        let p = &self.positions;
        let mut best = (0, f64::INFINITY);
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (sub(p[tri[(k + 1) % 3]], p[tri[k]]), sub(p[tri[(k + 2) % 3]], p[tri[k]]));
                let c = cross(a, b);
                let angle = norm(c).atan2(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).to_degrees();
                if angle < best.1 {
                    best = (t, angle);
                }
            }
        }
        best
    }

    /// A warning when some triangle has an angle below 0.5° (huge cotangent weights: the
    /// operators lose accuracy), else `None`.
    pub fn sliver_warning(&self) -> Option<String> {
        let (t, angle) = self.smallest_angle();
        (angle < 0.5).then(|| {
            format!(
                "triangle {t} has an angle of {angle:.2e}°: nearly degenerate triangles make the cotangent operators inaccurate (remesh or collapse them)"
            )
        })
    }

    /// Whether every component could be oriented consistently.
    pub fn is_orientable(&self) -> bool {
        self.orientable
    }

    /// Genus of an orientable surface: `(2c − χ − b) / 2` over c components and b boundary
    /// loops (the total over components); meaningless for a non-orientable one.
    pub fn genus(&self) -> i64 {
        (2 * self.n_components as i64 - self.euler_characteristic() - self.boundary_loops as i64) / 2
    }

    /// What validation repaired (empty when nothing).
    pub fn repairs(&self) -> &[String] {
        &self.repairs
    }

    /// Whether the mesh lies in the plane z = 0.
    pub fn is_planar(&self) -> bool {
        self.positions.iter().all(|p| p[2] == 0.0)
    }

    /// Midpoint subdivision: every triangle split into four at its edge midpoints (the
    /// geometry is unchanged; for benchmarks at larger sizes).
    ///
    /// # Errors
    /// When a quarter of a triangle falls below the zero-area threshold.
    pub fn subdivide(&self) -> Result<TriMesh> {
        let mut positions = self.positions.clone();
        let mut mid: HashMap<(usize, usize), usize> = HashMap::with_capacity(self.n_edges);
        let mut triangles = Vec::with_capacity(4 * self.triangles.len());
        for t in &self.triangles {
            let mut m = [0usize; 3];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                m[k] = *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    let (p, q) = (self.positions[a], self.positions[b]);
                    positions.push([(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0, (p[2] + q[2]) / 2.0]);
                    positions.len() - 1
                });
            }
            triangles.push([t[0], m[0], m[2]]);
            triangles.push([m[0], t[1], m[1]]);
            triangles.push([m[2], m[1], t[2]]);
            triangles.push([m[0], m[1], m[2]]);
        }
        TriMesh::new(positions, triangles)
    }

    /// One line: vertices, triangles, components, boundary loops, genus.
    pub fn describe(&self) -> String {
        format!(
            "{} vertices, {} triangles, {} component{}, {} boundary loop{}, {}",
            self.positions.len(),
            self.triangles.len(),
            self.n_components,
            if self.n_components == 1 { "" } else { "s" },
            self.boundary_loops,
            if self.boundary_loops == 1 { "" } else { "s" },
            if self.orientable {
                format!("genus {}", self.genus())
            } else {
                format!("non-orientable, Euler characteristic {}", self.euler_characteristic())
            }
        )
    }
}

impl Domain for TriMesh {
    fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    fn neighbors(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        self.adj[self.start[v]..self.start[v + 1]].iter().copied()
    }

    fn pairing_rule(&self) -> PairingRule {
        PairingRule::Surface
    }

    fn diameter(&self) -> f64 {
        self.diameter
    }

    fn point(&self, v: usize) -> [f64; 3] {
        self.positions[v]
    }

    fn triangles(&self) -> Vec<[usize; 3]> {
        self.triangles.clone()
    }
}

/// Test and example meshes: a UV sphere, a torus, a disk with holes.
pub mod shapes {
    use super::TriMesh;
    use std::f64::consts::PI;

    /// A UV sphere of radius `r` with `rings` latitude bands and `segments` meridians
    /// (poles as single vertices).
    ///
    /// # Panics
    /// If `rings < 2` or `segments < 3`.
    pub fn sphere(r: f64, rings: usize, segments: usize) -> TriMesh {
        assert!(rings >= 2 && segments >= 3);
        let mut p = vec![[0.0, 0.0, r]];
        for i in 1..rings {
            let th = PI * i as f64 / rings as f64;
            for j in 0..segments {
                let ph = 2.0 * PI * j as f64 / segments as f64;
                p.push([r * th.sin() * ph.cos(), r * th.sin() * ph.sin(), r * th.cos()]);
            }
        }
        p.push([0.0, 0.0, -r]);
        let south = p.len() - 1;
        let ring = |i: usize, j: usize| 1 + (i - 1) * segments + j % segments;
        let mut t = Vec::new();
        for j in 0..segments {
            t.push([0, ring(1, j), ring(1, j + 1)]);
            t.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
        }
        for i in 1..rings - 1 {
            for j in 0..segments {
                t.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
                t.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
            }
        }
        TriMesh::new(p, t).expect("a valid sphere")
    }

    /// A torus with radii `big` > `small`, `nu` × `nv` vertices.
    ///
    /// # Panics
    /// If `nu < 3` or `nv < 3`.
    pub fn torus(big: f64, small: f64, nu: usize, nv: usize) -> TriMesh {
        assert!(nu >= 3 && nv >= 3);
        let mut p = Vec::new();
        for i in 0..nu {
            let a = 2.0 * PI * i as f64 / nu as f64;
            for j in 0..nv {
                let b = 2.0 * PI * j as f64 / nv as f64;
                let rr = big + small * b.cos();
                p.push([rr * a.cos(), rr * a.sin(), small * b.sin()]);
            }
        }
        let id = |i: usize, j: usize| (i % nu) * nv + j % nv;
        let mut t = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh::new(p, t).expect("a valid torus")
    }

    /// A planar disk of radius 1 triangulated in `rings` rings of `segments` vertices
    /// around a centre vertex; rings whose radius falls inside one of `holes` (centre, radius)
    /// lose the triangles there, leaving holes.
    ///
    /// # Panics
    /// If the holes leave an invalid mesh.
    pub fn disk(rings: usize, segments: usize, holes: &[([f64; 2], f64)]) -> TriMesh {
        let mut p = vec![[0.0, 0.0, 0.0]];
        for i in 1..=rings {
            let r = i as f64 / rings as f64;
            for j in 0..segments {
                // alternate rings are rotated half a step: better-shaped triangles
                let a = 2.0 * PI * (j as f64 + 0.5 * (i % 2) as f64) / segments as f64;
                p.push([r * a.cos(), r * a.sin(), 0.0]);
            }
        }
        let ring = |i: usize, j: usize| if i == 0 { 0 } else { 1 + (i - 1) * segments + j % segments };
        let mut t = Vec::new();
        for j in 0..segments {
            t.push([0, ring(1, j), ring(1, j + 1)]);
        }
        for i in 1..rings {
            for j in 0..segments {
                if i % 2 == 1 {
                    t.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
                    t.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
                } else {
                    t.push([ring(i, j), ring(i + 1, j), ring(i, j + 1)]);
                    t.push([ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)]);
                }
            }
        }
        let inside = |v: usize| holes.iter().any(|(c, r)| (p[v][0] - c[0]).hypot(p[v][1] - c[1]) < *r);
        t.retain(|tri| !tri.iter().any(|&v| inside(v)));
        // drop vertices no triangle uses, renumbering
        let mut map = vec![usize::MAX; p.len()];
        let mut q = Vec::new();
        for tri in &t {
            for &v in tri {
                if map[v] == usize::MAX {
                    map[v] = q.len();
                    q.push(p[v]);
                }
            }
        }
        let t = t.into_iter().map(|tri| tri.map(|v| map[v])).collect();
        TriMesh::new(q, t).expect("a valid disk")
    }
}

#[cfg(test)]
mod tests {
    use super::shapes::*;
    use super::*;

    fn square() -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
        (vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn shapes_have_the_right_topology() {
        let s = sphere(1.0, 8, 12);
        assert_eq!((s.euler_characteristic(), s.boundary_loops(), s.genus(), s.n_components()), (2, 0, 0, 1));
        let t = torus(3.0, 1.0, 12, 8);
        assert_eq!((t.euler_characteristic(), t.boundary_loops(), t.genus()), (0, 0, 1));
        let d = disk(6, 16, &[]);
        assert_eq!((d.euler_characteristic(), d.boundary_loops(), d.genus()), (1, 1, 0));
        let h = disk(12, 32, &[([0.5, 0.0], 0.2), ([-0.5, 0.0], 0.2)]);
        assert_eq!((h.euler_characteristic(), h.boundary_loops(), h.genus()), (-1, 3, 0));
        assert!(s.repairs().is_empty() && t.repairs().is_empty() && h.repairs().is_empty());
    }

    #[test]
    fn orientation_is_repaired_and_reported() {
        let (p, mut t) = square();
        t[1] = [0, 3, 2];
        let m = TriMesh::new(p, t).unwrap();
        assert_eq!(m.repairs().len(), 1, "{:?}", m.repairs());
        assert_eq!(m.faces()[1], [0, 2, 3]);
    }

    #[test]
    fn invalid_meshes_are_refused_with_the_offending_elements() {
        let (p, t) = square();
        let err = |p: Vec<[f64; 3]>, t: Vec<[usize; 3]>| TriMesh::new(p, t).unwrap_err().to_string();
        let mut q = p.clone();
        q[2][1] = f64::NAN;
        assert!(err(q, t.clone()).contains("non-finite coordinates at vertices 2"));
        assert!(err(p.clone(), vec![[0, 1, 7]]).contains("beyond the 4 vertices"));
        assert!(err(p.clone(), vec![[0, 1, 1], [0, 2, 3]]).contains("repeat a vertex"));
        let mut q = p.clone();
        q[3] = [2.0, 2.0, 0.0]; // 0, 2, 3 collinear
        assert!(err(q, t.clone()).contains("triangles 1 have zero area"));
        assert!(err(p.clone(), vec![[0, 1, 2], [0, 2, 3], [2, 0, 1]]).contains("duplicate triangles 2 (= 0)"));
        let mut q = p.clone();
        q.push([5.0, 5.0, 0.0]);
        assert!(err(q, t.clone()).contains("vertices 4 are used by no triangle"));
        let mut q = p.clone();
        q.push([1.0, 1.0, 0.0]);
        let mut u = t.clone();
        u.push([1, 4, 3]);
        assert!(err(q, u).contains("same position: 2 and 4"));
        // three triangles on edge 0–2
        let mut q = p.clone();
        q.push([0.5, 0.5, 1.0]);
        let mut u = t.clone();
        u.push([0, 2, 4]);
        assert!(err(q, u).contains("non-manifold edges"));
        // two fans meeting at vertex 0 (a bowtie)
        let q = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, -1.0, 0.0]];
        assert!(err(q, vec![[0, 1, 2], [0, 3, 4]]).contains("non-manifold vertices 0"));
        assert!(err(Vec::new(), Vec::new()).contains("at least one triangle"));
    }

    #[test]
    fn a_refused_mesh_points_at_its_first_offending_element() {
        use crate::error::Location;
        let (p, t) = square();
        let at = |p: Vec<[f64; 3]>, t: Vec<[usize; 3]>| TriMesh::new(p, t).unwrap_err().location();
        let mut q = p.clone();
        q[2][1] = f64::INFINITY;
        assert_eq!(at(q, t.clone()), Some(Location::Vertex(2)));
        assert_eq!(at(p.clone(), vec![[0, 1, 2], [0, 2, 9]]), Some(Location::Triangle(1)));
        assert_eq!(at(p.clone(), vec![[0, 1, 2], [0, 2, 3], [2, 0, 1]]), Some(Location::Triangle(2)));
        let mut q = p.clone();
        q.push([5.0, 5.0, 0.0]);
        assert_eq!(at(q, t.clone()), Some(Location::Vertex(4)));
        let q = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, -1.0, 0.0]];
        assert_eq!(at(q, vec![[0, 1, 2], [0, 3, 4]]), Some(Location::Vertex(0)));
        assert_eq!(at(Vec::new(), Vec::new()), None);
    }

    #[test]
    fn subdivision_keeps_the_topology() {
        for m in [sphere(1.0, 6, 8), torus(3.0, 1.0, 8, 6), disk(4, 10, &[])] {
            let s = m.subdivide().unwrap();
            assert_eq!(s.faces().len(), 4 * m.faces().len());
            assert_eq!((s.euler_characteristic(), s.boundary_loops()), (m.euler_characteristic(), m.boundary_loops()));
        }
    }

    #[test]
    fn components_are_counted() {
        let (mut p, mut t) = square();
        p.extend([[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0]]);
        t.push([4, 5, 6]);
        let m = TriMesh::new(p, t).unwrap();
        assert_eq!(m.n_components(), 2);
        assert_eq!(m.components(), &[0, 0, 0, 0, 1, 1, 1]);
        assert_eq!(m.boundary_loops(), 2);
    }
}
