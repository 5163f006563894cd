//! Steady-state shape of a Cosserat rod with tendons, chambers and external loads, by shooting.
//!
//! [`solve_statics`] finds the total base wrench `(N(0), M(0))` (world frame) that meets the
//! tip conditions (`cosserat::shooting`). The actuation is always applied in full: with the
//! total-wrench form a tendon or a chamber adds nothing to the base wrench, so the actuated,
//! unloaded rod is solved exactly by a zero base wrench in one pass. The external loads are
//! then applied along the load factor `λ` from 0 to 1: first directly, from the exact tangent
//! predictor `dx/dλ = -J⁻¹ ∂r/∂λ` at the unloaded rod, with Broyden updates of the Jacobian
//! between exact evaluations; if that fails, or the predictor step is larger than
//! [`DIRECT_STEP_LIMIT`] (a strongly nonlinear problem, where Newton may land on another
//! equilibrium branch), by continuation in `λ`, refusing load steps that change the shape by
//! more than [`MAX_LOAD_STEP_TURN`], so that the solution found is the one connected to the
//! unloaded, actuated rod. The ODE is integrated between the breaks at tendon terminations,
//! chamber ends and point loads with fixed-step RK4 (the paper's method) or the adaptive
//! Dormand–Prince 5(4) pair; rotation matrices are re-orthonormalised after every step.

use std::sync::Arc;

use nalgebra::{Matrix6, Vector3};

use super::equations::{Equations, FULL};
use super::shooting::Shooting;
use super::stability::{certifies, tip_stability, Stability};
use crate::error::{Error, Result};
use crate::integrate::march::rk4_plan;
use crate::model::loads::{Frame, PointLoad};
use crate::model::{Actuation, RobotModel};
use crate::solve::{
    continuation, max_norm, newton, Armijo, ContinuationSettings, Evaluated, LineSearch,
    NewtonOptions, NewtonOutcome, NewtonSettings, Problem, SolverStats, Stopped,
};

pub use super::options::{
    CoarseDefect, Integrator, SolveOptions, WarmStart, COARSE_RATIO, COARSE_TOLERANCE,
    DEFAULT_MAX_ITERATIONS, DEFAULT_MAX_LOAD_STEPS, DEFAULT_RK4_STEPS, DEFAULT_TOLERANCE,
    DIRECT_STEP_LIMIT, MAX_LINE_SEARCH_HALVINGS, MAX_LOAD_STEP_TURN, MAX_RK4_STEPS,
    MIN_COARSE_STEPS,
};
pub use super::solution::StaticsSolution;
pub(crate) use super::solution::{assemble, scaled_back};

/// The stability of a solution from one march with the base-wrench columns by `integrator`
/// (e.g. a coarser mesh than it was solved on).
pub(crate) fn stability_on(sol: &StaticsSolution, integrator: Integrator) -> Option<Stability> {
    let model = &*sol.model;
    let pressures = sol.pressures();
    let eq = sol.equations(&pressures, 1.0);
    let plan = match integrator {
        Integrator::Rk4 { steps } => rk4_plan(model.breaks(), steps),
        Integrator::Adaptive(_) => Vec::new(),
    };
    let mut p = Shooting::new(eq, integrator, plan);
    p.stops = interior(&sol.s_out, model.length());
    let x = scaled(model, &sol.base_wrench);
    stability_at(&mut p, &x, None, false).map(|(s, _)| s)
}

/// The points of `s_out` strictly inside `(0, length)`.
pub(crate) fn interior(s_out: &[f64], length: f64) -> Vec<f64> {
    s_out
        .iter()
        .copied()
        .filter(|&s| s > 0.0 && s < length)
        .collect()
}

/// Newton settings of the shooting. Broyden's update of the Jacobian is used with the fixed
/// RK4 mesh (the residual is then a smooth function of the unknowns); with the adaptive
/// integrator the residual carries the integration error and exact Jacobians are evaluated.
/// A loaded solve ends on an exact Jacobian at the solution (the stability test needs its
/// columns).
pub(crate) fn settings(broyden: bool, jacobian: Option<&[f64]>, exact: bool) -> NewtonSettings<'_> {
    NewtonSettings {
        line_search: LineSearch {
            factor: 0.5,
            max_halvings: MAX_LINE_SEARCH_HALVINGS,
        },
        condition: Armijo::default(),
        first_step_limit: None,
        residual_first: false,
        broyden,
        jacobian,
        exact_at_solution: exact,
    }
}

/// What a solve reached: the Newton outcome (on failure, the last accepted state with its
/// residual at `load_factor`), its load factor and effort, and why a continuation stopped.
struct Reached {
    outcome: NewtonOutcome,
    load_factor: f64,
    iterations: usize,
    load_steps: usize,
    stopped: Option<Stopped>,
    /// The coarse mesh's residual at the solution, when it was reached from a coarse mesh.
    coarse_defect: Option<CoarseDefect>,
}

impl Reached {
    fn direct(outcome: NewtonOutcome) -> Self {
        Self {
            load_factor: 1.0,
            iterations: outcome.iterations,
            load_steps: 0,
            stopped: None,
            coarse_defect: None,
            outcome,
        }
    }
}

/// The direct solve at full load: from the warm start, or from the tangent predictor at the
/// unloaded rod. Returns the outcome and, for a cold start, the unloaded Jacobian and the
/// size of a predictor step refused by the step limit. A cold solution that moved the shape
/// by more than [`MAX_LOAD_STEP_TURN`] from the unloaded rod (the safeguard of one load step
/// of size 1) is refused, so that continuation follows the branch instead.
fn direct(
    p: &mut Shooting<'_>,
    options: &SolveOptions,
    x0: &[f64; 6],
    exact: bool,
) -> (NewtonOutcome, Option<Vec<f64>>, f64) {
    let opts = &options.newton;
    let limit = opts.continuation.then_some(DIRECT_STEP_LIMIT);
    let broyden = matches!(options.integrator, Integrator::Rk4 { .. });
    let settings = |j| settings(broyden, j, exact);
    if let Some(w) = &options.warm_start {
        let j = w.jacobian.map(|m| m.as_slice().to_vec());
        let s = NewtonSettings {
            first_step_limit: limit,
            residual_first: true,
            ..settings(j.as_deref())
        };
        return (newton(p, x0, 1.0, opts, &s), None, 0.0);
    }
    if p.eq.model.loads().is_unloaded() {
        // Nothing to apply: x = 0 solves the actuated rod exactly.
        let s = NewtonSettings {
            residual_first: true,
            ..settings(None)
        };
        return (newton(p, x0, 1.0, opts, &s), None, 0.0);
    }
    // The unloaded, actuated rod: x = 0 is exact at λ = 0, its Jacobian is closed form.
    let mut r = [0.0; 6];
    let mut j0 = vec![0.0; 36];
    if p.evaluate(x0, 0.0, Some(&mut j0), &mut r) != Evaluated::Jacobian {
        return (refused(x0, f64::INFINITY, 0.0), None, 0.0);
    }
    p.commit();
    let mut drdl = [0.0; 6];
    let mut guess = *x0;
    if p.load_derivative(x0, 0.0, &mut drdl) {
        let mut lu = crate::math::linalg::DenseLu::default();
        let mut t = drdl.map(|v| -v);
        if lu.factor(6, &j0) && lu.solve_in_place(&mut t) {
            let step = max_norm(&t);
            if limit.is_some_and(|l| step > l) {
                return (refused(x0, f64::INFINITY, step), Some(j0), step);
            }
            for k in 0..6 {
                guess[k] += t[k];
            }
        }
    }
    // The unloaded Jacobian is a poor one at full load: Newton evaluates its own at the
    // predicted point.
    let s = NewtonSettings {
        first_step_limit: if guess == *x0 { limit } else { None },
        ..settings(None)
    };
    let mut out = newton(p, &guess, 1.0, opts, &s);
    if !out.converged && !out.residual.is_finite() && guess != *x0 {
        // The predictor left the domain of the equations: Newton from the unloaded rod.
        let s = NewtonSettings {
            first_step_limit: limit,
            ..settings(Some(&j0))
        };
        out = newton(p, x0, 1.0, opts, &s);
    }
    if out.converged && opts.continuation && !(out.at_x && p.close()) {
        // Too far from the unloaded rod for one step: maybe another branch.
        return (refused(x0, out.residual, 0.0), Some(j0), 0.0);
    }
    let first = out.first_step;
    (out, Some(j0), first)
}

/// A refused direct solve (continuation takes over).
fn refused(x0: &[f64; 6], residual: f64, first_step: f64) -> NewtonOutcome {
    NewtonOutcome {
        x: x0.to_vec(),
        residual,
        converged: false,
        iterations: 0,
        first_step,
        jacobian: None,
        at_x: false,
        exact: false,
    }
}

/// Steps the external loads from the unloaded rod (x = 0 is exact at λ = 0) by continuation,
/// from the refused predictor step `first_step` (0: none), with load increments of at most
/// `max_increment`.
fn step_loads(
    p: &mut Shooting<'_>,
    options: &SolveOptions,
    j0: Option<Vec<f64>>,
    first_step: f64,
    max_increment: f64,
    exact: bool,
) -> Reached {
    let zero = [0.0; 6];
    let j0 = match j0 {
        Some(j) => Some(j),
        None => {
            let mut j = vec![0.0; 36];
            let mut r = [0.0; 6];
            (p.evaluate(&zero, 0.0, Some(&mut j), &mut r) == Evaluated::Jacobian).then_some(j)
        }
    };
    let first = if first_step > 0.0 {
        (0.8 * DIRECT_STEP_LIMIT / first_step).clamp(crate::solve::MIN_LOAD_INCREMENT, 0.5)
    } else {
        0.25
    }
    .min(max_increment);
    let start = ContinuationSettings {
        x0: &zero,
        jacobian0: j0.as_deref(),
        first_increment: first,
        max_increment,
    };
    let s = NewtonSettings {
        first_step_limit: Some(DIRECT_STEP_LIMIT),
        ..settings(
            matches!(options.integrator, Integrator::Rk4 { .. }),
            None,
            exact,
        )
    };
    let c = continuation(p, &start, &options.newton, &s);
    Reached {
        outcome: c.outcome,
        load_factor: c.load_factor,
        iterations: c.iterations,
        load_steps: c.steps,
        stopped: Some(c.stopped),
        coarse_defect: None,
    }
}

/// The direct solve, then continuation if it fails or is refused.
fn attempt(p: &mut Shooting<'_>, options: &SolveOptions, x0: &[f64; 6], exact: bool) -> Reached {
    attempt_exact(p, options, x0, (exact, exact))
}

/// [`attempt`], the direct solve and the continuation ending on an exact Jacobian as asked.
fn attempt_exact(
    p: &mut Shooting<'_>,
    options: &SolveOptions,
    x0: &[f64; 6],
    (exact_direct, exact): (bool, bool),
) -> Reached {
    let (result, j0, first_step) = direct(p, options, x0, exact_direct);
    if result.converged || !options.newton.continuation {
        return Reached::direct(result);
    }
    let iterations = result.iterations;
    let mut c = step_loads(p, options, j0, first_step, 0.5, exact);
    c.iterations += iterations;
    c
}

/// Largest change of the scaled unknowns (max norm) that Newton on the mesh asked may make from
/// the coarse solution of [`coarse_first`]: the two meshes' solutions differ by the
/// integration error (about 1e-5 and below); a larger move is another equilibrium.
const COARSE_TO_FINE_STEP: f64 = 1e-2;

/// Newton tolerance on the coarse mesh when its residual is corrected by the defect of a warm
/// start ([`CoarseDefect`]): the corrected coarse solution is then within the change of the
/// defect (about 1e-7 for a 2 % change of the actuation) of the solution on the mesh asked,
/// so the coarse iterations are worth converging further than [`COARSE_TOLERANCE`].
const CORRECTED_COARSE_TOLERANCE: f64 = 1e-7;

/// A cold loaded solve with its nonlinear iterations on the coarse mesh
/// ([`Integrator::coarse`]): [`attempt`] there (the tangent predictor, Newton, load steps if
/// needed) to [`COARSE_TOLERANCE`], one march with the columns at the coarse solution, then
/// Newton on the mesh asked from the coarse solution with that Jacobian. A coarse march costs a
/// fifth of one on the mesh asked and its Jacobian differs from that mesh's by the
/// integration error, so Newton there contracts the residual by about 1e-5 a step. Returns
/// `None` (the caller solves on the mesh asked from the start) where there is no coarse mesh,
/// for a warm start, held tendons or a continuation that must refuse unstable states, and when
/// either mesh fails or the mesh asked moves more than [`COARSE_TO_FINE_STEP`] from the coarse
/// solution. With the reached state comes the stability when the coarse columns certify it
/// ([`clearly_stable`]; its margin is then computed on the mesh asked when read).
fn coarse_first(
    p: &mut Shooting<'_>,
    options: &SolveOptions,
    x0: &[f64; 6],
) -> Option<(Reached, Option<Stability>)> {
    if !p.held.is_empty() || p.require_stable {
        return None;
    }
    let mut c = p.coarse()?;
    let Integrator::Rk4 { steps } = c.integrator else {
        return None;
    };
    // (No tendon is held here: the tension-free tendons' lengths are not needed.)
    c.passive_lengths = false;
    let defect = options
        .warm_start
        .and_then(|w| w.coarse_defect)
        .filter(|d| d.steps == steps && d.residual.iter().all(|v| v.is_finite()));
    let floor = match defect {
        Some(d) => {
            c.defect = d.residual;
            CORRECTED_COARSE_TOLERANCE
        }
        None => COARSE_TOLERANCE,
    };
    let start = SolveOptions {
        newton: NewtonOptions {
            tolerance: options.newton.tolerance.max(floor),
            throw: false,
            ..options.newton
        },
        ..*options
    };
    // The direct solve ends on the columns at the coarse solution (needed below): a step
    // predicted to converge is taken with them, saving the march that would evaluate them
    // after it; continuation's load steps do not (their columns would be wasted).
    c.certify = false;
    // Cold, the first columns are those of Newton's direction at the predicted point, which
    // judge no stability (the solution's columns do): marched without the Jacobi check.
    if options.warm_start.is_none() {
        c.skip_jacobi = 1;
    }
    let reached = attempt_exact(&mut c, &start, x0, (true, false));
    let xc = reached.outcome.x.clone();
    let o = &reached.outcome;
    let (mut j, mut r) = (vec![0.0; 36], [0.0; 6]);
    // The columns at the coarse solution: those of its last pass when it ended on them.
    let jacobian = match (&o.jacobian, &c.columns) {
        (Some(oj), Some(cj))
            if o.converged
                && o.exact
                && o.at_x
                && c.jacobi_checked
                && c.tip_twist.is_some()
                && oj[..] == cj[..] =>
        {
            j.copy_from_slice(oj);
            r = c.residual;
            true
        }
        _ => {
            // (Checked along the rod whatever pass came before: these columns judge.)
            c.skip_jacobi = 0;
            o.converged && c.evaluate(&xc, 1.0, Some(&mut j), &mut r) == Evaluated::Jacobian
        }
    };
    p.evaluations += c.evaluations;
    if !jacobian {
        return None;
    }
    let clear = clearly_stable(&c, &j, COARSE_TO_FINE_STEP);
    let s = NewtonSettings {
        residual_first: true,
        ..settings(true, Some(&j), clear.is_none())
    };
    let out = newton(p, &xc, 1.0, &options.newton, &s);
    let moved = (0..6).map(|k| (out.x[k] - xc[k]).abs()).fold(0.0, f64::max);
    if !out.converged || moved > COARSE_TO_FINE_STEP {
        return None;
    }
    // The coarse residual at the solution, to first order from the coarse solution: the
    // defect a warm start from this solution corrects its coarse iterations by.
    let residual = std::array::from_fn(|i| {
        r[i] + c.defect[i]
            + (0..6)
                .map(|k| j[i + 6 * k] * (out.x[k] - xc[k]))
                .sum::<f64>()
    });
    let fine = Reached {
        iterations: reached.iterations + out.iterations,
        load_steps: reached.load_steps,
        coarse_defect: Some(CoarseDefect { steps, residual }),
        ..Reached::direct(out)
    };
    Some((fine, clear))
}

/// Stable, as the columns of the last pass of `c` (on a coarse mesh; `j` its Jacobian) certify
/// for a solution at most `distance` away on the mesh asked ([`certifies`]: the same floor
/// and rate as the certificate of the predicted point, far above the coarse mesh's error in
/// the margin); the margin itself is left to be computed on the mesh asked when read (NaN
/// here).
fn clearly_stable(c: &Shooting<'_>, j: &[f64], distance: f64) -> Option<Stability> {
    c.tip_twist
        .filter(|_| c.jacobi_checked)
        .and_then(|tw| tip_stability(j, &tw, c.eq.model.length(), c.jacobi))
        .filter(|s| certifies(s, distance))
        .map(|_| Stability {
            stable: true,
            margin: f64::NAN,
            mode: None,
        })
}

/// The stability of the converged unknowns `x` of `p` when one march with the columns on
/// the coarse mesh certifies it ([`clearly_stable`]); `None` otherwise (and without a coarse
/// mesh), when the columns are marched on the mesh asked.
fn stable_on_coarse(p: &mut Shooting<'_>, x: &[f64]) -> Option<Stability> {
    let mut c = p.coarse()?;
    c.passive_lengths = false;
    let (mut j, mut r) = ([0.0; 36], [0.0; 6]);
    let marched = c.evaluate(x, 1.0, Some(&mut j), &mut r) == Evaluated::Jacobian;
    p.evaluations += c.evaluations;
    clearly_stable(&c, &j, 0.0).filter(|_| marched)
}

/// The dimensionless unknowns of a base wrench `[f; m]` (N, N m): the force over the model's
/// force scale `F`, the moment over `F L`.
pub(crate) fn scaled(model: &RobotModel, b: &[f64; 6]) -> [f64; 6] {
    let f = model.force_scale();
    let fm = f * model.length();
    [
        b[0] / f,
        b[1] / f,
        b[2] / f,
        b[3] / fm,
        b[4] / fm,
        b[5] / fm,
    ]
}

/// The stability of the converged state `x` of `p`, with the Jacobian there: from the tip
/// columns of its last pass if that pass was at `x` with them (`fresh`, `jacobian`), else
/// from a pass with the columns at `x`.
fn stability_at(
    p: &mut Shooting<'_>,
    x: &[f64],
    jacobian: Option<&[f64]>,
    fresh: bool,
) -> Option<(Stability, Vec<f64>)> {
    let length = p.eq.model.length();
    if let (true, Some(j), Some(tw)) = (fresh, jacobian, p.tip_twist) {
        return tip_stability(j, &tw, length, p.jacobi).map(|s| (s, j.to_vec()));
    }
    if let Some((_, exact)) = p.certificate(x, 1.0) {
        // Stable, certified by exact columns near x: the margin at x is computed when first
        // read (NaN here).
        let certified = Stability {
            stable: true,
            margin: f64::NAN,
            mode: None,
        };
        return Some((certified, jacobian.map_or(exact.to_vec(), <[f64]>::to_vec)));
    }
    let (_, cols, _) = p.pass::<FULL>(x, 1.0).ok()?;
    let mut j = vec![0.0; 36];
    for (c, col) in cols.iter().enumerate() {
        j[6 * c..6 * c + 6].copy_from_slice(col.as_slice());
    }
    let tw = p.tip_twist?;
    tip_stability(&j, &tw, length, p.jacobi).map(|s| (s, j))
}

/// Size of the imperfection of `seek_stable` (see [`SolveOptions::seek_stable`]): a dead tip wrench of `IMPERFECTION` times the
/// force scale `E I(0) / L²` (and `E I(0) / L` for its moment) along the unstable mode.
pub const IMPERFECTION: f64 = 1e-1;

/// A stable equilibrium found: its unknowns, stability and shooting Jacobian (column-major).
type Found = (Vec<f64>, Stability, Vec<f64>);

/// A stable equilibrium instead of the unstable one at `x` (see [`SolveOptions::seek_stable`]):
/// first continuation from the unloaded rod in load steps of at most 1/8, refusing unstable
/// states (the stable branch connected to the unloaded rod); then, for a symmetric problem whose
/// continuation stays on the unstable branch (a column past its critical load), the same
/// rod with a small dead tip wrench along the unstable mode ([`IMPERFECTION`], either sign)
/// solved by continuation, and the perfect rod solved again from there by Newton. Returns
/// the unknowns and the stability of the first converged, stable equilibrium found, and the
/// Newton iterations spent.
fn seek_stable(
    p: &mut Shooting<'_>,
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    (x, stability): (&[f64], &Stability),
) -> (Option<Found>, usize) {
    let mut iterations = 0;
    if options.newton.continuation {
        p.require_stable = true;
        let c = step_loads(p, options, None, 0.0, 0.125, true);
        p.require_stable = false;
        iterations += c.iterations;
        if c.outcome.converged && c.load_factor >= 1.0 {
            let o = &c.outcome;
            if let Some((s, j)) = stability_at(p, &o.x, o.jacobian.as_deref(), o.exact) {
                if s.stable {
                    return (Some((o.x.clone(), s, j)), iterations);
                }
            }
        }
    }
    let Some(mode) = stability.mode else {
        return (None, iterations);
    };
    // The mode's unit dimensionless tip wrench ζ = Y δx, in SI.
    let mut j = [0.0; 36];
    let mut r = [0.0; 6];
    if p.evaluate(x, 1.0, Some(&mut j), &mut r) != Evaluated::Jacobian {
        return (None, iterations);
    }
    let zeta: [f64; 6] = std::array::from_fn(|i| (0..6).map(|k| j[i + 6 * k] * mode[k]).sum());
    let f = model.force_scale() * IMPERFECTION;
    let quiet = SolveOptions {
        seek_stable: false,
        warm_start: None,
        newton: NewtonOptions {
            throw: false,
            ..options.newton
        },
        ..*options
    };
    for sign in [1.0, -1.0] {
        let w: [f64; 6] =
            std::array::from_fn(|i| sign * zeta[i] * if i < 3 { f } else { f * model.length() });
        let mut loads = model.loads().clone();
        loads.point_loads.push(PointLoad {
            s: model.length(),
            force: Vector3::new(w[0], w[1], w[2]),
            moment: Vector3::new(w[3], w[4], w[5]),
            frame: Frame::World,
        });
        let Ok(imperfect) = RobotModel::new(
            model.rod().clone(),
            model.tendons().to_vec(),
            model.chambers().to_vec(),
            loads,
        ) else {
            return (None, iterations);
        };
        let Ok(bent) = solve_with(&imperfect, actuation, &quiet, &[], true) else {
            continue;
        };
        iterations += bent.stats.iterations;
        if !bent.stats.converged {
            continue;
        }
        let x1 = scaled(model, &bent.base_wrench);
        let broyden = matches!(options.integrator, Integrator::Rk4 { .. });
        let jac = bent.jacobian.map(|m| m.as_slice().to_vec());
        let s = NewtonSettings {
            residual_first: true,
            ..settings(broyden, jac.as_deref(), true)
        };
        let out = newton(p, &x1, 1.0, &options.newton, &s);
        iterations += out.iterations;
        let moved = (0..6).map(|k| (out.x[k] - x[k]).abs()).fold(0.0, f64::max);
        if !out.converged || moved <= 1e-6 * (1.0 + max_norm(x)) {
            continue;
        }
        if let Some((s, j)) = stability_at(p, &out.x, out.jacobian.as_deref(), out.exact) {
            if s.stable {
                return (Some((out.x, s, j)), iterations);
            }
        }
    }
    (None, iterations)
}

/// The message of a solve that did not converge: why it stopped.
fn failure(reached: &Reached, max_load_steps: usize) -> String {
    let what = "shooting Newton (Cosserat rod statics)";
    match reached.stopped {
        Some(Stopped::StepsExhausted) => format!(
            "{what}: the load steps ran out at load factor {:.4} ({max_load_steps} steps; \
             raise max_load_steps)",
            reached.load_factor
        ),
        Some(Stopped::IncrementUnderflow) => format!(
            "{what}: no load step beyond load factor {:.4} converged on the branch from the \
             unloaded rod (load increment below {:e})",
            reached.load_factor,
            crate::solve::MIN_LOAD_INCREMENT
        ),
        Some(Stopped::StartFailed) => format!(
            "{what}: the actuated rod without external loads could not be integrated \
             (non-finite state or a failed constitutive solve: the actuation is beyond what \
             the integration resolves)"
        ),
        _ => what.to_string(),
    }
}

/// Solves the statics of `model` under `actuation` (`solve_statics(rod, tendons=(),
/// loads=None, ...)` in Python, which builds both), reporting the solution at the
/// integration mesh.
///
/// # Errors
/// As [`solve_statics_at`].
pub fn solve_statics(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
) -> Result<StaticsSolution> {
    solve_statics_at(model, actuation, options, &[])
}

/// Checks `s_out`: finite, in `[0, L]`, strictly increasing.
fn check_s_out(s_out: &[f64], length: f64) -> Result<()> {
    for (i, &s) in s_out.iter().enumerate() {
        if !(s.is_finite() && (0.0..=length).contains(&s)) {
            return Err(Error::invalid(
                format!("s_out[{i}]"),
                s,
                format!("in [0, length] = [0, {length}] m"),
            ));
        }
        if i > 0 && s <= s_out[i - 1] {
            return Err(Error::invalid(
                format!("s_out[{i}]"),
                s,
                format!(
                    "> s_out[{}] = {} m (strictly increasing)",
                    i - 1,
                    s_out[i - 1]
                ),
            ));
        }
    }
    Ok(())
}

/// [`solve_statics`] with the solution reported at the arc lengths `s_out` (m, strictly
/// increasing in `[0, L]`; empty: at the integration mesh). Every `s_out` is a node of every
/// pass (an RK4 interval is split there, an adaptive step ends there), not interpolated; at a
/// break (a tendon termination, a point load) the values just after the jump are reported.
///
/// A loaded solution reports its stability ([`StaticsSolution::stable`]); when the
/// equilibrium reached is unstable and [`SolveOptions::seek_stable`] is set, a stable one is
/// searched (smaller load steps from the unloaded rod, then along the unstable mode) and
/// returned if found.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the offending input (`tensions[i]`, `pressures[i]`,
/// their counts, options, `s_out[i]`); [`Error::NotConverged`] with the iterations, the
/// residual of the last accepted state and its load factor if the shooting does not converge
/// and `options.newton.throw` is true (its message says why: the load steps ran out, no load
/// step converged, the actuated rod could not be integrated), unless a hyperelastic material
/// failed on the way: then [`Error::InvalidParameter`] naming `stretch` (a fibre compressed
/// to zero length) or the law's parameters (a law that is not monotonic at the stretches
/// reached).
pub fn solve_statics_at(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    s_out: &[f64],
) -> Result<StaticsSolution> {
    solve_with(model, actuation, options, s_out, false)
}

/// The stability of the converged `reached`, replaced by a stable equilibrium when one is
/// sought and found ([`seek_stable`]).
fn stable_outcome(
    p: &mut Shooting<'_>,
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    reached: &mut Reached,
) -> Option<Stability> {
    let o = &reached.outcome;
    let stability = stability_at(p, &o.x, o.jacobian.as_deref(), o.exact).map(|(s, _)| s);
    if let Some(s) = stability.filter(|s| !s.stable && options.seek_stable) {
        let x = reached.outcome.x.clone();
        let (found, its) = seek_stable(p, model, actuation, options, (&x, &s));
        reached.iterations += its;
        if let Some((x, s, j)) = found {
            reached.outcome.x = x;
            reached.outcome.jacobian = Some(j);
            reached.outcome.at_x = false;
            return Some(s);
        }
    }
    stability
}

/// The options, output arc lengths, actuation and warm start of a solve of `model`.
fn check_inputs(
    model: &RobotModel,
    actuation: &Actuation,
    options: &SolveOptions,
    s_out: &[f64],
) -> Result<()> {
    options.validate()?;
    check_s_out(s_out, model.length())?;
    model.check_actuation(actuation)?;
    // A tendon with friction needs its tension profile (solve_frictional): a uniform tension
    // would be the frictionless answer, reported as if friction had been modelled.
    // (A tendon at zero tension carries no friction: the zero actuation of the displacement
    // reference is the frictionless one.)
    let tensions = actuation.tension_values(model.tendons().len());
    if actuation.profile.is_none() {
        if let Some(i) = (0..tensions.len()).find(|&i| {
            model.tendons()[i].friction() > 0.0
                && (tensions[i] != 0.0 || actuation.tendons.get(i).is_some_and(|t| t.is_held()))
        }) {
            return Err(Error::invalid(
                format!("tendons[{i}].friction"),
                model.tendons()[i].friction(),
                "0 here: a tendon with friction is solved by solve_frictional",
            ));
        }
    }
    // A guided tendon loads the rod at its guides only (solve_frictional): its tension along
    // the continuous channel would be another robot's answer.
    if let Some(i) = (0..tensions.len()).find(|&i| {
        model.tendons()[i].is_guided()
            && (tensions[i] != 0.0 || actuation.tendons.get(i).is_some_and(|t| t.is_held()))
    }) {
        return Err(Error::invalid(
            format!("tendons[{i}].guides"),
            format!("{} guides", model.tendons()[i].guides().len()),
            "none here: a tendon routed through guides is solved by solve_frictional",
        ));
    }
    if let Some(w) = &options.warm_start {
        model.check_wrench("warm_start.base_wrench", &w.base_wrench)?;
    }
    Ok(())
}

/// [`solve_statics_at`], the continuation refusing unstable states if `require_stable`.
fn solve_with(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    s_out: &[f64],
    require_stable: bool,
) -> Result<StaticsSolution> {
    check_inputs(model, actuation, options, s_out)?;
    let (nt, nc) = (model.tendons().len(), model.chambers().len());
    if actuation.has_held() {
        return super::displacement::solve_held(model, actuation, options, s_out);
    }
    let tensions = actuation.tension_values(nt);
    let pressures = actuation.pressure_values(nc);
    let plan = match options.integrator {
        Integrator::Rk4 { steps } => rk4_plan(model.breaks(), steps),
        Integrator::Adaptive(_) => Vec::new(),
    };
    let eq = Equations {
        model,
        tensions: &tensions,
        pressures: &pressures,
        load_factor: 1.0,
        profile: actuation.profile.as_deref(),
    };
    let mut p = Shooting::new(eq, options.integrator, plan);
    p.stops = interior(s_out, model.length());
    p.require_stable = require_stable;
    let x0 = match &options.warm_start {
        Some(w) => scaled(model, &w.base_wrench),
        None => [0.0; 6],
    };
    let opts = &options.newton;
    // Without external loads the equilibrium is unique (x = 0) and stable (docs/stability.md).
    let loaded = !model.loads().is_unloaded();
    let (reached, stability) = settle(&mut p, model, actuation, options, &x0, loaded);
    let result = &reached.outcome;
    let finite = p.nodes.iter().all(|n| n.y.iter().all(|v| v.is_finite()));
    let mut stats = SolverStats {
        iterations: reached.iterations,
        residual: result.residual,
        function_evaluations: 0,
        converged: result.converged && finite && result.residual.is_finite(),
        load_steps: reached.load_steps,
        load_factor: reached.load_factor,
    };
    let x = result.x.clone();
    let jacobian = result
        .jacobian
        .as_ref()
        .map(|j| Matrix6::from_column_slice(j));
    let mut sol = assemble(&mut p, model, scaled_back(model, &x), stats, s_out);
    let strains_finite = sol
        .v
        .iter()
        .chain(&sol.u)
        .all(|v| v.iter().all(|c| c.is_finite()));
    if !strains_finite {
        stats.converged = false;
        sol.stats.converged = false;
    }
    sol.stats.function_evaluations = p.evaluations;
    if sol.stats.converged {
        if let Some(e) = super::collapse::compressed_through_zero(&sol, "loads") {
            return Err(super::collapse::compressed_to_zero(model, &tensions).unwrap_or(e));
        }
    }
    if !stats.converged && opts.throw {
        let non_finite = !finite || !strains_finite;
        return Err(not_converged(
            &mut p,
            &reached,
            &stats,
            &tensions,
            opts.max_load_steps,
            non_finite,
        ));
    }
    sol.actuation = actuation.clone();
    sol.options = *options;
    sol.s_out = s_out.to_vec();
    sol.jacobian = jacobian;
    sol.coarse_defect = reached.coarse_defect;
    match stability {
        Some(s) => {
            sol.stable = s.stable;
            if !s.margin.is_nan() {
                let _ = sol.margin.set(s.margin);
            }
        }
        None => sol.stable = !loaded && sol.stats.converged,
    }
    Ok(sol)
}

/// The loads reached from `x0` ([`attempt`]) and, when converged under loads, the stability
/// of the equilibrium ([`stable_outcome`]); the last pass of `p` then at the returned
/// unknowns, whose residual (and convergence) is re-checked there if it was not.
fn settle(
    p: &mut Shooting<'_>,
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    x0: &[f64; 6],
    loaded: bool,
) -> (Reached, Option<Stability>) {
    let coarse = if loaded {
        coarse_first(p, options, x0)
    } else {
        None
    };
    // With a coarse mesh, the stability is judged there first (a fifth of the columns' cost).
    let judge_coarse = loaded && p.held.is_empty() && p.integrator.coarse().is_some();
    let (mut reached, clear) = match coarse {
        Some((reached, clear)) => (reached, clear),
        None => (attempt(p, options, x0, loaded && !judge_coarse), None),
    };
    let converged = reached.outcome.converged;
    let stability = if converged && loaded {
        clear
            .or_else(|| {
                let x = reached.outcome.x.clone();
                judge_coarse.then(|| stable_on_coarse(p, &x)).flatten()
            })
            .or_else(|| stable_outcome(p, model, actuation, options, &mut reached))
    } else {
        None
    };
    let result = &mut reached.outcome;
    // The recorded pass must be the one at the returned unknowns (and their load factor).
    if !result.at_x {
        let mut r = [0.0; 6];
        if p.evaluate(&result.x, reached.load_factor, None, &mut r) != Evaluated::Failed {
            result.residual = max_norm(&r);
        } else {
            result.residual = f64::INFINITY;
        }
        result.converged =
            result.converged && result.residual <= p.tolerance(&result.x, options.newton.tolerance);
    }
    if result.converged {
        // Material failures of rejected trial iterates are not the returned state's.
        p.ws.material_error = None;
    }
    (reached, stability)
}

/// The error of a solve that did not converge: a material failure of the state, a rod
/// compressed to zero length by its tendons, else [`Error::NotConverged`] with the stage
/// that failed ([`failure`], after at most `max_load_steps` load steps) and whether values
/// along the rod are not finite.
fn not_converged(
    p: &mut Shooting<'_>,
    reached: &Reached,
    stats: &SolverStats,
    tensions: &[f64],
    max_load_steps: usize,
    non_finite: bool,
) -> Error {
    if let Some(e) = p.ws.material_error.take() {
        return e;
    }
    if matches!(reached.stopped, Some(Stopped::StartFailed)) {
        if let Some(e) = super::collapse::compressed_to_zero(p.eq.model, tensions)
            .or_else(|| super::collapse::bent_inside_a_tendon(p.eq.model, tensions))
        {
            return e;
        }
    }
    let mut what = failure(reached, max_load_steps);
    if non_finite {
        what.push_str(": non-finite values along the rod");
    }
    Error::NotConverged {
        what,
        iterations: stats.iterations,
        residual: stats.residual,
        load_factor: stats.load_factor,
    }
}
