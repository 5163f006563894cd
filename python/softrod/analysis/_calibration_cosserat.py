"""Calibration of Cosserat robots: residuals and exact Jacobians from the linearised
boundary-value problem (``StaticsSolution.sensitivities``).

Every fitted parameter is one column (or a sum of columns) of the core's sensitivities at the
current parameters, rescaled to the parameter's unit:

* a material modulus that scales the whole law (``rod.material.youngs_modulus`` of a linear or
  Hookean rod, ``mu`` of a neo-Hookean one, ``secant_modulus``, a lone ``c10`` ...):
  ``stiffness_scale`` column divided by the value; ``stiffness_scale`` itself multiplies every
  modulus of the law;
* ``tension_scale`` (every measured tension times the factor): the core's tension-scale column;
* ``tendons[i].distance`` / ``.ratio`` / ``.radius`` and ``tendon_offset_scale``: the tendons'
  offset-scale columns;
* ``chambers[j].area`` and ``chamber_area_scale``: the chambers' area-scale columns;
* ``base_rotation_x``, ``_y``, ``_z`` (rad, about world axes, applied before the robot file's
  base rotation): the base-rotation columns.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .. import _args
from .._core import ParameterError

_SCALE_FIELDS = ("youngs_modulus", "shear_modulus", "mu", "c10", "c01", "c20", "c30")
_SCALE_FIELDS += ("secant_modulus",)
_AXES = {"base_rotation_x": 0, "base_rotation_y": 1, "base_rotation_z": 2}
_OFFSET_FIELDS = {"constant": "distance", "radius_proportional": "ratio", "helical": "radius"}


def _axis_rotation(k: int, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    i, j = (k + 1) % 3, (k + 2) % 3
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


def _law_scale(material: Mapping[str, Any], field: str) -> bool:
    """Whether ``field`` alone scales the law's stress (the other moduli zero or absent)."""
    kind = material.get("type", "linear")
    if kind == "linear":
        return field == "youngs_modulus" and material.get("shear_modulus") is None
    if kind in ("hookean",):
        return field == "youngs_modulus"
    if kind == "neo_hookean":
        return field == "mu"
    if kind == "linearised":
        return field == "secant_modulus"
    if kind in ("mooney_rivlin", "yeoh"):
        others = [f for f in ("c10", "c01", "c20", "c30") if f != field and f in material]
        return field in material and all(material[f] == 0.0 for f in others)
    return False


class CosseratModel:
    """A :class:`softrod.Robot` calibrated through its robot-file parameters."""

    dim = 3

    def __init__(self, robot):
        self.robot0 = robot
        if robot.spec is None:
            raise _args.bad(
                "invalid parameter `robot`: calibration changes the robot through its "
                "description (Robot.with_parameters); this robot has none"
            )
        self.length = float(robot.parameter("rod.length"))
        self.material = robot.parameter("rod.material")
        spec = robot.spec
        self.tendons = [robot.parameter(f"tendons[{i}]") for i in range(len(spec.tendons))]
        self.chambers = [robot.parameter(f"chambers[{j}]") for j in range(len(spec.chambers))]
        self.base = robot.parameter("rod.base_pose") if self._has_base() else None
        self._cache: dict[Any, Any] = {}
        self._warm: dict[int, Any] = {}
        self._interp: dict[Any, Any] = {}

    def _has_base(self) -> bool:
        try:
            return self.robot0.parameter("rod.base_pose") is not None
        except ParameterError:
            return False

    # ------------------------------------------------------------------ parameters

    def canonical(self, name: str, where: str = "parameters") -> str:
        if not isinstance(name, str):
            raise _args.type_error(where, name, "parameter names (str)")
        if name == "youngs_modulus":
            name = "rod.material.youngs_modulus"
        known = (
            "stiffness_scale, tension_scale, tendon_offset_scale, chamber_area_scale, "
            "base_rotation_x/y/z, rod.material.<modulus>, tendons[i].distance|ratio|radius, "
            "chambers[j].area"
        )
        if name in ("stiffness_scale", "tension_scale", *_AXES):
            return name
        if name == "tendon_offset_scale" and self.tendons:
            return name
        if name == "chamber_area_scale" and self.chambers:
            if all("area" in c or "radius" in c for c in self.chambers):
                return name
        if "." in name or "[" in name:
            try:  # a path of the robot file: an unknown key is named with a suggestion
                self.robot0.parameter(name)
            except ParameterError as exc:
                raise _args.value_error(
                    where, repr(name), str(exc).split(": must be ", 1)[-1]
                ) from None
            from ..robot import canonical_path

            name = canonical_path(name)  # `tendons[00].distance` is `tendons[0].distance`
        if name.startswith("rod.material."):
            field = name.split(".", 2)[2]
            if field in _SCALE_FIELDS and _law_scale(self.material, field):
                return name
            raise _args.bad(
                f"invalid parameter `{where}`: {name!r} does not scale the whole "
                f"{self.material.get('type', 'linear')} law of this robot (its exact column "
                "is the stiffness scale's); fit `stiffness_scale` instead"
            )
        for prefix, items, fields in (
            ("tendons[", self.tendons, None),
            ("chambers[", self.chambers, ("area",)),
        ):
            if name.startswith(prefix) and "]." in name:
                idx_text, field = name[len(prefix) :].split("].", 1)
                try:
                    idx = int(idx_text)
                except ValueError:
                    break
                if not 0 <= idx < len(items):
                    raise _args.bad(
                        f"invalid parameter `{where}`: {name!r}: index out of [0, {len(items)})"
                    )
                want = fields or (_OFFSET_FIELDS.get(items[idx].get("routing", "constant")),)
                if field in want and field in items[idx]:
                    return name
        raise _args.bad(
            f"invalid parameter `{where}`: {name!r} is not a parameter this robot can be "
            f"calibrated in (known: {known})"
        )

    def initial(self, name: str) -> float:
        if name.endswith("_scale"):
            return 1.0
        if name in _AXES:
            return 0.0
        return float(self.robot0.parameter(name))

    def typical(self, name: str, v0: float) -> float:
        if v0 != 0.0:
            return abs(v0)
        return 0.1 if name in _AXES else 1.0

    def default_bounds(self, name: str, v0: float) -> tuple[float, float]:
        if name in _AXES:
            return (-math.pi, math.pi)
        if name.endswith(".ratio"):
            return (0.0, 0.999)
        return (abs(v0) * 1e-3, abs(v0) * 1e3)

    def check_actuation(self, actuation: Any, where: str) -> dict[str, np.ndarray]:
        nt, nc = len(self.tendons), len(self.chambers)
        if isinstance(actuation, Mapping):
            unknown = set(actuation) - {"tensions", "pressures"}
            if unknown:
                raise _args.bad(
                    f"invalid parameter `{where}`: unknown keys {sorted(unknown)} "
                    "(tensions, pressures)"
                )
            t = actuation.get("tensions", [x["tension"] for x in self.tendons])
            p = actuation.get("pressures", [x.get("pressure", 0.0) for x in self.chambers])
        elif nc and not nt:
            t, p = [], actuation
        else:
            t, p = actuation, [x.get("pressure", 0.0) for x in self.chambers]
        t = np.atleast_1d(_args.finite_array(t, f"{where} tensions")).astype(float)
        p = np.atleast_1d(_args.finite_array(p, f"{where} pressures")).astype(float)
        if t.shape != (nt,) or p.shape != (nc,):
            raise _args.bad(
                f"invalid parameter `{where}`: {t.size} tensions and {p.size} pressures for a "
                f"robot with {nt} tendons and {nc} chambers"
            )
        if np.any(t < 0.0):
            raise _args.value_error(f"{where} tensions", t.tolist(), "tensions >= 0 N")
        return {"tensions": t, "pressures": p}

    # ------------------------------------------------------------------ robots

    def _changes(self, values: Mapping[str, float]) -> dict[str, Any]:
        ch: dict[str, Any] = {}
        for name, v in values.items():
            if name.startswith(("rod.material.", "tendons[", "chambers[")):
                ch[name] = v
        c = values.get("stiffness_scale")
        if c is not None:
            for f in _SCALE_FIELDS:
                if f in self.material:
                    base = ch.get(f"rod.material.{f}", self.material[f])
                    if isinstance(base, list):
                        ch[f"rod.material.{f}"] = [c * b for b in base]
                    else:
                        ch[f"rod.material.{f}"] = c * base
        c = values.get("tendon_offset_scale")
        if c is not None:
            for i, t in enumerate(self.tendons):
                f = _OFFSET_FIELDS.get(t.get("routing", "constant"))
                if f in t:
                    key = f"tendons[{i}].{f}"
                    ch[key] = c * ch.get(key, t[f])
                elif "offset" in t:
                    ch[f"tendons[{i}].offset"] = [c * x for x in t["offset"]]
        c = values.get("chamber_area_scale")
        if c is not None:
            for j, cm in enumerate(self.chambers):
                if "area" in cm:
                    key = f"chambers[{j}].area"
                    ch[key] = c * ch.get(key, cm["area"])
                else:  # a circular chamber: the area scales with the radius squared
                    ch[f"chambers[{j}].radius"] = math.sqrt(c) * cm["radius"]
        if any(k in values for k in _AXES):
            rot = np.eye(3)
            for k, axis in _AXES.items():
                if k in values:
                    rot = rot @ _axis_rotation(axis, values[k])
            r0 = np.array(self.base["rotation"]) if self.base else np.eye(3)
            ch["rod.base_pose.rotation"] = (rot @ r0).tolist()
        return ch

    def robot(self, values: Mapping[str, float]):
        key = tuple(sorted(values.items()))
        if key not in self._cache:
            self._cache.clear()
            ch = self._changes(values)
            self._cache[key] = self.robot0.with_parameters(ch) if ch else self.robot0
        return self._cache[key]

    # ------------------------------------------------------------------ columns

    def _core(self, names: Sequence[str]) -> tuple[list[str], list[list[tuple[int, float]]]]:
        """Core parameters to request and, per fitted name, (core index, weight) pairs (the
        weight multiplies the per-unit-factor column; divided by the value later)."""
        core: list[str] = []

        def col(label: str) -> int:
            if label not in core:
                core.append(label)
            return core.index(label)

        plan: list[list[tuple[int, float]]] = []
        for n in names:
            if n.startswith("rod.material.") or n == "stiffness_scale":
                plan.append([(col("stiffness_scale"), 1.0)])
            elif n == "tension_scale":
                plan.append([(col("tension_scale"), 1.0)])
            elif n == "tendon_offset_scale":
                plan.append(
                    [(col(f"tendon_offset_scale[{i}]"), 1.0) for i in range(len(self.tendons))]
                )
            elif n == "chamber_area_scale":
                plan.append(
                    [(col(f"chamber_area_scale[{j}]"), 1.0) for j in range(len(self.chambers))]
                )
            elif n.startswith("tendons["):
                i = int(n[len("tendons[") :].split("]")[0])
                plan.append([(col(f"tendon_offset_scale[{i}]"), 1.0)])
            elif n.startswith("chambers["):
                j = int(n[len("chambers[") :].split("]")[0])
                plan.append([(col(f"chamber_area_scale[{j}]"), 1.0)])
            else:
                plan.append([(col(f"base_rotation[{_AXES[n]}]"), 1.0)])
        return core, plan

    def evaluate(self, values, names, m, metric: str):
        if metric != "arm-index" and m.kind == "shape":
            raise _args.bad(
                "invalid parameter `metric` = 'nearest': Robot backbones are compared at "
                "equal arm index (metric='arm-index'); 'nearest' is for the planar arm"
            )
        robot = self.robot(values)
        scale = values.get("tension_scale", 1.0)
        act = m.actuation
        tensions = scale * act["tensions"]
        if m.kind == "markers" and m.index[-1] > self.length * (1.0 + 1e-12):
            raise _args.bad(
                f"invalid parameter `measurements`: marker arc length {m.index[-1]} m beyond "
                f"the robot's length {self.length} m"
            )
        options: dict[str, Any] = {}
        warm = self._warm.get(id(m))
        if warm is not None:
            options["warm_start"] = warm
        sol = robot.solve(
            tensions if len(tensions) else None,
            act["pressures"] if len(act["pressures"]) else None,
            **options,
        )
        self._warm[id(m)] = sol
        core, plan = self._core(names)
        nodes = np.asarray(sol.s)
        want = None
        if m.kind in ("shape", "markers"):
            want = (
                np.clip(m.index, 0.0, 1.0) * self.length
                if m.kind == "shape"
                else np.minimum(m.index, self.length)
            )
        # The sensitivities live on the solution's mesh nodes; points between nodes are
        # interpolated by cubic splines through the nodes (between breaks), the same linear
        # map for the positions and their derivatives, so the Jacobian stays exact.
        sens = sol.sensitivities(core)
        pose = np.asarray(sens["pose"])  # (nodes, 6, n_core)
        cols = np.zeros((pose.shape[0], 6, len(names)))
        for j, (n, pairs) in enumerate(zip(names, plan, strict=True)):
            for c, w in pairs:
                cols[:, :, j] += w * pose[:, :, c]
            if n.startswith(("rod.material.", "tendons[", "chambers[")) or n.endswith("_scale"):
                cols[:, :, j] /= values[n]
        pos = np.asarray(sol.position)
        if want is not None:
            key = (id(m), nodes.tobytes())
            if key not in self._interp:
                self._interp[key] = _interpolation(nodes, want)
            w, dw = self._interp[key]
            model = w @ pos
            jac = np.einsum("qn,nik->qik", w, cols[:, :3, :])
            info = None
            if m.kind == "shape":
                tangent = dw @ pos
                speed = np.linalg.norm(tangent, axis=1)
                info = {"tangent": tangent / speed[:, None], "length": self.length * speed}
            return (model - m.data).ravel(), jac.reshape(-1, len(names)), info
        tip = pos[-1]
        if m.data.shape == (4, 4):
            r_model = np.asarray(sol.rotation)[-1]
            r_obs = m.data[:3, :3]
            phi = _log_so3(r_model @ r_obs.T)
            jinv = _left_jacobian_inverse(phi)
            r = np.concatenate([tip - m.data[:3, 3], self.length * phi])
            j = np.vstack([cols[-1, :3, :], self.length * (jinv @ cols[-1, 3:, :])])
            return r, j, None
        return tip - m.data, cols[-1, :3, :], None


def _hat(w: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def _log_so3(r: np.ndarray) -> np.ndarray:
    c = np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0)
    theta = math.acos(c)
    w = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    if theta < 1e-6:
        return 0.5 * w
    return theta / (2.0 * math.sin(theta)) * w


def _left_jacobian_inverse(phi: np.ndarray) -> np.ndarray:
    """``J_l(phi)^-1``: ``d log(exp(dtheta) R) = J_l^-1 dtheta`` for ``R = exp(phi)``."""
    theta = float(np.linalg.norm(phi))
    k = _hat(phi)
    if theta < 1e-6:
        return np.eye(3) - 0.5 * k + k @ k / 12.0
    coef = 1.0 / theta**2 - (1.0 + math.cos(theta)) / (2.0 * theta * math.sin(theta))
    return np.eye(3) - 0.5 * k + coef * (k @ k)


def _interpolation(nodes: np.ndarray, query: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Matrices ``W``, ``W'`` (n_query, n_nodes) of cubic-spline interpolation through the
    nodes and its derivative, one spline per run of nodes between repeated nodes (breaks)."""
    from scipy.interpolate import CubicSpline

    n = len(nodes)
    w = np.zeros((len(query), n))
    dw = np.zeros((len(query), n))
    cuts = [0, *(np.flatnonzero(np.diff(nodes) <= 0.0) + 1).tolist(), n]
    done = np.zeros(len(query), dtype=bool)
    for a, b in itertools.pairwise(cuts):
        seg = nodes[a:b]
        if len(seg) < 2:
            continue
        inside = (~done) & (query >= seg[0]) & (query <= seg[-1])
        if not np.any(inside):
            continue
        k = len(seg)
        if k >= 4:
            spline = CubicSpline(seg, np.eye(k), axis=0)
            w[inside, a:b] = spline(query[inside])
            dw[inside, a:b] = spline(query[inside], 1)
        else:
            t = (query[inside] - seg[0]) / (seg[-1] - seg[0])
            w[inside, a], w[inside, b - 1] = 1.0 - t, t
            dw[inside, a], dw[inside, b - 1] = -1 / (seg[-1] - seg[0]), 1 / (seg[-1] - seg[0])
        done |= inside
    return w, dw
