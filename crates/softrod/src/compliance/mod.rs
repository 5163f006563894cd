//! Configuration-dependent compliance (seed 001): the integrated compliance along a solved
//! configuration, the exact tangent compliance of the equilibrium, eigenscrews.

pub mod eigenscrew;
mod integrated;
mod tangent;

pub use integrated::*;
pub use tangent::{
    tangent_compliance, tangent_compliance_held, TangentCompliance, TendonControl, COLUMNS_PER_PASS,
};
