//! Stability of an equilibrium with a constrained tip: conjugate points along the rod and
//! the stiffness of the free tip directions.
//!
//! With `H_c` the second variation of the rod clamped at both ends and `K_ff` the tip
//! stiffness (inverse of the tip compliance) restricted to the directions the constraint
//! leaves free, the inertia of a Schur complement gives `n₋(H) = n₋(H_c) + n₋(K_ff)` for the
//! constrained rod. `n₋(H_c)` is the number of conjugate points on `(0, L)` (Jacobi's
//! condition, counted with multiplicity): the arc lengths where the pose block `X(s)` of the
//! base-wrench columns is singular, counted along the final march with the columns by the
//! shooting's [`JacobiCheck`](crate::cosserat::JacobiCheck) (drops in the inertia of
//! `Yᵀ X`): a symmetric rod whose conjugate point is double (a round rod under torque)
//! changes the sign of `det X` twice at once, and is counted right.

use nalgebra::{Matrix3, Matrix6, SymmetricEigen};

use super::problem::{Constrained, Site};
use super::ContactState;

use crate::cosserat::{compliance_stability, Stability, NEUTRAL_MARGIN};

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
