//! # softrod
//!
//! Steady-state shape and configuration-dependent compliance of soft and continuum robots.
//!
//! Conventions used everywhere: SI units; arc length `s` along the undeformed backbone;
//! the body z axis is the rod tangent; wrenches are `[force; moment]` and twists
//! `[translation; rotation]`.
//!
//! Modules:
//! * [`planar`]: seed 000, the planar tapered cable-driven arm (closed form and final-value ODE);
//! * [`compare`]: distances between backbones at equal arm index;
//! * [`integrate`]: ODE integrators shared by every model;
//! * [`hyperelastic`]: uniaxial material laws (linear, Neo-Hookean, Mooney–Rivlin, Yeoh, Ogden)
//!   and a library of named silicones;
//! * [`fit`]: least-squares fitting of those laws to uniaxial test data;
//! * [`se3`]: the adjoint and the twist/wrench ordering (owned here, used everywhere);
//! * [`compliance`](mod@compliance), [`eigenscrew`], [`workspace`]: seed 001,
//!   configuration-dependent compliance and stiffness (Cosserat and PCC configurations),
//!   eigenscrews, workspace maps;
//! * [`error`]: the crate's one error type.

pub mod batch;
pub mod compliance;
pub mod cosserat;
pub mod error;
pub mod integrate;
pub mod math;
pub mod model;
pub mod pcc;
pub mod planar;
pub mod solve;

pub use batch::compare::{backbone_distance, BackboneDistance};
pub use batch::workspace::{workspace_map, WorkspaceSample};
pub use compliance::eigenscrew::{eigenscrews, Decomposition, Eigenscrew, Ellipsoid, MatrixKind};
pub use compliance::{
    compliance, pcc_compliance, tangent_compliance, Compliance, Configuration, TangentCompliance,
    TendonControl,
};
pub use cosserat::statics::{solve_statics, Integrator, SolveOptions, StaticsSolution, WarmStart};
pub use error::{Error, Result};
pub use integrate::{AdaptiveOptions, IntegrationStats};
pub use model::chamber::{Chamber, ChamberArea};
pub use model::loads::{Frame, Loads, PointLoad};
pub use model::material::fit::{
    fit_stats, fit_uniaxial, FitOptions, FitStats, ModelKind, StrainMeasure, StressMeasure,
    UniaxialData, UniaxialFit,
};
pub use model::material::hyperelastic::{
    Hookean, Linearised, MooneyRivlin, NeoHookean, Ogden, Silicone, UniaxialLaw, UniaxialModel,
    Yeoh,
};
pub use model::material::{LinearElastic, Material};
pub use model::rod::{Pose, Profile, Rod};
pub use model::section::{Section, SectionProperties};
pub use model::tendon::{Routing, Tendon};
pub use model::{Actuation, RobotModel, TendonInput};
pub use nalgebra;
pub use planar::{
    solve_planar, solve_planar_many, uniform_samples, PlanarBatch, PlanarCableArm, PlanarMethod,
    PlanarSolution,
};
pub use solve::{NewtonOptions, SolverStats};
