//! Rigid transforms of twists, wrenches, compliances and stiffnesses: the one place that owns
//! the adjoint and the ordering of their components.
//!
//! # Convention (used by the whole crate)
//! * A **twist** (small displacement or velocity of a frame) is `t = [δp; δθ]`:
//!   translation of the frame's origin first, rotation vector second.
//! * A **wrench** is `w = [f; m]`: force first, moment about the frame's origin second.
//! * Their pairing `wᵀ t = f·δp + m·δθ` is the work; it does not depend on the frame.
//! * A pose `g = (R, p)` maps frame B to frame A (`x_A = R x_B + p`). The **adjoint**
//!   `Ad_g = [[R, p̂ R], [0, R]]` maps B-twists to A-twists: `t_A = Ad_g t_B`.
//!   Wrenches map with `Ad_g⁻ᵀ = [[R, 0], [p̂ R, R]]`: `w_A = Ad_g⁻ᵀ w_B`.
//! * A compliance (`t = C w`) maps as `C_A = Ad_g C_B Ad_gᵀ`, a stiffness (`w = K t`) as
//!   `K_A = Ad_g⁻ᵀ K_B Ad_g⁻¹`.
//!
//! Worked example (tested below, numbers in `docs/compliance.md`): frame B at `p = (0, 0, L)`
//! with the world axes (`R = I`). A force `f_x` at B is, at the world origin A, the force `f_x`
//! and the moment `p × f = (0, L f_x, 0)`. A rotation `δθ_y` of a body about B's origin moves
//! the body point at A by `δθ × (0 - p) = p × δθ = (-L δθ_y, 0, 0)`: the A-twist is
//! `[p × δθ; δθ]`, the top-right block `p̂ R` of `Ad_g`.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::math::so3::hat;

/// Adjoint `Ad_g = [[R, p̂ R], [0, R]]` of the pose `g = (R, p)` (twists `[δp; δθ]`).
#[inline]
pub fn adjoint(r: &Matrix3<f64>, p: &Vector3<f64>) -> Matrix6<f64> {
    let mut a = Matrix6::zeros();
    let pr = hat(p) * r;
    a.fixed_view_mut::<3, 3>(0, 0).copy_from(r);
    a.fixed_view_mut::<3, 3>(0, 3).copy_from(&pr);
    a.fixed_view_mut::<3, 3>(3, 3).copy_from(r);
    a
}

/// Inverse adjoint `Ad_g⁻¹ = Ad_{g⁻¹} = [[Rᵀ, -Rᵀ p̂], [0, Rᵀ]]`.
#[inline]
pub fn adjoint_inverse(r: &Matrix3<f64>, p: &Vector3<f64>) -> Matrix6<f64> {
    let rt = r.transpose();
    adjoint(&rt, &(-(rt * p)))
}

/// Wrench map `Ad_g⁻ᵀ = [[R, 0], [p̂ R, R]]`: `w_A = Ad_g⁻ᵀ w_B`.
#[inline]
pub fn wrench_adjoint(r: &Matrix3<f64>, p: &Vector3<f64>) -> Matrix6<f64> {
    adjoint_inverse(r, p).transpose()
}

/// The rotation-only adjoint `blockdiag(R, R)` (change of axes at a fixed point).
#[inline]
pub fn rotation_adjoint(r: &Matrix3<f64>) -> Matrix6<f64> {
    adjoint(r, &Vector3::zeros())
}

/// `t_A = Ad_g t_B`.
#[inline]
pub fn transform_twist(r: &Matrix3<f64>, p: &Vector3<f64>, t: &Vector6<f64>) -> Vector6<f64> {
    adjoint(r, p) * t
}

/// `w_A = Ad_g⁻ᵀ w_B`.
#[inline]
pub fn transform_wrench(r: &Matrix3<f64>, p: &Vector3<f64>, w: &Vector6<f64>) -> Vector6<f64> {
    wrench_adjoint(r, p) * w
}

/// `C_A = Ad_g C_B Ad_gᵀ` (compliance: twist = C wrench).
#[inline]
pub fn transform_compliance(r: &Matrix3<f64>, p: &Vector3<f64>, c: &Matrix6<f64>) -> Matrix6<f64> {
    let a = adjoint(r, p);
    a * c * a.transpose()
}

/// `K_A = Ad_g⁻ᵀ K_B Ad_g⁻¹` (stiffness: wrench = K twist).
#[inline]
pub fn transform_stiffness(r: &Matrix3<f64>, p: &Vector3<f64>, k: &Matrix6<f64>) -> Matrix6<f64> {
    let ai = adjoint_inverse(r, p);
    ai.transpose() * k * ai
}

/// The reciprocal-product matrix `Δ = [[0, I], [I, 0]]`: `t₁ᵀ Δ t₂` is the reciprocal product
/// of two twists, `wᵀ t` the work of a wrench on a twist.
pub fn delta() -> Matrix6<f64> {
    let mut d = Matrix6::zeros();
    for i in 0..3 {
        d[(i, i + 3)] = 1.0;
        d[(i + 3, i)] = 1.0;
    }
    d
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::math::so3::exp_so3;

    #[test]
    fn adjoint_is_a_group_homomorphism_and_preserves_work() {
        let (r1, p1) = (
            exp_so3(&Vector3::new(0.3, -0.2, 1.1)),
            Vector3::new(0.1, 2.0, -0.3),
        );
        let (r2, p2) = (
            exp_so3(&Vector3::new(-0.7, 0.4, 0.2)),
            Vector3::new(-1.0, 0.5, 0.7),
        );
        let a12 = adjoint(&(r1 * r2), &(r1 * p2 + p1));
        assert!((a12 - adjoint(&r1, &p1) * adjoint(&r2, &p2)).amax() < 1e-14);
        assert!(
            (adjoint(&r1, &p1) * adjoint_inverse(&r1, &p1) - Matrix6::identity()).amax() < 1e-14
        );
        let t = Vector6::new(0.1, -0.3, 0.2, 0.5, 0.05, -0.4);
        let w = Vector6::new(1.0, 2.0, -1.5, 0.3, -0.2, 0.7);
        let work_b = w.dot(&t);
        let work_a = transform_wrench(&r1, &p1, &w).dot(&transform_twist(&r1, &p1, &t));
        assert!((work_a - work_b).abs() < 1e-14);
        // Ad preserves the reciprocal product.
        let a = adjoint(&r1, &p1);
        assert!((a.transpose() * delta() * a - delta()).amax() < 1e-14);
    }

    #[test]
    fn worked_example_force_at_a_distance() {
        // Frame B at p = (0, 0, L), world axes. A force f_x at B is, at the world origin, the
        // force f_x and the moment p × f = (0, L f_x, 0).
        let l = 0.5;
        let p = Vector3::new(0.0, 0.0, l);
        let w = transform_wrench(
            &Matrix3::identity(),
            &p,
            &Vector6::new(2.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        );
        assert!((w - Vector6::new(2.0, 0.0, 0.0, 0.0, l * 2.0, 0.0)).amax() < 1e-15);
        // A rotation δθ_y of B about B's origin is, at the world origin, the same rotation and
        // the translation p × δθ = (-L δθ_y, 0, 0) of the body point at the origin.
        let t = transform_twist(
            &Matrix3::identity(),
            &p,
            &Vector6::new(0.0, 0.0, 0.0, 0.0, 0.1, 0.0),
        );
        assert!((t - Vector6::new(-l * 0.1, 0.0, 0.0, 0.0, 0.1, 0.0)).amax() < 1e-15);
    }
}
