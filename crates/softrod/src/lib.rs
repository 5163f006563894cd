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

pub mod chamber;
pub mod compare;
pub mod compliance;
pub mod eigenscrew;
pub mod error;
pub mod fit;
pub mod hyperelastic;
pub mod integrate;
pub mod pcc;
pub mod pcc_statics;
pub mod planar;

pub use chamber::{Chamber, ChamberArea};
pub use compare::{backbone_distance, BackboneDistance};
pub use compliance::{
    compliance, pcc_compliance, tangent_compliance, Compliance, Configuration, TangentCompliance,
    TendonControl,
};
pub use eigenscrew::{eigenscrews, Decomposition, Eigenscrew, Ellipsoid, MatrixKind};
pub use error::{Error, Result};
pub use fit::{
    fit_stats, fit_uniaxial, FitOptions, FitStats, ModelKind, StrainMeasure, StressMeasure,
    UniaxialData, UniaxialFit,
};
pub use hyperelastic::{
    Hookean, Linearised, MooneyRivlin, NeoHookean, Ogden, Silicone, UniaxialLaw, UniaxialModel,
    Yeoh,
};
pub use integrate::{AdaptiveOptions, IntegrationStats};
pub use planar::{
    solve_planar, solve_planar_many, uniform_samples, PlanarBatch, PlanarCableArm, PlanarMethod,
    PlanarSolution,
};

pub mod cosserat;
pub mod loads;
pub mod material;
pub mod rod;
pub mod se3;
pub mod section;
pub mod so3;
pub mod statics;
pub mod tendon;
pub mod workspace;

pub use loads::{Frame, Loads, PointLoad};
pub use material::{LinearElastic, Material};
pub use nalgebra;
pub use rod::{Pose, Profile, Rod};
pub use section::{Section, SectionProperties};
pub use statics::{
    solve_statics, Integrator, SolveOptions, SolverStats, StaticsSolution, WarmStart,
};
pub use tendon::{Routing, Tendon};
pub use workspace::{workspace_map, WorkspaceSample};
