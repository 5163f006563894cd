//! Binding of the robot description: sections, the linear material, rods, tendons, chambers,
//! point loads and loads.
//!
//! Every class keeps the arguments it was built with (as given, in a dict): its read-only
//! properties return them (what a writer needs to serialise the object back), and pickling
//! rebuilds the object from them (`_rebuild(cls, (), kwargs)`), so an unpickled object is
//! built by the same validated constructor and solves bit for bit identically. Python
//! callables (rest strains, offsets, section functions, areas, distributed loads) pickle when
//! they do (module-level functions). They are called from the solver with the GIL
//! re-acquired; an exception they raise reaches the caller of the computation that called
//! them (see `callbacks.rs`). Every argument is converted by `convert.rs`, naming it.

use std::sync::Arc;

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use pyo3::IntoPyObjectExt;

use softrod::nalgebra::{Matrix3, Vector3};

use crate::callbacks::{run_attached, Callback};
use crate::convert::{arg, frame_from, pair, pose, vec3};
use crate::errors::{param_err, to_py_err, type_err};
use crate::sections::{material_of, PySection};

/// The constructor arguments of an object, for its properties and for pickling.
pub(crate) struct Args(Py<PyDict>);

impl Args {
    pub(crate) fn new(py: Python<'_>, items: &[(&str, Py<PyAny>)]) -> PyResult<Self> {
        let d = PyDict::new(py);
        for (k, v) in items {
            d.set_item(k, v)?;
        }
        Ok(Self(d.unbind()))
    }
    /// A copy of the arguments as a dict.
    pub(crate) fn dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.0.bind(py).copy()
    }
    pub(crate) fn get(&self, py: Python<'_>, key: &str) -> Py<PyAny> {
        self.0
            .bind(py)
            .get_item(key)
            .ok()
            .flatten()
            .map_or_else(|| py.None(), Bound::unbind)
    }
    /// `(_rebuild, (cls, (), kwargs))` for `__reduce__`.
    pub(crate) fn reduce<'py>(
        &self,
        py: Python<'py>,
        cls: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let rebuild = py.import("softrod._core")?.getattr("_rebuild")?;
        let inner = PyTuple::new(
            py,
            [
                cls,
                PyTuple::empty(py).into_any(),
                self.0.bind(py).copy()?.into_any(),
            ],
        )?;
        PyTuple::new(py, [rebuild, inner.into_any()])
    }
}

/// `f(*args, **kwargs)`: the one constructor call of every unpickled object.
#[pyfunction]
pub(crate) fn _rebuild<'py>(
    f: &Bound<'py, PyAny>,
    args: &Bound<'py, PyTuple>,
    kwargs: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyAny>> {
    f.call(args, Some(kwargs))
}

pub(crate) fn obj<'py, T>(py: Python<'py>, v: T) -> PyResult<Py<PyAny>>
where
    T: IntoPyObjectExt<'py>,
{
    v.into_py_any(py)
}

/// A 3-vector argument (constant) or a Python function of `s`, as a core profile.
fn profile(
    arg: &Bound<'_, PyAny>,
    what: &'static str,
    label: &'static str,
) -> PyResult<softrod::Profile> {
    if arg.is_callable() {
        let cb = Callback::new(arg.clone().unbind(), what, label);
        return Ok(softrod::Profile::Function(Arc::new(move |s| {
            Vector3::from(cb.floats::<3>(s))
        })));
    }
    Ok(softrod::Profile::Constant(vec3(arg, what)?))
}

/// Checks a function profile once at `s = 0` (a function of the loads, whose rod is not known
/// yet); a constant was checked on conversion.
fn check_at_zero(name: &str, p: &softrod::Profile) -> softrod::Result<()> {
    let v = p.at(0.0);
    for k in 0..3 {
        softrod::error::check_finite(&format!("{name}(0)[{k}]"), v[k])?;
    }
    Ok(())
}

// ----------------------------------------------------------------------------------- rod

/// A Cosserat rod (immutable): length (m), section, material, rest strains, density, base pose.
///
/// Rest strain `v*` (dimensionless) and rest curvature `u*` (1/m) are 3-vectors or functions of
/// `s` (m); density in kg/m^3; the base pose a 4x4 transform (m). Read-only properties return
/// the arguments as given (what a writer needs to save the rod).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct Rod {
    pub(crate) inner: softrod::Rod,
    args: Args,
}

#[pymethods]
impl Rod {
    #[new]
    #[pyo3(signature = (length, section, material, rest_strain=None, rest_curvature=None,
                        inextensible=false, density=None, base_pose=None, *, shear_coefficient=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::length)] length: f64,
        #[pyo3(from_py_with = arg::section)] section: Bound<'_, PySection>,
        material: &Bound<'_, PyAny>,
        rest_strain: Option<&Bound<'_, PyAny>>,
        rest_curvature: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = arg::inextensible)] inextensible: bool,
        #[pyo3(from_py_with = arg::density)] density: Option<f64>,
        base_pose: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = arg::shear_coefficient)] shear_coefficient: Option<f64>,
    ) -> PyResult<Self> {
        let sec = section.get().inner.clone();
        let material_core = material_of(material)?;
        let rest_strain_p = rest_strain
            .map(|v| profile(v, "rest_strain", "the rest strain"))
            .transpose()?;
        let rest_curvature_p = rest_curvature
            .map(|u| profile(u, "rest_curvature", "the rest curvature"))
            .transpose()?;
        let pose = match base_pose {
            Some(p) => {
                let (p, r) = pose(p, "base_pose")?;
                let rot = Matrix3::from_fn(|i, j| r[i][j]);
                Some(softrod::Pose::new(Vector3::from(p), rot).map_err(to_py_err)?)
            }
            None => None,
        };
        // The profiles' functions are called here (checked on the rod's length).
        let rod = run_attached("Rod", || {
            let mut rod = softrod::Rod::new(length, sec, material_core)?;
            if let Some(v) = rest_strain_p {
                rod = rod.with_rest_strain(v)?;
            }
            if let Some(u) = rest_curvature_p {
                rod = rod.with_rest_curvature(u)?;
            }
            rod = rod.with_inextensible(inextensible);
            if let Some(rho) = density {
                rod = rod.with_density(rho)?;
            }
            if let Some(k) = shear_coefficient {
                rod = rod.with_shear_coefficient(k)?;
            }
            if let Some(pose) = pose {
                rod = rod.with_base_pose(pose);
            }
            Ok(rod)
        })?;
        let none = || py.None();
        let opt = |v: Option<&Bound<'_, PyAny>>| v.map_or_else(none, |b| b.clone().unbind());
        let args = Args::new(
            py,
            &[
                ("length", obj(py, length)?),
                ("section", section.clone().into_any().unbind()),
                ("material", material.clone().unbind()),
                ("rest_strain", opt(rest_strain)),
                ("rest_curvature", opt(rest_curvature)),
                ("inextensible", obj(py, inextensible)?),
                ("density", obj(py, density)?),
                ("base_pose", opt(base_pose)),
                ("shear_coefficient", obj(py, shear_coefficient)?),
            ],
        )?;
        Ok(Self { inner: rod, args })
    }

    /// Length (m).
    #[getter]
    fn length(&self) -> f64 {
        self.inner.length()
    }
    /// The section, as given.
    #[getter]
    fn section(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "section")
    }
    /// The material, as given.
    #[getter]
    fn material(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "material")
    }
    /// The rest strain as given (None: `(0, 0, 1)`).
    #[getter]
    fn rest_strain(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "rest_strain")
    }
    /// The rest curvature as given (None: zero).
    #[getter]
    fn rest_curvature(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "rest_curvature")
    }
    #[getter]
    fn inextensible(&self) -> bool {
        self.inner.inextensible()
    }
    #[getter]
    fn density(&self) -> Option<f64> {
        self.inner.density()
    }
    /// Shear coefficient in use (the one given, or Cowper's value for the section).
    #[getter]
    fn shear_coefficient(&self) -> f64 {
        self.inner.shear_coefficient()
    }
    /// The shear coefficient as given (None: Cowper's value).
    #[getter]
    fn shear_coefficient_given(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "shear_coefficient")
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
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        slf.get().args.reduce(slf.py(), slf.get_type().into_any())
    }
}

// ----------------------------------------------------------------------------------- tendons

/// A tendon: body-frame offset (m) — an (x, y) pair or a function of s — tension (N), and the
/// arc length (m) where it ends (default: the tip).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct Tendon {
    pub(crate) inner: softrod::Tendon,
    pub(crate) tension: f64,
    /// How to rebuild it: the constructor (the class or a static factory) and its arguments.
    factory: &'static str,
    args: Args,
}

fn offset_fn(
    f: &Bound<'_, PyAny>,
    what: &'static str,
    label: &'static str,
) -> softrod::model::tendon::OffsetFn {
    let cb = Callback::new(f.clone().unbind(), what, label);
    Arc::new(move |s| cb.floats::<2>(s))
}

fn check_tension(tension: f64) -> PyResult<f64> {
    softrod::error::check_non_negative("tension", tension, "N").map_err(to_py_err)
}

#[pymethods]
impl Tendon {
    /// `offset`: `(x, y)` (m, body frame) or a function `s -> (x, y)`; `derivative`: the
    /// function's exact derivative `s -> (dx/ds, dy/ds)` (required with a function offset).
    /// `guides`: arc lengths (m, increasing, in `(0, end)`) of the disks the tendon runs
    /// through in straight chords (at its offset there), with the capstan coefficient
    /// `guide_friction` (one value, or one per guide); `None`: a continuous channel.
    #[new]
    #[pyo3(signature = (offset, tension, end=None, *, derivative=None, friction=0.0, guides=None, guide_friction=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        offset: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = arg::tension)] tension: f64,
        #[pyo3(from_py_with = arg::end)] end: Option<f64>,
        derivative: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = arg::friction)] friction: f64,
        guides: Option<&Bound<'_, PyAny>>,
        guide_friction: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let guides = guides.filter(|g| !g.is_none());
        let guide_friction = guide_friction.filter(|g| !g.is_none());
        let guide_list: Vec<f64> = match guides {
            Some(g) => g
                .extract()
                .map_err(|_| type_err("guides", g, "a sequence of arc lengths (m)"))?,
            None => Vec::new(),
        };
        let guide_mu: Vec<f64> = match guide_friction {
            None => vec![0.0],
            Some(g) => match g.extract::<f64>() {
                Ok(v) => vec![v],
                Err(_) => g
                    .extract()
                    .map_err(|_| type_err("guide_friction", g, "a coefficient or one per guide"))?,
            },
        };
        if guides.is_none() && guide_friction.is_some() {
            return Err(param_err(
                "guide_friction",
                "given",
                "None without guides (a continuous channel takes friction=)",
            ));
        }
        let derivative = derivative.filter(|d| !d.is_none());
        let routing = match (offset.is_callable(), derivative) {
            (false, None) => softrod::Routing::Constant(pair(offset, "offset")?),
            (false, Some(d)) => {
                return Err(type_err("derivative", d, "None for a constant offset"))
            }
            (true, Some(df)) => {
                if !df.is_callable() {
                    return Err(type_err("derivative", df, "a function of s"));
                }
                softrod::Routing::Function {
                    offset: offset_fn(offset, "offset", "the tendon offset"),
                    derivative: offset_fn(df, "derivative", "the tendon offset derivative"),
                }
            }
            (true, None) => {
                return Err(param_err(
                    "derivative",
                    "None",
                    "the exact derivative s -> (dx/ds, dy/ds) of a function offset",
                ))
            }
        };
        let tension = check_tension(tension)?;
        let inner = run_attached("Tendon", || {
            if let softrod::Routing::Function { offset, derivative } = &routing {
                // Called once here (the rod, hence the range of s, is not known yet).
                for (name, f) in [("offset", offset), ("derivative", derivative)] {
                    for (k, v) in f(0.0).iter().enumerate() {
                        softrod::error::check_finite(&format!("{name}(0)[{k}]"), *v)?;
                    }
                }
            }
            let t = softrod::Tendon::new(routing, end)?.with_friction(friction)?;
            if guide_list.is_empty() && guides.is_some() {
                return Err(softrod::Error::invalid(
                    "guides",
                    "an empty sequence",
                    "at least one guide arc length, or None",
                ));
            }
            t.with_guides(guide_list, &guide_mu)
        })?;
        let mut fields = vec![
            ("offset", offset.clone().unbind()),
            ("tension", obj(py, tension)?),
            ("end", obj(py, end)?),
            (
                "derivative",
                derivative.map_or_else(|| py.None(), |d| d.clone().unbind()),
            ),
            ("friction", obj(py, friction)?),
        ];
        if inner.is_guided() {
            fields.push(("guides", obj(py, inner.guides().to_vec())?));
            fields.push(("guide_friction", obj(py, inner.guide_friction().to_vec())?));
        }
        let args = Args::new(py, &fields)?;
        Ok(Self {
            inner,
            tension,
            factory: "",
            args,
        })
    }

    /// Tendon at `ratio` times the local section radius, at `angle` (rad) from body x
    /// (the planar cable-arm paper's cable: `ratio = a`, `angle = 0`).
    #[staticmethod]
    #[pyo3(signature = (ratio, angle, tension, end=None, *, friction=0.0))]
    fn radius_proportional(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::ratio)] ratio: f64,
        #[pyo3(from_py_with = arg::angle)] angle: f64,
        #[pyo3(from_py_with = arg::tension)] tension: f64,
        #[pyo3(from_py_with = arg::end)] end: Option<f64>,
        #[pyo3(from_py_with = arg::friction)] friction: f64,
    ) -> PyResult<Self> {
        let inner =
            softrod::Tendon::new(softrod::Routing::RadiusProportional { ratio, angle }, end)
                .and_then(|t| t.with_friction(friction))
                .map_err(to_py_err)?;
        let tension = check_tension(tension)?;
        let args = Args::new(
            py,
            &[
                ("ratio", obj(py, ratio)?),
                ("angle", obj(py, angle)?),
                ("tension", obj(py, tension)?),
                ("end", obj(py, end)?),
                ("friction", obj(py, friction)?),
            ],
        )?;
        Ok(Self {
            inner,
            tension,
            factory: "radius_proportional",
            args,
        })
    }

    /// Helical tendon of `radius` (m) and signed `pitch` (m per turn; > 0 right-handed),
    /// starting at `phase` (rad) from body x.
    #[staticmethod]
    #[pyo3(signature = (radius, pitch, tension, phase=0.0, end=None, *, friction=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn helical(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::radius)] radius: f64,
        #[pyo3(from_py_with = arg::pitch)] pitch: f64,
        #[pyo3(from_py_with = arg::tension)] tension: f64,
        #[pyo3(from_py_with = arg::phase)] phase: f64,
        #[pyo3(from_py_with = arg::end)] end: Option<f64>,
        #[pyo3(from_py_with = arg::friction)] friction: f64,
    ) -> PyResult<Self> {
        let inner = softrod::Tendon::new(
            softrod::Routing::Helical {
                radius,
                pitch,
                phase,
            },
            end,
        )
        .and_then(|t| t.with_friction(friction))
        .map_err(to_py_err)?;
        let tension = check_tension(tension)?;
        let args = Args::new(
            py,
            &[
                ("radius", obj(py, radius)?),
                ("pitch", obj(py, pitch)?),
                ("tension", obj(py, tension)?),
                ("phase", obj(py, phase)?),
                ("end", obj(py, end)?),
                ("friction", obj(py, friction)?),
            ],
        )?;
        Ok(Self {
            inner,
            tension,
            factory: "helical",
            args,
        })
    }

    /// The same tendon with another tension (N).
    fn with_tension(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = arg::tension)] tension: f64,
    ) -> PyResult<Self> {
        self.tensioned(py, tension)
    }
    /// Tension (N).
    #[getter]
    fn tension(&self) -> f64 {
        self.tension
    }
    /// Termination (m), None for the tip.
    #[getter]
    fn end(&self) -> Option<f64> {
        self.inner.end()
    }
    /// Friction coefficient between the tendon and its channel (dimensionless, >= 0; 0:
    /// frictionless).
    #[getter]
    fn friction(&self) -> f64 {
        self.inner.friction()
    }
    /// Arc lengths (m) of the guides the tendon runs through; empty for a continuous channel.
    #[getter]
    fn guides(&self) -> Vec<f64> {
        self.inner.guides().to_vec()
    }
    /// Capstan coefficient at each guide (dimensionless, one per guide).
    #[getter]
    fn guide_friction(&self) -> Vec<f64> {
        self.inner.guide_friction().to_vec()
    }
    /// Routing kind: "constant", "function", "radius_proportional" or "helical".
    #[getter]
    fn routing(&self) -> &'static str {
        match self.inner.routing() {
            softrod::Routing::Constant(_) => "constant",
            softrod::Routing::Function { .. } => "function",
            softrod::Routing::RadiusProportional { .. } => "radius_proportional",
            softrod::Routing::Helical { .. } => "helical",
        }
    }
    /// The routing's parameters as given (`offset` and `derivative`; `ratio` and `angle`;
    /// `radius`, `pitch` and `phase`), with `tension` and `end`.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.args.0.bind(py).copy()
    }
    fn __repr__(&self) -> String {
        let mut friction = match self.inner.friction() {
            0.0 => String::new(),
            mu => format!(", friction={mu}"),
        };
        if self.inner.is_guided() {
            friction += &format!(
                ", guides={:?}, guide_friction={:?}",
                self.inner.guides(),
                self.inner.guide_friction()
            );
        }
        format!(
            "Tendon({:?}, tension={}, end={}{friction})",
            self.inner.routing(),
            self.tension,
            py_option(self.inner.end())
        )
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let this = slf.get();
        let cls = slf.get_type().into_any();
        let f = if this.factory.is_empty() {
            cls
        } else {
            cls.getattr(this.factory)?
        };
        this.args.reduce(slf.py(), f)
    }
}

// ----------------------------------------------------------------------------------- chambers

/// A pneumatic chamber: gauge pressure (Pa), cross-section area (m^2, constant or a function
/// of s), centroid offset (x, y) (m, body frame) and extent [start, end] (m; end None: the
/// tip).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct Chamber {
    pub(crate) inner: softrod::Chamber,
    pub(crate) pressure: f64,
    args: Args,
}

#[pymethods]
impl Chamber {
    #[new]
    #[pyo3(signature = (pressure, area, offset, start=0.0, end=None))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = arg::pressure)] pressure: f64,
        area: &Bound<'_, PyAny>,
        offset: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = arg::start)] start: f64,
        #[pyo3(from_py_with = arg::end)] end: Option<f64>,
    ) -> PyResult<Self> {
        let pressure =
            softrod::model::chamber::check_pressure("pressure", pressure).map_err(to_py_err)?;
        let a = if area.is_callable() {
            let cb = Callback::new(area.clone().unbind(), "area", "the chamber area");
            softrod::ChamberArea::Function(Arc::new(move |s| cb.float(s)))
        } else {
            let v: f64 = crate::convert::Arg::from_arg(area, "area")
                .map_err(|_| type_err("area", area, "a number (m^2) or a function of s"))?;
            softrod::ChamberArea::Constant(v)
        };
        let offset_xy = pair(offset, "offset")?;
        let inner = run_attached("Chamber", || {
            let c = softrod::Chamber::new(a, offset_xy, start, end)?;
            if let softrod::ChamberArea::Function(_) = c.area() {
                // Called once here (the rod, hence the chamber's extent, is not known yet);
                // its values are checked with the rod (`chambers[i].area(s)`).
                softrod::error::check_finite(&format!("area({start})"), c.area_at(start))?;
            }
            Ok(c)
        })?;
        let args = Args::new(
            py,
            &[
                ("pressure", obj(py, pressure)?),
                ("area", area.clone().unbind()),
                ("offset", offset.clone().unbind()),
                ("start", obj(py, start)?),
                ("end", obj(py, end)?),
            ],
        )?;
        Ok(Self {
            inner,
            pressure,
            args,
        })
    }

    /// The same chamber at another gauge pressure (Pa).
    fn with_pressure(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = arg::pressure)] pressure: f64,
    ) -> PyResult<Self> {
        self.pressurised(py, pressure)
    }
    /// Gauge pressure (Pa).
    #[getter]
    fn pressure(&self) -> f64 {
        self.pressure
    }
    /// The area as given: a number (m^2) or a function of s.
    #[getter]
    fn area(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "area")
    }
    /// Cross-section area at arc length `s` (m^2).
    ///
    /// Raises `ParameterError` naming `s` outside `[start, end]`, or `area(s)` if the area is
    /// not finite and > 0 there.
    fn area_at(&self, #[pyo3(from_py_with = arg::s)] s: f64) -> PyResult<f64> {
        let c = &self.inner;
        run_attached("Chamber.area_at", || {
            let end = c.end().unwrap_or(f64::INFINITY);
            if !(s.is_finite() && s >= c.start() && s <= end) {
                return Err(softrod::Error::invalid(
                    "s",
                    s,
                    format!("finite and in [start, end] = [{}, {end}] m", c.start()),
                ));
            }
            softrod::error::check_positive(&format!("area({s})"), c.area_at(s), "m^2")
        })
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
            "Chamber(pressure={}, area={:?}, offset=({x}, {y}), start={}, end={})",
            self.pressure,
            self.inner.area(),
            self.inner.start(),
            py_option(self.inner.end())
        )
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        slf.get().args.reduce(slf.py(), slf.get_type().into_any())
    }
}

// ----------------------------------------------------------------------------------- loads

/// A force (N) and moment (N m) applied at arc length `s` (m), in the world or body frame.
///
/// `frame` "world" (dead load) or "body" (follower load); `s` in (0, L] (m).
#[pyclass(frozen, module = "softrod._core")]
#[derive(Clone)]
pub(crate) struct PointLoad {
    inner: softrod::PointLoad,
}

#[pymethods]
impl PointLoad {
    #[new]
    #[pyo3(signature = (s, force=None, moment=None, frame="world"))]
    fn new(
        #[pyo3(from_py_with = arg::s)] s: f64,
        force: Option<&Bound<'_, PyAny>>,
        moment: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = arg::frame)] frame: &str,
    ) -> PyResult<Self> {
        let v = |a: Option<&Bound<'_, PyAny>>, n| a.map_or(Ok(Vector3::zeros()), |a| vec3(a, n));
        let inner = softrod::PointLoad::new(
            s,
            v(force, "force")?,
            v(moment, "moment")?,
            frame_from("frame", frame)?,
        )
        .map_err(to_py_err)?;
        Ok(Self { inner })
    }
    /// Arc length (m).
    #[getter]
    fn s(&self) -> f64 {
        self.inner.s
    }
    /// Force (N).
    #[getter]
    fn force(&self) -> [f64; 3] {
        self.inner.force.into()
    }
    /// Moment (N m).
    #[getter]
    fn moment(&self) -> [f64; 3] {
        self.inner.moment.into()
    }
    /// "world" or "body".
    #[getter]
    fn frame(&self) -> &'static str {
        match self.inner.frame {
            softrod::Frame::World => "world",
            softrod::Frame::Body => "body",
        }
    }
    fn __repr__(&self) -> String {
        format!("{:?}", self.inner)
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let p = slf.get();
        let args = Args::new(
            py,
            &[
                ("s", obj(py, p.s())?),
                ("force", obj(py, p.force())?),
                ("moment", obj(py, p.moment())?),
                ("frame", obj(py, p.frame())?),
            ],
        )?;
        args.reduce(py, slf.get_type().into_any())
    }
}

/// External loads: tip force (N) and moment (N m) in `tip_frame`; point loads; distributed
/// force (N/m) and moment (N m/m), constant or functions of s (world frame); gravity (m/s^2,
/// world frame, needs the rod's density).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct Loads {
    pub(crate) inner: softrod::Loads,
    args: Args,
}

#[pymethods]
impl Loads {
    #[new]
    #[pyo3(signature = (tip_force=None, tip_moment=None, gravity=None, *, tip_frame="world",
                        point_loads=Vec::new(), distributed_force=None, distributed_moment=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        tip_force: Option<&Bound<'_, PyAny>>,
        tip_moment: Option<&Bound<'_, PyAny>>,
        gravity: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = arg::tip_frame)] tip_frame: &str,
        #[pyo3(from_py_with = arg::point_loads)] point_loads: Vec<Bound<'_, PointLoad>>,
        distributed_force: Option<&Bound<'_, PyAny>>,
        distributed_moment: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let v = |a: Option<&Bound<'_, PyAny>>, n| a.map_or(Ok(Vector3::zeros()), |a| vec3(a, n));
        let inner = softrod::Loads {
            tip_force: v(tip_force, "tip_force")?,
            tip_moment: v(tip_moment, "tip_moment")?,
            tip_frame: frame_from("tip_frame", tip_frame)?,
            point_loads: point_loads.iter().map(|p| p.get().inner).collect(),
            distributed_force: distributed_force
                .map(|f| profile(f, "distributed_force", "the distributed force"))
                .transpose()?,
            distributed_moment: distributed_moment
                .map(|f| profile(f, "distributed_moment", "the distributed moment"))
                .transpose()?,
            gravity: v(gravity, "gravity")?,
        };
        run_attached("Loads", || {
            inner.check_values()?;
            for (name, f) in [
                ("distributed_force", &inner.distributed_force),
                ("distributed_moment", &inner.distributed_moment),
            ] {
                if let Some(p) = f {
                    check_at_zero(name, p)?;
                }
            }
            Ok(())
        })?;
        let opt =
            |a: Option<&Bound<'_, PyAny>>| a.map_or_else(|| py.None(), |b| b.clone().unbind());
        let args = Args::new(
            py,
            &[
                ("tip_force", opt(tip_force)),
                ("tip_moment", opt(tip_moment)),
                ("gravity", opt(gravity)),
                ("tip_frame", obj(py, tip_frame)?),
                ("point_loads", obj(py, point_loads.clone())?),
                ("distributed_force", opt(distributed_force)),
                ("distributed_moment", opt(distributed_moment)),
            ],
        )?;
        Ok(Self { inner, args })
    }
    /// Tip force (N).
    #[getter]
    fn tip_force(&self) -> [f64; 3] {
        self.inner.tip_force.into()
    }
    /// Tip moment (N m).
    #[getter]
    fn tip_moment(&self) -> [f64; 3] {
        self.inner.tip_moment.into()
    }
    /// Gravitational acceleration (m/s^2, world).
    #[getter]
    fn gravity(&self) -> [f64; 3] {
        self.inner.gravity.into()
    }
    /// "world" or "body".
    #[getter]
    fn tip_frame(&self) -> &'static str {
        match self.inner.tip_frame {
            softrod::Frame::World => "world",
            softrod::Frame::Body => "body",
        }
    }
    /// The point loads.
    #[getter]
    fn point_loads(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "point_loads")
    }
    /// The distributed force as given (None, a 3-vector or a function of s).
    #[getter]
    fn distributed_force(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "distributed_force")
    }
    /// The distributed moment as given.
    #[getter]
    fn distributed_moment(&self, py: Python<'_>) -> Py<PyAny> {
        self.args.get(py, "distributed_moment")
    }
    fn __repr__(&self) -> String {
        format!("{:?}", self.inner)
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        slf.get().args.reduce(slf.py(), slf.get_type().into_any())
    }
}

fn is_function(p: &softrod::Profile) -> bool {
    matches!(p, softrod::Profile::Function(_))
}

impl Rod {
    /// Whether a Python callable is part of the rod (section, rest strain or curvature).
    pub(crate) fn has_callables(&self) -> bool {
        let r = &self.inner;
        r.section().is_function() || is_function(r.rest_strain()) || is_function(r.rest_curvature())
    }
}

impl Tendon {
    /// The same tendon with another tension (N), checked (`tension`).
    pub(crate) fn tensioned(&self, py: Python<'_>, tension: f64) -> PyResult<Self> {
        let tension = check_tension(tension)?;
        let args = Args(self.args.0.bind(py).copy()?.unbind());
        args.0.bind(py).set_item("tension", tension)?;
        Ok(Self {
            inner: self.inner.clone(),
            tension,
            factory: self.factory,
            args,
        })
    }

    /// Whether the routing is a Python callable.
    pub(crate) fn has_callables(&self) -> bool {
        matches!(self.inner.routing(), softrod::Routing::Function { .. })
    }
}

impl Chamber {
    /// The same chamber at another gauge pressure (Pa), checked (`pressure`).
    pub(crate) fn pressurised(&self, py: Python<'_>, pressure: f64) -> PyResult<Self> {
        let pressure =
            softrod::model::chamber::check_pressure("pressure", pressure).map_err(to_py_err)?;
        let args = Args(self.args.0.bind(py).copy()?.unbind());
        args.0.bind(py).set_item("pressure", pressure)?;
        Ok(Self {
            inner: self.inner.clone(),
            pressure,
            args,
        })
    }

    /// Whether the area is a Python callable.
    pub(crate) fn has_callables(&self) -> bool {
        matches!(self.inner.area(), softrod::ChamberArea::Function(_))
    }
}

impl Loads {
    /// Whether a distributed load is a Python callable.
    pub(crate) fn has_callables(&self) -> bool {
        let l = &self.inner;
        l.distributed_force.as_ref().is_some_and(is_function)
            || l.distributed_moment.as_ref().is_some_and(is_function)
    }
}

/// An optional number as Python writes it (`None` or the number) for a `__repr__`.
fn py_option(x: Option<f64>) -> String {
    x.map_or_else(|| "None".to_string(), |v| v.to_string())
}
