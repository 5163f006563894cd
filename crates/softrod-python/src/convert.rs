//! Conversions of Python arguments.

use numpy::{PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;

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
