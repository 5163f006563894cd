//! The layout of the state `(p, R, N, M)` and of its sensitivity columns, and the projection
//! of the rotation onto SO(3) with its derivative.

use nalgebra::{Matrix3, Vector3};

use super::{COLUMN, DR, STATE};
use crate::math::so3::reorthonormalise;

#[inline]
pub(crate) fn v3(y: &[f64], i: usize) -> Vector3<f64> {
    Vector3::new(y[i], y[i + 1], y[i + 2])
}

#[inline]
pub(crate) fn put3(y: &mut [f64], i: usize, v: &Vector3<f64>) {
    y[i] = v.x;
    y[i + 1] = v.y;
    y[i + 2] = v.z;
}

#[inline]
pub(crate) fn rot(y: &[f64]) -> Matrix3<f64> {
    Matrix3::from_column_slice(&y[3..12])
}

/// `δR` of the column starting at `b`.
#[inline]
pub(crate) fn col_rot(y: &[f64], b: usize) -> Matrix3<f64> {
    Matrix3::from_column_slice(&y[b + DR..b + DR + 9])
}

/// The rotation variation `δθ` (world, rad) of `δR` at `R`: the axial vector of the skew
/// part of `δR Rᵀ` (`δR = δθ̂ R` on the rotation group).
#[inline]
pub(crate) fn rotation_variation(r: &Matrix3<f64>, dr: &Matrix3<f64>) -> Vector3<f64> {
    let a = dr * r.transpose();
    Vector3::new(
        0.5 * (a[(2, 1)] - a[(1, 2)]),
        0.5 * (a[(0, 2)] - a[(2, 0)]),
        0.5 * (a[(1, 0)] - a[(0, 1)]),
    )
}

/// `A û` (column-major, into `out`): column `j` is `A (u × e_j)`, 18 products instead of
/// the 27 of a 3×3 product.
#[inline]
pub(crate) fn mul_hat(a: &Matrix3<f64>, u: &Vector3<f64>, out: &mut [f64]) {
    let (a0, a1, a2) = (a.column(0), a.column(1), a.column(2));
    let c0 = a1 * u.z - a2 * u.y;
    let c1 = a2 * u.x - a0 * u.z;
    let c2 = a0 * u.y - a1 * u.x;
    out[..3].copy_from_slice(c0.as_slice());
    out[3..6].copy_from_slice(c1.as_slice());
    out[6..9].copy_from_slice(c2.as_slice());
}

/// `A û + B ŵ` (column-major, into `out`), as [`mul_hat`].
#[inline]
pub(crate) fn mul_hat2(
    a: &Matrix3<f64>,
    u: &Vector3<f64>,
    b: &Matrix3<f64>,
    w: &Vector3<f64>,
    out: &mut [f64],
) {
    let (a0, a1, a2) = (a.column(0), a.column(1), a.column(2));
    let (b0, b1, b2) = (b.column(0), b.column(1), b.column(2));
    let c0 = a1 * u.z - a2 * u.y + b1 * w.z - b2 * w.y;
    let c1 = a2 * u.x - a0 * u.z + b2 * w.x - b0 * w.z;
    let c2 = a0 * u.y - a1 * u.x + b0 * w.y - b1 * w.x;
    out[..3].copy_from_slice(c0.as_slice());
    out[3..6].copy_from_slice(c1.as_slice());
    out[6..9].copy_from_slice(c2.as_slice());
}

/// Re-orthonormalises the rotation part of a state, and maps each column's `δR` by the
/// derivative of the same step, `δR (3I - RᵀR)/2 - R (δRᵀR + RᵀδR)/2` (at the unprojected
/// `R`).
#[inline]
pub(crate) fn project<const N: usize>(y: &mut [f64; N]) {
    project_columns(y, (N - STATE) / COLUMN);
}

/// [`project`] with only the first `ncol` columns mapped (the others, held at zero, stay
/// zero).
#[inline]
pub(crate) fn project_columns<const N: usize>(y: &mut [f64; N], ncol: usize) {
    let raw = rot(y);
    let r = reorthonormalise(&raw);
    y[3..12].copy_from_slice(r.as_slice());
    let rtr = raw.tr_mul(&raw);
    let half = Matrix3::identity() * 1.5 - rtr * 0.5;
    for c in 0..ncol.min((N - STATE) / COLUMN) {
        let b = STATE + COLUMN * c;
        let dr = col_rot(y, b);
        let sym = dr.tr_mul(&raw);
        let d = dr * half - raw * (sym + sym.transpose()) * 0.5;
        y[b + DR..b + DR + 9].copy_from_slice(d.as_slice());
    }
}
