//! Small helpers on the rotation group SO(3): the hat map, re-orthonormalisation and
//! rotation-matrix ↔ quaternion conversion.
//!
//! Rotation matrices map body-frame components to world-frame components (`x_world = R x_body`);
//! quaternions are stored scalar-last, `[x, y, z, w]` (the order of SciPy's `Rotation.as_quat`),
//! with `w >= 0`.

use nalgebra::{Matrix3, Vector3};

/// The hat map `û`: the skew-symmetric matrix with `û a = u × a`.
#[inline]
pub fn hat(u: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -u.z, u.y, u.z, 0.0, -u.x, -u.y, u.x, 0.0)
}

/// One Newton–Schulz step towards the nearest rotation, `R (3 I - RᵀR) / 2`.
///
/// For `R` within `δ` of orthonormal (`|RᵀR - I| = δ`) the result is within `O(δ²)`; the
/// integrators call it after every step, where `δ` is the local truncation error.
#[inline]
pub fn reorthonormalise(r: &Matrix3<f64>) -> Matrix3<f64> {
    let rtr = r.tr_mul(r);
    r * (Matrix3::identity() * 1.5 - rtr * 0.5)
}

/// Unit quaternion `[x, y, z, w]` (scalar last, `w >= 0`) of a rotation matrix
/// (Shepperd's method, stable for every rotation).
pub fn quaternion_xyzw(r: &Matrix3<f64>) -> [f64; 4] {
    let tr = r[(0, 0)] + r[(1, 1)] + r[(2, 2)];
    let q = if tr > r[(0, 0)].max(r[(1, 1)]).max(r[(2, 2)]) {
        let w4 = 2.0 * (1.0 + tr).sqrt();
        [
            (r[(2, 1)] - r[(1, 2)]) / w4,
            (r[(0, 2)] - r[(2, 0)]) / w4,
            (r[(1, 0)] - r[(0, 1)]) / w4,
            0.25 * w4,
        ]
    } else if r[(0, 0)] >= r[(1, 1)] && r[(0, 0)] >= r[(2, 2)] {
        let x4 = 2.0 * (1.0 + r[(0, 0)] - r[(1, 1)] - r[(2, 2)]).sqrt();
        [
            0.25 * x4,
            (r[(0, 1)] + r[(1, 0)]) / x4,
            (r[(0, 2)] + r[(2, 0)]) / x4,
            (r[(2, 1)] - r[(1, 2)]) / x4,
        ]
    } else if r[(1, 1)] >= r[(2, 2)] {
        let y4 = 2.0 * (1.0 + r[(1, 1)] - r[(0, 0)] - r[(2, 2)]).sqrt();
        [
            (r[(0, 1)] + r[(1, 0)]) / y4,
            0.25 * y4,
            (r[(1, 2)] + r[(2, 1)]) / y4,
            (r[(0, 2)] - r[(2, 0)]) / y4,
        ]
    } else {
        let z4 = 2.0 * (1.0 + r[(2, 2)] - r[(0, 0)] - r[(1, 1)]).sqrt();
        [
            (r[(0, 2)] + r[(2, 0)]) / z4,
            (r[(1, 2)] + r[(2, 1)]) / z4,
            0.25 * z4,
            (r[(1, 0)] - r[(0, 1)]) / z4,
        ]
    };
    let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let sign = if q[3] < 0.0 { -1.0 } else { 1.0 } / norm;
    [q[0] * sign, q[1] * sign, q[2] * sign, q[3] * sign]
}

/// Rotation matrix of a rotation vector `θ` (axis `θ/|θ|`, angle `|θ|` rad), by Rodrigues'
/// formula with series expansions near zero.
pub fn exp_so3(theta: &Vector3<f64>) -> Matrix3<f64> {
    let a2 = theta.norm_squared();
    let (sa, ca) = if a2 < 1e-8 {
        (
            1.0 - a2 / 6.0 * (1.0 - a2 / 20.0),
            0.5 - a2 / 24.0 * (1.0 - a2 / 30.0),
        )
    } else {
        let a = a2.sqrt();
        (a.sin() / a, (1.0 - a.cos()) / a2)
    };
    let k = hat(theta);
    Matrix3::identity() + k * sa + k * k * ca
}

/// Rotation vector `θ` of a rotation matrix (`exp_so3(θ) = r`, `|θ| <= π`), accurate to
/// round-off near the identity (the angle from `atan2`, not `acos`).
pub fn log_so3(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = 0.5
        * Vector3::new(
            r[(2, 1)] - r[(1, 2)],
            r[(0, 2)] - r[(2, 0)],
            r[(1, 0)] - r[(0, 1)],
        );
    let s = v.norm();
    let c = 0.5 * (r.trace() - 1.0);
    let angle = s.atan2(c);
    if s > 1e-6 * angle.max(1e-300) && angle < 3.0 {
        return v * (angle / s);
    }
    if angle < 3.0 {
        // Near the identity: θ / sin θ = 1 + θ²/6 + ...
        return v * (1.0 + s * s / 6.0);
    }
    // Near π: the axis from the symmetric part, R + Rᵀ = 2 c I + 2 (1 - c) a aᵀ.
    let b = (r + r.transpose()) * 0.5 - Matrix3::identity() * c;
    let k = (0..3)
        .max_by(|&i, &j| b[(i, i)].total_cmp(&b[(j, j)]))
        .unwrap_or(0);
    let mut a = b.column(k).into_owned();
    a /= a.norm().max(1e-300);
    if a.dot(&v) < 0.0 {
        a = -a;
    }
    a * angle
}

/// Largest entry of `|RᵀR - I|` and `|det R - 1|`: how far `r` is from a rotation.
pub fn orthonormality_error(r: &Matrix3<f64>) -> f64 {
    let e = (r.tr_mul(r) - Matrix3::identity()).amax();
    e.max((r.determinant() - 1.0).abs())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn log_inverts_exp() {
        for theta in [
            Vector3::new(1e-9, -2e-9, 3e-10),
            Vector3::new(0.3, -1.2, 0.5),
            Vector3::new(0.0, 0.0, 3.1),
            Vector3::new(1.0, 1.0, 1.0).normalize() * (std::f64::consts::PI - 2.7e-6),
        ] {
            let back = log_so3(&exp_so3(&theta));
            assert!(
                (back - theta).amax() <= 1e-12 * theta.norm().max(1e-9),
                "{theta:?} -> {back:?}"
            );
        }
    }

    #[test]
    fn hat_is_cross_product() {
        let u = Vector3::new(0.3, -1.2, 2.0);
        let a = Vector3::new(-0.7, 0.4, 1.1);
        assert!((hat(&u) * a - u.cross(&a)).amax() < 1e-15);
    }

    #[test]
    fn quaternion_round_trip_matches_nalgebra() {
        for th in [
            Vector3::new(0.1, 0.2, -0.3),
            Vector3::new(3.0, 0.1, 0.0),
            Vector3::new(0.0, -3.1, 0.2),
            Vector3::new(0.01, 0.0, 3.13),
        ] {
            let r = exp_so3(&th);
            let q = quaternion_xyzw(&r);
            let uq = nalgebra::UnitQuaternion::from_scaled_axis(th);
            let s = if uq.w < 0.0 { -1.0 } else { 1.0 };
            assert!((q[0] - s * uq.i).abs() < 1e-14);
            assert!((q[1] - s * uq.j).abs() < 1e-14);
            assert!((q[2] - s * uq.k).abs() < 1e-14);
            assert!((q[3] - s * uq.w).abs() < 1e-14);
            assert!((uq.to_rotation_matrix().matrix() - r).amax() < 1e-14);
        }
    }

    #[test]
    fn newton_schulz_squares_the_error() {
        let r = exp_so3(&Vector3::new(0.4, -0.2, 0.9)) * 1.0001;
        let e0 = orthonormality_error(&r);
        let e1 = orthonormality_error(&reorthonormalise(&r));
        assert!(e1 < 10.0 * e0 * e0, "{e0} {e1}");
    }
}
