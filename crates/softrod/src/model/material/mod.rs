//! Constitutive laws of a rod section: from the body-frame internal wrench to the strains.
//!
//! The solver asks a [`Material`] for the *elastic strain* `(v - v*, u - u*)` produced by a
//! body-frame wrench `(n, m)` on a section, and for the *tangent compliance* `d(v, u)/d(n, m)`
//! there. For a linear material these are `C (n, m)` and `C` with the diagonal section
//! compliance `C = diag(1/(k G A), 1/(k G A), 1/(E A), 1/(E Ix), 1/(E Iy), 1/(G J))`
//! (`k` the shear coefficient; shear and stretch compliances are zero in the inextensible,
//! unshearable Kirchhoff limit).
//!
//! # Hyperelastic rods
//! [`Material::Hyperelastic`] holds an incompressible uniaxial law (nominal stress `P(λ)`, see
//! [`crate::model::material::hyperelastic`]) and integrates it over the section as a *fibre section*: with
//! rigid cross-sections (the Cosserat kinematics that also places tendons and chambers), the
//! material fibre at the reference offset `r = (X, Y)` has the stretch
//! `λ_f = 1 + (v_z - v*_z) + (κ × r)_z = λ + κ_x Y - κ_y X` (`κ = u - u*`), carries the axial
//! force `P(λ_f) dA0` and nothing else, so the section's strain energy per undeformed length is
//! `∫ Ψ(λ_f) dA0` (`Ψ' = P`) and
//!
//! ```text
//! n_z = ∫ P(λ_f) dA0,   m_x = ∫ Y P(λ_f) dA0,   m_y = -∫ X P(λ_f) dA0,
//! ```
//!
//! with the symmetric tangent `∫ P'(λ_f) g gᵀ dA0`, `g = (1, Y, -X)`: axial stiffness
//! `A0 P'(λ)` and bending stiffness `P'(λ) I0` per undeformed curvature at the stretch `λ`, the
//! axial force `A0 P(λ) + P''(λ) I0 κ²/2 + ...` (stretch–bending coupling from the energy). The
//! integral uses [`FIBRES`] fibres of weight `A0/4` at `(±sqrt(2 Iy/A0), 0)` and
//! `(0, ±sqrt(2 Ix/A0))`, which reproduce `A0`, `Ix`, `Iy` exactly (so the law is exact for a
//! linear `P` and to second order in `κ r` for any law) and, for a solid circle bent about a
//! body axis, the fourth moments too. Shear and torsion carry no fibre stress: they are linear
//! with the small-strain shear modulus `G0 = E0 / 3` (incompressible, `ν = 1/2`), shear area
//! `k A0`. The law is hyperelastic (a potential), so its tangent and the rod's stiffness are
//! symmetric; its small-strain limit is [`LinearElastic`] with `E = E0` (`3 μ0` Neo-Hookean,
//! `6 (C10 + C01)` Mooney–Rivlin, `6 C10` Yeoh) and `ν = 1/2`.
//!
//! Why `P'` and the reference `I0` rather than the true tangent modulus `dσ/dλ = P + λ P'` and
//! the contracted `I0/λ²`: a fibre's force is `P dA0` and, with rigid sections, its moment arm
//! is its reference offset; `dσ/dλ` also counts the change of the fibre's area, which moves no
//! force. All three agree at `λ = 1`.
//!
//! # References
//! E. Spacone, F. C. Filippou, F. F. Taucer, "Fibre beam-column model for non-linear analysis
//! of R/C frames", Earthq. Eng. Struct. Dyn. 25(7), 1996 (fibre sections).

pub mod fit;
pub mod hyperelastic;
pub mod silicone;

use nalgebra::{Matrix6, Vector6};

use crate::error::{Error, Result};
use crate::model::material::hyperelastic::{UniaxialLaw, UniaxialModel};
use crate::model::section::SectionProperties;

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
        crate::limits::check_modulus("youngs_modulus", youngs_modulus)?;
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
        crate::limits::check_modulus("youngs_modulus", youngs_modulus)?;
        crate::limits::check_modulus("shear_modulus", shear_modulus)?;
        let nu = youngs_modulus / (2.0 * shear_modulus) - 1.0;
        if !(nu > -1.0 && nu <= 0.5 + 1e-12) {
            return Err(Error::invalid(
                "shear_modulus",
                shear_modulus,
                format!(
                    "in [E/3, inf) = [{}, inf) Pa with E = youngs_modulus (Poisson's ratio in \
                     (-1, 0.5])",
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

/// Number of fibres of the section rule of [`Material::Hyperelastic`].
pub const FIBRES: usize = 4;

/// Relative step tolerance of the wrench → strain inversion of a hyperelastic section.
pub const SECTION_TOLERANCE: f64 = 1e-14;

/// Iteration cap of the wrench → strain inversion of a hyperelastic section.
pub const SECTION_MAX_ITERATIONS: usize = 60;

/// The material of a rod.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Material {
    /// Isotropic linear elasticity.
    LinearElastic(LinearElastic),
    /// Incompressible hyperelastic fibre section (see the module documentation): axial force
    /// and bending from the uniaxial law at each fibre's stretch, shear and torsion linear with
    /// `G0 = E0 / 3`.
    Hyperelastic(UniaxialModel),
}

impl From<LinearElastic> for Material {
    fn from(m: LinearElastic) -> Self {
        Material::LinearElastic(m)
    }
}

impl From<UniaxialModel> for Material {
    fn from(m: UniaxialModel) -> Self {
        Material::Hyperelastic(m)
    }
}

/// Tangent compliance `d(v, u)/d(n, m)` of a section, in the body frame.
///
/// Diagonal: `[shear x, shear y, stretch z, bend x, bend y, twist z]`, units
/// `1/N` for the first three and `1/(N m²)` for the last three.
pub type TangentCompliance = [f64; 6];

/// The fibre section of a hyperelastic rod at one strain: wrench, stiffness and fibre stretches.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FibreState {
    /// Body wrench `[n; m]` (N, N m).
    pub wrench: [f64; 6],
    /// Tangent stiffness `d(n, m)/d(v, u)` (symmetric).
    pub stiffness: Matrix6<f64>,
    /// Stretch of each fibre.
    pub stretch: [f64; FIBRES],
}

/// Fibre offsets `(X, Y)` (m) and weight `A0/4` (m²) of the section rule.
#[inline]
fn fibres(props: &SectionProperties) -> ([[f64; 2]; FIBRES], f64) {
    let a = (2.0 * props.iy / props.area).sqrt();
    let b = (2.0 * props.ix / props.area).sqrt();
    (
        [[a, 0.0], [-a, 0.0], [0.0, b], [0.0, -b]],
        0.25 * props.area,
    )
}

impl Material {
    /// Poisson's ratio of the material (for the default shear coefficient); 1/2 for
    /// hyperelastic (incompressible) materials.
    pub fn poisson_ratio(&self) -> f64 {
        match self {
            Material::LinearElastic(m) => m.poisson_ratio(),
            Material::Hyperelastic(_) => 0.5,
        }
    }

    /// Whether the section law is linear (strain proportional to wrench).
    pub fn is_linear(&self) -> bool {
        matches!(self, Material::LinearElastic(_))
    }

    /// Small-strain Young's and shear moduli `(E0, G0)` (Pa).
    pub fn small_strain_moduli(&self) -> (f64, f64) {
        match self {
            Material::LinearElastic(m) => (m.youngs_modulus, m.shear_modulus),
            Material::Hyperelastic(law) => {
                let e0 = law.small_strain_modulus();
                (e0, e0 / 3.0)
            }
        }
    }

    /// Bending stiffness `E0 min(Ix, Iy)` (N m²) of a section at zero strain (a force scale
    /// for the solver).
    pub fn bending_stiffness(&self, props: &SectionProperties) -> f64 {
        self.small_strain_moduli().0 * props.ix.min(props.iy)
    }

    /// Small-strain section compliance `diag(1/(k G A), 1/(k G A), 1/(E A), 1/(E Ix),
    /// 1/(E Iy), 1/(G J))` (the exact one for a linear material), with zero shear and stretch
    /// compliances when `inextensible`.
    #[inline]
    pub fn compliance(
        &self,
        props: &SectionProperties,
        shear_coefficient: f64,
        inextensible: bool,
    ) -> TangentCompliance {
        let (e, g) = self.small_strain_moduli();
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

    /// The fibre section of a hyperelastic material at the elastic strain
    /// `e = (v - v*, u - u*)`; `None` for a linear material or if a fibre stretch is not
    /// positive. In the inextensible limit the stretch is 1 and the shear rows are zero.
    pub(crate) fn fibre_state(
        &self,
        props: &SectionProperties,
        shear_coefficient: f64,
        inextensible: bool,
        e: &[f64; 6],
    ) -> Option<FibreState> {
        let Material::Hyperelastic(law) = self else {
            return None;
        };
        let (_, g0) = self.small_strain_moduli();
        let (pts, w) = fibres(props);
        let lambda = if inextensible { 1.0 } else { 1.0 + e[2] };
        let mut wrench = [0.0; 6];
        let mut k = Matrix6::zeros();
        let mut stretch = [0.0; FIBRES];
        for (f, [x, y]) in pts.iter().enumerate() {
            let lf = lambda + e[3] * y - e[4] * x;
            if !(lf > 0.0 && lf.is_finite()) {
                return None;
            }
            stretch[f] = lf;
            let p = law.nominal_stress_unchecked(lf) * w;
            let dp = law.nominal_slope_unchecked(lf) * w;
            let g = [1.0, *y, -x];
            for a in 0..3 {
                wrench[2 + a] += g[a] * p;
                for b in 0..3 {
                    k[(2 + a, 2 + b)] += g[a] * g[b] * dp;
                }
            }
        }
        let ks = shear_coefficient * g0 * props.area;
        let kt = g0 * props.j;
        if inextensible {
            for a in 0..3 {
                k[(2, a + 2)] = 0.0;
                k[(a + 2, 2)] = 0.0;
            }
        } else {
            wrench[0] = ks * e[0];
            wrench[1] = ks * e[1];
            k[(0, 0)] = ks;
            k[(1, 1)] = ks;
        }
        wrench[5] = kt * e[5];
        k[(5, 5)] = kt;
        Some(FibreState {
            wrench,
            stiffness: k,
            stretch,
        })
    }

    /// Elastic strain `(v - v*, u - u*)` produced by the body-frame wrench `(n, m)` (N, N m)
    /// and the diagonal tangent compliance there (see [`Material::tangent_compliance`]).
    /// For a hyperelastic material the fibre section is inverted by Newton's method (stretch
    /// and bending coupled, shear and torsion linear); NaN if that fails (a wrench the law
    /// cannot carry).
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
        if self.is_linear() {
            return (e, c);
        }
        match self.invert_section(props, shear_coefficient, inextensible, wrench_body, e) {
            Some(e) => {
                let t = self.tangent_compliance(props, shear_coefficient, inextensible, &e);
                (e, t)
            }
            None => ([f64::NAN; 6], [f64::NAN; 6]),
        }
    }

    /// Newton inversion of the fibre section for the coupled rows (stretch, bending x, y),
    /// from `e`; shear and torsion are linear and already exact in `e`.
    fn invert_section(
        &self,
        props: &SectionProperties,
        shear_coefficient: f64,
        inextensible: bool,
        wrench: &[f64; 6],
        mut e: [f64; 6],
    ) -> Option<[f64; 6]> {
        let rows: &[usize] = if inextensible { &[3, 4] } else { &[2, 3, 4] };
        for _ in 0..SECTION_MAX_ITERATIONS {
            let st = self.fibre_state(props, shear_coefficient, inextensible, &e)?;
            let n = rows.len();
            let mut jac = nalgebra::DMatrix::zeros(n, n);
            let mut r = nalgebra::DVector::zeros(n);
            for (i, &a) in rows.iter().enumerate() {
                r[i] = st.wrench[a] - wrench[a];
                for (j, &b) in rows.iter().enumerate() {
                    jac[(i, j)] = st.stiffness[(a, b)];
                }
            }
            let dx = jac.lu().solve(&r)?;
            // Halve the step while a fibre would reach a non-positive stretch.
            let mut t = 1.0;
            let mut next = e;
            for _ in 0..60 {
                next = e;
                for (i, &a) in rows.iter().enumerate() {
                    next[a] -= t * dx[i];
                }
                if self
                    .fibre_state(props, shear_coefficient, inextensible, &next)
                    .is_some()
                {
                    break;
                }
                t *= 0.5;
            }
            let step = dx.amax() * t;
            e = next;
            if step <= SECTION_TOLERANCE * (1.0 + e.iter().fold(0.0f64, |m, v| m.max(v.abs()))) {
                return Some(e);
            }
        }
        None
    }

    /// Element compliance `c(s)` (the compliance-methodology paper, eq. 1) at the elastic strain
    /// `e = (v - v*, u - u*)` (zero rows in the inextensible limit):
    /// `diag(1/(k G A), 1/(k G A), 1/(E_t A), 1/(E_t Ix), 1/(E_t Iy), 1/(G J))` with the tangent
    /// stiffnesses of the section at that strain (`E_t A = ∂n_z/∂v_z`, `E_t Ix = ∂m_x/∂u_x`,
    /// ...). It leaves out the stretch–bending coupling of a bent hyperelastic section, which
    /// [`Material::tangent_compliance_matrix`] keeps. Linear materials: [`Material::compliance`].
    pub fn tangent_compliance(
        &self,
        props: &SectionProperties,
        shear_coefficient: f64,
        inextensible: bool,
        e: &[f64; 6],
    ) -> TangentCompliance {
        let c = self.compliance(props, shear_coefficient, inextensible);
        match self.fibre_state(props, shear_coefficient, inextensible, e) {
            None if self.is_linear() => c,
            None => [f64::NAN; 6],
            Some(st) => {
                let mut t = [0.0; 6];
                for k in 0..6 {
                    t[k] = if c[k] == 0.0 {
                        0.0
                    } else {
                        1.0 / st.stiffness[(k, k)]
                    };
                }
                t
            }
        }
    }

    /// Exact tangent compliance `d(v, u)/d(n, m)` of the section at the elastic strain `e`: the
    /// inverse of the section stiffness (symmetric), with zero rows and columns for the
    /// constrained strains of the inextensible limit; NaN if the section is not stable there.
    pub fn tangent_compliance_matrix(
        &self,
        props: &SectionProperties,
        shear_coefficient: f64,
        inextensible: bool,
        e: &[f64; 6],
    ) -> Matrix6<f64> {
        let c = self.compliance(props, shear_coefficient, inextensible);
        if self.is_linear() {
            return Matrix6::from_diagonal(&Vector6::from_column_slice(&c));
        }
        let Some(st) = self.fibre_state(props, shear_coefficient, inextensible, e) else {
            return Matrix6::repeat(f64::NAN);
        };
        let free: Vec<usize> = (0..6).filter(|&k| c[k] != 0.0).collect();
        let n = free.len();
        let sub = nalgebra::DMatrix::from_fn(n, n, |i, j| st.stiffness[(free[i], free[j])]);
        let mut out = Matrix6::zeros();
        match sub.cholesky() {
            Some(ch) => {
                let inv = ch.inverse();
                for (i, &a) in free.iter().enumerate() {
                    for (j, &b) in free.iter().enumerate() {
                        out[(a, b)] = inv[(i, j)];
                    }
                }
                out
            }
            None => Matrix6::repeat(f64::NAN),
        }
    }

    /// The uniaxial law of a hyperelastic material.
    pub fn uniaxial_law(&self) -> Option<&UniaxialModel> {
        match self {
            Material::Hyperelastic(law) => Some(law),
            Material::LinearElastic(_) => None,
        }
    }
}
