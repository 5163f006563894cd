//! Small mathematics shared by every model: rotations, rigid transforms (the one adjoint).

pub mod se3;
pub mod so3;
