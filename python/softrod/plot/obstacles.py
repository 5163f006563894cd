"""Simple obstacle shapes for the figures: planes, spheres, capsules and cylinders (m, world).

Each plotting function that takes ``obstacles=`` accepts these dataclasses, dicts such as
``{"type": "sphere", "center": [0, 0.05, 0.2], "radius": 0.02}``, or any object with the same
attributes (e.g. a contact model's obstacles).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .._core import ParameterError

__all__ = [
    "Capsule",
    "Cylinder",
    "Mesh",
    "Plane",
    "Sphere",
    "as_obstacle",
    "obstacle_surface",
]


def _field_error(name: str, value: object, why: str) -> ParameterError:
    err = ParameterError(f"invalid parameter `{name}` = {value!r}: {why}")
    err.parameter = name
    return err


def _unit(name: str, value: Sequence[float]) -> tuple[float, float, float]:
    """The direction of the finite vector ``value`` (shape (3,)) as a unit vector; scaled by its
    largest component first, so that 1e-300 and 1e300 have the direction they give."""
    n = np.asarray(value, dtype=float)
    largest = float(np.max(np.abs(n)))
    if not largest > 0:
        raise _field_error(name, value, "must be a nonzero vector")
    n = n / largest
    return tuple(float(x) for x in n / np.linalg.norm(n))


def _vector(name: str, value: object) -> tuple[float, float, float]:
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise _field_error(name, value, "must be 3 finite numbers (m, world)") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise _field_error(name, value, "must be 3 finite numbers (m, world)")
    return (float(v[0]), float(v[1]), float(v[2]))


def _radius(value: object) -> float:
    if isinstance(value, (str, bytes, bool)):  # (float("1") read a string as a radius)
        raise _field_error("radius", value, "must be a number > 0 (m)")
    try:
        r = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise _field_error("radius", value, "must be a number > 0 (m)") from None
    if not (np.isfinite(r) and r > 0):
        raise _field_error("radius", value, "must be finite and > 0 (m)")
    return r


def _friction(value: object) -> float:
    from .._core import MAX_FRICTION

    why = f"must be in [0, {MAX_FRICTION:g}] (a Coulomb coefficient, dimensionless)"
    if isinstance(value, bool):
        raise _field_error("friction", value, why)
    try:
        mu = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise _field_error("friction", value, why) from None
    if not (np.isfinite(mu) and 0 <= mu <= MAX_FRICTION):
        raise _field_error("friction", value, why)
    return mu


def _check(obj, vectors: tuple[str, ...], radius: bool) -> None:
    for name in vectors:
        object.__setattr__(obj, name, _vector(name, getattr(obj, name)))
    if radius:
        object.__setattr__(obj, "radius", _radius(obj.radius))
    object.__setattr__(obj, "friction", _friction(obj.friction))


@dataclass(frozen=True)
class Plane:
    """A plane through ``point`` (m, world, shape (3,)) with unit ``normal`` (shape (3,));
    ``friction`` is the Coulomb coefficient of its surface (dimensionless, >= 0; friction
    acts at point contacts, at the tip and inside the rod)."""

    point: tuple[float, float, float]
    normal: tuple[float, float, float]
    friction: float = 0.0

    def __post_init__(self) -> None:
        _check(self, ("point", "normal"), False)
        object.__setattr__(self, "normal", _unit("normal", self.normal))


@dataclass(frozen=True)
class Sphere:
    """A sphere of ``radius`` (m) about ``center`` (m, world, shape (3,)); ``friction`` as
    for :class:`Plane`."""

    center: tuple[float, float, float]
    radius: float
    friction: float = 0.0

    def __post_init__(self) -> None:
        _check(self, ("center",), True)


@dataclass(frozen=True)
class Capsule:
    """Points within ``radius`` (m) of the segment from ``a`` to ``b`` (m, world, (3,) each);
    ``friction`` as for :class:`Plane`."""

    a: tuple[float, float, float]
    b: tuple[float, float, float]
    radius: float
    friction: float = 0.0

    def __post_init__(self) -> None:
        _check(self, ("a", "b"), True)
        if self.a == self.b:
            raise _field_error("b", self.b, "must differ from `a` (the axis)")


@dataclass(frozen=True)
class Cylinder:
    """A closed cylinder of ``radius`` (m) with axis from ``a`` to ``b`` (m, world);
    ``friction`` as for :class:`Plane`."""

    a: tuple[float, float, float]
    b: tuple[float, float, float]
    radius: float
    friction: float = 0.0

    def __post_init__(self) -> None:
        _check(self, ("a", "b"), True)
        if self.a == self.b:
            raise _field_error("b", self.b, "must differ from `a` (the axis)")


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh: ``vertices`` (m, world, shape (N, 3)) and ``faces`` (vertex indices,
    shape (M, 3), counter-clockwise seen from outside). The gap is the signed distance to
    its triangles (negative inside a closed mesh), computed in the Rust core. ``friction``
    as for :class:`Plane`.
    """

    vertices: np.ndarray
    faces: np.ndarray
    friction: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "friction", _friction(self.friction))
        try:
            v = np.array(self.vertices, dtype=float)
        except (TypeError, ValueError):
            raise _field_error("vertices", self.vertices, "must be an (N, 3) array (m)") from None
        if v.ndim != 2 or v.shape[1] != 3 or not np.all(np.isfinite(v)):
            raise _field_error("vertices", self.vertices, "must be an (N, 3) finite array (m)")
        try:
            f = np.array(self.faces)
        except (TypeError, ValueError):
            raise _field_error("faces", self.faces, "must be an (M, 3) index array") from None
        if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0 or not np.issubdtype(f.dtype, np.integer):
            raise _field_error("faces", self.faces, "must be an (M, 3) integer array, M >= 1")
        if f.min() < 0 or f.max() >= len(v):
            raise _field_error("faces", self.faces, f"indices must be in [0, {len(v) - 1}]")
        v.setflags(write=False)
        f = f.astype(np.int64)
        f.setflags(write=False)
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Mesh)
            and np.array_equal(self.vertices, other.vertices)
            and np.array_equal(self.faces, other.faces)
            and self.friction == other.friction
        )

    def __hash__(self) -> int:
        return hash((self.vertices.tobytes(), self.faces.tobytes(), self.friction))

    @classmethod
    def from_file(cls, path, friction: float = 0.0) -> Mesh:
        """A mesh read by trimesh from ``path`` (coordinates in m; the format from the
        extension: trimesh's mesh formats, ``glb``, ``obj``, ``ply``,
        ``stl`` ...), with Coulomb coefficient ``friction``.

        Raises:
            ParameterError: At ``file``: no such file, an extension trimesh does not read (the
                message lists the formats), a file trimesh cannot parse, or one without a
                triangle (empty, junk, a point cloud).
        """
        import trimesh

        name = str(path)
        if not os.path.isfile(name):
            raise _field_error("file", name, "is not a file")
        try:
            m = trimesh.load_mesh(name, process=False)
        except NotImplementedError:  # trimesh has no loader for the extension
            ext = os.path.splitext(name)[1] or "(none)"
            raise _field_error(
                "file",
                name,
                f"its extension {ext} is not a mesh format trimesh reads: "
                f"{', '.join(_mesh_formats())}",
            ) from None
        except Exception as exc:  # any failure of trimesh's parsers on the user's file
            raise _field_error(
                "file", name, f"could not be read as a mesh ({type(exc).__name__}: {exc})"
            ) from None
        faces = np.asarray(getattr(m, "faces", np.zeros((0, 3))), dtype=np.int64)
        if faces.ndim != 2 or len(faces) == 0:
            raise _field_error(
                "file", name, "no triangles read (an empty file, or not a mesh in its format)"
            )
        return cls(np.asarray(m.vertices, dtype=float), faces, friction)


def _mesh_formats() -> list[str]:
    """The mesh formats (file extensions) that :meth:`Mesh.from_file` reads: trimesh's."""
    from trimesh.exchange.load import mesh_formats as formats

    return sorted(formats())


def _mesh_of(fields: dict) -> Mesh:
    friction = fields.get("friction", 0.0)
    if "file" in fields:
        return Mesh.from_file(fields["file"], friction)
    return Mesh(fields.get("vertices"), fields.get("faces"), friction)


_KINDS = {
    "plane": Plane,
    "sphere": Sphere,
    "capsule": Capsule,
    "cylinder": Cylinder,
    "mesh": lambda **f: _mesh_of(f),
}


def _bad(i: int, value: object, why: str) -> ParameterError:
    err = ParameterError(f"invalid parameter `obstacles[{i}]` = {value!r}: {why}")
    err.parameter = f"obstacles[{i}]"
    return err


def as_obstacle(obj, index: int = 0) -> Plane | Sphere | Capsule | Cylinder | Mesh:
    """Converts a dict or a duck-typed object to one of the obstacle dataclasses.

    Raises:
        ParameterError: Unknown type, missing field or a non-positive radius.
    """
    if isinstance(obj, (Plane, Sphere, Capsule, Cylinder, Mesh)):
        out = obj
    elif isinstance(obj, Mapping):
        kind = str(obj.get("type", "")).lower()
        if kind not in _KINDS:
            raise _bad(index, obj, f"`type` must be one of {', '.join(_KINDS)}")
        fields = {k: v for k, v in obj.items() if k != "type"}
        try:
            out = _KINDS[kind](**fields)
        except (TypeError, ParameterError) as exc:
            raise _bad(index, obj, str(exc)) from None
    elif hasattr(obj, "vertices") and hasattr(obj, "faces"):
        out = Mesh(obj.vertices, obj.faces, getattr(obj, "friction", 0.0))
    elif hasattr(obj, "normal") and hasattr(obj, "point"):
        out = Plane(obj.point, obj.normal, getattr(obj, "friction", 0.0))
    elif hasattr(obj, "center") and hasattr(obj, "radius"):
        out = Sphere(obj.center, obj.radius, getattr(obj, "friction", 0.0))
    elif hasattr(obj, "a") and hasattr(obj, "b") and hasattr(obj, "radius"):
        out = Capsule(obj.a, obj.b, obj.radius, getattr(obj, "friction", 0.0))
    else:
        raise _bad(index, obj, "must be a Plane, Sphere, Capsule, Cylinder or a dict with `type`")
    radius = getattr(out, "radius", 1.0)
    if not float(radius) > 0:
        raise _bad(index, obj, "the radius must be > 0 m")
    if isinstance(out, Plane) and not np.linalg.norm(out.normal) > 0:
        raise _bad(index, obj, "the normal must be nonzero")
    return out


def as_obstacles(obstacles: Sequence | None) -> list:
    """Every entry of ``obstacles`` through :func:`as_obstacle`."""
    if obstacles is None:
        return []
    if isinstance(obstacles, (str, bytes, Mapping)) or not isinstance(obstacles, Sequence):
        raise _field_error(
            "obstacles", obstacles, "must be a list of Plane, Sphere, Capsule or Cylinder"
        )
    return [as_obstacle(o, i) for i, o in enumerate(obstacles)]


def _basis(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    axis = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(axis, e1)


def obstacle_surface(obstacle, extent_centre: np.ndarray, extent: float, n: int = 32):
    """Grid ``(X, Y, Z)`` (m) of an obstacle's surface; a plane is drawn as a square of side
    ``extent`` (m) centred on the foot of ``extent_centre`` (m); a mesh gives its vertices
    (shape (N, 1) each)."""
    if isinstance(obstacle, Mesh):
        # The vertices, as an (N, 1) grid (drawn as triangles by the views).
        pts = obstacle.vertices[:, None, :]
    elif isinstance(obstacle, Sphere):
        c = np.asarray(obstacle.center, dtype=float)
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n), np.linspace(0, np.pi, n // 2 + 1))
        pts = obstacle.radius * np.stack(
            (np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)), -1
        )
        pts = pts + c
    elif isinstance(obstacle, Plane):
        normal = np.asarray(obstacle.normal, dtype=float)
        normal /= np.linalg.norm(normal)
        p0 = np.asarray(obstacle.point, dtype=float)
        foot = extent_centre - np.dot(extent_centre - p0, normal) * normal
        e1, e2 = _basis(normal)
        a, b = np.meshgrid(np.linspace(-0.5, 0.5, 2), np.linspace(-0.5, 0.5, 2))
        pts = foot + extent * (a[..., None] * e1 + b[..., None] * e2)
    else:
        a, b = np.asarray(obstacle.a, dtype=float), np.asarray(obstacle.b, dtype=float)
        axis = b - a
        length = float(np.linalg.norm(axis))
        e1, e2 = _basis(axis)
        t = axis / length
        theta = np.linspace(0, 2 * np.pi, n)
        if isinstance(obstacle, Capsule):
            # Meridian: hemisphere at a, cylinder, hemisphere at b.
            phi = np.linspace(-np.pi / 2, np.pi / 2, n // 2)
            half = len(phi) // 2
            r_sin = obstacle.radius * np.sin(phi)
            along = np.concatenate((r_sin[:half], length + r_sin[half:]))
            rad = obstacle.radius * np.cos(phi)
        else:
            along = np.array([0.0, 0.0, length, length])
            rad = np.array([0.0, obstacle.radius, obstacle.radius, 0.0])
        th, k = np.meshgrid(theta, np.arange(len(along)))
        ring = np.cos(th)[..., None] * e1 + np.sin(th)[..., None] * e2
        pts = a + along[k][..., None] * t + rad[k][..., None] * ring
    return pts[..., 0], pts[..., 1], pts[..., 2]
