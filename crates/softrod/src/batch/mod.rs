//! Many solves at once: workspace maps; distances between backbones.

pub mod compare;
pub mod workspace;
