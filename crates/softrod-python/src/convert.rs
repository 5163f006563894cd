//! The one argument-conversion layer: every extraction failure names the argument.

use numpy::{PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;

use softrod::nalgebra::Vector3;

use crate::errors::param_err;

/// Floats given as a NumPy array, any sequence, or one number.
#[derive(FromPyObject)]
pub(crate) enum Floats<'py> {
    Array(PyReadonlyArray1<'py, f64>),
    Scalar(f64),
    Seq(Vec<f64>),
}

impl Floats<'_> {
    pub(crate) fn to_vec(&self) -> PyResult<Vec<f64>> {
        Ok(match self {
            // Strided views (e.g. `x[::2]`, a matrix column) are copied element by element.
            Floats::Array(a) if a.is_contiguous() => a.as_slice()?.to_vec(),
            Floats::Array(a) => a.as_array().to_vec(),
            Floats::Scalar(x) => vec![*x],
            Floats::Seq(v) => v.clone(),
        })
    }
}

fn describe(obj: &Bound<'_, PyAny>) -> String {
    obj.repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "<object>".into())
}

/// `n` floats from a sequence or a 1-d array, naming `name` on failure.
pub(crate) fn floats_n(
    obj: &Bound<'_, PyAny>,
    name: &str,
    n: usize,
    what: &str,
) -> PyResult<Vec<f64>> {
    let v = match obj.extract::<Floats<'_>>() {
        Ok(Floats::Scalar(_)) | Err(_) => None,
        Ok(f) => Some(f.to_vec()?),
    };
    match v {
        Some(v) if v.len() == n => Ok(v),
        _ => Err(param_err(name, describe(obj), what)),
    }
}

/// A 3-vector (N, m, ...), naming `name` on failure.
pub(crate) fn vec3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vector3<f64>> {
    let v = floats_n(obj, name, 3, "a sequence of 3 floats (x, y, z)")?;
    Ok(Vector3::new(v[0], v[1], v[2]))
}

/// A body-frame `(x, y)` pair, naming `name` on failure.
pub(crate) fn pair(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 2]> {
    let v = floats_n(obj, name, 2, "a pair of floats (x, y) in m")?;
    Ok([v[0], v[1]])
}

/// A pose: a 4×4 homogeneous transform or `(position, rotation)`.
pub(crate) fn pose(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<([f64; 3], [[f64; 3]; 3])> {
    if let Ok(t) = obj.extract::<[[f64; 4]; 4]>() {
        if t[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err(param_err(
                &format!("{name}[3]"),
                format!("{:?}", t[3]),
                "[0, 0, 0, 1] (a homogeneous transform)",
            ));
        }
        return Ok((
            [t[0][3], t[1][3], t[2][3]],
            [
                [t[0][0], t[0][1], t[0][2]],
                [t[1][0], t[1][1], t[1][2]],
                [t[2][0], t[2][1], t[2][2]],
            ],
        ));
    }
    if let Ok(pr) = obj.extract::<([f64; 3], [[f64; 3]; 3])>() {
        return Ok(pr);
    }
    Err(param_err(
        name,
        describe(obj),
        "a 4x4 homogeneous transform or (position (3,), rotation (3, 3))",
    ))
}

/// A load frame, "world" or "body".
pub(crate) fn frame_from(name: &str, frame: &str) -> PyResult<softrod::Frame> {
    match frame {
        "world" => Ok(softrod::Frame::World),
        "body" => Ok(softrod::Frame::Body),
        other => Err(param_err(name, other, "\"world\" or \"body\"")),
    }
}

/// Any number of floats from a sequence or a 1-d array (`None`: empty), naming `name` on
/// failure.
pub(crate) fn floats_opt(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<Vec<f64>> {
    match obj {
        None => Ok(Vec::new()),
        Some(o) if o.is_none() => Ok(Vec::new()),
        Some(o) => match o.extract::<Floats<'_>>() {
            Ok(f) => f.to_vec(),
            Err(_) => Err(param_err(name, describe(o), "a sequence of floats (m)")),
        },
    }
}
