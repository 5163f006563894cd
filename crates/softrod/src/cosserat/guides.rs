//! Disk-guided tendons: straight chords between discrete guides, capstan friction per guide.
//!
//! A tendon with guides ([`Tendon::with_guides`](crate::Tendon::with_guides)) passes its base
//! hole (`s = 0`), every guide `g` (at `s_g`) and its termination at the points
//! `X_g = p(s_g) + R(s_g) r(s_g)` of its routing, and runs in a straight chord between
//! consecutive points, of unit direction `c_g = (X_{g+1} − X_g)/|X_{g+1} − X_g|` and tension
//! `τ_g` (`τ_0` the commanded base tension). At an interior guide of wrap angle
//! `θ_g = ∠(c_{g−1}, c_g)` and coefficient `μ_g` the capstan law bounds the outgoing tension,
//! `τ_g ∈ [τ_{g−1} e^(−μ_g θ_g), τ_{g−1} e^(+μ_g θ_g)]`, with the stick/slip rule of the
//! continuous channel ([`cell_rule`]): from rest the lower end (sliding toward the base),
//! from a previous state its tension clamped to the interval.
//!
//! The tendon touches the rod only at its guides and its termination: it loads guide `g` with
//! the point force `F_g = τ_g c_g − τ_{g−1} c_{g−1}` (the termination with `−τ_{G−1} c_{G−1}`)
//! applied at `X_g`, that is the force `F_g` and the moment `(X_g − p(s_g)) × F_g` at the
//! backbone. These are solved with the shape ([`GuideMethod`]):
//!
//! - a fixed point on the guide points: the rod is solved under the point loads of the current
//!   points (follower loads in the guides' frames of the last shape), the points are read from
//!   the new shape, until they move by less than [`FrictionOptions::tolerance`] times the rod
//!   length (Anderson-accelerated). Its gain is about `τ L²/EI` (the chords' geometric
//!   stiffness against the rod's bending compliance): it converges only where that is ≲ 1.
//! - Newton on the guide forces: the unknowns `z` are the body-frame forces at the anchors of
//!   the pulled guided tendons, the map `z ↦ z'` solves the rod under `z` (follower point
//!   loads at the guides' offsets) and reads the capstan forces `z'` of the points on the new
//!   shape in its frames; `F(z) = z' − z = 0` is solved by Newton with the exact Jacobian
//!   of the linearised rod ([`jacobian`]; by forward differences, one warm rod solve per
//!   unknown, where another tendon has channel friction or is displacement-controlled),
//!   reused while steps contract the residual by 4, a backtracking line search, and, if the full step from the start fails,
//!   continuation in the tensions from `previous` (or from zero). It ends at a residual of
//!   [`GUIDE_FORCE_TOLERANCE`] times the largest tension. Unlike the points, the forces in
//!   the guides' frames determine the rod solve alone, so `z ↦ z'` is a function and its
//!   Jacobian exists.
//!
//! The default ([`GuideMethod::Auto`]) is Newton where the exact Jacobian applies; otherwise
//! it tries the fixed point for [`GUIDE_FIXED_POINT_BUDGET`] rod solves, then Newton. The reported tensions, chords and
//! wraps are those of the points on the returned shape, the guide forces those the returned
//! rod was solved with, so the balance of rod + tendons holds to the residual.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::friction::{
    angle, base_slip, cell_rule, solve_frictional, Anderson, FrictionOptions, FrictionalSolution,
    Slip,
};
use crate::cosserat::statics::{StaticsSolution, WarmStart};
use crate::error::{Error, Result};
use crate::model::actuation::TendonInput;
use crate::model::loads::{Frame, Loads, PointLoad};
use crate::model::tendon::Tendon;
use crate::model::{Actuation, RobotModel};

mod jacobian;

/// Depth of the Anderson acceleration of the guide points (deep: the rod's response to the
/// lagged guide loads is not a contraction on a soft rod, and a deep history acts as a Krylov
/// solve of the linearised fixed point).
const GUIDE_ANDERSON_DEPTH: usize = 24;

/// The state of a guided tendon at one of its anchors: the base hole (`s = 0`), a guide, or
/// its termination (the last).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuideState {
    /// Arc length of the anchor (m).
    pub s: f64,
    /// Point the tendon passes (m, world).
    pub point: [f64; 3],
    /// Wrap angle between the incoming and the outgoing chord (rad); 0 at the base hole and
    /// the termination.
    pub wrap: f64,
    /// Friction coefficient (dimensionless); 0 at the base hole and the termination.
    pub friction: f64,
    /// Tension of the incoming chord (N); the base tension at the base hole.
    pub tension_in: f64,
    /// Tension of the outgoing chord (N); 0 at the termination.
    pub tension_out: f64,
    /// Slip state of the tendon through the guide.
    pub slip: Slip,
    /// Force of the tendon on the rod at the anchor (N, world; zero at the base hole, whose
    /// reaction the base takes).
    pub force: [f64; 3],
}

/// The anchors of guided tendon `i`: `0`, its guides, its termination (m).
fn anchors(model: &RobotModel, i: usize) -> Vec<f64> {
    let mut a = vec![0.0];
    a.extend_from_slice(model.tendons()[i].guides());
    a.push(model.tendon_ends()[i]);
    a
}

/// The node of `mesh` at `s` (every anchor is a break of the model, so a node).
fn node_at(mesh: &[f64], s: f64) -> usize {
    let j = mesh.partition_point(|&m| m < s);
    j.min(mesh.len() - 1)
}

/// The rotation (body to world) of the solution `st` at its node `j`.
fn node_rotation(st: &StaticsSolution, j: usize) -> Matrix3<f64> {
    Matrix3::from_fn(|a, b| st.rotation[j][a][b])
}

/// The rotation (body to world) of `st` at its node at `s` (m, see [`node_at`]).
fn rotation_at(st: &StaticsSolution, s: f64) -> Matrix3<f64> {
    node_rotation(st, node_at(&st.s, s))
}

/// The world points of the anchors of every guided tendon on the shape `sol`, flattened.
fn points_on(model: &RobotModel, guided: &[usize], sol: &FrictionalSolution) -> Vec<f64> {
    let st = &sol.statics;
    let mut out = Vec::new();
    for &i in guided {
        for s in anchors(model, i) {
            let j = node_at(&st.s, s);
            let r = node_rotation(st, j);
            let props = model.rod().section_at(s);
            let (o, _) = model.tendons()[i].routing().offset(s, &props);
            let x = Vector3::from(st.position[j]) + r * Vector3::new(o[0], o[1], 0.0);
            out.extend_from_slice(x.as_slice());
        }
    }
    out
}

/// The capstan rule through the anchors of tendon `i` with points `x` (3 per anchor), base
/// tension `base` and the previous states `prev` of its anchors (`None`: from rest); with
/// `branch` (a slip state per anchor) each interior guide keeps that branch of the rule
/// instead of choosing it: sticking at its previous tension, sliding at the lower
/// (loading) or upper (unloading) end of its capstan interval. The branch-fixed map is
/// smooth in the points; the rule itself has a kink wherever the previous tension sits at a
/// bound of the interval.
fn states(
    model: &RobotModel,
    i: usize,
    x: &[f64],
    base: f64,
    prev: Option<&[GuideState]>,
    branch: Option<&[Slip]>,
) -> Vec<GuideState> {
    let s = anchors(model, i);
    let na = s.len();
    let pt = |g: usize| Vector3::new(x[3 * g], x[3 * g + 1], x[3 * g + 2]);
    let chord: Vec<Vector3<f64>> = (0..na - 1)
        .map(|g| (pt(g + 1) - pt(g)).normalize())
        .collect();
    let mu = model.tendons()[i].guide_friction();
    let mut out = Vec::with_capacity(na);
    let mut tau = base;
    out.push(GuideState {
        s: 0.0,
        point: pt(0).into(),
        wrap: 0.0,
        friction: 0.0,
        tension_in: base,
        tension_out: base,
        slip: base_slip(base, prev.map(|p| p[0].tension_out)),
        force: [0.0; 3],
    });
    for g in 1..na {
        let incoming = tau * chord[g - 1];
        let (wrap, mu_g, out_tau, slip, force) = if g + 1 < na {
            let wrap = angle(&chord[g - 1], &chord[g]);
            let q = prev.map(|p| p[g].tension_out);
            let (t, slip) = match branch.map(|b| b[g]) {
                Some(Slip::Stick) => (q.unwrap_or(0.0), Slip::Stick),
                Some(Slip::Unloading) => (tau * (mu[g - 1] * wrap).exp(), Slip::Unloading),
                Some(Slip::Loading) => (tau * (-mu[g - 1] * wrap).exp(), Slip::Loading),
                _ => cell_rule(tau, mu[g - 1] * wrap, q),
            };
            (wrap, mu[g - 1], t, slip, t * chord[g] - incoming)
        } else {
            (0.0, 0.0, 0.0, out[g - 1].slip, -incoming)
        };
        out.push(GuideState {
            s: s[g],
            point: pt(g).into(),
            wrap,
            friction: mu_g,
            tension_in: tau,
            tension_out: out_tau,
            slip,
            force: force.into(),
        });
        tau = out_tau;
    }
    out
}

/// The model with its guided tendons in continuous channels of their mean guide coefficient
/// (and zero loads at their anchors, which keeps the same breaks).
fn channel_model(model: &RobotModel, guided: &[usize]) -> Result<Arc<RobotModel>> {
    let mut loads = model.loads().clone();
    for &i in guided {
        for s in anchors(model, i).into_iter().skip(1) {
            loads
                .point_loads
                .push(PointLoad::force(s, Vector3::zeros()));
        }
    }
    let tendons = model
        .tendons()
        .iter()
        .map(|t| {
            let mu = t.guide_friction();
            let mean = mu.iter().sum::<f64>() / mu.len().max(1) as f64;
            if t.is_guided() {
                t.without_guides().with_friction(mean)
            } else {
                Ok(t.clone())
            }
        })
        .collect::<Result<Vec<_>>>()?;
    with_tendons_and_loads(model, tendons, loads)
}

/// The model with the rod and chambers of `model` and the given `tendons` and `loads` (the
/// stand-ins of a guided robot).
fn with_tendons_and_loads(
    model: &RobotModel,
    tendons: Vec<Tendon>,
    loads: Loads,
) -> Result<Arc<RobotModel>> {
    RobotModel::new(
        model.rod().clone(),
        tendons,
        model.chambers().to_vec(),
        loads,
    )
}

/// `previous` is a solution of a robot with the same guides.
fn check_previous(
    model: &RobotModel,
    guided: &[usize],
    previous: Option<&FrictionalSolution>,
) -> Result<()> {
    let Some(p) = previous else { return Ok(()) };
    if p.guides.len() != model.tendons().len()
        || guided
            .iter()
            .any(|&i| p.guides[i].len() != anchors(model, i).len())
    {
        return Err(Error::invalid(
            "previous",
            "a solution of another robot",
            "a frictional solution of the same robot (the same guides)",
        ));
    }
    Ok(())
}

/// The flattened guide points `x` split per guided tendon.
fn split<'x>(model: &RobotModel, guided: &[usize], x: &'x [f64]) -> Vec<&'x [f64]> {
    let mut out = Vec::with_capacity(guided.len());
    let mut offset = 0;
    for &i in guided {
        let n = 3 * anchors(model, i).len();
        out.push(&x[offset..offset + n]);
        offset += n;
    }
    out
}

/// How [`solve_frictional`] solves a robot with disk-guided tendons
/// ([`FrictionOptions::guide_method`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GuideMethod {
    /// Newton on the guide forces where its exact Jacobian applies (the robot's other
    /// tendons frictionless and tension-controlled); otherwise the fixed point on the guide
    /// points first (a few rod solves where the tendon load is small against the rod's
    /// stiffness), Newton if it has not settled in [`GUIDE_FIXED_POINT_BUDGET`] rod solves
    /// or diverges.
    #[default]
    Auto,
    /// The fixed point on the guide points only (up to [`FrictionOptions::max_iterations`]
    /// rod solves); converges only where `τ L²/EI ≲ 1`.
    FixedPoint,
    /// Newton on the guide forces only (with continuation in the tensions if a full step
    /// fails).
    Newton,
    /// Newton on the guide forces only, its Jacobian by forward differences (one rod solve
    /// per unknown) even where the exact one applies: the reference the exact Jacobian is
    /// checked and timed against.
    NewtonFiniteDifferences,
}

/// Rod solves the fixed point gets before Newton takes over ([`GuideMethod::Auto`]).
pub const GUIDE_FIXED_POINT_BUDGET: usize = 16;

/// Growth of the fixed point's change over its smallest value taken as a divergence
/// ([`GuideMethod::Auto`] then turns to Newton).
const GUIDE_FIXED_POINT_GROWTH: f64 = 10.0;

/// Residual of the guide forces (largest component, relative to the largest base tension)
/// that ends Newton; a stall below [`FrictionOptions::tolerance`] is accepted.
pub const GUIDE_FORCE_TOLERANCE: f64 = 1e-12;

/// Step of the finite-difference Jacobian of the guide forces, relative to the largest base
/// tension.
const GUIDE_FD_STEP: f64 = 1e-6;

/// Newton iterations per tension level.
const GUIDE_NEWTON_ITERATIONS: usize = 25;

/// Smallest line-search step of Newton.
const GUIDE_MIN_STEP: f64 = 1.0 / 64.0;

/// A step that reuses the last Jacobian is accepted while the residual falls by at least
/// this factor; otherwise the Jacobian is rebuilt.
const GUIDE_CHORD_CONTRACTION: f64 = 0.25;

/// First and smallest step of the continuation in the tensions (fraction of the change).
const GUIDE_CONTINUATION_STEP: (f64, f64) = (0.25, 1.0 / 256.0);

/// Rod solves, marches and cell steps spent.
#[derive(Debug, Default)]
struct Counters {
    rod_solves: usize,
    iterations: usize,
    cell_steps: usize,
}

/// The rod solved under body-frame guide forces `z`: its solution, the capstan states read on
/// it (tensions, chords, wraps from its points; forces those applied) and the residual
/// `z' − z` (N) of the guide forces `z'` of those states in the guides' frames.
struct Evaluation {
    sol: FrictionalSolution,
    states: Vec<Vec<GuideState>>,
    residual: Vec<f64>,
    /// Largest component of the residual (N).
    norm: f64,
}

/// One guided solve: the model, its guided tendons, the rod's own actuation and history.
struct Guided<'a> {
    model: &'a Arc<RobotModel>,
    guided: Vec<usize>,
    actuation: &'a Actuation,
    /// The rod's actuation: the guided tendons at tension 0 (they load it by point loads).
    act: Actuation,
    /// The history of the other tendons (`None` if none has friction).
    inner_prev: Option<FrictionalSolution>,
    previous: Option<&'a FrictionalSolution>,
    options: &'a FrictionOptions,
    /// The slip state per anchor of every guided tendon held fixed in the capstan rule of
    /// the evaluations (`None`: chosen by the rule; the branch-fixed residual is the oracle
    /// of the exact Jacobian at a kink of the stick/slip rule).
    frozen: Option<Vec<Vec<Slip>>>,
}

impl<'a> Guided<'a> {
    fn new(
        model: &'a Arc<RobotModel>,
        actuation: &'a Actuation,
        options: &'a FrictionOptions,
        previous: Option<&'a FrictionalSolution>,
    ) -> Result<Self> {
        let nt = model.tendons().len();
        let guided: Vec<usize> = (0..nt)
            .filter(|&i| model.tendons()[i].is_guided())
            .collect();
        check_previous(model, &guided, previous)?;
        let mut act = actuation.clone();
        act.tendons.resize(nt, TendonInput::Tension(0.0));
        for &i in &guided {
            act.tendons[i] = TendonInput::Tension(0.0);
        }
        // The history of the other tendons, if any has friction (a previous solution also
        // sets the rod solve's warm start, replaced by the current shape's in `rod_solve`).
        let others =
            (0..nt).any(|i| !model.tendons()[i].is_guided() && model.tendons()[i].friction() > 0.0);
        let inner_prev = previous.filter(|_| others).map(|p| {
            let mut q = p.clone();
            for &i in &guided {
                for row in &mut q.tension {
                    row[i] = 0.0;
                }
            }
            q
        });
        Ok(Self {
            model,
            guided,
            actuation,
            act,
            inner_prev,
            previous,
            options,
            frozen: None,
        })
    }

    fn prev_states(&self, k: usize) -> Option<&'a [GuideState]> {
        self.previous.map(|p| p.guides[self.guided[k]].as_slice())
    }

    /// The capstan states of every guided tendon through the points `x` at base tensions
    /// `base` (N, per tendon of the model).
    fn states_at(&self, x: &[f64], base: &[f64]) -> Vec<Vec<GuideState>> {
        split(self.model, &self.guided, x)
            .into_iter()
            .enumerate()
            .map(|(k, xk)| {
                let i = self.guided[k];
                let branch = self.frozen.as_ref().map(|f| f[k].as_slice());
                states(self.model, i, xk, base[i], self.prev_states(k), branch)
            })
            .collect()
    }

    /// The rod solve of model `m` from the base wrench of `warm`.
    fn rod_solve(
        &self,
        m: &Arc<RobotModel>,
        warm: &FrictionalSolution,
        c: &mut Counters,
    ) -> Result<FrictionalSolution> {
        let mut inner = *self.options;
        inner.single_march = false;
        // The rod under frozen guide forces is not the guided robot: its stability (the
        // forces held in the guides' frames) is no reason to leave the branch.
        inner.statics.seek_stable = false;
        let prev = self.inner_prev.as_ref().map(|p| {
            let mut q = p.clone();
            q.statics.base_wrench = warm.statics.base_wrench;
            q.statics.jacobian = warm.statics.jacobian;
            q
        });
        inner.statics.warm_start = Some(predicted_warm_start(m, warm));
        let sol = solve_frictional(m, &self.act, &inner, prev.as_ref())?;
        c.iterations += sol.iterations;
        c.cell_steps += sol.cell_steps;
        c.rod_solves += 1;
        Ok(sol)
    }

    /// The first shape: `previous`, or the tendons in continuous channels of their mean
    /// guide coefficient (which the chords approach as the guides get dense).
    fn start(&self, c: &mut Counters) -> Result<FrictionalSolution> {
        match self.previous {
            Some(p) => Ok(p.clone()),
            None => {
                let m = channel_model(self.model, &self.guided)?;
                let sol = solve_frictional(&m, self.actuation, self.options, None)?;
                c.iterations += sol.iterations;
                c.cell_steps += sol.cell_steps;
                Ok(sol)
            }
        }
    }

    /// The fixed point on the guide points from `sol`, up to `budget` rod solves (`bounded`:
    /// also stopping once the change grows [`GUIDE_FIXED_POINT_GROWTH`]-fold over its
    /// smallest value, a divergence): the rod is
    /// solved under the follower loads of the current points (the moment arms and frames
    /// read on the last shape), the points are read on the new shape.
    fn fixed_point(
        &self,
        mut sol: FrictionalSolution,
        budget: usize,
        bounded: bool,
        c: &mut Counters,
    ) -> Result<FrictionalSolution> {
        let model = self.model;
        let base = self.actuation.tension_values(model.tendons().len());
        let l = model.length();
        let mut x = points_on(model, &self.guided, &sol);
        let mut anderson = Anderson::with_depth(false, GUIDE_ANDERSON_DEPTH);
        let mut solves = 0;
        let mut best = f64::INFINITY;
        loop {
            let st = self.states_at(&x, &base);
            // Follower loads: the forces in the guides' frames on the last shape (a dead
            // load of the tendon's pull would buckle a rod that its tendon only bends).
            let all = vec![true; self.guided.len()];
            let m = self.forces_model(&self.body_forces(&st, &sol, &all), &all)?;
            sol = self.rod_solve(&m, &sol, c)?;
            solves += 1;
            let next = points_on(model, &self.guided, &sol);
            let delta = next
                .iter()
                .zip(&x)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
                / l;
            if !delta.is_finite() {
                return Err(Error::NotConverged {
                    what: "guides: the guide points became non-finite".into(),
                    iterations: c.rod_solves,
                    residual: delta,
                    load_factor: sol.statics.stats.load_factor,
                });
            }
            if delta <= self.options.tolerance {
                return Ok(finish(
                    model,
                    &self.guided,
                    sol,
                    st,
                    (c.iterations, c.cell_steps),
                    delta,
                ));
            }
            best = best.min(delta);
            if solves >= budget || (bounded && delta > GUIDE_FIXED_POINT_GROWTH * best) {
                return Err(Error::NotConverged {
                    what: format!(
                        "guides: the guide points did not settle in {solves} rod solves of the \
                         fixed point (relative change {delta:e} > tolerance {:e})",
                        self.options.tolerance
                    ),
                    iterations: c.rod_solves,
                    residual: delta,
                    load_factor: sol.statics.stats.load_factor,
                });
            }
            x = anderson.update_flat(&x, next);
        }
    }

    /// The guided tendons whose forces are unknowns: those pulled at `base` or `from`.
    fn active(&self, base: &[f64], from: &[f64]) -> Vec<bool> {
        self.guided
            .iter()
            .map(|&i| base[i] > 0.0 || from[i] > 0.0)
            .collect()
    }

    /// The model under the body-frame guide forces `z` (3 per anchor after the base hole of
    /// every active guided tendon) applied at the guides' offsets; zero loads at the other
    /// anchors (the same breaks).
    fn forces_model(&self, z: &[f64], active: &[bool]) -> Result<Arc<RobotModel>> {
        let model = self.model;
        let mut loads = model.loads().clone();
        let mut q = 0;
        for (k, &i) in self.guided.iter().enumerate() {
            for s in anchors(model, i).into_iter().skip(1) {
                if active[k] {
                    let props = model.rod().section_at(s);
                    let (o, _) = model.tendons()[i].routing().offset(s, &props);
                    let o = Vector3::new(o[0], o[1], 0.0);
                    let f = Vector3::new(z[q], z[q + 1], z[q + 2]);
                    q += 3;
                    loads
                        .point_loads
                        .push(PointLoad::new(s, f, o.cross(&f), Frame::Body)?);
                } else {
                    loads
                        .point_loads
                        .push(PointLoad::force(s, Vector3::zeros()));
                }
            }
        }
        let tendons = model.tendons().iter().map(Tendon::without_guides).collect();
        with_tendons_and_loads(model, tendons, loads)
    }

    /// The forces of `states` at the anchors of the active tendons in the frames of `sol`
    /// (N, body), flattened as the unknowns.
    fn body_forces(
        &self,
        states: &[Vec<GuideState>],
        sol: &FrictionalSolution,
        active: &[bool],
    ) -> Vec<f64> {
        let mut z = Vec::new();
        for (k, st) in states.iter().enumerate() {
            if !active[k] {
                continue;
            }
            for g in st.iter().skip(1) {
                let r = rotation_at(&sol.statics, g.s);
                z.extend_from_slice((r.transpose() * Vector3::from(g.force)).as_slice());
            }
        }
        z
    }

    /// The rod under the guide forces `z` at base tensions `base`, from `warm`.
    fn evaluate(
        &self,
        z: &[f64],
        base: &[f64],
        active: &[bool],
        warm: &FrictionalSolution,
        c: &mut Counters,
    ) -> Result<Evaluation> {
        let m = self.forces_model(z, active)?;
        let sol = self.rod_solve(&m, warm, c)?;
        let x = points_on(self.model, &self.guided, &sol);
        let mut states = self.states_at(&x, base);
        let next = self.body_forces(&states, &sol, active);
        let residual: Vec<f64> = next.iter().zip(z).map(|(a, b)| a - b).collect();
        let norm = residual.iter().fold(0.0, |m: f64, r| m.max(r.abs()));
        if !norm.is_finite() {
            return Err(Error::NotConverged {
                what: "guides: the guide forces became non-finite".into(),
                iterations: c.rod_solves,
                residual: norm,
                load_factor: 1.0,
            });
        }
        // Report the forces the rod carries (those of the points to the residual).
        let mut q = 0;
        for (k, st) in states.iter_mut().enumerate() {
            if !active[k] {
                continue;
            }
            for g in st.iter_mut().skip(1) {
                let r = rotation_at(&sol.statics, g.s);
                g.force = (r * Vector3::new(z[q], z[q + 1], z[q + 2])).into();
                q += 3;
            }
        }
        Ok(Evaluation {
            sol,
            states,
            residual,
            norm,
        })
    }

    /// The Jacobian of the residual at `z` (evaluated in `cur`): exact from the linearised rod
    /// ([`jacobian`]) where it applies, otherwise by forward differences.
    fn jacobian(
        &self,
        z: &[f64],
        cur: &Evaluation,
        base: &[f64],
        active: &[bool],
        h: f64,
        c: &mut Counters,
    ) -> Result<DMatrix<f64>> {
        if self.options.guide_method != GuideMethod::NewtonFiniteDifferences
            && self.exact_jacobian_applies()
        {
            return self.exact_jacobian(cur, base, active, c);
        }
        let n = z.len();
        let mut jac = DMatrix::zeros(n, n);
        let mut zk = z.to_vec();
        for k in 0..n {
            zk[k] = z[k] + h;
            let e = self.evaluate(&zk, base, active, &cur.sol, c)?;
            zk[k] = z[k];
            for r in 0..n {
                jac[(r, k)] = (e.residual[r] - cur.residual[r]) / h;
            }
        }
        Ok(jac)
    }

    /// Newton with a backtracking line search on the guide forces at base tensions `base`
    /// from the forces `z` on the shape `warm`; the Jacobian is rebuilt when a step reusing
    /// it does not contract the residual by [`GUIDE_CHORD_CONTRACTION`].
    fn newton(
        &self,
        base: &[f64],
        active: &[bool],
        mut z: Vec<f64>,
        warm: &FrictionalSolution,
        c: &mut Counters,
    ) -> Result<(Vec<f64>, Evaluation)> {
        let scale = base
            .iter()
            .fold(0.0, |m: f64, t| m.max(*t))
            .max(f64::MIN_POSITIVE);
        let mut cur = self.evaluate(&z, base, active, warm, c)?;
        let mut lu = None;
        let mut fresh = false;
        for _ in 0..GUIDE_NEWTON_ITERATIONS {
            if cur.norm <= GUIDE_FORCE_TOLERANCE * scale || z.is_empty() {
                return Ok((z, cur));
            }
            if lu.is_none() {
                let h = GUIDE_FD_STEP * scale;
                lu = Some(self.jacobian(&z, &cur, base, active, h, c)?.lu());
                fresh = true;
            }
            let rhs = -DVector::from_column_slice(&cur.residual);
            let step = lu.as_ref().and_then(|lu| lu.solve(&rhs));
            let mut accepted = None;
            if let Some(step) = step {
                let mut alpha = 1.0;
                while alpha >= GUIDE_MIN_STEP {
                    let trial: Vec<f64> = z
                        .iter()
                        .zip(step.iter())
                        .map(|(a, d)| a + alpha * d)
                        .collect();
                    match self.evaluate(&trial, base, active, &cur.sol, c) {
                        Ok(e) if e.norm < (1.0 - 1e-4 * alpha) * cur.norm => {
                            accepted = Some((trial, e, alpha));
                            break;
                        }
                        Ok(_) | Err(Error::NotConverged { .. }) => alpha *= 0.5,
                        Err(e) => return Err(e),
                    }
                }
            }
            match accepted {
                Some((trial, e, alpha)) => {
                    if alpha < 1.0 || e.norm > GUIDE_CHORD_CONTRACTION * cur.norm {
                        lu = None;
                    }
                    fresh = false;
                    z = trial;
                    cur = e;
                }
                None if !fresh => lu = None,
                None if cur.norm <= self.options.tolerance * scale => return Ok((z, cur)),
                None => {
                    return Err(Error::NotConverged {
                        what: format!(
                            "guides: Newton on the guide forces found no descent step \
                             (relative residual {:e})",
                            cur.norm / scale
                        ),
                        iterations: c.rod_solves,
                        residual: cur.norm / scale,
                        load_factor: 1.0,
                    })
                }
            }
        }
        if cur.norm <= self.options.tolerance * scale {
            return Ok((z, cur));
        }
        Err(Error::NotConverged {
            what: format!(
                "guides: Newton on the guide forces did not converge in \
                 {GUIDE_NEWTON_ITERATIONS} iterations (relative residual {:e})",
                cur.norm / scale
            ),
            iterations: c.rod_solves,
            residual: cur.norm / scale,
            load_factor: 1.0,
        })
    }

    /// Newton on the guide forces: first at the full tensions from `start`, then, if that
    /// fails, by continuation in the tensions from `previous` (or from zero) with steps halved
    /// on failure.
    fn newton_solve(
        &self,
        start: &FrictionalSolution,
        c: &mut Counters,
    ) -> Result<FrictionalSolution> {
        let nt = self.model.tendons().len();
        let target = self.actuation.tension_values(nt);
        let from = match self.previous {
            Some(p) => p.statics.tendon_tensions.clone(),
            None => vec![0.0; nt],
        };
        let from: Vec<f64> = (0..nt)
            .map(|i| from.get(i).copied().unwrap_or(0.0))
            .collect();
        let active = self.active(&target, &from);
        let at = |lam: f64| -> Vec<f64> {
            (0..nt)
                .map(|i| {
                    if self.guided.contains(&i) {
                        from[i] + lam * (target[i] - from[i])
                    } else {
                        target[i]
                    }
                })
                .collect()
        };
        let scale = target
            .iter()
            .chain(&from)
            .fold(0.0, |m: f64, t| m.max(*t))
            .max(f64::MIN_POSITIVE);
        let done = |e: Evaluation, c: &Counters| {
            let rel = e.norm / scale;
            finish(
                self.model,
                &self.guided,
                e.sol,
                e.states,
                (c.iterations, c.cell_steps),
                rel,
            )
        };
        // The full step from the start's points.
        let x0 = points_on(self.model, &self.guided, start);
        let st0 = self.states_at(&x0, &target);
        let z0 = self.body_forces(&st0, start, &active);
        match self.newton(&target, &active, z0, start, c) {
            Ok((_, e)) => return Ok(done(e, c)),
            Err(Error::NotConverged { .. }) => (),
            Err(e) => return Err(e),
        }
        // Continuation from λ = 0: `previous` with its forces, or the rod without the guided
        // tendons' loads.
        let mut z = match self.previous {
            Some(p) => {
                let st: Vec<Vec<GuideState>> =
                    self.guided.iter().map(|&i| p.guides[i].clone()).collect();
                self.body_forces(&st, p, &active)
            }
            None => vec![0.0; z_len(self.model, &self.guided, &active)],
        };
        let mut warm = match self.previous {
            Some(p) => p.clone(),
            None => self.evaluate(&z, &at(0.0), &active, start, c)?.sol,
        };
        let (mut lam, mut step) = (0.0, GUIDE_CONTINUATION_STEP.0);
        loop {
            let next = (lam + step).min(1.0);
            match self.newton(&at(next), &active, z.clone(), &warm, c) {
                Ok((zn, e)) => {
                    if next >= 1.0 {
                        return Ok(done(e, c));
                    }
                    lam = next;
                    z = zn;
                    warm = e.sol;
                    step = (2.0 * step).min(1.0 - lam);
                }
                Err(Error::NotConverged { residual, .. }) => {
                    step *= 0.5;
                    if step < GUIDE_CONTINUATION_STEP.1 {
                        return Err(Error::NotConverged {
                            what: format!(
                                "guides: the continuation in the tensions stalled at load \
                                 factor {lam} (step {step:e}, Newton on the guide forces \
                                 from there ended at relative residual {residual:e})"
                            ),
                            iterations: c.rod_solves,
                            residual,
                            load_factor: lam,
                        });
                    }
                }
                Err(e) => return Err(e),
            }
        }
    }
}

/// The warm start of the rod solve of model `m` from the solution `warm` (of another model
/// with the same rod): its base wrench changed by the balance, on `warm`'s shape, of the
/// point loads of `m` less those of `warm`'s model (exact for a rigid rod; the guide forces
/// of an evaluation change the base wrench by their whole sum, which the warm shape's base
/// wrench alone leaves to the shooting Newton), and its Jacobian.
fn predicted_warm_start(m: &RobotModel, warm: &FrictionalSolution) -> WarmStart {
    let st = &warm.statics;
    let p0 = Vector3::from(st.position[0]);
    let wrench = |loads: &[PointLoad]| {
        let (mut f, mut n) = (Vector3::zeros(), Vector3::zeros());
        for pl in loads {
            let j = node_at(&st.s, pl.s);
            let (force, moment) = match pl.frame {
                Frame::World => (pl.force, pl.moment),
                Frame::Body => {
                    let r = node_rotation(st, j);
                    (r * pl.force, r * pl.moment)
                }
            };
            f += force;
            n += (Vector3::from(st.position[j]) - p0).cross(&force) + moment;
        }
        (f, n)
    };
    let (f1, n1) = wrench(&m.loads().point_loads);
    let (f0, n0) = wrench(&st.model.loads().point_loads);
    let mut w = st.warm_start();
    for k in 0..3 {
        w.base_wrench[k] += f1[k] - f0[k];
        w.base_wrench[3 + k] += n1[k] - n0[k];
    }
    w
}

/// Number of guide-force unknowns: 3 per anchor after the base hole of every active tendon.
fn z_len(model: &RobotModel, guided: &[usize], active: &[bool]) -> usize {
    guided
        .iter()
        .zip(active)
        .filter(|(_, &a)| a)
        .map(|(&i, _)| 3 * (anchors(model, i).len() - 1))
        .sum()
}

/// Solves the statics of a model with tendons routed through guides (see the module
/// documentation), from the state `previous` or from rest, by
/// [`FrictionOptions::guide_method`].
///
/// # Errors
/// What [`solve_frictional`] reports for the rod solves; [`Error::NotConverged`] if the guide
/// points do not settle (the fixed point in [`FrictionOptions::max_iterations`] rod solves,
/// Newton down to the smallest continuation step).
pub(super) fn solve_guided(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &FrictionOptions,
    previous: Option<&FrictionalSolution>,
) -> Result<FrictionalSolution> {
    let problem = Guided::new(model, actuation, options, previous)?;
    let mut c = Counters::default();
    let start = problem.start(&mut c)?;
    match options.guide_method {
        GuideMethod::FixedPoint => {
            problem.fixed_point(start, options.max_iterations, false, &mut c)
        }
        GuideMethod::Newton | GuideMethod::NewtonFiniteDifferences => {
            problem.newton_solve(&start, &mut c)
        }
        // With the exact Jacobian a Newton step costs about one rod solve: Newton directly.
        GuideMethod::Auto if problem.exact_jacobian_applies() => {
            problem.newton_solve(&start, &mut c)
        }
        GuideMethod::Auto => {
            let budget = GUIDE_FIXED_POINT_BUDGET.min(options.max_iterations);
            match problem.fixed_point(start.clone(), budget, true, &mut c) {
                Err(Error::NotConverged { .. }) => problem.newton_solve(&start, &mut c),
                other => other,
            }
        }
    }
}

/// The frictional solution with the guided tendons' columns: per node the tension, chord and
/// slip state of the chord the node lies on, the chord length from the base; their guide
/// states.
fn finish(
    model: &RobotModel,
    guided: &[usize],
    mut sol: FrictionalSolution,
    st: Vec<Vec<GuideState>>,
    (iterations, cell_steps): (usize, usize),
    delta: f64,
) -> FrictionalSolution {
    let l = model.length();
    let mesh = sol.statics.s.clone();
    sol.guides = vec![Vec::new(); model.tendons().len()];
    for (k, &i) in guided.iter().enumerate() {
        let a = &st[k];
        let end = model.tendon_ends()[i];
        let chord = |g: usize| {
            let d = Vector3::from(a[g + 1].point) - Vector3::from(a[g].point);
            (d.norm(), d / d.norm())
        };
        let total: f64 = (0..a.len() - 1).map(|g| chord(g).0).sum();
        let props = |s: f64| model.rod().section_at(s);
        for (j, &s) in mesh.iter().enumerate() {
            let present = s < end || (end == l && s == l);
            sol.friction_force[j][i] = [0.0; 3];
            if !present {
                sol.tension[j][i] = 0.0;
                sol.slip[j][i] = Slip::Absent;
                sol.tangent[j][i] = [0.0; 3];
                sol.path_length[j][i] = total;
                continue;
            }
            // The chord the node lies on: from the last anchor at or before it.
            let g = (a.partition_point(|x| x.s <= s) - 1).min(a.len() - 2);
            let (_, c) = chord(g);
            let before: f64 = (0..g).map(|h| chord(h).0).sum();
            let r = node_rotation(&sol.statics, j);
            let (o, _) = model.tendons()[i].routing().offset(s, &props(s));
            let y = Vector3::from(sol.statics.position[j]) + r * Vector3::new(o[0], o[1], 0.0);
            sol.tension[j][i] = a[g].tension_out;
            sol.slip[j][i] = a[g].slip;
            sol.tangent[j][i] = c.into();
            sol.path_length[j][i] = before + (y - Vector3::from(a[g].point)).dot(&c);
        }
        if let Some(t) = sol.statics.tendon_lengths.get_mut(i) {
            *t = total;
        }
        if let Some(t) = sol.statics.tendon_tensions.get_mut(i) {
            *t = a[0].tension_out;
        }
        sol.guides[i] = st[k].clone();
    }
    sol.iterations = iterations;
    sol.cell_steps = cell_steps;
    sol.change = delta;
    sol
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use nalgebra::{Matrix3, Vector3};

    use super::{states, GuideState};
    use crate::cosserat::friction::Slip;
    use crate::{LinearElastic, Loads, RobotModel, Rod, Section, Tendon};

    /// One guide by hand: chords `c0 = e_z` into the guide, `c1 = (sin θ, 0, cos θ)` of
    /// length `ℓ` out of it, base tension `τ0`, previous tension `q` at the guide. The force at
    /// the guide is `F1 = τ1 c1 − τ0 c0`; moving the termination by `δ` turns `c1` by
    /// `(I − c1 c1ᵀ) δ / ℓ`. Sticking (`τ1 = q`) its derivative is `q (I − c1 c1ᵀ) / ℓ`;
    /// sliding toward the base (`τ1 = τ0 e^(−μθ)`) it adds `−μ τ1 c1 tᵀ / ℓ`, `t` the
    /// direction of growing `θ`. With `q` inside the interval the rule's derivative is the
    /// sticking one; with `q` at the lower bound (a kink) the one-sided derivatives are the
    /// two branches, central differences of the rule average them (off by `μ q / (2ℓ)`), and
    /// the sticking branch held fixed gives the sticking derivative.
    #[test]
    fn one_guide_derivative_by_hand_sticking_and_at_the_kink() {
        let rod = Rod::new(
            0.3,
            Section::circular(1e-3).unwrap(),
            LinearElastic::new(2e11, 0.3).unwrap(),
        )
        .unwrap();
        let mu = 0.2;
        let tendon = Tendon::constant([0.0, 0.0], None)
            .unwrap()
            .with_guides(vec![0.15], &[mu])
            .unwrap();
        let model = RobotModel::new(rod, vec![tendon], Vec::new(), Loads::default()).unwrap();
        let (theta, ell, tau0): (f64, f64, f64) = (0.3, 0.15, 2.0);
        let c1 = Vector3::new(theta.sin(), 0.0, theta.cos());
        let t = Vector3::new(theta.cos(), 0.0, -theta.sin());
        let x = |d: Vector3<f64>| {
            let x2 = Vector3::new(0.0, 0.0, 0.15) + ell * c1 + d;
            vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.15, x2.x, x2.y, x2.z]
        };
        let prev = |q: f64| {
            let mut p = vec![
                GuideState {
                    s: 0.0,
                    point: [0.0; 3],
                    wrap: 0.0,
                    friction: 0.0,
                    tension_in: tau0,
                    tension_out: tau0,
                    slip: Slip::Loading,
                    force: [0.0; 3],
                };
                3
            ];
            p[1].tension_out = q;
            p[2].tension_out = 0.0;
            p
        };
        let force = |d: Vector3<f64>, q: f64, branch: Option<&[Slip]>| {
            let st = states(&model, 0, &x(d), tau0, Some(&prev(q)), branch);
            Vector3::from(st[1].force)
        };
        let h = 1e-7;
        let proj = Matrix3::identity() - c1 * c1.transpose();
        // q strictly inside the interval: the sticking derivative, along every direction.
        let q = tau0 * (-0.5 * mu * theta).exp();
        let mut worst: f64 = 0.0;
        for k in 0..3 {
            let e = Vector3::ith(k, h);
            let fd = (force(e, q, None) - force(-e, q, None)) / (2.0 * h);
            let hand = q * proj.column(k) / ell;
            worst = worst.max((fd - hand).amax() / q);
        }
        assert!(worst < 1e-8, "inside the interval: {worst:e}");
        // q at the lower bound: one-sided along ±t, the held branch, the central average.
        let q = tau0 * (-mu * theta).exp();
        let f0 = force(Vector3::zeros(), q, None);
        let stick = q * t / ell;
        let slide = q * t / ell - mu * q * c1 / ell;
        // Second-order one-sided differences (each side smooth).
        let one_sided = |d: f64| {
            (4.0 * force(d * t, q, None) - force(2.0 * d * t, q, None) - 3.0 * f0) / (2.0 * d)
        };
        let into_stick = one_sided(h);
        let into_slide = one_sided(-h);
        let held = [Slip::Loading, Slip::Stick, Slip::Loading];
        let fixed = (force(h * t, q, Some(&held)) - force(-h * t, q, Some(&held))) / (2.0 * h);
        let central = (force(h * t, q, None) - force(-h * t, q, None)) / (2.0 * h);
        let e1 = (into_stick - stick).amax() / q;
        let e2 = (into_slide - slide).amax() / q;
        let e3 = (fixed - stick).amax() / q;
        let e4 = (central - 0.5 * (stick + slide)).amax() / q;
        eprintln!(
            "one guide at the kink: one-sided into sticking {e1:e}, into sliding {e2:e}, \
             sticking branch held {e3:e}, central = mean of the branches {e4:e} \
             (the branches differ by {:e})",
            (stick - slide).amax() / q
        );
        assert!(e1 < 1e-6 && e2 < 1e-6 && e3 < 1e-8 && e4 < 1e-6);
    }
}
