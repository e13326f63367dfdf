//! Topology of the input: persistence of extrema and the choice of the kept set.
//!
//! Everything here compares vertices in SoS order (value, index) and sees the domain only
//! through [`crate::domain::Domain`]; it never sees an operator.

pub mod gradient;
pub mod morse_smale;
pub mod persistence;
pub mod selection;

pub use persistence::{
    count_sos_extrema, extrema_table, sublevel_pairs, superlevel_pairs, ExtremumInfo, ExtremumKind, Pair,
};
pub use selection::{select, KeptExtremum, KeptSet, Role, Selection};
