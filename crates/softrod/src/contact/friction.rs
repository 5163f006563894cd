//! Coulomb friction at tip contacts.
//!
//! A static problem needs a reference for the slip: here the contact point where the tip
//! first touched the obstacle along the proportional load path of the solve (the load factor
//! at which the gap of the solution without that contact vanishes, found by regula falsi
//! between the last accepted load step and the current one). A sticking contact holds its
//! contact point there: its rows are the gap and the two tangential displacements of the
//! contact point from the reference (over `L`). A sliding contact keeps the gap row and
//! puts its tangential force on the cone, opposite to the slip `u` (the tangential
//! displacement from the reference): `f_t + μ f_n u / max(|u|, ε L) = 0`, two rows, with
//! `ε` = [`SLIP_FLOOR`] so that the rows stay smooth where the slip starts from zero. The
//! active-set loop turns a sticking contact whose force leaves the cone into a sliding one,
//! and a sliding contact whose slip has gone back below `ε L` (it would reverse) into a
//! sticking one.

use nalgebra::Vector3;

use super::newton::{correct, Effort};
use super::obstacle_normal_basis;
use super::problem::{Active, Constrained, Site};
use super::rows::Forces;
use super::ContactState;
use crate::cosserat::equations::{v3, STATE};
use crate::solve::{Evaluated, NewtonOptions, Problem};

/// Slip (relative to the rod length) below which the direction of a sliding contact's force
/// is that of the slip scaled by `|u| / (ε L)` (a regularisation that keeps the rows smooth
/// at zero slip; a solution inside it turns the contact to sticking).
pub(super) const SLIP_FLOOR: f64 = 1e-9;
/// Relative excess of the tangential force over the cone at which a sticking contact slides.
const CONE_SLACK: f64 = 1e-9;
/// Most regula falsi iterations of the first-touch search.
const MAX_TOUCH_ITERATIONS: usize = 16;
/// Half-width (relative) of the bracket of load factors about a first touch searched again.
const RETOUCH_SPAN: f64 = 1e-2;
/// Newton tolerance (at most) of the solves of the first-touch search.
const TOUCH_TOLERANCE: f64 = 1e-10;
/// Gap (relative to the rod length) at which the first-touch search stops.
const TOUCH_GAP: f64 = 1e-13;

impl Constrained<'_> {
    /// The contact point on the rod's surface (m, world) and the outward normal of the
    /// obstacle of `a` for the tip state `y`, and the gap (m).
    fn tip_point(&self, a: &Active, y: &[f64; STATE]) -> (Vector3<f64>, Vector3<f64>, f64) {
        let l = self.model.length();
        let p = v3(y, 0);
        let (d, n) = self.obstacles[a.obstacle].distance(&p);
        let radius = self.model.rod().section_at(l).radius;
        (p - n * radius, n, d - radius)
    }

    /// The two tangential rows of the tip contact `a` with friction at the tip state `y`,
    /// scaled force `f`, homotopy parameter `relax` (see the module's documentation).
    pub(super) fn friction_rows(
        &self,
        a: &Active,
        y: &[f64; STATE],
        f: &Vector3<f64>,
        relax: f64,
        rows: &mut Vec<f64>,
    ) {
        let l = self.model.length();
        let (pc, n, _) = self.tip_point(a, y);
        let d = pc - a.reference;
        let (t1, t2) = obstacle_normal_basis(&n);
        if a.state == ContactState::Stick {
            rows.push((d.dot(&t1) - (1.0 - relax) * a.t0[0]) / l);
            rows.push((d.dot(&t2) - (1.0 - relax) * a.t0[1]) / l);
            return;
        }
        let mu = self.obstacles[a.obstacle].friction();
        let normal = f.dot(&n);
        let ft = f - n * normal;
        let r = match a.direction {
            Some(e) => ft + e * (mu * normal),
            None => {
                let u = d - n * d.dot(&n);
                ft + u * (mu * normal / u.norm().max(SLIP_FLOOR * l))
            }
        };
        rows.push(r.dot(&t1));
        rows.push(r.dot(&t2));
    }

    /// The tangential force (N, world) of every active contact at `x` (zero for
    /// frictionless ones), with the normals of `forces`.
    pub(super) fn tangential_forces(&self, x: &[f64], forces: &Forces) -> Vec<Vector3<f64>> {
        let fs = self.model.force_scale();
        self.active
            .iter()
            .zip(self.offsets())
            .zip(forces)
            .map(|((a, o), force)| {
                if a.state == ContactState::Frictionless || a.site != Site::Tip {
                    return Vector3::zeros();
                }
                let f = Vector3::new(x[o], x[o + 1], x[o + 2]) * fs;
                let n = force.1;
                f - n * f.dot(&n)
            })
            .collect()
    }
}

/// The state a tip contact with friction turns to at the converged `x` (the last pass at
/// it), if any: the first sticking contact whose tangential force is outside the cone
/// slides (with the slip direction its force opposes, to start from: at the sticking
/// solution the slip is zero), the first sliding contact whose slip is back below
/// [`SLIP_FLOOR`] sticks. Not on a coarse mesh, whose Newton tolerance leaves the held
/// displacements errors that the rod's axial stiffness turns into spurious forces: its
/// contacts stick, and the mesh asked decides.
pub(super) fn switch(
    p: &Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
) -> Option<(usize, ContactState, Option<Vector3<f64>>)> {
    if !p.refine {
        return None;
    }
    let y = p.last.as_ref()?.nodes.last()?.y;
    let l = p.model.length();
    let fs = p.model.force_scale();
    for (i, (a, o)) in p.active.iter().zip(p.offsets()).enumerate() {
        if a.site != Site::Tip || a.state == ContactState::Frictionless {
            continue;
        }
        let (pc, n, _) = p.tip_point(a, &y);
        let f = Vector3::new(x[o], x[o + 1], x[o + 2]) * fs;
        let normal = f.dot(&n);
        let ft = f - n * normal;
        let tangential = ft.norm();
        let mu = p.obstacles[a.obstacle].friction();
        match a.state {
            ContactState::Stick => {
                let slack = CONE_SLACK * normal.abs().max(opts.tolerance * fs);
                if tangential > mu * normal + slack {
                    return Some((i, ContactState::Slide, Some(-ft / tangential)));
                }
            }
            _ => {
                let d = pc - a.reference;
                let u = d - n * d.dot(&n);
                if u.norm() < SLIP_FLOOR * l {
                    return Some((i, ContactState::Stick, None));
                }
            }
        }
    }
    None
}

/// The contact point (m, world) where the tip first touches obstacle `o` along the
/// proportional load path: `x` is converged at the current load factor without that contact
/// (and penetrates it); the gap of that solution is followed by regula falsi (Illinois) on
/// the load factor between the last accepted load step and the current one. At the first
/// load step (load factor 0, the actuated rod) or if the search fails, the contact point of
/// `x` itself. The load factor is restored. Returns the point, the load factor of the touch
/// and whether it was found by the search; `None` if `x` cannot be evaluated.
pub(super) fn first_touch(
    p: &mut Constrained<'_>,
    x: &[f64],
    o: usize,
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<(Vector3<f64>, f64, bool)> {
    let probe = Active::frictionless(o, Site::Tip);
    let at = |p: &Constrained<'_>| -> Option<(Vector3<f64>, f64)> {
        let y = p.last.as_ref()?.nodes.last()?.y;
        let (pc, _, gap) = p.tip_point(&probe, &y);
        Some((pc, gap))
    };
    let mut r = vec![0.0; p.dim()];
    if p.evaluate(x, 1.0, None, &mut r) == Evaluated::Failed {
        return None;
    }
    let (here, g1) = at(p)?;
    let target = p.load;
    let from = p.from.min(target);
    if target <= from || g1 >= 0.0 {
        return Some((here, target, false));
    }
    let l = p.model.length();
    let mut touch = here;
    let mut found = (target, false);
    // The sticking rows hold the touch point along the rod too, where the rod is stiffest
    // (E A / L): the touch is solved to round-off, also on a coarse mesh.
    let refine = std::mem::replace(&mut p.refine, true);
    let mut strict = *opts;
    strict.tolerance = opts.tolerance.min(TOUCH_TOLERANCE);
    let opts = &strict;
    p.load = from;
    if let Some(mut xs) = correct(p, x, opts, effort) {
        if let Some((start, g0)) = at(p) {
            touch = start;
            found = (from, true);
            let (mut la, mut ga, mut lb, mut gb) = (from, g0, target, g1);
            let mut side = 0;
            for _ in 0..MAX_TOUCH_ITERATIONS {
                if ga <= 0.0 || ga.abs() <= TOUCH_GAP * l {
                    break;
                }
                let lambda = lb - gb * (lb - la) / (gb - ga);
                p.load = lambda;
                let Some(next) = correct(p, &xs, opts, effort) else {
                    (touch, found) = (here, (target, false));
                    break;
                };
                xs = next;
                let Some((pc, g)) = at(p) else {
                    (touch, found) = (here, (target, false));
                    break;
                };
                (touch, found) = (pc, (lambda, true));
                if g.abs() <= TOUCH_GAP * l || g == ga || g == gb {
                    // Found, or the gap no longer moves (Newton within its tolerance).
                    break;
                }
                if g > 0.0 {
                    (la, ga) = (lambda, g);
                    if side == -1 {
                        gb *= 0.5;
                    }
                    side = -1;
                } else {
                    (lb, gb) = (lambda, g);
                    if side == 1 {
                        ga *= 0.5;
                    }
                    side = 1;
                }
            }
        }
    }
    p.load = target;
    p.refine = refine;
    Some((touch, found.0, found.1))
}

/// The first-touch points of the tip contacts with friction found on another (coarser) mesh,
/// found again on the mesh of `p` from the solution `x` there: the search of [`first_touch`]
/// around the load factor of each touch, without that contact. A point not found again is
/// kept. The active set, load factor and Jacobian hint of `p` are restored.
pub(super) fn retouch(
    p: &mut Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
    effort: &mut Effort,
) {
    let hint = p.hint.take();
    let (load, from) = (p.load, p.from);
    for i in 0..p.active.len() {
        let a = p.active[i];
        if a.site != Site::Tip || a.state == ContactState::Frictionless {
            continue;
        }
        let saved = p.active.clone();
        let o = p.offsets()[i];
        let mut xr = x.to_vec();
        xr.drain(o..o + 3);
        p.active.remove(i);
        let span = RETOUCH_SPAN * a.touch.max(RETOUCH_SPAN);
        p.load = (a.touch + span).min(load);
        p.from = (a.touch - span).max(0.0);
        let again = correct(p, &xr, opts, effort)
            .and_then(|xs| first_touch(p, &xs, a.obstacle, opts, effort));
        p.active = saved;
        if let Some((point, lambda, true)) = again {
            p.active[i].reference = point;
            p.active[i].touch = lambda;
        }
    }
    (p.load, p.from) = (load, from);
    p.hint = hint;
}
