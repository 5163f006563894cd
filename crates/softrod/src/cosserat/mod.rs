//! The Cosserat-rod model with tendons and chambers: the equations and their variational
//! columns (`equations`), the constitutive local solve (linear and hyperelastic), the
//! shooting problem, the statics entry point and its solution ([`statics`]), and the exact
//! sensitivities of an equilibrium from the linearised boundary-value problem
//! ([`sensitivity`]: actuation Jacobians, parameter sensitivities).

pub(crate) mod collapse;
mod columns;
pub mod displacement;
pub(crate) mod equations;
pub mod friction;
mod friction_cell;
mod friction_held;
pub mod friction_linear;
mod friction_march;
pub mod friction_mesh;
mod guides;
mod hyperelastic_local;
pub mod mesh;
mod options;
pub mod sensitivity;
pub(crate) mod shooting;
mod solution;
mod stability;
pub mod statics;

pub use displacement::reference_lengths;
pub use equations::{LOCAL_MAX_ITERATIONS, LOCAL_TOLERANCE};
pub use friction::{
    friction_mesh, solve_frictional, solve_frictional_checked, solve_path, FrictionOptions,
    FrictionalSolution, GuideMethod, GuideState, Slip, GUIDE_FIXED_POINT_BUDGET,
    GUIDE_FORCE_TOLERANCE,
};
pub use friction_linear::{frictional_tip_compliance, Direction};
pub use sensitivity::{
    actuation_jacobian, actuation_jacobians, actuation_parameters, directional_actuation_jacobian,
    sensitivities, Linearisation, Parameter, Sensitivities,
};
pub(crate) use stability::{compliance_stability, tip_stability, JacobiCheck, Stability};
pub use stability::{CONSTRAINT_COMPLIANCE, NEUTRAL_MARGIN};
pub use statics::{
    solve_statics, solve_statics_at, Integrator, SolveOptions, StaticsSolution, WarmStart,
};
