//! Python exceptions and the one place where core errors become them.
//!
//! - `ParameterError` (a `ValueError`): a value outside its range; `.parameter` names it.
//! - `ParameterTypeError` (a `ParameterError` and a `TypeError`): an argument of the wrong type
//!   or shape; `.parameter` names it.
//! - `ConvergenceError` (a `RuntimeError`): `.iterations`, `.residual`.
//! - `TargetUnreachableError` (a `ConvergenceError`): `.distance`, `.rotation`, `.iterations`.
//! - `InternalError` (a `RuntimeError`): a defect of softrod caught at the binding (a Rust
//!   panic), never a user error.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

use softrod::Error;

create_exception!(
    softrod._core,
    ParameterError,
    PyValueError,
    "A parameter is outside its valid range; the message names it, its value and the range.\n\n\
     `parameter` is the name (e.g. `tip_force`); values are in SI units (m, N, Pa, rad)."
);
create_exception!(
    softrod._core,
    ConvergenceError,
    PyRuntimeError,
    "A solver or integrator did not converge; carries `iterations`, `residual` and \
     `load_factor`.\n\n\
     The residual is the solver's scaled (dimensionless) residual; `load_factor` is the \
     fraction of the external loads the last iterate carries (1: the full problem)."
);

create_exception!(
    softrod._core,
    TargetUnreachableError,
    ConvergenceError,
    "Inverse statics: the target is out of reach within the actuation bounds; carries \
     `distance` (m, to the closest pose found), `rotation` (rad) and `iterations`.\n\n\
     Pass `throw=False` to get the closest reachable pose with `converged=False` instead."
);

create_exception!(
    softrod._core,
    StabilityWarning,
    PyUserWarning,
    "The equilibrium returned is unstable (its tip tangent stiffness, in N/m and N m/rad, \
     is not positive definite) and no stable one was found.\n\nIssued by the solves \
     (`on_unstable=\"warn\"`, the default); its measure is \
     `StaticsSolution.stability_margin` (dimensionless: stiffness per EI(0)/L, EI in N m^2, \
     L in m); docs/stability.md."
);
create_exception!(
    softrod._core,
    StabilityError,
    PyRuntimeError,
    "The equilibrium reached is unstable and no stable one was found \
     (`on_unstable=\"raise\"`).\n\nCarries `stability_margin` (dimensionless: the tip \
     tangent stiffness per EI(0)/L, EI in N m^2, L in m) and the unstable `solution`."
);
create_exception!(
    softrod._core,
    InternalError,
    PyRuntimeError,
    "A defect of softrod caught at the binding (it would have been a crash); please report it.\n\n\
     The message says where it happened. Never raised for bad input."
);

static PARAMETER_TYPE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// `ParameterTypeError(ParameterError, TypeError)`: an argument of the wrong type or shape.
pub(crate) fn parameter_type_error(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    PARAMETER_TYPE_ERROR
        .get_or_try_init(py, || {
            let bases = PyTuple::new(
                py,
                [
                    py.get_type::<ParameterError>().into_any(),
                    py.get_type::<PyTypeError>().into_any(),
                ],
            )?;
            let ns = PyDict::new(py);
            ns.set_item("__module__", "softrod._core")?;
            ns.set_item(
                "__doc__",
                "An argument of the wrong type or shape: a ParameterError and a TypeError.\n\n\
                 `parameter` names the argument; the message says what was expected.",
            )?;
            let t =
                py.import("builtins")?
                    .getattr("type")?
                    .call1(("ParameterTypeError", bases, ns))?;
            Ok(t.cast_into::<PyType>()?.unbind())
        })
        .map(|t| t.bind(py))
}

/// The one place where core errors become Python exceptions.
pub(crate) fn to_py_err(e: Error) -> PyErr {
    let msg = one_line(&e.to_string());
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
        Error::TargetUnreachable {
            distance,
            rotation,
            iterations,
        } => Python::attach(|py| {
            let err = TargetUnreachableError::new_err(msg);
            let v = err.value(py);
            let _ = v.setattr("distance", distance);
            let _ = v.setattr("rotation", rotation);
            let _ = v.setattr("iterations", iterations);
            let _ = v.setattr("residual", distance);
            let _ = v.setattr("load_factor", 1.0);
            err
        }),
    }
}

/// A `ParameterError` naming `name` with its value and valid range.
pub(crate) fn param_err(name: &str, value: impl std::fmt::Display, expected: &str) -> PyErr {
    to_py_err(Error::invalid(name, value, expected))
}

/// A `ParameterTypeError` naming `name`: `obj` is not `expected`.
pub(crate) fn type_err(name: &str, obj: &Bound<'_, PyAny>, expected: &str) -> PyErr {
    let py = obj.py();
    let msg = one_line(&Error::invalid(name, describe(obj), expected).to_string());
    match parameter_type_error(py).and_then(|t| t.call1((msg.clone(),))) {
        Ok(value) => {
            let _ = value.setattr("parameter", name);
            PyErr::from_value(value)
        }
        Err(_) => PyTypeError::new_err(msg),
    }
}

/// An `InternalError`: a defect caught at the binding.
pub(crate) fn internal_err(what: &str) -> PyErr {
    InternalError::new_err(one_line(&format!(
        "internal error of softrod ({what}); please report it with the call that raised it"
    )))
}

/// `repr(obj)` on one line, at most 80 characters, with its type: `'abc' (str)`.
pub(crate) fn describe(obj: &Bound<'_, PyAny>) -> String {
    let repr = obj
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "<object>".into());
    let mut repr = one_line(&repr);
    if repr.chars().count() > 80 {
        repr = repr.chars().take(77).collect::<String>() + "...";
    }
    let ty = obj
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into());
    format!("{repr} ({ty})")
}

/// Collapses whitespace runs (newlines of array reprs, enum dumps) into single spaces.
pub(crate) fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A core error of a function of `params`: an error naming an intermediate (`u_x`, `curvature`
/// of the computed arc) says which arguments it was computed from.
pub(crate) fn blame(params: &'static [&'static str]) -> impl Fn(Error) -> PyErr {
    move |e| match e {
        Error::InvalidParameter {
            name,
            value,
            expected,
        } if !params.iter().any(|p| {
            name == *p || name.starts_with(&format!("{p}[")) || name.starts_with(&format!("{p}."))
        }) =>
        {
            to_py_err(Error::InvalidParameter {
                name,
                value,
                expected: format!("{expected} (computed from {})", params.join(", ")),
            })
        }
        other => to_py_err(other),
    }
}

/// `values` if every one is finite, else a `ParameterError` saying that the result of
/// `params` overflows (the inputs are individually valid but their combination is not
/// representable).
pub(crate) fn finite_result<'v>(
    values: impl IntoIterator<Item = &'v f64>,
    params: &[&str],
) -> PyResult<()> {
    if values.into_iter().all(|v| v.is_finite()) {
        return Ok(());
    }
    Err(param_err(
        params.first().copied().unwrap_or("arguments"),
        "(see the message)",
        &format!(
            "such that the result is finite: it overflows a double for these {}",
            params.join(", ")
        ),
    ))
}
