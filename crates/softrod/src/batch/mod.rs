//! Many solves at once: workspace maps; actuation sweeps of design points (with values at
//! chosen arc lengths); distances between backbones.

pub mod arc;
pub mod compare;
pub mod sweep;
pub mod workspace;
