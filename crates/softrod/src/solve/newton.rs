//! Damped Newton at one load factor, with Broyden updates of the Jacobian between exact
//! evaluations.

use super::{max_norm, Evaluated, NewtonOptions, Problem};
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
}

/// Contraction of the residual below which a Broyden step keeps the updated Jacobian.
const BROYDEN_CONTRACTION: f64 = 0.5;

/// Damped Newton on `problem` at load factor `lambda` from `x0`.
pub fn newton<P: Problem + ?Sized>(
    problem: &mut P,
    x0: &[f64],
    lambda: f64,
    options: &NewtonOptions,
    settings: &NewtonSettings<'_>,
) -> NewtonOutcome {
    let n = problem.dim();
    let mut x = x0.to_vec();
    let mut r = vec![0.0; n];
    let mut jac = vec![0.0; n * n];
    let mut out = NewtonOutcome {
        x: x.clone(),
        residual: f64::INFINITY,
        converged: false,
        iterations: 0,
        first_step: 0.0,
        jacobian: None,
        at_x: false,
    };
    let want = !settings.residual_first && settings.jacobian.is_none();
    let ev = problem.evaluate(&x, lambda, want.then_some(&mut jac[..]), &mut r);
    if ev == Evaluated::Failed {
        return out;
    }
    let mut rn = problem.norm(&r);
    out.residual = rn;
    out.at_x = true;
    let mut have_j = ev == Evaluated::Jacobian;
    if !have_j {
        if let Some(j) = settings.jacobian {
            jac.copy_from_slice(j);
            have_j = true;
        }
    }
    if rn <= problem.tolerance(&x, options.tolerance) {
        out.converged = true;
        out.jacobian = have_j.then(|| jac.clone());
        return out;
    }
    if !rn.is_finite() {
        return out;
    }
    if !have_j {
        if problem.evaluate(&x, lambda, Some(&mut jac), &mut r) != Evaluated::Jacobian {
            out.at_x = false;
            return out;
        }
        rn = problem.norm(&r);
    }
    let mut exact = settings.jacobian.is_none() || ev == Evaluated::Jacobian;
    let mut lu = DenseLu::default();
    let mut dx = vec![0.0; n];
    let mut xt = vec![0.0; n];
    let mut rt = vec![0.0; n];
    let mut jt = vec![0.0; n * n];
    let mut r_prev = f64::INFINITY;
    let mut refresh = false;
    let mut iteration = 0;
    while iteration < options.max_iterations {
        if refresh && !exact {
            // Evaluate the exact Jacobian at the current iterate.
            if problem.evaluate(&x, lambda, Some(&mut jac), &mut r) != Evaluated::Jacobian {
                out.at_x = false;
                break;
            }
            rn = problem.norm(&r);
            exact = true;
            out.at_x = true;
        }
        refresh = false;
        if !lu.factor(n, &jac) {
            break;
        }
        for k in 0..n {
            dx[k] = -r[k];
        }
        if !lu.solve_in_place(&mut dx) {
            break;
        }
        if let Some(limit) = settings.first_step_limit {
            if iteration == 0 && out.iterations == 0 && max_norm(&dx) > limit {
                out.first_step = max_norm(&dx);
                break;
            }
        }
        let tol = |p: &P, x: &[f64]| p.tolerance(x, options.tolerance);
        if settings.broyden || !exact {
            // A full step with the residual alone; Broyden's update of the Jacobian.
            for k in 0..n {
                xt[k] = x[k] + dx[k];
            }
            let ev = problem.evaluate(&xt, lambda, None, &mut rt);
            out.at_x = false;
            let rtn = if ev == Evaluated::Failed {
                f64::INFINITY
            } else {
                problem.norm(&rt)
            };
            if rtn <= tol(problem, &xt) || settings.condition.accept(1.0, rn, rtn) {
                // J += (Δr - J Δx) Δxᵀ / (Δxᵀ Δx), with Δx = dx.
                let dd: f64 = dx.iter().map(|v| v * v).sum();
                if dd > 0.0 {
                    let mut u = vec![0.0; n];
                    for i in 0..n {
                        let mut jdx = 0.0;
                        for k in 0..n {
                            jdx += jac[i + k * n] * dx[k];
                        }
                        u[i] = (rt[i] - r[i] - jdx) / dd;
                    }
                    for c in 0..n {
                        for i in 0..n {
                            jac[i + c * n] += u[i] * dx[c];
                        }
                    }
                }
                refresh = rtn > BROYDEN_CONTRACTION * rn;
                x.copy_from_slice(&xt);
                r.copy_from_slice(&rt);
                r_prev = rn;
                rn = rtn;
                exact = false;
                out.at_x = true;
                out.iterations += 1;
                iteration += 1;
                if rn <= tol(problem, &x) {
                    out.converged = true;
                    break;
                }
                continue;
            }
            if !exact {
                // The updated Jacobian failed: evaluate the exact one and retry.
                refresh = true;
                continue;
            }
        } else if r_prev.is_finite()
            && rn < 0.1 * r_prev
            && rn * (rn / r_prev).powi(2) < 0.5 * tol(problem, &x)
        {
            // Under quadratic convergence the next residual is about rn³ / r_prev²: when far
            // below the tolerance, try the full step with the residual alone (the last pass).
            for k in 0..n {
                xt[k] = x[k] + dx[k];
            }
            let ev = problem.evaluate(&xt, lambda, None, &mut rt);
            out.at_x = false;
            if ev != Evaluated::Failed {
                let rtn = problem.norm(&rt);
                if rtn <= tol(problem, &xt) {
                    x.copy_from_slice(&xt);
                    rn = rtn;
                    out.iterations += 1;
                    out.at_x = true;
                    out.converged = true;
                    break;
                }
            }
        }
        // Exact Newton direction, backtracking line search with exact Jacobians.
        r_prev = rn;
        let mut accepted = false;
        for alpha in settings.line_search.lengths() {
            for k in 0..n {
                xt[k] = x[k] + alpha * dx[k];
            }
            let ev = problem.evaluate(&xt, lambda, Some(&mut jt), &mut rt);
            out.at_x = false;
            if ev != Evaluated::Jacobian {
                continue;
            }
            let rtn = problem.norm(&rt);
            if settings.condition.accept(alpha, rn, rtn) || rtn <= tol(problem, &xt) {
                x.copy_from_slice(&xt);
                r.copy_from_slice(&rt);
                jac.copy_from_slice(&jt);
                rn = rtn;
                exact = true;
                accepted = true;
                out.at_x = true;
                break;
            }
        }
        if !accepted {
            break;
        }
        out.iterations += 1;
        iteration += 1;
        if rn <= tol(problem, &x) {
            out.converged = true;
            break;
        }
    }
    out.x = x;
    out.residual = rn;
    out.jacobian = Some(jac);
    out
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
        assert_eq!(ls.lengths().collect::<Vec<_>>(), vec![1.0, 0.5, 0.25, 0.125]);
        let a = Armijo { c: 0.1 };
        assert!(a.accept(1.0, 1.0, 0.9) && !a.accept(1.0, 1.0, 0.95));
        assert!(a.accept(0.5, 1.0, 0.95));
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
