//! A domain chosen at run time: what a file holds, a command runs on, or a binding passes.

use super::{Domain, Grid2d, Grid3d, Series, TetMesh, TriMesh};

/// A domain chosen at run time.
#[derive(Clone, Debug)]
pub enum AnyDomain {
    /// A series.
    Series(Series),
    /// An implicit grid.
    Grid(Grid2d),
    /// A triangle mesh.
    Mesh(TriMesh),
    /// An implicit volume grid.
    Volume(Grid3d),
    /// A tetrahedral mesh.
    Tets(TetMesh),
}

/// Runs `$body` with `$d` bound to the concrete domain inside an [`AnyDomain`] (every
/// variant implements [`Domain`] and the pipeline's `Smoothable`).
///
/// ```
/// use toposmooth::domain::{AnyDomain, Domain, Grid3d};
/// let d = AnyDomain::Volume(Grid3d::new(2, 3, 4).unwrap());
/// assert_eq!(toposmooth::with_domain!(&d, g => g.n_vertices()), 24);
/// ```
#[macro_export]
macro_rules! with_domain {
    ($any:expr, $d:ident => $body:expr) => {
        match $any {
            $crate::domain::AnyDomain::Series($d) => $body,
            $crate::domain::AnyDomain::Grid($d) => $body,
            $crate::domain::AnyDomain::Mesh($d) => $body,
            $crate::domain::AnyDomain::Volume($d) => $body,
            $crate::domain::AnyDomain::Tets($d) => $body,
        }
    };
}

impl AnyDomain {
    /// Vertices of the domain (the length a field must have).
    pub fn n_vertices(&self) -> usize {
        crate::with_domain!(self, d => d.n_vertices())
    }

    /// The dimension of the domain's cells: 1 (series), 2 (grids, triangle meshes), 3
    /// (volumes, tetrahedral meshes).
    pub fn dimension(&self) -> usize {
        match self {
            AnyDomain::Series(_) => 1,
            AnyDomain::Grid(_) | AnyDomain::Mesh(_) => 2,
            AnyDomain::Volume(_) | AnyDomain::Tets(_) => 3,
        }
    }

    /// A vertex as a reader finds it: `sample i`, `(row r, column c)` or `vertex i`.
    pub fn describe_vertex(&self, v: usize) -> String {
        match self {
            AnyDomain::Series(_) => format!("sample {v}"),
            AnyDomain::Grid(g) => {
                let (r, c) = g.row_col(v);
                format!("(row {r}, column {c})")
            }
            AnyDomain::Mesh(_) | AnyDomain::Tets(_) => format!("vertex {v}"),
            AnyDomain::Volume(g) => {
                let [i, j, k] = g.ijk(v);
                format!("(i {i}, j {j}, k {k})")
            }
        }
    }

    /// The domain in a few words: `50 samples`, `30 × 20 grid`, `mesh of …`.
    pub fn describe(&self) -> String {
        match self {
            AnyDomain::Series(s) => format!("{} samples", s.n_vertices()),
            AnyDomain::Grid(g) => format!("{} × {} grid", g.nx(), g.ny()),
            AnyDomain::Mesh(m) => format!("mesh of {}", m.describe()),
            AnyDomain::Volume(g) => format!("{} × {} × {} volume", g.nx(), g.ny(), g.nz()),
            AnyDomain::Tets(m) => format!("tetrahedral mesh of {}", m.describe()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertices_are_described_in_the_domain_s_terms() {
        let g = AnyDomain::Grid(Grid2d::new(4, 3).unwrap());
        assert_eq!(g.n_vertices(), 12);
        assert_eq!(g.describe_vertex(6), "(row 1, column 2)");
        assert_eq!(g.describe(), "4 × 3 grid");
        let s = AnyDomain::Series(Series::uniform(5));
        assert_eq!((s.n_vertices(), s.describe_vertex(3).as_str()), (5, "sample 3"));
    }
}
