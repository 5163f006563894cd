//! The constrained shooting problem: base wrench, tip constraint and contact unknowns, solved
//! by the crate's Newton and continuation, with an active set of contacts.

use std::sync::Arc;

use super::active_set::{active_set, step_loads};
use super::constraint::TipConstraint;
use super::finish::{fail, finish, jacobian_stability};
use super::newton::Effort;
use super::obstacle::Obstacle;
use super::problem::Constrained;
use super::ramp;
use super::stability::constrained_stability;
use super::{ContactCompliance, ContactSolution};
use crate::cosserat::equations::{rot, v3};
use crate::cosserat::statics::{scaled, solve_statics, Integrator, SolveOptions, COARSE_TOLERANCE};
use crate::error::{Error, Result};
use crate::model::{Actuation, RobotModel};
use crate::solve::{Evaluated, NewtonOptions, Problem};

/// Checks a scene: at most [`MAX_OBSTACLES`](crate::limits::MAX_OBSTACLES) obstacles, none
/// given twice (two copies of one plane are two coincident contacts, whose reactions no
/// equilibrium determines: a copied plane gave another, unstable equilibrium).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `obstacles.len()` (too many) or `obstacles[j]` (a copy of an
/// earlier one).
pub(crate) fn check_obstacles(obstacles: &[Obstacle]) -> Result<()> {
    crate::limits::check_count(
        "obstacles.len()",
        obstacles.len(),
        0,
        crate::limits::MAX_OBSTACLES,
    )?;
    for (j, o) in obstacles.iter().enumerate() {
        if let Some(i) = obstacles[..j].iter().position(|e| e == o) {
            return Err(Error::invalid(
                format!("obstacles[{j}]"),
                format!("obstacles[{i}] again"),
                "each obstacle once (a copy is a second contact at the same place)",
            ));
        }
    }
    Ok(())
}

/// Solves the statics of `model` under `actuation` with the tip held by `tip` (if any) and
/// the rod's surface kept out of `obstacles` by unilateral contact (frictionless, or with
/// Coulomb friction at point contacts: see [`Obstacle::with_friction`] and
/// [`ContactState`](super::ContactState)).
///
/// The unknowns are the base wrench (as in [`solve_statics`]), the force of every active
/// contact and, for a contact inside the rod, its arc length; the residual the tip
/// conditions (the held directions' pose error, the free directions' wrench balance), and per
/// contact its gap (zero), the slope of the gap along the rod (zero: the contact sits at the
/// least gap), and the force's components along the obstacle's surface (zero when
/// frictionless; with friction the sticking or sliding rows of `contact/friction.rs`).
/// The contacts are found by an active set: a contact is added at every local minimum of a
/// gap below `-10 tolerance L` (reached by relaxing its gap from the penetration found) and
/// released when its normal force is negative, until no force pulls and nothing penetrates.
/// The external loads and the tip target (from the unloaded tip pose) are stepped by load
/// continuation when the direct solve fails; with a free tip, a contact with friction made
/// by the actuation has the actuation stepped with the loads.
///
/// # Errors
/// As [`solve_statics`] for the model, actuation and options; [`Error::InvalidParameter`]
/// naming `obstacles.len()` beyond [`MAX_OBSTACLES`](crate::limits::MAX_OBSTACLES) or
/// `obstacles[j]` for a copy of an earlier obstacle, and `friction` when the rod lies along a plane with friction (a contact interval:
/// friction is modelled at point contacts only); [`Error::NotConverged`] (with
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
    check_obstacles(obstacles)?;
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
    let mut p = Constrained::new(
        model,
        (tensions, pressures),
        options.integrator,
        tip.copied(),
        obstacles,
    );
    // The actuated rod without loads: the target of the tip at load factor 0.
    let mut effort = Effort::default();
    // (Not with a triangle mesh: the curvature of its distance jumps between faces and
    // edges, and Newton from the coarse solution may settle on another face. Nor with
    // friction: the coarse tolerance leaves errors in the held displacements that the axial
    // stiffness turns into spurious friction forces, so sticking and sliding cannot be told
    // apart there, and a load path followed sticking throughout may end on another branch.)
    let coarse_ok = !obstacles
        .iter()
        .any(|o| matches!(o.shape(), Obstacle::Mesh(_)) || o.friction() > 0.0);
    let coarse = coarse_mesh(options.integrator).filter(|_| coarse_ok);
    // (On the mesh the solve starts on: the march of the rod at rest is kept for the check of
    // contacts past the middle of their obstacle.)
    p.integrator = coarse.unwrap_or(options.integrator);
    ramp::check_rest_clear(&mut p)?;
    if let Some(coarse) = coarse {
        // The contacts and the nonlinear iterations on the coarse mesh; then Newton on the
        // mesh asked from there, with the coarse Jacobian, and the active set checked there.
        p.integrator = coarse;
        (p.refine, p.rough) = (false, true);
        let start = SolveOptions {
            newton: coarse_newton(&options.newton),
            ..*options
        };
        if let Reach::Done(xc) = reach(&mut p, &start, &mut effort) {
            if let Some(x) = refined(&mut p, options, (coarse, Verdict::Coarse), &xc, &mut effort) {
                return finish_unless_crossed(&mut p, (model, actuation), options, x, &mut effort);
            }
        }
        if let Some(e) = refusal(&p) {
            return Err(e);
        }
        if p.pathless && p.crossing {
            // Past the middle of an obstacle: the load path followed on the coarse mesh
            // (each step there costs a fifth), then Newton on the mesh asked from its end.
            p.pathless = false;
            if let Some(x) = stepped_on_coarse(&mut p, options, coarse, &mut effort) {
                return finish(&mut p, model, actuation, options, &x, &effort, 1.0);
            }
        }
        // Else the mesh asked from the start (its iterations and load steps are those
        // reported; the evaluations count both).
        effort = Effort::default();
        restart(&mut p, options.integrator);
    }
    let reached = reach_asked(&mut p, options, &mut effort);
    if let Some(e) = refusal(&p) {
        return Err(e);
    }
    match reached {
        Reach::Done(x) => {
            p.load = 1.0;
            finish_unless_crossed(&mut p, (model, actuation), options, x, &mut effort)
        }
        Reach::Stepped(x) => finish(&mut p, model, actuation, options, &x, &effort, 1.0),
        Reach::Stopped { x, lambda, why } => stopped(
            &mut p,
            (model, actuation),
            options,
            (&x, lambda, why),
            &effort,
        ),
        Reach::Unintegrable => Err(Error::not_converged(
            "constrained shooting: the actuated rod without external loads could not be \
             integrated",
            0,
            f64::INFINITY,
        )),
    }
}

/// The error of a plane with friction along which the rod lies, if one was met.
fn refusal(p: &Constrained<'_>) -> Option<Error> {
    p.refused.map(|mu| {
        Error::invalid(
            "friction",
            mu,
            "0 for a plane the rod lies along (a contact interval; Coulomb friction is \
             modelled at point contacts only)",
        )
    })
}

/// The exact Jacobian of the coarse mesh at its solution `xc` (one march with the columns),
/// handed to Newton on the mesh asked in place of the updated one of the last coarse solve
/// (taken where the iterate was still far), and with a free tip and `verdict` on the coarse
/// mesh the stability of the coarse solution from it (see [`jacobian_stability`]).
fn at_coarse_solution(p: &mut Constrained<'_>, xc: &[f64], verdict: Verdict) {
    p.coarse_stability = None;
    let n = p.dim();
    let (mut j, mut r) = (vec![0.0; n * n], vec![0.0; n]);
    if p.evaluate(xc, 1.0, Some(&mut j), &mut r) != Evaluated::Jacobian {
        return;
    }
    if verdict == Verdict::Coarse {
        // (The contacts held where they can be, from this pass: no march.)
        let held = constrained_stability(p, xc).map(|(st, _)| st);
        p.coarse_stability = held
            .or_else(|| {
                p.last
                    .as_ref()
                    .and_then(|pass| jacobian_stability(p, pass, xc))
            })
            .map(|st| (p.active.clone(), st));
    }
    p.solved = Some((p.active.clone(), j));
}

/// The coarse mesh of the contact solve with `integrator` ([`Integrator::coarse`]).
pub(super) fn coarse_mesh(integrator: Integrator) -> Option<Integrator> {
    integrator.coarse()
}

/// Where the stability verdict of a solution refined from the coarse mesh is taken.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Verdict {
    /// On the coarse mesh when its margin is clear (see [`at_coarse_solution`]).
    Coarse,
    /// On the mesh asked: after a load path stepped on the coarse mesh, whose margin at the
    /// path's end can be further off (3e-4 relative on the rod resting on the cylinder of
    /// `tests/contact_stability.rs`), as when the path was stepped on the mesh asked.
    Asked,
}

/// Newton on the mesh asked (`options`) from the coarse solution `xc`, with the exact coarse
/// Jacobian there (see [`at_coarse_solution`]) and the active set checked on the mesh asked;
/// the stability verdict taken where `verdict` says.
fn refined(
    p: &mut Constrained<'_>,
    options: &SolveOptions,
    (coarse, verdict): (Integrator, Verdict),
    xc: &[f64],
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    at_coarse_solution(p, xc, verdict);
    (p.refine, p.rough) = (true, false);
    p.integrator = options.integrator;
    p.coarse = Some(coarse);
    p.last = None;
    p.load = 1.0;
    p.hint = p.solved.take();
    active_set(p, xc, &options.newton, effort)
}

/// The problem `p` back at the unloaded rod on the mesh `integrator`, with no contacts.
fn restart(p: &mut Constrained<'_>, integrator: Integrator) {
    p.integrator = integrator;
    p.coarse = None;
    (p.refine, p.rough) = (true, false);
    p.active.clear();
    p.last = None;
    p.load = 0.0;
    p.from = 0.0;
    p.reference.clear();
    p.hint = None;
    p.solved = None;
}

/// [`reach`] on the mesh asked. If it meets a contact with friction made by the actuation
/// ([`Constrained::pathless`]), or finds no contact set at load factor 0 (the actuated rod deep
/// in an obstacle whose nearest surface is not the one it entered by, as in a closed mesh; with
/// continuation allowed), the solve with the actuation stepped with the loads from the
/// unactuated rod ([`ramp::stepped`]), so that its first touch is on that path; failing that,
/// for the contact with friction, [`reach`] again with that contact's reference where the
/// actuated rod without it touches it.
fn reach_asked(p: &mut Constrained<'_>, options: &SolveOptions, effort: &mut Effort) -> Reach {
    let mut unfound = false;
    if !p.pathless {
        let reached = reach(p, options, effort);
        if !p.pathless {
            unfound = options.newton.continuation
                && !p.obstacles.is_empty()
                && matches!(reached, Reach::Stopped { lambda, .. } if lambda == 0.0);
            if !unfound {
                return reached;
            }
        }
    }
    p.pathless = false;
    let x = match step_actuation(p, (options.integrator, false), &options.newton, effort) {
        Ok(x) => return Reach::Stepped(x),
        Err(x) => x,
    };
    if unfound || p.crossing {
        return Reach::Stopped {
            x,
            lambda: p.from,
            why: if unfound {
                "no contact set at load factor 0, and the actuation stepped with the loads \
                 from the unactuated rod stops"
            } else {
                "the actuated rod runs past the middle of an obstacle, and the load path \
                 stepped toward it stops"
            },
        };
    }
    *effort = Effort::default();
    restart(p, options.integrator);
    p.pathless_ok = true;
    reach(p, options, effort)
}

/// The solve with the actuation stepped with the loads from the unactuated rod on the mesh
/// `integrator` ([`ramp::stepped`]; `rough`: that mesh is the coarse one, whose solution
/// only starts Newton on the mesh asked): the unknowns at full load, or those of the last
/// step accepted (at load factor `p.from`), with the full actuation restored in `p` either way.
fn step_actuation(
    p: &mut Constrained<'_>,
    (integrator, rough): (Integrator, bool),
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> std::result::Result<Vec<f64>, Vec<f64>> {
    restart(p, integrator);
    (p.refine, p.rough) = (!rough, rough);
    let (s, radius) = ramp::samples(p);
    let full = (p.tensions.clone(), p.pressures.clone());
    let stepped = match ramp::rest_nodes(p).map(<[_]>::to_vec) {
        Some(rest) => {
            let (t, q) = (&full.0, &full.1);
            ramp::stepped(p, (t, q), (&s, &radius, rest), opts, effort)
        }
        None => Err(vec![0.0; 6]),
    };
    (p.tensions, p.pressures) = full;
    p.load = 1.0;
    stepped
}

/// What [`reach`] reached.
enum Reach {
    /// Converged at full load, the unknowns.
    Done(Vec<f64>),
    /// Converged at full load with the actuation stepped with the loads (checked for
    /// obstacles crossed on the way), the unknowns.
    Stepped(Vec<f64>),
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
        Err(x) => {
            let why = "the rod crossed a thin obstacle on its way from the unactuated rod, and \
                       the load path stepped past it stops";
            let lambda = p.from;
            stopped(p, (model, actuation), options, (&x, lambda, why), effort)
        }
    }
}

/// A solve stopped at load factor `lambda` with the unknowns `x` reached there, for the
/// reason `why`: the state `x` under the full actuation and loads, not converged (its
/// residual and `lambda` in the statistics), or with `throw` the error carrying them.
fn stopped(
    p: &mut Constrained<'_>,
    (model, actuation): (&Arc<RobotModel>, &Actuation),
    options: &SolveOptions,
    (x, lambda, why): (&[f64], f64, &str),
    effort: &Effort,
) -> Result<ContactSolution> {
    p.load = 1.0;
    if !options.newton.throw {
        return finish(p, model, actuation, options, x, effort, lambda);
    }
    if p.dim() != x.len() || p.evaluate(x, 1.0, None, &mut vec![0.0; x.len()]) == Evaluated::Failed
    {
        p.last = None;
    }
    fail(p, effort, lambda, why)
}

/// The solution `x` (its pass the last of `p`) if no point of the rod crossed an obstacle on
/// its way from the unactuated rod, else the solve again with the actuation and the loads
/// stepped together ([`ramp`](super::ramp); free tip only), failing with the unknowns of its
/// last step accepted (at load factor `p.from`).
fn not_crossed(
    p: &mut Constrained<'_>,
    x: Vec<f64>,
    options: &SolveOptions,
    effort: &mut Effort,
) -> std::result::Result<Vec<f64>, Vec<f64>> {
    if p.tip.is_some() || !ramp::any_checked(p) {
        return Ok(x);
    }
    let (s, radius) = ramp::samples(p);
    let Some(shape) = p.last.as_ref().map(|pass| ramp::positions_at(pass, &s)) else {
        return Ok(x);
    };
    let Some(rest) = ramp::rest_nodes(p).map(<[_]>::to_vec) else {
        return Ok(x);
    };
    let depth = 10.0 * options.newton.tolerance * p.model.length();
    if !ramp::crossed(p, (&ramp::positions_on(&rest, &s), &shape), &radius, depth) {
        return Ok(x);
    }
    // Stepped on the coarse mesh if the solve has one (then Newton on the mesh asked from its
    // end), else, or if that fails, on the mesh asked.
    if let Some(x) = p
        .coarse
        .and_then(|coarse| stepped_on_coarse(p, options, coarse, effort))
    {
        return Ok(x);
    }
    step_actuation(p, (options.integrator, false), &options.newton, effort)
}

/// The Newton options of the coarse mesh: those asked with the tolerance no tighter than
/// [`COARSE_TOLERANCE`] (its solution only starts Newton on the mesh asked).
fn coarse_newton(asked: &NewtonOptions) -> NewtonOptions {
    NewtonOptions {
        tolerance: asked.tolerance.max(COARSE_TOLERANCE),
        ..*asked
    }
}

/// The actuation stepped with the loads on the mesh `coarse` ([`step_actuation`]), then
/// Newton on the mesh asked from its end ([`refined`], the stability verdict taken there).
fn stepped_on_coarse(
    p: &mut Constrained<'_>,
    options: &SolveOptions,
    coarse: Integrator,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    let xc = step_actuation(p, (coarse, true), &coarse_newton(&options.newton), effort).ok()?;
    refined(p, options, (coarse, Verdict::Asked), &xc, effort)
}
