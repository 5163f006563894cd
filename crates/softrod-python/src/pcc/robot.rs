//! The PCC robot class (segments, tendons, chambers), its statics solve and its solution.

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use softrod::nalgebra::{Matrix4, Vector3};
use softrod::pcc::statics::{self as statics, PccLoads, PccRobot as CoreRobot, PccSolveOptions};
use softrod::pcc::{self, ElasticSegment};

use super::*;
use crate::callbacks::run;
use crate::convert::{arg, count, Arg, Floats};
use crate::errors::{param_err, to_py_err};

/// One value per segment from a scalar or a sequence of `n`.
fn per_segment(v: Floats, n: usize, name: &str) -> PyResult<Vec<f64>> {
    let v = v.to_vec()?;
    match v.len() {
        1 => Ok(vec![v[0]; n]),
        k if k == n => Ok(v),
        k => Err(param_err(
            &format!("{name}.len()"),
            k,
            &format!("1 or the number of segments (the length of rest_lengths), {n}"),
        )),
    }
}

/// A PCC robot (immutable): elastic segments, routed tendons, chambers.
#[pyclass(frozen, module = "softrod._core", name = "PccRobot")]
pub(crate) struct PccRobot {
    pub(crate) inner: CoreRobot,
}

#[pymethods]
impl PccRobot {
    #[new]
    #[pyo3(signature = (rest_lengths, bending_stiffness, axial_stiffness=None))]
    fn new(
        #[pyo3(from_py_with = arg::rest_lengths)] rest_lengths: Floats,
        #[pyo3(from_py_with = arg::bending_stiffness)] bending_stiffness: Floats,
        #[pyo3(from_py_with = arg::axial_stiffness)] axial_stiffness: Option<Floats>,
    ) -> PyResult<Self> {
        let l0 = rest_lengths.to_vec()?;
        let n = l0.len();
        let ei = per_segment(bending_stiffness, n, "bending_stiffness")?;
        let ea = match axial_stiffness {
            Some(a) => Some(per_segment(a, n, "axial_stiffness")?),
            None => None,
        };
        let bodies = (0..n)
            .map(|i| {
                ElasticSegment::new(l0[i], ei[i], ea.as_ref().map(|a| a[i]))
                    .map_err(|e| indexed(e, i))
            })
            .collect::<softrod::Result<Vec<_>>>()
            .map_err(to_py_err)?;
        let inner = CoreRobot::new(bodies)
            .map_err(|_| param_err("rest_lengths", "[]", "at least one segment"))?;
        Ok(Self { inner })
    }

    /// Solid circular segments of `radius` (m) and Young's modulus (Pa).
    #[staticmethod]
    #[pyo3(signature = (rest_lengths, radius, youngs_modulus, *, extensible=true))]
    fn solid_circle(
        #[pyo3(from_py_with = arg::rest_lengths)] rest_lengths: Floats,
        #[pyo3(from_py_with = arg::radius)] radius: f64,
        #[pyo3(from_py_with = arg::youngs_modulus)] youngs_modulus: f64,
        #[pyo3(from_py_with = arg::extensible)] extensible: bool,
    ) -> PyResult<Self> {
        let l0 = rest_lengths.to_vec()?;
        let bodies = l0
            .iter()
            .map(|&l| ElasticSegment::solid_circle(l, radius, youngs_modulus, extensible))
            .collect::<softrod::Result<Vec<_>>>()
            .map_err(to_py_err)?;
        let inner = CoreRobot::new(bodies)
            .map_err(|_| param_err("rest_lengths", "[]", "at least one segment"))?;
        Ok(Self { inner })
    }

    /// A new robot with tendons ending at the tip of `segment` (and passing through the
    /// segments before it at the same body offsets).
    fn with_tendons(
        &self,
        #[pyo3(from_py_with = arg::segment)] segment: usize,
        #[pyo3(from_py_with = arg::distances)] distances: Floats,
        #[pyo3(from_py_with = arg::angles)] angles: Floats,
    ) -> PyResult<Self> {
        let t = tendons_from(distances, angles)?;
        let inner = self
            .inner
            .clone()
            .with_segment_tendons(segment, &t)
            .map_err(to_py_err)?;
        Ok(Self { inner })
    }

    /// A new robot with pneumatic chambers in `segment`.
    fn with_chambers(
        &self,
        #[pyo3(from_py_with = arg::segment)] segment: usize,
        #[pyo3(from_py_with = arg::areas)] areas: Floats,
        #[pyo3(from_py_with = arg::distances)] distances: Floats,
        #[pyo3(from_py_with = arg::angles)] angles: Floats,
    ) -> PyResult<Self> {
        let ch = chambers_from(areas, distances, angles)?;
        let inner = self
            .inner
            .clone()
            .with_chambers(segment, ch)
            .map_err(to_py_err)?;
        Ok(Self { inner })
    }

    #[getter]
    fn n_segments(&self) -> usize {
        self.inner.segments().len()
    }
    #[getter]
    fn n_tendons(&self) -> usize {
        self.inner.n_tendons()
    }
    #[getter]
    fn n_chambers(&self) -> usize {
        self.inner.n_chambers()
    }
    #[getter]
    fn rest_lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .inner
            .segments()
            .iter()
            .map(|s| s.rest_length())
            .collect();
        v.into_pyarray(py)
    }
    #[getter]
    fn bending_stiffness<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .inner
            .segments()
            .iter()
            .map(|s| s.bending_stiffness())
            .collect();
        v.into_pyarray(py)
    }
    /// Axial stiffness per segment (N), `None` for an inextensible one.
    #[getter]
    fn axial_stiffness(&self) -> Vec<Option<f64>> {
        self.inner
            .segments()
            .iter()
            .map(|s| s.axial_stiffness())
            .collect()
    }
    /// Tendons as rows (distance, angle, last_segment).
    #[getter]
    fn tendons<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let t = self.inner.tendons();
        Array::from_shape_fn((t.len(), 3), |(i, j)| match j {
            0 => t[i].distance(),
            1 => t[i].angle(),
            _ => t[i].last_segment() as f64,
        })
        .into_pyarray(py)
    }

    /// Chamber groups as `(segment, areas, distances, angles)`.
    #[getter]
    fn chambers(&self) -> Vec<ChamberGroup> {
        self.inner
            .chambers()
            .iter()
            .map(|(seg, c)| {
                (
                    *seg,
                    c.areas().to_vec(),
                    c.distances().to_vec(),
                    c.angles().to_vec(),
                )
            })
            .collect()
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let r = &slf.get().inner;
        let bodies: Vec<(f64, f64, Option<f64>)> = r
            .segments()
            .iter()
            .map(|b| (b.rest_length(), b.bending_stiffness(), b.axial_stiffness()))
            .collect();
        let tendons: Vec<(f64, f64, usize)> = r
            .tendons()
            .iter()
            .map(|t| (t.distance(), t.angle(), t.last_segment()))
            .collect();
        let f = py.import("softrod._core")?.getattr("_pcc_robot")?;
        let args = (bodies, tendons, slf.get().chambers()).into_pyobject(py)?;
        PyTuple::new(py, [f, args.into_any()])
    }
    fn __repr__(&self) -> String {
        format!(
            "PccRobot(segments={}, tendons={}, chambers={})",
            self.inner.segments().len(),
            self.inner.n_tendons(),
            self.inner.n_chambers()
        )
    }
}

/// A PCC robot from its parts (the pickled form of `PccRobot`): segments `(rest_length,
/// bending_stiffness, axial_stiffness)`, tendons `(distance, angle, last_segment)`, chamber
/// groups `(segment, areas, distances, angles)`.
#[pyfunction]
pub(crate) fn _pcc_robot(
    bodies: Vec<(f64, f64, Option<f64>)>,
    tendons: Vec<(f64, f64, usize)>,
    chambers: Vec<ChamberGroup>,
) -> PyResult<PccRobot> {
    let segs = bodies
        .iter()
        .map(|&(l, ei, ea)| ElasticSegment::new(l, ei, ea))
        .collect::<softrod::Result<Vec<_>>>()
        .map_err(to_py_err)?;
    let mut robot = CoreRobot::new(segs).map_err(to_py_err)?;
    for (d, b, last) in tendons {
        let t = statics::RoutedTendon::new(d, b, last).map_err(to_py_err)?;
        robot = robot.with_tendon(t).map_err(to_py_err)?;
    }
    for (seg, a, d, b) in chambers {
        let c = pcc::PccChambers::new(&a, &d, &b).map_err(to_py_err)?;
        robot = robot.with_chambers(seg, c).map_err(to_py_err)?;
    }
    Ok(PccRobot { inner: robot })
}

/// A solved PCC robot.
#[pyclass(frozen, module = "softrod._core", name = "PccSolution")]
pub(crate) struct PccSolution {
    pub(crate) inner: statics::PccStaticsSolution,
    /// The robot it solves (rest lengths for the compliance).
    pub(crate) robot: CoreRobot,
    /// The loads (actuation and tip wrench) it was solved with.
    pub(crate) loads: PccLoads,
    s: Vec<f64>,
    frames: Vec<Matrix4<f64>>,
    /// The call that produced it (for pickling: it is solved again, bit for bit).
    call: crate::model::Args,
}

#[pymethods]
impl PccSolution {
    /// Arc parameters per segment, rows (curvature, plane_angle, length).
    #[getter]
    fn arcs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let s = &self.inner.segments;
        Array::from_shape_fn((s.len(), 3), |(i, j)| match j {
            0 => s[i].curvature(),
            1 => s[i].plane_angle(),
            _ => s[i].length(),
        })
        .into_pyarray(py)
    }
    /// Curvature-vector coordinates per segment, rows (u_x, u_y, length).
    #[getter]
    fn coordinates<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let c = self.inner.coordinates();
        Array::from_shape_fn((c.len(), 3), |(i, j)| c[i][j]).into_pyarray(py)
    }
    #[getter]
    fn tip_pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        pose_array(py, &self.inner.tip_pose)
    }
    #[getter]
    fn tip_position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let t = &self.inner.tip_pose;
        vec![t[(0, 3)], t[(1, 3)], t[(2, 3)]].into_pyarray(py)
    }
    /// Deformed arc length of the frame samples (m).
    #[getter]
    fn s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.s.clone().into_pyarray(py)
    }
    /// Backbone frames (N, 4, 4) at `s`.
    #[getter]
    fn frames<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        poses_array(py, &self.frames)
    }
    /// Backbone positions (N, 3) at `s`.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let f = &self.frames;
        Array::from_shape_fn((f.len(), 3), |(k, i)| f[k][(i, 3)]).into_pyarray(py)
    }
    #[getter]
    fn tendon_lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.tendon_lengths.clone().into_pyarray(py)
    }
    #[getter]
    fn iterations(&self) -> usize {
        self.inner.stats.iterations
    }
    #[getter]
    fn residual(&self) -> f64 {
        self.inner.stats.residual
    }
    #[getter]
    fn converged(&self) -> bool {
        self.inner.stats.converged
    }
    #[getter]
    fn load_steps(&self) -> usize {
        self.inner.stats.load_steps
    }
    /// Fraction of the tip load the returned shape carries.
    #[getter]
    fn load_factor(&self) -> f64 {
        self.inner.stats.load_factor
    }
    /// Solver statistics (the keys of `StaticsSolution.stats`).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        crate::statics::stats_dict(py, &self.inner.stats)
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = py.import("softrod._core")?.getattr("pcc_solve")?;
        slf.get().call.reduce(py, f)
    }
    /// Backbone frames (N, 4, 4) at other arc lengths `s` (m, deformed, along the chain).
    fn frames_at<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = arg::s)] s: Floats,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let ts = self
            .inner
            .chain()
            .backbone(&s.to_vec()?)
            .map_err(to_py_err)?;
        Ok(poses_array(py, &ts))
    }
    fn __repr__(&self) -> String {
        format!(
            "PccSolution(segments={}, converged={}, iterations={})",
            self.inner.segments.len(),
            self.inner.stats.converged,
            self.inner.stats.iterations
        )
    }
}

/// Statics of a PCC robot under tensions, pressures and a world-frame tip wrench.
///
/// Stationary potential energy of the Cosserat rod restricted to arcs (see docs/pcc.md),
/// solved by Newton with the exact Jacobian in (u_x, u_y, length) per segment.
///
/// Args:
///     robot: The `Robot`.
///     tensions: One tension per tendon (N, >= 0), in the order the tendons were added.
///     pressures: One gauge pressure per chamber (Pa).
///     tip_force: Tip force (N, world frame, 3 values).
///     tip_moment: Tip moment (N m, world frame, 3 values).
///     s: Arc lengths (m, along the deformed chain) of the returned frames.
///     n_points: Number of uniformly spaced frames when `s` is not given.
///     tolerance: Scaled residual (rad for bending, strain for stretching).
///     max_iterations: Newton iterations per load step.
///     continuation: Step the tip load if the direct solve fails.
///     max_load_steps: Load steps under continuation.
///     warm_start: A previous `Solution` or (n, 3) arc rows.
///     throw: Raise `ConvergenceError` on non-convergence (else return the last iterate).
///
/// Returns:
///     A `Solution`: `arcs` (n, 3) rows (curvature, plane_angle, length), `tip_pose` (4, 4),
///     `frames` (N, 4, 4) at `s`, `tendon_lengths`, solver statistics.
#[pyfunction]
#[pyo3(signature = (robot, tensions=None, pressures=None, *, tip_force=None, tip_moment=None,
                    s=None, n_points=None, tolerance=None, max_iterations=None, continuation=None,
                    max_load_steps=None, warm_start=None, throw=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn pcc_solve<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::robot)] robot: Bound<'py, PccRobot>,
    tensions: Option<Bound<'py, PyAny>>,
    pressures: Option<Bound<'py, PyAny>>,
    tip_force: Option<Bound<'py, PyAny>>,
    tip_moment: Option<Bound<'py, PyAny>>,
    s: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::n_points)] n_points: Option<i64>,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: Option<f64>,
    #[pyo3(from_py_with = arg::max_iterations)] max_iterations: Option<i64>,
    #[pyo3(from_py_with = arg::continuation)] continuation: Option<bool>,
    #[pyo3(from_py_with = arg::max_load_steps)] max_load_steps: Option<i64>,
    warm_start: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::throw)] throw: Option<bool>,
) -> PyResult<PccSolution> {
    let o = |v: &Option<Bound<'py, PyAny>>| {
        v.as_ref().map_or_else(|| py.None(), |b| b.clone().unbind())
    };
    let call = crate::model::Args::new(
        py,
        &[
            ("robot", robot.clone().into_any().unbind()),
            ("tensions", o(&tensions)),
            ("pressures", o(&pressures)),
            ("tip_force", o(&tip_force)),
            ("tip_moment", o(&tip_moment)),
            ("s", o(&s)),
            ("n_points", crate::model::obj(py, n_points)?),
            ("tolerance", crate::model::obj(py, tolerance)?),
            ("max_iterations", crate::model::obj(py, max_iterations)?),
            ("continuation", crate::model::obj(py, continuation)?),
            ("max_load_steps", crate::model::obj(py, max_load_steps)?),
            ("warm_start", o(&warm_start)),
            ("throw", crate::model::obj(py, throw)?),
        ],
    )?;
    let floats = |v: Option<Bound<'py, PyAny>>, name: &str| -> PyResult<Option<Floats>> {
        v.filter(|b| !b.is_none())
            .map(|b| Floats::from_arg(&b, name))
            .transpose()
    };
    let (tensions, pressures) = (
        floats(tensions, "tensions")?,
        floats(pressures, "pressures")?,
    );
    let (tip_force, tip_moment, s) = (
        floats(tip_force, "tip_force")?,
        floats(tip_moment, "tip_moment")?,
        floats(s, "s")?,
    );
    let robot = robot.borrow();
    let d = PccSolveOptions::default();
    let max = softrod::limits::MAX_ITERATIONS;
    let max_iterations = max_iterations.map_or(Ok(d.newton.max_iterations), |k| {
        count("max_iterations", k, 1, max)
    })?;
    let max_load_steps = max_load_steps.map_or(Ok(d.newton.max_load_steps), |k| {
        count("max_load_steps", k, 1, max)
    })?;
    let tolerance = tolerance.unwrap_or(d.newton.tolerance);
    let continuation = continuation.unwrap_or(d.newton.continuation);
    let throw = throw.unwrap_or(d.newton.throw);
    // Checked before anything is solved or allocated.
    let n_points = n_points.map_or(Ok(DEFAULT_FRAMES), |k| {
        count("n_points", k, 2, softrod::limits::MAX_SAMPLES)
    })?;
    let loads = PccLoads {
        tensions: tensions
            .map(|t| t.to_vec())
            .transpose()?
            .unwrap_or_default(),
        pressures: pressures
            .map(|p| p.to_vec())
            .transpose()?
            .unwrap_or_default(),
        tip_force: tip_force
            .map(|f| vector3(f, "tip_force"))
            .transpose()?
            .unwrap_or_else(Vector3::zeros),
        tip_moment: tip_moment
            .map(|m| vector3(m, "tip_moment"))
            .transpose()?
            .unwrap_or_else(Vector3::zeros),
    };
    let warm = match warm_start.filter(|w| !w.is_none()) {
        None => None,
        Some(w) => match w.cast::<PccSolution>() {
            Ok(sol) => Some(sol.get().inner.warm_start()),
            Err(_) => {
                let rows = rows3(&w, "warm_start")?;
                Some(
                    pcc::PccChain::from_parameters(&rows)
                        .map_err(|e| to_py_err(renamed(e, "segments", "warm_start")))?
                        .segments()
                        .to_vec(),
                )
            }
        },
    };
    let options = PccSolveOptions {
        newton: softrod::NewtonOptions {
            tolerance,
            max_iterations,
            continuation,
            max_load_steps,
            throw,
        },
        warm_start: warm,
    };
    let samples = match s {
        Some(s) => Some(s.to_vec()?),
        None => None,
    };
    let model = &robot.inner;
    let solved_loads = loads.clone();
    let (inner, s, frames) = run(py, "pcc.solve", move || {
        let sol = statics::solve_pcc_statics(model, &loads, &options)?;
        let chain = sol.chain();
        let s = match samples {
            Some(s) => s,
            // Exactly 0 and exactly the chain's length at the ends.
            None => softrod::uniform_samples(chain.length(), n_points)?,
        };
        let frames = chain.backbone(&s)?;
        Ok((sol, s, frames))
    })?;
    Ok(PccSolution {
        inner,
        robot: model.clone(),
        loads: solved_loads,
        s,
        frames,
        call,
    })
}
