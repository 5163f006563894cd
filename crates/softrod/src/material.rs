//! Constitutive laws of a rod section: from the body-frame internal wrench to the strains.
//!
//! The solver only ever asks a [`Material`] for the *elastic strain* `(v - v*, u - u*)` produced
//! by a body-frame wrench `(n, m)` on a section, and for the *tangent compliance*
//! `d(v, u)/d(n, m)` there ([`Material::elastic_strain`]). For a linear material these are
//! `C (n, m)` and `C` with the diagonal section compliance
//! `C = diag(1/(k G A), 1/(k G A), 1/(E A), 1/(E Ix), 1/(E Iy), 1/(G J))`
//! (`k` the shear coefficient; shear and stretch compliances are zero in the inextensible,
//! unshearable Kirchhoff limit).
//!
//! # Adding a hyperelastic law
//! Add a variant (e.g. holding a [`crate::hyperelastic::UniaxialModel`], nominal stress
//! `P(λ)`) and implement its branch of
//! [`Material::elastic_strain`]: the axial strain solves `A P(1 + ε) = n_z` (one scalar Newton
//! solve per call), and the bending and shear compliances come from the tangent modulus
//! `dσ/dλ` at that stretch. The tangent must then also carry the coupling `du/dn_z` (bending
//! stiffness depending on the stretch), so [`TangentCompliance`] gains an off-diagonal part;
//! the local Newton solve and the sensitivity propagation in `cosserat.rs` already use the
//! tangent as returned, so the shooting solver needs no change.

use crate::error::{check_positive, Error, Result};
use crate::section::SectionProperties;

/// Isotropic linear elastic material (`LinearElastic(youngs_modulus, poisson_ratio)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    youngs_modulus: f64,
    shear_modulus: f64,
}

impl LinearElastic {
    /// From Young's modulus `E` (Pa) and Poisson's ratio `nu` (`G = E / (2 (1 + nu))`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `youngs_modulus` unless finite and > 0, or
    /// `poisson_ratio` unless in `(-1, 0.5]`.
    pub fn new(youngs_modulus: f64, poisson_ratio: f64) -> Result<Self> {
        check_positive("youngs_modulus", youngs_modulus, "Pa")?;
        if !(poisson_ratio.is_finite() && poisson_ratio > -1.0 && poisson_ratio <= 0.5) {
            return Err(Error::invalid(
                "poisson_ratio",
                poisson_ratio,
                "in (-1, 0.5]",
            ));
        }
        Ok(Self {
            youngs_modulus,
            shear_modulus: youngs_modulus / (2.0 * (1.0 + poisson_ratio)),
        })
    }

    /// From Young's modulus `E` and shear modulus `G` (Pa); the implied Poisson's ratio
    /// `E / (2 G) - 1` must lie in `(-1, 0.5]`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `youngs_modulus` or `shear_modulus`.
    pub fn with_shear_modulus(youngs_modulus: f64, shear_modulus: f64) -> Result<Self> {
        check_positive("youngs_modulus", youngs_modulus, "Pa")?;
        check_positive("shear_modulus", shear_modulus, "Pa")?;
        let nu = youngs_modulus / (2.0 * shear_modulus) - 1.0;
        if !(nu > -1.0 && nu <= 0.5 + 1e-12) {
            return Err(Error::invalid(
                "shear_modulus",
                shear_modulus,
                format!(
                    "in [E/3, inf) = [{}, inf) Pa (Poisson's ratio in (-1, 0.5])",
                    youngs_modulus / 3.0
                ),
            ));
        }
        Ok(Self {
            youngs_modulus,
            shear_modulus,
        })
    }

    /// Young's modulus `E` (Pa).
    pub fn youngs_modulus(&self) -> f64 {
        self.youngs_modulus
    }

    /// Shear modulus `G` (Pa).
    pub fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }

    /// Poisson's ratio `E / (2 G) - 1`.
    pub fn poisson_ratio(&self) -> f64 {
        self.youngs_modulus / (2.0 * self.shear_modulus) - 1.0
    }
}

/// The material of a rod. Only linear elasticity today; see the module documentation for
/// how a hyperelastic variant plugs in.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Material {
    /// Isotropic linear elasticity.
    LinearElastic(LinearElastic),
}

impl From<LinearElastic> for Material {
    fn from(m: LinearElastic) -> Self {
        Material::LinearElastic(m)
    }
}

/// Tangent compliance `d(v, u)/d(n, m)` of a section, in the body frame.
///
/// Diagonal: `[shear x, shear y, stretch z, bend x, bend y, twist z]`, units
/// `1/N` for the first three and `1/(N m²)` for the last three.
pub type TangentCompliance = [f64; 6];

impl Material {
    /// Poisson's ratio of the material (for the default shear coefficient).
    pub fn poisson_ratio(&self) -> f64 {
        match self {
            Material::LinearElastic(m) => m.poisson_ratio(),
        }
    }

    /// Bending stiffness `E min(Ix, Iy)` (N m²) of a section at zero strain (a force scale
    /// for the solver).
    pub fn bending_stiffness(&self, props: &SectionProperties) -> f64 {
        match self {
            Material::LinearElastic(m) => m.youngs_modulus * props.ix.min(props.iy),
        }
    }

    /// Linear section compliance `diag(1/(k G A), 1/(k G A), 1/(E A), 1/(E Ix), 1/(E Iy),
    /// 1/(G J))`, with zero shear and stretch compliances when `inextensible`.
    #[inline]
    pub fn compliance(
        &self,
        props: &SectionProperties,
        shear_coefficient: f64,
        inextensible: bool,
    ) -> TangentCompliance {
        match self {
            Material::LinearElastic(m) => {
                let (e, g) = (m.youngs_modulus, m.shear_modulus);
                let (cs, ca) = if inextensible {
                    (0.0, 0.0)
                } else {
                    (
                        1.0 / (shear_coefficient * g * props.area),
                        1.0 / (e * props.area),
                    )
                };
                [
                    cs,
                    cs,
                    ca,
                    1.0 / (e * props.ix),
                    1.0 / (e * props.iy),
                    1.0 / (g * props.j),
                ]
            }
        }
    }

    /// Elastic strain `(v - v*, u - u*)` produced by the body-frame wrench `(n, m)` (N, N m)
    /// and the tangent compliance there.
    #[inline]
    pub fn elastic_strain(
        &self,
        props: &SectionProperties,
        shear_coefficient: f64,
        inextensible: bool,
        wrench_body: &[f64; 6],
    ) -> ([f64; 6], TangentCompliance) {
        let c = self.compliance(props, shear_coefficient, inextensible);
        let mut e = [0.0; 6];
        for k in 0..6 {
            e[k] = c[k] * wrench_body[k];
        }
        (e, c)
    }
}
