//! Inverse statics: the actuation (tendon tensions, chamber pressures) that puts the tip — or
//! a set of points of the backbone — at a target, for the Cosserat model and for PCC.
//!
//! # Objective
//! Among the actuations `a` inside the bounds that reach the target exactly, the one of least
//! weighted norm from a reference actuation,
//!
//! ```text
//! min ½ Σ w_i (a_i - a_ref,i)²   s.t.   p(a) = p_target [, R(a) = R_target],   lo <= a <= hi,
//! ```
//!
//! with `a_ref = 0` and `w_i = 1 / N²` for a tension, `A_j² / N²` for the pressure of a chamber
//! of area `A_j` (the norm of the actuator forces) unless given. The minimum-norm actuation
//! has no co-contraction: antagonistic tendons do not pull against each other. A target out
//! of reach gives the closest reachable pose instead (least squares of the pose error, the
//! rotation weighted by `rotation_weight` m/rad, default the rod length), with
//! `converged = false` (or [`Error::TargetUnreachable`] with the remaining distance). A shape
//! target (points at arc lengths) is fitted in the least-squares sense: the actuation that
//! brings the backbone points closest to the targets (reached exactly if they can be).
//!
//! # Method
//! Sequential quadratic programming on the exact actuation Jacobian of the linearised
//! boundary-value problem ([`crate::cosserat::sensitivity`], or the PCC equilibrium), in two
//! phases.
//!
//! * Far from the target (pose error above [`NEAR_TARGET`] of the rod length): a trust region
//!   on the scaled actuation norm. The SQP step (below) is taken if it fits; otherwise the
//!   bounded Levenberg–Marquardt step `min |J_k d - e_k|² + μ |d|²_W` inside the bounds, `μ`
//!   set so that `|d|_W` meets the radius. The first radius moves the linearised pose by a
//!   quarter of the rod length: from a straight rod the linearisation asks for tensions of
//!   hundreds of newtons (its shortening is of second order in the bending).
//! * Near the target: the SQP step `min ½ dᵀ H d + (W (a_k - a_ref))ᵀ d` s.t. `J_k d = e_k`,
//!   `lo <= a_k + d <= hi` ([`qp::min_norm`] for `H = W`, then [`qp::active_set_qp`]), with
//!   a backtracking line search on the merit function `½ |a - a_ref|²_W + ν |e|` (`ν` 1.5
//!   times the multipliers' norm); steps below [`LOCAL_STEP`] are taken in full. `H` is the
//!   Hessian of the Lagrangian `W - Σ λ_k ∇²p_k` on the null space `Z` of the free columns of
//!   `J` (the only part that matters), from one directional difference of the exact Jacobian
//!   per null direction, `H z = W z - (J(a + εz) - J(a))ᵀ λ / ε`; it is made when the free
//!   set changes or the steps stop contracting ([`STALLED`]). With `H = W` alone the
//!   iteration oscillates where the curvature of the target manifold exceeds that of the
//!   norm.
//! * A model with probes ([`Forward::has_probes`]: an unloaded Cosserat robot, whose poses
//!   alone take one march of the state, about a quarter of an evaluation with its Jacobian)
//!   makes that curvature from second differences of the poses instead ([`PROBE_STEP`]), on
//!   the span of the range step `v` (the minimum-norm step off the null space) and `Z`:
//!   `Zᵀ H Z` and the cross term `Zᵀ H v`, which is all the SQP step uses of `H`, so the
//!   next step is Newton's on the KKT conditions (three probes for one null direction). It
//!   probes at every near step whose minimum-norm step is not within [`PROBE_FROM`] of the
//!   stopping test, and solves the step's program once, with the probed curvature (the
//!   program with the last curvature is solved only where no probe is made). Without the
//!   cross term (the directional differences above, or a secant) the steps contract only
//!   linearly, by about ten per step: a position error along the stiff axis of the rod asks
//!   for large range steps, and their coupling into the null space is first order; probing
//!   every near step converges quadratically (a warm-started 1 mm move in three or four
//!   evaluations and six probes).
//!
//! When the linearised target cannot be met inside the bounds, the bounded least squares
//! `min |J_k (a - a_k) - e_k|²` ([`qp::bounded_least_squares`], with the same norm as a
//! vanishing regularisation) is the step instead. The iteration stops when the pose error is
//! within the tolerances and the step is below `optimality_tolerance` (relative): the KKT
//! conditions of the program above hold. Every forward evaluation is one solve with its
//! Jacobian (for a robot without external loads, one march of the state with one column per
//! actuator; for such a robot with uniform intervals and a tip target, that march in closed
//! form, `uniform.rs`: one rigid RK4 step per interval and its exact derivative).
//!
//! [`inverse_statics_path`] follows a sequence of targets, each warm-started from the last.
//! The iteration is local; [`Starts`] runs it from several starts and keeps the best answer.
//!
//! The files: `problem.rs` (the checked program: bounds, weights, pose error rows), `sqp.rs`
//! (the iteration), `steps.rs` (its steps: quadratic programs, Levenberg–Marquardt, curvature,
//! trust radius), `starts.rs` (several starts), `cosserat.rs` (the Cosserat forward model), `uniform.rs` (its closed-form
//! march on uniform intervals), `pcc.rs` (the PCC forward model
//! and its closed-form iteration), `qp.rs` (the small quadratic programs).
//!
//! [`Error::TargetUnreachable`]: crate::error::Error::TargetUnreachable
//! [`Error::NotConverged`]: crate::error::Error::NotConverged

mod cosserat;
pub mod pcc;
mod pcc_closed;
mod problem;
pub mod qp;
mod sqp;
mod starts;
mod steps;
mod uniform;

use nalgebra::{DMatrix, Matrix3, Vector3};

use crate::cosserat::mesh::mesh_verdict;
use crate::cosserat::statics::{Integrator, SolveOptions};
use crate::error::{Error, Result};

pub use cosserat::{inverse_actuation, inverse_statics, CosseratForward};
pub(crate) use problem::{check_options, check_target};
pub use sqp::{inverse_statics_path, solve_inverse};
pub(crate) use starts::{check_starts, later_starts, over_starts, starts_on};
pub use starts::{
    Interrupt, Starts, MAX_STARTS, MAX_START_HALVINGS, SAME_OBJECTIVE, START_SLACK, START_TURNS,
};
pub(crate) use steps::{objective_change, trust_radius};

/// Default tolerance on the distance to a target position (m).
pub const DEFAULT_TOLERANCE: f64 = 1e-10;
/// Default tolerance on the rotation to a target orientation (rad).
pub const DEFAULT_ROTATION_TOLERANCE: f64 = 1e-9;
/// Default relative tolerance on the last step of the actuation (the KKT conditions).
pub const DEFAULT_OPTIMALITY_TOLERANCE: f64 = 1e-9;
/// Default cap on the iterations.
pub const DEFAULT_MAX_ITERATIONS: usize = 60;
/// Pose error (in units of the rod length) within which SQP steps are taken in full.
pub const NEAR_TARGET: f64 = 1e-4;
/// Regularisation of the bounded least squares, relative to the scale of `JᵀJ`.
pub const LEAST_SQUARES_REGULARISATION: f64 = 1e-12;
/// Relative length of an SQP step below which it is taken in full near the target (the merit
/// function cannot resolve smaller ones).
pub const LOCAL_STEP: f64 = 1e-5;
/// Ratio of successive steps near the target above which the curvature is made again.
pub const STALLED: f64 = 0.5;
/// The first trust radius: the scaled actuation that moves the linearised pose by this
/// fraction of the rod length.
pub const FIRST_RADIUS: f64 = 1.0;
/// Most halvings of a step.
pub const MAX_STEP_HALVINGS: usize = 30;
/// Relative length (scaled actuation, relative to `1 + |a|_W`) of the probes of the
/// curvature made from second differences of the poses.
pub const PROBE_STEP: f64 = 1e-4;
/// Most directions (range step and null directions) of the curvature made from probes: `k`
/// directions take `k (k + 1) / 2` probes.
pub const MAX_PROBE_DIRECTIONS: usize = 3;
/// Minimum-norm steps (relative to the stopping test's) above which the curvature is probed.
pub const PROBE_FROM: f64 = 100.0;

/// What the inverse statics aims at.
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// Target positions (m, world): one for the tip, or one per arc length of `s`.
    pub points: Vec<Vector3<f64>>,
    /// Undeformed arc lengths (m) of the backbone points that go to `points`; `None`: the tip.
    pub s: Option<Vec<f64>>,
    /// Target orientation of the tip (body → world), if any.
    pub rotation: Option<Matrix3<f64>>,
}

impl Target {
    /// The tip at `position` (m, world).
    pub fn tip(position: Vector3<f64>) -> Self {
        Self {
            points: vec![position],
            s: None,
            rotation: None,
        }
    }
}

/// Options of the inverse statics (keyword arguments in Python).
#[derive(Debug, Clone, PartialEq)]
pub struct InverseOptions {
    /// Weights `w_i > 0` of the actuation norm, one per tendon then per chamber (1/N², 1/Pa²;
    /// only their ratios matter, within 1e15 of each other); `None`: the actuator-force norm
    /// (see the module documentation).
    pub weights: Option<Vec<f64>>,
    /// Reference actuation `a_ref` (N, Pa); `None`: zero.
    pub reference: Option<Vec<f64>>,
    /// Bounds on every tension (N): `lo >= 0`, `hi` may be infinite.
    pub tension_bounds: (f64, f64),
    /// Bounds on every pressure (Pa, gauge): `lo >= -1 atm`, `hi` may be infinite.
    pub pressure_bounds: (f64, f64),
    /// Tolerance on the distance to the target position(s) (m).
    pub tolerance: f64,
    /// Tolerance on the rotation to the target orientation (rad).
    pub rotation_tolerance: f64,
    /// Relative tolerance on the last actuation step.
    pub optimality_tolerance: f64,
    /// Weight of the rotation error against the position error when the target is out of
    /// reach (m/rad); `None`: the rod length.
    pub rotation_weight: Option<f64>,
    /// Cap on the iterations.
    pub max_iterations: usize,
    /// `true`: a target out of reach is [`Error::TargetUnreachable`]; non-convergence is
    /// [`Error::NotConverged`]. `false`: returned with `converged == false`.
    pub throw: bool,
    /// The starts of the iteration (several: the best answer of all, see [`Starts`]).
    pub starts: Starts,
    /// Checked before each start after the first: stops a call of several starts.
    pub interrupt: Interrupt,
}

impl Default for InverseOptions {
    fn default() -> Self {
        Self {
            weights: None,
            reference: None,
            tension_bounds: (0.0, f64::INFINITY),
            pressure_bounds: (0.0, f64::INFINITY),
            tolerance: DEFAULT_TOLERANCE,
            rotation_tolerance: DEFAULT_ROTATION_TOLERANCE,
            optimality_tolerance: DEFAULT_OPTIMALITY_TOLERANCE,
            rotation_weight: None,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            throw: true,
            starts: Starts::One,
            interrupt: Interrupt::default(),
        }
    }
}

/// One evaluation of a forward model: the observed points' positions (m, world), the
/// rotation of the last one, and, if asked, per point the Jacobian of its pose twist
/// `[δp; δθ]` (world) with respect to the actuation (6 × n).
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Positions of the observed points (m, world).
    pub positions: Vec<Vector3<f64>>,
    /// Rotation of the last observed point (body → world).
    pub rotation: Matrix3<f64>,
    /// Per observed point, `d[δp; δθ]/da` (6 × n).
    pub jacobian: Option<Vec<DMatrix<f64>>>,
}

/// A forward model of the inverse statics: actuation → poses of the observed points.
pub trait Forward {
    /// Number of tendons and of chambers (the actuation is tensions then pressures).
    fn dims(&self) -> (usize, usize);
    /// Evaluates the model at the actuation `a`.
    ///
    /// # Errors
    /// When the forward solve fails.
    fn evaluate(&mut self, a: &[f64], jacobian: bool) -> Result<Evaluation>;
    /// Whether the model has a pass without the Jacobian several times cheaper than
    /// [`Forward::evaluate`] with it (for an unloaded Cosserat robot, one march of the state
    /// alone): the iteration then makes its curvature from second differences of the poses
    /// ([`PROBE_STEP`]).
    fn has_probes(&self) -> bool {
        false
    }
    /// The observed poses at `a` without the Jacobian.
    ///
    /// # Errors
    /// When the forward solve fails.
    fn probe(&mut self, a: &[f64]) -> Result<Evaluation> {
        self.evaluate(a, false)
    }
    /// Forgets what earlier evaluations leave for later ones (the warm start of the next
    /// forward solve), so that the next evaluation is that of a new forward model: each start
    /// of [`inverse_statics_path`] begins so, as each start of the inverse from a model does.
    fn forget(&mut self) {}
    /// A length scale (m): the rod length.
    fn length(&self) -> f64;
    /// The areas (m²) of the chambers, for the default weights.
    fn chamber_areas(&self) -> Vec<f64>;
}

/// The result of the inverse statics.
#[derive(Debug, Clone, PartialEq)]
pub struct InverseSolution {
    /// The actuation found: tensions (N), then pressures (Pa).
    pub actuation: Vec<f64>,
    /// Number of tendons (the first entries of `actuation`).
    pub n_tendons: usize,
    /// Largest distance from a target position (m).
    pub position_error: f64,
    /// Rotation to the target orientation (rad; 0 without one).
    pub rotation_error: f64,
    /// Iterations (SQP steps taken).
    pub iterations: usize,
    /// Forward evaluations (with the Jacobian).
    pub evaluations: usize,
    /// Forward passes without the Jacobian (probes of the curvature, [`Forward::probe`]).
    pub probes: usize,
    /// Whether the iteration converged: the target reached within the tolerances (for a
    /// shape target: the least-squares fit found) with the minimum-norm actuation.
    pub converged: bool,
    /// Whether the target was reached within the tolerances.
    pub reached: bool,
    /// The last evaluation (at `actuation`), with its Jacobian.
    pub evaluation: Evaluation,
    /// The quasi-Newton Hessian of the Lagrangian at the end (n × n), for a warm start.
    pub hessian: DMatrix<f64>,
    /// The start it came from ([`Starts`]): 0 for the warm start or the reference, `k` for
    /// the `k`-th later one.
    pub start: usize,
    /// The RK4 steps of the mesh the answer was found on (a Cosserat model on the RK4
    /// integrator: more than asked where the mesh control refined it); `None` otherwise.
    pub steps: Option<usize>,
}

impl InverseSolution {
    /// Tendon tensions (N).
    pub fn tensions(&self) -> &[f64] {
        &self.actuation[..self.n_tendons]
    }
    /// Chamber pressures (Pa).
    pub fn pressures(&self) -> &[f64] {
        &self.actuation[self.n_tendons..]
    }
}

/// A previous result to start from: its actuation and (if at the same model and loads) its
/// last evaluation, which saves the first forward evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct InverseWarmStart {
    /// Tensions then pressures (N, Pa).
    pub actuation: Vec<f64>,
    /// The evaluation at `actuation`, with its Jacobian.
    pub evaluation: Option<Evaluation>,
    /// The quasi-Newton Hessian of the Lagrangian (n × n) of that result.
    pub hessian: Option<DMatrix<f64>>,
}

impl InverseWarmStart {
    /// A warm start from an actuation alone (tensions then pressures).
    pub fn actuation(actuation: Vec<f64>) -> Self {
        Self {
            actuation,
            evaluation: None,
            hessian: None,
        }
    }
}

impl From<InverseSolution> for InverseWarmStart {
    fn from(s: InverseSolution) -> Self {
        Self {
            actuation: s.actuation,
            evaluation: Some(s.evaluation),
            hessian: Some(s.hessian),
        }
    }
}

/// An inverse statics `run` (on the solve options, with the inverse options and warm start
/// given; it returns the result and its forward model) under the mesh control of a forward
/// solve at its answer: on the default RK4 mesh, an answer whose estimated tip error
/// (`mesh_error` of the forward model there, relative to the length) exceeds
/// [`DEFAULT_MESH_POSITION_LIMIT`](crate::cosserat::mesh::DEFAULT_MESH_POSITION_LIMIT) makes
/// the inverse run again on a finer mesh from the answer (its actuation and Hessian; its
/// evaluation, of the coarser mesh, dropped), whose result returns; on a chosen mesh, one
/// above [`CHOSEN_MESH_POSITION_LIMIT`](crate::cosserat::mesh::CHOSEN_MESH_POSITION_LIMIT) is
/// an error naming `steps`. A target missed (`TargetUnreachable`, `NotConverged`) is judged
/// where the iteration stopped (run again without the error), since the verdict may be the
/// coarse mesh's. An answer on the finer mesh where the mesh asked suffices is found again on
/// the mesh asked (from it), so that the answer's mesh is the one a solve there takes; the
/// answer's `steps` say which it is.
///
/// # Errors
/// `run`'s; `steps` as above.
pub(crate) fn mesh_controlled<F>(
    solve: &SolveOptions,
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
    mut run: impl FnMut(
        &SolveOptions,
        &InverseOptions,
        Option<&InverseWarmStart>,
    ) -> Result<(InverseSolution, F)>,
    mut mesh_error: impl FnMut(&mut F, &[f64]) -> f64,
) -> Result<(InverseSolution, F)> {
    let first = run(solve, options, warm);
    let Integrator::Rk4 { steps } = solve.integrator else {
        return first;
    };
    let (out, mut fwd, missed) = match first {
        Ok((out, fwd)) => (out, fwd, None),
        Err(e @ (Error::TargetUnreachable { .. } | Error::NotConverged { .. })) => {
            let quiet = InverseOptions {
                throw: false,
                ..options.clone()
            };
            match run(solve, &quiet, warm) {
                Ok((last, again)) => (last, again, Some(e)),
                Err(_) => return Err(e),
            }
        }
        Err(e) => return Err(e),
    };
    let error = mesh_error(&mut fwd, &out.actuation);
    let Some(finer) = mesh_verdict(error, steps, solve.integrator.is_default_mesh())? else {
        return match missed {
            Some(e) => Err(e),
            None => Ok((
                InverseSolution {
                    steps: Some(steps),
                    ..out
                },
                fwd,
            )),
        };
    };
    let fine = SolveOptions {
        integrator: Integrator::Rk4 { steps: finer },
        ..*solve
    };
    let from = InverseWarmStart {
        evaluation: None,
        ..InverseWarmStart::from(&out)
    };
    // An answer of the coarser mesh where the finer one finds the rod cannot be solved (a
    // tendon's path turning back on itself between the coarse nodes) is no start: the finer
    // mesh starts where the first iteration did.
    let (out, fine_fwd) = match run(&fine, options, Some(&from)) {
        Err(e) if e.names("warm_start") => run(&fine, options, warm)?,
        other => other?,
    };
    // The finer mesh was chosen where the first iteration stopped; an answer where the mesh
    // asked suffices (the iteration passed through a more strongly bent shape) is sought
    // again on that mesh from there: the mesh a solve at the answer takes.
    let mut asked_suffices = || {
        let error = mesh_error(&mut fwd, &out.actuation);
        matches!(
            mesh_verdict(error, steps, solve.integrator.is_default_mesh()),
            Ok(None)
        )
    };
    if out.converged && asked_suffices() {
        let from = InverseWarmStart {
            evaluation: None,
            ..InverseWarmStart::from(&out)
        };
        if let Ok((again, fwd)) = run(solve, options, Some(&from)) {
            if again.converged {
                let steps = Some(steps);
                return Ok((InverseSolution { steps, ..again }, fwd));
            }
        }
    }
    let steps = Some(finer);
    Ok((InverseSolution { steps, ..out }, fine_fwd))
}

/// An inverse statics of `target` from each start of `options.starts` ([`over_starts`]),
/// each under the mesh control of [`mesh_controlled`]: the forward model made by `forward`
/// on the solve options given, solved by `inverse` (e.g. [`solve_inverse`]), its mesh judged
/// by `mesh_error` at an answer. Returns the best answer and its forward model.
///
/// # Errors
/// As [`over_starts`] and [`mesh_controlled`]; `forward`'s.
pub(crate) fn resolved<F: Forward>(
    target: &Target,
    options: &InverseOptions,
    solve: &SolveOptions,
    warm: Option<&InverseWarmStart>,
    forward: impl Fn(&SolveOptions) -> Result<F>,
    inverse: impl Fn(&mut F, &InverseOptions, Option<&InverseWarmStart>) -> Result<InverseSolution>,
    mesh_error: impl Fn(&mut F, &[f64]) -> f64,
) -> Result<(InverseSolution, F)> {
    let later = later_starts(target, options, || forward(solve))?;
    over_starts(options, warm, later, |io, w| {
        mesh_controlled(
            solve,
            io,
            w,
            |so, io, w| {
                let mut fwd = forward(so)?;
                let out = inverse(&mut fwd, io, w)?;
                Ok((out, fwd))
            },
            &mesh_error,
        )
    })
}

impl From<&InverseSolution> for InverseWarmStart {
    fn from(s: &InverseSolution) -> Self {
        Self {
            actuation: s.actuation.clone(),
            evaluation: Some(s.evaluation.clone()),
            hessian: Some(s.hessian.clone()),
        }
    }
}
