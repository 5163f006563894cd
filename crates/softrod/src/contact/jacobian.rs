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

use super::problem::{equations, Active, Constrained, Pass, Scratch, Site};
use super::rows::AtContact;
use crate::cosserat::equations::{
    col_rot, rot, rotation_variation, v3, Column, Evaluator, Workspace, COLUMN, DN, STATE,
};
use crate::cosserat::shooting::Node;
use crate::cosserat::statics::Integrator;
use crate::integrate::march::{march, rk4_plan, Scheme};
use crate::model::RobotModel;
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

impl Site2 {
    /// At a node of the march at `s` (on `interval`, state and columns `y`) where the
    /// contact sits: at its first copy, the state before the jump; at the second, the
    /// right-hand sides on both sides of the jump (`side` evaluates them), the columns of
    /// the contact's arc length (`δy(s⁺) = y'(s⁻) - y'(s⁺)` per unit of `s / L`) and force
    /// (`δN(s⁺) = -e_k f_ref`) seeded, and the state after it. `(l, fs)`: the rod's length
    /// (m) and force scale (N).
    fn record<const N: usize>(
        &mut self,
        side: &mut Evaluator<'_, '_>,
        s: f64,
        interval: usize,
        y: &mut [f64; N],
        (l, fs): (f64, f64),
    ) {
        if self.before.is_none() {
            self.before = Some((y.to_vec(), interval));
            return;
        }
        if self.after.is_some() {
            return;
        }
        let Some((pre, k0)) = self.before.as_ref().map(|b| (head(&b.0), b.1)) else {
            return;
        };
        let post = head(y);
        side.enter_interval(k0);
        let mut a = [0.0; STATE];
        side.rhs_into::<STATE>(s, &pre, &mut a);
        side.enter_interval(interval);
        let mut b = [0.0; STATE];
        side.rhs_into::<STATE>(self.post_at, &post, &mut b);
        self.rate = [a, b];
        let c = STATE + COLUMN * self.column;
        for i in 0..STATE {
            y[c + i] = (a[i] - b[i]) * l;
        }
        for q in 0..3 {
            y[STATE + COLUMN * (self.column + 1 + q) + DN + q] = -fs;
        }
        self.after = Some((y.to_vec(), interval));
    }
}

/// What the rows of one active contact are a function of: the contact, its arc length (m),
/// the states and intervals of its first and last nodes, its scaled force, its index among
/// the contacts inside the rod (none at the tip) and its first unknown.
struct RowsOf {
    active: Active,
    s: f64,
    first: ([f64; STATE], usize),
    last: ([f64; STATE], usize),
    f: Vector3<f64>,
    site: Option<usize>,
    o: usize,
}

/// The march's result that the Jacobian columns are read from: the end state with its
/// columns, the residual's derivative per column, the tip rotation, the march column of each
/// unknown, the unknowns' offsets, the contacts inside the rod, the contacts' row functions,
/// the rows at the point, the homotopy parameter and the dimension.
struct Linear<'a> {
    y: &'a [f64],
    dres: &'a [nalgebra::Vector6<f64>],
    r_tip: nalgebra::Matrix3<f64>,
    mcol: &'a [Option<usize>],
    offsets: &'a [usize],
    sites: &'a [Site2],
    at: &'a [RowsOf],
    rows: &'a [f64],
    mu: f64,
    n: usize,
}

/// The state part of march column `m` of `y` (zero for none).
fn column_of(y: &[f64], m: Option<usize>) -> [f64; STATE] {
    let mut d = [0.0; STATE];
    if let Some(m) = m {
        let b = STATE + COLUMN * m;
        d.copy_from_slice(&y[b..b + STATE]);
    }
    d
}

/// The size of a state change `d` in the rod's scales (length `l`, force scale `fs`): the
/// largest of its position over `l`, rotation, force over `fs` and moment over `fs l`.
fn scale(d: &[f64; STATE], l: f64, fs: f64) -> f64 {
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

/// The twist `[δp; δθ]` (m, rad; world) that march column `m` of `y` gives the state's
/// pose (zero for none).
fn twist_of(y: &[f64], m: Option<usize>) -> Vector6<f64> {
    let Some(m) = m else {
        return Vector6::zeros();
    };
    let b = STATE + COLUMN * m;
    let (dp, w) = (v3(y, b), rotation_variation(&rot(y), &col_rot(y, b)));
    Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
}

/// What a march with the columns leaves: the end state with its columns, the nodes, and the
/// state with its columns at the observed node (if one is observed).
struct ColumnMarch<const N: usize> {
    y: [f64; N],
    nodes: Vec<Node>,
    observed: Option<Vec<f64>>,
}

/// The march columns: the unknowns' `ncol`, then the actuators' (tensions, then pressures).
struct MarchColumns<'a> {
    ncol: usize,
    actuators: &'a [Column],
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

    /// [`Self::wide`] with the smallest march width that holds the columns.
    fn dispatch(
        &mut self,
        x: &[f64],
        mu: f64,
        j: &mut [f64],
        observe: Option<usize>,
    ) -> Option<(Vec<f64>, Option<Actuated>)> {
        if self.active.iter().any(|a| a.site.held()) {
            // (A belt's pressure depends on the state: its Jacobian is differenced.)
            return None;
        }
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

    /// [`Self::exact`] with the state and `(N - STATE) / COLUMN` columns in one march: the
    /// march of the columns, the rows at its end, then the Jacobian column by column; with
    /// an `observe`d node also the actuator columns ([`Self::actuated`]).
    fn wide<const N: usize>(
        &mut self,
        x: &[f64],
        mu: f64,
        j: &mut [f64],
        observe: Option<usize>,
    ) -> Option<(Vec<f64>, Option<Actuated>)> {
        let model = self.contact_model(x)?;
        let n = self.dim();
        let offsets = self.offsets();
        let (mcol, mut sites, ncol) = self.march_columns_of(x);
        let actuators: Vec<Column> = if observe.is_some() {
            (0..self.tensions.len())
                .map(Column::Tension)
                .chain((0..self.pressures.len()).map(Column::Pressure))
                .collect()
        } else {
            Vec::new()
        };
        let cols = MarchColumns {
            ncol,
            actuators: &actuators,
        };
        let nt = model.tendons().len();
        let mut scratch = self.scratch(nt);
        let ColumnMarch { y, nodes, observed } =
            self.march_with_columns::<N>(&model, x, &mut sites, &cols, observe, &mut scratch)?;
        let eq = equations(&model, &self.tensions, &self.pressures);
        let (res, dres) = eq.residual(&y, ncol + actuators.len());
        let (p_tip, r_tip) = (v3(&y, 0), rot(&y));
        let mut rows = self.tip_rows(&res, &p_tip, &r_tip).to_vec();
        let tip = (head(&y), nodes.last()?.interval);
        // The contact rows at the solution, and per contact the function of its node states.
        let [before, after] = &mut scratch.sides;
        let mut ev = [Evaluator { eq, ws: before }, Evaluator { eq, ws: after }];
        let at = self.contact_rows_at(&mut ev, x, mu, tip, &sites, &mut rows)?;
        if rows.len() != n || !rows.iter().all(|v| v.is_finite()) {
            return None;
        }
        let lin = Linear {
            y: &y,
            dres: &dres,
            r_tip,
            mcol: &mcol,
            offsets: &offsets,
            sites: &sites,
            at: &at,
            rows: &rows,
            mu,
            n,
        };
        let mut buf = Vec::with_capacity(4);
        let mut twists = Vec::with_capacity(n);
        for c in 0..n {
            twists.push(self.jacobian_column(&mut ev, &lin, c, j, &mut buf)?);
        }
        self.evaluations += scratch.side_evaluations();
        let actuated = match &observed {
            None => None,
            Some(yo) => Some(self.actuated(&model, &lin, &cols, yo)?),
        };
        let replaced = self.last.replace(Pass {
            model: std::sync::Arc::clone(&model),
            nodes,
            residual: res,
            key: self.key(x, mu),
            rows: rows.clone(),
            jacobian: Some((j.to_vec(), twists)),
            held: vec![None; self.active.len()],
            marched: None,
        });
        scratch.keep_nodes(replaced);
        self.scratch = Some(scratch);
        Some((rows, actuated))
    }

    /// The actuator columns of the march `lin` (`cols.actuators`, after the unknowns'): per
    /// actuator the derivative of the rows at fixed unknowns (the tip rows from its column,
    /// the contact rows by central differences with the actuator changed in the equations
    /// too) and the twist of the observed node (state and columns `yo`).
    fn actuated(
        &self,
        model: &RobotModel,
        lin: &Linear<'_>,
        cols: &MarchColumns<'_>,
        yo: &[f64],
    ) -> Option<Actuated> {
        let fs = self.model.force_scale();
        let mut out = Actuated {
            rows: Vec::with_capacity(cols.actuators.len()),
            twist: Vec::with_capacity(cols.actuators.len()),
            node: (0..lin.n).map(|c| twist_of(yo, lin.mcol[c])).collect(),
            position: v3(yo, 0),
        };
        for (k, col) in cols.actuators.iter().enumerate() {
            let m = cols.ncol + k;
            let b = STATE + COLUMN * m;
            let (dp, w) = (
                v3(lin.y, b),
                rotation_variation(&lin.r_tip, &col_rot(lin.y, b)),
            );
            let mut d = self
                .tip_rows_dot(&lin.dres[m], &dp, &w, &lin.r_tip)
                .to_vec();
            // The actuator's size: the force scale, or the pressure that makes it.
            let unit = match *col {
                Column::Pressure(q) => {
                    let (start, _) = model.chamber_extents()[q];
                    fs / model.chambers()[q].area_at(start)
                }
                _ => fs,
            };
            for held in lin.at {
                self.actuated_contact_rows(model, lin, held, (*col, m, unit), &mut d)?;
            }
            if d.len() != lin.n || !d.iter().all(|v| v.is_finite()) {
                return None;
            }
            out.rows.push(d);
            out.twist.push(twist_of(yo, Some(m)));
        }
        Some(out)
    }

    /// Appends to `d` the derivatives of the rows of the contact `held` along the actuator
    /// column `m` (the actuator `col` of size `unit`), by central differences of the rows
    /// with the node states moved along the column and the actuator changed.
    fn actuated_contact_rows(
        &self,
        model: &RobotModel,
        lin: &Linear<'_>,
        held: &RowsOf,
        (col, m, unit): (Column, usize, f64),
        d: &mut Vec<f64>,
    ) -> Option<()> {
        let (l, fs) = (self.model.length(), self.model.force_scale());
        let ((yf, kf), (yl, kl)) = (held.first, held.last);
        let (dyf, dyl) = match held.site {
            None => {
                let c = column_of(lin.y, Some(m));
                (c, c)
            }
            Some(i) => (
                column_of(&lin.sites[i].before.as_ref()?.0, Some(m)),
                column_of(&lin.sites[i].after.as_ref()?.0, Some(m)),
            ),
        };
        let h = ROW_STEP / scale(&dyf, l, fs).max(scale(&dyl, l, fs)).max(1.0 / unit);
        let nt = model.tendons().len();
        let side = |t: f64| -> Vec<f64> {
            let (mut tp, mut pp) = (self.tensions.clone(), self.pressures.clone());
            match col {
                Column::Tension(i) => tp[i] += t,
                Column::Pressure(q) => pp[q] += t,
                _ => {}
            }
            let eq2 = equations(model, &tp, &pp);
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
                s: held.s,
                first: (&yf2, kf),
                last: (&yl2, kl),
            };
            self.contact_rows(&mut ev2, &held.active, here, &held.f, lin.mu, &mut buf);
            buf
        };
        let (plus, minus) = (side(h), side(-h));
        d.extend(plus.iter().zip(&minus).map(|(p, q)| (p - q) / (2.0 * h)));
        Some(())
    }

    /// The march column of every unknown at `x` (none for a tip contact's force: six for the
    /// base wrench, then four per contact inside the rod, its arc length and force), those
    /// contacts, and the number of march columns.
    fn march_columns_of(&self, x: &[f64]) -> (Vec<Option<usize>>, Vec<Site2>, usize) {
        let l = self.model.length();
        let mut mcol: Vec<Option<usize>> = vec![None; self.dim()];
        for (k, m) in mcol.iter_mut().enumerate().take(6) {
            *m = Some(k);
        }
        // The contacts inside the rod (first unknown, arc length) in the order of the
        // contacts; their march columns in the order of their arc lengths (those of a contact
        // are zero before it, and the march integrates them from there: see
        // [`Self::march_with_columns`]).
        let interior: Vec<(usize, f64, Site)> = self
            .active
            .iter()
            .zip(self.offsets())
            .filter(|(a, _)| a.site != Site::Tip)
            .map(|(a, o)| (o, x[o] * l, a.site))
            .collect();
        let mut order: Vec<usize> = (0..interior.len()).collect();
        order.sort_by(|&a, &b| interior[a].1.total_cmp(&interior[b].1));
        let mut rank = vec![0; interior.len()];
        for (r, &i) in order.iter().enumerate() {
            rank[i] = r;
        }
        let mut sites: Vec<Site2> = Vec::with_capacity(interior.len());
        for (&(o, s, site), &r) in interior.iter().zip(&rank) {
            let column = 6 + 4 * r;
            for q in 0..4 {
                mcol[o + q] = Some(column + q);
            }
            let post_at = if site == Site::Interval {
                f64::from_bits(s.to_bits() + 1)
            } else {
                s
            };
            sites.push(Site2 {
                s,
                column,
                post_at,
                before: None,
                after: None,
                rate: [[0.0; STATE]; 2],
            });
        }
        (mcol, sites, 6 + 4 * interior.len())
    }

    /// One march at `x` of the state with the columns `cols` on the contact model `model`,
    /// the contacts inside the rod recorded and their columns seeded in `sites` (`scratch`
    /// evaluates the sides of their jumps), the columns kept at node `observe`. `None` if
    /// the march fails or does not reach every contact or the observed node.
    fn march_with_columns<const N: usize>(
        &mut self,
        model: &RobotModel,
        x: &[f64],
        sites: &mut [Site2],
        cols: &MarchColumns<'_>,
        observe: Option<usize>,
        scratch: &mut Scratch,
    ) -> Option<ColumnMarch<N>> {
        let l = self.model.length();
        let fs = self.model.force_scale();
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
        let eq = equations(model, &self.tensions, &self.pressures);
        let mut ws = scratch.march_workspace(model.tendons().len());
        ws.track_lengths = false;
        // Without actuator columns (after the unknowns'), a contact's columns, zero before
        // it, are integrated from its arc length on (they are in the order of the arc
        // lengths): until then only the base wrench's six.
        let from_sites = cols.actuators.is_empty();
        let mut columns = vec![Column::Free; if from_sites { 6 } else { cols.ncol }];
        columns.extend_from_slice(cols.actuators);
        ws.set_columns(&columns, &[]);
        let y0: [f64; N] = eq.initial(&x[..6]);
        let mut nodes = scratch.node_buffer();
        let mut observed: Option<Vec<f64>> = None;
        let y = {
            let mut ev = Evaluator { eq, ws: &mut ws };
            let mut side = Evaluator {
                eq,
                ws: &mut scratch.sides[0],
            };
            let nodes = &mut nodes;
            let sites = &mut *sites;
            march(
                &mut ev,
                model.breaks(),
                &[],
                y0,
                scheme,
                |ev, s, interval, y: &mut [f64; N]| {
                    for site in sites.iter_mut().filter(|c| c.s == s) {
                        site.record(&mut side, s, interval, y, (l, fs));
                        if from_sites && site.after.is_some() {
                            let seeded = site.column + 4;
                            if ev.ws.columns.len() < seeded {
                                ev.ws.columns.resize(seeded, Column::Free);
                            }
                        }
                    }
                    if observe == Some(nodes.len()) {
                        observed = Some(y.to_vec());
                    }
                    nodes.push(Node {
                        s,
                        interval,
                        y: head(y),
                    });
                },
            )
            .ok()
        };
        self.evaluations += ws.evaluations + scratch.side_evaluations();
        scratch.keep(ws, None);
        let y = y?;
        if !y[..STATE].iter().all(|v| v.is_finite()) || sites.iter().any(|c| c.after.is_none()) {
            return None;
        }
        if observe.is_some() && observed.is_none() {
            return None;
        }
        Some(ColumnMarch { y, nodes, observed })
    }

    /// Appends to `rows` the rows of every active contact from its node states (the tip's
    /// `tip` state and interval for a tip contact; the recorded sides of `sites` inside the
    /// rod), and returns per contact what they are a function of.
    fn contact_rows_at(
        &self,
        ev: &mut [Evaluator<'_, '_>; 2],
        x: &[f64],
        mu: f64,
        (tip_y, tip_k): ([f64; STATE], usize),
        sites: &[Site2],
        rows: &mut Vec<f64>,
    ) -> Option<Vec<RowsOf>> {
        let l = self.model.length();
        let mut interior = 0;
        let mut at = Vec::with_capacity(self.active.len());
        for (a, o) in self.active.iter().zip(self.offsets()) {
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
            self.contact_rows(ev, a, held, &f, mu, rows);
            at.push(RowsOf {
                active: *a,
                s,
                first: (yf, kf),
                last: (yl, kl),
                f,
                site,
                o,
            });
        }
        Some(at)
    }

    /// Column `c` of the Jacobian into `j` (the tip rows from the tip columns, the contact
    /// rows by central differences along the column); returns the tip twist of the column.
    fn jacobian_column(
        &self,
        ev: &mut [Evaluator<'_, '_>; 2],
        lin: &Linear<'_>,
        c: usize,
        j: &mut [f64],
        buf: &mut Vec<f64>,
    ) -> Option<nalgebra::Vector6<f64>> {
        let n = lin.n;
        let (dres_c, dp, w) = match lin.mcol[c] {
            Some(m) => {
                let b = STATE + COLUMN * m;
                (
                    lin.dres[m],
                    v3(lin.y, b),
                    rotation_variation(&lin.r_tip, &col_rot(lin.y, b)),
                )
            }
            None => {
                // A tip contact's force: the tip balance alone.
                let mut d = nalgebra::Vector6::zeros();
                let q = (c - lin.offsets.iter().rev().find(|o| **o <= c).copied()?) % 3;
                d[q] = -1.0;
                (d, Vector3::zeros(), Vector3::zeros())
            }
        };
        let tip = self.tip_rows_dot(&dres_c, &dp, &w, &lin.r_tip);
        j[n * c..n * c + 6].copy_from_slice(&tip);
        let mut row = 6;
        for held in lin.at {
            let size = held.active.size();
            let out = &mut j[n * c + row..n * c + row + size];
            self.contact_entries(ev, lin, held, (c, row), out, buf)?;
            row += size;
        }
        Some(nalgebra::Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z))
    }

    /// The derivatives `out` of the rows (from row `row`) of the contact `held` along column
    /// `c`: its node states moved along the column (and, for its own arc length, along the
    /// rod; for its own force, the force), by central differences (one-sided when `rough`).
    fn contact_entries(
        &self,
        ev: &mut [Evaluator<'_, '_>; 2],
        lin: &Linear<'_>,
        held: &RowsOf,
        (c, row): (usize, usize),
        out: &mut [f64],
        buf: &mut Vec<f64>,
    ) -> Option<()> {
        let l = self.model.length();
        let fs = self.model.force_scale();
        let (s, f, o) = (held.s, held.f, held.o);
        let ((yf, kf), (yl, kl)) = (held.first, held.last);
        let (mut ds, mut df) = (0.0, Vector3::zeros());
        let (mut dyf, mut dyl) = match held.site {
            None => {
                let d = column_of(lin.y, lin.mcol[c]);
                (d, d)
            }
            Some(i) => (
                column_of(&lin.sites[i].before.as_ref()?.0, lin.mcol[c]),
                column_of(&lin.sites[i].after.as_ref()?.0, lin.mcol[c]),
            ),
        };
        let first_force = if held.site.is_some() { o + 1 } else { o };
        if held.site.is_some() && c == o {
            // The contact's own arc length: both sides move with the state before
            // the jump.
            let i = held.site?;
            ds = l;
            for k in 0..STATE {
                dyf[k] += lin.sites[i].rate[0][k] * l;
                dyl[k] += lin.sites[i].rate[1][k] * l;
            }
        }
        if (first_force..first_force + 3).contains(&c) {
            df[c - first_force] = 1.0;
        }
        let nu = scale(&dyf, l, fs)
            .max(scale(&dyl, l, fs))
            .max(ds / l)
            .max(df.amax());
        if nu == 0.0 {
            out.fill(0.0);
            return Some(());
        }
        let h = ROW_STEP / nu;
        let a = &held.active;
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
            self.contact_rows(ev, a, moved, &f2, lin.mu, buf);
        };
        eval(h, buf);
        let plus = buf.clone();
        let size = out.len();
        if self.rough {
            // One-sided, from the rows at the point.
            let at = &lin.rows[row..row + size];
            for i in 0..size {
                out[i] = (plus[i] - at[i]) / h;
            }
        } else {
            eval(-h, buf);
            for i in 0..size {
                out[i] = (plus[i] - buf[i]) / (2.0 * h);
            }
        }
        Some(())
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
