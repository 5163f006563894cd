//! The robot description: rod, section, material laws, tendons, chambers and loads.

pub mod actuation;
pub mod chamber;
pub(crate) mod hold;
pub mod loads;
pub mod material;
pub mod robot;
pub mod rod;
pub mod section;
pub mod tendon;

pub use actuation::{Actuation, TendonInput};
pub use robot::RobotModel;
