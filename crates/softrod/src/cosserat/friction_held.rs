//! Displacement control with tendon friction: the base tensions of the held tendons are the
//! unknowns of the frictional solve.
//!
//! A held tendon `h` (pull-in `δ_h`, stiffness `k_h`) satisfies the complementarity of the
//! frictionless solve (`cosserat::displacement`): `τ_h >= 0`,
//! `g_h = ℓ_ref,h − ℓ_h − δ_h + τ_h / k_h >= 0`, `τ_h g_h = 0`, with `τ_h` its tension at the
//! base (where the motor holds it) and `ℓ_h` its path length in the frictional equilibrium
//! under those base tensions and the history `previous` (the tension along it follows the
//! capstan stick/slip rule, `cosserat::friction`). The taut tendons' base tensions are found by
//! Newton's method on `g = 0`, every evaluation one frictional solve from the same history: the
//! first Jacobian by forward differences, then Broyden updates; a tendon whose tension would
//! go negative is released (slack, `τ = 0`), a slack one that comes out stretched is taken up.
//! `ℓ_ref` is the path length at zero actuation ([`super::reference_lengths`]), unless the
//! actuation gives it. With `μ = 0` this is the frictionless displacement solve.
//!
//! A tendon routed through guides (`cosserat::guides`) is held the same way: its path is the
//! polyline of chords through its anchors, `ℓ_h` the polyline's length on the solved shape
//! (the `tendon_lengths` of the guided solution), `ℓ_ref` that length at zero actuation, and
//! `τ_h` the tension of its first chord; every evaluation is a guided solve.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use super::displacement::held_of;
use super::friction::{solve_on, FrictionOptions, FrictionalSolution};
use super::shooting::Held;
use crate::error::{Error, Result};
use crate::model::{Actuation, RobotModel, TendonInput};

/// Cap on the Newton iterations of the held base tensions.
pub const HELD_MAX_ITERATIONS: usize = 60;

/// Tolerance on the length residual `g` of the held tendons, relative to the rod length.
pub const HELD_TOLERANCE: f64 = 1e-13;

/// The first base tensions of the held tendons: the actuation's guess, the previous state's
/// base tensions, or zero.
fn first_tensions(
    actuation: &Actuation,
    held: &[Held],
    previous: Option<&FrictionalSolution>,
) -> Vec<f64> {
    match (&actuation.tension_guess, previous) {
        (Some(g), _) => held.iter().map(|h| g[h.tendon].max(0.0)).collect(),
        (None, Some(p)) => held
            .iter()
            .map(|h| p.tension[0][h.tendon].max(0.0))
            .collect(),
        (None, None) => vec![0.0; held.len()],
    }
}

/// Solves the frictional statics of `model` with displacement-controlled tendons (see the
/// module documentation) on the friction mesh `mesh` (m), from the state `previous` (on it)
/// or from rest.
///
/// # Errors
/// What [`solve_on`] reports; [`Error::NotConverged`] if the base tensions do not
/// settle in [`HELD_MAX_ITERATIONS`] iterations.
pub(super) fn solve_held_frictional(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &FrictionOptions,
    previous: Option<&FrictionalSolution>,
    mesh: &[f64],
) -> Result<FrictionalSolution> {
    let nt = model.tendons().len();
    let reference = match &actuation.reference_lengths {
        Some(r) => r.clone(),
        None => super::reference_lengths(model, &options.statics)?,
    };
    let held = held_of(model, actuation, &reference);
    let mut tau = first_tensions(actuation, &held, previous);
    let base = actuation.tension_values(nt);
    let solve = |tau: &[f64]| -> Result<(FrictionalSolution, DVector<f64>)> {
        let mut t = base.clone();
        for (k, h) in held.iter().enumerate() {
            t[h.tendon] = tau[k];
        }
        let mut act = actuation.clone();
        act.tendons = t.iter().map(|&x| TendonInput::Tension(x)).collect();
        let sol = solve_on(model, &act, options, previous, mesh)?;
        let g = DVector::from_fn(held.len(), |k, _| {
            let h = &held[k];
            h.target - sol.statics.tendon_lengths[h.tendon] + h.compliance * tau[k]
        });
        Ok((sol, g))
    };
    let l = model.length();
    let tol = HELD_TOLERANCE * l;
    // Forward-difference step in the tension (N): the model's force scale times 1e-7.
    let eps = 1e-7
        * model
            .force_scale()
            .max(tau.iter().fold(0.0, |a: f64, &b| a.max(b)));
    let (mut sol, mut g) = solve(&tau)?;
    let mut jac: Option<DMatrix<f64>> = None;
    for iteration in 0..HELD_MAX_ITERATIONS {
        // Slack tendons (no tension and not stretched) stay at zero: their rows are inactive.
        let active: Vec<bool> = (0..held.len())
            .map(|k| !(tau[k] <= 0.0 && g[k] > 0.0))
            .collect();
        let worst = (0..held.len())
            .filter(|&k| active[k])
            .map(|k| g[k].abs())
            .fold(0.0, f64::max);
        if worst <= tol {
            sol.iterations += iteration;
            // The zero of the displacements goes with the solution (as in the frictionless
            // displacement solve).
            sol.statics.actuation.reference_lengths = Some(reference);
            return Ok(sol);
        }
        let j = match jac.take() {
            Some(j) => j,
            None => {
                let mut j = DMatrix::zeros(held.len(), held.len());
                for k in 0..held.len() {
                    let mut t = tau.clone();
                    t[k] += eps;
                    let (_, gk) = solve(&t)?;
                    j.set_column(k, &((gk - &g) / eps));
                }
                j
            }
        };
        // The Newton step on the active rows and columns (inactive tensions held at 0).
        let idx: Vec<usize> = (0..held.len()).filter(|&k| active[k]).collect();
        let sub = DMatrix::from_fn(idx.len(), idx.len(), |a, b| j[(idx[a], idx[b])]);
        let rhs = DVector::from_fn(idx.len(), |a, _| -g[idx[a]]);
        let Some(step) = sub.lu().solve(&rhs) else {
            return Err(Error::NotConverged {
                what: "friction with displacement control: singular length Jacobian".into(),
                iterations: iteration,
                residual: worst,
                load_factor: 1.0,
            });
        };
        let mut next = tau.clone();
        for (a, &k) in idx.iter().enumerate() {
            next[k] = (tau[k] + step[a]).max(0.0);
        }
        let (s2, g2) = solve(&next)?;
        // Broyden's update of the Jacobian from the step taken.
        let dt = DVector::from_fn(held.len(), |k, _| next[k] - tau[k]);
        let dg = &g2 - &g;
        let denom = dt.dot(&dt);
        jac = Some(if denom > 0.0 {
            &j + (dg - &j * &dt) * dt.transpose() / denom
        } else {
            j
        });
        tau = next;
        sol = s2;
        g = g2;
    }
    Err(Error::NotConverged {
        what: format!(
            "friction with displacement control: the held tensions did not settle in \
             {HELD_MAX_ITERATIONS} iterations"
        ),
        iterations: HELD_MAX_ITERATIONS,
        residual: g.amax(),
        load_factor: 1.0,
    })
}
