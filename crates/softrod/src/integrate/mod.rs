//! Ordinary-differential-equation integration shared by every model: one explicit
//! Runge–Kutta driver, three tableaus, one step-size controller, one march over breaks.
//!
//! * [`tableau`]: classical RK4, Bogacki–Shampine 3(2) (MATLAB's `ode23`) and
//!   Dormand–Prince 5(4), each with its embedded error weights and dense output;
//! * [`driver`]: fixed steps or adaptive steps (error per component below
//!   `atol + rtol max(|y_n|, |y_{n+1}|)`, max norm, local extrapolation, FSAL), projection
//!   after every accepted step, quadratures riding on the stages, dense output;
//! * [`march`]: integration of a piecewise system interval by interval between breaks
//!   (tendon terminations, chamber ends, point loads) with jumps at the breaks and an
//!   observer of the nodes: the one march of the Cosserat statics, the compliance and the
//!   tangent compliance.
//!
//! States are fixed-size arrays `[f64; N]` so the compiler can keep them in registers.
//!
//! # References
//! P. Bogacki, L. F. Shampine, "A 3(2) pair of Runge–Kutta formulas",
//! Appl. Math. Lett. 2(4), 1989. J. R. Dormand, P. J. Prince, J. Comput. Appl. Math. 6(1),
//! 1980. E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*,
//! 2nd ed., Springer 1993, II.4–6. L. F. Shampine, M. W. Reichelt, "The MATLAB ODE suite",
//! SIAM J. Sci. Comput. 18(1), 1997.

pub mod driver;
pub mod march;
pub mod tableau;

pub use driver::{adaptive, fixed, DenseSolution, FnSystem, System};
pub use tableau::{Tableau, BS3, DP5, RK4};

use crate::error::{Error, Result};

/// Default relative tolerance of the adaptive integrators.
pub const DEFAULT_RTOL: f64 = 1e-8;
/// Default absolute tolerance of the adaptive integrators (in the state's own units).
pub const DEFAULT_ATOL: f64 = 1e-10;
/// Default cap on the number of attempted steps of one adaptive integration.
pub const DEFAULT_MAX_STEPS: usize = 100_000;

/// Options of an adaptive integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveOptions {
    /// Relative tolerance (> 0): per component, the local error estimate is kept below
    /// `atol + rtol * |y|`.
    pub rtol: f64,
    /// Absolute tolerance (> 0), in the units of the state.
    pub atol: f64,
    /// Maximum number of attempted steps before [`Error::NotConverged`].
    pub max_steps: usize,
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        Self {
            rtol: DEFAULT_RTOL,
            atol: DEFAULT_ATOL,
            max_steps: DEFAULT_MAX_STEPS,
        }
    }
}

impl AdaptiveOptions {
    /// Validates the tolerances.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-finite or non-positive `rtol`/`atol`, an `rtol`
    /// below 100 machine epsilons, or `max_steps == 0`.
    pub fn validated(self) -> Result<Self> {
        if !(self.rtol.is_finite() && self.rtol >= 100.0 * f64::EPSILON && self.rtol < 1.0) {
            return Err(Error::invalid("rtol", self.rtol, "in [2.2e-14, 1)"));
        }
        if !(self.atol.is_finite() && self.atol > 0.0) {
            return Err(Error::invalid("atol", self.atol, "finite and > 0"));
        }
        crate::limits::check_count(
            "max_steps",
            self.max_steps,
            1,
            crate::limits::MAX_ITERATIONS,
        )?;
        Ok(self)
    }
}

/// Statistics of one adaptive integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct IntegrationStats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
}
