//! Coulomb friction at point contacts, at the tip and inside the rod.
//!
//! A static problem needs a reference for the slip: here where the contact first touched
//! the obstacle along the proportional load path of the solve (the load factor at which the
//! gap of the solution without that contact vanishes, found by regula falsi between the last
//! accepted load step and the current one): the backbone point `p₀` of the contact there and
//! its arc length `s₀`. Inside the rod the gap of the solution without the contact is read at
//! a probe, a contact whose normal force is held at zero and whose arc length stays at the
//! least gap, so that the touch is found on the same mesh and to the same round-off as the
//! contact that follows it.
//!
//! The contact force acts on the backbone (a thin rod: the moment `R n × f_t` of a
//! tangential force about the backbone is not applied), and the slip is the displacement
//! work-conjugate to it: that of the backbone's material point at `s₀` along the obstacle's
//! tangent plane, to first order in the distance the contact has moved along the rod,
//! `u = P (p(s) + (s₀ - s) t(s) - p₀)`, with `s` the contact's arc length, `t` the rod's
//! tangent (the body z axis) and `P` the projection onto the obstacle's tangent plane (at
//! the tip `s = s₀ = L`). A rod turning about its backbone point at the contact moves the
//! contact along the rod and the obstacle by the same length: no slip. (The surface fibre at
//! the contact moves by `R` times the rotation of the section as the rod bends; counting it
//! without the moment of the offset force would not be consistent, and against the axial
//! stiffness `E A` it would ask for an axial friction force about `4 a / (3 R)` times the
//! normal force at a contact `a` from the base of a bent rod.)
//!
//! A sticking contact holds `u` at zero: its rows are the gap and the two components of `u`
//! (over `L`). A sliding contact keeps the gap row and puts its tangential force on the
//! cone, opposite to the slip: `f_t + μ f_n u / max(|u|, ε L) = 0`, two rows, with `ε` =
//! [`SLIP_FLOOR`] so that the rows stay smooth where the slip starts from zero. The
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
/// Newton tolerance (at most) of the solves of the first-touch search.
const TOUCH_TOLERANCE: f64 = 1e-10;
/// Gap (relative to the rod length) at which the first-touch search stops.
const TOUCH_GAP: f64 = 1e-13;

impl Constrained<'_> {
    /// The gap (m) between obstacle `o` and the rod's surface at arc length `s` (m) with the
    /// rod's state `y` there.
    fn gap_at(&self, o: usize, s: f64, y: &[f64; STATE]) -> f64 {
        let radius = self.model.rod().section_at(s).radius;
        self.obstacles[o].distance(&v3(y, 0)).0 - radius
    }

    /// The slip `u` (m, world) of the contact `a` at arc length `s` (m) with the rod's state
    /// `y` there (see the module's documentation), and the obstacle's outward normal.
    fn slip(&self, a: &Active, s: f64, y: &[f64; STATE]) -> (Vector3<f64>, Vector3<f64>) {
        let p = v3(y, 0);
        let (_, n) = self.obstacles[a.obstacle].distance(&p);
        let d = p + v3(y, 9) * (a.arc - s) - a.reference;
        (d - n * d.dot(&n), n)
    }

    /// The two tangential rows of the contact `a` with friction at arc length `s` (m) with
    /// the rod's state `y` there (before the jump of the force), scaled force `f`, homotopy
    /// parameter `relax` (see the module's documentation).
    pub(super) fn friction_rows(
        &self,
        a: &Active,
        s: f64,
        y: &[f64; STATE],
        f: &Vector3<f64>,
        relax: f64,
        rows: &mut Vec<f64>,
    ) {
        let l = self.model.length();
        let (u, n) = self.slip(a, s, y);
        let (t1, t2) = obstacle_normal_basis(&n);
        if a.state == ContactState::Stick {
            rows.push((u.dot(&t1) - (1.0 - relax) * a.t0[0]) / l);
            rows.push((u.dot(&t2) - (1.0 - relax) * a.t0[1]) / l);
            return;
        }
        let mu = self.obstacles[a.obstacle].friction();
        let normal = f.dot(&n);
        let ft = f - n * normal;
        let r = match a.direction {
            Some(e) => ft + e * (mu * normal),
            None => ft + u * (mu * normal / u.norm().max(SLIP_FLOOR * l)),
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
                if a.state == ContactState::Frictionless {
                    return Vector3::zeros();
                }
                let k = o + a.force_offset();
                let f = Vector3::new(x[k], x[k + 1], x[k + 2]) * fs;
                let n = force.1;
                f - n * f.dot(&n)
            })
            .collect()
    }

    /// The arc length (m) of the active contact with unknowns from `o` at `x`.
    pub(super) fn arc_of(&self, a: &Active, x: &[f64], o: usize) -> f64 {
        match a.site {
            Site::Tip => self.model.length(),
            Site::Interior | Site::Interval | Site::Belt | Site::BeltTip => {
                x[o] * self.model.length()
            }
        }
    }

    /// The state of the rod at arc length `s` (m) in the last pass (its first node there,
    /// before the jump of a force).
    fn state_at(&self, s: f64) -> Option<[f64; STATE]> {
        let pass = self.last.as_ref()?;
        pass.nodes.iter().find(|n| n.s == s).map(|n| n.y)
    }
}

/// The state a contact with friction turns to at the converged `x` (the last pass at it),
/// if any: the first sticking contact whose tangential force is outside the cone slides
/// (with the slip direction its force opposes, to start from: at the sticking solution the
/// slip is zero), the first sliding contact whose slip is back below [`SLIP_FLOOR`] sticks.
pub(super) fn switch(
    p: &Constrained<'_>,
    x: &[f64],
    opts: &NewtonOptions,
) -> Option<(usize, ContactState, Option<Vector3<f64>>)> {
    let l = p.model.length();
    let fs = p.model.force_scale();
    for (i, (a, o)) in p.active.iter().zip(p.offsets()).enumerate() {
        if a.state == ContactState::Frictionless {
            continue;
        }
        let s = p.arc_of(a, x, o);
        let Some(y) = p.state_at(s) else {
            continue;
        };
        let (u, n) = p.slip(a, s, &y);
        let k = o + a.force_offset();
        let f = Vector3::new(x[k], x[k + 1], x[k + 2]) * fs;
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
                if u.norm() < SLIP_FLOOR * l {
                    return Some((i, ContactState::Stick, None));
                }
            }
        }
    }
    None
}

/// Where a contact first touched its obstacle on the load path ([`first_touch`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Touch {
    /// The backbone point of the contact (m, world).
    pub(super) point: Vector3<f64>,
    /// Its arc length (m).
    pub(super) arc: f64,
}

/// Where a contact at `site` (inside the rod: near arc length `s`, m) first touches obstacle
/// `o` along the proportional load path: `x` is converged at the current load factor without
/// that contact (and penetrates it); the gap of that solution is followed by regula falsi
/// (Illinois) on the load factor between the last accepted load step and the current one.
/// Inside the rod the gap is read at a probe ([`Active::probe`]) held at the least gap. At
/// the first load step (load factor 0, the actuated rod) or if the search fails, the
/// contact of `x` itself. The load factor and active set are restored. `None` if `x`
/// cannot be evaluated (or, inside the rod, the probe not solved there).
pub(super) fn first_touch(
    p: &mut Constrained<'_>,
    x: &[f64],
    o: usize,
    (site, s): (Site, f64),
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Touch> {
    let l = p.model.length();
    let mut xs = x.to_vec();
    // The sticking rows hold the touch point along the rod too, where the rod is stiffest
    // (E A / L): the touch is solved to round-off.
    let mut strict = *opts;
    strict.tolerance = opts.tolerance.min(TOUCH_TOLERANCE);
    if site == Site::Tip {
        let mut r = vec![0.0; p.dim()];
        return (p.evaluate(x, 1.0, None, &mut r) != Evaluated::Failed)
            .then(|| search(p, xs, o, &strict, effort))
            .flatten();
    }
    let mut probe = Active::frictionless(o, Site::Interior);
    probe.probe = true;
    p.active.push(probe);
    xs.extend([s / l, 0.0, 0.0, 0.0]);
    let touched = correct(p, &xs, &strict, effort).and_then(|xs| search(p, xs, o, &strict, effort));
    p.active.pop();
    touched
}

/// The regula falsi of [`first_touch`] from `xs`, converged at the current load factor with
/// the contact absent (at the tip) or as the last active contact, a probe (inside the rod).
fn search(
    p: &mut Constrained<'_>,
    mut xs: Vec<f64>,
    o: usize,
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Touch> {
    let l = p.model.length();
    let probe = p.active.last().is_some_and(|a| a.probe);
    // The backbone point, arc length and gap of the contact in the last pass at `xs`.
    let at = |p: &Constrained<'_>, xs: &[f64]| -> Option<(Vector3<f64>, f64, f64)> {
        let s = if probe { xs[xs.len() - 4] * l } else { l };
        let y = p.state_at(s)?;
        Some((v3(&y, 0), s, p.gap_at(o, s, &y)))
    };
    let (here, s1, g1) = at(p, &xs)?;
    let target = p.load;
    let from = p.from.min(target);
    let at_target = Touch {
        point: here,
        arc: s1,
    };
    if target <= from || g1 >= 0.0 {
        return Some(at_target);
    }
    let mut touch = at_target;
    p.set_load(from);
    if let Some(start) = correct(p, &xs, opts, effort) {
        xs = start;
        if let Some((point, arc, g0)) = at(p, &xs) {
            touch = Touch { point, arc };
            let (mut la, mut ga, mut lb, mut gb) = (from, g0, target, g1);
            let mut side = 0;
            for _ in 0..MAX_TOUCH_ITERATIONS {
                if ga <= 0.0 || ga.abs() <= TOUCH_GAP * l {
                    break;
                }
                let lambda = lb - gb * (lb - la) / (gb - ga);
                p.set_load(lambda);
                let Some((next, (point, arc, g))) = correct(p, &xs, opts, effort)
                    .and_then(|next| at(p, &next).map(|found| (next, found)))
                else {
                    touch = at_target;
                    break;
                };
                xs = next;
                touch = Touch { point, arc };
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
    p.set_load(target);
    Some(touch)
}
