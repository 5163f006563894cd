//! The constitutive local solve: the strains `(v, u)` that balance the total body wrench with
//! the rod's elastic wrench and the tendon and fluid loads (Newton or chord steps), and its
//! tangent.

use nalgebra::{Vector3, Vector6};

use super::{Evaluator, Local, Tangent, LOCAL_MAX_ITERATIONS, LOCAL_TOLERANCE};
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
        let wv = Vector6::from_column_slice(&wb);
        let mut warm = self.ws.guess;
        // The tendon sums at the warm start are those the last solve ended with when the
        // offsets and tensions are the same (a straight routing within an interval).
        let mut known = match (warm, self.ws.guess_sums) {
            (Some(g), Some((at, t))) if offsets_kept && at == g => Some(t),
            _ => None,
        };
        let x = loop {
            let start = match warm {
                Some(g) => g,
                None => self.straight_guess(&xs, &cd, &wv),
            };
            match self.local_iteration(start, known, &xs, &cd, &wv, &c) {
                Some(x) => break x,
                // The warm start failed (a jump across a break, a far stage): from the
                // straight-tendon guess with a fresh Newton iteration, as without one.
                None if warm.is_some() => {
                    warm = None;
                    known = None;
                    self.ws.last_lu = None;
                }
                None => return Local::nan(),
            }
        };
        let mut out = Local::strains(&x);
        if tangent {
            // (I + C D)⁻¹ C at the solution.
            let Some((_, lu)) = self.local_inverse(&x, &c) else {
                return Local::nan();
            };
            self.ws.tangent = Tangent {
                diag: c,
                lu: Some(lu),
            };
            self.ws.last_lu = Some(lu);
        }
        let sums = self.finish_tendons(s, props, &mut out, &fluid);
        self.ws.guess = Some(x);
        self.ws.guess_sums = Some((x, sums));
        out
    }

    /// The tendon sums at the strains `x` and the inverse of the local Jacobian `I + C D`
    /// there: by Cholesky of the similar `I + C^½ D C^½` (`D` is symmetric positive
    /// semi-definite), else by Gauss–Jordan; `None` if it is singular.
    fn local_inverse(&self, x: &Vector6<f64>, c: &[f64; 6]) -> Option<(Vector6<f64>, Inverse6)> {
        let mut d = [[0.0; 6]; 6];
        let (tw, _) = self.tendon_sums_into(x, c, true, Some(&mut d));
        let lu = Inverse6::of_compliance_stiffness(c, &d).or_else(|| {
            let (_, h) = self.tendon_sums(x, c, true);
            h.as_ref().and_then(Inverse6::new)
        })?;
        Some((tw, lu))
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
                let (tw, lu) = self.local_inverse(&x, c)?;
                self.ws.last_lu = Some(lu);
                tw
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
