//! Binding of PCC kinematics, actuation maps and statics (`softrod.pcc` in Python).
//!
//! Every function here is `pcc_<name>` in `softrod._core` and `softrod.pcc.<name>` in the
//! package. Arc parameters are rows `(curvature, plane_angle, length)` (1/m, rad, m); poses
//! are 4×4 homogeneous transforms; Jacobians are 6×3 per segment with twists
//! `[translation; rotation]`.
//!
//! The files: `kinematics.rs` (arcs and chains: poses, frames, Jacobians, arcs from tips),
//! `actuation.rs` (tendon displacements, arcs from displacements, tensions and pressures),
//! `robot.rs` (the robot class, its statics solve and solution); this file holds the
//! argument conversions they share.

mod actuation;
mod kinematics;
mod robot;

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;

use softrod::nalgebra::{Matrix4, Vector3};
use softrod::pcc::{self, ArcCoordinates, JacobianFrame, PccSegment};

use crate::convert::{choice, Floats};
use crate::errors::{param_err, to_py_err, type_err};

pub(crate) use actuation::{
    pcc_arc_from_pressures, pcc_arc_from_pressures_jacobian, pcc_arc_from_tendon_displacements,
    pcc_arc_from_tendon_displacements_jacobian, pcc_arc_from_tendon_tensions,
    pcc_arc_from_tendon_tensions_jacobian, pcc_tendon_displacement_jacobian,
    pcc_tendon_displacement_misfit, pcc_tendon_displacements,
};
pub(crate) use kinematics::{
    pcc_arc_frames, pcc_arc_from_tip, pcc_arc_from_tip_with_length, pcc_arc_jacobian, pcc_arc_pose,
    pcc_arc_poses, pcc_chain_frames, pcc_chain_jacobian, pcc_chain_pose,
};
pub(crate) use robot::{_pcc_robot, pcc_solve, PccRobot, PccSolution};

/// A chamber group `(segment, areas, distances, angles)` (m², m, rad).
type ChamberGroup = (usize, Vec<f64>, Vec<f64>, Vec<f64>);

/// Frames sampled along a solution when neither `s` nor `n_points` is given.
const DEFAULT_FRAMES: usize = 50;

fn frame_from(frame: &str) -> PyResult<JacobianFrame> {
    Ok(
        match choice("frame", frame, &["spatial", "body", "hybrid"])? {
            "spatial" => JacobianFrame::Spatial,
            "body" => JacobianFrame::Body,
            _ => JacobianFrame::Hybrid,
        },
    )
}

fn coordinates_from(coordinates: &str) -> PyResult<ArcCoordinates> {
    let c = choice(
        "coordinates",
        coordinates,
        &["arc", "curvature_vector", "curvature-vector"],
    )?;
    Ok(if c == "arc" {
        ArcCoordinates::Arc
    } else {
        ArcCoordinates::CurvatureVector
    })
}

/// Rows of three floats: an (n, 3) array or nested sequence (one row of 3 is accepted too).
fn rows3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f64; 3]>> {
    let what = "an (n, 3) array of rows (curvature, plane_angle, length)";
    let a = match crate::convert::float_array(obj, name, what) {
        Ok(a) => a,
        Err(e) => {
            // A ragged list: name the row that is not 3 numbers.
            if let Ok(rows) = obj.cast::<pyo3::types::PyList>() {
                for (i, row) in rows.iter().enumerate() {
                    crate::convert::floats_n(
                        &row,
                        &format!("{name}[{i}]"),
                        3,
                        "a row of 3 numbers (curvature, plane_angle, length)",
                    )?;
                }
            }
            return Err(e);
        }
    };
    let a = match a.ndim() {
        1 => a.insert_axis(numpy::ndarray::Axis(0)),
        _ => a,
    };
    if a.ndim() != 2 || a.shape()[1] != 3 || a.shape()[0] == 0 {
        return Err(type_err(name, obj, what));
    }
    Ok(a.outer_iter().map(|r| [r[0], r[1], r[2]]).collect())
}

/// The name of a core error prefixed: `segments[0].curvature` as `warm_start[0].curvature`.
fn renamed(e: softrod::Error, from: &str, to: &str) -> softrod::Error {
    e.map_name(|name| name.replacen(from, to, 1))
}

/// A parameter error of entry `i` of an array argument: the parameter named `name[i]`.
fn indexed(e: softrod::Error, i: usize) -> softrod::Error {
    e.map_name(|name| format!("{name}[{i}]"))
}

fn vector3(v: Floats, name: &str) -> PyResult<Vector3<f64>> {
    let v = v.to_vec()?;
    if v.len() != 3 {
        return Err(param_err(&format!("{name}.len()"), v.len(), "3 (x, y, z)"));
    }
    Ok(Vector3::new(v[0], v[1], v[2]))
}

fn arc3(arc: Floats, name: &str) -> PyResult<PccSegment> {
    let a = vector3(arc, name)?;
    PccSegment::checked(a[0], a[1], a[2])
        .map_err(|e| to_py_err(renamed(e, "", &format!("{name}."))))
}

fn segments_from(obj: &Bound<'_, PyAny>) -> PyResult<Vec<PccSegment>> {
    let rows = rows3(obj, "segments")?;
    pcc::PccChain::from_parameters(&rows)
        .map(|c| c.segments().to_vec())
        .map_err(to_py_err)
}

fn pose_array<'py>(py: Python<'py>, t: &Matrix4<f64>) -> Bound<'py, PyArray2<f64>> {
    Array::from_shape_fn((4, 4), |(i, j)| t[(i, j)]).into_pyarray(py)
}

fn poses_array<'py>(py: Python<'py>, ts: &[Matrix4<f64>]) -> Bound<'py, PyArray3<f64>> {
    Array::from_shape_fn((ts.len(), 4, 4), |(k, i, j)| ts[k][(i, j)]).into_pyarray(py)
}

fn matrix_array<'py, R: softrod::nalgebra::Dim, C: softrod::nalgebra::Dim, S>(
    py: Python<'py>,
    m: &softrod::nalgebra::Matrix<f64, R, C, S>,
) -> Bound<'py, PyArray2<f64>>
where
    S: softrod::nalgebra::RawStorage<f64, R, C>,
{
    Array::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
}

fn arc_array<'py>(py: Python<'py>, s: &PccSegment) -> Bound<'py, PyArray1<f64>> {
    vec![s.curvature(), s.plane_angle(), s.length()].into_pyarray(py)
}

fn tendons_from(distances: Floats, angles: Floats) -> PyResult<pcc::PccTendons> {
    pcc::PccTendons::new(&distances.to_vec()?, &angles.to_vec()?).map_err(to_py_err)
}

fn chambers_from(areas: Floats, distances: Floats, angles: Floats) -> PyResult<pcc::PccChambers> {
    pcc::PccChambers::new(&areas.to_vec()?, &distances.to_vec()?, &angles.to_vec()?)
        .map_err(to_py_err)
}
