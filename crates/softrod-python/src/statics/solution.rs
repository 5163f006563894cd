//! The solution of a statics solve as a Python class: arrays along the mesh (cached), the
//! solver statistics, the sensitivities and Jacobians, pickling.

use std::sync::Arc;

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple};

use crate::callbacks::run;
use crate::errors::{param_err, to_py_err, type_err};

/// A solved rod, sampled at the integration mesh (SI units, world frame unless `_body`).
///
/// Positions (m), rotations, internal force (N) and moment (N m), strains, tendon lengths (m),
/// base wrench (N, N m), solver stats; it pickles (by solving again, bit for bit).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct StaticsSolution {
    pub(crate) inner: softrod::StaticsSolution,
    /// The friction state of a frictional solve (tension along the tendons, slip).
    pub(crate) friction: Option<Arc<softrod::FrictionalSolution>>,
    /// The arrays made so far (by getter).
    pub(super) cache: [PyOnceLock<Py<PyAny>>; 12],
    /// The call that produced it (for pickling: it is solved again, bit for bit).
    pub(super) call: super::call::Call,
    /// Contacts, contact forces and the tip reaction (with obstacles or a tip constraint).
    pub(super) contact: crate::contact::ContactData,
    /// The robot as solved (with its guides: the rod of a disk-guided solution, `inner.model`,
    /// carries the guide forces instead), the model of the displacements' zero.
    pub(super) robot: Arc<softrod::RobotModel>,
}

fn rows3(py: Python<'_>, v: &[[f64; 3]]) -> Py<PyAny> {
    let a = Array::from_shape_fn((v.len(), 3), |(i, j)| v[i][j]);
    a.into_pyarray(py).into_any().unbind()
}

impl StaticsSolution {
    /// Whether a tendon pulls through discrete guides: the stability of such an equilibrium
    /// is not assessed (the rod is solved under the guide forces held in the guides' frames,
    /// which leaves out the chords' own stiffness; docs/friction.md).
    pub(crate) fn pulled_through_guides(&self) -> bool {
        self.friction
            .as_ref()
            .is_some_and(|f| !f.stability_assessed())
    }

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
    /// Tension (N) along each tendon at every sample, shape (N, n_tendons): the base tension
    /// for a frictionless tendon, the capstan profile with friction; 0 beyond a termination.
    #[getter]
    fn tendon_tension<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let sol = &self.inner;
        let model = &sol.model;
        let nt = model.tendons().len();
        let a = match &self.friction {
            Some(f) => Array::from_shape_fn((f.tension.len(), nt), |(j, i)| f.tension[j][i]),
            None => {
                let base = sol.tensions();
                let (ends, l) = (model.tendon_ends(), model.length());
                Array::from_shape_fn((sol.s.len(), nt), |(j, i)| {
                    let s = sol.s[j];
                    if s < ends[i] || (ends[i] == l && s == l) {
                        base[i]
                    } else {
                        0.0
                    }
                })
            }
        };
        a.into_pyarray(py)
    }
    /// Friction force on the rod per unit length (N/m, world), `dτ/ds` times the tendon's
    /// path tangent, shape (N, n_tendons, 3); zero without friction.
    #[getter]
    fn friction_force<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let n = self.inner.s.len();
        let nt = self.inner.model.tendons().len();
        let a = match &self.friction {
            Some(f) => Array::from_shape_fn((n, nt, 3), |(j, i, k)| f.friction_force[j][i][k]),
            None => Array::zeros((n, nt, 3)),
        };
        a.into_pyarray(py)
    }
    /// Slip state of every tendon element, shape (N, n_tendons): +1 sliding toward the base
    /// (loading), -1 sliding toward the tip (unloading), 0 sticking or beyond the
    /// termination; +1 for a frictionless solve's tendons within their length.
    #[getter]
    fn slip<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i8>> {
        let sol = &self.inner;
        let model = &sol.model;
        let nt = model.tendons().len();
        let a = match &self.friction {
            Some(f) => Array::from_shape_fn((f.slip.len(), nt), |(j, i)| f.slip[j][i].sign()),
            None => {
                let (ends, l) = (model.tendon_ends(), model.length());
                Array::from_shape_fn((sol.s.len(), nt), |(j, i)| {
                    let s = sol.s[j];
                    i8::from(s < ends[i] || (ends[i] == l && s == l))
                })
            }
        };
        a.into_pyarray(py)
    }
    /// Per tendon, its anchors when it runs through guides (`Tendon(..., guides=...)`): a
    /// list of dicts with `s` (m), `point` (m, world), `wrap` (rad), `friction`,
    /// `tension_in` and `tension_out` (N, of the chords into and out of it), `slip` (+1, -1,
    /// 0) and `force` (N, world, the tendon's force on the rod), from the base hole to the
    /// termination; an empty list for a tendon in a continuous channel (or without friction
    /// modelled).
    #[getter]
    fn guides<'py>(&self, py: Python<'py>) -> PyResult<Vec<Vec<Bound<'py, PyDict>>>> {
        let nt = self.inner.model.tendons().len();
        let Some(f) = &self.friction else {
            return Ok(vec![Vec::new(); nt]);
        };
        f.guides
            .iter()
            .map(|row| {
                row.iter()
                    .map(|g| {
                        let d = PyDict::new(py);
                        d.set_item("s", g.s)?;
                        d.set_item("point", g.point.to_vec())?;
                        d.set_item("wrap", g.wrap)?;
                        d.set_item("friction", g.friction)?;
                        d.set_item("tension_in", g.tension_in)?;
                        d.set_item("tension_out", g.tension_out)?;
                        d.set_item("slip", g.slip.sign())?;
                        d.set_item("force", g.force.to_vec())?;
                        Ok(d)
                    })
                    .collect()
            })
            .collect()
    }

    /// Whether the solve modelled tendon friction (a tendon with `friction > 0` or a
    /// `previous` state).
    #[getter]
    fn frictional(&self) -> bool {
        self.friction.is_some()
    }
    /// Marches (one per quasi-Newton iterate of the base wrench, 1 without external loads)
    /// or, when the one-march solve fell back to it, rod solves of the fixed point on the
    /// profile; 0 without friction.
    #[getter]
    fn friction_iterations(&self) -> usize {
        self.friction.as_ref().map_or(0, |f| f.iterations)
    }
    /// Path length (m) of every tendon from the base to every sample, shape (N, n_tendons)
    /// (the whole path length beyond its termination), from the integrator's quadrature;
    /// `None` for a frictionless solve. The slip of a tendon toward the base at a sample
    /// between two states is the change of `tendon_lengths - path_length` there.
    #[getter]
    fn path_length<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        let f = self.friction.as_ref()?;
        let nt = self.inner.model.tendons().len();
        let a = Array::from_shape_fn((f.path_length.len(), nt), |(j, i)| f.path_length[j][i]);
        Some(a.into_pyarray(py))
    }
    /// The active contacts, one dict each: `obstacle` (index), `s` (m), `length` (m, 0 for a
    /// point contact; a contact interval on a plane otherwise), `point` (m, world, on the
    /// rod's surface), `normal` (the obstacle's outward unit normal), `normal_force` (N,
    /// >= 0), `tangential_force` (N, world; zero without friction), `state`
    /// (`"frictionless"`, `"stick"` or `"slide"`). Empty without obstacles.
    #[getter]
    fn contacts(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.contact.contacts_py(py)
    }
    /// Contact force on the rod at every sample (N, world), shape (N, 3); zeros without
    /// obstacles.
    #[getter]
    fn contact_force(&self, py: Python<'_>) -> Py<PyAny> {
        match &self.contact.contact_force {
            Some(f) => rows3(py, f),
            None => rows3(py, &vec![[0.0; 3]; self.inner.s.len()]),
        }
    }
    /// Reaction wrench [force; moment] of the tip constraint on the rod (N, N m; world),
    /// shape (6,), or None without a tip constraint.
    #[getter]
    fn tip_reaction(&self, py: Python<'_>) -> Option<Py<PyAny>> {
        self.contact
            .tip_reaction
            .map(|r| r.to_vec().into_pyarray(py).into_any().unbind())
    }
    /// Tangent compliance of the tip with the active contacts and the tip constraint as
    /// constraints (frictionless contacts hold the normal only), `[dp; dtheta]` of the tip
    /// (m, rad; world) per `[dF; dM]` of a dead tip load (N, N m; world), shape (6, 6); None
    /// without obstacles and tip constraint (then `tangent_compliance`, which treats contact
    /// forces as dead loads, is the same), when not converged, or with a belt (a contact
    /// interval on a curved obstacle: not linearised). Computed on first read.
    #[getter]
    fn contact_compliance<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        self.contact
            .compliance
            .get()
            .map(|m| Array::from_shape_fn((6, 6), |(i, j)| m[(i, j)]).into_pyarray(py))
    }
    /// Tension carried by each tendon (N), shape (n_tendons,): the input of a
    /// tension-controlled tendon, the solved tension of a displacement-controlled one (0 when
    /// slack).
    #[getter]
    fn tendon_tensions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.tendon_tensions.clone().into_pyarray(py)
    }
    /// Displacement of each tendon (m, shape (n_tendons,)): the shortening of its path at the
    /// base relative to the robot at zero actuation, `reference - tendon_lengths` (computed
    /// once per solution: one more solve at zero actuation unless it was displacement
    /// controlled).
    #[getter]
    fn tendon_displacements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let inner = &self.inner;
        let reference = match &inner.actuation.reference_lengths {
            Some(r) => r.clone(),
            None => run(py, "tendon_displacements", || {
                softrod::reference_lengths(&self.robot, &inner.options)
            })?,
        };
        Ok(reference
            .iter()
            .zip(&inner.tendon_lengths)
            .map(|(r, l)| r - l)
            .collect::<Vec<f64>>()
            .into_pyarray(py))
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
    /// Tendon tensions (N), shape (n_tendons,), as `tendon_tensions`.
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
    /// tension, dead loads; with obstacles and a free tip, frictionless point contacts held)
    /// is positive definite; always True without external loads or contacts, False for a
    /// result that did not converge; None (not assessed) when a tendon pulls through disk
    /// guides (docs/stability.md).
    #[getter]
    fn stable(&self) -> Option<bool> {
        (!self.pulled_through_guides()).then_some(self.inner.stable)
    }
    /// Smallest eigenvalue of the symmetric part of the dimensionless tip tangent stiffness
    /// D K D / (EI(0)/L), D = diag(L, L, L, 1, 1, 1): > 0 for a stable equilibrium; NaN if
    /// not converged or not assessed (a tendon pulling through disk guides;
    /// docs/stability.md).
    #[getter]
    fn stability_margin(&self, py: Python<'_>) -> f64 {
        if self.pulled_through_guides() {
            return f64::NAN;
        }
        py.detach(|| self.inner.stability_margin())
    }
    /// The RK4 steps of the mesh this solution was solved on (a default solve refined for a
    /// shape the default 40 steps cannot resolve reports its finer mesh); `None` with the
    /// adaptive integrator.
    #[getter]
    fn steps(&self) -> Option<usize> {
        match self.inner.options.integrator {
            softrod::Integrator::Rk4 { steps } => Some(steps),
            _ => None,
        }
    }
    /// Solver statistics: iterations, residual, function_evaluations, load_steps, load_factor,
    /// converged.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        stats_dict(py, &self.inner.stats)
    }
    /// Exact derivatives of this equilibrium with respect to named inputs and parameters (the
    /// linearised boundary-value problem on the solution's own mesh; no finite differences).
    ///
    /// `parameters`: names `tension[i]` (per N), `pressure[j]` (per Pa), `tension_scale`,
    /// `stiffness_scale`, `tendon_offset_scale[i]`, `chamber_area_scale[j]` (per unit factor at
    /// 1), `base_translation[k]` (per m), `base_rotation[k]` (per rad, world axis k). `nodes`:
    /// sample indices (default all). Returns a dict: `parameters`, `nodes`, `s` (m), `pose`
    /// (n_nodes, 6, n_parameters: position in m and rotation in rad, world frame, per unit of
    /// each parameter), `base_wrench` (6, n_parameters; N, N m) and `tendon_lengths`
    /// (n_tendons, n_parameters; m).
    #[pyo3(signature = (parameters, nodes=None))]
    fn sensitivities<'py>(
        &self,
        py: Python<'py>,
        parameters: Bound<'py, PyAny>,
        nodes: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let parameters: Vec<String> = items(&parameters, "parameters", "a list of names")?
            .iter()
            .enumerate()
            .map(|(k, item)| {
                item.extract::<String>()
                    .map_err(|_| type_err(&format!("parameters[{k}]"), item, "a name (str)"))
            })
            .collect::<PyResult<_>>()?;
        let nodes: Option<Vec<i64>> = nodes
            .filter(|b| !b.is_none())
            .map(|b| {
                items(&b, "nodes", "a list of node indices")?
                    .iter()
                    .enumerate()
                    .map(|(k, item)| {
                        if item.is_instance_of::<pyo3::types::PyBool>() {
                            return Err(type_err(&format!("nodes[{k}]"), item, "an integer"));
                        }
                        item.extract::<i64>()
                            .map_err(|_| type_err(&format!("nodes[{k}]"), item, "an integer"))
                    })
                    .collect::<PyResult<Vec<_>>>()
            })
            .transpose()?;
        if self.contact.constrained() {
            return Err(param_err(
                "solution",
                "a solution with active contacts or a tip constraint",
                "a solution without active contacts or tip constraint (its sensitivities \
                 would hold the contact forces and the tip reaction as dead loads)",
            ));
        }
        let params = parameters
            .iter()
            .enumerate()
            .map(|(k, name)| parse_parameter(k, name))
            .collect::<PyResult<Vec<_>>>()?;
        let n = self.inner.s.len();
        let nodes: Vec<usize> = match nodes {
            None => (0..n).collect(),
            Some(v) => v
                .iter()
                .enumerate()
                .map(|(k, &i)| {
                    usize::try_from(i).ok().filter(|&i| i < n).ok_or_else(|| {
                        param_err(&format!("nodes[{k}]"), i, &format!("in [0, {n})"))
                    })
                })
                .collect::<PyResult<_>>()?,
        };
        let sol = &self.inner;
        let sens = py
            .detach(|| {
                softrod::sensitivities(sol, &params, &nodes, softrod::Linearisation::Actuated)
            })
            .map_err(to_py_err)?;
        let np = params.len();
        let nn = sens.nodes.len();
        let pose = Array::from_shape_fn((nn, 6, np), |(i, r, c)| sens.pose[i][(r, c)]);
        let bw = Array::from_shape_fn((6, np), |(r, c)| sens.base_wrench[(r, c)]);
        let nt = sens.tendon_lengths.nrows();
        let tl = Array::from_shape_fn((nt, np), |(r, c)| sens.tendon_lengths[(r, c)]);
        let d = PyDict::new(py);
        d.set_item("parameters", parameters)?;
        d.set_item("nodes", sens.nodes.clone())?;
        d.set_item("s", sens.s.clone().into_pyarray(py))?;
        d.set_item("pose", pose.into_pyarray(py))?;
        d.set_item("base_wrench", bw.into_pyarray(py))?;
        d.set_item("tendon_lengths", tl.into_pyarray(py))?;
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
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        slf.get().call.reduce(slf.py())
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

/// A sensitivity parameter from its name (`tension[2]`, `stiffness_scale`, ...).
fn parse_parameter(k: usize, name: &str) -> PyResult<softrod::Parameter> {
    use softrod::Parameter as P;
    let bad = || {
        param_err(
            &format!("parameters[{k}]"),
            format!("{name:?}"),
            "one of tension[i], pressure[j], tension_scale, stiffness_scale, \
             tendon_offset_scale[i], chamber_area_scale[j], base_translation[k], base_rotation[k]",
        )
    };
    match name {
        "tension_scale" => return Ok(P::TensionScale),
        "stiffness_scale" => return Ok(P::StiffnessScale),
        _ => {}
    }
    let (head, rest) = name.split_once('[').ok_or_else(bad)?;
    let index: usize = rest
        .strip_suffix(']')
        .and_then(|i| i.parse().ok())
        .ok_or_else(bad)?;
    Ok(match head {
        "tension" => P::Tension(index),
        "pressure" => P::Pressure(index),
        "tendon_offset_scale" => P::TendonOffsetScale(index),
        "chamber_area_scale" => P::ChamberAreaScale(index),
        "base_translation" if index < 3 => P::BaseTranslation(index),
        "base_rotation" if index < 3 => P::BaseRotation(index),
        _ => return Err(bad()),
    })
}

/// The items of a list-like argument (not a string), or a type error naming it.
fn items<'py>(
    b: &Bound<'py, PyAny>,
    name: &str,
    expected: &str,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    if b.is_instance_of::<pyo3::types::PyString>() || b.is_none() {
        return Err(type_err(name, b, expected));
    }
    let it = b.try_iter().map_err(|_| type_err(name, b, expected))?;
    it.collect::<PyResult<Vec<_>>>()
        .map_err(|_| type_err(name, b, expected))
}
