//! The Cosserat-rod model with tendons and chambers: equations, constitutive local solve,
//! shooting statics.

pub(crate) mod equations;
mod hyperelastic_local;
pub mod statics;

pub use equations::{LOCAL_MAX_ITERATIONS, LOCAL_TOLERANCE};
