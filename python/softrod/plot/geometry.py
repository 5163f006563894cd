"""What a figure draws around the backbone: outer radius, tendon routings, chambers, disks.

The compiled :class:`softrod.Rod` and :class:`softrod.Tendon` do not expose their section or
routing parameters, so :func:`robot_geometry` reads them from the robot description
(:attr:`softrod.Robot.source`), rebuilding the section with the same classes the solver used.
When the binding exposes ``Rod.section`` or ``Tendon.offset_at(s)``, those are used first.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._core import (
    CircularSection,
    ParameterError,
    TableSection,
    TaperedCircularSection,
    TubeSection,
)

__all__ = ["ChamberGeometry", "RobotGeometry", "TendonGeometry", "robot_geometry"]

RadiusFn = Callable[[np.ndarray], np.ndarray]
OffsetFn = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class TendonGeometry:
    """One tendon's routing in the body frame.

    Attributes:
        offset: ``s`` (m, shape (n,)) -> body-frame offset ``r(s)`` from the backbone (m,
            shape (n, 2): body x, body y).
        end: Arc length where the tendon terminates (m).
        label: Legend text, e.g. ``"tendon 0 (4 N)"``.
        tension: Tension (N) used for the colour.
    """

    offset: OffsetFn
    end: float
    label: str
    tension: float = 0.0


@dataclass(frozen=True)
class ChamberGeometry:
    """One pneumatic chamber: a bore parallel to the backbone.

    Attributes:
        offset: Centroid offset in the body frame (m, shape (2,)).
        radius: Radius of the circle of the chamber's area (m).
        start: First arc length (m).
        end: Last arc length (m).
        pressure: Gauge pressure (Pa), used for the colour.
        label: Legend text.
    """

    offset: np.ndarray
    radius: float
    start: float
    end: float
    pressure: float
    label: str


@dataclass(frozen=True)
class RobotGeometry:
    """Everything drawn around a backbone (SI units, body frame).

    Attributes:
        length: Rod length (m).
        radius: ``s`` (m, shape (n,)) -> drawn outer radius (m, shape (n,)); ``None`` when the
            section is unknown (only the backbone is drawn).
        tendons: Tendon routings.
        chambers: Pneumatic chambers.
        disks: Arc lengths of spacer disks (m).
        disk_radius: Radius of the disks (m).
        radius_source: How ``radius`` was obtained (for captions and the report).
    """

    length: float
    radius: RadiusFn | None = None
    tendons: tuple[TendonGeometry, ...] = ()
    chambers: tuple[ChamberGeometry, ...] = ()
    disks: tuple[float, ...] = ()
    disk_radius: float = 0.0
    radius_source: str = "unknown"
    notes: tuple[str, ...] = field(default=())

    def max_radius(self) -> float:
        """Largest drawn radius (m): the rod's, the disks' or the farthest tendon's."""
        s = np.linspace(0.0, self.length, 64)
        r = float(np.max(self.radius(s))) if self.radius is not None else 0.0
        for t in self.tendons:
            r = max(r, float(np.max(np.linalg.norm(t.offset(s), axis=1))))
        for c in self.chambers:
            r = max(r, float(np.linalg.norm(c.offset)) + c.radius)
        return max(r, self.disk_radius)


def _plain(source: Any) -> Mapping[str, Any]:
    """The robot description as nested mappings (a dict, or a pydantic model's dump)."""
    if source is None:
        return {}
    if isinstance(source, Mapping):
        return source
    for name in ("model_dump", "dict"):
        dump = getattr(source, name, None)
        if callable(dump):
            return dump()
    return {}


def _section_from_table(t: Mapping[str, Any]):
    """The section object the solver built from a ``[rod.section]`` table."""
    kind = t.get("type", "circular")
    if kind == "circular":
        return CircularSection(float(t["radius"]))
    if kind == "tapered":
        return TaperedCircularSection(float(t["base_radius"]), float(t["tip_radius"]))
    if kind == "tube":
        return TubeSection(float(t["outer_radius"]), float(t.get("inner_radius", 0.0)))
    if kind == "table":
        return TableSection(t["s"], t["area"], t["ix"], t["iy"], t["j"])
    return None


def _radius_functions(section, length: float, kind: str) -> tuple[RadiusFn, RadiusFn]:
    """(drawn outer radius, the solver's section radius) as functions of ``s``.

    The solver's radius (used by radius-proportional routings) is the section's ``radius``;
    for tabulated sections it is the radius of the circle of area ``A``, which under-draws a
    section with bores, so those are drawn with ``sqrt(2 J / A)`` (exact for a solid circle,
    ``sqrt(Ro^2 + Ri^2)`` for a tube).
    """

    def props(s: np.ndarray, key: str) -> np.ndarray:
        return np.array([section.properties(float(x), length)[key] for x in np.atleast_1d(s)])

    def solver_radius(s):
        return props(s, "radius")

    if kind != "table":
        return solver_radius, solver_radius

    def drawn(s):
        s = np.atleast_1d(s)
        out = []
        for x in s:
            p = section.properties(float(x), length)
            out.append(math.sqrt(2.0 * p["j"] / p["area"]) if p["area"] > 0 else p["radius"])
        return np.array(out)

    return drawn, solver_radius


def _constant_offset(offset) -> OffsetFn:
    off = np.asarray(offset, dtype=float)
    return lambda s: np.tile(off, (len(np.atleast_1d(s)), 1))


def _tendon_offset(t: Mapping[str, Any], solver_radius: RadiusFn | None) -> OffsetFn | None:
    routing = t.get("routing", "constant")
    if routing == "constant":
        if "offset" in t:
            return _constant_offset(t["offset"])
        d, a = float(t["distance"]), math.radians(float(t.get("angle_deg", 0.0)))
        return _constant_offset((d * math.cos(a), d * math.sin(a)))
    if routing == "radius_proportional":
        if solver_radius is None:
            return None
        ratio, a = float(t["ratio"]), math.radians(float(t.get("angle_deg", 0.0)))
        direction = np.array([math.cos(a), math.sin(a)])
        return lambda s: ratio * solver_radius(np.atleast_1d(s))[:, None] * direction
    if routing == "helical":
        radius, pitch = float(t["radius"]), float(t["pitch"])
        phase = math.radians(float(t.get("phase_deg", 0.0)))

        def helix(s):
            ang = phase + 2.0 * math.pi * np.atleast_1d(s) / pitch
            return radius * np.column_stack((np.cos(ang), np.sin(ang)))

        return helix
    return None


def _as_radius_fn(radius) -> RadiusFn:
    if callable(radius):
        return lambda s: np.broadcast_to(
            np.asarray(radius(np.atleast_1d(s)), dtype=float), np.shape(np.atleast_1d(s))
        )
    r = float(radius)
    if not r >= 0:
        err = ParameterError(f"invalid parameter `radius` = {radius!r}: must be >= 0 m")
        err.parameter = "radius"
        raise err
    return lambda s: np.full(np.shape(np.atleast_1d(s)), r)


def robot_geometry(
    robot,
    *,
    radius: float | RadiusFn | None = None,
    disks: Sequence[float] | None = None,
    disk_radius: float | None = None,
) -> RobotGeometry:
    """The drawable geometry of a :class:`softrod.Robot` (or of a bare :class:`softrod.Rod`).

    Args:
        robot: A :class:`softrod.Robot` (read from a file or built with ``source``), or a
            :class:`softrod.Rod` (only what the binding exposes is drawn).
        radius: Drawn outer radius (m), a number or a function of ``s`` (m) returning metres;
            default: from the section.
        disks: Arc lengths (m) of spacer disks; default, when tendons run outside the rod
            (through disks): the base and the distinct tendon terminations; none otherwise.
            Pass ``()`` for no disks.
        disk_radius: Disk radius (m); default: 1.25 times the farthest tendon offset (at least
            the rod's radius).

    Returns:
        The geometry; its ``notes`` say what could not be drawn and why.
    """
    rod = getattr(robot, "rod", robot)
    length = float(rod.length)
    source = _plain(getattr(robot, "source", None))
    notes: list[str] = []
    drawn: RadiusFn | None = None
    solver_radius: RadiusFn | None = None
    radius_source = "unknown"
    section = getattr(rod, "section", None)
    sec_table = source.get("rod", {}).get("section") if source else None
    kind = str(sec_table.get("type", "circular")) if isinstance(sec_table, Mapping) else ""
    if section is None and isinstance(sec_table, Mapping):
        section = _section_from_table(sec_table)
    if section is not None and hasattr(section, "properties"):
        drawn, solver_radius = _radius_functions(section, length, kind)
        radius_source = "section (sqrt(2J/A))" if kind == "table" else "section"
    if radius is not None:
        drawn, radius_source = _as_radius_fn(radius), "given"
    if drawn is None:
        notes.append("section unknown: backbone drawn without its radius")

    tendons: list[TendonGeometry] = []
    tables = list(source.get("tendons", [])) if source else []
    for i, tendon in enumerate(getattr(robot, "tendons", ()) or ()):
        offset_at = getattr(tendon, "offset_at", None)
        offset: OffsetFn | None = None
        if callable(offset_at):

            def offset(s, f=offset_at):
                return np.array([np.asarray(f(float(x)), dtype=float) for x in np.atleast_1d(s)])

        elif i < len(tables):
            offset = _tendon_offset(tables[i], solver_radius)
        if offset is None:
            notes.append(f"tendon {i}: routing not available, not drawn")
            continue
        end = tendon.end if tendon.end is not None else length
        tension = float(tendon.tension)
        tendons.append(TendonGeometry(offset, float(end), f"tendon {i} ({tension:.3g} N)", tension))

    chambers: list[ChamberGeometry] = []
    for i, c in enumerate(getattr(robot, "chambers", ()) or ()):
        end = c.end if c.end is not None else length
        mid = 0.5 * (c.start + end)
        chambers.append(
            ChamberGeometry(
                offset=np.asarray(c.offset, dtype=float),
                radius=math.sqrt(max(float(c.area_at(mid)), 0.0) / math.pi),
                start=float(c.start),
                end=float(end),
                pressure=float(c.pressure),
                label=f"chamber {i} ({c.pressure / 1e3:.3g} kPa)",
            )
        )

    s_chk = np.linspace(0.0, length, 32)
    outside = [
        t
        for t in tendons
        if drawn is None or np.any(np.linalg.norm(t.offset(s_chk), axis=1) > 1.05 * drawn(s_chk))
    ]
    if disks is None:
        # Tendons outside the rod run through spacer disks: a base plate and one disk at
        # every termination. Tendons inside the body (a silicone arm's cable) have none.
        disks = sorted({0.0, *(round(t.end, 12) for t in outside)}) if outside else []
    disks = tuple(float(d) for d in disks)
    for d in disks:
        if not 0.0 <= d <= length:
            err = ParameterError(
                f"invalid parameter `disks` = {list(disks)!r}: arc lengths must be in "
                f"[0, {length:g}] m"
            )
            err.parameter = "disks"
            raise err
    if disk_radius is None:
        s = np.linspace(0.0, length, 32)
        far = max((float(np.max(np.linalg.norm(t.offset(s), axis=1))) for t in tendons), default=0)
        rod_r = float(np.max(drawn(s))) if drawn is not None else 0.0
        disk_radius = max(1.25 * far, 1.5 * rod_r)
    return RobotGeometry(
        length=length,
        radius=drawn,
        tendons=tuple(tendons),
        chambers=tuple(chambers),
        disks=disks,
        disk_radius=float(disk_radius),
        radius_source=radius_source,
        notes=tuple(notes),
    )
