//! Steady-state shape of a Cosserat rod with tendons and external loads, by shooting.
//!
//! [`solve_statics`] finds the unknown total base wrench `(N(0), M(0))` (world frame) such that
//! the integrated internal wrench matches the tip loads, with damped Newton iterations on an
//! exact Jacobian (variational equations integrated with the state, see `cosserat.rs`). If the
//! direct solve fails, or its first Newton step is larger than [`DIRECT_STEP_LIMIT`] (a strongly
//! nonlinear problem, where Newton may land on an unstable equilibrium branch such as a looped
//! elastica), it restarts from the unloaded rod and steps the load factor from 0 to 1
//! (continuation with a secant predictor), refusing load steps that change the shape by more
//! than [`MAX_LOAD_STEP_TURN`], so that the solution found is the one connected to the
//! unloaded rod. The ODE is integrated piecewise between the breaks at tendon terminations
//! and point loads, either with fixed-step RK4 (the seed's method) or with the adaptive
//! Dormand–Prince 5(4) pair; rotation matrices are re-orthonormalised after every step.
//!
//! The Newton residual and unknowns are scaled by `F = E I(0) / L²` (forces) and `F L`
//! (moments), so [`SolveOptions::tolerance`] is dimensionless: a residual `ε` leaves a tip
//! error of about `ε L / 3`.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::cosserat::equations::{rot, v3, ActiveTendon, Evaluator, Model, FULL, STATE};
use crate::error::{check_newton_options, Error, Result};
use crate::integrate::{dp54, rk4_step_in_place, AdaptiveOptions, Rk4Workspace};
use crate::model::loads::{Frame, Loads};
use crate::model::rod::Rod;
use crate::math::so3::{hat, quaternion_xyzw, reorthonormalise};
use crate::model::tendon::Tendon;

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
/// Sufficient-decrease constant of the line search (Armijo, on the residual norm).
pub const ARMIJO: f64 = 1e-4;
/// Largest first Newton step (max norm of the scaled base wrench, about the bending in rad it
/// predicts) taken directly when continuation is enabled; beyond it the load is stepped, so
/// that the solution stays on the equilibrium branch connected to the unloaded rod.
pub const DIRECT_STEP_LIMIT: f64 = 4.0;
/// Largest change of the shape per continuation step: rotation in rad at any mesh node (and
/// half of it, in units of the rod length, in position). Larger jumps may switch equilibrium
/// branch, so the step is halved.
pub const MAX_LOAD_STEP_TURN: f64 = 1.0;
/// Smallest load-factor increment of the continuation before giving up.
pub const MIN_LOAD_INCREMENT: f64 = 1e-4;

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
}

/// Options of [`solve_statics`] (keyword arguments in Python).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// ODE integrator.
    pub integrator: Integrator,
    /// Tolerance on the scaled residual (max norm), > 0. With the adaptive integrator the
    /// residual is only resolved down to the integration error, `10 rtol (1 + |x|)`.
    pub tolerance: f64,
    /// Newton iterations per solve (per load step), >= 1.
    pub max_iterations: usize,
    /// Whether to fall back on load stepping when the direct solve fails.
    pub continuation: bool,
    /// Load steps (attempted) under continuation, >= 1.
    pub max_load_steps: usize,
    /// Initial guess of the base wrench; `None` starts from zero (the unloaded rod).
    pub warm_start: Option<WarmStart>,
    /// `true`: non-convergence is [`Error::NotConverged`]; `false`: the last iterate is
    /// returned with `stats.converged == false`.
    pub throw: bool,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            integrator: Integrator::default(),
            tolerance: DEFAULT_TOLERANCE,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            continuation: true,
            max_load_steps: DEFAULT_MAX_LOAD_STEPS,
            warm_start: None,
            throw: true,
        }
    }
}

/// Solver statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverStats {
    /// Newton iterations (accepted steps), over all load steps.
    pub iterations: usize,
    /// Final scaled residual (max norm, dimensionless).
    pub residual: f64,
    /// Right-hand-side evaluations.
    pub function_evaluations: usize,
    /// Whether the residual met the tolerance.
    pub converged: bool,
    /// Load steps taken by the continuation (0: solved directly).
    pub load_steps: usize,
    /// Fraction of the loads (and tensions) the returned shape carries: 1 when converged; for
    /// a non-converged result under continuation, the last load factor reached.
    pub load_factor: f64,
}

/// A solved rod, sampled at the integration mesh.
///
/// Every array has one entry per sample. At an interval break (tendon termination, point
/// load) the sample appears twice with the same `s`: the values just before and just after
/// the jump. Vectors are `[x, y, z]`; rotations are body → world matrices; quaternions are
/// scalar-last `[x, y, z, w]` with `w >= 0`.
#[derive(Debug, Clone, PartialEq)]
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
}

impl StaticsSolution {
    /// Tip position (m, world).
    pub fn tip_position(&self) -> [f64; 3] {
        self.position.last().copied().unwrap_or([f64::NAN; 3])
    }

    /// Warm start for a nearby problem.
    pub fn warm_start(&self) -> WarmStart {
        WarmStart {
            base_wrench: self.base_wrench,
        }
    }
}

/// A recorded mesh node.
#[derive(Clone, Copy)]
struct Node {
    s: f64,
    interval: usize,
    y: [f64; STATE],
}

/// Per-interval step counts of the RK4 plan.
pub(crate) fn rk4_plan(breaks: &[f64], steps: usize) -> Vec<usize> {
    let l = breaks[breaks.len() - 1];
    breaks
        .windows(2)
        .map(|w| ((steps as f64 * (w[1] - w[0]) / l).round() as usize).max(1))
        .collect()
}

fn head(y: &[f64]) -> [f64; STATE] {
    let mut h = [0.0; STATE];
    h.copy_from_slice(&y[..STATE]);
    h
}

pub(crate) fn project<const N: usize>(y: &mut [f64; N]) {
    let r = reorthonormalise(&rot(y));
    y[3..12].copy_from_slice(r.as_slice());
}

/// The outcome of one shooting pass.
struct Pass {
    residual: Vector6<f64>,
    jacobian: Option<Matrix6<f64>>,
    /// Chord `p(L) - p(0)` (m, world).
    chord: Vector3<f64>,
}

/// Scratch shared by the passes of one solve.
struct Workspace {
    nodes: Vec<Node>,
    tendon_lengths: Vec<f64>,
}

/// Integrates from the base with unknowns `x` over all intervals, recording nodes.
fn shoot<const N: usize>(
    ev: &mut Evaluator<'_, '_>,
    x: &Vector6<f64>,
    integrator: &Integrator,
    plan: &[usize],
    ws: &mut Workspace,
) -> Result<Pass> {
    let model = ev.model;
    let breaks = &model.breaks;
    ws.nodes.clear();
    ws.tendon_lengths.iter_mut().for_each(|l| *l = 0.0);
    let mut y: [f64; N] = model.initial(x);
    let mut rk = Rk4Workspace::<N>::default();
    for k in 0..breaks.len() - 1 {
        let (a, b) = (breaks[k], breaks[k + 1]);
        ev.set_interval(k);
        ws.nodes.push(Node {
            s: a,
            interval: k,
            y: head(&y),
        });
        match integrator {
            Integrator::Rk4 { .. } => {
                let n = plan[k];
                let h = (b - a) / n as f64;
                for i in 0..n {
                    let t = a + h * i as f64;
                    let mut f = |s: f64, yy: &[f64; N], dy: &mut [f64; N]| ev.rhs_into(s, yy, dy);
                    rk4_step_in_place(&mut f, t, &mut y, h, &mut rk);
                    project(&mut y);
                    if !y[..STATE].iter().all(|v| v.is_finite()) {
                        return Err(Error::NotConverged {
                            what: "rod integration: non-finite state".into(),
                            iterations: i,
                            residual: f64::INFINITY,
                        });
                    }
                    ws.nodes.push(Node {
                        s: if i + 1 == n { b } else { t + h },
                        interval: k,
                        y: head(&y),
                    });
                }
            }
            Integrator::Adaptive(opts) => {
                let sol = dp54(
                    |s, yy: &[f64; N]| ev.rhs(s, yy),
                    a,
                    y,
                    b,
                    *opts,
                    STATE,
                    project,
                )?;
                // Tendon lengths: 3-point Gauss–Legendre on each step with the dense output.
                const G: [(f64, f64); 3] = [
                    (0.112_701_665_379_258_31, 5.0 / 18.0),
                    (0.5, 8.0 / 18.0),
                    (0.887_298_334_620_741_7, 5.0 / 18.0),
                ];
                ev.track_speeds = true;
                for i in 1..sol.t.len() {
                    let (t0, t1) = (sol.t[i - 1], sol.t[i]);
                    if !ws.tendon_lengths.is_empty() {
                        for (c, wg) in G {
                            let s = t0 + c * (t1 - t0);
                            let yy = sol.eval(s);
                            let r = rot(&yy);
                            let props = model.rod.section_at(s);
                            let nb = r.tr_mul(&v3(&yy, 12));
                            let mb = r.tr_mul(&v3(&yy, 15));
                            ev.local(s, &props, &nb, &mb, false);
                            for (i, t) in model.tendons.iter().enumerate() {
                                if t.end >= b {
                                    ws.tendon_lengths[i] += wg * (t1 - t0) * ev.tendon_speed[i];
                                }
                            }
                        }
                    }
                    ws.nodes.push(Node {
                        s: t1,
                        interval: k,
                        y: head(&sol.y[i]),
                    });
                }
                ev.track_speeds = false;
                y = sol.y[sol.y.len() - 1];
            }
        }
        if k + 2 < breaks.len() {
            model.jump(b, &mut y);
        }
    }
    let (residual, jacobian) = model.residual(&y);
    let chord = v3(&y, 0) - model.rod.base_pose().position();
    Ok(Pass {
        residual,
        jacobian,
        chord,
    })
}

fn shoot_any(
    ev: &mut Evaluator<'_, '_>,
    x: &Vector6<f64>,
    sens: bool,
    integrator: &Integrator,
    plan: &[usize],
    ws: &mut Workspace,
) -> Result<Pass> {
    if sens {
        shoot::<FULL>(ev, x, integrator, plan, ws)
    } else {
        shoot::<STATE>(ev, x, integrator, plan, ws)
    }
}

/// Outcome of the Newton iteration at one load factor.
struct NewtonOut {
    x: Vector6<f64>,
    residual: f64,
    converged: bool,
    iterations: usize,
    /// Whether the workspace holds the pass at `x`.
    recorded: bool,
    /// Size of a first Newton step refused for exceeding the step limit (0 otherwise).
    first_step: f64,
}

fn norm(r: &Vector6<f64>) -> f64 {
    if r.iter().all(|v| v.is_finite()) {
        r.amax()
    } else {
        f64::INFINITY
    }
}

/// Damped Newton on the scaled base wrench, from `x0`.
fn newton(
    ev: &mut Evaluator<'_, '_>,
    x0: Vector6<f64>,
    try_cheap: bool,
    step_limit: Option<f64>,
    opts: &SolveOptions,
    plan: &[usize],
    ws: &mut Workspace,
) -> NewtonOut {
    let tol_of = |x: &Vector6<f64>| match opts.integrator {
        Integrator::Rk4 { .. } => opts.tolerance,
        Integrator::Adaptive(a) => opts.tolerance.max(10.0 * a.rtol * (1.0 + x.amax())),
    };
    let mut x = x0;
    let mut out = NewtonOut {
        x,
        residual: f64::INFINITY,
        converged: false,
        iterations: 0,
        recorded: false,
        first_step: 0.0,
    };
    // A cheap first pass without sensitivities when the guess may already solve the problem
    // (warm starts; tendon-only loading, for which the total base wrench is exactly zero).
    let (mut r, mut rn) = (Vector6::repeat(f64::NAN), f64::INFINITY);
    if try_cheap {
        if let Ok(p) = shoot_any(ev, &x, false, &opts.integrator, plan, ws) {
            r = p.residual;
            rn = norm(&r);
        }
        out.residual = rn;
        out.recorded = rn.is_finite();
        if rn <= tol_of(&x) {
            out.converged = true;
            return out;
        }
    }
    // With a zero base force and no force applied along the rod, N(s) = 0 everywhere, and
    // the variational equations integrate in closed form: δN(L) = δN(0) and
    // δM(L) = δM(0) - (p(L) - p(0)) × δN(0). The exact Jacobian then comes from a pass
    // without sensitivities.
    let analytic = ev.model.force_free && x.fixed_rows::<3>(0).iter().all(|v| *v == 0.0);
    let mut jac = match shoot_any(ev, &x, !analytic, &opts.integrator, plan, ws) {
        Ok(p) if norm(&p.residual).is_finite() => {
            r = p.residual;
            rn = norm(&r);
            if analytic {
                let mut j = Matrix6::identity();
                let h = hat(&p.chord) / ev.model.length;
                for a in 0..3 {
                    for b in 0..3 {
                        j[(3 + a, b)] = -h[(a, b)];
                    }
                }
                Some(j)
            } else {
                p.jacobian
            }
        }
        _ => None,
    };
    out.recorded = jac.is_some();
    out.residual = rn;
    let mut r_prev = f64::INFINITY;
    for _ in 0..opts.max_iterations {
        let Some(j) = jac else {
            break;
        };
        let Some(dx) = j.lu().solve(&(-r)) else {
            break;
        };
        if !dx.iter().all(|v| v.is_finite()) {
            break;
        }
        if let Some(limit) = step_limit {
            if out.iterations == 0 && dx.amax() > limit {
                // Too far from the guess for Newton to stay on the equilibrium branch that is
                // connected to it: leave it to the continuation.
                out.first_step = dx.amax();
                break;
            }
        }
        // Under quadratic convergence the next residual is about rn³ / r_prev²; when that is
        // far below the tolerance, try the full step without sensitivities first (it is then
        // the last pass).
        if r_prev.is_finite() && rn < 0.1 * r_prev && rn * (rn / r_prev).powi(2) < 0.5 * tol_of(&x)
        {
            let xt = x + dx;
            if let Ok(p) = shoot_any(ev, &xt, false, &opts.integrator, plan, ws) {
                let rt = norm(&p.residual);
                if rt <= tol_of(&xt) {
                    out.iterations += 1;
                    out.x = xt;
                    out.residual = rt;
                    out.recorded = true;
                    out.converged = true;
                    return out;
                }
            }
        }
        r_prev = rn;
        let mut lambda = 1.0;
        let mut accepted = false;
        for _ in 0..=MAX_LINE_SEARCH_HALVINGS {
            let xt = x + dx * lambda;
            if let Ok(p) = shoot_any(ev, &xt, true, &opts.integrator, plan, ws) {
                let rt = norm(&p.residual);
                if rt <= (1.0 - ARMIJO * lambda) * rn || rt <= tol_of(&xt) {
                    x = xt;
                    r = p.residual;
                    rn = rt;
                    jac = p.jacobian;
                    accepted = true;
                    break;
                }
            }
            lambda *= 0.5;
        }
        out.recorded = accepted;
        if !accepted {
            break;
        }
        out.iterations += 1;
        out.x = x;
        out.residual = rn;
        if rn <= tol_of(&x) {
            out.converged = true;
            return out;
        }
    }
    out.x = x;
    out.residual = rn;
    out
}

/// Positions and rotations at the nodes of the pass held by the workspace.
fn shape_of(ws: &Workspace) -> Vec<(Vector3<f64>, Matrix3<f64>)> {
    ws.nodes.iter().map(|n| (v3(&n.y, 0), rot(&n.y))).collect()
}

/// Whether two shapes differ by at most [`MAX_LOAD_STEP_TURN`] in rotation (rad) and
/// `MAX_LOAD_STEP_TURN L / 2` in position, node by node on a common mesh (RK4), at the tip
/// otherwise (adaptive meshes differ between passes).
fn shape_change_is_small(
    a: &[(Vector3<f64>, Matrix3<f64>)],
    b: &[(Vector3<f64>, Matrix3<f64>)],
    length: f64,
) -> bool {
    let close = |(p0, r0): &(Vector3<f64>, Matrix3<f64>),
                 (p1, r1): &(Vector3<f64>, Matrix3<f64>)| {
        let c = ((r0.tr_mul(r1).trace() - 1.0) * 0.5).clamp(-1.0, 1.0);
        c.acos() <= MAX_LOAD_STEP_TURN && (p1 - p0).norm() <= 0.5 * MAX_LOAD_STEP_TURN * length
    };
    if a.len() == b.len() {
        a.iter().zip(b).all(|(x, y)| close(x, y))
    } else {
        match (a.last(), b.last()) {
            (Some(x), Some(y)) => close(x, y),
            _ => false,
        }
    }
}

/// Validates the inputs and builds the model at load factor 1.
pub(crate) fn build_model<'a>(
    rod: &'a Rod,
    tendons: &'a [Tendon],
    loads: &'a Loads,
) -> Result<Model<'a>> {
    let l = rod.length();
    loads.validate(l, rod.density())?;
    let mut prepared = Vec::with_capacity(tendons.len());
    let mut breaks = vec![0.0, l];
    for (i, t) in tendons.iter().enumerate() {
        let end = t.end().unwrap_or(l);
        if !(end.is_finite() && end > 0.0 && end <= l) {
            return Err(Error::invalid(
                format!("tendons[{i}].end"),
                end,
                format!("in (0, length] = (0, {l}] m"),
            ));
        }
        if t.tension() < 0.0 || !t.tension().is_finite() {
            return Err(Error::invalid(
                format!("tendons[{i}].tension"),
                t.tension(),
                "finite and >= 0 N",
            ));
        }
        breaks.push(end);
        prepared.push(ActiveTendon { tendon: t, end });
    }
    for p in &loads.point_loads {
        breaks.push(p.s);
    }
    for (start, end) in crate::model::chamber::validate(&loads.chambers, rod)? {
        breaks.extend([start, end]);
    }
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let props0 = rod.section_at(0.0);
    let f_ref = rod.material().bending_stiffness(&props0) / (l * l);
    if !(f_ref.is_finite() && f_ref > 0.0) {
        return Err(Error::invalid(
            "section(0)",
            format!("{props0:?}"),
            "positive and finite",
        ));
    }
    // Tendon offsets must be finite (user functions) and inside... finite at the checks.
    for (i, t) in tendons.iter().enumerate() {
        let end = prepared[i].end;
        for k in 0..=crate::model::rod::FUNCTION_CHECKS {
            let s = end * k as f64 / crate::model::rod::FUNCTION_CHECKS as f64;
            let (r, rp) = t.routing().offset(s, &rod.section_at(s));
            if !(r.iter().chain(rp.iter()).all(|v| v.is_finite())) {
                return Err(Error::invalid(
                    format!("tendons[{i}].offset({s})"),
                    format!("{r:?}, {rp:?}"),
                    "finite",
                ));
            }
        }
    }
    Ok(Model {
        rod,
        tendons: prepared,
        loads,
        shear_coefficient: rod.shear_coefficient(),
        rho_g: rod
            .density()
            .filter(|_| loads.gravity != Vector3::zeros())
            .map(|rho| loads.gravity * rho),
        factor: 1.0,
        f_ref,
        length: l,
        breaks,
        force_free: loads.distributed_force.is_none()
            && loads.gravity == Vector3::zeros()
            && loads.point_loads.iter().all(|p| {
                p.force == Vector3::zeros()
                    && (p.frame == Frame::World || p.moment == Vector3::zeros())
            })
            && (loads.tip_frame == Frame::World
                || (loads.tip_force == Vector3::zeros() && loads.tip_moment == Vector3::zeros())),
        material_error: std::sync::OnceLock::new(),
        uniform_compliance: (rod.section().is_uniform() && rod.material().is_linear()).then(|| {
            rod.material()
                .compliance(&props0, rod.shear_coefficient(), rod.inextensible())
        }),
    })
}

fn check_options(opts: &SolveOptions) -> Result<()> {
    match opts.integrator {
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
    check_newton_options(opts.tolerance, opts.max_iterations, opts.max_load_steps)?;
    if let Some(w) = &opts.warm_start {
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

/// Solves the statics of `rod` actuated by `tendons` under `loads`
/// (`solve_statics(rod, tendons=(), loads=None, ...)` in Python).
///
/// # Errors
/// [`Error::InvalidParameter`] naming the offending field (loads, tendon terminations outside
/// `(0, L]`, chambers outside `[0, L]` or the section, options); [`Error::NotConverged`] with
/// the Newton iterations and final scaled residual if the shooting does not converge and
/// `options.throw` is true, unless a hyperelastic material failed on the way: then
/// [`Error::InvalidParameter`] naming `stretch` (a fibre compressed to zero length) or the
/// law's parameters (a law that is not monotonic at the stretches reached).
pub fn solve_statics(
    rod: &Rod,
    tendons: &[Tendon],
    loads: &Loads,
    options: &SolveOptions,
) -> Result<StaticsSolution> {
    check_options(options)?;
    let mut model = build_model(rod, tendons, loads)?;
    let plan = match options.integrator {
        Integrator::Rk4 { steps } => rk4_plan(&model.breaks, steps),
        Integrator::Adaptive(_) => Vec::new(),
    };
    let fm = model.f_ref * model.length;
    let x0 = match &options.warm_start {
        Some(w) => {
            let b = &w.base_wrench;
            Vector6::new(
                b[0] / model.f_ref,
                b[1] / model.f_ref,
                b[2] / model.f_ref,
                b[3] / fm,
                b[4] / fm,
                b[5] / fm,
            )
        }
        None => Vector6::zeros(),
    };
    let mut ws = Workspace {
        nodes: Vec::new(),
        tendon_lengths: vec![0.0; tendons.len()],
    };
    let mut evaluations = 0usize;
    let mut stats = SolverStats {
        iterations: 0,
        residual: f64::INFINITY,
        function_evaluations: 0,
        converged: false,
        load_steps: 0,
        load_factor: 1.0,
    };

    let direct = {
        let mut ev = Evaluator::new(&model);
        let unloaded = loads.tip_force == Vector3::zeros()
            && loads.tip_moment == Vector3::zeros()
            && loads.point_loads.is_empty()
            && loads.distributed_force.is_none()
            && loads.distributed_moment.is_none()
            && model.rho_g.is_none();
        let try_cheap = options.warm_start.is_some() || unloaded;
        let limit = options.continuation.then_some(DIRECT_STEP_LIMIT);
        let out = newton(&mut ev, x0, try_cheap, limit, options, &plan, &mut ws);
        evaluations += ev.evaluations;
        out
    };
    stats.iterations = direct.iterations;
    let mut result = direct;

    if !result.converged && options.continuation {
        // Load stepping from the unloaded rod (x = 0 is exact at load factor 0), with a secant
        // predictor; a step fails (and is halved) if Newton does not converge or its first
        // step exceeds the step limit.
        let mut lambda = 0.0f64;
        let mut dl = if result.first_step > 0.0 {
            (0.8 * DIRECT_STEP_LIMIT / result.first_step).clamp(MIN_LOAD_INCREMENT, 0.5)
        } else {
            0.25
        };
        let mut x = Vector6::zeros();
        let mut prev: Option<(Vector6<f64>, f64)> = None;
        // Tip pose of the last accepted load step (the unloaded rod to begin with).
        model.factor = 0.0;
        let mut tip = {
            let mut ev = Evaluator::new(&model);
            let pass = shoot::<STATE>(&mut ev, &x, &options.integrator, &plan, &mut ws);
            evaluations += ev.evaluations;
            pass.ok().map(|_| shape_of(&ws))
        };
        let mut steps = 0usize;
        let mut last = None;
        while steps < options.max_load_steps {
            let target = (lambda + dl).min(1.0);
            model.factor = target;
            let guess = match prev {
                Some((xp, dlp)) => x + (x - xp) * ((target - lambda) / dlp),
                None => x,
            };
            let mut ev = Evaluator::new(&model);
            let out = newton(
                &mut ev,
                guess,
                false,
                Some(DIRECT_STEP_LIMIT),
                options,
                &plan,
                &mut ws,
            );
            evaluations += ev.evaluations;
            stats.iterations += out.iterations;
            steps += 1;
            // A load step must not move the tip by more than MAX_LOAD_STEP_TURN (rotation, rad)
            // or MAX_LOAD_STEP_TURN L (position): larger jumps may switch equilibrium branch.
            let new_tip = if out.converged {
                Some(shape_of(&ws))
            } else {
                None
            };
            let small = match (&tip, &new_tip) {
                (Some(a), Some(b)) => shape_change_is_small(a, b, model.length),
                _ => false,
            };
            if out.converged && small {
                tip = new_tip;
                prev = Some((x, target - lambda));
                lambda = target;
                x = out.x;
                let done = lambda >= 1.0;
                last = Some(out);
                if done {
                    break;
                }
                dl = (dl * 2.0).min(0.5);
            } else {
                dl *= 0.5;
                last = Some(NewtonOut {
                    converged: false,
                    ..out
                });
                if dl < MIN_LOAD_INCREMENT {
                    break;
                }
            }
        }
        stats.load_steps = steps;
        stats.load_factor = lambda;
        if let Some(out) = last {
            if out.converged && lambda >= 1.0 {
                result = out;
            } else {
                // Report the last converged load step.
                model.factor = lambda;
                result = NewtonOut {
                    x,
                    converged: false,
                    recorded: false,
                    ..out
                };
            }
        }
    }
    // Make sure the workspace holds the pass at the final unknowns (at the load factor they
    // belong to).
    if !result.recorded {
        let mut ev = Evaluator::new(&model);
        if let Ok(p) = shoot::<STATE>(&mut ev, &result.x, &options.integrator, &plan, &mut ws) {
            if !result.converged && stats.load_factor >= 1.0 {
                result.residual = norm(&p.residual);
            }
        }
        evaluations += ev.evaluations;
    }
    stats.residual = result.residual;
    stats.converged = result.converged;
    stats.function_evaluations = evaluations;
    if !result.converged && options.throw {
        if let Some(e) = model.material_error.get() {
            return Err(e.clone());
        }
        return Err(Error::NotConverged {
            what: "shooting Newton (Cosserat rod statics)".into(),
            iterations: stats.iterations,
            residual: result.residual,
        });
    }
    let x = result.x;
    let base_wrench = [
        x[0] * model.f_ref,
        x[1] * model.f_ref,
        x[2] * model.f_ref,
        x[3] * fm,
        x[4] * fm,
        x[5] * fm,
    ];
    let rk4 = matches!(options.integrator, Integrator::Rk4 { .. });
    Ok(assemble(&model, &ws, base_wrench, stats, rk4))
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

/// Derived quantities at the recorded nodes.
fn assemble(
    model: &Model<'_>,
    ws: &Workspace,
    base_wrench: [f64; 6],
    stats: SolverStats,
    rk4: bool,
) -> StaticsSolution {
    let n = ws.nodes.len();
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
        tendon_lengths: ws.tendon_lengths.clone(),
        base_wrench,
        stats,
    };
    let mut ev = Evaluator::new(model);
    ev.track_speeds = true;
    let nt = model.tendons.len();
    // Tendon speeds |p_i'| at the nodes of the current interval, per tendon (RK4 quadrature).
    let mut speeds: Vec<Vec<f64>> = vec![Vec::new(); nt];
    if rk4 {
        sol.tendon_lengths.iter_mut().for_each(|l| *l = 0.0);
    }
    let mut current = usize::MAX;
    for (j, node) in ws.nodes.iter().enumerate() {
        if node.interval != current {
            ev.set_interval(node.interval);
            current = node.interval;
            speeds.iter_mut().for_each(Vec::clear);
        }
        let y = &node.y;
        let r = rot(y);
        let nb_tot = r.tr_mul(&v3(y, 12));
        let mb_tot = r.tr_mul(&v3(y, 15));
        let props = model.rod.section_at(node.s);
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
            let b = model.breaks[k + 1];
            for (i, t) in model.tendons.iter().enumerate() {
                if t.end >= b {
                    speeds[i].push(ev.tendon_speed[i]);
                }
            }
            let last_of_interval = ws.nodes.get(j + 1).is_none_or(|n| n.interval != k);
            if last_of_interval {
                let h = (b - model.breaks[k])
                    / (ws.nodes.iter().filter(|n| n.interval == k).count() - 1).max(1) as f64;
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
