//! Applications built on the operators: geodesic distance (heat method); meshes of 2D shapes
//! from outlines.

pub mod geodesic;
pub mod outline;
