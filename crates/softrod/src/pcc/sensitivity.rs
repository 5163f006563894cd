//! The exact actuation Jacobian of a PCC equilibrium.
//!
//! The equilibrium `g(q, a) = 0` of `pcc/statics.rs` (curvature-vector coordinates `q` per
//! segment, actuation `a` = tensions then pressures) is linear in the actuation: a tendon
//! through segments `0..=k` contributes `∂g_θ/∂τ = (d sin β, -d cos β, 1)` to each of them in
//! `θ` coordinates, a chamber of area `A` at `r (cos β, sin β)` contributes
//! `∂g_θ/∂p = -A (r sin β, -r cos β, 1)` to its segment (mapped to `q` by
//! `∂θ/∂q = [ℓ 0 u_x; 0 ℓ u_y; 0 0 1]`; nothing on the length row of an inextensible
//! segment). By the implicit-function theorem `dq/da = -(∂g/∂q)⁻¹ ∂g/∂a`, with the exact
//! Jacobian of the equilibrium, and the tip twist `[ṗ; ω]` (hybrid: the tip point's velocity
//! and the angular velocity, base frame) is the chain Jacobian times `dq/da`. Without a tip
//! load `∂g/∂q` is block diagonal and constant in `θ`: the Jacobian is closed form.

use nalgebra::DMatrix;

use crate::error::{Error, Result};
use crate::pcc::kinematics::{ArcCoordinates, JacobianFrame};
use crate::pcc::statics::{pcc_equilibrium, PccLoads, PccRobot, PccStaticsSolution};

/// `∂g/∂a` (3n × (n_tendons + n_chambers)) of `robot` at the coordinates `q`.
fn actuation_columns(robot: &PccRobot, q: &[[f64; 3]]) -> DMatrix<f64> {
    let n = q.len();
    let (nt, nc) = (robot.n_tendons(), robot.n_chambers());
    let mut g = DMatrix::zeros(3 * n, nt + nc);
    let put = |col: usize, seg: usize, d: [f64; 3], g: &mut DMatrix<f64>| {
        let [ux, uy, l] = q[seg];
        g[(3 * seg, col)] += l * d[0];
        g[(3 * seg + 1, col)] += l * d[1];
        if robot.segments()[seg].axial_stiffness().is_some() {
            g[(3 * seg + 2, col)] += ux * d[0] + uy * d[1] + d[2];
        }
    };
    for (k, t) in robot.tendons().iter().enumerate() {
        let (sb, cb) = t.angle().sin_cos();
        let d = t.distance();
        for seg in 0..=t.last_segment() {
            put(k, seg, [d * sb, -d * cb, 1.0], &mut g);
        }
    }
    let mut col = nt;
    for (seg, ch) in robot.chambers() {
        for i in 0..ch.len() {
            let (a, r, b) = (ch.areas()[i], ch.distances()[i], ch.angles()[i]);
            let (sb, cb) = b.sin_cos();
            put(col, *seg, [-a * r * sb, a * r * cb, -a], &mut g);
            col += 1;
        }
    }
    g
}

/// The actuation Jacobian of the PCC equilibrium `solution` of `robot` under `loads` (the
/// loads it was solved with): the derivative of the tip twist `[ṗ; ω]` (base frame; m and rad)
/// with respect to each tension (per N), then each pressure (per Pa); 6 × (n_tendons +
/// n_chambers).
///
/// # Errors
/// [`Error::InvalidParameter`] naming the loads; [`Error::NotConverged`] if the equilibrium
/// Jacobian is singular (a buckled configuration).
pub fn pcc_actuation_jacobian(
    robot: &PccRobot,
    loads: &PccLoads,
    solution: &PccStaticsSolution,
) -> Result<DMatrix<f64>> {
    let q = solution.coordinates();
    let eq = pcc_equilibrium(robot, loads, &q)?;
    let g = actuation_columns(robot, &q);
    let dq = eq
        .jacobian
        .lu()
        .solve(&(-g))
        .ok_or_else(|| Error::NotConverged {
            what: "PCC actuation Jacobian: singular equilibrium Jacobian".into(),
            iterations: 0,
            residual: f64::INFINITY,
            load_factor: 1.0,
        })?;
    let chain = solution.chain();
    let j = chain.jacobian(JacobianFrame::Hybrid, ArcCoordinates::CurvatureVector);
    let out = j * dq;
    Ok(DMatrix::from_fn(6, out.ncols(), |r, c| out[(r, c)]))
}
