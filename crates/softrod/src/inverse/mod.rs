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
//!
//! When the linearised target cannot be met inside the bounds, the bounded least squares
//! `min |J_k (a - a_k) - e_k|²` ([`qp::bounded_least_squares`], with the same norm as a
//! vanishing regularisation) is the step instead. The iteration stops when the pose error is
//! within the tolerances and the step is below `optimality_tolerance` (relative): the KKT
//! conditions of the program above hold. Every forward evaluation is one solve with its
//! Jacobian (for a robot without external loads, one march of the state with one column per
//! actuator).
//!
//! [`inverse_statics_path`] follows a sequence of targets, each warm-started from the last.

pub mod pcc;
pub mod qp;

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::cosserat::equations::{Column, Equations};
use crate::cosserat::sensitivity::{
    actuation_jacobians, integrate, scheme_of, Linearisation, Request, Seed,
};
use crate::cosserat::shooting::{Node, Shooting};
use crate::cosserat::statics::{assemble, solve_statics, SolveOptions, StaticsSolution, WarmStart};
use crate::error::{Error, Result};
use crate::math::so3::log_so3;
use crate::model::chamber::ATMOSPHERIC_PRESSURE;
use crate::model::loads::{Frame, PointLoad};
use crate::model::{Actuation, RobotModel};
use crate::solve::SolverStats;
use qp::Bounds;

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
    /// Weights `w_i > 0` of the actuation norm, one per tendon then per chamber (1/N², 1/Pa²);
    /// `None`: the actuator-force norm (see the module documentation).
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
    /// Forward evaluations.
    pub evaluations: usize,
    /// Whether the iteration converged: the target reached within the tolerances (for a
    /// shape target: the least-squares fit found) with the minimum-norm actuation.
    pub converged: bool,
    /// Whether the target was reached within the tolerances.
    pub reached: bool,
    /// The last evaluation (at `actuation`), with its Jacobian.
    pub evaluation: Evaluation,
    /// The quasi-Newton Hessian of the Lagrangian at the end (n × n), for a warm start.
    pub hessian: DMatrix<f64>,
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

impl From<&InverseSolution> for InverseWarmStart {
    fn from(s: &InverseSolution) -> Self {
        Self {
            actuation: s.actuation.clone(),
            evaluation: Some(s.evaluation.clone()),
            hessian: Some(s.hessian.clone()),
        }
    }
}

/// The damped BFGS update (Powell) of the Lagrangian Hessian `h` for the step `a0 → a1`, with
/// the Jacobians (scaled rows) `j0`, `j1` and the multipliers `lambda`: `s = a1 - a0`,
/// `y = W s - (j1 - j0)ᵀ λ`. Returns whether it was updated.
fn bfgs_update(
    h: &mut DMatrix<f64>,
    weights: &[f64],
    a0: &[f64],
    a1: &[f64],
    j0: &DMatrix<f64>,
    j1: &DMatrix<f64>,
    lambda: &DVector<f64>,
) -> bool {
    let n = a0.len();
    let s = DVector::from_fn(n, |i, _| a1[i] - a0[i]);
    if j0.shape() != j1.shape() || lambda.len() != j0.nrows() {
        return false;
    }
    let ws = DVector::from_fn(n, |i, _| weights[i] * s[i]);
    let y = ws - (j1 - j0).tr_mul(lambda);
    let hs = &*h * &s;
    let shs = s.dot(&hs);
    if !(shs > 0.0 && shs.is_finite() && y.iter().all(|v| v.is_finite())) {
        return false;
    }
    let sy = s.dot(&y);
    let r = if sy >= 0.2 * shs {
        y
    } else {
        let theta = 0.8 * shs / (shs - sy);
        &y * theta + &hs * (1.0 - theta)
    };
    let sr = s.dot(&r);
    if sr.is_nan() || sr <= 0.0 {
        return false;
    }
    *h += &r * r.transpose() / sr - &hs * hs.transpose() / shs;
    // Keep it symmetric to round-off.
    let sym = (&*h + h.transpose()) * 0.5;
    h.copy_from(&sym);
    true
}

pub(crate) fn check_options(o: &InverseOptions, nt: usize, nc: usize, length: f64) -> Result<()> {
    let n = nt + nc;
    let (tl, th) = o.tension_bounds;
    if !(tl.is_finite() && tl >= 0.0 && !th.is_nan() && th >= tl) {
        return Err(Error::invalid(
            "tension_bounds",
            format!("({tl}, {th})"),
            "(lo, hi) with 0 <= lo <= hi (N; hi may be inf)",
        ));
    }
    let (pl, ph) = o.pressure_bounds;
    if !(pl.is_finite() && pl >= -ATMOSPHERIC_PRESSURE && !ph.is_nan() && ph >= pl) {
        return Err(Error::invalid(
            "pressure_bounds",
            format!("({pl}, {ph})"),
            format!("(lo, hi) with -{ATMOSPHERIC_PRESSURE} <= lo <= hi (Pa; hi may be inf)"),
        ));
    }
    if let Some(w) = &o.weights {
        if w.len() != n {
            return Err(Error::invalid(
                "weights.len()",
                w.len(),
                format!("one per tendon and chamber, {n}"),
            ));
        }
        for (i, v) in w.iter().enumerate() {
            if !(v.is_finite() && *v > 0.0) {
                return Err(Error::invalid(format!("weights[{i}]"), v, "finite and > 0"));
            }
        }
    }
    if let Some(r) = &o.reference {
        if r.len() != n {
            return Err(Error::invalid(
                "reference.len()",
                r.len(),
                format!("one per tendon and chamber, {n}"),
            ));
        }
        for (i, v) in r.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::invalid(format!("reference[{i}]"), v, "finite"));
            }
        }
    }
    for (name, v) in [
        ("tolerance", o.tolerance),
        ("rotation_tolerance", o.rotation_tolerance),
        ("optimality_tolerance", o.optimality_tolerance),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::invalid(name, v, "finite and > 0"));
        }
    }
    if let Some(w) = o.rotation_weight {
        if !(w.is_finite() && w > 0.0) {
            return Err(Error::invalid("rotation_weight", w, "finite and > 0 m/rad"));
        }
    }
    if o.max_iterations == 0 {
        return Err(Error::invalid("max_iterations", 0, ">= 1"));
    }
    let _ = length;
    Ok(())
}

pub(crate) fn check_target(target: &Target) -> Result<()> {
    if target.points.is_empty() {
        return Err(Error::invalid("target_points", "[]", "at least one point"));
    }
    for (k, p) in target.points.iter().enumerate() {
        // Beyond MAX_LENGTH the distance to the target would not be a number worth reporting.
        if !p
            .iter()
            .all(|v| v.is_finite() && v.abs() <= crate::limits::MAX_LENGTH)
        {
            return Err(Error::invalid(
                format!("target_position[{k}]"),
                format!("{:?}", p.as_slice()),
                format!(
                    "finite, each coordinate within ±{:e} m",
                    crate::limits::MAX_LENGTH
                ),
            ));
        }
    }
    if let Some(s) = &target.s {
        if s.len() != target.points.len() {
            return Err(Error::invalid(
                "target_s.len()",
                s.len(),
                format!("one per target point, {}", target.points.len()),
            ));
        }
    }
    if let Some(r) = &target.rotation {
        if !r.iter().all(|v| v.is_finite()) || crate::math::so3::orthonormality_error(r) > 1e-6 {
            return Err(Error::invalid(
                "target_rotation",
                format!("{r:?}"),
                "a rotation matrix (orthonormal to 1e-6, det +1)",
            ));
        }
    }
    Ok(())
}

/// The rows of the pose error and its Jacobian (scaled: positions in m, rotations times the
/// rotation weight).
fn error_rows(
    target: &Target,
    ev: &Evaluation,
    rotation_weight: f64,
) -> (DVector<f64>, Option<DMatrix<f64>>, f64, f64) {
    let np = target.points.len();
    let rows = 3 * np + if target.rotation.is_some() { 3 } else { 0 };
    let mut e = DVector::zeros(rows);
    let mut dist = 0.0f64;
    for (k, p) in target.points.iter().enumerate() {
        let d = p - ev.positions[k];
        dist = dist.max(d.norm());
        e.fixed_rows_mut::<3>(3 * k).copy_from(&d);
    }
    let mut rot = 0.0;
    if let Some(rt) = &target.rotation {
        let w = log_so3(&(rt * ev.rotation.transpose()));
        rot = w.norm();
        e.fixed_rows_mut::<3>(3 * np)
            .copy_from(&(w * rotation_weight));
    }
    let jac = ev.jacobian.as_ref().map(|js| {
        let n = js[0].ncols();
        let mut a = DMatrix::zeros(rows, n);
        for k in 0..np {
            a.view_mut((3 * k, 0), (3, n))
                .copy_from(&js[k].view((0, 0), (3, n)));
        }
        if target.rotation.is_some() {
            a.view_mut((3 * np, 0), (3, n))
                .copy_from(&(js[np - 1].view((3, 0), (3, n)) * rotation_weight));
        }
        a
    });
    (e, jac, dist, rot)
}

/// The inverse statics of any [`Forward`] model (see the module documentation).
///
/// # Errors
/// [`Error::InvalidParameter`] naming a bad option or target; [`Error::TargetUnreachable`]
/// for a target out of reach and [`Error::NotConverged`] otherwise when `throw` is set; the
/// forward model's errors at the first evaluation.
#[allow(clippy::too_many_lines)] // one sequential algorithm, documented above
pub fn solve_inverse<F: Forward + ?Sized>(
    forward: &mut F,
    target: &Target,
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<InverseSolution> {
    let (nt, nc) = forward.dims();
    let n = nt + nc;
    let length = forward.length();
    check_options(options, nt, nc, length)?;
    check_target(target)?;
    if n == 0 {
        return Err(Error::invalid(
            "robot",
            "no tendons or chambers",
            "at least one actuator",
        ));
    }
    let areas = forward.chamber_areas();
    let weights: Vec<f64> = match &options.weights {
        Some(w) => w.clone(),
        None => (0..n)
            .map(|i| if i < nt { 1.0 } else { areas[i - nt].powi(2) })
            .collect(),
    };
    let mut lo = vec![options.tension_bounds.0; nt];
    lo.extend(vec![options.pressure_bounds.0; nc]);
    let mut hi = vec![options.tension_bounds.1; nt];
    hi.extend(vec![options.pressure_bounds.1; nc]);
    let centre = options.reference.clone().unwrap_or_else(|| vec![0.0; n]);
    let bounds = Bounds {
        lo,
        hi,
        weights,
        centre,
    };
    let clamp = |a: &mut [f64]| {
        for (i, v) in a.iter_mut().enumerate() {
            *v = v.max(bounds.lo[i]).min(bounds.hi[i]);
        }
    };
    if let Some(w) = warm {
        if w.actuation.len() != n || w.actuation.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "warm_start",
                format!("{:?}", w.actuation),
                format!("{n} finite actuation values (tensions, then pressures)"),
            ));
        }
    }
    let rotation_weight = options.rotation_weight.unwrap_or(length);
    let shape = target.s.is_some();
    let mut a: Vec<f64> = match warm {
        Some(w) => w.actuation.clone(),
        None => bounds.centre.clone(),
    };
    clamp(&mut a);
    let mut evaluations = 0;
    let reuse = warm.and_then(|w| {
        (w.actuation == a)
            .then(|| w.evaluation.clone())
            .flatten()
            .filter(|e| e.jacobian.is_some() && e.positions.len() == target.points.len())
    });
    let mut ev = match reuse {
        Some(e) => e,
        None => {
            evaluations += 1;
            forward.evaluate(&a, true)?
        }
    };
    let near = NEAR_TARGET * length;
    let mut iterations = 0;
    // The Hessian of the Lagrangian: W, then W corrected on the null space of the free
    // constraints by directional differences of the exact Jacobian (`curved_for`: the free set
    // it was made for).
    let mut hess = DMatrix::from_diagonal(&DVector::from_column_slice(&bounds.weights));
    let mut curved_for: Option<Vec<bool>> = None;
    if let Some(h) = warm.and_then(|w| w.hessian.as_ref()) {
        if h.shape() == (n, n) && h.iter().all(|v| v.is_finite()) && *h != hess {
            hess.copy_from(h);
            curved_for = Some(free_set(&a, &bounds));
        }
    }
    let scaled_norm = |v: &[f64]| -> f64 {
        v.iter()
            .zip(&bounds.weights)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt()
    };
    // The penalty of the pose error in the merit function ½|a - c|²_W + ν |e| near the target.
    let mut nu = 0.0f64;
    // The scaled length of the last step taken near the target (0: none).
    let mut last_step = 0.0f64;
    // The trust radius (scaled actuation norm): unset until the first Jacobian is known.
    let mut radius = f64::NAN;
    let finish = |a: Vec<f64>,
                  ev: Evaluation,
                  dist: f64,
                  rot: f64,
                  iterations: usize,
                  evaluations: usize,
                  converged: bool,
                  reached: bool,
                  hessian: DMatrix<f64>| InverseSolution {
        actuation: a,
        n_tendons: nt,
        position_error: dist,
        rotation_error: rot,
        iterations,
        evaluations,
        converged,
        reached,
        evaluation: ev,
        hessian,
    };
    loop {
        let (e, jac, dist, rot) = error_rows(target, &ev, rotation_weight);
        let reached = dist <= options.tolerance && rot <= options.rotation_tolerance;
        let Some(jac) = jac else {
            return Err(Error::NotConverged {
                what: "inverse statics: no Jacobian".into(),
                iterations,
                residual: dist,
                load_factor: 1.0,
            });
        };
        // The quadratic program in y = a + Δ: min ½ |y - c|²_W, J y = b, bounds.
        let av = DVector::from_column_slice(&a);
        let b = &e + &jac * &av;
        let tol_qp = 1e-3
            * options
                .tolerance
                .min(options.rotation_tolerance * rotation_weight);
        let merit = e.norm();
        let mut solved = solve_qp(
            &jac,
            &b,
            &a,
            &bounds,
            &hess,
            curved_for.is_some(),
            tol_qp,
            shape,
        );
        if !solved.least_squares && merit <= near {
            let free = free_set(solved.y.as_slice(), &bounds);
            // A step that does not contract: the curvature is stale (a warm start's, or
            // another point's); made again here.
            let d: Vec<f64> = (0..n).map(|i| solved.y[i] - a[i]).collect();
            let stalled = last_step > 0.0 && scaled_norm(&d) > STALLED * last_step;
            if stalled || curved_for.as_ref() != Some(&free) {
                if let Some(lambda) = &solved.lambda {
                    let (h, used) = curvature(
                        forward,
                        target,
                        &a,
                        &jac,
                        lambda,
                        &free,
                        &bounds,
                        rotation_weight,
                    );
                    evaluations += used;
                    if let Some(h) = h {
                        hess = h;
                        curved_for = Some(free);
                        solved = solve_qp(&jac, &b, &a, &bounds, &hess, true, tol_qp, shape);
                    }
                }
            }
        }
        let least_squares = solved.least_squares;
        if let Some(l) = &solved.lambda {
            nu = 1.5 * l.norm();
        }
        let lambda_k = solved.lambda.clone();
        let y = solved.y;
        let mut step: Vec<f64> = (0..n).map(|i| y[i] - a[i]).collect();
        let norm_a = scaled_norm(&a);
        let small = scaled_norm(&step) <= options.optimality_tolerance * (1.0 + norm_a);
        if std::env::var("SOFTROD_DEBUG_INVERSE").is_ok() {
            eprintln!(
                "it {iterations}: dist {dist:.3e} rot {rot:.3e} ls {least_squares} |step| {:.3e} radius {radius:.3e} a {:?}",
                scaled_norm(&step),
                a
            );
        }
        // A small step that still moves an actuator onto its bound (or off it) is taken: the
        // minimum-norm actuation has it exactly there, not a round-off away.
        let same_bounds = free_set(y.as_slice(), &bounds) == free_set(&a, &bounds);
        let stationary = small && (reached || least_squares) && same_bounds;
        if stationary || iterations >= options.max_iterations {
            let converged = stationary && (reached || shape);
            let out = finish(
                a,
                ev,
                dist,
                rot,
                iterations,
                evaluations,
                converged,
                reached,
                hess,
            );
            if !converged && options.throw {
                if stationary || (least_squares && !reached) {
                    return Err(Error::TargetUnreachable {
                        distance: dist,
                        rotation: rot,
                        iterations,
                    });
                }
                return Err(Error::NotConverged {
                    what: "inverse statics (SQP)".into(),
                    iterations,
                    residual: dist.max(rot * rotation_weight),
                    load_factor: 1.0,
                });
            }
            return Ok(out);
        }
        if radius.is_nan() {
            // A first step that moves the linearised pose by at most a quarter of the rod
            // length (the linearisation of a straight rod asks for huge tensions to shorten it).
            let sigma = scaled_jacobian_norm(&jac, &bounds.weights);
            radius = if sigma > 0.0 {
                (FIRST_RADIUS * length / sigma).max(norm_a)
            } else {
                f64::INFINITY
            };
        }
        // Steps: the SQP step if inside the trust region, else the bounded Levenberg–Marquardt
        // step on the pose error of that length; a rejected step shrinks the region.
        let mut accepted = None;
        // Near the target: the SQP step with a backtracking line search on the merit function.
        let near_phase = merit <= near;
        let slope = {
            let d = DVector::from_column_slice(&step);
            let grad: f64 = (0..n)
                .map(|i| bounds.weights[i] * (a[i] - bounds.centre[i]) * step[i])
                .sum();
            grad + nu * ((&e - &jac * d).norm() - merit)
        };
        let mut alpha = 1.0;
        while radius > 1e-14 * (1.0 + norm_a) && alpha > 1e-10 {
            let full = near_phase || scaled_norm(&step) <= radius;
            if !full {
                step = levenberg_marquardt_step(&jac, &e, &a, &bounds, radius);
            }
            let step_norm = scaled_norm(&step) * alpha;
            if step_norm <= 1e-15 * (1.0 + norm_a) {
                break;
            }
            let mut trial: Vec<f64> = (0..n).map(|i| a[i] + alpha * step[i]).collect();
            clamp(&mut trial);
            evaluations += 1;
            let predicted = {
                let d = DVector::from_column_slice(&step);
                merit - (&e - &jac * d).norm()
            };
            if let Ok(t) = forward.evaluate(&trial, true) {
                let (et, _, _, _) = error_rows(target, &t, rotation_weight);
                let mt = et.norm();
                let ok = if near_phase {
                    // The change of the merit, summed without cancellation.
                    let df =
                        objective_change(&bounds.weights, &bounds.centre, &a[..n], &trial[..n]);
                    let dphi = df + nu * (mt - merit);
                    let local = step_norm <= LOCAL_STEP * (1.0 + norm_a);
                    (local && mt <= near) || dphi <= 1e-4 * alpha * slope.min(0.0)
                } else {
                    mt <= (1.0 - 1e-4) * merit || (full && mt <= near)
                };
                if mt.is_finite() && ok {
                    radius = trust_radius(radius, full, step_norm, merit - mt, predicted);
                    last_step = if near_phase { step_norm } else { 0.0 };
                    accepted = Some((trial, t));
                    break;
                }
            }
            if near_phase {
                alpha *= 0.5;
            } else {
                radius = 0.25 * step_norm.min(radius);
            }
        }
        iterations += 1;
        match accepted {
            Some((trial, t)) => {
                // The curvature met along the step refines the Hessian (far from the target
                // too: a warm start's first step is the longest secant it gets).
                if curved_for.is_some() {
                    if let (Some(lambda), Some(jn)) =
                        (&lambda_k, error_rows(target, &t, rotation_weight).1)
                    {
                        bfgs_update(&mut hess, &bounds.weights, &a, &trial, &jac, &jn, lambda);
                    }
                }
                a = trial;
                ev = t;
            }
            None => {
                // No decrease in any direction: the closest pose (a local minimum of the error).
                let converged = shape && !reached;
                let out = finish(
                    a,
                    ev,
                    dist,
                    rot,
                    iterations,
                    evaluations,
                    converged,
                    reached,
                    hess,
                );
                if options.throw && !out.converged {
                    return Err(Error::TargetUnreachable {
                        distance: dist,
                        rotation: rot,
                        iterations,
                    });
                }
                return Ok(out);
            }
        }
    }
}

/// The regularisation of the bounded least squares (a vanishing pull to the reference).
fn ls_regularisation(jac: &DMatrix<f64>, bounds: &Bounds) -> f64 {
    let scale = jac
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .powi(2)
        .max(1e-300);
    let wmax = bounds.weights.iter().fold(0.0f64, |m, v| m.max(*v));
    LEAST_SQUARES_REGULARISATION * scale / wmax
}

/// The spectral norm of `J W^{-1/2}` (the pose change per unit scaled actuation).
fn scaled_jacobian_norm(jac: &DMatrix<f64>, weights: &[f64]) -> f64 {
    let js = DMatrix::from_fn(jac.nrows(), jac.ncols(), |r, c| {
        jac[(r, c)] / weights[c].sqrt()
    });
    let g = &js * js.transpose();
    g.symmetric_eigenvalues()
        .iter()
        .fold(0.0f64, |m, v| m.max(*v))
        .sqrt()
}

/// The bounded Levenberg–Marquardt step `d` of scaled length about `radius`:
/// `min |J d - e|² + μ |d|²_W` with `lo <= a + d <= hi`, `μ` raised until `|d|_W <= radius`.
fn levenberg_marquardt_step(
    jac: &DMatrix<f64>,
    e: &DVector<f64>,
    a: &[f64],
    bounds: &Bounds,
    radius: f64,
) -> Vec<f64> {
    let n = a.len();
    let av = DVector::from_column_slice(a);
    let b = e + jac * &av;
    let local = Bounds {
        centre: a.to_vec(),
        ..bounds.clone()
    };
    let norm = |d: &[f64]| -> f64 {
        d.iter()
            .zip(&bounds.weights)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt()
    };
    let sigma = scaled_jacobian_norm(jac, &bounds.weights).max(1e-300);
    // |d| ≈ |e| / μ-scaled: start from μ with |Jᵀe| / μ ≈ radius.
    let mut mu = (sigma * e.norm() / radius).max(1e-6 * sigma * sigma);
    let mut best = vec![0.0; n];
    let mut fitted = false;
    for _ in 0..60 {
        let y = qp::bounded_least_squares(jac, &b, &local, mu);
        let d: Vec<f64> = (0..n).map(|i| y[i] - a[i]).collect();
        if norm(&d) <= radius * 1.000_001 {
            best = d;
            fitted = true;
            // Lengthen it while it fits (a few times).
            mu *= 0.25;
            if mu < 1e-3 * sigma * sigma * 1e-6 {
                break;
            }
        } else if fitted {
            break;
        } else {
            mu *= 4.0;
        }
    }
    best
}

/// Whether no external load acts (zero point loads only mark integration breaks).
fn no_external_loads(model: &RobotModel) -> bool {
    let l = model.loads();
    l.tip_force == Vector3::zeros()
        && l.tip_moment == Vector3::zeros()
        && l.point_loads
            .iter()
            .all(|p| p.force == Vector3::zeros() && p.moment == Vector3::zeros())
        && l.distributed_force.is_none()
        && l.distributed_moment.is_none()
        && model.rho_g().is_none()
}

/// The Cosserat model as a [`Forward`] model: a robot model, its solver options and the
/// observed nodes; warm-started from its last solve.
pub struct CosseratForward {
    model: Arc<RobotModel>,
    options: SolveOptions,
    /// Node indices of the observed points; `None`: the tip.
    nodes: Option<Vec<usize>>,
    last: Option<WarmStart>,
    /// The last solution (loaded robots only).
    pub solution: Option<StaticsSolution>,
    /// The last march of an unloaded robot: its actuation, nodes, tendon path lengths and
    /// scaled tip residual (a statics solution is assembled from it without solving again).
    march: Option<March>,
}

/// The state recorded along one march of an unloaded robot at the actuation `a`.
struct March {
    a: Vec<f64>,
    nodes: Vec<Node>,
    lengths: Vec<f64>,
    residual: f64,
    evaluations: usize,
}

impl CosseratForward {
    /// The forward model of `model` solved with `options`, observing the tip, or the backbone
    /// points at the undeformed arc lengths `s` (m; the model gets integration breaks there
    /// unless they are mesh nodes already).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `target_s[k]` outside `(0, L]`, or the model's.
    pub fn new(model: &Arc<RobotModel>, options: &SolveOptions, s: Option<&[f64]>) -> Result<Self> {
        options.validate()?;
        let mut me = Self {
            model: Arc::clone(model),
            options: *options,
            nodes: None,
            last: None,
            solution: None,
            march: None,
        };
        if let Some(s) = s {
            let l = model.length();
            for (k, &v) in s.iter().enumerate() {
                if !(v.is_finite() && v > 0.0 && v <= l) {
                    return Err(Error::invalid(
                        format!("target_s[{k}]"),
                        v,
                        format!("in (0, length] = (0, {l}] m"),
                    ));
                }
            }
            let zero = Actuation::zero(model.tendons().len(), model.chambers().len());
            let probe = solve_statics(model, &zero, options)?;
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * l;
            let on_mesh = s.iter().all(|&v| probe.s.iter().any(|&x| close(x, v)));
            if !on_mesh {
                let mut loads = model.loads().clone();
                for &v in s {
                    if !model.breaks().iter().any(|&b| close(b, v)) {
                        loads.point_loads.push(PointLoad {
                            s: v,
                            force: Vector3::zeros(),
                            moment: Vector3::zeros(),
                            frame: Frame::World,
                        });
                    }
                }
                me.model = model.with_loads(loads)?;
            }
            let probe = solve_statics(&me.model, &zero, options)?;
            let nodes = s
                .iter()
                .map(|&v| {
                    probe
                        .s
                        .iter()
                        .rposition(|&x| close(x, v))
                        .ok_or_else(|| Error::invalid("target_s", v, "a point of the mesh"))
                })
                .collect::<Result<Vec<_>>>()?;
            me.nodes = Some(nodes);
        }
        Ok(me)
    }

    /// The model solved (with breaks at the observed arc lengths).
    pub fn model(&self) -> &Arc<RobotModel> {
        &self.model
    }

    fn actuation(&self, a: &[f64]) -> Actuation {
        let nt = self.model.tendons().len();
        Actuation::tensions(&a[..nt]).with_pressures(&a[nt..])
    }

    /// The statics solution at the actuation `a` (m, N, Pa).
    ///
    /// # Errors
    /// As [`solve_statics`].
    pub fn solve(&self, a: &[f64]) -> Result<StaticsSolution> {
        if let Some(sol) = self.assembled(a) {
            return Ok(sol);
        }
        let opts = SolveOptions {
            warm_start: self.last,
            ..self.options
        };
        solve_statics(&self.model, &self.actuation(a), &opts)
    }
}

impl CosseratForward {
    /// The statics solution of an unloaded robot at `a` from the last march, if it was at `a`:
    /// the zero base wrench, the nodes and path lengths of that march (the state integrated
    /// there is the forward solve's, step for step); `None` otherwise.
    fn assembled(&self, a: &[f64]) -> Option<StaticsSolution> {
        let m = self.march.as_ref().filter(|m| m.a == a)?;
        let model = &self.model;
        let nt = model.tendons().len();
        let (tensions, pressures) = (&a[..nt], &a[nt..]);
        let eq = Equations {
            model,
            tensions,
            pressures,
            load_factor: 1.0,
            profile: None,
        };
        let mut plan = Vec::new();
        let _ = scheme_of(&self.options.integrator, model, &mut plan);
        let mut p = Shooting::new(eq, self.options.integrator, plan);
        p.nodes.clone_from(&m.nodes);
        p.lengths.clone_from(&m.lengths);
        let converged = m.residual <= self.options.newton.tolerance
            && m.nodes.iter().all(|n| n.y.iter().all(|v| v.is_finite()));
        let stats = SolverStats {
            iterations: 0,
            residual: m.residual,
            function_evaluations: m.evaluations,
            converged,
            load_steps: 0,
            load_factor: 1.0,
        };
        let mut sol = assemble(&mut p, model, [0.0; 6], stats, &[]);
        if !converged || p.ws.material_error.is_some() {
            return None;
        }
        sol.actuation = self.actuation(a);
        sol.options = self.options;
        sol.stable = true;
        Some(sol)
    }
}

impl CosseratForward {
    /// The evaluation of an unloaded robot with its Jacobian: the base wrench is zero and does
    /// not move with the actuation, so one march of the state with one column per actuator.
    fn unloaded(&mut self, a: &[f64]) -> Result<Evaluation> {
        let (nt, nc) = self.dims();
        let (tensions, pressures) = (&a[..nt], &a[nt..]);
        let act = self.actuation(a);
        act.validate(nt, nc)?;
        let eq = Equations {
            model: &self.model,
            tensions,
            pressures,
            load_factor: 1.0,
            profile: None,
        };
        let seeds: Vec<Seed> = (0..nt)
            .map(|i| Seed::Forced(Column::Tension(i)))
            .chain((0..nc).map(|j| Seed::Forced(Column::Pressure(j))))
            .collect();
        let mut plan = Vec::new();
        let scheme = scheme_of(&self.options.integrator, &self.model, &mut plan);
        let observe = self.nodes.clone().unwrap_or_default();
        let mut sorted = observe.clone();
        sorted.sort_unstable();
        sorted.dedup();
        let cols = integrate(
            eq,
            scheme,
            &[0.0; 6],
            &Request {
                seeds: &seeds,
                lengths: &[],
                observe: &sorted,
                load_node: None,
                record_nodes: true,
                stops: &[],
            },
        )?;
        self.march = Some(March {
            a: a.to_vec(),
            nodes: cols.nodes.clone(),
            lengths: cols.lengths.clone(),
            residual: crate::solve::max_norm(cols.residual.as_slice()),
            evaluations: cols.evaluations,
        });
        let to_matrix = |c: &[nalgebra::Vector6<f64>]| DMatrix::from_fn(6, nt + nc, |r, k| c[k][r]);
        Ok(match &self.nodes {
            None => Evaluation {
                positions: vec![cols.tip_pose.0],
                rotation: cols.tip_pose.1,
                jacobian: Some(vec![to_matrix(&cols.tip)]),
            },
            Some(nodes) => {
                let at = |i: usize| sorted.iter().position(|&x| x == i).unwrap_or(0);
                let positions = nodes
                    .iter()
                    .map(|&i| crate::cosserat::equations::v3(&cols.nodes[i].y, 0))
                    .collect();
                let last = *nodes.last().unwrap_or(&0);
                Evaluation {
                    positions,
                    rotation: cols.rotations[at(last)],
                    jacobian: Some(
                        nodes
                            .iter()
                            .map(|&i| to_matrix(&cols.poses[at(i)]))
                            .collect(),
                    ),
                }
            }
        })
    }
}

impl Forward for CosseratForward {
    fn dims(&self) -> (usize, usize) {
        (self.model.tendons().len(), self.model.chambers().len())
    }

    fn length(&self) -> f64 {
        self.model.length()
    }

    fn chamber_areas(&self) -> Vec<f64> {
        self.model
            .chambers()
            .iter()
            .zip(self.model.chamber_extents())
            .map(|(c, (start, _))| c.area_at(*start))
            .collect()
    }

    fn evaluate(&mut self, a: &[f64], jacobian: bool) -> Result<Evaluation> {
        if no_external_loads(&self.model) && jacobian {
            return self.unloaded(a);
        }
        let sol = self.solve(a)?;
        self.last = Some(sol.warm_start());
        let n = sol.s.len();
        let nodes = self.nodes.clone().unwrap_or_else(|| vec![n - 1]);
        let rot = |i: usize| {
            let r = sol.rotation[i];
            Matrix3::new(
                r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
            )
        };
        let positions = nodes
            .iter()
            .map(|&i| Vector3::from(sol.position[i]))
            .collect();
        let last = *nodes.last().unwrap_or(&(n - 1));
        let jac = if jacobian {
            let mut sorted = nodes.clone();
            sorted.sort_unstable();
            sorted.dedup();
            let js = actuation_jacobians(&sol, &sorted, Linearisation::Tension)?;
            Some(
                nodes
                    .iter()
                    .map(|i| js[sorted.iter().position(|x| x == i).unwrap_or(0)].clone())
                    .collect(),
            )
        } else {
            None
        };
        let out = Evaluation {
            positions,
            rotation: rot(last),
            jacobian: jac,
        };
        self.solution = Some(sol);
        Ok(out)
    }
}

/// The inverse statics of a Cosserat robot `model` (solved with `options`) for `target`
/// (see the module documentation); returns the result and the statics solution at the
/// actuation found.
///
/// # Errors
/// As [`solve_inverse`]; the forward solve's errors.
pub fn inverse_statics(
    model: &Arc<RobotModel>,
    target: &Target,
    options: &InverseOptions,
    solve: &SolveOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<(InverseSolution, StaticsSolution)> {
    let mut fwd = CosseratForward::new(model, solve, target.s.as_deref())?;
    let out = solve_inverse(&mut fwd, target, options, warm)?;
    let sol = match fwd.solution.take() {
        Some(s) if s.tensions() == out.tensions() && s.pressures() == out.pressures() => s,
        _ => fwd.solve(&out.actuation)?,
    };
    Ok((out, sol))
}

/// Follows `targets` (tip positions, m, world; with optional orientations), each inverse
/// warm-started from the last (the first from `warm`); with `throw == false` a target that is
/// not reached is returned with `converged == false` and the path goes on from it.
///
/// # Errors
/// As [`solve_inverse`] (with `throw`, at the first target not reached).
pub fn inverse_statics_path<F: Forward + ?Sized>(
    forward: &mut F,
    targets: &[Target],
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<Vec<InverseSolution>> {
    let mut out: Vec<InverseSolution> = Vec::with_capacity(targets.len());
    let mut w = warm.cloned();
    for t in targets {
        let s = solve_inverse(forward, t, options, w.as_ref())?;
        w = Some(InverseWarmStart::from(&s));
        out.push(s);
    }
    Ok(out)
}

/// The free variables of `y`: strictly inside their bounds.
fn free_set(y: &[f64], bounds: &Bounds) -> Vec<bool> {
    y.iter()
        .enumerate()
        .map(|(i, &v)| v > bounds.lo[i] && v < bounds.hi[i])
        .collect()
}

/// A solved quadratic program of one iteration.
struct QpStep {
    /// The new actuation.
    y: DVector<f64>,
    /// The multipliers of the linearised target (feasible programs).
    lambda: Option<DVector<f64>>,
    /// Whether the target could not be met inside the bounds (the bounded least squares).
    least_squares: bool,
}

/// The program of one iteration at `a`: `min ½ Δᵀ H Δ + (W (a - c))ᵀ Δ` (or `½ |y - c|²_W`
/// when `H = W`, `curved == false`) s.t. `J y = b`, bounds; the bounded least squares if the
/// target cannot be met (or for a shape target).
#[allow(clippy::too_many_arguments)]
fn solve_qp(
    jac: &DMatrix<f64>,
    b: &DVector<f64>,
    a: &[f64],
    bounds: &Bounds,
    hess: &DMatrix<f64>,
    curved: bool,
    tol: f64,
    shape: bool,
) -> QpStep {
    let n = a.len();
    let feasible = if shape {
        None
    } else {
        qp::min_norm(jac, b, bounds, tol)
    };
    match feasible {
        Some((y_w, l_w)) if curved => {
            let av = DVector::from_column_slice(a);
            let wd = DVector::from_fn(n, |i, _| bounds.weights[i] * (a[i] - bounds.centre[i]));
            let q = wd - hess * &av;
            // The multipliers of the program with W (those of the target at a solution).
            let r = qp::active_set_qp(hess, &q, jac, bounds, &y_w);
            let y = r.map_or(y_w, |(y, _)| y);
            QpStep {
                y,
                lambda: Some(l_w),
                least_squares: false,
            }
        }
        Some((y, l)) => QpStep {
            y,
            lambda: Some(l),
            least_squares: false,
        },
        None => QpStep {
            y: qp::bounded_least_squares(jac, b, bounds, ls_regularisation(jac, bounds)),
            lambda: None,
            least_squares: true,
        },
    }
}

/// Relative step of the directional differences of the Jacobian.
const CURVATURE_STEP: f64 = 1e-6;

/// The Hessian of the Lagrangian `½|a - c|²_W - λᵀ p(a)` on the null space `Z` of the free
/// columns of `J`: `H z = W z - (J(a + ε z) - J(a))ᵀ λ / ε` for each column `z` (one
/// evaluation each), as `W + Z (Zᵀ H Z - Zᵀ W Z) Zᵀ` (positive definite on `Z`). Returns the
/// matrix (`None` if an evaluation fails) and the evaluations used.
#[allow(clippy::too_many_arguments)]
fn curvature<F: Forward + ?Sized>(
    forward: &mut F,
    target: &Target,
    a: &[f64],
    jac: &DMatrix<f64>,
    lambda: &DVector<f64>,
    free: &[bool],
    bounds: &Bounds,
    rotation_weight: f64,
) -> (Option<DMatrix<f64>>, usize) {
    let n = a.len();
    let idx: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
    let k = idx.len();
    let m = jac.nrows();
    let w = DMatrix::from_diagonal(&DVector::from_column_slice(&bounds.weights));
    if k <= m {
        return (None, 0);
    }
    // Null space of the free columns, in the scaled variables W^{1/2} a.
    let jf = DMatrix::from_fn(m, k, |r, c| {
        jac[(r, idx[c])] / bounds.weights[idx[c]].sqrt()
    });
    let g = jf.tr_mul(&jf);
    let eig = g.symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0f64, |x, v| x.max(v.abs()));
    let cols: Vec<usize> = (0..k)
        .filter(|&c| eig.eigenvalues[c].abs() <= 1e-10 * top)
        .collect();
    if cols.is_empty() {
        return (None, 0);
    }
    let d = cols.len();
    if std::env::var("SOFTROD_DEBUG_INVERSE").is_ok() {
        eprintln!("curvature: {d} null directions");
    }
    let mut z = DMatrix::zeros(n, d);
    for (j, &c) in cols.iter().enumerate() {
        for (r, &i) in idx.iter().enumerate() {
            z[(i, j)] = eig.eigenvectors[(r, c)] / bounds.weights[i].sqrt();
        }
    }
    let scale = 1.0
        + a.iter()
            .zip(&bounds.weights)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt();
    let mut hz = DMatrix::zeros(n, d);
    let mut used = 0;
    for j in 0..d {
        let zj = z.column(j).into_owned();
        // The scaled length of z_j is 1: a step of CURVATURE_STEP relative to the actuation,
        // toward the inside of the bounds.
        let mut eps = CURVATURE_STEP * scale;
        let inside = |e: f64| {
            (0..n).all(|i| {
                let v = a[i] + e * zj[i];
                v >= bounds.lo[i] && v <= bounds.hi[i]
            })
        };
        if !inside(eps) {
            eps = -eps;
            if !inside(eps) {
                return (None, used);
            }
        }
        let trial: Vec<f64> = (0..n).map(|i| a[i] + eps * zj[i]).collect();
        used += 1;
        let Ok(ev) = forward.evaluate(&trial, true) else {
            return (None, used);
        };
        let Some(j2) = error_rows(target, &ev, rotation_weight).1 else {
            return (None, used);
        };
        let col = &w * &zj - (j2 - jac).tr_mul(lambda) / eps;
        hz.set_column(j, &col);
    }
    let mut mz = z.tr_mul(&hz);
    mz = (&mz + mz.transpose()) * 0.5;
    // Positive definite on Z (a strict local minimum has it; clamp otherwise).
    let e = mz.clone().symmetric_eigen();
    let floor = 1e-3;
    let vals = e.eigenvalues.map(|v| v.max(floor));
    let mz = &e.eigenvectors * DMatrix::from_diagonal(&vals) * e.eigenvectors.transpose();
    let zwz = z.tr_mul(&(&w * &z));
    let h = &w + &z * (mz - zwz) * z.transpose();
    let h = (&h + h.transpose()) * 0.5;
    (Some(h), used)
}

/// Change of the objective `½ Σ w_i (a_i − c_i)²` from `a` to `trial` (same length as `w`).
pub(crate) fn objective_change(w: &[f64], c: &[f64], a: &[f64], trial: &[f64]) -> f64 {
    (0..a.len())
        .map(|i| {
            let d = trial[i] - a[i];
            w[i] * d * (a[i] - c[i] + 0.5 * d)
        })
        .sum()
}

/// The trust radius after an accepted step of size `step_norm`: widened after a full
/// (unclipped) step; otherwise by the ratio of the achieved merit decrease `achieved` to the
/// `predicted` one (×4 above 0.75, halved step below 0.25).
pub(crate) fn trust_radius(
    radius: f64,
    full: bool,
    step_norm: f64,
    achieved: f64,
    predicted: f64,
) -> f64 {
    if full {
        return radius.max(2.0 * step_norm);
    }
    let ratio = if predicted > 0.0 {
        achieved / predicted
    } else {
        1.0
    };
    if ratio > 0.75 {
        4.0 * radius.max(step_norm)
    } else if ratio < 0.25 {
        0.5 * step_norm
    } else {
        radius
    }
}
