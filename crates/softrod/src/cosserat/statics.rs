//! Steady-state shape of a Cosserat rod with tendons, chambers and external loads, by shooting.
//!
//! [`solve_statics`] finds the total base wrench `(N(0), M(0))` (world frame) that meets the
//! tip conditions ([`super::shooting`]). The actuation is always applied in full: with the
//! total-wrench form a tendon or a chamber adds nothing to the base wrench, so the actuated,
//! unloaded rod is solved exactly by a zero base wrench in one pass. The external loads are
//! then applied along the load factor `λ` from 0 to 1: first directly, from the exact tangent
//! predictor `dx/dλ = -J⁻¹ ∂r/∂λ` at the unloaded rod, with Broyden updates of the Jacobian
//! between exact evaluations; if that fails, or the predictor step is larger than
//! [`DIRECT_STEP_LIMIT`] (a strongly nonlinear problem, where Newton may land on another
//! equilibrium branch), by continuation in `λ`, refusing load steps that change the shape by
//! more than [`MAX_LOAD_STEP_TURN`], so that the solution found is the one connected to the
//! unloaded, actuated rod. The ODE is integrated between the breaks at tendon terminations,
//! chamber ends and point loads with fixed-step RK4 (the seed's method) or the adaptive
//! Dormand–Prince 5(4) pair; rotation matrices are re-orthonormalised after every step.

use std::sync::Arc;

use nalgebra::{Matrix3, Matrix6, Vector3};

use super::equations::{rot, v3, Equations, Evaluator, Workspace};
use super::shooting::{Node, Shooting};
use crate::error::{Error, Result};
use crate::integrate::march::rk4_plan;
use crate::integrate::AdaptiveOptions;
use crate::math::so3::quaternion_xyzw;
use crate::model::{Actuation, RobotModel};
use crate::solve::{
    continuation, max_norm, newton, Armijo, ContinuationSettings, Evaluated, LineSearch,
    NewtonOptions, NewtonOutcome, NewtonSettings, Problem, SolverStats,
};

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

impl Default for Integrator {
    fn default() -> Self {
        Integrator::Rk4 {
            steps: DEFAULT_RK4_STEPS,
        }
    }
}

/// A starting point for the shooting unknowns, taken from a previous solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WarmStart {
    /// Total base wrench `[N(0); M(0)]` (N, N m; world frame) including the tendons' share.
    pub base_wrench: [f64; 6],
    /// The shooting Jacobian (scaled unknowns and residual) at that solution, if known: the
    /// first Jacobian of the new solve.
    pub jacobian: Option<Matrix6<f64>>,
}

impl WarmStart {
    /// A warm start from a base wrench alone.
    pub fn wrench(base_wrench: [f64; 6]) -> Self {
        Self {
            base_wrench,
            jacobian: None,
        }
    }
}

/// Options of [`solve_statics`] (keyword arguments in Python).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// ODE integrator.
    pub integrator: Integrator,
    /// Nonlinear solve. The tolerance is on the scaled shooting residual; with the adaptive
    /// integrator it is only resolved down to the integration error, `10 rtol (1 + |x|)`.
    pub newton: NewtonOptions,
    /// Initial guess of the base wrench; `None` starts from the unloaded rod.
    pub warm_start: Option<WarmStart>,
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

/// A solved rod, sampled at the integration mesh, with the model, actuation and options it
/// was solved with (so that [`crate::compliance::compliance`] and
/// [`crate::compliance::tangent_compliance`] need nothing else).
///
/// Every array has one entry per sample. At an interval break (tendon termination, point
/// load) the sample appears twice with the same `s`: the values just before and just after
/// the jump. Vectors are `[x, y, z]`; rotations are body → world matrices; quaternions are
/// scalar-last `[x, y, z, w]` with `w >= 0`.
#[derive(Debug, Clone)]
pub struct StaticsSolution {
    /// Undeformed arc length (m).
    pub s: Vec<f64>,
    /// Backbone position (m, world), shape (N, 3).
    pub position: Vec<[f64; 3]>,
    /// Rotation body → world, row-major, shape (N, 3, 3).
    pub rotation: Vec<[[f64; 3]; 3]>,
    /// Orientation quaternion `[x, y, z, w]`, shape (N, 4).
    pub quaternion: Vec<[f64; 4]>,
    /// Rod's internal force `n` (N, world), excluding the tendons' tension.
    pub n_world: Vec<[f64; 3]>,
    /// Rod's internal moment `m` (N m, world).
    pub m_world: Vec<[f64; 3]>,
    /// Rod's internal force `n` in body components (N).
    pub n_body: Vec<[f64; 3]>,
    /// Rod's internal moment `m` in body components (N m).
    pub m_body: Vec<[f64; 3]>,
    /// Shear/stretch strain `v` (body, dimensionless; `(0, 0, 1)` undeformed).
    pub v: Vec<[f64; 3]>,
    /// Bending/twist strain `u` (body, 1/m per undeformed length).
    pub u: Vec<[f64; 3]>,
    /// Path length of each tendon from the base to its termination (m), `∫ |p_i'| ds`.
    pub tendon_lengths: Vec<f64>,
    /// Total base wrench (rod + tendons), for [`SolveOptions::warm_start`].
    pub base_wrench: [f64; 6],
    /// Solver statistics.
    pub stats: SolverStats,
    /// The model solved.
    pub model: Arc<RobotModel>,
    /// The actuation it was solved for.
    pub actuation: Actuation,
    /// The options it was solved with.
    pub options: SolveOptions,
    /// The (exact or updated) shooting Jacobian at the solution, in scaled unknowns.
    pub jacobian: Option<Matrix6<f64>>,
}

impl StaticsSolution {
    /// Tip position (m, world).
    pub fn tip_position(&self) -> [f64; 3] {
        self.position.last().copied().unwrap_or([f64::NAN; 3])
    }

    /// Warm start for a nearby problem (base wrench and Jacobian).
    pub fn warm_start(&self) -> WarmStart {
        WarmStart {
            base_wrench: self.base_wrench,
            jacobian: self.jacobian,
        }
    }

    /// Tension of every tendon (N).
    pub fn tensions(&self) -> Vec<f64> {
        self.actuation.tension_values(self.model.tendons().len())
    }

    /// Pressure of every chamber (Pa).
    pub fn pressures(&self) -> Vec<f64> {
        self.actuation.pressure_values(self.model.chambers().len())
    }
}

/// Newton settings of the shooting. Broyden's update of the Jacobian is used with the fixed
/// RK4 mesh (the residual is then a smooth function of the unknowns); with the adaptive
/// integrator the residual carries the integration error and exact Jacobians are evaluated.
fn settings(broyden: bool, jacobian: Option<&[f64]>) -> NewtonSettings<'_> {
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
    }
}

/// The direct solve at full load: from the warm start, or from the tangent predictor at the
/// unloaded rod. Returns the outcome and, for a cold start, the unloaded Jacobian and the
/// size of a predictor step refused by the step limit.
fn direct(
    p: &mut Shooting<'_>,
    options: &SolveOptions,
    x0: &[f64; 6],
) -> (NewtonOutcome, Option<Vec<f64>>, f64) {
    let opts = &options.newton;
    let limit = opts.continuation.then_some(DIRECT_STEP_LIMIT);
    let broyden = matches!(options.integrator, Integrator::Rk4 { .. });
    let settings = |_: bool, j| settings(broyden, j);
    if let Some(w) = &options.warm_start {
        let j = w.jacobian.map(|m| m.as_slice().to_vec());
        let s = NewtonSettings {
            first_step_limit: limit,
            residual_first: true,
            ..settings(true, j.as_deref())
        };
        return (newton(p, x0, 1.0, opts, &s), None, 0.0);
    }
    if p.eq.model.loads().is_unloaded() {
        // Nothing to apply: x = 0 solves the actuated rod exactly.
        let s = NewtonSettings {
            residual_first: true,
            ..settings(true, None)
        };
        return (newton(p, x0, 1.0, opts, &s), None, 0.0);
    }
    // The unloaded, actuated rod: x = 0 is exact at λ = 0, its Jacobian is closed form.
    let mut r = [0.0; 6];
    let mut j0 = vec![0.0; 36];
    if p.evaluate(x0, 0.0, Some(&mut j0), &mut r) != Evaluated::Jacobian {
        let s = NewtonSettings {
            residual_first: true,
            ..settings(true, None)
        };
        return (newton(p, x0, 1.0, opts, &s), None, 0.0);
    }
    let mut drdl = [0.0; 6];
    let mut guess = *x0;
    if p.load_derivative(x0, 0.0, &mut drdl) {
        let mut lu = crate::math::linalg::DenseLu::default();
        let mut t = drdl.map(|v| -v);
        if lu.factor(6, &j0) && lu.solve_in_place(&mut t) {
            let step = max_norm(&t);
            if limit.is_some_and(|l| step > l) {
                let refused = NewtonOutcome {
                    x: x0.to_vec(),
                    residual: f64::INFINITY,
                    converged: false,
                    iterations: 0,
                    first_step: step,
                    jacobian: None,
                    at_x: false,
                };
                return (refused, Some(j0), step);
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
        ..settings(true, None)
    };
    let mut out = newton(p, &guess, 1.0, opts, &s);
    if !out.converged && !out.residual.is_finite() && guess != *x0 {
        // The predictor left the domain of the equations: Newton from the unloaded rod.
        let s = NewtonSettings {
            first_step_limit: limit,
            ..settings(true, Some(&j0))
        };
        out = newton(p, x0, 1.0, opts, &s);
    }
    let first = out.first_step;
    (out, Some(j0), first)
}

/// Solves the statics of `model` under `actuation` (`solve_statics(rod, tendons=(),
/// loads=None, ...)` in Python, which builds both).
///
/// # Errors
/// [`Error::InvalidParameter`] naming the offending input (`tensions[i]`, `pressures[i]`,
/// their counts, options); [`Error::NotConverged`] with the iterations and final scaled
/// residual if the shooting does not converge and `options.newton.throw` is true, unless a
/// hyperelastic material failed on the way: then [`Error::InvalidParameter`] naming `stretch`
/// (a fibre compressed to zero length) or the law's parameters (a law that is not monotonic at
/// the stretches reached).
pub fn solve_statics(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
) -> Result<StaticsSolution> {
    options.validate()?;
    let (nt, nc) = (model.tendons().len(), model.chambers().len());
    actuation.validate(nt, nc)?;
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
    };
    let mut p = Shooting::new(eq, options.integrator, plan);
    let f_ref = model.force_scale();
    let fm = f_ref * model.length();
    let x0 = match &options.warm_start {
        Some(w) => {
            let b = &w.base_wrench;
            [
                b[0] / f_ref,
                b[1] / f_ref,
                b[2] / f_ref,
                b[3] / fm,
                b[4] / fm,
                b[5] / fm,
            ]
        }
        None => [0.0; 6],
    };
    let opts = &options.newton;
    let mut stats = SolverStats {
        load_factor: 1.0,
        ..SolverStats::default()
    };
    let (mut result, j0, first_step) = direct(&mut p, options, &x0);
    stats.iterations = result.iterations;
    if !result.converged && opts.continuation {
        result = step_loads(&mut p, options, j0, first_step, &mut stats);
    }
    // The recorded pass must be the one at the returned unknowns (and their load factor).
    if !result.at_x {
        let mut r = [0.0; 6];
        if p.evaluate(&result.x, stats.load_factor, None, &mut r) != Evaluated::Failed
            && !result.converged
            && stats.load_factor >= 1.0
        {
            result.residual = max_norm(&r);
        }
    }
    stats.residual = result.residual;
    stats.converged = result.converged;
    stats.function_evaluations = p.evaluations;
    if !result.converged && opts.throw {
        if let Some(e) = p.ws.material_error.take() {
            return Err(e);
        }
        return Err(Error::NotConverged {
            what: "shooting Newton (Cosserat rod statics)".into(),
            iterations: stats.iterations,
            residual: result.residual,
        });
    }
    let x = &result.x;
    let base_wrench = [
        x[0] * f_ref,
        x[1] * f_ref,
        x[2] * f_ref,
        x[3] * fm,
        x[4] * fm,
        x[5] * fm,
    ];
    let jacobian = result
        .jacobian
        .as_ref()
        .map(|j| Matrix6::from_column_slice(j));
    let mut sol = assemble(&mut p, model, base_wrench, stats);
    sol.actuation = actuation.clone();
    sol.options = *options;
    sol.jacobian = jacobian;
    Ok(sol)
}

/// Steps the external loads from the unloaded rod (x = 0 is exact at λ = 0) by continuation,
/// from the refused predictor step `first_step` (0: none); the steps taken go into `stats`.
fn step_loads(
    p: &mut Shooting<'_>,
    options: &SolveOptions,
    j0: Option<Vec<f64>>,
    first_step: f64,
    stats: &mut SolverStats,
) -> NewtonOutcome {
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
    };
    let start = ContinuationSettings {
        x0: &zero,
        jacobian0: j0.as_deref(),
        first_increment: first,
        max_increment: 0.5,
    };
    let s = NewtonSettings {
        first_step_limit: Some(DIRECT_STEP_LIMIT),
        ..settings(matches!(options.integrator, Integrator::Rk4 { .. }), None)
    };
    let c = continuation(p, &start, &options.newton, &s);
    stats.iterations += c.iterations;
    stats.load_steps = c.steps;
    stats.load_factor = c.load_factor;
    c.outcome
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn rows(r: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [r[(0, 0)], r[(0, 1)], r[(0, 2)]],
        [r[(1, 0)], r[(1, 1)], r[(1, 2)]],
        [r[(2, 0)], r[(2, 1)], r[(2, 2)]],
    ]
}

/// Derived quantities at the recorded nodes of the last pass (which is at the solution).
fn assemble(
    p: &mut Shooting<'_>,
    shared: &Arc<RobotModel>,
    base_wrench: [f64; 6],
    stats: SolverStats,
) -> StaticsSolution {
    let n = p.nodes.len();
    let model = p.eq.model;
    let mut sol = StaticsSolution {
        s: Vec::with_capacity(n),
        position: Vec::with_capacity(n),
        rotation: Vec::with_capacity(n),
        quaternion: Vec::with_capacity(n),
        n_world: Vec::with_capacity(n),
        m_world: Vec::with_capacity(n),
        n_body: Vec::with_capacity(n),
        m_body: Vec::with_capacity(n),
        v: Vec::with_capacity(n),
        u: Vec::with_capacity(n),
        tendon_lengths: p.lengths.clone(),
        base_wrench,
        stats,
        model: Arc::clone(shared),
        actuation: Actuation::default(),
        options: SolveOptions::default(),
        jacobian: None,
    };
    let mut ws = Workspace::new(model.tendons().len());
    let mut ev = Evaluator {
        eq: p.eq,
        ws: &mut ws,
    };
    let rk4 = matches!(p.integrator, Integrator::Rk4 { .. });
    if sol.tendon_lengths.len() != model.tendons().len() {
        // The last pass failed before its lengths (a non-converged result): none to report.
        sol.tendon_lengths = vec![f64::NAN; model.tendons().len()];
    }
    if rk4 {
        sol.tendon_lengths.iter_mut().for_each(|l| *l = 0.0);
    }
    ev.ws.track_lengths = true;
    let nt = model.tendons().len();
    // Tendon speeds |p_i'| at the nodes of the current interval (RK4: Simpson on the nodes).
    let mut speeds: Vec<Vec<f64>> = vec![Vec::new(); nt];
    let mut current = usize::MAX;
    let nodes: &[Node] = &p.nodes;
    for (j, node) in nodes.iter().enumerate() {
        if node.interval != current {
            ev.set_interval(node.interval);
            current = node.interval;
            speeds.iter_mut().for_each(Vec::clear);
        }
        let y = &node.y;
        let r = rot(y);
        let nb_tot = r.tr_mul(&v3(y, 12));
        let mb_tot = r.tr_mul(&v3(y, 15));
        let props = model.rod().section_at(node.s);
        let loc = ev.local(node.s, &props, &nb_tot, &mb_tot, false);
        let nb = nb_tot - loc.tendon_force;
        let mb = mb_tot - loc.tendon_moment;
        sol.s.push(node.s);
        sol.position.push(arr(&v3(y, 0)));
        sol.rotation.push(rows(&r));
        sol.quaternion.push(quaternion_xyzw(&r));
        sol.n_world.push(arr(&(r * nb)));
        sol.m_world.push(arr(&(r * mb)));
        sol.n_body.push(arr(&nb));
        sol.m_body.push(arr(&mb));
        sol.v.push(arr(&loc.v));
        sol.u.push(arr(&loc.u));
        if rk4 && nt > 0 {
            let k = node.interval;
            let b = model.breaks()[k + 1];
            for (i, &end) in model.tendon_ends().iter().enumerate() {
                if end >= b {
                    speeds[i].push(ev.ws.tendon_speed[i]);
                }
            }
            let last_of_interval = nodes.get(j + 1).is_none_or(|n| n.interval != k);
            if last_of_interval {
                let count = nodes.iter().filter(|n| n.interval == k).count();
                let h = (b - model.breaks()[k]) / (count - 1).max(1) as f64;
                for (i, sp) in speeds.iter().enumerate() {
                    if !sp.is_empty() {
                        sol.tendon_lengths[i] += uniform_quadrature(sp, h);
                    }
                }
            }
        }
    }
    sol
}

/// Fourth-order quadrature of samples `f` on a uniform grid of spacing `h`: composite Simpson,
/// with Simpson's 3/8 rule on the last three panels when the number of panels is odd
/// (trapezoid for a single panel).
fn uniform_quadrature(f: &[f64], h: f64) -> f64 {
    let panels = f.len().saturating_sub(1);
    match panels {
        0 => 0.0,
        1 => 0.5 * h * (f[0] + f[1]),
        _ => {
            let simpson_end = if panels % 2 == 0 { panels } else { panels - 3 };
            let mut sum = 0.0;
            let mut i = 0;
            while i < simpson_end {
                sum += h / 3.0 * (f[i] + 4.0 * f[i + 1] + f[i + 2]);
                i += 2;
            }
            if simpson_end < panels {
                let k = simpson_end;
                sum += 3.0 * h / 8.0 * (f[k] + 3.0 * f[k + 1] + 3.0 * f[k + 2] + f[k + 3]);
            }
            sum
        }
    }
}
