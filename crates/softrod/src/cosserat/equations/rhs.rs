//! The right-hand side of the state and of its sensitivity columns, and the integrator's
//! interface (stages, accepted steps, projection, intervals and jumps).

use nalgebra::{Vector3, Vector6};

use super::hold::HeldState;
use super::{
    col_rot, mul_hat, mul_hat2, project_columns, put3, rot, v3, Column, Evaluator, Local, COLUMN,
    DM, DN, DR, STATE,
};
use crate::integrate::march::Piecewise;
use crate::integrate::System;

impl Evaluator<'_, '_> {
    /// The right-hand side of the state and of the active columns (`N >= STATE + COLUMN
    /// ncol`), and the stage integrands (tendon speeds, path-length sensitivities); returns
    /// the local solution (strains, actuator sums) at `s`.
    #[inline]
    pub fn rhs_into<const N: usize>(&mut self, s: f64, y: &[f64; N], out: &mut [f64; N]) -> Local {
        self.ws.evaluations += 1;
        let eq = self.eq;
        let props = eq.model.rod().section_at(s);
        let r = rot(y);
        let nw = v3(y, 12);
        let mw = v3(y, 15);
        let nb = r.tr_mul(&nw);
        let mb = r.tr_mul(&mw);
        let ncol = self.ws.columns.len().min((N - STATE) / COLUMN);
        // A held interval (a contact interval on a curved obstacle): its normal pressure.
        let hold = eq.model.hold_on(self.ws.interval);
        let rate = hold.map(|_| self.strain_rate(s, &nb, &mb));
        let loc = self.local(s, &props, &nb, &mb, ncol > 0 || hold.is_some());
        let (v, u) = (loc.v, loc.u);
        let pd = r * v;
        let mut nd = -eq.distributed_force(s, &props);
        let md = -pd.cross(&nw) - eq.distributed_moment(s);
        if let (Some(h), Some(rate)) = (hold, rate) {
            let st = HeldState { nb, mb, nd, md };
            let (q, n) = self.hold_pressure(h, y, &loc, &st, rate);
            self.ws.hold_pressure = (q, n);
            nd -= n * q;
        }
        put3(out, 0, &pd);
        mul_hat(&r, &u, &mut out[3..12]);
        put3(out, 12, &nd);
        put3(out, 15, &md);
        let nt = self.ws.tendon_speed.len();
        self.ws.integrand[..nt].copy_from_slice(&self.ws.tendon_speed);
        if ncol == 0 {
            return loc;
        }
        if !loc.v.x.is_finite() {
            self.ws.tangent.diag = [f64::NAN; 6];
        }
        let b_end = eq.model.breaks()[self.ws.interval + 1];
        let ends = eq.model.tendon_ends();
        let nl = self.ws.length_tendons.len();
        let needs_dirs = nl > 0 || self.ws.columns[..ncol].iter().any(Column::needs_directions);
        if needs_dirs {
            for i in 0..ends.len() {
                self.ws.dirs[i] =
                    (ends[i] >= b_end).then(|| self.tendon_direction(i, s, &props, &v, &u));
            }
        }
        // The rod's own (elastic) body wrench, for the stiffness columns.
        let n_el = Vector6::new(
            nb.x - loc.tendon_force.x,
            nb.y - loc.tendon_force.y,
            nb.z - loc.tendon_force.z,
            mb.x - loc.tendon_moment.x,
            mb.y - loc.tendon_moment.y,
            mb.z - loc.tendon_moment.z,
        );
        let tangent = self.ws.tangent;
        for c in 0..ncol {
            let b = STATE + COLUMN * c;
            let dr = col_rot(y, b);
            let dn = v3(y, b + DN);
            let dm = v3(y, b + DM);
            let dnb = dr.tr_mul(&nw) + r.tr_mul(&dn);
            let dmb = dr.tr_mul(&mw) + r.tr_mul(&dm);
            let mut e = [dnb.x, dnb.y, dnb.z, dmb.x, dmb.y, dmb.z];
            let column = self.ws.columns[c];
            // d|p_i'| of the tendon whose offset the column changes, at fixed strains.
            let mut offset_rate = None;
            if column != Column::Free {
                let (f, rate) = self.forcing(column, s, &props, &v, &u, &n_el);
                for k in 0..6 {
                    e[k] -= f[k];
                }
                offset_rate = rate;
            }
            let d = tangent.apply(&e);
            let (dv, du) = (
                Vector3::new(d[0], d[1], d[2]),
                Vector3::new(d[3], d[4], d[5]),
            );
            let dpd = dr * v + r * dv;
            let dmd = -(dpd.cross(&nw) + pd.cross(&dn));
            put3(out, b, &dpd);
            mul_hat2(&dr, &u, &r, &du, &mut out[b + DR..b + DR + 9]);
            put3(out, b + DN, &Vector3::zeros());
            put3(out, b + DM, &dmd);
            for h in 0..nl {
                let i = self.ws.length_tendons[h];
                let mut g = match &self.ws.dirs[i] {
                    Some(t) => t.dot(&Vector6::from(d)),
                    None => 0.0,
                };
                if let Some((k, rate)) = offset_rate {
                    if k == i {
                        g += rate;
                    }
                }
                self.ws.integrand[nt + c * nl + h] = g;
            }
        }
        for k in STATE + COLUMN * ncol..N {
            out[k] = 0.0;
        }
        loc
    }
}

impl<const N: usize> System<N> for Evaluator<'_, '_> {
    #[inline]
    fn rhs(&mut self, t: f64, y: &[f64; N], dy: &mut [f64; N]) {
        let _ = self.rhs_into(t, y, dy);
    }
    #[inline]
    fn stage_evaluated(&mut self, stage: usize) {
        let ws = &mut *self.ws;
        if ws.stages.len() <= stage {
            ws.stages.resize(stage + 1, Vec::new());
        }
        ws.stages[stage].clear();
        ws.stages[stage].extend_from_slice(&ws.integrand);
    }
    #[inline]
    fn step_accepted(&mut self, weights: &[f64], fsal: bool) {
        let ws = &mut *self.ws;
        for (i, &w) in weights.iter().enumerate() {
            if w != 0.0 {
                for (acc, g) in ws.integral.iter_mut().zip(&ws.stages[i]) {
                    *acc += w * g;
                }
            }
        }
        if fsal {
            let last = weights.len() - 1;
            let (first, rest) = ws.stages.split_at_mut(1);
            first[0].clone_from(&rest[last - 1]);
        }
    }
    #[inline]
    fn project(&mut self, y: &mut [f64; N]) {
        // (The columns beyond the active ones have no right-hand side: held where they are.)
        project_columns(y, self.ws.columns.len());
    }
}

impl<const N: usize> Piecewise<N> for Evaluator<'_, '_> {
    /// Every march starts from the straight-tendon guess (interval 0: nothing of an earlier
    /// march, which may have diverged, carries over); across an interior break the local
    /// warm start of the interval before is kept if the same tendons and chambers act on
    /// both sides (a point load's break, e.g. a contact's).
    fn enter_interval(&mut self, k: usize) {
        if k > 0 && k == self.ws.interval + 1 {
            Evaluator::enter_interval(self, k);
        } else {
            self.set_interval(k);
        }
    }
    fn jump(&mut self, s: f64, y: &mut [f64; N]) {
        let ncol = self.ws.columns.len().min((N - STATE) / COLUMN);
        self.eq.jump(s, y, ncol);
    }
}
