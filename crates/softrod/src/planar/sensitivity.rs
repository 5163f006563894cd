//! Exact parameter sensitivities of the planar cable arm (forward mode).
//!
//! For a parameter `p` of [`PlanarParameter`], the closed-form profile gives `k_p` and `q_p`
//! (with `D = E pi R^2 / 4 + T a^2`, `k = T a / (R D)`, `q = -T / (4 D)`):
//!
//! * `D_E = pi R^2 / 4`, `D_a = 2 T a`, `D_T = a^2`, `D_R = E pi R / 2`;
//! * `k_E = -k D_E / D`, `k_a = T / (R D) - k D_a / D`, `k_T = a / (R D) - k D_T / D`,
//!   `k_R = -k / R - k D_R / D`;
//! * `q_E = -q D_E / D`, `q_a = -q D_a / D`, `q_T = -1 / (4 D) - q D_T / D`, `q_R = -q D_R / D`;
//!
//! and the radii enter through `R(s) = R0 (1 - s / L) + RL s / L`. The backbone equations
//! `theta' = (1 + q) k`, `x' = (1 + q) cos theta`, `y' = (1 + q) sin theta` and the deformed
//! arc length `l' = 1 + q` are integrated together with their variational equations
//!
//! ```text
//! theta_p' = q_p k + (1 + q) k_p,
//! x_p' = q_p cos theta - (1 + q) sin theta theta_p,
//! y_p' = q_p sin theta + (1 + q) cos theta theta_p,
//! l_p' = q_p,
//! ```
//!
//! by the 4-stage Lobatto IIIA collocation rule (order 6) on fixed panels: the sensitivities
//! are the exact derivatives of the discrete march (the same panels for the solution and the
//! columns), not finite differences. Panels turn the tangent by at most [`SENSITIVITY_PANEL_TURN`]
//! rad, so the solution agrees with [`super::solve_planar`] to about `1e-11 L`.

use std::f64::consts::PI;

use super::{check_samples, PlanarCableArm};
use crate::error::Result;

/// Largest tangent-angle change (rad) across one panel of the sensitivity march.
pub const SENSITIVITY_PANEL_TURN: f64 = 0.05;
/// Largest relative radius change across one panel of the sensitivity march.
const SENSITIVITY_PANEL_TAPER: f64 = 0.02;

/// A parameter of the planar model whose sensitivity [`planar_sensitivities`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanarParameter {
    /// Young's modulus `E` (Pa).
    YoungsModulus,
    /// Cable offset ratio `a` (dimensionless).
    OffsetRatio,
    /// Cable tension `T` (N).
    Tension,
    /// Base radius `R0` (m).
    BaseRadius,
    /// Tip radius `RL` (m).
    TipRadius,
}

impl PlanarParameter {
    /// All parameters, in the column order of [`PlanarSensitivities`].
    pub const ALL: [PlanarParameter; 5] = [
        PlanarParameter::YoungsModulus,
        PlanarParameter::OffsetRatio,
        PlanarParameter::Tension,
        PlanarParameter::BaseRadius,
        PlanarParameter::TipRadius,
    ];
    /// Number of parameters.
    pub const COUNT: usize = 5;

    /// The name used by the bindings (`"youngs_modulus"`, `"offset_ratio"`, `"tension"`,
    /// `"base_radius"`, `"tip_radius"`).
    pub fn name(self) -> &'static str {
        match self {
            PlanarParameter::YoungsModulus => "youngs_modulus",
            PlanarParameter::OffsetRatio => "offset_ratio",
            PlanarParameter::Tension => "tension",
            PlanarParameter::BaseRadius => "base_radius",
            PlanarParameter::TipRadius => "tip_radius",
        }
    }
}

const NP: usize = PlanarParameter::COUNT;

/// The solution of one tension at chosen arc lengths with its derivatives with respect to
/// every [`PlanarParameter`]. Derivative arrays are row-major `(samples, 5)`, columns in the
/// order of [`PlanarParameter::ALL`], in the unit of the quantity per unit of the parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarSensitivities {
    /// Cable tension `T` (N).
    pub tension: f64,
    /// Undeformed arc length of each sample (m).
    pub s: Vec<f64>,
    /// Backbone x (m).
    pub x: Vec<f64>,
    /// Backbone y (m).
    pub y: Vec<f64>,
    /// Tangent angle (rad).
    pub angle: Vec<f64>,
    /// Axial strain `q` (zero beyond the anchor).
    pub strain: Vec<f64>,
    /// Deformed arc length from the base, `int_0^s (1 + q) ds` (m).
    pub arc: Vec<f64>,
    /// `dx/dp`, `(samples, 5)`.
    pub d_x: Vec<f64>,
    /// `dy/dp`, `(samples, 5)`.
    pub d_y: Vec<f64>,
    /// `dtheta/dp`, `(samples, 5)`.
    pub d_angle: Vec<f64>,
    /// `dl/dp` of the deformed arc length, `(samples, 5)`.
    pub d_arc: Vec<f64>,
    /// Tip `(x, y, theta, l)` at `s = L`.
    pub tip: [f64; 4],
    /// Derivatives of the tip `(x, y, theta, l)`, `(4, 5)` row-major.
    pub d_tip: [[f64; NP]; 4],
}

/// Profile `(k, q)` and its parameter derivatives at `s <= anchor`.
#[inline]
fn profile(arm: &PlanarCableArm, s: f64, t: f64) -> (f64, f64, [f64; NP], [f64; NP]) {
    let r = arm.radius(s);
    let (e, a) = (arm.youngs_modulus, arm.offset_ratio);
    let d = 0.25 * e * PI * r * r + t * a * a;
    let k = t * a / (r * d);
    let q = -0.25 * t / d;
    let (de, da, dt, dr) = (0.25 * PI * r * r, 2.0 * t * a, a * a, 0.5 * e * PI * r);
    let k_e = -k * de / d;
    let k_a = t / (r * d) - k * da / d;
    let k_t = a / (r * d) - k * dt / d;
    let k_r = -k / r - k * dr / d;
    let q_e = -q * de / d;
    let q_a = -q * da / d;
    let q_t = -0.25 / d - q * dt / d;
    let q_r = -q * dr / d;
    let w_tip = s / arm.length;
    let w_base = 1.0 - w_tip;
    (
        k,
        q,
        [k_e, k_a, k_t, k_r * w_base, k_r * w_tip],
        [q_e, q_a, q_t, q_r * w_base, q_r * w_tip],
    )
}

/// March state: angle, position, deformed arc length and their derivatives.
#[derive(Clone, Copy, Default)]
struct State {
    s: f64,
    theta: f64,
    x: f64,
    y: f64,
    l: f64,
    q: f64,
    d_theta: [f64; NP],
    d_x: [f64; NP],
    d_y: [f64; NP],
    d_l: [f64; NP],
}

/// The 4-stage Lobatto IIIA rule of the backbone march (nodes, stage matrix).
const C: [f64; 4] = super::LOBATTO4.c;
const A: [[f64; 4]; 4] = super::LOBATTO4.a;

impl State {
    /// One Lobatto IIIA panel over `[self.s, b]`, loaded.
    fn panel(&mut self, arm: &PlanarCableArm, t: f64, b: f64) {
        let h = b - self.s;
        let mut f = [0.0; 4];
        let mut g = [0.0; 4];
        let mut fp = [[0.0; NP]; 4];
        let mut gp = [[0.0; NP]; 4];
        for j in 0..4 {
            let sj = if j == 3 { b } else { self.s + C[j] * h };
            let (k, q, kp, qp) = profile(arm, sj, t);
            g[j] = 1.0 + q;
            f[j] = g[j] * k;
            for p in 0..NP {
                gp[j][p] = qp[p];
                fp[j][p] = qp[p] * k + g[j] * kp[p];
            }
            if j == 3 {
                self.q = q;
            }
        }
        let mut nx = self.x;
        let mut ny = self.y;
        let mut nl = self.l;
        let mut ndx = self.d_x;
        let mut ndy = self.d_y;
        let mut ndl = self.d_l;
        let mut theta_end = self.theta;
        let mut dtheta_end = self.d_theta;
        for j in 0..4 {
            let mut th = self.theta;
            let mut dth = self.d_theta;
            for l in 0..4 {
                th += h * A[j][l] * f[l];
                for p in 0..NP {
                    dth[p] += h * A[j][l] * fp[l][p];
                }
            }
            let (sn, cs) = th.sin_cos();
            let w = h * A[3][j];
            nx += w * g[j] * cs;
            ny += w * g[j] * sn;
            nl += w * g[j];
            for p in 0..NP {
                ndx[p] += w * (gp[j][p] * cs - g[j] * sn * dth[p]);
                ndy[p] += w * (gp[j][p] * sn + g[j] * cs * dth[p]);
                ndl[p] += w * gp[j][p];
            }
            if j == 3 {
                theta_end = th;
                dtheta_end = dth;
            }
        }
        self.s = b;
        self.theta = theta_end;
        self.d_theta = dtheta_end;
        self.x = nx;
        self.y = ny;
        self.l = nl;
        self.d_x = ndx;
        self.d_y = ndy;
        self.d_l = ndl;
    }

    /// Straight and unloaded to `b`.
    fn straight(&mut self, b: f64) {
        let d = b - self.s;
        let (sn, cs) = self.theta.sin_cos();
        self.x += d * cs;
        self.y += d * sn;
        self.l += d;
        for p in 0..NP {
            self.d_x[p] -= d * sn * self.d_theta[p];
            self.d_y[p] += d * cs * self.d_theta[p];
        }
        self.s = b;
        self.q = 0.0;
    }

    fn advance(&mut self, arm: &PlanarCableArm, t: f64, b: f64, rates: (f64, f64)) {
        let anchor = arm.anchor;
        if self.s < anchor {
            let end = b.min(anchor);
            let span = end - self.s;
            if span > 0.0 {
                let m = ((span * rates.0 / SENSITIVITY_PANEL_TURN)
                    .max(span * rates.1 / SENSITIVITY_PANEL_TAPER)
                    .min(1e7)
                    .ceil() as usize)
                    .max(1);
                let a0 = self.s;
                let h = span / m as f64;
                for i in 0..m {
                    let e = if i + 1 == m {
                        end
                    } else {
                        a0 + (i + 1) as f64 * h
                    };
                    self.panel(arm, t, e);
                }
            }
        }
        if b > anchor && b > self.s {
            self.straight(b);
        }
    }
}

/// Solves the arm for one tension at arc lengths `samples` (m, non-decreasing, in `[0, L]`)
/// with the exact derivatives of the backbone with respect to every [`PlanarParameter`]
/// (closed-form profile; see the module documentation).
///
/// # Errors
/// [`crate::Error::InvalidParameter`] for a bad tension or samples.
pub fn planar_sensitivities(
    arm: &PlanarCableArm,
    tension: f64,
    samples: &[f64],
) -> Result<PlanarSensitivities> {
    arm.check_tension(tension)?;
    let samples = check_samples(samples, arm.length)?;
    let n = samples.len();
    let anchor = arm.anchor;
    let turn = |s: f64| {
        let (k, q, _, _) = profile(arm, s, tension);
        ((1.0 + q) * k).abs()
    };
    let taper = arm.relative_taper();
    let rates = (turn(0.0).max(turn(anchor)), taper);
    let mut st = State {
        q: profile(arm, 0.0, tension).1,
        ..State::default()
    };
    let mut out = PlanarSensitivities {
        tension,
        s: samples.clone(),
        x: vec![0.0; n],
        y: vec![0.0; n],
        angle: vec![0.0; n],
        strain: vec![0.0; n],
        arc: vec![0.0; n],
        d_x: vec![0.0; n * NP],
        d_y: vec![0.0; n * NP],
        d_angle: vec![0.0; n * NP],
        d_arc: vec![0.0; n * NP],
        tip: [0.0; 4],
        d_tip: [[0.0; NP]; 4],
    };
    for (i, &si) in samples.iter().enumerate() {
        st.advance(arm, tension, si, rates);
        out.x[i] = st.x;
        out.y[i] = st.y;
        out.angle[i] = st.theta;
        out.strain[i] = if si <= anchor { st.q } else { 0.0 };
        out.arc[i] = st.l;
        out.d_x[i * NP..(i + 1) * NP].copy_from_slice(&st.d_x);
        out.d_y[i * NP..(i + 1) * NP].copy_from_slice(&st.d_y);
        out.d_angle[i * NP..(i + 1) * NP].copy_from_slice(&st.d_theta);
        out.d_arc[i * NP..(i + 1) * NP].copy_from_slice(&st.d_l);
    }
    st.advance(arm, tension, arm.length, rates);
    out.tip = [st.x, st.y, st.theta, st.l];
    out.d_tip = [st.d_x, st.d_y, st.d_theta, st.d_l];
    Ok(out)
}
