//! Applications built on the operators: geodesic distance (heat method) and skinning (posing a
//! mesh from handle weights and transforms, linear or dual-quaternion blending).

pub mod geodesic;
pub mod skinning;
