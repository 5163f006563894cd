//! Configuration-dependent compliance: integrated, tangent, eigenscrews.

pub mod eigenscrew;
mod integrated;

pub use integrated::*;
