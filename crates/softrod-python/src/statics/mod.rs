//! Binding of the Cosserat statics: `solve_statics`, `Robot.solve` and their solution.
//!
//! The Python signature keeps the objects a user builds (a rod, tendons with their tensions,
//! chambers with their pressures, loads); the binding splits them into the core's immutable
//! `RobotModel` and its `Actuation`. A `softrod.Robot` keeps its core model (validated once)
//! and passes its tensions and pressures as the actuation. Options start from the core's
//! `SolveOptions::default()`: an option not given keeps the core's default (stated once, in
//! the core).
//!
//! The files: `options.rs` (the options, the core model and actuation of the user's objects,
//! displacement control, actuator names in errors), `robot.rs` (the model of a robot and its
//! solve), `call.rs` (the call a solution keeps for pickling), `solution.rs` (the solution
//! class).

mod call;
mod options;
pub(crate) mod robot;
mod solution;

use std::sync::Arc;

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

use crate::callbacks::run;
use crate::convert::{arg, count};
use crate::errors::{param_err, type_err, StabilityError, StabilityWarning};
use crate::model::{Chamber, Loads, Rod, Tendon};

use call::{Call, Subject};
use options::Names;
pub(crate) use options::{
    actuator_names, apply_displacements, solve_options, Given, OptionArgs, Problem,
};
pub(crate) use solution::{stats_dict, StaticsSolution};

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
    if mode == OnUnstable::Ignore
        || inner.stable
        || !inner.stats.converged
        || sol.pulled_through_guides()
    {
        return Ok(sol);
    }
    let margin = inner.stability_margin();
    // (A solve with contacts or a held tip does not look for a stable equilibrium.)
    let after = if sol.contact.contact_force.is_some() {
        "with its contacts held; a solve with obstacles or a tip constraint reports it as found"
    } else {
        "and no stable equilibrium was found from it"
    };
    let why = if margin > -softrod::cosserat::NEUTRAL_MARGIN {
        "the tip stiffness is positive, but the rod would buckle between its ends (a conjugate \
         point of the rod with its tip clamped too), or the mesh does not resolve its buckling \
         under its compression (raise the RK4 steps)"
    } else {
        "the tip tangent stiffness is not positive definite"
    };
    let msg = format!(
        "the equilibrium returned is unstable (stability margin {margin:.4e}: {why}) {after}; \
         see docs/stability.md"
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
    #[pyo3(from_py_with = arg::on_unstable)] on_unstable: Option<&'py str>,
    previous: Option<Bound<'py, PyAny>>,
    displacements: Option<Bound<'py, PyAny>>,
    tendon_stiffness: Option<Bound<'py, PyAny>>,
    obstacles: Option<Bound<'py, PyAny>>,
    tip_constraint: Option<Bound<'py, PyAny>>,
) -> PyResult<StaticsSolution> {
    solve(
        py,
        Source::Objects {
            rod,
            tendons,
            loads,
            chambers,
        },
        Keywords {
            integrator,
            given: Given {
                steps,
                rtol,
                atol,
                tolerance,
                max_iterations,
                continuation,
                max_load_steps,
                throw,
                seek_stable,
            },
            warm_start,
            s_out,
            on_unstable,
            previous,
            displacements,
            tendon_stiffness,
            obstacles,
            tip_constraint,
        },
    )
}

/// The robot of a solve: the user's objects (a model built for this call), or a robot's
/// model (built once) with the tensions and pressures given (`None`: its objects').
pub(crate) enum Source<'py> {
    Objects {
        rod: Bound<'py, Rod>,
        tendons: Vec<Bound<'py, Tendon>>,
        loads: Option<Bound<'py, Loads>>,
        chambers: Vec<Bound<'py, Chamber>>,
    },
    Robot {
        model: Bound<'py, robot::RobotModel>,
        tensions: Option<Vec<f64>>,
        pressures: Option<Vec<f64>>,
    },
}

impl Source<'_> {
    /// The core model, the actuation, the names of the actuation in the core's errors and
    /// the call's subject (kept for pickling).
    fn resolve(self) -> PyResult<(Arc<softrod::RobotModel>, softrod::Actuation, Names, Subject)> {
        match self {
            Source::Objects {
                rod,
                tendons,
                loads,
                chambers,
            } => {
                let problem = Problem::new(&rod, &tendons, loads.as_ref(), &chambers)?;
                let subject = Subject::Objects {
                    rod: rod.unbind(),
                    tendons: tendons.into_iter().map(Bound::unbind).collect(),
                    loads: loads.map(Bound::unbind),
                    chambers: chambers.into_iter().map(Bound::unbind).collect(),
                };
                Ok((problem.model, problem.actuation, Names::OBJECTS, subject))
            }
            Source::Robot {
                model,
                tensions,
                pressures,
            } => {
                let m = model.get();
                let (actuation, names) = m.actuation(tensions.as_ref(), pressures.as_ref())?;
                let core = Arc::clone(&m.problem.model);
                let subject = Subject::Robot {
                    model: model.unbind(),
                    tensions,
                    pressures,
                };
                Ok((core, actuation, names, subject))
            }
        }
    }
}

/// The keyword arguments of a statics solve (`None`: not given).
pub(crate) struct Keywords<'py> {
    pub(crate) integrator: Option<&'py str>,
    pub(crate) given: Given,
    pub(crate) warm_start: Option<Bound<'py, PyAny>>,
    pub(crate) s_out: Option<Bound<'py, PyAny>>,
    pub(crate) on_unstable: Option<&'py str>,
    pub(crate) previous: Option<Bound<'py, PyAny>>,
    pub(crate) displacements: Option<Bound<'py, PyAny>>,
    pub(crate) tendon_stiffness: Option<Bound<'py, PyAny>>,
    pub(crate) obstacles: Option<Bound<'py, PyAny>>,
    pub(crate) tip_constraint: Option<Bound<'py, PyAny>>,
}

/// The one statics solve of the binding (`solve_statics`, `Robot.solve`): the options
/// checked, the model and actuation of `source`, the solve with the GIL released, the
/// solution.
fn solve<'py>(py: Python<'py>, source: Source<'py>, k: Keywords<'py>) -> PyResult<StaticsSolution> {
    let previous = k.previous.filter(|p| !p.is_none());
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
    let obstacle_list = crate::contact::obstacles(py, k.obstacles.as_ref())?;
    let tip = crate::contact::tip_constraint(k.tip_constraint.as_ref())?;
    let constrained = tip.is_some() || !obstacle_list.is_empty();
    let warm_start = k.warm_start.filter(|w| !w.is_none());
    let unstable = self::on_unstable(k.on_unstable)?;
    let s_values = crate::convert::floats_opt(k.s_out.as_ref(), "s_out")?;
    if constrained && !s_values.is_empty() {
        return Err(crate::errors::param_err(
            "s_out",
            format!("{} arc lengths", s_values.len()),
            "None with obstacles or a tip constraint (the solution is at the integration mesh)",
        ));
    }
    let args = OptionArgs {
        integrator: k.integrator,
        warm_start: warm_start.clone(),
        given: k.given,
    };
    let options = solve_options(&args)?;
    let (model, mut actuation, names, subject) = source.resolve()?;
    apply_displacements(
        &mut actuation,
        model.tendons().len(),
        k.displacements.as_ref(),
        k.tendon_stiffness.as_ref(),
    )?;
    if actuation.has_held() {
        if let Some(w) = warm_start
            .as_ref()
            .and_then(|w| w.cast::<StaticsSolution>().ok())
        {
            let prev = &w.get().inner;
            if prev.tendon_tensions.len() == model.tendons().len()
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
    let act = &actuation;
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
    let rename = |e| names.rename(e);
    let (result, friction, contact) = if frictional {
        let fo = softrod::FrictionOptions {
            statics: options,
            ..Default::default()
        };
        let f = run(py, "solve_statics", || {
            softrod::solve_frictional_checked(&model, act, &fo, prev_state.as_deref())
                .map_err(rename)
        })?;
        (
            f.statics.clone(),
            Some(Arc::new(f)),
            crate::contact::ContactData::default(),
        )
    } else {
        let (r, c) = run(py, "solve_statics", || {
            if constrained {
                let default = options.integrator.is_default_mesh();
                let c = softrod::cosserat::mesh::with_mesh_control(
                    &options,
                    default,
                    |o| softrod::solve_constrained(&model, act, o, tip.as_ref(), &obstacle_list),
                    |c| &c.solution,
                )
                .map_err(rename)?;
                let data = crate::contact::ContactData::from_solution(&c);
                Ok((c.solution, data))
            } else {
                softrod::cosserat::mesh::solve_at_output(&model, act, &options, &s_values)
                    .map_err(rename)
                    .map(|r| (r, crate::contact::ContactData::default()))
            }
        })?;
        (r, None, c)
    };
    let call = Call {
        subject,
        integrator: k.integrator.map(str::to_owned),
        given: k.given,
        warm_start: warm_start.map(Bound::unbind),
        s_out: s_values,
        previous: previous.map(Bound::unbind),
        displacements: k.displacements.map(Bound::unbind),
        tendon_stiffness: k.tendon_stiffness.map(Bound::unbind),
        obstacles: k.obstacles.map(Bound::unbind),
        tip_constraint: k.tip_constraint.map(Bound::unbind),
    };
    let sol = StaticsSolution {
        inner: result,
        friction,
        cache: std::array::from_fn(|_| PyOnceLock::new()),
        call,
        contact,
        robot: model,
    };
    report_unstable(py, sol, unstable)
}

/// The actuation Jacobian of a statics solution (Cosserat `StaticsSolution` or
/// `PccSolution`): the derivative of the pose twist `[δp; δθ]` (m, rad; world frame, the
/// robot's base frame for PCC) of node `node` (default -1: the tip; negative counts from the
/// end; PCC: the tip only) with respect to each tendon tension (per N), then each chamber
/// pressure (per Pa), every tendon at fixed tension; shape (6, n_tendons + n_chambers). Exact:
/// from the linearised boundary-value problem (Cosserat) or the equilibrium Jacobian (PCC),
/// no finite differences. For a frictional equilibrium the derivative is one-sided:
/// `direction` 1 (default, None: the same; "pull" or "load": increasing inputs, continued from the
/// solution) or -1 ("release" or "unload": decreasing inputs, the column
/// `(f(a) - f(a - h e)) / h`); for any other
/// solution the two agree. With active contacts or a tip constraint, the contacts and the
/// held tip directions are constraints (`ContactCompliance::actuation_jacobian`; friction at
/// a contact is refused naming `solution`).
#[pyfunction]
#[pyo3(signature = (solution, node=-1, direction=None))]
pub(crate) fn actuation_jacobian<'py>(
    py: Python<'py>,
    solution: Bound<'py, PyAny>,
    #[pyo3(from_py_with = arg::node)] node: i64,
    direction: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let direction = match &direction {
        Some(d) => jacobian_direction(d)?,
        None => softrod::Direction::Pull,
    };
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
        let contact = &s.get().contact;
        let j = if contact.constrained() {
            // The active contacts and the held tip directions as constraints (their
            // reactions move with the actuation).
            run(py, "actuation_jacobian", || {
                contact
                    .compliance
                    .actuation_jacobian(inner, Some(index as usize))
            })?
        } else {
            run(py, "actuation_jacobian", || {
                softrod::directional_actuation_jacobian(inner, Some(index as usize), direction)
            })?
        };
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

/// The direction of a one-sided derivative of a frictional equilibrium (the actuation
/// Jacobian, the tangent compliance): 1, "pull" or "load" (increasing inputs), -1, "release"
/// or "unload" (decreasing inputs).
pub(crate) fn jacobian_direction(value: &Bound<'_, PyAny>) -> PyResult<softrod::Direction> {
    if value.is_instance_of::<pyo3::types::PyBool>() {
        // A bool is an int in Python: not a direction.
    } else if let Ok(v) = value.extract::<i64>() {
        match v {
            1 => return Ok(softrod::Direction::Pull),
            -1 => return Ok(softrod::Direction::Release),
            _ => {}
        }
    } else if let Ok(v) = value.extract::<String>() {
        match v.as_str() {
            "pull" | "load" => return Ok(softrod::Direction::Pull),
            "release" | "unload" => return Ok(softrod::Direction::Release),
            _ => {}
        }
    }
    Err(param_err(
        "direction",
        value
            .repr()
            .map_or_else(|_| "?".to_string(), |r| r.to_string()),
        "1, 'pull' or 'load' (increasing inputs), -1, 'release' or 'unload' (decreasing inputs)",
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
        warm_start: warm_start.filter(|w| !w.is_none()),
        given: Given::mesh(steps, rtol, atol, tolerance),
    })?;
    let problem = Problem::new(&rod, &tendons, loads.as_ref(), &[])?;
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
