//! The residual rows of the constrained problem: the tip rows (pose error of the held
//! directions, wrench balance of the free ones) and their derivative, the rows of each
//! contact (gap, gap slope, tangential force), and the gaps and normal forces the active
//! set reads from the last pass.

use nalgebra::{Matrix3, UnitQuaternion, Vector3, Vector6};

use super::constraint::TipConstraint;
use super::problem::{Active, Constrained, Site};
use super::sweep::{least_gap_in_cell, CellEnd};
use super::{obstacle_normal_basis, ContactState};
use crate::cosserat::equations::{v3, Evaluator, STATE};

/// The gap at a node of the last pass: `(node index, s (m), gap (m), outward normal)`.
pub(super) type GapSample = (usize, f64, f64, Vector3<f64>);

/// Normal forces, normal, arc length and point of each active contact at `x`.
pub(super) type Forces = Vec<(f64, Vector3<f64>, f64, Vector3<f64>)>;

/// Where an active contact sits on a march: its arc length `s` (m) and the states and
/// intervals of the first node at `s` (before the jump of the contact force) and of the last
/// (after it).
#[derive(Clone, Copy)]
pub(super) struct AtContact<'y> {
    pub(super) s: f64,
    pub(super) first: (&'y [f64; STATE], usize),
    pub(super) last: (&'y [f64; STATE], usize),
}

impl Constrained<'_> {
    /// The target position and rotation of the tip at the current load factor.
    fn target(&self, c: &TipConstraint) -> (Vector3<f64>, Matrix3<f64>) {
        let l = self.load;
        let p = self.start.0 + (c.pose.position() - self.start.0) * l;
        let q0 = UnitQuaternion::from_matrix(&self.start.1);
        let q1 = UnitQuaternion::from_matrix(&c.pose.rotation());
        let q = q0
            .try_slerp(&q1, l, 1e-12)
            .unwrap_or(if l < 0.5 { q0 } else { q1 });
        (p, *q.to_rotation_matrix().matrix())
    }

    /// The six tip rows at the tip pose `(p, r)` with shooting residual `res`.
    pub(super) fn tip_rows(
        &self,
        res: &Vector6<f64>,
        p: &Vector3<f64>,
        r: &Matrix3<f64>,
    ) -> [f64; 6] {
        let Some(c) = &self.tip else {
            return std::array::from_fn(|k| res[k]);
        };
        let (pt, rt) = self.target(c);
        let frame = c.pose.rotation();
        let l = self.model.length();
        let dp = frame.tr_mul(&(p - pt)) / l;
        let f = frame.tr_mul(&res.fixed_rows::<3>(0).into_owned());
        let mut out = [0.0; 6];
        for k in 0..3 {
            out[k] = if c.held[k] { dp[k] } else { f[k] };
        }
        let m = res.fixed_rows::<3>(3).into_owned();
        match c.rotations_held() {
            3 => {
                let a = rt.tr_mul(r);
                out[3] = 0.5 * (a[(2, 1)] - a[(1, 2)]);
                out[4] = 0.5 * (a[(0, 2)] - a[(2, 0)]);
                out[5] = 0.5 * (a[(1, 0)] - a[(0, 1)]);
            }
            2 => {
                let d = rt.tr_mul(&r.column(2).into_owned());
                out[3] = -d.y;
                out[4] = d.x;
                out[5] = rt.tr_mul(&m).z;
            }
            _ => {
                let mm = frame.tr_mul(&m);
                out[3..6].copy_from_slice(mm.as_slice());
            }
        }
        out
    }

    /// The derivative of [`Self::tip_rows`] along a column: residual change `dres`, tip
    /// displacement `dp` and rotation `w` (world).
    pub(super) fn tip_rows_dot(
        &self,
        dres: &Vector6<f64>,
        dp: &Vector3<f64>,
        w: &Vector3<f64>,
        r: &Matrix3<f64>,
    ) -> [f64; 6] {
        let Some(c) = &self.tip else {
            return std::array::from_fn(|k| dres[k]);
        };
        let (_, rt) = self.target(c);
        let frame = c.pose.rotation();
        let l = self.model.length();
        let ddp = frame.tr_mul(dp) / l;
        let df = frame.tr_mul(&dres.fixed_rows::<3>(0).into_owned());
        let mut out = [0.0; 6];
        for k in 0..3 {
            out[k] = if c.held[k] { ddp[k] } else { df[k] };
        }
        let dm = dres.fixed_rows::<3>(3).into_owned();
        match c.rotations_held() {
            3 => {
                let da = rt.tr_mul(&(crate::math::so3::hat(w) * r));
                out[3] = 0.5 * (da[(2, 1)] - da[(1, 2)]);
                out[4] = 0.5 * (da[(0, 2)] - da[(2, 0)]);
                out[5] = 0.5 * (da[(1, 0)] - da[(0, 1)]);
            }
            2 => {
                let dd = rt.tr_mul(&w.cross(&r.column(2).into_owned()));
                out[3] = -dd.y;
                out[4] = dd.x;
                out[5] = rt.tr_mul(&dm).z;
            }
            _ => {
                let mm = frame.tr_mul(&dm);
                out[3..6].copy_from_slice(mm.as_slice());
            }
        }
        out
    }
    /// The residual rows of the active contact `a` at `at` (arc length `s`, m) with scaled
    /// force `f`, from the states (and intervals) of the first node at `s` (before the jump of
    /// the force) and the last (after it): the gap over `L` (relaxed by `mu` from its value when
    /// added), for a contact inside the rod the slope of the gap, and the force's two
    /// components along the obstacle's surface. `ev` are scratch evaluators of the contact
    /// model, one per side of the contact (so that each local solve starts from the last on
    /// its side).
    pub(super) fn contact_rows(
        &self,
        ev: &mut [Evaluator<'_, '_>; 2],
        a: &Active,
        at: AtContact<'_>,
        f: &Vector3<f64>,
        mu: f64,
        rows: &mut Vec<f64>,
    ) {
        let AtContact { s, first, last } = at;
        let l = self.model.length();
        let ob = &self.obstacles[a.obstacle];
        let props = self.model.rod().section_at(s);
        let (d, n) = ob.distance(&v3(first.0, 0));
        let g = d - props.radius;
        if a.probe {
            // The rod without the contact: its normal force held at zero.
            rows.push(f.dot(&n));
        } else {
            rows.push((g - (1.0 - mu) * a.g0) / l);
        }
        if a.site != Site::Tip {
            // A point contact sits at the kink of the gap (the shear jumps with the force):
            // the mean slope of its two sides vanishes; the segment of an interval lies flat
            // from just after its edge.
            let sides = if a.site == Site::Interval {
                [last, last]
            } else {
                [first, last]
            };
            let mut slope = 0.0;
            for (ev, (y, interval)) in ev.iter_mut().zip(sides) {
                ev.enter_interval(interval);
                let mut dy = [0.0; STATE];
                ev.rhs_into::<STATE>(s, y, &mut dy);
                slope += 0.5 * n.dot(&v3(&dy, 0));
            }
            let dg = slope - props.radius_rate;
            rows.push(dg - (1.0 - mu) * a.dg0);
        }
        if a.state == ContactState::Frictionless {
            let (t1, t2) = obstacle_normal_basis(&n);
            rows.push(f.dot(&t1));
            rows.push(f.dot(&t2));
        } else {
            self.friction_rows(a, s, first.0, f, mu, rows);
        }
    }

    /// The gap (m) and outward normal of obstacle `o` at every node of the last pass (first
    /// copy of a break).
    pub(super) fn gaps(&self, o: usize) -> Vec<GapSample> {
        let Some(pass) = &self.last else {
            return Vec::new();
        };
        let mut out: Vec<GapSample> = Vec::new();
        for (j, n) in pass.nodes.iter().enumerate() {
            if out.last().is_some_and(|l| l.1 == n.s) {
                continue;
            }
            let (d, normal) = self.obstacles[o].distance(&v3(&n.y, 0));
            let r = pass.model.rod().section_at(n.s).radius;
            out.push((j, n.s, d - r, normal));
        }
        out
    }

    /// The arc length (m) where the rod's surface runs deepest into obstacle `o` between two
    /// consecutive nodes of the last pass whose own gaps `(j, s, gap, _)` do not show it (an
    /// obstacle thinner than the node spacing), if it runs in by more than `penetration` and a
    /// thousandth of the cell ([`sweep`](super::sweep)).
    pub(super) fn penetration_in_cell(
        &self,
        o: usize,
        (a, b): (&GapSample, &GapSample),
        penetration: f64,
    ) -> Option<f64> {
        let pass = self.last.as_ref()?;
        let h = b.1 - a.1;
        let end = |j: usize, s: f64| {
            CellEnd::at_node(&pass.nodes[j].y, h, pass.model.rod().section_at(s).radius)
        };
        let threshold = -penetration.max(1e-3 * h);
        let (ea, eb) = (end(a.0, a.1), end(b.0, b.1));
        least_gap_in_cell(&self.obstacles[o], (&ea, a.2), (&eb, b.2), threshold)
            .map(|(t, _)| a.1 + t * h)
    }

    /// The normal force (N, signed) and normal of each active contact at `x` (last pass).
    pub(super) fn normal_forces(&self, x: &[f64]) -> Forces {
        let Some(pass) = &self.last else {
            return Vec::new();
        };
        let l = self.model.length();
        let fs = self.model.force_scale();
        self.active
            .iter()
            .zip(self.offsets())
            .enumerate()
            .map(|(i, (a, o))| {
                let (s, k) = match a.site {
                    Site::Tip => (l, o),
                    Site::Interior | Site::Interval => (x[o] * l, o + 1),
                    Site::Belt | Site::BeltTip => {
                        // The total of its pressure, along the normal where it is largest.
                        let held = pass.held.get(i).and_then(Option::as_ref);
                        let total = held.map_or(0.0, |h| h.total());
                        let n = held
                            .and_then(|h| h.peak())
                            .map_or(Vector3::z(), |h| h.normal);
                        let p = held
                            .and_then(|h| h.samples.first())
                            .map_or(Vector3::zeros(), |h| h.point);
                        return (total, n, x[o] * l, p);
                    }
                };
                let node = pass
                    .nodes
                    .iter()
                    .find(|n| n.s == s)
                    .unwrap_or(&pass.nodes[0]);
                let p = v3(&node.y, 0);
                let (_, n) = self.obstacles[a.obstacle].distance(&p);
                let f = Vector3::new(x[k], x[k + 1], x[k + 2]) * fs;
                (f.dot(&n), n, s, p)
            })
            .collect()
    }
}
