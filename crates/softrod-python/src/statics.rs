//! Binding of the Cosserat statics: `solve_statics` and its solution.
//!
//! The Python signature keeps the objects a user builds (a rod, tendons with their tensions,
//! chambers with their pressures, loads); the binding splits them into the core's immutable
//! `RobotModel` and its `Actuation`. Options start from the core's `SolveOptions::default()`:
//! an option not given keeps the core's default (stated once, in the core).

use std::sync::Arc;

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple};

use softrod::{AdaptiveOptions, Integrator, SolveOptions};

use crate::errors::{param_err, to_py_err, StabilityError, StabilityWarning};
use crate::model::{Args, Chamber, ErrorSlot, Loads, Rod, Tendon};

/// The user's options, each `None` when not given.
#[derive(Default)]
pub(crate) struct OptionArgs<'py> {
    pub integrator: Option<&'py str>,
    pub steps: Option<i64>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub tolerance: Option<f64>,
    pub max_iterations: Option<i64>,
    pub continuation: Option<bool>,
    pub max_load_steps: Option<i64>,
    pub warm_start: Option<Bound<'py, PyAny>>,
    pub throw: Option<bool>,
    pub seek_stable: Option<bool>,
}

/// A count option (>= 1), naming it.
pub(crate) fn count(name: &str, v: i64) -> PyResult<usize> {
    if v < 1 {
        return Err(param_err(name, v, ">= 1"));
    }
    Ok(v as usize)
}

/// The one keyword parser of the solve options: from the core's defaults, each given option
/// replaced (and checked, naming the keyword).
pub(crate) fn solve_options(a: &OptionArgs<'_>) -> PyResult<SolveOptions> {
    let mut o = SolveOptions::default();
    let adaptive_defaults = AdaptiveOptions::default();
    o.integrator = match a.integrator.unwrap_or("rk4") {
        "rk4" => match (a.steps, o.integrator) {
            (Some(s), _) => Integrator::Rk4 {
                steps: count("steps", s)?,
            },
            (None, i) => i,
        },
        "adaptive" => Integrator::Adaptive(AdaptiveOptions {
            rtol: a.rtol.unwrap_or(adaptive_defaults.rtol),
            atol: a.atol.unwrap_or(adaptive_defaults.atol),
            ..adaptive_defaults
        }),
        other => return Err(param_err("integrator", other, "\"rk4\" or \"adaptive\"")),
    };
    if let Some(t) = a.tolerance {
        o.newton.tolerance = t;
    }
    if let Some(m) = a.max_iterations {
        o.newton.max_iterations = count("max_iterations", m)?;
    }
    if let Some(c) = a.continuation {
        o.newton.continuation = c;
    }
    if let Some(m) = a.max_load_steps {
        o.newton.max_load_steps = count("max_load_steps", m)?;
    }
    if let Some(t) = a.throw {
        o.newton.throw = t;
    }
    if let Some(t) = a.seek_stable {
        o.seek_stable = t;
    }
    if let Some(w) = &a.warm_start {
        o.warm_start = Some(if let Ok(s) = w.cast::<StaticsSolution>() {
            s.get().inner.warm_start()
        } else if let Ok(b) = w.extract::<[f64; 6]>() {
            softrod::WarmStart::wrench(b)
        } else {
            return Err(param_err(
                "warm_start",
                "<object>",
                "a StaticsSolution or a base wrench [force; moment] of 6 floats",
            ));
        });
    }
    Ok(o)
}

/// The core model and actuation of the user's objects, with the error slots of their
/// callables.
pub(crate) struct Problem {
    pub(crate) model: Arc<softrod::RobotModel>,
    pub(crate) actuation: softrod::Actuation,
    pub(crate) slots: Vec<ErrorSlot>,
}

impl Problem {
    pub(crate) fn new(
        rod: &Rod,
        tendons: &[Bound<'_, Tendon>],
        loads: Option<&Loads>,
        chambers: &[Bound<'_, Chamber>],
    ) -> PyResult<Self> {
        let mut slots: Vec<ErrorSlot> = rod.slots.clone();
        slots.extend(tendons.iter().map(|t| t.get().slot.clone()));
        slots.extend(chambers.iter().map(|c| c.get().slot.clone()));
        if let Some(l) = loads {
            slots.push(l.slot.clone());
        }
        let model = softrod::RobotModel::new(
            rod.inner.clone(),
            tendons.iter().map(|t| t.get().inner.clone()).collect(),
            chambers.iter().map(|c| c.get().inner.clone()).collect(),
            loads.map(|l| l.inner.clone()).unwrap_or_default(),
        )
        .map_err(|e| {
            // A callable that raised during validation is the cause: report its exception.
            slots
                .iter()
                .find_map(ErrorSlot::take)
                .unwrap_or_else(|| to_py_err(e))
        })?;
        let tensions: Vec<f64> = tendons.iter().map(|t| t.get().tension).collect();
        let pressures: Vec<f64> = chambers.iter().map(|c| c.get().pressure).collect();
        let actuation = softrod::Actuation::tensions(&tensions).with_pressures(&pressures);
        Ok(Self {
            model,
            actuation,
            slots,
        })
    }

    /// The first exception raised by a Python callable during a computation, if any.
    pub(crate) fn callback_error(&self) -> Option<PyErr> {
        self.slots.iter().find_map(ErrorSlot::take)
    }
}

/// A solved rod, sampled at the integration mesh (SI units, world frame unless `_body`).
///
/// Positions (m), rotations, internal force (N) and moment (N m), strains, tendon lengths (m),
/// base wrench (N, N m), solver stats; it pickles (by solving again, bit for bit).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct StaticsSolution {
    pub(crate) inner: softrod::StaticsSolution,
    cache: [PyOnceLock<Py<PyAny>>; 12],
    /// Error slots of the callables of the problem it solves.
    pub(crate) slots: Vec<ErrorSlot>,
    /// The call that produced it (for pickling: it is solved again, bit for bit).
    call: Args,
}

impl StaticsSolution {
    pub(crate) fn callback_error(&self) -> Option<PyErr> {
        self.slots.iter().find_map(ErrorSlot::take)
    }
}

fn rows3(py: Python<'_>, v: &[[f64; 3]]) -> Py<PyAny> {
    let a = Array::from_shape_fn((v.len(), 3), |(i, j)| v[i][j]);
    a.into_pyarray(py).into_any().unbind()
}

impl StaticsSolution {
    fn cached(
        &self,
        py: Python<'_>,
        i: usize,
        make: impl FnOnce(Python<'_>) -> Py<PyAny>,
    ) -> Py<PyAny> {
        self.cache[i].get_or_init(py, || make(py)).clone_ref(py)
    }
}

#[pymethods]
impl StaticsSolution {
    /// Undeformed arc length of each sample (m), shape (N,).
    #[getter]
    fn s(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 0, |py| {
            self.inner.s.clone().into_pyarray(py).into_any().unbind()
        })
    }
    /// Backbone positions (m, world), shape (N, 3).
    #[getter]
    fn position(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 1, |py| rows3(py, &self.inner.position))
    }
    /// Rotations body -> world, shape (N, 3, 3).
    #[getter]
    fn rotation(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 2, |py| {
            let r = &self.inner.rotation;
            let a = Array::from_shape_fn((r.len(), 3, 3), |(i, j, k)| r[i][j][k]);
            let arr: Bound<'_, PyArray3<f64>> = a.into_pyarray(py);
            arr.into_any().unbind()
        })
    }
    /// Unit quaternions of the rotations, scalar last [x, y, z, w], shape (N, 4).
    #[getter]
    fn quaternion(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 3, |py| {
            let q = &self.inner.quaternion;
            Array::from_shape_fn((q.len(), 4), |(i, j)| q[i][j])
                .into_pyarray(py)
                .into_any()
                .unbind()
        })
    }
    /// Internal force n (N, world), shape (N, 3).
    #[getter]
    fn force(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 4, |py| rows3(py, &self.inner.n_world))
    }
    /// Internal moment m (N m, world), shape (N, 3).
    #[getter]
    fn moment(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 5, |py| rows3(py, &self.inner.m_world))
    }
    /// Internal force in body components (N), shape (N, 3).
    #[getter]
    fn force_body(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 6, |py| rows3(py, &self.inner.n_body))
    }
    /// Internal moment in body components (N m), shape (N, 3).
    #[getter]
    fn moment_body(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 7, |py| rows3(py, &self.inner.m_body))
    }
    /// Shear/stretch strain v (body; (0, 0, 1) undeformed), shape (N, 3).
    #[getter]
    fn v(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 8, |py| rows3(py, &self.inner.v))
    }
    /// Bending/twist strain u (1/m, body), shape (N, 3).
    #[getter]
    fn u(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 9, |py| rows3(py, &self.inner.u))
    }
    /// Path length of each tendon from the base to its end (m), shape (n_tendons,).
    #[getter]
    fn tendon_lengths(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 10, |py| {
            self.inner
                .tendon_lengths
                .clone()
                .into_pyarray(py)
                .into_any()
                .unbind()
        })
    }
    /// Total base wrench [force; moment] (N, N m; world), shape (6,).
    #[getter]
    fn base_wrench(&self, py: Python<'_>) -> Py<PyAny> {
        self.cached(py, 11, |py| {
            self.inner
                .base_wrench
                .to_vec()
                .into_pyarray(py)
                .into_any()
                .unbind()
        })
    }
    /// Tendon tensions it was solved for (N), shape (n_tendons,).
    #[getter]
    fn tensions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.tensions().into_pyarray(py)
    }
    /// Chamber pressures it was solved for (Pa), shape (n_chambers,).
    #[getter]
    fn pressures<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.pressures().into_pyarray(py)
    }
    /// Tip position (m, world), shape (3,).
    #[getter]
    fn tip_position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.tip_position().to_vec().into_pyarray(py)
    }
    /// Tip rotation body -> world, shape (3, 3).
    #[getter]
    fn tip_rotation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let r = self
            .inner
            .rotation
            .last()
            .copied()
            .unwrap_or([[f64::NAN; 3]; 3]);
        Array::from_shape_fn((3, 3), |(i, j)| r[i][j]).into_pyarray(py)
    }
    /// Whether the shooting residual met the tolerance.
    #[getter]
    fn converged(&self) -> bool {
        self.inner.stats.converged
    }
    /// Whether the equilibrium is stable: its tip tangent stiffness (tendons at fixed
    /// tension, dead loads) is positive definite; always True without external loads,
    /// False for a result that did not converge (docs/stability.md).
    #[getter]
    fn stable(&self) -> bool {
        self.inner.stable
    }
    /// Smallest eigenvalue of the symmetric part of the dimensionless tip tangent stiffness
    /// D K D / (EI(0)/L), D = diag(L, L, L, 1, 1, 1): > 0 for a stable equilibrium; NaN if
    /// not converged (docs/stability.md).
    #[getter]
    fn stability_margin(&self, py: Python<'_>) -> f64 {
        py.detach(|| self.inner.stability_margin())
    }
    /// Solver statistics: iterations, residual, function_evaluations, load_steps, load_factor,
    /// converged.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        stats_dict(py, &self.inner.stats)
    }
    fn __len__(&self) -> usize {
        self.inner.s.len()
    }
    fn __repr__(&self) -> String {
        let t = self.inner.tip_position();
        format!(
            "StaticsSolution(samples={}, tip_position=[{:.6e}, {:.6e}, {:.6e}] m, converged={}, \
             iterations={}, residual={:.2e})",
            self.inner.s.len(),
            t[0],
            t[1],
            t[2],
            self.inner.stats.converged,
            self.inner.stats.iterations,
            self.inner.stats.residual
        )
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = py.import("softrod._core")?.getattr("solve_statics")?;
        slf.get().call.reduce(py, f)
    }
}

/// The solver statistics as a dict (the same keys for every model).
pub(crate) fn stats_dict<'py>(
    py: Python<'py>,
    st: &softrod::SolverStats,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("iterations", st.iterations)?;
    d.set_item("residual", st.residual)?;
    d.set_item("function_evaluations", st.function_evaluations)?;
    d.set_item("load_steps", st.load_steps)?;
    d.set_item("load_factor", st.load_factor)?;
    d.set_item("converged", st.converged)?;
    Ok(d)
}

/// What to do when the equilibrium returned is unstable.
#[derive(Clone, Copy, PartialEq, Eq)]
enum OnUnstable {
    Warn,
    Raise,
    Ignore,
}

fn on_unstable(v: Option<&str>) -> PyResult<OnUnstable> {
    match v.unwrap_or("warn") {
        "warn" => Ok(OnUnstable::Warn),
        "raise" => Ok(OnUnstable::Raise),
        "ignore" => Ok(OnUnstable::Ignore),
        other => Err(param_err(
            "on_unstable",
            other,
            "\"warn\", \"raise\" or \"ignore\"",
        )),
    }
}

/// Warns (`StabilityWarning`) or raises (`StabilityError`) for a converged, unstable
/// solution, as asked.
fn report_unstable(
    py: Python<'_>,
    sol: StaticsSolution,
    mode: OnUnstable,
) -> PyResult<StaticsSolution> {
    let inner = &sol.inner;
    if mode == OnUnstable::Ignore || inner.stable || !inner.stats.converged {
        return Ok(sol);
    }
    let margin = inner.stability_margin();
    let msg = format!(
        "the equilibrium returned is unstable (stability margin {margin:.4e}: the tip \
         tangent stiffness is not positive definite) and no stable equilibrium was found \
         from it; see docs/stability.md"
    );
    if mode == OnUnstable::Warn {
        let category = py.get_type::<StabilityWarning>();
        PyErr::warn(py, &category, &std::ffi::CString::new(msg)?, 1)?;
        return Ok(sol);
    }
    let err = StabilityError::new_err(msg);
    let value = err.value(py);
    value.setattr("stability_margin", margin)?;
    value.setattr("solution", Py::new(py, sol)?)?;
    Err(err)
}

/// Solves the statics of `rod` with `tendons`, `loads` and pneumatic `chambers` by shooting
/// (see the docs). Options not given keep the core's defaults.
///
/// Tendon tensions (N) and chamber pressures (Pa) are the actuation; returns a
/// `StaticsSolution` (SI units; at the arc lengths `s_out` (m) if given) or raises
/// `ConvergenceError` (with iterations, residual, load_factor). An unstable equilibrium is
/// replaced by a stable one when found (`seek_stable`), else reported (`on_unstable`).
#[pyfunction]
#[pyo3(signature = (rod, tendons=Vec::new(), loads=None, *, integrator=None, steps=None,
                    rtol=None, atol=None, tolerance=None, max_iterations=None,
                    continuation=None, max_load_steps=None, warm_start=None, throw=None,
                    chambers=Vec::new(), s_out=None, seek_stable=None, on_unstable=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_statics<'py>(
    py: Python<'py>,
    rod: &Bound<'py, Rod>,
    tendons: Vec<Bound<'py, Tendon>>,
    loads: Option<&Bound<'py, Loads>>,
    integrator: Option<&'py str>,
    steps: Option<i64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<i64>,
    continuation: Option<bool>,
    max_load_steps: Option<i64>,
    warm_start: Option<Bound<'py, PyAny>>,
    throw: Option<bool>,
    chambers: Vec<Bound<'py, Chamber>>,
    s_out: Option<Bound<'py, PyAny>>,
    seek_stable: Option<bool>,
    on_unstable: Option<&'py str>,
) -> PyResult<StaticsSolution> {
    let unstable = self::on_unstable(on_unstable)?;
    let s_values = crate::convert::floats_opt(s_out.as_ref(), "s_out")?;
    let args = OptionArgs {
        integrator,
        steps,
        rtol,
        atol,
        tolerance,
        max_iterations,
        continuation,
        max_load_steps,
        warm_start: warm_start.clone(),
        throw,
        seek_stable,
    };
    let options = solve_options(&args)?;
    let problem = Problem::new(rod.get(), &tendons, loads.map(Bound::get), &chambers)?;
    let (model, act) = (&problem.model, &problem.actuation);
    let result = py.detach(|| softrod::solve_statics_at(model, act, &options, &s_values));
    if let Some(err) = problem.callback_error() {
        return Err(err);
    }
    let o = |v: Option<Py<PyAny>>| v.unwrap_or_else(|| py.None());
    let call = Args::new(
        py,
        &[
            ("rod", rod.clone().into_any().unbind()),
            ("tendons", tendons.into_pyobject(py)?.into_any().unbind()),
            ("loads", o(loads.map(|l| l.clone().into_any().unbind()))),
            (
                "integrator",
                integrator.into_pyobject(py)?.into_any().unbind(),
            ),
            ("steps", steps.into_pyobject(py)?.into_any().unbind()),
            ("rtol", rtol.into_pyobject(py)?.into_any().unbind()),
            ("atol", atol.into_pyobject(py)?.into_any().unbind()),
            (
                "tolerance",
                tolerance.into_pyobject(py)?.into_any().unbind(),
            ),
            (
                "max_iterations",
                max_iterations.into_pyobject(py)?.into_any().unbind(),
            ),
            (
                "continuation",
                continuation.into_pyobject(py)?.into_any().unbind(),
            ),
            (
                "max_load_steps",
                max_load_steps.into_pyobject(py)?.into_any().unbind(),
            ),
            ("warm_start", o(warm_start.map(Bound::unbind))),
            ("throw", throw.into_pyobject(py)?.into_any().unbind()),
            ("chambers", chambers.into_pyobject(py)?.into_any().unbind()),
            (
                "s_out",
                s_values.clone().into_pyobject(py)?.into_any().unbind(),
            ),
            (
                "seek_stable",
                seek_stable.into_pyobject(py)?.into_any().unbind(),
            ),
            (
                "on_unstable",
                "ignore".into_pyobject(py)?.into_any().unbind(),
            ),
        ],
    )?;
    let sol = StaticsSolution {
        inner: result.map_err(to_py_err)?,
        cache: std::array::from_fn(|_| PyOnceLock::new()),
        slots: problem.slots,
        call,
    };
    report_unstable(py, sol, unstable)
}

/// Benchmark hook: runs the same solve `repeats` times inside Rust and returns each call's
/// wall time (s), so that the Python overhead of `solve_statics` can be measured.
#[pyfunction]
#[pyo3(signature = (rod, tendons=Vec::new(), loads=None, *, repeats=1000, integrator=None,
                    steps=None, rtol=None, atol=None, tolerance=None, warm_start=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _time_solve_statics<'py>(
    py: Python<'py>,
    rod: &Bound<'py, Rod>,
    tendons: Vec<Bound<'py, Tendon>>,
    loads: Option<&Bound<'py, Loads>>,
    repeats: i64,
    integrator: Option<&'py str>,
    steps: Option<i64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    tolerance: Option<f64>,
    warm_start: Option<Bound<'py, PyAny>>,
) -> PyResult<Vec<f64>> {
    let repeats = count("repeats", repeats)?;
    let options = solve_options(&OptionArgs {
        integrator,
        steps,
        rtol,
        atol,
        tolerance,
        warm_start,
        ..Default::default()
    })?;
    let problem = Problem::new(rod.get(), &tendons, loads.map(Bound::get), &[])?;
    let (model, act) = (&problem.model, &problem.actuation);
    let times = py.detach(|| {
        (0..repeats)
            .map(|_| {
                let t0 = std::time::Instant::now();
                let r = softrod::solve_statics(model, act, &options);
                (t0.elapsed().as_secs_f64(), r.is_ok())
            })
            .collect::<Vec<_>>()
    });
    if let Some(err) = problem.callback_error() {
        return Err(err);
    }
    if times.iter().any(|(_, ok)| !ok) {
        if let Err(e) = softrod::solve_statics(model, act, &options) {
            return Err(to_py_err(e));
        }
    }
    Ok(times.into_iter().map(|(t, _)| t).collect())
}
