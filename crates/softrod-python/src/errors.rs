//! Python exceptions and the one place where core errors become them.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;

use softrod::Error;

create_exception!(
    _core,
    ParameterError,
    PyValueError,
    "A parameter is outside its valid range; the message names it, its value and the range.\n\n\
     `parameter` is the name (e.g. `tip_force`); values are in SI units (m, N, Pa, rad)."
);
create_exception!(
    _core,
    ConvergenceError,
    PyRuntimeError,
    "A solver or integrator did not converge; carries `iterations`, `residual` and \
     `load_factor`.\n\n\
     The residual is the solver's scaled (dimensionless) residual; `load_factor` is the \
     fraction of the external loads the last iterate carries (1: the full problem)."
);

create_exception!(
    _core,
    StabilityWarning,
    PyUserWarning,
    "The equilibrium returned is unstable (its tip tangent stiffness is not positive \
     definite) and no stable one was found; see `StaticsSolution.stability_margin`."
);
create_exception!(
    _core,
    StabilityError,
    PyRuntimeError,
    "The equilibrium reached is unstable and no stable one was found \
     (`on_unstable=\"raise\"`); carries `stability_margin` and the unstable `solution`."
);

/// The one place where core errors become Python exceptions.
pub(crate) fn to_py_err(e: Error) -> PyErr {
    let msg = e.to_string();
    match e {
        Error::InvalidParameter { name, .. } => Python::attach(|py| {
            let err = ParameterError::new_err(msg);
            let _ = err.value(py).setattr("parameter", name);
            err
        }),
        Error::NotConverged {
            iterations,
            residual,
            load_factor,
            ..
        } => Python::attach(|py| {
            let err = ConvergenceError::new_err(msg);
            let _ = err.value(py).setattr("iterations", iterations);
            let _ = err.value(py).setattr("residual", residual);
            let _ = err.value(py).setattr("load_factor", load_factor);
            err
        }),
    }
}

pub(crate) fn param_err(name: &str, value: impl std::fmt::Display, expected: &str) -> PyErr {
    to_py_err(Error::invalid(name, value, expected))
}
