//! The constitutive local solve: the strains `(v, u)` that balance the total body wrench with
//! the rod's elastic wrench and the tendon and fluid loads (Newton or chord steps), and its
//! tangent.

use nalgebra::{Vector3, Vector6};

use super::{Evaluator, Local, LocalMemo, Tangent, LOCAL_MAX_ITERATIONS, LOCAL_TOLERANCE};
use crate::math::linalg::Inverse6;
use crate::model::section::SectionProperties;

impl Evaluator<'_, '_> {
    /// Solves the constitutive equations at `s` for the total body wrench `(nb, mb)`; with
    /// `tangent`, also returns `d(v, u)/d(nb, mb)`. NaN strains if the local iteration fails.
    ///
    /// The iteration on `G(x) = x - x* - C (W - T(x)) = 0` starts from the previous solution
    /// and takes chord steps with the previous factorised Jacobian while they contract fast
    /// (consecutive evaluations are close), and exact Newton steps otherwise; the tangent is
    /// always factorised afresh at the solution.
    pub fn local(
        &mut self,
        s: f64,
        props: &SectionProperties,
        nb: &Vector3<f64>,
        mb: &Vector3<f64>,
        tangent: bool,
    ) -> Local {
        let model = self.eq.model;
        let rod = model.rod();
        let mut wb = [nb.x, nb.y, nb.z, mb.x, mb.y, mb.z];
        // The chambers' fluid carries part of the total wrench (see `chamber.rs`).
        let fluid = self.chamber_wrench(s);
        for k in 0..6 {
            wb[k] -= fluid[k];
        }
        if !rod.material().is_linear() {
            return self.local_hyperelastic(s, props, &wb, &fluid, tangent);
        }
        let vs = rod.rest_strain().at(s);
        let us = rod.rest_curvature().at(s);
        let (e, c) = match model.uniform_compliance() {
            Some(c) => {
                let mut e = [0.0; 6];
                for k in 0..6 {
                    e[k] = c[k] * wb[k];
                }
                (e, *c)
            }
            None => rod.material().elastic_strain(
                props,
                rod.shear_coefficient(),
                rod.inextensible(),
                &wb,
            ),
        };
        if self.ws.active.is_empty() {
            let out = Local {
                v: vs + Vector3::new(e[0], e[1], e[2]),
                u: us + Vector3::new(e[3], e[4], e[5]),
                tendon_force: Vector3::new(fluid[0], fluid[1], fluid[2]),
                tendon_moment: Vector3::new(fluid[3], fluid[4], fluid[5]),
            };
            if tangent {
                self.ws.tangent = Tangent { diag: c, lu: None };
            }
            self.passive_speeds(s, props, &out.v, &out.u);
            return out;
        }
        let offsets_kept = self.load_offsets(s, props);
        let cd = Vector6::from_column_slice(&c);
        let xs = Vector6::new(vs.x, vs.y, vs.z, us.x, us.y, us.z);
        // The rod and the tendons carry no wrench together (exactly so on a robot loaded by
        // its actuators only): the equations of the last such solve may be met again.
        let unloaded = wb.iter().all(|w| *w == 0.0);
        if unloaded && offsets_kept {
            if let Some(out) = self
                .ws
                .memo
                .and_then(|m| m.solves(&fluid, &xs, &c, tangent, self.ws.track_lengths))
            {
                return out;
            }
        }
        let wv = Vector6::from_column_slice(&wb);
        let Some(x) = self.strains(offsets_kept, &xs, &cd, &wv, &c) else {
            self.ws.memo = None;
            return Local::nan();
        };
        let mut out = Local::strains(&x);
        if tangent {
            // (I + C D)⁻¹ C at the solution.
            if self.local_inverse(&x, &c).is_none() {
                self.ws.memo = None;
                return Local::nan();
            }
            self.ws.tangent = Tangent {
                diag: c,
                lu: self.ws.last_lu,
            };
        }
        let sums = self.finish_tendons(s, props, &mut out, &fluid);
        self.ws.guess = Some(x);
        self.ws.guess_sums = Some((x, sums));
        if unloaded && self.ws.fixed_offsets {
            self.ws.memo = Some(LocalMemo::new(
                fluid,
                xs,
                c,
                out,
                tangent,
                self.ws.track_lengths,
            ));
        } else if self.ws.memo.is_some() {
            self.ws.memo = None;
        }
        out
    }

    /// The strains solving the local equations: from the last solution (and its tendon sums
    /// when the offsets are kept), else from the straight-tendon guess; `None` if both fail.
    fn strains(
        &mut self,
        offsets_kept: bool,
        xs: &Vector6<f64>,
        cd: &Vector6<f64>,
        wv: &Vector6<f64>,
        c: &[f64; 6],
    ) -> Option<Vector6<f64>> {
        let mut warm = self.ws.guess;
        // The tendon sums at the warm start are those the last solve ended with when the
        // offsets and tensions are the same (a straight routing within an interval).
        let mut known = match (warm, self.ws.guess_sums) {
            (Some(g), Some((at, t))) if offsets_kept && at == g => Some(t),
            _ => None,
        };
        loop {
            let start = match warm {
                Some(g) => g,
                None => self.straight_guess(xs, cd, wv),
            };
            match self.local_iteration(start, known, xs, cd, wv, c) {
                Some(x) => return Some(x),
                // The warm start failed (a jump across a break, a far stage): from the
                // straight-tendon guess with a fresh Newton iteration, as without one.
                None if warm.is_some() => {
                    warm = None;
                    known = None;
                    self.ws.last_lu = None;
                }
                None => return None,
            }
        }
    }

    /// The tendon sums at the strains `x`, with the inverse of the local Jacobian `I + C D`
    /// there into [`super::Workspace::last_lu`]: by Cholesky of the similar `I + C^½ D C^½`
    /// (`D` is symmetric positive semi-definite), else by Gauss–Jordan; `None` (and the last
    /// inverse kept) if it is singular.
    fn local_inverse(&mut self, x: &Vector6<f64>, c: &[f64; 6]) -> Option<Vector6<f64>> {
        let mut d = [[0.0; 6]; 6];
        let (tw, _) = self.tendon_sums_into(x, c, true, Some(&mut d));
        let lu = Inverse6::of_compliance_stiffness(c, &d).or_else(|| {
            let (_, h) = self.tendon_sums(x, c, true);
            h.as_ref().and_then(Inverse6::new)
        })?;
        self.ws.last_lu = Some(lu);
        Some(tw)
    }

    /// The strains with straight tendons (`t_i = e_z`): `x* + C (W - T_straight)`, the start
    /// of the local iteration without a warm start.
    fn straight_guess(
        &self,
        xs: &Vector6<f64>,
        cd: &Vector6<f64>,
        wv: &Vector6<f64>,
    ) -> Vector6<f64> {
        let mut tf = Vector3::zeros();
        let mut tm = Vector3::zeros();
        for (r, _, tau) in &self.ws.offsets {
            tf.z += tau;
            tm += r.cross(&Vector3::z()) * *tau;
        }
        xs + cd.component_mul(&(wv - Vector6::new(tf.x, tf.y, tf.z, tm.x, tm.y, tm.z)))
    }

    /// The local Newton (or chord) iteration on `G(x) = x - x* - C (W - T(x)) = 0` from `x`
    /// (`known`: `T(x)` if already evaluated); `None` if it fails.
    #[inline]
    fn local_iteration(
        &mut self,
        mut x: Vector6<f64>,
        mut known: Option<Vector6<f64>>,
        xs: &Vector6<f64>,
        cd: &Vector6<f64>,
        wv: &Vector6<f64>,
        c: &[f64; 6],
    ) -> Option<Vector6<f64>> {
        let mut last_step = f64::INFINITY;
        let mut chord = self.ws.last_lu.is_some();
        for _ in 0..LOCAL_MAX_ITERATIONS {
            let tw = if chord {
                known.take().unwrap_or_else(|| self.tendon_load(&x))
            } else {
                self.local_inverse(&x, c)?
            };
            let g = x - xs - cd.component_mul(&(wv - tw));
            let lu = self.ws.last_lu.as_ref()?;
            let dx = Vector6::from(lu.solve(&[g[0], g[1], g[2], g[3], g[4], g[5]]));
            x -= dx;
            // The largest step and strain in one sweep; a non-finite step or strain makes the
            // sum of the magnitudes non-finite.
            let (mut step, mut size, mut total) = (0.0_f64, 0.0_f64, 0.0);
            for k in 0..6 {
                let (a, b) = (dx[k].abs(), x[k].abs());
                step = if a > step { a } else { step };
                size = if b > size { b } else { size };
                total += a + b;
            }
            if !total.is_finite() {
                return None;
            }
            let tol = LOCAL_TOLERANCE * (1.0 + size);
            if step <= tol {
                return Some(x);
            }
            if chord {
                // Chord steps converge linearly with ratio rho: the error left after this step
                // is about step rho / (1 - rho). Switch to Newton unless they contract fast.
                if last_step.is_finite() {
                    let rho = step / last_step;
                    if rho > 0.1 {
                        chord = false;
                    } else if step * rho / (1.0 - rho) <= tol {
                        return Some(x);
                    }
                }
            } else {
                // Quadratic convergence: the error after this step is about |dx|³ / |dx_prev|².
                let predicted = step * (step / last_step).powi(2);
                if last_step.is_finite() && step < 1e-3 * last_step && predicted <= tol {
                    return Some(x);
                }
            }
            last_step = step;
        }
        None
    }

    /// Tendon loads and speeds `|p_i'|` at the local solution `out`, plus the fluid's share;
    /// returns the tendon sums alone, as [`Self::tendon_load`] computes them.
    #[inline]
    pub(crate) fn finish_tendons(
        &mut self,
        s: f64,
        props: &SectionProperties,
        out: &mut Local,
        fluid: &[f64; 6],
    ) -> Vector6<f64> {
        let (mut tf, mut tm) = (Vector3::zeros(), Vector3::zeros());
        for (k, &i) in self.ws.active.iter().enumerate() {
            let (r, rp, tau) = &self.ws.offsets[k];
            let w = out.v + out.u.cross(r) + rp;
            let len = w.norm();
            let t = w * (*tau / len);
            tf += t;
            tm += r.cross(&t);
            self.ws.tendon_speed[i] = len;
        }
        out.tendon_force = tf + Vector3::new(fluid[0], fluid[1], fluid[2]);
        out.tendon_moment = tm + Vector3::new(fluid[3], fluid[4], fluid[5]);
        let (v, u) = (out.v, out.u);
        self.passive_speeds(s, props, &v, &u);
        Vector6::new(tf.x, tf.y, tf.z, tm.x, tm.y, tm.z)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::sync::Arc;

    use nalgebra::Vector3;

    use super::super::{Equations, Evaluator, Workspace};
    use crate::model::chamber::{Chamber, ChamberArea};
    use crate::model::loads::Loads;
    use crate::model::material::LinearElastic;
    use crate::model::rod::{Profile, Rod};
    use crate::model::section::Section;
    use crate::model::tendon::Tendon;
    use crate::model::RobotModel;

    /// One local solve: where, the body wrench, and whether the tangent and the tension-free
    /// tendons' speeds are asked for.
    type Call = (f64, [f64; 6], bool, bool);

    /// Strains and sums, the tangent applied to the six unit wrenches, and every tendon speed
    /// of the call `c` in the workspace of `ev`.
    fn outcome(ev: &mut Evaluator<'_, '_>, c: &Call) -> Vec<f64> {
        let (s, w, tangent, lengths) = *c;
        ev.ws.track_lengths = lengths;
        let props = ev.eq.model.rod().section_at(s);
        let nb = Vector3::new(w[0], w[1], w[2]);
        let mb = Vector3::new(w[3], w[4], w[5]);
        let out = ev.local(s, &props, &nb, &mb, tangent);
        let mut all: Vec<f64> = [out.v, out.u, out.tendon_force, out.tendon_moment]
            .iter()
            .flat_map(|x| x.iter().copied())
            .collect();
        if tangent {
            for k in 0..6 {
                let mut e = [0.0; 6];
                e[k] = 1.0;
                all.extend(ev.ws.tangent.apply(&e));
            }
        }
        if lengths {
            all.extend(ev.ws.tendon_speed.iter().copied());
        }
        all
    }

    /// Every call of `calls`, made in turn on one workspace, gives what the same call gives
    /// on a fresh workspace: the last solve's memo (and warm start) never changes a result.
    fn history_free(model: &RobotModel, tensions: &[f64], pressures: &[f64], calls: &[Call]) {
        let eq = Equations::new(model, tensions, pressures);
        let nt = model.tendons().len();
        let mut ws = Workspace::new(nt);
        let mut ev = Evaluator { eq, ws: &mut ws };
        ev.set_interval(0);
        for (i, c) in calls.iter().enumerate() {
            let got = outcome(&mut ev, c);
            let mut fresh_ws = Workspace::new(nt);
            let mut fresh = Evaluator {
                eq,
                ws: &mut fresh_ws,
            };
            fresh.set_interval(0);
            let want = outcome(&mut fresh, c);
            for (a, b) in got.iter().zip(&want) {
                let tol = 1e-12 * (1.0 + b.abs());
                assert!(
                    (a - b).abs() <= tol,
                    "call {i} {c:?}: {got:?}\n vs {want:?}"
                );
            }
        }
    }

    fn tendons() -> Vec<Tendon> {
        vec![
            Tendon::constant([0.004, 0.0], None).unwrap(),
            Tendon::constant([0.0, 0.004], None).unwrap(),
            Tendon::constant([-0.004, 0.0], None).unwrap(),
        ]
    }

    const ZERO: [f64; 6] = [0.0; 6];

    /// Zero body wrench at one `s` after another (RK4 stages and nodes), where the rest
    /// curvature, the section or the chamber's area differs, then the same `s` again.
    fn along(tangent: bool) -> Vec<Call> {
        [0.0, 0.05, 0.05, 0.1, 0.1, 0.0, 0.1]
            .iter()
            .map(|&s| (s, ZERO, tangent, true))
            .collect()
    }

    fn rod(section: Section) -> Rod {
        Rod::new(0.1, section, LinearElastic::new(2e6, 0.45).unwrap()).unwrap()
    }

    #[test]
    fn a_rest_curvature_along_the_rod_is_solved_at_every_s() {
        let curved = rod(Section::circular(0.006).unwrap())
            .with_rest_curvature(Profile::Function(Arc::new(|s| {
                Vector3::new(0.0, 2.0 + 30.0 * s, 0.0)
            })))
            .unwrap();
        let m = RobotModel::new(curved, tendons(), vec![], Loads::default()).unwrap();
        history_free(&m, &[1.0, 0.5, 0.0], &[], &along(false));
        history_free(&m, &[1.0, 0.5, 0.0], &[], &along(true));
    }

    #[test]
    fn a_taper_is_solved_at_every_s() {
        let tapered = rod(Section::tapered_circular(0.006, 0.004).unwrap());
        let m = RobotModel::new(tapered, tendons(), vec![], Loads::default()).unwrap();
        history_free(&m, &[1.0, 0.5, 0.0], &[], &along(false));
        history_free(&m, &[1.0, 0.5, 0.0], &[], &along(true));
    }

    #[test]
    fn a_chamber_of_varying_area_is_solved_at_every_s() {
        // The total wrench equal to the fluid's at each s: the rod and the tendons carry none.
        let area = ChamberArea::Function(Arc::new(|s| 4e-6 * (1.0 + 5.0 * s)));
        let chamber = Chamber::new(area, [0.0, -0.003], 0.0, None).unwrap();
        let fluid = |c: Call| (c.0, chamber.fluid_wrench(c.0, 2e4), c.2, c.3);
        let calls: Vec<Vec<Call>> = [false, true]
            .iter()
            .map(|&t| along(t).into_iter().map(fluid).collect())
            .collect();
        let uniform = rod(Section::circular(0.006).unwrap());
        let m =
            RobotModel::new(uniform, tendons(), vec![chamber.clone()], Loads::default()).unwrap();
        for c in &calls {
            history_free(&m, &[1.0, 0.5, 0.0], &[2e4], c);
        }
    }

    #[test]
    fn the_tangent_and_the_speeds_are_those_of_the_call() {
        // A loaded solve leaves its tangent and speeds in the workspace; an unloaded one at
        // the same s that asks for neither must not hand them to one that asks for them.
        let uniform = rod(Section::circular(0.006).unwrap());
        let m = RobotModel::new(uniform, tendons(), vec![], Loads::default()).unwrap();
        let w = [0.3, -0.2, 1.5, 0.01, 0.02, 0.0];
        let calls = [
            (0.05, w, true, true),
            (0.05, ZERO, false, false),
            (0.05, ZERO, true, false),
            (0.05, w, true, true),
            (0.05, ZERO, false, false),
            (0.05, ZERO, false, true),
            (0.05, ZERO, true, true),
            (0.05, ZERO, true, true),
        ];
        history_free(&m, &[1.0, 0.5, 0.0], &[], &calls);
    }
}
