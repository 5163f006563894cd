//! The options of a statics solve, the core model and actuation of the user's objects
//! (tension and displacement control) and the actuator names in the core's errors.

use std::sync::Arc;

use pyo3::prelude::*;

use softrod::{AdaptiveOptions, Integrator, SolveOptions};

use super::StaticsSolution;
use crate::callbacks::run_attached;
use crate::convert::{count, floats_n};
use crate::errors::{param_err, to_py_err};
use crate::model::{Chamber, Loads, Rod, Tendon};

/// The numerical solve options as the user gave them, each `None` when not given (what a
/// solution keeps to pickle its call).
#[derive(Clone, Copy, Default)]
pub(crate) struct Given {
    pub steps: Option<i64>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub tolerance: Option<f64>,
    pub max_iterations: Option<i64>,
    pub continuation: Option<bool>,
    pub max_load_steps: Option<i64>,
    pub throw: Option<bool>,
    pub seek_stable: Option<bool>,
}

impl Given {
    /// Only the mesh and tolerance options given (`steps`, `rtol`, `atol`, `tolerance`): those
    /// of the entry points that take no load-step or stability options.
    pub(crate) fn mesh(
        steps: Option<i64>,
        rtol: Option<f64>,
        atol: Option<f64>,
        tolerance: Option<f64>,
    ) -> Self {
        Self {
            steps,
            rtol,
            atol,
            tolerance,
            ..Self::default()
        }
    }
}

/// The user's options, each `None` when not given.
#[derive(Default)]
pub(crate) struct OptionArgs<'py> {
    pub integrator: Option<&'py str>,
    pub warm_start: Option<Bound<'py, PyAny>>,
    pub given: Given,
}

/// The one keyword parser of the solve options: from the core's defaults, each given option
/// replaced (and checked, naming the keyword).
pub(crate) fn solve_options(a: &OptionArgs<'_>) -> PyResult<SolveOptions> {
    use softrod::limits::MAX_ITERATIONS;
    let mut o = SolveOptions::default();
    let defaults = AdaptiveOptions::default();
    // Tolerances are checked when given, whichever integrator uses them.
    let adaptive = AdaptiveOptions {
        rtol: a.given.rtol.unwrap_or(defaults.rtol),
        atol: a.given.atol.unwrap_or(defaults.atol),
        ..defaults
    }
    .validated()
    .map_err(to_py_err)?;
    o.integrator = match a.integrator.unwrap_or("rk4") {
        "rk4" => match (a.given.steps, o.integrator) {
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
    if let Some(t) = a.given.tolerance {
        o.newton.tolerance = t;
    }
    if let Some(m) = a.given.max_iterations {
        o.newton.max_iterations = count("max_iterations", m, 1, MAX_ITERATIONS)?;
    }
    if let Some(c) = a.given.continuation {
        o.newton.continuation = c;
    }
    if let Some(m) = a.given.max_load_steps {
        o.newton.max_load_steps = count("max_load_steps", m, 1, MAX_ITERATIONS)?;
    }
    if let Some(t) = a.given.throw {
        o.newton.throw = t;
    }
    if let Some(t) = a.given.seek_stable {
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
    /// The model of the user's `rod`, `tendons`, `loads` (none: unloaded) and `chambers`, with
    /// the actuation of the tendons' tensions (N) and the chambers' pressures (Pa).
    pub(crate) fn new(
        rod: &Bound<'_, Rod>,
        tendons: &[Bound<'_, Tendon>],
        loads: Option<&Bound<'_, Loads>>,
        chambers: &[Bound<'_, Chamber>],
    ) -> PyResult<Self> {
        let (rod, loads) = (rod.get(), loads.map(Bound::get));
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
    Names::OBJECTS.rename(e)
}

/// Which of the core's actuation names stand for the objects' own values in its errors.
#[derive(Clone, Copy)]
pub(crate) struct Names {
    /// The tensions are the tendons' (`tensions[i]` is `tendons[i].tension`).
    pub(crate) tendons: bool,
    /// The pressures are the chambers' (`pressures[i]` is `chambers[i].pressure`).
    pub(crate) chambers: bool,
}

impl Names {
    /// Tensions and pressures both carried by the objects (`solve_statics`).
    pub(crate) const OBJECTS: Self = Self {
        tendons: true,
        chambers: true,
    };

    /// The error with `tensions[i]` / `pressures[i]` renamed after the objects that carry
    /// them; values given as `tensions` / `pressures` keep their names.
    pub(crate) fn rename(self, e: softrod::Error) -> softrod::Error {
        match e {
            softrod::Error::InvalidParameter {
                name,
                value,
                expected,
            } => {
                let rename = |on: bool, prefix: &str, object: &str, field: &str| {
                    let index = name.strip_prefix(prefix)?.strip_suffix(']')?;
                    let i = index.parse::<usize>().ok().filter(|_| on)?;
                    Some(format!("{object}[{i}].{field}"))
                };
                let name = rename(self.tendons, "tensions[", "tendons", "tension")
                    .or_else(|| rename(self.chambers, "pressures[", "chambers", "pressure"))
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
}
