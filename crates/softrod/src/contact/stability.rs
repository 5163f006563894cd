//! Stability of an equilibrium with a constrained tip: conjugate points along the rod and
//! the stiffness of the free tip directions.
//!
//! With `H_c` the second variation of the rod clamped at both ends and `K_ff` the tip
//! stiffness (inverse of the tip compliance) restricted to the directions the constraint
//! leaves free, the inertia of a Schur complement gives `n₋(H) = n₋(H_c) + n₋(K_ff)` for the
//! constrained rod. `n₋(H_c)` is the number of conjugate points on `(0, L)` (Jacobi's
//! condition, counted with multiplicity): the arc lengths where the pose block `X(s)` of the
//! base-wrench columns is singular. They are counted as the passages through `-1` of the
//! eigenvalues of the unitary `U = (X - iY)(X + iY)⁻¹` (`Y(s)` the wrench block; `X, Y`
//! scaled as the shooting unknowns), which start at `-1` at the base and turn one way
//! (Legendre's condition): a symmetric rod whose conjugate point is double (a round rod
//! under torque) changes the sign of `det X` twice at once, and is counted right.

use nalgebra::{Complex, Matrix3, Matrix6, SymmetricEigen};

use super::problem::{Constrained, Site};
use super::ContactState;

use crate::cosserat::blocks;
use crate::cosserat::equations::{Column, Evaluator, FULL, STATE};
use crate::cosserat::shooting::Shooting;
use crate::cosserat::statics::Integrator;
use crate::cosserat::{compliance_stability, Stability, NEUTRAL_MARGIN};
use crate::integrate::march::{march, Scheme};

/// Sorted arguments (rad, in (-π, π]) of the eigenvalues of `(X - iY)(X + iY)⁻¹`.
fn angles(x: &Matrix6<f64>, y: &Matrix6<f64>) -> Option<[f64; 6]> {
    let z: Matrix6<Complex<f64>> = Matrix6::from_fn(|i, j| Complex::new(x[(i, j)], y[(i, j)]));
    let zi = z.try_inverse()?;
    let u = z.conjugate() * zi;
    let ev = u.schur().eigenvalues()?;
    let mut a: [f64; 6] = std::array::from_fn(|k| ev[k].arg());
    if !a.iter().all(|v| v.is_finite()) {
        return None;
    }
    a.sort_by(f64::total_cmp);
    Some(a)
}

fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let mut d = a % t;
    if d > std::f64::consts::PI {
        d -= t;
    } else if d <= -std::f64::consts::PI {
        d += t;
    }
    d
}

/// Number of passages through `π` between consecutive sorted angle sets, with the sign of
/// the passage (+1 upward), matching the sets by the cyclic shift of least motion.
fn passages(a: &[f64; 6], b: &[f64; 6]) -> i32 {
    let mut best = (f64::INFINITY, 0usize);
    for shift in 0..6 {
        let cost: f64 = (0..6).map(|k| wrap(b[(k + shift) % 6] - a[k]).abs()).sum();
        if cost < best.0 {
            best = (cost, shift);
        }
    }
    let mut n = 0;
    for k in 0..6 {
        let d = wrap(b[(k + best.1) % 6] - a[k]);
        let end = a[k] + d;
        if end > std::f64::consts::PI {
            n += 1;
        } else if end <= -std::f64::consts::PI {
            n -= 1;
        }
    }
    n
}

/// Conjugate points on `(0, L)` of the rod of `sh` at the scaled base wrench `x`, and the
/// scaled tip pose block `X(L)`; `None` if the march fails.
pub(crate) fn conjugate_points(sh: &mut Shooting<'_>, x: &[f64]) -> Option<(usize, Matrix6<f64>)> {
    let model = sh.eq.model;
    let (length, force) = (model.length(), model.force_scale());
    sh.eq.load_factor = 1.0;
    sh.ws.set_columns(&[Column::Free; 6], &[]);
    let y0: [f64; FULL] = sh.eq.initial(x);
    let scheme = match sh.integrator {
        Integrator::Rk4 { .. } => Scheme::Rk4(&sh.plan),
        Integrator::Adaptive(options) => Scheme::Adaptive {
            options,
            controlled: STATE,
        },
    };
    let eq = sh.eq;
    let mut ev = Evaluator { eq, ws: &mut sh.ws };
    let mut sets: Vec<[f64; 6]> = Vec::new();
    let mut failed = false;
    let mut tip = Matrix6::zeros();
    march(&mut ev, model.breaks(), &[], y0, scheme, |_, s, _, y| {
        if s <= 0.0 {
            return;
        }
        let (xb, yb) = blocks(y, length, force);
        tip = xb;
        match angles(&xb, &yb) {
            Some(a) => sets.push(a),
            None => failed = true,
        }
    })
    .ok()?;
    if failed || sets.is_empty() {
        return None;
    }
    // The direction the angles leave -1 from the base.
    let first: f64 = sets[0].iter().map(|a| a.signum()).sum();
    let direction = if first > 0.0 { -1 } else { 1 };
    let net: i32 = sets.windows(2).map(|w| passages(&w[0], &w[1])).sum();
    Some(((net * direction).max(0) as usize, tip))
}

/// The free-direction tip stiffness check: the smallest eigenvalue of the symmetric part of
/// the dimensionless tip stiffness `K̂ = Y X̂⁻¹` restricted to the directions `free` of the
/// frame `frame`, and the number of its negative eigenvalues; `None` if `X̂` is singular (the
/// tip at a conjugate point) or nothing is free.
pub(crate) fn free_stiffness(
    y: &Matrix6<f64>,
    x: &Matrix6<f64>,
    frame: &Matrix3<f64>,
    free: &[usize],
) -> Option<(f64, usize)> {
    if free.is_empty() {
        return None;
    }
    let k = y * x.try_inverse()?;
    let mut t = Matrix6::zeros();
    t.fixed_view_mut::<3, 3>(0, 0).copy_from(frame);
    t.fixed_view_mut::<3, 3>(3, 3).copy_from(frame);
    let kc = t.transpose() * k * t;
    let n = free.len();
    let sub = nalgebra::DMatrix::from_fn(n, n, |i, j| {
        0.5 * (kc[(free[i], free[j])] + kc[(free[j], free[i])])
    });
    let eig = SymmetricEigen::new(sub);
    let margin = eig.eigenvalues.min();
    let negative = eig
        .eigenvalues
        .iter()
        .filter(|v| **v < -NEUTRAL_MARGIN)
        .count();
    margin.is_finite().then_some((margin, negative))
}

/// Whether the stability of `p`'s equilibria holds its contacts ([`constrained_stability`]):
/// a free tip and frictionless or sticking point contacts (at the tip or inside the rod).
/// A sticking contact stays sticking under a small enough disturbance (its force is inside
/// the cone), so it holds its point as a bilateral constraint; a sliding one does not (its
/// friction force is not conservative).
pub(super) fn held_contacts(p: &Constrained<'_>) -> bool {
    p.tip.is_none()
        && !p.active.is_empty()
        && p.active.iter().all(|a| {
            let o = &p.obstacles[a.obstacle];
            matches!(a.site, Site::Tip | Site::Interior)
                && match a.state {
                    ContactState::Frictionless => o.friction() == 0.0,
                    ContactState::Stick => true,
                    ContactState::Slide => false,
                }
        })
}

/// The stability of a free-tip equilibrium with its frictionless or sticking point contacts
/// held as constraints (see `docs/stability.md`, "Under contact"): the tip criterion of
/// `solve_statics` on the tip compliance with the active contacts as constraints (each
/// contact keeps its gap, slides along the rod to its least gap and turns its force with the
/// obstacle's normal; a sticking one holds its point), which is exact when the rod with its
/// tip clamped too and the contacts held has no conjugate point. `None` where it does not
/// apply (a held tip, a sliding contact, a contact interval or belt, or a singular
/// constrained problem): the contacts are then read as dead loads. Returns it with the
/// compliance under contact (m, rad per N, N m; world) it was read from. The last pass of
/// `p` is kept.
pub(super) fn constrained_stability(
    p: &mut Constrained<'_>,
    x: &[f64],
) -> Option<(Stability, Matrix6<f64>)> {
    if !held_contacts(p) {
        return None;
    }
    let key = p.key(x, 1.0);
    let exact = p
        .last
        .as_ref()
        .is_some_and(|pass| pass.key == key && pass.jacobian.is_some());
    let c = if exact {
        p.compliance(x)
    } else {
        // (One march with the columns at `x`; the last pass kept for the solution.)
        let kept = p.last.take();
        let c = p.compliance(x);
        p.last = kept;
        c
    };
    let c = c?;
    compliance_stability(&c, p.model.length(), p.model.force_scale()).map(|st| (st, c))
}
