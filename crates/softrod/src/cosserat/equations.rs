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
//! base wrench, a variation `(δp, δR, δN, δM)` in the same coordinates as the state obeys the
//! variational equations
//!
//! ```text
//! δp' = δR v + R δv,   δR' = δR û + R δû,   δN' = 0,   δM' = -(δp' × N + p' × δN),
//! (δv, δu) = (I + C D)⁻¹ C (δRᵀ N + Rᵀ δN, δRᵀ M + Rᵀ δM).
//! ```
//!
//! Runge–Kutta methods commute with linearisation when the variation is written in the
//! coordinates of the state: the integrated columns, with the derivative of the
//! re-orthonormalisation applied after every step, are then the exact derivative of the
//! discrete march (not only an approximation of the continuous variation to the order of the
//! method), so the tangent compliance is the derivative of the solve it comes from. (A
//! 3-vector `w` with `δR = R ŵ` would differ from it by the method's truncation error, large
//! where the rod is strongly curved per step, e.g. the thin end of a taper.)
//!
//! # References
//! D. C. Rucker, R. J. Webster III, IEEE Trans. Robotics 27(6), 2011, eqs. (1)–(18).
//! J. Till, V. Aloi, D. C. Rucker, Int. J. Robotics Research 38(6), 2019 (shooting).

//!
//! Extra sensitivity columns (the tangent compliance, held tendons) follow the same
//! variational equations; a column for the tension of tendon `i` is forced by `-(t_i, r_i × t_i)`
//! in the body wrench of the constitutive solve (`∂n_b/∂τ_i` at fixed strains), and the
//! sensitivity of the tendon path length is `δℓ_i = ∫ t_iᵀ (δv + δu × r_i) ds`.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::error::Error;
use crate::integrate::march::Piecewise;
use crate::integrate::System;
use crate::math::linalg::Inverse6;
use crate::math::so3::{hat, reorthonormalise};
use crate::model::actuation::TensionProfile;
use crate::model::loads::Frame;
use crate::model::section::SectionProperties;
use crate::model::RobotModel;

/// Length of the state `(p, R, N, M)`: 3 + 9 + 3 + 3.
pub(crate) const STATE: usize = 18;
/// Length of one sensitivity column `(δp, δR, δN, δM)`, laid out as the state: the
/// derivative of the state along one unknown, so that the integrator's linear combinations
/// (and the projection's derivative) make it the exact derivative of the discrete march.
pub(crate) const COLUMN: usize = STATE;
/// Offset of `δR` (9, column-major) in a column.
pub(crate) const DR: usize = 3;
/// Offset of `δN` in a column.
pub(crate) const DN: usize = 12;
/// Offset of `δM` in a column.
pub(crate) const DM: usize = 15;
/// Length of the state with the six shooting columns appended.
pub(crate) const FULL: usize = STATE + 6 * COLUMN;

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

/// `δR` of the column starting at `b`.
#[inline]
pub(crate) fn col_rot(y: &[f64], b: usize) -> Matrix3<f64> {
    Matrix3::from_column_slice(&y[b + DR..b + DR + 9])
}

/// The rotation variation `δθ` (world, rad) of `δR` at `R`: the axial vector of the skew
/// part of `δR Rᵀ` (`δR = δθ̂ R` on the rotation group).
#[inline]
pub(crate) fn rotation_variation(r: &Matrix3<f64>, dr: &Matrix3<f64>) -> Vector3<f64> {
    let a = dr * r.transpose();
    Vector3::new(
        0.5 * (a[(2, 1)] - a[(1, 2)]),
        0.5 * (a[(0, 2)] - a[(2, 0)]),
        0.5 * (a[(1, 0)] - a[(0, 1)]),
    )
}

/// `A û` (column-major, into `out`): column `j` is `A (u × e_j)`, 18 products instead of
/// the 27 of a 3×3 product.
#[inline]
pub(crate) fn mul_hat(a: &Matrix3<f64>, u: &Vector3<f64>, out: &mut [f64]) {
    let (a0, a1, a2) = (a.column(0), a.column(1), a.column(2));
    let c0 = a1 * u.z - a2 * u.y;
    let c1 = a2 * u.x - a0 * u.z;
    let c2 = a0 * u.y - a1 * u.x;
    out[..3].copy_from_slice(c0.as_slice());
    out[3..6].copy_from_slice(c1.as_slice());
    out[6..9].copy_from_slice(c2.as_slice());
}

/// `A û + B ŵ` (column-major, into `out`), as [`mul_hat`].
#[inline]
pub(crate) fn mul_hat2(
    a: &Matrix3<f64>,
    u: &Vector3<f64>,
    b: &Matrix3<f64>,
    w: &Vector3<f64>,
    out: &mut [f64],
) {
    let (a0, a1, a2) = (a.column(0), a.column(1), a.column(2));
    let (b0, b1, b2) = (b.column(0), b.column(1), b.column(2));
    let c0 = a1 * u.z - a2 * u.y + b1 * w.z - b2 * w.y;
    let c1 = a2 * u.x - a0 * u.z + b2 * w.x - b0 * w.z;
    let c2 = a0 * u.y - a1 * u.x + b0 * w.y - b1 * w.x;
    out[..3].copy_from_slice(c0.as_slice());
    out[3..6].copy_from_slice(c1.as_slice());
    out[6..9].copy_from_slice(c2.as_slice());
}

/// Re-orthonormalises the rotation part of a state, and maps each column's `δR` by the
/// derivative of the same step, `δR (3I - RᵀR)/2 - R (δRᵀR + RᵀδR)/2` (at the unprojected
/// `R`).
#[inline]
pub(crate) fn project<const N: usize>(y: &mut [f64; N]) {
    let raw = rot(y);
    let r = reorthonormalise(&raw);
    y[3..12].copy_from_slice(r.as_slice());
    let rtr = raw.tr_mul(&raw);
    let half = Matrix3::identity() * 1.5 - rtr * 0.5;
    for c in 0..(N - STATE) / COLUMN {
        let b = STATE + COLUMN * c;
        let dr = col_rot(y, b);
        let sym = dr.tr_mul(&raw);
        let d = dr * half - raw * (sym + sym.transpose()) * 0.5;
        y[b + DR..b + DR + 9].copy_from_slice(d.as_slice());
    }
}

/// The tangent `d(v, u)/d(n_b, m_b)` of one constitutive solve: `(I + C D)⁻¹ C` with active
/// tendons (`lu` the inverted `I + C D`), `C` (`diag`) without.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tangent {
    pub diag: [f64; 6],
    pub lu: Option<Inverse6>,
}

impl Tangent {
    /// `d(v, u)` for the body-wrench perturbation `e`.
    #[inline(always)]
    pub fn apply(&self, e: &[f64; 6]) -> [f64; 6] {
        match &self.lu {
            None => std::array::from_fn(|k| self.diag[k] * e[k]),
            Some(lu) => lu.solve_scaled(&self.diag, e),
        }
    }
}

/// The local solution at one `s`: strains, tendon and fluid load sums (body frame). The
/// tangent, when asked for, is left in [`Workspace::tangent`] (a large value, not copied
/// around) for the variational columns of the same evaluation.
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
    /// The strains `x = (v, u)` before the tendon and fluid sums are added.
    pub(crate) fn strains(x: &Vector6<f64>) -> Self {
        Self {
            v: Vector3::new(x[0], x[1], x[2]),
            u: Vector3::new(x[3], x[4], x[5]),
            tendon_force: Vector3::zeros(),
            tendon_moment: Vector3::zeros(),
        }
    }

    pub(crate) fn nan() -> Self {
        Self {
            v: Vector3::repeat(f64::NAN),
            u: Vector3::repeat(f64::NAN),
            tendon_force: Vector3::zeros(),
            tendon_moment: Vector3::zeros(),
        }
    }
}

/// The equations of one configuration: the model, the tendon tensions (N) and chamber
/// pressures (Pa) of the actuation, and the load factor `λ` that scales the external loads
/// (the actuation is always applied in full).
#[derive(Clone, Copy)]
pub(crate) struct Equations<'a> {
    pub model: &'a RobotModel,
    pub tensions: &'a [f64],
    pub pressures: &'a [f64],
    pub load_factor: f64,
    /// The tension along the tendons when it varies (friction, `cosserat::friction`);
    /// `None`: `tensions` over each tendon's whole length.
    pub profile: Option<&'a TensionProfile>,
}

/// What a sensitivity column is a derivative with respect to: its forcing along the rod
/// (see `cosserat/sensitivity.rs`, where the parameters are documented).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Column {
    /// A component of the base wrench or of an applied wrench: no forcing term.
    Free,
    /// The tension of tendon `i` (per N).
    Tension(usize),
    /// The pressure of chamber `j` (per Pa).
    Pressure(usize),
    /// A common factor of every tension (per unit factor, at 1).
    TensionScale,
    /// A common factor of the section stiffness (per unit factor, at 1).
    StiffnessScale,
    /// A factor of the offset `r_i(s)` of tendon `i` (per unit factor, at 1).
    TendonOffsetScale(usize),
    /// A shift of the offset of tendon `i` along the body-frame direction (per m).
    TendonOffsetShift(usize, [f64; 2]),
    /// A factor of the area of chamber `j` (per unit factor, at 1).
    ChamberAreaScale(usize),
}

impl Column {
    /// Whether the column's forcing needs the directions of the tendons.
    fn needs_directions(&self) -> bool {
        matches!(
            self,
            Column::Tension(_)
                | Column::TensionScale
                | Column::TendonOffsetScale(_)
                | Column::TendonOffsetShift(..)
        )
    }
}

/// Scratch of the evaluations of one solve (the workspace): per-interval tendon and chamber
/// sets, warm starts of the local iteration, stage quadratures.
pub(crate) struct Workspace {
    /// Indices of the tendons that pass through the current interval with nonzero tension.
    pub active: Vec<usize>,
    /// Indices of the tendons that pass through the current interval without tension.
    pub passive: Vec<usize>,
    /// Offsets `(r, r', τ)` of the active tendons at the current `s`.
    pub offsets: Vec<(Vector3<f64>, Vector3<f64>, f64)>,
    /// Last local solution `(v, u)`, the warm start of the next local Newton iteration.
    pub guess: Option<Vector6<f64>>,
    /// Inverted local Jacobian of the last local Newton iteration (chord steps).
    pub last_lu: Option<Inverse6>,
    /// `|p_i'|` of every tendon at the last evaluation (zero for tendons not in the interval).
    pub tendon_speed: Vec<f64>,
    /// Right-hand-side evaluations so far.
    pub evaluations: usize,
    /// Indices of the pressurised chambers that fill the current interval.
    pub chambers: Vec<usize>,
    /// Current interval.
    pub interval: usize,
    /// The sensitivity columns integrated with the state (at most `(N - STATE) / COLUMN`).
    pub columns: Vec<Column>,
    /// Tendons whose path-length sensitivities are integrated for every column.
    pub length_tendons: Vec<usize>,
    /// Quadrature integrands of the current stage: tendon speeds, then per column the
    /// path-length sensitivities of `length_tendons`.
    pub integrand: Vec<f64>,
    /// The integrands of each stage of the current step.
    pub stages: Vec<Vec<f64>>,
    /// The integrals so far: tendon lengths (m), then path-length sensitivities.
    pub integral: Vec<f64>,
    /// Whether the tendon speeds (and so the tendon-length quadrature) are recorded at every
    /// evaluation (the speeds of the tensioned tendons always are).
    pub track_lengths: bool,
    /// Tangent of the last local solve asked for it (read by the variational columns of the
    /// same evaluation).
    pub tangent: Tangent,
    /// `(t_i, r_i × t_i)` (body) of the tendons through the current interval at the current
    /// evaluation, for the columns (`None`: not through it or not computed).
    pub dirs: Vec<Option<Vector6<f64>>>,
    /// First material failure met by a local solve, reported if the solve fails.
    pub material_error: Option<Error>,
}

impl Workspace {
    pub fn new(n_tendons: usize) -> Self {
        Self {
            active: Vec::with_capacity(n_tendons),
            passive: Vec::with_capacity(n_tendons),
            offsets: Vec::with_capacity(n_tendons),
            guess: None,
            last_lu: None,
            tendon_speed: vec![0.0; n_tendons],
            evaluations: 0,
            chambers: Vec::new(),
            interval: 0,
            columns: Vec::new(),
            length_tendons: Vec::new(),
            integrand: vec![0.0; n_tendons],
            stages: Vec::new(),
            integral: vec![0.0; n_tendons],
            track_lengths: false,
            tangent: Tangent {
                diag: [f64::NAN; 6],
                lu: None,
            },
            dirs: vec![None; n_tendons],
            material_error: None,
        }
    }

    /// Sets the columns and the tendons whose length sensitivities are integrated, and resets
    /// the quadratures.
    pub fn set_columns(&mut self, columns: &[Column], length_tendons: &[usize]) {
        self.columns.clear();
        self.columns.extend_from_slice(columns);
        self.length_tendons.clear();
        self.length_tendons.extend_from_slice(length_tendons);
        let m = self.tendon_speed.len() + columns.len() * length_tendons.len();
        self.integrand.resize(m, 0.0);
        self.reset_quadrature();
    }

    /// Zeroes the integrals (before a pass).
    pub fn reset_quadrature(&mut self) {
        self.integral.clear();
        self.integral.resize(self.integrand.len(), 0.0);
    }
}

/// Evaluates the right-hand side of the equations in a workspace.
pub(crate) struct Evaluator<'e, 'w> {
    pub eq: Equations<'e>,
    pub ws: &'w mut Workspace,
}

impl<'e> Equations<'e> {
    /// Distributed force `λ (f(s) + rho A(s) g)` (N/m, world).
    #[inline]
    pub fn distributed_force(&self, s: f64, props: &SectionProperties) -> Vector3<f64> {
        let loads = self.model.loads();
        let mut f = match &loads.distributed_force {
            Some(p) => p.at(s),
            None => Vector3::zeros(),
        };
        if let Some(g) = self.model.rho_g() {
            f += g * props.area;
        }
        f * self.load_factor
    }

    #[inline]
    fn distributed_moment(&self, s: f64) -> Vector3<f64> {
        match &self.model.loads().distributed_moment {
            Some(p) => p.at(s) * self.load_factor,
            None => Vector3::zeros(),
        }
    }

    /// Initial state for the scaled base wrench `x` (`N(0) = f_ref x[0..3]`,
    /// `M(0) = f_ref L x[3..6]`), with identity seeds for the first six columns when they
    /// fit in `N`.
    pub fn initial<const N: usize>(&self, x: &[f64]) -> [f64; N] {
        let mut y = [0.0; N];
        let pose = self.model.rod().base_pose();
        put3(&mut y, 0, &pose.position());
        y[3..12].copy_from_slice(pose.rotation().as_slice());
        let f_ref = self.model.force_scale();
        let fm = f_ref * self.model.length();
        for k in 0..3 {
            y[12 + k] = f_ref * x[k];
            y[15 + k] = fm * x[3 + k];
        }
        if N >= FULL {
            for k in 0..3 {
                y[STATE + COLUMN * k + DN + k] = f_ref;
                y[STATE + COLUMN * (k + 3) + DM + k] = fm;
            }
        }
        y
    }

    /// World-frame force and moment (and, for the first `ncol` columns, their sensitivities)
    /// of a load given in `frame`, applied where the state is `y`.
    #[inline]
    fn applied<const N: usize>(
        &self,
        y: &[f64; N],
        ncol: usize,
        force: &Vector3<f64>,
        moment: &Vector3<f64>,
        frame: Frame,
        d: &mut [[Vector3<f64>; 2]],
    ) -> (Vector3<f64>, Vector3<f64>) {
        let (f, m) = (force * self.load_factor, moment * self.load_factor);
        match frame {
            Frame::World => (f, m),
            Frame::Body => {
                let r = rot(y);
                for (k, dk) in d.iter_mut().enumerate().take(ncol) {
                    let dr = col_rot(y, STATE + COLUMN * k);
                    dk[0] += dr * f;
                    dk[1] += dr * m;
                }
                (r * f, r * m)
            }
        }
    }

    /// Applies the point loads at the interior break `sigma` (crossing it toward the tip) to
    /// the state and its first `ncol` columns.
    pub fn jump<const N: usize>(&self, sigma: f64, y: &mut [f64; N], ncol: usize) {
        let loads = self.model.loads();
        let mut d = vec![[Vector3::zeros(); 2]; ncol];
        for pl in loads.point_loads.iter().filter(|p| p.s == sigma) {
            d.iter_mut().for_each(|x| *x = [Vector3::zeros(); 2]);
            let (f, m) = self.applied(y, ncol, &pl.force, &pl.moment, pl.frame, &mut d);
            let (n1, m1) = (v3(y, 12) - f, v3(y, 15) - m);
            put3(y, 12, &n1);
            put3(y, 15, &m1);
            for (k, dk) in d.iter().enumerate() {
                let b = STATE + COLUMN * k;
                let (dn1, dm1) = (v3(y, b + DN) - dk[0], v3(y, b + DM) - dk[1]);
                put3(y, b + DN, &dn1);
                put3(y, b + DM, &dm1);
            }
        }
    }

    /// Scaled tip residual `[(N(L) - F)/f_ref; (M(L) - M)/(f_ref L)]` and its derivative
    /// along each of the first `ncol` columns.
    pub fn residual<const N: usize>(
        &self,
        y: &[f64; N],
        ncol: usize,
    ) -> (Vector6<f64>, Vec<Vector6<f64>>) {
        let lw = self.model.loads();
        let mut d = vec![[Vector3::zeros(); 2]; ncol];
        let (mut f, mut m) =
            self.applied(y, ncol, &lw.tip_force, &lw.tip_moment, lw.tip_frame, &mut d);
        let l = self.model.length();
        for pl in lw.point_loads.iter().filter(|p| p.s == l) {
            let (f2, m2) = self.applied(y, ncol, &pl.force, &pl.moment, pl.frame, &mut d);
            f += f2;
            m += m2;
        }
        let f_ref = self.model.force_scale();
        let fm = f_ref * l;
        let rf = (v3(y, 12) - f) / f_ref;
        let rm = (v3(y, 15) - m) / fm;
        let r = Vector6::new(rf.x, rf.y, rf.z, rm.x, rm.y, rm.z);
        let cols = (0..ncol)
            .map(|k| {
                let b = STATE + COLUMN * k;
                let jf = (v3(y, b + DN) - d[k][0]) / f_ref;
                let jm = (v3(y, b + DM) - d[k][1]) / fm;
                Vector6::new(jf.x, jf.y, jf.z, jm.x, jm.y, jm.z)
            })
            .collect();
        (r, cols)
    }

    /// `∂r/∂λ` of the scaled tip residual at fixed unknowns, when the external loads do not
    /// change the internal force along the rod (world-frame tip and point moments, tip force):
    /// minus the scaled applied tip wrench. `None` otherwise.
    pub fn load_derivative_force_free(&self) -> Option<Vector6<f64>> {
        let lw = self.model.loads();
        if !self.model.force_free() || lw.tip_frame == Frame::Body {
            return None;
        }
        if lw
            .point_loads
            .iter()
            .any(|p| p.frame == Frame::Body && p.moment != Vector3::zeros())
        {
            return None;
        }
        if lw.distributed_moment.is_some() {
            return None;
        }
        let l = self.model.length();
        let mut m = lw.tip_moment;
        let f = lw.tip_force;
        // A world-frame moment applied along the rod reaches the tip unchanged (N ≡ const).
        for p in lw.point_loads.iter() {
            m += p.moment;
        }
        let f_ref = self.model.force_scale();
        let fm = f_ref * l;
        Some(Vector6::new(
            -f.x / f_ref,
            -f.y / f_ref,
            -f.z / f_ref,
            -m.x / fm,
            -m.y / fm,
            -m.z / fm,
        ))
    }
}

impl Evaluator<'_, '_> {
    /// Selects the tendons and chambers active on interval `k`.
    pub fn set_interval(&mut self, k: usize) {
        let model = self.eq.model;
        let breaks = model.breaks();
        let (a, b) = (breaks[k], breaks[k + 1]);
        let ws = &mut *self.ws;
        ws.interval = k;
        ws.active.clear();
        ws.passive.clear();
        for (i, &end) in model.tendon_ends().iter().enumerate() {
            ws.tendon_speed[i] = 0.0;
            if end >= b {
                if self.eq.tensions[i] != 0.0 {
                    ws.active.push(i);
                } else {
                    ws.passive.push(i);
                }
            }
        }
        ws.guess = None;
        ws.last_lu = None;
        ws.chambers.clear();
        for (i, &(start, end)) in model.chamber_extents().iter().enumerate() {
            if start <= a && end >= b && self.eq.pressures[i] != 0.0 {
                ws.chambers.push(i);
            }
        }
    }

    /// Body-frame wrench carried by the fluid of the active chambers at `s` (zero without).
    #[inline]
    pub(crate) fn chamber_wrench(&self, s: f64) -> [f64; 6] {
        let mut w = [0.0; 6];
        let chambers = self.eq.model.chambers();
        for &i in &self.ws.chambers {
            let c = chambers[i].fluid_wrench(s, self.eq.pressures[i]);
            for k in 0..6 {
                w[k] += c[k];
            }
        }
        w
    }

    /// Offsets `(r, r', τ)` of the active tendons at `s` into the workspace.
    #[inline]
    pub(crate) fn load_offsets(&mut self, s: f64, props: &SectionProperties) {
        let tendons = self.eq.model.tendons();
        self.ws.offsets.clear();
        for &i in &self.ws.active {
            let (r, rp) = tendons[i].routing().offset(s, props);
            let tau = self
                .eq
                .profile
                .and_then(|p| p.at(i, s))
                .unwrap_or(self.eq.tensions[i]);
            self.ws.offsets.push((
                Vector3::new(r[0], r[1], 0.0),
                Vector3::new(rp[0], rp[1], 0.0),
                tau,
            ));
        }
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
        if !self.ws.track_lengths {
            return;
        }
        let tendons = self.eq.model.tendons();
        for &i in &self.ws.passive {
            let (r, rp) = tendons[i].routing().offset(s, props);
            let r = Vector3::new(r[0], r[1], 0.0);
            let rp = Vector3::new(rp[0], rp[1], 0.0);
            self.ws.tendon_speed[i] = (v + u.cross(&r) + rp).norm();
        }
    }

    /// `(t, r × t)` of tendon `i` (body) at strains `(v, u)`.
    pub(crate) fn tendon_direction(
        &self,
        i: usize,
        s: f64,
        props: &SectionProperties,
        v: &Vector3<f64>,
        u: &Vector3<f64>,
    ) -> Vector6<f64> {
        let (r, rp) = self.eq.model.tendons()[i].routing().offset(s, props);
        let r = Vector3::new(r[0], r[1], 0.0);
        let w = v + u.cross(&r) + Vector3::new(rp[0], rp[1], 0.0);
        let t = w / w.norm();
        let q = r.cross(&t);
        Vector6::new(t.x, t.y, t.z, q.x, q.y, q.z)
    }

    /// Tendon load sums `(Σ τ t, Σ τ r × t)` at the strains `x = (v, u)` (the chord steps of
    /// the local iteration: [`Self::tendon_sums`] without the Jacobian).
    #[inline]
    pub(crate) fn tendon_load(&self, x: &Vector6<f64>) -> Vector6<f64> {
        let v = Vector3::new(x[0], x[1], x[2]);
        let u = Vector3::new(x[3], x[4], x[5]);
        let mut tf = Vector3::zeros();
        let mut tm = Vector3::zeros();
        for (r, rp, tau) in &self.ws.offsets {
            let w = v + u.cross(r) + rp;
            let t = w * (*tau / w.norm());
            tf += t;
            tm += r.cross(&t);
        }
        Vector6::new(tf.x, tf.y, tf.z, tm.x, tm.y, tm.z)
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
        self.tendon_sums_into(x, c, jac, None)
    }

    /// [`Self::tendon_sums`]; with `stiffness`, `D` itself goes there (rows) instead of
    /// `I + C D`.
    #[inline]
    pub(crate) fn tendon_sums_into(
        &self,
        x: &Vector6<f64>,
        c: &[f64; 6],
        jac: bool,
        stiffness: Option<&mut [[f64; 6]; 6]>,
    ) -> (Vector6<f64>, Option<Matrix6<f64>>) {
        let jac = jac || stiffness.is_some();
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
        for (r, rp, tau) in &self.ws.offsets {
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
        if let Some(out) = stiffness {
            // D is symmetric: [[dfv, dfu], [dmv = dfuᵀ, dmu]].
            for i in 0..3 {
                for j in 0..3 {
                    out[i][j] = dfv[(i, j)];
                    out[i][j + 3] = dfu[(i, j)];
                    out[i + 3][j] = dmv[(i, j)];
                    out[i + 3][j + 3] = dmu[(i, j)];
                }
            }
            return (sums, None);
        }
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
        self.load_offsets(s, props);
        let cd = Vector6::from_column_slice(&c);
        let xs = Vector6::new(vs.x, vs.y, vs.z, us.x, us.y, us.z);
        let wv = Vector6::from_column_slice(&wb);
        let x = match self.ws.guess {
            Some(g) => g,
            None => {
                // Straight tendons: t_i = e_z.
                let mut tf = Vector3::zeros();
                let mut tm = Vector3::zeros();
                for (r, _, tau) in &self.ws.offsets {
                    tf.z += tau;
                    tm += r.cross(&Vector3::z()) * *tau;
                }
                xs + cd.component_mul(&(wv - Vector6::new(tf.x, tf.y, tf.z, tm.x, tm.y, tm.z)))
            }
        };
        let Some(x) = self.local_iteration(x, &xs, &cd, &wv, &c) else {
            return Local::nan();
        };
        let mut out = Local::strains(&x);
        if tangent {
            // (I + C D)⁻¹ C at the solution: by Cholesky of the similar I + C^½ D C^½
            // (D is symmetric positive semi-definite), else by Gauss–Jordan.
            let mut d = [[0.0; 6]; 6];
            self.tendon_sums_into(&x, &c, true, Some(&mut d));
            let lu = Inverse6::of_compliance_stiffness(&c, &d).or_else(|| {
                let (_, h) = self.tendon_sums(&x, &c, true);
                h.as_ref().and_then(Inverse6::new)
            });
            let Some(lu) = lu else {
                return Local::nan();
            };
            self.ws.tangent = Tangent {
                diag: c,
                lu: Some(lu),
            };
            self.ws.last_lu = Some(lu);
        }
        self.finish_tendons(s, props, &mut out, &fluid);
        self.ws.guess = Some(x);
        out
    }

    /// The local Newton (or chord) iteration on `G(x) = x - x* - C (W - T(x)) = 0` from `x`;
    /// `None` if it fails.
    #[inline]
    fn local_iteration(
        &mut self,
        mut x: Vector6<f64>,
        xs: &Vector6<f64>,
        cd: &Vector6<f64>,
        wv: &Vector6<f64>,
        c: &[f64; 6],
    ) -> Option<Vector6<f64>> {
        let mut last_step = f64::INFINITY;
        let mut chord = self.ws.last_lu.is_some();
        for _ in 0..LOCAL_MAX_ITERATIONS {
            let tw = if chord {
                self.tendon_load(&x)
            } else {
                let (tw, h) = self.tendon_sums(&x, c, true);
                self.ws.last_lu = Some(Inverse6::new(&h?)?);
                tw
            };
            let g = x - xs - cd.component_mul(&(wv - tw));
            let lu = self.ws.last_lu.as_ref()?;
            let dx = Vector6::from(lu.solve(&[g[0], g[1], g[2], g[3], g[4], g[5]]));
            x -= dx;
            if !x.iter().all(|v| v.is_finite()) {
                return None;
            }
            let step = dx.amax();
            let tol = LOCAL_TOLERANCE * (1.0 + x.amax());
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

    /// Tendon loads and speeds `|p_i'|` at the local solution `out`, plus the fluid's share.
    #[inline]
    pub(crate) fn finish_tendons(
        &mut self,
        s: f64,
        props: &SectionProperties,
        out: &mut Local,
        fluid: &[f64; 6],
    ) {
        let (mut tf, mut tm) = (Vector3::zeros(), Vector3::zeros());
        for (k, &i) in self.ws.active.iter().enumerate() {
            let (r, rp, tau) = &self.ws.offsets[k];
            let w = out.v + out.u.cross(r) + rp;
            let len = w.norm();
            let a = *tau / len;
            tf += w * a;
            tm += r.cross(&w) * a;
            self.ws.tendon_speed[i] = len;
        }
        out.tendon_force = tf + Vector3::new(fluid[0], fluid[1], fluid[2]);
        out.tendon_moment = tm + Vector3::new(fluid[3], fluid[4], fluid[5]);
        let (v, u) = (out.v, out.u);
        self.passive_speeds(s, props, &v, &u);
    }

    /// The right-hand side of the state and of the active columns (`N >= STATE + COLUMN
    /// ncol`), and the stage integrands (tendon speeds, path-length sensitivities); returns
    /// the local solution (strains, actuator sums) at `s`.
    #[inline]
    pub fn rhs_into<const N: usize>(&mut self, s: f64, y: &[f64; N], out: &mut [f64; N]) -> Local {
        self.ws.evaluations += 1;
        let eq = self.eq;
        let props = eq.model.rod().section_at(s);
        let r = rot(y);
        let nw = v3(y, 12);
        let mw = v3(y, 15);
        let nb = r.tr_mul(&nw);
        let mb = r.tr_mul(&mw);
        let ncol = self.ws.columns.len().min((N - STATE) / COLUMN);
        let loc = self.local(s, &props, &nb, &mb, ncol > 0);
        let (v, u) = (loc.v, loc.u);
        let pd = r * v;
        let nd = -eq.distributed_force(s, &props);
        let md = -pd.cross(&nw) - eq.distributed_moment(s);
        put3(out, 0, &pd);
        mul_hat(&r, &u, &mut out[3..12]);
        put3(out, 12, &nd);
        put3(out, 15, &md);
        let nt = self.ws.tendon_speed.len();
        self.ws.integrand[..nt].copy_from_slice(&self.ws.tendon_speed);
        if ncol == 0 {
            return loc;
        }
        if !loc.v.x.is_finite() {
            self.ws.tangent.diag = [f64::NAN; 6];
        }
        let b_end = eq.model.breaks()[self.ws.interval + 1];
        let ends = eq.model.tendon_ends();
        let nl = self.ws.length_tendons.len();
        let needs_dirs = nl > 0 || self.ws.columns[..ncol].iter().any(Column::needs_directions);
        if needs_dirs {
            for i in 0..ends.len() {
                self.ws.dirs[i] =
                    (ends[i] >= b_end).then(|| self.tendon_direction(i, s, &props, &v, &u));
            }
        }
        // The rod's own (elastic) body wrench, for the stiffness columns.
        let n_el = Vector6::new(
            nb.x - loc.tendon_force.x,
            nb.y - loc.tendon_force.y,
            nb.z - loc.tendon_force.z,
            mb.x - loc.tendon_moment.x,
            mb.y - loc.tendon_moment.y,
            mb.z - loc.tendon_moment.z,
        );
        let tangent = self.ws.tangent;
        for c in 0..ncol {
            let b = STATE + COLUMN * c;
            let dr = col_rot(y, b);
            let dn = v3(y, b + DN);
            let dm = v3(y, b + DM);
            let dnb = dr.tr_mul(&nw) + r.tr_mul(&dn);
            let dmb = dr.tr_mul(&mw) + r.tr_mul(&dm);
            let mut e = [dnb.x, dnb.y, dnb.z, dmb.x, dmb.y, dmb.z];
            let column = self.ws.columns[c];
            // d|p_i'| of the tendon whose offset the column changes, at fixed strains.
            let mut offset_rate = None;
            if column != Column::Free {
                let (f, rate) = self.forcing(column, s, &props, &v, &u, &n_el);
                for k in 0..6 {
                    e[k] -= f[k];
                }
                offset_rate = rate;
            }
            let d = tangent.apply(&e);
            let (dv, du) = (
                Vector3::new(d[0], d[1], d[2]),
                Vector3::new(d[3], d[4], d[5]),
            );
            let dpd = dr * v + r * dv;
            let dmd = -(dpd.cross(&nw) + pd.cross(&dn));
            put3(out, b, &dpd);
            mul_hat2(&dr, &u, &r, &du, &mut out[b + DR..b + DR + 9]);
            put3(out, b + DN, &Vector3::zeros());
            put3(out, b + DM, &dmd);
            for h in 0..nl {
                let i = self.ws.length_tendons[h];
                let mut g = match &self.ws.dirs[i] {
                    Some(t) => t.dot(&Vector6::from(d)),
                    None => 0.0,
                };
                if let Some((k, rate)) = offset_rate {
                    if k == i {
                        g += rate;
                    }
                }
                self.ws.integrand[nt + c * nl + h] = g;
            }
        }
        for k in STATE + COLUMN * ncol..N {
            out[k] = 0.0;
        }
        loc
    }
}

impl<const N: usize> System<N> for Evaluator<'_, '_> {
    #[inline]
    fn rhs(&mut self, t: f64, y: &[f64; N], dy: &mut [f64; N]) {
        let _ = self.rhs_into(t, y, dy);
    }
    #[inline]
    fn stage_evaluated(&mut self, stage: usize) {
        let ws = &mut *self.ws;
        if ws.stages.len() <= stage {
            ws.stages.resize(stage + 1, Vec::new());
        }
        ws.stages[stage].clear();
        ws.stages[stage].extend_from_slice(&ws.integrand);
    }
    #[inline]
    fn step_accepted(&mut self, weights: &[f64], fsal: bool) {
        let ws = &mut *self.ws;
        for (i, &w) in weights.iter().enumerate() {
            if w != 0.0 {
                for (acc, g) in ws.integral.iter_mut().zip(&ws.stages[i]) {
                    *acc += w * g;
                }
            }
        }
        if fsal {
            let last = weights.len() - 1;
            let (first, rest) = ws.stages.split_at_mut(1);
            first[0].clone_from(&rest[last - 1]);
        }
    }
    #[inline]
    fn project(&mut self, y: &mut [f64; N]) {
        project(y);
    }
}

impl<const N: usize> Piecewise<N> for Evaluator<'_, '_> {
    fn enter_interval(&mut self, k: usize) {
        self.set_interval(k);
    }
    fn jump(&mut self, s: f64, y: &mut [f64; N]) {
        let ncol = self.ws.columns.len().min((N - STATE) / COLUMN);
        self.eq.jump(s, y, ncol);
    }
}
