//! Discrete operators: stiffness (minus the Laplacian), lumped mass, polyharmonic energies.
//!
//! Conventions (libigl's, with the sign flipped once): `K = −L` is the symmetric positive
//! semi-definite stiffness matrix with `K·1 = 0`, `M` the diagonal lumped mass. The
//! polyharmonic energy of order `k` is `E_k(f) = fᵀ Q_k f` with `Q_1 = K`, `Q_2 = K M⁻¹ K`,
//! `Q_3 = K M⁻¹ K M⁻¹ K`, `Q_4 = K M⁻¹ K M⁻¹ K M⁻¹ K` (paper eq. 18; `∫ |∇^k f|²`).
//!
//! ```
//! use toposmooth::{domain::Series, operators::{series_stiffness, series_mass, polyharmonic, Energy}};
//! let s = Series::uniform(5);
//! let (k, m) = (series_stiffness(&s), series_mass(&s));
//! let q = polyharmonic(&k, &m, &Energy::order(2), &[1.0]);
//! // a linear function has zero Laplacian inside; only the ends (natural boundary) see it
//! let f: Vec<f64> = (0..5).map(|i| i as f64).collect();
//! assert!(toposmooth::operators::quadratic_form(&q, &f) > 0.0);
//! assert!(toposmooth::operators::quadratic_form(&q, &[1.0; 5]).abs() < 1e-12);
//! ```

mod columns;
mod cotan;
mod factor;
mod gradient;
mod harmonic;
mod polyharmonic;
mod series;
mod sparse;
mod tet;
mod volume;

pub use columns::{BilaplacianColumns, Blocks, Column, COLUMN_BLOCK};
pub use cotan::{
    cotan_stiffness, grid_mass, grid_stiffness, lumped_mass, negative_cotan_edges, positive_cotan_stiffness,
};
pub use factor::{edge_factor, polyharmonic_factor, Factor};
pub use gradient::{gradient_factor, gradient_operator};
pub use harmonic::{dirichlet_solve, dirichlet_solve_with, Dirichlet};
pub(crate) use polyharmonic::polyharmonic_products;
pub use polyharmonic::{polyharmonic, Energy};
pub use series::{series_mass, series_stiffness};
pub(crate) use sparse::with_pattern_of;
pub use sparse::{plus_diagonal, quadratic_form, quadratic_form_without_diagonal, scaled_plus_diagonal, Sparse};
pub use tet::{positive_tet_stiffness, tet_gradient_factor, tet_gradient_operator, tet_lumped_mass, tet_stiffness};
pub(crate) use volume::volume_edge_pattern;
pub use volume::{volume_mass, volume_stiffness};
