//! The constrained shooting problem: base wrench, tip constraint and contact unknowns, solved
//! by the crate's Newton and continuation, with an active set of contacts.

use std::sync::Arc;

use nalgebra::{Matrix3, Matrix6, UnitQuaternion, Vector3, Vector6};

use super::constraint::TipConstraint;
use super::friction::{first_touch, retouch, switch};
use super::obstacle::Obstacle;
use super::ramp;
use super::stability::{conjugate_points, free_stiffness};
use super::sweep::{least_gap_in_cell, CellEnd};
use super::{obstacle_normal_basis, Contact, ContactCompliance, ContactSolution, ContactState};
use crate::cosserat::equations::{rot, v3, Equations, Evaluator, Workspace, FULL, STATE};
use crate::cosserat::shooting::{Node, Shooting};
use crate::cosserat::statics::{
    assemble, scaled, scaled_back, settings, solve_statics, stability_on, Integrator, SolveOptions,
    MAX_LINE_SEARCH_HALVINGS, MAX_LOAD_STEP_TURN,
};
use crate::cosserat::{tip_stability, Stability, NEUTRAL_MARGIN};
use crate::error::{Error, Result};
use crate::integrate::march::rk4_plan;
use crate::math::linalg::DenseLu;
use crate::model::loads::{Loads, PointLoad};
use crate::model::rod::Profile;
use crate::model::{Actuation, RobotModel};
use crate::solve::{
    continuation, max_norm, ContinuationSettings, Evaluated, NewtonOptions, Problem, SolverStats,
    MIN_LOAD_INCREMENT,
};

/// Most rounds of the active-set loop (contacts added or released) per load step.
pub const MAX_ACTIVE_SET_ROUNDS: usize = 40;
/// Relative step of the forward differences of the Jacobian columns with contacts.
const DIFFERENCE_STEP: f64 = 1e-7;
/// Ratio of the RK4 steps of a contact solve to those of its coarse mesh.
const COARSE_RATIO: usize = 5;
/// Fewest RK4 steps of the coarse mesh of a contact solve.
const MIN_COARSE_STEPS: usize = 8;
/// Newton tolerance on the coarse mesh (at least the one asked): below the difference of the
/// two meshes' solutions, which Newton on the mesh asked removes.
const COARSE_TOLERANCE: f64 = 1e-6;
/// Stability margin on the coarse mesh beyond which its sign decides whether a contact
/// solution is stable (closer to zero, the margin is computed on the mesh asked).
const COARSE_MARGIN_GAP: f64 = 1e-2;

/// What the compliance of a converged contact solution needs, owned (see
/// [`ContactCompliance`]), and the compliance once computed.
#[derive(Debug)]
pub(crate) struct Frozen {
    model: Arc<RobotModel>,
    obstacles: Vec<Obstacle>,
    tensions: Vec<f64>,
    pressures: Vec<f64>,
    integrator: Integrator,
    tip: Option<TipConstraint>,
    start: (Vector3<f64>, Matrix3<f64>),
    active: Vec<Active>,
    x: Vec<f64>,
    value: std::sync::OnceLock<Option<Matrix6<f64>>>,
}

impl Frozen {
    /// The problem `p` at full load at its solution `x`.
    fn at(p: &Constrained<'_>, x: &[f64]) -> Self {
        Self {
            model: Arc::clone(p.shared),
            obstacles: p.obstacles.to_vec(),
            tensions: p.tensions.clone(),
            pressures: p.pressures.clone(),
            integrator: p.integrator,
            tip: p.tip,
            start: p.start,
            active: p.active.clone(),
            x: x.to_vec(),
            value: std::sync::OnceLock::new(),
        }
    }

    /// The problem at full load with the active set of the solution.
    fn problem(&self) -> Constrained<'_> {
        Constrained {
            model: &self.model,
            shared: &self.model,
            tensions: self.tensions.clone(),
            pressures: self.pressures.clone(),
            integrator: self.integrator,
            tip: self.tip,
            start: self.start,
            obstacles: &self.obstacles,
            active: self.active.clone(),
            load: 1.0,
            last: None,
            reference: Vec::new(),
            evaluations: 0,
            coarse: None,
            hint: None,
            solved: None,
            refine: true,
            rough: false,
            from: 1.0,
            refused: None,
        }
    }

    /// The constrained tip compliance (see [`Constrained::compliance`]), computed once.
    pub(crate) fn compliance(&self) -> Option<Matrix6<f64>> {
        *self
            .value
            .get_or_init(|| self.problem().compliance(&self.x))
    }

    /// Whether an active contact has friction (sticking or sliding).
    pub(crate) fn frictional(&self) -> bool {
        self.active
            .iter()
            .any(|a| a.state != ContactState::Frictionless)
    }

    /// The constrained actuation Jacobian of node `node` and its position (see
    /// [`Constrained::actuation_jacobian`]).
    pub(crate) fn actuation_jacobian(
        &self,
        node: usize,
    ) -> Option<(nalgebra::DMatrix<f64>, Vector3<f64>)> {
        self.problem().actuation_jacobian(&self.x, node)
    }
}

/// Where a contact acts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Site {
    /// At the tip `s = L` (unknown: the force).
    Tip,
    /// Inside the rod at an unknown arc length where the gap is least (unknowns: `s`, force).
    Interior,
    /// On a plane, from an unknown arc length `a` to the tip: a concentrated force at `a`
    /// (unknowns: `a`, force) and, on `(a, L]`, the distributed reaction that cancels the
    /// normal component of the distributed loads (the segment lies flat on the plane).
    Interval,
}

/// An active contact and the homotopy targets of its gap rows (its gap and gap slope when it
/// was added, relaxed to zero as the problem's parameter goes from 0 to 1); with friction (a
/// tip contact), its state, the contact point where it first touched (m, world) and the
/// homotopy targets of its sticking rows (its tangential displacements from there, m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Active {
    pub(super) obstacle: usize,
    pub(super) site: Site,
    pub(super) g0: f64,
    pub(super) dg0: f64,
    pub(super) state: ContactState,
    pub(super) reference: Vector3<f64>,
    pub(super) touch: f64,
    pub(super) t0: [f64; 2],
    /// A slip direction (unit, world) held while a contact turns from sticking to sliding.
    pub(super) direction: Option<Vector3<f64>>,
}

impl Active {
    /// A frictionless contact on `obstacle` at `site`, its gap targets zero.
    pub(super) fn frictionless(obstacle: usize, site: Site) -> Self {
        Self {
            obstacle,
            site,
            g0: 0.0,
            dg0: 0.0,
            state: ContactState::Frictionless,
            reference: Vector3::zeros(),
            touch: 0.0,
            t0: [0.0; 2],
            direction: None,
        }
    }
}

impl Active {
    pub(super) fn size(&self) -> usize {
        match self.site {
            Site::Tip => 3,
            Site::Interior | Site::Interval => 4,
        }
    }
}

/// The equations of `model` (a contact model) under the actuation, at full load.
pub(super) fn equations<'a>(
    model: &'a RobotModel,
    tensions: &'a [f64],
    pressures: &'a [f64],
) -> Equations<'a> {
    Equations {
        model,
        tensions,
        pressures,
        load_factor: 1.0,
        profile: None,
    }
}

/// The loads of `loads` times `lambda`.
fn scaled_loads(loads: &Loads, lambda: f64) -> Loads {
    let mut l = loads.clone();
    if lambda == 1.0 {
        return l;
    }
    l.tip_force *= lambda;
    l.tip_moment *= lambda;
    l.gravity *= lambda;
    for p in &mut l.point_loads {
        p.force *= lambda;
        p.moment *= lambda;
    }
    let scale = |p: &Option<Profile>| {
        p.as_ref().map(|p| match p {
            Profile::Constant(v) => Profile::Constant(v * lambda),
            Profile::Function(f) => {
                let f = Arc::clone(f);
                Profile::Function(Arc::new(move |s| f(s) * lambda))
            }
        })
    };
    l.distributed_force = scale(&loads.distributed_force);
    l.distributed_moment = scale(&loads.distributed_moment);
    l
}

/// What one evaluation left: the model it marched (with the contact forces as point loads),
/// its nodes, its raw shooting residual.
pub(super) struct Pass {
    pub(super) model: Arc<RobotModel>,
    pub(super) nodes: Vec<Node>,
    pub(super) residual: Vector6<f64>,
    /// What was evaluated, and its rows (a residual asked again is not marched again).
    pub(super) key: Key,
    pub(super) rows: Vec<f64>,
    /// With an exact Jacobian: it (column-major) and the tip twist `[δp; δθ]` (m, rad;
    /// world) per scaled unknown.
    pub(super) jacobian: Option<(Vec<f64>, Vec<Vector6<f64>>)>,
    /// Of a march of the state alone by `integrator`: the tendon path lengths (m) and
    /// tensions (N) it left (what a solution is assembled from, with the nodes).
    pub(super) marched: Option<(Integrator, Vec<f64>, Vec<f64>)>,
}

/// The unknowns, homotopy parameter, load factor, active set and tip constraint of an
/// evaluation.
pub(super) type Key = (Vec<f64>, f64, f64, Vec<Active>, Option<TipConstraint>);

/// The residual rows of one evaluation and, when asked, the exact Jacobian columns of the tip
/// rows along the base wrench.
type Rows = (Vec<f64>, Option<[[f64; 6]; 6]>);

/// The constrained shooting problem at load factor `load`; the parameter of
/// [`Problem::evaluate`] relaxes the gap targets of newly added contacts.
pub(crate) struct Constrained<'m> {
    pub(super) model: &'m RobotModel,
    pub(super) shared: &'m Arc<RobotModel>,
    pub(super) tensions: Vec<f64>,
    pub(super) pressures: Vec<f64>,
    pub(super) integrator: Integrator,
    pub(super) tip: Option<TipConstraint>,
    /// Tip pose of the actuated rod without loads (the target at load factor 0).
    pub(super) start: (Vector3<f64>, Matrix3<f64>),
    pub(super) obstacles: &'m [Obstacle],
    pub(super) active: Vec<Active>,
    pub(super) load: f64,
    pub(super) last: Option<Pass>,
    pub(super) reference: Vec<Vector3<f64>>,
    pub(super) evaluations: usize,
    /// The mesh the Jacobians are taken on when it is coarser than `integrator` (the rows
    /// still come from `integrator`; see [`coarse_mesh`]).
    pub(super) coarse: Option<Integrator>,
    /// A Jacobian (column-major) to start the next Newton solve with, and the active set it
    /// belongs to (used only with that active set).
    pub(super) hint: Option<(Vec<Active>, Vec<f64>)>,
    /// The (updated) Jacobian of the last converged Newton solve and its active set.
    pub(super) solved: Option<(Vec<Active>, Vec<f64>)>,
    /// Whether Newton continues past the tolerance toward round-off (not on the coarse
    /// mesh, whose solution is only a start).
    pub(super) refine: bool,
    /// Whether the contact rows of a Jacobian are differenced one-sided (on the coarse
    /// mesh, where the Jacobian only steers Newton) rather than centrally.
    pub(super) rough: bool,
    /// Load factor of the last accepted load step (where a first touch is searched from).
    pub(super) from: f64,
    /// The friction coefficient of an obstacle touched inside the rod, when refused.
    pub(super) refused: Option<f64>,
}

impl<'m> Constrained<'m> {
    fn dim_of(active: &[Active]) -> usize {
        6 + active.iter().map(Active::size).sum::<usize>()
    }

    pub(super) fn offsets(&self) -> Vec<usize> {
        let mut o = Vec::with_capacity(self.active.len());
        let mut k = 6;
        for a in &self.active {
            o.push(k);
            k += a.size();
        }
        o
    }

    /// The key of an evaluation at `x` and `mu` in the current state.
    pub(super) fn key(&self, x: &[f64], mu: f64) -> Key {
        // (The load factor steps nothing on an unloaded rod with a free tip.)
        let load = if self.tip.is_none() && self.model.loads().is_unloaded() {
            1.0
        } else {
            self.load
        };
        (x.to_vec(), mu, load, self.active.clone(), self.tip)
    }

    /// The target position and rotation of the tip at the current load factor.
    fn target(&self, c: &TipConstraint) -> (Vector3<f64>, Matrix3<f64>) {
        let l = self.load;
        let p = self.start.0 + (c.pose.position() - self.start.0) * l;
        let q0 = UnitQuaternion::from_matrix(&self.start.1);
        let q1 = UnitQuaternion::from_matrix(&c.pose.rotation());
        let q = q0
            .try_slerp(&q1, l, 1e-12)
            .unwrap_or(if l < 0.5 { q0 } else { q1 });
        (p, *q.to_rotation_matrix().matrix())
    }

    /// The six tip rows at the tip pose `(p, r)` with shooting residual `res`.
    pub(super) fn tip_rows(
        &self,
        res: &Vector6<f64>,
        p: &Vector3<f64>,
        r: &Matrix3<f64>,
    ) -> [f64; 6] {
        let Some(c) = &self.tip else {
            return std::array::from_fn(|k| res[k]);
        };
        let (pt, rt) = self.target(c);
        let frame = c.pose.rotation();
        let l = self.model.length();
        let dp = frame.tr_mul(&(p - pt)) / l;
        let f = frame.tr_mul(&res.fixed_rows::<3>(0).into_owned());
        let mut out = [0.0; 6];
        for k in 0..3 {
            out[k] = if c.held[k] { dp[k] } else { f[k] };
        }
        let m = res.fixed_rows::<3>(3).into_owned();
        match c.rotations_held() {
            3 => {
                let a = rt.tr_mul(r);
                out[3] = 0.5 * (a[(2, 1)] - a[(1, 2)]);
                out[4] = 0.5 * (a[(0, 2)] - a[(2, 0)]);
                out[5] = 0.5 * (a[(1, 0)] - a[(0, 1)]);
            }
            2 => {
                let d = rt.tr_mul(&r.column(2).into_owned());
                out[3] = -d.y;
                out[4] = d.x;
                out[5] = rt.tr_mul(&m).z;
            }
            _ => {
                let mm = frame.tr_mul(&m);
                out[3..6].copy_from_slice(mm.as_slice());
            }
        }
        out
    }

    /// The derivative of [`Self::tip_rows`] along a column: residual change `dres`, tip
    /// displacement `dp` and rotation `w` (world).
    pub(super) fn tip_rows_dot(
        &self,
        dres: &Vector6<f64>,
        dp: &Vector3<f64>,
        w: &Vector3<f64>,
        r: &Matrix3<f64>,
    ) -> [f64; 6] {
        let Some(c) = &self.tip else {
            return std::array::from_fn(|k| dres[k]);
        };
        let (_, rt) = self.target(c);
        let frame = c.pose.rotation();
        let l = self.model.length();
        let ddp = frame.tr_mul(dp) / l;
        let df = frame.tr_mul(&dres.fixed_rows::<3>(0).into_owned());
        let mut out = [0.0; 6];
        for k in 0..3 {
            out[k] = if c.held[k] { ddp[k] } else { df[k] };
        }
        let dm = dres.fixed_rows::<3>(3).into_owned();
        match c.rotations_held() {
            3 => {
                let da = rt.tr_mul(&(crate::math::so3::hat(w) * r));
                out[3] = 0.5 * (da[(2, 1)] - da[(1, 2)]);
                out[4] = 0.5 * (da[(0, 2)] - da[(2, 0)]);
                out[5] = 0.5 * (da[(1, 0)] - da[(0, 1)]);
            }
            2 => {
                let dd = rt.tr_mul(&w.cross(&r.column(2).into_owned()));
                out[3] = -dd.y;
                out[4] = dd.x;
                out[5] = rt.tr_mul(&dm).z;
            }
            _ => {
                let mm = frame.tr_mul(&dm);
                out[3..6].copy_from_slice(mm.as_slice());
            }
        }
        out
    }

    /// The model with the loads at the current load factor and the contact forces of `x` as
    /// world point loads; `None` if an arc length left the rod.
    pub(super) fn contact_model(&self, x: &[f64]) -> Option<Arc<RobotModel>> {
        if self.active.is_empty() && (self.load == 1.0 || self.model.loads().is_unloaded()) {
            return Some(Arc::clone(self.shared));
        }
        let l = self.model.length();
        let f = self.model.force_scale();
        let mut loads = scaled_loads(self.model.loads(), self.load);
        for (a, o) in self.active.iter().zip(self.offsets()) {
            let (s, k) = match a.site {
                Site::Tip => (l, o),
                Site::Interior | Site::Interval => (x[o] * l, o + 1),
            };
            if !(s > 0.0 && s <= l) {
                return None;
            }
            let force = Vector3::new(x[k], x[k + 1], x[k + 2]) * f;
            loads.point_loads.push(PointLoad::force(s, force));
            if a.site == Site::Interval {
                if s >= l {
                    return None;
                }
                let Obstacle::Plane { normal, .. } = *self.obstacles[a.obstacle].shape() else {
                    return None;
                };
                // The reaction starts just after the break at `s` (its own break), so that
                // no Runge-Kutta stage of the interval before sees it.
                let after = f64::from_bits(s.to_bits() + 1);
                loads
                    .point_loads
                    .push(PointLoad::force(after, Vector3::zeros()));
                let base = loads.distributed_force.clone();
                let rho_g = self.model.rod().density().map(|d| loads.gravity * d);
                let rod = self.model.rod().clone();
                loads.distributed_force = Some(Profile::Function(Arc::new(move |t| {
                    let mut f = base.as_ref().map_or(Vector3::zeros(), |p| p.at(t));
                    if t < after {
                        return f;
                    }
                    let mut applied = f;
                    if let Some(g) = rho_g {
                        applied += g * rod.section_at(t).area;
                    }
                    let push = normal.dot(&applied);
                    if push < 0.0 {
                        f -= normal * push;
                    }
                    f
                })));
            }
        }
        self.model.with_loads(loads).ok()
    }

    /// One march at `x`; with `full`, the six base-wrench columns too. Returns the residual
    /// rows, and with `full` the exact Jacobian of the tip rows along the base wrench.
    pub(super) fn run(&mut self, x: &[f64], mu: f64, full: bool) -> Option<Rows> {
        let model = self.contact_model(x)?;
        let plan = match self.integrator {
            Integrator::Rk4 { steps } => rk4_plan(model.breaks(), steps),
            Integrator::Adaptive(_) => Vec::new(),
        };
        let eq = equations(&model, &self.tensions, &self.pressures);
        let mut sh = Shooting::new(eq, self.integrator, plan);
        let pass = if full {
            sh.pass::<FULL>(&x[..6], 1.0)
        } else {
            sh.pass::<STATE>(&x[..6], 1.0)
        };
        self.evaluations += sh.evaluations;
        let (res, cols, _) = pass.ok()?;
        let tip = sh.nodes.last()?;
        let (p, r) = (v3(&tip.y, 0), rot(&tip.y));
        let mut rows = self.tip_rows(&res, &p, &r).to_vec();
        let jac = if full {
            let tw = sh.tip_twist?;
            Some(std::array::from_fn(|c| {
                let dp = tw[c].fixed_rows::<3>(0).into_owned();
                let w = tw[c].fixed_rows::<3>(3).into_owned();
                self.tip_rows_dot(&cols[c], &dp, &w, &r)
            }))
        } else {
            None
        };
        let l = self.model.length();
        let nt = model.tendons().len();
        let (mut before, mut after) = (Workspace::new(nt), Workspace::new(nt));
        let mut ev = [
            Evaluator {
                eq: sh.eq,
                ws: &mut before,
            },
            Evaluator {
                eq: sh.eq,
                ws: &mut after,
            },
        ];
        for (a, o) in self.active.iter().zip(self.offsets()) {
            let (s, k) = match a.site {
                Site::Tip => (l, o),
                Site::Interior | Site::Interval => (x[o] * l, o + 1),
            };
            let first = sh.nodes.iter().position(|n| n.s == s)?;
            let last = sh.nodes.iter().rposition(|n| n.s == s)?;
            let (nf, nl) = (&sh.nodes[first], &sh.nodes[last]);
            let f = Vector3::new(x[k], x[k + 1], x[k + 2]);
            self.contact_rows(
                &mut ev,
                a,
                s,
                (&nf.y, nf.interval),
                (&nl.y, nl.interval),
                &f,
                mu,
                &mut rows,
            );
        }
        if !rows.iter().all(|v| v.is_finite()) {
            return None;
        }
        self.last = Some(Pass {
            nodes: std::mem::take(&mut sh.nodes),
            residual: res,
            model: Arc::clone(&model),
            key: self.key(x, mu),
            rows: rows.clone(),
            jacobian: None,
            marched: (!full).then(|| {
                (
                    self.integrator,
                    std::mem::take(&mut sh.lengths),
                    std::mem::take(&mut sh.tensions),
                )
            }),
        });
        Some((rows, jac))
    }

    /// The residual rows of the active contact `a` at arc length `s` (m) with scaled force
    /// `f`, from the states (and intervals) of the first node at `s` (before the jump of the
    /// force) and the last (after it): the gap over `L` (relaxed by `mu` from its value when
    /// added), for a contact inside the rod the slope of the gap, and the force's two
    /// components along the obstacle's surface. `ev` are scratch evaluators of the contact
    /// model, one per side of the contact (so that each local solve starts from the last on
    /// its side).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn contact_rows(
        &self,
        ev: &mut [Evaluator<'_, '_>; 2],
        a: &Active,
        s: f64,
        first: (&[f64; STATE], usize),
        last: (&[f64; STATE], usize),
        f: &Vector3<f64>,
        mu: f64,
        rows: &mut Vec<f64>,
    ) {
        let l = self.model.length();
        let ob = &self.obstacles[a.obstacle];
        let props = self.model.rod().section_at(s);
        let (d, n) = ob.distance(&v3(first.0, 0));
        let g = d - props.radius;
        rows.push((g - (1.0 - mu) * a.g0) / l);
        if a.site != Site::Tip {
            // A point contact sits at the kink of the gap (the shear jumps with the force):
            // the mean slope of its two sides vanishes; the segment of an interval lies flat
            // from just after its edge.
            let sides = if a.site == Site::Interval {
                [last, last]
            } else {
                [first, last]
            };
            let mut slope = 0.0;
            for (ev, (y, interval)) in ev.iter_mut().zip(sides) {
                ev.set_interval(interval);
                let mut dy = [0.0; STATE];
                ev.rhs_into::<STATE>(s, y, &mut dy);
                slope += 0.5 * n.dot(&v3(&dy, 0));
            }
            let dg = slope - props.radius_rate;
            rows.push(dg - (1.0 - mu) * a.dg0);
        }
        if a.state == ContactState::Frictionless {
            let (t1, t2) = obstacle_normal_basis(&n);
            rows.push(f.dot(&t1));
            rows.push(f.dot(&t2));
        } else {
            self.friction_rows(a, first.0, f, mu, rows);
        }
    }

    /// The gap (m) and outward normal of obstacle `o` at every node of the last pass (first
    /// copy of a break).
    fn gaps(&self, o: usize) -> Vec<GapSample> {
        let Some(pass) = &self.last else {
            return Vec::new();
        };
        let mut out: Vec<GapSample> = Vec::new();
        for (j, n) in pass.nodes.iter().enumerate() {
            if out.last().is_some_and(|l| l.1 == n.s) {
                continue;
            }
            let (d, normal) = self.obstacles[o].distance(&v3(&n.y, 0));
            let r = pass.model.rod().section_at(n.s).radius;
            out.push((j, n.s, d - r, normal));
        }
        out
    }

    /// The arc length (m) where the rod's surface runs deepest into obstacle `o` between two
    /// consecutive nodes of the last pass whose own gaps `(j, s, gap, _)` do not show it (an
    /// obstacle thinner than the node spacing), if it runs in by more than `penetration` and a
    /// thousandth of the cell ([`sweep`](super::sweep)).
    fn penetration_in_cell(
        &self,
        o: usize,
        (a, b): (&GapSample, &GapSample),
        penetration: f64,
    ) -> Option<f64> {
        let pass = self.last.as_ref()?;
        let h = b.1 - a.1;
        let end = |j: usize, s: f64| {
            CellEnd::at_node(&pass.nodes[j].y, h, pass.model.rod().section_at(s).radius)
        };
        let threshold = -penetration.max(1e-3 * h);
        let (ea, eb) = (end(a.0, a.1), end(b.0, b.1));
        least_gap_in_cell(&self.obstacles[o], (&ea, a.2), (&eb, b.2), threshold)
            .map(|(t, _)| a.1 + t * h)
    }

    /// The normal force (N, signed) and normal of each active contact at `x` (last pass).
    fn normal_forces(&self, x: &[f64]) -> Forces {
        let Some(pass) = &self.last else {
            return Vec::new();
        };
        let l = self.model.length();
        let fs = self.model.force_scale();
        self.active
            .iter()
            .zip(self.offsets())
            .map(|(a, o)| {
                let (s, k) = match a.site {
                    Site::Tip => (l, o),
                    Site::Interior | Site::Interval => (x[o] * l, o + 1),
                };
                let node = pass
                    .nodes
                    .iter()
                    .find(|n| n.s == s)
                    .unwrap_or(&pass.nodes[0]);
                let p = v3(&node.y, 0);
                let (_, n) = self.obstacles[a.obstacle].distance(&p);
                let f = Vector3::new(x[k], x[k + 1], x[k + 2]) * fs;
                (f.dot(&n), n, s, p)
            })
            .collect()
    }
}

impl Problem for Constrained<'_> {
    fn dim(&self) -> usize {
        Self::dim_of(&self.active)
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        lambda: f64,
        jacobian: Option<&mut [f64]>,
        r: &mut [f64],
    ) -> Evaluated {
        self.evaluate_inner(x, lambda, jacobian, r)
    }

    fn commit(&mut self) {
        if let Some(p) = &self.last {
            self.reference = p.nodes.iter().map(|n| v3(&n.y, 0)).collect();
        }
    }

    fn close(&self) -> bool {
        let (Some(p), false) = (&self.last, self.reference.is_empty()) else {
            return false;
        };
        let limit = 0.5 * MAX_LOAD_STEP_TURN * self.model.length();
        let now: Vec<Vector3<f64>> = p.nodes.iter().map(|n| v3(&n.y, 0)).collect();
        if now.len() == self.reference.len() {
            now.iter()
                .zip(&self.reference)
                .all(|(a, b)| (a - b).norm() <= limit)
        } else {
            match (now.last(), self.reference.last()) {
                (Some(a), Some(b)) => (a - b).norm() <= limit,
                _ => false,
            }
        }
    }
}

impl Constrained<'_> {
    /// [`Problem::evaluate`]: a residual asked again at the last evaluation is not marched
    /// again; a Jacobian with contacts comes from one march with the variational columns
    /// (forward differences only when they do not fit in one march).
    fn evaluate_inner(
        &mut self,
        x: &[f64],
        lambda: f64,
        mut jacobian: Option<&mut [f64]>,
        r: &mut [f64],
    ) -> Evaluated {
        let n = self.dim();
        let exact = self.active.is_empty();
        if jacobian.is_none() {
            if let Some(last) = self.last.as_ref().filter(|l| l.key == self.key(x, lambda)) {
                r.copy_from_slice(&last.rows);
                return Evaluated::Residual;
            }
        }
        if let (Some(j), Some(coarse)) = (jacobian.as_deref_mut(), self.coarse) {
            // The Jacobian on the coarse mesh, the rows on the fine one.
            let fine = std::mem::replace(&mut self.integrator, coarse);
            self.coarse = None;
            self.rough = true;
            let mut rc = vec![0.0; n];
            let got = self.evaluate_inner(x, lambda, Some(&mut *j), &mut rc);
            self.integrator = fine;
            self.coarse = Some(coarse);
            self.rough = false;
            self.last = None;
            if got != Evaluated::Jacobian {
                return Evaluated::Failed;
            }
            let Some((rows, _)) = self.run(x, lambda, false) else {
                return Evaluated::Failed;
            };
            r.copy_from_slice(&rows);
            return Evaluated::Jacobian;
        }
        if let (Some(j), false) = (jacobian.as_deref_mut(), exact) {
            if let Some(rows) = self.exact(x, lambda, j) {
                r.copy_from_slice(&rows);
                return Evaluated::Jacobian;
            }
        }
        let Some((rows, jac)) = self.run(x, lambda, jacobian.is_some() && exact) else {
            return Evaluated::Failed;
        };
        r.copy_from_slice(&rows);
        let Some(j) = jacobian else {
            return Evaluated::Residual;
        };
        if let Some(cols) = jac {
            for (c, col) in cols.iter().enumerate() {
                j[n * c..n * c + 6].copy_from_slice(col);
            }
            return Evaluated::Jacobian;
        }
        // Forward differences over every unknown (the contact forces move the breaks).
        let saved = self.last.take();
        let mut xp = x.to_vec();
        for c in 0..n {
            let h = DIFFERENCE_STEP * (1.0 + x[c].abs());
            xp[c] = x[c] + h;
            let plus = self.run(&xp, lambda, false);
            xp[c] = x[c];
            let Some((a, _)) = plus else {
                self.last = saved;
                return Evaluated::Failed;
            };
            for i in 0..n {
                j[i + n * c] = (a[i] - rows[i]) / h;
            }
        }
        self.last = saved;
        Evaluated::Jacobian
    }
}

/// Effort of a solve.
#[derive(Default)]
pub(super) struct Effort {
    pub(super) iterations: usize,
    pub(super) load_steps: usize,
}

/// Newton at the full contact targets from `x`; the last pass left at the result.
pub(super) fn correct(
    p: &mut Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    exact_newton(p, x, opts, effort, true, false).map(|(x, _)| x)
}

/// Residual below which [`exact_newton`] stops refining a converged iterate (a fraction of
/// the tolerance, above round-off).
fn round_off(opts: &NewtonOptions) -> f64 {
    (opts.tolerance * 1e-4).max(64.0 * f64::EPSILON)
}

/// Newton at the full contact targets from `x` (the residual alone first when
/// `residual_first`): an exact Jacobian (one march with the variational columns) at the
/// start, then Broyden's rank-one updates between residual-only marches; a full step that
/// does not lower the residual's max norm (Armijo) is retried with the exact Jacobian at the
/// current iterate, and an exact step is halved until it does. Once within the tolerance, up
/// to two more steps are taken while they lower the residual toward round-off, so that the
/// balance of the reactions holds to the digits of the loads. Returns the iterate and its
/// residual, the last pass at it; `None` if the tolerance is not met.
fn exact_newton(
    p: &mut Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
    effort: &mut Effort,
    residual_first: bool,
    normal_first: bool,
) -> Option<(Vec<f64>, f64)> {
    let n = p.dim();
    let mut x = x.to_vec();
    let mut r = vec![0.0; n];
    let mut j = vec![0.0; n * n];
    if residual_first {
        if p.evaluate(&x, 1.0, None, &mut r) == Evaluated::Failed {
            return None;
        }
        let norm = max_norm(&r);
        if norm <= round_off(opts) {
            return Some((x, norm));
        }
    }
    let mut exact = start_jacobian(p, &x, residual_first, &mut j, &mut r)?;
    let mut norm = max_norm(&r);
    let (mut xt, mut rt) = (vec![0.0; n], vec![0.0; n]);
    if normal_first && predict(p, &mut x, &mut j, &mut r, effort) {
        exact = false;
        norm = max_norm(&r);
    }
    let mut lu = DenseLu::default();
    let mut refined = 0;
    // At most `max_iterations` accepted steps, and as many exact re-evaluations.
    let (mut steps, mut retries) = (0, 0);
    while steps < opts.max_iterations && retries <= opts.max_iterations {
        if norm <= opts.tolerance {
            if norm <= round_off(opts) || refined >= 2 || !p.refine {
                p.solved = Some((p.active.clone(), j));
                return Some((x, norm));
            }
            refined += 1;
        }
        let mut dx: Vec<f64> = r.iter().map(|v| -v).collect();
        if !(lu.factor(n, &j) && lu.solve_in_place(&mut dx)) {
            if exact {
                break;
            }
            // A singular update: the exact Jacobian here.
            retries += 1;
            if p.evaluate(&x, 1.0, Some(&mut j), &mut r) != Evaluated::Jacobian {
                break;
            }
            exact = true;
            norm = max_norm(&r);
            continue;
        }
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..=MAX_LINE_SEARCH_HALVINGS {
            for k in 0..n {
                xt[k] = x[k] + alpha * dx[k];
            }
            if p.evaluate(&xt, 1.0, None, &mut rt) != Evaluated::Failed {
                let trial = max_norm(&rt);
                if trial <= (1.0 - 1e-4 * alpha) * norm {
                    accepted = true;
                    break;
                }
            }
            if norm <= opts.tolerance || !exact {
                // Refining, or a Broyden step: a step that does not help is not halved.
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            if exact {
                break;
            }
            // The exact Jacobian at the iterate, and its step.
            retries += 1;
            if p.evaluate(&x, 1.0, Some(&mut j), &mut r) != Evaluated::Jacobian {
                break;
            }
            exact = true;
            norm = max_norm(&r);
            continue;
        }
        effort.iterations += 1;
        steps += 1;
        let step: Vec<f64> = dx.iter().map(|v| alpha * v).collect();
        broyden(&mut j, &step, &r, &rt);
        exact = false;
        std::mem::swap(&mut x, &mut xt);
        std::mem::swap(&mut r, &mut rt);
        norm = max_norm(&r);
    }
    if norm > opts.tolerance {
        return None;
    }
    // The last pass back at the iterate.
    if p.evaluate(&x, 1.0, None, &mut r) == Evaluated::Failed {
        return None;
    }
    p.solved = Some((p.active.clone(), j));
    Some((x, norm))
}

/// The Jacobian `j` and residual `r` at `x` that Newton starts from: the one handed over in
/// `p.hint` for the current active set (from the coarse mesh, or the solve that found `x`;
/// `r` already evaluated if `residual_first`), else the exact one. Returns whether it is
/// exact; `None` if the evaluation fails.
fn start_jacobian(
    p: &mut Constrained<'_>,
    x: &[f64],
    residual_first: bool,
    j: &mut Vec<f64>,
    r: &mut [f64],
) -> Option<bool> {
    let n = p.dim();
    let hint = p
        .hint
        .take()
        .filter(|(a, h)| *a == p.active && h.len() == n * n);
    if let Some((_, h)) = hint {
        if !residual_first && p.evaluate(x, 1.0, None, r) == Evaluated::Failed {
            return None;
        }
        *j = h;
        return Some(false);
    }
    (p.evaluate(x, 1.0, Some(j), r) == Evaluated::Jacobian).then_some(true)
}

/// The predictor of newly added contacts ([`normal_step`]) from `x` with the exact Jacobian
/// `j` and residual `r` there: taken (and `j` updated by Broyden's formula) if it lowers the
/// gaps; `true` then, with `x`, `j` and `r` at the new iterate.
fn predict(
    p: &mut Constrained<'_>,
    x: &mut Vec<f64>,
    j: &mut [f64],
    r: &mut Vec<f64>,
    effort: &mut Effort,
) -> bool {
    let Some(dx) = normal_step(p, x, j, r) else {
        return false;
    };
    let xt: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + b).collect();
    let mut rt = vec![0.0; r.len()];
    let offsets = p.offsets();
    let gaps = |r: &[f64]| offsets.iter().map(|&o| r[o].abs()).fold(0.0, f64::max);
    if p.evaluate(&xt, 1.0, None, &mut rt) == Evaluated::Failed || gaps(&rt) >= gaps(r) {
        return false;
    }
    effort.iterations += 1;
    broyden(j, &dx, r, &rt);
    *x = xt;
    *r = rt;
    true
}

/// Broyden's update of the column-major Jacobian `j` by the step `dx` that took the
/// residual from `r` to `rt`: `J += (Δr - J Δx) Δxᵀ / (Δxᵀ Δx)`.
fn broyden(j: &mut [f64], dx: &[f64], r: &[f64], rt: &[f64]) {
    let n = dx.len();
    let ss: f64 = dx.iter().map(|v| v * v).sum();
    if ss <= 0.0 {
        return;
    }
    let mut u: Vec<f64> = (0..n).map(|i| rt[i] - r[i]).collect();
    for (c, sc) in dx.iter().enumerate() {
        for (i, ui) in u.iter_mut().enumerate() {
            *ui -= j[i + n * c] * sc;
        }
    }
    for (c, sc) in dx.iter().enumerate() {
        let w = sc / ss;
        for (i, ui) in u.iter().enumerate() {
            j[i + n * c] += ui * w;
        }
    }
}

/// The step from `x` (Jacobian `j`, residual `r`, the last pass at `x`) of the linearised
/// problem with every contact held at its arc length and its force changed along the
/// obstacle's normal there: the tip rows and the gap rows solved for the base wrench and one
/// normal force per contact (the contact-free compliance along the normal gives the force
/// that closes the gap). `None` if that system is singular.
fn normal_step(p: &Constrained<'_>, x: &[f64], j: &[f64], r: &[f64]) -> Option<Vec<f64>> {
    let n = p.dim();
    let forces = p.normal_forces(x);
    let offsets = p.offsets();
    let m = 6 + p.active.len();
    let rows: Vec<usize> = (0..6).chain(offsets.iter().copied()).collect();
    let first_force: Vec<usize> = p
        .active
        .iter()
        .zip(&offsets)
        .map(|(a, &o)| if a.site == Site::Tip { o } else { o + 1 })
        .collect();
    let mut a = vec![0.0; m * m];
    for c in 0..6 {
        for (ri, &i) in rows.iter().enumerate() {
            a[ri + m * c] = j[i + n * c];
        }
    }
    for (k, &f0) in first_force.iter().enumerate() {
        let normal = forces.get(k)?.1;
        for (ri, &i) in rows.iter().enumerate() {
            a[ri + m * (6 + k)] = (0..3).map(|q| j[i + n * (f0 + q)] * normal[q]).sum();
        }
    }
    let mut rhs: Vec<f64> = rows.iter().map(|&i| -r[i]).collect();
    let mut lu = DenseLu::default();
    if !(lu.factor(m, &a) && lu.solve_in_place(&mut rhs)) {
        return None;
    }
    let mut dx = vec![0.0; n];
    dx[..6].copy_from_slice(&rhs[..6]);
    for (k, &f0) in first_force.iter().enumerate() {
        let normal = forces[k].1;
        for q in 0..3 {
            dx[f0 + q] = rhs[6 + k] * normal[q];
        }
    }
    Some(dx)
}

/// The gap at a node of the last pass: `(node index, s (m), gap (m), outward normal)`.
type GapSample = (usize, f64, f64, Vector3<f64>);

/// Normal forces, normal, arc length and point of each active contact at `x`.
pub(super) type Forces = Vec<(f64, Vector3<f64>, f64, Vector3<f64>)>;

/// New contacts at the local minima of the gaps below `-penetration` (not at an existing
/// contact, not inside an interval).
fn candidates(p: &Constrained<'_>, forces: &Forces, penetration: f64) -> Vec<(usize, Site, f64)> {
    let l = p.model.length();
    let mut added = Vec::new();
    for o in 0..p.obstacles.len() {
        let g = p.gaps(o);
        for i in 1..g.len() {
            let (_, s, gi, _) = g[i];
            let at_tip = i + 1 == g.len();
            let minimum = gi < -penetration && gi <= g[i - 1].2 && (at_tip || gi <= g[i + 1].2);
            let taken = forces
                .iter()
                .zip(&p.active)
                .any(|(f, a)| a.obstacle == o && (f.2 - s).abs() <= 1e-12 * l);
            let inside = p
                .active
                .iter()
                .zip(forces)
                .any(|(a, f)| a.obstacle == o && a.site == Site::Interval && s >= f.2);
            if minimum && !taken && !inside {
                if at_tip {
                    added.push((o, Site::Tip, s));
                } else {
                    added.push((o, Site::Interior, parabola_minimum(&g[i - 1..=i + 1])));
                }
            }
        }
    }
    added
}

/// New contacts where the rod runs into an obstacle between two nodes whose own gaps do not
/// show it (an obstacle thinner than the node spacing), away from the active contacts: the
/// last check of the active set, once no node penetrates.
fn cell_candidates(
    p: &Constrained<'_>,
    forces: &Forces,
    penetration: f64,
) -> Vec<(usize, Site, f64)> {
    let l = p.model.length();
    let mut added = Vec::new();
    for o in 0..p.obstacles.len() {
        let g = p.gaps(o);
        for i in 1..g.len() {
            let (s0, s1) = (g[i - 1].1, g[i].1);
            let near = |s: f64| s >= s0 - 1e-12 * l && s <= s1 + 1e-12 * l;
            let covered = forces.iter().zip(&p.active).any(|(f, a)| {
                a.obstacle == o && (near(f.2) || (a.site == Site::Interval && s1 >= f.2))
            });
            if covered || g[i - 1].2 < -penetration || g[i].2 < -penetration {
                continue;
            }
            if let Some(s) = p.penetration_in_cell(o, (&g[i - 1], &g[i]), penetration) {
                added.push((o, Site::Interior, s));
            }
        }
    }
    added
}

/// The arc length of the least gap of the parabola through three consecutive samples
/// `(_, s, gap, _)` whose middle one is a local minimum (its own arc length if the three are
/// collinear): a new contact starts where the gap is least, not at the nearest node.
fn parabola_minimum(g: &[GapSample]) -> f64 {
    let ((_, s0, g0, _), (_, s1, g1, _), (_, s2, g2, _)) = (g[0], g[1], g[2]);
    let (h0, h1) = (s1 - s0, s2 - s1);
    let (d0, d1) = ((g1 - g0) / h0, (g2 - g1) / h1);
    let curvature = 2.0 * (d1 - d0) / (h0 + h1);
    if !(curvature > 0.0 && h0 > 0.0 && h1 > 0.0) {
        return s1;
    }
    // The slope at s1 of the parabola, and its zero.
    let slope = (d0 * h1 + d1 * h0) / (h0 + h1);
    (s1 - slope / curvature).clamp(s0, s2)
}

/// A plane touched twice (or an interval touched before its edge) becomes one interval from
/// the first contact to the tip; `true` if a merge was made.
fn merge_plane(
    p: &mut Constrained<'_>,
    x: &mut Vec<f64>,
    forces: &Forces,
    added: &[(usize, Site, f64)],
) -> bool {
    let l = p.model.length();
    for &(o, _, s) in added {
        if !matches!(p.obstacles[o].shape(), Obstacle::Plane { .. }) {
            continue;
        }
        let offsets = p.offsets();
        let on: Vec<usize> = (0..p.active.len())
            .filter(|i| p.active[*i].obstacle == o)
            .collect();
        if on.is_empty() {
            continue;
        }
        let mut a = s;
        for &i in &on {
            a = a.min(forces[i].2);
        }
        if a >= l {
            continue;
        }
        for &i in on.iter().rev() {
            let size = p.active[i].size();
            p.active.remove(i);
            x.drain(offsets[i]..offsets[i] + size);
        }
        p.active.push(Active::frictionless(o, Site::Interval));
        x.push(a / l);
        x.extend([0.0; 3]);
        return true;
    }
    false
}

/// Adds the contacts `added` at zero force and relaxes their gaps from the values found to
/// zero by continuation; the state at full contact targets.
fn add_contacts(
    p: &mut Constrained<'_>,
    mut x: Vec<f64>,
    added: Vec<(usize, Site, f64)>,
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    let l = p.model.length();
    for a in &mut p.active {
        a.g0 = 0.0;
        a.dg0 = 0.0;
        a.t0 = [0.0; 2];
    }
    // Where the new contacts with friction first touched, on the load path.
    let mut touched = Vec::with_capacity(added.len());
    for &(o, site, _) in &added {
        let rough = site == Site::Tip && p.obstacles[o].friction() > 0.0;
        touched.push(if rough {
            Some(first_touch(p, &x, o, opts, effort)?)
        } else {
            None
        });
    }
    for ((o, site, s), touched) in added.into_iter().zip(touched) {
        let mut a = Active::frictionless(o, site);
        if let Some((reference, touch, _)) = touched {
            a.state = ContactState::Stick;
            a.reference = reference;
            a.touch = touch;
        }
        p.active.push(a);
        if site != Site::Tip {
            x.push(s / l);
        }
        x.extend([0.0; 3]);
    }
    // Straight to the contact (one exact Newton solve), else by relaxing the gaps.
    if let Some((xs, _)) = exact_newton(p, &x, opts, effort, false, true) {
        return Some(xs);
    }
    // The gap targets of the new contacts: their rows at zero force.
    let mut r = vec![0.0; p.dim()];
    if p.evaluate(&x, 1.0, None, &mut r) == Evaluated::Failed {
        return None;
    }
    let offsets = p.offsets();
    for (a, o) in p.active.iter_mut().zip(offsets) {
        a.g0 = r[o] * l;
        if a.site != Site::Tip {
            a.dg0 = r[o + 1];
        }
        if a.state == ContactState::Stick {
            a.t0 = [r[o + 1] * l, r[o + 2] * l];
        }
    }
    let start = ContinuationSettings {
        x0: &x,
        jacobian0: None,
        first_increment: 1.0,
        max_increment: 1.0,
    };
    let c = continuation(p, &start, opts, &settings(true, None, false));
    effort.iterations += c.iterations;
    for a in &mut p.active {
        a.g0 = 0.0;
        a.dg0 = 0.0;
        a.t0 = [0.0; 2];
    }
    if !(c.outcome.converged && c.load_factor >= 1.0) {
        return None;
    }
    correct(p, &c.outcome.x, opts, effort)
}

/// The active-set loop at the current load factor from the state `x` (converged at the
/// previous load factor): Newton; release the contact pulling hardest; add one contact at
/// each local minimum of a gap below `-penetration`, reached by relaxing its gap from the
/// current value; until no contact pulls and nothing penetrates.
pub(super) fn active_set(
    p: &mut Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    let l = p.model.length();
    let fs = p.model.force_scale();
    let penetration = 10.0 * opts.tolerance * l;
    let mut x = correct(p, x, opts, effort)?;
    for _ in 0..MAX_ACTIVE_SET_ROUNDS {
        // Release the most negative contact force.
        let forces = p.normal_forces(&x);
        let worst = forces
            .iter()
            .enumerate()
            .filter(|(_, f)| f.0 < -opts.tolerance * fs)
            .min_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
            .map(|(i, _)| i);
        if let Some(i) = worst {
            let o = p.offsets()[i];
            let size = p.active[i].size();
            p.active.remove(i);
            x.drain(o..o + size);
            x = correct(p, &x, opts, effort)?;
            continue;
        }
        // Sticking outside the cone, or sliding back to where it touched.
        if let Some((i, state, direction)) = switch(p, &x, opts) {
            p.active[i].state = state;
            if direction.is_some() {
                // First along the slip the sticking force pushed to, then free to turn.
                p.active[i].direction = direction;
                x = correct(p, &x, opts, effort)?;
                p.active[i].direction = None;
            }
            x = correct(p, &x, opts, effort)?;
            continue;
        }
        let mut added = candidates(p, &forces, penetration);
        if added.is_empty() {
            added = cell_candidates(p, &forces, penetration);
        }
        if let Some(&(o, _, _)) = added
            .iter()
            .find(|(o, site, _)| *site != Site::Tip && p.obstacles[*o].friction() > 0.0)
        {
            // Friction inside the rod is not modelled: refused, not solved without it.
            p.refused = Some(p.obstacles[o].friction());
            return None;
        }
        if merge_plane(p, &mut x, &forces, &added) {
            x = correct(p, &x, opts, effort)?;
            continue;
        }
        // An interval whose segment lifts off the plane is only its edge contact.
        let lifted = p.active.iter().enumerate().position(|(i, a)| {
            a.site == Site::Interval
                && p.gaps(a.obstacle)
                    .iter()
                    .any(|g| g.1 > forces[i].2 && g.2 > penetration)
        });
        if let Some(i) = lifted {
            p.active[i].site = Site::Interior;
            x = correct(p, &x, opts, effort)?;
            continue;
        }
        if added.is_empty() {
            return Some(x);
        }
        x = add_contacts(p, x, added, opts, effort)?;
    }
    None
}

/// Steps the load factor (external loads and tip target) from 0 to 1 from the state `x`
/// at load factor 0, halving a step whose active-set loop fails or moves the shape too far;
/// on failure, the load factor reached and why.
fn step_loads(
    p: &mut Constrained<'_>,
    mut x: Vec<f64>,
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> std::result::Result<Vec<f64>, (f64, &'static str, Vec<f64>)> {
    let mut lambda = 0.0;
    let mut dl: f64 = 1.0;
    while lambda < 1.0 {
        if effort.load_steps >= opts.max_load_steps {
            return Err((lambda, "the load steps ran out", x));
        }
        let target = (lambda + dl).min(1.0);
        let saved = (x.clone(), p.active.clone());
        p.load = target;
        effort.load_steps += 1;
        match active_set(p, &x, opts, effort) {
            Some(xs) if p.close() || !opts.continuation => {
                x = xs;
                lambda = target;
                p.from = lambda;
                p.commit();
                dl = (dl * 2.0).min(1.0);
            }
            _ => {
                (x, p.active) = saved;
                p.load = lambda;
                if !opts.continuation {
                    return Err((lambda, "the direct solve failed", x));
                }
                dl *= 0.5;
                if dl < MIN_LOAD_INCREMENT {
                    return Err((
                        lambda,
                        "no load step converged (load increment underflow)",
                        x,
                    ));
                }
            }
        }
    }
    Ok(x)
}

/// Solves the statics of `model` under `actuation` with the tip held by `tip` (if any) and
/// the rod's surface kept out of `obstacles` by unilateral contact (frictionless, or with
/// Coulomb friction at the tip: see [`Obstacle::with_friction`] and [`ContactState`]).
///
/// The unknowns are the base wrench (as in [`solve_statics`]), the force of every active
/// contact and, for a contact inside the rod, its arc length; the residual the tip
/// conditions (the held directions' pose error, the free directions' wrench balance), and per
/// contact its gap (zero), the slope of the gap along the rod (zero: the contact sits at the
/// least gap), and the force's components along the obstacle's surface (zero: frictionless).
/// The contacts are found by an active set: a contact is added at every local minimum of a
/// gap below `-10 tolerance L` (reached by relaxing its gap from the penetration found) and
/// released when its normal force is negative, until no force pulls and nothing penetrates.
/// The external loads and the tip target (from the unloaded tip pose) are stepped by load
/// continuation when the direct solve fails.
///
/// # Errors
/// As [`solve_statics`] for the model, actuation and options; [`Error::InvalidParameter`]
/// naming `friction` when an obstacle with friction is touched inside the rod (friction is
/// modelled at tip contacts only); [`Error::NotConverged`] (with
/// the iterations, residual and load factor reached) when no equilibrium with a consistent
/// active set is found and `options.newton.throw` is set.
pub fn solve_constrained(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    tip: Option<&TipConstraint>,
    obstacles: &[Obstacle],
) -> Result<ContactSolution> {
    options.validate()?;
    model.check_actuation(actuation)?;
    if tip.is_none() && obstacles.is_empty() {
        let solution = solve_statics(model, actuation, options)?;
        let n = solution.s.len();
        return Ok(ContactSolution {
            solution,
            tip_reaction: None,
            contacts: Vec::new(),
            contact_force: vec![[0.0; 3]; n],
            conjugate_points: None,
            compliance: ContactCompliance::default(),
        });
    }
    let tensions = actuation.tension_values(model.tendons().len());
    let pressures = actuation.pressure_values(model.chambers().len());
    let mut p = Constrained {
        model,
        shared: model,
        tensions,
        pressures,
        integrator: options.integrator,
        tip: tip.copied(),
        start: (Vector3::zeros(), Matrix3::identity()),
        obstacles,
        active: Vec::new(),
        load: 0.0,
        last: None,
        reference: Vec::new(),
        evaluations: 0,
        coarse: None,
        hint: None,
        solved: None,
        refine: true,
        rough: false,
        from: 0.0,
        refused: None,
    };
    // The actuated rod without loads: the target of the tip at load factor 0.
    let mut effort = Effort::default();
    // (Not with a triangle mesh: the curvature of its distance jumps between faces and
    // edges, and Newton from the coarse solution may settle on another face.)
    let smooth = !obstacles
        .iter()
        .any(|o| matches!(o.shape(), Obstacle::Mesh(_)));
    if let Some(coarse) = coarse_mesh(options.integrator).filter(|_| smooth) {
        // The contacts and the nonlinear iterations on the coarse mesh; then Newton on the
        // mesh asked from there, with the coarse Jacobian, and the active set checked there.
        p.integrator = coarse;
        (p.refine, p.rough) = (false, true);
        let mut start = *options;
        start.newton.tolerance = options.newton.tolerance.max(COARSE_TOLERANCE);
        let reached = reach(&mut p, &start, &mut effort);
        (p.refine, p.rough) = (true, false);
        if let Reach::Done(xc) = reached {
            p.integrator = options.integrator;
            p.coarse = Some(coarse);
            p.last = None;
            p.load = 1.0;
            p.hint = p.solved.take();
            retouch(&mut p, &xc, &options.newton, &mut effort);
            if let Some(x) = active_set(&mut p, &xc, &options.newton, &mut effort) {
                return finish_unless_crossed(&mut p, (model, actuation), options, x, &mut effort);
            }
        }
        if let Some(e) = refusal(&p) {
            return Err(e);
        }
        // Else the mesh asked from the start (its iterations and load steps are those
        // reported; the evaluations count both).
        effort = Effort::default();
        p.integrator = options.integrator;
        p.coarse = None;
        p.active.clear();
        p.last = None;
        p.load = 0.0;
        p.reference.clear();
        p.hint = None;
        p.solved = None;
    }
    let reached = reach(&mut p, options, &mut effort);
    if let Some(e) = refusal(&p) {
        return Err(e);
    }
    match reached {
        Reach::Done(x) => {
            p.load = 1.0;
            finish_unless_crossed(&mut p, (model, actuation), options, x, &mut effort)
        }
        Reach::Stopped { lambda, why, .. } if options.newton.throw => {
            fail(&p, &options.newton, &effort, lambda, why)
        }
        Reach::Stopped { x, lambda, .. } => {
            p.load = 1.0;
            finish(&mut p, model, actuation, options, &x, &effort, lambda)
        }
        Reach::Unintegrable => Err(Error::not_converged(
            "constrained shooting: the actuated rod without external loads could not be \
             integrated",
            0,
            f64::INFINITY,
        )),
    }
}

/// The error of an obstacle with friction touched inside the rod, if one was.
fn refusal(p: &Constrained<'_>) -> Option<Error> {
    p.refused.map(|mu| {
        Error::invalid(
            "friction",
            mu,
            "0 for an obstacle touched inside the rod (Coulomb friction is modelled at tip \
             contacts only)",
        )
    })
}

/// Steps of the coarse mesh of the contact solve with `integrator`: RK4 with a fifth of its
/// steps (at least [`MIN_COARSE_STEPS`]); `None` (no coarse mesh) otherwise.
fn coarse_mesh(integrator: Integrator) -> Option<Integrator> {
    match integrator {
        Integrator::Rk4 { steps } if steps >= COARSE_RATIO * MIN_COARSE_STEPS => {
            Some(Integrator::Rk4 {
                steps: steps / COARSE_RATIO,
            })
        }
        _ => None,
    }
}

/// What [`reach`] reached.
enum Reach {
    /// Converged at full load, the unknowns.
    Done(Vec<f64>),
    /// Stopped at load factor `lambda` (the active set as left, the unknowns reached).
    Stopped {
        x: Vec<f64>,
        lambda: f64,
        why: &'static str,
    },
    /// The actuated rod without loads could not be integrated.
    Unintegrable,
}

/// The active set and the unknowns at full load from the unloaded rod (or the warm start):
/// the contacts of the actuated rod at load factor 0, then the loads and the tip target
/// stepped by continuation.
fn reach(p: &mut Constrained<'_>, options: &SolveOptions, effort: &mut Effort) -> Reach {
    let model = p.model;
    let zero = vec![0.0; 6];
    let free_tip = p.tip.take();
    let unloaded = p.run(&zero, 1.0, false).map(|_| ());
    p.tip = free_tip;
    let start_node = p.last.as_ref().and_then(|l| l.nodes.last().copied());
    let (Some(()), Some(node)) = (unloaded, start_node) else {
        return Reach::Unintegrable;
    };
    p.start = (v3(&node.y, 0), rot(&node.y));
    p.commit();
    let opts = options.newton;
    let mut x: Vec<f64> = match &options.warm_start {
        Some(w) => scaled(model, &w.base_wrench).to_vec(),
        None => zero.clone(),
    };
    let mut reached = None;
    if options.warm_start.is_some() {
        p.load = 1.0;
        if let Some(xs) = active_set(p, &x, &opts, effort) {
            reached = Some(xs);
        } else {
            p.active.clear();
            x = zero.clone();
            p.load = 0.0;
        }
    }
    if reached.is_none() {
        // Load factor 0 (contacts of the actuated rod), then the loads and the target.
        match active_set(p, &x, &opts, effort) {
            Some(xs) => x = xs,
            None => {
                // The last state reached (not converged), under the full loads.
                p.active.clear();
                return Reach::Stopped {
                    x: x[..6].to_vec(),
                    lambda: 0.0,
                    why: "no contact set at load factor 0",
                };
            }
        }
        p.commit();
        if !(model.loads().is_unloaded() && p.tip.is_none()) {
            // (Otherwise nothing is stepped: load factor 0 is the problem.)
            x = match step_loads(p, x, &opts, effort) {
                Ok(x) => x,
                Err((lambda, why, x)) => return Reach::Stopped { x, lambda, why },
            };
        }
        reached = Some(x);
    }
    Reach::Done(reached.unwrap_or_default())
}

/// The solution at `x` ([`finish`]) once checked for obstacles crossed on the way
/// ([`not_crossed`]).
fn finish_unless_crossed(
    p: &mut Constrained<'_>,
    (model, actuation): (&Arc<RobotModel>, &Actuation),
    options: &SolveOptions,
    x: Vec<f64>,
    effort: &mut Effort,
) -> Result<ContactSolution> {
    match not_crossed(p, x, options, effort) {
        Ok(x) => finish(p, model, actuation, options, &x, effort, 1.0),
        Err(why) => fail(p, &options.newton, effort, 0.0, why),
    }
}

/// The solution `x` (its pass the last of `p`) if no point of the rod crossed an obstacle on
/// its way from the unactuated rod, else the solve again with the actuation and the loads
/// stepped together ([`ramp`](super::ramp); free tip only).
fn not_crossed(
    p: &mut Constrained<'_>,
    x: Vec<f64>,
    options: &SolveOptions,
    effort: &mut Effort,
) -> std::result::Result<Vec<f64>, &'static str> {
    if p.tip.is_some() || !ramp::any_checked(p) {
        return Ok(x);
    }
    let (s, radius) = ramp::samples(p);
    let Some(shape) = p.last.as_ref().map(|pass| ramp::positions_at(pass, &s)) else {
        return Ok(x);
    };
    let last = p.last.take();
    let Some(rest) = ramp::rest_shape(p, &s) else {
        p.last = last;
        return Ok(x);
    };
    let depth = 10.0 * options.newton.tolerance * p.model.length();
    if !ramp::crossed(p, (&rest, &shape), &radius, depth) {
        p.last = last;
        return Ok(x);
    }
    // Stepped on the mesh asked.
    (p.integrator, p.coarse, p.refine, p.rough) = (options.integrator, None, true, false);
    let full = (p.tensions.clone(), p.pressures.clone());
    let stepped = ramp::stepped(
        p,
        (&full.0, &full.1),
        (&s, &radius, rest),
        &options.newton,
        effort,
    );
    stepped.ok_or("the rod crossed a thin obstacle on its way from the unactuated rod, and stepping the actuation with the loads past it failed")
}

/// The error (or, without `throw`, nothing better to return) of a failed solve.
fn fail(
    p: &Constrained<'_>,
    opts: &NewtonOptions,
    effort: &Effort,
    lambda: f64,
    why: &str,
) -> Result<ContactSolution> {
    let _ = opts;
    Err(Error::NotConverged {
        what: format!("constrained shooting (tip constraint, contact): {why}"),
        iterations: effort.iterations,
        residual: p
            .last
            .as_ref()
            .map_or(f64::INFINITY, |l| max_norm(l.residual.as_slice())),
        load_factor: lambda,
    })
}

/// Exact Newton steps from the converged `x` toward round-off (see [`exact_newton`]), so
/// that the balance of the reactions holds to the digits of the loads, not only of the
/// tolerance; `x` itself if they do not lower the residual. The last pass is left at the
/// result, whose residual is returned (`None` if it cannot be integrated).
fn polish(p: &mut Constrained<'_>, x: &[f64], options: &SolveOptions) -> Option<(Vec<f64>, f64)> {
    let mut effort = Effort::default();
    p.hint = p.solved.take();
    if let Some(out) = exact_newton(p, x, &options.newton, &mut effort, true, false) {
        return Some(out);
    }
    let mut r = vec![0.0; p.dim()];
    (p.evaluate(x, 1.0, None, &mut r) != Evaluated::Failed).then(|| (x.to_vec(), max_norm(&r)))
}

/// The contacts of a solution and the contact force at its samples (an interval's
/// distributed reaction lumped by the trapezoid rule).
fn report(
    active: &[Active],
    forces: &Forces,
    tangential: &[Vector3<f64>],
    model: &RobotModel,
    cm: &RobotModel,
    sol: &crate::cosserat::StaticsSolution,
) -> (Vec<Contact>, Vec<[f64; 3]>) {
    let l = model.length();
    let mut contact_force = vec![[0.0; 3]; sol.s.len()];
    let mut contacts = Vec::with_capacity(forces.len());
    for (((fnorm, n, s, pc), a), ft) in forces.iter().zip(active).zip(tangential) {
        let radius = model.rod().section_at(*s).radius;
        let point = pc - n * radius;
        contacts.push(Contact {
            obstacle: a.obstacle,
            s: *s,
            length: 0.0,
            point: [point.x, point.y, point.z],
            normal: [n.x, n.y, n.z],
            normal_force: *fnorm,
            tangential_force: [ft.x, ft.y, ft.z],
            state: a.state,
        });
        if let Some(j) = sol.s.iter().rposition(|v| v == s) {
            for k in 0..3 {
                contact_force[j][k] += fnorm * n[k] + ft[k];
            }
        }
        if a.site == Site::Interval {
            // The distributed reaction on (a, L], lumped at the samples by the trapezoid rule.
            let after = f64::from_bits(s.to_bits() + 1);
            let density = |t: f64| {
                let mut f = cm
                    .loads()
                    .distributed_force
                    .as_ref()
                    .map_or(Vector3::zeros(), |p| p.at(t));
                // The model's distributed force already carries the reaction: take it alone.
                if let Some(g) = cm.rho_g() {
                    f += g * cm.rod().section_at(t).area;
                }
                f
            };
            let base = model.loads().distributed_force.as_ref();
            let mut total = 0.0;
            let idx: Vec<usize> = (0..sol.s.len()).filter(|j| sol.s[*j] >= after).collect();
            for w in idx.windows(2) {
                let (j0, j1) = (w[0], w[1]);
                let h = sol.s[j1] - sol.s[j0];
                if h <= 0.0 {
                    continue;
                }
                for j in [j0, j1] {
                    let t = sol.s[j];
                    let applied = base.map_or(Vector3::zeros(), |p| p.at(t));
                    let reaction = density(t)
                        - applied
                        - cm.rho_g()
                            .map_or(Vector3::zeros(), |g| g * cm.rod().section_at(t).area);
                    let lump = reaction * (0.5 * h);
                    total += lump.dot(n);
                    for k in 0..3 {
                        contact_force[j][k] += lump[k];
                    }
                }
            }
            let tip = Vector3::from(sol.tip_position()) - n * radius;
            contacts.push(Contact {
                obstacle: a.obstacle,
                s: after,
                length: l - after,
                point: [tip.x, tip.y, tip.z],
                normal: [n.x, n.y, n.z],
                normal_force: total,
                tangential_force: [0.0; 3],
                state: a.state,
            });
        }
    }
    (contacts, contact_force)
}

/// The stability of a rod with a held tip (see [`super::stability`]): whether stable, the
/// margin (the free directions' smallest stiffness; `+inf` for a full clamp, minus the
/// number of conjugate points when there are some) and the conjugate points.
fn held_stability(
    sh: &mut Shooting<'_>,
    x: &[f64],
    c: &TipConstraint,
    cols: &[Vector6<f64>],
    tw: &[Vector6<f64>; 6],
) -> (bool, f64, Option<usize>) {
    let l = sh.eq.model.length();
    let mut y = Matrix6::zeros();
    let mut xt = Matrix6::zeros();
    for k in 0..6 {
        for i in 0..6 {
            y[(i, k)] = cols[k][i];
            xt[(i, k)] = tw[k][i] / if i < 3 { l } else { 1.0 };
        }
    }
    let count = conjugate_points(sh, x).map(|c| c.0);
    let free: Vec<usize> = (0..6).filter(|k| !c.held[*k]).collect();
    let stiff = free_stiffness(&y, &xt, &c.pose.rotation(), &free);
    let (stable, margin) = match (count, stiff) {
        (Some(0), Some((m, neg))) => (neg == 0 && m > -NEUTRAL_MARGIN, m),
        (Some(0), None) if free.is_empty() => (true, f64::INFINITY),
        (Some(n), _) if n > 0 => (false, -(n as f64)),
        _ => (false, 0.0),
    };
    (stable, margin, count)
}

/// With a free tip, the stability of the contacts as dead loads from the exact Jacobian of
/// the pass at `x` (its base-wrench block and tip columns, as the compliance left it), so
/// that no march with the columns is needed again; `None` otherwise.
fn jacobian_stability(p: &Constrained<'_>, pass: &Pass, x: &[f64]) -> Option<Stability> {
    let (j, twists) = pass.jacobian.as_ref()?;
    if p.tip.is_some() || pass.key != p.key(x, 1.0) || twists.len() < 6 {
        return None;
    }
    let n = p.dim();
    let mut y = [0.0; 36];
    for c in 0..6 {
        y[6 * c..6 * c + 6].copy_from_slice(&j[n * c..n * c + 6]);
    }
    let tw: [Vector6<f64>; 6] = std::array::from_fn(|k| twists[k]);
    tip_stability(&y, &tw, p.model.length())
}

/// The shooting residual at the solution `x` and, with a held tip, the base-wrench columns,
/// with the nodes in `sh`: those of the last pass when it marched the state alone at `x` on
/// the mesh of `sh` (free tip), else from a new march.
fn final_march(
    p: &Constrained<'_>,
    sh: &mut Shooting<'_>,
    pass: Pass,
    x: &[f64],
) -> Result<(Vector6<f64>, Vec<Vector6<f64>>)> {
    if let Some((mesh, lengths, tensions)) = pass.marched {
        if p.tip.is_none() && mesh == sh.integrator && pass.key == p.key(x, 1.0) {
            sh.nodes = pass.nodes;
            sh.lengths = lengths;
            sh.tensions = tensions;
            return Ok((pass.residual, Vec::new()));
        }
    }
    let marched = if p.tip.is_none() {
        sh.pass::<STATE>(&x[..6], 1.0)
    } else {
        sh.pass::<FULL>(&x[..6], 1.0)
    };
    let (res, cols, _) = marched.map_err(|e| {
        Error::not_converged(format!("constrained shooting: {e}"), 0, f64::INFINITY)
    })?;
    Ok((res, cols))
}

/// The solution at the converged unknowns `x`: the shape with its contact forces, the tip
/// reaction, the contacts, the stability.
fn finish(
    p: &mut Constrained<'_>,
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    x: &[f64],
    effort: &Effort,
    load_factor: f64,
) -> Result<ContactSolution> {
    let reached = if load_factor >= 1.0 {
        polish(p, x, options)
    } else {
        let mut r = vec![0.0; p.dim()];
        (p.evaluate(x, 1.0, None, &mut r) != Evaluated::Failed).then(|| (x.to_vec(), max_norm(&r)))
    };
    let Some((polished, residual)) = reached else {
        return fail(
            p,
            &options.newton,
            effort,
            1.0,
            "the solution could not be integrated",
        );
    };
    let x: &[f64] = &polished;
    let forces = p.normal_forces(x);
    // The compliance under the constraints, on first read.
    let compliance =
        ContactCompliance::of((residual <= options.newton.tolerance).then(|| Frozen::at(p, x)));
    let Some(pass) = p.last.take() else {
        return fail(p, &options.newton, effort, 1.0, "no pass");
    };
    let free_stability = jacobian_stability(p, &pass, x);
    let cm = Arc::clone(&pass.model);
    let plan = match options.integrator {
        Integrator::Rk4 { steps } => rk4_plan(cm.breaks(), steps),
        Integrator::Adaptive(_) => Vec::new(),
    };
    let eq = Equations {
        model: &cm,
        tensions: &p.tensions,
        pressures: &p.pressures,
        load_factor: 1.0,
        profile: None,
    };
    let mut sh = Shooting::new(eq, options.integrator, plan);
    let (res, cols) = final_march(p, &mut sh, pass, x)?;
    let tip_twist = sh.tip_twist;
    let stats = SolverStats {
        iterations: effort.iterations,
        residual,
        function_evaluations: p.evaluations + sh.evaluations,
        converged: residual <= options.newton.tolerance && load_factor >= 1.0,
        load_steps: effort.load_steps,
        load_factor,
    };
    let fs = model.force_scale();
    let l = model.length();
    let mut sol = assemble(&mut sh, &cm, scaled_back(model, &x[..6]), stats, &[]);
    sol.actuation = actuation.clone();
    sol.options = *options;
    let tangential = p.tangential_forces(x, &forces);
    let (contacts, contact_force) = report(&p.active, &forces, &tangential, model, &cm, &sol);
    let tip_reaction = p.tip.as_ref().map(|_| {
        let f = res.fixed_rows::<3>(0) * fs;
        let m = res.fixed_rows::<3>(3) * (fs * l);
        [f.x, f.y, f.z, m.x, m.y, m.z]
    });
    // Stability: with a held tip, conjugate points and the free directions' stiffness; with
    // a free tip, the tip criterion of `solve_statics` (contacts as dead loads).
    let mut conjugate = None;
    if let (Some(c), Some(tw)) = (p.tip, tip_twist) {
        let (stable, margin, count) = held_stability(&mut sh, &x[..6], &c, &cols, &tw);
        conjugate = count;
        sol.stable = stable && sol.stats.converged;
        let _ = sol.margin.set(margin);
    } else if let Some(st) = free_stability.filter(|_| sol.stats.converged) {
        let _ = sol.margin.set(st.margin);
        sol.stable = st.stable;
    } else if let Some(st) = coarse_mesh(options.integrator)
        .filter(|_| sol.stats.converged)
        .and_then(|mesh| stability_on(&sol, mesh))
        .filter(|st| st.margin.abs() > COARSE_MARGIN_GAP)
    {
        // Clear on the coarse mesh; the margin itself is computed on the mesh asked when
        // read.
        sol.stable = st.stable;
    } else {
        sol.stable = sol.stats.converged && sol.stability_margin() > -NEUTRAL_MARGIN;
    }
    if !sol.stats.converged && options.newton.throw {
        return fail(
            p,
            &options.newton,
            effort,
            1.0,
            "the residual at the solution is above the tolerance",
        );
    }
    Ok(ContactSolution {
        solution: sol,
        tip_reaction,
        contacts,
        contact_force,
        conjugate_points: conjugate,
        compliance,
    })
}
