//! The two small quadratic programs of the inverse statics, solved exactly.
//!
//! * [`min_norm`]: the weighted minimum-norm point of a box that meets linear equalities,
//!   `min ½ Σ w_i (y_i - c_i)²` s.t. `A y = b`, `lo <= y <= hi`. Solved in the dual: for
//!   multipliers `λ` the minimiser over the box is separable, `y(λ) = clamp(c + W⁻¹ Aᵀ λ)`,
//!   and the concave, piecewise-quadratic dual is maximised by Newton's method on its gradient
//!   `b - A y(λ)` (generalised Hessian `A D W⁻¹ Aᵀ`, `D` the free variables) with a backtracking
//!   line search. It terminates when the free set is the optimal one: the last Newton step is
//!   exact, so the equalities hold to round-off. `None` if the equalities cannot be met inside
//!   the box (the dual grows without bound).
//! * [`bounded_least_squares`]: `min ½ |A y - b|² + ½ μ Σ w_i (y_i - c_i)²` s.t.
//!   `lo <= y <= hi` (`μ > 0` small: among the least-squares points, the one closest to `c`), by
//!   a primal active set on the bounds (exact, finite).
//!
//! `n` (variables) is the number of actuators and `m` (rows) at most a few: dense algebra.

use nalgebra::{DMatrix, DVector};

use crate::math::linalg::{cholesky_factor, cholesky_solve, DenseLu};

/// Most Newton iterations of the dual (each changes the free set or ends).
const MAX_DUAL_ITERATIONS: usize = 100;
/// Most active-set changes of the bounded least squares (per variable).
const MAX_ACTIVE_SET_CHANGES: usize = 10;

/// The box and the weighted centre of a QP.
#[derive(Debug, Clone)]
pub struct Bounds {
    /// Lower bounds (may be `-inf`).
    pub lo: Vec<f64>,
    /// Upper bounds (may be `+inf`).
    pub hi: Vec<f64>,
    /// Weights `w_i > 0`.
    pub weights: Vec<f64>,
    /// Centre `c` (the reference actuation).
    pub centre: Vec<f64>,
}

impl Bounds {
    fn clamp(&self, i: usize, v: f64) -> f64 {
        v.max(self.lo[i]).min(self.hi[i])
    }
}

/// `min ½ Σ w_i (y_i - c_i)²` s.t. `A y = b`, `lo <= y <= hi` (see the module documentation);
/// `tol` is the accepted max-norm of `A y - b`. Returns the minimiser and the multipliers `λ`
/// of the equalities (`W (y - c) = Aᵀ λ` on the free variables); `None` if infeasible.
pub fn min_norm(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    bx: &Bounds,
    tol: f64,
) -> Option<(DVector<f64>, DVector<f64>)> {
    min_norm_from(a, b, bx, tol, None)
}

/// [`min_norm`] with the dual iteration started from the multipliers `start` (one per row of
/// `a`; e.g. those of the previous program of an SQP iteration, near the new ones), else from
/// zero. The minimiser is the same (the dual is concave); only the iterations differ.
pub fn min_norm_from(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    bx: &Bounds,
    tol: f64,
    start: Option<&DVector<f64>>,
) -> Option<(DVector<f64>, DVector<f64>)> {
    let (m, n) = a.shape();
    let inv_w: Vec<f64> = bx.weights.iter().map(|w| 1.0 / w).collect();
    // y(λ) and its free set, written into `y`, `free` (`atl` scratch: Aᵀλ).
    let y_of = |lambda: &DVector<f64>,
                atl: &mut DVector<f64>,
                y: &mut DVector<f64>,
                free: &mut Vec<bool>| {
        a.tr_mul_to(lambda, atl);
        free.clear();
        for i in 0..n {
            let v = bx.centre[i] + inv_w[i] * atl[i];
            y[i] = bx.clamp(i, v);
            // At a kink the generalised derivative is taken as free.
            free.push(v >= bx.lo[i] && v <= bx.hi[i]);
        }
    };
    // The residual `b - A y` into `g`.
    let residual = |y: &DVector<f64>, g: &mut DVector<f64>| {
        a.mul_to(y, g);
        g.neg_mut();
        *g += b;
    };
    let dual = |lambda: &DVector<f64>, y: &DVector<f64>, g: &DVector<f64>| -> f64 {
        let mut f = 0.0;
        for i in 0..n {
            f += 0.5 * bx.weights[i] * (y[i] - bx.centre[i]).powi(2);
        }
        f + lambda.dot(g)
    };
    let mut lambda = match start {
        Some(l) if l.len() == m && l.iter().all(|v| v.is_finite()) => l.clone(),
        _ => DVector::zeros(m),
    };
    let mut atl = DVector::zeros(n);
    let (mut y, mut free) = (DVector::zeros(n), Vec::with_capacity(n));
    let (mut yt, mut ft) = (DVector::zeros(n), Vec::with_capacity(n));
    let (mut g, mut gt) = (DVector::zeros(m), DVector::zeros(m));
    let mut trial = DVector::zeros(m);
    let mut h = DMatrix::zeros(m, m);
    y_of(&lambda, &mut atl, &mut y, &mut free);
    residual(&y, &mut g);
    let mut psi = dual(&lambda, &y, &g);
    let scale = b.amax().max(1e-300);
    for _ in 0..MAX_DUAL_ITERATIONS {
        if g.amax() <= tol {
            return Some((y, lambda));
        }
        // Generalised Hessian A D W⁻¹ Aᵀ (regularised against a rank-deficient free set).
        h.fill(0.0);
        for i in 0..n {
            if free[i] {
                for c in 0..m {
                    let ac = a[(c, i)] * inv_w[i];
                    for r in 0..m {
                        h[(r, c)] += a[(r, i)] * ac;
                    }
                }
            }
        }
        let trace = h.trace();
        let reg = if trace > 0.0 {
            1e-14 * trace
        } else {
            // Nothing free: a gradient step on the dual.
            a.iter().fold(0.0f64, |m, v| m.max(v * v))
                / inv_w
                    .iter()
                    .fold(f64::INFINITY, |m, v| m.min(1.0 / v))
                    .max(1e-300)
        };
        for k in 0..m {
            h[(k, k)] += reg.max(1e-300);
        }
        let d = h.clone().cholesky()?.solve(&g);
        let slope = g.dot(&d);
        let gmax = g.amax();
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..60 {
            trial.copy_from(&lambda);
            trial.axpy(alpha, &d, 1.0);
            y_of(&trial, &mut atl, &mut yt, &mut ft);
            residual(&yt, &mut gt);
            let pt = dual(&trial, &yt, &gt);
            // On an unchanged free set the dual is a concave quadratic and the step a
            // (regularised) Newton step: a smaller residual is progress even where the dual's
            // value is lost in round-off (large multipliers of a nearly singular target).
            let same_free = ft == free && gt.amax() < gmax;
            if pt >= psi + 1e-4 * alpha * slope
                || (pt - psi).abs() <= 1e-15 * psi.abs()
                || same_free
            {
                std::mem::swap(&mut lambda, &mut trial);
                std::mem::swap(&mut y, &mut yt);
                std::mem::swap(&mut free, &mut ft);
                std::mem::swap(&mut g, &mut gt);
                psi = pt;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted || lambda.amax() > 1e30 * (1.0 + scale) {
            break;
        }
    }
    (g.amax() <= tol).then_some((y, lambda))
}

/// `min ½ yᵀ H y + qᵀ y` s.t. `A y = b`, `lo <= y <= hi` with `H` symmetric positive definite,
/// from the feasible point `y0`, by a primal active set on the bounds (each working set's
/// equality-constrained problem solved through its KKT system). Returns the minimiser and the
/// multipliers `λ` of the equalities (`H y + q = Aᵀ λ + bound multipliers`); `None` if a KKT
/// system is singular.
pub fn active_set_qp(
    h: &DMatrix<f64>,
    q: &DVector<f64>,
    a: &DMatrix<f64>,
    bx: &Bounds,
    y0: &DVector<f64>,
) -> Option<(DVector<f64>, DVector<f64>)> {
    let (m, n) = a.shape();
    let mut y = y0.clone();
    let mut fixed: Vec<bool> = (0..n)
        .map(|i| y[i] <= bx.lo[i] || y[i] >= bx.hi[i])
        .collect();
    // The vectors of every working set, allocated once.
    let mut free: Vec<usize> = Vec::with_capacity(n);
    let (mut grad, mut p) = (vec![0.0; n], vec![0.0; n]);
    let (mut kkt, mut rhs) = (
        Vec::with_capacity((n + m) * (n + m)),
        Vec::with_capacity(n + m),
    );
    let mut lu = DenseLu::default();
    let mut lambda = DVector::zeros(m);
    let gradient = |y: &DVector<f64>, grad: &mut [f64]| {
        for (i, g) in grad.iter_mut().enumerate() {
            *g = q[i] + (0..n).map(|j| h[(i, j)] * y[j]).sum::<f64>();
        }
    };
    for _ in 0..MAX_ACTIVE_SET_CHANGES * (n + 1) {
        free.clear();
        free.extend((0..n).filter(|&i| !fixed[i]));
        let k = free.len();
        let size = k + m;
        // KKT: [H_FF  A_Fᵀ; A_F 0] [p_F; -λ] = [-(H y + q)_F; 0], column-major.
        gradient(&y, &mut grad);
        kkt.clear();
        kkt.resize(size * size, 0.0);
        rhs.clear();
        rhs.resize(size, 0.0);
        for (r, &i) in free.iter().enumerate() {
            rhs[r] = -grad[i];
            for (c, &j) in free.iter().enumerate() {
                kkt[r + c * size] = h[(i, j)];
            }
            for e in 0..m {
                kkt[r + (k + e) * size] = a[(e, i)];
                kkt[k + e + r * size] = a[(e, i)];
            }
        }
        if !lu.factor(size, &kkt) || !lu.solve_in_place(&mut rhs) {
            return None;
        }
        for e in 0..m {
            lambda[e] = -rhs[k + e];
        }
        p.iter_mut().for_each(|v| *v = 0.0);
        for (r, &i) in free.iter().enumerate() {
            p[i] = rhs[r];
        }
        let scale = 1.0 + y.amax();
        let mut at_minimum = p.iter().all(|v| v.abs() <= 1e-14 * scale);
        if !at_minimum {
            let mut t = 1.0;
            let mut blocking = None;
            for &i in &free {
                if p[i] < 0.0 && y[i] + p[i] < bx.lo[i] {
                    let ti = (bx.lo[i] - y[i]) / p[i];
                    if ti < t {
                        t = ti;
                        blocking = Some((i, bx.lo[i]));
                    }
                } else if p[i] > 0.0 && y[i] + p[i] > bx.hi[i] {
                    let ti = (bx.hi[i] - y[i]) / p[i];
                    if ti < t {
                        t = ti;
                        blocking = Some((i, bx.hi[i]));
                    }
                }
            }
            let t = t.max(0.0);
            for i in 0..n {
                y[i] += p[i] * t;
            }
            match blocking {
                Some((i, v)) => {
                    y[i] = v;
                    fixed[i] = true;
                }
                // The full step: the minimiser on this face (its multipliers are `lambda`).
                None => at_minimum = true,
            }
        }
        if at_minimum {
            gradient(&y, &mut grad);
            // Bound multipliers μ = H y + q - Aᵀ λ: >= 0 at a lower bound, <= 0 at an upper.
            let gscale = 1e-12 * (1.0 + grad.iter().fold(0.0f64, |g, v| g.max(v.abs())));
            let mut worst: Option<(usize, f64)> = None;
            for i in (0..n).filter(|&i| fixed[i]) {
                let mu = grad[i] - (0..m).map(|e| a[(e, i)] * lambda[e]).sum::<f64>();
                let wrong = if y[i] <= bx.lo[i] { -mu } else { mu };
                if wrong > gscale && worst.is_none_or(|(_, w)| wrong > w) {
                    worst = Some((i, wrong));
                }
            }
            match worst {
                Some((i, _)) => fixed[i] = false,
                None => return Some((y, lambda)),
            }
        }
    }
    None
}

/// `min ½ |A y - b|² + ½ μ Σ w_i (y_i - c_i)²` s.t. `lo <= y <= hi` (see the module
/// documentation).
pub fn bounded_least_squares(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    bx: &Bounds,
    mu: f64,
) -> DVector<f64> {
    NormalEquations::new(a, b).solve(bx, mu, &mut BlsWork::default())
}

/// The normal equations `AᵀA`, `-Aᵀb` of a bounded least squares, made once for several
/// regularisations `μ` (the Levenberg–Marquardt search of `steps.rs`).
pub(crate) struct NormalEquations {
    ata: DMatrix<f64>,
    atb: DVector<f64>,
}

/// The scratch of [`NormalEquations::solve`], reused across calls (no allocation once sized).
#[derive(Default)]
pub(crate) struct BlsWork {
    q: Vec<f64>,
    c: Vec<f64>,
    target: Vec<f64>,
    free: Vec<usize>,
    fixed: Vec<Option<f64>>,
    qf: Vec<f64>,
    chol: Vec<f64>,
    rhs: Vec<f64>,
    grad: Vec<f64>,
}

impl NormalEquations {
    /// The normal equations of `|A y - b|²`.
    pub(crate) fn new(a: &DMatrix<f64>, b: &DVector<f64>) -> Self {
        Self {
            ata: a.tr_mul(a),
            atb: -a.tr_mul(b),
        }
    }

    /// The bounded least squares with the regularisation `μ` (as [`bounded_least_squares`]).
    pub(crate) fn solve(&self, bx: &Bounds, mu: f64, ws: &mut BlsWork) -> DVector<f64> {
        let n = self.ata.ncols();
        ws.q.clear();
        ws.q.extend_from_slice(self.ata.as_slice());
        ws.c.clear();
        ws.c.extend_from_slice(self.atb.as_slice());
        // Column-major n × n: q[(i, j)] = q[i + n j].
        let (q, c) = (&mut ws.q, &mut ws.c);
        for i in 0..n {
            q[i + n * i] += mu * bx.weights[i];
            c[i] -= mu * bx.weights[i] * bx.centre[i];
        }
        // Start from the centre, clamped; `fixed[i]` = Some(bound) holds y_i at a bound.
        let mut y = DVector::from_fn(n, |i, _| bx.clamp(i, bx.centre[i]));
        ws.fixed.clear();
        ws.fixed
            .extend((0..n).map(|i| (y[i] == bx.lo[i] || y[i] == bx.hi[i]).then_some(y[i])));
        for _ in 0..MAX_ACTIVE_SET_CHANGES * (n + 1) {
            ws.free.clear();
            ws.free.extend((0..n).filter(|&i| ws.fixed[i].is_none()));
            let (free, fixed) = (&ws.free, &ws.fixed);
            // The minimiser over the free variables with the others fixed.
            ws.target.clear();
            ws.target.extend_from_slice(y.as_slice());
            if !free.is_empty() {
                let k = free.len();
                ws.qf.clear();
                ws.qf.resize(k * k, 0.0);
                ws.rhs.clear();
                ws.rhs.resize(k, 0.0);
                for (r, &i) in free.iter().enumerate() {
                    ws.rhs[r] = -c[i];
                    for (s, &j) in free.iter().enumerate() {
                        ws.qf[r * k + s] = q[i + n * j];
                    }
                    for j in 0..n {
                        if let Some(v) = fixed[j] {
                            ws.rhs[r] -= q[i + n * j] * v;
                        }
                    }
                }
                if !(cholesky_factor(&ws.qf, k, 0.0, &mut ws.chol)
                    && cholesky_solve(&ws.chol, k, &mut ws.rhs))
                {
                    return y;
                }
                for (r, &i) in free.iter().enumerate() {
                    ws.target[i] = ws.rhs[r];
                }
            }
            let target = &ws.target;
            // Step toward it until a bound is hit.
            let mut t = 1.0;
            let mut blocking = None;
            for &i in free {
                let d = target[i] - y[i];
                if d < 0.0 && target[i] < bx.lo[i] {
                    let ti = (bx.lo[i] - y[i]) / d;
                    if ti < t {
                        t = ti;
                        blocking = Some((i, bx.lo[i]));
                    }
                } else if d > 0.0 && target[i] > bx.hi[i] {
                    let ti = (bx.hi[i] - y[i]) / d;
                    if ti < t {
                        t = ti;
                        blocking = Some((i, bx.hi[i]));
                    }
                }
            }
            for &i in free {
                y[i] += t.max(0.0) * (target[i] - y[i]);
            }
            if let Some((i, v)) = blocking {
                y[i] = v;
                ws.fixed[i] = Some(v);
                continue;
            }
            // Optimal on this face: release a fixed variable whose gradient points inward.
            ws.grad.clear();
            ws.grad
                .extend((0..n).map(|i| (0..n).map(|j| q[i + n * j] * y[j]).sum::<f64>() + c[i]));
            let grad = &ws.grad;
            let gmax = grad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut worst: Option<(usize, f64)> = None;
            for i in 0..n {
                if let Some(v) = ws.fixed[i] {
                    let inward = if v == bx.lo[i] { -grad[i] } else { grad[i] };
                    if inward > 1e-14 * (1.0 + gmax) && worst.is_none_or(|(_, w)| inward > w) {
                        worst = Some((i, inward));
                    }
                }
            }
            match worst {
                Some((i, _)) => ws.fixed[i] = None,
                None => return y,
            }
        }
        y
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A tiny deterministic generator (no dependency).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64) / ((1u64 << 53) as f64)
        }
    }

    /// Every face of an `n`-dimensional box, as per variable `0` (free), `1` (at its lower
    /// bound) or `2` (at its upper bound): the `3ⁿ` cases of the brute-force references.
    fn faces(n: usize) -> impl Iterator<Item = Vec<u8>> {
        (0..3usize.pow(n as u32)).map(move |code| {
            let mut state = vec![0u8; n];
            let mut c = code;
            for s in state.iter_mut() {
                *s = (c % 3) as u8;
                c /= 3;
            }
            state
        })
    }

    /// Brute force: every subset of bounds fixed at lower/upper/free, solving the KKT system of
    /// each and keeping the best feasible point.
    fn brute_min_norm(a: &DMatrix<f64>, b: &DVector<f64>, bx: &Bounds) -> Option<DVector<f64>> {
        let (m, n) = a.shape();
        let mut best: Option<(f64, DVector<f64>)> = None;
        for state in faces(n) {
            let free: Vec<usize> = (0..n).filter(|&i| state[i] == 0).collect();
            let mut y = DVector::zeros(n);
            let mut ok = true;
            for i in 0..n {
                match state[i] {
                    1 => y[i] = bx.lo[i],
                    2 => y[i] = bx.hi[i],
                    _ => {}
                }
                if !y[i].is_finite() {
                    ok = false;
                }
            }
            if !ok {
                continue;
            }
            // KKT of the free variables: W_F y_F - A_Fᵀ λ = W_F c_F, A_F y_F = b - A_B y_B.
            let k = free.len();
            let mut kkt = DMatrix::zeros(k + m, k + m);
            let mut rhs = DVector::zeros(k + m);
            for (r, &i) in free.iter().enumerate() {
                kkt[(r, r)] = bx.weights[i];
                rhs[r] = bx.weights[i] * bx.centre[i];
                for j in 0..m {
                    kkt[(r, k + j)] = -a[(j, i)];
                    kkt[(k + j, r)] = a[(j, i)];
                }
            }
            for j in 0..m {
                rhs[k + j] = b[j];
                for i in 0..n {
                    if state[i] != 0 {
                        rhs[k + j] -= a[(j, i)] * y[i];
                    }
                }
            }
            let Some(sol) = kkt.lu().solve(&rhs) else {
                continue;
            };
            for (r, &i) in free.iter().enumerate() {
                y[i] = sol[r];
            }
            let feasible = (0..n).all(|i| y[i] >= bx.lo[i] - 1e-12 && y[i] <= bx.hi[i] + 1e-12)
                && (a * &y - b).amax() <= 1e-9;
            if feasible {
                let f: f64 = (0..n)
                    .map(|i| bx.weights[i] * (y[i] - bx.centre[i]).powi(2))
                    .sum();
                if best.as_ref().is_none_or(|(bf, _)| f < *bf) {
                    best = Some((f, y));
                }
            }
        }
        best.map(|(_, y)| y)
    }

    fn random_problem(g: &mut Lcg, m: usize, n: usize) -> (DMatrix<f64>, DVector<f64>, Bounds) {
        let a = DMatrix::from_fn(m, n, |_, _| g.next() * 2.0 - 1.0);
        let y0 = DVector::from_fn(n, |_, _| g.next() * 2.0);
        let b = &a * &y0;
        let bx = Bounds {
            lo: vec![0.0; n],
            hi: (0..n)
                .map(|_| if g.next() < 0.3 { 1.5 } else { f64::INFINITY })
                .collect(),
            weights: (0..n).map(|_| 0.5 + g.next()).collect(),
            centre: (0..n)
                .map(|_| if g.next() < 0.5 { 0.0 } else { g.next() })
                .collect(),
        };
        (a, b, bx)
    }

    #[test]
    fn min_norm_matches_brute_force_on_small_problems() {
        let mut g = Lcg(7);
        let mut solved = 0;
        for trial in 0..300 {
            let (m, n) = (1 + trial % 3, 3 + trial % 4);
            let (a, b, bx) = random_problem(&mut g, m, n);
            let brute = brute_min_norm(&a, &b, &bx);
            let fast = min_norm(&a, &b, &bx, 1e-12).map(|(y, _)| y);
            match (brute, fast) {
                (Some(x), Some(y)) => {
                    assert!(
                        (&x - &y).amax() <= 1e-9 * (1.0 + x.amax()),
                        "{trial}: {x} vs {y}"
                    );
                    solved += 1;
                }
                (None, None) => {}
                (x, y) => panic!("trial {trial}: brute {x:?} vs dual {y:?}"),
            }
        }
        assert!(solved > 150, "{solved}");
    }

    #[test]
    fn active_set_qp_matches_min_norm_with_a_diagonal_hessian_and_improves_a_general_one() {
        let mut g = Lcg(17);
        for trial in 0..200 {
            let (m, n) = (1 + trial % 3, 3 + trial % 4);
            let (a, b, bx) = random_problem(&mut g, m, n);
            let Some((y, lambda)) = min_norm(&a, &b, &bx, 1e-12) else {
                continue;
            };
            let w = DMatrix::from_diagonal(&DVector::from_column_slice(&bx.weights));
            let c = DVector::from_column_slice(&bx.centre);
            let q = -(&w * &c);
            // From a feasible point away from the optimum: the brute-force minimiser.
            let y0 = brute_min_norm(&a, &b, &bx).unwrap();
            let (z, mu) = active_set_qp(&w, &q, &a, &bx, &y0).unwrap();
            assert!((&z - &y).amax() <= 1e-9 * (1.0 + y.amax()), "{trial}");
            assert!(
                (&mu - &lambda).amax() <= 1e-6 * (1.0 + lambda.amax()),
                "{trial}: {mu} {lambda}"
            );
            // A general SPD Hessian: the result is feasible and no worse than y.
            let r = DMatrix::from_fn(n, n, |_, _| g.next() - 0.5);
            let h = &w + &r * r.transpose();
            let f = |v: &DVector<f64>| 0.5 * v.dot(&(&h * v)) + q.dot(v);
            let (z, _) = active_set_qp(&h, &q, &a, &bx, &y).unwrap();
            assert!((&a * &z - &b).amax() <= 1e-9);
            assert!((0..n).all(|i| z[i] >= bx.lo[i] - 1e-12 && z[i] <= bx.hi[i] + 1e-12));
            assert!(f(&z) <= f(&y) + 1e-12 * f(&y).abs());
        }
    }

    #[test]
    fn min_norm_reports_an_infeasible_box() {
        // y0 + y1 = -1 with y >= 0.
        let a = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
        let b = DVector::from_element(1, -1.0);
        let bx = Bounds {
            lo: vec![0.0; 2],
            hi: vec![f64::INFINITY; 2],
            weights: vec![1.0; 2],
            centre: vec![0.0; 2],
        };
        assert!(min_norm(&a, &b, &bx, 1e-12).is_none());
    }

    /// Brute force of the bounded least squares: every face.
    fn brute_bls(a: &DMatrix<f64>, b: &DVector<f64>, bx: &Bounds, mu: f64) -> DVector<f64> {
        let n = a.ncols();
        let f = |y: &DVector<f64>| {
            0.5 * (a * y - b).norm_squared()
                + 0.5
                    * mu
                    * (0..n)
                        .map(|i| bx.weights[i] * (y[i] - bx.centre[i]).powi(2))
                        .sum::<f64>()
        };
        let mut best: Option<(f64, DVector<f64>)> = None;
        for state in faces(n) {
            let mut y = DVector::zeros(n);
            if (0..n).any(|i| state[i] == 2 && !bx.hi[i].is_finite()) {
                continue;
            }
            for i in 0..n {
                y[i] = match state[i] {
                    1 => bx.lo[i],
                    2 => bx.hi[i],
                    _ => 0.0,
                };
            }
            let free: Vec<usize> = (0..n).filter(|&i| state[i] == 0).collect();
            if !free.is_empty() {
                let q = a.tr_mul(a);
                let k = free.len();
                let mut qf = DMatrix::zeros(k, k);
                let mut rhs = DVector::zeros(k);
                let atb = a.tr_mul(b);
                for (r, &i) in free.iter().enumerate() {
                    rhs[r] = atb[i] + mu * bx.weights[i] * bx.centre[i];
                    for (s, &j) in free.iter().enumerate() {
                        qf[(r, s)] = q[(i, j)] + if i == j { mu * bx.weights[i] } else { 0.0 };
                    }
                    for j in 0..n {
                        if state[j] != 0 {
                            rhs[r] -= q[(i, j)] * y[j];
                        }
                    }
                }
                let sol = qf.cholesky().unwrap().solve(&rhs);
                for (r, &i) in free.iter().enumerate() {
                    y[i] = sol[r];
                }
            }
            if (0..n).all(|i| y[i] >= bx.lo[i] - 1e-12 && y[i] <= bx.hi[i] + 1e-12) {
                let v = f(&y);
                if best.as_ref().is_none_or(|(bv, _)| v < *bv) {
                    best = Some((v, y));
                }
            }
        }
        best.unwrap().1
    }

    #[test]
    fn bounded_least_squares_matches_brute_force() {
        let mut g = Lcg(11);
        for trial in 0..300 {
            let (m, n) = (1 + trial % 4, 2 + trial % 4);
            let (a, mut b, bx) = random_problem(&mut g, m, n);
            // Targets outside the reachable set too.
            for k in 0..m {
                b[k] += (g.next() - 0.5) * 6.0;
            }
            let mu = 1e-6;
            let brute = brute_bls(&a, &b, &bx, mu);
            let fast = bounded_least_squares(&a, &b, &bx, mu);
            assert!(
                (&brute - &fast).amax() <= 1e-7 * (1.0 + brute.amax()),
                "{trial}: {brute} vs {fast}"
            );
        }
    }
}
