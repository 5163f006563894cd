//! The local constitutive solve for hyperelastic rods, and the chambers' share of the wrench.
//!
//! With a nonlinear section law `F(e)` (body wrench of the elastic strain `e = x - x*`,
//! `x = (v, u)`, see [`crate::model::material`]) the implicit equation at `s` is
//! `F(x - x*) + T(x) = W - W_c`: rod, tendons and chamber fluid share the total body wrench
//! `W`. It is solved by Newton's method on the scaled residual
//! `G(x) = c0 ⊙ (F + T - W + W_c)` (`c0` the small-strain compliance; in the inextensible limit
//! the constrained rows are `x_i - x*_i`), whose Jacobian is `c0 ⊙ (K + D)` with `K = dF/de`
//! the symmetric section stiffness and `D` the tendon term. The tangent left for the
//! sensitivities, `(c0 ⊙ (K + D))⁻¹ c0 = (K + D)⁻¹`, is stored in the same form as for a linear
//! material (`tangent_diag = c0`, `tangent_lu` the factorised Jacobian), so the variational
//! equations and the shooting Jacobian stay exact.

use nalgebra::{Matrix6, Vector3, Vector6};

use super::equations::{Evaluator, Local, Lu6, LOCAL_MAX_ITERATIONS, LOCAL_TOLERANCE};
use crate::error::Error;
use crate::model::material::hyperelastic::UniaxialLaw;
use crate::model::section::SectionProperties;

/// Most step halvings of the local Newton iteration (keeping every fibre stretch positive).
const MAX_HALVINGS: usize = 40;

impl Evaluator<'_, '_> {
    /// Selects the chambers that fill the current interval `[a, b]`.
    pub(crate) fn select_chambers(&mut self, a: f64, b: f64) {
        self.chambers.clear();
        for (i, c) in self.model.loads.chambers.iter().enumerate() {
            let end = c.end().unwrap_or(self.model.length);
            if c.start() <= a && end >= b && c.pressure() != 0.0 {
                self.chambers.push(i);
            }
        }
    }

    /// Body-frame wrench carried by the fluid of the active chambers at `s` (zero without).
    #[inline]
    pub(crate) fn chamber_wrench(&self, s: f64) -> [f64; 6] {
        let mut w = [0.0; 6];
        for &i in &self.chambers {
            let c = self.model.loads.chambers[i].fluid_wrench(s, self.model.factor);
            for k in 0..6 {
                w[k] += c[k];
            }
        }
        w
    }

    /// Records the first material error of the solve (reported if the solve fails).
    fn material_error(&self, err: Error) {
        let _ = self.model.material_error.set(err);
    }

    /// The local solve for a hyperelastic rod (see the module documentation); `wb` is the
    /// total body wrench minus the chambers' share. NaN strains if it fails, with the reason
    /// recorded in the model.
    pub(crate) fn local_hyperelastic(
        &mut self,
        s: f64,
        props: &SectionProperties,
        wb: &[f64; 6],
        fluid: &[f64; 6],
        tangent: bool,
    ) -> Local {
        let model = self.model;
        let rod = model.rod;
        let material = rod.material();
        let k = model.shear_coefficient;
        let inext = rod.inextensible();
        let c = material.compliance(props, k, inext);
        let cd = Vector6::from_column_slice(&c);
        let vs = rod.rest_strain().at(s);
        let us = rod.rest_curvature().at(s);
        let xs = Vector6::new(vs.x, vs.y, vs.z, us.x, us.y, us.z);
        let wv = Vector6::from_column_slice(wb);
        self.offsets.clear();
        for &i in &self.active {
            let t = &model.tendons[i];
            let (r, rp) = t.tendon.routing().offset(s, props);
            self.offsets.push((
                Vector3::new(r[0], r[1], 0.0),
                Vector3::new(rp[0], rp[1], 0.0),
                t.tendon.tension() * model.factor,
            ));
        }
        let mut x = match self.guess {
            Some(g) => g,
            None => {
                let mut tw = Vector6::zeros();
                for (r, _, tau) in &self.offsets {
                    tw[2] += tau;
                    let q = r.cross(&Vector3::z()) * *tau;
                    tw[3] += q.x;
                    tw[4] += q.y;
                }
                xs + cd.component_mul(&(wv - tw))
            }
        };
        // Residual and Jacobian at x; None if a fibre stretch is not positive.
        let eval = |ev: &Self, x: &Vector6<f64>| -> Option<(Vector6<f64>, Matrix6<f64>)> {
            let e: [f64; 6] = (x - xs).into();
            let st = material.fibre_state(props, k, inext, &e)?;
            let (tw, h) = ev.tendon_sums(x, &c, true);
            let mut h = h?;
            let mut g = Vector6::zeros();
            for i in 0..6 {
                if c[i] == 0.0 {
                    g[i] = e[i];
                } else {
                    g[i] = c[i] * (st.wrench[i] + tw[i] - wv[i]);
                    h[(i, i)] -= 1.0;
                    for j in 0..6 {
                        h[(i, j)] += c[i] * st.stiffness[(i, j)];
                    }
                }
            }
            Some((g, h))
        };
        let fail = |ev: &mut Self, what: String| {
            ev.material_error(Error::NotConverged {
                what,
                iterations: LOCAL_MAX_ITERATIONS,
                residual: f64::NAN,
            });
            ev.guess = None;
            Local::nan()
        };
        let (mut g, mut h) = match eval(self, &x) {
            Some(gh) => gh,
            None => {
                // The warm start is not admissible: restart from the rest strain.
                x = xs;
                match eval(self, &x) {
                    Some(gh) => gh,
                    None => return fail(self, format!("hyperelastic section at s = {s} m")),
                }
            }
        };
        let mut converged = false;
        // Whether a step was shortened because a fibre stretch would not be positive.
        let mut hit_zero = false;
        for _ in 0..LOCAL_MAX_ITERATIONS {
            let Some(lu) = Lu6::new(&h) else {
                break;
            };
            let dx = Vector6::from(lu.solve(&[g[0], g[1], g[2], g[3], g[4], g[5]]));
            if !dx.iter().all(|v| v.is_finite()) {
                break;
            }
            let mut t = 1.0;
            let mut next = None;
            for _ in 0..MAX_HALVINGS {
                let xt = x - dx * t;
                if let Some(gh) = eval(self, &xt) {
                    next = Some((xt, gh));
                    break;
                }
                hit_zero = true;
                t *= 0.5;
            }
            let Some((xt, (gt, ht))) = next else {
                break;
            };
            x = xt;
            (g, h) = (gt, ht);
            if dx.amax() * t <= LOCAL_TOLERANCE * (1.0 + x.amax()) {
                converged = true;
                break;
            }
        }
        let e: [f64; 6] = (x - xs).into();
        let (Some(law), Some(state)) = (
            material.uniaxial_law(),
            material.fibre_state(props, k, inext, &e),
        ) else {
            return fail(self, format!("hyperelastic section at s = {s} m"));
        };
        // Stability: the fibre forces must increase with the stretch (at the solution, or where
        // the iteration stopped).
        for &lf in &state.stretch {
            let slope = law.nominal_slope_unchecked(lf);
            if !(slope > 0.0 && slope.is_finite()) {
                self.material_error(Error::invalid(
                    format!("{} parameters", law.model_name()),
                    law,
                    format!(
                        "a stable law at the stretches reached (dP/dstretch > 0): \
                         dP/dstretch = {slope:.4e} Pa at fibre stretch {lf:.6} (s = {s} m)"
                    ),
                ));
                self.guess = None;
                return Local::nan();
            }
        }
        if !converged {
            if hit_zero {
                let least = state.stretch.iter().fold(f64::INFINITY, |m, v| m.min(*v));
                self.material_error(Error::invalid(
                    "stretch",
                    format!("{least:.3e}"),
                    format!(
                        "> 0 at every fibre of the section at s = {s} m: the loads and \
                         pressures compress the rod toward zero length (body wrench of the \
                         rod {wb:?} N, N m)"
                    ),
                ));
                self.guess = None;
                return Local::nan();
            }
            return fail(
                self,
                format!("hyperelastic section solve at s = {s} m (body wrench {wb:?})"),
            );
        }
        if tangent {
            let Some(lu) = Lu6::new(&h) else {
                return Local::nan();
            };
            self.tangent_diag = c;
            self.tangent_lu = Some(lu);
        }
        let mut out = Local {
            v: Vector3::new(x[0], x[1], x[2]),
            u: Vector3::new(x[3], x[4], x[5]),
            tendon_force: Vector3::new(fluid[0], fluid[1], fluid[2]),
            tendon_moment: Vector3::new(fluid[3], fluid[4], fluid[5]),
        };
        for (j, &i) in self.active.iter().enumerate() {
            let (r, rp, tau) = &self.offsets[j];
            let w = out.v + out.u.cross(r) + rp;
            let len = w.norm();
            let a = *tau / len;
            out.tendon_force += w * a;
            out.tendon_moment += r.cross(&w) * a;
            self.tendon_speed[i] = len;
        }
        if self.track_speeds {
            self.passive_speeds(s, props, &out.v, &out.u);
        }
        self.guess = Some(x);
        out
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use std::f64::consts::PI;

    use nalgebra::{Matrix6, Vector3, Vector6};

    use crate::cosserat::equations::{Evaluator, Model, FULL, STATE};
    use crate::model::chamber::{Chamber, ChamberArea};
    use crate::model::material::hyperelastic::{Silicone, UniaxialModel};
    use crate::model::loads::{Frame, Loads, PointLoad};
    use crate::model::rod::Rod;
    use crate::model::section::Section;
    use crate::math::so3::reorthonormalise;
    use crate::cosserat::statics::build_model;
    use crate::model::tendon::Tendon;

    /// One shooting pass with fixed-step RK4 (`steps` per interval): scaled residual and, with
    /// `N == FULL`, its Jacobian from the variational equations.
    fn pass<const N: usize>(
        model: &Model<'_>,
        x: &Vector6<f64>,
        steps: usize,
    ) -> (Vector6<f64>, Option<Matrix6<f64>>) {
        let mut ev = Evaluator::new(model);
        let mut y: [f64; N] = model.initial(x);
        let nb = model.breaks.len();
        for k in 0..nb - 1 {
            ev.set_interval(k);
            let (a, b) = (model.breaks[k], model.breaks[k + 1]);
            let h = (b - a) / steps as f64;
            for i in 0..steps {
                let t = a + h * i as f64;
                let k1 = ev.rhs(t, &y);
                let mut y2 = y;
                (0..N).for_each(|j| y2[j] += 0.5 * h * k1[j]);
                let k2 = ev.rhs(t + 0.5 * h, &y2);
                let mut y3 = y;
                (0..N).for_each(|j| y3[j] += 0.5 * h * k2[j]);
                let k3 = ev.rhs(t + 0.5 * h, &y3);
                let mut y4 = y;
                (0..N).for_each(|j| y4[j] += h * k3[j]);
                let k4 = ev.rhs(t + h, &y4);
                (0..N).for_each(|j| y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
                let r = reorthonormalise(&crate::cosserat::equations::rot(&y));
                y[3..12].copy_from_slice(r.as_slice());
            }
            if k + 2 < nb {
                model.jump(b, &mut y);
            }
        }
        model.residual(&y)
    }

    #[test]
    fn shooting_jacobian_is_exact_for_a_hyperelastic_rod_with_chambers() {
        let rod = Rod::new(
            0.16,
            Section::tube(0.012, 0.002).unwrap(),
            UniaxialModel::from(Silicone::DragonSkin10.yeoh()),
        )
        .unwrap();
        let ac = PI * 0.0025f64.powi(2);
        let tendons = [Tendon::constant([0.008, 0.0], 2.0, Some(0.12)).unwrap()];
        let loads = Loads {
            tip_force: Vector3::new(0.1, -0.05, 0.2),
            tip_moment: Vector3::new(0.0, 2e-3, 1e-3),
            point_loads: vec![PointLoad {
                s: 0.1,
                force: Vector3::new(0.0, 0.1, 0.0),
                moment: Vector3::zeros(),
                frame: Frame::Body,
            }],
            chambers: vec![
                Chamber::new(60e3, ChamberArea::Constant(ac), [0.0, 0.0072], 0.0, None).unwrap(),
                Chamber::new(
                    30e3,
                    ChamberArea::Constant(ac),
                    [0.0072 * (-30f64).to_radians().cos(), -0.0036],
                    0.03,
                    Some(0.13),
                )
                .unwrap(),
            ],
            ..Default::default()
        };
        let model = build_model(&rod, &tendons, &loads).unwrap();
        let x = Vector6::new(0.3, -0.2, 0.5, 0.1, -0.15, 0.05);
        let (_, jac) = pass::<FULL>(&model, &x, 40);
        let jac = jac.unwrap();
        let h = 1e-6;
        let mut fd = Matrix6::zeros();
        for j in 0..6 {
            let mut xp = x;
            xp[j] += h;
            let mut xm = x;
            xm[j] -= h;
            let col =
                (pass::<STATE>(&model, &xp, 40).0 - pass::<STATE>(&model, &xm, 40).0) / (2.0 * h);
            fd.set_column(j, &col);
        }
        let err = (jac - fd).amax() / jac.amax();
        println!("relative Jacobian error {err:e}");
        assert!(err < 1e-6, "relative Jacobian error {err:e}\n{jac}\n{fd}");
        // The shape is far from linear: the axial stretch is well above 1.
        assert!(model.material_error.get().is_none());
    }
}
