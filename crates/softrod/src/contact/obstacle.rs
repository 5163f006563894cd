//! Rigid obstacles and their signed distance: planes, spheres, capsules and finite cylinders.
//!
//! Geometry follows the plotting classes of the Python package (`softrod.Plane(point,
//! normal)`, `Sphere(center, radius)`, `Capsule(a, b, radius)`, `Cylinder(a, b, radius)`), all
//! in world coordinates (m). The rod's surface is the envelope of the spheres of its local
//! outer radius `R(s)` centred on the backbone, so the gap at `s` is the signed distance of
//! the backbone point to the obstacle minus `R(s)`.

use std::sync::Arc;

use nalgebra::Vector3;

pub use super::mesh::TriangleMesh;

use crate::model::hold::Surface;

use crate::error::{Error, Result};

/// A rigid obstacle (world frame, m).
#[derive(Debug, Clone, PartialEq)]
pub enum Obstacle {
    /// The half-space behind the plane through `point` with unit outward `normal`.
    Plane {
        /// A point of the plane (m).
        point: Vector3<f64>,
        /// Unit outward normal (the free side).
        normal: Vector3<f64>,
    },
    /// A solid ball.
    Sphere {
        /// Centre (m).
        center: Vector3<f64>,
        /// Radius (m), > 0.
        radius: f64,
    },
    /// The points within `radius` of the segment `a`–`b`.
    Capsule {
        /// First end of the axis (m).
        a: Vector3<f64>,
        /// Second end of the axis (m).
        b: Vector3<f64>,
        /// Radius (m), > 0.
        radius: f64,
    },
    /// A solid circular cylinder with flat end caps at `a` and `b`.
    Cylinder {
        /// Centre of the first cap (m).
        a: Vector3<f64>,
        /// Centre of the second cap (m).
        b: Vector3<f64>,
        /// Radius (m), > 0.
        radius: f64,
    },
    /// A triangle mesh ([`TriangleMesh`]; world frame, m): the signed distance to its
    /// triangles, negative inside a closed mesh (outward faces counter-clockwise).
    Mesh(Arc<TriangleMesh>),
    /// The obstacle `shape` (any of the others) with Coulomb friction of coefficient
    /// `friction` (> 0, dimensionless) at its surface; made by [`Obstacle::with_friction`].
    Frictional {
        /// The geometry (not itself `Frictional`).
        shape: Box<Obstacle>,
        /// Coulomb friction coefficient μ (> 0): the tangential force on a contact is at
        /// most μ times its normal force.
        friction: f64,
    },
}

fn finite3(name: &str, v: [f64; 3]) -> Result<Vector3<f64>> {
    for (k, x) in v.iter().enumerate() {
        if !x.is_finite() {
            return Err(Error::invalid(format!("{name}[{k}]"), x, "finite (m)"));
        }
    }
    Ok(Vector3::from(v))
}

/// The vector `normal` made unit.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `normal` if it is zero or its length not finite.
pub(super) fn unit_normal(normal: [f64; 3]) -> Result<Vector3<f64>> {
    let n = Vector3::from(normal);
    // (Scaled by its largest component first: a vector of 1e-300 or 1e300 has a length that
    // underflows or overflows, and a direction.)
    let largest = n.amax();
    if !(largest.is_finite() && largest > 0.0) {
        return Err(Error::invalid(
            "normal",
            format!("{normal:?}"),
            "a non-zero vector",
        ));
    }
    Ok((n / largest).normalize())
}

fn positive(name: &str, r: f64) -> Result<f64> {
    if r.is_finite() && r > 0.0 {
        Ok(r)
    } else {
        Err(Error::invalid(name, r, "finite and > 0 (m)"))
    }
}

fn axis(a: [f64; 3], b: [f64; 3]) -> Result<(Vector3<f64>, Vector3<f64>)> {
    let (a, b) = (finite3("a", a)?, finite3("b", b)?);
    let l = (b - a).norm();
    if l.is_finite() && l > 0.0 {
        Ok((a, b))
    } else {
        Err(Error::invalid(
            "b",
            format!("{b:?}"),
            "a point other than a (m)",
        ))
    }
}

/// A unit vector normal to `n` (for a degenerate direction).
fn any_normal(n: &Vector3<f64>) -> Vector3<f64> {
    let t = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    n.cross(&t).normalize()
}

impl Obstacle {
    /// The plane through `point` (m) with outward `normal` (any non-zero length).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `point[k]` or `normal` (not finite or zero).
    pub fn plane(point: [f64; 3], normal: [f64; 3]) -> Result<Self> {
        let point = finite3("point", point)?;
        finite3("normal", normal)?;
        Ok(Self::Plane {
            point,
            normal: unit_normal(normal)?,
        })
    }

    /// The ball of `radius` (m) about `center` (m).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `center[k]` or `radius`.
    pub fn sphere(center: [f64; 3], radius: f64) -> Result<Self> {
        Ok(Self::Sphere {
            center: finite3("center", center)?,
            radius: positive("radius", radius)?,
        })
    }

    /// The capsule of `radius` (m) about the segment `a`–`b` (m).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `a[k]`, `b[k]`, `b` (equal to `a`) or `radius`.
    pub fn capsule(a: [f64; 3], b: [f64; 3], radius: f64) -> Result<Self> {
        let (a, b) = axis(a, b)?;
        Ok(Self::Capsule {
            a,
            b,
            radius: positive("radius", radius)?,
        })
    }

    /// The cylinder of `radius` (m) between the cap centres `a` and `b` (m).
    ///
    /// # Errors
    /// As [`Obstacle::capsule`].
    pub fn cylinder(a: [f64; 3], b: [f64; 3], radius: f64) -> Result<Self> {
        let (a, b) = axis(a, b)?;
        Ok(Self::Cylinder {
            a,
            b,
            radius: positive("radius", radius)?,
        })
    }

    /// A triangle mesh from its vertices (m, world) and faces (vertex indices,
    /// counter-clockwise seen from outside).
    ///
    /// # Errors
    /// As [`TriangleMesh::new`].
    pub fn mesh(vertices: Vec<[f64; 3]>, faces: Vec<[usize; 3]>) -> Result<Self> {
        Ok(Self::Mesh(Arc::new(TriangleMesh::new(vertices, faces)?)))
    }

    /// The obstacle with Coulomb friction coefficient `mu` (dimensionless, finite, >= 0) at
    /// its surface; `mu = 0` is the frictionless obstacle. Friction acts at point contacts, at
    /// the tip and inside the rod (see [`super::ContactState`]); a plane with friction the rod
    /// lies along (a contact interval) is refused by the solve.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `friction` outside `[0,`
    /// [`MAX_FRICTION`](crate::limits::MAX_FRICTION)`]`.
    pub fn with_friction(self, mu: f64) -> Result<Self> {
        crate::limits::check_friction("friction", mu)?;
        let shape = match self {
            Self::Frictional { shape, .. } => *shape,
            other => other,
        };
        Ok(if mu == 0.0 {
            shape
        } else {
            Self::Frictional {
                shape: Box::new(shape),
                friction: mu,
            }
        })
    }

    /// The Coulomb friction coefficient of the surface (dimensionless; 0: frictionless).
    pub fn friction(&self) -> f64 {
        match self {
            Self::Frictional { friction, .. } => *friction,
            _ => 0.0,
        }
    }

    /// The geometry of the obstacle (itself, or the shape of a frictional one).
    pub fn shape(&self) -> &Obstacle {
        match self {
            Self::Frictional { shape, .. } => shape.shape(),
            other => other,
        }
    }

    /// Signed distance (m; negative inside) of the point `x` (m) to the obstacle's surface,
    /// and the unit outward normal of the surface at the closest point (the gradient of the
    /// distance).
    pub fn distance(&self, x: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let radial = |d: Vector3<f64>, r: f64, fallback: Vector3<f64>| {
            let l = d.norm();
            if l > 0.0 {
                (l - r, d / l)
            } else {
                (-r, fallback)
            }
        };
        match *self {
            Self::Frictional { ref shape, .. } => shape.distance(x),
            Self::Mesh(ref m) => m.distance(x),
            Self::Plane { point, normal } => (normal.dot(&(x - point)), normal),
            Self::Sphere { center, radius } => radial(x - center, radius, Vector3::z()),
            Self::Capsule { a, b, radius } => {
                let u = b - a;
                let t = ((x - a).dot(&u) / u.norm_squared()).clamp(0.0, 1.0);
                radial(x - (a + u * t), radius, any_normal(&u))
            }
            Self::Cylinder { a, b, radius } => {
                let h = (b - a).norm();
                let u = (b - a) / h;
                let t = (x - a).dot(&u);
                let rho = x - a - u * t;
                let r = rho.norm();
                let e = if r > 0.0 { rho / r } else { any_normal(&u) };
                let dr = r - radius;
                let (dz, axial) = if t < 0.5 * h { (-t, -u) } else { (t - h, u) };
                if dr > 0.0 && dz > 0.0 {
                    let d = (dr * dr + dz * dz).sqrt();
                    (d, (e * dr + axial * dz) / d)
                } else if dr > dz {
                    (dr, e)
                } else {
                    (dz, axial)
                }
            }
        }
    }
}

impl Surface for Obstacle {
    fn distance(&self, x: &Vector3<f64>) -> (f64, Vector3<f64>) {
        Obstacle::distance(self, x)
    }

    fn curvature(&self, x: &Vector3<f64>, t: &Vector3<f64>) -> Option<f64> {
        self.distance_curvature(x, t)
    }
}

impl Obstacle {
    /// `tᵀ H t` with `H` the Hessian of the signed distance at `x` (m, world; `t` any
    /// vector): `(|t|² - (n·t)²)/ρ` about a sphere's centre or a capsule's end (`ρ` the
    /// distance to it), `(|t|² - (n·t)² - (e·t)²)/ρ` about the axis of a capsule or of a
    /// cylinder's side (`e` the axis, `ρ` the distance to it), zero for a plane or a
    /// cylinder's flat cap; `None` for a triangle mesh, on a cylinder's rim and on an axis
    /// or centre.
    pub(crate) fn distance_curvature(&self, x: &Vector3<f64>, t: &Vector3<f64>) -> Option<f64> {
        let about = |d: Vector3<f64>, axis: Option<Vector3<f64>>| {
            let rho = d.norm();
            if rho <= 0.0 {
                return None;
            }
            let n = d / rho;
            let along = axis.map_or(0.0, |e| e.dot(t).powi(2));
            Some((t.norm_squared() - n.dot(t).powi(2) - along) / rho)
        };
        match *self {
            Self::Frictional { ref shape, .. } => shape.distance_curvature(x, t),
            Self::Mesh(_) => None,
            Self::Plane { .. } => Some(0.0),
            Self::Sphere { center, .. } => about(x - center, None),
            Self::Capsule { a, b, .. } => {
                let u = b - a;
                let s = (x - a).dot(&u) / u.norm_squared();
                if s <= 0.0 {
                    about(x - a, None)
                } else if s >= 1.0 {
                    about(x - b, None)
                } else {
                    about(x - (a + u * s), Some(u.normalize()))
                }
            }
            Self::Cylinder { a, b, radius } => {
                let h = (b - a).norm();
                let u = (b - a) / h;
                let s = (x - a).dot(&u);
                let rho = x - a - u * s;
                let dr = rho.norm() - radius;
                let dz = if s < 0.5 * h { -s } else { s - h };
                if dr > 0.0 && dz > 0.0 {
                    None
                } else if dr > dz {
                    about(rho, Some(u))
                } else {
                    Some(0.0)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// The returned normal is the gradient of the distance (central differences), and the
    /// distances are the closed forms at a few points.
    #[test]
    fn normals_are_gradients_of_the_distance() {
        let obstacles = [
            Obstacle::plane([0.0, 0.0, 0.1], [0.0, 1.0, 1.0]).unwrap(),
            Obstacle::sphere([0.1, 0.0, 0.0], 0.05).unwrap(),
            Obstacle::capsule([0.0, 0.0, 0.0], [0.0, 0.0, 0.2], 0.03).unwrap(),
            Obstacle::cylinder([0.0, 0.0, 0.0], [0.0, 0.0, 0.2], 0.03).unwrap(),
        ];
        let points = [
            Vector3::new(0.07, 0.02, 0.25),
            Vector3::new(0.01, 0.011, 0.1),
            Vector3::new(0.2, -0.1, -0.05),
            Vector3::new(0.0, 0.01, 0.19),
        ];
        let h = 1e-7;
        for o in &obstacles {
            for x in &points {
                let (_, n) = o.distance(x);
                for k in 0..3 {
                    let mut e = Vector3::zeros();
                    e[k] = h;
                    let g = (o.distance(&(x + e)).0 - o.distance(&(x - e)).0) / (2.0 * h);
                    assert!((g - n[k]).abs() < 1e-6, "{o:?} at {x:?}: {g} vs {}", n[k]);
                }
            }
        }
        let d = obstacles[1].distance(&Vector3::new(0.1, 0.0, 0.2)).0;
        assert!((d - 0.15).abs() < 1e-15);
        let d = obstacles[3].distance(&Vector3::new(0.0, 0.01, 0.19)).0;
        assert!((d + 0.01).abs() < 1e-15);
        let d = obstacles[3].distance(&Vector3::new(0.07, 0.0, 0.23)).0;
        assert!((d - 0.05).abs() < 1e-15);
    }

    /// Friction changes neither the geometry nor the distance; a second coefficient replaces
    /// the first, and 0 gives back the frictionless obstacle.
    #[test]
    fn friction_keeps_the_geometry() {
        let sphere = Obstacle::sphere([0.1, 0.0, 0.0], 0.05).unwrap();
        let rough = sphere.clone().with_friction(0.4).unwrap();
        assert_eq!(rough.friction(), 0.4);
        assert_eq!(rough.shape(), &sphere);
        let x = Vector3::new(0.0, 0.02, 0.03);
        assert_eq!(rough.distance(&x), sphere.distance(&x));
        let again = rough.clone().with_friction(0.2).unwrap();
        assert_eq!((again.friction(), again.shape()), (0.2, &sphere));
        assert_eq!(rough.with_friction(0.0).unwrap(), sphere);
        assert_eq!(sphere.friction(), 0.0);
    }

    #[test]
    fn bad_geometry_is_a_named_error() {
        assert!(Obstacle::sphere([0.0; 3], -1.0)
            .unwrap_err()
            .to_string()
            .contains("radius"));
        assert!(Obstacle::plane([0.0; 3], [0.0; 3])
            .unwrap_err()
            .to_string()
            .contains("normal"));
        assert!(Obstacle::capsule([0.0; 3], [0.0; 3], 0.1)
            .unwrap_err()
            .to_string()
            .contains('b'));
    }
}
