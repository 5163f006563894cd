//! Binding of the cross-sections and the linear material (the rest of the robot description
//! is in `model.rs`); every class keeps its constructor arguments for its properties and for
//! pickling.

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::callbacks::{run_attached, Callback};
use crate::convert::arg;
use crate::errors::{param_err, to_py_err, type_err};
use crate::model::{obj, Args};

// ----------------------------------------------------------------------------------- sections

/// A rod's cross-section along its length.
/// Properties in SI units: area (m^2), second moments and torsion constant (m^4), radius (m);
/// subclasses `CircularSection`, `TaperedCircularSection`, `TubeSection`, `TableSection`,
/// `FunctionSection`.
#[pyclass(frozen, module = "softrod._core", name = "Section", subclass)]
pub(crate) struct PySection {
    pub(crate) inner: softrod::Section,
    args: Args,
}

impl PySection {
    fn init(
        py: Python<'_>,
        inner: softrod::Section,
        items: &[(&str, Py<PyAny>)],
    ) -> PyResult<PyClassInitializer<Self>> {
        Ok(PyClassInitializer::from(Self {
            inner,
            args: Args::new(py, items)?,
        }))
    }
}

#[pymethods]
impl PySection {
    fn __repr__(&self) -> String {
        format!("{:?}", self.inner)
    }
    /// Section properties at arc length `s` (m) of a rod of `length` (m): dict of area (m^2),
    /// ix, iy, j (m^4), radius (m).
    ///
    /// Raises `ParameterError` naming `length` (finite, > 0), `s` (in `[0, length]`) or the
    /// property that is not finite and > 0 there.
    fn properties<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = arg::s)] s: f64,
        #[pyo3(from_py_with = arg::length)] length: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let section = &self.inner;
        let p = run_attached("Section.properties", || {
            softrod::limits::check_length("length", length, false)?;
            let s = softrod::math::samples::in_range(|| "s".into(), s, length)?;
            section
                .properties(s, length)
                .validated(&format!("section({s})"))
        })?;
        let d = PyDict::new(py);
        d.set_item("area", p.area)?;
        d.set_item("ix", p.ix)?;
        d.set_item("iy", p.iy)?;
        d.set_item("j", p.j)?;
        d.set_item("radius", p.radius)?;
        Ok(d)
    }
    /// The constructor arguments by name (what a writer needs to rebuild the section).
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.args.dict(py)
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        slf.get().args.reduce(slf.py(), slf.get_type().into_any())
    }
}

/// Solid circular section of constant radius (m).
///
/// `radius` (m) finite and > 0; area `pi r^2` (m^2), `Ix = Iy = pi r^4 / 4` (m^4).
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct CircularSection {
    radius: f64,
}

#[pymethods]
impl CircularSection {
    #[new]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::radius)] radius: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let inner = softrod::Section::circular(radius).map_err(to_py_err)?;
        let items = [("radius", obj(py, radius)?)];
        Ok(PySection::init(py, inner, &items)?.add_subclass(Self { radius }))
    }
    /// Radius (m).
    #[getter]
    fn radius(&self) -> f64 {
        self.radius
    }
}

/// Solid circular section tapering linearly from `base_radius` to `tip_radius` (m).
///
/// Radii (m) finite and > 0; the radius at arc length `s` is `R0 + (RL - R0) s / L` (m).
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct TaperedCircularSection {
    base_radius: f64,
    tip_radius: f64,
}

#[pymethods]
impl TaperedCircularSection {
    #[new]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::base_radius)] base_radius: f64,
        #[pyo3(from_py_with = arg::tip_radius)] tip_radius: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let inner =
            softrod::Section::tapered_circular(base_radius, tip_radius).map_err(to_py_err)?;
        let items = [
            ("base_radius", obj(py, base_radius)?),
            ("tip_radius", obj(py, tip_radius)?),
        ];
        Ok(PySection::init(py, inner, &items)?.add_subclass(Self {
            base_radius,
            tip_radius,
        }))
    }
    /// Radius at the base (m).
    #[getter]
    fn base_radius(&self) -> f64 {
        self.base_radius
    }
    /// Radius at the tip (m).
    #[getter]
    fn tip_radius(&self) -> f64 {
        self.tip_radius
    }
}

/// Circular tube with `outer_radius` and `inner_radius` (m).
///
/// `inner_radius` (m) in `[0, outer_radius)`; 0 is a solid circle.
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct TubeSection {
    outer_radius: f64,
    inner_radius: f64,
}

#[pymethods]
impl TubeSection {
    #[new]
    #[pyo3(signature = (outer_radius, inner_radius=0.0))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::outer_radius)] outer_radius: f64,
        #[pyo3(from_py_with = arg::inner_radius)] inner_radius: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let inner = softrod::Section::tube(outer_radius, inner_radius).map_err(to_py_err)?;
        let items = [
            ("outer_radius", obj(py, outer_radius)?),
            ("inner_radius", obj(py, inner_radius)?),
        ];
        Ok(PySection::init(py, inner, &items)?.add_subclass(Self {
            outer_radius,
            inner_radius,
        }))
    }
    /// Outer radius (m).
    #[getter]
    fn outer_radius(&self) -> f64 {
        self.outer_radius
    }
    /// Inner radius (m).
    #[getter]
    fn inner_radius(&self) -> f64 {
        self.inner_radius
    }
}

/// Section given by tables over arc length: `s` (m, increasing from 0 to the rod length),
/// `area` (m^2), `ix`, `iy`, `j` (m^4); linear interpolation between rows.
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct TableSection;

#[pymethods]
impl TableSection {
    #[new]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::s)] s: Vec<f64>,
        #[pyo3(from_py_with = arg::area)] area: Vec<f64>,
        #[pyo3(from_py_with = arg::ix)] ix: Vec<f64>,
        #[pyo3(from_py_with = arg::iy)] iy: Vec<f64>,
        #[pyo3(from_py_with = arg::j)] j: Vec<f64>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let inner = softrod::Section::table(&s, &area, &ix, &iy, &j).map_err(to_py_err)?;
        let items = [
            ("s", obj(py, s)?),
            ("area", obj(py, area)?),
            ("ix", obj(py, ix)?),
            ("iy", obj(py, iy)?),
            ("j", obj(py, j)?),
        ];
        Ok(PySection::init(py, inner, &items)?.add_subclass(Self))
    }
}

/// Section given by a function `s (m) -> (area, ix, iy, j)` (SI); slower than the built-ins.
///
/// The function returns area (m^2) and `ix`, `iy`, `j` (m^4) at arc length `s` (m); it pickles
/// when it is a module-level function.
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct FunctionSection;

#[pymethods]
impl FunctionSection {
    #[new]
    fn new(py: Python<'_>, function: Py<PyAny>) -> PyResult<PyClassInitializer<Self>> {
        if !function.bind(py).is_callable() {
            return Err(type_err("function", function.bind(py), "a function of s"));
        }
        let cb = Callback::new(function.clone_ref(py), "function", "the section function");
        let inner = softrod::Section::function(Arc::new(move |s| {
            let [area, ix, iy, j] = cb.floats::<4>(s);
            softrod::model::section::SectionProperties {
                area,
                ix,
                iy,
                j,
                radius: (area / std::f64::consts::PI).sqrt(),
                radius_rate: 0.0,
            }
        }));
        // Called once here at s = 0 (the rod's length is not known yet).
        run_attached("FunctionSection", || {
            inner.properties(0.0, 1.0).validated("function(0)")?;
            Ok(())
        })?;
        let items = [("function", function)];
        Ok(PySection::init(py, inner, &items)?.add_subclass(Self))
    }
}

// ----------------------------------------------------------------------------------- material

/// Linear elastic material: Young's modulus (Pa) and Poisson's ratio, or the shear modulus.
///
/// `youngs_modulus` (Pa) > 0; `poisson_ratio` (dimensionless) in (-1, 0.5], or `shear_modulus`
/// (Pa) instead.
#[pyclass(frozen, module = "softrod._core")]
#[derive(Clone)]
pub(crate) struct LinearElastic {
    pub(crate) inner: softrod::LinearElastic,
}

#[pymethods]
impl LinearElastic {
    #[new]
    #[pyo3(signature = (youngs_modulus, poisson_ratio=None, *, shear_modulus=None))]
    fn new(
        #[pyo3(from_py_with = arg::youngs_modulus)] youngs_modulus: f64,
        #[pyo3(from_py_with = arg::poisson_ratio)] poisson_ratio: Option<f64>,
        #[pyo3(from_py_with = arg::shear_modulus)] shear_modulus: Option<f64>,
    ) -> PyResult<Self> {
        let inner = match (poisson_ratio, shear_modulus) {
            (Some(nu), None) => softrod::LinearElastic::new(youngs_modulus, nu),
            (None, Some(g)) => softrod::LinearElastic::with_shear_modulus(youngs_modulus, g),
            (None, None) => {
                return Err(param_err(
                    "poisson_ratio",
                    "None",
                    "given (in (-1, 0.5]), or shear_modulus given instead",
                ))
            }
            (Some(_), Some(g)) => {
                return Err(param_err(
                    "shear_modulus",
                    g,
                    "None when poisson_ratio is given",
                ))
            }
        }
        .map_err(to_py_err)?;
        Ok(Self { inner })
    }
    #[getter]
    fn youngs_modulus(&self) -> f64 {
        self.inner.youngs_modulus()
    }
    #[getter]
    fn shear_modulus(&self) -> f64 {
        self.inner.shear_modulus()
    }
    #[getter]
    fn poisson_ratio(&self) -> f64 {
        self.inner.poisson_ratio()
    }
    fn __repr__(&self) -> String {
        format!(
            "LinearElastic(youngs_modulus={}, poisson_ratio={})",
            self.inner.youngs_modulus(),
            self.inner.poisson_ratio()
        )
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        // E and G are the stored values: rebuilding from them is exact.
        let py = slf.py();
        let m = &slf.get().inner;
        let args = Args::new(
            py,
            &[
                ("youngs_modulus", obj(py, m.youngs_modulus())?),
                ("shear_modulus", obj(py, m.shear_modulus())?),
            ],
        )?;
        args.reduce(py, slf.get_type().into_any())
    }
}

/// A rod material: `LinearElastic`, or a uniaxial hyperelastic law (`NeoHookean`,
/// `MooneyRivlin`, `Yeoh`, ...; incompressible fibre section, see `docs/pneumatic.md`).
pub(crate) fn material_of(arg: &Bound<'_, PyAny>) -> PyResult<softrod::Material> {
    if let Ok(m) = arg.cast::<LinearElastic>() {
        return Ok(m.get().inner.into());
    }
    if let Ok(l) = arg.cast::<crate::materials::PyUniaxialLaw>() {
        return Ok(l.get().inner.clone().into());
    }
    Err(type_err(
        "material",
        arg,
        "a LinearElastic or a UniaxialLaw (NeoHookean, MooneyRivlin, Yeoh, ...)",
    ))
}
