//! Load continuation: from a state exact at load factor 0, step the load factor to 1 with a
//! predictor (the exact tangent `dx/dλ = -J⁻¹ ∂r/∂λ` where the problem provides `∂r/∂λ`,
//! else the secant through the last two steps) and a Newton corrector, halving a step that
//! does not converge, takes a first Newton step beyond the limit, or moves the state too far
//! (the problem's [`Problem::close`] safeguard), doubling it after a success.

use super::newton::{newton, NewtonOutcome, NewtonSettings};
use super::{Evaluated, NewtonOptions, Problem, MIN_LOAD_INCREMENT};
use crate::math::linalg::DenseLu;

/// Where the continuation starts and how it steps.
#[derive(Debug, Clone, Copy)]
pub struct ContinuationSettings<'a> {
    /// The exact solution at load factor 0.
    pub x0: &'a [f64],
    /// The Jacobian there, if known (for the tangent predictor of the first step).
    pub jacobian0: Option<&'a [f64]>,
    /// First load-factor increment.
    pub first_increment: f64,
    /// Largest load-factor increment.
    pub max_increment: f64,
}

/// Why [`continuation`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stopped {
    /// The full load (load factor 1) was reached.
    Converged,
    /// The load steps ([`NewtonOptions::max_load_steps`]) ran out.
    StepsExhausted,
    /// The load increment fell below [`MIN_LOAD_INCREMENT`].
    IncrementUnderflow,
    /// The evaluation of the start state failed.
    StartFailed,
}

/// Result of [`continuation`].
#[derive(Debug, Clone, PartialEq)]
pub struct Continued {
    /// The Newton outcome of the last accepted step (converged at `load_factor` = 1 on
    /// success); on failure its `x` is the last accepted state and `residual` that state's
    /// residual at `load_factor` (`converged` false).
    pub outcome: NewtonOutcome,
    /// The load factor of the last accepted state.
    pub load_factor: f64,
    /// Load steps attempted.
    pub steps: usize,
    /// Newton iterations over all steps.
    pub iterations: usize,
    /// Why it stopped.
    pub stopped: Stopped,
}

/// `-J⁻¹ v` (column-major `J`), `None` if singular.
fn tangent(jac: &[f64], v: &[f64]) -> Option<Vec<f64>> {
    let n = v.len();
    let mut lu = DenseLu::default();
    if !lu.factor(n, jac) {
        return None;
    }
    let mut t: Vec<f64> = v.iter().map(|x| -x).collect();
    lu.solve_in_place(&mut t).then_some(t)
}

/// Steps the load factor of `problem` from 0 to 1 (see the module documentation).
pub fn continuation<P: Problem + ?Sized>(
    problem: &mut P,
    start: &ContinuationSettings<'_>,
    options: &NewtonOptions,
    settings: &NewtonSettings<'_>,
) -> Continued {
    let n = problem.dim();
    let mut x = start.x0.to_vec();
    let mut r = vec![0.0; n];
    // The reference state of the safeguard: the solution at load factor 0.
    let start_failed = problem.evaluate(&x, 0.0, None, &mut r) == Evaluated::Failed;
    if start_failed {
        r.fill(f64::INFINITY);
    }
    problem.commit();
    let mut lambda = 0.0f64;
    let mut dl = start
        .first_increment
        .clamp(MIN_LOAD_INCREMENT, start.max_increment);
    let mut drdl = vec![0.0; n];
    let mut slope: Option<Vec<f64>> = match start.jacobian0 {
        Some(j) if problem.load_derivative(&x, 0.0, &mut drdl) => tangent(j, &drdl),
        _ => None,
    };
    let mut prev: Option<(Vec<f64>, f64)> = None;
    let mut jac: Option<Vec<f64>> = start.jacobian0.map(<[f64]>::to_vec);
    let mut accepted = NewtonOutcome {
        x: x.clone(),
        residual: problem.norm(&r),
        converged: false,
        iterations: 0,
        first_step: 0.0,
        jacobian: jac.clone(),
        at_x: true,
        exact: false,
    };
    let mut out = Continued {
        outcome: accepted.clone(),
        load_factor: 0.0,
        steps: 0,
        iterations: 0,
        stopped: Stopped::StepsExhausted,
    };
    if start_failed {
        out.stopped = Stopped::StartFailed;
        return out;
    }
    while out.steps < options.max_load_steps {
        let target = (lambda + dl).min(1.0);
        let h = target - lambda;
        let guess: Vec<f64> = match (&slope, &prev) {
            (Some(t), _) => (0..n).map(|k| x[k] + t[k] * h).collect(),
            (None, Some((xp, dlp))) => (0..n).map(|k| x[k] + (x[k] - xp[k]) * (h / dlp)).collect(),
            (None, None) => x.clone(),
        };
        let s = NewtonSettings {
            jacobian: jac.as_deref().filter(|_| settings.broyden),
            ..*settings
        };
        let step = newton(problem, &guess, target, options, &s);
        out.steps += 1;
        out.iterations += step.iterations;
        let ok = step.converged && step.at_x && problem.close();
        if ok {
            problem.commit();
            prev = Some((x.clone(), h));
            lambda = target;
            x.clone_from(&step.x);
            jac.clone_from(&step.jacobian);
            slope = match &jac {
                Some(j) if problem.load_derivative(&x, lambda, &mut drdl) => tangent(j, &drdl),
                _ => None,
            };
            accepted = step.clone();
            out.outcome = step;
            out.load_factor = lambda;
            if lambda >= 1.0 {
                out.stopped = Stopped::Converged;
                break;
            }
            dl = (dl * 2.0).min(start.max_increment);
        } else {
            // Back to the last accepted state (the problem's last evaluation is elsewhere).
            out.outcome = NewtonOutcome {
                converged: false,
                at_x: false,
                exact: false,
                ..accepted.clone()
            };
            dl *= 0.5;
            if dl < MIN_LOAD_INCREMENT {
                out.stopped = Stopped::IncrementUnderflow;
                break;
            }
        }
    }
    out.load_factor = lambda;
    if out.stopped != Stopped::Converged {
        // The last accepted step converged at a load factor below 1: not the full load.
        out.outcome.converged = false;
    }
    out
}
