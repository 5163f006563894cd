//! The call a solution was solved by, kept as given: it becomes the keyword arguments of
//! `solve_statics` only when the solution is pickled (and solved again, bit for bit), not at
//! every solve.

use pyo3::prelude::*;
use pyo3::types::PyTuple;
use pyo3::IntoPyObjectExt;

use super::options::Given;
use super::robot::RobotModel;
use crate::model::{Args, Chamber, Loads, Rod, Tendon};

/// What was solved: the user's objects, or a robot's model under an actuation.
pub(crate) enum Subject {
    /// `solve_statics(rod, tendons, loads, chambers=...)`.
    Objects {
        rod: Py<Rod>,
        tendons: Vec<Py<Tendon>>,
        loads: Option<Py<Loads>>,
        chambers: Vec<Py<Chamber>>,
    },
    /// `Robot.solve(tensions, pressures)`: the robot's model with these tensions (N) and
    /// pressures (Pa), each `None` when its objects' own.
    Robot {
        model: Py<RobotModel>,
        tensions: Option<Vec<f64>>,
        pressures: Option<Vec<f64>>,
    },
}

/// The options of the call as given (`None`: not given).
pub(crate) struct Call {
    pub(crate) subject: Subject,
    pub(crate) integrator: Option<String>,
    pub(crate) given: Given,
    pub(crate) warm_start: Option<Py<PyAny>>,
    pub(crate) s_out: Vec<f64>,
    pub(crate) previous: Option<Py<PyAny>>,
    pub(crate) displacements: Option<Py<PyAny>>,
    pub(crate) tendon_stiffness: Option<Py<PyAny>>,
    pub(crate) obstacles: Option<Py<PyAny>>,
    pub(crate) tip_constraint: Option<Py<PyAny>>,
}

impl Call {
    /// `(_rebuild, (solve_statics, (), kwargs))`: the call of `solve_statics` that solves the
    /// same problem again (a robot's actuation as its tendons and chambers at those tensions
    /// and pressures; `on_unstable="ignore"`: the solution exists).
    pub(crate) fn reduce<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let f = py.import("softrod._core")?.getattr("solve_statics")?;
        let [rod, tendons, loads, chambers] = self.objects(py)?;
        let o = |v: &Option<Py<PyAny>>| v.as_ref().map_or_else(|| py.None(), |b| b.clone_ref(py));
        let args = Args::new(
            py,
            &[
                ("rod", rod),
                ("tendons", tendons),
                ("loads", loads),
                ("integrator", self.integrator.clone().into_py_any(py)?),
                ("steps", self.given.steps.into_py_any(py)?),
                ("rtol", self.given.rtol.into_py_any(py)?),
                ("atol", self.given.atol.into_py_any(py)?),
                ("tolerance", self.given.tolerance.into_py_any(py)?),
                ("max_iterations", self.given.max_iterations.into_py_any(py)?),
                ("continuation", self.given.continuation.into_py_any(py)?),
                ("max_load_steps", self.given.max_load_steps.into_py_any(py)?),
                ("warm_start", o(&self.warm_start)),
                ("throw", self.given.throw.into_py_any(py)?),
                ("chambers", chambers),
                ("s_out", self.s_out.clone().into_py_any(py)?),
                ("seek_stable", self.given.seek_stable.into_py_any(py)?),
                ("on_unstable", "ignore".into_py_any(py)?),
                ("previous", o(&self.previous)),
                ("displacements", o(&self.displacements)),
                ("tendon_stiffness", o(&self.tendon_stiffness)),
                ("obstacles", o(&self.obstacles)),
                ("tip_constraint", o(&self.tip_constraint)),
            ],
        )?;
        args.reduce(py, f)
    }

    /// The rod, the list of tendons, the loads (or None) and the list of chambers solved.
    fn objects(&self, py: Python<'_>) -> PyResult<[Py<PyAny>; 4]> {
        let loads = |l: &Option<Py<Loads>>| {
            l.as_ref()
                .map_or_else(|| py.None(), |l| l.clone_ref(py).into_any())
        };
        match &self.subject {
            Subject::Objects {
                rod,
                tendons,
                loads: l,
                chambers,
            } => Ok([
                rod.clone_ref(py).into_any(),
                list(py, tendons)?,
                loads(l),
                list(py, chambers)?,
            ]),
            Subject::Robot {
                model,
                tensions,
                pressures,
            } => {
                let m = model.get();
                let tendons = match tensions {
                    None => list(py, &m.tendons)?,
                    Some(t) => m
                        .tendons
                        .iter()
                        .zip(t)
                        .map(|(x, &t)| Py::new(py, x.get().tensioned(py, t)?))
                        .collect::<PyResult<Vec<_>>>()?
                        .into_py_any(py)?,
                };
                let chambers = match pressures {
                    None => list(py, &m.chambers)?,
                    Some(p) => m
                        .chambers
                        .iter()
                        .zip(p)
                        .map(|(x, &p)| Py::new(py, x.get().pressurised(py, p)?))
                        .collect::<PyResult<Vec<_>>>()?
                        .into_py_any(py)?,
                };
                Ok([
                    m.rod.clone_ref(py).into_any(),
                    tendons,
                    loads(&m.loads),
                    chambers,
                ])
            }
        }
    }
}

/// A Python list of `items`.
fn list<T>(py: Python<'_>, items: &[Py<T>]) -> PyResult<Py<PyAny>> {
    items
        .iter()
        .map(|x| x.clone_ref(py).into_any())
        .collect::<Vec<_>>()
        .into_py_any(py)
}
