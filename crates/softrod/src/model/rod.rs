//! The rod model: length, cross-section, material, rest strains, density and base pose.
//!
//! A [`Rod`] is an immutable, validated description; solving never mutates it. Frames: the base
//! pose maps the body frame at `s = 0` to the world frame; the body z axis is the rod tangent of
//! the undeformed straight rod (`v* = (0, 0, 1)`), x and y span the cross-section.

use std::fmt;
use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use crate::error::{check_positive, Error, Result};
use crate::math::so3::orthonormality_error;
use crate::model::material::Material;
use crate::model::section::{Section, SectionProperties};

/// Tolerance on `|RᵀR - I|` and `|det R - 1|` when a user gives a rotation matrix.
pub const ROTATION_TOLERANCE: f64 = 1e-9;

/// Number of intervals on which user functions of `s` are sampled and checked at construction.
pub const FUNCTION_CHECKS: usize = 64;

/// A user function `s (m) -> 3-vector`; it must be thread-safe.
pub type VectorFn = Arc<dyn Fn(f64) -> Vector3<f64> + Send + Sync>;

/// A 3-vector that is constant along the rod or a function of the arc length `s` (m).
#[derive(Clone)]
pub enum Profile {
    /// The same value at every `s`.
    Constant(Vector3<f64>),
    /// A user function of `s`.
    Function(VectorFn),
}

impl fmt::Debug for Profile {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Profile::Constant(v) => write!(f, "Constant([{}, {}, {}])", v.x, v.y, v.z),
            Profile::Function(_) => write!(f, "Function(<fn>)"),
        }
    }
}

impl Profile {
    /// Value at `s` (m).
    #[inline]
    pub fn at(&self, s: f64) -> Vector3<f64> {
        match self {
            Profile::Constant(v) => *v,
            Profile::Function(f) => f(s),
        }
    }

    /// Whether the profile is the constant zero vector.
    pub fn is_zero(&self) -> bool {
        matches!(self, Profile::Constant(v) if *v == Vector3::zeros())
    }

    /// The values checked: the constant (labelled `""`), or the function at the
    /// [`FUNCTION_CHECKS`] + 1 uniform points of `[0, length]` (labelled `"(s)"`).
    pub(crate) fn check_points(&self, length: f64) -> Vec<(String, Vector3<f64>)> {
        match self {
            Profile::Constant(v) => vec![(String::new(), *v)],
            Profile::Function(f) => (0..=FUNCTION_CHECKS)
                .map(|i| {
                    let s = length * i as f64 / FUNCTION_CHECKS as f64;
                    (format!("({s})"), f(s))
                })
                .collect(),
        }
    }

    /// Checks finiteness (constants) or finiteness on a grid over `[0, length]` (functions).
    pub(crate) fn check(&self, name: &str, length: f64) -> Result<()> {
        for (at, v) in self.check_points(length) {
            check_finite_vec(name, &at, &v)?;
        }
        Ok(())
    }
}

fn check_finite_vec(name: &str, at: &str, v: &Vector3<f64>) -> Result<()> {
    for k in 0..3 {
        if !v[k].is_finite() {
            return Err(Error::invalid(format!("{name}{at}[{k}]"), v[k], "finite"));
        }
    }
    Ok(())
}

/// A rigid pose: position (m, world frame) and rotation (body → world).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    position: Vector3<f64>,
    rotation: Matrix3<f64>,
}

impl Default for Pose {
    fn default() -> Self {
        Self::identity()
    }
}

impl Pose {
    /// The world origin with the body axes along the world axes (tangent along world +z).
    pub fn identity() -> Self {
        Self {
            position: Vector3::zeros(),
            rotation: Matrix3::identity(),
        }
    }

    /// A pose from a position (m) and a rotation matrix whose columns are the body x, y, z axes
    /// in world components.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `base_pose.position` or `base_pose.rotation` if not
    /// finite, or if the rotation is not orthonormal with determinant 1 to
    /// [`ROTATION_TOLERANCE`].
    pub fn new(position: Vector3<f64>, rotation: Matrix3<f64>) -> Result<Self> {
        for k in 0..3 {
            if !position[k].is_finite() {
                return Err(Error::invalid(
                    format!("base_pose.position[{k}]"),
                    position[k],
                    "finite (m)",
                ));
            }
        }
        let err = orthonormality_error(&rotation);
        if rotation.iter().any(|v| !v.is_finite()) || err.is_nan() || err > ROTATION_TOLERANCE {
            return Err(Error::invalid(
                "base_pose.rotation",
                format!("{rotation:?}"),
                format!("a rotation matrix (|R^T R - I|, |det R - 1| <= {ROTATION_TOLERANCE:e})"),
            ));
        }
        Ok(Self { position, rotation })
    }

    /// Position (m, world frame).
    pub fn position(&self) -> Vector3<f64> {
        self.position
    }

    /// Rotation body → world.
    pub fn rotation(&self) -> Matrix3<f64> {
        self.rotation
    }
}

/// A Cosserat rod (immutable, validated).
///
/// Built by [`Rod::new`] and refined by the `with_*` methods, each of which validates its
/// argument: `Rod(length, section, material, rest_strain=None, rest_curvature=None,
/// inextensible=False, density=None, base_pose=None)` in Python.
#[derive(Clone, Debug)]
pub struct Rod {
    length: f64,
    section: Section,
    material: Material,
    rest_strain: Profile,
    rest_curvature: Profile,
    inextensible: bool,
    density: Option<f64>,
    base_pose: Pose,
    shear_coefficient: Option<f64>,
}

impl Rod {
    /// A straight rod of `length` (m) with the given section and material; rest strain
    /// `v* = (0, 0, 1)`, rest curvature `u* = 0`, extensible and shearable, no density, base
    /// at the world origin with the tangent along world +z, Cowper's shear coefficient.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `length` unless finite, > 0 and at most
    /// [`MAX_LENGTH`](crate::limits::MAX_LENGTH), or naming the
    /// section property that is invalid on `[0, length]` (a table not covering it, a function
    /// returning non-positive values).
    pub fn new(length: f64, section: Section, material: impl Into<Material>) -> Result<Self> {
        crate::limits::check_length("length", length, false)?;
        section.check_on(length, FUNCTION_CHECKS)?;
        Ok(Self {
            length,
            section,
            material: material.into(),
            rest_strain: Profile::Constant(Vector3::z()),
            rest_curvature: Profile::Constant(Vector3::zeros()),
            inextensible: false,
            density: None,
            base_pose: Pose::identity(),
            shear_coefficient: None,
        })
    }

    /// Sets the rest (reference) strain `v*(s)` (dimensionless, body frame); straight and
    /// unstretched is `(0, 0, 1)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `rest_strain` (`rest_strain(s)[k]` for a function) if
    /// not finite, or if the rest stretch along the tangent `v*_z` is not > 0 at every check
    /// point: `v*_z <= 0` is a rod folded onto itself or turned backwards in its rest shape.
    pub fn with_rest_strain(mut self, rest_strain: Profile) -> Result<Self> {
        for (at, v) in rest_strain.check_points(self.length) {
            check_finite_vec("rest_strain", &at, &v)?;
            if v[2].is_nan() || v[2] <= 0.0 {
                return Err(Error::invalid(
                    format!("rest_strain{at}[2]"),
                    v[2],
                    "> 0: the rest stretch along the tangent ((0, 0, 1) is straight and \
                     unstretched)",
                ));
            }
        }
        self.rest_strain = rest_strain;
        Ok(self)
    }

    /// Sets the rest curvature `u*(s)` (1/m, body frame): bending about x, y and twist about z
    /// per unit undeformed length, for precurved rods.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `rest_curvature` if not finite.
    pub fn with_rest_curvature(mut self, rest_curvature: Profile) -> Result<Self> {
        rest_curvature.check("rest_curvature", self.length)?;
        self.rest_curvature = rest_curvature;
        Ok(self)
    }

    /// Inextensible and unshearable (Kirchhoff) limit: `v = v*` whatever the internal force.
    pub fn with_inextensible(mut self, inextensible: bool) -> Self {
        self.inextensible = inextensible;
        self
    }

    /// Sets the mass density (kg/m³), used by gravity loads (`rho A(s) g` per unit length).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `density` unless finite, > 0 and at most
    /// [`MAX_DENSITY`](crate::limits::MAX_DENSITY).
    pub fn with_density(mut self, density: f64) -> Result<Self> {
        check_positive("density", density, "kg/m^3")?;
        if density > crate::limits::MAX_DENSITY {
            return Err(Error::invalid(
                "density",
                density,
                format!(
                    "<= {:e} kg/m^3 (44 times the densest element's)",
                    crate::limits::MAX_DENSITY
                ),
            ));
        }
        self.density = Some(density);
        Ok(self)
    }

    /// Sets the base pose (see [`Pose`]).
    pub fn with_base_pose(mut self, base_pose: Pose) -> Self {
        self.base_pose = base_pose;
        self
    }

    /// Overrides the shear coefficient `k` (shear area `k A`); by default Cowper's value for
    /// the section ([`Section::cowper_shear_coefficient`], 0.886 for a solid circle at
    /// `nu = 0.3`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `shear_coefficient` unless finite and > 0.
    pub fn with_shear_coefficient(mut self, shear_coefficient: f64) -> Result<Self> {
        check_positive("shear_coefficient", shear_coefficient, "")?;
        self.shear_coefficient = Some(shear_coefficient);
        Ok(self)
    }

    /// Length `L` (m).
    pub fn length(&self) -> f64 {
        self.length
    }
    /// The cross-section.
    pub fn section(&self) -> &Section {
        &self.section
    }
    /// The material.
    pub fn material(&self) -> &Material {
        &self.material
    }
    /// Rest strain `v*(s)`.
    pub fn rest_strain(&self) -> &Profile {
        &self.rest_strain
    }
    /// Rest curvature `u*(s)` (1/m).
    pub fn rest_curvature(&self) -> &Profile {
        &self.rest_curvature
    }
    /// Whether the rod is inextensible and unshearable.
    pub fn inextensible(&self) -> bool {
        self.inextensible
    }
    /// Mass density (kg/m³), if given.
    pub fn density(&self) -> Option<f64> {
        self.density
    }
    /// Base pose.
    pub fn base_pose(&self) -> Pose {
        self.base_pose
    }
    /// Shear coefficient `k` in use (the override or Cowper's value).
    pub fn shear_coefficient(&self) -> f64 {
        self.shear_coefficient.unwrap_or_else(|| {
            self.section
                .cowper_shear_coefficient(self.material.poisson_ratio())
        })
    }

    /// Section properties at `s` (m).
    #[inline]
    pub fn section_at(&self, s: f64) -> SectionProperties {
        self.section.properties(s, self.length)
    }
}
