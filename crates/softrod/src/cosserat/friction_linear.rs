//! The actuation Jacobian of a frictional equilibrium: a one-sided (directional) derivative
//! with the tension profile part of the variational state of the frictional march.
//!
//! Continued from the solution (the solution its own previous state), a small change of an
//! input in one direction keeps every tendon element in the state the nonlinear solve gives
//! it. With `τ_k` the tension at node `k`, `Δθ_k` the turning of the path over the cell
//! `[s_k, s_k+1]` and `lo = τ_k e^(−μΔθ)`, `hi = τ_k e^(+μΔθ)` its capstan bounds, the solve
//! with `previous` sets `τ'_k+1 = clamp(τ_k+1, lo', hi')`, so to first order
//!
//! ```text
//! δτ_k+1 = max(0, δlo)   at the lower bound (sliding toward the base),
//! δτ_k+1 = min(0, δhi)   at the upper bound (sliding toward the tip),
//! δτ_k+1 = 0             strictly inside the bounds (sticking),
//! δlo = e^(−μΔθ) (δτ_k − μ τ_k δΔθ_k),   δhi = e^(+μΔθ) (δτ_k + μ τ_k δΔθ_k),
//! ```
//!
//! (both bounds at once, `Δθ = 0`: `clamp(0, δlo, δhi)`), `δΔθ_k` the change of the angle
//! between the path tangents at the two nodes, which depend on the strains there and so on
//! the shape variation and on `δτ` at the node. An element at its bound slides on if the
//! change pushes it further and sticks otherwise. The rule is piecewise linear in the
//! direction of the change: pulling a tendon (`+δτ_0`) and releasing it (`−δτ_0`) give
//! different columns ([`Direction`]).
//!
//! **Variational march.** The columns `(δp, δR, δN, δM)` are integrated with the state over
//! every cell of the friction mesh as in the frictionless linearisation, each with its own
//! `δτ` per tendon: the profile's variation over the cell (the derivative of its geometric
//! interpolation between `δτ_k` and `δτ_k+1`) forces the constitutive split as a change of
//! the tendons' tension does. `δτ_k+1` enters the step it results from: one extra column per
//! frictional tendon (zero at the proximal node, a unit distal tension variation) makes the
//! distal state affine in `δτ_k+1`, and the rule above is then a small piecewise-linear
//! system per cell, solved by choosing every element's branch until the choices agree with
//! the signs of `δlo`, `δhi` they produce.
//!
//! **Loaded rods.** With external loads the base wrench changes too: the six base-wrench
//! columns carry their own `δτ`, on the branches the actuation column chose, and the base
//! wrench change `δx` solves the tip condition. The branches depend on `δx`, so the march is
//! repeated from the new `δx` until the branches of two successive marches agree (then the
//! last solve is exact on them).

use nalgebra::{DMatrix, Matrix6, Vector3, Vector6};

use super::equations::{
    col_rot, rot, rotation_variation, v3, Column, Equations, Evaluator, Workspace, COLUMN, DM, DN,
    STATE,
};
use super::friction::angle;
use super::friction_cell::{angle_variation, Bounds, Branch, CellRule, CellSystem, NodeLin};
use super::friction_march::Cell;
use super::statics::{Integrator, StaticsSolution};
use crate::error::{Error, Result};
use crate::integrate::{adaptive, fixed, DP5, RK4};
use crate::model::actuation::TensionProfile;
use crate::model::RobotModel;

/// Relative distance of a tension to its capstan bound within which the element is taken
/// at the bound (sliding on if pushed further): the tension profile of a solution is
/// resolved to the friction tolerance (`1e-9` by default), far below this.
pub const BOUND_TOLERANCE: f64 = 1e-7;

/// Cap on the marches of a loaded rod (the branches of the elements chosen again from the
/// last base-wrench change).
pub const MAX_BRANCH_PASSES: usize = 20;

/// The direction of the one-sided derivative of a frictional equilibrium.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Direction {
    /// The derivative for an increasing input (`(f(a + h e) − f(a)) / h`, `h → 0+`).
    #[default]
    Pull,
    /// The derivative for a decreasing input (`(f(a) − f(a − h e)) / h`, `h → 0+`).
    Release,
}

impl Direction {
    /// `+1` (pull) or `−1` (release).
    pub fn sign(self) -> f64 {
        match self {
            Direction::Pull => 1.0,
            Direction::Release => -1.0,
        }
    }
}

/// What the actuation column differentiates with respect to.
#[derive(Debug, Clone, Copy)]
enum Input {
    Tendon(usize),
    Pressure(usize),
    /// Component `k` of a dead world-frame wrench added at the tip (force, then moment).
    TipWrench(usize),
}

/// The solution's data the variational march needs.
pub(super) struct Frozen<'a> {
    pub(super) model: &'a RobotModel,
    pub(super) mesh: &'a [f64],
    /// Tension per node and tendon (N; 0 where the tendon is not).
    pub(super) tau: Vec<Vec<f64>>,
    pub(super) base: Vec<f64>,
    pub(super) pressures: Vec<f64>,
    pub(super) mus: Vec<f64>,
    pub(super) x: [f64; 6],
    pub(super) integrator: Integrator,
    /// Base-wrench columns (0 when the base wrench cannot change: no internal force).
    pub(super) nb: usize,
}

impl<'a> Frozen<'a> {
    /// The frozen state of `solution` (friction coefficients `mus`), with the six
    /// base-wrench columns.
    fn of(solution: &'a StaticsSolution, mus: &[f64]) -> Result<Self> {
        let model = &*solution.model;
        Ok(Self {
            model,
            mesh: &solution.s,
            tau: node_tensions(solution, mus)?,
            base: solution.tendon_tensions.clone(),
            pressures: solution.pressures(),
            mus: mus.to_vec(),
            x: super::statics::scaled(model, &solution.base_wrench),
            integrator: solution.options.integrator,
            nb: 6,
        })
    }

    pub(super) fn present(&self, i: usize, s: f64) -> bool {
        let (ends, l) = (self.model.tendon_ends(), self.model.length());
        s < ends[i] || (ends[i] == l && s == l)
    }
}

/// One variational march.
struct Pass {
    /// Per node, per main column (the input's, then the base-wrench ones), `(δp, δθ)`.
    poses: Vec<Vec<Vector6<f64>>>,
    /// Per main column, the derivative of the scaled tip residual.
    residual: Vec<Vector6<f64>>,
    /// The branches the input's column took, cell by cell.
    branches: Vec<Branch>,
}

/// Column `c`'s pose change at state `y`.
fn pose_of(y: &[f64], c: usize) -> Vector6<f64> {
    let b0 = STATE + COLUMN * c;
    let (dp, w) = (v3(y, b0), rotation_variation(&rot(y), &col_rot(y, b0)));
    Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
}

/// The variational march of the inputs `inputs` in the direction `sigma` (±1), one column
/// each with its own slip branches; with the base-wrench columns if `fr.nb` (then one input,
/// the base wrench changed by `dx` (scaled) at the base, the base-wrench columns on its
/// branches).
fn march<const N: usize>(
    fr: &Frozen<'_>,
    inputs: &[Input],
    sigma: f64,
    dx: &[f64; 6],
) -> Result<Pass> {
    let nt = fr.base.len();
    let ctx = Marcher {
        fr,
        inputs,
        sigma,
        nt,
        nm: inputs.len() + fr.nb,
        profiled: fr.mus.iter().map(|&m| m > 0.0).collect(),
    };
    let breaks = fr.model.breaks();
    let mut cell = TensionProfile::new(
        (0..nt)
            .map(|i| (fr.mus[i] > 0.0).then(|| (vec![0.0, 1.0], vec![fr.base[i]; 2])))
            .collect(),
    );
    let mut ws = Workspace::new(nt);
    let mut at = ctx.start::<N>(&cell, &mut ws, dx)?;
    let n = fr.mesh.len();
    let mut poses = Vec::with_capacity(n);
    poses.push((0..ctx.nm).map(|c| pose_of(&at.y, c)).collect::<Vec<_>>());
    let mut branches = Vec::new();
    for c in Cell::along(fr.mesh, breaks) {
        let first = ctx.cell(&mut cell, &mut ws, &mut at, c)?;
        branches.extend_from_slice(&first);
        poses.push((0..ctx.nm).map(|c| pose_of(&at.y, c)).collect());
    }
    let (_, residual) = ctx.eq().residual(&at.y, ctx.nm);
    Ok(Pass {
        poses,
        residual,
        branches,
    })
}

/// What the variational march carries from node to node: the state with its main columns,
/// per main column and tendon `δτ`, the tendons' path tangents and, per main column, their
/// variations.
struct At<const N: usize> {
    y: [f64; N],
    dtau: Vec<Vec<f64>>,
    ta: Vec<Option<Vector3<f64>>>,
    dta: Vec<Vec<Option<Vector3<f64>>>>,
}

/// The cell rule of one cell and, per main column, the constant parts `lo`, `hi` of its
/// bounds.
type RuleParts = (CellRule, Vec<Vec<f64>>, Vec<Vec<f64>>);

/// The distal tension changes of one cell: the frictional tendons whose distal change is an
/// unknown of the cell rule, and per tendon the ratio of a slack tendon's distal to its
/// proximal change (1 for the others).
struct Distal {
    unknown: Vec<usize>,
    ratio: Vec<f64>,
}

/// The fixed data of one variational march: the frozen solution, the inputs and their
/// direction, the number of tendons and of main columns (the inputs', then the base-wrench
/// ones), and which tendons carry a tension profile.
struct Marcher<'f, 'a, 'i> {
    fr: &'f Frozen<'a>,
    inputs: &'i [Input],
    sigma: f64,
    nt: usize,
    nm: usize,
    profiled: Vec<bool>,
}

impl Marcher<'_, '_, '_> {
    /// The equations at the solution's base tensions (no profile).
    fn eq(&self) -> Equations<'_> {
        Equations::new(self.fr.model, &self.fr.base, &self.fr.pressures)
    }

    /// A chamber's pressure change (per Pa) along column `c`.
    fn pressure_of(&self, c: usize) -> Option<(usize, f64)> {
        match self.inputs.get(c) {
            Some(Input::Pressure(j)) => Some((*j, self.sigma)),
            _ => None,
        }
    }

    /// The state at the base: the base wrench changed by `dx` along the input's column, the
    /// base-wrench columns seeded, the inputs' tension changes and the tangents there.
    fn start<const N: usize>(
        &self,
        cell: &TensionProfile,
        ws: &mut Workspace,
        dx: &[f64; 6],
    ) -> Result<At<N>> {
        let (fr, nt, nm) = (self.fr, self.nt, self.nm);
        let f_ref = fr.model.force_scale();
        let fm = f_ref * fr.model.length();
        let eq = self.eq();
        let mut y: [f64; N] = eq.initial(&fr.x);
        y[STATE..].fill(0.0);
        for k in 0..3 {
            y[STATE + DN + k] = f_ref * dx[k];
            y[STATE + DM + k] = fm * dx[3 + k];
        }
        for k in 0..fr.nb {
            let b0 = STATE + COLUMN * (self.inputs.len() + k);
            if k < 3 {
                y[b0 + DN + k] = f_ref;
            } else {
                y[b0 + DM + k - 3] = fm;
            }
        }
        // δτ per main column and tendon at the current node.
        let mut dtau = vec![vec![0.0; nt]; nm];
        for (c, input) in self.inputs.iter().enumerate() {
            if let Input::Tendon(k) = input {
                dtau[c][*k] = self.sigma;
            }
        }
        let mut ev = Evaluator {
            eq: Equations {
                profile: Some(cell),
                ..eq
            },
            ws,
        };
        ev.set_interval(0);
        let node = NodeLin::at(fr, &mut ev, 0.0, &y)?;
        let dta: Vec<_> = (0..nm)
            .map(|c| node.variation(&y, STATE + COLUMN * c, &dtau[c], self.pressure_of(c)))
            .collect();
        Ok(At {
            y,
            dtau,
            ta: node.tangents(),
            dta,
        })
    }

    /// Steps `at` over the cell `c`: the tension profile over the cell, the cell step of the
    /// state with the main columns and one column per unknown distal change, the cell rule,
    /// and the main columns with their distal changes on their branches. Returns the
    /// branches of the first input's column.
    fn cell<const N: usize>(
        &self,
        cell: &mut TensionProfile,
        ws: &mut Workspace,
        at: &mut At<N>,
        c: Cell,
    ) -> Result<Vec<Branch>> {
        let ends = self.ends(cell, c);
        let distal = self.distal(cell, ws, at, c)?;
        let nq = distal.unknown.len();
        let ncols = self.nm + nq;
        let width = (N - STATE) / COLUMN;
        if ncols > width {
            return Err(Error::invalid(
                "tendons",
                format!("{nq} frictional tendons"),
                format!("at most {} frictional tendons", width - self.nm),
            ));
        }
        let coef = self.coefficients(&at.dtau, &distal);
        let (y1, node) = self.step(cell, ws, at, c, &ends, &coef)?;
        let tb = node.tangents();
        let at_node = |col: usize| -> Vec<f64> {
            (0..self.nt)
                .map(|i| {
                    if !self.fr.present(i, c.b) {
                        0.0
                    } else if col >= self.nm {
                        f64::from(u8::from(distal.unknown[col - self.nm] == i))
                    } else {
                        coef[col][i][1]
                    }
                })
                .collect()
        };
        let mut dtb: Vec<Vec<Option<Vector3<f64>>>> = (0..ncols)
            .map(|col| {
                node.variation(
                    &y1,
                    STATE + COLUMN * col,
                    &at_node(col),
                    self.pressure_of(col),
                )
            })
            .collect();
        let (rule, lo, hi) = self.rule(at, &tb, &dtb, &ends, &distal.unknown, c.b)?;
        // Each input's column on its own branches, the base-wrench ones on the first's.
        let n_in = self.inputs.len();
        let mut zs = Vec::with_capacity(self.nm);
        let mut first = Vec::new();
        for col in 0..n_in {
            let (br, z) = rule.branches(&lo[col], &hi[col])?;
            if col == 0 {
                first = br;
            }
            zs.push(z);
        }
        for col in n_in..self.nm {
            zs.push(rule.solve(&first, &lo[col], &hi[col])?);
        }
        self.advance(at, &y1, &zs, &mut dtb, &distal, c.b);
        dtb.truncate(self.nm);
        at.dta = dtb;
        at.ta = tb;
        Ok(first)
    }

    /// Per tendon, its tensions at the ends of cell `c` (N), set as the cell of the profile
    /// of the frictional ones.
    fn ends(&self, cell: &mut TensionProfile, c: Cell) -> Vec<[f64; 2]> {
        let (fr, j) = (self.fr, c.j);
        let mut ends = vec![[0.0; 2]; self.nt];
        for i in 0..self.nt {
            let distal = if fr.present(i, c.b) {
                fr.tau[j + 1][i]
            } else {
                fr.tau[j][i]
            };
            ends[i] = [fr.tau[j][i], distal];
            if fr.mus[i] > 0.0 {
                cell.set_cell(i, [c.a, c.b], ends[i]);
            }
        }
        ends
    }

    /// The unknown distal changes of cell `c`. A slack tendon (zero tension at both nodes)
    /// keeps the ratio e^(−μΔθ) of its distal to its proximal tension change (the term in
    /// δΔθ vanishes with τ): its Δθ from the state stepped alone; the others' distal
    /// changes are unknowns.
    fn distal<const N: usize>(
        &self,
        cell: &TensionProfile,
        ws: &mut Workspace,
        at: &At<N>,
        c: Cell,
    ) -> Result<Distal> {
        let (fr, j, b) = (self.fr, c.j, c.b);
        let slack: Vec<usize> = (0..self.nt)
            .filter(|&i| {
                fr.mus[i] > 0.0
                    && fr.present(i, b)
                    && fr.tau[j][i] == 0.0
                    && fr.tau[j + 1][i] == 0.0
            })
            .collect();
        let ratio = if slack.is_empty() {
            vec![1.0; self.nt]
        } else {
            slack_ratios(fr, ws, cell, &at.y, c, &at.ta)?
        };
        let unknown: Vec<usize> = (0..self.nt)
            .filter(|&i| fr.mus[i] > 0.0 && fr.present(i, b) && !slack.contains(&i))
            .collect();
        Ok(Distal { unknown, ratio })
    }

    /// Per column (the main ones, then one per unknown distal change) and tendon, its
    /// proximal and distal tension changes `(δτ_k, δτ_k+1)` over the cell (an unknown's
    /// distal change 0 in the main columns, 1 in its own).
    fn coefficients(&self, dtau: &[Vec<f64>], distal: &Distal) -> Vec<Vec<[f64; 2]>> {
        let (nm, nt) = (self.nm, self.nt);
        let mut coef = vec![vec![[0.0; 2]; nt]; nm + distal.unknown.len()];
        for c in 0..nm {
            for i in 0..nt {
                let d = dtau[c][i];
                coef[c][i] = [
                    d,
                    if distal.unknown.contains(&i) {
                        0.0
                    } else {
                        d * distal.ratio[i]
                    },
                ];
            }
        }
        for (q, &i) in distal.unknown.iter().enumerate() {
            coef[nm + q][i] = [0.0, 1.0];
        }
        coef
    }

    /// The cell step of the state and the columns `coef` over cell `c` (the jump at a break
    /// applied), and the linearisation at its end.
    fn step<const N: usize>(
        &self,
        cell: &TensionProfile,
        ws: &mut Workspace,
        at: &mut At<N>,
        c: Cell,
        ends: &[[f64; 2]],
        coef: &[Vec<[f64; 2]>],
    ) -> Result<([f64; N], NodeLin)> {
        let ncols = coef.len();
        let pressure: Vec<_> = (0..ncols).map(|col| self.pressure_of(col)).collect();
        at.y[STATE + COLUMN * self.nm..].fill(0.0);
        ws.set_columns(&vec![Column::Free; ncols], &[]);
        let mut sys = CellSystem {
            ev: Evaluator {
                eq: Equations {
                    profile: Some(cell),
                    ..self.eq()
                },
                ws,
            },
            a: c.a,
            b: c.b,
            ends,
            profiled: &self.profiled,
            dtau: coef,
            pressure: &pressure,
            dirs: vec![None; self.nt],
        };
        if sys.ev.ws.interval != c.interval {
            sys.ev.set_interval(c.interval);
        }
        let (a, b, y) = (c.a, c.b, at.y);
        let mut y1 = match self.fr.integrator {
            Integrator::Rk4 { .. } => fixed(&RK4, &mut sys, a, y, b, 1, |_, _, _| {})?,
            Integrator::Adaptive(o) => {
                adaptive(&DP5, &mut sys, [a, b], y, &o, STATE, |_, _, _| {})?.0
            }
        };
        if c.crosses {
            sys.ev.eq.jump(b, &mut y1, ncols);
            sys.ev.set_interval(c.interval + 1);
        }
        let node = NodeLin::at(self.fr, &mut sys.ev, b, &y1)?;
        Ok((y1, node))
    }

    /// The cell rule, affine in the distal changes z, from the tangents and their variations
    /// at both ends of the cell (`at`, and `tb`, `dtb` at `b`), and per main column its
    /// constant parts `lo`, `hi`.
    fn rule<const N: usize>(
        &self,
        at: &At<N>,
        tb: &[Option<Vector3<f64>>],
        dtb: &[Vec<Option<Vector3<f64>>>],
        ends: &[[f64; 2]],
        unknown: &[usize],
        b: f64,
    ) -> Result<RuleParts> {
        let (fr, nm, nq) = (self.fr, self.nm, unknown.len());
        let mut rule = CellRule {
            bounds: Vec::with_capacity(nq),
            l: DMatrix::zeros(nq, nq),
            h: DMatrix::zeros(nq, nq),
        };
        let mut lo = vec![vec![0.0; nq]; nm];
        let mut hi = vec![vec![0.0; nq]; nm];
        for (p, &i) in unknown.iter().enumerate() {
            let (Some(a_t), Some(b_t)) = (at.ta[i], tb[i]) else {
                continue;
            };
            let theta = angle(&a_t, &b_t);
            let mu = fr.mus[i];
            let g = (mu * theta).exp();
            let [t0, t1] = ends[i];
            let tol = BOUND_TOLERANCE * t0.max(t1);
            rule.bounds.push(Bounds {
                lower: (t1 - t0 / g).abs() <= tol,
                upper: (t1 - t0 * g).abs() <= tol,
            });
            let zero = Vector3::zeros();
            for c in 0..nm {
                let da = at.dta[c][i].unwrap_or(zero);
                let db = dtb[c][i].unwrap_or(zero);
                let dth = angle_variation(&a_t, &b_t, &da, &db);
                lo[c][p] = (at.dtau[c][i] - mu * t0 * dth) / g;
                hi[c][p] = g * (at.dtau[c][i] + mu * t0 * dth);
            }
            for q in 0..nq {
                let db = dtb[nm + q][i].unwrap_or(zero);
                let dth = angle_variation(&a_t, &b_t, &zero, &db);
                rule.l[(p, q)] = -mu * t0 * dth / g;
                rule.h[(p, q)] = g * mu * t0 * dth;
            }
        }
        if rule.bounds.len() != nq {
            return Err(Error::NotConverged {
                what: format!(
                    "frictional linearisation: a tendon has no path tangent at s = {b} m"
                ),
                iterations: 0,
                residual: f64::INFINITY,
                load_factor: 1.0,
            });
        }
        Ok((rule, lo, hi))
    }

    /// The main columns at the end `b` of the cell (state `y1`) with their distal tension
    /// changes `zs`: the unknowns' columns added, the tangent variations `dtb` and the
    /// tension changes `δτ` of `at` updated.
    fn advance<const N: usize>(
        &self,
        at: &mut At<N>,
        y1: &[f64; N],
        zs: &[Vec<f64>],
        dtb: &mut [Vec<Option<Vector3<f64>>>],
        distal: &Distal,
        b: f64,
    ) {
        let (nm, nt) = (self.nm, self.nt);
        let mut y_next = *y1;
        for (c, z) in zs.iter().enumerate() {
            let b0 = STATE + COLUMN * c;
            for (q, zq) in z.iter().enumerate() {
                let bq = STATE + COLUMN * (nm + q);
                for k in 0..COLUMN {
                    y_next[b0 + k] += zq * y1[bq + k];
                }
                for i in 0..nt {
                    if let (Some(d), Some(dq)) = (dtb[c][i], dtb[nm + q][i]) {
                        dtb[c][i] = Some(d + dq * *zq);
                    }
                }
            }
            for i in 0..nt {
                at.dtau[c][i] = match distal.unknown.iter().position(|&u| u == i) {
                    Some(p) => z[p],
                    None if self.fr.present(i, b) => at.dtau[c][i] * distal.ratio[i],
                    None => 0.0,
                };
            }
        }
        at.y = y_next;
    }
}

/// Per tendon, `e^(−μΔθ)` over the cell `c` from the state `y` (stepped alone, the path
/// tangents `ta` at its start); 1 for the tendons without friction.
fn slack_ratios<const N: usize>(
    fr: &Frozen<'_>,
    ws: &mut Workspace,
    cell: &TensionProfile,
    y: &[f64; N],
    c: Cell,
    ta: &[Option<Vector3<f64>>],
) -> Result<Vec<f64>> {
    let Cell {
        a,
        b,
        interval,
        crosses,
        ..
    } = c;
    let eq = Equations {
        model: fr.model,
        tensions: &fr.base,
        pressures: &fr.pressures,
        load_factor: 1.0,
        profile: Some(cell),
    };
    ws.set_columns(&[], &[]);
    let mut ev = Evaluator { eq, ws };
    if ev.ws.interval != interval {
        ev.set_interval(interval);
    }
    let mut ys = [0.0; STATE];
    ys.copy_from_slice(&y[..STATE]);
    let mut y1 = match fr.integrator {
        Integrator::Rk4 { .. } => fixed(&RK4, &mut ev, a, ys, b, 1, |_, _, _| {})?,
        Integrator::Adaptive(o) => adaptive(&DP5, &mut ev, [a, b], ys, &o, STATE, |_, _, _| {})?.0,
    };
    if crosses {
        ev.eq.jump(b, &mut y1, 0);
        ev.set_interval(interval + 1);
    }
    let tb = NodeLin::at(fr, &mut ev, b, &y1)?.tangents();
    Ok((0..fr.base.len())
        .map(|i| match (ta[i], tb[i]) {
            (Some(x), Some(z)) if fr.mus[i] > 0.0 => (-fr.mus[i] * angle(&x, &z)).exp(),
            _ => 1.0,
        })
        .collect())
}

/// The one-sided derivative of the poses at every node along `input` in `direction`
/// (per unit input, sign included: the release column is `(f(a) − f(a − h e)) / h`).
fn directional<const N: usize>(
    fr: &Frozen<'_>,
    input: Input,
    direction: Direction,
) -> Result<Vec<Vector6<f64>>> {
    let sigma = direction.sign();
    let mut dx = [0.0; 6];
    let mut last: Option<Vec<Branch>> = None;
    for pass in 0..MAX_BRANCH_PASSES {
        let p = march::<N>(fr, &[input], sigma, &dx)?;
        if fr.nb == 0 {
            return Ok(p.poses.iter().map(|c| c[0] * sigma).collect());
        }
        let d = Matrix6::from_columns(&p.residual[1..7]);
        let mut r0 = p.residual[0];
        if let Input::TipWrench(k) = input {
            // The scaled tip residual `(N(L) − F) / f_ref`, `(M(L) − M) / (f_ref L)`.
            let f_ref = fr.model.force_scale();
            r0[k] -= sigma
                / if k < 3 {
                    f_ref
                } else {
                    f_ref * fr.model.length()
                };
        }
        let step = d.lu().solve(&(-r0)).ok_or_else(|| Error::NotConverged {
            what: "frictional linearisation: singular shooting Jacobian".into(),
            iterations: pass + 1,
            residual: f64::INFINITY,
            load_factor: 1.0,
        })?;
        if last.as_ref() == Some(&p.branches) {
            return Ok(p
                .poses
                .iter()
                .map(|c| {
                    let mut t = c[0];
                    for k in 0..6 {
                        t += c[1 + k] * step[k];
                    }
                    t * sigma
                })
                .collect());
        }
        last = Some(p.branches);
        for k in 0..6 {
            dx[k] += step[k];
        }
    }
    Err(Error::NotConverged {
        what: format!(
            "frictional linearisation: the slip branches did not settle in \
             {MAX_BRANCH_PASSES} marches"
        ),
        iterations: MAX_BRANCH_PASSES,
        residual: f64::INFINITY,
        load_factor: 1.0,
    })
}

/// The tension per node and tendon of a frictional solution (its profile at its mesh).
fn node_tensions(solution: &StaticsSolution, mus: &[f64]) -> Result<Vec<Vec<f64>>> {
    let model = &*solution.model;
    let (ends, l) = (model.tendon_ends(), model.length());
    let nt = mus.len();
    let mesh = &solution.s;
    let profile = solution.actuation.profile.as_deref();
    let mut tau = vec![vec![0.0; nt]; mesh.len()];
    for i in 0..nt {
        let track = profile.and_then(|p| p.tendon(i)).filter(|_| mus[i] > 0.0);
        for (j, &s) in mesh.iter().enumerate() {
            if !(s < ends[i] || (ends[i] == l && s == l)) {
                continue;
            }
            tau[j][i] = match track {
                Some((nodes, vals)) if nodes.get(j) == Some(&s) => vals[j],
                Some(_) => {
                    return Err(Error::invalid(
                        "solution",
                        "a tension profile off its mesh",
                        "a frictional solution at its friction mesh",
                    ))
                }
                None => solution.tendon_tensions[i],
            };
        }
    }
    Ok(tau)
}

/// Width of a state with `c` columns.
const fn width(c: usize) -> usize {
    STATE + COLUMN * c
}

/// The one-sided actuation Jacobians of a frictional equilibrium `solution` (a
/// [`crate::FrictionalSolution`]'s `statics`) at the nodes `nodes` (increasing, distinct),
/// in `direction`: per node, `d[δp; δθ]` (world; m, rad) per N of each tendon's base tension,
/// then per Pa of each chamber's pressure; 6 × (n_tendons + n_chambers). The release column
/// of a slack tendon (zero tension) is zero: it cannot be released.
///
/// # Errors
/// [`Error::NotConverged`] if a constitutive solve fails, or the slip branches do not settle.
pub(crate) fn frictional_actuation_jacobians(
    solution: &StaticsSolution,
    nodes: &[usize],
    direction: Direction,
) -> Result<Vec<DMatrix<f64>>> {
    let model = &*solution.model;
    let nt = model.tendons().len();
    let nc = model.chambers().len();
    let mus: Vec<f64> = model.tendons().iter().map(|t| t.friction()).collect();
    let mut fr = Frozen::of(solution, &mus)?;
    if fr.x[..3].iter().all(|v| *v == 0.0) && model.force_free() {
        fr.nb = 0;
    }
    let nb = fr.nb;
    let frictional = mus.iter().filter(|&&m| m > 0.0).count();
    let need = 1 + nb + frictional;
    let mut out = vec![DMatrix::zeros(6, nt + nc); nodes.len()];
    let inputs: Vec<(usize, Input)> = (0..nt)
        .map(Input::Tendon)
        .chain((0..nc).map(Input::Pressure))
        .enumerate()
        .filter(|(_, input)| match (input, direction) {
            (Input::Tendon(k), Direction::Release) => fr.base[*k] != 0.0,
            _ => true,
        })
        .collect();
    if nb == 0 {
        // No base-wrench change: every input's column in one march (as many as fit).
        let per = (width(24) - STATE) / COLUMN - frictional;
        for chunk in inputs.chunks(per.max(1)) {
            let ins: Vec<Input> = chunk.iter().map(|(_, i)| *i).collect();
            let sigma = direction.sign();
            let p = match chunk.len() + frictional {
                0..=6 => march::<{ width(6) }>(&fr, &ins, sigma, &[0.0; 6])?,
                7..=12 => march::<{ width(12) }>(&fr, &ins, sigma, &[0.0; 6])?,
                13..=18 => march::<{ width(18) }>(&fr, &ins, sigma, &[0.0; 6])?,
                _ => march::<{ width(24) }>(&fr, &ins, sigma, &[0.0; 6])?,
            };
            for (c, (col, _)) in chunk.iter().enumerate() {
                for (m, &node) in out.iter_mut().zip(nodes) {
                    m.set_column(*col, &(p.poses[node][c] * sigma));
                }
            }
        }
        return Ok(out);
    }
    for (col, input) in inputs {
        let poses = match need {
            0..=6 => directional::<{ width(6) }>(&fr, input, direction)?,
            7..=12 => directional::<{ width(12) }>(&fr, input, direction)?,
            13..=18 => directional::<{ width(18) }>(&fr, input, direction)?,
            _ => directional::<{ width(24) }>(&fr, input, direction)?,
        };
        for (m, &node) in out.iter_mut().zip(nodes) {
            m.set_column(col, &poses[node]);
        }
    }
    Ok(out)
}

/// The one-sided tangent compliance of a frictional equilibrium `solution` at its tip: per
/// column `k`, the derivative of the tip twist `[δp; δθ]` (world; m, rad) for a dead
/// world-frame tip wrench `[f; m]` (N, N m) growing along `+e_k` ([`Direction::Pull`]) or
/// along `−e_k` ([`Direction::Release`]; the column is then `(f(0) − f(−h e_k)) / h`), the
/// tension profile following the same stick/slip rule as the actuation Jacobian (tendons at
/// fixed base tension). The columns need not form a symmetric matrix: each is the derivative
/// along its own direction.
///
/// # Errors
/// [`Error::NotConverged`] if a constitutive solve fails or the slip branches do not settle.
pub fn frictional_tip_compliance(
    solution: &StaticsSolution,
    direction: Direction,
) -> Result<Matrix6<f64>> {
    let model = &*solution.model;
    let mus: Vec<f64> = model.tendons().iter().map(|t| t.friction()).collect();
    let fr = Frozen::of(solution, &mus)?;
    let need = 7 + mus.iter().filter(|&&m| m > 0.0).count();
    let mut out = Matrix6::zeros();
    for k in 0..6 {
        let input = Input::TipWrench(k);
        let poses = match need {
            0..=12 => directional::<{ width(12) }>(&fr, input, direction)?,
            13..=18 => directional::<{ width(18) }>(&fr, input, direction)?,
            _ => directional::<{ width(24) }>(&fr, input, direction)?,
        };
        out.set_column(k, &poses[poses.len() - 1]);
    }
    Ok(out)
}
