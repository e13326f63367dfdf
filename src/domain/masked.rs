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

use super::{Domain, Grid3d, TetMesh};
use crate::error::{Error, Result};

/// A volume grid restricted to the voxels a mask holds inside.
#[derive(Clone, Debug)]
pub struct MaskedVolume {
    grid: Grid3d,
    mesh: TetMesh,
    /// The grid index of each of the mesh's vertices, increasing.
    voxel: Vec<usize>,
    /// Whether each grid voxel is a vertex of the domain.
    used: Vec<bool>,
    /// Inside voxels of the mask.
    inside: usize,
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
        let mut used = vec![false; n];
        let mut tets: Vec<[usize; 4]> = Vec::new();
        for t in grid.tetrahedra() {
            if t.iter().all(|&v| inside[v]) {
                for &v in &t {
                    used[v] = true;
                }
                tets.push(t);
            }
        }
        if tets.is_empty() {
            return Err(Error::input(format!(
                "the mask holds {count} of {n} voxels inside but no tetrahedron of the grid (a domain needs a cube's \
                 worth of inside voxels somewhere)"
            )));
        }
        let voxel: Vec<usize> = (0..n).filter(|&v| used[v]).collect();
        let mut vertex = vec![usize::MAX; n];
        for (i, &v) in voxel.iter().enumerate() {
            vertex[v] = i;
        }
        let positions = voxel.iter().map(|&v| grid.position(v)).collect();
        let tets = tets.into_iter().map(|t| t.map(|v| vertex[v])).collect();
        let mesh = TetMesh::complex(positions, tets)?;
        Ok(MaskedVolume { grid: grid.clone(), mesh, voxel, used, inside: count })
    }

    /// The grid the mask lies on.
    pub fn grid(&self) -> &Grid3d {
        &self.grid
    }

    /// The domain: a tetrahedral complex over the used voxels, numbered in grid order.
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// The grid index of each domain vertex.
    pub fn voxels(&self) -> &[usize] {
        &self.voxel
    }

    /// Whether each grid voxel is a vertex of the domain.
    pub fn used(&self) -> &[bool] {
        &self.used
    }

    /// Inside voxels on no inside tetrahedron, left out of the domain.
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

    /// One line: inside voxels, domain vertices and tetrahedra, components, voxels left out.
    pub fn describe(&self) -> String {
        let n = self.grid.n_vertices();
        format!(
            "mask: {} of {n} voxels inside ({:.1} %); domain {} vertices, {} tetrahedra, {} component{}{}",
            self.inside,
            100.0 * self.inside as f64 / n as f64,
            self.voxel.len(),
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
    fn cubes_meeting_at_one_vertex_make_a_non_manifold_complex_with_one_component() {
        let g = Grid3d::new(3, 3, 3).unwrap();
        let mut inside = vec![false; 27];
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..2 {
                    inside[g.index(i, j, k)] = true;
                    inside[g.index(i + 1, j + 1, k + 1)] = true;
                }
            }
        }
        let m = MaskedVolume::new(&g, &inside).unwrap();
        assert_eq!(m.mesh().n_vertices(), 15);
        assert_eq!(m.mesh().n_components(), 1);
        // the manifold mesh refuses the same tetrahedra
        assert!(TetMesh::new(m.mesh().positions().to_vec(), m.mesh().tets().to_vec()).is_err());
    }
}
