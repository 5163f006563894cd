//! Newton at the full contact targets: an exact Jacobian at the start, Broyden's updates
//! between residual-only marches, and the predictor of newly added contacts.

use super::problem::{Constrained, Site};
use super::ContactState;
use crate::cosserat::statics::MAX_LINE_SEARCH_HALVINGS;
use crate::math::linalg::DenseLu;
use crate::solve::{max_norm, Evaluated, NewtonOptions, Problem};

/// Effort of a solve.
#[derive(Default)]
pub(super) struct Effort {
    pub(super) iterations: usize,
    pub(super) load_steps: usize,
}

/// Newton at the full contact targets from `x`; the last pass left at the result.
pub(super) fn correct(
    p: &mut Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    exact_newton(p, x, opts, effort, true, false).map(|(x, _)| x)
}

/// Residual below which [`exact_newton`] stops refining a converged iterate: a thousandth
/// of the tolerance (three digits beyond it, enough for the global balance of the
/// reactions), never below round-off. With a sticking contact, round-off itself (the
/// refinement goes on while it helps): its rows hold a displacement of the rod along its
/// axis, where the axial stiffness `E A / L` turns a residual of 1e-13 L into a friction
/// force some 1e-4 of the contact force of a slender rod.
fn refinement_floor(p: &Constrained<'_>, opts: &NewtonOptions) -> f64 {
    if p.active.iter().any(|a| a.state == ContactState::Stick) {
        return 0.0;
    }
    (opts.tolerance * 1e-3).max(64.0 * f64::EPSILON)
}

/// Newton at the full contact targets from `x` (the residual alone first when
/// `residual_first`): an exact Jacobian (one march with the variational columns) at the
/// start, then Broyden's rank-one updates between residual-only marches; a full step that
/// does not lower the residual's max norm (Armijo) is retried with the exact Jacobian at the
/// current iterate, and an exact step is halved until it does. Once within the tolerance, up
/// to two more steps are taken while they lower the residual toward round-off, so that the
/// balance of the reactions holds to the digits of the loads. Returns the iterate and its
/// residual, the last pass at it; `None` if the tolerance is not met.
pub(super) fn exact_newton(
    p: &mut Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
    effort: &mut Effort,
    residual_first: bool,
    normal_first: bool,
) -> Option<(Vec<f64>, f64)> {
    let n = p.dim();
    let mut x = x.to_vec();
    let mut r = vec![0.0; n];
    let mut j = vec![0.0; n * n];
    if residual_first {
        if p.evaluate(&x, 1.0, None, &mut r) == Evaluated::Failed {
            return None;
        }
        let norm = max_norm(&r);
        if norm <= refinement_floor(p, opts) {
            return Some((x, norm));
        }
    }
    let mut exact = start_jacobian(p, &x, residual_first, &mut j, &mut r)?;
    let mut norm = max_norm(&r);
    let (mut xt, mut rt) = (vec![0.0; n], vec![0.0; n]);
    if normal_first && predict(p, &mut x, &mut j, &mut r, effort) {
        exact = false;
        norm = max_norm(&r);
    }
    let mut lu = DenseLu::default();
    let mut refined = 0;
    // At most `max_iterations` accepted steps, and as many exact re-evaluations.
    let (mut steps, mut retries) = (0, 0);
    while steps < opts.max_iterations && retries <= opts.max_iterations {
        if norm <= opts.tolerance {
            if norm <= refinement_floor(p, opts) || refined >= 2 || !p.refine {
                p.solved = Some((p.active.clone(), j));
                return Some((x, norm));
            }
            refined += 1;
        }
        let mut dx: Vec<f64> = r.iter().map(|v| -v).collect();
        let accepted = if lu.factor(n, &j) && lu.solve_in_place(&mut dx) {
            let mut alpha = 1.0;
            let mut accepted = None;
            for _ in 0..=MAX_LINE_SEARCH_HALVINGS {
                for k in 0..n {
                    xt[k] = x[k] + alpha * dx[k];
                }
                if p.evaluate(&xt, 1.0, None, &mut rt) != Evaluated::Failed {
                    let trial = max_norm(&rt);
                    if trial <= (1.0 - 1e-4 * alpha) * norm {
                        accepted = Some(alpha);
                        break;
                    }
                }
                if norm <= opts.tolerance || !exact {
                    // Refining, or a Broyden step: a step that does not help is not halved.
                    break;
                }
                alpha *= 0.5;
            }
            accepted
        } else {
            None
        };
        let Some(alpha) = accepted else {
            if exact {
                break;
            }
            // A singular update, or a step of it that does not help: the exact Jacobian at
            // the iterate, and its step.
            retries += 1;
            if p.evaluate(&x, 1.0, Some(&mut j), &mut r) != Evaluated::Jacobian {
                break;
            }
            exact = true;
            norm = max_norm(&r);
            continue;
        };
        effort.iterations += 1;
        steps += 1;
        let step: Vec<f64> = dx.iter().map(|v| alpha * v).collect();
        broyden(&mut j, &step, &r, &rt);
        exact = false;
        std::mem::swap(&mut x, &mut xt);
        std::mem::swap(&mut r, &mut rt);
        norm = max_norm(&r);
    }
    if norm > opts.tolerance {
        return None;
    }
    // The last pass back at the iterate.
    if p.evaluate(&x, 1.0, None, &mut r) == Evaluated::Failed {
        return None;
    }
    p.solved = Some((p.active.clone(), j));
    Some((x, norm))
}

/// The Jacobian `j` and residual `r` at `x` that Newton starts from: the one handed over in
/// `p.hint` for the current active set (from the coarse mesh, or the solve that found `x`;
/// `r` already evaluated if `residual_first`), else the exact one. Returns whether it is
/// exact; `None` if the evaluation fails.
fn start_jacobian(
    p: &mut Constrained<'_>,
    x: &[f64],
    residual_first: bool,
    j: &mut Vec<f64>,
    r: &mut [f64],
) -> Option<bool> {
    let n = p.dim();
    let hint = p
        .hint
        .take()
        .filter(|(a, h)| *a == p.active && h.len() == n * n);
    if let Some((_, h)) = hint {
        if !residual_first && p.evaluate(x, 1.0, None, r) == Evaluated::Failed {
            return None;
        }
        *j = h;
        return Some(false);
    }
    (p.evaluate(x, 1.0, Some(j), r) == Evaluated::Jacobian).then_some(true)
}

/// The predictor of newly added contacts ([`normal_step`]) from `x` with the exact Jacobian
/// `j` and residual `r` there: taken (and `j` updated by Broyden's formula) if it lowers the
/// gaps; `true` then, with `x`, `j` and `r` at the new iterate.
fn predict(
    p: &mut Constrained<'_>,
    x: &mut Vec<f64>,
    j: &mut [f64],
    r: &mut Vec<f64>,
    effort: &mut Effort,
) -> bool {
    let Some(dx) = normal_step(p, x, j, r) else {
        return false;
    };
    let xt: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + b).collect();
    let mut rt = vec![0.0; r.len()];
    let offsets = p.offsets();
    let gaps = |r: &[f64]| offsets.iter().map(|&o| r[o].abs()).fold(0.0, f64::max);
    if p.evaluate(&xt, 1.0, None, &mut rt) == Evaluated::Failed || gaps(&rt) >= gaps(r) {
        return false;
    }
    effort.iterations += 1;
    broyden(j, &dx, r, &rt);
    *x = xt;
    *r = rt;
    true
}

/// Broyden's update of the column-major Jacobian `j` by the step `dx` that took the
/// residual from `r` to `rt`: `J += (Δr - J Δx) Δxᵀ / (Δxᵀ Δx)`.
fn broyden(j: &mut [f64], dx: &[f64], r: &[f64], rt: &[f64]) {
    let n = dx.len();
    let ss: f64 = dx.iter().map(|v| v * v).sum();
    if ss <= 0.0 {
        return;
    }
    let mut u: Vec<f64> = (0..n).map(|i| rt[i] - r[i]).collect();
    for (c, sc) in dx.iter().enumerate() {
        for (i, ui) in u.iter_mut().enumerate() {
            *ui -= j[i + n * c] * sc;
        }
    }
    for (c, sc) in dx.iter().enumerate() {
        let w = sc / ss;
        for (i, ui) in u.iter().enumerate() {
            j[i + n * c] += ui * w;
        }
    }
}

/// The step from `x` (Jacobian `j`, residual `r`, the last pass at `x`) of the linearised
/// problem with every contact held at its arc length and its force changed along the
/// obstacle's normal there: the tip rows and the gap rows solved for the base wrench and one
/// normal force per contact (the contact-free compliance along the normal gives the force
/// that closes the gap). `None` if that system is singular.
fn normal_step(p: &Constrained<'_>, x: &[f64], j: &[f64], r: &[f64]) -> Option<Vec<f64>> {
    if p.active.iter().any(|a| a.site.held()) {
        return None;
    }
    let n = p.dim();
    let forces = p.normal_forces(x);
    let offsets = p.offsets();
    let m = 6 + p.active.len();
    let rows: Vec<usize> = (0..6).chain(offsets.iter().copied()).collect();
    let first_force: Vec<usize> = p
        .active
        .iter()
        .zip(&offsets)
        .map(|(a, &o)| if a.site == Site::Tip { o } else { o + 1 })
        .collect();
    let mut a = vec![0.0; m * m];
    for c in 0..6 {
        for (ri, &i) in rows.iter().enumerate() {
            a[ri + m * c] = j[i + n * c];
        }
    }
    for (k, &f0) in first_force.iter().enumerate() {
        let normal = forces.get(k)?.1;
        for (ri, &i) in rows.iter().enumerate() {
            a[ri + m * (6 + k)] = (0..3).map(|q| j[i + n * (f0 + q)] * normal[q]).sum();
        }
    }
    let mut rhs: Vec<f64> = rows.iter().map(|&i| -r[i]).collect();
    let mut lu = DenseLu::default();
    if !(lu.factor(m, &a) && lu.solve_in_place(&mut rhs)) {
        return None;
    }
    let mut dx = vec![0.0; n];
    dx[..6].copy_from_slice(&rhs[..6]);
    for (k, &f0) in first_force.iter().enumerate() {
        let normal = forces[k].1;
        for q in 0..3 {
            dx[f0 + q] = rhs[6 + k] * normal[q];
        }
    }
    Some(dx)
}
