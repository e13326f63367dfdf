//! A volume grid restricted to a mask: the domain is the tetrahedra of the grid's split
//! (SPEC.md, "Volume grid") whose four corners are all inside, so two inside voxels are
//! neighbours when they share such a tetrahedron's edge. MRI and CT volumes are mostly
//! background; smoothing only the inside is both faster and what the scan means.
//!
//! The tetrahedra may meet at a single edge or vertex (a mask is any set of voxels), so the
//! domain is a tetrahedral complex rather than a manifold [`TetMesh`]: nothing the volume
//! route does (neighbours, persistence, P1 operators, the certificate) needs a manifold.
//! Inside voxels on no such tetrahedron (specks and one-voxel-thin sheets) are left out with
//! the outside and counted.
//!
//! ```
//! use toposmooth::domain::{Domain, Grid3d, MaskedVolume};
//! let g = Grid3d::new(3, 3, 3)?;
//! // everything but one corner voxel
//! let inside: Vec<bool> = (0..27).map(|v| v != 26).collect();
//! let m = MaskedVolume::new(&g, &inside)?;
//! assert_eq!(m.mesh().n_vertices(), 26);
//! assert_eq!(m.left_out(), 0);
//! # Ok::<(), toposmooth::Error>(())
//! ```

use super::{Domain, Grid2d, Grid3d, TetMesh, TriMesh};
use crate::error::{Error, Result};

/// A volume grid restricted to the voxels a mask holds inside.
#[derive(Clone, Debug)]
pub struct MaskedVolume {
    grid: Grid3d,
    mesh: TetMesh,
    on: Restriction,
}

/// Which grid points a masked domain holds and how its vertices map to them: what
/// [`MaskedVolume`] and [`MaskedGrid`] share (both dereference to it).
#[derive(Clone, Debug)]
pub struct Restriction {
    /// The grid index of each of the domain's vertices, increasing.
    voxel: Vec<usize>,
    /// Whether each grid point is a vertex of the domain.
    used: Vec<bool>,
    /// Inside points of the mask.
    inside: usize,
}

impl Restriction {
    /// The points of `n` on some `cells` (grid indices), the cells renumbered onto them.
    fn new<const K: usize>(n: usize, cells: Vec<[usize; K]>, inside: usize) -> (Restriction, Vec<[usize; K]>) {
        let mut used = vec![false; n];
        cells.iter().flatten().for_each(|&v| used[v] = true);
        let voxel: Vec<usize> = (0..n).filter(|&v| used[v]).collect();
        let mut vertex = vec![usize::MAX; n];
        for (i, &v) in voxel.iter().enumerate() {
            vertex[v] = i;
        }
        let cells = cells.into_iter().map(|c| c.map(|v| vertex[v])).collect();
        (Restriction { voxel, used, inside }, cells)
    }

    /// The grid index of each domain vertex.
    pub fn voxels(&self) -> &[usize] {
        &self.voxel
    }

    /// Whether each grid point is a vertex of the domain.
    pub fn used(&self) -> &[bool] {
        &self.used
    }

    /// Inside points left out of the domain (on no inside cell, or removed as pinch points).
    pub fn left_out(&self) -> usize {
        self.inside - self.voxel.len()
    }

    /// A grid field's values at the domain's vertices.
    pub fn restrict<T: Copy>(&self, f: &[T]) -> Vec<T> {
        self.voxel.iter().map(|&v| f[v]).collect()
    }

    /// The grid field that is `inner` on the domain and `outside` elsewhere.
    pub fn extend<T: Copy>(&self, inner: &[T], outside: &[T]) -> Vec<T> {
        let mut f = outside.to_vec();
        for (&v, &x) in self.voxel.iter().zip(inner) {
            f[v] = x;
        }
        f
    }
}

impl std::ops::Deref for MaskedVolume {
    type Target = Restriction;
    fn deref(&self) -> &Restriction {
        &self.on
    }
}

impl std::ops::Deref for MaskedGrid {
    type Target = Restriction;
    fn deref(&self) -> &Restriction {
        &self.on
    }
}

impl MaskedVolume {
    /// The tetrahedra of `grid` whose corners are all `inside` (one flag per voxel, VTK
    /// order).
    ///
    /// # Errors
    /// [`Error::Input`] when `inside` has the wrong length or no tetrahedron lies inside.
    pub fn new(grid: &Grid3d, inside: &[bool]) -> Result<MaskedVolume> {
        let n = grid.n_vertices();
        if inside.len() != n {
            return Err(Error::input(format!("the mask has {} values, the volume {n} voxels", inside.len())));
        }
        let count = inside.iter().filter(|&&b| b).count();
        let tets: Vec<[usize; 4]> = grid.tetrahedra().filter(|t| t.iter().all(|&v| inside[v])).collect();
        if tets.is_empty() {
            return Err(Error::input(format!(
                "the mask holds {count} of {n} voxels inside but no tetrahedron of the grid (a domain needs a cube's \
                 worth of inside voxels somewhere)"
            )));
        }
        let (on, tets) = Restriction::new(n, tets, count);
        let positions = on.voxel.iter().map(|&v| grid.position(v)).collect();
        let mesh = TetMesh::complex(positions, tets)?;
        Ok(MaskedVolume { grid: grid.clone(), mesh, on })
    }

    /// The grid the mask lies on.
    pub fn grid(&self) -> &Grid3d {
        &self.grid
    }

    /// The domain: a tetrahedral complex over the used voxels, numbered in grid order.
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// One line: inside voxels, domain vertices and tetrahedra, components, voxels left out.
    pub fn describe(&self) -> String {
        let n = self.grid.n_vertices();
        format!(
            "mask: {} of {n} voxels inside ({:.1} %); domain {} vertices, {} tetrahedra, {} component{}{}",
            self.on.inside,
            100.0 * self.on.inside as f64 / n as f64,
            self.on.voxel.len(),
            self.mesh.tets().len(),
            self.mesh.n_components(),
            if self.mesh.n_components() == 1 { "" } else { "s" },
            match self.left_out() {
                0 => String::new(),
                k => format!("; {k} inside voxels on no inside tetrahedron left unchanged"),
            }
        )
    }
}

/// A 2D grid restricted to a mask: the triangles of the grid's split with every corner
/// inside, after removing the inside pixels where triangles meet at a single vertex (the
/// triangle mesh of the 2D route, with its Morse–Smale complex, needs a manifold: each
/// vertex's triangles one fan). The removed pixels are left unchanged with the outside.
#[derive(Clone, Debug)]
pub struct MaskedGrid {
    grid: Grid2d,
    mesh: TriMesh,
    on: Restriction,
    pinched: usize,
}

impl MaskedGrid {
    /// The triangles of `grid` whose corners are all `inside` (one flag per pixel, row
    /// after row), pinch points removed.
    ///
    /// # Errors
    /// [`Error::Input`] when `inside` has the wrong length or no triangle lies inside.
    pub fn new(grid: &Grid2d, inside: &[bool]) -> Result<MaskedGrid> {
        let n = grid.n_vertices();
        if inside.len() != n {
            return Err(Error::input(format!("the mask has {} values, the grid {n} pixels", inside.len())));
        }
        let count = inside.iter().filter(|&&b| b).count();
        let mut keep = inside.to_vec();
        let mut pinched = 0;
        let triangles = loop {
            let tris: Vec<[usize; 3]> = grid.triangles().filter(|t| t.iter().all(|&v| keep[v])).collect();
            let pinch = pinch_points(n, &tris);
            if pinch.is_empty() {
                break tris;
            }
            pinched += pinch.len();
            for v in pinch {
                keep[v] = false;
            }
        };
        if triangles.is_empty() {
            return Err(Error::input(format!(
                "the mask holds {count} of {n} pixels inside but no triangle of the grid (a domain needs a square's \
                 worth of inside pixels somewhere)"
            )));
        }
        let (on, triangles) = Restriction::new(n, triangles, count);
        let positions = on.voxel.iter().map(|&v| grid.point(v)).collect();
        let mesh = TriMesh::new(positions, triangles)?;
        Ok(MaskedGrid { grid: grid.clone(), mesh, on, pinched })
    }

    /// The grid the mask lies on.
    pub fn grid(&self) -> &Grid2d {
        &self.grid
    }

    /// The domain: a triangle mesh over the used pixels, numbered in grid order.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// One line: inside pixels, domain vertices and triangles, components, pixels left out.
    pub fn describe(&self) -> String {
        let n = self.grid.n_vertices();
        format!(
            "mask: {} of {n} pixels inside ({:.1} %); domain {} vertices, {} triangles, {} component{}{}",
            self.on.inside,
            100.0 * self.on.inside as f64 / n as f64,
            self.on.voxel.len(),
            self.mesh.faces().len(),
            self.mesh.n_components(),
            if self.mesh.n_components() == 1 { "" } else { "s" },
            match self.left_out() {
                0 => String::new(),
                k => format!("; {k} inside pixels left unchanged ({} where triangles meet at a point)", self.pinched),
            }
        )
    }
}

/// Vertices whose triangles do not form one fan: the edges opposite a vertex in its
/// triangles (its link) must make one path or one cycle.
fn pinch_points(n: usize, tris: &[[usize; 3]]) -> Vec<usize> {
    let mut link: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for t in tris {
        for k in 0..3 {
            link[t[k]].push((t[(k + 1) % 3], t[(k + 2) % 3]));
        }
    }
    let mut out = Vec::new();
    for (v, edges) in link.iter().enumerate() {
        if edges.is_empty() {
            continue;
        }
        // degrees in the link and its connectivity (a handful of edges: quadratic is fine)
        let mut nodes: Vec<usize> = edges.iter().flat_map(|&(a, b)| [a, b]).collect();
        nodes.sort_unstable();
        nodes.dedup();
        let degree = |x: usize| edges.iter().filter(|&&(a, b)| a == x || b == x).count();
        let mut reached = vec![nodes[0]];
        let mut i = 0;
        while i < reached.len() {
            let x = reached[i];
            for &(a, b) in edges {
                for (p, q) in [(a, b), (b, a)] {
                    if p == x && !reached.contains(&q) {
                        reached.push(q);
                    }
                }
            }
            i += 1;
        }
        if reached.len() < nodes.len() || nodes.iter().any(|&x| degree(x) > 2) {
            out.push(v);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_domain_is_the_tetrahedra_with_all_corners_inside_and_specks_are_left_out() {
        let g = Grid3d::new(5, 4, 3).unwrap();
        let n = g.n_vertices();
        // two 2 × 2 × 2 blocks diagonally apart (their nearest voxels are grid neighbours but
        // share no inside tetrahedron) and a lone voxel
        let mut inside = vec![false; n];
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..2 {
                    inside[g.index(i, j, k)] = true;
                    inside[g.index(i + 2, j + 2, k + 1)] = true;
                }
            }
        }
        inside[g.index(4, 0, 2)] = true;
        let m = MaskedVolume::new(&g, &inside).unwrap();
        // two cubes of six tetrahedra, not connected
        assert_eq!(m.mesh().tets().len(), 12);
        assert_eq!(m.mesh().n_vertices(), 16);
        assert_eq!(m.left_out(), 1);
        assert_eq!(m.mesh().n_components(), 2);
        let f: Vec<usize> = (0..n).collect();
        let inner = m.restrict(&f);
        assert_eq!(inner[0], 0);
        assert_eq!(m.extend(&inner, &vec![usize::MAX; n])[g.index(1, 1, 1)], g.index(1, 1, 1));
        assert!(m.describe().contains("1 inside voxels on no inside tetrahedron"), "{}", m.describe());
        assert!(MaskedVolume::new(&g, &vec![false; n]).is_err());
        assert!(MaskedVolume::new(&g, &inside[1..]).is_err());
    }

    #[test]
    fn a_2d_mask_is_a_triangle_mesh_without_pinch_points() {
        let g = Grid2d::new(6, 6).unwrap();
        // two 3 × 3 blocks meeting only at the pixel (2, 2) across the (−,+) diagonal (blocks
        // along the (+,+) one share the split's diagonal triangles), and a lone pixel
        let mut inside = vec![false; 36];
        for r in 0..3 {
            for c in 0..3 {
                inside[g.index(r, c + 2)] = true;
                inside[g.index(r + 2, c)] = true;
            }
        }
        inside[g.index(5, 5)] = true;
        let m = MaskedGrid::new(&g, &inside).unwrap();
        // the pinch pixel goes with one triangle of each block: seven remain in each
        assert_eq!((m.mesh().faces().len(), m.mesh().n_vertices(), m.mesh().n_components()), (14, 16, 2));
        assert_eq!(m.left_out(), 2);
        assert!(!m.used()[g.index(2, 2)] && m.used()[g.index(1, 3)]);
        assert!(m.describe().contains("1 where triangles meet at a point"), "{}", m.describe());
        // the domain's own pixels rebuild the same domain
        let again = MaskedGrid::new(&g, m.used()).unwrap();
        assert_eq!((again.voxels(), again.left_out()), (m.voxels(), 0));
        assert!(MaskedGrid::new(&g, &[false; 36]).is_err());
    }

    #[test]
    fn cubes_meeting_at_one_vertex_make_a_non_manifold_complex_with_one_component() {
        let g = Grid3d::new(3, 3, 3).unwrap();
        let mut inside = vec![false; 27];
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..2 {
                    // the cubes at (1, 0, 0) and (0, 1, 1) share only the voxel (1, 1, 1),
                    // and no tetrahedron of the split has corners in both (its corners lie
                    // in one cube, from its first corner to the opposite one)
                    inside[g.index(i + 1, j, k)] = true;
                    inside[g.index(i, j + 1, k + 1)] = true;
                }
            }
        }
        let m = MaskedVolume::new(&g, &inside).unwrap();
        assert_eq!((m.mesh().n_vertices(), m.mesh().tets().len()), (15, 12));
        assert_eq!(m.mesh().n_components(), 1);
        // the manifold mesh refuses the same tetrahedra
        assert!(TetMesh::new(m.mesh().positions().to_vec(), m.mesh().tets().to_vec()).is_err());
    }
}
