//! Piecewise-constant-curvature kinematics, actuation maps and statics.

pub mod kinematics;
pub mod statics;

pub use kinematics::*;
