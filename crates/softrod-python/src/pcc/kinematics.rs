//! PCC kinematics: the pose, frames and Jacobian of one arc and of a chain, the arc through
//! a tip position.

use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;

use softrod::pcc::{self, PccSegment};

use super::*;
use crate::convert::{arg, Floats};
use crate::errors::{blame, finite_result, param_err};

/// Tip pose (4×4) of one arc.
#[pyfunction]
pub(crate) fn pcc_arc_pose(
    py: Python<'_>,
    #[pyo3(from_py_with = arg::curvature)] curvature: f64,
    #[pyo3(from_py_with = arg::plane_angle)] plane_angle: f64,
    #[pyo3(from_py_with = arg::length)] length: f64,
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    const NAMES: &[&str] = &["curvature", "plane_angle", "length"];
    let t = pcc::arc_pose(curvature, plane_angle, length).map_err(blame(NAMES))?;
    finite_result(t.iter(), NAMES)?;
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
    const NAMES: &[&str] = &["curvature", "plane_angle", "length", "s"];
    let s = s.to_vec()?;
    let ts = pcc::arc_frames(curvature, plane_angle, length, &s).map_err(blame(NAMES))?;
    finite_result(ts.iter().flat_map(|m| m.iter()), NAMES)?;
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
    const NAMES: &[&str] = &["curvature", "plane_angle", "length", "frame", "coordinates"];
    let (f, c) = (frame_from(frame)?, coordinates_from(coordinates)?);
    let j = pcc::arc_jacobian(curvature, plane_angle, length, f, c).map_err(blame(NAMES))?;
    finite_result(j.iter(), NAMES)?;
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
    const NAMES: &[&str] = &["segments", "s"];
    let chain = pcc::PccChain::new(segments_from(segments)?).map_err(blame(NAMES))?;
    let ts = chain
        .backbone(&s.to_vec()?)
        .map_err(blame(&["segments", "s"]))?;
    finite_result(ts.iter().flat_map(|m| m.iter()), NAMES)?;
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
