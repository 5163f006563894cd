//! Binding of the planar cable-arm paper's planar cable arm and the backbone distance.

use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::model::{obj, Args};

use softrod::AdaptiveOptions;

use crate::callbacks::run;
use crate::convert::{arg, choice, count, Arg, Floats, Matrix};
use crate::errors::{param_err, to_py_err};

// The Python signatures spell the core's default tolerances as literals (so that
// `inspect.signature` shows them); these checks keep the two in step.
const _: () = assert!(softrod::integrate::DEFAULT_RTOL == 1e-8);
const _: () = assert!(softrod::integrate::DEFAULT_ATOL == 1e-10);
const _: () = assert!(softrod::integrate::DEFAULT_MAX_STEPS == 100_000);

fn method_from(
    method: &str,
    rtol: f64,
    atol: f64,
    max_steps: i64,
) -> PyResult<softrod::PlanarMethod> {
    let max_steps = count("max_steps", max_steps, 1, softrod::limits::MAX_ITERATIONS)?;
    // The tolerances are checked whichever method uses them.
    let opts = AdaptiveOptions {
        rtol,
        atol,
        max_steps,
    }
    .validated()
    .map_err(to_py_err)?;
    match choice("method", method, &["closed-form", "closed_form", "ode"])? {
        "ode" => Ok(softrod::PlanarMethod::Ode(opts)),
        _ => Ok(softrod::PlanarMethod::ClosedForm),
    }
}

fn samples_from(length: f64, n_points: i64, s: Option<Floats>) -> PyResult<Vec<f64>> {
    match s {
        Some(s) => s.to_vec(),
        None => {
            let n = count("n_points", n_points, 2, softrod::limits::MAX_SAMPLES)?;
            softrod::uniform_samples(length, n).map_err(to_py_err)
        }
    }
}

/// The planar cable-arm paper's tapered cable-driven arm (immutable).
///
/// Length, radii (m), cable offset ratio (dimensionless), Young's modulus (Pa), cable anchor
/// (m); `solve(tension)` with the tension in N.
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct PlanarCableArm {
    inner: softrod::PlanarCableArm,
}

fn extract_floats(b: &Bound<'_, PyAny>, name: &str) -> PyResult<Floats> {
    Floats::from_arg(b, name)
}

/// The call `arm.<method>(first, n_points=..., s=..., ...)` of a solution, for pickling.
#[allow(clippy::too_many_arguments)]
fn call_args<'py>(
    arm: &Bound<'py, PlanarCableArm>,
    method_name: &'static str,
    first: Py<PyAny>,
    n_points: i64,
    s: &Option<Bound<'py, PyAny>>,
    method: &str,
    rtol: f64,
    atol: f64,
    max_steps: i64,
) -> PyResult<(Py<PyAny>, Args)> {
    let py = arm.py();
    let first_name = if method_name == "solve" {
        "tension"
    } else {
        "tensions"
    };
    let args = Args::new(
        py,
        &[
            (first_name, first),
            ("n_points", obj(py, n_points)?),
            (
                "s",
                s.as_ref().map_or_else(|| py.None(), |b| b.clone().unbind()),
            ),
            ("method", obj(py, method)?),
            ("rtol", obj(py, rtol)?),
            ("atol", obj(py, atol)?),
            ("max_steps", obj(py, max_steps)?),
        ],
    )?;
    Ok((arm.getattr(method_name)?.unbind(), args))
}

/// Samples of one solved planar arm.
///
/// Arc length, backbone x, y (m), curvature (1/m), axial strain (dimensionless), tangent
/// angle (rad), per sample.
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct PlanarSolution {
    call: (Py<PyAny>, Args),
    #[pyo3(get)]
    tension: f64,
    #[pyo3(get)]
    s: Py<PyArray1<f64>>,
    #[pyo3(get)]
    curvature: Py<PyArray1<f64>>,
    #[pyo3(get)]
    strain: Py<PyArray1<f64>>,
    #[pyo3(get)]
    angle: Py<PyArray1<f64>>,
    #[pyo3(get)]
    x: Py<PyArray1<f64>>,
    #[pyo3(get)]
    y: Py<PyArray1<f64>>,
    #[pyo3(get)]
    tip: Py<PyArray1<f64>>,
    #[pyo3(get)]
    tip_angle: f64,
    #[pyo3(get)]
    max_compressive_strain: f64,
    #[pyo3(get)]
    method: String,
    #[pyo3(get)]
    stats: Option<Py<PyDict>>,
}

#[pymethods]
impl PlanarSolution {
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let (f, args) = &slf.get().call;
        args.reduce(slf.py(), f.bind(slf.py()).clone())
    }
    fn __repr__(&self) -> String {
        format!(
            "PlanarSolution(tension={} N, method={:?}, tip_angle={:.6} rad)",
            self.tension, self.method, self.tip_angle
        )
    }
}

/// Many tensions solved on one set of samples; 2-D arrays are `(n_tensions, n_samples)`.
///
/// Tensions (N), backbone x, y (m), curvature (1/m), strain (dimensionless), angle (rad).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct PlanarBatch {
    call: (Py<PyAny>, Args),
    #[pyo3(get)]
    tension: Py<PyArray1<f64>>,
    #[pyo3(get)]
    s: Py<PyArray1<f64>>,
    #[pyo3(get)]
    curvature: Py<PyArray2<f64>>,
    #[pyo3(get)]
    strain: Py<PyArray2<f64>>,
    #[pyo3(get)]
    angle: Py<PyArray2<f64>>,
    #[pyo3(get)]
    x: Py<PyArray2<f64>>,
    #[pyo3(get)]
    y: Py<PyArray2<f64>>,
    #[pyo3(get)]
    tip: Py<PyArray2<f64>>,
    #[pyo3(get)]
    tip_angle: Py<PyArray1<f64>>,
}

#[pymethods]
impl PlanarBatch {
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let (f, args) = &slf.get().call;
        args.reduce(slf.py(), f.bind(slf.py()).clone())
    }
    fn __repr__(&self, py: Python<'_>) -> String {
        let shape = self.x.bind(py).dims();
        format!("PlanarBatch(tensions={}, samples={})", shape[0], shape[1])
    }
    fn __len__(&self, py: Python<'_>) -> usize {
        self.x.bind(py).dims()[0]
    }
}

fn to_2d(py: Python<'_>, v: Vec<f64>, rows: usize, cols: usize) -> PyResult<Py<PyArray2<f64>>> {
    Ok(v.into_pyarray(py).reshape([rows, cols])?.unbind())
}

#[pymethods]
impl PlanarCableArm {
    #[new]
    #[pyo3(signature = (length, base_radius, tip_radius, offset_ratio, youngs_modulus, anchor=None))]
    fn new(
        #[pyo3(from_py_with = arg::length)] length: f64,
        #[pyo3(from_py_with = arg::base_radius)] base_radius: f64,
        #[pyo3(from_py_with = arg::tip_radius)] tip_radius: f64,
        #[pyo3(from_py_with = arg::offset_ratio)] offset_ratio: f64,
        #[pyo3(from_py_with = arg::youngs_modulus)] youngs_modulus: f64,
        #[pyo3(from_py_with = arg::anchor)] anchor: Option<f64>,
    ) -> PyResult<Self> {
        softrod::PlanarCableArm::new(
            length,
            base_radius,
            tip_radius,
            offset_ratio,
            youngs_modulus,
            anchor,
        )
        .map(|inner| Self { inner })
        .map_err(to_py_err)
    }

    /// The paper's experimental arm (L 270 mm, R0 15 mm, RL 7.4 mm, a 1/3, E 110 kPa).
    #[staticmethod]
    fn published_arm() -> Self {
        Self {
            inner: softrod::PlanarCableArm::published_arm(),
        }
    }

    /// The same arm as `published_arm()` (its earlier name, kept working).
    #[staticmethod]
    fn seed_arm() -> Self {
        Self::published_arm()
    }

    #[getter]
    fn length(&self) -> f64 {
        self.inner.length()
    }
    #[getter]
    fn base_radius(&self) -> f64 {
        self.inner.base_radius()
    }
    #[getter]
    fn tip_radius(&self) -> f64 {
        self.inner.tip_radius()
    }
    #[getter]
    fn offset_ratio(&self) -> f64 {
        self.inner.offset_ratio()
    }
    #[getter]
    fn youngs_modulus(&self) -> f64 {
        self.inner.youngs_modulus()
    }
    #[getter]
    fn anchor(&self) -> f64 {
        self.inner.anchor()
    }
    #[getter]
    fn max_tension(&self) -> f64 {
        self.inner.max_tension()
    }

    /// Section radius R(s) (m) at arc lengths `s` (m).
    ///
    /// Raises `ParameterError` naming `s[i]` for an arc length outside `[0, length]` (the taper
    /// is not extrapolated).
    fn radius<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = arg::s)] s: Floats,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let s = s.to_vec()?;
        let r = s
            .iter()
            .enumerate()
            .map(|(i, &si)| self.inner.radius_at(|| format!("s[{i}]"), si))
            .collect::<softrod::Result<Vec<_>>>()
            .map_err(to_py_err)?;
        Ok(r.into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        let a = &self.inner;
        format!(
            "PlanarCableArm(length={}, base_radius={}, tip_radius={}, offset_ratio={}, \
             youngs_modulus={}, anchor={})",
            a.length(),
            a.base_radius(),
            a.tip_radius(),
            a.offset_ratio(),
            a.youngs_modulus(),
            a.anchor()
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let a = &slf.get().inner;
        let args = Args::new(
            py,
            &[
                ("length", obj(py, a.length())?),
                ("base_radius", obj(py, a.base_radius())?),
                ("tip_radius", obj(py, a.tip_radius())?),
                ("offset_ratio", obj(py, a.offset_ratio())?),
                ("youngs_modulus", obj(py, a.youngs_modulus())?),
                ("anchor", obj(py, a.anchor())?),
            ],
        )?;
        args.reduce(py, slf.get_type().into_any())
    }

    #[pyo3(signature = (tension, n_points=201, *, s=None, method="closed-form", rtol=1e-8, atol=1e-10, max_steps=100_000))]
    #[allow(clippy::too_many_arguments)]
    fn solve<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
        #[pyo3(from_py_with = arg::tension)] tension: f64,
        #[pyo3(from_py_with = arg::n_points)] n_points: i64,
        s: Option<Bound<'py, PyAny>>,
        #[pyo3(from_py_with = arg::method)] method: &str,
        #[pyo3(from_py_with = arg::rtol)] rtol: f64,
        #[pyo3(from_py_with = arg::atol)] atol: f64,
        #[pyo3(from_py_with = arg::max_steps)] max_steps: i64,
    ) -> PyResult<PlanarSolution> {
        let call = call_args(
            slf,
            "solve",
            obj(py, tension)?,
            n_points,
            &s,
            method,
            rtol,
            atol,
            max_steps,
        )?;
        let s = s.map(|b| extract_floats(&b, "s")).transpose()?;
        let this = slf.get();
        let samples = samples_from(this.inner.length(), n_points, s)?;
        let m = method_from(method, rtol, atol, max_steps)?;
        let arm = this.inner;
        let sol = run(py, "PlanarCableArm.solve", move || {
            softrod::solve_planar(&arm, tension, &samples, m)
        })?;
        let stats = match sol.ode_stats {
            Some(st) => {
                let d = PyDict::new(py);
                d.set_item("accepted_steps", st.accepted)?;
                d.set_item("rejected_steps", st.rejected)?;
                d.set_item("evaluations", st.evaluations)?;
                Some(d.unbind())
            }
            None => None,
        };
        let mcs = sol.max_compressive_strain();
        Ok(PlanarSolution {
            tension: sol.tension,
            s: sol.s.into_pyarray(py).unbind(),
            curvature: sol.curvature.into_pyarray(py).unbind(),
            strain: sol.strain.into_pyarray(py).unbind(),
            angle: sol.angle.into_pyarray(py).unbind(),
            x: sol.x.into_pyarray(py).unbind(),
            y: sol.y.into_pyarray(py).unbind(),
            tip: sol.tip.to_vec().into_pyarray(py).unbind(),
            tip_angle: sol.tip_angle,
            max_compressive_strain: mcs,
            method: if sol.ode_stats.is_some() {
                "ode"
            } else {
                "closed-form"
            }
            .to_string(),
            stats,
            call,
        })
    }

    /// Exact sensitivities of the backbone at arc lengths `s` (m) for one tension (N).
    ///
    /// Returns a dict: `parameters` (the column names), `s`, `x`, `y` (m), `angle` (rad),
    /// `strain`, `arc` (deformed arc length, m), their derivatives `d_x`, `d_y`, `d_angle`,
    /// `d_arc` of shape (n, 5) per unit of each parameter, `tip` (x, y, angle, arc) and `d_tip`
    /// (4, 5). Forward mode on the closed-form profile, no finite differences.
    #[pyo3(signature = (tension, s))]
    fn sensitivities<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = arg::tension)] tension: f64,
        #[pyo3(from_py_with = arg::s)] s: Floats,
    ) -> PyResult<Bound<'py, PyDict>> {
        let samples = s.to_vec()?;
        let arm = self.inner;
        let r = run(py, "PlanarCableArm.sensitivities", move || {
            softrod::planar_sensitivities(&arm, tension, &samples)
        })?;
        let n = r.s.len();
        let np = softrod::PlanarParameter::COUNT;
        let d = PyDict::new(py);
        let names: Vec<&str> = softrod::PlanarParameter::ALL
            .iter()
            .map(|p| p.name())
            .collect();
        d.set_item("parameters", names)?;
        d.set_item("tension", r.tension)?;
        d.set_item("s", r.s.into_pyarray(py))?;
        d.set_item("x", r.x.into_pyarray(py))?;
        d.set_item("y", r.y.into_pyarray(py))?;
        d.set_item("angle", r.angle.into_pyarray(py))?;
        d.set_item("strain", r.strain.into_pyarray(py))?;
        d.set_item("arc", r.arc.into_pyarray(py))?;
        d.set_item("d_x", to_2d(py, r.d_x, n, np)?)?;
        d.set_item("d_y", to_2d(py, r.d_y, n, np)?)?;
        d.set_item("d_angle", to_2d(py, r.d_angle, n, np)?)?;
        d.set_item("d_arc", to_2d(py, r.d_arc, n, np)?)?;
        d.set_item("tip", r.tip.to_vec().into_pyarray(py))?;
        let dt: Vec<f64> = r.d_tip.iter().flatten().copied().collect();
        d.set_item("d_tip", to_2d(py, dt, 4, np)?)?;
        Ok(d)
    }

    #[pyo3(signature = (tensions, n_points=201, *, s=None, method="closed-form", rtol=1e-8, atol=1e-10, max_steps=100_000))]
    #[allow(clippy::too_many_arguments)]
    fn solve_many<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
        tensions: Bound<'py, PyAny>,
        #[pyo3(from_py_with = arg::n_points)] n_points: i64,
        s: Option<Bound<'py, PyAny>>,
        #[pyo3(from_py_with = arg::method)] method: &str,
        #[pyo3(from_py_with = arg::rtol)] rtol: f64,
        #[pyo3(from_py_with = arg::atol)] atol: f64,
        #[pyo3(from_py_with = arg::max_steps)] max_steps: i64,
    ) -> PyResult<PlanarBatch> {
        let call = call_args(
            slf,
            "solve_many",
            tensions.clone().unbind(),
            n_points,
            &s,
            method,
            rtol,
            atol,
            max_steps,
        )?;
        let s = s.map(|b| extract_floats(&b, "s")).transpose()?;
        let t = extract_floats(&tensions, "tensions")?.to_vec()?;
        let this = slf.get();
        let samples = samples_from(this.inner.length(), n_points, s)?;
        let m = method_from(method, rtol, atol, max_steps)?;
        let arm = this.inner;
        let b = run(py, "PlanarCableArm.solve_many", move || {
            softrod::solve_planar_many(&arm, &t, &samples, m)
        })?;
        let (nt, ns) = (b.tensions.len(), b.s.len());
        let tip: Vec<f64> = b.tip.iter().flatten().copied().collect();
        Ok(PlanarBatch {
            tension: b.tensions.into_pyarray(py).unbind(),
            s: b.s.into_pyarray(py).unbind(),
            curvature: to_2d(py, b.curvature, nt, ns)?,
            strain: to_2d(py, b.strain, nt, ns)?,
            angle: to_2d(py, b.angle, nt, ns)?,
            x: to_2d(py, b.x, nt, ns)?,
            y: to_2d(py, b.y, nt, ns)?,
            tip: to_2d(py, tip, nt, 2)?,
            tip_angle: b.tip_angle.into_pyarray(py).unbind(),
            call,
        })
    }
}

/// Distance of two backbones `(n, dim)` at equal arm index; returns a dict.
#[pyfunction]
#[pyo3(signature = (a, b, n_index=None))]
pub(crate) fn backbone_distance<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::a)] a: Matrix,
    #[pyo3(from_py_with = arg::b)] b: Matrix,
    #[pyo3(from_py_with = arg::n_index)] n_index: Option<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (a, b) = (a.0, b.0);
    let (da, db) = (a.ncols(), b.ncols());
    if da != db {
        return Err(param_err(
            "b.shape[1]",
            db,
            &format!("equal to a.shape[1] = {da}"),
        ));
    }
    let n_index = n_index
        .map(|n| count("n_index", n, 2, softrod::limits::MAX_SAMPLES))
        .transpose()?;
    let av = a.iter().copied().collect::<Vec<_>>();
    let bv = b.iter().copied().collect::<Vec<_>>();
    let d = run(py, "backbone_distance", || {
        softrod::backbone_distance(&av, &bv, da, n_index)
    })?;
    let out = PyDict::new(py);
    out.set_item("max", d.max)?;
    out.set_item("mean", d.mean)?;
    out.set_item("argmax_index", d.argmax_index)?;
    out.set_item("index", d.index.into_pyarray(py))?;
    out.set_item("distance", d.distance.into_pyarray(py))?;
    Ok(out)
}
