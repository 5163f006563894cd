//! The RK4 mesh checked against the shape it solves: an a-posteriori estimate of the
//! truncation error, and the refinement or refusal every solve a user calls goes through.
//!
//! Classical RK4 applied to `R' = R û` replaces `exp(h û)` by its Taylor polynomial of degree
//! four, so a step that turns by `θ = h |u|` errs by `θ⁵ / 120` rad
//! ([`rk4_rotation_error`]); a turn missed at `s` moves the rest of the rod, so the tip's
//! position errs by about `Σ θ⁵/120 (L - s)/L` of the length ([`rk4_position_error`]).
//! [`solve_at_output`] (the statics solve of the Python API, sweeps and workspace maps),
//! [`with_mesh_control`] (solves with obstacles or tendon friction) and the inverse statics
//! judge the mesh by [`mesh_verdict`]: the default mesh is refined above
//! [`DEFAULT_MESH_POSITION_LIMIT`], a chosen one (or the finest default refinement) refused
//! above [`CHOSEN_MESH_POSITION_LIMIT`]. The turn of a step is the backbone's or, where it is
//! faster, that of a loaded tendon's routing (RK4 integrates its loads as it integrates the
//! rotations): a helix's `2π / |pitch|`, a routing function's `|r'| / max |r|`.

use crate::cosserat::statics::{
    solve_statics_at, Integrator, SolveOptions, StaticsSolution, DEFAULT_RK4_STEPS,
};
use crate::error::{Error, Result};
use crate::integrate::march::rk4_plan;
use crate::model::tendon::{OffsetFn, Routing, Tendon};

/// Largest refinement factor of the default mesh.
pub(crate) const MAX_REFINEMENT: usize = 32;

/// Estimated truncation error of the rotations of the RK4 march of `solution` (rad): the sum
/// over its steps of `θ⁵ / 120`, `θ = h max(|u_i|, |u_{i+1}|)` the step's turning angle.
/// NaN if a curvature is not finite.
pub fn rk4_rotation_error(solution: &StaticsSolution) -> f64 {
    step_errors(solution).map(|(_, e)| e).sum()
}

/// Per step of the RK4 march of `solution`: its start (m) and its rotation error `θ⁵ / 120`
/// (rad), `θ = h max(|u_i|, |u_{i+1}|, ω)` with `ω` the fastest turn rate of a loaded tendon's
/// routing on the step ([`Routings::rate`]).
fn step_errors(solution: &StaticsSolution) -> impl Iterator<Item = (f64, f64)> + '_ {
    let norm = |u: &[f64; 3]| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let routings = Routings::new(solution);
    solution
        .s
        .windows(2)
        .zip(solution.u.windows(2))
        .map(move |(s, u)| {
            let rate = routings.rate(s[0], s[1]);
            let theta = (s[1] - s[0]) * norm(&u[0]).max(norm(&u[1])).max(rate);
            (s[0], theta.powi(5) / 120.0)
        })
}

/// The routings of the tendons of a solution that carry tension, for their turn rates
/// ([`Tendon::turn_rate_at`](crate::model::Tendon::turn_rate_at)): RK4 integrates the loads
/// of a helical tendon as it integrates the rotations, and misses them as badly where a step
/// turns the helix by a radian or more.
struct Routings<'a> {
    /// The tendons that carry tension and are routed along a helix or by a function (the
    /// others do not turn), each with the scale of its rate: the largest distance (m) of a
    /// routing function's offset from the backbone at the solution's nodes (1 for a helix).
    turning: Vec<(&'a Tendon, f64)>,
}

impl<'a> Routings<'a> {
    fn new(solution: &'a StaticsSolution) -> Self {
        let largest = |offset: &OffsetFn| {
            let distance = |s: &f64| {
                let r = offset(*s);
                r[0].hypot(r[1])
            };
            let finite = solution.s.iter().map(distance).filter(|d| d.is_finite());
            finite.fold(0.0, f64::max)
        };
        let turning = solution
            .model
            .tendons()
            .iter()
            .zip(&solution.tendon_tensions)
            .filter(|(_, &tension)| tension != 0.0)
            .filter_map(|(t, _)| match t.routing() {
                Routing::Function { offset, .. } => Some((t, largest(offset))),
                Routing::Helical { .. } => Some((t, 1.0)),
                _ => None,
            })
            .collect();
        Self { turning }
    }

    /// The fastest turn rate (rad/m) on the step `[a, b]` (m), at its ends and middle, of the
    /// routing of a tendon that carries tension there.
    fn rate(&self, a: f64, b: f64) -> f64 {
        let mut rate = 0.0_f64;
        for &(t, scale) in &self.turning {
            for s in [a, 0.5 * (a + b), b] {
                if t.end().is_none_or(|e| s < e) {
                    rate = rate.max(t.turn_rate_at(s, scale));
                }
            }
        }
        rate
    }
}

/// Estimated truncation error of the tip position of the RK4 march of `solution`, relative
/// to the rod's length: the rotation error of each step ([`rk4_rotation_error`]'s terms)
/// times the length after the step's start, over `L`. A turn that RK4 misses at the tip of a
/// thin, tightly curled rod moves little of it; one near the base moves all of it. NaN if a
/// curvature is not finite.
pub fn rk4_position_error(solution: &StaticsSolution) -> f64 {
    let length = solution.model.length();
    step_errors(solution)
        .map(|(s, e)| e * (length - s) / length)
        .sum()
}
/// Target of [`rk4_rotation_error`] (rad) for a solve reported at chosen arc lengths
/// ([`solve_at_output`]): positions there within about `1e-9 L` on stress-free arcs up to
/// `2π`.
pub const OUTPUT_ROTATION_TARGET: f64 = 1e-9;

/// [`solve_statics_at`] under the mesh control of [`with_mesh_control`]: an RK4 solution
/// whose mesh cannot resolve its shape is refined (the default mesh, above
/// [`DEFAULT_MESH_POSITION_LIMIT`], and a default solve that does not converge is tried on
/// one eight times finer) or refused (a chosen mesh, above [`CHOSEN_MESH_POSITION_LIMIT`]).
/// With `s_out`, the shape is solved at the mesh's nodes first; at the default mesh its
/// rotational truncation error ([`rk4_rotation_error`]) is estimated there and, above
/// [`OUTPUT_ROTATION_TARGET`], the values at `s_out` are solved on a mesh `m` times finer
/// (warm-started; `m` from the fourth-order convergence, up to 32 times the default mesh),
/// whose steps the returned solution's options record. The adaptive integrator is
/// [`solve_statics_at`] as it is.
///
/// # Errors
/// As [`solve_statics_at`]; [`Error::InvalidParameter`] naming `steps` for a chosen RK4 mesh
/// whose estimated tip-position error exceeds [`CHOSEN_MESH_POSITION_LIMIT`].
pub fn solve_at_output(
    model: &std::sync::Arc<crate::model::RobotModel>,
    actuation: &crate::model::Actuation,
    options: &SolveOptions,
    s_out: &[f64],
) -> Result<StaticsSolution> {
    let ours = options.integrator.is_default_mesh();
    let solve_on = |o: &SolveOptions| solve_statics_at(model, actuation, o, &[]);
    if s_out.is_empty() {
        return with_mesh_control(options, ours, solve_on, |s| s);
    }
    if !matches!(options.integrator, Integrator::Rk4 { .. }) {
        return solve_statics_at(model, actuation, options, s_out);
    }
    // The shape at the mesh's nodes, under the mesh control.
    let mut quiet = *options;
    quiet.newton.throw = true;
    let mesh = match with_mesh_control(&quiet, ours, solve_on, |s| s) {
        Ok(mesh) => mesh,
        Err(e) if e.names("steps") => return Err(e),
        Err(_) => return solve_statics_at(model, actuation, options, s_out),
    };
    let Integrator::Rk4 { steps } = mesh.options.integrator else {
        return solve_statics_at(model, actuation, options, s_out);
    };
    let error = rk4_rotation_error(&mesh);
    let m = if !ours || error.is_nan() || error <= OUTPUT_ROTATION_TARGET {
        1
    } else {
        ((error / OUTPUT_ROTATION_TARGET).powf(0.25).ceil() as usize).clamp(2, MAX_REFINEMENT)
    };
    if m == 1 && mesh.options.integrator == options.integrator {
        return solve_statics_at(model, actuation, options, s_out);
    }
    let mut fine = *options;
    fine.integrator = Integrator::Rk4 {
        steps: (m * steps).min(MAX_REFINEMENT * DEFAULT_RK4_STEPS),
    };
    fine.warm_start = Some(mesh.warm_start());
    // The branch was settled (and a stable equilibrium sought) on the mesh of `mesh`.
    fine.seek_stable = false;
    solve_statics_at(model, actuation, &fine, s_out)
}

/// Estimated tip-position error ([`rk4_position_error`], relative to the length) of a
/// solution on the default RK4 mesh above which it is solved again on a finer one
/// ([`solve_at_output`]): a shape the default mesh does not resolve (a curl of two turns or more, a
/// thin tapered tip curled tight). A 40-step solution of a stress-free arc of `2π` estimates
/// 1.6e-5.
pub const DEFAULT_MESH_POSITION_LIMIT: f64 = 1e-4;

/// Estimated tip-position error ([`rk4_position_error`]) of a solution on a chosen RK4 mesh
/// above which the solve is refused naming `steps`: a tenth of the length, where the shape is
/// meaningless (steps that turn the rod by two radians or more: RK4's rotations grow).
pub const CHOSEN_MESH_POSITION_LIMIT: f64 = 0.1;

/// Refinement of the default mesh on which a solve that fails there is tried again.
const RETRY_REFINEMENT: usize = 8;

/// Target of [`rk4_position_error`] for the finer mesh of [`mesh_verdict`].
const RESOLVED_POSITION_TARGET: f64 = 1e-8;

/// `solve` on the mesh of `options` under the mesh control of [`solve_at_output`], for every
/// solve that holds a statics solution (`statics` of the result: the solution itself, a
/// contact or a frictional solution). On a mesh the solve chose (`ours`: the default one or
/// its refinement), a solve that does not converge is tried again on a mesh
/// eight times finer (a tight curl the mesh cannot march may converge there; its
/// result if it converges, else the first outcome); then the converged solution's mesh is
/// judged ([`mesh_verdict`]): too coarse for the shape, `solve` is called again on the finer
/// mesh, whose result returns; a chosen mesh that is meaningless is an error naming `steps`.
///
/// # Errors
/// `solve`'s; [`Error::InvalidParameter`] naming
/// `steps` for a chosen mesh whose estimated tip error exceeds [`CHOSEN_MESH_POSITION_LIMIT`].
pub fn with_mesh_control<T>(
    options: &SolveOptions,
    ours: bool,
    mut solve: impl FnMut(&SolveOptions) -> Result<T>,
    statics: impl Fn(&T) -> &StaticsSolution,
) -> Result<T> {
    controlled(options, ours, &mut solve, &statics)
}

/// [`with_mesh_control`] on `dyn` closures (it calls itself for a chosen mesh that fails).
fn controlled<T>(
    options: &SolveOptions,
    ours: bool,
    solve: &mut dyn FnMut(&SolveOptions) -> Result<T>,
    statics: &dyn Fn(&T) -> &StaticsSolution,
) -> Result<T> {
    let Integrator::Rk4 { steps } = options.integrator else {
        return solve(options);
    };
    let on = |steps: usize| SolveOptions {
        integrator: Integrator::Rk4 { steps },
        ..*options
    };
    let most = MAX_REFINEMENT * DEFAULT_RK4_STEPS;
    let first = solve(options);
    // (Only a solve that did not converge, or a material failure on the way: a named error of
    // the input is the same on any mesh.)
    let failed = match &first {
        Ok(t) => !statics(t).stats.converged,
        Err(e) => matches!(e, Error::NotConverged { .. }),
    };
    if !ours && (failed || first.is_err()) {
        // A chosen mesh that fails may be one too coarse for the shape: judged from the shape
        // on the mesh the solve would choose.
        let resolved = controlled(&on(DEFAULT_RK4_STEPS), true, solve, statics);
        if let Ok(t) = resolved {
            let error = rk4_position_error_on(statics(&t), steps);
            if error > CHOSEN_MESH_POSITION_LIMIT {
                return Err(meaningless(steps, error));
            }
        }
        return first;
    }
    let (outcome, steps) = match first {
        _ if ours && failed && steps < most => {
            let retry = (RETRY_REFINEMENT * steps).min(most);
            match solve(&on(retry)) {
                Ok(t) if statics(&t).stats.converged => (t, retry),
                _ => return first,
            }
        }
        first => (first?, steps),
    };
    let sol = statics(&outcome);
    if !sol.stats.converged {
        return Ok(outcome);
    }
    let Some(finer) = mesh_verdict(rk4_position_error(sol), steps, ours)? else {
        return Ok(outcome);
    };
    let refined = solve(&on(finer))?;
    let sol = statics(&refined);
    if sol.stats.converged {
        // (One refinement: the finest mesh only judged whether it resolves the shape at all.)
        mesh_verdict(rk4_position_error(sol), most, ours)?;
    }
    Ok(refined)
}

/// The estimated tip error ([`rk4_position_error`], relative to the length) of an RK4 march
/// on `steps` steps of the shape of `solution` (solved on another mesh): each step's turn
/// from the largest curvature of the solution's nodes on it (and its ends).
fn rk4_position_error_on(solution: &StaticsSolution, steps: usize) -> f64 {
    let model = &solution.model;
    let (breaks, length) = (model.breaks(), model.length());
    let norm = |u: &[f64; 3]| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let curvature: Vec<f64> = solution.u.iter().map(norm).collect();
    let slack = 1e-12 * length;
    let routings = Routings::new(solution);
    let mut error = 0.0;
    let mut first = 0;
    for (k, &n) in rk4_plan(breaks, steps).iter().enumerate() {
        let h = (breaks[k + 1] - breaks[k]) / n.max(1) as f64;
        for j in 0..n {
            let a = breaks[k] + j as f64 * h;
            while first + 1 < solution.s.len() && solution.s[first + 1] < a - slack {
                first += 1;
            }
            // The nodes on [a, a + h] and the one before it (the curvature at a lies between).
            let most = solution.s[first..]
                .iter()
                .zip(&curvature[first..])
                .take_while(|(s, _)| **s <= a + h + slack)
                .map(|(_, u)| *u)
                .fold(routings.rate(a, a + h), f64::max);
            error += (h * most).powi(5) / 120.0 * (length - a) / length;
        }
    }
    error
}

/// The RK4 steps on which a problem solved on `steps` with the estimated tip error `error`
/// ([`rk4_position_error`], relative to the length) must be solved again, `None` if the mesh
/// resolves the shape (or `error` is NaN). On a mesh the solve chose (`ours`: the default
/// one or its refinement), above [`DEFAULT_MESH_POSITION_LIMIT`]: a mesh `m` times finer (`m`
/// from the fourth-order convergence toward 1e-8, at least 2, up to 32 times the default
/// mesh); on a chosen mesh, and on the finest the solve chooses, above
/// [`CHOSEN_MESH_POSITION_LIMIT`], an error naming `steps`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `steps` as above.
pub fn mesh_verdict(error: f64, steps: usize, ours: bool) -> Result<Option<usize>> {
    if error.is_nan() {
        return Ok(None);
    }
    let refinement = (error / RESOLVED_POSITION_TARGET).powf(0.25).ceil();
    let most = MAX_REFINEMENT * DEFAULT_RK4_STEPS;
    if ours && error > DEFAULT_MESH_POSITION_LIMIT && steps < most {
        let finer = ((steps as f64 * refinement) as usize)
            .max(2 * steps)
            .min(most);
        return Ok(Some(finer));
    }
    // (Also the finest mesh the solve would choose: a shape it cannot resolve either, such as
    // a helical tendon of thousands of turns, is as meaningless.)
    if error > CHOSEN_MESH_POSITION_LIMIT {
        return Err(meaningless(steps, error));
    }
    Ok(None)
}

/// The error naming `steps` for a chosen RK4 mesh whose estimated tip error `error` (relative
/// to the length) exceeds [`CHOSEN_MESH_POSITION_LIMIT`], with the steps that resolve it.
fn meaningless(steps: usize, error: f64) -> Error {
    let refinement = (error / RESOLVED_POSITION_TARGET).powf(0.25).ceil();
    let needed = steps as f64 * refinement;
    let remedy = if needed <= 1e7 {
        format!(
            "about {needed:.0} steps resolve it to 1e-8 (or use the default mesh, which \
             refines itself up to {} steps, or the adaptive integrator)",
            MAX_REFINEMENT * DEFAULT_RK4_STEPS
        )
    } else {
        "no RK4 mesh of a sensible size resolves it (use the adaptive integrator)".to_owned()
    };
    Error::invalid(
        "steps",
        steps,
        format!(
            "enough RK4 steps to resolve the shape: on these the tip's position errs by about \
             {error:.2e} of the length (Σ θ⁵/120 (L - s)/L over the steps, θ the turn of a \
             step of the backbone or of a tendon's routing), and the shape is \
             meaningless; {remedy}"
        ),
    )
}
