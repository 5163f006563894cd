//! The chain kinematics of the unloaded PCC robot in the actuation: the affine map to the
//! segment coordinates, the tip position and its first and second derivatives, and the
//! Hessian of the Lagrangian.

use nalgebra::{Matrix3 as M3, Vector3 as V3};

use crate::pcc::statics::{seg_kin, PccRobot, SegKin};

/// The affine map `θ = θ0 + M a` of an unloaded robot.
#[derive(Default)]
pub(super) struct Affine {
    /// Actuators.
    pub(super) n: usize,
    /// Rest lengths (`θ0 = (0, 0, ℓ0)`).
    pub(super) rest: Vec<f64>,
    /// `∂θ_s/∂a_k` at `s n + k`.
    pub(super) cols: Vec<[f64; 3]>,
}

impl Affine {
    /// The map of `robot` into `self` (its vectors reused).
    pub(super) fn fill(&mut self, robot: &PccRobot) {
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
pub(super) struct Chain {
    pub(super) p: V3<f64>,
    pub(super) r: M3<f64>,
    pub(super) kin: Vec<SegKin>,
    pub(super) base: Vec<M3<f64>>,
    pub(super) tip: Vec<V3<f64>>,
    pub(super) vc: Vec<[V3<f64>; 3]>,
    pub(super) oc: Vec<[V3<f64>; 3]>,
    pub(super) jac: Vec<V3<f64>>,
}

impl Chain {
    /// Evaluates the chain at `a`; `false` if a length is not positive or a value not finite.
    pub(super) fn eval(&mut self, aff: &Affine, a: &[f64]) -> bool {
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
    pub(super) fn theta_hessian(&self, lambda: &V3<f64>, h: &mut Vec<f64>) {
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
pub(super) fn lagrangian_hessian(
    aff: &Affine,
    h: &[f64],
    w: &[f64],
    hm: &mut Vec<f64>,
    out: &mut Vec<f64>,
) {
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
pub(super) fn lagrangian_times(
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
