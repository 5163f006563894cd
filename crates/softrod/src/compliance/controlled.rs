//! The integrated compliance of a Cosserat solution under step-size control.
//!
//! The cumulative integral `Q(s) = ∫₀ˢ Ad c Adᵀ dσ` (see [`super::integrated`]) is appended to
//! the state and integrated with it from the solution's base wrench by the adaptive
//! Dormand–Prince pair, with every component under error control (the compliance-methodology paper's eq. 8 integrates
//! it with the kinematics in the same way). `Q` is carried dimensionless,
//! `Q̂ = S Q S E I(0) / L` with `S = diag(1/L, 1/L, 1/L, 1, 1, 1)`, so that its entries are of
//! order one and one relative tolerance applies to all of them; its 21 upper-triangle entries
//! are stored. The tolerances are the solution's own for an adaptive solution, else
//! [`COMPLIANCE_RTOL`] and [`COMPLIANCE_ATOL`]: [`super::compliance_at`] of an RK4 solution is
//! then that of its configuration (base wrench) to about `10 COMPLIANCE_RTOL`, independent of its
//! mesh ([`super::compliance`] of an RK4 solution keeps the cheaper quadrature on its mesh).
//! The requested arc lengths are stops of the march (a step ends there), so values are exact,
//! not interpolated.

use nalgebra::{Matrix3, Matrix6, Vector3};

use crate::cosserat::equations::{project, rot, v3, Evaluator, Local, Workspace, STATE};
use crate::cosserat::statics::{interior, scaled, Integrator, StaticsSolution};
use crate::error::{Error, Result};
use crate::integrate::march::{march, Piecewise, Scheme};
use crate::integrate::{AdaptiveOptions, System};
use crate::math::so3::hat;

/// Relative tolerance of the compliance march of an RK4 solution.
pub const COMPLIANCE_RTOL: f64 = 1e-8;
/// Absolute tolerance of the compliance march of an RK4 solution (state units: m, N, N m;
/// `Q̂` is dimensionless).
pub const COMPLIANCE_ATOL: f64 = 1e-10;

/// Entries of the upper triangle of a symmetric 6×6 matrix.
const TRIANGLE: usize = 21;
/// State plus `Q̂`.
const WIDTH: usize = STATE + TRIANGLE;

/// `(i, j)` with `i <= j`, row by row.
fn triangle() -> [(usize, usize); TRIANGLE] {
    let mut t = [(0, 0); TRIANGLE];
    let mut k = 0;
    for i in 0..6 {
        for j in i..6 {
            t[k] = (i, j);
            k += 1;
        }
    }
    t
}

/// The state and `Q̂`: the shooting equations plus the compliance integrand.
struct WithCompliance<'e, 'w> {
    ev: Evaluator<'e, 'w>,
    /// Base position (the origin of `Q`).
    p0: Vector3<f64>,
    /// `S` entries (1/L for translations) and the scale `E I(0) / L`.
    inv_length: f64,
    scale: f64,
    index: [(usize, usize); TRIANGLE],
}

impl WithCompliance<'_, '_> {
    /// Element compliance `c(s)` at the local solution `loc` (the material's tangent at the
    /// rod's own strain).
    fn element(&self, s: f64, loc: &Local) -> [f64; 6] {
        let rod = self.ev.eq.model.rod();
        let (vs, us) = (rod.rest_strain().at(s), rod.rest_curvature().at(s));
        let e = [
            loc.v.x - vs.x,
            loc.v.y - vs.y,
            loc.v.z - vs.z,
            loc.u.x - us.x,
            loc.u.y - us.y,
            loc.u.z - us.z,
        ];
        rod.material().tangent_compliance(
            &rod.section_at(s),
            rod.shear_coefficient(),
            rod.inextensible(),
            &e,
        )
    }
}

/// `Ad c Adᵀ` with `Ad = [[R, P R], [0, R]]`, `P = (p - p(0))^`: with `A = R c_v Rᵀ` and
/// `B = R c_u Rᵀ` it is `[[A + P B Pᵀ, P B], [B Pᵀ, B]]`.
fn integrand(r: &Matrix3<f64>, dp: &Vector3<f64>, c: &[f64; 6]) -> Matrix6<f64> {
    let a = r * Matrix3::from_diagonal(&Vector3::new(c[0], c[1], c[2])) * r.transpose();
    let b = r * Matrix3::from_diagonal(&Vector3::new(c[3], c[4], c[5])) * r.transpose();
    let p = hat(dp);
    let pb = p * b;
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(a + pb * p.transpose()));
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(&pb);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&pb.transpose());
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&b);
    m
}

impl System<WIDTH> for WithCompliance<'_, '_> {
    fn rhs(&mut self, s: f64, y: &[f64; WIDTH], dy: &mut [f64; WIDTH]) {
        let mut head = [0.0; STATE];
        head.copy_from_slice(&y[..STATE]);
        let mut out = [0.0; STATE];
        let loc = self.ev.rhs_into(s, &head, &mut out);
        dy[..STATE].copy_from_slice(&out);
        let c = self.element(s, &loc);
        let m = integrand(&rot(&head), &(v3(&head, 0) - self.p0), &c);
        for (k, &(i, j)) in self.index.iter().enumerate() {
            let si = if i < 3 { self.inv_length } else { 1.0 };
            let sj = if j < 3 { self.inv_length } else { 1.0 };
            dy[STATE + k] = m[(i, j)] * si * sj * self.scale;
        }
    }
    fn project(&mut self, y: &mut [f64; WIDTH]) {
        let mut head = [0.0; STATE];
        head.copy_from_slice(&y[..STATE]);
        project(&mut head);
        y[..STATE].copy_from_slice(&head);
    }
}

impl Piecewise<WIDTH> for WithCompliance<'_, '_> {
    fn enter_interval(&mut self, k: usize) {
        self.ev.set_interval(k);
    }
    fn jump(&mut self, s: f64, y: &mut [f64; WIDTH]) {
        let mut head = [0.0; STATE];
        head.copy_from_slice(&y[..STATE]);
        self.ev.eq.jump(s, &mut head, 0);
        y[..STATE].copy_from_slice(&head);
    }
}

/// A node of the compliance march: arc length, position, rotation, element compliance and
/// `Q` (SI).
pub(crate) struct MarchedNode {
    pub s: f64,
    pub position: Vector3<f64>,
    pub rotation: Matrix3<f64>,
    pub element: [f64; 6],
    pub q: Matrix6<f64>,
}

/// The tolerances of the compliance march of `solution`.
fn tolerances(solution: &StaticsSolution) -> AdaptiveOptions {
    match solution.options.integrator {
        Integrator::Adaptive(a) => a,
        Integrator::Rk4 { .. } => AdaptiveOptions {
            rtol: COMPLIANCE_RTOL,
            atol: COMPLIANCE_ATOL,
            ..AdaptiveOptions::default()
        },
    }
}

/// Marches the state and `Q` of `solution` from its base wrench with stops at `s_out`, and
/// returns the node at each `s_out` in order (a repeated value takes the next copy: before,
/// then after the jump at a break).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `s_out[i]` outside `[0, L]`; what the march reports.
pub(crate) fn march_compliance(
    solution: &StaticsSolution,
    s_out: &[f64],
) -> Result<Vec<MarchedNode>> {
    let model = &*solution.model;
    let length = model.length();
    for (i, &s) in s_out.iter().enumerate() {
        if !(s.is_finite() && (0.0..=length).contains(&s)) {
            return Err(Error::invalid(
                format!("s_out[{i}]"),
                s,
                format!("in [0, length] = [0, {length}] m"),
            ));
        }
    }
    let pressures = solution.pressures();
    let eq = solution.equations(&pressures, solution.stats.load_factor);
    // The moment scale `F L` of the scaled unknowns.
    let fm = model.force_scale() * length;
    let head: [f64; STATE] = eq.initial(&scaled(model, &solution.base_wrench));
    let mut y0 = [0.0; WIDTH];
    y0[..STATE].copy_from_slice(&head);
    let mut ws = Workspace::new(model.tendons().len());
    let mut sys = WithCompliance {
        ev: Evaluator { eq, ws: &mut ws },
        p0: model.rod().base_pose().position(),
        inv_length: 1.0 / length,
        scale: fm,
        index: triangle(),
    };
    let mut stops = interior(s_out, length);
    stops.sort_by(f64::total_cmp);
    stops.dedup();
    let scheme = Scheme::Adaptive {
        options: tolerances(solution),
        controlled: WIDTH,
    };
    let mut recorded: Vec<(f64, [f64; WIDTH], [f64; 6])> = Vec::new();
    let mut sorted = s_out.to_vec();
    sorted.sort_by(f64::total_cmp);
    // (`==` on the sorted values: -0 is 0.)
    let wanted = |s: f64| {
        let k = sorted.partition_point(|&x| x < s);
        k < sorted.len() && sorted[k] == s
    };
    march(
        &mut sys,
        model.breaks(),
        &stops,
        y0,
        scheme,
        |sys, s, _, y| {
            if wanted(s) {
                // The element compliance at the node (a local solve there).
                let mut head = [0.0; STATE];
                head.copy_from_slice(&y[..STATE]);
                let mut out = [0.0; STATE];
                let loc = sys.ev.rhs_into(s, &head, &mut out);
                recorded.push((s, *y, sys.element(s, &loc)));
            }
        },
    )?;
    let index = triangle();
    let unscale = |i: usize| if i < 3 { length } else { 1.0 };
    let mut used = vec![false; recorded.len()];
    let mut out = Vec::with_capacity(s_out.len());
    for &s in s_out {
        // The march records in increasing s (a break twice): the first node at s not yet
        // reported, else the last one at s.
        let first = recorded.partition_point(|r| r.0 < s);
        let same = first + recorded[first..].iter().take_while(|r| r.0 == s).count();
        let k = (first..same)
            .find(|&k| !used[k])
            .or_else(|| same.checked_sub(1).filter(|&k| k >= first))
            .ok_or_else(|| Error::invalid("s_out", s, "a point of the rod"))?;
        used[k] = true;
        let (s, y, element) = &recorded[k];
        let mut q = Matrix6::zeros();
        for (m, &(i, j)) in index.iter().enumerate() {
            let v = y[STATE + m] * unscale(i) * unscale(j) / fm;
            q[(i, j)] = v;
            q[(j, i)] = v;
        }
        out.push(MarchedNode {
            s: *s,
            position: v3(y, 0),
            rotation: rot(y),
            element: *element,
            q,
        });
    }
    Ok(out)
}
