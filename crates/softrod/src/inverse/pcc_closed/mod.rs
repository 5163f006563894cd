//! The PCC inverse statics of an unloaded, tendon-driven robot and a tip position in closed
//! form.
//!
//! Without a tip wrench the equilibrium is closed form and *affine* in the actuation in the
//! coordinates `θ = (θ_x, θ_y, ℓ)` of every segment (`pcc/statics.rs`): `θ = θ0 + M a`. The
//! tip position is the chain kinematics of `θ`, whose first and second derivatives are closed
//! form (`seg_kin`), so the actuation Jacobian is `J = J_θ M` and the Hessian of the
//! Lagrangian `½|a - c|²_W - λᵀ p(a)` is `W - Mᵀ (Σ λ_k ∇²_θ p_k) M`, exact.
//!
//! The iteration is that of `solve_inverse` (the same objective, minimum-norm and
//! least-squares programs, trust region far from the target, merit function near it, and
//! stopping test), with what the exact Hessian allows:
//!
//! * The curved step (the Hessian kept whole, cross terms included, unless `Zᵀ H Z` must be
//!   raised to be positive definite on the null space `Z`: the step is Newton's on the KKT
//!   conditions) is taken whenever the minimum-norm step fits the trust region, far from the
//!   target too: the far phase converges as Newton's does, not linearly.
//! * The curved step keeps the bounds by a primal active set from the minimum-norm point (as
//!   `qp::active_set_qp` of the generic iteration), rather than falling back to the
//!   minimum-norm step when it leaves the box.
//! * A full near step that the merit function rejects because the pose error it leaves is of
//!   second order (the Maratos effect) is corrected by the minimum-norm step back to the
//!   target before it is shortened.
//! * The dual iterations of the small programs start from the last multipliers.
//!
//! Everything is dense algebra on vectors reused from one iteration to the next: the
//! minimum-norm and Levenberg–Marquardt programs in the dual (three multipliers), the curved
//! step by the KKT systems of its working sets, the null space by a pivoted Gram–Schmidt on
//! its projector.

mod chain;
mod curved;
mod dual;

use std::cell::Cell;

use nalgebra::{DMatrix, Vector3 as V3};

use super::{
    objective_change, trust_radius, Evaluation, InverseOptions, InverseSolution, InverseWarmStart,
    FIRST_RADIUS, LEAST_SQUARES_REGULARISATION, LOCAL_STEP, NEAR_TARGET,
};
use crate::pcc::statics::PccRobot;
use chain::{lagrangian_hessian, Affine, Chain};
use curved::{convexify, curved_step, reduced_step, ConvexWork, CurvedWork, Reduced, ReducedWork};
use dual::{dual, linearised_target, lm_step, scaled_norm_of, Box_, DualProgram, DualWork, LmWork};

/// Most changes of the working set per variable in [`curved_step`].
pub(super) const CURVED_ACTIVE_SET_CHANGES: usize = 10;
/// Pose error (in units of the rod length) below which the steps are curved (ten times
/// [`NEAR_TARGET`]): from farther, the curved step can head for another, larger local minimum of
/// the norm on the target (1 in 400 random targets of the two-segment robot at 1e-2).
const CURVED_FROM: f64 = 1e-3;
/// Floor of the eigenvalues of `Zᵀ H Z` (scaled variables) in [`convexify`].
pub(super) const CURVATURE_FLOOR: f64 = 1e-3;

/// The scratch of the iteration's steps.
#[derive(Default)]
struct Work {
    dual: DualWork,
    lm: LmWork,
    /// `Σ λ_k ∇²_θ p_k` of the last curved step (q × q).
    theta: Vec<f64>,
    /// Scratch of the products with the Hessian (q, q, and n × q).
    hm: Vec<f64>,
    reduced: ReducedWork,
    convex: ConvexWork,
    curved: CurvedWork,
    /// The curved step.
    d: Vec<f64>,
}

/// The state of the closed-form iteration: the affine map, the box, the target and the
/// scales, the iterate and its chain, and the scratch of the steps.
#[derive(Default)]
struct ClosedForm {
    aff: Affine,
    bx: Box_,
    target: V3<f64>,
    /// The rod length (m).
    length: f64,
    /// Pose error below which the iteration is in its near phase (m).
    near: f64,
    /// Tolerance of the minimum-norm program's constraint (m).
    tol_qp: f64,
    /// The actuation: tensions (N), then pressures (Pa).
    a: Vec<f64>,
    /// The chain at `a`, and at the trial actuation.
    cur: Chain,
    next: Chain,
    /// The minimum-norm (or least-squares) point of the last program.
    y: Vec<f64>,
    /// The step of the last program.
    step: Vec<f64>,
    /// The multipliers of the last feasible minimum-norm program (the start of the next).
    lambda: V3<f64>,
    /// The Hessian of the Lagrangian of the last curved step (n × n, row-major).
    hess: Vec<f64>,
    /// Whether the last step was curved, and whether `hess` was formed for it (the reduced
    /// step applies it without forming it).
    curved: bool,
    hess_formed: bool,
    /// The trial actuation, and the second-order corrected one.
    trial: Vec<f64>,
    corrected: Vec<f64>,
    /// The trust radius (scaled actuation norm): NaN until the first Jacobian is known.
    radius: f64,
    /// The penalty of the pose error in the merit function.
    nu: f64,
    iterations: usize,
    evaluations: usize,
    work: Work,
}

impl ClosedForm {
    /// Resets the state to the first iterate of a new problem (the warm start's actuation or
    /// the reference, clamped), its vectors reused; `false` if the warm start does not fit or
    /// the chain cannot be evaluated there.
    fn reset(
        &mut self,
        robot: &PccRobot,
        target: &V3<f64>,
        options: &InverseOptions,
        warm: Option<&InverseWarmStart>,
    ) -> bool {
        self.aff.fill(robot);
        let (nt, n) = (robot.n_tendons(), self.aff.n);
        let bx = &mut self.bx;
        bx.w.clear();
        match &options.weights {
            Some(w) => bx.w.extend_from_slice(w),
            None => {
                bx.w.resize(nt, 1.0);
                let areas = robot.chambers().iter().flat_map(|(_, c)| c.areas());
                bx.w.extend(areas.map(|a| a * a));
            }
        }
        let (tb, pb) = (options.tension_bounds, options.pressure_bounds);
        bx.lo.clear();
        bx.lo
            .extend((0..n).map(|i| if i < nt { tb.0 } else { pb.0 }));
        bx.hi.clear();
        bx.hi
            .extend((0..n).map(|i| if i < nt { tb.1 } else { pb.1 }));
        bx.c.clear();
        match &options.reference {
            Some(c) => bx.c.extend_from_slice(c),
            None => bx.c.resize(n, 0.0),
        }
        self.a.clear();
        match warm {
            Some(w) if w.actuation.len() == n && w.actuation.iter().all(|v| v.is_finite()) => {
                self.a.extend_from_slice(&w.actuation);
            }
            Some(_) => return false,
            None => self.a.extend_from_slice(&bx.c),
        }
        for (i, v) in self.a.iter_mut().enumerate() {
            *v = bx.clamp(i, *v);
        }
        if !self.cur.eval(&self.aff, &self.a) {
            return false;
        }
        self.target = *target;
        self.length = self.aff.rest.iter().sum();
        self.near = NEAR_TARGET * self.length;
        self.tol_qp = 1e-3 * options.tolerance;
        for v in [
            &mut self.y,
            &mut self.step,
            &mut self.trial,
            &mut self.corrected,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
        self.lambda = V3::zeros();
        self.curved = false;
        self.radius = f64::NAN;
        self.nu = 0.0;
        self.iterations = 0;
        self.evaluations = 1;
        true
    }

    /// The step of the program at the iterate for the pose error `e` (into `self.step`): the
    /// minimum-norm step (the bounded least squares if the linearised target cannot be met
    /// inside the bounds), curved where the minimum-norm step fits the trust region (always
    /// near the target). Returns the multipliers (`None`: least squares); `None` if the least
    /// squares fail.
    fn program_step(&mut self, e: &V3<f64>, merit: f64) -> Option<Option<V3<f64>>> {
        let n = self.aff.n;
        let (jac, bx) = (&self.cur.jac, &self.bx);
        let b = linearised_target(jac, e, &self.a[..n]);
        let min_norm = DualProgram::min_norm(&bx.c, self.tol_qp);
        let ws = &mut self.work;
        let lambda = dual(
            jac,
            &b,
            bx,
            &min_norm,
            self.lambda,
            &mut self.y,
            &mut ws.dual,
        );
        if lambda.is_none() {
            // The linearised target cannot be met inside the bounds: the bounded least
            // squares, with the norm as a vanishing regularisation.
            let jmax = jac.iter().fold(0.0f64, |m, j| m.max(j.amax()));
            let wmax = bx.w.iter().fold(0.0f64, |m, v| m.max(*v));
            let reg = (LEAST_SQUARES_REGULARISATION * jmax.powi(2).max(1e-300) / wmax).max(1e-300);
            let least_squares = DualProgram {
                mu: reg,
                rho: 1.0,
                ..min_norm
            };
            dual(
                jac,
                &b,
                bx,
                &least_squares,
                V3::zeros(),
                &mut self.y,
                &mut ws.dual,
            )?;
        }
        for i in 0..n {
            self.step[i] = self.y[i] - self.a[i];
        }
        self.curved = false;
        let Some(l) = lambda else {
            return Some(None);
        };
        self.lambda = l;
        // Far from the target a step longer than the trust region is replaced by the
        // Levenberg–Marquardt step: its curvature would not be used.
        let far = merit > self.near;
        let fits = bx.norm(&self.step) <= self.radius;
        if merit > CURVED_FROM * self.length || (far && !fits) {
            return Some(lambda);
        }
        if (0..n).filter(|&i| bx.inside(i, self.y[i])).count() <= 3 {
            // No null space of the free columns: the curved step is the minimum-norm one.
            return Some(lambda);
        }
        self.cur.theta_hessian(&l, &mut ws.theta);
        let cols = (&self.aff, &ws.theta[..], &jac[..]);
        match reduced_step(
            cols,
            (&self.a, &self.y),
            bx,
            &mut ws.convex,
            &mut ws.reduced,
        ) {
            Reduced::NoNullSpace => {}
            Reduced::Step => {
                self.step.copy_from_slice(&ws.reduced.d);
                self.curved = true;
                self.hess_formed = false;
            }
            Reduced::Bounds => {
                // The bounds change on the face: the primal active set on the whole Hessian.
                let hess = &mut self.hess;
                lagrangian_hessian(&self.aff, &ws.theta, &bx.w, &mut ws.hm, hess);
                convexify(hess, jac, &self.y, bx, &mut ws.convex);
                let h = (&hess[..], &jac[..]);
                if curved_step(h, &self.a, &self.y, bx, &mut ws.d, &mut ws.curved) {
                    self.step.copy_from_slice(&ws.d);
                    self.curved = true;
                    self.hess_formed = true;
                }
            }
        }
        Some(lambda)
    }

    /// The step search of `solve_inverse` (trust region far from the target, line search on
    /// the merit function near it) from the iterate along `self.step`; the accepted
    /// actuation is left in `trial` and its chain in `next`. Returns whether a step was
    /// accepted.
    fn search(&mut self, e: &V3<f64>, merit: f64, norm_a: f64) -> bool {
        let n = self.aff.n;
        let near_phase = merit <= self.near;
        let residual_after = |jac: &[V3<f64>], d: &[f64]| {
            let mut r = *e;
            for i in 0..n {
                r -= jac[i] * d[i];
            }
            r.norm()
        };
        let grad: f64 = (0..n)
            .map(|i| self.bx.w[i] * (self.a[i] - self.bx.c[i]) * self.step[i])
            .sum();
        let slope = grad + self.nu * (residual_after(&self.cur.jac, &self.step) - merit);
        let mut alpha = 1.0;
        while self.radius > 1e-14 * (1.0 + norm_a) && alpha > 1e-10 {
            let full = near_phase || self.bx.norm(&self.step) <= self.radius;
            if !full {
                let (jac, ws) = (&self.cur.jac, &mut self.work.lm);
                lm_step(jac, (e, &self.a), &self.bx, self.radius, &mut self.step, ws);
            }
            let step_norm = self.bx.norm(&self.step) * alpha;
            if step_norm <= 1e-15 * (1.0 + norm_a) {
                break;
            }
            for i in 0..n {
                self.trial[i] = self.bx.clamp(i, self.a[i] + alpha * self.step[i]);
            }
            self.evaluations += 1;
            let predicted = merit - residual_after(&self.cur.jac, &self.step);
            if self.next.eval(&self.aff, &self.trial) {
                let mt = (self.target - self.next.p).norm();
                let ok = if near_phase {
                    let df = objective_change(&self.bx.w, &self.bx.c, &self.a, &self.trial);
                    let local = step_norm <= LOCAL_STEP * (1.0 + norm_a);
                    (local && mt <= self.near)
                        || df + self.nu * (mt - merit) <= 1e-4 * alpha * slope.min(0.0)
                } else {
                    mt <= (1.0 - 1e-4) * merit || (full && mt <= self.near)
                };
                if mt.is_finite() && ok {
                    self.radius = trust_radius(self.radius, full, step_norm, merit - mt, predicted);
                    return true;
                }
                if near_phase && alpha == 1.0 && mt.is_finite() && self.correct(merit, slope) {
                    return true;
                }
            }
            if near_phase {
                alpha *= 0.5;
            } else {
                self.radius = 0.25 * step_norm.min(self.radius);
            }
        }
        false
    }

    /// The second-order correction of a full near step that the merit function rejects: the
    /// minimum-norm change `c` of the trial actuation with `J c = e(trial)` (the Jacobian at
    /// the iterate), inside the bounds; taken if `trial + c` passes the merit test of the
    /// full step. On success the corrected actuation is left in `trial` and its chain in
    /// `next`.
    fn correct(&mut self, merit: f64, slope: f64) -> bool {
        let n = self.aff.n;
        let jac = &self.cur.jac;
        let b = linearised_target(jac, &(self.target - self.next.p), &self.trial[..n]);
        let program = DualProgram::min_norm(&self.trial, self.tol_qp);
        let ws = &mut self.work.dual;
        if dual(
            jac,
            &b,
            &self.bx,
            &program,
            V3::zeros(),
            &mut self.corrected,
            ws,
        )
        .is_none()
        {
            return false;
        }
        self.evaluations += 1;
        if !self.next.eval(&self.aff, &self.corrected) {
            return false;
        }
        let mt = (self.target - self.next.p).norm();
        let df = objective_change(&self.bx.w, &self.bx.c, &self.a, &self.corrected);
        if !(mt.is_finite() && df + self.nu * (mt - merit) <= 1e-4 * slope.min(0.0)) {
            return false;
        }
        self.trial.copy_from_slice(&self.corrected);
        true
    }

    /// The result at the iterate (reached): its pose, the pose Jacobian in the actuation
    /// (position rows, then rotation rows `Ω M`) and the Hessian (`W` unless the last step
    /// was curved).
    fn solution(&mut self, nt: usize) -> InverseSolution {
        if self.curved && !self.hess_formed {
            // The reduced step formed no Hessian: the whole one at the last program.
            let ws = &mut self.work;
            lagrangian_hessian(&self.aff, &ws.theta, &self.bx.w, &mut ws.hm, &mut self.hess);
            convexify(
                &mut self.hess,
                &self.cur.jac,
                &self.y,
                &self.bx,
                &mut ws.convex,
            );
        }
        let (aff, cur, n) = (&self.aff, &self.cur, self.aff.n);
        let dist = (self.target - cur.p).norm();
        let ns = aff.rest.len();
        let jac = DMatrix::from_fn(6, n, |r, k| {
            if r < 3 {
                cur.jac[k][r]
            } else {
                (0..ns)
                    .map(|s| {
                        (0..3)
                            .map(|c| cur.oc[s][c][r - 3] * aff.cols[s * n + k][c])
                            .sum::<f64>()
                    })
                    .sum()
            }
        });
        let hessian = if self.curved {
            DMatrix::from_row_slice(n, n, &self.hess)
        } else {
            DMatrix::from_fn(n, n, |r, c| if r == c { self.bx.w[r] } else { 0.0 })
        };
        InverseSolution {
            actuation: self.a.clone(),
            n_tendons: nt,
            position_error: dist,
            rotation_error: 0.0,
            iterations: self.iterations,
            evaluations: self.evaluations,
            probes: 0,
            converged: true,
            reached: true,
            evaluation: Evaluation {
                positions: vec![cur.p],
                rotation: cur.r,
                jacobian: Some(vec![jac]),
            },
            hessian,
            start: 0,
            steps: None,
        }
    }
}

impl ClosedForm {
    /// The iteration from the state `reset` made (the steps are those of `solve_inverse`, in
    /// the same order); the result if the target is reached.
    fn run(&mut self, robot: &PccRobot, options: &InverseOptions) -> Option<InverseSolution> {
        loop {
            let e = self.target - self.cur.p;
            let merit = e.norm();
            let reached = merit <= options.tolerance;
            let norm_a = self.bx.norm(&self.a);
            if self.radius.is_nan() {
                // A first step that moves the linearised pose by at most the rod length (the
                // linearisation of a straight rod asks for huge tensions to shorten it).
                let sigma = scaled_norm_of(&self.cur.jac, &self.bx.w);
                self.radius = if sigma > 0.0 {
                    (FIRST_RADIUS * self.length / sigma).max(norm_a)
                } else {
                    f64::INFINITY
                };
            }
            let lambda = self.program_step(&e, merit)?;
            if let Some(l) = &lambda {
                self.nu = 1.5 * l.norm();
            }
            let small = self.bx.norm(&self.step) <= options.optimality_tolerance * (1.0 + norm_a);
            if small && reached {
                break;
            }
            if small && lambda.is_none() {
                // Stationary short of the target: the generic iteration reports it.
                return None;
            }
            if self.iterations >= options.max_iterations {
                return None;
            }
            let accepted = self.search(&e, merit, norm_a);
            self.iterations += 1;
            if !accepted {
                return None;
            }
            self.a.copy_from_slice(&self.trial);
            std::mem::swap(&mut self.cur, &mut self.next);
        }
        Some(self.solution(robot.n_tendons()))
    }
}

thread_local! {
    /// The state of the last closed-form solve on this thread, reset by the next: its vectors
    /// keep their capacity, so that a solve allocates only its result.
    static STATE: Cell<Option<Box<ClosedForm>>> = const { Cell::new(None) };
}

/// The closed-form iteration for an unloaded robot and a tip position; `None` hands the
/// problem to the generic iteration (a linearised target out of reach inside the bounds, a
/// failed step, the iterations exhausted: the generic one decides and reports those cases).
pub(super) fn closed_form(
    robot: &PccRobot,
    target: &V3<f64>,
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
) -> Option<InverseSolution> {
    let mut cf = STATE.with(Cell::take).unwrap_or_default();
    let out = if cf.reset(robot, target, options, warm) {
        cf.run(robot, options)
    } else {
        None
    };
    STATE.with(|s| s.set(Some(cf)));
    out
}
