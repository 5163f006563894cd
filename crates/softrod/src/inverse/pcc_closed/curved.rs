//! The curved step: the null space of the free constraint columns, the Hessian made positive
//! definite on it, and the step by the KKT systems of its working sets.

use nalgebra::{DMatrix, Matrix3 as M3, Vector3 as V3};

use super::chain::{lagrangian_times, Affine};
use super::dual::Box_;
use super::{CURVATURE_FLOOR, CURVED_ACTIVE_SET_CHANGES};
use crate::math::linalg::{cholesky_factor, cholesky_solve, DenseLu};

/// The scratch of [`convexify`].
#[derive(Default)]
pub(super) struct ConvexWork {
    /// The free variables.
    pub(super) idx: Vec<usize>,
    /// The scaled free columns `J_i / √w_i`, and one range vector.
    pub(super) cols: Vec<V3<f64>>,
    pub(super) range: Vec<f64>,
    /// The projector on the null space (k × k), then what is left of it.
    pub(super) proj: Vec<f64>,
    /// The null-space basis (n × d, column-major, `Zᵀ W Z = I`).
    pub(super) z: Vec<f64>,
    /// `H Z` (n × d, column-major).
    pub(super) hz: Vec<f64>,
    /// `Zᵀ H Z` (d × d), then its Cholesky factor.
    pub(super) zhz: Vec<f64>,
    pub(super) chol: Vec<f64>,
}

/// `ws.proj -= Σ v vᵀ` over the orthonormal range vectors `v = A_Fᵀ u / √σ` of the
/// eigenpairs `(σ, u)` of `G = A_F A_Fᵀ` above `1e-10` of the largest; returns their number.
pub(super) fn range_projector(g: &M3<f64>, ws: &mut ConvexWork) -> usize {
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
pub(super) fn null_space(jac: &[V3<f64>], bx: &Box_, ws: &mut ConvexWork) -> usize {
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

/// The Hessian `h` (n × n, row-major) made positive definite on the null space `Z` of the
/// free columns of `J` (those free in `y_w`, scaled variables `W^{1/2} a`): kept exact when
/// `Zᵀ h Z` has its eigenvalues above [`CURVATURE_FLOOR`] (the cross terms `Zᵀ h Y` make the
/// curved step Newton's), otherwise only `Zᵀ h Z` raised to that floor, so that the curved
/// step is a descent step toward a minimum, never a saddle. Without a null space: `W` (the
/// step is then the constraints' alone, the minimum-norm step), and `false`.
pub(super) fn convexify(
    h: &mut [f64],
    jac: &[V3<f64>],
    y_w: &[f64],
    bx: &Box_,
    ws: &mut ConvexWork,
) -> bool {
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
    if cholesky_factor(&ws.zhz, d, CURVATURE_FLOOR, &mut ws.chol) {
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
pub(super) enum Reduced {
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
pub(super) struct ReducedWork {
    /// The step.
    pub(super) d: Vec<f64>,
    /// `H' d_r`, then the gradient `H' d + W (a - c)`.
    pub(super) hd: Vec<f64>,
    /// `H Z` (n × dim Z, column-major).
    pub(super) hz: Vec<f64>,
    /// `Zᵀ H' Z`, its raise `Δ` and Cholesky factor (dim Z × dim Z).
    pub(super) m: Vec<f64>,
    pub(super) delta: Vec<f64>,
    pub(super) chol: Vec<f64>,
    /// `t`, `Z t`, and the scratch of the raise.
    pub(super) t: Vec<f64>,
    pub(super) zt: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) prod: (Vec<f64>, Vec<f64>),
}

/// The curved step on the face of the minimum-norm point `y_w` by the null-space method:
/// `d = d_r + Z t`, `d_r = y_w - a`, `t = -(Zᵀ H' Z)⁻¹ Zᵀ (H' d_r + W (a - c))`, `H'` the Hessian
/// of the Lagrangian `W - Mᵀ H_θ M` (`H_θ` = `theta`) with `Zᵀ H Z` raised to
/// [`CURVATURE_FLOOR`] as [`convexify`] raises it, applied to the `1 + dim Z` vectors it
/// meets rather than formed. It is the first face of [`curved_step`]'s active set, and that
/// step when it stays in the box and the multipliers of the bounds have their signs
/// ([`Reduced::Step`]).
pub(super) fn reduced_step(
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
    if !(cholesky_factor(&ws.m, dz, 0.0, &mut ws.chol) && cholesky_solve(&ws.chol, dz, &mut ws.t)) {
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
pub(super) fn reduced_hessian(
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
    if !cholesky_factor(&ws.m, dz, CURVATURE_FLOOR, &mut ws.chol) {
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
pub(super) fn bounds_hold(
    jac: &[V3<f64>],
    bx: &Box_,
    (free, y_w): (&[usize], &[f64]),
    grad: &[f64],
) -> bool {
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
pub(super) struct CurvedWork {
    pub(super) grad: Vec<f64>,
    pub(super) p: Vec<f64>,
    pub(super) fixed: Vec<bool>,
    pub(super) free: Vec<usize>,
    pub(super) kkt: Vec<f64>,
    pub(super) rhs: Vec<f64>,
    pub(super) lu: DenseLu,
}

impl CurvedWork {
    /// `grad = H d + W (a - c)`; returns its largest magnitude.
    pub(super) fn gradient(&mut self, h: &[f64], a: &[f64], d: &[f64], bx: &Box_) -> f64 {
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
    pub(super) fn face(&mut self, h: &[f64], jac: &[V3<f64>]) -> Option<V3<f64>> {
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
pub(super) fn curved_step(
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
