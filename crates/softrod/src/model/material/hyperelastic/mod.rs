//! Uniaxial material laws: linear, linearised (secant) and incompressible hyperelastic.
//!
//! Every law maps the axial stretch `λ = l / l0 = 1 + ε` of an incompressible bar in simple
//! tension or compression (`λ2 = λ3 = λ^(-1/2)`) to its axial stress. Two stress measures are
//! used:
//!
//! * nominal (engineering, first Piola–Kirchhoff) stress `P`: force per *undeformed* area, so
//!   the axial force of a rod section of rest area `A0` is `N = A0 P(λ)`;
//! * true (Cauchy) stress `σ = λ P`: force per *deformed* area `A0 / λ`.
//!
//! For a strain-energy density `W(I1, I2)` with `I1 = λ² + 2/λ` and `I2 = 2λ + 1/λ²`,
//!
//! ```text
//! σ = 2 (λ² − 1/λ) (∂W/∂I1 + (1/λ) ∂W/∂I2),      P = σ / λ,
//! ```
//!
//! and the tangent modulus is `E(ε) = dσ/dε` (with `ε = λ − 1`, so `dσ/dε = dσ/dλ`). Every
//! law here gives `σ`, `P`, `dσ/dλ` and `dP/dλ` in closed form, valid in tension (`λ > 1`) and
//! compression (`0 < λ < 1`). Stresses and moduli are in Pa, stretch and strain are
//! dimensionless, forces in N and areas in m².
//!
//! The laws share the [`UniaxialLaw`] trait; [`UniaxialModel`] is the closed set of them as one
//! value type (what a rod model stores and what a fit returns). [`Silicone`](super::silicone::Silicone) is a small library
//! of named silicones with sourced parameters.
//!
//! # References
//! * R. W. Ogden, *Non-linear Elastic Deformations*, Dover 1997, ch. 7 (incompressible
//!   uniaxial tension, stress measures).
//! * R. S. Rivlin, D. W. Saunders, Phil. Trans. R. Soc. A 243, 1951 (Mooney–Rivlin).
//! * O. H. Yeoh, Rubber Chem. Technol. 66(5), 1993 (the Yeoh form).
//! * R. W. Ogden, Proc. R. Soc. A 326, 1972 (the Ogden form).
//! * the compliance-methodology paper, section II.B, and its corrections (docs/materials.md).

use std::fmt;

use crate::error::{check_finite, check_positive, Error, Result};

/// Number of stretches (geometrically spaced, end points included) at which
/// [`UniaxialLaw::check_stable`] evaluates `dP/dλ`.
pub const STABILITY_SAMPLES: usize = 2001;

/// Relative stretch tolerance of the force → stretch inversion
/// ([`UniaxialLaw::stretch_from_nominal_stress`]).
pub const INVERSE_STRETCH_TOLERANCE: f64 = 1e-13;

/// Iteration cap of the force → stretch inversion (Newton with bisection safeguard).
pub const INVERSE_MAX_ITERATIONS: usize = 200;

/// Smallest stretch the force → stretch inversion searches (a compression to 1e-9 of the length).
pub const INVERSE_STRETCH_MIN: f64 = 1e-9;

/// Largest stretch the force → stretch inversion searches.
pub const INVERSE_STRETCH_MAX: f64 = 1e6;

/// Checks a stretch `λ`: finite and strictly positive.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn check_stretch(name: &str, stretch: f64) -> Result<f64> {
    check_positive(name, stretch, "(stretch = current length / rest length)")
}

/// Checks an engineering strain `ε = λ − 1`: finite and `> −1`; returns the stretch `1 + ε`.
fn check_strain(name: &str, strain: f64) -> Result<f64> {
    if strain.is_finite() && strain > -1.0 {
        Ok(1.0 + strain)
    } else {
        Err(Error::invalid(
            name,
            strain,
            "finite and > -1 (engineering strain = stretch - 1)",
        ))
    }
}

/// An incompressible uniaxial constitutive law: axial stress as a function of axial stretch.
///
/// Implementors give the nominal stress and its slope (the `*_unchecked` methods, which take a
/// stretch already known to be finite and positive and never panic); every other method is
/// provided, validates its input and returns [`Error::InvalidParameter`] naming the argument.
/// The trait is object safe (`&dyn UniaxialLaw`).
pub trait UniaxialLaw: fmt::Debug + fmt::Display + Send + Sync {
    /// Short model name, e.g. `"Yeoh"` (used in error messages).
    fn model_name(&self) -> &'static str;

    /// Small-strain Young's modulus `E0 = dσ/dε` at `ε = 0` (Pa): `3 μ0` for an incompressible
    /// hyperelastic law with initial shear modulus `μ0`.
    fn small_strain_modulus(&self) -> f64;

    /// Nominal stress `P(λ)` (Pa) for a stretch already validated as finite and `> 0`.
    fn nominal_stress_unchecked(&self, stretch: f64) -> f64;

    /// Slope `dP/dλ` of the nominal stress (Pa) for a validated stretch.
    fn nominal_slope_unchecked(&self, stretch: f64) -> f64;

    /// True stress `σ(λ) = λ P(λ)` (Pa) for a validated stretch.
    fn true_stress_unchecked(&self, stretch: f64) -> f64 {
        stretch * self.nominal_stress_unchecked(stretch)
    }

    /// Tangent modulus `dσ/dλ = P + λ dP/dλ` (Pa) for a validated stretch.
    fn true_slope_unchecked(&self, stretch: f64) -> f64 {
        self.nominal_stress_unchecked(stretch) + stretch * self.nominal_slope_unchecked(stretch)
    }

    /// Nominal (engineering) stress `P(λ)`: axial force per undeformed area (Pa).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`stretch`) unless `stretch` is finite and `> 0` and the
    /// stress there is a finite float (so for every evaluation below).
    fn nominal_stress(&self, stretch: f64) -> Result<f64> {
        let stretch = check_stretch("stretch", stretch)?;
        finite_at(
            self,
            "stretch",
            stretch,
            self.nominal_stress_unchecked(stretch),
        )
    }

    /// True (Cauchy) stress `σ(λ) = λ P(λ)`: axial force per deformed area (Pa).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`stretch`) unless `stretch` is finite and `> 0`.
    fn true_stress(&self, stretch: f64) -> Result<f64> {
        let stretch = check_stretch("stretch", stretch)?;
        finite_at(
            self,
            "stretch",
            stretch,
            self.true_stress_unchecked(stretch),
        )
    }

    /// Tangent modulus `E(ε) = dσ/dε` of the true stress at engineering strain `ε = λ − 1` (Pa).
    ///
    /// Equals [`small_strain_modulus`](Self::small_strain_modulus) at `ε = 0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`strain`) unless `strain` is finite and `> −1`.
    fn tangent_modulus(&self, strain: f64) -> Result<f64> {
        let stretch = check_strain("strain", strain)?;
        finite_at(self, "strain", strain, self.true_slope_unchecked(stretch))
    }

    /// Slope `dP/dλ` of the nominal stress (Pa): the axial stiffness per rest area.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`stretch`) unless `stretch` is finite and `> 0`.
    fn nominal_tangent(&self, stretch: f64) -> Result<f64> {
        let stretch = check_stretch("stretch", stretch)?;
        finite_at(
            self,
            "stretch",
            stretch,
            self.nominal_slope_unchecked(stretch),
        )
    }

    /// Secant modulus `P(1 + ε) / ε` at engineering strain `ε` (Pa), e.g. the "100 % modulus"
    /// of a datasheet at `ε = 1`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`strain`) unless `strain` is finite, `> −1` and `≠ 0`.
    fn secant_modulus(&self, strain: f64) -> Result<f64> {
        let stretch = check_strain("strain", strain)?;
        if strain == 0.0 {
            return Err(Error::invalid(
                "strain",
                strain,
                "non-zero (secant modulus)",
            ));
        }
        Ok(self.nominal_stress_unchecked(stretch) / strain)
    }

    /// Axial force `N = A0 P(λ)` (N) of a section of rest area `area0` (m²).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `area0` or `stretch` if either is not finite and `> 0`.
    fn axial_force(&self, area0: f64, stretch: f64) -> Result<f64> {
        let area0 = check_positive("area0", area0, "m^2")?;
        Ok(area0 * self.nominal_stress(stretch)?)
    }

    /// Axial stiffness `dN/dλ = A0 dP/dλ` (N) of a section of rest area `area0` (m²).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `area0` or `stretch` if either is not finite and `> 0`.
    fn axial_stiffness(&self, area0: f64, stretch: f64) -> Result<f64> {
        let area0 = check_positive("area0", area0, "m^2")?;
        Ok(area0 * self.nominal_tangent(stretch)?)
    }

    /// Stretch `λ` at which the nominal stress equals `nominal_stress` (Pa): the inverse of
    /// [`nominal_stress`](Self::nominal_stress), by Newton's method safeguarded by bisection
    /// on a bracket grown geometrically from `λ = 1` within
    /// `[INVERSE_STRETCH_MIN, INVERSE_STRETCH_MAX]`, to a relative stretch tolerance of
    /// [`INVERSE_STRETCH_TOLERANCE`].
    ///
    /// For a stable law (see [`check_stable`](Self::check_stable)) the solution is unique; for
    /// an unstable one this returns one of the solutions.
    ///
    /// # Errors
    /// * [`Error::InvalidParameter`] (`nominal_stress`) if it is not finite or not reached by
    ///   the law in the searched stretch range (e.g. a compressive stress `≤ −E` for the linear
    ///   law, which would need `λ ≤ 0`).
    /// * [`Error::NotConverged`] if the iteration cap [`INVERSE_MAX_ITERATIONS`] is reached.
    fn stretch_from_nominal_stress(&self, nominal_stress: f64) -> Result<f64> {
        let target = check_finite("nominal_stress", nominal_stress)?;
        invert_nominal_stress(self, target)
    }

    /// Stretch at which a section of rest area `area0` (m²) carries the axial force `force`
    /// (N, positive in tension); see
    /// [`stretch_from_nominal_stress`](Self::stretch_from_nominal_stress).
    ///
    /// # Errors
    /// As [`stretch_from_nominal_stress`](Self::stretch_from_nominal_stress), and
    /// [`Error::InvalidParameter`] naming `area0` or `force` if not finite (`area0 > 0`).
    fn stretch_from_axial_force(&self, area0: f64, force: f64) -> Result<f64> {
        let area0 = check_positive("area0", area0, "m^2")?;
        let force = check_finite("force", force)?;
        invert_nominal_stress(self, force / area0).map_err(|e| match e {
            Error::InvalidParameter { expected, .. } => Error::InvalidParameter {
                name: "force".into(),
                value: force.to_string(),
                expected: format!("{expected} (times area0 = {area0} m^2)"),
            },
            other => other,
        })
    }

    /// Checks that the law is stable on `[stretch_min, stretch_max]`: the nominal stress (hence
    /// the axial force) strictly increases with stretch, `dP/dλ > 0`. In tension this implies a
    /// positive tangent modulus `dσ/dε`. `dP/dλ` is evaluated at [`STABILITY_SAMPLES`]
    /// geometrically spaced stretches, end points included.
    ///
    /// # Errors
    /// * [`Error::InvalidParameter`] naming `stretch_min` / `stretch_max` unless
    ///   `0 < stretch_min <= stretch_max` (both finite).
    /// * [`Error::InvalidParameter`] naming the model's parameters, with the first stretch at
    ///   which `dP/dλ <= 0` (or is not finite), if the law is unstable there.
    fn check_stable(&self, stretch_min: f64, stretch_max: f64) -> Result<()> {
        let lo = check_stretch("stretch_min", stretch_min)?;
        let hi = check_stretch("stretch_max", stretch_max)?;
        if hi < lo {
            return Err(Error::invalid(
                "stretch_max",
                hi,
                format!("finite and >= stretch_min = {lo}"),
            ));
        }
        let ratio = (hi / lo).ln();
        for i in 0..STABILITY_SAMPLES {
            let t = i as f64 / (STABILITY_SAMPLES - 1) as f64;
            let stretch = if i + 1 == STABILITY_SAMPLES {
                hi
            } else {
                lo * (ratio * t).exp()
            };
            let slope = self.nominal_slope_unchecked(stretch);
            if !(slope.is_finite() && slope > 0.0) {
                return Err(Error::invalid(
                    format!("{} parameters", self.model_name()),
                    self,
                    format!(
                        "a stable law on [stretch_min, stretch_max] = [{lo}, {hi}] \
                         (dP/dstretch > 0); dP/dstretch = {slope:.4e} Pa at stretch {stretch:.6}"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// `value` if finite, else an [`Error::InvalidParameter`] naming the input `name` = `input`
/// at which `law` overflows.
fn finite_at<L: UniaxialLaw + ?Sized>(law: &L, name: &str, input: f64, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::invalid(
            name,
            input,
            format!(
                "a value at which {law} gives a finite stress (it is {value} there: the law \
                 overflows a double)"
            ),
        ))
    }
}

/// Newton–bisection inversion of `P(λ) = target` (see
/// [`UniaxialLaw::stretch_from_nominal_stress`]).
fn invert_nominal_stress<L: UniaxialLaw + ?Sized>(law: &L, target: f64) -> Result<f64> {
    let p = |x: f64| law.nominal_stress_unchecked(x) - target;
    // Bracket [lo, hi] with p(lo) <= 0 <= p(hi), grown geometrically from λ = 1.
    let (mut lo, mut hi) = (1.0_f64, 1.0_f64);
    let f1 = p(1.0);
    if f1 == 0.0 {
        return Ok(1.0);
    }
    let unreachable = || {
        let p_min = law.nominal_stress_unchecked(INVERSE_STRETCH_MIN);
        let p_max = law.nominal_stress_unchecked(INVERSE_STRETCH_MAX);
        Error::invalid(
            "nominal_stress",
            target,
            format!(
                "within the range of the {} law for stretch in [{INVERSE_STRETCH_MIN:e}, \
                 {INVERSE_STRETCH_MAX:e}]: [{p_min:.4e}, {p_max:.4e}] Pa",
                law.model_name()
            ),
        )
    };
    if f1 < 0.0 {
        loop {
            lo = hi;
            hi *= 2.0;
            if hi > INVERSE_STRETCH_MAX {
                return Err(unreachable());
            }
            let f = p(hi);
            if f >= 0.0 {
                break;
            }
            if !f.is_finite() {
                return Err(unreachable());
            }
        }
    } else {
        loop {
            hi = lo;
            lo *= 0.5;
            if lo < INVERSE_STRETCH_MIN {
                return Err(unreachable());
            }
            let f = p(lo);
            if f <= 0.0 {
                break;
            }
            if !f.is_finite() {
                return Err(unreachable());
            }
        }
    }
    // Safeguarded Newton inside the bracket.
    let mut x = 0.5 * (lo + hi);
    let mut residual = f64::INFINITY;
    for _ in 0..INVERSE_MAX_ITERATIONS {
        let f = p(x);
        residual = f.abs();
        if f == 0.0 {
            return Ok(x);
        }
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let slope = law.nominal_slope_unchecked(x);
        let newton = x - f / slope;
        let next = if slope > 0.0 && newton.is_finite() && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - x).abs() <= INVERSE_STRETCH_TOLERANCE * x
            || (hi - lo) <= INVERSE_STRETCH_TOLERANCE * x
        {
            return Ok(next);
        }
        x = next;
    }
    Err(Error::not_converged(
        format!("{} stretch-from-stress inversion", law.model_name()),
        INVERSE_MAX_ITERATIONS,
        residual,
    ))
}

mod laws;

pub(crate) use laws::ogden_term;
pub use laws::{Hookean, Linearised, MooneyRivlin, NeoHookean, Ogden, Yeoh};

/// Any of the uniaxial laws, as one value type (what a rod model stores and a fit returns).
#[derive(Debug, Clone, PartialEq)]
pub enum UniaxialModel {
    /// [`Hookean`].
    Hookean(Hookean),
    /// [`Linearised`].
    Linearised(Linearised),
    /// [`NeoHookean`].
    NeoHookean(NeoHookean),
    /// [`MooneyRivlin`].
    MooneyRivlin(MooneyRivlin),
    /// [`Yeoh`].
    Yeoh(Yeoh),
    /// [`Ogden`].
    Ogden(Ogden),
}

macro_rules! dispatch {
    ($self:ident, $law:ident => $body:expr) => {
        match $self {
            UniaxialModel::Hookean($law) => $body,
            UniaxialModel::Linearised($law) => $body,
            UniaxialModel::NeoHookean($law) => $body,
            UniaxialModel::MooneyRivlin($law) => $body,
            UniaxialModel::Yeoh($law) => $body,
            UniaxialModel::Ogden($law) => $body,
        }
    };
}

impl UniaxialModel {
    /// The law as a trait object.
    pub fn as_law(&self) -> &dyn UniaxialLaw {
        dispatch!(self, law => law)
    }
}

impl fmt::Display for UniaxialModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        dispatch!(self, law => fmt::Display::fmt(law, f))
    }
}

impl UniaxialLaw for UniaxialModel {
    fn model_name(&self) -> &'static str {
        dispatch!(self, law => law.model_name())
    }
    fn small_strain_modulus(&self) -> f64 {
        dispatch!(self, law => law.small_strain_modulus())
    }
    fn nominal_stress_unchecked(&self, stretch: f64) -> f64 {
        dispatch!(self, law => law.nominal_stress_unchecked(stretch))
    }
    fn nominal_slope_unchecked(&self, stretch: f64) -> f64 {
        dispatch!(self, law => law.nominal_slope_unchecked(stretch))
    }
    fn true_stress_unchecked(&self, stretch: f64) -> f64 {
        dispatch!(self, law => law.true_stress_unchecked(stretch))
    }
    fn true_slope_unchecked(&self, stretch: f64) -> f64 {
        dispatch!(self, law => law.true_slope_unchecked(stretch))
    }
}

macro_rules! into_model {
    ($($ty:ident),*) => {$(
        impl From<$ty> for UniaxialModel {
            fn from(law: $ty) -> Self {
                UniaxialModel::$ty(law)
            }
        }
    )*};
}
into_model!(Hookean, Linearised, NeoHookean, MooneyRivlin, Yeoh, Ogden);
