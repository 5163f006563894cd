//! The steps of the inverse-statics iteration: the quadratic program of one iteration (the
//! minimum-norm step, the curved step, the bounded least squares), the bounded
//! Levenberg–Marquardt step, the curvature of the target manifold from directional
//! differences of the exact Jacobian, the damped BFGS update and the trust radius.

use nalgebra::{DMatrix, DVector};

use super::problem::Program;
use super::qp::{self, Bounds};
use super::{Forward, LEAST_SQUARES_REGULARISATION, MAX_PROBE_DIRECTIONS, PROBE_STEP};

/// The damped BFGS update (Powell) of the Lagrangian Hessian `h` for the step `a0 → a1`, with
/// the Jacobians (scaled rows) `j0`, `j1` and the multipliers `lambda`: `s = a1 - a0`,
/// `y = W s - (j1 - j0)ᵀ λ`. Returns whether it was updated.
pub(super) fn bfgs_update(
    h: &mut DMatrix<f64>,
    weights: &[f64],
    a0: &[f64],
    a1: &[f64],
    j0: &DMatrix<f64>,
    j1: &DMatrix<f64>,
    lambda: &DVector<f64>,
) -> bool {
    let n = a0.len();
    let s = DVector::from_fn(n, |i, _| a1[i] - a0[i]);
    if j0.shape() != j1.shape() || lambda.len() != j0.nrows() {
        return false;
    }
    let ws = DVector::from_fn(n, |i, _| weights[i] * s[i]);
    let y = ws - (j1 - j0).tr_mul(lambda);
    let hs = &*h * &s;
    let shs = s.dot(&hs);
    if !(shs > 0.0 && shs.is_finite() && y.iter().all(|v| v.is_finite())) {
        return false;
    }
    let sy = s.dot(&y);
    let r = if sy >= 0.2 * shs {
        y
    } else {
        let theta = 0.8 * shs / (shs - sy);
        &y * theta + &hs * (1.0 - theta)
    };
    let sr = s.dot(&r);
    if sr.is_nan() || sr <= 0.0 {
        return false;
    }
    // h += r rᵀ / sr - hs hsᵀ / shs, symmetric to round-off.
    for c in 0..n {
        for k in 0..=c {
            let v = 0.5 * (h[(k, c)] + h[(c, k)]) + r[k] * r[c] / sr - hs[k] * hs[c] / shs;
            h[(k, c)] = v;
            h[(c, k)] = v;
        }
    }
    true
}

/// The regularisation of the bounded least squares (a vanishing pull to the reference).
fn ls_regularisation(jac: &DMatrix<f64>, bounds: &Bounds) -> f64 {
    let scale = jac
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .powi(2)
        .max(1e-300);
    let wmax = bounds.weights.iter().fold(0.0f64, |m, v| m.max(*v));
    LEAST_SQUARES_REGULARISATION * scale / wmax
}

/// The spectral norm of `J W^{-1/2}` (the pose change per unit scaled actuation).
pub(super) fn scaled_jacobian_norm(jac: &DMatrix<f64>, weights: &[f64]) -> f64 {
    if jac.nrows() == 3 {
        // A tip position: the 3 × 3 Gram matrix on the stack.
        let mut g = nalgebra::Matrix3::zeros();
        for (c, w) in weights.iter().enumerate() {
            let col = jac.fixed_view::<3, 1>(0, c) / w.sqrt();
            g += col * col.transpose();
        }
        return g
            .symmetric_eigenvalues()
            .iter()
            .fold(0.0f64, |m, v| m.max(*v))
            .sqrt();
    }
    let js = DMatrix::from_fn(jac.nrows(), jac.ncols(), |r, c| {
        jac[(r, c)] / weights[c].sqrt()
    });
    let g = &js * js.transpose();
    g.symmetric_eigenvalues()
        .iter()
        .fold(0.0f64, |m, v| m.max(*v))
        .sqrt()
}

/// The bounded Levenberg–Marquardt step `d` of scaled length about `radius`:
/// `min |J d - e|² + μ |d|²_W` with `lo <= a + d <= hi`, `μ` raised until `|d|_W <= radius`.
pub(super) fn levenberg_marquardt_step(
    jac: &DMatrix<f64>,
    e: &DVector<f64>,
    a: &[f64],
    bounds: &Bounds,
    radius: f64,
) -> Vec<f64> {
    let n = a.len();
    let av = DVector::from_column_slice(a);
    let b = e + jac * &av;
    let local = Bounds {
        centre: a.to_vec(),
        ..bounds.clone()
    };
    let norm = |d: &[f64]| -> f64 {
        d.iter()
            .zip(&bounds.weights)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt()
    };
    let sigma = scaled_jacobian_norm(jac, &bounds.weights).max(1e-300);
    // |d| ≈ |e| / μ-scaled: start from μ with |Jᵀe| / μ ≈ radius.
    let mut mu = (sigma * e.norm() / radius).max(1e-6 * sigma * sigma);
    let mut best = vec![0.0; n];
    let mut fitted = false;
    // The normal equations and the scratch are the same for every μ.
    let normal = qp::NormalEquations::new(jac, &b);
    let mut ws = qp::BlsWork::default();
    for _ in 0..60 {
        let y = normal.solve(&local, mu, &mut ws);
        let d: Vec<f64> = (0..n).map(|i| y[i] - a[i]).collect();
        if norm(&d) <= radius * 1.000_001 {
            best = d;
            fitted = true;
            // Lengthen it while it fits (a few times).
            mu *= 0.25;
            if mu < 1e-3 * sigma * sigma * 1e-6 {
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

/// The free variables of `y`: strictly inside their bounds.
pub(super) fn free_set(y: &[f64], bounds: &Bounds) -> Vec<bool> {
    y.iter()
        .enumerate()
        .map(|(i, &v)| v > bounds.lo[i] && v < bounds.hi[i])
        .collect()
}

/// A solved quadratic program of one iteration.
pub(super) struct QpStep {
    /// The new actuation.
    pub y: DVector<f64>,
    /// The multipliers of the linearised target (feasible programs).
    pub lambda: Option<DVector<f64>>,
    /// Whether the target could not be met inside the bounds (the bounded least squares).
    pub least_squares: bool,
    /// The minimum-norm point (the program with `W`), if feasible.
    pub y_min_norm: Option<DVector<f64>>,
}

/// The program of one iteration at `a`: `min ½ Δᵀ H Δ + (W (a - c))ᵀ Δ` (or `½ |y - c|²_W`
/// when `H = W`, `curved == false`) s.t. `J y = b`, bounds; the bounded least squares if the
/// target cannot be met (or for a shape target). The dual of the minimum-norm program starts
/// from the multipliers `start` (the last program's) if given.
pub(super) fn solve_qp(
    p: &Program<'_>,
    lin: (&DMatrix<f64>, &DVector<f64>),
    a: &[f64],
    hess: &DMatrix<f64>,
    curved: bool,
    start: Option<&DVector<f64>>,
) -> QpStep {
    let (jac, b) = lin;
    let bounds = &p.bounds;
    let feasible = if p.shape {
        None
    } else {
        // The last program's multipliers only speed the dual iteration up: where it fails from
        // them it is run again cold before the target is declared out of the bounds' reach.
        qp::min_norm_from(jac, b, bounds, p.tol_qp, start)
            .or_else(|| start.and_then(|_| qp::min_norm_from(jac, b, bounds, p.tol_qp, None)))
    };
    match feasible {
        Some((y_w, l_w)) if curved => curved_qp(p, jac, a, hess, (y_w, l_w)),
        Some((y, l)) => QpStep {
            y_min_norm: Some(y.clone()),
            y,
            lambda: Some(l),
            least_squares: false,
        },
        None => QpStep {
            y: qp::bounded_least_squares(jac, b, bounds, ls_regularisation(jac, bounds)),
            lambda: None,
            least_squares: true,
            y_min_norm: None,
        },
    }
}

/// The curved program of one iteration at `a` (`min ½ Δᵀ H Δ + (W (a - c))ᵀ Δ` s.t. the
/// linearised target, bounds) from its minimum-norm point `y_w` and multipliers `l_w` (those
/// of the program with `W`, kept: the target's at a solution).
pub(super) fn curved_qp(
    p: &Program<'_>,
    jac: &DMatrix<f64>,
    a: &[f64],
    hess: &DMatrix<f64>,
    (y_w, l_w): (DVector<f64>, DVector<f64>),
) -> QpStep {
    let n = a.len();
    let bounds = &p.bounds;
    let av = DVector::from_column_slice(a);
    let wd = DVector::from_fn(n, |i, _| bounds.weights[i] * (a[i] - bounds.centre[i]));
    let q = wd - hess * &av;
    let r = qp::active_set_qp(hess, &q, jac, bounds, &y_w);
    let y = r.map_or_else(|| y_w.clone(), |(y, _)| y);
    QpStep {
        y,
        lambda: Some(l_w),
        least_squares: false,
        y_min_norm: Some(y_w),
    }
}

/// Relative step of the directional differences of the Jacobian.
const CURVATURE_STEP: f64 = 1e-6;

/// The Hessian of the Lagrangian `½|a - c|²_W - λᵀ p(a)` on the null space `Z` of the free
/// columns of `J`: `H z = W z - (J(a + ε z) - J(a))ᵀ λ / ε` for each column `z` (one
/// evaluation each), as `W + Z (Zᵀ H Z - Zᵀ W Z) Zᵀ` (positive definite on `Z`). Returns the
/// matrix (`None` if an evaluation fails) and the evaluations used.
pub(super) fn curvature<F: Forward + ?Sized>(
    forward: &mut F,
    p: &Program<'_>,
    a: &[f64],
    jac: &DMatrix<f64>,
    lambda: &DVector<f64>,
    free: &[bool],
) -> (Option<DMatrix<f64>>, usize) {
    let n = a.len();
    let bounds = &p.bounds;
    let w = DMatrix::from_diagonal(&DVector::from_column_slice(&bounds.weights));
    let Some(z) = null_space(jac, &bounds.weights, free) else {
        return (None, 0);
    };
    let d = z.ncols();
    let scale = 1.0
        + a.iter()
            .zip(&bounds.weights)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt();
    let mut hz = DMatrix::zeros(n, d);
    let mut used = 0;
    for j in 0..d {
        let zj = z.column(j).into_owned();
        // The scaled length of z_j is 1: a step of CURVATURE_STEP relative to the actuation,
        // toward the inside of the bounds.
        let mut eps = CURVATURE_STEP * scale;
        let inside = |e: f64| {
            (0..n).all(|i| {
                let v = a[i] + e * zj[i];
                v >= bounds.lo[i] && v <= bounds.hi[i]
            })
        };
        if !inside(eps) {
            eps = -eps;
            if !inside(eps) {
                return (None, used);
            }
        }
        let trial: Vec<f64> = (0..n).map(|i| a[i] + eps * zj[i]).collect();
        used += 1;
        let Ok(ev) = forward.evaluate(&trial, true) else {
            return (None, used);
        };
        let Some(j2) = p.error(&ev).jac else {
            return (None, used);
        };
        let col = &w * &zj - (j2 - jac).tr_mul(lambda) / eps;
        hz.set_column(j, &col);
    }
    let mut mz = z.tr_mul(&hz);
    mz = (&mz + mz.transpose()) * 0.5;
    // Positive definite on Z (a strict local minimum has it; clamp otherwise).
    let e = mz.clone().symmetric_eigen();
    let floor = 1e-3;
    let vals = e.eigenvalues.map(|v| v.max(floor));
    let mz = &e.eigenvectors * DMatrix::from_diagonal(&vals) * e.eigenvectors.transpose();
    let zwz = z.tr_mul(&(&w * &z));
    let h = &w + &z * (mz - zwz) * z.transpose();
    let h = (&h + h.transpose()) * 0.5;
    (Some(h), used)
}

/// A basis `Z` (n × d, `Zᵀ W Z = I`, zero on the fixed variables) of the null space of the
/// free columns of `jac`; `None` if it is empty.
fn null_space(jac: &DMatrix<f64>, weights: &[f64], free: &[bool]) -> Option<DMatrix<f64>> {
    let n = weights.len();
    let idx: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
    let k = idx.len();
    let m = jac.nrows();
    if k <= m {
        return None;
    }
    // Null space of the free columns, in the scaled variables W^{1/2} a.
    let jf = DMatrix::from_fn(m, k, |r, c| jac[(r, idx[c])] / weights[idx[c]].sqrt());
    let g = jf.tr_mul(&jf);
    let eig = g.symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0f64, |x, v| x.max(v.abs()));
    let cols: Vec<usize> = (0..k)
        .filter(|&c| eig.eigenvalues[c].abs() <= 1e-10 * top)
        .collect();
    if cols.is_empty() {
        return None;
    }
    let mut z = DMatrix::zeros(n, cols.len());
    for (j, &c) in cols.iter().enumerate() {
        for (r, &i) in idx.iter().enumerate() {
            z[(i, j)] = eig.eigenvectors[(r, c)] / weights[i].sqrt();
        }
    }
    Some(z)
}

/// `m` with its eigenvalues raised to `floor` (positive definite).
fn floored(m: &DMatrix<f64>, floor: f64) -> DMatrix<f64> {
    let m = (m + m.transpose()) * 0.5;
    let e = m.symmetric_eigen();
    let vals = e.eigenvalues.map(|v| v.max(floor));
    &e.eigenvectors * DMatrix::from_diagonal(&vals) * e.eigenvectors.transpose()
}

/// Where [`probed_curvature`] probes: the iterate `a` (scaled actuation), its pose error
/// `e0`, the Jacobian `jac` of the poses and the multipliers `lambda` of the last QP.
#[derive(Clone, Copy)]
pub(super) struct ProbeSite<'a> {
    pub(super) a: &'a [f64],
    pub(super) e0: &'a DVector<f64>,
    pub(super) jac: &'a DMatrix<f64>,
    pub(super) lambda: &'a DVector<f64>,
}

/// The Hessian of the Lagrangian `½|a - c|²_W - λᵀ p(a)` on the span `S` of the range step
/// `v` (its part `W`-orthogonal to the null space, dropped when negligible) and the null
/// space `Z` of the free columns of `J`, from second differences of the poses alone
/// ([`Forward::probe`]): for unit directions `u`, `w` of `S`,
/// `λᵀ p''[u, u] = 2 λᵀ (p(a + h u) - p(a) - h J u) / h²` (`h` = [`PROBE_STEP`] relative, one
/// probe each; `p''[u, w]` by polarisation from one more probe at `a + h (u + w)`). That is
/// the part of the Hessian an SQP step uses — `Zᵀ H Z` and `Zᵀ H v` — so the step is
/// Newton's. Returns `base` corrected on `S` (`base + P (H_S - Sᵀ base S) Pᵀ`,
/// `Sᵀ P = I`, with `Zᵀ H Z` floored positive definite), or `W` corrected so if that is not
/// positive definite; `None` without probes, more than [`MAX_PROBE_DIRECTIONS`] directions,
/// a probe outside the bounds or failed. Also returns the probes used.
pub(super) fn probed_curvature<F: Forward + ?Sized>(
    forward: &mut F,
    p: &Program<'_>,
    at: &ProbeSite<'_>,
    free: &[bool],
    v: &[f64],
    base: &DMatrix<f64>,
) -> (Option<DMatrix<f64>>, usize) {
    let ProbeSite { a, e0, jac, lambda } = *at;
    let n = a.len();
    let bounds = &p.bounds;
    let Some(z) = null_space(jac, &bounds.weights, free) else {
        return (None, 0);
    };
    let d = z.ncols();
    let wt = &bounds.weights;
    let scale = 1.0 + p.scaled_norm(a);
    // The range part of v, W-orthogonal to Z, in unit W-norm (if not negligible).
    let mut vr = DVector::from_column_slice(v);
    let zw = z.tr_mul(&DVector::from_fn(n, |i, _| wt[i] * vr[i]));
    vr -= &z * zw;
    let vn = p.scaled_norm(vr.as_slice());
    let with_v = vn > 1e-12 * scale;
    let k = d + usize::from(with_v);
    if k > MAX_PROBE_DIRECTIONS {
        return (None, 0);
    }
    let mut s = DMatrix::zeros(n, k);
    if with_v {
        s.set_column(0, &(vr / vn));
    }
    for j in 0..d {
        s.set_column(k - d + j, &z.column(j));
    }
    let h = PROBE_STEP * scale;
    let mut used = 0;
    // The probe's actuation.
    let mut trial = vec![0.0; n];
    // λᵀ p''[u, u] along the direction u (scaled length 1 or √2), ±h inside the bounds.
    let mut second = |u: &DVector<f64>, used: &mut usize| -> Option<f64> {
        let inside = |t: f64| {
            (0..n).all(|i| {
                let x = a[i] + t * u[i];
                x >= bounds.lo[i] && x <= bounds.hi[i]
            })
        };
        let t = [h, -h].into_iter().find(|&t| inside(t))?;
        for i in 0..n {
            trial[i] = a[i] + t * u[i];
        }
        *used += 1;
        let ev = forward.probe(&trial).ok()?;
        if ev.positions.len() != p.target.points.len() || e0.len() != 3 * ev.positions.len() {
            return None;
        }
        // e = target - p: p(a + t u) - p(a) - t J u = -(e1 - e0) - t J u, dotted with λ.
        let mut ldp = 0.0;
        for (k, (target, pos)) in p.target.points.iter().zip(&ev.positions).enumerate() {
            for c in 0..3 {
                let r = 3 * k + c;
                let ju: f64 = (0..n).map(|i| jac[(r, i)] * u[i]).sum();
                let e1 = target[c] - pos[c];
                ldp += lambda[r] * (-(e1 - e0[r]) - ju * t);
            }
        }
        let q = 2.0 * ldp / (t * t);
        q.is_finite().then_some(q)
    };
    let mut lpp = DMatrix::zeros(k, k);
    for i in 0..k {
        let Some(q) = second(&s.column(i).into_owned(), &mut used) else {
            return (None, used);
        };
        lpp[(i, i)] = q;
    }
    for i in 0..k {
        for j in i + 1..k {
            let u = s.column(i) + s.column(j);
            let Some(q) = second(&u, &mut used) else {
                return (None, used);
            };
            let c = 0.5 * (q - lpp[(i, i)] - lpp[(j, j)]);
            lpp[(i, j)] = c;
            lpp[(j, i)] = c;
        }
    }
    let mut hs = s.tr_mul(&DMatrix::from_fn(n, k, |i, j| wt[i] * s[(i, j)])) - lpp;
    // Positive definite on Z (a strict local minimum has it; clamp otherwise).
    let zz = hs.view((k - d, k - d), (d, d)).into_owned();
    hs.view_mut((k - d, k - d), (d, d))
        .copy_from(&floored(&zz, 1e-3));
    let Some(sts) = s.tr_mul(&s).try_inverse() else {
        return (None, used);
    };
    let pm = &s * sts;
    let corrected = |b: &DMatrix<f64>| {
        let h = b + &pm * (&hs - s.tr_mul(&(b * &s))) * pm.transpose();
        (&h + h.transpose()) * 0.5
    };
    let h = corrected(base);
    if h.clone().cholesky().is_some() {
        return (Some(h), used);
    }
    let h = corrected(&DMatrix::from_diagonal(&DVector::from_column_slice(wt)));
    if h.clone().cholesky().is_some() {
        return (Some(h), used);
    }
    (None, used)
}

/// Change of the objective `½ Σ w_i (a_i − c_i)²` from `a` to `trial` (same length as `w`).
pub(crate) fn objective_change(w: &[f64], c: &[f64], a: &[f64], trial: &[f64]) -> f64 {
    (0..a.len())
        .map(|i| {
            let d = trial[i] - a[i];
            w[i] * d * (a[i] - c[i] + 0.5 * d)
        })
        .sum()
}

/// The trust radius after an accepted step of size `step_norm`: widened after a full
/// (unclipped) step; otherwise by the ratio of the achieved merit decrease `achieved` to the
/// `predicted` one (×4 above 0.75, halved step below 0.25).
pub(crate) fn trust_radius(
    radius: f64,
    full: bool,
    step_norm: f64,
    achieved: f64,
    predicted: f64,
) -> f64 {
    if full {
        return radius.max(2.0 * step_norm);
    }
    let ratio = if predicted > 0.0 {
        achieved / predicted
    } else {
        1.0
    };
    if ratio > 0.75 {
        4.0 * radius.max(step_norm)
    } else if ratio < 0.25 {
        0.5 * step_norm
    } else {
        radius
    }
}
