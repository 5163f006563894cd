//! The active set of contacts: contacts released when they pull, added at the local minima
//! of the gaps (or inside a cell, for thin obstacles), merged into intervals on a plane, and
//! the load steps of the external loads and the tip target.

use super::belt;
use super::friction::{first_touch, switch};
use super::newton::{correct, exact_newton, Effort};
use super::obstacle::Obstacle;
use super::problem::{Active, Constrained, Site};
use super::ramp;
use super::rows::{Forces, GapSample};
use super::ContactState;
use crate::cosserat::statics::settings;
use crate::solve::{
    continuation, ContinuationSettings, Evaluated, NewtonOptions, Problem, MIN_LOAD_INCREMENT,
};

/// Most rounds of the active-set loop (contacts added or released) per load step.
pub const MAX_ACTIVE_SET_ROUNDS: usize = 40;

/// Most contacts on one obstacle: a rod lying along a plane away from its tip (not modelled:
/// an interval reaches the tip) would otherwise take a point contact at every node it
/// touches.
pub const MAX_POINT_CONTACTS: usize = 16;

/// Most continuation steps tried (accepted or halved) when new contacts' gaps are relaxed to
/// zero ([`relax`]). Over the contact tests, the relaxations that succeed take 1 to 12 (174 of
/// 207 one); those that fail took 14 to 36, halving from the full relaxation to the smallest
/// increment without accepting a step, each at full Newton cost.
const RELAX_ATTEMPTS: usize = 16;

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
                .any(|(a, f)| a.obstacle == o && a.site == Site::Interval && s >= f.2)
                || belt::covers(p, o, (s, s));
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
    let mut added = Vec::new();
    for o in 0..p.obstacles.len() {
        let g = p.gaps(o);
        for i in 1..g.len() {
            let (s0, s1) = (g[i - 1].1, g[i].1);
            // A cell next to a point contact is checked too: the rod can cross the obstacle
            // between its contact and a node just clear of it (a rod across a small sphere).
            let covered = forces
                .iter()
                .zip(&p.active)
                .any(|(f, a)| a.obstacle == o && a.site == Site::Interval && s1 >= f.2);
            let covered = covered || belt::covers(p, o, (s0, s1));
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
/// the first contact to the tip; `true` if a merge was made, or refused: an interval on a
/// plane with friction is not modelled (`p.refused` is then set).
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
        // An interval reaches the tip: where the rod leaves the plane beyond the contacts
        // they stay points.
        if !belt::on_obstacle(p, o, (a, l), belt::clearance(p)) {
            continue;
        }
        let mu = p.obstacles[o].friction();
        if mu > 0.0 {
            p.refused = Some(mu);
            return true;
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

/// Whether one of the contacts `added` lies in its obstacle past its middle
/// ([`ramp::past_middle`]) seen from the unactuated rod or from the last accepted step.
fn far_side(p: &mut Constrained<'_>, added: &[(usize, Site, f64)]) -> bool {
    if !added.iter().any(|&(o, ..)| ramp::thick(&p.obstacles[o])) {
        return false;
    }
    if p.path.is_none() && ramp::rest_nodes(p).is_none() {
        return false;
    }
    let from = match p.path {
        Some(_) => p.approach.as_deref(),
        None => p.rest.as_ref().map(|(_, nodes)| nodes.as_slice()),
    };
    from.is_some_and(|from| ramp::past_middle(p, added, from))
}

/// Adds the contacts `added` at zero force and relaxes their gaps from the values found to
/// zero by continuation; the state at full contact targets. A contact with friction starts
/// sticking where it first touched on the load path.
fn add_contacts(
    p: &mut Constrained<'_>,
    mut x: Vec<f64>,
    added: Vec<(usize, Site, f64)>,
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    let l = p.model.length();
    let rough = added.iter().any(|&(o, ..)| p.obstacles[o].friction() > 0.0);
    let actuated = p.tensions.iter().chain(&p.pressures).any(|v| *v != 0.0);
    let free = p.path.is_none() && p.tip.is_none() && !p.pathless_ok;
    if rough && actuated && free && p.load <= p.from {
        // Made by the actuation (applied in full): its first touch is to be found with the
        // actuation stepped with the loads.
        p.pathless = true;
        return None;
    }
    if p.tip.is_none() && !p.pathless_ok && far_side(p, &added) {
        if p.path.is_none() {
            (p.pathless, p.crossing) = (true, true);
        }
        return None;
    }
    // Where the new contacts with friction first touched, on the load path.
    let mut touched = Vec::with_capacity(added.len());
    for &(o, site, s) in &added {
        touched.push(if p.obstacles[o].friction() > 0.0 {
            Some(first_touch(p, &x, o, (site, s), opts, effort)?)
        } else {
            None
        });
    }
    for ((o, site, s), touched) in added.into_iter().zip(touched) {
        let mut a = Active::frictionless(o, site);
        if let Some(t) = touched {
            a.state = ContactState::Stick;
            a.reference = t.point;
            a.arc = t.arc;
        }
        p.active.push(a);
        if site != Site::Tip {
            x.push(s / l);
        }
        x.extend([0.0; 3]);
    }
    reach_contacts(p, &x, opts, effort)
}

/// The state at full contact targets from `x`, where the newest contacts (at zero force)
/// penetrate: one exact Newton solve with the predictor of new contacts, else their gaps
/// relaxed from the values found to zero by continuation ([`relax`]).
fn reach_contacts(
    p: &mut Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    for a in &mut p.active {
        a.g0 = 0.0;
        a.dg0 = 0.0;
        a.t0 = [0.0; 2];
    }
    if let Some((xs, _)) = exact_newton(p, x, opts, effort, false, true) {
        return Some(xs);
    }
    relax(p, x, opts, effort)
}

/// The state at full contact targets from `x`: the rows of every active contact (gap, its
/// slope, a sticking contact's tangential displacement) relaxed from their values at `x` to
/// zero by continuation, then Newton.
pub(super) fn relax(
    p: &mut Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    let l = p.model.length();
    // The gap targets of the new contacts: their rows at zero force.
    let mut r = vec![0.0; p.dim()];
    if p.evaluate(x, 1.0, None, &mut r) == Evaluated::Failed {
        return None;
    }
    let offsets = p.offsets();
    for (a, o) in p.active.iter_mut().zip(offsets) {
        a.g0 = r[o] * l;
        if a.site != Site::Tip {
            a.dg0 = r[o + 1];
        }
        if a.state == ContactState::Stick {
            let k = o + a.force_offset();
            a.t0 = [r[k + 1] * l, r[k + 2] * l];
        }
    }
    let start = ContinuationSettings {
        x0: x,
        jacobian0: None,
        first_increment: 1.0,
        max_increment: 1.0,
    };
    let attempts = NewtonOptions {
        max_load_steps: opts.max_load_steps.min(RELAX_ATTEMPTS),
        ..*opts
    };
    let c = continuation(p, &start, &attempts, &settings(true, None, false));
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
    // Where contacts were added from the check between the nodes: a cell is checked once
    // (next to the kink of a shearable backbone at a contact, the arc interpolated through it
    // dips below the obstacle again after every contact added there: docs/contact.md).
    let mut tried: Vec<(usize, f64)> = Vec::new();
    let cell = belt::clearance(p) * 1e3;
    let near = |a: f64, b: f64| (a - b).abs() <= cell;
    for _ in 0..MAX_ACTIVE_SET_ROUNDS {
        // Release the most negative contact force (a sticking one slides first, below).
        let forces = p.normal_forces(&x);
        let worst = forces
            .iter()
            .enumerate()
            .filter(|(i, f)| {
                let a = &p.active[*i];
                !a.site.held() && a.state != ContactState::Stick && f.0 < -opts.tolerance * fs
            })
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
        // A belt whose forces pull (see `belt::change`).
        if let Some(change) = belt::change(p, &x, opts.tolerance * fs, opts.tolerance * fs / l) {
            x = belt::apply(p, x, change, opts, effort)?;
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
        let in_cells = added.is_empty();
        if in_cells {
            added = cell_candidates(p, &forces, penetration);
            added.retain(|&(o, _, s)| !tried.iter().any(|&(to, ts)| to == o && near(ts, s)));
        }
        // Next to a contact on a curved obstacle, with the rod on it in between: a belt.
        if let Some(plan) = belt::plan(p, &forces, &added, belt::clearance(p)) {
            if p.rough {
                // (Its boundary layers need the mesh asked.)
                return None;
            }
            let saved = p.active.clone();
            if let Some(xf) = belt::form(p, x.clone(), &plan, opts, effort) {
                x = xf;
                continue;
            }
            // No belt found there: the new contacts are added as points (the last pass
            // restored at `x` first).
            p.active = saved;
            x = correct(p, &x, opts, effort)?;
        }
        if merge_plane(p, &mut x, &forces, &added) {
            if p.refused.is_some() {
                // Friction along a contact interval is not modelled: refused, not solved
                // without it.
                return None;
            }
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
        if in_cells {
            tried.extend(added.iter().map(|&(o, _, s)| (o, s)));
        }
        // A stretch lying on an obstacle away from the tip is not modelled (see `merge_plane`):
        // it would take a point contact at every node it touches.
        let crowded = (0..p.obstacles.len()).any(|o| {
            let here = p.active.iter().filter(|a| a.obstacle == o).count();
            here + added.iter().filter(|a| a.0 == o).count() > MAX_POINT_CONTACTS
        });
        if crowded {
            return None;
        }
        x = add_contacts(p, x, added, opts, effort)?;
    }
    None
}

/// Steps the load factor (external loads and tip target) from 0 to 1 from the state `x`
/// at load factor 0, halving a step whose active-set loop fails or moves the shape too far;
/// on failure, the load factor reached and why.
pub(super) fn step_loads(
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
