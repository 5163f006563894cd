//! PCC actuation maps: tendon displacements of an arc and their Jacobian, the arc from tendon
//! displacements, tensions or chamber pressures and its Jacobian.

use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use softrod::pcc::{self, ElasticSegment};

use super::*;
use crate::convert::{arg, Floats};
use crate::errors::{blame, finite_result};

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

/// Per tendon, the length change of the least-squares arc minus the one given (m).
#[pyfunction]
#[pyo3(signature = (displacements, distances, angles, rest_length, *, extensible=true))]
pub(crate) fn pcc_tendon_displacement_misfit<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::displacements)] displacements: Floats,
    #[pyo3(from_py_with = arg::distances)] distances: Floats,
    #[pyo3(from_py_with = arg::angles)] angles: Floats,
    #[pyo3(from_py_with = arg::rest_length)] rest_length: f64,
    #[pyo3(from_py_with = arg::extensible)] extensible: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let t = tendons_from(distances, angles)?;
    let m = pcc::tendon_displacement_misfit(&displacements.to_vec()?, &t, rest_length, extensible)
        .map_err(blame(&[
            "displacements",
            "distances",
            "angles",
            "rest_length",
            "extensible",
        ]))?;
    Ok(m.into_pyarray(py))
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
    const NAMES: &[&str] = &[
        "displacements",
        "distances",
        "angles",
        "rest_length",
        "extensible",
        "coordinates",
    ];
    let c = coordinates_from(coordinates)?;
    let t = tendons_from(distances, angles)?;
    let j = pcc::arc_from_tendon_displacements_jacobian(
        &displacements.to_vec()?,
        &t,
        rest_length,
        extensible,
        c,
    )
    .map_err(blame(NAMES))?;
    finite_result(j.iter(), NAMES)?;
    Ok(matrix_array(py, &j))
}

fn body_from(
    rest_length: f64,
    bending_stiffness: f64,
    axial_stiffness: Option<f64>,
) -> PyResult<ElasticSegment> {
    // (Its errors name its own arguments; another function's list was appended to them.)
    ElasticSegment::new(rest_length, bending_stiffness, axial_stiffness).map_err(blame(&[
        "rest_length",
        "bending_stiffness",
        "axial_stiffness",
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
    const NAMES: &[&str] = &[
        "tensions",
        "distances",
        "angles",
        "rest_length",
        "bending_stiffness",
        "axial_stiffness",
        "coordinates",
    ];
    let c = coordinates_from(coordinates)?;
    let t = tendons_from(distances, angles)?;
    let body = body_from(rest_length, bending_stiffness, axial_stiffness)?;
    let j = pcc::arc_from_tendon_tensions_jacobian(&tensions.to_vec()?, &t, &body, c)
        .map_err(blame(NAMES))?;
    finite_result(j.iter(), NAMES)?;
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
    const NAMES: &[&str] = &[
        "pressures",
        "areas",
        "distances",
        "angles",
        "rest_length",
        "bending_stiffness",
        "axial_stiffness",
        "coordinates",
    ];
    let j = pcc::arc_from_pressures_jacobian(&pressures.to_vec()?, &ch, &body, c)
        .map_err(blame(NAMES))?;
    finite_result(j.iter(), NAMES)?;
    Ok(matrix_array(py, &j))
}
