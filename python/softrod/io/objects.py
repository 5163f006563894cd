"""Between a validated robot description (:class:`~softrod.io.robot_file.RobotFile`) and the
model objects of the core (:class:`softrod.Rod`, :class:`softrod.Tendon`, ...), both ways.

:func:`build` makes the objects of a description, reporting every constructor error at its
file location. :func:`describe` reads a description back from objects built in code, through
their read-only properties; what the objects do not expose (or cannot: a Python callable) is
named in the error.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._core import (
    SILICONES,
    Chamber,
    CircularSection,
    FunctionSection,
    Hookean,
    LinearElastic,
    Linearised,
    Loads,
    MooneyRivlin,
    NeoHookean,
    Ogden,
    ParameterError,
    PointLoad,
    Rod,
    TableSection,
    TaperedCircularSection,
    Tendon,
    TubeSection,
    Yeoh,
    silicone,
)
from . import robot_file as rf
from .robot_file import FieldError

__all__ = ["Parts", "build", "describe"]


@dataclass(frozen=True)
class Parts:
    """The model objects of one robot description."""

    rod: Rod
    tendons: tuple[Tendon, ...]
    chambers: tuple[Chamber, ...]
    loads: Loads
    solver: dict[str, Any]
    obstacles: tuple = ()
    tip_constraint: Any = None


_CORE_MESSAGE = re.compile(r"invalid parameter `([^`]*)` = (.*?): (.*)", re.DOTALL)


def _core_error(location: str, exc: Exception) -> FieldError:
    """A constructor's error at the file location of the table it was built from."""
    text = str(exc)
    param = getattr(exc, "parameter", "") or ""
    m = _CORE_MESSAGE.match(text)
    value: Any = None
    if m:
        param = param or m.group(1)
        try:
            value = float(m.group(2))
        except ValueError:
            value = m.group(2)
        text = m.group(3)
    where = f"{location}.{param}" if param else location
    return FieldError(where, text, value, "model")


def _attempt(errors: list[FieldError], location: str, make: Callable[[], Any]) -> Any:
    try:
        return make()
    except (ParameterError, ValueError, TypeError, OverflowError) as exc:
        errors.append(_core_error(location, exc))
        return None


def _degrees(angle: float) -> float:
    """The angle (rad) in degrees, as the float that reads back (``math.radians``) to the
    same radians where one exists (for about ten in eleven angles; else the nearest, one unit
    in the last place off)."""
    d = math.degrees(angle)
    best, err = d, abs(math.radians(d) - angle)
    up = down = d
    for _ in range(4):
        up, down = math.nextafter(up, math.inf), math.nextafter(down, -math.inf)
        for c in (up, down):
            e = abs(math.radians(c) - angle)
            if e < err:
                best, err = c, e
    return best


def _polar(distance: float, angle_deg: float | None) -> list[float]:
    a = math.radians(angle_deg or 0.0)
    return [distance * math.cos(a), distance * math.sin(a)]


def _section(s: Any) -> Any:
    if isinstance(s, rf.CircularSectionSpec):
        return CircularSection(s.radius)
    if isinstance(s, rf.TaperedSectionSpec):
        return TaperedCircularSection(s.base_radius, s.tip_radius)
    if isinstance(s, rf.TubeSectionSpec):
        return TubeSection(s.outer_radius, s.inner_radius)
    return TableSection(s.s, s.area, s.ix, s.iy, s.j)


def build_material(m: Any, errors: list[FieldError]) -> Any:
    """The material law; an error is appended (and None returned) when it cannot be built."""
    where = "rod.material"
    if isinstance(m, rf.SiliconeSpec):
        known = {rf._silicone_key(n): n for n in SILICONES}
        entry = _attempt(
            errors, f"{where}.silicone", lambda: silicone(known[rf._silicone_key(m.silicone)])
        )
        if entry is None:
            return None
        law = getattr(entry, m.type)
        if law is None:
            errors.append(
                FieldError(
                    f"{where}.type",
                    f"the library has no {m.type} parameters for {entry.name}",
                    m.type,
                    "rule",
                )
            )
        return law
    makers = {
        rf.LinearMaterialSpec: lambda: LinearElastic(
            m.youngs_modulus, m.poisson_ratio, shear_modulus=m.shear_modulus
        ),
        rf.NeoHookeanSpec: lambda: NeoHookean(m.mu),
        rf.MooneyRivlinSpec: lambda: MooneyRivlin(m.c10, m.c01),
        rf.YeohSpec: lambda: Yeoh(m.c10, m.c20, m.c30),
        rf.OgdenSpec: lambda: Ogden(m.mu, m.alpha),
        rf.HookeanSpec: lambda: Hookean(m.youngs_modulus),
        rf.LinearisedSpec: lambda: Linearised(m.secant_modulus, m.reference_strain),
    }
    return _attempt(errors, where, makers[type(m)])


def _tendon(t: Any) -> Tendon:
    if isinstance(t, rf.ConstantTendonSpec):
        offset = t.offset if t.offset is not None else _polar(t.distance, t.angle_deg)
        return Tendon(
            offset,
            t.tension,
            t.end,
            friction=t.friction,
            guides=t.guides,
            guide_friction=t.guide_friction,
        )
    if isinstance(t, rf.RadiusProportionalTendonSpec):
        return Tendon.radius_proportional(
            t.ratio, math.radians(t.angle_deg), t.tension, t.end, friction=t.friction
        )
    return Tendon.helical(
        t.radius, t.pitch, t.tension, math.radians(t.phase_deg), t.end, friction=t.friction
    )


def _chamber(c: rf.ChamberSpec) -> Chamber:
    area = c.area if c.area is not None else math.pi * c.radius * c.radius
    offset = c.offset if c.offset is not None else _polar(c.distance, c.angle_deg)
    return Chamber(c.pressure, area, offset, c.start, c.end)


def _loads(spec: rf.LoadsSpec | None, errors: list[FieldError]) -> Loads:
    if spec is None:
        return Loads()
    points = []
    for i, p in enumerate(spec.point_loads):
        pl = _attempt(
            errors,
            f"loads.point_loads[{i}]",
            lambda p=p: PointLoad(p.s, p.force, p.moment, p.frame),
        )
        points.append(pl)
    if any(p is None for p in points):
        return Loads()
    return _attempt(
        errors,
        "loads",
        lambda: Loads(
            tip_force=spec.tip_force,
            tip_moment=spec.tip_moment,
            gravity=spec.gravity,
            tip_frame=spec.tip_frame,
            point_loads=points,
            distributed_force=spec.distributed_force,
            distributed_moment=spec.distributed_moment,
        ),
    )


def build(spec: rf.RobotFile, source: str | None = None) -> Parts:
    """The model objects of a validated description.

    Raises:
        ParameterError: With every constructor error in ``errors``, located in the file.
    """
    errors: list[FieldError] = []
    r = spec.rod
    section = _attempt(errors, "rod.section", lambda: _section(r.section))
    material = build_material(r.material, errors)
    rod = None
    if section is not None and material is not None:
        pose = None
        if r.base_pose is not None:
            pose = (r.base_pose.position, r.base_pose.rotation)
        rod = _attempt(
            errors,
            "rod",
            lambda: Rod(
                r.length,
                section,
                material,
                rest_strain=r.rest_strain,
                rest_curvature=r.rest_curvature,
                inextensible=r.inextensible,
                density=r.density,
                base_pose=pose,
                shear_coefficient=r.shear_coefficient,
            ),
        )
    tendons = [
        _attempt(errors, f"tendons[{i}]", lambda t=t: _tendon(t))
        for i, t in enumerate(spec.tendons)
    ]
    chambers = [
        _attempt(errors, f"chambers[{i}]", lambda c=c: _chamber(c))
        for i, c in enumerate(spec.chambers)
    ]
    loads = _loads(spec.loads, errors)
    # A mesh file's relative path is relative to the robot file.
    base = os.path.dirname(os.path.abspath(source)) if source else os.getcwd()
    obstacles = [
        _attempt(errors, f"obstacles[{i}].{o.type}", lambda o=o: obstacle_of(o, base))
        for i, o in enumerate(spec.obstacles)
    ]
    if errors:
        rf.raise_errors(errors, source)
    solver = spec.solver.options() if spec.solver is not None else {}
    return Parts(
        rod,
        tuple(tendons),
        tuple(chambers),
        loads,
        solver,
        tuple(obstacles),
        tip_constraint_of(spec.tip_constraint),
    )


def _mesh_of(o: Any, base: str) -> Any:
    """The Mesh of a ``type = "mesh"`` table: read (relative to ``base``), scaled, posed."""
    from ..contact import Mesh

    if o.file is not None:
        path = o.file if os.path.isabs(o.file) else os.path.join(base, o.file)
        mesh = Mesh.from_file(path)
        vertices, faces = mesh.vertices, mesh.faces
    else:
        vertices, faces = np.asarray(o.vertices, dtype=float), np.asarray(o.faces)
    vertices = o.scale * vertices
    if o.rotation is not None:
        vertices = vertices @ np.asarray(o.rotation, dtype=float).T
    if o.position is not None:
        vertices = vertices + np.asarray(o.position, dtype=float)
    return Mesh(vertices, faces, o.friction)


def obstacle_of(o: Any, base: str | None = None) -> Any:
    """The obstacle dataclass of an ``[[obstacles]]`` table (a mesh file's relative path is
    taken from ``base``, default the working directory)."""
    from ..contact import Capsule, Cylinder, Plane, Sphere

    if isinstance(o, rf.MeshSpec):
        return _mesh_of(o, base if base is not None else os.getcwd())
    if isinstance(o, rf.PlaneSpec):
        return Plane(tuple(o.point), tuple(o.normal), o.friction)
    if isinstance(o, rf.SphereSpec):
        return Sphere(tuple(o.center), o.radius, o.friction)
    kind = Capsule if isinstance(o, rf.CapsuleSpec) else Cylinder
    return kind(tuple(o.a), tuple(o.b), o.radius, o.friction)


def tip_constraint_of(t: Any) -> Any:
    """The tip constraint of a ``[tip_constraint]`` table (None without one)."""
    import numpy as np

    from ..contact import Clamp, Pin, Slide

    if t is None:
        return None
    missing = [
        k
        for k in {"clamp": ["position"], "pin": ["point"], "slide": ["point", "normal"]}[t.type]
        if getattr(t, k) is None
    ]
    if missing:
        rf.raise_errors(
            [
                FieldError(f"tip_constraint.{k}", f"needed by `{t.type}`", kind="missing")
                for k in missing
            ]
        )
    if t.type == "clamp":
        pose = np.eye(4)
        pose[:3, 3] = t.position
        if t.rotation is not None:
            r = np.asarray(t.rotation, dtype=float)
            if r.shape != (3, 3) or not np.allclose(r.T @ r, np.eye(3), atol=1e-9):
                rf.raise_errors(
                    [
                        FieldError(
                            "tip_constraint.rotation",
                            "must be a rotation matrix (orthonormal rows, 3x3)",
                            t.rotation,
                            kind="range",
                        )
                    ]
                )
            pose[:3, :3] = r
        return Clamp(pose, tuple(t.held) if t.held is not None else None)
    if t.type == "pin":
        return Pin(tuple(t.point))
    return Slide(tuple(t.point), tuple(t.normal))


def tip_constraint_spec(t: Any) -> dict[str, Any]:
    """The ``[tip_constraint]`` table of a ``Clamp``, ``Pin`` or ``Slide``."""
    import numpy as np

    from ..contact import Clamp, Pin

    if isinstance(t, Clamp):
        pose = np.asarray(t.pose, dtype=float)
        out: dict[str, Any] = {
            "type": "clamp",
            "position": [float(x) for x in pose[:3, 3]],
            "rotation": [[float(x) for x in row] for row in pose[:3, :3]],
        }
        if t.held is not None:
            out["held"] = [bool(h) for h in t.held]
        return out
    if isinstance(t, Pin):
        return {"type": "pin", "point": [float(x) for x in t.point]}
    return {
        "type": "slide",
        "point": [float(x) for x in t.point],
        "normal": [float(x) for x in t.normal],
    }


def obstacle_spec(o: Any) -> dict[str, Any]:
    """The ``[[obstacles]]`` table of an obstacle dataclass."""
    from ..plot.obstacles import as_obstacle

    o = as_obstacle(o)
    friction = float(getattr(o, "friction", 0.0))
    if type(o).__name__ == "Mesh":
        # Written out in full: a robot file then stands on its own.
        mesh: dict[str, Any] = {
            "type": "mesh",
            "vertices": [[float(x) for x in v] for v in o.vertices],
            "faces": [[int(i) for i in f] for f in o.faces],
        }
        if friction > 0:
            mesh["friction"] = friction
        return mesh
    kind = type(o).__name__.lower()
    fields = {k: getattr(o, k) for k in o.__dataclass_fields__ if k != "friction"}
    out: dict[str, Any] = {"type": kind}
    for k, v in fields.items():
        out[k] = float(v) if k == "radius" else [float(x) for x in v]
    if friction > 0:
        out["friction"] = friction
    return out


# ----------------------------------------------------------------------------- objects -> spec


class _Reader:
    """Reads properties of model objects, remembering the ones that are not there."""

    def __init__(self) -> None:
        self.missing: list[str] = []
        self.unserialisable: list[str] = []

    def get(self, obj: Any, name: str) -> Any:
        try:
            return getattr(obj, name)
        except AttributeError:
            self.missing.append(f"{type(obj).__name__}.{name}")
            return None

    def error(self) -> ParameterError | None:
        parts = []
        if self.unserialisable:
            parts.append("cannot be written to a file: " + ", ".join(self.unserialisable))
        if self.missing:
            names = ", ".join(dict.fromkeys(self.missing))
            parts.append(f"the model objects do not expose {names}")
        if not parts:
            return None
        exc = ParameterError(
            "cannot describe this robot as a robot file (to_toml, with_parameters, "
            "compare_models): " + "; ".join(parts)
        )
        exc.parameter = "robot"
        exc.missing = list(dict.fromkeys(self.missing))
        exc.unserialisable = list(self.unserialisable)
        return exc


def _floats(v: Any) -> list[float]:
    return [float(x) for x in np.asarray(v, dtype=float).ravel()]


def _vector(value: Any, what: str, r: _Reader) -> list[float] | None:
    if value is None:
        return None
    if callable(value):
        r.unserialisable.append(f"{what} (a Python function)")
        return None
    return _floats(value)


def _describe_section(sec: Any, r: _Reader) -> dict[str, Any] | None:
    if isinstance(sec, FunctionSection):
        r.unserialisable.append("rod.section (a FunctionSection)")
        return None
    fields = {
        CircularSection: ("circular", ("radius",)),
        TaperedCircularSection: ("tapered", ("base_radius", "tip_radius")),
        TubeSection: ("tube", ("outer_radius", "inner_radius")),
        TableSection: ("table", ("s", "area", "ix", "iy", "j")),
    }
    if type(sec) not in fields:
        r.unserialisable.append(f"rod.section (a {type(sec).__name__})")
        return None
    kind, names = fields[type(sec)]
    out: dict[str, Any] = {"type": kind}
    for name in names:
        v = r.get(sec, name)
        if v is not None:
            out[name] = _floats(v) if kind == "table" else float(v)
    return out


_LAW_TYPES = {
    NeoHookean: "neo_hookean",
    MooneyRivlin: "mooney_rivlin",
    Yeoh: "yeoh",
    Ogden: "ogden",
    Hookean: "hookean",
    Linearised: "linearised",
}


def _describe_material(mat: Any, r: _Reader) -> dict[str, Any] | None:
    if isinstance(mat, LinearElastic):
        e, nu, g = mat.youngs_modulus, mat.poisson_ratio, mat.shear_modulus
        # Whichever of Poisson's ratio and the shear modulus rebuilds the same numbers.
        if LinearElastic(e, nu).shear_modulus == g:
            return {"type": "linear", "youngs_modulus": e, "poisson_ratio": nu}
        return {"type": "linear", "youngs_modulus": e, "shear_modulus": g}
    kind = _LAW_TYPES.get(type(mat))
    if kind is None:
        r.unserialisable.append(f"rod.material (a {type(mat).__name__})")
        return None
    return {"type": kind, **dict(mat.parameters)}


def _describe_tendon(t: Tendon, i: int, r: _Reader) -> dict[str, Any] | None:
    out: dict[str, Any] = {"tension": float(t.tension)}
    if t.end is not None:
        out["end"] = float(t.end)
    if t.friction:
        out["friction"] = float(t.friction)
    routing, p = r.get(t, "routing"), r.get(t, "parameters")
    if routing is None or p is None:
        return None
    if routing == "constant" and p.get("derivative") is None and not callable(p["offset"]):
        if t.guides:
            out["guides"] = [float(g) for g in t.guides]
            out["guide_friction"] = [float(m) for m in t.guide_friction]
        return {**out, "offset": _floats(p["offset"])}
    if routing == "radius_proportional":
        return {
            **out,
            "routing": routing,
            "ratio": p["ratio"],
            "angle_deg": _degrees(p["angle"]),
        }
    if routing == "helical":
        return {
            **out,
            "routing": routing,
            "radius": p["radius"],
            "pitch": p["pitch"],
            "phase_deg": _degrees(p["phase"]),
        }
    r.unserialisable.append(f"tendons[{i}] (routing {routing!r} with a Python function)")
    return None


def _describe_chamber(c: Chamber, i: int, r: _Reader) -> dict[str, Any] | None:
    area = r.get(c, "area")
    if area is None:
        return None
    if callable(area):
        r.unserialisable.append(f"chambers[{i}].area (a Python function)")
        return None
    out = {
        "pressure": float(c.pressure),
        "area": float(area),
        "offset": _floats(c.offset),
        "start": float(c.start),
    }
    if c.end is not None:
        out["end"] = float(c.end)
    return out


def _describe_loads(loads: Loads, r: _Reader) -> dict[str, Any] | None:
    out: dict[str, Any] = {}
    for name in ("tip_force", "tip_moment", "gravity", "distributed_force", "distributed_moment"):
        v = _vector(r.get(loads, name), f"loads.{name}", r)
        if v is not None:
            out[name] = v
    frame = r.get(loads, "tip_frame")
    if frame is not None:
        out["tip_frame"] = frame
    points = r.get(loads, "point_loads")
    if points:
        out["point_loads"] = [
            {
                "s": float(p.s),
                "force": _floats(p.force),
                "moment": _floats(p.moment),
                "frame": p.frame,
            }
            for p in points
        ]
    return out


def describe(
    rod: Rod,
    tendons: Sequence[Tendon],
    chambers: Sequence[Chamber],
    loads: Loads | None,
    solver: dict[str, Any],
    name: str,
    description: str,
) -> rf.RobotFile:
    """The robot description of model objects built in code (``loads=None``: unloaded).

    Raises:
        ParameterError: Naming every property the objects do not expose and every part that
            is a Python callable (``missing`` and ``unserialisable`` list them).
    """
    r = _Reader()
    rod_table: dict[str, Any] = {
        "length": float(rod.length),
        "inextensible": bool(rod.inextensible),
        "shear_coefficient": float(rod.shear_coefficient),
    }
    if rod.density is not None:
        rod_table["density"] = float(rod.density)
    pose = np.asarray(rod.base_pose, dtype=float)
    if not np.array_equal(pose, np.eye(4)):
        rod_table["base_pose"] = {
            "position": _floats(pose[:3, 3]),
            "rotation": [_floats(row) for row in pose[:3, :3]],
        }
    section = r.get(rod, "section")
    material = r.get(rod, "material")
    rod_table["section"] = _describe_section(section, r) if section is not None else None
    rod_table["material"] = _describe_material(material, r) if material is not None else None
    for key in ("rest_strain", "rest_curvature"):
        v = _vector(r.get(rod, key), f"rod.{key}", r)
        if v is not None:
            rod_table[key] = v
    data: dict[str, Any] = {
        "name": name,
        "description": description,
        "rod": rod_table,
        "tendons": [_describe_tendon(t, i, r) for i, t in enumerate(tendons)],
        "chambers": [_describe_chamber(c, i, r) for i, c in enumerate(chambers)],
    }
    if loads is not None:
        data["loads"] = _describe_loads(loads, r)
    if solver:
        data["solver"] = dict(solver)
    exc = r.error()
    if exc is not None:
        raise exc
    return rf.validate_robot_dict(data)
