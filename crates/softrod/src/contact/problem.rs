//! The constrained shooting problem: its unknowns (base wrench, contact forces and arc
//! lengths), its active contacts, the model each evaluation marches, and its residual and
//! Jacobian as a [`Problem`] of the crate's solver.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3, Vector6};

use super::belt::Held;
use super::constraint::TipConstraint;
use super::obstacle::Obstacle;
use super::obstacle_normal_basis;
use super::rows::AtContact;
use super::ContactState;
use crate::cosserat::equations::{rot, v3, Equations, Evaluator, Workspace, FULL, STATE};
use crate::cosserat::shooting::{Node, Shooting};
use crate::cosserat::statics::{Integrator, MAX_LOAD_STEP_TURN};
use crate::integrate::march::rk4_plan;
use crate::model::loads::{Loads, PointLoad};
use crate::model::rod::Profile;
use crate::model::RobotModel;
use crate::solve::{Evaluated, Problem};

/// Relative step of the forward differences of the Jacobian columns with contacts.
const DIFFERENCE_STEP: f64 = 1e-7;

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
    /// Lying on a curved obstacle from an unknown arc length `a` to an unknown `b`
    /// (unknowns: `a`, `b`): on `[a, b]` the normal pressure that keeps the gap zero (a
    /// held interval of the model, see `contact/belt.rs`).
    Belt,
    /// Lying on a curved obstacle from an unknown arc length `a` to the tip, with a force at
    /// the tip (unknowns: `a`, the tip force).
    BeltTip,
}

impl Site {
    /// Whether the contact holds an interval of the rod on the obstacle (a belt).
    pub(super) fn held(self) -> bool {
        matches!(self, Site::Belt | Site::BeltTip)
    }
}

/// An active contact and the homotopy targets of its gap rows (its gap and gap slope when it
/// was added, relaxed to zero as the problem's parameter goes from 0 to 1); with friction,
/// its state, where it first touched (the contact point, m, world, and the arc length, m)
/// and the homotopy targets of its sticking rows (its tangential displacements from there,
/// m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Active {
    pub(super) obstacle: usize,
    pub(super) site: Site,
    pub(super) g0: f64,
    pub(super) dg0: f64,
    pub(super) state: ContactState,
    pub(super) reference: Vector3<f64>,
    /// Arc length (m) of the contact where it first touched (`L` at the tip).
    pub(super) arc: f64,
    pub(super) t0: [f64; 2],
    /// A slip direction (unit, world) held while a contact turns from sticking to sliding.
    pub(super) direction: Option<Vector3<f64>>,
    /// A probe of the first-touch search inside the rod: its normal force is held at zero in
    /// place of its gap, so that the rod is the one without it and the probe's arc length,
    /// held at the least gap, gives where and how far the rod is from touching.
    pub(super) probe: bool,
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
            arc: 0.0,
            t0: [0.0; 2],
            direction: None,
            probe: false,
        }
    }
}

impl Active {
    pub(super) fn size(&self) -> usize {
        match self.site {
            Site::Belt => 2,
            Site::Tip => 3,
            Site::Interior | Site::Interval | Site::BeltTip => 4,
        }
    }

    /// Offset of the first force unknown among the contact's unknowns (after the arc length
    /// inside the rod), and of its two tangential rows among its rows, less one.
    pub(super) fn force_offset(&self) -> usize {
        self.size() - 3
    }
}

/// The equations of `model` (a contact model) under the actuation, at full load.
pub(super) fn equations<'a>(
    model: &'a RobotModel,
    tensions: &'a [f64],
    pressures: &'a [f64],
) -> Equations<'a> {
    Equations::new(model, tensions, pressures)
}

/// The RK4 steps per step of the uniform mesh on a belt (see [`mesh_of`]).
const BELT_SUBSTEPS: usize = 4;

/// The RK4 plan and the stops of a march of the contact model `model` with `integrator`:
/// [`rk4_plan`] over its breaks, or with a belt (a held interval, whose ends move with the
/// unknowns) one step between the nodes of the uniform mesh and the breaks (an empty plan
/// with the uniform nodes as stops), so that the march changes continuously with the ends;
/// on a belt the uniform mesh is refined [`BELT_SUBSTEPS`] times (the gap is held there by
/// integrating `g'' = 0`, whose drift falls as the fourth power of the step).
pub(super) fn mesh_of(model: &RobotModel, integrator: Integrator) -> (Vec<usize>, Vec<f64>) {
    match integrator {
        Integrator::Rk4 { steps } if !model.holds().is_empty() => {
            let l = model.length();
            let fine = steps * BELT_SUBSTEPS;
            let stops = (1..fine)
                .map(|k| l * k as f64 / fine as f64)
                .enumerate()
                .filter(|&(k, s)| {
                    (k + 1) % BELT_SUBSTEPS == 0 || model.holds().iter().any(|h| s > h.a && s < h.b)
                })
                .map(|(_, s)| s)
                .collect();
            (Vec::new(), stops)
        }
        Integrator::Rk4 { steps } => (rk4_plan(model.breaks(), steps), Vec::new()),
        Integrator::Adaptive(_) => (Vec::new(), Vec::new()),
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
    /// Per active contact, what its belt carries (`None` for the other sites).
    pub(super) held: Vec<Option<Held>>,
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

/// Scratch of the evaluations of a constrained problem, kept from march to march.
pub(super) struct Scratch {
    /// The contact rows' evaluations, one per side of a contact: the warm starts of their
    /// local solves (see [`Evaluator::enter_interval`](crate::cosserat::equations::Evaluator::enter_interval)).
    pub(super) sides: [Workspace; 2],
    /// The workspace of a march (every march starts afresh in it; allocated once).
    march: Option<Workspace>,
    /// A node buffer (that of a pass no longer needed).
    nodes: Vec<Node>,
}

impl Scratch {
    fn new(nt: usize) -> Self {
        Self {
            sides: [Workspace::new(nt), Workspace::new(nt)],
            march: None,
            nodes: Vec::new(),
        }
    }

    /// The right-hand-side evaluations of the contact rows since the last call (each counted
    /// once: the side workspaces live from march to march).
    pub(super) fn side_evaluations(&mut self) -> usize {
        self.sides
            .iter_mut()
            .map(|w| std::mem::take(&mut w.evaluations))
            .sum()
    }

    /// The march workspace for `nt` tendons (taken, new if none; give it back with
    /// [`Self::keep`]), with no evaluations and no material failure recorded.
    pub(super) fn march_workspace(&mut self, nt: usize) -> Workspace {
        match self.march.take().filter(|w| w.tendon_speed.len() == nt) {
            Some(mut ws) => {
                ws.evaluations = 0;
                ws.material_error = None;
                ws
            }
            None => Workspace::new(nt),
        }
    }

    /// The node buffer (taken, empty).
    pub(super) fn node_buffer(&mut self) -> Vec<Node> {
        let mut nodes = std::mem::take(&mut self.nodes);
        nodes.clear();
        nodes
    }

    /// Keeps the march workspace `ws` and the nodes of `pass` (replaced) for the next march.
    pub(super) fn keep(&mut self, ws: Workspace, pass: Option<Pass>) {
        self.march = Some(ws);
        self.keep_nodes(pass);
    }

    /// Keeps the nodes of `pass` (replaced) for the next march.
    pub(super) fn keep_nodes(&mut self, pass: Option<Pass>) {
        if let Some(p) = pass {
            self.nodes = p.nodes;
        }
    }
}

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
    /// Whether the problem is on the coarse mesh, whose evaluations only steer Newton: the
    /// contact rows of a Jacobian are then differenced one-sided rather than centrally, and
    /// a march integrates the path lengths of the tensioned tendons only (no solution is
    /// assembled from it).
    pub(super) rough: bool,
    /// Load factor of the last accepted load step (where a first touch is searched from).
    pub(super) from: f64,
    /// The friction coefficient of a plane with friction the rod lies along, when refused.
    pub(super) refused: Option<f64>,
    /// With the actuation stepped with the loads: the full tensions (N) and pressures (Pa),
    /// which the load factor then scales too ([`Self::set_load`]).
    pub(super) path: Option<(Vec<f64>, Vec<f64>)>,
    /// Whether the actuation applied in full cannot be trusted to reach the contacts: a
    /// contact with friction was met where no load path leads to it (made by the actuation,
    /// at load factor 0: its first touch is to be found), or a contact past the middle of its
    /// obstacle (`crossing`). The solve is then made with the actuation stepped with the
    /// loads ([`ramp::stepped`](super::ramp::stepped)).
    pub(super) pathless: bool,
    /// Whether such a contact is taken as it is, its reference where the rod without it
    /// touches it (when stepping the actuation failed, or with a held tip).
    pub(super) pathless_ok: bool,
    /// The unactuated, unloaded rod's nodes and the mesh they were marched on, once asked.
    pub(super) rest: Option<(Integrator, Vec<Node>)>,
    /// With the actuation stepped with the loads, the nodes of the last accepted step.
    pub(super) approach: Option<Vec<Node>>,
    /// Whether the actuated rod was found past the middle of an obstacle of finite thickness.
    pub(super) crossing: bool,
    /// Scratch of the evaluations, kept from march to march (see [`Scratch`]).
    pub(super) scratch: Option<Box<Scratch>>,
    /// With a free tip, the stability (contacts as dead loads) of the coarse mesh's
    /// solution, from its exact Jacobian there, and the active set it belongs to.
    pub(super) coarse_stability: Option<(Vec<Active>, crate::cosserat::Stability)>,
}

impl<'m> Constrained<'m> {
    /// The problem of `model` under the actuation `(tensions, pressures)` (N, Pa) with the
    /// tip held by `tip` (if any) among `obstacles`, on the mesh `integrator`: at load factor
    /// 0, no contact, nothing evaluated.
    pub(super) fn new(
        model: &'m Arc<RobotModel>,
        (tensions, pressures): (Vec<f64>, Vec<f64>),
        integrator: Integrator,
        tip: Option<TipConstraint>,
        obstacles: &'m [Obstacle],
    ) -> Self {
        Self {
            model,
            shared: model,
            tensions,
            pressures,
            integrator,
            tip,
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
            path: None,
            pathless: false,
            pathless_ok: false,
            rest: None,
            approach: None,
            crossing: false,
            scratch: None,
            coarse_stability: None,
        }
    }

    pub(super) fn dim_of(active: &[Active]) -> usize {
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

    /// Sets the load factor (and, on the path of the actuation, the actuation with it).
    pub(super) fn set_load(&mut self, lambda: f64) {
        self.load = lambda;
        if let Some((tensions, pressures)) = &self.path {
            for (t, full) in self.tensions.iter_mut().zip(tensions) {
                *t = lambda * full;
            }
            for (q, full) in self.pressures.iter_mut().zip(pressures) {
                *q = lambda * full;
            }
        }
    }

    /// The key of an evaluation at `x` and `mu` in the current state.
    pub(super) fn key(&self, x: &[f64], mu: f64) -> Key {
        // (The load factor steps nothing on an unloaded rod with a free tip, unless it steps
        // the actuation.)
        let load = if self.tip.is_none() && self.model.loads().is_unloaded() && self.path.is_none()
        {
            1.0
        } else {
            self.load
        };
        (x.to_vec(), mu, load, self.active.clone(), self.tip)
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
        let mut holds = Vec::new();
        for (a, o) in self.active.iter().zip(self.offsets()) {
            let (s, k) = match a.site {
                Site::Tip => (l, o),
                Site::Interior | Site::Interval => (x[o] * l, o + 1),
                Site::Belt => {
                    holds.push(self.hold_of(a, x[o] * l, x[o + 1] * l)?);
                    let h = holds.last()?;
                    loads
                        .point_loads
                        .push(PointLoad::force(h.a, Vector3::zeros()));
                    loads
                        .point_loads
                        .push(PointLoad::force(h.b, Vector3::zeros()));
                    continue;
                }
                Site::BeltTip => {
                    holds.push(self.hold_of(a, x[o] * l, l)?);
                    let h = holds.last()?;
                    loads
                        .point_loads
                        .push(PointLoad::force(h.a, Vector3::zeros()));
                    (l, o + 1)
                }
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
        if holds.is_empty() {
            self.model.with_loads(loads).ok()
        } else {
            self.model.with_loads_and_holds(loads, holds).ok()
        }
    }

    /// The scratch of the evaluations ([`Self::scratch`], taken; new if none), for `nt`
    /// tendons.
    pub(super) fn scratch(&mut self, nt: usize) -> Box<Scratch> {
        self.scratch
            .take()
            .filter(|w| w.sides[0].tendon_speed.len() == nt)
            .unwrap_or_else(|| Box::new(Scratch::new(nt)))
    }

    /// One march at `x`; with `full`, the six base-wrench columns too. Returns the residual
    /// rows, and with `full` the exact Jacobian of the tip rows along the base wrench.
    pub(super) fn run(&mut self, x: &[f64], mu: f64, full: bool) -> Option<Rows> {
        let model = self.contact_model(x)?;
        let nt = model.tendons().len();
        let mut scratch = self.scratch(nt);
        let (plan, stops) = mesh_of(&model, self.integrator);
        let eq = equations(&model, &self.tensions, &self.pressures);
        let mut sh =
            Shooting::with_workspace(eq, self.integrator, plan, scratch.march_workspace(nt));
        sh.stops = stops;
        sh.nodes = scratch.node_buffer();
        sh.passive_lengths = !self.rough;
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
        let [before, after] = &mut scratch.sides;
        let mut ev = [
            Evaluator {
                eq: sh.eq,
                ws: before,
            },
            Evaluator {
                eq: sh.eq,
                ws: after,
            },
        ];
        let held = self.rows_of_contacts(&mut ev, &sh.nodes, x, mu, &mut rows);
        self.evaluations += scratch.side_evaluations();
        let held = held?;
        let finite = rows.iter().all(|v| v.is_finite());
        let pass = finite.then(|| Pass {
            nodes: std::mem::take(&mut sh.nodes),
            residual: res,
            model: Arc::clone(&model),
            key: self.key(x, mu),
            rows: rows.clone(),
            jacobian: None,
            held,
            marched: (!full && !self.rough).then(|| {
                (
                    self.integrator,
                    std::mem::take(&mut sh.lengths),
                    std::mem::take(&mut sh.tensions),
                )
            }),
        });
        let replaced = pass.and_then(|p| self.last.replace(p));
        scratch.keep(sh.ws, replaced);
        self.scratch = Some(scratch);
        finite.then_some((rows, jac))
    }
}

impl Constrained<'_> {
    /// Appends the rows of every active contact at `x` (homotopy `mu`) from the `nodes` of a
    /// march (see [`Self::contact_rows`], [`Self::belt_rows`]); returns what each belt
    /// carries, `None` if a contact's arc length is not a node.
    fn rows_of_contacts(
        &self,
        ev: &mut [Evaluator<'_, '_>; 2],
        nodes: &[Node],
        x: &[f64],
        mu: f64,
        rows: &mut Vec<f64>,
    ) -> Option<Vec<Option<Held>>> {
        let l = self.model.length();
        let mut held = Vec::with_capacity(self.active.len());
        for (a, o) in self.active.iter().zip(self.offsets()) {
            let (s, k) = match a.site {
                Site::Tip => (l, o),
                Site::Interior | Site::Interval => (x[o] * l, o + 1),
                Site::Belt | Site::BeltTip => (x[o] * l, o + 1),
            };
            let first = nodes.iter().position(|n| n.s == s)?;
            let last = nodes.iter().rposition(|n| n.s == s)?;
            let (nf, nl) = (&nodes[first], &nodes[last]);
            let at = AtContact {
                s,
                first: (&nf.y, nf.interval),
                last: (&nl.y, nl.interval),
            };
            if a.site.held() {
                self.belt_rows(&mut ev[1], a, at, mu, rows);
                let b = if a.site == Site::Belt {
                    x[o + 1] * l
                } else {
                    l
                };
                held.push(Some(self.held(&mut ev[1], nodes, (s, b))?));
                if a.site == Site::BeltTip {
                    // The tip force along the obstacle's normal at the tip.
                    let tip = v3(&nodes.last()?.y, 0);
                    let (_, n) = self.obstacles[a.obstacle].distance(&tip);
                    let (t1, t2) = obstacle_normal_basis(&n);
                    let f = Vector3::new(x[k], x[k + 1], x[k + 2]);
                    rows.push(f.dot(&t1));
                    rows.push(f.dot(&t2));
                }
                continue;
            }
            let f = Vector3::new(x[k], x[k + 1], x[k + 2]);
            self.contact_rows(ev, a, at, &f, mu, rows);
            held.push(None);
        }
        Some(held)
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
