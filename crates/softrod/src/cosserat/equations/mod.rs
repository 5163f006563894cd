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
//!
//! The files: `state.rs` (the layout of the state and its columns, the projection onto the
//! rotations), `boundary.rs` (the initial state, the external loads, the jumps at point loads,
//! the tip residual), `tendons.rs` (the tendons and chambers of an interval, the tendon load
//! sums and their Jacobian), `local.rs` (the constitutive local solve), `rhs.rs` (the
//! right-hand side of the state and its columns, the integrator's interface).

mod boundary;
mod hold;
mod local;
mod rhs;
mod state;
mod tendons;

use nalgebra::{Vector3, Vector6};

use crate::error::Error;
use crate::math::linalg::Inverse6;
use crate::model::actuation::TensionProfile;
use crate::model::RobotModel;

pub(crate) use state::*;

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

/// A linear local solve of an interval whose offsets and tensions are fixed
/// ([`Workspace::fixed_offsets`]) at a zero body wrench (the rod and the tendons carry no
/// load together; on a robot loaded by its actuators only the shooting starts from a zero
/// base wrench and the total wrench stays exactly zero), with the other inputs that
/// determine it: the fluid's share of the wrench, the rest strains and the compliance at `s`.
/// An evaluation that repeats them exactly has the same solution, so on a uniform rod every
/// evaluation of an interval after its first is a look-up. Any other local solve replaces or
/// clears it, so that the workspace's tangent and tendon speeds are always those of the
/// memo's solve when it is read.
#[derive(Clone, Copy)]
pub(crate) struct LocalMemo {
    pub fluid: [f64; 6],
    pub rest: Vector6<f64>,
    pub compliance: [f64; 6],
    /// The solution (strains, tendon and fluid sums).
    pub out: Local,
    /// Whether the tangent at the solution was left in [`Workspace::tangent`].
    pub tangent: bool,
    /// Whether the tension-free tendons' speeds were recorded.
    pub lengths: bool,
}

impl LocalMemo {
    /// The memo of a solve at a zero body wrench with these other inputs (the offsets and
    /// tensions of the workspace).
    #[cold]
    #[inline(never)]
    pub fn new(
        fluid: [f64; 6],
        rest: Vector6<f64>,
        compliance: [f64; 6],
        out: Local,
        tangent: bool,
        lengths: bool,
    ) -> Self {
        Self {
            fluid,
            rest,
            compliance,
            out,
            tangent,
            lengths,
        }
    }

    /// The solution of the equations of these inputs (at a zero body wrench, with the
    /// offsets and tensions the memo was made with), if the memo holds it, with the tangent
    /// and the tension-free tendons' speeds if they are asked for.
    #[inline]
    pub fn solves(
        &self,
        fluid: &[f64; 6],
        rest: &Vector6<f64>,
        compliance: &[f64; 6],
        tangent: bool,
        lengths: bool,
    ) -> Option<Local> {
        (self.fluid == *fluid
            && self.rest == *rest
            && self.compliance == *compliance
            && (self.tangent || !tangent)
            && (self.lengths || !lengths))
            .then_some(self.out)
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

impl<'a> Equations<'a> {
    /// The equations of a configuration under its full external loads (`λ = 1`), with
    /// `tensions` over each tendon's whole length.
    pub fn new(model: &'a RobotModel, tensions: &'a [f64], pressures: &'a [f64]) -> Self {
        Self {
            model,
            tensions,
            pressures,
            load_factor: 1.0,
            profile: None,
        }
    }
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
    /// Whether `offsets` (and `passive_offsets`) hold for the whole current interval
    /// (constant routings and tensions).
    pub fixed_offsets: bool,
    /// Offsets `r` of the passive tendons, with `fixed_offsets`.
    pub passive_offsets: Vec<Vector3<f64>>,
    /// Last local solution `(v, u)`, the warm start of the next local Newton iteration.
    pub guess: Option<Vector6<f64>>,
    /// The tendon sums `T(x)` at the strains `x` a linear local solve last ended with (its
    /// first chord step from there needs no evaluation if the offsets are unchanged).
    pub guess_sums: Option<(Vector6<f64>, Vector6<f64>)>,
    /// Inverted local Jacobian of the last local Newton iteration (chord steps).
    pub last_lu: Option<Inverse6>,
    /// The last local solve, if it was one at a zero body wrench (see [`LocalMemo`]).
    pub memo: Option<LocalMemo>,
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
    /// The normal pressure (N/m) of a held interval at the last evaluation on one (see
    /// `hold.rs`), and its outward normal.
    pub hold_pressure: (f64, Vector3<f64>),
}

impl Workspace {
    pub fn new(n_tendons: usize) -> Self {
        Self {
            active: Vec::with_capacity(n_tendons),
            passive: Vec::with_capacity(n_tendons),
            offsets: Vec::with_capacity(n_tendons),
            fixed_offsets: false,
            passive_offsets: Vec::with_capacity(n_tendons),
            guess: None,
            guess_sums: None,
            last_lu: None,
            memo: None,
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
            hold_pressure: (0.0, Vector3::zeros()),
        }
    }

    /// Resets to the state [`Workspace::new`] makes for `n_tendons`, keeping the storage of its
    /// vectors (a sequence of solves with one workspace allocates once).
    pub fn renew(&mut self, n_tendons: usize) {
        self.active.clear();
        self.passive.clear();
        self.offsets.clear();
        self.fixed_offsets = false;
        self.passive_offsets.clear();
        self.guess = None;
        self.guess_sums = None;
        self.last_lu = None;
        self.memo = None;
        self.tendon_speed.clear();
        self.tendon_speed.resize(n_tendons, 0.0);
        self.evaluations = 0;
        self.chambers.clear();
        self.interval = 0;
        self.columns.clear();
        self.length_tendons.clear();
        self.integrand.clear();
        self.integrand.resize(n_tendons, 0.0);
        self.stages.clear();
        self.integral.clear();
        self.integral.resize(n_tendons, 0.0);
        self.track_lengths = false;
        self.tangent = Tangent {
            diag: [f64::NAN; 6],
            lu: None,
        };
        self.dirs.clear();
        self.dirs.resize(n_tendons, None);
        self.material_error = None;
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
