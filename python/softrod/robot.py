"""Robot description files (TOML): everything the Python API can build, without callables.

A file has the tables ``[rod]`` (with ``[rod.section]`` and ``[rod.material]``: linear, or
hyperelastic by law or silicone name), arrays of ``[[tendons]]`` and ``[[chambers]]``
(pneumatic), ``[loads]`` (with ``[[loads.point_loads]]``) and ``[solver]``; SI units
throughout. See ``docs/robot-files.md`` for the schema and ``examples/robots/`` for examples.
Every error names the offending field, e.g. ``tendons[2].tension``.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from ._core import (
    Chamber,
    CircularSection,
    LinearElastic,
    Loads,
    MooneyRivlin,
    NeoHookean,
    ParameterError,
    PointLoad,
    Rod,
    Section,
    StaticsSolution,
    TableSection,
    TaperedCircularSection,
    Tendon,
    TubeSection,
    UniaxialLaw,
    Yeoh,
    silicone,
    solve_statics,
)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["Robot", "load_robot"]

_SOLVER_KEYS = {
    "integrator",
    "steps",
    "rtol",
    "atol",
    "tolerance",
    "max_iterations",
    "continuation",
    "max_load_steps",
}


class _Fields:
    """Reads one TOML table, remembering its path for error messages."""

    def __init__(self, table: Any, path: str):
        if not isinstance(table, Mapping):
            raise ParameterError(f"invalid field `{path}`: must be a table, got {table!r}")
        self.table, self.path, self.used = table, path, set()

    def name(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def get(self, key: str, default: Any = None, *, required: bool = False) -> Any:
        self.used.add(key)
        if key not in self.table:
            if required:
                raise ParameterError(f"missing field `{self.name(key)}`")
            return default
        return self.table[key]

    def number(self, key: str, default: Any = None, *, required: bool = False) -> Any:
        v = self.get(key, default, required=required)
        if v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ParameterError(f"invalid field `{self.name(key)}` = {v!r}: must be a number")
        return float(v)

    def vector(self, key: str, n: int, default: Any = None) -> Any:
        v = self.get(key, default)
        if v is None:
            return None
        if not (
            isinstance(v, list)
            and len(v) == n
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
        ):
            raise ParameterError(f"invalid field `{self.name(key)}` = {v!r}: must be {n} numbers")
        return [float(x) for x in v]

    def finish(self) -> None:
        extra = sorted(set(self.table) - self.used)
        if extra:
            raise ParameterError(
                f"unknown field `{self.name(extra[0])}` (known: {', '.join(sorted(self.used))})"
            )


def _named(path: str, make):
    """Runs a constructor, prefixing the field path to any ParameterError."""
    try:
        return make()
    except ParameterError as exc:
        param = getattr(exc, "parameter", "")
        err = ParameterError(f"invalid field `{path}`: {exc}")
        err.parameter = f"{path}.{param}" if param else path
        raise err from None


def _section(t: _Fields) -> Section:
    kind = t.get("type", "circular")
    p = t.path
    if kind == "circular":
        sec = _named(p, lambda: CircularSection(t.number("radius", required=True)))
    elif kind == "tapered":
        sec = _named(
            p,
            lambda: TaperedCircularSection(
                t.number("base_radius", required=True), t.number("tip_radius", required=True)
            ),
        )
    elif kind == "tube":
        sec = _named(
            p,
            lambda: TubeSection(
                t.number("outer_radius", required=True), t.number("inner_radius", 0.0)
            ),
        )
    elif kind == "table":
        cols = [t.get(k, required=True) for k in ("s", "area", "ix", "iy", "j")]
        sec = _named(p, lambda: TableSection(*cols))
    else:
        raise ParameterError(
            f"invalid field `{t.name('type')}` = {kind!r}: must be circular, tapered, tube or table"
        )
    t.finish()
    return sec


_HYPERELASTIC = ("neo_hookean", "mooney_rivlin", "yeoh")


def _material(t: _Fields) -> LinearElastic | UniaxialLaw:
    name = t.get("silicone")
    kind = t.get("type", "linear" if name is None else "yeoh")
    if name is not None:
        if kind not in _HYPERELASTIC:
            raise ParameterError(
                f"invalid field `{t.name('type')}` = {kind!r}: with `silicone`, must be "
                "neo_hookean, mooney_rivlin or yeoh (the law of the library entry)"
            )
        try:
            entry = silicone(str(name))
        except ParameterError as exc:
            err = ParameterError(f"invalid field `{t.name('silicone')}`: {exc}")
            err.parameter = t.name("silicone")
            raise err from None
        law = getattr(entry, kind)
        if law is None:
            raise ParameterError(
                f"invalid field `{t.name('type')}` = {kind!r}: the library has no {kind} "
                f"parameters for {entry.name}"
            )
    elif kind == "linear":
        law = _named(
            t.path,
            lambda: LinearElastic(
                t.number("youngs_modulus", required=True),
                t.number("poisson_ratio"),
                shear_modulus=t.number("shear_modulus"),
            ),
        )
    elif kind == "neo_hookean":
        law = _named(t.path, lambda: NeoHookean(t.number("mu", required=True)))
    elif kind == "mooney_rivlin":
        law = _named(
            t.path,
            lambda: MooneyRivlin(t.number("c10", required=True), t.number("c01", required=True)),
        )
    elif kind == "yeoh":
        law = _named(
            t.path,
            lambda: Yeoh(
                t.number("c10", required=True), t.number("c20", 0.0), t.number("c30", 0.0)
            ),
        )
    else:
        raise ParameterError(
            f"invalid field `{t.name('type')}` = {kind!r}: must be linear, neo_hookean, "
            "mooney_rivlin or yeoh"
        )
    t.finish()
    return law


def _pose(t: _Fields) -> Any:
    pose = t.get("base_pose")
    if pose is None:
        return None
    pf = _Fields(pose, t.name("base_pose"))
    pos = pf.vector("position", 3, [0.0, 0.0, 0.0])
    rot = pf.get("rotation", [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    if not (
        isinstance(rot, list)
        and len(rot) == 3
        and all(isinstance(r, list) and len(r) == 3 for r in rot)
    ):
        raise ParameterError(f"invalid field `{pf.name('rotation')}`: must be a 3x3 matrix")
    pf.finish()
    return (pos, rot)


def _rod(t: _Fields) -> Rod:
    section = _section(_Fields(t.get("section", required=True), t.name("section")))
    material = _material(_Fields(t.get("material", required=True), t.name("material")))
    rod = _named(
        t.path,
        lambda: Rod(
            t.number("length", required=True),
            section,
            material,
            rest_strain=t.vector("rest_strain", 3),
            rest_curvature=t.vector("rest_curvature", 3),
            inextensible=bool(t.get("inextensible", False)),
            density=t.number("density"),
            base_pose=_pose(t),
            shear_coefficient=t.number("shear_coefficient"),
        ),
    )
    t.finish()
    return rod


def _tendon(t: _Fields) -> Tendon:
    routing = t.get("routing", "constant")
    tension = t.number("tension", 0.0)
    end = t.number("end")
    if routing == "constant":
        offset = t.vector("offset", 2)
        if offset is None:
            dist = t.number("distance", required=True)
            ang = math.radians(t.number("angle_deg", 0.0))
            offset = [dist * math.cos(ang), dist * math.sin(ang)]
        tendon = _named(t.path, lambda: Tendon(offset, tension, end))
    elif routing == "radius_proportional":
        tendon = _named(
            t.path,
            lambda: Tendon.radius_proportional(
                t.number("ratio", required=True),
                math.radians(t.number("angle_deg", 0.0)),
                tension,
                end,
            ),
        )
    elif routing == "helical":
        tendon = _named(
            t.path,
            lambda: Tendon.helical(
                t.number("radius", required=True),
                t.number("pitch", required=True),
                tension,
                math.radians(t.number("phase_deg", 0.0)),
                end,
            ),
        )
    else:
        raise ParameterError(
            f"invalid field `{t.name('routing')}` = {routing!r}: must be constant, "
            "radius_proportional or helical"
        )
    t.finish()
    return tendon


def _chamber(t: _Fields) -> Chamber:
    offset = t.vector("offset", 2)
    if offset is None:
        dist = t.number("distance", required=True)
        ang = math.radians(t.number("angle_deg", 0.0))
        offset = [dist * math.cos(ang), dist * math.sin(ang)]
    area = t.number("area")
    radius = t.number("radius")
    if (area is None) == (radius is None):
        raise ParameterError(
            f"invalid field `{t.name('area')}`: give either `area` (m^2) or `radius` (m, a "
            "circular chamber), not both or neither"
        )
    if radius is not None:
        if not radius > 0:
            raise ParameterError(f"invalid field `{t.name('radius')}` = {radius}: must be > 0 m")
        area = math.pi * radius * radius
    chamber = _named(
        t.path,
        lambda: Chamber(
            t.number("pressure", 0.0), area, offset, t.number("start", 0.0), t.number("end")
        ),
    )
    t.finish()
    return chamber


def _loads(t: _Fields) -> Loads:
    points = []
    for i, pl in enumerate(t.get("point_loads", [])):
        pf = _Fields(pl, f"{t.path}.point_loads[{i}]")
        points.append(
            _named(
                pf.path,
                lambda pf=pf: PointLoad(
                    pf.number("s", required=True),
                    pf.vector("force", 3, [0.0] * 3),
                    pf.vector("moment", 3, [0.0] * 3),
                    pf.get("frame", "world"),
                ),
            )
        )
        pf.finish()
    loads = _named(
        t.path,
        lambda: Loads(
            tip_force=t.vector("tip_force", 3),
            tip_moment=t.vector("tip_moment", 3),
            gravity=t.vector("gravity", 3),
            tip_frame=t.get("tip_frame", "world"),
            point_loads=points,
            distributed_force=t.vector("distributed_force", 3),
            distributed_moment=t.vector("distributed_moment", 3),
        ),
    )
    t.finish()
    return loads


def _check_across(
    data: Mapping[str, Any],
    rod: Rod,
    tendons: tuple[Tendon, ...],
    chambers: tuple[Chamber, ...] = (),
) -> None:
    """Rules that tie fields together, checked at load time rather than at the first solve."""
    for i, chamber in enumerate(chambers):
        if chamber.end is not None and chamber.end > rod.length:
            raise ParameterError(
                f"invalid field `chambers[{i}].end` = {chamber.end}: must be in (start, "
                f"rod.length] = ({chamber.start}, {rod.length}] m"
            )
        if chamber.start >= rod.length:
            raise ParameterError(
                f"invalid field `chambers[{i}].start` = {chamber.start}: must be in "
                f"[0, rod.length) = [0, {rod.length}) m"
            )
    for i, tendon in enumerate(tendons):
        if tendon.end is not None and not 0.0 < tendon.end <= rod.length:
            raise ParameterError(
                f"invalid field `tendons[{i}].end` = {tendon.end}: must be in (0, rod.length] = "
                f"(0, {rod.length}] m"
            )
    gravity = data.get("loads", {}).get("gravity")
    if gravity is not None and any(g != 0 for g in gravity) and rod.density is None:
        raise ParameterError(
            "invalid field `loads.gravity`: needs `rod.density` (kg/m^3), which is not given"
        )


@dataclass(frozen=True)
class Robot:
    """A robot read from a description file: rod, tendons, chambers, loads and solver options.

    SI units throughout (m, N, Pa, rad); tensions in N, pressures in Pa (gauge).

    Attributes:
        name: The file's ``name`` (or its file name).
        rod: The rod model.
        tendons: Tendons, in file order.
        chambers: Pneumatic chambers, in file order.
        loads: External loads (unloaded when the file has none).
        solver: Keyword arguments for :func:`softrod.solve_statics`.
        description: Free text from the file.
        source: The parsed description it was built from (tables as read; the tensions and
            pressures of ``tendons`` and ``chambers`` take precedence), used by
            :func:`softrod.compare_models` to map the robot onto simpler models.
    """

    name: str
    rod: Rod
    tendons: tuple[Tendon, ...] = ()
    loads: Loads = field(default_factory=Loads)
    solver: dict[str, Any] = field(default_factory=dict)
    description: str = ""
    chambers: tuple[Chamber, ...] = ()
    source: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def solve(self, **overrides: Any) -> StaticsSolution:
        """Solves the robot's statics; keyword arguments override the file's solver options."""
        options = {**self.solver, **overrides}
        if self.chambers:
            options.setdefault("chambers", self.chambers)
        return solve_statics(self.rod, self.tendons, self.loads, **options)

    def with_pressures(self, pressures) -> Robot:
        """The same robot with new chamber pressures (Pa, gauge), one per chamber."""
        pressures = list(pressures)
        if len(pressures) != len(self.chambers):
            raise ParameterError(
                f"invalid parameter `pressures` with {len(pressures)} values: must have one per "
                f"chamber ({len(self.chambers)})"
            )
        new = tuple(
            c.with_pressure(float(p)) for c, p in zip(self.chambers, pressures, strict=True)
        )
        return replace(self, chambers=new)

    def with_tensions(self, tensions) -> Robot:
        """The same robot with new tendon tensions (N), one per tendon."""
        tensions = list(tensions)
        if len(tensions) != len(self.tendons):
            raise ParameterError(
                f"invalid parameter `tensions` with {len(tensions)} values: must have one per "
                f"tendon ({len(self.tendons)})"
            )
        new = tuple(t.with_tension(float(x)) for t, x in zip(self.tendons, tensions, strict=True))
        return replace(self, tendons=new, solver=dict(self.solver))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], name: str = "robot") -> Robot:
        """Builds a robot from a parsed description (the TOML file's tables)."""
        top = _Fields(data, "")
        rod = _rod(_Fields(top.get("rod", required=True), "rod"))
        tendons = tuple(
            _tendon(_Fields(t, f"tendons[{i}]")) for i, t in enumerate(top.get("tendons", []))
        )
        chambers = tuple(
            _chamber(_Fields(c, f"chambers[{i}]")) for i, c in enumerate(top.get("chambers", []))
        )
        loads = _loads(_Fields(top.get("loads", {}), "loads"))
        _check_across(top.table, rod, tendons, chambers)
        sf = _Fields(top.get("solver", {}), "solver")
        solver = {k: sf.get(k) for k in sorted(set(sf.table) & _SOLVER_KEYS)}
        sf.finish()
        robot = cls(
            name=str(top.get("name", name)),
            rod=rod,
            tendons=tendons,
            loads=loads,
            solver=solver,
            description=str(top.get("description", "")),
            chambers=chambers,
            source=data,
        )
        top.finish()
        return robot


def load_robot(path: str | os.PathLike[str]) -> Robot:
    """Reads a robot description file (TOML).

    Args:
        path: The ``.toml`` file.

    Returns:
        The robot, ready to :meth:`Robot.solve`.

    Raises:
        ParameterError: A missing, unknown or invalid field (named in the message), or a file
            that is not valid TOML.
    """
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"invalid robot file {os.fspath(path)!r}: {exc}") from None
    return Robot.from_dict(data, name=os.path.splitext(os.path.basename(path))[0])
