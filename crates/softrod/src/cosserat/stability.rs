//! Stability of a Cosserat-rod equilibrium from the tip columns of the shooting problem.
//!
//! The rod is clamped at its base and free at its tip. Its equilibria are the stationary
//! points of the potential energy (elastic energy, `τ ℓ_i` for a tendon held at tension `τ`,
//! the work of dead external loads); an equilibrium is stable when the second variation `H`
//! of the energy is positive definite. Write `C` for the 6×6 tangent compliance at the tip
//! (tip twist per extra dead tip wrench, tendons at fixed tension) and `H_c` for the second
//! variation of the same rod with its tip clamped too. The inertia of a Schur complement
//! (Haynsworth) gives
//!
//! ```text
//! n₋(H) = n₋(H_c) + n₋(C),
//! ```
//!
//! `n₋` the number of negative eigenvalues. The first term counts the conjugate points of the
//! doubly clamped problem along the rod (Jacobi's condition; Till & Rucker's test on the
//! determinant of the pose block of the shooting Jacobian); it vanishes unless the rod, with
//! its tip clamped in the solved pose, would buckle on its own; it is counted along the march of
//! the columns ([`JacobiCheck`]). The second is what a user feels at the tip: a direction in
//! which the tip moves against an extra push. softrod reports the tip condition as the margin,
//! and stability when both terms vanish:
//!
//! * `stability_margin` = the smallest eigenvalue of the symmetric part of the dimensionless
//!   tip stiffness `K̂ = D C⁻¹ D / (E I(0)/L)`, `D = diag(L, L, L, 1, 1, 1)`; computed as
//!   `min 1/μ` over the eigenvalues `μ` of the symmetric part of `Ĉ = K̂⁻¹ = D⁻¹ X Y⁻¹`,
//!   where `Y` is the shooting Jacobian (scaled tip residual per scaled base wrench) and `X`
//!   the tip twist per scaled base wrench, both from the six base-wrench columns of one
//!   march at the solution. Directions of zero compliance (the axis of a straight
//!   inextensible, unshearable rod: constraints, not degrees of freedom) are left out.
//! * `stable` = `stability_margin > -1e-8` ([`NEUTRAL_MARGIN`]: a neutral mode, such as the
//!   rotation of a buckled round column about its load axis, counts as stable), no conjugate
//!   point, and a march that resolved the columns ([`JacobiCheck`]).
//!
//! Follower (body-frame) loads are not conservative: the margin is then that of the
//! symmetric part of the tangent stiffness (loss of it is divergence; flutter is not
//! detected). See `docs/stability.md`.
//!
//! # References
//! J. Till, D. C. Rucker, "Elastic stability of Cosserat rods and parallel continuum robots",
//! IEEE Trans. Robotics 33(3), 2017. E. V. Haynsworth, "Determination of the inertia of a
//! partitioned Hermitian matrix", Linear Algebra Appl. 1(1), 1968.

use nalgebra::{Matrix6, SymmetricEigen, Vector6};

use super::equations::{col_rot, rot, rotation_variation, v3, COLUMN, DM, DN, FULL, STATE};
use crate::math::linalg::Lu6;

/// Margin within which an equilibrium counts as neutral and is reported stable: a rod with
/// a symmetry about its load (a round column under its own weight) has a zero-stiffness mode
/// in its buckled states, the rotation of the shape about the load axis.
pub const NEUTRAL_MARGIN: f64 = 1e-8;

/// Relative size of a tip-compliance eigenvalue below which its direction counts as a
/// constraint (zero compliance to round-off), not as a degree of freedom.
pub const CONSTRAINT_COMPLIANCE: f64 = 1e-9;

/// Smallest stability margin at the last exact columns of a solve for which [`certifies`]
/// vouches for the stability at the solution without evaluating its columns there.
pub const CERTIFIED_MARGIN: f64 = 0.05;

/// Assumed bound on the rate of change of the stability margin per scaled unit of the base
/// wrench (max norm) between the last exact columns and the solution (see [`certifies`]).
pub const MARGIN_RATE: f64 = 10.0;

/// Whether the stability `s` from the exact columns at a point `distance` (max norm of the
/// scaled base wrench) from a solution certifies that solution stable: `s` is stable with a
/// margin of at least [`CERTIFIED_MARGIN`] and [`MARGIN_RATE`] `distance` more, so that a
/// margin changing by at most [`MARGIN_RATE`] per unit stays above [`CERTIFIED_MARGIN`] at the
/// solution. Never certifies an unstable, critical or nearly critical state: those are judged
/// from the columns at the solution itself (see `docs/stability.md`).
pub(crate) fn certifies(s: &Stability, distance: f64) -> bool {
    s.stable && distance.is_finite() && s.margin >= CERTIFIED_MARGIN + MARGIN_RATE * distance
}

/// The stability of one equilibrium (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stability {
    /// Whether the tip tangent stiffness is positive definite (`margin > -NEUTRAL_MARGIN`).
    pub stable: bool,
    /// Smallest eigenvalue of the symmetric part of the dimensionless tip stiffness.
    pub margin: f64,
    /// For an unstable equilibrium, the change of the scaled base wrench that moves the rod
    /// along its softest unstable mode (unit dimensionless tip wrench).
    pub(crate) mode: Option<[f64; 6]>,
}

/// The eigen-decomposition of the symmetric part of a dimensionless tip compliance `c`, its
/// smallest stiffness `1/μ` over the eigenvalues `μ` (directions of zero compliance, below
/// [`CONSTRAINT_COMPLIANCE`] of the largest, left out) and the index of that eigenvalue;
/// `None` if no direction is left.
fn softest(c: &Matrix6<f64>) -> Option<(SymmetricEigen<f64, nalgebra::U6>, f64, Option<usize>)> {
    let eig = SymmetricEigen::new((c + c.transpose()) * 0.5);
    let big = eig.eigenvalues.amax();
    let mut margin = f64::INFINITY;
    let mut softest = None;
    for (k, &mu) in eig.eigenvalues.iter().enumerate() {
        if mu.abs() <= CONSTRAINT_COMPLIANCE * big {
            continue;
        }
        let stiffness = 1.0 / mu;
        if stiffness < margin {
            margin = stiffness;
            softest = Some(k);
        }
    }
    margin.is_finite().then_some((eig, margin, softest))
}

/// The stability read from a tip compliance `c` (m, rad per N, N m; world) of a rod of length
/// `length` and force scale `force` (`E I(0) / L²`, N): the tip criterion on its
/// dimensionless form `(E I(0) / L) D⁻¹ c D⁻¹` (see the module documentation), without a
/// mode; `None` if it is not finite or has no direction of nonzero compliance.
pub(crate) fn compliance_stability(c: &Matrix6<f64>, length: f64, force: f64) -> Option<Stability> {
    if !c.iter().all(|v| v.is_finite()) {
        return None;
    }
    let d = |i: usize| if i < 3 { length } else { 1.0 };
    let hat = Matrix6::from_fn(|i, k| c[(i, k)] * force * length / (d(i) * d(k)));
    let (_, margin, _) = softest(&hat)?;
    Some(Stability {
        stable: margin > -NEUTRAL_MARGIN,
        margin,
        mode: None,
    })
}

/// The stability from the scaled shooting Jacobian `y` (column-major 6×6) and the tip twist
/// of each base-wrench column `x` (m, rad per scaled unit), for a rod of length `length`.
/// `None` if the Jacobian is not finite.
///
/// `jacobi`: the conjugate points and resolution of the march of the columns
/// ([`JacobiCheck`]); unless it is clear, the equilibrium is reported not stable whatever the
/// tip's margin.
pub(crate) fn tip_stability(
    y: &[f64],
    x: &[Vector6<f64>; 6],
    length: f64,
    jacobi: JacobiCheck,
) -> Option<Stability> {
    let ym = Matrix6::from_column_slice(y);
    if !ym.iter().all(|v| v.is_finite()) || !x.iter().all(|c| c.iter().all(|v| v.is_finite())) {
        return None;
    }
    let Some(lu_t) = Lu6::new(&ym.transpose()) else {
        // Singular: the equilibrium is critical (a zero tip stiffness).
        return Some(Stability {
            stable: false,
            margin: 0.0,
            mode: None,
        });
    };
    // Ĉ = D⁻¹ X Y⁻¹, row by row: Yᵀ ĉ_i = (row i of D⁻¹ X).
    let mut c = Matrix6::zeros();
    for i in 0..6 {
        let scale = if i < 3 { 1.0 / length } else { 1.0 };
        let row: [f64; 6] = std::array::from_fn(|k| x[k][i] * scale);
        let sol = lu_t.solve(&row);
        for k in 0..6 {
            c[(i, k)] = sol[k];
        }
    }
    let (eig, margin, softest) = softest(&c)?;
    let stable = margin > -NEUTRAL_MARGIN && jacobi.clear();
    let mode = match softest {
        Some(k) if !stable => {
            // The base-wrench change of the unit tip wrench ζ: Y δx = ζ.
            let z = eig.eigenvectors.column(k);
            let lu = Lu6::new(&ym)?;
            Some(lu.solve(&[z[0], z[1], z[2], z[3], z[4], z[5]]))
        }
        _ => None,
    };
    Some(Stability {
        stable,
        margin,
        mode,
    })
}

/// The scaled pose and wrench blocks of the six base-wrench columns of a state, in
/// canonical coordinates: the moment variation is `δM + M × δθ / 2` (world), which makes
/// `XᵀY` symmetric (the term `M · (δθ₁ × δθ₂)` of the symplectic form on the rotations).
fn blocks(y: &[f64; FULL], length: f64, force: f64) -> (Matrix6<f64>, Matrix6<f64>) {
    let r = rot(y);
    let m = v3(y, 15) / (force * length);
    let (mut x, mut w) = (Matrix6::zeros(), Matrix6::zeros());
    for k in 0..6 {
        let b = STATE + COLUMN * k;
        let dp = v3(y, b) / length;
        let th = rotation_variation(&r, &col_rot(y, b));
        let dn = v3(y, b + DN) / force;
        let dm = v3(y, b + DM) / (force * length) + m.cross(&th) * 0.5;
        for i in 0..3 {
            x[(i, k)] = dp[i];
            x[(i + 3, k)] = th[i];
            w[(i, k)] = dn[i];
            w[(i + 3, k)] = dm[i];
        }
    }
    (x, w)
}

/// What a march of the six base-wrench columns says beyond the tip: the conjugate points of the
/// rod with its tip clamped too (Jacobi's condition), and whether the march resolved the
/// columns at all.
///
/// **Conjugate points.** At every node the columns give the pose variations `X(s)` and the
/// wrench variations `Y(s)` per base wrench, in the canonical coordinates of [`blocks`]
/// (`XᵀY` symmetric). `X Y⁻¹` is then symmetric (the tip compliance of the rod cut at `s`):
/// one of its eigenvalues rises through zero where `X` is singular (a conjugate point) and one
/// jumps from `+∞` to `-∞` where `Y` is (a focal point). Every drop in its count of negative
/// eigenvalues from one node to the next is a conjugate point passed, with its multiplicity (a
/// round column's two bending planes at once); a conjugate and a focal point within one step
/// cancel. With any, `n₋(H) = n₋(H_c) + n₋(C)` has its first term and the equilibrium is not
/// stable whatever the tip's margin (a column with a compressive load at mid-length between
/// 31 and 35 times its Euler load: the tip criterion alone found it stable).
///
/// **Resolution.** A compressed rod's Jacobi fields oscillate with its buckling wavenumber
/// `k = √(N/EI)` (axial compression `N` of the state's force, rod and tendons: the tendons' own
/// pull does not buckle the rod; `EI` the softer bending stiffness), and RK4 follows them only
/// while `k h` (`h` the step) stays below [`RESOLVED_TURN`]; beyond it the columns are neither
/// accurate nor bounded (a straight column at 10⁴ times its Euler load on 40 steps: `k h =
/// 3.9`, tip margin -2.7e-30), and no verdict is drawn from them: not stable.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct JacobiCheck {
    last: Option<(f64, Option<usize>)>,
    /// Conjugate points passed so far.
    pub conjugate: usize,
    /// Whether a step was too long for the compressed rod's buckling wavenumber.
    pub unresolved: bool,
}

/// The largest `k h` (rad: buckling wavenumber times step) at which a march's columns count
/// as resolved (RK4's stability limit on the imaginary axis is `2√2`; at 1 its error in one
/// step is about 1e-3 of the field).
pub const RESOLVED_TURN: f64 = 1.0;

impl JacobiCheck {
    /// Adds the node at `s` (m) with full state `y` (the state, then the six columns), of a
    /// rod of length `length` (m) and force scale `force` (N), whose softer bending compliance
    /// there is `bending` (1/(N m²)).
    pub fn node(&mut self, s: f64, y: &[f64; FULL], (length, force): (f64, f64), bending: f64) {
        let compression = -v3(y, 12).dot(&(rot(y) * nalgebra::Vector3::z()));
        let k = (compression.max(0.0) * bending).sqrt();
        let neg = negatives_at(y, length, force);
        if let Some((before, last)) = self.last {
            if k * (s - before).abs() > RESOLVED_TURN {
                self.unresolved = true;
            }
            if let (Some(last), Some(neg)) = (last, neg) {
                self.conjugate += last.saturating_sub(neg);
            }
        }
        self.last = Some((s, neg.or(self.last.and_then(|l| l.1))));
    }

    /// No conjugate point, and a march that resolves them.
    pub fn clear(&self) -> bool {
        self.conjugate == 0 && !self.unresolved
    }
}

/// The number of negative eigenvalues of `X Y⁻¹` at a node (see [`JacobiCheck`]), as those of
/// the congruent `Yᵀ X` (symmetric in these coordinates; the same inertia wherever `Y` is
/// invertible, and no solve), directions of zero compliance left out; `None` where it is not
/// defined (the base, where `X = 0`; non-finite columns).
fn negatives_at(y: &[f64; FULL], length: f64, force: f64) -> Option<usize> {
    let (xm, ym) = blocks(y, length, force);
    let m = ym.tr_mul(&xm);
    let sym = (m + m.transpose()) * 0.5;
    if !sym.iter().all(|v| v.is_finite()) || sym.amax() == 0.0 {
        return None;
    }
    if sym.cholesky().is_some() {
        return Some(0);
    }
    let eig = SymmetricEigen::new(sym);
    let big = eig.eigenvalues.amax();
    Some(
        eig.eigenvalues
            .iter()
            .filter(|&&mu| mu < -CONSTRAINT_COMPLIANCE * big)
            .count(),
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A straight uniform Euler–Bernoulli cantilever (length 1, EI = 1) in scaled unknowns:
    /// Y = I, X the tip compliance in SI; its dimensionless tip stiffness is D C⁻¹ D, whose
    /// symmetric part has the closed-form smallest eigenvalue of the 2×2 bending block
    /// [[12, -6], [-6, 4]]: 8 - 2 sqrt(13).
    #[test]
    fn straight_cantilever_margin_is_the_closed_form() {
        let y: Vec<f64> = Matrix6::<f64>::identity().as_slice().to_vec();
        let mut x = [Vector6::zeros(); 6];
        // Bending in the x-z plane: force x -> (δx = 1/3, δθy = 1/2); moment y -> (1/2, 1).
        x[0][0] = 1.0 / 3.0;
        x[0][4] = 0.5;
        x[4][0] = 0.5;
        x[4][4] = 1.0;
        x[1][1] = 1.0 / 3.0;
        x[1][3] = -0.5;
        x[3][1] = -0.5;
        x[3][3] = 1.0;
        x[2][2] = 1e-3;
        x[5][5] = 1.0;
        let s = tip_stability(&y, &x, 1.0, JacobiCheck::default()).unwrap();
        let exact = 8.0 - 2.0 * 13f64.sqrt();
        assert!(s.stable && (s.margin - exact).abs() < 1e-12, "{s:?}");
        // The same with the axis constrained (zero axial compliance).
        x[2][2] = 0.0;
        let s = tip_stability(&y, &x, 1.0, JacobiCheck::default()).unwrap();
        assert!(s.stable && (s.margin - exact).abs() < 1e-12, "{s:?}");
        // A negative bending compliance: unstable, with a mode.
        x[0][0] = -1.0;
        let s = tip_stability(&y, &x, 1.0, JacobiCheck::default()).unwrap();
        assert!(!s.stable && s.margin < 0.0 && s.mode.is_some(), "{s:?}");
    }

    #[test]
    fn certificate_needs_a_margin_that_outlasts_the_distance() {
        let s = |margin: f64| Stability {
            stable: margin > -NEUTRAL_MARGIN,
            margin,
            mode: None,
        };
        assert!(certifies(&s(0.8), 0.07) && !certifies(&s(0.8), 0.08));
        assert!(certifies(&s(CERTIFIED_MARGIN), 0.0));
        assert!(!certifies(&s(0.9 * CERTIFIED_MARGIN), 0.0));
        assert!(!certifies(&s(-1.0), 0.0) && !certifies(&s(0.8), f64::NAN));
    }

    use std::sync::Arc;

    use nalgebra::Vector3;

    use crate::cosserat::statics::{solve_statics, SolveOptions};
    use crate::model::loads::Loads;
    use crate::model::material::LinearElastic;
    use crate::model::rod::Rod;
    use crate::model::section::Section;
    use crate::model::{Actuation, RobotModel};

    /// A steel cantilever column (L = 0.5 m, r = 1 mm) under a dead tip force: axial `ratio`
    /// times Euler's critical load `π² E I / (4 L²)`, lateral `lateral` times `E I / L²`.
    fn column(ratio: f64, lateral: f64) -> Arc<RobotModel> {
        let (l, r, e): (f64, f64, f64) = (0.5, 1e-3, 200e9);
        let ei = e * std::f64::consts::PI * r.powi(4) / 4.0;
        let p_cr = std::f64::consts::PI.powi(2) * ei / (4.0 * l * l);
        let rod = Rod::new(
            l,
            Section::circular(r).unwrap(),
            LinearElastic::new(e, 0.3).unwrap(),
        );
        let f = Vector3::new(lateral * ei / (l * l), 0.0, -ratio * p_cr);
        RobotModel::rod_only(rod.unwrap(), Loads::tip_force(f)).unwrap()
    }

    /// Near Euler's load the margin is small: the certificate refuses and the columns at the
    /// solution decide (the margin is then known at once). Below the load the column is
    /// stable, above it the straight column is not (Euler).
    #[test]
    fn near_the_euler_load_the_columns_at_the_solution_decide() {
        let opts = SolveOptions {
            seek_stable: false,
            ..SolveOptions::default()
        };
        let none = Actuation::default();
        let below = solve_statics(&column(0.97, 1e-3), &none, &opts).unwrap();
        assert!(below.stats.converged && below.stable);
        let m = *below
            .margin
            .get()
            .expect("decided by the columns at the solution");
        assert!(m > 0.0 && m < CERTIFIED_MARGIN, "margin {m}");
        let above = solve_statics(&column(1.03, 0.0), &none, &opts).unwrap();
        assert!(above.stats.converged && !above.stable);
        assert!(above.margin.get().is_some_and(|m| *m < -NEUTRAL_MARGIN));
    }

    /// A straight column far past Euler's load, on meshes that cannot resolve its buckling
    /// modes: at 10⁴ and 10⁵ times the load the wavenumber `k = (π/2L)√ratio` times the step
    /// of 40 RK4 steps is 3.9 and 12.4 (of 400 steps, 0.39 and 1.24): the columns overflow
    /// the tip criterion (margins -2.7e-30 and -2.1e-118 on 40 steps, reported stable
    /// before), and the verdict is not stable. Where the mesh resolves them (10⁴ on 400 steps)
    /// the tip criterion decides, with a margin of the closed form's size. Resolved or not,
    /// below the load it is stable.
    #[test]
    fn a_column_past_its_buckling_loads_is_not_stable_on_any_mesh() {
        let none = Actuation::default();
        let on = |steps: usize, seek: bool| SolveOptions {
            integrator: crate::cosserat::statics::Integrator::Rk4 { steps },
            seek_stable: seek,
            ..SolveOptions::default()
        };
        for ratio in [1e4, 1e5] {
            for steps in [40, 200] {
                let sol = solve_statics(&column(ratio, 0.0), &none, &on(steps, false)).unwrap();
                assert!(
                    sol.stats.converged && !sol.stable,
                    "{ratio} P_cr on {steps} steps: stable, margin {}",
                    sol.stability_margin()
                );
            }
        }
        let resolved = solve_statics(&column(1e4, 0.0), &none, &on(400, false)).unwrap();
        assert!(!resolved.stable && resolved.stability_margin() < -1.0);
        let below = solve_statics(&column(0.5, 0.0), &none, &on(40, false)).unwrap();
        assert!(below.stable);
    }

    /// Far from critical, a solution certified stable by the exact columns of the predicted
    /// point has its margin computed when read: it is at least the certificate's floor.
    #[test]
    fn a_certified_solution_is_stable_by_the_columns_at_the_solution() {
        let sol = solve_statics(
            &column(0.0, 0.3),
            &Actuation::default(),
            &SolveOptions::default(),
        )
        .unwrap();
        assert!(sol.stats.converged && sol.stable);
        assert!(
            sol.margin.get().is_none(),
            "certified: margin computed when read"
        );
        let m = sol.stability_margin();
        assert!(m >= CERTIFIED_MARGIN, "margin {m}");
    }
}
