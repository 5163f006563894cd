//! Ordinary-differential-equation integrators shared by every model.
//!
//! * [`bs23`]: the adaptive Bogacki–Shampine 3(2) pair (the method of MATLAB's `ode23`),
//!   FSAL, with cubic Hermite dense output; integrates forward or backward in `t`.
//! * [`rk4_step`], [`rk4`]: the classical fixed-step fourth-order Runge–Kutta method.
//! * [`dp54`]: the adaptive Dormand–Prince 5(4) pair, FSAL, with its fourth-order continuous
//!   extension as dense output, error control on a leading part of the state and a projection
//!   hook after each step.
//!
//! States are fixed-size arrays `[f64; N]` so the compiler can keep them in registers.
//!
//! # References
//! P. Bogacki, L. F. Shampine, "A 3(2) pair of Runge–Kutta formulas",
//! Appl. Math. Lett. 2(4), 1989. L. F. Shampine, M. W. Reichelt, "The MATLAB ODE suite",
//! SIAM J. Sci. Comput. 18(1), 1997.

use crate::error::{Error, Result};

/// Default relative tolerance of the adaptive integrators.
pub const DEFAULT_RTOL: f64 = 1e-8;
/// Default absolute tolerance of the adaptive integrators (in the state's own units).
pub const DEFAULT_ATOL: f64 = 1e-10;
/// Default cap on the number of attempted steps of one adaptive integration.
pub const DEFAULT_MAX_STEPS: usize = 100_000;

/// Options of an adaptive integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveOptions {
    /// Relative tolerance (> 0): per component, the local error estimate is kept below
    /// `atol + rtol * |y|`.
    pub rtol: f64,
    /// Absolute tolerance (> 0), in the units of the state.
    pub atol: f64,
    /// Maximum number of attempted steps before [`Error::NotConverged`].
    pub max_steps: usize,
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        Self {
            rtol: DEFAULT_RTOL,
            atol: DEFAULT_ATOL,
            max_steps: DEFAULT_MAX_STEPS,
        }
    }
}

impl AdaptiveOptions {
    /// Validates the tolerances.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-finite or non-positive `rtol`/`atol`, an `rtol`
    /// below 100 machine epsilons, or `max_steps == 0`.
    pub fn validated(self) -> Result<Self> {
        if !(self.rtol.is_finite() && self.rtol >= 100.0 * f64::EPSILON && self.rtol < 1.0) {
            return Err(Error::invalid("rtol", self.rtol, "in [2.2e-14, 1)"));
        }
        if !(self.atol.is_finite() && self.atol > 0.0) {
            return Err(Error::invalid("atol", self.atol, "finite and > 0"));
        }
        if self.max_steps == 0 {
            return Err(Error::invalid("max_steps", self.max_steps, ">= 1"));
        }
        Ok(self)
    }
}

/// Statistics of one adaptive integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct IntegrationStats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// Right-hand-side evaluations.
    pub evaluations: usize,
}

/// The accepted steps of an adaptive integration, with cubic Hermite dense output.
#[derive(Debug, Clone)]
pub struct DenseSolution<const N: usize> {
    /// Mesh points in the order of integration (decreasing if integrated backward).
    pub t: Vec<f64>,
    /// States at the mesh points.
    pub y: Vec<[f64; N]>,
    /// Derivatives at the mesh points.
    pub dy: Vec<[f64; N]>,
    /// Step statistics.
    pub stats: IntegrationStats,
}

impl<const N: usize> DenseSolution<N> {
    /// Interpolated state at `t` (cubic Hermite on the step that contains `t`, third order
    /// like the method). `t` outside the integrated interval is clamped to it.
    pub fn eval(&self, t: f64) -> [f64; N] {
        let Some(i) = step_containing(&self.t, t) else {
            return self.y[0];
        };
        let (t0, t1) = (self.t[i], self.t[i + 1]);
        let h = t1 - t0;
        let x = ((t - t0) / h).clamp(0.0, 1.0);
        let x2 = x * x;
        let x3 = x2 * x;
        let h00 = 2.0 * x3 - 3.0 * x2 + 1.0;
        let h10 = x3 - 2.0 * x2 + x;
        let h01 = -2.0 * x3 + 3.0 * x2;
        let h11 = x3 - x2;
        let mut out = [0.0; N];
        for j in 0..N {
            out[j] = h00 * self.y[i][j]
                + h * h10 * self.dy[i][j]
                + h01 * self.y[i + 1][j]
                + h * h11 * self.dy[i + 1][j];
        }
        out
    }
}

/// Index `i` of the step `[t_i, t_{i+1}]` of a mesh (increasing or decreasing, in integration
/// order) that contains `t`, clamped to the first or last step; `None` for a one-point mesh.
fn step_containing(mesh: &[f64], t: f64) -> Option<usize> {
    let n = mesh.len();
    if n < 2 {
        return None;
    }
    let pos = if mesh[n - 1] > mesh[0] {
        mesh.partition_point(|&ti| ti <= t)
    } else {
        mesh.partition_point(|&ti| ti >= t)
    };
    Some(pos.clamp(1, n - 1) - 1)
}

const BS23: &str = "ode23 (Bogacki-Shampine) integration";
const DP54: &str = "Dormand-Prince 5(4) integration";

fn not_converged(method: &str, detail: &str, iterations: usize, residual: f64) -> Error {
    Error::NotConverged {
        what: format!("{method}{detail}"),
        iterations,
        residual,
    }
}

/// Max norm over the first `controlled` components of the local error estimate `e(j)`, each
/// scaled by `atol + rtol * max(|y_j|, |y_new,j|)` (1 = at tolerance), as in MATLAB's solvers.
#[inline]
fn scaled_error<const N: usize>(
    y: &[f64; N],
    y_new: &[f64; N],
    controlled: usize,
    opts: &AdaptiveOptions,
    e: impl Fn(usize) -> f64,
) -> f64 {
    (0..controlled).fold(0.0f64, |m, j| {
        let sc = opts.atol + opts.rtol * y[j].abs().max(y_new[j].abs());
        m.max((e(j) / sc).abs())
    })
}

/// Factor of the next step after a scaled error `err` for a pair whose propagated solution has
/// order `order` (error ~ `h^order`): `0.9 err^(-1/order)`, within `[0.2, 5]` after an accepted
/// step and `[0.1, 0.9]` after a rejected one.
#[inline]
fn step_factor(err: f64, order: f64, accepted: bool) -> f64 {
    if accepted && err == 0.0 {
        return 5.0;
    }
    let f = 0.9 * err.powf(-1.0 / order);
    if accepted {
        f.clamp(0.2, 5.0)
    } else {
        f.clamp(0.1, 0.9)
    }
}

/// Initial step size (Hairer–Nørsett–Wanner's heuristic) from the first `controlled`
/// components of the state `y0` and its derivative `k1`, within `[tiny, |span|]`.
fn initial_step<const N: usize>(
    y0: &[f64; N],
    k1: &[f64; N],
    controlled: usize,
    span: f64,
    tiny: f64,
    opts: &AdaptiveOptions,
) -> f64 {
    let scale = |j: usize| opts.atol + opts.rtol * y0[j].abs();
    let d0 = (0..controlled)
        .map(|j| (y0[j] / scale(j)).abs())
        .fold(0.0, f64::max);
    let d1 = (0..controlled)
        .map(|j| (k1[j] / scale(j)).abs())
        .fold(0.0, f64::max);
    let h = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6 * span.abs()
    } else {
        0.01 * d0 / d1
    };
    h.min(span.abs()).max(tiny)
}

/// The signed step from `t` toward `t1` (direction `dir`) of size at most `h`, stretched to land
/// exactly on `t1` when less than `tiny` would remain.
#[inline]
fn clipped_step(t: f64, t1: f64, h: f64, dir: f64, tiny: f64) -> f64 {
    let hs = h.min((t1 - t).abs()) * dir;
    if (t1 - (t + hs)) * dir <= tiny {
        t1 - t
    } else {
        hs
    }
}

#[inline]
fn axpy<const N: usize>(y: &[f64; N], h: f64, terms: &[(f64, &[f64; N])]) -> [f64; N] {
    let mut out = *y;
    for &(c, k) in terms {
        for j in 0..N {
            out[j] += h * c * k[j];
        }
    }
    out
}

/// Integrates `dy/dt = f(t, y)` from `(t0, y0)` to `t1` with the Bogacki–Shampine 3(2) pair.
///
/// `t1 < t0` integrates backward (a final-value problem). Local extrapolation: the third-order
/// solution is propagated, the embedded second-order one only estimates the error, which is kept
/// below `atol + rtol * max(|y_n|, |y_{n+1}|)` per component (max norm), as in `ode23`.
///
/// # Errors
/// [`Error::InvalidParameter`] for bad options or non-finite end points;
/// [`Error::NotConverged`] if `max_steps` is exceeded, the step size underflows, or the
/// right-hand side returns a non-finite value.
pub fn bs23<const N: usize, F>(
    mut f: F,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    options: AdaptiveOptions,
) -> Result<DenseSolution<N>>
where
    F: FnMut(f64, &[f64; N]) -> [f64; N],
{
    let opts = options.validated()?;
    if !t0.is_finite() || !t1.is_finite() {
        return Err(Error::invalid("t_span", format!("[{t0}, {t1}]"), "finite"));
    }
    let mut stats = IntegrationStats::default();
    let mut sol = DenseSolution {
        t: vec![t0],
        y: vec![y0],
        dy: Vec::new(),
        stats,
    };
    let mut k1 = f(t0, &y0);
    stats.evaluations += 1;
    sol.dy.push(k1);
    let span = t1 - t0;
    if span == 0.0 {
        sol.stats = stats;
        return Ok(sol);
    }
    let dir = span.signum();
    let tiny = 16.0 * f64::EPSILON * t0.abs().max(t1.abs()).max(f64::MIN_POSITIVE);

    // Initial step (Hairer–Nørsett–Wanner's heuristic, order 3).
    let mut h = initial_step(&y0, &k1, N, span, tiny, &opts);

    let (mut t, mut y) = (t0, y0);
    let mut attempts = 0usize;
    let mut last_err = f64::NAN;
    while (t1 - t) * dir > tiny {
        attempts += 1;
        if attempts > opts.max_steps {
            return Err(not_converged(BS23, "", attempts - 1, last_err));
        }
        let hs = clipped_step(t, t1, h, dir, tiny);
        let k2 = f(t + 0.5 * hs, &axpy(&y, hs, &[(0.5, &k1)]));
        let k3 = f(t + 0.75 * hs, &axpy(&y, hs, &[(0.75, &k2)]));
        let y_new = axpy(
            &y,
            hs,
            &[(2.0 / 9.0, &k1), (1.0 / 3.0, &k2), (4.0 / 9.0, &k3)],
        );
        let t_new = if hs == t1 - t { t1 } else { t + hs };
        let k4 = f(t_new, &y_new);
        stats.evaluations += 3;
        let err = scaled_error(&y, &y_new, N, &opts, |j| {
            hs * (-5.0 / 72.0 * k1[j] + 1.0 / 12.0 * k2[j] + 1.0 / 9.0 * k3[j] - 1.0 / 8.0 * k4[j])
        });
        if !err.is_finite() || y_new.iter().any(|v| !v.is_finite()) {
            return Err(not_converged(
                BS23,
                ": non-finite state",
                attempts,
                f64::INFINITY,
            ));
        }
        last_err = err;
        if err <= 1.0 {
            t = t_new;
            y = y_new;
            k1 = k4;
            stats.accepted += 1;
            sol.t.push(t);
            sol.y.push(y);
            sol.dy.push(k1);
            h = hs.abs() * step_factor(err, 3.0, true);
        } else {
            stats.rejected += 1;
            h = hs.abs() * step_factor(err, 3.0, false);
            if h <= tiny {
                return Err(not_converged(BS23, ": step size underflow", attempts, err));
            }
        }
    }
    sol.stats = stats;
    Ok(sol)
}

/// One classical fourth-order Runge–Kutta step of size `h` from `(t, y)`.
///
/// `f` is called exactly four times, in the order `(t, y)`, `(t + h/2, ·)`, `(t + h/2, ·)`,
/// `(t + h, ·)`, so a caller can accumulate quadratures of side quantities with the weights
/// `h (1, 2, 2, 1) / 6` (Simpson's rule).
#[inline]
pub fn rk4_step<const N: usize, F>(f: &mut F, t: f64, y: &[f64; N], h: f64) -> [f64; N]
where
    F: FnMut(f64, &[f64; N]) -> [f64; N],
{
    let k1 = f(t, y);
    let k2 = f(t + 0.5 * h, &axpy(y, h, &[(0.5, &k1)]));
    let k3 = f(t + 0.5 * h, &axpy(y, h, &[(0.5, &k2)]));
    let k4 = f(t + h, &axpy(y, h, &[(1.0, &k3)]));
    let mut out = *y;
    let h6 = h / 6.0;
    for j in 0..N {
        out[j] += h6 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
    }
    out
}

/// Stage buffers of [`rk4_step_in_place`], reused across steps (no allocation, no copies of
/// the state on return).
#[derive(Debug, Clone)]
pub struct Rk4Workspace<const N: usize> {
    k: [[f64; N]; 4],
    tmp: [f64; N],
}

impl<const N: usize> Default for Rk4Workspace<N> {
    fn default() -> Self {
        Self {
            k: [[0.0; N]; 4],
            tmp: [0.0; N],
        }
    }
}

/// One classical fourth-order Runge–Kutta step of size `h`, updating `y` in place.
///
/// `f(t, y, dy)` must write every component of `dy`. Evaluation order as [`rk4_step`];
/// the results are bitwise identical to it.
#[inline]
pub fn rk4_step_in_place<const N: usize, F>(
    f: &mut F,
    t: f64,
    y: &mut [f64; N],
    h: f64,
    ws: &mut Rk4Workspace<N>,
) where
    F: FnMut(f64, &[f64; N], &mut [f64; N]),
{
    let [k1, k2, k3, k4] = &mut ws.k;
    let tmp = &mut ws.tmp;
    f(t, y, k1);
    for j in 0..N {
        tmp[j] = y[j] + h * 0.5 * k1[j];
    }
    f(t + 0.5 * h, tmp, k2);
    for j in 0..N {
        tmp[j] = y[j] + h * 0.5 * k2[j];
    }
    f(t + 0.5 * h, tmp, k3);
    for j in 0..N {
        tmp[j] = y[j] + h * k3[j];
    }
    f(t + h, tmp, k4);
    let h6 = h / 6.0;
    for j in 0..N {
        y[j] += h6 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
    }
}

/// Integrates `dy/dt = f(t, y)` from `(t0, y0)` to `t1` in `steps` equal classical RK4 steps
/// (fourth order; `t1 < t0` integrates backward). Returns the mesh points and the states there
/// (`steps + 1` of each).
///
/// # Errors
/// [`Error::InvalidParameter`] if `steps == 0` or an end point is not finite;
/// [`Error::NotConverged`] if a state becomes non-finite.
pub fn rk4<const N: usize, F>(
    mut f: F,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    steps: usize,
) -> Result<(Vec<f64>, Vec<[f64; N]>)>
where
    F: FnMut(f64, &[f64; N]) -> [f64; N],
{
    if steps == 0 {
        return Err(Error::invalid("steps", steps, ">= 1"));
    }
    if !t0.is_finite() || !t1.is_finite() {
        return Err(Error::invalid("t_span", format!("[{t0}, {t1}]"), "finite"));
    }
    let h = (t1 - t0) / steps as f64;
    let mut ts = Vec::with_capacity(steps + 1);
    let mut ys = Vec::with_capacity(steps + 1);
    ts.push(t0);
    ys.push(y0);
    let mut y = y0;
    for i in 0..steps {
        let t = t0 + h * i as f64;
        y = rk4_step(&mut f, t, &y, h);
        if y.iter().any(|v| !v.is_finite()) {
            return Err(Error::NotConverged {
                what: "rk4 integration: non-finite state".into(),
                iterations: i + 1,
                residual: f64::INFINITY,
            });
        }
        ts.push(if i + 1 == steps { t1 } else { t + h });
        ys.push(y);
    }
    Ok((ts, ys))
}

/// Dormand–Prince 5(4) tableau (Hairer, Nørsett & Wanner, *Solving ODEs I*, table 5.2) and
/// the coefficients of its fourth-order continuous extension.
mod dp {
    pub const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
    pub const A21: f64 = 0.2;
    pub const A3: [f64; 2] = [3.0 / 40.0, 9.0 / 40.0];
    pub const A4: [f64; 3] = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
    pub const A5: [f64; 4] = [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
    ];
    pub const A6: [f64; 5] = [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
    ];
    /// Fifth-order weights (also the last stage row; FSAL). `b2 = 0`.
    pub const B: [f64; 6] = [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ];
    /// Error weights `b - b*` for stages 1..7 (`e2 = 0`).
    pub const E: [f64; 7] = [
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ];
    /// Dense-output weights for stages 1..7 (`d2 = 0`).
    pub const D: [f64; 7] = [
        -12715105075.0 / 11282082432.0,
        0.0,
        87487479700.0 / 32700410799.0,
        -10690763975.0 / 1880347072.0,
        701980252875.0 / 199316789632.0,
        -1453857185.0 / 822651844.0,
        69997945.0 / 29380423.0,
    ];
}

/// The accepted steps of a Dormand–Prince 5(4) integration, with its fourth-order continuous
/// extension as dense output.
#[derive(Debug, Clone)]
pub struct Dp54Solution<const N: usize> {
    /// Mesh points in the order of integration.
    pub t: Vec<f64>,
    /// States at the mesh points (after the caller's projection, if any).
    pub y: Vec<[f64; N]>,
    /// Per step `i` (from `t[i]` to `t[i+1]`), the five dense-output coefficient vectors.
    pub dense: Vec<[[f64; N]; 5]>,
    /// Step statistics.
    pub stats: IntegrationStats,
}

impl<const N: usize> Dp54Solution<N> {
    /// Interpolated state at `t` (fourth-order continuous extension of the step containing
    /// `t`); `t` outside the integrated interval is clamped to it.
    pub fn eval(&self, t: f64) -> [f64; N] {
        let Some(i) = step_containing(&self.t, t) else {
            return self.y[0];
        };
        let (t0, t1) = (self.t[i], self.t[i + 1]);
        let th = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let th1 = 1.0 - th;
        let r = &self.dense[i];
        let mut out = [0.0; N];
        for j in 0..N {
            out[j] = r[0][j] + th * (r[1][j] + th1 * (r[2][j] + th * (r[3][j] + th1 * r[4][j])));
        }
        out
    }
}

/// Integrates `dy/dt = f(t, y)` from `(t0, y0)` to `t1` with the adaptive Dormand–Prince 5(4)
/// pair (local extrapolation, FSAL, fourth-order dense output).
///
/// Only the first `controlled` components enter the error estimate (e.g. a state without the
/// sensitivities appended to it); the error per component is kept below
/// `atol + rtol * max(|y_n|, |y_{n+1}|)` (max norm). After every accepted step `project` may
/// modify the state (e.g. re-orthonormalise a rotation matrix); pass `|_| {}` for none.
///
/// # Errors
/// [`Error::InvalidParameter`] for bad options, non-finite end points or
/// `controlled ∉ 1..=N`; [`Error::NotConverged`] if `max_steps` is exceeded, the step size
/// underflows, or the state becomes non-finite.
///
/// # References
/// J. R. Dormand, P. J. Prince, J. Comput. Appl. Math. 6(1), 1980; E. Hairer, S. P. Nørsett,
/// G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., Springer 1993, II.5–6.
pub fn dp54<const N: usize, F, P>(
    mut f: F,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    options: AdaptiveOptions,
    controlled: usize,
    mut project: P,
) -> Result<Dp54Solution<N>>
where
    F: FnMut(f64, &[f64; N]) -> [f64; N],
    P: FnMut(&mut [f64; N]),
{
    let opts = options.validated()?;
    if !t0.is_finite() || !t1.is_finite() {
        return Err(Error::invalid("t_span", format!("[{t0}, {t1}]"), "finite"));
    }
    if controlled == 0 || controlled > N {
        return Err(Error::invalid(
            "controlled",
            controlled,
            format!("in 1..={N}"),
        ));
    }
    let mut stats = IntegrationStats::default();
    let mut sol = Dp54Solution {
        t: vec![t0],
        y: vec![y0],
        dense: Vec::new(),
        stats,
    };
    let span = t1 - t0;
    if span == 0.0 {
        return Ok(sol);
    }
    let mut k1 = f(t0, &y0);
    stats.evaluations += 1;
    let dir = span.signum();
    let tiny = 16.0 * f64::EPSILON * t0.abs().max(t1.abs()).max(f64::MIN_POSITIVE);
    let mut h = initial_step(&y0, &k1, controlled, span, tiny, &opts);
    let (mut t, mut y) = (t0, y0);
    let mut attempts = 0usize;
    let mut last_err = f64::NAN;
    while (t1 - t) * dir > tiny {
        attempts += 1;
        if attempts > opts.max_steps {
            return Err(not_converged(DP54, "", attempts - 1, last_err));
        }
        let hs = clipped_step(t, t1, h, dir, tiny);
        let k2 = f(t + dp::C[1] * hs, &axpy(&y, hs, &[(dp::A21, &k1)]));
        let k3 = f(
            t + dp::C[2] * hs,
            &axpy(&y, hs, &[(dp::A3[0], &k1), (dp::A3[1], &k2)]),
        );
        let k4 = f(
            t + dp::C[3] * hs,
            &axpy(
                &y,
                hs,
                &[(dp::A4[0], &k1), (dp::A4[1], &k2), (dp::A4[2], &k3)],
            ),
        );
        let k5 = f(
            t + dp::C[4] * hs,
            &axpy(
                &y,
                hs,
                &[
                    (dp::A5[0], &k1),
                    (dp::A5[1], &k2),
                    (dp::A5[2], &k3),
                    (dp::A5[3], &k4),
                ],
            ),
        );
        let t_new = if hs == t1 - t { t1 } else { t + hs };
        let k6 = f(
            t_new,
            &axpy(
                &y,
                hs,
                &[
                    (dp::A6[0], &k1),
                    (dp::A6[1], &k2),
                    (dp::A6[2], &k3),
                    (dp::A6[3], &k4),
                    (dp::A6[4], &k5),
                ],
            ),
        );
        let y_new = axpy(
            &y,
            hs,
            &[
                (dp::B[0], &k1),
                (dp::B[2], &k3),
                (dp::B[3], &k4),
                (dp::B[4], &k5),
                (dp::B[5], &k6),
            ],
        );
        let k7 = f(t_new, &y_new);
        stats.evaluations += 6;
        let err = scaled_error(&y, &y_new, controlled, &opts, |j| {
            hs * (dp::E[0] * k1[j]
                + dp::E[2] * k3[j]
                + dp::E[3] * k4[j]
                + dp::E[4] * k5[j]
                + dp::E[5] * k6[j]
                + dp::E[6] * k7[j])
        });
        if !err.is_finite() || y_new.iter().any(|v| !v.is_finite()) {
            return Err(not_converged(
                DP54,
                ": non-finite state",
                attempts,
                f64::INFINITY,
            ));
        }
        last_err = err;
        if err <= 1.0 {
            let mut rc = [[0.0; N]; 5];
            for j in 0..N {
                let dy = y_new[j] - y[j];
                let bspl = hs * k1[j] - dy;
                rc[0][j] = y[j];
                rc[1][j] = dy;
                rc[2][j] = bspl;
                rc[3][j] = dy - hs * k7[j] - bspl;
                rc[4][j] = hs
                    * (dp::D[0] * k1[j]
                        + dp::D[2] * k3[j]
                        + dp::D[3] * k4[j]
                        + dp::D[4] * k5[j]
                        + dp::D[5] * k6[j]
                        + dp::D[6] * k7[j]);
            }
            t = t_new;
            y = y_new;
            project(&mut y);
            k1 = k7;
            stats.accepted += 1;
            sol.t.push(t);
            sol.y.push(y);
            sol.dense.push(rc);
            h = hs.abs() * step_factor(err, 5.0, true);
        } else {
            stats.rejected += 1;
            h = hs.abs() * step_factor(err, 5.0, false);
            if h <= tiny {
                return Err(not_converged(DP54, ": step size underflow", attempts, err));
            }
        }
    }
    sol.stats = stats;
    Ok(sol)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn exponential_decay_forward_meets_tolerance() {
        let opts = AdaptiveOptions {
            rtol: 1e-9,
            atol: 1e-12,
            ..Default::default()
        };
        let sol = bs23(|_, y: &[f64; 1]| [-2.0 * y[0]], 0.0, [1.0], 3.0, opts).unwrap();
        let y_end = sol.y.last().unwrap()[0];
        let exact = (-6.0f64).exp();
        assert!((y_end - exact).abs() / exact < 1e-6, "{y_end} vs {exact}");
        // Dense output at an interior point.
        let mid = sol.eval(1.3)[0];
        assert!((mid - (-2.6f64).exp()).abs() < 1e-8);
    }

    #[test]
    fn backward_integration_of_final_value_problem() {
        // y' = cos t, y(2) = sin 2, integrate to 0: y(0) = 0.
        let sol = bs23(
            |t, _y: &[f64; 1]| [t.cos()],
            2.0,
            [2.0f64.sin()],
            0.0,
            AdaptiveOptions {
                rtol: 1e-10,
                atol: 1e-12,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(*sol.t.last().unwrap(), 0.0);
        assert!(sol.y.last().unwrap()[0].abs() < 1e-9);
        assert!((sol.eval(1.0)[0] - 1.0f64.sin()).abs() < 1e-8);
    }

    #[test]
    fn third_order_error_scaling() {
        // Global error ~ tol: tightening rtol by 1000 must reduce the error by >= 100.
        let run = |rtol: f64| {
            let sol = bs23(
                |t, y: &[f64; 2]| [y[1], -y[0] + 0.0 * t],
                0.0,
                [0.0, 1.0],
                10.0,
                AdaptiveOptions {
                    rtol,
                    atol: rtol * 1e-2,
                    ..Default::default()
                },
            )
            .unwrap();
            (sol.y.last().unwrap()[0] - 10.0f64.sin()).abs()
        };
        let (e1, e2) = (run(1e-6), run(1e-9));
        assert!(e2 < e1 / 100.0, "{e1} {e2}");
    }

    #[test]
    fn rejects_bad_tolerances() {
        let bad = AdaptiveOptions {
            rtol: -1.0,
            ..Default::default()
        };
        assert!(matches!(
            bs23(|_, y: &[f64; 1]| *y, 0.0, [1.0], 1.0, bad),
            Err(Error::InvalidParameter { .. })
        ));
    }

    #[test]
    fn max_steps_reports_non_convergence() {
        let opts = AdaptiveOptions {
            max_steps: 3,
            ..Default::default()
        };
        let r = bs23(
            |t, _y: &[f64; 1]| [(50.0 * t).sin()],
            0.0,
            [0.0],
            10.0,
            opts,
        );
        assert!(matches!(r, Err(Error::NotConverged { iterations: 3, .. })));
    }

    #[test]
    fn rk4_is_fourth_order() {
        let err = |steps| {
            let (_, ys) =
                rk4(|_, y: &[f64; 2]| [y[1], -y[0]], 0.0, [0.0, 1.0], 3.0, steps).unwrap();
            (ys.last().unwrap()[0] - 3.0f64.sin()).abs()
        };
        let ratio = err(20) / err(40);
        assert!((ratio - 16.0).abs() < 1.0, "ratio {ratio}");
    }

    #[test]
    fn dp54_meets_tolerance_and_dense_output() {
        for rtol in [1e-6, 1e-9, 1e-12] {
            let opts = AdaptiveOptions {
                rtol,
                atol: rtol * 1e-3,
                ..Default::default()
            };
            let sol = dp54(
                |_, y: &[f64; 2]| [y[1], -y[0]],
                0.0,
                [0.0, 1.0],
                6.0,
                opts,
                2,
                |_| {},
            )
            .unwrap();
            let e = (sol.y.last().unwrap()[0] - 6.0f64.sin()).abs();
            assert!(e < 10.0 * rtol, "rtol {rtol}: {e}");
            let ed = (sol.eval(2.345)[0] - 2.345f64.sin()).abs();
            assert!(ed < 10.0 * rtol, "dense rtol {rtol}: {ed}");
        }
    }

    #[test]
    fn rk4_in_place_matches_rk4_step_bitwise() {
        fn rhs(t: f64, y: &[f64; 3]) -> [f64; 3] {
            [y[1], -y[0] + t.sin(), y[0] * y[1]]
        }
        let mut f = |t: f64, y: &[f64; 3]| rhs(t, y);
        let mut g = |t: f64, y: &[f64; 3], dy: &mut [f64; 3]| *dy = rhs(t, y);
        let mut ws = Rk4Workspace::default();
        let (mut a, mut b) = ([0.3, -0.2, 1.0], [0.3, -0.2, 1.0]);
        for i in 0..10 {
            let t = 0.1 * i as f64;
            a = rk4_step(&mut f, t, &a, 0.1);
            rk4_step_in_place(&mut g, t, &mut b, 0.1, &mut ws);
        }
        assert_eq!(a, b);
    }
}
