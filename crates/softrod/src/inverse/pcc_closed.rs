//! The PCC inverse statics of an unloaded, tendon-driven robot and a tip position in closed
//! form.
//!
//! Without a tip wrench the equilibrium is closed form and *affine* in the actuation in the
//! coordinates `θ = (θ_x, θ_y, ℓ)` of every segment (`pcc/statics.rs`): `θ = θ0 + M a`. The
//! tip position is the chain kinematics of `θ`, whose first and second derivatives are closed
//! form (`seg_kin`), so the actuation Jacobian is `J = J_θ M` and the Hessian of the
//! Lagrangian `½|a - c|²_W - λᵀ p(a)` is `W - Mᵀ (Σ λ_k ∇²_θ p_k) M`, exact.
//!
//! The iteration is that of `solve_inverse` (the same objective, minimum-norm and
//! least-squares programs, trust region far from the target, merit function near it, and
//! stopping test), with what the exact Hessian allows:
//!
//! * The curved step (the Hessian kept whole, cross terms included, unless `Zᵀ H Z` must be
//!   raised to be positive definite on the null space `Z`: the step is Newton's on the KKT
//!   conditions) is taken whenever the minimum-norm step fits the trust region, far from the
//!   target too: the far phase converges as Newton's does, not linearly.
//! * The curved step keeps the bounds by a primal active set from the minimum-norm point (as
//!   `qp::active_set_qp` of the generic iteration), rather than falling back to the
//!   minimum-norm step when it leaves the box.
//! * A full near step that the merit function rejects because the pose error it leaves is of
//!   second order (the Maratos effect) is corrected by the minimum-norm step back to the
//!   target before it is shortened.
//! * The dual iterations of the small programs start from the last multipliers.
//!
//! Everything is dense algebra on vectors reused from one iteration to the next: the
//! minimum-norm and Levenberg–Marquardt programs in the dual (three multipliers), the curved
//! step by the KKT systems of its working sets, the null space by a pivoted Gram–Schmidt on
//! its projector.

use std::cell::Cell;

use nalgebra::{DMatrix, Matrix3 as M3, Vector3 as V3};

use super::{
    objective_change, trust_radius, Evaluation, InverseOptions, InverseSolution, InverseWarmStart,
    FIRST_RADIUS, LEAST_SQUARES_REGULARISATION, LOCAL_STEP, NEAR_TARGET,
};
use crate::math::linalg::DenseLu;
use crate::pcc::statics::{seg_kin, PccRobot, SegKin};

/// Most changes of the working set per variable in [`curved_step`].
const CURVED_ACTIVE_SET_CHANGES: usize = 10;
/// Pose error (in units of the rod length) below which the steps are curved (ten times
/// [`NEAR_TARGET`]): from farther, the curved step can head for another, larger local minimum of
/// the norm on the target (1 in 400 random targets of the two-segment robot at 1e-2).
const CURVED_FROM: f64 = 1e-3;
/// Floor of the eigenvalues of `Zᵀ H Z` (scaled variables) in [`convexify`].
const CURVATURE_FLOOR: f64 = 1e-3;

/// The affine map `θ = θ0 + M a` of an unloaded robot.
#[derive(Default)]
struct Affine {
    /// Actuators.
    n: usize,
    /// Rest lengths (`θ0 = (0, 0, ℓ0)`).
    rest: Vec<f64>,
    /// `∂θ_s/∂a_k` at `s n + k`.
    cols: Vec<[f64; 3]>,
}

impl Affine {
    /// The map of `robot` into `self` (its vectors reused).
    fn fill(&mut self, robot: &PccRobot) {
        let segs = robot.segments();
        let (nt, nc) = (robot.n_tendons(), robot.n_chambers());
        let n = nt + nc;
        self.n = n;
        self.rest.clear();
        self.rest.extend(segs.iter().map(|s| s.rest_length()));
        let cols = &mut self.cols;
        cols.clear();
        cols.resize(segs.len() * n, [0.0; 3]);
        // The generalized actuator force g on (θ_x, θ_y, ℓ) per unit actuation, to θ.
        let mut put = |s: usize, k: usize, g: [f64; 3]| {
            let body = &segs[s];
            let th = body.rest_length() / body.bending_stiffness();
            let dl = body
                .axial_stiffness()
                .map_or(0.0, |ea| body.rest_length() / ea);
            let c = &mut cols[s * n + k];
            c[0] += th * g[0];
            c[1] += th * g[1];
            c[2] += dl * g[2];
        };
        for (k, t) in robot.tendons().iter().enumerate() {
            let (sb, cb) = t.angle().sin_cos();
            let d = t.distance();
            for s in 0..=t.last_segment() {
                put(s, k, [-d * sb, d * cb, -1.0]);
            }
        }
        let mut k = nt;
        for (seg, ch) in robot.chambers() {
            for i in 0..ch.len() {
                let (a, r) = (ch.areas()[i], ch.distances()[i]);
                let (sb, cb) = ch.angles()[i].sin_cos();
                put(*seg, k, [a * r * sb, -a * r * cb, a]);
                k += 1;
            }
        }
    }
}

/// The chain at one actuation: tip position and rotation, per segment its kinematics, base
/// rotation, tip and the world columns `V` (tip position) and `Ω` (rotation) per `θ`
/// coordinate, and the position Jacobian in the actuation (`n` columns).
#[derive(Default)]
struct Chain {
    p: V3<f64>,
    r: M3<f64>,
    kin: Vec<SegKin>,
    base: Vec<M3<f64>>,
    tip: Vec<V3<f64>>,
    vc: Vec<[V3<f64>; 3]>,
    oc: Vec<[V3<f64>; 3]>,
    jac: Vec<V3<f64>>,
}

impl Chain {
    /// Evaluates the chain at `a`; `false` if a length is not positive or a value not finite.
    fn eval(&mut self, aff: &Affine, a: &[f64]) -> bool {
        let n = aff.n;
        self.kin.clear();
        self.base.clear();
        self.tip.clear();
        let (mut gr, mut gp) = (M3::identity(), V3::zeros());
        for (s, &l0) in aff.rest.iter().enumerate() {
            let mut th = [0.0, 0.0, l0];
            for (k, &ak) in a.iter().enumerate() {
                let c = &aff.cols[s * n + k];
                th[0] += c[0] * ak;
                th[1] += c[1] * ak;
                th[2] += c[2] * ak;
            }
            if !(th[2] > 0.0 && th.iter().all(|v| v.is_finite())) {
                return false;
            }
            let kin = seg_kin(th[0], th[1], th[2]);
            self.base.push(gr);
            gp += gr * kin.p;
            gr *= kin.r;
            self.kin.push(kin);
            self.tip.push(gp);
        }
        (self.p, self.r) = (gp, gr);
        self.vc.clear();
        self.oc.clear();
        for s in 0..aff.rest.len() {
            let (b, k) = (&self.base[s], &self.kin[s]);
            let dd = gp - self.tip[s];
            let oc = [b * k.w[0], b * k.w[1], V3::zeros()];
            let vc = [0, 1, 2].map(|c| b * k.dp[c] + oc[c].cross(&dd));
            self.vc.push(vc);
            self.oc.push(oc);
        }
        self.jac.clear();
        for k in 0..n {
            let mut col = V3::zeros();
            for s in 0..aff.rest.len() {
                let m = &aff.cols[s * n + k];
                for c in 0..3 {
                    col += self.vc[s][c] * m[c];
                }
            }
            self.jac.push(col);
        }
        self.p.iter().all(|v| v.is_finite())
    }

    /// `Σ λ_k ∇²_θ p_k` (q × q, row-major, `q = 3` per segment, symmetric) into `h`.
    fn theta_hessian(&self, lambda: &V3<f64>, h: &mut Vec<f64>) {
        let ns = self.kin.len();
        let q = 3 * ns;
        h.clear();
        h.resize(q * q, 0.0);
        for s in 0..ns {
            let (b, k) = (&self.base[s], &self.kin[s]);
            let dd = self.p - self.tip[s];
            // λ·(B x) = (Bᵀλ)·x, λ·(a × (b × d)) = (λ × a)·(b × d), λ·((B x) × d) =
            // (Bᵀ(d × λ))·x: the multipliers taken into each term once.
            let (bl, bd) = (b.tr_mul(lambda), b.tr_mul(&dd.cross(lambda)));
            let lo = self.oc[s].map(|o| lambda.cross(&o));
            let od = self.oc[s].map(|o| o.cross(&dd));
            for c in 0..3 {
                for m in 0..3 {
                    let mut v = bl.dot(&k.ddp[c][m]) + lo[c].dot(&od[m]);
                    if c < 2 && m < 2 {
                        v += bd.dot(&k.dw[c][m]);
                    }
                    h[(3 * s + c) * q + 3 * s + m] = v;
                }
            }
            // Distal segments: λ·(Ω_sc × V_tm), symmetric.
            for t in s + 1..ns {
                for c in 0..2 {
                    let lo = lambda.cross(&self.oc[s][c]);
                    for m in 0..3 {
                        let v = self.vc[t][m].dot(&lo);
                        h[(3 * s + c) * q + 3 * t + m] = v;
                        h[(3 * t + m) * q + 3 * s + c] = v;
                    }
                }
            }
        }
        // Symmetric to round-off.
        for i in 0..q {
            for j in 0..i {
                let v = 0.5 * (h[i * q + j] + h[j * q + i]);
                h[i * q + j] = v;
                h[j * q + i] = v;
            }
        }
    }
}

/// The Hessian of the Lagrangian `W - Mᵀ H_θ M` (n × n, row-major) into `out`, `H_θ` from
/// [`Chain::theta_hessian`]; `hm` is scratch.
fn lagrangian_hessian(aff: &Affine, h: &[f64], w: &[f64], hm: &mut Vec<f64>, out: &mut Vec<f64>) {
    let n = aff.n;
    let q = 3 * aff.rest.len();
    // H M first (q × n); row `3 s + c` of M is `cols[s n + k][c]`.
    hm.clear();
    hm.resize(q * n, 0.0);
    for i in 0..q {
        let row = &mut hm[i * n..(i + 1) * n];
        for (t, cols) in aff.cols.chunks_exact(n).enumerate() {
            for m in 0..3 {
                let hij = h[i * q + 3 * t + m];
                if hij != 0.0 {
                    for (r, c) in row.iter_mut().zip(cols) {
                        *r += hij * c[m];
                    }
                }
            }
        }
    }
    out.clear();
    out.resize(n * n, 0.0);
    for (s, cols) in aff.cols.chunks_exact(n).enumerate() {
        for (k, c) in cols.iter().enumerate() {
            let row = &mut out[k * n..(k + 1) * n];
            for m in 0..3 {
                if c[m] != 0.0 {
                    let hrow = &hm[(3 * s + m) * n..(3 * s + m + 1) * n];
                    for (o, v) in row.iter_mut().zip(hrow) {
                        *o -= c[m] * v;
                    }
                }
            }
        }
    }
    for k in 0..n {
        out[k * n + k] += w[k];
    }
}

/// `(W - Mᵀ H_θ M) v` into `out` (`u`, `hu`: scratch of length `q`).
fn lagrangian_times(
    aff: &Affine,
    (h, w): (&[f64], &[f64]),
    v: &[f64],
    (u, hu): (&mut Vec<f64>, &mut Vec<f64>),
    out: &mut [f64],
) {
    let n = aff.n;
    let q = 3 * aff.rest.len();
    u.clear();
    u.resize(q, 0.0);
    for (s, cols) in aff.cols.chunks_exact(n).enumerate() {
        for (c, vk) in cols.iter().zip(v) {
            for m in 0..3 {
                u[3 * s + m] += c[m] * vk;
            }
        }
    }
    hu.clear();
    hu.extend((0..q).map(|i| (0..q).map(|j| h[i * q + j] * u[j]).sum::<f64>()));
    for k in 0..n {
        out[k] = w[k] * v[k];
    }
    for (s, cols) in aff.cols.chunks_exact(n).enumerate() {
        for (o, c) in out.iter_mut().zip(cols) {
            *o -= c[0] * hu[3 * s] + c[1] * hu[3 * s + 1] + c[2] * hu[3 * s + 2];
        }
    }
}

/// The box, weights and centre of the small programs.
#[derive(Default)]
struct Box_ {
    lo: Vec<f64>,
    hi: Vec<f64>,
    w: Vec<f64>,
    c: Vec<f64>,
}

impl Box_ {
    fn norm(&self, d: &[f64]) -> f64 {
        d.iter()
            .zip(&self.w)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt()
    }
    fn clamp(&self, i: usize, v: f64) -> f64 {
        v.max(self.lo[i]).min(self.hi[i])
    }
    fn inside(&self, i: usize, v: f64) -> bool {
        v > self.lo[i] && v < self.hi[i]
    }
}

/// The parameters of a program of [`dual`]: the centre `c` of the norm, its factor `μ`, the
/// penalty `ρ` of the constraint residual, the tolerance on the dual gradient (m).
#[derive(Clone, Copy)]
struct DualProgram<'c> {
    centre: &'c [f64],
    mu: f64,
    rho: f64,
    tol: f64,
}

/// The scratch of [`dual`].
#[derive(Default)]
struct DualWork {
    trial: Vec<f64>,
    free: Vec<bool>,
    trial_free: Vec<bool>,
}

/// `min ½ Σ μ w_i (y_i - c_i)² + ½ ρ |J y - b|²/ρ²`-type programs in the dual: the maximiser
/// `λ` of `ψ(λ) = ½ μ |y - c|²_W - λᵀ (J y - b) - ½ ρ |λ|²` with `y(λ) = clamp(c + Jᵀλ / (μ w))`
/// (Newton on the gradient `b - J y - ρ λ`, backtracking; from `start` unless `ψ` is higher
/// at zero). A step is taken where `ψ` rises, or on an unchanged free set where the
/// gradient falls (the dual is a concave quadratic there and the step Newton's; `ψ` can be
/// lost in round-off). `ρ = 0`: the minimum-norm point of the box meeting `J y = b` to `tol`
/// (`None` if infeasible); `ρ = 1`: the bounded Levenberg–Marquardt point
/// `min |J y - b|² + μ |y - c|²_W`. `y` is written; returns `λ`.
fn dual(
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
fn scaled_norm_of(jac: &[V3<f64>], w: &[f64]) -> f64 {
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
struct LmWork {
    y: Vec<f64>,
    dual: DualWork,
}

/// `μ` at which the step of the free variables of `y` (the bounded Levenberg–Marquardt
/// point at the last `μ`, its fixed variables held) has the scaled length `aim` with the
/// fixed ones: Newton's method on the secular equation `1/|d(μ)| = 1/aim` with
/// `|d_F(μ)|² = Σ σ_k (u_kᵀ r)² / (σ_k + μ)²` over the eigenpairs of `J_F W_F⁻¹ J_Fᵀ` (Moré).
/// `Some(0)` if no `μ > 0` reaches it; `None` if the fixed variables alone exceed it.
fn secular_mu(
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
fn lm_step(
    jac: &[V3<f64>],
    (e, a): (&V3<f64>, &[f64]),
    bx: &Box_,
    radius: f64,
    step: &mut Vec<f64>,
    ws: &mut LmWork,
) {
    let n = a.len();
    let mut b = *e;
    for i in 0..n {
        b += jac[i] * a[i];
    }
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

/// The scratch of [`convexify`].
#[derive(Default)]
struct ConvexWork {
    /// The free variables.
    idx: Vec<usize>,
    /// The scaled free columns `J_i / √w_i`, and one range vector.
    cols: Vec<V3<f64>>,
    range: Vec<f64>,
    /// The projector on the null space (k × k), then what is left of it.
    proj: Vec<f64>,
    /// The null-space basis (n × d, column-major, `Zᵀ W Z = I`).
    z: Vec<f64>,
    /// `H Z` (n × d, column-major).
    hz: Vec<f64>,
    /// `Zᵀ H Z` (d × d), then its Cholesky factor.
    zhz: Vec<f64>,
    chol: Vec<f64>,
}

/// `ws.proj -= Σ v vᵀ` over the orthonormal range vectors `v = A_Fᵀ u / √σ` of the
/// eigenpairs `(σ, u)` of `G = A_F A_Fᵀ` above `1e-10` of the largest; returns their number.
fn range_projector(g: &M3<f64>, ws: &mut ConvexWork) -> usize {
    let k = ws.cols.len();
    let eig = g.symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0f64, |x, v| x.max(v.abs()));
    let mut rank = 0;
    for (r, &s) in eig.eigenvalues.iter().enumerate() {
        if s.abs() <= 1e-10 * top {
            continue;
        }
        rank += 1;
        let u = eig.eigenvectors.column(r) / s.sqrt();
        ws.range.clear();
        ws.range.extend(ws.cols.iter().map(|c| c.dot(&u)));
        for i in 0..k {
            for j in 0..k {
                ws.proj[i * k + j] -= ws.range[i] * ws.range[j];
            }
        }
    }
    rank
}

/// The basis `Z` (into `ws.z`, `Zᵀ W Z = I`, zero on the fixed variables) of the null space
/// of the columns `ws.idx` of `J` (scaled variables `W^{1/2} a`; the range is the span of the
/// eigenvectors of `J_F W_F⁻¹ J_Fᵀ` above `1e-10` of the largest); returns its dimension.
fn null_space(jac: &[V3<f64>], bx: &Box_, ws: &mut ConvexWork) -> usize {
    let n = bx.w.len();
    let k = ws.idx.len();
    ws.cols.clear();
    ws.cols
        .extend(ws.idx.iter().map(|&i| jac[i] / bx.w[i].sqrt()));
    let mut g = M3::zeros();
    for v in &ws.cols {
        g += v * v.transpose();
    }
    ws.proj.clear();
    ws.proj.resize(k * k, 0.0);
    for i in 0..k {
        ws.proj[i * k + i] = 1.0;
    }
    // Well conditioned (λ_min/λ_max >= det/tr³ > 1e-8, far from the rank test): P = I - Aᵀ G⁻¹ A
    // without the eigenvectors.
    let (det, tr) = (g.determinant(), g.trace());
    let rank = match g.try_inverse() {
        Some(inv) if det > 1e-8 * tr.powi(3) => {
            for i in 0..k {
                let gi = inv * ws.cols[i];
                for j in 0..k {
                    ws.proj[i * k + j] -= ws.cols[j].dot(&gi);
                }
            }
            3
        }
        _ => range_projector(&g, ws),
    };
    let d = k.saturating_sub(rank);
    ws.z.clear();
    ws.z.resize(n * d, 0.0);
    // Pivoted Gram–Schmidt on the projector: the column of the largest norm, normalised, then
    // taken out of what is left (a projector again).
    for j in 0..d {
        let (mut piv, mut best) = (0, -1.0);
        for i in 0..k {
            if ws.proj[i * k + i] > best {
                (piv, best) = (i, ws.proj[i * k + i]);
            }
        }
        if best.is_nan() || best <= 0.0 {
            return j;
        }
        let s = 1.0 / best.sqrt();
        for i in 0..k {
            ws.z[j * n + ws.idx[i]] = ws.proj[i * k + piv] * s;
        }
        for r in 0..k {
            let qr = ws.z[j * n + ws.idx[r]];
            for c in 0..k {
                ws.proj[r * k + c] -= qr * ws.z[j * n + ws.idx[c]];
            }
        }
    }
    for j in 0..d {
        for &i in &ws.idx {
            ws.z[j * n + i] /= bx.w[i].sqrt();
        }
    }
    d
}

/// Whether the symmetric `d × d` matrix `m - shift I` is positive definite; its Cholesky
/// factor (lower, row-major) into `chol`.
fn cholesky(m: &[f64], d: usize, shift: f64, chol: &mut Vec<f64>) -> bool {
    chol.clear();
    chol.extend_from_slice(&m[..d * d]);
    for i in 0..d {
        chol[i * d + i] -= shift;
    }
    for j in 0..d {
        let mut s = chol[j * d + j];
        for k in 0..j {
            s -= chol[j * d + k] * chol[j * d + k];
        }
        if s.is_nan() || s <= 0.0 {
            return false;
        }
        let s = s.sqrt();
        chol[j * d + j] = s;
        for i in j + 1..d {
            let mut v = chol[i * d + j];
            for k in 0..j {
                v -= chol[i * d + k] * chol[j * d + k];
            }
            chol[i * d + j] = v / s;
        }
    }
    true
}

/// Solves `L Lᵀ x = b` in place with the factor of [`cholesky`]; `false` if not finite.
fn cholesky_solve(l: &[f64], d: usize, b: &mut [f64]) -> bool {
    for i in 0..d {
        let s: f64 = (0..i).map(|k| l[i * d + k] * b[k]).sum();
        b[i] = (b[i] - s) / l[i * d + i];
    }
    for i in (0..d).rev() {
        let s: f64 = (i + 1..d).map(|k| l[k * d + i] * b[k]).sum();
        b[i] = (b[i] - s) / l[i * d + i];
    }
    b[..d].iter().all(|v| v.is_finite())
}

/// The Hessian `h` (n × n, row-major) made positive definite on the null space `Z` of the
/// free columns of `J` (those free in `y_w`, scaled variables `W^{1/2} a`): kept exact when
/// `Zᵀ h Z` has its eigenvalues above [`CURVATURE_FLOOR`] (the cross terms `Zᵀ h Y` make the
/// curved step Newton's), otherwise only `Zᵀ h Z` raised to that floor, so that the curved
/// step is a descent step toward a minimum, never a saddle. Without a null space: `W` (the
/// step is then the constraints' alone, the minimum-norm step), and `false`.
fn convexify(h: &mut [f64], jac: &[V3<f64>], y_w: &[f64], bx: &Box_, ws: &mut ConvexWork) -> bool {
    let n = y_w.len();
    ws.idx.clear();
    ws.idx.extend((0..n).filter(|&i| bx.inside(i, y_w[i])));
    let d = if ws.idx.len() > 3 {
        null_space(jac, bx, ws)
    } else {
        0
    };
    if d == 0 {
        for r in 0..n {
            for c in 0..n {
                h[r * n + c] = if r == c { bx.w[r] } else { 0.0 };
            }
        }
        return false;
    }
    for r in 0..n {
        for c in 0..r {
            let v = 0.5 * (h[r * n + c] + h[c * n + r]);
            h[r * n + c] = v;
            h[c * n + r] = v;
        }
    }
    ws.hz.clear();
    ws.hz.resize(n * d, 0.0);
    for j in 0..d {
        for r in 0..n {
            ws.hz[j * n + r] = (0..n).map(|c| h[r * n + c] * ws.z[j * n + c]).sum();
        }
    }
    ws.zhz.clear();
    ws.zhz.resize(d * d, 0.0);
    for i in 0..d {
        for j in 0..=i {
            let v: f64 = (0..n).map(|r| ws.z[i * n + r] * ws.hz[j * n + r]).sum();
            let u: f64 = (0..n).map(|r| ws.z[j * n + r] * ws.hz[i * n + r]).sum();
            ws.zhz[i * d + j] = 0.5 * (u + v);
            ws.zhz[j * d + i] = 0.5 * (u + v);
        }
    }
    if cholesky(&ws.zhz, d, CURVATURE_FLOOR, &mut ws.chol) {
        // Positive definite on Z already: the exact Hessian, cross terms included (the step
        // is Newton's).
        return true;
    }
    // Only `Zᵀ H Z` raised (`Zᵀ W Z = I`): `h += W Z (floored - Zᵀ H Z) Zᵀ W`.
    let m = DMatrix::from_row_slice(d, d, &ws.zhz);
    let e = m.clone().symmetric_eigen();
    let vals = e.eigenvalues.map(|v| v.max(CURVATURE_FLOOR));
    let delta = &e.eigenvectors * DMatrix::from_diagonal(&vals) * e.eigenvectors.transpose() - m;
    for r in 0..n {
        for c in 0..n {
            let mut v = 0.0;
            for i in 0..d {
                for j in 0..d {
                    v += ws.z[i * n + r] * delta[(i, j)] * ws.z[j * n + c];
                }
            }
            h[r * n + c] += bx.w[r] * v * bx.w[c];
        }
    }
    for r in 0..n {
        for c in 0..r {
            let v = 0.5 * (h[r * n + c] + h[c * n + r]);
            h[r * n + c] = v;
            h[c * n + r] = v;
        }
    }
    true
}

/// What [`reduced_step`] found.
enum Reduced {
    /// No null space of the free columns: the minimum-norm step is the curved one.
    NoNullSpace,
    /// The curved step, in [`ReducedWork::d`].
    Step,
    /// The step leaves the box, or a bound's multiplier has the wrong sign: the working set
    /// changes.
    Bounds,
}

/// The scratch of [`reduced_step`].
#[derive(Default)]
struct ReducedWork {
    /// The step.
    d: Vec<f64>,
    /// `H' d_r`, then the gradient `H' d + W (a - c)`.
    hd: Vec<f64>,
    /// `H Z` (n × dim Z, column-major).
    hz: Vec<f64>,
    /// `Zᵀ H' Z`, its raise `Δ` and Cholesky factor (dim Z × dim Z).
    m: Vec<f64>,
    delta: Vec<f64>,
    chol: Vec<f64>,
    /// `t`, `Z t`, and the scratch of the raise.
    t: Vec<f64>,
    zt: Vec<f64>,
    u: Vec<f64>,
    prod: (Vec<f64>, Vec<f64>),
}

/// The curved step on the face of the minimum-norm point `y_w` by the null-space method:
/// `d = d_r + Z t`, `d_r = y_w - a`, `t = -(Zᵀ H' Z)⁻¹ Zᵀ (H' d_r + W (a - c))`, `H'` the Hessian
/// of the Lagrangian `W - Mᵀ H_θ M` (`H_θ` = `theta`) with `Zᵀ H Z` raised to
/// [`CURVATURE_FLOOR`] as [`convexify`] raises it, applied to the `1 + dim Z` vectors it
/// meets rather than formed. It is the first face of [`curved_step`]'s active set, and that
/// step when it stays in the box and the multipliers of the bounds have their signs
/// ([`Reduced::Step`]).
fn reduced_step(
    (aff, theta, jac): (&Affine, &[f64], &[V3<f64>]),
    (a, y_w): (&[f64], &[f64]),
    bx: &Box_,
    cw: &mut ConvexWork,
    ws: &mut ReducedWork,
) -> Reduced {
    let n = a.len();
    cw.idx.clear();
    cw.idx.extend((0..n).filter(|&i| bx.inside(i, y_w[i])));
    let dz = null_space(jac, bx, cw);
    if dz == 0 {
        return Reduced::NoNullSpace;
    }
    let z = |j: usize| &cw.z[j * n..(j + 1) * n];
    let hw = (theta, &bx.w[..]);
    reduced_hessian(aff, hw, (&cw.z, dz), ws);
    // `W Z Δ Zᵀ W v` added to `out` (the raise of `Zᵀ H Z`, `Zᵀ W Z = I`).
    let raise = |v: &[f64], out: &mut [f64], u: &mut Vec<f64>, dl: &[f64]| {
        u.clear();
        u.extend((0..dz).map(|j| (0..n).map(|r| z(j)[r] * bx.w[r] * v[r]).sum::<f64>()));
        for j in 0..dz {
            let c: f64 = (0..dz).map(|k| dl[j * dz + k] * u[k]).sum();
            for r in 0..n {
                out[r] += bx.w[r] * z(j)[r] * c;
            }
        }
    };
    ws.d.clear();
    ws.d.extend((0..n).map(|i| y_w[i] - a[i]));
    ws.hd.resize(n, 0.0);
    lagrangian_times(aff, hw, &ws.d, (&mut ws.prod.0, &mut ws.prod.1), &mut ws.hd);
    raise(&ws.d, &mut ws.hd, &mut ws.u, &ws.delta);
    // t = -M⁻¹ Zᵀ (H' d_r + g).
    ws.t.clear();
    ws.t.extend((0..dz).map(|j| {
        -(0..n)
            .map(|r| z(j)[r] * (ws.hd[r] + bx.w[r] * (a[r] - bx.c[r])))
            .sum::<f64>()
    }));
    if !(cholesky(&ws.m, dz, 0.0, &mut ws.chol) && cholesky_solve(&ws.chol, dz, &mut ws.t)) {
        return Reduced::Bounds;
    }
    for j in 0..dz {
        for r in 0..n {
            ws.d[r] += z(j)[r] * ws.t[j];
        }
    }
    if cw
        .idx
        .iter()
        .any(|&i| !(a[i] + ws.d[i] >= bx.lo[i] && a[i] + ws.d[i] <= bx.hi[i]))
    {
        return Reduced::Bounds;
    }
    // The gradient at the step, H' d + g = H' d_r + H' Z t + g, and the multipliers of the
    // target from the free rows (`J_F λ = grad_F` at the face's minimum).
    for j in 0..dz {
        for r in 0..n {
            ws.hd[r] += ws.hz[j * n + r] * ws.t[j];
        }
    }
    ws.zt.clear();
    ws.zt.resize(n, 0.0);
    for j in 0..dz {
        for r in 0..n {
            ws.zt[r] += z(j)[r] * ws.t[j];
        }
    }
    raise(&ws.zt, &mut ws.hd, &mut ws.u, &ws.delta);
    for i in 0..n {
        ws.hd[i] += bx.w[i] * (a[i] - bx.c[i]);
    }
    if bounds_hold(jac, bx, (&cw.idx, y_w), &ws.hd) {
        Reduced::Step
    } else {
        Reduced::Bounds
    }
}

/// `H Z` (into `ws.hz`) and `Zᵀ H Z` raised to [`CURVATURE_FLOOR`] (into `ws.m`, the raise
/// into `ws.delta`) for the basis `z` (n × dz, column-major).
fn reduced_hessian(
    aff: &Affine,
    hw: (&[f64], &[f64]),
    (z, dz): (&[f64], usize),
    ws: &mut ReducedWork,
) {
    let n = aff.n;
    ws.hz.clear();
    ws.hz.resize(n * dz, 0.0);
    for j in 0..dz {
        let prod = (&mut ws.prod.0, &mut ws.prod.1);
        lagrangian_times(
            aff,
            hw,
            &z[j * n..(j + 1) * n],
            prod,
            &mut ws.hz[j * n..(j + 1) * n],
        );
    }
    let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
    let col = |j: usize| j * n..(j + 1) * n;
    ws.m.clear();
    ws.m.resize(dz * dz, 0.0);
    for i in 0..dz {
        for j in 0..=i {
            let zi_hzj = dot(&z[col(i)], &ws.hz[col(j)]);
            let zj_hzi = dot(&z[col(j)], &ws.hz[col(i)]);
            let v = 0.5 * (zi_hzj + zj_hzi);
            ws.m[i * dz + j] = v;
            ws.m[j * dz + i] = v;
        }
    }
    ws.delta.clear();
    ws.delta.resize(dz * dz, 0.0);
    if !cholesky(&ws.m, dz, CURVATURE_FLOOR, &mut ws.chol) {
        let m = DMatrix::from_row_slice(dz, dz, &ws.m);
        let e = m.clone().symmetric_eigen();
        let vals = e.eigenvalues.map(|v| v.max(CURVATURE_FLOOR));
        let f = &e.eigenvectors * DMatrix::from_diagonal(&vals) * e.eigenvectors.transpose();
        for i in 0..dz {
            for j in 0..dz {
                let fij = 0.5 * (f[(i, j)] + f[(j, i)]);
                ws.delta[i * dz + j] = fij - ws.m[i * dz + j];
                ws.m[i * dz + j] = fij;
            }
        }
    }
}

/// Whether the multipliers of the bounds at the fixed variables of `y_w` (those not in
/// `free`) have their signs for the gradient `grad` of the face's minimum: `μ = grad - Jᵀ λ`,
/// `J_F λ = grad_F`, `>= 0` at a lower bound and `<= 0` at an upper.
fn bounds_hold(jac: &[V3<f64>], bx: &Box_, (free, y_w): (&[usize], &[f64]), grad: &[f64]) -> bool {
    let (mut g, mut r) = (M3::zeros(), V3::zeros());
    for &i in free {
        g += jac[i] * jac[i].transpose();
        r += jac[i] * grad[i];
    }
    let Some(lambda) = g.try_inverse().map(|gi| gi * r) else {
        return false;
    };
    let gmax = grad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let gscale = 1e-12 * (1.0 + gmax);
    (0..y_w.len()).filter(|&i| !bx.inside(i, y_w[i])).all(|i| {
        let mu = grad[i] - jac[i].dot(&lambda);
        let wrong = if y_w[i] <= bx.lo[i] { -mu } else { mu };
        wrong <= gscale
    })
}

/// The scratch of [`curved_step`].
#[derive(Default)]
struct CurvedWork {
    grad: Vec<f64>,
    p: Vec<f64>,
    fixed: Vec<bool>,
    free: Vec<usize>,
    kkt: Vec<f64>,
    rhs: Vec<f64>,
    lu: DenseLu,
}

impl CurvedWork {
    /// `grad = H d + W (a - c)`; returns its largest magnitude.
    fn gradient(&mut self, h: &[f64], a: &[f64], d: &[f64], bx: &Box_) -> f64 {
        let n = a.len();
        let mut gmax = 0.0f64;
        for i in 0..n {
            let hd: f64 = (0..n).map(|j| h[i * n + j] * d[j]).sum();
            self.grad[i] = hd + bx.w[i] * (a[i] - bx.c[i]);
            gmax = gmax.max(self.grad[i].abs());
        }
        gmax
    }

    /// The step `p` (into `self.p`) and multipliers of the equality-constrained problem on
    /// the current working set: `[H_FF J_Fᵀ; J_F 0] [p_F; -λ] = [-grad_F; 0]`; `None` if its
    /// KKT system is singular.
    fn face(&mut self, h: &[f64], jac: &[V3<f64>]) -> Option<V3<f64>> {
        let n = self.fixed.len();
        self.free.clear();
        self.free.extend((0..n).filter(|&i| !self.fixed[i]));
        let k = self.free.len();
        let m = k + 3;
        self.kkt.clear();
        self.kkt.resize(m * m, 0.0);
        self.rhs.clear();
        self.rhs.resize(m, 0.0);
        for (r, &i) in self.free.iter().enumerate() {
            for (c, &j) in self.free.iter().enumerate() {
                self.kkt[r + c * m] = h[i * n + j];
            }
            for e in 0..3 {
                self.kkt[r + (k + e) * m] = jac[i][e];
                self.kkt[k + e + r * m] = jac[i][e];
            }
            self.rhs[r] = -self.grad[i];
        }
        if !self.lu.factor(m, &self.kkt) || !self.lu.solve_in_place(&mut self.rhs) {
            return None;
        }
        self.p.iter_mut().for_each(|v| *v = 0.0);
        for (r, &i) in self.free.iter().enumerate() {
            self.p[i] = self.rhs[r];
        }
        Some(-V3::new(self.rhs[k], self.rhs[k + 1], self.rhs[k + 2]))
    }
}

/// The curved step `d`: `min ½ dᵀ H d + (W (a - c))ᵀ d` s.t. `J d = J (y_w - a)` (the
/// linearised target, met by the minimum-norm point `y_w`), `lo <= a + d <= hi`, by a primal
/// active set on the bounds from `y_w` (as `qp::active_set_qp`: each working set's
/// equality-constrained problem through its KKT system, the blocking bound added, the bound
/// of the most wrong-signed multiplier released). `false` if a KKT system is singular or the
/// working sets do not settle.
fn curved_step(
    (h, jac): (&[f64], &[V3<f64>]),
    a: &[f64],
    y_w: &[f64],
    bx: &Box_,
    d: &mut Vec<f64>,
    ws: &mut CurvedWork,
) -> bool {
    let n = a.len();
    d.clear();
    d.extend((0..n).map(|i| y_w[i] - a[i]));
    ws.fixed.clear();
    ws.fixed.extend((0..n).map(|i| !bx.inside(i, y_w[i])));
    ws.grad.resize(n, 0.0);
    ws.p.resize(n, 0.0);
    for _ in 0..CURVED_ACTIVE_SET_CHANGES * (n + 1) {
        ws.gradient(h, a, d, bx);
        let Some(lambda) = ws.face(h, jac) else {
            return false;
        };
        let scale = 1.0 + (0..n).fold(0.0f64, |m, i| m.max((a[i] + d[i]).abs()));
        let mut at_minimum = ws.p.iter().all(|v| v.abs() <= 1e-14 * scale);
        if !at_minimum {
            let (mut t, mut blocking) = (1.0, None);
            for &i in &ws.free {
                let (y, p) = (a[i] + d[i], ws.p[i]);
                let bound = if p < 0.0 && y + p < bx.lo[i] {
                    bx.lo[i]
                } else if p > 0.0 && y + p > bx.hi[i] {
                    bx.hi[i]
                } else {
                    continue;
                };
                let ti = (bound - y) / p;
                if ti < t {
                    (t, blocking) = (ti, Some((i, bound)));
                }
            }
            let t = t.max(0.0);
            for i in 0..n {
                d[i] += t * ws.p[i];
            }
            match blocking {
                Some((i, v)) => {
                    d[i] = v - a[i];
                    ws.fixed[i] = true;
                }
                None => at_minimum = true,
            }
        }
        if at_minimum {
            // Bound multipliers μ = H d + g - Jᵀ λ: >= 0 at a lower bound, <= 0 at an upper.
            let gscale = 1e-12 * (1.0 + ws.gradient(h, a, d, bx));
            let mut worst: Option<(usize, f64)> = None;
            for i in (0..n).filter(|&i| ws.fixed[i]) {
                let mu = ws.grad[i] - jac[i].dot(&lambda);
                let wrong = if a[i] + d[i] <= bx.lo[i] { -mu } else { mu };
                if wrong > gscale && worst.is_none_or(|(_, w)| wrong > w) {
                    worst = Some((i, wrong));
                }
            }
            match worst {
                Some((i, _)) => ws.fixed[i] = false,
                None => return true,
            }
        }
    }
    false
}

/// The scratch of the iteration's steps.
#[derive(Default)]
struct Work {
    dual: DualWork,
    lm: LmWork,
    /// `Σ λ_k ∇²_θ p_k` of the last curved step (q × q).
    theta: Vec<f64>,
    /// Scratch of the products with the Hessian (q, q, and n × q).
    hm: Vec<f64>,
    reduced: ReducedWork,
    convex: ConvexWork,
    curved: CurvedWork,
    /// The curved step.
    d: Vec<f64>,
}

/// The state of the closed-form iteration: the affine map, the box, the target and the
/// scales, the iterate and its chain, and the scratch of the steps.
#[derive(Default)]
struct ClosedForm {
    aff: Affine,
    bx: Box_,
    target: V3<f64>,
    /// The rod length (m).
    length: f64,
    /// Pose error below which the iteration is in its near phase (m).
    near: f64,
    /// Tolerance of the minimum-norm program's constraint (m).
    tol_qp: f64,
    /// The actuation: tensions (N), then pressures (Pa).
    a: Vec<f64>,
    /// The chain at `a`, and at the trial actuation.
    cur: Chain,
    next: Chain,
    /// The minimum-norm (or least-squares) point of the last program.
    y: Vec<f64>,
    /// The step of the last program.
    step: Vec<f64>,
    /// The multipliers of the last feasible minimum-norm program (the start of the next).
    lambda: V3<f64>,
    /// The Hessian of the Lagrangian of the last curved step (n × n, row-major).
    hess: Vec<f64>,
    /// Whether the last step was curved, and whether `hess` was formed for it (the reduced
    /// step applies it without forming it).
    curved: bool,
    hess_formed: bool,
    /// The trial actuation, and the second-order corrected one.
    trial: Vec<f64>,
    corrected: Vec<f64>,
    /// The trust radius (scaled actuation norm): NaN until the first Jacobian is known.
    radius: f64,
    /// The penalty of the pose error in the merit function.
    nu: f64,
    iterations: usize,
    evaluations: usize,
    work: Work,
}

impl ClosedForm {
    /// Resets the state to the first iterate of a new problem (the warm start's actuation or
    /// the reference, clamped), its vectors reused; `false` if the warm start does not fit or
    /// the chain cannot be evaluated there.
    fn reset(
        &mut self,
        robot: &PccRobot,
        target: &V3<f64>,
        options: &InverseOptions,
        warm: Option<&InverseWarmStart>,
    ) -> bool {
        self.aff.fill(robot);
        let (nt, n) = (robot.n_tendons(), self.aff.n);
        let bx = &mut self.bx;
        bx.w.clear();
        match &options.weights {
            Some(w) => bx.w.extend_from_slice(w),
            None => {
                bx.w.resize(nt, 1.0);
                let areas = robot.chambers().iter().flat_map(|(_, c)| c.areas());
                bx.w.extend(areas.map(|a| a * a));
            }
        }
        let (tb, pb) = (options.tension_bounds, options.pressure_bounds);
        bx.lo.clear();
        bx.lo
            .extend((0..n).map(|i| if i < nt { tb.0 } else { pb.0 }));
        bx.hi.clear();
        bx.hi
            .extend((0..n).map(|i| if i < nt { tb.1 } else { pb.1 }));
        bx.c.clear();
        match &options.reference {
            Some(c) => bx.c.extend_from_slice(c),
            None => bx.c.resize(n, 0.0),
        }
        self.a.clear();
        match warm {
            Some(w) if w.actuation.len() == n && w.actuation.iter().all(|v| v.is_finite()) => {
                self.a.extend_from_slice(&w.actuation);
            }
            Some(_) => return false,
            None => self.a.extend_from_slice(&bx.c),
        }
        for (i, v) in self.a.iter_mut().enumerate() {
            *v = bx.clamp(i, *v);
        }
        if !self.cur.eval(&self.aff, &self.a) {
            return false;
        }
        self.target = *target;
        self.length = self.aff.rest.iter().sum();
        self.near = NEAR_TARGET * self.length;
        self.tol_qp = 1e-3 * options.tolerance;
        for v in [
            &mut self.y,
            &mut self.step,
            &mut self.trial,
            &mut self.corrected,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
        self.lambda = V3::zeros();
        self.curved = false;
        self.radius = f64::NAN;
        self.nu = 0.0;
        self.iterations = 0;
        self.evaluations = 1;
        true
    }

    /// The step of the program at the iterate for the pose error `e` (into `self.step`): the
    /// minimum-norm step (the bounded least squares if the linearised target cannot be met
    /// inside the bounds), curved where the minimum-norm step fits the trust region (always
    /// near the target). Returns the multipliers (`None`: least squares); `None` if the least
    /// squares fail.
    fn program_step(&mut self, e: &V3<f64>, merit: f64) -> Option<Option<V3<f64>>> {
        let n = self.aff.n;
        let (jac, bx) = (&self.cur.jac, &self.bx);
        let mut b = *e;
        for i in 0..n {
            b += jac[i] * self.a[i];
        }
        let min_norm = DualProgram {
            centre: &bx.c,
            mu: 1.0,
            rho: 0.0,
            tol: self.tol_qp,
        };
        let ws = &mut self.work;
        let lambda = dual(
            jac,
            &b,
            bx,
            &min_norm,
            self.lambda,
            &mut self.y,
            &mut ws.dual,
        );
        if lambda.is_none() {
            // The linearised target cannot be met inside the bounds: the bounded least
            // squares, with the norm as a vanishing regularisation.
            let jmax = jac.iter().fold(0.0f64, |m, j| m.max(j.amax()));
            let wmax = bx.w.iter().fold(0.0f64, |m, v| m.max(*v));
            let reg = (LEAST_SQUARES_REGULARISATION * jmax.powi(2).max(1e-300) / wmax).max(1e-300);
            let least_squares = DualProgram {
                mu: reg,
                rho: 1.0,
                ..min_norm
            };
            dual(
                jac,
                &b,
                bx,
                &least_squares,
                V3::zeros(),
                &mut self.y,
                &mut ws.dual,
            )?;
        }
        for i in 0..n {
            self.step[i] = self.y[i] - self.a[i];
        }
        self.curved = false;
        let Some(l) = lambda else {
            return Some(None);
        };
        self.lambda = l;
        // Far from the target a step longer than the trust region is replaced by the
        // Levenberg–Marquardt step: its curvature would not be used.
        let far = merit > self.near;
        let fits = bx.norm(&self.step) <= self.radius;
        if merit > CURVED_FROM * self.length || (far && !fits) {
            return Some(lambda);
        }
        if (0..n).filter(|&i| bx.inside(i, self.y[i])).count() <= 3 {
            // No null space of the free columns: the curved step is the minimum-norm one.
            return Some(lambda);
        }
        self.cur.theta_hessian(&l, &mut ws.theta);
        let cols = (&self.aff, &ws.theta[..], &jac[..]);
        match reduced_step(
            cols,
            (&self.a, &self.y),
            bx,
            &mut ws.convex,
            &mut ws.reduced,
        ) {
            Reduced::NoNullSpace => {}
            Reduced::Step => {
                self.step.copy_from_slice(&ws.reduced.d);
                self.curved = true;
                self.hess_formed = false;
            }
            Reduced::Bounds => {
                // The bounds change on the face: the primal active set on the whole Hessian.
                let hess = &mut self.hess;
                lagrangian_hessian(&self.aff, &ws.theta, &bx.w, &mut ws.hm, hess);
                convexify(hess, jac, &self.y, bx, &mut ws.convex);
                let h = (&hess[..], &jac[..]);
                if curved_step(h, &self.a, &self.y, bx, &mut ws.d, &mut ws.curved) {
                    self.step.copy_from_slice(&ws.d);
                    self.curved = true;
                    self.hess_formed = true;
                }
            }
        }
        Some(lambda)
    }

    /// The step search of `solve_inverse` (trust region far from the target, line search on
    /// the merit function near it) from the iterate along `self.step`; the accepted
    /// actuation is left in `trial` and its chain in `next`. Returns whether a step was
    /// accepted.
    fn search(&mut self, e: &V3<f64>, merit: f64, norm_a: f64) -> bool {
        let n = self.aff.n;
        let near_phase = merit <= self.near;
        let residual_after = |jac: &[V3<f64>], d: &[f64]| {
            let mut r = *e;
            for i in 0..n {
                r -= jac[i] * d[i];
            }
            r.norm()
        };
        let grad: f64 = (0..n)
            .map(|i| self.bx.w[i] * (self.a[i] - self.bx.c[i]) * self.step[i])
            .sum();
        let slope = grad + self.nu * (residual_after(&self.cur.jac, &self.step) - merit);
        let mut alpha = 1.0;
        while self.radius > 1e-14 * (1.0 + norm_a) && alpha > 1e-10 {
            let full = near_phase || self.bx.norm(&self.step) <= self.radius;
            if !full {
                let (jac, ws) = (&self.cur.jac, &mut self.work.lm);
                lm_step(jac, (e, &self.a), &self.bx, self.radius, &mut self.step, ws);
            }
            let step_norm = self.bx.norm(&self.step) * alpha;
            if step_norm <= 1e-15 * (1.0 + norm_a) {
                break;
            }
            for i in 0..n {
                self.trial[i] = self.bx.clamp(i, self.a[i] + alpha * self.step[i]);
            }
            self.evaluations += 1;
            let predicted = merit - residual_after(&self.cur.jac, &self.step);
            if self.next.eval(&self.aff, &self.trial) {
                let mt = (self.target - self.next.p).norm();
                let ok = if near_phase {
                    let df = objective_change(&self.bx.w, &self.bx.c, &self.a, &self.trial);
                    let local = step_norm <= LOCAL_STEP * (1.0 + norm_a);
                    (local && mt <= self.near)
                        || df + self.nu * (mt - merit) <= 1e-4 * alpha * slope.min(0.0)
                } else {
                    mt <= (1.0 - 1e-4) * merit || (full && mt <= self.near)
                };
                if mt.is_finite() && ok {
                    self.radius = trust_radius(self.radius, full, step_norm, merit - mt, predicted);
                    return true;
                }
                if near_phase && alpha == 1.0 && mt.is_finite() && self.correct(merit, slope) {
                    return true;
                }
            }
            if near_phase {
                alpha *= 0.5;
            } else {
                self.radius = 0.25 * step_norm.min(self.radius);
            }
        }
        false
    }

    /// The second-order correction of a full near step that the merit function rejects: the
    /// minimum-norm change `c` of the trial actuation with `J c = e(trial)` (the Jacobian at
    /// the iterate), inside the bounds; taken if `trial + c` passes the merit test of the
    /// full step. On success the corrected actuation is left in `trial` and its chain in
    /// `next`.
    fn correct(&mut self, merit: f64, slope: f64) -> bool {
        let n = self.aff.n;
        let jac = &self.cur.jac;
        let mut b = self.target - self.next.p;
        for i in 0..n {
            b += jac[i] * self.trial[i];
        }
        let program = DualProgram {
            centre: &self.trial,
            mu: 1.0,
            rho: 0.0,
            tol: self.tol_qp,
        };
        let ws = &mut self.work.dual;
        if dual(
            jac,
            &b,
            &self.bx,
            &program,
            V3::zeros(),
            &mut self.corrected,
            ws,
        )
        .is_none()
        {
            return false;
        }
        self.evaluations += 1;
        if !self.next.eval(&self.aff, &self.corrected) {
            return false;
        }
        let mt = (self.target - self.next.p).norm();
        let df = objective_change(&self.bx.w, &self.bx.c, &self.a, &self.corrected);
        if !(mt.is_finite() && df + self.nu * (mt - merit) <= 1e-4 * slope.min(0.0)) {
            return false;
        }
        self.trial.copy_from_slice(&self.corrected);
        true
    }

    /// The result at the iterate (reached): its pose, the pose Jacobian in the actuation
    /// (position rows, then rotation rows `Ω M`) and the Hessian (`W` unless the last step
    /// was curved).
    fn solution(&mut self, nt: usize) -> InverseSolution {
        if self.curved && !self.hess_formed {
            // The reduced step formed no Hessian: the whole one at the last program.
            let ws = &mut self.work;
            lagrangian_hessian(&self.aff, &ws.theta, &self.bx.w, &mut ws.hm, &mut self.hess);
            convexify(
                &mut self.hess,
                &self.cur.jac,
                &self.y,
                &self.bx,
                &mut ws.convex,
            );
        }
        let (aff, cur, n) = (&self.aff, &self.cur, self.aff.n);
        let dist = (self.target - cur.p).norm();
        let ns = aff.rest.len();
        let jac = DMatrix::from_fn(6, n, |r, k| {
            if r < 3 {
                cur.jac[k][r]
            } else {
                (0..ns)
                    .map(|s| {
                        (0..3)
                            .map(|c| cur.oc[s][c][r - 3] * aff.cols[s * n + k][c])
                            .sum::<f64>()
                    })
                    .sum()
            }
        });
        let hessian = if self.curved {
            DMatrix::from_row_slice(n, n, &self.hess)
        } else {
            DMatrix::from_fn(n, n, |r, c| if r == c { self.bx.w[r] } else { 0.0 })
        };
        InverseSolution {
            actuation: self.a.clone(),
            n_tendons: nt,
            position_error: dist,
            rotation_error: 0.0,
            iterations: self.iterations,
            evaluations: self.evaluations,
            probes: 0,
            converged: true,
            reached: true,
            evaluation: Evaluation {
                positions: vec![cur.p],
                rotation: cur.r,
                jacobian: Some(vec![jac]),
            },
            hessian,
        }
    }
}

impl ClosedForm {
    /// The iteration from the state `reset` made (the steps are those of `solve_inverse`, in
    /// the same order); the result if the target is reached.
    fn run(&mut self, robot: &PccRobot, options: &InverseOptions) -> Option<InverseSolution> {
        loop {
            let e = self.target - self.cur.p;
            let merit = e.norm();
            let reached = merit <= options.tolerance;
            let norm_a = self.bx.norm(&self.a);
            if self.radius.is_nan() {
                // A first step that moves the linearised pose by at most the rod length (the
                // linearisation of a straight rod asks for huge tensions to shorten it).
                let sigma = scaled_norm_of(&self.cur.jac, &self.bx.w);
                self.radius = if sigma > 0.0 {
                    (FIRST_RADIUS * self.length / sigma).max(norm_a)
                } else {
                    f64::INFINITY
                };
            }
            let lambda = self.program_step(&e, merit)?;
            if let Some(l) = &lambda {
                self.nu = 1.5 * l.norm();
            }
            let small = self.bx.norm(&self.step) <= options.optimality_tolerance * (1.0 + norm_a);
            if small && reached {
                break;
            }
            if small && lambda.is_none() {
                // Stationary short of the target: the generic iteration reports it.
                return None;
            }
            if self.iterations >= options.max_iterations {
                return None;
            }
            let accepted = self.search(&e, merit, norm_a);
            self.iterations += 1;
            if !accepted {
                return None;
            }
            self.a.copy_from_slice(&self.trial);
            std::mem::swap(&mut self.cur, &mut self.next);
        }
        Some(self.solution(robot.n_tendons()))
    }
}

thread_local! {
    /// The state of the last closed-form solve on this thread, reset by the next: its vectors
    /// keep their capacity, so that a solve allocates only its result.
    static STATE: Cell<Option<Box<ClosedForm>>> = const { Cell::new(None) };
}

/// The closed-form iteration for an unloaded robot and a tip position; `None` hands the
/// problem to the generic iteration (a linearised target out of reach inside the bounds, a
/// failed step, the iterations exhausted: the generic one decides and reports those cases).
pub(super) fn closed_form(
    robot: &PccRobot,
    target: &V3<f64>,
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
) -> Option<InverseSolution> {
    let mut cf = STATE.with(Cell::take).unwrap_or_default();
    let out = if cf.reset(robot, target, options, warm) {
        cf.run(robot, options)
    } else {
        None
    };
    STATE.with(|s| s.set(Some(cf)));
    out
}
