//! The options of a Cosserat solve: the integrator, the Newton options, the warm start, and
//! the defaults and limits they are checked against.

use nalgebra::Matrix6;

use crate::error::{Error, Result};
use crate::integrate::AdaptiveOptions;
use crate::solve::NewtonOptions;

/// Default number of RK4 steps over the whole rod (split among the intervals in proportion
/// to their length, at least one each).
pub const DEFAULT_RK4_STEPS: usize = 40;
/// Largest accepted number of RK4 steps (the mesh is stored).
pub const MAX_RK4_STEPS: usize = 10_000_000;
/// Default tolerance on the scaled shooting residual (max norm).
pub const DEFAULT_TOLERANCE: f64 = 1e-10;
/// Default cap on Newton iterations per solve (per load step under continuation).
pub const DEFAULT_MAX_ITERATIONS: usize = 30;
/// Default cap on load steps under continuation.
pub const DEFAULT_MAX_LOAD_STEPS: usize = 64;
/// Most step halvings of the Newton line search.
pub const MAX_LINE_SEARCH_HALVINGS: usize = 12;
/// Largest predictor step (max norm of the scaled base wrench, about the bending in rad it
/// predicts) taken directly when continuation is enabled; beyond it the load is stepped, so
/// that the solution stays on the equilibrium branch connected to the unloaded rod.
pub const DIRECT_STEP_LIMIT: f64 = 4.0;
/// Largest change of the shape per continuation step: rotation in rad at any mesh node (and
/// half of it, in units of the rod length, in position). Larger jumps may switch equilibrium
/// branch, so the step is halved.
pub const MAX_LOAD_STEP_TURN: f64 = 1.0;

/// Ratio of the RK4 steps of a solve to those of its coarse mesh (RK4 of at least 40 steps).
pub const COARSE_RATIO: usize = 5;
/// Fewest RK4 steps of a coarse mesh.
pub const MIN_COARSE_STEPS: usize = 8;
/// Newton tolerance on the coarse mesh (at least the one asked): below the difference of the
/// two meshes' residuals (2.6e-5 on the NiTi robot pressing a sphere, 3e-6 to 7e-5 under tip
/// loads), which Newton on the mesh asked removes; converging the coarse mesh further only
/// adds coarse passes.
pub const COARSE_TOLERANCE: f64 = 1e-5;

/// The ODE integrator used by the shooting method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    /// Classical RK4 with `steps` equal-length steps over `[0, L]` in total (each interval
    /// between breaks gets `max(1, round(steps * length / L))`).
    Rk4 {
        /// Total number of steps (>= 1).
        steps: usize,
    },
    /// Adaptive Dormand–Prince 5(4) with error control on `(p, R, N, M)`.
    Adaptive(AdaptiveOptions),
}

impl Integrator {
    /// The coarse mesh on which a loaded or contact solve runs its nonlinear iterations
    /// before Newton on this one: RK4 with a fifth of the steps (at least
    /// [`MIN_COARSE_STEPS`]); `None` (no coarse mesh) for fewer steps or the adaptive
    /// integrator.
    pub(crate) fn coarse(self) -> Option<Integrator> {
        match self {
            Integrator::Rk4 { steps } if steps >= COARSE_RATIO * MIN_COARSE_STEPS => {
                Some(Integrator::Rk4 {
                    steps: steps / COARSE_RATIO,
                })
            }
            _ => None,
        }
    }

    /// Whether this is the default mesh ([`DEFAULT_RK4_STEPS`] RK4 steps), which a solve under
    /// mesh control refines itself (see [`crate::cosserat::mesh`]); any other is chosen.
    pub fn is_default_mesh(&self) -> bool {
        *self == Integrator::default()
    }
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator::Rk4 {
            steps: DEFAULT_RK4_STEPS,
        }
    }
}

/// A starting point for the shooting unknowns, taken from a previous solution (the tensions
/// of its displacement-controlled tendons go into [`Actuation::tension_guess`](crate::Actuation::tension_guess)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WarmStart {
    /// Total base wrench `[N(0); M(0)]` (N, N m; world frame) including the tendons' share.
    pub base_wrench: [f64; 6],
    /// The shooting Jacobian (scaled unknowns and residual) at that solution, if known: the
    /// first Jacobian of the new solve.
    pub jacobian: Option<Matrix6<f64>>,
    /// The coarse mesh's residual at that solution, if it was solved from a coarse mesh: the
    /// new solve's coarse iterations subtract it, so that they land near the solution on the
    /// mesh asked rather than near the coarse one.
    pub coarse_defect: Option<CoarseDefect>,
}

/// The scaled shooting residual of a coarse mesh (RK4 with [`COARSE_RATIO`] times fewer steps) at a solution on
/// the mesh asked: the integration error that separates the two meshes' solutions, which
/// changes little from one solve to a nearby one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoarseDefect {
    /// RK4 steps of the coarse mesh.
    pub steps: usize,
    /// The coarse residual at the solution (dimensionless, as the shooting residual).
    pub residual: [f64; 6],
}

impl WarmStart {
    /// A warm start from a base wrench alone.
    pub fn wrench(base_wrench: [f64; 6]) -> Self {
        Self {
            base_wrench,
            jacobian: None,
            coarse_defect: None,
        }
    }
}

/// Options of [`solve_statics`](crate::solve_statics) (keyword arguments in Python).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// ODE integrator.
    pub integrator: Integrator,
    /// Nonlinear solve. The tolerance is on the scaled shooting residual; with the adaptive
    /// integrator it is only resolved down to the integration error, `10 rtol (1 + |x|)`.
    pub newton: NewtonOptions,
    /// Initial guess of the base wrench; `None` starts from the unloaded rod.
    pub warm_start: Option<WarmStart>,
    /// When the equilibrium reached is unstable, search for a stable one (smaller load steps
    /// from the unloaded rod, then along the unstable mode) and return it if found.
    pub seek_stable: bool,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            integrator: Integrator::default(),
            newton: NewtonOptions {
                tolerance: DEFAULT_TOLERANCE,
                max_iterations: DEFAULT_MAX_ITERATIONS,
                continuation: true,
                max_load_steps: DEFAULT_MAX_LOAD_STEPS,
                throw: true,
            },
            warm_start: None,
            seek_stable: true,
        }
    }
}

impl SolveOptions {
    /// Checks the options.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `integrator.steps`, `rtol`, `atol`, `max_steps`,
    /// `tolerance`, `max_iterations`, `max_load_steps` or `warm_start.base_wrench[k]`.
    pub fn validate(&self) -> Result<()> {
        match self.integrator {
            Integrator::Rk4 { steps } => {
                if steps == 0 || steps > MAX_RK4_STEPS {
                    return Err(Error::invalid(
                        "integrator.steps",
                        steps,
                        format!("in [1, {MAX_RK4_STEPS}]"),
                    ));
                }
            }
            Integrator::Adaptive(a) => {
                a.validated()?;
            }
        }
        self.newton.validate()?;
        if let Some(w) = &self.warm_start {
            for (k, v) in w.base_wrench.iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::invalid(
                        format!("warm_start.base_wrench[{k}]"),
                        v,
                        "finite",
                    ));
                }
            }
        }
        Ok(())
    }
}
