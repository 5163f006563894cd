//! Gaps between the nodes of a march: an obstacle thinner than the spacing of the nodes (a
//! wire, a thin plate) can lie between two nodes whose own gaps are positive while the rod
//! runs through it.
//!
//! Between two consecutive nodes the backbone is the cubic Hermite arc through their
//! positions with the tangents `Δs R e₃` (exact to the strains, `O(ε Δs)`, and to `O(Δs⁴)`
//! in the shape), and the rod's radius is linear in between. The gap along the arc,
//! `g(t) = d(c(t)) - r(t)` with `d` the obstacle's signed distance (1-Lipschitz in space),
//! is Lipschitz in `t` with the constant `3 max |Qₖ₊₁ - Qₖ| + |Δr|` over the Bézier control
//! points `Qₖ` of the arc (its derivative lies in their hull). Branch and bound on that
//! constant certifies that the gap stays above a threshold or finds where it is least.
//!
//! Next to a contact the gap is near zero over much of the cell and the Lipschitz bound
//! needs many evaluations to certify it (up to the budget, and a rod lying across a sphere
//! has such a cell on each side of its contact). For a convex obstacle (all but a triangle
//! mesh) the signed distance lies above its tangent plane at any point, so on a part
//! `[t₀, t₁]` of the arc `d(c(t)) >= d(c(tₖ)) + n(tₖ)·(c(t) - c(tₖ))` at either end `tₖ`, and
//! `n·c(t)` is at least the least of `n·Pⱼ` over the control points `Pⱼ` of that part: a
//! bound of second order in the part's length where the rod runs along the surface.

use nalgebra::Vector3;

use super::obstacle::Obstacle;
use crate::cosserat::equations::{rot, v3};

/// Most gap evaluations per cell.
const MAX_EVALUATIONS: usize = 200;

/// One end of a cell: the backbone point (m), its tangent times the cell length (m), and the
/// rod's outer radius there (m).
#[derive(Debug, Clone, Copy)]
pub(super) struct CellEnd {
    pub point: Vector3<f64>,
    pub tangent: Vector3<f64>,
    pub radius: f64,
}

impl CellEnd {
    /// The end of a cell of length `h` (m) at a node of state `y` (position, then rotation
    /// rows), the rod's radius there `radius` (m): tangent `h R e₃`.
    pub fn at_node(y: &[f64], h: f64, radius: f64) -> Self {
        Self {
            point: v3(y, 0),
            tangent: rot(y) * Vector3::z() * h,
            radius,
        }
    }
}

/// The point at fraction `t ∈ [0, 1]` of the cubic Hermite arc from `a` to `b` (its
/// Bézier control points `q`).
fn bezier(q: &[Vector3<f64>; 4], t: f64) -> Vector3<f64> {
    let s = 1.0 - t;
    q[0] * (s * s * s) + q[1] * (3.0 * s * s * t) + q[2] * (3.0 * s * t * t) + q[3] * (t * t * t)
}

/// The Bézier control points of the cubic Hermite arc from `a` to `b`.
fn control_points(a: &CellEnd, b: &CellEnd) -> [Vector3<f64>; 4] {
    [
        a.point,
        a.point + a.tangent / 3.0,
        b.point - b.tangent / 3.0,
        b.point,
    ]
}

/// The point at fraction `t ∈ [0, 1]` of the cubic Hermite arc from `a` to `b` (m).
pub(super) fn arc_point(a: &CellEnd, b: &CellEnd, t: f64) -> Vector3<f64> {
    bezier(&control_points(a, b), t)
}

/// The least gap (m) of `obstacle` along the arc from `a` to `b` if it falls below
/// `threshold` (m, negative), as `(t, gap)` with `t ∈ [0, 1]` the fraction of the cell;
/// `None` if the gap stays above `threshold` everywhere on the arc (`ga`, `gb`: the gaps at
/// the two ends).
pub(super) fn least_gap_in_cell(
    obstacle: &Obstacle,
    (a, ga): (&CellEnd, f64),
    (b, gb): (&CellEnd, f64),
    threshold: f64,
) -> Option<(f64, f64)> {
    let convex = !matches!(obstacle.shape(), Obstacle::Mesh(_));
    search(obstacle, (a, ga), (b, gb), threshold, convex).0
}

/// One end of a part of the arc: `t`, the gap there, and the tangent plane's offset
/// `d - n·c` and normal `n` (convex obstacles only).
#[derive(Clone, Copy)]
struct Sample {
    t: f64,
    gap: f64,
    plane: Option<(f64, Vector3<f64>)>,
}

/// [`least_gap_in_cell`] and the gap evaluations it took; `convex`: whether the obstacle's
/// tangent planes bound it.
fn search(
    obstacle: &Obstacle,
    (a, ga): (&CellEnd, f64),
    (b, gb): (&CellEnd, f64),
    threshold: f64,
    convex: bool,
) -> (Option<(f64, f64)>, usize) {
    let q = control_points(a, b);
    let speed = 3.0 * (0..3).map(|k| (q[k + 1] - q[k]).norm()).fold(0.0, f64::max);
    let lipschitz = speed + (b.radius - a.radius).abs();
    let radius = |t: f64| a.radius + (b.radius - a.radius) * t;
    let sample = |t: f64, known: Option<f64>| {
        let c = bezier(&q, t);
        let (d, n) = obstacle.distance(&c);
        Sample {
            t,
            gap: known.unwrap_or(d - radius(t)),
            plane: convex.then(|| (d - n.dot(&c), n)),
        }
    };
    let bound = |x: &Sample, y: &Sample| {
        let lipschitz = 0.5 * (x.gap + y.gap - lipschitz * (y.t - x.t));
        let r = radius(x.t).max(radius(y.t));
        [x, y]
            .iter()
            .filter_map(|e| e.plane)
            .map(|(offset, n)| offset + least_along(&q, &n, x.t, y.t) - r)
            .fold(lipschitz, f64::max)
    };
    let (s0, s1) = (sample(0.0, Some(ga)), sample(1.0, Some(gb)));
    let mut evaluations = usize::from(convex) * 2;
    let mut best = if ga <= gb { (0.0, ga) } else { (1.0, gb) };
    // Parts (start, end, bound): refined best first (least bound), until no part may hold
    // a gap below the threshold (certified: nothing is below it), or the budget runs out.
    // (Once a gap below the threshold is found, the parts at it have bounds below it too:
    // the search then spends its budget locating the least gap.)
    let first = bound(&s0, &s1);
    if first >= threshold {
        return (None, evaluations);
    }
    let mut open = vec![(s0, s1, first)];
    for _ in 0..MAX_EVALUATIONS {
        let Some(k) = (0..open.len()).min_by(|&i, &j| open[i].2.total_cmp(&open[j].2)) else {
            break;
        };
        let (x, y, lb) = open.swap_remove(k);
        if lb >= threshold {
            break;
        }
        let m = sample(0.5 * (x.t + y.t), None);
        evaluations += 1;
        if m.gap < best.1 {
            best = (m.t, m.gap);
        }
        open.push((x, m, bound(&x, &m)));
        open.push((m, y, bound(&m, &y)));
    }
    ((best.1 < threshold).then_some(best), evaluations)
}

/// The least of `n·Pⱼ` over the control points `Pⱼ` of the part `[t0, t1]` of the cubic
/// Bézier arc `q` (their blossoms), a lower bound of `n·c(t)` on the part.
fn least_along(q: &[Vector3<f64>; 4], n: &Vector3<f64>, t0: f64, t1: f64) -> f64 {
    let p = [n.dot(&q[0]), n.dot(&q[1]), n.dot(&q[2]), n.dot(&q[3])];
    let blossom = |u: [f64; 3]| {
        let lerp = |x: f64, y: f64, t: f64| x + (y - x) * t;
        let a = [
            lerp(p[0], p[1], u[0]),
            lerp(p[1], p[2], u[0]),
            lerp(p[2], p[3], u[0]),
        ];
        let b = [lerp(a[0], a[1], u[1]), lerp(a[1], a[2], u[1])];
        lerp(b[0], b[1], u[2])
    };
    [
        blossom([t0, t0, t0]),
        blossom([t0, t0, t1]),
        blossom([t0, t1, t1]),
        blossom([t1, t1, t1]),
    ]
    .into_iter()
    .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn straight(z0: f64, z1: f64, r: f64) -> (CellEnd, CellEnd) {
        let t = Vector3::new(0.0, 0.0, z1 - z0);
        let end = |z| CellEnd {
            point: Vector3::new(0.0, 0.0, z),
            tangent: t,
            radius: r,
        };
        (end(z0), end(z1))
    }

    /// A wire across a straight cell at 0.3 of it: found there, with its closed-form gap
    /// (distance of the axis minus both radii), though both ends are clear of it.
    #[test]
    fn a_wire_inside_a_cell_is_found_where_the_gap_is_least() {
        let (a, b) = straight(0.0, 0.01, 1e-3);
        let wire = Obstacle::capsule([5e-4, -1.0, 0.003], [5e-4, 1.0, 0.003], 2e-4).unwrap();
        let ga = wire.distance(&a.point).0 - a.radius;
        let gb = wire.distance(&b.point).0 - b.radius;
        assert!(ga > 0.0 && gb > 0.0);
        let (t, g) = least_gap_in_cell(&wire, (&a, ga), (&b, gb), -1e-6).unwrap();
        assert!((t - 0.3).abs() < 1e-3, "t = {t}");
        let exact = 5e-4 - 2e-4 - 1e-3;
        assert!((g - exact).abs() < 1e-9, "gap {g:e} vs {exact:e}");
    }

    /// A straight cell of 5 mm from a contact on the top of a sphere (radius 10 mm; rod
    /// radius 1 mm): the gap grows from zero as `x² / 2 (R + r)`, and the Lipschitz bound
    /// alone spends about 50 evaluations to certify it above -5 µm; the tangent planes of the
    /// convex sphere certify it in a few.
    #[test]
    fn a_cell_along_a_sphere_from_its_contact_is_certified_in_a_few_evaluations() {
        let (r, big, h) = (1e-3, 0.01, 5e-3);
        let sphere = Obstacle::sphere([0.0, 0.0, -big], big).unwrap();
        let t = Vector3::new(h, 0.0, 0.0);
        let end = |x: f64| CellEnd {
            point: Vector3::new(x, 0.0, r),
            tangent: t,
            radius: r,
        };
        let (a, b) = (end(0.0), end(h));
        let ga = sphere.distance(&a.point).0 - r;
        let gb = sphere.distance(&b.point).0 - r;
        assert!(ga.abs() < 1e-15 && gb > 0.0);
        let (found, evaluations) = search(&sphere, (&a, ga), (&b, gb), -1e-3 * h, true);
        let (alone, lipschitz) = search(&sphere, (&a, ga), (&b, gb), -1e-3 * h, false);
        println!("certified in {evaluations} evaluations ({lipschitz} by the Lipschitz bound)");
        assert!(found.is_none() && alone.is_none());
        assert!(evaluations <= 6, "{evaluations} evaluations");
        assert!(lipschitz >= 30, "{lipschitz} evaluations");
    }

    /// A chord of the sphere whose two ends lie on its surface (inflated by the rod's radius):
    /// found in the middle, at the sagitta's depth `sqrt(ρ² - (h/2)²) - ρ`, `ρ = R + r`.
    #[test]
    fn a_chord_of_a_sphere_is_found_at_its_sagitta() {
        let (r, big, h) = (1e-3, 0.01, 5e-3);
        let rho: f64 = big + r;
        let z = (rho * rho - 0.25 * h * h).sqrt();
        let sphere = Obstacle::sphere([0.0, 0.0, -z], big).unwrap();
        let t = Vector3::new(h, 0.0, 0.0);
        let end = |x: f64| CellEnd {
            point: Vector3::new(x, 0.0, 0.0),
            tangent: t,
            radius: r,
        };
        let (a, b) = (end(-0.5 * h), end(0.5 * h));
        let (t, g) = least_gap_in_cell(&sphere, (&a, 0.0), (&b, 0.0), -1e-3 * h).unwrap();
        let exact = z - rho;
        assert!((t - 0.5).abs() < 1e-6, "t = {t}");
        assert!((g - exact).abs() < 1e-15, "gap {g:e} vs {exact:e}");
    }

    /// Clear of the obstacle everywhere (the wire 0.1 mm beyond the surface): certified,
    /// within the evaluation budget.
    #[test]
    fn a_clear_cell_is_certified() {
        let (a, b) = straight(0.0, 0.01, 1e-3);
        let wire = Obstacle::capsule([1.3e-3, -1.0, 0.003], [1.3e-3, 1.0, 0.003], 2e-4).unwrap();
        let ga = wire.distance(&a.point).0 - a.radius;
        let gb = wire.distance(&b.point).0 - b.radius;
        assert!(least_gap_in_cell(&wire, (&a, ga), (&b, gb), -1e-6).is_none());
    }
}
