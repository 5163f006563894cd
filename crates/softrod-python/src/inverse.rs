//! Binding of the inverse statics: the actuation reaching a target, as a dict the Python
//! wrapper (`softrod.inverse_statics`) turns into an `InverseSolution`.

use std::borrow::Cow;

use numpy::IntoPyArray;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use softrod::nalgebra::{Matrix3, Vector3};
use softrod::pcc::statics::{PccLoads, PccSolveOptions};
use softrod::{InverseOptions, InverseWarmStart, Target};

use crate::callbacks::run;
use crate::convert::{arg, floats_opt, vec3, Matrix};
use crate::errors::param_err;
use crate::model::{Chamber, Loads, Rod, Tendon};
use crate::statics::{actuator_names, solve_options, Given, OptionArgs, Problem};

/// The state an inverse result hands to the next call (its actuation, last evaluation with
/// the Jacobian, and Lagrangian Hessian): opaque to Python, passed back as `warm_state`.
#[pyclass(frozen, module = "softrod._core", name = "_InverseWarmState")]
pub(crate) struct InverseWarmState {
    inner: InverseWarmStart,
}

/// The warm start of a call: `warm_state` (if its actuation is that of `warm_start`, or
/// `warm_start` is not given; with its evaluation only when `same_model`), else the actuation
/// of `warm_start` alone.
fn merge_warm<'a>(
    warm: Option<InverseWarmStart>,
    state: Option<&'a Bound<'_, InverseWarmState>>,
    same_model: bool,
) -> Option<Cow<'a, InverseWarmStart>> {
    let from_state = |st: &'a Bound<'_, InverseWarmState>| {
        let inner = &st.get().inner;
        if same_model {
            Cow::Borrowed(inner)
        } else {
            Cow::Owned(InverseWarmStart {
                evaluation: None,
                ..inner.clone()
            })
        }
    };
    match (warm, state) {
        (None, st) => st.map(from_state),
        (Some(w), Some(st)) if st.get().inner.actuation == w.actuation => Some(from_state(st)),
        (Some(w), _) => Some(Cow::Owned(w)),
    }
}

/// The target and the options of an inverse call, checked and named.
#[allow(clippy::too_many_arguments)]
fn target_and_options(
    target_position: &Bound<'_, PyAny>,
    target_s: Option<&Bound<'_, PyAny>>,
    target_rotation: Option<&Bound<'_, PyAny>>,
    weights: Option<&Bound<'_, PyAny>>,
    tension_bounds: Option<&Bound<'_, PyAny>>,
    pressure_bounds: Option<&Bound<'_, PyAny>>,
    warm_start: Option<&Bound<'_, PyAny>>,
    throw: bool,
    tolerance: Option<f64>,
    max_iterations: Option<i64>,
) -> PyResult<(Target, InverseOptions, Option<InverseWarmStart>)> {
    let arcs = floats_opt(target_s, "target_s")?;
    let points = if target_s.is_some_and(|t| !t.is_none()) {
        let m: Matrix = crate::convert::Arg::from_arg(target_position, "target_position")?;
        if m.0.ncols() != 3 || m.0.nrows() != arcs.len() {
            return Err(param_err(
                "target_position",
                format!("shape {:?}", m.0.shape()),
                &format!(
                    "({}, 3): one point (m, world) per arc length of target_s",
                    arcs.len()
                ),
            ));
        }
        (0..m.0.nrows())
            .map(|k| Vector3::new(m.0[(k, 0)], m.0[(k, 1)], m.0[(k, 2)]))
            .collect()
    } else {
        vec![vec3(target_position, "target_position")?]
    };
    let rotation = match target_rotation.filter(|r| !r.is_none()) {
        None => None,
        Some(r) => {
            let m: Matrix = crate::convert::Arg::from_arg(r, "target_rotation")?;
            if m.0.shape() != [3, 3] {
                return Err(param_err(
                    "target_rotation",
                    format!("shape {:?}", m.0.shape()),
                    "a 3x3 rotation matrix (body -> world)",
                ));
            }
            Some(Matrix3::from_fn(|i, j| m.0[(i, j)]))
        }
    };
    let mut o = InverseOptions {
        throw,
        interrupt: softrod::Interrupt(Some(crate::callbacks::interrupted)),
        ..InverseOptions::default()
    };
    o.tension_bounds = bounds(tension_bounds, "tension_bounds", o.tension_bounds)?;
    o.pressure_bounds = bounds(pressure_bounds, "pressure_bounds", o.pressure_bounds)?;
    let w = floats_opt(weights, "weights")?;
    o.weights = (!w.is_empty()).then_some(w);
    if let Some(t) = tolerance {
        o.tolerance = t;
    }
    if let Some(m) = max_iterations {
        o.max_iterations =
            crate::convert::count("max_iterations", m, 1, softrod::limits::MAX_ITERATIONS)?;
    }
    let warm = floats_opt(warm_start, "warm_start")?;
    let warm = (!warm.is_empty()).then(|| InverseWarmStart::actuation(warm));
    let target = Target {
        points,
        s: target_s.is_some_and(|t| !t.is_none()).then_some(arcs),
        rotation,
    };
    Ok((target, o, warm))
}

/// The result of an inverse call as the dict the Python wrappers read (the warm state takes
/// the result's evaluation and Hessian).
fn result_dict(py: Python<'_>, inv: softrod::InverseSolution) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(
        intern!(py, "tensions"),
        inv.tensions().to_vec().into_pyarray(py),
    )?;
    d.set_item(
        intern!(py, "pressures"),
        inv.pressures().to_vec().into_pyarray(py),
    )?;
    d.set_item(intern!(py, "position_error"), inv.position_error)?;
    d.set_item(intern!(py, "rotation_error"), inv.rotation_error)?;
    d.set_item(intern!(py, "iterations"), inv.iterations)?;
    d.set_item(intern!(py, "converged"), inv.converged)?;
    d.set_item(intern!(py, "reached"), inv.reached)?;
    d.set_item(intern!(py, "start"), inv.start)?;
    let state = InverseWarmState {
        inner: InverseWarmStart::from(inv),
    };
    d.set_item(intern!(py, "warm_state"), Bound::new(py, state)?)?;
    Ok(d)
}

/// The starts of an inverse call: None (one), a count, or an array of actuations (k, n).
fn starts_from(obj: Option<&Bound<'_, PyAny>>) -> PyResult<softrod::Starts> {
    let Some(s) = obj.filter(|s| !s.is_none()) else {
        return Ok(softrod::Starts::One);
    };
    let is_int = s.is_instance_of::<pyo3::types::PyInt>()
        || s.hasattr("__index__")? && !s.hasattr("__len__")?;
    if is_int {
        let range = format!("in [1, {}]", softrod::MAX_STARTS);
        if s.is_instance_of::<pyo3::types::PyBool>() {
            return Err(crate::errors::type_err("starts", s, "an integer"));
        }
        let Ok(k) = s.extract::<i64>() else {
            // (Beyond 64 bits: a count, but not one of the range.)
            return Err(param_err("starts", crate::errors::describe(s), &range));
        };
        let k = crate::convert::count("starts", k, 1, softrod::MAX_STARTS)?;
        return Ok(softrod::Starts::Spread(k));
    }
    let m: Matrix = crate::convert::Arg::from_arg(s, "starts").map_err(|_| {
        crate::errors::type_err(
            "starts",
            s,
            "a count of starts, or a 2-d array of actuations (one start per row)",
        )
    })?;
    Ok(softrod::Starts::Given(
        m.0.rows()
            .into_iter()
            .map(|r| r.iter().copied().collect())
            .collect(),
    ))
}

/// A pair of bounds `(lo, hi)` (`hi` None: unbounded) or the default.
fn bounds(obj: Option<&Bound<'_, PyAny>>, name: &str, default: (f64, f64)) -> PyResult<(f64, f64)> {
    let Some(b) = obj.filter(|b| !b.is_none()) else {
        return Ok(default);
    };
    let what = "a pair (lo, hi) of numbers (hi may be None: unbounded)";
    let items = match b.cast::<PyTuple>() {
        Ok(t) if t.len() == 2 => vec![t.get_item(0)?, t.get_item(1)?],
        _ => crate::convert::sequence(b, name, what)?,
    };
    if items.len() != 2 {
        return Err(param_err(
            &format!("{name}.len()"),
            items.len(),
            "2: (lo, hi)",
        ));
    }
    let lo: f64 = crate::convert::Arg::from_arg(&items[0], &format!("{name}[0]"))?;
    let hi: f64 = if items[1].is_none() {
        f64::INFINITY
    } else {
        crate::convert::Arg::from_arg(&items[1], &format!("{name}[1]"))?
    };
    Ok((lo, hi))
}

/// Inverse statics of the robot `(rod, tendons, loads, chambers)` for a tip target (see
/// `softrod.inverse_statics`). Returns a dict: `tensions`, `pressures`, `position_error` (m),
/// `rotation_error` (rad), `iterations`, `converged`, `reached`, `warm_state` (what a call
/// warm-started from this one reuses) and, with obstacles, `stable` and `stability_margin` of
/// the contact solution at the answer (when it is the last one solved).
#[pyfunction]
#[pyo3(signature = (rod, tendons, loads, chambers, target_position, *, target_rotation=None,
                    target_s=None, weights=None, tension_bounds=None, pressure_bounds=None, warm_start=None,
                    throw=true, tolerance=None, max_iterations=None, integrator=None, steps=None,
                    rtol=None, atol=None, warm_state=None, same_model=false, obstacles=None,
                    starts=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _inverse_statics<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::rod)] rod: Bound<'py, Rod>,
    #[pyo3(from_py_with = arg::tendons)] tendons: Vec<Bound<'py, Tendon>>,
    #[pyo3(from_py_with = arg::loads)] loads: Option<Bound<'py, Loads>>,
    #[pyo3(from_py_with = arg::chambers)] chambers: Vec<Bound<'py, Chamber>>,
    target_position: Bound<'py, PyAny>,
    target_rotation: Option<Bound<'py, PyAny>>,
    target_s: Option<Bound<'py, PyAny>>,
    weights: Option<Bound<'py, PyAny>>,
    tension_bounds: Option<Bound<'py, PyAny>>,
    pressure_bounds: Option<Bound<'py, PyAny>>,
    warm_start: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::throw)] throw: bool,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: Option<f64>,
    #[pyo3(from_py_with = arg::max_iterations)] max_iterations: Option<i64>,
    #[pyo3(from_py_with = arg::integrator)] integrator: Option<&'py str>,
    #[pyo3(from_py_with = arg::steps)] steps: Option<i64>,
    #[pyo3(from_py_with = arg::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = arg::atol)] atol: Option<f64>,
    warm_state: Option<Bound<'py, InverseWarmState>>,
    same_model: bool,
    obstacles: Option<Bound<'py, PyAny>>,
    starts: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let obstacles = crate::contact::obstacles(py, obstacles.as_ref())?;
    let (target, mut o, warm) = target_and_options(
        &target_position,
        target_s.as_ref(),
        target_rotation.as_ref(),
        weights.as_ref(),
        tension_bounds.as_ref(),
        pressure_bounds.as_ref(),
        warm_start.as_ref(),
        throw,
        tolerance,
        max_iterations,
    )?;
    o.starts = starts_from(starts.as_ref())?;
    let solve = solve_options(&OptionArgs {
        integrator,
        given: Given::mesh(steps, rtol, atol, None),
        ..OptionArgs::default()
    })?;
    let problem = Problem::new(&rod, &tendons, loads.as_ref(), &chambers)?;
    let warm = merge_warm(warm, warm_state.as_ref(), same_model);
    let model = &problem.model;
    // The forward solution is made in Python (when it is asked for), not here.
    let inv = run(py, "inverse_statics", || {
        if !obstacles.is_empty() {
            // The forward model is the contact solve (the arm may rest on an obstacle).
            if target.s.is_some() {
                return Err(softrod::Error::invalid(
                    "target_s",
                    "given",
                    "None with obstacles (the contact inverse aims at the tip)",
                ));
            }
            let (inv, mut fwd) = softrod::contact_inverse_resolved(
                model,
                &obstacles,
                &target,
                &o,
                &solve,
                warm.as_deref(),
            )
            .map_err(actuator_names)?;
            // The stability of the contact solution at the answer (the last one solved, or
            // solved again) when the target was reached.
            let last = fwd.solution.take().filter(|s| {
                s.solution.tensions() == inv.tensions() && s.solution.pressures() == inv.pressures()
            });
            let at_answer = match last {
                Some(s) => Some(s),
                None if inv.reached => fwd.solve(&inv.actuation).ok(),
                None => None,
            };
            let stability = at_answer.map(|s| (s.solution.stable, s.solution.stability_margin()));
            return Ok((inv, stability));
        }
        softrod::inverse_actuation(model, &target, &o, &solve, warm.as_deref())
            .map(|inv| (inv, None))
            .map_err(actuator_names)
    })?;
    let (inv, stability) = inv;
    // The mesh of the answer when the mesh control refined the one asked: the solution at
    // the answer is solved there (its tip is the one the position error measures).
    let asked = match solve.integrator {
        softrod::Integrator::Rk4 { steps } => Some(steps),
        softrod::Integrator::Adaptive(_) => None,
    };
    let refined = inv.steps.filter(|s| Some(*s) != asked);
    let d = result_dict(py, inv)?;
    d.set_item(intern!(py, "refined_steps"), refined)?;
    if let Some((stable, margin)) = stability {
        d.set_item(intern!(py, "stable"), stable)?;
        d.set_item(intern!(py, "stability_margin"), margin)?;
    }
    Ok(d)
}

/// Inverse statics of the PCC robot `robot` under a tip wrench (`tip_force` N, `tip_moment`
/// N m, world) for a tip target (see `softrod.pcc.inverse_statics`); the same dict as
/// `_inverse_statics`.
#[pyfunction]
#[pyo3(signature = (robot, target_position, *, target_rotation=None, weights=None,
                    tension_bounds=None, pressure_bounds=None, tip_force=None, tip_moment=None,
                    warm_start=None, throw=true, tolerance=None, max_iterations=None,
                    warm_state=None, same_model=false, starts=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _pcc_inverse_statics<'py>(
    py: Python<'py>,
    robot: PyRef<'py, crate::pcc::PccRobot>,
    target_position: Bound<'py, PyAny>,
    target_rotation: Option<Bound<'py, PyAny>>,
    weights: Option<Bound<'py, PyAny>>,
    tension_bounds: Option<Bound<'py, PyAny>>,
    pressure_bounds: Option<Bound<'py, PyAny>>,
    tip_force: Option<Bound<'py, PyAny>>,
    tip_moment: Option<Bound<'py, PyAny>>,
    warm_start: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::throw)] throw: bool,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: Option<f64>,
    #[pyo3(from_py_with = arg::max_iterations)] max_iterations: Option<i64>,
    warm_state: Option<Bound<'py, InverseWarmState>>,
    same_model: bool,
    starts: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (target, mut o, warm) = target_and_options(
        &target_position,
        None,
        target_rotation.as_ref(),
        weights.as_ref(),
        tension_bounds.as_ref(),
        pressure_bounds.as_ref(),
        warm_start.as_ref(),
        throw,
        tolerance,
        max_iterations,
    )?;
    o.starts = starts_from(starts.as_ref())?;
    let vec_or_zero = |v: Option<Bound<'py, PyAny>>, name: &str| -> PyResult<Vector3<f64>> {
        match v.filter(|b| !b.is_none()) {
            None => Ok(Vector3::zeros()),
            Some(b) => vec3(&b, name),
        }
    };
    let loads = PccLoads {
        tip_force: vec_or_zero(tip_force, "tip_force")?,
        tip_moment: vec_or_zero(tip_moment, "tip_moment")?,
        ..PccLoads::default()
    };
    let warm = merge_warm(warm, warm_state.as_ref(), same_model);
    let model = &robot.inner;
    let inv = run(py, "pcc.inverse_statics", || {
        softrod::pcc_inverse_statics(
            model,
            &loads,
            &target,
            &o,
            &PccSolveOptions::default(),
            warm.as_deref(),
        )
    })?;
    result_dict(py, inv)
}
