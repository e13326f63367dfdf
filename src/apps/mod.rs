//! Applications built on the operators: geodesic distance (heat method).

pub mod geodesic;
