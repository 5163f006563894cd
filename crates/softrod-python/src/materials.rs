//! Binding of the uniaxial material laws, their least-squares fit and the silicone library.
//!
//! Every law is a subclass of the Python base class `UniaxialLaw`, which holds the core's
//! `UniaxialModel`; the subclasses keep a typed copy for their parameter getters. Evaluation is
//! vectorised here by calling the core's validated scalar methods element by element: any array
//! shape in, the same shape out, a 0-d input (a number) gives a float. A bad element raises
//! `ParameterError` naming the argument and its index, e.g. `stretch[2]`.

use numpy::ndarray::{ArrayD, Dimension};
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use softrod::model::material::fit::{
    FitOptions, ModelKind, StrainMeasure, StressMeasure, UniaxialData,
};
use softrod::{Error, UniaxialLaw as _, UniaxialModel};

use crate::convert::{arg, count, Floats, Values};
use crate::errors::{param_err, to_py_err};

/// Yeoh terms fitted when `terms` is not given.
const DEFAULT_YEOH_TERMS: usize = 3;
/// Ogden terms fitted when `terms` is not given.
const DEFAULT_OGDEN_TERMS: usize = 2;

/// Appends the element index to the parameter name of an `InvalidParameter` error.
fn at_index(e: Error, index: &[usize]) -> Error {
    match e {
        Error::InvalidParameter {
            name,
            value,
            expected,
        } => {
            let index: Vec<String> = index.iter().map(usize::to_string).collect();
            Error::InvalidParameter {
                name: format!("{name}[{}]", index.join(", ")),
                value,
                expected,
            }
        }
        other => other,
    }
}

/// Applies `f` to every element: a 0-d input gives a float, an array an array of its shape.
fn map_values(
    py: Python<'_>,
    values: &Values,
    f: impl Fn(f64) -> softrod::Result<f64>,
) -> PyResult<Py<PyAny>> {
    let view = values.0.view();
    if view.ndim() == 0 {
        let x = view.iter().next().copied().unwrap_or(f64::NAN);
        let y = f(x).map_err(to_py_err)?;
        return Ok(y.into_pyobject(py)?.into_any().unbind());
    }
    let mut out = Vec::with_capacity(view.len());
    for (index, &x) in view.indexed_iter() {
        out.push(f(x).map_err(|e| to_py_err(at_index(e, index.slice())))?);
    }
    let array = ArrayD::from_shape_vec(view.raw_dim(), out)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(array.into_pyarray(py).into_any().unbind())
}

/// The model's parameters by name (Pa; Ogden exponents dimensionless, as lists).
fn parameters<'py>(py: Python<'py>, model: &UniaxialModel) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match model {
        UniaxialModel::Hookean(l) => d.set_item("youngs_modulus", l.youngs_modulus())?,
        UniaxialModel::Linearised(l) => {
            d.set_item("secant_modulus", l.secant_modulus())?;
            d.set_item("reference_strain", l.reference_strain())?;
        }
        UniaxialModel::NeoHookean(l) => d.set_item("mu", l.mu())?,
        UniaxialModel::MooneyRivlin(l) => {
            d.set_item("c10", l.c10())?;
            d.set_item("c01", l.c01())?;
        }
        UniaxialModel::Yeoh(l) => {
            d.set_item("c10", l.c10())?;
            d.set_item("c20", l.c20())?;
            d.set_item("c30", l.c30())?;
        }
        UniaxialModel::Ogden(l) => {
            d.set_item("mu", l.mu().to_vec())?;
            d.set_item("alpha", l.alpha().to_vec())?;
        }
    }
    Ok(d)
}

/// A Python object of the subclass matching the law.
pub(crate) fn law_object(py: Python<'_>, model: UniaxialModel) -> PyResult<Py<PyAny>> {
    let base = |m: &UniaxialModel| PyClassInitializer::from(PyUniaxialLaw { inner: m.clone() });
    let obj = match &model {
        UniaxialModel::Hookean(l) => {
            Py::new(py, base(&model).add_subclass(Hookean { law: *l }))?.into_any()
        }
        UniaxialModel::Linearised(l) => {
            Py::new(py, base(&model).add_subclass(Linearised { law: *l }))?.into_any()
        }
        UniaxialModel::NeoHookean(l) => {
            Py::new(py, base(&model).add_subclass(NeoHookean { law: *l }))?.into_any()
        }
        UniaxialModel::MooneyRivlin(l) => {
            Py::new(py, base(&model).add_subclass(MooneyRivlin { law: *l }))?.into_any()
        }
        UniaxialModel::Yeoh(l) => {
            Py::new(py, base(&model).add_subclass(Yeoh { law: *l }))?.into_any()
        }
        UniaxialModel::Ogden(l) => {
            Py::new(py, base(&model).add_subclass(Ogden { law: l.clone() }))?.into_any()
        }
    };
    Ok(obj)
}

// ----------------------------------------------------------------------------------- laws

/// An incompressible uniaxial law: axial stress (Pa) as a function of the stretch
/// `λ = l / l0 = 1 + ε`. Base class of the material laws; not constructed directly.
#[pyclass(frozen, module = "softrod._core", name = "UniaxialLaw", subclass)]
pub(crate) struct PyUniaxialLaw {
    pub(crate) inner: UniaxialModel,
}

#[pymethods]
impl PyUniaxialLaw {
    /// Nominal (engineering) stress `P(λ)`, force per undeformed area (Pa); same shape as
    /// `stretch`.
    fn nominal_stress(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = arg::stretch)] stretch: Values,
    ) -> PyResult<Py<PyAny>> {
        map_values(py, &stretch, |x| self.inner.nominal_stress(x))
    }
    /// True (Cauchy) stress `σ(λ) = λ P(λ)`, force per deformed area (Pa).
    fn true_stress(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = arg::stretch)] stretch: Values,
    ) -> PyResult<Py<PyAny>> {
        map_values(py, &stretch, |x| self.inner.true_stress(x))
    }
    /// Tangent modulus `dσ/dε` at engineering strain `ε = λ − 1` (Pa).
    fn tangent_modulus(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = arg::strain)] strain: Values,
    ) -> PyResult<Py<PyAny>> {
        map_values(py, &strain, |x| self.inner.tangent_modulus(x))
    }
    /// Slope `dP/dλ` of the nominal stress (Pa).
    fn nominal_tangent(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = arg::stretch)] stretch: Values,
    ) -> PyResult<Py<PyAny>> {
        map_values(py, &stretch, |x| self.inner.nominal_tangent(x))
    }
    /// Stretch at which the nominal stress equals `nominal_stress` (Pa): the inverse of
    /// `nominal_stress`.
    fn stretch_from_nominal_stress(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = arg::nominal_stress)] nominal_stress: Values,
    ) -> PyResult<Py<PyAny>> {
        map_values(py, &nominal_stress, |x| {
            self.inner.stretch_from_nominal_stress(x)
        })
    }
    /// Raises `ParameterError` unless `dP/dλ > 0` on `[stretch_min, stretch_max]`.
    fn check_stable(
        &self,
        #[pyo3(from_py_with = arg::stretch_min)] stretch_min: f64,
        #[pyo3(from_py_with = arg::stretch_max)] stretch_max: f64,
    ) -> PyResult<()> {
        self.inner
            .check_stable(stretch_min, stretch_max)
            .map_err(to_py_err)
    }
    /// Young's modulus at zero strain, `dσ/dε` at `ε = 0` (Pa).
    #[getter]
    fn small_strain_modulus(&self) -> f64 {
        self.inner.small_strain_modulus()
    }
    /// Model name, e.g. `"Yeoh"`.
    #[getter]
    fn model_name(&self) -> &'static str {
        self.inner.model_name()
    }
    /// The parameters by name (Pa; Ogden `alpha` dimensionless).
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        parameters(py, &self.inner)
    }
    fn __repr__(&self) -> String {
        self.inner.to_string()
    }
    /// Pickles as the constructor of its class called with its parameters (exact).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let rebuild = py.import("softrod._core")?.getattr("_rebuild")?;
        let inner = PyTuple::new(
            py,
            [
                slf.get_type().into_any(),
                PyTuple::empty(py).into_any(),
                parameters(py, &slf.get().inner)?.into_any(),
            ],
        )?;
        PyTuple::new(py, [rebuild, inner.into_any()])
    }
}

/// Linear law `P = E (λ − 1)` with Young's modulus `youngs_modulus` (Pa).
///
/// The nominal stress `P` is in Pa, the stretch `λ` dimensionless.
#[pyclass(frozen, extends = PyUniaxialLaw, module = "softrod._core")]
pub(crate) struct Hookean {
    law: softrod::Hookean,
}

#[pymethods]
impl Hookean {
    #[new]
    fn new(
        #[pyo3(from_py_with = arg::youngs_modulus)] youngs_modulus: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let law = softrod::Hookean::new(youngs_modulus).map_err(to_py_err)?;
        Ok(
            PyClassInitializer::from(PyUniaxialLaw { inner: law.into() })
                .add_subclass(Self { law }),
        )
    }
    /// Young's modulus `E` (Pa).
    #[getter]
    fn youngs_modulus(&self) -> f64 {
        self.law.youngs_modulus()
    }
}

/// Linearised law `P = E_l (λ − 1)`: the secant modulus `secant_modulus` (Pa) of a curve at
/// engineering strain `reference_strain`.
#[pyclass(frozen, extends = PyUniaxialLaw, module = "softrod._core")]
pub(crate) struct Linearised {
    law: softrod::Linearised,
}

impl Linearised {
    fn init(law: softrod::Linearised) -> PyClassInitializer<Self> {
        PyClassInitializer::from(PyUniaxialLaw { inner: law.into() }).add_subclass(Self { law })
    }
}

#[pymethods]
impl Linearised {
    #[new]
    fn new(
        #[pyo3(from_py_with = arg::secant_modulus)] secant_modulus: f64,
        #[pyo3(from_py_with = arg::reference_strain)] reference_strain: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let law = softrod::Linearised::new(secant_modulus, reference_strain).map_err(to_py_err)?;
        Ok(Self::init(law))
    }
    /// From one datasheet point: nominal stress (Pa) at engineering strain `strain` (e.g. the
    /// "100 % modulus" at `strain = 1`).
    #[staticmethod]
    fn from_secant_point(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::nominal_stress)] nominal_stress: f64,
        #[pyo3(from_py_with = arg::strain)] strain: f64,
    ) -> PyResult<Py<Self>> {
        let law =
            softrod::Linearised::from_secant_point(nominal_stress, strain).map_err(to_py_err)?;
        Py::new(py, Self::init(law))
    }
    /// Secant modulus `E_l` (Pa).
    #[getter]
    fn secant_modulus(&self) -> f64 {
        self.law.secant_modulus()
    }
    /// Engineering strain at which the secant was taken.
    #[getter]
    fn reference_strain(&self) -> f64 {
        self.law.reference_strain()
    }
}

/// Incompressible Neo-Hookean law with initial shear modulus `mu` (Pa).
///
/// `W = mu/2 (I1 - 3)`; small-strain Young's modulus `3 mu` (Pa).
#[pyclass(frozen, extends = PyUniaxialLaw, module = "softrod._core")]
pub(crate) struct NeoHookean {
    law: softrod::NeoHookean,
}

#[pymethods]
impl NeoHookean {
    #[new]
    fn new(#[pyo3(from_py_with = arg::mu)] mu: f64) -> PyResult<PyClassInitializer<Self>> {
        let law = softrod::NeoHookean::new(mu).map_err(to_py_err)?;
        Ok(
            PyClassInitializer::from(PyUniaxialLaw { inner: law.into() })
                .add_subclass(Self { law }),
        )
    }
    /// Initial shear modulus `μ0` (Pa).
    #[getter]
    fn mu(&self) -> f64 {
        self.law.mu()
    }
}

/// Incompressible two-parameter Mooney–Rivlin law with `c10`, `c01` (Pa).
///
/// `W = c10 (I1 - 3) + c01 (I2 - 3)`; small-strain modulus `6 (c10 + c01)` (Pa).
#[pyclass(frozen, extends = PyUniaxialLaw, module = "softrod._core")]
pub(crate) struct MooneyRivlin {
    law: softrod::MooneyRivlin,
}

#[pymethods]
impl MooneyRivlin {
    #[new]
    fn new(
        #[pyo3(from_py_with = arg::c10)] c10: f64,
        #[pyo3(from_py_with = arg::c01)] c01: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let law = softrod::MooneyRivlin::new(c10, c01).map_err(to_py_err)?;
        Ok(
            PyClassInitializer::from(PyUniaxialLaw { inner: law.into() })
                .add_subclass(Self { law }),
        )
    }
    /// `C10` (Pa).
    #[getter]
    fn c10(&self) -> f64 {
        self.law.c10()
    }
    /// `C01` (Pa).
    #[getter]
    fn c01(&self) -> f64 {
        self.law.c01()
    }
}

/// Incompressible Yeoh law with `c10 > 0`, `c20`, `c30` (Pa).
///
/// `W = sum_i ci0 (I1 - 3)^i`; small-strain modulus `6 c10` (Pa).
#[pyclass(frozen, extends = PyUniaxialLaw, module = "softrod._core")]
pub(crate) struct Yeoh {
    law: softrod::Yeoh,
}

#[pymethods]
impl Yeoh {
    #[new]
    #[pyo3(signature = (c10, c20=0.0, c30=0.0))]
    fn new(
        #[pyo3(from_py_with = arg::c10)] c10: f64,
        #[pyo3(from_py_with = arg::c20)] c20: f64,
        #[pyo3(from_py_with = arg::c30)] c30: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let law = softrod::Yeoh::new(c10, c20, c30).map_err(to_py_err)?;
        Ok(
            PyClassInitializer::from(PyUniaxialLaw { inner: law.into() })
                .add_subclass(Self { law }),
        )
    }
    /// `C10` (Pa).
    #[getter]
    fn c10(&self) -> f64 {
        self.law.c10()
    }
    /// `C20` (Pa).
    #[getter]
    fn c20(&self) -> f64 {
        self.law.c20()
    }
    /// `C30` (Pa).
    #[getter]
    fn c30(&self) -> f64 {
        self.law.c30()
    }
}

/// Incompressible N-term Ogden law: moduli `mu` (Pa) and exponents `alpha`, shape (N,) each;
/// initial shear modulus `sum(mu)`.
#[pyclass(frozen, extends = PyUniaxialLaw, module = "softrod._core")]
pub(crate) struct Ogden {
    law: softrod::Ogden,
}

#[pymethods]
impl Ogden {
    #[new]
    fn new(
        #[pyo3(from_py_with = arg::mu)] mu: Floats,
        #[pyo3(from_py_with = arg::alpha)] alpha: Floats,
    ) -> PyResult<PyClassInitializer<Self>> {
        let (mu, alpha) = (mu.0, alpha.0);
        let law = softrod::Ogden::new(&mu, &alpha).map_err(to_py_err)?;
        Ok(PyClassInitializer::from(PyUniaxialLaw {
            inner: law.clone().into(),
        })
        .add_subclass(Self { law }))
    }
    /// Term moduli `μ_p` (Pa).
    #[getter]
    fn mu(&self) -> Vec<f64> {
        self.law.mu().to_vec()
    }
    /// Term exponents `α_p`.
    #[getter]
    fn alpha(&self) -> Vec<f64> {
        self.law.alpha().to_vec()
    }
}

// ----------------------------------------------------------------------------------- fitting

/// A law fitted to uniaxial data, with its error on the points it was fitted to (Pa, in the
/// data's stress measure).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct UniaxialFit {
    model: UniaxialModel,
    law: Py<PyAny>,
    /// Root-mean-square residual (Pa).
    #[pyo3(get)]
    rms: f64,
    /// Coefficient of determination.
    #[pyo3(get)]
    r_squared: f64,
    /// Largest absolute residual (Pa).
    #[pyo3(get)]
    max_abs_residual: f64,
    /// Number of points fitted.
    #[pyo3(get)]
    points: usize,
    /// Levenberg–Marquardt iterations (0 for the exact linear solves).
    #[pyo3(get)]
    iterations: usize,
    /// Stress measure of the data and residuals: "nominal" or "true".
    #[pyo3(get)]
    stress_measure: &'static str,
    /// Smallest and largest stretch of the points fitted.
    #[pyo3(get)]
    stretch_range: (f64, f64),
}

#[pymethods]
impl UniaxialFit {
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = slf.get();
        let func = py.import("softrod._core")?.getattr("_uniaxial_fit")?;
        let args = (
            f.law.clone_ref(py),
            f.rms,
            f.r_squared,
            f.max_abs_residual,
            f.points,
            f.iterations,
            f.stress_measure,
            f.stretch_range,
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [func, args.into_any()])
    }
    /// The fitted law (a `UniaxialLaw` subclass: `NeoHookean`, `Yeoh`, ...).
    #[getter]
    fn model(&self, py: Python<'_>) -> Py<PyAny> {
        self.law.clone_ref(py)
    }
    /// The fitted parameters by name (Pa; Ogden `alpha` dimensionless).
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        parameters(py, &self.model)
    }
    fn __repr__(&self) -> String {
        format!(
            "UniaxialFit({}, points={}, rms={:.4e} Pa, r_squared={:.6}, max_abs_residual={:.4e} Pa)",
            self.model, self.points, self.rms, self.r_squared, self.max_abs_residual
        )
    }
}

fn model_kind(model: &str, terms: Option<i64>) -> PyResult<ModelKind> {
    let key: String = model
        .chars()
        .filter(char::is_ascii_alphanumeric)
        .map(|c| c.to_ascii_lowercase())
        .collect();
    let counted = |default: usize| -> PyResult<usize> {
        match terms {
            None => Ok(default),
            Some(t) if t >= 1 => Ok(t as usize),
            Some(t) => Err(param_err("terms", t, ">= 1")),
        }
    };
    let fixed = |kind: ModelKind| -> PyResult<ModelKind> {
        match terms {
            None => Ok(kind),
            Some(t) => Err(param_err(
                "terms",
                t,
                &format!("None for the {model} model (its parameters are fixed)"),
            )),
        }
    };
    match key.as_str() {
        "neohookean" => fixed(ModelKind::NeoHookean),
        "mooneyrivlin" => fixed(ModelKind::MooneyRivlin),
        "linearised" | "linearized" => fixed(ModelKind::Linearised),
        "yeoh" => Ok(ModelKind::Yeoh {
            terms: counted(DEFAULT_YEOH_TERMS)?,
        }),
        "ogden" => Ok(ModelKind::Ogden {
            terms: counted(DEFAULT_OGDEN_TERMS)?,
        }),
        _ => Err(param_err(
            "model",
            model,
            "\"neo-hookean\", \"mooney-rivlin\", \"yeoh\", \"ogden\" or \"linearised\"",
        )),
    }
}

fn parse_strain_measure(name: &str) -> PyResult<StrainMeasure> {
    match name {
        "engineering" => Ok(StrainMeasure::Engineering),
        "stretch" => Ok(StrainMeasure::Stretch),
        "logarithmic" => Ok(StrainMeasure::Logarithmic),
        other => Err(param_err(
            "strain_measure",
            other,
            "\"engineering\", \"stretch\" or \"logarithmic\"",
        )),
    }
}

fn parse_stress_measure(name: &str) -> PyResult<(StressMeasure, &'static str)> {
    match name {
        "nominal" | "engineering" => Ok((StressMeasure::Nominal, "nominal")),
        "true" => Ok((StressMeasure::True, "true")),
        other => Err(param_err(
            "stress_measure",
            other,
            "\"nominal\" (or \"engineering\") or \"true\"",
        )),
    }
}

/// Fits a law to uniaxial test data by least squares (see the docs).
///
/// `strain` (dimensionless) and `stress` (Pa) arrays; returns a `UniaxialFit` with the law and
/// its errors (Pa).
#[pyfunction]
#[pyo3(signature = (strain, stress, model="neo-hookean", *, strain_measure="engineering",
                    stress_measure="nominal", terms=None, nonnegative=false, stretch_range=None,
                    max_iterations=None, tolerance=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_uniaxial(
    py: Python<'_>,
    #[pyo3(from_py_with = arg::strain)] strain: Vec<f64>,
    #[pyo3(from_py_with = arg::stress)] stress: Vec<f64>,
    #[pyo3(from_py_with = arg::model)] model: &str,
    #[pyo3(from_py_with = arg::strain_measure)] strain_measure: &str,
    #[pyo3(from_py_with = arg::stress_measure)] stress_measure: &str,
    #[pyo3(from_py_with = arg::terms)] terms: Option<i64>,
    #[pyo3(from_py_with = arg::nonnegative)] nonnegative: bool,
    #[pyo3(from_py_with = arg::stretch_range)] stretch_range: Option<(f64, f64)>,
    #[pyo3(from_py_with = arg::max_iterations)] max_iterations: Option<i64>,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: Option<f64>,
) -> PyResult<UniaxialFit> {
    let kind = model_kind(model, terms)?;
    let strain_m = parse_strain_measure(strain_measure)?;
    let (stress_m, stress_name) = parse_stress_measure(stress_measure)?;
    let defaults = FitOptions::default();
    let max_iterations = max_iterations.map_or(Ok(defaults.max_iterations), |n| {
        count("max_iterations", n, 1, softrod::limits::MAX_ITERATIONS)
    })?;
    let options = FitOptions {
        nonnegative,
        max_iterations,
        tolerance: tolerance.unwrap_or(defaults.tolerance),
    };

    let mut data = UniaxialData::new(&strain, strain_m, &stress, stress_m).map_err(to_py_err)?;
    if let Some((lo, hi)) = stretch_range {
        data = data.within(lo, hi).map_err(|e| match e {
            // The range is one argument here: say so.
            Error::InvalidParameter {
                name,
                value,
                expected,
            } => to_py_err(Error::InvalidParameter {
                name,
                value,
                expected: format!("{expected} (stretch_range = (stretch_min, stretch_max))"),
            }),
            other => to_py_err(other),
        })?;
    }
    let range = (data.stretch_min(), data.stretch_max());
    let fit = py
        .detach(move || softrod::fit_uniaxial(&data, kind, &options))
        .map_err(|e| match e {
            // The options are keyword arguments here: `tolerance`, not `options.tolerance`.
            Error::InvalidParameter {
                name,
                value,
                expected,
            } => to_py_err(Error::InvalidParameter {
                name: name.trim_start_matches("options.").to_string(),
                value,
                expected,
            }),
            other => to_py_err(other),
        })?;
    Ok(UniaxialFit {
        law: law_object(py, fit.model.clone())?,
        model: fit.model,
        rms: fit.stats.rms,
        r_squared: fit.stats.r_squared,
        max_abs_residual: fit.stats.max_abs_residual,
        points: fit.stats.points,
        iterations: fit.iterations,
        stress_measure: stress_name,
        stretch_range: range,
    })
}

/// A fit from its parts (the pickled form of `UniaxialFit`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _uniaxial_fit(
    law: &Bound<'_, PyUniaxialLaw>,
    #[pyo3(from_py_with = arg::rms)] rms: f64,
    #[pyo3(from_py_with = arg::r_squared)] r_squared: f64,
    #[pyo3(from_py_with = arg::max_abs_residual)] max_abs_residual: f64,
    #[pyo3(from_py_with = arg::points)] points: usize,
    #[pyo3(from_py_with = arg::iterations)] iterations: usize,
    #[pyo3(from_py_with = arg::stress_measure)] stress_measure: &str,
    #[pyo3(from_py_with = arg::stretch_range)] stretch_range: (f64, f64),
) -> PyResult<UniaxialFit> {
    let stress_measure = match stress_measure {
        "nominal" => "nominal",
        "true" => "true",
        other => {
            return Err(param_err(
                "stress_measure",
                other,
                "\"nominal\" or \"true\"",
            ))
        }
    };
    Ok(UniaxialFit {
        model: law.get().inner.clone(),
        law: law.clone().into_any().unbind(),
        rms,
        r_squared,
        max_abs_residual,
        points,
        iterations,
        stress_measure,
        stretch_range,
    })
}

// ----------------------------------------------------------------------------------- library

/// A named silicone of the library, with sourced parameters (see `softrod.silicone`).
///
/// Its laws are in Pa (Neo-Hookean, Mooney–Rivlin, Yeoh), with the source of the parameters.
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct Silicone {
    inner: softrod::Silicone,
}

#[pymethods]
impl Silicone {
    /// Display name, e.g. "Dragon Skin 10".
    #[getter]
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    /// Neo-Hookean law.
    #[getter]
    fn neo_hookean(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        law_object(py, self.inner.neo_hookean().into())
    }
    /// Two-parameter Mooney–Rivlin law, or None where none is sourced.
    #[getter]
    fn mooney_rivlin(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        self.inner
            .mooney_rivlin()
            .map(|l| law_object(py, l.into()))
            .transpose()
    }
    /// Yeoh law.
    #[getter]
    fn yeoh(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        law_object(py, self.inner.yeoh().into())
    }
    /// Stretch range (min, max) of the data the parameters were fitted to, or None.
    #[getter]
    fn fit_stretch_range(&self) -> Option<(f64, f64)> {
        self.inner.fit_stretch_range()
    }
    /// Where the parameters come from.
    #[getter]
    fn source(&self) -> &'static str {
        self.inner.source()
    }
    fn __repr__(&self) -> String {
        format!("Silicone({:?})", self.inner.name())
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = py.import("softrod._core")?.getattr("silicone")?;
        let args = PyTuple::new(py, [slf.get().inner.name()])?;
        PyTuple::new(py, [f, args.into_any()])
    }
}

/// The silicone named `name` (case, spaces, `-` and `_` ignored), e.g. "Dragon Skin 10".
///
/// Raises `ParameterError` naming `name` for an unknown silicone; the laws are in Pa.
#[pyfunction]
pub(crate) fn silicone(#[pyo3(from_py_with = arg::name)] name: &str) -> PyResult<Silicone> {
    let inner = softrod::Silicone::from_name(name).map_err(to_py_err)?;
    Ok(Silicone { inner })
}

/// Names of the library's silicones, as a tuple (the value of `SILICONES`).
pub(crate) fn silicone_names(py: Python<'_>) -> PyResult<Bound<'_, PyTuple>> {
    PyTuple::new(py, softrod::Silicone::ALL.iter().map(|s| s.name()))
}
