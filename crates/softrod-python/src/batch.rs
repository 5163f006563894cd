//! Binding of the actuation sweeps (`softrod::sweep`), used by `softrod.sweep`: converts the
//! jobs (robot objects, solver options, actuation tables) and returns the outputs as arrays.

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use softrod::{ActuationTable, SampleStatus, SweepJob, SweepRequest, SweepSample};

use crate::errors::param_err;
use crate::model::{Chamber, Loads, Rod, Tendon};
use crate::statics::{solve_options, Given, OptionArgs, Problem};

/// The output names of a sweep, in the order of the docs.
const OUTPUTS: &str = "\"tip_pose\", \"tendon_lengths\", \"backbone\", \"compliance\", \
                       \"stiffness\", \"gamma_c\", \"eigen_stiffness\", \
                       \"translational_compliance\", \"contacts\"";

fn request(outputs: &[String]) -> PyResult<SweepRequest> {
    let mut r = SweepRequest::default();
    for (i, o) in outputs.iter().enumerate() {
        match o.as_str() {
            "tip_pose" => r.tip_pose = true,
            "tendon_lengths" => r.tendon_lengths = true,
            "backbone" => r.backbone = true,
            "compliance" => r.compliance = true,
            "stiffness" => r.stiffness = true,
            "gamma_c" => r.gamma_c = true,
            "eigen_stiffness" => r.eigen_stiffness = true,
            "translational_compliance" => r.translational_compliance = true,
            "contacts" => r.contacts = true,
            other => {
                return Err(param_err(
                    &format!("outputs[{i}]"),
                    other,
                    &format!("one of {OUTPUTS}"),
                ))
            }
        }
    }
    Ok(r)
}

/// A required item of a job dict.
fn item<'py>(job: &Bound<'py, PyDict>, k: usize, key: &str) -> PyResult<Bound<'py, PyAny>> {
    job.get_item(key)?
        .ok_or_else(|| param_err(&format!("jobs[{k}].{key}"), "missing", "given"))
}

/// A row-major table of `width` columns (an empty table for `width == 0`).
fn rows(obj: &Bound<'_, PyAny>, name: &str, samples: usize, width: usize) -> PyResult<Vec<f64>> {
    if width == 0 {
        return Ok(Vec::new());
    }
    let a: PyReadonlyArray2<'_, f64> = obj
        .extract()
        .map_err(|_| param_err(name, "<object>", "a 2-d float64 array"))?;
    if a.shape() != [samples, width] {
        return Err(param_err(
            name,
            format!("shape {:?}", a.shape()),
            &format!("shape ({samples}, {width})"),
        ));
    }
    Ok(a.as_array().iter().copied().collect())
}

fn option<'py, T: for<'a> FromPyObject<'a, 'py>>(
    opts: &Bound<'py, PyDict>,
    k: usize,
    key: &str,
) -> PyResult<Option<T>> {
    match opts.get_item(key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => match v.extract::<T>() {
            Ok(x) => Ok(Some(x)),
            Err(_) => Err(param_err(
                &format!("jobs[{k}].options.{key}"),
                v.repr()
                    .map_or_else(|_| "<object>".into(), |r| r.to_string()),
                "a valid option",
            )),
        },
    }
}

/// One converted job: the problem (model and error slots) and its tables.
struct Converted {
    problem: Problem,
    options: softrod::SolveOptions,
    samples: usize,
    tensions: Vec<f64>,
    pressures: Vec<f64>,
    tip_force: Option<Vec<f64>>,
    tip_moment: Option<Vec<f64>>,
    arc_lengths: Vec<f64>,
    obstacles: Vec<softrod::Obstacle>,
    tip_constraint: Option<softrod::TipConstraint>,
}

/// An optional item of a job dict (None when missing).
fn optional<'py>(job: &Bound<'py, PyDict>, key: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
    Ok(job.get_item(key)?.filter(|v| !v.is_none()))
}

fn convert(job: &Bound<'_, PyDict>, k: usize) -> PyResult<Converted> {
    let rod = item(job, k, "rod")?;
    let rod = rod.cast::<Rod>()?;
    let tendons: Vec<Bound<'_, Tendon>> = item(job, k, "tendons")?.extract()?;
    let chambers: Vec<Bound<'_, Chamber>> = item(job, k, "chambers")?.extract()?;
    let loads = item(job, k, "loads")?;
    let loads: Option<Bound<'_, Loads>> = if loads.is_none() {
        None
    } else {
        Some(loads.cast::<Loads>()?.clone())
    };
    let problem = Problem::new(rod, &tendons, loads.as_ref(), &chambers)?;
    let opts = item(job, k, "options")?;
    let opts = opts.cast::<PyDict>()?;
    let integrator: Option<String> = option(opts, k, "integrator")?;
    let options = solve_options(&OptionArgs {
        integrator: integrator.as_deref(),
        given: Given {
            steps: option(opts, k, "steps")?,
            rtol: option(opts, k, "rtol")?,
            atol: option(opts, k, "atol")?,
            tolerance: option(opts, k, "tolerance")?,
            max_iterations: option(opts, k, "max_iterations")?,
            continuation: option(opts, k, "continuation")?,
            max_load_steps: option(opts, k, "max_load_steps")?,
            ..Given::default()
        },
        ..Default::default()
    })?;
    let samples: usize = item(job, k, "samples")?.extract()?;
    let (nt, nc) = (
        problem.model.tendons().len(),
        problem.model.chambers().len(),
    );
    let name = |key: &str| format!("jobs[{k}].{key}");
    let tensions = rows(&item(job, k, "tensions")?, &name("tensions"), samples, nt)?;
    let pressures = rows(&item(job, k, "pressures")?, &name("pressures"), samples, nc)?;
    let load = |key: &str| -> PyResult<Option<Vec<f64>>> {
        let v = item(job, k, key)?;
        if v.is_none() {
            Ok(None)
        } else {
            rows(&v, &name(key), samples, 3).map(Some)
        }
    };
    let tip_force = load("tip_force")?;
    let tip_moment = load("tip_moment")?;
    let arcs: PyReadonlyArray1<'_, f64> = item(job, k, "arc_lengths")?
        .extract()
        .map_err(|_| param_err(&name("arc_lengths"), "<object>", "a 1-d float64 array"))?;
    // (A robot's obstacles and tip constraint were checked when it was made.)
    let obstacles = crate::contact::obstacles(job.py(), optional(job, "obstacles")?.as_ref())?;
    let tip_constraint = crate::contact::tip_constraint(optional(job, "tip_constraint")?.as_ref())?;
    Ok(Converted {
        problem,
        options,
        samples,
        tensions,
        pressures,
        tip_force,
        tip_moment,
        arc_lengths: arcs.as_array().to_vec(),
        obstacles,
        tip_constraint,
    })
}

/// The error class of a sample, as the Python exception it would have raised ("" if none):
/// `"ConvergenceError"` or `"ParameterError: <parameter>"`.
fn error_name(s: &SweepSample) -> String {
    match &s.error {
        None => String::new(),
        Some(softrod::Error::NotConverged { .. }) => "ConvergenceError".into(),
        Some(softrod::Error::TargetUnreachable { .. }) => "TargetUnreachableError".into(),
        Some(softrod::Error::InvalidParameter { name, .. }) => format!("ParameterError: {name}"),
    }
}

fn status_code(s: &SweepSample) -> i8 {
    match s.status {
        SampleStatus::Converged => 0,
        SampleStatus::NotConverged => 1,
        SampleStatus::Failed => 2,
    }
}

/// The arrays of one job's samples.
fn arrays<'py>(
    py: Python<'py>,
    samples: &[SweepSample],
    request: &SweepRequest,
    n_arcs: usize,
    nt: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let n = samples.len();
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&SweepSample) -> f64| samples.iter().map(f).collect::<Vec<f64>>();
    d.set_item(
        "status",
        samples
            .iter()
            .map(status_code)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("error", PyList::new(py, samples.iter().map(error_name))?)?;
    let ints = |f: &dyn Fn(&softrod::SolverStats) -> usize| {
        samples
            .iter()
            .map(|s| f(&s.stats) as i64)
            .collect::<Vec<i64>>()
    };
    d.set_item("iterations", ints(&|st| st.iterations).into_pyarray(py))?;
    d.set_item("load_steps", ints(&|st| st.load_steps).into_pyarray(py))?;
    d.set_item(
        "function_evaluations",
        ints(&|st| st.function_evaluations).into_pyarray(py),
    )?;
    d.set_item("residual", col(&|s| s.stats.residual).into_pyarray(py))?;
    // 1 stable, 0 unstable, -1 not converged (the solve's own verdict).
    let stable = samples
        .iter()
        .map(|s| s.stable.map_or(-1_i8, i8::from))
        .collect::<Vec<i8>>();
    d.set_item("stable", stable.into_pyarray(py))?;
    d.set_item(
        "load_factor",
        col(&|s| s.stats.load_factor).into_pyarray(py),
    )?;
    if request.tip_pose {
        d.set_item(
            "tip_position",
            Array::from_shape_fn((n, 3), |(i, j)| samples[i].tip_position[j]).into_pyarray(py),
        )?;
        d.set_item(
            "tip_quaternion",
            Array::from_shape_fn((n, 4), |(i, j)| samples[i].tip_quaternion[j]).into_pyarray(py),
        )?;
    }
    if request.tendon_lengths {
        d.set_item(
            "tendon_lengths",
            Array::from_shape_fn((n, nt), |(i, j)| samples[i].tendon_lengths[j]).into_pyarray(py),
        )?;
    }
    if request.contacts {
        let counts: Vec<i64> = samples.iter().map(|s| s.contact_count as i64).collect();
        d.set_item("contact_count", counts.into_pyarray(py))?;
        d.set_item(
            "contact_force",
            Array::from_shape_fn((n, 3), |(i, j)| samples[i].contact_force[j]).into_pyarray(py),
        )?;
        d.set_item(
            "tip_reaction",
            Array::from_shape_fn((n, 6), |(i, j)| samples[i].tip_reaction[j]).into_pyarray(py),
        )?;
    }
    let m = n_arcs;
    let arc = |i: usize, a: usize| samples[i].arcs.get(a);
    let put3 = |key: &str, width: usize, f: &dyn Fn(&softrod::ArcSample, usize) -> f64| {
        let a = Array::from_shape_fn((n, m, width), |(i, a, j)| {
            arc(i, a).map_or(f64::NAN, |x| f(x, j))
        });
        d.set_item(key, a.into_pyarray(py))
    };
    if request.backbone {
        put3("backbone_position", 3, &|x, j| x.position[j])?;
        put3("backbone_quaternion", 4, &|x, j| x.quaternion[j])?;
    }
    if request.gamma_c {
        put3("gamma_c", 3, &|x, j| x.gamma_c[j])?;
    }
    if request.eigen_stiffness {
        put3("eigen_stiffness", 6, &|x, j| x.eigen_stiffness[j])?;
    }
    if request.translational_compliance {
        put3("translational_compliance", 3, &|x, j| {
            x.translational_compliance[j]
        })?;
    }
    for (key, wanted, stiff) in [
        ("compliance", request.compliance, false),
        ("stiffness", request.stiffness, true),
    ] {
        if wanted {
            let a = Array::from_shape_fn((n, m, 6, 6), |(i, a, r, c)| {
                arc(i, a).map_or(f64::NAN, |x| {
                    if stiff {
                        x.stiffness[(r, c)]
                    } else {
                        x.compliance[(r, c)]
                    }
                })
            });
            d.set_item(key, a.into_pyarray(py))?;
        }
    }
    Ok(d)
}

/// Solves the actuation sweeps of `jobs` (used by `softrod.sweep`).
///
/// Each job is a dict: `rod`, `tendons`, `chambers`, `loads` (robot objects; their tensions
/// and pressures are replaced), `options` (a robot's solver options), `samples` (M),
/// `tensions` (N, shape (M, n_tendons)), `pressures` (Pa, shape (M, n_chambers)),
/// `tip_force` and `tip_moment` (N, N m, shape (M, 3), or None to keep the loads'),
/// `arc_lengths` (m, shape (K,)) and, optionally, `obstacles` and `tip_constraint` (as
/// `solve_statics` takes them; each sample is then a contact solve, started cold). `outputs` names what to measure; rows are warm-started
/// within blocks of `block` rows (see docs/sweeps.md); `parallel` runs the blocks on all
/// cores. Returns one dict of arrays per job (`status`: 0 converged, 1 not converged,
/// 2 failed; `error`: the error class per sample, "" if none).
#[pyfunction]
#[pyo3(signature = (jobs, *, outputs, block=softrod::batch::sweep::DEFAULT_WARM_BLOCK as i64,
                    parallel=true))]
pub(crate) fn _sweep<'py>(
    py: Python<'py>,
    jobs: Vec<Bound<'py, PyDict>>,
    outputs: Vec<String>,
    block: i64,
    parallel: bool,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let request = request(&outputs)?;
    if block < 1 {
        return Err(param_err("block", block, ">= 1"));
    }
    let converted: Vec<Converted> = jobs
        .iter()
        .enumerate()
        .map(|(k, j)| convert(j, k))
        .collect::<PyResult<_>>()?;
    let core_jobs: Vec<SweepJob<'_>> = converted
        .iter()
        .map(|c| SweepJob {
            model: c.problem.model.clone(),
            options: c.options,
            actuations: ActuationTable {
                samples: c.samples,
                tensions: &c.tensions,
                pressures: &c.pressures,
                tip_force: c.tip_force.as_deref(),
                tip_moment: c.tip_moment.as_deref(),
            },
            arc_lengths: c.arc_lengths.clone(),
            obstacles: c.obstacles.clone(),
            tip_constraint: c.tip_constraint,
        })
        .collect();
    let own_pool = parallel && converted.iter().any(|c| c.problem.has_callables);
    let out = crate::callbacks::run_parallel(py, "sweep", own_pool, || {
        softrod::sweep(&core_jobs, &request, block as usize, parallel)
    })?;
    out.iter()
        .zip(&converted)
        .map(|(samples, c)| {
            arrays(
                py,
                samples,
                &request,
                c.arc_lengths.len(),
                c.problem.model.tendons().len(),
            )
        })
        .collect()
}
