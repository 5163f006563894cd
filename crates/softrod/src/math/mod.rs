//! Small mathematics shared by every model: rotations, rigid transforms (the one adjoint),
//! small dense linear algebra, the arc series of constant-curvature kinematics and arc-length
//! samples.

pub mod linalg;
pub mod samples;
pub mod se3;
pub mod series;
pub mod so3;
