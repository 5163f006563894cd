//! # softrod
//!
//! Steady-state shape and configuration-dependent compliance of soft and continuum robots.
//!
//! Conventions used everywhere: SI units; arc length `s` along the undeformed backbone;
//! the body z axis is the rod tangent; wrenches are `[force; moment]` and twists
//! `[translation; rotation]`.
//!
//! Modules:
//! * [`planar`]: seed 000, the planar tapered cable-driven arm (closed form and final-value ODE);
//! * [`compare`]: distances between backbones at equal arm index;
//! * [`integrate`]: ODE integrators shared by every model;
//! * [`error`]: the crate's one error type.

pub mod compare;
pub mod error;
pub mod integrate;
pub mod planar;

pub use compare::{backbone_distance, BackboneDistance};
pub use error::{Error, Result};
pub use integrate::{AdaptiveOptions, IntegrationStats};
pub use planar::{
    solve_planar, solve_planar_many, uniform_samples, PlanarBatch, PlanarCableArm, PlanarMethod,
    PlanarSolution,
};
