//! External loads on a rod: tip wrench, point wrenches, distributed force and moment, gravity.
//!
//! All vectors are in the world frame unless a [`Frame::Body`] is given (body components are
//! rotated with the rod: follower loads). Forces in N, moments in N m, distributed forces in
//! N/m, distributed moments in N m/m, gravity in m/s².

use nalgebra::Vector3;

use crate::error::{Error, Result};
use crate::model::rod::Profile;

/// Frame in which a load's components are given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Frame {
    /// World components (dead load).
    #[default]
    World,
    /// Body components at the point of application (follower load).
    Body,
}

/// A force and moment applied at one arc length (a jump in the internal wrench).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLoad {
    /// Arc length of application (m), in `(0, L]`; `L` adds to the tip wrench.
    pub s: f64,
    /// Force (N).
    pub force: Vector3<f64>,
    /// Moment (N m).
    pub moment: Vector3<f64>,
    /// Frame of `force` and `moment`.
    pub frame: Frame,
}

impl PointLoad {
    /// A validated point load: `s` (m) finite and > 0 (`<= L` is checked with the rod),
    /// `force` (N) and `moment` (N m) finite.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `s`, `force[k]` or `moment[k]`.
    pub fn new(s: f64, force: Vector3<f64>, moment: Vector3<f64>, frame: Frame) -> Result<Self> {
        let p = Self {
            s,
            force,
            moment,
            frame,
        };
        p.check_values("")?;
        Ok(p)
    }

    fn check_values(&self, prefix: &str) -> Result<()> {
        if !(self.s.is_finite() && self.s > 0.0) {
            return Err(Error::invalid(
                format!("{prefix}s"),
                self.s,
                "finite and > 0 m (in (0, length])",
            ));
        }
        check_vec(&format!("{prefix}force"), &self.force)?;
        check_vec(&format!("{prefix}moment"), &self.moment)
    }

    /// A world-frame force (N) at `s` (m).
    pub fn force(s: f64, force: Vector3<f64>) -> Self {
        Self {
            s,
            force,
            moment: Vector3::zeros(),
            frame: Frame::World,
        }
    }
}

/// External loads (`Loads(tip_force=..., tip_moment=..., gravity=..., ...)` in Python).
///
/// A plain description validated by the solver; `Loads::default()` is unloaded.
#[derive(Debug, Clone, Default)]
pub struct Loads {
    /// Force at the tip `s = L` (N).
    pub tip_force: Vector3<f64>,
    /// Moment at the tip (N m).
    pub tip_moment: Vector3<f64>,
    /// Frame of `tip_force` and `tip_moment`.
    pub tip_frame: Frame,
    /// Point forces and moments along the rod.
    pub point_loads: Vec<PointLoad>,
    /// Distributed force `f(s)` (N/m, world frame), if any.
    pub distributed_force: Option<Profile>,
    /// Distributed moment `l(s)` (N m/m, world frame), if any.
    pub distributed_moment: Option<Profile>,
    /// Gravitational acceleration (m/s², world frame); needs the rod's density. The load is
    /// `rho A(s) g` per unit undeformed length.
    pub gravity: Vector3<f64>,
}

fn check_vec(name: &str, v: &Vector3<f64>) -> Result<()> {
    for k in 0..3 {
        if !v[k].is_finite() {
            return Err(Error::invalid(format!("{name}[{k}]"), v[k], "finite"));
        }
    }
    Ok(())
}

impl Loads {
    /// Loads with only a world-frame tip force (N).
    pub fn tip_force(force: Vector3<f64>) -> Self {
        Self {
            tip_force: force,
            ..Self::default()
        }
    }

    /// Loads with only a world-frame tip moment (N m).
    pub fn tip_moment(moment: Vector3<f64>) -> Self {
        Self {
            tip_moment: moment,
            ..Self::default()
        }
    }

    /// Checks the values that do not depend on the rod: the tip and point wrenches and gravity
    /// finite, point loads at `s > 0`, constant distributed loads finite (functions are
    /// checked with the rod, on its length).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the field (`tip_force[1]`, `point_loads[2].s`, ...).
    pub fn check_values(&self) -> Result<()> {
        check_vec("tip_force", &self.tip_force)?;
        check_vec("tip_moment", &self.tip_moment)?;
        check_vec("gravity", &self.gravity)?;
        for (i, p) in self.point_loads.iter().enumerate() {
            p.check_values(&format!("point_loads[{i}]."))?;
        }
        for (name, f) in [
            ("distributed_force", &self.distributed_force),
            ("distributed_moment", &self.distributed_moment),
        ] {
            if let Some(Profile::Constant(v)) = f {
                check_vec(name, v)?;
            }
        }
        Ok(())
    }

    /// Checks every value for a rod of `length` (m) with optional `density`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the field (`loads.tip_force[1]`,
    /// `loads.point_loads[2].s`, `density` when gravity is set without it, ...).
    pub fn validate(&self, length: f64, density: Option<f64>) -> Result<()> {
        check_vec("loads.tip_force", &self.tip_force)?;
        check_vec("loads.tip_moment", &self.tip_moment)?;
        check_vec("loads.gravity", &self.gravity)?;
        for (i, p) in self.point_loads.iter().enumerate() {
            if !(p.s.is_finite() && p.s > 0.0 && p.s <= length) {
                return Err(Error::invalid(
                    format!("loads.point_loads[{i}].s"),
                    p.s,
                    format!("in (0, length] = (0, {length}] m"),
                ));
            }
            check_vec(&format!("loads.point_loads[{i}].force"), &p.force)?;
            check_vec(&format!("loads.point_loads[{i}].moment"), &p.moment)?;
        }
        if let Some(f) = &self.distributed_force {
            f.check("loads.distributed_force", length)?;
        }
        if let Some(l) = &self.distributed_moment {
            l.check("loads.distributed_moment", length)?;
        }
        if self.gravity != Vector3::zeros() && density.is_none() {
            return Err(Error::invalid(
                "density",
                "None",
                "set on the rod (kg/m^3) when loads.gravity is nonzero",
            ));
        }
        Ok(())
    }

    /// Whether there is no external load at all (the total base wrench is then zero for any
    /// actuation).
    pub fn is_unloaded(&self) -> bool {
        self.tip_force == Vector3::zeros()
            && self.tip_moment == Vector3::zeros()
            && self.point_loads.is_empty()
            && self.distributed_force.is_none()
            && self.distributed_moment.is_none()
            && self.gravity == Vector3::zeros()
    }
}
