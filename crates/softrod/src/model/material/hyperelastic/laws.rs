//! The closed-form uniaxial laws: Hooke's law, its secant linearisation and the
//! incompressible hyperelastic laws (neo-Hookean, Mooney–Rivlin, Yeoh, Ogden), each with its
//! nominal and true stress and their stretch derivatives (see the parent module for the
//! measures and references).

use std::fmt;

use super::{check_strain, UniaxialLaw};
use crate::error::{check_finite, Error, Result};
use crate::limits::{check_modulus, check_parameter};

/// `λ² − 1/λ = (λ − 1)(λ² + λ + 1)/λ`, written to keep its relative accuracy near `λ = 1`.
#[inline]
fn sigma_factor(stretch: f64) -> f64 {
    (stretch - 1.0) * (stretch * stretch + stretch + 1.0) / stretch
}

/// `I1 − 3 = λ² + 2/λ − 3 = (λ − 1)² (λ + 2) / λ`, accurate near `λ = 1`.
#[inline]
fn i1_minus_3(stretch: f64) -> f64 {
    let d = stretch - 1.0;
    d * d * (stretch + 2.0) / stretch
}

/// Linear elastic uniaxial law (Hooke's law) in engineering measures: `P = E (λ − 1)`, the law
/// of a rod with axial stiffness `E A0`; true stress `σ = λ P` by incompressibility. (Named
/// `Hookean`, not `LinearElastic`, which is the rod-section material of `crate::model::material`.)
///
/// Note that `dσ/dε = E (2λ − 1)` is not constant (only `dP/dλ = E` is) and turns negative
/// below `λ = 1/2`, while the force stays monotonic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hookean {
    pub(in crate::model::material) youngs_modulus: f64,
}

impl Hookean {
    /// A linear law with Young's modulus `youngs_modulus` (Pa).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`youngs_modulus`) unless finite and `> 0`.
    pub fn new(youngs_modulus: f64) -> Result<Self> {
        Ok(Self {
            youngs_modulus: check_modulus("youngs_modulus", youngs_modulus)?,
        })
    }

    /// Young's modulus `E` (Pa).
    pub fn youngs_modulus(&self) -> f64 {
        self.youngs_modulus
    }
}

impl fmt::Display for Hookean {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Hookean(youngs_modulus={:e} Pa)", self.youngs_modulus)
    }
}

impl UniaxialLaw for Hookean {
    fn model_name(&self) -> &'static str {
        "Hookean"
    }
    fn small_strain_modulus(&self) -> f64 {
        self.youngs_modulus
    }
    fn nominal_stress_unchecked(&self, stretch: f64) -> f64 {
        self.youngs_modulus * (stretch - 1.0)
    }
    fn nominal_slope_unchecked(&self, _stretch: f64) -> f64 {
        self.youngs_modulus
    }
}

/// A linearised law: the linear law `P = E_l (λ − 1)` whose modulus `E_l` is the secant
/// modulus of a nonlinear curve at a reference strain (the compliance-methodology paper, II.B.1: "100 % modulus"), or a
/// straight line through the origin fitted to data (`crate::model::material::fit::fit_uniaxial` with
/// `ModelKind::Linearised`). The reference strain records where the line is exact (or the
/// largest strain of the fitted data).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linearised {
    pub(in crate::model::material) secant_modulus: f64,
    pub(in crate::model::material) reference_strain: f64,
}

impl Linearised {
    /// A linearised law with secant modulus `secant_modulus` (Pa), taken at the engineering
    /// strain `reference_strain`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `secant_modulus` (finite, `> 0`) or
    /// `reference_strain` (finite, `> −1`, `≠ 0`).
    pub fn new(secant_modulus: f64, reference_strain: f64) -> Result<Self> {
        let secant_modulus = check_modulus("secant_modulus", secant_modulus)?;
        check_strain("reference_strain", reference_strain)?;
        if reference_strain == 0.0 {
            return Err(Error::invalid(
                "reference_strain",
                reference_strain,
                "non-zero (the strain of the secant)",
            ));
        }
        Ok(Self {
            secant_modulus,
            reference_strain,
        })
    }

    /// From one datasheet point: nominal stress `nominal_stress` (Pa) at engineering strain
    /// `strain` (e.g. the 100 % modulus: `strain = 1`). `E_l = nominal_stress / strain`.
    ///
    /// # Errors
    /// As [`Linearised::new`]; also [`Error::InvalidParameter`] (`nominal_stress`) if the
    /// resulting modulus is not finite and `> 0`.
    pub fn from_secant_point(nominal_stress: f64, strain: f64) -> Result<Self> {
        check_finite("nominal_stress", nominal_stress)?;
        check_strain("strain", strain)?;
        if strain == 0.0 {
            return Err(Error::invalid("strain", strain, "non-zero"));
        }
        let modulus = nominal_stress / strain;
        if !(modulus.is_finite() && modulus > 0.0 && modulus <= crate::limits::MAX_MODULUS) {
            return Err(Error::invalid(
                "nominal_stress",
                nominal_stress,
                "of the same sign as strain (a positive secant modulus)",
            ));
        }
        Self::new(modulus, strain)
    }

    /// The secant of another law at engineering strain `strain`.
    ///
    /// # Errors
    /// As [`UniaxialLaw::secant_modulus`], and [`Error::InvalidParameter`] if the secant is not
    /// positive (an unstable law).
    pub fn secant_of(law: &dyn UniaxialLaw, strain: f64) -> Result<Self> {
        let modulus = law.secant_modulus(strain)?;
        if !(modulus.is_finite() && modulus > 0.0) {
            return Err(Error::invalid(
                format!("{} secant modulus", law.model_name()),
                modulus,
                format!("finite and > 0 Pa at strain {strain}"),
            ));
        }
        Self::new(modulus, strain)
    }

    /// Secant modulus `E_l` (Pa).
    pub fn secant_modulus(&self) -> f64 {
        self.secant_modulus
    }

    /// Engineering strain at which the secant was taken.
    pub fn reference_strain(&self) -> f64 {
        self.reference_strain
    }

    /// The same law as a [`Hookean`] with `E = E_l`.
    pub fn as_hookean(&self) -> Hookean {
        Hookean {
            youngs_modulus: self.secant_modulus,
        }
    }
}

impl fmt::Display for Linearised {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Linearised(secant_modulus={:e} Pa, reference_strain={})",
            self.secant_modulus, self.reference_strain
        )
    }
}

impl UniaxialLaw for Linearised {
    fn model_name(&self) -> &'static str {
        "Linearised"
    }
    fn small_strain_modulus(&self) -> f64 {
        self.secant_modulus
    }
    fn nominal_stress_unchecked(&self, stretch: f64) -> f64 {
        self.secant_modulus * (stretch - 1.0)
    }
    fn nominal_slope_unchecked(&self, _stretch: f64) -> f64 {
        self.secant_modulus
    }
}

/// Incompressible Neo-Hookean law `W = μ0/2 (I1 − 3)`: `σ = μ0 (λ² − 1/λ)`,
/// `P = μ0 (λ − 1/λ²)`, `E0 = 3 μ0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookean {
    pub(in crate::model::material) mu: f64,
}

impl NeoHookean {
    /// A Neo-Hookean law with initial shear modulus `mu` (Pa); `C10 = mu / 2`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`mu`) unless finite and `> 0`.
    pub fn new(mu: f64) -> Result<Self> {
        Ok(Self {
            mu: check_modulus("mu", mu)?,
        })
    }

    /// Initial shear modulus `μ0` (Pa).
    pub fn mu(&self) -> f64 {
        self.mu
    }
}

impl fmt::Display for NeoHookean {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "NeoHookean(mu={:e} Pa)", self.mu)
    }
}

impl UniaxialLaw for NeoHookean {
    fn model_name(&self) -> &'static str {
        "NeoHookean"
    }
    fn small_strain_modulus(&self) -> f64 {
        3.0 * self.mu
    }
    fn nominal_stress_unchecked(&self, stretch: f64) -> f64 {
        self.mu * sigma_factor(stretch) / stretch
    }
    fn nominal_slope_unchecked(&self, stretch: f64) -> f64 {
        self.mu * (1.0 + 2.0 / (stretch * stretch * stretch))
    }
    fn true_stress_unchecked(&self, stretch: f64) -> f64 {
        self.mu * sigma_factor(stretch)
    }
    fn true_slope_unchecked(&self, stretch: f64) -> f64 {
        self.mu * (2.0 * stretch + 1.0 / (stretch * stretch))
    }
}

/// Incompressible two-parameter Mooney–Rivlin law `W = C10 (I1 − 3) + C01 (I2 − 3)`:
/// `σ = 2 (λ² − 1/λ)(C10 + C01/λ)`, `E0 = 6 (C10 + C01)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MooneyRivlin {
    pub(in crate::model::material) c10: f64,
    pub(in crate::model::material) c01: f64,
}

impl MooneyRivlin {
    /// A Mooney–Rivlin law with coefficients `c10`, `c01` (Pa). Either may be negative, but the
    /// initial shear modulus `2 (c10 + c01)` must be positive; use
    /// [`UniaxialLaw::check_stable`] for the stretch range of interest.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `c10` or `c01` if not finite, or `c10 + c01` if `<= 0`.
    pub fn new(c10: f64, c01: f64) -> Result<Self> {
        let c10 = check_parameter("c10", c10)?;
        let c01 = check_parameter("c01", c01)?;
        if c10 + c01 <= 0.0 {
            return Err(Error::invalid(
                "c10 + c01",
                c10 + c01,
                "> 0 Pa (initial shear modulus 2 (c10 + c01) > 0)",
            ));
        }
        Ok(Self { c10, c01 })
    }

    /// `C10` (Pa).
    pub fn c10(&self) -> f64 {
        self.c10
    }

    /// `C01` (Pa).
    pub fn c01(&self) -> f64 {
        self.c01
    }
}

impl fmt::Display for MooneyRivlin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "MooneyRivlin(c10={:e} Pa, c01={:e} Pa)",
            self.c10, self.c01
        )
    }
}

impl UniaxialLaw for MooneyRivlin {
    fn model_name(&self) -> &'static str {
        "MooneyRivlin"
    }
    fn small_strain_modulus(&self) -> f64 {
        6.0 * (self.c10 + self.c01)
    }
    fn nominal_stress_unchecked(&self, stretch: f64) -> f64 {
        self.true_stress_unchecked(stretch) / stretch
    }
    fn nominal_slope_unchecked(&self, stretch: f64) -> f64 {
        // P = 2 (λ − 1/λ²)(C10 + C01/λ).
        let l3 = stretch * stretch * stretch;
        let g = sigma_factor(stretch) / stretch;
        2.0 * (1.0 + 2.0 / l3) * (self.c10 + self.c01 / stretch)
            - 2.0 * g * self.c01 / (stretch * stretch)
    }
    fn true_stress_unchecked(&self, stretch: f64) -> f64 {
        2.0 * sigma_factor(stretch) * (self.c10 + self.c01 / stretch)
    }
    fn true_slope_unchecked(&self, stretch: f64) -> f64 {
        let l2 = stretch * stretch;
        2.0 * (2.0 * stretch + 1.0 / l2) * (self.c10 + self.c01 / stretch)
            - 2.0 * sigma_factor(stretch) * self.c01 / l2
    }
}

/// Incompressible Yeoh law `W = C10 (I1 − 3) + C20 (I1 − 3)² + C30 (I1 − 3)³`:
/// `σ = 2 (λ² − 1/λ) ∂W/∂I1`, `E0 = 6 C10`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Yeoh {
    pub(in crate::model::material) c10: f64,
    pub(in crate::model::material) c20: f64,
    pub(in crate::model::material) c30: f64,
}

impl Yeoh {
    /// A Yeoh law with `c10 > 0` and any finite `c20`, `c30` (Pa); pass `0.0` for unused terms
    /// (one term is Neo-Hookean with `mu = 2 c10`). A negative `c20` is common in fits and may
    /// lose stability at large stretch; use [`UniaxialLaw::check_stable`].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `c10` (finite, `> 0`), `c20` or `c30` (finite).
    pub fn new(c10: f64, c20: f64, c30: f64) -> Result<Self> {
        Ok(Self {
            c10: check_modulus("c10", c10)?,
            c20: check_parameter("c20", c20)?,
            c30: check_parameter("c30", c30)?,
        })
    }

    /// `C10` (Pa).
    pub fn c10(&self) -> f64 {
        self.c10
    }

    /// `C20` (Pa).
    pub fn c20(&self) -> f64 {
        self.c20
    }

    /// `C30` (Pa).
    pub fn c30(&self) -> f64 {
        self.c30
    }

    /// `∂W/∂I1` and its derivative with respect to `λ`.
    fn w1(&self, stretch: f64) -> (f64, f64) {
        let x = i1_minus_3(stretch);
        let w1 = self.c10 + 2.0 * self.c20 * x + 3.0 * self.c30 * x * x;
        let dx = 2.0 * sigma_factor(stretch) / stretch; // dI1/dλ = 2λ − 2/λ²
        let dw1 = (2.0 * self.c20 + 6.0 * self.c30 * x) * dx;
        (w1, dw1)
    }
}

impl fmt::Display for Yeoh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Yeoh(c10={:e} Pa, c20={:e} Pa, c30={:e} Pa)",
            self.c10, self.c20, self.c30
        )
    }
}

impl UniaxialLaw for Yeoh {
    fn model_name(&self) -> &'static str {
        "Yeoh"
    }
    fn small_strain_modulus(&self) -> f64 {
        6.0 * self.c10
    }
    fn nominal_stress_unchecked(&self, stretch: f64) -> f64 {
        self.true_stress_unchecked(stretch) / stretch
    }
    fn nominal_slope_unchecked(&self, stretch: f64) -> f64 {
        let (w1, dw1) = self.w1(stretch);
        let g = sigma_factor(stretch) / stretch; // λ − 1/λ²
        2.0 * (1.0 + 2.0 / (stretch * stretch * stretch)) * w1 + 2.0 * g * dw1
    }
    fn true_stress_unchecked(&self, stretch: f64) -> f64 {
        2.0 * sigma_factor(stretch) * self.w1(stretch).0
    }
    fn true_slope_unchecked(&self, stretch: f64) -> f64 {
        let (w1, dw1) = self.w1(stretch);
        2.0 * (2.0 * stretch + 1.0 / (stretch * stretch)) * w1 + 2.0 * sigma_factor(stretch) * dw1
    }
}

/// Largest `|α ln λ|` below which the Ogden term is evaluated by its Taylor series.
const OGDEN_SERIES_LIMIT: f64 = 0.1;

/// Number of Taylor terms used below [`OGDEN_SERIES_LIMIT`] (truncation error < 1e-17).
const OGDEN_SERIES_TERMS: i32 = 14;

/// `f(α, L) = (e^(αL) − e^(−αL/2)) / α` with `L = ln λ` and its derivative `∂f/∂α`, accurate
/// for every finite `α` (including `α → 0`, where `f → 3L/2`).
pub(crate) fn ogden_term(alpha: f64, log_stretch: f64) -> (f64, f64) {
    let z = alpha * log_stretch;
    if z.abs() < OGDEN_SERIES_LIMIT {
        // e^z − e^(−z/2) = Σ_k z^k (1 − (−1/2)^k) / k!
        let (mut f, mut df) = (0.0, 0.0);
        let mut zpow = 1.0; // z^(k−1)
        let mut zpow_prev = 0.0; // z^(k−2)
        let mut fact = 1.0; // k!
        let mut half = -0.5_f64; // (−1/2)^k
        for k in 1..=OGDEN_SERIES_TERMS {
            let kf = f64::from(k);
            fact *= kf;
            let c = (1.0 - half) / fact;
            f += c * zpow;
            if k >= 2 {
                df += (kf - 1.0) * c * zpow_prev;
            }
            zpow_prev = zpow;
            zpow *= z;
            half *= -0.5;
        }
        (log_stretch * f, log_stretch * log_stretch * df)
    } else {
        let f = (z.exp_m1() - (-0.5 * z).exp_m1()) / alpha;
        let df = (log_stretch * (z.exp() + 0.5 * (-0.5 * z).exp()) - f) / alpha;
        (f, df)
    }
}

/// Incompressible N-term Ogden law, in the convention
/// `W = Σ_p 2 μ_p / α_p² (λ1^α_p + λ2^α_p + λ3^α_p − 3)`, so that the initial shear modulus is
/// `μ0 = Σ μ_p` and `E0 = 3 Σ μ_p`:
/// `σ = Σ_p (2 μ_p / α_p)(λ^α_p − λ^(−α_p/2))`.
///
/// One term with `α = 2` is Neo-Hookean; terms `(2 C10, 2)` and `(2 C01, −2)` make
/// Mooney–Rivlin. A term with `μ_p > 0` has positive energy and raises `dσ/dλ` (Ogden's
/// condition `μ_p α_p > 0` in his original convention `W = Σ μ_p/α_p (…)`).
#[derive(Debug, Clone, PartialEq)]
pub struct Ogden {
    pub(in crate::model::material) mu: Vec<f64>,
    pub(in crate::model::material) alpha: Vec<f64>,
}

impl Ogden {
    /// An Ogden law from moduli `mu` (Pa) and exponents `alpha` (dimensionless), one entry per
    /// term (shape `[N]` each, `N >= 1`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `mu` / `alpha` if the lengths differ or are zero, an
    /// entry is not finite, an `alpha` is zero, or `Σ mu <= 0` (initial shear modulus).
    pub fn new(mu: &[f64], alpha: &[f64]) -> Result<Self> {
        if mu.is_empty() || mu.len() != alpha.len() {
            return Err(Error::invalid(
                "mu",
                format!("{} terms (alpha has {})", mu.len(), alpha.len()),
                "at least one term, as many as alpha",
            ));
        }
        for (i, (&m, &a)) in mu.iter().zip(alpha).enumerate() {
            check_parameter(&format!("mu[{i}]"), m)?;
            if !(a.is_finite() && a != 0.0) {
                return Err(Error::invalid(
                    format!("alpha[{i}]"),
                    a,
                    "finite and non-zero",
                ));
            }
        }
        let mu0: f64 = mu.iter().sum();
        if mu0 <= 0.0 {
            return Err(Error::invalid(
                "mu",
                format!("{mu:?}"),
                "sum(mu) > 0 Pa (initial shear modulus)",
            ));
        }
        Ok(Self {
            mu: mu.to_vec(),
            alpha: alpha.to_vec(),
        })
    }

    /// Term moduli `μ_p` (Pa).
    pub fn mu(&self) -> &[f64] {
        &self.mu
    }

    /// Term exponents `α_p`.
    pub fn alpha(&self) -> &[f64] {
        &self.alpha
    }

    /// Number of terms `N`.
    pub fn terms(&self) -> usize {
        self.mu.len()
    }
}

impl fmt::Display for Ogden {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Ogden(mu=[")?;
        for (i, m) in self.mu.iter().enumerate() {
            write!(f, "{}{m:e}", if i > 0 { ", " } else { "" })?;
        }
        write!(f, "] Pa, alpha=[")?;
        for (i, a) in self.alpha.iter().enumerate() {
            write!(f, "{}{a}", if i > 0 { ", " } else { "" })?;
        }
        write!(f, "])")
    }
}

impl UniaxialLaw for Ogden {
    fn model_name(&self) -> &'static str {
        "Ogden"
    }
    fn small_strain_modulus(&self) -> f64 {
        3.0 * self.mu.iter().sum::<f64>()
    }
    fn nominal_stress_unchecked(&self, stretch: f64) -> f64 {
        self.true_stress_unchecked(stretch) / stretch
    }
    fn nominal_slope_unchecked(&self, stretch: f64) -> f64 {
        (self.true_slope_unchecked(stretch) - self.nominal_stress_unchecked(stretch)) / stretch
    }
    fn true_stress_unchecked(&self, stretch: f64) -> f64 {
        let log_stretch = stretch.ln();
        self.mu
            .iter()
            .zip(&self.alpha)
            .map(|(&m, &a)| 2.0 * m * ogden_term(a, log_stretch).0)
            .sum()
    }
    fn true_slope_unchecked(&self, stretch: f64) -> f64 {
        self.mu
            .iter()
            .zip(&self.alpha)
            .map(|(&m, &a)| 2.0 * m * (stretch.powf(a - 1.0) + 0.5 * stretch.powf(-0.5 * a - 1.0)))
            .sum()
    }
}
