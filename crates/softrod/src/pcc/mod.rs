//! Piecewise-constant-curvature kinematics, actuation maps and statics.

pub mod actuation;
pub mod kinematics;
pub mod statics;

pub use actuation::*;
pub use kinematics::*;
