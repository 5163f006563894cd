"""End constraints for :func:`softrod.solve_statics` (``tip_constraint=``) and the obstacles
of ``obstacles=`` (the same dataclasses the figures draw, :mod:`softrod.plot.obstacles`).

All in SI units and world coordinates. The constraints are exact (rows of the shooting
problem, see ``docs/contact.md``); the reaction is ``solution.tip_reaction``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .plot.obstacles import Capsule, Cylinder, Mesh, Plane, Sphere, _field_error, _unit, _vector

__all__ = ["Capsule", "Clamp", "Cylinder", "Mesh", "Pin", "Plane", "Slide", "Sphere"]


@dataclass(frozen=True, eq=False)
class Clamp:
    """The tip clamped at ``pose``: a 4x4 homogeneous transform (position in m, rotation body
    -> world). ``held`` (optional, six booleans ``[x, y, z, rx, ry, rz]`` in the pose's frame)
    releases directions: e.g. ``[True, True, False, True, True, False]`` lets the tip slide
    along and twist about the pose's z axis. Rotations are held all three, only about x and
    y (the tip's tangent along the pose's z axis), or none."""

    pose: np.ndarray
    held: Sequence[bool] | None = field(default=None)

    def __post_init__(self) -> None:
        try:
            t = np.array(self.pose, dtype=float)
        except (TypeError, ValueError):
            raise _field_error("pose", self.pose, "must be a 4x4 homogeneous transform") from None
        if t.shape != (4, 4) or not np.all(np.isfinite(t)):
            raise _field_error("pose", self.pose, "must be a finite 4x4 homogeneous transform")
        r = t[:3, :3]
        if not np.allclose(t[3], [0, 0, 0, 1]) or not np.allclose(r.T @ r, np.eye(3), atol=1e-9):
            raise _field_error(
                "pose",
                self.pose,
                "must be a rigid transform (orthonormal rotation, last row 0 0 0 1)",
            )
        t.setflags(write=False)
        object.__setattr__(self, "pose", t)
        if self.held is not None:
            held = tuple(self.held) if isinstance(self.held, (list, tuple)) else None
            if held is None or len(held) != 6 or not all(isinstance(h, bool) for h in held):
                raise _field_error("held", self.held, "must be six booleans [x, y, z, rx, ry, rz]")
            object.__setattr__(self, "held", held)


@dataclass(frozen=True)
class Pin:
    """The tip pinned at ``point`` (m, world, shape (3,)), free to rotate."""

    point: Sequence[float]

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vector("point", self.point))


@dataclass(frozen=True)
class Slide:
    """The tip sliding without friction on the plane through ``point`` (m) with ``normal``:
    held along the normal only."""

    point: Sequence[float]
    normal: Sequence[float]

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vector("point", self.point))
        object.__setattr__(self, "normal", _unit("normal", _vector("normal", self.normal)))
