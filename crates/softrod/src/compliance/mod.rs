//! Configuration-dependent compliance (the compliance-methodology paper): the integrated compliance along a solved
//! configuration, the exact tangent compliance of the equilibrium, eigenscrews.

mod controlled;
pub mod eigenscrew;
mod integrated;
pub mod refine;
mod tangent;

pub use crate::cosserat::mesh::{
    rk4_position_error, rk4_rotation_error, solve_at_output, with_mesh_control,
    CHOSEN_MESH_POSITION_LIMIT, DEFAULT_MESH_POSITION_LIMIT, OUTPUT_ROTATION_TARGET,
};
pub use controlled::{COMPLIANCE_ATOL, COMPLIANCE_RTOL};
pub use integrated::*;
pub use refine::MESH_ROTATION_TARGET;
pub use tangent::{
    frictional_tangent_compliance, tangent_compliance, tangent_compliance_held, TangentCompliance,
    TendonControl, COLUMNS_PER_PASS,
};
