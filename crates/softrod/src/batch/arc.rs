//! Values of a solved rod at chosen arc lengths, between the nodes of its integration mesh.
//!
//! A [`StaticsSolution`] is sampled at the mesh nodes. At an arc length `s` between two nodes
//! `s_j < s < s_{j+1}` of the same interval, each quantity is the cubic Hermite interpolant of
//! its node values and its exact derivatives, which the rod's equations give at every node:
//!
//! * position: `p' = R v`;
//! * orientation (unit quaternion `q = [x, y, z, w]`, the neighbour's sign aligned):
//!   `q' = ½ q ⊗ [u; 0]` (`R' = R û`), normalised after interpolation;
//! * the cumulative compliance integral of the integrated compliance
//!   (`crate::compliance`): `Q(s) = ∫₀ˢ Ad_{(R, p - p(0))} c Ad_{(R, p - p(0))}ᵀ dσ`, whose
//!   derivative is the integrand, and `C_world(s) = Ad_{(I, p(0) - p(s))} Q(s) Ad_{(I, ..)}ᵀ`.
//!
//! The interpolation error is `O(h⁴)` (`h` the node spacing), the order of the RK4 mesh and of
//! the compliance quadrature; at a node the node's own values are returned unchanged. At an
//! interval break (a node listed twice) the values after the jump are used: position,
//! orientation and compliance are continuous there.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector4};

use crate::compliance::{element_compliance, Compliance};
use crate::cosserat::statics::StaticsSolution;
use crate::math::se3::transform_compliance;

/// Where an arc length falls on the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// At node `j` (the last of the nodes with that arc length).
    Node(usize),
    /// Strictly between nodes `j` and `j + 1`.
    Between(usize),
    /// Outside `[s_0, s_last]` (or not finite).
    Outside,
}

/// Locates `s` among the non-decreasing node arc lengths `nodes`.
pub fn locate(nodes: &[f64], s: f64) -> Location {
    let n = nodes.len();
    if n == 0 || !s.is_finite() || s < nodes[0] || s > nodes[n - 1] {
        return Location::Outside;
    }
    let idx = nodes.partition_point(|&x| x <= s);
    if idx > 0 && nodes[idx - 1] == s {
        Location::Node(idx - 1)
    } else if idx > 0 && idx < n {
        Location::Between(idx - 1)
    } else {
        Location::Outside
    }
}

/// Cubic Hermite basis `(h00, h10, h01, h11)` at `τ ∈ [0, 1]` (the `h1*` are to be multiplied
/// by the interval length).
fn hermite(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        2.0 * t3 - 3.0 * t2 + 1.0,
        t3 - 2.0 * t2 + t,
        -2.0 * t3 + 3.0 * t2,
        t3 - t2,
    ]
}

fn matrix3(r: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::new(
        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
    )
}

/// Quaternion `[x, y, z, w]` of a body → world rotation, as a vector.
fn quat(q: &[f64; 4]) -> Vector4<f64> {
    Vector4::new(q[0], q[1], q[2], q[3])
}

/// `q' = ½ q ⊗ [u; 0]` for the body bending/twist rate `u`.
fn quat_rate(q: &Vector4<f64>, u: &Vector3<f64>) -> Vector4<f64> {
    let v = Vector3::new(q[0], q[1], q[2]);
    let w = q[3];
    let d = u * w + v.cross(u);
    Vector4::new(0.5 * d.x, 0.5 * d.y, 0.5 * d.z, -0.5 * v.dot(u))
}

/// Rotation matrix (body → world) of a unit quaternion `[x, y, z, w]`.
pub fn rotation_of(q: &[f64; 4]) -> Matrix3<f64> {
    let [x, y, z, w] = *q;
    Matrix3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - z * w),
        2.0 * (x * z + y * w),
        2.0 * (x * y + z * w),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - x * w),
        2.0 * (x * z - y * w),
        2.0 * (y * z + x * w),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// Position (m, world) and unit quaternion `[x, y, z, w]` (`w >= 0`) at arc length `s`; NaN
/// outside the rod.
pub fn pose_at(solution: &StaticsSolution, s: f64) -> ([f64; 3], [f64; 4]) {
    match locate(&solution.s, s) {
        Location::Outside => ([f64::NAN; 3], [f64::NAN; 4]),
        Location::Node(j) => (solution.position[j], solution.quaternion[j]),
        Location::Between(j) => {
            let h = solution.s[j + 1] - solution.s[j];
            let b = hermite((s - solution.s[j]) / h);
            let tangent = |k: usize| matrix3(&solution.rotation[k]) * Vector3::from(solution.v[k]);
            let p = Vector3::from(solution.position[j]) * b[0]
                + tangent(j) * (b[1] * h)
                + Vector3::from(solution.position[j + 1]) * b[2]
                + tangent(j + 1) * (b[3] * h);
            let q0 = quat(&solution.quaternion[j]);
            let mut q1 = quat(&solution.quaternion[j + 1]);
            if q0.dot(&q1) < 0.0 {
                q1 = -q1;
            }
            let d0 = quat_rate(&q0, &Vector3::from(solution.u[j]));
            let d1 = quat_rate(&q1, &Vector3::from(solution.u[j + 1]));
            let q = (q0 * b[0] + d0 * (b[1] * h) + q1 * b[2] + d1 * (b[3] * h)).normalize();
            // The sign convention of the nodes' quaternions (w >= 0).
            let q = if q[3] < 0.0 { -q } else { q };
            ([p.x, p.y, p.z], [q[0], q[1], q[2], q[3]])
        }
    }
}

/// The integrated compliance of a solution at chosen arc lengths (see the module docs).
pub struct ComplianceAt<'a> {
    solution: &'a StaticsSolution,
    compliance: &'a Compliance,
    element: Vec<[f64; 6]>,
}

impl<'a> ComplianceAt<'a> {
    /// Prepares the interpolation of `compliance` (the integrated compliance of `solution`
    /// at every node, [`crate::compliance::compliance`]).
    pub fn new(solution: &'a StaticsSolution, compliance: &'a Compliance) -> Self {
        Self {
            solution,
            compliance,
            element: element_compliance(solution),
        }
    }

    fn offset(&self, k: usize) -> Vector3<f64> {
        Vector3::from(self.solution.position[k]) - Vector3::from(self.solution.position[0])
    }

    /// `Q(s_k)`, recovered from the world compliance at node `k`.
    fn cumulative(&self, k: usize) -> Matrix6<f64> {
        transform_compliance(
            &Matrix3::identity(),
            &self.offset(k),
            &self.compliance.world[k],
        )
    }

    /// `Q'(s_k)`: the integrand `Ad_{(R, p - p(0))} c Ad_{(R, p - p(0))}ᵀ` at node `k`.
    fn integrand(&self, k: usize) -> Matrix6<f64> {
        let c = Matrix6::from_diagonal(&nalgebra::Vector6::from(self.element[k]));
        transform_compliance(&matrix3(&self.solution.rotation[k]), &self.offset(k), &c)
    }

    /// World compliance `C_world(s)` (twist `[δp; δθ]` = C `[f; m]`, SI units) at `s`, given
    /// the position `p(s)` there ([`pose_at`]); NaN outside the rod.
    pub fn world(&self, s: f64, position: &[f64; 3]) -> Matrix6<f64> {
        match locate(&self.solution.s, s) {
            Location::Outside => Matrix6::repeat(f64::NAN),
            Location::Node(j) => self.compliance.world[j],
            Location::Between(j) => {
                let sn = &self.solution.s;
                let h = sn[j + 1] - sn[j];
                let b = hermite((s - sn[j]) / h);
                let q = self.cumulative(j) * b[0]
                    + self.integrand(j) * (b[1] * h)
                    + self.cumulative(j + 1) * b[2]
                    + self.integrand(j + 1) * (b[3] * h);
                let back = Vector3::from(self.solution.position[0]) - Vector3::from(*position);
                let c = transform_compliance(&Matrix3::identity(), &back, &q);
                (c + c.transpose()) * 0.5
            }
        }
    }

    /// Body compliance at `s` (node `j` exactly, else the world compliance rotated into the
    /// body axes of the orientation `quaternion` there).
    pub fn body(&self, s: f64, world: &Matrix6<f64>, quaternion: &[f64; 4]) -> Matrix6<f64> {
        match locate(&self.solution.s, s) {
            Location::Outside => Matrix6::repeat(f64::NAN),
            Location::Node(j) => self.compliance.body[j],
            Location::Between(_) => {
                let rt = rotation_of(quaternion).transpose();
                let c = transform_compliance(&rt, &Vector3::zeros(), world);
                (c + c.transpose()) * 0.5
            }
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::math::so3::quaternion_xyzw;

    #[test]
    fn locate_nodes_breaks_and_gaps() {
        let s = [0.0, 0.1, 0.2, 0.2, 0.3];
        assert_eq!(locate(&s, 0.0), Location::Node(0));
        assert_eq!(locate(&s, 0.05), Location::Between(0));
        assert_eq!(locate(&s, 0.2), Location::Node(3));
        assert_eq!(locate(&s, 0.25), Location::Between(3));
        assert_eq!(locate(&s, 0.3), Location::Node(4));
        assert_eq!(locate(&s, 0.31), Location::Outside);
        assert_eq!(locate(&s, -1e-9), Location::Outside);
        assert_eq!(locate(&s, f64::NAN), Location::Outside);
    }

    #[test]
    fn hermite_reproduces_cubics() {
        // f(t) = 1 + 2t - t² + 3t³ on [0.2, 0.7] from end values and slopes.
        let f = |t: f64| 1.0 + 2.0 * t - t * t + 3.0 * t.powi(3);
        let df = |t: f64| 2.0 - 2.0 * t + 9.0 * t * t;
        let (a, c) = (0.2, 0.7);
        let h = c - a;
        for k in 0..=10 {
            let t = a + h * k as f64 / 10.0;
            let b = hermite((t - a) / h);
            let v = f(a) * b[0] + df(a) * h * b[1] + f(c) * b[2] + df(c) * h * b[3];
            assert!((v - f(t)).abs() < 1e-14);
        }
    }

    #[test]
    fn quaternion_rate_matches_rotation_rate() {
        // R(s) = exp(s û) from R0: q(s) = q0 ⊗ [sin(|u|s/2) û; cos(|u|s/2)].
        let u = Vector3::new(0.3, -1.2, 0.5);
        let q0 = Vector4::new(0.1, 0.2, 0.3, 0.9).normalize();
        let qs = |s: f64| -> Vector4<f64> {
            let a: f64 = u.norm() * s / 2.0;
            let e = u.normalize() * a.sin();
            let (v0, w0) = (Vector3::new(q0[0], q0[1], q0[2]), q0[3]);
            let (v1, w1) = (e, a.cos());
            let v = v1 * w0 + v0 * w1 + v0.cross(&v1);
            Vector4::new(v.x, v.y, v.z, w0 * w1 - v0.dot(&v1))
        };
        let eps = 1e-6;
        let fd = (qs(eps) - qs(-eps)) / (2.0 * eps);
        assert!((fd - quat_rate(&q0, &u)).norm() < 1e-9);
        let r = rotation_of(&[q0[0], q0[1], q0[2], q0[3]]);
        let back = quaternion_xyzw(&r);
        for k in 0..4 {
            assert!((back[k] - q0[k]).abs() < 1e-15);
        }
    }
}
