//! The PCC model as a [`Forward`] model of the inverse statics: closed-form equilibria without
//! a tip load (Newton with the exact Jacobian otherwise) and the exact actuation Jacobian of
//! `pcc/sensitivity.rs`. Tip targets only.

use nalgebra::{Matrix3, Vector3};

use super::{Evaluation, Forward};
use crate::error::Result;
use crate::pcc::sensitivity::pcc_actuation_jacobian;
use crate::pcc::statics::{
    solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions, PccStaticsSolution,
};

/// A PCC robot under a tip wrench as a forward model, warm-started from its last solve.
pub struct PccForward<'r> {
    robot: &'r PccRobot,
    loads: PccLoads,
    options: PccSolveOptions,
    /// The last solution.
    pub solution: Option<PccStaticsSolution>,
}

impl<'r> PccForward<'r> {
    /// The forward model of `robot` under the tip wrench of `loads` (its tensions and
    /// pressures are replaced by the actuation), solved with `options`.
    pub fn new(robot: &'r PccRobot, loads: &PccLoads, options: &PccSolveOptions) -> Self {
        Self {
            robot,
            loads: loads.clone(),
            options: options.clone(),
            solution: None,
        }
    }

    /// The loads at the actuation `a` (tensions then pressures).
    pub fn loads_at(&self, a: &[f64]) -> PccLoads {
        let nt = self.robot.n_tendons();
        PccLoads {
            tensions: a[..nt].to_vec(),
            pressures: a[nt..].to_vec(),
            ..self.loads.clone()
        }
    }
}

impl Forward for PccForward<'_> {
    fn dims(&self) -> (usize, usize) {
        (self.robot.n_tendons(), self.robot.n_chambers())
    }

    fn length(&self) -> f64 {
        self.robot.segments().iter().map(|s| s.rest_length()).sum()
    }

    fn chamber_areas(&self) -> Vec<f64> {
        self.robot
            .chambers()
            .iter()
            .flat_map(|(_, c)| c.areas().to_vec())
            .collect()
    }

    fn evaluate(&mut self, a: &[f64], jacobian: bool) -> Result<Evaluation> {
        let loads = self.loads_at(a);
        let loaded = loads.tip_force != Vector3::zeros() || loads.tip_moment != Vector3::zeros();
        let opts = PccSolveOptions {
            // The unloaded equilibrium is closed form; a loaded one starts from the last.
            warm_start: if loaded {
                self.solution.as_ref().map(PccStaticsSolution::warm_start)
            } else {
                None
            },
            ..self.options.clone()
        };
        let sol = solve_pcc_statics(self.robot, &loads, &opts)?;
        let t = sol.tip_pose;
        let positions = vec![Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)])];
        let rotation: Matrix3<f64> = t.fixed_view::<3, 3>(0, 0).into_owned();
        let jac = if jacobian {
            Some(vec![pcc_actuation_jacobian(self.robot, &loads, &sol)?])
        } else {
            None
        };
        self.solution = Some(sol);
        Ok(Evaluation {
            positions,
            rotation,
            jacobian: jac,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// The unloaded PCC robot in closed form.
//
// Without a tip wrench the equilibrium is closed form and *affine* in the actuation in the
// coordinates `θ = (θ_x, θ_y, ℓ)` of every segment (`pcc/statics.rs`): `θ = θ0 + M a`. The tip
// position is the chain kinematics of `θ`, whose first and second derivatives are closed form
// (`seg_kin`), so the actuation Jacobian is `J = J_θ M` and the Hessian of the Lagrangian
// `½|a - c|²_W - λᵀ p(a)` is `W - Mᵀ (Σ λ_k ∇²_θ p_k) M`, exact. The iteration is that of
// `solve_inverse` (the same two phases, steps, merit function and stopping test) with the
// exact Hessian near the target instead of directional differences (kept whole, cross terms
// included, unless `Zᵀ H Z` must be raised to be positive definite: the step is Newton's and
// a warm 1 mm move takes three iterations), on stack-sized dense
// algebra: the minimum-norm step and the Levenberg–Marquardt step are solved in the dual
// (three multipliers), the curved step by the KKT system of its free variables.
// ---------------------------------------------------------------------------------------------

use nalgebra::{DMatrix as Dm, Matrix3 as M3, Vector3 as V3};

use super::{
    check_options, check_target, objective_change, solve_inverse, trust_radius, InverseOptions,
    InverseSolution, InverseWarmStart, Target, FIRST_RADIUS, LEAST_SQUARES_REGULARISATION,
    LOCAL_STEP, NEAR_TARGET,
};
use crate::math::linalg::DenseLu;
use crate::pcc::statics::{seg_kin, SegKin};

/// The affine map `θ = θ0 + M a` of an unloaded robot.
struct Affine {
    /// Actuators.
    n: usize,
    /// Rest lengths (`θ0 = (0, 0, ℓ0)`).
    rest: Vec<f64>,
    /// `∂θ_s/∂a_k` at `s n + k`.
    cols: Vec<[f64; 3]>,
}

impl Affine {
    fn new(robot: &PccRobot) -> Self {
        let segs = robot.segments();
        let (nt, nc) = (robot.n_tendons(), robot.n_chambers());
        let n = nt + nc;
        let mut cols = vec![[0.0; 3]; segs.len() * n];
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
        Self {
            n,
            rest: segs.iter().map(|s| s.rest_length()).collect(),
            cols,
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

    /// `Mᵀ (Σ λ_k ∇²_θ p_k) M` (n × n, row-major) into `out`.
    fn curvature(&self, aff: &Affine, lambda: &V3<f64>, out: &mut Vec<f64>) {
        let (n, ns) = (aff.n, aff.rest.len());
        let q = 3 * ns;
        let mut h = vec![0.0; q * q];
        for s in 0..ns {
            let (b, k) = (&self.base[s], &self.kin[s]);
            let dd = self.p - self.tip[s];
            for c in 0..3 {
                for m in 0..3 {
                    let mut v = b * k.ddp[c][m] + self.oc[s][c].cross(&self.oc[s][m].cross(&dd));
                    if c < 2 && m < 2 {
                        v += (b * k.dw[c][m]).cross(&dd);
                    }
                    h[(3 * s + c) * q + 3 * s + m] = lambda.dot(&v);
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
        // Mᵀ (H M), H M first (q × n).
        let mut hm = vec![0.0; q * n];
        for i in 0..q {
            for j in 0..q {
                let hij = h[i * q + j];
                if hij == 0.0 {
                    continue;
                }
                let cj = &aff.cols[(j / 3) * n..(j / 3 + 1) * n];
                for (k, c) in cj.iter().enumerate() {
                    hm[i * n + k] += hij * c[j % 3];
                }
            }
        }
        out.clear();
        out.resize(n * n, 0.0);
        for i in 0..q {
            let ci = &aff.cols[(i / 3) * n..(i / 3 + 1) * n];
            for (k, c) in ci.iter().enumerate() {
                let mik = c[i % 3];
                if mik == 0.0 {
                    continue;
                }
                for l in 0..n {
                    out[k * n + l] += mik * hm[i * n + l];
                }
            }
        }
    }
}

/// The box, weights and centre of the small programs.
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

/// `min ½ Σ μ w_i (y_i - c_i)² + ½ ρ |J y - b|²/ρ²`-type programs in the dual: the maximiser
/// `λ` of `ψ(λ) = ½ μ |y - c|²_W - λᵀ (J y - b) - ½ ρ |λ|²` with `y(λ) = clamp(c + Jᵀλ / (μ w))`
/// (Newton on the gradient `b - J y - ρ λ`, backtracking). `ρ = 0`: the minimum-norm point
/// of the box meeting `J y = b` to `tol` (`None` if infeasible); `ρ = 1`: the bounded
/// Levenberg–Marquardt point `min |J y - b|² + μ |y - c|²_W`. `y` is written; returns `λ`.
fn dual(
    jac: &[V3<f64>],
    b: &V3<f64>,
    bx: &Box_,
    program: &DualProgram<'_>,
    y: &mut [f64],
) -> Option<V3<f64>> {
    let DualProgram {
        centre,
        mu,
        rho,
        tol,
    } = *program;
    let n = jac.len();
    let y_of = |l: &V3<f64>, y: &mut [f64]| -> f64 {
        let mut psi = 0.0;
        let mut r = -b;
        for i in 0..n {
            let v = centre[i] + jac[i].dot(l) / (mu * bx.w[i]);
            y[i] = bx.clamp(i, v);
            psi += 0.5 * mu * bx.w[i] * (y[i] - centre[i]).powi(2);
            r += jac[i] * y[i];
        }
        psi - l.dot(&r) - 0.5 * rho * l.norm_squared()
    };
    let mut lambda = V3::zeros();
    let mut psi = y_of(&lambda, y);
    let mut trial = vec![0.0; n];
    // The free set and gradient of the last Newton step: when a step on an unchanged free set
    // (the full one is exact for it) leaves the gradient where it was, it is at round-off.
    let (mut free, mut last_free) = (vec![false; n], Vec::new());
    let mut last_g = f64::INFINITY;
    for _ in 0..100 {
        let mut g = *b - rho * lambda;
        let mut h = M3::identity() * rho;
        for i in 0..n {
            g -= jac[i] * y[i];
            let v = centre[i] + jac[i].dot(&lambda) / (mu * bx.w[i]);
            free[i] = v >= bx.lo[i] && v <= bx.hi[i];
            if free[i] {
                h += jac[i] * jac[i].transpose() / (mu * bx.w[i]);
            }
        }
        let gn = g.amax();
        let floor = free == last_free && gn > 0.5 * last_g && gn <= 1e3 * tol;
        if gn <= tol || floor {
            return Some(lambda);
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
        last_free.clone_from(&free);
        last_g = gn;
        for _ in 0..60 {
            let lt = lambda + d * alpha;
            let pt = y_of(&lt, &mut trial);
            if pt >= psi + 1e-4 * alpha * slope || (pt - psi).abs() <= 1e-15 * psi.abs() {
                (lambda, psi) = (lt, pt);
                y.copy_from_slice(&trial);
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

/// The bounded Levenberg–Marquardt step of scaled length about `radius` (as
/// `levenberg_marquardt_step` of the generic iteration).
fn lm_step(jac: &[V3<f64>], e: &V3<f64>, a: &[f64], bx: &Box_, radius: f64) -> Vec<f64> {
    let n = a.len();
    let mut b = *e;
    for i in 0..n {
        b += jac[i] * a[i];
    }
    let sigma = scaled_norm_of(jac, &bx.w).max(1e-300);
    let mut mu = (sigma * e.norm() / radius).max(1e-6 * sigma * sigma);
    let (mut best, mut fitted) = (vec![0.0; n], false);
    let mut y = vec![0.0; n];
    let tol = 1e-15 * (e.amax() + b.amax());
    for _ in 0..60 {
        let program = DualProgram {
            centre: a,
            mu,
            rho: 1.0,
            tol,
        };
        if dual(jac, &b, bx, &program, &mut y).is_none() {
            break;
        }
        let d: Vec<f64> = (0..n).map(|i| y[i] - a[i]).collect();
        if bx.norm(&d) <= radius * 1.000_001 {
            best = d;
            fitted = true;
            mu *= 0.25;
            if mu < 1e-9 * sigma * sigma {
                break;
            }
        } else if fitted {
            break;
        } else {
            mu *= 4.0;
        }
    }
    best
}

/// The Hessian `h` (n × n, row-major) made positive definite on the null space `Z` of the
/// free columns of `J` (those free in `y_w`, scaled variables `W^{1/2} a`): kept exact when
/// `Zᵀ h Z` has its eigenvalues above `1e-3` (the cross terms `Zᵀ h Y` make the curved step
/// Newton's), otherwise only `Zᵀ h Z` raised to that floor, so that the curved step is a
/// descent step toward a minimum, never a saddle. Without a null space: `W` (the step is
/// then the constraints' alone).
fn convexify(h: &mut [f64], jac: &[V3<f64>], y_w: &[f64], bx: &Box_) {
    let n = y_w.len();
    let idx: Vec<usize> = (0..n)
        .filter(|&i| y_w[i] > bx.lo[i] && y_w[i] < bx.hi[i])
        .collect();
    let k = idx.len();
    let w = Dm::from_diagonal(&nalgebra::DVector::from_column_slice(&bx.w));
    let mut out = w.clone();
    if k > 3 {
        let jf = Dm::from_fn(3, k, |r, c| jac[idx[c]][r] / bx.w[idx[c]].sqrt());
        let eig = jf.tr_mul(&jf).symmetric_eigen();
        let top = eig.eigenvalues.iter().fold(0.0f64, |x, v| x.max(v.abs()));
        let cols: Vec<usize> = (0..k)
            .filter(|&c| eig.eigenvalues[c].abs() <= 1e-10 * top)
            .collect();
        if !cols.is_empty() {
            let mut z = Dm::zeros(n, cols.len());
            for (j, &c) in cols.iter().enumerate() {
                for (r, &i) in idx.iter().enumerate() {
                    z[(i, j)] = eig.eigenvectors[(r, c)] / bx.w[i].sqrt();
                }
            }
            let hm = Dm::from_row_slice(n, n, h);
            let hm = (&hm + hm.transpose()) * 0.5;
            let zhz = z.tr_mul(&(&hm * &z));
            let zhz = (&zhz + zhz.transpose()) * 0.5;
            let e = zhz.clone().symmetric_eigen();
            if e.eigenvalues.iter().all(|&v| v >= 1e-3) {
                // Positive definite on Z already: the exact Hessian, cross terms included
                // (the step is Newton's).
                out = hm;
            } else {
                let vals = e.eigenvalues.map(|v| v.max(1e-3));
                let mz = &e.eigenvectors * Dm::from_diagonal(&vals) * e.eigenvectors.transpose();
                // Only `Zᵀ H Z` raised (`Zᵀ W Z = I`): the rest of the exact Hessian kept.
                let wz = &w * &z;
                out = &hm + &wz * (mz - zhz) * wz.transpose();
                out = (&out + out.transpose()) * 0.5;
            }
        }
    }
    for r in 0..n {
        for c in 0..n {
            h[r * n + c] = out[(r, c)];
        }
    }
}

/// The curved step: `min ½ dᵀ H d + (W (a - c))ᵀ d` s.t. `J d = e` with the variables that
/// are at a bound in `y_w` held there; `None` if its KKT system is singular or the result
/// leaves the box.
fn curved_step(
    h: &[f64],
    jac: &[V3<f64>],
    e: &V3<f64>,
    a: &[f64],
    y_w: &[f64],
    bx: &Box_,
) -> Option<Vec<f64>> {
    let n = a.len();
    let free: Vec<usize> = (0..n)
        .filter(|&i| y_w[i] > bx.lo[i] && y_w[i] < bx.hi[i])
        .collect();
    let nf = free.len();
    let k = nf + 3;
    let d_fixed: Vec<f64> = (0..n)
        .map(|i| {
            if free.contains(&i) {
                0.0
            } else {
                y_w[i] - a[i]
            }
        })
        .collect();
    // [H_FF J_Fᵀ; J_F 0] [d_F; ν] = [-g_F - H_FA d_A; e - J_A d_A], column-major.
    let mut kkt = vec![0.0; k * k];
    let mut rhs = vec![0.0; k];
    for (r, &i) in free.iter().enumerate() {
        for (c, &j) in free.iter().enumerate() {
            kkt[r + c * k] = h[i * n + j];
        }
        for m in 0..3 {
            kkt[r + (nf + m) * k] = jac[i][m];
            kkt[nf + m + r * k] = jac[i][m];
        }
        let mut v = -bx.w[i] * (a[i] - bx.c[i]);
        for j in 0..n {
            v -= h[i * n + j] * d_fixed[j];
        }
        rhs[r] = v;
    }
    let mut ea = *e;
    for j in 0..n {
        ea -= jac[j] * d_fixed[j];
    }
    rhs[nf..].copy_from_slice(ea.as_slice());
    let mut lu = DenseLu::default();
    if !lu.factor(k, &kkt) || !lu.solve_in_place(&mut rhs) {
        return None;
    }
    let mut d = d_fixed;
    for (r, &i) in free.iter().enumerate() {
        d[i] = rhs[r];
        let v = a[i] + d[i];
        if !(v >= bx.lo[i] && v <= bx.hi[i]) {
            return None;
        }
    }
    Some(d)
}

/// The state of the closed-form iteration: the affine map, the box, the target and the
/// scales, the iterate and its chain, and the scratch of the steps.
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
    /// The Hessian of the Lagrangian of the last curved step (n × n, row-major).
    hess: Vec<f64>,
    /// The trial actuation.
    trial: Vec<f64>,
    /// The trust radius (scaled actuation norm): NaN until the first Jacobian is known.
    radius: f64,
    /// The penalty of the pose error in the merit function.
    nu: f64,
    iterations: usize,
    evaluations: usize,
}

impl ClosedForm {
    /// The first iterate (the warm start's actuation or the reference, clamped); `None` if
    /// the warm start does not fit or the chain cannot be evaluated there.
    fn new(
        robot: &PccRobot,
        target: &V3<f64>,
        options: &InverseOptions,
        warm: Option<&InverseWarmStart>,
    ) -> Option<Self> {
        let aff = Affine::new(robot);
        let (nt, n) = (robot.n_tendons(), aff.n);
        let length: f64 = aff.rest.iter().sum();
        let areas: Vec<f64> = robot
            .chambers()
            .iter()
            .flat_map(|(_, c)| c.areas().to_vec())
            .collect();
        let w = match &options.weights {
            Some(w) => w.clone(),
            None => (0..n)
                .map(|i| if i < nt { 1.0 } else { areas[i - nt].powi(2) })
                .collect(),
        };
        let (tb, pb) = (options.tension_bounds, options.pressure_bounds);
        let bx = Box_ {
            lo: (0..n).map(|i| if i < nt { tb.0 } else { pb.0 }).collect(),
            hi: (0..n).map(|i| if i < nt { tb.1 } else { pb.1 }).collect(),
            w,
            c: options.reference.clone().unwrap_or_else(|| vec![0.0; n]),
        };
        let mut a: Vec<f64> = match warm {
            Some(w) if w.actuation.len() == n && w.actuation.iter().all(|v| v.is_finite()) => {
                w.actuation.clone()
            }
            Some(_) => return None,
            None => bx.c.clone(),
        };
        for (i, v) in a.iter_mut().enumerate() {
            *v = bx.clamp(i, *v);
        }
        let mut cur = Chain::default();
        if !cur.eval(&aff, &a) {
            return None;
        }
        Some(Self {
            aff,
            bx,
            target: *target,
            length,
            near: NEAR_TARGET * length,
            tol_qp: 1e-3 * options.tolerance,
            a,
            cur,
            next: Chain::default(),
            y: vec![0.0; n],
            hess: Vec::new(),
            trial: vec![0.0; n],
            radius: f64::NAN,
            nu: 0.0,
            iterations: 0,
            evaluations: 1,
        })
    }

    /// The step of the program at the iterate for the pose error `e`: the minimum-norm step
    /// (the bounded least squares if the linearised target cannot be met inside the bounds),
    /// curved near the target. Returns the step, the multipliers (`None`: least squares) and
    /// whether the step is curved; `None` if the least squares fail.
    fn program_step(
        &mut self,
        e: &V3<f64>,
        merit: f64,
    ) -> Option<(Vec<f64>, Option<V3<f64>>, bool)> {
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
        let lambda = dual(jac, &b, bx, &min_norm, &mut self.y);
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
            dual(jac, &b, bx, &least_squares, &mut self.y)?;
        }
        let mut step: Vec<f64> = (0..n).map(|i| self.y[i] - self.a[i]).collect();
        let mut curved = false;
        if merit <= self.near && lambda.is_some() {
            let hess = &mut self.hess;
            self.cur
                .curvature(&self.aff, &lambda.unwrap_or_default(), hess);
            for (k, v) in hess.iter_mut().enumerate() {
                *v = -*v + if k % (n + 1) == 0 { bx.w[k / n] } else { 0.0 };
            }
            convexify(hess, jac, &self.y, bx);
            if let Some(d) = curved_step(hess, jac, e, &self.a, &self.y, bx) {
                step = d;
                curved = true;
            }
        }
        Some((step, lambda, curved))
    }

    /// The step search of `solve_inverse` (trust region far from the target, line search on
    /// the merit function near it) from the iterate along `step`; the accepted actuation is
    /// left in `trial` and its chain in `next`. Returns whether a step was accepted.
    fn search(&mut self, e: &V3<f64>, merit: f64, mut step: Vec<f64>, norm_a: f64) -> bool {
        let n = self.aff.n;
        let near_phase = merit <= self.near;
        let residual_after = |jac: &[V3<f64>], d: &[f64]| {
            let mut r = *e;
            for i in 0..n {
                r -= jac[i] * d[i];
            }
            r.norm()
        };
        let bx = &self.bx;
        let grad: f64 = (0..n)
            .map(|i| bx.w[i] * (self.a[i] - bx.c[i]) * step[i])
            .sum();
        let slope = grad + self.nu * (residual_after(&self.cur.jac, &step) - merit);
        let mut alpha = 1.0;
        while self.radius > 1e-14 * (1.0 + norm_a) && alpha > 1e-10 {
            let full = near_phase || bx.norm(&step) <= self.radius;
            if !full {
                step = lm_step(&self.cur.jac, e, &self.a, bx, self.radius);
            }
            let step_norm = bx.norm(&step) * alpha;
            if step_norm <= 1e-15 * (1.0 + norm_a) {
                break;
            }
            for i in 0..n {
                self.trial[i] = bx.clamp(i, self.a[i] + alpha * step[i]);
            }
            self.evaluations += 1;
            let predicted = merit - residual_after(&self.cur.jac, &step);
            if self.next.eval(&self.aff, &self.trial) {
                let mt = (self.target - self.next.p).norm();
                let ok = if near_phase {
                    let df = objective_change(&bx.w, &bx.c, &self.a[..n], &self.trial[..n]);
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
            }
            if near_phase {
                alpha *= 0.5;
            } else {
                self.radius = 0.25 * step_norm.min(self.radius);
            }
        }
        false
    }

    /// The result at the iterate (reached): its pose, the pose Jacobian in the actuation
    /// (position rows, then rotation rows `Ω M`) and the Hessian (`W` unless the last step
    /// was curved).
    fn solution(self, nt: usize, curved: bool) -> InverseSolution {
        let (aff, cur, n) = (&self.aff, &self.cur, self.aff.n);
        let dist = (self.target - cur.p).norm();
        let ns = aff.rest.len();
        let jac = Dm::from_fn(6, n, |r, k| {
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
        let hessian = if curved {
            Dm::from_row_slice(n, n, &self.hess)
        } else {
            Dm::from_fn(n, n, |r, c| if r == c { self.bx.w[r] } else { 0.0 })
        };
        InverseSolution {
            actuation: self.a,
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

/// The closed-form iteration for an unloaded robot and a tip position; `None` hands the
/// problem to the generic iteration (a linearised target out of reach inside the bounds, a
/// failed step, the iterations exhausted: the generic one decides and reports those cases).
/// The steps are those of `solve_inverse`, in the same order.
fn closed_form(
    robot: &PccRobot,
    target: &V3<f64>,
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
) -> Option<InverseSolution> {
    let mut cf = ClosedForm::new(robot, target, options, warm)?;
    let mut curved;
    loop {
        let e = cf.target - cf.cur.p;
        let merit = e.norm();
        let reached = merit <= options.tolerance;
        let (step, lambda, c) = cf.program_step(&e, merit)?;
        curved = c;
        if let Some(l) = &lambda {
            cf.nu = 1.5 * l.norm();
        }
        let norm_a = cf.bx.norm(&cf.a);
        let small = cf.bx.norm(&step) <= options.optimality_tolerance * (1.0 + norm_a);

        if small && reached {
            break;
        }
        if small && lambda.is_none() {
            // Stationary short of the target: the generic iteration reports it.
            return None;
        }
        if cf.iterations >= options.max_iterations {
            return None;
        }
        if cf.radius.is_nan() {
            let sigma = scaled_norm_of(&cf.cur.jac, &cf.bx.w);
            cf.radius = if sigma > 0.0 {
                (FIRST_RADIUS * cf.length / sigma).max(norm_a)
            } else {
                f64::INFINITY
            };
        }
        let accepted = cf.search(&e, merit, step, norm_a);
        cf.iterations += 1;
        if !accepted {
            return None;
        }
        cf.a.copy_from_slice(&cf.trial);
        std::mem::swap(&mut cf.cur, &mut cf.next);
    }
    Some(cf.solution(robot.n_tendons(), curved))
}

/// The inverse statics of the PCC robot `robot` under the tip wrench of `loads` (its
/// tensions and pressures are ignored) for `target`, the equilibria solved with `solve`: the
/// same objective, iteration and result as [`solve_inverse`] on a [`PccForward`]. For an
/// unloaded, tendon-driven robot and a tip position target it runs in closed form (the
/// module's notes);
/// otherwise, and whenever that iteration cannot decide, it is [`solve_inverse`].
///
/// # Errors
/// As [`solve_inverse`].
pub fn pcc_inverse_statics(
    robot: &PccRobot,
    loads: &PccLoads,
    target: &Target,
    options: &InverseOptions,
    solve: &PccSolveOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<InverseSolution> {
    let (nt, nc) = (robot.n_tendons(), robot.n_chambers());
    let length: f64 = robot.segments().iter().map(|s| s.rest_length()).sum();
    check_options(options, nt, nc, length)?;
    check_target(target)?;
    let unloaded = loads.tip_force == Vector3::zeros() && loads.tip_moment == Vector3::zeros();
    // Tendons only: with chambers the norm can be nearly flat along the target (pressure
    // against tension), where the generic iteration's answer is kept.
    if unloaded
        && nt > 0
        && nc == 0
        && target.s.is_none()
        && target.rotation.is_none()
        && target.points.len() == 1
    {
        if let Some(out) = closed_form(robot, &target.points[0], options, warm) {
            return Ok(out);
        }
    }
    let mut fwd = PccForward::new(robot, loads, solve);
    solve_inverse(&mut fwd, target, options, warm)
}
