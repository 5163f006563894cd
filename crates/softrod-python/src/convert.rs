//! Conversions of Python arguments.

use numpy::PyReadonlyArray1;
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
            Floats::Array(a) => a.as_slice()?.to_vec(),
            Floats::Scalar(x) => vec![*x],
            Floats::Seq(v) => v.clone(),
        })
    }
}
