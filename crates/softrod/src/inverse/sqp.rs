//! The iteration of the inverse statics (the module documentation of [`super`]): the start
//! (warm or cold), the linearisation of the pose error, the quadratic program of each
//! iteration, the stopping test, and the step search (trust region far from the target, line
//! search on the merit function near it).

use nalgebra::{DMatrix, DVector};

use super::problem::{PoseError, Program};
use super::steps::{
    bfgs_update, curvature, curved_qp, free_set, levenberg_marquardt_step, objective_change,
    probed_curvature, scaled_jacobian_norm, solve_qp, trust_radius, ProbeSite, QpStep,
};
use super::{
    Evaluation, Forward, InverseOptions, InverseSolution, InverseWarmStart, Target, FIRST_RADIUS,
    LOCAL_STEP, PROBE_FROM, STALLED,
};
use crate::error::{Error, Result};

/// The iterate and what the iteration carries from one step to the next.
struct Iterate {
    /// The actuation: tensions (N), then pressures (Pa).
    a: Vec<f64>,
    /// The evaluation at `a`.
    ev: Evaluation,
    /// The Hessian of the Lagrangian: `W`, then `W` corrected on the null space of the free
    /// constraints by directional differences of the exact Jacobian.
    hess: DMatrix<f64>,
    /// The free set `hess` was made for (`None`: `hess = W`).
    curved_for: Option<Vec<bool>>,
    /// The multipliers of the last feasible minimum-norm program (the start of the next
    /// one's dual iteration).
    lambda: Option<DVector<f64>>,
    /// The penalty `ν` of the pose error in the merit function `½|a - c|²_W + ν |e|` near
    /// the target.
    nu: f64,
    /// The scaled length of the last step taken near the target (0: none).
    last_step: f64,
    /// The trust radius (scaled actuation norm): NaN until the first Jacobian is known.
    radius: f64,
    /// SQP steps taken.
    iterations: usize,
    /// Forward evaluations.
    evaluations: usize,
    /// Probes (poses without the Jacobian).
    probes: usize,
    /// Whether the forward model has probes ([`Forward::probe`]).
    probes_available: bool,
    /// How many times actuators were put on their bounds at the end.
    snapped: usize,
    /// The pose error of `ev`, if made already (the evaluation accepted last).
    err: Option<PoseError>,
}

impl Iterate {
    /// The result at the iterate, linearised as `lin`.
    fn finish(self, p: &Program<'_>, lin: &Linear, converged: bool) -> InverseSolution {
        InverseSolution {
            actuation: self.a,
            n_tendons: p.nt,
            position_error: lin.dist,
            rotation_error: lin.rot,
            iterations: self.iterations,
            evaluations: self.evaluations,
            probes: self.probes,
            converged,
            reached: lin.reached,
            evaluation: self.ev,
            hessian: self.hess,
            start: 0,
            steps: None,
        }
    }
}

/// The pose error at the iterate and its linearisation.
struct Linear {
    /// Scaled error rows.
    e: DVector<f64>,
    /// Their Jacobian in the actuation.
    jac: DMatrix<f64>,
    /// The right-hand side `b = e + J a` of the linearised target `J y = b`.
    b: DVector<f64>,
    /// Largest distance from a target position (m).
    dist: f64,
    /// Rotation to the target orientation (rad).
    rot: f64,
    /// `|e|`.
    merit: f64,
    /// Whether the target is reached within the tolerances.
    reached: bool,
}

/// The inverse statics of any [`Forward`] model (see the module documentation).
///
/// # Errors
/// [`Error::InvalidParameter`] naming a bad option or target; [`Error::TargetUnreachable`]
/// for a target out of reach and [`Error::NotConverged`] otherwise when `throw` is set; the
/// forward model's errors at the first evaluation.
pub fn solve_inverse<F: Forward + ?Sized>(
    forward: &mut F,
    target: &Target,
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<InverseSolution> {
    let p = Program::new(forward, target, options)?;
    let n = p.n();
    let mut it = start(forward, &p, warm)?;
    loop {
        let lin = linearise(&p, &mut it)?;
        let solved = program_step(forward, &p, &mut it, &lin);
        let least_squares = solved.least_squares;
        let lambda_k = solved.lambda;
        let mut y = solved.y;
        let norm_a = p.scaled_norm(&it.a);
        let tol_step = options.optimality_tolerance * (1.0 + norm_a);
        let mut step: Vec<f64> = (0..n).map(|i| y[i] - it.a[i]).collect();
        let small = p.scaled_norm(&step) <= tol_step;
        if small && lin.reached && it.snapped < 3 {
            // An actuator left within the step tolerance of its bound (a degenerate optimum:
            // on the bound and on the target at once) is put on it; the next evaluation
            // checks the target there (a few times at most).
            let mut snap = false;
            for i in 0..n {
                let reach = tol_step / p.bounds.weights[i].sqrt();
                for bound in [p.bounds.lo[i], p.bounds.hi[i]] {
                    if y[i] != bound && (y[i] - bound).abs() <= reach {
                        y[i] = bound;
                        step[i] = bound - it.a[i];
                        snap = true;
                    }
                }
            }
            it.snapped += usize::from(snap);
        }
        // A small step that still moves an actuator onto its bound (or off it) is taken: the
        // minimum-norm actuation has it exactly there, not a round-off away.
        let bx = &p.bounds;
        let inside = |v: f64, i: usize| v > bx.lo[i] && v < bx.hi[i];
        let same_bounds = (0..n).all(|i| inside(y[i], i) == inside(it.a[i], i));
        let stationary = small && (lin.reached || least_squares) && same_bounds;
        if stationary || it.iterations >= options.max_iterations {
            return stopped(&p, it, &lin, stationary, least_squares);
        }
        if it.radius.is_nan() {
            // A first step that moves the linearised pose by at most a quarter of the rod
            // length (the linearisation of a straight rod asks for huge tensions to shorten it).
            let sigma = scaled_jacobian_norm(&lin.jac, &p.bounds.weights);
            it.radius = if sigma > 0.0 {
                (FIRST_RADIUS * p.length / sigma).max(norm_a)
            } else {
                f64::INFINITY
            };
        }
        let accepted = search(forward, &p, &mut it, &lin, step, norm_a);
        it.iterations += 1;
        let Some((trial, t)) = accepted else {
            // No decrease in any direction: the closest pose (a local minimum of the error).
            return stuck(&p, it, &lin);
        };
        // The curvature met along the step refines the Hessian (far from the target too: a
        // warm start's first step is the longest secant it gets).
        let err = p.error(&t);
        if it.curved_for.is_some() {
            if let (Some(lambda), Some(jn)) = (&lambda_k, &err.jac) {
                let w = &p.bounds.weights;
                bfgs_update(&mut it.hess, w, &it.a, &trial, &lin.jac, jn, lambda);
            }
        }
        it.a = trial;
        it.ev = t;
        it.err = Some(err);
    }
}

/// An error of the first evaluation at `a` (clamped from `given`) that names a tension
/// (`tensions[i]`: the robot cannot be solved there), renamed after the input that put the
/// actuator there: the bounds that moved it, else the warm start or the reference it was
/// taken from.
fn at_start(e: Error, (given, a): (&[f64], &[f64]), warm: bool) -> Error {
    let Some((name, value, expected)) = e.parameter() else {
        return e;
    };
    let index = name
        .strip_prefix("tensions[")
        .and_then(|r| r.strip_suffix(']'))
        .and_then(|k| k.parse::<usize>().ok())
        .filter(|&i| i < a.len());
    let Some(i) = index else {
        return e;
    };
    let source = match (a[i] != given[i], warm) {
        (true, _) => "tension_bounds",
        (false, true) => "warm_start",
        (false, false) => "reference",
    };
    Error::invalid(source, format!("{name} = {value} at the start"), expected)
}

/// The first iterate: the warm start's actuation (its evaluation and Hessian if they fit) or
/// the reference, clamped into the bounds.
fn start<F: Forward + ?Sized>(
    forward: &mut F,
    p: &Program<'_>,
    warm: Option<&InverseWarmStart>,
) -> Result<Iterate> {
    let n = p.n();
    if let Some(w) = warm {
        if w.actuation.len() != n || w.actuation.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "warm_start",
                format!("{:?}", w.actuation),
                format!("{n} finite actuation values (tensions, then pressures)"),
            ));
        }
    }
    let mut a: Vec<f64> = match warm {
        Some(w) => w.actuation.clone(),
        None => p.bounds.centre.clone(),
    };
    let given = a.clone();
    p.clamp(&mut a);
    let mut evaluations = 0;
    let reuse = warm.and_then(|w| {
        (w.actuation == a)
            .then(|| w.evaluation.clone())
            .flatten()
            .filter(|e| e.jacobian.is_some() && e.positions.len() == p.target.points.len())
    });
    let ev = match reuse {
        Some(e) => e,
        None => {
            evaluations += 1;
            forward
                .evaluate(&a, true)
                .map_err(|e| at_start(e, (&given, &a), warm.is_some()))?
        }
    };
    let probes_available = forward.has_probes();
    let mut hess = DMatrix::from_diagonal(&DVector::from_column_slice(&p.bounds.weights));
    let mut curved_for: Option<Vec<bool>> = None;
    if let Some(h) = warm.and_then(|w| w.hessian.as_ref()) {
        if h.shape() == (n, n) && h.iter().all(|v| v.is_finite()) && *h != hess {
            hess.copy_from(h);
            curved_for = Some(free_set(&a, &p.bounds));
        }
    }
    Ok(Iterate {
        a,
        ev,
        hess,
        curved_for,
        lambda: None,
        nu: 0.0,
        last_step: 0.0,
        radius: f64::NAN,
        iterations: 0,
        evaluations,
        probes: 0,
        probes_available,
        snapped: 0,
        err: None,
    })
}

/// The pose error at the iterate and its linearisation.
///
/// # Errors
/// [`Error::NotConverged`] if the evaluation has no Jacobian.
fn linearise(p: &Program<'_>, it: &mut Iterate) -> Result<Linear> {
    let PoseError { e, jac, dist, rot } = it.err.take().unwrap_or_else(|| p.error(&it.ev));
    let reached = dist <= p.options.tolerance && rot <= p.options.rotation_tolerance;
    let Some(jac) = jac else {
        return Err(Error::NotConverged {
            what: "inverse statics: no Jacobian".into(),
            iterations: it.iterations,
            residual: dist,
            load_factor: 1.0,
        });
    };
    let av = DVector::from_column_slice(&it.a);
    let b = &e + &jac * &av;
    let merit = e.norm();
    Ok(Linear {
        e,
        jac,
        b,
        dist,
        rot,
        merit,
        reached,
    })
}

/// The quadratic program of one iteration in `y = a + Δ` (`min ½ |y - c|²_W`, `J y = b`,
/// bounds); near the target with the curvature, probed at every near step (a model with
/// probes) or made again where it is stale (a warm start's, or another point's: the free set
/// changed or the steps stopped contracting).
/// Sets the merit penalty from the multipliers.
fn program_step<F: Forward + ?Sized>(
    forward: &mut F,
    p: &Program<'_>,
    it: &mut Iterate,
    lin: &Linear,
) -> QpStep {
    let n = p.n();
    let jb = (&lin.jac, &lin.b);
    // A model with cheap probes has its curvature probed at every near step (below): the
    // program with the last curvature is solved only where it is not.
    let probing = it.probes_available && p.target.rotation.is_none() && !p.shape;
    let probe_here = probing && lin.merit <= p.near;
    let curved = it.curved_for.is_some() && !probe_here;
    let mut solved = solve_qp(p, jb, &it.a, &it.hess, curved, it.lambda.as_ref());
    if !solved.least_squares && lin.merit <= p.near {
        let tol_step = p.options.optimality_tolerance * (1.0 + p.scaled_norm(&it.a));
        let mut probed = false;
        if probe_here {
            probed = probe(forward, p, it, lin, &mut solved, tol_step);
            if !probed && it.curved_for.is_some() {
                if let (Some(yw), Some(l)) = (solved.y_min_norm.take(), solved.lambda.take()) {
                    solved = curved_qp(p, &lin.jac, &it.a, &it.hess, (yw, l));
                }
            }
        }
        let free = free_set(solved.y.as_slice(), &p.bounds);
        let d: Vec<f64> = (0..n).map(|i| solved.y[i] - it.a[i]).collect();
        let stalled = it.last_step > 0.0 && p.scaled_norm(&d) > STALLED * it.last_step;
        // Where the curvature is stale (the free set changed, the steps stopped contracting)
        // and it was not probed, it is made from directional differences of the Jacobian.
        if !probed && (stalled || it.curved_for.as_ref() != Some(&free)) {
            if let Some(lambda) = &solved.lambda {
                let (h, used) = curvature(forward, p, &it.a, &lin.jac, lambda, &free);
                it.evaluations += used;
                if let Some(h) = h {
                    it.hess = h;
                    it.curved_for = Some(free);
                    let start = solved.lambda.clone();
                    solved = solve_qp(p, jb, &it.a, &it.hess, true, start.as_ref());
                }
            }
        }
    }
    if let Some(l) = &solved.lambda {
        it.nu = 1.5 * l.norm();
        it.lambda = Some(l.clone());
    }
    solved
}

/// The curvature probed at the iterate (range step and null space: the next step is
/// Newton's on the KKT conditions) unless the minimum-norm step is within [`PROBE_FROM`] of the
/// stopping test, and the program solved with it into `solved`; whether it was.
fn probe<F: Forward + ?Sized>(
    forward: &mut F,
    p: &Program<'_>,
    it: &mut Iterate,
    lin: &Linear,
    solved: &mut QpStep,
    tol_step: f64,
) -> bool {
    let n = p.n();
    let (Some(lambda), Some(yw)) = (&solved.lambda, &solved.y_min_norm) else {
        return false;
    };
    // The range step: that of the program with W (its part off the null space).
    let v: Vec<f64> = (0..n).map(|i| yw[i] - it.a[i]).collect();
    if p.scaled_norm(&v) <= PROBE_FROM * tol_step {
        return false;
    }
    let free_w = free_set(yw.as_slice(), &p.bounds);
    let w_diag;
    let base = if it.curved_for.is_some() {
        &it.hess
    } else {
        w_diag = DMatrix::from_diagonal(&DVector::from_column_slice(&p.bounds.weights));
        &w_diag
    };
    let at = ProbeSite {
        a: &it.a,
        e0: &lin.e,
        jac: &lin.jac,
        lambda,
    };
    let (h, used) = probed_curvature(forward, p, &at, &free_w, &v, base);
    it.probes += used;
    let Some(h) = h else {
        return false;
    };
    it.hess = h;
    it.curved_for = Some(free_w);
    // The minimum-norm program is the one solved already.
    let (Some(yw), Some(l)) = (solved.y_min_norm.take(), solved.lambda.take()) else {
        return false;
    };
    *solved = curved_qp(p, &lin.jac, &it.a, &it.hess, (yw, l));
    true
}

/// The result of an iteration stopped at a stationary point or at the iteration cap.
///
/// # Errors
/// With `throw`, [`Error::TargetUnreachable`] or [`Error::NotConverged`] if not converged.
fn stopped(
    p: &Program<'_>,
    it: Iterate,
    lin: &Linear,
    stationary: bool,
    least_squares: bool,
) -> Result<InverseSolution> {
    let converged = stationary && (lin.reached || p.shape);
    let out = it.finish(p, lin, converged);
    if !converged && p.options.throw {
        if stationary || (least_squares && !lin.reached) {
            return Err(unreachable(p, lin, out.iterations));
        }
        return Err(Error::NotConverged {
            what: "inverse statics (SQP)".into(),
            iterations: out.iterations,
            residual: lin.dist.max(lin.rot * p.rotation_weight),
            load_factor: 1.0,
        });
    }
    Ok(out)
}

/// The result when no step decreases the merit: the closest pose (a local minimum of the
/// error).
///
/// # Errors
/// With `throw`, [`Error::TargetUnreachable`] unless a shape target was fitted.
fn stuck(p: &Program<'_>, it: Iterate, lin: &Linear) -> Result<InverseSolution> {
    let converged = p.shape && !lin.reached;
    let out = it.finish(p, lin, converged);
    if p.options.throw && !out.converged {
        return Err(unreachable(p, lin, out.iterations));
    }
    Ok(out)
}

/// Precision of the forward solves' poses, as a fraction of the rod length (and in rad): a
/// tolerance below it asks for digits the forward solves do not resolve.
const RESOLVED_FRACTION: f64 = 1e-11;

/// Closest distance, as a fraction of the rod length (and in rad), within which an iteration
/// that asked for a tolerance below [`RESOLVED_FRACTION`] is taken to have got as close as
/// the forward solves allow.
const NEAR_FRACTION: f64 = 1e-8;

/// [`Error::TargetUnreachable`] for the closest pose of `lin`, unless a tolerance asked for
/// less than the forward solves resolve and the pose is that close: then the tolerance is
/// named ([`Error::InvalidParameter`]; `tolerance = 1e-30` m was reported out of reach at
/// 8.5e-12 m).
fn unreachable(p: &Program<'_>, lin: &Linear, iterations: usize) -> Error {
    let o = &p.options;
    let near = lin.dist <= NEAR_FRACTION * p.length && lin.rot <= NEAR_FRACTION;
    let below = [
        ("tolerance", o.tolerance, RESOLVED_FRACTION * p.length, "m"),
        (
            "rotation_tolerance",
            o.rotation_tolerance,
            RESOLVED_FRACTION,
            "rad",
        ),
    ]
    .into_iter()
    .find(|(_, value, floor, _)| value < floor);
    if let (true, Some((name, value, floor, unit))) = (near, below) {
        return Error::invalid(
            name,
            value,
            format!(
                "at least about {floor:.1e} {unit} here (the forward solves' precision): the \
                 iteration stops {:.3e} m and {:.3e} rad from the target",
                lin.dist, lin.rot
            ),
        );
    }
    Error::TargetUnreachable {
        distance: lin.dist,
        rotation: lin.rot,
        iterations,
    }
}

/// The step from the iterate: the SQP step `step` if inside the trust region, else the
/// bounded Levenberg–Marquardt step on the pose error of that length, a rejected step
/// shrinking the region; near the target, the SQP step with a backtracking line search on
/// the merit function. Returns the accepted actuation and its evaluation (`None`: no
/// decrease in any direction); updates the trust radius and the last near step.
fn search<F: Forward + ?Sized>(
    forward: &mut F,
    p: &Program<'_>,
    it: &mut Iterate,
    lin: &Linear,
    mut step: Vec<f64>,
    norm_a: f64,
) -> Option<(Vec<f64>, Evaluation)> {
    let n = p.n();
    let (bounds, e, jac, merit) = (&p.bounds, &lin.e, &lin.jac, lin.merit);
    let near_phase = merit <= p.near;
    let slope = {
        let d = DVector::from_column_slice(&step);
        let grad: f64 = (0..n)
            .map(|i| bounds.weights[i] * (it.a[i] - bounds.centre[i]) * step[i])
            .sum();
        grad + it.nu * ((e - jac * d).norm() - merit)
    };
    let mut alpha = 1.0;
    while it.radius > 1e-14 * (1.0 + norm_a) && alpha > 1e-10 {
        let full = near_phase || p.scaled_norm(&step) <= it.radius;
        if !full {
            step = levenberg_marquardt_step(jac, e, &it.a, bounds, it.radius);
        }
        let step_norm = p.scaled_norm(&step) * alpha;
        if step_norm <= 1e-15 * (1.0 + norm_a) {
            break;
        }
        let mut trial: Vec<f64> = (0..n).map(|i| it.a[i] + alpha * step[i]).collect();
        p.clamp(&mut trial);
        it.evaluations += 1;
        let predicted = {
            let d = DVector::from_column_slice(&step);
            merit - (e - jac * d).norm()
        };
        if let Ok(t) = forward.evaluate(&trial, true) {
            let mt = p.error_norm(&t);
            let ok = if near_phase {
                // The change of the merit, summed without cancellation.
                let df = objective_change(&bounds.weights, &bounds.centre, &it.a[..n], &trial[..n]);
                let dphi = df + it.nu * (mt - merit);
                let local = step_norm <= LOCAL_STEP * (1.0 + norm_a);
                (local && mt <= p.near) || dphi <= 1e-4 * alpha * slope.min(0.0)
            } else {
                mt <= (1.0 - 1e-4) * merit || (full && mt <= p.near)
            };
            if mt.is_finite() && ok {
                it.radius = trust_radius(it.radius, full, step_norm, merit - mt, predicted);
                it.last_step = if near_phase { step_norm } else { 0.0 };
                return Some((trial, t));
            }
        }
        if near_phase {
            alpha *= 0.5;
        } else {
            it.radius = 0.25 * step_norm.min(it.radius);
        }
    }
    None
}

/// Follows `targets` (tip positions, m, world; with optional orientations), each inverse
/// warm-started from the last (the first from `warm`, and from each start of
/// `options.starts`, each on the forward model as new: [`Forward::forget`]); with
/// `throw == false` a target that is not reached is returned with `converged == false` and
/// the path goes on from it.
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
    if let Some(first) = targets.first() {
        let later = super::starts_on(forward, first, options)?;
        let several = later.is_some();
        let (s, ()) = super::over_starts(options, warm, later, |o, w| {
            if several {
                forward.forget();
            }
            solve_inverse(forward, first, o, w).map(|s| (s, ()))
        })?;
        w = Some(InverseWarmStart::from(&s));
        out.push(s);
    }
    for t in targets.iter().skip(1) {
        let s = solve_inverse(forward, t, options, w.as_ref())?;
        w = Some(InverseWarmStart::from(&s));
        out.push(s);
    }
    Ok(out)
}
