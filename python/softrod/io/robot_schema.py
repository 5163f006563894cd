"""The schema of a robot description file (TOML): one pydantic model per table,
:class:`RobotFile` at the top.

Validation is strict: numbers are numbers (``true`` or ``"3"`` are not), integers are
integers, floats are finite, tables are tables, unknown keys are errors. The located error
messages are made in :mod:`softrod.io.robot_errors`; reading and writing are in
:mod:`softrod.io.robot_file`, which re-exports every name of this module.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any, Literal, Union

from pydantic import (
    AllowInfNan,
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    Strict,
    Tag,
    model_validator,
)
from pydantic_core import PydanticCustomError

from .._core import MAX_FRICTION, SILICONES

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
    friction: _num(
        "friction coefficient between tendon and channel (capstan law)", ge=0, le=MAX_FRICTION
    ) = 0.0


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
    friction: _num(
        "Coulomb friction coefficient of the surface (dimensionless)", ge=0, le=MAX_FRICTION
    ) = 0.0


class SphereSpec(_Table):
    """A sphere obstacle."""

    type: Literal["sphere"]
    center: _vec(3, "centre (m, world)")
    radius: _num("radius (m)", gt=0)
    friction: _num(
        "Coulomb friction coefficient of the surface (dimensionless)", ge=0, le=MAX_FRICTION
    ) = 0.0


class CapsuleSpec(_Table):
    """The points within `radius` of the segment `a`-`b` (world)."""

    type: Literal["capsule"]
    a: _vec(3, "first end of the axis (m, world)")
    b: _vec(3, "second end of the axis (m, world)")
    radius: _num("radius (m)", gt=0)
    friction: _num(
        "Coulomb friction coefficient of the surface (dimensionless)", ge=0, le=MAX_FRICTION
    ) = 0.0


class CylinderSpec(_Table):
    """A closed cylinder with cap centres `a` and `b` (world)."""

    type: Literal["cylinder"]
    a: _vec(3, "centre of the first cap (m, world)")
    b: _vec(3, "centre of the second cap (m, world)")
    radius: _num("radius (m)", gt=0)
    friction: _num(
        "Coulomb friction coefficient of the surface (dimensionless)", ge=0, le=MAX_FRICTION
    ) = 0.0


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
    friction: _num(
        "Coulomb friction coefficient of the surface (dimensionless)", ge=0, le=MAX_FRICTION
    ) = 0.0

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
