//! The actuators of an interval: the tendons (tensioned and passive) and chambers that pass
//! through it, the tendon offsets and directions, and the tendon load sums with their
//! Jacobian.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::Evaluator;
use crate::math::so3::hat;
use crate::model::section::SectionProperties;
use crate::model::tendon::Routing;

impl Evaluator<'_, '_> {
    /// Selects the tendons and chambers active on interval `k`.
    pub fn set_interval(&mut self, k: usize) {
        let breaks = self.eq.model.breaks();
        let (a, b) = (breaks[k], breaks[k + 1]);
        let nt = self.eq.model.tendons().len();
        let nc = self.eq.model.chambers().len();
        self.ws.interval = k;
        self.ws.active.clear();
        self.ws.passive.clear();
        for i in 0..nt {
            self.ws.tendon_speed[i] = 0.0;
            match self.tendon_role(i, b) {
                Some(true) => self.ws.active.push(i),
                Some(false) => self.ws.passive.push(i),
                None => {}
            }
        }
        self.ws.guess = None;
        self.ws.last_lu = None;
        self.ws.memo = None;
        self.fix_offsets();
        self.ws.chambers.clear();
        for i in 0..nc {
            if self.chamber_acts(i, a, b) {
                self.ws.chambers.push(i);
            }
        }
    }

    /// [`Self::set_interval`], but keeping the warm start of the local solve (the last strains
    /// and the factorised local Jacobian) when the tendons and chambers acting on interval `k`
    /// are those already held: for evaluations at nearly the same states again and again (the
    /// contact rows, march after march) and for a march across a point load's break, a chord
    /// step or two instead of a local Newton solve from the straight-tendon guess.
    pub fn enter_interval(&mut self, k: usize) {
        if self.ws.guess.is_some() && self.holds_actuators_of(k) {
            self.ws.interval = k;
        } else {
            self.set_interval(k);
        }
    }

    /// Whether tendon `i` acts on an interval ending at `b`: `Some(true)` pulled, `Some(false)`
    /// passing tension-free (its path length tracked), `None` ended before.
    #[inline]
    fn tendon_role(&self, i: usize, b: f64) -> Option<bool> {
        (self.eq.model.tendon_ends()[i] >= b).then(|| self.eq.tensions[i] != 0.0)
    }

    /// Whether chamber `i` is pressurised over all of the interval `[a, b]`.
    #[inline]
    fn chamber_acts(&self, i: usize, a: f64, b: f64) -> bool {
        let (start, end) = self.eq.model.chamber_extents()[i];
        start <= a && end >= b && self.eq.pressures[i] != 0.0
    }

    /// Whether the tendons and chambers [`Self::set_interval`] would select on interval `k`
    /// are those the workspace holds.
    fn holds_actuators_of(&self, k: usize) -> bool {
        let breaks = self.eq.model.breaks();
        if k + 1 >= breaks.len() {
            return false;
        }
        let (a, b) = (breaks[k], breaks[k + 1]);
        let nt = self.eq.model.tendons().len();
        let nc = self.eq.model.chambers().len();
        let ws = &*self.ws;
        let active = (0..nt).filter(|&i| self.tendon_role(i, b) == Some(true));
        let passive = (0..nt).filter(|&i| self.tendon_role(i, b) == Some(false));
        let chambers = (0..nc).filter(|&i| self.chamber_acts(i, a, b));
        active.eq(ws.active.iter().copied())
            && passive.eq(ws.passive.iter().copied())
            && chambers.eq(ws.chambers.iter().copied())
    }

    /// Body-frame wrench carried by the fluid of the active chambers at `s` (zero without).
    #[inline]
    pub(crate) fn chamber_wrench(&self, s: f64) -> [f64; 6] {
        let mut w = [0.0; 6];
        let chambers = self.eq.model.chambers();
        for &i in &self.ws.chambers {
            let c = chambers[i].fluid_wrench(s, self.eq.pressures[i]);
            for k in 0..6 {
                w[k] += c[k];
            }
        }
        w
    }

    /// With constant tension along the tendons and every tendon of the interval routed at a
    /// constant offset, the offsets of the interval, once (the evaluations then only check
    /// the tensions in [`Self::load_offsets`] and read the passive offsets as they are).
    fn fix_offsets(&mut self) {
        let tendons = self.eq.model.tendons();
        let ws = &mut *self.ws;
        ws.fixed_offsets = false;
        ws.offsets.clear();
        ws.passive_offsets.clear();
        let constant = |i: &usize| matches!(tendons[*i].routing(), Routing::Constant(_));
        if self.eq.profile.is_some() || !ws.active.iter().chain(&ws.passive).all(constant) {
            return;
        }
        let a = self.eq.model.breaks()[ws.interval];
        let props = self.eq.model.rod().section_at(a);
        for &i in &ws.active {
            let (r, rp) = body_offset(tendons[i].routing(), a, &props);
            ws.offsets.push((r, rp, self.eq.tensions[i]));
        }
        for &i in &ws.passive {
            let (r, _) = body_offset(tendons[i].routing(), a, &props);
            ws.passive_offsets.push(r);
        }
        ws.fixed_offsets = true;
    }

    /// Offsets `(r, r', τ)` of the active tendons at `s` into the workspace; whether they are
    /// those already held (then the tendon sums at given strains are too).
    #[inline]
    pub(crate) fn load_offsets(&mut self, s: f64, props: &SectionProperties) -> bool {
        // (An evaluator with a tension profile may carry on in the interval: then as for any
        // routing.)
        self.ws.fixed_offsets &= self.eq.profile.is_none();
        if self.ws.fixed_offsets {
            // The tensions are read afresh: an evaluator with other tensions may carry on in
            // the interval (a march resumed at a break keeps the interval's warm start).
            let ws = &mut *self.ws;
            let mut kept = true;
            for (&i, o) in ws.active.iter().zip(ws.offsets.iter_mut()) {
                if o.2 != self.eq.tensions[i] {
                    o.2 = self.eq.tensions[i];
                    kept = false;
                }
            }
            return kept;
        }
        let tendons = self.eq.model.tendons();
        let ws = &mut *self.ws;
        let mut kept = ws.offsets.len() == ws.active.len();
        ws.offsets
            .resize(ws.active.len(), (Vector3::zeros(), Vector3::zeros(), 0.0));
        for (k, &i) in ws.active.iter().enumerate() {
            let (r, rp) = body_offset(tendons[i].routing(), s, props);
            let tau = self
                .eq
                .profile
                .and_then(|p| p.at(i, s))
                .unwrap_or(self.eq.tensions[i]);
            let new = (r, rp, tau);
            kept &= ws.offsets[k] == new;
            ws.offsets[k] = new;
        }
        kept
    }

    /// Records `|p_i'|` of the tension-free tendons for the strains `(v, u)`.
    #[inline]
    pub(crate) fn passive_speeds(
        &mut self,
        s: f64,
        props: &SectionProperties,
        v: &Vector3<f64>,
        u: &Vector3<f64>,
    ) {
        if !self.ws.track_lengths {
            return;
        }
        if self.ws.fixed_offsets {
            let ws = &mut *self.ws;
            for (&i, r) in ws.passive.iter().zip(&ws.passive_offsets) {
                ws.tendon_speed[i] = (v + u.cross(r)).norm();
            }
            return;
        }
        let tendons = self.eq.model.tendons();
        for &i in &self.ws.passive {
            let (r, rp) = body_offset(tendons[i].routing(), s, props);
            self.ws.tendon_speed[i] = (v + u.cross(&r) + rp).norm();
        }
    }

    /// `(t, r × t)` of tendon `i` (body) at strains `(v, u)`.
    pub(crate) fn tendon_direction(
        &self,
        i: usize,
        s: f64,
        props: &SectionProperties,
        v: &Vector3<f64>,
        u: &Vector3<f64>,
    ) -> Vector6<f64> {
        let (r, rp) = body_offset(self.eq.model.tendons()[i].routing(), s, props);
        let w = v + u.cross(&r) + rp;
        let t = w / w.norm();
        let q = r.cross(&t);
        Vector6::new(t.x, t.y, t.z, q.x, q.y, q.z)
    }

    /// Tendon load sums `(Σ τ t, Σ τ r × t)` at the strains `x = (v, u)` (the chord steps of
    /// the local iteration: [`Self::tendon_sums`] without the Jacobian).
    #[inline]
    pub(crate) fn tendon_load(&self, x: &Vector6<f64>) -> Vector6<f64> {
        let v = Vector3::new(x[0], x[1], x[2]);
        let u = Vector3::new(x[3], x[4], x[5]);
        let mut tf = Vector3::zeros();
        let mut tm = Vector3::zeros();
        for (r, rp, tau) in &self.ws.offsets {
            let w = v + u.cross(r) + rp;
            let t = w * (*tau / w.norm());
            tf += t;
            tm += r.cross(&t);
        }
        Vector6::new(tf.x, tf.y, tf.z, tm.x, tm.y, tm.z)
    }

    /// Tendon load sums `(Σ τ t, Σ τ r × t)` at the strains `x = (v, u)`, and, if `jac`, the
    /// local Jacobian `I + C D` (see the module documentation).
    ///
    /// Per tendon, with `t = w/|w|`, `q = r × t`, `a = τ/|w|` and `A = a (I - t tᵀ)`:
    /// `dT_F/dv = A`, `dT_F/du = -A r̂ = -a (r̂ + t qᵀ)`, `dT_M/dv = r̂ A = a (r̂ - q tᵀ)`,
    /// `dT_M/du = -r̂ A r̂ = -a (r rᵀ - |r|² I + q qᵀ)`.
    #[inline]
    pub(crate) fn tendon_sums(
        &self,
        x: &Vector6<f64>,
        c: &[f64; 6],
        jac: bool,
    ) -> (Vector6<f64>, Option<Matrix6<f64>>) {
        self.tendon_sums_into(x, c, jac, None)
    }

    /// [`Self::tendon_sums`]; with `stiffness`, `D` itself goes there (rows) instead of
    /// `I + C D`.
    #[inline]
    pub(crate) fn tendon_sums_into(
        &self,
        x: &Vector6<f64>,
        c: &[f64; 6],
        jac: bool,
        stiffness: Option<&mut [[f64; 6]; 6]>,
    ) -> (Vector6<f64>, Option<Matrix6<f64>>) {
        let jac = jac || stiffness.is_some();
        let v = Vector3::new(x[0], x[1], x[2]);
        let u = Vector3::new(x[3], x[4], x[5]);
        let mut tf = Vector3::zeros();
        let mut tm = Vector3::zeros();
        let mut sa = 0.0;
        let mut sar = Vector3::zeros();
        let mut ar2 = 0.0;
        let mut tt = Matrix3::zeros();
        let mut tq = Matrix3::zeros();
        let mut qq = Matrix3::zeros();
        let mut rr = Matrix3::zeros();
        for (r, rp, tau) in &self.ws.offsets {
            let w = v + u.cross(r) + rp;
            let inv_len = 1.0 / w.norm();
            let t = w * inv_len;
            let q = r.cross(&t);
            tf += t * *tau;
            tm += q * *tau;
            if jac {
                let a = *tau * inv_len;
                let at = t * a;
                sa += a;
                sar += r * a;
                ar2 += a * r.norm_squared();
                tt += at * t.transpose();
                tq += at * q.transpose();
                qq += q * (q * a).transpose();
                rr += r * (r * a).transpose();
            }
        }
        let sums = Vector6::new(tf.x, tf.y, tf.z, tm.x, tm.y, tm.z);
        if !jac {
            return (sums, None);
        }
        let rh = hat(&sar);
        let dfv = Matrix3::identity() * sa - tt;
        let dfu = -(rh + tq);
        let dmv = rh - tq.transpose();
        let dmu = Matrix3::identity() * ar2 - rr - qq;
        if let Some(out) = stiffness {
            // D is symmetric: [[dfv, dfu], [dmv = dfuᵀ, dmu]].
            for i in 0..3 {
                for j in 0..3 {
                    out[i][j] = dfv[(i, j)];
                    out[i][j + 3] = dfu[(i, j)];
                    out[i + 3][j] = dmv[(i, j)];
                    out[i + 3][j + 3] = dmu[(i, j)];
                }
            }
            return (sums, None);
        }
        let mut h = Matrix6::identity();
        for i in 0..3 {
            for j in 0..3 {
                h[(i, j)] += c[i] * dfv[(i, j)];
                h[(i, j + 3)] += c[i] * dfu[(i, j)];
                h[(i + 3, j)] += c[i + 3] * dmv[(i, j)];
                h[(i + 3, j + 3)] += c[i + 3] * dmu[(i, j)];
            }
        }
        (sums, Some(h))
    }
}

/// A tendon's offset `r` and its derivative `r'` at `s` as body-frame 3-vectors (m, m/m).
#[inline]
fn body_offset(
    routing: &Routing,
    s: f64,
    props: &SectionProperties,
) -> (Vector3<f64>, Vector3<f64>) {
    let (r, rp) = routing.offset(s, props);
    (
        Vector3::new(r[0], r[1], 0.0),
        Vector3::new(rp[0], rp[1], 0.0),
    )
}
