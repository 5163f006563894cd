//! Eigenscrew decomposition of a 6×6 spatial stiffness or compliance, and its compliance
//! ellipsoids.
//!
//! With twists `t = [δp; δθ]`, wrenches `w = [f; m]` and `Δ = [[0, I], [I, 0]]`
//! ([`crate::math::se3::delta`]), an **eigenscrew** of a stiffness `K` is a twist `ξ` that `K` maps
//! to a wrench on the same screw axis: `K ξ = κ Δ ξ` (Patterson & Lipkin 1993). For a
//! symmetric positive definite `K = L Lᵀ` these are `ξ = L⁻ᵀ η` with `η` the eigenvectors of
//! the symmetric `L⁻¹ Δ L⁻ᵀ` (eigenvalues `1/κ`): six real eigenstiffnesses, three positive
//! and three negative, and the decomposition `K = Σ κ_i (Δξ_i)(Δξ_i)ᵀ / (ξ_iᵀ Δ ξ_i)` into
//! screw springs (Huang & Schimmels 2000). For a compliance `C` the eigenscrews are wrenches
//! `C w = μ Δ w` with `μ = 1/κ` on the same axes.
//!
//! A screw with direction part `a` and moment part `b` (twist: `a = δθ`, `b = δp`; wrench:
//! `a = f`, `b = m`) has the axis direction `a/|a|`, pitch `h = a·b/|a|²` and the axis point
//! closest to the origin `c = a × b/|a|²`.
//!
//! # References
//! T. Patterson, H. Lipkin, "Structure of robot compliance", J. Mech. Design 115(3), 1993.
//! S. Huang, J. M. Schimmels, "The eigenscrew decomposition of spatial stiffness matrices",
//! IEEE Trans. Robotics and Automation 16(2), 2000.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::error::{Error, Result};
use crate::math::se3::delta;

/// Which matrix is decomposed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MatrixKind {
    /// A stiffness `K` (wrench = K twist): eigenvectors are twists.
    #[default]
    Stiffness,
    /// A compliance `C` (twist = C wrench): eigenvectors are wrenches.
    Compliance,
}

/// One eigenscrew.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eigenscrew {
    /// Eigenvalue: `κ` (stiffness; N/rad along the axis) or `μ = 1/κ` (compliance).
    pub value: f64,
    /// Eigenvector (twist `[δp; δθ]` or wrench `[f; m]`), scaled so that `vᵀ M v = 1`.
    pub vector: [f64; 6],
    /// Unit axis direction.
    pub direction: [f64; 3],
    /// Point of the axis closest to the frame origin (m).
    pub point: [f64; 3],
    /// Pitch (m/rad).
    pub pitch: f64,
}

/// An ellipsoid: semi-axes and their unit directions (columns), largest first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipsoid {
    /// Semi-axes (the principal compliances: m/N translational, rad/(N m) rotational).
    pub semi_axes: [f64; 3],
    /// Directions, `directions[k]` the unit vector of `semi_axes[k]`.
    pub directions: [[f64; 3]; 3],
}

/// The eigenscrew decomposition and the compliance ellipsoids at the frame's origin.
#[derive(Debug, Clone, PartialEq)]
pub struct Decomposition {
    /// The six eigenscrews, by decreasing eigenvalue.
    pub screws: Vec<Eigenscrew>,
    /// Translational compliance ellipsoid: eigenvalues and eigenvectors of the force-to-
    /// translation block `C_tt` (displacement under a unit force along each direction).
    pub translational: Ellipsoid,
    /// Rotational compliance ellipsoid: the moment-to-rotation block `C_rr`.
    pub rotational: Ellipsoid,
}

fn ellipsoid(m: &Matrix3<f64>) -> Ellipsoid {
    let e = m.symmetric_eigen();
    let mut idx = [0, 1, 2];
    idx.sort_by(|&a, &b| e.eigenvalues[b].total_cmp(&e.eigenvalues[a]));
    let mut out = Ellipsoid {
        semi_axes: [0.0; 3],
        directions: [[0.0; 3]; 3],
    };
    for (k, &i) in idx.iter().enumerate() {
        out.semi_axes[k] = e.eigenvalues[i];
        let v = e.eigenvectors.column(i);
        out.directions[k] = [v[0], v[1], v[2]];
    }
    out
}

/// Axis direction, closest point and pitch of a screw with direction part `a` and moment part
/// `b`.
fn axis(a: &Vector3<f64>, b: &Vector3<f64>) -> ([f64; 3], [f64; 3], f64) {
    let a2 = a.norm_squared();
    let d = a / a2.sqrt();
    let c = a.cross(b) / a2;
    ([d.x, d.y, d.z], [c.x, c.y, c.z], a.dot(b) / a2)
}

/// Eigenscrews of a symmetric positive definite stiffness or compliance `m`, and the
/// compliance ellipsoids (of `m`, or of `m⁻¹` for a stiffness).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `matrix` if it is not finite, not symmetric (to 1e-9
/// relative), not positive definite, or so large or ill-conditioned that its decomposition
/// overflows.
pub fn eigenscrews(m: &Matrix6<f64>, kind: MatrixKind) -> Result<Decomposition> {
    if !m.iter().all(|v| v.is_finite()) {
        return Err(Error::invalid("matrix", "non-finite entries", "finite"));
    }
    let asym = (m - m.transpose()).amax();
    if asym > 1e-9 * m.amax() {
        return Err(Error::invalid(
            "matrix",
            format!("asymmetry {asym:.3e}"),
            "symmetric (to 1e-9 relative)",
        ));
    }
    let sym = (m + m.transpose()) * 0.5;
    let Some(ch) = sym.cholesky() else {
        return Err(Error::invalid(
            "matrix",
            "not positive definite",
            "positive definite",
        ));
    };
    let l = ch.l();
    let Some(li) = l.try_inverse() else {
        return Err(Error::invalid("matrix", "singular", "positive definite"));
    };
    let s = li * delta() * li.transpose();
    let e = ((s + s.transpose()) * 0.5).symmetric_eigen();
    let mut screws: Vec<Eigenscrew> = (0..6)
        .map(|i| {
            let eta: Vector6<f64> = e.eigenvectors.column(i).into_owned();
            let v = li.transpose() * eta;
            let (dir, mom) = match kind {
                MatrixKind::Stiffness => (
                    v.fixed_rows::<3>(3).into_owned(),
                    v.fixed_rows::<3>(0).into_owned(),
                ),
                MatrixKind::Compliance => (
                    v.fixed_rows::<3>(0).into_owned(),
                    v.fixed_rows::<3>(3).into_owned(),
                ),
            };
            let (direction, point, pitch) = axis(&dir, &mom);
            Eigenscrew {
                value: 1.0 / e.eigenvalues[i],
                vector: [v[0], v[1], v[2], v[3], v[4], v[5]],
                direction,
                point,
                pitch,
            }
        })
        .collect();
    screws.sort_by(|a, b| b.value.total_cmp(&a.value));
    let c = match kind {
        MatrixKind::Compliance => sym,
        MatrixKind::Stiffness => ch.inverse(),
    };
    let ctt = c.fixed_view::<3, 3>(0, 0).into_owned();
    let crr = c.fixed_view::<3, 3>(3, 3).into_owned();
    let d = Decomposition {
        screws,
        translational: ellipsoid(&ctt),
        rotational: ellipsoid(&crr),
    };
    // Entries near the float range overflow the decomposition (squares, inverses).
    let finite = d.screws.iter().all(|s| {
        s.value.is_finite()
            && s.pitch.is_finite()
            && s.vector
                .iter()
                .chain(&s.direction)
                .chain(&s.point)
                .all(|v| v.is_finite())
    }) && [d.translational, d.rotational].iter().all(|e| {
        e.semi_axes
            .iter()
            .chain(e.directions.iter().flatten())
            .all(|v| v.is_finite())
    });
    if !finite {
        return Err(Error::invalid(
            "matrix",
            format!("entries up to {:.3e}", m.amax()),
            "a matrix whose decomposition is representable (its entries, their squares and its \
             inverse finite)",
        ));
    }
    Ok(d)
}
