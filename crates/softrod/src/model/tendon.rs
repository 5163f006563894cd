//! Tendons: routing and termination (the tension is an input, see [`crate::model::actuation`]).
//!
//! A tendon runs through the rod at the body-frame offset `r(s) = (x(s), y(s), 0)` from the
//! backbone (m), from the base (where it is pulled, see [`crate::model::Actuation`]) to its termination `end`
//! (m), where it is fixed to the rod. Its path is `p_i(s) = p(s) + R(s) r(s)`. It loads the
//! rod as in Rucker & Webster (2011): a distributed force from the curvature of its path, and a
//! point force and moment at its termination; see `cosserat.rs` for how the solver applies
//! them exactly.
//!
//! # References
//! D. C. Rucker, R. J. Webster III, "Statics and dynamics of continuum robots with general
//! tendon routing and external loading", IEEE Trans. Robotics 27(6), 2011.

use std::f64::consts::PI;
use std::fmt;
use std::sync::Arc;

use crate::error::{check_non_negative, check_positive, Error, Result};
use crate::model::section::SectionProperties;

/// A user function `s (m) -> (x, y)` (m, body frame); it must be thread-safe.
pub type OffsetFn = Arc<dyn Fn(f64) -> [f64; 2] + Send + Sync>;

/// How a tendon is routed: its body-frame offset `r(s)` (m) and derivative `r'(s)`.
#[derive(Clone)]
pub enum Routing {
    /// Constant offset `(x, y)` (m).
    Constant([f64; 2]),
    /// Offset `ratio * R(s) * (cos angle, sin angle)` proportional to the section's outer
    /// radius `R(s)` (the planar cable-arm paper's cable: `ratio = a`, `angle = 0`); `angle` in rad from body x.
    RadiusProportional {
        /// Offset over radius (dimensionless).
        ratio: f64,
        /// Angle from body x toward body y (rad).
        angle: f64,
    },
    /// Helix `radius * (cos(phase + 2 pi s / pitch), sin(phase + 2 pi s / pitch))`.
    /// A positive `pitch` (m per turn) is a right-handed helix about the body z axis (the angle
    /// grows with `s`: counter-clockwise seen from the tip looking toward the base), a negative
    /// one left-handed.
    Helical {
        /// Distance from the backbone (m).
        radius: f64,
        /// Arc length per full turn (m), signed by handedness; nonzero.
        pitch: f64,
        /// Angle at `s = 0` from body x toward body y (rad).
        phase: f64,
    },
    /// User offset `r(s)` and its exact derivative `r'(s)` (dimensionless).
    Function {
        /// `s -> (x, y)` (m).
        offset: OffsetFn,
        /// `s -> (dx/ds, dy/ds)`.
        derivative: OffsetFn,
    },
}

impl fmt::Debug for Routing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Routing::Constant(r) => write!(f, "Constant({r:?})"),
            Routing::RadiusProportional { ratio, angle } => {
                write!(f, "RadiusProportional(ratio={ratio}, angle={angle})")
            }
            Routing::Helical {
                radius,
                pitch,
                phase,
            } => write!(f, "Helical(radius={radius}, pitch={pitch}, phase={phase})"),
            Routing::Function { .. } => write!(f, "Function(<fn>, <fn>)"),
        }
    }
}

impl Routing {
    /// Offset `r(s)` and derivative `r'(s)` for a section with properties `props` at `s`.
    #[inline]
    pub fn offset(&self, s: f64, props: &SectionProperties) -> ([f64; 2], [f64; 2]) {
        match self {
            Routing::Constant(r) => (*r, [0.0, 0.0]),
            Routing::RadiusProportional { ratio, angle } => {
                let (sn, cs) = angle.sin_cos();
                let d = ratio * props.radius;
                let dd = ratio * props.radius_rate;
                ([d * cs, d * sn], [dd * cs, dd * sn])
            }
            Routing::Helical {
                radius,
                pitch,
                phase,
            } => {
                let w = 2.0 * PI / pitch;
                let (sn, cs) = (phase + w * s).sin_cos();
                (
                    [radius * cs, radius * sn],
                    [-radius * w * sn, radius * w * cs],
                )
            }
            Routing::Function { offset, derivative } => (offset(s), derivative(s)),
        }
    }
}

/// One tendon: routing and termination (`Tendon(offset, tension, end=None)` in Python, where
/// the tension becomes the actuation input).
#[derive(Clone, Debug)]
pub struct Tendon {
    routing: Routing,
    end: Option<f64>,
    friction: f64,
}

impl Tendon {
    /// A tendon with the given routing and termination `end` (m, in `(0, L]`; `None` for the
    /// tip). `end <= L` is checked when the robot model is built.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `end` (not finite or <= 0), or the routing parameter
    /// that is invalid (`ratio`, `angle`, `radius`, `pitch`, `phase`, `offset`: not finite;
    /// `radius`, `ratio` negative; `pitch` zero).
    pub fn new(routing: Routing, end: Option<f64>) -> Result<Self> {
        if let Some(e) = end {
            check_positive("end", e, "m")?;
        }
        match &routing {
            Routing::Constant(r) => {
                for k in 0..2 {
                    if !r[k].is_finite() {
                        return Err(Error::invalid(format!("offset[{k}]"), r[k], "finite (m)"));
                    }
                }
            }
            Routing::RadiusProportional { ratio, angle } => {
                check_non_negative("ratio", *ratio, "")?;
                if !angle.is_finite() {
                    return Err(Error::invalid("angle", angle, "finite (rad)"));
                }
            }
            Routing::Helical {
                radius,
                pitch,
                phase,
            } => {
                check_non_negative("radius", *radius, "m")?;
                if !(pitch.is_finite() && *pitch != 0.0) {
                    return Err(Error::invalid(
                        "pitch",
                        pitch,
                        "finite and nonzero (m/turn)",
                    ));
                }
                if !phase.is_finite() {
                    return Err(Error::invalid("phase", phase, "finite (rad)"));
                }
            }
            Routing::Function { .. } => {}
        }
        Ok(Self {
            routing,
            end,
            friction: 0.0,
        })
    }

    /// The same tendon with the Coulomb friction coefficient `mu` (dimensionless, >= 0)
    /// between the tendon and its channel: the capstan law `|dτ/dσ| <= μ τ κ_path` along the
    /// path (see `cosserat::friction`). `0` (the default) is a frictionless tendon.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `friction` (not finite or negative).
    pub fn with_friction(mut self, mu: f64) -> Result<Self> {
        check_non_negative("friction", mu, "")?;
        self.friction = mu;
        Ok(self)
    }

    /// Friction coefficient of the tendon in its channel (dimensionless, >= 0).
    pub fn friction(&self) -> f64 {
        self.friction
    }

    /// Tendon at the constant offset `(x, y)` (m).
    ///
    /// # Errors
    /// As [`Tendon::new`].
    pub fn constant(offset: [f64; 2], end: Option<f64>) -> Result<Self> {
        Self::new(Routing::Constant(offset), end)
    }

    /// Routing.
    pub fn routing(&self) -> &Routing {
        &self.routing
    }
    /// Termination (m), `None` for the tip.
    pub fn end(&self) -> Option<f64> {
        self.end
    }
}
