//! The one nonlinear solver of softrod: damped Newton (or Broyden's update of the Jacobian)
//! with a backtracking line search under the Armijo condition, and load continuation with a
//! tangent or secant predictor. The Cosserat shooting and the PCC statics are [`Problem`]s;
//! inverse statics and contact plug in the same way.
//!
//! The pieces are small and separate, after argmin: a [`LineSearch`] proposes step lengths
//! and a [`Condition`] accepts them; [`newton`] runs the iteration at one load factor;
//! [`continuation`] steps the load factor from a solved state.

mod continuation;
mod newton;

pub use continuation::{continuation, ContinuationSettings, Continued, Stopped};
pub use newton::{newton, Armijo, Condition, LineSearch, NewtonOutcome, NewtonSettings};

use crate::error::{Error, Result};

/// Smallest load-factor increment of the continuation before giving up.
pub const MIN_LOAD_INCREMENT: f64 = 1e-4;

/// Options of the nonlinear solve (keyword arguments in Python), shared by every problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Tolerance on the problem's scaled residual (max norm), > 0.
    pub tolerance: f64,
    /// Newton iterations per solve (per load step under continuation), >= 1.
    pub max_iterations: usize,
    /// Whether to step the external loads when the direct solve fails or is refused.
    pub continuation: bool,
    /// Load steps (attempted) under continuation, >= 1.
    pub max_load_steps: usize,
    /// `true`: non-convergence is [`Error::NotConverged`]; `false`: the last iterate is
    /// returned with `stats.converged == false`.
    pub throw: bool,
}

impl NewtonOptions {
    /// Checks the options: a `tolerance` in `[ε, 1)` (ε the machine epsilon), at least one iteration
    /// and one load step, caps at most [`crate::limits::MAX_ITERATIONS`].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `tolerance`, `max_iterations` or `max_load_steps`.
    pub fn validate(&self) -> Result<()> {
        // The scaled residual is O(1) at the scale of the loads: below the machine epsilon a
        // tolerance asks for digits a double does not have.
        // At 1 or above, a residual as large as the loads would count as converged.
        if !(self.tolerance.is_finite() && self.tolerance >= f64::EPSILON && self.tolerance < 1.0) {
            return Err(Error::invalid(
                "tolerance",
                self.tolerance,
                format!(
                    "in [{:e}, 1): at least the machine epsilon, below the scale of the loads",
                    f64::EPSILON
                ),
            ));
        }
        use crate::limits::{check_count, MAX_ITERATIONS};
        check_count("max_iterations", self.max_iterations, 1, MAX_ITERATIONS)?;
        check_count("max_load_steps", self.max_load_steps, 1, MAX_ITERATIONS)?;
        Ok(())
    }
}

/// Statistics of a nonlinear solve (the same for every problem).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolverStats {
    /// Newton (or Broyden) iterations, over all load steps.
    pub iterations: usize,
    /// Final scaled residual (max norm, dimensionless).
    pub residual: f64,
    /// Residual evaluations (for the Cosserat shooting: right-hand-side evaluations).
    pub function_evaluations: usize,
    /// Whether the residual met the tolerance.
    pub converged: bool,
    /// Load steps taken by the continuation (0: solved directly).
    pub load_steps: usize,
    /// Fraction of the external loads the returned state carries: 1 when converged; for a
    /// non-converged result under continuation, the last load factor reached.
    pub load_factor: f64,
}

/// What an evaluation of a [`Problem`] produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Evaluated {
    /// The evaluation failed (non-finite state, a material failure): the point is rejected.
    Failed,
    /// The residual only.
    Residual,
    /// The residual and its Jacobian.
    Jacobian,
}

/// A square nonlinear system `r(x, λ) = 0` in scaled unknowns, `λ` the load factor.
pub trait Problem {
    /// Number of unknowns (and residuals).
    fn dim(&self) -> usize;
    /// Residual `r(x, λ)` into `r`; with `jacobian`, also `∂r/∂x` (column-major `dim × dim`).
    /// A problem may fill the Jacobian unasked when it is free (returning
    /// [`Evaluated::Jacobian`]).
    fn evaluate(
        &mut self,
        x: &[f64],
        lambda: f64,
        jacobian: Option<&mut [f64]>,
        r: &mut [f64],
    ) -> Evaluated;
    /// The norm the tolerance applies to, of the residual `r` of the last evaluation; the max
    /// norm by default.
    fn norm(&self, r: &[f64]) -> f64 {
        max_norm(r)
    }
    /// Tolerance on the norm of the residual at `x` (the option, or the resolution of the
    /// problem's discretisation).
    fn tolerance(&self, x: &[f64], tolerance: f64) -> f64 {
        let _ = x;
        tolerance
    }
    /// `∂r/∂λ` at `(x, λ)` into `out`, for the tangent predictor of the continuation; `false`
    /// when not available (a secant predictor is used).
    fn load_derivative(&mut self, _x: &[f64], _lambda: f64, _out: &mut [f64]) -> bool {
        false
    }
    /// Remembers the state of the last evaluation as the reference of [`Problem::close`].
    fn commit(&mut self) {}
    /// Whether the state of the last evaluation is close enough to the committed reference to
    /// stay on the same equilibrium branch (the continuation's safeguard); `true` by default.
    fn close(&self) -> bool {
        true
    }
    /// Whether what the problem checks at a solution `x` at load factor `lambda` (the
    /// stability of a rod) is already certified by an exact Jacobian evaluated near it, so
    /// that [`NewtonSettings::exact_at_solution`] need not evaluate one at `x`; `false` by
    /// default.
    fn certified(&mut self, x: &[f64], lambda: f64) -> bool {
        let _ = (x, lambda);
        false
    }
    /// Whether an exact Newton step below the rounding of the unknowns ([`ROUND_OFF_STEP`]
    /// units of the machine epsilon of `max(1, |x|∞)`) ends the solve as converged, at the
    /// residual it reached (at most [`ROUND_OFF_RESIDUAL`]): the residual is a smooth function of the unknowns whose Jacobian is
    /// exact, so that no representable point is closer to its root, and what remains is the
    /// round-off of its evaluation amplified by its sensitivity. `false` by default.
    fn stops_at_round_off(&self) -> bool {
        false
    }
}

/// Units of the machine epsilon (relative to `max(1, |x|∞)`) of an exact Newton step that
/// ends a solve whose problem [stops at round-off](Problem::stops_at_round_off).
pub const ROUND_OFF_STEP: f64 = 16.0;

/// Largest scaled residual a solve may end on at round-off: beyond it the residual's
/// sensitivity exceeds what double precision resolves (a soft rod hanging in gravity stops at
/// 1e-8 to 2e-6 and its answers converge with the mesh; longer ones stopped at 1e-2 to 11
/// centimetres off), and the solve is not converged.
pub const ROUND_OFF_RESIDUAL: f64 = 1e-5;

/// Max norm, infinite if any entry is not finite.
pub fn max_norm(v: &[f64]) -> f64 {
    let mut m = 0.0f64;
    for x in v {
        if !x.is_finite() {
            return f64::INFINITY;
        }
        m = m.max(x.abs());
    }
    m
}
