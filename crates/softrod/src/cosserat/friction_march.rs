//! The frictional march: the tension profile a state of one march from the base (the capstan
//! rule applied cell by cell), for a given base wrench; the unloaded equilibrium in one march
//! (the base wrench is zero) and the loaded one by Newton's method on the base wrench, every
//! iterate one frictional march with the six base-wrench columns.
//!
//! Over a cell of the friction mesh the distal tension `τ_{k+1}` sets the profile the rod is
//! integrated with (geometric between the nodes) and the capstan rule on the resulting shape
//! sets `τ_{k+1}`: the cell is repeated from its proximal node until the two agree to
//! [`FrictionOptions::tolerance`] times the largest base tension (a secant iteration from a
//! first guess extrapolated from the turning rate of the last cells).
//!
//! **Loaded models.** The columns are integrated with the cell profiles held fixed, so the
//! Jacobian they give misses the change of the profile with the base wrench. Newton's method
//! corrects it by a secant (Broyden) update of that missing part from the iterates, so the
//! steps converge superlinearly; the residual is the exact one of the march.

use std::sync::Arc;

use nalgebra::{Matrix6, Vector3, Vector6};

use super::friction::{
    angle, base_profile, base_slip, cell_rule, friction_forces, node_tangents, tangent_rows,
    to_profile, FrictionOptions, FrictionalSolution, Slip, BREAK_OFFSET,
};
use crate::cosserat::equations::{rot, v3, Column, Equations, Evaluator, Workspace, FULL, STATE};
use crate::cosserat::shooting::{Node, Shooting};
use crate::cosserat::stability::tip_stability;
use crate::cosserat::statics::{
    assemble, interior, scaled, scaled_back, solve_statics_at, Integrator, StaticsSolution,
    DIRECT_STEP_LIMIT, MAX_LOAD_STEP_TURN,
};
use crate::error::{Error, Result};
use crate::integrate::march::Piecewise;
use crate::integrate::{adaptive, fixed, DP5, RK4};
use crate::model::actuation::TensionProfile;
use crate::model::{Actuation, RobotModel};
use crate::solve::SolverStats;

/// Cap on the evaluations of one cell of the frictional march (each one step of the rod over
/// the cell and a constitutive solve at its distal node).
pub const MAX_CELL_ATTEMPTS: usize = 60;

/// The next guess of the distal tensions of a cell from the last two attempts: per tendon, a
/// secant step on `rule(g) = g` (the rule's slope `ρ` from the two attempts) where `|ρ| < 0.9`,
/// else the rule's value (a fixed-point step).
fn next_guess(guess: &mut [f64], rule: &[f64], last: Option<(&[f64], &[f64])>) {
    for i in 0..guess.len() {
        let (g, r) = (guess[i], rule[i]);
        let mut next = r;
        if let Some((g0, r0)) = last {
            let rho = (r - r0[i]) / (g - g0[i]);
            if rho.is_finite() && rho.abs() < 0.9 {
                let secant = g + (r - g) / (1.0 - rho);
                if secant.is_finite() && secant >= 0.0 {
                    next = secant;
                }
            }
        }
        guess[i] = next;
    }
}

/// Extrapolation weights of the next value of a smooth sequence from its last `m` values
/// (polynomial of degree `m - 1`, most recent first).
const EXTRAPOLATION: [&[f64]; 4] = [
    &[1.0],
    &[2.0, -1.0],
    &[3.0, -3.0, 1.0],
    &[4.0, -6.0, 4.0, -1.0],
];

/// The turning rate (rad/m) of tendon `i` over the next cell, extrapolated from the last (up
/// to four) cells that inform it (`rates`: per cell and tendon, `None` for a cell shorter than
/// ten break offsets, across a break, or without the tendon); 0 without one.
fn extrapolated_rate(rates: &[Option<f64>], nt: usize, i: usize) -> f64 {
    let last = rates
        .chunks_exact(nt)
        .rev()
        .take(EXTRAPOLATION.len())
        .map_while(|r| r[i]);
    let values: Vec<f64> = last.collect();
    match values.len() {
        0 => 0.0,
        m => EXTRAPOLATION[m - 1]
            .iter()
            .zip(&values)
            .map(|(w, r)| w * r)
            .sum(),
    }
}

/// What one frictional march from a base wrench gives.
pub(super) struct Marched<const N: usize> {
    /// The state at the tip (with the base-wrench columns when `N == FULL`).
    pub y: [f64; N],
    /// The scaled tip residual and its columns (frozen profile; empty without columns).
    pub residual: Vector6<f64>,
    pub columns: Vec<Vector6<f64>>,
    /// Tension and slip state per node and tendon.
    pub tau: Vec<Vec<f64>>,
    pub slip: Vec<Vec<Slip>>,
    /// Path tangents per node and tendon.
    pub dirs: Vec<Vec<Option<Vector3<f64>>>>,
    /// The recorded nodes (state only).
    pub nodes: Vec<Node>,
    /// Path length per node and tendon, and the whole path lengths (m).
    pub path_length: Vec<Vec<f64>>,
    pub lengths: Vec<f64>,
    /// Cell steps, the largest accepted change of a cell (N), right-hand-side evaluations.
    pub cell_steps: usize,
    pub worst: f64,
    pub evaluations: usize,
}

/// What a frictional march needs besides its base wrench.
pub(super) struct Setup<'a> {
    pub model: &'a Arc<RobotModel>,
    pub actuation: &'a Actuation,
    pub options: &'a FrictionOptions,
    pub mesh: &'a [f64],
    pub base: &'a [f64],
    pub prev: Option<&'a [Vec<f64>]>,
}

impl Setup<'_> {
    /// The largest base tension (N; at least the smallest positive number).
    fn scale(&self) -> f64 {
        self.base
            .iter()
            .fold(0.0, |a: f64, &b| a.max(b))
            .max(f64::MIN_POSITIVE)
    }

    /// The model's pressures.
    fn pressures(&self) -> Vec<f64> {
        self.actuation.pressure_values(self.model.chambers().len())
    }
}

/// One march from the scaled base wrench `x` over the friction mesh with the tension a state
/// (see the module documentation); with `N == FULL` the six base-wrench columns are
/// integrated along (with the cell profiles held fixed: the cell is iterated on the state
/// alone, then stepped once more with the columns). `unloaded`: the total wrench is zero all
/// along (`x = 0`, no external load), so the strains at a node after an RK4 step are those
/// of its last stage. `hint`: the path tangents of a nearby march on the same mesh (the last
/// Newton iterate), whose turning over each cell is the first guess of its rule.
/// `cell_tolerance`: the change of a cell's distal tension, relative to the largest base
/// tension, that ends its iteration ([`FrictionOptions::tolerance`] but for the early
/// iterates of a loaded solve).
pub(super) fn march_cells<const N: usize>(
    setup: &Setup<'_>,
    x: &[f64; 6],
    unloaded: bool,
    hint: Option<&[Vec<Option<Vector3<f64>>>]>,
    cell_tolerance: f64,
) -> Result<Marched<N>> {
    let fixed = Fixed::new(setup, unloaded, hint, cell_tolerance);
    let mut march = CellMarch::<N>::start(fixed, x)?;
    for c in Cell::along(setup.mesh, setup.model.breaks()) {
        march.cell(c)?;
    }
    Ok(march.finish())
}

/// Per tendon, its unit path tangent (world) at a node, `None` where it is not there.
type Tangents = Vec<Option<Vector3<f64>>>;

/// Cell `j` of the friction mesh, `[a, b]` (m), the integration interval it starts in and
/// whether `b` is a break into the next one (the cells of this march and of the variational
/// march of `friction_linear`).
#[derive(Clone, Copy)]
pub(super) struct Cell {
    pub(super) j: usize,
    pub(super) a: f64,
    pub(super) b: f64,
    pub(super) interval: usize,
    pub(super) crosses: bool,
}

impl Cell {
    /// The cells of `mesh` (m, increasing, every break of the model a node of it), base to
    /// tip, with the intervals of the model's `breaks` (m) they start in.
    pub(super) fn along<'a>(mesh: &'a [f64], breaks: &'a [f64]) -> impl Iterator<Item = Cell> + 'a {
        let mut interval = 0;
        mesh.windows(2).enumerate().map(move |(j, ab)| {
            let (a, b) = (ab[0], ab[1]);
            let crosses = breaks[interval + 1] == b && interval + 2 < breaks.len();
            let c = Cell {
                j,
                a,
                b,
                interval,
                crosses,
            };
            interval = c.next_interval();
            c
        })
    }

    /// The integration interval at the distal node `b`.
    fn next_interval(self) -> usize {
        self.interval + usize::from(self.crosses)
    }
}

/// The fixed data of one frictional march: the setup, the number of tendons, the rod's
/// length and the tendons' ends (m), the model's pressures and the tendons' friction
/// coefficients, the hint of the first guesses, whether the strains at a
/// node are those of the last RK4 stage (`reuse`), and the largest base tension `scale` (N)
/// with the cell tolerance relative to it and in N (`tol`).
struct Fixed<'m> {
    setup: &'m Setup<'m>,
    nt: usize,
    l: f64,
    ends: &'m [f64],
    pressures: Vec<f64>,
    mus: Vec<f64>,
    hint: Option<&'m [Tangents]>,
    reuse: bool,
    cell_tolerance: f64,
    scale: f64,
    tol: f64,
}

impl<'m> Fixed<'m> {
    /// The fixed data of a march on `setup` (the other arguments those of [`march_cells`]).
    fn new(
        setup: &'m Setup<'m>,
        unloaded: bool,
        hint: Option<&'m [Tangents]>,
        cell_tolerance: f64,
    ) -> Self {
        let scale = setup.scale();
        Fixed {
            setup,
            nt: setup.base.len(),
            l: setup.model.length(),
            ends: setup.model.tendon_ends(),
            pressures: setup.pressures(),
            mus: setup.model.tendons().iter().map(|t| t.friction()).collect(),
            hint,
            reuse: unloaded && matches!(setup.options.statics.integrator, Integrator::Rk4 { .. }),
            cell_tolerance,
            scale,
            tol: cell_tolerance * scale,
        }
    }

    /// Whether tendon `i` is there at `s` (m): before its termination, or at the tip if it
    /// ends there.
    fn present(&self, i: usize, s: f64) -> bool {
        present(self.ends, self.l, i, s)
    }

    /// The equations at the base tensions (no profile).
    fn eq(&self) -> Equations<'_> {
        Equations::new(self.setup.model, self.setup.base, &self.pressures)
    }

    /// The evaluator of the equations on the tension profile `cell`.
    fn evaluator<'e>(
        &'e self,
        cell: &'e TensionProfile,
        ws: &'e mut Workspace,
    ) -> Evaluator<'e, 'e> {
        Evaluator {
            eq: Equations {
                profile: Some(cell),
                ..self.eq()
            },
            ws,
        }
    }

    /// The tendons' path tangents at the node `s` (m) of state `y` from the strains there,
    /// `None` if they are not finite. Without external loads the total wrench is zero all
    /// along, so the strains depend on `s` alone: after an RK4 step (`reuse`) they are those
    /// of its last stage, at the same `s`.
    fn tangents(
        &self,
        ev: &mut Evaluator<'_, '_>,
        s: f64,
        y: &[f64],
        reuse: bool,
    ) -> Option<Tangents> {
        let model = self.setup.model;
        let r = rot(y);
        let (v, u) = match ev.ws.guess.filter(|_| reuse && !ev.ws.active.is_empty()) {
            Some(g) => (
                Vector3::new(g[0], g[1], g[2]),
                Vector3::new(g[3], g[4], g[5]),
            ),
            None => {
                let props = model.rod().section_at(s);
                let loc = ev.local(
                    s,
                    &props,
                    &r.tr_mul(&v3(y, 12)),
                    &r.tr_mul(&v3(y, 15)),
                    false,
                );
                (loc.v, loc.u)
            }
        };
        let finite = v.iter().chain(u.iter()).all(|c| c.is_finite());
        finite.then(|| node_tangents(model, s, &r, &v, &u))
    }
}

/// Whether the tendon ending at `ends[i]` (m) is there at `s` (m) on a rod of length `l`
/// (m): before its end, or at the tip if it ends there.
fn present(ends: &[f64], l: f64, i: usize, s: f64) -> bool {
    s < ends[i] || (ends[i] == l && s == l)
}

/// The error of a failed step of a cell: the workspace's material failure, else `what`
/// not converged after `attempts` with `residual`.
fn failed(ws: &mut Workspace, what: String, attempts: usize, residual: f64) -> Error {
    ws.material_error.take().unwrap_or(Error::NotConverged {
        what,
        iterations: attempts,
        residual,
        load_factor: 1.0,
    })
}

/// The state of one frictional march: the profile over the current cell, the workspace
/// (with the tendon lengths so far) and its quadratures at the cell's proximal node
/// (`saved`), the state and integration interval at the last accepted node, per node and
/// tendon the tension, slip state, path tangent and path length, the recorded nodes, per
/// cell and tendon the turning rate (see [`extrapolated_rate`]), the current cell's guess
/// and rule of its distal tensions with the rule's slip states, and the cell steps so far
/// with the largest accepted change of a cell (N).
struct CellMarch<'m, const N: usize> {
    fixed: Fixed<'m>,
    cell: TensionProfile,
    ws: Workspace,
    saved: Vec<f64>,
    y: [f64; N],
    interval: usize,
    tau: Vec<Vec<f64>>,
    slip: Vec<Vec<Slip>>,
    dirs: Vec<Tangents>,
    path_length: Vec<Vec<f64>>,
    nodes: Vec<Node>,
    rates: Vec<Option<f64>>,
    guess: Vec<f64>,
    rule: Vec<f64>,
    rule_slip: Vec<Slip>,
    cell_steps: usize,
    worst: f64,
}

impl<'m, const N: usize> CellMarch<'m, N> {
    /// The march at the base from the scaled base wrench `x`: the base tensions and slip
    /// states, the path tangents there and the base node.
    fn start(fixed: Fixed<'m>, x: &[f64; 6]) -> Result<Self> {
        let Setup { base, prev, .. } = *fixed.setup;
        let (nt, n) = (base.len(), fixed.setup.mesh.len());
        let cell = TensionProfile::new(
            (0..nt)
                .map(|i| (fixed.mus[i] > 0.0).then(|| (vec![0.0, 0.0], vec![base[i]; 2])))
                .collect(),
        );
        let mut tau = vec![vec![0.0; nt]; n];
        let mut slip = vec![vec![Slip::Absent; nt]; n];
        let mut ws = Workspace::new(nt);
        ws.set_columns(&[], &[]);
        ws.track_lengths = true;
        let y: [f64; N] = fixed.eq().initial(x);
        for i in 0..nt {
            if fixed.present(i, 0.0) {
                tau[0][i] = base[i];
                slip[0][i] = base_slip(base[i], prev.map(|p| p[0][i]));
            }
        }
        let mut dirs = Vec::with_capacity(n);
        {
            let mut ev = fixed.evaluator(&cell, &mut ws);
            ev.set_interval(0);
            let Some(d) = fixed.tangents(&mut ev, 0.0, &y, false) else {
                return Err(failed(
                    &mut ws,
                    "friction: the constitutive solve failed at the base".into(),
                    0,
                    f64::INFINITY,
                ));
            };
            dirs.push(d);
        }
        let mut nodes = Vec::with_capacity(n);
        nodes.push(node(0.0, 0, &y));
        Ok(CellMarch {
            fixed,
            cell,
            ws,
            saved: Vec::new(),
            y,
            interval: 0,
            tau,
            slip,
            dirs,
            path_length: vec![vec![0.0; nt]; n],
            nodes,
            rates: Vec::with_capacity(n * nt),
            guess: vec![0.0; nt],
            rule: vec![0.0; nt],
            rule_slip: vec![Slip::Absent; nt],
            cell_steps: 0,
            worst: 0.0,
        })
    }

    /// Marches over cell `c`: its first guess, the iteration to its rule, the repeat with
    /// the columns, and the accepted distal node recorded.
    fn cell(&mut self, c: Cell) -> Result<()> {
        self.saved.clone_from(&self.ws.integral);
        self.first_guess(c);
        let (ys1, d1) = self.settle(c)?;
        let y1 = self.repeat_with_columns(c, &ys1)?;
        self.record(c, y1, d1);
        Ok(())
    }

    /// The first guess of the distal tensions of cell `c`: the rule with the turning of the
    /// hint, corrected by the difference to the hint over the last cell; else with the
    /// turning rate extrapolated from the last cells (none across a break).
    fn first_guess(&mut self, c: Cell) {
        let Self {
            fixed,
            tau,
            dirs,
            rates,
            guess,
            ..
        } = self;
        let (tau, dirs): (&[Vec<f64>], &[Tangents]) = (tau, dirs);
        let (rates, guess): (&[Option<f64>], &mut [f64]) = (rates, guess);
        let (j, a, b, crosses) = (c.j, c.a, c.b, c.crosses);
        let (hint, prev, nt) = (fixed.hint, fixed.setup.prev, fixed.nt);
        let (mus, ends, l): (&[f64], &[f64], f64) = (&fixed.mus, fixed.ends, fixed.l);
        for i in 0..nt {
            let theta = match hint.map(|h| (&h[j][i], &h[j + 1][i])) {
                Some((Some(ta), Some(tb))) => {
                    let shift = match (j.checked_sub(1), hint) {
                        (Some(k), Some(h)) if !crosses => match (&h[k][i], &dirs[k][i]) {
                            (Some(ha), Some(da)) => {
                                angle(da, &dirs[j][i].unwrap_or(*da))
                                    - angle(ha, &h[j][i].unwrap_or(*ha))
                            }
                            _ => 0.0,
                        },
                        _ => 0.0,
                    };
                    (angle(ta, tb) + shift).max(0.0)
                }
                _ if crosses => 0.0,
                _ => (extrapolated_rate(rates, nt, i) * (b - a)).max(0.0),
            };
            guess[i] = if present(ends, l, i, b) {
                cell_rule(tau[j][i], mus[i] * theta, prev.map(|p| p[j + 1][i])).0
            } else {
                0.0
            };
        }
    }

    /// Cell `c` repeated from its proximal node until the guess of its distal tensions and
    /// the rule agree to the tolerance (each attempt from the next guess of
    /// [`next_guess`]): the accepted distal state and path tangents, the rule's tensions and
    /// slip states in `rule`, `rule_slip`.
    fn settle(&mut self, c: Cell) -> Result<([f64; STATE], Tangents)> {
        let mut last: Option<(Vec<f64>, Vec<f64>)> = None;
        let mut attempts = 0;
        let ys = node(c.a, c.interval, &self.y).y;
        loop {
            attempts += 1;
            let (y1, d1) = self.attempt(c, ys, attempts)?;
            let change = self.apply_rule(c.j, &d1);
            let fixed = &self.fixed;
            if !change.is_finite() {
                let what = "friction: the tension profile became non-finite".to_string();
                return Err(failed(&mut self.ws, what, attempts, change));
            }
            if change <= fixed.tol {
                self.worst = self.worst.max(change);
                self.cell_steps += attempts;
                return Ok((y1, d1));
            }
            if attempts >= MAX_CELL_ATTEMPTS {
                let what = format!(
                    "friction: the tension at s = {} m did not settle in {attempts} steps of \
                     its cell (change {:e} > tolerance {:e} relative)",
                    c.b,
                    change / fixed.scale,
                    fixed.cell_tolerance
                );
                let residual = change / fixed.scale;
                return Err(failed(&mut self.ws, what, attempts, residual));
            }
            let before = self.guess.clone();
            next_guess(
                &mut self.guess,
                &self.rule,
                last.as_ref().map(|(g, r)| (g.as_slice(), r.as_slice())),
            );
            last = Some((before, self.rule.clone()));
            self.ws.integral.clone_from(&self.saved);
        }
    }

    /// One attempt of cell `c` (the `attempts`-th): the profile over the cell from the
    /// proximal tensions to the guessed distal ones, the state stepped over it from `ys`,
    /// and the path tangents at its distal node.
    fn attempt(
        &mut self,
        c: Cell,
        ys: [f64; STATE],
        attempts: usize,
    ) -> Result<([f64; STATE], Tangents)> {
        let Self {
            fixed,
            cell,
            ws,
            tau,
            guess,
            ..
        } = self;
        let (tau_j, guess): (&[f64], &[f64]) = (&tau[c.j], guess);
        let (ends, l) = (fixed.ends, fixed.l);
        for i in 0..fixed.nt {
            let distal = if present(ends, l, i, c.b) {
                guess[i]
            } else {
                tau_j[i]
            };
            cell.set_cell(i, [c.a, c.b], [tau_j[i], distal]);
        }
        let mut ev = fixed.evaluator(cell, ws);
        if ev.ws.interval != c.interval {
            ev.set_interval(c.interval);
        }
        let integrator = &fixed.setup.options.statics.integrator;
        let y1 = match step_cell(&mut ev, integrator, [c.a, c.b], ys, c.crosses) {
            Ok(y1) => y1,
            Err(e) => return Err(ev.ws.material_error.take().unwrap_or(e)),
        };
        if c.crosses {
            ev.set_interval(c.next_interval());
        }
        let reuse = fixed.reuse && !c.crosses;
        let Some(d1) = fixed.tangents(&mut ev, c.b, &y1, reuse) else {
            let what = format!("friction: the constitutive solve failed at s = {} m", c.b);
            return Err(failed(ws, what, attempts, f64::INFINITY));
        };
        Ok((y1, d1))
    }

    /// The capstan rule of cell `j` on the path tangents `d1` at its distal node: its
    /// distal tensions and slip states in `rule`, `rule_slip`; returns their largest change
    /// from the guess (N).
    fn apply_rule(&mut self, j: usize, d1: &[Option<Vector3<f64>>]) -> f64 {
        let Self {
            fixed,
            tau,
            dirs,
            guess,
            rule,
            rule_slip,
            ..
        } = self;
        let (mus, prev): (&[f64], _) = (&fixed.mus, fixed.setup.prev);
        let (tau_j, dirs_j, guess): (&[f64], &[_], &[f64]) = (&tau[j], &dirs[j], guess);
        let (rule, rule_slip): (&mut [f64], &mut [Slip]) = (rule, rule_slip);
        let mut change: f64 = 0.0;
        for i in 0..fixed.nt {
            (rule[i], rule_slip[i]) = match (&dirs_j[i], &d1[i]) {
                (Some(ta), Some(tb)) => {
                    let mu_theta = if mus[i] > 0.0 {
                        mus[i] * angle(ta, tb)
                    } else {
                        0.0
                    };
                    cell_rule(tau_j[i], mu_theta, prev.map(|p| p[j + 1][i]))
                }
                _ => (0.0, Slip::Absent),
            };
            change = change.max((rule[i] - guess[i]).abs());
        }
        change
    }

    /// The accepted cell `c` once more with the base-wrench columns (`N > STATE`), from the
    /// same proximal state and with the same profile, its state replaced by the attempts'
    /// `ys1` (the columns' step repeats it to the local solve's tolerance); `ys1` alone
    /// without columns.
    fn repeat_with_columns(&mut self, c: Cell, ys1: &[f64; STATE]) -> Result<[f64; N]> {
        if N <= STATE {
            let mut y1 = [0.0; N];
            y1.copy_from_slice(&ys1[..N]);
            return Ok(y1);
        }
        let Self {
            fixed,
            cell,
            ws,
            saved,
            y,
            ..
        } = self;
        let kept = ws.integral.clone();
        ws.integral.clone_from(saved);
        let mut ev = fixed.evaluator(cell, ws);
        with_columns(ev.ws, &[Column::Free; 6]);
        ev.set_interval(c.interval);
        let integrator = &fixed.setup.options.statics.integrator;
        let stepped = step_cell(&mut ev, integrator, [c.a, c.b], *y, c.crosses);
        with_columns(ev.ws, &[]);
        ev.set_interval(c.next_interval());
        let mut full = match stepped {
            Ok(full) => full,
            Err(e) => return Err(ev.ws.material_error.take().unwrap_or(e)),
        };
        full[..STATE].copy_from_slice(ys1);
        ws.integral = kept;
        Ok(full)
    }

    /// Records the accepted distal node of cell `c` (state `y1`, path tangents `d1`): the
    /// cell's turning rates, the rule's tensions and slip states, the path lengths so far.
    fn record(&mut self, c: Cell, y1: [f64; N], d1: Tangents) {
        let (j, nt) = (c.j, self.fixed.nt);
        let tiny = 10.0 * BREAK_OFFSET * self.fixed.l;
        let (mus, dirs) = (&self.fixed.mus, &self.dirs);
        self.rates
            .extend((0..nt).map(|i| match (&dirs[j][i], &d1[i]) {
                (Some(ta), Some(tb)) if mus[i] > 0.0 && c.b - c.a > tiny && !c.crosses => {
                    Some(angle(ta, tb) / (c.b - c.a))
                }
                _ => None,
            }));
        self.tau[j + 1].copy_from_slice(&self.rule);
        self.slip[j + 1].copy_from_slice(&self.rule_slip);
        self.dirs.push(d1);
        self.path_length[j + 1].copy_from_slice(&self.ws.integral[..nt]);
        self.y = y1;
        self.interval = c.next_interval();
        self.nodes.push(node(c.b, self.interval, &self.y));
    }

    /// What the march gives: the tip residual (with its columns when `N == FULL`), the
    /// profile along and the counts.
    fn finish(self) -> Marched<N> {
        let nt = self.fixed.nt;
        let ncol = if N >= FULL { 6 } else { 0 };
        let (residual, columns) = self.fixed.eq().residual(&self.y, ncol);
        Marched {
            y: self.y,
            residual,
            columns,
            tau: self.tau,
            slip: self.slip,
            dirs: self.dirs,
            nodes: self.nodes,
            path_length: self.path_length,
            lengths: self.ws.integral[..nt].to_vec(),
            cell_steps: self.cell_steps,
            worst: self.worst,
            evaluations: self.ws.evaluations,
        }
    }
}

/// One step of the rod over the cell `[a, b]` from `y` (RK4: one step; adaptive: to its
/// tolerance), then the jump at `b` if it is a break (`crosses`).
fn step_cell<const M: usize>(
    ev: &mut Evaluator<'_, '_>,
    integrator: &Integrator,
    [a, b]: [f64; 2],
    y: [f64; M],
    crosses: bool,
) -> Result<[f64; M]> {
    let mut y1 = match integrator {
        Integrator::Rk4 { .. } => fixed(&RK4, ev, a, y, b, 1, |_, _, _| {})?,
        Integrator::Adaptive(o) => adaptive(&DP5, ev, [a, b], y, o, STATE, |_, _, _| {})?.0,
    };
    if crosses {
        Piecewise::jump(ev, b, &mut y1);
    }
    Ok(y1)
}

/// Sets the columns of `ws`, keeping its quadratures (the tendon lengths so far).
fn with_columns(ws: &mut Workspace, columns: &[Column]) {
    let kept = ws.integral.clone();
    ws.set_columns(columns, &[]);
    ws.integral = kept;
}

/// A node of state `y` (its first [`STATE`] entries).
fn node<const N: usize>(s: f64, interval: usize, y: &[f64; N]) -> Node {
    let mut h = [0.0; STATE];
    h.copy_from_slice(&y[..STATE]);
    Node { s, interval, y: h }
}

impl Marched<FULL> {
    /// The march without its columns.
    fn state(self) -> Marched<STATE> {
        Marched {
            y: node(0.0, 0, &self.y).y,
            residual: self.residual,
            columns: Vec::new(),
            tau: self.tau,
            slip: self.slip,
            dirs: self.dirs,
            nodes: self.nodes,
            path_length: self.path_length,
            lengths: self.lengths,
            cell_steps: self.cell_steps,
            worst: self.worst,
            evaluations: self.evaluations,
        }
    }
}

/// The frictional solution of a converged march `m` from the scaled base wrench `x`: the
/// rod's solution at the mesh nodes with the whole profile, after `iterations` marches and
/// `cell_steps` steps of their cells. `loaded`: the shooting Jacobian and the stability at
/// the solution come from one pass with the base-wrench columns, the profile held fixed.
fn finish(
    setup: &Setup<'_>,
    m: Marched<STATE>,
    x: &[f64; 6],
    mut stats: SolverStats,
    (iterations, cell_steps): (usize, usize),
    loaded: bool,
) -> Result<FrictionalSolution> {
    let Setup {
        model,
        actuation,
        options,
        mesh,
        base,
        ..
    } = *setup;
    let pressures = setup.pressures();
    let plan = match options.statics.integrator {
        Integrator::Rk4 { steps } => crate::integrate::march::rk4_plan(model.breaks(), steps),
        Integrator::Adaptive(_) => Vec::new(),
    };
    let mut act = actuation.clone();
    act.profile = Some(Arc::new(to_profile(model, mesh, &m.tau)));
    let profile = act.profile.clone();
    let eq = Equations {
        model,
        tensions: base,
        pressures: &pressures,
        load_factor: 1.0,
        profile: profile.as_deref(),
    };
    let mut p = Shooting::new(eq, options.statics.integrator, plan);
    let mut linear = None;
    if loaded {
        p.stops = interior(mesh, model.length());
        let (_, cols, _) = p.pass::<FULL>(x, 1.0)?;
        stats.function_evaluations += p.evaluations;
        let mut j = [0.0; 36];
        for (c, col) in cols.iter().enumerate() {
            j[6 * c..6 * c + 6].copy_from_slice(col.as_slice());
        }
        let stability = p
            .tip_twist
            .and_then(|tw| tip_stability(&j, &tw, model.length(), p.jacobi));
        linear = Some((Matrix6::from_column_slice(&j), stability));
        p.stops.clear();
    }
    p.nodes = m.nodes;
    p.lengths = m.lengths;
    let mut sol: StaticsSolution = assemble(&mut p, model, scaled_back(model, x), stats, &[]);
    if let Some(e) = p.ws.material_error.take() {
        return Err(e);
    }
    sol.actuation = act;
    sol.options = options.statics;
    sol.s_out = mesh.to_vec();
    sol.stable = true;
    if let Some((j, stability)) = linear {
        sol.jacobian = Some(j);
        if let Some(s) = stability {
            sol.stable = s.stable;
            let _ = sol.margin.set(s.margin);
        }
    }
    let scale = setup.scale();
    let tangent = tangent_rows(&m.dirs);
    let forces = friction_forces(mesh, &m.tau, &m.dirs);
    Ok(FrictionalSolution {
        guides: vec![Vec::new(); setup.base.len()],
        statics: sol,
        tension: m.tau,
        slip: m.slip,
        tangent,
        friction_force: forces,
        path_length: m.path_length,
        iterations,
        change: m.worst / scale,
        cell_steps,
    })
}

/// The frictional equilibrium of an unloaded model (no external load: the total wrench is
/// zero all along, `x = 0` is the shooting solution) in one march over the friction mesh.
pub(super) fn solve_unloaded(setup: &Setup<'_>) -> Result<FrictionalSolution> {
    let x = [0.0; 6];
    let m = march_cells::<STATE>(setup, &x, true, None, setup.options.tolerance)?;
    let stats = SolverStats {
        iterations: 0,
        residual: m.residual.amax(),
        function_evaluations: m.evaluations,
        converged: true,
        load_steps: 0,
        load_factor: 1.0,
    };
    let steps = m.cell_steps;
    finish(setup, m, &x, stats, (1, steps), false)
}

/// The frictional equilibrium of a loaded model by a quasi-Newton method on the scaled base
/// wrench from `x0`, every iterate one frictional march. The first Jacobian is `warm` (the
/// previous state's) or that of the first march's base-wrench columns (the profile held
/// fixed, so it misses the profile's change with the base wrench); Broyden's update
/// corrects it from the iterates, whose marches carry the state alone. `None` if it does not
/// converge within the Newton options' iteration cap or the residual grows more than
/// tenfold in a step (the caller falls back). `cold`: `x0` is the unloaded rod (`x = 0`);
/// as in the frictionless solve, a first step longer than [`DIRECT_STEP_LIMIT`] or a
/// solution farther than [`MAX_LOAD_STEP_TURN`] from the unloaded shape (maybe another
/// branch) is refused (`None`) too.
///
/// # Errors
/// A material failure or a cell that does not settle, at the first march.
pub(super) fn solve_loaded(
    setup: &Setup<'_>,
    x0: [f64; 6],
    cold: bool,
    warm: Option<&Matrix6<f64>>,
) -> Result<Option<FrictionalSolution>> {
    let newton = &setup.options.statics.newton;
    let tolerance = |x: &Vector6<f64>| match setup.options.statics.integrator {
        Integrator::Rk4 { .. } => newton.tolerance,
        Integrator::Adaptive(a) => newton.tolerance.max(10.0 * a.rtol * (1.0 + x.amax())),
    };
    let mut x = Vector6::from_column_slice(&x0);
    let exact = setup.options.tolerance;
    // The cells of an iterate far from the solution are resolved only as far as the step
    // from it needs: to `LOOSE_CELLS` times its residual (never below the tolerance).
    let mut loose = exact;
    let (mut m, mut j) = match warm {
        Some(j) => (march_cells::<STATE>(setup, &x0, false, None, exact)?, *j),
        None => {
            let full = march_cells::<FULL>(setup, &x0, false, None, exact)?;
            let j = Matrix6::from_columns(&full.columns);
            (full.state(), j)
        }
    };
    let reference = cold.then(|| m.nodes.clone());
    let (mut steps, mut evaluations, mut marches) = (m.cell_steps, m.evaluations, 1);
    loop {
        let r = m.residual;
        let rn = r.amax();
        if rn <= tolerance(&x) {
            if loose <= exact {
                break;
            }
            // Converged on loosely resolved cells: the same base wrench at the tolerance.
            loose = exact;
            let xa: [f64; 6] = x.into();
            let Ok(again) = march_cells::<STATE>(setup, &xa, false, Some(&m.dirs), exact) else {
                return Ok(None);
            };
            marches += 1;
            steps += again.cell_steps;
            evaluations += again.evaluations;
            m = again;
            continue;
        }
        if marches >= newton.max_iterations.max(1) {
            return Ok(None);
        }
        let Some(step) = j.lu().solve(&(-r)) else {
            return Ok(None);
        };
        if !step.iter().all(|v| v.is_finite())
            || (cold && marches == 1 && step.amax() > DIRECT_STEP_LIMIT)
        {
            return Ok(None);
        }
        let xn = x + step;
        let xa: [f64; 6] = xn.into();
        loose = (LOOSE_CELLS * rn).max(exact);
        let Ok(next) = march_cells::<STATE>(setup, &xa, false, Some(&m.dirs), loose) else {
            return Ok(None);
        };
        marches += 1;
        steps += next.cell_steps;
        evaluations += next.evaluations;
        let grown = next.residual.amax();
        if grown.is_nan() || grown > 10.0 * rn {
            return Ok(None);
        }
        let dr = next.residual - r;
        j += (dr - j * step) * step.transpose() / step.dot(&step);
        x = xn;
        m = next;
    }
    if let Some(r0) = reference.as_deref() {
        if !near(r0, &m.nodes, setup.model.length()) {
            return Ok(None);
        }
    }
    let stats = SolverStats {
        iterations: marches,
        residual: m.residual.amax(),
        function_evaluations: evaluations,
        converged: true,
        load_steps: 0,
        load_factor: 1.0,
    };
    let xa: [f64; 6] = x.into();
    finish(setup, m, &xa, stats, (marches, steps), true).map(Some)
}

/// The frictional equilibrium with the tension a state of the march: one march for an
/// unloaded model; for a loaded one, the quasi-Newton iteration of [`solve_loaded`] from the
/// previous state, or from the unloaded rod, else from the frictionless solve. `None` if the
/// iteration does not converge (the caller falls back to the fixed point).
///
/// # Errors
/// What the marches and the frictionless solve report.
pub(super) fn solve_marched(
    setup: &Setup<'_>,
    previous: Option<&FrictionalSolution>,
) -> Result<Option<FrictionalSolution>> {
    let Setup {
        model,
        actuation,
        options,
        mesh,
        base,
        ..
    } = *setup;
    if model.loads().is_unloaded() {
        return solve_unloaded(setup).map(Some);
    }
    // Newton on the base wrench from the previous state's, or from the unloaded rod,
    // else from the frictionless solve's (every tendon at its base tension).
    let x0 = previous.map(|p| scaled(model, &p.statics.base_wrench));
    let warm = previous.and_then(|p| p.statics.jacobian.as_ref());
    if let Some(sol) = solve_loaded(setup, x0.unwrap_or([0.0; 6]), x0.is_none(), warm)? {
        return Ok(Some(sol));
    }
    if x0.is_none() {
        let mut act = actuation.clone();
        act.profile = Some(Arc::new(to_profile(
            model,
            mesh,
            &base_profile(model, mesh, base),
        )));
        let plain = solve_statics_at(model, &act, &options.statics, &[])?;
        if let Some(sol) = solve_loaded(
            setup,
            scaled(model, &plain.base_wrench),
            false,
            plain.jacobian.as_ref(),
        )? {
            return Ok(Some(sol));
        }
    }
    Ok(None)
}

/// The cell tolerance of a loaded solve's iterate relative to the residual of the one before.
const LOOSE_CELLS: f64 = 1e-4;

/// Whether two shapes on the same nodes differ by at most [`MAX_LOAD_STEP_TURN`] in rotation
/// (rad) and `MAX_LOAD_STEP_TURN L / 2` in position at every node.
fn near(a: &[Node], b: &[Node], length: f64) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            let c = ((rot(&p.y).tr_mul(&rot(&q.y)).trace() - 1.0) * 0.5).clamp(-1.0, 1.0);
            c.acos() <= MAX_LOAD_STEP_TURN
                && (v3(&p.y, 0) - v3(&q.y, 0)).norm() <= 0.5 * MAX_LOAD_STEP_TURN * length
        })
}
