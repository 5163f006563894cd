//! Obstacles crossed on the way: the actuation stepped with the loads.
//!
//! The contact solve applies the actuation in full (the actuated rod without loads is one
//! march) and adds contacts where that shape penetrates. An obstacle the rod would meet on
//! its way from the unactuated shape, but that the final shape lies wholly beyond (a wire
//! between the straight and the bent robot), is then never seen. After a solve, every point
//! of the rod (sampled more finely than the thinnest obstacle) is moved along the straight
//! segment from its unactuated, unloaded position to its position in the solution; if one of
//! these segments runs into an obstacle that both its ends are clear of, the rod may have
//! crossed it, and the problem is solved again with the actuation and the loads stepped
//! together from zero, each step checked the same way against the previous one (and halved
//! if it crossed), so that the rod meets the obstacle on its side.
//!
//! The same stepped solve is taken from the start when a contact about to be added lies past
//! the middle of its obstacle seen from the unactuated rod ([`past_middle`]): relaxing its gap
//! would push the rod out through the obstacle. It then follows the load path ([`on_secant`]):
//! secant predictors, steps refused where the corrector leaves the secant (a fold or a
//! bifurcation), snaps below [`SNAP_STEP`].

use nalgebra::Vector3;

use super::active_set::active_set;
use super::belt;
use super::newton::Effort;
use super::obstacle::Obstacle;
use super::problem::{Active, Constrained, Pass, Site};
use super::sweep::{arc_point, least_gap_in_cell, CellEnd};
use crate::cosserat::equations::{rot, v3};
use crate::cosserat::shooting::Node;
use crate::error::Error;
use crate::solve::{NewtonOptions, MIN_LOAD_INCREMENT};

/// Most sample points along the rod for the crossing check.
const MAX_SAMPLES: usize = 4000;
/// Largest step of the load factor when stepping.
const MAX_STEP: f64 = 0.25;
/// The cosine below which a new contact's outward normal, against the normal where its
/// material point entered the obstacle, sends the rod out forward through the obstacle.
const FORWARD_EXIT: f64 = -0.1;
/// Below this step of the load factor, a stepped solve that follows the path through
/// bifurcations accepts a corrector off the path's secant (the rod snaps).
const SNAP_STEP: f64 = 1.0 / 256.0;
/// What a corrector may lie off the path's secant besides half the predicted motion, as a
/// fraction of the rod's length.
const BRANCH_TOLERANCE: f64 = 1e-4;

/// The thickness (m) an obstacle offers to a rod crossing it: `None` for a plane (a rod
/// beyond it penetrates it).
fn thickness(o: &Obstacle) -> Option<f64> {
    match o.shape() {
        Obstacle::Plane { .. } | Obstacle::Frictional { .. } => None,
        Obstacle::Sphere { radius, .. }
        | Obstacle::Capsule { radius, .. }
        | Obstacle::Cylinder { radius, .. } => Some(2.0 * radius),
        Obstacle::Mesh(m) => {
            let v = m.vertices();
            let extent = (0..3)
                .map(|k| {
                    let (lo, hi) = v
                        .iter()
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                            (a.min(p[k]), b.max(p[k]))
                        });
                    hi - lo
                })
                .fold(f64::INFINITY, f64::min);
            Some(extent)
        }
    }
}

/// The arc lengths (m) the crossing check samples, and the rod's radius (m) at each; empty
/// if no obstacle has a finite thickness.
pub(super) fn samples(p: &Constrained<'_>) -> (Vec<f64>, Vec<f64>) {
    let l = p.model.length();
    let Some(thin) = p.obstacles.iter().filter_map(thickness).reduce(f64::min) else {
        return (Vec::new(), Vec::new());
    };
    let rod = p.model.rod();
    let r_min = [0.0, 0.5 * l, l]
        .iter()
        .map(|&s| rod.section_at(s).radius)
        .fold(f64::INFINITY, f64::min);
    let spacing = (0.5 * (thin + 2.0 * r_min)).max(l / MAX_SAMPLES as f64);
    let n = ((l / spacing).ceil() as usize).max(1);
    let s: Vec<f64> = (0..=n).map(|k| l * k as f64 / n as f64).collect();
    let r = s.iter().map(|&s| rod.section_at(s).radius).collect();
    (s, r)
}

/// The backbone of `pass` at the arc lengths `s` (sorted): the cubic Hermite arc through the
/// two nodes around each (tangents `Δs R e₃`).
pub(super) fn positions_at(pass: &Pass, s: &[f64]) -> Vec<Vector3<f64>> {
    positions_on(&pass.nodes, s)
}

/// The backbone through `nodes` at the arc lengths `s` (sorted), as [`positions_at`].
pub(super) fn positions_on(nodes: &[Node], s: &[f64]) -> Vec<Vector3<f64>> {
    let mut j = 0;
    s.iter()
        .map(|&t| {
            while j + 2 < nodes.len() && nodes[j + 1].s < t {
                j += 1;
            }
            let (a, b) = (&nodes[j], &nodes[(j + 1).min(nodes.len() - 1)]);
            let h = b.s - a.s;
            if h <= 0.0 {
                return v3(&b.y, 0);
            }
            let u = ((t - a.s) / h).clamp(0.0, 1.0);
            arc_point(
                &CellEnd::at_node(&a.y, h, 0.0),
                &CellEnd::at_node(&b.y, h, 0.0),
                u,
            )
        })
        .collect()
}

/// The obstacles and sites of `p`'s active contacts.
fn signature(p: &Constrained<'_>) -> Vec<(usize, Site)> {
    p.active.iter().map(|a| (a.obstacle, a.site)).collect()
}

/// Whether the shape `now` (at the samples) lies on the secant of the path through the
/// shapes `before` and `at` of the last two steps, extended by `r` times the last step: no
/// sample off the prediction by more than half the predicted motion plus [`BRANCH_TOLERANCE`]
/// times the rod's length `l` (m). A corrector that lands farther has left the branch (at a
/// bifurcation) or the path turns faster than the step can follow (near a fold).
fn on_secant(
    now: &[Vector3<f64>],
    (before, at): (&[Vector3<f64>], &[Vector3<f64>]),
    r: f64,
    l: f64,
) -> bool {
    let (mut off, mut motion) = (0.0f64, 0.0f64);
    for ((n, b), a) in now.iter().zip(before).zip(at) {
        let predicted = a + (a - b) * r;
        off = off.max((n - predicted).norm());
        motion = motion.max((predicted - a).norm());
    }
    off <= 0.5 * motion + BRANCH_TOLERANCE * l
}

/// Whether `o` has a finite thickness (a rod can pass it or through it).
pub(super) fn thick(o: &Obstacle) -> bool {
    thickness(o).is_some()
}

/// Whether obstacle `i` is checked for crossing: of finite thickness and not touched in
/// `p`'s active set.
fn checked(p: &Constrained<'_>, i: usize) -> bool {
    thickness(&p.obstacles[i]).is_some() && !p.active.iter().any(|a| a.obstacle == i)
}

/// Whether any obstacle is to be checked for crossing ([`crossed`]).
pub(super) fn any_checked(p: &Constrained<'_>) -> bool {
    (0..p.obstacles.len()).any(|i| checked(p, i))
}

/// The gaps (m) of `o` at the two ends of the straight segment from `a` to `b` (a point of the
/// rod of radius `r` moving), and whether the gap along it falls below `threshold` (m).
fn segment_gap(
    o: &Obstacle,
    a: Vector3<f64>,
    b: Vector3<f64>,
    r: f64,
    threshold: f64,
) -> (f64, f64, bool) {
    let end = |point: Vector3<f64>| CellEnd {
        point,
        tangent: b - a,
        radius: r,
    };
    let (ea, eb) = (end(a), end(b));
    let ga = o.distance(&a).0 - r;
    let gb = o.distance(&b).0 - r;
    let below = least_gap_in_cell(o, (&ea, ga), (&eb, gb), threshold).is_some();
    (ga, gb, below)
}

/// Whether a point of the rod moved from `from` to `to` (same samples, radii `radius`)
/// along a segment that runs into an obstacle by more than `depth` (m) while both its ends
/// are clear of it by `-depth`. Obstacles the rod touches in `p`'s active set are not
/// checked: the rod met them (a rod wrapped around an obstacle it touches moves through it
/// only on the straight segments).
pub(super) fn crossed(
    p: &Constrained<'_>,
    (from, to): (&[Vector3<f64>], &[Vector3<f64>]),
    radius: &[f64],
    depth: f64,
) -> bool {
    (0..p.obstacles.len()).filter(|&i| checked(p, i)).any(|i| {
        (0..from.len()).any(|k| {
            let (ga, gb, below) = segment_gap(&p.obstacles[i], from[k], to[k], radius[k], -depth);
            ga >= -depth && gb >= -depth && below
        })
    })
}

/// Whether a point of the rod moved from `from` to `to` by more than half the thickness of
/// an obstacle (plus the rod's diameter) it passed within that distance of: a step that may
/// have carried it through the obstacle between two checks.
fn too_far(
    p: &Constrained<'_>,
    (from, to): (&[Vector3<f64>], &[Vector3<f64>]),
    radius: &[f64],
) -> bool {
    p.obstacles.iter().any(|o| {
        let Some(t) = thickness(o) else {
            return false;
        };
        (0..from.len()).any(|k| {
            let limit = 0.5 * (t + 2.0 * radius[k]);
            (to[k] - from[k]).norm() > limit && segment_gap(o, from[k], to[k], radius[k], limit).2
        })
    })
}

/// The rod's unactuated, unloaded nodes on `p`'s mesh (one march at zero unknowns, kept in
/// `p.rest` for that mesh), leaving `p` as it was.
pub(super) fn rest_nodes<'a>(p: &'a mut Constrained<'_>) -> Option<&'a [Node]> {
    if p.rest
        .as_ref()
        .is_some_and(|(mesh, _)| *mesh == p.integrator)
    {
        return p.rest.as_ref().map(|(_, nodes)| nodes.as_slice());
    }
    let saved = (
        std::mem::take(&mut p.active),
        p.tensions.clone(),
        p.pressures.clone(),
        p.load,
        p.tip.take(),
        p.last.take(),
    );
    p.tensions.iter_mut().for_each(|t| *t = 0.0);
    p.pressures.iter_mut().for_each(|t| *t = 0.0);
    p.load = 0.0;
    let ok = p.run(&[0.0; 6], 1.0, false).is_some();
    let nodes = p.last.take().filter(|_| ok).map(|pass| pass.nodes);
    (p.active, p.tensions, p.pressures, p.load, p.tip, p.last) = saved;
    p.rest = nodes.map(|n| (p.integrator, n));
    p.rest.as_ref().map(|(_, nodes)| nodes.as_slice())
}

/// The rod must start clear of every obstacle: an obstacle its unactuated, unloaded backbone
/// lies in (the base in a plane's solid side, a sphere around the rod) leaves no load path
/// out of it, and no contact set at load factor 0. Checked at the nodes of `p`'s mesh and
/// along the arcs between them (the least gap of each cell's cubic arc, so that an obstacle
/// of any size the backbone runs through is found); the backbone may lie on a surface (a rod
/// mounted on a plane through its base).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `obstacles[i]`, with the depth and where.
pub(super) fn check_rest_clear(p: &mut Constrained<'_>) -> crate::error::Result<()> {
    if p.obstacles.is_empty() {
        return Ok(());
    }
    let depth = 1e-9 * p.model.length();
    let obstacles = p.obstacles;
    let model = p.model;
    let Some(nodes) = rest_nodes(p) else {
        // Not integrable: the solve reports that.
        return Ok(());
    };
    let radius = |s: f64| model.rod().section_at(s).radius;
    for (i, o) in obstacles.iter().enumerate() {
        let found = deepest_at_rest(o, nodes, depth)
            .map(|(sk, x, d)| (sk, x, d, "backbone"))
            .or_else(|| {
                surface_at_rest(o, nodes, &radius, depth).map(|(sk, x, d)| (sk, x, d, "surface"))
            });
        if let Some((sk, x, d, part)) = found {
            let kind = match o.shape() {
                Obstacle::Plane { .. } => "a plane",
                Obstacle::Sphere { .. } => "a sphere",
                Obstacle::Capsule { .. } => "a capsule",
                Obstacle::Cylinder { .. } => "a cylinder",
                _ => "a mesh",
            };
            return Err(Error::invalid(
                format!("obstacles[{i}]"),
                kind,
                format!(
                    "clear of the rod at rest (its unactuated, unloaded {part} lies \
                     {:.3e} m inside it at s = {sk:.4} m, ({:.4}, {:.4}, {:.4}) m)",
                    -d, x.x, x.y, x.z
                ),
            ));
        }
    }
    Ok(())
}

/// The first place (arc length, m; point, m; gap, m) where the backbone through `nodes` lies
/// deeper than `depth` (m) in `o`: a node, or the least gap of the cubic arc of a cell.
fn deepest_at_rest(o: &Obstacle, nodes: &[Node], depth: f64) -> Option<(f64, Vector3<f64>, f64)> {
    let gap = |n: &Node| o.distance(&v3(&n.y, 0)).0;
    if let Some(n) = nodes.first().filter(|n| gap(n) < -depth) {
        return Some((n.s, v3(&n.y, 0), gap(n)));
    }
    nodes.windows(2).find_map(|w| {
        let (a, b) = (&w[0], &w[1]);
        let (ga, gb) = (gap(a), gap(b));
        if gb < -depth {
            return Some((b.s, v3(&b.y, 0), gb));
        }
        let h = b.s - a.s;
        if h <= 0.0 {
            return None;
        }
        let (ea, eb) = (
            CellEnd::at_node(&a.y, h, 0.0),
            CellEnd::at_node(&b.y, h, 0.0),
        );
        let (t, g) = least_gap_in_cell(o, (&ea, ga), (&eb, gb), -depth)?;
        Some((a.s + t * h, arc_point(&ea, &eb, t), g))
    })
}

/// The first node (arc length, m; backbone point, m; gap, m) of `nodes` whose cross-section
/// (a disc of radius `radius(s)`, m, normal to the tangent) reaches deeper than `depth` (m)
/// into `o` while its backbone is outside: the gap `d - r |n × t|`, `n` the obstacle's normal
/// at the backbone and `t` the tangent (a plane along the rod cutting its surface; a base
/// plate through the base, whose normal is the tangent, does not).
fn surface_at_rest(
    o: &Obstacle,
    nodes: &[Node],
    radius: &dyn Fn(f64) -> f64,
    depth: f64,
) -> Option<(f64, Vector3<f64>, f64)> {
    nodes.iter().find_map(|n| {
        let x = v3(&n.y, 0);
        let (d, normal) = o.distance(&x);
        let tangent = rot(&n.y) * Vector3::z();
        let g = d - radius(n.s) * normal.cross(&tangent).norm();
        (g < -depth).then_some((n.s, x, g))
    })
}

/// Whether one of the contacts `added` (obstacle, site, arc length) to `p`'s last pass lies
/// in an obstacle of finite thickness past its middle, seen from where its material point
/// came from (in the rod through the nodes `from`, clear of the obstacle): the straight
/// segment from there enters the obstacle where its outward normal opposes the normal at the
/// contact's place (cosine below [`FORWARD_EXIT`]).
pub(super) fn past_middle(
    p: &Constrained<'_>,
    added: &[(usize, Site, f64)],
    from: &[Node],
) -> bool {
    let Some(pass) = p.last.as_ref() else {
        return false;
    };
    let rod = p.model.rod();
    added.iter().any(|&(o, _, s)| {
        let obstacle = &p.obstacles[o];
        if thickness(obstacle).is_none() {
            return false;
        }
        let r = rod.section_at(s).radius;
        let (a, b) = (
            positions_on(from, &[s])[0],
            positions_on(&pass.nodes, &[s])[0],
        );
        let gap = |t: f64| obstacle.distance(&(a + (b - a) * t)).0 - r;
        if !(gap(0.0) > 0.0 && gap(1.0) < 0.0) {
            return false;
        }
        let (mut clear, mut inside) = (0.0, 1.0);
        for _ in 0..60 {
            let t = 0.5 * (clear + inside);
            if gap(t) > 0.0 {
                clear = t;
            } else {
                inside = t;
            }
        }
        let entry = obstacle.distance(&(a + (b - a) * clear)).1;
        entry.dot(&obstacle.distance(&b).1) < FORWARD_EXIT
    })
}

/// The shape `at` (at the samples, radii `radius`) slid off the obstacles of finite thickness
/// it touches in `touched`: every sample moved by one vector that sums, for each such
/// obstacle, its thickness plus the rod's diameter along the way the sample nearest to it
/// moved on the last step (from `before`), less its part along the obstacle's normal. A rod
/// that snaps when its contact slides off an obstacle's end (the edge of a cylinder, the cap
/// of a capsule) passes there on its way to where it lands. `None` if nothing slid.
fn slid_off(
    p: &Constrained<'_>,
    touched: &[Active],
    (before, at): (&[Vector3<f64>], &[Vector3<f64>]),
    radius: &[f64],
) -> Option<Vec<Vector3<f64>>> {
    let mut shift = Vector3::zeros();
    for a in touched {
        let o = &p.obstacles[a.obstacle];
        let Some(t) = thickness(o) else {
            continue;
        };
        let gap = |k: usize| o.distance(&at[k]).0 - radius[k];
        let k = (0..at.len()).min_by(|&i, &j| gap(i).total_cmp(&gap(j)))?;
        let n = o.distance(&at[k]).1;
        let moved = at[k] - before.get(k)?;
        let slide = moved - n * n.dot(&moved);
        if slide.norm() <= f64::EPSILON * p.model.length() {
            continue;
        }
        shift += slide.normalize() * (t + 2.0 * radius[k]);
    }
    (shift != Vector3::zeros()).then(|| at.iter().map(|x| x + shift).collect())
}

/// The branch ends (a fold): the rod snaps from the shape `from` (at the samples `s`, radii
/// `radius`). It lands where the solve at the current load factor from the contact-free
/// shape puts it, unless it crossed an obstacle deeper than `depth` (m) on the way there:
/// straight, or, given the shape `before` a step earlier, after sliding off the obstacles it
/// touched ([`slid_off`]). A new contact past the middle of its obstacle, seen from the last
/// step, is refused by the active set. The unknowns and the shape where it lands.
fn snap(
    p: &mut Constrained<'_>,
    (s, radius, depth): (&[f64], &[f64], f64),
    (before, from): (Option<&[Vector3<f64>]>, &[Vector3<f64>]),
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Option<(Vec<f64>, Vec<Vector3<f64>>)> {
    let touched = std::mem::take(&mut p.active);
    p.last = None;
    let xn = active_set(p, &[0.0; 6], opts, effort)?;
    let shape = positions_at(p.last.as_ref()?, s);
    let clear = |a: &[Vector3<f64>], b: &[Vector3<f64>]| !crossed(p, (a, b), radius, depth);
    let landed = clear(from, &shape)
        || before
            .and_then(|b| slid_off(p, &touched, (b, from), radius))
            .is_some_and(|off| clear(from, &off) && clear(&off, &shape));
    landed.then_some((xn, shape))
}

/// The tip contacts whose gap (at the tip, on an obstacle free of friction and not touched
/// at the tip), extrapolated linearly from its value at the step accepted before (in `gaps`,
/// replaced by those of the last pass), closes within the next step of the same length.
fn closing_tips(p: &Constrained<'_>, gaps: &mut Vec<f64>) -> Vec<(usize, Site, f64)> {
    let l = p.model.length();
    let now: Vec<f64> = (0..p.obstacles.len())
        .map(|o| p.gaps(o).last().map_or(f64::INFINITY, |g| g.2))
        .collect();
    let out = (0..p.obstacles.len())
        .filter(|&o| {
            p.obstacles[o].friction() == 0.0
                && !p
                    .active
                    .iter()
                    .any(|a| a.obstacle == o && a.site == Site::Tip)
                && gaps
                    .get(o)
                    .is_some_and(|&g0| now[o] < g0 && 2.0 * now[o] - g0 <= 0.0)
        })
        .map(|o| (o, Site::Tip, l))
        .collect();
    *gaps = now;
    out
}

/// The active-set solve with the actuation (`tensions`, `pressures`: the full ones) and the
/// loads stepped together from zero, from the unactuated rod `rest` (its nodes; the samples
/// `s`, radii `radius`), each step refused and halved if the rod crossed an obstacle on it. The
/// load factor scales the actuation too ([`Constrained::path`]), so that a contact with
/// friction finds its first touch on this path. When the solve was sent here by a contact
/// past the middle of its obstacle (`p.crossing`), the path is followed: each step starts
/// from the secant of the last two (with an unchanged active set), is refused if its shape
/// leaves that secant ([`on_secant`]) or adds a contact past the middle of its obstacle seen
/// from the previous step, and below [`SNAP_STEP`] the rod snaps to the solve from the
/// contact-free shape at that load factor unless it crossed an obstacle.
///
/// Failing, the unknowns of the last step accepted (at load factor `p.from`, the active set
/// left as it was there).
pub(super) fn stepped(
    p: &mut Constrained<'_>,
    (tensions, pressures): (&[f64], &[f64]),
    (s, radius, rest): (&[f64], &[f64], Vec<Node>),
    opts: &NewtonOptions,
    effort: &mut Effort,
) -> Result<Vec<f64>, Vec<f64>> {
    let depth = 10.0 * opts.tolerance * p.model.length();
    let mut previous = positions_on(&rest, s);
    p.approach = Some(rest);
    p.active.clear();
    p.hint = None;
    p.solved = None;
    p.path = Some((tensions.to_vec(), pressures.to_vec()));
    p.from = 0.0;
    let mut x = vec![0.0; 6];
    let faithful = p.crossing;
    let l = p.model.length();
    // The secant of the path: the step (of the load factor) to the current state, and the
    // state before it (unknowns, shape); kept only when that step left the active set as it
    // was.
    let mut secant: Option<(f64, Vec<f64>, Vec<Vector3<f64>>)> = None;
    let (mut lambda, mut step) = (0.0, MAX_STEP);
    // Tip contacts about to close on the next step, from the tip's gaps at the last two.
    let mut near: Vec<(usize, Site, f64)> = Vec::new();
    let mut tip_gaps: Vec<f64> = Vec::new();
    let mut attempts = 0;
    while lambda < 1.0 {
        // (The load steps of the options bound the steps tried, accepted or halved.)
        attempts += 1;
        if attempts > opts.max_load_steps {
            (p.path, p.approach) = (None, None);
            return Err(x);
        }
        let next = (lambda + step).min(1.0);
        let sig = signature(p);
        let along = secant.as_ref().filter(|(_, xb, _)| xb.len() == x.len());
        let start: Vec<f64> = match along {
            Some((h, xb, _)) => {
                let r = (next - lambda) / h;
                x.iter().zip(xb).map(|(a, b)| a + (a - b) * r).collect()
            }
            None => x.clone(),
        };
        p.set_load(next);
        p.last = None;
        let saved = p.active.clone();
        let mut solved = active_set(p, &start, opts, effort);
        if solved.is_none() && !faithful && along.is_some() {
            // Off the secant's prediction: from the last step's state.
            p.active.clone_from(&saved);
            p.last = None;
            solved = active_set(p, &x, opts, effort);
        }
        if solved.is_none() && !near.is_empty() {
            // The tip about to touch (a belt reaching it, an arm closing on an obstacle):
            // held from the start of the step.
            p.active.clone_from(&saved);
            p.last = None;
            let mut xt = x.clone();
            for &(o, _, _) in &near {
                xt = belt::anticipate_tip(p, xt, o);
            }
            solved = active_set(p, &xt, opts, effort);
        }
        let shape = solved.and_then(|xn| {
            let shape = positions_at(p.last.as_ref()?, s);
            let moved = (&previous[..], &shape[..]);
            let on_branch = match along {
                Some((h, _, before))
                    if faithful && next - lambda > SNAP_STEP && signature(p) == sig =>
                {
                    on_secant(&shape, (before, &previous), (next - lambda) / h, l)
                }
                _ => true,
            };
            (on_branch && !too_far(p, moved, radius) && !crossed(p, moved, radius, depth))
                .then_some((xn, shape))
        });
        let shape = shape.or_else(|| {
            // The last step before the stepping stops, and the only one where stepping for
            // obstacles crossed on the way snaps.
            let last = 0.5 * step < MIN_LOAD_INCREMENT;
            if !(last || faithful && next - lambda <= SNAP_STEP) {
                return None;
            }
            // (At the last step, also after sliding off the obstacles it touched.)
            let before = along.filter(|_| last).map(|(_, _, b)| &b[..]);
            snap(p, (s, radius, depth), (before, &previous), opts, effort)
        });
        match shape {
            Some((xn, shape)) => {
                effort.load_steps += 1;
                near = closing_tips(p, &mut tip_gaps);
                p.approach = p.last.as_ref().map(|pass| pass.nodes.clone());
                secant = (signature(p) == sig).then(|| {
                    (
                        next - lambda,
                        std::mem::take(&mut x),
                        std::mem::take(&mut previous),
                    )
                });
                (x, previous, lambda) = (xn, shape, next);
                p.from = lambda;
                step = (2.0 * step).min(MAX_STEP);
            }
            None => {
                p.active = saved;
                step *= 0.5;
                if step < MIN_LOAD_INCREMENT {
                    (p.path, p.approach) = (None, None);
                    return Err(x);
                }
            }
        }
    }
    (p.path, p.approach) = (None, None);
    Ok(x)
}
