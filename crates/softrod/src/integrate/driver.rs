//! The one explicit Runge–Kutta driver: fixed or adaptive steps over any [`Tableau`].

use super::tableau::Tableau;
use super::{AdaptiveOptions, IntegrationStats};
use crate::error::{Error, Result};

/// A first-order system `dy/dt = f(t, y)` with optional hooks for the driver.
pub trait System<const N: usize> {
    /// Writes `f(t, y)` into `dy` (every component).
    fn rhs(&mut self, t: f64, y: &[f64; N], dy: &mut [f64; N]);
    /// Called right after stage `stage` of a step was evaluated (for quadratures of side
    /// quantities riding on the stages: keep the integrand of this stage).
    #[inline]
    fn stage_evaluated(&mut self, _stage: usize) {}
    /// Called when a step is accepted, with the stage weights `h b_i` (add `Σ h b_i g_i` to
    /// the quadratures). With `fsal`, the last stage becomes the next step's first.
    #[inline]
    fn step_accepted(&mut self, _weights: &[f64], _fsal: bool) {}
    /// Projection of an accepted state back onto the constraint manifold (e.g.
    /// re-orthonormalisation of a rotation); identity by default.
    #[inline]
    fn project(&mut self, _y: &mut [f64; N]) {}
}

/// A closure `f(t, y) -> dy/dt` as a [`System`].
pub struct FnSystem<F>(pub F);

impl<const N: usize, F: FnMut(f64, &[f64; N]) -> [f64; N]> System<N> for FnSystem<F> {
    #[inline]
    fn rhs(&mut self, t: f64, y: &[f64; N], dy: &mut [f64; N]) {
        *dy = (self.0)(t, y);
    }
}

/// Stage buffers of one integration (reused across steps, and by [`fixed_in`] across the
/// integrations of a march).
pub struct Stages<const N: usize, const S: usize> {
    k: [[f64; N]; S],
    tmp: [f64; N],
}

impl<const N: usize, const S: usize> Stages<N, S> {
    /// Zeroed buffers, on the heap (`S + 1` states).
    #[must_use]
    pub fn new() -> Box<Self> {
        Box::new(Self {
            k: [[0.0; N]; S],
            tmp: [0.0; N],
        })
    }
}

/// Evaluates stages `1..S` of a step of size `h` from `(t, y)` (stage 0 in `st.k[0]`), leaving
/// the last stage's argument in `st.tmp`. `t_end` is the exact end of the step (for
/// `c_i = 1`).
#[inline]
fn stages<const N: usize, const S: usize, Y: System<N>>(
    tab: &Tableau<S>,
    sys: &mut Y,
    t: f64,
    y: &[f64; N],
    h: f64,
    t_end: f64,
    st: &mut Stages<N, S>,
) {
    for i in 1..S {
        // The nonzero coefficients of row i (one for RK4's stages).
        let mut terms = [(0usize, 0.0f64); S];
        let mut m = 0;
        for j in 0..i {
            if tab.a[i][j] != 0.0 {
                terms[m] = (j, h * tab.a[i][j]);
                m += 1;
            }
        }
        let (done, rest) = st.k.split_at_mut(i);
        match &terms[..m] {
            [(j, w)] => {
                let kj = &done[*j];
                for c in 0..N {
                    st.tmp[c] = y[c] + w * kj[c];
                }
            }
            terms => {
                for c in 0..N {
                    let mut v = y[c];
                    for (j, w) in terms {
                        v += w * done[*j][c];
                    }
                    st.tmp[c] = v;
                }
            }
        }
        let ti = if tab.c[i] == 1.0 {
            t_end
        } else {
            t + tab.c[i] * h
        };
        sys.rhs(ti, &st.tmp, &mut rest[0]);
        sys.stage_evaluated(i);
    }
}

/// `y += h Σ b_i k_i` in place.
#[inline]
fn advance<const N: usize, const S: usize>(
    tab: &Tableau<S>,
    y: &mut [f64; N],
    h: f64,
    st: &Stages<N, S>,
) {
    let w = weights(tab, h);
    for c in 0..N {
        let mut v = 0.0;
        for (wj, kj) in w.iter().zip(st.k.iter()) {
            v += wj * kj[c];
        }
        y[c] += v;
    }
}

/// Stages of a step from `(t, y)` and its result `y + h Σ b_i k_i`.
#[inline]
fn step<const N: usize, const S: usize, Y: System<N>>(
    tab: &Tableau<S>,
    sys: &mut Y,
    t: f64,
    y: &[f64; N],
    h: f64,
    t_end: f64,
    st: &mut Stages<N, S>,
) -> [f64; N] {
    stages(tab, sys, t, y, h, t_end, st);
    if tab.fsal {
        // The last stage was evaluated at y + h Σ a_{S,j} k_j = y + h Σ b_j k_j.
        return st.tmp;
    }
    let mut out = *y;
    advance(tab, &mut out, h, st);
    out
}

fn weights<const S: usize>(tab: &Tableau<S>, h: f64) -> [f64; S] {
    let mut w = [0.0; S];
    for i in 0..S {
        w[i] = h * tab.b[i];
    }
    w
}

/// Integrates `sys` from `(t0, y0)` to `t1` in `steps` equal steps of `tab` (`t1 < t0`
/// integrates backward), projecting after every step and calling `on_step(sys, t, y)` after
/// each (`y` may be modified). Returns the final state.
///
/// # Errors
/// [`Error::NotConverged`] if a state becomes non-finite.
pub fn fixed<const N: usize, const S: usize, Y: System<N>>(
    tab: &Tableau<S>,
    sys: &mut Y,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    steps: usize,
    on_step: impl FnMut(&mut Y, f64, &mut [f64; N]),
) -> Result<[f64; N]> {
    fixed_in(tab, sys, &mut Stages::new(), (t0, y0), t1, steps, on_step)
}

/// [`fixed`] with the stage buffers `st` of the caller (a march of many intervals allocates
/// them once), from `(t0, y0)`.
///
/// # Errors
/// [`Error::NotConverged`] if a state becomes non-finite.
pub fn fixed_in<const N: usize, const S: usize, Y: System<N>>(
    tab: &Tableau<S>,
    sys: &mut Y,
    st: &mut Stages<N, S>,
    (t0, y0): (f64, [f64; N]),
    t1: f64,
    steps: usize,
    mut on_step: impl FnMut(&mut Y, f64, &mut [f64; N]),
) -> Result<[f64; N]> {
    let h = (t1 - t0) / steps.max(1) as f64;
    let mut y = y0;
    for i in 0..steps {
        let t = t0 + h * i as f64;
        let t_end = if i + 1 == steps { t1 } else { t + h };
        sys.rhs(t, &y, &mut st.k[0]);
        sys.stage_evaluated(0);
        y = step(tab, sys, t, &y, h, t_end, st);
        sys.step_accepted(&weights(tab, h), false);
        sys.project(&mut y);
        if !y.iter().all(|v| v.is_finite()) {
            return Err(not_converged(
                tab.name,
                ": non-finite state",
                i + 1,
                f64::INFINITY,
            ));
        }
        on_step(sys, t_end, &mut y);
    }
    Ok(y)
}

fn not_converged(method: &str, detail: &str, iterations: usize, residual: f64) -> Error {
    Error::not_converged(
        format!("{method} integration{detail}"),
        iterations,
        residual,
    )
}

/// Factor of the next step after a scaled error `err` for an error estimate of order `order`
/// (error ~ `h^order`): `0.9 err^(-1/order)`, within `[0.2, 5]` after an accepted step and
/// `[0.1, 0.9]` after a rejected one. The one step-size controller.
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

/// Max norm over the first `controlled` components of the local error estimate
/// `h Σ e_i k_i`, each scaled by `atol + rtol max(|y_j|, |y_new,j|)` (1 = at tolerance).
fn error_norm<const N: usize, const S: usize>(
    tab: &Tableau<S>,
    st: &Stages<N, S>,
    (y, y_new): (&[f64; N], &[f64; N]),
    h: f64,
    controlled: usize,
    opts: &AdaptiveOptions,
) -> f64 {
    let mut err = 0.0f64;
    for j in 0..controlled {
        let mut e = 0.0;
        for (i, k) in st.k.iter().enumerate() {
            if tab.e[i] != 0.0 {
                e += tab.e[i] * k[j];
            }
        }
        let sc = opts.atol + opts.rtol * y[j].abs().max(y_new[j].abs());
        err = err.max((h * e / sc).abs());
    }
    err
}

/// The coefficients of the continuous extension of an accepted step (see
/// [`DenseSolution::dense`]).
fn dense_coefficients<const N: usize, const S: usize>(
    tab: &Tableau<S>,
    st: &Stages<N, S>,
    (y, y_new): (&[f64; N], &[f64; N]),
    h: f64,
    dense: &mut [[f64; N]; 5],
) {
    let k_last = &st.k[S - 1];
    for j in 0..N {
        let dy = y_new[j] - y[j];
        let bspl = h * st.k[0][j] - dy;
        dense[0][j] = y[j];
        dense[1][j] = dy;
        dense[2][j] = bspl;
        dense[3][j] = dy - h * k_last[j] - bspl;
        let mut d = 0.0;
        for (i, k) in st.k.iter().enumerate() {
            if tab.d[i] != 0.0 {
                d += tab.d[i] * k[j];
            }
        }
        dense[4][j] = h * d;
    }
}

/// The accepted steps of an adaptive integration with the tableau's continuous extension.
#[derive(Debug, Clone)]
pub struct DenseSolution<const N: usize> {
    /// Mesh points in the order of integration (decreasing if integrated backward).
    pub t: Vec<f64>,
    /// States at the mesh points (after the projection, if any).
    pub y: Vec<[f64; N]>,
    /// Per step `i` (from `t[i]` to `t[i+1]`), the five coefficient vectors of the continuous
    /// extension `r0 + θ(r1 + (1-θ)(r2 + θ(r3 + (1-θ) r4)))`.
    pub dense: Vec<[[f64; N]; 5]>,
    /// Step statistics.
    pub stats: IntegrationStats,
}

impl<const N: usize> DenseSolution<N> {
    /// Interpolated state at `t` (continuous extension of the step containing `t`); `t`
    /// outside the integrated interval is clamped to it.
    pub fn eval(&self, t: f64) -> [f64; N] {
        let n = self.t.len();
        if n < 2 {
            return self.y[0];
        }
        let pos = if self.t[n - 1] > self.t[0] {
            self.t.partition_point(|&ti| ti <= t)
        } else {
            self.t.partition_point(|&ti| ti >= t)
        };
        let i = pos.clamp(1, n - 1) - 1;
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

/// What an adaptive step hands to its observer: the step's end points and, on request, its
/// continuous extension.
pub struct AcceptedStep<'a, const N: usize> {
    /// Start of the step.
    pub t0: f64,
    /// End of the step.
    pub t1: f64,
    /// Continuous-extension coefficients (see [`DenseSolution::dense`]).
    pub dense: &'a [[f64; N]; 5],
}

/// Integrates `sys` over `[t0, t1]` from `y0` (`t1 < t0` integrates backward) with the embedded
/// pair `tab` and the one step-size controller: the first `controlled` components enter the
/// error estimate (e.g. a state without its sensitivities), each kept below
/// `atol + rtol max(|y_n|, |y_{n+1}|)` (max norm). After every accepted step the state is
/// projected and `on_step(sys, y, step)` is called. Returns the final state and statistics.
///
/// # Errors
/// [`Error::InvalidParameter`] for bad options, non-finite end points, `controlled ∉ 1..=N` or
/// a tableau without error weights; [`Error::NotConverged`] if `max_steps` is exceeded, the
/// step size underflows, or the state becomes non-finite.
pub fn adaptive<const N: usize, const S: usize, Y: System<N>>(
    tab: &Tableau<S>,
    sys: &mut Y,
    [t0, t1]: [f64; 2],
    y0: [f64; N],
    options: &AdaptiveOptions,
    controlled: usize,
    mut on_step: impl FnMut(&mut Y, &mut [f64; N], &AcceptedStep<'_, N>),
) -> Result<([f64; N], IntegrationStats)> {
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
    if tab.error_order == 0 || !tab.fsal {
        return Err(Error::invalid("tableau", tab.name, "an FSAL embedded pair"));
    }
    let mut stats = IntegrationStats::default();
    let span = t1 - t0;
    if span == 0.0 {
        return Ok((y0, stats));
    }
    let mut st = Stages::<N, S>::new();
    sys.rhs(t0, &y0, &mut st.k[0]);
    sys.stage_evaluated(0);
    stats.evaluations += 1;
    let dir = span.signum();
    let tiny = 16.0 * f64::EPSILON * t0.abs().max(t1.abs()).max(f64::MIN_POSITIVE);
    let mut h = initial_step(&y0, &st.k[0], controlled, span, tiny, &opts);
    let order = tab.error_order as f64;
    let (mut t, mut y) = (t0, y0);
    let mut attempts = 0usize;
    let mut last_err = f64::NAN;
    let mut dense = [[0.0; N]; 5];
    while (t1 - t) * dir > tiny {
        attempts += 1;
        if attempts > opts.max_steps {
            return Err(not_converged(tab.name, "", attempts - 1, last_err));
        }
        let hs = {
            let hs = h.min((t1 - t).abs()) * dir;
            if (t1 - (t + hs)) * dir <= tiny {
                t1 - t
            } else {
                hs
            }
        };
        let t_new = if hs == t1 - t { t1 } else { t + hs };
        let y_new = step(tab, sys, t, &y, hs, t_new, &mut st);
        stats.evaluations += S - 1;
        let err = error_norm(tab, &st, (&y, &y_new), hs, controlled, &opts);
        if !err.is_finite() || y_new.iter().any(|v| !v.is_finite()) {
            return Err(not_converged(
                tab.name,
                ": non-finite state",
                attempts,
                f64::INFINITY,
            ));
        }
        last_err = err;
        if err <= 1.0 {
            dense_coefficients(tab, &st, (&y, &y_new), hs, &mut dense);
            sys.step_accepted(&weights(tab, hs), true);
            let t_prev = t;
            t = t_new;
            y = y_new;
            sys.project(&mut y);
            st.k[0] = st.k[S - 1];
            stats.accepted += 1;
            on_step(
                sys,
                &mut y,
                &AcceptedStep {
                    t0: t_prev,
                    t1: t,
                    dense: &dense,
                },
            );
            h = hs.abs() * step_factor(err, order, true);
        } else {
            stats.rejected += 1;
            h = hs.abs() * step_factor(err, order, false);
            if h <= tiny {
                return Err(not_converged(
                    tab.name,
                    ": step size underflow",
                    attempts,
                    err,
                ));
            }
        }
    }
    Ok((y, stats))
}

/// [`adaptive`] recording every accepted step with its continuous extension.
///
/// # Errors
/// As [`adaptive`].
pub fn adaptive_dense<const N: usize, const S: usize, Y: System<N>>(
    tab: &Tableau<S>,
    sys: &mut Y,
    [t0, t1]: [f64; 2],
    y0: [f64; N],
    options: &AdaptiveOptions,
    controlled: usize,
) -> Result<DenseSolution<N>> {
    let mut sol = DenseSolution {
        t: vec![t0],
        y: vec![y0],
        dense: Vec::new(),
        stats: IntegrationStats::default(),
    };
    let (_, stats) = adaptive(tab, sys, [t0, t1], y0, options, controlled, |_, y, step| {
        sol.t.push(step.t1);
        sol.y.push(*y);
        sol.dense.push(*step.dense);
    })?;
    sol.stats = stats;
    Ok(sol)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::super::tableau::{BS3, DP5, RK4};
    use super::*;

    /// y'' = -y, y(0) = 0, y'(0) = 1: y = sin t.
    fn oscillator() -> FnSystem<impl FnMut(f64, &[f64; 2]) -> [f64; 2]> {
        FnSystem(|_t: f64, y: &[f64; 2]| [y[1], -y[0]])
    }

    fn fixed_error<const S: usize>(tab: &Tableau<S>, steps: usize) -> f64 {
        let y = fixed(
            tab,
            &mut oscillator(),
            0.0,
            [0.0, 1.0],
            3.0,
            steps,
            |_, _, _| {},
        )
        .unwrap();
        (y[0] - 3.0f64.sin()).abs()
    }

    /// Order of convergence of the propagated solution, from the global error at fixed steps.
    #[test]
    fn each_tableau_converges_with_its_order() {
        for (name, p, e1, e2) in [
            (
                "rk4",
                RK4.order,
                fixed_error(&RK4, 40),
                fixed_error(&RK4, 80),
            ),
            (
                "bs3",
                BS3.order,
                fixed_error(&BS3, 40),
                fixed_error(&BS3, 80),
            ),
            (
                "dp5",
                DP5.order,
                fixed_error(&DP5, 40),
                fixed_error(&DP5, 80),
            ),
        ] {
            let observed = (e1 / e2).log2();
            assert!(
                (observed - p as f64).abs() < 0.45,
                "{name}: observed order {observed} vs {p}"
            );
        }
    }

    /// Order of each pair's embedded error estimate: the estimate of one step scales as
    /// `h^error_order`.
    #[test]
    fn each_pair_error_estimate_has_its_order() {
        fn estimate<const S: usize>(tab: &Tableau<S>, h: f64) -> f64 {
            let mut sys = FnSystem(|t: f64, y: &[f64; 1]| [y[0] * t.cos()]);
            let mut st = Stages::<1, S>::new();
            sys.rhs(0.3, &[1.0], &mut st.k[0]);
            let _ = step(tab, &mut sys, 0.3, &[1.0], h, 0.3 + h, &mut st);
            let mut e = 0.0;
            for i in 0..S {
                e += tab.e[i] * st.k[i][0];
            }
            (h * e).abs()
        }
        for (name, q, r) in [
            (
                "bs3",
                BS3.error_order,
                estimate(&BS3, 0.02) / estimate(&BS3, 0.01),
            ),
            (
                "dp5",
                DP5.error_order,
                estimate(&DP5, 0.04) / estimate(&DP5, 0.02),
            ),
        ] {
            let observed = r.log2();
            assert!(
                (observed - q as f64).abs() < 0.25,
                "{name}: {observed} vs {q}"
            );
        }
    }

    #[test]
    fn adaptive_pairs_meet_the_tolerance_with_dense_output_forward_and_backward() {
        for rtol in [1e-6, 1e-9] {
            let opts = AdaptiveOptions {
                rtol,
                atol: rtol * 1e-3,
                ..Default::default()
            };
            let dp =
                adaptive_dense(&DP5, &mut oscillator(), [0.0, 6.0], [0.0, 1.0], &opts, 2).unwrap();
            assert!((dp.y.last().unwrap()[0] - 6.0f64.sin()).abs() < 10.0 * rtol);
            assert!((dp.eval(2.345)[0] - 2.345f64.sin()).abs() < 10.0 * rtol);
            // Final-value problem: y' = cos t, y(2) = sin 2, integrated back to 0.
            let mut f = FnSystem(|t: f64, _y: &[f64; 1]| [t.cos()]);
            let bs = adaptive_dense(&BS3, &mut f, [2.0, 0.0], [2.0f64.sin()], &opts, 1).unwrap();
            assert_eq!(*bs.t.last().unwrap(), 0.0);
            assert!(bs.y.last().unwrap()[0].abs() < 100.0 * rtol);
            assert!((bs.eval(1.0)[0] - 1.0f64.sin()).abs() < 100.0 * rtol);
        }
    }

    #[test]
    fn bad_options_and_max_steps_are_reported() {
        let bad = AdaptiveOptions {
            rtol: -1.0,
            ..Default::default()
        };
        let mut f = FnSystem(|_t: f64, y: &[f64; 1]| *y);
        assert!(matches!(
            adaptive_dense(&BS3, &mut f, [0.0, 1.0], [1.0], &bad, 1),
            Err(Error::InvalidParameter { .. })
        ));
        let few = AdaptiveOptions {
            max_steps: 3,
            ..Default::default()
        };
        let mut g = FnSystem(|t: f64, _y: &[f64; 1]| [(50.0 * t).sin()]);
        let r = adaptive_dense(&BS3, &mut g, [0.0, 10.0], [0.0], &few, 1);
        assert!(matches!(r, Err(Error::NotConverged { iterations: 3, .. })));
        assert!(matches!(
            adaptive_dense(
                &RK4,
                &mut f,
                [0.0, 1.0],
                [1.0],
                &AdaptiveOptions::default(),
                1
            ),
            Err(Error::InvalidParameter { .. })
        ));
    }
}
