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

use super::equations::{Evaluator, Local, Tangent, LOCAL_MAX_ITERATIONS, LOCAL_TOLERANCE};
use crate::error::Error;
use crate::math::linalg::{Inverse6, Lu6};
use crate::model::material::hyperelastic::UniaxialLaw;
use crate::model::section::SectionProperties;

/// Least fibre stretch below which a local iteration that halved its steps to keep the
/// stretches positive, and failed, is reported as the rod compressed to zero length (a
/// `ParameterError`); above it, as a failed section solve.
const ZERO_LENGTH_STRETCH: f64 = 0.01;

/// Most step halvings of the local Newton iteration (keeping every fibre stretch positive).
const MAX_HALVINGS: usize = 40;

impl Evaluator<'_, '_> {
    /// Records the first material error of the solve (reported if the solve fails).
    fn material_error(&mut self, err: Error) {
        if self.ws.material_error.is_none() {
            self.ws.material_error = Some(err);
        }
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
        let rod = self.eq.model.rod();
        let material = rod.material();
        let k = rod.shear_coefficient();
        let inext = rod.inextensible();
        let c = material.compliance(props, k, inext);
        let cd = Vector6::from_column_slice(&c);
        let vs = rod.rest_strain().at(s);
        let us = rod.rest_curvature().at(s);
        let xs = Vector6::new(vs.x, vs.y, vs.z, us.x, us.y, us.z);
        let wv = Vector6::from_column_slice(wb);
        self.load_offsets(s, props);
        let mut x = match self.ws.guess {
            Some(g) => g,
            None => {
                let mut tw = Vector6::zeros();
                for (r, _, tau) in &self.ws.offsets {
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
            ev.material_error(Error::not_converged(what, LOCAL_MAX_ITERATIONS, f64::NAN));
            ev.ws.guess = None;
            Local::nan()
        };
        let (g, h) = match eval(self, &x) {
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
        let this = &*self;
        let rho = (props.ix.max(props.iy) / props.area).sqrt();
        let (x, h, converged, hit_zero) = damped_newton(|x| eval(this, x), x, g, h, rho);
        let e: [f64; 6] = (x - xs).into();
        let (Some(law), Some(state)) = (
            material.uniaxial_law(),
            material.fibre_state(props, k, inext, &e),
        ) else {
            return fail(self, format!("hyperelastic section at s = {s} m"));
        };
        if let Err(e) = check_fibres(law, &state.stretch, s, converged, hit_zero, wb) {
            self.material_error(e);
            self.ws.guess = None;
            return Local::nan();
        }
        let mut out = Local::strains(&x);
        if tangent {
            let Some(lu) = Inverse6::new(&h) else {
                return Local::nan();
            };
            self.ws.tangent = Tangent {
                diag: c,
                lu: Some(lu),
            };
        }
        self.finish_tendons(s, props, &mut out, fluid);
        self.ws.guess = Some(x);
        out
    }
}

/// The material failures of a hyperelastic section solve at `s`: a law that is not stable at
/// the stretches reached, a fibre compressed to zero length (`hit_zero`), or no convergence.
fn check_fibres(
    law: &crate::model::material::hyperelastic::UniaxialModel,
    stretch: &[f64],
    s: f64,
    converged: bool,
    hit_zero: bool,
    wb: &[f64; 6],
) -> Result<(), Error> {
    // Stability: the fibre forces must increase with the stretch (at the solution, or where
    // the iteration stopped).
    for &lf in stretch {
        let slope = law.nominal_slope_unchecked(lf);
        if !(slope > 0.0 && slope.is_finite()) {
            return Err(Error::invalid(
                format!("{} parameters", law.model_name()),
                law,
                format!(
                    "a stable law at the stretches reached (dP/dstretch > 0): \
                     dP/dstretch = {slope:.4e} Pa at fibre stretch {lf:.6} (s = {s} m)"
                ),
            ));
        }
    }
    if converged {
        return Ok(());
    }
    let least = stretch.iter().fold(f64::INFINITY, |m, v| m.min(*v));
    // A stretch still far from zero where the iteration stopped is no compression to zero
    // length (the iteration failed at a wild wrench, e.g. a march its mesh cannot follow).
    if hit_zero && least < ZERO_LENGTH_STRETCH {
        return Err(Error::invalid(
            "stretch",
            format!("{least:.3e}"),
            format!(
                "> 0 at every fibre of the section at s = {s} m: the loads and \
                 pressures compress the rod toward zero length (body wrench of the \
                 rod {wb:?} N, N m)"
            ),
        ));
    }
    Err(Error::not_converged(
        format!("hyperelastic section solve at s = {s} m (body wrench {wb:?})"),
        LOCAL_MAX_ITERATIONS,
        f64::NAN,
    ))
}

/// The size of a strain vector `x = (v, u)` in fibre strain: `max(|v_i|, ρ |u_i|)` with `ρ`
/// (m) the section's radius of gyration. Curvatures (1/m) carry the round-off of the fibre sums
/// at the scale `1/ρ`; measured in 1/m against `1 + |x|` a thin rod's curvature cannot meet the
/// tolerance near zero (the iteration cycles at the round-off floor).
fn fibre_norm(x: &Vector6<f64>, rho: f64) -> f64 {
    (0..6).fold(0.0, |m: f64, i| {
        m.max(x[i].abs() * if i < 3 { 1.0 } else { rho })
    })
}

/// Newton's method on the local residual `eval(x) = (g, ∂g/∂x)` from `x` (with `g`, `h` at
/// `x`), halving a step while a fibre stretch would not be positive; converged when the step,
/// in fibre strain ([`fibre_norm`], `rho` the radius of gyration), is below
/// [`LOCAL_TOLERANCE`] relative to `1 +` the strain, or when at most 1e3 times that it stops
/// shrinking (the round-off floor). Returns the last iterate, its Jacobian, whether it converged
/// and whether a step was shortened.
fn damped_newton(
    eval: impl Fn(&Vector6<f64>) -> Option<(Vector6<f64>, Matrix6<f64>)>,
    mut x: Vector6<f64>,
    mut g: Vector6<f64>,
    mut h: Matrix6<f64>,
    rho: f64,
) -> (Vector6<f64>, Matrix6<f64>, bool, bool) {
    let mut hit_zero = false;
    let mut last_step = f64::INFINITY;
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
            if let Some(gh) = eval(&xt) {
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
        let step = fibre_norm(&dx, rho) * t;
        let tol = LOCAL_TOLERANCE * (1.0 + fibre_norm(&x, rho));
        if step <= tol || (step <= 1e3 * tol && step >= 0.5 * last_step) {
            return (x, h, true, hit_zero);
        }
        last_step = step;
    }
    (x, h, false, hit_zero)
}
