//! The core model of a `softrod.Robot`, validated once and shared by all its solves, and the
//! solve of that model under an actuation (`Robot.solve`): the tensions and pressures are an
//! input of the core, not new tendon and chamber objects.

use pyo3::prelude::*;

use super::options::{Given, Names, Problem};
use super::{solve, Keywords, Source, StaticsSolution};
use crate::convert::{arg, numbers_1d};
use crate::errors::{param_err, to_py_err};
use crate::model::{Chamber, Loads, Rod, Tendon};

/// The validated core model of a robot's rod, tendons, loads and chambers (built once by
/// `softrod.Robot`, shared by its solves); the objects' tensions and pressures are its
/// default actuation.
#[pyclass(frozen, module = "softrod._core", name = "_RobotModel")]
pub(crate) struct RobotModel {
    pub(crate) problem: Problem,
    pub(crate) rod: Py<Rod>,
    pub(crate) tendons: Vec<Py<Tendon>>,
    pub(crate) loads: Option<Py<Loads>>,
    pub(crate) chambers: Vec<Py<Chamber>>,
}

#[pymethods]
impl RobotModel {
    #[new]
    #[pyo3(signature = (rod, tendons=Vec::new(), loads=None, chambers=Vec::new()))]
    fn new(
        #[pyo3(from_py_with = arg::rod)] rod: Bound<'_, Rod>,
        #[pyo3(from_py_with = arg::tendons)] tendons: Vec<Bound<'_, Tendon>>,
        #[pyo3(from_py_with = arg::loads)] loads: Option<Bound<'_, Loads>>,
        #[pyo3(from_py_with = arg::chambers)] chambers: Vec<Bound<'_, Chamber>>,
    ) -> PyResult<Self> {
        let problem = Problem::new(&rod, &tendons, loads.as_ref(), &chambers)?;
        Ok(Self {
            problem,
            rod: rod.unbind(),
            tendons: tendons.into_iter().map(Bound::unbind).collect(),
            loads: loads.map(Bound::unbind),
            chambers: chambers.into_iter().map(Bound::unbind).collect(),
        })
    }
}

impl RobotModel {
    /// The core model and the actuation of `tensions` (N) and `pressures` (Pa), each the
    /// objects' own when `None`, checked and named (`tensions[i]`, `pressures[i]`).
    pub(crate) fn actuation(
        &self,
        tensions: Option<&Vec<f64>>,
        pressures: Option<&Vec<f64>>,
    ) -> PyResult<(softrod::Actuation, Names)> {
        let mut actuation = self.problem.actuation.clone();
        if let Some(t) = tensions {
            actuation.tendons = t
                .iter()
                .map(|&x| softrod::TendonInput::Tension(x))
                .collect();
        }
        if let Some(p) = pressures {
            actuation.pressures.clone_from(p);
        }
        if tensions.is_some() || pressures.is_some() {
            // Before displacement control replaces some tensions: every value given is checked.
            actuation
                .validate(self.tendons.len(), self.chambers.len())
                .map_err(to_py_err)?;
        }
        let names = Names {
            tendons: tensions.is_none(),
            chambers: pressures.is_none(),
        };
        Ok((actuation, names))
    }
}

/// One value per actuator: `name` (a number or a 1-d sequence or array of numbers) must have
/// `n`.
pub(crate) fn per_actuator(
    obj: Option<&Bound<'_, PyAny>>,
    name: &str,
    n: usize,
    what: &str,
) -> PyResult<Option<Vec<f64>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let v = numbers_1d(obj, name)?;
    if v.len() != n {
        let given = match v.len() {
            1 => "1 value".to_string(),
            k => format!("{k} values"),
        };
        return Err(param_err(
            name,
            given,
            &format!("one value per {what} ({n})"),
        ));
    }
    Ok(Some(v))
}

/// Solves the statics of a robot's model under `tensions` (N, one per tendon) and `pressures`
/// (Pa, one per chamber), each default the objects' own; the keywords of `solve_statics`.
/// The solution is that of `solve_statics` with the robot's objects at this actuation (and
/// pickles as that call).
#[pyfunction]
#[pyo3(signature = (model, tensions=None, pressures=None, *, integrator=None, steps=None,
                    rtol=None, atol=None, tolerance=None, max_iterations=None,
                    continuation=None, max_load_steps=None, warm_start=None, throw=None,
                    s_out=None, seek_stable=None, on_unstable=None, previous=None,
                    displacements=None, tendon_stiffness=None, obstacles=None,
                    tip_constraint=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _solve_robot<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::model)] model: Bound<'py, RobotModel>,
    tensions: Option<Bound<'py, PyAny>>,
    pressures: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::integrator)] integrator: Option<&'py str>,
    #[pyo3(from_py_with = arg::steps)] steps: Option<i64>,
    #[pyo3(from_py_with = arg::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = arg::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: Option<f64>,
    #[pyo3(from_py_with = arg::max_iterations)] max_iterations: Option<i64>,
    #[pyo3(from_py_with = arg::continuation)] continuation: Option<bool>,
    #[pyo3(from_py_with = arg::max_load_steps)] max_load_steps: Option<i64>,
    warm_start: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::throw)] throw: Option<bool>,
    s_out: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::seek_stable)] seek_stable: Option<bool>,
    #[pyo3(from_py_with = arg::on_unstable)] on_unstable: Option<&'py str>,
    previous: Option<Bound<'py, PyAny>>,
    displacements: Option<Bound<'py, PyAny>>,
    tendon_stiffness: Option<Bound<'py, PyAny>>,
    obstacles: Option<Bound<'py, PyAny>>,
    tip_constraint: Option<Bound<'py, PyAny>>,
) -> PyResult<StaticsSolution> {
    let m = model.get();
    let tensions = per_actuator(tensions.as_ref(), "tensions", m.tendons.len(), "tendon")?;
    let pressures = per_actuator(pressures.as_ref(), "pressures", m.chambers.len(), "chamber")?;
    solve(
        py,
        Source::Robot {
            model,
            tensions,
            pressures,
        },
        Keywords {
            integrator,
            given: Given {
                steps,
                rtol,
                atol,
                tolerance,
                max_iterations,
                continuation,
                max_load_steps,
                throw,
                seek_stable,
            },
            warm_start,
            s_out,
            on_unstable,
            previous,
            displacements,
            tendon_stiffness,
            obstacles,
            tip_constraint,
        },
    )
}
