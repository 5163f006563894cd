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
    let q = control_points(a, b);
    let speed = 3.0 * (0..3).map(|k| (q[k + 1] - q[k]).norm()).fold(0.0, f64::max);
    let lipschitz = speed + (b.radius - a.radius).abs();
    let gap = |t: f64| obstacle.distance(&bezier(&q, t)).0 - (a.radius + (b.radius - a.radius) * t);
    let bound = |t0: f64, g0: f64, t1: f64, g1: f64| 0.5 * (g0 + g1 - lipschitz * (t1 - t0));
    let mut best = if ga <= gb { (0.0, ga) } else { (1.0, gb) };
    // Intervals (t0, g0, t1, g1, bound): refined best first (least bound), until no interval
    // may hold a gap below the threshold (certified: nothing is below it), or the budget
    // runs out. (Once a gap below the threshold is found, the intervals at it have bounds
    // below it too: the search then spends its budget locating the least gap.)
    let first = bound(0.0, ga, 1.0, gb);
    if first >= threshold {
        return None;
    }
    let mut open = vec![(0.0, ga, 1.0, gb, first)];
    for _ in 0..MAX_EVALUATIONS {
        let Some(k) = (0..open.len()).min_by(|&i, &j| open[i].4.total_cmp(&open[j].4)) else {
            break;
        };
        let (t0, g0, t1, g1, lb) = open.swap_remove(k);
        if lb >= threshold {
            break;
        }
        let tm = 0.5 * (t0 + t1);
        let gm = gap(tm);
        if gm < best.1 {
            best = (tm, gm);
        }
        open.push((t0, g0, tm, gm, bound(t0, g0, tm, gm)));
        open.push((tm, gm, t1, g1, bound(tm, gm, t1, g1)));
    }
    (best.1 < threshold).then_some(best)
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
