//! Contact intervals on curved obstacles: the rod lying on a sphere, capsule or cylinder over
//! an interval `[a, b]` (a belt).
//!
//! A point force on a shearable rod kinks its backbone (the shear strain jumps with the
//! internal force): the gap's slope drops by about `F/(k G A)` across a contact, so the rod
//! dips into a curved obstacle on both sides of a point contact, by about
//! `F² / (8 (k G A)² c)` where `c` is the gap's curvature there, unless the force is spread.
//! Where that dip reaches the nodes (a soft rod, a large force, or a rod that nearly follows
//! the obstacle: an arm wrapped around a cylinder, whose free curvature is tighter than the
//! cylinder's but is held to it between its first touch and its tip) the contact is an
//! interval. On it the normal pressure `q(s)` that keeps the gap zero is computed from the
//! state at every `s` (a held interval of the model: see `model/hold.rs` and
//! `cosserat/equations/hold.rs`); the unknowns are the two ends `a`, `b` and the rows the gap
//! and its slope at `a` (the gap then stays zero up to `b`, where the rod leaves the
//! obstacle). A belt is valid while its pressure pushes everywhere (`q ≥ 0`); beyond its ends
//! the gap's curvature is `q B` at the end (`B` the section's normal compliance), so it
//! leaves the obstacle on its side.
//!
//! The active set forms a belt from a point contact on a curved, frictionless obstacle when a
//! new penetration is found next to it with the rod on the obstacle in between (and extends a
//! belt the same way); a belt whose pressure pulls somewhere becomes a point contact again at
//! its largest pressure. The Jacobian of a problem with a belt is differenced (the pressure's
//! derivatives along the variational columns are not integrated: the columns hold it as a
//! dead load, which is also what the stability and the tangent compliance of the solution
//! assume of every contact force).

use std::sync::Arc;

use nalgebra::{Matrix6, Vector3, Vector6};

use super::active_set;
use super::newton::{exact_newton, Effort};
use super::obstacle::Obstacle;
use super::problem::{Active, Constrained, Site};
use super::rows::{AtContact, Forces};
use crate::cosserat::equations::{v3, Evaluator, STATE};
use crate::cosserat::shooting::Node;
use crate::model::hold::Hold;
use crate::solve::NewtonOptions;

/// The pressure of a belt at one node: arc length (m), pressure (N/m), outward normal,
/// backbone point (m, world).
#[derive(Debug, Clone, Copy)]
pub(super) struct HeldSample {
    pub(super) s: f64,
    pub(super) q: f64,
    pub(super) normal: Vector3<f64>,
    pub(super) point: Vector3<f64>,
}

/// What a belt carries on one march: its pressure at the nodes from `a` to `b`, and the
/// position, total force and total moment of the march at its two ends (world).
#[derive(Debug, Clone)]
pub(super) struct Held {
    pub(super) samples: Vec<HeldSample>,
    pub(super) ends: [(Vector3<f64>, Vector3<f64>, Vector3<f64>); 2],
}

impl Held {
    /// The total normal force (N): the pressure integrated by the trapezoid rule.
    pub(super) fn total(&self) -> f64 {
        self.samples
            .windows(2)
            .map(|w| 0.5 * (w[0].q + w[1].q) * (w[1].s - w[0].s))
            .sum()
    }

    /// The sample of largest pressure.
    pub(super) fn peak(&self) -> Option<&HeldSample> {
        self.samples.iter().max_by(|a, b| a.q.total_cmp(&b.q))
    }

    /// The least pressure (N/m).
    pub(super) fn least(&self) -> f64 {
        self.samples
            .iter()
            .map(|h| h.q)
            .fold(f64::INFINITY, f64::min)
    }

    /// The arc lengths of its ends (m).
    pub(super) fn range(&self) -> (f64, f64) {
        match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => (a.s, b.s),
            _ => (f64::NAN, f64::NAN),
        }
    }
}

/// Whether obstacle `o` can hold a belt: a sphere, capsule or cylinder without friction,
/// touched by a shearable rod.
pub(super) fn holds_belt(p: &Constrained<'_>, o: usize) -> bool {
    let ob = &p.obstacles[o];
    ob.friction() == 0.0
        && !p.model.rod().inextensible()
        && matches!(
            ob.shape(),
            Obstacle::Sphere { .. } | Obstacle::Capsule { .. } | Obstacle::Cylinder { .. }
        )
}

impl Constrained<'_> {
    /// The held interval of the belt `a` from `sa` to `sb` (m), if inside the rod.
    pub(super) fn hold_of(&self, a: &Active, sa: f64, sb: f64) -> Option<Hold> {
        let l = self.model.length();
        if !(sa > 0.0 && sa < sb && sb <= l) {
            return None;
        }
        Some(Hold {
            surface: Arc::new(self.obstacles[a.obstacle].shape().clone()),
            a: sa,
            b: sb,
        })
    }

    /// The rows of the belt `a` starting at `at` (the node after its start, on its first
    /// interval): its gap over `L` and the gap's slope there, relaxed by `mu` from their
    /// values when it was formed.
    pub(super) fn belt_rows(
        &self,
        ev: &mut Evaluator<'_, '_>,
        a: &Active,
        at: AtContact<'_>,
        mu: f64,
        rows: &mut Vec<f64>,
    ) {
        let l = self.model.length();
        let (y, interval) = at.last;
        let props = self.model.rod().section_at(at.s);
        let (d, n) = self.obstacles[a.obstacle].distance(&v3(y, 0));
        rows.push((d - props.radius - (1.0 - mu) * a.g0) / l);
        ev.enter_interval(interval);
        let mut dy = [0.0; STATE];
        ev.rhs_into::<STATE>(at.s, y, &mut dy);
        rows.push(n.dot(&v3(&dy, 0)) - props.radius_rate - (1.0 - mu) * a.dg0);
    }

    /// The pressure of the belt from `a` to `b` (m) at the `nodes` of a march on its model
    /// (`ev`), and the march's state at its ends; `None` if it has no node.
    pub(super) fn held(
        &self,
        ev: &mut Evaluator<'_, '_>,
        nodes: &[Node],
        (a, b): (f64, f64),
    ) -> Option<Held> {
        let model = ev.eq.model;
        let mut samples = Vec::new();
        let mut ends = Vec::with_capacity(2);
        for n in nodes {
            let on = model
                .hold_on(n.interval)
                .is_some_and(|h| h.a == a && h.b == b);
            if !on || n.s < a || n.s > b {
                continue;
            }
            ev.enter_interval(n.interval);
            let mut dy = [0.0; STATE];
            ev.rhs_into::<STATE>(n.s, &n.y, &mut dy);
            let (q, normal) = ev.ws.hold_pressure;
            let point = v3(&n.y, 0);
            samples.push(HeldSample {
                s: n.s,
                q,
                normal,
                point,
            });
            if ends.is_empty() || n.s == b {
                ends.push((point, v3(&n.y, 12), v3(&n.y, 15)));
            }
        }
        if samples.len() < 2 || ends.len() < 2 {
            return None;
        }
        Some(Held {
            samples,
            ends: [ends[0], ends[ends.len() - 1]],
        })
    }
}

/// Whether a belt on obstacle `o` in the last pass overlaps the arc lengths `[s0, s1]` (m).
pub(super) fn covers(p: &Constrained<'_>, o: usize, (s0, s1): (f64, f64)) -> bool {
    let Some(pass) = p.last.as_ref() else {
        return false;
    };
    p.active.iter().zip(&pass.held).any(|(a, h)| {
        a.obstacle == o
            && h.as_ref().is_some_and(|h| {
                let (a, b) = h.range();
                s1 >= a && s0 <= b
            })
    })
}

/// The gap (m) below which the rod counts as lying on an obstacle between two contacts:
/// a thousandth of the node spacing (the depth the check between the nodes resolves).
pub(super) fn clearance(p: &Constrained<'_>) -> f64 {
    let n = p
        .last
        .as_ref()
        .map_or(1, |pass| pass.nodes.len().max(2) - 1);
    1e-3 * p.model.length() / n as f64
}

/// A belt to form: the obstacle, its ends (m; `to_tip`: from the first to the tip, with a
/// tip force), and the active contacts it replaces.
pub(super) struct Plan {
    obstacle: usize,
    range: (f64, f64),
    replaces: Vec<usize>,
    to_tip: bool,
}

/// Whether the rod lies on obstacle `o` between the arc lengths `s0` and `s1` in the last
/// pass: no node strictly between them is clear of it by more than `clear` (m).
pub(super) fn on_obstacle(p: &Constrained<'_>, o: usize, (s0, s1): (f64, f64), clear: f64) -> bool {
    let (lo, hi) = (s0.min(s1), s0.max(s1));
    p.gaps(o)
        .iter()
        .filter(|g| g.1 > lo && g.1 < hi)
        .all(|g| g.2 <= clear)
}

/// The belt to form for the new contacts `added` (with `forces` of the active ones), if
/// any: a new contact on an obstacle that holds belts, next to a point contact or a belt on
/// the same obstacle with the rod on the obstacle in between (no node clear of it by more
/// than `clear`, m), joins it; at the tip, the belt then reaches the tip.
pub(super) fn plan(
    p: &Constrained<'_>,
    forces: &Forces,
    added: &[(usize, Site, f64)],
    clear: f64,
) -> Option<Plan> {
    let l = p.model.length();
    let held = &p.last.as_ref()?.held;
    for &(o, site, s) in added {
        if !matches!(site, Site::Interior | Site::Tip) || !holds_belt(p, o) {
            continue;
        }
        for (i, a) in p.active.iter().enumerate() {
            if a.obstacle != o {
                continue;
            }
            let range = match a.site {
                Site::Interior => (forces[i].2, forces[i].2),
                Site::Belt | Site::BeltTip => held.get(i)?.as_ref()?.range(),
                _ => continue,
            };
            let near = if s < range.0 { range.0 } else { range.1 };
            let to_tip = site == Site::Tip || a.site == Site::BeltTip;
            // (A tip joins a belt only: a point contact next to the tip stays one.)
            if site == Site::Tip && a.site != Site::Belt {
                continue;
            }
            if on_obstacle(p, o, (near, s), clear) {
                let range = (range.0.min(s), if to_tip { l } else { range.1.max(s) });
                return Some(Plan {
                    obstacle: o,
                    range,
                    replaces: vec![i],
                    to_tip,
                });
            }
        }
    }
    None
}

/// What the active set changes of a belt whose forces do not push.
#[derive(Debug, Clone, Copy)]
pub(super) enum Change {
    /// Its pressure pulls in all: released.
    Drop,
    /// Its pressure pulls somewhere: a point contact at its largest pressure.
    ToPoint,
    /// A belt to the tip whose tip force pulls: a belt ending before the tip, at `b` (m).
    Untip(f64),
    /// A belt to the tip whose pressure pulls somewhere: a belt to `b` (m) and a point
    /// contact at the tip (a point contact at the tip alone if `b` is its start).
    Split(f64),
}

/// The first belt of the last pass at `x` whose forces do not push (its total or its tip
/// force below `-force`, N; its pressure below `-pressure`, N/m), and its change.
pub(super) fn change(
    p: &Constrained<'_>,
    x: &[f64],
    force: f64,
    pressure: f64,
) -> Option<(usize, Change)> {
    let pass = p.last.as_ref()?;
    let l = p.model.length();
    let fs = p.model.force_scale();
    let spacing = l / (pass.nodes.len().max(2) - 1) as f64;
    for (i, (a, o)) in p.active.iter().zip(p.offsets()).enumerate() {
        let Some(h) = pass.held.get(i).and_then(Option::as_ref) else {
            continue;
        };
        if h.total() < -force {
            return Some((i, Change::Drop));
        }
        if a.site == Site::BeltTip {
            let tip = v3(&pass.nodes.last()?.y, 0);
            let (_, n) = p.obstacles[a.obstacle].distance(&tip);
            let f = Vector3::new(x[o + 1], x[o + 2], x[o + 3]) * fs;
            if f.dot(&n) < -force {
                let (sa, _) = h.range();
                return Some((i, Change::Untip((l - 2.0 * spacing).max(0.5 * (sa + l)))));
            }
            if let Some(k) = h.samples.iter().position(|q| q.q < -pressure) {
                let b = if k == 0 {
                    h.range().0
                } else {
                    h.samples[k - 1].s
                };
                return Some((i, Change::Split(b)));
            }
        } else if h.least() < -pressure {
            return Some((i, Change::ToPoint));
        }
    }
    None
}

/// Applies `change` to the belt `i` of `x` and solves (see [`relax`]).
pub(super) fn apply(
    p: &mut Constrained<'_>,
    mut x: Vec<f64>,
    (i, change): (usize, Change),
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    let l = p.model.length();
    let fs = p.model.force_scale();
    let held = p.last.as_ref()?.held.get(i)?.clone()?;
    let o = p.offsets()[i];
    let (obstacle, site) = (p.active[i].obstacle, p.active[i].site);
    let size = p.active[i].size();
    let removed: Vec<f64> = x.drain(o..o + size).collect();
    p.active.remove(i);
    let (sa, _) = held.range();
    match change {
        Change::Drop => {}
        Change::ToPoint => {
            let peak = *held.peak()?;
            p.active
                .push(Active::frictionless(obstacle, Site::Interior));
            x.push(peak.s / l);
            x.extend((peak.normal * (held.total() / fs)).iter());
        }
        Change::Untip(b) => {
            p.active.push(Active::frictionless(obstacle, Site::Belt));
            x.extend([sa / l, b / l]);
        }
        Change::Split(b) => {
            if b > sa {
                p.active.push(Active::frictionless(obstacle, Site::Belt));
                x.extend([sa / l, b / l]);
            }
            p.active.push(Active::frictionless(obstacle, Site::Tip));
            let f = if site == Site::BeltTip {
                &removed[1..4]
            } else {
                &[0.0; 3][..]
            };
            x.extend_from_slice(f);
        }
    }
    relax(p, x, opts, effort)
}

/// Replaces the contacts of `plan` in `x` by its belt and solves: Newton at once, else by
/// relaxing the belt's gap and slope from their values at its start. The state at full
/// contact targets, or `None`.
pub(super) fn form(
    p: &mut Constrained<'_>,
    mut x: Vec<f64>,
    plan: &Plan,
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    let l = p.model.length();
    let offsets = p.offsets();
    let mut replaces = plan.replaces.clone();
    replaces.sort_unstable();
    // A tip force of the contacts replaced, kept.
    let mut tip_force = [0.0; 3];
    for &i in replaces.iter().rev() {
        let size = p.active[i].size();
        let removed: Vec<f64> = x.drain(offsets[i]..offsets[i] + size).collect();
        match p.active[i].site {
            Site::BeltTip => tip_force.copy_from_slice(&removed[1..4]),
            Site::Tip => tip_force.copy_from_slice(&removed[0..3]),
            _ => {}
        }
        p.active.remove(i);
    }
    let (a, b) = plan.range;
    if plan.to_tip {
        p.active
            .push(Active::frictionless(plan.obstacle, Site::BeltTip));
        x.push(a / l);
        x.extend(tip_force);
    } else {
        p.active
            .push(Active::frictionless(plan.obstacle, Site::Belt));
        x.extend([a / l, b / l]);
    }
    relax(p, x, opts, effort)
}

/// The tip of the rod about to touch obstacle `o` (see `ramp.rs`): a point contact at the
/// tip added with a zero force (a belt on `o` is kept: an arm whose free curvature is
/// tighter than the obstacle's lifts off it before its tip, which touches). Returns the
/// unknowns extended accordingly.
pub(super) fn anticipate_tip(p: &mut Constrained<'_>, mut x: Vec<f64>, o: usize) -> Vec<f64> {
    p.active.push(Active::frictionless(o, Site::Tip));
    x.extend([0.0; 3]);
    x
}

/// Newton on the current active set from `x`; else the rows of every contact relaxed from
/// their values at `x` to zero by continuation ([`active_set::relax`]).
fn relax(
    p: &mut Constrained<'_>,
    x: Vec<f64>,
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<Vec<f64>> {
    if let Some((xs, _)) = exact_newton(p, &x, opts, effort, true, false) {
        return Some(xs);
    }
    active_set::relax(p, &x, opts, effort)
}

/// The contact force of a belt at the samples `s` (m) with backbone `position` (m, world) of
/// a solution: its pressure lumped by the trapezoid rule at the samples from `a` to `b`,
/// corrected by the least-norm lumps `λ + μ × p_j` so that their sum and moment about the
/// origin are those the march applied: `N(a) - N(b)` and `Ω(a) - Ω(b)` with
/// `Ω = M + p × N`, less the distributed loads `f` (per metre, at the samples) over the belt
/// (by the trapezoid rule; no distributed moment is loaded on a belt).
pub(super) fn lumps(
    held: &Held,
    s: &[f64],
    position: &[[f64; 3]],
    applied: &dyn Fn(f64) -> Vector3<f64>,
) -> Vec<(usize, Vector3<f64>)> {
    let (a, b) = held.range();
    // (One sample per arc length: a break's two copies share their position.)
    let idx: Vec<usize> = (0..s.len())
        .filter(|&j| s[j] >= a && s[j] <= b && (j == 0 || s[j - 1] != s[j]))
        .collect();
    let mut out: Vec<(usize, Vector3<f64>)> = Vec::with_capacity(idx.len());
    let (mut f_lumped, mut m_lumped) = (Vector3::zeros(), Vector3::zeros());
    let (mut f_applied, mut m_applied) = (Vector3::zeros(), Vector3::zeros());
    let pressure = |t: f64| {
        held.samples
            .iter()
            .find(|h| h.s == t)
            .map_or(Vector3::zeros(), |h| h.normal * h.q)
    };
    for (k, &j) in idx.iter().enumerate() {
        let lo = if k > 0 { s[idx[k - 1]] } else { s[j] };
        let hi = if k + 1 < idx.len() {
            s[idx[k + 1]]
        } else {
            s[j]
        };
        let w = 0.5 * (hi - lo);
        let c = pressure(s[j]) * w;
        let pj = Vector3::from(position[j]);
        f_lumped += c;
        m_lumped += pj.cross(&c);
        let fa = applied(s[j]) * w;
        f_applied += fa;
        m_applied += pj.cross(&fa);
        out.push((j, c));
    }
    let ([pa, na, ma], [pb, nb, mb]) = (
        [held.ends[0].0, held.ends[0].1, held.ends[0].2],
        [held.ends[1].0, held.ends[1].1, held.ends[1].2],
    );
    let f_exact = na - nb - f_applied;
    let m_exact = (ma + pa.cross(&na)) - (mb + pb.cross(&nb)) - m_applied;
    // The least-norm correction: lumps λ + μ × p_j with the sum and moment missing.
    let points: Vec<Vector3<f64>> = out
        .iter()
        .map(|(j, _)| Vector3::from(position[*j]))
        .collect();
    let apply = |lm: &Vector6<f64>| {
        let (l, m) = (lm.fixed_rows::<3>(0), lm.fixed_rows::<3>(3));
        let (l, m) = (Vector3::from(l), Vector3::from(m));
        let (mut f, mut t) = (Vector3::zeros(), Vector3::zeros());
        for pj in &points {
            let c = l + m.cross(pj);
            f += c;
            t += pj.cross(&c);
        }
        Vector6::new(f.x, f.y, f.z, t.x, t.y, t.z)
    };
    let mut k = Matrix6::zeros();
    for c in 0..6 {
        let mut e = Vector6::zeros();
        e[c] = 1.0;
        k.set_column(c, &apply(&e));
    }
    let rhs = {
        let (df, dm) = (f_exact - f_lumped, m_exact - m_lumped);
        Vector6::new(df.x, df.y, df.z, dm.x, dm.y, dm.z)
    };
    if let Ok(lm) = k.svd(true, true).solve(&rhs, 1e-12 * k.amax()) {
        let (l, m) = (
            Vector3::new(lm[0], lm[1], lm[2]),
            Vector3::new(lm[3], lm[4], lm[5]),
        );
        for ((_, c), pj) in out.iter_mut().zip(&points) {
            *c += l + m.cross(pj);
        }
    }
    out
}
