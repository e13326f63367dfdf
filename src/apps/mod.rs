//! Applications built on the operators and the pipeline: geodesic distance (heat method),
//! handles and shape-aware weights, skinning and colour diffusion (no-data mode), and the
//! triangulation of 2D outlines.

#[cfg(feature = "meshing")]
pub mod cage;
pub mod diffuse;
pub mod geodesic;
pub mod handles;
#[cfg(feature = "meshing")]
pub mod outline;
pub mod skinning;
pub mod weights;
