//! Binding of the compliance module: integrated and tangent compliance of a solved rod,
//! eigenscrews, workspace maps. Arrays only; the numerics are in `softrod::compliance`,
//! `softrod::compliance::eigenscrew` and `softrod::batch::workspace`.

use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use softrod::math::linalg::invert_spd;
use softrod::nalgebra::Matrix6;

use crate::callbacks::{run, run_parallel};
use crate::convert::{arg, count, Matrix};
use crate::errors::{param_err, to_py_err, type_err};
use crate::model::{Args, Chamber, Loads, Rod, Tendon};
use crate::pcc::PccSolution;
use crate::statics::{solve_options, Given, OptionArgs, Problem, StaticsSolution};

fn mat6<'py>(py: Python<'py>, m: &Matrix6<f64>) -> Bound<'py, PyArray2<f64>> {
    Array::from_shape_fn((6, 6), |(i, j)| m[(i, j)]).into_pyarray(py)
}

fn mats6<'py>(py: Python<'py>, v: &[Matrix6<f64>]) -> Bound<'py, PyArray3<f64>> {
    Array::from_shape_fn((v.len(), 6, 6), |(k, i, j)| v[k][(i, j)]).into_pyarray(py)
}

/// Integrated compliance and stiffness at every node of a solution (the compliance-methodology paper, eqs. 6-7).
///
/// Compliances `C` (6x6: m/N, 1/N, rad/(N m) blocks) map a wrench [f; m] (N, N m) to a twist
/// [translation (m); rotation (rad)], world and body frames; stiffness `K = C^-1`.
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct Compliance {
    inner: softrod::Compliance,
    /// The call that produced it (for pickling: it is computed again, bit for bit).
    call: Args,
}

#[pymethods]
impl Compliance {
    /// Undeformed arc length of each node (m), shape (N,).
    #[getter]
    fn s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.s.clone().into_pyarray(py)
    }
    /// Element compliance c(s) (body), shape (N, 6).
    #[getter]
    fn element<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let e = &self.inner.element;
        Array::from_shape_fn((e.len(), 6), |(i, j)| e[i][j]).into_pyarray(py)
    }
    /// World-frame compliance at each node, shape (N, 6, 6).
    #[getter]
    fn world<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        mats6(py, &self.inner.world)
    }
    /// Body-frame compliance at each node, shape (N, 6, 6).
    #[getter]
    fn body<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        mats6(py, &self.inner.body)
    }
    /// World-frame stiffness (NaN where C is not positive definite; inverted on access),
    /// shape (N, 6, 6).
    #[getter]
    fn stiffness_world<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        mats6(py, &self.inner.stiffness_world().0)
    }
    /// Body-frame stiffness (NaN where C is not positive definite), shape (N, 6, 6).
    #[getter]
    fn stiffness_body<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        mats6(py, &self.inner.stiffness_body())
    }
    /// 1-norm condition number of C at each node (SI units; inf where singular), shape (N,).
    #[getter]
    fn condition<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.stiffness_world().1.into_pyarray(py)
    }
    /// Dimensionless flexural compliance per body axis (x, y, z), shape (N, 3).
    #[getter]
    fn gamma_c<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let g = &self.inner.gamma_c;
        Array::from_shape_fn((g.len(), 3), |(i, j)| g[i][j]).into_pyarray(py)
    }
    /// Tip compliance, world frame, shape (6, 6).
    #[getter]
    fn tip_world<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat6(py, &self.inner.tip_world())
    }
    /// Tip compliance, body frame, shape (6, 6).
    #[getter]
    fn tip_body<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat6(py, &self.inner.tip_body())
    }
    /// Tip stiffness, world frame, shape (6, 6).
    #[getter]
    fn tip_stiffness_world<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat6(py, &invert_spd(&self.inner.tip_world()).0)
    }
    /// Tip stiffness, body frame, shape (6, 6).
    #[getter]
    fn tip_stiffness_body<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat6(py, &invert_spd(&self.inner.tip_body()).0)
    }
    /// 1-norm condition number of the tip compliance.
    #[getter]
    fn tip_condition(&self) -> f64 {
        invert_spd(&self.inner.tip_world()).1
    }
    fn __len__(&self) -> usize {
        self.inner.s.len()
    }
    fn __repr__(&self) -> String {
        format!(
            "Compliance(nodes={}, tip_condition={:.3e})",
            self.inner.s.len(),
            self.tip_condition()
        )
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = py.import("softrod._core")?.getattr("compliance")?;
        slf.get().call.reduce(py, f)
    }
}

/// A Cosserat or a PCC solution.
#[derive(FromPyObject)]
pub(crate) enum AnySolution<'py> {
    Cosserat(PyRef<'py, StaticsSolution>),
    Pcc(PyRef<'py, PccSolution>),
}

/// The paper's integrated compliance along a solved rod (world and body frames), Cosserat or
/// PCC (same computation; the PCC arcs take `rod`'s section and material).
///
/// Returns a `Compliance`: 6x6 matrices per node (m/N, 1/N, rad/(N m) blocks) in the world
/// and body frames, and the dimensionless `gamma_c`. With `s_out` (m, in `[0, L]`, a Cosserat
/// solution only) it is marched under step-size control to those arc lengths (each a stop of
/// the march: exact, not interpolated), one row per value.
#[pyfunction]
#[pyo3(signature = (solution, rod=None, *, panels=None, s_out=None))]
pub(crate) fn compliance<'py>(
    py: Python<'py>,
    solution: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = arg::rod)] rod: Option<Bound<'py, Rod>>,
    #[pyo3(from_py_with = arg::panels)] panels: Option<i64>,
    s_out: Option<Bound<'py, PyAny>>,
) -> PyResult<Compliance> {
    let s_out = s_out.filter(|s| !s.is_none());
    let s_values = crate::convert::floats_opt(s_out.as_ref(), "s_out")?;
    let call = Args::new(
        py,
        &[
            ("solution", solution.clone().unbind()),
            (
                "rod",
                rod.as_ref()
                    .map_or_else(|| py.None(), |r| r.clone().into_any().unbind()),
            ),
            ("panels", panels.into_pyobject(py)?.into_any().unbind()),
            (
                "s_out",
                s_out
                    .as_ref()
                    .map_or_else(|| py.None(), |s| s.clone().unbind()),
            ),
        ],
    )?;
    let solution: AnySolution<'_> = solution.extract().map_err(|_| {
        type_err(
            "solution",
            solution,
            "a StaticsSolution or a softrod.pcc Solution",
        )
    })?;
    let panels = panels
        .map(|p| count("panels", p, 1, softrod::limits::MAX_SAMPLES))
        .transpose()?;
    let rod = rod.as_ref().map(|r| r.borrow());
    let inner = match solution {
        AnySolution::Cosserat(solution) => {
            if rod.is_some() {
                return Err(param_err(
                    "rod",
                    "a Rod",
                    "None for a Cosserat solution (it carries its rod)",
                ));
            }
            let sol = &solution.inner;
            if s_out.is_some() {
                if s_values.is_empty() {
                    return Err(param_err("s_out", "[]", "at least one arc length (m)"));
                }
                run(py, "compliance", || {
                    softrod::compliance::compliance_at(sol, &s_values)
                })
            } else {
                run(py, "compliance", || softrod::compliance(sol))
            }
        }
        AnySolution::Pcc(solution) => {
            if s_out.is_some() {
                return Err(param_err(
                    "s_out",
                    format!("{s_values:?}"),
                    "None for a PCC solution (its panels are set by `panels`)",
                ));
            }
            let rod = rod.ok_or_else(|| {
                param_err("rod", "None", "the Rod giving the section and material")
            })?;
            let (r, robot, sol) = (&rod.inner, &solution.robot, &solution.inner);
            run(py, "compliance", || {
                softrod::pcc_compliance(r, robot, sol, panels)
            })
        }
    }?;
    Ok(Compliance { inner, call })
}

/// Exact tangent compliance at one node of a loaded, actuated equilibrium.
///
/// `world` and `body` are 6x6 (m/N, 1/N, rad/(N m) blocks); `tension_rate` in N/N and
/// N/(N m) per tendon.
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct TangentCompliance {
    inner: softrod::TangentCompliance,
    tendons: String,
    call: Args,
}

#[pymethods]
impl TangentCompliance {
    /// Node index in the solution.
    #[getter]
    fn node(&self) -> usize {
        self.inner.node
    }
    /// Arc length of the node (m).
    #[getter]
    fn s(&self) -> f64 {
        self.inner.s
    }
    /// d[dp; dtheta]/d[f; m], world components at the node, shape (6, 6).
    #[getter]
    fn world<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat6(py, &self.inner.world)
    }
    /// The same in the node's body axes, shape (6, 6).
    #[getter]
    fn body<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat6(py, &self.inner.body)
    }
    /// Inverse of `world` (NaN if singular), shape (6, 6).
    #[getter]
    fn stiffness_world<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat6(py, &self.inner.stiffness_world)
    }
    /// Inverse of `body` (NaN if singular), shape (6, 6).
    #[getter]
    fn stiffness_body<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat6(py, &self.inner.stiffness_body)
    }
    /// 1-norm condition number (SI units).
    #[getter]
    fn condition(&self) -> f64 {
        self.inner.condition
    }
    /// Whether the tangent is symmetric (conservative loads).
    #[getter]
    fn symmetric(&self) -> bool {
        self.inner.symmetric
    }
    /// d tension / d[f; m] per tendon, shape (n_tendons, 6); zero rows for tendons at fixed
    /// tension.
    #[getter]
    fn tension_rate<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let t = &self.inner.tension_rate;
        Array::from_shape_fn((t.len(), 6), |(i, j)| t[i][j]).into_pyarray(py)
    }
    /// "tension" or "length".
    #[getter]
    fn tendons(&self) -> String {
        self.tendons.clone()
    }
    fn __repr__(&self) -> String {
        format!(
            "TangentCompliance(node={}, s={}, tendons={:?}, condition={:.3e})",
            self.inner.node, self.inner.s, self.tendons, self.inner.condition
        )
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = py.import("softrod._core")?.getattr("tangent_compliance")?;
        slf.get().call.reduce(py, f)
    }
}

/// Exact tangent compliance of the equilibrium `solution` at `node` (default: the tip), with
/// the tendons at fixed "tension" or fixed "length" (all, or the indices `held`).
///
/// Any number of tendons can be held; returns a `TangentCompliance` (6x6, m/N, 1/N, rad/(N m)
/// blocks). For a frictional equilibrium (tendons in continuous channels) the tip compliance
/// with the tendons at fixed base tension is one-sided, the tension profile following the
/// stick/slip rule continued from the solution: `direction` 1, "pull" or "load" (default,
/// None: the same; each wrench component increasing) or -1, "release" or "unload" (each
/// decreasing, the column `(f(0) - f(-h e_k)) / h`). Elsewhere on a frictional equilibrium
/// (another node, tendons at fixed length; `direction` must then be None) the profile is held
/// fixed, as on a disk-guided solution (its guide forces held fixed; `direction` must be None).
/// For a frictionless solution `direction` is checked and the two directions agree.
#[pyfunction]
#[pyo3(signature = (solution, tendons="tension", *, held=None, node=None, direction=None))]
pub(crate) fn tangent_compliance<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::solution)] solution: Bound<'py, StaticsSolution>,
    #[pyo3(from_py_with = arg::tendons)] tendons: &str,
    #[pyo3(from_py_with = arg::held)] held: Option<Vec<i64>>,
    #[pyo3(from_py_with = arg::node)] node: Option<i64>,
    direction: Option<Bound<'py, PyAny>>,
) -> PyResult<TangentCompliance> {
    let direction = direction.filter(|d| !d.is_none());
    let call = Args::new(
        py,
        &[
            ("solution", solution.clone().into_any().unbind()),
            ("tendons", tendons.into_pyobject(py)?.into_any().unbind()),
            ("held", held.clone().into_pyobject(py)?.into_any().unbind()),
            ("node", node.into_pyobject(py)?.into_any().unbind()),
            (
                "direction",
                direction.clone().map_or_else(|| py.None(), Bound::unbind),
            ),
        ],
    )?;
    let one_sided = match &direction {
        Some(d) => Some((crate::statics::jacobian_direction(d)?, d)),
        None => None,
    };
    let solution = solution.get();
    let nt = solution.inner.model.tendons().len();
    let held: Vec<usize> = match (tendons, held) {
        ("tension", None) => Vec::new(),
        ("tension", Some(_)) => {
            return Err(param_err("held", "given", "None unless tendons=\"length\""));
        }
        ("length", None) => (0..nt).collect(),
        ("length", Some(h)) => {
            let mut out = Vec::with_capacity(h.len());
            for (k, i) in h.into_iter().enumerate() {
                if i < 0 {
                    return Err(param_err(&format!("held[{k}]"), i, ">= 0"));
                }
                out.push(i as usize);
            }
            out
        }
        (other, _) => {
            return Err(param_err(
                "tendons",
                format!("{other:?}"),
                "\"tension\" or \"length\"",
            ))
        }
    };
    let n = solution.inner.s.len() as i64;
    let node = match node {
        None => None,
        Some(k) if k < 0 && k >= -n => Some((n + k) as usize),
        Some(k) if k >= 0 => Some(k as usize),
        Some(k) => return Err(param_err("node", k, "in [-N, N)")),
    };
    let sol = &solution.inner;
    let tip = node.is_none_or(|k| k + 1 == sol.s.len());
    let result = match frictional_kind(solution) {
        Frictional::Channel if tendons == "tension" && tip => {
            let d = one_sided.map_or(softrod::Direction::Pull, |(d, _)| d);
            run(py, "tangent_compliance", || {
                softrod::compliance::frictional_tangent_compliance(sol, d)
            })?
        }
        kind => {
            if let (Some((_, value)), false) = (one_sided, kind == Frictional::No) {
                return Err(param_err(
                    "direction",
                    value
                        .repr()
                        .map_or_else(|_| "?".to_string(), |r| r.to_string()),
                    match kind {
                        Frictional::Guided => {
                            "None for a disk-guided solution (its tangent compliance holds \
                             the guide forces fixed)"
                        }
                        _ => {
                            "None unless tendons=\"tension\" at the tip (node None or -1): \
                             the one-sided compliance of a frictional equilibrium is that of \
                             the tip at fixed base tensions"
                        }
                    },
                ));
            }
            run(py, "tangent_compliance", || {
                softrod::compliance::tangent_compliance_held(sol, &held, node)
            })?
        }
    };
    Ok(TangentCompliance {
        inner: result,
        tendons: tendons.to_string(),
        call,
    })
}

/// Which friction a statics solution carries.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Frictional {
    /// None: a frictionless solve.
    No,
    /// Tendons in continuous channels (a tension profile along them).
    Channel,
    /// A disk-guided tendon (the rod under the converged guide forces).
    Guided,
}

fn frictional_kind(solution: &StaticsSolution) -> Frictional {
    let guided = solution
        .friction
        .as_ref()
        .is_some_and(|f| f.guides.iter().any(|g| !g.is_empty()));
    if guided {
        Frictional::Guided
    } else if solution.inner.actuation.profile.is_some() {
        Frictional::Channel
    } else {
        Frictional::No
    }
}

/// Eigenscrew decomposition of a 6x6 stiffness or compliance, with the compliance ellipsoids.
///
/// Values in N/m, N/rad (stiffness) or m/N, rad/(N m) (compliance); pitches in m/rad; axis
/// points in m.
#[pyclass(frozen, module = "softrod._core")]
pub(crate) struct Eigenscrews {
    inner: softrod::Decomposition,
    kind: String,
    matrix: Py<PyAny>,
}

#[pymethods]
impl Eigenscrews {
    /// Eigenvalues (eigenstiffnesses for a stiffness, eigencompliances for a compliance),
    /// decreasing, shape (6,).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self.inner.screws.iter().map(|s| s.value).collect();
        v.into_pyarray(py)
    }
    /// Eigenvectors (twists for a stiffness, wrenches for a compliance), one per row,
    /// shape (6, 6).
    #[getter]
    fn vectors<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let s = &self.inner.screws;
        Array::from_shape_fn((6, 6), |(i, j)| s[i].vector[j]).into_pyarray(py)
    }
    /// Unit screw-axis directions, shape (6, 3).
    #[getter]
    fn directions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let s = &self.inner.screws;
        Array::from_shape_fn((6, 3), |(i, j)| s[i].direction[j]).into_pyarray(py)
    }
    /// Points of the axes closest to the frame origin (m), shape (6, 3).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let s = &self.inner.screws;
        Array::from_shape_fn((6, 3), |(i, j)| s[i].point[j]).into_pyarray(py)
    }
    /// Pitches (m/rad), shape (6,).
    #[getter]
    fn pitches<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self.inner.screws.iter().map(|s| s.pitch).collect();
        v.into_pyarray(py)
    }
    /// Translational compliance ellipsoid semi-axes (m/N), decreasing, shape (3,).
    #[getter]
    fn translational_axes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.translational.semi_axes.to_vec().into_pyarray(py)
    }
    /// Their unit directions, one per row, shape (3, 3).
    #[getter]
    fn translational_directions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let d = &self.inner.translational.directions;
        Array::from_shape_fn((3, 3), |(i, j)| d[i][j]).into_pyarray(py)
    }
    /// Rotational compliance ellipsoid semi-axes (rad/(N m)), decreasing, shape (3,).
    #[getter]
    fn rotational_axes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.rotational.semi_axes.to_vec().into_pyarray(py)
    }
    /// Their unit directions, one per row, shape (3, 3).
    #[getter]
    fn rotational_directions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let d = &self.inner.rotational.directions;
        Array::from_shape_fn((3, 3), |(i, j)| d[i][j]).into_pyarray(py)
    }
    /// "stiffness" or "compliance".
    #[getter]
    fn kind(&self) -> String {
        self.kind.clone()
    }
    fn __repr__(&self) -> String {
        let v: Vec<String> = self
            .inner
            .screws
            .iter()
            .map(|s| format!("{:.4e}", s.value))
            .collect();
        format!(
            "Eigenscrews(kind={:?}, values=[{}])",
            self.kind,
            v.join(", ")
        )
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let f = py.import("softrod._core")?.getattr("eigenscrews")?;
        let e = slf.get();
        let args = (e.matrix.clone_ref(py), e.kind.clone()).into_pyobject(py)?;
        PyTuple::new(py, [f, args.into_any()])
    }
}

/// Eigenscrews of a symmetric positive definite 6x6 `matrix` (kind "stiffness" or
/// "compliance"; twists [translation; rotation], wrenches [force; moment]).
#[pyfunction]
#[pyo3(signature = (matrix, kind="stiffness"))]
pub(crate) fn eigenscrews(
    py: Python<'_>,
    #[pyo3(from_py_with = arg::matrix)] matrix: Matrix,
    #[pyo3(from_py_with = arg::kind)] kind: &str,
) -> PyResult<Eigenscrews> {
    let copy = matrix.0.clone().into_pyarray(py).into_any().unbind();
    let a = matrix.0.view();
    if a.shape() != [6, 6] {
        return Err(param_err(
            "matrix",
            format!("shape {:?}", a.shape()),
            "shape (6, 6)",
        ));
    }
    let m = Matrix6::from_fn(|i, j| a[[i, j]]);
    let k = match kind {
        "stiffness" => softrod::MatrixKind::Stiffness,
        "compliance" => softrod::MatrixKind::Compliance,
        other => {
            return Err(param_err(
                "kind",
                format!("{other:?}"),
                "\"stiffness\" or \"compliance\"",
            ))
        }
    };
    let inner = softrod::eigenscrews(&m, k).map_err(to_py_err)?;
    Ok(Eigenscrews {
        inner,
        kind: kind.to_string(),
        matrix: copy,
    })
}

/// One block of a workspace map (used by `softrod.workspace_map`): solves `rod` with
/// `tendons` (their tensions replaced by each row of `tensions`, shape (M, n_tendons)) and
/// returns a dict of arrays.
#[pyfunction]
#[pyo3(signature = (rod, tendons, tensions, loads=None, *, integrator=None, steps=None,
                    rtol=None, atol=None, tolerance=None, chunk=softrod::batch::workspace::DEFAULT_CHUNK as i64,
                    tangent=None, chambers=Vec::new()))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _workspace_map<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = arg::rod)] rod: Bound<'py, Rod>,
    #[pyo3(from_py_with = arg::tendons)] tendons: Vec<Bound<'py, Tendon>>,
    #[pyo3(from_py_with = arg::tensions)] tensions: Matrix,
    #[pyo3(from_py_with = arg::loads)] loads: Option<Bound<'py, Loads>>,
    #[pyo3(from_py_with = arg::integrator)] integrator: Option<&'py str>,
    #[pyo3(from_py_with = arg::steps)] steps: Option<i64>,
    #[pyo3(from_py_with = arg::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = arg::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: Option<f64>,
    #[pyo3(from_py_with = arg::chunk)] chunk: i64,
    #[pyo3(from_py_with = arg::tangent)] tangent: Option<&str>,
    #[pyo3(from_py_with = arg::chambers)] chambers: Vec<Bound<'py, Chamber>>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let tangent = match tangent {
        None => None,
        Some("tension") => Some(softrod::TendonControl::Tension),
        Some("length") => Some(softrod::TendonControl::Length),
        Some(other) => {
            return Err(param_err(
                "tangent",
                format!("{other:?}"),
                "None, \"tension\" or \"length\"",
            ))
        }
    };
    let options = solve_options(&OptionArgs {
        integrator,
        given: Given::mesh(steps, rtol, atol, tolerance),
        ..Default::default()
    })?;
    let problem = Problem::new(&rod, &tendons, loads.as_ref(), &chambers)?;
    let nt = problem.model.tendons().len();
    let chunk = count("chunk", chunk, 1, usize::MAX >> 1)?;
    let a = tensions.0.view();
    if a.ndim() != 2 || a.shape()[1] != nt {
        return Err(param_err(
            "tensions",
            format!("shape {:?}", a.shape()),
            &format!("shape (M, n_tendons) with n_tendons = len(tendons) = {nt}"),
        ));
    }
    let flat: Vec<f64> = a.iter().copied().collect();
    let samples = run_parallel(py, "workspace_map", problem.has_callables, || {
        softrod::workspace_map(
            &problem.model,
            &problem.actuation,
            &flat,
            &options,
            chunk,
            tangent,
        )
    })?;
    let m = samples.len();
    let d = pyo3::types::PyDict::new(py);
    d.set_item(
        "converged",
        samples.iter().map(|s| s.converged).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "tip_position",
        Array::from_shape_fn((m, 3), |(i, j)| samples[i].tip_position[j]).into_pyarray(py),
    )?;
    d.set_item(
        "max_translational_compliance",
        samples
            .iter()
            .map(|s| s.max_translational_compliance)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "min_translational_compliance",
        samples
            .iter()
            .map(|s| s.min_translational_compliance)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "eigen_stiffness",
        Array::from_shape_fn((m, 6), |(i, j)| samples[i].eigen_stiffness[j]).into_pyarray(py),
    )?;
    d.set_item(
        "tangent_max_translational_compliance",
        samples
            .iter()
            .map(|s| s.tangent_max_translational_compliance)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "condition",
        samples
            .iter()
            .map(|s| s.condition)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    Ok(d)
}
