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
//! backbone. These are solved with the shape by a fixed point on the guide points: the rod is
//! solved under the point loads of the current points (with any other tendons, frictional or
//! not, as usual), the points are read from the new shape, until they move by less than
//! [`FrictionOptions::tolerance`] times the rod length (Anderson-accelerated). The reported
//! tensions, chords and guide forces are those the converged rod was solved with, so the
//! balance of rod + tendons holds to rounding.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::friction::{
    angle, base_slip, cell_rule, solve_frictional, Anderson, FrictionOptions, FrictionalSolution,
    Slip,
};
use crate::error::{Error, Result};
use crate::model::actuation::TendonInput;
use crate::model::loads::{Frame, PointLoad};
use crate::model::tendon::Tendon;
use crate::model::{Actuation, RobotModel};

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

/// The world points of the anchors of every guided tendon on the shape `sol`, flattened.
fn points_on(model: &RobotModel, guided: &[usize], sol: &FrictionalSolution) -> Vec<f64> {
    let st = &sol.statics;
    let mut out = Vec::new();
    for &i in guided {
        for s in anchors(model, i) {
            let j = node_at(&st.s, s);
            let r = Matrix3::from_fn(|a, b| st.rotation[j][a][b]);
            let props = model.rod().section_at(s);
            let (o, _) = model.tendons()[i].routing().offset(s, &props);
            let x = Vector3::from(st.position[j]) + r * Vector3::new(o[0], o[1], 0.0);
            out.extend_from_slice(x.as_slice());
        }
    }
    out
}

/// The capstan rule through the anchors of tendon `i` with points `x` (3 per anchor), base
/// tension `base` and the previous states `prev` of its anchors (`None`: from rest).
fn states(
    model: &RobotModel,
    i: usize,
    x: &[f64],
    base: f64,
    prev: Option<&[GuideState]>,
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
            let (t, slip) = cell_rule(tau, mu[g - 1] * wrap, q);
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

/// The model with its guided tendons as plain ones (tension 0 in the rod's actuation) under
/// its own loads plus the point loads of the guided tendons in `states` (`None`: zero loads
/// at their anchors, which keeps the same breaks), the moment arms read on `sol`.
fn loaded_model(
    model: &RobotModel,
    guided: &[usize],
    states: Option<&[Vec<GuideState>]>,
    sol: Option<&FrictionalSolution>,
) -> Result<Arc<RobotModel>> {
    let mut loads = model.loads().clone();
    for (k, &i) in guided.iter().enumerate() {
        match states {
            Some(st) => {
                for g in st[k].iter().skip(1) {
                    // A follower load: the force in the guide's frame on the last shape, at
                    // the guide's offset (a dead load of the tendon's pull would buckle a
                    // rod that its tendon only bends).
                    let (f, o) = match sol {
                        Some(sol) => {
                            let j = node_at(&sol.statics.s, g.s);
                            let r = Matrix3::from_fn(|a, b| sol.statics.rotation[j][a][b]);
                            let props = model.rod().section_at(g.s);
                            let (o, _) = model.tendons()[i].routing().offset(g.s, &props);
                            (
                                r.transpose() * Vector3::from(g.force),
                                Vector3::new(o[0], o[1], 0.0),
                            )
                        }
                        None => (Vector3::zeros(), Vector3::zeros()),
                    };
                    loads
                        .point_loads
                        .push(PointLoad::new(g.s, f, o.cross(&f), Frame::Body)?);
                }
            }
            None => {
                for s in anchors(model, i).into_iter().skip(1) {
                    loads
                        .point_loads
                        .push(PointLoad::force(s, Vector3::zeros()));
                }
            }
        }
    }
    let tendons = model.tendons().iter().map(Tendon::without_guides).collect();
    RobotModel::new(
        model.rod().clone(),
        tendons,
        model.chambers().to_vec(),
        loads,
    )
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

/// Solves the statics of a model with tendons routed through guides (see the module
/// documentation), from the state `previous` or from rest.
///
/// # Errors
/// What [`solve_frictional`] reports for the rod solves; [`Error::NotConverged`] if the guide
/// points do not settle in [`FrictionOptions::max_iterations`] rod solves.
pub(super) fn solve_guided(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &FrictionOptions,
    previous: Option<&FrictionalSolution>,
) -> Result<FrictionalSolution> {
    let nt = model.tendons().len();
    let guided: Vec<usize> = (0..nt)
        .filter(|&i| model.tendons()[i].is_guided())
        .collect();
    let base = actuation.tension_values(nt);
    // The rod's own actuation: the guided tendons load it through the point loads only.
    let mut act = actuation.clone();
    act.tendons.resize(nt, TendonInput::Tension(0.0));
    for &i in &guided {
        act.tendons[i] = TendonInput::Tension(0.0);
    }
    // The history of the other tendons (the guided ones carry none along the rod).
    let inner_prev = previous.map(|p| {
        let mut q = p.clone();
        for &i in &guided {
            for row in &mut q.tension {
                row[i] = 0.0;
            }
        }
        q
    });
    check_previous(model, &guided, previous)?;
    let prev_states = |k: usize| previous.map(|p| p.guides[guided[k]].as_slice());
    let mut sol = match previous {
        Some(p) => p.clone(),
        None => {
            // The first guide points: the tendons in continuous channels (their mean guide
            // coefficient), which the chords approach as the guides get dense.
            let m = channel_model(model, &guided)?;
            solve_frictional(&m, actuation, options, None)?
        }
    };
    let l = model.length();
    let mut x = points_on(model, &guided, &sol);
    let mut anderson = Anderson::with_depth(false, GUIDE_ANDERSON_DEPTH);
    let mut iterations = sol.iterations;
    let mut cell_steps = sol.cell_steps;
    let mut rod_solves = 0;
    loop {
        let st: Vec<Vec<GuideState>> = split(model, &guided, &x)
            .into_iter()
            .enumerate()
            .map(|(k, xk)| states(model, guided[k], xk, base[guided[k]], prev_states(k)))
            .collect();
        let m = loaded_model(model, &guided, Some(&st), Some(&sol))?;
        // The moment arms were read on the last shape; the points on the new shape are
        // the same to the tolerance at convergence.
        // The rod solve from the last iterate's base wrench (the fixed point of the profile
        // takes it; a start from the unloaded rod would cross the whole load path again).
        let mut inner = *options;
        inner.single_march = false;
        inner.statics.warm_start = Some(sol.statics.warm_start());
        sol = solve_frictional(&m, &act, &inner, inner_prev.as_ref())?;
        iterations += sol.iterations;
        cell_steps += sol.cell_steps;
        rod_solves += 1;
        let next = points_on(model, &guided, &sol);
        let delta = next
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / l;
        if !delta.is_finite() {
            return Err(Error::NotConverged {
                what: "guides: the guide points became non-finite".into(),
                iterations: rod_solves,
                residual: delta,
                load_factor: sol.statics.stats.load_factor,
            });
        }
        if delta <= options.tolerance {
            return Ok(finish(
                model,
                &guided,
                sol,
                st,
                (iterations, cell_steps),
                delta,
            ));
        }
        if rod_solves >= options.max_iterations {
            return Err(Error::NotConverged {
                what: format!(
                    "guides: the guide points did not settle in {rod_solves} rod solves \
                     (relative change {delta:e} > tolerance {:e})",
                    options.tolerance
                ),
                iterations: rod_solves,
                residual: delta,
                load_factor: sol.statics.stats.load_factor,
            });
        }
        x = anderson.update_flat(&x, next);
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
            let r = Matrix3::from_fn(|p, q| sol.statics.rotation[j][p][q]);
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
