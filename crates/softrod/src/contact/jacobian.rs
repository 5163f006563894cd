//! The exact Jacobian of the constrained shooting problem: one march of the state with the
//! variational columns of every unknown.
//!
//! The six base-wrench columns start from a unit base wrench (as in the contact-free
//! solve). A contact force inside the rod is a dead world-frame point load at its arc length
//! `s`: its three columns start at `s` from the jump of the internal force, `δN(s⁺) = -e_k`
//! per newton. Moving the contact along the rod moves the jump: its column starts at `s`
//! from `δy(s⁺) = y'(s⁻) - y'(s⁺)` per metre (the difference of the right-hand sides on the
//! two sides of the jump). A contact at the tip changes only the tip balance (`-e_k`). The
//! contact rows are algebraic in the states at the contact's nodes, so their derivatives
//! along each column are taken by central differences of those few evaluations (no march);
//! the tip rows use the tip columns. One march replaces the `6 + 4 n_c` marches of forward
//! differences.
//!
//! For the actuation Jacobian the same march carries one forced column per actuator (tension,
//! then pressure, as in the contact-free sensitivities) and keeps the columns at one observed
//! node: the rows' derivatives at fixed unknowns along those columns (the contact rows
//! differenced with the actuator changed in the equations too, since their slope row
//! evaluates the right-hand side) and the node's twist per unknown and per actuator.

use nalgebra::{Vector3, Vector6};

use super::problem::{equations, Constrained, Pass, Site};
use super::rows::AtContact;
use crate::cosserat::equations::{
    col_rot, rot, rotation_variation, v3, Column, Evaluator, Workspace, COLUMN, DN, STATE,
};
use crate::cosserat::statics::Integrator;
use crate::integrate::march::{march, rk4_plan, Scheme};
use crate::solve::Problem;

/// State length of a march with `c` columns.
const fn width(c: usize) -> usize {
    STATE + COLUMN * c
}

/// Relative step of the central differences of the contact rows along a column.
const ROW_STEP: f64 = 1e-6;

/// What the march keeps of a contact inside the rod.
struct Site2 {
    /// Arc length (m).
    s: f64,
    /// Its first march column (the arc length; the force's three follow).
    column: usize,
    /// Where the post-jump right-hand side is taken (just after the edge of an interval).
    post_at: f64,
    /// State and columns before and after the jump, and the intervals.
    before: Option<(Vec<f64>, usize)>,
    after: Option<(Vec<f64>, usize)>,
    /// Right-hand sides of the state before and after the jump.
    rate: [[f64; STATE]; 2],
}

fn head(y: &[f64]) -> [f64; STATE] {
    let mut h = [0.0; STATE];
    h.copy_from_slice(&y[..STATE]);
    h
}

/// What the actuator columns of a march left (see [`Constrained::exact_actuated`]).
pub(super) struct Actuated {
    /// Per actuator (tensions, then pressures), the derivative of the residual rows at fixed
    /// unknowns (per N, per Pa).
    pub(super) rows: Vec<Vec<f64>>,
    /// Per actuator, the twist `[δp; δθ]` (m, rad; world) of the observed node at fixed
    /// unknowns.
    pub(super) twist: Vec<Vector6<f64>>,
    /// Per scaled unknown, the twist of the observed node.
    pub(super) node: Vec<Vector6<f64>>,
    /// Position of the observed node (m, world).
    pub(super) position: Vector3<f64>,
}

impl Constrained<'_> {
    /// The residual rows at `x` and the exact Jacobian (column-major, `dim × dim`, into `j`)
    /// from one march; `None` if the march fails or the columns do not fit in one march (the
    /// caller then differences).
    pub(super) fn exact(&mut self, x: &[f64], mu: f64, j: &mut [f64]) -> Option<Vec<f64>> {
        self.dispatch(x, mu, j, None).map(|(rows, _)| rows)
    }

    /// As [`Self::exact`], with the actuator columns and the columns at the node of index
    /// `observe` (in the order of the march's nodes, those of a solution).
    pub(super) fn exact_actuated(
        &mut self,
        x: &[f64],
        j: &mut [f64],
        observe: usize,
    ) -> Option<(Vec<f64>, Actuated)> {
        let (rows, act) = self.dispatch(x, 1.0, j, Some(observe))?;
        Some((rows, act?))
    }

    fn dispatch(
        &mut self,
        x: &[f64],
        mu: f64,
        j: &mut [f64],
        observe: Option<usize>,
    ) -> Option<(Vec<f64>, Option<Actuated>)> {
        let interior = self.active.iter().filter(|a| a.site != Site::Tip).count();
        let actuators = if observe.is_some() {
            self.tensions.len() + self.pressures.len()
        } else {
            0
        };
        match 6 + 4 * interior + actuators {
            0..=6 => self.wide::<{ width(6) }>(x, mu, j, observe),
            7..=10 => self.wide::<{ width(10) }>(x, mu, j, observe),
            11..=14 => self.wide::<{ width(14) }>(x, mu, j, observe),
            15..=18 => self.wide::<{ width(18) }>(x, mu, j, observe),
            19..=26 => self.wide::<{ width(26) }>(x, mu, j, observe),
            27..=34 if observe.is_some() => self.wide::<{ width(34) }>(x, mu, j, observe),
            _ => None,
        }
    }

    #[allow(clippy::too_many_lines)] // one march and its chain rule, documented above
    fn wide<const N: usize>(
        &mut self,
        x: &[f64],
        mu: f64,
        j: &mut [f64],
        observe: Option<usize>,
    ) -> Option<(Vec<f64>, Option<Actuated>)> {
        let model = self.contact_model(x)?;
        let l = self.model.length();
        let fs = self.model.force_scale();
        let n = self.dim();
        let offsets = self.offsets();
        // The march column of every unknown (none for a tip contact's force).
        let mut mcol: Vec<Option<usize>> = vec![None; n];
        for (k, m) in mcol.iter_mut().enumerate().take(6) {
            *m = Some(k);
        }
        let mut sites: Vec<Site2> = Vec::new();
        let mut next = 6;
        for (a, &o) in self.active.iter().zip(&offsets) {
            if a.site == Site::Tip {
                continue;
            }
            let s = x[o] * l;
            for q in 0..4 {
                mcol[o + q] = Some(next + q);
            }
            let post_at = if a.site == Site::Interval {
                f64::from_bits(s.to_bits() + 1)
            } else {
                s
            };
            sites.push(Site2 {
                s,
                column: next,
                post_at,
                before: None,
                after: None,
                rate: [[0.0; STATE]; 2],
            });
            next += 4;
        }
        let ncol = next;
        // The actuator columns follow the unknowns' (only with an observed node).
        let (nt, nc) = (self.tensions.len(), self.pressures.len());
        let actuators: Vec<Column> = if observe.is_some() {
            (0..nt)
                .map(Column::Tension)
                .chain((0..nc).map(Column::Pressure))
                .collect()
        } else {
            Vec::new()
        };
        let mut columns = vec![Column::Free; ncol];
        columns.extend_from_slice(&actuators);
        let plan = match self.integrator {
            Integrator::Rk4 { steps } => rk4_plan(model.breaks(), steps),
            Integrator::Adaptive(_) => Vec::new(),
        };
        let scheme = match self.integrator {
            Integrator::Rk4 { .. } => Scheme::Rk4(&plan),
            Integrator::Adaptive(options) => Scheme::Adaptive {
                options,
                controlled: STATE,
            },
        };
        let eq = equations(&model, &self.tensions, &self.pressures);
        let nt = model.tendons().len();
        let mut ws = Workspace::new(nt);
        ws.set_columns(&columns, &[]);
        let mut scratch = Workspace::new(nt);
        let y0: [f64; N] = eq.initial(&x[..6]);
        let mut nodes = Vec::new();
        let mut observed: Option<Vec<f64>> = None;
        let y = {
            let mut ev = Evaluator { eq, ws: &mut ws };
            let mut side = Evaluator {
                eq,
                ws: &mut scratch,
            };
            let sites = &mut sites;
            let nodes = &mut nodes;
            march(
                &mut ev,
                model.breaks(),
                &[],
                y0,
                scheme,
                |_, s, interval, y: &mut [f64; N]| {
                    for site in sites.iter_mut().filter(|c| c.s == s) {
                        if site.before.is_none() {
                            site.before = Some((y.to_vec(), interval));
                            continue;
                        }
                        if site.after.is_some() {
                            continue;
                        }
                        let Some((pre, k0)) = site.before.as_ref().map(|b| (head(&b.0), b.1))
                        else {
                            continue;
                        };
                        let post = head(y);
                        side.set_interval(k0);
                        let mut a = [0.0; STATE];
                        side.rhs_into::<STATE>(s, &pre, &mut a);
                        side.set_interval(interval);
                        let mut b = [0.0; STATE];
                        side.rhs_into::<STATE>(site.post_at, &post, &mut b);
                        site.rate = [a, b];
                        let c = STATE + COLUMN * site.column;
                        for i in 0..STATE {
                            y[c + i] = (a[i] - b[i]) * l;
                        }
                        for q in 0..3 {
                            y[STATE + COLUMN * (site.column + 1 + q) + DN + q] = -fs;
                        }
                        site.after = Some((y.to_vec(), interval));
                    }
                    if observe == Some(nodes.len()) {
                        observed = Some(y.to_vec());
                    }
                    nodes.push(crate::cosserat::shooting::Node {
                        s,
                        interval,
                        y: head(y),
                    });
                },
            )
            .ok()?
        };
        self.evaluations += ws.evaluations + scratch.evaluations;
        if !y[..STATE].iter().all(|v| v.is_finite()) || sites.iter().any(|c| c.after.is_none()) {
            return None;
        }
        let (res, dres) = eq.residual(&y, columns.len());
        let (p_tip, r_tip) = (v3(&y, 0), rot(&y));
        let mut rows = self.tip_rows(&res, &p_tip, &r_tip).to_vec();
        let tip_y = head(&y);
        let tip_k = nodes.last()?.interval;
        // The contact rows at the solution, and per contact the function of its node states.
        let mut other = Workspace::new(nt);
        let mut ev = [
            Evaluator {
                eq,
                ws: &mut scratch,
            },
            Evaluator { eq, ws: &mut other },
        ];
        let mut interior = 0;
        // (arc length, first and last node state + interval, scaled force, site index)
        let mut at = Vec::with_capacity(self.active.len());
        for (a, &o) in self.active.iter().zip(&offsets) {
            let (s, k, site) = match a.site {
                Site::Tip => (l, o, None),
                _ => {
                    interior += 1;
                    (x[o] * l, o + 1, Some(interior - 1))
                }
            };
            let (yf, kf, yl, kl) = match site {
                None => (tip_y, tip_k, tip_y, tip_k),
                Some(i) => {
                    let (b, kb) = sites[i].before.as_ref()?;
                    let (c, kc) = sites[i].after.as_ref()?;
                    (head(b), *kb, head(c), *kc)
                }
            };
            let f = Vector3::new(x[k], x[k + 1], x[k + 2]);
            let held = AtContact {
                s,
                first: (&yf, kf),
                last: (&yl, kl),
            };
            self.contact_rows(&mut ev, a, held, &f, mu, &mut rows);
            at.push((s, yf, kf, yl, kl, f, site, o));
        }
        if rows.len() != n || !rows.iter().all(|v| v.is_finite()) {
            return None;
        }
        // The Jacobian, column by column.
        let column_of = |y: &[f64], m: Option<usize>| -> [f64; STATE] {
            let mut d = [0.0; STATE];
            if let Some(m) = m {
                let b = STATE + COLUMN * m;
                d.copy_from_slice(&y[b..b + STATE]);
            }
            d
        };
        let scale = |d: &[f64; STATE]| -> f64 {
            let mut v: f64 = 0.0;
            for i in 0..3 {
                v = v.max(d[i].abs() / l);
                v = v.max(d[DN + i].abs() / fs);
                v = v.max(d[DN + 3 + i].abs() / (fs * l));
            }
            for i in 3..12 {
                v = v.max(d[i].abs());
            }
            v
        };
        let mut buf = Vec::with_capacity(4);
        let mut twists = Vec::with_capacity(n);
        for c in 0..n {
            let (dres_c, dp, w) = match mcol[c] {
                Some(m) => {
                    let b = STATE + COLUMN * m;
                    (
                        dres[m],
                        v3(&y, b),
                        rotation_variation(&r_tip, &col_rot(&y, b)),
                    )
                }
                None => {
                    // A tip contact's force: the tip balance alone.
                    let mut d = nalgebra::Vector6::zeros();
                    let q = (c - offsets.iter().rev().find(|o| **o <= c).copied()?) % 3;
                    d[q] = -1.0;
                    (d, Vector3::zeros(), Vector3::zeros())
                }
            };
            twists.push(nalgebra::Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z));
            let tip = self.tip_rows_dot(&dres_c, &dp, &w, &r_tip);
            j[n * c..n * c + 6].copy_from_slice(&tip);
            let mut row = 6;
            for (a, &(s, yf, kf, yl, kl, f, site, o)) in self.active.iter().zip(&at) {
                let size = a.size();
                let (mut ds, mut df) = (0.0, Vector3::zeros());
                let (mut dyf, mut dyl) = match site {
                    None => {
                        let d = column_of(&y, mcol[c]);
                        (d, d)
                    }
                    Some(i) => (
                        column_of(&sites[i].before.as_ref()?.0, mcol[c]),
                        column_of(&sites[i].after.as_ref()?.0, mcol[c]),
                    ),
                };
                let first_force = if site.is_some() { o + 1 } else { o };
                if site.is_some() && c == o {
                    // The contact's own arc length: both sides move with the state before
                    // the jump.
                    let i = site?;
                    ds = l;
                    for k in 0..STATE {
                        dyf[k] += sites[i].rate[0][k] * l;
                        dyl[k] += sites[i].rate[1][k] * l;
                    }
                }
                if (first_force..first_force + 3).contains(&c) {
                    df[c - first_force] = 1.0;
                }
                let nu = scale(&dyf).max(scale(&dyl)).max(ds / l).max(df.amax());
                if nu == 0.0 {
                    for i in 0..size {
                        j[n * c + row + i] = 0.0;
                    }
                    row += size;
                    continue;
                }
                let h = ROW_STEP / nu;
                let mut eval = |t: f64, buf: &mut Vec<f64>| {
                    let mut yf2 = yf;
                    let mut yl2 = yl;
                    for k in 0..STATE {
                        yf2[k] += t * dyf[k];
                        yl2[k] += t * dyl[k];
                    }
                    buf.clear();
                    let f2 = f + df * t;
                    let moved = AtContact {
                        s: s + ds * t,
                        first: (&yf2, kf),
                        last: (&yl2, kl),
                    };
                    self.contact_rows(&mut ev, a, moved, &f2, mu, buf);
                };
                eval(h, &mut buf);
                let plus = buf.clone();
                if self.rough {
                    // One-sided, from the rows at the point.
                    let at = &rows[row..row + size];
                    for i in 0..size {
                        j[n * c + row + i] = (plus[i] - at[i]) / h;
                    }
                } else {
                    eval(-h, &mut buf);
                    for i in 0..size {
                        j[n * c + row + i] = (plus[i] - buf[i]) / (2.0 * h);
                    }
                }
                row += size;
            }
        }
        let actuated = match &observed {
            None => None,
            Some(yo) => {
                let twist_of = |y: &[f64], m: Option<usize>| -> Vector6<f64> {
                    let Some(m) = m else {
                        return Vector6::zeros();
                    };
                    let b = STATE + COLUMN * m;
                    let (dp, w) = (v3(y, b), rotation_variation(&rot(y), &col_rot(y, b)));
                    Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
                };
                let node = (0..n).map(|c| twist_of(yo, mcol[c])).collect();
                let mut out = Actuated {
                    rows: Vec::with_capacity(actuators.len()),
                    twist: Vec::with_capacity(actuators.len()),
                    node,
                    position: v3(yo, 0),
                };
                for (k, col) in actuators.iter().enumerate() {
                    let m = ncol + k;
                    let b = STATE + COLUMN * m;
                    let (dp, w) = (v3(&y, b), rotation_variation(&r_tip, &col_rot(&y, b)));
                    let mut d = self.tip_rows_dot(&dres[m], &dp, &w, &r_tip).to_vec();
                    // The actuator's size: the force scale, or the pressure that makes it.
                    let unit = match *col {
                        Column::Pressure(q) => {
                            let (start, _) = model.chamber_extents()[q];
                            fs / model.chambers()[q].area_at(start)
                        }
                        _ => fs,
                    };
                    for (a, &(s, yf, kf, yl, kl, f, site, _)) in self.active.iter().zip(&at) {
                        let (dyf, dyl) = match site {
                            None => {
                                let d = column_of(&y, Some(m));
                                (d, d)
                            }
                            Some(i) => (
                                column_of(&sites[i].before.as_ref()?.0, Some(m)),
                                column_of(&sites[i].after.as_ref()?.0, Some(m)),
                            ),
                        };
                        let h = ROW_STEP / scale(&dyf).max(scale(&dyl)).max(1.0 / unit);
                        let side = |t: f64| -> Vec<f64> {
                            let (mut tp, mut pp) = (self.tensions.clone(), self.pressures.clone());
                            match *col {
                                Column::Tension(i) => tp[i] += t,
                                Column::Pressure(q) => pp[q] += t,
                                _ => {}
                            }
                            let eq2 = equations(&model, &tp, &pp);
                            let (mut w1, mut w2) = (Workspace::new(nt), Workspace::new(nt));
                            let mut ev2 = [
                                Evaluator {
                                    eq: eq2,
                                    ws: &mut w1,
                                },
                                Evaluator {
                                    eq: eq2,
                                    ws: &mut w2,
                                },
                            ];
                            let (mut yf2, mut yl2) = (yf, yl);
                            for i in 0..STATE {
                                yf2[i] += t * dyf[i];
                                yl2[i] += t * dyl[i];
                            }
                            let mut buf = Vec::with_capacity(4);
                            let here = AtContact {
                                s,
                                first: (&yf2, kf),
                                last: (&yl2, kl),
                            };
                            self.contact_rows(&mut ev2, a, here, &f, mu, &mut buf);
                            buf
                        };
                        let (plus, minus) = (side(h), side(-h));
                        d.extend(plus.iter().zip(&minus).map(|(p, q)| (p - q) / (2.0 * h)));
                    }
                    if d.len() != n || !d.iter().all(|v| v.is_finite()) {
                        return None;
                    }
                    out.rows.push(d);
                    out.twist.push(twist_of(yo, Some(m)));
                }
                Some(out)
            }
        };
        if observe.is_some() && actuated.is_none() {
            return None;
        }
        self.last = Some(Pass {
            model: std::sync::Arc::clone(&model),
            nodes,
            residual: res,
            key: self.key(x, mu),
            rows: rows.clone(),
            jacobian: Some((j.to_vec(), twists)),
            marched: None,
        });
        Some((rows, actuated))
    }

    /// The tip compliance at the converged `x` with the active contacts and the tip
    /// constraint as constraints: `[δp; δθ]` of the tip (m, rad; world) per `[δF; δM]` of a
    /// dead tip load (N, N m; world), from the linearised constrained problem
    /// `J δx = -∂r/∂w` and the tip columns of the unknowns; `None` if the Jacobian is
    /// singular or the march fails.
    pub(super) fn compliance(&mut self, x: &[f64]) -> Option<nalgebra::Matrix6<f64>> {
        let n = self.dim();
        let key = self.key(x, 1.0);
        let cached = self
            .last
            .as_ref()
            .filter(|l| l.key == key && l.jacobian.is_some());
        if cached.is_none() {
            let mut j = vec![0.0; n * n];
            self.exact(x, 1.0, &mut j)?;
        }
        let (j, twists) = self.last.as_ref()?.jacobian.clone()?;
        let r_tip = rot(&self.last.as_ref()?.nodes.last()?.y);
        let l = self.model.length();
        let fs = self.model.force_scale();
        let mut lu = crate::math::linalg::DenseLu::default();
        if !lu.factor(n, &j) {
            return None;
        }
        let mut c = nalgebra::Matrix6::zeros();
        for k in 0..6 {
            // The tip rows' change with a unit tip load: the free balance rows lose it.
            let mut d = nalgebra::Vector6::zeros();
            d[k] = -1.0 / if k < 3 { fs } else { fs * l };
            let tip = self.tip_rows_dot(&d, &Vector3::zeros(), &Vector3::zeros(), &r_tip);
            let mut dx = vec![0.0; n];
            for i in 0..6 {
                dx[i] = -tip[i];
            }
            if !lu.solve_in_place(&mut dx) {
                return None;
            }
            let q: nalgebra::Vector6<f64> = twists.iter().zip(&dx).map(|(t, v)| t * *v).sum();
            c.set_column(k, &q);
        }
        c.iter().all(|v| v.is_finite()).then_some(c)
    }
}
