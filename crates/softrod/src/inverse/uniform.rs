//! The RK4 march of an unloaded robot whose intervals are uniform, in closed form: the tip
//! pose and its exact actuation Jacobian without integrating the state stage by stage.
//!
//! Without external loads the total internal wrench `(N, M)` is zero all along the rod, so
//! the constitutive local solve of every stage has the same input. On an interval where the
//! section, the material (linear), the rest strains and the tendon offsets do not depend on
//! `s`, its solution — the strains `(v, u)`, the tangent `T = (I + C D)⁻¹ C` and the tendon
//! directions `(t_i, r_i × t_i)` — is the same at every stage. An RK4 step of
//! `p' = R v`, `R' = R û` with constant strains is then, exactly,
//!
//! ```text
//! R_{k+1} = proj(R_k P),   P = I + X + X²/2 + X³/6 + X⁴/24,   X = h û,
//! p_{k+1} = p_k + R_k q,   q = h (I + X/2 + X²/6 + X³/24) v,
//! ```
//!
//! with `proj(A) = A (3I - AᵀA)/2` the march's re-orthonormalisation, and since
//! `proj(R_k P) = R_k proj(P)` for an orthonormal `R_k`, the march is the repeated
//! multiplication by one rigid step `G = (Q, q)`, `Q = proj(P)`: `g_{k+1} = g_k G`. The
//! derivative of this map along the tension of tendon `i` is that of the march (the same
//! discrete equations, not a different discretisation): `δ(v, u) = -T (t_i, r_i × t_i)` where
//! the tendon passes (zero elsewhere), `δG = (δQ, δq)` from the derivatives of `P`, `q` and
//! `proj`, and
//!
//! ```text
//! δR_{k+1} = δR_k Q + R_k δQ,   δp_{k+1} = δp_k + δR_k q + R_k δq.
//! ```
//!
//! About 0.1 M instructions for the tip pose and six columns, against 1.3 M for the march
//! with its columns (`docs/command.md`); the tip pose agrees with the march to round-off
//! (tested in `tests/inverse.rs` against the forward solve and its actuation Jacobian).

use nalgebra::{DMatrix, Matrix3, Vector3, Vector6};

use super::Evaluation;
use crate::cosserat::equations::{rotation_variation, Equations, Evaluator, Workspace};
use crate::cosserat::statics::Integrator;
use crate::integrate::march::rk4_plan;
use crate::math::so3::{hat, reorthonormalise};
use crate::model::tendon::Routing;
use crate::model::RobotModel;

/// Whether the march of `model` (unloaded, checked by the caller) with `integrator` has the
/// closed form of this module: RK4, a uniform linear-elastic rod with constant rest strains,
/// no chambers, tendons at constant offsets without friction or guides.
pub(super) fn applies(model: &RobotModel, integrator: &Integrator) -> bool {
    matches!(integrator, Integrator::Rk4 { .. })
        && model.uniform_along()
        && model
            .tendons()
            .iter()
            .all(|t| matches!(t.routing(), Routing::Constant(_)) && t.friction() == 0.0)
}

/// `X^k` for `k = 1..4` of `X = h û`.
fn powers(x: &Matrix3<f64>) -> [Matrix3<f64>; 4] {
    let x2 = x * x;
    let x3 = x2 * x;
    [*x, x2, x3, x3 * x]
}

/// The step polynomials `P(X)` and `S(X) = I + X/2 + X²/6 + X³/24` (so that `q = h S v`).
fn step_polynomials(xp: &[Matrix3<f64>; 4]) -> (Matrix3<f64>, Matrix3<f64>) {
    let i = Matrix3::identity();
    let p = i + xp[0] + xp[1] / 2.0 + xp[2] / 6.0 + xp[3] / 24.0;
    let s = i + xp[0] / 2.0 + xp[1] / 6.0 + xp[2] / 24.0;
    (p, s)
}

/// The derivatives `(δP, δS)` of the step polynomials along `δX`.
fn step_derivatives(xp: &[Matrix3<f64>; 4], dx: &Matrix3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let (x, x2, x3) = (&xp[0], &xp[1], &xp[2]);
    let d2 = dx * x + x * dx;
    let d3 = dx * x2 + x * dx * x + x2 * dx;
    let d4 = dx * x3 + x * dx * x2 + x2 * dx * x + x3 * dx;
    let dp = dx + d2 / 2.0 + d3 / 6.0 + d4 / 24.0;
    let ds = dx / 2.0 + d2 / 6.0 + d3 / 24.0;
    (dp, ds)
}

/// The derivative of the re-orthonormalisation `A (3I - AᵀA)/2` at `A` along `δA`.
fn projection_derivative(a: &Matrix3<f64>, da: &Matrix3<f64>) -> Matrix3<f64> {
    let half = Matrix3::identity() * 1.5 - a.tr_mul(a) * 0.5;
    let sym = da.tr_mul(a);
    da * half - a * (sym + sym.transpose()) * 0.5
}

/// One interval of the closed-form march: the rigid step `(Q, q)`, its steps and, per
/// column, the step's derivative `(δQ, δq)` and whether the tendon passes the interval (a
/// tendon that does not forces nothing there).
struct Interval {
    q_rot: Matrix3<f64>,
    q_pos: Vector3<f64>,
    steps: usize,
    columns: Vec<(Matrix3<f64>, Vector3<f64>)>,
    passes: Vec<bool>,
}

/// The interval `k` of the march of `model` at the tensions `a` (N) in `steps` RK4 steps,
/// with the columns of every tension if `jacobian`; `None` if its local solve fails.
fn interval(
    ev: &mut Evaluator<'_, '_>,
    k: usize,
    steps: usize,
    jacobian: bool,
) -> Option<Interval> {
    let model = ev.eq.model;
    let breaks = model.breaks();
    let (lo, hi) = (breaks[k], breaks[k + 1]);
    ev.set_interval(k);
    let props = model.rod().section_at(lo);
    let zero = Vector3::zeros();
    let loc = ev.local(lo, &props, &zero, &zero, jacobian);
    let (v, u) = (loc.v, loc.u);
    if !(v.iter().chain(u.iter()).all(|x| x.is_finite())) {
        return None;
    }
    let h = (hi - lo) / steps.max(1) as f64;
    let x = hat(&(u * h));
    let xp = powers(&x);
    let (p, s) = step_polynomials(&xp);
    let q_rot = reorthonormalise(&p);
    let q_pos = s * v * h;
    let mut columns = Vec::new();
    let mut passes = Vec::new();
    if jacobian {
        let tangent = ev.ws.tangent;
        let ends = model.tendon_ends();
        // The step's derivative along each unit strain (v, u), then per tension.
        // (A stretch or shear strain moves q alone: δq = h S δv.)
        let basis: Vec<(Matrix3<f64>, Vector3<f64>)> = (0..6)
            .map(|j| {
                if j < 3 {
                    return (Matrix3::zeros(), s.column(j) * h);
                }
                let du = Vector3::ith(j - 3, h);
                let (dp, ds) = step_derivatives(&xp, &hat(&du));
                (projection_derivative(&p, &dp), ds * v * h)
            })
            .collect();
        for (i, &end) in ends.iter().enumerate() {
            passes.push(end >= hi);
            if end < hi {
                columns.push((Matrix3::zeros(), Vector3::zeros()));
                continue;
            }
            let f: [f64; 6] = ev.tendon_direction(i, lo, &props, &v, &u).into();
            let d = tangent.apply(&f.map(|x| -x));
            let mut dq = Matrix3::zeros();
            let mut dqp = Vector3::zeros();
            for (j, (bq, bp)) in basis.iter().enumerate() {
                dq += bq * d[j];
                dqp += bp * d[j];
            }
            columns.push((dq, dqp));
        }
    }
    Some(Interval {
        q_rot,
        q_pos,
        steps,
        columns,
        passes,
    })
}

/// The estimated tip error of the RK4 march of the unloaded `model` at the tensions `a` (N)
/// on `integrator` ([`applies`]), relative to the length: on each interval the strains are
/// those of every stage, so [`rk4_position_error`](crate::cosserat::mesh::rk4_position_error)'s
/// sum `Σ θ⁵/120 (L - s)/L` over its `n` steps from `s₀` with `θ = h |u|` is
/// `θ⁵/120 (n (L - s₀) - h n (n - 1)/2)/L`. `None` if a local solve fails.
pub(super) fn position_error(
    model: &RobotModel,
    integrator: &Integrator,
    a: &[f64],
    ws: &mut Workspace,
) -> Option<f64> {
    let Integrator::Rk4 { steps } = *integrator else {
        return None;
    };
    let plan = rk4_plan(model.breaks(), steps);
    let eq = Equations::new(model, a, &[]);
    ws.renew(model.tendons().len());
    let mut ev = Evaluator { eq, ws };
    let (breaks, length) = (model.breaks(), model.length());
    let zero = Vector3::zeros();
    let mut error = 0.0;
    for (k, &n) in plan.iter().enumerate() {
        let lo = breaks[k];
        ev.set_interval(k);
        let props = model.rod().section_at(lo);
        let u = ev.local(lo, &props, &zero, &zero, false).u;
        let h = (breaks[k + 1] - lo) / n.max(1) as f64;
        let n = n as f64;
        error +=
            (h * u.norm()).powi(5) / 120.0 * (n * (length - lo) - h * n * (n - 1.0) / 2.0) / length;
    }
    error.is_finite().then_some(error)
}

/// The tip pose of the unloaded `model` at the tensions `a` (N) marched with `integrator`
/// (RK4, [`applies`]), and if `jacobian` its actuation Jacobian (6 × n_tendons, `[δp; δθ]`,
/// world). `None` if a local solve fails (the march reports why).
pub(super) fn tip(
    model: &RobotModel,
    integrator: &Integrator,
    a: &[f64],
    jacobian: bool,
    ws: &mut Workspace,
) -> Option<Evaluation> {
    let Integrator::Rk4 { steps } = *integrator else {
        return None;
    };
    let nt = model.tendons().len();
    let plan = rk4_plan(model.breaks(), steps);
    let eq = Equations::new(model, a, &[]);
    ws.renew(nt);
    let mut ev = Evaluator { eq, ws };
    let base = model.rod().base_pose();
    let mut p = base.position();
    let mut r = base.rotation();
    let ncol = if jacobian { nt } else { 0 };
    let mut dp = vec![Vector3::zeros(); ncol];
    let mut dr = vec![Matrix3::zeros(); ncol];
    for (k, &n) in plan.iter().enumerate() {
        let iv = interval(&mut ev, k, n, jacobian)?;
        let (p0, r0) = (p, r);
        // A tendon that does not pass the interval forces nothing there: its column moves with
        // the rod as a rigid body (δR ← δR R₀ᵀ R, δp ← δp + δR R₀ᵀ (p - p₀)), applied at the end.
        let forced = &iv.passes;
        for _ in 0..iv.steps {
            for c in (0..ncol).filter(|&c| forced[c]) {
                let (dq, dqp) = &iv.columns[c];
                dp[c] += dr[c] * iv.q_pos + r * dqp;
                dr[c] = dr[c] * iv.q_rot + r * dq;
            }
            p += r * iv.q_pos;
            r *= iv.q_rot;
        }
        let (rel, dp_rel) = (r0.tr_mul(&r), r0.tr_mul(&(p - p0)));
        for c in (0..ncol).filter(|&c| !forced[c]) {
            dp[c] += dr[c] * dp_rel;
            dr[c] *= rel;
        }
    }
    if !(p.iter().chain(r.iter()).all(|x| x.is_finite())) {
        return None;
    }
    let jac = jacobian.then(|| {
        let cols: Vec<Vector6<f64>> = (0..nt)
            .map(|c| {
                let w = rotation_variation(&r, &dr[c]);
                Vector6::new(dp[c].x, dp[c].y, dp[c].z, w.x, w.y, w.z)
            })
            .collect();
        vec![DMatrix::from_fn(6, nt, |row, c| cols[c][row])]
    });
    Some(Evaluation {
        positions: vec![p],
        rotation: r,
        jacobian: jac,
    })
}
