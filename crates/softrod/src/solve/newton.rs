//! Damped Newton at one load factor, with Broyden updates of the Jacobian between exact
//! evaluations.

use super::{max_norm, Evaluated, NewtonOptions, Problem, ROUND_OFF_RESIDUAL, ROUND_OFF_STEP};
use crate::math::linalg::DenseLu;

/// Sufficient-decrease condition of a step of length `alpha`: accepts the trial residual
/// norm `trial` against the current `current`.
pub trait Condition {
    /// Whether the step is accepted.
    fn accept(&self, alpha: f64, current: f64, trial: f64) -> bool;
}

/// Armijo's condition on the residual norm: `|r(x + α dx)| <= (1 - c α) |r(x)|`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Armijo {
    /// Sufficient-decrease constant `c` in `(0, 1)`.
    pub c: f64,
}

impl Default for Armijo {
    fn default() -> Self {
        Self { c: 1e-4 }
    }
}

impl Condition for Armijo {
    #[inline]
    fn accept(&self, alpha: f64, current: f64, trial: f64) -> bool {
        trial <= (1.0 - self.c * alpha) * current
    }
}

/// Backtracking line search: step lengths `1, f, f², ...` (`max_halvings + 1` of them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineSearch {
    /// Reduction factor of the step length, in `(0, 1)`.
    pub factor: f64,
    /// Most reductions.
    pub max_halvings: usize,
}

impl LineSearch {
    /// The step lengths to try, longest first.
    pub fn lengths(&self) -> impl Iterator<Item = f64> + '_ {
        (0..=self.max_halvings).scan(1.0, move |a, _| {
            let out = *a;
            *a *= self.factor;
            Some(out)
        })
    }
}

/// How [`newton`] iterates (the problem's own policy; [`NewtonOptions`] are the user's).
#[derive(Debug, Clone, Copy)]
pub struct NewtonSettings<'a> {
    /// Step lengths of the line search.
    pub line_search: LineSearch,
    /// Acceptance of a step.
    pub condition: Armijo,
    /// A first step longer than this (max norm) is refused and reported in
    /// [`NewtonOutcome::first_step`] (the continuation then steps the load).
    pub first_step_limit: Option<f64>,
    /// Evaluate the residual alone at the initial guess first (it may already solve).
    pub residual_first: bool,
    /// Update the Jacobian by Broyden's formula after each full step instead of evaluating it,
    /// as long as the residual falls fast (the exact Jacobian is evaluated again otherwise).
    pub broyden: bool,
    /// A Jacobian at (or near) the initial guess to start from (column-major).
    pub jacobian: Option<&'a [f64]>,
    /// End on an exact Jacobian evaluated at the converged iterate (the problem's last
    /// evaluation then carries it, e.g. for a stability test): a Broyden step predicted to
    /// converge is taken with the Jacobian, and a converged iterate without one is evaluated
    /// once more; neither where [`Problem::certified`] says the check needs no Jacobian there.
    pub exact_at_solution: bool,
}

/// Result of [`newton`].
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonOutcome {
    /// The last accepted iterate.
    pub x: Vec<f64>,
    /// Its residual norm (max norm; infinite if never evaluated successfully).
    pub residual: f64,
    /// Whether the residual met the tolerance.
    pub converged: bool,
    /// Accepted steps.
    pub iterations: usize,
    /// Size of a first step refused by [`NewtonSettings::first_step_limit`] (0 otherwise).
    pub first_step: f64,
    /// The Jacobian (exact or updated) at `x`, column-major.
    pub jacobian: Option<Vec<f64>>,
    /// Whether the problem's last evaluation was at `x` (its recorded state belongs to `x`).
    pub at_x: bool,
    /// Whether `jacobian` is exact at `x` and came with the problem's last evaluation (at `x`).
    pub exact: bool,
}

/// Contraction of the residual below which a Broyden step keeps the updated Jacobian.
const BROYDEN_CONTRACTION: f64 = 0.5;

/// The iterate of [`newton`]: unknowns, residual and its norm, the Jacobian (exact, or
/// updated by Broyden's formula), and scratch.
struct Iterate {
    x: Vec<f64>,
    r: Vec<f64>,
    jac: Vec<f64>,
    rn: f64,
    exact: bool,
    xt: Vec<f64>,
    rt: Vec<f64>,
    jt: Vec<f64>,
}

/// The first evaluations at `x0`: the residual (alone first when asked), then a Jacobian
/// (given, or evaluated). `None` if an evaluation fails or the start already solves.
fn start<P: Problem + ?Sized>(
    problem: &mut P,
    x0: &[f64],
    lambda: f64,
    options: &NewtonOptions,
    settings: &NewtonSettings<'_>,
    out: &mut NewtonOutcome,
) -> Option<Iterate> {
    let n = problem.dim();
    let mut it = Iterate {
        x: x0.to_vec(),
        r: vec![0.0; n],
        jac: if settings.residual_first && settings.jacobian.is_none() {
            Vec::new()
        } else {
            vec![0.0; n * n]
        },
        rn: f64::INFINITY,
        exact: false,
        // Scratch of the iterations, allocated once the start does not solve.
        xt: Vec::new(),
        rt: Vec::new(),
        jt: Vec::new(),
    };
    let want = !settings.residual_first && settings.jacobian.is_none();
    let ev = problem.evaluate(&it.x, lambda, want.then_some(&mut it.jac[..]), &mut it.r);
    if ev == Evaluated::Residual && settings.jacobian.is_none() {
        // Not needed unless the start fails.
        it.jac.clear();
    }
    if ev == Evaluated::Failed {
        return None;
    }
    it.rn = problem.norm(&it.r);
    out.residual = it.rn;
    out.at_x = true;
    let mut have_j = ev == Evaluated::Jacobian;
    it.exact = have_j;
    if !have_j {
        if let Some(j) = settings.jacobian {
            it.jac.copy_from_slice(j);
            have_j = true;
        }
    }
    if it.rn <= problem.tolerance(&it.x, options.tolerance) {
        out.converged = true;
        out.exact = ev == Evaluated::Jacobian;
        if settings.exact_at_solution && !out.exact && !problem.certified(&it.x, lambda) {
            let mut j = vec![0.0; n * n];
            if problem.evaluate(&it.x, lambda, Some(&mut j), &mut it.r) == Evaluated::Jacobian {
                out.residual = problem.norm(&it.r);
                out.converged = out.residual <= problem.tolerance(&it.x, options.tolerance);
                out.exact = true;
                out.jacobian = Some(j);
                return None;
            }
            out.at_x = false;
        }
        out.jacobian = have_j.then(|| it.jac.clone());
        return None;
    }
    if !it.rn.is_finite() {
        return None;
    }
    it.jac.resize(n * n, 0.0);
    it.xt.resize(n, 0.0);
    it.rt.resize(n, 0.0);
    it.jt.resize(n * n, 0.0);
    if !have_j && !exact_jacobian(problem, &mut it, lambda, out) {
        return None;
    }
    Some(it)
}

/// The residual norm at the trial point `x + dx` (into `it.xt`, `it.rt`), from the residual
/// alone; infinite if the evaluation fails.
fn trial_residual<P: Problem + ?Sized>(
    problem: &mut P,
    it: &mut Iterate,
    dx: &[f64],
    lambda: f64,
) -> f64 {
    for k in 0..dx.len() {
        it.xt[k] = it.x[k] + dx[k];
    }
    if problem.evaluate(&it.xt, lambda, None, &mut it.rt) == Evaluated::Failed {
        f64::INFINITY
    } else {
        problem.norm(&it.rt)
    }
}

/// What a Broyden step did.
enum Broyden {
    /// Accepted; `true` when the residual fell slowly (evaluate the Jacobian next).
    Accepted(bool),
    /// Refused: the residual did not fall enough.
    Refused,
}

/// A full step `dx` with the residual alone; on sufficient decrease, Broyden's update
/// `J += (Δr - J Δx) Δxᵀ / (Δxᵀ Δx)`.
fn broyden_step<P: Problem + ?Sized>(
    problem: &mut P,
    it: &mut Iterate,
    dx: &[f64],
    lambda: f64,
    settings: &NewtonSettings<'_>,
    tol: f64,
) -> Broyden {
    let n = dx.len();
    let rtn = trial_residual(problem, it, dx, lambda);
    if !(rtn <= tol || settings.condition.accept(1.0, it.rn, rtn)) {
        return Broyden::Refused;
    }
    let dd: f64 = dx.iter().map(|v| v * v).sum();
    if dd > 0.0 {
        let mut u = vec![0.0; n];
        for i in 0..n {
            let mut jdx = 0.0;
            for k in 0..n {
                jdx += it.jac[i + k * n] * dx[k];
            }
            u[i] = (it.rt[i] - it.r[i] - jdx) / dd;
        }
        for c in 0..n {
            for i in 0..n {
                it.jac[i + c * n] += u[i] * dx[c];
            }
        }
    }
    let slow = rtn > BROYDEN_CONTRACTION * it.rn;
    it.x.copy_from_slice(&it.xt);
    it.r.copy_from_slice(&it.rt);
    it.rn = rtn;
    it.exact = false;
    Broyden::Accepted(slow)
}

/// Backtracking line search along the exact Newton direction `dx`, evaluating exact
/// Jacobians; `true` if a step was accepted.
fn line_search<P: Problem + ?Sized>(
    problem: &mut P,
    it: &mut Iterate,
    dx: &[f64],
    lambda: f64,
    settings: &NewtonSettings<'_>,
    options: &NewtonOptions,
) -> bool {
    for alpha in settings.line_search.lengths() {
        for k in 0..dx.len() {
            it.xt[k] = it.x[k] + alpha * dx[k];
        }
        if problem.evaluate(&it.xt, lambda, Some(&mut it.jt), &mut it.rt) != Evaluated::Jacobian {
            continue;
        }
        let rtn = problem.norm(&it.rt);
        if settings.condition.accept(alpha, it.rn, rtn)
            || rtn <= problem.tolerance(&it.xt, options.tolerance)
        {
            std::mem::swap(&mut it.x, &mut it.xt);
            std::mem::swap(&mut it.r, &mut it.rt);
            std::mem::swap(&mut it.jac, &mut it.jt);
            it.rn = rtn;
            it.exact = true;
            return true;
        }
    }
    false
}

/// Under quadratic convergence the next residual is about `rn³ / r_prev²`: when that is far
/// below the tolerance, the full step is tried with the residual alone (the last evaluation).
/// `true` if it meets the tolerance (the iterate is then updated).
fn last_step<P: Problem + ?Sized>(
    problem: &mut P,
    it: &mut Iterate,
    dx: &[f64],
    lambda: f64,
    options: &NewtonOptions,
) -> bool {
    let rtn = trial_residual(problem, it, dx, lambda);
    if rtn <= problem.tolerance(&it.xt, options.tolerance) {
        it.x.copy_from_slice(&it.xt);
        it.rn = rtn;
        return true;
    }
    false
}

/// The full Newton step `dx` without line search (a step predicted to converge); whether it
/// was accepted (counted as an iteration).
fn full_step<P: Problem + ?Sized>(
    problem: &mut P,
    it: &mut Iterate,
    dx: &[f64],
    lambda: f64,
    settings: &NewtonSettings<'_>,
    options: &NewtonOptions,
    out: &mut NewtonOutcome,
) -> bool {
    out.at_x = false;
    let single = NewtonSettings {
        line_search: LineSearch {
            max_halvings: 0,
            ..settings.line_search
        },
        ..*settings
    };
    if !line_search(problem, it, dx, lambda, &single, options) {
        return false;
    }
    out.at_x = true;
    out.iterations += 1;
    true
}

/// The exact Jacobian (column-major `n × n`) and residual at the current iterate `it.x`, into
/// `it.jac`, `it.r`, `it.rn`, marking it exact and `out.at_x`; `false` (and `out.at_x`
/// cleared) if the evaluation fails.
fn exact_jacobian<P: Problem + ?Sized>(
    problem: &mut P,
    it: &mut Iterate,
    lambda: f64,
    out: &mut NewtonOutcome,
) -> bool {
    if problem.evaluate(&it.x, lambda, Some(&mut it.jac), &mut it.r) != Evaluated::Jacobian {
        out.at_x = false;
        return false;
    }
    (it.rn, it.exact, out.at_x) = (problem.norm(&it.r), true, true);
    true
}

/// After convergence on a residual-only evaluation: the exact Jacobian at the solution.
fn jacobian_at_solution<P: Problem + ?Sized>(
    problem: &mut P,
    it: &mut Iterate,
    lambda: f64,
    options: &NewtonOptions,
    out: &mut NewtonOutcome,
) {
    if exact_jacobian(problem, it, lambda, out) {
        out.converged = it.rn <= problem.tolerance(&it.x, options.tolerance);
    }
}

/// Whether the problem's check at the point `x + dx` a step predicted to converge reaches is
/// certified without an exact Jacobian there ([`Problem::certified`]).
fn certified_after<P: Problem + ?Sized>(
    problem: &mut P,
    x: &[f64],
    dx: &[f64],
    lambda: f64,
) -> bool {
    let next: Vec<f64> = x.iter().zip(dx).map(|(a, b)| a + b).collect();
    problem.certified(&next, lambda)
}

/// Damped Newton on `problem` at load factor `lambda` from `x0`.
pub fn newton<P: Problem + ?Sized>(
    problem: &mut P,
    x0: &[f64],
    lambda: f64,
    options: &NewtonOptions,
    settings: &NewtonSettings<'_>,
) -> NewtonOutcome {
    let n = problem.dim();
    let mut out = NewtonOutcome::unsolved(x0);
    let Some(it) = start(problem, x0, lambda, options, settings, &mut out) else {
        return out;
    };
    let mut run = Run {
        problem,
        lambda,
        options,
        settings,
        it,
        out,
        r_prev: f64::INFINITY,
        refresh: false,
        single_failed: false,
    };
    let mut lu = DenseLu::default();
    let mut dx = vec![0.0; n];
    while run.out.iterations < options.max_iterations {
        match run.iteration(&mut lu, &mut dx) {
            Turn::Next | Turn::Through => {}
            Turn::Converged => {
                run.out.converged = true;
                break;
            }
            Turn::Stop => break,
        }
    }
    run.finish()
}

/// What a stage of a Newton iteration leaves the loop to do.
enum Turn {
    /// The next iteration.
    Next,
    /// Stop: converged.
    Converged,
    /// Stop: failed.
    Stop,
    /// The next stage of this iteration.
    Through,
}

/// A damped Newton solve in progress: the problem at its load factor, the iterate, the
/// outcome so far, and the loop's memory (the previous residual norm, whether the exact
/// Jacobian is to be evaluated before the next step, whether the full step predicted to
/// converge failed).
struct Run<'a, 's, P: Problem + ?Sized> {
    problem: &'a mut P,
    lambda: f64,
    options: &'a NewtonOptions,
    settings: &'a NewtonSettings<'s>,
    it: Iterate,
    out: NewtonOutcome,
    r_prev: f64,
    refresh: bool,
    single_failed: bool,
}

impl<P: Problem + ?Sized> Run<'_, '_, P> {
    /// One iteration: the Newton direction `dx` (factored in `lu`), then the full step
    /// predicted to converge, a Broyden step or a last step, else the line search.
    fn iteration(&mut self, lu: &mut DenseLu, dx: &mut [f64]) -> Turn {
        if !self.direction(lu, dx) {
            return Turn::Stop;
        }
        if self.at_round_off(dx) {
            return Turn::Converged;
        }
        let tol = self.problem.tolerance(&self.it.x, self.options.tolerance);
        // Under superlinear convergence the next residual is about rn² / r_prev: a step
        // predicted to converge is taken with the Jacobian when the solve must end on one.
        let rn = self.it.rn;
        match self.predicted(dx, rn, tol) {
            Turn::Through => {}
            turn => return turn,
        }
        self.single_failed = false;
        match self.quick(dx, rn, tol) {
            Turn::Through => {}
            turn => return turn,
        }
        self.r_prev = self.it.rn;
        self.out.at_x = false;
        let (problem, it) = (&mut *self.problem, &mut self.it);
        if !line_search(problem, it, dx, self.lambda, self.settings, self.options) {
            return Turn::Stop;
        }
        self.out.at_x = true;
        self.out.iterations += 1;
        self.converged_or_next()
    }

    /// Whether the exact Newton step `dx` from the iterate (the problem's last evaluation) is
    /// below the rounding of the unknowns, for a problem that [stops at
    /// round-off](Problem::stops_at_round_off).
    fn at_round_off(&self, dx: &[f64]) -> bool {
        self.it.exact
            && self.out.at_x
            && self.problem.stops_at_round_off()
            && self.it.rn <= ROUND_OFF_RESIDUAL
            && max_norm(dx) <= ROUND_OFF_STEP * f64::EPSILON * max_norm(&self.it.x).max(1.0)
    }

    /// [`Turn::Converged`] if the iterate is within the tolerance, else [`Turn::Next`].
    fn converged_or_next(&self) -> Turn {
        if self.it.rn <= self.problem.tolerance(&self.it.x, self.options.tolerance) {
            Turn::Converged
        } else {
            Turn::Next
        }
    }

    /// The Newton direction `dx` of the iterate (the exact Jacobian first if a refresh is
    /// due); `false` if it cannot be evaluated or factored, or a first step is beyond the
    /// limit of the settings.
    fn direction(&mut self, lu: &mut DenseLu, dx: &mut [f64]) -> bool {
        if self.refresh
            && !self.it.exact
            && !exact_jacobian(&mut *self.problem, &mut self.it, self.lambda, &mut self.out)
        {
            return false;
        }
        self.refresh = false;
        if !lu.factor(dx.len(), &self.it.jac) {
            return false;
        }
        dx.iter_mut().zip(&self.it.r).for_each(|(d, r)| *d = -r);
        if !lu.solve_in_place(dx) {
            return false;
        }
        if let Some(limit) = self.settings.first_step_limit {
            if self.out.iterations == 0 && max_norm(dx) > limit {
                self.out.first_step = max_norm(dx);
                return false;
            }
        }
        true
    }

    /// When the solve must end on an exact Jacobian, the full step `dx` predicted to
    /// converge (residual `rn` now, tolerance `tol`), taken with the Jacobian; if it fails,
    /// the exact direction of the iterate next.
    fn predicted(&mut self, dx: &[f64], rn: f64, tol: f64) -> Turn {
        if !(self.settings.exact_at_solution
            && !self.single_failed
            && self.r_prev.is_finite()
            && rn * (rn / self.r_prev) <= 10.0 * tol
            && !certified_after(&mut *self.problem, &self.it.x, dx, self.lambda))
        {
            return Turn::Through;
        }
        let (problem, it, out) = (&mut *self.problem, &mut self.it, &mut self.out);
        if full_step(
            problem,
            it,
            dx,
            self.lambda,
            self.settings,
            self.options,
            out,
        ) {
            self.r_prev = rn;
            return self.converged_or_next();
        }
        // The full step failed: search along the exact Newton direction of the iterate.
        self.single_failed = true;
        if !self.it.exact {
            self.refresh = true;
            return Turn::Next;
        }
        Turn::Through
    }

    /// A Broyden step along `dx` (with Broyden's updates, or an updated Jacobian), or the
    /// last step of a solve converging fast enough to end without a line search.
    fn quick(&mut self, dx: &[f64], rn: f64, tol: f64) -> Turn {
        if self.settings.broyden || !self.it.exact {
            let was_exact = self.it.exact;
            self.out.at_x = false;
            let (problem, it) = (&mut *self.problem, &mut self.it);
            match broyden_step(problem, it, dx, self.lambda, self.settings, tol) {
                Broyden::Accepted(slow) => {
                    self.r_prev = rn;
                    self.refresh = slow;
                    self.out.at_x = true;
                    self.out.iterations += 1;
                    return self.converged_or_next();
                }
                Broyden::Refused if !was_exact => {
                    // The updated Jacobian failed: evaluate the exact one and retry.
                    self.refresh = true;
                    return Turn::Next;
                }
                Broyden::Refused => {}
            }
        } else if !self.settings.exact_at_solution
            && self.r_prev.is_finite()
            && self.it.rn < 0.1 * self.r_prev
            && self.it.rn * (self.it.rn / self.r_prev).powi(2) < 0.5 * tol
        {
            self.out.at_x = false;
            if last_step(
                &mut *self.problem,
                &mut self.it,
                dx,
                self.lambda,
                self.options,
            ) {
                self.out.iterations += 1;
                self.out.at_x = true;
                return Turn::Converged;
            }
        }
        Turn::Through
    }

    /// The outcome, with the exact Jacobian at the solution when the settings ask for one.
    fn finish(self) -> NewtonOutcome {
        let Self {
            problem,
            lambda,
            options,
            settings,
            mut it,
            mut out,
            ..
        } = self;
        if out.converged
            && settings.exact_at_solution
            && !(it.exact && out.at_x)
            && !problem.certified(&it.x, lambda)
        {
            jacobian_at_solution(problem, &mut it, lambda, options, &mut out);
        }
        out.finish(it)
    }
}

impl NewtonOutcome {
    /// No iteration yet from `x0`.
    fn unsolved(x0: &[f64]) -> Self {
        Self {
            x: x0.to_vec(),
            residual: f64::INFINITY,
            converged: false,
            iterations: 0,
            first_step: 0.0,
            jacobian: None,
            at_x: false,
            exact: false,
        }
    }

    /// The outcome at the last iterate `it`.
    fn finish(mut self, it: Iterate) -> Self {
        self.exact = it.exact && self.at_x;
        self.x = it.x;
        self.residual = it.rn;
        self.jacobian = Some(it.jac);
        self
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::super::{Evaluated, NewtonOptions, Problem};
    use super::*;

    /// Intersection of the circle |x| = 2 with the hyperbola x y = 1, scaled by λ on the
    /// right-hand side: r = (x² + y² - 4, x y - λ). Roots in closed form.
    struct Circle {
        evaluations: usize,
    }

    impl Problem for Circle {
        fn dim(&self) -> usize {
            2
        }
        fn evaluate(
            &mut self,
            x: &[f64],
            lambda: f64,
            jacobian: Option<&mut [f64]>,
            r: &mut [f64],
        ) -> Evaluated {
            self.evaluations += 1;
            r[0] = x[0] * x[0] + x[1] * x[1] - 4.0;
            r[1] = x[0] * x[1] - lambda;
            match jacobian {
                Some(j) => {
                    j.copy_from_slice(&[2.0 * x[0], x[1], 2.0 * x[1], x[0]]);
                    Evaluated::Jacobian
                }
                None => Evaluated::Residual,
            }
        }
    }

    fn settings(broyden: bool) -> NewtonSettings<'static> {
        NewtonSettings {
            line_search: LineSearch {
                factor: 0.5,
                max_halvings: 12,
            },
            condition: Armijo::default(),
            first_step_limit: None,
            residual_first: false,
            broyden,
            jacobian: None,
            exact_at_solution: false,
        }
    }

    const OPTS: NewtonOptions = NewtonOptions {
        tolerance: 1e-13,
        max_iterations: 40,
        continuation: false,
        max_load_steps: 1,
        throw: false,
    };

    /// x = sqrt(2 + sqrt(3)), y = 1/x: the root near (2, 0.5).
    fn exact_root() -> [f64; 2] {
        let x = (2.0 + 3f64.sqrt()).sqrt();
        [x, 1.0 / x]
    }

    #[test]
    fn newton_and_broyden_find_the_closed_form_root() {
        for broyden in [false, true] {
            let mut p = Circle { evaluations: 0 };
            let out = newton(&mut p, &[2.0, 0.6], 1.0, &OPTS, &settings(broyden));
            assert!(out.converged && out.at_x, "broyden {broyden}: {out:?}");
            let e = exact_root();
            assert!((out.x[0] - e[0]).abs() < 1e-12 && (out.x[1] - e[1]).abs() < 1e-12);
        }
    }

    #[test]
    fn newton_converges_quadratically() {
        // Residual norms of successive exact Newton iterates: e_{k+1} <= C e_k².
        let mut norms = Vec::new();
        for it in 1..=4 {
            let mut p = Circle { evaluations: 0 };
            let o = NewtonOptions {
                max_iterations: it,
                tolerance: 1e-300,
                ..OPTS
            };
            norms.push(newton(&mut p, &[2.0, 0.6], 1.0, &o, &settings(false)).residual);
        }
        for k in 1..3 {
            assert!(norms[k] <= 10.0 * norms[k - 1] * norms[k - 1], "{norms:?}");
        }
    }

    #[test]
    fn line_search_lengths_and_armijo() {
        let ls = LineSearch {
            factor: 0.5,
            max_halvings: 3,
        };
        assert_eq!(
            ls.lengths().collect::<Vec<_>>(),
            vec![1.0, 0.5, 0.25, 0.125]
        );
        let a = Armijo { c: 0.1 };
        assert!(a.accept(1.0, 1.0, 0.9) && !a.accept(1.0, 1.0, 0.95));
        assert!(a.accept(0.5, 1.0, 0.95));
    }

    /// `r(x) = K (x - a) + e(x)`: a root resolved only to `|e| / K`, `e` a deterministic
    /// evaluation noise of amplitude `noise` (from the bits of `x`); with `root` false,
    /// `r(x) = x² + 1`, which has no root.
    struct Stiff {
        root: bool,
        noise: f64,
        at_round_off: bool,
    }

    const STIFF_K: f64 = 1e9;
    const STIFF_A: f64 = 0.3;

    impl Problem for Stiff {
        fn dim(&self) -> usize {
            1
        }
        fn evaluate(
            &mut self,
            x: &[f64],
            _lambda: f64,
            jacobian: Option<&mut [f64]>,
            r: &mut [f64],
        ) -> Evaluated {
            let e = self.noise * ((x[0].to_bits() % 1000) as f64 / 500.0 - 1.0);
            let j;
            (r[0], j) = if self.root {
                (STIFF_K * (x[0] - STIFF_A) + e, STIFF_K)
            } else {
                (x[0] * x[0] + 1.0, 2.0 * x[0])
            };
            match jacobian {
                Some(jac) => {
                    jac[0] = j;
                    Evaluated::Jacobian
                }
                None => Evaluated::Residual,
            }
        }
        fn stops_at_round_off(&self) -> bool {
            self.at_round_off
        }
    }

    #[test]
    fn an_exact_step_below_the_rounding_of_the_unknowns_ends_a_solve_that_allows_it() {
        let o = NewtonOptions {
            tolerance: 1e-10,
            ..OPTS
        };
        for at_round_off in [false, true] {
            let mut p = Stiff {
                root: true,
                noise: 1e-6,
                at_round_off,
            };
            let out = newton(&mut p, &[0.2], 1.0, &o, &settings(false));
            assert_eq!(out.converged, at_round_off, "{out:?}");
            // Where the noise allows: |x - a| <= |e| / K (and the rounding of a).
            assert!((out.x[0] - STIFF_A).abs() <= 1e-6 / STIFF_K + 4.0 * f64::EPSILON);
            // Its residual is the noise's, above the tolerance.
            assert!(!at_round_off || out.residual > o.tolerance, "{out:?}");
        }
        // A residual without a root is never reported converged.
        let mut p = Stiff {
            root: false,
            noise: 0.0,
            at_round_off: true,
        };
        let out = newton(&mut p, &[0.5], 1.0, &o, &settings(false));
        assert!(!out.converged && out.residual >= 1.0, "{out:?}");
    }

    #[test]
    fn a_long_first_step_is_refused() {
        let mut p = Circle { evaluations: 0 };
        let s = NewtonSettings {
            first_step_limit: Some(0.1),
            ..settings(false)
        };
        let out = newton(&mut p, &[3.0, 0.0], 1.0, &OPTS, &s);
        assert!(!out.converged && out.first_step > 0.1 && out.iterations == 0);
    }
}
