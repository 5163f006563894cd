//! The small programs in the dual (three multipliers): the minimum-norm point in the box and
//! the Levenberg–Marquardt step.

use nalgebra::{Matrix3 as M3, Vector3 as V3};

/// The box, weights and centre of the small programs.
#[derive(Default)]
pub(super) struct Box_ {
    pub(super) lo: Vec<f64>,
    pub(super) hi: Vec<f64>,
    pub(super) w: Vec<f64>,
    pub(super) c: Vec<f64>,
}

impl Box_ {
    pub(super) fn norm(&self, d: &[f64]) -> f64 {
        d.iter()
            .zip(&self.w)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt()
    }
    pub(super) fn clamp(&self, i: usize, v: f64) -> f64 {
        v.max(self.lo[i]).min(self.hi[i])
    }
    pub(super) fn inside(&self, i: usize, v: f64) -> bool {
        v > self.lo[i] && v < self.hi[i]
    }
}

/// The parameters of a program of [`dual`]: the centre `c` of the norm, its factor `μ`, the
/// penalty `ρ` of the constraint residual, the tolerance on the dual gradient (m).
#[derive(Clone, Copy)]
pub(super) struct DualProgram<'c> {
    pub(super) centre: &'c [f64],
    pub(super) mu: f64,
    pub(super) rho: f64,
    pub(super) tol: f64,
}

impl<'c> DualProgram<'c> {
    /// The minimum-norm program (`μ = 1`, `ρ = 0`) centred on `centre`, to `tol` (m).
    pub(super) fn min_norm(centre: &'c [f64], tol: f64) -> Self {
        Self {
            centre,
            mu: 1.0,
            rho: 0.0,
            tol,
        }
    }
}

/// The right-hand side `b = e + J a` (m) of the linearised target `J y = b` of the programs,
/// for the pose error `e` (m) at the actuation `a`: `jac` the position Jacobian columns (m
/// per unit actuation), the first `a.len()` of them used.
#[inline]
pub(super) fn linearised_target(jac: &[V3<f64>], e: &V3<f64>, a: &[f64]) -> V3<f64> {
    let mut b = *e;
    for i in 0..a.len() {
        b += jac[i] * a[i];
    }
    b
}

/// The scratch of [`dual`].
#[derive(Default)]
pub(super) struct DualWork {
    pub(super) trial: Vec<f64>,
    pub(super) free: Vec<bool>,
    pub(super) trial_free: Vec<bool>,
}

/// `min ½ Σ μ w_i (y_i - c_i)² + ½ ρ |J y - b|²/ρ²`-type programs in the dual: the maximiser
/// `λ` of `ψ(λ) = ½ μ |y - c|²_W - λᵀ (J y - b) - ½ ρ |λ|²` with `y(λ) = clamp(c + Jᵀλ / (μ w))`
/// (Newton on the gradient `b - J y - ρ λ`, backtracking; from `start` unless `ψ` is higher
/// at zero). A step is taken where `ψ` rises, or on an unchanged free set where the
/// gradient falls (the dual is a concave quadratic there and the step Newton's; `ψ` can be
/// lost in round-off). `ρ = 0`: the minimum-norm point of the box meeting `J y = b` to `tol`
/// (`None` if infeasible); `ρ = 1`: the bounded Levenberg–Marquardt point
/// `min |J y - b|² + μ |y - c|²_W`. `y` is written; returns `λ`.
pub(super) fn dual(
    jac: &[V3<f64>],
    b: &V3<f64>,
    bx: &Box_,
    program: &DualProgram<'_>,
    start: V3<f64>,
    y: &mut [f64],
    ws: &mut DualWork,
) -> Option<V3<f64>> {
    let DualProgram {
        centre,
        mu,
        rho,
        tol,
    } = *program;
    let n = jac.len();
    // y(λ) and its free set into `y`, `free`; returns ψ(λ) and the gradient.
    let y_of = |l: &V3<f64>, y: &mut [f64], free: &mut [bool]| -> (f64, V3<f64>) {
        let mut psi = 0.0;
        let mut r = -b;
        for i in 0..n {
            let v = centre[i] + jac[i].dot(l) / (mu * bx.w[i]);
            free[i] = v >= bx.lo[i] && v <= bx.hi[i];
            y[i] = bx.clamp(i, v);
            psi += 0.5 * mu * bx.w[i] * (y[i] - centre[i]).powi(2);
            r += jac[i] * y[i];
        }
        (psi - l.dot(&r) - 0.5 * rho * l.norm_squared(), -r - l * rho)
    };
    ws.trial.clear();
    ws.trial.resize(n, 0.0);
    ws.free.clear();
    ws.free.resize(n, false);
    ws.trial_free.clear();
    ws.trial_free.resize(n, false);
    // The start, unless the dual is higher at zero (a start from another program can be far
    // off: the multipliers at a straight rod are huge).
    let mut lambda = V3::zeros();
    let (mut psi, mut g) = y_of(&lambda, y, &mut ws.free);
    if start != lambda && start.iter().all(|v| v.is_finite()) {
        let (ps, gs) = y_of(&start, &mut ws.trial, &mut ws.trial_free);
        if ps > psi {
            (lambda, psi, g) = (start, ps, gs);
            y.copy_from_slice(&ws.trial);
            ws.free.copy_from_slice(&ws.trial_free);
        }
    }
    // Whether the last step changed ψ by round-off alone (no rise, no fall of the gradient).
    let mut stalled = false;
    let mut last_g = f64::INFINITY;
    // Whether the last step kept the free set (the dual a quadratic along it).
    let mut kept = false;
    for _ in 0..100 {
        let gn = g.amax();
        // A step on an unchanged free set (the full one is exact for it) that leaves the
        // gradient where it was: it is at round-off.
        if gn <= tol || (kept && gn > 0.5 * last_g && gn <= 1e3 * tol) {
            return Some(lambda);
        }
        if stalled && gn > 0.5 * last_g {
            // At the floor of the gradient: a Levenberg–Marquardt point is found to it; the
            // minimum-norm program is given up, as the generic one is after its iterations.
            return (rho > 0.0 || gn <= 1e3 * tol).then_some(lambda);
        }
        let mut h = M3::identity() * rho;
        for i in (0..n).filter(|&i| ws.free[i]) {
            h += jac[i] * jac[i].transpose() / (mu * bx.w[i]);
        }
        let tr = h.trace();
        if !(tr > 0.0 && tr.is_finite()) {
            return None;
        }
        for k in 0..3 {
            h[(k, k)] += 1e-14 * tr;
        }
        let d = h.cholesky()?.solve(&g);
        let slope = g.dot(&d);
        let mut alpha = 1.0;
        let mut accepted = false;
        last_g = gn;
        for _ in 0..60 {
            let lt = lambda + d * alpha;
            let (pt, gt) = y_of(&lt, &mut ws.trial, &mut ws.trial_free);
            let rises = pt >= psi + 1e-4 * alpha * slope;
            let falls = ws.trial_free == ws.free && gt.amax() < gn;
            if rises || falls || (pt - psi).abs() <= 1e-15 * psi.abs() {
                stalled = !(rises || falls);
                kept = ws.trial_free == ws.free;
                (lambda, psi, g) = (lt, pt, gt);
                y.copy_from_slice(&ws.trial);
                ws.free.copy_from_slice(&ws.trial_free);
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted || lambda.amax() > 1e30 * (1.0 + b.amax()) {
            return None;
        }
    }
    None
}

/// The spectral norm of `J W^{-1/2}`.
pub(super) fn scaled_norm_of(jac: &[V3<f64>], w: &[f64]) -> f64 {
    let mut g = M3::zeros();
    for (j, wi) in jac.iter().zip(w) {
        g += j * j.transpose() / *wi;
    }
    g.symmetric_eigenvalues()
        .iter()
        .fold(0.0f64, |m, v| m.max(*v))
        .sqrt()
}

/// The scratch of [`lm_step`].
#[derive(Default)]
pub(super) struct LmWork {
    pub(super) y: Vec<f64>,
    pub(super) dual: DualWork,
}

/// `μ` at which the step of the free variables of `y` (the bounded Levenberg–Marquardt
/// point at the last `μ`, its fixed variables held) has the scaled length `aim` with the
/// fixed ones: Newton's method on the secular equation `1/|d(μ)| = 1/aim` with
/// `|d_F(μ)|² = Σ σ_k (u_kᵀ r)² / (σ_k + μ)²` over the eigenpairs of `J_F W_F⁻¹ J_Fᵀ` (Moré).
/// `Some(0)` if no `μ > 0` reaches it; `None` if the fixed variables alone exceed it.
pub(super) fn secular_mu(
    jac: &[V3<f64>],
    (b, a): (&V3<f64>, &[f64]),
    bx: &Box_,
    y: &[f64],
    (mu, aim): (f64, f64),
) -> Option<f64> {
    let (mut fixed, mut r, mut g) = (0.0, *b, M3::zeros());
    for i in 0..a.len() {
        if bx.inside(i, y[i]) {
            r -= jac[i] * a[i];
            g += jac[i] * jac[i].transpose() / bx.w[i];
        } else {
            r -= jac[i] * y[i];
            fixed += bx.w[i] * (y[i] - a[i]).powi(2);
        }
    }
    let t2 = aim * aim - fixed;
    if t2.is_nan() || t2 <= 0.0 {
        return None;
    }
    let eig = g.symmetric_eigen();
    let rho2 = eig.eigenvectors.tr_mul(&r).map(|v| v * v);
    let f = |m: f64| -> (f64, f64) {
        (0..3).fold((0.0, 0.0), |(f, df), k| {
            let (s, q) = (eig.eigenvalues[k].max(0.0), rho2[k]);
            (
                f + s * q / (s + m).powi(2),
                df - 2.0 * s * q / (s + m).powi(3),
            )
        })
    };
    if f(0.0).0 <= t2 {
        return Some(0.0);
    }
    let t = t2.sqrt();
    let mut m = mu;
    for _ in 0..30 {
        let (fm, dfm) = f(m);
        // φ(μ) = 1/√f - 1/t, φ' = -f'/(2 f^{3/2}).
        let phi = 1.0 / fm.sqrt() - 1.0 / t;
        let dphi = -0.5 * dfm / (fm * fm.sqrt());
        let next = m - phi / dphi;
        let next = if next > 0.0 { next } else { 0.1 * m };
        if !next.is_finite() {
            return None;
        }
        if (next - m).abs() <= 1e-3 * m {
            return Some(next);
        }
        m = next;
    }
    Some(m)
}

/// The bounded Levenberg–Marquardt step `min |J d - e|² + μ |d|²_W`, `lo <= a + d <= hi`,
/// into `step`: that of `levenberg_marquardt_step` of the generic iteration, the longest
/// inside `radius` on the grid `μ_k = μ_0 4^k` (`μ_k >= 1e-9 σ²`), found by bisecting the
/// grid between the indices known to fit and known not to, each guess from
/// [`secular_mu`] at the last bounded step (the scan of the generic iteration takes a dual
/// solve per grid point from `μ_0`).
pub(super) fn lm_step(
    jac: &[V3<f64>],
    (e, a): (&V3<f64>, &[f64]),
    bx: &Box_,
    radius: f64,
    step: &mut Vec<f64>,
    ws: &mut LmWork,
) {
    let n = a.len();
    let b = linearised_target(jac, e, a);
    let sigma = scaled_norm_of(jac, &bx.w).max(1e-300);
    let mu0 = (sigma * e.norm() / radius).max(1e-6 * sigma * sigma);
    let grid = |k: i32| mu0 * 4f64.powi(k);
    // The lowest grid index tried.
    let mut k_min = 0;
    while grid(k_min - 1) >= 1e-9 * sigma * sigma {
        k_min -= 1;
    }
    step.clear();
    step.resize(n, 0.0);
    ws.y.clear();
    ws.y.resize(n, 0.0);
    // The smallest index known to fit, the largest known not to.
    let (mut fits, mut too_long): (Option<i32>, Option<i32>) = (None, None);
    let mut lambda = V3::zeros();
    let tol = 1e-15 * (e.amax() + b.amax());
    let mut k = 0;
    for _ in 0..60 {
        let mu = grid(k);
        let program = DualProgram {
            centre: a,
            mu,
            rho: 1.0,
            tol,
        };
        // The multipliers of the last μ start the next one's dual iteration.
        let Some(l) = dual(jac, &b, bx, &program, lambda, &mut ws.y, &mut ws.dual) else {
            return;
        };
        lambda = l;
        let norm = (0..n)
            .map(|i| (ws.y[i] - a[i]).powi(2) * bx.w[i])
            .sum::<f64>()
            .sqrt();
        if norm <= radius * 1.000_001 {
            for i in 0..n {
                step[i] = ws.y[i] - a[i];
            }
            fits = Some(k);
        } else {
            too_long = Some(k);
        }
        let (lo, hi) = match (too_long, fits) {
            (_, Some(f)) if f == k_min => return,
            (Some(t), Some(f)) if t + 1 >= f => return,
            (t, f) => (t.unwrap_or(k_min - 1), f.unwrap_or(i32::MAX)),
        };
        // The next index: the grid point at or above the μ the secular equation asks for,
        // inside the bracket (lo, hi); its middle if the guess falls outside.
        let guess = secular_mu(jac, (&b, a), bx, &ws.y, (mu, radius)).map(|m| {
            if m > 0.0 {
                ((m / mu0).ln() / 4f64.ln()).ceil().clamp(-1e6, 1e6) as i32
            } else {
                k_min
            }
        });
        k = match guess {
            Some(g) if g > lo && g < hi => g,
            _ if hi == i32::MAX => lo + 1,
            _ => lo + (hi - lo) / 2,
        };
        if k <= lo || k >= hi {
            k = lo + 1;
        }
    }
}
