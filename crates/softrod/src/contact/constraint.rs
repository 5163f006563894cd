//! End constraints on the tip: clamped at a pose, pinned at a point, sliding on a plane, or
//! any of the six tip degrees of freedom held in a frame.

use nalgebra::{Matrix3, Vector3};

use crate::error::{Error, Result};
use crate::model::rod::Pose;

/// The tip held in some of its six degrees of freedom, in the frame of `pose`: translations
/// along the frame's x, y, z axes and rotations about them. A held translation puts the tip
/// at `pose`'s position along that axis; held rotations either all three (the tip frame is
/// `pose`'s rotation) or the two about x and y (the tip's z axis, its tangent, along `pose`'s
/// z axis, free to twist about it). The directions not held carry the applied tip loads; the
/// held ones a reaction ([`super::ContactSolution::tip_reaction`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipConstraint {
    /// Target position (m, world) and frame of the held directions (body → world).
    pub pose: Pose,
    /// Held directions `[x, y, z, rx, ry, rz]` of the frame.
    pub held: [bool; 6],
}

impl TipConstraint {
    /// The tip clamped at `pose`: position and orientation (a 4×4 transform in Python,
    /// `softrod.Clamp(pose)`).
    pub fn clamp(pose: Pose) -> Self {
        Self {
            pose,
            held: [true; 6],
        }
    }

    /// The tip pinned at `point` (m, world), free to rotate (`softrod.Pin(point)`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `point[k]` if not finite.
    pub fn pin(point: [f64; 3]) -> Result<Self> {
        let pose = Pose::new(Vector3::from(point), Matrix3::identity())
            .map_err(|_| Error::invalid("point", format!("{point:?}"), "finite (m)"))?;
        Ok(Self {
            pose,
            held: [true, true, true, false, false, false],
        })
    }

    /// The tip sliding without friction on the plane through `point` (m) with `normal`: held
    /// along the normal only.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `point` or `normal` (not finite, zero).
    pub fn slide(point: [f64; 3], normal: [f64; 3]) -> Result<Self> {
        let z = super::obstacle::unit_normal(normal)?;
        let x = crate::contact::obstacle_normal_basis(&z).0;
        let y = z.cross(&x);
        let r = Matrix3::from_columns(&[x, y, z]);
        let pose = Pose::new(Vector3::from(point), r)
            .map_err(|_| Error::invalid("point", format!("{point:?}"), "finite (m)"))?;
        Ok(Self {
            pose,
            held: [false, false, true, false, false, false],
        })
    }

    /// The tip held in the directions `held` of `pose`'s frame.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `held` when the rotations held are not all three,
    /// the two about x and y, or none, or when nothing is held.
    pub fn new(pose: Pose, held: [bool; 6]) -> Result<Self> {
        let rot = [held[3], held[4], held[5]];
        if !matches!(
            rot,
            [true, true, true] | [true, true, false] | [false, false, false]
        ) {
            return Err(Error::invalid(
                "held",
                format!("{held:?}"),
                "rotations [rx, ry, rz] held all, only rx and ry, or none",
            ));
        }
        if !held.iter().any(|h| *h) {
            return Err(Error::invalid(
                "held",
                format!("{held:?}"),
                "at least one held direction",
            ));
        }
        Ok(Self { pose, held })
    }

    /// Number of held rotations (0, 2 or 3).
    pub(crate) fn rotations_held(&self) -> usize {
        self.held[3..].iter().filter(|h| **h).count()
    }
}
