//! Piecewise-constant-curvature (PCC) kinematics of continuum robots.
//!
//! Each segment is a circular arc described by its *arc parameters*: curvature `κ` (1/m, per
//! deformed length, signed), bending-plane angle `φ` (rad) and arc length `ℓ` (m, deformed,
//! `>= 0`). The kinematics splits, as in Webster & Jones (2010), into
//!
//! * a robot-independent map, arc parameters ↔ pose ([`PccSegment::pose`], [`arc_pose`],
//!   [`arc_frames`], [`arc_jacobian`], [`arc_from_tip`], [`arc_from_tip_with_length`]) and its
//!   product over a chain ([`PccChain`], [`chain_pose`]);
//! * the same arc in the bending-vector coordinates `(θ_x, θ_y, ℓ)` of the PCC statics, with
//!   first and second derivatives of its tip pose (`seg_kin`), from the one set of series-safe
//!   arc functions ([`crate::math::series`]);
//! * robot-specific maps, actuation → arc parameters, for tendons ([`super::PccTendons`]: from
//!   displacements or tensions) and pneumatic chambers ([`super::PccChambers`]: from pressures), with
//!   their Jacobians.
//!
//! # Convention
//! The segment's base is at the origin of its base frame with the tangent along `+z` (the body
//! z axis is the tangent everywhere). The segment bends in the plane containing `z` and the
//! direction `(cos φ, sin φ, 0)`: a positive `κ` moves the tip toward that direction. At arc
//! length `s` in `[0, ℓ]` the frame is
//!
//! ```text
//! R(s) = Rz(φ) Ry(κ s) Rz(-φ),
//! p(s) = ((1 - cos κs)/κ cos φ, (1 - cos κs)/κ sin φ, sin(κs)/κ),
//! ```
//!
//! so that a planar arc with `φ = 0` ends at `((1 - cos κℓ)/κ, 0, sin(κℓ)/κ)`. This is the
//! Webster & Jones transform **with the trailing `Rz(-φ)`** (the twist-free convention): the
//! frame is not twisted about the tangent, `R(s)` is the rotation by `κ s` about the fixed axis
//! `(-sin φ, cos φ, 0)`, and the segment is exactly a Cosserat rod with constant body curvature
//! `u = κ (-sin φ, cos φ, 0)` and `v = (0, 0, 1)`, i.e. `T(s) = exp(s [v; u]^)`. (Their eq. 2
//! without `Rz(-φ)` twists the tip frame by `φ` about the tangent and makes the body frame
//! jump when `φ` changes at `κ = 0`.) Consequences: a straight segment's frame is the identity
//! whatever `φ`, and the pose is a smooth function of the *curvature vector* `(u_x, u_y)`
//! ([`ArcCoordinates::CurvatureVector`]), through `κ = 0`.
//!
//! Chains: segment `i`'s arc parameters are expressed in the tip frame of segment `i - 1`
//! (the base frame for the first), and the chain's pose is the product of the segment
//! transforms.
//!
//! Tendon `i` runs at distance `d_i` from the backbone at angle `β_i` from the body x axis
//! toward body y (body offset `d_i (cos β_i, sin β_i, 0)`), is fixed at the segment's tip and
//! pulled at its base: pulling one tendon bends the segment toward it (`φ = β_i`). Chamber `i`
//! has its centroid at `r_i (cos β_i, sin β_i, 0)`; pressurising one chamber lengthens that
//! side and bends the segment away from it (`φ = β_i + π`).
//!
//! The elastic maps (tensions, pressures) balance the actuators' tip moment with `E I κ`, `κ`
//! per *deformed* length as in the planar cable-arm paper, and stretch the segment by the axial force over
//! `E A`. The Cosserat engine's `u` is per undeformed length, so for the same moment its
//! bending angle is larger by the stretch `1 + ε`; keep this in mind when comparing models.
//!
//! Twists are `[translation; rotation]`; see [`JacobianFrame`] for the three Jacobians.
//! Poses are 4×4 homogeneous transforms mapping segment-tip (body) coordinates to base
//! coordinates.
//!
//! # Straight segments
//! Every function of `θ = κ ℓ` that is `0/0` at `θ = 0` is evaluated in a form without
//! cancellation (`(1 - cos θ)/θ² = sinc²(θ/2)/2`, `sin θ / θ = sinc(θ/2) cos(θ/2)`) or by its
//! Taylor series below [`SERIES_BOUND`](crate::math::series::SERIES_BOUND) (the arc series shared
//! with the PCC statics), so poses and Jacobians are finite and smooth
//! through `κ = 0`. The plane angle itself is undefined at `κ = 0`: inverse maps return `φ = 0`
//! there, and Jacobians *into* `(κ, φ, ℓ)` are only defined for `κ ≠ 0` (use the curvature
//! vector coordinates, which are smooth).
//!
//! # References
//! R. J. Webster III, B. A. Jones, "Design and kinematic modeling of constant curvature
//! continuum robots: a review", IJRR 29(13), 2010 (arc ↔ pose, Jacobians, tendon lengths).

use nalgebra::{Matrix3, Matrix4, Matrix6x3, Matrix6xX, Vector3};

use crate::error::{check_finite, Error, Result};
use crate::limits::MAX_BENDING_ANGLE;
use crate::math::samples::in_range;
use crate::math::series::{arc_fns, arc_s1, arc_sb};

/// Samples of the bending angle over `[0, 2π]` that bracket the closest arc in
/// [`arc_from_tip_with_length`] before it is refined.
pub const FIT_SAMPLES: usize = 64;

/// The frame of a Jacobian: which 6-vector a column is, for a unit rate of one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JacobianFrame {
    /// Spatial twist `[v_s; ω_s]` with `Ṫ T⁻¹ = [ω_s^, v_s; 0, 0]` (base-frame components;
    /// `v_s` is the velocity of the base-frame point currently at the origin).
    #[default]
    Spatial,
    /// Body twist `[v_b; ω_b]` with `T⁻¹ Ṫ = [ω_b^, v_b; 0, 0]` (tip-frame components).
    Body,
    /// Tip-point velocity and angular velocity, both in base-frame components, `[ṗ; ω_s]`
    /// (Webster & Jones' `J`; `ṗ = v_s + ω_s × p`).
    Hybrid,
}

/// The coordinates of a segment's configuration that a Jacobian differentiates with respect
/// to (or into).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ArcCoordinates {
    /// Arc parameters `(κ, φ, ℓ)` (1/m, rad, m). The `φ` column of a pose Jacobian vanishes at
    /// `κ = 0`; Jacobians into these coordinates are undefined at `κ = 0`.
    #[default]
    Arc,
    /// Body curvature vector and length `(u_x, u_y, ℓ)` with `u = κ (-sin φ, cos φ, 0)`
    /// (1/m, 1/m, m): smooth everywhere, including straight segments.
    CurvatureVector,
}

/// One constant-curvature segment (immutable, validated arc parameters).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PccSegment {
    pub(crate) curvature: f64,
    plane_angle: f64,
    pub(crate) length: f64,
    pub(crate) cos_phi: f64,
    pub(crate) sin_phi: f64,
}

/// A rigid transform `(R, p)`, composed without 4×4 products.
#[derive(Debug, Clone, Copy)]
struct Rigid {
    r: Matrix3<f64>,
    p: Vector3<f64>,
}

impl Rigid {
    fn identity() -> Self {
        Self {
            r: Matrix3::identity(),
            p: Vector3::zeros(),
        }
    }

    #[inline]
    fn then(&self, next: &Rigid) -> Rigid {
        Rigid {
            r: self.r * next.r,
            p: self.p + self.r * next.p,
        }
    }

    #[inline]
    fn to_matrix(self) -> Matrix4<f64> {
        let mut t = Matrix4::identity();
        t.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.r);
        t.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.p);
        t
    }
}

/// Trigonometric functions of a bending angle `θ`, all well conditioned at `θ = 0`.
#[derive(Debug, Clone, Copy)]
struct ArcTrig {
    sin: f64,
    cos: f64,
    /// `1 - cos θ`.
    omc: f64,
    /// `sin θ / θ`.
    s1: f64,
    /// `(1 - cos θ) / θ²`.
    c2: f64,
}

/// The trigonometric functions of `θ` from the one arc series ([`crate::math::series`]).
#[inline]
fn arc_trig(theta: f64) -> ArcTrig {
    let x = theta * theta;
    let (s, b) = arc_sb(x);
    let omc = x * b;
    ArcTrig {
        sin: theta * s,
        cos: 1.0 - omc,
        omc,
        s1: s,
        c2: b,
    }
}

/// `(θ cos θ - sin θ)/θ² = d(sin θ/θ)/dθ = 2 θ dS/dx`.
#[inline]
fn dsinc(theta: f64) -> f64 {
    2.0 * theta * arc_s1(theta * theta)
}

fn check_length(name: &str, length: f64) -> Result<f64> {
    if length.is_finite() && length >= 0.0 {
        Ok(length)
    } else {
        Err(Error::invalid(name, length, "finite and >= 0 m"))
    }
}

impl PccSegment {
    /// A segment from its arc parameters: `curvature` `κ` (1/m, any sign; negative bends
    /// toward `φ + π`), `plane_angle` `φ` (rad), `length` `ℓ` (m).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `curvature` or `plane_angle` if not finite, or
    /// `length` unless finite and `>= 0`.
    pub fn new(curvature: f64, plane_angle: f64, length: f64) -> Result<Self> {
        check_finite("curvature", curvature)?;
        check_finite("plane_angle", plane_angle)?;
        check_length("length", length)?;
        let (sin_phi, cos_phi) = plane_angle.sin_cos();
        Ok(Self {
            curvature,
            plane_angle,
            length,
            cos_phi,
            sin_phi,
        })
    }

    /// A segment from arc parameters given by a user, as [`PccSegment::new`] with the limits
    /// of [`crate::limits`]: `length <= MAX_LENGTH` and `|κ| ℓ <= MAX_BENDING_ANGLE`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `curvature`, `plane_angle` or `length`.
    pub fn checked(curvature: f64, plane_angle: f64, length: f64) -> Result<Self> {
        check_finite("curvature", curvature)?;
        check_finite("plane_angle", plane_angle)?;
        crate::limits::check_length("length", length, true)?;
        let theta = (curvature * length).abs();
        if theta > MAX_BENDING_ANGLE {
            return Err(Error::invalid(
                "curvature",
                curvature,
                format!(
                    "such that |curvature| x length <= {MAX_BENDING_ANGLE:e} rad (length = \
                     {length} m)"
                ),
            ));
        }
        Self::new(curvature, plane_angle, length)
    }

    /// A straight segment of `length` (m) (`κ = 0`, `φ = 0`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `length` unless finite and `>= 0`.
    pub fn straight(length: f64) -> Result<Self> {
        Self::new(0.0, 0.0, length)
    }

    /// A segment from its body curvature vector `(u_x, u_y)` (1/m) and `length` (m):
    /// `κ = |u| >= 0`, `φ = atan2(-u_x, u_y)` (`φ = 0` for `u = 0`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `u_x`, `u_y` if not finite, or `length`.
    pub fn from_curvature_vector(u_x: f64, u_y: f64, length: f64) -> Result<Self> {
        check_finite("u_x", u_x)?;
        check_finite("u_y", u_y)?;
        let kappa = u_x.hypot(u_y);
        let phi = if kappa > 0.0 { (-u_x).atan2(u_y) } else { 0.0 };
        Self::new(kappa, phi, length)
    }

    /// Curvature `κ` (1/m).
    pub fn curvature(&self) -> f64 {
        self.curvature
    }
    /// Bending-plane angle `φ` (rad), as given.
    pub fn plane_angle(&self) -> f64 {
        self.plane_angle
    }
    /// Arc length `ℓ` (m).
    pub fn length(&self) -> f64 {
        self.length
    }
    /// Total bending angle `θ = κ ℓ` (rad).
    pub fn bending_angle(&self) -> f64 {
        self.curvature * self.length
    }
    /// Body curvature vector `u = κ (-sin φ, cos φ, 0)` (1/m), the same in every frame of the
    /// arc.
    pub fn curvature_vector(&self) -> Vector3<f64> {
        Vector3::new(
            -self.curvature * self.sin_phi,
            self.curvature * self.cos_phi,
            0.0,
        )
    }

    /// Frame at arc length `s` (not checked).
    #[inline]
    fn rigid_at(&self, s: f64) -> Rigid {
        let (c, sn) = (self.cos_phi, self.sin_phi);
        let th = self.curvature * s;
        let t = arc_trig(th);
        // (1 - cos κs)/κ = s θ (1 - cos θ)/θ².
        let a = s * th * t.c2;
        let r = Matrix3::new(
            1.0 - c * c * t.omc,
            -sn * c * t.omc,
            c * t.sin,
            -sn * c * t.omc,
            1.0 - sn * sn * t.omc,
            sn * t.sin,
            -c * t.sin,
            -sn * t.sin,
            t.cos,
        );
        Rigid {
            r,
            p: Vector3::new(c * a, sn * a, s * t.s1),
        }
    }

    /// Tip pose: the 4×4 transform from the tip frame to the segment's base frame.
    #[inline]
    pub fn pose(&self) -> Matrix4<f64> {
        self.rigid_at(self.length).to_matrix()
    }

    /// Tip position (m, base frame).
    #[inline]
    pub fn tip_position(&self) -> Vector3<f64> {
        self.rigid_at(self.length).p
    }

    /// Backbone frame at arc length `s` (m) in `[0, ℓ]`, as a 4×4 transform to the base frame
    /// (round-off at the ends clamped, see [`in_range`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `s` unless finite and in `[0, ℓ]`.
    pub fn pose_at(&self, s: f64) -> Result<Matrix4<f64>> {
        let s = in_range(|| "s".into(), s, self.length)?;
        Ok(self.rigid_at(s).to_matrix())
    }

    /// Backbone frames at each arc length of `s` (m, each in `[0, ℓ]`, any order).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `s[i]` for the first arc length out of range.
    pub fn backbone(&self, s: &[f64]) -> Result<Vec<Matrix4<f64>>> {
        s.iter()
            .enumerate()
            .map(|(i, &si)| {
                let si = in_range(|| format!("s[{i}]"), si, self.length)?;
                Ok(self.rigid_at(si).to_matrix())
            })
            .collect()
    }

    /// Columns `(∂p, ω_s)` of the tip pose per unit rate of each coordinate, with the tip.
    fn raw_jacobian(
        &self,
        coordinates: ArcCoordinates,
    ) -> (Rigid, [Vector3<f64>; 3], [Vector3<f64>; 3]) {
        let (c, sn, k, l) = (self.cos_phi, self.sin_phi, self.curvature, self.length);
        let th = k * l;
        let t = arc_trig(th);
        let g = t.s1 - t.c2; // d/dθ (1 - cos θ)/θ
        let h = dsinc(th); // d/dθ sin θ/θ
        let l2 = l * l;
        let tip = self.rigid_at(l);
        // ∂/∂κ.
        let dp_k = Vector3::new(c * g * l2, sn * g * l2, h * l2);
        let w_k = Vector3::new(-sn * l, c * l, 0.0);
        // (1/κ) ∂/∂φ, smooth at κ = 0.
        let dp_f = Vector3::new(-sn * l2 * t.c2, c * l2 * t.c2, 0.0);
        let w_f = Vector3::new(-c * l * t.s1, -sn * l * t.s1, l * th * t.c2);
        // ∂/∂ℓ: the unit tangent and the curvature vector.
        let dp_l = tip.r.column(2).into_owned();
        let w_l = Vector3::new(-sn * k, c * k, 0.0);
        match coordinates {
            ArcCoordinates::Arc => (tip, [dp_k, dp_f * k, dp_l], [w_k, w_f * k, w_l]),
            ArcCoordinates::CurvatureVector => (
                tip,
                // ∂/∂u_x = -sin φ ∂/∂κ - (cos φ/κ) ∂/∂φ; ∂/∂u_y = cos φ ∂/∂κ - (sin φ/κ) ∂/∂φ.
                [-sn * dp_k - c * dp_f, c * dp_k - sn * dp_f, dp_l],
                [-sn * w_k - c * w_f, c * w_k - sn * w_f, w_l],
            ),
        }
    }

    /// The 6×3 Jacobian of the tip pose with respect to `coordinates`, as twists in `frame`
    /// (see [`JacobianFrame`]), in closed form and smooth through `κ = 0`.
    pub fn jacobian(&self, frame: JacobianFrame, coordinates: ArcCoordinates) -> Matrix6x3<f64> {
        let (tip, dp, w) = self.raw_jacobian(coordinates);
        let mut j = Matrix6x3::zeros();
        for col in 0..3 {
            let (v, om) = match frame {
                JacobianFrame::Spatial => (dp[col] - w[col].cross(&tip.p), w[col]),
                JacobianFrame::Body => (tip.r.tr_mul(&dp[col]), tip.r.tr_mul(&w[col])),
                JacobianFrame::Hybrid => (dp[col], w[col]),
            };
            j.fixed_view_mut::<3, 1>(0, col).copy_from(&v);
            j.fixed_view_mut::<3, 1>(3, col).copy_from(&om);
        }
        j
    }
}

/// Tip pose of one arc (4×4, tip frame → base frame); see [`PccSegment::pose`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming the invalid arc parameter.
pub fn arc_pose(curvature: f64, plane_angle: f64, length: f64) -> Result<Matrix4<f64>> {
    Ok(PccSegment::checked(curvature, plane_angle, length)?.pose())
}

/// Backbone frames of one arc at the arc lengths `s` (m); see [`PccSegment::backbone`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming the invalid arc parameter or `s[i]`.
pub fn arc_frames(
    curvature: f64,
    plane_angle: f64,
    length: f64,
    s: &[f64],
) -> Result<Vec<Matrix4<f64>>> {
    PccSegment::checked(curvature, plane_angle, length)?.backbone(s)
}

/// 6×3 Jacobian of one arc's tip pose; see [`PccSegment::jacobian`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming the invalid arc parameter.
pub fn arc_jacobian(
    curvature: f64,
    plane_angle: f64,
    length: f64,
    frame: JacobianFrame,
    coordinates: ArcCoordinates,
) -> Result<Matrix6x3<f64>> {
    Ok(PccSegment::checked(curvature, plane_angle, length)?.jacobian(frame, coordinates))
}

fn check_position(position: &Vector3<f64>) -> Result<()> {
    for k in 0..3 {
        if !(position[k].is_finite() && position[k].abs() <= crate::limits::MAX_LENGTH) {
            return Err(Error::invalid(
                format!("position[{k}]"),
                position[k],
                format!(
                    "finite and of magnitude <= {:e} m",
                    crate::limits::MAX_LENGTH
                ),
            ));
        }
    }
    Ok(())
}

/// The unique arc from the base (origin, tangent `+z`) through a tip `position` (m, base
/// frame), with `κ >= 0`, `φ = atan2(y, x)` and bending angle in `[0, 2π)`: the inverse map of
/// an extensible segment (its length is an output). With `r = |(x, y)|`:
/// `κ = 2 r / (r² + z²)`, `θ = 2 atan2(r, z)`, `ℓ = θ / κ`.
///
/// On the `+z` axis the arc is straight (`κ = 0`, `φ = 0`, `ℓ = z`).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `position[k]` if not finite, or `position` if it lies on
/// the axis below the base (`x = y = 0`, `z < 0`: no arc reaches it).
pub fn arc_from_tip(position: &Vector3<f64>) -> Result<PccSegment> {
    check_position(position)?;
    let (x, y, z) = (position.x, position.y, position.z);
    let r = x.hypot(y);
    if r == 0.0 {
        if z >= 0.0 {
            return PccSegment::new(0.0, 0.0, z);
        }
        return Err(Error::invalid(
            "position",
            format!("[{x}, {y}, {z}]"),
            "reachable by an arc tangent to +z at the origin (not on the -z axis)",
        ));
    }
    let d2 = r * r + z * z;
    let half = r.atan2(z); // θ/2 in (0, π]
    PccSegment::new(2.0 * r / d2, y.atan2(x), d2 * (half / r))
}

/// Result of [`arc_from_tip_with_length`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipFit {
    /// The arc of the given length whose tip is closest to the target.
    pub segment: PccSegment,
    /// Distance from its tip to the target (m); zero (to rounding) when the target is
    /// reachable.
    pub residual: f64,
}

/// Inverse map of an inextensible segment of known `length` (m): the arc with `κ >= 0`,
/// bending angle in `[0, 2π]` and `φ = atan2(y, x)` whose tip is closest to `position`
/// (m, base frame).
///
/// The reachable tips form a surface, so the target over-determines `(κ, φ)`; when it is
/// reachable the arc is exact (residual at rounding level), otherwise it is the least-squares
/// arc and [`TipFit::residual`] says by how much it misses. The bending angle is bracketed on
/// [`FIT_SAMPLES`] samples and refined by a root search on the distance's derivative. On the
/// axis `φ = 0`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `position[k]` if not finite or `length` unless finite
/// and > 0.
pub fn arc_from_tip_with_length(position: &Vector3<f64>, length: f64) -> Result<TipFit> {
    check_position(position)?;
    crate::limits::check_length("length", length, false)?;
    let (x, y, z) = (position.x, position.y, position.z);
    let r = x.hypot(y);
    let phi = if r > 0.0 { y.atan2(x) } else { 0.0 };
    let l = length;
    // Tip in the bending plane and its θ-derivative, per unit length.
    let plane = |th: f64| {
        let t = arc_trig(th);
        (l * th * t.c2, l * t.s1, l * (t.s1 - t.c2), l * dsinc(th))
    };
    let dist2 = |th: f64| {
        let (px, pz, _, _) = plane(th);
        (px - r).powi(2) + (pz - z).powi(2)
    };
    // Half the derivative of the squared distance.
    let slope = |th: f64| {
        let (px, pz, dx, dz) = plane(th);
        (px - r) * dx + (pz - z) * dz
    };
    let two_pi = 2.0 * std::f64::consts::PI;
    let node = |i: usize| two_pi * i as f64 / FIT_SAMPLES as f64;
    let mut best = 0;
    let mut best_d = dist2(0.0);
    for i in 1..=FIT_SAMPLES {
        let d = dist2(node(i));
        if d < best_d {
            best = i;
            best_d = d;
        }
    }
    let mut theta = node(best);
    // Refine on each side of the best sample where the slope changes sign.
    let mut candidates = [theta; 2];
    for (side, (lo, hi)) in [
        (node(best.saturating_sub(1)), theta),
        (theta, node((best + 1).min(FIT_SAMPLES))),
    ]
    .into_iter()
    .enumerate()
    {
        let (fa, fb) = (slope(lo), slope(hi));
        if hi > lo && fa < 0.0 && fb > 0.0 {
            candidates[side] = illinois(&slope, lo, hi, fa, fb);
        }
    }
    for c in candidates {
        let d = dist2(c);
        if d < best_d {
            best_d = d;
            theta = c;
        }
    }
    Ok(TipFit {
        segment: PccSegment::new(theta / l, phi, l)?,
        residual: best_d.sqrt(),
    })
}

/// Root of `f` in `[a, b]` with `f(a) < 0 < f(b)` by the Illinois variant of regula falsi.
fn illinois<F: Fn(f64) -> f64>(f: &F, mut a: f64, mut b: f64, mut fa: f64, mut fb: f64) -> f64 {
    let mut side = 0i8;
    let mut x = a;
    for _ in 0..200 {
        let prev = x;
        x = (a * fb - b * fa) / (fb - fa);
        if !(x > a && x < b) {
            x = 0.5 * (a + b);
        }
        let fx = f(x);
        if fx == 0.0 || (x - prev).abs() <= 4.0 * f64::EPSILON * x.abs().max(1.0) {
            break;
        }
        if fx < 0.0 {
            a = x;
            fa = fx;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            b = x;
            fb = fx;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    x
}

/// A chain of constant-curvature segments (immutable): segment `i`'s arc parameters are
/// relative to the tip frame of segment `i - 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct PccChain {
    segments: Vec<PccSegment>,
    /// Cumulative arc length at each segment's tip (m).
    ends: Vec<f64>,
}

impl PccChain {
    /// A chain of at least one segment.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `segments` if empty.
    pub fn new(segments: Vec<PccSegment>) -> Result<Self> {
        if segments.is_empty() {
            return Err(Error::invalid("segments", "[]", "at least one segment"));
        }
        let mut total = 0.0;
        let ends = segments
            .iter()
            .map(|seg| {
                total += seg.length;
                total
            })
            .collect();
        Ok(Self { segments, ends })
    }

    /// A chain from rows `[κ, φ, ℓ]` (1/m, rad, m).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `segments[i].curvature` (etc.) or `segments`.
    pub fn from_parameters(parameters: &[[f64; 3]]) -> Result<Self> {
        let segments = parameters
            .iter()
            .enumerate()
            .map(|(i, q)| {
                PccSegment::checked(q[0], q[1], q[2])
                    .map_err(|e| e.map_name(|name| format!("segments[{i}].{name}")))
            })
            .collect::<Result<Vec<_>>>()?;
        Self::new(segments)
    }

    /// The segments, base to tip.
    pub fn segments(&self) -> &[PccSegment] {
        &self.segments
    }
    /// Number of segments.
    pub fn len(&self) -> usize {
        self.segments.len()
    }
    /// Always false: a chain has at least one segment.
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }
    /// Total arc length (m).
    pub fn length(&self) -> f64 {
        self.ends[self.ends.len() - 1]
    }

    /// Tip pose of the chain (4×4, tip frame → base frame).
    pub fn tip_pose(&self) -> Matrix4<f64> {
        chain_pose(&self.segments)
    }

    /// Pose of every segment's tip in the chain's base frame, base to tip.
    pub fn segment_poses(&self) -> Vec<Matrix4<f64>> {
        let mut acc = Rigid::identity();
        self.segments
            .iter()
            .map(|seg| {
                acc = acc.then(&seg.rigid_at(seg.length));
                acc.to_matrix()
            })
            .collect()
    }

    /// Backbone frame at the chain's arc length `s` (m) in `[0, total length]`; at a segment
    /// junction both segments give the same frame.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `s` if out of range.
    pub fn pose_at(&self, s: f64) -> Result<Matrix4<f64>> {
        self.backbone(&[s]).map(|v| v[0]).map_err(|_| {
            Error::invalid("s", s, format!("in [0, length] = [0, {}] m", self.length()))
        })
    }

    /// Backbone frames at the chain's arc lengths `s` (m, each in `[0, total length]`, any
    /// order; round-off at the ends clamped, see [`in_range`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `s[i]` for the first arc length out of range.
    pub fn backbone(&self, s: &[f64]) -> Result<Vec<Matrix4<f64>>> {
        let total = self.length();
        let mut bases = Vec::with_capacity(self.segments.len());
        let mut acc = Rigid::identity();
        for seg in &self.segments {
            bases.push(acc);
            acc = acc.then(&seg.rigid_at(seg.length));
        }
        s.iter()
            .enumerate()
            .map(|(i, &si)| {
                let si = in_range(|| format!("s[{i}]"), si, total).map_err(|e| match e {
                    Error::InvalidParameter {
                        name,
                        value,
                        expected,
                    } => Error::InvalidParameter {
                        name,
                        value,
                        expected: format!("{expected} (the total length of the segments)"),
                    },
                    other => other,
                })?;
                let k = self
                    .ends
                    .partition_point(|&e| e < si)
                    .min(self.segments.len() - 1);
                let start = if k == 0 { 0.0 } else { self.ends[k - 1] };
                let seg = &self.segments[k];
                let local = (si - start).clamp(0.0, seg.length);
                Ok(bases[k].then(&seg.rigid_at(local)).to_matrix())
            })
            .collect()
    }

    /// The 6×3n Jacobian of the chain's tip pose with respect to every segment's coordinates
    /// (columns `3i..3i+3` for segment `i`), as twists in `frame`.
    pub fn jacobian(&self, frame: JacobianFrame, coordinates: ArcCoordinates) -> Matrix6xX<f64> {
        chain_jacobian(&self.segments, frame, coordinates)
    }
}

/// Tip pose of a chain of segments (4×4; segment `i` relative to the tip of `i - 1`); the
/// identity for an empty slice.
pub fn chain_pose(segments: &[PccSegment]) -> Matrix4<f64> {
    segments
        .iter()
        .fold(Rigid::identity(), |acc, seg| {
            acc.then(&seg.rigid_at(seg.length))
        })
        .to_matrix()
}

/// The 6×3n Jacobian of a chain's tip pose (see [`PccChain::jacobian`]).
///
/// Segment `i`'s spatial columns are mapped by the adjoint of the pose of its base,
/// `Ad_T = [R, p^ R; 0, R]`, then the whole matrix is expressed in `frame`.
pub fn chain_jacobian(
    segments: &[PccSegment],
    frame: JacobianFrame,
    coordinates: ArcCoordinates,
) -> Matrix6xX<f64> {
    let mut j = Matrix6xX::zeros(3 * segments.len());
    let mut base = Rigid::identity();
    for (i, seg) in segments.iter().enumerate() {
        let local = seg.jacobian(JacobianFrame::Spatial, coordinates);
        for col in 0..3 {
            let v = local.fixed_view::<3, 1>(0, col).into_owned();
            let w = base.r * local.fixed_view::<3, 1>(3, col);
            let v = base.r * v + base.p.cross(&w);
            j.fixed_view_mut::<3, 1>(0, 3 * i + col).copy_from(&v);
            j.fixed_view_mut::<3, 1>(3, 3 * i + col).copy_from(&w);
        }
        base = base.then(&seg.rigid_at(seg.length));
    }
    if frame != JacobianFrame::Spatial {
        for col in 0..j.ncols() {
            let v = j.fixed_view::<3, 1>(0, col).into_owned();
            let w = j.fixed_view::<3, 1>(3, col).into_owned();
            let (v, w) = match frame {
                JacobianFrame::Body => (base.r.tr_mul(&(v - base.p.cross(&w))), base.r.tr_mul(&w)),
                _ => (v + w.cross(&base.p), w),
            };
            j.fixed_view_mut::<3, 1>(0, col).copy_from(&v);
            j.fixed_view_mut::<3, 1>(3, col).copy_from(&w);
        }
    }
    j
}

// ---------------------------------------------------------------------------------------------
// Segment kinematics in θ coordinates (θ_x, θ_y, ℓ) with first and second derivatives.
// ---------------------------------------------------------------------------------------------

/// One segment's tip pose (segment base frame) and its derivatives in `(θ_x, θ_y, ℓ)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SegKin {
    pub(crate) r: Matrix3<f64>,
    pub(crate) p: Vector3<f64>,
    /// `∂p/∂(θ_x, θ_y, ℓ)`.
    pub(crate) dp: [Vector3<f64>; 3],
    /// Spatial angular velocity per unit `θ_x`, `θ_y` (zero for `ℓ`).
    pub(crate) w: [Vector3<f64>; 2],
    /// `∂²p/∂q_k∂q_m`.
    pub(crate) ddp: [[Vector3<f64>; 3]; 3],
    /// `∂w_k/∂θ_m`.
    pub(crate) dw: [[Vector3<f64>; 2]; 2],
}

/// One segment's kinematics at `(θ_x, θ_y, ℓ) = (a, b, l)`.
#[inline]
pub(crate) fn seg_kin(a: f64, b: f64, l: f64) -> SegKin {
    let x = a * a + b * b;
    let f = arc_fns(x);
    let (ab, a2, b2) = (a * b, a * a, b * b);
    let r = Matrix3::new(
        1.0 - f.b * b2,
        f.b * ab,
        f.s * b,
        f.b * ab,
        1.0 - f.b * a2,
        -f.s * a,
        -f.s * b,
        f.s * a,
        1.0 - f.b * x,
    );
    // P = p/ℓ = (B b, -B a, S).
    let pp = Vector3::new(f.b * b, -f.b * a, f.s);
    let dpa = Vector3::new(2.0 * ab * f.b1, -2.0 * a2 * f.b1 - f.b, 2.0 * a * f.s1);
    let dpb = Vector3::new(2.0 * b2 * f.b1 + f.b, -2.0 * ab * f.b1, 2.0 * b * f.s1);
    let daa = Vector3::new(
        2.0 * b * f.b1 + 4.0 * a2 * b * f.b2,
        -6.0 * a * f.b1 - 4.0 * a2 * a * f.b2,
        2.0 * f.s1 + 4.0 * a2 * f.s2,
    );
    let dab = Vector3::new(
        2.0 * a * f.b1 + 4.0 * a * b2 * f.b2,
        -2.0 * b * f.b1 - 4.0 * a2 * b * f.b2,
        4.0 * ab * f.s2,
    );
    let dbb = Vector3::new(
        6.0 * b * f.b1 + 4.0 * b2 * b * f.b2,
        -2.0 * a * f.b1 - 4.0 * a * b2 * f.b2,
        2.0 * f.s1 + 4.0 * b2 * f.s2,
    );
    let wa = Vector3::new(1.0 - f.c * b2, f.c * ab, -f.b * b);
    let wb = Vector3::new(f.c * ab, 1.0 - f.c * a2, f.b * a);
    let waa = Vector3::new(
        -2.0 * a * b2 * f.c1,
        2.0 * a2 * b * f.c1 + b * f.c,
        -2.0 * ab * f.b1,
    );
    let wab = Vector3::new(
        -2.0 * b2 * b * f.c1 - 2.0 * b * f.c,
        2.0 * a * b2 * f.c1 + a * f.c,
        -2.0 * b2 * f.b1 - f.b,
    );
    let wba = Vector3::new(
        2.0 * a2 * b * f.c1 + b * f.c,
        -2.0 * a2 * a * f.c1 - 2.0 * a * f.c,
        2.0 * a2 * f.b1 + f.b,
    );
    let wbb = Vector3::new(
        2.0 * a * b2 * f.c1 + a * f.c,
        -2.0 * a2 * b * f.c1,
        2.0 * ab * f.b1,
    );
    let z = Vector3::zeros();
    SegKin {
        r,
        p: pp * l,
        dp: [dpa * l, dpb * l, pp],
        w: [wa, wb],
        ddp: [
            [daa * l, dab * l, dpa],
            [dab * l, dbb * l, dpb],
            [dpa, dpb, z],
        ],
        dw: [[waa, wab], [wba, wbb]],
    }
}
