//! The representative function u: a function with exactly the kept extrema whose edge
//! orientation the output must follow (paper section 3.3). On a series, linear between
//! consecutive kept extrema ([`series`]); on a surface or a volume, the data with its cancelled
//! basins flooded ([`flooded`], the default for data) or the paper's separatrix interpolation
//! ([`separatrix`]); with no data, a harmonic function whose order survives underflow
//! (`harmonic_order`).

mod flooded;
#[cfg(feature = "serde")]
pub(crate) mod harmonic_order;
mod separatrix;
mod series;

pub use flooded::flooded_representative;
pub use separatrix::{separatrix_representative, Repairs};
pub use series::series_representative;
