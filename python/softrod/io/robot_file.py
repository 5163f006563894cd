"""Robot description files (TOML): the schema, reading with located errors, and writing.

The schema is a tree of pydantic models, one per table of the file (:class:`RobotFile` at the
top). Validation is strict: numbers are numbers (``true`` or ``"3"`` are not), integers are
integers, floats are finite, tables are tables, unknown keys are errors with a suggestion for
the closest known key. Every error carries its location in the file's own notation
(``tendons[2].distance``), and all errors of a file are reported together: a
:class:`softrod.ParameterError` whose ``errors`` attribute lists :class:`FieldError` records
and whose ``parameter`` is the first location. ``softrod schema`` prints the JSON Schema
(:func:`robot_file_json_schema`), also published in ``docs/robot-file.schema.json``.

Rules that tie fields together (a tendon ending past the rod's tip, gravity without a density)
are checked once the fields are valid, with the same kind of errors.
"""

from __future__ import annotations

import difflib
import math
import os
import sys
import typing
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Annotated, Any, Literal, Union

from pydantic import (
    AllowInfNan,
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    Strict,
    Tag,
    ValidationError,
    model_validator,
)
from pydantic_core import PydanticCustomError

from .._core import SILICONES, ParameterError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = [
    "ChamberSpec",
    "FieldError",
    "LoadsSpec",
    "RobotFile",
    "RodSpec",
    "SolverSpec",
    "dump_robot_toml",
    "read_robot_toml",
    "robot_file_errors",
    "robot_file_json_schema",
    "validate_robot_dict",
]

#: Largest integration steps, Newton iterations and load steps a file may ask for (named
#: limits rather than an allocation that fails).
MAX_STEPS = 1_000_000
MAX_ITERATIONS = 100_000
MAX_LOAD_STEPS = 100_000

Float = Annotated[float, Strict(), AllowInfNan(False)]
Int = Annotated[int, Strict()]
Bool = Annotated[bool, Strict()]
Str = Annotated[str, Strict()]


def _num(description: str, **bounds: float) -> Any:
    return Annotated[Float, Field(description=description, **bounds)]


def _vec(n: int, description: str) -> Any:
    return Annotated[list[Float], Field(min_length=n, max_length=n, description=description)]


Vec2 = _vec(2, "[x, y] (m, body frame)")
Vec3 = _vec(3, "3-vector")


class _Table(BaseModel):
    """A table of the file: unknown keys are errors; immutable once validated."""

    model_config = ConfigDict(extra="forbid", frozen=True)


def _exclusive(table: Mapping[str, Any], a: str, b: str, what: str) -> None:
    """Exactly one of two keys (reported at the first)."""
    if (table.get(a) is None) == (table.get(b) is None):
        raise PydanticCustomError(
            "exclusive",
            "give either `{a}` or `{b}` ({what}), not both or neither",
            {"field": a, "a": a, "b": b, "what": what},
        )


# ----------------------------------------------------------------------------- sections


class CircularSectionSpec(_Table):
    """Solid circle of constant radius."""

    type: Literal["circular"] = "circular"
    radius: _num("radius (m)", gt=0)


class TaperedSectionSpec(_Table):
    """Solid circle tapering linearly from the base radius to the tip radius."""

    type: Literal["tapered"]
    base_radius: _num("radius at s = 0 (m)", gt=0)
    tip_radius: _num("radius at s = length (m)", gt=0)


class TubeSectionSpec(_Table):
    """Circular tube."""

    type: Literal["tube"]
    outer_radius: _num("outer radius (m)", gt=0)
    inner_radius: _num("inner radius (m)", ge=0) = 0.0


_Positives = Annotated[list[_num("", gt=0)], Field(min_length=2)]


class TableSectionSpec(_Table):
    """Section properties tabulated over arc length (linear interpolation)."""

    type: Literal["table"]
    s: Annotated[list[Float], Field(min_length=2, description="arc lengths (m), 0 to length")]
    area: Annotated[_Positives, Field(description="areas (m^2)")]
    ix: Annotated[_Positives, Field(description="second moments about body x (m^4)")]
    iy: Annotated[_Positives, Field(description="second moments about body y (m^4)")]
    j: Annotated[_Positives, Field(description="torsion constants (m^4)")]

    @model_validator(mode="after")
    def _same_lengths(self) -> TableSectionSpec:
        n = len(self.s)
        for name in ("area", "ix", "iy", "j"):
            if len(getattr(self, name)) != n:
                raise PydanticCustomError(
                    "table_length",
                    "must have one value per entry of `s` ({n}), got {m}",
                    {"field": name, "n": n, "m": len(getattr(self, name))},
                )
        return self


# ----------------------------------------------------------------------------- materials


class LinearMaterialSpec(_Table):
    """Linear elastic: Young's modulus with Poisson's ratio or the shear modulus."""

    type: Literal["linear"] = "linear"
    youngs_modulus: _num("Young's modulus (Pa)", gt=0)
    poisson_ratio: _num("Poisson's ratio", gt=-1, le=0.5) | None = None
    shear_modulus: _num("shear modulus (Pa)", gt=0) | None = None


class NeoHookeanSpec(_Table):
    """Neo-Hookean law (incompressible fibre section)."""

    type: Literal["neo_hookean"]
    mu: _num("initial shear modulus (Pa)", gt=0)


class MooneyRivlinSpec(_Table):
    """Two-parameter Mooney-Rivlin law."""

    type: Literal["mooney_rivlin"]
    c10: _num("C10 (Pa)")
    c01: _num("C01 (Pa)")


class YeohSpec(_Table):
    """Yeoh law."""

    type: Literal["yeoh"]
    c10: _num("C10 (Pa)", gt=0)
    c20: _num("C20 (Pa)") = 0.0
    c30: _num("C30 (Pa)") = 0.0


class OgdenSpec(_Table):
    """N-term Ogden law."""

    type: Literal["ogden"]
    mu: Annotated[list[Float], Field(min_length=1, description="moduli mu_i (Pa)")]
    alpha: Annotated[list[Float], Field(min_length=1, description="exponents alpha_i")]


class HookeanSpec(_Table):
    """Linear uniaxial law P = E (stretch - 1) (incompressible fibre section)."""

    type: Literal["hookean"]
    youngs_modulus: _num("Young's modulus (Pa)", gt=0)


class LinearisedSpec(_Table):
    """Linear law through the origin with a secant modulus taken at a reference strain."""

    type: Literal["linearised"]
    secant_modulus: _num("secant modulus (Pa)", gt=0)
    reference_strain: _num("engineering strain of the secant point")


def _silicone_key(name: str) -> str:
    return " ".join(name.lower().split())


class SiliconeSpec(_Table):
    """A silicone of the library (``softrod materials``) with one of its fitted laws."""

    silicone: Annotated[
        Str,
        Field(
            description="library name, case-insensitive",
            json_schema_extra={"examples": list(SILICONES)},
        ),
    ]
    type: Annotated[
        Literal["neo_hookean", "mooney_rivlin", "yeoh"],
        Field(description="which of the library's laws"),
    ] = "yeoh"

    @model_validator(mode="after")
    def _known(self) -> SiliconeSpec:
        known = {_silicone_key(n): n for n in SILICONES}
        if _silicone_key(self.silicone) not in known:
            raise PydanticCustomError(
                "silicone",
                "must be one of {names} (case-insensitive)",
                {"field": "silicone", "names": ", ".join(SILICONES), "choices": list(SILICONES)},
            )
        return self


# ----------------------------------------------------------------------------- tendons


def _tag_of(key: str, default: str, members: Mapping[str, type], by_key=None):
    """Discriminator of a union of tables: the value of ``key`` (``default`` when absent)."""
    by_class = {m: t for t, m in members.items()}

    def tag(value: Any) -> str:
        if not isinstance(value, Mapping):
            return by_class.get(type(value), default)
        for k, t in (by_key or {}).items():
            if k in value:
                return t
        v = value.get(key, default)
        return v if isinstance(v, str) else repr(v)

    return tag


def _union(key: str, default: str, members: dict[str, type], by_key=None) -> Any:
    tags = ", ".join(members)
    return Annotated[
        Union[tuple(Annotated[m, Tag(t)] for t, m in members.items())],  # noqa: UP007
        Discriminator(
            _tag_of(key, default, members, by_key),
            custom_error_type="invalid_tag",
            custom_error_message=f"must be one of {tags}",
            custom_error_context={"field": key, "expected": tags},
        ),
    ]


class _TendonBase(_Table):
    tension: _num("tension (N)", ge=0) = 0.0
    end: _num("arc length where the tendon ends (m); default the tip", gt=0) | None = None
    friction: _num("friction coefficient between tendon and channel (capstan law)", ge=0) = 0.0


class ConstantTendonSpec(_TendonBase):
    """A tendon at a constant body-frame offset (in a continuous channel, or through guides)."""

    routing: Literal["constant"] = "constant"
    offset: Vec2 | None = None
    distance: _num("distance from the backbone (m)", ge=0) | None = None
    angle_deg: _num("angle from body x toward body y (deg), with `distance`") | None = None
    guides: list[Float] | None = Field(
        None, description="arc lengths (m) of the disks the tendon runs through in chords"
    )
    guide_friction: Float | list[Float] | None = Field(
        None, description="capstan coefficient at the guides (one, or one per guide)"
    )

    @model_validator(mode="after")
    def _one_offset(self) -> ConstantTendonSpec:
        _exclusive(self.__dict__, "distance", "offset", "the offset")
        if self.offset is not None and self.angle_deg is not None:
            raise PydanticCustomError(
                "with_distance", "goes with `distance`, not `offset`", {"field": "angle_deg"}
            )
        return self


class RadiusProportionalTendonSpec(_TendonBase):
    """A tendon whose offset is a fixed fraction of the local section radius."""

    routing: Literal["radius_proportional"]
    ratio: _num("offset / local radius", ge=0, lt=1)
    angle_deg: _num("angle from body x toward body y (deg)") = 0.0


class HelicalTendonSpec(_TendonBase):
    """A helical tendon around the backbone."""

    routing: Literal["helical"]
    radius: _num("helix radius (m)", gt=0)
    pitch: _num("advance per turn (m); positive is right-handed")
    phase_deg: _num("angle at s = 0 from body x (deg)") = 0.0


TendonSpec = _union(
    "routing",
    "constant",
    {
        "constant": ConstantTendonSpec,
        "radius_proportional": RadiusProportionalTendonSpec,
        "helical": HelicalTendonSpec,
    },
)
SectionSpec = _union(
    "type",
    "circular",
    {
        "circular": CircularSectionSpec,
        "tapered": TaperedSectionSpec,
        "tube": TubeSectionSpec,
        "table": TableSectionSpec,
    },
)
MaterialSpec = _union(
    "type",
    "linear",
    {
        "linear": LinearMaterialSpec,
        "neo_hookean": NeoHookeanSpec,
        "mooney_rivlin": MooneyRivlinSpec,
        "yeoh": YeohSpec,
        "ogden": OgdenSpec,
        "hookean": HookeanSpec,
        "linearised": LinearisedSpec,
        "silicone": SiliconeSpec,
    },
    by_key={"silicone": "silicone"},
)


# ----------------------------------------------------------------------------- the rest


class ChamberSpec(_Table):
    """A pneumatic chamber: pressure, area, centroid offset and extent along the rod."""

    pressure: _num("gauge pressure (Pa)") = 0.0
    area: _num("cross-section area (m^2)", gt=0) | None = None
    radius: _num("radius of a circular chamber (m)", gt=0) | None = None
    offset: Vec2 | None = None
    distance: _num("centroid distance from the backbone (m)", ge=0) | None = None
    angle_deg: _num("centroid angle from body x toward body y (deg)") | None = None
    start: _num("arc length where the chamber starts (m)", ge=0) = 0.0
    end: _num("arc length where it ends (m); default the tip", gt=0) | None = None

    @model_validator(mode="after")
    def _one_each(self) -> ChamberSpec:
        _exclusive(self.__dict__, "area", "radius", "m^2, or m for a circular chamber")
        _exclusive(self.__dict__, "distance", "offset", "the centroid")
        if self.offset is not None and self.angle_deg is not None:
            raise PydanticCustomError(
                "with_distance", "goes with `distance`, not `offset`", {"field": "angle_deg"}
            )
        if self.end is not None and self.end <= self.start:
            raise PydanticCustomError(
                "order", "must be > `start` = {start} m", {"field": "end", "start": self.start}
            )
        return self


class BasePoseSpec(_Table):
    """Pose of the rod's base in the world: position and rotation (body -> world)."""

    position: _vec(3, "base position (m)") = [0.0, 0.0, 0.0]
    rotation: Annotated[
        list[_vec(3, "row")],
        Field(min_length=3, max_length=3, description="3x3 rotation rows (body -> world)"),
    ] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]


class RodSpec(_Table):
    """The rod: length, section, material and optional rest shape, density and base pose."""

    length: _num("length (m)", gt=0)
    section: SectionSpec
    material: MaterialSpec
    density: _num("density (kg/m^3), needed for gravity", gt=0) | None = None
    inextensible: Annotated[Bool, Field(description="Kirchhoff rod: no stretch or shear")] = False
    shear_coefficient: _num("shear coefficient (default Cowper's)", gt=0) | None = None
    rest_strain: _vec(3, "rest strain v (body frame); default [0, 0, 1]") | None = None
    rest_curvature: _vec(3, "rest curvature u (1/m, body frame); default 0") | None = None
    base_pose: BasePoseSpec | None = None


class PointLoadSpec(_Table):
    """A force and moment applied at one arc length."""

    s: _num("arc length (m)", ge=0)
    force: _vec(3, "force (N)") = [0.0, 0.0, 0.0]
    moment: _vec(3, "moment (N m)") = [0.0, 0.0, 0.0]
    frame: Literal["world", "body"] = "world"


class LoadsSpec(_Table):
    """External loads (world frame unless told otherwise)."""

    tip_force: _vec(3, "tip force (N)") | None = None
    tip_moment: _vec(3, "tip moment (N m)") | None = None
    tip_frame: Literal["world", "body"] = "world"
    gravity: _vec(3, "gravitational acceleration (m/s^2, world); needs rod.density") | None = None
    distributed_force: _vec(3, "force per length (N/m, world)") | None = None
    distributed_moment: _vec(3, "moment per length (N m/m, world)") | None = None
    point_loads: list[PointLoadSpec] = []


class SolverSpec(_Table):
    """Options of :func:`softrod.solve_statics` (the core's defaults when absent)."""

    integrator: Literal["rk4", "adaptive"] | None = None
    steps: Annotated[Int, Field(ge=1, le=MAX_STEPS, description="RK4 steps")] | None = None
    rtol: _num("relative tolerance of the adaptive integrator", gt=0) | None = None
    atol: _num("absolute tolerance of the adaptive integrator", gt=0) | None = None
    tolerance: _num("Newton residual tolerance", gt=0) | None = None
    max_iterations: Annotated[Int, Field(ge=1, le=MAX_ITERATIONS)] | None = None
    continuation: Bool | None = None
    max_load_steps: Annotated[Int, Field(ge=1, le=MAX_LOAD_STEPS)] | None = None

    def options(self) -> dict[str, Any]:
        """The options that are given, as keyword arguments."""
        return {k: v for k, v in self.__dict__.items() if v is not None}


class PlaneSpec(_Table):
    """A plane obstacle through `point` with outward `normal` (world)."""

    type: Literal["plane"]
    point: _vec(3, "a point of the plane (m, world)")
    normal: _vec(3, "outward normal (world; any nonzero length)")
    friction: _num("Coulomb friction coefficient of the surface (dimensionless)", ge=0) = 0.0


class SphereSpec(_Table):
    """A sphere obstacle."""

    type: Literal["sphere"]
    center: _vec(3, "centre (m, world)")
    radius: _num("radius (m)", gt=0)
    friction: _num("Coulomb friction coefficient of the surface (dimensionless)", ge=0) = 0.0


class CapsuleSpec(_Table):
    """The points within `radius` of the segment `a`-`b` (world)."""

    type: Literal["capsule"]
    a: _vec(3, "first end of the axis (m, world)")
    b: _vec(3, "second end of the axis (m, world)")
    radius: _num("radius (m)", gt=0)
    friction: _num("Coulomb friction coefficient of the surface (dimensionless)", ge=0) = 0.0


class CylinderSpec(_Table):
    """A closed cylinder with cap centres `a` and `b` (world)."""

    type: Literal["cylinder"]
    a: _vec(3, "centre of the first cap (m, world)")
    b: _vec(3, "centre of the second cap (m, world)")
    radius: _num("radius (m)", gt=0)
    friction: _num("Coulomb friction coefficient of the surface (dimensionless)", ge=0) = 0.0


class MeshSpec(_Table):
    """A triangle mesh: read from `file` (STL, OBJ, PLY, ... by trimesh; a relative path is
    relative to the robot file) or given by `vertices` and `faces`; its vertices scaled by
    `scale`, then rotated by `rotation` and moved by `position` (world)."""

    type: Literal["mesh"]
    file: Str | None = None
    vertices: (
        Annotated[list[Vec3], Field(min_length=3, description="vertices (m, mesh frame)")] | None
    ) = None
    faces: (
        Annotated[
            list[Annotated[list[Annotated[int, Field(ge=0)]], Field(min_length=3, max_length=3)]],
            Field(min_length=1, description="vertex indices of each triangle"),
        ]
        | None
    ) = None
    scale: _num("factor from the mesh's units to m (1e-3 for a mesh in mm)", gt=0) = 1.0
    position: _vec(3, "translation of the mesh frame (m, world)") | None = None
    rotation: (
        Annotated[
            list[_vec(3, "row")],
            Field(min_length=3, max_length=3, description="3x3 rotation rows (mesh -> world)"),
        ]
        | None
    ) = None
    friction: _num("Coulomb friction coefficient of the surface (dimensionless)", ge=0) = 0.0

    @model_validator(mode="after")
    def _one_source(self) -> MeshSpec:
        _exclusive(self.__dict__, "file", "vertices", "a mesh file, or vertices and faces")
        if self.vertices is not None and self.faces is None:
            raise PydanticCustomError("needed", "needed with `vertices`", {"field": "faces"})
        if self.vertices is None and self.faces is not None:
            raise PydanticCustomError(
                "with_vertices", "goes with `vertices`, not `file`", {"field": "faces"}
            )
        return self


ObstacleSpec = Annotated[
    PlaneSpec | SphereSpec | CapsuleSpec | CylinderSpec | MeshSpec, Field(discriminator="type")
]


class TipConstraintSpec(_Table):
    """The tip held: `clamp` at `position` and `rotation` (optionally only the `held`
    directions), `pin` at `point`, or `slide` on the plane through `point` with `normal`."""

    type: Literal["clamp", "pin", "slide"]
    position: _vec(3, "clamped tip position (m, world)") | None = None
    rotation: (
        Annotated[
            list[_vec(3, "row")],
            Field(min_length=3, max_length=3, description="3x3 rotation rows (body -> world)"),
        ]
        | None
    ) = None
    held: (
        Annotated[
            list[Bool],
            Field(min_length=6, max_length=6, description="held [x, y, z, rx, ry, rz]"),
        ]
        | None
    ) = None
    point: _vec(3, "pin or plane point (m, world)") | None = None
    normal: _vec(3, "plane normal of `slide` (world)") | None = None


class RobotFile(_Table):
    """A whole robot description file."""

    name: Str | None = None
    description: Str = ""
    rod: RodSpec
    tendons: list[TendonSpec] = []
    chambers: list[ChamberSpec] = []
    loads: LoadsSpec | None = None
    solver: SolverSpec | None = None
    obstacles: list[ObstacleSpec] = []
    tip_constraint: TipConstraintSpec | None = None


# ----------------------------------------------------------------------------- errors


@dataclass(frozen=True)
class FieldError:
    """One error of a robot description.

    Attributes:
        location: Where, in the file's notation (``tendons[2].distance``; ``""`` for the
            whole file).
        message: What is wrong and what is valid (``must be > 0``).
        value: The offending value (``None`` when the key is missing or unknown).
        kind: A short machine-readable kind: ``missing``, ``unknown_key``, ``type``,
            ``range``, ``choice``, ``rule`` or ``model`` (rejected by the model itself).
        suggestion: For a misspelt key or choice, the closest valid one.
    """

    location: str
    message: str
    value: Any = None
    kind: str = "rule"
    suggestion: str | None = None

    def __str__(self) -> str:
        where = f"`{self.location}`" if self.location else "the file"
        if self.value is not None and self.kind not in ("missing", "unknown_key"):
            return f"{where} = {_short(self.value)}: {self.message}"
        return f"{where}: {self.message}"


def _toml_text(value: Any) -> str:
    """A value as it reads in a TOML file (``true``, ``"2"``, ``inf``, ``[1.0, 2.0]``)."""
    import json

    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, list):
        return "[" + ", ".join(_toml_text(v) for v in value) + "]"
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{k} = {_toml_text(v)}" for k, v in value.items()) + " }"
    return repr(value)


def _short(value: Any, limit: int = 60) -> str:
    text = _toml_text(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def format_location(loc: Sequence[Any]) -> str:
    """``("tendons", 2, "distance")`` -> ``"tendons[2].distance"``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def raise_errors(errors: Sequence[FieldError], source: str | None = None) -> typing.NoReturn:
    """Raises one :class:`ParameterError` carrying every error (``errors``), the first
    location (``parameter``) and the file (``source``)."""
    errors = list(errors)
    head = f"{source}: " if source else ""
    if len(errors) == 1 and not errors[0].location:
        text = f"{head}invalid robot file: {errors[0].message}"
    elif len(errors) == 1:
        text = f"{head}invalid field {errors[0]}"
    else:
        lines = "\n".join(f"  {e}" for e in errors)
        text = f"{head}{len(errors)} invalid fields:\n{lines}"
    exc = ParameterError(text)
    exc.errors = errors
    exc.parameter = errors[0].location if errors else ""
    exc.source = source
    raise exc


# Tags of the unions, which pydantic inserts in error locations after the union's field.
_UNION_FIELDS = {"section", "material"}


def _clean_loc(loc: Sequence[Any]) -> tuple[Any, ...]:
    """Drops the union tags pydantic adds to a location (``rod.material.yeoh.c10``)."""
    out: list[Any] = []
    for i, part in enumerate(loc):
        prev = loc[i - 1] if i else None
        under_union = prev in _UNION_FIELDS or (
            isinstance(prev, int) and i >= 2 and loc[i - 2] == "tendons"
        )
        if under_union and isinstance(part, str) and not out[-1:] == [part]:
            if part in _all_tags():
                continue
        out.append(part)
    return tuple(out)


def _all_tags() -> set[str]:
    return {
        "circular",
        "tapered",
        "tube",
        "table",
        "linear",
        "neo_hookean",
        "mooney_rivlin",
        "yeoh",
        "ogden",
        "hookean",
        "linearised",
        "silicone",
        "constant",
        "radius_proportional",
        "helical",
    }


def _unwrap(tp: Any) -> list[Any]:
    """The candidate types of an annotation (Annotated, Optional and unions unwrapped)."""
    origin = typing.get_origin(tp)
    if origin is Annotated:
        return _unwrap(typing.get_args(tp)[0])
    if origin is Union or type(tp).__name__ == "UnionType":
        return [t for a in typing.get_args(tp) for t in _unwrap(a) if t is not type(None)]
    return [tp]


def _tagged(tp: Any) -> dict[str, type]:
    """Members of a tagged union by tag (empty if ``tp`` is not one)."""
    if typing.get_origin(tp) is Annotated:
        inner = typing.get_args(tp)[0]
        if typing.get_origin(inner) is Union:
            out = {}
            for member in typing.get_args(inner):
                args = typing.get_args(member)
                tags = [m for m in args[1:] if isinstance(m, Tag)]
                if tags:
                    out[tags[0].tag] = args[0]
            return out
    return {}


def _models_at(raw_loc: Sequence[Any]) -> list[type[BaseModel]]:
    """The models a raw pydantic location (with union tags) points into."""
    current: list[Any] = [RobotFile]
    for part in raw_loc:
        nxt: list[Any] = []
        for tp in current:
            tagged = _tagged(tp)
            if tagged:
                if isinstance(part, str) and part in tagged:
                    nxt.append(tagged[part])
                continue
            for t in _unwrap(tp):
                if isinstance(t, type) and issubclass(t, BaseModel) and isinstance(part, str):
                    field = t.model_fields.get(part)
                    if field is not None:
                        nxt.append(field.annotation)
                        nxt.extend(_unwrap_meta(field))
                elif typing.get_origin(t) is list and isinstance(part, int):
                    nxt.extend(typing.get_args(t))
        current = nxt
    out = []
    for tp in current:
        tagged = _tagged(tp)
        members = list(tagged.values()) if tagged else _unwrap(tp)
        out.extend(t for t in members if isinstance(t, type) and issubclass(t, BaseModel))
    return out


def _unwrap_meta(field: Any) -> list[Any]:
    """A field's annotation with its ``Annotated`` metadata restored (tagged unions keep the
    discriminator in the metadata pydantic moves out of the annotation)."""
    disc = [m for m in field.metadata if isinstance(m, Discriminator)]
    if disc and typing.get_origin(field.annotation) is Union:
        return [Annotated[(field.annotation, *disc)]]
    return []


def _suggest(word: str, candidates: Sequence[str]) -> str | None:
    """The closest candidate (case-insensitive), if close enough."""
    lower = {str(c).lower(): str(c) for c in candidates}
    close = difflib.get_close_matches(word.lower(), list(lower), n=1, cutoff=0.6)
    return lower[close[0]] if close else None


_TYPE_WORDS = {
    "float_type": "must be a number",
    "int_type": "must be an integer",
    "bool_type": "must be true or false",
    "string_type": "must be a string",
    "list_type": "must be an array",
    "model_type": "must be a table",
    "model_attributes_type": "must be a table",
    "dict_type": "must be a table",
    "finite_number": "must be a finite number",
    "float_parsing": "must be a number",
    "int_from_float": "must be an integer",
}


def _translate(err: Mapping[str, Any]) -> tuple[tuple[Any, ...], str, str, Any]:
    """(location, message, kind, value) of one pydantic error."""
    raw_loc, typ, ctx = tuple(err["loc"]), err["type"], err.get("ctx") or {}
    value = err.get("input")
    if typ in _TYPE_WORDS:
        return raw_loc, _TYPE_WORDS[typ], "type", value
    bounds = {
        "greater_than": ("> ", "gt"),
        "greater_than_equal": (">= ", "ge"),
        "less_than": ("< ", "lt"),
        "less_than_equal": ("<= ", "le"),
    }
    if typ in bounds:
        op, key = bounds[typ]
        unit = _unit(raw_loc)
        return raw_loc, f"must be {op}{ctx[key]:g}{' ' + unit if unit else ''}", "range", value
    if typ in ("too_short", "too_long"):
        lo, hi = ctx.get("min_length"), ctx.get("max_length")
        want = f"{lo} values" if lo == hi or (hi is None and typ == "too_long") else None
        if want is None:
            want = f"at least {lo} values" if typ == "too_short" else f"at most {hi} values"
        return raw_loc, f"must have {want} (got {ctx.get('actual_length')})", "type", value
    if typ == "literal_error":
        choices = ", ".join(_choices(str(ctx.get("expected", ""))))
        return raw_loc, f"must be one of {choices}", "choice", value
    if typ == "missing":
        return raw_loc, "missing (required)", "missing", None
    if typ == "extra_forbidden":
        return raw_loc, "unknown key", "unknown_key", None
    if typ == "invalid_tag":
        field = ctx.get("field", "type")
        tag = value.get(field) if isinstance(value, Mapping) else value
        return (*raw_loc, field), f"must be one of {ctx.get('expected')}", "choice", tag
    if "field" in ctx:  # a rule of one table, reported at the field it names
        msg = err["msg"]
        table_value = value if isinstance(value, Mapping) else {}
        return (*raw_loc, ctx["field"]), msg, "rule", table_value.get(ctx["field"])
    return raw_loc, err["msg"], "rule", value


_UNITS = ("m", "Pa", "N", "N m", "m^2", "m^4", "kg/m^3", "m/s^2", "N/m", "N m/m", "1/m", "deg")


def _descriptions(tp: Any) -> list[str]:
    """Descriptions found in an annotation's metadata, outermost first."""
    out = []
    if typing.get_origin(tp) is Annotated:
        args = typing.get_args(tp)
        out += [m.description for m in args[1:] if getattr(m, "description", None)]
        out += _descriptions(args[0])
    elif typing.get_origin(tp) is Union or type(tp).__name__ == "UnionType":
        for a in typing.get_args(tp):
            out += _descriptions(a)
    return out


def _unit(raw_loc: Sequence[Any]) -> str:
    """The unit in a field's description (``"radius (m)"`` -> ``"m"``), or ``""``."""
    import re

    key = raw_loc[-1] if raw_loc else None
    for model in _models_at(raw_loc[:-1]):
        field = model.model_fields.get(key) if isinstance(key, str) else None
        if field is None:
            continue
        texts = [field.description or "", *_descriptions(field.annotation)]
        texts += [m.description for m in field.metadata if getattr(m, "description", None)]
        for text in texts:
            for inner in re.findall(r"\(([^()]*)\)", text):
                unit = inner.split(",")[0].split(";")[0].strip()
                if unit in _UNITS:
                    return unit
    return ""


def _choices(message: str) -> list[str]:
    return [c.strip(" '\"") for c in message.replace(" or ", ", ").split(",") if c.strip()]


def robot_file_errors(exc: ValidationError) -> list[FieldError]:
    """The errors of a failed :class:`RobotFile` validation, located and with suggestions.

    A misspelt key and the required key it stands for (``youngs_modulu`` for
    ``youngs_modulus``) are reported as one error naming both.
    """
    raw = exc.errors(include_url=False)
    items = []
    for err in raw:
        raw_loc, msg, kind, value = _translate(err)
        items.append((raw_loc, _clean_loc(raw_loc), msg, kind, value))
    missing = {(loc[:-1], loc[-1]) for _, loc, _, kind, _ in items if kind == "missing"}
    absorbed: set[tuple[Any, ...]] = set()
    out: list[FieldError] = []
    for raw_loc, loc, msg, kind, value in items:
        suggestion = None
        if kind == "unknown_key":
            parent, key = loc[:-1], str(loc[-1])
            wanted = [m for p, m in missing if p == parent and isinstance(m, str)]
            suggestion = _suggest(key, wanted)
            if suggestion is not None:
                absorbed.add((*parent, suggestion))
            else:
                known = sorted({f for m in _models_at(raw_loc[:-1]) for f in m.model_fields})
                suggestion = _suggest(key, known)
                if suggestion is None and known:
                    msg += f" (known: {', '.join(known)})"
            if suggestion is not None:
                msg += f"; did you mean `{suggestion}`?"
        elif kind in ("choice", "rule") and isinstance(value, str):
            ctx = raw[len(out)].get("ctx") or {}
            choices = ctx.get("choices") or _choices(msg.removeprefix("must be one of "))
            suggestion = _suggest(value, choices) if kind == "choice" or "choices" in ctx else None
            if suggestion is not None:
                msg += f"; did you mean `{suggestion}`?"
        out.append(FieldError(format_location(loc), msg, value, kind, suggestion))
    return [
        e
        for e, (_, loc, *_rest) in zip(out, items, strict=True)
        if not (e.kind == "missing" and tuple(loc) in absorbed)
    ]


# ----------------------------------------------------------------------------- rules


def _nonzero(v: Sequence[float] | None) -> bool:
    return v is not None and any(x != 0.0 for x in v)


def consistency_errors(spec: RobotFile) -> list[FieldError]:
    """Rules that tie fields of different tables together (the rod's length, density)."""
    length = spec.rod.length
    errs: list[FieldError] = []
    for i, t in enumerate(spec.tendons):
        if t.end is not None and t.end > length:
            errs.append(
                FieldError(
                    f"tendons[{i}].end",
                    f"must be in (0, rod.length] = (0, {length}] m",
                    t.end,
                    "range",
                )
            )
    for i, c in enumerate(spec.chambers):
        if c.start >= length:
            errs.append(
                FieldError(
                    f"chambers[{i}].start",
                    f"must be in [0, rod.length) = [0, {length}) m",
                    c.start,
                    "range",
                )
            )
        if c.end is not None and c.end > length:
            errs.append(
                FieldError(
                    f"chambers[{i}].end",
                    f"must be in (start, rod.length] = ({c.start}, {length}] m",
                    c.end,
                    "range",
                )
            )
    loads = spec.loads
    if loads is not None:
        for i, p in enumerate(loads.point_loads):
            if p.s > length:
                errs.append(
                    FieldError(
                        f"loads.point_loads[{i}].s",
                        f"must be in [0, rod.length] = [0, {length}] m",
                        p.s,
                        "range",
                    )
                )
        if _nonzero(loads.gravity) and spec.rod.density is None:
            errs.append(
                FieldError(
                    "loads.gravity",
                    "needs `rod.density` (kg/m^3), which is not given",
                    loads.gravity,
                    "rule",
                )
            )
    sec = spec.rod.section
    if isinstance(sec, TableSectionSpec) and (sec.s[0] != 0.0 or sec.s[-1] != length):
        errs.append(
            FieldError(
                "rod.section.s",
                f"must run from 0 to rod.length = {length} m",
                sec.s,
                "range",
            )
        )
    return errs


# ----------------------------------------------------------------------------- entry points


def validate_robot_dict(data: Any, source: str | None = None) -> RobotFile:
    """Validates a parsed description (the TOML file's tables) against the schema.

    Args:
        data: The tables, as :mod:`tomllib` reads them.
        source: The file it came from, for the message.

    Returns:
        The validated, immutable description.

    Raises:
        ParameterError: With every error in ``errors`` (:class:`FieldError`).
    """
    if not isinstance(data, Mapping):
        raise_errors([FieldError("", "must be a table of tables", data, "type")], source)
    try:
        spec = RobotFile.model_validate(dict(data))
    except ValidationError as exc:
        raise_errors(robot_file_errors(exc), source)
    errs = consistency_errors(spec)
    if errs:
        raise_errors(errs, source)
    return spec


def read_robot_toml(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Parses a robot file into its tables (no validation).

    Raises:
        OSError: If the file cannot be read.
        ParameterError: If it is not UTF-8 text or not valid TOML (with the line).
    """
    name = os.fspath(path)
    with open(path, "rb") as fh:
        raw = fh.read()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise_errors(
            [
                FieldError(
                    "",
                    f"not UTF-8 text (byte 0x{raw[exc.start]:02x} on line {line}): "
                    "a robot file is TOML, which is UTF-8",
                    kind="type",
                )
            ],
            name,
        )
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise_errors([FieldError("", f"not valid TOML: {exc}", kind="type")], name)


def robot_file_json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a robot description file."""
    schema = RobotFile.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "softrod robot description file"
    return schema


def _toml_item(value: Any) -> Any:
    import tomlkit

    if isinstance(value, Mapping):
        table = tomlkit.table()
        for k, v in value.items():
            table.add(k, _toml_item(v))
        return table
    if isinstance(value, list) and value and all(isinstance(v, Mapping) for v in value):
        aot = tomlkit.aot()
        for v in value:
            aot.append(_toml_item(v))
        return aot
    return value


def dump_robot_toml(spec: RobotFile) -> str:
    """The TOML text of a description (the keys given or set; comments are not kept).

    Tables are written as ``[rod.section]``, arrays of tables as ``[[tendons]]``, numbers
    exactly (``load_robot`` reads back the same floats).
    """
    import tomlkit

    data = spec.model_dump(mode="python", exclude_unset=True, exclude_none=True)
    doc = tomlkit.document()
    for key, value in data.items():
        if value == []:
            continue
        doc.add(key, _toml_item(value))
    return tomlkit.dumps(doc)
