//! Piecewise-constant-curvature kinematics, actuation maps, statics and the actuation
//! Jacobian of an equilibrium.

pub mod actuation;
pub mod kinematics;
pub mod sensitivity;
pub mod statics;

pub use actuation::*;
pub use kinematics::*;
pub use sensitivity::pcc_actuation_jacobian;
