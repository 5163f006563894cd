//! Binding of the Cosserat-rod statics engine: sections, materials, rods, tendons, loads and
//! `solve_statics`.
//!
//! Python callables (rest strains, tendon offsets, section functions, distributed loads) are
//! called from the solver with the GIL re-acquired; an exception they raise is kept and
//! re-raised once the solve returns.

use std::sync::{Arc, Mutex};

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyDict;

use softrod::nalgebra::{Matrix3, Vector3};
use softrod::AdaptiveOptions;

use crate::errors::{param_err, to_py_err};

/// Where an exception raised by a Python callable waits until the solve returns.
#[derive(Clone, Default)]
pub(crate) struct ErrorSlot(Arc<Mutex<Option<PyErr>>>);

impl ErrorSlot {
    fn keep(&self, err: PyErr) {
        if let Ok(mut slot) = self.0.lock() {
            if slot.is_none() {
                *slot = Some(err);
            }
        }
    }
    fn take(&self) -> Option<PyErr> {
        self.0.lock().ok().and_then(|mut s| s.take())
    }
}

/// Calls `f(s)` and extracts `T`; on failure keeps the error and returns `fallback`.
fn call_py<T: for<'a, 'py> FromPyObjectOwned<'py>>(
    f: &Py<PyAny>,
    slot: &ErrorSlot,
    s: f64,
    what: &'static str,
    fallback: T,
) -> T {
    Python::attach(|py| {
        match f
            .call1(py, (s,))
            .and_then(|r| r.extract::<T>(py).map_err(Into::into))
        {
            Ok(v) => v,
            Err(e) => {
                let msg = format!("{what} raised or returned a bad value at s = {s}: {e}");
                slot.keep(pyo3::exceptions::PyValueError::new_err(msg));
                fallback
            }
        }
    })
}

/// A 3-vector argument: constant or a Python function of `s`.
#[derive(FromPyObject)]
pub(crate) enum VectorArg {
    Constant([f64; 3]),
    Function(Py<PyAny>),
}

fn profile(arg: VectorArg, slot: &ErrorSlot, what: &'static str) -> PyResult<softrod::Profile> {
    match arg {
        VectorArg::Constant(v) => Ok(softrod::Profile::Constant(Vector3::from(v))),
        VectorArg::Function(f) => {
            Python::attach(|py| {
                if !f.bind(py).is_callable() {
                    return Err(param_err(what, "<object>", "a 3-vector or a function of s"));
                }
                Ok(())
            })?;
            let slot = slot.clone();
            Ok(softrod::Profile::Function(Arc::new(move |s| {
                Vector3::from(call_py::<[f64; 3]>(&f, &slot, s, what, [f64::NAN; 3]))
            })))
        }
    }
}

fn frame_from(name: &str, frame: &str) -> PyResult<softrod::model::loads::Frame> {
    match frame {
        "world" => Ok(softrod::model::loads::Frame::World),
        "body" => Ok(softrod::model::loads::Frame::Body),
        other => Err(param_err(name, other, "\"world\" or \"body\"")),
    }
}

// ----------------------------------------------------------------------------------- sections

/// A rod's cross-section along its length.
#[pyclass(frozen, module = "softrod._core", name = "Section", subclass)]
#[derive(Clone)]
pub(crate) struct PySection {
    inner: softrod::Section,
    slot: ErrorSlot,
}

#[pymethods]
impl PySection {
    fn __repr__(&self) -> String {
        format!("{:?}", self.inner)
    }
    /// Section properties at arc length `s` (m) of a rod of `length` (m): dict of area (m^2),
    /// ix, iy, j (m^4), radius (m).
    fn properties<'py>(
        &self,
        py: Python<'py>,
        s: f64,
        length: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let p = self.inner.properties(s, length);
        let d = PyDict::new(py);
        d.set_item("area", p.area)?;
        d.set_item("ix", p.ix)?;
        d.set_item("iy", p.iy)?;
        d.set_item("j", p.j)?;
        d.set_item("radius", p.radius)?;
        Ok(d)
    }
}

/// Solid circular section of constant radius (m).
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct CircularSection;

#[pymethods]
impl CircularSection {
    #[new]
    fn new(radius: f64) -> PyResult<PyClassInitializer<Self>> {
        let inner = softrod::Section::circular(radius).map_err(to_py_err)?;
        Ok(PyClassInitializer::from(PySection {
            inner,
            slot: ErrorSlot::default(),
        })
        .add_subclass(Self))
    }
}

/// Solid circular section tapering linearly from `base_radius` to `tip_radius` (m).
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct TaperedCircularSection;

#[pymethods]
impl TaperedCircularSection {
    #[new]
    fn new(base_radius: f64, tip_radius: f64) -> PyResult<PyClassInitializer<Self>> {
        let inner =
            softrod::Section::tapered_circular(base_radius, tip_radius).map_err(to_py_err)?;
        Ok(PyClassInitializer::from(PySection {
            inner,
            slot: ErrorSlot::default(),
        })
        .add_subclass(Self))
    }
}

/// Circular tube with `outer_radius` and `inner_radius` (m).
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct TubeSection;

#[pymethods]
impl TubeSection {
    #[new]
    #[pyo3(signature = (outer_radius, inner_radius=0.0))]
    fn new(outer_radius: f64, inner_radius: f64) -> PyResult<PyClassInitializer<Self>> {
        let inner = softrod::Section::tube(outer_radius, inner_radius).map_err(to_py_err)?;
        Ok(PyClassInitializer::from(PySection {
            inner,
            slot: ErrorSlot::default(),
        })
        .add_subclass(Self))
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
        s: Vec<f64>,
        area: Vec<f64>,
        ix: Vec<f64>,
        iy: Vec<f64>,
        j: Vec<f64>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let inner = softrod::Section::table(&s, &area, &ix, &iy, &j).map_err(to_py_err)?;
        Ok(PyClassInitializer::from(PySection {
            inner,
            slot: ErrorSlot::default(),
        })
        .add_subclass(Self))
    }
}

/// Section given by a function `s (m) -> (area, ix, iy, j)` (SI); slower than the built-ins.
#[pyclass(frozen, extends = PySection, module = "softrod._core")]
pub(crate) struct FunctionSection;

#[pymethods]
impl FunctionSection {
    #[new]
    fn new(function: Py<PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let slot = ErrorSlot::default();
        let s2 = slot.clone();
        let inner = softrod::Section::function(Arc::new(move |s| {
            let [area, ix, iy, j] =
                call_py::<[f64; 4]>(&function, &s2, s, "section function", [f64::NAN; 4]);
            softrod::model::section::SectionProperties {
                area,
                ix,
                iy,
                j,
                radius: (area / std::f64::consts::PI).sqrt(),
                radius_rate: 0.0,
            }
        }));
        Ok(PyClassInitializer::from(PySection { inner, slot }).add_subclass(Self))
    }
}

// ----------------------------------------------------------------------------------- material

/// Linear elastic material: Young's modulus (Pa) and Poisson's ratio, or the shear modulus.
#[pyclass(frozen, module = "softrod._core")]
#[derive(Clone)]
pub(crate) struct LinearElastic {
    inner: softrod::LinearElastic,
}

#[pymethods]
impl LinearElastic {
    #[new]
    #[pyo3(signature = (youngs_modulus, poisson_ratio=None, *, shear_modulus=None))]
    fn new(
        youngs_modulus: f64,
        poisson_ratio: Option<f64>,
        shear_modulus: Option<f64>,
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
}

/// A rod material: `LinearElastic`, or a uniaxial hyperelastic law (`NeoHookean`,
/// `MooneyRivlin`, `Yeoh`, ...; incompressible fibre section, see `docs/pneumatic.md`).
#[derive(FromPyObject)]
pub(crate) enum MaterialArg<'py> {
    Linear(PyRef<'py, LinearElastic>),
    Law(PyRef<'py, crate::materials::PyUniaxialLaw>),
}

impl MaterialArg<'_> {
    fn material(&self) -> softrod::Material {
        match self {
            MaterialArg::Linear(m) => m.inner.into(),
            MaterialArg::Law(l) => l.inner.clone().into(),
        }
    }
}

// ----------------------------------------------------------------------------------- rod

/// A base pose: a 4x4 homogeneous transform, or `(position, rotation)`.
#[derive(FromPyObject)]
pub(crate) enum PoseArg {
    Homogeneous([[f64; 4]; 4]),
    Pair(([f64; 3], [[f64; 3]; 3])),
}

/// A Cosserat rod (immutable): length (m), section, material, rest strains, density, base pose.
#[pyclass(frozen, module = "softrod._core")]
#[derive(Clone)]
pub(crate) struct Rod {
    pub(crate) inner: softrod::Rod,
    slots: Vec<ErrorSlot>,
}

#[pymethods]
impl Rod {
    #[new]
    #[pyo3(signature = (length, section, material, rest_strain=None, rest_curvature=None,
                        inextensible=false, density=None, base_pose=None, *, shear_coefficient=None))]
    fn new(
        length: f64,
        section: PyRef<'_, PySection>,
        material: MaterialArg<'_>,
        rest_strain: Option<VectorArg>,
        rest_curvature: Option<VectorArg>,
        inextensible: bool,
        density: Option<f64>,
        base_pose: Option<PoseArg>,
        shear_coefficient: Option<f64>,
    ) -> PyResult<Self> {
        let slot = ErrorSlot::default();
        let mut rod = softrod::Rod::new(length, section.inner.clone(), material.material())
            .map_err(to_py_err)?;
        if let Some(v) = rest_strain {
            rod = rod
                .with_rest_strain(profile(v, &slot, "rest_strain")?)
                .map_err(to_py_err)?;
        }
        if let Some(u) = rest_curvature {
            rod = rod
                .with_rest_curvature(profile(u, &slot, "rest_curvature")?)
                .map_err(to_py_err)?;
        }
        rod = rod.with_inextensible(inextensible);
        if let Some(rho) = density {
            rod = rod.with_density(rho).map_err(to_py_err)?;
        }
        if let Some(k) = shear_coefficient {
            rod = rod.with_shear_coefficient(k).map_err(to_py_err)?;
        }
        if let Some(pose) = base_pose {
            let (p, r) = match pose {
                PoseArg::Homogeneous(t) => {
                    if t[3] != [0.0, 0.0, 0.0, 1.0] {
                        return Err(param_err(
                            "base_pose[3]",
                            format!("{:?}", t[3]),
                            "[0, 0, 0, 1] (a homogeneous transform)",
                        ));
                    }
                    (
                        [t[0][3], t[1][3], t[2][3]],
                        [
                            [t[0][0], t[0][1], t[0][2]],
                            [t[1][0], t[1][1], t[1][2]],
                            [t[2][0], t[2][1], t[2][2]],
                        ],
                    )
                }
                PoseArg::Pair(pr) => pr,
            };
            let rot = Matrix3::from_fn(|i, j| r[i][j]);
            let pose = softrod::Pose::new(Vector3::from(p), rot).map_err(to_py_err)?;
            rod = rod.with_base_pose(pose);
        }
        let slots = vec![slot, section.slot.clone()];
        Ok(Self { inner: rod, slots })
    }

    #[getter]
    fn length(&self) -> f64 {
        self.inner.length()
    }
    #[getter]
    fn inextensible(&self) -> bool {
        self.inner.inextensible()
    }
    #[getter]
    fn density(&self) -> Option<f64> {
        self.inner.density()
    }
    #[getter]
    fn shear_coefficient(&self) -> f64 {
        self.inner.shear_coefficient()
    }
    /// Base pose as a 4x4 homogeneous transform (body at s = 0 to world).
    #[getter]
    fn base_pose<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let pose = self.inner.base_pose();
        let (p, r) = (pose.position(), pose.rotation());
        let t = Array::from_shape_fn((4, 4), |(i, j)| match (i, j) {
            (3, 3) => 1.0,
            (3, _) => 0.0,
            (_, 3) => p[i],
            _ => r[(i, j)],
        });
        Ok(t.into_pyarray(py))
    }
    fn __repr__(&self) -> String {
        format!(
            "Rod(length={}, section={:?}, inextensible={})",
            self.inner.length(),
            self.inner.section(),
            self.inner.inextensible()
        )
    }
}

// ----------------------------------------------------------------------------------- tendons

#[derive(FromPyObject)]
pub(crate) enum OffsetArg {
    Pair([f64; 2]),
    Function(Py<PyAny>),
}

/// A tendon: body-frame offset (m) — an (x, y) pair or a function of s — tension (N), and the
/// arc length (m) where it ends (default: the tip).
#[pyclass(frozen, module = "softrod._core")]
#[derive(Clone)]
pub(crate) struct Tendon {
    pub(crate) inner: softrod::Tendon,
    slot: ErrorSlot,
}

fn offset_fn(f: Py<PyAny>, slot: &ErrorSlot, what: &'static str) -> softrod::model::tendon::OffsetFn {
    let slot = slot.clone();
    Arc::new(move |s| call_py::<[f64; 2]>(&f, &slot, s, what, [f64::NAN; 2]))
}

#[pymethods]
impl Tendon {
    /// `offset`: `(x, y)` (m, body frame) or a function `s -> (x, y)`; `derivative`: the
    /// function's exact derivative `s -> (dx/ds, dy/ds)` (required with a function offset).
    #[new]
    #[pyo3(signature = (offset, tension, end=None, *, derivative=None))]
    fn new(
        offset: OffsetArg,
        tension: f64,
        end: Option<f64>,
        derivative: Option<Py<PyAny>>,
    ) -> PyResult<Self> {
        let slot = ErrorSlot::default();
        let routing = match (offset, derivative) {
            (OffsetArg::Pair(xy), None) => softrod::Routing::Constant(xy),
            (OffsetArg::Pair(_), Some(_)) => {
                return Err(param_err(
                    "derivative",
                    "<function>",
                    "None for a constant offset",
                ))
            }
            (OffsetArg::Function(f), Some(df)) => softrod::Routing::Function {
                offset: offset_fn(f, &slot, "tendon offset"),
                derivative: offset_fn(df, &slot, "tendon offset derivative"),
            },
            (OffsetArg::Function(_), None) => {
                return Err(param_err(
                    "derivative",
                    "None",
                    "the exact derivative s -> (dx/ds, dy/ds) of a function offset",
                ))
            }
        };
        let inner = softrod::Tendon::new(routing, tension, end).map_err(to_py_err)?;
        Ok(Self { inner, slot })
    }

    /// Tendon at `ratio` times the local section radius, at `angle` (rad) from body x
    /// (seed 000's cable: `ratio = a`, `angle = 0`).
    #[staticmethod]
    #[pyo3(signature = (ratio, angle, tension, end=None))]
    fn radius_proportional(
        ratio: f64,
        angle: f64,
        tension: f64,
        end: Option<f64>,
    ) -> PyResult<Self> {
        let inner = softrod::Tendon::new(
            softrod::Routing::RadiusProportional { ratio, angle },
            tension,
            end,
        )
        .map_err(to_py_err)?;
        Ok(Self {
            inner,
            slot: ErrorSlot::default(),
        })
    }

    /// Helical tendon of `radius` (m) and signed `pitch` (m per turn; > 0 right-handed),
    /// starting at `phase` (rad) from body x.
    #[staticmethod]
    #[pyo3(signature = (radius, pitch, tension, phase=0.0, end=None))]
    fn helical(
        radius: f64,
        pitch: f64,
        tension: f64,
        phase: f64,
        end: Option<f64>,
    ) -> PyResult<Self> {
        let inner = softrod::Tendon::new(
            softrod::Routing::Helical {
                radius,
                pitch,
                phase,
            },
            tension,
            end,
        )
        .map_err(to_py_err)?;
        Ok(Self {
            inner,
            slot: ErrorSlot::default(),
        })
    }

    /// The same tendon with another tension (N).
    fn with_tension(&self, tension: f64) -> PyResult<Self> {
        let inner = self.inner.with_tension(tension).map_err(to_py_err)?;
        Ok(Self {
            inner,
            slot: self.slot.clone(),
        })
    }
    #[getter]
    fn tension(&self) -> f64 {
        self.inner.tension()
    }
    #[getter]
    fn end(&self) -> Option<f64> {
        self.inner.end()
    }
    fn __repr__(&self) -> String {
        format!(
            "Tendon({:?}, tension={}, end={:?})",
            self.inner.routing(),
            self.inner.tension(),
            self.inner.end()
        )
    }
}

// ----------------------------------------------------------------------------------- chambers

/// A chamber area argument: a constant (m^2) or a function of s.
#[derive(FromPyObject)]
pub(crate) enum AreaArg {
    Constant(f64),
    Function(Py<PyAny>),
}

/// A pneumatic chamber: gauge pressure (Pa), cross-section area (m^2, constant or a function
/// of s), centroid offset (x, y) (m, body frame) and extent [start, end] (m; end None: the
/// tip).
#[pyclass(frozen, module = "softrod._core")]
#[derive(Clone)]
pub(crate) struct Chamber {
    pub(crate) inner: softrod::Chamber,
    slot: ErrorSlot,
}

#[pymethods]
impl Chamber {
    #[new]
    #[pyo3(signature = (pressure, area, offset, start=0.0, end=None))]
    fn new(
        pressure: f64,
        area: AreaArg,
        offset: [f64; 2],
        start: f64,
        end: Option<f64>,
    ) -> PyResult<Self> {
        let slot = ErrorSlot::default();
        let area = match area {
            AreaArg::Constant(a) => softrod::ChamberArea::Constant(a),
            AreaArg::Function(f) => {
                Python::attach(|py| {
                    if !f.bind(py).is_callable() {
                        return Err(param_err("area", "<object>", "a number or a function of s"));
                    }
                    Ok(())
                })?;
                let slot = slot.clone();
                softrod::ChamberArea::Function(Arc::new(move |s| {
                    call_py::<f64>(&f, &slot, s, "chamber area", f64::NAN)
                }))
            }
        };
        let inner = softrod::Chamber::new(pressure, area, offset, start, end).map_err(to_py_err)?;
        Ok(Self { inner, slot })
    }

    /// The same chamber at another gauge pressure (Pa).
    fn with_pressure(&self, pressure: f64) -> PyResult<Self> {
        let inner = self.inner.with_pressure(pressure).map_err(to_py_err)?;
        Ok(Self {
            inner,
            slot: self.slot.clone(),
        })
    }
    /// Gauge pressure (Pa).
    #[getter]
    fn pressure(&self) -> f64 {
        self.inner.pressure()
    }
    /// Cross-section area at arc length `s` (m^2).
    fn area_at(&self, s: f64) -> f64 {
        self.inner.area_at(s)
    }
    /// Centroid offset (x, y) (m, body frame).
    #[getter]
    fn offset(&self) -> (f64, f64) {
        let [x, y] = self.inner.offset();
        (x, y)
    }
    /// Start of the chamber (m).
    #[getter]
    fn start(&self) -> f64 {
        self.inner.start()
    }
    /// End of the chamber (m), None for the tip.
    #[getter]
    fn end(&self) -> Option<f64> {
        self.inner.end()
    }
    fn __repr__(&self) -> String {
        let [x, y] = self.inner.offset();
        format!(
            "Chamber(pressure={}, area={:?}, offset=({x}, {y}), start={}, end={:?})",
            self.inner.pressure(),
            self.inner.area(),
            self.inner.start(),
            self.inner.end()
        )
    }
}

// ----------------------------------------------------------------------------------- loads

/// A force (N) and moment (N m) applied at arc length `s` (m), in the world or body frame.
#[pyclass(frozen, module = "softrod._core")]
#[derive(Clone)]
pub(crate) struct PointLoad {
    inner: softrod::PointLoad,
}

#[pymethods]
impl PointLoad {
    #[new]
    #[pyo3(signature = (s, force=[0.0; 3], moment=[0.0; 3], frame="world"))]
    fn new(s: f64, force: [f64; 3], moment: [f64; 3], frame: &str) -> PyResult<Self> {
        Ok(Self {
            inner: softrod::PointLoad {
                s,
                force: Vector3::from(force),
                moment: Vector3::from(moment),
                frame: frame_from("frame", frame)?,
            },
        })
    }
    fn __repr__(&self) -> String {
        format!("{:?}", self.inner)
    }
}

/// External loads: tip force (N) and moment (N m) in `tip_frame`; point loads; distributed
/// force (N/m) and moment (N m/m), constant or functions of s (world frame); gravity (m/s^2,
/// world frame, needs the rod's density).
#[pyclass(frozen, module = "softrod._core")]
#[derive(Clone)]
pub(crate) struct Loads {
    pub(crate) inner: softrod::Loads,
    slot: ErrorSlot,
}

#[pymethods]
impl Loads {
    #[new]
    #[pyo3(signature = (tip_force=None, tip_moment=None, gravity=None, *, tip_frame="world",
                        point_loads=Vec::new(), distributed_force=None, distributed_moment=None))]
    fn new(
        tip_force: Option<[f64; 3]>,
        tip_moment: Option<[f64; 3]>,
        gravity: Option<[f64; 3]>,
        tip_frame: &str,
        point_loads: Vec<PyRef<'_, PointLoad>>,
        distributed_force: Option<VectorArg>,
        distributed_moment: Option<VectorArg>,
    ) -> PyResult<Self> {
        let slot = ErrorSlot::default();
        let inner = softrod::Loads {
            tip_force: Vector3::from(tip_force.unwrap_or([0.0; 3])),
            tip_moment: Vector3::from(tip_moment.unwrap_or([0.0; 3])),
            tip_frame: frame_from("tip_frame", tip_frame)?,
            point_loads: point_loads.iter().map(|p| p.inner).collect(),
            distributed_force: distributed_force
                .map(|f| profile(f, &slot, "distributed_force"))
                .transpose()?,
            distributed_moment: distributed_moment
                .map(|f| profile(f, &slot, "distributed_moment"))
                .transpose()?,
            gravity: Vector3::from(gravity.unwrap_or([0.0; 3])),
            chambers: Vec::new(),
        };
        Ok(Self { inner, slot })
    }
    fn __repr__(&self) -> String {
        format!("{:?}", self.inner)
    }
}

// ----------------------------------------------------------------------------------- solution

/// A solved rod, sampled at the integration mesh (SI units, world frame unless `_body`).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct StaticsSolution {
    pub(crate) inner: softrod::StaticsSolution,
    cache: [PyOnceLock<Py<PyAny>>; 12],
    /// The problem it solves (rod, tendons, loads, options), for `softrod.compliance`.
    pub(crate) problem: Option<Arc<Problem>>,
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
    /// Solver statistics: iterations, residual, function_evaluations, load_steps, converged.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let st = &self.inner.stats;
        let d = PyDict::new(py);
        d.set_item("iterations", st.iterations)?;
        d.set_item("residual", st.residual)?;
        d.set_item("function_evaluations", st.function_evaluations)?;
        d.set_item("load_steps", st.load_steps)?;
        d.set_item("converged", st.converged)?;
        Ok(d)
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
}

/// A warm start: a previous solution or a base wrench `[force; moment]` (6 values).
#[derive(FromPyObject)]
pub(crate) enum WarmArg<'py> {
    Solution(PyRef<'py, StaticsSolution>),
    Wrench([f64; 6]),
}

/// A statics problem ready for the core: rod, tendons, loads, options and the error slots of
/// their Python callables.
pub(crate) struct Problem {
    pub(crate) rod: softrod::Rod,
    pub(crate) tendons: Vec<softrod::Tendon>,
    pub(crate) loads: softrod::Loads,
    pub(crate) options: softrod::SolveOptions,
    slots: Vec<ErrorSlot>,
}

impl Problem {
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        rod: &Rod,
        tendons: &[PyRef<'_, Tendon>],
        loads: Option<&Loads>,
        integrator: &str,
        steps: i64,
        rtol: f64,
        atol: f64,
        tolerance: f64,
        max_iterations: i64,
        continuation: bool,
        max_load_steps: i64,
        warm_start: Option<WarmArg<'_>>,
        throw: bool,
    ) -> PyResult<Self> {
        let integ = match integrator {
            "rk4" => {
                if steps < 1 {
                    return Err(param_err("steps", steps, ">= 1"));
                }
                softrod::Integrator::Rk4 {
                    steps: steps as usize,
                }
            }
            "adaptive" => softrod::Integrator::Adaptive(AdaptiveOptions {
                rtol,
                atol,
                ..Default::default()
            }),
            other => return Err(param_err("integrator", other, "\"rk4\" or \"adaptive\"")),
        };
        if max_iterations < 1 {
            return Err(param_err("max_iterations", max_iterations, ">= 1"));
        }
        if max_load_steps < 1 {
            return Err(param_err("max_load_steps", max_load_steps, ">= 1"));
        }
        let warm = match warm_start {
            None => None,
            Some(WarmArg::Solution(s)) => Some(s.inner.warm_start()),
            Some(WarmArg::Wrench(w)) => Some(softrod::WarmStart { base_wrench: w }),
        };
        let options = softrod::SolveOptions {
            integrator: integ,
            tolerance,
            max_iterations: max_iterations as usize,
            continuation,
            max_load_steps: max_load_steps as usize,
            warm_start: warm,
            throw,
        };
        let mut slots: Vec<ErrorSlot> = rod.slots.clone();
        slots.extend(tendons.iter().map(|t| t.slot.clone()));
        if let Some(l) = loads {
            slots.push(l.slot.clone());
        }
        Ok(Self {
            rod: rod.inner.clone(),
            tendons: tendons.iter().map(|t| t.inner.clone()).collect(),
            loads: loads.map(|l| l.inner.clone()).unwrap_or_default(),
            options,
            slots,
        })
    }

    fn solve(&self) -> softrod::Result<softrod::StaticsSolution> {
        softrod::solve_statics(&self.rod, &self.tendons, &self.loads, &self.options)
    }

    /// The problem with pneumatic `chambers` (kept in the core's loads).
    fn with_chambers(mut self, chambers: &[PyRef<'_, Chamber>]) -> Self {
        self.loads
            .chambers
            .extend(chambers.iter().map(|c| c.inner.clone()));
        self.slots.extend(chambers.iter().map(|c| c.slot.clone()));
        self
    }

    /// The first exception raised by a Python callable during the solve, if any.
    pub(crate) fn callback_error(&self) -> Option<PyErr> {
        self.slots.iter().find_map(ErrorSlot::take)
    }
}

/// Solves the statics of `rod` with `tendons`, `loads` and pneumatic `chambers` by shooting
/// (see the docs).
#[pyfunction]
#[pyo3(signature = (rod, tendons=Vec::new(), loads=None, *, integrator="rk4", steps=40,
                    rtol=1e-8, atol=1e-10, tolerance=1e-10, max_iterations=30,
                    continuation=true, max_load_steps=64, warm_start=None, throw=true,
                    chambers=Vec::new()))]
pub(crate) fn solve_statics(
    py: Python<'_>,
    rod: PyRef<'_, Rod>,
    tendons: Vec<PyRef<'_, Tendon>>,
    loads: Option<PyRef<'_, Loads>>,
    integrator: &str,
    steps: i64,
    rtol: f64,
    atol: f64,
    tolerance: f64,
    max_iterations: i64,
    continuation: bool,
    max_load_steps: i64,
    warm_start: Option<WarmArg<'_>>,
    throw: bool,
    chambers: Vec<PyRef<'_, Chamber>>,
) -> PyResult<StaticsSolution> {
    let problem = Arc::new(
        Problem::new(
            &rod,
            &tendons,
            loads.as_deref(),
            integrator,
            steps,
            rtol,
            atol,
            tolerance,
            max_iterations,
            continuation,
            max_load_steps,
            warm_start,
            throw,
        )?
        .with_chambers(&chambers),
    );
    let result = py.detach(|| problem.solve());
    if let Some(err) = problem.callback_error() {
        return Err(err);
    }
    Ok(StaticsSolution {
        inner: result.map_err(to_py_err)?,
        cache: std::array::from_fn(|_| PyOnceLock::new()),
        problem: Some(problem),
    })
}

/// Benchmark hook: runs the same solve `repeats` times inside Rust and returns each call's
/// wall time (s), so that the Python overhead of `solve_statics` can be measured.
#[pyfunction]
#[pyo3(signature = (rod, tendons=Vec::new(), loads=None, *, repeats=1000, integrator="rk4",
                    steps=40, rtol=1e-8, atol=1e-10, tolerance=1e-10, warm_start=None))]
pub(crate) fn _time_solve_statics(
    py: Python<'_>,
    rod: PyRef<'_, Rod>,
    tendons: Vec<PyRef<'_, Tendon>>,
    loads: Option<PyRef<'_, Loads>>,
    repeats: i64,
    integrator: &str,
    steps: i64,
    rtol: f64,
    atol: f64,
    tolerance: f64,
    warm_start: Option<WarmArg<'_>>,
) -> PyResult<Vec<f64>> {
    if repeats < 1 {
        return Err(param_err("repeats", repeats, ">= 1"));
    }
    let problem = Problem::new(
        &rod,
        &tendons,
        loads.as_deref(),
        integrator,
        steps,
        rtol,
        atol,
        tolerance,
        30,
        true,
        64,
        warm_start,
        true,
    )?;
    let times = py.detach(|| {
        (0..repeats)
            .map(|_| {
                let t0 = std::time::Instant::now();
                let r = problem.solve();
                (t0.elapsed().as_secs_f64(), r.is_ok())
            })
            .collect::<Vec<_>>()
    });
    if let Some(err) = problem.callback_error() {
        return Err(err);
    }
    if times.iter().any(|(_, ok)| !ok) {
        if let Err(e) = problem.solve() {
            return Err(to_py_err(e));
        }
    }
    Ok(times.into_iter().map(|(t, _)| t).collect())
}
