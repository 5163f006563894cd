"""The same robot description solved with every applicable model, side by side.

Models, from the most general: ``cosserat`` (the reference, :meth:`Robot.solve`), ``pcc``
(:func:`softrod.pcc.solve`, one segment per distinct tendon end or chamber boundary) and
``planar`` (the planar cable-arm paper's closed-form arm, :class:`softrod.PlanarCableArm`).
A model that does not apply is listed with the reason.
"""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import _args, pcc
from .._core import ParameterError, PlanarCableArm
from ..io import robot_file as rf
from ..io.robot_file import RobotFile
from ..robot import Robot, load_robot
from .compare import backbone_distance

__all__ = ["ModelComparison", "ModelResult", "compare_models"]

#: Default number of timed solves per model (the reported time is their median).
DEFAULT_REPEATS = 5
#: Most timed solves per model.
MAX_REPEATS = 10_000
#: Relative tolerance on segment breaks (m/m): closer tendon ends or chamber bounds merge.
_END_TOLERANCE = 1e-12
_NO_SOURCE = "the robot's section, material and routings cannot be read back to map it"


@dataclass(frozen=True)
class ModelResult:
    """One model's solution of the robot and its differences from the Cosserat model.

    Attributes:
        model: ``"cosserat"``, ``"pcc"`` or ``"planar"``.
        applies: Whether the model can represent the robot.
        note: Why it does not apply, or how the robot was mapped onto it.
        positions: Backbone points (m, world), shape (n, 3); empty if it does not apply.
        tip_position: Tip position (m, world), shape (3,).
        tip_rotation: Tip frame (body -> world), shape (3, 3); ``None`` for the planar model.
        tip_tangent: Unit tip tangent (world), shape (3,).
        tip_error: Distance between its tip and the Cosserat tip (m).
        angle_error: Angle between its tip frame and the Cosserat one (rad; between the tip
            tangents for the planar model).
        backbone_max: Largest backbone distance to the Cosserat one at equal arm index (m).
        backbone_mean: Mean backbone distance at equal arm index (m).
        solve_time: Median wall time of one solve (s).
        solution: The model's own solution object (``None`` if it does not apply).
    """

    model: str
    applies: bool
    note: str
    positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    tip_position: np.ndarray | None = None
    tip_rotation: np.ndarray | None = None
    tip_tangent: np.ndarray | None = None
    tip_error: float = math.nan
    angle_error: float = math.nan
    backbone_max: float = math.nan
    backbone_mean: float = math.nan
    solve_time: float = math.nan
    solution: Any = None


@dataclass(frozen=True)
class ModelComparison:
    """Every model's result for one robot, Cosserat first (SI units: m, rad, s).

    Attributes:
        robot: The robot's name.
        results: One :class:`ModelResult` per model.
    """

    robot: str
    results: tuple[ModelResult, ...]

    def __getitem__(self, model: str) -> ModelResult:
        for r in self.results:
            if r.model == model:
                return r
        raise KeyError(model)

    def table(self) -> str:
        """The comparison as a plain-text table (mm, degrees, ms) and the inapplicable models."""
        head = (
            f"{'model':<9} {'tip x, y, z (mm)':>26} {'tip err (mm)':>12} {'angle (deg)':>11} "
            f"{'max dist (mm)':>13} {'mean dist (mm)':>14} {'time (ms)':>10}"
        )
        lines = [head, "-" * len(head)]
        for r in self.results:
            if not r.applies:
                continue
            p = r.tip_position * 1e3
            lines.append(
                f"{r.model:<9} {p[0]:8.2f} {p[1]:8.2f} {p[2]:8.2f} {_num(r.tip_error * 1e3, 12)} "
                f"{_num(math.degrees(r.angle_error), 11)} {_num(r.backbone_max * 1e3, 13)} "
                f"{_num(r.backbone_mean * 1e3, 14)} {r.solve_time * 1e3:10.3f}"
            )
        for r in self.results:
            if r.applies:
                lines.append(f"{r.model}: {r.note}")
        for r in self.results:
            if not r.applies:
                lines.append(f"{r.model}: does not apply: {r.note}")
        return "\n".join(lines)


def _num(x: float, width: int) -> str:
    """Three decimals, or three significant digits below 1e-3 (a nonzero difference shows)."""
    return f"{x:{width}.3f}" if x == 0 or abs(x) >= 1e-3 else f"{x:{width}.2e}"


def _median_time(solve, repeats: int):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = solve()
        times.append(time.perf_counter() - t0)
    return out, statistics.median(times)


def _angle(ra: np.ndarray, rb: np.ndarray) -> float:
    """Rotation angle of ``ra^T rb`` (rad), by atan2 (accurate for small angles too)."""
    m = ra.T @ rb
    s = 0.5 * np.linalg.norm([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])
    return float(math.atan2(s, 0.5 * (np.trace(m) - 1.0)))


def _tangent_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two vectors (rad), by atan2."""
    return float(math.atan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b)))


def _linear_modulus(spec: RobotFile) -> float | None:
    mat = spec.rod.material
    return mat.youngs_modulus if isinstance(mat, rf.LinearMaterialSpec) else None


def _offset(t: Any) -> tuple[float, float]:
    """Distance (m) and angle (rad) of a constant-offset tendon or chamber."""
    if t.offset is not None:
        x, y = t.offset
        return math.hypot(x, y), math.atan2(y, x)
    return float(t.distance), math.radians(t.angle_deg or 0.0)


def _nonzero(v) -> bool:
    return v is not None and any(float(x) != 0.0 for x in v)


def _external_loads(loads: rf.LoadsSpec | None) -> list[str]:
    """Names of the non-zero external loads other than a world-frame tip wrench."""
    if loads is None:
        return []
    out = [
        k
        for k in ("gravity", "distributed_force", "distributed_moment")
        if _nonzero(getattr(loads, k))
    ]
    if loads.point_loads:
        out.append("point_loads")
    tip = _nonzero(loads.tip_force) or _nonzero(loads.tip_moment)
    if tip and loads.tip_frame != "world":
        out.append("a body-frame (follower) tip wrench")
    return out


def _tip_wrench(loads: rf.LoadsSpec | None) -> tuple[list[float], list[float]]:
    if loads is None:
        return [0.0] * 3, [0.0] * 3
    return loads.tip_force or [0.0] * 3, loads.tip_moment or [0.0] * 3


def _base(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    pose = np.asarray(robot.rod.base_pose)
    return pose[:3, :3], pose[:3, 3]


def _planar(robot: Robot, spec: RobotFile, s: np.ndarray, repeats: int) -> ModelResult:
    rod, tendons = spec.rod, spec.tendons
    sec = rod.section
    kind = sec.type
    why = []
    if len(tendons) != 1:
        why.append(f"{len(tendons)} tendons (needs exactly one)")
    elif tendons[0].routing != "radius_proportional":
        why.append("the tendon is not radius-proportional")
    if kind not in ("circular", "tapered"):
        why.append(f"a {kind} section (needs a circular or tapered solid circle)")
    modulus = _linear_modulus(spec)
    if modulus is None:
        why.append("a hyperelastic material (needs linear elastic)")
    if spec.chambers:
        why.append("pneumatic chambers")
    force, moment = _tip_wrench(spec.loads)
    if _external_loads(spec.loads) or _nonzero(force) or _nonzero(moment):
        why.append("external loads")
    if _nonzero(rod.rest_strain) or _nonzero(rod.rest_curvature):
        why.append("a rest strain or curvature")
    if why:
        return ModelResult("planar", False, "; ".join(why))
    r0 = float(sec.radius if kind == "circular" else sec.base_radius)
    rl = float(sec.radius if kind == "circular" else sec.tip_radius)
    end = robot.tendons[0].end
    anchor = robot.rod.length if end is None else float(end)
    arm = PlanarCableArm(robot.rod.length, r0, rl, float(tendons[0].ratio), modulus, anchor=anchor)
    tension = robot.tendons[0].tension
    sol, dt = _median_time(lambda: arm.solve(tension, s=s), repeats)
    beta = math.radians(tendons[0].angle_deg)
    d = np.array([math.cos(beta), math.sin(beta), 0.0])
    ez = np.array([0.0, 0.0, 1.0])
    rb, pb = _base(robot)
    pts = pb + (np.outer(sol.x, ez) + np.outer(sol.y, d)) @ rb.T
    th = sol.tip_angle
    tangent = rb @ (math.cos(th) * ez + math.sin(th) * d)
    note = (
        f"PlanarCableArm(L={robot.rod.length:g}, R0={r0:g}, RL={rl:g}, "
        f"ratio={tendons[0].ratio:.4g}, E={modulus:g}, anchor={anchor:g}); planar y along the "
        f"tendon at {math.degrees(beta):g} deg"
    )
    return ModelResult(
        "planar",
        True,
        note,
        positions=pts,
        tip_position=pts[-1],
        tip_tangent=tangent / np.linalg.norm(tangent),
        solve_time=dt,
        solution=sol,
    )


def _pcc(robot: Robot, spec: RobotFile, s: np.ndarray, repeats: int) -> ModelResult:
    rod, tendons, chambers = spec.rod, spec.tendons, spec.chambers
    sec = rod.section
    kind = sec.type
    length = robot.rod.length
    why = []
    if kind != "circular":
        why.append(f"a {kind} section (needs a uniform circular one)")
    modulus = _linear_modulus(spec)
    if modulus is None:
        why.append("a hyperelastic material (needs linear elastic)")
    bad = [i for i, t in enumerate(tendons) if t.routing != "constant"]
    if bad:
        why.append(f"tendons {bad} are not at a constant offset")
    ext = _external_loads(spec.loads)
    if ext:
        why.append("external loads other than a world tip wrench: " + ", ".join(ext))
    if _nonzero(rod.rest_strain) or _nonzero(rod.rest_curvature):
        why.append("a rest strain or curvature")
    if why:
        return ModelResult("pcc", False, "; ".join(why))
    ends = {length}
    for t in robot.tendons:
        ends.add(length if t.end is None else float(t.end))
    for c in robot.chambers:
        ends.add(length if c.end is None else float(c.end))
        if c.start > 0:
            ends.add(float(c.start))
    breaks = [0.0]
    for e in sorted(ends):
        if e - breaks[-1] > _END_TOLERANCE * length:
            breaks.append(e)
    breaks[-1] = length
    rest = np.diff(breaks)

    def segment_of(end: float) -> int:
        return int(np.argmin([abs(b - end) for b in breaks[1:]]))

    model = pcc.Robot.solid_circle(
        rest, float(sec.radius), modulus, extensible=not robot.rod.inextensible
    )
    for t, table in zip(robot.tendons, tendons, strict=True):
        dist, ang = _offset(table)
        model = model.with_tendons(segment_of(length if t.end is None else t.end), [dist], [ang])
    pressures = []
    for c, table in zip(robot.chambers, chambers, strict=True):
        dist, ang = _offset(table)
        first = segment_of(c.start) + 1 if c.start > 0 else 0
        last = segment_of(length if c.end is None else c.end)
        for k in range(first, last + 1):
            model = model.with_chambers(
                k, [c.area_at(0.5 * (breaks[k] + breaks[k + 1]))], [dist], [ang]
            )
            pressures.append(c.pressure)
    rb, pb = _base(robot)
    tip_force, tip_moment = _tip_wrench(spec.loads)
    force = rb.T @ np.asarray(tip_force, dtype=float)
    moment = rb.T @ np.asarray(tip_moment, dtype=float)
    tensions = [t.tension for t in robot.tendons]
    sol, dt = _median_time(
        lambda: pcc.solve(model, tensions, pressures, tip_force=force, tip_moment=moment),
        repeats,
    )
    # The same material points as the Cosserat nodes: segment k is uniformly stretched.
    arcs = sol.arcs[:, 2]
    start = np.concatenate(([0.0], np.cumsum(arcs)))
    k = np.clip(np.searchsorted(breaks, s, side="right") - 1, 0, len(rest) - 1)
    s_def = np.minimum(start[k] + (s - np.asarray(breaks)[k]) * arcs[k] / rest[k], start[-1])
    frames = sol.frames_at(s_def)
    pts = pb + frames[:, :3, 3] @ rb.T
    tip_r = rb @ frames[-1, :3, :3]
    note = f"{len(rest)} segment(s) of {', '.join(f'{x:g}' for x in rest)} m"
    return ModelResult(
        "pcc",
        True,
        note,
        positions=pts,
        tip_position=pts[-1],
        tip_rotation=tip_r,
        tip_tangent=tip_r[:, 2],
        solve_time=dt,
        solution=sol,
    )


def compare_models(
    robot: Robot | str | os.PathLike[str],
    *,
    tensions: Sequence[float] | None = None,
    repeats: int = DEFAULT_REPEATS,
) -> ModelComparison:
    """Solves one robot description with every applicable model and compares with Cosserat.

    The Cosserat model (:meth:`Robot.solve`) is the reference. PCC applies to a uniform
    circular, linear-elastic rod with constant-offset tendons, chambers and a world-frame tip
    wrench (one segment per distinct tendon end or chamber boundary). The planar model of the
    planar cable-arm paper applies to a single radius-proportional tendon (anchored where it
    ends) on a circular or tapered section without external loads (its plane holds the rod's
    axis and the tendon's direction). The PCC and planar backbones are sampled at the material
    points of the Cosserat mesh nodes (undeformed arc length), so that the backbone distance
    at equal arm index compares like with like.

    Args:
        robot: A :class:`Robot` or the path of its description file (TOML).
        tensions: Tendon tensions (N), one per tendon, instead of the file's.
        repeats: Timed solves per model (the median is reported), in [1, MAX_REPEATS].

    Returns:
        The results, Cosserat first, then PCC and planar (applicable or not).

    Raises:
        ParameterError: A bad robot file, tensions, ``repeats`` or ``n_points``.
        ConvergenceError: A model's solve fails.
    """
    repeats = _args.count(repeats, "repeats", 1, MAX_REPEATS)
    if not isinstance(robot, Robot):
        if not isinstance(robot, (str, os.PathLike)):
            raise _args.type_error("robot", robot, "a Robot or the path of a robot file")
        robot = load_robot(_args.path(robot, "robot"))
    if tensions is not None:
        robot = robot.with_tensions(tensions)
    sol, dt = _median_time(robot.solve, int(repeats))
    ref_r = np.asarray(sol.tip_rotation)
    ref = ModelResult(
        "cosserat",
        True,
        f"reference ({len(sol.s)} mesh nodes)",
        positions=np.asarray(sol.position),
        tip_position=np.asarray(sol.tip_position),
        tip_rotation=ref_r,
        tip_tangent=ref_r[:, 2],
        tip_error=0.0,
        angle_error=0.0,
        backbone_max=0.0,
        backbone_mean=0.0,
        solve_time=dt,
        solution=sol,
    )
    results = [ref]
    s_nodes = np.unique(np.asarray(sol.s))
    try:
        spec = robot.spec
    except ParameterError as exc:
        spec, why = None, f"{_NO_SOURCE}: {exc}"
    for model, build in (("pcc", _pcc), ("planar", _planar)):
        if spec is None:
            results.append(ModelResult(model, False, why))
            continue
        r = build(robot, spec, s_nodes, int(repeats))
        if r.applies:
            d = backbone_distance(r.positions, ref.positions)
            angle = (
                _angle(r.tip_rotation, ref_r)
                if r.tip_rotation is not None
                else _tangent_angle(r.tip_tangent, ref.tip_tangent)
            )
            r = ModelResult(
                r.model,
                True,
                r.note,
                positions=r.positions,
                tip_position=r.tip_position,
                tip_rotation=r.tip_rotation,
                tip_tangent=r.tip_tangent,
                tip_error=float(np.linalg.norm(r.tip_position - ref.tip_position)),
                angle_error=angle,
                backbone_max=d.max,
                backbone_mean=d.mean,
                solve_time=r.solve_time,
                solution=r.solution,
            )
        results.append(r)
    return ModelComparison(robot.name, tuple(results))
