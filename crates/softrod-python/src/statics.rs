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

use crate::callbacks::{run, run_attached};
use crate::convert::{arg, count, floats_n};
use crate::errors::{param_err, to_py_err, type_err, StabilityError, StabilityWarning};
use crate::model::{Args, Chamber, Loads, Rod, Tendon};

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

/// The one keyword parser of the solve options: from the core's defaults, each given option
/// replaced (and checked, naming the keyword).
pub(crate) fn solve_options(a: &OptionArgs<'_>) -> PyResult<SolveOptions> {
    use softrod::limits::MAX_ITERATIONS;
    let mut o = SolveOptions::default();
    let defaults = AdaptiveOptions::default();
    // Tolerances are checked when given, whichever integrator uses them.
    let adaptive = AdaptiveOptions {
        rtol: a.rtol.unwrap_or(defaults.rtol),
        atol: a.atol.unwrap_or(defaults.atol),
        ..defaults
    }
    .validated()
    .map_err(to_py_err)?;
    o.integrator = match a.integrator.unwrap_or("rk4") {
        "rk4" => match (a.steps, o.integrator) {
            (Some(s), _) => Integrator::Rk4 {
                steps: count("steps", s, 1, softrod::cosserat::statics::MAX_RK4_STEPS)?,
            },
            (None, i) => i,
        },
        "adaptive" => Integrator::Adaptive(adaptive),
        other => {
            return Err(param_err(
                "integrator",
                format!("{other:?}"),
                "\"rk4\" or \"adaptive\"",
            ))
        }
    };
    if let Some(t) = a.tolerance {
        o.newton.tolerance = t;
    }
    if let Some(m) = a.max_iterations {
        o.newton.max_iterations = count("max_iterations", m, 1, MAX_ITERATIONS)?;
    }
    if let Some(c) = a.continuation {
        o.newton.continuation = c;
    }
    if let Some(m) = a.max_load_steps {
        o.newton.max_load_steps = count("max_load_steps", m, 1, MAX_ITERATIONS)?;
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
        } else {
            let b = floats_n(
                w,
                "warm_start",
                6,
                "a StaticsSolution or a base wrench [force; moment] of 6 numbers (N, N m)",
            )?;
            softrod::WarmStart::wrench([b[0], b[1], b[2], b[3], b[4], b[5]])
        });
    }
    o.validate().map_err(to_py_err)?;
    Ok(o)
}

/// The core model and actuation of the user's objects.
pub(crate) struct Problem {
    pub(crate) model: Arc<softrod::RobotModel>,
    pub(crate) actuation: softrod::Actuation,
    /// Whether a Python callable is part of the model (parallel work needs its own pool).
    pub(crate) has_callables: bool,
}

impl Problem {
    pub(crate) fn new(
        rod: &Rod,
        tendons: &[Bound<'_, Tendon>],
        loads: Option<&Loads>,
        chambers: &[Bound<'_, Chamber>],
    ) -> PyResult<Self> {
        let (r, l) = (rod.inner.clone(), loads.map(|l| l.inner.clone()));
        let ts: Vec<softrod::Tendon> = tendons.iter().map(|t| t.get().inner.clone()).collect();
        let cs: Vec<softrod::Chamber> = chambers.iter().map(|c| c.get().inner.clone()).collect();
        let has_callables = rod.has_callables()
            || tendons.iter().any(|t| t.get().has_callables())
            || chambers.iter().any(|c| c.get().has_callables())
            || loads.is_some_and(Loads::has_callables);
        // Validation calls the callables on the rod's check points.
        let model = run_attached("RobotModel", || {
            softrod::RobotModel::new(r, ts, cs, l.unwrap_or_default())
        })?;
        let tensions: Vec<f64> = tendons.iter().map(|t| t.get().tension).collect();
        let pressures: Vec<f64> = chambers.iter().map(|c| c.get().pressure).collect();
        let actuation = softrod::Actuation::tensions(&tensions).with_pressures(&pressures);
        Ok(Self {
            model,
            actuation,
            has_callables,
        })
    }
}

/// Applies `displacements` (one per tendon: a number (m) holds the tendon at that pull-in of
/// its base end, `None` or NaN keeps it tension-controlled) and `tendon_stiffness` (N/m, one
/// number or one per tendon; default inextensible) to `actuation`.
pub(crate) fn apply_displacements(
    actuation: &mut softrod::Actuation,
    n_tendons: usize,
    displacements: Option<&Bound<'_, PyAny>>,
    stiffness: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let Some(d) = displacements.filter(|d| !d.is_none()) else {
        if stiffness.is_some_and(|k| !k.is_none()) {
            return Err(param_err(
                "tendon_stiffness",
                "(given)",
                "given only with displacements (it is the stiffness of the held tendons)",
            ));
        }
        return Ok(());
    };
    let what = "a sequence of one number (m) or None per tendon";
    let items = crate::convert::sequence(d, "displacements", what)?;
    if items.len() != n_tendons {
        return Err(param_err(
            "displacements.len()",
            items.len(),
            &format!("the number of tendons, {n_tendons}"),
        ));
    }
    let values: Vec<f64> = items
        .iter()
        .enumerate()
        .map(|(i, x)| {
            if x.is_none() {
                Ok(f64::NAN)
            } else {
                crate::convert::Arg::from_arg(x, &format!("displacements[{i}]"))
            }
        })
        .collect::<PyResult<_>>()?;
    let k: Vec<f64> = match stiffness.filter(|k| !k.is_none()) {
        None => vec![f64::INFINITY; n_tendons],
        Some(k) => {
            let v = crate::convert::floats_opt(Some(k), "tendon_stiffness")?;
            match v.len() {
                1 => vec![v[0]; n_tendons],
                n if n == n_tendons => v,
                n => {
                    return Err(param_err(
                        "tendon_stiffness.len()",
                        n,
                        &format!("1 or the number of tendons, {n_tendons}"),
                    ))
                }
            }
        }
    };
    if actuation.tendons.len() != n_tendons {
        actuation.tendons = vec![softrod::TendonInput::Tension(0.0); n_tendons];
    }
    for (i, (&x, &ki)) in values.iter().zip(&k).enumerate() {
        if !x.is_nan() {
            if !(x.is_finite() && x.abs() <= softrod::limits::MAX_LENGTH) {
                return Err(param_err(
                    &format!("displacements[{i}]"),
                    x,
                    &format!(
                        "finite, |value| <= {} m (or None: tension control)",
                        softrod::limits::MAX_LENGTH
                    ),
                ));
            }
            if ki.is_nan() || ki <= 0.0 {
                return Err(param_err(
                    &format!("tendon_stiffness[{i}]"),
                    ki,
                    "> 0 N/m (inf: inextensible)",
                ));
            }
            actuation.tendons[i] = softrod::TendonInput::Displacement {
                displacement: x,
                stiffness: ki,
            };
        }
    }
    Ok(())
}

/// The core's `tensions[i]` / `pressures[i]` as the Python objects that carry them:
/// `tendons[i].tension`, `chambers[i].pressure`.
pub(crate) fn actuator_names(e: softrod::Error) -> softrod::Error {
    match e {
        softrod::Error::InvalidParameter {
            name,
            value,
            expected,
        } => {
            let rename = |prefix: &str, object: &str, field: &str| -> Option<String> {
                let index = name.strip_prefix(prefix)?.strip_suffix(']')?;
                index
                    .parse::<usize>()
                    .ok()
                    .map(|i| format!("{object}[{i}].{field}"))
            };
            let name = rename("tensions[", "tendons", "tension")
                .or_else(|| rename("pressures[", "chambers", "pressure"))
                .unwrap_or(name);
            softrod::Error::InvalidParameter {
                name,
                value,
                expected,
            }
        }
        other => other,
    }
}

/// A solved rod, sampled at the integration mesh (SI units, world frame unless `_body`).
///
/// Positions (m), rotations, internal force (N) and moment (N m), strains, tendon lengths (m),
/// base wrench (N, N m), solver stats; it pickles (by solving again, bit for bit).
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct StaticsSolution {
    pub(crate) inner: softrod::StaticsSolution,
    /// The friction state of a frictional solve (tension along the tendons, slip).
    pub(crate) friction: Option<Arc<softrod::FrictionalSolution>>,
    cache: [PyOnceLock<Py<PyAny>>; 12],
    /// The call that produced it (for pickling: it is solved again, bit for bit).
    call: Args,
    /// Contacts, contact forces and the tip reaction (with obstacles or a tip constraint).
    contact: crate::contact::ContactData,
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
    /// forces as dead loads, is the same) or when not converged. Computed on first read.
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
                softrod::reference_lengths(&inner.model, &inner.options)
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
                    chambers=Vec::new(), s_out=None, seek_stable=None, on_unstable=None,
                    previous=None, displacements=None, tendon_stiffness=None,
                    obstacles=None, tip_constraint=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_statics<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::rod)] rod: Bound<'py, Rod>,
    #[pyo3(from_py_with = arg::tendons)] tendons: Vec<Bound<'py, Tendon>>,
    #[pyo3(from_py_with = arg::loads)] loads: Option<Bound<'py, Loads>>,
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
    #[pyo3(from_py_with = arg::chambers)] chambers: Vec<Bound<'py, Chamber>>,
    s_out: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = arg::seek_stable)] seek_stable: Option<bool>,
    on_unstable: Option<&'py str>,
    previous: Option<Bound<'py, PyAny>>,
    displacements: Option<Bound<'py, PyAny>>,
    tendon_stiffness: Option<Bound<'py, PyAny>>,
    obstacles: Option<Bound<'py, PyAny>>,
    tip_constraint: Option<Bound<'py, PyAny>>,
) -> PyResult<StaticsSolution> {
    let previous = previous.filter(|p| !p.is_none());
    let prev_state: Option<Arc<softrod::FrictionalSolution>> = match &previous {
        None => None,
        Some(p) => {
            let Ok(p) = p.cast::<StaticsSolution>() else {
                return Err(type_err("previous", p, "a StaticsSolution (or None)"));
            };
            match &p.get().friction {
                Some(f) => Some(Arc::clone(f)),
                None => {
                    return Err(param_err(
                        "previous",
                        "a frictionless solution",
                        "a solution of a solve with friction (a tendon with friction > 0)",
                    ))
                }
            }
        }
    };
    let obstacle_list = crate::contact::obstacles(py, obstacles.as_ref())?;
    let tip = crate::contact::tip_constraint(tip_constraint.as_ref())?;
    let constrained = tip.is_some() || !obstacle_list.is_empty();
    let warm_start = warm_start.filter(|w| !w.is_none());
    let unstable = self::on_unstable(on_unstable)?;
    let s_values = crate::convert::floats_opt(s_out.as_ref(), "s_out")?;
    if constrained && !s_values.is_empty() {
        return Err(crate::errors::param_err(
            "s_out",
            format!("{s_values:?}"),
            "None with obstacles or a tip constraint (the solution is at the integration mesh)",
        ));
    }
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
    let problem = Problem::new(
        rod.get(),
        &tendons,
        loads.as_ref().map(Bound::get),
        &chambers,
    )?;
    let mut actuation = problem.actuation.clone();
    apply_displacements(
        &mut actuation,
        problem.model.tendons().len(),
        displacements.as_ref(),
        tendon_stiffness.as_ref(),
    )?;
    if actuation.has_held() {
        if let Some(w) = warm_start
            .as_ref()
            .and_then(|w| w.cast::<StaticsSolution>().ok())
        {
            let prev = &w.get().inner;
            if prev.tendon_tensions.len() == problem.model.tendons().len()
                && prev.tendon_tensions.iter().all(|t| t.is_finite())
            {
                actuation.tension_guess = Some(prev.tendon_tensions.clone());
            }
        }
    }
    if constrained && actuation.has_held() {
        return Err(crate::errors::param_err(
            "displacements",
            "given",
            "None with obstacles or a tip constraint (tension control only)",
        ));
    }
    let (model, act) = (&problem.model, &actuation);
    let frictional = prev_state.is_some()
        || model
            .tendons()
            .iter()
            .any(|t| t.friction() > 0.0 || t.is_guided());
    if frictional && !s_values.is_empty() {
        return Err(param_err(
            "s_out",
            format!("{} arc lengths", s_values.len()),
            "None with friction (the solution is reported at the friction mesh)",
        ));
    }
    if frictional && constrained {
        return Err(param_err(
            "obstacles",
            "obstacles or a tip constraint with tendon friction",
            "no obstacles and no tip constraint when a tendon has friction (not modelled together)",
        ));
    }
    let (result, friction, contact) = if frictional {
        let fo = softrod::FrictionOptions {
            statics: options,
            ..Default::default()
        };
        let f = run(py, "solve_statics", || {
            softrod::solve_frictional(model, act, &fo, prev_state.as_deref())
                .map_err(actuator_names)
        })?;
        (
            f.statics.clone(),
            Some(Arc::new(f)),
            crate::contact::ContactData::default(),
        )
    } else {
        let (r, c) = run(py, "solve_statics", || {
            if constrained {
                let c =
                    softrod::solve_constrained(model, act, &options, tip.as_ref(), &obstacle_list)
                        .map_err(actuator_names)?;
                let data = crate::contact::ContactData::from_solution(&c);
                Ok((c.solution, data))
            } else {
                softrod::compliance::solve_at_output(model, act, &options, &s_values)
                    .map_err(actuator_names)
                    .map(|r| (r, crate::contact::ContactData::default()))
            }
        })?;
        (r, None, c)
    };
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
            ("previous", o(previous.map(Bound::unbind))),
            ("displacements", o(displacements.map(Bound::unbind))),
            ("tendon_stiffness", o(tendon_stiffness.map(Bound::unbind))),
            ("obstacles", o(obstacles.map(Bound::unbind))),
            ("tip_constraint", o(tip_constraint.map(Bound::unbind))),
        ],
    )?;
    let sol = StaticsSolution {
        inner: result,
        friction,
        cache: std::array::from_fn(|_| PyOnceLock::new()),
        call,
        contact,
    };
    report_unstable(py, sol, unstable)
}

/// The actuation Jacobian of a statics solution (Cosserat `StaticsSolution` or
/// `PccSolution`): the derivative of the pose twist `[δp; δθ]` (m, rad; world frame, the
/// robot's base frame for PCC) of node `node` (default -1: the tip; negative counts from the
/// end; PCC: the tip only) with respect to each tendon tension (per N), then each chamber
/// pressure (per Pa), every tendon at fixed tension; shape (6, n_tendons + n_chambers). Exact:
/// from the linearised boundary-value problem (Cosserat) or the equilibrium Jacobian (PCC),
/// no finite differences.
#[pyfunction]
#[pyo3(signature = (solution, node=-1))]
pub(crate) fn actuation_jacobian<'py>(
    py: Python<'py>,
    solution: Bound<'py, PyAny>,
    #[pyo3(from_py_with = arg::node)] node: i64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let to_array = |m: &softrod::nalgebra::DMatrix<f64>| {
        Array::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
    };
    if let Ok(s) = solution.cast::<StaticsSolution>() {
        let inner = &s.get().inner;
        let n = inner.s.len() as i64;
        let index = if node < 0 { n + node } else { node };
        if !(0..n).contains(&index) {
            return Err(param_err(
                "node",
                node,
                &format!("a node index in [-{n}, {n})"),
            ));
        }
        let j = run(py, "actuation_jacobian", || {
            softrod::actuation_jacobian(inner, Some(index as usize))
        })?;
        return Ok(to_array(&j));
    }
    if let Ok(s) = solution.cast::<crate::pcc::PccSolution>() {
        let sol = s.get();
        if node != -1 {
            return Err(param_err(
                "node",
                node,
                "-1 (the tip: the PCC actuation Jacobian is at the tip)",
            ));
        }
        let j = run(py, "actuation_jacobian", || {
            softrod::pcc::pcc_actuation_jacobian(&sol.robot, &sol.loads, &sol.inner)
        })?;
        return Ok(to_array(&j));
    }
    Err(crate::errors::type_err(
        "solution",
        &solution,
        "a StaticsSolution or a PccSolution",
    ))
}

/// Benchmark hook: runs the same solve `repeats` times inside Rust and returns each call's
/// wall time (s), so that the Python overhead of `solve_statics` can be measured.
#[pyfunction]
#[pyo3(signature = (rod, tendons=Vec::new(), loads=None, *, repeats=1000, integrator=None,
                    steps=None, rtol=None, atol=None, tolerance=None, warm_start=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _time_solve_statics<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::rod)] rod: Bound<'py, Rod>,
    #[pyo3(from_py_with = arg::tendons)] tendons: Vec<Bound<'py, Tendon>>,
    #[pyo3(from_py_with = arg::loads)] loads: Option<Bound<'py, Loads>>,
    #[pyo3(from_py_with = arg::repeats)] repeats: i64,
    #[pyo3(from_py_with = arg::integrator)] integrator: Option<&'py str>,
    #[pyo3(from_py_with = arg::steps)] steps: Option<i64>,
    #[pyo3(from_py_with = arg::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = arg::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: Option<f64>,
    warm_start: Option<Bound<'py, PyAny>>,
) -> PyResult<Vec<f64>> {
    let repeats = count("repeats", repeats, 1, softrod::limits::MAX_SAMPLES)?;
    let options = solve_options(&OptionArgs {
        integrator,
        steps,
        rtol,
        atol,
        tolerance,
        warm_start: warm_start.filter(|w| !w.is_none()),
        ..Default::default()
    })?;
    let problem = Problem::new(rod.get(), &tendons, loads.as_ref().map(Bound::get), &[])?;
    let (model, act) = (&problem.model, &problem.actuation);
    run(py, "_time_solve_statics", || {
        let mut times = Vec::with_capacity(repeats);
        for _ in 0..repeats {
            let t0 = std::time::Instant::now();
            softrod::solve_statics(model, act, &options)?;
            times.push(t0.elapsed().as_secs_f64());
        }
        Ok(times)
    })
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
