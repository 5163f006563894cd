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
    guides: Vec<f64>,
    guide_friction: Vec<f64>,
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
            guides: Vec::new(),
            guide_friction: Vec::new(),
        })
    }

    /// The same tendon with the Coulomb friction coefficient `mu` (dimensionless, >= 0)
    /// between the tendon and its channel: the capstan law `|dτ/dσ| <= μ τ κ_path` along the
    /// path (see `cosserat::friction`). `0` (the default) is a frictionless tendon.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `friction` (outside `[0,`
    /// [`MAX_FRICTION`](crate::limits::MAX_FRICTION)`]`).
    pub fn with_friction(mut self, mu: f64) -> Result<Self> {
        crate::limits::check_friction("friction", mu)?;
        self.friction = mu;
        Ok(self)
    }

    /// Friction coefficient of the tendon in its channel (dimensionless, >= 0).
    pub fn friction(&self) -> f64 {
        self.friction
    }

    /// The same tendon routed through discrete guides (spacer disks) at the arc lengths
    /// `guides` (m, strictly increasing, in `(0, end)`; checked against the rod when the model
    /// is built) with the Coulomb coefficient `friction[g]` (dimensionless, >= 0) at guide `g`
    /// (one value for all, or one per guide). The tendon passes each guide at its routing
    /// offset `r(s_g)`, runs in straight chords between the base hole (`s = 0`), the guides
    /// and its termination, and at a guide of wrap angle `θ` (the angle between the chords)
    /// obeys the capstan law `τ_out ∈ [τ_in e^(−μ_g θ), τ_in e^(+μ_g θ)]`
    /// (see `cosserat::guides`). An empty `guides` is a tendon in a continuous channel.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `guides[g]` (not finite, <= 0 or not increasing) or
    /// `guide_friction` (a length other than 1 or `guides.len()`, or a value outside `[0,`
    /// [`MAX_FRICTION`](crate::limits::MAX_FRICTION)`]`).
    pub fn with_guides(mut self, guides: Vec<f64>, friction: &[f64]) -> Result<Self> {
        for (g, &s) in guides.iter().enumerate() {
            if !(s.is_finite() && s > 0.0) || (g > 0 && s <= guides[g - 1]) {
                return Err(Error::invalid(
                    format!("guides[{g}]"),
                    s,
                    "finite, > 0 m and strictly increasing",
                ));
            }
        }
        let per: Vec<f64> = match friction.len() {
            1 => vec![friction[0]; guides.len()],
            n if n == guides.len() => friction.to_vec(),
            n => {
                return Err(Error::invalid(
                    "guide_friction",
                    format!("{n} values"),
                    format!("1 or one per guide ({})", guides.len()),
                ))
            }
        };
        for (g, &mu) in per.iter().enumerate() {
            crate::limits::check_friction(&format!("guide_friction[{g}]"), mu)?;
        }
        self.guides = guides;
        self.guide_friction = if self.guides.is_empty() {
            Vec::new()
        } else {
            per
        };
        Ok(self)
    }

    /// Arc lengths (m) of the guides the tendon runs through; empty for a continuous channel.
    pub fn guides(&self) -> &[f64] {
        &self.guides
    }

    /// Friction coefficient at each guide (dimensionless, one per entry of [`Tendon::guides`]).
    pub fn guide_friction(&self) -> &[f64] {
        &self.guide_friction
    }

    /// The same tendon in a continuous channel (its guides dropped).
    pub(crate) fn without_guides(&self) -> Self {
        Self {
            guides: Vec::new(),
            guide_friction: Vec::new(),
            ..self.clone()
        }
    }

    /// Whether the tendon is routed through discrete guides (straight chords between them).
    pub fn is_guided(&self) -> bool {
        !self.guides.is_empty()
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

    /// How fast the routing turns about the backbone (rad/m): `2π / |pitch|` for a helix, 0
    /// for the other routings (a user function's rate varies along the rod:
    /// [`Tendon::turn_rate_at`]). The RK4 mesh must follow it as it follows the backbone's
    /// curvature (`cosserat::mesh`).
    pub fn turn_rate(&self) -> f64 {
        match self.routing {
            Routing::Helical { pitch, .. } => std::f64::consts::TAU / pitch.abs(),
            _ => 0.0,
        }
    }

    /// How fast the routing changes at `s` (m), in rad/m: [`Tendon::turn_rate`] for the
    /// closed-form routings, and for a user function `|r'(s)| / scale`, `scale` (m) the
    /// largest distance of its offset from the backbone (a helix's `2π / |pitch|`; an offset
    /// whose distance oscillates, its frequency; one crossing the backbone, the slow rate of
    /// its crossing); 0 where it is not finite.
    pub fn turn_rate_at(&self, s: f64, scale: f64) -> f64 {
        let Routing::Function { derivative, .. } = &self.routing else {
            return self.turn_rate();
        };
        let d = derivative(s);
        let rate = d[0].hypot(d[1]) / scale;
        if rate.is_finite() {
            rate
        } else {
            0.0
        }
    }
}
