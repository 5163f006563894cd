//! The Cosserat-rod equations with tendons, as a right-hand side for shooting.
//!
//! Along the undeformed arc length `s` (world frame unless noted; `(·)_b` body components):
//!
//! ```text
//! p' = R v,        R' = R û,
//! N' = -f(s),      M' = -p' × N - l(s),
//! ```
//!
//! where `N`, `M` are the **total** internal force and moment carried across the section at
//! `s` by the rod *and the tendons that pass through it*:
//! `N = n + Σ τ_i t_i`, `M = m + Σ (R r_i) × τ_i t_i`, with `n`, `m` the rod's own (elastic)
//! internal wrench, `t_i` the unit tangent of tendon `i`'s path `p_i = p + R r_i`, and
//! `f`, `l` the external distributed force and moment. Cutting the rod *and* its tendons at `s`,
//! the only loads on the distal part are external, hence these two equations. In body
//! components the constitutive law closes the system:
//!
//! ```text
//! n_b = N_b - Σ τ_i t_i,b,   m_b = M_b - Σ τ_i r_i × t_i,b,
//! v = v* + C_v n_b,          u = u* + C_u m_b,
//! t_i,b = w_i / |w_i|,       w_i = v + u × r_i + r_i',
//! ```
//!
//! an implicit equation for `(v, u)` solved by a local Newton iteration at every evaluation
//! (its Jacobian `I + C D`, `D = d(Σ τ t, Σ τ r × t)/d(v, u)`, is exact).
//!
//! This is Rucker & Webster's (2011) tendon model exactly, written for the total wrench:
//! differentiating `n = N - Σ τ t_i` gives their distributed tendon load
//! `-τ_i t_i'` (from the curvature of the tendon path); at a termination `σ` the tendon's term
//! drops out of the sum while `N`, `M` are continuous, so the rod's own wrench jumps by exactly
//! their point force `-τ_i t_i(σ)` and moment `-(R r_i) × τ_i t_i(σ)`. Where the curvature
//! jumps (at a termination or a point load), the tendons that continue have a kink in their
//! path and add the point force `τ_j (t_j⁺ - t_j⁻)` of a tensioned string over a kink (their
//! distributed load integrated across the jump); the total-wrench form includes it exactly.
//! The integration intervals break at every termination and point load, so all jumps are
//! applied exactly.
//!
//! The shooting Jacobian is propagated with the state: for each of the six unknowns of the
//! base wrench, a variation `(δp, w, δN, δM)` with `δR = R ŵ` (body-frame rotation variation)
//! obeys the variational equations
//!
//! ```text
//! δp' = R (w × v + δv),   w' = w × u + δu,   δN' = 0,   δM' = -(δp' × N + p' × δN),
//! (δv, δu) = (I + C D)⁻¹ C (N_b × w + Rᵀ δN, M_b × w + Rᵀ δM).
//! ```
//!
//! # References
//! D. C. Rucker, R. J. Webster III, IEEE Trans. Robotics 27(6), 2011, eqs. (1)–(18).
//! J. Till, V. Aloi, D. C. Rucker, Int. J. Robotics Research 38(6), 2019 (shooting).

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::model::loads::{Frame, Loads};
use crate::model::rod::Rod;
use crate::model::section::SectionProperties;
use crate::math::so3::hat;
use crate::model::tendon::Tendon;


/// Length of the state `(p, R, N, M)`: 3 + 9 + 3 + 3.
pub(crate) const STATE: usize = 18;
/// Length of the state with the six sensitivity columns `(δp, w, δN, δM)` appended.
pub(crate) const FULL: usize = STATE + 6 * 12;

/// Relative step tolerance of the local (constitutive) Newton iteration.
pub const LOCAL_TOLERANCE: f64 = 1e-14;
/// Iteration cap of the local (constitutive) Newton iteration.
pub const LOCAL_MAX_ITERATIONS: usize = 50;

#[inline]
pub(crate) fn v3(y: &[f64], i: usize) -> Vector3<f64> {
    Vector3::new(y[i], y[i + 1], y[i + 2])
}

#[inline]
pub(crate) fn put3(y: &mut [f64], i: usize, v: &Vector3<f64>) {
    y[i] = v.x;
    y[i + 1] = v.y;
    y[i + 2] = v.z;
}

#[inline]
pub(crate) fn rot(y: &[f64]) -> Matrix3<f64> {
    Matrix3::from_column_slice(&y[3..12])
}

/// LU factorisation with partial pivoting of a 6×6 matrix (row-major arrays, no allocation;
/// several times faster than the generic routine for this size).
#[derive(Clone, Copy)]
pub(crate) struct Lu6 {
    a: [[f64; 6]; 6],
    inv_diag: [f64; 6],
    perm: [usize; 6],
}

impl Lu6 {
    /// Factorises `m`; `None` if it is singular to working precision or not finite.
    #[inline]
    pub fn new(m: &Matrix6<f64>) -> Option<Self> {
        let mut a = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                a[i][j] = m[(i, j)];
            }
        }
        let mut perm = [0, 1, 2, 3, 4, 5];
        let mut inv_diag = [0.0; 6];
        for k in 0..6 {
            let mut p = k;
            let mut best = a[k][k].abs();
            for i in k + 1..6 {
                if a[i][k].abs() > best {
                    best = a[i][k].abs();
                    p = i;
                }
            }
            if !(best > 0.0 && best.is_finite()) {
                return None;
            }
            if p != k {
                a.swap(p, k);
                perm.swap(p, k);
            }
            let inv = 1.0 / a[k][k];
            inv_diag[k] = inv;
            for i in k + 1..6 {
                let f = a[i][k] * inv;
                a[i][k] = f;
                for j in k + 1..6 {
                    a[i][j] -= f * a[k][j];
                }
            }
        }
        Some(Self { a, inv_diag, perm })
    }

    /// Solves `M x = b`.
    #[inline]
    pub fn solve(&self, b: &[f64; 6]) -> [f64; 6] {
        let mut x = [0.0; 6];
        for i in 0..6 {
            let mut v = b[self.perm[i]];
            for j in 0..i {
                v -= self.a[i][j] * x[j];
            }
            x[i] = v;
        }
        for i in (0..6).rev() {
            let mut v = x[i];
            for j in i + 1..6 {
                v -= self.a[i][j] * x[j];
            }
            x[i] = v * self.inv_diag[i];
        }
        x
    }
}

/// The local solution at one `s`: strains and tendon load sums (body frame).
#[derive(Clone, Copy)]
pub(crate) struct Local {
    pub v: Vector3<f64>,
    pub u: Vector3<f64>,
    /// `Σ τ t_i` (N, body frame), plus the chambers' fluid force.
    pub tendon_force: Vector3<f64>,
    /// `Σ τ r_i × t_i` (N m, body frame), plus the chambers' fluid moment.
    pub tendon_moment: Vector3<f64>,
}

impl Local {
    pub(crate) fn nan() -> Self {
        Self {
            v: Vector3::repeat(f64::NAN),
            u: Vector3::repeat(f64::NAN),
            tendon_force: Vector3::zeros(),
            tendon_moment: Vector3::zeros(),
        }
    }
}

/// A prepared tendon: termination and scaled tension.
pub(crate) struct ActiveTendon<'a> {
    pub tendon: &'a Tendon,
    pub end: f64,
}

/// The validated problem at one load factor.
pub(crate) struct Model<'a> {
    pub rod: &'a Rod,
    pub tendons: Vec<ActiveTendon<'a>>,
    pub loads: &'a Loads,
    pub shear_coefficient: f64,
    /// `rho g` (N/m³), if gravity is on.
    pub rho_g: Option<Vector3<f64>>,
    /// Load factor `λ` multiplying every load and tension.
    pub factor: f64,
    /// Force scale (N) of the shooting unknowns and residual; moments use `f_ref L`.
    pub f_ref: f64,
    pub length: f64,
    /// Interval end points `0 = b_0 < b_1 < ... = L`.
    pub breaks: Vec<f64>,
    /// Whether no force is applied along the rod (only world-frame tip loads and moments):
    /// then `N ≡ 0` for a zero base force.
    pub force_free: bool,
    /// The section compliance when it does not depend on `s` (linear material, uniform
    /// section), precomputed.
    pub uniform_compliance: Option<[f64; 6]>,
    /// First material failure met by a local solve (a fibre stretch <= 0, an unstable
    /// hyperelastic law), reported if the solve fails.
    pub material_error: std::sync::OnceLock<crate::error::Error>,
}

impl<'a> Model<'a> {
    /// Distributed force `λ (f(s) + rho A(s) g)` (N/m, world).
    #[inline]
    pub(crate) fn distributed_force(&self, s: f64, props: &SectionProperties) -> Vector3<f64> {
        let mut f = match &self.loads.distributed_force {
            Some(p) => p.at(s),
            None => Vector3::zeros(),
        };
        if let Some(g) = &self.rho_g {
            f += g * props.area;
        }
        f * self.factor
    }

    #[inline]
    fn distributed_moment(&self, s: f64) -> Vector3<f64> {
        match &self.loads.distributed_moment {
            Some(p) => p.at(s) * self.factor,
            None => Vector3::zeros(),
        }
    }

    /// Initial state for the scaled base wrench `x` (`N(0) = f_ref x[0..3]`,
    /// `M(0) = f_ref L x[3..6]`), with identity sensitivity seeds when `N == FULL`.
    pub fn initial<const N: usize>(&self, x: &Vector6<f64>) -> [f64; N] {
        let mut y = [0.0; N];
        let pose = self.rod.base_pose();
        put3(&mut y, 0, &pose.position());
        y[3..12].copy_from_slice(pose.rotation().as_slice());
        let fm = self.f_ref * self.length;
        for k in 0..3 {
            y[12 + k] = self.f_ref * x[k];
            y[15 + k] = fm * x[3 + k];
        }
        if N == FULL {
            for k in 0..3 {
                y[STATE + 12 * k + 6 + k] = self.f_ref;
                y[STATE + 12 * (k + 3) + 9 + k] = fm;
            }
        }
        y
    }

    /// World-frame force and moment (and their sensitivity columns) of a load given in
    /// `frame`, applied where the state is `y`.
    #[inline]
    fn applied<const N: usize>(
        &self,
        y: &[f64; N],
        force: &Vector3<f64>,
        moment: &Vector3<f64>,
        frame: Frame,
    ) -> (Vector3<f64>, Vector3<f64>, [[Vector3<f64>; 2]; 6]) {
        let (f, m) = (force * self.factor, moment * self.factor);
        let mut d = [[Vector3::zeros(); 2]; 6];
        match frame {
            Frame::World => (f, m, d),
            Frame::Body => {
                let r = rot(y);
                if N == FULL {
                    for (k, dk) in d.iter_mut().enumerate() {
                        let w = v3(y, STATE + 12 * k + 3);
                        dk[0] = r * w.cross(&f);
                        dk[1] = r * w.cross(&m);
                    }
                }
                (r * f, r * m, d)
            }
        }
    }

    /// Applies the point loads at the interior break `sigma` (crossing it toward the tip).
    pub fn jump<const N: usize>(&self, sigma: f64, y: &mut [f64; N]) {
        for pl in self.loads.point_loads.iter().filter(|p| p.s == sigma) {
            let (f, m, d) = self.applied(y, &pl.force, &pl.moment, pl.frame);
            let (n1, m1) = (v3(y, 12) - f, v3(y, 15) - m);
            put3(y, 12, &n1);
            put3(y, 15, &m1);
            if N == FULL {
                for (k, dk) in d.iter().enumerate() {
                    let b = STATE + 12 * k;
                    let (dn1, dm1) = (v3(y, b + 6) - dk[0], v3(y, b + 9) - dk[1]);
                    put3(y, b + 6, &dn1);
                    put3(y, b + 9, &dm1);
                }
            }
        }
    }

    /// Scaled tip residual `[(N(L) - F)/f_ref; (M(L) - M)/(f_ref L)]` and, when `N == FULL`,
    /// its Jacobian with respect to the scaled base wrench.
    pub fn residual<const N: usize>(&self, y: &[f64; N]) -> (Vector6<f64>, Option<Matrix6<f64>>) {
        let lw = &self.loads;
        let (mut f, mut m, mut d) = self.applied(y, &lw.tip_force, &lw.tip_moment, lw.tip_frame);
        for pl in lw.point_loads.iter().filter(|p| p.s == self.length) {
            let (f2, m2, d2) = self.applied(y, &pl.force, &pl.moment, pl.frame);
            f += f2;
            m += m2;
            for k in 0..6 {
                d[k][0] += d2[k][0];
                d[k][1] += d2[k][1];
            }
        }
        let fm = self.f_ref * self.length;
        let rf = (v3(y, 12) - f) / self.f_ref;
        let rm = (v3(y, 15) - m) / fm;
        let r = Vector6::new(rf.x, rf.y, rf.z, rm.x, rm.y, rm.z);
        if N != FULL {
            return (r, None);
        }
        let mut j = Matrix6::zeros();
        for k in 0..6 {
            let b = STATE + 12 * k;
            let jf = (v3(y, b + 6) - d[k][0]) / self.f_ref;
            let jm = (v3(y, b + 9) - d[k][1]) / fm;
            for i in 0..3 {
                j[(i, k)] = jf[i];
                j[(i + 3, k)] = jm[i];
            }
        }
        (r, Some(j))
    }
}

/// Evaluates the right-hand side; holds the per-interval set of active tendons and scratch.
pub(crate) struct Evaluator<'m, 'a> {
    pub model: &'m Model<'a>,
    /// Indices of the tendons that pass through the current interval with nonzero tension.
    pub(crate) active: Vec<usize>,
    /// Indices of the tendons that pass through the current interval without tension (their
    /// paths are still followed for their lengths).
    pub(crate) passive: Vec<usize>,
    /// Scratch: offsets `(r, r', τ)` of the active tendons at the current `s`.
    pub(crate) offsets: Vec<(Vector3<f64>, Vector3<f64>, f64)>,
    /// Last local solution `(v, u)`, the warm start of the next local Newton iteration.
    pub(crate) guess: Option<Vector6<f64>>,
    /// Factorised local Jacobian `I + C D` of the last local Newton iteration (chord steps).
    pub(crate) last_lu: Option<Lu6>,
    /// Tangent `d(v, u)/d(n_b, m_b)` of the last [`Evaluator::local`] call made with
    /// `tangent = true`: the compliance `C` (`tangent_diag`), premultiplied by `(I + C D)⁻¹`
    /// when tendons are active (`tangent_lu` holds the factorised `I + C D`).
    pub(crate) tangent_diag: [f64; 6],
    pub(crate) tangent_lu: Option<Lu6>,
    /// `|w_i| = |p_i'|` of every tendon at the last evaluation (only updated while
    /// `track_speeds` is set; stale for tendons that end before the current interval).
    pub tendon_speed: Vec<f64>,
    /// Whether [`Evaluator::local`] records the tendon speeds.
    pub track_speeds: bool,
    /// Right-hand-side evaluations so far.
    pub evaluations: usize,
    /// Indices of the pressurised chambers that fill the current interval.
    pub(crate) chambers: Vec<usize>,
}

impl<'m, 'a> Evaluator<'m, 'a> {
    pub fn new(model: &'m Model<'a>) -> Self {
        let n = model.tendons.len();
        Self {
            model,
            active: Vec::with_capacity(n),
            passive: Vec::with_capacity(n),
            offsets: Vec::with_capacity(n),
            guess: None,
            last_lu: None,
            tangent_diag: [0.0; 6],
            tangent_lu: None,
            tendon_speed: vec![0.0; n],
            track_speeds: false,
            evaluations: 0,
            chambers: Vec::new(),
        }
    }

    /// Selects the tendons active on interval `k` (those ending at or beyond its end).
    pub fn set_interval(&mut self, k: usize) {
        let b = self.model.breaks[k + 1];
        self.active.clear();
        self.passive.clear();
        for (i, t) in self.model.tendons.iter().enumerate() {
            if t.end >= b {
                if t.tendon.tension() * self.model.factor > 0.0 {
                    self.active.push(i);
                } else {
                    self.passive.push(i);
                }
            }
        }
        self.guess = None;
        self.last_lu = None;
        self.select_chambers(self.model.breaks[k], b);
    }

    /// Records `|p_i'|` of the tension-free tendons for the strains `(v, u)`.
    #[inline]
    pub(crate) fn passive_speeds(
        &mut self,
        s: f64,
        props: &SectionProperties,
        v: &Vector3<f64>,
        u: &Vector3<f64>,
    ) {
        for &i in &self.passive {
            let (r, rp) = self.model.tendons[i].tendon.routing().offset(s, props);
            let r = Vector3::new(r[0], r[1], 0.0);
            let rp = Vector3::new(rp[0], rp[1], 0.0);
            self.tendon_speed[i] = (v + u.cross(&r) + rp).norm();
        }
    }

    /// Tendon load sums `(Σ τ t, Σ τ r × t)` at the strains `x = (v, u)`, and, if `jac`, the
    /// local Jacobian `I + C D` (see the module documentation).
    ///
    /// Per tendon, with `t = w/|w|`, `q = r × t`, `a = τ/|w|` and `A = a (I - t tᵀ)`:
    /// `dT_F/dv = A`, `dT_F/du = -A r̂ = -a (r̂ + t qᵀ)`, `dT_M/dv = r̂ A = a (r̂ - q tᵀ)`,
    /// `dT_M/du = -r̂ A r̂ = -a (r rᵀ - |r|² I + q qᵀ)`.
    #[inline]
    pub(crate) fn tendon_sums(
        &self,
        x: &Vector6<f64>,
        c: &[f64; 6],
        jac: bool,
    ) -> (Vector6<f64>, Option<Matrix6<f64>>) {
        let v = Vector3::new(x[0], x[1], x[2]);
        let u = Vector3::new(x[3], x[4], x[5]);
        let mut tf = Vector3::zeros();
        let mut tm = Vector3::zeros();
        let mut sa = 0.0;
        let mut sar = Vector3::zeros();
        let mut ar2 = 0.0;
        let mut tt = Matrix3::zeros();
        let mut tq = Matrix3::zeros();
        let mut qq = Matrix3::zeros();
        let mut rr = Matrix3::zeros();
        for (r, rp, tau) in &self.offsets {
            let w = v + u.cross(r) + rp;
            let inv_len = 1.0 / w.norm();
            let t = w * inv_len;
            let q = r.cross(&t);
            tf += t * *tau;
            tm += q * *tau;
            if jac {
                let a = *tau * inv_len;
                let at = t * a;
                sa += a;
                sar += r * a;
                ar2 += a * r.norm_squared();
                tt += at * t.transpose();
                tq += at * q.transpose();
                qq += q * (q * a).transpose();
                rr += r * (r * a).transpose();
            }
        }
        let sums = Vector6::new(tf.x, tf.y, tf.z, tm.x, tm.y, tm.z);
        if !jac {
            return (sums, None);
        }
        let rh = hat(&sar);
        let dfv = Matrix3::identity() * sa - tt;
        let dfu = -(rh + tq);
        let dmv = rh - tq.transpose();
        let dmu = Matrix3::identity() * ar2 - rr - qq;
        let mut h = Matrix6::identity();
        for i in 0..3 {
            for j in 0..3 {
                h[(i, j)] += c[i] * dfv[(i, j)];
                h[(i, j + 3)] += c[i] * dfu[(i, j)];
                h[(i + 3, j)] += c[i + 3] * dmv[(i, j)];
                h[(i + 3, j + 3)] += c[i + 3] * dmu[(i, j)];
            }
        }
        (sums, Some(h))
    }

    /// Solves the constitutive equations at `s` for the body wrench `(nb, mb)`; with
    /// `tangent`, also stores `d(v, u)/d(nb, mb)` for [`Evaluator::rhs`].
    /// Returns NaN strains if the local iteration fails.
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
        let model = self.model;
        let rod = model.rod;
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
        let (e, c) = match &model.uniform_compliance {
            Some(c) => {
                let mut e = [0.0; 6];
                for k in 0..6 {
                    e[k] = c[k] * wb[k];
                }
                (e, *c)
            }
            None => rod.material().elastic_strain(
                props,
                model.shear_coefficient,
                rod.inextensible(),
                &wb,
            ),
        };
        if self.active.is_empty() {
            let out = Local {
                v: vs + Vector3::new(e[0], e[1], e[2]),
                u: us + Vector3::new(e[3], e[4], e[5]),
                tendon_force: Vector3::new(fluid[0], fluid[1], fluid[2]),
                tendon_moment: Vector3::new(fluid[3], fluid[4], fluid[5]),
            };
            if tangent {
                self.tangent_diag = c;
                self.tangent_lu = None;
            }
            if self.track_speeds {
                self.passive_speeds(s, props, &out.v, &out.u);
            }
            return out;
        }
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
        let cd = Vector6::from_column_slice(&c);
        let xs = Vector6::new(vs.x, vs.y, vs.z, us.x, us.y, us.z);
        let wv = Vector6::from_column_slice(&wb);
        let mut x = match self.guess {
            Some(g) => g,
            None => {
                // Straight tendons: t_i = e_z.
                let mut tf = Vector3::zeros();
                let mut tm = Vector3::zeros();
                for (r, _, tau) in &self.offsets {
                    tf.z += tau;
                    tm += r.cross(&Vector3::z()) * *tau;
                }
                xs + cd.component_mul(&(wv - Vector6::new(tf.x, tf.y, tf.z, tm.x, tm.y, tm.z)))
            }
        };
        let mut last_step = f64::INFINITY;
        let mut converged = false;
        let mut chord = self.last_lu.is_some();
        for _ in 0..LOCAL_MAX_ITERATIONS {
            let (tw, h) = self.tendon_sums(&x, &c, !chord);
            let g = x - xs - cd.component_mul(&(wv - tw));
            if let Some(h) = h {
                match Lu6::new(&h) {
                    Some(lu) => self.last_lu = Some(lu),
                    None => return Local::nan(),
                }
            }
            let Some(lu) = &self.last_lu else {
                return Local::nan();
            };
            let dx = Vector6::from(lu.solve(&[g[0], g[1], g[2], g[3], g[4], g[5]]));
            x -= dx;
            if !x.iter().all(|v| v.is_finite()) {
                return Local::nan();
            }
            let step = dx.amax();
            let tol = LOCAL_TOLERANCE * (1.0 + x.amax());
            if step <= tol {
                converged = true;
                break;
            }
            if chord {
                // Chord steps converge linearly with ratio rho: the error left after this step
                // is about step rho / (1 - rho). Switch to Newton unless they contract fast.
                if last_step.is_finite() {
                    let rho = step / last_step;
                    if rho > 0.1 {
                        chord = false;
                    } else if step * rho / (1.0 - rho) <= tol {
                        converged = true;
                        break;
                    }
                }
            } else {
                // Quadratic convergence: the error after this step is about |dx|³ / |dx_prev|².
                let predicted = step * (step / last_step).powi(2);
                if last_step.is_finite() && step < 1e-3 * last_step && predicted <= tol {
                    converged = true;
                    break;
                }
            }
            last_step = step;
        }
        if !converged {
            return Local::nan();
        }
        let mut out = Local {
            v: Vector3::new(x[0], x[1], x[2]),
            u: Vector3::new(x[3], x[4], x[5]),
            tendon_force: Vector3::zeros(),
            tendon_moment: Vector3::zeros(),
        };
        if tangent {
            // (I + C D)⁻¹ C at the solution: keep the factorisation for the sensitivities.
            let (_, h) = self.tendon_sums(&x, &c, true);
            let Some(lu) = h.as_ref().and_then(Lu6::new) else {
                return Local::nan();
            };
            self.tangent_diag = c;
            self.tangent_lu = Some(lu);
            self.last_lu = Some(lu);
        }
        // Tendon loads and speeds |p_i'| at the solution.
        let (mut tf, mut tm) = (Vector3::zeros(), Vector3::zeros());
        for (k, &i) in self.active.iter().enumerate() {
            let (r, rp, tau) = &self.offsets[k];
            let w = out.v + out.u.cross(r) + rp;
            let len = w.norm();
            let a = *tau / len;
            tf += w * a;
            tm += r.cross(&w) * a;
            self.tendon_speed[i] = len;
        }
        out.tendon_force = tf + Vector3::new(fluid[0], fluid[1], fluid[2]);
        out.tendon_moment = tm + Vector3::new(fluid[3], fluid[4], fluid[5]);
        if self.track_speeds {
            self.passive_speeds(s, props, &out.v, &out.u);
        }
        self.guess = Some(x);
        out
    }

    /// Tangent `d(v, u)/d(n_b, m_b)` of the constitutive solve (`(I + C D)⁻¹ C` with active
    /// tendons) left by the last [`Evaluator::rhs`] call with sensitivities (`N == FULL`);
    /// used by `compliance.rs`.
    pub(crate) fn tangent(&self) -> Matrix6<f64> {
        let c = &self.tangent_diag;
        match &self.tangent_lu {
            Some(lu) => {
                let mut m = Matrix6::zeros();
                for j in 0..6 {
                    let mut e = [0.0; 6];
                    e[j] = c[j];
                    let col = lu.solve(&e);
                    for i in 0..6 {
                        m[(i, j)] = col[i];
                    }
                }
                m
            }
            None => Matrix6::from_diagonal(&Vector6::from_column_slice(c)),
        }
    }

    /// Right-hand side of the state (`N == STATE`) or of the state with sensitivities
    /// (`N == FULL`).
    #[inline]
    pub fn rhs<const N: usize>(&mut self, s: f64, y: &[f64; N]) -> [f64; N] {
        let mut out = [0.0; N];
        self.rhs_into(s, y, &mut out);
        out
    }

    /// [`Evaluator::rhs`] written into `out` (every component), for in-place integrators.
    #[inline]
    pub fn rhs_into<const N: usize>(&mut self, s: f64, y: &[f64; N], out: &mut [f64; N]) {
        self.evaluations += 1;
        let model = self.model;
        let props = model.rod.section_at(s);
        let r = rot(y);
        let nw = v3(y, 12);
        let mw = v3(y, 15);
        let nb = r.tr_mul(&nw);
        let mb = r.tr_mul(&mw);
        let loc = self.local(s, &props, &nb, &mb, N == FULL);
        let (v, u) = (loc.v, loc.u);
        let pd = r * v;
        let rd = r * hat(&u);
        let nd = -model.distributed_force(s, &props);
        let md = -pd.cross(&nw) - model.distributed_moment(s);
        put3(out, 0, &pd);
        out[3..12].copy_from_slice(rd.as_slice());
        put3(out, 12, &nd);
        put3(out, 15, &md);
        if N == FULL {
            for k in 0..6 {
                let b = STATE + 12 * k;
                let w = v3(y, b + 3);
                let dn = v3(y, b + 6);
                let dm = v3(y, b + 9);
                let dnb = nb.cross(&w) + r.tr_mul(&dn);
                let dmb = mb.cross(&w) + r.tr_mul(&dm);
                let c = &self.tangent_diag;
                let cw = [
                    c[0] * dnb.x,
                    c[1] * dnb.y,
                    c[2] * dnb.z,
                    c[3] * dmb.x,
                    c[4] * dmb.y,
                    c[5] * dmb.z,
                ];
                let d = match &self.tangent_lu {
                    None => cw,
                    Some(lu) => lu.solve(&cw),
                };
                let (dv, du) = (
                    Vector3::new(d[0], d[1], d[2]),
                    Vector3::new(d[3], d[4], d[5]),
                );
                let dpd = r * (w.cross(&v) + dv);
                let wd = w.cross(&u) + du;
                let dmd = -(dpd.cross(&nw) + pd.cross(&dn));
                put3(out, b, &dpd);
                put3(out, b + 3, &wd);
                put3(out, b + 6, &Vector3::zeros());
                put3(out, b + 9, &dmd);
            }
        }
    }
}
