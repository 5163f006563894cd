"""Calibration: model parameters fitted to measured shapes, with honest uncertainty.

:func:`calibrate` fits named parameters of a robot (the planar cable arm or a Cosserat robot)
to measured backbones or tip poses by bounded nonlinear least squares (SciPy's
``least_squares``, trust-region reflective). Residuals and their **exact** Jacobians come from
softrod's sensitivities: the variational equations of the planar model's backbone ODE, or the
linearised boundary-value problem of a Cosserat robot. No finite differences.

Residuals (model minus measurement, metres):

* ``metric="arm-index"``: each measured point is compared with the model point at the same arm
  index, the fraction of the backbone's length from the base (the comparison of the planar
  cable-arm paper). The measured index is the arc length of a cubic spline through the points
  (the chord length of a polyline is shorter by ``O(h^2 kappa^2)``); the model's is its deformed
  arc length (planar model) or its undeformed arc length (Cosserat robots). Two (planar) or three
  residuals per point.
* ``metric="nearest"``: the distance of each measured point to the nearest point of the model
  backbone (signed across the planar arm), one residual per point: insensitive to where the
  measured backbone starts and ends.
* A tip measurement: the tip position, and the tip angle (planar) or rotation (Cosserat) times
  the arm length.

Uncertainty: with ``J`` the Jacobian of the ``m`` residuals at the optimum and ``n`` parameters,
``sigma^2 = |r|^2 / (m - n)`` and ``cov = sigma^2 (J^T J)^-1``; ``standard_errors`` are the
square roots of its diagonal and ``correlation`` its normalised form. They assume independent
residuals of equal variance (see ``docs/calibration.md``). Identifiability is judged on the
Jacobian in relative units with unit columns: a condition number above ``condition_limit``
raises :class:`IdentifiabilityWarning` naming the combination the data cannot determine.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from .. import _args
from .._core import ConvergenceError, ParameterError, PlanarCableArm

__all__ = ["Calibration", "IdentifiabilityWarning", "calibrate"]

METRICS = ("arm-index", "nearest")


#: RMS residual, as a fraction of the arm's length, above which a fit is reported as poor
#: (:class:`PoorFitWarning`): fits to photographs leave about 1e-3 of it.
POOR_FIT_FRACTION = 0.05


class PoorFitWarning(UserWarning):
    """The fit leaves residuals of a sizeable fraction of the arm's length: a local minimum
    of the least-squares problem (e.g. from a starting value far off) or a model that does not
    describe the measurements; its standard errors describe that minimum only.

    Attributes:
        rms: RMS residual (m).
        length: The arm's length (m).
    """

    def __init__(self, message: str, rms: float = math.nan, length: float = math.nan):
        super().__init__(message)
        self.rms = rms
        self.length = length


class IdentifiabilityWarning(UserWarning):
    """The measurements cannot determine some combination of the fitted parameters.

    Attributes:
        parameters: Names of the parameters in the undetermined combination.
        combination: Their weights in it (relative units, unit norm).
        condition: Condition number of the scaled Jacobian.
    """

    def __init__(self, message: str, parameters=(), combination=(), condition=math.inf):
        super().__init__(message)
        self.parameters = tuple(parameters)
        self.combination = tuple(combination)
        self.condition = condition


@dataclass(frozen=True, eq=False)
class Calibration:
    """The result of :func:`calibrate`.

    Attributes:
        parameters: Fitted parameter names, in the order of the matrices.
        values: Fitted value of each parameter (its unit: Pa, m, rad, dimensionless).
        initial: Starting value of each parameter.
        standard_errors: Standard error of each parameter (same unit); ``inf`` for a parameter
            in a combination the data cannot determine.
        covariance: Covariance of the estimates, (n, n).
        correlation: Correlation of the estimates, (n, n); NaN for parameters in an
            undetermined combination.
        residuals: Residuals of each measurement at the optimum (model minus measured, m):
            (n_i, dim) per point for "arm-index", (n_i,) for "nearest", (k,) for a tip.
        residual_std: Estimated standard deviation of one residual, ``sigma`` (m).
        rms: Root mean square of all residuals (m).
        degrees_of_freedom: ``m - n``.
        jacobian: Jacobian of all residuals with respect to the parameters at the optimum,
            (m, n), m per unit of each parameter.
        condition: Condition number of the Jacobian in relative units with unit columns.
        identifiable: Whether ``condition`` is below the limit.
        robot: The calibrated robot (a ``PlanarCableArm`` or ``Robot``); parameters that are
            not part of the robot's description (a tension scale, a base angle) are only in
            ``values``.
        metric: The residual metric.
        success: Whether the solver met its tolerances.
        message: The solver's message, and the number of rejected trial values (where the
            model cannot be evaluated) with the last one, if any.
        evaluations: Number of residual evaluations (over all starts).
        starts: Each start of the fit, in order: ``initial`` values, and either the
            ``values`` it reached with their ``rms`` residual (m) and ``evaluations``, or the
            ``error`` why it could not be fitted from (the model refused the start, or every
            trial step). ``initial`` above is the start of the fit returned.
    """

    parameters: tuple[str, ...]
    values: dict[str, float]
    initial: dict[str, float]
    standard_errors: dict[str, float]
    covariance: np.ndarray
    correlation: np.ndarray
    residuals: list[np.ndarray]
    residual_std: float
    rms: float
    degrees_of_freedom: int
    jacobian: np.ndarray
    condition: float
    identifiable: bool
    robot: Any
    metric: str
    success: bool
    message: str
    evaluations: int
    starts: list[dict[str, Any]] = field(default_factory=list, repr=False)
    extra: dict = field(default_factory=dict, repr=False)

    def interval(self, level: float = 0.95) -> dict[str, tuple[float, float]]:
        """Confidence interval of each parameter, ``value -+ t_(m-n) se`` (Student t).

        Args:
            level: Confidence level in (0, 1).
        """
        level = _args.number(level, "level")
        if not 0.0 < level < 1.0:
            raise _args.value_error("level", level, "in (0, 1)")
        from scipy import stats

        q = float(stats.t.ppf(0.5 + level / 2.0, max(self.degrees_of_freedom, 1)))
        return {
            k: (v - q * self.standard_errors[k], v + q * self.standard_errors[k])
            for k, v in self.values.items()
        }

    def __repr__(self) -> str:
        parts = ", ".join(
            f"{k}={v:.6g} ± {self.standard_errors[k]:.2g}" for k, v in self.values.items()
        )
        return (
            f"Calibration({parts}; rms={self.rms:.3g} m, metric={self.metric!r}, "
            f"identifiable={self.identifiable})"
        )


# ---------------------------------------------------------------------------- measurements


@dataclass(frozen=True)
class _Measurement:
    actuation: Any
    kind: str  # "shape", "markers" (points at known arc lengths) or "tip"
    data: np.ndarray  # (n, dim) points, or the tip vector / 4x4 pose
    index: np.ndarray | None  # arm index of each point in [0, 1]


def _arm_index(points: np.ndarray, where: str = "measurements") -> np.ndarray:
    """Normalised arc length of a cubic spline through the points (chord parametrisation)."""
    chord = np.linalg.norm(np.diff(points, axis=0), axis=1)
    u = np.concatenate([[0.0], np.cumsum(chord)])
    if u[-1] <= 0.0:
        raise _args.bad(f"invalid parameter `{where}`: a backbone of zero length")
    if len(points) < 4 or np.any(chord <= 0.0):
        return u / u[-1]
    from scipy.interpolate import CubicSpline

    spline = CubicSpline(u, points, axis=0)
    d = spline.derivative()
    x, w = np.polynomial.legendre.leggauss(8)
    a, b = u[:-1], u[1:]
    t = 0.5 * (b - a)[:, None] * x[None, :] + 0.5 * (a + b)[:, None]
    speed = np.linalg.norm(d(t.ravel()), axis=-1).reshape(t.shape)
    seg = 0.5 * (b - a) * (speed @ w)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    return arc / arc[-1]


def _observation(obs: Any, dim: int, where: str) -> tuple[str, np.ndarray]:
    if hasattr(obs, "points") and hasattr(obs, "arc_length"):  # a Backbone
        if getattr(obs, "unit", "m") != "m":
            raise _args.bad(
                f"invalid parameter `{where}`: a Backbone in pixels; extract it with `scale` "
                "(m per pixel) to calibrate a model in metres"
            )
        obs = obs.points
    elif hasattr(obs, "x") and hasattr(obs, "y") and hasattr(obs, "tension"):
        obs = np.column_stack([obs.x, obs.y])  # a PlanarSolution
    try:
        arr = np.array(obs, dtype=np.float64)
    except (TypeError, ValueError):
        raise _args.type_error(
            where, obs, "an array of points (n, dim), a tip or a Backbone"
        ) from None
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > 1e9):
        raise _args.bad(
            f"invalid parameter `{where}`: values must be finite coordinates below 1e9 m"
        )
    if arr.ndim == 2 and arr.shape == (4, 4) and dim == 3:
        r = arr[:3, :3]
        rigid = (
            np.allclose(r.T @ r, np.eye(3), atol=1e-6)
            and np.linalg.det(r) > 0
            and np.array_equal(arr[3], [0.0, 0.0, 0.0, 1.0])
        )
        if not rigid:
            raise _args.bad(
                f"invalid parameter `{where}` = {' '.join(repr(arr.tolist()).split())}: a 4x4 "
                "tip pose must be a rigid transform (rotation block orthonormal to 1e-6 with "
                "determinant +1, last row [0, 0, 0, 1])"
            )
        return "tip", arr
    if arr.ndim == 1 and (arr.shape[0] == dim or (dim == 2 and arr.shape[0] == 3)):
        return "tip", arr
    if arr.ndim == 2 and arr.shape[1] == dim and arr.shape[0] >= 2:
        return "shape", arr
    raise _args.bad(
        f"invalid parameter `{where}` with shape {arr.shape}: must be points (n >= 2, {dim}), "
        f"a tip position ({dim},)" + (", a tip (x, y, angle)" if dim == 2 else ", a 4x4 tip pose")
    )


def _measurements(
    measurements: Any, actuations: Any, dim: int, check=lambda a, where: a
) -> list[_Measurement]:
    if isinstance(measurements, (str, bytes)) or not isinstance(measurements, Sequence):
        raise _args.type_error(
            "measurements", measurements, "a list of (actuation, points or tip) pairs"
        )
    if len(measurements) == 0:
        raise _args.bad("invalid parameter `measurements` = []: at least one measurement")
    if actuations is not None:
        if isinstance(actuations, (str, bytes)) or not isinstance(
            actuations, (Sequence, np.ndarray)
        ):
            raise _args.type_error("actuations", actuations, "a list, one per measurement")
        actuations = list(actuations)
        if len(actuations) != len(measurements):
            raise _args.bad(
                f"invalid parameter `actuations`: {len(actuations)} actuations for "
                f"{len(measurements)} measurements"
            )
    out = []
    for i, m in enumerate(measurements):
        where = f"measurements[{i}]"
        if actuations is not None:
            act, obs, act_where = actuations[i], m, f"actuations[{i}]"
        elif isinstance(m, (tuple, list)) and len(m) in (2, 3):
            act, obs = m[0], m[1]
            act_where = f"measurements[{i}][0]"
            if len(m) == 3:
                s = _args.finite_array(m[2], f"measurements[{i}][2]", ndim=1)
                kind, data = _observation(obs, dim, where)
                if kind != "shape" or len(s) != len(data):
                    raise _args.bad(
                        f"invalid parameter `measurements[{i}]`: an (actuation, points, s) "
                        f"triple needs one arc length per point ({len(s)} for "
                        f"{len(data) if data.ndim == 2 else 0} points)"
                    )
                if np.any(s < 0.0) or np.any(np.diff(s) < 0.0):
                    raise _args.bad(
                        f"invalid parameter `measurements[{i}][2]`: arc lengths must be >= 0 "
                        "and non-decreasing (m)"
                    )
                out.append(_Measurement(check(act, act_where), "markers", data, s))
                continue
        else:
            raise _args.type_error(
                where, m, "an (actuation, observation) pair (or give `actuations`)"
            )
        kind, data = _observation(obs, dim, where)
        index = _arm_index(data, where) if kind == "shape" else None
        out.append(_Measurement(check(act, act_where), kind, data, index))
    return out


# ---------------------------------------------------------------------------- planar model


_ROT90 = np.array([[0.0, -1.0], [1.0, 0.0]])


def _rot(phi: float) -> np.ndarray:
    c, s = math.cos(phi), math.sin(phi)
    return np.array([[c, -s], [s, c]])


class _PlanarModel:
    """The planar cable-arm paper's arm: core columns (E, a, T, R0, RL) of ``sensitivities``."""

    dim = 2
    PARAMETERS: ClassVar[dict[str, str]] = {
        "youngs_modulus": "Young's modulus E (Pa)",
        "offset_ratio": "cable offset ratio a",
        "tension_scale": "factor on every measured tension",
        "pretension": "tension added to every measured tension (N)",
        "base_radius": "base radius R0 (m)",
        "tip_radius": "tip radius RL (m)",
        "base_angle": "rotation of the arm's base about the origin (rad)",
    }
    ALIASES: ClassVar[dict[str, str]] = {"E": "youngs_modulus", "a": "offset_ratio"}
    CORE: ClassVar[dict[str, int]] = {
        "youngs_modulus": 0,
        "offset_ratio": 1,
        "base_radius": 3,
        "tip_radius": 4,
    }

    def __init__(self, arm: PlanarCableArm):
        self.arm = arm
        self.length = arm.length

    def canonical(self, name: str, where: str = "parameters") -> str:
        if not isinstance(name, str):
            raise _args.type_error(where, name, "parameter names (str)")
        name = self.ALIASES.get(name, name)
        if name not in self.PARAMETERS:
            raise _args.bad(
                f"invalid parameter `{where}`: {name!r} is not a parameter of the planar "
                f"arm (known: {', '.join(self.PARAMETERS)}; aliases E, a)"
            )
        return name

    def initial(self, name: str) -> float:
        return {
            "youngs_modulus": self.arm.youngs_modulus,
            "offset_ratio": self.arm.offset_ratio,
            "tension_scale": 1.0,
            "pretension": 0.0,
            "base_radius": self.arm.base_radius,
            "tip_radius": self.arm.tip_radius,
            "base_angle": 0.0,
        }[name]

    def typical(self, name: str, v0: float) -> float:
        if v0 != 0.0:
            return abs(v0)
        return {"pretension": 0.1, "base_angle": 0.1}.get(name, 1.0)

    def default_bounds(self, name: str, v0: float) -> tuple[float, float]:
        if name == "offset_ratio":
            return (0.0, 0.999)
        if name in ("pretension",):
            return (-math.inf, math.inf)
        if name == "base_angle":
            return (-math.pi, math.pi)
        return (abs(v0) * 1e-3, abs(v0) * 1e3)

    def robot(self, values: Mapping[str, float]) -> PlanarCableArm:
        a = self.arm
        return PlanarCableArm(
            a.length,
            values.get("base_radius", a.base_radius),
            values.get("tip_radius", a.tip_radius),
            values.get("offset_ratio", a.offset_ratio),
            values.get("youngs_modulus", a.youngs_modulus),
            a.anchor,
        )

    def check_actuation(self, actuation: Any, where: str) -> float:
        t = _args.number(actuation, where)
        if not 0.0 <= t < self.arm.max_tension:
            raise _args.value_error(
                where, t, f"a cable tension in [0, {self.arm.max_tension:.6g}) N"
            )
        return t

    def _tension(self, m: _Measurement, values: Mapping[str, float]) -> tuple[float, float]:
        t0 = m.actuation
        return values.get("tension_scale", 1.0) * t0 + values.get("pretension", 0.0), t0

    def _columns(self, core: np.ndarray, t0: float, names: Sequence[str]) -> np.ndarray:
        """Core derivative columns (..., 5) -> the fitted parameters' (..., n); the base
        angle's column is filled by the caller."""
        out = np.zeros((*core.shape[:-1], len(names)))
        for j, n in enumerate(names):
            if n in self.CORE:
                out[..., j] = core[..., self.CORE[n]]
            elif n == "tension_scale":
                out[..., j] = t0 * core[..., 2]
            elif n == "pretension":
                out[..., j] = core[..., 2]
        return out

    def evaluate(self, values, names, m: _Measurement, metric: str):
        arm = self.robot(values)
        t, t0 = self._tension(m, values)
        phi = values.get("base_angle", 0.0)
        rot = _rot(phi)
        L = arm.length
        if m.kind == "tip":
            d = arm.sensitivities(t, [L])
            tip, dt = d["tip"], d["d_tip"]
            pos = rot @ tip[:2]
            jac = rot @ self._columns(dt[:2], t0, names)
            r = [pos - m.data[:2]]
            rows = [jac]
            if "base_angle" in names:
                rows[0][:, names.index("base_angle")] = _ROT90 @ pos
            if m.data.shape[0] == 3:
                ja = L * self._columns(dt[2], t0, names)[None, :]
                if "base_angle" in names:
                    ja[0, names.index("base_angle")] = L
                r.append([L * (tip[2] + phi - m.data[2])])
                rows.append(ja)
            return np.concatenate(r), np.vstack(rows)
        if m.kind == "markers":
            if m.index[-1] > L * (1.0 + 1e-12):
                raise _args.bad(
                    f"invalid parameter `measurements`: marker arc length {m.index[-1]} m "
                    f"beyond the arm's length {L} m"
                )
            d = arm.sensitivities(t, np.minimum(m.index, L))
            core = np.stack([d["d_x"], d["d_y"]], axis=1)
            jac = np.einsum("ij,njk->nik", rot, self._columns(core, t0, names))
            model = np.column_stack([d["x"], d["y"]]) @ rot.T
            if "base_angle" in names:
                jac[:, :, names.index("base_angle")] = model @ _ROT90.T
            return (model - m.data).ravel(), jac.reshape(-1, len(names)), None
        if metric == "arm-index":
            return self._arm_index(arm, t, t0, rot, phi, names, m)
        return self._nearest(arm, t, t0, rot, phi, names, m)

    def _at_index(self, arm, t, sigma):
        """Model samples at deformed-arc fractions ``sigma`` (Newton on the arc length)."""
        L = arm.length
        s = np.clip(sigma * L, 0.0, L)
        for _ in range(30):
            d = arm.sensitivities(t, s)
            target = sigma * d["tip"][3]
            ds = (d["arc"] - target) / (1.0 + d["strain"])
            s_new = np.maximum.accumulate(np.clip(s - ds, 0.0, L))
            if np.max(np.abs(s_new - s)) <= 1e-14 * L:
                break
            s = s_new
        return s, arm.sensitivities(t, s)

    def _arm_index(self, arm, t, t0, rot, phi, names, m):
        sigma = m.index
        _, d = self._at_index(arm, t, sigma)
        pts = np.column_stack([d["x"], d["y"]])
        # dr(s*)/dp = r_p + r' ds*/dp with l(s*) = sigma l(L): r' ds*/dp is the unit
        # tangent times sigma l_p(L) - l_p(s*).
        tangent = np.column_stack([np.cos(d["angle"]), np.sin(d["angle"])])
        shift = sigma[:, None] * d["d_tip"][3][None, :] - d["d_arc"]  # (n, 5)
        core = np.stack([d["d_x"], d["d_y"]], axis=1) + tangent[:, :, None] * shift[:, None, :]
        jac = np.einsum("ij,njk->nik", rot, self._columns(core, t0, names))
        model = pts @ rot.T
        if "base_angle" in names:
            jac[:, :, names.index("base_angle")] = model @ _ROT90.T
        info = {"tangent": tangent @ rot.T, "length": float(d["tip"][3])}
        return (model - m.data).ravel(), jac.reshape(-1, len(names)), info

    def _nearest(self, arm, t, t0, rot, phi, names, m):
        L = arm.length
        q = m.data @ rot  # measured points in the arm's frame (rot^T p)
        dense = arm.solve(t, max(401, 4 * len(q)))
        grid = np.column_stack([dense.x, dense.y])
        from scipy.spatial import cKDTree

        _, idx = cKDTree(grid).query(q)
        s = dense.s[idx]
        for _ in range(30):
            order = np.argsort(s, kind="stable")
            d = arm.sensitivities(t, s[order])
            inv = np.empty_like(order)
            inv[order] = np.arange(len(order))
            x, y, th, g = (d[k][inv] for k in ("x", "y", "angle", "strain"))
            tx, ty = np.cos(th), np.sin(th)
            e = np.column_stack([x, y]) - q
            step = (tx * e[:, 0] + ty * e[:, 1]) / (1.0 + g)
            s_new = np.clip(s - step, 0.0, L)
            if np.max(np.abs(s_new - s)) <= 1e-14 * L:
                s = s_new
                break
            s = s_new
        order = np.argsort(s, kind="stable")
        d = arm.sensitivities(t, s[order])
        inv = np.empty_like(order)
        inv[order] = np.arange(len(order))
        x, y, th = (d[k][inv] for k in ("x", "y", "angle"))
        e = np.column_stack([x, y]) - q
        u = np.column_stack([-np.sin(th), np.cos(th)])  # normal
        ends = (s <= 0.0) | (s >= L)
        if np.any(ends):
            norm = np.linalg.norm(e[ends], axis=1)
            u[ends] = np.where(norm[:, None] > 0, e[ends] / np.maximum(norm, 1e-300)[:, None], 0)
        r = np.einsum("ni,ni->n", u, e)
        core = np.stack([d["d_x"][inv], d["d_y"][inv]], axis=1)
        jac = np.einsum("ni,nik->nk", u, self._columns(core, t0, names))
        if "base_angle" in names:
            # q = R(phi)^T p, dq/dphi = -J q.
            jac[:, names.index("base_angle")] = np.einsum("ni,ni->n", u, q @ _ROT90.T)
        return r, jac, None


# ---------------------------------------------------------------------------- engine


def _model_for(robot: Any):
    if isinstance(robot, PlanarCableArm):
        return _PlanarModel(robot)
    from ..robot import Robot

    if isinstance(robot, Robot):
        from ._calibration_cosserat import CosseratModel

        return CosseratModel(robot)
    raise _args.type_error("robot", robot, "a PlanarCableArm or a Robot")


def _bounds(bounds: Any, names: Sequence[str], model, p0: np.ndarray):
    lo = np.empty(len(names))
    hi = np.empty(len(names))
    given: Mapping[str, Any] = {}
    if bounds is not None:
        if not isinstance(bounds, Mapping):
            raise _args.type_error("bounds", bounds, "a dict: parameter -> (low, high)")
        given = {model.canonical(k, "bounds"): v for k, v in bounds.items()}
        unknown = set(given) - set(names)
        if unknown:
            raise _args.bad(
                f"invalid parameter `bounds`: {sorted(unknown)} are not fitted parameters "
                f"({', '.join(names)})"
            )
    for j, n in enumerate(names):
        if n in given:
            b = given[n]
            try:
                a, c = (float(v) for v in b)
            except (TypeError, ValueError):
                raise _args.type_error(f"bounds[{n!r}]", b, "a pair (low, high)") from None
        else:
            a, c = model.default_bounds(n, p0[j])
            relative = (a, c) == (abs(p0[j]) * 1e-3, abs(p0[j]) * 1e3)
            if relative and not p0[j] > 0.0:
                # (A positive parameter: its default bounds are a factor of 1000 either side
                # of the start, which must then be > 0.)
                raise _args.value_error(
                    f"initial[{n!r}]",
                    float(p0[j]),
                    "> 0 (a positive parameter; without `bounds` it is fitted within a "
                    "factor of 1000 of its start)",
                )
        if not (a < c) or math.isnan(a) or math.isnan(c):
            raise _args.value_error(f"bounds[{n!r}]", (float(a), float(c)), "low < high")
        if not a <= p0[j] <= c:
            raise _args.value_error(
                f"initial[{n!r}]", p0[j], f"within its bounds [{a:.6g}, {c:.6g}]"
            )
        lo[j], hi[j] = a, c
    return lo, hi


def _stack(model, values, names, meas, metric, infos=None):
    rs, js, parts = [], [], []
    for m in meas:
        out = model.evaluate(values, names, m, metric)
        r, j = out[0], out[1]
        if infos is not None:
            infos.append(out[2] if len(out) > 2 else None)
        rs.append(r)
        js.append(j)
        parts.append(len(r))
    return np.concatenate(rs), np.vstack(js), parts


def _residual_variance(r, parts, meas, infos, dim, metric) -> tuple[float, int]:
    """Sum of squares and count of the residual components that carry the measurement noise
    one to one: at equal arm index only the components normal to the model's tangent (the
    tangential one is absorbed by the measured index moving with the point)."""
    total, count, start = 0.0, 0, 0
    for _m, k, info in zip(meas, parts, infos, strict=True):
        chunk = r[start : start + k]
        start += k
        if info is not None and metric == "arm-index":
            e = chunk.reshape(-1, dim)
            t = info["tangent"]
            normal = e - t * np.einsum("ni,ni->n", e, t)[:, None]
            total += float(np.sum(normal * normal))
            count += len(e) * (dim - 1)
        else:
            total += float(chunk @ chunk)
            count += k
    return total, count


def _errors_in_variables(jac, pinv, parts, meas, infos, metric) -> np.ndarray:
    """``A (I - M)(I - M)^T A^T / sigma^2`` with ``A = (J^T J)^+ J^T``: the first-order
    covariance of the estimates under independent noise of variance ``sigma^2`` on every
    measured coordinate, where at equal arm index the measured index moves with the points
    (``M = dr_model(sigma(P))/dP``: the model point slides along its tangent by ``l_L dsigma``,
    ``sigma`` the polyline's normalised length). Without arm-index shapes this is
    ``(J^T J)^+``."""
    w = jac @ pinv  # (m, n) = A^T
    b = w.copy()
    start = 0
    for m, k, info in zip(meas, parts, infos, strict=True):
        if info is not None and metric == "arm-index":
            p = m.data
            dim = p.shape[1]
            blk = w[start : start + k].reshape(len(p), dim, -1)  # (N, dim, n)
            t, ell = info["tangent"], info["length"]
            ell = np.asarray(ell, dtype=float).reshape(-1, 1)  # scalar or per point
            c = ell * np.einsum("ia,ian->in", t, blk)  # (N, n)
            chord = np.diff(p, axis=0)
            seg = np.linalg.norm(chord, axis=1)
            u = chord / np.maximum(seg, 1e-300)[:, None]  # (N-1, dim)
            arc_n = float(seg.sum())
            sigma = np.concatenate([[0.0], np.cumsum(seg)]) / arc_n
            suffix = np.cumsum(c[::-1], axis=0)[::-1]  # C_k = sum_{i >= k} c_i
            g = np.zeros((len(p), dim, c.shape[1]))
            g[1:] += u[:, :, None] * suffix[1:, None, :]
            g[:-1] -= u[:, :, None] * suffix[1:, None, :]
            # d arc_N / dp_k = u_{k-1} - u_k (with u_{-1} = u_{N-1} = 0).
            dn = np.zeros((len(p), dim))
            dn[1:] += u
            dn[:-1] -= u
            g -= dn[:, :, None] * (sigma @ c)[None, None, :]
            b[start : start + k] -= (g / arc_n).reshape(k, -1)
        start += k
    return b.T @ b


def _fmt_values(values: Mapping[str, float]) -> str:
    """``youngs_modulus = 31234.5, offset_ratio = 0.3`` (the fitted parameters' values)."""
    return ", ".join(f"{k} = {v:.6g}" for k, v in values.items())


def _evaluates(model, names: Sequence[str], meas, metric: str) -> bool:
    """Whether the model can be evaluated at the robot's own values of the parameters."""
    own = {n: model.initial(n) for n in names}
    try:
        _stack(model, own, names, meas, metric)
    except (ParameterError, ConvergenceError):
        return False
    return True


def _at_start(exc: Exception, values: Mapping[str, float]) -> Exception:
    """The error of a model that cannot be evaluated at the caller's ``initial`` values (and
    can at the robot's own): the model's refusal, said to hold at those values."""
    text = " ".join(str(exc).split())
    why = (
        "the model cannot be evaluated at the starting value(s) of the fitted parameters, "
        f"{_fmt_values(values)}: {text}"
    )
    if isinstance(exc, ConvergenceError):
        err = ConvergenceError(f"`initial`: {why}")
        # (What the model's own solve carried, as every ConvergenceError does.)
        for k in ("iterations", "residual", "load_factor"):
            setattr(err, k, getattr(exc, k, 0 if k == "iterations" else float("nan")))
        return err
    err = ParameterError(f"invalid parameter `initial`: {why}")
    err.parameter = "initial"
    return err


@dataclass
class _Run:
    """One least-squares fit of :func:`calibrate` from one start (scaled unknowns ``z0``)."""

    z0: np.ndarray
    result: Any  # SciPy's OptimizeResult
    final: dict[str, Any]  # the evaluation at the optimum: r, j, parts, infos
    message: str
    stuck: ConvergenceError | None  # every trial from the start was rejected

    @property
    def cost(self) -> float:
        """Half the sum of squared residuals at the optimum (infinite for a stuck run)."""
        r = self.final["r"]
        return math.inf if self.stuck is not None else float(0.5 * np.dot(r, r))

    def summary(self, names: Sequence[str], scale: np.ndarray) -> dict[str, Any]:
        """The start, its optimum and RMS residual (m), or why it could not move."""
        out: dict[str, Any] = {"initial": dict(zip(names, (self.z0 * scale).tolist(), strict=True))}
        if self.stuck is not None:
            out["error"] = " ".join(str(self.stuck).split())
            out["evaluations"] = int(self.result.nfev)
        else:
            r = self.final["r"]
            out["values"] = dict(zip(names, (self.result.x * scale).tolist(), strict=True))
            out["rms"] = float(np.sqrt(np.mean(r * r)))
            out["evaluations"] = int(self.result.nfev)
        return out


def _least_squares_from(
    z0, first, model, names, meas, metric, scale, zbounds, init, loss, max_evaluations
) -> _Run:
    """SciPy's trust-region least squares from the scaled start ``z0``. A start the model
    cannot be evaluated at raises (for the ``first``, the caller's, named as theirs); trial
    values it cannot be evaluated at are rejected (non-finite residuals)."""
    from scipy.optimize import least_squares

    cache: dict[str, Any] = {}
    rejected: list[tuple[dict[str, float], Exception]] = []

    def evaluate(z: np.ndarray):
        key = z.tobytes()
        if cache.get("key") != key:
            values = dict(zip(names, (z * scale).tolist(), strict=True))
            infos: list[Any] = []
            try:
                r, j, parts = _stack(model, values, names, meas, metric, infos)
            except (ParameterError, ConvergenceError) as exc:
                if "parts" not in cache:  # the starting point: nothing to fall back on
                    if not first or not init or not _evaluates(model, names, meas, metric):
                        raise  # not the caller's starting values: the error stands
                    raise _at_start(exc, values) from exc
                # A trial the model cannot be evaluated at (e.g. a modulus at which a
                # measured tension would compress the arm to zero length): non-finite
                # residuals make the trust-region solver reject it and shrink its step.
                rejected.append((values, exc))
                size = int(sum(cache["parts"]))
                r, j = np.full(size, np.nan), np.full((size, len(names)), np.nan)
                parts, infos = cache["parts"], cache["infos"]
            else:  # trials other than the start that could be evaluated
                cache.setdefault("start", key)
                cache["evaluated"] = cache.get("evaluated", 0) + (key != cache["start"])
            cache.update(key=key, r=r, j=j * scale[None, :], parts=parts, infos=infos)
        return cache

    res = least_squares(
        lambda z: evaluate(z)["r"],
        z0,
        jac=lambda z: evaluate(z)["j"],
        bounds=zbounds,
        method="trf",
        ftol=1e-10,
        xtol=1e-10,
        gtol=1e-10,
        x_scale=1.0,
        loss=loss,
        max_nfev=max_evaluations,
    )
    evaluated = cache.get("evaluated", 0)
    final = dict(evaluate(res.x))
    message = str(res.message)
    stuck = None
    if rejected:
        at, exc = rejected[-1]
        message += (
            f"; {len(rejected)} trial value(s) rejected where the model cannot be evaluated "
            f"(last: {_fmt_values(at)}: {' '.join(str(exc).split())})"
        )
        if evaluated == 0:  # no trial other than the start could be evaluated
            at, exc = rejected[0]  # the first, largest step
            start = dict(zip(names, (z0 * scale).tolist(), strict=True))
            stuck = ConvergenceError(
                f"calibrate could not move from the starting values ({_fmt_values(start)}): "
                "every trial value of the fitted parameters was rejected, the model cannot be "
                f"evaluated there (e.g. at the trial value {_fmt_values(at)}: "
                f"{' '.join(str(exc).split())}); give `initial` values or `bounds` of the "
                "fitted parameters where it can"
            )
            # The optimiser's evaluations, its residual at the start (none moved), full data.
            stuck.iterations = int(res.nfev)
            stuck.residual = float(np.linalg.norm(final["r"]))
            stuck.load_factor = 1.0
    return _Run(z0, res, final, message, stuck)


def _other_starts(
    starts: int, names: Sequence[str], lo: np.ndarray, hi: np.ndarray, scale: np.ndarray
) -> np.ndarray:
    """The scaled starts after the first: a Latin hypercube (seed 0) of ``starts - 1`` points
    in the bounds, log-uniform for a parameter with positive bounds, uniform otherwise."""
    if starts <= 1:
        return np.empty((0, len(names)))
    for n, a, c in zip(names, lo, hi, strict=True):
        if not (math.isfinite(a) and math.isfinite(c)):
            raise _args.value_error(
                f"bounds[{n!r}]", (float(a), float(c)), "finite, to draw `starts` from"
            )
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=len(names), seed=0).random(starts - 1)
    x = np.empty_like(u)
    for j, (a, c) in enumerate(zip(lo, hi, strict=True)):
        if a > 0.0:  # log-uniform
            x[:, j] = np.exp(np.log(a) + u[:, j] * (np.log(c) - np.log(a)))
        else:
            x[:, j] = a + u[:, j] * (c - a)
    return x / scale


def calibrate(
    robot: Any,
    measurements: Sequence[Any],
    parameters: Sequence[str],
    *,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    metric: str = "arm-index",
    actuations: Sequence[Any] | None = None,
    initial: Mapping[str, float] | None = None,
    loss: str = "linear",
    max_evaluations: int = 200,
    condition_limit: float = 1e8,
    starts: int = 1,
) -> Calibration:
    """Fits named parameters of a robot to measured shapes or tip poses.

    Args:
        robot: A :class:`softrod.PlanarCableArm` or a :class:`softrod.Robot`; its current
            parameters are the starting point.
        measurements: ``(actuation, observation)`` pairs. The actuation is the cable tension
            (N) of the planar arm, or a Robot's tendon tensions (N, one per tendon) and/or
            chamber pressures (Pa): a sequence of tensions, or a dict
            ``{"tensions": [...], "pressures": [...]}``. The observation is a backbone, points
            (n, 2) for the planar arm or (n, 3) for a Robot in its base frame (m), base first,
            or a :class:`softrod.Backbone` extracted with ``scale`` (m); or a tip: position
            (2,) or (x, y, angle) (3,) for the planar arm, position (3,) or a 4x4 pose for a
            Robot. With ``actuations`` the list holds only observations.
        parameters: Names to fit. Planar arm: ``youngs_modulus`` (alias ``E``),
            ``offset_ratio`` (alias ``a``), ``tension_scale``, ``pretension``, ``base_radius``,
            ``tip_radius``, ``base_angle``. Robot: paths of the robot file
            (``rod.material.youngs_modulus``, ``rod.material.mu``, ``tendons[0].distance``)
            and ``tension_scale``, ``chamber_area_scale``, ``tendon_offset_scale``,
            ``base_angle`` (see ``docs/calibration.md``).
        bounds: Parameter -> (low, high); defaults: positive parameters within a factor of
            1000 of their start, ``offset_ratio`` in [0, 0.999], angles in [-pi, pi].
        metric: ``"arm-index"`` (points at equal arm index) or ``"nearest"`` (distance to the
            nearest model point) for backbone observations.
        actuations: The actuations, when ``measurements`` holds only observations.
        initial: Starting values (parameter -> value) instead of the robot's.
        loss: SciPy's loss (``"linear"``, or a robust one such as ``"soft_l1"``; the standard
            errors assume ``"linear"``).
        max_evaluations: Largest number of residual evaluations of one start.
        starts: Number of starts (1 to 1000): the first is the robot's values (or
            ``initial``), the others a Latin hypercube (seed 0) in the bounds, log-uniform for
            a positive parameter; the fit with the smallest sum of squared residuals is
            returned, every start in ``Calibration.starts``. Needs finite bounds.
        condition_limit: Condition number of the scaled Jacobian above which the parameters
            are reported not identifiable.

    Returns:
        The :class:`Calibration`. A trial value of the fitted parameters at which the model
        cannot be evaluated (e.g. a modulus at which a measured tension would compress the
        arm to zero length, or a solve that does not converge) is rejected: the optimiser
        shrinks its step and stays where the model is valid; ``message`` counts the rejected
        trials and quotes the last one.

    Raises:
        ParameterError: Unknown parameters, bad measurements, bounds or options (named);
            ``initial`` values at which the model cannot be evaluated (named, with the
            model's reason at those values).
        ConvergenceError: Every trial value was rejected: the fit cannot move from its start
            (the message quotes a trial value and why the model refused it).

    Warns:
        IdentifiabilityWarning: The data cannot determine a combination of the parameters
            (e.g. E together with a tension scale).
        PoorFitWarning: The RMS residual exceeds :data:`POOR_FIT_FRACTION` of the arm's
            length (a local minimum, or a model that does not describe the data).
    """
    model = _model_for(robot)
    if metric not in METRICS:
        raise _args.value_error("metric", metric, f"one of {', '.join(METRICS)}")
    if isinstance(parameters, str) or not isinstance(parameters, Sequence):
        raise _args.type_error("parameters", parameters, "a list of parameter names")
    if len(parameters) == 0:
        raise _args.bad("invalid parameter `parameters` = []: at least one parameter")
    names = [model.canonical(p) for p in parameters]
    if len(set(names)) != len(names):
        raise _args.bad(f"invalid parameter `parameters` = {list(parameters)}: repeated")
    max_evaluations = _args.count(max_evaluations, "max_evaluations", 1, 100_000)
    starts = _args.count(starts, "starts", 1, 1000)
    condition_limit = _args.number(condition_limit, "condition_limit")
    if not condition_limit > 1.0:
        raise _args.value_error("condition_limit", condition_limit, "> 1")
    if loss not in ("linear", "soft_l1", "huber", "cauchy", "arctan"):
        raise _args.value_error("loss", loss, "linear, soft_l1, huber, cauchy or arctan")
    meas = _measurements(measurements, actuations, model.dim, model.check_actuation)
    if initial is not None and not isinstance(initial, Mapping):
        raise _args.type_error("initial", initial, "a dict: parameter -> starting value")
    init = {
        model.canonical(k, "initial"): _args.number(v, f"initial[{k!r}]")
        for k, v in (initial or {}).items()
    }
    p0 = np.array([init.get(n, model.initial(n)) for n in names], dtype=float)
    lo, hi = _bounds(bounds, names, model, p0)
    scale = np.array([model.typical(n, v) for n, v in zip(names, p0, strict=True)])

    def fit_from(z0: np.ndarray, first: bool) -> _Run:
        return _least_squares_from(
            z0, first, model, names, meas, metric, scale, (zlo, zhi), init, loss, max_evaluations
        )

    zlo, zhi = lo / scale, hi / scale
    z0 = np.clip(p0 / scale, zlo, zhi)
    others = _other_starts(starts, names, lo, hi, scale)  # (bounds checked before any fit)
    runs = [fit_from(z0, True)]
    tried = [runs[0].summary(names, scale)]
    for zs in others:
        try:
            run = fit_from(zs, False)
        except (ParameterError, ConvergenceError) as exc:  # the model refuses this start
            tried.append(
                {
                    "initial": dict(zip(names, (zs * scale).tolist(), strict=True)),
                    "error": " ".join(str(exc).split()),
                }
            )
            continue
        runs.append(run)
        tried.append(run.summary(names, scale))
    moved = [run for run in runs if run.stuck is None]
    if not moved:
        raise runs[0].stuck  # type: ignore[misc]
    best = min(moved, key=lambda run: run.cost)
    res, final, message = best.result, best.final, best.message
    p0 = best.z0 * scale
    z = res.x
    r, jz, parts = final["r"], final["j"], final["parts"]
    p = z * scale
    values = dict(zip(names, p.tolist(), strict=True))
    jac = jz / scale[None, :]
    m, n = jac.shape
    infos = final["infos"]
    sigma2, m_eff = _residual_variance(r, parts, meas, infos, model.dim, metric)
    dof = m_eff - n
    sigma2 = sigma2 / dof if dof > 0 else math.nan
    # Identifiability on the relative Jacobian with unit columns.
    rel = jac * np.where(p != 0.0, np.abs(p), scale)[None, :]
    norms = np.linalg.norm(rel, axis=0)
    unit = rel / np.where(norms > 0, norms, 1.0)[None, :]
    _, sv, vt = np.linalg.svd(unit, full_matrices=False)
    condition = float(sv[0] / sv[-1]) if sv[-1] > 0 and np.all(norms > 0) else math.inf
    identifiable = condition <= condition_limit and dof > 0
    # Covariance sigma^2 (J^T J)^-1 through the SVD of the column-equilibrated Jacobian.
    colscale = np.where(norms > 0, norms, 1.0) / np.where(p != 0.0, np.abs(p), scale)
    keep = sv > sv[0] / condition_limit
    inv = (vt[keep].T / sv[keep] ** 2) @ vt[keep]
    pinv = inv / np.outer(colscale, colscale)  # (J^T J)^+ in physical units
    cov = sigma2 * _errors_in_variables(jac, pinv, parts, meas, infos, metric)
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    weak: list[str] = []
    if not identifiable:
        null = vt[~keep] if np.any(~keep) else vt[-1:]
        bad = np.any(np.abs(null) > 0.05, axis=0) | (norms == 0)
        weak = [names[j] for j in range(n) if bad[j]]
        se = np.where(bad, math.inf, se)
        w = vt[-1]
        combo = " ".join(f"{w[j]:+.3f}·ln({names[j]})" for j in range(n) if abs(w[j]) > 0.05)
        why = (
            f"fewer residuals ({m}) than parameters"
            if dof <= 0
            else f"condition number {condition:.3g} > {condition_limit:.3g}"
        )
        warnings.warn(
            IdentifiabilityWarning(
                f"the measurements cannot determine {' and '.join(weak)} separately ({why}); "
                f"the residuals do not change along {combo or 'a parameter with no effect'}; "
                "fix one of them or add measurements that separate them",
                weak,
                [float(w[j]) for j in range(n)],
                condition,
            ),
            stacklevel=2,
        )
    with np.errstate(invalid="ignore", divide="ignore"):
        dd = np.sqrt(np.maximum(np.diag(cov), 0.0))
        corr = cov / np.outer(dd, dd)
    corr[np.diag_indices(n)] = 1.0
    for j, name in enumerate(names):
        if name in weak:  # no meaningful correlation along an undetermined combination
            corr[j, :] = corr[:, j] = math.nan
    rms = float(np.sqrt(np.mean(r * r)))
    if rms > POOR_FIT_FRACTION * model.length:
        warnings.warn(
            PoorFitWarning(
                f"the fit leaves an RMS residual of {rms:.3g} m, {100 * rms / model.length:.3g} "
                f"% of the arm's length ({_fmt_values(values)}): a local minimum (try other "
                "`initial` values or more `starts`) or a model that does not describe the "
                "measurements",
                rms,
                model.length,
            ),
            stacklevel=2,
        )
    residuals = []
    start = 0
    for meas_i, k in zip(meas, parts, strict=True):
        chunk = r[start : start + k]
        start += k
        if meas_i.kind == "markers" or (meas_i.kind == "shape" and metric == "arm-index"):
            chunk = chunk.reshape(-1, model.dim)
        residuals.append(chunk.copy())
    return Calibration(
        parameters=tuple(names),
        values=values,
        initial=dict(zip(names, p0.tolist(), strict=True)),
        standard_errors=dict(zip(names, se.tolist(), strict=True)),
        covariance=cov,
        correlation=corr,
        residuals=residuals,
        residual_std=math.sqrt(sigma2) if sigma2 == sigma2 else math.nan,
        rms=rms,
        degrees_of_freedom=dof,
        jacobian=jac,
        condition=condition,
        identifiable=identifiable,
        robot=model.robot(values),
        metric=metric,
        success=bool(res.success),
        message=message,
        evaluations=sum(int(run.result.nfev) for run in runs),
        starts=tried,
        extra={"weak": weak},
    )
