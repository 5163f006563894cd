//! Pneumatic chambers: pressurised cavities running along the rod.
//!
//! A chamber is a cavity of the rod between the arc lengths `start` and `end` (its end caps),
//! filled with fluid at the gauge pressure `p` (Pa), whose intersection with the rod's
//! cross-section at `s` has area `A_c(s)` (m², constant or a function of `s`) and centroid at
//! the constant body-frame offset `r_c = (x, y)` (m) from the backbone.
//!
//! # Model
//! Cut the rod *and the fluid* by the cross-section plane at `s` (normal `d3 = R e_z`). The
//! fluid's stress is isotropic, `-p I`, so across the cut it carries the force `-p A_c d3`
//! applied at the centroid `p + R r_c`; the rod's own internal wrench is what remains of the
//! total one:
//!
//! ```text
//! N = n - Σ p A_c d3,     M = m - Σ (R r_c) × p A_c d3,
//! ```
//!
//! and `N`, `M` obey the plain equilibrium equations of the rod (the pressure on the walls and
//! caps is internal to "rod + fluid"). In body components the fluid's share is the constant
//! `(-p A_c e_z, -p A_c r_c × e_z)`: it does not depend on the strains, so the constitutive
//! solve and the shooting Jacobian need nothing new. Differentiating `n = N + p A_c d3` gives
//! the loads the fluid puts on the rod: on the side walls `-(p A_c d3)'` per unit length (for a
//! chamber bent with the rod, `p A_c` times the curvature, pointing away from the centre of
//! curvature; for a varying section, the axial push `-p A_c' d3` on the sloping wall) and, at
//! the caps, the point forces `+p A_c d3` at `end` and `-p A_c d3` at `start` with their
//! moments: exactly the jumps of `n` where the fluid term enters and leaves the sum. The set is
//! self-equilibrated: a chamber alone changes no reaction at the base.
//!
//! Compared with a tendon (Rucker & Webster 2011) of tension `-p A_c` along the chamber's
//! centre line `p + R r_c`: the two agree when the centre line stays parallel to `d3` (no shear,
//! no twist, constant offset), and differ otherwise, because a fluid column transmits its
//! pressure normal to the cut, not along its own axis.
//!
//! Assumptions: rigid cross-sections (the Cosserat kinematics), uniform pressure (statics),
//! thin walls whose own stiffness is part of the rod's section, no radial ballooning and no
//! inextensible fibre reinforcement of the chamber walls (which would carry part of the cap
//! force), `A_c` measured in the rod's cross-section plane.

use std::fmt;
use std::sync::Arc;

use crate::error::{check_finite, check_non_negative, check_positive, Error, Result};
use crate::model::rod::{Rod, FUNCTION_CHECKS};

/// Standard atmospheric pressure (Pa): the lowest gauge pressure a chamber can hold (vacuum).
pub const ATMOSPHERIC_PRESSURE: f64 = 101_325.0;

/// A user function `s (m) -> A_c (m²)`; it must be thread-safe.
pub type AreaFn = Arc<dyn Fn(f64) -> f64 + Send + Sync>;

/// Cross-section area of a chamber: constant or a function of the arc length.
#[derive(Clone)]
pub enum ChamberArea {
    /// The same area (m²) everywhere.
    Constant(f64),
    /// A user function `s -> A_c(s)` (m²), checked positive on a grid at solve time.
    Function(AreaFn),
}

impl fmt::Debug for ChamberArea {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ChamberArea::Constant(a) => write!(f, "{a}"),
            ChamberArea::Function(_) => write!(f, "<fn>"),
        }
    }
}

/// One pneumatic chamber: cavity geometry (`Chamber(pressure, area, offset, start=0, end=None)`
/// in Python, where the pressure becomes the actuation input).
#[derive(Clone, Debug)]
pub struct Chamber {
    area: ChamberArea,
    offset: [f64; 2],
    start: f64,
    end: Option<f64>,
}

/// Checks a gauge pressure (Pa): finite and `>= -`[`ATMOSPHERIC_PRESSURE`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`.
pub fn check_pressure(name: impl std::fmt::Display, pressure: f64) -> Result<f64> {
    if !pressure.is_finite() {
        check_finite(&name.to_string(), pressure)?;
    }
    if pressure < -ATMOSPHERIC_PRESSURE {
        return Err(Error::invalid(
            name.to_string(),
            pressure,
            format!(">= -{ATMOSPHERIC_PRESSURE} Pa (gauge; below is more than vacuum)"),
        ));
    }
    Ok(pressure)
}

impl Chamber {
    /// A chamber with cross-section `area` (m²), centroid `offset` (m, body frame) and extent
    /// `[start, end]` (m; `end = None` for the tip). That the extent lies in `[0, L]` and the
    /// chamber inside the section is checked when the robot model is built.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `area`, `offset[k]`, `start` (finite, >= 0) or `end`
    /// (finite, > start).
    pub fn new(area: ChamberArea, offset: [f64; 2], start: f64, end: Option<f64>) -> Result<Self> {
        if let ChamberArea::Constant(a) = area {
            check_positive("area", a, "m^2")?;
        }
        for (k, v) in offset.iter().enumerate() {
            check_finite(&format!("offset[{k}]"), *v)?;
        }
        check_non_negative("start", start, "m")?;
        if let Some(e) = end {
            if !(e.is_finite() && e > start) {
                return Err(Error::invalid(
                    "end",
                    e,
                    format!("finite and > start = {start} m"),
                ));
            }
        }
        Ok(Self {
            area,
            offset,
            start,
            end,
        })
    }

    /// A chamber of constant `area` (m²) over the whole rod.
    ///
    /// # Errors
    /// As [`Chamber::new`].
    pub fn constant(area: f64, offset: [f64; 2]) -> Result<Self> {
        Self::new(ChamberArea::Constant(area), offset, 0.0, None)
    }

    /// Cross-section area.
    pub fn area(&self) -> &ChamberArea {
        &self.area
    }
    /// Centroid offset `(x, y)` (m, body frame).
    pub fn offset(&self) -> [f64; 2] {
        self.offset
    }
    /// Start of the chamber (m).
    pub fn start(&self) -> f64 {
        self.start
    }
    /// End of the chamber (m), `None` for the tip.
    pub fn end(&self) -> Option<f64> {
        self.end
    }

    /// Area `A_c(s)` (m²).
    #[inline]
    pub fn area_at(&self, s: f64) -> f64 {
        match &self.area {
            ChamberArea::Constant(a) => *a,
            ChamberArea::Function(f) => f(s),
        }
    }

    /// Body-frame wrench `[-p A_c e_z; -p A_c r_c × e_z]` carried across the section at `s` by
    /// the fluid at gauge `pressure` (Pa).
    #[inline]
    pub(crate) fn fluid_wrench(&self, s: f64, pressure: f64) -> [f64; 6] {
        let f = -pressure * self.area_at(s);
        let [x, y] = self.offset;
        // r × e_z = (y, -x, 0).
        [0.0, 0.0, f, f * y, -f * x, 0.0]
    }
}

/// Validates `chambers` for `rod`, returning their extents `(start, end)` (m).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `chambers[i].start` / `chambers[i].end` outside
/// `[0, L]`, `chambers[i].area(s)` (non-positive, non-finite, or wider than a disk of radius
/// [`MAX_OFFSET_RATIO`](crate::limits::MAX_OFFSET_RATIO) `L`) or
/// `chambers[i].offset` for a chamber not inside the section: the disk of area `A_c` at the
/// offset must fit in the outer radius `sqrt(R(s)² + Σ A_c/π)`, with `R(s)` the section's radius
/// (its outer radius for circles and tubes, that of the circle of its area for tables and
/// functions, whose area may exclude the voids).
pub(crate) fn validate(chambers: &[Chamber], rod: &Rod) -> Result<Vec<(f64, f64)>> {
    let l = rod.length();
    let mut extents = Vec::with_capacity(chambers.len());
    for (i, c) in chambers.iter().enumerate() {
        let end = c.end.unwrap_or(l);
        if c.start >= l {
            return Err(Error::invalid(
                format!("chambers[{i}].start"),
                c.start,
                format!("in [0, length) = [0, {l}) m"),
            ));
        }
        if !(end > c.start && end <= l) {
            return Err(Error::invalid(
                format!("chambers[{i}].end"),
                end,
                format!("in (start, length] = ({}, {l}] m", c.start),
            ));
        }
        extents.push((c.start, end));
    }
    for (i, c) in chambers.iter().enumerate() {
        let (a, b) = extents[i];
        for k in 0..=FUNCTION_CHECKS {
            let s = a + (b - a) * k as f64 / FUNCTION_CHECKS as f64;
            let area = c.area_at(s);
            if !(area.is_finite() && area > 0.0) {
                return Err(Error::invalid(
                    format!("chambers[{i}].area({s})"),
                    area,
                    "finite and > 0 m^2",
                ));
            }
            let widest = std::f64::consts::PI * (crate::limits::MAX_OFFSET_RATIO * l).powi(2);
            if area > widest {
                return Err(Error::invalid(
                    format!("chambers[{i}].area({s})"),
                    area,
                    format!(
                        "<= pi ({} L)^2 = {widest:.4e} m^2 (a chamber wider than the rod is long \
                         is no slender robot's)",
                        crate::limits::MAX_OFFSET_RATIO
                    ),
                ));
            }
            let props = rod.section_at(s);
            let voids: f64 = chambers
                .iter()
                .zip(&extents)
                .filter(|(_, (a, b))| *a <= s && s <= *b)
                .map(|(c, _)| c.area_at(s))
                .sum();
            let outer = (props.radius * props.radius + voids / std::f64::consts::PI).sqrt();
            let reach = c.offset[0].hypot(c.offset[1]) + (area / std::f64::consts::PI).sqrt();
            if reach > outer {
                return Err(Error::invalid(
                    format!("chambers[{i}].offset"),
                    format!("{:?}", c.offset),
                    format!(
                        "inside the section at s = {s} m: |offset| + sqrt(area/pi) = {reach:.6e} \
                         m must be <= the outer radius {outer:.6e} m"
                    ),
                ));
            }
        }
    }
    Ok(extents)
}
