//! Small mathematics shared by every model: rotations, rigid transforms (the one adjoint),
//! small dense linear algebra and the arc series of constant-curvature kinematics.

pub mod linalg;
pub mod se3;
pub mod series;
pub mod so3;
