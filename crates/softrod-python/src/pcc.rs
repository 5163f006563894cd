//! Binding of PCC kinematics, actuation maps and statics (`softrod.pcc` in Python).
//!
//! Every function here is `pcc_<name>` in `softrod._core` and `softrod.pcc.<name>` in the
//! package. Arc parameters are rows `(curvature, plane_angle, length)` (1/m, rad, m); poses
//! are 4×4 homogeneous transforms; Jacobians are 6×3 per segment with twists
//! `[translation; rotation]`.

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use softrod::nalgebra::{Matrix4, Vector3};
use softrod::pcc::statics::{self as statics, PccLoads, PccRobot as CoreRobot, PccSolveOptions};
use softrod::pcc::{self, ArcCoordinates, ElasticSegment, JacobianFrame, PccSegment};

use crate::callbacks::run;
use crate::convert::{arg, choice, count, Arg, Floats};
use crate::errors::{blame, finite_result, param_err, to_py_err, type_err};

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

/// A core error with its parameter name mapped by `f` (other errors unchanged).
fn map_name(e: softrod::Error, f: impl FnOnce(String) -> String) -> softrod::Error {
    match e {
        softrod::Error::InvalidParameter {
            name,
            value,
            expected,
        } => softrod::Error::InvalidParameter {
            name: f(name),
            value,
            expected,
        },
        other => other,
    }
}

/// The name of a core error prefixed: `segments[0].curvature` as `warm_start[0].curvature`.
fn renamed(e: softrod::Error, from: &str, to: &str) -> softrod::Error {
    map_name(e, |name| name.replacen(from, to, 1))
}

/// A parameter error of entry `i` of an array argument: the parameter named `name[i]`.
fn indexed(e: softrod::Error, i: usize) -> softrod::Error {
    map_name(e, |name| format!("{name}[{i}]"))
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

// ------------------------------------------------------------------------------ kinematics

/// Tip pose (4×4) of one arc.
#[pyfunction]
pub(crate) fn pcc_arc_pose(
    py: Python<'_>,
    #[pyo3(from_py_with = arg::curvature)] curvature: f64,
    #[pyo3(from_py_with = arg::plane_angle)] plane_angle: f64,
    #[pyo3(from_py_with = arg::length)] length: f64,
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let t = pcc::arc_pose(curvature, plane_angle, length).map_err(blame(&[
        "curvature",
        "plane_angle",
        "length",
    ]))?;
    finite_result(t.iter(), &["curvature", "plane_angle", "length"])?;
    Ok(pose_array(py, &t))
}

/// Arcs from which [`pcc_arc_poses`] computes its poses on all cores.
const PARALLEL_POSES: usize = 20_000;

/// Tip poses (N, 4, 4) of N arcs: `curvature`, `plane_angle`, `length` are arrays of one
/// length (a number is repeated); one call for any number of poses.
#[pyfunction]
pub(crate) fn pcc_arc_poses<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::curvature)] curvature: Floats,
    #[pyo3(from_py_with = arg::plane_angle)] plane_angle: Floats,
    #[pyo3(from_py_with = arg::length)] length: Floats,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (k, p, l) = (curvature.to_vec()?, plane_angle.to_vec()?, length.to_vec()?);
    let n = k.len().max(p.len()).max(l.len());
    for (name, v) in [("curvature", &k), ("plane_angle", &p), ("length", &l)] {
        if v.len() != n && v.len() != 1 {
            return Err(param_err(
                &format!("{name}.len()"),
                v.len(),
                &format!("1 or the common length {n} of curvature, plane_angle and length"),
            ));
        }
    }
    let at = |v: &[f64], i: usize| if v.len() == 1 { v[0] } else { v[i] };
    let segment =
        |i: usize| PccSegment::checked(at(&k, i), at(&p, i), at(&l, i)).map_err(|e| indexed(e, i));
    let mut flat = vec![0.0; 16 * n];
    let fill = |i: usize, out: &mut [f64]| -> softrod::Result<()> {
        let t = segment(i)?.pose();
        for r in 0..4 {
            for c in 0..4 {
                out[4 * r + c] = t[(r, c)];
            }
        }
        Ok(())
    };
    let result = py.detach(|| -> softrod::Result<()> {
        if n < PARALLEL_POSES {
            return flat
                .chunks_exact_mut(16)
                .enumerate()
                .try_for_each(|(i, out)| fill(i, out));
        }
        use rayon::prelude::*;
        let ok = flat
            .par_chunks_exact_mut(16)
            .enumerate()
            .try_for_each(|(i, out)| fill(i, out))
            .is_ok();
        // The error of the first invalid arc, whichever thread met an invalid one first.
        if ok {
            Ok(())
        } else {
            (0..n).try_for_each(|i| segment(i).map(|_| ()))
        }
    });
    result.map_err(blame(&["curvature", "plane_angle", "length"]))?;
    let out = numpy::ndarray::Array3::from_shape_vec((n, 4, 4), flat)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    Ok(out.into_pyarray(py))
}

/// Backbone frames (N, 4, 4) of one arc at arc lengths `s`.
#[pyfunction]
pub(crate) fn pcc_arc_frames<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::curvature)] curvature: f64,
    #[pyo3(from_py_with = arg::plane_angle)] plane_angle: f64,
    #[pyo3(from_py_with = arg::length)] length: f64,
    #[pyo3(from_py_with = arg::s)] s: Floats,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let s = s.to_vec()?;
    let ts = pcc::arc_frames(curvature, plane_angle, length, &s).map_err(blame(&[
        "curvature",
        "plane_angle",
        "length",
        "s",
    ]))?;
    finite_result(
        ts.iter().flat_map(|m| m.iter()),
        &["curvature", "plane_angle", "length", "s"],
    )?;
    Ok(poses_array(py, &ts))
}

/// 6×3 Jacobian of one arc's tip pose.
#[pyfunction]
#[pyo3(signature = (curvature, plane_angle, length, *, frame="spatial", coordinates="arc"))]
pub(crate) fn pcc_arc_jacobian<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::curvature)] curvature: f64,
    #[pyo3(from_py_with = arg::plane_angle)] plane_angle: f64,
    #[pyo3(from_py_with = arg::length)] length: f64,
    #[pyo3(from_py_with = arg::frame)] frame: &str,
    #[pyo3(from_py_with = arg::coordinates)] coordinates: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (f, c) = (frame_from(frame)?, coordinates_from(coordinates)?);
    let j = pcc::arc_jacobian(curvature, plane_angle, length, f, c).map_err(blame(&[
        "curvature",
        "plane_angle",
        "length",
        "frame",
        "coordinates",
    ]))?;
    finite_result(
        j.iter(),
        &["curvature", "plane_angle", "length", "frame", "coordinates"],
    )?;
    Ok(matrix_array(py, &j))
}

/// Tip pose (4×4) of a chain of arcs given as rows (curvature, plane_angle, length).
#[pyfunction]
pub(crate) fn pcc_chain_pose<'py>(
    py: Python<'py>,
    segments: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let segs = segments_from(segments)?;
    Ok(pose_array(py, &pcc::chain_pose(&segs)))
}

/// Backbone frames (N, 4, 4) of a chain at its arc lengths `s`.
#[pyfunction]
pub(crate) fn pcc_chain_frames<'py>(
    py: Python<'py>,
    segments: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = arg::s)] s: Floats,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let chain = pcc::PccChain::new(segments_from(segments)?).map_err(blame(&["segments", "s"]))?;
    let ts = chain
        .backbone(&s.to_vec()?)
        .map_err(blame(&["segments", "s"]))?;
    finite_result(ts.iter().flat_map(|m| m.iter()), &["segments", "s"])?;
    Ok(poses_array(py, &ts))
}

/// 6×3n Jacobian of a chain's tip pose.
#[pyfunction]
#[pyo3(signature = (segments, *, frame="spatial", coordinates="arc"))]
pub(crate) fn pcc_chain_jacobian<'py>(
    py: Python<'py>,
    segments: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = arg::frame)] frame: &str,
    #[pyo3(from_py_with = arg::coordinates)] coordinates: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (f, c) = (frame_from(frame)?, coordinates_from(coordinates)?);
    let segs = segments_from(segments)?;
    Ok(matrix_array(py, &pcc::chain_jacobian(&segs, f, c)))
}

/// The arc (curvature, plane_angle, length) through a tip position (extensible segment).
#[pyfunction]
pub(crate) fn pcc_arc_from_tip<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::position)] position: Floats,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let p = vector3(position, "position")?;
    let s = pcc::arc_from_tip(&p).map_err(blame(&["position"]))?;
    Ok(arc_array(py, &s))
}

/// The arc of a given length whose tip is closest to a position, and the distance (m).
#[pyfunction]
pub(crate) fn pcc_arc_from_tip_with_length<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::position)] position: Floats,
    #[pyo3(from_py_with = arg::length)] length: f64,
) -> PyResult<(Bound<'py, PyArray1<f64>>, f64)> {
    let p = vector3(position, "position")?;
    let fit = pcc::arc_from_tip_with_length(&p, length).map_err(blame(&["position", "length"]))?;
    Ok((arc_array(py, &fit.segment), fit.residual))
}

// ---------------------------------------------------------------------------- actuation maps

fn tendons_from(distances: Floats, angles: Floats) -> PyResult<pcc::PccTendons> {
    pcc::PccTendons::new(&distances.to_vec()?, &angles.to_vec()?)
        .map_err(blame(&["position", "length"]))
}

fn chambers_from(areas: Floats, distances: Floats, angles: Floats) -> PyResult<pcc::PccChambers> {
    pcc::PccChambers::new(&areas.to_vec()?, &distances.to_vec()?, &angles.to_vec()?)
        .map_err(blame(&["position", "length"]))
}

/// Tendon length changes (m) of a segment with arc parameters `arc`.
#[pyfunction]
#[pyo3(signature = (arc, distances, angles, rest_length=None))]
pub(crate) fn pcc_tendon_displacements<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::arc)] arc: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::rest_length)] rest_length: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let seg = arc3(arc, "arc")?;
    let t = tendons_from(distances, angles)?;
    let d = pcc::tendon_displacements(&seg, &t, rest_length).map_err(blame(&[
        "arc",
        "distances",
        "angles",
        "rest_length",
    ]))?;
    finite_result(&d, &["arc", "distances", "rest_length"])?;
    Ok(d.into_pyarray(py))
}

/// n×3 Jacobian of the tendon length changes with respect to the segment's coordinates.
#[pyfunction]
#[pyo3(signature = (arc, distances, angles, *, coordinates="arc"))]
pub(crate) fn pcc_tendon_displacement_jacobian<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::arc)] arc: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::coordinates)] coordinates: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let c = coordinates_from(coordinates)?;
    let seg = arc3(arc, "arc")?;
    let t = tendons_from(distances, angles)?;
    Ok(matrix_array(
        py,
        &pcc::tendon_displacement_jacobian(&seg, &t, c),
    ))
}

/// The arc from tendon length changes (m).
#[pyfunction]
#[pyo3(signature = (displacements, distances, angles, rest_length, *, extensible=true))]
pub(crate) fn pcc_arc_from_tendon_displacements<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::displacements)] displacements: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::rest_length)] rest_length: f64,
    #[pyo3(from_py_with = arg::extensible)] extensible: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let t = tendons_from(distances, angles)?;
    let s =
        pcc::arc_from_tendon_displacements(&displacements.to_vec()?, &t, rest_length, extensible)
            .map_err(blame(&[
            "displacements",
            "distances",
            "angles",
            "rest_length",
            "extensible",
        ]))?;
    Ok(arc_array(py, &s))
}

/// 3×n Jacobian of the arc from tendon length changes.
#[pyfunction]
#[pyo3(signature = (displacements, distances, angles, rest_length, *, extensible=true, coordinates="arc"))]
pub(crate) fn pcc_arc_from_tendon_displacements_jacobian<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::displacements)] displacements: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::rest_length)] rest_length: f64,
    #[pyo3(from_py_with = arg::extensible)] extensible: bool,
    #[pyo3(from_py_with = arg::coordinates)] coordinates: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let c = coordinates_from(coordinates)?;
    let t = tendons_from(distances, angles)?;
    let j = pcc::arc_from_tendon_displacements_jacobian(
        &displacements.to_vec()?,
        &t,
        rest_length,
        extensible,
        c,
    )
    .map_err(blame(&[
        "displacements",
        "distances",
        "angles",
        "rest_length",
        "extensible",
        "coordinates",
    ]))?;
    finite_result(
        j.iter(),
        &[
            "displacements",
            "distances",
            "angles",
            "rest_length",
            "extensible",
            "coordinates",
        ],
    )?;
    Ok(matrix_array(py, &j))
}

fn body_from(
    rest_length: f64,
    bending_stiffness: f64,
    axial_stiffness: Option<f64>,
) -> PyResult<ElasticSegment> {
    ElasticSegment::new(rest_length, bending_stiffness, axial_stiffness).map_err(blame(&[
        "displacements",
        "distances",
        "angles",
        "rest_length",
        "extensible",
        "coordinates",
    ]))
}

/// The arc of a uniform elastic segment pulled by tendon tensions (N).
#[pyfunction]
#[pyo3(signature = (tensions, distances, angles, rest_length, bending_stiffness, axial_stiffness=None))]
pub(crate) fn pcc_arc_from_tendon_tensions<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::tensions)] tensions: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::rest_length)] rest_length: f64,
    #[pyo3(from_py_with = arg::bending_stiffness)] bending_stiffness: f64,
    #[pyo3(from_py_with = arg::axial_stiffness)] axial_stiffness: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let t = tendons_from(distances, angles)?;
    let body = body_from(rest_length, bending_stiffness, axial_stiffness)?;
    let s = pcc::arc_from_tendon_tensions(&tensions.to_vec()?, &t, &body).map_err(blame(&[
        "tensions",
        "distances",
        "angles",
        "rest_length",
        "bending_stiffness",
        "axial_stiffness",
    ]))?;
    Ok(arc_array(py, &s))
}

/// 3×n Jacobian of the arc with respect to the tendon tensions.
#[pyfunction]
#[pyo3(signature = (tensions, distances, angles, rest_length, bending_stiffness, axial_stiffness=None, *, coordinates="arc"))]
pub(crate) fn pcc_arc_from_tendon_tensions_jacobian<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::tensions)] tensions: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::rest_length)] rest_length: f64,
    #[pyo3(from_py_with = arg::bending_stiffness)] bending_stiffness: f64,
    #[pyo3(from_py_with = arg::axial_stiffness)] axial_stiffness: Option<f64>,
    #[pyo3(from_py_with = arg::coordinates)] coordinates: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let c = coordinates_from(coordinates)?;
    let t = tendons_from(distances, angles)?;
    let body = body_from(rest_length, bending_stiffness, axial_stiffness)?;
    let j = pcc::arc_from_tendon_tensions_jacobian(&tensions.to_vec()?, &t, &body, c).map_err(
        blame(&[
            "tensions",
            "distances",
            "angles",
            "rest_length",
            "bending_stiffness",
            "axial_stiffness",
            "coordinates",
        ]),
    )?;
    finite_result(
        j.iter(),
        &[
            "tensions",
            "distances",
            "angles",
            "rest_length",
            "bending_stiffness",
            "axial_stiffness",
            "coordinates",
        ],
    )?;
    Ok(matrix_array(py, &j))
}

/// The arc of a uniform elastic segment with chamber pressures (Pa).
#[pyfunction]
#[pyo3(signature = (pressures, areas, distances, angles, rest_length, bending_stiffness, axial_stiffness=None))]
pub(crate) fn pcc_arc_from_pressures<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::pressures)] pressures: Floats,
    #[pyo3(from_py_with = arg::areas)] areas: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::rest_length)] rest_length: f64,
    #[pyo3(from_py_with = arg::bending_stiffness)] bending_stiffness: f64,
    #[pyo3(from_py_with = arg::axial_stiffness)] axial_stiffness: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let ch = chambers_from(areas, distances, angles)?;
    let body = body_from(rest_length, bending_stiffness, axial_stiffness)?;
    let s = pcc::arc_from_pressures(&pressures.to_vec()?, &ch, &body).map_err(blame(&[
        "pressures",
        "areas",
        "distances",
        "angles",
        "rest_length",
        "bending_stiffness",
        "axial_stiffness",
    ]))?;
    Ok(arc_array(py, &s))
}

/// 3×n Jacobian of the arc with respect to the chamber pressures.
#[pyfunction]
#[pyo3(signature = (pressures, areas, distances, angles, rest_length, bending_stiffness, axial_stiffness=None, *, coordinates="arc"))]
pub(crate) fn pcc_arc_from_pressures_jacobian<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::pressures)] pressures: Floats,
    #[pyo3(from_py_with = arg::areas)] areas: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::rest_length)] rest_length: f64,
    #[pyo3(from_py_with = arg::bending_stiffness)] bending_stiffness: f64,
    #[pyo3(from_py_with = arg::axial_stiffness)] axial_stiffness: Option<f64>,
    #[pyo3(from_py_with = arg::coordinates)] coordinates: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let c = coordinates_from(coordinates)?;
    let ch = chambers_from(areas, distances, angles)?;
    let body = body_from(rest_length, bending_stiffness, axial_stiffness)?;
    let j =
        pcc::arc_from_pressures_jacobian(&pressures.to_vec()?, &ch, &body, c).map_err(blame(&[
            "pressures",
            "areas",
            "distances",
            "angles",
            "rest_length",
            "bending_stiffness",
            "axial_stiffness",
            "coordinates",
        ]))?;
    Ok(matrix_array(py, &j))
}

// ---------------------------------------------------------------------------------- statics

/// One value per segment from a scalar or a sequence of `n`.
fn per_segment(v: Floats, n: usize, name: &str) -> PyResult<Vec<f64>> {
    let v = v.to_vec()?;
    match v.len() {
        1 => Ok(vec![v[0]; n]),
        k if k == n => Ok(v),
        k => Err(param_err(
            &format!("{name}.len()"),
            k,
            &format!("1 or the number of segments (the length of rest_lengths), {n}"),
        )),
    }
}

/// A PCC robot (immutable): elastic segments, routed tendons, chambers.
#[pyclass(frozen, module = "softrod._core", name = "PccRobot")]
pub(crate) struct PccRobot {
    pub(crate) inner: CoreRobot,
}

#[pymethods]
impl PccRobot {
    #[new]
    #[pyo3(signature = (rest_lengths, bending_stiffness, axial_stiffness=None))]
    fn new(
        #[pyo3(from_py_with = arg::rest_lengths)] rest_lengths: Floats,
        #[pyo3(from_py_with = arg::bending_stiffness)] bending_stiffness: Floats,
        #[pyo3(from_py_with = arg::axial_stiffness)] axial_stiffness: Option<Floats>,
    ) -> PyResult<Self> {
        let l0 = rest_lengths.to_vec()?;
        let n = l0.len();
        let ei = per_segment(bending_stiffness, n, "bending_stiffness")?;
        let ea = match axial_stiffness {
            Some(a) => Some(per_segment(a, n, "axial_stiffness")?),
            None => None,
        };
        let bodies = (0..n)
            .map(|i| {
                ElasticSegment::new(l0[i], ei[i], ea.as_ref().map(|a| a[i]))
                    .map_err(|e| indexed(e, i))
            })
            .collect::<softrod::Result<Vec<_>>>()
            .map_err(to_py_err)?;
        let inner = CoreRobot::new(bodies)
            .map_err(|_| param_err("rest_lengths", "[]", "at least one segment"))?;
        Ok(Self { inner })
    }

    /// Solid circular segments of `radius` (m) and Young's modulus (Pa).
    #[staticmethod]
    #[pyo3(signature = (rest_lengths, radius, youngs_modulus, *, extensible=true))]
    fn solid_circle(
        #[pyo3(from_py_with = arg::rest_lengths)] rest_lengths: Floats,
        #[pyo3(from_py_with = arg::radius)] radius: f64,
        #[pyo3(from_py_with = arg::youngs_modulus)] youngs_modulus: f64,
        #[pyo3(from_py_with = arg::extensible)] extensible: bool,
    ) -> PyResult<Self> {
        let l0 = rest_lengths.to_vec()?;
        let bodies = l0
            .iter()
            .map(|&l| ElasticSegment::solid_circle(l, radius, youngs_modulus, extensible))
            .collect::<softrod::Result<Vec<_>>>()
            .map_err(to_py_err)?;
        let inner = CoreRobot::new(bodies)
            .map_err(|_| param_err("rest_lengths", "[]", "at least one segment"))?;
        Ok(Self { inner })
    }

    /// A new robot with tendons ending at the tip of `segment` (and passing through the
    /// segments before it at the same body offsets).
    fn with_tendons(
        &self,
        #[pyo3(from_py_with = arg::segment)] segment: usize,
        #[pyo3(from_py_with = arg::distances)] distances: Floats,
        #[pyo3(from_py_with = arg::angles)] angles: Floats,
    ) -> PyResult<Self> {
        let t = tendons_from(distances, angles)?;
        let inner = self
            .inner
            .clone()
            .with_segment_tendons(segment, &t)
            .map_err(to_py_err)?;
        Ok(Self { inner })
    }

    /// A new robot with pneumatic chambers in `segment`.
    fn with_chambers(
        &self,
        #[pyo3(from_py_with = arg::segment)] segment: usize,
        #[pyo3(from_py_with = arg::areas)] areas: Floats,
        #[pyo3(from_py_with = arg::distances)] distances: Floats,
        #[pyo3(from_py_with = arg::angles)] angles: Floats,
    ) -> PyResult<Self> {
        let ch = chambers_from(areas, distances, angles)?;
        let inner = self
            .inner
            .clone()
            .with_chambers(segment, ch)
            .map_err(to_py_err)?;
        Ok(Self { inner })
    }

    #[getter]
    fn n_segments(&self) -> usize {
        self.inner.segments().len()
    }
    #[getter]
    fn n_tendons(&self) -> usize {
        self.inner.n_tendons()
    }
    #[getter]
    fn n_chambers(&self) -> usize {
        self.inner.n_chambers()
    }
    #[getter]
    fn rest_lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .inner
            .segments()
            .iter()
            .map(|s| s.rest_length())
            .collect();
        v.into_pyarray(py)
    }
    #[getter]
    fn bending_stiffness<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .inner
            .segments()
            .iter()
            .map(|s| s.bending_stiffness())
            .collect();
        v.into_pyarray(py)
    }
    /// Axial stiffness per segment (N), `None` for an inextensible one.
    #[getter]
    fn axial_stiffness(&self) -> Vec<Option<f64>> {
        self.inner
            .segments()
            .iter()
            .map(|s| s.axial_stiffness())
            .collect()
    }
    /// Tendons as rows (distance, angle, last_segment).
    #[getter]
    fn tendons<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let t = self.inner.tendons();
        Array::from_shape_fn((t.len(), 3), |(i, j)| match j {
            0 => t[i].distance(),
            1 => t[i].angle(),
            _ => t[i].last_segment() as f64,
        })
        .into_pyarray(py)
    }

    /// Chamber groups as `(segment, areas, distances, angles)`.
    #[getter]
    fn chambers(&self) -> Vec<ChamberGroup> {
        self.inner
            .chambers()
            .iter()
            .map(|(seg, c)| {
                (
                    *seg,
                    c.areas().to_vec(),
                    c.distances().to_vec(),
                    c.angles().to_vec(),
                )
            })
            .collect()
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let r = &slf.get().inner;
        let bodies: Vec<(f64, f64, Option<f64>)> = r
            .segments()
            .iter()
            .map(|b| (b.rest_length(), b.bending_stiffness(), b.axial_stiffness()))
            .collect();
        let tendons: Vec<(f64, f64, usize)> = r
            .tendons()
            .iter()
            .map(|t| (t.distance(), t.angle(), t.last_segment()))
            .collect();
        let f = py.import("softrod._core")?.getattr("_pcc_robot")?;
        let args = (bodies, tendons, slf.get().chambers()).into_pyobject(py)?;
        PyTuple::new(py, [f, args.into_any()])
    }
    fn __repr__(&self) -> String {
        format!(
            "PccRobot(segments={}, tendons={}, chambers={})",
            self.inner.segments().len(),
            self.inner.n_tendons(),
            self.inner.n_chambers()
        )
    }
}

/// A PCC robot from its parts (the pickled form of `PccRobot`): segments `(rest_length,
/// bending_stiffness, axial_stiffness)`, tendons `(distance, angle, last_segment)`, chamber
/// groups `(segment, areas, distances, angles)`.
#[pyfunction]
pub(crate) fn _pcc_robot(
    bodies: Vec<(f64, f64, Option<f64>)>,
    tendons: Vec<(f64, f64, usize)>,
    chambers: Vec<ChamberGroup>,
) -> PyResult<PccRobot> {
    let segs = bodies
        .iter()
        .map(|&(l, ei, ea)| ElasticSegment::new(l, ei, ea))
        .collect::<softrod::Result<Vec<_>>>()
        .map_err(to_py_err)?;
    let mut robot = CoreRobot::new(segs).map_err(to_py_err)?;
    for (d, b, last) in tendons {
        let t = statics::RoutedTendon::new(d, b, last).map_err(to_py_err)?;
        robot = robot.with_tendon(t).map_err(to_py_err)?;
    }
    for (seg, a, d, b) in chambers {
        let c = pcc::PccChambers::new(&a, &d, &b).map_err(to_py_err)?;
        robot = robot.with_chambers(seg, c).map_err(to_py_err)?;
    }
    Ok(PccRobot { inner: robot })
}

/// A solved PCC robot.
#[pyclass(frozen, module = "softrod._core", name = "PccSolution")]
pub(crate) struct PccSolution {
    pub(crate) inner: statics::PccStaticsSolution,
    /// The robot it solves (rest lengths for the compliance).
    pub(crate) robot: CoreRobot,
    /// The loads (actuation and tip wrench) it was solved with.
    pub(crate) loads: PccLoads,
    s: Vec<f64>,
    frames: Vec<Matrix4<f64>>,
    /// The call that produced it (for pickling: it is solved again, bit for bit).
    call: crate::model::Args,
}

#[pymethods]
impl PccSolution {
    /// Arc parameters per segment, rows (curvature, plane_angle, length).
    #[getter]
    fn arcs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let s = &self.inner.segments;
        Array::from_shape_fn((s.len(), 3), |(i, j)| match j {
            0 => s[i].curvature(),
            1 => s[i].plane_angle(),
            _ => s[i].length(),
        })
        .into_pyarray(py)
    }
    /// Curvature-vector coordinates per segment, rows (u_x, u_y, length).
    #[getter]
    fn coordinates<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let c = self.inner.coordinates();
        Array::from_shape_fn((c.len(), 3), |(i, j)| c[i][j]).into_pyarray(py)
    }
    #[getter]
    fn tip_pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        pose_array(py, &self.inner.tip_pose)
    }
    #[getter]
    fn tip_position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let t = &self.inner.tip_pose;
        vec![t[(0, 3)], t[(1, 3)], t[(2, 3)]].into_pyarray(py)
    }
    /// Deformed arc length of the frame samples (m).
    #[getter]
    fn s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.s.clone().into_pyarray(py)
    }
    /// Backbone frames (N, 4, 4) at `s`.
    #[getter]
    fn frames<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        poses_array(py, &self.frames)
    }
    /// Backbone positions (N, 3) at `s`.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let f = &self.frames;
        Array::from_shape_fn((f.len(), 3), |(k, i)| f[k][(i, 3)]).into_pyarray(py)
    }
    #[getter]
    fn tendon_lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.tendon_lengths.clone().into_pyarray(py)
    }
    #[getter]
    fn iterations(&self) -> usize {
        self.inner.stats.iterations
    }
    #[getter]
    fn residual(&self) -> f64 {
        self.inner.stats.residual
    }
    #[getter]
    fn converged(&self) -> bool {
        self.inner.stats.converged
    }
    #[getter]
    fn load_steps(&self) -> usize {
        self.inner.stats.load_steps
    }
    /// Fraction of the tip load the returned shape carries.
    #[getter]
    fn load_factor(&self) -> f64 {
        self.inner.stats.load_factor
    }
    /// Solver statistics (the keys of `StaticsSolution.stats`).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::statics::stats_dict(py, &self.inner.stats)
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = py.import("softrod._core")?.getattr("pcc_solve")?;
        slf.get().call.reduce(py, f)
    }
    /// Backbone frames (N, 4, 4) at other arc lengths `s` (m, deformed, along the chain).
    fn frames_at<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = arg::s)] s: Floats,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let ts = self
            .inner
            .chain()
            .backbone(&s.to_vec()?)
            .map_err(to_py_err)?;
        Ok(poses_array(py, &ts))
    }
    fn __repr__(&self) -> String {
        format!(
            "PccSolution(segments={}, converged={}, iterations={})",
            self.inner.segments.len(),
            self.inner.stats.converged,
            self.inner.stats.iterations
        )
    }
}

/// Statics of a PCC robot under tensions, pressures and a world-frame tip wrench.
///
/// Stationary potential energy of the Cosserat rod restricted to arcs (see docs/pcc.md),
/// solved by Newton with the exact Jacobian in (u_x, u_y, length) per segment.
///
/// Args:
///     robot: The `Robot`.
///     tensions: One tension per tendon (N, >= 0), in the order the tendons were added.
///     pressures: One gauge pressure per chamber (Pa).
///     tip_force: Tip force (N, world frame, 3 values).
///     tip_moment: Tip moment (N m, world frame, 3 values).
///     s: Arc lengths (m, along the deformed chain) of the returned frames.
///     n_points: Number of uniformly spaced frames when `s` is not given.
///     tolerance: Scaled residual (rad for bending, strain for stretching).
///     max_iterations: Newton iterations per load step.
///     continuation: Step the tip load if the direct solve fails.
///     max_load_steps: Load steps under continuation.
///     warm_start: A previous `Solution` or (n, 3) arc rows.
///     throw: Raise `ConvergenceError` on non-convergence (else return the last iterate).
///
/// Returns:
///     A `Solution`: `arcs` (n, 3) rows (curvature, plane_angle, length), `tip_pose` (4, 4),
///     `frames` (N, 4, 4) at `s`, `tendon_lengths`, solver statistics.
#[pyfunction]
#[pyo3(signature = (robot, tensions=None, pressures=None, *, tip_force=None, tip_moment=None,
                    s=None, n_points=None, tolerance=None, max_iterations=None, continuation=None,
                    max_load_steps=None, warm_start=None, throw=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn pcc_solve<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::robot)] robot: Bound<'py, PccRobot>,
    tensions: Option<Bound<'py, PyAny>>,
    pressures: Option<Bound<'py, PyAny>>,
    tip_force: Option<Bound<'py, PyAny>>,
    tip_moment: Option<Bound<'py, PyAny>>,
    s: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::n_points)] n_points: Option<i64>,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: Option<f64>,
    #[pyo3(from_py_with = arg::max_iterations)] max_iterations: Option<i64>,
    #[pyo3(from_py_with = arg::continuation)] continuation: Option<bool>,
    #[pyo3(from_py_with = arg::max_load_steps)] max_load_steps: Option<i64>,
    warm_start: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::throw)] throw: Option<bool>,
) -> PyResult<PccSolution> {
    let o = |v: &Option<Bound<'py, PyAny>>| {
        v.as_ref().map_or_else(|| py.None(), |b| b.clone().unbind())
    };
    let call = crate::model::Args::new(
        py,
        &[
            ("robot", robot.clone().into_any().unbind()),
            ("tensions", o(&tensions)),
            ("pressures", o(&pressures)),
            ("tip_force", o(&tip_force)),
            ("tip_moment", o(&tip_moment)),
            ("s", o(&s)),
            ("n_points", crate::model::obj(py, n_points)?),
            ("tolerance", crate::model::obj(py, tolerance)?),
            ("max_iterations", crate::model::obj(py, max_iterations)?),
            ("continuation", crate::model::obj(py, continuation)?),
            ("max_load_steps", crate::model::obj(py, max_load_steps)?),
            ("warm_start", o(&warm_start)),
            ("throw", crate::model::obj(py, throw)?),
        ],
    )?;
    let floats = |v: Option<Bound<'py, PyAny>>, name: &str| -> PyResult<Option<Floats>> {
        v.filter(|b| !b.is_none())
            .map(|b| Floats::from_arg(&b, name))
            .transpose()
    };
    let (tensions, pressures) = (
        floats(tensions, "tensions")?,
        floats(pressures, "pressures")?,
    );
    let (tip_force, tip_moment, s) = (
        floats(tip_force, "tip_force")?,
        floats(tip_moment, "tip_moment")?,
        floats(s, "s")?,
    );
    let robot = robot.borrow();
    let d = PccSolveOptions::default();
    let max = softrod::limits::MAX_ITERATIONS;
    let max_iterations = max_iterations.map_or(Ok(d.newton.max_iterations), |k| {
        count("max_iterations", k, 1, max)
    })?;
    let max_load_steps = max_load_steps.map_or(Ok(d.newton.max_load_steps), |k| {
        count("max_load_steps", k, 1, max)
    })?;
    let tolerance = tolerance.unwrap_or(d.newton.tolerance);
    let continuation = continuation.unwrap_or(d.newton.continuation);
    let throw = throw.unwrap_or(d.newton.throw);
    // Checked before anything is solved or allocated.
    let n_points = n_points.map_or(Ok(DEFAULT_FRAMES), |k| {
        count("n_points", k, 2, softrod::limits::MAX_SAMPLES)
    })?;
    let loads = PccLoads {
        tensions: tensions
            .map(|t| t.to_vec())
            .transpose()?
            .unwrap_or_default(),
        pressures: pressures
            .map(|p| p.to_vec())
            .transpose()?
            .unwrap_or_default(),
        tip_force: tip_force
            .map(|f| vector3(f, "tip_force"))
            .transpose()?
            .unwrap_or_else(Vector3::zeros),
        tip_moment: tip_moment
            .map(|m| vector3(m, "tip_moment"))
            .transpose()?
            .unwrap_or_else(Vector3::zeros),
    };
    let warm = match warm_start.filter(|w| !w.is_none()) {
        None => None,
        Some(w) => match w.cast::<PccSolution>() {
            Ok(sol) => Some(sol.get().inner.warm_start()),
            Err(_) => {
                let rows = rows3(&w, "warm_start")?;
                Some(
                    pcc::PccChain::from_parameters(&rows)
                        .map_err(|e| to_py_err(renamed(e, "segments", "warm_start")))?
                        .segments()
                        .to_vec(),
                )
            }
        },
    };
    let options = PccSolveOptions {
        newton: softrod::NewtonOptions {
            tolerance,
            max_iterations,
            continuation,
            max_load_steps,
            throw,
        },
        warm_start: warm,
    };
    let samples = match s {
        Some(s) => Some(s.to_vec()?),
        None => None,
    };
    let model = &robot.inner;
    let solved_loads = loads.clone();
    let (inner, s, frames) = run(py, "pcc.solve", move || {
        let sol = statics::solve_pcc_statics(model, &loads, &options)?;
        let chain = sol.chain();
        let s = match samples {
            Some(s) => s,
            // Exactly 0 and exactly the chain's length at the ends.
            None => softrod::uniform_samples(chain.length(), n_points)?,
        };
        let frames = chain.backbone(&s)?;
        Ok((sol, s, frames))
    })?;
    Ok(PccSolution {
        inner,
        robot: model.clone(),
        loads: solved_loads,
        s,
        frames,
        call,
    })
}
