//! The normal pressure that holds the backbone on a surface over a held interval (see
//! `model/hold.rs`): a contact interval on a curved obstacle.
//!
//! With `d` the surface's signed distance, `n = ∇d`, `H` its Hessian and `R(s)` the rod's
//! outer radius, the gap `g = d(p) - R` has the derivatives
//!
//! ```text
//! g'  = n · p' - R',
//! g'' = p'ᵀ H p' + n · p'' - R'',     p'' = R_b (u × v + v'),
//! ```
//!
//! and the strain rate `v'` is the constitutive tangent `T = d(v, u)/d(n_b, m_b)` applied to
//! the rate of the body wrench, `n_b' = -u × n_b + R_bᵀ N'`, `m_b' = -u × m_b + R_bᵀ M'`,
//! plus the explicit rate `∂v/∂s` at a fixed wrench (tapered sections, varying offsets). A
//! normal pressure `q n` (N/m, on the rod) enters only `N' = -f - q n`, so
//! `g'' = A - q B` with `B = n · R_b T_v (R_bᵀ n, 0)`, the compliance of the section along
//! the normal (shear and extension: `B ≈ 1/(k G A)` across a straight rod). `q = A / B` keeps
//! `g'' = 0`: started at an arc length where `g = g' = 0` (the rows of the contact), the gap
//! stays zero along the interval. An inextensible, unshearable rod has `B = 0` and cannot be
//! held this way (its contact intervals need edge forces): `q` is then not finite.

use nalgebra::Vector3;

use super::{rot, v3, Evaluator, Local};
use crate::model::hold::Hold;

/// Relative step (of the rod's length) of the central differences in `s` of the strains at a
/// fixed body wrench and of the radius rate, on rods that are not uniform along their length.
const RATE_STEP: f64 = 1e-6;

/// What [`Evaluator::hold_pressure`] needs of the state at `s`: the body wrench, and the
/// world-frame rates of the total force (without the held pressure) and moment.
pub(crate) struct HeldState {
    pub nb: Vector3<f64>,
    pub mb: Vector3<f64>,
    pub nd: Vector3<f64>,
    pub md: Vector3<f64>,
}

impl Evaluator<'_, '_> {
    /// The explicit rate `∂v/∂s` (1/m) of the shear-extension strains at the fixed body
    /// wrench `(nb, mb)` (zero on a rod uniform along its length), by central differences of
    /// the local solve; called before the local solve at `s`, whose warm start it leaves
    /// close.
    pub(crate) fn strain_rate(
        &mut self,
        s: f64,
        nb: &Vector3<f64>,
        mb: &Vector3<f64>,
    ) -> (Vector3<f64>, f64) {
        let model = self.eq.model;
        if model.uniform_along() {
            return (Vector3::zeros(), 0.0);
        }
        let h = RATE_STEP * model.length();
        let rod = model.rod();
        let (p0, p1) = (rod.section_at(s - h), rod.section_at(s + h));
        let v0 = self.local(s - h, &p0, nb, mb, false).v;
        let v1 = self.local(s + h, &p1, nb, mb, false).v;
        let radius_rate2 = (p1.radius_rate - p0.radius_rate) / (2.0 * h);
        ((v1 - v0) / (2.0 * h), radius_rate2)
    }

    /// The normal pressure `q` (N/m; positive pushes the rod out of the surface) that keeps
    /// `g'' = 0` on `hold` (state `y`, local solution `loc` with its tangent in the
    /// workspace, wrench rates `st`, explicit rates `(∂v/∂s, R'')` from
    /// [`Self::strain_rate`]), and the outward normal there. `q` is NaN where the surface's
    /// curvature is undefined or the section is rigid along the normal.
    pub(crate) fn hold_pressure(
        &self,
        hold: &Hold,
        y: &[f64],
        loc: &Local,
        st: &HeldState,
        (rate, radius_rate2): (Vector3<f64>, f64),
    ) -> (f64, Vector3<f64>) {
        let r = rot(y);
        let p = v3(y, 0);
        let (v, u) = (loc.v, loc.u);
        let pd = r * v;
        let (_, n) = hold.surface.distance(&p);
        let Some(curvature) = hold.surface.curvature(&p, &pd) else {
            return (f64::NAN, n);
        };
        let nbd = -u.cross(&st.nb) + r.tr_mul(&st.nd);
        let mbd = -u.cross(&st.mb) + r.tr_mul(&st.md);
        let tangent = self.ws.tangent;
        let d0 = tangent.apply(&[nbd.x, nbd.y, nbd.z, mbd.x, mbd.y, mbd.z]);
        let vd = Vector3::new(d0[0], d0[1], d0[2]) + rate;
        let a = curvature + n.dot(&(r * (u.cross(&v) + vd))) - radius_rate2;
        let nn = r.tr_mul(&n);
        let dq = tangent.apply(&[nn.x, nn.y, nn.z, 0.0, 0.0, 0.0]);
        let b = n.dot(&(r * Vector3::new(dq[0], dq[1], dq[2])));
        let q = if b > 0.0 { a / b } else { f64::NAN };
        (q, n)
    }
}
