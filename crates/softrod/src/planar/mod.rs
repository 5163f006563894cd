//! The planar cable-arm paper: the planar steady-state model of a tapered cable-driven arm.
//!
//! A silicone cone of length `L` with radius `R(s) = R0 + (RL - R0) s / L`, one cable at
//! distance `a R(s)` from the backbone, anchored at `s = anchor` (default the tip) and pulled at
//! the base with tension `T`. Planar, no gravity, linear material `E`. Along the undeformed arc
//! length `s`:
//!
//! * curvature (per deformed length) `k(s) = T a R / (E pi R^4 / 4 + T a^2 R^2)`,
//! * axial strain `q(s) = T (a R k - 1) / (E pi R^2)`,
//! * tangent angle `theta(s) = int_0^s (1 + q) k ds`,
//! * backbone `x' = (1 + q) cos theta`, `y' = (1 + q) sin theta` (x along the unloaded arm,
//!   y toward the cable).
//!
//! Beyond the anchor the arm is unloaded and straight. `k` is either evaluated in closed form or
//! obtained from the published final-value ODE (with the final value's typo corrected,
//! `R(L)^4`), integrated from the anchor to the base with the adaptive driver of [`crate::integrate`] and the Bogacki–Shampine tableau.
//!
//! The backbone (`theta`, `x`, `y`) is integrated by Lobatto IIIA collocation on panels no
//! longer than the output spacing: 3 stages (order 4) where the tangent turns by less than
//! 0.023 rad per panel, else 4 stages (order 6) on panels turning by at most
//! [`MAX_PANEL_TURN`] rad, whichever needs fewer evaluations. Both keep the backbone error
//! below about `1e-10 L`. Panels break at the anchor, where `k` jumps.
//!
//! # References
//! The planar cable-arm paper and its corrections (docs/planar.md).

use std::f64::consts::PI;

use rayon::prelude::*;

pub mod sensitivity;
pub use sensitivity::{planar_sensitivities, PlanarParameter, PlanarSensitivities};

use crate::error::{check_positive, Error, Result};
use crate::integrate::driver::adaptive_dense;
use crate::integrate::{AdaptiveOptions, FnSystem, IntegrationStats, BS3};
use crate::math::samples::in_range;

/// Largest tangent-angle change (rad) allowed across one backbone-integration panel.
///
/// With the order-6 panel rule this keeps the backbone error below 1e-10 of the arm length.
pub const MAX_PANEL_TURN: f64 = 0.1;

/// The planar cable-arm paper's tapered cable-driven arm (immutable, validated).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarCableArm {
    length: f64,
    base_radius: f64,
    tip_radius: f64,
    offset_ratio: f64,
    youngs_modulus: f64,
    anchor: f64,
    /// `dR/ds = (RL - R0) / L`, cached so that `R(s)` costs no division.
    taper: f64,
}

/// Largest relative error of the strain that the ODE method may inherit from its curvature
/// ([`PlanarCableArm::check_ode_tension`]).
pub const ODE_STRAIN_ERROR: f64 = 1e-3;

/// How the curvature profile `k(s)` is evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlanarMethod {
    /// The closed form `k = T a R / (E pi R^4 / 4 + T a^2 R^2)`.
    ClosedForm,
    /// The published final-value ODE, integrated from the anchor to the base with the adaptive
    /// Bogacki–Shampine 3(2) pair (MATLAB `ode23`'s method) at the given tolerances.
    Ode(AdaptiveOptions),
}

/// Samples of one solved arm. All arrays have the length of the requested samples.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarSolution {
    /// Cable tension `T` (N).
    pub tension: f64,
    /// Undeformed arc length of each sample (m).
    pub s: Vec<f64>,
    /// Curvature `k` per deformed length (1/m); zero beyond the anchor.
    pub curvature: Vec<f64>,
    /// Axial strain `q` (dimensionless, negative in compression); zero beyond the anchor.
    pub strain: Vec<f64>,
    /// Tangent angle `theta` from the x axis toward the cable (rad).
    pub angle: Vec<f64>,
    /// Backbone x, along the unloaded arm (m).
    pub x: Vec<f64>,
    /// Backbone y, toward the cable (m).
    pub y: Vec<f64>,
    /// Tip position `(x, y)` at `s = L` (m).
    pub tip: [f64; 2],
    /// Tangent angle at the tip (rad).
    pub tip_angle: f64,
    /// Integrator statistics of the ODE path (`None` for the closed form).
    pub ode_stats: Option<IntegrationStats>,
}

impl PlanarSolution {
    /// Largest compressive axial strain, `max(-q)` (dimensionless, >= 0).
    pub fn max_compressive_strain(&self) -> f64 {
        self.strain.iter().fold(0.0f64, |m, &q| m.max(-q))
    }
}

/// Many tensions solved on one set of samples; 2-D arrays are row-major `(tensions, samples)`.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarBatch {
    /// Tensions (N), one per row.
    pub tensions: Vec<f64>,
    /// Undeformed arc length of each sample (m), shared by all rows.
    pub s: Vec<f64>,
    /// Curvature (1/m), `tensions.len() * s.len()`.
    pub curvature: Vec<f64>,
    /// Axial strain, `tensions.len() * s.len()`.
    pub strain: Vec<f64>,
    /// Tangent angle (rad), `tensions.len() * s.len()`.
    pub angle: Vec<f64>,
    /// Backbone x (m), `tensions.len() * s.len()`.
    pub x: Vec<f64>,
    /// Backbone y (m), `tensions.len() * s.len()`.
    pub y: Vec<f64>,
    /// Tip positions `(x, y)` (m), one per tension.
    pub tip: Vec<[f64; 2]>,
    /// Tip tangent angles (rad), one per tension.
    pub tip_angle: Vec<f64>,
}

impl PlanarCableArm {
    /// Builds and validates an arm.
    ///
    /// * `length` `L` (m), `base_radius` `R0` and `tip_radius` `RL` (m): all finite and > 0;
    /// * `offset_ratio` `a` in `[0, 1)`: the cable runs at `a R(s)` from the backbone;
    /// * `youngs_modulus` `E` (Pa) > 0;
    /// * `anchor` (m) in `(0, L]`, `None` for the tip.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range.
    pub fn new(
        length: f64,
        base_radius: f64,
        tip_radius: f64,
        offset_ratio: f64,
        youngs_modulus: f64,
        anchor: Option<f64>,
    ) -> Result<Self> {
        crate::limits::check_length("length", length, false)?;
        check_positive("base_radius", base_radius, "m")?;
        check_positive("tip_radius", tip_radius, "m")?;
        if !(offset_ratio.is_finite() && (0.0..1.0).contains(&offset_ratio)) {
            return Err(Error::invalid("offset_ratio", offset_ratio, "in [0, 1)"));
        }
        crate::limits::check_modulus("youngs_modulus", youngs_modulus)?;
        // The bending stiffness E pi R^4 / 4 at both ends must be a finite nonzero float (a
        // radius of 1e-100 m or 1e100 m is positive but under- or overflows it).
        for (name, r) in [("base_radius", base_radius), ("tip_radius", tip_radius)] {
            let i = PI * r.powi(4) / 4.0;
            if !(i.is_finite() && i > f64::MIN_POSITIVE) {
                return Err(Error::invalid(
                    name,
                    r,
                    "finite and > 0 m, with pi R^4 / 4 a finite nonzero float",
                ));
            }
            let ei = youngs_modulus * i;
            if !(ei.is_finite() && ei > f64::MIN_POSITIVE) {
                return Err(Error::invalid(
                    "youngs_modulus",
                    youngs_modulus,
                    format!("finite and > 0 Pa, with E pi R^4 / 4 finite and nonzero at {name}"),
                ));
            }
        }
        let anchor = anchor.unwrap_or(length);
        if !(anchor.is_finite() && anchor > 0.0 && anchor <= length) {
            return Err(Error::invalid(
                "anchor",
                anchor,
                format!("in (0, length] = (0, {length}] m"),
            ));
        }
        Ok(Self {
            length,
            base_radius,
            tip_radius,
            offset_ratio,
            youngs_modulus,
            anchor,
            taper: (tip_radius - base_radius) / length,
        })
    }

    /// The experimental arm of *Planar steady-state physical model for a soft cable-driven
    /// octopus-like arm manipulator*: `L = 270 mm`, `R0 = 15 mm`, `RL = 7.4 mm`, `a = 1/3`,
    /// `E = 110 kPa`, cable anchored at the tip.
    pub fn published_arm() -> Self {
        Self {
            length: 0.270,
            base_radius: 0.015,
            tip_radius: 0.0074,
            offset_ratio: 1.0 / 3.0,
            youngs_modulus: 110e3,
            anchor: 0.270,
            taper: (0.0074 - 0.015) / 0.270,
        }
    }

    /// The same arm as [`Self::published_arm`] (its earlier name, kept working).
    pub fn seed_arm() -> Self {
        Self::published_arm()
    }

    /// Arm length `L` (m).
    pub fn length(&self) -> f64 {
        self.length
    }
    /// Base radius `R0` (m).
    pub fn base_radius(&self) -> f64 {
        self.base_radius
    }
    /// Tip radius `RL` (m).
    pub fn tip_radius(&self) -> f64 {
        self.tip_radius
    }
    /// Cable offset ratio `a` (dimensionless).
    pub fn offset_ratio(&self) -> f64 {
        self.offset_ratio
    }
    /// Young's modulus `E` (Pa).
    pub fn youngs_modulus(&self) -> f64 {
        self.youngs_modulus
    }
    /// Cable anchor arc length (m).
    pub fn anchor(&self) -> f64 {
        self.anchor
    }

    /// Section radius `R(s)` (m), linear taper.
    #[inline]
    pub fn radius(&self, s: f64) -> f64 {
        self.base_radius + self.taper * s
    }

    /// Section radius `R(s)` (m) at an arc length `s` checked to lie in `[0, L]` (round-off
    /// at the ends clamped): the taper is not extrapolated beyond the arm.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `name` if `s` is not finite or outside `[0, L]`.
    pub fn radius_at(&self, name: impl FnOnce() -> String, s: f64) -> Result<f64> {
        Ok(self.radius(in_range(name, s, self.length)?))
    }

    /// Smallest section radius over the loaded part `[0, anchor]` (m): the taper is linear,
    /// so the smaller of `R(0)` and `R(anchor)`.
    #[inline]
    fn min_loaded_radius(&self) -> f64 {
        self.radius(0.0).min(self.radius(self.anchor))
    }

    /// Relative taper rate `|R'| / R_min` over the loaded part (1/m), the bound on how fast the
    /// profile varies with the section that the panel counts of both marches use.
    #[inline]
    fn relative_taper(&self) -> f64 {
        self.taper.abs() / self.min_loaded_radius()
    }

    /// Taper rate `dR/ds` (dimensionless).
    #[inline]
    pub fn radius_rate(&self) -> f64 {
        self.taper
    }

    /// Closed-form curvature `k(s)` (1/m) and axial strain `q(s)` at `s <= anchor`.
    ///
    /// Uses `q = T (a R k - 1) / (E pi R^2) = -T / (4 D)` with `D = E pi R^2 / 4 + T a^2`
    /// and `k = T a / (R D)`, one division per call.
    #[inline]
    pub fn closed_form(&self, s: f64, tension: f64) -> (f64, f64) {
        let r = self.radius(s);
        let a = self.offset_ratio;
        let d = 0.25 * self.youngs_modulus * PI * r * r + tension * a * a;
        let inv_rd = 1.0 / (r * d);
        (tension * a * inv_rd, -0.25 * tension * r * inv_rd)
    }

    /// Axial strain `q = T (a R k - 1) / (E pi R^2)` for a given curvature `k` (eq. 1 of the planar cable-arm paper).
    #[inline]
    pub fn strain(&self, s: f64, curvature: f64, tension: f64) -> f64 {
        let r = self.radius(s);
        tension * (self.offset_ratio * r * curvature - 1.0) / (self.youngs_modulus * PI * r * r)
    }

    /// Final value of the ODE, `k(anchor) = T a R / (T a^2 R^2 + E (pi/4) R^4)` (1/m), with
    /// the paper's `R(L)^2` corrected to `R(L)^4`.
    pub fn final_value(&self, tension: f64) -> f64 {
        let r = self.radius(self.anchor);
        let a = self.offset_ratio;
        tension * a * r / (tension * a * a * r * r + self.youngs_modulus * PI / 4.0 * r.powi(4))
    }

    /// Right-hand side of the published ODE, `dk/ds` (1/m^2), term by term as printed:
    /// `k Rdot R (-E pi R^2 - 2 T a^2) / (R^2 (E pi/4 R^2 + T a^2))
    ///  + T a Rdot / (R^2 (E pi/4 R^2 + T a^2))`.
    #[inline]
    pub fn curvature_rate(&self, s: f64, curvature: f64, tension: f64) -> f64 {
        let r = self.radius(s);
        let rd = self.radius_rate();
        let (e, a) = (self.youngs_modulus, self.offset_ratio);
        let den = r * r * (e * PI / 4.0 * r * r + tension * a * a);
        curvature * rd * r * (-e * PI * r * r - 2.0 * tension * a * a) / den
            + tension * a * rd / den
    }

    /// Validates a tension: finite, >= 0, and small enough that `1 + q > 0` along the arm
    /// (the linear model stops making sense when the arm is compressed to zero length).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `tension`.
    pub fn check_tension(&self, tension: f64) -> Result<f64> {
        if !(tension.is_finite() && tension >= 0.0) {
            return Err(Error::invalid("tension", tension, "finite and >= 0 N"));
        }
        let limit = self.max_tension();
        if tension >= limit {
            return Err(Error::invalid(
                "tension",
                tension,
                format!("< {limit:.6e} N (axial strain would reach -1)"),
            ));
        }
        Ok(tension)
    }

    /// The tension checked for the ODE method at the relative tolerance `rtol`: the strain
    /// `q = T (a R k - 1) / (E pi R^2)` is a difference that cancels as `T` grows (`a R k`
    /// tends to 1), so `k`'s relative error reaches `q` multiplied by `4 T a^2 / (E pi R^2)`;
    /// above [`ODE_STRAIN_ERROR`] at the thinnest loaded section the strain, and the shape,
    /// would be digits of the integration error (at `a = 0.6` and `T = 1e12` N the ODE's strain
    /// was -153). The closed form has no such limit.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `tension` above that bound.
    pub fn check_ode_tension(&self, tension: f64, rtol: f64) -> Result<()> {
        let r = self.min_loaded_radius();
        let a2 = self.offset_ratio * self.offset_ratio;
        let amplification = 4.0 * tension * a2 / (self.youngs_modulus * PI * r * r);
        if amplification * rtol <= ODE_STRAIN_ERROR {
            return Ok(());
        }
        let limit = ODE_STRAIN_ERROR / rtol * self.youngs_modulus * PI * r * r / (4.0 * a2);
        Err(Error::invalid(
            "tension",
            tension,
            format!(
                "<= {limit:.6e} N for the ODE method at rtol = {rtol:e} (its strain \
                 T (a R k - 1) / (E pi R^2) cancels: k's error is multiplied by \
                 4 T a^2 / (E pi R^2) = {amplification:.3e}); the closed form has no such limit"
            ),
        ))
    }

    /// The absolute tolerance `atol` (1/m) checked for the ODE method: an error of the
    /// curvature up to `atol` everywhere turns the tip by up to `atol L` (rad); above
    /// [`ODE_STRAIN_ERROR`] the shape would be digits of the tolerance (`atol = 1` moved the
    /// published arm's tip 18 mm at 2 N).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `atol` above that bound.
    pub fn check_ode_atol(&self, atol: f64) -> Result<()> {
        let limit = ODE_STRAIN_ERROR / self.length;
        if atol <= limit {
            return Ok(());
        }
        Err(Error::invalid(
            "atol",
            atol,
            format!(
                "<= {limit:.6e} 1/m for the ODE method (the curvature's absolute error turns \
                 the tip by up to atol L = {:.3e} rad)",
                atol * self.length
            ),
        ))
    }

    /// Supremum of the tension for which `1 + q > 0` along the loaded part (N);
    /// infinite when `a >= 1/2`.
    pub fn max_tension(&self) -> f64 {
        let r_min = self.min_loaded_radius();
        let a2 = self.offset_ratio * self.offset_ratio;
        let c = 1.0 - 4.0 * a2;
        if c <= 0.0 {
            f64::INFINITY
        } else {
            self.youngs_modulus * PI * r_min * r_min / c
        }
    }
}

pub use crate::math::samples::uniform_samples;

/// Checks user-given arc lengths: non-decreasing, in `[0, length]` (round-off at the ends
/// clamped, see [`crate::math::samples::in_range`]).
pub(crate) fn check_samples(samples: &[f64], length: f64) -> Result<Vec<f64>> {
    if samples.is_empty() {
        return Err(Error::invalid("s", "[]", "at least one arc length"));
    }
    let mut prev = 0.0;
    let mut out = Vec::with_capacity(samples.len());
    for (i, &s) in samples.iter().enumerate() {
        let s = in_range(|| format!("s[{i}]"), s, length)?;
        if s < prev {
            return Err(Error::invalid(
                format!("s[{i}]"),
                s,
                format!("non-decreasing and in [0, length] = [0, {length}] m"),
            ));
        }
        out.push(s);
        prev = s;
    }
    Ok(out)
}

/// `max(1, ceil(x))` for `x >= 0` without libm (baseline x86-64 has no rounding instruction).
#[inline]
fn panel_count(x: f64) -> usize {
    // Through i32 (one instruction each way); panel counts beyond 2^30 are not meaningful.
    let x = x.min(1073741824.0);
    let i = x as i32; // NaN -> 0
    (if (i as f64) < x { i + 1 } else { i.max(1) }) as usize
}

/// `(cos x, sin x)` for `|x| <= 0.2` by truncated Taylor series, else libm.
///
/// The truncation error (`x^8 / 8!` < 7e-11 at 0.2, < 3e-13 at [`MAX_PANEL_TURN`]) moves the
/// backbone by at most `L` times that, below the panel rule's own error.
#[inline]
fn small_angle_cis<const SHORT: bool>(x: f64) -> (f64, f64) {
    let x2 = x * x;
    if SHORT && x2 <= SHORT_CIS_MAX * SHORT_CIS_MAX {
        // |x| <= 0.03: error x^6 / 720 < 1.1e-12.
        let c = 1.0 - x2 * (1.0 / 2.0) * (1.0 - x2 * (1.0 / 12.0));
        let s = x * (1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0)));
        return (c, s);
    }
    if x2 > 0.04 {
        let (s, c) = x.sin_cos();
        return (c, s);
    }
    let c = 1.0 - x2 * (1.0 / 2.0) * (1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0)));
    let s = x * (1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0) * (1.0 - x2 * (1.0 / 42.0))));
    (c, s)
}

/// Largest angle (rad) for the short series of [`small_angle_cis`].
const SHORT_CIS_MAX: f64 = 0.03;

/// A Lobatto IIIA collocation rule with `S` stages (nodes include both panel ends, so the
/// first stage reuses the previous panel's last evaluation).
struct Rule<const S: usize> {
    /// Nodes in `[0, 1]`.
    c: [f64; S],
    /// Stage matrix rows 2..=S (row 1 is zero).
    a: [[f64; S]; S],
    /// Weights (equal to the last row of the stage matrix).
    b: [f64; S],
    /// Largest tangent turn (rad) per panel that keeps this rule's backbone error below
    /// `1e-10 L`: its global error is about `L (h kappa)^p / C_p` (`p` the order).
    max_turn: f64,
    /// Largest relative change of the section radius per panel, `h |R'| / R_min`: the
    /// curvature varies like `R^-3`, so this bounds the quadrature error of a slowly turning
    /// but strongly tapered arm (calibrated against an RK4 reference, see the tests).
    max_taper: f64,
}

/// How fast the integrand varies along the arm (1/m): the largest tangent turning rate
/// `|(1 + q) k|` and the taper rate `|R'| / R_min`.
#[derive(Clone, Copy)]
struct Rates {
    turn: f64,
    taper: f64,
}

const SQ5: f64 = 2.236_067_977_499_79;

/// Lobatto IIIA, 3 stages (Simpson), order 4: error `L (h kappa)^4 / 2880`.
const LOBATTO3: Rule<3> = Rule {
    c: [0.0, 0.5, 1.0],
    a: [
        [0.0, 0.0, 0.0],
        [5.0 / 24.0, 1.0 / 3.0, -1.0 / 24.0],
        [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    ],
    b: [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    max_turn: 0.023,
    max_taper: 0.006,
};

/// Lobatto IIIA, 4 stages, order 6 (also the rule of the sensitivity march).
const LOBATTO4: Rule<4> = Rule {
    c: [0.0, (5.0 - SQ5) / 10.0, (5.0 + SQ5) / 10.0, 1.0],
    a: [
        [0.0, 0.0, 0.0, 0.0],
        [
            (11.0 + SQ5) / 120.0,
            (25.0 - SQ5) / 120.0,
            (25.0 - 13.0 * SQ5) / 120.0,
            (-1.0 + SQ5) / 120.0,
        ],
        [
            (11.0 - SQ5) / 120.0,
            (25.0 + 13.0 * SQ5) / 120.0,
            (25.0 + SQ5) / 120.0,
            (-1.0 - SQ5) / 120.0,
        ],
        [1.0 / 12.0, 5.0 / 12.0, 5.0 / 12.0, 1.0 / 12.0],
    ],
    b: [1.0 / 12.0, 5.0 / 12.0, 5.0 / 12.0, 1.0 / 12.0],
    max_turn: MAX_PANEL_TURN,
    max_taper: 0.04,
};

/// State of the backbone integration: arc length, angle, unit tangent, position, and the
/// profile `(k, q)` at the current arc length.
#[derive(Clone, Copy)]
struct BackboneState {
    s: f64,
    theta: f64,
    cos: f64,
    sin: f64,
    x: f64,
    y: f64,
    k: f64,
    q: f64,
}

impl BackboneState {
    /// Advances over `[self.s, b]` (all of it loaded), choosing the cheaper of the order-4
    /// and order-6 rules that meets its turn bound (fine output spacing favours order 4,
    /// coarse spacing or high curvature order 6).
    #[inline]
    fn advance_loaded<P: Fn(f64) -> (f64, f64)>(&mut self, profile: &P, b: f64, rates: Rates) {
        let span = b - self.s;
        if span <= 0.0 {
            return;
        }
        let (turn, taper) = (span * rates.turn, span * rates.taper);
        if turn <= LOBATTO3.max_turn && taper <= LOBATTO3.max_taper {
            // One Simpson panel: the common case at fine output spacing.
            self.simpson_panels(profile, b, 1);
            return;
        }
        let m4 = panel_count(turn * (1.0 / LOBATTO3.max_turn))
            .max(panel_count(taper * (1.0 / LOBATTO3.max_taper)));
        let m6 = panel_count(turn * (1.0 / LOBATTO4.max_turn))
            .max(panel_count(taper * (1.0 / LOBATTO4.max_taper)));
        // Cost in profile evaluations: 2 per order-4 panel, 3 per order-6 panel.
        if 2 * m4 <= 3 * m6 {
            self.simpson_panels(profile, b, m4);
        } else {
            self.lobatto4_panels(profile, b, m6);
        }
    }

    /// `m` equal panels of [`LOBATTO3`] over `[self.s, b]`, written out by hand: this is the
    /// hot path at fine output spacing (about 110 flops per panel).
    #[inline(always)]
    fn simpson_panels<P: Fn(f64) -> (f64, f64)>(&mut self, profile: &P, b: f64, m: usize) {
        const A1: [f64; 3] = LOBATTO3.a[1];
        let h = (b - self.s) / m as f64;
        let a0 = self.s;
        let (mut f0, mut g0) = ((1.0 + self.q) * self.k, 1.0 + self.q);
        for p in 0..m {
            let s0 = a0 + p as f64 * h;
            let s_end = if p + 1 == m { b } else { s0 + h };
            let (k1, q1) = profile(s0 + 0.5 * h);
            let (k2, q2) = profile(s_end);
            let (g1, g2) = (1.0 + q1, 1.0 + q2);
            let (f1, f2) = (g1 * k1, g2 * k2);
            let d1 = h * (A1[0] * f0 + A1[1] * f1 + A1[2] * f2);
            let d2 = h * (1.0 / 6.0) * (f0 + 4.0 * f1 + f2);
            let (c1, s1) = small_angle_cis::<true>(d1);
            let (c2, s2) = small_angle_cis::<true>(d2);
            let (c0, s0_) = (self.cos, self.sin);
            let (x1, y1) = (c0 * c1 - s0_ * s1, s0_ * c1 + c0 * s1);
            let (x2, y2) = (c0 * c2 - s0_ * s2, s0_ * c2 + c0 * s2);
            let (w0, w1, w2) = (g0 * (h / 6.0), g1 * (h * 2.0 / 3.0), g2 * (h / 6.0));
            self.x += w0 * c0 + w1 * x1 + w2 * x2;
            self.y += w0 * s0_ + w1 * y1 + w2 * y2;
            // |t| drifts by the series error (< 1e-12) per panel; `advance` renormalises.
            self.cos = x2;
            self.sin = y2;
            self.theta += d2;
            self.s = s_end;
            (self.k, self.q) = (k2, q2);
            (f0, g0) = (f2, g2);
        }
    }

    /// `m` equal panels of [`LOBATTO4`] over `[self.s, b]`, written out by hand like
    /// [`Self::simpson_panels`] (high curvature or coarse output spacing).
    #[inline(always)]
    fn lobatto4_panels<P: Fn(f64) -> (f64, f64)>(&mut self, profile: &P, b: f64, m: usize) {
        const C: [f64; 4] = LOBATTO4.c;
        const A1: [f64; 4] = LOBATTO4.a[1];
        const A2: [f64; 4] = LOBATTO4.a[2];
        const W: [f64; 4] = LOBATTO4.b;
        let h = (b - self.s) / m as f64;
        let a0 = self.s;
        let (mut f0, mut g0) = ((1.0 + self.q) * self.k, 1.0 + self.q);
        for p in 0..m {
            let s0 = a0 + p as f64 * h;
            let s_end = if p + 1 == m { b } else { s0 + h };
            let (k1, q1) = profile(s0 + C[1] * h);
            let (k2, q2) = profile(s0 + C[2] * h);
            let (k3, q3) = profile(s_end);
            let (g1, g2, g3) = (1.0 + q1, 1.0 + q2, 1.0 + q3);
            let (f1, f2, f3) = (g1 * k1, g2 * k2, g3 * k3);
            let d1 = h * (A1[0] * f0 + A1[1] * f1 + A1[2] * f2 + A1[3] * f3);
            let d2 = h * (A2[0] * f0 + A2[1] * f1 + A2[2] * f2 + A2[3] * f3);
            let d3 = h * (W[0] * f0 + W[1] * f1 + W[2] * f2 + W[3] * f3);
            let (c1, s1) = small_angle_cis::<false>(d1);
            let (c2, s2) = small_angle_cis::<false>(d2);
            let (c3, s3) = small_angle_cis::<false>(d3);
            let (c0, s0_) = (self.cos, self.sin);
            let (x1, y1) = (c0 * c1 - s0_ * s1, s0_ * c1 + c0 * s1);
            let (x2, y2) = (c0 * c2 - s0_ * s2, s0_ * c2 + c0 * s2);
            let (x3, y3) = (c0 * c3 - s0_ * s3, s0_ * c3 + c0 * s3);
            let (w0, w1, w2, w3) = (W[0] * h * g0, W[1] * h * g1, W[2] * h * g2, W[3] * h * g3);
            self.x += w0 * c0 + w1 * x1 + w2 * x2 + w3 * x3;
            self.y += w0 * s0_ + w1 * y1 + w2 * y2 + w3 * y3;
            self.cos = x3;
            self.sin = y3;
            self.theta += d3;
            self.s = s_end;
            (self.k, self.q) = (k3, q3);
            (f0, g0) = (f3, g3);
        }
    }

    /// Advances straight (unloaded: `k = q = 0`) to `b`.
    #[inline]
    fn advance_straight(&mut self, b: f64) {
        let d = b - self.s;
        self.x += d * self.cos;
        self.y += d * self.sin;
        self.s = b;
        self.k = 0.0;
        self.q = 0.0;
    }

    /// Advances to `b`, loaded up to `anchor` and straight beyond it.
    #[inline]
    fn advance<P: Fn(f64) -> (f64, f64)>(
        &mut self,
        profile: &P,
        b: f64,
        anchor: f64,
        rates: Rates,
    ) {
        if self.s < anchor {
            self.advance_loaded(profile, b.min(anchor), rates);
            // Renormalise the unit tangent (first-order correction of |t|^2 - 1).
            let fix = 1.5 - 0.5 * (self.cos * self.cos + self.sin * self.sin);
            self.cos *= fix;
            self.sin *= fix;
        }
        if b > anchor {
            self.advance_straight(b);
        }
    }
}

/// Output slices of one solve (each of the samples' length).
struct Out<'a> {
    k: &'a mut [f64],
    q: &'a mut [f64],
    theta: &'a mut [f64],
    x: &'a mut [f64],
    y: &'a mut [f64],
}

/// Integrates the backbone for a curvature/strain profile, writing the samples.
/// Returns the tip `(x, y, theta)`.
fn integrate_backbone<P: Fn(f64) -> (f64, f64)>(
    profile: P,
    samples: &[f64],
    length: f64,
    anchor: f64,
    rates: Rates,
    out: Out<'_>,
) -> (f64, f64, f64) {
    let (k0, q0) = profile(0.0);
    let mut st = BackboneState {
        s: 0.0,
        theta: 0.0,
        cos: 1.0,
        sin: 0.0,
        x: 0.0,
        y: 0.0,
        k: k0,
        q: q0,
    };
    for (i, &si) in samples.iter().enumerate() {
        st.advance(&profile, si, anchor, rates);
        out.k[i] = st.k;
        out.q[i] = st.q;
        out.theta[i] = st.theta;
        out.x[i] = st.x;
        out.y[i] = st.y;
    }
    st.advance(&profile, length, anchor, rates);
    (st.x, st.y, st.theta)
}

/// Solves one tension into the output slices; returns tip and ODE statistics.
fn solve_into(
    arm: &PlanarCableArm,
    tension: f64,
    samples: &[f64],
    method: PlanarMethod,
    out: Out<'_>,
) -> Result<((f64, f64, f64), Option<IntegrationStats>)> {
    arm.check_tension(tension)?;
    let (l, anchor) = (arm.length, arm.anchor);
    let taper = arm.relative_taper();
    match method {
        PlanarMethod::ClosedForm => {
            let turn = |(k, q): (f64, f64)| ((1.0 + q) * k).abs();
            let rates = Rates {
                turn: turn(arm.closed_form(0.0, tension))
                    .max(turn(arm.closed_form(anchor, tension))),
                taper,
            };
            let tip = integrate_backbone(
                |s| arm.closed_form(s, tension),
                samples,
                l,
                anchor,
                rates,
                out,
            );
            Ok((tip, None))
        }
        PlanarMethod::Ode(options) => {
            arm.check_ode_tension(tension, options.rtol)?;
            arm.check_ode_atol(options.atol)?;
            let mut rhs = FnSystem(|s: f64, k: &[f64; 1]| [arm.curvature_rate(s, k[0], tension)]);
            let sol = adaptive_dense(
                &BS3,
                &mut rhs,
                [anchor, 0.0],
                [arm.final_value(tension)],
                &options,
                1,
            )?;
            let rates = Rates {
                turn: sol.y.iter().fold(0.0f64, |m, k| m.max(k[0].abs())),
                taper,
            };
            let profile = |s: f64| {
                let k = sol.eval(s)[0];
                (k, arm.strain(s, k, tension))
            };
            let tip = integrate_backbone(profile, samples, l, anchor, rates, out);
            Ok((tip, Some(sol.stats)))
        }
    }
}

/// Solves the arm for one tension at the given arc-length samples.
///
/// `samples` are undeformed arc lengths (m), non-decreasing, in `[0, L]` (see
/// [`uniform_samples`]). The tip is always reported at `s = L`.
///
/// # Errors
/// [`Error::InvalidParameter`] for a bad tension or samples; [`Error::NotConverged`] if the
/// ODE integration fails.
pub fn solve_planar(
    arm: &PlanarCableArm,
    tension: f64,
    samples: &[f64],
    method: PlanarMethod,
) -> Result<PlanarSolution> {
    let samples = &check_samples(samples, arm.length)?[..];
    let n = samples.len();
    let (mut k, mut q, mut th, mut x, mut y) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    );
    let ((tx, ty, tth), ode_stats) = solve_into(
        arm,
        tension,
        samples,
        method,
        Out {
            k: &mut k,
            q: &mut q,
            theta: &mut th,
            x: &mut x,
            y: &mut y,
        },
    )?;
    Ok(PlanarSolution {
        tension,
        s: samples.to_vec(),
        curvature: k,
        strain: q,
        angle: th,
        x,
        y,
        tip: [tx, ty],
        tip_angle: tth,
        ode_stats,
    })
}

/// Solves many tensions on one set of samples, in parallel over tensions.
///
/// # Errors
/// The first error of any tension (see [`solve_planar`]); tensions are validated before any
/// work is done.
pub fn solve_planar_many(
    arm: &PlanarCableArm,
    tensions: &[f64],
    samples: &[f64],
    method: PlanarMethod,
) -> Result<PlanarBatch> {
    let samples = &check_samples(samples, arm.length)?[..];
    for (i, &t) in tensions.iter().enumerate() {
        arm.check_tension(t)
            .map_err(|e| e.map_name(|_| format!("tensions[{i}]")))?;
    }
    let (nt, ns) = (tensions.len(), samples.len());
    let mut batch = PlanarBatch {
        tensions: tensions.to_vec(),
        s: samples.to_vec(),
        curvature: vec![0.0; nt * ns],
        strain: vec![0.0; nt * ns],
        angle: vec![0.0; nt * ns],
        x: vec![0.0; nt * ns],
        y: vec![0.0; nt * ns],
        tip: vec![[0.0; 2]; nt],
        tip_angle: vec![0.0; nt],
    };
    if nt == 0 {
        return Ok(batch);
    }
    let rows = batch
        .curvature
        .par_chunks_mut(ns)
        .zip(batch.strain.par_chunks_mut(ns))
        .zip(batch.angle.par_chunks_mut(ns))
        .zip(batch.x.par_chunks_mut(ns))
        .zip(batch.y.par_chunks_mut(ns))
        .zip(batch.tip.par_iter_mut())
        .zip(batch.tip_angle.par_iter_mut())
        .zip(tensions.par_iter());
    rows.with_min_len(64).try_for_each(
        |(((((((k, q), th), x), y), tip), tip_angle), &t)| -> Result<()> {
            let ((tx, ty, tth), _) = solve_into(
                arm,
                t,
                samples,
                method,
                Out {
                    k,
                    q,
                    theta: th,
                    x,
                    y,
                },
            )?;
            *tip = [tx, ty];
            *tip_angle = tth;
            Ok(())
        },
    )?;
    Ok(batch)
}
