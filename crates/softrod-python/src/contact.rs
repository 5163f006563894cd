//! Obstacles and tip constraints from Python objects, and the contact part of a solution.
//!
//! Obstacles go through `softrod.plot.obstacles.as_obstacles` (the dataclasses `Plane`,
//! `Sphere`, `Capsule`, `Cylinder`, dicts with `type`, or duck-typed objects), so that the
//! objects drawn and the objects solved are the same. A tip constraint is any object with a
//! `pose` (4×4 transform; optional `held`, six booleans), with `point` and `normal` (sliding
//! on a plane) or with `point` alone (pinned): `softrod.Clamp`, `softrod.Slide`,
//! `softrod.Pin`.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{pose, vec3};
use crate::errors::{param_err, to_py_err, type_err};

/// The obstacles of `obj` (a sequence, or None).
pub(crate) fn obstacles(
    py: Python<'_>,
    obj: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<softrod::Obstacle>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(Vec::new());
    };
    let list = py
        .import("softrod.plot.obstacles")?
        .getattr("as_obstacles")?
        .call1((obj,))?;
    let mut out = Vec::new();
    for (i, o) in list.try_iter()?.enumerate() {
        let o = o?;
        let name = |f: &str| format!("obstacles[{i}].{f}");
        let kind = o.get_type().name()?.to_string();
        let v = |f: &str| -> PyResult<[f64; 3]> {
            let x = vec3(&o.getattr(f)?, &name(f))?;
            Ok([x.x, x.y, x.z])
        };
        let r = || -> PyResult<f64> { o.getattr("radius")?.extract::<f64>() };
        let made = match kind.as_str() {
            "Plane" => softrod::Obstacle::plane(v("point")?, v("normal")?),
            "Sphere" => softrod::Obstacle::sphere(v("center")?, r()?),
            "Capsule" => softrod::Obstacle::capsule(v("a")?, v("b")?, r()?),
            "Cylinder" => softrod::Obstacle::cylinder(v("a")?, v("b")?, r()?),
            "Mesh" => {
                let vertices: Vec<[f64; 3]> = o
                    .getattr("vertices")?
                    .extract()
                    .map_err(|_| type_err(&name("vertices"), &o, "an (N, 3) array (m)"))?;
                let faces: Vec<[usize; 3]> = o
                    .getattr("faces")?
                    .extract()
                    .map_err(|_| type_err(&name("faces"), &o, "an (M, 3) array of indices"))?;
                softrod::Obstacle::mesh(vertices, faces)
            }
            _ => {
                return Err(type_err(
                    &format!("obstacles[{i}]"),
                    &o,
                    "a Plane, Sphere, Capsule, Cylinder or Mesh",
                ))
            }
        };
        // The Coulomb coefficient of the surface (0 when the object has none).
        let friction = match o.getattr("friction") {
            Ok(f) if !f.is_none() => f
                .extract::<f64>()
                .map_err(|_| type_err(&name("friction"), &f, "a number >= 0"))?,
            _ => 0.0,
        };
        let made = made.and_then(|m| m.with_friction(friction));
        out.push(made.map_err(|e| to_py_err(e.map_name(|n| format!("obstacles[{i}].{n}"))))?);
    }
    Ok(out)
}

fn held(obj: &Bound<'_, PyAny>) -> PyResult<[bool; 6]> {
    let name = "tip_constraint.held";
    let v: Vec<bool> = obj
        .extract()
        .map_err(|_| type_err(name, obj, "six booleans [x, y, z, rx, ry, rz]"))?;
    if v.len() != 6 {
        return Err(param_err(
            name,
            v.len(),
            "six entries [x, y, z, rx, ry, rz]",
        ));
    }
    Ok(std::array::from_fn(|k| v[k]))
}

/// The tip constraint of `obj` (None: a free tip).
pub(crate) fn tip_constraint(
    obj: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<softrod::TipConstraint>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let what = "softrod.Clamp(pose), softrod.Pin(point) or softrod.Slide(point, normal)";
    let fix = |e: softrod::Error| {
        to_py_err(
            e.map_name(|name| format!("tip_constraint.{}", name.trim_start_matches("base_pose."))),
        )
    };
    if let Ok(p) = obj.getattr("pose") {
        let (pos, rot) = pose(&p, "tip_constraint.pose")?;
        let r = softrod::nalgebra::Matrix3::from_fn(|i, j| rot[i][j]);
        let pose = softrod::Pose::new(softrod::nalgebra::Vector3::from(pos), r).map_err(fix)?;
        let held = match obj.getattr("held") {
            Ok(h) if !h.is_none() => held(&h)?,
            _ => [true; 6],
        };
        return softrod::TipConstraint::new(pose, held)
            .map(Some)
            .map_err(fix);
    }
    let point = match obj.getattr("point") {
        Ok(p) => vec3(&p, "tip_constraint.point")?,
        Err(_) => return Err(type_err("tip_constraint", obj, what)),
    };
    let point = [point.x, point.y, point.z];
    if let Ok(n) = obj.getattr("normal") {
        let n = vec3(&n, "tip_constraint.normal")?;
        return softrod::TipConstraint::slide(point, [n.x, n.y, n.z])
            .map(Some)
            .map_err(fix);
    }
    softrod::TipConstraint::pin(point).map(Some).map_err(fix)
}

/// The contact part of a solution.
#[derive(Debug, Clone, Default)]
pub(crate) struct ContactData {
    pub contacts: Vec<softrod::Contact>,
    pub contact_force: Option<Vec<[f64; 3]>>,
    pub tip_reaction: Option<[f64; 6]>,
    pub compliance: softrod::ContactCompliance,
}

impl ContactData {
    pub(crate) fn from_solution(sol: &softrod::ContactSolution) -> Self {
        Self {
            contacts: sol.contacts.clone(),
            contact_force: Some(sol.contact_force.clone()),
            tip_reaction: sol.tip_reaction,
            compliance: sol.compliance.clone(),
        }
    }

    /// Whether the solution is held by active contacts or a tip constraint (whose
    /// linearisations must hold them rather than take their forces as dead loads).
    pub(crate) fn constrained(&self) -> bool {
        !self.contacts.is_empty() || self.tip_reaction.is_some()
    }

    /// The contacts as a list of dicts.
    pub(crate) fn contacts_py(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let out = pyo3::types::PyList::empty(py);
        for c in &self.contacts {
            let d = PyDict::new(py);
            d.set_item("obstacle", c.obstacle)?;
            d.set_item("s", c.s)?;
            d.set_item("length", c.length)?;
            d.set_item("point", c.point.to_vec())?;
            d.set_item("normal", c.normal.to_vec())?;
            d.set_item("normal_force", c.normal_force)?;
            d.set_item("tangential_force", c.tangential_force.to_vec())?;
            let state = match c.state {
                softrod::ContactState::Frictionless => "frictionless",
                softrod::ContactState::Stick => "stick",
                softrod::ContactState::Slide => "slide",
            };
            d.set_item("state", state)?;
            out.append(d)?;
        }
        Ok(out.into_any().unbind())
    }
}
