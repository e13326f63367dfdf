//! Domains: the vertex–edge structure a field lives on.
//!
//! Topology, constraints and verification see a domain only through the [`Domain`] trait:
//! a vertex count and the neighbours of each vertex (SPEC.md, "Domains and neighbours").
//!
//! ```
//! use toposmooth::domain::{Domain, Series};
//! let s = Series::uniform(4);
//! assert_eq!(s.neighbors(0).collect::<Vec<_>>(), vec![1]);
//! assert_eq!(s.neighbors(2).collect::<Vec<_>>(), vec![1, 3]);
//! ```

mod any;
mod cells;
mod grid;
mod masked;
mod mesh;
mod order;
mod series;
mod tet_mesh;
pub mod vec3;
mod volume;

pub use any::AnyDomain;
pub use grid::{Grid2d, Plane, MAX_SPACING, MIN_SPACING};
pub use masked::{MaskedGrid, MaskedVolume, Restriction};
pub use mesh::{shapes, triangle_area, TriMesh};
pub use order::{sos_greater, sos_less, sos_sort, sos_untied, value_range};
pub use series::Series;
pub use tet_mesh::TetMesh;
pub use volume::{Grid3d, NEIGHBOUR_OFFSETS};

/// How persistence pairs are formed on a domain (SPEC.md, "Persistence").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairingRule {
    /// A path: maxima are the merge points of the sublevel minima; pairs are (min, max).
    Path,
    /// A surface: minima from sublevel sets, maxima from superlevel sets, paired with saddles.
    Surface,
}

/// A simplicial domain carrying one value per vertex.
pub trait Domain {
    /// Number of vertices `#V`.
    fn n_vertices(&self) -> usize;
    /// Neighbours of `v` (vertices sharing an edge with it), each once.
    fn neighbors(&self, v: usize) -> impl Iterator<Item = usize> + '_;
    /// Which persistence pairing applies.
    fn pairing_rule(&self) -> PairingRule;
    /// Largest distance between two vertices (or a bound of it): the length scale of defaults.
    fn diameter(&self) -> f64;

    /// Position of vertex `v` (a series lies on the x axis; a grid in the plane z = 0).
    fn point(&self, v: usize) -> [f64; 3];

    /// The triangles of a 2D domain (none for a series).
    fn triangles(&self) -> Vec<[usize; 3]> {
        Vec::new()
    }

    /// Every edge once, as `(i, j)` with `i < j`.
    fn edges(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for i in 0..self.n_vertices() {
            for j in self.neighbors(i) {
                if i < j {
                    out.push((i, j));
                }
            }
        }
        out
    }
}
