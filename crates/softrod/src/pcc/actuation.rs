//! Robot-specific PCC maps: actuation (tendon displacements, tensions, chamber pressures) → arc
//! parameters of one segment, with their Jacobians (Webster & Jones 2010; the elastic maps
//! balance the actuators' tip moment with `E I κ`, see [`crate::pcc`]).

use nalgebra::{Matrix2xX, Matrix3xX, MatrixXx3};

use super::kinematics::{ArcCoordinates, PccSegment};
use crate::error::{check_finite, check_positive, Error, Result};

/// Relative tolerance on the smallest eigenvalue of the normal equations of the tendon
/// displacement map: layouts below it cannot resolve the arc parameters.
pub const RANK_TOLERANCE: f64 = 1e-12;

/// Elastic properties of a uniform segment for the tension and pressure maps (immutable).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticSegment {
    rest_length: f64,
    bending_stiffness: f64,
    axial_stiffness: Option<f64>,
}

impl ElasticSegment {
    /// `rest_length` `ℓ0` (m), `bending_stiffness` `E I` (N m²), `axial_stiffness` `E A` (N),
    /// `None` for an inextensible segment.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the parameter that is not finite and > 0.
    pub fn new(
        rest_length: f64,
        bending_stiffness: f64,
        axial_stiffness: Option<f64>,
    ) -> Result<Self> {
        crate::limits::check_length("rest_length", rest_length, false)?;
        check_positive("bending_stiffness", bending_stiffness, "N m^2")?;
        if let Some(ea) = axial_stiffness {
            check_positive("axial_stiffness", ea, "N")?;
        }
        Ok(Self {
            rest_length,
            bending_stiffness,
            axial_stiffness,
        })
    }

    /// A solid circular section of `radius` (m) and Young's modulus `youngs_modulus` (Pa):
    /// `E I = E π r⁴/4`, `E A = E π r²` (or inextensible).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the parameter that is not finite and > 0.
    pub fn solid_circle(
        rest_length: f64,
        radius: f64,
        youngs_modulus: f64,
        extensible: bool,
    ) -> Result<Self> {
        check_positive("radius", radius, "m")?;
        crate::limits::check_modulus("youngs_modulus", youngs_modulus)?;
        let area = std::f64::consts::PI * radius * radius;
        let second_moment = area * radius * radius / 4.0;
        if !(second_moment.is_finite() && second_moment > f64::MIN_POSITIVE) {
            return Err(Error::invalid(
                "radius",
                radius,
                "finite and > 0 m, with pi r^4 / 4 a finite nonzero float",
            ));
        }
        let (ei, ea) = (youngs_modulus * second_moment, youngs_modulus * area);
        if !(ei.is_finite() && ei > f64::MIN_POSITIVE && ea.is_finite()) {
            return Err(Error::invalid(
                "youngs_modulus",
                youngs_modulus,
                "finite and > 0 Pa, with E pi r^4 / 4 and E pi r^2 finite and nonzero",
            ));
        }
        Self::new(rest_length, ei, extensible.then_some(ea))
    }

    /// Rest length `ℓ0` (m).
    pub fn rest_length(&self) -> f64 {
        self.rest_length
    }
    /// Bending stiffness `E I` (N m²).
    pub fn bending_stiffness(&self) -> f64 {
        self.bending_stiffness
    }
    /// Axial stiffness `E A` (N), `None` if inextensible.
    pub fn axial_stiffness(&self) -> Option<f64> {
        self.axial_stiffness
    }
}

/// Tendons of one segment (immutable): distances `d_i` (m) from the backbone and angles `β_i`
/// (rad) from body x toward body y. Terminated at the segment's tip.
#[derive(Debug, Clone, PartialEq)]
pub struct PccTendons {
    distances: Vec<f64>,
    angles: Vec<f64>,
    cos: Vec<f64>,
    sin: Vec<f64>,
    /// Least-squares inverse of the displacement map, rows `(e, a, b)` (extensible).
    pinv_extensible: Option<Matrix3xX<f64>>,
    /// Rows `(a, b)` (inextensible).
    pinv_inextensible: Option<Matrix2xX<f64>>,
}

fn check_actuators(distances: &[f64], angles: &[f64]) -> Result<()> {
    if distances.is_empty() {
        return Err(Error::invalid("distances", "[]", "at least one actuator"));
    }
    if angles.len() != distances.len() {
        return Err(Error::invalid(
            "angles.len()",
            angles.len(),
            format!("equal to distances.len() = {}", distances.len()),
        ));
    }
    for (i, (&d, &b)) in distances.iter().zip(angles).enumerate() {
        crate::limits::check_length(&format!("distances[{i}]"), d, false)?;
        check_finite(&format!("angles[{i}]"), b)?;
    }
    Ok(())
}

/// Pseudo-inverse `(MᵀM)⁻¹Mᵀ` (3×n) of the extensible displacement map, rows
/// `[1, -d_i cos β_i, -d_i sin β_i]`; `None` if `MᵀM` is singular to [`RANK_TOLERANCE`].
fn pseudo_inverse3(rows: &[[f64; 3]]) -> Option<Matrix3xX<f64>> {
    let mt = Matrix3xX::from_fn(rows.len(), |r, c| rows[c][r]);
    let normal = &mt * mt.transpose();
    let eig = normal.symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    if !(hi > 0.0 && lo > RANK_TOLERANCE * hi) {
        return None;
    }
    Some(normal.try_inverse()? * mt)
}

/// Pseudo-inverse (2×n) of the inextensible displacement map, rows
/// `[-d_i cos β_i, -d_i sin β_i]`.
fn pseudo_inverse2(rows: &[[f64; 2]]) -> Option<Matrix2xX<f64>> {
    let mt = Matrix2xX::from_fn(rows.len(), |r, c| rows[c][r]);
    let normal = &mt * mt.transpose();
    let eig = normal.symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    if !(hi > 0.0 && lo > RANK_TOLERANCE * hi) {
        return None;
    }
    Some(normal.try_inverse()? * mt)
}

impl PccTendons {
    /// Tendons at `distances` `d_i` (m, > 0) and `angles` `β_i` (rad).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `distances` if empty, `angles.len()` if the lengths
    /// differ, or the first invalid `distances[i]` / `angles[i]`.
    pub fn new(distances: &[f64], angles: &[f64]) -> Result<Self> {
        check_actuators(distances, angles)?;
        let (sin, cos): (Vec<f64>, Vec<f64>) = angles.iter().map(|b| b.sin_cos()).unzip();
        let ext: Vec<[f64; 3]> = distances
            .iter()
            .zip(cos.iter().zip(&sin))
            .map(|(d, (c, s))| [1.0, -d * c, -d * s])
            .collect();
        let inext: Vec<[f64; 2]> = ext.iter().map(|r| [r[1], r[2]]).collect();
        Ok(Self {
            distances: distances.to_vec(),
            angles: angles.to_vec(),
            cos,
            sin,
            pinv_extensible: pseudo_inverse3(&ext),
            pinv_inextensible: pseudo_inverse2(&inext),
        })
    }

    /// `count` tendons at the same `distance` (m), equally spaced from `first_angle` (rad).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `count` if zero, or as [`PccTendons::new`].
    pub fn equally_spaced(count: usize, distance: f64, first_angle: f64) -> Result<Self> {
        if count == 0 {
            return Err(Error::invalid("count", count, ">= 1"));
        }
        let step = 2.0 * std::f64::consts::PI / count as f64;
        let angles: Vec<f64> = (0..count).map(|i| first_angle + step * i as f64).collect();
        Self::new(&vec![distance; count], &angles)
    }

    /// Number of tendons.
    pub fn len(&self) -> usize {
        self.distances.len()
    }
    /// Always false (at least one tendon).
    pub fn is_empty(&self) -> bool {
        self.distances.is_empty()
    }
    /// Distances `d_i` (m).
    pub fn distances(&self) -> &[f64] {
        &self.distances
    }
    /// Angles `β_i` (rad).
    pub fn angles(&self) -> &[f64] {
        &self.angles
    }
}

/// Pneumatic chambers of one segment (immutable): cross-section areas `A_i` (m²), centroid
/// distances `r_i` (m) and angles `β_i` (rad, from body x toward body y).
#[derive(Debug, Clone, PartialEq)]
pub struct PccChambers {
    areas: Vec<f64>,
    distances: Vec<f64>,
    angles: Vec<f64>,
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl PccChambers {
    /// Chambers with `areas` (m², > 0), `distances` (m, > 0) and `angles` (rad).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first invalid entry or mismatched length.
    pub fn new(areas: &[f64], distances: &[f64], angles: &[f64]) -> Result<Self> {
        check_actuators(distances, angles)?;
        if areas.len() != distances.len() {
            return Err(Error::invalid(
                "areas.len()",
                areas.len(),
                format!("equal to distances.len() = {}", distances.len()),
            ));
        }
        for (i, &a) in areas.iter().enumerate() {
            let max = crate::limits::MAX_LENGTH * crate::limits::MAX_LENGTH;
            if !(a.is_finite() && a > 0.0 && a <= max) {
                return Err(Error::invalid(
                    format!("areas[{i}]"),
                    a,
                    format!("finite, > 0 and <= {max:e} m^2"),
                ));
            }
        }
        let (sin, cos) = angles.iter().map(|b| b.sin_cos()).unzip();
        Ok(Self {
            areas: areas.to_vec(),
            distances: distances.to_vec(),
            angles: angles.to_vec(),
            cos,
            sin,
        })
    }

    /// `count` chambers of equal `area` (m²) at the same `distance` (m), equally spaced from
    /// `first_angle` (rad).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `count` if zero, or as [`PccChambers::new`].
    pub fn equally_spaced(
        count: usize,
        area: f64,
        distance: f64,
        first_angle: f64,
    ) -> Result<Self> {
        if count == 0 {
            return Err(Error::invalid("count", count, ">= 1"));
        }
        let step = 2.0 * std::f64::consts::PI / count as f64;
        let angles: Vec<f64> = (0..count).map(|i| first_angle + step * i as f64).collect();
        Self::new(&vec![area; count], &vec![distance; count], &angles)
    }

    /// Number of chambers.
    pub fn len(&self) -> usize {
        self.areas.len()
    }
    /// Always false (at least one chamber).
    pub fn is_empty(&self) -> bool {
        self.areas.is_empty()
    }
    /// Areas `A_i` (m²).
    pub fn areas(&self) -> &[f64] {
        &self.areas
    }
    /// Centroid distances `r_i` (m).
    pub fn distances(&self) -> &[f64] {
        &self.distances
    }
    /// Angles `β_i` (rad).
    pub fn angles(&self) -> &[f64] {
        &self.angles
    }
}

fn check_count(name: &str, got: usize, expected: usize) -> Result<()> {
    if got == expected {
        Ok(())
    } else {
        Err(Error::invalid(
            format!("{name}.len()"),
            got,
            format!("equal to the number of actuators, {expected}"),
        ))
    }
}

/// Tendon length changes `Δl_i` (m, positive when the tendon pays out) for a segment of
/// arc parameters `segment` whose rest length is `rest_length` (m; `None`: the segment's
/// length, i.e. inextensible):
/// `Δl_i = (ℓ - ℓ0) - d_i κ ℓ cos(φ - β_i)`.
///
/// This is exact for tendons parallel to the backbone in a twist-free arc: the tendon at body
/// offset `r_i` has length `∫ |1 + (u × r_i)·z| ds = ℓ (1 - d_i κ cos(φ - β_i))` while
/// `d_i |κ| < 1`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `rest_length` unless finite and > 0.
pub fn tendon_displacements(
    segment: &PccSegment,
    tendons: &PccTendons,
    rest_length: Option<f64>,
) -> Result<Vec<f64>> {
    let l0 = match rest_length {
        Some(l0) => check_positive("rest_length", l0, "m")?,
        None => segment.length,
    };
    let (k, l) = (segment.curvature, segment.length);
    Ok((0..tendons.len())
        .map(|i| {
            let cos_rel = segment.cos_phi * tendons.cos[i] + segment.sin_phi * tendons.sin[i];
            (l - l0) - tendons.distances[i] * k * l * cos_rel
        })
        .collect())
}

/// The n×3 Jacobian `∂Δl/∂q` of [`tendon_displacements`] with respect to the segment's
/// `coordinates` `q`, at fixed rest length (so `∂Δl_i/∂ℓ = 1 - d_i κ cos(φ - β_i)`).
/// Smooth everywhere in both coordinate systems.
pub fn tendon_displacement_jacobian(
    segment: &PccSegment,
    tendons: &PccTendons,
    coordinates: ArcCoordinates,
) -> MatrixXx3<f64> {
    let (k, l, cf, sf) = (
        segment.curvature,
        segment.length,
        segment.cos_phi,
        segment.sin_phi,
    );
    let mut j = MatrixXx3::zeros(tendons.len());
    for i in 0..tendons.len() {
        let (d, cb, sb) = (tendons.distances[i], tendons.cos[i], tendons.sin[i]);
        let cos_rel = cf * cb + sf * sb;
        let sin_rel = sf * cb - cf * sb;
        j[(i, 2)] = 1.0 - d * k * cos_rel;
        match coordinates {
            ArcCoordinates::Arc => {
                j[(i, 0)] = -d * l * cos_rel;
                j[(i, 1)] = d * k * l * sin_rel;
            }
            ArcCoordinates::CurvatureVector => {
                // Δl = (ℓ - ℓ0) - d ℓ (u_y cos β - u_x sin β).
                j[(i, 0)] = d * l * sb;
                j[(i, 1)] = -d * l * cb;
            }
        }
    }
    j
}

fn check_values(name: &str, values: &[f64], non_negative: bool) -> Result<()> {
    for (i, &v) in values.iter().enumerate() {
        if !(v.is_finite() && (!non_negative || v >= 0.0)) {
            let expected = if non_negative {
                "finite and >= 0"
            } else {
                "finite"
            };
            return Err(Error::invalid(format!("{name}[{i}]"), v, expected));
        }
    }
    Ok(())
}

/// `(e, a, b)`: elongation `ℓ - ℓ0` and bending vector `θ (cos φ, sin φ)` from displacements.
fn displacement_unknowns(
    displacements: &[f64],
    tendons: &PccTendons,
    rest_length: f64,
    extensible: bool,
) -> Result<(f64, f64, f64)> {
    check_count("displacements", displacements.len(), tendons.len())?;
    check_values("displacements", displacements, false)?;
    check_positive("rest_length", rest_length, "m")?;
    let degenerate = |need: &str| {
        Error::invalid(
            "tendons",
            format!("{} tendons at angles {:?}", tendons.len(), tendons.angles),
            format!("a layout that resolves {need} (full-rank displacement map)"),
        )
    };
    let (e, a, b) = if extensible {
        let p = tendons
            .pinv_extensible
            .as_ref()
            .ok_or_else(|| degenerate("elongation and bending (>= 3 tendons)"))?;
        let mut x = [0.0; 3];
        for (i, &dl) in displacements.iter().enumerate() {
            for r in 0..3 {
                x[r] += p[(r, i)] * dl;
            }
        }
        (x[0], x[1], x[2])
    } else {
        let p = tendons
            .pinv_inextensible
            .as_ref()
            .ok_or_else(|| degenerate("bending (>= 2 non-opposite tendons)"))?;
        let mut x = [0.0; 2];
        for (i, &dl) in displacements.iter().enumerate() {
            for r in 0..2 {
                x[r] += p[(r, i)] * dl;
            }
        }
        (0.0, x[0], x[1])
    };
    if !(rest_length + e > 0.0 && e.is_finite()) {
        return Err(Error::invalid(
            "displacements",
            format!("{displacements:?}"),
            format!("a common elongation > -rest_length = {} m", -rest_length),
        ));
    }
    Ok((e, a, b))
}

/// Inverse of [`tendon_displacements`]: the arc (with `κ >= 0`) from tendon length changes
/// `displacements` (m) of a segment of `rest_length` (m). Extensible: unknowns elongation and
/// bending (needs 3 tendons not all on one line through the backbone); inextensible (`ℓ =
/// ℓ0`): bending only (needs 2 non-opposite tendons). With more tendons than unknowns the
/// displacements are fitted in the least-squares sense (consistent ones exactly).
///
/// The map is linear in the elongation `e` and the bending vector `θ (cos φ, sin φ)`:
/// `Δl_i = e - d_i θ cos(φ - β_i)`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `displacements.len()`, `displacements[i]`,
/// `rest_length`, `tendons` (degenerate layout), or `displacements` (length would be <= 0);
/// `length` or `curvature` for an arc beyond the limits of [`PccSegment::checked`] (a
/// displacement of 1e300 m made an arc 3.3e299 m long that every other function refuses).
pub fn arc_from_tendon_displacements(
    displacements: &[f64],
    tendons: &PccTendons,
    rest_length: f64,
    extensible: bool,
) -> Result<PccSegment> {
    fitted_arc(displacements, tendons, rest_length, extensible).map(|(arc, _)| arc)
}

/// The least-squares arc of [`arc_from_tendon_displacements`] and its unknowns `(e, a, b)`.
fn fitted_arc(
    displacements: &[f64],
    tendons: &PccTendons,
    rest_length: f64,
    extensible: bool,
) -> Result<(PccSegment, (f64, f64, f64))> {
    let (e, a, b) = displacement_unknowns(displacements, tendons, rest_length, extensible)?;
    let l = rest_length + e;
    let arc = PccSegment::from_curvature_vector(-b / l, a / l, l)?;
    let arc = PccSegment::checked(arc.curvature(), arc.plane_angle(), arc.length())?;
    Ok((arc, (e, a, b)))
}

/// The misfit of [`arc_from_tendon_displacements`]: for each tendon, the length change (m) of
/// the least-squares arc minus the one given, `Δl_i(arc) - displacements[i]`. Zero to rounding
/// when the displacements are those of one arc (always with as many tendons as unknowns);
/// with more tendons, what one arc cannot explain: measurement error, a slack or stretched
/// tendon, a segment that is not an arc, or (inextensible) a length change of the backbone.
///
/// # Errors
/// As [`arc_from_tendon_displacements`].
pub fn tendon_displacement_misfit(
    displacements: &[f64],
    tendons: &PccTendons,
    rest_length: f64,
    extensible: bool,
) -> Result<Vec<f64>> {
    // (Displacements the arc refuses have no misfit either.)
    let (_, (e, a, b)) = fitted_arc(displacements, tendons, rest_length, extensible)?;
    Ok((0..tendons.len())
        .map(|i| {
            let d = tendons.distances[i];
            e - d * (a * tendons.cos[i] + b * tendons.sin[i]) - displacements[i]
        })
        .collect())
}

/// Converts a 3×n Jacobian into `(u_x, u_y, ℓ)` at curvature vector `(u_x, u_y)` into
/// `coordinates`.
fn to_coordinates(
    mut j: Matrix3xX<f64>,
    u_x: f64,
    u_y: f64,
    coordinates: ArcCoordinates,
) -> Result<Matrix3xX<f64>> {
    if coordinates == ArcCoordinates::CurvatureVector {
        return Ok(j);
    }
    let k2 = u_x * u_x + u_y * u_y;
    if !(k2 > 0.0 && k2.is_finite()) {
        return Err(Error::invalid(
            "curvature",
            0.0,
            "nonzero: (curvature, plane_angle) are not differentiable at a straight segment; \
             use ArcCoordinates::CurvatureVector",
        ));
    }
    let k = k2.sqrt();
    for col in 0..j.ncols() {
        let (dx, dy) = (j[(0, col)], j[(1, col)]);
        j[(0, col)] = (u_x * dx + u_y * dy) / k;
        j[(1, col)] = (u_x * dy - u_y * dx) / k2;
    }
    Ok(j)
}

/// The 3×n Jacobian of [`arc_from_tendon_displacements`] with respect to the displacements,
/// in closed form. In [`ArcCoordinates::Arc`] it is undefined at a straight segment
/// (`∂φ/∂Δl` grows as `1/κ`).
///
/// # Errors
/// As [`arc_from_tendon_displacements`], and [`Error::InvalidParameter`] naming `curvature`
/// for arc coordinates at `κ = 0`.
pub fn arc_from_tendon_displacements_jacobian(
    displacements: &[f64],
    tendons: &PccTendons,
    rest_length: f64,
    extensible: bool,
    coordinates: ArcCoordinates,
) -> Result<Matrix3xX<f64>> {
    let (e, a, b) = displacement_unknowns(displacements, tendons, rest_length, extensible)?;
    let l = rest_length + e;
    let n = tendons.len();
    let mut j = Matrix3xX::zeros(n);
    for i in 0..n {
        let (de, da, db) = match (
            extensible,
            &tendons.pinv_extensible,
            &tendons.pinv_inextensible,
        ) {
            (true, Some(p), _) => (p[(0, i)], p[(1, i)], p[(2, i)]),
            (false, _, Some(p)) => (0.0, p[(0, i)], p[(1, i)]),
            _ => (0.0, 0.0, 0.0), // unreachable: checked by displacement_unknowns
        };
        // u_x = -b/ℓ, u_y = a/ℓ, ℓ = ℓ0 + e.
        j[(0, i)] = b / (l * l) * de - db / l;
        j[(1, i)] = -a / (l * l) * de + da / l;
        j[(2, i)] = de;
    }
    to_coordinates(j, -b / l, a / l, coordinates)
}

/// Per unit of actuation `q_i`: axial force (N) and body moment `(m_x, m_y)` (N m).
type Loading = (f64, f64, f64);

/// The elastic arc under actuation loads: `E I u = Σ q_i m_i`, `ℓ = ℓ0 (1 + Σ q_i f_i / E A)`.
/// Returns `(u_x, u_y, ℓ)`.
fn elastic_arc<F: Fn(usize) -> Loading>(
    name: &str,
    values: &[f64],
    loading: F,
    body: &ElasticSegment,
) -> Result<(f64, f64, f64)> {
    let (mut f, mut mx, mut my) = (0.0, 0.0, 0.0);
    for (i, &q) in values.iter().enumerate() {
        let (fi, mxi, myi) = loading(i);
        f += q * fi;
        mx += q * mxi;
        my += q * myi;
    }
    let ei = body.bending_stiffness;
    let l = match body.axial_stiffness {
        Some(ea) => body.rest_length * (1.0 + f / ea),
        None => body.rest_length,
    };
    if !(l > 0.0 && l.is_finite()) {
        return Err(Error::invalid(
            name,
            format!("{values:?}"),
            format!(
                "an axial strain > -1: net axial force {f:e} N over axial_stiffness {} N",
                body.axial_stiffness.unwrap_or(f64::INFINITY)
            ),
        ));
    }
    Ok((mx / ei, my / ei, l))
}

fn elastic_jacobian<F: Fn(usize) -> Loading>(
    n: usize,
    loading: F,
    body: &ElasticSegment,
) -> Matrix3xX<f64> {
    let ei = body.bending_stiffness;
    Matrix3xX::from_fn(n, |r, i| {
        let (fi, mxi, myi) = loading(i);
        match r {
            0 => mxi / ei,
            1 => myi / ei,
            _ => body
                .axial_stiffness
                .map_or(0.0, |ea| body.rest_length * fi / ea),
        }
    })
}

/// A layout of actuators of one segment whose unit actuation loads it (tendons, chambers).
trait Actuators {
    /// Name of the actuation values in errors.
    const VALUES: &'static str;
    /// Whether the values must be `>= 0` (tensions) or only finite (pressures).
    const NON_NEGATIVE: bool;
    /// Number of actuators.
    fn count(&self) -> usize;
    /// [`Loading`] of actuator `i` at unit actuation.
    fn loading(&self, i: usize) -> Loading;
}

impl Actuators for PccTendons {
    const VALUES: &'static str = "tensions";
    const NON_NEGATIVE: bool = true;
    fn count(&self) -> usize {
        self.len()
    }
    /// Tendon `i` at unit tension: axial force `-1` (compression) and tip moment
    /// `r_i × (-z) = d_i (-sin β_i, cos β_i)`.
    fn loading(&self, i: usize) -> Loading {
        let d = self.distances[i];
        (-1.0, -d * self.sin[i], d * self.cos[i])
    }
}

impl Actuators for PccChambers {
    const VALUES: &'static str = "pressures";
    const NON_NEGATIVE: bool = false;
    fn count(&self) -> usize {
        self.len()
    }
    /// Chamber `i` at unit pressure: axial force `A_i` and moment `r_i × (A_i z)`.
    fn loading(&self, i: usize) -> Loading {
        let (a, r) = (self.areas[i], self.distances[i]);
        (a, a * r * self.sin[i], -a * r * self.cos[i])
    }
}

/// `(u_x, u_y, ℓ)` (1/m, 1/m, m) of the checked actuation `values` (tensions in N, pressures
/// in Pa), one per actuator.
fn actuated_arc<A: Actuators>(
    values: &[f64],
    actuators: &A,
    body: &ElasticSegment,
) -> Result<(f64, f64, f64)> {
    check_count(A::VALUES, values.len(), actuators.count())?;
    check_values(A::VALUES, values, A::NON_NEGATIVE)?;
    elastic_arc(A::VALUES, values, |i| actuators.loading(i), body)
}

/// The segment of [`actuated_arc`] (`κ >= 0`).
fn actuated_segment<A: Actuators>(
    values: &[f64],
    actuators: &A,
    body: &ElasticSegment,
) -> Result<PccSegment> {
    let (ux, uy, l) = actuated_arc(values, actuators, body)?;
    PccSegment::from_curvature_vector(ux, uy, l)
}

/// The 3×n Jacobian of the arc of [`actuated_arc`] with respect to the `n` actuation values,
/// in `coordinates`.
fn actuated_jacobian<A: Actuators>(
    values: &[f64],
    actuators: &A,
    body: &ElasticSegment,
    coordinates: ArcCoordinates,
) -> Result<Matrix3xX<f64>> {
    let (ux, uy, _) = actuated_arc(values, actuators, body)?;
    let j = elastic_jacobian(actuators.count(), |i| actuators.loading(i), body);
    to_coordinates(j, ux, uy, coordinates)
}

/// The arc of a linear elastic uniform segment `body` pulled by `tensions` (N, >= 0) in
/// `tendons` (moment balance at the tip, tendon forces taken along the tangent):
/// `E I κ (cos φ, sin φ) = Σ τ_i d_i (cos β_i, sin β_i)`, axial strain `-Σ τ_i / E A`
/// (`ℓ = ℓ0 (1 - Σ τ_i / E A)`; `ℓ = ℓ0` if inextensible). `κ` is per deformed length, as in
/// The planar cable-arm paper. Returns `κ >= 0`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `tensions.len()`, `tensions[i]` (negative or not
/// finite), or `tensions` (compressed to zero length).
pub fn arc_from_tendon_tensions(
    tensions: &[f64],
    tendons: &PccTendons,
    body: &ElasticSegment,
) -> Result<PccSegment> {
    actuated_segment(tensions, tendons, body)
}

/// The 3×n Jacobian of [`arc_from_tendon_tensions`] with respect to the tensions (constant in
/// curvature-vector coordinates).
///
/// # Errors
/// As [`arc_from_tendon_tensions`], and naming `curvature` for arc coordinates at `κ = 0`.
pub fn arc_from_tendon_tensions_jacobian(
    tensions: &[f64],
    tendons: &PccTendons,
    body: &ElasticSegment,
    coordinates: ArcCoordinates,
) -> Result<Matrix3xX<f64>> {
    actuated_jacobian(tensions, tendons, body, coordinates)
}

/// The arc of a linear elastic uniform segment `body` with chamber `pressures` (Pa, gauge;
/// negative for vacuum): axial force `F = Σ p_i A_i`, moment `Σ p_i A_i r_i × z` (bending
/// away from a pressurised chamber), `E I u = moment`, `ℓ = ℓ0 (1 + F / E A)` (`ℓ0` if
/// inextensible). Returns `κ >= 0`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `pressures.len()`, `pressures[i]` (not finite), or
/// `pressures` (compressed to zero length).
pub fn arc_from_pressures(
    pressures: &[f64],
    chambers: &PccChambers,
    body: &ElasticSegment,
) -> Result<PccSegment> {
    actuated_segment(pressures, chambers, body)
}

/// The 3×n Jacobian of [`arc_from_pressures`] with respect to the pressures (constant in
/// curvature-vector coordinates).
///
/// # Errors
/// As [`arc_from_pressures`], and naming `curvature` for arc coordinates at `κ = 0`.
pub fn arc_from_pressures_jacobian(
    pressures: &[f64],
    chambers: &PccChambers,
    body: &ElasticSegment,
    coordinates: ArcCoordinates,
) -> Result<Matrix3xX<f64>> {
    actuated_jacobian(pressures, chambers, body, coordinates)
}
