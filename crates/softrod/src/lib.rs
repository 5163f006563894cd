//! # softrod
//!
//! Steady-state shape and configuration-dependent compliance of soft and continuum robots.
//!
//! Conventions used everywhere: SI units; arc length `s` along the undeformed backbone;
//! the body z axis is the rod tangent; wrenches are `[force; moment]` and twists
//! `[translation; rotation]` ([`math::se3`] owns the adjoint).
//!
//! The crate is laid out as the architecture (see `docs/architecture.md`):
//! * [`model`]: the validated, immutable [`RobotModel`] (rod, section, material, tendon
//!   routings, chamber geometry, loads) and the [`Actuation`] input (tensions, pressures);
//! * [`contact`]: end constraints and unilateral contact with obstacles through the
//!   shooting problem, [`solve_constrained`];
//! * [`cosserat`]: the Cosserat-rod statics, [`solve_statics`]`(&model, &actuation,
//!   &options)`, whose [`StaticsSolution`] keeps its model, actuation and options;
//! * [`compliance`](mod@compliance): integrated and tangent compliance, eigenscrews;
//! * [`pcc`]: piecewise-constant-curvature kinematics, actuation maps and statics;
//! * [`planar`]: the planar tapered cable arm (closed form and final-value ODE);
//! * [`batch`]: workspace maps, actuation sweeps of design points and backbone distances;
//! * [`inverse`]: inverse statics (minimum-norm actuation reaching a target) and trajectory
//!   tracking, for the Cosserat and PCC models; [`cosserat::sensitivity`] gives the exact
//!   actuation Jacobians and parameter sensitivities it uses;
//! * [`integrate`]: the one Runge–Kutta driver (RK4, Bogacki–Shampine, Dormand–Prince
//!   tableaus) and the march over breaks;
//! * [`solve`]: the one nonlinear solver (Newton, Broyden, line search, continuation);
//! * [`math`]: rotations, the adjoint, small linear algebra, the arc series;
//! * [`error`]: the crate's one error type; [`limits`]: the limits on input sizes and loads.

pub mod batch;
pub mod compliance;
pub mod contact;
pub mod cosserat;
pub mod error;
pub mod integrate;
pub mod inverse;
pub mod limits;
pub mod math;
pub mod model;
pub mod pcc;
pub mod planar;
pub mod solve;

pub use batch::compare::{backbone_distance, BackboneDistance};
pub use batch::sweep::{
    sweep, ActuationTable, ArcSample, SampleStatus, SweepJob, SweepRequest, SweepSample,
};
pub use batch::workspace::{workspace_map, WorkspaceSample};
pub use compliance::eigenscrew::{eigenscrews, Decomposition, Eigenscrew, Ellipsoid, MatrixKind};
pub use compliance::{
    compliance, pcc_compliance, tangent_compliance, Compliance, Configuration, TangentCompliance,
    TendonControl,
};
pub use contact::{
    contact_inverse_resolved, contact_inverse_statics, solve_constrained, solve_contact_inverse,
    Contact, ContactCompliance, ContactForward, ContactSolution, ContactState, Obstacle,
    TipConstraint, TriangleMesh,
};
pub use cosserat::displacement::reference_lengths;
pub use cosserat::friction::{
    friction_mesh, solve_frictional, solve_frictional_checked, solve_path, FrictionOptions,
    FrictionalSolution, GuideMethod, GuideState, Slip, GUIDE_FIXED_POINT_BUDGET,
    GUIDE_FORCE_TOLERANCE,
};
pub use cosserat::friction_linear::{frictional_tip_compliance, Direction};
pub use cosserat::sensitivity::{
    actuation_jacobian, actuation_jacobians, actuation_parameters, directional_actuation_jacobian,
    sensitivities, Linearisation, Parameter, Sensitivities,
};
pub use cosserat::statics::{
    solve_statics, solve_statics_at, Integrator, SolveOptions, StaticsSolution, WarmStart,
};
pub use error::{Error, Result};
pub use integrate::{AdaptiveOptions, IntegrationStats};
pub use inverse::pcc::{pcc_inverse_statics, PccForward};
pub use inverse::{
    inverse_actuation, inverse_statics, inverse_statics_path, solve_inverse, CosseratForward,
    Evaluation, Forward, Interrupt, InverseOptions, InverseSolution, InverseWarmStart, Starts,
    Target, MAX_STARTS,
};
pub use model::actuation::TensionProfile;
pub use model::chamber::{Chamber, ChamberArea};
pub use model::loads::{Frame, Loads, PointLoad};
pub use model::material::fit::{
    fit_stats, fit_uniaxial, FitOptions, FitStats, ModelKind, StrainMeasure, StressMeasure,
    UniaxialData, UniaxialFit,
};
pub use model::material::hyperelastic::{
    Hookean, Linearised, MooneyRivlin, NeoHookean, Ogden, UniaxialLaw, UniaxialModel, Yeoh,
};
pub use model::material::silicone::Silicone;
pub use model::material::{LinearElastic, Material};
pub use model::rod::{Pose, Profile, Rod};
pub use model::section::{Section, SectionProperties};
pub use model::tendon::{Routing, Tendon};
pub use model::{Actuation, RobotModel, TendonInput};
pub use nalgebra;
pub use planar::{
    planar_sensitivities, solve_planar, solve_planar_many, uniform_samples, PlanarBatch,
    PlanarCableArm, PlanarMethod, PlanarParameter, PlanarSensitivities, PlanarSolution,
};
pub use solve::{NewtonOptions, SolverStats};
